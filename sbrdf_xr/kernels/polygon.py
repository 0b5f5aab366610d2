"""Compiled plane-polygon kernels of the exact shadow method (numba, nogil).

Signed area, Sutherland-Hodgman clipping by a convex polygon, convex hulls, bounding
boxes, and the area of a union of convex polygons (inclusion-exclusion within a work
budget, vertical slabs past it), used by :mod:`sbrdf_xr.kernels.shadow` in the plane
of a receiving facet.  Plain arrays in and out; polygons are (x, y) float arrays plus a
count.
"""

from __future__ import annotations

import numba as nb
import numpy as np

__all__ = [
    "BUDGET",
    "MAXM",
    "MAXV",
    "bounds",
    "clip",
    "hull",
    "signed_area",
    "union_area",
    "union_area_boxes",
    "union_area_slabs",
]

MAXV = 96  #: vertex capacity of one clipped polygon
#: Shadow polygons per facet united by inclusion-exclusion (more, or past the work budget:
#: vertical slabs).
MAXM = 64
BUDGET = 20000  #: polygon intersections per facet before falling back to the GEOS union


@nb.njit(cache=True, nogil=True)
def signed_area(px, py, n):
    """Signed area of the polygon (px, py, n) by the shoelace formula, positive when
    counter-clockwise.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.kernels.polygon import signed_area
    >>> px, py = np.array([0.0, 2.0, 2.0, 0.0]), np.array([0.0, 0.0, 1.0, 1.0])
    >>> signed_area(px, py, 4), signed_area(px[::-1].copy(), py[::-1].copy(), 4)
    (2.0, -2.0)
    >>> signed_area(px, py, 3)  # the first three vertices: a triangle
    1.0
    """
    s = 0.0
    for k in range(n):
        k1 = k + 1 if k + 1 < n else 0
        s += px[k] * py[k1] - px[k1] * py[k]
    return 0.5 * s


@nb.njit(cache=True, nogil=True)
def clip(sx, sy, ns, cx, cy, nc, ox, oy, tx, ty):
    """Sutherland-Hodgman: subject polygon (sx, sy, ns) clipped by the convex counter-clockwise
    polygon (cx, cy, nc), written to (ox, oy); (tx, ty) is scratch.  Returns the vertex count
    (-1 if the capacity would be exceeded).  Exact for convex subjects (the intersection of two
    convex sets is the clipped polygon).

    Examples
    --------
    The unit square clipped by itself shifted by (0.5, 0.5) is a square of area 0.25:

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.polygon import MAXV, clip, signed_area
    >>> sx, sy = np.array([0.0, 1.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0, 1.0])
    >>> ox, oy, tx, ty = (np.empty(MAXV) for _ in range(4))
    >>> n = clip(sx, sy, 4, sx + 0.5, sy + 0.5, 4, ox, oy, tx, ty)
    >>> n, signed_area(ox, oy, n), sorted(zip(ox[:n].tolist(), oy[:n].tolist()))
    (4, 0.25, [(0.5, 0.5), (0.5, 1.0), (1.0, 0.5), (1.0, 1.0)])
    >>> clip(sx, sy, 4, sx + 2.0, sy, 4, ox, oy, tx, ty)  # disjoint
    0
    """
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
def hull(px, py, n, ox, oy, idx):
    """Convex hull (Andrew's monotone chain, counter-clockwise, collinear points dropped) of n
    points, written to (ox, oy); idx is integer scratch.  Returns the vertex count.  Clipped
    polygons are convex only up to rounding; their hull is exactly convex, so every edge line
    of it supports it, and near-duplicate vertices cannot leave a stray edge direction.

    Examples
    --------
    A square's corners, its centre and an edge midpoint (collinear) give the square,
    counter-clockwise from its lowest-leftmost corner:

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.polygon import MAXV, hull
    >>> px = np.array([1.0, 0.0, 0.5, 1.0, 0.0, 0.5])
    >>> py = np.array([1.0, 0.0, 0.5, 0.0, 1.0, 0.0])
    >>> ox, oy, idx = np.empty(MAXV), np.empty(MAXV), np.empty(MAXV, dtype=np.int64)
    >>> n = hull(px, py, 6, ox, oy, idx)
    >>> n, ox[:n].tolist(), oy[:n].tolist()
    (4, [0.0, 1.0, 1.0, 0.0], [0.0, 0.0, 1.0, 1.0])
    """
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
def bounds(px, py, n, out):
    """Bounding box of the polygon (px, py, n), written to out as (xmin, xmax, ymin, ymax).

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.kernels.polygon import bounds
    >>> out = np.empty(4)
    >>> bounds(np.array([0.0, 2.0, 1.0]), np.array([-1.0, 0.5, 3.0]), 3, out)
    >>> out.tolist()
    [0.0, 2.0, -1.0, 3.0]
    """
    out[0] = out[2] = np.inf
    out[1] = out[3] = -np.inf
    for k in range(n):
        out[0] = min(out[0], px[k])
        out[1] = max(out[1], px[k])
        out[2] = min(out[2], py[k])
        out[3] = max(out[3], py[k])


@nb.njit(cache=True, nogil=True)
def union_area(gx, gy, gn, m, tiny, stack_x, stack_y, stack_n, nxt, tx, ty):
    """Area of the union of m convex counter-clockwise polygons (gx[k], gy[k], gn[k]) by
    inclusion-exclusion over the non-empty intersections, depth first (an empty intersection
    prunes every superset; bounding boxes that do not overlap skip the clip).  Returns
    (area, ok); ok is False past the work budget.

    Examples
    --------
    Two unit squares overlapping by half and a third across both (the union is
    ``[0, 1.5] x [0, 1]`` and the top half of the third, 2 in all):

    >>> import numpy as np
    >>> gx = np.array([[0.0, 1, 1, 0], [0.5, 1.5, 1.5, 0.5], [0.25, 1.25, 1.25, 0.25]])
    >>> gy = np.array([[0.0, 0, 1, 1], [0.0, 0, 1, 1], [0.5, 0.5, 1.5, 1.5]])
    >>> gn = np.array([4, 4, 4])
    >>> from sbrdf_xr.kernels.polygon import MAXM, MAXV, union_area
    >>> stack_x, stack_y = np.empty((MAXM + 1, MAXV)), np.empty((MAXM + 1, MAXV))
    >>> stack_n, nxt = np.empty(MAXM + 1, dtype=np.int64), np.empty(MAXM + 1, dtype=np.int64)
    >>> tx, ty = np.empty(MAXV), np.empty(MAXV)
    >>> area, ok = union_area(gx, gy, gn, 3, 1e-15, stack_x, stack_y, stack_n, nxt, tx, ty)
    >>> round(area, 12), ok
    (2.0, True)
    """
    box = np.empty((m, 4))
    sbox = np.empty((m + 1, 4))
    return union_area_boxes(gx, gy, gn, m, tiny, stack_x, stack_y, stack_n, nxt, tx, ty, box, sbox)


@nb.njit(cache=True, nogil=True)
def union_area_boxes(gx, gy, gn, m, tiny, stack_x, stack_y, stack_n, nxt, tx, ty, box, sbox):
    """:func:`union_area` with the scratch of the bounding boxes given: ``box`` (>= m, 4) and
    ``sbox`` (>= m + 1, 4), so that a kernel calling it for every facet allocates nothing.

    Examples
    --------
    The example of :func:`union_area`, with the boxes' scratch passed in:

    >>> import numpy as np
    >>> gx = np.array([[0.0, 1, 1, 0], [0.5, 1.5, 1.5, 0.5], [0.25, 1.25, 1.25, 0.25]])
    >>> gy = np.array([[0.0, 0, 1, 1], [0.0, 0, 1, 1], [0.5, 0.5, 1.5, 1.5]])
    >>> from sbrdf_xr.kernels.polygon import MAXM, MAXV, union_area_boxes
    >>> stack_x, stack_y = np.empty((MAXM + 1, MAXV)), np.empty((MAXM + 1, MAXV))
    >>> stack_n, nxt = np.empty(MAXM + 1, dtype=np.int64), np.empty(MAXM + 1, dtype=np.int64)
    >>> tx, ty, box, sbox = np.empty(MAXV), np.empty(MAXV), np.empty((3, 4)), np.empty((4, 4))
    >>> area, ok = union_area_boxes(gx, gy, np.array([4, 4, 4]), 3, 1e-15, stack_x, stack_y,
    ...                             stack_n, nxt, tx, ty, box, sbox)
    >>> round(area, 12), ok
    (2.0, True)
    """
    for k in range(m):
        bounds(gx[k], gy[k], gn[k], box[k])
    total = 0.0
    ops = 0
    for a in range(m):
        n0 = gn[a]
        for k in range(n0):
            stack_x[0, k] = gx[a, k]
            stack_y[0, k] = gy[a, k]
        stack_n[0] = n0
        sbox[0] = box[a]
        total += signed_area(gx[a], gy[a], n0)
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
            if ops > BUDGET:
                return 0.0, False
            nq = clip(
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
            area = signed_area(stack_x[d + 1], stack_y[d + 1], nq)
            if area <= tiny:
                continue
            total += area if (d % 2 == 1) else -area  # subset size d + 2
            stack_n[d + 1] = nq
            bounds(stack_x[d + 1], stack_y[d + 1], nq, sbox[d + 1])
            nxt[d + 1] = b + 1
            d += 1
    return total, True


@nb.njit(cache=True, nogil=True)
def union_area_slabs(gx, gy, gn, m):
    """Area of the union of m convex polygons by vertical slabs.

    The slab boundaries are every vertex abscissa and every abscissa where edges of two
    polygons cross; inside a slab each polygon covers a y-interval whose ends move linearly
    with x and never cross another end, so the length of the union of the intervals is
    linear in x and its value at the slab's middle times the slab's width is the slab's
    area, exactly.  O(E**2) for E edges in all: used past the inclusion-exclusion budget.

    Examples
    --------
    Two unit squares overlapping by half and a third across both (the union is
    ``[0, 1.5] x [0, 1]`` and the top half of the third, 2 in all):

    >>> import numpy as np
    >>> gx = np.array([[0.0, 1, 1, 0], [0.5, 1.5, 1.5, 0.5], [0.25, 1.25, 1.25, 0.25]])
    >>> gy = np.array([[0.0, 0, 1, 1], [0.0, 0, 1, 1], [0.5, 0.5, 1.5, 1.5]])
    >>> gn = np.array([4, 4, 4])
    >>> from sbrdf_xr.kernels.polygon import union_area_slabs
    >>> round(union_area_slabs(gx, gy, gn, 3), 12)
    2.0
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
