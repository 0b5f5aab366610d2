r"""Robertson–Sandford (R-S) semi-empirical spectral BRDF (paper 001, §4).

Four parameters: the diffuse spectral reflectance ``rho_D(lambda)``, the spectral
(hemispherical) emissivity ``epsilon(lambda)``, the grazing-angle parameter ``b`` and
the specular lobe width ``e`` (paper 001 §4, Table 4).  The BRDF is the sum of a
diffuse term (Eq. 13) and a Trowbridge–Reitz specular lobe (Eqs. 15–16) with a
grazing cut-off (Eq. 21).  The least-squares fit to measured samples is
:mod:`sbrdf_xr.brdf.robertson_sandford_fit`.

How the equations are read (the text of paper 001 is an extraction with mangled
symbols; every reading below is checked by quadrature in the tests)
-------------------------------------------------------------------------------

* **Eq. 10**, ``G(b) = (1/pi) int cos(theta) g(theta) dOmega`` over the hemisphere.
  The printed closed form ``[1 - b^2/(1-b^2) log(1/b^2)] / (1-b^2)`` equals that
  integral (substitute ``u = cos^2 theta``: ``G = int_0^1 u du / (b^2 + (1-b^2) u)``).
  It has ``G(0) = 1`` (Lambertian), a removable singularity at ``b = 1`` (``G = 1/2``)
  and is valid for ``b > 1`` (``G ~ log(b^2)/b^2``).  Near ``b = 1`` the printed form
  cancels catastrophically (relative error ~ ``eps / (1-b^2)^2``); there the series
  ``G = sum_n c^n / ((n+1)(n+2))``, ``c = 1 - b^2``, is used.
* **Eq. 11** reads ``rho(lambda, theta_i) = rho_s(lambda, theta_i) + rho_d(lambda,
  theta_i) = 1 - epsilon(lambda, theta_i)``: the directional-hemispherical
  reflectance (the bar is the integral of ``f_r cos(theta_r) dOmega_r``).
* **Eq. 13**, ``f_d = g(theta_r) rho_D g(theta_i) / (pi G(b)^2)`` with ``rho_d(lambda)``
  read as ``rho_D``.  Integrating over the reflection hemisphere gives the diffusely
  scattered fraction ``rho_d(lambda, theta_i) = rho_D g(theta_i) / G(b)`` (not
  ``rho_D g(theta_i)`` as the sentence after Eq. 13 says: the extra ``1/G`` comes from
  Eq. 13's ``G^2``).  Its cosine-weighted average over incidence directions is
  ``rho_D``, so ``rho_D`` is the bihemispherical diffuse reflectance, just as
  ``epsilon(lambda)`` is the hemispherical emissivity of Eq. 8.  The term is
  reciprocal (Eq. 12).
* **Eq. 17**, ``rho_s(lambda, theta_i) = 1 - rho_d(lambda, theta_i) - epsilon(lambda,
  theta_i) = 1 - (rho_D + epsilon) g(theta_i) / G(b)``, so that the diffuse plus
  specular reflectance is exactly ``1 - epsilon(lambda, theta_i)`` (Eq. 11).
  ``rho_s >= 0`` at every incidence (the worst case is normal incidence, where
  ``g = 1``) requires ``rho_D + epsilon <= G(b)``; this is the domain enforced by
  :func:`check_params`.  It implies ``rho_D + epsilon <= 1`` (``G <= 1``), which is
  only the incidence-averaged version of the same condition.
* **Eq. 18**, ``H(theta_i) = (1/4 pi) int h(alpha) dOmega_r`` over the reflection
  hemisphere.  The printed closed form equals this integral (checked by quadrature
  to 1e-12), so Eq. 15 integrates (``f_s cos(theta_r) dOmega_r``) to ``rho_s``
  exactly.  It is evaluated in the algebraically equivalent, cancellation-free form
  ``H = (S + A)^2 / (4 e^2 S)`` (``A >= 0``), ``H = 4 e^2 / (S (S - A)^2)`` (``A < 0``),
  with ``A = (1 - e^2) cos(theta_i)`` and ``S = sqrt(A^2 + 4 e^2)``, which is stable
  for needle lobes (``e -> 0``) and for ``e > 1``.
* **Eq. 21** with ``delta = b``, "normalised to 1.0 at theta = 80 deg", is read as
  the factor ``c(theta_r) = 1`` for ``theta_r <= 80 deg`` and
  ``c(theta_r) = d(theta_r) / d(80 deg)`` above, multiplying the *specular* term
  only (the diffuse term already falls to zero at grazing through ``g(theta_r)``).
  It is continuous at 80 deg, removes the ``1/cos(theta_r)`` divergence of Eq. 15,
  and makes ``f_s -> 0`` at the horizon (for ``b > 0``).  As in the paper, ``H`` is
  *not* renormalised ("very messy normalization integrals"), so with the cut-off the
  hemispherical integral is ``1 - epsilon(lambda, theta_i) - rho_s L(theta_i)``
  where ``L`` is the fraction of the lobe removed above 80 deg.  For the Table 4
  paints ``L`` is 0.3 % (AFGL-01) and 0.003 % (AFGL-10) at normal incidence,
  1.4 % and 0.015 % at 60 deg, 9 % and 2.6 % at 80 deg, and grows toward grazing.
  ``cutoff=False`` gives the uncut model, whose integral is exactly
  ``1 - epsilon(lambda, theta_i)``.

References
----------
Sandford, B. P., "Infrared reflectance properties of aircraft paints" (paper 001),
§2.1 (Eqs. 5–6) and §4 (Eqs. 7–21, Tables 3–4).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import special

from .. import geometry
from ..errors import ValidationError
from ._common import (
    _angles_to_vectors,
    _band_param,
    _cast_out,
    _check_names,
    _check_theta_i,
    _check_wavelength,
    _facet_frame,
    _render_grid,
    _sin2,
)

__all__ = [
    "PARAMS",
    "angular_g",
    "brdf",
    "brdf_angles",
    "check_params",
    "cutoff_factor",
    "diffuse_brdf",
    "diffuse_reflectance",
    "directional_emissivity",
    "directional_hemispherical_reflectance",
    "normalisation_G",
    "normalisation_H",
    "render_grid",
    "specular_brdf",
    "specular_reflectance",
    "structure_h",
    "total_reflectance",
]

#: Parameter names: diffuse reflectance rho_D [1] and emissivity epsilon [1]
#: (spectral), grazing parameter b [1] and lobe width e [1] (scalar or per band).
PARAMS: tuple[str, ...] = ("rho_D", "epsilon", "b", "e")

#: Domain of the lobe width e [1]: below 1e-12 the lobe is narrower than float64
#: unit vectors resolve (and h ~ e^-4 approaches the float64 range).
E_MIN = 1.0e-12
E_MAX = 1.0e6
B_MAX = 1.0e6
#: Polar angle where the grazing cut-off of Eq. 21 is normalised to 1 [degree].
CUTOFF_ANGLE = 80.0
_COS_CUT = float(np.cos(np.radians(CUTOFF_ANGLE)))
_TAN2_CUT = float(np.tan(np.radians(CUTOFF_ANGLE)) ** 2)
#: Floor on cos(theta_r) in the 1/cos(theta_r) of Eq. 15 (reached only for b = 0,
#: where the paper's specular term genuinely diverges at the horizon).
_COS_FLOOR = 1.0e-150
#: |1 - b^2| below which G(b) uses its power series.
_G_SERIES_RADIUS = 0.5
_G_SERIES_TERMS = 64
#: Gauss–Legendre orders of the cut-off-loss quadrature (azimuth, each polar piece).
_N_PHI = 96
_N_X = 48


# --------------------------------------------------------------------------
# angular functions (Eqs. 9, 10, 16, 18, 21)
# --------------------------------------------------------------------------


def _g_cs(cos2: np.ndarray, sin2: np.ndarray, b: np.ndarray | float) -> np.ndarray:
    """Eq. 9 as ``cos^2 / (cos^2 + b^2 sin^2)``, = 1 for b = 0, 0 at 90 deg for b > 0."""
    den = cos2 + (b * b) * sin2
    ok = den > 0
    return np.where(ok, cos2 / np.where(ok, den, 1.0), 1.0)


def angular_g(theta: ArrayLike, b: ArrayLike) -> NDArray[np.float64]:
    """Angular shape of emission and diffuse scatter, paper 001 Eq. 9.

    Parameters
    ----------
    theta : array_like
        Polar angle from the normal [degree], ``0 <= theta <= 90``.
    b : array_like
        Grazing-angle parameter [1], ``b >= 0``.

    Returns
    -------
    ndarray
        ``g = 1 / (1 + b^2 tan^2 theta)`` [1], evaluated as
        ``cos^2 / (cos^2 + b^2 sin^2)`` so that it is finite at 90 deg (0 for ``b > 0``,
        1 for ``b = 0``).
    """
    t = np.radians(np.asarray(theta, dtype=np.float64))
    return _g_cs(np.cos(t) ** 2, np.sin(t) ** 2, np.asarray(b, dtype=np.float64))


def normalisation_G(b: ArrayLike) -> NDArray[np.float64]:
    """Normalisation of the emissivity's angular distribution, paper 001 Eq. 10.

    Parameters
    ----------
    b : array_like
        Grazing-angle parameter [1], ``b >= 0``.

    Returns
    -------
    ndarray
        ``G(b) = (1/pi) int_hemisphere cos(theta) g(theta) dOmega`` [1]:
        ``(1/c) [1 + b^2 log(b^2) / c]`` with ``c = 1 - b^2`` (Eq. 10 as printed),
        and the convergent series ``sum_{n>=0} c^n / ((n+1)(n+2))`` for
        ``|c| < 0.5`` (removable singularity at ``b = 1``, ``G(1) = 1/2``).
        ``G(0) = 1`` exactly; ``G -> 0`` as ``b -> inf``.
    """
    b = np.asarray(b, dtype=np.float64)
    b2 = b * b
    c = (1.0 - b) * (1.0 + b)
    near = np.abs(c) < _G_SERIES_RADIUS
    c_safe = np.where(near, 1.0, c)
    closed = (1.0 + special.xlogy(b2, b2) / c_safe) / c_safe
    n = np.arange(_G_SERIES_TERMS)
    coef = 1.0 / ((n + 1.0) * (n + 2.0))
    c_ser = np.where(near, c, 0.0)
    series = np.zeros_like(c_ser)
    for a in coef[::-1]:  # Horner over series terms (not over samples)
        series = series * c_ser + a
    return np.where(near, series, closed)


def _h_cs(cos2a: np.ndarray, sin2a: np.ndarray, e: np.ndarray) -> np.ndarray:
    """Eq. 16 from cos^2 and sin^2 of alpha (sum of non-negative terms: no cancellation)."""
    return 1.0 / ((e * e) * cos2a + sin2a) ** 2


def structure_h(alpha: ArrayLike, e: ArrayLike) -> NDArray[np.float64]:
    """Trowbridge–Reitz surface structure function, paper 001 Eq. 16.

    Parameters
    ----------
    alpha : array_like
        Angle between the glint vector and the normal [degree] (Eq. 6).
    e : array_like
        Lobe width (ellipsoid eccentricity) [1], ``e > 0``.

    Returns
    -------
    ndarray
        ``h = 1 / (e^2 cos^2 alpha + sin^2 alpha)^2`` [1]; ``h(0) = e^-4``.
    """
    a = np.radians(np.asarray(alpha, dtype=np.float64))
    return _h_cs(np.cos(a) ** 2, np.sin(a) ** 2, np.asarray(e, dtype=np.float64))


def _e2_h_norm(cos_i: np.ndarray, e: np.ndarray | float) -> np.ndarray:
    """``e^2 H(theta_i)`` (Eq. 18) in its cancellation-free form."""
    a = (1.0 - e) * (1.0 + e) * cos_i
    s = np.hypot(a, 2.0 * e)
    # A >= 0: (S + A)^2 / (4 S);  A < 0: 4 e^4 / (S (S - A)^2)   (both times e^2 H).
    # Both branches are written with |A|, so neither denominator can vanish where the
    # other branch is selected (S - A -> 0 for needle lobes, e -> 0, with A > 0).  S = 0
    # only for e = 0 at grazing incidence, where the limit of e^2 H (= e) is 0.
    b = np.abs(a)
    e2 = e * e
    s_safe = np.where(s > 0, s, 1.0)
    sb2 = (s_safe + b) ** 2
    return np.where(
        s > 0, np.where(a >= 0, sb2 / (4.0 * s_safe), 4.0 * e2 * e2 / (s_safe * sb2)), 0.0
    )


def normalisation_H(theta_i: ArrayLike, e: ArrayLike) -> NDArray[np.float64]:
    """Normalisation of the specular lobe, paper 001 Eq. 18.

    Parameters
    ----------
    theta_i : array_like
        Incidence angle [degree], ``0 <= theta_i <= 90``.
    e : array_like
        Lobe width [1], ``e > 0``.

    Returns
    -------
    ndarray
        ``H = (1/4 pi) int_hemisphere h(alpha) dOmega_r`` [1] (Eq. 18), evaluated
        as ``(S + A)^2 / (4 e^2 S)`` for ``A >= 0`` and ``4 e^2 / (S (S - A)^2)`` for
        ``A < 0`` with ``A = (1 - e^2) cos(theta_i)``, ``S = sqrt(A^2 + 4 e^2)``:
        algebraically equal to the printed Eq. 18, without its cancellations.
        ``H(0) = 1 / (e^2 (1 + e^2))``, ``H = 1/2`` for ``e = 1``, ``H(90 deg) = 1/(2e)``.
    """
    ti = np.radians(np.asarray(theta_i, dtype=np.float64))
    e = np.asarray(e, dtype=np.float64)
    return _e2_h_norm(np.cos(ti), e) / (e * e)


def _cutoff_cs(cos_r: np.ndarray, sin2_r: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Eq. 21 cut-off ``c(theta_r)``, 1 up to 80 deg, d/d(80) above (0 at the horizon)."""
    d80_inv = 1.0 + (b * b) * _TAN2_CUT
    cos2 = cos_r * cos_r
    den = cos2 + (b * b) * sin2_r
    ok = den > 0
    d = np.where(ok, cos2 / np.where(ok, den, 1.0), 1.0)
    return np.where(cos_r >= _COS_CUT, 1.0, np.minimum(d * d80_inv, 1.0))


def _cutoff_over_cos(cos_r: np.ndarray, sin2_r: np.ndarray, b: np.ndarray | float) -> np.ndarray:
    """``c(theta_r) / cos(theta_r)`` without dividing by a vanishing cosine."""
    cr = np.maximum(cos_r, _COS_FLOOR)
    d80_inv = 1.0 + (b * b) * _TAN2_CUT
    beyond = cr * d80_inv / (cr * cr + (b * b) * sin2_r)
    return np.where(cr >= _COS_CUT, 1.0 / cr, np.minimum(beyond, 1.0 / cr))


def cutoff_factor(theta_r: ArrayLike, b: ArrayLike) -> NDArray[np.float64]:
    """Grazing cut-off of the specular term, paper 001 Eq. 21 with ``delta = b``.

    Parameters
    ----------
    theta_r : array_like
        Reflection polar angle [degree], ``0 <= theta_r <= 90``.
    b : array_like
        Grazing-angle parameter [1], ``b >= 0``.

    Returns
    -------
    ndarray
        ``1`` for ``theta_r <= 80 deg``; ``d(theta_r) / d(80 deg)`` above, where
        ``d = 1 / (1 + b^2 tan^2 theta)`` ("normalised to 1.0 at theta = 80 deg",
        read as a factor applied only above 80 deg so that it never amplifies).
    """
    t = np.radians(np.asarray(theta_r, dtype=np.float64))
    return _cutoff_cs(np.cos(t), np.sin(t) ** 2, np.asarray(b, dtype=np.float64))


# --------------------------------------------------------------------------
# parameters and directional quantities (Eqs. 8, 11, 17)
# --------------------------------------------------------------------------


def check_params(wavelength: ArrayLike, **params: Any) -> dict[str, NDArray[np.float64]]:
    """Validate R-S parameters and broadcast them to the wavelength grid.

    Parameters
    ----------
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    rho_D : array_like, scalar or shape (n_wl,)
        Diffuse spectral reflectance [1], ``rho_D >= 0``.
    epsilon : array_like, scalar or shape (n_wl,)
        Spectral hemispherical emissivity [1], ``0 <= epsilon <= 1``.
    b : array_like, scalar or shape (n_wl,)
        Grazing-angle parameter [1], ``0 <= b <= 1e6``.
    e : array_like, scalar or shape (n_wl,)
        Specular lobe width [1], ``1e-12 <= e <= 1e6``.

    Returns
    -------
    dict
        The four parameters as float64 arrays of shape ``(n_wl,)``.

    Raises
    ------
    ValidationError
        Missing/unexpected names, shapes not matching ``wavelength``, NaN, values
        outside the domains above, or ``rho_D + epsilon > G(b)`` (Eq. 17's
        ``rho_s`` would be negative at normal incidence; see the module notes).
    """
    wl = _check_wavelength(wavelength)
    _check_names(params, PARAMS, "robertson_sandford")
    n = wl.size
    out = {
        "rho_D": _band_param("rho_D", params["rho_D"], n, lower=0.0),
        "epsilon": _band_param("epsilon", params["epsilon"], n, lower=0.0, upper=1.0),
        "b": _band_param("b", params["b"], n, lower=0.0, upper=B_MAX),
        "e": _band_param("e", params["e"], n, lower=E_MIN, upper=E_MAX),
    }
    g_b = normalisation_G(out["b"])
    total = out["rho_D"] + out["epsilon"]
    bad = total > g_b * (1.0 + 1e-12)
    if np.any(bad):
        raise ValidationError(
            f"rho_D + epsilon: got {total[bad][:5].tolist()} with G(b) = "
            f"{g_b[bad][:5].tolist()}; allowed domain is rho_D + epsilon <= G(b) "
            "(<= 1 for b = 0) so that rho_s of Eq. 17 is >= 0 at every incidence [1]"
        )
    return out


def directional_emissivity(
    theta: ArrayLike, wavelength: ArrayLike, **params: Any
) -> NDArray[np.float64]:
    """Directional spectral emissivity, paper 001 Eq. 8.

    Parameters
    ----------
    theta : array_like
        Polar angle [degree], ``0 <= theta <= 90``.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    **params
        ``rho_D``, ``epsilon``, ``b``, ``e`` (see :func:`check_params`).

    Returns
    -------
    ndarray, shape theta.shape + (n_wl,)
        ``epsilon(lambda, theta) = epsilon(lambda) g(theta) / G(b)`` [1]; its
        cosine-weighted hemispherical mean is ``epsilon(lambda)``.
    """
    p = check_params(wavelength, **params)
    t = _check_theta_i(theta)[..., None]
    return p["epsilon"] * angular_g(t, p["b"]) / normalisation_G(p["b"])


def diffuse_reflectance(
    theta_i: ArrayLike, wavelength: ArrayLike, **params: Any
) -> NDArray[np.float64]:
    """Diffusely scattered fraction ``rho_d(lambda, theta_i)`` (integral of Eq. 13).

    Parameters
    ----------
    theta_i : array_like
        Incidence angle [degree], ``0 <= theta_i <= 90``.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    **params
        ``rho_D``, ``epsilon``, ``b``, ``e``.

    Returns
    -------
    ndarray, shape theta_i.shape + (n_wl,)
        ``rho_D g(theta_i) / G(b)`` [1]: the hemispherical integral of
        ``f_d cos(theta_r)`` of Eq. 13 (see the module notes on Eq. 13).
    """
    p = check_params(wavelength, **params)
    t = _check_theta_i(theta_i)[..., None]
    return p["rho_D"] * angular_g(t, p["b"]) / normalisation_G(p["b"])


def specular_reflectance(
    theta_i: ArrayLike, wavelength: ArrayLike, **params: Any
) -> NDArray[np.float64]:
    """Specularly reflected fraction ``rho_s(lambda, theta_i)``, paper 001 Eq. 17.

    Parameters
    ----------
    theta_i : array_like
        Incidence angle [degree], ``0 <= theta_i <= 90``.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    **params
        ``rho_D``, ``epsilon``, ``b``, ``e``.

    Returns
    -------
    ndarray, shape theta_i.shape + (n_wl,)
        ``1 - (rho_D + epsilon) g(theta_i) / G(b)`` [1], ``>= 0`` on the domain.
    """
    p = check_params(wavelength, **params)
    t = _check_theta_i(theta_i)[..., None]
    gi = angular_g(t, p["b"]) / normalisation_G(p["b"])
    return np.maximum(1.0 - (p["rho_D"] + p["epsilon"]) * gi, 0.0)


def total_reflectance(
    theta_i: ArrayLike, wavelength: ArrayLike, **params: Any
) -> NDArray[np.float64]:
    """Total (directional-hemispherical) reflectance without cut-off, paper 001 Eq. 11.

    Parameters
    ----------
    theta_i : array_like
        Incidence angle [degree], ``0 <= theta_i <= 90``.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    **params
        ``rho_D``, ``epsilon``, ``b``, ``e``.

    Returns
    -------
    ndarray, shape theta_i.shape + (n_wl,)
        ``rho_s + rho_d = 1 - epsilon(lambda, theta_i)`` [1] (paper 001 Fig. 9).
    """
    return 1.0 - directional_emissivity(theta_i, wavelength, **params)


# --------------------------------------------------------------------------
# the BRDF (Eqs. 13, 15)
# --------------------------------------------------------------------------


def _terms(
    n: np.ndarray,
    s: np.ndarray,
    o: np.ndarray,
    cos_i: np.ndarray,
    cos_r: np.ndarray,
    p: dict[str, np.ndarray],
    cutoff: bool,
) -> tuple[np.ndarray, np.ndarray]:
    """Diffuse and specular BRDF [sr-1] (…, n_wl) for unit vectors (no masking)."""
    b, e = p["b"], p["e"]
    cos_i = np.clip(cos_i, 0.0, 1.0)[..., None]
    cos_r_c = np.clip(cos_r, 0.0, 1.0)[..., None]
    sin2_i = _sin2(n, s)[..., None]
    sin2_r = _sin2(n, o)[..., None]
    g_norm = normalisation_G(b)
    gi = _g_cs(cos_i**2, sin2_i, b)
    gr = _g_cs(cos_r_c**2, sin2_r, b)
    f_d = p["rho_D"] * gi * gr / (np.pi * g_norm**2)  # Eq. 13

    glint = geometry.half_vector(s, o)  # Eq. 5
    cos_a = np.einsum("...k,...k->...", glint, n)[..., None]  # Eq. 6
    sin2_a = _sin2(n, glint)[..., None]
    # h / H with h from Eq. 16 and e^2 H from Eq. 18: h/H = e^2 / ((e^2 cos^2 + sin^2)^2 e^2 H)
    e2 = e * e
    h_over_h = e2 / ((e2 * cos_a**2 + sin2_a) ** 2 * _e2_h_norm(cos_i, e))
    rho_s = np.maximum(1.0 - (p["rho_D"] + p["epsilon"]) * gi / g_norm, 0.0)  # Eq. 17
    if cutoff:
        geom = _cutoff_over_cos(cos_r_c, sin2_r, b)  # Eq. 21 / cos(theta_r)
    else:
        geom = 1.0 / np.maximum(cos_r_c, _COS_FLOOR)
    f_s = rho_s / (4.0 * np.pi) * h_over_h * geom  # Eq. 15
    return f_d, f_s


def _evaluate(
    normal: ArrayLike,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    wavelength: ArrayLike,
    params: dict[str, Any],
    cutoff: bool,
    which: str,
) -> np.ndarray:
    p = check_params(wavelength, **params)
    n, s, o, cos_i, cos_r, mask, dtype = _facet_frame(normal, to_sun, to_observer)
    f_d, f_s = _terms(n, s, o, cos_i, cos_r, p, cutoff)
    f = {"diffuse": f_d, "specular": f_s, "total": f_d + f_s}[which]
    return _cast_out(np.where(mask[..., None], f, 0.0), dtype)


def diffuse_brdf(
    normal: ArrayLike,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    wavelength: ArrayLike,
    **params: Any,
) -> np.ndarray:
    """Diffuse R-S BRDF, paper 001 Eq. 13 (reciprocal, Eq. 12).

    Parameters
    ----------
    normal, to_sun, to_observer : array_like, shape (..., 3)
        Facet normal and directions to the source and observer [1].
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    **params
        ``rho_D``, ``epsilon``, ``b``, ``e`` (see :func:`check_params`).

    Returns
    -------
    ndarray, shape broadcast(...) + (n_wl,)
        ``f_d = rho_D g(theta_i) g(theta_r) / (pi G(b)^2)`` [sr-1]; zero where unlit
        or unseen.
    """
    return _evaluate(normal, to_sun, to_observer, wavelength, params, True, "diffuse")


def specular_brdf(
    normal: ArrayLike,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    wavelength: ArrayLike,
    *,
    cutoff: bool = True,
    **params: Any,
) -> np.ndarray:
    """Specular R-S BRDF, paper 001 Eqs. 15–18 with the cut-off of Eq. 21.

    Parameters
    ----------
    normal, to_sun, to_observer : array_like, shape (..., 3)
        Facet normal and directions to the source and observer [1].
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    cutoff : bool, default True
        Apply the grazing cut-off (Eq. 21, module notes).
    **params
        ``rho_D``, ``epsilon``, ``b``, ``e``.

    Returns
    -------
    ndarray, shape broadcast(...) + (n_wl,)
        ``f_s = rho_s(lambda, theta_i) h(alpha) c(theta_r) / (4 pi H(theta_i)
        cos(theta_r))`` [sr-1], with the glint vector of Eq. 5
        (:func:`sbrdf_xr.geometry.half_vector`, defined at phase angle 180 deg).  For
        ``b = 0`` (no cut-off) ``cos(theta_r)`` is floored at 1e-150, the only
        departure from Eq. 15, to keep the divergence at the horizon finite.
    """
    return _evaluate(normal, to_sun, to_observer, wavelength, params, cutoff, "specular")


def brdf(
    normal: ArrayLike,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    wavelength: ArrayLike,
    *,
    cutoff: bool = True,
    **params: Any,
) -> np.ndarray:
    """Robertson–Sandford spectral BRDF ``f_d + f_s`` (paper 001 Eqs. 13 and 15).

    Parameters
    ----------
    normal, to_sun, to_observer : array_like, shape (..., 3)
        Facet normal and directions to the source and observer [1]; need not be
        unit length; broadcast against each other.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    cutoff : bool, default True
        Apply the grazing cut-off of Eq. 21 to the specular term.
    rho_D, epsilon : array_like, scalar or shape (n_wl,)
        Diffuse reflectance and hemispherical emissivity [1].
    b, e : array_like, scalar or shape (n_wl,)
        Grazing-angle parameter and specular lobe width [1].

    Returns
    -------
    ndarray, shape broadcast(...) + (n_wl,)
        BRDF [sr-1]; exactly zero where ``N.s <= 0`` or ``N.o <= 0``.  Integrated
        over the hemisphere (``f_r cos(theta_r) dOmega_r``) it gives
        ``1 - epsilon(lambda, theta_i)`` (Eq. 11) without the cut-off, and
        :func:`directional_hemispherical_reflectance` with it.
    """
    return _evaluate(normal, to_sun, to_observer, wavelength, params, cutoff, "total")


def brdf_angles(
    theta_i: ArrayLike,
    delta_theta: ArrayLike,
    phi: ArrayLike,
    wavelength: ArrayLike,
    *,
    cutoff: bool = True,
    **params: Any,
) -> np.ndarray:
    """R-S BRDF from the paper-000 angles (see :func:`brdf`).

    Parameters
    ----------
    theta_i, delta_theta, phi : array_like
        Paper-000 Fig. 4 angles [degree]; broadcast against each other.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    cutoff : bool, default True
        Apply the grazing cut-off of Eq. 21.
    **params
        ``rho_D``, ``epsilon``, ``b``, ``e``.

    Returns
    -------
    ndarray, shape broadcast(...) + (n_wl,)
        BRDF [sr-1].
    """
    vecs = _angles_to_vectors(theta_i, delta_theta, phi)
    return brdf(*vecs, wavelength, cutoff=cutoff, **params)


def render_grid(
    theta_i: ArrayLike,
    delta_theta: ArrayLike,
    phi: ArrayLike,
    wavelength: ArrayLike,
    *,
    cutoff: bool = True,
    **params: Any,
) -> np.ndarray:
    """R-S BRDF on the outer product of 1-D paper-000 angle grids.

    Parameters
    ----------
    theta_i, delta_theta, phi : array_like, 1-D
        Angle grids [degree].
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    cutoff : bool, default True
        Apply the grazing cut-off of Eq. 21.
    **params
        ``rho_D``, ``epsilon``, ``b``, ``e``.

    Returns
    -------
    ndarray, shape (n_ti, n_dt, n_phi, n_wl)
        BRDF [sr-1].
    """
    return _render_grid(brdf_angles, theta_i, delta_theta, phi, wavelength, cutoff=cutoff, **params)


# --------------------------------------------------------------------------
# hemispherical reflectance with the cut-off (quadrature)
# --------------------------------------------------------------------------


def _cutoff_loss(cos_i: np.ndarray, b: np.ndarray, e: np.ndarray) -> np.ndarray:
    """Fraction ``L`` of the specular lobe removed by the Eq. 21 cut-off.

    ``L = (1/4 pi H) int h(alpha) (1 - c(theta_r)) dOmega_r`` over the band
    ``80 deg < theta_r < 90 deg``.  Written in half-vector coordinates
    ``(phi_h, x)`` with ``tan(alpha) = e tan(x)`` (centred on the glint direction,
    so needle lobes are resolved), ``e^2 H L = (2/pi) int_0^pi dphi int dx
    [sin x cos x cos(theta_i) + e sin^2 x cos(phi) sin(theta_i)] (1 - c)``.  The
    x-range where ``theta_r > 80 deg`` is found in closed form
    (``cos(theta_r) = R cos(2 alpha - beta)``), so each Gauss–Legendre piece has a
    smooth integrand.  Inputs broadcast; returns their broadcast shape.
    """
    cos_i, b, e = np.broadcast_arrays(*(np.asarray(a, dtype=np.float64) for a in (cos_i, b, e)))
    sin_i = np.sqrt(np.maximum(1.0 - cos_i**2, 0.0))
    tp, wp = np.polynomial.legendre.leggauss(_N_PHI)
    phi = 0.5 * np.pi * (tp + 1.0)
    w_phi = 0.5 * np.pi * wp
    tx, wx = np.polynomial.legendre.leggauss(_N_X)
    tx, wx = 0.5 * (tx + 1.0), 0.5 * wx  # on [0, 1]

    ci = cos_i[..., None]
    si = sin_i[..., None]
    bb = b[..., None, None]
    ee = e[..., None]
    cphi = np.cos(phi)
    bprime = cphi * si  # cos(theta_r) = A' cos 2a + B' sin 2a
    r = np.hypot(ci, bprime)
    beta = np.arctan2(bprime, ci)
    gamma = np.arccos(np.clip(_COS_CUT / np.maximum(r, 1e-300), -1.0, 1.0))
    a_max = 0.5 * (beta + 0.5 * np.pi)
    a1 = np.clip(0.5 * (beta - gamma), 0.0, a_max)
    a2 = np.clip(0.5 * (beta + gamma), 0.0, a_max)

    def x_of(alpha: np.ndarray) -> np.ndarray:
        return np.arctan2(np.tan(alpha), ee)

    total = np.zeros(cos_i.shape)
    for lo, hi in ((np.zeros_like(a1), a1), (a2, a_max)):  # the two pieces of the band
        x_lo, x_hi = x_of(lo), x_of(hi)
        x = x_lo[..., None] + (x_hi - x_lo)[..., None] * tx
        alpha = np.arctan(ee[..., None] * np.tan(x))
        cos_r = ci[..., None] * np.cos(2 * alpha) + bprime[..., None] * np.sin(2 * alpha)
        cos_r = np.clip(cos_r, 0.0, 1.0)
        cut = _cutoff_cs(cos_r, 1.0 - cos_r**2, bb)
        f = (
            np.sin(x) * np.cos(x) * ci[..., None]
            + ee[..., None] * np.sin(x) ** 2 * (cphi * si)[..., None]
        ) * (1.0 - cut)
        inner = np.einsum("...px,x->...p", f, wx) * (x_hi - x_lo)
        total = total + np.einsum("...p,p->...", inner, w_phi)
    loss = (2.0 / np.pi) * total / _e2_h_norm(cos_i, e)
    return np.clip(loss, 0.0, 1.0)


def directional_hemispherical_reflectance(
    theta_i: ArrayLike,
    wavelength: ArrayLike,
    *,
    cutoff: bool = True,
    **params: Any,
) -> NDArray[np.float64]:
    """Directional-hemispherical reflectance of the R-S model.

    Parameters
    ----------
    theta_i : array_like
        Incidence angle [degree], ``0 <= theta_i <= 90``.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    cutoff : bool, default True
        Include the grazing cut-off of Eq. 21 (as :func:`brdf` does).
    **params
        ``rho_D``, ``epsilon``, ``b``, ``e``.

    Returns
    -------
    ndarray, shape theta_i.shape + (n_wl,)
        Without the cut-off, the closed form of Eq. 11, ``1 - epsilon(lambda,
        theta_i)``.  With it, ``rho_d + rho_s (1 - L(theta_i))`` where the lost
        fraction ``L`` is computed by Gauss–Legendre quadrature in glint-centred
        coordinates (relative accuracy ~1e-9 below 80 deg incidence, ~1e-5 above,
        where the band boundary has a square-root singularity in azimuth).
    """
    p = check_params(wavelength, **params)
    ti = _check_theta_i(theta_i)
    rho_d = p["rho_D"] * angular_g(ti[..., None], p["b"]) / normalisation_G(p["b"])
    eps = p["epsilon"] * angular_g(ti[..., None], p["b"]) / normalisation_G(p["b"])
    rho_s = np.maximum(1.0 - rho_d - eps, 0.0)
    if not cutoff:
        return rho_d + rho_s
    # The loss depends on (theta_i, b, e) only: evaluate on the distinct (b, e) pairs.
    pairs, inverse = np.unique(np.stack([p["b"], p["e"]], axis=-1), axis=0, return_inverse=True)
    cos_flat = np.cos(np.radians(ti.ravel()))
    loss_pairs = np.empty((cos_flat.size, pairs.shape[0]))
    chunk = max(1, 256 // max(1, pairs.shape[0]))
    for start in range(0, cos_flat.size, chunk):  # memory bound, not a per-sample loop
        c = cos_flat[start : start + chunk, None]
        loss_pairs[start : start + chunk] = _cutoff_loss(c, pairs[:, 0], pairs[:, 1])
    loss = loss_pairs[:, inverse.ravel()].reshape((*ti.shape, p["b"].size))
    # b = 0: no cut-off at all (d == 1).
    loss = np.where(p["b"] > 0, loss, 0.0)
    return rho_d + rho_s * (1.0 - loss)
