r"""Robertson–Sandford body, Beckmann specular core and a Harvey–Shack ABg halo.

``f_r = s(theta_i) (f_RS + f_core + A / (B + |beta - beta_0|^g))``

* ``f_RS + f_core``: :mod:`sbrdf_xr.brdf.specular_core` (the Robertson–Sandford body,
  paper 001 Eqs. 13 and 15, and a Beckmann core of reflectance ``core_rho cos
  theta_i``, Walter et al. 2007 Eqs. 20, 25, 27).
* The halo: the ABg scatter model (Harvey 1976; Pfisterer 2011), the standard
  stray-light model of the scatter between a specular beam and the diffuse body.
  ``beta`` is the projection on the surface of the direction to the observer and
  ``beta_0`` that of the mirror direction (direction cosines), so that ``|beta -
  beta_0| = |(s + o) - N (N.(s + o))|``, the length of the tangential part of ``s +
  o``; ``A`` (``halo_a`` [sr-1]) sets the level, ``B`` (``halo_b`` [1]) the flat top
  (the halo turns over at ``|beta - beta_0| ~ B^(1/g)``) and ``g`` (``halo_g`` [1])
  the power law of the wings.  Harvey's observation, the basis of the model, is
  that a polished surface's scatter is shift-invariant in direction-cosine space: the
  same function of ``|beta - beta_0|`` at every incidence angle.  It is reciprocal
  (symmetric in ``s`` and ``o``) and isotropic about the mirror direction.  Measured
  in-plane scans of a near-mirror show such a halo: the Starlink chassis' scans (532
  nm) fall from the core to the body over two to four degrees as a power of the angle
  from specular (about the 2.5th power at 60 deg incidence, and the halo at 5 and 60
  deg follows one such power law once the angle is measured in direction cosines,
  ``cos theta_r`` times the angle), where a Gaussian core as wide as the measured peak
  falls a factor 3 below the samples at two degrees and orders of magnitude at three.
* Energy (:func:`energy_scale`): the model is scaled at each incidence angle by
  ``s = min(1, 1 / (1 - epsilon(theta_i) + core_rho cos theta_i + H(theta_i)))``,
  ``H`` a bound of the halo's directional-hemispherical reflectance: the halo over the
  disc of radius ``1 + sin theta_i`` about ``beta_0``, which holds the unit disc of
  visible directions, ``H = 2 pi A I(1 + sin theta_i)`` with ``I(R) = int_0^R r dr /
  (B + r^g) = R^2 / (2 B) 2F1(1, 2/g; 1 + 2/g; -R^g / B)``.  The model's
  directional-hemispherical reflectance is then at most one at every incidence angle
  (the bound is exact at normal incidence and a few per cent high towards grazing).

The halo's own reflectance (:func:`halo_reflectance`) integrates ``A / (B + r^g)``
over the unit disc of direction cosines (``cos theta_o d omega_o = d beta``): in polar
coordinates about ``beta_0``, ``A int I(R(psi)) d psi`` with ``R(psi) = -sin theta_i
cos psi + sqrt(1 - sin^2 theta_i sin^2 psi)`` the distance to the disc's edge, by the
trapezoid rule in ``psi`` (periodic and smooth: 512 points reach rounding).

References
----------
Harvey, J. E., *Light-scattering characteristics of optical surfaces*, PhD thesis,
University of Arizona, 1976 (shift invariance in direction cosines).
Pfisterer, R. N., "Approximated scatter models for stray light analysis", Optics &
Photonics News 22(10), 2011 (the ABg model and its fits).
Walter, B., Marschner, S. R., Li, H., Torrance, K. E., EGSR 2007, Eqs. 20, 25, 27.
Sandford, paper 001 §4 (Eqs. 8, 11, 13, 15).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares
from scipy.special import hyp2f1

from ..units import to_unit
from . import specular_core as sc
from ._common import _angles_to_vectors, _cast_out, _check_theta_i, _facet_frame
from ._model import Model, Parameter

__all__ = [
    "MODEL",
    "PARAMS",
    "brdf",
    "brdf_angles",
    "check_params",
    "directional_hemispherical_reflectance",
    "energy_scale",
    "fit_halo",
    "halo_brdf",
    "halo_reflectance",
    "render_grid",
]

#: The parameters: the Robertson-Sandford and core ones, then the halo's.
PARAMETERS = (
    *sc.PARAMETERS,
    Parameter("halo_a", "sr-1", "ABg halo level A", lower=0.0),
    Parameter("halo_b", "1", "ABg halo flat top B", lower=0.0, lower_open=True, spectral=False),
    Parameter("halo_g", "1", "ABg halo power g", lower=0.1, upper=6.0, spectral=False),
)
_HALO = ("halo_a", "halo_b", "halo_g")
#: Points of the trapezoid rule in azimuth about the mirror direction (halo_reflectance).
_N_PSI = 512


def halo_brdf(
    normal: ArrayLike,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    halo_a: ArrayLike,
    halo_b: ArrayLike,
    halo_g: ArrayLike,
) -> np.ndarray:
    """The ABg halo alone, ``A / (B + |beta - beta_0|^g)`` [sr-1] (Harvey 1976).

    Parameters
    ----------
    normal, to_sun, to_observer : array_like, shape (..., 3)
        Facet normal and directions to the source and observer [1]; broadcast.
    halo_a : array_like, shape (n_wl,)
        Level ``A`` [sr-1].
    halo_b, halo_g : array_like, shape (n_wl,)
        Flat top ``B`` [1] and power ``g`` [1] (validated by the caller).

    Returns
    -------
    ndarray, shape broadcast(...) + (n_wl,)
        [sr-1], float64; zero where unlit or unseen.

    Examples
    --------
    At the mirror direction the halo is ``A / B``:

    >>> s, o = [0.5, 0.0, 0.866], [-0.5, 0.0, 0.866]
    >>> float(halo_brdf([0.0, 0.0, 1.0], s, o, [2e-3], [1e-6], [2.5])[0])
    2000.0
    """
    halo_a = to_unit(halo_a, "sr-1", "halo_a")
    n, s, o, _, _, mask, _ = _facet_frame(normal, to_sun, to_observer)
    t = s + o
    tt = t - n * np.einsum("...k,...k->...", n, t)[..., None]
    d = np.sqrt(np.einsum("...k,...k->...", tt, tt))[..., None]
    a, b, g = (np.asarray(x, dtype=np.float64) for x in (halo_a, halo_b, halo_g))
    return np.where(mask[..., None], a / (b + d**g), 0.0)


def _radial(r: ArrayLike, b: ArrayLike, g: ArrayLike) -> NDArray[np.float64]:
    """``I(R) = int_0^R r dr / (B + r^g) = R^2 / (2 B) 2F1(1, 2/g; 1 + 2/g; -R^g / B)``."""
    r, b, g = (np.asarray(x, dtype=np.float64) for x in (r, b, g))
    c = 2.0 / g
    return np.asarray(r**2 / (2.0 * b) * hyp2f1(1.0, c, 1.0 + c, -(r**g) / b), dtype=np.float64)


def _halo_bound(ti: np.ndarray, p: Any) -> NDArray[np.float64]:
    """``H = 2 pi A I(1 + sin theta_i)`` [1], ``ti.shape + (n_wl,)``: at least the halo's
    reflectance (module docstring)."""
    r = 1.0 + np.sin(np.radians(ti))[..., None]
    return 2.0 * np.pi * p["halo_a"] * _radial(r, p["halo_b"], p["halo_g"])


def halo_reflectance(
    theta_i: ArrayLike, halo_a: ArrayLike, halo_b: ArrayLike, halo_g: ArrayLike
) -> NDArray[np.float64]:
    """The halo's directional-hemispherical reflectance, ``A int I(R(psi)) d psi`` [1].

    Parameters
    ----------
    theta_i : array_like
        Incidence angles [degree], ``0 <= theta_i <= 90``.
    halo_a : array_like, shape (n_wl,)
        Level ``A`` [sr-1].
    halo_b, halo_g : array_like, shape (n_wl,)
        Flat top ``B`` [1] and power ``g`` [1].

    Returns
    -------
    ndarray, shape theta_i.shape + (n_wl,)
        [1].

    Examples
    --------
    A flat halo (``g`` small against ``B = 1``) is Lambertian: ``pi A / (1 + 1)``:

    >>> np.round(halo_reflectance([0.0, 60.0], [2.0], [1.0], [1e-9]), 6).tolist()
    [[3.141593], [3.141593]]
    """
    ti = np.radians(_check_theta_i(theta_i))[..., None, None]
    halo_a = to_unit(halo_a, "sr-1", "halo_a")
    a, b, g = (np.atleast_1d(np.asarray(x, dtype=np.float64)) for x in (halo_a, halo_b, halo_g))
    psi = np.arange(_N_PSI) * (2.0 * np.pi / _N_PSI)
    sb = np.sin(ti)
    root = np.sqrt(np.maximum(1.0 - (sb * np.sin(psi)[:, None]) ** 2, 0.0))
    edge = np.maximum(root - sb * np.cos(psi)[:, None], 0.0)  # 0 at grazing, forward
    return a * _radial(edge, b, g).mean(axis=-2) * 2.0 * np.pi


def brdf(
    normal: ArrayLike,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    wavelength: ArrayLike,
    **params: Any,
) -> np.ndarray:
    """Robertson–Sandford body, Beckmann core and ABg halo (module docstring; Harvey
    1976; Walter et al. 2007 Eqs. 20, 25, 27; paper 001 Eqs. 13 and 15).

    Parameters
    ----------
    normal, to_sun, to_observer : array_like, shape (..., 3)
        Facet normal and directions to the source and observer [1]; broadcast.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    rho_D, epsilon, b, e, core_rho, core_roughness : array_like
        As :func:`sbrdf_xr.brdf.specular_core.brdf` (all [1]).
    halo_a : array_like, scalar or shape (n_wl,)
        The halo's level ``A`` [sr-1].
    halo_b, halo_g : float
        Its flat top ``B`` [1] and power ``g`` [1].

    Returns
    -------
    ndarray, shape broadcast(...) + (n_wl,)
        BRDF [sr-1]; zero where ``N.s <= 0`` or ``N.o <= 0``.

    Examples
    --------
    With ``halo_a = 0`` it is the model with a specular core:

    >>> from sbrdf_xr.brdf import robertson_sandford as rs, specular_core as sc
    >>> n, s, o = [0.0, 0.0, 1.0], [0.5, 0.0, 1.0], [-0.5, 0.0, 1.0]
    >>> p = dict(rs.TABLE4["AFGL-01"], core_rho=0.1, core_roughness=0.01)
    >>> bool(np.allclose(brdf(n, s, o, [4000.0], halo_a=0.0, halo_b=1e-6, halo_g=2.5, **p),
    ...                  sc.brdf(n, s, o, [4000.0], **p)))
    True
    """
    p = MODEL.check_params(wavelength, **params)
    out, ti, dtype = sc._unscaled(normal, to_sun, to_observer, wavelength, p)
    out = out + halo_brdf(normal, to_sun, to_observer, *(p[k] for k in _HALO))
    return _cast_out(out * _scale(ti, wavelength, p), dtype)


def _scale(ti: np.ndarray, wavelength: ArrayLike, p: Any) -> NDArray[np.float64]:
    return 1.0 / np.maximum(sc._most(ti, wavelength, p) + _halo_bound(ti, p), 1.0)


def energy_scale(theta_i: ArrayLike, wavelength: ArrayLike, **params: Any) -> NDArray[np.float64]:
    """The factor ``min(1, 1 / (1 - epsilon(theta_i) + core_rho cos theta_i +
    H(theta_i)))`` by which the model is scaled at incidence ``theta_i`` (module
    docstring; paper 001 Eqs. 8 and 11; :func:`sbrdf_xr.brdf.specular_core.energy_scale`
    with the halo's bound ``H``).

    Parameters
    ----------
    theta_i : array_like
        Incidence angles [degree], ``0 <= theta_i <= 90``.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    **params
        As :func:`brdf`.

    Returns
    -------
    ndarray, shape theta_i.shape + (n_wl,)
        [1], in ``(0, 1]``.

    Examples
    --------
    >>> p = dict(rho_D=0.05, epsilon=0.5, b=0.0, e=0.3, core_rho=0.4, core_roughness=0.01,
    ...          halo_a=1e-3, halo_b=1e-6, halo_g=2.5)
    >>> np.round(energy_scale([0.0, 60.0], [532.0], **p), 4).tolist()
    [[0.9088], [1.0]]
    """
    p = MODEL.check_params(wavelength, **params)
    return _scale(_check_theta_i(theta_i), wavelength, p)


def directional_hemispherical_reflectance(
    theta_i: ArrayLike, wavelength: ArrayLike, **params: Any
) -> NDArray[np.float64]:
    """The body's, the core's (:func:`sbrdf_xr.brdf.specular_core.core_loss`) and the
    halo's (:func:`halo_reflectance`) reflectances, times :func:`energy_scale`: at
    most one (paper 001 Eq. 11).

    Parameters
    ----------
    theta_i : array_like
        Incidence angle [degree], ``0 <= theta_i <= 90``.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    **params
        As :func:`brdf`.

    Returns
    -------
    ndarray, shape theta_i.shape + (n_wl,)
        [1].

    Examples
    --------
    Scaled to one at normal incidence (where the halo's bound is its reflectance):

    >>> p = dict(rho_D=0.05, epsilon=0.5, b=0.0, e=0.3, core_rho=0.4, core_roughness=0.01,
    ...          halo_a=1e-3, halo_b=1e-6, halo_g=2.5)
    >>> np.round(directional_hemispherical_reflectance([0.0, 60.0], [532.0], **p), 4).tolist()
    [[1.0], [0.8929]]
    """
    p = MODEL.check_params(wavelength, **params)
    ti = _check_theta_i(theta_i)
    halo = halo_reflectance(ti, *(p[k] for k in _HALO))
    return (sc._unscaled_reflectance(ti, wavelength, p) + halo) * _scale(ti, wavelength, p)


def fit_halo(
    theta_i: ArrayLike,
    delta_theta: ArrayLike,
    phi: ArrayLike,
    spectra: ArrayLike,
    body: ArrayLike,
    core: dict[str, Any],
    reference: ArrayLike | None = None,
) -> dict[str, Any]:
    """Fit the core and the halo together beside a known body (log least squares).

    Fits ``body + core + halo`` to the samples above zero and not reference points,
    in the logarithm (the relative error, the measure of the table's leave-out
    check): the core's ``core_roughness`` and ``core_rho`` per wavelength (reflectance
    ``core_rho cos theta_i``), the halo's ``halo_a`` per wavelength, ``halo_b`` and
    ``halo_g``, and each incidence angle's offset along ``delta_theta`` (within +-1
    degree, the core and the halo moving together: a goniometer's zero or the
    sample's tilt).  Starts from a fit of the core alone (``core``,
    :func:`sbrdf_xr.brdf.specular_core.fit_core`) and three halo powers (1.5, 2.5,
    3.5), the best kept.

    Parameters
    ----------
    theta_i, delta_theta, phi : array_like, shape (s,)
        Sample angles [degree].
    spectra : array_like, shape (s, n_wl)
        The samples [sr-1].
    body : array_like, shape (s, n_wl)
        The body's BRDF at the samples [sr-1].
    core : dict
        :func:`~sbrdf_xr.brdf.specular_core.fit_core`'s result (the start).
    reference : array_like of bool, shape (s,), optional
        Reference points (left out).

    Returns
    -------
    dict
        ``core_rho`` [1], ``core_roughness`` [1], ``halo_a`` [sr-1], ``halo_b`` [1],
        ``halo_g`` [1], ``core_offset`` [degree], ``rms_log`` [1] and ``n_used``.

    Examples
    --------
    A halo of power 2.5 beside a flat body is recovered from an in-plane scan:

    >>> from sbrdf_xr.geometry import facet_vectors
    >>> t, d = np.full(81, 30.0), np.linspace(-8.0, 8.0, 81)
    >>> n, s, o = facet_vectors(t, d, np.zeros(81))
    >>> y = 0.1 + halo_brdf(n, s, o, [1e-3], [1e-5], [2.5])
    >>> start = dict(core_rho=[1e-6], core_roughness=0.003, core_offset=[0.0])
    >>> fit = fit_halo(t, d, np.zeros(81), y, np.full((81, 1), 0.1), start)
    >>> round(float(fit["halo_g"]), 4), np.round(fit["halo_a"] * 1e3, 4).tolist()
    (2.5, [1.0])
    """
    y = np.asarray(to_unit(spectra, "sr-1", "spectra"), dtype=np.float64)
    base = np.asarray(to_unit(body, "sr-1", "body"), dtype=np.float64)
    ok = np.all(y > 0, axis=1) & np.all(base > 0, axis=1)
    if reference is not None:
        ok &= ~np.asarray(reference, dtype=bool)
    ti, dt, ph = (np.asarray(to_unit(a, "deg", k), dtype=np.float64)[ok] for k, a in
                  (("theta_i", theta_i), ("delta_theta", delta_theta), ("phi", phi)))  # fmt: skip
    y, base = y[ok], base[ok]
    _, scan = np.unique(ti, return_inverse=True)
    law = np.cos(np.radians(ti))[:, None]
    n_wl = y.shape[1]

    def unpack(x: np.ndarray) -> tuple[np.ndarray, ...]:
        m, rho, a = np.exp(x[0]), np.exp(x[1 : 1 + n_wl]), np.exp(x[1 + n_wl : 1 + 2 * n_wl])
        return m, rho, a, np.exp(x[1 + 2 * n_wl]), x[2 + 2 * n_wl], x[3 + 2 * n_wl :]

    def model(x: np.ndarray) -> np.ndarray:
        m, rho, a, b, g, off = unpack(x)
        n, s, o = _angles_to_vectors(ti, dt - off[scan], ph)
        core_v = sc.core_brdf(n, s, o, rho * law, np.full(n_wl, m))
        return base + core_v + halo_brdf(n, s, o, a, np.full(n_wl, b), np.full(n_wl, g))

    def residuals(x: np.ndarray) -> np.ndarray:
        return (np.log(model(x)) - np.log(y)).ravel()

    off0 = np.asarray(core["core_offset"], dtype=np.float64)
    rho0 = np.clip(np.asarray(core["core_rho"], dtype=np.float64), 1e-8, 1.0)
    m0 = float(np.clip(core["core_roughness"], 1e-4, 0.5))
    lo = np.concatenate([[np.log(1e-4)], np.full(n_wl, np.log(1e-8)), np.full(n_wl, -40.0),
                         [-40.0, 0.5], np.full(off0.size, -1.0)])  # fmt: skip
    hi = np.concatenate([[np.log(0.5)], np.zeros(n_wl), np.full(n_wl, np.log(1e3)),
                         [0.0, 4.0], np.full(off0.size, 1.0)])  # fmt: skip
    best = None
    for g0 in (1.5, 2.5, 3.5):
        # start: the halo a tenth of the body at 0.05 in direction cosines (~3 degrees),
        # turning over at 0.005
        b0 = 0.005**g0
        a0 = np.clip(0.1 * np.median(base, axis=0) * 0.05**g0, 1e-17, 1e2)
        x0 = np.concatenate([[np.log(m0)], np.log(rho0), np.log(a0), [np.log(b0), g0], off0])
        res = least_squares(residuals, np.clip(x0, lo, hi), bounds=(lo, hi), **sc._TOLERANCES)
        if best is None or res.cost < best.cost:
            best = res
    assert best is not None
    m, rho, a, b, g, off = unpack(best.x)
    return {
        "core_rho": rho,
        "core_roughness": float(m),
        "halo_a": a,
        "halo_b": float(b),
        "halo_g": float(g),
        "core_offset": off.copy(),
        "rms_log": float(np.sqrt(np.mean(best.fun**2))),
        "n_used": int(y.size),
    }


#: The Robertson-Sandford model with a specular core and an ABg halo.
MODEL = Model(
    name="robertson_sandford_halo",
    long_name="Robertson-Sandford body, Beckmann specular core and ABg halo",
    brdf=brdf,
    parameters=PARAMETERS,
    citation="Harvey, PhD thesis 1976 (ABg); Pfisterer, OPN 2011; Sandford, paper 001 "
    "section 4 (Eqs. 13, 15); Walter et al., EGSR 2007, Eqs. 20, 25, 27",
    reflectance=directional_hemispherical_reflectance,
    constraint=sc.MODEL.constraint,  # the Robertson-Sandford part's (rho_s >= 0)
)
PARAMS = MODEL.param_names
check_params, brdf_angles, render_grid = MODEL.check_params, MODEL.brdf_angles, MODEL.render_grid
