"""The files of a cube being written: the ``.part`` netCDF file, its bookkeeping sidecar,
and the rules for what may already be at the destination.

See :mod:`sbrdf_xr.store.writer` for the format (the ``Bookkeeping`` and ``Encoding``
sections) and the overwrite/resume rules.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import dask.array as da
import netCDF4
import numpy as np
import xarray as xr

from . import fingerprint as _fingerprint
from .common import CubeWriteError, _discard, _log, _opt
from .disk import file_kind
from .layout import VOLATILE_ATTRS, BlockLayout, storage_kind

__all__ = [
    "FORMAT",
    "FORMAT_VERSION",
    "HDF5_CHUNK_BYTES",
    "check_destination",
    "check_finished",
    "coordinates_attrs",
    "create_part",
    "hdf5_chunks",
    "nc_attr",
    "open_part",
    "read_log",
    "set_attrs",
    "set_global_attrs",
    "to_storage",
    "tune",
    "write_header",
]

#: Format name and version in the header of the bookkeeping sidecar.
FORMAT = "sbrdf_xr.write_cube"
FORMAT_VERSION = 1
#: Largest HDF5 chunk of a streamed variable [byte]; larger Dask chunks are split.
#: Chunks of 1-2 MiB write about twice as fast as 4-8 MiB ones through netCDF-4/HDF5
#: (measured on this package's sweeps) and keep a one-chunk cache small.
HDF5_CHUNK_BYTES = 2 * 2**20


def coordinates_attrs(ds: xr.Dataset) -> tuple[dict[str, str], str | None]:
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


def nc_attr(value: Any) -> Any:
    if isinstance(value, list | tuple) and value and all(isinstance(x, str) for x in value):
        return list(value)
    if isinstance(value, list | tuple):
        return np.asarray(value)
    return value


def set_attrs(target: Any, attrs: Mapping[str, Any]) -> None:
    for key, value in attrs.items():
        target.setncattr(key, nc_attr(value))


def to_storage(values: Any, kind: str) -> np.ndarray:
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


def hdf5_chunks(shape: tuple[int, ...], itemsize: int) -> list[int] | None:
    """HDF5 chunk shape for a streamed variable: its Dask chunk, halved until small."""
    if not shape or 0 in shape:
        return None
    c = list(shape)
    while math.prod(c) * itemsize > HDF5_CHUNK_BYTES and max(c) > 1:
        i = int(np.argmax(c))
        c[i] = -(-c[i] // 2)
    return c


def is_contiguous(kind: str, var: xr.Variable, complevel: int) -> bool:
    """Whether a streamed variable is stored contiguous, laid out whole at creation.

    Every uncompressed numeric (or boolean) variable with values is.  Its blocks then
    write raw values at fixed offsets and never touch HDF5's metadata, so a writer
    killed at any instant leaves metadata that were flushed and synced with the file's
    creation: a resume rewrites the unlogged blocks and the file stays readable.
    Compressed variables need chunks, whose index HDF5 updates (and flushes) as
    blocks arrive.
    """
    return kind != "str" and not complevel and var.ndim > 0 and var.size > 0


def tune(v: netCDF4.Variable, streamed: bool) -> None:
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


def create_part(part: Path, ds: xr.Dataset, plan: BlockLayout, complevel: int) -> netCDF4.Dataset:
    """Create ``part`` with every dim, variable and attribute; write the numpy-backed values."""
    coords_attr, global_coords = coordinates_attrs(ds)
    nc = netCDF4.Dataset(part, mode="w", format="NETCDF4")
    try:
        for dim, size in ds.sizes.items():
            nc.createDimension(str(dim), int(size))
        lazy = {v.name for v in plan.lazy}
        for name, var in ds.variables.items():
            name = str(name)
            kind = storage_kind(name, var.dtype)
            dtype: Any = {"bool": np.int8, "str": str}.get(kind, var.dtype.newbyteorder("="))
            kw: dict[str, Any] = {}
            whole = name in lazy and is_contiguous(kind, var, complevel)
            if whole:
                kw["contiguous"] = True
            elif name in lazy and kind != "str":
                shape = tuple(max(plan.chunks[d]) for d in map(str, var.dims))
                kw["chunksizes"] = hdf5_chunks(shape, np.dtype(dtype).itemsize)
            if complevel and kind == "numeric" and var.ndim:
                kw.update(zlib=True, complevel=int(complevel), shuffle=True)
            attrs = dict(var.attrs)
            fill = attrs.pop("_FillValue", False)
            v = nc.createVariable(name, dtype, tuple(map(str, var.dims)), fill_value=fill, **kw)
            tune(v, name in lazy)
            if kind == "bool":
                attrs["dtype"] = "bool"
            if name in coords_attr:
                attrs["coordinates"] = coords_attr[name]
            set_attrs(v, attrs)
            if name not in lazy:
                v[...] = to_storage(var.values, kind)
            elif whole:
                # one element written lays the whole variable out in the file now: the
                # blocks then write raw values into it and change no HDF5 metadata
                v[(0,) * var.ndim] = np.zeros((), dtype=dtype)
        set_global_attrs(nc, ds, global_coords)
        nc.sync()
    except BaseException:
        nc.close()
        raise
    return nc


def set_global_attrs(nc: netCDF4.Dataset, ds: xr.Dataset, global_coords: str | None) -> None:
    for key in nc.ncattrs():
        nc.delncattr(key)
    attrs = dict(ds.attrs)
    if global_coords:
        attrs["coordinates"] = global_coords
    set_attrs(nc, attrs)


def open_part(part: Path, ds: xr.Dataset, plan: BlockLayout) -> netCDF4.Dataset:
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
            tune(nc.variables[name], isinstance(var.data, da.Array))
        set_global_attrs(nc, ds, coordinates_attrs(ds)[1])
        nc.sync()
    except BaseException:
        nc.close()
        raise
    return nc


def read_back_error(part: Path) -> str | None:
    """Why the finished ``part`` does not read back, or None when it does.

    Opens it read-only and reads every attribute and the first and last value of every
    variable (which walks a chunked variable's index from end to end): what a torn
    HDF5 metadata write leaves unreadable.
    """
    try:
        with netCDF4.Dataset(part, mode="r") as nc:
            nc.set_auto_maskandscale(False)
            for a in nc.ncattrs():
                nc.getncattr(a)
            for v in nc.variables.values():
                for a in v.ncattrs():
                    v.getncattr(a)
                if v.size:
                    v[(0,) * v.ndim]
                    v[tuple(n - 1 for n in v.shape)]
    except Exception as exc:  # HDF5 reports damage as several exception types
        return f"{type(exc).__name__}: {exc}"
    return None


# --------------------------------------------------------------- bookkeeping


def read_log(log: Path, part: Path) -> tuple[dict[str, Any], set[int]]:
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
        if header.get("format") != FORMAT:
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


def write_header(log: Path, plan: BlockLayout) -> None:
    header = {
        "format": FORMAT,
        "version": FORMAT_VERSION,
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


def check_destination(path: Path, part: Path, log: Path, overwrite: bool, resume: bool) -> str:
    """Apply the overwrite/resume rules before anything is touched.

    Returns ``"new"`` (start afresh), ``"resume"`` (continue the ``.part``) or
    ``"finished"`` (``resume`` with a finished cube and no ``.part``).
    """
    for p in (path, part, log):
        kind = file_kind(p)
        if kind not in (None, "file"):
            raise CubeWriteError(
                f"{p} is {kind}, not a regular file; cubes replace only regular files, even with "
                f"{_opt('overwrite')}. Remove it or choose another output"
            )
    has_path, has_part = file_kind(path) == "file", file_kind(part) == "file"
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


def check_finished(path: Path, ds: xr.Dataset) -> None:
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
