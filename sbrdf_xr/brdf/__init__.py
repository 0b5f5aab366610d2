"""Analytic spectral BRDF models as pure, vectorised numpy functions.

Every model module implements the same interface (see :mod:`sbrdf_xr.brdf.lambert`):
``PARAMS``, ``check_params``, ``brdf``, ``brdf_angles``, ``render_grid`` and
``directional_hemispherical_reflectance``.  Models are listed once in :data:`MODELS`
and selected by name with :func:`get_model` (colour-science dispatcher style).

Models
------
``"lambert"``
    Perfectly diffuse, ``rho / pi`` (:mod:`~sbrdf_xr.brdf.lambert`).
``"robertson_sandford"``
    Robertson–Sandford semi-empirical paint model, paper 001 §4
    (:mod:`~sbrdf_xr.brdf.robertson_sandford`).
``"microfacet"``
    Cook–Torrance / Walter et al. 2007 GGX microfacet model with exact Fresnel terms
    (:mod:`~sbrdf_xr.brdf.microfacet`, :mod:`~sbrdf_xr.brdf.optics`).
"""

from __future__ import annotations

from types import ModuleType

from ..errors import ValidationError
from . import lambert, microfacet, optics, robertson_sandford

__all__ = ["MODELS", "get_model", "lambert", "microfacet", "optics", "robertson_sandford"]

#: Registry of the analytic models: name -> module implementing the common interface.
MODELS: dict[str, ModuleType] = {
    "lambert": lambert,
    "robertson_sandford": robertson_sandford,
    "microfacet": microfacet,
}


def get_model(name: str) -> ModuleType:
    """Return the model module registered under ``name``.

    Parameters
    ----------
    name : str
        One of the keys of :data:`MODELS`.

    Returns
    -------
    module
        The model module (``PARAMS``, ``check_params``, ``brdf``, ``brdf_angles``,
        ``render_grid``, ``directional_hemispherical_reflectance``).

    Raises
    ------
    ValidationError
        If ``name`` is not a registered model; the message lists the valid names.
    """
    if not isinstance(name, str) or name not in MODELS:
        raise ValidationError(
            f"model: got {name!r}; valid model names are {sorted(MODELS)}"
        )
    return MODELS[name]
