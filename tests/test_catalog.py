"""Tests of sbrdf_xr.catalog and the catalogs that ship."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from sbrdf_xr import catalog, material
from sbrdf_xr.errors import CatalogError


def test_every_entry_has_provenance_and_loads():
    assert catalog.names(), "the catalog is empty"
    for e in catalog.entries():
        assert e.description and e.provenance
        assert e.source in ("measured", "synthetic") or e.source.startswith("model:")
        assert e.file.is_file()
        obj = catalog.load(e.name)
        if e.kind == "material":
            material.validate_material(obj)
        elif e.kind == "measurements":
            material.validate_measurements(obj)


def test_unknown_names_and_kinds():
    with pytest.raises(CatalogError, match="no catalog entry named 'nope'; known:"):
        catalog.load("nope")
    with pytest.raises(CatalogError, match="unknown catalog kind"):
        catalog.entries("colour")


def test_lambertian_reference_integrates_to_its_albedo():
    rho = material.hemispherical_reflectance(catalog.load("lambertian-grey-50"), [0.0, 45.0, 80.0])
    np.testing.assert_allclose(rho.values, 0.5, rtol=1e-6)  # float32 table: 1e-7 relative


def test_built_entry_equals_build_lut_of_its_measurements_and_is_read_only():
    """Loads share one built table (no second copy in memory): its values cannot be
    changed in place, its attrs are each load's own, and ``.copy()`` is writable."""
    built = catalog.load("example-lobe")
    direct = material.build_lut(catalog.load("example-lobe-measurements"), material="example-lobe")
    xr.testing.assert_identical(built, direct)
    with pytest.raises(ValueError, match="copy"):
        built[...] = 0.0
    built.attrs["provenance"] = "changed"
    mine = built.copy()
    mine[...] = 0.0
    again = catalog.load("example-lobe")
    assert float(again.max()) > 0  # the shared table was not modified
    assert again.attrs.get("provenance") != "changed"
    assert np.shares_memory(again.values, built.values)


def test_installed_package_finds_its_catalogs_from_any_directory(tmp_path):
    """After `pip install .` the catalogs ship inside the package (not editable)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    code = (
        "import sbrdf_xr, sbrdf_xr.catalog as c; print(sbrdf_xr.__file__); "
        "print(c.catalog_dir()); print(len(c.names()))"
    )
    res = subprocess.run(
        [sys.executable, "-c", code],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    if res.returncode != 0 and "No module named 'sbrdf_xr'" in res.stderr:
        pytest.skip("sbrdf_xr is not installed in this interpreter (source-tree run)")
    assert res.returncode == 0, res.stderr
    module_file, cat_dir, n = res.stdout.split()
    repo = Path(__file__).resolve().parent.parent
    if Path(module_file).resolve().parent == repo / "sbrdf_xr":
        pytest.skip("sbrdf_xr is installed in editable mode")
    assert Path(cat_dir).resolve().is_relative_to(Path(module_file).resolve().parent)
    assert int(n) == len(catalog.names())
