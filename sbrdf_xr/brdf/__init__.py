"""Analytic spectral BRDF models as pure, vectorised numpy functions.

Every model is one :class:`Model` object (:mod:`sbrdf_xr.brdf._model`): its name, its
``brdf`` function, its parameters declared with units, long_name and domain
(:class:`Parameter`), whether it is anisotropic, its citation and its
directional-hemispherical reflectance.  The evaluation from paper-000 angles
(``brdf_angles``), the rendering on angle grids (``render_grid``) and the parameter
validation (``check_params``) are methods of :class:`Model`, written once for every
model.  Models are registered in :data:`BRDF_MODELS` and selected by name with
:func:`get_model` (case-insensitive; colour-science's ``CanonicalMapping`` and
``validate_method`` style).

Units: wavelengths (and layer thicknesses) in nm, angles in degree.  Every such
argument of the functions of this package also takes an astropy Quantity, converted
as the function's first step (a wavelength also from a frequency or wavenumber);
a Quantity of another kind raises :class:`~sbrdf_xr.errors.UnitError` naming the
argument (:func:`sbrdf_xr.units.to_unit`).  The arithmetic stays pure numpy.

Adding a model is one module defining a :class:`Model` and its line in
:data:`_REGISTERED` below (or, from outside the package, :func:`register_model`).

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
``"robertson_sandford_core"``
    Robertson–Sandford plus a narrow Beckmann specular core, for near-mirrors measured
    in-plane (:mod:`~sbrdf_xr.brdf.specular_core`).
``"robertson_sandford_halo"``
    The same with a Harvey–Shack ABg halo between the core and the body
    (:mod:`~sbrdf_xr.brdf.halo`).

Anisotropic models (:data:`ANISOTROPIC_MODELS`) take the facet tangent as well: their
``brdf`` has a ``tangent`` keyword, ``brdf_angles`` and ``render_grid`` a ``psi``
keyword (a table with an extra ``psi`` axis).

``"anisotropic_microfacet"``
    Anisotropic GGX with Smith masking (:mod:`~sbrdf_xr.brdf.anisotropic`), for brushed
    metals; equal to ``"microfacet"`` when ``alpha_x = alpha_y``.
"""

from . import (
    anisotropic,
    halo,
    lambert,
    microfacet,
    optics,
    robertson_sandford,
    robertson_sandford_angular,
    specular_core,
)
from ._model import Model, ModelRegistry, Parameter

__all__ = [
    "ANISOTROPIC_MODELS",
    "BRDF_MODELS",
    "MODELS",
    "Model",
    "ModelRegistry",
    "Parameter",
    "anisotropic",
    "get_model",
    "halo",
    "lambert",
    "microfacet",
    "optics",
    "register_model",
    "robertson_sandford",
    "robertson_sandford_angular",
    "specular_core",
    "unregister_model",
]

#: Every registered model, by name.
BRDF_MODELS = ModelRegistry()
#: The isotropic models (a live view of :data:`BRDF_MODELS`).
MODELS = BRDF_MODELS.view(anisotropic=False)
#: The anisotropic models (their tables have a ``psi`` axis; a live view).
ANISOTROPIC_MODELS = BRDF_MODELS.view(anisotropic=True)

#: The package's models, one line each.
_REGISTERED = (lambert, robertson_sandford, microfacet, anisotropic, specular_core, halo)


def get_model(name: str) -> Model:
    """Return the model registered under ``name`` (case-insensitive).

    Parameters
    ----------
    name : str
        A name of :data:`BRDF_MODELS`; case, ``-``, ``_`` and spaces are ignored.

    Returns
    -------
    Model

    Raises
    ------
    ValidationError
        If ``name`` is not a registered model; the message lists the valid names.

    Examples
    --------
    >>> get_model("Robertson-Sandford").param_names
    ('rho_D', 'epsilon', 'b', 'e')
    >>> get_model("phong")
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.ValidationError: model: got 'phong'; valid model names are
    ['anisotropic_microfacet', 'lambert', 'microfacet', 'robertson_sandford',
    'robertson_sandford_core', 'robertson_sandford_halo'] (case-insensitive)
    """
    return BRDF_MODELS[name]


def register_model(model: Model, *, replace: bool = False) -> Model:
    """Register ``model`` under ``model.name`` (:meth:`ModelRegistry.register`).

    Parameters
    ----------
    model : Model
        A complete declaration (every parameter with units, long_name and domain).
    replace : bool, default False
        Replace a model registered under the same name.

    Returns
    -------
    Model

    Raises
    ------
    ValidationError
        Not a :class:`Model`, or the name is taken and ``replace`` is false.

    Examples
    --------
    >>> import numpy as np
    >>> def grey(normal, to_sun, to_observer, wavelength, **params):
    ...     return lambert.brdf(normal, to_sun, to_observer, wavelength, rho=params["a"])
    >>> m = register_model(
    ...     Model(
    ...         name="grey",
    ...         long_name="a grey Lambertian surface",
    ...         brdf=grey,
    ...         parameters=(Parameter("a", "1", "albedo", lower=0.0, upper=1.0),),
    ...         citation="Lambert (1760)",
    ...     )
    ... )
    >>> f = get_model("grey").brdf_angles(0.0, 0.0, 0.0, [550.0], a=0.5)
    >>> round(float(f[0] * np.pi), 6)
    0.5
    >>> unregister_model("grey").name
    'grey'
    """
    return BRDF_MODELS.register(model, replace=replace)


def unregister_model(name: str) -> Model:
    """Remove the model registered under ``name`` and return it.

    Raises
    ------
    ValidationError
        If ``name`` is not a registered model.

    Examples
    --------
    >>> import dataclasses
    >>> m = register_model(dataclasses.replace(get_model("lambert"), name="lambert_copy"))
    >>> unregister_model("Lambert-Copy").name
    'lambert_copy'
    """
    return BRDF_MODELS.unregister(name)


for _module in _REGISTERED:
    register_model(_module.MODEL)
del _module
