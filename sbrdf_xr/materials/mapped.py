"""Catalog tables memory-mapped from the table cache: one copy in memory for every process.

A table the cache keeps (:mod:`sbrdf_xr.materials.cache`, a netCDF file ``T.nc``) gets,
the first time it is loaded in a dtype, its values as a plain NumPy file beside it
(``T.nc.float64.npy``) and the rest of the table (coordinates, attributes, dimension
order) with the record of that file (``T.nc.float64.meta``, netCDF): the SHA-256 of the
values' dtype, shape and bytes (the digest the engine's content fingerprint takes of a
table's values, :mod:`sbrdf_xr.engine.fingerprint`), the file's size and modification
time (and those of ``T.nc``: a table file changed since makes both anew).  Later loads
map the values file read-only (``numpy.load(..., mmap_mode="r")``)
instead of reading the table into memory: every process on the machine, and every Dask
worker, then shares the same pages of the operating system's file cache, and only the
pages a sweep reads are ever resident.

A plan that travels to a Dask worker carries a :class:`MappedSlice` (the file, its
digest, and which bytes of it) for each table instead of the arrays
(:func:`share` / :func:`restore`); the worker maps the file itself.  A values file that
changed on disk since it was recorded (a size or modification time that differs and
values whose digest no longer matches) raises
:class:`~sbrdf_xr.errors.TableFileChangedError`, naming the file and both digests.

Examples
--------
>>> import os, tempfile
>>> from pathlib import Path
>>> import numpy as np
>>> from sbrdf_xr.materials import mapped
>>> from sbrdf_xr.materials.files import open_material, to_netcdf
>>> from sbrdf_xr.materials.schema import lambertian
>>> tmp = Path(tempfile.mkdtemp())
>>> path = to_netcdf(lambertian(0.5, [500.0, 600.0], material="grey"), tmp / "grey.nc")
>>> table = mapped.mapped_table(path, open_material, "float64")
>>> type(mapped.mapping_of(table.values)).__name__, table.values.flags.writeable
('TableFile', False)
>>> bool(table.identical(open_material(path)))
True
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import xarray as xr

from .._output import atomic_file
from ..errors import OutputError, TableFileChangedError
from .schema import VALUES_CHECKED

__all__ = [
    "MappedSlice",
    "TableFile",
    "mapped_table",
    "mapping_of",
    "open_values",
    "recorded_digest",
    "restore",
    "share",
    "validated",
    "values_digest",
]


class TableFile(NamedTuple):
    """A values file of the table cache, as it was recorded: the handle a plan carries.

    Attributes
    ----------
    path : str
        The ``.npy`` file.
    sha256 : str
        SHA-256 of the values' dtype, shape and bytes (:func:`values_digest`).
    size : int
        The file's size when recorded [byte].
    mtime_ns : int
        Its modification time when recorded [ns].
    dtype : str
        The values' dtype (``float64`` or ``float32``).
    shape : tuple of int
        The values' shape.

    Examples
    --------
    >>> from sbrdf_xr.materials.mapped import TableFile
    >>> TableFile("t.npy", "ab" * 32, 1024, 0, "float64", (2, 2, 2, 3))._fields[:2]
    ('path', 'sha256')
    """

    path: str
    sha256: str
    size: int
    mtime_ns: int
    dtype: str
    shape: tuple[int, ...]


class MappedSlice(NamedTuple):
    """An array that views a mapped values file, by position: what pickles in its place.

    Attributes
    ----------
    file : TableFile
        The mapped file.
    offset : int
        Offset of the array's first element in the values [byte].
    shape : tuple of int
        The array's shape.
    strides : tuple of int
        The array's strides [byte].
    dtype : str
        The array's dtype.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials.mapped import MappedSlice, share
    >>> a = np.zeros(3)
    >>> share(a) is a  # an array in memory is pickled as itself
    True
    >>> MappedSlice._fields
    ('file', 'offset', 'shape', 'strides', 'dtype')
    """

    file: TableFile
    offset: int
    shape: tuple[int, ...]
    strides: tuple[int, ...]
    dtype: str


#: id(mmap) -> (the file, the mapped array) of every values file this process mapped.
_BY_MAP: dict[int, tuple[TableFile, np.ndarray]] = {}
#: (path, sha256) -> the mapped array: each file is mapped once per process.
_BY_FILE: dict[tuple[str, str], np.ndarray] = {}
#: (path, sha256) -> (size, mtime_ns) of a file whose values were hashed and matched.
_VERIFIED: dict[tuple[str, str], tuple[int, int]] = {}
_LOCK = threading.Lock()
#: Bytes hashed at a time when a values file is checked against its record.
_CHUNK = 2**24


def values_digest(values: np.ndarray) -> str:
    """SHA-256 of an array's dtype, shape and values, as the engine's content fingerprint
    takes it of a table's values.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials.mapped import values_digest
    >>> a = np.arange(6.0).reshape(2, 3)
    >>> values_digest(a) == values_digest(a.copy()), values_digest(a) == values_digest(a.T)
    (True, False)
    """
    arr = np.ascontiguousarray(values)
    h = hashlib.sha256(f"{arr.dtype.str}{arr.shape}".encode())
    h.update(arr.data.cast("B"))
    return h.hexdigest()


def _file_digest(path: Path) -> str:
    """:func:`values_digest` of a values file, read in chunks (never mapped: hashing a
    file makes none of its pages resident in this process)."""
    fmt = np.lib.format
    with open(path, "rb") as f:
        version = fmt.read_magic(f)
        header = fmt.read_array_header_1_0 if version == (1, 0) else fmt.read_array_header_2_0
        got_shape, fortran, got_dtype = header(f)
        layout = " F" if fortran else ""  # another layout: other values in effect
        h = hashlib.sha256(f"{got_dtype.str}{tuple(got_shape)}{layout}".encode())
        for chunk in iter(lambda: f.read(_CHUNK), b""):
            h.update(chunk)
    return h.hexdigest()


def _files(path: Path, dtype: str) -> tuple[Path, Path]:
    return path.with_name(f"{path.name}.{dtype}.npy"), path.with_name(f"{path.name}.{dtype}.meta")


def open_values(file: TableFile) -> np.ndarray:
    """The values of ``file``, mapped read-only (once per process), checked against its
    record.

    Raises
    ------
    TableFileChangedError
        The file's size or modification time differ from the record and its values'
        digest no longer matches (the file was rewritten or replaced), or it is gone.

    Examples
    --------
    >>> import os, tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.materials import mapped
    >>> from sbrdf_xr.materials.files import open_material, to_netcdf
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> tmp = Path(tempfile.mkdtemp())
    >>> path = to_netcdf(lambertian(0.5, [500.0, 600.0], material="grey"), tmp / "grey.nc")
    >>> file = mapped.mapping_of(mapped.mapped_table(path, open_material, "float64").values)
    >>> mapped.open_values(file).shape == file.shape
    True
    >>> changed = file._replace(path=str(tmp / "gone.npy"))
    >>> mapped.open_values(changed)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.TableFileChangedError: table values file .../gone.npy: gone ...
    """
    key = (file.path, file.sha256)
    with _LOCK:
        hit = _BY_FILE.get(key)
    if hit is not None:
        return hit
    _check(file)
    arr = np.load(file.path, mmap_mode="r", allow_pickle=False)
    if arr.dtype != np.dtype(file.dtype) or arr.shape != tuple(file.shape):
        raise TableFileChangedError(
            f"table values file {file.path}: holds {arr.dtype} {arr.shape}, recorded as "
            f"{file.dtype} {tuple(file.shape)}; load the material again"
        )
    with _LOCK:
        if key not in _BY_FILE:
            _BY_FILE[key] = arr
            _BY_MAP[id(arr._mmap)] = (file, arr)
        return _BY_FILE[key]


def _check(file: TableFile) -> None:
    """TableFileChangedError unless ``file`` still holds the values it was recorded with
    (its size and modification time unchanged, or else its digest)."""
    p = Path(file.path)
    try:
        st = p.stat()
    except OSError as exc:
        raise TableFileChangedError(
            f"table values file {p}: gone ({type(exc).__name__}); it held the values of "
            f"digest {file.sha256[:16]}...: the table cache was pruned or cleared since "
            "the scene was planned (sbrdf-xr cache prune, or a table build pruning the "
            "tables unused for SBRDF_XR_CACHE_KEEP_DAYS days); restart the process that "
            "planned the scene (it keeps the table it loaded) and plan it again: loading "
            "the material rebuilds the file"
        ) from None
    stat = (st.st_size, st.st_mtime_ns)
    if stat == (file.size, file.mtime_ns) or _VERIFIED.get((file.path, file.sha256)) == stat:
        return
    now = _file_digest(p)
    if now == file.sha256:  # the same values written again (two processes caching at once)
        _VERIFIED[(file.path, file.sha256)] = stat
        return
    raise TableFileChangedError(
        f"table values file {p}: changed on disk since it was recorded (its values' "
        f"digest is {now[:16]}..., recorded {file.sha256[:16]}...); load the material "
        "again and plan the scene anew"
    )


def mapping_of(a: Any) -> TableFile | None:
    """The values file ``a`` views (mapped by this module), or None.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials.mapped import mapping_of
    >>> mapping_of(np.zeros(2)) is None
    True
    """
    found = _mapped(a)
    return None if found is None else found[0]


def validated(a: Any) -> bool:
    """Whether ``a`` views a mapped values file: its values were checked (finite,
    non-negative) when the file was written from a validated table, and the file is
    checked unchanged (:func:`recorded_digest`) whenever its digest is taken.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials.mapped import validated
    >>> validated(np.zeros(2))
    False
    """
    return _mapped(a) is not None


VALUES_CHECKED.append(validated)


def _mapped(a: Any) -> tuple[TableFile, np.ndarray] | None:
    base: Any = a
    while isinstance(base, np.ndarray):
        base = base.base
    if base is None:
        return None
    with _LOCK:
        return _BY_MAP.get(id(base))


def recorded_digest(a: Any) -> str | None:
    """The recorded :func:`values_digest` of ``a`` when it is a whole mapped values file
    (its bytes not read again), else None.

    Raises
    ------
    TableFileChangedError
        The file changed on disk since it was mapped (:func:`open_values`).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.materials import mapped
    >>> from sbrdf_xr.materials.files import open_material, to_netcdf
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> tmp = Path(tempfile.mkdtemp())
    >>> path = to_netcdf(lambertian(0.5, [500.0, 600.0], material="grey"), tmp / "grey.nc")
    >>> values = mapped.mapped_table(path, open_material, "float64").values
    >>> mapped.recorded_digest(values) == mapped.values_digest(values)
    True
    >>> mapped.recorded_digest(values[:1]) is None  # a part of it is hashed as usual
    True
    """
    found = _mapped(a)
    if found is None or not isinstance(a, np.ndarray):
        return None
    file, whole = found
    if (
        a.shape != whole.shape
        or a.dtype != whole.dtype
        or not a.flags.c_contiguous
        or a.__array_interface__["data"][0] != whole.__array_interface__["data"][0]
    ):
        return None
    _check(file)
    return file.sha256


def share(a: Any) -> Any:
    """``a`` as a :class:`MappedSlice` when it views a mapped values file (what a plan
    pickles in place of its tables), else ``a`` itself.

    Examples
    --------
    >>> import pickle, tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.materials import mapped
    >>> from sbrdf_xr.materials.files import open_material, to_netcdf
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> tmp = Path(tempfile.mkdtemp())
    >>> path = to_netcdf(lambertian(0.5, [500.0, 600.0], material="grey"), tmp / "grey.nc")
    >>> values = mapped.mapped_table(path, open_material, "float64").values
    >>> rows = values.reshape(-1, 2)[1:]
    >>> handle = mapped.share(rows)
    >>> type(handle).__name__, handle.offset, len(pickle.dumps(handle)) < 1000
    ('MappedSlice', 16, True)
    >>> back = mapped.restore(pickle.loads(pickle.dumps(handle)))
    >>> bool((back == rows).all()), back.flags.writeable
    (True, False)
    """
    found = _mapped(a)
    if found is None or not isinstance(a, np.ndarray):
        return a
    file, whole = found
    offset = a.__array_interface__["data"][0] - whole.__array_interface__["data"][0]
    return MappedSlice(file, int(offset), a.shape, a.strides, a.dtype.str)


def restore(x: Any) -> Any:
    """The array a :class:`MappedSlice` stands for (its file mapped here), else ``x``.

    Examples
    --------
    >>> from sbrdf_xr.materials.mapped import restore
    >>> restore(3.0)
    3.0
    """
    if not isinstance(x, MappedSlice):
        return x
    whole = open_values(x.file)
    return np.ndarray(x.shape, np.dtype(x.dtype), buffer=whole, offset=x.offset, strides=x.strides)


def mapped_table(
    path: str | os.PathLike[str], read: Callable[[Path], xr.DataArray], dtype: str
) -> xr.DataArray:
    """The table of cache file ``path`` with its values memory-mapped in ``dtype``.

    The first call writes the values file and its record beside ``path`` from
    ``read(path)`` (which validates the table); later calls read only the record and
    coordinates and map the values.  When the directory cannot be written the table is
    ``read(path)`` in memory.

    Parameters
    ----------
    path : path-like
        A table file of the cache.
    read : callable
        Reads the table from ``path`` (the cache's reader).
    dtype : str
        ``float64`` or ``float32``.

    Returns
    -------
    xarray.DataArray
        Values read-only, identical to ``read(path)`` cast to ``dtype``.

    Examples
    --------
    See the module's example.

    >>> from sbrdf_xr.materials.mapped import mapped_table
    >>> callable(mapped_table)
    True
    """
    path = Path(path)
    npy, meta = _files(path, dtype)
    with contextlib.suppress(OSError, ValueError, KeyError, TableFileChangedError):
        return _open_table(path, npy, meta)
    table = read(path)
    try:
        _write_table(table, path, npy, meta, dtype)
        return _open_table(path, npy, meta)
    except (OSError, OutputError, TableFileChangedError):  # a read-only cache: in memory
        return table if table.dtype == np.dtype(dtype) else table.astype(dtype)


def _stat(path: Path) -> str:
    st = path.stat()
    return f"{st.st_size} {st.st_mtime_ns} {st.st_ino}"


def _write_table(table: xr.DataArray, path: Path, npy: Path, meta: Path, dtype: str) -> None:
    values = np.ascontiguousarray(table.values, dtype=dtype)
    with atomic_file(npy, overwrite=True) as tmp:
        with open(tmp, "wb") as f:
            np.lib.format.write_array(f, values, allow_pickle=False)
    st = npy.stat()
    record = {
        "sha256": values_digest(values),
        "size": st.st_size,
        "mtime_ns": str(st.st_mtime_ns),
        "dtype": dtype,
        "shape": json.dumps(list(values.shape)),
        "dims": json.dumps([str(d) for d in table.dims]),
        "name": "" if table.name is None else str(table.name),
        "table": _stat(path),  # the table file it was made from, as it was
    }
    skeleton = xr.Dataset({"table": ((), 0, dict(table.attrs))}, coords=table.coords)
    skeleton.attrs = {f"values_{k}": v for k, v in record.items()}
    with atomic_file(meta, overwrite=True) as tmp:
        skeleton.to_netcdf(tmp, engine="netcdf4")


def _open_table(path: Path, npy: Path, meta: Path) -> xr.DataArray:
    with xr.open_dataset(meta, engine="netcdf4") as ds:
        skeleton = ds.load()
    r = {k.removeprefix("values_"): v for k, v in skeleton.attrs.items()}
    if r["table"] != _stat(path):
        raise ValueError(f"{path} changed since {meta} was made from it")
    file = TableFile(
        str(npy),
        str(r["sha256"]),
        int(r["size"]),
        int(r["mtime_ns"]),
        str(r["dtype"]),
        tuple(json.loads(r["shape"])),
    )
    values = open_values(file)
    coords = {k: v.variable for k, v in skeleton.coords.items()}
    name = str(r["name"]) or None
    attrs = dict(skeleton["table"].attrs)
    da = xr.DataArray(values, coords=coords, dims=json.loads(r["dims"]), name=name, attrs=attrs)
    for v in da.coords.variables.values():  # read-only through and through, as the values
        if not isinstance(v, xr.IndexVariable) and isinstance(v.data, np.ndarray):
            v.data.flags.writeable = False
    return da
