"""Tests of sbrdf_xr.engine.attitude_table: one reader of attitude tables, so that
``Scene(attitude={...})`` and a scene file's ``[attitude]`` give the same scene."""

from __future__ import annotations

import tomllib

import astropy.units as u
import numpy as np
import pytest
import trimesh

from sbrdf_xr import geometry, load_spacecraft
from sbrdf_xr.engine import Scene, attitudes_from_table, scene_from_dict, simulate
from sbrdf_xr.errors import SceneError, UnitError
from sbrdf_xr.materials import models, open_model

#: One TOML ``[attitude]`` table of every kind (the scene-file form).
TABLES = {
    "sweep": 'kind = "sweep"\naxis = [0, 0, -1]\nstart = 5\nstop = 95\nstep = 30\n'
    "initial_axis = [0, 1, 0]\ninitial_angle = 20\n",
    "default-sweep": "stop = 3\n",
    "uniform": 'kind = "uniform"\nn = 4\nseed = 7\n',
    "euler": 'kind = "euler"\nsequence = "zyx"\nangles = [[10, 20, 30], [40, 50, 60]]\n',
    "euler-one-row": 'kind = "euler"\nsequence = "zyx"\nangles = [10, 20, 30]\n',
    "quaternions": 'kind = "quaternions"\nquaternions = [[0, 0, 0, 1], [0, 0, 1, 0]]\n',
}


def _mesh(tmp_path):
    mesh = tmp_path / "box.stl"
    trimesh.creation.box(extents=(1.0, 2.0, 3.0)).export(mesh)
    models.to_netcdf(
        models.model_material(
            "lambert", [500.0, 600.0, 700.0], material="paint", provenance="albedo 0.5", rho=0.5
        ),
        tmp_path / "paint.nc",
    )
    return mesh


@pytest.mark.parametrize("kind", list(TABLES))
def test_python_and_scene_files_take_the_same_attitude_tables(tmp_path, kind):
    """The file's [attitude] and Scene(attitude=<the same table>) plan and simulate alike."""
    mesh = _mesh(tmp_path)
    text = (
        'spacecraft = { path = "box.stl", material = "paint" }\n'
        "phase_angles = [10.0, 90.0]\n"
        '[materials]\npaint = "paint.nc"\n'
        f"[attitude]\n{TABLES[kind]}"
    )
    d = tomllib.loads(text)
    from_file = scene_from_dict(d, base_dir=tmp_path)
    in_python = Scene(
        load_spacecraft(mesh, material="paint"),
        materials={"paint": open_model(tmp_path / "paint.nc")},
        attitude=d["attitude"],
        phase_angles=[10.0, 90.0],
    )
    np.testing.assert_array_equal(in_python.attitudes, from_file.attitudes)
    if from_file.attitude_angle is None:
        assert in_python.attitude_angle is None
    else:
        np.testing.assert_array_equal(in_python.attitude_angle, from_file.attitude_angle)
    assert str(in_python.plan()) == str(from_file.plan())
    a, b = simulate(in_python), simulate(from_file)
    for v in ("signal", "spacecraft_sbrdf", "area"):
        np.testing.assert_array_equal(a[v].values, b[v].values)


def test_each_kind_is_the_geometry_function_it_names():
    """sweep -> rotation_sweep, uniform -> uniform_attitudes, euler -> euler_attitudes."""
    q, angles = attitudes_from_table(tomllib.loads(TABLES["sweep"]))
    initial = geometry.axis_rotation([0, 1, 0], 20.0)
    np.testing.assert_array_equal(
        q, geometry.rotation_sweep([0, 0, -1], [5.0, 35.0, 65.0], initial)
    )
    assert angles.tolist() == [5.0, 35.0, 65.0]  # stop excluded
    q, angles = attitudes_from_table(tomllib.loads(TABLES["uniform"]))
    np.testing.assert_array_equal(q, geometry.uniform_attitudes(4, 7))
    assert angles is None
    q, _ = attitudes_from_table(tomllib.loads(TABLES["euler"]))
    np.testing.assert_array_equal(q, geometry.euler_attitudes("zyx", [[10, 20, 30], [40, 50, 60]]))


def test_python_values_arrays_tuples_and_quantities():
    """numpy arrays and tuples are taken as lists, angle Quantities in degree."""
    as_file = attitudes_from_table({"kind": "sweep", "stop": 90, "step": 30, "axis": [1, 0, 0]})
    in_python = attitudes_from_table(
        {"kind": "sweep", "stop": np.pi / 2 * u.rad, "step": 30 * u.deg, "axis": (1, 0, 0)}
    )
    # pi / 2 rad -> 90 deg up to rounding of the conversion (1 ulp); the sweep excludes stop
    np.testing.assert_allclose(in_python[0], as_file[0], rtol=0, atol=1e-15)
    quats = np.array([[0.0, 0.0, 0.0, 1.0]])
    q, _ = attitudes_from_table({"kind": "quaternions", "quaternions": quats})
    np.testing.assert_array_equal(q, quats)
    q, _ = attitudes_from_table({"kind": "uniform", "n": np.int64(3)})
    assert q.shape == (3, 4)
    with pytest.raises(UnitError, match="attitude stop"):
        attitudes_from_table({"stop": 3 * u.m}, "attitude")


@pytest.mark.parametrize(
    "table, match",
    [
        ({"kind": "sweep", "stpo": 90}, r"attitude: unknown key 'stpo'; did you mean 'stop'"),
        ({"kind": "spin"}, "unknown kind 'spin'; allowed: sweep, uniform, euler, quaternions"),
        ({"kind": "uniform"}, "kind 'uniform' needs 'n'"),
        ({"stop": 10, "step": 0}, "attitude step: must not be 0"),
        ({"kind": "euler", "sequence": "zyx"}, "needs 'sequence'.*and 'angles'"),
        ({"kind": "quaternions", "quaternions": [[0, 0, 1]]}, r"quaternions\[0\]: expected 4"),
        ({"stop": "90"}, "key 'stop' has type str"),
    ],
)
def test_a_bad_table_is_named_in_python_terms(table, match):
    box = load_spacecraft(trimesh.creation.box(), material="paint")
    with pytest.raises(SceneError, match=match):
        Scene(box, attitude=table, phase_angles=[10.0])


def test_attitude_and_attitudes_are_one_or_the_other():
    box = load_spacecraft(trimesh.creation.box(), material="paint")
    with pytest.raises(SceneError, match=r"either attitude .* or attitudes"):
        Scene(box, attitude={"stop": 3}, attitudes=[[0, 0, 0, 1.0]], phase_angles=[10.0])
    with pytest.raises(SceneError, match="a grid needs both"):
        Scene(box, attitude={"stop": 3})
    scene = Scene(box, attitude={"stop": 3}, phase_angles=[10.0], attitude_angle=[7, 8, 9])
    assert np.asarray(scene.attitude_angle).tolist() == [7, 8, 9]  # given labels are kept
    assert scene.with_options(method="cubic").attitudes.shape == (3, 4)  # copies keep them
