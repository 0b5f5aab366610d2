"""Reading spacecraft meshes: five formats, length units, material maps, facet labels.

:func:`sbrdf_xr.body.spacecraft.load_spacecraft` reads a mesh with :func:`read_mesh`
(STL, OBJ, PLY, glTF/GLB or a trimesh object), labels its facets with
:func:`label_faces`, checks (and optionally repairs) it with
:func:`sbrdf_xr.body.repair.clean_mesh` and builds the
:class:`~sbrdf_xr.body.spacecraft.Spacecraft` from the result.  ``clean_mesh`` and its
tolerances, and :data:`~sbrdf_xr.body.facets.NORMAL_TOLERANCE`, are also importable
from here.
"""

from __future__ import annotations

import tomllib
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import trimesh

from ..errors import MeshError, ValidationError, input_file, reading
from ..units import LENGTH_UNITS, metres_per
from ._mesh_files import check_mesh_file
from .facets import NORMAL_TOLERANCE
from .repair import MERGE_DISTANCE, ZERO_AREA_FACTOR, clean_mesh

__all__ = [
    "LENGTH_UNITS",
    "MERGE_DISTANCE",
    "NORMAL_TOLERANCE",
    "TANGENT_ATTRIBUTE",
    "ZERO_AREA_FACTOR",
    "Color",
    "clean_mesh",
    "face_tangents",
    "label_faces",
    "length_factor",
    "normalise_map",
    "read_material_map",
    "read_mesh",
]

Color = tuple[int, int, int]


def length_factor(length_unit: Any) -> float:
    """Size of one ``length_unit`` in metres (:func:`sbrdf_xr.units.metres_per`).

    Parameters
    ----------
    length_unit : str, astropy unit or Quantity
        A key of :data:`LENGTH_UNITS` (exact, else any case; SI symbols whose case
        changes their meaning are read as written: ``"Mm"`` is the megametre and is
        refused), an astropy length unit or a length Quantity.

    Returns
    -------
    float
        Metres per unit [m].

    Raises
    ------
    UnitError
        If the unit is not a known length unit, or is the megametre.

    Examples
    --------
    >>> length_factor("mm"), length_factor("in"), length_factor("MM")
    (0.001, 0.0254, 0.001)
    """
    return metres_per(length_unit, "length_unit")


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

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> path = Path(tempfile.mkdtemp()) / "colours.toml"
    >>> text = '[[material]]\\nname = "paint"\\nrgb = [255, 255, 255]\\nlabels = ["panel"]\\n'
    >>> _ = path.write_text(text)
    >>> read_material_map(path)
    {(255, 255, 255): 'paint', 'panel': 'paint'}
    """
    path = input_file(path, "material_map", ValidationError)
    where = f"material map {path}"
    try:
        with reading(path, where, "UTF-8 text"):
            text = path.read_text(encoding="utf-8")
        raw = tomllib.loads(text)
    except ValueError as exc:  # TOML's message says where, not what; or over 4300 digits
        raise ValidationError(f"{where}: cannot be read as TOML: {exc}") from None
    out: dict[Any, str] = {}
    tables = raw.get("material")
    if not isinstance(tables, list) or not tables:
        raise ValidationError(f"{where}: expected [[material]] tables, found none")
    for i, table in enumerate(tables):
        if not isinstance(table, dict):
            raise ValidationError(f"{where}: material[{i}] is not a [[material]] table")
        name = table.get("name")
        if not isinstance(name, str) or not name:
            raise ValidationError(f"{where}: material[{i}] lacks a 'name' string")
        rgb = table.get("rgb", [])
        if not isinstance(rgb, list):
            raise ValidationError(
                f"{where}: material[{i}] ({name!r}) rgb: expected [r, g, b] or a list of "
                f"them, got {type(rgb).__name__}"
            )
        colours = [rgb] if rgb and not isinstance(rgb[0], list) else rgb
        labels = table.get("labels", [])
        if not isinstance(labels, list) or any(
            isinstance(x, bool) or not isinstance(x, str | int) for x in labels
        ):
            raise ValidationError(
                f"{where}: material[{i}] ({name!r}) labels: expected a list of names or integers"
            )
        for c in colours:
            if _as_color(c if isinstance(c, list) else [c]) is None:
                raise ValidationError(f"{where}: material[{i}] ({name!r}) rgb: got {c!r}")
        keys = [tuple(c) for c in colours] + labels
        if not keys:
            raise ValidationError(f"{where}: material {name!r} has neither 'rgb' nor 'labels'")
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
    try:
        arr = np.asarray(key)
    except ValueError:  # ragged
        arr = np.asarray(None)
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


def normalise_map(
    material_map: Mapping[Any, str] | str | Path, known_materials: Iterable[str] | None
) -> tuple[dict[Color, str], dict[str, str]]:
    """Split a material map (or the TOML file of one) into colour keys and name keys.

    Parameters
    ----------
    material_map : mapping or str or Path
        Facet label -> material name (see :func:`sbrdf_xr.body.spacecraft.load_spacecraft`).
    known_materials : iterable of str, optional
        Materials that exist; a map naming any other is an error.

    Returns
    -------
    colours : dict of (r, g, b) to str
    names : dict of str to str

    Raises
    ------
    ValidationError
        For an empty map, a key that is neither a colour nor a name, an empty material
        name, or a material not in ``known_materials``.

    Examples
    --------
    >>> normalise_map({"#ff0000": "aluminium", (0, 0, 255): "cell", "panel": "paint"}, None)
    ({(255, 0, 0): 'aluminium', (0, 0, 255): 'cell'}, {'panel': 'paint'})
    """
    if isinstance(material_map, str | Path):
        material_map = read_material_map(material_map)
    if not isinstance(material_map, Mapping) or not material_map:
        raise ValidationError(
            "material_map: expected a non-empty mapping of colour or name -> material, "
            f"got {material_map!r}"
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


class _Labelled:
    """Vertices, facets and per-facet label candidates read from a file or trimesh object."""

    def __init__(self) -> None:
        self.vertices: list[np.ndarray] = []
        self.faces: list[np.ndarray] = []
        self.rgb: list[np.ndarray] = []  # (n, 3) int, -1 where unknown
        self.names: list[list[np.ndarray]] = []  # per part: candidate name arrays (object)
        self.tangents: list[np.ndarray] = []  # (n, 3) float, NaN where the file has none
        self.tangent = np.zeros((0, 3))
        self.rgb_bits = 8
        self.offset = 0
        self.units: str | None = None  # the length unit the file states, if any

    def add(
        self,
        vertices: np.ndarray,
        faces: np.ndarray,
        rgb: np.ndarray | None,
        names: list[Any],
        tangents: np.ndarray | None = None,
    ) -> None:
        n = len(faces)
        self.tangents.append(
            np.full((n, 3), np.nan) if tangents is None else np.asarray(tangents, np.float64)
        )
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
        self.tangent = np.concatenate(self.tangents)
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


#: Name of the per-face tangent attribute read from meshes (a trimesh face attribute
#: or a PLY face property of 3 values, or the three properties ``tangent_x``,
#: ``tangent_y``, ``tangent_z``).
TANGENT_ATTRIBUTE = "tangent"


def face_tangents(mesh: trimesh.Trimesh, prop: str = TANGENT_ATTRIBUTE) -> np.ndarray | None:
    """Per-face tangent directions a mesh carries, shape (n_faces, 3), or None.

    Read from the trimesh face attribute ``prop``, or the PLY face property ``prop``
    (a list of 3 numbers per face), or the PLY face properties ``prop_x``, ``prop_y``,
    ``prop_z``.

    Examples
    --------
    >>> box = trimesh.creation.box()
    >>> face_tangents(box) is None
    True
    >>> box.face_attributes["tangent"] = np.tile([1.0, 0.0, 0.0], (12, 1))
    >>> face_tangents(box).shape
    (12, 3)
    """
    n = len(mesh.faces)
    vals: Any = None
    fa = getattr(mesh, "face_attributes", {}) or {}
    raw = mesh.metadata.get("_ply_raw", {}).get("face", {}).get("data")
    names = _ply_face_props(raw)
    if prop in fa:
        vals = fa[prop]
    elif prop in names:
        vals = raw[prop]
        if isinstance(raw, np.ndarray) and vals.dtype.names and "f1" in vals.dtype.names:
            vals = vals["f1"]  # binary PLY list property: (count, values)
    elif all(f"{prop}_{c}" in names or f"{prop}_{c}" in fa for c in "xyz"):
        cols = [fa.get(f"{prop}_{c}", None) for c in "xyz"]
        vals = np.column_stack(
            [
                np.asarray(raw[f"{prop}_{c}"]) if v is None else v
                for v, c in zip(cols, "xyz", strict=True)
            ]
        )
    if vals is None:
        return None
    arr = np.asarray(vals, dtype=np.float64)
    if arr.shape != (n, 3):
        raise MeshError(
            f"{prop}: the per-face tangent attribute must hold 3 numbers per facet "
            f"(shape ({n}, 3)), got shape {arr.shape}"
        )
    return arr


def _ply_face_props(raw: Any) -> set[str]:
    if isinstance(raw, dict):
        return set(raw) - {"vertex_indices"}
    if isinstance(raw, np.ndarray) and raw.dtype.names:
        return set(raw.dtype.names) - {"vertex_indices"}
    return set()


def _is_none(a: np.ndarray) -> np.ndarray:
    """Elementwise ``a is None`` (for object arrays of labels)."""
    return np.equal(a, np.array(None, dtype=object))


def _visual_labels(mesh: trimesh.Trimesh) -> tuple[np.ndarray | None, str | None]:
    """Per-face colours and the material name carried by a mesh's visual."""
    visual = getattr(mesh, "visual", None)
    kind = getattr(visual, "kind", None)
    if visual is not None and kind in ("face", "vertex"):
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


def read_mesh(
    path_or_mesh: Any, face_property: str | None, file_type: str | None
) -> tuple[_Labelled, str | None]:
    """Read a mesh source into labelled arrays; return them and a default name.

    Examples
    --------
    >>> labelled, name = read_mesh(trimesh.creation.box(), None, None)
    >>> vertices, faces, rgb, names = labelled.arrays()
    >>> vertices.shape, faces.shape, rgb.shape
    ((8, 3), (12, 3), (12, 3))
    """
    out = _Labelled()
    default_name = None
    obj = path_or_mesh
    if isinstance(obj, str | Path):
        path = input_file(obj, "mesh file", MeshError)
        check_mesh_file(path, file_type)  # declared counts, vertex rows: before reading
        default_name = path.stem
        try:
            obj = trimesh.load(path, file_type=file_type, process=False)
        except Exception as exc:  # the library's message may quote the file: not shown
            raise MeshError(
                f"{path}: could not be read as a mesh ({type(exc).__name__}); "
                "expected a format trimesh reads (STL, OBJ, PLY, glTF/GLB, OFF, ...)"
            ) from None
    stated = getattr(obj, "units", None)
    out.units = str(stated) if stated else None
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
            tang = face_tangents(geom)
            if tang is not None:  # directions turn with the node, lengths do not matter
                tang = tang @ np.asarray(transform, dtype=np.float64)[:3, :3].T
            out.add(verts, geom.faces, rgb, [prop, mat_name, geom_name, node], tang)
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
    out.add(obj.vertices, obj.faces, rgb, [prop, mat_name], face_tangents(obj))
    return out, default_name or obj.metadata.get("name")


def label_faces(
    labelled: _Labelled,
    rgb: np.ndarray,
    names: list[np.ndarray],
    colours: dict[Color, str],
    name_map: dict[str, str],
) -> np.ndarray:
    """Material name of every face; MeshError listing the labels that are not in the map.

    Examples
    --------
    >>> box = trimesh.creation.box()
    >>> box.visual.face_colors = [255, 0, 0, 255]
    >>> labelled, _ = read_mesh(box, None, None)
    >>> vertices, faces, rgb, names = labelled.arrays()
    >>> colours, name_map = normalise_map({"#ff0000": "aluminium"}, None)
    >>> label_faces(labelled, rgb, names, colours, name_map)[:3]
    array(['aluminium', 'aluminium', 'aluminium'], dtype='<U9')
    """
    n = len(rgb)
    material = np.full(n, None, dtype=object)
    for cand in names:
        todo = np.flatnonzero(_is_none(material) & ~_is_none(cand))
        if len(todo) == 0:
            continue
        uniq, inv = np.unique(cand[todo].astype(str), return_inverse=True)
        lookup = np.array([name_map.get(u) for u in uniq], dtype=object)
        material[todo] = lookup[inv]
    todo = np.flatnonzero(_is_none(material))
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
    missing = np.flatnonzero(_is_none(material))
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
