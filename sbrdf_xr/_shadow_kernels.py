"""Compiled kernels of the exact shadow method of :mod:`sbrdf_xr.visibility`.

Polygon clipping, convex hulls and the area of a union of polygons in the plane of a
receiving facet (numba, nogil), the view grid that finds candidate occluders, and
the per-facet kernel that projects every occluder along a direction.  Plain arrays in
and out; polygons are (x, y) float arrays plus a count.
"""

from __future__ import annotations

import numba as nb
import numpy as np

_MAXV = 96  #: vertex capacity of one clipped polygon
#: Shadow polygons per facet united by inclusion-exclusion (more, or past the work budget:
#: vertical slabs).
_MAXM = 64
#: Shadow polygons per facet held by the compiled kernel; a facet with more goes to GEOS.
MAX_SHADOWS = 1024
_BUDGET = 20000  #: polygon intersections per facet before falling back to the GEOS union


@nb.njit(cache=True, nogil=True)
def _signed_area(px, py, n):
    s = 0.0
    for k in range(n):
        k1 = k + 1 if k + 1 < n else 0
        s += px[k] * py[k1] - px[k1] * py[k]
    return 0.5 * s


@nb.njit(cache=True, nogil=True)
def _clip(sx, sy, ns, cx, cy, nc, ox, oy, tx, ty):
    """Sutherland-Hodgman: subject polygon (sx, sy, ns) clipped by the convex counter-clockwise
    polygon (cx, cy, nc), written to (ox, oy); (tx, ty) is scratch.  Returns the vertex count
    (-1 if the capacity would be exceeded).  Exact for convex subjects (the intersection of two
    convex sets is the clipped polygon)."""
    n = ns
    for k in range(n):
        ox[k] = sx[k]
        oy[k] = sy[k]
    for e in range(nc):
        if n == 0:
            return 0
        ax = cx[e]
        ay = cy[e]
        e1 = e + 1 if e + 1 < nc else 0
        bx = cx[e1] - ax
        by = cy[e1] - ay
        for k in range(n):
            tx[k] = ox[k]
            ty[k] = oy[k]
        m = 0
        px = tx[n - 1]
        py = ty[n - 1]
        dp = bx * (py - ay) - by * (px - ax)
        for k in range(n):
            qx = tx[k]
            qy = ty[k]
            dq = bx * (qy - ay) - by * (qx - ax)
            if m + 2 >= ox.shape[0]:
                return -1
            if dq >= 0.0:
                if dp < 0.0:
                    t = dp / (dp - dq)
                    ox[m] = px + t * (qx - px)
                    oy[m] = py + t * (qy - py)
                    m += 1
                ox[m] = qx
                oy[m] = qy
                m += 1
            elif dp > 0.0:
                t = dp / (dp - dq)
                ox[m] = px + t * (qx - px)
                oy[m] = py + t * (qy - py)
                m += 1
            px = qx
            py = qy
            dp = dq
        n = m
    return n


@nb.njit(cache=True, nogil=True)
def _hull(px, py, n, ox, oy, idx):
    """Convex hull (Andrew's monotone chain, counter-clockwise, collinear points dropped) of n
    points, written to (ox, oy); idx is integer scratch.  Returns the vertex count.  Clipped
    polygons are convex only up to rounding; their hull is exactly convex, so every edge line
    of it supports it, and near-duplicate vertices cannot leave a stray edge direction."""
    for k in range(n):
        idx[k] = k
    for k in range(1, n):  # insertion sort by (x, y)
        v = idx[k]
        q = k - 1
        while q >= 0 and (px[idx[q]] > px[v] or (px[idx[q]] == px[v] and py[idx[q]] > py[v])):
            idx[q + 1] = idx[q]
            q -= 1
        idx[q + 1] = v
    m = 0
    for k in range(n):  # lower chain
        v = idx[k]
        while (
            m >= 2
            and (
                (ox[m - 1] - ox[m - 2]) * (py[v] - oy[m - 2])
                - (oy[m - 1] - oy[m - 2]) * (px[v] - ox[m - 2])
            )
            <= 0.0
        ):
            m -= 1
        ox[m] = px[v]
        oy[m] = py[v]
        m += 1
    low = m + 1
    for k in range(n - 2, -1, -1):  # upper chain
        v = idx[k]
        while (
            m >= low
            and (
                (ox[m - 1] - ox[m - 2]) * (py[v] - oy[m - 2])
                - (oy[m - 1] - oy[m - 2]) * (px[v] - ox[m - 2])
            )
            <= 0.0
        ):
            m -= 1
        ox[m] = px[v]
        oy[m] = py[v]
        m += 1
    return m - 1 if m > 1 else m


@nb.njit(cache=True, nogil=True)
def _bounds(px, py, n, out):
    out[0] = out[2] = np.inf
    out[1] = out[3] = -np.inf
    for k in range(n):
        out[0] = min(out[0], px[k])
        out[1] = max(out[1], px[k])
        out[2] = min(out[2], py[k])
        out[3] = max(out[3], py[k])


@nb.njit(cache=True, nogil=True)
def _union_area(gx, gy, gn, m, tiny, stack_x, stack_y, stack_n, nxt, tx, ty):
    """Area of the union of m convex counter-clockwise polygons (gx[k], gy[k], gn[k]) by
    inclusion-exclusion over the non-empty intersections, depth first (an empty intersection
    prunes every superset; bounding boxes that do not overlap skip the clip).  Returns
    (area, ok); ok is False past the work budget."""
    box = np.empty((m, 4))
    sbox = np.empty((m + 1, 4))
    for k in range(m):
        _bounds(gx[k], gy[k], gn[k], box[k])
    total = 0.0
    ops = 0
    for a in range(m):
        n0 = gn[a]
        for k in range(n0):
            stack_x[0, k] = gx[a, k]
            stack_y[0, k] = gy[a, k]
        stack_n[0] = n0
        sbox[0] = box[a]
        total += _signed_area(gx[a], gy[a], n0)
        nxt[0] = a + 1
        d = 0
        while d >= 0:
            if nxt[d] >= m:
                d -= 1
                continue
            b = nxt[d]
            nxt[d] += 1
            if (
                box[b, 0] >= sbox[d, 1]
                or box[b, 1] <= sbox[d, 0]
                or box[b, 2] >= sbox[d, 3]
                or box[b, 3] <= sbox[d, 2]
            ):
                continue
            ops += 1
            if ops > _BUDGET:
                return 0.0, False
            nq = _clip(
                stack_x[d],
                stack_y[d],
                stack_n[d],
                gx[b],
                gy[b],
                gn[b],
                stack_x[d + 1],
                stack_y[d + 1],
                tx,
                ty,
            )
            if nq < 0:
                return 0.0, False
            if nq < 3:
                continue
            area = _signed_area(stack_x[d + 1], stack_y[d + 1], nq)
            if area <= tiny:
                continue
            total += area if (d % 2 == 1) else -area  # subset size d + 2
            stack_n[d + 1] = nq
            _bounds(stack_x[d + 1], stack_y[d + 1], nq, sbox[d + 1])
            nxt[d + 1] = b + 1
            d += 1
    return total, True


@nb.njit(cache=True, nogil=True)
def _union_area_slabs(gx, gy, gn, m):
    """Area of the union of m convex polygons by vertical slabs.

    The slab boundaries are every vertex abscissa and every abscissa where edges of two
    polygons cross; inside a slab each polygon covers a y-interval whose ends move linearly
    with x and never cross another end, so the length of the union of the intervals is
    linear in x and its value at the slab's middle times the slab's width is the slab's
    area, exactly.  O(E**2) for E edges in all: used past the inclusion-exclusion budget.
    """
    nv = 0
    for k in range(m):
        nv += gn[k]
    ne = 0
    xs = np.empty(0)
    n_cross = 0
    for sweep in range(2):  # count the crossings, then store them
        if sweep == 1:
            xs = np.empty(nv + n_cross)
            for k in range(m):
                for v in range(gn[k]):
                    xs[ne] = gx[k, v]
                    ne += 1
        ne = 0 if sweep == 0 else ne
        for k in range(m):
            for v in range(gn[k]):
                v1 = v + 1 if v + 1 < gn[k] else 0
                ax, ay = gx[k, v], gy[k, v]
                rx, ry = gx[k, v1] - ax, gy[k, v1] - ay
                for q in range(k + 1, m):
                    for w in range(gn[q]):
                        w1 = w + 1 if w + 1 < gn[q] else 0
                        bx, by = gx[q, w], gy[q, w]
                        sx, sy = gx[q, w1] - bx, gy[q, w1] - by
                        den = rx * sy - ry * sx
                        if den == 0.0:
                            continue  # parallel: their ends never swap inside a slab
                        t = ((bx - ax) * sy - (by - ay) * sx) / den
                        u = ((bx - ax) * ry - (by - ay) * rx) / den
                        if 0.0 < t < 1.0 and 0.0 < u < 1.0:
                            if sweep == 0:
                                n_cross += 1
                            else:
                                xs[ne] = ax + t * rx
                                ne += 1
    xs = np.sort(xs[:ne])
    lo = np.empty(m)
    hi = np.empty(m)
    total = 0.0
    for e in range(ne - 1):
        x0 = xs[e]
        x1 = xs[e + 1]
        if x1 <= x0:
            continue
        xm = 0.5 * (x0 + x1)
        n_int = 0
        for k in range(m):
            ylo = np.inf
            yhi = -np.inf
            for v in range(gn[k]):
                v1 = v + 1 if v + 1 < gn[k] else 0
                xa, xb = gx[k, v], gx[k, v1]
                if (xa < xm) != (xb < xm):
                    y = gy[k, v] + (xm - xa) * (gy[k, v1] - gy[k, v]) / (xb - xa)
                    ylo = min(ylo, y)
                    yhi = max(yhi, y)
            if yhi > ylo:
                lo[n_int] = ylo
                hi[n_int] = yhi
                n_int += 1
        if n_int == 0:
            continue
        order = np.argsort(lo[:n_int])
        length = 0.0
        cur_lo = lo[order[0]]
        cur_hi = hi[order[0]]
        for q in range(1, n_int):
            a = lo[order[q]]
            b = hi[order[q]]
            if a > cur_hi:
                length += cur_hi - cur_lo
                cur_lo = a
                cur_hi = b
            elif b > cur_hi:
                cur_hi = b
        length += cur_hi - cur_lo
        total += (x1 - x0) * length
    return total


@nb.njit(cache=True, nogil=True)
def _view_grid(d, V, F, occluder):
    """Bounding boxes of every facet in the plane perpendicular to ``d``, depth ranges along
    ``d``, and a uniform grid binning the occluders (CSR: start, items)."""
    ax = 0
    if abs(d[1]) < abs(d[ax]):
        ax = 1
    if abs(d[2]) < abs(d[ax]):
        ax = 2
    e = np.zeros(3)
    e[ax] = 1.0
    a = np.array([d[1] * e[2] - d[2] * e[1], d[2] * e[0] - d[0] * e[2], d[0] * e[1] - d[1] * e[0]])
    a /= np.sqrt(a[0] ** 2 + a[1] ** 2 + a[2] ** 2)
    b = np.array([d[1] * a[2] - d[2] * a[1], d[2] * a[0] - d[0] * a[2], d[0] * a[1] - d[1] * a[0]])
    nv = V.shape[0]
    nf = F.shape[0]
    U = np.empty(nv)
    W = np.empty(nv)
    D = np.empty(nv)
    for v in range(nv):
        U[v] = V[v, 0] * a[0] + V[v, 1] * a[1] + V[v, 2] * a[2]
        W[v] = V[v, 0] * b[0] + V[v, 1] * b[1] + V[v, 2] * b[2]
        D[v] = V[v, 0] * d[0] + V[v, 1] * d[1] + V[v, 2] * d[2]
    box = np.empty((nf, 6))  # u0 u1 w0 w1 t0 t1
    g0u = np.inf
    g1u = -np.inf
    g0w = np.inf
    g1w = -np.inf
    n_occ = 0
    for f in range(nf):
        i0, i1, i2 = F[f, 0], F[f, 1], F[f, 2]
        box[f, 0] = min(U[i0], U[i1], U[i2])
        box[f, 1] = max(U[i0], U[i1], U[i2])
        box[f, 2] = min(W[i0], W[i1], W[i2])
        box[f, 3] = max(W[i0], W[i1], W[i2])
        box[f, 4] = min(D[i0], D[i1], D[i2])
        box[f, 5] = max(D[i0], D[i1], D[i2])
        if occluder[f]:
            n_occ += 1
            g0u = min(g0u, box[f, 0])
            g1u = max(g1u, box[f, 1])
            g0w = min(g0w, box[f, 2])
            g1w = max(g1w, box[f, 3])
    ng = max(1, min(1024, int(np.sqrt(n_occ))))
    if n_occ == 0:
        g0u = g1u = g0w = g1w = 0.0
    su = (g1u - g0u) / ng if g1u > g0u else 1.0
    sw = (g1w - g0w) / ng if g1w > g0w else 1.0
    grid = np.array([g0u, g0w, 1.0 / su, 1.0 / sw, float(ng)])
    count = np.zeros(ng * ng + 1, dtype=np.int64)
    for f in range(nf):
        if not occluder[f]:
            continue
        c0 = min(ng - 1, max(0, int((box[f, 0] - g0u) / su)))
        c1 = min(ng - 1, max(0, int((box[f, 1] - g0u) / su)))
        r0 = min(ng - 1, max(0, int((box[f, 2] - g0w) / sw)))
        r1 = min(ng - 1, max(0, int((box[f, 3] - g0w) / sw)))
        for r in range(r0, r1 + 1):
            for c in range(c0, c1 + 1):
                count[r * ng + c + 1] += 1
    start = np.cumsum(count)
    items = np.empty(start[-1], dtype=np.int64)
    fill = start[:-1].copy()
    for f in range(nf):
        if not occluder[f]:
            continue
        c0 = min(ng - 1, max(0, int((box[f, 0] - g0u) / su)))
        c1 = min(ng - 1, max(0, int((box[f, 1] - g0u) / su)))
        r0 = min(ng - 1, max(0, int((box[f, 2] - g0w) / sw)))
        r1 = min(ng - 1, max(0, int((box[f, 3] - g0w) / sw)))
        for r in range(r0, r1 + 1):
            for c in range(c0, c1 + 1):
                items[fill[r * ng + c]] = f
                fill[r * ng + c] += 1
    return box, grid, start, items


@nb.njit(cache=True, nogil=True)
def _shadow_polygon(
    i, j, d0, d1, d2, ndi, V, F, N, P0, E1, E2, cx, cy, eps_h, hh, px, py, qx, qy, tx, ty, idx
):
    """Shadow that facet j casts on facet i along d = (d0, d1, d2), clipped to facet i, in
    the plane frame of i (written to qx, qy; counter-clockwise).  Returns its vertex count (0
    if none).  Scalar indexing only (array views cost more than the arithmetic here)."""
    hmax = -np.inf
    for v in range(3):
        f = F[j, v]
        hh[v] = (
            N[i, 0] * (V[f, 0] - P0[i, 0])
            + N[i, 1] * (V[f, 1] - P0[i, 1])
            + N[i, 2] * (V[f, 2] - P0[i, 2])
        )
        hmax = max(hmax, hh[v])
    if hmax <= eps_h:
        return 0  # on or behind the plane of i
    s1 = (E1[i, 0] * d0 + E1[i, 1] * d1 + E1[i, 2] * d2) / ndi
    s2 = (E2[i, 0] * d0 + E2[i, 1] * d1 + E2[i, 2] * d2) / ndi
    n_p = 0
    for v in range(3):  # cut to h >= 0, project along d onto the plane: x - d h / N.d
        w = v + 1 if v < 2 else 0
        fv = F[j, v]
        fw = F[j, w]
        if hh[v] >= 0.0:
            y0 = V[fv, 0] - P0[i, 0]
            y1 = V[fv, 1] - P0[i, 1]
            y2 = V[fv, 2] - P0[i, 2]
            px[n_p] = E1[i, 0] * y0 + E1[i, 1] * y1 + E1[i, 2] * y2 - hh[v] * s1
            py[n_p] = E2[i, 0] * y0 + E2[i, 1] * y1 + E2[i, 2] * y2 - hh[v] * s2
            n_p += 1
        if (hh[v] >= 0.0) != (hh[w] >= 0.0):
            t = hh[v] / (hh[v] - hh[w])
            y0 = V[fv, 0] + t * (V[fw, 0] - V[fv, 0]) - P0[i, 0]
            y1 = V[fv, 1] + t * (V[fw, 1] - V[fv, 1]) - P0[i, 1]
            y2 = V[fv, 2] + t * (V[fw, 2] - V[fv, 2]) - P0[i, 2]
            px[n_p] = E1[i, 0] * y0 + E1[i, 1] * y1 + E1[i, 2] * y2
            py[n_p] = E2[i, 0] * y0 + E2[i, 1] * y1 + E2[i, 2] * y2
            n_p += 1
    for e in range(3):  # all of it outside one edge of the facet: no overlap
        e1 = e + 1 if e < 2 else 0
        ex = cx[e1] - cx[e]
        ey = cy[e1] - cy[e]
        outside = True
        for v in range(n_p):
            if ex * (py[v] - cy[e]) - ey * (px[v] - cx[e]) > 0.0:
                outside = False
                break
        if outside:
            return 0
    if _signed_area(px, py, n_p) < 0.0:  # make it counter-clockwise
        for v in range(n_p // 2):
            px[v], px[n_p - 1 - v] = px[n_p - 1 - v], px[v]
            py[v], py[n_p - 1 - v] = py[n_p - 1 - v], py[v]
    nc = _clip(px, py, n_p, cx, cy, 3, tx, ty, qx, qy)
    if nc < 3:
        return 0
    nq = _hull(tx, ty, nc, qx, qy, idx)
    if nq < 3 or _signed_area(qx, qy, nq) <= 1e-15 * _signed_area(cx, cy, 3):
        return 0
    return nq


@nb.njit(cache=True, nogil=True)
def exact_kernel(V, F, N, P0, E1, E2, T2, receiver, dirs, watertight, eps_h):
    """Lit (and visible) fraction of every facet for every geometry, exactly.

    ``dirs`` (G, K, 3): K directions per geometry that must all be unobstructed.  For facet i
    and direction d (N_i.d > 0) a point p of the facet is shadowed iff the ray p + t d
    (t > 0) meets the surface; on a closed surface the first hit enters the solid, so the
    occluders are the facets with N_j.d < 0 (every facet with N_j.d != 0 on an open surface),
    cut to their part in front of the plane of i and projected along d onto it.  The union of
    these convex polygons over the K directions, clipped to the facet, is its shadowed area,
    computed by inclusion-exclusion over convex intersections; facets past the work budget
    get NaN (the caller unions their polygons with GEOS).  Candidate occluders come from a
    uniform grid over the bounding boxes in the plane perpendicular to d, then a depth test.
    """
    G = dirs.shape[0]
    K = dirs.shape[1]
    nf = F.shape[0]
    frac = np.zeros((G, nf))
    gx = np.empty((MAX_SHADOWS, 8))  # a shadow clipped to a triangle has at most 7 vertices
    gy = np.empty((MAX_SHADOWS, 8))
    gn = np.empty(MAX_SHADOWS, dtype=np.int64)
    stack_x = np.empty((_MAXM + 1, _MAXV))
    stack_y = np.empty((_MAXM + 1, _MAXV))
    stack_n = np.empty(_MAXM + 1, dtype=np.int64)
    nxt = np.empty(_MAXM + 1, dtype=np.int64)
    tx = np.empty(_MAXV)
    ty = np.empty(_MAXV)
    px = np.empty(8)
    py = np.empty(8)
    hh = np.empty(3)
    qx = np.empty(_MAXV)
    qy = np.empty(_MAXV)
    idx = np.empty(_MAXV, dtype=np.int64)
    cx = np.empty(3)
    cy = np.empty(3)
    nd = np.empty((K, nf))
    stamp = np.empty((K, nf), dtype=np.int64)
    for g in range(G):
        for k in range(K):
            for f in range(nf):
                nd[k, f] = (
                    N[f, 0] * dirs[g, k, 0] + N[f, 1] * dirs[g, k, 1] + N[f, 2] * dirs[g, k, 2]
                )
                stamp[k, f] = -1
        boxes = []
        grids = []
        starts = []
        itemss = []
        for k in range(K):
            occ = (nd[k] < 0.0) if watertight else (nd[k] != 0.0)
            box, grid, start, items = _view_grid(dirs[g, k], V, F, occ)
            boxes.append(box)
            grids.append(grid)
            starts.append(start)
            itemss.append(items)
        for i in range(nf):
            facing = True
            for k in range(K):
                if nd[k, i] <= 0.0:
                    facing = False
            if not facing:
                continue  # fraction 0
            if not receiver[i]:
                frac[g, i] = 1.0
                continue
            for c in range(3):
                cx[c] = T2[i, c, 0]
                cy[c] = T2[i, c, 1]
            area_t = _signed_area(cx, cy, 3)
            m = 0
            too_many = False
            for k in range(K):
                box = boxes[k]
                grid = grids[k]
                start = starts[k]
                items = itemss[k]
                ng = int(grid[4])
                dk0 = dirs[g, k, 0]
                dk1 = dirs[g, k, 1]
                dk2 = dirs[g, k, 2]
                c0 = int(np.floor((box[i, 0] - grid[0]) * grid[2]))
                c1 = int(np.floor((box[i, 1] - grid[0]) * grid[2]))
                r0 = int(np.floor((box[i, 2] - grid[1]) * grid[3]))
                r1 = int(np.floor((box[i, 3] - grid[1]) * grid[3]))
                if c1 < 0 or r1 < 0 or c0 >= ng or r0 >= ng:
                    continue
                for r in range(max(r0, 0), min(r1, ng - 1) + 1):
                    for c in range(max(c0, 0), min(c1, ng - 1) + 1):
                        cell = r * ng + c
                        for q in range(start[cell], start[cell + 1]):
                            j = items[q]
                            if j == i or stamp[k, j] == i:
                                continue
                            stamp[k, j] = i
                            if (
                                box[j, 0] >= box[i, 1]
                                or box[j, 1] <= box[i, 0]
                                or box[j, 2] >= box[i, 3]
                                or box[j, 3] <= box[i, 2]
                                or box[j, 5] <= box[i, 4]
                            ):
                                continue  # apart across d, or wholly behind i along d
                            nq = _shadow_polygon(
                                i,
                                j,
                                dk0,
                                dk1,
                                dk2,
                                nd[k, i],
                                V,
                                F,
                                N,
                                P0,
                                E1,
                                E2,
                                cx,
                                cy,
                                eps_h,
                                hh,
                                px,
                                py,
                                qx,
                                qy,
                                tx,
                                ty,
                                idx,
                            )
                            if nq == 0:
                                continue
                            if m == MAX_SHADOWS or nq > 8:
                                too_many = True
                                continue
                            for v in range(nq):
                                gx[m, v] = qx[v]
                                gy[m, v] = qy[v]
                            gn[m] = nq
                            m += 1
            if m == 0:
                frac[g, i] = 1.0
                continue
            if too_many:
                frac[g, i] = np.nan
                continue
            ok = False
            shadow = 0.0
            if m <= _MAXM:
                shadow, ok = _union_area(
                    gx, gy, gn, m, 1e-15 * area_t, stack_x, stack_y, stack_n, nxt, tx, ty
                )
            if not ok:
                shadow = _union_area_slabs(gx, gy, gn, m)
            frac[g, i] = min(1.0, max(0.0, 1.0 - shadow / area_t))
    return frac


@nb.njit(cache=True, nogil=True)
def facet_shadows(i, dirs, V, F, N, P0, E1, E2, T2, watertight, eps_h):
    """Every shadow polygon on facet i for the K directions ``dirs`` (K, 3), by testing every
    facet (no grid): vertices (n, 2) and CSR offsets.  For the GEOS fallback."""
    nf = F.shape[0]
    K = dirs.shape[0]
    cx = T2[i, :, 0].copy()
    cy = T2[i, :, 1].copy()
    tx = np.empty(_MAXV)
    ty = np.empty(_MAXV)
    px = np.empty(8)
    py = np.empty(8)
    hh = np.empty(3)
    qx = np.empty(_MAXV)
    qy = np.empty(_MAXV)
    idx = np.empty(_MAXV, dtype=np.int64)
    xy = np.empty((8 * 64, 2))
    start = [0]
    n = 0
    for k in range(K):
        d = dirs[k]
        ndi = N[i, 0] * d[0] + N[i, 1] * d[1] + N[i, 2] * d[2]
        for j in range(nf):
            if j == i:
                continue
            ndj = N[j, 0] * d[0] + N[j, 1] * d[1] + N[j, 2] * d[2]
            if (watertight and ndj >= 0.0) or ndj == 0.0:
                continue
            nq = _shadow_polygon(
                i,
                j,
                d[0],
                d[1],
                d[2],
                ndi,
                V,
                F,
                N,
                P0,
                E1,
                E2,
                cx,
                cy,
                eps_h,
                hh,
                px,
                py,
                qx,
                qy,
                tx,
                ty,
                idx,
            )
            if nq == 0:
                continue
            if n + nq > xy.shape[0]:
                bigger = np.empty((2 * xy.shape[0] + nq, 2))
                bigger[:n] = xy[:n]
                xy = bigger
            for v in range(nq):
                xy[n + v, 0] = qx[v]
                xy[n + v, 1] = qy[v]
            n += nq
            start.append(n)
    return xy[:n].copy(), np.array(start, dtype=np.int64)
