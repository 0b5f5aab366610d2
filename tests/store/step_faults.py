"""Deterministic fault injection at every step of a cube's write (run by ``test_steps.py``).

Run as a script in a fresh process: ``python step_faults.py '{"mode": ..., ...}'``.  The
process builds a small cube (2 blocks), then forks one child per trial so that every
trial starts from the same state:

``count``
    One undisturbed write, counting its steps: the calls of ``os`` that create, write,
    sync, rename or truncate files (:data:`OS_CALLS`), the ``fallocate`` reservations and
    the opening of netCDF files, each numbered in the thread that makes it (the writing
    thread, and the thread that syncs blocks behind it).
``raise``
    For each step: that call fails with ``ENOSPC`` (a disk that fills at that instant),
    then a fresh child resumes the write without faults.
``kill``
    For each step: the process ends at that call (``os._exit``, no clean-up: as a
    ``SIGKILL``), then a fresh child resumes.
``limit``
    For each size from 0 to the finished file's in ``stride`` bytes: the file-size limit
    (``RLIMIT_FSIZE``, ``SIGXFSZ`` ignored, so writes past it fail with ``EFBIG`` as a full
    disk fails them with ``ENOSPC``) is set to it with the room check off, so the limit is
    met inside HDF5's own writes of the layout; then a fresh child resumes.

One JSON line is printed per trial: how the faulty write ended (its exit status, named
error or not, message), the files left, and whether the resume gave the reference cube.
"""

from __future__ import annotations

import errno
import json
import os
import resource
import signal
import sys
import tempfile
import threading
import types
import warnings
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent), str(HERE.parents[1])]

import dask  # noqa: E402
import numpy as np  # noqa: E402
import xarray as xr  # noqa: E402

from sbrdf_xr import _output  # noqa: E402
from sbrdf_xr.errors import SbrdfError  # noqa: E402
from sbrdf_xr.store import disk, files  # noqa: E402
from sbrdf_xr.store import write as write_any  # noqa: E402

#: The ``os`` calls that change files: each is a step at which a disk can fill or a
#: writer be killed.
OS_CALLS = ("open", "write", "pwrite", "fsync", "replace", "rename", "ftruncate", "mkdir")
#: Calls that are steps only for a kill: a full disk does not fail them.
KILL_ONLY = ("unlink", "rmdir")
#: Exit status of a child ended at a step (as a killed writer ends).
KILLED = 137


def cube() -> xr.Dataset:
    """2 blocks of 2 attitudes x 3 phase angles x 20 wavelengths."""
    from test_writer import make_cube

    return make_cube(n_attitude=4, n_phase=3, n_wavelength=20, chunks=(2, 3))


class Steps:
    """Counts the steps of a write per thread; fails or ends the process at one of them."""

    def __init__(self, at: tuple[str, int] | None = None, action: str = "raise") -> None:
        self.at, self.action = at, action
        self.counts: dict[str, int] = {}
        self.names: dict[str, list[str]] = {}
        self.lock = threading.Lock()

    def step(self, name: str) -> None:
        role = "main" if threading.current_thread() is threading.main_thread() else "sync"
        with self.lock:
            k = self.counts.get(role, 0)
            self.counts[role] = k + 1
            self.names.setdefault(role, []).append(name)
        if self.at == (role, k):
            if self.action == "kill":
                os._exit(KILLED)
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    def wrap(self, name: str, fn):
        def wrapped(*args, **kwargs):
            self.step(name)
            return fn(*args, **kwargs)

        return wrapped

    def install(self) -> None:
        for name in OS_CALLS + (KILL_ONLY if self.action == "kill" else ()):
            setattr(os, name, self.wrap(f"os.{name}", getattr(os, name)))
        disk._allocate = self.wrap("fallocate", disk._allocate)
        _output._rename2 = self.wrap("renameat2", _output._rename2)
        import netCDF4

        files.netCDF4 = types.SimpleNamespace(Dataset=self.wrap("netCDF4.Dataset", netCDF4.Dataset))


def in_child(fn) -> tuple[int, dict]:
    """Run ``fn`` (returning a dict) in a forked child: its exit status and its dict."""
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        os.close(r)
        try:
            out = fn()
        except BaseException as exc:
            out = {"ok": False, "error": f"{type(exc).__name__}: {exc}"}
        os.write(w, json.dumps(out).encode())
        os._exit(0)
    os.close(w)
    chunks = []
    while data := os.read(r, 65536):
        chunks.append(data)
    os.close(r)
    _, status = os.waitpid(pid, 0)
    text = b"".join(chunks).decode()
    return os.waitstatus_to_exitcode(status), json.loads(text) if text else {}


def faulty_write(path: Path, args: dict, steps: Steps | None, limit: int | None) -> dict:
    if limit is not None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, resource.RLIM_INFINITY))
        disk.CHECK_SPACE = False  # the room is taken after it was checked
    if steps is not None:
        steps.install()
    try:
        write_any(cube(), path, scheduler="synchronous", complevel=args.get("complevel"))
        out: dict = {"ok": True}
    except Exception as exc:
        out = {"ok": False, "named": isinstance(exc, SbrdfError), "error": type(exc).__name__}
        out["message"] = str(exc)
    if steps is not None:
        out["counts"] = steps.counts
        out["names"] = steps.names
    return out


def resumed(path: Path, args: dict, reference: dict[str, np.ndarray]) -> dict:
    """Resume; should the resume say the ``.part`` cannot be continued and to discard it
    (a compressed ``.part`` whose HDF5 write failed mid-block), do so, and say it."""
    level = args.get("complevel")
    discarded = False
    try:
        write_any(cube(), path, scheduler="synchronous", complevel=level, resume=True)
    except SbrdfError as exc:
        if "overwrite=True, resume=False to discard it" not in str(exc):
            raise
        write_any(cube(), path, scheduler="synchronous", complevel=level, overwrite=True)
        discarded = True
    opener = xr.open_zarr if path.suffix == ".zarr" else xr.open_dataset
    with opener(path) as back:
        same = all(np.array_equal(back[k].values, v) for k, v in reference.items())
        same = same and set(map(str, back.variables)) == set(reference)
    return {"ok": True, "identical": bool(same), "discarded": discarded}


def main() -> None:
    warnings.simplefilter("ignore")
    args = json.loads(sys.argv[1])
    dask.config.set(scheduler="synchronous")
    ref = {str(k): np.asarray(v.values) for k, v in cube().compute().variables.items()}
    root = Path(tempfile.mkdtemp(prefix="step_faults_", dir=args["tmp"]))
    name = "c" + args.get("suffix", ".nc")
    mode = args["mode"]
    if mode in ("count", "raise", "kill"):
        (root / "count").mkdir()  # as every trial's directory
        action = args.get("action", "raise") if mode == "count" else mode
        status, counted = in_child(
            lambda: faulty_write(root / "count" / name, args, Steps(None, action), None)
        )
        assert status == 0 and counted.get("ok"), (status, counted)
        if mode == "count":
            print(json.dumps(counted))
            return
        stride = int(args.get("stride", 1))
        trials = [
            (role, k)
            for role, n in sorted(counted["counts"].items())
            for k in range(0, n, stride)
            if role in args.get("roles", ("main", "sync"))
        ]
        names = counted["names"]
    else:
        stride = int(args["stride"])
        status, whole = in_child(lambda: faulty_write(root / "whole" / name, args, None, None))
        assert status == 0 and whole.get("ok"), (status, whole)
        size = sum(p.stat().st_size for p in (root / "whole").rglob("*") if p.is_file())
        trials = [("limit", n) for n in range(0, size + stride, stride)]
    for role, k in trials:
        d = root / f"{role}{k}"
        d.mkdir()
        path = d / name
        if mode == "limit":
            status, out = in_child(lambda p=path, n=k: faulty_write(p, args, None, n))
            step = f"file size limit {k} B"
        else:
            steps = Steps((role, k), mode)
            status, out = in_child(lambda p=path, s=steps: faulty_write(p, args, s, None))
            step = f"{role} step {k}: {names[role][k]}"
        left = sorted(p.name for p in d.iterdir())
        status2, again = in_child(lambda p=path: resumed(p, args, ref))
        out.pop("counts", None)
        out.pop("names", None)
        record = {"step": step, "status": status, **out, "left": left}
        record["resume"] = {"status": status2, **again, "left": sorted(os.listdir(d))}
        print(json.dumps(record), flush=True)


if __name__ == "__main__":
    main()
