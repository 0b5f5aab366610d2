"""Lambertian (perfectly diffuse) spectral BRDF.

``f_r(lambda) = rho(lambda) / pi`` for a lit (``N.s > 0``) and visible (``N.o > 0``)
facet, zero otherwise (paper 001 §2: "A 100 percent reflecting and perfectly
diffuse sample has, for all incident angles, a BRDF of 1/pi sr-1").  Its
directional-hemispherical reflectance is ``rho`` exactly.

The helpers that implement the common model interface live in
:mod:`sbrdf_xr.brdf._common`.

Common interface
----------------
Every model module defines ``PARAMS``, ``check_params``, ``brdf``, ``brdf_angles``,
``render_grid`` and ``directional_hemispherical_reflectance``.  Spectral parameters
are 1-D arrays aligned with ``wavelength`` [nm] (shape ``(n_wl,)``; a scalar means a
flat spectrum); scalar parameters may be scalars or per-band arrays of shape
``(n_wl,)``.  Results have shape ``broadcast(leading dims) + (n_wl,)``.

Precision policy: all arithmetic is done in float64; the result is returned in the
working precision of the geometric inputs (float32 if every floating input is
float32, float64 otherwise), clipped to the finite range of that dtype.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._common import (
    _angles_to_vectors,
    _band_param,
    _cast_out,
    _check_names,
    _check_theta_i,
    _check_wavelength,
    _facet_frame,
    _render_grid,
)

__all__ = [
    "PARAMS",
    "brdf",
    "brdf_angles",
    "check_params",
    "directional_hemispherical_reflectance",
    "render_grid",
]

#: Names of the model parameters: the spectral diffuse reflectance [1].
PARAMS: tuple[str, ...] = ("rho",)


# --------------------------------------------------------------------------
# the Lambert model
# --------------------------------------------------------------------------


def check_params(wavelength: ArrayLike, **params: Any) -> dict[str, NDArray[np.float64]]:
    """Validate Lambert parameters and broadcast them to the wavelength grid.

    Parameters
    ----------
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    rho : array_like, scalar or shape (n_wl,)
        Spectral (directional-hemispherical) reflectance [1], ``0 <= rho <= 1``.

    Returns
    -------
    dict
        ``{"rho": ndarray (n_wl,)}`` in float64.

    Raises
    ------
    ValidationError
        Missing or unexpected parameters, shape mismatch, NaN, or out-of-domain values.
    """
    wl = _check_wavelength(wavelength)
    _check_names(params, PARAMS, "lambert")
    return {"rho": _band_param("rho", params["rho"], wl.size, lower=0.0, upper=1.0)}


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
    """
    p = check_params(wavelength, **params)
    _, _, _, _, _, mask, dtype = _facet_frame(normal, to_sun, to_observer)
    out = np.where(mask[..., None], p["rho"] / np.pi, 0.0)
    return _cast_out(out, dtype)


def brdf_angles(
    theta_i: ArrayLike,
    delta_theta: ArrayLike,
    phi: ArrayLike,
    wavelength: ArrayLike,
    **params: Any,
) -> np.ndarray:
    """Lambertian BRDF from the paper-000 angles.

    Parameters
    ----------
    theta_i, delta_theta, phi : array_like
        Paper-000 Fig. 4 angles [degree]; broadcast against each other.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    **params
        See :func:`brdf`.

    Returns
    -------
    ndarray, shape broadcast(...) + (n_wl,)
        BRDF [sr-1].
    """
    return brdf(*_angles_to_vectors(theta_i, delta_theta, phi), wavelength, **params)


def render_grid(
    theta_i: ArrayLike,
    delta_theta: ArrayLike,
    phi: ArrayLike,
    wavelength: ArrayLike,
    **params: Any,
) -> np.ndarray:
    """Lambertian BRDF on the outer product of 1-D angle grids.

    Parameters
    ----------
    theta_i, delta_theta, phi : array_like, 1-D
        Grids of paper-000 angles [degree].
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    **params
        See :func:`brdf`.

    Returns
    -------
    ndarray, shape (n_ti, n_dt, n_phi, n_wl)
        BRDF [sr-1].
    """
    return _render_grid(brdf_angles, theta_i, delta_theta, phi, wavelength, **params)


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
    """
    p = check_params(wavelength, **params)
    ti = _check_theta_i(theta_i)
    return np.broadcast_to(p["rho"], ti.shape + p["rho"].shape).copy()
