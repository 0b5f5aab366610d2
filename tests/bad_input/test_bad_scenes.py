"""Bad scene files: every one ends in a named error that names the key (or the file), or
gives a scene whose plan stays within its limits; implausible values are refused or warned.

Hypothesis puts one bad value (zero, negative, NaN, infinite, missing, ragged, nested,
empty, huge, strings in numbers, non-UTF-8 bytes, and values wrong only for their key:
a table step of 1e-9 degree, a phase angle of 1e9 degree, a temperature of 1e9 K) into a
valid scene, into its ``[attitude]``, ``[geometry]`` and ``[spacecraft]`` tables and its
material maps.  A scene that loads must compile to a plan within the memory of a case.
"""

from __future__ import annotations

import numpy as np
import pytest
from bad_input_files import BASE, GREY, copy_of, toml_text, write_toml
from bad_input_tour import run_case, tour_settings
from hypothesis import given
from hypothesis import strategies as st

from sbrdf_xr.engine import MAX_SCENE_COUNT, load_scene
from sbrdf_xr.errors import SceneError

CATEGORY = "scene TOML"

# Bad values of every shape a TOML file can hold.
numbers = st.one_of(
    st.sampled_from([0, -1, 0.0, -0.0, 1e-300, -1e300, 1e308, 2**63 - 1, -(2**63), 10**12]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(-(2**63), 2**63 - 1),
)
scalars = st.one_of(numbers, st.text(max_size=6), st.booleans())
bad_values = st.one_of(
    scalars,
    st.lists(scalars, max_size=4),
    st.lists(st.lists(scalars, max_size=4), max_size=3),  # nested, ragged, strings in numbers
    st.sampled_from(
        [
            [],
            [[]],
            [[1, 2, 3], [4, 5]],
            [[0, 0, 1, 0], [1, 0]],
            [1, [2]],
            [float("nan")] * 3,
            [0, 0, 0],
            [[0, 0, 0]],
            [[1e308, 1e308, 1e308]],
            ["1", "2", "3"],
        ]
    ),
    st.dictionaries(st.text(max_size=4), scalars, max_size=2),
)
TOP_KEYS = [
    "name",
    "description",
    "spacecraft",
    "materials",
    "phase_angles",
    "bisector",
    "plane_normal",
    "outputs",
    "effects",
    "method",
    "dtype",
    "merge",
    "shadow_method",
    "shadow_density",
    "chunk",
    "wavelength_stride",
    "band_integration",
    "table_theta_step",
    "evaluation",
    "kernel",
    "block_bytes",
    "tilt_nodes",
    "size_limit",
    "surface_tilt",
    "bands",
    "band_extrapolate",
    "earth_direction",
    "earth_albedo",
    "earth_range",
    "earth_phase_angle",
    "temperature",
    "unknown_key",
]
#: Values wrong only for their key (inside the TOML type the key takes).
KEY_VALUES = {
    "table_theta_step": [1e-9, 1e-6, 1e-4, 0.05, 1.0, 45.0, 46.0],
    "wavelength_stride": [0, 2, 1000, 10**9],
    "chunk": [0, 1, 10**9, 10**12],
    "block_bytes": [0, 1, 2**40],
    "size_limit": [0, 1e-300, 1e300, -1.0],
    "shadow_density": [0, 64, 65, 10**9],
    "tilt_nodes": [0, 1, 32, 33],
    "phase_angles": [[-10.0], [181.0], [1e9], [0.0, 180.0], [360.0], [-1e-9], [1e-300]],
    "temperature": [1e9, 1e5, 6000.0, 300.0, 3.0, 1e-300, {"tjpv-cell": 1e9}, {"krypton": 300.0}],
    "earth_range": [6371.0, 6372.0, 4.2e4, 1e12, 1e30],
    "earth_albedo": [1e6, 1.0, 0.0, -0.1],
    "earth_phase_angle": [180.0, 181.0, -1.0, 1e9],
    "band_extrapolate": ["bogus", "zero", "constant", "", "ZERO"],
    "bands": [["V"], ["bogus"], ["V", "V"], ["U", "B", "V", "R", "I"], ["user:x"]],
    "surface_tilt": [46.0, 45.0, -1.0, {"krypton": 1.0}, {"tjpv-cell": 90.0}, {"tjpv-cell": 2.0}],
    "method": ["cubic", "CUBIC", "bogus"],
    "dtype": ["float16", "int32", "float32"],
    "outputs": [["signal"], ["bogus"], ["signal", "signal"]],
    "effects": [["sunlight"], ["bogus"], ["thermal"], ["earthshine"], ["eclipse"]],
    "spacecraft": ["canx1", "lambertian-grey-50", "mont-megantic", "nope", "../x.stl", "~/x.stl"],
}
ATTITUDE_KEYS = [
    "kind",
    "axis",
    "start",
    "stop",
    "step",
    "initial_axis",
    "initial_angle",
    "n",
    "seed",
    "sequence",
    "angles",
    "quaternions",
]
KINDS = ["sweep", "uniform", "euler", "quaternions", "spiral"]


def _wrong(key: str, value) -> bool:
    """Whether a value the TOML type allows is wrong for its key (must be refused or warned)."""

    def num(x) -> bool:
        return isinstance(x, int | float) and not isinstance(x, bool)

    if key == "phase_angles" and isinstance(value, list):
        return any(num(x) and not (0 <= x <= 180) for x in value)
    if key == "temperature":
        vals = value.values() if isinstance(value, dict) else [value]
        if isinstance(value, dict) and any(k not in BASE["materials"] for k in value):
            return True  # a material the spacecraft does not have: a typo, silently unused
        return any(num(x) and (x > 1e4 or x <= 0) for x in vals)
    if key == "surface_tilt" and isinstance(value, dict):
        return any(k not in BASE["materials"] for k in value)
    if key == "band_extrapolate" and isinstance(value, str):
        return value not in ("zero", "constant")
    if key == "earth_range" and num(value):
        return value > 1e9
    return False


@st.composite
def bad_scenes(draw) -> tuple[dict, str, bool]:
    d = copy_of(BASE)
    where = draw(st.sampled_from(["top", "key", "attitude", "geometry", "drop"]))
    wrong = False
    if where == "top":
        key = draw(st.sampled_from(TOP_KEYS))
        d[key] = draw(bad_values)
        wrong = _wrong(key, d[key])
    elif where == "key":
        key = draw(st.sampled_from(sorted(KEY_VALUES)))
        d[key] = draw(st.sampled_from(KEY_VALUES[key]))
        wrong = _wrong(key, d[key])
        if key == "effects" and d[key] == ["earthshine"]:
            d["earth_direction"] = [0.0, 0.0, 1.0]
    elif where == "attitude":
        kind = draw(st.sampled_from(KINDS))
        d["attitude"] = {"kind": kind, **({"stop": 10} if kind == "sweep" else {})}
        keys = draw(st.lists(st.sampled_from(ATTITUDE_KEYS), min_size=1, max_size=3, unique=True))
        for key in keys:
            d["attitude"][key] = draw(bad_values)
        key = "attitude"
    elif where == "geometry":
        del d["attitude"], d["phase_angles"]
        d["geometry"] = {"to_sun": [[1.0, 0.0, 0.0]], "to_observer": [[0.0, 1.0, 0.0]]}
        key = draw(st.sampled_from(["to_sun", "to_observer", "to_earth"]))
        d["geometry"][key] = draw(bad_values)
    else:  # a required or paired key missing
        key = draw(st.sampled_from(["spacecraft", "phase_angles", "attitude", "stop"]))
        if key == "stop":
            del d["attitude"]["stop"]
        else:
            del d[key]
    return d, key, wrong


def _plan_fits(scene) -> None:
    """A scene that loaded describes a non-empty result whose plan compiles."""
    assert scene.n_geometries >= 1
    assert 1 <= len(scene.outputs)
    assert scene.n_geometries <= MAX_SCENE_COUNT * MAX_SCENE_COUNT
    plan = scene.plan()
    assert plan.estimate.output_bytes >= 0


def check_scene_file(path, key: str, wrong: bool = False, category: str = CATEGORY) -> str:
    return run_case(
        category,
        lambda: load_scene(path),
        wrong=wrong,
        where=[key, str(path), "scene", "[", "size_limit"],
        check=_plan_fits,
        label=f"{key}: {path.read_bytes()[:300]!r}",
    )


@tour_settings(300)
@given(case=bad_scenes())
def test_scene_files_give_named_errors(tmp_path, case):
    d, key, wrong = case
    check_scene_file(write_toml(tmp_path / "scene.toml", d), key, wrong)


@tour_settings(40)
@given(junk=st.binary(min_size=1, max_size=40), at=st.integers(0, 200))
def test_scene_file_bytes_give_named_errors(tmp_path, junk, at):
    """Arbitrary bytes (non-UTF-8 among them) spliced into a valid scene file."""
    text = toml_text(BASE).encode()
    at = min(at, len(text))
    path = tmp_path / "scene.toml"
    path.write_bytes(text[:at] + junk + text[at:])
    check_scene_file(path, "scene")


# ------------------------------------------------------------------ [spacecraft] and maps

MAP_TABLES = [
    {"name": "a", "rgb": 5},
    {"name": "a", "rgb": [1, 2]},
    {"name": "a", "rgb": [256, 0, 0]},
    {"name": "a", "rgb": [-1, 0, 0]},
    {"name": "a", "rgb": ["a", "b", "c"]},
    {"name": "a", "rgb": [[1, 2, 3], [4]]},
    {"name": "a", "rgb": [1.5, 0, 0]},
    {"name": "a", "labels": 5},
    {"name": "a", "labels": [[]]},
    {"name": "a", "labels": [{}]},
    {"name": 5, "rgb": [1, 2, 3]},
    {"name": "", "rgb": [1, 2, 3]},
    {"rgb": [1, 2, 3]},
    {"name": "a"},
    {"name": GREY, "rgb": [128, 128, 128]},  # valid: the box is grey
    {"name": "nope-material", "rgb": [128, 128, 128]},
]


def _map_text(table) -> str:
    from bad_input_files import toml_value

    return "[[material]]\n" + "".join(f"{k} = {toml_value(v)}\n" for k, v in table.items())


@pytest.fixture(scope="module")
def grey_box(tmp_path_factory):
    import trimesh

    d = tmp_path_factory.mktemp("box")
    box = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
    box.visual.face_colors = [128, 128, 128, 255]
    box.export(d / "box.ply")
    return d / "box.ply"


@tour_settings(40)
@given(
    table=st.sampled_from(MAP_TABLES),
    form=st.sampled_from(["file", "inline", "bytes", "not-a-list", "empty"]),
    junk=st.binary(min_size=1, max_size=8),
)
def test_material_maps(tmp_path, grey_box, table, form, junk):
    map_path = tmp_path / "map.toml"
    text = _map_text(table)
    if form == "bytes":
        map_path.write_bytes(text.encode() + b"# " + junk + b"\n" + junk)
    elif form == "not-a-list":
        map_path.write_text("material = 5\n")
    elif form == "empty":
        map_path.write_text("")
    else:
        map_path.write_text(text)
    spacecraft = {"path": str(grey_box)}
    if form == "inline":
        spacecraft["material_map"] = {str(k): v for k, v in table.items()}
    else:
        spacecraft["material_map"] = str(map_path)
    d = copy_of(BASE)
    d["spacecraft"] = spacecraft
    del d["materials"]
    path = write_toml(tmp_path / "scene.toml", d)
    run_case(
        "material maps",
        lambda: load_scene(path),
        where=[str(map_path), "material_map", "[spacecraft]"],
        check=_plan_fits,
        label=f"{form}: {text!r}",
    )


SPACECRAFT_VALUES = {
    "length_unit": ["m", "mm", "Mm", "furlong", "", 5, "km"],
    "face_property": ["", "nope", 5],
    "repair": [True, 5, "yes"],
    "name": ["", "x" * 300, 5],
    "material": [GREY, "nope", "", 5, "mont-megantic"],
    "path": [
        "missing.ply",
        "../box.ply",
        "~/box.ply",
        "/dev/zero",
        "/dev/null",
        ".",
        "",
        "box",
        5,
        "secret.obj",
    ],
}


@tour_settings(40)
@given(data=st.data())
def test_spacecraft_tables(tmp_path, grey_box, secret_files, data):
    key = data.draw(st.sampled_from(sorted(SPACECRAFT_VALUES)))
    value = data.draw(st.sampled_from(SPACECRAFT_VALUES[key]))
    if value == "secret.obj":
        value = str(secret_files[".obj"])
    spacecraft = {"path": str(grey_box), "material": GREY, key: value}
    d = copy_of(BASE)
    d["spacecraft"] = spacecraft
    del d["materials"]
    path = write_toml(tmp_path / "scene.toml", d)
    run_case(
        CATEGORY,
        lambda: load_scene(path),
        wrong=(key == "length_unit" and value in ("Mm", "km")),
        where=[key, "[spacecraft]", str(grey_box), str(path)],
        check=_plan_fits,
        label=f"[spacecraft] {key} = {value!r}",
    )


# ------------------------------------------------------------------ paths in scene files


@pytest.mark.parametrize(
    "given, shown",
    [
        ("sub/../box.ply", "{d}/box.ply"),
        ("./box.ply", "{d}/box.ply"),
        ("../scenes/../box.ply", "{up}/box.ply"),
        ("~/no-such-box-here.ply", "{home}/no-such-box-here.ply"),
    ],
)
def test_scene_paths_are_shown_resolved(tmp_path, given, shown):
    """A mesh path of a scene file is taken from the scene file's directory and shown
    resolved (``..``, ``.`` and ``~`` expanded) in the message."""
    from pathlib import Path

    d = tmp_path / "scenes"
    d.mkdir()
    scene = copy_of(BASE)
    scene["spacecraft"] = {"path": given, "material": GREY}
    del scene["materials"]
    path = write_toml(d / "scene.toml", scene)
    want = shown.format(d=d, up=tmp_path, home=Path.home())
    run_case(
        CATEGORY,
        lambda: load_scene(path),
        wrong=True,
        where=[want],
        match="does not exist",
        label=f"spacecraft path {given!r}",
    )


# ------------------------------------------------------------------ exact cases


@pytest.mark.parametrize(
    "change, match",
    [
        ({"attitude": {"stop": 10, "step": 0}}, "step: must not be 0"),
        ({"attitude": {"stop": float("nan")}}, "stop: must be finite"),
        ({"attitude": {"stop": float("inf")}}, "stop: must be finite"),
        ({"attitude": {"start": 0}}, "needs 'stop'"),
        ({"attitude": {"stop": 10, "step": -1}}, "has no attitude"),
        ({"attitude": {"stop": 1e12, "step": 1e-3}}, "at most"),
        ({"attitude": {"kind": "uniform", "n": 10**15}}, "from 1 to"),
        (
            {"attitude": {"kind": "quaternions", "quaternions": [[0, 0, 0, 1], [0, 1]]}},
            r"quaternions\[1\]",
        ),
        (
            {"attitude": {"kind": "quaternions", "quaternions": [[0, 0, "0", 1]]}},
            "expected a number",
        ),
        (
            {"attitude": {"kind": "euler", "sequence": "zyx", "angles": [[1, 2, 3], [4]]}},
            r"angles\[1\]",
        ),
        ({"phase_angles": [[10.0], [20.0]]}, "expected a number"),
        ({"phase_angles": []}, "phase_angles: the list is empty"),
        ({"outputs": []}, "outputs: the list is empty"),
        ({"phase_angles": ["ten"]}, "expected a number"),
        ({"bisector": [1, 0]}, "vector of 3 numbers"),
        ({"temperature": {"tjpv-cell": "hot"}}, "expected a number"),
        ({"shadow_density": 10**9}, "shadow_density"),
        ({"table_theta_step": 1e-9}, "table_theta_step.*size_limit"),
        ({"band_extrapolate": "bogus"}, "band_extrapolate.*zero.*constant"),
        ({"temperature": 1e9}, "temperature"),
        ({"temperature": {"krypton": 300.0}}, "krypton"),
        ({"surface_tilt": {"krypton": 1.0}}, "krypton"),
        ({"phase_angles": [1e9]}, r"phase_angles.*\[0, 180\]"),
    ],
)
def test_scene_file_cases_of_the_report(tmp_path, change, match):
    d = copy_of(BASE)
    for k, v in change.items():
        if k == "attitude":
            d["attitude"] = {"kind": "sweep", **v}
        else:
            d[k] = v
    path = tmp_path / "scene.toml"
    path.write_text(toml_text(d))
    with pytest.raises(SceneError, match=match):
        load_scene(path).plan()


def test_non_utf8_and_unreadable_scene_files(tmp_path):
    path = tmp_path / "scene.toml"
    path.write_bytes(toml_text(BASE).encode().replace(b"bad-input", b"bad-\xff\xfe"))
    with pytest.raises(SceneError, match="not UTF-8"):
        load_scene(path)
    (tmp_path / "dir.toml").mkdir()
    with pytest.raises(SceneError, match=r"(?i)cannot be read.*is a directory"):
        load_scene(tmp_path / "dir.toml")
    from sbrdf_xr.engine import resolve_scene

    with pytest.raises(SceneError, match="is a directory"):
        resolve_scene(tmp_path / "dir.toml")


def test_empty_results_are_refused_through_the_python_api(tmp_path):
    """A Scene asking for no output or no phase angle cannot write an empty cube."""
    from sbrdf_xr import simulate, write
    from sbrdf_xr.errors import ValidationError

    path = tmp_path / "scene.toml"
    path.write_text(toml_text(BASE))
    scene = load_scene(path)
    with pytest.raises(ValidationError, match="no data variables"):
        write(simulate(scene.with_options(outputs=())), tmp_path / "a.nc")
    with pytest.raises(ValidationError, match="empty along phase_angle"):
        write(simulate(scene.with_options(phase_angles=np.array([]))), tmp_path / "b.nc")
    assert not list(tmp_path.glob("*.nc*"))


def test_nan_and_negative_tables_are_refused():
    from sbrdf_xr import Scene, catalog
    from sbrdf_xr.body import spacecraft

    sc = spacecraft.canx1()
    grey = catalog.load(GREY)
    for bad, match in ((grey.where(grey.theta_i != 10), "NaN"), (grey - 1.0, "negative")):
        with pytest.raises(SceneError, match=match):
            Scene(
                sc,
                materials={m: bad for m in sc.materials},
                attitudes=[[0, 0, 0, 1]],
                phase_angles=[10.0],
            )


def test_zero_area_facet_does_not_warn():
    import trimesh

    from sbrdf_xr.body.spacecraft import Spacecraft

    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    sc = Spacecraft(trimesh.Trimesh(v, np.array([[0, 1, 2], [0, 1, 1]]), process=False), ["a", "a"])
    t = sc.merged()  # RuntimeWarning is an error in the tests
    np.testing.assert_array_equal(t.area.values, [0.5, 0.0])
    np.testing.assert_array_equal(t.normal.values, [[0, 0, 1], [0, 0, 0]])
