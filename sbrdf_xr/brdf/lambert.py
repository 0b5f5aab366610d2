"""Lambertian (perfectly diffuse) spectral BRDF.

``f_r(lambda) = rho(lambda) / pi`` for a lit (``N.s > 0``) and visible (``N.o > 0``)
facet, zero otherwise (paper 001 §2: "A 100 percent reflecting and perfectly
diffuse sample has, for all incident angles, a BRDF of 1/pi sr-1").  Its
directional-hemispherical reflectance is ``rho`` exactly.

The model is declared once, as :data:`MODEL` (a :class:`sbrdf_xr.brdf.Model`); the
evaluation from paper-000 angles, the grid rendering and the parameter validation
are the model interface's (:mod:`sbrdf_xr.brdf._model`), re-exported here as
``brdf_angles``, ``render_grid`` and ``check_params``.

Spectral parameters are 1-D arrays aligned with ``wavelength`` [nm] (shape
``(n_wl,)``; a scalar means a flat spectrum).  Results have shape
``broadcast(leading dims) + (n_wl,)``.

Precision policy: all arithmetic is done in float64; the result is returned in the
working precision of the geometric inputs (float32 if every floating input is
float32, float64 otherwise), clipped to the finite range of that dtype.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ._common import _cast_out, _check_theta_i, _facet_frame
from ._model import Model, Parameter

__all__ = [
    "MODEL",
    "PARAMS",
    "brdf",
    "brdf_angles",
    "check_params",
    "directional_hemispherical_reflectance",
    "render_grid",
]

#: The parameter: the spectral diffuse (directional-hemispherical) reflectance.
PARAMETERS = (Parameter("rho", "1", "Lambertian albedo", lower=0.0, upper=1.0),)


def brdf(
    normal: ArrayLike,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    wavelength: ArrayLike,
    **params: Any,
) -> np.ndarray:
    """Lambertian spectral BRDF ``rho(lambda) / pi``.

    Parameters
    ----------
    normal, to_sun, to_observer : array_like, shape (..., 3)
        Facet normal, direction to the source and to the observer [1]; need not be
        unit length; broadcast against each other.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    rho : array_like, scalar or shape (n_wl,)
        Spectral reflectance [1].

    Returns
    -------
    ndarray, shape broadcast(...) + (n_wl,)
        BRDF [sr-1]; exactly zero where ``N.s <= 0`` or ``N.o <= 0``.

    References
    ----------
    Paper 001 §2 (perfectly diffuse surface: ``1/pi`` sr-1 for unit reflectance).

    Examples
    --------
    >>> import numpy as np
    >>> n, s, o = [0.0, 0.0, 1.0], [0.5, 0.0, 1.0], [-0.5, 0.0, 1.0]
    >>> np.round(brdf(n, s, o, [450.0, 650.0], rho=[0.2, 0.4]) * np.pi, 6)
    array([0.2, 0.4])
    """
    p = MODEL.check_params(wavelength, **params)
    _, _, _, _, _, mask, dtype = _facet_frame(normal, to_sun, to_observer)
    out = np.where(mask[..., None], p["rho"] / np.pi, 0.0)
    return _cast_out(out, dtype)


def directional_hemispherical_reflectance(
    theta_i: ArrayLike, wavelength: ArrayLike, **params: Any
) -> np.ndarray:
    """Directional-hemispherical reflectance of a Lambertian surface (closed form).

    Parameters
    ----------
    theta_i : array_like
        Incidence angle [degree], ``0 <= theta_i <= 90``.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    rho : array_like, scalar or shape (n_wl,)
        Spectral reflectance [1].

    Returns
    -------
    ndarray, shape theta_i.shape + (n_wl,)
        ``rho(lambda)`` for every ``theta_i`` [1] (paper 001 Eq. 1 integrated exactly).

    Examples
    --------
    >>> directional_hemispherical_reflectance([0.0, 60.0], [450.0, 650.0], rho=[0.2, 0.4]).tolist()
    [[0.2, 0.4], [0.2, 0.4]]
    """
    p = MODEL.check_params(wavelength, **params)
    ti = _check_theta_i(theta_i)
    return np.broadcast_to(p["rho"], ti.shape + p["rho"].shape).copy()


#: The Lambert model.
MODEL = Model(
    name="lambert",
    long_name="perfectly diffuse surface, rho / pi",
    brdf=brdf,
    parameters=PARAMETERS,
    citation="Sandford, paper 001 section 2 (a perfectly diffuse sample: 1/pi sr-1)",
    reflectance=directional_hemispherical_reflectance,
    reciprocal=True,
)
PARAMS = MODEL.param_names
check_params, brdf_angles, render_grid = MODEL.check_params, MODEL.brdf_angles, MODEL.render_grid
