"""The joint fit of a pass (invert.fit_observation) and its calibration study.

The data are written by another route than the fit's model: ``simulated_light_curve``
simulates the spectral signal of each material (``simulate``) and band-integrates it with
``photometry.magnitudes``, while the fit evaluates band pre-integrated tables with the
compiled kernel at body-frame directions it computes itself from the spin state.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from astropy.table import Table

from sbrdf_xr import catalog, invert
from sbrdf_xr.errors import FitQualityWarning, InversionError
from sbrdf_xr.lightcurves import read_light_curve
from sbrdf_xr.observing import Observation, Orbit, Site, times

ECSV = "observe/canx1-zimmerwald-night.ecsv"
TRUTH_SPIN = {
    "axis_longitude": 215.0,
    "axis_latitude": 40.0,
    "period": 57.0,
    "phase": 30.0,
    "epoch": "2024-03-17T19:55:00",
}
FRACTIONS = {"aluminium-6061-t6": 0.15, "tjpv-cell": 0.30, "white-paint-a276": 0.55}
EXTINCTION = {"V": 0.22, "R": 0.15, "I": 0.09}
#: About as far from the truth as fit_spin leaves it on extinction-laden magnitudes.
START = {**TRUTH_SPIN, "axis_longitude": 212.0, "axis_latitude": 37.0, "period": 57.1}


def _night(t0: str = "2024-03-17T19:55:00", t1: str = "2024-03-17T20:00:40") -> Observation:
    orbit = Orbit.from_file(catalog.data_path("observe/canx1-example.tle"))
    return Observation(orbit, Site.from_catalog("zimmerwald"), times(t0, t1, 1.0), name="night")


@pytest.fixture(scope="module")
def night():
    return _night()


@pytest.fixture(scope="module")
def lc():
    return read_light_curve(catalog.data_path(ECSV))


@pytest.fixture(scope="module")
def fit(sc, lc, night):
    return invert.fit_observation(lc, sc, night, START)


def _half_turn(d: float) -> float:
    return (d + 90.0) % 180.0 - 90.0


def test_noise_free_pass_gives_the_truth(sc, night):
    # data by simulate + band integration, fit by the kernel on pre-integrated tables:
    # the two agree to 1e-14 mag (attrs model_check), so the noise-free truth is the
    # minimum; the tolerance is the optimizer's stopping rule (xtol 1e-10 relative)
    clean, _ = invert.simulated_light_curve(
        sc,
        _night("2024-03-17T19:55:40", "2024-03-17T20:00:19"),
        TRUTH_SPIN,
        area_fraction=FRACTIONS,
        extinction=EXTINCTION,
    )
    clean["uncertainty"] = clean["uncertainty"] + 0.02
    with pytest.warns(FitQualityWarning, match="below the 0.1 % point"):  # no noise: too good
        fit = invert.fit_observation(clean, sc, night, START)
    assert float(fit.chi2) < 1e-6
    for k in ("axis_longitude", "axis_latitude", "period"):
        assert float(fit[k]) == pytest.approx(TRUTH_SPIN[k], rel=1e-6)
    assert _half_turn(float(fit.phase) - TRUTH_SPIN["phase"]) == pytest.approx(0.0, abs=1e-4)
    for b, k in EXTINCTION.items():
        assert float(fit.extinction_coefficient.sel(band=b)) == pytest.approx(k, abs=1e-6)
    for m, f in FRACTIONS.items():
        assert float(fit.area_fraction.sel(material=m)) == pytest.approx(f, abs=1e-6)
    assert float(fit.area_fraction.sum()) == pytest.approx(1.0, abs=1e-12)
    assert "largest difference" in fit.attrs["model_check"]


def test_the_night_is_fitted_within_its_uncertainties(fit, lc):
    truth = Table.read(catalog.data_path(ECSV)).meta["simulated_truth"]
    assert fit.attrs["fit_quality"] == "consistent"
    assert 0.8 < float(fit.reduced_chi_square) < 1.25  # 271 dof: 99.9 % interval 0.76 .. 1.29
    assert int(fit.degrees_of_freedom) == lc.sizes["obs"] - fit.sizes["parameter"] == 271
    pulls = {
        "axis_longitude": float(fit.axis_longitude) - truth["spin_axis_longitude_deg"],
        "axis_latitude": float(fit.axis_latitude) - truth["spin_axis_latitude_deg"],
        "period": float(fit.period) - truth["spin_period_s"],
        "phase": _half_turn(float(fit.phase) - truth["spin_phase_deg"]),
    }
    for k, d in pulls.items():
        assert abs(d) < 4 * float(fit[k + "_uncertainty"]), k
    for b, k in truth["extinction_mag_per_airmass"].items():
        d = float(fit.extinction_coefficient.sel(band=b)) - k
        assert abs(d) < 4 * float(fit.extinction_coefficient_uncertainty.sel(band=b))
    for m, f in truth["area_fraction"].items():
        d = float(fit.area_fraction.sel(material=m)) - f
        assert abs(d) < 4 * float(fit.area_fraction_uncertainty.sel(material=m))
    # the residuals are the measured minus the model magnitudes
    np.testing.assert_allclose(fit.model_magnitude + fit.residual, lc.magnitude, atol=1e-12)


def test_result_is_self_describing(fit):
    for name, v in fit.variables.items():
        if v.dtype.kind == "M":  # UTC times: their units are set when written (CF encoding)
            continue
        assert "units" in v.attrs and "long_name" in v.attrs, name
    c = fit.correlation.values
    np.testing.assert_allclose(np.diag(c), 1.0, atol=1e-12)
    np.testing.assert_allclose(c, c.T, atol=1e-12)
    assert np.all(np.abs(c) <= 1 + 1e-12)
    est = fit.estimate.to_series()
    assert est["period"] == float(fit.period) and est["phase"] == float(fit.phase)
    # the last material takes the rest: its uncertainty is that of the sum of the others
    cov = c[-2:, -2:] * np.outer(fit.uncertainty[-2:], fit.uncertainty[-2:])
    assert float(fit.area_fraction_uncertainty[-1]) == pytest.approx(np.sqrt(cov.sum()))
    assert fit.attrs["uncertainty_scaling"].startswith("unscaled")
    assert fit.attrs["epoch"] == "2024-03-17T19:55:00.000"
    assert fit.attrs["status"] == "ok" and fit.attrs["unconstrained"] == "none"
    assert fit.attrs["bounded"].startswith("none")


def test_starts_from_fit_spin(sc, lc, night, fit):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FitQualityWarning)  # extinction left in the data
        spin = invert.fit_spin(
            lc,
            sc,
            night,
            periods=invert.period_grid(54.0, 60.0, 280.0),
            n_axes=40,
            search_times=40,
            n_starts=2,
        )
    again = invert.fit_observation(lc, sc, night, spin, starts="aliases", check=False)
    # refined from the start, its four period aliases and fit_spin's four twins; the
    # solution is the lowest, and the table says how far above it the others stopped
    assert again.sizes["start"] == 9 and "twin antipode" in again.start.values
    assert float(again.start_chi2_gap.min()) == 0.0
    assert float(again.start_chi2.min()) == pytest.approx(float(again.chi2), rel=1e-12)
    # the same minimum up to CanX-1's half-turn symmetry: fit_spin starts at a phase near
    # 210 deg, and the twin half a turn away fits as well within 0.01 in chi2 (the body is
    # nearly, not exactly, the same turned half a turn about z)
    assert float(again.chi2) == pytest.approx(float(fit.chi2), abs=0.05)
    for k in ("axis_longitude", "axis_latitude", "period"):
        assert abs(float(again[k]) - float(fit[k])) < 0.1 * float(fit[k + "_uncertainty"]), k
    assert abs(_half_turn(float(again.phase) - float(fit.phase))) < 0.1 * float(
        fit.phase_uncertainty
    )


def test_options(sc, lc, night, fit):
    band = invert.fit_observation(lc, sc, night, START, offset="band", check=False)
    assert band.sizes["parameter"] == 12
    # a calibrated table: the zero points vanish within their uncertainties
    assert np.all(np.abs(band.zero_point) < 4 * band.zero_point_uncertainty)
    common = invert.fit_observation(lc, sc, night, START, offset="common", check=False)
    assert "magnitude_offset" in common and "zero_point" not in common
    given = invert.fit_observation(lc, sc, night, START, extinction=EXTINCTION, check=False)
    assert given.extinction_coefficient.values.tolist() == list(EXTINCTION.values())
    assert np.all(given.extinction_coefficient_uncertainty == 0)
    free = invert.fit_observation(lc, sc, night, START, areas="free", check=False)
    assert free.sizes["parameter"] == 10
    # one more free parameter cannot fit worse
    assert float(free.chi2) <= float(fit.chi2) + 1e-6
    scaled = invert.fit_observation(lc, sc, night, START, scale_uncertainties=True, check=False)
    ratio = scaled.uncertainty / fit.uncertainty
    np.testing.assert_allclose(ratio, np.sqrt(float(fit.reduced_chi_square)), rtol=1e-3)


def test_a_wrong_model_warns(sc, lc, night):
    with pytest.warns(FitQualityWarning, match="joint fit: chi2 .* beyond the 99.9 %"):
        bad = invert.fit_observation(
            lc, sc, night, START, extinction=None, areas="fixed", check=False
        )
    assert bad.attrs["fit_quality"] == "poor"


@pytest.mark.parametrize(
    ("change", "match"),
    [
        ({"bands": ["V", "R"]}, r"bands \['I'\] are not among the simulated bands"),
        ({"offset": "band", "areas": "free"}, "neither is determined"),
        ({"offset": "zero"}, "offset: 'zero'; allowed None"),
        ({"areas": "sum"}, "areas: 'sum'; allowed 'total'"),
        ({"extinction": {"V": 0.2}}, r"no coefficient for bands \['R', 'I'\]"),
        ({"extinction": "guess"}, "extinction: 'guess'; allowed 'fit'"),
        ({"system": "AB"}, "the light curve's magnitudes are 'Vega'"),
        ({"starts": "all"}, "starts: 'all'; allowed 'given'"),
        ({"starts": START}, "starts: got a dict; allowed 'given', 'aliases' or a sequence"),
        ({"starts": [{**START, "period": -1.0}]}, r"start values must be finite with period > 0"),
        (
            {"extinction_prior": {"V": (0.2, 0.0), "R": (0.1, 0.1), "I": (0.05, 0.1)}},
            r"extinction_prior\['V'\]: k 0.2, width 0.0; allowed finite values with a width > 0",
        ),
        ({"extinction_prior": {"V": (0.2, 0.1)}}, r"no \(k, width\) for bands \['R', 'I'\]"),
        ({"extinction_prior": {"V": 0.2, "R": 1, "I": 2}}, r"allowed a pair \(k, width\)"),
    ],
)
def test_bad_options(sc, lc, night, change, match):
    with pytest.raises(InversionError, match=match):
        invert.fit_observation(lc, sc, night, START, **change)


def test_bad_data(sc, lc, night):
    short = _night("2024-03-17T19:56:00", "2024-03-17T20:00:40")
    with pytest.raises(InversionError, match="outside the observation window"):
        invert.fit_observation(lc, sc, short, START)
    with pytest.raises(InversionError, match="8 values for 9 parameters"):
        invert.fit_observation(lc.isel(obs=slice(0, 8)), sc, night, START)
    flux = lc.rename(magnitude="flux", uncertainty="flux_uncertainty")
    with pytest.raises(InversionError, match="needs calibrated magnitudes"):
        invert.fit_observation(flux, sc, night, START)
    with pytest.raises(InversionError, match=r"spin: missing \['phase'\]"):
        invert.fit_observation(lc, sc, night, {k: v for k, v in START.items() if k != "phase"})
    dark = _night("2024-03-17T19:54:00", "2024-03-17T20:00:40")
    early = lc.assign_coords(time=lc.time - np.timedelta64(90, "s"))
    with pytest.raises(InversionError, match="in the Earth's umbra"):
        invert.fit_observation(early, sc, dark, START)
    with pytest.raises(InversionError, match=r"expected an sbrdf_xr\.observing\.Observation"):
        invert.fit_observation(lc, sc, "zimmerwald", START)


def test_aliases_find_the_minimum_a_start_misses(sc):
    # a 10 s spin over a 279 s pass: a start 0.2 s off slips the phase by 360 * 279 * 0.2
    # / 10**2 = 200 deg over the pass (more than the quarter turn P**2 / (4 T) = 0.09 s
    # allows) and the local fit stops in another minimum
    truth = {**TRUTH_SPIN, "period": 10.0}
    pass_ = _night("2024-03-17T19:55:40", "2024-03-17T20:00:19")
    clean, _ = invert.simulated_light_curve(
        sc, pass_, truth, area_fraction=FRACTIONS, extinction=EXTINCTION
    )
    lc = clean.copy()
    lc["magnitude"] = clean.magnitude + np.random.default_rng(3).normal(0.0, 0.02, lc.sizes["obs"])
    lc["uncertainty"] = clean.uncertainty + 0.02
    start = {**truth, "axis_longitude": 216.0, "axis_latitude": 41.0, "period": 10.2, "phase": 33.0}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", FitQualityWarning)
        local = invert.fit_observation(lc, sc, pass_, start, check=False)
    said = " ".join(str(w.message) for w in caught)
    assert "beyond the 99.9 %" in said and "the fit failed" in said and "fit_spin" in said
    assert float(local.reduced_chi_square) > 5 and abs(float(local.period) - 10.0) > 0.2
    # its minimum needs impossible areas: refined inside the bounds, and marked failed
    assert local.attrs["status"] == "failed" and "outside physics" in local.attrs["bounded"]
    f = local.area_fraction.values
    assert np.all((f >= 0) & (f <= 1)) and float(f.sum()) == pytest.approx(1.0)
    assert np.all(np.isfinite(local.uncertainty.values))
    with warnings.catch_warnings():
        warnings.simplefilter("error", FitQualityWarning)  # consistent, and not ambiguous
        fit = invert.fit_observation(lc, sc, pass_, start, starts="aliases", check=False)
    assert fit.start.values.tolist() == [
        "given", "alias -2/2 turn", "alias -1/2 turn", "alias +1/2 turn", "alias +2/2 turn"
    ]  # fmt: skip
    # no other minimum is ambiguous; CanX-1's symmetries give exact twins (a half turn
    # about its spin axis and two flips), named in ambiguity, their chi2 gaps of rounding
    assert (
        float(fit.reduced_chi_square) < 1.25
        and fit.attrs["ambiguity"] == fit.attrs["symmetry_twins"]
    )
    assert fit.twin.values.tolist() == [
        "turn 180 deg",
        "flip about [0, 1, 0]",
        "flip about [1, 0, 0]",
    ]
    assert np.all(np.abs(fit.twin_chi2_gap.values) < 1e-6)
    assert abs(float(fit.period) - 10.0) < 4 * float(fit.period_uncertainty)
    assert float(fit.start_chi2_gap.sel(start="given")) == pytest.approx(
        float(local.chi2) - float(fit.chi2), rel=1e-9
    )
    # the same from an explicit start near the truth
    near = {**start, "period": 10.01}
    again = invert.fit_observation(lc, sc, pass_, start, starts=[near], check=False)
    assert again.start.values.tolist() == ["given", "start 0"]
    assert float(again.chi2) == pytest.approx(float(fit.chi2), abs=0.5)  # micro-minima


def _recovery(sc, n_draws: int, seed: int):
    return invert.observation_recovery(
        sc,
        _night("2024-03-17T19:55:40", "2024-03-17T20:00:19"),
        TRUTH_SPIN,
        area_fraction=FRACTIONS,
        extinction=EXTINCTION,
        n_draws=n_draws,
        seed=seed,
        phase_symmetry=180.0,
    )


def test_recovery_few_draws(sc):
    study = _recovery(sc, 4, seed=1)
    assert int(study.n_draws) == 4 and int(study.quality_warnings) == 0
    # every estimate within 4 sigma of the truth in every draw (a calibrated estimator
    # leaves 4 sigma once in 16 000 values)
    assert float(np.abs(study.pull).max()) < 4.0
    assert float(study.axis_error.max()) < 2.0  # degree; the start was 2 deg off
    for v in study.data_vars.values():
        assert "units" in v.attrs and "long_name" in v.attrs


@pytest.mark.slow
def test_recovery_calibrated():
    from sbrdf_xr.body.spacecraft import canx1

    study = _recovery(canx1(), 200, seed=2)
    # 200 draws: a pull width scatters by 1/sqrt(400) = 0.05 and a pull mean by 0.07;
    # 1000 draws (docs/guide/inversion.md) measured widths 0.98 .. 1.04 and 1.10 for the
    # axis longitude, so 0.83 .. 1.27 allows the measured spread plus 3 of that scatter
    assert np.all((study.pull_width > 0.83) & (study.pull_width < 1.27))
    assert np.all(np.abs(study.pull_mean) < 0.25)
    # coverage of 2 sigma: 0.954 for a Gaussian, 0.924 measured for the axis longitude;
    # 200 draws scatter it by 0.019
    assert np.all(study.coverage_2sigma >= 0.87)
    assert int(study.quality_warnings) <= 3
