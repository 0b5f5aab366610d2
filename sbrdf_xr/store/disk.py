"""Disk-durability primitives of the cube writers (see ``Durability`` in
:mod:`sbrdf_xr.store.writer`), and the words for their failures.

Room checked and reserved before a block is written (free space, ``RLIMIT_FSIZE``,
``fallocate``), a failed HDF5 write fenced off and cut back to the last synced state,
the page cache of written blocks dropped, and the cause of an I/O failure in words
(:func:`reason`) with what to do about it (:func:`fix`).  Where a file may be written at
all (special files, symbolic links, temporary names) is :mod:`sbrdf_xr._output`'s job.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import stat
import sys
from collections import deque
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path
from typing import Any

from .._output import error_words, io_failure, libc_function, write_all
from ..errors import CubeWriteError

__all__ = [
    "CHECK_SPACE",
    "FALLOCATE",
    "FALLOC_FL_KEEP_SIZE",
    "HEAD_BYTES",
    "SyncBehind",
    "abandon",
    "check_held",
    "check_opens",
    "check_room",
    "cut_back",
    "drop_behind",
    "fallocate_fn",
    "fence",
    "fix",
    "let_go",
    "reason",
    "reserve",
]

#: Whether each block's room on the file system is checked before it is written.
CHECK_SPACE = True
#: Bytes at the start of a ``.part`` (the HDF5 superblock) saved after each sync.
HEAD_BYTES = 4096
#: Free space [byte] kept beyond a block's raw size for HDF5 metadata (chunk index,
#: object headers, superblock) written with it.
_SPACE_MARGIN = 256 * 2**10


#: HDF5 handles abandoned after a failed write (:func:`abandon`), by (device, inode).
_ABANDONED: dict[tuple[int, int], Any] = {}


class _NoRoom(OSError):
    """Raised before a write that would not fit: nothing was written."""


def _mib(n: float) -> str:
    return f"{n / 2**20:.1f} MiB"


def _file_size_limit() -> int | None:
    try:
        import resource
    except ImportError:  # pragma: no cover - not on POSIX
        return None
    soft, _ = resource.getrlimit(resource.RLIMIT_FSIZE)
    return None if soft == resource.RLIM_INFINITY else int(soft)


def reason(exc: BaseException, part: Path | None = None, need: int = 0) -> str:
    """The cause of an I/O failure in words ("no space left on device", ...).

    HDF5 reports a failed write as "HDF error" without its cause; with ``part`` (the file
    being written) and ``need`` (bytes it was still to grow by) the cause is then
    diagnosed from the free space and the file size limit.

    Examples
    --------
    >>> import errno
    >>> from sbrdf_xr.store.disk import reason
    >>> reason(OSError(errno.EFBIG, "File too large"))
    'file size limit exceeded'
    >>> reason(RuntimeError("NetCDF: HDF error"))
    'RuntimeError: NetCDF: HDF error'
    """
    words = error_words(exc)
    if words is None and part is not None:
        words = _diagnose(part, need)
    if words is None:  # HDF5's "HDF error" with the free space and the size limit
        return io_failure(exc, part) if part is not None else f"{type(exc).__name__}: {exc}"
    detail = getattr(exc, "strerror", None) if isinstance(exc, _NoRoom) else None
    return f"{words} ({detail})" if detail else words


_FIXES = {
    "no space left on device": "free some space",
    "file size limit exceeded": "raise the file size limit (ulimit -f)",
    "disk quota exceeded": "free some space within your quota",
}


def fix(why: str) -> str:
    """What to do about a failure worded by :func:`reason`.

    Examples
    --------
    >>> from sbrdf_xr.store.disk import fix
    >>> fix("no space left on device (about 3.0 MiB needed, 1.0 MiB free on /tmp)")
    'free some space'
    >>> fix("RuntimeError: NetCDF: HDF error")
    'fix the cause'
    """
    if "HDF5 gives no cause" in why:
        return "free some space or raise the file size limit (ulimit -f), whichever is short,"
    return next((v for k, v in _FIXES.items() if why.startswith(k)), "fix the cause")


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


def check_room(part: Path, need: int) -> None:
    """Refuse, before writing, ``need`` bytes (plus metadata) that would not fit.

    Raises an :class:`OSError` with ``errno`` ``ENOSPC`` (not enough free space on the
    file system of ``part``) or ``EFBIG`` (``part`` would grow past ``RLIMIT_FSIZE``).

    Examples
    --------
    >>> import errno
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.store.disk import check_room
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     part = Path(tmp) / "cube.nc.part"
    ...     print(check_room(part, 4096))
    ...     try:
    ...         check_room(part, 2**62)  # 4 EiB: more than any disk holds
    ...     except OSError as exc:
    ...         print(errno.errorcode[exc.errno], str(exc).split(",")[0])
    None
    ENOSPC [Errno 28] about 4398046511104.2 MiB needed
    """
    if not CHECK_SPACE:
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


FALLOC_FL_KEEP_SIZE = 1


def fallocate_fn() -> Any:
    """The C library's ``fallocate(fd, mode, offset, length)`` through ctypes (0 on
    success, -1 with ``ctypes.get_errno()`` set on failure), or None without it.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.store.disk import FALLOC_FL_KEEP_SIZE, fallocate_fn
    >>> fallocate = fallocate_fn()
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     fd = os.open(Path(tmp) / "cube.nc.part", os.O_RDWR | os.O_CREAT)
    ...     try:
    ...         print(fallocate(fd, FALLOC_FL_KEEP_SIZE, 0, 2**20))
    ...         st = os.fstat(fd)
    ...     finally:
    ...         os.close(fd)
    0
    >>> st.st_size, st.st_blocks * 512 >= 2**20  # size unchanged, 1 MiB of disk allocated
    (0, True)
    """
    import ctypes

    return libc_function(
        "fallocate", [ctypes.c_int, ctypes.c_int, ctypes.c_int64, ctypes.c_int64], ctypes.c_int
    )


FALLOCATE = fallocate_fn() if sys.platform.startswith("linux") else None


def _allocate(fd: int, offset: int, length: int, what: str) -> None:
    """``fallocate`` ``length`` bytes from ``offset`` of the file open as ``fd`` (its size
    unchanged); a full disk, quota or size limit raises :class:`_NoRoom` naming ``what``."""
    if FALLOCATE is None or not CHECK_SPACE or length <= 0:
        return
    import ctypes

    if FALLOCATE(fd, FALLOC_FL_KEEP_SIZE, offset, length) != 0:
        code = ctypes.get_errno()
        if code in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG):
            raise _NoRoom(code, f"reserving {_mib(length)} {what} failed")


def reserve_file(fd: int) -> None:
    """Allocate the disk blocks of the whole file open as ``fd`` (its size unchanged).

    An uncompressed cube's variables are laid out whole when the ``.part`` is created
    (a sparse file of the cube's final size): reserving its holes finds a full disk
    before any block is computed.  Parts already allocated cost nothing; file systems
    without ``fallocate`` skip the reservation.
    """
    _allocate(fd, 0, os.fstat(fd).st_size, "for the cube on disk")


def reserve(fd: int, nbytes: int) -> None:
    """Reserve ``nbytes`` of disk beyond the end of the file open as ``fd`` (size unchanged).

    HDF5 appends each block at the end of the file; with the room already allocated
    a full disk is found here, before HDF5 writes anything, instead of in the middle
    of HDF5's flush.  File systems without ``fallocate`` skip the reservation.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.store.disk import reserve
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     fd = os.open(Path(tmp) / "cube.nc.part", os.O_RDWR | os.O_CREAT)
    ...     try:
    ...         _ = os.write(fd, b"superblock")
    ...         reserve(fd, 2**20)  # room for a 1 MiB block, past the end of the file
    ...         st = os.fstat(fd)
    ...     finally:
    ...         os.close(fd)
    >>> st.st_size, st.st_blocks * 512 >= 2**20 + 10
    (10, True)
    """
    _allocate(fd, os.fstat(fd).st_size, int(nbytes) + _SPACE_MARGIN, "for the next block")


def drop_behind(fd: int) -> None:
    """Let the kernel drop the page cache of the file open as ``fd`` (called after ``fsync``).

    Each block is on disk once synced, so its cached pages are clean and nobody reads
    them again during the write.  Dropping them after every block keeps the page
    cache the write occupies at about one block, whatever the cube's size, and hands
    the same pages to the next block.  Pages the kernel has to find anew cost far
    more than reused ones on virtual machines whose memory the host reclaims (free
    page reporting): on this project's 2-core machine a 225 MB cube written through
    fresh pages ran at about 300 MB/s, and about 2.5x faster with its pages dropped
    behind it.  A no-op where ``posix_fadvise`` is missing.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.store.disk import drop_behind
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     fd = os.open(Path(tmp) / "cube.nc.part", os.O_RDWR | os.O_CREAT)
    ...     try:
    ...         _ = os.write(fd, b"block 0")
    ...         os.fsync(fd)
    ...         drop_behind(fd)  # only the cache goes: the synced data stay
    ...         print(os.pread(fd, 7, 0))
    ...     finally:
    ...         os.close(fd)
    b'block 0'
    """
    advise = getattr(os, "posix_fadvise", None)
    if advise is not None:
        with contextlib.suppress(OSError):
            advise(fd, 0, 0, os.POSIX_FADV_DONTNEED)


class SyncBehind:
    """Blocks to disk in a thread of their own, in order, while the writer writes the next.

    For each block submitted: the cube file ``fsync``-ed and its page cache dropped
    (:func:`drop_behind`), then the block's line appended to the log and the log
    ``fsync``-ed, so a block reaches the log only once its data are on disk.  After a
    failed sync nothing more is logged (a later ``fsync`` may succeed although data
    were lost).  The writing thread takes each block back with :meth:`wait_oldest`,
    which raises that block's ``OSError``.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.store.disk import SyncBehind
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     fd = os.open(Path(tmp) / "cube.nc.part", os.O_RDWR | os.O_CREAT)
    ...     log_fd = os.open(Path(tmp) / "cube.nc.part.jsonl", os.O_WRONLY | os.O_CREAT)
    ...     sync = SyncBehind(fd, log_fd)
    ...     try:
    ...         for k in range(3):
    ...             _ = os.write(fd, b"block")  # block k written to the cube file
    ...             sync.submit(k)  # synced and logged while the next one is written
    ...         print([sync.wait_oldest() for _ in range(3)])
    ...     finally:
    ...         sync.close()
    ...         os.close(fd)
    ...         os.close(log_fd)
    ...     print((Path(tmp) / "cube.nc.part.jsonl").read_text(), end="")
    [0, 1, 2]
    {"block": 0}
    {"block": 1}
    {"block": 2}
    """

    def __init__(self, fd: int, log_fd: int) -> None:
        self.fd, self.log_fd = fd, log_fd
        self.pool = ThreadPoolExecutor(1, thread_name_prefix="write_cube_sync")
        self.pending: deque[tuple[int, Future[None]]] = deque()
        self.failed = False

    def submit(self, k: int) -> None:
        """Queue block ``k``, whose data the HDF5 library has just flushed to the file."""
        self.pending.append((k, self.pool.submit(self._to_disk, k)))

    def _to_disk(self, k: int) -> None:
        if self.failed:
            raise OSError(errno.EIO, "an earlier block could not be synced")
        try:
            os.fsync(self.fd)
            drop_behind(self.fd)
            write_all(self.log_fd, (json.dumps({"block": k}) + "\n").encode())
            os.fsync(self.log_fd)
        except BaseException:
            self.failed = True
            raise

    def wait_oldest(self) -> int:
        """Wait for the oldest queued block to be on disk and logged; return its index."""
        k, fut = self.pending.popleft()
        fut.result()
        return k

    def settle(self) -> list[int]:
        """Wait for every queued block (after a failure elsewhere); the ones logged."""
        logged = []
        while self.pending:
            k, fut = self.pending.popleft()
            with contextlib.suppress(Exception):
                fut.result()
                logged.append(k)
        return logged

    def close(self) -> None:
        self.pool.shutdown(wait=True)


def fence(part: Path) -> None:
    """Make every read-write descriptor of ``part`` in this process read-only.

    After a failed write HDF5 still holds dirty metadata of the failed block; were it
    flushed (on close, or at exit), it would overwrite the last synced state in place
    and point it at data that never reached the disk.  Replacing HDF5's descriptor by
    a read-only one on the same file makes those writes fail harmlessly, so the file
    can be cut back to its last synced size.  (Linux: descriptors found in /proc.)

    Examples
    --------
    >>> import errno
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.store.disk import fence
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     part = Path(tmp) / "cube.nc.part"
    ...     _ = part.write_bytes(b"synced")
    ...     fd = os.open(part, os.O_RDWR)  # as HDF5 holds it
    ...     try:
    ...         fence(part)
    ...         try:
    ...             os.write(fd, b"torn metadata")
    ...         except OSError as exc:
    ...             print(errno.errorcode[exc.errno])
    ...         print(os.pread(fd, 6, 0))  # still readable
    ...     finally:
    ...         os.close(fd)
    ...     print(part.read_bytes())
    EBADF
    b'synced'
    b'synced'
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


def cut_back(part: Path, size: int, head: bytes) -> str | None:
    """Restore ``part`` to its last synced state: its ``size`` and its first bytes ``head``.

    HDF5 rewrites its superblock (at the start of the file, holding the end-of-file
    address) in place when a write fails; the rest of the synced file is untouched
    (blocks are appended).  Returns None if the file then opens, else why not.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import netCDF4
    >>> from sbrdf_xr.store.disk import HEAD_BYTES, cut_back
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     part = Path(tmp) / "cube.nc.part"
    ...     with netCDF4.Dataset(part, "w") as nc:
    ...         _ = nc.createDimension("attitude", 3)
    ...         nc.createVariable("radiance", "f4", ("attitude",))[:] = [1.0, 2.0, 3.0]
    ...     size, head = part.stat().st_size, part.read_bytes()[:HEAD_BYTES]  # last synced
    ...     with open(part, "r+b") as f:  # a failed write: superblock torn, bytes appended
    ...         _ = f.write(bytes(64))
    ...         _ = f.seek(0, 2)
    ...         _ = f.write(b"x" * 1000)
    ...     print(cut_back(part, size, head), part.stat().st_size == size)
    ...     with netCDF4.Dataset(part) as nc:
    ...         print(nc["radiance"][:].tolist())
    None True
    [1.0, 2.0, 3.0]
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
    return check_opens(part)


def abandon(handle: Any, part: Path) -> None:
    """Keep ``handle`` (a netCDF4 Dataset whose write failed) open and untouched for the
    life of the process: no further HDF5 call, not even at exit.

    Closing a file whose descriptor was fenced (:func:`fence`) can crash HDF5; an
    abandoned handle is referenced for ever (so its finaliser, which would close it,
    never runs) and its ``(device, inode)`` is remembered: HDF5 would share the open
    handle with any new open of the same file, so this process must not reopen it
    (:func:`check_held`).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.errors import CubeWriteError
    >>> from sbrdf_xr.store.disk import abandon, check_held
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     part = Path(tmp) / "cube.nc.part"
    ...     _ = part.write_bytes(b"synced")
    ...     check_held(part)  # nothing abandoned: no error
    ...     abandon(object(), part)
    ...     try:
    ...         check_held(part)
    ...     except CubeWriteError as exc:
    ...         print(str(exc).replace(tmp, "<tmp>"))
    HDF5 in this process still holds <tmp>/cube.nc.part since a write of it failed; continue
    it from a new process
    """
    import ctypes

    with contextlib.suppress(OSError):
        st = part.stat()
        _ABANDONED[(st.st_dev, st.st_ino)] = handle
    ctypes.pythonapi.Py_IncRef(ctypes.py_object(handle))  # never finalised, even at exit


def let_go(nc: Any, part: Path, torn: bool) -> None:
    """Let go of the HDF5 handle ``nc`` of ``part`` after an I/O failure, never crashing.

    Outside an HDF5 call (``torn`` false: a reservation, a sync or the bookkeeping
    failed) HDF5's state is the synced file and it is closed as usual (its close rewrites
    the superblock in place).  After a failed HDF5 write its metadata in memory may be
    torn: its descriptor is made read-only (:func:`fence`) and the handle is abandoned
    without another HDF5 call (:func:`abandon`), because closing a fenced file can crash
    HDF5 (a segmentation fault in its error path, found by fault injection at each step
    of the layout).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import netCDF4
    >>> from sbrdf_xr.store.disk import let_go
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     nc = netCDF4.Dataset(Path(tmp) / "c.nc.part", "w")
    ...     nc.sync()
    ...     let_go(nc, Path(tmp) / "c.nc.part", torn=False)  # synced: closed as usual
    ...     print(nc.isopen())
    False
    """
    if nc is None:
        return
    if torn:
        fence(part)
        abandon(nc, part)
    else:
        with contextlib.suppress(Exception):
            nc.close()


def check_held(part: Path) -> None:
    """Raise :class:`~sbrdf_xr.errors.CubeWriteError` if ``part`` is a file whose HDF5
    handle this process abandoned (:func:`abandon`); reopening it here would share that
    handle's torn state.

    Examples
    --------
    >>> from pathlib import Path
    >>> from sbrdf_xr.store.disk import check_held
    >>> check_held(Path("no-such-cube.nc.part")) is None
    True
    """
    try:
        st = part.stat()
    except OSError:
        return
    if (st.st_dev, st.st_ino) in _ABANDONED:
        raise CubeWriteError(
            f"HDF5 in this process still holds {part} since a write of it failed; "
            "continue it from a new process"
        )


def check_opens(part: Path) -> str | None:
    """None if ``part`` opens as netCDF in a fresh process (this one's HDF5 may still hold it).

    Otherwise the last line of that process's error output says why not.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import netCDF4
    >>> from sbrdf_xr.store.disk import check_opens
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     good, bad = Path(tmp) / "good.nc", Path(tmp) / "bad.nc"
    ...     netCDF4.Dataset(good, "w").close()
    ...     _ = bad.write_bytes(b"not a netCDF file")
    ...     print(check_opens(good))
    ...     print(check_opens(bad).rsplit(":", 1)[0])  # the file's name follows
    None
    OSError: [Errno -51] NetCDF: Unknown file format
    """
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
