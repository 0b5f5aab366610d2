r"""Angular functions of the Robertson–Sandford model (paper 001 §4, Eqs. 9, 10, 16, 18, 21).

The emissivity and diffuse shape ``g`` (Eq. 9) and its normalisation ``G`` (Eq. 10),
the Trowbridge–Reitz structure function ``h`` (Eq. 16) and its normalisation ``H``
(Eq. 18), the grazing cut-off ``c`` (Eq. 21) and the fraction of the specular lobe
that the cut-off removes.  Angles are in degree (a Quantity is converted).  How each
equation is read is stated in :mod:`sbrdf_xr.brdf.robertson_sandford`; the BRDF built
from these functions is there.

References
----------
Sandford, B. P., "Infrared reflectance properties of aircraft paints" (paper 001),
§4 (Eqs. 9, 10, 16, 18, 21).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import special

from ..units import to_unit

__all__ = [
    "CUTOFF_ANGLE",
    "angular_g",
    "cutoff_factor",
    "normalisation_G",
    "normalisation_H",
    "structure_h",
]

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
#: Cut-off-loss quadrature: Gauss–Legendre points per panel, the geometric ratio of
#: the panels graded toward the lobe and the horizon, the smallest panel as a
#: fraction of the narrowest width.
_N_NODES = 16
_GRADE = 0.2
_SCALE = 0.05


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

    Examples
    --------
    >>> import numpy as np
    >>> np.round(angular_g([0.0, 45.0, 90.0], 0.5), 6).tolist()
    [1.0, 0.8, 0.0]
    """
    t = np.radians(np.asarray(to_unit(theta, "deg", "theta"), dtype=np.float64))
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

    Examples
    --------
    >>> import numpy as np
    >>> np.round(normalisation_G([0.0, 0.12, 1.0]), 6).tolist()
    [1.0, 0.951749, 0.5]
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

    Examples
    --------
    >>> import numpy as np
    >>> np.round(structure_h([0.0, 90.0], 0.5), 6).tolist()  # e^-4 at the glint, 1 at 90 deg
    [16.0, 1.0]
    """
    a = np.radians(np.asarray(to_unit(alpha, "deg", "alpha"), dtype=np.float64))
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

    Examples
    --------
    >>> round(float(normalisation_H(0.0, 0.3)), 6), round(1 / (0.3**2 * (1 + 0.3**2)), 6)
    (10.19368, 10.19368)
    >>> round(float(normalisation_H(30.0, 1.0)), 6)
    0.5
    """
    ti = np.radians(np.asarray(to_unit(theta_i, "deg", "theta_i"), dtype=np.float64))
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

    Examples
    --------
    >>> import numpy as np
    >>> np.round(cutoff_factor([45.0, 85.0, 90.0], 0.12), 6).tolist()
    [1.0, 0.50781, 0.0]
    """
    t = np.radians(np.asarray(to_unit(theta_r, "deg", "theta_r"), dtype=np.float64))
    return _cutoff_cs(np.cos(t), np.sin(t) ** 2, np.asarray(b, dtype=np.float64))


# --------------------------------------------------------------------------
# the cut-off loss (quadrature)
# --------------------------------------------------------------------------


def _graded_rule(breaks: np.ndarray, n_nodes: int = _N_NODES) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Legendre nodes and weights on the panels between sorted ``breaks`` (last axis)."""
    t, w = np.polynomial.legendre.leggauss(n_nodes)
    lo, hi = breaks[..., :-1, None], breaks[..., 1:, None]
    half = 0.5 * (hi - lo)
    nodes = (lo + half * (t + 1.0)).reshape(*breaks.shape[:-1], -1)
    return nodes, (half * w).reshape(nodes.shape)


def _n_grades(length: float, smallest: float) -> int:
    """Number of geometric panels (ratio :data:`_GRADE`) from ``length`` down to ``smallest``."""
    ratio = max(smallest, 1e-300) / max(length, 1e-300)
    return max(1, int(np.ceil(np.log(ratio) / np.log(_GRADE))) + 1)


def _loss_rows(theta_i: np.ndarray, b: float, e: float, psi: np.ndarray, w_psi: np.ndarray):
    """``e^2 H L`` for incidence angles ``theta_i`` [rad] (1-D), one (b, e) pair."""
    lo, hi = np.radians(CUTOFF_ANGLE), 0.5 * np.pi
    peak = np.clip(theta_i, lo, hi)[:, None]
    width = hi - lo
    frac = _GRADE ** np.arange(1, _n_grades(width, _SCALE * e) + 1)
    horizon = hi - width * _GRADE ** np.arange(1, _n_grades(width, _SCALE * max(b, 1e-8)) + 1)
    breaks = np.concatenate(
        [
            np.broadcast_to([lo, hi], (theta_i.size, 2)),
            peak,
            peak - (peak - lo) * frac,
            peak + (hi - peak) * frac,
            np.broadcast_to(horizon, (theta_i.size, horizon.size)),
        ],
        axis=1,
    )
    th, w_th = _graded_rule(np.sort(breaks, axis=1))
    th, w_th = th[..., None], w_th[..., None]
    ti = theta_i[:, None, None]
    s_r, c_r = np.sin(th), np.cos(th)
    # the glint vector (s + o) in the facet frame, psi = pi - phi_r (psi = 0: the
    # plane of incidence, forward); written without cancellation near the mirror
    # direction (theta_r = theta_i, psi = 0) where needle lobes live.
    tx = (
        2.0 * np.cos(0.5 * (ti + th)) * np.sin(0.5 * (ti - th)) + 2.0 * s_r * np.sin(0.5 * psi) ** 2
    )
    ty = s_r * np.sin(psi)
    nz = np.cos(ti) + c_r
    t2 = tx * tx + ty * ty
    den = (e * e) * nz * nz + t2
    ok = den > 0
    e2h = np.where(ok, (e * e) * ((nz * nz + t2) / np.where(ok, den, 1.0)) ** 2, 1.0 / (e * e))
    # 1 - c(theta_r) of Eq. 21 above 80 deg, without the cancellation at 80 deg
    lost = (
        (b * b)
        * np.sin(th - lo)
        * np.sin(th + lo)
        / (np.cos(lo) ** 2 * (c_r**2 + (b * b) * s_r**2))
    )
    f = 2.0 * e2h * lost * s_r  # both halves of the azimuth range
    return np.einsum("imk,im,k->i", f, w_th[..., 0], w_psi) / (4.0 * np.pi)


def _cutoff_loss(theta_i: np.ndarray, b: float, e: float) -> np.ndarray:
    """Fraction ``L`` of the specular lobe removed by the Eq. 21 cut-off.

    ``L = (1/4 pi H) int h(alpha) (1 - c(theta_r)) dOmega_r`` over the band
    ``80 deg < theta_r < 90 deg``, for incidence angles ``theta_i`` [rad] (any shape)
    and one ``(b, e)`` pair.  The band is a rectangle in ``(theta_r, psi)``
    (``psi = pi - phi_r``), so the only difficulty is the lobe: it peaks at the
    mirror direction ``(theta_i, 0)`` (clipped into the band when ``theta_i < 80``
    deg) with widths ``~e`` in ``theta_r`` and down to ``~e cos(theta_i)`` and
    ``~e^2`` in ``psi`` (near grazing the glint vector of nearly opposite ``s`` and
    ``o`` turns fast).  Both coordinates are cut into panels graded geometrically
    (ratio :data:`_GRADE`) toward the peak, and toward the horizon where ``1 - c``
    varies on the scale ``b``, down to a fraction :data:`_SCALE` of those widths;
    a Gauss–Legendre rule of :data:`_N_NODES` points on each panel then converges
    exponentially (the hp-quadrature of a point singularity).  The integrand is
    written without cancellation, so needle lobes (``e = 1e-4``) at ``theta_i =
    89.99 deg`` are integrated to ~1e-12 (tests compare with an adaptive cubature).
    """
    theta_i = np.asarray(theta_i, dtype=np.float64)
    flat = theta_i.ravel()
    if b <= 0 or flat.size == 0:
        return np.zeros(theta_i.shape)
    order = np.argsort(flat)
    out = np.empty(flat.size)
    step = 16
    for start in range(0, flat.size, step):  # memory bound, not a per-sample loop
        idx = order[start : start + step]
        rows = flat[idx]
        # the lobe's width in psi: ~e cos(theta_i), and ~e^2 (the ridge) near grazing
        c_min = max(float(np.cos(np.max(rows))), 1e-7)
        w_smallest = max(_SCALE * e * max(c_min, e), 1e-16)
        psi_breaks = np.concatenate(
            [[0.0], np.pi * _GRADE ** np.arange(_n_grades(np.pi, w_smallest))[::-1]]
        )
        psi, w_psi = _graded_rule(psi_breaks)
        out[idx] = _loss_rows(rows, b, e, psi, w_psi)
    e2h_norm = _e2_h_norm(np.cos(flat), e)
    return np.clip(out / e2h_norm, 0.0, 1.0).reshape(theta_i.shape)
