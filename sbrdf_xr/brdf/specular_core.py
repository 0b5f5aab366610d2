r"""Robertson–Sandford plus a narrow specular core: a near-mirror's glint on a paint-like body.

``f_r = f_RS + rho_c D(h) G1(s) G1(o) / (4 |N.s| |N.o|)``

* ``f_RS``: the Robertson–Sandford model (paper 001 Eqs. 13 and 15,
  :mod:`sbrdf_xr.brdf.robertson_sandford`), the diffuse body and the broad lobe.
* The core: a Cook–Torrance lobe with the Beckmann distribution of normals of rms slope
  ``m`` (``core_roughness``), ``D = exp(-tan^2 theta_h / m^2) / (pi m^2 cos^4
  theta_h)`` (Walter et al. 2007 Eq. 25), the Smith masking of that distribution in its
  rational approximation (Walter et al. 2007 Eq. 27), and a constant reflectance
  ``rho_c`` (``core_rho``) per wavelength in place of the Fresnel term.  Beckmann's
  distribution falls as a Gaussian in the angle from specular, where GGX's (the
  microfacet model's) falls as a power: a mirror core a fraction of a degree wide has
  no GGX tails to speak of, and only a Gaussian can follow it and the body beside it.
* The core's reflectance follows the incidence angle: ``core_rho cos theta_i``.  A
  scatterometer reads the mirror beam of a specular reflectance ``R`` as ``R / (Omega
  cos theta_r)`` over the cone ``Omega`` about the mirror direction that its optics
  (and the surface's facets) spread it into (Stover, *Optical Scattering*, 3rd ed.,
  SPIE 2012: the specular beam in a BRDF scan), a peak growing as ``1 / cos theta_i``;
  Beckmann's peak grows as ``1 / cos^2 theta_i`` (its half vectors foreshorten the
  cone out of the plane of incidence), so the same in-plane core needs a reflectance
  ``R cos theta_i``.  Fitted scan by scan, the Starlink chassis' cores (5, 41.4, 60,
  75 deg) give 0.95-1.1, 0.68, 0.42-0.55, 0.26-0.46 (the folds of its leave-out
  check): ``~cos theta_i``, where one constant ``core_rho`` is off by factors.
* Energy (:func:`energy_scale`): where body and core together would reflect more than
  one, the whole model is scaled down at that incidence angle, ``s(theta_i) = min(1, 1
  / (1 - epsilon(theta_i) + core_rho cos theta_i))``: ``1 - epsilon(theta_i)`` is the
  body's reflectance without its grazing cut-off (paper 001 Eqs. 8 and 11; the
  cut-off only loses energy) and the core reflects ``core_rho cos theta_i L`` with
  ``L <= 1`` (:func:`core_loss`), so the model's directional-hemispherical reflectance
  is at most one at every incidence angle.  Scaling body and core together keeps the
  model's shape at each incidence angle, the shape a table filled with the model times
  the measured ratio takes from it (scaling the core alone would hand its energy to
  the body out of the plane of incidence, where a table's measured ratio multiplies
  it).

A measured in-plane scan of a near-mirror (the Starlink v1.5 chassis: about 1500 sr-1
within one degree of specular, a few sr-1 three degrees off) shows such a core on a
broad, paint-like body.  :func:`fit_core` fits the core (its reflectance per
wavelength, one rms slope) to the samples, beside a Robertson–Sandford body fitted first.

The directional-hemispherical reflectance is ``s(theta_i)`` times that of the
Robertson–Sandford part plus ``core_rho cos theta_i L(theta_i, m)``: ``L`` by quadrature
over the half vector (the substitution ``u = tan theta_h / m`` makes the integrand
``exp(-u^2) u`` smooth; 64 Gauss–Legendre points in ``u`` on [0, 6] and 256 in
azimuth).  ``L`` is 1 within 1e-3 for a narrow core away from grazing incidence, and
falls as the core meets the horizon.

References
----------
Walter, B., Marschner, S. R., Li, H., Torrance, K. E., "Microfacet models for
refraction through rough surfaces", EGSR 2007, Eqs. 20, 25, 27.
Sandford, paper 001 §4 (the Robertson–Sandford model; Eqs. 8, 11).
Stover, J. C., *Optical Scattering: Measurement and Analysis*, 3rd ed., SPIE 2012
(the BRDF of the specular beam in a scatterometer scan).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares

from ..units import to_unit
from . import robertson_sandford as rs
from ._common import _angles_to_vectors, _cast_out, _check_theta_i, _facet_frame
from ._model import Model, Parameter

__all__ = [
    "MODEL",
    "PARAMS",
    "brdf",
    "brdf_angles",
    "check_params",
    "core_brdf",
    "core_loss",
    "directional_hemispherical_reflectance",
    "energy_scale",
    "fit_core",
    "render_grid",
]

#: The parameters: the Robertson-Sandford ones, then the core's.
PARAMETERS = (
    *rs.PARAMETERS,
    Parameter(
        "core_rho",
        "1",
        "reflectance of the specular core at normal incidence",
        lower=0.0,
        upper=1.0,
    ),
    Parameter(
        "core_roughness",
        "1",
        "Beckmann rms slope of the specular core",
        lower=1e-5,
        upper=1.0,
    ),
)

#: Quadrature of :func:`core_loss`: Gauss-Legendre points in ``u = tan(theta_h) / m`` on
#: [0, U_MAX] and uniform points in azimuth (periodic: the trapezoid rule).
_N_U, _U_MAX, _N_AZ = 64, 6.0, 256


def _smith_a(cos_v: np.ndarray, m: np.ndarray) -> np.ndarray:
    """``a = cos / (m sin)`` of the Smith masking (inf at the normal)."""
    sin_v = np.sqrt(np.maximum(1.0 - cos_v**2, 0.0))
    shape = np.broadcast(cos_v, m).shape
    return np.maximum(np.divide(cos_v, m * sin_v, out=np.full(shape, np.inf), where=sin_v > 0), 0.0)


def _smith_g1(cos_v: np.ndarray, m: np.ndarray) -> np.ndarray:
    """Smith masking of the Beckmann distribution, rational approximation (Walter et al.
    2007 Eq. 27): ``a = cos / (m sin)``, ``G1 = (3.535 a + 2.181 a^2) / (1 + 2.276 a +
    2.577 a^2)`` below ``a = 1.6``, 1 above."""
    a = np.minimum(_smith_a(cos_v, m), 1.6)
    g = (3.535 * a + 2.181 * a**2) / (1.0 + 2.276 * a + 2.577 * a**2)
    return np.where(a < 1.6, g, 1.0)


def _g1_over_cos(cos_v: np.ndarray, m: np.ndarray) -> np.ndarray:
    """``G1 / cos`` in a form finite at grazing (``a / cos = 1 / (m sin)``)."""
    a_full = _smith_a(cos_v, m)
    a = np.minimum(a_full, 1.6)
    sin_v = np.sqrt(np.maximum(1.0 - cos_v**2, 0.0))
    near = (3.535 + 2.181 * a) / (m * np.maximum(sin_v, 1e-300) * (1.0 + 2.276 * a + 2.577 * a**2))
    far = 1.0 / np.maximum(cos_v, 1e-300)
    return np.where(a_full < 1.6, near, far)


def core_brdf(
    normal: ArrayLike,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    core_rho: ArrayLike,
    core_roughness: ArrayLike,
) -> np.ndarray:
    """The specular core alone, ``rho_c D G1(s) G1(o) / (4 |N.s| |N.o|)`` [sr-1].

    Parameters
    ----------
    normal, to_sun, to_observer : array_like, shape (..., 3)
        Facet normal and directions to the source and observer [1]; broadcast.
    core_rho, core_roughness : array_like, shape (n_wl,)
        The core's reflectance [1] and Beckmann rms slope [1] (validated by the caller).

    Returns
    -------
    ndarray, shape broadcast(...) + (n_wl,)
        [sr-1], float64; zero where unlit or unseen and at exact forward scatter.

    Examples
    --------
    At the mirror direction of normal incidence ``D = 1 / (pi m^2)`` and ``G1 = 1``:

    >>> import numpy as np
    >>> z = [0.0, 0.0, 1.0]
    >>> float(core_brdf(z, z, z, [0.5], [0.01])[0] * 4 * np.pi * 0.01**2)
    0.5
    """
    n, s, o, cos_i, cos_r, mask, _ = _facet_frame(normal, to_sun, to_observer)
    rho = np.asarray(core_rho, dtype=np.float64)
    m = np.asarray(core_roughness, dtype=np.float64)
    half = s + o
    norm = np.sqrt(np.einsum("...k,...k->...", half, half))
    h = half / np.where(norm > 0, norm, 1.0)[..., None]
    cos_h = np.einsum("...k,...k->...", n, h)
    cross = np.cross(n, h)
    sin2 = np.einsum("...k,...k->...", cross, cross)
    # tan^2 bounded by 1e200 (no overflow where h lies in the surface): the lobe is 0 there
    tan2 = sin2 / np.maximum(np.maximum(cos_h**2, sin2 * 1e-200), 1e-300)
    ok = mask & (norm > 1e-12) & (cos_h > 0)
    x = tan2[..., None] / m**2
    lobe = ok[..., None] & (x < 700.0)  # exp(-700) ~ 1e-304: zero beyond
    c4 = np.where(lobe, cos_h[..., None], 1.0) ** 4
    d = np.where(lobe, np.exp(-np.minimum(x, 700.0)) / (np.pi * m**2 * c4), 0.0)
    ci, cr = np.where(ok, cos_i, 1.0)[..., None], np.where(ok, cos_r, 1.0)[..., None]
    g = _g1_over_cos(ci, m) * _g1_over_cos(cr, m)
    return np.where(lobe, rho * d * g / 4.0, 0.0)


def brdf(
    normal: ArrayLike,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    wavelength: ArrayLike,
    **params: Any,
) -> np.ndarray:
    """Robertson–Sandford plus the specular core (module docstring; Walter et al. 2007
    Eqs. 20, 25, 27; paper 001 Eqs. 13 and 15).

    Parameters
    ----------
    normal, to_sun, to_observer : array_like, shape (..., 3)
        Facet normal and directions to the source and observer [1]; need not be
        unit length; broadcast against each other.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    rho_D, epsilon, b, e : array_like, scalar or shape (n_wl,)
        The Robertson–Sandford parameters [1] (:mod:`sbrdf_xr.brdf.robertson_sandford`).
    core_rho : array_like, scalar or shape (n_wl,)
        Reflectance of the specular core at normal incidence [1]; ``core_rho cos
        theta_i`` at ``theta_i`` (the model then scaled by :func:`energy_scale`).
    core_roughness : array_like, scalar or shape (n_wl,)
        Its Beckmann rms slope [1] (0.01: about 0.8 degree of ``theta_r`` from specular
        to ``1/e`` in the plane of incidence).

    Returns
    -------
    ndarray, shape broadcast(...) + (n_wl,)
        BRDF [sr-1]; zero where ``N.s <= 0`` or ``N.o <= 0``.  Not reciprocal (the
        Robertson–Sandford part is not; the core is).

    Examples
    --------
    With ``core_rho = 0`` it is the Robertson–Sandford model:

    >>> import numpy as np
    >>> from sbrdf_xr.brdf import robertson_sandford as rs
    >>> n, s, o = [0.0, 0.0, 1.0], [0.5, 0.0, 1.0], [-0.5, 0.0, 1.0]
    >>> p = rs.TABLE4["AFGL-01"]
    >>> bool(np.allclose(brdf(n, s, o, [4000.0], core_rho=0.0, core_roughness=0.01, **p),
    ...                  rs.brdf(n, s, o, [4000.0], **p)))
    True
    """
    p = MODEL.check_params(wavelength, **params)
    out, ti, dtype = _unscaled(normal, to_sun, to_observer, wavelength, p)
    return _cast_out(out * _scale(ti, wavelength, p), dtype)


def _unscaled(
    normal: ArrayLike, to_sun: ArrayLike, to_observer: ArrayLike, wavelength: ArrayLike, p: Any
) -> tuple[NDArray[np.float64], NDArray[np.float64], np.dtype]:
    """Body plus core before :func:`energy_scale` [sr-1], the incidence angles [degree]
    (90 where unlit) and the output dtype; ``p`` checked parameters."""
    body: dict[str, Any] = {k: p[k] for k in rs.PARAMS}
    n, s, _, cos_i, _, _, dtype = _facet_frame(normal, to_sun, to_observer)
    out = np.asarray(rs.brdf(normal, to_sun, to_observer, wavelength, **body), dtype=np.float64)
    sin_i = np.sqrt(np.einsum("...k,...k->...", np.cross(n, s), np.cross(n, s)))
    ti = np.degrees(np.arctan2(sin_i, np.maximum(cos_i, 0.0)))  # 90 where unlit: no light
    rho = p["core_rho"] * np.cos(np.radians(ti))[..., None]
    out = out + core_brdf(normal, to_sun, to_observer, rho, p["core_roughness"])
    return out, ti, dtype


def _most(ti: np.ndarray, wavelength: ArrayLike, p: Any) -> NDArray[np.float64]:
    """``1 - epsilon(theta_i) + core_rho cos theta_i``: at least what body and core
    reflect [1], ``ti.shape + (n_wl,)``."""
    body: dict[str, Any] = {k: p[k] for k in rs.PARAMS}
    most = 1.0 - rs.directional_emissivity(ti, wavelength, **body)
    return np.asarray(most + p["core_rho"] * np.cos(np.radians(ti))[..., None], dtype=np.float64)


def _scale(ti: np.ndarray, wavelength: ArrayLike, p: dict[str, Any]) -> NDArray[np.float64]:
    """``min(1, 1 / (1 - epsilon(theta_i) + core_rho cos theta_i))``, ``ti.shape + (n_wl,)``."""
    return 1.0 / np.maximum(_most(ti, wavelength, p), 1.0)


def energy_scale(theta_i: ArrayLike, wavelength: ArrayLike, **params: Any) -> NDArray[np.float64]:
    """The factor by which the model is scaled at incidence ``theta_i`` so that it
    reflects at most one: ``min(1, 1 / (1 - epsilon(theta_i) + core_rho cos theta_i))``
    (module docstring; paper 001 Eqs. 8 and 11 for the body's reflectance ``1 -
    epsilon(theta_i)``).

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
    A body reflecting 0.5 and a core of 0.4: no scaling; a core of 1: ``1 / 1.5``:

    >>> p = dict(rho_D=0.05, epsilon=0.5, b=0.0, e=0.3, core_rho=0.4, core_roughness=0.01)
    >>> np.round(energy_scale([0.0], [532.0], **p), 6).tolist()
    [[1.0]]
    >>> p["core_rho"] = 1.0
    >>> np.round(energy_scale([0.0], [532.0], **p), 6).tolist()
    [[0.666667]]
    """
    p = MODEL.check_params(wavelength, **params)
    return _scale(_check_theta_i(theta_i), wavelength, p)


def core_loss(theta_i: ArrayLike, core_roughness: float) -> NDArray[np.float64]:
    """The directional-hemispherical reflectance of a core of unit ``rho_c``, ``L``.

    ``L = int exp(-u^2) u / pi G1(s) G1(o) (h.s) / (cos theta_i cos theta_h) du dphi_h``
    over the half vectors whose mirror direction is above the horizon (``u = tan
    theta_h / m``; ``d omega_o = 4 (h.s) d omega_h``, Walter et al. 2007 Eq. 14).

    Parameters
    ----------
    theta_i : array_like
        Incidence angles [degree], ``0 <= theta_i <= 90``.
    core_roughness : float
        Beckmann rms slope [1].

    Returns
    -------
    ndarray, shape theta_i.shape
        [1]; 1 for a narrow core away from grazing incidence.

    Examples
    --------
    >>> np.round(core_loss([0.0, 60.0, 89.0], 0.01), 3).tolist()
    [1.0, 1.0, 0.941]
    """
    ti = np.radians(_check_theta_i(theta_i))
    m = float(core_roughness)
    x, w = np.polynomial.legendre.leggauss(_N_U)
    u, wu = 0.5 * _U_MAX * (x + 1.0), 0.5 * _U_MAX * w
    az = np.arange(_N_AZ) * (2.0 * np.pi / _N_AZ)
    th = np.arctan(m * u)[:, None]
    h = np.stack([np.sin(th) * np.cos(az), np.sin(th) * np.sin(az), np.cos(th) + 0 * az], -1)
    s = np.stack([np.sin(ti), np.zeros_like(ti), np.cos(ti)], -1)[..., None, None, :]
    hs = np.einsum("...k,...k->...", h, s)
    o_z = 2.0 * hs * h[..., 2] - s[..., 2]
    m_arr = np.asarray(m)
    g = _smith_g1(np.cos(ti)[..., None, None] + 0 * hs, m_arr) * _smith_g1(
        np.maximum(o_z, 0.0), m_arr
    )
    cos_i = np.maximum(np.cos(ti), 1e-300)[..., None, None]
    radial = (np.exp(-(u**2)) * u / np.pi)[:, None]
    f = radial * hs / (cos_i * np.cos(th)) * g
    f = np.where((o_z > 0) & (hs > 0), f, 0.0)
    return np.einsum("...ua,u->...", f, wu) * (2.0 * np.pi / _N_AZ)


def directional_hemispherical_reflectance(
    theta_i: ArrayLike, wavelength: ArrayLike, **params: Any
) -> NDArray[np.float64]:
    """Directional-hemispherical reflectance: the Robertson–Sandford part's plus
    ``core_rho cos theta_i L(theta_i, m)`` (:func:`core_loss`), times
    :func:`energy_scale`: at most one (paper 001 Eq. 11, ``L <= 1``).

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
    >>> from sbrdf_xr.brdf import robertson_sandford as rs
    >>> p = rs.TABLE4["AFGL-01"]
    >>> r = directional_hemispherical_reflectance([0.0], [4000.0], core_rho=0.1,
    ...                                           core_roughness=0.01, **p)
    >>> float(np.round(r - rs.directional_hemispherical_reflectance([0.0], [4000.0], **p), 4)[0, 0])
    0.1
    """
    p = MODEL.check_params(wavelength, **params)
    ti = _check_theta_i(theta_i)
    return _unscaled_reflectance(ti, wavelength, p) * _scale(ti, wavelength, p)


def _unscaled_reflectance(ti: np.ndarray, wavelength: ArrayLike, p: Any) -> NDArray[np.float64]:
    """Body's plus core's reflectance before :func:`energy_scale` [1]."""
    body_params: dict[str, Any] = {k: p[k] for k in rs.PARAMS}
    body = rs.directional_hemispherical_reflectance(ti, wavelength, **body_params)
    ms, inverse = np.unique(p["core_roughness"], return_inverse=True)
    loss = np.stack([core_loss(ti, mj) for mj in ms], axis=-1)[..., inverse.ravel()]
    core = p["core_rho"] * np.cos(np.radians(ti))[..., None] * loss
    return np.asarray(body + core, dtype=np.float64)


def fit_core(
    theta_i: ArrayLike,
    delta_theta: ArrayLike,
    phi: ArrayLike,
    spectra: ArrayLike,
    body: ArrayLike,
    reference: ArrayLike | None = None,
) -> dict[str, Any]:
    """Fit the specular core to samples beside a known body (least squares in the values).

    Fits ``body + core`` to the samples above zero and not reference points: one
    ``core_roughness``, ``core_rho`` per wavelength (the core's reflectance ``core_rho cos
    theta_i``, without :func:`energy_scale`: that bound is energy's, not the data's, and
    leaves the shape as it is) and, as nuisance parameters, one offset of each incidence
    angle's core along ``delta_theta`` (within +-1 degree: a goniometer's zero or the
    sample's tilt puts a measured mirror core a fraction of a degree from specular; the
    model keeps it at specular and the table's ratio to the measurements takes the
    offset).  The residuals are ``(body + core - sample) / peak``, ``peak`` the largest
    sample of the incidence angle at that wavelength: the values, not their logarithm,
    so the core's few samples set its width and the body's many samples, orders of
    magnitude below, do not widen it.  Best of three starting widths (rms slopes 0.003,
    0.01, 0.03).

    Parameters
    ----------
    theta_i, delta_theta, phi : array_like, shape (s,)
        Sample angles [degree].
    spectra : array_like, shape (s, n_wl)
        The samples [sr-1].
    body : array_like, shape (s, n_wl)
        The body's BRDF at the samples [sr-1] (a Robertson-Sandford fit's).
    reference : array_like of bool, shape (s,), optional
        Reference points (left out).

    Returns
    -------
    dict
        ``core_rho`` (shape ``(n_wl,)``) [1], ``core_roughness`` [1], ``core_offset``
        (one per incidence angle, in ``theta_i`` order) [degree], ``rms_log`` (the
        root-mean-square log residual of the fit at the samples [1]) and ``n_used``.

    Examples
    --------
    A core of rms slope 0.008 on a flat body is recovered from an in-plane scan:

    >>> import numpy as np
    >>> from sbrdf_xr.geometry import facet_vectors
    >>> t, d = np.full(41, 30.0), np.linspace(-4.0, 4.0, 41)
    >>> n, s, o = facet_vectors(t, d, np.zeros(41))
    >>> y = 0.1 + core_brdf(n, s, o, [0.3 * np.cos(np.radians(30.0))], [0.008])
    >>> fit = fit_core(t, d, np.zeros(41), y, np.full((41, 1), 0.1))
    >>> round(float(fit["core_roughness"]), 6), np.round(fit["core_rho"], 6).tolist()
    (0.008, [0.3])
    """
    y = np.asarray(to_unit(spectra, "sr-1", "spectra"), dtype=np.float64)
    base = np.asarray(to_unit(body, "sr-1", "body"), dtype=np.float64)
    ok = np.all(y > 0, axis=1) & np.all(base > 0, axis=1)
    if reference is not None:
        ok &= ~np.asarray(reference, dtype=bool)
    ti, dt, ph = (np.asarray(to_unit(a, "deg", k), dtype=np.float64)[ok] for k, a in
                  (("theta_i", theta_i), ("delta_theta", delta_theta), ("phi", phi)))  # fmt: skip
    y, base = y[ok], base[ok]
    scans, scan = np.unique(ti, return_inverse=True)
    peak = np.zeros_like(y)
    for k in range(scans.size):
        peak[scan == k] = y[scan == k].max(axis=0)
    law = np.cos(np.radians(ti))[:, None]
    n_wl, n_scan = y.shape[1], scans.size

    def model(x: np.ndarray) -> np.ndarray:
        m, rho, off = np.exp(x[0]), np.exp(x[1 : 1 + n_wl]), x[1 + n_wl :]
        n, s, o = _angles_to_vectors(ti, dt - off[scan], ph)
        return base + core_brdf(n, s, o, rho * law, np.full(n_wl, m))

    def residuals(x: np.ndarray) -> np.ndarray:
        return ((model(x) - y) / peak).ravel()

    best = None
    lo = np.concatenate([[np.log(1e-4)], np.full(n_wl, np.log(1e-8)), np.full(n_scan, -1.0)])
    hi = np.concatenate([[np.log(0.5)], np.zeros(n_wl), np.full(n_scan, 1.0)])
    for m0 in (0.003, 0.01, 0.03):
        x0 = np.concatenate([[np.log(m0)], np.full(n_wl, np.log(0.1)), np.zeros(n_scan)])
        res = least_squares(residuals, x0, bounds=(lo, hi), x_scale=1.0, **_TOLERANCES)
        if best is None or res.cost < best.cost:
            best = res
    assert best is not None
    log_res = np.log(model(best.x)) - np.log(y)
    return {
        "core_rho": np.exp(best.x[1 : 1 + n_wl]),
        "core_roughness": float(np.exp(best.x[0])),
        "core_offset": best.x[1 + n_wl :].copy(),
        "rms_log": float(np.sqrt(np.mean(log_res**2))),
        "n_used": int(y.size),
    }


#: Stopping tolerances of :func:`fit_core`'s least squares: converged to the optimum's
#: last digits, so that inputs equal to rounding give fits equal to ~1e-10 (scipy's
#: defaults, 1e-8, stop where the result still moves at 1e-7).
_TOLERANCES = {"ftol": 1e-12, "xtol": 1e-12, "gtol": 1e-12}


def _constraint(checked: dict[str, NDArray[np.float64]]) -> None:
    """The Robertson-Sandford part's joint condition (``rho_s >= 0``)."""
    if rs.MODEL.constraint is not None:
        rs.MODEL.constraint({k: checked[k] for k in rs.PARAMS})


#: The Robertson-Sandford model with a specular core.
MODEL = Model(
    name="robertson_sandford_core",
    long_name="Robertson-Sandford body plus a Beckmann specular core",
    brdf=brdf,
    parameters=PARAMETERS,
    citation="Sandford, paper 001 section 4 (Eqs. 13, 15); Walter et al., EGSR 2007, "
    "Eqs. 20, 25, 27 (Beckmann core with Smith masking)",
    reflectance=directional_hemispherical_reflectance,
    constraint=_constraint,
)
PARAMS = MODEL.param_names
check_params, brdf_angles, render_grid = MODEL.check_params, MODEL.brdf_angles, MODEL.render_grid
