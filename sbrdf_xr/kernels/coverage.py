"""The area of a triangle covered by convex shadows, in compiled code (numba, nogil).

The steps of :func:`sbrdf_xr.kernels.shadow_pairs.pairs_kernel` between a pair that
passed the table's tests and a lit fraction, written for few array arguments (every
array passed to a compiled function costs a reference count in and out, which on small
polygons costs more than the arithmetic):

* :func:`clipped_shadow`: a cut occluder projected along a slope ``s`` onto the plane of
  the receiving triangle, rejected when it lies outside an edge of the triangle or the
  triangle lies outside one of its edges (separating axes), recognised when it covers the
  triangle whole, and otherwise clipped by only those triangle edges it crosses.
* :func:`covered_area`: the area of the union of the clipped shadows as a sum of positive
  terms, each shadow less the shadows before it (``P_k`` minus ``P_j``: the parts of
  ``P_k`` outside one edge line of the convex ``P_j`` and inside the lines before it), so
  no alternating sum and no general polygon union; a shadow's bounding box apart from a
  piece's skips it.

Polygons are rows of one array ``poly[k, 0, :n]`` (x) and ``poly[k, 1, :n]`` (y),
counter-clockwise, with their vertex counts in ``count``.
"""

from __future__ import annotations

import numba as nb
import numpy as np

__all__ = ["VERTICES", "clipped_shadow", "covered_area", "workspace"]

#: Vertices of a clipped shadow at most (a cut occluder's 9, one more per triangle edge).
VERTICES = 16
_PIECE = 32  # vertices of a piece at most
_PIECES = 128  # pieces of one shadow held at once


@nb.njit(cache=True, nogil=True)
def workspace(n_polygons):
    """Scratch of :func:`clipped_shadow` and :func:`covered_area` for ``n_polygons``
    shadows: ``(poly, count, work, wn)``.

    Examples
    --------
    >>> from sbrdf_xr.kernels.coverage import workspace
    >>> poly, count, work, wn = workspace(4)
    >>> poly.shape, count.shape, work.shape[0], wn.shape
    ((6, 2, 16), (6,), 259, (259,))
    """
    poly = np.empty((n_polygons + 2, 2, VERTICES))
    count = np.zeros(n_polygons + 2, dtype=np.int64)
    work = np.empty((2 * _PIECES + 3, 2, _PIECE))
    wn = np.zeros(2 * _PIECES + 3, dtype=np.int64)
    return poly, count, work, wn


@nb.njit(cache=True, nogil=True, inline="always")
def _area(a, k, n):
    """Signed area of the polygon ``a[k, :, :n]`` (shoelace)."""
    s = 0.0
    x0 = a[k, 0, n - 1]
    y0 = a[k, 1, n - 1]
    for v in range(n):
        x1 = a[k, 0, v]
        y1 = a[k, 1, v]
        s += x0 * y1 - x1 * y0
        x0 = x1
        y0 = y1
    return 0.5 * s


@nb.njit(cache=True, nogil=True, inline="always")
def _cut(a, src, n, dst, ax, ay, ex, ey):
    """``a[src, :, :n]`` cut to the left of the line through (ax, ay) along (ex, ey), into
    ``a[dst]`` (vertices on the line kept once, crossings only where the sign changes);
    returns the count."""
    m = 0
    px = a[src, 0, n - 1]
    py = a[src, 1, n - 1]
    dp = ex * (py - ay) - ey * (px - ax)
    for v in range(n):
        qx = a[src, 0, v]
        qy = a[src, 1, v]
        dq = ex * (qy - ay) - ey * (qx - ax)
        if (dp < 0.0 and dq > 0.0) or (dp > 0.0 and dq < 0.0):
            t = dp / (dp - dq)
            a[dst, 0, m] = px + t * (qx - px)
            a[dst, 1, m] = py + t * (qy - py)
            m += 1
        if dq >= 0.0:
            a[dst, 0, m] = qx
            a[dst, 1, m] = qy
            m += 1
        px = qx
        py = qy
        dp = dq
    return m


@nb.njit(cache=True, nogil=True)
def clipped_shadow(cut, p, n, s1, s2, c0x, c0y, c1x, c1y, c2x, c2y, tiny, trust, poly, k):
    """The cut occluder ``cut[p, :n]`` (rows u, v, h) projected with slopes (s1, s2), as
    ``(u - h s1, v - h s2)``, and clipped to the counter-clockwise triangle (c0, c1, c2),
    written counter-clockwise to ``poly[k]``.

    Returns its vertex count; 0 when it meets the triangle in no area (or an area <=
    ``tiny``); -1 when it covers the triangle whole.  Rows ``-1`` and ``-2`` of ``poly`` are
    scratch.  The separating and covering tests read the shadow's edge lines only when
    ``trust`` (the caller's bound on the slope: far past it the projected vertices lie far
    off and their rounding is larger than the facet) and when it turns one way at every
    vertex (each edge line then supports it); otherwise it is clipped (which does not need
    its orientation) and oriented by the clipped area, whose vertices are near the facet.

    Examples
    --------
    A square of side 0.6 at height 1 over the triangle (0, 0), (2, 0), (0, 2): seen straight
    down its shadow lies inside the triangle; along the slope (-0.5, 0) it moves by 0.5 in
    x and the hypotenuse cuts a corner of 0.005 off it; along (3, 0) it misses.

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.coverage import clipped_shadow, workspace
    >>> cut = np.zeros((1, 9, 3))
    >>> cut[0, :4] = [[0.2, 0.2, 1.0], [0.8, 0.2, 1.0], [0.8, 0.8, 1.0], [0.2, 0.8, 1.0]]
    >>> poly = workspace(1)[0]
    >>> n = clipped_shadow(cut, 0, 4, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 2.0, 0.0, True, poly, 0)
    >>> n, poly[0, 0, :n].tolist()
    (4, [0.2, 0.8, 0.8, 0.2])
    >>> n = clipped_shadow(cut, 0, 4, -0.5, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 2.0, 0.0, True, poly, 0)
    >>> x, y = poly[0, 0, :n], poly[0, 1, :n]
    >>> n, round(float(0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)), 6)
    (5, 0.355)
    >>> clipped_shadow(cut, 0, 4, 3.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 2.0, 0.0, True, poly, 0)
    0
    """
    a = poly.shape[0] - 2  # scratch rows a, a + 1
    lo0 = lo1 = lo2 = np.inf  # least side of a vertex per triangle edge (< 0: outside)
    hi0 = hi1 = hi2 = -np.inf
    for v in range(n):
        x = cut[p, v, 0] - cut[p, v, 2] * s1
        y = cut[p, v, 1] - cut[p, v, 2] * s2
        poly[a, 0, v] = x
        poly[a, 1, v] = y
        d0 = (c1x - c0x) * (y - c0y) - (c1y - c0y) * (x - c0x)
        d1 = (c2x - c1x) * (y - c1y) - (c2y - c1y) * (x - c1x)
        d2 = (c0x - c2x) * (y - c2y) - (c0y - c2y) * (x - c2x)
        lo0, hi0 = min(lo0, d0), max(hi0, d0)
        lo1, hi1 = min(lo1, d1), max(hi1, d1)
        lo2, hi2 = min(lo2, d2), max(hi2, d2)
    if hi0 <= 0.0 or hi1 <= 0.0 or hi2 <= 0.0:  # outside one edge of the triangle
        return 0
    m = n
    src = a
    if not (lo0 >= 0.0 and lo1 >= 0.0 and lo2 >= 0.0):  # not inside the triangle
        if trust:
            state = _against_corners(poly, a, n, c0x, c0y, c1x, c1y, c2x, c2y)
            if state != 0:
                return state if state < 0 else 0
        for e in range(3):
            lo = lo0 if e == 0 else (lo1 if e == 1 else lo2)
            if lo >= 0.0:  # no vertex outside this edge
                continue
            ax = c0x if e == 0 else (c1x if e == 1 else c2x)
            ay = c0y if e == 0 else (c1y if e == 1 else c2y)
            bx = c1x if e == 0 else (c2x if e == 1 else c0x)
            by = c1y if e == 0 else (c2y if e == 1 else c0y)
            dst = a + 1 if src == a else a
            m = _cut(poly, src, m, dst, ax, ay, bx - ax, by - ay)
            src = dst
            if m < 3:
                return 0
    area = _area(poly, src, m)  # of a polygon inside the triangle: well conditioned
    if abs(area) <= tiny:
        return 0
    for v in range(m):  # counter-clockwise
        w = v if area > 0.0 else m - 1 - v
        poly[k, 0, w] = poly[src, 0, v]
        poly[k, 1, w] = poly[src, 1, v]
    return m


@nb.njit(cache=True, nogil=True, inline="always")
def _against_corners(poly, a, n, c0x, c0y, c1x, c1y, c2x, c2y):
    """The triangle against the edge lines of the polygon ``poly[a, :, :n]``: -1 if every
    corner is inside every line (covered), 1 if every corner is outside (or on) one line
    (apart), 0 otherwise or when the polygon does not turn one way at every vertex (its
    orientation, read from its turns)."""
    covered = True
    apart = False
    px = poly[a, 0, n - 1]
    py = poly[a, 1, n - 1]
    ex0 = px - poly[a, 0, n - 2]
    ey0 = py - poly[a, 1, n - 2]
    sign = 0.0
    for v in range(n):
        qx = poly[a, 0, v]
        qy = poly[a, 1, v]
        ex = qx - px
        ey = qy - py
        turn = ex0 * ey - ey0 * ex
        if sign == 0.0:
            sign = 1.0 if turn > 0.0 else -1.0
        if sign * turn <= 0.0:  # not one way: the edge lines need not support it
            return 0
        d0 = sign * (ex * (c0y - py) - ey * (c0x - px))
        d1 = sign * (ex * (c1y - py) - ey * (c1x - px))
        d2 = sign * (ex * (c2y - py) - ey * (c2x - px))
        if d0 <= 0.0 and d1 <= 0.0 and d2 <= 0.0:
            apart = True
        if d0 < 0.0 or d1 < 0.0 or d2 < 0.0:
            covered = False
        px = qx
        py = qy
        ex0 = ex
        ey0 = ey
    if apart:
        return 1
    return -1 if covered else 0


@nb.njit(cache=True, nogil=True)
def _supporting(poly, count, k, scratch):
    """Make ``poly[k]`` turn left at every vertex (each edge line then supports it), by
    Graham's scan in its own order from its lowest vertex (it is convex up to rounding:
    its vertices are sorted by angle about that vertex); ``poly[scratch]`` is scratch.
    Returns the count left (< 3: no area)."""
    n = count[k]
    ok = True
    for v in range(n):
        a = v - 1 if v > 0 else n - 1
        b = v + 1 if v + 1 < n else 0
        turn = (poly[k, 0, v] - poly[k, 0, a]) * (poly[k, 1, b] - poly[k, 1, v])
        if turn - (poly[k, 1, v] - poly[k, 1, a]) * (poly[k, 0, b] - poly[k, 0, v]) <= 0.0:
            ok = False
            break
    if ok:
        return n
    s0 = 0
    for v in range(1, n):
        if poly[k, 1, v] < poly[k, 1, s0] or (
            poly[k, 1, v] == poly[k, 1, s0] and poly[k, 0, v] < poly[k, 0, s0]
        ):
            s0 = v
    m = 0
    for j in range(n + 1):
        v = s0 + j if s0 + j < n else s0 + j - n
        x = poly[k, 0, v]
        y = poly[k, 1, v]
        while (
            m >= 2
            and (poly[scratch, 0, m - 1] - poly[scratch, 0, m - 2]) * (y - poly[scratch, 1, m - 2])
            - (poly[scratch, 1, m - 1] - poly[scratch, 1, m - 2]) * (x - poly[scratch, 0, m - 2])
            <= 0.0
        ):
            m -= 1
        if j < n:
            poly[scratch, 0, m] = x
            poly[scratch, 1, m] = y
            m += 1
    for v in range(m):
        poly[k, 0, v] = poly[scratch, 0, v]
        poly[k, 1, v] = poly[scratch, 1, v]
    count[k] = m
    return m


@nb.njit(cache=True, nogil=True, inline="always")
def _split(work, r, n, ax, ay, ex, ey, out, inside):
    """``work[r, :, :n]`` split by the line through (ax, ay) along (ex, ey): the part right
    of it into ``work[out]``, the part left of it into ``work[inside]``, in one pass.
    Returns ``(n_out, n_in)``; ``(0, -1)`` when all of it is left of the line (nothing
    written: it stays as it is), ``(-1, 0)`` when none is (nothing written: all of it is
    outside)."""
    d = work.shape[0] - 1  # the sides, in row d
    lo = np.inf
    hi = -np.inf
    for v in range(n):
        side = ex * (work[r, 1, v] - ay) - ey * (work[r, 0, v] - ax)
        work[d, 0, v] = side
        lo = min(lo, side)
        hi = max(hi, side)
    if lo >= 0.0:
        return 0, -1
    if hi <= 0.0:
        return -1, 0
    no = 0
    ni = 0
    px = work[r, 0, n - 1]
    py = work[r, 1, n - 1]
    dp = work[d, 0, n - 1]
    for v in range(n):
        qx = work[r, 0, v]
        qy = work[r, 1, v]
        dq = work[d, 0, v]
        if (dp < 0.0 and dq > 0.0) or (dp > 0.0 and dq < 0.0):
            t = dp / (dp - dq)
            x = px + t * (qx - px)
            y = py + t * (qy - py)
            work[out, 0, no] = x
            work[out, 1, no] = y
            work[inside, 0, ni] = x
            work[inside, 1, ni] = y
            no += 1
            ni += 1
        if dq <= 0.0:
            work[out, 0, no] = qx
            work[out, 1, no] = qy
            no += 1
        if dq >= 0.0:
            work[inside, 0, ni] = qx
            work[inside, 1, ni] = qy
            ni += 1
        px = qx
        py = qy
        dp = dq
    return no, ni


@nb.njit(cache=True, nogil=True)
def _minus(work, wn, src, dst, out, poly, count, j, tiny):
    """The pieces ``work[src:src + out]`` less the convex ``poly[j]``, written to
    ``work[dst:]``; returns the new piece count, -1 past the capacity."""
    n = count[j]
    x0 = x1 = poly[j, 0, 0]
    y0 = y1 = poly[j, 1, 0]
    for v in range(1, n):
        x0 = min(x0, poly[j, 0, v])
        x1 = max(x1, poly[j, 0, v])
        y0 = min(y0, poly[j, 1, v])
        y1 = max(y1, poly[j, 1, v])
    rest = 2 * _PIECES  # rows rest, rest + 1: the part of a piece inside the lines so far
    made = 0
    for a in range(src, src + out):
        na = wn[a]
        lx = hx = work[a, 0, 0]
        ly = hy = work[a, 1, 0]
        for v in range(1, na):
            lx = min(lx, work[a, 0, v])
            hx = max(hx, work[a, 0, v])
            ly = min(ly, work[a, 1, v])
            hy = max(hy, work[a, 1, v])
        r = a
        nr = na
        if not (lx >= x1 or hx <= x0 or ly >= y1 or hy <= y0):  # boxes overlap
            for e in range(n):
                e1 = e + 1 if e + 1 < n else 0
                ax = poly[j, 0, e]
                ay = poly[j, 1, e]
                if made == _PIECES or nr + 1 > _PIECE:
                    return -1
                t = rest if r != rest else rest + 1
                no, ni = _split(
                    work, r, nr, ax, ay, poly[j, 0, e1] - ax, poly[j, 1, e1] - ay, dst + made, t
                )
                if no < 0:  # all of the rest is outside this edge: it is the piece
                    break
                if no >= 3 and _area(work, dst + made, no) > tiny:
                    wn[dst + made] = no
                    made += 1
                if ni >= 0:
                    r = t
                    nr = ni
                if nr < 3:
                    break
            else:
                continue  # what is left is inside the polygon: dropped
            if nr < 3:
                continue
        if made == _PIECES:
            return -1
        for v in range(nr):  # the piece (or its rest) stays
            work[dst + made, 0, v] = work[r, 0, v]
            work[dst + made, 1, v] = work[r, 1, v]
        wn[dst + made] = nr
        made += 1
    return made


@nb.njit(cache=True, nogil=True)
def covered_area(poly, count, m, tiny, work, wn):
    """Area of the union of the m convex counter-clockwise polygons ``poly[:m]`` (counts
    ``count``), as ``sum_k area(P_k minus P_0 ... P_k-1)``: every term a sum of positive
    piece areas (pieces of area <= ``tiny`` dropped).  ``work`` and ``wn`` are
    :func:`workspace`'s.  Each subtracted polygon first turns left at every vertex
    (Graham's scan in its order).  Returns the area, or -1.0 when the pieces would overflow
    the workspace (the caller unites the polygons otherwise).

    Examples
    --------
    The squares [0, 1]^2 and [0.5, 1.5] x [0, 1] and the triangle (0, 0), (1, 0), (0, 1),
    inside the first: 1.5.

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.coverage import covered_area, workspace
    >>> poly, count, work, wn = workspace(3)
    >>> poly[0, :, :4] = [[0, 1, 1, 0], [0, 0, 1, 1]]
    >>> poly[1, :, :4] = [[0.5, 1.5, 1.5, 0.5], [0, 0, 1, 1]]
    >>> poly[2, :, :3] = [[0, 1, 0], [0, 0, 1]]
    >>> count[:3] = [4, 4, 3]
    >>> float(covered_area(poly, count, 3, 0.0, work, wn))
    1.5
    """
    if m == 1:
        return _area(poly, 0, count[0])
    scratch = poly.shape[0] - 1
    total = 0.0
    for k in range(m):
        if k < m - 1 and _supporting(poly, count, k, scratch) < 3:
            count[k] = 0
        n = count[k]
        if n < 3:
            continue
        for v in range(n):
            work[0, 0, v] = poly[k, 0, v]
            work[0, 1, v] = poly[k, 1, v]
        wn[0] = n
        out = 1
        src = 0
        for j in range(k):
            if count[j] < 3:
                continue
            dst = _PIECES if src == 0 else 0
            out = _minus(work, wn, src, dst, out, poly, count, j, tiny)
            if out < 0:
                return -1.0
            src = dst
            if out == 0:
                break
        for a in range(src, src + out):
            total += _area(work, a, wn[a])
    return total
