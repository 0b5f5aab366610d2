"""Tests of sbrdf_xr.engine.schema and sbrdf_xr.engine.knobs: one declaration of every
scene-file key and knob, the reference generated from it, and the material forms that
Python and TOML share."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest
import trimesh
import xarray as xr

from sbrdf_xr import load_spacecraft
from sbrdf_xr.cli.parser import build_parser
from sbrdf_xr.engine import Scene, builtin_scenes, load_scene, scene_from_dict, simulate
from sbrdf_xr.engine.knobs import KNOBS
from sbrdf_xr.engine.schema import SCENE_KEYS, reference
from sbrdf_xr.errors import SceneError
from sbrdf_xr.materials import models

REFERENCE = Path(__file__).resolve().parents[2] / "docs" / "guide" / "scene-file-reference.md"
X = [[1.0, 0.0, 0.0]]


def test_the_guide_reference_is_the_generated_one():
    text = REFERENCE.read_text(encoding="utf-8")
    found = re.search(r"<!-- scene-keys[^>]*-->\n(.*?)<!-- /scene-keys -->", text, re.DOTALL)
    assert found, "docs/guide/scene-file-reference.md: the scene-keys markers are missing"
    assert found.group(1) == reference(), (
        "docs/guide/scene-file-reference.md is stale: paste "
        "sbrdf_xr.engine.schema.reference() between its scene-keys markers"
    )
    for key in ("n", "seed", "kind", "quaternions", "to_earth", "earth", "path"):
        assert f"| `{key}` |" in found.group(1)


def test_every_knob_is_a_key_and_a_scene_field_declared_once():
    """The Scene's default, the TOML type and the check all come from the knob entry."""
    fields = {f.name: f for f in dataclasses.fields(Scene)}
    for name, knob in KNOBS.items():
        assert fields[name].default is knob.default
        assert SCENE_KEYS[name].types == knob.toml and knob.trades in SCENE_KEYS[name].help
    grey = {"paint": "lambertian-grey-50"}
    base = {"spacecraft": {"path": "box.stl", "material": "paint"}, "materials": grey}
    with pytest.raises(SceneError, match="key 'method' has type int"):
        scene_from_dict({**base, "method": 3})
    with pytest.raises(SceneError, match="key 'shadow_density' has type bool"):
        scene_from_dict({**base, "shadow_density": True})
    with pytest.raises(SceneError, match=r"chunk: got 0; expected None \(from block_bytes\)"):
        Scene(_box(), _grey_table(), to_sun=X, to_observer=X, chunk=0)


def test_simulate_help_lists_every_builtin_scene_knob_and_preset():
    sub = build_parser()._subparsers._group_actions[0].choices["simulate"]
    text = " ".join(sub.format_help().split())
    for name in builtin_scenes():
        assert name in text
    for name, knob in KNOBS.items():
        assert f"{name}: {knob.domain()}" in text
    assert "fast, balanced, reference" in text


# -------------------------------------------------------------- material forms


def _box():
    return load_spacecraft(trimesh.creation.box(), material="paint")


def _grey_model() -> xr.Dataset:
    return models.model_material(
        "lambert", [500.0, 600.0, 700.0], material="paint", provenance="albedo 0.5", rho=0.5
    )


def _grey_table() -> dict[str, xr.DataArray]:
    from sbrdf_xr.materials.schema import lambertian

    return {"paint": lambertian(0.5, [500.0, 600.0, 700.0], material="paint")}


@pytest.mark.parametrize("evaluation", ["table", "analytic"])
def test_a_model_material_in_python_is_a_model_file_in_toml(tmp_path, evaluation):
    """Scene(materials={"paint": model}) and a TOML scene naming the model's file give the
    same cube; a Lambertian of albedo 0.5 gives 0.5 / pi face on."""
    mesh = tmp_path / "box.stl"
    trimesh.creation.box().export(mesh)
    models.to_netcdf(_grey_model(), tmp_path / "paint.nc")
    (tmp_path / "scene.toml").write_text(
        'spacecraft = { path = "box.stl", material = "paint" }\n'
        f'evaluation = "{evaluation}"\n'
        "[materials]\n"
        'paint = "paint.nc"\n'
        "[geometry]\n"
        "to_sun = [[1.0, 0.0, 0.0]]\n"
        "to_observer = [[1.0, 0.0, 0.0]]\n"
    )
    from_toml = load_scene(tmp_path / "scene.toml")
    assert from_toml.materials == {} and list(from_toml.models) == ["paint"]  # not rendered
    in_python = Scene(
        load_spacecraft(mesh, material="paint"),
        materials={"paint": _grey_model()},
        to_sun=X,
        to_observer=X,
        evaluation=evaluation,
    )
    a, b = simulate(from_toml), simulate(in_python)
    for v in ("signal", "spacecraft_sbrdf", "area"):
        np.testing.assert_array_equal(a[v].values, b[v].values)
    np.testing.assert_allclose(a.signal.values, 0.5 / np.pi, rtol=1e-9)
    rendered = "tables" in in_python.__dict__
    assert rendered == (evaluation == "table")  # analytic evaluation renders no table


def test_analytic_evaluation_needs_no_table():
    """A material the catalog does not know, given only as a model."""
    scene = Scene(_box(), models={"paint": _grey_model()}, to_sun=X, to_observer=X)
    analytic = simulate(scene.with_options(evaluation="analytic"))
    np.testing.assert_allclose(analytic.signal.values, 0.5 / np.pi, rtol=1e-12)
    assert "tables" not in scene.__dict__
    tabulated = simulate(scene)  # a table evaluation renders the model on first use
    np.testing.assert_allclose(tabulated.signal.values, analytic.signal.values, rtol=1e-9)
    with pytest.raises(SceneError, match="no table for \\['paint'\\] \\(nor a model\\)"):
        Scene(_box(), materials={"other": _grey_model()}, to_sun=X, to_observer=X)
    with pytest.raises(SceneError, match="in both materials and models"):
        Scene(
            _box(),
            materials={"paint": _grey_model()},
            models={"paint": _grey_model()},
            to_sun=X,
            to_observer=X,
        )
