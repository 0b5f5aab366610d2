"""Scene files: the TOML schema of a scene, the checks of its values, reading it.

:func:`load_scene` reads a TOML file and :func:`scene_from_dict` builds a
:class:`~sbrdf_xr.engine.scene.Scene` from a parsed table; every key, type and domain is
checked here (a :class:`~sbrdf_xr.errors.SceneError` names the key, what it got and what
is allowed) before any catalog entry or file is loaded.  Both are re-exported from
:mod:`sbrdf_xr.engine.builtin` and :mod:`sbrdf_xr.engine`.
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .. import geometry
from ..errors import CatalogError, SceneError, ValidationError, did_you_mean, renamed_attributes
from .knobs import KNOBS
from .scene import Scene
from .schema import ATTITUDE_KEYS, GEOMETRY_KEYS, SCENE_KEYS, SPACECRAFT_KEYS, toml_types

__all__ = [
    "MAX_SCENE_COUNT",
    "MAX_SHADOW_DENSITY",
    "load_material_specs",
    "load_scene",
    "scene_from_dict",
    "scene_material_tables",
]


_SCENE_KEYS = toml_types(SCENE_KEYS)
_SPACECRAFT_KEYS = toml_types(SPACECRAFT_KEYS)
_ATTITUDE_KEYS = toml_types(ATTITUDE_KEYS)
_GEOMETRY_KEYS = toml_types(GEOMETRY_KEYS)


def _check_keys(table: Any, allowed: Mapping[str, Any], where: str) -> None:
    if not isinstance(table, Mapping):
        raise SceneError(f"{where}: expected a table of keys, got {type(table).__name__}")
    for k, v in table.items():
        if k not in allowed:
            raise SceneError(
                f"{where}: unknown key {k!r}; {did_you_mean(k, allowed, 'allowed keys')}"
            )
        types = allowed[k]
        types = types if isinstance(types, tuple) else (types,)
        if not isinstance(v, types) or (isinstance(v, bool) and bool not in types):
            names = " or ".join(t.__name__ for t in types)
            raise SceneError(
                f"{where}: key {k!r} has type {type(v).__name__} ({_show(v)}); expected {names}"
            )


#: Most attitudes or geometry pairs a scene file may list or generate.
MAX_SCENE_COUNT = 10_000_000


#: Largest magnitude of a direction's component in a scene file (its length must not overflow).
_MAX_COMPONENT = 1e100


#: Largest shadow-sampling density a scene may ask for (sub-facet samples per side; the knob
#: table's bound).
MAX_SHADOW_DENSITY = int(KNOBS["shadow_density"].high or 0)


def _show(v: Any) -> str:
    text = repr(v)
    return text if len(text) <= 60 else text[:57] + "..."


def _is_number(x: Any) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool)


def _number(v: Any, where: str) -> float:
    """A finite number from a scene file."""
    if not _is_number(v):
        raise SceneError(f"{where}: expected a number, got {_show(v)} ({type(v).__name__})")
    try:
        x = float(v)
    except OverflowError:
        raise SceneError(f"{where}: {_show(v)} is too large") from None
    if not np.isfinite(x):
        raise SceneError(f"{where}: must be finite, got {x}")
    return x


def _numbers(v: Any, where: str, *, allow_empty: bool = False) -> np.ndarray:
    """A flat list of finite numbers from a scene file."""
    if not isinstance(v, list):
        raise SceneError(f"{where}: expected a list of numbers, got {_show(v)}")
    if not v and not allow_empty:
        raise SceneError(f"{where}: the list is empty; give at least one value")
    if len(v) > MAX_SCENE_COUNT:
        raise SceneError(f"{where}: {len(v)} values; at most {MAX_SCENE_COUNT} are allowed")
    return np.array([_number(x, f"{where}[{i}]") for i, x in enumerate(v)], dtype=np.float64)


def _rows(v: Any, width: int, where: str) -> np.ndarray:
    """A non-empty list of rows of ``width`` finite numbers (vectors, quaternions)."""
    if not isinstance(v, list) or not v:
        raise SceneError(
            f"{where}: expected a non-empty list of [{', '.join(['x'] * width)}] rows, "
            f"got {_show(v)}"
        )
    if len(v) > MAX_SCENE_COUNT:
        raise SceneError(f"{where}: {len(v)} rows; at most {MAX_SCENE_COUNT} are allowed")
    out = np.empty((len(v), width))
    for i, row in enumerate(v):
        if not isinstance(row, list) or len(row) != width:
            raise SceneError(f"{where}[{i}]: expected {width} numbers, got {_show(row)}")
        out[i] = [_number(x, f"{where}[{i}][{j}]") for j, x in enumerate(row)]
    return out


def _vector(v: Any, where: str) -> tuple[float, float, float]:
    if not isinstance(v, list) or len(v) != 3:
        raise SceneError(f"{where}: expected a vector of 3 numbers, got {_show(v)}")
    x = (_number(v[0], f"{where}[0]"), _number(v[1], f"{where}[1]"), _number(v[2], f"{where}[2]"))
    if not any(x):
        raise SceneError(f"{where}: the zero vector has no direction")
    if max(map(abs, x)) > _MAX_COMPONENT:
        raise SceneError(
            f"{where}: components must not exceed {_MAX_COMPONENT:g} in magnitude, got {list(x)}"
        )
    return x


def _strings(v: Any, where: str, *, allow_empty: bool = True) -> tuple[str, ...]:
    if not isinstance(v, list) or not all(isinstance(x, str) for x in v):
        raise SceneError(f"{where}: expected a list of strings, got {_show(v)}")
    if not v and not allow_empty:
        raise SceneError(f"{where}: the list is empty; give at least one")
    return tuple(v)


def _count(v: Any, where: str) -> int:
    if not isinstance(v, int) or isinstance(v, bool) or not 1 <= v <= MAX_SCENE_COUNT:
        raise SceneError(
            f"{where}: expected an integer from 1 to {MAX_SCENE_COUNT}, got {_show(v)}"
        )
    return int(v)


def _attitudes_from_table(t: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray | None]:
    _check_keys(t, _ATTITUDE_KEYS, "[attitude]")
    kind = t.get("kind", "sweep")
    try:
        if kind == "sweep":
            if "stop" not in t:
                raise SceneError(
                    "[attitude]: a sweep needs 'stop' (and optionally 'start' and 'step') [degree]"
                )
            start = _number(t.get("start", 0.0), "[attitude] start")
            stop = _number(t["stop"], "[attitude] stop")
            step = _number(t.get("step", 1.0), "[attitude] step")
            if step == 0:
                raise SceneError("[attitude] step: must not be 0")
            n = int(np.ceil((stop - start) / step))
            if n < 1:
                raise SceneError(
                    f"[attitude]: a sweep from {start:g} to {stop:g} (excluded) in steps of "
                    f"{step:g} degree has no attitude; stop must lie beyond start in the "
                    "direction of step"
                )
            if n > MAX_SCENE_COUNT:
                raise SceneError(
                    f"[attitude]: the sweep has {n} attitudes; "
                    f"at most {MAX_SCENE_COUNT} are allowed"
                )
            angles = np.arange(start, stop, step)
            initial = None
            if "initial_axis" in t:
                initial = geometry.axis_rotation(
                    _vector(t["initial_axis"], "[attitude] initial_axis"),
                    _number(t.get("initial_angle", 0.0), "[attitude] initial_angle"),
                )
            axis = _vector(t.get("axis", [0, 0, 1]), "[attitude] axis")
            return geometry.rotation_sweep(axis, angles, initial), angles
        if kind == "uniform":
            if "n" not in t:
                raise SceneError("[attitude]: kind 'uniform' needs 'n' (the number of attitudes)")
            seed = t.get("seed", 0)
            if not 0 <= seed < 2**63:
                raise SceneError(
                    f"[attitude] seed: expected an integer from 0 to 2**63 - 1, got {seed}"
                )
            return geometry.uniform_attitudes(_count(t["n"], "[attitude] n"), seed), None
        if kind == "euler":
            if "sequence" not in t or "angles" not in t:
                raise SceneError(
                    "[attitude]: kind 'euler' needs 'sequence' (e.g. 'zyx') and 'angles' [degree]"
                )
            seq, ang = t["sequence"], t["angles"]
            if ang and all(isinstance(a, list) for a in ang):
                angles = _rows(ang, len(seq), "[attitude] angles")
            else:
                angles = _numbers(ang, "[attitude] angles")
            return geometry.euler_attitudes(seq, angles), None
        if kind == "quaternions":
            if "quaternions" not in t:
                raise SceneError(
                    "[attitude]: kind 'quaternions' needs 'quaternions' (rows of x, y, z, w)"
                )
            return geometry.check_quaternions(
                _rows(t["quaternions"], 4, "[attitude] quaternions")
            ), None
    except SceneError:
        raise
    except (ValidationError, ValueError, TypeError) as exc:
        raise SceneError(f"[attitude]: {exc}") from None
    raise SceneError(
        f"[attitude]: unknown kind {kind!r}; allowed: sweep, uniform, euler, quaternions"
    )


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
    for k in ("earth_albedo", "earth_range_km", "earth_phase_angle", "earth_temperature"):
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
        kw["attitudes"], angles = _attitudes_from_table(d["attitude"])
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
    return scene_from_dict(d, path.parent)


#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(__name__, globals(), {"material_tables": "scene_material_tables"})
