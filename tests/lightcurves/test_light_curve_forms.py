"""Measured light curves in the forms observers keep: long and wide, any row order,
magnitudes or fluxes, AB or Vega stated, UTC, JD or MJD times, filter names as written.

Every file is written with astropy (or as CSV text) in tmp_path and read back.
"""

from __future__ import annotations

import warnings

import astropy.units as u
import numpy as np
import pytest
from astropy.table import Table
from astropy.time import Time

from sbrdf_xr import lightcurves as L
from sbrdf_xr.errors import LightCurveError

T0 = np.datetime64("2024-03-17T01:21:00", "ns")
FORMATS = [(".ecsv", "ascii.ecsv"), (".fits", "fits"), (".vot", "votable"), (".csv", "ascii.csv")]


def _night(n=12, seed=0):
    """Times every 10 s; V, R, I magnitudes; uncertainties."""
    rng = np.random.default_rng(seed)
    t = T0 + (np.arange(n) * 10e9).astype("timedelta64[ns]")
    mags = {
        b: 12.0 + 0.2 * np.sin(np.arange(n) / 3.0) + off
        for b, off in (("V", 0.0), ("R", -0.4), ("I", -0.7))
    }
    errs = {b: rng.uniform(0.01, 0.03, n) for b in mags}
    return t, mags, errs


def _write(tab, path, fmt):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # FITS writes long keys as HIERARCH
        tab.write(path, format=fmt, overwrite=True)


def _iso(t):
    return [str(x)[:23] + "Z" for x in t]


@pytest.mark.parametrize(("suffix", "fmt"), FORMATS)
def test_a_wide_table_in_any_row_order(tmp_path, suffix, fmt):
    t, mags, errs = _night()
    perm = np.random.default_rng(1).permutation(t.size)
    cols = {"time": _iso(t[perm])}
    for b in ("V", "R"):
        cols[b] = mags[b][perm]
        cols[f"{b}_err"] = errs[b][perm]
    tab = Table(cols)
    tab["V"][3] = np.nan  # a time without V: an empty cell, not an observation
    tab.meta["magnitude_system"] = "Vega"
    path = tmp_path / f"wide{suffix}"
    _write(tab, path, fmt)
    lc = L.read_light_curve(
        path, system="Vega" if fmt in ("fits", "votable", "ascii.csv") else None
    )
    assert lc.attrs["table_form"] == "wide" and lc.attrs["magnitude_system"] == "Vega"
    assert lc.sizes["obs"] == 2 * t.size - 1
    assert np.all(np.diff(lc.time.values) >= np.timedelta64(0, "ns"))  # sorted by time
    assert "sorted by time" in lc.attrs["row_order"]
    for b in ("V", "R"):
        sel = lc.band.values == b
        back = np.searchsorted(t, lc.time.values[sel])
        want = mags[b][back]
        if b == "V":
            assert perm[3] not in back  # the empty cell left out
        # text formats keep ~10 significant digits
        np.testing.assert_allclose(lc.magnitude.values[sel], want, atol=1e-9)
        np.testing.assert_allclose(lc.uncertainty.values[sel], errs[b][back], atol=1e-9)
        # the file's own row of each observation
        np.testing.assert_array_equal(perm[lc.file_row.values[sel] - 1], back)


@pytest.mark.parametrize(("suffix", "fmt"), FORMATS)
def test_a_long_table_grouped_by_band_is_sorted_by_time(tmp_path, suffix, fmt):
    t, mags, errs = _night()
    rows = [(b, k) for b in ("V", "R", "I") for k in range(t.size)]  # all V, then R, then I
    tab = Table(
        {
            "time": _iso([t[k] for _, k in rows]),
            "filter": [b for b, _ in rows],
            "mag": [mags[b][k] for b, k in rows],
            "mag_err": [errs[b][k] for b, k in rows],
        }
    )
    path = tmp_path / f"long{suffix}"
    _write(tab, path, fmt)
    lc = L.read_light_curve(path, system="AB")
    assert lc.attrs["table_form"] == "long" and lc.sizes["obs"] == len(rows)
    assert np.all(np.diff(lc.time.values) >= np.timedelta64(0, "ns"))
    # at one time the bands keep the file's order (a stable sort)
    assert lc.band.values[:3].tolist() == ["V", "R", "I"]
    assert lc.file_row.values[:3].tolist() == [1, t.size + 1, 2 * t.size + 1]


def test_fluxes_become_ab_magnitudes(tmp_path):
    t, mags, _ = _night(4)
    # AB: 3631 Jy at magnitude 0 (the package's AB_ZERO_POINT_JY; astropy's ABmag takes
    # Oke & Gunn's 48.60, 3630.78 Jy, 6.6e-5 mag apart)
    mjy = 3631e3 * 10.0 ** (-0.4 * mags["V"])
    tab = Table(
        {
            "time": Time(t, scale="utc"),
            "band": ["V"] * 4,
            "flux": mjy * u.mJy,
            "flux_err": 0.01 * mjy * u.mJy,
        }
    )
    tab.write(tmp_path / "f.ecsv")
    lc = L.read_light_curve(tmp_path / "f.ecsv")
    np.testing.assert_allclose(lc.magnitude.values, mags["V"], atol=1e-12)
    # sigma_m = 2.5 / ln 10 * sigma_f / f, first order
    np.testing.assert_allclose(lc.uncertainty.values, 2.5 / np.log(10) * 0.01, rtol=1e-12)
    assert lc.attrs["magnitude_system"] == "AB" and "3631 Jy" in lc.attrs["flux_conversion"]
    tab.meta["magnitude_system"] = "Vega"
    tab.write(tmp_path / "fv.ecsv")
    with pytest.raises(LightCurveError, match=r"fluxes give AB magnitudes, but .* Vega"):
        L.read_light_curve(tmp_path / "fv.ecsv")
    (tmp_path / "nounit.csv").write_text("time,band,flux,flux_err\n2024-03-17T01:21:00Z,V,1,0.1\n")
    with pytest.raises(LightCurveError, match="fluxes without a unit cannot be magnitudes"):
        L.read_light_curve(tmp_path / "nounit.csv")


def test_a_flux_per_wavelength_uses_the_pivot_wavelength(tmp_path):
    """A spectrum flat in f_lambda has band-averaged <f_lambda> = f_lambda; its AB
    magnitude computed by speclite over the V curve (an independent integration) is the
    one read from the flux per wavelength."""
    import speclite.filters

    flam = 2e-15  # erg s-1 cm-2 A-1
    v = speclite.filters.load_filters("bessell-V")
    wl = np.arange(4000.0, 7500.0, 1.0) * u.AA
    spec = np.full(wl.size, flam) * u.erg / u.s / u.cm**2 / u.AA
    want = float(v.get_ab_magnitudes(spec, wl)["bessell-V"][0])
    tab = Table(
        {
            "time": _iso([T0]),
            "band": ["V"],
            "flux": [flam] * u.erg / u.s / u.cm**2 / u.AA,
            "flux_err": [flam / 100] * u.erg / u.s / u.cm**2 / u.AA,
        }
    )
    tab.write(tmp_path / "flam.ecsv")
    lc = L.read_light_curve(tmp_path / "flam.ecsv")
    # the pivot identity is exact for these integrals; speclite and the package
    # integrate the same curve on different grids: 1e-4 mag
    assert float(lc.magnitude[0]) == pytest.approx(want, abs=1e-4)


def test_the_system_from_column_metadata_a_unit_or_the_argument(tmp_path):
    t, mags, errs = _night(3)
    tab = Table(
        {"time": _iso(t), "band": ["V"] * 3, "magnitude": mags["V"], "uncertainty": errs["V"]}
    )
    tab["magnitude"].meta["magnitude_system"] = "Vega"
    tab.write(tmp_path / "colmeta.ecsv")
    assert L.read_light_curve(tmp_path / "colmeta.ecsv").attrs["magnitude_system"] == "Vega"
    tab2 = tab.copy()
    tab2["magnitude"].meta = {}
    tab2["magnitude"].unit = u.ABmag
    tab2.write(tmp_path / "abunit.ecsv")
    assert L.read_light_curve(tmp_path / "abunit.ecsv").attrs["magnitude_system"] == "AB"
    with pytest.raises(LightCurveError, match="states the AB system, not system='Vega'"):
        L.read_light_curve(tmp_path / "abunit.ecsv", system="Vega")
    tab2.meta = {}
    tab2["magnitude"].unit = None
    tab2.write(tmp_path / "plain.ecsv")
    assert L.read_light_curve(tmp_path / "plain.ecsv").attrs["magnitude_system"] == "unstated"
    assert (
        L.read_light_curve(tmp_path / "plain.ecsv", system="vega").attrs["magnitude_system"]
        == "Vega"
    )


def test_julian_dates_need_a_stated_scale(tmp_path):
    t, mags, errs = _night(3)
    mjd = Time(t, scale="utc").mjd
    text = "".join(
        f"{float(m)!r},V,{v},{e}\n" for m, v, e in zip(mjd, mags["V"], errs["V"], strict=True)
    )
    (tmp_path / "mjd.csv").write_text("MJD,band,mag,err\n" + text)
    with pytest.raises(LightCurveError, match="holds modified Julian dates but no time scale"):
        L.read_light_curve(tmp_path / "mjd.csv")
    lc = L.read_light_curve(tmp_path / "mjd.csv", time_scale="utc")
    # an MJD double holds times to ~1 us near 2024
    assert np.all(np.abs((lc.time.values - t) / np.timedelta64(1, "us")) < 2.0)
    (tmp_path / "mjd_utc.csv").write_text("mjd_utc,band,mag,err\n" + text)
    assert L.read_light_curve(tmp_path / "mjd_utc.csv").attrs["time_source"].startswith("MJD")
    # TAI dates: 37 s after UTC in 2024
    jd_tai = Time(t, scale="utc").tai.jd
    rows = "".join(
        f"{float(j)!r},Bessell-V,{v},{e}\n"
        for j, v, e in zip(jd_tai, mags["V"], errs["V"], strict=True)
    )
    tab = tmp_path / "jd.csv"
    tab.write_text("jd,filter,magnitude,uncertainty\n" + rows)
    lc = L.read_light_curve(tab, time_scale="tai")
    assert np.all(np.abs((lc.time.values - t) / np.timedelta64(1, "us")) < 200.0)
    table = Table(
        {
            "mjd": Time(t, scale="utc").tt.mjd,
            "band": ["V"] * 3,
            "mag": mags["V"],
            "mag_err": errs["V"],
        }
    )
    table.meta["TIMESYS"] = "TT"
    _write(table, tmp_path / "tt.fits", "fits")
    lc = L.read_light_curve(tmp_path / "tt.fits")
    assert np.all(np.abs((lc.time.values - t) / np.timedelta64(1, "us")) < 2.0)
    (tmp_path / "bjd.csv").write_text("bjd_tdb,band,mag,err\n2460386.5,V,12,0.1\n")
    with pytest.raises(LightCurveError, match="heliocentric or barycentric dates"):
        L.read_light_curve(tmp_path / "bjd.csv")


@pytest.mark.parametrize(
    ("written", "band"),
    [
        ("V", "V"),
        ("Johnson V", "V"),
        ("Bessell-V", "V"),
        ("bessell_v", "V"),
        ("Cousins R", "R"),
        ("Rc", "R"),
        ("R_C", "R"),
        ("Ic", "I"),
        ("B", "B"),
        ("r'", "r"),
        ("sdss-g", "g"),
        ("SDSS i'", "i"),
        ("z", "z"),
        ("bessell-I", "I"),
        ("sdss2010-r", "r"),
        ("decam2014-g", "decam2014-g"),
    ],
)
def test_filter_names_map_to_the_packages_bands(tmp_path, written, band):
    assert L.band_label(written) == band
    (tmp_path / "f.csv").write_text(
        f'time,filter,mag,err\n2024-03-17T01:21:00Z,"{written}",12,0.1\n'
    )
    lc = L.read_light_curve(tmp_path / "f.csv")
    assert lc.band.values.tolist() == [band]
    assert lc.filter_as_written.values.tolist() == [written]


def test_unknown_or_ambiguous_filters_are_refused_with_the_known_bands(tmp_path):
    for name, why in (
        ("Clear", "not a band the package knows; known: U B V R I"),
        ("Johnson R", "Johnson's own R differs from the Cousins R"),
        ("Johnson I", "Johnson's own I"),
        ("v", "ambiguous"),
        ("G", "not a band the package knows"),
    ):
        with pytest.raises(LightCurveError, match=why):
            L.band_label(name)
    (tmp_path / "w.csv").write_text(
        "time,Clear,Clear_err,V,V_err\n2024-03-17T01:21:00Z,11,0.1,12,0.1\n"
    )
    with pytest.raises(LightCurveError, match=r"column 'Clear': filter 'Clear': not a band"):
        L.read_light_curve(tmp_path / "w.csv")
    lc = L.read_light_curve(tmp_path / "w.csv", band_map={"Clear": "V"})
    assert lc.band.values.tolist() == ["V", "V"]
    (tmp_path / "noerr.csv").write_text("time,V,R,R_err\n2024-03-17T01:21:00Z,12,11,0.1\n")
    with pytest.raises(LightCurveError, match=r"column 'V' .* has no uncertainty column"):
        L.read_light_curve(tmp_path / "noerr.csv")


def test_wide_tables_need_an_uncertainty_for_every_value(tmp_path):
    (tmp_path / "gap.csv").write_text(
        "time,V,V_err\n2024-03-17T01:21:00Z,12,0.1\n2024-03-17T01:21:10Z,12.1,\n"
    )
    with pytest.raises(
        LightCurveError,
        match=r"row 2 \(line 3 of the file\), column 'V_err': "
        "no uncertainty for the value 12.1",
    ):
        L.read_light_curve(tmp_path / "gap.csv")
    (tmp_path / "none.csv").write_text("time,seeing\n2024-03-17T01:21:00Z,1.2\n")
    with pytest.raises(LightCurveError, match="no band column"):
        L.read_light_curve(tmp_path / "none.csv")


def test_long_table_nan_rows_are_named(tmp_path):
    (tmp_path / "nan.csv").write_text(
        "time,band,mag,err\n2024-03-17T01:21:00Z,V,12,0.1\n2024-03-17T01:21:10Z,V,nan,0.1\n"
    )
    with pytest.raises(
        LightCurveError,
        match=r"row 2 \(line 3 of the file\), column 'mag': "
        "value 'nan' is not a finite number",
    ):
        L.read_light_curve(tmp_path / "nan.csv")
