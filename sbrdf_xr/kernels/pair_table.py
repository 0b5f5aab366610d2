"""The table of the pairs of facets that can shadow each other, built once per body (numba).

For every receiving facet ``i``, the occluders that can ever shadow it are those with a
part strictly in front of its plane (the half-space test); each is cut to that part and
stored in the plane frame of ``i`` as vertices ``(u, v, h)`` (in-plane coordinates and
height above the plane), with the box of the slopes ``s = (E1_i.d, E2_i.d) / N_i.d`` of the
directions ``d`` from which its shadow can reach the facet: the quotients ``(u - a) / h``
over the cut vertices and the facet's vertices ``a`` bound it (a linear-fractional function
takes its extremes at vertices), a vertex on the plane (``h = 0``) opening the box on the
side its numerator has.  Three more bounds use the facet's edges as separating axes: with
``w`` the unit direction of edge ``e`` (from corner ``c``), the projected vertex
``(u - h s_1, v - h s_2)`` is on or outside the edge when ``w x (u - c) - h (w x s) <= 0``,
so the whole shadow is outside it when ``sigma = w_1 s_2 - w_2 s_1`` exceeds
``tau = max (w x (u - c)) / h`` over the cut vertices (``+inf`` if a vertex on the plane
is inside the edge line); ``tau`` is widened by the same margin as the box.  The pairs of
a facet are sorted by the distance of their box from ``s = 0``.
:func:`sbrdf_xr.kernels.shadow_pairs.pairs_kernel` reads the table.
"""

from __future__ import annotations

import numba as nb
import numpy as np

# Compiled into this module's kernels: numba's disk cache of a module is keyed by its own
# source file only, so a change of these two (shadow_pairs) must come with an edit here,
# or a tree that already compiled this module loads machine code built against the old
# ones (a crash).  Last rebuilt against them: the coverage pieces of the pair kernel.
from .shadow_pairs import _buffers, _pairs_into

__all__ = [
    "MARGIN",
    "MAX_OCCLUDER_VERTICES",
    "grouped_pair_table",
    "merged_tables",
    "pair_table",
    "posed_pairs_kernel",
]

#: Vertices of a merged occluder polygon at most (its cut adds one, the clip three more).
MAX_OCCLUDER_VERTICES = 8
#: Relative widening of every slope box (the rounding of the slopes is ~1e-16 relative).
MARGIN = 1e-12
_CUT = MAX_OCCLUDER_VERTICES + 1  # vertices of a cut occluder


@nb.njit(cache=True, nogil=True)
def _cut(i, idx, n, V, N, P0, E1, E2, out):
    """The part of the polygon ``V[idx[:n]]`` on or in front of the plane of facet i, in the
    frame of i: rows (u, v, h) of ``out``; returns the vertex count."""
    m = 0
    for a in range(n):
        b = a + 1 if a + 1 < n else 0
        fa = idx[a]
        fb = idx[b]
        ha = N[i, 0] * (V[fa, 0] - P0[i, 0]) + N[i, 1] * (V[fa, 1] - P0[i, 1])
        ha += N[i, 2] * (V[fa, 2] - P0[i, 2])
        hb = N[i, 0] * (V[fb, 0] - P0[i, 0]) + N[i, 1] * (V[fb, 1] - P0[i, 1])
        hb += N[i, 2] * (V[fb, 2] - P0[i, 2])
        if ha >= 0.0:
            y0 = V[fa, 0] - P0[i, 0]
            y1 = V[fa, 1] - P0[i, 1]
            y2 = V[fa, 2] - P0[i, 2]
            out[m, 0] = E1[i, 0] * y0 + E1[i, 1] * y1 + E1[i, 2] * y2
            out[m, 1] = E2[i, 0] * y0 + E2[i, 1] * y1 + E2[i, 2] * y2
            out[m, 2] = ha
            m += 1
        if (ha >= 0.0) != (hb >= 0.0):
            t = ha / (ha - hb)
            y0 = V[fa, 0] + t * (V[fb, 0] - V[fa, 0]) - P0[i, 0]
            y1 = V[fa, 1] + t * (V[fb, 1] - V[fa, 1]) - P0[i, 1]
            y2 = V[fa, 2] + t * (V[fb, 2] - V[fa, 2]) - P0[i, 2]
            out[m, 0] = E1[i, 0] * y0 + E1[i, 1] * y1 + E1[i, 2] * y2
            out[m, 1] = E2[i, 0] * y0 + E2[i, 1] * y1 + E2[i, 2] * y2
            out[m, 2] = 0.0
            m += 1
    return m


@nb.njit(cache=True, nogil=True)
def _slope_box(cut, n, tri, box):
    """Bounding box (s1 lo, s1 hi, s2 lo, s2 hi) of the slopes s for which the cut polygon
    (rows u, v, h) projected along d can meet the triangle ``tri`` (3, 2), then the three
    thresholds past which it lies outside an edge of the triangle; returns the box's
    squared distance from s = 0."""
    r2 = 0.0
    for c in range(2):
        t_lo = min(tri[0, c], tri[1, c], tri[2, c])
        t_hi = max(tri[0, c], tri[1, c], tri[2, c])
        lo = np.inf
        hi = -np.inf
        for v in range(n):
            x = cut[v, c]
            h = cut[v, 2]
            if h > 0.0:
                lo = min(lo, (x - t_hi) / h)
                hi = max(hi, (x - t_lo) / h)
            else:
                if x > t_lo:
                    hi = np.inf
                if x < t_hi:
                    lo = -np.inf
        lo -= MARGIN * (1.0 + abs(lo))
        hi += MARGIN * (1.0 + abs(hi))
        box[2 * c] = lo
        box[2 * c + 1] = hi
        if lo > 0.0:
            r2 += lo * lo
        elif hi < 0.0:
            r2 += hi * hi
    for e in range(3):  # the triangle's edges as separating axes (module docstring)
        e1 = e + 1 if e < 2 else 0
        ux = tri[e1, 0] - tri[e, 0]
        uy = tri[e1, 1] - tri[e, 1]
        norm = np.sqrt(ux * ux + uy * uy)
        ux /= norm
        uy /= norm
        tau = -np.inf
        for v in range(n):
            a = ux * (cut[v, 1] - tri[e, 1]) - uy * (cut[v, 0] - tri[e, 0])
            if cut[v, 2] > 0.0:
                tau = max(tau, a / cut[v, 2])
            elif a > 0.0:
                tau = np.inf
        box[4 + e] = tau + MARGIN * (1.0 + abs(tau)) if np.isfinite(tau) else tau
    return r2


@nb.njit(cache=True, nogil=True)
def _height_range(i, f, V, F, N, P0):
    lo = np.inf
    hi = -np.inf
    for v in range(3):
        x = F[f, v]
        h = N[i, 0] * (V[x, 0] - P0[i, 0]) + N[i, 1] * (V[x, 1] - P0[i, 1])
        h += N[i, 2] * (V[x, 2] - P0[i, 2])
        lo = min(lo, h)
        hi = max(hi, h)
    return lo, hi


@nb.njit(cache=True, nogil=True)
def pair_table(
    V, F, N, P0, E1, E2, T2, receiver, poly, npoly, gnorm, gopen, mstart, members, eps_h
):
    """The pairs (receiver, occluder) that can shadow each other, once per body.

    ``poly`` (n_groups, :data:`MAX_OCCLUDER_VERTICES`) holds the vertex indices of every
    occluder polygon (``npoly`` of them used, counter-clockwise about ``gnorm``), whose
    facets are ``members[mstart[g]:mstart[g + 1]]``.  A pair is kept when the occluder has
    a vertex higher than ``eps_h`` above the receiver's plane and is not parallel to it
    facing the same way (such a one-sided facet is never an occluder while the receiver
    faces the light).  Returns ``(recv, pstart, pgroup, pcount, cut, box, r2)``: the
    receivers, CSR offsets of their pairs, each pair's occluder, its cut polygon (count and
    rows u, v, h in the receiver's frame), its slope box (columns 0-3) and edge thresholds
    (columns 4-6, module docstring) and the squared distance of the box from 0 (ascending
    within a receiver).

    Examples
    --------
    The two plates of :func:`sbrdf_xr.kernels.shadow.exact_kernel` (a 2 x 2 plate at
    z = 0, a 1 x 2 plate above its left half at z = 1, open: one-sided facets blocking from
    both sides), each facet its own occluder: both lower facets can be shadowed by both
    upper ones, and nothing can shadow the upper ones.

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.pair_table import pair_table
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
    >>> npoly, gopen = np.full(4, 3), np.ones(4, bool)
    >>> mstart, members = np.arange(5), np.arange(4)
    >>> recv, pstart, pgroup, pcount, cut, box, r2 = pair_table(
    ...     V, F, N, V[F[:, 0]], E1, E2, T2, np.ones(4, bool), poly, npoly, N, gopen,
    ...     mstart, members, 1e-9)
    >>> recv.tolist(), pstart.tolist(), sorted(pgroup[:2].tolist()), pcount.tolist()
    ([0, 1, 2, 3], [0, 2, 4, 4, 4], [2, 3], [3, 3, 3, 3])
    >>> cut[0, :3, 2].tolist()  # heights of the upper facets above the lower plane
    [1.0, 1.0, 1.0]
    """
    same = np.zeros(max(F.shape[0], poly.shape[0]), dtype=np.int64)
    return grouped_pair_table(
        V,
        F,
        N,
        P0,
        E1,
        E2,
        T2,
        receiver,
        poly,
        npoly,
        gnorm,
        gopen,
        mstart,
        members,
        eps_h,
        same[: F.shape[0]],
        same[: poly.shape[0]],
        True,
    )


@nb.njit(cache=True, nogil=True)
def grouped_pair_table(
    V,
    F,
    N,
    P0,
    E1,
    E2,
    T2,
    receiver,
    poly,
    npoly,
    gnorm,
    gopen,
    mstart,
    members,
    eps_h,
    rgroup,
    ogroup,
    within,
):
    """:func:`pair_table` of the pairs within the rigid groups of a posed body (``within``
    True: receiver ``i`` and occluder ``g`` with ``rgroup[i] == ogroup[g]``) or between
    them (False).  The pairs within a group keep their frame coordinates, boxes and
    thresholds when the group turns, so they are found once; those between groups per pose.

    Examples
    --------
    The two plates of :func:`pair_table`'s example, the upper one a group of its own: all
    the pairs are between groups.

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.pair_table import grouped_pair_table
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
    >>> group = np.array([0, 0, 1, 1])
    >>> args = (V, F, N, V[F[:, 0]], E1, E2, T2, np.ones(4, bool), poly, np.full(4, 3), N,
    ...         np.ones(4, bool), np.arange(5), np.arange(4), 1e-9, group, group)
    >>> [grouped_pair_table(*args, w)[1].tolist() for w in (True, False)]  # pstart
    [[0, 0, 0, 0, 0], [0, 2, 4, 4, 4]]
    """
    nf = F.shape[0]
    ng = poly.shape[0]
    cap = max(16, 4 * nf)
    pgroup = np.empty(cap, dtype=np.int64)
    pcount = np.empty(cap, dtype=np.int64)
    cut = np.empty((cap, _CUT, 3))
    box = np.empty((cap, 7))
    r2 = np.empty(cap)
    recv = np.empty(nf, dtype=np.int64)
    pstart = np.zeros(nf + 1, dtype=np.int64)
    scratch = np.empty((_CUT, 3))
    one = np.empty(3, dtype=np.int64)
    nr = 0
    n = 0
    for i in range(nf):
        if not receiver[i]:
            continue
        first = n
        tri = T2[i]
        for g in range(ng):
            if (rgroup[i] == ogroup[g]) != within:
                continue
            if (
                not gopen[g]
                and gnorm[g, 0] == N[i, 0]
                and gnorm[g, 1] == N[i, 1]
                and gnorm[g, 2] == N[i, 2]
            ):
                continue
            hmax = -np.inf
            for v in range(npoly[g]):
                x = poly[g, v]
                h = N[i, 0] * (V[x, 0] - P0[i, 0]) + N[i, 1] * (V[x, 1] - P0[i, 1])
                hmax = max(hmax, h + N[i, 2] * (V[x, 2] - P0[i, 2]))
            if hmax <= eps_h:
                continue
            whole = True  # no facet of it a sliver in the tolerance band: merged is exact
            if mstart[g + 1] - mstart[g] > 1:
                for q in range(mstart[g], mstart[g + 1]):
                    _, hi = _height_range(i, members[q], V, F, N, P0)
                    if hi <= eps_h and hi >= 0.0:
                        whole = False
            for q in range(mstart[g], mstart[g + 1] if not whole else mstart[g] + 1):
                if whole:
                    m = _cut(i, poly[g], npoly[g], V, N, P0, E1, E2, scratch)
                else:
                    f = members[q]
                    _, hi = _height_range(i, f, V, F, N, P0)
                    if hi <= eps_h or f == i:
                        continue
                    for v in range(3):
                        one[v] = F[f, v]
                    m = _cut(i, one, 3, V, N, P0, E1, E2, scratch)
                if m < 3:
                    continue
                if n == cap:  # grow
                    cap *= 2
                    pgroup = _grown(pgroup, cap)
                    pcount = _grown(pcount, cap)
                    cut = _grown3(cut, cap)
                    box = _grown2(box, cap)
                    r2 = _grown(r2, cap)
                pgroup[n] = g
                pcount[n] = m
                cut[n, :m] = scratch[:m]
                r2[n] = _slope_box(scratch, m, tri, box[n])
                n += 1
        order = np.argsort(r2[first:n], kind="mergesort") + first
        pgroup[first:n] = pgroup[order]
        pcount[first:n] = pcount[order]
        cut[first:n] = cut[order]
        box[first:n] = box[order]
        r2[first:n] = r2[order]
        recv[nr] = i
        nr += 1
        pstart[nr] = n
    return (
        recv[:nr].copy(),
        pstart[: nr + 1].copy(),
        pgroup[:n].copy(),
        pcount[:n].copy(),
        cut[:n].copy(),
        box[:n].copy(),
        r2[:n].copy(),
    )


@nb.njit(cache=True, nogil=True)
def _grown(a, cap):
    out = np.empty(cap, dtype=a.dtype)
    out[: a.shape[0]] = a
    return out


@nb.njit(cache=True, nogil=True)
def _grown2(a, cap):
    out = np.empty((cap, a.shape[1]), dtype=a.dtype)
    out[: a.shape[0]] = a
    return out


@nb.njit(cache=True, nogil=True)
def _grown3(a, cap):
    out = np.empty((cap, a.shape[1], a.shape[2]), dtype=a.dtype)
    out[: a.shape[0]] = a
    return out


@nb.njit(cache=True, nogil=True)
def merged_tables(a, b):
    """Two tables of the same receivers (as :func:`grouped_pair_table` gives them for one
    receiver mask) merged into one, each receiver's pairs still in ascending ``r2``.

    Examples
    --------
    The tables within and between the groups of :func:`grouped_pair_table`'s example
    give :func:`pair_table`'s:

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.pair_table import grouped_pair_table, merged_tables
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
    >>> group = np.array([0, 0, 1, 1])
    >>> args = (V, F, N, V[F[:, 0]], E1, E2, T2, np.ones(4, bool), poly, np.full(4, 3), N,
    ...         np.ones(4, bool), np.arange(5), np.arange(4), 1e-9, group, group)
    >>> table = merged_tables(grouped_pair_table(*args, True), grouped_pair_table(*args, False))
    >>> table[1].tolist(), table[2].tolist()
    ([0, 2, 4, 4, 4], [2, 3, 2, 3])
    """
    recv, pa, ga, ca, cuta, boxa, ra = a
    _, pb, gb, cb, cutb, boxb, rb = b
    n = ga.shape[0] + gb.shape[0]
    pstart = np.zeros(recv.shape[0] + 1, dtype=np.int64)
    pgroup = np.empty(n, dtype=np.int64)
    pcount = np.empty(n, dtype=np.int64)
    cut = np.empty((n, cuta.shape[1], 3))
    box = np.empty((n, boxa.shape[1]))
    r2 = np.empty(n)
    k = 0
    for r in range(recv.shape[0]):
        i = pa[r]
        j = pb[r]
        while i < pa[r + 1] or j < pb[r + 1]:
            if j == pb[r + 1] or (i < pa[r + 1] and ra[i] <= rb[j]):
                pgroup[k], pcount[k], cut[k], box[k], r2[k] = ga[i], ca[i], cuta[i], boxa[i], ra[i]
                i += 1
            else:
                pgroup[k], pcount[k], cut[k], box[k], r2[k] = gb[j], cb[j], cutb[j], boxb[j], rb[j]
                j += 1
            k += 1
        pstart[r + 1] = k
    return recv, pstart, pgroup, pcount, cut, box, r2


@nb.njit(cache=True, nogil=True)
def posed_pairs_kernel(frames, turned, occluders, within, active, eps_h, dirs):
    """Lit fractions (G, n_facets) of a posed body, one pose per geometry, by the pair table.

    ``frames`` (V, F, N, P0, E1, E2, T2): the rest frames, copies whose rows this turns;
    ``turned`` (pV, pN, pE1, pE2, pP0, vrows, rows): per geometry, the posed vertices
    ``vrows`` and the posed frames of the facets ``rows`` (the parts'); ``occluders``
    (receiver, poly, count, open, start, members, seeds, rgroup, ogroup): the occluder
    polygons (their normals are their seed facets' posed ones), the facets' and polygons'
    groups; ``within``: :func:`grouped_pair_table` of the pairs within groups, found once.
    Per pose the pairs between groups are found and merged in, and
    :func:`~sbrdf_xr.kernels.shadow_pairs.pairs_kernel` runs (one scratch for all poses).
    Rows of geometries not ``active`` stay 0 (the caller knows nothing is shadowed there).

    Examples
    --------
    The two plates of :func:`pair_table`'s example, the upper one a part turned by 0 and by
    90 degree about the line x = 0.5, z = 1 (edge-on: it shades nothing), lit from +z:

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.pair_table import grouped_pair_table, posed_pairs_kernel
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
    >>> group, ok, gopen = np.array([0, 0, 1, 1]), np.ones(4, bool), np.ones(4, bool)
    >>> frames = (V, F, N, V[F[:, 0]], E1, E2, T2)
    >>> occ = (ok, poly, np.full(4, 3), gopen, np.arange(5), np.arange(4), np.arange(4),
    ...        group, group)
    >>> within = grouped_pair_table(*frames, *occ[:3], N, *occ[3:6], 1e-9, group, group, True)
    >>> R = np.array([np.eye(3), [[0, 0, 1.0], [0, 1, 0], [-1.0, 0, 0]]])  # about y
    >>> hinge = np.array([0.5, 0.0, 1.0])
    >>> pV = hinge + np.einsum("gij,vj->gvi", R, V[4:] - hinge)
    >>> turn = lambda a: np.einsum("gij,fj->gfi", R, a[2:])
    >>> turned = (pV, turn(N), turn(E1), turn(E2), hinge + turn(V[F[:, 0]] - hinge),
    ...           np.arange(4, 8), np.arange(2, 4))
    >>> dirs = np.tile([0.0, 0.0, 1.0], (2, 1, 1))
    >>> copies = tuple(a.copy() for a in frames)
    >>> f = posed_pairs_kernel(copies, turned, occ, within, np.ones(2, bool), 1e-9, dirs)
    >>> print(np.round(f[:, :2], 6))  # the lower plate's two triangles
    [[0.75 0.25]
     [1.   1.  ]]
    """
    V, F, N, P0, E1, E2, T2 = frames
    pV, pN, pE1, pE2, pP0, vrows, rows = turned
    receiver, poly, npoly, gopen, mstart, members, seeds, rgroup, ogroup = occluders
    G = dirs.shape[0]
    frac = np.zeros((G, N.shape[0]))
    gnorm = np.empty((seeds.shape[0], 3))
    buf = _buffers(dirs, gnorm)
    for g in range(G):
        if not active[g]:
            continue
        for a in range(vrows.shape[0]):
            for c in range(3):
                V[vrows[a], c] = pV[g, a, c]
        for a in range(rows.shape[0]):
            for c in range(3):
                N[rows[a], c] = pN[g, a, c]
                E1[rows[a], c] = pE1[g, a, c]
                E2[rows[a], c] = pE2[g, a, c]
                P0[rows[a], c] = pP0[g, a, c]
        for q in range(seeds.shape[0]):
            for c in range(3):
                gnorm[q, c] = N[seeds[q], c]
        between = grouped_pair_table(
            V,
            F,
            N,
            P0,
            E1,
            E2,
            T2,
            receiver,
            poly,
            npoly,
            gnorm,
            gopen,
            mstart,
            members,
            eps_h,
            rgroup,
            ogroup,
            False,
        )
        table = merged_tables(within, between)
        d = dirs[g : g + 1]
        _pairs_into(frac[g : g + 1], N, N, E1, E2, T2, table, gnorm, gopen, d, buf)
    return frac
