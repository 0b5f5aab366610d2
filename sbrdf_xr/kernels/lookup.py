"""Look-up helpers of the compiled kernels (:mod:`sbrdf_xr.kernels.sums`,
:mod:`sbrdf_xr.kernels.anisotropic`): the grid cell of an angle from its axis' bucket map,
the node weights of ``_lut.axis_weights`` along one axis, and the weighted sum of table
rows into the spectral accumulators.
"""

from __future__ import annotations

import numba
import numpy as np

__all__: list[str] = []


@numba.njit(nogil=True, cache=True, inline="always")
def _clip(grid: np.ndarray, lo: int, n: int, x: float) -> float:  # pragma: no cover - compiled
    """``x`` clipped to the axis' first and last node."""
    if x < grid[lo]:
        return grid[lo]
    if x > grid[lo + n - 1]:
        return grid[lo + n - 1]
    return x


@numba.njit(nogil=True, cache=True, inline="always")
def _cell(
    grid: np.ndarray, lo: int, n: int, x: float, bmap: np.ndarray, blo: int, nb: int, binv: float
) -> tuple[int, float]:  # pragma: no cover - compiled
    """The cell ``i`` of ``x`` (clipped to the grid) on a grid of ``n >= 2`` nodes and the
    fraction ``t`` within it: ``searchsorted(grid, x, "right") - 1`` clipped to
    ``[0, n - 2]``, from the bucket map (:func:`bucket_map`) and comparisons with the
    nodes (no binary search's unpredictable branches)."""
    x = _clip(grid, lo, n, x)
    kb = int((x - grid[lo]) * binv)
    if kb < 0:
        kb = 0
    elif kb > nb - 1:
        kb = nb - 1
    i = bmap[blo + kb]
    while i < n - 1 and grid[lo + i + 1] <= x:
        i += 1
    while i > 0 and grid[lo + i] > x:
        i -= 1
    if i > n - 2:
        i = n - 2
    return i, (x - grid[lo + i]) / (grid[lo + i + 1] - grid[lo + i])


@numba.njit(nogil=True, cache=True, inline="always")
def _axis(
    grid: np.ndarray,
    lo: int,
    n: int,
    x: float,
    method: int,
    idx: np.ndarray,
    w: np.ndarray,
    bmap: np.ndarray,
    blo: int,
    nb: int,
    binv: float,
) -> int:  # pragma: no cover - compiled
    """Node indices and weights along one axis (``_lut.axis_weights``); returns the count.

    The cell is found from the axis' bucket map (:func:`bucket_map`) and corrected by
    comparisons with the nodes, so it is exactly ``searchsorted(grid, x, "right") - 1``
    without a binary search's unpredictable branches.
    """
    x = _clip(grid, lo, n, x)
    if n == 1:
        idx[0] = 0
        w[0] = 1.0
        return 1
    i, t = _cell(grid, lo, n, x, bmap, blo, nb, binv)
    if method == 0:
        idx[0] = i + 1 if t >= 0.5 else i
        w[0] = 1.0
        return 1
    if method == 1:
        idx[0] = i
        idx[1] = i + 1
        w[0] = 1.0 - t
        w[1] = t
        return 2
    k = 4 if n >= 4 else n
    j0 = i - 1
    if j0 < 0:
        j0 = 0
    elif j0 > n - k:
        j0 = n - k
    for p in range(k):
        idx[p] = j0 + p
        w[p] = 1.0
    for p in range(k):
        xp = grid[lo + j0 + p]
        for q in range(k):
            if p != q:
                xq = grid[lo + j0 + q]
                w[p] *= (x - xq) / (xp - xq)
    return k


@numba.njit(nogil=True, cache=True, inline="always")
def _gather8(values, r, sd, st, wn, acc_s, acc_p, ws, wp):  # pragma: no cover - compiled
    """:func:`_gather` of the 8 rows of a trilinear look-up, the cell's corner ``r`` and the
    row steps ``sd`` (delta_theta) and ``st`` (theta_i), summed as :func:`_gather` sums
    them (the first four rows, then the last four)."""
    n_wl = values.shape[1]
    w0, w1, w2, w3 = wn[0], wn[1], wn[2], wn[3]
    w4, w5, w6, w7 = wn[4], wn[5], wn[6], wn[7]
    r2 = r + sd
    r4 = r + st
    r6 = r4 + sd
    for k in range(n_wl):
        f = (w0 * values[r, k] + w1 * values[r + 1, k]) + (
            w2 * values[r2, k] + w3 * values[r2 + 1, k]
        )
        v = f + (
            (w4 * values[r4, k] + w5 * values[r4 + 1, k])
            + (w6 * values[r6, k] + w7 * values[r6 + 1, k])
        )
        acc_s[k] += ws * v
        acc_p[k] += wp * v


@numba.njit(nogil=True, cache=True)
def _gather(values, rows, wn, nk, f, acc_s, acc_p, ws, wp):  # pragma: no cover - compiled
    """``acc_s += ws * sum_n wn[n] values[rows[n]]`` and likewise ``acc_p`` with ``wp``.

    Four table rows per pass over the spectrum (fewer loads and stores of ``f``);
    the last pass adds straight into the accumulators.
    """
    n_wl = values.shape[1]
    n4 = nk - nk % 4
    n = 0
    started = False
    while n < nk:
        last = (n + 4 >= nk) if n < n4 else (n + 1 == nk)
        if n < n4:
            r0, r1, r2, r3 = rows[n], rows[n + 1], rows[n + 2], rows[n + 3]
            w0, w1, w2, w3 = wn[n], wn[n + 1], wn[n + 2], wn[n + 3]
            if last and not started:
                for k in range(n_wl):
                    v = (w0 * values[r0, k] + w1 * values[r1, k]) + (
                        w2 * values[r2, k] + w3 * values[r3, k]
                    )
                    acc_s[k] += ws * v
                    acc_p[k] += wp * v
            elif last:
                for k in range(n_wl):
                    v = f[k] + (
                        (w0 * values[r0, k] + w1 * values[r1, k])
                        + (w2 * values[r2, k] + w3 * values[r3, k])
                    )
                    acc_s[k] += ws * v
                    acc_p[k] += wp * v
            elif not started:
                for k in range(n_wl):
                    f[k] = (w0 * values[r0, k] + w1 * values[r1, k]) + (
                        w2 * values[r2, k] + w3 * values[r3, k]
                    )
            else:
                for k in range(n_wl):
                    f[k] += (w0 * values[r0, k] + w1 * values[r1, k]) + (
                        w2 * values[r2, k] + w3 * values[r3, k]
                    )
            n += 4
        else:
            r0 = rows[n]
            w0 = wn[n]
            if last and not started:
                for k in range(n_wl):
                    v = w0 * values[r0, k]
                    acc_s[k] += ws * v
                    acc_p[k] += wp * v
            elif last:
                for k in range(n_wl):
                    v = f[k] + w0 * values[r0, k]
                    acc_s[k] += ws * v
                    acc_p[k] += wp * v
            elif not started:
                for k in range(n_wl):
                    f[k] = w0 * values[r0, k]
            else:
                for k in range(n_wl):
                    f[k] += w0 * values[r0, k]
            n += 1
        started = True
