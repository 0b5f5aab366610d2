"""Fault injection into cube writing: kills, full disks, concurrent writers, changed inputs.

Every trial ends in one of two ways: a cube under the final name whose values equal an
uninterrupted write, or a named error (an :class:`~sbrdf_xr.errors.SbrdfError`) with a
``.part`` that a later ``resume`` finishes to such a cube.  No trial may leave a wrong
cube under the final name.  The outcomes are collected in a table printed at the end of
the module (value-identical, named errors, data lost, wrong cubes).

Writers that are killed or limited run in subprocesses (``SIGKILL``;
``resource.setrlimit(RLIMIT_FSIZE)`` with ``SIGXFSZ`` ignored so that writes fail with
``EFBIG``, the way a full disk fails them with ``ENOSPC``).  Cubes are small so the module
runs in CI.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import random
import signal
import socket
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from sbrdf_xr.cli import main
from sbrdf_xr.errors import SbrdfError
from sbrdf_xr.store.writer import (
    LOCK_SUFFIX,
    LOG_SUFFIX,
    PART_SUFFIX,
    CubeLockedError,
    CubeWriteError,
    write_cube,
)

TESTS = Path(__file__).resolve().parent
REPO = TESTS.parents[1]
#: Seconds to wait for a subprocess writer before giving up.
TIMEOUT = 120.0
#: Seed of the random kill points and size limits (the trials are reproducible).
SEED = 14

sys.path.insert(0, str(TESTS))
sys.path.insert(1, str(TESTS.parent))
from test_writer import dask_cluster, make_cube  # noqa: E402, F401

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals and rlimits")

#: One row per trial: (kind, outcome) with outcome in the columns of the table.
TRIALS: list[tuple[str, str]] = []
#: Blocks marked as stored when each Zarr writer was killed (-1: before its ``.part``
#: existed; 24: after the rename).
KILL_POINTS: list[int] = []
OUTCOMES = ("value-identical", "named error, resumed", "named error", "data lost", "wrong cube")


@pytest.fixture(scope="module", autouse=True)
def fault_table(request):
    """Print the table of trials after the module (shown even with output captured)."""
    yield
    kinds = sorted({k for k, _ in TRIALS})
    lines = [f"{'fault-injection trials':<28}{'trials':>7}" + "".join(f"{o:>22}" for o in OUTCOMES)]
    for kind in [*kinds, "all"]:
        rows = [o for k, o in TRIALS if kind in (k, "all")]
        lines.append(
            f"{kind:<28}{len(rows):>7}" + "".join(f"{rows.count(o):>22}" for o in OUTCOMES)
        )
    reporter = request.config.pluginmanager.get_plugin("terminalreporter")
    capman = request.config.pluginmanager.getplugin("capturemanager")
    if KILL_POINTS:
        lines.append(f"Zarr writers killed with these blocks stored: {sorted(KILL_POINTS)}")
    with capman.global_and_fixture_disabled() if capman else contextlib.nullcontext():
        for line in ["", *lines]:
            if reporter is not None:
                reporter.write_line(line)
            else:  # pragma: no cover
                print(line)


def cube_24(**kw) -> xr.Dataset:
    """24 blocks of about 100 kB.

    (24 attitudes in chunks of 1) x 4 phase angles x 2000 wavelengths.
    """
    return make_cube(n_attitude=24, n_phase=4, n_wavelength=2000, chunks=(1, 4), **kw)


def read(path: Path) -> xr.Dataset:
    with xr.open_dataset(path, engine="netcdf4") as ds:
        return ds.load()


def recorded(path: Path) -> list[int]:
    log = path.with_name(path.name + LOG_SUFFIX)
    if not log.exists():
        return []
    out = []
    for line in log.read_text().splitlines()[1:]:
        with contextlib.suppress(ValueError, KeyError):
            out.append(json.loads(line)["block"])
    return out


def same_values(path: Path, reference: xr.Dataset) -> bool:
    got = read(path)
    try:
        xr.testing.assert_identical(got.drop_attrs(), reference.drop_attrs())
    except AssertionError:
        return False
    return True


WRITER = textwrap.dedent(
    """
    import json, os, resource, signal, sys
    sys.path[:0] = [{repo!r}, {tests!r}, {tests_root!r}]
    from test_faults import cube_24
    from sbrdf_xr.store import disk as _write_disk, writer as _writer
    from sbrdf_xr.errors import SbrdfError
    args = json.loads(sys.argv[1])
    if args.get("limit"):
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # writes past the limit fail with EFBIG
        resource.setrlimit(resource.RLIMIT_FSIZE, (args["limit"], resource.RLIM_INFINITY))
    _write_disk.CHECK_SPACE = args.get("check_space", True)
    kill_after = args.get("kill_after")
    def on_block(event):
        if kill_after is not None and event.n_written >= kill_after:
            os.kill(os.getpid(), signal.SIGKILL)
    try:
        _writer.write_cube(cube_24(delay=args.get("delay", 0.0)), args["path"],
                           overwrite=args.get("overwrite", False), resume=args.get("resume", False),
                           max_in_flight=2, on_block=on_block, complevel=args.get("complevel", 0))
        print(json.dumps({{"ok": True}}))
    except Exception as exc:
        print(json.dumps({{"ok": False, "named": isinstance(exc, SbrdfError),
                          "error": type(exc).__name__, "message": str(exc)}}))
    """
)


def writer(tmp_path: Path, **args) -> subprocess.Popen:
    script = tmp_path / "writer.py"
    if not script.exists():
        script.write_text(
            WRITER.format(repo=str(REPO), tests=str(TESTS), tests_root=str(TESTS.parent))
        )
    return subprocess.Popen(
        [sys.executable, str(script), json.dumps(args)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def result(proc: subprocess.Popen) -> dict:
    out, err = proc.communicate(timeout=TIMEOUT)
    lines = out.strip().splitlines()
    assert lines, f"the writer printed nothing (exit {proc.returncode}): {err[-2000:]}"
    return json.loads(lines[-1])


@pytest.fixture(scope="module")
def reference() -> xr.Dataset:
    return cube_24().compute()


# ------------------------------------------------------------------ SIGKILL


def test_sigkill_at_random_points(tmp_path, reference, caplog):
    """Writers killed at seeded random points resume to value-identical cubes."""
    rng = random.Random(SEED)
    for trial in range(6):
        path = tmp_path / f"kill{trial}" / "cube.nc"
        path.parent.mkdir()
        kill_at = rng.randint(0, 23)  # blocks recorded before the kill (0: during creation)
        proc = writer(path.parent, path=str(path), delay=0.01)
        deadline = time.monotonic() + TIMEOUT
        if kill_at == 0:
            time.sleep(rng.uniform(0.0, 1.0))
        while kill_at and len(recorded(path)) < kill_at and proc.poll() is None:
            assert time.monotonic() < deadline, "the writer made no progress"
            time.sleep(0.005)
        with contextlib.suppress(ProcessLookupError):
            os.kill(proc.pid, signal.SIGKILL)
        proc.communicate(timeout=TIMEOUT)
        if path.exists():  # killed too late: the rename was done
            outcome = "value-identical" if same_values(path, reference) else "wrong cube"
        else:
            before = recorded(path)
            caplog.clear()
            with caplog.at_level(logging.WARNING, logger="sbrdf_xr.write_cube"):
                write_cube(cube_24(), path, resume=True)
            if path.with_name(path.name + LOCK_SUFFIX).exists():
                outcome = "wrong cube"  # the lock must be released
            else:
                outcome = "value-identical" if same_values(path, reference) else "wrong cube"
            if before:
                assert any("stale lock" in r.getMessage() for r in caplog.records)
        TRIALS.append(("SIGKILL at random points", outcome))
        assert outcome == "value-identical", (trial, kill_at)
        assert sorted(p.name for p in path.parent.iterdir()) == ["cube.nc", "writer.py"]


# ------------------------------------------------------------------ full disk


@pytest.mark.parametrize(
    "check_space",
    [True, pytest.param(False, marks=pytest.mark.slow)],
    ids=["checked", "unforeseen"],
)
def test_file_size_limit_is_found_before_any_block(tmp_path, reference, check_space):
    """An uncompressed cube is laid out whole when its ``.part`` is created, so a
    file-size limit below its size (EFBIG, as a full disk gives ENOSPC) stops the write
    at creation, named, before any block is computed, and leaves nothing behind; under
    the limit a resume is refused the same way; without it the cube is written.

    ``checked``: the room is checked first (the default).  ``unforeseen``: the check is
    off, so HDF5's own flush fails, and the cause is still named.
    """
    rng = random.Random(SEED + check_space)
    for trial in range(2):
        path = tmp_path / f"limit{trial}" / "cube.nc"
        path.parent.mkdir()
        limit = rng.randint(600_000, 2_000_000)  # the whole cube is about 2.5 MB
        kind = f"file size limit, whole ({'checked' if check_space else 'unforeseen'})"
        for resume in (False, True):
            r = result(
                writer(
                    path.parent, path=str(path), limit=limit, check_space=check_space, resume=resume
                )
            )
            assert not r["ok"] and r["named"], r
            assert "file size limit exceeded" in r["message"], r
            assert "Nothing was written; raise the file size limit" in r["message"], r
            assert sorted(p.name for p in path.parent.iterdir()) == ["writer.py"]
        write_cube(cube_24(), path, resume=True)
        outcome = "named error, resumed" if same_values(path, reference) else "wrong cube"
        TRIALS.append((kind, outcome))
        assert outcome == "named error, resumed"


@pytest.mark.parametrize(
    "check_space",
    [True, pytest.param(False, marks=pytest.mark.slow)],
    ids=["checked", "unforeseen"],
)
def test_file_size_limit_of_a_compressed_cube(tmp_path, reference, check_space):
    """A compressed cube grows block by block (its chunks are indexed as they arrive):
    a file-size limit (EFBIG, as a full disk gives ENOSPC) stops the write with the
    cause named; the ``.part`` keeps its blocks, a resume under the limit is refused by
    name, and a resume without the limit finishes the cube.

    ``checked``: the room is checked before each block (the default).  ``unforeseen``: the
    check is off, so HDF5's own write fails mid-block and the file is cut back to its last
    synced state; the outcome is recorded in the table.
    """
    rng = random.Random(SEED + check_space)
    for trial in range(3):
        path = tmp_path / f"limit{trial}" / "cube.nc"
        path.parent.mkdir()
        limit = rng.randint(600_000, 1_800_000)  # the compressed cube is about 2.3 MB
        args = {"path": str(path), "limit": limit, "check_space": check_space, "complevel": 1}
        r = result(writer(path.parent, **args))
        kind = f"file size limit, zlib ({'checked' if check_space else 'unforeseen'})"
        assert not r["ok"] and r["named"], r
        assert "file size limit exceeded" in r["message"], r
        assert not path.exists()
        kept = recorded(path)
        if "could not be kept" in r["message"]:
            TRIALS.append((kind, "data lost"))
            assert not check_space, r
            continue
        # Still "full": resuming is refused with the cause, not a traceback.
        again = result(writer(path.parent, **args, resume=True))
        assert not again["ok"] and again["named"], again
        assert "file size limit exceeded" in again["message"], again
        # Space freed: resume finishes the cube from the blocks kept.
        try:
            write_cube(cube_24(), path, resume=True, complevel=1)
        except SbrdfError:
            TRIALS.append((kind, "data lost"))
            assert not check_space
            assert not path.exists()  # never a wrong cube under the final name
            continue
        outcome = "named error, resumed" if same_values(path, reference) else "wrong cube"
        TRIALS.append((kind, outcome))
        assert outcome != "wrong cube"
        if check_space:
            assert kept, "no block was kept"
            assert outcome == "named error, resumed"


# ------------------------------------------------------------------ two writers


def test_two_writers_on_one_path(tmp_path, reference):
    """While one writer runs, a second (even with overwrite) is refused by the lock."""
    path = tmp_path / "cube.nc"
    path.write_bytes(b"an older cube")
    # about 10 s of writing: long enough for a second process to start and be refused on
    # a loaded machine (the in-process refusal is checked first, within milliseconds)
    first = writer(tmp_path, path=str(path), overwrite=True, delay=0.8)
    deadline = time.monotonic() + TIMEOUT
    while len(recorded(path)) < 2:
        assert first.poll() is None and time.monotonic() < deadline, (
            "the first writer did not start"
        )
        time.sleep(0.01)
    lock = json.loads(path.with_name(path.name + LOCK_SUFFIX).read_text())
    assert lock["pid"] == first.pid and lock["host"] == socket.gethostname() and lock["started"]
    with pytest.raises(CubeLockedError, match="being written by another writer"):
        write_cube(cube_24(), path, resume=True)
    second = result(writer(tmp_path, path=str(path), overwrite=True))
    assert first.poll() is None, "the first writer ended before the second was refused"
    assert not second["ok"] and second["error"] == "CubeLockedError", second
    assert f"pid {first.pid}" in second["message"]
    assert result(first)["ok"]
    outcome = "value-identical" if same_values(path, reference) else "wrong cube"
    TRIALS.append(("two writers on one path", outcome))
    assert outcome == "value-identical"
    assert not path.with_name(path.name + LOCK_SUFFIX).exists()


def test_stale_lock_of_a_dead_writer_is_removed_with_a_message(tmp_path, caplog):
    path = tmp_path / "cube.nc"
    dead = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        capture_output=True,
        text=True,
        check=True,
    )
    pid = int(dead.stdout)
    lock = path.with_name(path.name + LOCK_SUFFIX)
    lock.write_text(
        json.dumps(
            {"pid": pid, "host": socket.gethostname(), "started": "2026-01-01T00:00:00+00:00"}
        )
    )
    with caplog.at_level(logging.WARNING, logger="sbrdf_xr.write_cube"):
        write_cube(make_cube(), path)
    assert any(
        f"pid {pid}" in r.getMessage() and "no longer running" in r.getMessage()
        for r in caplog.records
    )
    assert not lock.exists()


def test_lock_of_another_host_is_left_alone(tmp_path):
    path = tmp_path / "cube.nc"
    lock = path.with_name(path.name + LOCK_SUFFIX)
    lock.write_text(
        json.dumps({"pid": 1, "host": "elsewhere.example", "started": "2026-01-01T00:00:00+00:00"})
    )
    with pytest.raises(CubeLockedError, match=r"elsewhere\.example.*remove"):
        write_cube(make_cube(), path)
    assert lock.exists() and not path.exists()


def test_lock_released_on_every_exit_path(tmp_path):
    path = tmp_path / "cube.nc"
    lock = path.with_name(path.name + LOCK_SUFFIX)
    switch = tmp_path / "fail"
    switch.touch()
    with pytest.raises(CubeWriteError):  # a block fails
        write_cube(make_cube(fail_switch=str(switch), fail_at=(1, 1)), path)
    assert not lock.exists()

    def interrupt(event):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt) as info:  # an interrupt
        write_cube(make_cube(), path, resume=True, on_block=interrupt)
    assert "resume=True" in "".join(info.value.__notes__)
    assert not lock.exists()
    with pytest.raises(FileExistsError):  # refused before writing
        write_cube(make_cube(), path)
    assert not lock.exists()
    write_cube(make_cube(), path, resume=True)
    assert not lock.exists()


# ------------------------------------------------------------------ destinations


def _fifo(p: Path) -> None:
    os.mkfifo(p)


def _symlink(p: Path) -> None:
    target = p.with_name("target.nc")
    target.write_bytes(b"someone else's file")
    p.symlink_to(target)


def _dangling(p: Path) -> None:
    p.symlink_to(p.with_name("nowhere.nc"))


def _directory(p: Path) -> None:
    p.mkdir()


def _device(p: Path) -> None:
    try:
        os.mknod(p, 0o600 | __import__("stat").S_IFCHR, os.makedev(1, 3))  # like /dev/null
    except PermissionError:
        pytest.skip("creating a device node needs privileges")


@pytest.mark.parametrize(
    "make",
    [_fifo, _symlink, _dangling, _directory, _device],
    ids=["fifo", "symlink", "dangling-symlink", "directory", "device"],
)
@pytest.mark.parametrize("which", ["path", "part"])
def test_overwrite_replaces_only_regular_files(tmp_path, make, which):
    path = tmp_path / "cube.nc"
    target = path if which == "path" else path.with_name(path.name + PART_SUFFIX)
    make(target)
    before = sorted((p.name, os.lstat(p).st_mode) for p in tmp_path.iterdir())
    for kw in ({"overwrite": True}, {"overwrite": True, "resume": True}):
        with pytest.raises(CubeWriteError, match="not a regular file"):
            write_cube(make_cube(), path, **kw)
    assert sorted((p.name, os.lstat(p).st_mode) for p in tmp_path.iterdir()) == before
    if make is _symlink:
        assert path.with_name("target.nc").read_bytes() == b"someone else's file"


# ------------------------------------------------------------------ finished cubes


def test_resume_of_a_finished_cube_is_a_no_op(tmp_path, caplog):
    path = tmp_path / "cube.nc"
    write_cube(make_cube(), path)
    stamp = path.stat().st_mtime_ns
    with caplog.at_level(logging.INFO, logger="sbrdf_xr.write_cube"):
        assert write_cube(make_cube(), path, resume=True) == path
    assert path.stat().st_mtime_ns == stamp
    assert any("already complete" in r.getMessage() for r in caplog.records)
    with pytest.raises(CubeWriteError, match="finished cube of other inputs"):
        write_cube(make_cube(n_attitude=13), path, resume=True)
    assert path.stat().st_mtime_ns == stamp


def test_empty_cubes_are_refused(tmp_path):
    from sbrdf_xr.errors import ValidationError

    with pytest.raises(ValidationError, match="no data variables"):
        write_cube(make_cube()[[]], tmp_path / "a.nc")
    with pytest.raises(ValidationError, match="empty along phase_angle"):
        write_cube(make_cube().isel(phase_angle=slice(0, 0)), tmp_path / "b.nc")
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------ changed inputs


SCENE = """
name = "faults"
spacecraft = "canx1"
phase_angles = [10.0]
outputs = ["spacecraft_sbrdf", "signal", "brdf", "area"]
chunk = 1
[attitude]
kind = "sweep"
axis = [0, 0, -1]
start = 0
stop = 48
step = 2
"""
REMAP = """
[materials]
"aluminium-6061-t6" = "aluminium-6061-t6"
"tjpv-cell" = "tjpv-cell"
"white-paint-a276" = "white-paint-a276-paper"
"""

KILLER = textwrap.dedent(
    """
    import os, signal, sys
    sys.path[:0] = [{repo!r}]
    from sbrdf_xr import simulate
    from sbrdf_xr.store.formats import write_netcdf_cube  # what 'sbrdf-xr simulate' writes
    def on_block(event):
        if event.n_written == 8:
            os.kill(os.getpid(), signal.SIGKILL)
    write_netcdf_cube(simulate(sys.argv[1]), sys.argv[2], max_in_flight=1, on_block=on_block)
    """
)


def test_resume_after_a_changed_table_is_refused(tmp_path, capsys):
    """The issue's case: a run killed after 8 of 24 blocks and resumed with
    ``white-paint-a276`` remapped to the paper's table is refused, naming the material;
    the original scene then resumes to the uninterrupted cube."""
    from sbrdf_xr import simulate
    from sbrdf_xr.engine import load_scene
    from sbrdf_xr.engine.fingerprint import scene_fingerprint

    scene, remapped = tmp_path / "scene.toml", tmp_path / "remapped.toml"
    scene.write_text(SCENE)
    remapped.write_text(SCENE + REMAP)
    path = tmp_path / "cube.nc"
    script = tmp_path / "killer.py"
    script.write_text(KILLER.format(repo=str(REPO)))
    load_scene(scene).plan()  # the tables built here and cached: the child only reads them
    proc = subprocess.run(
        [sys.executable, str(script), str(scene), str(path)],
        timeout=TIMEOUT,
        capture_output=True,
        text=True,
    )
    assert proc.returncode == -signal.SIGKILL, proc.stderr[-2000:]
    # the 8 blocks reported, and perhaps the next one, whose sync ran behind them
    assert sorted(recorded(path)) in (list(range(8)), list(range(9))) and not path.exists()
    part, log = (path.with_name(path.name + s) for s in (PART_SUFFIX, LOG_SUFFIX))
    saved = {p: (p.read_bytes(), p.stat().st_mtime_ns) for p in (part, log)}

    with pytest.raises(CubeWriteError, match="material 'white-paint-a276': table changed"):
        write_cube(simulate(remapped), path, resume=True)
    capsys.readouterr()  # what the Python run printed (the progress of a table it built)
    assert main(["simulate", str(remapped), "-o", str(path), "--resume", "-q"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "material 'white-paint-a276': table changed" in err[0], err
    assert "--overwrite" in err[0] and "overwrite=True" not in err[0]
    assert {p: (p.read_bytes(), p.stat().st_mtime_ns) for p in (part, log)} == saved

    assert main(["simulate", str(scene), "-o", str(path), "--resume", "-q"]) == 0
    assert f"wrote {path}" in capsys.readouterr().out
    from sbrdf_xr.store.formats import write_netcdf_cube

    clean = write_netcdf_cube(simulate(scene), tmp_path / "clean.nc")  # what the CLI writes
    got, want = read(path), read(clean)
    xr.testing.assert_identical(got.drop_attrs(), want.drop_attrs())
    fp = scene_fingerprint(load_scene(scene))
    assert {k: got.attrs[k] for k in fp} == fp
    TRIALS.append(("resume after changed table", "named error, resumed"))

    # Resuming the finished cube does nothing, and says so.
    assert main(["simulate", str(scene), "-o", str(path), "--resume", "-q"]) == 0
    assert "already complete" in capsys.readouterr().out
    assert main(["simulate", str(remapped), "-o", str(path), "--resume", "-q"]) == 2
    assert "finished cube of other inputs" in capsys.readouterr().err
    np.testing.assert_array_equal(read(path)["signal"].values, want["signal"].values)


# ------------------------------------------------------------------ Zarr

ZARR_WRITER = textwrap.dedent(
    """
    import json, sys
    sys.path[:0] = [{repo!r}, {tests!r}, {tests_root!r}]
    from test_faults import cube_24
    from sbrdf_xr.store.zarr_store import write_zarr
    from sbrdf_xr.errors import SbrdfError
    args = json.loads(sys.argv[1])
    gate = {{k: args[k] for k in ("gate", "gate_from") if k in args}}
    cube = cube_24(delay=args.get("delay", 0.0), **gate)
    print("started", flush=True)
    try:
        write_zarr(cube, args["path"], overwrite=args.get("overwrite", False),
                   resume=args.get("resume", False), max_in_flight=args.get("max_in_flight"))
        print(json.dumps({{"ok": True}}))
    except Exception as exc:
        print(json.dumps({{"ok": False, "named": isinstance(exc, SbrdfError),
                          "error": type(exc).__name__, "message": str(exc)}}))
    """
)


def zarr_writer(tmp_path: Path, **args) -> subprocess.Popen:
    script = tmp_path / "zarr_writer.py"
    if not script.exists():
        script.write_text(
            ZARR_WRITER.format(repo=str(REPO), tests=str(TESTS), tests_root=str(TESTS.parent))
        )
    proc = subprocess.Popen(
        [sys.executable, str(script), json.dumps(args)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    line = proc.stdout.readline()  # the cube is built: the write starts now
    assert line.strip() == "started", proc.stderr.read()[-2000:]
    return proc


def zarr_result(proc: subprocess.Popen) -> dict:
    """The last line a Zarr writer printed (its first, "started", was read already: the
    rest may sit in the reader's buffer, so it is read through it, not around it)."""
    out = proc.stdout.read()
    err = proc.stderr.read()
    proc.wait(timeout=TIMEOUT)
    lines = out.strip().splitlines()
    assert lines, f"the writer printed nothing (exit {proc.returncode}): {err[-2000:]}"
    return json.loads(lines[-1])


def read_zarr(path: Path) -> xr.Dataset:
    with xr.open_zarr(path) as ds:
        return ds.load()


def zarr_marks(path: Path) -> int:
    from sbrdf_xr.store.zarr_store import marked_blocks

    return len(marked_blocks(path.with_name(path.name + PART_SUFFIX), 24))


def zarr_kill_trials(tmp_path: Path, reference: xr.Dataset, n: int, seed: int) -> None:
    """``n`` writers of a 24-block Zarr cube killed at random instants, each resumed."""
    from sbrdf_xr.store.zarr_store import write_zarr

    pytest.importorskip("zarr")
    rng = random.Random(seed)
    for trial in range(n):
        path = tmp_path / f"kill{trial}" / "cube.zarr"
        path.parent.mkdir()
        # the instant: while the store is created (-1), or after a random number of blocks
        # were stored and a random part of the next 0.1 s block (24: during the rename)
        after = rng.randint(-1, 24) if trial else -1  # the first while the store is created
        proc = zarr_writer(path.parent, path=str(path), delay=0.1)
        deadline = time.monotonic() + TIMEOUT
        while after > 0 and zarr_marks(path) < after and proc.poll() is None:
            assert time.monotonic() < deadline, "the writer made no progress"
            time.sleep(0.002)
        time.sleep(rng.uniform(0.0, 0.05 if after < 0 else 0.1))  # the store's creation: ~0.1 s
        with contextlib.suppress(ProcessLookupError):
            os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=TIMEOUT)
        proc.stdout.close()
        proc.stderr.close()
        part = path.with_name(path.name + PART_SUFFIX)
        stored = 24 if path.exists() else zarr_marks(path) if part.exists() else -1
        KILL_POINTS.append(stored)
        # what a user does next: resume (a no-op for a finished store, which clears the lock)
        write_zarr(cube_24(), path, resume=True)
        try:
            xr.testing.assert_identical(read_zarr(path), reference)
            outcome = "value-identical"
        except AssertionError:
            outcome = "wrong cube"
        left = sorted(p.name for p in path.parent.iterdir())
        if left != ["cube.zarr", "zarr_writer.py"]:
            outcome = "wrong cube"  # a lock or a .part left behind
        TRIALS.append(("Zarr SIGKILL at random instants", outcome))
        assert outcome == "value-identical", (trial, stored, left)


def test_zarr_sigkill_at_random_instants(tmp_path, reference):
    """Writers of a Zarr cube killed at seeded random instants (while the store is
    created, with blocks in flight, while it is renamed) resume to value-identical
    stores, leaving no lock or ``.part``."""
    zarr_kill_trials(tmp_path, reference, n=3, seed=SEED)


@pytest.mark.slow
def test_zarr_sigkill_at_random_instants_many(tmp_path, reference):
    zarr_kill_trials(tmp_path, reference, n=12, seed=SEED + 1)


@pytest.mark.parametrize(
    "start",
    [
        "mid-write",
        pytest.param("together", marks=pytest.mark.slow),
        "together-overwrite",
    ],
)
def test_two_zarr_writers_on_one_path(tmp_path, reference, start):
    """Two simultaneous Zarr writers of one path: one writes, the other is refused by the
    lock (naming the holder), and the store opens and equals the cube.

    The overlap is forced, not assumed from timing: the blocks of both writers wait for a
    gate file (mid-write: from the third block on), opened only once one writer has ended,
    so the winner still holds the lock when the loser tries it, however slowly either
    starts.
    """
    from sbrdf_xr.store.zarr_store import write_zarr

    pytest.importorskip("zarr")
    path = tmp_path / "cube.zarr"
    gate = tmp_path / "gate"
    overwrite = start == "together-overwrite"
    if overwrite:
        write_zarr(cube_24().isel(attitude=slice(0, 6)), path)
    held = {"gate": str(gate), "gate_from": 2 if start == "mid-write" else 0}
    first = zarr_writer(tmp_path, path=str(path), overwrite=overwrite, **held)
    deadline = time.monotonic() + TIMEOUT
    if start == "mid-write":
        while zarr_marks(path) < 2:
            assert first.poll() is None and time.monotonic() < deadline, "no progress"
            time.sleep(0.01)
    second = zarr_writer(tmp_path, path=str(path), overwrite=overwrite, **held)
    while first.poll() is None and second.poll() is None:  # the loser ends; the winner waits
        assert time.monotonic() < deadline, "neither writer ended"
        time.sleep(0.01)
    gate.touch()
    results = [zarr_result(first), zarr_result(second)]
    won = [r for r in results if r["ok"]]
    refused = [r for r in results if not r["ok"]]
    assert len(won) == 1 and len(refused) == 1, results
    assert refused[0]["error"] == "CubeLockedError", refused
    assert "being written by another writer" in refused[0]["message"]
    outcome = "value-identical"
    try:
        xr.testing.assert_identical(read_zarr(path), reference)
    except AssertionError:
        outcome = "wrong cube"
    TRIALS.append(("two Zarr writers on one path", outcome))
    assert outcome == "value-identical"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cube.zarr", "gate", "zarr_writer.py"]


@pytest.mark.parametrize("suffix", [".nc", ".zarr"])
def test_every_worker_of_the_cluster_dies(tmp_path, dask_cluster, suffix):  # noqa: F811
    """Both workers killed mid-sweep: a named WorkersLostError (not a Dask exception, not
    a hang), the blocks written kept, and a resume without the cluster finishes the cube."""
    import dask

    from sbrdf_xr.errors import WorkersLostError
    from sbrdf_xr.store import write

    if suffix == ".zarr":
        pytest.importorskip("zarr")
    address, workers = dask_cluster
    path = tmp_path / f"c{suffix}"
    ds = make_cube(chunks=(3, 2), delay=0.2)  # 20 blocks
    events: list[int] = []

    def on_block(event) -> None:
        events.append(event.index)
        if len(events) == 3:
            for w in workers:
                os.kill(w.pid, signal.SIGKILL)

    with (
        dask.config.set({"sbrdf_xr.no-workers-timeout": "2s"}),
        pytest.raises(WorkersLostError) as info,
    ):
        write(ds, path, scheduler=address, on_block=on_block)
    message = str(info.value)
    assert "no worker for 2 s" in message and "resume=True" in message, message
    assert f"{path}{PART_SUFFIX}" in message and not path.exists()
    write(make_cube(chunks=(3, 2)), path, resume=True)  # threads of this process
    with xr.open_zarr(path) if suffix == ".zarr" else xr.open_dataset(path) as back:
        xr.testing.assert_identical(back.load(), make_cube(chunks=(3, 2)).compute())
    TRIALS.append((f"every worker killed ({suffix})", "named error, resumed"))


@pytest.mark.parametrize("suffix", [".nc", pytest.param(".zarr", marks=pytest.mark.slow)])
def test_the_scheduler_dies(tmp_path, dask_cluster, suffix):  # noqa: F811
    """The scheduler killed mid-sweep: a named WorkersLostError, the blocks written kept,
    and a resume without the cluster finishes the cube."""
    import distributed

    from sbrdf_xr.errors import WorkersLostError
    from sbrdf_xr.store import write

    if suffix == ".zarr":
        pytest.importorskip("zarr")
    address, _ = dask_cluster
    with distributed.Client(address, set_as_default=False) as c:
        scheduler_pid = c.run_on_scheduler(os.getpid)
    path = tmp_path / f"c{suffix}"
    events: list[int] = []

    def on_block(event) -> None:
        events.append(event.index)
        if len(events) == 3:
            os.kill(scheduler_pid, signal.SIGKILL)

    with pytest.raises(WorkersLostError) as info:
        write(make_cube(chunks=(3, 2), delay=0.2), path, scheduler=address, on_block=on_block)
    message = str(info.value)
    assert "scheduler" in message and "resume=True" in message and "\n" not in message, message
    assert f"{path}{PART_SUFFIX}" in message and not path.exists()
    write(make_cube(chunks=(3, 2)), path, resume=True)
    with xr.open_zarr(path) if suffix == ".zarr" else xr.open_dataset(path) as back:
        xr.testing.assert_identical(back.load(), make_cube(chunks=(3, 2)).compute())
    TRIALS.append((f"scheduler killed ({suffix})", "named error, resumed"))
