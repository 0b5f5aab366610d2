"""Every flag of every command of ``sbrdf-xr`` given bad values: each case ends in a named
error (one line ``sbrdf-xr: error: ...``, exit status 2, naming the flag or the file) or
in argparse's usage message; none in a traceback, a hang or a result.

The commands: ``simulate``, ``observe``, ``photometry``, ``invert unmix``, ``invert spin``,
``plot``, ``bench`` (argument errors only: a guard stops any benchmark from running),
``knobs``, ``catalog`` and ``info``.  The values: not numbers, negative or zero where a
size or a distance is asked, NaN, infinities, huge sizes, unknown names (bands, materials,
scenes, sites, attitude laws), missing files, a directory where a file is expected,
files of another kind, wrong units and combinations of flags that exclude each other;
and the spectrum files of ``invert unmix`` (empty, not numbers, missing columns,
wavelengths in micrometres).  Commands that would simulate are given ``--plan`` (or a
tiny cube), so that a value accepted by mistake costs little.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import trimesh
from bad_input_tour import run_cli, tour_settings
from hypothesis import given
from hypothesis import strategies as st

from sbrdf_xr import Scene, load_spacecraft, simulate, write
from sbrdf_xr.materials.schema import lambertian

CATEGORY = "CLI flags"
#: Seconds before a case counts as a hang (every case is refused before any real work).
TIMEOUT = 60.0

#: Values that are no numbers, or no finite ones, for any numeric flag.
NOT_FINITE = ["abc", "", "nan", "NaN", "inf", "-inf", "1,5", "0x10", "1e999"]
#: Values that are numbers but no sizes, distances or periods.
NOT_POSITIVE = ["0", "-1", "-1e-300", "-1e308"]


@pytest.fixture(scope="module")
def files(tmp_path_factory, secret_files):
    """A tiny per-material cube (a grey box at three geometries), its spectrum, band
    magnitudes and a light curve, a mesh, a directory and a path that does not exist."""
    d = tmp_path_factory.mktemp("cli_flags")
    mesh = trimesh.creation.box()
    mesh.export(d / "box.stl")
    box = load_spacecraft(mesh, material="grey")
    wl = np.linspace(400.0, 1000.0, 13)
    x = [[0.6, 0.0, 0.8], [0.8, 0.0, 0.6], [0.0, 0.6, 0.8]]
    scene = Scene(
        box,
        {"grey": lambertian(0.5, wl, material="grey")},
        to_sun=x,
        to_observer=x[::-1],
        outputs=("signal", "per_material"),
        kernel="numpy",
    )
    cube = simulate(scene)
    write(cube, d / "cube.nc")
    y = cube.signal_material.isel(geometry=0).sum("material").values
    pd.DataFrame({"wavelength": wl, "signal": y, "uncertainty": 0.01 * y}).to_csv(
        d / "spec.csv", index=False
    )
    t = np.repeat(np.arange(0.0, 20.0, 2.0), 3)
    pd.DataFrame(
        {
            "time": t,
            "band": np.tile(["V", "R", "I"], t.size // 3),
            "magnitude": 10.0 + 0.1 * np.sin(t),
            "uncertainty": 0.01,
        }
    ).to_csv(d / "lc.csv", index=False)
    (d / "a_dir").mkdir()
    return {
        "dir": d,
        "cube": str(d / "cube.nc"),
        "spec": str(d / "spec.csv"),
        "lc": str(d / "lc.csv"),
        "mesh": str(d / "box.stl"),
        "a_dir": str(d / "a_dir"),
        "missing": str(d / "no_such_file.nc"),
        "secret_csv": str(secret_files[".csv"]),
        "secret_nc": str(secret_files[".nc"]),
        "secret_toml": str(secret_files[".toml"]),
        "secret_tle": str(secret_files[".tle"]),
        "secret_stl": str(secret_files[".stl"]),
    }


@pytest.fixture(autouse=True)
def _no_benchmark(monkeypatch):
    """A guard: a ``bench`` case that reaches the benchmarks fails at once instead."""
    import sbrdf_xr.bench
    import sbrdf_xr.bench.engine

    def refuse(*args, **kwargs):
        raise AssertionError("a bench case reached the benchmarks")

    monkeypatch.setattr(sbrdf_xr.bench, "run", refuse)
    monkeypatch.setattr(sbrdf_xr.bench.engine, "engine_rows", refuse)


def _sub(f: dict, text: str) -> str:
    """``{name}`` of the fixture's files in an argument."""
    return text.format(**f) if "{" in text else text


# Each command: its base arguments (a valid run, made cheap) as (flag, values) pairs, and
# the bad cases, each a list of (flag, values or None to drop the flag) replacing the base.
OUT = "{dir}/out.nc"
BASES: dict[str, list[tuple[str, list[str]]]] = {
    "simulate": [
        ("", ["simulate", "canx1-rotation"]),
        ("-o", [OUT]),
        ("--plan", []),
    ],
    "observe": [
        ("", ["observe"]),
        ("--elements", ["canx1-example"]),
        ("--site", ["mont-megantic"]),
        ("--start", ["2024-03-17T01:22:00"]),
        ("--duration", ["10"]),
        ("-o", [OUT]),
        ("--plan", []),
    ],
    "photometry": [
        ("", ["photometry", "{cube}"]),
        ("--range-km", ["1000"]),
        ("-q", []),
    ],
    "unmix": [
        ("", ["invert", "unmix", "{spec}"]),
        ("--cube", ["{cube}"]),
        ("--isel", ["geometry=0"]),
        ("--select", ["none"]),
    ],
    "spin": [
        ("", ["invert", "spin", "{lc}"]),
        ("--to-sun", ["1", "0", "0"]),
        ("--to-observer", ["0", "1", "0"]),
        ("--periods", ["16", "24", "3"]),
        ("--n-axes", ["4"]),
        ("--n-phases", ["4"]),
    ],
    "plot": [("", ["plot", "{cube}"]), ("-o", ["{dir}/fig.png"])],
    "bench": [("", ["bench", "--quick"])],
    "knobs": [("", ["knobs"])],
    "catalog": [("", ["catalog"])],
    "info": [("", ["info"])],
}


def _argv(f: dict, command: str, changes: list[tuple[str, list[str] | None]]) -> list[str]:
    """The base arguments of ``command`` with ``changes`` applied (a flag given again
    replaces the base's; ``None`` drops it; the ``""`` flag is the positional head)."""
    items = dict(BASES[command])
    for flag, values in changes:
        if values is None:
            items.pop(flag, None)
        else:
            items[flag] = values
    argv: list[str] = []
    for flag, values in items.items():
        argv += ([flag] if flag else []) + [_sub(f, v) for v in values]
    return argv


def _cases() -> list[tuple[str, list[tuple[str, list[str] | None]]]]:
    out: list[tuple[str, list[tuple[str, list[str] | None]]]] = []

    def add(command: str, *changes: tuple[str, list[str] | None]) -> None:
        out.append((command, list(changes)))

    # simulate
    for scene in ["bogus-scene", "{missing}", "{a_dir}", "{secret_toml}", "{secret_csv}", ""]:
        add("simulate", ("", ["simulate", scene]))
    # (a cube's name may have any suffix but .zarr, and missing parents are made)
    for o in ["{a_dir}", "{secret_csv}", "", "{cube}"]:
        add("simulate", ("-o", [o]), ("--plan", None))
    for preset in ["bogus", "", "FAST"]:
        add("simulate", ("--preset", [preset]))
    for s in [
        "bogus=1",
        "noequals",
        "method=bogus",
        "dtype=float8",
        "block_bytes=-1",
        "block_bytes=nan",
        "block_bytes=abc",
        "block_bytes=1e30",
        "=1",
    ]:
        add("simulate", ("--set", [s]))
    for level in ["10", "-1", "abc", "nan"]:
        add("simulate", ("--complevel", [level]))
    for sc in ["bogus-craft", "{missing}", "{a_dir}", "{secret_stl}", "{secret_csv}"]:
        add("simulate", ("--spacecraft", [sc]))
    add("simulate", ("--mesh-material", ["white-paint-a276"]))
    add("simulate", ("--spacecraft", ["{mesh}"]), ("--mesh-material", ["bogus-material"]))
    add("simulate", ("--spacecraft", ["{mesh}"]), ("--material-map", ["{missing}"]))
    add("simulate", ("--spacecraft", ["{mesh}"]), ("--material-map", ["{secret_toml}"]))
    add(
        "simulate",
        ("--spacecraft", ["{mesh}"]),
        ("--mesh-material", ["white-paint-a276"]),
        ("--material-map", ["{secret_toml}"]),
    )
    for unit in ["furlong", "Mm", "", "nan"]:
        add(
            "simulate",
            ("--spacecraft", ["{mesh}"]),
            ("--mesh-material", ["white-paint-a276"]),
            ("--length-unit", [unit]),
        )
    add("simulate", ("--length-unit", ["mm"]))
    for m in [
        "bogus=white-paint-a276",
        "white-paint-a276",
        "white-paint-a276=bogus-table",
        "white-paint-a276={missing}",
        "white-paint-a276={a_dir}",
        "white-paint-a276={secret_nc}",
        "=white-paint-a276",
    ]:
        add("simulate", ("--material", [m]))
    for plot in ["{a_dir}", "{dir}/fig.xyz"]:
        add("simulate", ("--plot", [plot]), ("--plan", None), ("-o", ["{a_dir}"]))
    add("simulate", ("--bogus-flag", []))

    # observe
    for el in ["bogus-orbit", "{missing}", "{a_dir}", "{secret_tle}", "{secret_csv}", ""]:
        add("observe", ("--elements", [el]))
    add("observe", ("--satellite", ["99999"]))
    for site in ["bogus-site", "", "Mont-Megantic "]:
        add("observe", ("--site", [site]))
    for lat, lon in [("91", "0"), ("nan", "0"), ("45", "inf"), ("45", "1e9"), ("-91", "0")]:
        add("observe", ("--site", None), ("--lat", [lat]), ("--lon", [lon]))
    add("observe", ("--lat", ["45"]), ("--lon", ["0"]))  # with --site: two sites
    add("observe", ("--site", None))  # no site
    add("observe", ("--site", None), ("--lat", ["45"]))  # no longitude
    for h in ["1e9", "nan", "-1e7", "inf"]:
        add("observe", ("--site", None), ("--lat", ["45"]), ("--lon", ["0"]), ("--height", [h]))
    for e in ["100", "-100", "nan"]:
        add("observe", ("--min-elevation", [e]))
    for start in ["99999-01-01T00:00:00", "2024-13-01T00:00:00", "yesterday", "", "1900-01-01"]:
        add("observe", ("--start", [start]))
    for stop in ["2024-03-17T01:21:00", "abc", "2124-03-17T01:23:00"]:
        add("observe", ("--duration", None), ("--stop", [stop]))
    add("observe", ("--stop", ["2024-03-17T01:23:00"]))  # and --duration
    add("observe", ("--duration", None))
    for dur in [*NOT_POSITIVE, "nan", "inf", "1e12"]:
        add("observe", ("--duration", [dur]))
    for step in [*NOT_POSITIVE, "nan", "inf", "1e-9", "1e9"]:
        add("observe", ("--step", [step]))
    add("observe", ("--attitude", ["bogus"]))
    add("observe", ("--attitude", ["inertial"]))
    for q in [["0", "0", "0", "0"], ["nan", "0", "0", "1"], ["inf", "0", "0", "1"]]:
        add("observe", ("--attitude", ["inertial"]), ("--quaternion", q))
    for yaw in ["nan", "inf"]:
        add("observe", ("--yaw", [yaw]))
    for axis in ["bogus", "0,0,0", "nan,0,1", "+w", ""]:
        add("observe", ("--nadir-axis", [axis]))
    add("observe", ("--nadir-axis", ["+z"]), ("--velocity-axis", ["+z"]))
    for flag, value in [
        ("--sun-axis", "bogus"),
        ("--secondary-axis", "0,0,0"),
        ("--secondary-target", "bogus"),
    ]:
        add("observe", ("--attitude", ["sun-pointing"]), (flag, [value]))
    add("observe", ("--attitude", ["spin"]))
    for period in [*NOT_POSITIVE, "nan", "inf", "1e-12"]:
        add("observe", ("--attitude", ["spin"]), ("--period", [period]))
    for rate in ["nan", "inf", "0", "1e12"]:
        add("observe", ("--attitude", ["spin"]), ("--rate", [rate]))
    add("observe", ("--attitude", ["spin"]), ("--period", ["10"]), ("--rate", ["3"]))
    add("observe", ("--attitude", ["spin"]), ("--period", ["10"]), ("--phase", ["nan"]))
    add("observe", ("--attitude", ["spin"]), ("--period", ["10"]), ("--spin-axis", ["0,0,0"]))
    for initial in ["bogus", "0,0,0,0", "1,2,3"]:
        add("observe", ("--attitude", ["spin"]), ("--period", ["10"]), ("--initial", [initial]))
    add("observe", ("--attitude", ["spin"]), ("--period", ["10"]), ("--epoch", ["yesterday"]))
    add("observe", ("--attitude", ["tumble"]))
    add("observe", ("--attitude", ["tumble"]), ("--omega", ["1", "2", "3"]))
    for omega in [["nan", "0", "0"], ["inf", "0", "0"], ["1e12", "0", "0"]]:
        add(
            "observe",
            ("--attitude", ["tumble"]),
            ("--omega", omega),
            ("--inertia", ["1", "2", "3"]),
        )
    for inertia in [["0", "0", "0"], ["-1", "2", "3"], ["nan", "1", "1"], ["1", "1", "5"]]:
        add(
            "observe",
            ("--attitude", ["tumble"]),
            ("--omega", ["1", "2", "3"]),
            ("--inertia", inertia),
        )
    for density in ["0", "-1", "nan", "inf"]:
        add(
            "observe",
            ("--attitude", ["tumble"]),
            ("--omega", ["1", "2", "3"]),
            ("--density", [density]),
        )
    add("observe", ("--attitude", ["series"]))
    for series in ["{missing}", "{a_dir}", "{secret_csv}"]:
        add("observe", ("--attitude", ["series"]), ("--series", [series]))
    for sc in ["bogus-craft", "{missing}", "{a_dir}"]:
        add("observe", ("--spacecraft", [sc]))
    add("observe", ("--mesh-material", ["white-paint-a276"]))
    add("observe", ("--spacecraft", ["{mesh}"]), ("--length-unit", ["furlong"]))
    add("observe", ("--material", ["bogus=white-paint-a276"]))
    for bands in [["bogus"], ["V", "V"], [""], ["none", "V"]]:
        add("observe", ("--bands", bands))
    add("observe", ("--earth", ["flat"]))
    for o in ["{a_dir}", "{secret_csv}", "{cube}"]:
        add("observe", ("-o", [o]), ("--plan", None))

    # photometry
    for cube in ["{missing}", "{a_dir}", "{secret_nc}", "{secret_csv}", "{spec}", "{lc}"]:
        add("photometry", ("", ["photometry", cube]))
    for bands in [["bogus"], [""], ["V", "bogus"], ["V", "V"]]:
        add("photometry", ("--bands", bands))
    for r in [*NOT_FINITE, *NOT_POSITIVE]:
        add("photometry", ("--range-km", [r]))
    add("photometry", ("--range-km", None))
    for s in [*NOT_FINITE, *NOT_POSITIVE]:
        add("photometry", ("--sun-distance-au", [s]))
    for ext in ["V=abc", "V", "=0.2", "V=nan", "bogus=0.2", "V=-1"]:
        add("photometry", ("--extinction", [ext]))
    for colours in ["V", "V-X", "V-R,", "-", "V-R-I", "bogus-V"]:
        add("photometry", ("--colours", [colours]))
    for flag, value in [
        ("--system", "bogus"),
        ("--solar", "bogus"),
        ("--weighting", "bogus"),
        ("--quadrature", "bogus"),
        ("--extrapolate", "bogus"),
    ]:
        add("photometry", (flag, [value]))
    for o in ["{a_dir}", "{secret_csv}", "{cube}", ""]:
        add("photometry", ("-o", [o]))
    for o in ["{a_dir}", "{dir}/no/such/dir/p.nc", "{secret_csv}", "{dir}/p.png", ""]:
        add("photometry", ("--csv", [o]))

    # invert unmix
    for measured in ["{missing}", "{a_dir}", "{secret_csv}", "{secret_nc}", "{cube}"]:
        add("unmix", ("", ["invert", "unmix", measured]))
    for cube in ["{missing}", "{a_dir}", "{secret_nc}", "{spec}"]:
        add("unmix", ("--cube", [cube]))
    add("unmix", ("--cube", None))
    for isel in [
        "attitude=999",
        "geometry=999",
        "geometry=-999",
        "geometry",
        "geometry=one",
        "geometry=nan",
        "geometry=1e3",
        "=0",
        "",
    ]:
        add("unmix", ("--isel", [isel]))
    add("unmix", ("--isel", ["geometry=0", "--isel", "geometry=1"]))
    for r in [*NOT_FINITE, *NOT_POSITIVE]:
        add("unmix", ("", ["invert", "unmix", "{dir}/mags.csv"]), ("--range-km", [r]))
    add("unmix", ("", ["invert", "unmix", "{dir}/mags.csv"]), ("--range-km", None))
    add("unmix", ("--select", ["bogus"]))
    add("unmix", ("--criterion", ["bogus"]))
    for o in ["{a_dir}", "{secret_csv}", "{cube}"]:
        add("unmix", ("-o", [o]))

    # invert spin
    for measured in ["{missing}", "{a_dir}", "{secret_csv}", "{spec}", "{cube}"]:
        add("spin", ("", ["invert", "spin", measured]))
    for periods in [
        ["10", "20", "1e12"],
        ["10", "20", "0"],
        ["10", "20", "-3"],
        ["10", "20", "2.5"],
        ["10", "20", "nan"],
        ["10", "20", "inf"],
        ["20", "10", "3"],
        ["0", "10", "3"],
        ["-1", "10", "3"],
        ["nan", "10", "3"],
        ["10", "inf", "3"],
        ["1e-300", "1e-299", "3"],
        ["abc", "10", "3"],
        ["10", "20"],
    ]:
        add("spin", ("--periods", periods))
    add("spin", ("--periods", None))
    for n in ["0", "-1", "1e9", "abc", "2.5", "1000000000000"]:
        add("spin", ("--n-axes", [n]))
        add("spin", ("--n-phases", [n]))
    for axis in [["0", "0", "0"], ["nan", "0", "1"], ["inf", "0", "1"], ["1e-320", "0", "0"]]:
        add("spin", ("--axis-body", axis))
    for v in [["0", "0", "0"], ["nan", "0", "1"], ["inf", "0", "0"]]:
        add("spin", ("--to-sun", v))
        add("spin", ("--to-observer", v))
    add("spin", ("--to-observer", None))
    add("spin", ("--to-sun", None), ("--to-observer", None))
    add("spin", ("--cube", ["{cube}"]))  # and --to-sun
    add("spin", ("--scene", ["canx1-pass"]))  # and --to-sun
    for cube in ["{missing}", "{a_dir}", "{secret_nc}", "{cube}"]:
        add("spin", ("--to-sun", None), ("--to-observer", None), ("--cube", [cube]))
    for scene in ["bogus-scene", "canx1-rotation", "{missing}", "{secret_toml}"]:
        add("spin", ("--to-sun", None), ("--to-observer", None), ("--scene", [scene]))
    for sl in ["0", "-1", "nan", "inf", "abc"]:
        add("spin", ("--size-limit", [sl]))
    for sc in ["bogus-craft", "{missing}", "{a_dir}", "{secret_stl}"]:
        add("spin", ("--spacecraft", [sc]))
    add("spin", ("--mesh-material", ["white-paint-a276"]))
    add("spin", ("--spacecraft", ["{mesh}"]), ("--mesh-material", ["bogus-material"]))
    add(
        "spin",
        ("--spacecraft", ["{mesh}"]),
        ("--mesh-material", ["white-paint-a276"]),
        ("--length-unit", ["furlong"]),
    )
    for flag in ("--method", "--offset"):
        add("spin", (flag, ["bogus"]))
    for o in ["{a_dir}", "{secret_csv}"]:
        add("spin", ("-o", [o]))

    # plot
    for cube in ["{missing}", "{a_dir}", "{secret_nc}", "{secret_csv}", "{spec}"]:
        add("plot", ("", ["plot", cube]))
    for o in ["{a_dir}", "{dir}/fig.xyz", "{dir}/fig.nc", "{secret_csv}", "{cube}", ""]:
        add("plot", ("-o", [o]))
    add("plot", ("-o", None))

    # bench: argument errors only
    for extra in [
        ["--repeat", "abc"],
        ["--repeat", "0"],
        ["--repeat", "-3"],
        ["--repeat", "2.5"],
        ["--repeat"],
        ["--bogus"],
        ["-o", "{a_dir}"],
        ["-o", "{cube}"],
        ["--csv", "{a_dir}"],
        ["--csv", "{secret_csv}"],
        ["--plot", "{a_dir}"],
        ["--plot", "{dir}/b.xyz"],
        ["extra"],
    ]:
        add("bench", ("", ["bench", "--quick", *extra]))

    # knobs, catalog, info
    add("knobs", ("", ["knobs", "extra"]))
    add("knobs", ("", ["knobs", "--bogus"]))
    for extra in [
        [],
        ["bogus"],
        ["list", "--kind", "bogus"],
        ["list", "extra"],
        ["show"],
        ["show", "bogus-entry"],
        ["show", ""],
        ["show", "../../etc/passwd"],
        ["show", "{secret_nc}"],
        ["show", "{a_dir}"],
        ["show", "canx1", "extra"],
    ]:
        add("catalog", ("", ["catalog", *extra]))
    for extra in [["{missing}"], ["{a_dir}"], ["{secret_nc}"], ["{secret_csv}"], ["a", "b"]]:
        add("info", ("", ["info", *extra]))
    return out


CASES = _cases()


def _where(argv: list[str], changes) -> list[str]:
    """What a message may name: the flags changed and their values (or the command's
    positional arguments, when the case changes those)."""
    where: list[str] = []
    for flag, values in changes:
        if flag:  # (a flag dropped may be named as missing)
            where.append(flag)
            where.append(flag.lstrip("-").replace("-", "_"))
        for v in values or []:
            if len(v) > 2:
                where.append(v)
    if any(not flag for flag, _ in changes) or any(v is None for _, v in changes):
        where += [a for a in argv if len(a) > 2]
    return where


@pytest.fixture(scope="module")
def mags(files):
    """Band magnitudes (a light-curve file of one time) for ``invert unmix``."""
    path = files["dir"] / "mags.csv"
    pd.DataFrame(
        {"time": [0.0] * 3, "band": ["V", "R", "I"], "magnitude": 12.0, "uncertainty": 0.01}
    ).to_csv(path, index=False)
    return path


@pytest.mark.parametrize(
    ("command", "changes"),
    CASES,
    ids=[f"{i}-{c}" for i, (c, _) in enumerate(CASES)],
)
def test_bad_flag(files, mags, capsys, command, changes):
    argv = _argv(files, command, changes)
    where = [_sub(files, w) for w in _where(argv, changes)]
    run_cli(CATEGORY, argv, capsys, wrong=True, where=where, timeout=TIMEOUT)


#: The spectrum files of ``invert unmix`` (the cube covers 400-1000 nm).
SPECTRA = {
    "empty": "",
    "blank-lines": "\n\n\n",
    "header-only": "wavelength,signal,uncertainty\n",
    "not-numbers": "wavelength,signal,uncertainty\n500,abc,0.1\n600,0.1,0.01\n",
    "wavelength-text": "wavelength,signal,uncertainty\nfive hundred,0.1,0.01\n600,0.1,0.01\n",
    "missing-uncertainty": "wavelength,signal\n500,0.1\n600,0.1\n",
    "missing-signal": "wavelength,uncertainty\n500,0.1\n600,0.1\n",
    "no-header": "500,0.1,0.01\n600,0.1,0.01\n700,0.1,0.01\n",
    "micrometres": "wavelength,signal,uncertainty\n0.5,0.1,0.01\n0.6,0.1,0.01\n0.7,0.1,0.01\n",
    "metres": "wavelength,signal,uncertainty\n5e-7,0.1,0.01\n6e-7,0.1,0.01\n7e-7,0.1,0.01\n",
    "outside": "wavelength,signal,uncertainty\n2000,0.1,0.01\n2100,0.1,0.01\n2200,0.1,0.01\n",
    "negative-wavelength": "wavelength,signal,uncertainty\n-500,0.1,0.01\n600,0.1,0.01\n",
    "nan": "wavelength,signal,uncertainty\n500,nan,0.01\n600,0.1,0.01\n",
    "inf": "wavelength,signal,uncertainty\n500,inf,0.01\n600,0.1,0.01\n",
    "zero-uncertainty": "wavelength,signal,uncertainty\n500,0.1,0\n600,0.1,0.01\n",
    "repeated": "wavelength,signal,uncertainty\n500,0.1,0.01\n500,0.1,0.01\n",
    "ragged": "wavelength,signal,uncertainty\n500,0.1\n600,0.1,0.01,7\n",
    "semicolons": "wavelength;signal;uncertainty\n500;0.1;0.01\n600;0.1;0.01\n",
    "binary": "\x00\x01\x02\xff",
}


@pytest.mark.parametrize("name", sorted(SPECTRA))
def test_bad_unmix_spectrum(files, capsys, tmp_path, name):
    path = tmp_path / "measured.csv"
    path.write_bytes(SPECTRA[name].encode("latin-1"))
    argv = ["invert", "unmix", str(path), "--cube", files["cube"], "--isel", "geometry=0"]
    run_cli(CATEGORY, argv, capsys, wrong=True, where=[str(path)], timeout=TIMEOUT)


#: Numeric flags: (command, flag, how many values, whether zero is allowed).
NUMERIC = [
    ("photometry", "--range-km", 1, False),
    ("photometry", "--sun-distance-au", 1, False),
    ("observe", "--duration", 1, False),
    ("observe", "--step", 1, False),
    ("observe", "--height", 1, True),
    ("spin", "--n-axes", 1, False),
    ("spin", "--n-phases", 1, False),
    ("spin", "--size-limit", 1, False),
    ("spin", "--periods", 3, False),
    ("spin", "--axis-body", 3, True),
]


@tour_settings(60)
@given(data=st.data())
def test_bad_numbers(files, mags, capsys, data):
    """Numbers drawn beyond each numeric flag's domain: not finite, not positive, or
    beyond any plan's size (a huge count, a step of a nanosecond)."""
    command, flag, n, zero_ok = data.draw(st.sampled_from(NUMERIC))
    bad = st.sampled_from(["nan", "inf", "-inf", "1e400", "abc"])
    if not zero_ok:
        bad = st.one_of(bad, st.floats(max_value=0.0, allow_nan=False).map(repr))
    if flag in ("--n-axes", "--n-phases"):
        bad = st.one_of(bad, st.integers(10**9, 10**30).map(str))
    if flag == "--step":
        bad = st.one_of(bad, st.floats(1e-300, 1e-6).map(repr))
    if flag == "--height":
        bad = st.one_of(bad, st.floats(1e8, 1e300).map(repr))
    if n == 1:
        values = [data.draw(bad)]
    else:
        good = st.floats(1.0, 100.0).map(repr)
        values = data.draw(st.lists(st.one_of(good, bad), min_size=n, max_size=n))
        if flag == "--periods" and values[2] not in ("nan", "inf", "-inf", "1e400", "abc"):
            # a count: the good draws are made bad as counts (fractions or huge)
            values[2] = data.draw(st.sampled_from(["2.5", "1e12", "0", "-4"]))
        if flag == "--axis-body" and all(v not in ("nan", "inf", "-inf", "1e400") for v in values):
            values = ["0", "0", "0"] if data.draw(st.booleans()) else [values[0], "nan", "0"]
        if flag == "--periods" and all(
            v not in ("nan", "inf", "-inf", "1e400", "abc") for v in values[:2]
        ):
            values[:2] = sorted(values[:2], key=float, reverse=True)
            if values[0] == values[1]:
                values[1] = "-" + values[1]
    changes: list[tuple[str, list[str] | None]] = [(flag, values)]
    if command == "observe" and flag == "--height":
        changes = [("--site", None), ("--lat", ["45"]), ("--lon", ["0"]), *changes]
    argv = _argv(files, command, changes)
    run_cli(CATEGORY, argv, capsys, wrong=True, where=[flag, *values], timeout=TIMEOUT)
