"""The exact shadow method by a table of the pairs that can shadow each other (numba, nogil).

The grid kernel of :mod:`sbrdf_xr.kernels.shadow` finds the candidate occluders of every
facet anew for every direction.  Most of that work does not depend on the direction, so
it is done once per body (:func:`sbrdf_xr.kernels.pair_table.pair_table`): every
receiving facet's occluders, cut and stored in its frame as ``(u, v, h)`` with the box of
slopes ``s = (E1_i.d, E2_i.d) / N_i.d`` from which each can reach it.  Here, per direction,
a pair costs a box test and its shadow four flops per vertex, ``(u - h s_1, v - h s_2)``;
a facet's pairs are sorted by the distance of their box from ``s = 0``, so a direction
high above the facet stops early.  A shadow is rejected when an edge of the facet or of
the shadow separates them, clipped by only the facet edges it crosses, and a shadow
covering the facet whole stops it at once (:func:`~sbrdf_xr.kernels.coverage.
clipped_shadow`).  The shadows along the ``K`` directions of a geometry are united as a
sum of positive terms, each shadow less those before it
(:func:`~sbrdf_xr.kernels.coverage.covered_area`; vertical slabs past its workspace).  The
skipped pairs are those whose shadow is empty (a relative margin of
:data:`~sbrdf_xr.kernels.pair_table.MARGIN` on the box), so the result is the grid
kernel's to float rounding.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from .coverage import clipped_shadow, covered_area, workspace
from .polygon import union_area_slabs
from .shadow import MAX_SHADOWS

__all__ = ["STAGES", "pairs_kernel"]

_CHUNK = 512  # geometries whose facing flags are held while each receiver runs through them
#: The stages of :func:`pairs_kernel`, in order; ``stage=k`` stops after the k-th (a profile:
#: the fractions are then not final).
STAGES = ("facing", "walk", "shadows", "union")
#: Squared slope up to which a shadow's edge lines are trusted to reject or cover a facet
#: (|s| <= 1e3: its vertices within 1e3 body sizes, their rounding 1e-13 of the body).
_TRUST = 1e6


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
def pairs_kernel(
    normals, N, E1, E2, T2, recv, pstart, pgroup, pcount, cut, box, r2, gnorm, gopen, dirs, stage=4
):
    """Lit (and visible) fraction of every facet for every geometry, from the pair table.

    ``dirs`` (G, K, 3): K unit directions per geometry that must all be unobstructed.  The
    table is :func:`~sbrdf_xr.kernels.pair_table.pair_table`'s; ``gnorm``, ``gopen`` the
    occluders' normals and open flags (an occluder blocks d when its normal faces away from
    d, or when it is one-sided on an open surface).  A facet facing away from a direction
    gets 0, by its ``normals`` (the stored ones, which decide) or by ``N`` (its winding, as
    the grid kernel has it);
    a facet that is no receiver and faces every direction gets 1; a receiver with more
    shadows than the buffers hold gets NaN (the caller unites them with GEOS).  ``stage``
    < 4 stops after that step of :data:`STAGES` (to profile the kernel).

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
    buf = _buffers(dirs, gnorm)
    _pairs_into(frac, normals, N, E1, E2, T2, table, gnorm, gopen, dirs, buf, stage)
    return frac


@nb.njit(cache=True, nogil=True)
def _buffers(dirs, gnorm):
    """The scratch of :func:`_pairs_into` for directions like ``dirs`` and the occluders of
    ``gnorm`` (allocated once per call of :func:`pairs_kernel`, or once per posed sweep)."""
    occ = np.empty((_CHUNK, dirs.shape[1], gnorm.shape[0]), dtype=np.bool_)
    return occ, np.empty((dirs.shape[1], 2)), np.empty((3, 2)), workspace(MAX_SHADOWS)


@nb.njit(cache=True, nogil=True)
def _pairs_into(frac, normals, N, E1, E2, T2, table, gnorm, gopen, dirs, buf, stage=4):
    """:func:`pairs_kernel` written into ``frac`` (G, n_facets), with its scratch ``buf``:
    a chunk of geometries' facing flags, then each receiver through the chunk."""
    occ = buf[0]
    G = dirs.shape[0]
    for g0 in range(0, G, _CHUNK):
        g1 = min(G, g0 + _CHUNK)
        for g in range(g0, g1):
            _facing(dirs, g, normals, gnorm, gopen, occ[g - g0], frac)
        if stage < 2:
            continue
        for r in range(table[0].shape[0]):
            _receiver(frac, r, g0, g1, N, E1, E2, T2, table, dirs, buf, stage)
    return frac


@nb.njit(cache=True, nogil=True)
def _slopes(N, E1, E2, i, dirs, g, s):
    """Slopes ``s[k] = (E1_i.d, E2_i.d) / N_i.d`` of the K directions of geometry g in the
    frame of facet i; returns their largest squared length, or -1.0 if the facet does not
    face one of them."""
    rad = 0.0
    for k in range(dirs.shape[1]):
        d0 = dirs[g, k, 0]
        d1 = dirs[g, k, 1]
        d2 = dirs[g, k, 2]
        nd = N[i, 0] * d0 + N[i, 1] * d1 + N[i, 2] * d2
        if nd <= 0.0:
            return -1.0
        s[k, 0] = (E1[i, 0] * d0 + E1[i, 1] * d1 + E1[i, 2] * d2) / nd
        s[k, 1] = (E2[i, 0] * d0 + E2[i, 1] * d1 + E2[i, 2] * d2) / nd
        rad = max(rad, s[k, 0] * s[k, 0] + s[k, 1] * s[k, 1])
    return rad


@nb.njit(cache=True, nogil=True)
def _receiver(frac, r, g0, g1, N, E1, E2, T2, table, dirs, buf, stage):
    """Receiver ``r`` of the table through the geometries g0 <= g < g1: its pairs walked
    while their slope boxes can reach it, the shadows of those that pass the box and edge
    tests clipped to it, their union's area turned into its lit fraction."""
    recv, pstart, pgroup, pcount, cut, box, r2 = table
    occ, s, w, space = buf
    poly, count, work, wn = space
    i = recv[r]
    p0 = pstart[r]
    p1 = pstart[r + 1]
    c0x, c0y, c1x, c1y = T2[i, 0, 0], T2[i, 0, 1], T2[i, 1, 0], T2[i, 1, 1]
    c2x, c2y = T2[i, 2, 0], T2[i, 2, 1]
    for e in range(3):  # unit edge directions: the separating axes of the table
        e1 = e + 1 if e < 2 else 0
        norm = np.sqrt((T2[i, e1, 0] - T2[i, e, 0]) ** 2 + (T2[i, e1, 1] - T2[i, e, 1]) ** 2)
        w[e, 0] = (T2[i, e1, 0] - T2[i, e, 0]) / norm
        w[e, 1] = (T2[i, e1, 1] - T2[i, e, 1]) / norm
    area_t = 0.5 * ((c1x - c0x) * (c2y - c0y) - (c2x - c0x) * (c1y - c0y))
    tiny = 1e-15 * area_t
    for g in range(g0, g1):
        rad = _slopes(N, E1, E2, i, dirs, g, s)
        if rad < 0.0 or frac[g, i] == 0.0:
            frac[g, i] = 0.0
            continue
        if p0 == p1 or r2[p0] > rad:
            continue  # nothing can reach this high above the facet: fraction 1
        m = 0
        too_many = False
        covered = False
        trust = rad <= _TRUST
        for p in range(p0, p1):
            if r2[p] > rad:
                break
            q = pgroup[p]
            for k in range(dirs.shape[1]):
                s1 = s[k, 0]
                s2 = s[k, 1]
                if (
                    not occ[g - g0, k, q]
                    or s1 < box[p, 0]
                    or s1 > box[p, 1]
                    or s2 < box[p, 2]
                    or s2 > box[p, 3]
                    or w[0, 0] * s2 - w[0, 1] * s1 > box[p, 4]
                    or w[1, 0] * s2 - w[1, 1] * s1 > box[p, 5]
                    or w[2, 0] * s2 - w[2, 1] * s1 > box[p, 6]
                    or stage < 3
                ):
                    continue
                if m == MAX_SHADOWS:
                    too_many = True
                    continue
                nq = clipped_shadow(
                    cut, p, pcount[p], s1, s2, c0x, c0y, c1x, c1y, c2x, c2y, tiny, trust, poly, m
                )
                if nq < 0:
                    covered = True
                    break
                if nq > 0:
                    count[m] = nq
                    m += 1
            if covered:
                break
        if covered:
            frac[g, i] = 0.0
        elif too_many:
            frac[g, i] = np.nan
        elif m > 0 and stage >= 4:
            area = covered_area(poly, count, m, 1e-17 * area_t, work, wn)
            if area < 0.0:  # more pieces than the workspace holds: vertical slabs
                area = union_area_slabs(poly[:, 0], poly[:, 1], count, m)
            frac[g, i] = min(1.0, max(0.0, 1.0 - area / area_t))
