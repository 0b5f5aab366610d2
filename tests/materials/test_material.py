"""Tests of sbrdf_xr.materials.tables: schema, lookup wrapper, LUT construction, reflectance,
I/O."""

from __future__ import annotations

import warnings

import dask
import dask.array as dsa
import numpy as np
import pytest
import xarray as xr
from hypothesis import example, given, settings
from hypothesis import strategies as st
from hypothesis_profiles import examples

import sbrdf_xr  # noqa: F401  (registers the accessors)
from sbrdf_xr import testing
from sbrdf_xr.errors import NonPhysicalWarning, ValidationError
from sbrdf_xr.materials import energy as E
from sbrdf_xr.materials import tables as M


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
        (
            lambda d: d.isel(delta_theta=slice(None, None, -1)),
            "delta_theta: coordinate must be strictly increasing",
        ),
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
    ref = da.interp(theta_i=ti, delta_theta=dt, phi=ph, method="linear").transpose(
        "geom", "wavelength"
    )
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


@pytest.fixture(scope="module")
def meas_symmetric():
    return M.build_lut(testing.make_measurements(n_wavelength=31))


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
    # (the paper's normal incidence: the symmetric default averages the theta_i = 0 row
    # over azimuth, which carries lobe values onto its phi edge)
    lut = M.build_lut(narrow, normal_incidence="paper")
    np.testing.assert_array_equal(lut.isel(phi=-1), 0.0)
    np.testing.assert_array_equal(lut.isel(delta_theta=[0, -1]), 0.0)
    # A diffuse floor above the noise: the apparatus limits come first, the extents are
    # measured points, and the table holds their values instead of dropping to zero.
    assert (lut.attrs["edge_delta_theta_min"], lut.attrs["edge_phi_max"]) == ("zero", "zero")
    beyond = M.lookup(lut, 40.0, float(lut.delta_theta[0]) - 5.0, 0.0)
    np.testing.assert_array_equal(beyond, 0.0)
    floor = testing.make_measurements(n_wavelength=7, width=3.0, diffuse=0.2)
    assert not floor.reference.any()
    lut = M.build_lut(floor, check_energy=False)  # (a 0.2 sr-1 floor under a lobe: rho > 1)
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
    lut = M.build_lut(
        meas,
        n_phi=11,
        n_delta_theta=11,
        theta_i=np.arange(0, 91, 5.0),
        extrapolation="constant",
        dtype=np.float32,
        normal_incidence="paper",
    )
    assert lut.dtype == np.float32 and lut.sizes["phi"] == 11 and lut.sizes["delta_theta"] == 11
    # Constant extrapolation below 10 deg: rows equal the 10-degree row of the spline.
    np.testing.assert_allclose(lut.sel(theta_i=0.0), lut.sel(theta_i=5.0), rtol=1e-6)


@pytest.mark.parametrize(
    ("mutate", "match"),
    [
        (lambda d: d.isel(sample=slice(0, 0)), "empty"),
        (lambda d: d.isel(sample=d.theta_i == 10.0), "need measurements at >= 2 incidence angles"),
        (
            lambda d: d.assign(
                measured_sbrdf=d.measured_sbrdf.where(d.sample != 1).assign_attrs(units="sr-1")
            ),
            r"NaN or infinite values in sample\(s\) \[1\]",
        ),
        (
            lambda d: d.assign(measured_sbrdf=(d.measured_sbrdf - 5).assign_attrs(units="sr-1")),
            "negative",
        ),
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
    full = dict(
        theta_i=np.array([0.0, 45.0, 90.0]),
        delta_theta=np.array([-180.0, 0.0, 90.0]),
        phi=np.array([0.0, 45.0, 90.0]),
    )
    lam = testing.make_material(value=0.5 / np.pi, **full)
    rho = lam.sbrdf.hemispherical_reflectance()
    assert rho.dims == ("theta_i", "wavelength") and rho.attrs["units"] == "1"
    np.testing.assert_allclose(rho.values, 0.5, rtol=1e-11)
    bright = testing.make_material(value=1.5 / np.pi, **full)
    with pytest.warns(NonPhysicalWarning, match="reaches 1.500 > 1"):
        E.hemispherical_reflectance(bright)


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


# ------------------------------------------------------- repeated geometries


def test_repeated_geometries_are_a_named_error_or_averaged(meas):
    # One sample repeated with a 3x spectrum: an error naming the geometry, or the mean.
    rep = xr.concat([meas, meas.isel(sample=[5])], dim="sample")
    rep["measured_sbrdf"].values[-1] *= 3.0
    with pytest.raises(
        ValidationError, match=r"repeat 1 geometry .* samples \[5, 150\].*duplicates='mean'"
    ):
        M.build_lut(rep)
    avg = M.build_lut(rep, duplicates="mean", check_energy=False)
    fixed = meas.copy(deep=True)
    fixed["measured_sbrdf"].values[5] *= 2.0  # mean of 1x and 3x
    np.testing.assert_allclose(avg, M.build_lut(fixed, check_energy=False), rtol=1e-12, atol=1e-15)
    # Every sample duplicated: the error is about the input, not NaN in the output.
    both = xr.concat([meas, meas], dim="sample")
    with pytest.raises(ValidationError, match="150 geometries"):
        M.build_lut(both)
    np.testing.assert_allclose(
        M.build_lut(both, duplicates="mean", check_energy=False),
        M.build_lut(meas, check_energy=False),
        rtol=1e-12,
        atol=1e-15,
    )
    with pytest.raises(ValidationError, match="duplicates: got 'sum'"):
        M.build_lut(meas, duplicates="sum")


# ----------------------------------------------------------- below the noise


def test_below_noise_model_fill_keeps_the_floor_and_the_measurements():
    # A glossy dielectric whose diffuse floor is below the noise: the paper zeroes the
    # floor beyond the extents; below_noise="model" fills it from the model.  With the
    # generating model as the "fit" (no noise, so every measured/model ratio is 1) the
    # filled table is the model on the grid: the look-up error is interpolation only.
    from sbrdf_xr.materials import models

    wl = np.linspace(450.0, 1000.0, 4)
    spec = models.model_material(
        "microfacet",
        wl,
        material="gloss",
        provenance="test",
        roughness=0.1,
        n=1.5,
        k=0.0,
        rho_d=0.05,
    )
    meas = models.measure(spec, (10.0, 25.0, 40.0, 55.0, 70.0))
    assert meas.reference.any()
    # The theta_i = 90 row of a glossy table meets the horizon between 5-degree nodes; the
    # nodes at and beyond the horizon hold the last visible value (not the model's limit
    # at grazing exit), so no row gains energy there.
    with warnings.catch_warnings():
        warnings.simplefilter("error", NonPhysicalWarning)
        M.build_lut(
            meas, below_noise="model", model=spec, extrapolation="constant", renormalise="none"
        )
    # The flux-conserving renormalisation (the default with below_noise="model") scales
    # every row by the energy the model loses or gains on the grid: with every
    # measured/model ratio 1 the table keeps the model's reflectance at every row, to
    # the accuracy of the model's own quadrature (~1e-6; 1e-4 next to grazing).
    filled = M.build_lut(meas, below_noise="model", model=spec, extrapolation="constant")
    assert filled.attrs["renormalise"] == "model"
    mod, _, kw = models.model_parameters(spec)
    ti_all = filled.theta_i.values
    np.testing.assert_allclose(
        E.hemispherical_reflectance(filled),
        mod.directional_hemispherical_reflectance(np.minimum(ti_all, 90.0), wl, **kw),
        rtol=1e-9,
    )
    with pytest.raises(ValidationError, match="renormalise: got 'flux'"):
        M.build_lut(meas, below_noise="model", model=spec, renormalise="flux")
    with pytest.raises(ValidationError, match="needs below_noise='model'"):
        M.build_lut(meas, renormalise="model")
    assert filled.attrs["below_noise"] == "model"
    assert filled.delta_theta.values[0] == -180.0 and filled.delta_theta.values[-1] == 90.0
    assert filled.phi.values[-1] == 90.0
    far = (40.0, -60.0, 30.0)
    truth = models.spectra(spec, *far)
    # (linear interpolation of the smooth floor and tail on 5-degree nodes: < 1 %)
    np.testing.assert_allclose(M.lookup(filled, *far), truth, rtol=0.01)
    # At the measured geometries (not grid nodes) the filled table is the model
    # interpolated on the grid: within the linear-interpolation error of the lobe
    # (nodes ~1 deg apart on a lobe of alpha = 0.1: up to 16 %).
    sel = ((meas.theta_i == 40.0) & ~meas.reference).values
    got = M.lookup(
        filled, meas.theta_i.values[sel], meas.delta_theta.values[sel], meas.phi.values[sel]
    )
    np.testing.assert_allclose(got, meas.measured_sbrdf.values[sel], rtol=0.2)
    # Energy: the filled table keeps the model's reflectance (interpolation: 2 %).
    model, _, kw = models.model_parameters(spec)
    rho_m = model.directional_hemispherical_reflectance([20.0, 40.0, 60.0], wl, **kw)
    np.testing.assert_allclose(
        E.hemispherical_reflectance(filled, [20.0, 40.0, 60.0]), rho_m, rtol=0.02
    )
    with pytest.raises(ValidationError, match="below_noise"):
        M.build_lut(meas, below_noise="floor")


def test_build_lut_warns_where_a_table_creates_energy():
    # A measured floor of 0.5 sr-1 everywhere: reflectance pi * 0.5 > 1 at every angle.
    wl = np.array([500.0, 600.0])
    meas = testing.make_measurements(n_wavelength=2)
    meas["measured_sbrdf"].values[:] = 0.5
    meas["reference"].values[:] = False
    with pytest.warns(NonPhysicalWarning, match=r"does not conserve energy.*theta_i = \[0.0"):
        M.build_lut(meas)
    del wl


# ---------------------------------------------------------- simple materials


@pytest.mark.parametrize("method", ["nearest", "linear", "cubic"])
def test_lambertian_material_is_exact_everywhere(method):
    wl = np.array([400.0, 550.0, 700.0])
    rng = np.random.default_rng(3)
    s = rng.standard_normal((4000, 3))
    o = rng.standard_normal((4000, 3))
    s[:, 2], o[:, 2] = np.abs(s[:, 2]), np.abs(o[:, 2])
    from sbrdf_xr import geometry

    a = geometry.facet_angles(np.array([0.0, 0.0, 1.0]), s, o)
    for albedo in (0.3, np.array([0.1, 0.5, 0.9])):
        lam = M.lambertian(albedo, wl)
        got = M.lookup(lam, a.theta_i, a.delta_theta, a.phi, method=method).values
        np.testing.assert_allclose(
            got, np.broadcast_to(np.asarray(albedo) / np.pi, got.shape), rtol=1e-12
        )
        rho = E.hemispherical_reflectance(lam, [0.0, 45.0, 89.0])
        # Gauss-Legendre on the constant integrand: ~1e-13
        np.testing.assert_allclose(rho, np.broadcast_to(albedo, rho.shape), rtol=1e-10)
    const = M.constant_material([0.1, 0.2, 0.3], wl, material="c")
    np.testing.assert_allclose(
        M.lookup(const, 89.9, -179.0, 89.9, method=method), [0.1, 0.2, 0.3], rtol=1e-12
    )
    with pytest.raises(ValidationError, match="rho"):
        M.lambertian(1.5, wl)
    with pytest.raises(ValidationError, match="value: expected"):
        M.constant_material([0.1, 0.2], wl, material="c")


# ----------------------------------------------------------- normal incidence


def _sun_azimuth_spread(table, theta_r, obs_az, dtype, ti_deg=1e-6, n_az=48):
    from sbrdf_xr import geometry

    ti = np.radians(ti_deg)
    th = np.radians(theta_r)
    o = np.array(
        [np.sin(th) * np.cos(obs_az), np.sin(th) * np.sin(obs_az), np.cos(th)], dtype=dtype
    )
    az = np.linspace(0.0, 2 * np.pi, n_az, endpoint=False)
    s = np.stack([np.sin(ti) * np.cos(az), np.sin(ti) * np.sin(az), np.full(n_az, np.cos(ti))], -1)
    a = geometry.facet_angles(np.array([0, 0, 1], dtype=dtype), s.astype(dtype), o[None, :])
    v = M.lookup(table, a.theta_i, a.delta_theta, a.phi).values.astype(np.float64)
    # Relative to the local value, but not below 1e-4 of the normal-incidence row's peak:
    # near a zero of the profile (the "-paper" aluminium is 0 at the exact specular point
    # of theta_i = 0) a continuous look-up varies by ~2 theta_i / theta_r of a value that
    # is itself ~0, which is no jump; a jump of 1e-3 of anything above that floor is caught.
    floor = 1e-4 * np.asarray(table.isel(theta_i=0).max(("delta_theta", "phi")), dtype=float)
    ref = np.maximum(v.max(axis=0), floor)
    ok = ref > 1e-9
    return float(np.max((v.max(axis=0) - v.min(axis=0))[ok] / ref[ok])) if ok.any() else 0.0


@settings(max_examples=examples(25), deadline=None)
@given(
    theta_r=st.floats(0.0, 85.0),
    obs_az=st.floats(0.0, 2 * np.pi),
    dtype=st.sampled_from([np.float64, np.float32]),
)
def test_normal_incidence_lookup_does_not_depend_on_the_sun_azimuth(
    meas_symmetric, theta_r, obs_az, dtype
):
    # theta_i = 1e-6 deg: the look-up is the theta_i = 0 row's profile at the observer's
    # polar angle (weight 1 - 3e-13), the same for every Sun azimuth.  float32 angles
    # carry ~1e-7 relative rounding; the bounds are the 0.1 % and 0.5 %.
    spread = _sun_azimuth_spread(meas_symmetric, theta_r, obs_az, dtype)
    assert spread <= (1e-3 if dtype == np.float64 else 5e-3)


def test_normal_incidence_of_the_paper_construction_does_depend_on_the_sun_azimuth(meas):
    lut = M.build_lut(meas, normal_incidence="paper")
    assert max(_sun_azimuth_spread(lut, tr, 0.3, np.float64) for tr in (5.0, 15.0, 30.0)) > 0.01


def test_normal_incidence_row_is_the_azimuthal_average(meas_symmetric):
    lut = meas_symmetric
    assert (
        lut.attrs["normal_incidence"] == "symmetric" and lut.attrs["normal_incidence_blend"] == 5.0
    )
    row = lut.isel(theta_i=0)
    # A function of theta_r only: equal at (dt, 0) and (0, phi) for the same theta_r
    # where both are nodes of the symmetric part (linear interpolation of that function
    # along the contour: ~1 % on this grid).
    tr = float(lut.phi[4])
    a = M.lookup(lut, 0.0, tr, 0.0).values
    b = M.lookup(lut, 0.0, 0.0, tr).values
    np.testing.assert_allclose(a, b, rtol=1e-12)
    assert np.all(np.isfinite(row.values))


SHIPPED = [
    "aluminium-6061-t6",
    "tjpv-cell",
    "white-paint-a276",
    "aluminium-6061-t6-paper",
    "tjpv-cell-paper",
    "white-paint-a276-paper",
    "example-lobe",
    "lambertian-grey-50",
]


@pytest.mark.parametrize("name", SHIPPED)
@settings(max_examples=examples(10), deadline=None)
@given(
    theta_r=st.floats(0.0, 85.0),
    obs_az=st.floats(0.0, 2 * np.pi),
    dtype=st.sampled_from([np.float64, np.float32]),
)
# found by the deep profile: the observer 1e-6 deg from the normal, beside the zero of
# the "-paper" aluminium at the specular point (old relative spread 2 %, of a 6e-8 value)
@example(theta_r=1e-06, obs_az=0.0, dtype=np.float64)
def test_shipped_tables_do_not_jump_at_normal_incidence(name, theta_r, obs_az, dtype):
    from sbrdf_xr import catalog

    table = catalog.load(name)
    # A jump is a discontinuity. A continuous look-up still varies with the Sun's azimuth
    # because the specular direction moves by 2 theta_i: with the observer within 0.002 deg
    # of a peaked normal-incidence profile (the "-paper" aluminium, slope ~500/deg relative)
    # that is 0.1 % at theta_i = 1e-6 deg. In float64, theta_i = 1e-8 deg shrinks that
    # physical part 100-fold and leaves any jump as it is; float32 cannot resolve
    # 1e-8 deg (it rounds to normal incidence), so it keeps 1e-6 deg and its 0.5 % bound.
    ti_deg = 1e-8 if dtype == np.float64 else 1e-6
    spread = _sun_azimuth_spread(table, theta_r, obs_az, dtype, ti_deg=ti_deg)
    assert spread <= (1e-3 if dtype == np.float64 else 5e-3)


# ------------------------------------------------------------- anisotropic construction


def _rotated_sets(spec, rotations, theta_i=(10.0, 25.0, 40.0, 55.0, 70.0)):
    from sbrdf_xr.materials import goniometer
    from sbrdf_xr.materials import models as _models

    sets = []
    for rot in rotations:
        wl = spec.wavelength.values
        m = goniometer.measure(_models.spectrum_function(spec, psi=rot), wl, theta_i)
        m.attrs["sample_rotation"] = float(rot)
        sets.append(m)
    return sets


def test_anisotropic_table_from_sample_rotations():
    """Virtual measurements of a brushed metal at 6 rotations, against the model."""
    from sbrdf_xr.materials import models as _models

    wl = np.array([450.0, 650.0, 900.0])
    spec = _models.model_material(
        "anisotropic_microfacet",
        wl,
        material="brushed",
        provenance="test",
        alpha_x=0.15,
        alpha_y=0.4,
        n=[1.2, 1.5, 2.0],
        k=[6.0, 7.5, 8.5],
        rho_d=0.01,
    )
    rotations = np.array([90.0, 0.0, 150.0, 30.0, 240.0, 120.0])  # 240 is 60 (t ~ -t)
    sets = _rotated_sets(spec, rotations)
    # the paper's construction extrapolates below the smallest measured theta_i (10 deg)
    # and overshoots there; its energy is not what this test is about
    kw = {"check_energy": False}
    table = M.build_lut_anisotropic(sets, **kw)
    assert table.dims == ("theta_i", "delta_theta", "phi", "psi", "wavelength")
    np.testing.assert_array_equal(table.psi, [0.0, 30.0, 60.0, 90.0, 120.0, 150.0])
    assert "6 sample rotations" in table.attrs["provenance"]
    rng = np.random.default_rng(0)
    n = 3000
    ti, dt, ph = rng.uniform(10, 70, n), rng.uniform(-30, 30, n), rng.uniform(0, 30, n)
    k = rng.integers(0, 6, n)
    at_nodes = table.psi.values[k]
    got = M.lookup_anisotropic(table, ti, dt, ph, at_nodes)
    truth = _models.spectra(spec, ti, dt, ph, psi=at_nodes)
    # the isotropic table each set gives (build_lut), at its own rotation
    iso = np.empty_like(got)
    for j, rot in enumerate(np.mod(rotations, 180.0)):
        sel = at_nodes == rot
        t = M.build_lut(sets[j], normal_incidence="paper", **kw)
        iso[sel] = M.lookup(t, ti[sel], dt[sel], ph[sel]).values
    big = truth > 0.05 * truth.max(axis=0)  # inside the lobes

    def median_error(x, y):
        return float(np.median(np.abs(x - y)[big] / truth[big]))

    # resampling onto the common grids adds little to the construction's own error
    # (measured: 16.5% against 16.3% median, the error of the paper's construction of
    # a lobe sampled at 21 geometries per incidence angle; table against the isotropic
    # builds 2e-16 median)
    e_iso, e_table = median_error(iso, truth), median_error(got, truth)
    assert e_table < 1.15 * e_iso and median_error(got, iso) < 0.05, (e_iso, e_table)
    # between the rotations (30 deg apart), linear in psi: measured 17.6% median
    ps = rng.uniform(0.0, 180.0, n)
    between = M.lookup_anisotropic(table, ti, dt, ph, ps)
    truth_b = _models.spectra(spec, ti, dt, ph, psi=ps)
    big_b = truth_b > 0.05 * truth_b.max(axis=0)
    e_between = float(np.median(np.abs(between - truth_b)[big_b] / truth_b[big_b]))
    assert e_between < 1.3 * e_table, (e_between, e_table)
    # ... and the table is anisotropic as the model is: along vs across the brushing
    along = M.lookup_anisotropic(table, 40.0, 15.0, 0.0, 0.0)
    across = M.lookup_anisotropic(table, 40.0, 15.0, 0.0, 90.0)
    m_along = _models.spectra(spec, 40.0, 15.0, 0.0, psi=0.0)
    m_across = _models.spectra(spec, 40.0, 15.0, 0.0, psi=90.0)
    assert np.all(np.sign(along - across) == np.sign(m_along - m_across))


def test_anisotropic_construction_rejects_bad_rotations():
    from sbrdf_xr.materials import models as _models

    wl = np.array([500.0])
    spec = _models.model_material(
        "anisotropic_microfacet",
        wl,
        material="b",
        provenance="t",
        alpha_x=0.2,
        alpha_y=0.4,
        n=1.2,
        k=6.0,
        rho_d=0.01,
    )
    sets = _rotated_sets(spec, [0.0, 180.0], theta_i=(20.0, 50.0))
    with pytest.raises(ValidationError, match="differ modulo 180"):
        M.build_lut_anisotropic(sets)
    with pytest.raises(ValidationError, match="two or more"):
        M.build_lut_anisotropic(sets[:1])
    del sets[1].attrs["sample_rotation"]
    with pytest.raises(ValidationError, match="sample_rotation"):
        M.build_lut_anisotropic(sets)


# ------------------------------------------------- energy of the shipped tables

#: Incidence angles of the energy check [degree].
ENERGY_THETA_I = np.array([0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 85.0])
#: The catalog's tables that must keep their generating model's energy, with that model.
#: The "-paper" tables are the paper's construction alone (zero below the noise, cubic
#: extrapolation), kept for comparison with the paper, and example-lobe is a
#: non-physical test lobe built with build_lut's (paper) defaults: neither claims to.
ENERGY_TABLES = {
    "aluminium-6061-t6": "aluminium-6061-t6-model",
    "white-paint-a276": "white-paint-a276-model",
    "lambertian-grey-50": None,
    "tjpv-cell": "tjpv-cell-model",
}


@pytest.mark.parametrize("name", sorted(ENERGY_TABLES))
def test_shipped_tables_keep_their_generating_models_energy(name):
    """Directional-hemispherical reflectance of every shipped table within 3 % of its
    generating model's at every theta_i 0-85 deg and wavelength, and at most 1 on every
    row.  The table's reflectance is the package's quadrature of its interpolant (exact
    to ~1e-12 for the multilinear look-up); the model's is the model's own half-vector
    quadrature, checked here against a direct quadrature of the model function
    (testing.reference_reflectance) on a subset of wavelengths to 1e-4 (they agree to
    ~1e-5: so the 3 % is the table's error alone, the bound the construction is held to)."""
    from sbrdf_xr import catalog
    from sbrdf_xr.materials import models

    table = catalog.load(name)
    wl = table.wavelength.values
    rho_t = E.hemispherical_reflectance(table, ENERGY_THETA_I).values
    if ENERGY_TABLES[name] is None:  # a Lambertian table: rho is its albedo, 0.5
        rho_m = np.full_like(rho_t, 0.5)
    else:
        spec = catalog.load(ENERGY_TABLES[name])
        mod, _, kw = models.model_parameters(spec)
        rho_m = mod.directional_hemispherical_reflectance(ENERGY_THETA_I, wl, **kw)
        sub = slice(0, None, 35)
        direct = testing.reference_reflectance(
            models.spectrum_function(spec.isel(wavelength=sub)), ENERGY_THETA_I, fine=0.2, order=6
        )
        np.testing.assert_allclose(direct, rho_m[:, sub], rtol=1e-4)
    rel = np.abs(rho_t / rho_m - 1.0)
    worst = np.unravel_index(np.argmax(rel), rel.shape)
    assert rel.max() <= 0.03, (
        f"{name}: reflectance off its model's by {rel[worst]:.3f} at theta_i = "
        f"{ENERGY_THETA_I[worst[0]]} deg, {wl[worst[1]]} nm"
    )
    assert float(E.hemispherical_reflectance(table).max()) <= 1.0  # every row, 0-90 deg
