"""Tests of sbrdf_xr.engine: scene files, built-in scenes, presets."""

from __future__ import annotations

import re

import numpy as np
import pytest

from sbrdf_xr.engine import builtin_scenes, load_scene, resolve_scene
from sbrdf_xr.errors import CatalogError, SceneError

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
        ("[attitude]\nn = " + "9" * 5000 + "\n", "an integer of more than 4300 digits"),
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


# ----------------------------------------------------------------- files in scene files

# Sun and observer both along +x: only the +x face of the 1 m cube (area 1 m2) counts, at
# normal incidence, so the signal is albedo / pi [m2 sr-1] exactly (float32 tables: 1e-6).
HEAD_ON = """
[geometry]
to_sun = [[1.0, 0.0, 0.0]]
to_observer = [[1.0, 0.0, 0.0]]
"""


def _signal(scene):
    from sbrdf_xr.engine.run import simulate

    return simulate(scene)["signal"].values.ravel()


def test_mesh_and_material_files_relative_to_the_scene_file(user_files):
    (user_files / "scenes").mkdir()
    text = (
        '[spacecraft]\npath = "../files/box.stl"\nmaterial = "paint"\n'
        + HEAD_ON
        + '[materials]\npaint = "../files/grey30.nc"\n'
    )
    scene = load_scene(write(user_files / "scenes", text))
    assert scene.spacecraft.name == "box" and scene.models is None
    np.testing.assert_allclose(_signal(scene), 0.3 / np.pi, rtol=1e-6)


def test_a_model_file_is_rendered_and_kept_for_analytic_evaluation(user_files):
    text = (
        'spacecraft = { path = "files/box.stl", material = "paint" }\n'
        + 'evaluation = "analytic"\n'
        + HEAD_ON
        + '[materials]\npaint = "files/model40.nc"\n'
    )
    scene = load_scene(write(user_files, text))
    assert list(scene.models) == ["paint"] and scene.models["paint"].attrs["model"] == "lambert"
    np.testing.assert_allclose(_signal(scene), 0.4 / np.pi, rtol=1e-12)  # analytic: exact
    table = scene.with_options(evaluation="table")
    np.testing.assert_allclose(_signal(table), 0.4 / np.pi, rtol=1e-12)  # rendered float64


def test_user_catalog_names_in_a_scene_file(user_files, monkeypatch):
    monkeypatch.setenv("SBRDF_XR_CATALOG_PATH", str(user_files / "usercat"))
    # the material is not listed: it is the user catalog's entry of the same name
    scene = load_scene(write(user_files, 'spacecraft = "user-box"\n' + HEAD_ON))
    assert sorted(scene.materials) == ["user-grey-30"]
    np.testing.assert_allclose(_signal(scene), 0.3 / np.pi, rtol=1e-6)


def test_an_inline_material_map(user_files):
    text = (
        '[spacecraft]\npath = "usercat/meshes/box.ply"\n'
        'material_map = { "#808080" = "lambertian-grey-50" }\n' + HEAD_ON
    )
    scene = load_scene(write(user_files, text))
    assert scene.spacecraft.materials == ["lambertian-grey-50"]


@pytest.mark.parametrize(
    ("spacecraft", "materials", "error", "match"),
    [
        (
            'spacecraft = "files/nope.stl"',
            "",
            CatalogError,
            r"spacecraft: file .*files/nope.stl does not exist \(relative paths are taken from",
        ),
        (
            'spacecraft = "files/box.step"',
            "",
            SceneError,
            r"'files/box.step' is neither a catalog name nor a file with a known suffix",
        ),
        (
            'spacecraft = "files/box.stl"',
            "",
            SceneError,
            r"needs exactly one of material .*; write a \[spacecraft\] table: "
            r'path = "files/box.stl" and material = "..."',
        ),
        (
            'spacecraft = { material = "m" }',
            "",
            SceneError,
            r"\[spacecraft\]: key 'path' is required",
        ),
        (
            'spacecraft = { path = "files/box.stl", colour = "red" }',
            "",
            SceneError,
            r"\[spacecraft\]: unknown key 'colour'",
        ),
        (
            'spacecraft = { path = "files/box.stl", material = "paint" }',
            'paint = "files/missing.nc"',
            CatalogError,
            r"\[materials\] 'paint': material: file .*missing.nc does not exist",
        ),
        (
            'spacecraft = { path = "files/box.stl", material = "paint" }',
            'paint = "files/grey30.csv"',
            SceneError,
            r"\[materials\] 'paint': .* allowed suffixes: .nc, .nc4, .netcdf",
        ),
        (
            'spacecraft = { path = "files/box.stl", material = "paint" }',
            'paint = "canx1"',
            SceneError,
            r"\[materials\] 'paint': material: catalog entry 'canx1' is a spacecraft entry",
        ),
        (
            'spacecraft = { path = "files/box.stl", material = "paint" }',
            "paint = 3",
            SceneError,
            r"\[materials\]: 'paint' must name a catalog entry or a netCDF file",
        ),
    ],
)
def test_bad_files_in_scene_files(user_files, spacecraft, materials, error, match):
    text = spacecraft + "\n" + HEAD_ON + "[materials]\n" + materials + "\n"
    with pytest.raises(error, match=match):
        load_scene(write(user_files, text))


def test_scene_construction_reads_no_files(user_files, monkeypatch):
    """Scene(...) with every table given opens no file: the I/O is in load_scene."""
    import builtins

    from sbrdf_xr import catalog
    from sbrdf_xr.engine import Scene

    sc = catalog.load_spacecraft_spec(user_files / "files" / "box.stl", material="paint")
    table = catalog.load_material_spec(user_files / "files" / "grey30.nc")

    def no_open(*args, **kwargs):
        raise AssertionError(f"Scene(...) opened {args[:1]}")

    monkeypatch.setattr(builtins, "open", no_open)
    monkeypatch.setattr(catalog, "load", no_open)
    scene = Scene(sc, materials={"paint": table}, to_sun=[[1, 0, 0]], to_observer=[[1, 0, 0]])
    assert scene.n_geometries == 1


def test_scene_without_tables_loads_them_on_first_use(monkeypatch):
    """Scene(spacecraft) with no materials reads nothing until its tables are needed; the
    tables then come from the catalog once, and copies made by with_options share them."""
    import trimesh

    from sbrdf_xr import catalog
    from sbrdf_xr.body import spacecraft
    from sbrdf_xr.engine import Scene

    body = spacecraft.load_spacecraft(trimesh.creation.box(), material="lambertian-grey-50")
    loaded: list[str] = []
    real_load = catalog.load

    def counting_load(name, **kwargs):
        loaded.append(name)
        return real_load(name, **kwargs)

    monkeypatch.setattr(catalog, "load", counting_load)
    scene = Scene(body, to_sun=[[1, 0, 0]], to_observer=[[1, 0, 0]])
    assert loaded == [] and scene.materials is None
    assert sorted(scene.tables) == ["lambertian-grey-50"] and loaded == ["lambertian-grey-50"]
    again = scene.with_options(method="nearest")
    assert again.tables is scene.tables and loaded == ["lambertian-grey-50"]
    np.testing.assert_allclose(_signal(again), 0.5 / np.pi, rtol=1e-6)  # +x face, head-on


def test_a_float32_scene_loads_its_tables_in_float32_and_its_plan_reads_them_in_place():
    """A float32 scene holds its catalog tables once, in float32 (half the memory of
    the float64 tables), and its plan packs views of them, not copies; changing the
    dtype loads the tables again, changing another knob shares them."""
    import trimesh

    from sbrdf_xr.body import spacecraft
    from sbrdf_xr.engine import Scene

    body = spacecraft.load_spacecraft(trimesh.creation.icosphere(2), material="example-lobe")
    rng = np.random.default_rng(3)
    sun = rng.normal(size=(50, 3))
    obs = sun + 0.3 * rng.normal(size=(50, 3))
    sun, obs = (v / np.linalg.norm(v, axis=1, keepdims=True) for v in (sun, obs))
    single = Scene(body, to_sun=sun, to_observer=obs, dtype="float32")
    assert all(da.dtype == np.float32 for da in single.tables.values())
    packed = single.plan().tables.values
    assert all(v.dtype == np.float32 for v in packed)
    for v, da in zip(packed, single.tables.values(), strict=True):
        assert np.shares_memory(v, da.values)
    wide = single.with_options(dtype="float64")
    assert all(da.dtype == np.float64 for da in wide.tables.values())
    assert single.with_options(method="nearest").tables is single.tables
    # float32 tables and sums against float64: a few float32 roundings, far below 1e-5
    np.testing.assert_allclose(_signal(single), _signal(wide), rtol=1e-5, atol=0)


def test_scene_without_tables_names_a_material_the_catalog_lacks():
    import trimesh

    from sbrdf_xr.body import spacecraft
    from sbrdf_xr.engine import Scene

    body = spacecraft.load_spacecraft(trimesh.creation.box(), material="no-such-table")
    scene = Scene(body, to_sun=[[1, 0, 0]], to_observer=[[1, 0, 0]])  # reads nothing yet
    with pytest.raises(SceneError, match="no-such-table"):
        scene.plan()


# ----------------------------------------------------------------- errors that suggest


def _other_kinds() -> list[str]:
    """Catalog names that are not materials: a material error must offer none of them."""
    from sbrdf_xr import catalog

    return [n for k in ("site", "orbit", "spacecraft") for n in catalog.names(k)]


@pytest.mark.parametrize(
    ("spacecraft", "materials", "section"),
    [
        (  # the misspelt name labels facets in the map: the map is blamed, not [materials]
            '[spacecraft]\npath = "usercat/meshes/box.ply"\n'
            'material_map = { "#808080" = "aluminium-6061" }\n',
            "",
            "[spacecraft] material_map 'aluminium-6061'",
        ),
        (
            'spacecraft = { path = "files/box.stl", material = "aluminium-6061" }\n',
            "",
            "[spacecraft] material 'aluminium-6061'",
        ),
        (
            'spacecraft = { path = "files/box.stl", material = "paint" }\n',
            '[materials]\npaint = "aluminium-6061"\n',
            "[materials] 'paint'",
        ),
    ],
)
def test_a_misspelt_material_suggests_materials_and_names_its_section(
    user_files, spacecraft, materials, section
):
    with pytest.raises(CatalogError) as info:
        load_scene(write(user_files, spacecraft + HEAD_ON + materials))
    text = str(info.value)
    assert text.startswith(section + ": ")
    assert "did you mean 'aluminium-6061-t6'" in text
    assert "[materials]" not in text or section.startswith("[materials]")
    offered = text.partition("did you mean")[2]
    assert not [n for n in _other_kinds() if re.search(rf"(?<![\w-]){n}(?![\w-])", offered)]


@pytest.mark.parametrize(
    ("old", "new", "match"),
    [
        (
            "phase_angles = [10.0, 20.0]",
            "phase_angle = [10.0, 20.0]",
            r"^scene: unknown key 'phase_angle'; did you mean 'phase_angles'",
        ),
        (
            "stop = 360",
            "stpo = 360",
            r"^\[attitude\]: unknown key 'stpo'; did you mean 'stop' or 'step'\?",
        ),
        (  # nothing close: no suggestion, the keys of the table listed
            "chunk = 50",
            "colour = 50",
            r"^scene: unknown key 'colour'; allowed keys: attitude, ",
        ),
    ],
)
def test_an_unknown_key_suggests_the_keys_of_its_table(tmp_path, old, new, match):
    assert old in ROTATION
    with pytest.raises(SceneError, match=match) as info:
        load_scene(write(tmp_path, ROTATION.replace(old, new)))
    if new.startswith("stpo"):  # the [attitude] keys only, not the scene's
        assert "phase_angles" not in str(info.value)


@pytest.mark.parametrize(
    ("name", "match"),
    [
        (
            "kryptonite",
            r"'kryptonite' is not a material of the spacecraft 'canx1'; its materials: ",
        ),
        ("tjpv-cel", r"'tjpv-cel' is not a material .*; did you mean 'tjpv-cell'\?"),
    ],
)
def test_materials_keys_must_be_materials_of_the_spacecraft(tmp_path, name, match):
    text = ROTATION + f'"{name}" = "lambertian-grey-50"\n'
    with pytest.raises(SceneError, match=r"^\[materials\]: " + match):
        load_scene(write(tmp_path, text))
