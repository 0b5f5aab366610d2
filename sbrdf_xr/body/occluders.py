"""Occluders of the exact shadow method, found once per body: merged polygons and pairs.

Two steps of :mod:`sbrdf_xr.body.visibility`'s exact method that do not depend on the
Sun or the observer, cached with the body:

* :func:`occluder_polygons`: coplanar facets that share an edge are merged into convex
  polygons (the two triangles of a rectangle become one quadrilateral).  The shadow of
  such a polygon is the union of its facets' shadows (cutting by a plane, projecting
  along a direction and clipping to a convex facet are exact on a convex union), so
  fewer, larger shadows are united per receiving facet.  A merge needs the facets to be
  coplanar to :data:`COPLANAR` of the body's size (float rounding of a flat CAD face), to
  face the same way, to be of the same kind (one-sided facets of an open surface or not),
  and the union to stay convex, with at most
  :data:`~sbrdf_xr.kernels.pair_table.MAX_OCCLUDER_VERTICES` corners: a vertex exactly on
  the line of its neighbours (the seed's frame, as along a straight edge of a CAD face
  cut by the triangulation) is no corner and is dropped, so a strip of facets merges.
* :func:`pair_table`: for every facet that can be shadowed, the occluders with a vertex in
  front of its plane, cut and stored in its frame with the box of the directions from
  which they can reach it (:func:`sbrdf_xr.kernels.pair_table.pair_table`).  The table
  grows as (receivers x occluders in front), so past :data:`MAX_PAIR_WORK` pairs examined
  it is not built and the exact method falls back to its direction grid.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..kernels.pair_table import MAX_OCCLUDER_VERTICES
from ..kernels.pair_table import pair_table as _pair_kernel

__all__ = ["COPLANAR", "MAX_PAIR_WORK", "occluder_polygons", "pair_table"]

#: Height off a facet's plane, as a fraction of the body's size, within which a neighbour's
#: vertex counts as in the plane for a merge (a few float64 roundings).
COPLANAR = 1e-15
#: Receivers x occluders examined at most for the pair table (about 10 ms of work and, at
#: the few per cent of pairs kept on CAD bodies, a table of a few MB).
MAX_PAIR_WORK = 4_000_000


def _turn(xy: np.ndarray, a: int, b: int, c: int) -> float:
    (ax, ay), (bx, by), (cx, cy) = xy[a], xy[b], xy[c]
    return float((bx - ax) * (cy - ay) - (by - ay) * (cx - ax))


def _corners(poly: list[int], xy: np.ndarray) -> list[int]:
    """The vertices of ``poly`` that are corners: those on the line of their neighbours
    (a turn of exactly 0 in the seed's frame, as the vertices along a straight edge of a
    CAD face are) dropped."""
    n = len(poly)
    return [v for k, v in enumerate(poly) if _turn(xy, poly[k - 1], v, poly[(k + 1) % n]) != 0.0]


def _grow(
    seed: int, frames: dict[str, Any], edges: dict[tuple[int, int], int], free: np.ndarray
) -> tuple[list[int], list[int]]:
    """Grow a convex polygon from facet ``seed`` by coplanar neighbours (marked used): its
    vertex indices and its facets."""
    V, F, N, P0 = frames["V"], frames["F"], frames["N"], frames["P0"]
    E1, E2, open_facet = frames["E1"], frames["E2"], frames["open_facet"]
    tol = COPLANAR * frames["scale"]
    rel = V - P0[seed]
    h = rel @ N[seed]
    xy = np.column_stack([rel @ E1[seed], rel @ E2[seed]])
    poly = [int(v) for v in F[seed]]
    members = [seed]
    free[seed] = False
    grown = True
    while grown and len(_corners(poly, xy)) < MAX_OCCLUDER_VERTICES:
        grown = False
        for e in range(len(poly)):
            a, b = poly[e], poly[(e + 1) % len(poly)]
            f = edges.get((b, a), -1)
            if f < 0 or not free[f] or open_facet[f] != open_facet[seed] or N[f] @ N[seed] <= 0:
                continue
            c = next(int(v) for v in F[f] if v != a and v != b)
            if c in poly or abs(h[c]) > tol:
                continue
            prev, after = poly[e - 1], poly[(e + 2) % len(poly)]
            if _turn(xy, prev, a, c) < 0.0 or _turn(xy, a, c, b) <= 0.0:
                continue
            if _turn(xy, c, b, after) < 0.0:  # (a vertex on a straight edge may stay)
                continue
            poly.insert(e + 1, c)
            free[f] = False
            members.append(int(f))
            grown = True
            break
    return _corners(poly, xy), members


def occluder_polygons(frames: dict[str, Any]) -> dict[str, np.ndarray]:
    """Convex occluder polygons of merged coplanar facets (see the module docstring).

    Parameters
    ----------
    frames : dict
        The exact method's per-facet arrays (``V``, ``F``, ``N``, ``P0``, ``E1``, ``E2``,
        ``open_facet``, ``scale``) of :func:`sbrdf_xr.body.visibility.exact_frames`.

    Returns
    -------
    dict
        ``poly`` (n, 8) vertex indices, counter-clockwise about ``normal``; ``count``
        vertices used; ``normal`` (n, 3) [1]; ``open`` flags; ``start`` and ``members``:
        CSR lists of the facets merged into each polygon.

    Examples
    --------
    A unit cube's twelve triangles merge into its six square faces:

    >>> import trimesh
    >>> from sbrdf_xr.body.occluders import occluder_polygons
    >>> from sbrdf_xr.body.visibility import exact_frames
    >>> occ = occluder_polygons(exact_frames(trimesh.creation.box(), {}))
    >>> occ["count"].tolist(), occ["start"].tolist()
    ([4, 4, 4, 4, 4, 4], [0, 2, 4, 6, 8, 10, 12])
    """
    F = frames["F"]
    ok = np.linalg.norm(frames["N"], axis=1) > 0
    edges = {
        (int(F[f, v]), int(F[f, (v + 1) % 3])): int(f) for f in np.flatnonzero(ok) for v in range(3)
    }
    free = ok.copy()
    polys, members = [], []
    for f in np.flatnonzero(ok):
        if free[f]:
            p, m = _grow(int(f), frames, edges, free)
            polys.append(p)
            members.append(m)
    seeds = [m[0] for m in members]
    poly = np.zeros((len(polys), MAX_OCCLUDER_VERTICES), dtype=np.int64)
    for g, p in enumerate(polys):
        poly[g, : len(p)] = p
    return {
        "poly": poly,
        "count": np.array([len(p) for p in polys], dtype=np.int64),
        "normal": np.ascontiguousarray(frames["N"][seeds]),
        "open": np.ascontiguousarray(frames["open_facet"][seeds]),
        "start": np.cumsum([0] + [len(m) for m in members]).astype(np.int64),
        "members": np.array([f for m in members for f in m], dtype=np.int64),
    }


def pair_table(frames: dict[str, Any], cache: dict[str, Any]) -> dict[str, Any] | None:
    """The pairs that can shadow each other (cached), or None past :data:`MAX_PAIR_WORK`.

    Parameters
    ----------
    frames : dict
        The exact method's per-facet arrays (:func:`sbrdf_xr.body.visibility.exact_frames`).
    cache : dict
        The body's cache.

    Returns
    -------
    dict or None
        ``occluders`` (:func:`occluder_polygons`) and ``table``, the arrays of
        :func:`sbrdf_xr.kernels.pair_table.pair_table`.

    Examples
    --------
    >>> from sbrdf_xr.body.occluders import pair_table
    >>> from sbrdf_xr.body.visibility import exact_frames
    >>> from sbrdf_xr.testing import l_shaped_spacecraft
    >>> body = l_shaped_spacecraft()
    >>> pairs = pair_table(exact_frames(body.mesh, body._cache), body._cache)
    >>> recv, pstart = pairs["table"][:2]
    >>> len(recv), int(pstart[-1])  # the inner floor's and wall's facets, their pairs
    (4, 16)
    """
    if "exact:pairs" in cache:
        return cache["exact:pairs"]
    occ = occluder_polygons(frames)
    work = int(frames["receiver"].sum()) * len(occ["count"])
    out = None
    if work <= MAX_PAIR_WORK:
        table = _pair_kernel(
            frames["V"],
            frames["F"],
            frames["N"],
            frames["P0"],
            frames["E1"],
            frames["E2"],
            frames["T2"],
            frames["receiver"],
            occ["poly"],
            occ["count"],
            occ["normal"],
            occ["open"],
            occ["start"],
            occ["members"],
            frames["eps"],
        )
        out = {"occluders": occ, "table": table}
    cache["exact:pairs"] = out
    return out
