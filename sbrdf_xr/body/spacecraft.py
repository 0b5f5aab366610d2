"""Spacecraft: a triangulated surface in metres whose every facet carries a material name.

Paper 000 §3.3 represents a spacecraft by a triangular-faceted CAD model (STL) in which the
colour of a facet selects its material (Table 2: vertices ``V``, facets ``F``, normals ``N``,
colours ``C``).  This module reads such models from any format :mod:`trimesh` reads, maps
facet colours or material/group names to material names, checks that the surface can be used
(:mod:`sbrdf_xr.body.repair`) and converts the length unit to metres.  It also builds the
facet table used by the simulation, merges facets that share (normal, material), and ships
the CanX-1-like model of paper 000 §4 (:func:`canx1`).

Facet labels, by format
-----------------------
========  ==================================================================================
STL       binary STL, per-facet colour in the 16-bit attribute word, VisCAM/SolidView
          convention: bit 15 set = colour valid, bits 10-14 red, 5-9 green, 0-4 blue (5 bit
          per channel; map colours are compared after quantisation to 5 bit).
OBJ       ``usemtl`` material names (and the ``Kd`` colour of the material).
PLY       face colours (``red``, ``green``, ``blue`` face properties), or any other face
          property named by ``face_property=`` (e.g. an integer ``material_id``).
glTF/GLB  material names and base colours of the primitives; also node and mesh names.
========  ==================================================================================

Checks and repairs
------------------
Every problem of the surface (non-finite vertices, zero-area or duplicate facets, an open
surface, inconsistent winding, inside-out bodies) raises :class:`~sbrdf_xr.errors.MeshError`
unless ``repair=True``; then the documented repair is applied and reported with a
:class:`MeshRepairWarning` (never silently).  The checks, their order, repairs and
tolerances are listed in :mod:`sbrdf_xr.body.repair`.  Self-intersections and internal
faces are not detected.  A surface may be open (a panel, a sheet): every facet has a front
and, where ``back_material`` says so, a back (:mod:`sbrdf_xr.body.sides`); parts that turn
about a hinge are :mod:`sbrdf_xr.body.parts`.

The facet tables are built by :mod:`sbrdf_xr.body.facets` and the picture by
:mod:`sbrdf_xr.body.picture`.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import trimesh
import xarray as xr
from numpy.typing import NDArray

from .. import _catalog_index
from ..errors import (
    CatalogError,
    MeshError,
    MeshRepairWarning,
    UnitWarning,
    ValidationError,
    input_file,
)
from ..geometry.anisotropy import DEFAULT_TANGENT_DIRECTION, project_tangents
from ..units import check_plausible, to_unit
from .facets import NORMAL_TOLERANCE, check_facet_material, facet_table, merge_facets
from .meshes import (
    LENGTH_UNITS,
    Color,
    label_faces,
    length_factor,
    normalise_map,
    read_material_map,
    read_mesh,
)
from .parts import Part, check_parts
from .picture import plot_facets
from .repair import clean_mesh
from .sides import Sides, build_sides

__all__ = [
    "CANX1_MATERIALS",
    "LENGTH_UNITS",
    "NORMAL_TOLERANCE",
    "MeshRepairWarning",
    "Spacecraft",
    "canx1",
    "length_factor",
    "load_spacecraft",
    "read_material_map",
]


#: Material names of the built-in CanX-1-like model and their facet colours (paper 000 Fig. 11).
CANX1_MATERIALS: dict[str, tuple[int, int, int]] = {
    "aluminium-6061-t6": (255, 0, 0),
    "tjpv-cell": (0, 0, 255),
    "white-paint-a276": (255, 255, 255),
}


# --------------------------------------------------------------------------- public API


def _tangent_directions(tangent: Any, n_facets: int) -> NDArray[np.float64]:
    """Tangent direction(s) [1], shape (3,) or (n_facets, 3); ValidationError otherwise."""
    d = np.asarray(tangent, dtype=np.float64)
    if d.shape not in ((3,), (n_facets, 3)):
        raise ValidationError(
            f"tangent: expected one direction (3,) or one per facet ({n_facets}, 3), "
            f"got shape {d.shape}"
        )
    return d


def load_spacecraft(
    path_or_mesh: str | Path | trimesh.Trimesh | trimesh.Scene,
    material_map: Mapping[Any, str] | str | Path | None = None,
    *,
    material: str | None = None,
    length_unit: Any = None,
    repair: bool = False,
    name: str | None = None,
    known_materials: Iterable[str] | None = None,
    face_property: str | None = None,
    file_type: str | None = None,
    tangent: Any = None,
    back_material: str | Mapping[str, str] | None = None,
) -> Spacecraft:
    """Load a triangulated spacecraft model and label every facet with a material.

    Parameters
    ----------
    path_or_mesh : str, Path, trimesh.Trimesh or trimesh.Scene
        A mesh file in any format trimesh reads (binary STL with facet colours, OBJ with
        ``usemtl`` groups, PLY with face colours or a face property, glTF/GLB with
        materials, ...) or an already loaded trimesh object.
    material_map : mapping or str or Path
        Facet label -> material name.  Keys are colours (``(r, g, b)`` integers 0-255 or
        ``"#rrggbb"``) or names (material, group, node or mesh names, or values of
        ``face_property``); a path reads a TOML map (:func:`read_material_map`).  Names are
        tried first, then colours.
    material : str, optional
        Instead of ``material_map``: the one material of every facet (a one-material
        body; the mesh needs no colours or labels).
    length_unit : str, astropy unit or Quantity, optional
        Length unit of the file's coordinates (see :data:`LENGTH_UNITS`, or an astropy
        length unit); converted to metres.  CAD exports are often in ``"mm"``.  Default:
        the unit the file states (glTF: metres; 3MF and others that record one), else
        metres.  A unit that contradicts the file's statement warns
        (:class:`~sbrdf_xr.errors.UnitWarning`), as does a body whose largest side is
        outside 1 mm - 1 km (:data:`sbrdf_xr.units.PLAUSIBLE`).
    repair : bool
        Repair the problems listed in :mod:`sbrdf_xr.body.repair` (with a
        :class:`MeshRepairWarning` for each) instead of raising :class:`MeshError`.
    name : str, optional
        Name of the spacecraft (default: the file stem, the mesh's name or ``"spacecraft"``).
    known_materials : iterable of str, optional
        Materials that exist; a map naming any other material is an error.
    face_property : str, optional
        Name of a per-face property (PLY) or face attribute holding the facet labels.
    file_type : str, optional
        Format of a file without a telling extension (``"stl"``, ``"ply"``, ...).
    tangent : array_like, shape (3,) or (n_facets, 3), optional
        Facet tangents for anisotropic materials (:mod:`sbrdf_xr.geometry.anisotropy`): a
        body-frame direction [1] projected onto every facet, or one direction per
        facet of the mesh as read.  Without it, the mesh's per-face ``tangent``
        attribute if it has one (:func:`sbrdf_xr.body.meshes.face_tangents`; faces
        without a valid one take the default), else the default direction
        (:data:`sbrdf_xr.geometry.anisotropy.DEFAULT_TANGENT_DIRECTION`).  Directions parallel
        to a facet's normal take the documented fallback of
        :func:`sbrdf_xr.geometry.anisotropy.project_tangents`.  Isotropic materials ignore
        tangents.
    back_material : str or mapping of str to str, optional
        Backs of the facets (an open surface: a panel, a sheet): one material for the
        back of every facet, or front material -> back material (facets of other
        materials stay one-sided).  See :mod:`sbrdf_xr.body.sides`.

    Returns
    -------
    Spacecraft
        The labelled, checked model in metres.

    Raises
    ------
    MeshError
        If the source is not a triangle mesh, is empty, has unmapped facets, or has one of
        the problems of :mod:`sbrdf_xr.body.repair` while ``repair`` is False.
    ValidationError
        If the length unit or the map is invalid, or the map names an unknown material.
    MeshError
        If ``path_or_mesh`` is a path that is not a readable file (missing, a directory, a
        FIFO, a device, empty) or not a usable mesh; the message names the file.

    Examples
    --------
    >>> sc = load_spacecraft(trimesh.creation.box(extents=(100, 100, 100)), material="paint",
    ...                      length_unit="mm", name="cube")
    >>> sc
    <Spacecraft 'cube': 12 facets, materials ['paint'], extent [0.1, 0.1, 0.1] m>
    >>> round(float(sc.mesh.area), 6)
    0.06
    """
    factor = None if length_unit is None else length_factor(length_unit)
    if (material_map is None) == (material is None):
        raise ValidationError(
            "load_spacecraft: give exactly one of material_map (facet label -> material) and "
            f"material (one material for every facet); got material_map={material_map!r}, "
            f"material={material!r}"
        )
    colours: dict[Color, str] = {}
    name_map: dict[str, str] = {}
    if material is not None:
        if not isinstance(material, str) or not material.strip():
            raise ValidationError(f"material: expected a non-empty material name, got {material!r}")
        if known_materials is not None and material not in set(known_materials):
            raise ValidationError(
                f"material: {material!r} does not exist; "
                f"known materials: {sorted(set(known_materials))}"
            )
    elif material_map is not None:
        colours, name_map = normalise_map(material_map, known_materials)
    opts = (face_property, file_type, material, colours, name_map, name, length_unit, factor)
    if not isinstance(path_or_mesh, str | Path):
        return _with_backs(_load(path_or_mesh, *opts, tangent, repair), back_material)
    path = input_file(path_or_mesh, "mesh file", MeshError)
    try:
        return _with_backs(_load(path, *opts, tangent, repair), back_material)
    except MeshError as exc:  # say which file
        if str(path) in str(exc):
            raise
        raise MeshError(f"mesh file {path}: {exc}") from None


def _load(
    path_or_mesh: Any,
    face_property: str | None,
    file_type: str | None,
    material: str | None,
    colours: dict[Color, str],
    name_map: dict[str, str],
    name: str | None,
    length_unit: Any,
    factor: float | None,
    tangent: Any,
    repair: bool,
) -> Spacecraft:
    labelled, default_name = read_mesh(path_or_mesh, face_property, file_type)
    vertices, faces, rgb, names = labelled.arrays()
    if len(faces) == 0:
        raise MeshError("the mesh is empty: it has no facets")
    facet_material = (
        np.full(len(faces), material, dtype=object)
        if material is not None
        else label_faces(labelled, rgb, names, colours, name_map)
    )
    factor = _unit_factor(factor, length_unit, labelled.units)
    with np.errstate(invalid="ignore", over="ignore"):
        vertices = vertices * factor
    finite = vertices[np.isfinite(vertices).all(axis=1)]
    if len(finite):
        side = float(np.max(np.ptp(finite, axis=0)))
        check_plausible(
            side,
            "mesh_size_m",
            f"mesh {name or default_name or 'spacecraft'}: largest side",
            fix="give the file's unit as length_unit (e.g. length_unit='mm')",
        )
    source = "default"
    if tangent is not None:
        direction = _tangent_directions(tangent, len(faces))
        source = "per facet" if direction.ndim == 2 else "direction"
        direction = np.broadcast_to(direction, (len(faces), 3))
    else:
        direction = labelled.tangent
        have = np.isfinite(direction).all(axis=1) & (np.linalg.norm(direction, axis=1) > 0)
        direction = np.where(have[:, None], direction, np.asarray(DEFAULT_TANGENT_DIRECTION))
        if have.any():
            source = "mesh attribute"
    # clean_mesh drops and adds facets: follow every facet's origin through it
    mesh, origin = clean_mesh(vertices, faces, np.arange(len(faces)), repair)
    origin = np.asarray(origin, dtype=np.int64)
    palette = {m: c for c, m in colours.items()}
    return Spacecraft(
        mesh,
        facet_material[origin],
        name=name or default_name or "spacecraft",
        colors=palette,
        tangent=direction[origin],
        tangent_source=source,
    )


def _with_backs(sc: Spacecraft, back_material: str | Mapping[str, str] | None) -> Spacecraft:
    """``sc`` with the backs ``back_material`` asks for (see :func:`load_spacecraft`)."""
    if back_material is None:
        return sc
    if isinstance(back_material, Mapping):
        unknown = sorted(set(back_material) - set(sc.materials))
        if unknown:
            raise ValidationError(
                f"back_material: front materials {unknown} are on no facet; the facets "
                f"have {sc.materials}"
            )
        back = [back_material.get(m, "") for m in sc.facet_material.tolist()]
    elif isinstance(back_material, str) and back_material.strip():
        back = [back_material] * sc.n_facets
    else:
        raise ValidationError(
            "back_material: expected a material name or a mapping front material -> back "
            f"material, got {back_material!r}"
        )
    return Spacecraft(
        sc.mesh,
        sc.facet_material,
        name=sc.name,
        colors=sc.colors,
        tangent=sc.facet_tangent,
        tangent_source=sc.tangent_source,
        back_material=back,
    )


def _unit_factor(factor: float | None, length_unit: Any, stated: str | None) -> float:
    """Metres per file unit: the one given, else the one the file states, else 1; a given
    unit that contradicts the file's statement warns."""
    try:
        from_file = None if stated is None else length_factor(stated)
    except ValidationError:  # a statement the table does not know: not used
        from_file = None
    if factor is None:
        return 1.0 if from_file is None else from_file
    if from_file is not None and not np.isclose(factor, from_file, rtol=1e-9):
        warnings.warn(
            f"length_unit={length_unit!r} reads the coordinates in {factor:g} m units, but "
            f"the file states they are in {stated!r} ({from_file:g} m): the body comes out "
            f"{factor / from_file:g} times the size the file means; leave length_unit out "
            "to follow the file",
            UnitWarning,
            stacklevel=3,
        )
    return factor


class Spacecraft:
    """A triangulated surface in metres with a material name on every facet: a bus and
    optionally named parts that turn about hinges.

    Composition, not a trimesh subclass: :attr:`mesh` is the geometry and
    :attr:`facet_material` the labels.  Build it with :func:`load_spacecraft` (which checks
    the mesh) or :func:`canx1`.  The surface may be open; facets are one-sided unless
    ``back_material`` gives a back (:mod:`sbrdf_xr.body.sides`).

    Parameters
    ----------
    mesh : trimesh.Trimesh
        Geometry in metres, normals pointing outwards.
    facet_material : array_like of str, shape (n_facets,)
        Material name of every facet.
    name : str
        Name of the spacecraft.
    colors : mapping of str to (r, g, b), optional
        Display colour of each material (0-255), used by :meth:`plot`.
    tangent : array_like, shape (3,) or (n_facets, 3), optional
        Tangent direction(s) [1] for anisotropic materials, projected onto every facet
        (:func:`sbrdf_xr.geometry.anisotropy.project_tangents`, with its fallback for
        directions along the normal); default
        :data:`sbrdf_xr.geometry.anisotropy.DEFAULT_TANGENT_DIRECTION`.  Kept as
        :attr:`facet_tangent`, unit vectors orthogonal to the facet normals.
    tangent_source : str, optional
        Where the tangents come from (``"default"``, ``"direction"``, ``"per facet"``,
        ``"mesh attribute"``), for display; inferred when omitted.
    back_material : str or array_like of str, shape (n_facets,), optional
        Material of the back of every facet (``""``: no back, one-sided), or one name for
        every facet.  Backs on a closed surface are dropped with a
        :class:`~sbrdf_xr.errors.HiddenSideWarning`.
    parts : sequence of Part, optional
        Articulated parts (:class:`sbrdf_xr.body.parts.Part`): facets turning about a hinge
        with a pointing law; the other facets are the bus.

    Examples
    --------
    >>> sc = Spacecraft(trimesh.creation.box(), ["paint"] * 6 + ["cell"] * 6, name="cube")
    >>> sc.n_facets, sc.materials, sc.is_convex
    (12, ['cell', 'paint'], True)
    >>> facets = sc.facets()
    >>> dict(facets.sizes), round(float(facets.area.sum()), 6)
    ({'facet': 12, 'xyz': 3}, 6.0)
    >>> sc.merged().sizes["term"]  # facets sharing a normal and a material
    8
    >>> np.round(np.diag(sc.inertia(density=1000.0)), 3)  # a 1000 kg cube of side 1 m [kg m2]
    array([166.667, 166.667, 166.667])
    """

    def __init__(
        self,
        mesh: trimesh.Trimesh,
        facet_material: Iterable[str],
        *,
        name: str = "spacecraft",
        colors: Mapping[str, Color] | None = None,
        tangent: Any = None,
        tangent_source: str | None = None,
        back_material: Any = None,
        parts: Iterable[Part] | None = None,
    ) -> None:
        if not isinstance(mesh, trimesh.Trimesh):
            raise ValidationError(f"mesh: expected a trimesh.Trimesh, got {type(mesh).__name__}")
        labels = check_facet_material(facet_material, len(mesh.faces))
        labels.setflags(write=False)
        self.mesh = mesh
        self.facet_material: NDArray[np.str_] = labels
        self.name = str(name)
        self.colors: dict[str, Color] = dict(colors or {})
        self._cache: dict[str, Any] = {}
        d = None if tangent is None else _tangent_directions(tangent, len(mesh.faces))
        t = project_tangents(np.asarray(mesh.face_normals, dtype=np.float64), d)
        t.setflags(write=False)
        #: Unit tangent of every facet, orthogonal to its normal [1], shape (n_facets, 3).
        self.facet_tangent: NDArray[np.float64] = t
        self.tangent_source = tangent_source or (
            "default" if d is None else "direction" if d.ndim == 1 else "per facet"
        )
        back = None
        if back_material is not None:
            if isinstance(back_material, str):
                back_material = [back_material] * len(mesh.faces)
            back = np.array(
                ["" if b is None else str(b) for b in back_material], dtype=object
            ).astype(str)
            if back.shape != (len(mesh.faces),):
                raise ValidationError(
                    f"back_material: expected one name per facet ({len(mesh.faces)}) or one "
                    f"name, got {back.shape[0]}"
                )
        #: Back material of every facet, ``""`` where it has none (one-sided), or None.
        self.facet_back: NDArray[np.str_] | None = back if back is not None and back.any() else None
        normals = np.asarray(mesh.face_normals, dtype=np.float64)
        #: The articulated parts (:mod:`sbrdf_xr.body.parts`), with their normals at angle 0.
        self.parts: tuple[Part, ...] = check_parts(
            parts, len(mesh.faces), normals, np.asarray(mesh.area_faces)
        )
        #: The sides light can reach (:mod:`sbrdf_xr.body.sides`).
        self.sides: Sides = build_sides(
            mesh, labels, self.facet_back, self.facet_tangent, self.parts
        )
        if self.facet_back is not None:  # the backs kept (those on closed surfaces are not)
            kept = np.full(len(mesh.faces), "", dtype=object)
            kept[self.sides.facet[self.sides.back]] = self.sides.material[self.sides.back]
            self.facet_back = kept.astype(str) if self.sides.back.any() else None

    @property
    def moving_parts(self) -> tuple[Part, ...]:
        """The parts whose angle changes with the geometry (not :class:`Fixed`).

        Examples
        --------
        >>> Spacecraft(trimesh.creation.box(), ["paint"] * 12).moving_parts
        ()
        """
        return tuple(p for p in self.parts if p.moving)

    @property
    def n_sides(self) -> int:
        """Number of one-sided facets light can reach: every front plus every back.

        Examples
        --------
        >>> Spacecraft(trimesh.creation.box(), ["paint"] * 12).n_sides
        12
        """
        return self.sides.n_sides

    def with_tangent(self, tangent: Any) -> Spacecraft:
        """The same spacecraft with other facet tangents (see the class parameters).

        Parameters
        ----------
        tangent : array_like, shape (3,) or (n_facets, 3)
            Body-frame direction [1], or one per facet.

        Returns
        -------
        Spacecraft
            Sharing the mesh and materials of this one.

        Examples
        --------
        >>> import trimesh
        >>> box = Spacecraft(trimesh.creation.box(), ["paint"] * 12)
        >>> box.mesh.face_normals[:2].tolist()
        [[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]]
        >>> box.facet_tangent[:2].tolist()  # the default x, or y on the x faces
        [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]
        >>> box.with_tangent((0, 0, 1)).facet_tangent[:2].tolist()
        [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]
        """
        return Spacecraft(
            self.mesh,
            self.facet_material,
            name=self.name,
            colors=self.colors,
            tangent=tangent,
            back_material=self.facet_back,
            parts=self.parts,
        )

    def with_parts(self, parts: Iterable[Part]) -> Spacecraft:
        """The same spacecraft with these articulated parts (:mod:`sbrdf_xr.body.parts`).

        Parameters
        ----------
        parts : iterable of Part
            Facets of the mesh turning about hinges; the other facets are the bus.

        Returns
        -------
        Spacecraft

        Examples
        --------
        >>> from sbrdf_xr.body.parts import Part, SunTracking
        >>> box = Spacecraft(trimesh.creation.box(), ["paint"] * 12)
        >>> lid = Part("lid", [4, 6], law=SunTracking(normal=(1, 0, 0)))
        >>> box.with_parts([lid]).moving_parts[0].name
        'lid'
        """
        return Spacecraft(
            self.mesh,
            self.facet_material,
            name=self.name,
            colors=self.colors,
            tangent=self.facet_tangent,
            tangent_source=self.tangent_source,
            back_material=self.facet_back,
            parts=parts,
        )

    def __repr__(self) -> str:
        return (
            f"<Spacecraft {self.name!r}: {self.n_facets} facets, materials {self.materials}, "
            f"extent {np.round(self.mesh.extents, 6).tolist()} m>"
        )

    @property
    def n_facets(self) -> int:
        """Number of facets.

        Examples
        --------
        >>> Spacecraft(trimesh.creation.box(), ["paint"] * 12).n_facets
        12
        """
        return len(self.mesh.faces)

    @property
    def materials(self) -> list[str]:
        """Sorted unique material names.

        Examples
        --------
        >>> Spacecraft(trimesh.creation.box(), ["paint"] * 6 + ["cell"] * 6).materials
        ['cell', 'paint']
        """
        return sorted(set(self.sides.material.tolist()))

    @property
    def is_convex(self) -> bool:
        """Whether the closed surface is convex.

        Uses :attr:`trimesh.Trimesh.is_convex`: a watertight single body whose every pair of
        adjacent facets is locally convex within ``1e-5`` times the bounding-box diagonal, so
        coplanar facets (a subdivided cube) count as convex.

        Examples
        --------
        >>> Spacecraft(trimesh.creation.box(), ["paint"] * 12).is_convex
        True
        """
        if "is_convex" not in self._cache:
            self._cache["is_convex"] = (
                not self.moving_parts and self.sides.mesh is self.mesh and bool(self.mesh.is_convex)
            )
        return self._cache["is_convex"]

    def inertia(self, density: float = 1.0) -> NDArray[np.float64]:
        """Inertia tensor about the centre of mass of the closed body at uniform density.

        Volume integrals over the closed surface (divergence theorem) by
        :func:`trimesh.triangles.mass_properties`.

        Parameters
        ----------
        density : float
            Uniform density [kg m-3].

        Returns
        -------
        ndarray, shape (3, 3)
            Inertia tensor in the body frame [kg m2].

        Examples
        --------
        >>> sc = Spacecraft(trimesh.creation.box(extents=(1.0, 1.0, 1.0)), ["paint"] * 12)
        >>> np.round(sc.inertia(density=6.0), 6)  # a 6 kg cube of side 1 m: m a**2 / 6 = 1 kg m2
        array([[ 1., -0., -0.],
               [-0.,  1., -0.],
               [-0., -0.,  1.]])
        """
        density = to_unit(density, "kg m-3", "density")
        if not (np.isfinite(density) and density > 0):
            raise ValidationError(f"density: must be a positive number [kg m-3], got {density!r}")
        if not self.mesh.is_watertight:
            raise MeshError(
                f"inertia: needs a volume, and the surface of {self.name!r} is open (some "
                "edges belong to a single facet); give the inertia tensor of the real "
                "spacecraft instead"
            )
        props = trimesh.triangles.mass_properties(self.mesh.triangles, density=float(density))
        return np.asarray(props["inertia"], dtype=np.float64)

    def facets(self) -> xr.Dataset:
        """Facet table: normal, area, centroid and material of every facet.

        Returns
        -------
        xarray.Dataset
            Over dims ``facet`` and ``xyz``: ``normal (facet, xyz)`` [1], ``area (facet)``
            [m2], ``centroid (facet, xyz)`` [m], ``material (facet)`` (names) and
            ``tangent (facet, xyz)`` [1] (:attr:`facet_tangent`).

        Examples
        --------
        >>> ds = Spacecraft(trimesh.creation.box(), ["paint"] * 12).facets()
        >>> sorted(ds.data_vars), ds.area.attrs["units"]
        (['area', 'centroid', 'material', 'normal', 'tangent'], 'm2')
        >>> ds.normal.isel(facet=0).values.tolist()
        [-1.0, 0.0, 0.0]
        """
        s = self.sides
        table = facet_table(s.mesh, s.material, s.tangent, self.name)
        if s.mesh is not self.mesh:  # backs or parts: say which facet and group each side is
            table["mesh_facet"] = (
                "facet",
                s.facet,
                {"long_name": "facet of the mesh", "units": "1"},
            )
            table["back"] = ("facet", s.back, {"long_name": "the back of the facet", "units": "1"})
            table["part"] = ("facet", s.group, {"long_name": "0: bus, k: part k - 1", "units": "1"})
        return table

    def merged(
        self, tolerance: float = NORMAL_TOLERANCE, tangent_materials: Iterable[str] = ()
    ) -> xr.Dataset:
        """Collapse facets that share (normal, material) into terms with summed area.

        Any facet sum whose summand depends on a facet only through its normal, material and
        area (``sum_j A_j g(N_j, material_j)``: the unshadowed radiometric sum of paper 000
        Eq. 3-4) is the same over terms, with far fewer terms.  Centroids are lost, so
        per-facet effects (shadowing, occlusion) need the facet table instead.

        Parameters
        ----------
        tolerance : float
            Two facets share a term if they have the same material and their unit normals
            round to the same grid point of spacing ``tolerance`` per component [1]; member
            normals then differ from the term normal by less than ``tolerance * sqrt(3)``.
            Exactly equal normals always share a term.
        tangent_materials : iterable of str
            Anisotropic materials: their facets share a term only if their tangents
            (``t`` and ``-t`` alike) also round to the same grid point.

        Returns
        -------
        xarray.Dataset
            Over dim ``term``: ``normal (term, xyz)`` (area-weighted mean of the members,
            renormalised), ``area (term)`` [m2], ``material (term)``, ``n_facets (term)``,
            ``tangent (term, xyz)`` (the first member's, made orthogonal to the term
            normal); and
            the mapping back ``facet_term (facet)``, the term of every facet.  Terms are in
            order of their first facet.

        Examples
        --------
        >>> sc = Spacecraft(trimesh.creation.box(), ["paint"] * 12)
        >>> terms = sc.merged()
        >>> terms.sizes["term"], terms.area.values.tolist()  # 6 faces of 2 facets each
        (6, [1.0, 1.0, 1.0, 1.0, 1.0, 1.0])
        """
        s = self.sides
        return merge_facets(
            s.mesh,
            s.material,
            s.tangent,
            self.name,
            tolerance=tolerance,
            tangent_materials=tangent_materials,
            groups=None if s.mesh is self.mesh else s.group,
        )

    def plot(
        self,
        ax: Any = None,
        *,
        colors: Mapping[str, Any] | None = None,
        edgecolor: Any = "0.3",
        linewidth: float = 0.2,
        legend: bool = True,
        elev: float = 25.0,
        azim: float = 35.0,
    ) -> Any:
        """Draw the model in 3-D, each facet coloured by its material (paper 000 Fig. 11).

        Parameters
        ----------
        ax : mpl_toolkits.mplot3d.Axes3D, optional
            Axes to draw in; a new figure is made otherwise.
        colors : mapping of str to colour, optional
            Colour of each material (default: the colours of the material map, else a
            matplotlib cycle).
        edgecolor, linewidth
            Facet edges.
        legend : bool
            Add a legend of the materials.
        elev, azim : float
            View angles [degree].

        Returns
        -------
        matplotlib.figure.Figure

        Examples
        --------
        >>> import matplotlib
        >>> matplotlib.use("Agg")
        >>> import matplotlib.pyplot as plt
        >>> fig = Spacecraft(trimesh.creation.box(), ["paint"] * 6 + ["cell"] * 6).plot()
        >>> type(fig).__name__, len(fig.axes)
        ('Figure', 1)
        >>> plt.close(fig)
        """
        return plot_facets(
            self.mesh,
            self.facet_material,
            ax,
            name=self.name,
            colors=colors,
            rgb=self.colors,
            edgecolor=edgecolor,
            linewidth=linewidth,
            legend=legend,
            elev=elev,
            azim=azim,
        )


# --------------------------------------------------------------------------- catalog


def load_catalog_entry(entry: _catalog_index.CatalogEntry) -> Spacecraft:
    """Load a ``kind = "spacecraft"`` catalog entry.

    The entry's ``path`` is the mesh; extra fields: ``material_map`` (path of the TOML map,
    relative to the catalog directory; required), ``length_unit`` (default: the unit the
    file states, else ``"m"``),
    ``face_property`` (optional).

    Examples
    --------
    >>> sc = load_catalog_entry(_catalog_index.entry("canx1"))
    >>> sc.name, sc.n_facets, round(float(sc.mesh.extents.max()), 4)  # largest extent [m]
    ('canx1', 684, 0.1032)
    """
    try:
        map_file = entry.extra["material_map"]
    except KeyError:
        raise CatalogError(
            f"spacecraft entry {entry.name!r} lacks the field 'material_map'"
        ) from None
    return load_spacecraft(
        entry.file,
        read_material_map(entry.data_path(map_file)),
        length_unit=entry.extra.get("length_unit"),
        name=entry.name,
        face_property=entry.extra.get("face_property"),
    )


def canx1() -> Spacecraft:
    """The CanX-1 Engineering Model-like nanosatellite of paper 000 §4 (catalog entry ``canx1``).

    A 10 cm cube centred at the origin (faces normal to +-x, +-y, +-z) with two
    triple-junction cells 40 mm x 70 mm, raised 0.5 mm, on each of the four side faces
    (side by side along y on +-X, stacked along z on +-Y), aluminium 6061-T6 frame rails along
    the side-face borders (5 mm on +-X, 10 mm vertical rails on +-Y, so the Y sides carry more
    aluminium) and white paint elsewhere; 684 facets (paper: 698).  Built by
    ``tools/build_canx1.py``, shipped as ``catalogs/spacecraft/canx1.ply``.

    Returns
    -------
    Spacecraft
        Materials ``aluminium-6061-t6``, ``tjpv-cell``, ``white-paint-a276``.

    Examples
    --------
    >>> sc = canx1()
    >>> sc.n_facets, sc.materials
    (684, ['aluminium-6061-t6', 'tjpv-cell', 'white-paint-a276'])
    """
    return load_catalog_entry(_catalog_index.entry("canx1"))
