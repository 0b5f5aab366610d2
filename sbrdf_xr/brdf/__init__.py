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

Anisotropic models (:data:`ANISOTROPIC_MODELS`) take the facet tangent as well: their
``brdf`` has a ``tangent`` keyword, ``brdf_angles`` a ``psi`` keyword and
``render_grid`` a ``psi`` grid (a table with an extra ``psi`` axis).

``"anisotropic_microfacet"``
    Anisotropic GGX with Smith masking (:mod:`~sbrdf_xr.brdf.anisotropic`), for brushed
    metals; equal to ``"microfacet"`` when ``alpha_x = alpha_y``.
"""

from __future__ import annotations

from types import ModuleType

from ..errors import ValidationError
from . import anisotropic, lambert, microfacet, optics, robertson_sandford

__all__ = [
    "ANISOTROPIC_MODELS",
    "MODELS",
    "anisotropic",
    "get_model",
    "lambert",
    "microfacet",
    "optics",
    "robertson_sandford",
]

#: Registry of the analytic models: name -> module implementing the common interface.
MODELS: dict[str, ModuleType] = {
    "lambert": lambert,
    "robertson_sandford": robertson_sandford,
    "microfacet": microfacet,
}
#: Registry of the anisotropic models (their tables have a ``psi`` axis).
ANISOTROPIC_MODELS: dict[str, ModuleType] = {
    "anisotropic_microfacet": anisotropic,
}


def get_model(name: str) -> ModuleType:
    """Return the model module registered under ``name``.

    Parameters
    ----------
    name : str
        One of the keys of :data:`MODELS` or :data:`ANISOTROPIC_MODELS`.

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
    if isinstance(name, str) and name in ANISOTROPIC_MODELS:
        return ANISOTROPIC_MODELS[name]
    if not isinstance(name, str) or name not in MODELS:
        raise ValidationError(
            f"model: got {name!r}; valid model names are {sorted(MODELS)} and the anisotropic "
            f"{sorted(ANISOTROPIC_MODELS)}"
        )
    return MODELS[name]
