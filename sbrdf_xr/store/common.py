"""Names shared by the cube writer's parts: file suffixes, errors, message style, events."""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import errno
import logging
import os
from pathlib import Path
from typing import Any

from ..errors import SbrdfError

_log = logging.getLogger("sbrdf_xr.write_cube")


#: Suffix of the temporary file the cube is written to before the final rename.
PART_SUFFIX = ".part"


#: Suffix of the bookkeeping sidecar (JSON lines) of an unfinished cube.
LOG_SUFFIX = ".part.jsonl"


#: Suffix of the exclusive writer lock held while a cube is being written.
LOCK_SUFFIX = ".lock"


_SYNC_NAMES = ("sync", "synchronous", "single-threaded")


_THREAD_NAMES = ("threads", "threading")


class CubeWriteError(SbrdfError):
    """A cube could not be written, or an unfinished ``.part`` cannot be resumed."""


class CubeLockedError(CubeWriteError):
    """Another writer holds the lock of this cube (``<path>.lock``)."""


class SchedulerError(SbrdfError):
    """A Dask scheduler address that is malformed or cannot be reached."""


#: Free space [byte] kept beyond a block's raw size for HDF5 metadata (chunk index,
#: object headers, superblock) written with it.
_SPACE_MARGIN = 256 * 2**10


#: Seconds a lock file without readable content counts as being created, not stale.
_LOCK_GRACE = 10.0


_STYLE: contextvars.ContextVar[str] = contextvars.ContextVar(
    "sbrdf_xr_option_style", default="python"
)


@contextlib.contextmanager
def command_line_messages() -> Any:
    """Within this context, messages name command-line options (``--resume``), not arguments.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import dask.array as da
    >>> import xarray as xr
    >>> from sbrdf_xr.store.common import command_line_messages
    >>> from sbrdf_xr.store.writer import write_cube
    >>> ds = xr.Dataset({"radiance": ("attitude", da.ones(4, chunks=2))})
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = Path(tmp) / "cube.nc"
    ...     _ = path.write_bytes(b"")  # a file already there: write_cube refuses to replace it
    ...     try:
    ...         write_cube(ds, path)
    ...     except FileExistsError as exc:
    ...         print(str(exc).split("; ")[1])
    ...     with command_line_messages():
    ...         try:
    ...             write_cube(ds, path)
    ...         except FileExistsError as exc:
    ...             print(str(exc).split("; ")[1])
    pass overwrite=True to replace it
    pass --overwrite to replace it
    """
    token = _STYLE.set("cli")
    try:
        yield
    finally:
        _STYLE.reset(token)


def _opt(name: str) -> str:
    """``--resume`` on the command line, ``resume=True`` in Python."""
    return f"--{name}" if _STYLE.get() == "cli" else f"{name}=True"


def _discard() -> str:
    if _STYLE.get() == "cli":
        return "run again with --overwrite (without --resume) to discard it and start again"
    return "pass overwrite=True, resume=False to discard it and start again"


def _again() -> str:
    if _STYLE.get() == "cli":
        return "run the same command again with --resume"
    return "call write_cube again with resume=True"


@dataclasses.dataclass(frozen=True)
class BlockWritten:
    """What :func:`write_cube` passes to ``on_block`` after each block is committed.

    Attributes
    ----------
    index : int
        Block number (C order over the grid of chunks).
    slices : dict of str to slice
        Position of the block along each chunked dimension.
    n_written : int
        Blocks committed so far, including those of an earlier, resumed run.
    n_blocks : int
        Blocks in the cube.
    in_flight : int
        Blocks submitted for computation but not yet written, after this one.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import dask.array as da
    >>> import xarray as xr
    >>> from sbrdf_xr.store.writer import write_cube
    >>> ds = xr.Dataset({"radiance": (("attitude", "wavelength"), da.ones((4, 3), chunks=(2, 3)))})
    >>> events = []
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = Path(tmp) / "cube.nc"
    ...     _ = write_cube(ds, path, scheduler="synchronous", on_block=events.append)
    >>> for e in events:
    ...     print(e.index, e.slices["attitude"], f"{e.n_written}/{e.n_blocks}", e.in_flight)
    0 slice(0, 2, None) 1/2 0
    1 slice(2, 4, None) 2/2 0
    """

    index: int
    slices: dict[str, slice]
    n_written: int
    n_blocks: int
    in_flight: int


def _reason(exc: BaseException, part: Path | None = None, need: int = 0) -> str:
    """The cause of an I/O failure in words ("no space left on device", ...); ``need``:
    bytes the file was still to grow by (its final size, when it was being created)."""
    code = getattr(exc, "errno", None)
    words = _ERRNO_WORDS.get(code) if isinstance(code, int) else None
    if words is None and part is not None:
        words = _diagnose(part, need)
    if words is None:
        return f"{type(exc).__name__}: {exc}"
    detail = getattr(exc, "strerror", None) if isinstance(exc, _NoRoom) else None
    return f"{words} ({detail})" if detail else words


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
}


_FIXES = {
    "no space left on device": "free some space",
    "file size limit exceeded": "raise the file size limit (ulimit -f)",
    "disk quota exceeded": "free some space within your quota",
}


def _fix(reason: str) -> str:
    return next((v for k, v in _FIXES.items() if reason.startswith(k)), "fix the cause")


def _diagnose(part: Path, need: int = 0) -> str | None:
    """Why a write into ``part`` may have failed when HDF5 does not say (it reports "HDF error")."""
    try:
        st = os.statvfs(part.parent)
        free = (st.f_bfree if os.geteuid() == 0 else st.f_bavail) * st.f_frsize
        if free < need + _SPACE_MARGIN:
            return "no space left on device"
    except (OSError, AttributeError):
        pass
    limit = _file_size_limit()
    try:
        size = part.stat().st_size
    except OSError:
        size = 0
    if limit is not None and size + need + _SPACE_MARGIN > limit:
        return "file size limit exceeded"
    return None


def _file_size_limit() -> int | None:
    try:
        import resource
    except ImportError:  # pragma: no cover - not on POSIX
        return None
    soft, _ = resource.getrlimit(resource.RLIMIT_FSIZE)
    return None if soft == resource.RLIM_INFINITY else int(soft)


class _NoRoom(OSError):
    """Raised before a write that would not fit: nothing was written."""


def libc_function(name: str, argtypes: list[Any], restype: Any) -> Any:
    """The C library's function ``name`` through ctypes (``errno`` kept), or None where
    the C library has no such function.

    Examples
    --------
    >>> import ctypes
    >>> from sbrdf_xr.store.common import libc_function
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


def _malloc_trim() -> Any:
    import ctypes

    return libc_function("malloc_trim", [ctypes.c_size_t], ctypes.c_int)


_MALLOC_TRIM = _malloc_trim()


def release_freed_memory() -> None:
    """Hand the memory this process has freed back to the operating system (glibc's
    ``malloc_trim(0)``; nothing elsewhere).

    Preparing a cube (the plan's geometry, the coordinates, the fingerprint's hashes)
    frees many block-sized temporaries that glibc keeps in its heap, where they count
    in the resident memory for the whole write.  The writer calls this once, before
    it streams the blocks; Dask's documentation recommends the same call for memory
    that was freed but not released.  On this project's 2-core machine it lowered a
    1e6-attitude write's peak resident memory by about 50 MiB.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.store.common import release_freed_memory
    >>> temporaries = [np.ones(2**16) for _ in range(16)]
    >>> del temporaries
    >>> release_freed_memory() is None  # nothing to return, and safe on any platform
    True
    """
    if _MALLOC_TRIM is not None:
        _MALLOC_TRIM(0)


def _mib(n: float) -> str:
    return f"{n / 2**20:.1f} MiB"
