"""Every file the package writes is put on disk here, safely.

The rules, the same for every output (cubes in netCDF and Zarr, material and model
tables, photometry files and CSVs, inversion results, benchmark tables, figures):

* **Only regular files are replaced**, and directories the package wrote itself (a Zarr
  store, marked by a :data:`MARKER` file inside).  A FIFO, socket, device node, symbolic
  link (dangling or not), or a directory where a file is expected (or a file where a
  directory is), at the output path or at one of its siblings by name (``.part``,
  ``.lock``, the ``.part.jsonl`` sidecar), is refused with an error that names the path
  and what is there (:func:`refuse_special`), with or without ``overwrite``.
* **Nothing that this process did not create is opened for writing.**  An output is
  written to a new temporary file beside it, created with ``O_CREAT | O_EXCL |
  O_NOFOLLOW`` (:func:`atomic_file`), and renamed over the output when complete: a FIFO
  is never opened (no hang), a symbolic link never followed, and the old output stays
  intact until the new one is whole.  Files that are reopened (a ``.part`` being
  resumed, a lock) are opened with :func:`open_regular`, which refuses anything but a
  regular file without blocking.
* **An existing output is replaced only when asked** (``overwrite``); without it the
  final rename refuses to replace anything, even a file that appeared meanwhile
  (:func:`rename_no_replace`).
* **A directory is deleted only if it carries the package's marker**
  (:func:`remove_marked_dir`); anything else is refused with a message saying how to
  proceed.

Messages name Python arguments (``overwrite=True``) or, inside
:func:`command_line_messages`, command-line options (``--overwrite``).
"""

from __future__ import annotations

import contextlib
import contextvars
import errno
import json
import os
import shutil
import stat
import tempfile
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path
from typing import Any

from .errors import OutputError

__all__ = [
    "MARKER",
    "WRITER",
    "atomic_file",
    "check_output",
    "command_line_messages",
    "error_words",
    "file_kind",
    "fsync_dir",
    "fsync_tree",
    "holds_nothing",
    "io_failure",
    "libc_function",
    "make_marked_dir",
    "netcdf_encoding",
    "open_regular",
    "option",
    "read_marker",
    "refuse_special",
    "remove_marked_dir",
    "rename_no_replace",
    "replace_dir",
    "write_all",
    "write_marker",
    "write_netcdf",
]

#: File that marks a directory written by this package (a Zarr store, or its ``.part``).
MARKER = ".sbrdf_xr.json"
#: The ``writer`` recorded in every :data:`MARKER`.
WRITER = "sbrdf_xr"
#: The ``state`` :func:`read_marker` gives a :data:`MARKER` of the package cut short (by a
#: disk that filled while it was written, before writes were checked to be complete).
TORN = "torn"

_STYLE: contextvars.ContextVar[str] = contextvars.ContextVar(
    "sbrdf_xr_option_style", default="python"
)


@contextlib.contextmanager
def command_line_messages() -> Iterator[None]:
    """Within this context, messages name command-line options (``--overwrite``), not arguments.

    Examples
    --------
    >>> from sbrdf_xr._output import command_line_messages, option
    >>> option("overwrite")
    'overwrite=True'
    >>> with command_line_messages():
    ...     option("overwrite")
    '--overwrite'
    """
    token = _STYLE.set("cli")
    try:
        yield
    finally:
        _STYLE.reset(token)


def option(name: str) -> str:
    """``--name`` on the command line (:func:`command_line_messages`), ``name=True`` in Python.

    Examples
    --------
    >>> from sbrdf_xr._output import option
    >>> option("resume")
    'resume=True'
    """
    return f"--{name}" if _STYLE.get() == "cli" else f"{name}=True"


def cli_style() -> bool:
    """Whether messages are worded for the command line (see :func:`command_line_messages`)."""
    return _STYLE.get() == "cli"


_ERRNO_WORDS = {
    errno.ENOSPC: "no space left on device",
    errno.EFBIG: "file size limit exceeded",
    errno.EDQUOT: "disk quota exceeded",
    errno.EACCES: "permission denied",
    errno.EPERM: "operation not permitted",
    errno.EROFS: "read-only file system",
    errno.EIO: "input/output error",
    errno.ENOENT: "no such file or directory",
    errno.ENOTDIR: "not a directory",
    errno.EISDIR: "is a directory",
    errno.ELOOP: "a symbolic link is in the way",
    errno.ENAMETOOLONG: "file name too long",
}


def error_words(exc: BaseException) -> str | None:
    """The cause of an I/O failure in words ("no space left on device"), or None if unknown.

    Examples
    --------
    >>> import errno
    >>> from sbrdf_xr._output import error_words
    >>> error_words(OSError(errno.ENOSPC, "No space left on device"))
    'no space left on device'
    >>> error_words(ValueError("not an I/O error")) is None
    True
    """
    code = getattr(exc, "errno", None)
    return _ERRNO_WORDS.get(code) if isinstance(code, int) else None


def io_failure(exc: BaseException, path: str | os.PathLike[str]) -> str:
    """The cause of a failed write into ``path`` in words: :func:`error_words`, else the
    error itself; HDF5's "HDF error", which gives no cause, with its usual ones measured
    (the free space of ``path``'s directory by ``shutil.disk_usage``, the file size limit).

    Examples
    --------
    >>> from sbrdf_xr._output import io_failure
    >>> text = io_failure(RuntimeError("NetCDF: HDF error"), "/tmp/cube.nc")
    >>> print(text.split("; ")[0])
    RuntimeError: NetCDF: HDF error: HDF5 gives no cause
    >>> print(text.split("; ")[1].split(" (")[0])
    most likely the disk filled or the file size limit was reached
    >>> io_failure(OSError(errno.ENOSPC, "No space left on device"), "/tmp/cube.nc")
    'no space left on device'
    """
    text = error_words(exc) or f"{type(exc).__name__}: {exc}"
    if "HDF error" not in str(exc):
        return text
    try:
        free = f"{shutil.disk_usage(Path(path).parent).free / 2**20:.1f} MiB free"
    except OSError:
        free = "free space unknown"
    import resource

    soft = resource.getrlimit(resource.RLIMIT_FSIZE)[0]
    limit = "none" if soft == resource.RLIM_INFINITY else f"{soft / 2**20:.3g} MiB"
    return (
        f"{text}: HDF5 gives no cause; most likely the disk filled or the file size limit "
        f"was reached ({free} on {Path(path).parent}, file size limit {limit}, writing {path})"
    )


def file_kind(p: str | os.PathLike[str]) -> str | None:
    """None if nothing is at ``p``, ``"file"`` for a regular file, else what it is.

    A symbolic link is reported as such (it is not followed), dangling or not.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr._output import file_kind
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     d = Path(tmp)
    ...     _ = (d / "cube.nc").write_bytes(b"")
    ...     (d / "link.nc").symlink_to(d / "cube.nc")
    ...     os.mkfifo(d / "pipe.nc")
    ...     for name in ("missing.nc", "cube.nc", "link.nc", "pipe.nc", "."):
    ...         print(name, file_kind(d / name))
    missing.nc None
    cube.nc file
    link.nc a symbolic link
    pipe.nc a FIFO (named pipe)
    . a directory
    """
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


def refuse_special(
    paths: Iterable[str | os.PathLike[str]],
    *,
    directory: bool = False,
    error: type[OutputError] = OutputError,
) -> None:
    """Raise ``error`` for anything at ``paths`` that is not a regular file (or, with
    ``directory``, not a directory), naming the path and what is there.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr._output import refuse_special
    >>> from sbrdf_xr.errors import OutputError
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     out = Path(tmp) / "phot.nc"
    ...     refuse_special([out])  # nothing there: nothing to refuse
    ...     out.symlink_to("/etc/passwd")
    ...     try:
    ...         refuse_special([out])
    ...     except OutputError as exc:
    ...         print(str(exc).replace(tmp, "<tmp>"))
    <tmp>/phot.nc is a symbolic link, not a regular file; outputs replace only regular files,
    even with overwrite=True. Remove it or choose another output
    """
    for p in paths:
        kind = file_kind(p)
        if kind is None or kind == ("a directory" if directory else "file"):
            continue
        if directory:
            raise error(
                f"{p} is {'a regular file' if kind == 'file' else kind}, not a directory; "
                f"a Zarr store replaces only a directory sbrdf_xr wrote, even with "
                f"{option('overwrite')}. Remove it or choose another output"
            )
        raise error(
            f"{p} is {kind}, not a regular file; outputs replace only regular files, even "
            f"with {option('overwrite')}. Remove it or choose another output"
        )


def check_output(
    path: str | os.PathLike[str],
    *,
    overwrite: bool = False,
    siblings: Iterable[str | os.PathLike[str]] = (),
    error: type[OutputError] = OutputError,
) -> Path:
    """Refuse an output before anything is computed: a name that names no file, a special
    file at ``path`` or ``siblings`` (:func:`refuse_special`), or an existing ``path``
    without ``overwrite`` (:class:`FileExistsError`).

    Returns
    -------
    pathlib.Path
        ``path``.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr._output import check_output
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     out = Path(tmp) / "phot.csv"
    ...     print(check_output(out) == out)
    ...     _ = out.write_text("band,mag\\n")
    ...     print(check_output(out, overwrite=True) == out)
    ...     try:
    ...         check_output(out)
    ...     except FileExistsError as exc:
    ...         print(str(exc).replace(tmp, "<tmp>"))
    True
    True
    <tmp>/phot.csv exists; pass overwrite=True to replace it
    """
    path = Path(path)
    if path.name in ("", ".", "..") or str(path).endswith(os.sep):
        raise error(f"{str(path)!r} names no file; give a file name for the output")
    refuse_special([path, *siblings], error=error)
    if file_kind(path) is not None and not overwrite:
        raise FileExistsError(f"{path} exists; pass {option('overwrite')} to replace it")
    return path


def _make_parent(path: Path, error: type[OutputError]) -> None:
    if file_kind(path.parent) is None:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            why = error_words(exc) or str(exc)
            raise error(f"cannot write {path}: creating {path.parent} failed: {why}") from exc


@contextlib.contextmanager
def atomic_file(
    path: str | os.PathLike[str],
    *,
    overwrite: bool = False,
    error: type[OutputError] = OutputError,
) -> Iterator[Path]:
    """Write ``path`` through a new temporary file beside it, renamed over it when complete.

    Checks ``path`` first (:func:`check_output`), then yields the temporary file (created
    empty, ``O_CREAT | O_EXCL | O_NOFOLLOW``, named ``<name>.<random>.part``) for the
    caller to write by name.  When the block ends without error the file is given the
    usual permissions (``0o666`` less the umask), synced to disk and renamed to ``path``
    (without ``overwrite``, only if nothing appeared there meanwhile); on any error it
    is removed and ``path`` is left as it was.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr._output import atomic_file
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     out = Path(tmp) / "table.csv"
    ...     with atomic_file(out) as part:
    ...         _ = part.write_text("a,b\\n1,2\\n")
    ...         print(os.listdir(tmp) == [part.name], part.name.startswith("table.csv."))
    ...     print(os.listdir(tmp), out.read_text().splitlines())
    ...     try:
    ...         with atomic_file(out, overwrite=True) as part:
    ...             _ = part.write_text("half a tab")
    ...             raise RuntimeError("the writer failed")
    ...     except RuntimeError:
    ...         print(os.listdir(tmp), out.read_text().splitlines())  # the old file, intact
    True True
    ['table.csv'] ['a,b', '1,2']
    ['table.csv'] ['a,b', '1,2']
    """
    path = check_output(path, overwrite=overwrite, error=error)
    _make_parent(path, error)
    try:
        fd, name = tempfile.mkstemp(prefix=f"{path.name}.", suffix=".part", dir=path.parent)
    except OSError as exc:
        why = error_words(exc) or str(exc)
        raise error(f"cannot write {path}: {why}") from exc
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        fd = open_regular(tmp, os.O_RDONLY, error=error)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        refuse_special([path], error=error)
        if overwrite:
            os.replace(tmp, path)
        else:
            rename_no_replace(tmp, path)
        fsync_dir(path.parent)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def netcdf_encoding(ds: Any, complevel: int = 4) -> dict[str, dict[str, Any]]:
    """The netCDF encoding of :func:`write_netcdf`: no fill values anywhere; lossless zlib
    compression with byte shuffle of the floating-point data variables (none for
    ``complevel`` 0).

    Examples
    --------
    >>> import xarray as xr
    >>> from sbrdf_xr._output import netcdf_encoding
    >>> ds = xr.Dataset({"v": ("x", [1.0, 2.0])}, coords={"x": [0, 1]})
    >>> netcdf_encoding(ds)["v"]
    {'_FillValue': None, 'zlib': True, 'complevel': 4, 'shuffle': True}
    >>> netcdf_encoding(ds, complevel=0)["v"], netcdf_encoding(ds)["x"]
    ({'_FillValue': None}, {'_FillValue': None})
    """
    import numpy as np

    enc: dict[str, dict[str, Any]] = {str(name): {"_FillValue": None} for name in ds.variables}
    for name, var in ds.data_vars.items():
        if var.ndim and np.issubdtype(var.dtype, np.floating) and complevel > 0:
            enc[str(name)].update(zlib=True, complevel=complevel, shuffle=True)
    return enc


def write_netcdf(
    ds: Any,
    path: str | os.PathLike[str],
    *,
    overwrite: bool = False,
    complevel: int = 4,
    error: type[OutputError] = OutputError,
) -> Path:
    """Write the xarray Dataset ``ds`` as CF netCDF-4 through :func:`atomic_file`: the CF
    and ACDD attributes completed (:func:`sbrdf_xr._names.cf_finish`), the encoding of
    :func:`netcdf_encoding`, the output checked first (:func:`check_output`).

    Returns
    -------
    pathlib.Path
        ``path``.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> import xarray as xr
    >>> from sbrdf_xr._output import write_netcdf
    >>> from sbrdf_xr.errors import OutputError
    >>> ds = xr.Dataset({"v": ("x", [1.0, 2.0])})
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     out = write_netcdf(ds, Path(tmp) / "v.nc")
    ...     with xr.open_dataset(out) as back:
    ...         print(back.v.values.tolist(), back.attrs["Conventions"])
    ...     os.mkfifo(Path(tmp) / "pipe.nc")
    ...     try:
    ...         write_netcdf(ds, Path(tmp) / "pipe.nc", overwrite=True)
    ...     except OutputError as exc:
    ...         print(str(exc).split(tmp)[1].split(";")[0])
    [1.0, 2.0] CF-1.10
    /pipe.nc is a FIFO (named pipe), not a regular file
    """
    from ._names import cf_finish

    path = check_output(path, overwrite=overwrite, error=error)
    ds = cf_finish(ds)  # Conventions, title, source, history, flags, ancillary links
    with atomic_file(path, overwrite=overwrite, error=error) as tmp:
        try:
            ds.to_netcdf(tmp, engine="netcdf4", encoding=netcdf_encoding(ds, complevel))
        except (OSError, RuntimeError) as exc:  # netCDF4 raises RuntimeError for HDF5's
            raise error(f"cannot write {path}: {io_failure(exc, tmp)}; nothing replaced") from exc
    return path


_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)


def open_regular(
    path: str | os.PathLike[str],
    flags: int,
    mode: int = 0o644,
    *,
    error: type[OutputError] = OutputError,
) -> int:
    """``os.open`` that opens only a regular file: never follows a symbolic link, never
    blocks on a FIFO (``O_NONBLOCK`` until the file is known to be regular).

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr._output import open_regular
    >>> from sbrdf_xr.errors import OutputError
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     fd = open_regular(Path(tmp) / "log", os.O_WRONLY | os.O_CREAT)
    ...     os.close(fd)
    ...     os.mkfifo(Path(tmp) / "pipe")
    ...     try:  # a plain open for writing would wait for a reader for ever
    ...         open_regular(Path(tmp) / "pipe", os.O_WRONLY | os.O_APPEND)
    ...     except OutputError as exc:
    ...         print(str(exc).split(tmp)[1])
    /pipe is a FIFO (named pipe), not a regular file; nothing was opened
    """
    try:
        fd = os.open(path, flags | _NOFOLLOW | os.O_NONBLOCK, mode)
    except OSError as exc:
        kind = file_kind(path)
        if kind not in (None, "file"):
            raise error(f"{path} is {kind}, not a regular file; nothing was opened") from exc
        raise
    st = os.fstat(fd)
    if not stat.S_ISREG(st.st_mode):
        os.close(fd)
        raise error(f"{path} is {file_kind(path)}, not a regular file; nothing was opened")
    os.set_blocking(fd, True)
    return fd


def fsync_dir(directory: str | os.PathLike[str]) -> None:
    """``fsync`` ``directory``, so that a file created, renamed or removed in it stays so
    after a crash; a directory that cannot be opened is skipped without error.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr._output import fsync_dir
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     _ = (Path(tmp) / "cube.nc.part").write_bytes(b"data")
    ...     os.replace(Path(tmp) / "cube.nc.part", Path(tmp) / "cube.nc")
    ...     fsync_dir(Path(tmp))  # the rename is now durable
    ...     fsync_dir(Path(tmp) / "missing")  # nothing to sync: no error
    ...     print(os.listdir(tmp))
    ['cube.nc']
    """
    with contextlib.suppress(OSError):
        fd = os.open(directory, os.O_RDONLY | os.O_DIRECTORY | _NOFOLLOW)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def fsync_tree(directory: str | os.PathLike[str]) -> None:
    """``fsync`` every regular file and directory under ``directory`` (itself included).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr._output import fsync_tree
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     _ = (Path(tmp) / "a").mkdir()
    ...     _ = (Path(tmp) / "a" / "0.0").write_bytes(b"chunk")
    ...     fsync_tree(tmp)  # both levels and the chunk are on disk
    ...     print((Path(tmp) / "a" / "0.0").read_bytes())
    b'chunk'
    """
    for root, _, files in os.walk(directory):
        for name in files:
            with contextlib.suppress(OSError, OutputError):
                fd = open_regular(Path(root) / name, os.O_RDONLY)
                try:
                    os.fsync(fd)
                finally:
                    os.close(fd)
        fsync_dir(root)


def libc_function(name: str, argtypes: list[Any], restype: Any) -> Any:
    """The C library's function ``name`` through ctypes (``errno`` kept), or None where
    the C library has no such function.

    Examples
    --------
    >>> import ctypes
    >>> from sbrdf_xr._output import libc_function
    >>> strlen = libc_function("strlen", [ctypes.c_char_p], ctypes.c_size_t)
    >>> strlen(b"spectral")
    8
    >>> libc_function("no_such_libc_function", [], ctypes.c_int) is None
    True
    """
    try:
        import ctypes
        import ctypes.util

        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        fn = getattr(libc, name)
    except (OSError, AttributeError):  # pragma: no cover - not glibc
        return None
    fn.argtypes = argtypes
    fn.restype = restype
    return fn


def _renameat2() -> Any:
    import ctypes

    return libc_function(
        "renameat2",
        [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint],
        ctypes.c_int,
    )


_RENAMEAT2 = _renameat2()
_AT_FDCWD = -100
_RENAME_NOREPLACE, _RENAME_EXCHANGE = 1, 2


def _rename2(src: Path, dst: Path, flags: int) -> bool:
    """``renameat2(src, dst, flags)``: True if done, False where unsupported; raises the
    :class:`OSError` of any other failure."""
    if _RENAMEAT2 is None:  # pragma: no cover - not glibc >= 2.28
        return False
    import ctypes

    if _RENAMEAT2(_AT_FDCWD, os.fsencode(src), _AT_FDCWD, os.fsencode(dst), flags) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.EINVAL, errno.ENOSYS, errno.ENOTSUP):
        return False
    raise OSError(code, os.strerror(code), str(dst))


def rename_no_replace(src: str | os.PathLike[str], dst: str | os.PathLike[str]) -> None:
    """Rename ``src`` to ``dst`` atomically, refusing (:class:`FileExistsError`) if
    anything is at ``dst``: ``renameat2(RENAME_NOREPLACE)``, or a hard link for a file
    where the file system lacks it.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr._output import rename_no_replace
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     a, b, c = (Path(tmp) / n for n in ("a.part", "b", "c"))
    ...     for p in (a, b):
    ...         _ = p.write_text(p.name)
    ...     try:
    ...         rename_no_replace(a, b)
    ...     except FileExistsError:
    ...         print("b was kept:", b.read_text())
    ...     rename_no_replace(a, c)
    ...     print(sorted(os.listdir(tmp)), c.read_text())
    b was kept: b
    ['b', 'c'] a.part
    """
    src, dst = Path(src), Path(dst)
    if _rename2(src, dst, _RENAME_NOREPLACE):
        return
    if file_kind(src) == "file":
        os.link(src, dst)  # FileExistsError if dst exists
        os.unlink(src)
        return
    if file_kind(dst) is not None:
        raise FileExistsError(errno.EEXIST, "File exists", str(dst))
    os.rename(src, dst)


def replace_dir(
    src: str | os.PathLike[str],
    dst: str | os.PathLike[str],
    *,
    error: type[OutputError] = OutputError,
) -> None:
    """Put the directory ``src`` (marked, :data:`MARKER`) at ``dst``, replacing a marked
    directory there: exchanged atomically (``renameat2(RENAME_EXCHANGE)``) and then
    deleted, so that ``dst`` is at every instant the old directory or the new one.
    Without that call the old one is moved aside to ``<dst>.replaced`` first.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr._output import make_marked_dir, replace_dir
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     old, new = Path(tmp) / "cube.zarr", Path(tmp) / "cube.zarr.part"
    ...     for d in (old, new):
    ...         make_marked_dir(d, {"name": d.name})
    ...     replace_dir(new, old)
    ...     print(os.listdir(tmp), sorted(os.listdir(old)))
    ['cube.zarr'] ['.sbrdf_xr.json']
    """
    src, dst = Path(src), Path(dst)
    if file_kind(dst) is None:
        rename_no_replace(src, dst)
    elif file_kind(dst) != "a directory" or read_marker(dst) is None:
        remove_marked_dir(dst, error=error)  # refuses: not a directory the package wrote
    elif _rename2(src, dst, _RENAME_EXCHANGE):
        remove_marked_dir(src, error=error)
    else:  # pragma: no cover - no renameat2
        aside = dst.with_name(dst.name + ".replaced")
        remove_marked_dir(aside, error=error)
        os.rename(dst, aside)
        os.rename(src, dst)
        remove_marked_dir(aside, error=error)
    fsync_dir(dst.parent)


def write_marker(directory: str | os.PathLike[str], info: Mapping[str, Any]) -> None:
    """Write (or replace, atomically) the :data:`MARKER` of ``directory``: ``info`` and the
    package as its ``writer``, as JSON, synced to disk.

    Examples
    --------
    >>> import json
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr._output import MARKER, write_marker
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     write_marker(tmp, {"state": "writing"})
    ...     print(json.loads((Path(tmp) / MARKER).read_text()))
    {'writer': 'sbrdf_xr', 'state': 'writing'}
    """
    d = Path(directory)
    fd, name = tempfile.mkstemp(prefix=f"{MARKER}.", suffix=".part", dir=d)
    # the writer first: even a marker cut short names the package
    record = {"writer": WRITER, **{k: info[k] for k in sorted(info) if k != "writer"}}
    try:
        write_all(fd, (json.dumps(record) + "\n").encode())
        os.fsync(fd)
    except BaseException:
        os.close(fd)
        Path(name).unlink(missing_ok=True)
        raise
    else:
        os.close(fd)
    try:
        os.replace(name, d / MARKER)
    except BaseException:
        Path(name).unlink(missing_ok=True)
        raise
    fsync_dir(d)


def write_all(fd: int, data: bytes) -> None:
    """``os.write`` ``data`` to ``fd`` whole: a short write (a disk filling up) is
    continued, and a write that makes no progress raises ``OSError(ENOSPC)``.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr._output import write_all
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     fd = os.open(Path(tmp) / "log", os.O_WRONLY | os.O_CREAT)
    ...     write_all(fd, b"x" * 100_000)
    ...     os.close(fd)
    ...     print((Path(tmp) / "log").stat().st_size)
    100000
    """
    view = memoryview(data)
    while view:
        n = os.write(fd, view)
        if n <= 0:
            raise OSError(errno.ENOSPC, "No space left on device (a write made no progress)")
        view = view[n:]


def read_marker(
    directory: str | os.PathLike[str], *, strict: bool = False
) -> dict[str, Any] | None:
    """The :data:`MARKER` of ``directory`` if the package wrote it, else None.

    A marker of the package cut short (no longer JSON) gives ``{"writer": "sbrdf_xr",
    "state": "torn"}`` (:data:`TORN`): the directory is the package's, its content unknown.
    With ``strict`` a marker that cannot be opened or read raises instead of giving None.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr._output import read_marker, write_marker
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     print(read_marker(tmp))
    ...     write_marker(tmp, {"state": "complete"})
    ...     print(read_marker(tmp)["state"])
    ...     whole = (Path(tmp) / ".sbrdf_xr.json").read_bytes()
    ...     _ = (Path(tmp) / ".sbrdf_xr.json").write_bytes(whole[:40])  # cut short
    ...     print(read_marker(tmp))
    None
    complete
    {'writer': 'sbrdf_xr', 'state': 'torn'}
    """
    try:
        fd = open_regular(Path(directory) / MARKER, os.O_RDONLY)
        with os.fdopen(fd, "rb") as f:
            raw = f.read(2**24)
    except (OSError, OutputError):
        if strict:  # an I/O failure raised, for its cause to be named
            raise
        return None
    try:
        info = json.loads(raw.decode())
    except (ValueError, UnicodeDecodeError):
        # cut short: the package's own if it begins as the package writes markers (the
        # writer first; before that, sorted keys with this package's format early on)
        ours = raw.startswith(b'{"writer": "%s"' % WRITER.encode()) or (
            raw.startswith(b'{"block_dims": ') and b'"format": "sbrdf_xr.' in raw[:4096]
        )
        return {"writer": WRITER, "state": TORN} if ours else None
    return info if isinstance(info, dict) and info.get("writer") == WRITER else None


def holds_nothing(directory: str | os.PathLike[str]) -> bool:
    """Whether ``directory`` is empty but for a :data:`MARKER` being written (the state
    :func:`make_marked_dir` leaves when it is interrupted): nothing in it is anyone's data.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr._output import holds_nothing
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     print(holds_nothing(tmp))
    ...     _ = (Path(tmp) / ".sbrdf_xr.json.k3j9x0.part").write_text('{"writ')
    ...     print(holds_nothing(tmp))
    ...     _ = (Path(tmp) / "notes.txt").write_text("mine")
    ...     print(holds_nothing(tmp))
    True
    True
    False
    """
    try:
        names = os.listdir(directory)
    except OSError:
        return False
    return all(
        n.startswith(MARKER + ".")
        and n.endswith(".part")
        and file_kind(Path(directory) / n) == "file"
        for n in names
    )


def make_marked_dir(path: str | os.PathLike[str], info: Mapping[str, Any]) -> None:
    """Create the directory ``path`` (it must not exist) and mark it with ``info``.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr._output import make_marked_dir
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     make_marked_dir(Path(tmp) / "cube.zarr.part", {"state": "creating"})
    ...     print(os.listdir(Path(tmp) / "cube.zarr.part"))
    ['.sbrdf_xr.json']
    """
    os.mkdir(path)
    write_marker(path, info)


def remove_marked_dir(
    path: str | os.PathLike[str],
    *,
    empty_ok: bool = False,
    error: type[OutputError] = OutputError,
) -> None:
    """Delete the directory ``path`` if the package wrote it (it carries the package's
    :data:`MARKER`); with ``empty_ok`` an empty directory too, or one that holds only a
    marker being written (:func:`holds_nothing`: nothing is lost).  Anything else is
    refused with ``error``, and nothing is deleted.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr._output import make_marked_dir, remove_marked_dir
    >>> from sbrdf_xr.errors import OutputError
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     ours, theirs = Path(tmp) / "ours.zarr", Path(tmp) / "photos.zarr"
    ...     make_marked_dir(ours, {})
    ...     theirs.mkdir()
    ...     _ = (theirs / "holiday.jpg").write_bytes(b"...")
    ...     remove_marked_dir(ours)
    ...     try:
    ...         remove_marked_dir(theirs)
    ...     except OutputError as exc:
    ...         print(str(exc).replace(tmp, "<tmp>"))
    ...     print(os.listdir(tmp))
    <tmp>/photos.zarr is a directory that sbrdf_xr did not write (it holds no .sbrdf_xr.json);
    it was left as it is. Move or remove it yourself, or choose another output
    ['photos.zarr']
    """
    p = Path(path)
    kind = file_kind(p)
    if kind is None:
        return
    if kind != "a directory":
        refuse_special([p], directory=True, error=error)
    if read_marker(p) is None:
        if empty_ok and holds_nothing(p):
            with contextlib.suppress(OSError):
                for name in os.listdir(p):  # only the package's own marker, half-written
                    os.unlink(p / name)
                os.rmdir(p)  # fails unless empty
                return
        raise error(
            f"{p} is a directory that sbrdf_xr did not write (it holds no {MARKER}); it was "
            "left as it is. Move or remove it yourself, or choose another output"
        )
    # the marker last: a removal that fails half-way leaves a directory still marked
    for _ in range(5):  # what a writer's last in-flight stores add meanwhile, again
        for entry in os.scandir(p):
            if entry.name == MARKER:
                continue
            if entry.is_dir(follow_symlinks=False):
                shutil.rmtree(entry.path, ignore_errors=True)
            else:
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(entry.path)
        if os.listdir(p) == [MARKER]:
            break
    os.unlink(p / MARKER)
    os.rmdir(p)
    fsync_dir(p.parent)
