"""The look-up and the accumulation shared by the compiled kernels
(:mod:`sbrdf_xr.kernels.sums`, :mod:`sbrdf_xr.kernels.anisotropic`).

* an axis of a material's table (:class:`_Axis`, read from the packed grids by
  :func:`_material_axes`), the cell of an angle from its bucket map and the node
  weights of ``lut.axis_weights`` along it (:func:`_cell`, :func:`_axis`);
* the out-of-range policy of ``lut.lookup_matrix`` (:func:`_outside`);
* the table rows and weights of one look-up in ``(theta_i, delta_theta, phi)``
  (:func:`_lookup_rows`) and the periodic linear cell in ``psi``
  (``anisotropy.psi_weights``, :func:`_psi_cell`);
* the accumulation: the lit-and-visible areas of a pair (:func:`_add_areas`), and the
  weighted sum of table rows into the spectral accumulators (:func:`_gather`,
  :func:`_gather8`).
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np

from ..anisotropy import PSI_PERIOD

__all__: list[str] = []


class _Axis(NamedTuple):
    """One axis of one material's table as the kernels read it: the nodes
    ``grid[lo : lo + n]`` and the bucket map ``bmap[blo : blo + nb]`` of inverse bucket
    width ``binv`` (:func:`sbrdf_xr.kernels.packing.bucket_map`)."""

    grid: np.ndarray
    lo: int
    n: int
    bmap: np.ndarray
    blo: int
    nb: int
    binv: float


class _Scratch(NamedTuple):
    """A kernel's work buffers: node indices and weights of the three axes (up to 4
    each), the rows and weights of one look-up and a spectrum."""

    it: np.ndarray
    wt: np.ndarray
    idt: np.ndarray
    wdt: np.ndarray
    iph: np.ndarray
    wph: np.ndarray
    rows: np.ndarray
    wn: np.ndarray
    f: np.ndarray


@numba.njit(nogil=True, cache=True)
def _scratch(n_rows, n_wl, dtype):  # pragma: no cover - compiled
    """Buffers for ``n_rows`` rows per look-up and ``n_wl`` wavelengths (weights of the
    rows and the spectrum in ``dtype``, the dtype of the tables)."""
    return _Scratch(
        np.empty(4, dtype=np.int64),
        np.empty(4),
        np.empty(4, dtype=np.int64),
        np.empty(4),
        np.empty(4, dtype=np.int64),
        np.empty(4),
        np.empty(n_rows, dtype=np.int64),
        np.empty(n_rows, dtype=dtype),
        np.empty(n_wl, dtype=dtype),
    )


@numba.njit(nogil=True, cache=True, inline="always")
def _material_axes(grids, m):  # pragma: no cover - compiled
    """The ``(theta_i, delta_theta, phi)`` axes of material ``m`` of packed grids
    (:class:`sbrdf_xr.kernels.packing.TableGrids`)."""
    b = grids.b_off
    return (
        _Axis(
            grids.tgrid,
            grids.t_off[m],
            grids.t_off[m + 1] - grids.t_off[m],
            grids.bmap[0],
            b[0, m],
            b[0, m + 1] - b[0, m],
            grids.binv[0, m],
        ),
        _Axis(
            grids.dgrid,
            grids.d_off[m],
            grids.d_off[m + 1] - grids.d_off[m],
            grids.bmap[1],
            b[1, m],
            b[1, m + 1] - b[1, m],
            grids.binv[1, m],
        ),
        _Axis(
            grids.pgrid,
            grids.p_off[m],
            grids.p_off[m + 1] - grids.p_off[m],
            grids.bmap[2],
            b[2, m],
            b[2, m + 1] - b[2, m],
            grids.binv[2, m],
        ),
    )


@numba.njit(nogil=True, cache=True, inline="always")
def _first(ax):  # pragma: no cover - compiled
    return ax.grid[ax.lo]


@numba.njit(nogil=True, cache=True, inline="always")
def _last(ax):  # pragma: no cover - compiled
    return ax.grid[ax.lo + ax.n - 1]


@numba.njit(nogil=True, cache=True, inline="always")
def _clip(ax, x: float) -> float:  # pragma: no cover - compiled
    """``x`` clipped to the axis' first and last node."""
    if x < ax.grid[ax.lo]:
        return ax.grid[ax.lo]
    if x > ax.grid[ax.lo + ax.n - 1]:
        return ax.grid[ax.lo + ax.n - 1]
    return x


@numba.njit(nogil=True, cache=True, inline="always")
def _cell(ax, x: float) -> tuple[int, float]:  # pragma: no cover - compiled
    """The cell ``i`` of ``x`` (clipped to the grid) on an axis of ``n >= 2`` nodes and
    the fraction ``t`` within it: ``searchsorted(grid, x, "right") - 1`` clipped to
    ``[0, n - 2]``, from the bucket map (:func:`bucket_map`) and comparisons with the
    nodes (no binary search's unpredictable branches)."""
    grid, lo, n = ax.grid, ax.lo, ax.n
    x = _clip(ax, x)
    kb = int((x - grid[lo]) * ax.binv)
    if kb < 0:
        kb = 0
    elif kb > ax.nb - 1:
        kb = ax.nb - 1
    i = ax.bmap[ax.blo + kb]
    while i < n - 1 and grid[lo + i + 1] <= x:
        i += 1
    while i > 0 and grid[lo + i] > x:
        i -= 1
    if i > n - 2:
        i = n - 2
    return i, (x - grid[lo + i]) / (grid[lo + i + 1] - grid[lo + i])


@numba.njit(nogil=True, cache=True, inline="always")
def _axis(ax, x: float, method: int, idx: np.ndarray, w: np.ndarray) -> int:  # pragma: no cover
    """Node indices and weights along one axis (``lut.axis_weights``); returns the count.

    The cell is found from the axis' bucket map (:func:`bucket_map`) and corrected by
    comparisons with the nodes, so it is exactly ``searchsorted(grid, x, "right") - 1``
    without a binary search's unpredictable branches.
    """
    x = _clip(ax, x)
    n = ax.n
    if n == 1:
        idx[0] = 0
        w[0] = 1.0
        return 1
    i, t = _cell(ax, x)
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
        xp = ax.grid[ax.lo + j0 + p]
        for q in range(k):
            if p != q:
                xq = ax.grid[ax.lo + j0 + q]
                w[p] *= (x - xq) / (xp - xq)
    return k


@numba.njit(nogil=True, cache=True, inline="always")
def _outside(axes, edges, dt: float, phi: float, edge_tol: float) -> bool:  # pragma: no cover
    """The out-of-range policy of ``lut.lookup_matrix``: zero beyond the
    ``delta_theta`` grid below or above, or beyond the ``phi`` grid, where the
    material's ``edges`` (three flags) say so."""
    return (
        (edges[0] and dt < _first(axes[1]) - edge_tol)
        or (edges[1] and dt > _last(axes[1]) + edge_tol)
        or (edges[2] and phi > _last(axes[2]) + edge_tol)
    )


@numba.njit(nogil=True, cache=True, inline="always")
def _lookup_rows(axes, ti, dt, phi, method, sc, scale):  # pragma: no cover - compiled
    """The rows of one look-up at ``(theta_i, delta_theta, phi)`` [degree] and their
    weights times ``scale``, into ``sc.rows`` and ``sc.wn`` from the start; returns the
    count."""
    kt = _axis(axes[0], ti, method, sc.it, sc.wt)
    kd = _axis(axes[1], dt, method, sc.idt, sc.wdt)
    kp = _axis(axes[2], phi, method, sc.iph, sc.wph)
    nd, npp = axes[1].n, axes[2].n
    nk = 0
    for a in range(kt):
        for b in range(kd):
            row0 = (sc.it[a] * nd + sc.idt[b]) * npp
            wab = sc.wt[a] * sc.wdt[b] * scale
            for c in range(kp):
                sc.rows[nk] = row0 + sc.iph[c]
                sc.wn[nk] = wab * sc.wph[c]
                nk += 1
    return nk


@numba.njit(nogil=True, cache=True, inline="always")
def _psi_cell(nodes, closed, psi):  # pragma: no cover - compiled
    """The two ``psi`` nodes around ``psi`` [degree] and the weight of the second
    (``anisotropy.psi_weights``: linear, periodic over 180 degree)."""
    n_psi = nodes.size
    x = nodes[0] + (psi - nodes[0]) % PSI_PERIOD
    if x >= nodes[0] + PSI_PERIOD:
        x = nodes[0]
    if n_psi == 1:
        return 0, 0, 0.0
    last = n_psi - 1 if closed else n_psi
    k0 = 0
    while k0 + 1 < last and nodes[k0 + 1] <= x:
        k0 += 1
    lo = nodes[k0]
    hi = nodes[k0 + 1] if k0 + 1 < n_psi else nodes[0] + PSI_PERIOD
    k1 = k0 + 1 if k0 + 1 < n_psi else 0
    w1 = (x - lo) / (hi - lo)
    if w1 < 0.0:
        w1 = 0.0
    elif w1 > 1.0:
        w1 = 1.0
    return k0, k1, w1


@numba.njit(nogil=True, cache=True, inline="always")
def _add_areas(out, facets, has_frac, g, tt, no):  # pragma: no cover - compiled
    """Add a lit and seen pair's areas to ``out.area`` (``a_2D = a c cos(theta_r)``) and
    ``out.lit_visible_area`` (``a c``) of geometry ``g``; returns ``a_2D`` [m2]."""
    a_eff = facets.area[tt]
    if has_frac:
        a_eff = a_eff * facets.fraction[g, tt]
    a2d = a_eff * no
    out.area[g] += a2d
    out.lit_visible_area[g] += a_eff
    return a2d


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
