"""Tests of sbrdf_xr.store.writer.write_cube: streaming, atomic, resumable netCDF cubes.

The synthetic cubes are lazy (``dask.array.map_blocks``) and deterministic: every
block is drawn from a random generator seeded with the variable's seed and the
block's position, so a resumed write must equal an uninterrupted one exactly.
Block functions can log their calls to a file and fail on a file-based switch,
which works across threads, processes and cluster workers alike.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import dask
import dask.array as da
import netCDF4
import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_profiles import examples

from sbrdf_xr.errors import ValidationError
from sbrdf_xr.store.disk import SyncBehind, drop_behind
from sbrdf_xr.store.runners import release_freed_memory
from sbrdf_xr.store.writer import (
    LOG_SUFFIX,
    PART_SUFFIX,
    BlockWritten,
    CubeWriteError,
    write_cube,
)

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
#: Seconds to wait for a cluster process to start or stop before giving up.
CLUSTER_TIMEOUT = 60.0


# ------------------------------------------------------------------ factories


def block_values(
    block_info=None,
    *,
    seed: int,
    calls: str | None = None,
    fail_switch: str | None = None,
    fail_at: tuple[int, ...] | None = None,
    delay: float = 0.0,
    gate: str | None = None,
    gate_from: int = 0,
) -> np.ndarray:
    """Deterministic values of one block; optionally logged, slowed down or failing, or
    held (the blocks from attitude chunk ``gate_from`` on) until the file ``gate`` exists."""
    info = block_info[None]
    loc = tuple(int(i) for i in info["chunk-location"])
    if gate is not None and loc[0] >= gate_from:
        deadline = time.monotonic() + 120.0  # a test that never opens the gate fails
        while not os.path.exists(gate):
            if time.monotonic() > deadline:
                raise RuntimeError(f"the gate {gate} was never opened")
            time.sleep(0.01)
    if calls is not None:
        fd = os.open(calls, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        try:
            os.write(fd, (json.dumps([seed, *loc]) + "\n").encode())
        finally:
            os.close(fd)
    if fail_switch is not None and loc == tuple(fail_at or ()) and os.path.exists(fail_switch):
        raise RuntimeError(f"injected failure in block {loc}")
    if delay:
        time.sleep(delay)
    rng = np.random.default_rng([seed, *loc])
    return rng.standard_normal(info["chunk-shape"]).astype(info["dtype"])


def lazy(chunks, dtype, seed, **kw) -> da.Array:
    dtype = np.dtype(dtype)
    return da.map_blocks(
        block_values, chunks=chunks, dtype=dtype, meta=np.array((), dtype), seed=seed, **kw
    )


def make_cube(
    n_attitude: int = 12,
    n_phase: int = 10,
    n_wavelength: int = 40,
    chunks: tuple[int, int] = (5, 4),
    spectral: str = "wavelength",
    **kw,
) -> xr.Dataset:
    """Lazy cube over (attitude, phase_angle, wavelength|band) with CF metadata."""
    ch = (
        da.core.normalize_chunks(chunks[0], (n_attitude,))[0],
        da.core.normalize_chunks(chunks[1], (n_phase,))[0],
        (n_wavelength,),
    )
    dims = ("attitude", "phase_angle", spectral)
    rng = np.random.default_rng(7)
    to_sun = rng.standard_normal((n_attitude, n_phase, 3))
    to_sun /= np.linalg.norm(to_sun, axis=-1, keepdims=True)
    if spectral == "wavelength":
        spec = {
            "units": "nm",
            "long_name": "vacuum wavelength",
            "standard_name": "radiation_wavelength",
        }
        spec_values = np.linspace(350.0, 1000.0, n_wavelength)
    else:
        spec = {"units": "1", "long_name": "photometric band"}
        spec_values = np.array([f"B{i}" for i in range(n_wavelength)])
    return xr.Dataset(
        {
            "irradiance": (
                dims,
                lazy(ch, "f4", seed=1, **kw),
                {"units": "W m-2 nm-1", "long_name": "spectral irradiance at the observer"},
            ),
            "sbrdf": (dims, lazy(ch, "f8", seed=2, **kw), {"units": "sr-1", "long_name": "sBRDF"}),
            "lit": (
                dims[:2],
                lazy(ch[:2], "f8", seed=3, **kw) > 0,
                {"long_name": "any facet lit"},
            ),
        },
        coords={
            "attitude": (
                "attitude",
                np.arange(n_attitude),
                {"units": "1", "long_name": "attitude index"},
            ),
            "phase_angle": (
                "phase_angle",
                np.linspace(0.0, 170.0, n_phase),
                {"units": "degree", "long_name": "angle between the Sun and observer directions"},
            ),
            spectral: (spectral, spec_values, spec),
            "to_sun": (
                ("attitude", "phase_angle", "xyz"),
                to_sun,
                {"units": "1", "long_name": "unit vector toward the Sun in the body frame"},
            ),
            "spacecraft": ((), "canx1", {"long_name": "spacecraft name"}),
        },
        attrs={
            "Conventions": "CF-1.10",
            "title": "synthetic cube",
            "source": "sbrdf_xr tests",
            "history": "created by make_cube",
            "materials": ["white paint", "solar cell"],
            "wavelength_range": [350.0, 1000.0],
            "n_facets": 42,
        },
    )


def make_geometry_cube(
    n_geometry: int = 50, n_wavelength: int = 30, chunk: int = 8, **kw
) -> xr.Dataset:
    """Lazy cube over (geometry, wavelength)."""
    ch = (da.core.normalize_chunks(chunk, (n_geometry,))[0], (n_wavelength,))
    return xr.Dataset(
        {"sbrdf": (("geometry", "wavelength"), lazy(ch, "f4", seed=5, **kw), {"units": "sr-1"})},
        coords={
            "geometry": ("geometry", np.arange(n_geometry), {"units": "1"}),
            "wavelength": ("wavelength", np.linspace(400.0, 700.0, n_wavelength), {"units": "nm"}),
            "theta_i": ("geometry", np.linspace(0.0, 89.0, n_geometry), {"units": "degree"}),
        },
        attrs={"Conventions": "CF-1.10", "title": "geometry cube"},
    )


def read(path: Path) -> xr.Dataset:
    with xr.open_dataset(path, engine="netcdf4") as ds:
        return ds.load()


def logged_blocks(calls: Path) -> list[tuple[int, ...]]:
    if not calls.exists():
        return []
    return [tuple(json.loads(line)) for line in calls.read_text().splitlines()]


def recorded_blocks(path: Path) -> list[int]:
    log = path.with_name(path.name + LOG_SUFFIX)
    return [json.loads(line)["block"] for line in log.read_text().splitlines()[1:]]


# ------------------------------------------------------------------ round trip


@pytest.mark.parametrize(
    "factory",
    [
        make_cube,
        lambda: make_cube(chunks=(4, (3, 3, 4)), spectral="band", n_wavelength=5),
        lambda: make_cube(chunks=(12, 10)),  # a single block
        make_geometry_cube,
        lambda: make_geometry_cube().assign_coords(
            theta_r=("geometry", da.linspace(0.0, 80.0, 50, chunks=8), {"units": "degree"})
        ),
        lambda: make_cube().compute(),  # nothing lazy: no blocks at all
    ],
    ids=["wavelength", "band-irregular", "one-block", "geometry", "lazy-coordinate", "numpy-only"],
)
def test_round_trip_threaded(tmp_path, factory):
    ds = factory()
    out = write_cube(ds, tmp_path / "cube.nc")
    assert out == tmp_path / "cube.nc"
    got = read(out)
    xr.testing.assert_identical(got, ds.compute())
    for name, var in ds.variables.items():
        assert got[name].dtype == var.dtype or var.dtype.kind == "U"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cube.nc"]
    with netCDF4.Dataset(out) as nc:
        for name in ds.coords:
            assert "_FillValue" not in nc.variables[name].ncattrs()


@settings(max_examples=examples(15), deadline=None, database=None)
@given(
    shape=st.tuples(st.integers(1, 9), st.integers(1, 7), st.integers(1, 5)),
    data=st.data(),
)
def test_round_trip_any_chunking(tmp_path_factory, shape, data):
    """Any chunking (regular or not, one block or many) and any in-flight limit round-trip."""
    chunks = tuple(
        tuple(data.draw(st.lists(st.integers(1, n), min_size=1).filter(lambda c, n=n: sum(c) == n)))
        if n <= 3
        else data.draw(st.integers(1, n))
        for n in shape[:2]
    )
    ds = make_cube(*shape, chunks=chunks)
    out = tmp_path_factory.mktemp("chunking") / "cube.nc"
    write_cube(ds, out, max_in_flight=data.draw(st.integers(1, 4)))
    xr.testing.assert_identical(read(out), ds.compute())


def test_round_trip_synchronous_and_compressed(tmp_path):
    ds = make_cube()
    a = write_cube(ds, tmp_path / "a.nc", scheduler="synchronous", complevel=4)
    xr.testing.assert_identical(read(a), ds.compute())
    with netCDF4.Dataset(a) as nc:
        assert nc.variables["sbrdf"].filters()["zlib"]
        assert nc.variables["sbrdf"].chunking() == [5, 4, 40]


def test_on_block_reports_every_block_once(tmp_path):
    ds = make_cube()
    events: list[BlockWritten] = []
    write_cube(ds, tmp_path / "c.nc", on_block=events.append, max_in_flight=3)
    assert sorted(e.index for e in events) == list(range(9))
    assert [e.n_written for e in events] == list(range(1, 10))
    assert all(e.n_blocks == 9 and e.in_flight <= 2 for e in events)
    first = next(e for e in events if e.index == 0)
    assert first.slices == {
        "attitude": slice(0, 5),
        "phase_angle": slice(0, 4),
        "wavelength": slice(0, 40),
    }


def test_progress_bar_tqdm_and_plain(tmp_path, capsys, monkeypatch):
    write_cube(make_cube(), tmp_path / "a.nc", progress=True)
    assert "9/9" in capsys.readouterr().err
    monkeypatch.setitem(sys.modules, "tqdm", None)  # import tqdm -> ImportError
    write_cube(make_cube(), tmp_path / "b.nc", progress=True)
    assert "b.nc: 9/9 blocks" in capsys.readouterr().err


# ------------------------------------------------------------------ atomicity and resume


def test_failure_leaves_part_and_resume_completes(tmp_path):
    calls, switch = tmp_path / "calls.jsonl", tmp_path / "fail"
    switch.touch()
    path = tmp_path / "cube.nc"
    ds = make_cube(calls=str(calls), fail_switch=str(switch), fail_at=(1, 1))
    with pytest.raises(CubeWriteError, match="resume=True") as info:
        write_cube(ds, path)
    assert isinstance(info.value.__cause__, RuntimeError)
    assert "at block 4 (attitude[5:10], phase_angle[4:8], wavelength[0:40])" in str(info.value)
    assert not path.exists()
    assert path.with_name("cube.nc" + PART_SUFFIX).exists()
    before = set(recorded_blocks(path))
    assert before and 4 not in before

    # Rerunning without resume must not touch the unfinished cube.
    with pytest.raises(FileExistsError, match="resume=True"):
        write_cube(ds, path)

    switch.unlink()
    first_run = len(logged_blocks(calls))
    write_cube(ds, path, resume=True)
    resumed = {loc[1] * 3 + loc[2] for loc in logged_blocks(calls)[first_run:] if len(loc) == 4}
    assert resumed.isdisjoint(before), "blocks written before the failure were recomputed"
    assert resumed | before == set(range(9))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["calls.jsonl", "cube.nc"]

    clean = write_cube(make_cube(), tmp_path / "clean.nc")
    xr.testing.assert_identical(read(path), read(clean))
    xr.testing.assert_identical(read(path), make_cube().compute())


def test_resume_after_killed_process(tmp_path):
    """A writer killed by SIGKILL mid-sweep leaves a .part that resumes to the same cube."""
    path = tmp_path / "cube.nc"
    script = tmp_path / "writer.py"
    script.write_text(
        textwrap.dedent(
            f"""
            import sys
            sys.path[:0] = [{str(REPO)!r}, {str(HERE)!r}, {str(HERE.parent)!r}]
            from test_writer import make_cube
            from sbrdf_xr.store.writer import write_cube
            write_cube(make_cube(delay=0.1), {str(path)!r}, max_in_flight=2)
            """
        )
    )
    proc = subprocess.Popen([sys.executable, str(script)])
    log = path.with_name(path.name + LOG_SUFFIX)
    try:
        deadline = time.monotonic() + CLUSTER_TIMEOUT
        while time.monotonic() < deadline:
            if log.exists() and len(log.read_text().splitlines()) >= 3:  # header + 2 blocks
                break
            assert proc.poll() is None, "the writer ended before it could be killed"
            time.sleep(0.02)
        os.kill(proc.pid, signal.SIGKILL)
    finally:
        with contextlib.suppress(ProcessLookupError):
            proc.kill()
        proc.wait(timeout=CLUSTER_TIMEOUT)
    assert not path.exists()
    done = recorded_blocks(path)
    assert 2 <= len(done) < 9
    events: list[BlockWritten] = []
    write_cube(make_cube(), path, resume=True, on_block=events.append)
    assert {e.index for e in events}.isdisjoint(done)
    assert sorted([e.index for e in events] + done) == list(range(9))
    xr.testing.assert_identical(read(path), make_cube().compute())


def test_blocks_of_an_uncompressed_cube_change_no_hdf5_metadata(tmp_path):
    """What makes a kill at any instant resumable: the streamed variables are laid out
    whole at creation, so from the first block to the last every byte of the ``.part``
    that changes lies inside a variable's data; the metadata a resume reads are the
    ones synced at creation.  A compressed cube's chunk index does change (the contrast
    shows the check can fail)."""
    h5py = pytest.importorskip("h5py")

    def snapshots(path, **kw) -> list[bytes]:
        part = path.with_name(path.name + ".part")
        seen: list[bytes] = []
        write_cube(make_cube(), path, on_block=lambda e: seen.append(part.read_bytes()), **kw)
        return seen

    def outside_data(path, seen) -> set[int]:
        """Offsets outside the streamed variables' data that differ between snapshots."""
        with h5py.File(path, "r", locking=False) as f:
            spans = [
                (f[n].id.get_offset(), f[n].id.get_storage_size())
                for n in ("irradiance", "sbrdf", "lit")
                if f[n].id.get_offset() is not None
            ]
        first = np.frombuffer(seen[0], dtype=np.uint8)
        changed: set[int] = set()
        for snap in seen[1:]:
            b = np.frombuffer(snap, dtype=np.uint8)
            n = min(b.size, first.size)
            diff = np.flatnonzero(b[:n] != first[:n]).tolist() + list(range(n, b.size))
            changed.update(i for i in diff if not any(o <= i < o + z for o, z in spans))
        return changed

    whole = tmp_path / "whole.nc"
    seen = snapshots(whole)
    assert len(seen) == 9 and len({len(b) for b in seen}) == 1  # the file never grows
    with h5py.File(whole, "r", locking=False) as f:
        assert f["sbrdf"].id.get_create_plist().get_layout() == h5py.h5d.CONTIGUOUS
    assert outside_data(whole, seen) == set()
    xr.testing.assert_identical(read(whole), make_cube().compute())

    zipped = tmp_path / "zipped.nc"
    seen = snapshots(zipped, complevel=1)
    assert outside_data(zipped, seen)  # chunks were appended and indexed
    xr.testing.assert_identical(read(zipped), make_cube().compute())


def test_read_back_error_names_a_damaged_file_and_passes_a_sound_one(tmp_path):
    from sbrdf_xr.store.files import read_back_error

    path = tmp_path / "cube.nc"
    write_cube(make_cube(), path, complevel=1)
    assert read_back_error(path) is None
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])  # the second half (chunks, index) gone
    err = read_back_error(path)
    assert err is not None and err.split(":")[0] in ("OSError", "RuntimeError", "IndexError")


def test_existing_file_is_not_touched(tmp_path):
    path = tmp_path / "cube.nc"
    path.write_bytes(b"an older cube")
    switch = tmp_path / "fail"
    switch.touch()
    failing = make_cube(fail_switch=str(switch), fail_at=(0, 0))
    with pytest.raises(FileExistsError, match=str(path)):
        write_cube(failing, path)  # raises before computing anything
    assert path.read_bytes() == b"an older cube"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cube.nc", "fail"]

    # overwrite keeps the old file until the new one is complete ...
    with pytest.raises(CubeWriteError):
        write_cube(failing, path, overwrite=True)
    assert path.read_bytes() == b"an older cube"
    # ... and then replaces it.
    write_cube(make_cube(), path, overwrite=True)
    xr.testing.assert_identical(read(path), make_cube().compute())


def test_overwrite_discards_unfinished_part(tmp_path):
    switch = tmp_path / "fail"
    switch.touch()
    path = tmp_path / "cube.nc"
    with pytest.raises(CubeWriteError):
        write_cube(make_cube(fail_switch=str(switch), fail_at=(0, 1)), path)
    write_cube(make_geometry_cube(), path, overwrite=True)
    xr.testing.assert_identical(read(path), make_geometry_cube().compute())
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cube.nc", "fail"]


@pytest.mark.parametrize(
    "other",
    [
        lambda: make_cube(n_attitude=13),
        lambda: make_cube(chunks=(6, 4)),
        lambda: make_cube().assign_coords(phase_angle=make_cube()["phase_angle"] + 1.0),
        lambda: make_cube().drop_vars("lit"),
        lambda: make_cube().assign(sbrdf=make_cube()["sbrdf"].astype("f4")),
        lambda: make_cube().assign_attrs(title="another cube"),
    ],
    ids=["size", "chunks", "coordinate-values", "variables", "dtype", "attrs"],
)
def test_resume_refuses_another_cube(tmp_path, other):
    switch = tmp_path / "fail"
    switch.touch()
    path = tmp_path / "cube.nc"
    with pytest.raises(CubeWriteError):
        write_cube(make_cube(fail_switch=str(switch), fail_at=(1, 0)), path)
    part = path.with_name(path.name + PART_SUFFIX)
    log = path.with_name(path.name + LOG_SUFFIX)
    saved = {p: (p.read_bytes(), p.stat().st_mtime_ns) for p in (part, log)}
    with pytest.raises(CubeWriteError, match="different cube"):
        write_cube(other(), path, resume=True)
    assert {p: (p.read_bytes(), p.stat().st_mtime_ns) for p in (part, log)} == saved


def test_resume_tolerates_new_history(tmp_path):
    switch = tmp_path / "fail"
    switch.touch()
    path = tmp_path / "cube.nc"
    with pytest.raises(CubeWriteError):
        write_cube(make_cube(fail_switch=str(switch), fail_at=(2, 1)), path)
    ds = make_cube().assign_attrs(history="resumed later")
    write_cube(ds, path, resume=True)
    xr.testing.assert_identical(read(path), ds.compute())


def test_resume_without_part_starts_afresh(tmp_path):
    path = tmp_path / "cube.nc"
    write_cube(make_cube(), path, resume=True)
    xr.testing.assert_identical(read(path), make_cube().compute())


def test_resume_needs_bookkeeping(tmp_path):
    path = tmp_path / "cube.nc"
    part = path.with_name(path.name + PART_SUFFIX)
    part.write_bytes(b"not a cube")
    with pytest.raises(CubeWriteError, match="no bookkeeping"):
        write_cube(make_cube(), path, resume=True)
    assert part.read_bytes() == b"not a cube"


@pytest.mark.parametrize("content", ["empty", "hdf5 header", "laid out"])
def test_part_without_bookkeeping_is_started_again_in_place(tmp_path, caplog, content):
    """A .part that a writer killed at its first instant leaves (its name claimed, its
    HDF5 layout begun, before the bookkeeping existed in older versions): ``resume``
    writes it again from the start, with a message, instead of refusing."""
    path = tmp_path / "cube.nc"
    part = path.with_name(path.name + PART_SUFFIX)
    if content == "laid out":
        write_cube(make_cube(), path)
        os.replace(path, part)
    else:
        part.write_bytes(b"" if content == "empty" else b"\x89HDF\r\n\x1a\n" + bytes(40))
    with caplog.at_level(logging.WARNING, logger="sbrdf_xr.write_cube"):
        write_cube(make_cube(), path, resume=True)
    assert any("written again from the start" in r.getMessage() for r in caplog.records)
    xr.testing.assert_identical(read(path), make_cube().compute())
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cube.nc"]


# ------------------------------------------------------------------ validation


def test_invalid_input_touches_nothing(tmp_path):
    path = tmp_path / "cube.nc"
    ds = make_cube()
    bad = [
        ds.assign(extra=(("attitude", "phase_angle"), da.zeros((12, 10), chunks=(6, 5)))),
        ds.assign_coords(epoch=np.datetime64("2026-01-01")),
        ds.assign_attrs(flag=True),
        ds.assign_attrs(coordinates="to_sun"),
    ]
    for case in bad:
        with pytest.raises(ValidationError):
            write_cube(case, path)
    with pytest.raises(ValidationError, match="scheduler"):
        write_cube(ds, path, scheduler="bogus")
    with pytest.raises(ValidationError, match="max_in_flight"):
        write_cube(ds, path, max_in_flight=0)
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------ bounded memory


_LOCK = threading.Lock()
_COUNTS = {"started": 0, "written": 0, "worst": 0}


def counting_block(block_info=None) -> np.ndarray:
    """Records how many blocks were computed but not yet written when a new one starts."""
    with _LOCK:
        _COUNTS["worst"] = max(_COUNTS["worst"], _COUNTS["started"] - _COUNTS["written"] + 1)
        _COUNTS["started"] += 1
    time.sleep(0.005)
    return np.ones(block_info[None]["chunk-shape"])


@pytest.mark.parametrize("max_in_flight", [1, 3, None], ids=["1", "3", "default"])
def test_blocks_in_flight_are_bounded(tmp_path, max_in_flight):
    _COUNTS.update(started=0, written=0, worst=0)
    chunks = ((2,) * 10, (2,) * 5, (8,))
    ds = xr.Dataset(
        {
            "v": (
                ("attitude", "phase_angle", "wavelength"),
                da.map_blocks(counting_block, chunks=chunks, dtype="f8", meta=np.array((), "f8")),
            )
        }
    )
    bound = 2 + 1 if max_in_flight is None else max_in_flight  # default: the workers + 1

    def written(event: BlockWritten) -> None:
        with _LOCK:
            _COUNTS["written"] += 1
        assert event.in_flight <= bound - 1

    with dask.config.set(num_workers=2):
        write_cube(ds, tmp_path / "c.nc", max_in_flight=max_in_flight, on_block=written)
    assert _COUNTS["started"] == _COUNTS["written"] == 50
    # a block is reported once its sync, which runs while the next block is computed and
    # written, has returned: one block more than those in flight, and that one holds no
    # arrays any more (they were released when it was written)
    assert _COUNTS["worst"] <= bound + 1
    if bound > 1:
        assert _COUNTS["worst"] > 1  # blocks did overlap


_STARTED = threading.Event()


def flagged_block(block_info=None) -> np.ndarray:
    """A block that says it has started computing."""
    _STARTED.set()
    return np.ones(block_info[None]["chunk-shape"])


def flagged_cube() -> xr.Dataset:
    chunks = ((4,) * 6, (16,))
    data = da.map_blocks(flagged_block, chunks=chunks, dtype="f8", meta=np.array((), "f8"))
    return xr.Dataset({"v": (("attitude", "wavelength"), data, {"units": "1"})})


def test_first_blocks_compute_while_the_file_is_created(tmp_path, monkeypatch):
    """Blocks are submitted once the room is checked, before the ``.part`` is created
    and laid out, so the kernel does not wait for the file's preparation."""
    import sbrdf_xr.store._blocks as writer  # the writer's step that creates the .part

    create = writer.create_part
    seen: list[bool] = []

    def create_after_a_block_started(*args, **kwargs):
        seen.append(_STARTED.wait(timeout=60.0))  # a hang guard, not a timing
        return create(*args, **kwargs)

    _STARTED.clear()
    monkeypatch.setattr(writer, "create_part", create_after_a_block_started)
    with dask.config.set(num_workers=2):
        write_cube(flagged_cube(), tmp_path / "c.nc")
    assert seen == [True]
    np.testing.assert_array_equal(read(tmp_path / "c.nc").v.values, 1.0)


def test_no_block_is_computed_when_the_room_is_refused(tmp_path, monkeypatch):
    import errno

    import sbrdf_xr.store._blocks as writer  # the writer's step that checks the room
    from sbrdf_xr.store.disk import _NoRoom

    def full(part, need):
        raise _NoRoom(errno.ENOSPC, f"about {need} B needed, 0 B free")

    _STARTED.clear()
    monkeypatch.setattr(writer, "check_room", full)
    with pytest.raises(CubeWriteError, match=r"no space left on device.*Nothing was written"):
        write_cube(flagged_cube(), tmp_path / "c.nc")
    assert not _STARTED.is_set()
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def _resident_bytes(path: Path) -> int:
    """Bytes of ``path`` in the page cache (``mincore`` over a read-only mapping)."""
    import ctypes
    import ctypes.util
    import mmap

    libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
    size = path.stat().st_size
    page = mmap.PAGESIZE
    vec = (ctypes.c_ubyte * (-(-size // page)))()
    with open(path, "rb") as f, mmap.mmap(f.fileno(), size, prot=mmap.PROT_READ) as mm:
        view = np.frombuffer(mm, dtype=np.uint8)
        rc = libc.mincore(ctypes.c_void_p(view.ctypes.data), ctypes.c_size_t(size), vec)
        del view  # the mapping closes only without exported buffers
    assert rc == 0, os.strerror(ctypes.get_errno())
    return sum(b & 1 for b in vec) * page


@pytest.mark.skipif(not hasattr(os, "posix_fadvise"), reason="no posix_fadvise here")
def test_written_blocks_leave_the_page_cache(tmp_path):
    """Each synced block is dropped from the page cache: a streamed cube occupies about
    one block of it at the end, not the whole file."""
    chunks = ((64,) * 16, (4,), (256,))  # 16 blocks of 512 KiB, 8 MiB in all
    ds = xr.Dataset({"v": (("attitude", "phase_angle", "wavelength"), lazy(chunks, "f8", 3))})
    out = write_cube(ds, tmp_path / "c.nc")
    block = 64 * 4 * 256 * 8
    resident = _resident_bytes(out)
    assert out.stat().st_size > 16 * block
    assert resident <= 2 * block, (resident, block)
    xr.testing.assert_identical(read(out), ds.compute())  # and nothing was lost


def test_drop_behind_keeps_the_file_and_ignores_bad_descriptors(tmp_path):
    path = tmp_path / "f.bin"
    data = np.random.default_rng(1).bytes(3 * 2**20)
    path.write_bytes(data)
    fd = os.open(path, os.O_RDWR)
    try:
        os.fsync(fd)
        drop_behind(fd)
    finally:
        os.close(fd)
    assert path.read_bytes() == data
    drop_behind(fd)  # closed: nothing raised, nothing done
    release_freed_memory()  # harmless at any time


def test_sync_behind_logs_blocks_in_order_once_on_disk(tmp_path):
    data, log = tmp_path / "c.part", tmp_path / "c.part.jsonl"
    data.write_bytes(b"x" * 2**20)
    log.write_text('{"format": "test"}\n')
    fd, log_fd = os.open(data, os.O_RDWR), os.open(log, os.O_WRONLY | os.O_APPEND)
    sync = SyncBehind(fd, log_fd)
    try:
        for k in (4, 0, 7):
            sync.submit(k)
        assert [sync.wait_oldest() for _ in range(3)] == [4, 0, 7]
    finally:
        sync.close()
        os.close(fd)
        os.close(log_fd)
    assert [json.loads(x) for x in log.read_text().splitlines()[1:]] == [
        {"block": 4},
        {"block": 0},
        {"block": 7},
    ]


def test_sync_behind_logs_nothing_after_a_failed_sync(tmp_path):
    """A descriptor that cannot be synced (a pipe: EINVAL) fails its block, and every later
    block too: nothing reaches the log, and settling reports no block as kept."""
    log = tmp_path / "c.part.jsonl"
    log.write_text('{"format": "test"}\n')
    read_end, write_end = os.pipe()
    log_fd = os.open(log, os.O_WRONLY | os.O_APPEND)
    sync = SyncBehind(write_end, log_fd)
    try:
        sync.submit(0)
        with pytest.raises(OSError):
            sync.wait_oldest()
        sync.submit(1)
        sync.submit(2)
        assert sync.settle() == []
        assert not sync.pending
    finally:
        sync.close()
        for f in (read_end, write_end, log_fd):
            os.close(f)
    assert log.read_text().splitlines()[1:] == []


def _peak_rss_script(path: Path, shape: tuple[int, int, int], chunks: tuple[int, int]) -> str:
    return textwrap.dedent(
        f"""
        import json, resource, sys
        sys.path[:0] = [{str(REPO)!r}, {str(HERE)!r}, {str(HERE.parent)!r}]
        import numpy as np, dask.array as da, xarray as xr
        from test_writer import lazy
        from sbrdf_xr.store.writer import write_cube
        shape, chunks = {shape!r}, {chunks!r}
        ch = tuple(
            da.core.normalize_chunks(c, (n,))[0] for c, n in zip(chunks + (shape[2],), shape)
        )
        dims = ("attitude", "phase_angle", "wavelength")
        ds = xr.Dataset({{"sbrdf": (dims, lazy(ch, "f8", seed=9))}})
        warm = ds.isel(attitude=slice(0, chunks[0]), phase_angle=slice(0, chunks[1]))
        write_cube(warm, {str(path)!r} + ".warm")  # one block: loads the libraries
        before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        write_cube(ds, {str(path)!r}, max_in_flight=2)
        after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        print(json.dumps({{"before": before * 1024, "after": after * 1024, "cube": ds.nbytes,
                          "block": ds["sbrdf"].data.blocks[0, 0].nbytes}}))
        """
    )


def _measure_peak(tmp_path: Path, shape, chunks) -> dict[str, int]:
    script = tmp_path / "rss.py"
    path = tmp_path / "big.nc"
    script.write_text(_peak_rss_script(path, shape, chunks))
    out = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, timeout=600, check=True
    )
    r = json.loads(out.stdout.strip().splitlines()[-1])
    assert path.stat().st_size >= r["cube"]
    return r


def test_peak_memory_small(tmp_path):
    r = _measure_peak(tmp_path, (400, 100, 500), (20, 25))  # 160 MB in 80 blocks of 2 MB
    growth = r["after"] - r["before"]
    # Two blocks in flight, plus Dask's and HDF5's bookkeeping: far below the cube.
    assert growth < max(10 * r["block"], 32 * 2**20), r
    assert growth < r["cube"] / 4, r


@pytest.mark.slow
def test_peak_memory_large(tmp_path):
    r = _measure_peak(tmp_path, (2000, 256, 400), (50, 64))  # 1.6 GB in 160 blocks of 10 MB
    growth = r["after"] - r["before"]
    assert growth < 20 * r["block"], r
    assert growth < r["cube"] / 8, r


# ------------------------------------------------------------------ distributed


def test_local_cluster(tmp_path):
    distributed = pytest.importorskip("distributed")
    with (
        distributed.LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
            local_directory=str(tmp_path / "dask"),
        ) as cluster,
        distributed.Client(cluster, set_as_default=False) as client,
    ):
        out = write_cube(make_cube(), tmp_path / "c.nc", client=client)
        assert client.status == "running"  # a given client is left open
    xr.testing.assert_identical(read(out), make_cube().compute())


def _wait_for(predicate, what: str) -> None:
    deadline = time.monotonic() + CLUSTER_TIMEOUT
    while not predicate():
        if time.monotonic() > deadline:
            raise TimeoutError(f"timed out waiting for {what}")
        time.sleep(0.1)


@pytest.fixture
def dask_cluster(tmp_path):
    """A scheduler and two single-thread workers as separate processes on loopback."""
    distributed = pytest.importorskip("distributed")
    sfile = tmp_path / "scheduler.json"
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(REPO), str(HERE), str(HERE.parent)]),
    }
    common = ["--no-dashboard"]
    procs: list[subprocess.Popen] = []
    logs = []

    def start(module: str, *args: str) -> subprocess.Popen:
        log = open(tmp_path / f"{module.rsplit('.', 1)[-1]}-{len(procs)}.log", "w")
        logs.append(log)
        p = subprocess.Popen(
            [sys.executable, "-m", module, *args, *common],
            env=env,
            cwd=tmp_path,
            stdout=log,
            stderr=subprocess.STDOUT,
        )
        procs.append(p)
        return p

    try:
        start(
            "distributed.cli.dask_scheduler",
            "--host",
            "127.0.0.1",
            "--port",
            "0",
            "--scheduler-file",
            str(sfile),
        )
        _wait_for(lambda: sfile.exists() and sfile.stat().st_size > 0, "the scheduler file")
        address = json.loads(sfile.read_text())["address"]
        workers = [
            start(
                "distributed.cli.dask_worker",
                "--scheduler-file",
                str(sfile),
                "--nthreads",
                "1",
                "--no-nanny",
                "--host",
                "127.0.0.1",
                "--local-directory",
                str(tmp_path / "dask"),
                "--death-timeout",
                "60",
            )
            for _ in range(2)
        ]
        with distributed.Client(address, set_as_default=False, timeout=CLUSTER_TIMEOUT) as c:
            c.wait_for_workers(2, timeout=CLUSTER_TIMEOUT)
        yield address, workers
    finally:
        for p in reversed(procs):  # workers first, then the scheduler
            if p.poll() is None:
                p.terminate()
        deadline = time.monotonic() + 5.0
        for p in procs:
            try:
                p.wait(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                p.kill()  # a graceful close that hangs must not hang the tests
                p.wait(timeout=CLUSTER_TIMEOUT)
        for log in logs:
            log.close()


def test_scheduler_address(tmp_path, dask_cluster):
    address, _ = dask_cluster
    out = write_cube(make_cube(), tmp_path / "c.nc", scheduler=address, progress=True)
    xr.testing.assert_identical(read(out), make_cube().compute())


def test_worker_killed_mid_sweep(tmp_path, dask_cluster):
    address, workers = dask_cluster
    calls = tmp_path / "calls.jsonl"
    ds = make_cube(chunks=(3, 2), calls=str(calls), delay=0.05)  # 20 blocks
    events: list[int] = []
    killed: list[int] = []

    def on_block(event: BlockWritten) -> None:
        events.append(event.index)
        if len(events) == 3:
            os.kill(workers[0].pid, signal.SIGKILL)
            killed.append(workers[0].pid)

    out = write_cube(ds, tmp_path / "c.nc", scheduler=address, on_block=on_block)
    assert killed and workers[0].wait(timeout=CLUSTER_TIMEOUT) == -signal.SIGKILL
    assert sorted(events) == list(range(20)), "a block was lost or written twice"
    xr.testing.assert_identical(read(out), make_cube(chunks=(3, 2)).compute())
    irradiance = [tuple(loc[1:3]) for loc in logged_blocks(calls) if loc[0] == 1]
    assert set(irradiance) == {(i, j) for i in range(4) for j in range(5)}
    # Blocks lost with the worker were computed again (how many depends on timing).
    assert len(irradiance) >= 20


@pytest.mark.parametrize("recorded", [True, False], ids=["sidecar", "sidecar-without-level"])
def test_resume_with_another_complevel_is_refused_and_touches_nothing(tmp_path, recorded):
    """The level is read from the sidecar (or, from a sidecar that predates it, from the
    ``.part`` itself, read-only); another level is refused, naming the one to use."""
    path = tmp_path / "c.nc"
    switch = tmp_path / "fail"
    switch.touch()
    with pytest.raises(CubeWriteError):
        write_cube(make_cube(fail_switch=str(switch), fail_at=(1, 1)), path, complevel=3)
    part, log = path.with_name(path.name + PART_SUFFIX), path.with_name(path.name + LOG_SUFFIX)
    if not recorded:
        lines = log.read_text().splitlines()
        header = json.loads(lines[0])
        del header["complevel"]
        log.write_text("\n".join([json.dumps(header), *lines[1:]]) + "\n")
    before = {p.name: p.read_bytes() for p in (part, log)}
    with pytest.raises(CubeWriteError, match=r"started with complevel 3 .*complevel=3"):
        write_cube(make_cube(), path, resume=True)
    assert {p.name: p.read_bytes() for p in (part, log)} == before
    write_cube(make_cube(), path, resume=True, complevel=3)
    xr.testing.assert_identical(read(path), make_cube().compute())
