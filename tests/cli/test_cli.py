"""Tests of the sbrdf-xr command line."""

from __future__ import annotations

import re

import numpy as np
import pytest

from sbrdf_xr import catalog
from sbrdf_xr.cli import main


def test_catalog_list_prints_every_entry(capsys):
    assert main(["catalog", "list"]) == 0
    out = capsys.readouterr().out
    for name in catalog.names():
        assert name in out
    assert f"{len(catalog.names())} entries" in out


def test_catalog_list_by_kind(capsys):
    assert main(["catalog", "list", "--kind", "measurements"]) == 0
    out = capsys.readouterr().out
    assert "example-lobe-measurements" in out and "lambertian-grey-50" not in out


def test_catalog_show_and_unknown(capsys):
    assert main(["catalog", "show", "lambertian-grey-50"]) == 0
    assert "provenance:" in capsys.readouterr().out
    assert main(["catalog", "show", "nope"]) == 2
    assert "no catalog entry named 'nope'" in capsys.readouterr().err


def test_info(capsys, tmp_path):
    assert main(["info"]) == 0
    assert "sbrdf_xr" in capsys.readouterr().out
    from sbrdf_xr import testing
    from sbrdf_xr.materials import tables as material

    path = material.to_netcdf(testing.make_material(), tmp_path / "m.nc")
    assert main(["info", str(path)]) == 0
    assert "sbrdf" in capsys.readouterr().out


def test_bench_repeat_must_be_positive(capsys):
    assert main(["bench", "--quick", "--repeat", "0"]) == 2
    assert "--repeat: got 0; expected a whole number >= 1" in capsys.readouterr().err


def test_bad_subcommand_exits_with_usage():
    with pytest.raises(SystemExit) as exc:
        main(["fly"])
    assert exc.value.code == 2


def test_bench_quick_runs_and_reports_ratios(capsys, tmp_path):
    """The benchmark is code users run: it must not rot (no timing is asserted)."""
    import xarray as xr

    csv, nc, png = tmp_path / "b.csv", tmp_path / "b.nc", tmp_path / "front.png"
    argv = ["bench", "--quick", "--repeat", "2", "--csv", str(csv), "-o", str(nc)]
    assert main([*argv, "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert "sbrdf_xr linear look-up kernel" in out and "xarray .interp (linear)" in out
    assert (
        "lookup method: linear" in out
        and "band pre-integration" in out
        and "shadowing: sampled density" in out
    )
    ds = xr.open_dataset(nc)
    # the load average at both ends of the run heads the table and is kept with it
    assert out.startswith("load average (1, 5, 15 min): ") and " at the end, on " in out
    assert ds.attrs["load_average"] == out.splitlines()[0]
    # The reference row is its own baseline; float32 changes magnitudes by far less than 1 mmag.
    ref = [c for c in ds.case.values if c.startswith("reference")]
    assert ref and float(ds.time_ratio.sel(case=ref[0])[0]) == 1.0
    f32 = ds.mmag_max.sel(case="precision: float32").values
    assert np.all(f32 < 0.1)
    # The analytic generating models differ from the tabulated reference (the table method's error).
    assert np.all(
        ds.mmag_max.sel(case="materials: analytic generating models (ground truth)").values > 1
    )
    # Every preset has its row: its errors against the reference and the generating models,
    # its time as the best of repeated runs with their spread.
    for preset in ("fast", "balanced", "reference"):
        row = ds.sel(case=f"preset: {preset}")
        assert np.all(np.isfinite(row.model_mmag_max)) and np.all(row.model_mmag_max > 1)
        assert np.all(row.time_spread >= 0) and np.all(row.time_ratio > 0)
    assert np.all(ds.mmag_max.sel(case="preset: reference").values == 0)
    assert "preset: balanced" in out and "vs generating models" in out
    ds.close()
    assert csv.stat().st_size > 0 and png.stat().st_size > 0


def test_catalog_list_and_show_say_where_entries_come_from(user_files, monkeypatch, capsys):
    cat = user_files / "usercat"
    monkeypatch.setenv("SBRDF_XR_CATALOG_PATH", str(cat))
    assert main(["catalog", "list"]) == 0
    out = capsys.readouterr().out
    line = next(ln for ln in out.splitlines() if ln.startswith("user-box "))
    assert line.split()[1:4] == ["spacecraft", "synthetic", "user1"]
    assert next(ln for ln in out.splitlines() if ln.startswith("canx1 ")).split()[3] == "shipped"
    assert f"user1    {cat.resolve()}" in out and f"{len(catalog.names())} entries" in out
    assert main(["catalog", "show", "user-grey-30"]) == 0
    assert f"catalog:     {cat.resolve()}" in capsys.readouterr().out
    assert main(["catalog", "show", "canx1"]) == 0
    assert "catalog:     shipped" in capsys.readouterr().out


def test_catalog_name_clash_is_one_error_line(user_files, monkeypatch, capsys):
    cat = user_files / "usercat"
    text = (cat / "index.toml").read_text(encoding="utf-8")
    (cat / "index.toml").write_text(text.replace('"user-box"', '"canx1"'), encoding="utf-8")
    monkeypatch.setenv("SBRDF_XR_CATALOG_PATH", str(cat))
    assert main(["catalog", "list"]) == 2
    err = capsys.readouterr().err
    assert (
        err.startswith("sbrdf-xr: error: user catalog ")
        and "'canx1' is already in the shipped" in err
    )


def test_simulate_with_a_mesh_file_and_material_files(user_files, capsys):
    files = user_files / "files"
    out = user_files / "box.nc"
    args = ["simulate", "canx1-plusx-specular", "-o", str(out), "-q"]
    body = ["--spacecraft", str(files / "box.stl"), "--mesh-material", "paint"]
    assert main([*args, *body, "--material", f"paint={files / 'grey30.nc'}"]) == 0
    import xarray as xr

    with xr.open_dataset(out) as cube:
        assert cube.attrs["spacecraft"] == "box" and list(cube.material.values) == ["paint"]
    capsys.readouterr()
    # a model file, on the shipped spacecraft: only that material changes
    assert main([*args, "--material", f"tjpv-cell={files / 'model40.nc'}", "--plan"]) == 0
    assert "plan for scene" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("extra", "match"),
    [
        (["--spacecraft", "{files}/box.stl"], "a mesh file needs --mesh-material NAME"),
        (["--spacecraft", "{files}/nope.stl", "--mesh-material", "m"], "nope.stl does not exist"),
        (["--spacecraft", "{files}/box.step", "--mesh-material", "m"], "allowed suffixes"),
        (["--spacecraft", "canx1", "--mesh-material", "m"], "'canx1' is a catalog entry"),
        (["--mesh-material", "m"], "give --spacecraft too"),
        (["--material", "paint"], "expected MATERIAL=NAME or MATERIAL=FILE.nc"),
        (["--material", "paint=x.nc"], r"\['paint'\] are not materials of the spacecraft 'canx1'"),
        (["--material", "tjpv-cell={files}/none.nc"], "none.nc does not exist"),
    ],
)
def test_simulate_bad_body_options(user_files, capsys, extra, match):
    files = user_files / "files"
    argv = ["simulate", "canx1-plusx-specular", "-o", str(user_files / "x.nc"), "--plan"]
    assert main(argv + [a.format(files=files) for a in extra]) == 2
    err = capsys.readouterr().err
    assert err.startswith("sbrdf-xr: error: ") and re.search(match, err), err


def test_simulate_defaults_are_the_librarys():
    """The command line writes what the library writes unless told otherwise: it leaves the
    level to the writer (for netCDF an uncompressed cube, the one a kill at any instant
    leaves resumable; for a resume the level the cube was started with)."""
    import inspect

    from sbrdf_xr.cli.parser import build_parser
    from sbrdf_xr.store.writer import DEFAULT_COMPLEVEL, write_cube

    args = build_parser().parse_args(["simulate", "canx1-rotation", "-o", "cube.nc"])
    library = inspect.signature(write_cube).parameters["complevel"].default
    assert args.complevel is None and library == DEFAULT_COMPLEVEL == 0


def test_simulate_help_lists_every_builtin_scene(capsys, monkeypatch):
    from sbrdf_xr.engine import builtin_scenes

    monkeypatch.setenv("COLUMNS", "400")  # no line break inside a hyphenated name
    with pytest.raises(SystemExit):
        main(["simulate", "--help"])
    out = capsys.readouterr().out
    assert len(builtin_scenes()) == 3
    for name in builtin_scenes():
        assert name in out


@pytest.mark.parametrize(
    ("extra", "match"),
    [
        (
            ["--spacecraft", "{files}/box.stl", "--mesh-material", "aluminium-6061"],
            r"--mesh-material 'aluminium-6061': material: no catalog entry named "
            r"'aluminium-6061'; did you mean 'aluminium-6061-t6'",
        ),
        (
            ["--material", "tjpv-cell=aluminium-6061"],
            r"--material 'tjpv-cell': .*; did you mean 'aluminium-6061-t6'",
        ),
        (
            ["--material", "tjpv-cel=lambertian-grey-50"],
            r"\['tjpv-cel'\] are not materials .*; did you mean 'tjpv-cell'\?",
        ),
    ],
)
def test_simulate_misspelt_materials_get_suggestions(user_files, capsys, extra, match):
    files = user_files / "files"
    argv = ["simulate", "canx1-plusx-specular", "-o", str(user_files / "x.nc"), "--plan"]
    assert main(argv + [a.format(files=files) for a in extra]) == 2
    err = capsys.readouterr().err
    assert re.search(match, err), err
    assert not [n for n in catalog.names("site") + catalog.names("orbit") if n in err]


def test_simulate_quiet_prints_only_what_it_wrote(user_files, capsys):
    """``-q``: no plan, no progress bar, the line naming the cube; ``--plan -q`` still
    prints the plan (asked for)."""
    out = user_files / "quiet.nc"
    assert main(["simulate", "canx1-plusx-specular", "-o", str(out), "-q"]) == 0
    captured = capsys.readouterr()
    assert captured.out.splitlines() == [f"wrote {out}"]
    assert main(["simulate", "canx1-plusx-specular", "-o", str(out), "-q", "--plan"]) == 0
    assert capsys.readouterr().out.startswith("plan for scene")
