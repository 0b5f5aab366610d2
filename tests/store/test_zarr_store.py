"""Tests of sbrdf_xr.store.zarr_store.write_zarr: Zarr cubes with the netCDF writer's rules.

The same synthetic lazy cubes as the netCDF writer's tests (``test_writer.make_cube``):
deterministic blocks, optionally logged to a file (which block was computed, how often)
and failing on a file-based switch.  Kill trials, concurrent writers and a cluster that
loses its workers are in ``test_faults.py``.
"""

from __future__ import annotations

import json
import logging
import os
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from sbrdf_xr._output import MARKER, command_line_messages
from sbrdf_xr.errors import CubeLockedError, CubeWriteError, ValidationError
from sbrdf_xr.store import formats
from sbrdf_xr.store.files import PART_SUFFIX
from sbrdf_xr.store.lock import LOCK_SUFFIX
from sbrdf_xr.store.writer import write_cube
from sbrdf_xr.store.zarr_store import BLOCKS, marked_blocks, unfinished, write_zarr

pytest.importorskip("zarr")

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from test_writer import logged_blocks, make_cube, make_geometry_cube  # noqa: E402


def read(path: Path) -> xr.Dataset:
    with xr.open_zarr(path) as ds:
        return ds.load()


def tree(d: Path) -> dict[str, bytes | None]:
    """Every entry under ``d``: relative name -> bytes of a file, None for a directory,
    ``"-> target"`` for a symbolic link (not followed)."""
    out: dict[str, bytes | str | None] = {}
    for root, dirs, files in os.walk(d):
        for n in dirs + files:
            p = Path(root) / n
            rel = str(p.relative_to(d))
            if p.is_symlink():
                out[rel] = f"-> {os.readlink(p)}"
            else:
                out[rel] = None if p.is_dir() else p.read_bytes()
    return out


@pytest.mark.parametrize(
    "factory",
    [
        make_cube,
        lambda: make_cube(chunks=(12, 10)),  # a single block
        lambda: make_cube(chunks=(5, 3)),  # last chunks smaller
        make_geometry_cube,
    ],
    ids=["grid", "one-block", "ragged-end", "geometry"],
)
def test_round_trip_equals_the_cube_and_the_netcdf_writer(tmp_path, factory):
    ds = factory()
    path = write_zarr(ds, tmp_path / "c.zarr")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.zarr"]
    assert MARKER in os.listdir(path) and BLOCKS not in os.listdir(path)
    back = read(path)
    xr.testing.assert_identical(back, ds.compute())
    with xr.open_dataset(write_cube(ds, tmp_path / "c.nc")) as nc:
        xr.testing.assert_identical(back, nc.load())


def test_complevel_chooses_the_compression_and_keeps_values(tmp_path):
    import zarr

    ds = make_cube()
    default = write_zarr(ds, tmp_path / "default.zarr")
    plain = write_zarr(ds, tmp_path / "plain.zarr", complevel=0)
    packed = write_zarr(ds, tmp_path / "packed.zarr", complevel=5)

    def codec(store):
        return zarr.open_array(store=str(store / "sbrdf"), mode="r").metadata.compressor

    assert codec(default).cname == "lz4"  # Zarr's own default
    assert codec(plain) is None
    assert (codec(packed).cname, codec(packed).clevel, codec(packed).shuffle) == ("zlib", 5, 1)
    xr.testing.assert_identical(read(plain), read(packed))
    xr.testing.assert_identical(read(plain), read(default))
    with pytest.raises(ValidationError, match="complevel"):
        write_zarr(ds, tmp_path / "bad.zarr", complevel=10)


def test_each_block_is_computed_once_and_marked_after_its_data(tmp_path):
    calls = tmp_path / "calls.jsonl"
    seen: list[tuple[int, set[int]]] = []
    part = tmp_path / ("c.zarr" + PART_SUFFIX)

    def on_block(event):  # the mark of a block is on disk when it is reported
        seen.append((event.index, marked_blocks(part, event.n_blocks)))

    ds = make_cube(calls=str(calls))
    write_zarr(ds, tmp_path / "c.zarr", on_block=on_block, max_in_flight=2)
    assert all(k in marks for k, marks in seen) and len(seen) == 9
    irradiance = [tuple(loc[1:3]) for loc in logged_blocks(calls) if loc[0] == 1]
    assert sorted(irradiance) == sorted({(i, j) for i in range(3) for j in range(3)})


def test_resume_computes_only_the_unmarked_blocks(tmp_path):
    path = tmp_path / "c.zarr"
    calls, switch = tmp_path / "calls.jsonl", tmp_path / "fail"
    switch.touch()
    with pytest.raises(CubeWriteError) as info:
        write_zarr(
            make_cube(calls=str(calls), fail_switch=str(switch), fail_at=(2, 1)),
            path,
            scheduler="synchronous",
        )
    message = str(info.value)
    assert "injected failure" in message and "resume=True" in message and "write_zarr" in message
    part = path.with_name(path.name + PART_SUFFIX)
    kept = marked_blocks(part, 9)
    assert kept == set(range(7)) and not path.exists()
    assert "7 of 9 blocks stored, Zarr's default compression" in unfinished(path)
    switch.unlink()
    calls.unlink()
    write_zarr(make_cube(calls=str(calls)), path, resume=True)
    again = {tuple(loc[1:3]) for loc in logged_blocks(calls) if loc[0] == 1}
    assert again == {(2, 1), (2, 2)}  # blocks 7 and 8 only
    xr.testing.assert_identical(read(path), make_cube().compute())
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.zarr", "calls.jsonl"]


@pytest.mark.parametrize(
    ("other", "match"),
    [
        (lambda: make_cube(n_attitude=13), "dims and sizes differ"),
        (lambda: make_cube(chunks=(4, 4)), "chunks differ"),
        (lambda: make_cube().assign_attrs(title="another"), "global attribute 'title'"),
    ],
    ids=["dims", "chunks", "attribute"],
)
def test_resume_with_other_inputs_is_refused_and_names_the_change(tmp_path, other, match):
    path = tmp_path / "c.zarr"
    switch = tmp_path / "fail"
    switch.touch()
    with pytest.raises(CubeWriteError):
        write_zarr(make_cube(fail_switch=str(switch), fail_at=(1, 0)), path)
    part = path.with_name(path.name + PART_SUFFIX)
    before = tree(part)
    with pytest.raises(CubeWriteError, match=match):
        write_zarr(other(), path, resume=True)
    assert tree(part) == before


def test_resume_with_another_complevel_is_refused_naming_the_level(tmp_path):
    path = tmp_path / "c.zarr"
    switch = tmp_path / "fail"
    switch.touch()
    with pytest.raises(CubeWriteError):
        write_zarr(make_cube(fail_switch=str(switch), fail_at=(1, 0)), path, complevel=3)
    part = path.with_name(path.name + PART_SUFFIX)
    before = tree(part)
    with pytest.raises(CubeWriteError, match=r"started with complevel 3.*complevel=3"):
        write_zarr(make_cube(), path, resume=True, complevel=0)
    with command_line_messages(), pytest.raises(CubeWriteError, match="--complevel 3"):
        write_zarr(make_cube(), path, resume=True, complevel=5)
    assert tree(part) == before
    switch.unlink()
    write_zarr(make_cube(), path, resume=True)  # no level given: the .part's is kept
    xr.testing.assert_identical(read(path), make_cube().compute())
    import zarr

    assert zarr.open_array(store=str(path / "sbrdf"), mode="r").metadata.compressor.clevel == 3


def test_a_leftover_part_is_kept_without_overwrite(tmp_path):
    path = tmp_path / "c.zarr"
    switch = tmp_path / "fail"
    switch.touch()
    with pytest.raises(CubeWriteError):
        write_zarr(make_cube(fail_switch=str(switch), fail_at=(1, 0)), path)
    part = path.with_name(path.name + PART_SUFFIX)
    before = tree(part)
    with pytest.raises(FileExistsError, match="unfinished write"):
        write_zarr(make_cube(), path)
    assert tree(part) == before
    write_zarr(make_cube(), path, overwrite=True)  # discarded, written afresh
    xr.testing.assert_identical(read(path), make_cube().compute())
    assert not part.exists()


def test_overwrite_replaces_only_a_store_this_package_wrote(tmp_path):
    path = tmp_path / "c.zarr"
    write_zarr(make_cube(n_attitude=6), path)
    with pytest.raises(FileExistsError, match="exists; pass overwrite=True"):
        write_zarr(make_cube(), path)
    write_zarr(make_cube(), path, overwrite=True)
    xr.testing.assert_identical(read(path), make_cube().compute())
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.zarr"]

    photos = tmp_path / "photos.zarr"
    photos.mkdir()
    (photos / "holiday.jpg").write_bytes(b"\xff\xd8 a user's photo")
    for kw in ({"overwrite": True}, {"overwrite": True, "resume": True}, {}):
        with pytest.raises(CubeWriteError, match=r"did not write.*left as it is"):
            write_zarr(make_cube(), photos, **kw)
    assert tree(photos) == {"holiday.jpg": b"\xff\xd8 a user's photo"}

    empty = tmp_path / "empty.zarr"
    empty.mkdir()  # not ours either: never replaced, even empty
    with pytest.raises(CubeWriteError, match="did not write"):
        write_zarr(make_cube(), empty, overwrite=True)
    assert empty.is_dir() and not any(empty.iterdir())


def test_a_foreign_part_directory_is_never_deleted(tmp_path):
    path = tmp_path / "c.zarr"
    part = path.with_name(path.name + PART_SUFFIX)
    part.mkdir()
    (part / "notes.txt").write_text("mine")
    for kw in ({}, {"overwrite": True}, {"resume": True}, {"overwrite": True, "resume": True}):
        with pytest.raises(CubeWriteError, match="did not write"):
            write_zarr(make_cube(), path, **kw)
    assert tree(part) == {"notes.txt": b"mine"}
    (part / "notes.txt").unlink()  # an empty .part holds nothing: it is used
    write_zarr(make_cube(), path)
    assert not part.exists() and path.is_dir()


@pytest.mark.parametrize("where", ["path", "part"])
@pytest.mark.parametrize("dangling", [False, True], ids=["symlink", "dangling-symlink"])
def test_symbolic_links_are_refused_and_their_targets_kept(tmp_path, where, dangling):
    path = tmp_path / "c.zarr"
    target = tmp_path / "elsewhere"
    if not dangling:
        write_zarr(make_cube(n_attitude=6), target)  # even a store of ours, behind a link
    link = path if where == "path" else path.with_name(path.name + PART_SUFFIX)
    link.symlink_to(target)
    before = tree(tmp_path)
    for kw in ({"overwrite": True}, {"overwrite": True, "resume": True}):
        with pytest.raises(CubeWriteError, match="is a symbolic link, not a directory"):
            write_zarr(make_cube(), path, **kw)
    assert tree(tmp_path) == before and link.is_symlink()


def test_resume_of_a_finished_store_is_a_no_op(tmp_path, caplog):
    path = write_zarr(make_cube(), tmp_path / "c.zarr")
    before = tree(path)
    with caplog.at_level(logging.INFO, logger="sbrdf_xr.write_cube"):
        assert write_zarr(make_cube(), path, resume=True) == path
    assert any("already complete" in r.getMessage() for r in caplog.records)
    assert tree(path) == before
    with pytest.raises(CubeWriteError, match="finished cube of other inputs"):
        write_zarr(make_cube(n_attitude=13), path, resume=True)
    assert tree(path) == before


def test_irregular_chunks_are_refused_before_anything_is_written(tmp_path):
    with pytest.raises(ValidationError, match="equal size along phase_angle"):
        write_zarr(make_cube(chunks=(4, (3, 3, 4))), tmp_path / "c.zarr")
    assert list(tmp_path.iterdir()) == []


def test_lock_keeps_writers_apart_and_is_released_on_every_exit(tmp_path):
    path = tmp_path / "c.zarr"
    lock = path.with_name(path.name + LOCK_SUFFIX)
    lock.write_text(json.dumps({"pid": 1, "host": "elsewhere.example", "started": "then"}))
    with pytest.raises(CubeLockedError, match=r"elsewhere\.example"):
        write_zarr(make_cube(), path)
    lock.unlink()

    def interrupt(event):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt) as info:
        write_zarr(make_cube(), path, on_block=interrupt)
    assert "write_zarr" in "".join(info.value.__notes__) and not lock.exists()
    write_zarr(make_cube(), path, resume=True)
    assert not lock.exists()
    xr.testing.assert_identical(read(path), make_cube().compute())


def test_the_registry_picks_zarr_by_suffix_and_writes_times(tmp_path):
    times = np.array(["2026-01-01T00:00", "2026-01-01T00:01"], dtype="datetime64[ns]")
    cube = xr.Dataset({"v": ("time", [1.0, 2.0], {"units": "1"})}, coords={"time": times})
    cube = cube.chunk(time=1)
    assert formats.format_for(tmp_path / "c.zarr/", "cube").name == "zarr-cube"
    path = formats.write(cube, tmp_path / "c.zarr")
    xr.testing.assert_identical(read(path), cube.compute())


def test_a_store_that_cannot_be_created_leaves_nothing(tmp_path, monkeypatch):
    """A full disk while the store's metadata are written: named, and no ``.part`` left
    (no block was recorded, so nothing is lost)."""
    import errno

    def full(self, *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(xr.Dataset, "to_zarr", full)
    with pytest.raises(CubeWriteError, match=r"no space left on device.*Nothing was written"):
        write_zarr(make_cube(), tmp_path / "c.zarr")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("stop_in", ["make_marked_dir", "to_zarr", "rename_no_replace"])
def test_a_writer_stopped_while_creating_or_renaming_resumes(tmp_path, monkeypatch, stop_in):
    """Stopped (as by a kill) while the store is created, or when it is complete and
    being renamed (its block marks already removed): a resume finishes it."""
    import sbrdf_xr.store.zarr_store as zs

    path = tmp_path / "c.zarr"
    original = xr.Dataset.to_zarr if stop_in == "to_zarr" else getattr(zs, stop_in)

    def stopped(*args, **kwargs):
        if stop_in == "make_marked_dir":
            original(*args, **kwargs)  # the directory and its marker, then the stop
        raise KeyboardInterrupt

    if stop_in == "to_zarr":
        monkeypatch.setattr(xr.Dataset, "to_zarr", stopped)
    else:
        monkeypatch.setattr(zs, stop_in, stopped)
    with pytest.raises(KeyboardInterrupt):
        write_zarr(make_cube(), path)
    part = path.with_name(path.name + PART_SUFFIX)
    assert part.is_dir() and not path.exists()
    monkeypatch.undo()
    write_zarr(make_cube(), path, resume=True)
    xr.testing.assert_identical(read(path), make_cube().compute())
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.zarr"]


@pytest.mark.parametrize("layout", ["writer first", "sorted keys"])
@pytest.mark.parametrize("how", ["resume", "overwrite"])
def test_a_part_whose_marker_was_cut_short_is_recovered(tmp_path, caplog, how, layout):
    """A ``.part`` whose marker a full disk cut short (a short write, before writes were
    checked to be whole; the issue's was cut at 4096 bytes): still the package's own,
    whether written with the writer first (now) or with sorted keys (earlier versions); a
    plain rerun names what to do, ``resume`` and ``overwrite`` write the cube again in
    place."""
    path = tmp_path / "c.zarr"
    part = path.with_name(path.name + PART_SUFFIX)
    write_zarr(make_cube(), path)
    os.rename(path, part)
    whole = (part / MARKER).read_bytes()
    if layout == "sorted keys":
        whole = json.dumps(json.loads(whole), sort_keys=True).encode()
    (part / MARKER).write_bytes(whole[: len(whole) // 2])
    with pytest.raises(FileExistsError, match=r"an unfinished write of c\.zarr"):
        write_zarr(make_cube(), path)
    with caplog.at_level(logging.WARNING, logger="sbrdf_xr.write_cube"):
        write_zarr(make_cube(), path, **{how: True})
    if how == "resume":
        assert any("was cut short" in r.getMessage() for r in caplog.records)
    xr.testing.assert_identical(read(path), make_cube().compute())
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.zarr"]


def test_a_marker_written_by_short_writes_is_whole(tmp_path, monkeypatch):
    """``os.write`` writing at most 100 bytes a call (as on a disk filling up): the marker
    is written whole; a write that makes no progress (the disk full) leaves no marker."""
    import errno as _errno

    from sbrdf_xr._output import read_marker, write_marker

    real = os.write
    monkeypatch.setattr(os, "write", lambda fd, data: real(fd, bytes(data[:100])))
    info = {"state": "writing", "structure": {"text": "x" * 5000}}
    write_marker(tmp_path, info)
    assert read_marker(tmp_path) == {"writer": "sbrdf_xr", **info}
    calls = []

    def full(fd, data):  # 100 bytes fit, then the disk is full
        calls.append(len(data))
        if len(calls) > 1:
            raise OSError(_errno.ENOSPC, "No space left on device")
        return real(fd, bytes(data[:100]))

    monkeypatch.setattr(os, "write", full)
    with pytest.raises(OSError) as info_exc:
        write_marker(tmp_path, {**info, "state": "complete"})
    assert info_exc.value.errno == _errno.ENOSPC
    assert read_marker(tmp_path)["state"] == "writing"  # the old marker, untouched
    assert sorted(os.listdir(tmp_path)) == [MARKER]  # no temporary file left
