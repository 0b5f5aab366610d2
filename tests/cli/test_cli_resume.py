"""``sbrdf-xr simulate --resume`` states what it keeps, and refuses what it cannot keep.

A run is interrupted (``KeyboardInterrupt`` from the block callback, as Ctrl-C would)
after two of five blocks; the command line's ``--resume`` then prints what the ``.part``
keeps (blocks, complevel, chunks) and finishes the cube (with the ``.part``'s blocks if
others are asked), or refuses a resume whose complevel, settings or format differ from the
``.part``'s (a ``.part`` of the other
format under the name, or the cube unfinished under the other format's suffix), in one
line that names the difference, leaving the ``.part`` as it was.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest
import xarray as xr

from sbrdf_xr import simulate
from sbrdf_xr.cli import main
from sbrdf_xr.store import PART_SUFFIX, write

SCENE = """
name = "grey-box"
spacecraft = { path = "box.stl", material = "lambertian-grey-50" }
phase_angles = [0.0, 60.0]
chunk = 2
[attitude]
kind = "sweep"
axis = [0, 0, 1]
stop = 90.0
step = 10.0
"""


@pytest.fixture
def scene(tmp_path) -> Path:
    import trimesh

    trimesh.creation.box().export(tmp_path / "box.stl")
    path = tmp_path / "box.toml"
    path.write_text(SCENE)
    return path


def interrupted(scene: Path, out: Path, **kw) -> None:
    """Leave ``out``'s ``.part`` with two of the cube's five blocks."""

    def stop(event):
        if event.n_written == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        write(simulate(scene), out, on_block=stop, max_in_flight=1, **kw)
    assert out.with_name(out.name + PART_SUFFIX).exists() and not out.exists()


def snapshot(part: Path) -> dict[str, bytes]:
    if part.is_file():
        return {part.name: part.read_bytes()}
    return {
        str(Path(r, f).relative_to(part)): Path(r, f).read_bytes()
        for r, _, fs in os.walk(part)
        for f in fs
    }


def read(path: Path) -> xr.Dataset:
    with xr.open_zarr(path) if path.suffix == ".zarr" else xr.open_dataset(path) as ds:
        return ds.load()


@pytest.mark.parametrize("suffix", [".nc", ".zarr"])
@pytest.mark.parametrize("level", [[], ["--complevel", "2"]], ids=["kept", "same"])
def test_resume_states_what_it_keeps(tmp_path, scene, capsys, suffix, level):
    if suffix == ".zarr":
        pytest.importorskip("zarr")
    out = tmp_path / f"cube{suffix}"
    interrupted(scene, out, complevel=2)
    assert main(["simulate", str(scene), "-o", str(out), "--resume", "-q", *level]) == 0
    lines = capsys.readouterr().out.splitlines()
    said = next(line for line in lines if line.startswith("resumed "))
    # the two blocks reported, and perhaps the next one, synced behind them
    assert re.search(rf"{re.escape(str(out))}{PART_SUFFIX}: [23] of 5 blocks", said), said
    assert "complevel 2, chunks of attitude 2;" in said and "those were kept" in said
    assert lines[-1] == f"wrote {out}"
    clean = write(simulate(scene), tmp_path / f"clean{suffix}", complevel=2)
    xr.testing.assert_identical(read(out).drop_attrs(), read(clean).drop_attrs())


@pytest.mark.parametrize("suffix", [".nc", ".zarr"])
@pytest.mark.parametrize(
    ("extra", "match"),
    [
        (["--complevel", "5"], "started with complevel 2 .*Resume with --complevel 2"),
        (["--set", "method=cubic"], r"different cube \(setting 'method': 'linear' -> 'cubic'\)"),
    ],
    ids=["complevel", "setting"],
)
def test_resume_refuses_another_layout_in_one_line(tmp_path, scene, capsys, suffix, extra, match):
    if suffix == ".zarr":
        pytest.importorskip("zarr")
    out = tmp_path / f"cube{suffix}"
    interrupted(scene, out, complevel=2)
    part = out.with_name(out.name + PART_SUFFIX)
    before = snapshot(part)
    assert main(["simulate", str(scene), "-o", str(out), "--resume", "-q", *extra]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and re.search(match, err[0]), err
    assert "--overwrite" in err[0]
    assert snapshot(part) == before and not out.exists()


@pytest.mark.parametrize("suffix", [".nc", ".zarr"])
def test_resume_with_other_blocks_finishes_with_the_parts_own(tmp_path, scene, capsys, suffix):
    """Block sizes do not change a value: a ``.part`` begun with other blocks (another
    ``chunk`` or ``block_bytes``, or an older default) is finished with its own."""
    if suffix == ".zarr":
        pytest.importorskip("zarr")
    out = tmp_path / f"cube{suffix}"
    interrupted(scene, out, complevel=2)
    argv = ["simulate", str(scene), "-o", str(out), "--resume", "-q", "--set", "chunk=5"]
    assert main(argv) == 0
    assert "those were kept" in capsys.readouterr().out
    clean = write(simulate(scene), tmp_path / f"clean{suffix}", complevel=2)
    xr.testing.assert_identical(read(out).drop_attrs(), read(clean).drop_attrs())
    assert read(out).attrs["knob_chunk"] == 2  # the blocks it was begun with


def test_resume_refuses_the_part_of_another_format(tmp_path, scene, capsys):
    """A ``.part`` left by the other format (here a netCDF ``.part`` where a Zarr store's
    goes) is named and kept, not replaced or taken for a store."""
    pytest.importorskip("zarr")
    nc = tmp_path / "cube.nc"
    interrupted(scene, nc)
    zarr = tmp_path / "cube.zarr"
    os.rename(nc.with_name(nc.name + PART_SUFFIX), zarr.with_name(zarr.name + PART_SUFFIX))
    for flags in (["--resume"], ["--overwrite"], ["--resume", "--overwrite"]):
        assert main(["simulate", str(scene), "-o", str(zarr), "-q", *flags]) == 2
        err = capsys.readouterr().err
        assert "cube.zarr.part is a regular file, not a directory" in err, err
    assert (tmp_path / "cube.zarr.part").is_file()


@pytest.mark.parametrize(("started", "resumed"), [(".nc", ".zarr"), (".zarr", ".nc")])
def test_resume_in_another_format_names_the_unfinished_cube(
    tmp_path, scene, capsys, started, resumed
):
    """``--resume`` under the other format's suffix, with the cube unfinished in the
    format it was started in: refused in one line naming that cube, nothing written."""
    pytest.importorskip("zarr")
    first = tmp_path / f"cube{started}"
    interrupted(scene, first, complevel=2)
    part = first.with_name(first.name + PART_SUFFIX)
    before = snapshot(part)
    listing = sorted(p.name for p in tmp_path.iterdir())
    out = tmp_path / f"cube{resumed}"
    assert main(["simulate", str(scene), "-o", str(out), "--resume", "-q"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"the {'netCDF' if started == '.nc' else 'Zarr'} cube" in err[0]
    assert f"{first} is unfinished ({part}: " in err[0], err
    assert "a resume keeps the format it was started in" in err[0]
    assert snapshot(part) == before and sorted(p.name for p in tmp_path.iterdir()) == listing
    # without --resume the other format is written afresh, the unfinished cube kept
    assert main(["simulate", str(scene), "-o", str(out), "-q"]) == 0
    assert out.exists() and snapshot(part) == before
