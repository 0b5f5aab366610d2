"""CF-1.10 compliance (IOOS compliance-checker, offline) of photometry, material and cube files."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from sbrdf_xr import catalog
from sbrdf_xr import photometry as P
from sbrdf_xr import testing as T
from sbrdf_xr.engine import Scene
from sbrdf_xr.engine.run import simulate
from sbrdf_xr.materials import models
from sbrdf_xr.materials import tables as material

pytest.importorskip("compliance_checker")

CATALOG_MATERIALS = sorted(
    (Path(__file__).resolve().parents[2] / "catalogs" / "materials").glob("*.nc")
)
# table4-paints.nc has a string coordinate variable 'sample(sample)'; compliance-checker
# 6.1's monotonicity check raises on strings instead of reporting (no error or warning).
CHECKER_RAISES_ON_STRING_COORDINATES = {"table4-paints.nc"}


def cf_report(path: Path) -> tuple[list[str], list[str], list[str]]:
    """(errors, warnings, checks that raised) of compliance-checker cf:1.10 on ``path``.

    Errors are failed high-priority checks, warnings failed medium-priority ones, as the
    checker's own text report counts them.
    """
    import warnings

    from compliance_checker.runner import CheckSuite

    cs = CheckSuite()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # the checker's own ioos_sos plugin
        cs.load_all_available_checkers()
    ds = cs.load_dataset(str(path))
    groups, raised = cs.run_all(ds, ["cf:1.10"], skip_checks=[])["cf:1.10"]
    errors, warnings = [], []

    def walk(results):
        for r in results:
            v = r.value
            failed = (v[0] < v[1]) if isinstance(v, tuple) else not v
            if failed:
                (errors if r.weight == 3 else warnings if r.weight == 2 else []).append(
                    f"{r.name}: {r.msgs}"
                )
            walk(r.children or [])

    walk(groups)
    return errors, warnings, sorted(raised)


def _scene():
    wl = np.arange(290.0, 1201.0, 10.0)
    spec = models.model_material("lambert", wl, rho=0.5, material="white", provenance="test")
    table = models.render(
        spec,
        theta_i=np.arange(0.0, 91.0, 15.0),
        delta_theta=np.arange(-180.0, 91.0, 30.0),
        phi=np.arange(0.0, 91.0, 15.0),
    )
    scene = Scene(
        T.cube_spacecraft(1.0),
        materials={T.TEST_SPACECRAFT_MATERIAL: table},
        to_sun=[[1.0, 0.0, 0.0], [0.6, 0.8, 0.0]],
        to_observer=[[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
    )
    return scene


def _cube():
    return simulate(_scene()).compute()


def simulate_scene_lazy():
    return simulate(_scene())


def _attribute_names_are_cf(ds) -> list[str]:
    ok = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
    bad = [k for k in ds.attrs if not ok.match(k)]
    for name, var in ds.variables.items():
        bad += [f"{name}.{k}" for k in var.attrs if not ok.match(k) and not k.startswith("_")]
    return bad


@pytest.mark.parametrize("system", ["AB", "Vega"])
def test_photometry_file_is_cf_clean(tmp_path, system):
    import xarray as xr

    ds = P.photometry(_cube(), ["B", "V", "R"], 1000.0, system=system)
    path = P.to_netcdf(ds, tmp_path / "phot.nc")
    errors, warnings, raised = cf_report(path)
    assert (errors, warnings, raised) == ([], [], [])
    with xr.open_dataset(path) as raw:
        for name, var in raw.variables.items():
            assert var.attrs.get("long_name"), name
        assert (
            raw.magnitude.attrs["units"] == "1"
            and raw.magnitude.attrs["magnitude_system"] == system
        )
        assert _attribute_names_are_cf(raw) == []
        for a in ("title", "source", "history", "Conventions"):
            assert raw.attrs[a]
    back = P.open_photometry(path)
    xr.testing.assert_equal(back.magnitude, ds.magnitude)
    assert back.band.values.tolist() == ["B", "V", "R"] and back.colour.values.tolist() == [
        "B-V",
        "V-R",
    ]


def test_written_material_files_are_cf_clean(tmp_path):
    import xarray as xr

    paths = [
        material.to_netcdf(catalog.load("lambertian-grey-50"), tmp_path / "table.nc"),
        material.to_netcdf(catalog.load("white-paint-a276-measurements"), tmp_path / "meas.nc"),
        models.to_netcdf(catalog.load("white-paint-a276-fit"), tmp_path / "fit.nc"),
    ]
    for path in paths:
        assert cf_report(path) == ([], [], []), path.name
    with xr.open_dataset(tmp_path / "meas.nc", decode_cf=False) as raw:
        assert raw.reference.attrs["flag_meanings"] == "measured_point reference_point"
        np.testing.assert_array_equal(raw.reference.attrs["flag_values"], [0, 1])
    with xr.open_dataset(tmp_path / "fit.nc") as raw:
        assert raw.rho_D.attrs["ancillary_variables"] == "u_rho_D"
    assert material.open_measurements(tmp_path / "meas.nc").reference.dtype == bool


@pytest.mark.parametrize("path", CATALOG_MATERIALS, ids=[p.name for p in CATALOG_MATERIALS])
def test_shipped_material_files_are_cf_clean(path):
    errors, warnings, raised = cf_report(path)
    assert (errors, warnings) == ([], [])
    assert raised == (
        ["check_coordinate_variables_strict_monotonicity"]
        if path.name in CHECKER_RAISES_ON_STRING_COORDINATES
        else []
    )


@pytest.mark.xfail(
    strict=True,
    reason="cubes keep string dimension coordinates (xyz, component, "
    "material, band) for label-based selection; compliance-checker 6.1 raises in its "
    "monotonicity check on them instead of reporting",
)
def test_cube_file_is_cf_clean(tmp_path):
    from sbrdf_xr import write

    path = tmp_path / "cube.nc"
    write(simulate_scene_lazy(), path)
    assert cf_report(path) == ([], [], [])
