"""Tests of sbrdf_xr.scene: scene files, built-in scenes, presets."""

from __future__ import annotations

import numpy as np
import pytest

from sbrdf_xr.errors import SceneError
from sbrdf_xr.scene import builtin_scenes, load_scene, resolve_scene

GREY = """
[materials]
"aluminium-6061-t6" = "lambertian-grey-50"
"tjpv-cell" = "example-lobe"
"white-paint-a276" = "lambertian-grey-50"
"""

ROTATION = (
    """
name = "toml-rotation"
spacecraft = "canx1"
phase_angles = [10.0, 20.0]
outputs = ["spacecraft_sbrdf", "signal", "brdf", "area"]
method = "nearest"
chunk = 50

[attitude]
kind = "sweep"
axis = [0, 0, -1]
start = 0
stop = 360
step = 2
initial_axis = [0, 0, 1]
initial_angle = 25
"""
    + GREY
)


def write(tmp_path, text, name="s.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_toml_scene_round_trip(tmp_path):
    scene = load_scene(write(tmp_path, ROTATION))
    assert scene.name == "toml-rotation" and scene.method == "nearest" and scene.chunk == 50
    assert scene.attitudes.shape == (180, 4) and list(scene.phase_angles) == [10.0, 20.0]
    np.testing.assert_array_equal(scene.attitude_angle, np.arange(0, 360, 2.0))
    assert "toml-rotation" in str(scene.plan())


def test_toml_explicit_geometry(tmp_path):
    text = (
        'spacecraft = "canx1"\n[geometry]\nto_sun = [[1.0, 0.0, 0.0]]\n'
        "to_observer = [[0.0, 1.0, 0.0]]\n" + GREY
    )
    scene = load_scene(write(tmp_path, text))
    assert not scene.is_grid and scene.n_geometries == 1


@pytest.mark.parametrize(
    ("text", "match"),
    [
        (ROTATION.replace('method = "nearest"', 'methdo = "nearest"'), "unknown key 'methdo'"),
        (ROTATION.replace("chunk = 50", 'chunk = "fifty"'), "key 'chunk' has type str"),
        (ROTATION.replace('kind = "sweep"', 'kind = "tumble"'), "unknown kind 'tumble'"),
        (
            ROTATION.replace(
                'outputs = ["spacecraft_sbrdf", "signal", "brdf", "area"]',
                'outputs = ["spacecraft_sbrdf", "smell"]',
            ),
            "outputs: unknown",
        ),
        (
            ROTATION.replace('spacecraft = "canx1"', 'spacecraft = "lambertian-grey-50"'),
            "not a spacecraft",
        ),
        ("this is = not toml", "invalid TOML"),
        (
            'spacecraft = "canx1"\n[geometry]\nto_sun = [[2.0, 0.0, 0.0]]\n'
            "to_observer = [[0.0, 1.0, 0.0]]\n" + GREY,
            "unit vectors",
        ),
    ],
)
def test_bad_scene_files(tmp_path, text, match):
    with pytest.raises(SceneError, match=match):
        load_scene(write(tmp_path, text))


def test_resolve_scene_names_and_files(tmp_path):
    assert set(builtin_scenes()) == {"canx1-rotation", "canx1-plusx-specular", "canx1-pass"}
    with pytest.raises(SceneError, match="unknown scene 'nope'; built-in scenes"):
        resolve_scene("nope")
    with pytest.raises(SceneError, match="does not exist"):
        resolve_scene(tmp_path / "missing.toml")
