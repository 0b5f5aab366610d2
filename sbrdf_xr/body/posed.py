"""Shadowing between the bus and its turned parts: the visibility methods on a posed body.

A spacecraft with articulated parts (:mod:`sbrdf_xr.body.parts`) has another surface at
every geometry: each part turned about its hinge.  :func:`posed_fraction` poses the
surface of every side (:mod:`sbrdf_xr.body.sides`) for each geometry and computes the
lit-and-visible fractions on the union, so parts shadow the bus, the bus shadows parts,
and parts shadow each other.

``"exact"``
    The compiled kernel of :func:`sbrdf_xr.body.visibility.lit_fraction`, one geometry
    at a time, on the rest frames turned by the pose (a rotation turns a facet's normal,
    in-plane frame and first vertex; its in-plane triangle is unchanged).  The facets
    that cannot be shadowed are found per pose from the convex hull of each group's
    vertices (turned with its group).
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

from typing import Any

import numpy as np
import trimesh

from ..kernels.shadow import exact_kernel
from .rays import SEED
from .sides import posed_vertices
from .spacecraft import Spacecraft
from .visibility import _fractions, _plane_frames

__all__ = ["posed_fraction"]


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


def _turn(a: np.ndarray, group: np.ndarray, rot: np.ndarray, point: Any = None) -> np.ndarray:
    """Rows of ``a`` of group k + 1 turned by ``rot[k]`` (about ``point[k]`` if given)."""
    out = a.copy()
    for k in range(rot.shape[0]):
        sel = group == k + 1
        if point is None:
            out[sel] = a[sel] @ rot[k].T
        else:
            out[sel] = point[k] + (a[sel] - point[k]) @ rot[k].T
    return out


def _exact_posed(spacecraft: Spacecraft, rot: np.ndarray, dirs: np.ndarray) -> np.ndarray:
    """Exact fractions (G, n_sides) for poses ``rot`` (G, P, 3, 3) and directions (G, K, 3)."""
    s = spacecraft.sides
    rest = _plane_frames(s.mesh, spacecraft._cache)
    parts = spacecraft.parts
    points = [p.point for p in parts]
    group = s.group
    hulls = _group_hulls(spacecraft)
    tol = rest["eps"]
    out = np.zeros((rot.shape[0], s.n_sides))
    for g in range(rot.shape[0]):
        r = rot[g]
        V = np.ascontiguousarray(posed_vertices(s, parts, r))
        N = np.ascontiguousarray(_turn(rest["N"], group, r))
        E1 = np.ascontiguousarray(_turn(rest["E1"], group, r))
        E2 = np.ascontiguousarray(_turn(rest["E2"], group, r))
        P0 = np.ascontiguousarray(_turn(rest["P0"], group, r, points))
        hull = np.concatenate(
            [hulls[0]]
            + [points[k] + (hulls[k + 1] - points[k]) @ r[k].T for k in range(len(parts))]
        )
        height = (hull @ N.T - np.einsum("ij,ij->i", N, P0)).max(axis=0)
        receiver = (np.linalg.norm(N, axis=1) > 0) & (height > tol)
        d = np.ascontiguousarray(dirs[g : g + 1])
        front = np.all(d[0] @ N.T > 0, axis=0)
        if not (receiver & front).any():
            out[g] = front
            continue
        frac = exact_kernel(
            V, rest["F"], N, P0, E1, E2, rest["T2"], receiver, d, rest["watertight"], tol
        )[0]
        if np.isnan(frac).any():  # past the kernel's budget: the posed mesh through GEOS
            mesh = trimesh.Trimesh(V, rest["F"], process=False)
            frac = _fractions(
                mesh, list(d[0][:, None, :]), "exact", 4, None, None, False, 0, False
            )[0][0]
        out[g] = np.where(front, frac, 0.0)
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
    """
    dirs = np.ascontiguousarray(np.stack(directions, axis=1), dtype=np.float64)
    rot = np.asarray(rotations, dtype=np.float64)
    if method == "exact":
        return _exact_posed(spacecraft, rot, dirs)
    s = spacecraft.sides
    out = np.zeros((rot.shape[0], s.n_sides))
    for g in range(rot.shape[0]):
        mesh = trimesh.Trimesh(
            posed_vertices(s, spacecraft.parts, rot[g]), s.mesh.faces, process=False
        )
        d = [dirs[g : g + 1, k] for k in range(dirs.shape[1])]
        out[g] = _fractions(mesh, d, method, density, engine, offset, False, seed, False)[0][0]
    return out
