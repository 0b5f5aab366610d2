"""The files of a netCDF cube being written: the ``.part`` file, its bookkeeping sidecar,
the rules for what may already be at the destination, and how a message says to go on.

See :mod:`sbrdf_xr.store.writer` for the format (the ``Bookkeeping`` and ``Encoding``
sections) and the overwrite/resume rules.  Every file here is created, opened and
replaced through the package's safe output (:mod:`sbrdf_xr._output`).
"""

from __future__ import annotations

import glob
import json
import logging
import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import dask.array as da
import netCDF4
import numpy as np
import xarray as xr

from .._output import (
    atomic_file,
    cli_style,
    error_words,
    file_kind,
    open_regular,
    option,
    refuse_special,
    rename_no_replace,
)
from ..errors import CubeWriteError
from . import fingerprint as _fingerprint
from .layout import VOLATILE_ATTRS, BlockLayout, storage_kind

__all__ = [
    "FORMAT",
    "FORMAT_VERSION",
    "HDF5_CHUNK_BYTES",
    "LOG_SUFFIX",
    "PART_SUFFIX",
    "again_hint",
    "check_destination",
    "check_finished",
    "clear_leftovers",
    "coordinates_attrs",
    "create_part",
    "destination_state",
    "discard_hint",
    "hdf5_chunks",
    "make_parent",
    "nc_attr",
    "open_part",
    "part_complevel",
    "publish",
    "read_log",
    "set_attrs",
    "set_global_attrs",
    "started_again",
    "to_storage",
    "tune",
    "write_header",
]

#: Suffix of the unfinished cube (a file, or a Zarr store's directory) before its rename.
PART_SUFFIX = ".part"
#: Suffix of the bookkeeping sidecar (JSON lines) of an unfinished netCDF cube.
LOG_SUFFIX = ".part.jsonl"
#: Format name and version in the header of the bookkeeping sidecar.
FORMAT = "sbrdf_xr.write_cube"
FORMAT_VERSION = 1
#: Largest HDF5 chunk of a streamed variable [byte]; larger Dask chunks are split.
#: Chunks of 1-2 MiB write about twice as fast as 4-8 MiB ones through netCDF-4/HDF5
#: (measured on this package's sweeps) and keep a one-chunk cache small.
HDF5_CHUNK_BYTES = 2 * 2**20

_log = logging.getLogger("sbrdf_xr.write_cube")


def discard_hint() -> str:
    """How to discard an unfinished cube and start again, for Python or the command line.

    Examples
    --------
    >>> from sbrdf_xr._output import command_line_messages
    >>> from sbrdf_xr.store.files import discard_hint
    >>> discard_hint()
    'pass overwrite=True, resume=False to discard it and start again'
    >>> with command_line_messages():
    ...     discard_hint()
    'run again with --overwrite (without --resume) to discard it and start again'
    """
    if cli_style():
        return "run again with --overwrite (without --resume) to discard it and start again"
    return "pass overwrite=True, resume=False to discard it and start again"


def again_hint(function: str = "write_cube") -> str:
    """How to continue an unfinished cube, for Python (``function``) or the command line.

    Examples
    --------
    >>> from sbrdf_xr._output import command_line_messages
    >>> from sbrdf_xr.store.files import again_hint
    >>> again_hint()
    'call write_cube again with resume=True'
    >>> with command_line_messages():
    ...     again_hint()
    'run the same command again with --resume'
    """
    if cli_style():
        return "run the same command again with --resume"
    return f"call {function} again with resume=True"


def coordinates_attrs(ds: xr.Dataset) -> tuple[dict[str, str], str | None]:
    """Per-variable and global ``coordinates`` attributes, as xarray writes them.

    Examples
    --------
    ``lat`` lies along ``x`` and so belongs to ``v``; no variable has the dimension of
    ``label``, which is named in the global attribute instead.

    >>> import xarray as xr
    >>> from sbrdf_xr.store.files import coordinates_attrs
    >>> ds = xr.Dataset(
    ...     {"v": (("x", "y"), [[1.0, 2.0], [3.0, 4.0]])},
    ...     coords={"x": [0, 1], "lat": ("x", [10.0, 20.0]), "label": ("z", ["a", "b"])},
    ... )
    >>> coordinates_attrs(ds)
    ({'v': 'lat'}, 'label')
    >>> coordinates_attrs(ds.drop_vars(["lat", "label"]))
    ({}, None)
    """
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
    """An attribute value as netCDF4 stores it: a list of str, an array of numbers, or as is.

    Examples
    --------
    >>> from sbrdf_xr.store.files import nc_attr
    >>> nc_attr(("red", "green"))
    ['red', 'green']
    >>> nc_attr((0.0, 1.0)), nc_attr([1, 2]).dtype.kind
    (array([0., 1.]), 'i')
    >>> nc_attr("sr-1"), nc_attr(0.5)
    ('sr-1', 0.5)
    """
    if isinstance(value, list | tuple) and value and all(isinstance(x, str) for x in value):
        return list(value)
    if isinstance(value, list | tuple):
        return np.asarray(value)
    return value


def set_attrs(target: Any, attrs: Mapping[str, Any]) -> None:
    """Set ``attrs`` on a netCDF4 dataset or variable, each value as :func:`nc_attr` makes it.

    Examples
    --------
    >>> import netCDF4
    >>> from sbrdf_xr.store.files import set_attrs
    >>> nc = netCDF4.Dataset("attrs.nc", "w", diskless=True)  # in memory, no file
    >>> v = nc.createVariable("v", "f8")
    >>> set_attrs(v, {"units": "sr-1", "valid_range": (0.0, 1.0), "bands": ("r", "g")})
    >>> {k: v.getncattr(k) for k in v.ncattrs()}
    {'units': 'sr-1', 'valid_range': array([0., 1.]), 'bands': ['r', 'g']}
    >>> nc.close()
    """
    for key, value in attrs.items():
        target.setncattr(key, nc_attr(value))


def to_storage(values: Any, kind: str) -> np.ndarray:
    """Values as they are written for their :func:`~sbrdf_xr.store.layout.storage_kind`.

    Booleans become ``int8`` (0/1), strings an object array of ``str``, and numbers
    keep their dtype in native byte order.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.store.files import to_storage
    >>> to_storage(np.array([True, False]), "bool")
    array([1, 0], dtype=int8)
    >>> to_storage(np.array(["r", "gb"]), "str")
    array(['r', 'gb'], dtype=object)
    >>> big_endian = np.arange(3, dtype=">f8")
    >>> out = to_storage(big_endian, "numeric")
    >>> out.dtype, out.dtype.isnative, bool(np.array_equal(out, big_endian))
    (dtype('float64'), True, True)
    """
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
    """HDF5 chunk shape for a streamed variable: its Dask chunk, halved until small.

    Examples
    --------
    A 4096 x 1024 float64 chunk (32 MiB) is halved, longest side first, down to
    :data:`HDF5_CHUNK_BYTES` (2 MiB); a small chunk is kept as it is.

    >>> from sbrdf_xr.store.files import HDF5_CHUNK_BYTES, hdf5_chunks
    >>> c = hdf5_chunks((4096, 1024), 8)
    >>> c, c[0] * c[1] * 8 == HDF5_CHUNK_BYTES
    ([512, 512], True)
    >>> hdf5_chunks((10, 3), 8)
    [10, 3]
    >>> hdf5_chunks((), 8) is None, hdf5_chunks((0, 3), 8) is None
    (True, True)
    """
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

    Examples
    --------
    >>> import netCDF4
    >>> from sbrdf_xr.store.files import tune
    >>> nc = netCDF4.Dataset("tune.nc", "w", diskless=True)  # in memory, no file
    >>> _ = nc.createDimension("x", 2**19)
    >>> v = nc.createVariable("v", "f8", ("x",), chunksizes=(2**18,))
    >>> tune(v, streamed=True)
    >>> v.get_var_chunk_cache()[0] == 2**18 * 8, v.mask, v.scale  # one 2 MiB chunk
    (True, False, False)
    >>> nc.close()
    """
    v.set_auto_maskandscale(False)
    chunking = v.chunking()
    if streamed and isinstance(chunking, list):
        nbytes = math.prod(chunking) * v.dtype.itemsize if isinstance(v.dtype, np.dtype) else 0
        v.set_var_chunk_cache(size=max(nbytes, 2**20), nelems=101, preemption=1.0)


def create_part(part: Path, ds: xr.Dataset, plan: BlockLayout, complevel: int) -> netCDF4.Dataset:
    """Create ``part`` with every dim, variable and attribute; write the numpy-backed values.

    Examples
    --------
    The coordinate ``x`` is written at once; the Dask-backed ``v`` is laid out
    contiguous (uncompressed) or in HDF5 chunks of its Dask chunks (compressed), for the
    blocks to fill; a boolean is stored as ``int8`` tagged ``dtype = "bool"``.

    >>> import tempfile
    >>> from pathlib import Path
    >>> import dask.array as da
    >>> import xarray as xr
    >>> from sbrdf_xr.store.files import create_part
    >>> from sbrdf_xr.store.layout import layout_of
    >>> ds = xr.Dataset(
    ...     {
    ...         "v": (("x", "y"), da.zeros((4, 3), chunks=(2, 3))),
    ...         "ok": ("x", da.ones(4, chunks=2, dtype=bool)),
    ...     },
    ...     coords={"x": [0.0, 1.0, 2.0, 3.0]},
    ...     attrs={"title": "demo"},
    ... )
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     part = Path(tmp) / "cube.nc.part"
    ...     with create_part(part, ds, layout_of(ds), complevel=0) as nc:
    ...         print({d: len(n) for d, n in nc.dimensions.items()}, list(nc.variables))
    ...         print(nc["x"][:].tolist(), nc["v"].chunking(), nc.getncattr("title"))
    ...         print(nc["ok"].dtype, nc["ok"].getncattr("dtype"))
    ...     part.unlink()  # a .part is created anew, never over an existing file
    ...     with create_part(part, ds, layout_of(ds), complevel=4) as nc:
    ...         print(nc["v"].chunking(), nc["v"].filters()["complevel"])
    {'x': 4, 'y': 3} ['v', 'ok', 'x']
    [0.0, 1.0, 2.0, 3.0] contiguous demo
    int8 bool
    [2, 3] 4
    """
    coords_attr, global_coords = coordinates_attrs(ds)
    # the name is claimed as a new regular file first (never a FIFO or a link followed);
    # netCDF then rewrites that file
    os.close(open_regular(part, os.O_WRONLY | os.O_CREAT | os.O_EXCL, error=CubeWriteError))
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
    """Replace the global attributes of ``nc`` by those of ``ds`` (and ``coordinates``).

    Examples
    --------
    >>> import netCDF4
    >>> import xarray as xr
    >>> from sbrdf_xr.store.files import set_global_attrs
    >>> nc = netCDF4.Dataset("globals.nc", "w", diskless=True)  # in memory, no file
    >>> nc.setncattr("history", "an earlier run")
    >>> set_global_attrs(nc, xr.Dataset(attrs={"title": "demo"}), "label")
    >>> {k: nc.getncattr(k) for k in nc.ncattrs()}
    {'title': 'demo', 'coordinates': 'label'}
    >>> nc.close()
    """
    for key in nc.ncattrs():
        nc.delncattr(key)
    attrs = dict(ds.attrs)
    if global_coords:
        attrs["coordinates"] = global_coords
    set_attrs(nc, attrs)


def open_part(part: Path, ds: xr.Dataset, plan: BlockLayout) -> netCDF4.Dataset:
    """Open an unfinished ``part`` for appending and check its layout against ``ds``.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import dask.array as da
    >>> import xarray as xr
    >>> from sbrdf_xr.errors import CubeWriteError
    >>> from sbrdf_xr.store.files import create_part, open_part
    >>> from sbrdf_xr.store.layout import layout_of
    >>> ds = xr.Dataset({"v": (("x", "y"), da.zeros((4, 3), chunks=(2, 3)))})
    >>> smaller = ds.isel(y=slice(0, 2))
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     part = Path(tmp) / "cube.nc.part"
    ...     create_part(part, ds, layout_of(ds), complevel=0).close()
    ...     with open_part(part, ds, layout_of(ds)) as nc:
    ...         print(nc.isopen(), nc.filepath() == str(part))
    ...     try:
    ...         open_part(part, smaller, layout_of(smaller))
    ...     except CubeWriteError as exc:
    ...         print(str(exc).replace(tmp, "<tmp>"))
    True True
    <tmp>/cube.nc.part: dimension 'y' is missing or has another size
    """
    refuse_special([part], error=CubeWriteError)
    try:
        nc = netCDF4.Dataset(part, mode="a")
    except OSError as exc:
        raise CubeWriteError(
            f"{part} cannot be opened ({exc}); it was probably damaged while being "
            f"written. {discard_hint()[0].upper()}{discard_hint()[1:]}"
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
    HDF5 metadata write leaves unreadable.  An error of the system (``OSError`` with an
    errno: a full disk, too many open files) is raised, not taken for damage.
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
    except OSError as exc:
        if exc.errno is not None and exc.errno > 0:  # the system's (a full disk), not damage
            raise
        return f"{type(exc).__name__}: {exc}"
    except Exception as exc:  # HDF5 reports damage as several exception types
        return f"{type(exc).__name__}: {exc}"
    return None


# --------------------------------------------------------------- bookkeeping


def clear_leftovers(log: Path) -> None:
    """Remove the temporary headers of ``log`` (:func:`write_header`'s) that a writer
    killed while writing one left; called with the lock held, so no writer is running.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.store.files import clear_leftovers
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     log = Path(tmp) / "cube.nc.part.jsonl"
    ...     _ = (Path(tmp) / "cube.nc.part.jsonl.k3j9x0.part").write_text('{"form')
    ...     clear_leftovers(log)
    ...     print(list(Path(tmp).iterdir()))
    []
    """
    for tmp in log.parent.glob(glob.escape(log.name) + ".*" + PART_SUFFIX):
        if file_kind(tmp) == "file":
            tmp.unlink(missing_ok=True)


def started_again(part: Path, log: Path, why: BaseException | None = None) -> bool:
    """Whether an unfinished ``part`` is written again from the start, with a logged
    message: one that does not open as the cube (``why``), or has no bookkeeping ``log``,
    while no block of it was recorded and it is what a writer stopped at its first
    instants leaves (empty, or an HDF5 file being laid out).  Anything else is kept.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.store.files import started_again
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     part, log = Path(tmp) / "cube.nc.part", Path(tmp) / "cube.nc.part.jsonl"
    ...     _ = part.write_bytes(b"")  # its name claimed, then the writer killed
    ...     first = started_again(part, log)
    ...     _ = part.write_bytes(b"someone's notes")
    ...     print(first, started_again(part, log))
    True False
    """
    if why is None and file_kind(log) is not None:
        return False
    try:
        with open(part, "rb") as f:
            head = f.read(8)
    except OSError:
        return False
    if head not in (b"", b"\x89HDF\r\n\x1a\n"):
        return False
    what = f"does not open as this cube ({why})" if why else f"has no bookkeeping file {log.name}"
    _log.warning(
        "%s %s and holds no recorded block: it is written again from the start", part, what
    )
    return True


def read_log(log: Path, part: Path) -> tuple[dict[str, Any], set[int]]:
    """Header and completed blocks of an unfinished cube.

    Examples
    --------
    A torn last line (a write interrupted mid-record) is ignored:

    >>> import tempfile
    >>> from pathlib import Path
    >>> import dask.array as da
    >>> import xarray as xr
    >>> from sbrdf_xr.errors import CubeWriteError
    >>> from sbrdf_xr.store.files import read_log, write_header
    >>> from sbrdf_xr.store.layout import layout_of
    >>> plan = layout_of(xr.Dataset({"v": ("x", da.zeros(4, chunks=1))}))
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     part, log = Path(tmp) / "cube.nc.part", Path(tmp) / "cube.nc.part.jsonl"
    ...     write_header(log, plan)
    ...     with open(log, "a", encoding="utf-8") as f:
    ...         _ = f.write('{"block": 2}\\n{"block": 0}\\n{"blo')
    ...     header, done = read_log(log, part)
    ...     print(header["n_blocks"], header["fingerprint"] == plan.fingerprint, sorted(done))
    ...     log.unlink()
    ...     try:
    ...         read_log(log, part)
    ...     except CubeWriteError as exc:
    ...         print(str(exc).replace(tmp, "<tmp>"))
    4 True [0, 2]
    <tmp>/cube.nc.part has no bookkeeping file cube.nc.part.jsonl, so which blocks it holds
    is unknown; pass overwrite=True, resume=False to discard it and start again
    """
    if file_kind(log) is None:
        raise CubeWriteError(
            f"{part} has no bookkeeping file {log.name}, so which blocks it holds is unknown; "
            f"{discard_hint()}"
        )
    try:
        with os.fdopen(open_regular(log, os.O_RDONLY, error=CubeWriteError), "rb") as f:
            lines = f.read().decode("utf-8").split("\n")
    except (OSError, UnicodeDecodeError) as exc:
        raise CubeWriteError(f"{log}: cannot be read ({exc}); {discard_hint()}") from exc
    try:
        header = json.loads(lines[0])
        if header.get("format") != FORMAT:
            raise ValueError(f"format {header.get('format')!r}")
    except (ValueError, AttributeError) as exc:
        raise CubeWriteError(
            f"{log}: not a write_cube bookkeeping file ({exc}); {discard_hint()}"
        ) from exc
    done: set[int] = set()
    for line in lines[1:-1]:  # the last element follows the last newline: empty or torn
        try:
            done.add(int(json.loads(line)["block"]))
        except (ValueError, KeyError, TypeError):
            continue
    return header, done


def write_header(log: Path, plan: BlockLayout, complevel: int = 0) -> None:
    """Write the bookkeeping sidecar ``log`` afresh: one JSON header line, synced to disk.

    The header is written to a new temporary file and renamed over ``log``
    (:func:`sbrdf_xr._output.atomic_file`), so a reader sees the old file or the whole new
    header, never part of it.

    Examples
    --------
    >>> import json
    >>> import tempfile
    >>> from pathlib import Path
    >>> import dask.array as da
    >>> import xarray as xr
    >>> from sbrdf_xr.store.files import write_header
    >>> from sbrdf_xr.store.layout import layout_of
    >>> plan = layout_of(xr.Dataset({"v": (("x", "y"), da.zeros((4, 3), chunks=(2, 3)))}))
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     log = Path(tmp) / "cube.nc.part.jsonl"
    ...     write_header(log, plan, complevel=4)
    ...     lines = log.read_text(encoding="utf-8").splitlines()
    ...     print(len(lines), sorted(p.name for p in Path(tmp).iterdir()))
    1 ['cube.nc.part.jsonl']
    >>> header = json.loads(lines[0])
    >>> sorted(header)
    ['block_dims', 'complevel', 'fingerprint', 'format', 'n_blocks', 'structure', 'version']
    >>> header["format"], header["version"], header["n_blocks"], header["complevel"]
    ('sbrdf_xr.write_cube', 1, 2, 4)
    """
    header = {
        "format": FORMAT,
        "version": FORMAT_VERSION,
        "fingerprint": plan.fingerprint,
        "n_blocks": plan.n_blocks,
        "block_dims": list(plan.block_dims),
        "complevel": int(complevel),
        "structure": plan.structure,
    }
    with atomic_file(log, overwrite=True, error=CubeWriteError) as tmp:
        tmp.write_text(json.dumps(header, sort_keys=True) + "\n", encoding="utf-8")


def part_complevel(nc: netCDF4.Dataset, plan: BlockLayout) -> int:
    """The zlib level the streamed variables of an open ``.part`` were created with.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import dask.array as da
    >>> import xarray as xr
    >>> from sbrdf_xr.store.files import create_part, part_complevel
    >>> from sbrdf_xr.store.layout import layout_of
    >>> ds = xr.Dataset({"v": (("x", "y"), da.zeros((4, 3), chunks=(2, 3)))})
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     for level in (0, 3):
    ...         part = Path(tmp) / f"cube{level}.nc.part"
    ...         with create_part(part, ds, layout_of(ds), complevel=level) as nc:
    ...             print(part_complevel(nc, layout_of(ds)))
    0
    3
    """
    for v in plan.lazy:
        var = nc.variables.get(v.name)
        if var is not None and isinstance(var.dtype, np.dtype) and var.dtype.kind in "iuf":
            filters = var.filters() or {}
            return int(filters.get("complevel", 0)) if filters.get("zlib") else 0
    return 0


def check_destination(path: Path, part: Path, log: Path, overwrite: bool, resume: bool) -> str:
    """Apply the overwrite/resume rules before anything is touched.

    Returns ``"new"`` (start afresh), ``"resume"`` (continue the ``.part``) or
    ``"finished"`` (``resume`` with a finished cube and no ``.part``).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.errors import CubeWriteError
    >>> from sbrdf_xr.store.files import check_destination
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = Path(tmp) / "cube.nc"
    ...     part, log = Path(tmp) / "cube.nc.part", Path(tmp) / "cube.nc.part.jsonl"
    ...     print(check_destination(path, part, log, overwrite=False, resume=False))
    ...     path.touch()  # a finished cube
    ...     print(check_destination(path, part, log, overwrite=False, resume=True))
    ...     try:
    ...         check_destination(path, part, log, overwrite=False, resume=False)
    ...     except FileExistsError as exc:
    ...         print(str(exc).replace(tmp, "<tmp>"))
    ...     part.touch()  # and an unfinished write of it
    ...     print(check_destination(path, part, log, overwrite=True, resume=True))
    ...     print(check_destination(path, part, log, overwrite=True, resume=False))
    ...     path.unlink()
    ...     path.mkdir()
    ...     try:
    ...         check_destination(path, part, log, overwrite=True, resume=False)
    ...     except CubeWriteError as exc:
    ...         print(str(exc).replace(tmp, "<tmp>"))
    new
    finished
    <tmp>/cube.nc exists; pass overwrite=True to replace it
    resume
    new
    <tmp>/cube.nc is a directory, not a regular file; outputs replace only regular files, even
    with overwrite=True. Remove it or choose another output
    """
    refuse_special([path, part, log], error=CubeWriteError)
    has_path, has_part = file_kind(path) == "file", file_kind(part) == "file"
    return destination_state(path, part, has_path, has_part, overwrite=overwrite, resume=resume)


def destination_state(
    path: Path, part: Path, has_path: bool, has_part: bool, *, overwrite: bool, resume: bool
) -> str:
    """What a cube writer does at ``path`` given whether the finished cube (``has_path``)
    and an unfinished write of it (``has_part``, at ``part``) are there: ``"new"``,
    ``"resume"`` or ``"finished"`` (nothing to do); FileExistsError when the options do
    not say what to do with what is there.  Shared by the netCDF and Zarr writers.

    Examples
    --------
    >>> from pathlib import Path
    >>> p, part = Path("cube.nc"), Path("cube.nc.part")
    >>> [destination_state(p, part, True, True, overwrite=True, resume=r) for r in (True, False)]
    ['resume', 'new']
    >>> destination_state(p, part, True, False, overwrite=False, resume=True)
    'finished'
    """
    if has_part and resume:
        if has_path and not overwrite:
            raise FileExistsError(
                f"{path} exists and {part} holds an unfinished write of it: pass "
                f"{option('resume')} with {option('overwrite')} to finish it and replace "
                f"{path.name}, or remove one of them"
            )
        return "resume"
    if has_path and resume and not overwrite:
        return "finished"
    if has_path and not overwrite:
        raise FileExistsError(f"{path} exists; pass {option('overwrite')} to replace it")
    if has_part and not overwrite:
        raise FileExistsError(
            f"{part} exists: an unfinished write of {path.name}. Pass {option('resume')} to "
            f"continue it, or {option('overwrite')} to discard it and start again"
        )
    return "new"


def check_finished(path: Path, ds: xr.Dataset) -> None:
    """``resume`` of a finished cube: a no-op if it is this cube, else an error.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import dask.array as da
    >>> import xarray as xr
    >>> from sbrdf_xr.errors import CubeWriteError
    >>> from sbrdf_xr.store.files import check_finished
    >>> from sbrdf_xr.store.writer import write_cube
    >>> ds = xr.Dataset(
    ...     {"v": (("x", "y"), da.zeros((4, 3), chunks=(2, 3)))},
    ...     coords={"x": [0.0, 1.0, 2.0, 3.0]},
    ...     attrs={"title": "demo"},
    ... )
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = write_cube(ds, Path(tmp) / "cube.nc", scheduler="synchronous")
    ...     print(check_finished(path, ds), check_finished(path, ds.assign_attrs(history="now")))
    ...     for other in (ds.isel(x=slice(0, 2)), ds.assign_attrs(title="other")):
    ...         try:
    ...             check_finished(path, other)
    ...         except CubeWriteError as exc:
    ...             print(str(exc).replace(tmp, "<tmp>"))
    None None
    <tmp>/cube.nc is a finished cube of other inputs (dims and sizes differ: {'x': 4, 'y': 3}
    in the file, {'x': 2, 'y': 3} now); nothing was resumed. Pass overwrite=True to replace it
    <tmp>/cube.nc is a finished cube of other inputs (global attribute 'title' differs);
    nothing was resumed. Pass overwrite=True to replace it
    """
    try:
        with netCDF4.Dataset(path) as nc:
            dims = {str(d): len(v) for d, v in nc.dimensions.items()}
            names = set(map(str, nc.variables))
            attrs = {k: nc.getncattr(k) for k in nc.ncattrs()}
    except OSError as exc:
        raise CubeWriteError(
            f"{path} exists and is not a readable netCDF cube ({exc}); pass {option('overwrite')} "
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
            f"Pass {option('overwrite')} to replace it"
        )
    _log.info("%s is already complete; there is nothing to resume", path)


def make_parent(path: Path) -> None:
    """Create the directory of ``path`` if it is missing (an error names why it cannot be).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.store.files import make_parent
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     make_parent(Path(tmp) / "runs" / "2026" / "cube.nc")
    ...     print((Path(tmp) / "runs" / "2026").is_dir())
    True
    """
    if not path.parent.exists():
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            why = error_words(exc) or str(exc)
            raise CubeWriteError(
                f"cannot write {path}: creating {path.parent} failed: {why}"
            ) from exc


def publish(part: Path, path: Path, overwrite: bool) -> None:
    """Rename the finished ``part`` to ``path``: replacing a regular file only with
    ``overwrite``, and without it only if nothing appeared there meanwhile.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.errors import CubeWriteError
    >>> from sbrdf_xr.store.files import publish
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     part, path = Path(tmp) / "cube.nc.part", Path(tmp) / "cube.nc"
    ...     _ = part.write_text("new cube")
    ...     _ = path.write_text("a cube written meanwhile")
    ...     try:
    ...         publish(part, path, overwrite=False)
    ...     except CubeWriteError as exc:
    ...         print(str(exc).split(";")[0].replace(tmp, "<tmp>"))
    ...     publish(part, path, overwrite=True)
    ...     print(path.read_text(), part.exists())
    <tmp>/cube.nc appeared while the cube was written
    new cube False
    """
    refuse_special([path], error=CubeWriteError)
    if overwrite:
        os.replace(part, path)
    else:
        try:
            rename_no_replace(part, path)
        except FileExistsError as exc:
            raise CubeWriteError(
                f"{path} appeared while the cube was written; it was not replaced and the "
                f"finished cube is kept in {part}: {again_hint()} and {option('overwrite')} to "
                "replace it"
            ) from exc
