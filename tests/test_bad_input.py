"""Bad input never ends in a raw traceback.

Hypothesis generates scene files (a valid scene with one key given a bad value: zero,
negative, NaN, infinite, missing, ragged, nested, empty, huge, strings in numbers,
non-UTF-8 bytes) and command lines (bad scheduler addresses, unwritable outputs, ``info``,
``plot`` and ``photometry`` on files that are not cubes).  Through the Python API every
input either gives a usable scene or raises a named :class:`~sbrdf_xr.errors.SbrdfError`;
through :func:`sbrdf_xr.cli.main` it ends in argparse's usage message (exit status 2) or
one line ``sbrdf-xr: error: ...`` and exit status 2.  The counts (generated, named errors,
accepted, tracebacks) are printed at the end of the module.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import sys
from collections import Counter
from pathlib import Path

import dask
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis_profiles import examples

from sbrdf_xr.cli import main
from sbrdf_xr.engine import MAX_SCENE_COUNT, Scene, load_scene
from sbrdf_xr.errors import SbrdfError, SceneError

COUNTS: Counter[str] = Counter()

#: A valid scene, cheap to load (the grey table for every material of CanX-1).
BASE = {
    "name": "bad-input",
    "spacecraft": "canx1",
    "phase_angles": [10.0, 30.0],
    "outputs": ["spacecraft_sbrdf", "signal", "brdf", "area"],
    "chunk": 4,
    "attitude": {"kind": "sweep", "axis": [0, 0, 1], "start": 0, "stop": 20, "step": 5},
    "materials": {
        m: "lambertian-grey-50" for m in ("aluminium-6061-t6", "tjpv-cell", "white-paint-a276")
    },
}


@pytest.fixture(scope="module", autouse=True)
def count_table(request):
    yield
    reporter = request.config.pluginmanager.get_plugin("terminalreporter")
    keys = ("generated", "named errors", "usage errors", "accepted", "tracebacks")
    lines = ["", "bad-input suite      " + "".join(f"{k:>14}" for k in keys)]
    for suite in sorted({k.split(":")[0] for k in COUNTS}):
        lines.append(f"{suite:<21}" + "".join(f"{COUNTS[f'{suite}:{k}']:>14}" for k in keys))
    capman = request.config.pluginmanager.getplugin("capturemanager")
    with capman.global_and_fixture_disabled() if capman else contextlib.nullcontext():
        for line in lines:
            if reporter is not None:
                reporter.write_line(line)


def toml_value(v) -> str:
    """TOML text of a Python value (inline tables for dicts)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def toml_text(d: dict) -> str:
    plain = [f"{json.dumps(k)} = {toml_value(v)}" for k, v in d.items() if not isinstance(v, dict)]
    tables = [
        f"\n[{json.dumps(k)}]\n"
        + "\n".join(f"{json.dumps(a)} = {toml_value(b)}" for a, b in v.items())
        for k, v in d.items()
        if isinstance(v, dict)
    ]
    return "\n".join(plain) + "\n" + "\n".join(tables) + "\n"


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
    "shadow_density",
    "chunk",
    "bands",
    "band_extrapolate",
    "earth_direction",
    "earth_albedo",
    "earth_range_km",
    "earth_phase_angle",
    "temperature",
    "unknown_key",
]
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


@st.composite
def bad_scenes(draw) -> dict:
    d = json.loads(json.dumps(BASE))
    where = draw(st.sampled_from(["top", "attitude", "geometry", "drop"]))
    if where == "top":
        d[draw(st.sampled_from(TOP_KEYS))] = draw(bad_values)
    elif where == "attitude":
        kind = draw(st.sampled_from(KINDS))
        d["attitude"] = {"kind": kind, **({"stop": 10} if kind == "sweep" else {})}
        for key in draw(
            st.lists(st.sampled_from(ATTITUDE_KEYS), min_size=1, max_size=3, unique=True)
        ):
            d["attitude"][key] = draw(bad_values)
    elif where == "geometry":
        del d["attitude"], d["phase_angles"]
        d["geometry"] = {"to_sun": [[1.0, 0.0, 0.0]], "to_observer": [[0.0, 1.0, 0.0]]}
        d["geometry"][draw(st.sampled_from(["to_sun", "to_observer", "to_earth"]))] = draw(
            bad_values
        )
    else:  # a required or paired key missing
        key = draw(st.sampled_from(["spacecraft", "phase_angles", "attitude", "stop"]))
        if key == "stop":
            del d["attitude"]["stop"]
        else:
            del d[key]
    return d


def _accept(scene: Scene) -> None:
    """A scene that parsed must describe a non-empty result."""
    assert scene.n_geometries >= 1
    assert 1 <= len(scene.outputs)
    assert scene.n_geometries <= MAX_SCENE_COUNT * MAX_SCENE_COUNT


def check_scene_file(path: Path, suite: str) -> None:
    COUNTS[f"{suite}:generated"] += 1
    try:
        scene = load_scene(path)
    except SbrdfError:
        COUNTS[f"{suite}:named errors"] += 1
        return
    except BaseException:
        COUNTS[f"{suite}:tracebacks"] += 1
        raise
    _accept(scene)
    COUNTS[f"{suite}:accepted"] += 1


@settings(
    max_examples=examples(300),
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(d=bad_scenes())
def test_scene_files_give_named_errors(tmp_path, d):
    path = tmp_path / "scene.toml"
    try:
        path.write_text(toml_text(d), encoding="utf-8", errors="surrogatepass")
    except UnicodeEncodeError:  # a lone surrogate: not writable as UTF-8, write its bytes
        path.write_bytes(toml_text(d).encode("utf-8", "surrogatepass"))
    check_scene_file(path, "scene TOML")


@settings(
    max_examples=examples(40),
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(junk=st.binary(min_size=1, max_size=40), at=st.integers(0, 200))
def test_scene_file_bytes_give_named_errors(tmp_path, junk, at):
    """Arbitrary bytes (non-UTF-8 among them) spliced into a valid scene file."""
    text = toml_text(BASE).encode()
    at = min(at, len(text))
    path = tmp_path / "scene.toml"
    path.write_bytes(text[:at] + junk + text[at:])
    check_scene_file(path, "scene bytes")


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
    ],
)
def test_scene_file_cases_of_the_report(tmp_path, change, match):
    d = json.loads(json.dumps(BASE))
    for k, v in change.items():
        if k == "attitude":
            d["attitude"] = {"kind": "sweep", **v}
        else:
            d[k] = v
    path = tmp_path / "scene.toml"
    path.write_text(toml_text(d))
    with pytest.raises(SceneError, match=match):
        load_scene(path)


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
    from sbrdf_xr import catalog
    from sbrdf_xr.body import spacecraft

    sc = spacecraft.canx1()
    grey = catalog.load("lambertian-grey-50")
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


# ------------------------------------------------------------------ command lines


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Files that are not cubes, and places that cannot be written."""
    from sbrdf_xr import testing
    from sbrdf_xr.materials import tables as material

    d = tmp_path_factory.mktemp("cli")
    (d / "text.nc").write_text("hello, I am not netCDF\n")
    (d / "empty.nc").write_bytes(b"")
    (d / "binary.nc").write_bytes(bytes(range(256)))
    (d / "hdf5.nc").write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 100)
    material.to_netcdf(testing.make_material(), d / "material.nc")
    (d / "adir.nc").mkdir()
    (d / "file.txt").write_text("x")
    (d / "scene.toml").write_text(toml_text(BASE))
    return d


addresses = st.one_of(
    st.text(max_size=20),
    st.sampled_from(
        [
            "bogus",
            "tcp://",
            "tcp://127.0.0.1",
            "tcp://127.0.0.1:0",
            "tcp://127.0.0.1:99999",
            "tcp://127.0.0.1:-5",
            "http://127.0.0.1:8786",
            "tcp://[::1:8786",
            ":8786",
            "tcp://127.0.0.1:8786/path",
            "tcp://127.0.0.1: 8786",
            "tcp://bad host:1",
            "tcp://127.0.0.1:1",
            "inproc://x",
        ]
    ),
)


def run_cli(argv: list[str], suite: str, capsys) -> None:
    """main(argv) must end in a usage message (SystemExit 2) or one error line and status 2."""
    COUNTS[f"{suite}:generated"] += 1
    try:
        status = main(argv)
    except SystemExit as exc:
        assert exc.code == 2, (argv, exc.code)
        assert "usage:" in capsys.readouterr().err
        COUNTS[f"{suite}:usage errors"] += 1
        return
    except BaseException:
        COUNTS[f"{suite}:tracebacks"] += 1
        raise
    captured = capsys.readouterr()
    if status == 0:
        COUNTS[f"{suite}:accepted"] += 1
        return
    lines = [ln for ln in captured.err.splitlines() if ln.strip()]
    assert status == 2, (argv, status, captured.err)
    assert len(lines) == 1 and lines[0].startswith("sbrdf-xr: error: "), (argv, captured.err)
    assert "Traceback" not in captured.err
    COUNTS[f"{suite}:named errors"] += 1


@settings(
    max_examples=examples(40),
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(address=addresses)
def test_bad_scheduler_addresses(files, address, capsys):
    out = files / "never.nc"
    with dask.config.set({"distributed.comm.timeouts.connect": "2s"}):
        run_cli(
            ["simulate", str(files / "scene.toml"), "-o", str(out), "-q", "--scheduler", address],
            "CLI scheduler",
            capsys,
        )
    assert not out.exists()


OUTPUTS = [
    "/proc/sbrdf/x.nc",
    "/proc/x.nc",
    "/dev/null",
    "{d}/adir.nc",
    "{d}/file.txt/x.nc",
    "{d}/",
    "/sys/x.nc",
    "",
]
NON_CUBES = [
    "text.nc",
    "empty.nc",
    "binary.nc",
    "hdf5.nc",
    "material.nc",
    "adir.nc",
    "missing.nc",
    "file.txt",
    "scene.toml",
]


@settings(
    max_examples=examples(60),
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(
    argv=st.one_of(
        st.tuples(
            st.just("simulate"), st.just("{d}/scene.toml"), st.just("-o"), st.sampled_from(OUTPUTS)
        ),
        st.tuples(st.just("info"), st.sampled_from(NON_CUBES)),
        st.tuples(
            st.just("plot"), st.sampled_from(NON_CUBES), st.just("-o"), st.just("{d}/fig.png")
        ),
        st.tuples(st.just("plot"), st.just("{d}/text.nc"), st.just("-o"), st.sampled_from(OUTPUTS)),
        st.tuples(
            st.just("photometry"),
            st.sampled_from(NON_CUBES),
            st.just("--bands"),
            st.just("V"),
            st.just("--range-km"),
            st.sampled_from(["36000", "nan", "-1", "x"]),
        ),
        st.tuples(st.just("catalog"), st.just("show"), st.text(max_size=12)),
        st.lists(
            st.sampled_from(
                [
                    "simulate",
                    "info",
                    "plot",
                    "-o",
                    "--resume",
                    "--overwrite",
                    "x.nc",
                    "--plan",
                    "--preset",
                    "warp",
                    "catalog",
                    "show",
                    "--bands",
                ]
            ),
            max_size=5,
        ),
    )
)
def test_bad_command_lines(files, argv, capsys):
    argv = [str(files / a) if a in NON_CUBES else a.replace("{d}", str(files)) for a in argv]
    cwd = os.getcwd()
    os.chdir(files)  # relative outputs land in the scratch directory
    try:
        run_cli(list(argv), "CLI arguments", capsys)
    finally:
        os.chdir(cwd)


def test_info_escapes_control_characters(tmp_path, capsys):
    import xarray as xr

    ds = xr.Dataset(
        {"v": ("x", [1.0], {"units": "1", "long_name": "bell\x07 and \x1b[2J clear"})},
        attrs={"title": "\x1b]0;pwned\x07\x1b[31mred\nfake line"},
    )
    ds.to_netcdf(tmp_path / "evil.nc")
    assert main(["info", str(tmp_path / "evil.nc")]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out and "\x07" not in out
    assert "\\x1b[31mred\\nfake line" in out and "\\x07" in out


def test_catalog_show_escapes_control_characters(tmp_path, capsys, monkeypatch):
    from sbrdf_xr import catalog

    e = catalog.entry("lambertian-grey-50")
    evil = type(e)(**{**e.__dict__, "description": "\x1b[31mred\x1b[0m", "provenance": "ok\x9b2J"})
    monkeypatch.setattr(catalog, "entry", lambda name: evil)
    assert main(["catalog", "show", "lambertian-grey-50"]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out and "\x9b" not in out and "\\x1b[31mred" in out


def test_unreachable_scheduler_is_one_line(files, capsys):
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        assert (
            main(
                [
                    "simulate",
                    str(files / "scene.toml"),
                    "-o",
                    str(files / "n.nc"),
                    "-q",
                    "--scheduler",
                    "tcp://127.0.0.1:9",
                ]
            )
            == 2
        )
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cannot connect to the Dask scheduler at tcp://127.0.0.1:9" in err[0]


def test_messages_name_command_line_options(files, capsys):
    out = files / "twice.nc"
    argv = ["simulate", str(files / "scene.toml"), "-o", str(out), "-q"]
    assert main(argv) == 0
    capsys.readouterr()
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "--overwrite" in err and "overwrite=True" not in err
    assert main([*argv, "--resume"]) == 0
    assert "already complete" in capsys.readouterr().out
    out.unlink()
    assert sys.platform == "win32" or not (files / "twice.nc.lock").exists()
