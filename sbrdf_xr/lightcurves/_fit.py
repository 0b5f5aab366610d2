"""Weighted least squares of a light-curve comparison: the linear terms and one shift.

The model of observation ``i`` is ``m_i = s_i(x) + f_i + A_i . beta``: a simulated
magnitude ``s_i`` at a shift ``x`` (a time shift or a rotation-phase offset; none when
not fitted), fixed terms ``f_i`` (a range term, extinction with given coefficients) and
linear terms (zero points, extinction coefficients times air mass) with design matrix
``A``.  For a given ``x`` the linear terms are the weighted linear least-squares
solution (``w_i = 1 / sigma_i^2``), so ``chi2(x)`` is profiled over them; ``x`` is
found by a scan and a bounded Brent refinement.  The covariance of all parameters is
the Gauss-Newton ``(J^T W J)^-1`` at the solution, ``J = [A, ds/dx]``, with the stated
uncertainties (not rescaled by the reduced chi-square).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..errors import LightCurveError


@dataclass
class LinearFit:
    """The solution of the linear terms at one shift."""

    beta: np.ndarray
    covariance: np.ndarray
    chi2: float
    model: np.ndarray  # s + f + A beta, over the used observations


def solve_linear(y: np.ndarray, a: np.ndarray, w: np.ndarray, names: list[str]) -> LinearFit | None:
    """Weighted least squares of ``y = A beta``; None when ``A`` is rank-deficient.

    Examples
    --------
    >>> a = np.ones((4, 1))
    >>> fit = solve_linear(np.array([1.0, 2.0, 3.0, 4.0]), a, np.ones(4), ["ZP"])
    >>> float(fit.beta[0]), float(fit.covariance[0, 0]), float(fit.chi2)
    (2.5, 0.25, 5.0)
    """
    sw = np.sqrt(w)
    aw, yw = a * sw[:, None], y * sw
    if a.shape[1] == 0:
        return LinearFit(np.zeros(0), np.zeros((0, 0)), float(yw @ yw), np.zeros_like(y))
    q, r = np.linalg.qr(aw)
    d = np.abs(np.diag(r))
    if d.min() <= 1e-10 * max(d.max(), 1e-300):
        return None
    beta = np.linalg.solve(r, q.T @ yw)
    rinv = np.linalg.inv(r)
    res = yw - aw @ beta
    return LinearFit(beta, rinv @ rinv.T, float(res @ res), a @ beta)


def degenerate(a: np.ndarray, w: np.ndarray, names: list[str]) -> list[str]:
    """The parameters ``A`` cannot tell apart (those of its null space).

    Examples
    --------
    >>> degenerate(np.array([[1.0, 1.0], [1.0, 1.0], [1.0, 1.0]]), np.ones(3), ["ZP", "k"])
    ['ZP', 'k']
    """
    aw = a * np.sqrt(w)[:, None]
    _, sv, vt = np.linalg.svd(aw, full_matrices=False)
    null = vt[sv <= 1e-10 * max(sv.max(), 1e-300)]
    return [n for j, n in enumerate(names) if np.any(np.abs(null[:, j]) > 1e-6)]


def profile_scan(
    chi2: Callable[[float], float], grid: np.ndarray, step: float, lo: float, hi: float
) -> tuple[float, np.ndarray]:
    """The ``x`` of least profiled ``chi2``: the grid's best, refined by bounded Brent
    within one step (kept inside ``[lo, hi]``); also ``chi2`` over the grid.

    Examples
    --------
    >>> x, scan = profile_scan(lambda x: (x - 0.3) ** 2, np.linspace(-1, 1, 21), 0.1, -1, 1)
    >>> round(x, 6), scan.size
    (0.3, 21)
    """
    from scipy.optimize import minimize_scalar

    scan = np.array([chi2(float(x)) for x in grid])
    if not np.isfinite(scan).any():
        raise LightCurveError(
            "simulated: the model reflects no light at the measured times or angles for "
            "any trial shift"
        )
    k = int(np.nanargmin(np.where(np.isfinite(scan), scan, np.nan)))
    a, b = max(lo, grid[k] - step), min(hi, grid[k] + step)
    if b <= a:
        return float(grid[k]), scan
    res = minimize_scalar(chi2, bounds=(a, b), method="bounded", options={"xatol": 1e-9 * step})
    x = float(res.x) if np.isfinite(res.fun) and res.fun <= scan[k] else float(grid[k])
    return x, scan


def gauss_newton_covariance(
    a: np.ndarray, w: np.ndarray, ds_dx: np.ndarray | None
) -> np.ndarray | None:
    """``(J^T W J)^-1`` with ``J = [A, ds/dx]`` (``ds/dx`` None: the linear terms only).

    Examples
    --------
    >>> a = np.ones((3, 1))
    >>> np.round(gauss_newton_covariance(a, np.ones(3), np.array([-1.0, 0.0, 1.0])), 6)
    array([[0.333333, 0.      ],
           [0.      , 0.5     ]])
    """
    j = a if ds_dx is None else np.column_stack([a, ds_dx])
    m = (j * w[:, None]).T @ j
    try:
        cov = np.linalg.inv(m)
    except np.linalg.LinAlgError:
        return None
    return None if not np.all(np.isfinite(cov)) or np.any(np.diag(cov) < 0) else cov
