"""Branch and bound over the spin grid: the exact best states from spin-angle tables.

See :func:`sbrdf_xr.invert.fit_spin` (``method="bound"``).  The ``direct`` search runs
every candidate (axis, period, phase) at every time through the kernel.  Here the work is
shared by the candidates of one axis, whose period and phase change only the spin angle
``psi = phase + 360 t / P``:

1. **Tables.**  Per axis, the kernel at every distinct time on ``n`` spin angles (step
   ``h = 360 / n`` degree; the geometry at each time is exact), in one batch.
2. **Error estimate of the tables.**  The even angles form a coarse table of step ``2h``;
   its Catmull-Rom interpolant at the odd angles (the coarse cells' midpoints) is compared
   with the kernel there.  The estimate of the interpolation error of the fine table in a
   cell, ``eps``, is :data:`SAFETY` times the largest such midpoint error over the coarse
   cells within :data:`REACH` of it, plus a rounding floor.  The fine interpolant's error
   is the coarse one's over 2 (a kink of the signal, where a facet turns away or a
   table cell is crossed) to 8 (smooth parts), and a cell's largest error is at most
   twice its midpoint's for a kink: hence the factor.  It is an estimate, not a proof:
   a feature narrower than ``h`` that no table angle sees escapes it
   (:func:`bound_violations` measures it against the kernel).
3. **Lower bounds.**  Every candidate's model ``m~`` is read from its axis's table
   (Catmull-Rom, as the ``table`` search) with ``|m - m~| <= eps`` per value.  With the
   weighted norm ``||.||`` and ``E = ||eps||``, for every flux scale ``k`` of a band (or
   of all bands: ``offset="common"``), ``||y - k m|| >= ||y - k m~|| - |k| E``; writing
   ``||y - k m~||**2 = c + D (k - k~)**2`` (``c`` the approximate chi-square, ``D =
   ||m~||**2``, ``k~`` its best scale) the minimum over ``k`` of the right side is
   ``sqrt(c (1 - E**2 / D)) - |k~| E`` (when ``E**2 < D``, else the bound is 0): its
   square, clipped at 0 and summed over the bands, is a lower bound of the exact
   chi-square.
4. **Axes first on a quarter of the times.**  A chi-square over some of the values is a
   lower bound of the whole one (each value adds a square, for every flux scale): steps
   1-3 on every :data:`STRIDE`-th time bound every candidate at a quarter of the cost;
   the best subset state of ``2 n_best`` axes is evaluated exactly, and only the axes
   whose bound can still go below the ``n_best``-th best of those get the full tables.
5. **Exact where a candidate can still win.**  Candidates in increasing order of their
   bound are evaluated through the kernel (as ``direct``) while the bound lies below the
   ``n_best``-th best per-axis exact minimum and below its own axis's best.  The
   ``n_best`` best axes, their best states and chi-squares are then those of the
   ``direct`` search whenever the error estimate holds.

Cost: at most ``n_axes x times x n (1 + 1 / STRIDE)`` kernel geometries instead of
``candidates x times``, the lower bounds compiled (no Python per candidate, the times
outer so that a time's tables stay in cache), and the few exact candidates.

Where the time of the ``direct`` search goes (1e4 candidates of CanX-1, 300 times, V R I,
one thread, load 3 on two cores): 3.4 us per geometry, of which the compiled kernel
(angles, look-up, sums over the 20 merged terms; no shadowing in the spin model) 69 %,
the body-frame directions (Rodrigues in numpy) 26 %, the chi-square 3.6 %, the gathers
0.8 %, the spin angles 0.4 %, the alignments 0.2 %: the work per candidate and time
itself, which only sharing it across candidates removes.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numba
import numpy as np

from ...errors import InversionError
from .search import BLOCK_BYTES, Problem, _map, _tables, _threads

__all__ = [
    "BOUND_ANGLES",
    "REACH",
    "SAFETY",
    "BoundSearch",
    "bound_angles",
    "bound_violations",
    "lower_bound",
    "search_bound",
    "table_errors",
]

#: Factor on the coarse table's midpoint errors in the estimate of the fine table's error.
SAFETY = 8.0
#: Coarse cells on each side whose midpoint errors bound a fine cell (the Catmull-Rom
#: stencil spans one coarse cell on each side; two give a margin).
REACH = 4
#: Rounding floor of the error estimate, relative to the largest table value of a time and
#: band (the kernel's sums and the interpolation round at this level, far below it).
FLOOR = 1e-12
#: Fewest spin angles of the tables (0.5 degree): coarser ones bound loosely, and the
#: exact evaluations they leave cost more than the finer tables.
BOUND_ANGLES = 720
#: Time stride of the first pass over the axes, and the fewest times it needs.
STRIDE = 4
MIN_TIMES = 8
#: Relative slack of a lower bound against a chi-square (the bound's own rounding).
SLACK = 1e-9


@dataclasses.dataclass(frozen=True)
class BoundSearch:
    """The outcome of :func:`search_bound`: ``grid`` (axes, periods, phases) holds the
    exact chi-square where ``exact`` and the tables' approximation elsewhere; ``lower``
    the lower bounds; ``n_exact`` the candidates evaluated exactly; ``threshold`` the
    ``n_best``-th best per-axis exact minimum that pruned the rest."""

    grid: np.ndarray
    lower: np.ndarray
    exact: np.ndarray
    n_exact: int
    threshold: float


def bound_angles(n_angles: int) -> int:
    """Spin angles of the bound search's tables: ``n_angles`` made even, at least
    :data:`BOUND_ANGLES`.

    Examples
    --------
    >>> from sbrdf_xr.invert._spin.bound import bound_angles
    >>> bound_angles(360), bound_angles(1001)
    (720, 1002)
    """
    return max(int(n_angles) + int(n_angles) % 2, BOUND_ANGLES)


def table_errors(f: np.ndarray) -> np.ndarray:
    """Error estimate ``eps`` of the Catmull-Rom interpolation of spin-angle tables, per
    fine cell: ``f`` (..., n, B) with ``n`` even -> (..., n, B) (cell ``j`` from angle ``j``
    to ``j + 1``).

    Examples
    --------
    A sinusoid on 36 angles: the estimate lies above the true error of the fine
    interpolant at the cells' midpoints.

    >>> import numpy as np
    >>> from sbrdf_xr.invert._spin.bound import table_errors
    >>> psi = np.arange(36) * 10.0
    >>> f = (2 + np.sin(np.radians(psi)))[:, None]
    >>> eps = table_errors(f)[:, 0]
    >>> mid = np.radians(psi + 5.0)
    >>> cr = (-np.roll(f, 1) + 9 * f + 9 * np.roll(f, -1) - np.roll(f, -2))[:, 0] / 16
    >>> bool(np.all(np.abs(cr - (2 + np.sin(mid))) <= eps))
    True
    """
    n = f.shape[-2]
    if n % 2 or n < 8:
        raise InversionError(f"spin-angle tables: {n} angles; allowed an even number >= 8")
    c = f[..., 0::2, :]  # the coarse table: cell i from angle 2i to 2i + 2
    cr = (
        9.0 * (c + np.roll(c, -1, axis=-2)) - np.roll(c, 1, axis=-2) - np.roll(c, -2, axis=-2)
    ) / 16.0
    e = np.abs(f[..., 1::2, :] - cr)
    m = e.copy()
    for d in range(1, REACH + 1):
        m = np.maximum(m, np.maximum(np.roll(e, d, axis=-2), np.roll(e, -d, axis=-2)))
    floor = FLOOR * np.abs(f).max(axis=-2, keepdims=True)
    return SAFETY * np.repeat(m, 2, axis=-2) + floor


@numba.njit(nogil=True, cache=True)
def lower_bound(syy: float, sym: float, smm: float, see: float) -> tuple[float, float]:
    """Chi-square of a model ``m~`` with its best flux scale, and a lower bound of the
    chi-square of every model ``m`` with ``|m - m~| <= eps``, from the weighted sums
    ``syy = ||y||**2``, ``sym = <y, m~>``, ``smm = ||m~||**2``, ``see = ||eps||**2``
    (see the module: ``(sqrt(c (1 - E**2 / D)) - |k~| E)**2``, 0 when ``E**2 >= D``).

    Examples
    --------
    Without error the bound is the chi-square (less the rounding slack); with an error
    as large as the model it says nothing:

    >>> from sbrdf_xr.invert._spin.bound import lower_bound
    >>> c, lb = lower_bound(14.0, 10.0, 10.0, 0.0)  # y = (1, 2, 3), m~ = (1, 3, 0)
    >>> round(c, 9), round(lb, 6)
    (4.0, 4.0)
    >>> lower_bound(14.0, 10.0, 10.0, 10.0)
    (4.0, 0.0)
    """
    if smm <= 1e-300:
        return syy, 0.0
    k = sym / smm
    c = max(syy - sym * k, 0.0)
    if see >= smm:
        return c, 0.0
    cs = max(c - SLACK * syy, 0.0)
    r = np.sqrt(cs * (1.0 - see / smm)) - abs(k) * np.sqrt(see)
    return c, r * r if r > 0.0 else 0.0


@numba.njit(nogil=True, cache=True)
def _bound_axis(  # pragma: no cover - compiled
    fp, ep, times, v_start, v_band, v_group, v_y, v_w, factor, periods, phases, cells, syy, out
):
    """Approximate chi-square and its lower bound for every (period, phase) of one axis.

    ``fp`` (T, B, n + 3): the tables per time and band, padded periodically (entry ``j +
    1`` is angle ``j``); ``ep`` (T, B, n): the error estimate per cell; the values sorted
    by time (``v_start`` (T + 1,) their offsets); ``cells`` the candidates (flat indices
    into periods x phases); ``out`` (2, cells): the approximation and the bound.  Time
    outer, candidates inner: one time's rows stay in cache while every candidate reads
    them.
    """
    n = ep.shape[2]
    n_q = phases.shape[0]
    n_groups = syy.shape[0]
    acc = np.zeros((cells.shape[0], n_groups, 3))
    for ti in range(times.shape[0]):
        a0, a1 = v_start[ti], v_start[ti + 1]
        if a1 == a0:
            continue
        fac = factor[ti]
        afac = abs(fac)
        for s in range(cells.shape[0]):
            p = cells[s] // n_q
            q = cells[s] - p * n_q
            x = (phases[q] * n / 360.0 + times[ti] * n / periods[p]) % n
            j = int(x)
            if j >= n:
                j = n - 1
            u = x - j
            u2 = u * u
            u3 = u2 * u
            c0 = 0.5 * (-u + 2.0 * u2 - u3)
            c1 = 1.0 + 0.5 * (3.0 * u3 - 5.0 * u2)
            c2 = 0.5 * (u + 4.0 * u2 - 3.0 * u3)
            c3 = 0.5 * (u3 - u2)
            for i in range(a0, a1):
                b = v_band[i]
                m = (
                    c0 * fp[ti, b, j]
                    + c1 * fp[ti, b, j + 1]
                    + c2 * fp[ti, b, j + 2]
                    + c3 * fp[ti, b, j + 3]
                ) * fac
                e = ep[ti, b, j] * afac
                g = v_group[i]
                wi = v_w[i]
                acc[s, g, 0] += wi * v_y[i] * m
                acc[s, g, 1] += wi * m * m
                acc[s, g, 2] += wi * e * e
    for s in range(cells.shape[0]):
        a = 0.0
        lb = 0.0
        for g in range(n_groups):
            c, r = lower_bound(syy[g], acc[s, g, 0], acc[s, g, 1], acc[s, g, 2])
            a += c
            lb += r
        out[0, s] = a
        out[1, s] = lb


def _axis_bounds(
    prob: Problem,
    axis: np.ndarray,
    periods: np.ndarray,
    phases: np.ndarray,
    n_angles: int,
    cells: np.ndarray,
) -> np.ndarray:
    """Approximation and bound (2, cells) of the candidates ``cells`` of one axis."""
    f = np.asarray(_tables(prob, axis, n_angles, False), dtype=np.float64)  # (T, n, B)
    eps = np.ascontiguousarray(table_errors(f).transpose(0, 2, 1))
    ft = f.transpose(0, 2, 1)
    fp = np.ascontiguousarray(np.concatenate([ft[..., -1:], ft, ft[..., :2]], axis=-1))
    order = np.argsort(prob.t_index, kind="stable")
    group = (prob.band if prob.offset == "band" else np.zeros_like(prob.band))[order]
    y, w = np.asarray(prob.y, np.float64), np.asarray(prob.w, np.float64)
    syy = np.bincount(group, weights=(w * y * y)[order], minlength=prob.n_scales)
    out = np.empty((2, cells.size))
    _bound_axis(
        fp,
        eps,
        np.asarray(prob.times, dtype=np.float64),
        np.searchsorted(prob.t_index[order], np.arange(prob.times.size + 1)).astype(np.int64),
        np.asarray(prob.band[order], dtype=np.int64),
        np.asarray(group, dtype=np.int64),
        np.ascontiguousarray(y[order]),
        np.ascontiguousarray(w[order]),
        np.asarray(prob.factor, dtype=np.float64),
        np.asarray(periods, dtype=np.float64),
        np.asarray(phases, dtype=np.float64),
        np.ascontiguousarray(cells, dtype=np.int64),
        syy,
        out,
    )
    return out


def _kth(best: np.ndarray, k: int) -> float:
    return float(np.partition(best, k - 1)[k - 1]) if best.size >= k else np.inf


def search_bound(
    prob: Problem,
    axes: np.ndarray,
    periods: np.ndarray,
    phases: np.ndarray,
    n_threads: int | None,
    n_angles: int,
    n_best: int = 1,
    batch: int = 256,
    stride: int = STRIDE,
) -> BoundSearch:
    """Chi-square over the grid by branch and bound (see the module): exact at the
    ``n_best`` best axes' best states (and every candidate that could still beat them).

    Axes first on every ``stride``-th time (a chi-square over fewer values is a lower bound
    of the full one): axes whose every bound exceeds the threshold there get no full tables.

    Examples
    --------
    See :func:`sbrdf_xr.invert.fit_spin` with ``method="bound"``.
    """
    n_angles = n_angles + n_angles % 2
    shape = (len(axes), len(periods), len(phases))
    k = max(1, min(int(n_best), shape[0]))
    approx = np.empty(shape)
    lower = np.zeros(shape)
    grid = np.empty(shape)
    exact = np.zeros(shape, dtype=bool)
    best_axis = np.full(shape[0], np.inf)

    every = np.arange(shape[1] * shape[2])
    tau = np.inf

    def fill(pr: Problem, which: np.ndarray) -> None:
        def run(j: int) -> None:
            a, low = approx[which[j]].reshape(-1), lower[which[j]].reshape(-1)
            cells = every[low <= tau * (1 + SLACK)]  # only candidates that can still win
            a[cells], new = _axis_bounds(pr, axes[which[j]], periods, phases, n_angles, cells)
            low[cells] = np.maximum(low[cells], new)

        _map(run, len(which), n_threads)

    def evaluate(flat: np.ndarray) -> None:
        ia, ip, iq = np.unravel_index(flat, shape)
        c2 = _exact(prob, axes[ia], periods[ip], phases[iq], n_threads)
        grid[ia, ip, iq] = c2
        exact[ia, ip, iq] = True
        np.minimum.at(best_axis, ia, c2)

    alive = np.arange(shape[0])
    if stride > 1 and prob.times.size // stride >= MIN_TIMES:
        sub = prob.subset(prob.times.size // stride)
        fill(sub, alive)
        approx *= prob.y.size / sub.y.size  # a rough whole-curve value, for the map only
        per_axis = approx.reshape(shape[0], -1)
        first = np.argsort(per_axis.min(axis=1), kind="stable")[: 2 * k]
        evaluate(first * per_axis.shape[1] + per_axis[first].argmin(axis=1))
        tau = _kth(best_axis, k)
        alive = np.flatnonzero(lower.reshape(shape[0], -1).min(axis=1) <= tau * (1 + SLACK))
    fill(prob, alive)
    grid[~exact] = approx[~exact]
    flat_lower = lower.reshape(-1)
    order = np.argsort(flat_lower, kind="stable")
    pos, size = 0, k
    while pos < order.size:
        tau = _kth(best_axis, k)
        if flat_lower[order[pos]] > tau * (1 + SLACK):
            break
        take = order[pos : pos + size]
        pos += take.size
        size = min(2 * size, batch)  # the first few decide the threshold: then wider
        ia = take // (shape[1] * shape[2])
        bar = np.minimum(best_axis[ia], tau) * (1 + SLACK)
        need = (flat_lower[take] <= bar) & ~exact.reshape(-1)[take]
        if need.any():
            evaluate(take[need])
    return BoundSearch(grid, lower, exact, int(exact.sum()), _kth(best_axis, k))


def _exact(
    prob: Problem, axes: np.ndarray, periods: np.ndarray, phases: np.ndarray, n_threads: Any
) -> np.ndarray:
    """Exact chi-square of listed candidates (each its own axis, period, phase), in blocks
    through the kernel as the ``direct`` search."""
    per = 8 * prob.times.size * (6 + 2 * prob.n_bands) + 8 * 4 * prob.y.size
    chunk = max(1, min(4096, BLOCK_BYTES // per, -(-len(axes) // _threads(n_threads))))
    edges = [*range(0, len(axes), chunk), len(axes)]
    out = np.empty(len(axes))

    def run(j: int) -> None:
        sl = slice(edges[j], edges[j + 1])
        out[sl] = prob.chi2(axes[sl], periods[sl], phases[sl])

    _map(run, len(edges) - 1, n_threads)
    return out


def bound_violations(
    prob: Problem,
    axes: np.ndarray,
    periods: np.ndarray,
    phases: np.ndarray,
    n_angles: int,
    n_samples: int = 64,
    seed: int = 0,
) -> tuple[int, int, float]:
    """Check of the error estimate against the kernel at ``n_samples`` random candidates:
    (values beyond their ``eps``, values checked, largest ``|m - m~| / eps``).

    Examples
    --------
    See ``tests/invert/test_spin_bound.py``.
    """
    n_angles = n_angles + n_angles % 2
    rng = np.random.default_rng(seed)
    bad, seen, worst = 0, 0, 0.0
    n = n_angles
    for _ in range(n_samples):
        ia = int(rng.integers(len(axes)))
        per = float(periods[rng.integers(len(periods))])
        ph = float(phases[rng.integers(len(phases))])
        f = _tables(prob, axes[ia], n, False)
        eps = table_errors(f)
        m = prob.model(axes[ia : ia + 1], np.array([per]), np.array([ph]))[0]
        t = prob.times[prob.t_index]
        x = ((ph + 360.0 * t / per) % 360.0) * (n / 360.0)
        j = np.floor(x).astype(np.int64)
        u = x - j
        fo = f[prob.t_index, :, prob.band]
        i = np.arange(t.size)
        p0, p1, p2, p3 = (fo[i, (j + d) % n] for d in (-1, 0, 1, 2))
        v = p1 + 0.5 * u * (
            p2 - p0 + u * (2 * p0 - 5 * p1 + 4 * p2 - p3 + u * (3 * (p1 - p2) + p3 - p0))
        )
        fac = prob.factor[prob.t_index]
        err = np.abs(m - v * fac)
        lim = eps[prob.t_index, j % n, prob.band] * np.abs(fac)
        bad += int(np.sum(err > lim))
        seen += err.size
        worst = max(worst, float(np.max(err / np.maximum(lim, 1e-300))))
    return bad, seen, worst
