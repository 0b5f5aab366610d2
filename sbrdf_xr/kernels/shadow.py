"""Compiled kernels of the exact shadow method of :mod:`sbrdf_xr.body.visibility`.

The view grid that finds candidate occluders, the shadow one facet casts on another,
and the per-facet kernel that projects every occluder along a direction (numba,
nogil); the polygon clipping, convex hulls and the area of a union of polygons in the
plane of a receiving facet are in :mod:`sbrdf_xr.kernels.polygon`.  Plain arrays in
and out; polygons are (x, y) float arrays plus a count.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from .polygon import MAXM, MAXV, clip, hull, signed_area, union_area, union_area_slabs

#: Shadow polygons per facet held by the compiled kernel; a facet with more goes to GEOS.
MAX_SHADOWS = 1024


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
    if signed_area(px, py, n_p) < 0.0:  # make it counter-clockwise
        for v in range(n_p // 2):
            px[v], px[n_p - 1 - v] = px[n_p - 1 - v], px[v]
            py[v], py[n_p - 1 - v] = py[n_p - 1 - v], py[v]
    nc = clip(px, py, n_p, cx, cy, 3, tx, ty, qx, qy)
    if nc < 3:
        return 0
    nq = hull(tx, ty, nc, qx, qy, idx)
    if nq < 3 or signed_area(qx, qy, nq) <= 1e-15 * signed_area(cx, cy, 3):
        return 0
    return nq


@nb.njit(cache=True, nogil=True)
def exact_kernel(V, F, N, P0, E1, E2, T2, receiver, dirs, open_facet, eps_h):
    """Lit (and visible) fraction of every facet for every geometry, exactly.

    ``dirs`` (G, K, 3): K directions per geometry that must all be unobstructed.  For facet i
    and direction d (N_i.d > 0) a point p of the facet is shadowed iff the ray p + t d
    (t > 0) meets the surface; on a closed surface the first hit enters the solid, so the
    occluders are the facets with N_j.d < 0, and also those with N_j.d > 0 where
    ``open_facet[j]`` (a one-sided facet of an open surface blocks light from behind too),
    cut to their part in front of the plane of i and projected along d onto it.  The union of
    these convex polygons over the K directions, clipped to the facet, is its shadowed area,
    computed by inclusion-exclusion over convex intersections; facets past the work budget
    get NaN (the caller unions their polygons with GEOS).  Candidate occluders come from a
    uniform grid over the bounding boxes in the plane perpendicular to d, then a depth test.

    Examples
    --------
    An open surface: a 2 x 2 plate at z = 0 and a 1 x 2 plate above its left half at z = 1,
    lit from +z.  The upper plate shades a quarter of the lower plate's first triangle and
    three quarters of its second; the upper plate is fully lit.

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.shadow import exact_kernel
    >>> V = np.array([[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0],
    ...               [0, 0, 1], [1, 0, 1], [1, 2, 1], [0, 2, 1]], dtype=float)
    >>> F = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    >>> tri = V[F]
    >>> N = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    >>> N /= np.linalg.norm(N, axis=1, keepdims=True)
    >>> E1 = tri[:, 1] - tri[:, 0]
    >>> E1 /= np.linalg.norm(E1, axis=1, keepdims=True)
    >>> E2 = np.cross(N, E1)
    >>> rel = tri - tri[:, :1]
    >>> T2 = np.ascontiguousarray(np.stack(
    ...     [np.einsum("fvx,fx->fv", rel, E1), np.einsum("fvx,fx->fv", rel, E2)], axis=-1))
    >>> P0 = np.ascontiguousarray(tri[:, 0])
    >>> dirs = np.array([[[0.0, 0.0, 1.0]]])  # (G=1, K=1, 3)
    >>> frac = exact_kernel(V, F, N, P0, E1, E2, T2, np.ones(4, bool), dirs, np.ones(4, bool), 1e-9)
    >>> print(np.round(frac, 6))
    [[0.75 0.25 1.   1.  ]]
    """
    G = dirs.shape[0]
    K = dirs.shape[1]
    nf = F.shape[0]
    frac = np.zeros((G, nf))
    gx = np.empty((MAX_SHADOWS, 8))  # a shadow clipped to a triangle has at most 7 vertices
    gy = np.empty((MAX_SHADOWS, 8))
    gn = np.empty(MAX_SHADOWS, dtype=np.int64)
    stack_x = np.empty((MAXM + 1, MAXV))
    stack_y = np.empty((MAXM + 1, MAXV))
    stack_n = np.empty(MAXM + 1, dtype=np.int64)
    nxt = np.empty(MAXM + 1, dtype=np.int64)
    tx = np.empty(MAXV)
    ty = np.empty(MAXV)
    px = np.empty(8)
    py = np.empty(8)
    hh = np.empty(3)
    qx = np.empty(MAXV)
    qy = np.empty(MAXV)
    idx = np.empty(MAXV, dtype=np.int64)
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
            occ = (nd[k] < 0.0) | ((nd[k] > 0.0) & open_facet)
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
            area_t = signed_area(cx, cy, 3)
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
            if m <= MAXM:
                shadow, ok = union_area(
                    gx, gy, gn, m, 1e-15 * area_t, stack_x, stack_y, stack_n, nxt, tx, ty
                )
            if not ok:
                shadow = union_area_slabs(gx, gy, gn, m)
            frac[g, i] = min(1.0, max(0.0, 1.0 - shadow / area_t))
    return frac


@nb.njit(cache=True, nogil=True)
def facet_shadows(i, dirs, V, F, N, P0, E1, E2, T2, open_facet, eps_h):
    """Every shadow polygon on facet i for the K directions ``dirs`` (K, 3), by testing every
    facet (no grid): vertices (n, 2) and CSR offsets.  For the GEOS fallback.

    Examples
    --------
    The two plates of :func:`exact_kernel`'s example: on the lower plate's first triangle
    the upper plate casts one shadow, the triangle (0, 0), (1, 0), (1, 1) in the facet's
    own frame (area 1/2 of the triangle's 2, so the lit fraction is 3/4).

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.shadow import facet_shadows
    >>> V = np.array([[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0],
    ...               [0, 0, 1], [1, 0, 1], [1, 2, 1], [0, 2, 1]], dtype=float)
    >>> F = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    >>> tri = V[F]
    >>> N = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    >>> N /= np.linalg.norm(N, axis=1, keepdims=True)
    >>> E1 = tri[:, 1] - tri[:, 0]
    >>> E1 /= np.linalg.norm(E1, axis=1, keepdims=True)
    >>> E2 = np.cross(N, E1)
    >>> rel = tri - tri[:, :1]
    >>> T2 = np.ascontiguousarray(np.stack(
    ...     [np.einsum("fvx,fx->fv", rel, E1), np.einsum("fvx,fx->fv", rel, E2)], axis=-1))
    >>> P0 = np.ascontiguousarray(tri[:, 0])
    >>> dirs = np.array([[0.0, 0.0, 1.0]])  # (K=1, 3)
    >>> xy, start = facet_shadows(0, dirs, V, F, N, P0, E1, E2, T2, np.ones(4, bool), 1e-9)
    >>> start.tolist()
    [0, 3]
    >>> print(np.round(xy, 6))
    [[0. 0.]
     [1. 0.]
     [1. 1.]]
    """
    nf = F.shape[0]
    K = dirs.shape[0]
    cx = T2[i, :, 0].copy()
    cy = T2[i, :, 1].copy()
    tx = np.empty(MAXV)
    ty = np.empty(MAXV)
    px = np.empty(8)
    py = np.empty(8)
    hh = np.empty(3)
    qx = np.empty(MAXV)
    qy = np.empty(MAXV)
    idx = np.empty(MAXV, dtype=np.int64)
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
            if ndj == 0.0 or (ndj > 0.0 and not open_facet[j]):
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
