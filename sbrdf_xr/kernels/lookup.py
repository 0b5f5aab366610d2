"""The look-up and the accumulation shared by the compiled kernels
(:mod:`sbrdf_xr.kernels.sums`, :mod:`sbrdf_xr.kernels.anisotropic`).

* an axis of a material's table (:class:`_Axis`, read from the packed grids by
  :func:`_material_axes`), the cell of an angle from its bucket map and the node
  weights of ``lut.axis_weights`` along it (:func:`_cell`, :func:`_axis`);

* the out-of-range policy of ``lut.lookup_matrix`` (:func:`_range_limits` once per
  material, :func:`_outside` per pair);
* the table rows and weights of one look-up in ``(theta_i, delta_theta, phi)``
  (:func:`_lookup_rows`) and the periodic linear cell in ``psi``
  (``anisotropy.psi_weights``, :func:`_psi_cell`);
* the accumulation: the weighted sum of table rows into the spectral accumulators
  (:func:`_gather`, :func:`_gather8`).

The kernels take their arguments as named tuples (:mod:`sbrdf_xr.kernels.packing`) and
unpack them once.  What runs per (geometry, term) pair takes scalars and as few arrays
as it can: an array handed to an inlined helper costs a reference count on every call
(measured: a helper adding a pair's areas into the output arrays made the band-only
kernel 30 % slower), so the pair's areas are added in the kernels' own loops.
"""

from __future__ import annotations

from typing import NamedTuple

import numba

from ..geometry.anisotropy import PSI_PERIOD

__all__: list[str] = []


class _Axis(NamedTuple):
    """Axis ``axis`` (0, 1, 2: ``theta_i``, ``delta_theta``, ``phi``) of one material's
    table: the nodes ``grid[lo : lo + n]`` and the bucket map
    ``bmap[axis, blo : blo + nb]`` of inverse bucket width ``binv``
    (:func:`sbrdf_xr.kernels.packing.bucket_map`) of the packed grid and map arrays,
    which travel beside it (a named tuple of arrays passed to a helper costs a reference
    count per array on every call)."""

    axis: int
    lo: int
    n: int
    blo: int
    nb: int
    binv: float


@numba.njit(nogil=True, cache=True, inline="always")
def _material_axes(t_off, d_off, p_off, b_off, binv, m):  # pragma: no cover - compiled
    """The ``(theta_i, delta_theta, phi)`` axes of material ``m`` of packed grids
    (:class:`sbrdf_xr.kernels.packing.TableGrids`)."""
    return (
        _Axis(
            0,
            t_off[m],
            t_off[m + 1] - t_off[m],
            b_off[0, m],
            b_off[0, m + 1] - b_off[0, m],
            binv[0, m],
        ),
        _Axis(
            1,
            d_off[m],
            d_off[m + 1] - d_off[m],
            b_off[1, m],
            b_off[1, m + 1] - b_off[1, m],
            binv[1, m],
        ),
        _Axis(
            2,
            p_off[m],
            p_off[m + 1] - p_off[m],
            b_off[2, m],
            b_off[2, m + 1] - b_off[2, m],
            binv[2, m],
        ),
    )


@numba.njit(nogil=True, cache=True, inline="always")
def _clip(grid, ax, x: float) -> float:  # pragma: no cover - compiled
    """``x`` clipped to the axis' first and last node."""
    if x < grid[ax.lo]:
        return grid[ax.lo]
    if x > grid[ax.lo + ax.n - 1]:
        return grid[ax.lo + ax.n - 1]
    return x


@numba.njit(nogil=True, cache=True, inline="always")
def _cell(grid, bmap, ax, x: float) -> tuple[int, float]:  # pragma: no cover - compiled
    """The cell ``i`` of ``x`` (clipped to the grid) on an axis of ``n >= 2`` nodes and
    the fraction ``t`` within it: ``searchsorted(grid, x, "right") - 1`` clipped to
    ``[0, n - 2]``, from the bucket map (:func:`bucket_map`) and comparisons with the
    nodes (no binary search's unpredictable branches)."""
    lo, n = ax.lo, ax.n
    x = _clip(grid, ax, x)
    kb = int((x - grid[lo]) * ax.binv)
    if kb < 0:
        kb = 0
    elif kb > ax.nb - 1:
        kb = ax.nb - 1
    i = bmap[ax.axis, ax.blo + kb]
    while i < n - 1 and grid[lo + i + 1] <= x:
        i += 1
    while i > 0 and grid[lo + i] > x:
        i -= 1
    if i > n - 2:
        i = n - 2
    return i, (x - grid[lo + i]) / (grid[lo + i + 1] - grid[lo + i])


@numba.njit(nogil=True, cache=True, inline="always")
def _axis(grid, bmap, ax, x, method, idx, w):  # pragma: no cover - compiled
    """Node indices and weights along one axis (``lut.axis_weights``) into the axis' row
    of the ``(3, 4)`` arrays ``idx`` and ``w``; returns the count.

    The cell is found from the axis' bucket map (:func:`bucket_map`) and corrected by
    comparisons with the nodes, so it is exactly ``searchsorted(grid, x, "right") - 1``
    without a binary search's unpredictable branches.
    """
    x = _clip(grid, ax, x)
    n, a = ax.n, ax.axis
    if n == 1:
        idx[a, 0] = 0
        w[a, 0] = 1.0
        return 1
    i, t = _cell(grid, bmap, ax, x)
    if method == 0:
        idx[a, 0] = i + 1 if t >= 0.5 else i
        w[a, 0] = 1.0
        return 1
    if method == 1:
        idx[a, 0] = i
        idx[a, 1] = i + 1
        w[a, 0] = 1.0 - t
        w[a, 1] = t
        return 2
    k = 4 if n >= 4 else n
    j0 = i - 1
    if j0 < 0:
        j0 = 0
    elif j0 > n - k:
        j0 = n - k
    for p in range(k):
        idx[a, p] = j0 + p
        w[a, p] = 1.0
    for p in range(k):
        xp = grid[ax.lo + j0 + p]
        for q in range(k):
            if p != q:
                xq = grid[ax.lo + j0 + q]
                w[a, p] *= (x - xq) / (xp - xq)
    return k


@numba.njit(nogil=True, cache=True, inline="always")
def _range_limits(dgrid, pgrid, axes, edges, m):  # pragma: no cover - compiled
    """Material ``m``'s out-of-range policy as scalars for :func:`_outside`: its three
    flags (zero beyond ``delta_theta`` below, above, beyond ``phi`` above) and the grid
    ends they refer to [degree]."""
    d, p = axes[1], axes[2]
    return (
        edges[m, 0],
        edges[m, 1],
        edges[m, 2],
        dgrid[d.lo],
        dgrid[d.lo + d.n - 1],
        pgrid[p.lo + p.n - 1],
    )


@numba.njit(nogil=True, cache=True, inline="always")
def _outside(limits, dt, phi, edge_tol):  # pragma: no cover - compiled
    """The out-of-range policy of ``lut.lookup_matrix`` at ``(delta_theta, phi)``
    [degree] with the :func:`_range_limits` of the material."""
    e_lo, e_hi, e_phi, d_lo, d_hi, p_hi = limits
    return (
        (e_lo and dt < d_lo - edge_tol)
        or (e_hi and dt > d_hi + edge_tol)
        or (e_phi and phi > p_hi + edge_tol)
    )


@numba.njit(nogil=True, cache=True)
def _lookup_rows(
    tgrid, dgrid, pgrid, bmap, axes, ti, dt, phi, method, idx, w, rows, wn, scale
):  # pragma: no cover - compiled
    """The rows of one look-up at ``(theta_i, delta_theta, phi)`` [degree] and their
    weights times ``scale``, into ``rows`` and ``wn`` from the start (``idx``, ``w``:
    ``(3, 4)`` work arrays of the axes); returns the count."""
    kt = _axis(tgrid, bmap, axes[0], ti, method, idx, w)
    kd = _axis(dgrid, bmap, axes[1], dt, method, idx, w)
    kp = _axis(pgrid, bmap, axes[2], phi, method, idx, w)
    nd, npp = axes[1].n, axes[2].n
    nk = 0
    for a in range(kt):
        for b in range(kd):
            row0 = (idx[0, a] * nd + idx[1, b]) * npp
            wab = w[0, a] * w[1, b] * scale
            for c in range(kp):
                rows[nk] = row0 + idx[2, c]
                wn[nk] = wab * w[2, c]
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
