"""The sides of a spacecraft's facets that light can reach: fronts, backs and their parts.

Every facet has a front, the side its winding (right-hand rule) faces; a facet given a
back material also has a back, the same triangle wound the other way, with its own
material (a solar array: cells in front, a backsheet behind; a sheet of MLI).  The
*surface* is the mesh of all sides, fronts first then backs, each a one-sided facet
for the rest of the package (facet tables, merging, shadowing, the kernels), so a
two-sided plate is two coincident one-sided facets facing opposite ways.  On a body
with articulated parts (:mod:`sbrdf_xr.body.parts`) every group (the bus, each part)
has its own copy of its vertices, so that parts can turn without tearing the bus.

A back on a facet of a closed component (every edge shared by two of its facets)
faces the inside of a solid: it can never be lit or seen.  It is dropped with a
:class:`~sbrdf_xr.errors.HiddenSideWarning`.

Examples
--------
A 1 m x 1 m plate of two triangles with a back material:

>>> import numpy as np
>>> import trimesh
>>> plate = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
...                         [[0, 1, 2], [0, 2, 3]], process=False)
>>> s = build_sides(plate, np.array(["cell"] * 2), np.array(["sheet"] * 2),
...                 np.tile([1.0, 0, 0], (2, 1)), ())
>>> s.material.tolist(), s.back.tolist()
(['cell', 'cell', 'sheet', 'sheet'], [False, False, True, True])
>>> s.mesh.face_normals[[0, 2], 2].tolist()  # fronts face +z, backs -z
[1.0, -1.0]
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import trimesh
from numpy.typing import NDArray

from ..errors import HiddenSideWarning
from .parts import Part

__all__ = ["Sides", "build_sides", "closed_facets", "posed_vertices"]


@dataclass(frozen=True, eq=False)
class Sides:
    """The surface of all sides and, per side, its facet, face, material, tangent, group.

    ``group`` is 0 for the bus and ``k + 1`` for part ``k``; ``vertex_group`` the group
    of every vertex of :attr:`mesh`.

    Examples
    --------
    >>> from sbrdf_xr.testing import plate_spacecraft
    >>> s = plate_spacecraft().sides
    >>> s.n_sides, s.facet.tolist(), s.group.tolist()
    (4, [0, 1, 0, 1], [0, 0, 0, 0])
    """

    mesh: trimesh.Trimesh
    facet: NDArray[np.int64]
    back: NDArray[np.bool_]
    material: NDArray[np.str_]
    tangent: NDArray[np.float64]
    group: NDArray[np.int64]
    vertex_group: NDArray[np.int64]

    @property
    def n_sides(self) -> int:
        """Number of sides (facets of :attr:`mesh`)."""
        return int(self.facet.size)


def closed_facets(mesh: trimesh.Trimesh) -> NDArray[np.bool_]:
    """Facets that belong to a closed component (no edge of it used by one facet only).

    Examples
    --------
    >>> closed_facets(trimesh.creation.box()).all()
    np.True_
    """
    n = len(mesh.faces)
    labels = trimesh.graph.connected_component_labels(mesh.face_adjacency, node_count=n)
    edges = np.asarray(mesh.edges_sorted)
    _, inverse, counts = np.unique(edges, axis=0, return_inverse=True, return_counts=True)
    open_edge = counts[inverse.reshape(-1)] == 1
    open_comp = np.zeros(labels.max() + 1 if n else 0, dtype=bool)
    open_comp[labels[np.asarray(mesh.edges_face)[open_edge]]] = True
    return ~open_comp[labels]


def build_sides(
    mesh: trimesh.Trimesh,
    material: NDArray[np.str_],
    back_material: NDArray[np.str_] | None,
    tangent: NDArray[np.float64],
    parts: Sequence[Part],
) -> Sides:
    """The sides of ``mesh`` (module docstring); the mesh itself when every facet is
    one-sided and there are no parts.

    Examples
    --------
    >>> box = trimesh.creation.box()
    >>> s = build_sides(box, np.array(["paint"] * 12), None, np.zeros((12, 3)), ())
    >>> s.mesh is box, s.n_sides
    (True, 12)
    """
    n = len(mesh.faces)
    back = np.zeros(n, dtype=bool) if back_material is None else back_material != ""
    if back.any():
        hidden = back & closed_facets(mesh)
        if hidden.any():
            warnings.warn(
                f"{int(hidden.sum())} facets with a back material belong to a closed "
                f"surface (first: {np.flatnonzero(hidden)[:5].tolist()}): their backs face "
                "the inside of a solid and can never be lit or seen; they are dropped",
                HiddenSideWarning,
                stacklevel=4,
            )
            back = back & ~hidden
    group_of = np.zeros(n, dtype=np.int64)
    for k, p in enumerate(parts):
        group_of[p.facets] = k + 1
    facet = np.concatenate([np.arange(n), np.flatnonzero(back)])
    is_back = np.concatenate([np.zeros(n, bool), np.ones(int(back.sum()), bool)])
    mats = np.asarray(material, dtype=str)
    backs = np.asarray(back_material if back_material is not None else mats, dtype=str)
    side_mat = mats if not back.any() else np.concatenate([mats, backs[back]])
    if not back.any() and not parts:
        return Sides(
            mesh, facet, is_back, side_mat, tangent, group_of, np.zeros(len(mesh.vertices), int)
        )
    faces = np.asarray(mesh.faces)
    side_faces = np.concatenate([faces, faces[back][:, ::-1]])
    side_group = group_of[facet]
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    verts, new_faces, vgroup = [], np.empty_like(side_faces), []
    offset = 0
    for g in np.unique(side_group):  # each group its own copy of the vertices it uses
        sel = side_group == g
        used, local = np.unique(side_faces[sel], return_inverse=True)
        new_faces[sel] = local.reshape(-1, 3) + offset
        verts.append(vertices[used])
        vgroup.append(np.full(used.size, g))
        offset += used.size
    surface = trimesh.Trimesh(np.concatenate(verts), new_faces, process=False)
    return Sides(
        surface,
        facet,
        is_back,
        side_mat,
        np.asarray(tangent)[facet],
        side_group,
        np.concatenate(vgroup),
    )


def posed_vertices(
    sides: Sides, parts: Sequence[Part], rotations: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Vertices of the surface with part ``k`` turned by ``rotations[k]`` (3, 3) about its
    hinge: ``p + R (x - p)`` [m].

    Examples
    --------
    >>> from sbrdf_xr.body.parts import Part, hinge_rotation
    >>> plate = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [1, 1, 0]], [[0, 1, 2]], process=False)
    >>> part = Part("p", [0], axis=[1, 0, 0])
    >>> s = build_sides(plate, np.array(["a"]), None, np.zeros((1, 3)), (part,))
    >>> posed_vertices(s, (part,), hinge_rotation([1, 0, 0], [np.pi / 2])).round(12) + 0.0
    array([[0., 0., 0.],
           [1., 0., 0.],
           [1., 0., 1.]])
    """
    v = np.array(sides.mesh.vertices, dtype=np.float64)
    for k, p in enumerate(parts):
        sel = sides.vertex_group == k + 1
        v[sel] = p.point + (v[sel] - p.point) @ rotations[k].T
    return v
