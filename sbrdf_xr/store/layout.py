"""The block layout of a cube and its structure fingerprint (metadata only, nothing computed).

:func:`layout_of` validates a Dataset for :func:`sbrdf_xr.store.writer.write_cube` and lays
out its *blocks*: one chunk of every chunked dimension, numbered in C order over the
grid of chunks, with the lazy variables that fall in each.  Its ``structure`` record
(dims and sizes, chunks of the block dimensions, every variable's dims, dtype,
attributes, laziness and a SHA-256 of every numpy-backed variable's values, global
attributes except :data:`VOLATILE_ATTRS`) is hashed into the ``fingerprint`` that a
resume must match; :func:`difference` says in words what changed between two records.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
from collections.abc import Hashable, Mapping
from typing import Any

import dask.array as da
import numpy as np
import xarray as xr

from ..errors import ValidationError
from . import fingerprint as _fingerprint

__all__ = [
    "NUMERIC_KINDS",
    "VOLATILE_ATTRS",
    "BlockLayout",
    "LazyVariable",
    "attr_json",
    "block_bytes",
    "check_attrs",
    "describe_chunks",
    "difference",
    "encode_times",
    "layout_of",
    "storage_kind",
    "values_sha",
]

#: Global attributes that may change between an interrupted run and its resume.
VOLATILE_ATTRS = frozenset(
    {"history", "date_created", "date_modified", "date_issued", "date_metadata_modified"}
)

NUMERIC_KINDS = "iuf"


@dataclasses.dataclass
class LazyVariable:
    """A Dask-backed variable of a cube: its name, its dims and the Dask array the blocks write.

    Examples
    --------
    >>> import dask.array as da
    >>> import xarray as xr
    >>> from sbrdf_xr.store.layout import layout_of
    >>> ds = xr.Dataset(
    ...     {"v": (("x", "y"), da.zeros((4, 3), chunks=(2, 3))), "w": ("x", [1.0, 2.0, 3.0, 4.0])}
    ... )
    >>> [(lv.name, lv.dims, lv.data.chunks) for lv in layout_of(ds).lazy]  # w is numpy-backed
    [('v', ('x', 'y'), ((2, 2), (3,)))]
    """

    name: str
    dims: tuple[str, ...]
    data: da.Array


@dataclasses.dataclass
class BlockLayout:
    """Blocks of a cube and its fingerprint (built from metadata only).

    Examples
    --------
    A cube chunked in two along ``x`` has two blocks; block 1 is the second ``x`` chunk,
    and every lazy variable with a piece in it is written with it.

    >>> import dask.array as da
    >>> import xarray as xr
    >>> from sbrdf_xr.store.layout import layout_of
    >>> ds = xr.Dataset(
    ...     {
    ...         "v": (("x", "y"), da.zeros((4, 3), chunks=(2, 3))),
    ...         "w": ("x", da.ones(4, chunks=2)),
    ...     },
    ...     coords={"x": [0.0, 1.0, 2.0, 3.0]},
    ... )
    >>> plan = layout_of(ds)
    >>> plan.block_dims, plan.grid, plan.n_blocks
    (('x', 'y'), (2, 1), 2)
    >>> plan.index(1)
    {'x': 1, 'y': 0}
    >>> plan.slices(1)
    {'x': slice(2, 4, None), 'y': slice(0, 3, None)}
    >>> for name, region, key in plan.pieces(1):
    ...     print(name, region, key[1:])
    v (slice(2, 4, None), slice(0, 3, None)) (1, 0)
    w (slice(2, 4, None),) (1,)
    """

    block_dims: tuple[str, ...]
    chunks: dict[str, tuple[int, ...]]
    offsets: dict[str, np.ndarray]
    grid: tuple[int, ...]
    lazy: list[LazyVariable]
    structure: dict[str, Any]
    fingerprint: str
    _graph: dict[Any, Any] | None = None

    @property
    def n_blocks(self) -> int:
        return math.prod(self.grid) if self.block_dims else 0

    def index(self, k: int) -> dict[str, int]:
        idx = (int(i) for i in np.unravel_index(k, self.grid))
        return dict(zip(self.block_dims, idx, strict=True))

    def slices(self, k: int) -> dict[str, slice]:
        idx = self.index(k)
        off = self.offsets
        return {d: slice(int(off[d][i]), int(off[d][i + 1])) for d, i in idx.items()}

    def pieces(self, k: int) -> list[tuple[str, tuple[slice, ...], Any]]:
        """``(variable, region, Dask key)`` for every lazy variable written with block ``k``."""
        idx = self.index(k)
        sl = self.slices(k)
        out = []
        for v in self.lazy:
            if any(idx[d] for d in self.block_dims if d not in v.dims):
                continue
            key = (v.data.name, *(idx[d] for d in v.dims))
            out.append((v.name, tuple(sl[d] for d in v.dims), key))
        return out

    def task(self, k: int, keys: list[Any]) -> tuple[dict[Any, Any], Any]:
        """The part of the cube's graph that block ``k`` needs, and the key of a task
        that packs its pieces into a tuple.

        The whole graph is materialised once; each block then takes only the tasks its
        keys depend on (culling walks the block's own dependencies), so the cost of a
        block does not grow with the number of blocks.
        """
        if self._graph is None:
            from dask.highlevelgraph import HighLevelGraph

            self._graph = dict(HighLevelGraph.merge(*[v.data.__dask_graph__() for v in self.lazy]))
        from dask.optimization import cull

        sub, _ = cull(self._graph, keys)
        out = f"write_cube-block-{k}-{self.fingerprint[:16]}"
        sub[out] = (tuple, list(keys))
        return sub, out


def encode_times(cube: xr.Dataset) -> xr.Dataset:
    """``cube`` with its datetime64 coordinates as CF numbers with ``units`` and ``calendar``.

    xarray's own encoder, the one :func:`xarray.open_dataset` decodes; the netCDF writer
    stores numbers, and the block layout (and fingerprint) of either format is taken
    from the encoded cube.

    Examples
    --------
    >>> import numpy as np
    >>> import xarray as xr
    >>> from sbrdf_xr.store.layout import encode_times
    >>> times = np.array(["2026-01-01T00:00", "2026-01-01T00:01"], dtype="datetime64[ns]")
    >>> cube = xr.Dataset({"v": ("time", [1.0, 2.0])}, coords={"time": times})
    >>> enc = encode_times(cube)
    >>> enc.time.values.tolist(), enc.time.attrs["units"]
    ([0, 1], 'minutes since 2026-01-01 00:00:00')
    >>> xr.decode_cf(enc).time.values.tolist() == cube.time.values.tolist()
    True
    """
    times = [k for k, v in cube.coords.items() if v.dtype.kind in "mM"]
    if not times:
        return cube
    encoded = {}
    for k in times:
        v = xr.conventions.encode_cf_variable(cube[k].variable, name=str(k))
        v.attrs.pop("_FillValue", None)  # CF 2.5.1: no fill value on a coordinate variable
        encoded[k] = v
    return cube.assign_coords(encoded)


def storage_kind(name: Hashable, dtype: np.dtype) -> str:
    """``numeric``, ``bool`` or ``str``; anything else is an error.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.store.layout import storage_kind
    >>> [storage_kind("v", np.dtype(t)) for t in ("float32", "int16", "bool", "U8", "O")]
    ['numeric', 'numeric', 'bool', 'str', 'str']
    >>> storage_kind("v", np.dtype("float16"))
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.ValidationError: v: dtype float16 cannot be stored in netCDF; cast to float32
    >>> try:
    ...     storage_kind("t", np.dtype("datetime64[ns]"))
    ... except ValueError as exc:
    ...     print(exc)
    t: dtype datetime64[ns] is not supported by write_cube (allowed: integers, float32, float64,
    bool, str); encode times as numbers with CF units first
    """
    if dtype.kind in NUMERIC_KINDS and dtype.itemsize in (1, 2, 4, 8):
        if dtype.kind == "f" and dtype.itemsize < 4:
            raise ValidationError(
                f"{name}: dtype {dtype} cannot be stored in netCDF; cast to float32"
            )
        return "numeric"
    if dtype.kind == "b":
        return "bool"
    if dtype.kind in "UO":
        return "str"
    hint = "; encode times as numbers with CF units first" if dtype.kind in "mM" else ""
    raise ValidationError(
        f"{name}: dtype {dtype} is not supported by write_cube "
        f"(allowed: integers, float32, float64, bool, str){hint}"
    )


def attr_json(value: Any) -> Any:
    """An attribute value as JSON can hold it, numpy values tagged with their dtype.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.store.layout import attr_json
    >>> attr_json(np.array([1.0, 2.0]))
    {'array': [1.0, 2.0], 'dtype': 'float64'}
    >>> attr_json(np.float32(0.5))
    {'scalar': 0.5, 'dtype': 'float32'}
    >>> attr_json(("nm", np.int64(3))), attr_json("sr-1")
    (['nm', {'scalar': 3, 'dtype': 'int64'}], 'sr-1')
    """
    if isinstance(value, np.ndarray):
        return {"array": value.tolist(), "dtype": str(value.dtype)}
    if isinstance(value, np.generic):
        return {"scalar": value.item(), "dtype": str(value.dtype)}
    if isinstance(value, list | tuple):
        return [attr_json(x) for x in value]
    return value


def check_attrs(owner: str, attrs: Mapping[Any, Any]) -> None:
    """Raise :class:`~sbrdf_xr.errors.ValidationError` for an attribute netCDF cannot store.

    Examples
    --------
    >>> from sbrdf_xr.store.layout import check_attrs
    >>> check_attrs("variable 'v'", {"units": "nm", "valid_range": (0.0, 1.0)}) is None
    True
    >>> check_attrs("variable 'v'", {"masked": True})
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.ValidationError: variable 'v': attribute 'masked' = True cannot be stored in
    netCDF (allowed: str, numbers, sequences of them); convert it, e.g. to str
    >>> check_attrs("global attributes", {"coordinates": "x"})
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.ValidationError: global attributes: attribute 'coordinates' is written by
    write_cube itself; remove it
    """
    for key, value in attrs.items():
        if not isinstance(key, str):
            raise ValidationError(f"{owner}: attribute names must be str, got {key!r}")
        if key == "coordinates":
            raise ValidationError(
                f"{owner}: attribute 'coordinates' is written by write_cube itself; remove it"
            )
        items = value if isinstance(value, list | tuple) else [value]
        for item in items:
            if isinstance(item, bool | np.bool_) or not isinstance(
                item, str | int | float | np.number | np.ndarray
            ):
                raise ValidationError(
                    f"{owner}: attribute {key!r} = {value!r} cannot be stored in netCDF "
                    f"(allowed: str, numbers, sequences of them); convert it, e.g. to str"
                )


def values_sha(values: np.ndarray, kind: str) -> str:
    """SHA-256 hex digest of an array's values (and dtype, unless ``kind`` is ``str``).

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.store.layout import values_sha
    >>> a = np.arange(3.0)
    >>> len(values_sha(a, "numeric")), values_sha(a, "numeric") == values_sha(a.copy(), "numeric")
    (64, True)
    >>> values_sha(a, "numeric") == values_sha(a.astype(np.float32), "numeric")  # dtype counts
    False
    >>> words = ["r", "g"]
    >>> values_sha(np.array(words), "str") == values_sha(np.array(words, dtype=object), "str")
    True
    """
    h = hashlib.sha256()
    if kind == "str":
        h.update(json.dumps([str(x) for x in values.ravel().tolist()]).encode())
    else:
        h.update(str(values.dtype).encode())
        h.update(np.ascontiguousarray(values).data)  # the buffer itself, not a copy
    return h.hexdigest()


def layout_of(ds: xr.Dataset) -> BlockLayout:
    """Validate ``ds`` (metadata only, nothing is computed) and lay out its blocks.

    Examples
    --------
    >>> import dask.array as da
    >>> import xarray as xr
    >>> from sbrdf_xr.store.layout import layout_of
    >>> ds = xr.Dataset(
    ...     {"v": (("x", "y"), da.zeros((4, 3), chunks=(2, 3)))},
    ...     coords={"x": [0.0, 1.0, 2.0, 3.0]},
    ...     attrs={"title": "demo", "history": "written today"},
    ... )
    >>> plan = layout_of(ds)
    >>> plan.block_dims, plan.chunks, plan.n_blocks
    (('x', 'y'), {'x': (2, 2), 'y': (3,)}, 2)
    >>> len(plan.fingerprint), sorted(plan.structure["attrs"])  # history is volatile
    (64, ['title'])

    The fingerprint follows the values of the numpy-backed variables, not the volatile
    attributes:

    >>> layout_of(ds.assign_attrs(history="resumed")).fingerprint == plan.fingerprint
    True
    >>> layout_of(ds.assign_coords(x=[0.0, 1.0, 2.0, 4.0])).fingerprint == plan.fingerprint
    False
    >>> layout_of(ds.isel(x=slice(0, 0)))
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.ValidationError: ds: the cube is empty along x (size 0); there is nothing to
    write
    """
    if not isinstance(ds, xr.Dataset):
        raise ValidationError(f"ds: expected an xarray.Dataset, got {type(ds).__name__}")
    try:
        chunks = {str(d): tuple(int(c) for c in cs) for d, cs in ds.chunks.items()}
    except ValueError as exc:
        raise ValidationError(
            f"ds: the variables are chunked differently ({exc}); call ds.unify_chunks() "
            "or rechunk them alike"
        ) from exc
    check_attrs("global attributes", ds.attrs)
    if not ds.data_vars:
        raise ValidationError("ds: the cube has no data variables; there is nothing to write")
    empty = [f"{d!s} (size 0)" for d, n in ds.sizes.items() if n == 0]
    if empty:
        raise ValidationError(
            f"ds: the cube is empty along {', '.join(empty)}; there is nothing to write"
        )
    lazy: list[LazyVariable] = []
    variables: list[dict[str, Any]] = []
    for name, var in ds.variables.items():
        if not isinstance(name, str) or any(c.isspace() for c in name):
            raise ValidationError(f"{name!r}: variable names must be str without whitespace")
        kind = storage_kind(name, var.dtype)
        check_attrs(f"variable {name!r}", var.attrs)
        if kind == "bool" and "dtype" in var.attrs:
            raise ValidationError(f"{name}: a bool variable cannot carry a 'dtype' attribute")
        is_dask = isinstance(var.data, da.Array)
        if var.chunks is not None and not is_dask:
            raise ValidationError(
                f"{name}: chunked by {type(var.data).__name__}; only Dask arrays are supported"
            )
        entry: dict[str, Any] = {
            "name": name,
            "dims": list(map(str, var.dims)),
            "dtype": str(var.dtype) if kind == "numeric" else kind,
            "coord": name in ds.coords,
            "lazy": is_dask,
            "attrs": {k: attr_json(v) for k, v in var.attrs.items()},
        }
        if is_dask:
            lazy.append(LazyVariable(name, tuple(map(str, var.dims)), var.data))
        else:
            values = np.asarray(var.values)
            if values.dtype.kind == "O" and not all(isinstance(x, str) for x in values.flat):
                raise ValidationError(f"{name}: object arrays must hold str only")
            entry["sha256"] = values_sha(values, kind)
        variables.append(entry)
    block_dims = tuple(str(d) for d in ds.sizes if str(d) in chunks)
    structure = {
        "dims": [[str(d), int(n)] for d, n in ds.sizes.items()],
        "chunks": [[d, list(chunks[d])] for d in block_dims],  # in block-numbering order
        "variables": sorted(variables, key=lambda v: v["name"]),
        "attrs": {k: attr_json(v) for k, v in ds.attrs.items() if k not in VOLATILE_ATTRS},
    }
    text = json.dumps(structure, sort_keys=True, allow_nan=True, separators=(",", ":"))
    return BlockLayout(
        block_dims=block_dims,
        chunks={d: chunks[d] for d in block_dims},
        offsets={d: np.concatenate([[0], np.cumsum(chunks[d])]) for d in block_dims},
        grid=tuple(len(chunks[d]) for d in block_dims),
        lazy=lazy,
        structure=structure,
        fingerprint=hashlib.sha256(text.encode()).hexdigest(),
    )


def difference(old: Mapping[str, Any], new: Mapping[str, Any]) -> str:
    """First difference between two ``structure`` records, in words.

    Differences of the content fingerprint (:mod:`sbrdf_xr.store.fingerprint`) come first,
    naming every part that changed (a material table, the mesh, a setting, ...).

    Examples
    --------
    >>> import dask.array as da
    >>> import xarray as xr
    >>> from sbrdf_xr.store.layout import difference, layout_of
    >>> ds = xr.Dataset(
    ...     {"v": (("x", "y"), da.zeros((4, 3), chunks=(2, 3)))},
    ...     coords={"x": [0.0, 1.0, 2.0, 3.0]},
    ... )
    >>> old = layout_of(ds).structure
    >>> difference(old, layout_of(ds.assign_coords(x=[0.0, 1.0, 2.0, 4.0])).structure)
    "values of 'x' differ"
    >>> difference(old, layout_of(ds.chunk(x=1)).structure)
    "chunks differ: [['x', [2, 2]], ['y', [3]]] in the .part, [['x', [1, 1, 1, 1]], ['y', [3]]] now"
    >>> difference(old, layout_of(ds.isel(x=slice(0, 2))).structure)
    "dims and sizes differ: [['x', 4], ['y', 3]] in the .part, [['x', 2], ['y', 3]] now"

    Equal records leave the version of the file format as the difference:

    >>> difference(old, old)
    'the file format version differs'
    """
    new = json.loads(json.dumps(new))  # compare like with like (tuples become lists)
    changed = _fingerprint.changes(old.get("attrs", {}), new.get("attrs", {}))
    if changed:
        return "; ".join(changed)
    if old.get("dims") != new.get("dims"):
        return f"dims and sizes differ: {old.get('dims')} in the .part, {new.get('dims')} now"
    if old.get("chunks") != new.get("chunks"):
        return f"chunks differ: {old.get('chunks')} in the .part, {new.get('chunks')} now"
    ov = {v["name"]: v for v in old.get("variables", [])}
    nv = {v["name"]: v for v in new.get("variables", [])}
    if set(ov) != set(nv):
        return f"variables differ: {sorted(ov)} in the .part, {sorted(nv)} now"
    for name in nv:
        for key in ("dims", "dtype", "coord", "lazy", "sha256", "attrs"):
            if ov[name].get(key) != nv[name].get(key):
                what = "values" if key == "sha256" else key
                return f"{what} of {name!r} differ"
    oa, na = old.get("attrs", {}), new.get("attrs", {})
    keys = sorted(k for k in set(oa) | set(na) if oa.get(k) != na.get(k))
    if keys:
        plural = "s" if len(keys) > 1 else ""
        return f"global attribute{plural} {', '.join(map(repr, keys[:5]))} differ"
    return "the file format version differs"


def describe_chunks(chunks: list[list[Any]]) -> str:
    """The ``chunks`` of a ``structure`` record in words: the block size along every
    dimension cut into more than one chunk.

    Examples
    --------
    >>> from sbrdf_xr.store.layout import describe_chunks
    >>> describe_chunks([["attitude", [2, 2, 1]], ["phase_angle", [4]], ["wavelength", [71]]])
    'chunks of attitude 2'
    >>> describe_chunks([["attitude", [5]]])
    'one block'
    """
    cut = [f"{d} {c[0]}" for d, c in chunks if len(c) > 1]
    return f"chunks of {', '.join(cut)}" if cut else "one block"


def lazy_bytes(plan: BlockLayout) -> int:
    """Raw size of all the lazy variables [byte] (the blocks' share of the file)."""
    return sum(math.prod(v.data.shape) * v.data.dtype.itemsize for v in plan.lazy)


def block_bytes(plan: BlockLayout) -> int:
    """Largest raw size of one block [byte] (what a block may add to the file, uncompressed).

    Examples
    --------
    One block of this cube holds a 2 x 3 float64 piece of ``v`` and 2 float32 values of
    ``w``: 2 * 3 * 8 + 2 * 4 = 56 bytes.

    >>> import dask.array as da
    >>> import xarray as xr
    >>> from sbrdf_xr.store.layout import block_bytes, layout_of
    >>> ds = xr.Dataset(
    ...     {
    ...         "v": (("x", "y"), da.zeros((4, 3), chunks=(2, 3))),
    ...         "w": ("x", da.ones(4, chunks=2, dtype="float32")),
    ...     }
    ... )
    >>> block_bytes(layout_of(ds))
    56
    """
    total = 0
    for v in plan.lazy:
        shape = [
            max(plan.chunks[d]) if d in plan.chunks else n
            for d, n in zip(v.dims, v.data.shape, strict=True)
        ]
        total += math.prod(shape) * v.data.dtype.itemsize
    return total
