"""Tests of the sbrdf-xr command line."""

from __future__ import annotations

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
    from sbrdf_xr import material, testing

    path = material.to_netcdf(testing.make_material(), tmp_path / "m.nc")
    assert main(["info", str(path)]) == 0
    assert "sbrdf" in capsys.readouterr().out


def test_bad_subcommand_exits_with_usage():
    with pytest.raises(SystemExit) as exc:
        main(["fly"])
    assert exc.value.code == 2


def test_bench_quick_runs_and_reports_ratios(capsys, tmp_path):
    """The benchmark is code users run: it must not rot (no timing is asserted)."""
    import xarray as xr

    csv, nc, png = tmp_path / "b.csv", tmp_path / "b.nc", tmp_path / "front.png"
    assert main(["bench", "--quick", "--csv", str(csv), "-o", str(nc), "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert "sbrdf_xr linear look-up kernel" in out and "xarray .interp (linear)" in out
    assert (
        "lookup method: linear" in out
        and "band pre-integration" in out
        and "shadowing: sampled density" in out
    )
    ds = xr.open_dataset(nc)
    # The reference row is its own baseline; float32 changes magnitudes by far less than 1 mmag.
    ref = [c for c in ds.case.values if c.startswith("reference")]
    assert ref and float(ds.time_ratio.sel(case=ref[0])[0]) == 1.0
    f32 = ds.mmag_max.sel(case="precision: float32").values
    assert np.all(f32 < 0.1)
    # The analytic generating models differ from the tabulated reference (the table method's error).
    assert np.all(
        ds.mmag_max.sel(case="materials: analytic generating models (ground truth)").values > 1
    )
    ds.close()
    assert csv.stat().st_size > 0 and png.stat().st_size > 0
