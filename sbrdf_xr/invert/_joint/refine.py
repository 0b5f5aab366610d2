"""The local refinement of a joint fit from one start, inside the physical bounds when
its minimum is not.

See :func:`sbrdf_xr.invert.fit_observation` and :mod:`sbrdf_xr.invert._joint.bounds`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from .._spin.refine import tangent_frame
from .bounds import stick_breaking, stick_breaking_inverse
from .model import PassModel
from .result import Layout
from .starts import Start

__all__ = ["MAX_NFEV", "Local", "jacobian", "outside_physics", "refine"]

#: Function evaluations allowed to the least-squares fit.
MAX_NFEV = 2000


@dataclasses.dataclass(frozen=True)
class Local:
    """The minimum refined from one start: the optimizer's result, the axis of its
    parameters (tangent plane of the start's axis), its residual function, chi-square."""

    res: Any
    axis_of: Callable[[np.ndarray], np.ndarray]
    residuals: Callable[[np.ndarray], np.ndarray]
    chi2: float
    label: str
    x: np.ndarray
    bounded: bool = False


def refine(model: PassModel, lay: Layout, st: Start, span: float, bounded: bool = False) -> Local:
    """Levenberg-Marquardt from one start (the axis on the tangent plane of its axis); with
    ``bounded``, the trust-region reflective method on the area fractions' stick-breaking
    transform in ``[0, 1]`` (or scales ``>= 0``), keeping them inside physics."""
    data = model.data
    e0 = st.axis
    east, north = tangent_frame(e0)

    def axis_of(p: np.ndarray) -> np.ndarray:
        a = e0 + np.radians(p[0]) * east + np.radians(p[1]) * north
        return a / np.linalg.norm(a)

    def residuals(p: np.ndarray) -> np.ndarray:
        terms = model.terms(axis_of(p), p[2], p[3])
        m = model.magnitudes(terms, lay.band_scales(p)) + lay.extra(p, data)
        return np.append((data.magnitude - m) / data.sigma, lay.prior_residuals(p))

    p0 = lay.start(st.period, st.phase_ref)
    opts = {"diff_step": 1e-7, "max_nfev": MAX_NFEV, "ftol": 1e-10, "xtol": 1e-10}
    scale = lay.x_scale(st.period, span)
    if not bounded:
        res = least_squares(residuals, p0, x_scale=scale, method="lm", **opts)
        x = res.x
    else:
        to_p, q0, lo, hi = bounded_map(lay, p0, st.period)
        res = least_squares(
            lambda q: residuals(to_p(q)), q0, x_scale=scale, method="trf", bounds=(lo, hi), **opts
        )
        x = to_p(res.x)
    chi2 = float(2.0 * res.cost) if x[2] > 0 else np.inf
    return Local(res, axis_of, residuals, chi2, st.label, x, bounded)


#: How to recover from a failed fit.


def bounded_map(
    lay: Layout, p0: np.ndarray, period: float
) -> tuple[Callable[[np.ndarray], np.ndarray], np.ndarray, np.ndarray, np.ndarray]:
    """The bounded parameters ``q`` of a fit (area fractions by their stick-breaking
    transform ``u`` in ``[0, 1]``, scales ``>= 0``, period ``> 0``): the map ``q -> p``, the
    start ``q0`` and the bounds."""
    sl = lay.sl["f"]
    lo = np.full(lay.n, -np.inf)
    hi = np.full(lay.n, np.inf)
    lo[2] = 1e-6 * period
    q0 = p0.copy()
    if lay.areas == "total":
        lo[sl], hi[sl] = 0.0, 1.0
        q0[sl] = stick_breaking_inverse(p0[sl])
    elif lay.areas == "free":
        lo[sl] = 0.0

    def to_p(q: np.ndarray) -> np.ndarray:
        p = np.array(q, dtype=np.float64)
        if lay.areas == "total":
            p[sl] = stick_breaking(q[sl])[:-1]
        return p

    return to_p, np.clip(q0, lo, hi), lo, hi


def outside_physics(lay: Layout, p: np.ndarray, tol: float = 1e-9) -> list[str]:
    """The area fractions (or scales) of ``p`` outside their physical bounds, as text.

    Examples
    --------
    >>> from sbrdf_xr.invert._joint.refine import outside_physics
    >>> from sbrdf_xr.invert._joint.result import Layout
    >>> lay = Layout(("V",), ("a", "b"), np.array([1.0, 1.0]), "fit", None, "total")
    >>> outside_physics(lay, np.array([0, 0, 10, 0, 0.1, 1.3]))
    ['a 1.3', 'b -0.3']
    """
    if lay.areas == "fixed":
        return []
    f = lay.fractions(p) if lay.areas == "total" else lay.scales(p)
    top = 1.0 if lay.areas == "total" else np.inf
    bad = (f < -tol) | (f > top + tol)
    return [f"{m} {v:.4g}" for m, v, b in zip(lay.materials, f, bad, strict=True) if b]


def jacobian(fun: Any, p: np.ndarray, steps: np.ndarray) -> np.ndarray:
    """Central-difference Jacobian of ``fun`` at ``p``."""
    cols = []
    for j, h in enumerate(steps):
        d = np.zeros_like(p)
        d[j] = h
        cols.append((fun(p + d) - fun(p - d)) / (2 * h))
    return np.stack(cols, axis=-1)
