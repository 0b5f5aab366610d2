"""Measured BRDFs as laboratories deliver them: angle grouping, in-plane and scattered
data, the self-check, the readers and the ``material build`` command."""

from __future__ import annotations

import functools
import warnings

import numpy as np
import pytest
import xarray as xr
from hypothesis import given
from hypothesis import strategies as st

from sbrdf_xr import catalog
from sbrdf_xr.cli import main
from sbrdf_xr.errors import NonPhysicalWarning, UnitError, ValidationError
from sbrdf_xr.geometry import from_conventional
from sbrdf_xr.materials import (
    build_lut,
    constant_material,
    lookup,
    models,
    open_material,
    read_measurements,
)
from sbrdf_xr.materials.coverage import (
    ANGLE_TOL,
    scan_layout,
    snap_angles,
    specular_distance,
)
from sbrdf_xr.materials.readers import measurement_set
from sbrdf_xr.materials.selfcheck import _holdout_check, _self_check, sample_errors

WL = np.array([450.0, 550.0, 650.0])
#: Lambert 0.3 plus a lobe: the Robertson-Sandford model (paper 001) with rho_D = 0.3.
LOBE = dict(rho_D=0.3, epsilon=0.1, b=0.1, e=0.3)
#: Synthetic sets with the model known reproduce held-out samples to this median
#: relative error (the issue's bound); the table's grid interpolation is the rest.
SYNTHETIC_MEDIAN = 0.02


def _spec():
    return models.model_material(
        "robertson_sandford", WL, material="lobe", provenance="test", **LOBE
    )


def _conventional_set():
    """The issue's goniometer set: a long table in conventional angles, converted."""
    ti, tr, pr = np.meshgrid(
        [20.0, 40.0, 60.0], np.arange(0.0, 81.0, 5.0), np.arange(0.0, 181.0, 15.0), indexing="ij"
    )
    ti, tr, pr = ti.ravel(), tr.ravel(), pr.ravel()
    keep = ~((tr == 0.0) & (pr > 0.0))  # the normal once
    a, d, p = from_conventional(ti[keep], 0.0, tr[keep], pr[keep])
    return a, d, p, models.spectra(_spec(), a, d, p)


def _errors(table, a, d, p, vals):
    got = lookup(
        table, xr.DataArray(a, dims="s"), xr.DataArray(d, dims="s"), xr.DataArray(p, dims="s")
    )
    return np.abs(got.values - vals) / vals


def test_float_noisy_conventional_angles_no_longer_give_a_table_of_zeros():
    a, d, p, vals = _conventional_set()
    # float noise: equal angles are unequal floats
    assert np.unique(d).size > np.unique(np.round(d, 6)).size
    ds = measurement_set(a, d, p, WL, vals, material="lobe", provenance="test")
    table = build_lut(ds, model=_spec())
    assert table.attrs["layout"].startswith("scattered at theta_i = 20, 40, 60")
    assert "model" in table.attrs["modelled"]
    # the look-up: [0, 0, 0] before; now within the grid's interpolation error
    here = lookup(table, 40.0, -4.0, 6.0).values
    truth = models.spectra(_spec(), 40.0, -4.0, 6.0)
    np.testing.assert_allclose(here, truth, rtol=0.05)
    err = _errors(table, a, d, p, vals)
    assert np.median(err) < SYNTHETIC_MEDIAN
    assert table.attrs["self_check_median"] < SYNTHETIC_MEDIAN


def test_held_out_samples_of_the_conventional_set_with_a_fitted_model():
    a, d, p, vals = _conventional_set()
    hold = np.arange(a.size) % 4 == 0
    ds = measurement_set(a[~hold], d[~hold], p[~hold], WL, vals[~hold], material="lobe",
                         provenance="test")  # fmt: skip
    table = build_lut(ds)  # a Robertson-Sandford fit fills between the samples
    err = _errors(table, a[hold], d[hold], p[hold], vals[hold])
    assert np.median(err) < SYNTHETIC_MEDIAN


@given(st.lists(st.floats(-170.0, 170.0), min_size=1, max_size=20), st.floats(0.0, 1e-9))
def test_snap_merges_float_noise_and_keeps_distinct_angles(base, noise):
    x = np.repeat(np.round(np.asarray(base), 3), 2)
    x[1::2] += noise  # noise far below the tolerance
    s = snap_angles(x)
    assert np.unique(s).size == np.unique(np.round(np.asarray(base), 3)).size
    assert np.max(np.abs(s - x)) <= ANGLE_TOL


def test_scan_layouts_and_the_distance_from_specular():
    assert scan_layout([-5.0, 0.0, 5.0], [0.0, 0.0, 0.0]) == "in-plane"
    # cos(gamma) = cos(phi) cos(delta_theta): the angle to the mirror direction
    g = specular_distance(np.array([3.0, -3.0, 0.0]), np.array([4.0, 4.0, 0.0]))
    want = np.degrees(np.arccos(np.cos(np.radians(4.0)) * np.cos(np.radians(3.0))))
    np.testing.assert_allclose(g, [want, -want, 0.0], rtol=1e-12, atol=1e-12)


def _in_plane(ti=(10.0, 30.0, 50.0, 70.0)):
    t, s = np.meshgrid(np.asarray(ti), np.arange(-85.0, 86.0, 1.0), indexing="ij")
    t, s = t.ravel(), s.ravel()
    ok = np.abs(s) < 89.0
    t, s = t[ok], s[ok]
    d = s - t
    return t, d, models.spectra(_spec(), t, d, 0.0)


def test_an_in_plane_scan_gives_an_isotropic_table_filled_by_the_fit():
    t, d, vals = _in_plane()
    hold = np.arange(t.size) % 4 == 0
    ds = measurement_set(t[~hold], d[~hold], np.zeros((~hold).sum()), WL, vals[~hold],
                         material="scan", provenance="test")  # fmt: skip
    table = build_lut(ds)
    assert table.attrs["layout"] == "in-plane at theta_i = 10, 30, 50, 70 deg"
    assert "phi > 0" in table.attrs["modelled"]
    assert "phi > 0" in table.attrs["provenance"]  # shown by print(table)
    assert table.attrs["self_check_worst"] < 1e-9  # the scan's own nodes
    assert table.attrs["holdout_check_median"] < SYNTHETIC_MEDIAN  # its own leave-out check
    held = _errors(table, t[hold], d[hold], np.zeros(hold.sum()), vals[hold])
    assert np.median(held) < SYNTHETIC_MEDIAN
    # out of the plane: the fitted model (the generating one, recovered)
    rng = np.random.default_rng(0)
    q = (rng.uniform(10, 70, 200), rng.uniform(-30, 15, 200), rng.uniform(1, 30, 200))
    truth = models.spectra(_spec(), *q)
    out = _errors(table, *q, truth)
    assert np.median(out) < 0.05  # linear look-up between grid nodes of a lobe


def test_in_plane_data_with_the_papers_zero_policy_is_a_clear_error():
    t, d, vals = _in_plane((20.0, 50.0))
    ds = measurement_set(t, d, np.zeros(t.size), WL, vals, material="scan", provenance="t")
    with pytest.raises(ValidationError, match="no sample out of the plane of incidence"):
        build_lut(ds, below_noise="zero")


def test_the_self_check_raises_on_a_table_of_zeros_and_warns_on_a_wrong_one():
    ti, dt, ph = np.array([30.0, 30.0]), np.array([0.0, 5.0]), np.zeros(2)
    spectra = np.array([[0.2], [0.1]])
    ds = xr.Dataset(attrs={"material": "m"})
    zero = constant_material(0.0, [550.0], material="zero")
    with pytest.raises(ValidationError, match="is zero at 2 of the 2 sample values"):
        _self_check(zero, ds, (ti, dt, ph), spectra, np.zeros(2, bool))
    big = constant_material(1.0, [550.0], material="big")
    with pytest.warns(NonPhysicalWarning, match=r"misses its own samples.*worst at"):
        out = _self_check(big, ds, (ti, dt, ph), spectra, np.zeros(2, bool))
    assert out["self_check_median"] == pytest.approx(6.5)  # (0.8/0.2 + 0.9/0.1) / 2
    _, _, used = sample_errors(big, ti, dt, ph, spectra, floor=0.6)
    assert used[:, 0].tolist() == [True, False]  # 0.1 < 0.6 of the peak 0.2


# ------------------------------------------------------------------ readers


def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return p


STARLINK_LIKE = """# (phi_i, theta_i) are the zenith and azimuth angles
# of ingoing light; and is at a wavelength lambda = 532 nm
#
# phi_i     theta_i     phi_o     theta_o     brdf
30.00     -180.00     -10.00     0.00     1.0e-02
30.00     -180.00     30.00     0.00     5.3e+04
30.00     -180.00     50.00     0.00     2.0e-02
"""


def test_a_long_table_with_the_zenith_and_wavelength_in_its_header(tmp_path):
    p = _write(tmp_path, "scan.csv", STARLINK_LIKE)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the near-mirror peak is not "other units"
        ds = read_measurements(p)
    np.testing.assert_allclose(ds.delta_theta.values, [-40.0, 0.0, 20.0], atol=1e-9)
    np.testing.assert_allclose(ds.phi.values, 0.0, atol=1e-9)
    assert ds.wavelength.values.tolist() == [532.0]
    assert "phi the zenith" in ds.attrs["provenance"]


def test_readers_round_trip_csv_ecsv_netcdf_and_per_wavelength(tmp_path):
    from astropy.table import Table

    a, d, p, vals = _conventional_set()
    rng = np.random.default_rng(1)
    idx = rng.choice(a.size, 40, replace=False)
    rows = ["theta_i,delta_theta,phi,wavelength,brdf [sr-1]"]
    for k in idx:
        for j, w in enumerate(WL):
            rows.append(",".join(repr(float(x)) for x in (a[k], d[k], p[k], w, vals[k, j])))
    long = read_measurements(_write(tmp_path, "long.csv", "\n".join(rows) + "\n"))
    assert dict(long.sizes) == {"sample": 40, "wavelength": 3}
    t = Table({"theta_i": a[idx], "delta_theta": d[idx], "phi": p[idx], "brdf": vals[idx, 0]})
    t["brdf"].unit = "1/sr"
    t.write(tmp_path / "t.ecsv")
    ecsv = read_measurements(tmp_path / "t.ecsv", wavelength=550.0)
    xr.Dataset({k: ("row", v) for k, v in
                (("theta_i", a[idx]), ("delta_theta", d[idx]), ("phi", p[idx]),
                 ("brdf", vals[idx, 0]))}).to_netcdf(tmp_path / "t.nc")  # fmt: skip
    nc = read_measurements(tmp_path / "t.nc", wavelength=550.0)
    for ds in (ecsv, nc):
        order = np.lexsort((ds.phi.values, ds.delta_theta.values, ds.theta_i.values))
        ref = np.lexsort((long.phi.values, long.delta_theta.values, long.theta_i.values))
        np.testing.assert_allclose(
            ds.measured_sbrdf.values[order, 0], long.measured_sbrdf.values[ref, 0], rtol=1e-15
        )
    # a measurement-set netCDF reads as it is
    from sbrdf_xr.materials.files import to_netcdf

    to_netcdf(long, tmp_path / "set.nc")
    xr.testing.assert_equal(read_measurements(tmp_path / "set.nc"), long)


@pytest.mark.parametrize(
    ("text", "kw", "match", "error"),
    [
        ("theta_i,theta_s,brdf\n30,0,nan\n", {}, "NaN or infinite", ValidationError),
        ("theta_i,theta_s,brdf\n30,0,-1\n", {}, "negative", ValidationError),
        ("theta_i,brdf\n30,1\n", {}, "lacks the signed scattering angle", ValidationError),
        ("theta_i,theta_s,brdf\n95,0,1\n", {}, "row 1 has 95.0 degree", ValidationError),
        ("theta_i,theta_s,brdf\n30,0,1\n30,0,2\n", {}, "repeat 1 geometry", ValidationError),
        ("theta_i,theta_s,brdf\n", {}, "no data rows", ValidationError),
        ("theta_i,theta_s,brdf [m]\n30,0,1\n", {}, "not a BRDF unit", UnitError),
        (
            "theta_i,theta_s,brdf [sr-1]\n30,0,1\n",
            {"units": "1/deg2"},
            "states the unit",
            UnitError,
        ),
    ],
)
def test_bad_scans_are_named_errors(tmp_path, text, kw, match, error):
    p = _write(tmp_path, "bad.csv", text)
    with pytest.raises(error, match=match):
        read_measurements(p, format="scan", wavelength=532.0, **kw)


def test_unknown_formats_and_missing_wavelengths_are_named(tmp_path):
    with pytest.raises(ValidationError, match=r"no reader for suffix '\.xyz'"):
        read_measurements(_write(tmp_path, "a.xyz", "1"))
    with pytest.raises(ValidationError, match="format: got 'nope'"):
        read_measurements(_write(tmp_path, "a.csv", "1"), format="nope")
    p = _write(tmp_path, "nowl.csv", "theta_i,phi_i,theta_r,phi_r,brdf\n30,0,30,180,1\n")
    with pytest.raises(ValidationError, match="pass wavelength="):
        read_measurements(p)


# ------------------------------------------------------------------ Starlink and CLI


def test_the_shipped_starlink_scans_read_without_an_other_units_alarm():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for name in ("starlink-v1.5-chassis", "starlink-v1.5-solar-array"):
            ds = catalog.load(f"{name}-measurements")
            assert ds.sizes["sample"] == 724
            assert ds.attrs["material"] == name
    assert float(ds.measured_sbrdf.max()) == pytest.approx(5.33414e4)


def test_material_build_command(tmp_path, capsys):
    t, d, vals = _in_plane((20.0, 50.0))
    rows = ["theta_i,theta_s,brdf"] + [
        f"{a},{a + b},{float(v)!r}" for a, b, v in zip(t, d, vals[:, 1], strict=True)
    ]
    src = _write(tmp_path, "scan.csv", "\n".join(rows) + "\n")
    out = tmp_path / "table.nc"
    assert main(["material", "build", str(src), "-o", str(out), "--format", "scan",
                 "--wavelength", "550"]) == 0  # fmt: skip
    text = capsys.readouterr().out
    assert "measured: in-plane at theta_i = 20, 50 deg" in text
    assert "self-check over" in text
    table = open_material(out)
    assert table.attrs["self_check_worst"] < 1e-9


# ------------------------------------------------------------------ MERL


def _rgb_lobe(s, o):
    """The test lobe at the three channels (red, green, blue) of a MERL file."""
    from sbrdf_xr.geometry import facet_angles

    n = np.zeros_like(s)
    n[:, 2] = 1.0
    a = facet_angles(n, s, o, check=False)
    return models.spectra(_rgb_spec(), a.theta_i, a.delta_theta, a.phi)[:, ::-1]


def _rgb_spec():
    from sbrdf_xr.materials.merl import CHANNEL_WAVELENGTHS

    return models.model_material(
        "robertson_sandford", list(CHANNEL_WAVELENGTHS), material="rgb", provenance="test",
        rho_D=[0.2, 0.3, 0.4], epsilon=0.1, b=0.1, e=0.3,
    )  # fmt: skip


def test_a_merl_file_of_constant_channels_reads_them_exactly(tmp_path):
    from sbrdf_xr.materials.merl import write_merl

    p = write_merl(tmp_path / "c.binary", lambda s, o: np.tile([0.3, 0.2, 0.1], (len(s), 1)))
    with pytest.warns(NonPhysicalWarning, match="unmeasured cells"):  # grazing cells
        ds = read_measurements(p, theta_i=(10.0, 50.0), step=5.0)
    assert "MERL RGB colour channels" in ds.attrs["channels"]
    np.testing.assert_allclose(ds.measured_sbrdf.values, [[0.1, 0.2, 0.3]] * ds.sizes["sample"],
                               rtol=1e-12)  # fmt: skip


@pytest.mark.parametrize(
    ("cut", "match"), [(100, "truncated"), (-8, "trailing bytes"), (None, "declares dimensions")]
)
def test_a_merl_file_of_the_wrong_size_is_a_named_error(tmp_path, cut, match):
    good = 12 + 3 * 90 * 90 * 180 * 8
    if cut is None:
        raw = np.asarray([90, 90, 360], "<i4").tobytes() + bytes(good - 12)
    else:
        raw = np.asarray([90, 90, 180], "<i4").tobytes() + bytes(good - 12 - cut)
    p = tmp_path / "bad.binary"
    p.write_bytes(raw)
    with pytest.raises(ValidationError, match=match):
        read_measurements(p)


@pytest.mark.slow
def test_a_merl_file_of_a_known_model_round_trips_and_builds(tmp_path):
    from sbrdf_xr.materials.merl import write_merl

    p = write_merl(tmp_path / "lobe.binary", _rgb_lobe)
    with pytest.warns(NonPhysicalWarning, match="unmeasured cells"):
        ds = read_measurements(p)
    truth = models.spectra(_rgb_spec(), ds.theta_i.values, ds.delta_theta.values, ds.phi.values)
    err = np.abs(ds.measured_sbrdf.values - truth) / truth
    assert np.median(err) < 1e-3  # bins interpolated linearly between their centres
    hold = np.arange(ds.sizes["sample"]) % 4 == 0
    table = build_lut(ds.isel(sample=np.flatnonzero(~hold)))
    held = _errors(table, ds.theta_i.values[hold], ds.delta_theta.values[hold],
                   ds.phi.values[hold], ds.measured_sbrdf.values[hold])  # fmt: skip
    assert np.median(held) < SYNTHETIC_MEDIAN


@pytest.mark.slow
def test_the_starlink_solar_array_predicts_held_out_samples():
    """Every 4th sample of each scan left out (the build's own leave-out check), over
    the samples above 1e-3 of their scan's peak: the issue's 10 % (measured 1.4 %)."""
    table = build_lut(catalog.load("starlink-v1.5-solar-array-measurements"))
    assert table.attrs["self_check_worst"] < 1e-9
    assert table.attrs["holdout_check_median"] < 0.10


@pytest.mark.slow
def test_the_starlink_chassis_predicts_held_out_samples_with_its_core_and_halo():
    """The shipped chassis (a Robertson-Sandford fill with a Beckmann core that follows
    the incidence angle and a Harvey-Shack ABg halo, fitted together in the logarithm)
    against the same leave-out check.  Its 13 held-out samples above the floor: median
    8.7 %, 95th percentile 38 %, worst 38 % (11.8 %, 60 %, 63 % with the core alone;
    10.7 %, 56 %, 60 % with one constant core fitted in the logarithm; 16.1 %, 75 %,
    76 % with the Robertson-Sandford fill alone).  The halo takes the samples two to
    four degrees from specular (at 75 deg incidence, -2 and +2 deg: 1 % and 9 %, 63 % and
    57 % with the core alone).  The build is deterministic: the bounds leave room for
    the optimiser's rounding across platforms, not for a worse fit."""
    table = catalog.load("starlink-v1.5-chassis")
    assert table.attrs["extrapolation_model"] == "robertson_sandford_halo"
    assert table.attrs["self_check_worst"] < 1e-9
    assert table.attrs["holdout_check_n"] == 13
    assert table.attrs["holdout_check_median"] < 0.09
    assert table.attrs["holdout_check_p95"] < 0.39
    assert table.attrs["holdout_check_worst"] < 0.39


@pytest.mark.slow
def test_the_starlink_chassis_fit_reflects_at_most_one():
    """The fitted model of the chassis (body, core and halo; the halo's fitted power
    3.6) reflects at most one at every incidence angle, by the model's own reflectance
    (its quadratures are checked against independent ones in tests/brdf/test_halo.py)."""
    fit = models.fit_model(
        catalog.load("starlink-v1.5-chassis-measurements"), "robertson-sandford-halo"
    )
    mod, wl, kw = models.model_parameters(fit)
    rho = mod.directional_hemispherical_reflectance(np.arange(0.0, 90.5, 1.0), wl, **kw)
    assert np.all(np.isfinite(rho)) and np.all(rho <= 1.0 + 1e-12)
    assert float(fit.halo_a[0]) > 0.0 and 1.0 < float(fit.halo_g[0]) < 4.0


def _scans(name):
    """A catalog measurement set as the build checks it: snapped angles, the samples
    with reference points zeroed, the reference mask."""
    ds = catalog.load(name)
    angles = tuple(snap_angles(ds[d].values) for d in ("theta_i", "delta_theta", "phi"))
    spectra = ds.measured_sbrdf.transpose("sample", "wavelength").values.copy()
    ref = ds.reference.values.copy()
    spectra[ref] = 0.0
    return ds, angles, spectra, ref


@pytest.mark.slow
def test_the_starlink_chassis_k_fold_leave_out_check():
    """All four folds of the leave-out check (each inner sample of each scan held out
    once, four builds): 54 held-out samples above the floor instead of 13, so one sample
    moves the median by about 1 % instead of several.  Measured: median 11.4 %, 95th
    percentile 141 %, worst 356 %, fold medians 12.9, 7.9, 8.7, 12.8 % (with the core
    alone: 11.7 %, 216 %, 280 %, folds 9.1, 27.6, 11.8, 11.5 %; one constant core
    fitted in the logarithm: 19.3 %, 180 %, 493 %).  Fold 2 is the build's own check,
    to the last bit."""
    ds, angles, spectra, ref = _scans("starlink-v1.5-chassis-measurements")
    build = functools.partial(
        build_lut, model="robertson-sandford-halo", check_energy="clamp", holdout=0
    )
    out = _holdout_check(build, ds, angles, spectra, ref, folds=range(4))
    assert out["holdout_kfold_n"] == 54
    assert out["holdout_kfold_median"] < 0.116
    assert out["holdout_kfold_p95"] < 1.45
    table = catalog.load("starlink-v1.5-chassis")
    assert out["holdout_fold_medians"][2] == table.attrs["holdout_check_median"]


def test_the_core_fit_recovers_a_known_core_from_an_in_plane_scan():
    """A scan of the model itself, 0.5-degree steps: the body is refitted without the
    core's samples until the core's width settles.  Fitting the body once, to every
    sample, returns 0.0048 and 0.26 (the body takes part of the core); the iteration
    brings both within 2 % (what is left is the body's fit, whose own tolerance sets it)."""
    spec = models.model_material(
        "robertson_sandford_core", [532.0], material="glint", provenance="test",
        rho_D=0.05, epsilon=0.5, b=0.05, e=0.04, core_rho=0.4, core_roughness=0.006,
    )  # fmt: skip
    ti, dt = np.meshgrid([5.0, 40.0, 60.0], np.arange(-20.0, 20.5, 0.5), indexing="ij")
    ti, dt = ti.ravel(), dt.ravel()
    scan = measurement_set(ti, dt, np.zeros(ti.size), [532.0],
                           models.spectra(spec, ti, dt, 0.0), material="glint",
                           provenance="test")  # fmt: skip
    fit = models.fit_model(scan, "robertson-sandford-core")
    assert float(fit.core_roughness[0]) == pytest.approx(0.006, rel=0.02)
    assert float(fit.core_rho[0]) == pytest.approx(0.4, rel=0.02)


@pytest.mark.slow
def test_the_halo_fit_follows_a_known_halo_but_does_not_identify_it():
    """A scan of the model with a halo (0.5-degree steps, three incidence angles): the
    fitted model follows the scan to 2.4 % rms in the logarithm, but its parameters are
    not the model's: the body's lobe takes part of the halo (b 0.10 for 0.05) and the
    halo's power goes to its bound 4 (for 2.8).  The fit alternates body and core plus
    halo; a joint fit of all of them would be needed to identify them.  The core is
    recovered (rms slope within 1 %)."""
    spec = models.model_material(
        "robertson_sandford_halo", [532.0], material="glint", provenance="test",
        rho_D=0.05, epsilon=0.5, b=0.05, e=0.04, core_rho=0.4, core_roughness=0.006,
        halo_a=1e-4, halo_b=0.01**2.8, halo_g=2.8,
    )  # fmt: skip
    ti, dt = np.meshgrid([5.0, 40.0, 60.0], np.arange(-20.0, 20.5, 0.5), indexing="ij")
    ti, dt = ti.ravel(), dt.ravel()
    truth = models.spectra(spec, ti, dt, 0.0)
    scan = measurement_set(ti, dt, np.zeros(ti.size), [532.0], truth, material="glint",
                           provenance="test")  # fmt: skip
    fit = models.fit_model(scan, "robertson-sandford-halo")
    assert fit.attrs["rms_log"] < 0.03
    assert float(fit.core_roughness[0]) == pytest.approx(0.006, rel=0.01)
    err = np.abs(np.log(models.spectra(fit, ti, dt, 0.0) / truth))
    assert np.median(err) < 0.03
