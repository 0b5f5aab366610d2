"""Measured light curves through astropy tables, and the fit's bad inputs.

The tables are ECSV, FITS, VOTable or CSV.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from sbrdf_xr import lightcurves as L
from sbrdf_xr.errors import ValidationError

PERIOD_S = 600.0
PHI0, DM0 = 47.3, 1.234


def _sim(
    step: float = 1.0, range_km: float | None = None, system: str | None = None
) -> xr.DataArray:
    ang = np.arange(0.0, 360.0, step)
    th = np.deg2rad(ang)
    base = 12.0 + 0.8 * np.sin(th) + 0.3 * np.cos(2 * th + 1.0)
    da = xr.DataArray(
        np.stack([base + 0.6, base], axis=1),
        dims=("attitude", "band"),
        coords={
            "attitude": np.arange(ang.size),
            "attitude_angle": ("attitude", ang),
            "band": ["B", "V"],
        },
        name="magnitude",
    )
    if range_km is not None:
        da.attrs["range_km"] = range_km
    if system is not None:
        da.attrs["magnitude_system"] = system
    return da


def _truth(band, theta):
    th = np.deg2rad(theta)
    return 12.0 + 0.8 * np.sin(th) + 0.3 * np.cos(2 * th + 1.0) + np.where(band == "B", 0.6, 0.0)


def _nights(n=240, seed=4, sigma=0.01, range_km=None):
    """Three nights of B and V, absolute UTC times, rotation period 600 s."""
    rng = np.random.default_rng(seed)
    starts = np.array(
        ["2024-03-01T20:00", "2024-03-02T21:00", "2024-03-04T19:30"], dtype="datetime64[ns]"
    )
    t = np.sort(
        np.concatenate(
            [
                s + (np.sort(rng.uniform(0, 7200, n // 3)) * 1e9).astype("timedelta64[ns]")
                for s in starts
            ]
        )
    )
    secs = (t - t[0]) / np.timedelta64(1, "s")
    band = rng.choice(["B", "V"], t.size)
    rng_km = np.full(t.size, 1000.0) if range_km is None else range_km(t.size, rng)
    mag = (
        _truth(band, 360.0 * secs / PERIOD_S + PHI0)
        + DM0
        + 5 * np.log10(rng_km / 1000.0)
        + rng.normal(0, sigma, t.size)
    )
    return t, band, mag, np.full(t.size, sigma), rng_km


def _table(range_km=None):
    import astropy.units as u
    from astropy.table import Table
    from astropy.time import Time

    t, band, mag, unc, rkm = _nights(range_km=range_km)
    tab = Table(
        {
            "time": Time(t, scale="utc"),
            "band": band,
            "magnitude": mag * u.mag,
            "uncertainty": unc * u.mag,
            "range": (rkm * 1000.0) * u.m,
        }
    )
    tab.meta["magnitude_system"] = "Vega"
    return tab, t, mag


@pytest.mark.parametrize(
    ("suffix", "fmt"), [(".ecsv", "ascii.ecsv"), (".fits", "fits"), (".vot", "votable")]
)
def test_tables_with_units_and_absolute_utc_times(tmp_path, suffix, fmt):
    tab, t, mag = _table()
    path = tmp_path / f"lc{suffix}"
    if fmt == "votable":
        tab["time"].precision = 9
        tab["time"] = tab["time"].isot  # VOTable times as ISO strings ...
        tab["time"] = [s + "Z" for s in tab["time"]]  # ... with the zone stated
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # FITS writes the long key magnitude_system as HIERARCH
        tab.write(path, format=fmt)
    lc = L.read_light_curve(path, system="Vega" if fmt != "ascii.ecsv" else None)
    assert lc.time.dtype == np.dtype("datetime64[ns]")
    # times to the ns (FITS/ECSV Time columns round-trip at the us level: jd1+jd2 doubles)
    np.testing.assert_array_less(np.abs((lc.time.values - t) / np.timedelta64(1, "us")), 1.0)
    # ECSV and VOTable TABLEDATA write floats as text with ~10 significant digits: 1e-9 at m ~ 14
    np.testing.assert_allclose(
        lc.magnitude.values, mag, rtol=0, atol=1e-12 if fmt == "fits" else 1e-9
    )
    np.testing.assert_allclose(lc.range_km.values, 1000.0, rtol=1e-12)  # m -> km
    assert lc.attrs["magnitude_system"] == "Vega"
    assert lc.magnitude.attrs["ancillary_variables"] == "uncertainty"
    res = L.compare(lc, _sim(range_km=1000.0, system="Vega"), period=PERIOD_S, zero_points="common")
    # 240 points over three nights: sigma(phase) ~ 0.04 deg, sigma(offset) ~ 0.0007 mag
    assert float(res.phase_offset) == pytest.approx(PHI0, abs=0.15)
    assert float(res.magnitude_offset) == pytest.approx(DM0, abs=0.003)


def test_csv_iso_times_need_a_zone_or_a_stated_scale(tmp_path):
    path = tmp_path / "naive.csv"
    path.write_text(
        "time,band,magnitude,uncertainty\n2024-01-01T00:00:00Z,V,12,0.1\n"
        "2024-01-01T00:01:00,V,12,0.1\n"
    )
    with pytest.raises(
        ValidationError,
        match=r"row 2 \(line 3 of the file\), column 'time': "
        r"'2024-01-01T00:01:00' has no time zone and cannot be read as UTC",
    ):
        L.read_light_curve(path)
    lc = L.read_light_curve(path, time_scale="utc")
    assert lc.time.values[1] == np.datetime64("2024-01-01T00:01:00", "ns")
    off = tmp_path / "offset.csv"
    off.write_text("time,band,magnitude,uncertainty\n2024-01-01T02:00:00+02:00,V,12,0.1\n")
    assert L.read_light_curve(off).time.values[0] == np.datetime64("2024-01-01T00:00:00", "ns")
    with pytest.raises(ValidationError, match="time_scale: got 'ut1'; allowed: utc, tai"):
        L.read_light_curve(path, time_scale="ut1")
    # a stated scale converts the zone-less times (TAI - UTC = 37 s in 2024); 'Z' stays UTC
    tai = L.read_light_curve(path, time_scale="tai")
    assert tai.time.values[0] == np.datetime64("2024-01-01T00:00:00", "ns")
    assert tai.time.values[1] == np.datetime64("2024-01-01T00:00:23", "ns")


def test_mixed_systems_missing_columns_and_bad_units_are_named(tmp_path):
    mixed = tmp_path / "mixed.csv"
    mixed.write_text(
        "rotation_angle,band,magnitude,uncertainty,system\n0,V,12,0.1,Vega\n1,V,12,0.1,AB\n"
    )
    with pytest.raises(
        ValidationError,
        match=r"row 2 \(line 3 of the file\), column 'system': 'AB' differs "
        "from 'Vega'",
    ):
        L.read_light_curve(mixed)
    one = tmp_path / "one.csv"
    one.write_text("rotation_angle,band,magnitude,uncertainty,system\n0,V,12,0.1,vega\n")
    assert L.read_light_curve(one).attrs["magnitude_system"] == "Vega"
    with pytest.raises(ValidationError, match="states the Vega system, not system='AB'"):
        L.read_light_curve(one, system="AB")
    import astropy.units as u
    from astropy.table import Table

    tab = Table(
        {
            "rotation_angle": [0.0, 1.0] * u.deg,
            "band": ["V", "V"],
            "magnitude": [12.0, 12.1] * u.mag,
        }
    )
    tab.write(tmp_path / "miss.ecsv")
    with pytest.raises(ValidationError, match=r"missing column\(s\) \['uncertainty'\]"):
        L.read_light_curve(tmp_path / "miss.ecsv")
    tab["uncertainty"] = [0.1, 0.1] * u.s
    tab.write(tmp_path / "unit.ecsv", overwrite=True)
    with pytest.raises(
        ValidationError, match="column 'uncertainty' has unit s, which cannot be converted to mag"
    ):
        L.read_light_curve(tmp_path / "unit.ecsv")
    tab["uncertainty"] = [0.1, 0.1] * u.mag
    tab["rotation_angle"] = [0.0, 0.5] * u.rad
    tab.write(tmp_path / "rad.ecsv", overwrite=True)
    assert L.read_light_curve(tmp_path / "rad.ecsv").rotation_angle.values[1] == pytest.approx(
        np.degrees(0.5)
    )
    bad_range = tmp_path / "range.csv"
    bad_range.write_text("rotation_angle,band,magnitude,uncertainty,range_km\n0,V,12,0.1,-3\n")
    with pytest.raises(ValidationError, match="column 'range_km': must be > 0 km"):
        L.read_light_curve(bad_range)


def test_the_fit_uses_per_row_range_and_refuses_a_system_mismatch(tmp_path):
    tab, _, _ = _table(range_km=lambda n, rng: rng.uniform(800.0, 3000.0, n))
    tab.write(tmp_path / "r.ecsv")
    lc = L.read_light_curve(tmp_path / "r.ecsv")
    res = L.compare(lc, _sim(range_km=1000.0, system="Vega"), period=PERIOD_S, zero_points="common")
    assert float(res.magnitude_offset) == pytest.approx(
        DM0, abs=0.003
    )  # the 5 log10 d term is modelled
    assert 0.7 < float(res.reduced_chi_square) < 1.3
    with pytest.raises(ValidationError, match="in the Vega system but the simulation is in AB"):
        L.compare(lc, _sim(range_km=1000.0, system="AB"), period=PERIOD_S, zero_points="common")
    with pytest.raises(ValidationError, match="no range_km attribute"):
        L.compare(lc, _sim(system="Vega"), period=PERIOD_S, zero_points="common")


def test_extinction_with_an_airmass_column(tmp_path):
    rng = np.random.default_rng(0)
    theta = np.sort(rng.uniform(0, 720, 200))
    band = rng.choice(["B", "V"], 200)
    x = rng.uniform(1.0, 2.5, 200)
    k = {"B": 0.25, "V": 0.15}
    mag = (
        _truth(band, theta + PHI0)
        + DM0
        + np.array([k[b] for b in band]) * x
        + rng.normal(0, 0.01, 200)
    )
    path = tmp_path / "x.csv"
    import pandas as pd

    pd.DataFrame(
        {"rotation_angle": theta, "band": band, "magnitude": mag, "uncertainty": 0.01, "airmass": x}
    ).to_csv(path, index=False)
    lc = L.read_light_curve(path)
    res = L.compare(lc, _sim(), extinction=k, zero_points="common")
    assert float(res.magnitude_offset) == pytest.approx(DM0, abs=0.004)
    naive = L.compare(lc, _sim(), zero_points="common")
    assert float(naive.reduced_chi_square) > 5 * float(res.reduced_chi_square)  # the test can tell


def _small(tmp_path, n=3, sigma="0.01"):
    path = tmp_path / f"s{n}.csv"
    rows = "".join(f"{10 * i},V,{12 + 0.1 * i},{sigma}\n" for i in range(n))
    path.write_text("rotation_angle,band,magnitude,uncertainty\n" + rows)
    return path


def test_fit_bad_inputs_get_named_errors(tmp_path):
    lc = L.read_light_curve(_small(tmp_path, 5))
    for bad in (0, -3, 2.5, True):
        with pytest.raises(ValidationError, match="n_scan: must be an integer >= 1"):
            L.compare(lc, _sim(), n_scan=bad, zero_points="common")
    assert np.isfinite(float(L.compare(lc, _sim(), n_scan=1, zero_points="common").chi_square))
    one = L.read_light_curve(_small(tmp_path, 1))
    with pytest.raises(ValidationError, match=r"1 observation\(s\).*needs at least 3"):
        L.compare(one, _sim(), zero_points="common")
    with pytest.raises(ValidationError, match=r"1 observation\(s\).*needs at least 2"):
        L.compare(one, _sim(), fit_phase=False, zero_points="common")
    two = L.read_light_curve(_small(tmp_path, 2))
    assert (
        int(L.compare(two, _sim(), fit_phase=False, zero_points="common").degrees_of_freedom) == 1
    )
    with pytest.raises(ValidationError, match=r"column 'uncertainty': must be >= 1e-06 mag"):
        L.read_light_curve(_small(tmp_path, 5, sigma="1e-300"))
    tiny = lc.copy()
    tiny["uncertainty"] = ("obs", np.full(5, 1e-300))
    with pytest.raises(ValidationError, match=r"observation 0 \(row 1\) has uncertainty 1e-300"):
        L.compare(tiny, _sim(), zero_points="common")


def test_netcdf_round_trip_keeps_absolute_times(tmp_path):
    tab, _, _ = _table()
    tab.write(tmp_path / "lc.ecsv")
    lc = L.read_light_curve(tmp_path / "lc.ecsv")
    lc.to_netcdf(tmp_path / "lc.nc")
    back = L.read_light_curve(tmp_path / "lc.nc")
    np.testing.assert_array_equal(back.time.values, lc.time.values)
    assert back.attrs["magnitude_system"] == "Vega"
