"""Stream a lazy cube to netCDF block by block: bounded memory, atomic, resumable.

:func:`write_cube` computes a Dask-backed :class:`xarray.Dataset` one *block* at a
time and writes each block into a netCDF-4 file as soon as it arrives, so peak
memory is set by the chunk size and ``max_in_flight``, never by the cube size.

Blocks
    A block is one chunk of every chunked dimension of the Dataset (for a
    spectral cube: one ``attitude`` x ``phase_angle`` chunk, or one ``geometry``
    chunk, the spectral dimension being a single chunk), with all the lazy
    variables that fall in it.  Blocks are numbered in C order over the grid of
    chunks.  A lazy variable that lacks one of the chunked dimensions is written
    with the block whose index along that dimension is 0.

Atomicity
    Everything is written to ``<path>.part`` in the same directory, which is
    renamed (:func:`os.replace`) to ``path`` only after every block is written,
    flushed and ``fsync``-ed.  A cube is never half-written under its final name,
    and with ``overwrite=True`` the old file stays intact until the new one is
    complete.  Only regular files are ever replaced: a FIFO, symbolic link, device
    node or directory at ``path`` or at the ``.part`` is refused, overwrite or not.

Lock (``<path>.lock``)
    One writer per path: the lock file is created atomically (``O_CREAT |
    O_EXCL``), holds the writer's pid, host and start time, and carries a ``flock``
    for the life of the write; it is removed on every way out (success, error,
    interrupt).  A second writer gets :class:`CubeLockedError` naming the holder.
    A lock left by a writer that died on this host (its pid gone, its ``flock``
    released by the kernel) is stale: it is removed with a logged message and the
    write proceeds.  A lock from another host is never removed automatically.

Durability
    A block is reported (``on_block``, the sidecar) only after its data were
    written, the file flushed (``nc.sync``) and ``fsync``-ed.  Before each block
    the room it needs is checked (free space, ``RLIMIT_FSIZE``) and reserved
    (``fallocate`` past the end of the file, where supported), so that a full disk
    or a file-size limit stops the write *before* HDF5 writes anything: the
    ``.part`` stays exactly as last synced and the error names the cause ("no
    space left on device", "file size limit exceeded").  Should HDF5's own write
    fail anyway, HDF5's descriptor is made read-only (nothing more reaches the
    file) and the file is cut back to its last synced size and superblock; if it
    then does not open, the message says that the ``.part`` was lost.

Bookkeeping (``<path>.part.jsonl``)
    A sidecar JSON-lines file next to the ``.part``.  Line 1 is a header object::

        {"format": "sbrdf_xr.write_cube", "version": 1, "fingerprint": "<sha256>",
         "n_blocks": 24, "block_dims": ["attitude", "phase_angle"],
         "structure": {...}}

    where ``structure`` describes the cube (dims and sizes, chunks of the block
    dimensions, every variable's dims, dtype, attributes, laziness, and a SHA-256
    of the values of every numpy-backed variable, global attributes except the
    volatile ones in :data:`VOLATILE_ATTRS`) and ``fingerprint`` is the SHA-256
    of its canonical JSON.  Every following line is ``{"block": k}``, appended
    and ``fsync``-ed only after block ``k``'s data were written to the ``.part``
    and flushed to disk; a torn last line (a crash mid-append) is ignored.  The
    final netCDF file therefore carries no bookkeeping at all; the sidecar is
    deleted after the rename.  (netCDF cannot delete a variable, so a
    ``_block_done`` variable could not be removed without copying the cube.)

Resume
    ``resume=True`` with an existing ``.part`` checks that the header's
    fingerprint equals the fingerprint of ``ds`` (same dims, sizes, chunking,
    variables, dtypes, attributes and coordinate values) and then computes only
    the blocks not listed.  The lazy values themselves are not hashed (that would
    need computing them); instead cubes of :func:`sbrdf_xr.simulate.simulate`
    carry the content fingerprint of their scene (:mod:`sbrdf_xr.fingerprint`:
    table values, mesh, materials map, filters, settings, geometry, version) in
    their global attributes, so a resume with other inputs is refused with a
    message naming what changed.  ``resume=True`` with a finished ``path`` and no
    ``.part`` checks that it is the same cube and does nothing.  Global attributes in
    :data:`VOLATILE_ATTRS` (``history`` and the ACDD dates) may change between
    runs; they are rewritten from ``ds`` on resume.

Schedulers
    By default blocks are computed in-process by a pool of threads (Dask's
    synchronous scheduler within each block, ``dask.config`` ``num_workers`` or
    the CPU count blocks at a time).  With ``client`` (a
    :class:`distributed.Client`) or ``scheduler`` (an address), each block is
    submitted to the cluster with :meth:`~distributed.Client.compute` and the
    results are gathered, as they complete, by the calling process, which is the
    only writer.  A lost worker's tasks are recomputed by Dask; a block is
    written exactly once (the writer skips blocks already recorded).

Encoding
    Variables are stored in their in-memory dtype with no fill value and no
    packing (``encoding`` set on the variables is ignored); ``bool`` is stored as
    ``int8`` with the attribute ``dtype = "bool"`` and strings as variable-length
    strings, as xarray does, so that :func:`xarray.open_dataset` gives back the
    Dataset with identical values and attributes.  Non-dimension coordinates are
    listed in ``coordinates`` attributes (per variable, or global for those that
    belong to no variable), as xarray writes them.
"""

from __future__ import annotations

import contextlib
import dataclasses
import errno
import hashlib
import json
import math
import os
import stat
import sys
import time
from collections.abc import Callable, Hashable, Mapping
from pathlib import Path
from typing import Any

import dask.array as da
import netCDF4
import numpy as np
import xarray as xr

from . import fingerprint as _fingerprint
from ._lock import (
    _Lock,
)
from ._runners import (
    _check_address,
    _runner,
    connect,
)
from ._write_common import (
    _SPACE_MARGIN,
    _SYNC_NAMES,
    _THREAD_NAMES,
    LOCK_SUFFIX,
    LOG_SUFFIX,
    PART_SUFFIX,
    BlockWritten,
    CubeLockedError,
    CubeWriteError,
    SchedulerError,
    _again,
    _discard,
    _file_size_limit,
    _fix,
    _log,
    _mib,
    _NoRoom,
    _opt,
    _reason,
    command_line_messages,
)
from .errors import SbrdfError, ValidationError

__all__ = [
    "LOCK_SUFFIX",
    "LOG_SUFFIX",
    "PART_SUFFIX",
    "VOLATILE_ATTRS",
    "BlockWritten",
    "CubeLockedError",
    "CubeWriteError",
    "SchedulerError",
    "command_line_messages",
    "connect",
    "write_cube",
]


#: Global attributes that may change between an interrupted run and its resume.
VOLATILE_ATTRS = frozenset(
    {"history", "date_created", "date_modified", "date_issued", "date_metadata_modified"}
)

_FORMAT = "sbrdf_xr.write_cube"
_FORMAT_VERSION = 1
#: Largest HDF5 chunk of a streamed variable [byte]; larger Dask chunks are split.
#: Chunks of 1-2 MiB write about twice as fast as 4-8 MiB ones through netCDF-4/HDF5
#: (measured on this package's sweeps) and keep a one-chunk cache small.
_HDF5_CHUNK_BYTES = 2 * 2**20
_NUMERIC_KINDS = "iuf"


#: Whether each block's room on the file system is checked before it is written.
_CHECK_SPACE = True
#: Bytes at the start of a ``.part`` (the HDF5 superblock) saved after each sync.
_HEAD_BYTES = 4096


# ------------------------------------------------------------------ planning


@dataclasses.dataclass
class _Lazy:
    name: str
    dims: tuple[str, ...]
    data: da.Array


@dataclasses.dataclass
class _Plan:
    """Blocks of a cube and its fingerprint (built from metadata only)."""

    block_dims: tuple[str, ...]
    chunks: dict[str, tuple[int, ...]]
    offsets: dict[str, np.ndarray]
    grid: tuple[int, ...]
    lazy: list[_Lazy]
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


def _storage_kind(name: Hashable, dtype: np.dtype) -> str:
    """``numeric``, ``bool`` or ``str``; anything else is an error."""
    if dtype.kind in _NUMERIC_KINDS and dtype.itemsize in (1, 2, 4, 8):
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


def _attr_json(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return {"array": value.tolist(), "dtype": str(value.dtype)}
    if isinstance(value, np.generic):
        return {"scalar": value.item(), "dtype": str(value.dtype)}
    if isinstance(value, list | tuple):
        return [_attr_json(x) for x in value]
    return value


def _check_attrs(owner: str, attrs: Mapping[Any, Any]) -> None:
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


def _values_sha(values: np.ndarray, kind: str) -> str:
    h = hashlib.sha256()
    if kind == "str":
        h.update(json.dumps([str(x) for x in values.ravel().tolist()]).encode())
    else:
        h.update(str(values.dtype).encode())
        h.update(np.ascontiguousarray(values).tobytes())
    return h.hexdigest()


def _plan(ds: xr.Dataset) -> _Plan:
    """Validate ``ds`` (metadata only, nothing is computed) and lay out its blocks."""
    if not isinstance(ds, xr.Dataset):
        raise ValidationError(f"ds: expected an xarray.Dataset, got {type(ds).__name__}")
    try:
        chunks = {str(d): tuple(int(c) for c in cs) for d, cs in ds.chunks.items()}
    except ValueError as exc:
        raise ValidationError(
            f"ds: the variables are chunked differently ({exc}); call ds.unify_chunks() "
            "or rechunk them alike"
        ) from exc
    _check_attrs("global attributes", ds.attrs)
    if not ds.data_vars:
        raise ValidationError("ds: the cube has no data variables; there is nothing to write")
    empty = [f"{d!s} (size 0)" for d, n in ds.sizes.items() if n == 0]
    if empty:
        raise ValidationError(
            f"ds: the cube is empty along {', '.join(empty)}; there is nothing to write"
        )
    lazy: list[_Lazy] = []
    variables: list[dict[str, Any]] = []
    for name, var in ds.variables.items():
        if not isinstance(name, str) or any(c.isspace() for c in name):
            raise ValidationError(f"{name!r}: variable names must be str without whitespace")
        kind = _storage_kind(name, var.dtype)
        _check_attrs(f"variable {name!r}", var.attrs)
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
            "attrs": {k: _attr_json(v) for k, v in var.attrs.items()},
        }
        if is_dask:
            lazy.append(_Lazy(name, tuple(map(str, var.dims)), var.data))
        else:
            values = np.asarray(var.values)
            if values.dtype.kind == "O" and not all(isinstance(x, str) for x in values.flat):
                raise ValidationError(f"{name}: object arrays must hold str only")
            entry["sha256"] = _values_sha(values, kind)
        variables.append(entry)
    block_dims = tuple(str(d) for d in ds.sizes if str(d) in chunks)
    structure = {
        "dims": [[str(d), int(n)] for d, n in ds.sizes.items()],
        "chunks": [[d, list(chunks[d])] for d in block_dims],  # in block-numbering order
        "variables": sorted(variables, key=lambda v: v["name"]),
        "attrs": {k: _attr_json(v) for k, v in ds.attrs.items() if k not in VOLATILE_ATTRS},
    }
    text = json.dumps(structure, sort_keys=True, allow_nan=True, separators=(",", ":"))
    return _Plan(
        block_dims=block_dims,
        chunks={d: chunks[d] for d in block_dims},
        offsets={d: np.concatenate([[0], np.cumsum(chunks[d])]) for d in block_dims},
        grid=tuple(len(chunks[d]) for d in block_dims),
        lazy=lazy,
        structure=structure,
        fingerprint=hashlib.sha256(text.encode()).hexdigest(),
    )


def _difference(old: Mapping[str, Any], new: Mapping[str, Any]) -> str:
    """First difference between two ``structure`` records, in words.

    Differences of the content fingerprint (:mod:`sbrdf_xr.fingerprint`) come first,
    naming every part that changed (a material table, the mesh, a setting, ...).
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


# ------------------------------------------------------------------- netCDF


def _coordinates_attrs(ds: xr.Dataset) -> tuple[dict[str, str], str | None]:
    """Per-variable and global ``coordinates`` attributes, as xarray writes them."""
    non_dim = {str(c) for c in ds.coords if c not in ds.dims}
    per_var: dict[str, set[str]] = {str(n): set() for n in ds.variables}
    for c in non_dim:
        target = set(ds.variables[c].dims)
        for name, var in ds.variables.items():
            if name not in non_dim and name not in var.dims and target <= set(var.dims):
                per_var[str(name)].add(c)
    attached = set().union(*per_var.values()) if per_var else set()
    leftover = non_dim - attached
    return (
        {n: " ".join(sorted(cs)) for n, cs in per_var.items() if cs},
        " ".join(sorted(leftover)) if leftover else None,
    )


def _nc_attr(value: Any) -> Any:
    if isinstance(value, list | tuple) and value and all(isinstance(x, str) for x in value):
        return list(value)
    if isinstance(value, list | tuple):
        return np.asarray(value)
    return value


def _set_attrs(target: Any, attrs: Mapping[str, Any]) -> None:
    for key, value in attrs.items():
        target.setncattr(key, _nc_attr(value))


def _to_storage(values: Any, kind: str) -> np.ndarray:
    arr = np.asarray(values)
    if kind == "bool":
        return arr.astype(np.int8)
    if kind == "str":
        out = np.empty(arr.shape, dtype=object)
        out[...] = arr.astype(str) if arr.dtype.kind != "O" else arr
        return out
    if not arr.dtype.isnative:
        arr = arr.astype(arr.dtype.newbyteorder("="))
    return arr


def _hdf5_chunks(shape: tuple[int, ...], itemsize: int) -> list[int] | None:
    """HDF5 chunk shape for a streamed variable: its Dask chunk, halved until small."""
    if not shape or 0 in shape:
        return None
    c = list(shape)
    while math.prod(c) * itemsize > _HDF5_CHUNK_BYTES and max(c) > 1:
        i = int(np.argmax(c))
        c[i] = -(-c[i] // 2)
    return c


def _tune(v: netCDF4.Variable, streamed: bool) -> None:
    """Raw values in and out; a chunk cache of one chunk for streamed variables.

    netCDF's default cache (64 MiB per variable) would hold on to written chunks
    and make memory grow with the number of variables rather than the block size.
    Blocks cover whole HDF5 chunks except at irregular chunk edges, so one chunk
    of cache is enough.
    """
    v.set_auto_maskandscale(False)
    chunking = v.chunking()
    if streamed and isinstance(chunking, list):
        nbytes = math.prod(chunking) * v.dtype.itemsize if isinstance(v.dtype, np.dtype) else 0
        v.set_var_chunk_cache(size=max(nbytes, 2**20), nelems=101, preemption=1.0)


def _create(part: Path, ds: xr.Dataset, plan: _Plan, complevel: int) -> netCDF4.Dataset:
    """Create ``part`` with every dim, variable and attribute; write the numpy-backed values."""
    coords_attr, global_coords = _coordinates_attrs(ds)
    nc = netCDF4.Dataset(part, mode="w", format="NETCDF4")
    try:
        for dim, size in ds.sizes.items():
            nc.createDimension(str(dim), int(size))
        lazy = {v.name for v in plan.lazy}
        for name, var in ds.variables.items():
            name = str(name)
            kind = _storage_kind(name, var.dtype)
            dtype: Any = {"bool": np.int8, "str": str}.get(kind, var.dtype.newbyteorder("="))
            kw: dict[str, Any] = {}
            if name in lazy and kind != "str":
                shape = tuple(max(plan.chunks[d]) for d in map(str, var.dims))
                kw["chunksizes"] = _hdf5_chunks(shape, np.dtype(dtype).itemsize)
            if complevel and kind == "numeric" and var.ndim:
                kw.update(zlib=True, complevel=int(complevel), shuffle=True)
            attrs = dict(var.attrs)
            fill = attrs.pop("_FillValue", False)
            v = nc.createVariable(name, dtype, tuple(map(str, var.dims)), fill_value=fill, **kw)
            _tune(v, name in lazy)
            if kind == "bool":
                attrs["dtype"] = "bool"
            if name in coords_attr:
                attrs["coordinates"] = coords_attr[name]
            _set_attrs(v, attrs)
            if name not in lazy:
                v[...] = _to_storage(var.values, kind)
        _set_global_attrs(nc, ds, global_coords)
        nc.sync()
    except BaseException:
        nc.close()
        raise
    return nc


def _set_global_attrs(nc: netCDF4.Dataset, ds: xr.Dataset, global_coords: str | None) -> None:
    for key in nc.ncattrs():
        nc.delncattr(key)
    attrs = dict(ds.attrs)
    if global_coords:
        attrs["coordinates"] = global_coords
    _set_attrs(nc, attrs)


def _open_part(part: Path, ds: xr.Dataset, plan: _Plan) -> netCDF4.Dataset:
    """Open an unfinished ``part`` for appending and check its layout against ``ds``."""
    try:
        nc = netCDF4.Dataset(part, mode="a")
    except OSError as exc:
        raise CubeWriteError(
            f"{part} cannot be opened ({exc}); it was probably damaged while being "
            f"written. {_discard()[0].upper()}{_discard()[1:]}"
        ) from exc
    try:
        for dim, size in ds.sizes.items():
            if str(dim) not in nc.dimensions or len(nc.dimensions[str(dim)]) != size:
                raise CubeWriteError(f"{part}: dimension {dim!r} is missing or has another size")
        for name, var in ds.variables.items():
            if name not in nc.variables or nc.variables[name].dimensions != tuple(
                map(str, var.dims)
            ):
                raise CubeWriteError(f"{part}: variable {name!r} is missing or has other dims")
            _tune(nc.variables[name], isinstance(var.data, da.Array))
        _set_global_attrs(nc, ds, _coordinates_attrs(ds)[1])
        nc.sync()
    except BaseException:
        nc.close()
        raise
    return nc


# --------------------------------------------------------------- bookkeeping


def _read_log(log: Path, part: Path) -> tuple[dict[str, Any], set[int]]:
    """Header and completed blocks of an unfinished cube."""
    if not log.exists():
        raise CubeWriteError(
            f"{part} has no bookkeeping file {log.name}, so which blocks it holds is unknown; "
            f"{_discard()}"
        )
    try:
        with open(log, encoding="utf-8") as f:
            lines = f.read().split("\n")
    except (OSError, UnicodeDecodeError) as exc:
        raise CubeWriteError(f"{log}: cannot be read ({exc}); {_discard()}") from exc
    try:
        header = json.loads(lines[0])
        if header.get("format") != _FORMAT:
            raise ValueError(f"format {header.get('format')!r}")
    except (ValueError, AttributeError) as exc:
        raise CubeWriteError(
            f"{log}: not a write_cube bookkeeping file ({exc}); {_discard()}"
        ) from exc
    done: set[int] = set()
    for line in lines[1:-1]:  # the last element follows the last newline: empty or torn
        try:
            done.add(int(json.loads(line)["block"]))
        except (ValueError, KeyError, TypeError):
            continue
    return header, done


def _write_header(log: Path, plan: _Plan) -> None:
    header = {
        "format": _FORMAT,
        "version": _FORMAT_VERSION,
        "fingerprint": plan.fingerprint,
        "n_blocks": plan.n_blocks,
        "block_dims": list(plan.block_dims),
        "structure": plan.structure,
    }
    tmp = log.with_name(log.name + ".tmp")
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(json.dumps(header, sort_keys=True) + "\n")
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, log)


def _fsync_dir(directory: Path) -> None:
    with contextlib.suppress(OSError):
        fd = os.open(directory, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


# ------------------------------------------------------------------ runners


# ------------------------------------------------------------------ progress


class _TextProgress:
    """A one-line stderr counter, used when tqdm is not installed."""

    def __init__(self, total: int, initial: int, desc: str) -> None:
        self.n, self.total, self.desc = initial, total, desc
        self.last = 0.0
        self._show(force=True)

    def _show(self, force: bool = False) -> None:
        now = time.monotonic()
        if force or now - self.last >= 0.5:
            self.last = now
            sys.stderr.write(f"\r{self.desc}: {self.n}/{self.total} blocks")
            sys.stderr.flush()

    def update(self, n: int = 1) -> None:
        self.n += n
        self._show(force=self.n == self.total)

    def close(self) -> None:
        self._show(force=True)
        sys.stderr.write("\n")
        sys.stderr.flush()


class _NoProgress:
    def update(self, n: int = 1) -> None:
        pass

    def close(self) -> None:
        pass


def _progress(enabled: bool, total: int, initial: int, desc: str) -> Any:
    if not enabled:
        return _NoProgress()
    try:
        from tqdm import tqdm
    except ImportError:
        return _TextProgress(total, initial, desc)
    return tqdm(total=total, initial=initial, desc=desc, unit="block", file=sys.stderr)


# -------------------------------------------------------------------- write


def _check_room(part: Path, need: int) -> None:
    """Refuse, before writing, ``need`` bytes (plus metadata) that would not fit."""
    if not _CHECK_SPACE:
        return
    need = int(need) + _SPACE_MARGIN
    try:
        st = os.statvfs(part.parent)
    except (OSError, AttributeError):  # pragma: no cover - not on POSIX
        st = None
    if st is not None:
        free = (st.f_bfree if os.geteuid() == 0 else st.f_bavail) * st.f_frsize
        if free < need:
            raise _NoRoom(
                errno.ENOSPC, f"about {_mib(need)} needed, {_mib(free)} free on {part.parent}"
            )
    limit = _file_size_limit()
    if limit is not None:
        size = part.stat().st_size if part.exists() else 0
        if size + need > limit:
            raise _NoRoom(
                errno.EFBIG,
                f"{part.name} would grow from {_mib(size)} past the limit of {_mib(limit)}",
            )


_FALLOC_FL_KEEP_SIZE = 1


def _fallocate_fn() -> Any:
    try:
        import ctypes
        import ctypes.util

        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        fn = libc.fallocate
    except (OSError, AttributeError):  # pragma: no cover - not glibc
        return None
    fn.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.c_int64, ctypes.c_int64]
    fn.restype = ctypes.c_int
    return fn


_FALLOCATE = _fallocate_fn() if sys.platform.startswith("linux") else None


def _reserve(fd: int, nbytes: int) -> None:
    """Reserve ``nbytes`` of disk beyond the end of the file open as ``fd`` (size unchanged).

    HDF5 appends each block at the end of the file; with the room already allocated
    a full disk is found here, before HDF5 writes anything, instead of in the middle
    of HDF5's flush.  File systems without ``fallocate`` skip the reservation.
    """
    if _FALLOCATE is None or not _CHECK_SPACE:
        return
    import ctypes

    size = os.fstat(fd).st_size
    if _FALLOCATE(fd, _FALLOC_FL_KEEP_SIZE, size, int(nbytes) + _SPACE_MARGIN) != 0:
        code = ctypes.get_errno()
        if code in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG):
            raise _NoRoom(
                code, f"reserving {_mib(int(nbytes) + _SPACE_MARGIN)} for the next block failed"
            )


def _block_bytes(plan: _Plan) -> int:
    """Largest raw size of one block [byte] (what a block may add to the file, uncompressed)."""
    total = 0
    for v in plan.lazy:
        shape = [
            max(plan.chunks[d]) if d in plan.chunks else n
            for d, n in zip(v.dims, v.data.shape, strict=True)
        ]
        total += math.prod(shape) * v.data.dtype.itemsize
    return total


# --------------------------------------------------------------------- lock


# -------------------------------------------------------------------- write


def _file_kind(p: Path) -> str | None:
    """None if nothing is at ``p``, ``"file"`` for a regular file, else what it is."""
    try:
        mode = os.lstat(p).st_mode
    except (FileNotFoundError, NotADirectoryError):
        return None
    if stat.S_ISREG(mode):
        return "file"
    kinds = (
        (stat.S_ISDIR, "a directory"),
        (stat.S_ISLNK, "a symbolic link"),
        (stat.S_ISFIFO, "a FIFO (named pipe)"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    )
    return next((name for test, name in kinds if test(mode)), "not a regular file")


def _check_destination(path: Path, part: Path, log: Path, overwrite: bool, resume: bool) -> str:
    """Apply the overwrite/resume rules before anything is touched.

    Returns ``"new"`` (start afresh), ``"resume"`` (continue the ``.part``) or
    ``"finished"`` (``resume`` with a finished cube and no ``.part``).
    """
    for p in (path, part, log):
        kind = _file_kind(p)
        if kind not in (None, "file"):
            raise CubeWriteError(
                f"{p} is {kind}, not a regular file; cubes replace only regular files, even with "
                f"{_opt('overwrite')}. Remove it or choose another output"
            )
    has_path, has_part = _file_kind(path) == "file", _file_kind(part) == "file"
    if has_part and resume:
        if has_path and not overwrite:
            raise FileExistsError(
                f"{path} exists and {part} holds an unfinished write of it: pass {_opt('resume')} "
                f"with {_opt('overwrite')} to finish it and replace {path.name}, "
                "or remove one of them"
            )
        return "resume"
    if has_path and resume and not overwrite:
        return "finished"
    if has_path and not overwrite:
        raise FileExistsError(f"{path} exists; pass {_opt('overwrite')} to replace it")
    if has_part and not overwrite:
        raise FileExistsError(
            f"{part} exists: an unfinished write of {path.name}. Pass {_opt('resume')} to "
            f"continue it, or {_opt('overwrite')} to discard it and start again"
        )
    return "new"


def _check_finished(path: Path, ds: xr.Dataset) -> None:
    """``resume`` of a finished cube: a no-op if it is this cube, else an error."""
    try:
        with netCDF4.Dataset(path) as nc:
            dims = {str(d): len(v) for d, v in nc.dimensions.items()}
            names = set(map(str, nc.variables))
            attrs = {k: nc.getncattr(k) for k in nc.ncattrs()}
    except OSError as exc:
        raise CubeWriteError(
            f"{path} exists and is not a readable netCDF cube ({exc}); pass {_opt('overwrite')} "
            "to replace it"
        ) from exc
    want = {str(d): int(n) for d, n in ds.sizes.items()}
    problems = _fingerprint.changes(attrs, ds.attrs)
    if dims != want:
        problems.append(f"dims and sizes differ: {dims} in the file, {want} now")
    if names != set(map(str, ds.variables)):
        problems.append(
            f"variables differ: {sorted(names)} in the file, {sorted(map(str, ds.variables))} now"
        )
    if not problems:
        for k, v in ds.attrs.items():
            if k not in VOLATILE_ATTRS and isinstance(v, str) and attrs.get(k) != v:
                problems.append(f"global attribute {k!r} differs")
                break
    if problems:
        raise CubeWriteError(
            f"{path} is a finished cube of other inputs ({'; '.join(problems)}); "
            "nothing was resumed. "
            f"Pass {_opt('overwrite')} to replace it"
        )
    _log.info("%s is already complete; there is nothing to resume", path)


def write_cube(
    ds: xr.Dataset,
    path: str | os.PathLike[str],
    *,
    overwrite: bool = False,
    resume: bool = False,
    client: Any = None,
    scheduler: str | None = None,
    max_in_flight: int | None = None,
    progress: bool = False,
    complevel: int = 0,
    on_block: Callable[[BlockWritten], None] | None = None,
) -> Path:
    """Compute a lazy cube block by block and stream it to a netCDF-4 file.

    The file is written as ``<path>.part`` and renamed to ``path`` when complete;
    the blocks already written are recorded in ``<path>.part.jsonl`` so that an
    interrupted write can be resumed, and ``<path>.lock`` is held meanwhile so that
    no two writers share a path (see the module documentation).

    Parameters
    ----------
    ds : xarray.Dataset
        The cube.  Dask-backed variables are computed block by block (one chunk
        of every chunked dimension at a time); numpy-backed variables (usually
        the coordinates) are written first.  Chunks must agree between variables.
    path : path-like
        Destination file.
    overwrite : bool, default False
        Replace an existing ``path`` (kept intact until the new cube is
        complete) and discard an unfinished ``.part`` when not resuming.  Only a
        regular file is ever replaced.
    resume : bool, default False
        Continue an unfinished ``<path>.part`` of the same cube (same content
        fingerprint), computing only the missing blocks; without a ``.part`` the
        write starts afresh, and with a finished ``path`` of the same cube it does
        nothing.
    client : distributed.Client, optional
        Compute the blocks on this cluster (left open).
    scheduler : str, optional
        Address of a Dask scheduler (``"tcp://host:port"``) to connect to for the
        duration of the write; or ``"threads"`` (the default, in-process) or
        ``"synchronous"`` (one block at a time in the calling thread, for
        debugging).
    max_in_flight : int, optional
        Largest number of blocks being computed or waiting to be written at any
        time; bounds memory at about ``max_in_flight`` block sizes.  Default
        twice the number of worker threads.
    progress : bool, default False
        Show a progress bar of blocks on stderr (tqdm if installed).
    complevel : int, default 0
        zlib level (1-9, with byte shuffle) for the numeric variables; 0 stores
        them uncompressed.
    on_block : callable, optional
        Called with a :class:`BlockWritten` in the writing thread after each
        block is committed (written, flushed, synced and recorded).

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    FileExistsError
        ``path`` exists and ``overwrite`` is false, or an unfinished ``.part``
        exists and neither ``resume`` nor ``overwrite`` is given.  Nothing is
        touched.
    ValidationError
        ``ds`` cannot be written (inconsistent chunks, unsupported dtypes or
        attributes, no data variables or a dimension of size 0) or the arguments
        are invalid.  Nothing is touched.
    CubeLockedError
        Another writer holds ``<path>.lock``.  Nothing is touched.
    SchedulerError
        ``scheduler`` cannot be reached.
    CubeWriteError
        Something other than a regular file at ``path`` (a FIFO, symlink, device,
        directory); a ``.part`` that belongs to another cube (its fingerprint
        differs: the message names what changed) or cannot be read (it is left
        untouched); a finished ``path`` of another cube with ``resume``; or a
        block computation or write that failed.  A write that fails for lack of
        room (disk full, file size limit) is refused before the block is written
        when that can be foreseen, and the file is cut back to its last synced
        state otherwise: the message names the cause, the blocks written so far
        stay in the ``.part`` and ``resume=True`` continues from them.  The
        original exception is chained.

    Notes
    -----
    Only the calling process writes; workers only compute.  Tasks shared by
    several blocks (for example a lazily built look-up table) are recomputed
    for every block: persist or compute them first.
    """
    path = Path(path)
    if path.name in ("", ".", ".."):
        raise ValidationError(f"path: {str(path)!r} names no file; give a file name for the cube")
    part = path.with_name(path.name + PART_SUFFIX)
    log = path.with_name(path.name + LOG_SUFFIX)
    plan = _plan(ds)
    if max_in_flight is not None and (
        not isinstance(max_in_flight, int | np.integer) or max_in_flight < 1
    ):
        raise ValidationError(f"max_in_flight: must be an integer >= 1, got {max_in_flight!r}")
    if not 0 <= int(complevel) <= 9:
        raise ValidationError(f"complevel: must be 0 (no compression) to 9, got {complevel!r}")
    if client is not None and scheduler is not None:
        raise ValidationError("pass either client or scheduler, not both")
    if scheduler is not None and scheduler not in _THREAD_NAMES + _SYNC_NAMES:
        _check_address(scheduler)
    if _file_kind(path.parent) is None:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise CubeWriteError(
                f"cannot write {path}: creating {path.parent} failed: {_reason(exc)}"
            ) from exc
    lock = _Lock(path.with_name(path.name + LOCK_SUFFIX), path)
    lock.acquire()
    try:
        return _write_locked(
            ds,
            path,
            part,
            log,
            plan,
            overwrite=overwrite,
            resume=resume,
            client=client,
            scheduler=scheduler,
            max_in_flight=max_in_flight,
            progress=progress,
            complevel=complevel,
            on_block=on_block,
        )
    finally:
        lock.release()


def _write_locked(
    ds: xr.Dataset,
    path: Path,
    part: Path,
    log: Path,
    plan: _Plan,
    *,
    overwrite: bool,
    resume: bool,
    client: Any,
    scheduler: str | None,
    max_in_flight: int | None,
    progress: bool,
    complevel: int,
    on_block: Callable[[BlockWritten], None] | None,
) -> Path:
    """:func:`write_cube` once the lock is held."""
    state = _check_destination(path, part, log, overwrite, resume)
    if state == "finished":
        _check_finished(path, ds)
        return path
    resuming = state == "resume"
    done: set[int] = set()
    if resuming:
        header, done = _read_log(log, part)
        if header.get("fingerprint") != plan.fingerprint:
            why = _difference(header.get("structure", {}), plan.structure)
            raise CubeWriteError(
                f"{part} belongs to a different cube ({why}); it was left untouched. "
                f"Resume with the same inputs, or {_discard()}"
            )
        done = {k for k in done if 0 <= k < plan.n_blocks}

    runner = _runner(client, scheduler)
    nc: netCDF4.Dataset | None = None
    try:
        if resuming:
            size0 = part.stat().st_size
            try:
                _check_room(part, _block_bytes(plan))
                nc = _open_part(part, ds, plan)
            except CubeWriteError:
                raise
            except Exception as exc:
                if not isinstance(exc, _NoRoom):
                    with contextlib.suppress(OSError):
                        os.truncate(part, size0)  # undo a half-written attribute update
                why = _reason(exc, part)
                raise CubeWriteError(
                    f"cannot resume {path}: {why}. The {len(done)} of {plan.n_blocks} blocks "
                    f"written so far are kept in {part}; {_fix(why)} and {_again()}"
                ) from exc
        else:
            log.unlink(missing_ok=True)
            part.unlink(missing_ok=True)
            try:
                _check_room(part, 0)
                nc = _create(part, ds, plan, complevel)
                _write_header(log, plan)
            except BaseException as exc:
                if nc is not None:
                    with contextlib.suppress(Exception):
                        nc.close()
                part.unlink(missing_ok=True)  # nothing recorded yet: nothing lost
                log.unlink(missing_ok=True)
                if isinstance(exc, Exception) and not isinstance(exc, SbrdfError):
                    raise CubeWriteError(
                        f"cannot write {path}: creating {part} failed: {_reason(exc, part)}"
                    ) from exc
                raise
    except BaseException:
        runner.close()
        raise

    bar: Any = _NoProgress()
    fd = log_fd = -1
    k = -1
    writing = False
    good, head = -1, b""
    try:
        writing = True
        fd = os.open(part, os.O_RDWR)
        os.fsync(fd)
        good, head = os.fstat(fd).st_size, os.pread(fd, _HEAD_BYTES, 0)
        log_fd = os.open(log, os.O_WRONLY | os.O_APPEND)
        writing = False
        limit = int(max_in_flight or 2 * runner.n_workers)
        todo = iter([b for b in range(plan.n_blocks) if b not in done])
        kinds = {str(n): _storage_kind(n, v.dtype) for n, v in ds.variables.items()}
        bar = _progress(progress, plan.n_blocks, len(done), path.name)
        pieces: dict[int, list[tuple[str, tuple[slice, ...], Any]]] = {}
        exhausted = False
        while True:
            while not exhausted and runner.pending < limit:
                nxt = next(todo, None)
                if nxt is None:
                    exhausted = True
                else:
                    pieces[nxt] = plan.pieces(nxt)
                    runner.submit(nxt, plan.task(nxt, [p for _, _, p in pieces[nxt]]))
            if not runner.pending:
                break
            k, handle = runner.next_done()
            arrays = runner.result(handle)
            if k in done:  # a block is written exactly once
                continue
            block = pieces.pop(k)
            nbytes = sum(np.asarray(a).nbytes for a in arrays)
            _check_room(part, nbytes)
            _reserve(fd, nbytes)
            writing = True
            for (name, region, _), values in zip(block, arrays, strict=True):
                expected = tuple(s.stop - s.start for s in region)
                if np.shape(values) != expected:
                    raise CubeWriteError(
                        f"block {k}: {name!r} computed with shape {np.shape(values)}, "
                        f"expected {expected} from the chunks"
                    )
                nc.variables[name][region] = _to_storage(values, kinds[name])
            del arrays
            nc.sync()
            os.fsync(fd)
            good, head = os.fstat(fd).st_size, os.pread(fd, _HEAD_BYTES, 0)
            writing = False
            os.write(log_fd, (json.dumps({"block": k}) + "\n").encode())
            os.fsync(log_fd)
            done.add(k)
            bar.update(1)
            if on_block is not None:
                on_block(BlockWritten(k, plan.slices(k), len(done), plan.n_blocks, runner.pending))
            k = -1
        writing = True
        nc.close()
        nc = None
        os.ftruncate(fd, os.fstat(fd).st_size)  # release room reserved past the end
        os.fsync(fd)
        writing = False
        for p in (path, part):
            kind = _file_kind(p)
            if kind not in (None, "file"):
                raise CubeWriteError(f"{p} became {kind} during the write; it was not replaced")
        os.replace(part, path)
    except Exception as exc:
        where = f"at block {k} ({_describe(plan.slices(k))}) " if k >= 0 else ""
        why = (
            _reason(exc, part)
            if isinstance(exc, OSError) or writing
            else f"{type(exc).__name__}: {exc}"
        )
        lost = None
        if writing and good >= 0:  # an I/O failure: cut the file back to its last synced state
            _fence(part)
            if nc is not None:
                with contextlib.suppress(Exception):
                    nc.close()
                nc = None
            lost = _cut_back(part, good, head)
        intro = f"writing {path} failed {where}after {len(done)} of {plan.n_blocks} blocks: {why}. "
        if lost is not None:
            raise CubeWriteError(f"{intro}{part} could not be kept ({lost}); {_discard()}") from exc
        if writing and good >= 0:
            raise CubeWriteError(
                f"{intro}HDF5 failed in the middle of a block; {part} was cut back to its last "
                f"synced state, with the blocks written so far. "
                f"{_fix(why)[0].upper()}{_fix(why)[1:]} "
                f"and {_again()}; should HDF5 fail again at the same block, the file cannot be "
                f"continued: {_discard()}"
            ) from exc
        raise CubeWriteError(
            f"{intro}The blocks written so far are kept in {part}; {_fix(why)} and {_again()} "
            "to compute only the missing blocks"
        ) from exc
    except BaseException as exc:
        exc.add_note(
            f"write_cube: {len(done)} of {plan.n_blocks} blocks of {path} are kept in {part}; "
            f"{_again()} to finish it"
        )
        raise
    finally:
        runner.close()
        bar.close()
        if nc is not None:
            with contextlib.suppress(Exception):
                nc.close()
        if fd >= 0:  # release room reserved past the end (the size is unchanged)
            with contextlib.suppress(OSError):
                os.ftruncate(fd, os.fstat(fd).st_size)
        for f in (fd, log_fd):
            if f >= 0:
                os.close(f)
    log.unlink(missing_ok=True)
    _fsync_dir(path.parent)
    return path


def _fence(part: Path) -> None:
    """Make every read-write descriptor of ``part`` in this process read-only.

    After a failed write HDF5 still holds dirty metadata of the failed block; were it
    flushed (on close, or at exit), it would overwrite the last synced state in place
    and point it at data that never reached the disk.  Replacing HDF5's descriptor by
    a read-only one on the same file makes those writes fail harmlessly, so the file
    can be cut back to its last synced size.  (Linux: descriptors found in /proc.)
    """
    fds = Path("/proc/self/fd")
    if not fds.is_dir():  # pragma: no cover - not Linux
        return
    try:
        ino = part.stat().st_ino
    except OSError:
        return
    ro = -1
    try:
        for entry in list(fds.iterdir()):
            with contextlib.suppress(OSError, ValueError):
                n = int(entry.name)
                st = os.fstat(n)
                if st.st_ino != ino or not stat.S_ISREG(st.st_mode):
                    continue
                flags = Path(f"/proc/self/fdinfo/{n}").read_text().split("flags:")[1].split()[0]
                if int(flags, 8) & os.O_ACCMODE == os.O_RDONLY:
                    continue
                if ro < 0:
                    ro = os.open(part, os.O_RDONLY)
                os.dup2(ro, n)
    finally:
        if ro >= 0:
            os.close(ro)


def _cut_back(part: Path, size: int, head: bytes) -> str | None:
    """Restore ``part`` to its last synced state: its ``size`` and its first bytes ``head``.

    HDF5 rewrites its superblock (at the start of the file, holding the end-of-file
    address) in place when a write fails; the rest of the synced file is untouched
    (blocks are appended).  Returns None if the file then opens, else why not.
    """
    try:
        if part.stat().st_size > size:
            os.truncate(part, size)
        fd = os.open(part, os.O_WRONLY)
        try:
            os.pwrite(fd, head, 0)
            os.fsync(fd)
        finally:
            os.close(fd)
    except OSError as exc:
        return str(exc)
    return _check_opens(part)


def _check_opens(part: Path) -> str | None:
    """None if ``part`` opens as netCDF in a fresh process (this one's HDF5 may still hold it)."""
    import subprocess

    code = "import sys, netCDF4; netCDF4.Dataset(sys.argv[1]).close()"
    try:
        r = subprocess.run(
            [sys.executable, "-c", code, str(part)],
            capture_output=True,
            text=True,
            timeout=120,
            env={**os.environ, "HDF5_USE_FILE_LOCKING": "FALSE"},
        )
    except (OSError, subprocess.SubprocessError) as exc:
        return f"it could not be checked: {exc}"
    if r.returncode:
        lines = r.stderr.strip().splitlines()
        return lines[-1] if lines else f"exit status {r.returncode}"
    return None


def _describe(slices: Mapping[str, slice]) -> str:
    return ", ".join(f"{d}[{s.start}:{s.stop}]" for d, s in slices.items())
