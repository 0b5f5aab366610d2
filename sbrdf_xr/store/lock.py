"""The exclusive writer lock of a cube (``<path>.lock``), for netCDF and Zarr alike.

flock where the file system has it, a PID file otherwise, stale locks taken over; anything
at ``<path>.lock`` that is not a regular file (a FIFO, symbolic link, device, directory)
is refused, never opened.
"""

from __future__ import annotations

import contextlib
import datetime
import json
import logging
import os
import socket
import stat
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from .._output import file_kind, write_all
from ..errors import CubeLockedError, CubeWriteError
from .disk import reason

#: Suffix of the exclusive writer lock held while a cube is being written.
LOCK_SUFFIX = ".lock"
#: Seconds a lock file without readable content counts as being created, not stale.
_LOCK_GRACE = 10.0

_log = logging.getLogger("sbrdf_xr.write_cube")


def _pid_alive(pid: Any) -> bool:
    if not isinstance(pid, int) or pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    except (OverflowError, OSError):
        return False
    return True


def _try_flock(fd: int) -> bool | None:
    """True if this process now holds ``flock`` on ``fd``.

    False if another holds it, None if unsupported.
    """
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not on POSIX
        return None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    except OSError:
        return None
    return True


_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)


class _Lock:
    """Exclusive writer lock of one cube: ``<path>.lock``.

    Taken by creating the file atomically (``O_CREAT | O_EXCL``), holding ``flock`` on
    it for the life of the write, and recording the holder's pid, host and start
    time inside.  A lock left by a writer that died (SIGKILL, power loss) is stale:
    on the same host its pid is no longer running and nobody holds its ``flock``;
    it is then removed with a logged message.  A lock from another host is never
    removed automatically (its pid cannot be checked from here).
    """

    def __init__(self, path: Path, target: Path) -> None:
        self.path, self.target = path, target
        self.fd = -1
        self.ino = -1

    def acquire(self) -> None:
        for _ in range(8):
            kind = file_kind(self.path)
            if kind not in (None, "file"):
                raise CubeWriteError(
                    f"{self.path} is {kind}, not a regular file, where the lock of "
                    f"{self.target} goes; it was left as it is. Remove it, or choose another "
                    "output"
                )
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_EXCL | _NOFOLLOW, 0o644)
            except FileExistsError:
                self._clear_stale()
                continue
            except OSError as exc:
                raise CubeWriteError(
                    f"cannot write {self.target}: creating the lock {self.path} "
                    f"failed: {reason(exc)}"
                ) from exc
            try:
                for _ in range(50):  # a stale-lock check may hold it for an instant
                    if _try_flock(fd) is not False:
                        break
                    time.sleep(0.01)
                info = {
                    "pid": os.getpid(),
                    "host": socket.gethostname(),
                    "cube": str(self.target),
                    "started": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
                }
                write_all(fd, (json.dumps(info) + "\n").encode())
                os.fsync(fd)
                self.ino = os.fstat(fd).st_ino
            except BaseException as exc:
                os.close(fd)
                with contextlib.suppress(OSError):
                    os.unlink(self.path)
                if isinstance(exc, OSError):
                    raise CubeWriteError(
                        f"cannot write {self.target}: writing the lock {self.path} "
                        f"failed: {reason(exc, self.path)}"
                    ) from exc
                raise
            self.fd = fd
            return
        raise CubeLockedError(
            f"{self.target}: the lock {self.path} keeps being taken by other writers"
        )

    def _locked(self, info: Mapping[str, Any] | None) -> CubeLockedError:
        who = (
            f"pid {info.get('pid')} on host {info.get('host')}, started {info.get('started')}"
            if info
            else "a writer that is starting"
        )
        return CubeLockedError(
            f"{self.target} is being written by another writer ({who}; lock {self.path}); "
            "wait for it to finish or stop it, or write to another file"
        )

    def _clear_stale(self) -> None:
        try:
            fd = os.open(self.path, os.O_RDWR | _NOFOLLOW | os.O_NONBLOCK)
        except FileNotFoundError:
            return
        except OSError as exc:
            raise CubeLockedError(
                f"{self.path} exists and cannot be used as a lock ({reason(exc)}); "
                f"remove it if no writer of {self.target} is running"
            ) from exc
        try:
            st = os.fstat(fd)
            if not stat.S_ISREG(st.st_mode):
                raise CubeWriteError(
                    f"{self.path} is {file_kind(self.path)}, not a regular file, where the lock "
                    f"of {self.target} goes; it was left as it is. Remove it, or choose another "
                    "output"
                )
            held = _try_flock(fd)
            raw = os.pread(fd, 4096, 0) if hasattr(os, "pread") else b""
            try:
                info = json.loads(raw.decode())
                info = info if isinstance(info, dict) else None
            except (ValueError, UnicodeDecodeError):
                info = None
            if held is False:
                raise self._locked(info)
            if info is None and held and not self._still_empty(fd):
                return  # a writer took it meanwhile: looked at again
            if info is None:
                if not held and time.time() - st.st_mtime < _LOCK_GRACE:
                    raise self._locked(None)
                why = "it names no owner" + (" and no writer holds it" if held else "")
            else:
                pid, host = info.get("pid"), info.get("host")
                if host != socket.gethostname():
                    raise CubeLockedError(
                        f"{self.target} is locked by pid {pid} on host {host} (started "
                        f"{info.get('started')}); whether that writer still runs cannot be checked "
                        f"from {socket.gethostname()}. If it does not, remove {self.path} "
                        "and try again"
                    )
                if held is None and _pid_alive(pid):
                    raise self._locked(info)
                why = (
                    f"its writer, pid {pid} started {info.get('started')}, is no longer running"
                    if not _pid_alive(pid)
                    else f"pid {pid} no longer holds it"
                )
            try:
                same = os.stat(self.path, follow_symlinks=False).st_ino == st.st_ino
            except FileNotFoundError:
                return
            if same:
                os.unlink(self.path)
                _log.warning("removed the stale lock %s: %s (an interrupted write)", self.path, why)
        finally:
            os.close(fd)

    @staticmethod
    def _still_empty(fd: int) -> bool:
        """An empty lock whose ``flock`` was free: free and empty still after its creator's
        time to take the ``flock`` (``acquire`` retries for 0.5 s), so none is starting."""
        import fcntl

        fcntl.flock(fd, fcntl.LOCK_UN)
        time.sleep(0.6)
        if _try_flock(fd) is False:
            return False
        return not os.pread(fd, 4096, 0).strip()

    def release(self) -> None:
        if self.fd < 0:
            return
        try:
            with contextlib.suppress(OSError):
                if os.stat(self.path, follow_symlinks=False).st_ino == self.ino:
                    os.unlink(self.path)
        finally:
            os.close(self.fd)
            self.fd = -1
