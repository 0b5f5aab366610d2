"""Content fingerprint of a scene: what a cube was computed from.

A cube is a function of its material tables, its mesh, which table stands for which
material, the filters of its bands, every numerical knob, its geometry and the package
version.  :func:`scene_fingerprint` hashes each of these (SHA-256) and returns them as
the flat string attributes laid out in :mod:`sbrdf_xr.store.fingerprint` (the store
writes them and compares them when a cube is resumed, with
:func:`sbrdf_xr.store.fingerprint.changes`; it never reads a scene).

:func:`sbrdf_xr.engine.run.simulate` stores them in every cube.  Hashes are computed from
values, never from object identity, so the same scene built twice has the same
fingerprint.  The digest of a read-only array (a catalog table, whose values no one can
write) is computed once and kept while the array lives, and so is the digest of a whole
table whose values are read-only: it is reused while the table still holds the same
values array and coordinate variables (index coordinates cannot be written in place) and
equal attributes, checked on every call, so a scene that differs from the last one only in
geometry or knobs does not hash its tables again; writeable arrays are hashed every time.
(Making a read-only array writeable again and changing it in place defeats this; the
catalog's tables are read-only so that they can be shared.)  A catalog table memory-mapped
from the table cache (:mod:`sbrdf_xr.materials.mapped`) is not read at all: the digest of
its values was recorded, by the same formula, when its values file was written, and the
file is checked to be unchanged on every call.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import re
import threading
import weakref
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr

from .._names import __version__
from ..materials.mapped import recorded_digest
from ..store.fingerprint import KNOBS_JSON, MATERIAL_NAMES, MATERIAL_PREFIX, PREFIX

if TYPE_CHECKING:
    from .views import SceneView

__all__ = ["scene_fingerprint"]

#: Scene fields that are geometry (hashed together) rather than knobs.
_GEOMETRY_FIELDS = (
    "attitudes",
    "phase_angles",
    "bisector",
    "plane_normal",
    "to_sun",
    "to_observer",
    "to_earth",
    "attitude_angle",
    "observation",
)
#: Scene fields hashed on their own, or labels that do not change any value (the block
#: sizes: a cube's values are those of every block size, so a ``.part`` begun with other
#: blocks resumes, rechunked to its own).
_OTHER_FIELDS = (
    "spacecraft",
    "materials",
    "name",
    "description",
    "_checked",
    "_cache",
    "chunk",
    "block_bytes",
)
#: Knobs renamed since cubes were first written, under the name their fingerprint keeps
#: (so that a cube written before the rename still resumes).
_FINGERPRINT_NAMES = {"earth_range": "earth_range_km"}


def _canonical(value: Any) -> Any:
    """A JSON-able, order-independent image of ``value`` (arrays by dtype, shape and hash)."""
    t = type(value)
    if t is str or t is int or t is bool or value is None:  # the common cases, first
        return value
    if t is float:
        return repr(value)
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {
            f.name: _canonical(getattr(value, f.name))
            for f in dataclasses.fields(value)
            if f.compare  # not caches and derived state
        }
    if isinstance(value, Mapping):
        return {str(k): _canonical(v) for k, v in sorted(value.items(), key=lambda kv: str(kv[0]))}
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "OUS":
            return [_canonical(x) for x in value.tolist()]
        return {"dtype": str(value.dtype), "shape": list(value.shape), "sha256": _array_sha(value)}
    if isinstance(value, np.generic):
        return _canonical(value.item())
    if isinstance(value, list | tuple):
        return [_canonical(x) for x in value]
    if isinstance(value, float):
        return repr(value)  # exact, and NaN/inf survive JSON
    if value is None or isinstance(value, bool | int | str):
        return value
    return f"{type(value).__name__}:{value!r}"


def _json(value: Any) -> str:
    return json.dumps(_canonical(value), sort_keys=True, separators=(",", ":"))


def _read_only(a: np.ndarray) -> bool:
    """Whether no one can write ``a``'s values: it and every array it views are read-only,
    and the memory at the bottom of the chain is its own or an immutable buffer."""
    base: Any = a
    while isinstance(base, np.ndarray):
        if base.flags.writeable:
            return False
        base = base.base
    if base is None:
        return True
    try:
        return memoryview(base).readonly
    except TypeError:  # memory of an unknown kind (an mmap, a foreign buffer): may change
        return False


#: id(array) -> (weak reference, layout when hashed, digest) for read-only arrays.
_DIGESTS: dict[int, tuple[weakref.ref, tuple, str]] = {}
#: Re-entrant: a kept array or table freed while the lock is held (an entry replaced, or
#: the garbage collector running) calls its ``forget`` in the same thread.
_DIGESTS_LOCK = threading.RLock()


def _layout(a: np.ndarray) -> tuple:
    return (a.__array_interface__["data"][0], a.shape, a.strides, a.dtype.str)


def _forgetter(kept: dict[int, tuple], key: int) -> Any:
    """The weak reference callback that drops ``kept[key]`` when its object dies.

    The lock and the dict are bound now, not looked up when it runs: at interpreter exit
    the module's globals may already be gone when the last kept objects are freed.
    """
    lock = _DIGESTS_LOCK

    def forget(ref: weakref.ref) -> None:
        with lock:
            if key in kept and kept[key][0] is ref:
                del kept[key]

    return forget


def _array_sha(a: Any) -> str:
    """SHA-256 of an array's dtype, shape and values.

    The digest of a read-only array (:func:`_read_only`: it and every array under it)
    is kept while the array lives and reused as long as it is still read-only and still
    views the same memory; a writeable array is hashed every time, so changing its
    values in place always changes its digest.
    """
    if not isinstance(a, np.ndarray) or a.dtype.kind in "OUS" or not _read_only(a):
        return _array_sha_now(a)
    recorded = recorded_digest(a)  # a memory-mapped table: its digest without its pages
    if recorded is not None:
        return recorded
    key, layout = id(a), _layout(a)
    with _DIGESTS_LOCK:
        hit = _DIGESTS.get(key)
    if hit is not None and hit[0]() is a and hit[1] == layout:
        return hit[2]
    sha = _array_sha_now(a)

    with _DIGESTS_LOCK:
        _DIGESTS[key] = (weakref.ref(a, _forgetter(_DIGESTS, key)), layout, sha)
    return sha


def _array_sha_now(a: Any) -> str:
    arr = np.ascontiguousarray(np.asarray(a))
    h = hashlib.sha256(f"{arr.dtype.str}{arr.shape}".encode())
    if arr.dtype.kind in "mM":  # datetimes and durations: their integer counts
        arr = arr.view(np.int64)
    if arr.dtype.kind == "O":
        h.update(json.dumps([str(x) for x in arr.ravel().tolist()]).encode())
    else:  # numbers, and fixed-width strings by their code units (the dtype gives the width)
        h.update(arr.data.cast("B"))
    return h.hexdigest()


def _sha(*parts: str) -> str:
    h = hashlib.sha256()
    for p in parts:
        h.update(p.encode())
        h.update(b"\0")
    return h.hexdigest()


def _table_sha(da: Any) -> str:
    """Values, dims, every coordinate and the attributes of one material table (or of each
    variable of a model material).

    The digest of a table whose values are read-only is kept while the table lives and
    reused while :func:`_table_state` is unchanged; any other table is hashed every time.
    """
    if hasattr(da, "data_vars"):  # a model (Dataset): every variable, and its attributes
        parts = [f"{k}={_table_sha_now(da[k])}" for k in sorted(map(str, da.data_vars))]
        attrs = {k: v for k, v in da.attrs.items() if k not in _VOLATILE_TABLE_ATTRS}
        return _sha(*parts, _json(attrs))
    found = _table_state(da)
    if found is None:
        return _table_sha_now(da)
    state, held = found
    key = id(da)
    with _DIGESTS_LOCK:
        hit = _TABLES.get(key)
    if hit is not None and hit[0]() is da and hit[1] == state:
        return hit[3]
    sha = _table_sha_now(da)

    with _DIGESTS_LOCK:  # ``held`` keeps the identities in ``state`` from being reused
        _TABLES[key] = (weakref.ref(da, _forgetter(_TABLES, key)), state, held, sha)
    return sha


#: id(table) -> (weak reference, state when hashed, objects whose ids the state holds,
#: digest) for tables whose values are read-only (:func:`_table_sha`).
_TABLES: dict[int, tuple[weakref.ref, tuple, list, str]] = {}


class _Opaque(Exception):
    """A value :func:`_plain` cannot take an exact snapshot of."""


_PLAIN_SCALARS = (str, bytes, int, float, bool, type(None))


def _plain(v: Any) -> Any:
    """An immutable snapshot of an attribute value that compares equal exactly when the
    value is still the same (types included: ``1``, ``1.0`` and ``True`` differ)."""
    t = type(v)
    if t is str:  # the common case; a str equals only a str
        return v
    if t in _PLAIN_SCALARS:
        return (t, v)
    if isinstance(v, np.generic) and v.dtype.kind not in "OV":
        return (t, v.dtype.str, v.tobytes())
    if isinstance(v, np.ndarray) and v.dtype.kind not in "OV":
        return (np.ndarray, v.dtype.str, v.shape, v.tobytes())
    if isinstance(v, list | tuple):
        return (t, tuple(_plain(x) for x in v))
    if isinstance(v, Mapping):
        return (t, tuple((_plain(k), _plain(x)) for k, x in v.items()))
    raise _Opaque


def _table_state(da: Any) -> tuple[tuple, list] | None:
    """What :func:`_table_sha_now` reads from ``da``, cheaply, and the objects whose ids it
    holds; None unless the values are a read-only array (:func:`_read_only`).

    The values and any other coordinate count by identity and memory (read-only, so equal
    identity means equal values), index coordinates by identity (their values cannot be
    written in place), the dims and every attribute by an exact snapshot (:func:`_plain`).
    """
    values = getattr(getattr(da, "variable", None), "data", None)
    if not isinstance(values, np.ndarray) or not _read_only(values):
        return None
    held: list[Any] = [values]
    try:
        parts: list[Any] = [id(values), _layout(values), tuple(map(str, da.dims)), _plain(da.attrs)]
        for name, var in da.coords.variables.items():
            if isinstance(var, xr.IndexVariable):
                token: Any = id(var)
                held.append(var)
            else:
                data = var.data
                if not isinstance(data, np.ndarray) or not _read_only(data):
                    return None
                token = (id(data), _layout(data))
                held.append(data)
            parts.append((str(name), tuple(map(str, var.dims)), token, _plain(var.attrs)))
    except _Opaque:
        return None
    return tuple(parts), held


def _table_sha_now(da: Any) -> str:
    parts = [_array_sha(np.asarray(da.values)), _json(list(map(str, da.dims)))]
    for name in sorted(map(str, da.coords)):
        c = da.coords[name]
        parts += [
            name,
            _json(list(map(str, c.dims))),
            _array_sha(np.asarray(c.values)),
            _json(dict(c.attrs)),
        ]
    # when and by what a file was written says nothing about its values
    parts.append(_json({k: v for k, v in da.attrs.items() if k not in _VOLATILE_TABLE_ATTRS}))
    return _sha(*parts)


#: Table attributes that record when a file was written, not what it holds.
_VOLATILE_TABLE_ATTRS = frozenset(
    {"history", "date_created", "date_modified", "date_issued", "date_metadata_modified"}
)


def _attr_suffixes(names: list[str]) -> dict[str, str]:
    """Material name -> attribute-name suffix (letters, digits, underscores), collision-free."""
    clean = {n: re.sub(r"[^A-Za-z0-9_]", "_", n) or "_" for n in names}
    counts: dict[str, int] = {}
    for s in clean.values():
        counts[s] = counts.get(s, 0) + 1
    return {
        n: s if counts[s] == 1 else f"{s}_{hashlib.sha256(n.encode()).hexdigest()[:8]}"
        for n, s in clean.items()
    }


def _filters_sha(bands: Any) -> str:
    if not bands:
        return _sha("no bands")
    from ..photometry import filters

    f = filters(list(bands))
    return _sha(
        _array_sha(f.values),
        *(_array_sha(np.asarray(f[c].values)) for c in sorted(map(str, f.coords))),
    )


def _mesh_sha(spacecraft: Any) -> str:
    mesh = getattr(spacecraft, "mesh", None)
    if mesh is None:
        return _sha(f"{type(spacecraft).__name__}:{spacecraft!r}")
    parts = [
        _array_sha(np.asarray(mesh.vertices, dtype=np.float64)),
        _array_sha(np.asarray(mesh.faces, dtype=np.int64)),
        _array_sha(np.asarray(spacecraft.facet_material, dtype=str)),
    ]
    if getattr(spacecraft, "tangent_source", "default") != "default":
        # tangents other than the default (a function of the mesh) change anisotropic terms
        parts.append(_array_sha(np.asarray(spacecraft.facet_tangent, dtype=np.float64)))
    back = getattr(spacecraft, "facet_back", None)
    if back is not None:  # two-sided facets: their backs are terms of their own
        parts.append(_array_sha(np.asarray(back, dtype=str)))
    for p in getattr(spacecraft, "parts", ()):  # articulated parts: hinge and law
        parts.append(_sha(p.name, repr(p.law), _array_sha(np.asarray(p.facets, np.int64))))
        parts.append(_array_sha(np.concatenate([p.axis, p.point])))
    return _sha(*parts)


def scene_fingerprint(scene: SceneView) -> dict[str, str]:
    """Content fingerprint of a scene, as flat netCDF global attributes.

    Parameters
    ----------
    scene : sbrdf_xr.engine.Scene
        A validated scene.

    Returns
    -------
    dict of str to str
        Attribute name -> SHA-256 hex digest (and two JSON strings,
        ``fingerprint_material_names`` and ``fingerprint_knobs_json``); see the module
        documentation for the names.  Equal scenes give equal dicts; any change of a
        table value, coordinate or attribute, of the mesh, the materials map, the
        filters, a knob, the geometry or the package version changes ``fingerprint``
        and the part concerned.

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> scene = Scene(box, {"grey": grey}, attitudes=[[0, 0, 0, 1.0]], phase_angles=[0.0, 60.0])
    >>> from sbrdf_xr.engine.fingerprint import scene_fingerprint
    >>> fp = scene_fingerprint(scene)
    >>> list(fp)  # doctest: +NORMALIZE_WHITESPACE
    ['fingerprint', 'fingerprint_filters', 'fingerprint_geometry', 'fingerprint_knobs',
     'fingerprint_knobs_json', 'fingerprint_material_grey', 'fingerprint_material_names',
     'fingerprint_materials', 'fingerprint_mesh', 'fingerprint_package']
    >>> len(fp["fingerprint"]), fp["fingerprint_material_names"]  # SHA-256 hex digest
    (64, '{"grey": "grey"}')

    Values, not identities, are hashed: the same scene built again has the same print.

    >>> same = Scene(box, {"grey": grey}, attitudes=[[0, 0, 0, 1.0]], phase_angles=[0.0, 60.0])
    >>> scene_fingerprint(same) == fp
    True
    """
    materials = dict(scene.material_data)  # a table, or the model of a material without one
    names = sorted(materials)
    suffix = _attr_suffixes(names)
    out: dict[str, str] = {}
    for n in names:
        out[MATERIAL_PREFIX + suffix[n]] = _table_sha(materials[n])
    out[MATERIAL_NAMES] = json.dumps({suffix[n]: n for n in names}, sort_keys=True)
    out[f"{PREFIX}_materials"] = _sha(
        _json(
            {
                n: {
                    "material": materials[n].attrs.get("material"),
                    "source": materials[n].attrs.get("source"),
                    "name": getattr(materials[n], "name", None),
                }
                for n in names
            }
        )
    )
    out[f"{PREFIX}_mesh"] = _mesh_sha(scene.spacecraft)
    out[f"{PREFIX}_filters"] = _filters_sha(getattr(scene, "bands", ()))
    fields = [f.name for f in dataclasses.fields(scene)]
    knobs = {
        _FINGERPRINT_NAMES.get(f, f): getattr(scene, f)
        for f in fields
        if f not in _GEOMETRY_FIELDS + _OTHER_FIELDS
    }
    out[KNOBS_JSON] = _json(knobs)
    out[f"{PREFIX}_knobs"] = _sha(out[KNOBS_JSON])
    out[f"{PREFIX}_geometry"] = _sha(
        *(f"{f}={_json(getattr(scene, f, None))}" for f in _GEOMETRY_FIELDS)
    )
    out[f"{PREFIX}_package"] = _sha(f"sbrdf_xr {__version__}")
    out[PREFIX] = _sha(*(f"{k}={v}" for k, v in sorted(out.items())))
    return {PREFIX: out.pop(PREFIX), **dict(sorted(out.items()))}
