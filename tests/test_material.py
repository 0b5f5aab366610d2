"""Tests of sbrdf_xr.material: schema, lookup wrapper, LUT construction, reflectance, I/O."""

from __future__ import annotations

import dask
import dask.array as dsa
import numpy as np
import pytest
import xarray as xr

import sbrdf_xr  # noqa: F401  (registers the accessors)
from sbrdf_xr import material as M
from sbrdf_xr import testing
from sbrdf_xr.errors import NonPhysicalWarning, ValidationError


class _RaiseIfComputes:
    """Dask scheduler that fails on any computation (xarray's raise_if_dask_computes)."""

    def __call__(self, dsk, keys, **kwargs):
        raise AssertionError("graph building triggered a dask computation")


# ------------------------------------------------------------------ schema


def test_new_material_carries_cf_attributes():
    da = testing.make_material()
    assert da.name == "sbrdf" and da.dims == ("theta_i", "delta_theta", "phi", "wavelength")
    assert da.attrs["units"] == "sr-1" and da.attrs["long_name"]
    for d in da.dims:
        assert da[d].attrs["units"] and da[d].attrs["long_name"]
    assert da.wavelength.attrs["standard_name"] == "radiation_wavelength"


@pytest.mark.parametrize(
    ("mutate", "match"),
    [
        (lambda d: d.rename(phi="psi"), "dims must be"),
        (lambda d: d.isel(wavelength=0), "dims must be"),
        (lambda d: d.assign_attrs(units="1"), "sbrdf: units"),
        (lambda d: d.assign_coords(phi=d.phi.assign_attrs(units="rad")), "phi: units"),
        (lambda d: d.isel(delta_theta=slice(None, None, -1)), "delta_theta: coordinate must be strictly increasing"),
        (lambda d: d.where(d.theta_i != 30), "NaN"),
        (lambda d: d - 10.0, "negative"),
        (lambda d: d.assign_coords(theta_i=d.theta_i + 5), r"theta_i: must lie in \[0, 90\]"),
        (lambda d: d.assign_attrs(source="made-up"), "source"),
        (lambda d: d.drop_vars("wavelength"), "wavelength: coordinate is missing"),
    ],
)
def test_invalid_tables_name_the_problem(mutate, match):
    da = testing.make_material()
    bad = mutate(da)
    if "units" not in bad.attrs and match != "sbrdf: units":
        bad.attrs["units"] = "sr-1"
    with pytest.raises(ValidationError, match=match):
        M.validate_material(bad)


def test_not_a_dataarray():
    with pytest.raises(ValidationError, match=r"expected an xarray\.DataArray"):
        M.validate_material(np.zeros((2, 2, 2, 2)))


def test_transposed_table_is_accepted_in_canonical_order():
    da = testing.make_material()
    out = M.validate_material(da.transpose("wavelength", "phi", "theta_i", "delta_theta"))
    assert out.dims == da.dims
    xr.testing.assert_identical(out, da)


# ------------------------------------------------------------------ lookup


def test_lookup_wrapper_labels_and_matches_xarray_interp():
    da = testing.make_material()
    rng = np.random.default_rng(0)
    ti = xr.DataArray(rng.uniform(0, 90, 40), dims="geom")
    dt = xr.DataArray(rng.uniform(-60, 40, 40), dims="geom")
    ph = xr.DataArray(rng.uniform(0, 30, 40), dims="geom")
    out = da.sbrdf.lookup(ti, dt, ph)
    assert out.dims == ("geom", "wavelength")
    assert out.attrs["units"] == "sr-1" and out.attrs["lookup_method"] == "linear"
    np.testing.assert_array_equal(out.wavelength, da.wavelength)
    ref = da.interp(theta_i=ti, delta_theta=dt, phi=ph, method="linear").transpose("geom", "wavelength")
    np.testing.assert_allclose(out.values, ref.values, rtol=1e-12)


def test_lookup_broadcasts_named_dims():
    da = testing.make_material()
    ti = xr.DataArray([10.0, 20.0, 30.0], dims="attitude")
    dt = xr.DataArray([0.0, 5.0], dims="phase_angle")
    out = M.lookup(da, ti, dt, 1.0, method="cubic")
    assert out.dims == ("attitude", "phase_angle", "wavelength")


def test_lookup_is_lazy_for_dask_and_equals_numpy():
    da = testing.make_material()
    rng = np.random.default_rng(1)
    vals = [rng.uniform(0, 90, 100), rng.uniform(-60, 40, 100), rng.uniform(0, 30, 100)]
    lazy = [xr.DataArray(dsa.from_array(v, chunks=25), dims="geom") for v in vals]
    with dask.config.set(scheduler=_RaiseIfComputes()):
        out = M.lookup(da, *lazy)
    assert out.chunks is not None
    eager = M.lookup(da, *(xr.DataArray(v, dims="geom") for v in vals))
    xr.testing.assert_allclose(out.compute(scheduler="sync"), eager, rtol=0, atol=0)


def test_lookup_rejects_nan_angles_and_unknown_method():
    da = testing.make_material()
    with pytest.raises(ValidationError, match="delta_theta: query angles contain NaN"):
        M.lookup(da, [10.0], [np.nan], [0.0])
    with pytest.raises(ValidationError, match="method: unknown look-up method 'quadratic'"):
        M.lookup(da, [10.0], [0.0], [0.0], method="quadratic")


# -------------------------------------------------------------- build_lut


@pytest.fixture(scope="module")
def meas():
    return testing.make_measurements(n_wavelength=31)


def test_paper_grids():
    np.testing.assert_allclose(M.paper_phi_grid(2.5), np.linspace(0, 2.5, 21))
    g = M.paper_delta_theta_grid(-46.0, 51.0)
    assert g.size == 21 and g[10] == 0.0
    np.testing.assert_allclose(np.diff(g[:11]), 4.6)
    np.testing.assert_allclose(np.diff(g[10:]), 5.1)


def test_build_lut_follows_the_paper_construction(meas):
    lut = M.build_lut(meas)
    assert lut.sizes == {"theta_i": 91, "delta_theta": 21, "phi": 21, "wavelength": 31}
    np.testing.assert_array_equal(lut.theta_i, np.arange(91.0))
    assert lut.phi.values[-1] == pytest.approx(float(meas.phi.max()))
    assert lut.delta_theta.values[0] == pytest.approx(float(meas.delta_theta.min()))
    assert lut.delta_theta.values[-1] == pytest.approx(float(meas.delta_theta.max()))
    assert lut.attrs["construction"] == "paper000-3.2" and lut.attrs["n_measurements"] == 150


def test_reference_points_make_the_edges_zero_and_measured_extents_are_held():
    # A narrow lobe on no floor: every extent is where the signal is in the noise.
    narrow = testing.make_measurements(n_wavelength=7, width=3.0, diffuse=0.0)
    assert int(narrow.reference.sum()) == 45
    lut = M.build_lut(narrow)
    np.testing.assert_array_equal(lut.isel(phi=-1), 0.0)
    np.testing.assert_array_equal(lut.isel(delta_theta=[0, -1]), 0.0)
    # A diffuse floor above the noise: the apparatus limits come first, the extents are
    # measured points, and the table holds their values instead of dropping to zero.
    assert (lut.attrs["edge_delta_theta_min"], lut.attrs["edge_phi_max"]) == ("zero", "zero")
    beyond = M.lookup(lut, 40.0, float(lut.delta_theta[0]) - 5.0, 0.0)
    np.testing.assert_array_equal(beyond, 0.0)
    floor = testing.make_measurements(n_wavelength=7, width=3.0, diffuse=0.2)
    assert not floor.reference.any()
    lut = M.build_lut(floor)
    assert lut.attrs["edge_delta_theta_min"] == lut.attrs["edge_phi_max"] == "hold"
    # Beyond a held edge the look-up holds the edge value instead of dropping to zero.
    edge = M.lookup(lut, 70.0, float(lut.delta_theta[0]), 10.0)
    np.testing.assert_allclose(M.lookup(lut, 70.0, float(lut.delta_theta[0]) - 5.0, 10.0), edge)
    assert float(edge.min()) > 0
    # (the floor is 0.16-0.24 sr-1; cubic extrapolation in theta_i may dip below it)
    assert float(lut.isel(phi=-1).min()) > 0.05


def test_build_lut_interpolating_spline_reproduces_specular_measurements(meas):
    """With lam = 0 the spline passes through the data; (delta_theta, phi) = (0, 0) is a
    measured geometry and a grid node at every measured theta_i."""
    lut = M.build_lut(meas, smoothing=0.0)
    spec = meas.where((meas.delta_theta == 0) & (meas.phi == 0), drop=True)
    for k in range(spec.sizes["sample"]):
        s = spec.isel(sample=k)
        got = lut.sel(theta_i=float(s.theta_i), delta_theta=0.0, phi=0.0)
        np.testing.assert_allclose(got.values, s.measured_sbrdf.values, rtol=1e-10)


def test_build_lut_error_against_truth_is_small_inside_the_measured_range(meas):
    lut = M.build_lut(meas, smoothing=0.0)
    truth = testing.lobe_function(meas.wavelength.values)
    rng = np.random.default_rng(0)
    ti = rng.uniform(10, 70, 300)
    dt = rng.uniform(-3, 3, 300)
    ph = rng.uniform(0, 3, 300)
    got = M.lookup(lut, ti, dt, ph).values
    rel = np.abs(got / truth(ti, dt, ph) - 1)
    # Table 1 puts the phi columns about one lobe sigma apart; linear interpolation
    # of a Gaussian across one sigma is off by up to 1 - (1 + e**-0.5)/2 / e**-0.125
    # = 9% at mid-step, and by less elsewhere: the table should do no worse.
    assert np.median(rel) < 0.09 and rel.max() < 0.2


def test_build_lut_options_and_dtype(meas):
    lut = M.build_lut(meas, n_phi=11, n_delta_theta=11, theta_i=np.arange(0, 91, 5.0),
                      extrapolation="constant", dtype=np.float32)
    assert lut.dtype == np.float32 and lut.sizes["phi"] == 11 and lut.sizes["delta_theta"] == 11
    # Constant extrapolation below 10 deg: rows equal the 10-degree row of the spline.
    np.testing.assert_allclose(lut.sel(theta_i=0.0), lut.sel(theta_i=5.0), rtol=1e-6)


@pytest.mark.parametrize(
    ("mutate", "match"),
    [
        (lambda d: d.isel(sample=slice(0, 0)), "empty"),
        (lambda d: d.isel(sample=d.theta_i == 10.0), "need measurements at >= 2 incidence angles"),
        (lambda d: d.assign(measured_sbrdf=d.measured_sbrdf.where(d.sample != 1).assign_attrs(units="sr-1")),
         r"NaN or infinite values in sample\(s\) \[1\]"),
        (lambda d: d.assign(measured_sbrdf=(d.measured_sbrdf - 5).assign_attrs(units="sr-1")), "negative"),
        (lambda d: d.assign_coords(phi=d.phi.assign_attrs(units="rad")), "phi: units"),
        (lambda d: d.drop_vars("delta_theta"), "delta_theta: coordinate over 'sample' is missing"),
        (lambda d: d.rename(measured_sbrdf="brdf"), "lacks the data variable 'measured_sbrdf'"),
    ],
)
def test_bad_measurement_sets_name_the_problem(meas, mutate, match):
    with pytest.raises(ValidationError, match=match):
        M.build_lut(mutate(meas))


def test_single_row_incidence_angle_is_rejected(meas):
    one_row = meas.isel(sample=(meas.theta_i != 10.0) | (meas.delta_theta == 0.0))
    with pytest.raises(ValidationError, match="single delta_theta"):
        M.build_lut(one_row)


# ------------------------------------------------------------- reflectance


def test_hemispherical_reflectance_wrapper_and_warning():
    full = dict(theta_i=np.array([0.0, 45.0, 90.0]), delta_theta=np.array([-180.0, 0.0, 90.0]),
                phi=np.array([0.0, 45.0, 90.0]))
    lam = testing.make_material(value=0.5 / np.pi, **full)
    rho = lam.sbrdf.hemispherical_reflectance()
    assert rho.dims == ("theta_i", "wavelength") and rho.attrs["units"] == "1"
    np.testing.assert_allclose(rho.values, 0.5, rtol=1e-11)
    bright = testing.make_material(value=1.5 / np.pi, **full)
    with pytest.warns(NonPhysicalWarning, match="reaches 1.500 > 1"):
        M.hemispherical_reflectance(bright)


# --------------------------------------------------------------------- I/O


def test_netcdf_round_trip_is_exact(tmp_path, meas):
    lut = M.build_lut(meas)
    path = M.to_netcdf(lut, tmp_path / "m.nc")
    back = M.open_material(path)
    # the writer adds the file-level ACDD attributes title and history (CF/ACDD basics)
    assert back.attrs.pop("title") and back.attrs.pop("history")
    xr.testing.assert_identical(back, lut)
    assert back.dtype == lut.dtype
    mpath = M.to_netcdf(meas, tmp_path / "meas.nc")
    mback = M.open_measurements(mpath)
    xr.testing.assert_identical(mback.drop_attrs(deep=False), meas.drop_attrs(deep=False))
    assert mback.reference.dtype == bool


def test_netcdf_never_overwrites_by_accident(tmp_path):
    lut = testing.make_material()
    path = M.to_netcdf(lut, tmp_path / "m.nc")
    before = path.read_bytes()
    with pytest.raises(FileExistsError, match="overwrite=True"):
        M.to_netcdf(lut * 2, path)
    assert path.read_bytes() == before
    assert not list(tmp_path.glob("*.part"))
