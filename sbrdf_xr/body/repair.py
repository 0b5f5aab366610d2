"""Checks and repairs of a spacecraft mesh: finite, no degenerate facets, closed, outward.

:func:`sbrdf_xr.body.spacecraft.load_spacecraft` reads a mesh (:mod:`sbrdf_xr.body.meshes`) and
passes its vertices and facets to :func:`clean_mesh`, which checks that the surface can be
used (finite, no zero-area or duplicate facets, closed and consistently wound with outward
normals).

Every problem raises :class:`~sbrdf_xr.errors.MeshError` unless ``repair=True``; then the
documented repair below is applied and reported with a
:class:`~sbrdf_xr.errors.MeshRepairWarning` (never silently).  In order:

1. non-finite (NaN/inf) vertices: the vertex and every facet using it are removed;
2. (not a repair) vertices at the same position (coordinates equal after rounding to
   :data:`MERGE_DISTANCE` = 1e-8 m) are merged, since STL stores
   every facet with its own three vertices;
3. zero-area facets (area <= :data:`ZERO_AREA_FACTOR` x the squared bounding-box diagonal,
   or repeated vertices): removed;
4. duplicate facets (same three vertices, any order or winding): the first is kept;
5. open surface (edges used by one facet): holes are filled with :func:`trimesh.repair.fill_holes`;
   each new facet takes the material of the nearest original facet; an error remains if the
   surface is still open;
6. inconsistent winding: :func:`trimesh.repair.fix_winding`;
7. inside-out bodies (negative volume): their facets are flipped
   (:func:`trimesh.repair.fix_inversion`).

Self-intersections and internal faces are not detected.  Zero-thickness panels, common in
CAD exports, make a surface open: model them as thin boxes (ray-cast shadowing needs a closed
surface to tell the inside from the outside).
"""

from __future__ import annotations

import warnings

import numpy as np
import trimesh

from ..errors import MeshError, MeshRepairWarning

__all__ = ["MERGE_DISTANCE", "ZERO_AREA_FACTOR", "clean_mesh"]


#: Facets whose area is at most this factor times the squared bounding-box diagonal are
#: zero-area (about a 1e-7 relative edge length).
ZERO_AREA_FACTOR = 1.0e-14


#: Vertices whose coordinates agree after rounding to this step are one vertex [m].
MERGE_DISTANCE = 1.0e-8


def _problem(repair: bool, message: str, fix: str) -> None:
    if not repair:
        raise MeshError(f"{message}; pass repair=True to {fix}")
    warnings.warn(f"{message}: repaired ({fix})", MeshRepairWarning, stacklevel=4)


def clean_mesh(
    vertices: np.ndarray, faces: np.ndarray, material: np.ndarray, repair: bool
) -> tuple[trimesh.Trimesh, np.ndarray]:
    """Run checks/repairs 1-7 of the module docstring.

    Examples
    --------
    >>> box = trimesh.creation.box()
    >>> mesh, material = clean_mesh(
    ...     np.asarray(box.vertices), np.asarray(box.faces), np.full(12, "paint"), repair=False
    ... )
    >>> len(mesh.faces), bool(mesh.is_watertight), round(float(mesh.volume), 6)
    (12, True, 1.0)
    """
    if len(faces) == 0:
        raise MeshError("the mesh is empty: it has no facets")
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise MeshError(f"facets index vertices outside 0..{len(vertices) - 1}")
    # 1. non-finite vertices
    bad_v = ~np.isfinite(vertices).all(axis=1)
    if bad_v.any():
        bad_f = bad_v[faces].any(axis=1)
        _problem(
            repair,
            f"{int(bad_v.sum())} vertices are not finite (NaN or inf), "
            f"used by {int(bad_f.sum())} facets",
            "remove them and their facets",
        )
        vertices = np.where(bad_v[:, None], 0.0, vertices)
        faces, material = faces[~bad_f], material[~bad_f]
        if len(faces) == 0:
            raise MeshError("the mesh is empty after removing facets with non-finite vertices")
    # 2. merge coincident vertices (not a repair: STL has no shared vertices)
    mesh = trimesh.Trimesh(vertices, faces, process=False, validate=False)
    digits = round(-np.log10(MERGE_DISTANCE))
    mesh.merge_vertices(merge_tex=True, merge_norm=True, digits_vertex=digits)
    mesh.remove_unreferenced_vertices()
    faces = np.asarray(mesh.faces)
    vertices = np.asarray(mesh.vertices)
    # 3. zero-area facets
    scale = float(np.linalg.norm(np.ptp(vertices, axis=0)))
    tri = vertices[faces]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    repeated = (
        (faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (faces[:, 0] == faces[:, 2])
    )
    zero = repeated | (area <= ZERO_AREA_FACTOR * scale**2)
    if zero.any():
        _problem(
            repair,
            f"{int(zero.sum())} of {len(faces)} facets have zero area "
            f"(first: {np.flatnonzero(zero)[:5].tolist()})",
            "remove them",
        )
        faces, material = faces[~zero], material[~zero]
        if len(faces) == 0:
            raise MeshError("the mesh is empty after removing zero-area facets")
    # 4. duplicate facets
    _, first = np.unique(np.sort(faces, axis=1), axis=0, return_index=True)
    if len(first) < len(faces):
        keep = np.zeros(len(faces), bool)
        keep[first] = True
        _problem(
            repair,
            f"{len(faces) - len(first)} facets duplicate another facet "
            f"(first: {np.flatnonzero(~keep)[:5].tolist()})",
            "keep the first of each set of duplicates",
        )
        faces, material = faces[keep], material[keep]
    mesh = trimesh.Trimesh(vertices, faces, process=False, validate=False)
    # 5. open surface
    if not mesh.is_watertight:
        e = np.sort(mesh.edges_sorted, axis=1)
        _, counts = np.unique(e, axis=0, return_counts=True)
        n_open, n_fin = int(np.sum(counts == 1)), int(np.sum(counts > 2))
        if n_fin:  # no repair makes this a closed surface
            raise MeshError(
                f"the surface is not manifold: {n_fin} edges are shared by more than two "
                f"facets (and {n_open} belong to a single facet); a closed surface shares "
                "every edge between exactly two"
            )
        _problem(
            repair,
            f"the surface is not closed ({n_open} edges belong to a single facet)",
            "fill the holes with trimesh.repair.fill_holes",
        )
        n_before = len(mesh.faces)
        old_centres = mesh.triangles_center.copy()
        trimesh.repair.fill_holes(mesh)
        if not mesh.is_watertight:
            raise MeshError(
                "the surface is not closed and trimesh.repair.fill_holes could not close it"
            )
        if len(mesh.faces) > n_before:
            from scipy.spatial import cKDTree

            _, nearest = cKDTree(old_centres).query(mesh.triangles_center[n_before:])
            material = np.concatenate([material, material[nearest]])
    # 6. winding
    if not mesh.is_winding_consistent:
        _problem(
            repair,
            "the facets are not consistently wound",
            "reorient them with trimesh.repair.fix_winding",
        )
        trimesh.repair.fix_winding(mesh)
    # 7. inside-out bodies
    probe = mesh.copy()
    trimesh.repair.fix_inversion(probe, multibody=True)
    flipped = (np.asarray(probe.faces) != np.asarray(mesh.faces)).any(axis=1)
    if flipped.any():
        _problem(
            repair,
            f"{int(flipped.sum())} facets belong to inside-out bodies "
            "(negative volume, normals pointing inwards)",
            "flip them",
        )
        mesh = probe
    return trimesh.Trimesh(
        np.asarray(mesh.vertices), np.asarray(mesh.faces), process=False
    ), material
