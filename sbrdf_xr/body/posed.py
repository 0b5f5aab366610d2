"""Shadowing between the bus and its turned parts: the visibility methods on a posed body.

A spacecraft with articulated parts (:mod:`sbrdf_xr.body.parts`) has another surface at
every geometry: each part turned about its hinge.  :func:`posed_fraction` poses the
surface of every side (:mod:`sbrdf_xr.body.sides`) for each geometry and computes the
lit-and-visible fractions on the union, so parts shadow the bus, the bus shadows parts,
and parts shadow each other.

``"exact"``
    The pair-table kernel of :func:`sbrdf_xr.body.visibility.lit_fraction`, one geometry
    at a time, on the rest frames turned by the pose (a rotation turns a facet's normal,
    in-plane frame and first vertex; its in-plane triangle is unchanged).  The pairs
    within a rigid group (the bus, each part) keep their coordinates in the receiver's
    frame, their slope boxes and thresholds when the group turns, so they are found once
    per body (:func:`sbrdf_xr.kernels.pair_table.grouped_pair_table`); the pairs between
    groups are found per pose and merged in (:func:`~sbrdf_xr.kernels.pair_table.
    merged_tables`).  Past :data:`~sbrdf_xr.body.occluders.MAX_PAIR_WORK` the grid kernel
    runs instead.  Geometries where no facet can be shadowed are found per pose from the
    convex hull of each group's vertices (turned with its group).
``"sampled"``
    The sampled method on the posed mesh, one geometry at a time (a new ray-engine scene
    per geometry: slow on long sweeps).

Examples
--------
The box with a plate 1 m above it (:func:`sbrdf_xr.testing.box_with_plate_spacecraft`):
turned edge-on (90 deg about x), the plate no longer shades the top, which is then all lit
from straight above:

>>> import numpy as np
>>> from sbrdf_xr.body.parts import hinge_rotation
>>> from sbrdf_xr.testing import box_with_plate_spacecraft
>>> body = box_with_plate_spacecraft(parts=True)
>>> d = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
>>> rot = np.stack([hinge_rotation([1, 0, 0], [0.0])[0], hinge_rotation([1, 0, 0], [np.pi / 2])[0]])
>>> f = posed_fraction(body, rot[:, None], [d, d])
>>> top = [4, 6]  # the two facets of the cube's +z face
>>> f[:, top].round(12).tolist()
[[0.0, 0.0], [1.0, 1.0]]
"""

from __future__ import annotations

import numpy as np
import trimesh

from ..kernels.pair_table import grouped_pair_table, posed_pairs_kernel
from ..kernels.shadow import exact_kernel
from .occluders import MAX_PAIR_WORK, occluder_polygons
from .rays import SEED
from .sides import posed_vertices
from .spacecraft import Spacecraft
from .visibility import _fractions, _plane_frames

__all__ = ["posed_fraction"]

#: Geometries posed at once by the exact method (bounds its temporary arrays).
_CHUNK = 64


def _group_hulls(spacecraft: Spacecraft) -> list[np.ndarray]:
    """Vertices of the convex hull of every group (the bus, each part), cached."""
    cache = spacecraft._cache
    if "posed:hulls" not in cache:
        s = spacecraft.sides
        hulls = []
        for g in range(len(spacecraft.parts) + 1):
            pts = np.asarray(s.mesh.vertices)[s.vertex_group == g]
            if len(pts) > 16:  # small groups keep their vertices
                try:
                    with np.errstate(all="ignore"):
                        pts = np.asarray(trimesh.convex.convex_hull(pts).vertices)
                except Exception:  # flat or degenerate groups: their own vertices
                    pass
            hulls.append(pts)
        cache["posed:hulls"] = hulls
    return cache["posed:hulls"]


def _posed_pairs(spacecraft: Spacecraft) -> dict | None:
    """The occluder polygons and the pairs within each rigid group (cached), or None past
    :data:`~sbrdf_xr.body.occluders.MAX_PAIR_WORK`."""
    cache = spacecraft._cache
    if "posed:pairs" not in cache:
        s = spacecraft.sides
        rest = _plane_frames(s.mesh, cache)
        occ = occluder_polygons(rest)
        ok = np.linalg.norm(rest["N"], axis=1) > 0
        out = None
        if int(ok.sum()) * len(occ["count"]) <= MAX_PAIR_WORK:
            seeds = occ["members"][occ["start"][:-1]]
            groups = (seeds, s.group, s.group[seeds])
            occluders = (ok, occ["poly"], occ["count"], occ["open"], occ["start"], occ["members"])
            V, F, N, P0, E1, E2, T2 = (rest[k] for k in ("V", "F", "N", "P0", "E1", "E2", "T2"))
            poly, count, gopen, start, members = occluders[1:]
            within = grouped_pair_table(
                V, F, N, P0, E1, E2, T2, ok, poly, count, occ["normal"], gopen, start, members,
                rest["eps"], s.group, s.group[seeds], True,
            )  # fmt: skip
            out = {"occluders": (*occluders, *groups), "within": within}
        cache["posed:pairs"] = out
    return cache["posed:pairs"]


def _exact_posed(
    spacecraft: Spacecraft, rot: np.ndarray, dirs: np.ndarray, tabled: bool = True
) -> np.ndarray:
    """Exact fractions (G, n_sides) for poses ``rot`` (G, P, 3, 3) and directions (G, K, 3),
    by the pair table (``tabled``, unless past its work bound) or the grid kernel.

    The bus rows of the frames stay as they are; only the rows of the parts are turned at
    each geometry, in place in buffers the kernel reads (their cost grows with the parts,
    not the bus).  A bus facet cannot be shadowed if the bus's hull and every part's
    (turned) hull lie on or behind its plane.
    """
    s = spacecraft.sides
    rest = _plane_frames(s.mesh, spacecraft._cache)
    parts = spacecraft.parts
    hulls = _group_hulls(spacecraft)
    tol = rest["eps"]
    G = rot.shape[0]
    V, N, E1, E2, P0 = (rest[k].copy() for k in ("V", "N", "E1", "E2", "P0"))
    part = s.group > 0
    rows = np.flatnonzero(part)
    vrows = np.flatnonzero(s.vertex_group > 0)
    k_row = s.group[rows] - 1
    k_vert = s.vertex_group[vrows] - 1
    point = np.array([p.point for p in parts])

    # every geometry's part rows at once: x -> p + R (x - p), n -> R n
    def turned(a: np.ndarray, k: np.ndarray, about: bool) -> np.ndarray:
        r = rot[:, k]  # (G, n, 3, 3)
        if not about:
            return np.einsum("gnij,nj->gni", r, a)
        return point[k] + np.einsum("gnij,nj->gni", r, a - point[k])

    pV = turned(rest["V"][vrows], k_vert, True)
    pN = turned(rest["N"][rows], k_row, False)
    pE1 = turned(rest["E1"][rows], k_row, False)
    pE2 = turned(rest["E2"][rows], k_row, False)
    pP0 = turned(rest["P0"][rows], k_row, True)
    # receivers: a facet none of whose hull points (bus and turned parts) is in front
    moved = np.concatenate(
        [
            p.point + np.einsum("gij,nj->gni", rot[:, k], hulls[k + 1] - p.point)
            for k, p in enumerate(parts)
        ],
        axis=1,
    )  # (G, m, 3)
    off_bus = np.einsum("ij,ij->i", N, P0)
    height = np.broadcast_to((hulls[0] @ N.T - off_bus).max(axis=0), (G, len(N))).copy()
    height[:, rows] = (
        np.einsum("mj,gnj->gnm", hulls[0], pN) - np.einsum("gnj,gnj->gn", pN, pP0)[:, :, None]
    ).max(axis=2)
    off = np.broadcast_to(off_bus, (G, len(N))).copy()
    off[:, rows] = np.einsum("gnj,gnj->gn", pN, pP0)
    allN = np.broadcast_to(N, (G, len(N), 3)).copy()
    allN[:, rows] = pN
    height = np.maximum(height, np.einsum("gmj,gnj->gnm", moved, allN).max(axis=2) - off)
    receiver = (np.linalg.norm(N, axis=1) > 0) & (height > tol)  # (G, n)
    front = np.all(np.einsum("gkj,gnj->gkn", dirs, allN) > 0, axis=1)  # (G, n)
    active = (receiver & front).any(axis=1)
    out = front.astype(np.float64)  # nothing can be shadowed where no receiver faces
    todo = np.flatnonzero(active)
    pairs = _posed_pairs(spacecraft) if tabled else None
    if pairs is not None:  # every pose in one compiled call
        frames = (V.copy(), rest["F"], N.copy(), P0.copy(), E1.copy(), E2.copy(), rest["T2"])
        posed = (pV, pN, pE1, pE2, pP0, vrows, rows)
        frac = posed_pairs_kernel(
            frames, posed, pairs["occluders"], pairs["within"], active, tol, dirs
        )
        out[active] = np.where(front, frac, 0.0)[active]
        todo = np.flatnonzero(active & np.isnan(frac).any(axis=1))  # past the buffers
    for g in todo:
        V[vrows], N[rows], E1[rows], E2[rows], P0[rows] = pV[g], pN[g], pE1[g], pE2[g], pP0[g]
        d = np.ascontiguousarray(dirs[g : g + 1])
        frac = np.full(s.n_sides, np.nan)
        if pairs is None:
            frac = exact_kernel(
                V, rest["F"], N, P0, E1, E2, rest["T2"], receiver[g], d, rest["open_facet"], tol
            )[0]
        if np.isnan(frac).any():  # past the kernel's budget: the posed mesh through GEOS
            mesh = trimesh.Trimesh(V.copy(), rest["F"], process=False)
            frac = _fractions(
                mesh, list(d[0][:, None, :]), "exact", 4, None, None, False, 0, False
            )[0][0]
        out[g] = np.where(front[g], frac, 0.0)
    return out


def posed_fraction(
    spacecraft: Spacecraft,
    rotations: np.ndarray,
    directions: list[np.ndarray],
    *,
    method: str = "exact",
    density: int | str = 4,
    engine: str | None = None,
    offset: float | None = None,
    seed: int = SEED,
) -> np.ndarray:
    """Fraction of every side unobstructed along all ``directions`` on the posed body.

    Parameters
    ----------
    spacecraft : Spacecraft
        With parts.
    rotations : ndarray, shape (G, n_parts, 3, 3)
        The rotation of every part at every geometry (bus frame).
    directions : list of ndarray, shape (G, 3)
        Unit directions in the bus frame (the Sun, then the observer).
    method, density, engine, offset, seed
        As in :func:`sbrdf_xr.body.visibility.lit_fraction`.

    Returns
    -------
    ndarray, shape (G, n_sides)
        Fractions in ``[0, 1]`` [1].

    Examples
    --------
    The plate above the box, turned edge-on, shades nothing; flat, it shades the whole top:

    >>> from sbrdf_xr.body.parts import hinge_rotation
    >>> from sbrdf_xr.testing import box_with_plate_spacecraft
    >>> body = box_with_plate_spacecraft(parts=True)
    >>> up = np.array([[0.0, 0.0, 1.0]] * 2)
    >>> rot = hinge_rotation([1, 0, 0], [0.0, np.pi / 2])[:, None]
    >>> posed_fraction(body, rot, [up, up])[:, [4, 6]].round(12).tolist()
    [[0.0, 0.0], [1.0, 1.0]]
    """
    dirs = np.ascontiguousarray(np.stack(directions, axis=1), dtype=np.float64)
    rot = np.asarray(rotations, dtype=np.float64)
    if method == "exact":  # in chunks of geometries: the receivers' arrays grow with them
        parts = [
            _exact_posed(spacecraft, rot[g : g + _CHUNK], dirs[g : g + _CHUNK])
            for g in range(0, rot.shape[0], _CHUNK)
        ]
        return np.concatenate(parts) if parts else np.zeros((0, spacecraft.n_sides))
    s = spacecraft.sides
    out = np.zeros((rot.shape[0], s.n_sides))
    for g in range(rot.shape[0]):
        mesh = trimesh.Trimesh(
            posed_vertices(s, spacecraft.parts, rot[g]), s.mesh.faces, process=False
        )
        d = [dirs[g : g + 1, k] for k in range(dirs.shape[1])]
        out[g] = _fractions(mesh, d, method, density, engine, offset, False, seed, False)[0][0]
    return out
