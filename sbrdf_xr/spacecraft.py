"""Spacecraft: a triangulated surface in metres whose every facet carries a material name.

Paper 000 §3.3 represents a spacecraft by a triangular-faceted CAD model (STL) in which the
colour of a facet selects its material (Table 2: vertices ``V``, facets ``F``, normals ``N``,
colours ``C``).  This module reads such models from any format :mod:`trimesh` reads, maps
facet colours or material/group names to material names, checks that the surface can be used
(finite, no zero-area or duplicate facets, closed and consistently wound with outward normals)
and converts the length unit to metres.  It also builds the facet table used by the
simulation, merges facets that share (normal, material), and ships the CanX-1-like model of
paper 000 §4 (:func:`canx1`).

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
Every problem raises :class:`~sbrdf_xr.errors.MeshError` unless ``repair=True``; then the
documented repair below is applied and reported with a :class:`MeshRepairWarning` (never
silently).  In order:

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

import tomllib
import warnings
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import trimesh
import xarray as xr
from numpy.typing import NDArray

from . import _catalog_index
from ._names import FACET, MATERIAL, VECTOR, attrs
from .errors import CatalogError, MeshError, MeshRepairWarning, ValidationError

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

#: Length units accepted by :func:`load_spacecraft` and their size in metres [m].
LENGTH_UNITS: dict[str, float] = {
    "m": 1.0,
    "meter": 1.0,
    "metre": 1.0,
    "km": 1.0e3,
    "cm": 1.0e-2,
    "centimeter": 1.0e-2,
    "centimetre": 1.0e-2,
    "mm": 1.0e-3,
    "millimeter": 1.0e-3,
    "millimetre": 1.0e-3,
    "um": 1.0e-6,
    "micrometer": 1.0e-6,
    "micrometre": 1.0e-6,
    "in": 0.0254,
    "inch": 0.0254,
    "ft": 0.3048,
    "foot": 0.3048,
}

#: Facets whose area is at most this factor times the squared bounding-box diagonal are
#: zero-area (about a 1e-7 relative edge length).
ZERO_AREA_FACTOR = 1.0e-14

#: Component tolerance below which two unit normals are the same in :meth:`Spacecraft.merged`.
NORMAL_TOLERANCE = 1.0e-9

#: Vertices whose coordinates agree after rounding to this step are one vertex [m].
MERGE_DISTANCE = 1.0e-8

#: Material names of the built-in CanX-1-like model and their facet colours (paper 000 Fig. 11).
CANX1_MATERIALS: dict[str, tuple[int, int, int]] = {
    "aluminium-6061-t6": (255, 0, 0),
    "tjpv-cell": (0, 0, 255),
    "white-paint-a276": (255, 255, 255),
}

Color = tuple[int, int, int]


# --------------------------------------------------------------------------- units


def length_factor(length_unit: str) -> float:
    """Size of one ``length_unit`` in metres.

    Parameters
    ----------
    length_unit : str
        A key of :data:`LENGTH_UNITS` (case-insensitive), e.g. ``"m"``, ``"mm"``, ``"in"``.

    Returns
    -------
    float
        Metres per unit [m].

    Raises
    ------
    ValidationError
        If the unit is not a known length unit.
    """
    key = length_unit.strip().lower() if isinstance(length_unit, str) else None
    if key not in LENGTH_UNITS:
        raise ValidationError(
            f"length_unit: got {length_unit!r}, which is not a length unit; "
            f"allowed: {', '.join(LENGTH_UNITS)}"
        )
    return LENGTH_UNITS[key]


# --------------------------------------------------------------------------- material maps


def read_material_map(path: str | Path) -> dict[Any, str]:
    """Read a facet-label -> material map from a TOML file.

    The file holds one ``[[material]]`` table per material::

        [[material]]
        name = "aluminium-6061-t6"   # material name
        rgb = [255, 0, 0]            # optional: facet colour(s), 0-255
        labels = ["alu", 3]          # optional: material/group names or face-property values

    ``rgb`` may also be a list of colours.

    Parameters
    ----------
    path : str or Path
        The TOML file.

    Returns
    -------
    dict
        ``{(r, g, b): name, label: name, ...}`` as accepted by :func:`load_spacecraft`.

    Raises
    ------
    ValidationError
        If the file is not valid TOML or a table lacks ``name`` or has no key.
    """
    path = Path(path)
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise ValidationError(f"material map {path}: cannot be read as TOML: {exc}") from exc
    out: dict[Any, str] = {}
    tables = raw.get("material")
    if not isinstance(tables, list) or not tables:
        raise ValidationError(f"material map {path}: expected [[material]] tables, found none")
    for i, table in enumerate(tables):
        name = table.get("name")
        if not isinstance(name, str) or not name:
            raise ValidationError(f"material map {path}: table {i} lacks a 'name' string")
        rgb = table.get("rgb", [])
        colours = [rgb] if rgb and not isinstance(rgb[0], list) else rgb
        keys = [tuple(c) for c in colours] + list(table.get("labels", []))
        if not keys:
            raise ValidationError(
                f"material map {path}: material {name!r} has neither 'rgb' nor 'labels'"
            )
        for k in keys:
            out[k] = name
    return out


def _as_color(key: Any) -> Color | None:
    """The RGB colour a map key stands for, or None if it is a name."""
    if isinstance(key, str):
        k = key.strip()
        if len(k) == 7 and k.startswith("#"):
            try:
                return (int(k[1:3], 16), int(k[3:5], 16), int(k[5:7], 16))
            except ValueError:
                return None
        return None
    if isinstance(key, bool | int | np.integer):
        return None
    arr = np.asarray(key)
    if arr.shape != (3,) or not np.issubdtype(arr.dtype, np.number):
        raise ValidationError(
            f"material_map: key {key!r} is neither a colour (3 integers 0-255) nor a name"
        )
    if (
        not np.all(np.isfinite(arr))
        or np.any(arr != np.round(arr))
        or arr.min() < 0
        or arr.max() > 255
    ):
        raise ValidationError(f"material_map: colour key {key!r} must be 3 integers in 0-255")
    return (int(arr[0]), int(arr[1]), int(arr[2]))


def _normalise_map(
    material_map: Mapping[Any, str] | str | Path, known_materials: Iterable[str] | None
) -> tuple[dict[Color, str], dict[str, str]]:
    if isinstance(material_map, str | Path):
        material_map = read_material_map(material_map)
    if not isinstance(material_map, Mapping) or not material_map:
        raise ValidationError(
            f"material_map: expected a non-empty mapping of colour or name -> material, got {material_map!r}"
        )
    colours: dict[Color, str] = {}
    names: dict[str, str] = {}
    for key, value in material_map.items():
        if not isinstance(value, str) or not value.strip():
            raise ValidationError(
                f"material_map: key {key!r} maps to {value!r}; material names are non-empty strings"
            )
        colour = _as_color(key)
        if colour is not None:
            colours[colour] = value
        else:
            names[str(key)] = value
    if known_materials is not None:
        known = set(known_materials)
        unknown = sorted({*colours.values(), *names.values()} - known)
        if unknown:
            raise ValidationError(
                f"material_map: names material(s) {unknown} that do not exist; "
                f"known materials: {sorted(known)}"
            )
    return colours, names


# --------------------------------------------------------------------------- reading


class _Labelled:
    """Vertices, facets and per-facet label candidates read from a file or trimesh object."""

    def __init__(self) -> None:
        self.vertices: list[np.ndarray] = []
        self.faces: list[np.ndarray] = []
        self.rgb: list[np.ndarray] = []  # (n, 3) int, -1 where unknown
        self.names: list[list[np.ndarray]] = []  # per part: candidate name arrays (object)
        self.rgb_bits = 8
        self.offset = 0

    def add(
        self, vertices: np.ndarray, faces: np.ndarray, rgb: np.ndarray | None, names: list[Any]
    ) -> None:
        n = len(faces)
        self.vertices.append(np.asarray(vertices, dtype=np.float64).reshape(-1, 3))
        self.faces.append(np.asarray(faces, dtype=np.int64).reshape(-1, 3) + self.offset)
        self.offset += len(self.vertices[-1])
        self.rgb.append(
            np.full((n, 3), -1, np.int64) if rgb is None else np.asarray(rgb, np.int64)[:, :3]
        )
        cands = []
        for nm in names:  # keep positions aligned across parts: None -> all-None candidate
            if nm is None or np.ndim(nm) == 0:
                cands.append(np.full(n, nm, dtype=object))
            else:
                cands.append(np.asarray(nm).astype(str).astype(object))
        self.names.append(cands)

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[np.ndarray]]:
        if not self.faces:
            return np.zeros((0, 3)), np.zeros((0, 3), np.int64), np.zeros((0, 3), np.int64), []
        n_cand = max(len(c) for c in self.names)
        cands = []
        for k in range(n_cand):
            parts = [
                c[k] if k < len(c) else np.full(len(f), None, object)
                for c, f in zip(self.names, self.faces, strict=True)
            ]
            cands.append(np.concatenate(parts))
        return (
            np.concatenate(self.vertices),
            np.concatenate(self.faces),
            np.concatenate(self.rgb),
            cands,
        )


def _face_property(mesh: trimesh.Trimesh, prop: str) -> np.ndarray:
    """Values of a face property (PLY element property or trimesh face attribute)."""
    if prop in getattr(mesh, "face_attributes", {}):
        vals = np.asarray(mesh.face_attributes[prop])
    else:
        raw = mesh.metadata.get("_ply_raw", {}).get("face", {}).get("data")
        if isinstance(raw, dict) and prop in raw:
            vals = np.asarray(raw[prop])
        elif isinstance(raw, np.ndarray) and raw.dtype.names and prop in raw.dtype.names:
            vals = np.asarray(raw[prop])
        else:
            available = sorted(set(getattr(mesh, "face_attributes", {})) | _ply_face_props(raw))
            raise MeshError(
                f"face_property: the mesh has no face property {prop!r}; available: {available}"
            )
    return vals.reshape(len(mesh.faces), -1)[:, 0]


def _ply_face_props(raw: Any) -> set[str]:
    if isinstance(raw, dict):
        return set(raw) - {"vertex_indices"}
    if isinstance(raw, np.ndarray) and raw.dtype.names:
        return set(raw.dtype.names) - {"vertex_indices"}
    return set()


def _visual_labels(mesh: trimesh.Trimesh) -> tuple[np.ndarray | None, str | None]:
    """Per-face colours and the material name carried by a mesh's visual."""
    visual = getattr(mesh, "visual", None)
    kind = getattr(visual, "kind", None)
    if kind in ("face", "vertex"):
        return np.asarray(visual.face_colors)[:, :3], None
    material = getattr(visual, "material", None)
    if material is not None:
        name = getattr(material, "name", None)
        try:
            colour = np.asarray(material.main_color)[:3]
        except Exception:  # pragma: no cover - exotic materials
            colour = None
        rgb = None if colour is None else np.tile(colour, (len(mesh.faces), 1))
        return rgb, name
    return None, None


def _stl_colors(mesh: trimesh.Trimesh) -> np.ndarray | None:
    """Decode VisCAM/SolidView 15-bit facet colours of a binary STL (5 bits per channel)."""
    attr = getattr(mesh, "face_attributes", {}).get("stl")
    if attr is None:
        return None
    a = np.asarray(attr, dtype=np.uint16).reshape(-1)
    valid = (a & 0x8000) != 0
    if not valid.any():
        return None
    rgb = np.stack([(a >> 10) & 31, (a >> 5) & 31, a & 31], axis=1).astype(np.int64)
    rgb[~valid] = -1
    return rgb


def _read(
    path_or_mesh: Any, face_property: str | None, file_type: str | None
) -> tuple[_Labelled, str | None]:
    """Read a mesh source into labelled arrays; return them and a default name."""
    out = _Labelled()
    default_name = None
    obj = path_or_mesh
    if isinstance(obj, str | Path):
        path = Path(obj)
        if not path.is_file():
            raise FileNotFoundError(f"mesh file {path} does not exist")
        default_name = path.stem
        try:
            obj = trimesh.load(path, file_type=file_type, process=False)
        except Exception as exc:
            raise MeshError(
                f"{path}: could not be read as a mesh ({type(exc).__name__}: {exc}); "
                "expected a format trimesh reads (STL, OBJ, PLY, glTF/GLB, OFF, ...)"
            ) from exc
    if isinstance(obj, trimesh.Scene):
        if not obj.geometry:
            raise MeshError("the mesh source is an empty scene: it holds no geometry")
        for node in obj.graph.nodes_geometry:
            transform, geom_name = obj.graph[node]
            geom = obj.geometry[geom_name]
            if not isinstance(geom, trimesh.Trimesh):
                continue
            rgb, mat_name = _visual_labels(geom)
            prop = _face_property(geom, face_property) if face_property else None
            verts = trimesh.transform_points(np.asarray(geom.vertices, dtype=np.float64), transform)
            out.add(verts, geom.faces, rgb, [prop, mat_name, geom_name, node])
        if not out.faces:
            raise MeshError(
                "the mesh source holds no triangle mesh (only "
                f"{sorted({type(g).__name__ for g in obj.geometry.values()})})"
            )
        return out, default_name
    if not isinstance(obj, trimesh.Trimesh):
        raise MeshError(
            f"expected a triangle mesh (a file trimesh reads, a trimesh.Trimesh or trimesh.Scene), "
            f"got {type(obj).__name__}"
        )
    rgb, mat_name = _visual_labels(obj)
    stl = _stl_colors(obj)
    if stl is not None:
        rgb = stl
        out.rgb_bits = 5
    prop = _face_property(obj, face_property) if face_property else None
    out.add(obj.vertices, obj.faces, rgb, [prop, mat_name])
    return out, default_name or obj.metadata.get("name")


def _label_faces(
    labelled: _Labelled,
    rgb: np.ndarray,
    names: list[np.ndarray],
    colours: dict[Color, str],
    name_map: dict[str, str],
) -> np.ndarray:
    """Material name of every face; MeshError listing the labels that are not in the map."""
    n = len(rgb)
    material = np.full(n, None, dtype=object)
    for cand in names:
        todo = np.flatnonzero(np.equal(material, None) & ~np.equal(cand, None))
        if len(todo) == 0:
            continue
        uniq, inv = np.unique(cand[todo].astype(str), return_inverse=True)
        lookup = np.array([name_map.get(u) for u in uniq], dtype=object)
        material[todo] = lookup[inv]
    todo = np.flatnonzero(np.equal(material, None))
    unmapped_colours: list[Color] = []
    if len(todo) and colours:
        have = todo[(rgb[todo] >= 0).all(axis=1)]
        if len(have):
            keys = np.array(list(colours), dtype=np.int64)
            if labelled.rgb_bits == 5:
                keys = np.round(keys * 31 / 255).astype(np.int64)
            uniq, inv = np.unique(rgb[have], axis=0, return_inverse=True)
            lookup = np.full(len(uniq), None, dtype=object)
            values = list(colours.values())
            for i, u in enumerate(uniq):  # loop over distinct colours (few), not facets
                match = np.flatnonzero((keys == u).all(axis=1))
                if len(match):
                    lookup[i] = values[match[0]]
                else:
                    c = u if labelled.rgb_bits == 8 else np.round(u * 255 / 31)
                    unmapped_colours.append((int(c[0]), int(c[1]), int(c[2])))
            material[have] = lookup[inv.reshape(-1)]
    missing = np.flatnonzero(np.equal(material, None))
    if len(missing):
        labels: list[Any] = list(dict.fromkeys(unmapped_colours))
        for cand in names:
            labels += [v for v in dict.fromkeys(cand[missing]) if v is not None]
        if not labels and not (rgb[missing] >= 0).all(axis=1).any():
            what = "no colour and no name matching the map"
        else:
            what = f"label(s) {labels[:10]}{' ...' if len(labels) > 10 else ''}"
        raise MeshError(
            f"material_map: {len(missing)} of {n} facets are unmapped: {what}; "
            f"the map has colours {sorted(colours)} and names {sorted(name_map)}"
        )
    return material.astype(str)


# --------------------------------------------------------------------------- checks and repairs


def _problem(repair: bool, message: str, fix: str) -> None:
    if not repair:
        raise MeshError(f"{message}; pass repair=True to {fix}")
    warnings.warn(f"{message}: repaired ({fix})", MeshRepairWarning, stacklevel=4)


def _clean(
    vertices: np.ndarray, faces: np.ndarray, material: np.ndarray, repair: bool
) -> tuple[trimesh.Trimesh, np.ndarray]:
    """Run checks/repairs 1-7 of the module docstring."""
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
            f"{int(bad_v.sum())} vertices are not finite (NaN or inf), used by {int(bad_f.sum())} facets",
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
            f"{int(zero.sum())} of {len(faces)} facets have zero area (first: {np.flatnonzero(zero)[:5].tolist()})",
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
            f"{len(faces) - len(first)} facets duplicate another facet (first: {np.flatnonzero(~keep)[:5].tolist()})",
            "keep the first of each set of duplicates",
        )
        faces, material = faces[keep], material[keep]
    mesh = trimesh.Trimesh(vertices, faces, process=False, validate=False)
    # 5. open surface
    if not mesh.is_watertight:
        n_open = len(trimesh.grouping.group_rows(mesh.edges_sorted, require_count=1))
        _problem(
            repair,
            f"the surface is not closed ({n_open} edges belong to a single facet, or edges are shared by more than two)",
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
            f"{int(flipped.sum())} facets belong to inside-out bodies (negative volume, normals pointing inwards)",
            "flip them",
        )
        mesh = probe
    return trimesh.Trimesh(
        np.asarray(mesh.vertices), np.asarray(mesh.faces), process=False
    ), material


# --------------------------------------------------------------------------- public API


def load_spacecraft(
    path_or_mesh: str | Path | trimesh.Trimesh | trimesh.Scene,
    material_map: Mapping[Any, str] | str | Path | None = None,
    *,
    material: str | None = None,
    length_unit: str = "m",
    repair: bool = False,
    name: str | None = None,
    known_materials: Iterable[str] | None = None,
    face_property: str | None = None,
    file_type: str | None = None,
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
    length_unit : str
        Length unit of the file's coordinates (see :data:`LENGTH_UNITS`); converted to
        metres.  CAD exports are often in ``"mm"``.
    repair : bool
        Repair the problems listed in the module docstring (with a
        :class:`MeshRepairWarning` for each) instead of raising :class:`MeshError`.
    name : str, optional
        Name of the spacecraft (default: the file stem, the mesh's name or ``"spacecraft"``).
    known_materials : iterable of str, optional
        Materials that exist; a map naming any other material is an error.
    face_property : str, optional
        Name of a per-face property (PLY) or face attribute holding the facet labels.
    file_type : str, optional
        Format of a file without a telling extension (``"stl"``, ``"ply"``, ...).

    Returns
    -------
    Spacecraft
        The labelled, checked model in metres.

    Raises
    ------
    MeshError
        If the source is not a triangle mesh, is empty, has unmapped facets, or has one of
        the problems of the module docstring while ``repair`` is False.
    ValidationError
        If the length unit or the map is invalid, or the map names an unknown material.
    FileNotFoundError
        If ``path_or_mesh`` is a path that does not exist.
    """
    factor = length_factor(length_unit)
    if (material_map is None) == (material is None):
        raise ValidationError(
            "load_spacecraft: give exactly one of material_map (facet label -> material) and "
            f"material (one material for every facet); got material_map={material_map!r}, "
            f"material={material!r}"
        )
    if material is not None:
        if not isinstance(material, str) or not material.strip():
            raise ValidationError(f"material: expected a non-empty material name, got {material!r}")
        if known_materials is not None and material not in set(known_materials):
            raise ValidationError(
                f"material: {material!r} does not exist; known materials: {sorted(set(known_materials))}"
            )
        colours, name_map = {}, {}
    else:
        colours, name_map = _normalise_map(material_map, known_materials)
    labelled, default_name = _read(path_or_mesh, face_property, file_type)
    vertices, faces, rgb, names = labelled.arrays()
    if len(faces) == 0:
        raise MeshError("the mesh is empty: it has no facets")
    if material is not None:
        material = np.full(len(faces), material, dtype=object)
    else:
        material = _label_faces(labelled, rgb, names, colours, name_map)
    with np.errstate(invalid="ignore", over="ignore"):
        vertices = vertices * factor
    mesh, material = _clean(vertices, faces, material, repair)
    palette = {m: c for c, m in colours.items()}
    return Spacecraft(mesh, material, name=name or default_name or "spacecraft", colors=palette)


class Spacecraft:
    """A closed triangulated surface in metres with a material name on every facet.

    Composition, not a trimesh subclass: :attr:`mesh` is the geometry and
    :attr:`facet_material` the labels.  Build it with :func:`load_spacecraft` (which checks
    the mesh) or :func:`canx1`.

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
    """

    def __init__(
        self,
        mesh: trimesh.Trimesh,
        facet_material: Iterable[str],
        *,
        name: str = "spacecraft",
        colors: Mapping[str, Color] | None = None,
    ) -> None:
        if not isinstance(mesh, trimesh.Trimesh):
            raise ValidationError(f"mesh: expected a trimesh.Trimesh, got {type(mesh).__name__}")
        labels = np.asarray(list(facet_material), dtype=str)
        if labels.shape != (len(mesh.faces),):
            raise ValidationError(
                f"facet_material: expected {len(mesh.faces)} names (one per facet), got shape {labels.shape}"
            )
        labels.setflags(write=False)
        self.mesh = mesh
        self.facet_material: NDArray[np.str_] = labels
        self.name = str(name)
        self.colors: dict[str, Color] = dict(colors or {})
        self._cache: dict[str, Any] = {}

    def __repr__(self) -> str:
        return (
            f"<Spacecraft {self.name!r}: {self.n_facets} facets, materials {self.materials}, "
            f"extent {np.round(self.mesh.extents, 6).tolist()} m>"
        )

    @property
    def n_facets(self) -> int:
        """Number of facets."""
        return len(self.mesh.faces)

    @property
    def materials(self) -> list[str]:
        """Sorted unique material names."""
        return sorted(set(self.facet_material.tolist()))

    @property
    def is_convex(self) -> bool:
        """Whether the closed surface is convex.

        Uses :attr:`trimesh.Trimesh.is_convex`: a watertight single body whose every pair of
        adjacent facets is locally convex within ``1e-5`` times the bounding-box diagonal, so
        coplanar facets (a subdivided cube) count as convex.
        """
        if "is_convex" not in self._cache:
            self._cache["is_convex"] = bool(self.mesh.is_convex)
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
        """
        if not (np.isfinite(density) and density > 0):
            raise ValidationError(f"density: must be a positive number [kg m-3], got {density!r}")
        props = trimesh.triangles.mass_properties(self.mesh.triangles, density=float(density))
        return np.asarray(props["inertia"], dtype=np.float64)

    def facets(self) -> xr.Dataset:
        """Facet table: normal, area, centroid and material of every facet.

        Returns
        -------
        xarray.Dataset
            Over dims ``facet`` and ``xyz``: ``normal (facet, xyz)`` [1], ``area (facet)``
            [m2], ``centroid (facet, xyz)`` [m] and ``material (facet)`` (names).
        """
        mesh = self.mesh
        ds = xr.Dataset(
            {
                "normal": (
                    (FACET, VECTOR),
                    np.asarray(mesh.face_normals, dtype=np.float64),
                    attrs("normal"),
                ),
                "area": ((FACET,), np.asarray(mesh.area_faces, dtype=np.float64), attrs("area")),
                "centroid": (
                    (FACET, VECTOR),
                    np.asarray(mesh.triangles_center, dtype=np.float64),
                    attrs("centroid"),
                ),
                MATERIAL: ((FACET,), self.facet_material.copy(), attrs(MATERIAL)),
            },
            coords={
                FACET: (FACET, np.arange(self.n_facets), attrs(FACET)),
                VECTOR: (VECTOR, ["x", "y", "z"], attrs(VECTOR)),
            },
            attrs={"spacecraft": self.name, "title": f"facets of {self.name}"},
        )
        return ds

    def merged(self, tolerance: float = NORMAL_TOLERANCE) -> xr.Dataset:
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

        Returns
        -------
        xarray.Dataset
            Over dim ``term``: ``normal (term, xyz)`` (area-weighted mean of the members,
            renormalised), ``area (term)`` [m2], ``material (term)``, ``n_facets (term)``; and
            the mapping back ``facet_term (facet)``, the term of every facet.  Terms are in
            order of their first facet.
        """
        if not (np.isfinite(tolerance) and tolerance > 0):
            raise ValidationError(
                f"tolerance: got {tolerance!r}; expected a positive finite number"
            )
        normals = np.asarray(self.mesh.face_normals, dtype=np.float64)
        area = np.asarray(self.mesh.area_faces, dtype=np.float64)
        mat_names, mat_code = np.unique(self.facet_material, return_inverse=True)
        keys = np.column_stack(
            [mat_code.reshape(-1), np.round(normals / tolerance).astype(np.int64)]
        )
        _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
        order = np.argsort(first, kind="stable")  # terms in order of first facet
        rank = np.empty_like(order)
        rank[order] = np.arange(len(order))
        term = rank[inverse.reshape(-1)]
        n_terms = len(order)
        t_area = np.bincount(term, weights=area, minlength=n_terms)
        t_normal = np.stack(
            [np.bincount(term, weights=area * normals[:, k], minlength=n_terms) for k in range(3)],
            axis=1,
        )
        norm = np.linalg.norm(t_normal, axis=1, keepdims=True)
        # A term of zero-area facets only (no normal) keeps a zero normal: it faces
        # nothing and contributes nothing, without 0/0.
        t_normal = np.divide(t_normal, norm, out=np.zeros_like(t_normal), where=norm > 0)
        n_facets = np.bincount(term, minlength=n_terms)
        t_material = mat_names[mat_code.reshape(-1)[np.asarray(first)[order]]]
        return xr.Dataset(
            {
                "normal": (("term", VECTOR), t_normal, attrs("normal")),
                "area": (
                    ("term",),
                    t_area,
                    attrs("area", long_name="summed facet area of the term"),
                ),
                MATERIAL: (("term",), t_material, attrs(MATERIAL)),
                "n_facets": (("term",), n_facets, attrs("n_facets")),
                "facet_term": ((FACET,), term, attrs("facet_term")),
            },
            coords={
                "term": ("term", np.arange(n_terms), attrs("term")),
                FACET: (FACET, np.arange(self.n_facets), attrs(FACET)),
                VECTOR: (VECTOR, ["x", "y", "z"], attrs(VECTOR)),
            },
            attrs={
                "spacecraft": self.name,
                "normal_tolerance": tolerance,
                "title": f"merged facets of {self.name}",
            },
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
        """
        import matplotlib.pyplot as plt
        from matplotlib.colors import to_rgba
        from matplotlib.patches import Patch
        from mpl_toolkits.mplot3d.art3d import Poly3DCollection

        if ax is None:
            fig = plt.figure(figsize=(6, 6))
            ax = fig.add_subplot(projection="3d")
        else:
            fig = ax.figure
        cycle = plt.rcParams["axes.prop_cycle"].by_key().get("color", ["C0"])
        palette: dict[str, Any] = {}
        for i, m in enumerate(self.materials):
            if colors and m in colors:
                palette[m] = to_rgba(colors[m])
            elif m in self.colors:
                palette[m] = to_rgba(np.asarray(self.colors[m]) / 255.0)
            else:
                palette[m] = to_rgba(cycle[i % len(cycle)])
        names, code = np.unique(self.facet_material, return_inverse=True)
        face_rgba = np.array([palette[n] for n in names])[code.reshape(-1)]
        tri = np.asarray(self.mesh.triangles)
        coll = Poly3DCollection(
            tri, facecolors=face_rgba, edgecolors=edgecolor, linewidths=linewidth
        )
        ax.add_collection3d(coll)
        lo, hi = self.mesh.bounds
        centre, half = (lo + hi) / 2, float(np.max(hi - lo)) / 2
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - half, centre[1] + half)
        ax.set_zlim(centre[2] - half, centre[2] + half)
        ax.set_box_aspect((1, 1, 1))
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_zlabel("z [m]")
        ax.view_init(elev=elev, azim=azim)
        ax.set_title(f"{self.name}: {self.n_facets} facets")
        if legend:
            ax.legend(
                handles=[
                    Patch(facecolor=palette[m], edgecolor="0.3", label=m) for m in self.materials
                ],
                loc="upper left",
            )
        return fig


# --------------------------------------------------------------------------- catalog


def load_catalog_entry(entry: _catalog_index.CatalogEntry) -> Spacecraft:
    """Load a ``kind = "spacecraft"`` catalog entry.

    The entry's ``path`` is the mesh; extra fields: ``material_map`` (path of the TOML map,
    relative to the catalog directory; required), ``length_unit`` (default ``"m"``),
    ``face_property`` (optional).
    """
    try:
        map_file = entry.extra["material_map"]
    except KeyError:
        raise CatalogError(
            f"spacecraft entry {entry.name!r} lacks the field 'material_map'"
        ) from None
    return load_spacecraft(
        entry.file,
        read_material_map(_catalog_index.data_path(map_file)),
        length_unit=entry.extra.get("length_unit", "m"),
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
    """
    return load_catalog_entry(_catalog_index.entry("canx1"))
