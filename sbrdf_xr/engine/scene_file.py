"""Scene files: the TOML schema of a scene, the checks of its values, reading it.

:func:`load_scene` reads a TOML file and :func:`scene_from_dict` builds a
:class:`~sbrdf_xr.engine.scene.Scene` from a parsed table; every key, type and domain is
checked here (a :class:`~sbrdf_xr.errors.SceneError` names the key, what it got and what
is allowed) before any catalog entry or file is loaded.  Both are re-exported from
:mod:`sbrdf_xr.engine.builtin` and :mod:`sbrdf_xr.engine`.
"""

from __future__ import annotations

import tomllib
import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import xarray as xr

from ..errors import (
    CatalogError,
    RenamedWarning,
    SceneError,
    ValidationError,
    did_you_mean,
    renamed_attributes,
)
from .attitude_table import (
    MAX_SCENE_COUNT,
    _check_keys,
    _number,
    _numbers,
    _rows,
    _show,
    _vector,
    attitudes_from_table,
)
from .knobs import KNOBS
from .scene import Scene
from .schema import (
    GEOMETRY_KEYS,
    RENAMED_SCENE_KEYS,
    SCENE_KEYS,
    SPACECRAFT_KEYS,
    WRITE_KEYS,
    toml_types,
)

__all__ = [
    "MAX_SCENE_COUNT",
    "MAX_SHADOW_DENSITY",
    "load_material_specs",
    "load_scene",
    "scene_from_dict",
    "scene_material_tables",
    "write_options",
]


_SCENE_KEYS = toml_types(SCENE_KEYS)
_SPACECRAFT_KEYS = toml_types(SPACECRAFT_KEYS)
_GEOMETRY_KEYS = toml_types(GEOMETRY_KEYS)
_WRITE_KEYS = toml_types(WRITE_KEYS)

#: Largest shadow-sampling density a scene may ask for (sub-facet samples per side; the knob
#: table's bound).
MAX_SHADOW_DENSITY = int(KNOBS["shadow_density"].high or 0)


def _strings(v: Any, where: str, *, allow_empty: bool = True) -> tuple[str, ...]:
    if not isinstance(v, list) or not all(isinstance(x, str) for x in v):
        raise SceneError(f"{where}: expected a list of strings, got {_show(v)}")
    if not v and not allow_empty:
        raise SceneError(f"{where}: the list is empty; give at least one")
    return tuple(v)


def _renamed_keys(d: Any) -> Any:
    """``d`` with the old keys of :data:`~sbrdf_xr.engine.schema.RENAMED_SCENE_KEYS` read
    as their new ones, each with a :class:`~sbrdf_xr.errors.RenamedWarning`."""
    if not isinstance(d, Mapping) or not set(d) & set(RENAMED_SCENE_KEYS):
        return d
    d = dict(d)
    for old, new in RENAMED_SCENE_KEYS.items():
        if old in d:
            if new in d:
                raise SceneError(
                    f"scene: keys {old!r} and {new!r} both given; {old!r} is the old name of "
                    f"{new!r}: give only {new!r}"
                )
            warnings.warn(
                f"scene: the key {old!r} is renamed {new!r}; the old name will be removed in "
                "the next release",
                RenamedWarning,
                stacklevel=3,
            )
            d[new] = d.pop(old)
    return d


def _spacecraft(spec: Any, base_dir: str | Path | None) -> Any:
    """The spacecraft of a scene file: a catalog name, a mesh path, or a [spacecraft] table."""
    from .. import catalog

    options: dict[str, Any] = {}
    parts = None
    table = isinstance(spec, Mapping)
    if isinstance(spec, Mapping):
        _check_keys(spec, _SPACECRAFT_KEYS, "[spacecraft]")
        if "path" not in spec:
            raise SceneError(
                "[spacecraft]: key 'path' is required (a mesh file, relative to the scene file)"
            )
        options = {k: v for k, v in spec.items() if k not in ("path", "parts")}
        parts = spec.get("parts")
        spec = spec["path"]
        if not catalog.is_file_spec(spec):
            spec = Path(spec)  # a table always names a file
    try:
        sc = catalog.load_spacecraft_spec(spec, base_dir=base_dir, **options)
        return sc if parts is None else _with_parts(sc, parts)
    except (CatalogError, SceneError) as exc:
        if table and not str(exc).startswith("[spacecraft]"):
            raise type(exc)(f"[spacecraft] path: {exc}") from None
        raise
    except (ValidationError, FileNotFoundError) as exc:
        hint = ""
        if isinstance(spec, str) and catalog.is_file_spec(spec) and "needs exactly one" in str(exc):
            hint = (
                f'; write a [spacecraft] table: path = "{spec}" and material = "..." or '
                'material_map = "map.toml"'
            )
        raise SceneError(f"{'[spacecraft] ' if table else ''}{exc}{hint}") from None


def _with_parts(sc: Any, parts: Any) -> Any:
    """``sc`` with the parts of a ``[[spacecraft.parts]]`` array of tables."""
    from ..body.parts import part_from_spec

    if not isinstance(parts, list) or not all(isinstance(p, Mapping) for p in parts):
        raise SceneError("[spacecraft] parts: expected [[spacecraft.parts]] tables")
    try:
        return sc.with_parts([part_from_spec(p, sc.facet_material) for p in parts])
    except ValidationError as exc:
        raise SceneError(f"[spacecraft] parts: {exc}") from None


def scene_material_tables(
    specs: Mapping[str, str | Path],
    base_dir: str | Path | None = None,
    where: Mapping[str, str] | None = None,
) -> tuple[dict[str, xr.DataArray], dict[str, xr.Dataset]]:
    """:func:`sbrdf_xr.catalog.material_tables`, with its bad input as a :class:`SceneError`.

    Examples
    --------
    >>> tables, models = scene_material_tables({"paint": "lambertian-grey-50"})
    >>> sorted(tables), models
    (['paint'], {})
    """
    from .. import catalog

    try:
        return catalog.material_tables(specs, base_dir, where)
    except SceneError:
        raise
    except ValidationError as exc:
        raise SceneError(str(exc)) from None


def load_material_specs(
    specs: Mapping[str, str | Path],
    base_dir: str | Path | None = None,
    where: Mapping[str, str] | None = None,
) -> dict[str, xr.DataArray | xr.Dataset]:
    """Material tables and BRDF models from catalog names or netCDF files, nothing rendered:
    what ``Scene(materials=...)`` takes (a model becomes a table only when a plan needs
    one).  An error names where each material was given (``where``; default
    ``"[materials]"``).

    Raises
    ------
    CatalogError
        For an unknown name or a file that does not exist.
    SceneError
        For an entry of another kind or a file that is neither a table nor a model.

    Examples
    --------
    >>> from sbrdf_xr.engine.scene_file import load_material_specs
    >>> found = load_material_specs({"paint": "lambertian-grey-50", "cell": "tjpv-cell-model"})
    >>> {m: type(v).__name__ for m, v in found.items()}
    {'paint': 'DataArray', 'cell': 'Dataset'}
    """
    from .. import catalog

    out: dict[str, xr.DataArray | xr.Dataset] = {}
    for mat, spec in specs.items():
        named = f"{(where or {}).get(mat, '[materials]')} {mat!r}"
        try:
            out[mat] = catalog.load_material_spec(spec, base_dir=base_dir)
        except CatalogError as exc:
            raise CatalogError(f"{named}: {exc}") from None
        except ValidationError as exc:
            raise SceneError(f"{named}: {exc}") from None
    return out


def scene_from_dict(d: Mapping[str, Any], base_dir: str | Path | None = None) -> Scene:
    """Build a scene from the contents of a scene file (see :func:`load_scene`); relative
    file names in it (mesh, material map and material files, an ``[observation]``'s
    quaternion series) are taken from ``base_dir``.

    Raises
    ------
    SceneError
        For every key that is unknown, of the wrong type, out of its domain, empty where
        something is needed (``phase_angles``, ``outputs``), or larger than
        :data:`MAX_SCENE_COUNT`; :class:`~sbrdf_xr.errors.CatalogError` for catalog names
        and files that do not exist.

    Examples
    --------
    The CanX-1 mesh with every material replaced by the catalog's Lambertian grey
    table, three attitudes of a sweep about z and two phase angles:

    >>> from sbrdf_xr.engine import scene_from_dict
    >>> grey = "lambertian-grey-50"
    >>> scene = scene_from_dict({
    ...     "name": "grey-canx1",
    ...     "spacecraft": "canx1",
    ...     "phase_angles": [10.0, 30.0],
    ...     "attitude": {"kind": "sweep", "axis": [0, 0, 1], "stop": 90, "step": 30},
    ...     "materials": {"aluminium-6061-t6": grey, "tjpv-cell": grey, "white-paint-a276": grey},
    ... })
    >>> scene.name, scene.n_geometries, scene.attitude_angle.tolist()
    ('grey-canx1', 6, [0.0, 30.0, 60.0])
    >>> scene_from_dict({"spacecraft": "canx1", "colour": "red"})
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.SceneError: scene: unknown key 'colour'; allowed keys: ...
    """
    d = _renamed_keys(d)
    _check_keys(d, _SCENE_KEYS, "scene")

    kw: dict[str, Any] = {
        k: d[k] for k in ("name", "description", "merge", "band_extrapolate") if k in d
    }
    # the numerical knobs, checked by the Scene against the knob table
    kw.update({k: d[k] for k in KNOBS if k in d})
    if "size_limit" in d:
        kw["size_limit"] = _number(d["size_limit"], "size_limit")
    if "surface_tilt" in d:
        st = d["surface_tilt"]
        kw["surface_tilt"] = (
            {str(m): _number(x, f"surface_tilt.{m}") for m, x in st.items()}
            if isinstance(st, Mapping)
            else _number(st, "surface_tilt")
        )
    for k in ("earth_albedo", "earth_range", "earth_phase_angle", "earth_temperature"):
        if k in d:
            kw[k] = _number(d[k], k)
    if "temperature" in d:
        t = d["temperature"]
        if isinstance(t, Mapping):
            kw["temperature"] = {str(m): _number(x, f"temperature.{m}") for m, x in t.items()}
        else:
            kw["temperature"] = t if t == "equilibrium" else _number(t, "temperature")
    if "outputs" in d:
        kw["outputs"] = _strings(d["outputs"], "outputs", allow_empty=False)
    for k in ("effects", "bands"):
        if k in d:
            kw[k] = _strings(d[k], k)
    for k in ("bisector", "plane_normal", "earth_direction"):
        if k in d:
            kw[k] = _vector(d[k], k)
    if "geometry" in d:
        g = d["geometry"]
        _check_keys(g, _GEOMETRY_KEYS, "[geometry]")
        for k in ("to_sun", "to_observer"):
            if k not in g:
                raise SceneError(f"[geometry]: key {k!r} is required (rows of 3 numbers)")
            kw[k] = _rows(g[k], 3, f"[geometry] {k}")
        if "to_earth" in g:
            kw["to_earth"] = _rows(g["to_earth"], 3, "[geometry] to_earth")
    _write_table(d)  # checked here, used by the writer (write_options)
    if "observation" in d:
        from ..observing.observe import observation_from_dict

        if "attitude" in d or "geometry" in d or "phase_angles" in d:
            raise SceneError(
                "scene: an [observation] gives the geometry; leave out [attitude], "
                "[geometry] and phase_angles"
            )
        try:
            kw["observation"] = observation_from_dict(
                d["observation"], base_dir, size_limit=kw.get("size_limit", 1.0)
            )
        except (ValidationError, CatalogError) as exc:
            raise SceneError(f"[observation]: {exc}") from exc
    if "attitude" in d:
        if "geometry" in d:
            raise SceneError(
                "scene: give either an [attitude] table (with phase_angles) or a "
                "[geometry] table, not both"
            )
        if "phase_angles" not in d:
            raise SceneError("scene: an [attitude] table needs 'phase_angles' [degree]")
        kw["attitudes"], angles = attitudes_from_table(d["attitude"])
        if angles is not None:
            kw["attitude_angle"] = angles
        kw["phase_angles"] = _numbers(d["phase_angles"], "phase_angles")
    elif "phase_angles" in d:
        raise SceneError("scene: 'phase_angles' needs an [attitude] table")
    # Catalog entries and files are loaded last, once every cheap check has passed.
    if "spacecraft" not in d:
        raise SceneError("scene: key 'spacecraft' is required (a catalog name or a mesh file)")
    sc = _spacecraft(d["spacecraft"], base_dir)
    # every material of the spacecraft by its own name, unless [materials] names another;
    # an error names the section the name was written in
    body = d["spacecraft"]
    named_in = (
        f"[spacecraft] {'material_map' if 'material_map' in body else 'material'}"
        if isinstance(body, Mapping)
        else f"spacecraft {body!r}"
    )
    specs: dict[str, str] = {m: m for m in sc.materials}
    where = dict.fromkeys(sc.materials, named_in)
    for mat, spec in d.get("materials", {}).items():
        if mat not in specs:
            raise SceneError(
                f"[materials]: {mat!r} is not a material of the spacecraft {sc.name!r}; "
                + did_you_mean(mat, sc.materials, "its materials")
            )
        where[mat] = "[materials]"
        if not isinstance(spec, str):
            raise SceneError(
                f"[materials]: {mat!r} must name a catalog entry or a netCDF file (a "
                f"string), got {_show(spec)}"
            )
        specs[mat] = spec
    materials = load_material_specs(specs, base_dir, where)
    try:
        return Scene(sc, materials=materials, **kw)
    except SceneError:
        raise
    except (ValidationError, ValueError, TypeError) as exc:  # a check deeper in the package
        raise SceneError(f"scene: {exc}") from None


def load_scene(path: str | Path) -> Scene:
    """Load a scene from a TOML file.

    Example file::

        name = "my-rotation"
        spacecraft = "canx1"              # a catalog entry
        phase_angles = [10.0]             # degree
        outputs = ["spacecraft_sbrdf", "signal", "brdf", "area"]
        effects = ["sunlight"]
        method = "linear"

        [attitude]                        # or [geometry] with to_sun / to_observer lists
        kind = "sweep"                    # sweep | uniform | euler | quaternions
        axis = [0, 0, -1]
        start = 0
        stop = 360
        step = 1
        initial_axis = [0, 0, 1]
        initial_angle = 25

        [materials]                       # optional: material name -> catalog entry
        "white-paint-a276" = "white-paint-a276"   # (default: the entry of that name)

    Wherever a catalog name is expected a file may stand instead, and relative paths are
    taken from the scene file's directory.  The spacecraft may be a mesh file of one
    material or labelled facets (any suffix of
    :data:`sbrdf_xr.catalog.MESH_SUFFIXES`), given as a table::

        [spacecraft]
        path = "meshes/bus.stl"           # required
        material = "lambertian-grey-50"   # one material for every facet, or:
        # material_map = "bus-colours.toml" (sbrdf_xr.body.spacecraft.read_material_map format)
        # material_map = { "#ff0000" = "aluminium-6061-t6", "panel" = "tjpv-cell" }
        length_unit = "mm"                # optional, also face_property, repair, name

    and a material may be a netCDF file of a material table
    (:func:`sbrdf_xr.materials.files.to_netcdf`) or of a BRDF model
    (:func:`sbrdf_xr.materials.models.to_netcdf`; rendered to a table by
    :func:`sbrdf_xr.materials.models.render`, and evaluated exactly with
    ``evaluation = "analytic"``)::

        [materials]
        "lambertian-grey-50" = "tables/my-grey.nc"

    Names are looked up in the shipped catalog and in the user catalogs of
    ``SBRDF_XR_CATALOG_PATH`` (:mod:`sbrdf_xr.catalog`).  Unknown keys and wrong types
    raise :class:`~sbrdf_xr.errors.SceneError`; unknown names and missing files
    :class:`~sbrdf_xr.errors.CatalogError`.

    Examples
    --------
    The CanX-1 mesh with the catalog's Lambertian grey table for all its materials:

    >>> import tempfile
    >>> from pathlib import Path
    >>> text = '''
    ... name = "grey-canx1"
    ... spacecraft = "canx1"
    ... phase_angles = [10.0]
    ... [attitude]
    ... kind = "sweep"
    ... axis = [0, 0, 1]
    ... stop = 90.0
    ... step = 45.0
    ... [materials]
    ... "aluminium-6061-t6" = "lambertian-grey-50"
    ... "tjpv-cell" = "lambertian-grey-50"
    ... "white-paint-a276" = "lambertian-grey-50"
    ... '''
    >>> from sbrdf_xr.engine import load_scene
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = Path(tmp) / "grey.toml"
    ...     _ = path.write_text(text)
    ...     scene = load_scene(path)
    >>> scene.name, scene.n_geometries, scene.spacecraft.n_facets
    ('grey-canx1', 2, 684)
    """
    path = Path(path)
    return scene_from_dict(_read_toml(path), path.parent)


def _read_toml(path: Path) -> dict[str, Any]:
    """The contents of a TOML scene file; a :class:`SceneError` for a file that cannot be
    read or is not UTF-8 TOML."""
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise SceneError(f"scene file {path}: cannot be read ({exc.strerror or exc})") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise SceneError(
            f"scene file {path}: not UTF-8 text (byte 0x{raw[exc.start]:02x} at offset "
            f"{exc.start}); TOML files are UTF-8"
        ) from None
    try:
        d = tomllib.loads(text)
    except ValueError as exc:  # TOMLDecodeError, or an integer of over 4300 digits
        why = "an integer of more than 4300 digits" if "digits" in str(exc) else exc
        raise SceneError(f"{path}: invalid TOML: {why}") from None
    except RecursionError:
        raise SceneError(f"{path}: invalid TOML: nested too deeply") from None
    return d


def _write_table(d: Mapping[str, Any]) -> dict[str, str]:
    """The ``[write]`` table of a scene file's contents, checked (empty when none)."""
    from ..store.derived import OUTPUTS

    t = d.get("write", {})
    _check_keys(t, _WRITE_KEYS, "[write]")
    out = dict(t)
    if "outputs" in out and out["outputs"] not in OUTPUTS:
        raise SceneError(
            f"[write] outputs: got {out['outputs']!r}; allowed: "
            f"{', '.join(repr(o) for o in OUTPUTS)}"
        )
    return out


def write_options(path: str | Path) -> dict[str, str]:
    """How ``sbrdf-xr simulate`` writes the cube of a scene file: its ``[write]`` table
    (:data:`~sbrdf_xr.engine.schema.WRITE_KEYS`; the keyword arguments of
    :func:`sbrdf_xr.store.write` of the same names), checked; empty when it has none.

    Raises
    ------
    SceneError
        The file cannot be read, is not TOML, or its ``[write]`` table has an unknown
        key or value.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.engine.scene_file import write_options
    >>> from sbrdf_xr.errors import SceneError
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = Path(tmp) / "scene.toml"
    ...     _ = path.write_text('spacecraft = "canx1"\\n[write]\\noutputs = "all"\\n')
    ...     print(write_options(path))
    ...     _ = path.write_text('spacecraft = "canx1"\\n[write]\\noutputs = "some"\\n')
    ...     try:
    ...         write_options(path)
    ...     except SceneError as exc:
    ...         print(exc)
    {'outputs': 'all'}
    [write] outputs: got 'some'; allowed: 'independent', 'all'
    """
    return _write_table(_read_toml(Path(path)))


#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(__name__, globals(), {"material_tables": "scene_material_tables"})
