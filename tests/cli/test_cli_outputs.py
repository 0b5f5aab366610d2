"""``sbrdf-xr simulate --outputs independent|all`` and a scene file's ``[write]`` table;
a ``.part`` begun with every variable (as versions before the lean cubes wrote it)
resumed with the variables it has.

The ``.part`` is made by a real killed write: a child process writes the cube with
``outputs="all"`` and kills itself (``SIGKILL``) after two of five blocks, as a machine
that loses power would.
"""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
import xarray as xr

from sbrdf_xr import simulate
from sbrdf_xr.cli import main
from sbrdf_xr.engine import load_scene
from sbrdf_xr.errors import CubeWriteError, SceneError
from sbrdf_xr.store import PART_SUFFIX
from sbrdf_xr.store.formats import write_netcdf_cube

REPO = Path(__file__).resolve().parents[2]
#: Seconds a killed child may take (a grey box of ten attitudes: well under one).
TIMEOUT = 120.0

SCENE = """
name = "grey-box"
spacecraft = { path = "box.stl", material = "lambertian-grey-50" }
phase_angles = [0.0, 60.0]
outputs = ["spacecraft_sbrdf", "signal", "brdf", "area", "per_material"]
chunk = 2
[attitude]
kind = "sweep"
axis = [0, 0, 1]
stop = 90.0
step = 10.0
"""

#: Every variable a cube of SCENE has, and those left out of a lean one.
DERIVED = {"brdf", "signal"}

KILLER = textwrap.dedent(
    """
    import os, signal, sys
    sys.path[:0] = [{repo!r}]
    from sbrdf_xr import simulate
    from sbrdf_xr.store.formats import write_netcdf_cube
    def on_block(event):
        if event.n_written == 2:
            os.kill(os.getpid(), signal.SIGKILL)
    # every variable written: the layout of a .part begun before the lean cubes
    write_netcdf_cube(simulate(sys.argv[1]), sys.argv[2], outputs="all", max_in_flight=1,
                      on_block=on_block)
    """
)


@pytest.fixture
def scene(tmp_path) -> Path:
    import trimesh

    trimesh.creation.box().export(tmp_path / "box.stl")
    path = tmp_path / "scene.toml"
    path.write_text(SCENE)
    return path


def _variables(path: Path) -> set[str]:
    with xr.open_dataset(path) as ds:
        return set(map(str, ds.data_vars))


@pytest.mark.parametrize("outputs", ["all", "independent"])
def test_the_option_chooses_the_variables_written(tmp_path, scene, outputs, capsys):
    out = tmp_path / "cube.nc"
    assert main(["simulate", str(scene), "-o", str(out), "-q", "--outputs", outputs]) == 0
    written = _variables(out)
    assert DERIVED <= written if outputs == "all" else not DERIVED & written
    assert "signal_material" in written and "spacecraft_sbrdf" in written


def test_the_scene_files_write_table_and_the_option_over_it(tmp_path, scene, capsys):
    scene.write_text(SCENE + '\n[write]\noutputs = "all"\n')
    out = tmp_path / "cube.nc"
    assert main(["simulate", str(scene), "-o", str(out), "-q"]) == 0
    assert DERIVED <= _variables(out)
    argv = ["simulate", str(scene), "-o", str(out), "-q", "--overwrite"]
    assert main([*argv, "--outputs", "independent"]) == 0  # the option wins
    assert not DERIVED & _variables(out)
    assert load_scene(scene).name == "grey-box"  # the table is no part of the scene


def test_a_bad_write_table_is_refused_by_name(tmp_path, scene, capsys):
    scene.write_text(SCENE + '\n[write]\noutputs = "every"\n')
    with pytest.raises(SceneError, match="\\[write\\] outputs: got 'every'; allowed: "):
        load_scene(scene)
    assert main(["simulate", str(scene), "-o", str(tmp_path / "c.nc"), "-q"]) == 2
    assert "[write] outputs: got 'every'" in capsys.readouterr().err
    scene.write_text(SCENE + "\n[write]\ncomplevel = 4\n")
    with pytest.raises(SceneError, match="\\[write\\]: unknown key 'complevel'"):
        load_scene(scene)
    with pytest.raises(SystemExit) as exc:  # argparse: the choices named
        main(["simulate", str(scene), "-o", "c.nc", "--outputs", "every"])
    assert exc.value.code == 2
    assert "choose from 'independent', 'all'" in capsys.readouterr().err


def _killed_with_every_variable(tmp_path: Path, scene: Path) -> Path:
    """A cube's ``.part`` written with every variable, its writer killed after two of
    five blocks."""
    out = tmp_path / "cube.nc"
    script = tmp_path / "killer.py"
    script.write_text(KILLER.format(repo=str(REPO)))
    proc = subprocess.run(
        [sys.executable, str(script), str(scene), str(out)],
        timeout=TIMEOUT,
        capture_output=True,
        text=True,
    )
    assert proc.returncode == -signal.SIGKILL, proc.stderr[-2000:]
    assert not out.exists() and out.with_name(out.name + PART_SUFFIX).exists()
    return out


def test_a_part_begun_with_every_variable_resumes_with_them(tmp_path, scene, capsys):
    out = _killed_with_every_variable(tmp_path, scene)
    part = out.with_name(out.name + PART_SUFFIX)
    before = part.read_bytes()
    # asked for the lean variables: refused by name, saying what resumes it; nothing touched
    with pytest.raises(
        CubeWriteError, match=r"started with outputs='all'.*Resume with outputs='all'"
    ):
        write_netcdf_cube(simulate(scene), out, resume=True, outputs="independent")
    argv = ["simulate", str(scene), "-o", str(out), "-q", "--resume"]
    assert main([*argv, "--outputs", "independent"]) == 2
    err = capsys.readouterr().err
    assert "Resume with --outputs all" in err and "--overwrite" in err, err
    assert part.read_bytes() == before
    # without --outputs the resume keeps the variables the .part has, and finishes it
    assert main(argv) == 0
    printed = capsys.readouterr().out
    # the kill comes after the second block is recorded; the writer's thread may record
    # one more before the signal lands
    kept = re.search(r"resumed .*: (\d) of 5 blocks written", printed)
    assert kept and 2 <= int(kept.group(1)) < 5, printed
    clean = write_netcdf_cube(simulate(scene), tmp_path / "clean.nc", outputs="all")
    with xr.open_dataset(out) as got, xr.open_dataset(clean) as want:
        assert DERIVED <= set(map(str, got.data_vars))
        xr.testing.assert_identical(got.drop_attrs(), want.drop_attrs())


def test_a_lean_part_resumes_lean_and_refuses_all(tmp_path, scene, capsys):
    out = tmp_path / "cube.nc"

    def stop(event):
        if event.n_written == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        write_netcdf_cube(simulate(scene), out, max_in_flight=1, on_block=stop)
    with pytest.raises(CubeWriteError, match="started with outputs='independent'"):
        write_netcdf_cube(simulate(scene), out, resume=True, outputs="all")
    write_netcdf_cube(simulate(scene), out, resume=True)
    assert not DERIVED & _variables(out)
