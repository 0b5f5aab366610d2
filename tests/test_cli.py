"""Tests of the sbrdf-xr command line."""

from __future__ import annotations

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


def test_bench_quick_runs_and_reports_ratios(capsys):
    """The benchmark is code users run: it must not rot (no timing is asserted)."""
    assert main(["bench", "--quick"]) == 0
    out = capsys.readouterr().out
    assert "sbrdf_xr linear kernel" in out and "xarray .interp (linear)" in out
    assert "max rel diff" in out
