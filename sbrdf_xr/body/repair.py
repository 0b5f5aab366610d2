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
5. edges shared by more than two facets (not manifold): an error, no repair; open
   surfaces are allowed (not a problem): a sheet, a panel, a solar array exported
   as a surface; every facet faces the side its winding gives (its front), and closed
   components are checked as solids below.  Only quantities that need a volume
   (:meth:`~sbrdf_xr.body.spacecraft.Spacecraft.inertia`) refuse an open surface;
6. inconsistent winding: :func:`trimesh.repair.fix_winding`;
7. inside-out closed components (negative volume): their facets are flipped.

Repairs are reported only once every check has passed: a mesh that cannot be used
raises :class:`~sbrdf_xr.errors.MeshError` without having warned "repaired" first.
Self-intersections and internal faces are not detected.
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


def _problem(repair: bool, message: str, fix: str, done: list[str]) -> None:
    """Raise, or note the repair in ``done`` (warned once the mesh is usable)."""
    if not repair:
        raise MeshError(f"{message}; pass repair=True to {fix}")
    done.append(f"{message}: repaired ({fix})")


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
    done: list[str] = []
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
            done,
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
            done,
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
            done,
        )
        faces, material = faces[keep], material[keep]
    mesh = trimesh.Trimesh(vertices, faces, process=False, validate=False)
    # 5. open surfaces are allowed, edges shared by more than two facets are not
    e = np.sort(mesh.edges_sorted, axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    n_fin = int(np.sum(counts > 2))
    if n_fin:
        raise MeshError(
            f"the surface is not manifold: {n_fin} edges are shared by more than two facets; "
            "a surface (closed or open) shares every edge between at most two (give a "
            "panel joined to the bus along an edge its own copy of the edge's vertices)"
        )
    # 6. winding
    if not mesh.is_winding_consistent:
        _problem(
            repair,
            "the facets are not consistently wound",
            "reorient them with trimesh.repair.fix_winding",
            done,
        )
        trimesh.repair.fix_winding(mesh)
    # 7. inside-out closed components
    flipped = _inside_out(mesh)
    if flipped.any():
        _problem(
            repair,
            f"{int(flipped.sum())} facets belong to inside-out bodies "
            "(negative volume, normals pointing inwards)",
            "flip them",
            done,
        )
        faces = np.asarray(mesh.faces).copy()
        faces[flipped] = faces[flipped][:, ::-1]
        mesh = trimesh.Trimesh(np.asarray(mesh.vertices), faces, process=False, validate=False)
    for message in done:
        warnings.warn(message, MeshRepairWarning, stacklevel=4)
    return trimesh.Trimesh(
        np.asarray(mesh.vertices), np.asarray(mesh.faces), process=False
    ), material


def _inside_out(mesh: trimesh.Trimesh) -> np.ndarray:
    """Facets of closed components whose signed volume is negative."""
    from .sides import closed_facets

    out = np.zeros(len(mesh.faces), dtype=bool)
    closed = closed_facets(mesh)
    if not closed.any():
        return out
    labels = trimesh.graph.connected_component_labels(mesh.face_adjacency, len(mesh.faces))
    tri = np.asarray(mesh.triangles)
    vol = np.einsum("fi,fi->f", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])) / 6.0
    comp_vol = np.bincount(labels, weights=vol)
    return closed & (comp_vol[labels] < 0)
