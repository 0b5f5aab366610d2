"""Spin fit with one flux scale for every band (``offset="common"``) on magnitudes.

One common scale compares the model's band colours with the measured ones, so the model
must be in the magnitude system of the data: the band signal times ``10**(-0.4 m_sun,b)``
(:func:`sbrdf_xr.photometry.magnitudes`).  The data are CanX-1 on a held-out spin state
(drawn once, seeded) over 120 s of the built-in pass, magnitudes computed by
:func:`sbrdf_xr.photometry.magnitudes` from the simulated spectra (the photometry's own
band integration, not the fit's pre-integrated tables), plus 0.02 mag of Gaussian noise.
A right model then gives a chi-square of its distribution: reduced chi2 1 within
``sqrt(2 / dof)`` (0.075 for the 355 degrees of freedom here).  Before the model's band
colours were put in the data's system, the common scale left them at the Sun's colours
in band-signal units: reduced chi2 210 on these Vega magnitudes, 39 on AB ones.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest
import xarray as xr
from scipy.stats import chi2 as chi2_dist

from sbrdf_xr import invert
from sbrdf_xr.engine import Scene
from sbrdf_xr.engine.run import simulate
from sbrdf_xr.errors import FitQualityWarning, InversionError
from sbrdf_xr.invert._spin.data import band_factors
from sbrdf_xr.observing.observe import canx1_pass
from sbrdf_xr.photometry import magnitudes

BANDS = ("V", "R", "I")
SIGMA_MAG = 0.02


def _unit(v):
    return v / np.linalg.norm(v)


@pytest.fixture(scope="module")
def held_out(sc):
    """The pass, its truth and its noiseless magnitudes in both systems (time, band)."""
    rng = np.random.default_rng(23)
    axis_body, axis = _unit(rng.normal(size=3)), _unit(rng.normal(size=3))
    period, phase = rng.uniform(60.0, 120.0), rng.uniform(0.0, 360.0)
    law = invert.spin_model(axis_body, axis, period, phase)
    obs = dataclasses.replace(canx1_pass(), attitude=law)
    obs = dataclasses.replace(obs, times=obs.times[61:181])  # sunlit, 120 s
    cube = simulate(Scene(sc, observation=obs, outputs=("signal", "band_signal"), bands=BANDS))
    mags = {
        s: magnitudes(cube, list(BANDS), system=s).transpose("time", "band") for s in ("Vega", "AB")
    }
    lit = np.isfinite(mags["Vega"].values).all(axis=1)  # times the body shows nothing dropped
    return {
        "sc": sc,
        "obs": obs,
        "axis_body": axis_body,
        "axis": axis,
        "period": period,
        "time": cube.time.values[lit],
        "mags": {s: m.values[lit] for s, m in mags.items()},
        "band_signal": cube["band_signal"].transpose("time", "band").values[lit],
    }


def _light_curve(d, seed, system="Vega", label=None, band_offset=(0.0, 0.0, 0.0)):
    m = d["mags"][system] + np.asarray(band_offset)
    m = m + SIGMA_MAG * np.random.default_rng(seed).normal(size=m.shape)
    return xr.Dataset(
        {
            "magnitude": ("obs", m.ravel()),
            "uncertainty": ("obs", np.full(m.size, SIGMA_MAG)),
        },
        coords={
            "time": ("obs", np.repeat(d["time"], len(BANDS))),
            "band": ("obs", np.tile(BANDS, d["time"].size)),
        },
        attrs={"magnitude_system": system if label is None else label},
    )


def _fit(d, lc, offset):
    periods = invert.period_grid(0.97 * d["period"], 1.03 * d["period"], 120.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FitQualityWarning)
        return invert.fit_spin(
            lc,
            d["sc"],
            d["obs"],
            periods=periods,
            axis_body=d["axis_body"],
            offset=offset,
            n_axes=60,
            n_starts=3,
        )


def _limits(dof):
    """The 0.1 % and 99.9 % points of the chi-square distribution (the fit's own check)."""
    return chi2_dist.ppf([1e-3, 1 - 1e-3], dof)


def test_band_factors_are_the_colours_of_the_magnitudes(held_out):
    """The engine's band signal (pre-integrated tables, as in the fit) times the factors
    is proportional to the fluxes ``10**(-0.4 m)`` of :func:`magnitudes` (the simulated
    spectra integrated over each band), with the same constant in every band, in both
    systems."""
    d = held_out
    sb = d["band_signal"]
    for system in ("Vega", "AB"):
        factors, note = band_factors(_light_curve(d, 0, system), BANDS, "common")
        ratio = 10 ** (-0.4 * d["mags"][system]) / (sb * factors)
        # the two band integrations agree to rounding (measured 1e-14 relative)
        np.testing.assert_allclose(ratio / ratio[:, :1], 1.0, rtol=1e-10)
        assert system in note
    # the two systems' colours differ (V - I by 0.4 mag): mixing them is not harmless
    vega = band_factors(_light_curve(d, 0, "Vega"), BANDS, "common")[0]
    ab = band_factors(_light_curve(d, 0, "AB"), BANDS, "common")[0]
    assert abs(2.5 * np.log10(vega[2] / ab[2])) > 0.3


@pytest.mark.parametrize("system", ["Vega", "AB"])
def test_common_offset_fits_magnitudes(held_out, system):
    """Magnitudes without a per-band offset: one common scale fits them as well as one
    per band (chi2 of the right model within its distribution; the two chi2 differ by a
    chi2 of 2 degrees of freedom, below its 99.9 % point 13.8), and finds the truth."""
    d = held_out
    lc = _light_curve(d, 5, system)
    common, band = _fit(d, lc, "common"), _fit(d, lc, "band")
    lo, hi = _limits(int(common["degrees_of_freedom"]))
    assert lo < float(common["chi2"]) < hi, float(common["reduced_chi_square"])
    assert common.attrs["fit_quality"] == "consistent" and system in common.attrs["offset_note"]
    assert int(common["degrees_of_freedom"]) == int(band["degrees_of_freedom"]) + 2
    assert 0 <= float(common["chi2"]) - float(band["chi2"]) < chi2_dist.ppf(1 - 1e-3, 2)
    assert invert.axis_separation(common["axis_vector"].values, d["axis"]) < 1.0
    assert abs(float(common["period"]) - d["period"]) < 3 * float(common["period_uncertainty"])


def test_common_offset_reveals_band_offsets_and_wrong_systems(held_out):
    """What a reduced chi2 far above 1 with offset="common" means once the model is in
    the data's system: the data carry colours the model has not (a zero point off by 0.15
    mag in R: measured 14), or the magnitudes are in another system than stated (Vega
    read as AB: 78).  offset="band" absorbs both (1.02, 0.84)."""
    d = held_out
    shifted = _light_curve(d, 6, band_offset=(0.0, 0.15, 0.0))
    assert float(_fit(d, shifted, "common")["reduced_chi_square"]) > 10
    assert _fit(d, shifted, "band").attrs["fit_quality"] == "consistent"
    mislabelled = _light_curve(d, 7, "Vega", label="AB")
    assert float(_fit(d, mislabelled, "common")["reduced_chi_square"]) > 10
    with pytest.raises(InversionError, match=r"states 'unstated'.*offset='band'"):
        invert.fit_spin(
            _light_curve(d, 8, label="unstated"),
            d["sc"],
            d["obs"],
            periods=[d["period"]],
            offset="common",
        )


@pytest.mark.slow
def test_common_offset_noise_draws(held_out):
    """20 noise draws in Vega magnitudes, offset="common": every reduced chi2 within 5
    of its spreads ``sqrt(2 / dof)`` of 1, their mean within 4 spreads of the mean's
    (``sqrt(2 / (20 dof))``), every axis within 1 degree and period within 3 sigma."""
    d = held_out
    rows = []
    for seed in range(100, 120):
        r = _fit(d, _light_curve(d, seed), "common")
        rows.append(
            (
                float(r["reduced_chi_square"]),
                invert.axis_separation(r["axis_vector"].values, d["axis"]),
                (float(r["period"]) - d["period"]) / float(r["period_uncertainty"]),
            )
        )
    red, axis_err, pull = np.array(rows).T
    dof = int(r["degrees_of_freedom"])
    print(f"\nreduced chi2 {np.round(red, 3).tolist()}; axis error max {axis_err.max():.3f} deg")
    assert np.all(np.abs(red - 1) < 5 * np.sqrt(2 / dof))
    assert abs(red.mean() - 1) < 4 * np.sqrt(2 / (red.size * dof))
    assert np.all(axis_err < 1.0) and np.all(np.abs(pull) < 3)
