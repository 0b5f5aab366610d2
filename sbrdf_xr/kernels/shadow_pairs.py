"""The exact shadow method by a table of the pairs that can shadow each other (numba, nogil).

The grid kernel of :mod:`sbrdf_xr.kernels.shadow` finds the candidate occluders of every
facet anew for every direction.  Most of that work does not depend on the direction, so
it is done once per body (:func:`sbrdf_xr.kernels.pair_table.pair_table`): every
receiving facet's occluders, cut and stored in its frame as ``(u, v, h)`` with the box of
slopes ``s = (E1_i.d, E2_i.d) / N_i.d`` from which each can reach it.  Here, per direction,
a pair costs a box test and its shadow four flops per vertex, ``(u - h s_1, v - h s_2)``;
a facet's pairs are sorted by the distance of their box from ``s = 0``, so a direction
high above the facet stops early.  A shadow covering the facet whole stops it at once.
The shadows along the ``K`` directions of a geometry, clipped to the facet, are united as
in :func:`sbrdf_xr.kernels.shadow.exact_kernel` (one: its area; two or three:
inclusion-exclusion), or from :data:`PIECES_FROM` on as a sum of lit pieces
(:func:`lit_area`), whose terms are all positive.  The skipped pairs are those whose
shadow is empty (a relative margin of :data:`~sbrdf_xr.kernels.pair_table.MARGIN` on the
box), so the result is the grid kernel's to float rounding.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from .polygon import MAXM, MAXV, clip, signed_area, union_area_boxes, union_area_slabs
from .shadow import MAX_SHADOWS

__all__ = ["PIECES_FROM", "SMALL_UNION", "lit_area", "pairs_kernel"]

_SHADOW = 16  # vertices of a clipped shadow: at most (occluder vertices + 1) + 3
#: Shadows on one facet from which their union is taken as lit pieces, not by
#: inclusion-exclusion (whose alternating sum loses ~1e-16 of its terms' total).
PIECES_FROM = 4
#: Shadows on one facet at most united by inclusion-exclusion clipped directly (at most
#: 7 terms).
SMALL_UNION = 3
_PIECES = 256  # lit pieces held (more: inclusion-exclusion, then slabs)
_CHUNK = 512  # geometries whose facing flags are held while each receiver runs through them


@nb.njit(cache=True, nogil=True)
def _shadow(cut, p, n, s1, s2, cx, cy, area_t, px, py, ox, oy, tx, ty):
    """The cut occluder p (rows u, v, h) projected with slopes (s1, s2) and clipped to the
    triangle (cx, cy), written to (ox, oy) counter-clockwise (convex up to rounding);
    returns its vertex count, 0 if it has no area, -1 if it covers the whole triangle."""
    for v in range(n):
        px[v] = cut[p, v, 0] - cut[p, v, 2] * s1
        py[v] = cut[p, v, 1] - cut[p, v, 2] * s2
    within = True  # every vertex inside (or on) the facet: no clipping to do
    for e in range(3):  # all of it outside one edge of the facet: no overlap
        e1 = e + 1 if e < 2 else 0
        ex = cx[e1] - cx[e]
        ey = cy[e1] - cy[e]
        outside = True
        for v in range(n):
            side = ex * (py[v] - cy[e]) - ey * (px[v] - cx[e])
            if side > 0.0:
                outside = False
            elif side < 0.0:
                within = False
        if outside:
            return 0
    if signed_area(px, py, n) < 0.0:  # make it counter-clockwise
        for v in range(n // 2):
            px[v], px[n - 1 - v] = px[n - 1 - v], px[v]
            py[v], py[n - 1 - v] = py[n - 1 - v], py[v]
    if within:
        for v in range(n):
            ox[v] = px[v]
            oy[v] = py[v]
        return n if signed_area(ox, oy, n) > 1e-15 * area_t else 0
    inside = True  # every corner of the facet inside (or on) the convex shadow: all of it
    for v in range(n):
        v1 = v + 1 if v + 1 < n else 0
        ex = px[v1] - px[v]
        ey = py[v1] - py[v]
        for c in range(3):
            if ex * (cy[c] - py[v]) - ey * (cx[c] - px[v]) < 0.0:
                inside = False
                break
        if not inside:
            break
    if inside:
        return -1
    nc = clip(px, py, n, cx, cy, 3, ox, oy, tx, ty)
    if nc < 3 or signed_area(ox, oy, nc) <= 1e-15 * area_t:
        return 0
    return nc


@nb.njit(cache=True, nogil=True)
def _scan(px, py, n, ox, oy):
    """Convex hull of a polygon convex up to rounding (counter-clockwise; duplicate,
    collinear and slightly reflex vertices dropped), by Graham's scan in the polygon's own
    order from its lowest (then leftmost) vertex: its vertices are already sorted by angle
    about that vertex, so no sort is needed.  Written to (ox, oy); returns the count."""
    s0 = 0
    for v in range(1, n):
        if py[v] < py[s0] or (py[v] == py[s0] and px[v] < px[s0]):
            s0 = v
    m = 0
    for j in range(n + 1):
        v = s0 + j if s0 + j < n else s0 + j - n
        x = px[v]
        y = py[v]
        while (
            m >= 2
            and (ox[m - 1] - ox[m - 2]) * (y - oy[m - 2])
            - (oy[m - 1] - oy[m - 2]) * (x - ox[m - 2])
            <= 0.0
        ):
            m -= 1
        if j < n:
            ox[m] = x
            oy[m] = y
            m += 1
    return m


@nb.njit(cache=True, nogil=True)
def _convex(gx, gy, gn, m, tx, ty):
    """Replace each of the m clipped shadows that is not strictly convex (a clip is convex
    only up to rounding) by its convex hull (:func:`_scan`), as the inclusion-exclusion
    needs every edge line to support its polygon; returns the count left (hulls of no area
    dropped)."""
    kept = 0
    for k in range(m):
        n = gn[k]
        convex = True  # a left turn at every corner: convex already, every edge supporting
        for v in range(n):
            a = v - 1 if v > 0 else n - 1
            b = v + 1 if v + 1 < n else 0
            turn = (gx[k, v] - gx[k, a]) * (gy[k, b] - gy[k, v])
            if turn - (gy[k, v] - gy[k, a]) * (gx[k, b] - gx[k, v]) <= 0.0:
                convex = False
                break
        if convex:
            if kept < k:
                for v in range(n):
                    gx[kept, v] = gx[k, v]
                    gy[kept, v] = gy[k, v]
                gn[kept] = n
            kept += 1
            continue
        nq = _scan(gx[k], gy[k], n, tx, ty)
        if nq < 3:
            continue
        for v in range(nq):
            gx[kept, v] = tx[v]
            gy[kept, v] = ty[v]
        gn[kept] = nq
        kept += 1
    return kept


@nb.njit(cache=True, nogil=True)
def _half(sx, sy, n, ax, ay, ex, ey, side, ox, oy):
    """The part of the convex polygon (sx, sy, n) left of the line through (ax, ay) along
    (ex, ey) (``side`` 1.0) or right of it (``side`` -1.0), written to (ox, oy); returns its
    vertex count."""
    m = 0
    px = sx[n - 1]
    py = sy[n - 1]
    dp = side * (ex * (py - ay) - ey * (px - ax))
    for k in range(n):
        qx = sx[k]
        qy = sy[k]
        dq = side * (ex * (qy - ay) - ey * (qx - ax))
        if (dp > 0.0 and dq < 0.0) or (dp < 0.0 and dq > 0.0):
            t = dp / (dp - dq)
            ox[m] = px + t * (qx - px)
            oy[m] = py + t * (qy - py)
            m += 1
        if dq >= 0.0:
            ox[m] = qx
            oy[m] = qy
            m += 1
        px = qx
        py = qy
        dp = dq
    return m


@nb.njit(cache=True, nogil=True)
def lit_area(cx, cy, gx, gy, gn, m, tiny, ax, ay, an, bx, by, bn, tx, ty):
    """Area of the triangle (cx, cy) left by m convex counter-clockwise shadows, as a sum of
    convex lit pieces: each shadow ``P`` replaces every piece ``L`` it overlaps by the parts
    of ``L`` outside one edge line of ``P`` and inside the lines before it (``L \\ P`` for a
    convex ``P``).  No inclusion-exclusion: the lit area is a sum of positive terms, exact
    to rounding even where many shadows cover the facet.  Pieces of area <= ``tiny`` are
    dropped.  (ax, ay, an) and (bx, by, bn) hold the pieces (their rows bound how many);
    returns the area, or -1.0 if they would overflow.

    Examples
    --------
    The unit right triangle less the square [0, 0.5]^2 and the triangle above y = 0.75:
    0.5 - 0.25 - 0.03125.

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.shadow_pairs import lit_area
    >>> gx = np.array([[0.0, 0.5, 0.5, 0.0], [0.0, 0.25, 0.0, 0.0]])
    >>> gy = np.array([[0.0, 0.0, 0.5, 0.5], [0.75, 0.75, 1.0, 0.0]])
    >>> gn = np.array([4, 3])
    >>> a, b = (np.empty((64, 32)) for _ in range(2))
    >>> an, bn = np.empty(64, dtype=np.int64), np.empty(64, dtype=np.int64)
    >>> tx, ty = np.empty(32), np.empty(32)
    >>> cx, cy = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])
    >>> lit_area(cx, cy, gx, gy, gn, 2, 0.0, a, a.copy(), an, b, b.copy(), bn, tx, ty)
    0.21875
    """
    cap = an.shape[0]
    width = ax.shape[1]
    for c in range(3):
        ax[0, c] = cx[c]
        ay[0, c] = cy[c]
    an[0] = 3
    count = 1
    for k in range(m):
        n = gn[k]
        x0 = x1 = gx[k, 0]
        y0 = y1 = gy[k, 0]
        for v in range(1, n):
            x0 = min(x0, gx[k, v])
            x1 = max(x1, gx[k, v])
            y0 = min(y0, gy[k, v])
            y1 = max(y1, gy[k, v])
        out = 0
        for a in range(count):
            na = an[a]
            apart = True  # bounding boxes apart: the piece stays as it is
            for v in range(na):
                if ax[a, v] > x0 and ax[a, v] < x1 and ay[a, v] > y0 and ay[a, v] < y1:
                    apart = False
                    break
            if apart:
                lo_x = hi_x = ax[a, 0]
                lo_y = hi_y = ay[a, 0]
                for v in range(1, na):
                    lo_x = min(lo_x, ax[a, v])
                    hi_x = max(hi_x, ax[a, v])
                    lo_y = min(lo_y, ay[a, v])
                    hi_y = max(hi_y, ay[a, v])
                apart = lo_x >= x1 or hi_x <= x0 or lo_y >= y1 or hi_y <= y0
            if apart:
                if out == cap or na > width:
                    return -1.0
                for v in range(na):
                    bx[out, v] = ax[a, v]
                    by[out, v] = ay[a, v]
                bn[out] = na
                out += 1
                continue
            nr = na  # the rest of the piece, inside the edges so far: in tx, ty
            for v in range(na):
                tx[v] = ax[a, v]
                ty[v] = ay[a, v]
            for e in range(n):
                e1 = e + 1 if e + 1 < n else 0
                ex = gx[k, e1] - gx[k, e]
                ey = gy[k, e1] - gy[k, e]
                if out == cap or nr + 1 > width:
                    return -1.0
                no = _half(tx, ty, nr, gx[k, e], gy[k, e], ex, ey, -1.0, bx[out], by[out])
                if no >= 3 and signed_area(bx[out], by[out], no) > tiny:
                    bn[out] = no
                    out += 1
                if out == cap:
                    return -1.0
                nr = _half(tx, ty, nr, gx[k, e], gy[k, e], ex, ey, 1.0, bx[out], by[out])
                for v in range(nr):
                    tx[v] = bx[out, v]
                    ty[v] = by[out, v]
                if nr < 3:
                    break
        ax, bx = bx, ax
        ay, by = by, ay
        an, bn = bn, an
        count = out
    total = 0.0
    for a in range(count):
        total += signed_area(ax[a], ay[a], an[a])
    return total


@nb.njit(cache=True, nogil=True)
def _facing(dirs, g, normals, gnorm, gopen, occ, frac):
    """For geometry g: which occluders block each direction (``occ``), and 1 or 0 in
    ``frac[g]`` as each facet faces every direction or not."""
    for k in range(dirs.shape[1]):
        d0 = dirs[g, k, 0]
        d1 = dirs[g, k, 1]
        d2 = dirs[g, k, 2]
        for q in range(gnorm.shape[0]):
            nd = gnorm[q, 0] * d0 + gnorm[q, 1] * d1 + gnorm[q, 2] * d2
            occ[k, q] = nd < 0.0 or (nd > 0.0 and gopen[q])
    for f in range(normals.shape[0]):
        lit = 1.0
        for k in range(dirs.shape[1]):
            nd = normals[f, 0] * dirs[g, k, 0] + normals[f, 1] * dirs[g, k, 1]
            if nd + normals[f, 2] * dirs[g, k, 2] <= 0.0:
                lit = 0.0
        frac[g, f] = lit


@nb.njit(cache=True, nogil=True)
def _union_small(gx, gy, gn, m, tiny, bx, by, tx, ty):
    """Area of the union of m <= :data:`SMALL_UNION` convex counter-clockwise polygons by
    inclusion-exclusion, each intersection clipped directly into ``bx[depth]`` (the terms
    of :func:`~sbrdf_xr.kernels.polygon.union_area_boxes`, an intersection of area <=
    ``tiny`` dropped with its supersets, without its stack and boxes)."""
    total = 0.0
    for a in range(m):
        total += signed_area(gx[a], gy[a], gn[a])
        for b in range(a + 1, m):
            n1 = clip(gx[a], gy[a], gn[a], gx[b], gy[b], gn[b], bx[0], by[0], tx, ty)
            if n1 < 3:
                continue
            area = signed_area(bx[0], by[0], n1)
            if area <= tiny:
                continue
            total -= area
            for c in range(b + 1, m):
                n2 = clip(bx[0], by[0], n1, gx[c], gy[c], gn[c], bx[1], by[1], tx, ty)
                if n2 < 3:
                    continue
                area = signed_area(bx[1], by[1], n2)
                if area <= tiny:
                    continue
                total += area
                for e in range(c + 1, m):
                    n3 = clip(bx[1], by[1], n2, gx[e], gy[e], gn[e], bx[2], by[2], tx, ty)
                    if n3 >= 3:
                        area = signed_area(bx[2], by[2], n3)
                        if area > tiny:
                            total -= area
    return total


@nb.njit(cache=True, nogil=True)
def _lit(cx, cy, area_t, gx, gy, gn, m, scratch):
    """Lit fraction of the triangle (cx, cy) of area ``area_t`` left by its m clipped
    shadows (one: its area; up to :data:`SMALL_UNION`: inclusion-exclusion by
    :func:`_union_small`; from :data:`PIECES_FROM` on: lit pieces; slabs past the
    budgets)."""
    stack_x, stack_y, stack_n, nxt, tx, ty, ubox, sbox, ax, ay, an, bx, by, bn = scratch
    if m == 1:
        shadow = signed_area(gx[0], gy[0], gn[0])
    else:
        m = _convex(gx, gy, gn, m, tx, ty)
        if m >= PIECES_FROM and m > SMALL_UNION:
            lit = lit_area(cx, cy, gx, gy, gn, m, 1e-17 * area_t, ax, ay, an, bx, by, bn, tx, ty)
            if lit >= 0.0:
                return min(1.0, lit / area_t)
        ok = False
        shadow = 0.0
        if m <= SMALL_UNION:
            shadow = _union_small(gx, gy, gn, m, 1e-15 * area_t, stack_x, stack_y, tx, ty)
            ok = True
        elif m <= MAXM:
            shadow, ok = union_area_boxes(
                gx, gy, gn, m, 1e-15 * area_t, stack_x, stack_y, stack_n, nxt, tx, ty, ubox, sbox
            )
        if not ok:
            shadow = union_area_slabs(gx, gy, gn, m)
    return min(1.0, max(0.0, 1.0 - shadow / area_t))


@nb.njit(cache=True, nogil=True)
def pairs_kernel(
    normals, N, E1, E2, T2, recv, pstart, pgroup, pcount, cut, box, r2, gnorm, gopen, dirs
):
    """Lit (and visible) fraction of every facet for every geometry, from the pair table.

    ``dirs`` (G, K, 3): K unit directions per geometry that must all be unobstructed.  The
    table is :func:`~sbrdf_xr.kernels.pair_table.pair_table`'s; ``gnorm``, ``gopen`` the
    occluders' normals and open flags (an occluder blocks d when its normal faces away from
    d, or when it is one-sided on an open surface).  A facet facing away from a direction
    gets 0, by its ``normals`` (the stored ones, which decide) or by ``N`` (its winding, as
    the grid kernel has it);
    a facet that is no receiver and faces every direction gets 1; a receiver with more
    shadows than the buffers hold gets NaN (the caller unites them with GEOS).

    Examples
    --------
    The two plates of :func:`~sbrdf_xr.kernels.pair_table.pair_table`'s example, lit from
    +z: the upper plate shades a quarter of the lower plate's first triangle and three
    quarters of its second.

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.pair_table import pair_table
    >>> from sbrdf_xr.kernels.shadow_pairs import pairs_kernel
    >>> V = np.array([[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0],
    ...               [0, 0, 1], [1, 0, 1], [1, 2, 1], [0, 2, 1]], dtype=float)
    >>> F = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    >>> N = np.tile([0.0, 0.0, 1.0], (4, 1))
    >>> E1 = V[F[:, 1]] - V[F[:, 0]]
    >>> E1 /= np.linalg.norm(E1, axis=1, keepdims=True)
    >>> E2 = np.cross(N, E1)
    >>> rel = V[F] - V[F[:, :1]]
    >>> T2 = np.ascontiguousarray(np.stack(
    ...     [np.einsum("fvx,fx->fv", rel, E1), np.einsum("fvx,fx->fv", rel, E2)], axis=-1))
    >>> poly = np.zeros((4, 8), dtype=np.int64)
    >>> poly[:, :3] = F
    >>> gopen = np.ones(4, bool)
    >>> table = pair_table(V, F, N, V[F[:, 0]], E1, E2, T2, np.ones(4, bool), poly,
    ...                    np.full(4, 3), N, gopen, np.arange(5), np.arange(4), 1e-9)
    >>> dirs = np.array([[[0.0, 0.0, 1.0]]])  # (G=1, K=1, 3)
    >>> print(np.round(pairs_kernel(N, N, E1, E2, T2, *table, N, gopen, dirs), 6))
    [[0.75 0.25 1.   1.  ]]
    """
    frac = np.empty((dirs.shape[0], N.shape[0]))
    table = (recv, pstart, pgroup, pcount, cut, box, r2)
    _pairs_into(frac, normals, N, E1, E2, T2, table, gnorm, gopen, dirs, _buffers(dirs, gnorm))
    return frac


@nb.njit(cache=True, nogil=True)
def _buffers(dirs, gnorm):
    """The scratch of :func:`_pairs_into` for directions like ``dirs`` and the occluders of
    ``gnorm`` (allocated once per call of :func:`pairs_kernel`, or once per posed sweep)."""
    K = dirs.shape[1]
    gx, gy = np.empty((MAX_SHADOWS, _SHADOW)), np.empty((MAX_SHADOWS, _SHADOW))
    gn = np.empty(MAX_SHADOWS, dtype=np.int64)
    px, py, cx, cy = np.empty(_SHADOW), np.empty(_SHADOW), np.empty(3), np.empty(3)
    w, s = np.empty((3, 2)), np.empty((K, 2))
    qx, qy, tx, ty = np.empty(MAXV), np.empty(MAXV), np.empty(MAXV), np.empty(MAXV)
    occ = np.empty((_CHUNK, K, gnorm.shape[0]), dtype=np.bool_)
    scratch = (
        np.empty((MAXM + 1, MAXV)),
        np.empty((MAXM + 1, MAXV)),
        np.empty(MAXM + 1, dtype=np.int64),
        np.empty(MAXM + 1, dtype=np.int64),
        np.empty(MAXV),
        np.empty(MAXV),
        np.empty((MAXM, 4)),
        np.empty((MAXM + 1, 4)),
        np.empty((_PIECES, MAXV)),
        np.empty((_PIECES, MAXV)),
        np.empty(_PIECES, dtype=np.int64),
        np.empty((_PIECES, MAXV)),
        np.empty((_PIECES, MAXV)),
        np.empty(_PIECES, dtype=np.int64),
    )
    return gx, gy, gn, px, py, qx, qy, tx, ty, cx, cy, w, occ, s, scratch


@nb.njit(cache=True, nogil=True)
def _pairs_into(frac, normals, N, E1, E2, T2, table, gnorm, gopen, dirs, buf):
    """:func:`pairs_kernel` written into ``frac`` (G, n_facets), with its scratch ``buf``."""
    recv, pstart, pgroup, pcount, cut, box, r2 = table
    gx, gy, gn, px, py, qx, qy, tx, ty, cx, cy, w, occ, s, scratch = buf
    G = dirs.shape[0]
    K = dirs.shape[1]
    for g0 in range(0, G, _CHUNK):  # a chunk of geometries, then each receiver through them
        g1 = min(G, g0 + _CHUNK)
        for g in range(g0, g1):
            _facing(dirs, g, normals, gnorm, gopen, occ[g - g0], frac)
        for r in range(recv.shape[0]):
            i = recv[r]
            p0 = pstart[r]
            p1 = pstart[r + 1]
            for c in range(3):
                cx[c] = T2[i, c, 0]
                cy[c] = T2[i, c, 1]
            for e in range(3):  # unit edge directions: the separating axes of the table
                e1 = e + 1 if e < 2 else 0
                norm = np.sqrt((cx[e1] - cx[e]) ** 2 + (cy[e1] - cy[e]) ** 2)
                w[e, 0] = (cx[e1] - cx[e]) / norm
                w[e, 1] = (cy[e1] - cy[e]) / norm
            area_t = signed_area(cx, cy, 3)
            for g in range(g0, g1):
                rad = 0.0
                facing = True
                for k in range(K):
                    d0 = dirs[g, k, 0]
                    d1 = dirs[g, k, 1]
                    d2 = dirs[g, k, 2]
                    nd = N[i, 0] * d0 + N[i, 1] * d1 + N[i, 2] * d2
                    if nd <= 0.0:
                        facing = False
                        break
                    s[k, 0] = (E1[i, 0] * d0 + E1[i, 1] * d1 + E1[i, 2] * d2) / nd
                    s[k, 1] = (E2[i, 0] * d0 + E2[i, 1] * d1 + E2[i, 2] * d2) / nd
                    rad = max(rad, s[k, 0] * s[k, 0] + s[k, 1] * s[k, 1])
                if not facing or frac[g, i] == 0.0:
                    frac[g, i] = 0.0
                    continue
                if p0 == p1 or r2[p0] > rad:
                    continue  # nothing can reach this high above the facet: fraction 1
                og = occ[g - g0]
                m = 0
                too_many = False
                covered = False
                for p in range(p0, p1):
                    if r2[p] > rad:
                        break
                    q = pgroup[p]
                    for k in range(K):
                        s1 = s[k, 0]
                        s2 = s[k, 1]
                        if (
                            not og[k, q]
                            or s1 < box[p, 0]
                            or s1 > box[p, 1]
                            or s2 < box[p, 2]
                            or s2 > box[p, 3]
                            or w[0, 0] * s2 - w[0, 1] * s1 > box[p, 4]
                            or w[1, 0] * s2 - w[1, 1] * s1 > box[p, 5]
                            or w[2, 0] * s2 - w[2, 1] * s1 > box[p, 6]
                        ):
                            continue
                        nq = _shadow(
                            cut, p, pcount[p], s1, s2, cx, cy, area_t, px, py, qx, qy, tx, ty
                        )
                        if nq == 0:
                            continue
                        if nq < 0:
                            covered = True
                            break
                        if m == MAX_SHADOWS or nq > _SHADOW:
                            too_many = True
                            continue
                        for v in range(nq):
                            gx[m, v] = qx[v]
                            gy[m, v] = qy[v]
                        gn[m] = nq
                        m += 1
                    if covered:
                        break
                if covered:
                    frac[g, i] = 0.0
                elif too_many:
                    frac[g, i] = np.nan
                elif m > 0:
                    frac[g, i] = _lit(cx, cy, area_t, gx, gy, gn, m, scratch)
    return frac
