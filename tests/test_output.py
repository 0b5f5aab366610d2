"""Tests of sbrdf_xr._output: the safe output every writer of the package goes through.

Special files are made for real (``mkfifo``, ``mknod`` when permitted, a bound Unix
socket, symbolic links); a write that would block on a FIFO is turned into a failure by
``SIGALRM`` instead of hanging the suite.
"""

from __future__ import annotations

import contextlib
import os
import signal
import socket
import stat
from pathlib import Path

import pytest

from sbrdf_xr._output import (
    MARKER,
    atomic_file,
    check_output,
    command_line_messages,
    file_kind,
    make_marked_dir,
    open_regular,
    read_marker,
    refuse_special,
    remove_marked_dir,
    rename_no_replace,
    replace_dir,
    write_marker,
)
from sbrdf_xr.errors import OutputError

pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="POSIX special files")

#: Seconds after which a blocked open counts as a hang.
HANG = 20


@contextlib.contextmanager
def no_hang(seconds: int = HANG):
    def alarm(signum, frame):
        raise TimeoutError(f"blocked for {seconds} s (a FIFO opened for writing?)")

    old = signal.signal(signal.SIGALRM, alarm)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def make_special(p: Path, kind: str) -> object:
    """Make a special file of ``kind`` at ``p``; returns what keeps it alive (a socket)."""
    if kind == "fifo":
        os.mkfifo(p)
    elif kind == "symlink":
        target = p.with_name(p.name + ".target")
        target.write_bytes(b"someone else's file")
        p.symlink_to(target)
    elif kind == "symlink-to-dir":
        target = p.with_name(p.name + ".target")
        target.mkdir()
        (target / "kept.txt").write_text("a user's file")
        p.symlink_to(target, target_is_directory=True)
    elif kind == "dangling-symlink":
        p.symlink_to(p.with_name("nowhere"))
    elif kind == "devnull-symlink":
        p.symlink_to("/dev/null")
    elif kind == "char-device":
        try:
            os.mknod(p, 0o600 | stat.S_IFCHR, os.makedev(1, 3))  # like /dev/null
        except PermissionError:
            p.symlink_to("/dev/null")  # without privileges: a link to a device
    elif kind == "socket":
        cwd = os.getcwd()
        os.chdir(p.parent)  # a Unix socket's path is short; bind it by its name
        try:
            s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            s.bind(p.name)
        finally:
            os.chdir(cwd)
        return s
    elif kind == "directory":
        p.mkdir()
        (p / "kept.txt").write_text("a user's file")
    else:  # pragma: no cover
        raise ValueError(kind)
    return None


KINDS = [
    "fifo",
    "symlink",
    "symlink-to-dir",
    "dangling-symlink",
    "char-device",
    "devnull-symlink",
    "socket",
    "directory",
]


def snapshot(d: Path) -> list[tuple[str, int, bytes | None]]:
    """Every entry under ``d``: name, mode, and the bytes of regular files."""
    out = []
    for root, dirs, files in os.walk(d):
        for name in sorted(dirs + files):
            p = Path(root) / name
            st = os.lstat(p)
            data = p.read_bytes() if stat.S_ISREG(st.st_mode) else None
            out.append((str(p.relative_to(d)), st.st_mode, data))
    return sorted(out)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("overwrite", [False, True])
def test_atomic_file_refuses_every_special_file_and_changes_nothing(tmp_path, kind, overwrite):
    out = tmp_path / "out.csv"
    keep = make_special(out, kind)
    before = snapshot(tmp_path)
    with no_hang(), pytest.raises(OutputError) as info:
        with atomic_file(out, overwrite=overwrite) as tmp:
            tmp.write_text("new")
    assert str(out) in str(info.value) and file_kind(out) in str(info.value)
    assert "not a regular file" in str(info.value)
    assert snapshot(tmp_path) == before
    del keep


def test_atomic_file_replaces_only_when_asked_and_refuses_what_appears(tmp_path, monkeypatch):
    out = tmp_path / "out.csv"
    with atomic_file(out) as tmp:
        tmp.write_text("first")
    with pytest.raises(FileExistsError, match="pass overwrite=True"):
        with atomic_file(out) as tmp:
            tmp.write_text("second")
    with command_line_messages(), pytest.raises(FileExistsError, match="pass --overwrite"):
        check_output(out)
    assert out.read_text() == "first"
    # a file that appears under the final name while the output is written is kept
    out.unlink()
    with pytest.raises(FileExistsError):
        with atomic_file(out) as tmp:
            tmp.write_text("mine")
            out.write_text("theirs")
    assert out.read_text() == "theirs"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv"]
    # a FIFO that appears meanwhile is never replaced, overwrite or not
    out.unlink()
    with no_hang(), pytest.raises(OutputError, match="FIFO"):
        with atomic_file(out, overwrite=True) as tmp:
            tmp.write_text("mine")
            os.mkfifo(out)
    assert file_kind(out) == "a FIFO (named pipe)"
    umask = os.umask(0)
    os.umask(umask)
    out.unlink()
    with atomic_file(out) as tmp:
        tmp.write_text("x")
    assert stat.S_IMODE(out.stat().st_mode) == 0o666 & ~umask


def test_names_that_name_no_file_are_refused(tmp_path):
    for bad in ("", ".", str(tmp_path) + "/.."):
        with pytest.raises(OutputError, match="names no file"):
            check_output(bad)


@pytest.mark.parametrize("kind", KINDS)
def test_open_regular_never_blocks_or_follows(tmp_path, kind):
    p = tmp_path / "log"
    keep = make_special(p, kind)
    for flags in (os.O_WRONLY | os.O_APPEND, os.O_RDWR, os.O_RDONLY):
        with no_hang(), pytest.raises((OutputError, OSError)):
            os.close(open_regular(p, flags))
    del keep


def test_refuse_special_names_path_and_kind_for_files_and_directories(tmp_path):
    d = tmp_path / "cube.zarr"
    d.write_text("a file where a store goes")
    with pytest.raises(OutputError, match=r"cube.zarr is a regular file, not a directory"):
        refuse_special([d], directory=True)
    refuse_special([tmp_path], directory=True)  # a directory is what is expected
    with pytest.raises(OutputError, match="is a directory, not a regular file"):
        refuse_special([tmp_path])


def test_rename_no_replace_for_files_and_directories(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir()
    b.mkdir()
    with pytest.raises(FileExistsError):
        rename_no_replace(a, b)  # even an empty directory is not replaced
    c = tmp_path / "c"
    rename_no_replace(a, c)
    assert c.is_dir() and not a.exists()


def test_marked_directories_only_are_deleted(tmp_path):
    ours = tmp_path / "ours.zarr"
    make_marked_dir(ours, {"state": "complete"})
    (ours / "v").mkdir()
    (ours / "v" / "0.0").write_bytes(b"chunk")
    (ours / "link").symlink_to(tmp_path / "precious")  # a link inside: removed, not followed
    (tmp_path / "precious").write_text("kept")
    assert read_marker(ours)["state"] == "complete"
    remove_marked_dir(ours)
    assert not ours.exists() and (tmp_path / "precious").read_text() == "kept"

    theirs = tmp_path / "theirs.zarr"
    theirs.mkdir()
    (theirs / MARKER).write_text('{"writer": "someone else"}')  # a marker not of ours
    for empty_ok in (False, True):
        with pytest.raises(OutputError, match="did not write"):
            remove_marked_dir(theirs, empty_ok=empty_ok)
    assert (theirs / MARKER).exists()

    empty = tmp_path / "empty.zarr.part"
    empty.mkdir()
    with pytest.raises(OutputError, match="did not write"):
        remove_marked_dir(empty)
    remove_marked_dir(empty, empty_ok=True)  # nothing in it to lose
    assert not empty.exists()
    half = tmp_path / "half.zarr.part"  # a writer killed while it wrote the marker
    half.mkdir()
    (half / f"{MARKER}.x7k2m9.part").write_text('{"state": "crea')
    remove_marked_dir(half, empty_ok=True)
    assert not half.exists()

    link = tmp_path / "link.zarr"
    link.symlink_to(theirs)
    with pytest.raises(OutputError, match="symbolic link"):
        remove_marked_dir(link)
    assert link.is_symlink() and theirs.is_dir()


def test_replace_dir_keeps_the_old_store_until_the_new_one_is_in_place(tmp_path):
    old, new = tmp_path / "c.zarr", tmp_path / "c.zarr.part"
    make_marked_dir(old, {"n": 1})
    make_marked_dir(new, {"n": 2})
    replace_dir(new, old)
    assert read_marker(old)["n"] == 2 and not new.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.zarr"]
    foreign = tmp_path / "f.zarr"
    foreign.mkdir()
    make_marked_dir(new, {"n": 3})
    write_marker(new, {"n": 3})
    with pytest.raises(OutputError, match="did not write"):
        replace_dir(new, foreign)  # a directory the package did not write is never replaced
    assert foreign.is_dir() and read_marker(new)["n"] == 3


_FULL_WRITE = """
import resource, signal, sys
from pathlib import Path
import numpy as np, xarray as xr
from sbrdf_xr._output import write_netcdf
from sbrdf_xr.errors import OutputError
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG
resource.setrlimit(resource.RLIMIT_FSIZE, (200_000, resource.RLIM_INFINITY))
ds = xr.Dataset({"v": (("x", "y"), np.random.default_rng(0).random((400, 400)))})
try:
    write_netcdf(ds, Path(sys.argv[1]), complevel=4)
except OutputError as exc:
    print(exc)
"""


def test_a_compressed_netcdf_that_hits_the_file_size_limit_names_the_likely_cause(tmp_path):
    """A real failure, not an injected one: 1.2 MB of incompressible float64 under a file
    size limit of 200 kB (in a child process).  HDF5 says only "NetCDF: HDF error" (all the
    message was before); now the error names the likely causes with the free space of the
    directory (``shutil.disk_usage``), the limit and the file, and nothing is left behind."""
    import subprocess
    import sys

    out = tmp_path / "v.nc"
    run = subprocess.run(
        [sys.executable, "-c", _FULL_WRITE, str(out)], capture_output=True, text=True, timeout=300
    )
    text = run.stdout.strip()
    assert run.returncode == 0 and text.startswith(f"cannot write {out}: "), (text, run.stderr)
    assert "HDF error: HDF5 gives no cause; most likely the disk filled or the file size" in text
    assert f"MiB free on {tmp_path}, file size limit 0.191 MiB, writing {out}." in text, text
    assert text.endswith("; nothing replaced") and os.listdir(tmp_path) == []
