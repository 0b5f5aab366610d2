"""compare against a simulated pass: alignment in UTC, zero points, extinction, time shift,
their uncertainties (against scipy's curve_fit), bad input, and the figure."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from sbrdf_xr import lightcurves as L
from sbrdf_xr import photometry as P
from sbrdf_xr.errors import LightCurveError

T0 = np.datetime64("2024-03-17T01:21:00", "ns")
STEP = 0.25  # [s] of the simulated curve


def _truth(secs, band):
    """A smooth pass-like curve [mag]: a slow brightening and a 12 s glint cycle."""
    base = 13.0 - 0.5 * np.tanh((secs - 60.0) / 40.0) + 0.3 * np.sin(2 * np.pi * secs / 12.0)
    return base + {"V": 0.0, "R": -0.45, "I": -0.7}[band]


def _airmass(secs):
    return 2.2 - 1.1 * np.sin(np.pi * secs / 240.0)  # 2.2 -> 1.1 -> 2.2 over 240 s


def _sim(step=STEP, span=240.0, bands=("V", "R", "I"), system="AB"):
    secs = np.arange(0.0, span + step / 2, step)
    t = T0 + (secs * 1e9).astype("timedelta64[ns]")
    m = np.stack([_truth(secs, b) for b in bands], axis=1)
    return xr.DataArray(
        m,
        dims=("time", "band"),
        coords={"time": t, "band": list(bands), "airmass": ("time", _airmass(secs))},
        attrs={"magnitude_system": system, "units": "1"},
        name="magnitude",
    )


def _measured(
    zp, k=None, shift=0.0, sigma=0.02, seed=0, every=2.0, span=(20.0, 220.0), bands=("V", "R")
):
    """Interleaved bands every ``every`` s; truth at t + shift, + ZP + k X + noise."""
    rng = np.random.default_rng(seed)
    secs, band = [], []
    for j, b in enumerate(bands):
        s = np.arange(span[0] + j * every / len(bands), span[1], every)
        secs.append(s)
        band += [b] * s.size
    secs = np.concatenate(secs)
    band = np.array(band)
    x = _airmass(secs + shift)
    mag = np.array([_truth(np.array([s + shift]), b)[0] for s, b in zip(secs, band, strict=True)])
    mag = mag + np.array([zp[b] for b in band])
    if k is not None:
        mag = mag + np.array([k[b] for b in band]) * x
    mag = mag + rng.normal(0.0, sigma, secs.size)
    t = T0 + (secs * 1e9).astype("timedelta64[ns]")
    return xr.Dataset(
        {"magnitude": ("obs", mag), "uncertainty": ("obs", np.full(secs.size, sigma))},
        coords={
            "time": ("obs", t),
            "band": ("obs", band),
            "file_row": ("obs", 1 + np.arange(secs.size)),
        },
        attrs={"magnitude_system": "AB"},
    )


def test_noiseless_zero_points_and_extinction_are_recovered_exactly():
    zp, k = {"V": 0.31, "R": -0.12}, {"V": 0.21, "R": 0.13}
    # measured exactly at simulated nodes (every 2 s on a 0.25 s grid): no interpolation
    fit = L.compare(_measured(zp, k, sigma=1e-4, seed=1), _sim(), extinction="fit")
    # noise of 1e-4 mag over 100 points per band: ZP and k to a few 1e-5
    for b in ("V", "R"):
        assert float(fit.zero_point.sel(band=b)) == pytest.approx(zp[b], abs=2e-4)
        assert float(fit.extinction_coefficient.sel(band=b)) == pytest.approx(k[b], abs=2e-4)
    assert fit.attrs["mode"] == "observation"
    assert "airmass, interpolated" in fit.attrs["airmass_source"]
    assert float(fit.colour_index_difference.sel(colour="V-R")) == pytest.approx(
        zp["V"] - zp["R"], abs=3e-4
    )
    common = L.compare(_measured({"V": 0.2, "R": 0.2}, sigma=1e-4), _sim(), zero_points="common")
    assert float(common.magnitude_offset) == pytest.approx(0.2, abs=1e-4)
    assert common.sizes["parameter"] == 1


def test_given_extinction_coefficients_are_applied_not_fitted():
    zp, k = {"V": 0.3, "R": 0.1}, {"V": 0.2, "R": 0.1}
    meas = _measured(zp, k, sigma=0.001)
    fit = L.compare(meas, _sim(), extinction=k)
    assert float(fit.zero_point.sel(band="V")) == pytest.approx(0.3, abs=5e-4)
    assert fit.sizes["parameter"] == 2 and float(fit.extinction_coefficient_uncertainty[0]) == 0
    naive = L.compare(meas, _sim())
    # without extinction the airmass swing 1.1-2.2 leaves 0.1-0.2 mag trends: chi2 tells
    assert float(naive.reduced_chi_square) > 100 * float(fit.reduced_chi_square)


def test_a_time_shift_is_recovered():
    """Truth at t + 1.7 s; the simulated curve on a 0.25 s grid (interpolation error of the
    12 s glint: 0.3 (2 pi/12)^2 0.25^2 / 8 ~ 6e-4 mag, below the 0.005 mag noise)."""
    meas = _measured({"V": 0.1, "R": 0.1}, shift=1.7, sigma=0.005, seed=3)
    fit = L.compare(meas, _sim(), fit_time_shift=True, max_time_shift=5.0)
    sigma = float(fit.time_shift_uncertainty)
    assert 0.0 < sigma < 0.05
    assert float(fit.time_shift) == pytest.approx(1.7, abs=4 * sigma)
    assert 0.8 < float(fit.reduced_chi_square) < 1.25  # 200 dof: 1 +- 0.1
    assert "time_shift" in fit.parameter.values.tolist()
    assert fit.chi_square_scan.sizes["shift_scan"] == 720
    without = L.compare(meas, _sim())
    assert float(without.reduced_chi_square) > 10.0


def test_the_covariance_is_curve_fits_on_the_same_model():
    """ZP, k per band and the time shift against scipy.optimize.curve_fit (absolute sigma)."""
    from scipy.optimize import curve_fit

    sim = _sim()
    meas = _measured({"V": 0.3, "R": 0.2}, {"V": 0.2, "R": 0.1}, shift=0.8, sigma=0.01, seed=5)
    fit = L.compare(meas, sim, extinction="fit", fit_time_shift=True, max_time_shift=3.0)
    secs_sim = (sim.time.values - T0) / np.timedelta64(1, "s")
    secs = (meas.time.values - T0) / np.timedelta64(1, "s")
    isv = meas.band.values == "V"
    flux = 10 ** (-0.4 * sim.values)

    def model(_, zv, zr, kv, kr, dt):
        f = np.where(
            isv,
            np.interp(secs + dt, secs_sim, flux[:, 0]),
            np.interp(secs + dt, secs_sim, flux[:, 1]),
        )
        x = np.interp(secs + dt, secs_sim, sim.airmass.values)
        return -2.5 * np.log10(f) + np.where(isv, zv + kv * x, zr + kr * x)

    pars, pcov = curve_fit(
        model,
        secs,
        meas.magnitude.values,
        p0=(0.3, 0.2, 0.2, 0.1, 0.8),
        sigma=meas.uncertainty.values,
        absolute_sigma=True,
    )
    names = ["ZP_V", "ZP_R", "k_V", "k_R", "time_shift"]
    est = fit.estimate.sel(parameter=names).values
    sd = fit.standard_error.sel(parameter=names).values
    # the same optimum: to a small fraction of each uncertainty
    assert np.all(np.abs(est - pars) < 0.02 * np.sqrt(np.diag(pcov)))
    # compare's derivative in time spans half a 0.25 s node, curve_fit's a tiny step within
    # one linear piece: the time-shift sigma agrees to a few per cent, the others closer
    np.testing.assert_allclose(sd[:4], np.sqrt(np.diag(pcov))[:4], rtol=0.01)
    np.testing.assert_allclose(sd[4], np.sqrt(pcov[4, 4]), rtol=0.05)


def test_measured_times_outside_the_window_are_refused():
    sim = _sim(span=100.0)
    meas = _measured({"V": 0.0, "R": 0.0})  # 20-220 s
    with pytest.raises(
        LightCurveError,
        match=r"observation\(s\) outside the simulated window "
        r"2024-03-17T01:21:00.000 .. 2024-03-17T01:22:40.000 UTC, first at "
        r"2024-03-17T01:22:42.000 UTC \(row 42\)",
    ):
        L.compare(meas, sim)
    late = meas.assign_coords(time=meas.time + np.timedelta64(3600, "s"))
    with pytest.raises(LightCurveError, match="no overlap: the measured times"):
        L.compare(late, sim)
    full = _measured({"V": 0.0, "R": 0.0}, span=(0.0, 241.0))  # 0 s to 240 s: all of it
    with pytest.raises(LightCurveError, match="leave no room for a shift of up to 10 s"):
        L.compare(full, _sim(), fit_time_shift=True)


def test_bands_not_simulated_and_other_bad_input():
    sim = _sim(bands=("V", "I"))
    meas = _measured({"V": 0.0, "R": 0.0})
    with pytest.raises(
        LightCurveError,
        match=r"the measured bands \['R'\] are not simulated "
        r"\(simulated bands: \['V', 'I'\]\)",
    ):
        L.compare(meas, sim)
    bad = meas.copy(deep=True)
    bad["magnitude"].values[4] = np.nan
    with pytest.raises(
        LightCurveError,
        match=r"observation 4 \(row 5\) has magnitude nan, which "
        r"is not a finite number \(a NaN row\)",
    ):
        L.compare(bad, _sim())
    neg = meas.copy(deep=True)
    neg["uncertainty"].values[2] = -0.01
    with pytest.raises(LightCurveError, match=r"has uncertainty -0\.01, which is negative"):
        L.compare(neg, _sim())
    secs = meas.assign_coords(time=("obs", np.arange(meas.sizes["obs"], dtype=float)))
    with pytest.raises(LightCurveError, match="numbers of seconds without an origin"):
        L.compare(secs, _sim())
    with pytest.raises(LightCurveError, match="in the AB system but the simulation is in Vega"):
        L.compare(meas, _sim(system="Vega"))
    for kw, msg in (
        ({"zero_points": "each"}, "zero_points: got 'each'"),
        ({"extinction": 0.2}, "extinction: expected None, 'fit' or a mapping"),
        ({"airmass": "table"}, "airmass: got 'table'"),
        ({"max_time_shift": -1.0}, "max_time_shift: must be > 0 s"),
    ):
        with pytest.raises(LightCurveError, match=msg):
            L.compare(meas, _sim(), **kw)


def test_nothing_is_fitted_to_fewer_samples_than_parameters():
    meas = _measured({"V": 0.0, "R": 0.0})
    first_r = int(np.flatnonzero(meas.band.values == "R")[0])
    two = meas.isel(obs=[0, first_r])  # V and R once each
    with pytest.raises(
        LightCurveError,
        match=r"2 observation\(s\) .* fitting 2 parameter\(s\) "
        r"\(a zero point per band\) needs at least 3",
    ):
        L.compare(two, _sim())
    assert int(L.compare(meas.isel(obs=[0, 1, first_r]), _sim()).degrees_of_freedom) == 1
    v3 = meas.isel(obs=np.flatnonzero(meas.band.values == "V")[:3])
    with pytest.raises(LightCurveError, match=r"3 observation\(s\) .* fitting 3 parameter"):
        L.compare(v3, _sim(), extinction="fit", fit_time_shift=True)
    flat = meas.isel(
        obs=np.flatnonzero(meas.band.values == "V")[:1].tolist()
        + np.flatnonzero(meas.band.values == "R")[:40].tolist()
    )
    with pytest.raises(
        LightCurveError,
        match=r"band 'V' has 1 observation\(s\) for its 2 "
        "parameters",
    ):
        L.compare(flat, _sim(), extinction="fit")
    short = meas.isel(obs=slice(0, 4))  # 6 s of a 240 s airmass swing: X nearly constant
    sim = _sim().assign_coords(airmass=("time", np.full(_sim().sizes["time"], 1.3)))
    with pytest.raises(
        LightCurveError,
        match=r"in band 'V' the air mass spans only "
        r"1.3000-1.3000: k and the zero point cannot be told apart",
    ):
        L.compare(short, sim, extinction="fit")


def test_observations_where_the_model_is_dark_are_excluded_and_listed():
    sim = _sim()
    dark = sim.copy(
        data=np.where((sim.time.values < T0 + np.timedelta64(30, "s"))[:, None], np.inf, sim.values)
    )
    fit = L.compare(_measured({"V": 0.1, "R": 0.1}, sigma=0.001), dark)
    n = int(fit.n_excluded)
    assert n == 10 and int(fit.excluded.sum()) == n  # 20-30 s, every 2 s, two bands
    assert fit.attrs["excluded_rows"].split()[:2] == ["1", "2"]
    assert np.isnan(fit.residual.values[fit.excluded.values]).all()
    assert float(fit.zero_point.sel(band="V")) == pytest.approx(0.1, abs=1e-3)


def test_a_cube_is_compared_in_the_measured_bands_and_system(tmp_path):
    """A grey cube over time: its magnitudes in the measured bands are computed inside."""
    secs = np.arange(0.0, 241.0, 1.0)
    t = T0 + (secs * 1e9).astype("timedelta64[ns]")
    wl = np.arange(300.0, 1101.0, 10.0)
    c = 1e-5 * (1.0 + 0.2 * np.sin(secs / 10.0))
    cube = xr.Dataset(
        {
            "signal": (
                ("time", "wavelength"),
                np.repeat(c[:, None], wl.size, 1),
                {"units": "m2 sr-1"},
            )
        },
        coords={
            "time": t,
            "wavelength": ("wavelength", wl, {"units": "nm"}),
            "range": ("time", np.full(secs.size, 1000.0), {"units": "km"}),
        },
    )
    mags = P.magnitudes(cube, ["V", "R"], system="Vega")
    k = np.arange(10, 230, 5)
    meas = xr.Dataset(
        {
            "magnitude": ("obs", np.r_[mags.values[k, 0], mags.values[k, 1]] + 0.05),
            "uncertainty": ("obs", np.full(2 * k.size, 0.01)),
        },
        coords={
            "time": ("obs", np.r_[t[k], t[k]]),
            "band": ("obs", ["V"] * k.size + ["R"] * k.size),
        },
        attrs={"magnitude_system": "Vega"},
    )
    fit = L.compare(meas, cube)
    np.testing.assert_allclose(fit.zero_point.values, 0.05, atol=1e-9)
    assert fit.attrs["magnitude_system"] == "Vega"


def test_plot_comparison_of_a_pass(tmp_path):
    from matplotlib.figure import Figure

    meas = _measured({"V": 0.3, "R": 0.1}, {"V": 0.2, "R": 0.1}, shift=1.2, sigma=0.02)
    fit = L.compare(meas, _sim(), extinction="fit", fit_time_shift=True)
    fig = L.plot_comparison(fit)
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    text = fig.axes[0].texts[0].get_text()
    assert "AB magnitudes" in text and "ZP V = " in text and "time shift = " in text
    assert fig.axes[1].get_xlabel() == "time [UTC] on 2024-03-17"
    from sbrdf_xr.plot import figure_problems

    assert figure_problems(fig) == []  # labels with units, no text over text
    fig.savefig(tmp_path / "pass.png", dpi=80)
    assert (tmp_path / "pass.png").stat().st_size > 10_000


def test_the_figures_curve_passes_through_the_model_at_the_observations():
    """model_curve (the fitted model at the simulated nodes, on the figure's abscissa) meets
    model_magnitude at every observation, for a pass and for a rotation sweep."""
    meas = _measured({"V": 0.3, "R": 0.1}, {"V": 0.2, "R": 0.1}, shift=1.2, sigma=0.02)
    fit = L.compare(meas, _sim(), extinction="fit", fit_time_shift=True)
    secs = (fit.time.values - T0) / np.timedelta64(1, "s")
    curve_s = (fit.curve_time.values - T0) / np.timedelta64(1, "s")
    for i, b in enumerate(fit.band.values):
        sel = fit.obs_band.values == b
        at = np.interp(secs[sel], curve_s, fit.model_curve.values[:, i])
        # linear in magnitude between 0.25 s nodes against linear in flux: < 1e-3 mag
        np.testing.assert_allclose(at, fit.model_magnitude.values[sel], atol=1e-3)
    ang = np.arange(0.0, 360.0, 1.0)
    sim = xr.DataArray(
        np.stack([12 + 0.5 * np.cos(np.radians(2 * ang)), 12.3 + np.sin(np.radians(ang))], 1),
        dims=("attitude", "band"),
        coords={"attitude_angle": ("attitude", ang), "band": ["B", "V"]},
    )
    theta = np.arange(0.0, 720.0, 7.0)
    band = np.where(np.arange(theta.size) % 2, "B", "V")
    m = np.where(
        band == "B",
        12 + 0.5 * np.cos(np.radians(2 * (theta + 33))) + 0.2,
        12.3 + np.sin(np.radians(theta + 33)) - 0.1,
    )
    lc = xr.Dataset(
        {"magnitude": ("obs", m), "uncertainty": ("obs", np.full(m.size, 0.01))},
        coords={"rotation_angle": ("obs", theta), "band": ("obs", band)},
    )
    fit = L.compare(lc, sim)
    assert float(fit.phase_offset) == pytest.approx(33.0, abs=0.01)
    for i, b in enumerate(fit.band.values):
        sel = fit.obs_band.values == b
        at = np.interp(
            fit.model_rotation_angle.values[sel],
            fit.curve_angle.values,
            fit.model_curve.values[:, i],
            period=360.0,
        )
        np.testing.assert_allclose(at, fit.model_magnitude.values[sel], atol=1e-3)
