"""Tests of sbrdf_xr.observing.observe against skyfield, closed-form shadow geometry and shapely."""

from __future__ import annotations

import dataclasses
import datetime as dt
import json
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_profiles import examples
from scipy.optimize import brentq

from sbrdf_xr import catalog, geometry
from sbrdf_xr import observing as att
from sbrdf_xr.errors import (
    AttitudeError,
    EpochGapWarning,
    NotObservableError,
    ObservationError,
    ValidationError,
)
from sbrdf_xr.observing import observe, orbits

REPO = Path(__file__).resolve().parents[2]

# Agreement with skyfield's own evaluation of the same models.  The geometry is
# computed once for all times with IAU 2000B nutation and the topocentric angles in
# numpy; skyfield evaluates per call with IAU 2000A.  Nutation cancels in the
# site-relative ITRS vector, so the measured residuals are ~1e-12 deg and ~1e-11 km;
# the tolerances leave 1000x for platforms and library versions while staying far
# below anything photometry can see (1e-9 deg ~ 0.02 mm at 1000 km).
ANGLE_TOL_DEG = 1e-9
RANGE_TOL_KM = 1e-8
# The Sun direction: geocentric apparent Sun splined and aberrated by the spacecraft's
# geocentric velocity to first order, against skyfield's aberration by the summed
# barycentric velocity: they differ by the cross term |v_earth| |v_sat| / c^2 ~ 3e-9 rad
# (0.6 mas); 0.01 arcsec allowed.
SUN_TOL_ARCSEC = 0.01
# Phase angle: the same 0.6 mas plus 1 mas of nutation in the line of sight: 1e-6 deg.
PHASE_TOL_DEG = 1e-6


@pytest.fixture(scope="module")
def canx1():
    obs = observe.canx1_pass()
    return obs, obs.geometry()


def skyfield_times(t64):
    ts, _ = orbits.skyfield_data()
    py = [dt.datetime.fromisoformat(str(x)[:26]).replace(tzinfo=dt.UTC) for x in t64]
    return ts.from_datetimes(py), py


def test_topocentric_angles_and_range_against_skyfield(canx1):
    obs, g = canx1
    t, _ = skyfield_times(g.time.values)
    alt, az, dist = (obs.orbit.satellite - obs.site.position).at(t).altaz()
    d_el = np.abs(alt.degrees - g.elevation.values).max()
    d_az = np.abs((az.degrees - g.azimuth.values + 180.0) % 360.0 - 180.0).max()
    d_r = np.abs(dist.km - g.range.values).max()
    print(f"elevation {d_el:.2e} deg, azimuth {d_az:.2e} deg, range {d_r:.2e} km")
    assert d_el < ANGLE_TOL_DEG and d_az < ANGLE_TOL_DEG and d_r < RANGE_TOL_KM, (d_el, d_az, d_r)


def test_gcrs_state_against_skyfield_per_time_evaluation(canx1):
    # The splined nutation and equation of the equinoxes against skyfield's IAU 2000A at
    # every time: measured 5e-12 km; 1e-8 km (10 um) allowed.
    obs, g = canx1
    t, _ = skyfield_times(g.time.values)
    r_ref = obs.orbit.satellite.at(t).position.km.T
    site_ref = obs.site.position.at(t).position.km.T
    st_ = obs._state()
    assert np.abs(st_["r"] - r_ref).max() < 1e-8
    assert np.abs(st_["site"] - site_ref).max() < 1e-8


def test_sun_direction_and_phase_angle_against_skyfield(canx1):
    obs, g = canx1
    _, eph = orbits.skyfield_data()
    sat, site = obs.orbit.satellite, obs.site.position
    rot = geometry.rotation_matrices(g.quaternion.values)
    sun_ref = np.einsum("nij,nj->ni", rot, g.to_sun.values)  # back to the GCRS
    _, py = skyfield_times(g.time.values)
    ts, _ = orbits.skyfield_data()
    worst_sun = worst_phase = 0.0
    for i in range(0, g.sizes["time"], 20):  # one scalar skyfield evaluation per time
        ti = ts.from_datetime(py[i])
        s = (eph["earth"] + sat).at(ti).observe(eph["sun"]).apparent().position.km
        su = s / np.linalg.norm(s)
        worst_sun = max(
            worst_sun,
            3600
            * np.degrees(np.arctan2(np.linalg.norm(np.cross(su, sun_ref[i])), su @ sun_ref[i])),
        )
        los = (site - sat).at(ti).position.km
        phase = np.degrees(np.arctan2(np.linalg.norm(np.cross(s, los)), s @ los))
        worst_phase = max(worst_phase, abs(phase - g.phase_angle.values[i]))
        # Distances agree to 1e-8 au (1.5 km, 1e-8 relative): skyfield's aberrated vector
        # is displaced by v tau across the line of sight, the distance is kept here.
        assert abs(np.linalg.norm(s) / observe.AU_KM - g.sun_distance.values[i]) < 1e-8
    print(f"Sun direction residual {worst_sun:.2e} arcsec, phase angle {worst_phase:.2e} deg")
    assert worst_sun < SUN_TOL_ARCSEC, worst_sun
    assert worst_phase < PHASE_TOL_DEG, worst_phase
    # The body-frame pair carries the same phase angle (rotations preserve angles).
    np.testing.assert_allclose(
        geometry.phase_angle(g.to_sun.values, g.to_observer.values),
        g.phase_angle.values,
        atol=1e-10,
    )


def test_shadow_boundary_brackets_skyfield_is_sunlit(canx1):
    # skyfield's is_sunlit is a point Sun with a spherical Earth: its switch must fall in
    # the penumbra of our spherical Earth, where the disc is about half covered.
    obs = dataclasses.replace(canx1[0], earth="sphere")
    g = obs.geometry()
    _, eph = orbits.skyfield_data()
    t, _ = skyfield_times(g.time.values)
    lit = obs.orbit.satellite.at(t).is_sunlit(eph)
    switch = np.flatnonzero(np.diff(lit.astype(int)))
    assert switch.size == 1
    f = g.sunlit_fraction.values
    assert 0 < f[switch[0]] < 1 and 0 < f[switch[0] + 1] <= 1
    assert f[switch[0]] <= 0.5 <= f[switch[0] + 1]


# ----------------------------------------------------------------- Earth shadow, closed forms

R_E = observe.EARTH_EQUATORIAL_RADIUS_KM
R_S = observe.SUN_RADIUS_KM
MU = 398600.4418


def circular_shadow_times(radius, beta_deg, sun_distance, sun_radius):
    """Penumbra and umbra entry times of a circular orbit (model under test, a sphere)."""
    n = np.sqrt(MU / radius**3)
    beta = np.radians(beta_deg)
    s_hat = np.array([np.cos(beta), 0.0, np.sin(beta)])

    def frac(t):
        r = radius * np.array([np.cos(n * t), np.sin(n * t), 0.0])
        s = sun_distance * s_hat - r
        return float(observe.sunlit_fraction(r, s, sun_radius=sun_radius, earth="sphere"))

    x_cyl = np.sqrt(radius**2 - R_E**2)
    t_cyl = np.arccos(-x_cyl / (radius * np.cos(beta))) / n
    eps = 1e-12
    t_pen = brentq(lambda t: frac(t) - (1 - eps), t_cyl - 60, t_cyl + 1e-9, xtol=1e-10)
    t_umb = (
        brentq(lambda t: frac(t) - eps, t_cyl - 1e-9, t_cyl + 60, xtol=1e-10)
        if sun_radius > 0
        else t_pen
    )
    return n, t_pen, t_umb


@pytest.mark.parametrize(
    "radius,beta_deg", [(6378.137 + 500, 0.0), (6378.137 + 820, 35.0), (26560.0, 10.0)]
)
def test_shadow_entry_cylindrical_closed_form(radius, beta_deg):
    # Point Sun at a practically infinite distance: the cylinder rho = R_E, x > 0.
    n, t_pen, _ = circular_shadow_times(radius, beta_deg, 1e16, 0.0)
    x = np.sqrt(radius**2 - R_E**2)
    t_closed = np.arccos(-x / (radius * np.cos(np.radians(beta_deg)))) / n
    print(f"r={radius} beta={beta_deg}: cylinder {t_pen - t_closed:.2e} s")
    assert abs(t_pen - t_closed) < 1e-3, t_pen - t_closed  # [s]


@pytest.mark.parametrize(
    "radius,beta_deg", [(6378.137 + 500, 0.0), (6378.137 + 820, 35.0), (26560.0, 10.0)]
)
def test_shadow_entry_conical_closed_form(radius, beta_deg):
    # Penumbra: the internal tangent cone of Earth and Sun, apex d_p sunward of the Earth,
    # sin f_p = (R_S + R_E)/D; umbra: the external cone, apex d_u behind the Earth,
    # sin f_u = (R_S - R_E)/D.  A point at axial x (anti-Sun) and radius rho lies on them
    # where rho = (x + d_p) tan f_p, or rho = (d_u - x) tan f_u; with rho^2 = r^2 - x^2
    # each is a quadratic in x, and x = -r cos(theta) cos(beta) gives the orbit phase.
    d_sun = observe.AU_KM
    n, t_pen, t_umb = circular_shadow_times(radius, beta_deg, d_sun, R_S)
    cb = np.cos(np.radians(beta_deg))
    out = {}
    for kind, sin_f, d, sign in (
        ("pen", (R_S + R_E) / d_sun, None, +1),
        ("umb", (R_S - R_E) / d_sun, None, -1),
    ):
        d = R_E / sin_f
        tau2 = np.tan(np.arcsin(sin_f)) ** 2
        # (1 + tau2) x^2 + 2 sign tau2 d x + tau2 d^2 - r^2 = 0
        roots = np.roots([1 + tau2, 2 * sign * tau2 * d, tau2 * d * d - radius**2]).real
        x = roots[np.argmin(np.abs(roots - np.sqrt(radius**2 - R_E**2)))]
        out[kind] = np.arccos(-x / (radius * cb)) / n
    # Both within a millisecond (the root finder works to 1e-10 s; the fraction leaves 1
    # as the 3/2 power of the overlap depth, so eps = 1e-12 moves the root < 1e-6 s).
    print(
        f"r={radius} beta={beta_deg}: penumbra {t_pen - out['pen']:.2e} s, "
        f"umbra {t_umb - out['umb']:.2e} s"
    )
    assert abs(t_pen - out["pen"]) < 1e-3, t_pen - out["pen"]
    assert abs(t_umb - out["umb"]) < 1e-3, t_umb - out["umb"]
    assert t_umb - t_pen > 1.0  # a real penumbra of seconds


radii = st.floats(1e-4, 0.05)


@settings(max_examples=examples(200), deadline=None)
@given(radii, radii, st.floats(0.0, 1.0), st.floats(0.0, 1.0))
def test_sunlit_fraction_bounded_and_monotone_through_penumbra(a, b, u1, u2):
    lo, hi = abs(a - b), a + b
    c1, c2 = sorted([lo + u1 * (hi - lo), lo + u2 * (hi - lo)])
    f1, f2 = observe.disc_overlap_fraction(a, b, [c1, c2])
    assert 0.0 <= f1 <= 1.0 and 0.0 <= f2 <= 1.0
    assert f1 <= f2 + 1e-12  # uncovering grows with the separation
    # Continuous at the penumbra's edges.
    edge = observe.disc_overlap_fraction(a, b, [lo, hi, hi * 1.5, lo * (1 - 1e-12)])
    assert abs(edge[1] - 1) < 1e-9 and edge[2] == 1.0
    nested = 1 - min(a, b) ** 2 / a**2
    assert abs(edge[0] - nested) < 1e-6 and abs(edge[3] - nested) < 1e-6


@settings(max_examples=examples(40), deadline=None)
@given(st.floats(0.5, 2.0), st.floats(0.2, 5.0), st.floats(0.0, 1.0))
def test_disc_overlap_against_shapely_polygons(a, ratio, u):
    shapely = pytest.importorskip("shapely")
    b = a * ratio
    c = abs(a - b) + u * 2 * min(a, b)
    sun = shapely.Point(0, 0).buffer(a, quad_segs=512)
    earth = shapely.Point(c, 0).buffer(b, quad_segs=512)
    expected = 1 - sun.intersection(earth).area / sun.area
    # 2048-gons: relative area error ~ (pi/2048)^2 / 3 ~ 1e-6 per disc, scaled by b/a.
    assert abs(float(observe.disc_overlap_fraction(a, b, c)) - expected) < 2e-5 * max(1.0, ratio)


def test_point_sun_is_a_step():
    np.testing.assert_array_equal(
        observe.disc_overlap_fraction(0.0, 0.1, [0.05, 0.1, 0.2]), [0.0, 1.0, 1.0]
    )


# ----------------------------------------------------------------- observation outputs


def test_canx1_pass_geometry(canx1):
    _, g = canx1
    assert g.sizes["time"] == 301 and g.time.dtype == np.dtype("datetime64[ns]")
    for key in (
        "tle_line1",
        "tle_line2",
        "site_latitude",
        "site_longitude",
        "site_height",
        "site_name",
    ):
        assert key in g.attrs
    assert g.attrs["tle_line1"].startswith("1 27847U") and g.attrs["site_name"] == "mont-megantic"
    assert g.attrs["site_latitude"] == pytest.approx(45.4555)
    f = g.sunlit_fraction.values
    assert f[0] == 0.0 and f[-1] == 1.0 and np.all(np.diff(f) >= -1e-12)  # an eclipse exit
    assert (f == 1).mean() > 0.75
    assert g.elevation.min() > 20 and g.site_sun_elevation.max() < -18
    assert np.all(np.isfinite(g.airmass)) and g.airmass.min() >= 1
    for name in ("to_sun", "to_observer", "to_earth"):
        np.testing.assert_allclose(np.linalg.norm(g[name].values, axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(g.quaternion.values, axis=1), 1.0, atol=1e-12)
    assert np.all(np.einsum("ni,ni->n", g.quaternion.values[1:], g.quaternion.values[:-1]) > 0)
    for name, var in {**g.data_vars, **g.coords}.items():
        if name != "time":
            assert var.attrs.get("units") and var.attrs.get("long_name"), name
    # 820 km orbit: range from the altitude up to the slant range at 20 deg.
    assert 800 < g.range.min() < g.range.max() < 2500
    assert np.all((g.sun_distance > 0.98) & (g.sun_distance < 1.0))


def test_airmass_model():
    # Kasten & Young (1989): 1 at the zenith, 37.92 at the horizon, sec z nearby.
    am = observe.airmass([90.0, 30.0, 0.0, -5.0])
    assert am[0] == pytest.approx(1.0, abs=1e-3) and am[1] == pytest.approx(1.995, abs=2e-3)
    assert am[2] == pytest.approx(37.92, abs=0.01) and np.isnan(am[3])
    with pytest.raises(ValidationError, match="allowed: 'simple'"):
        observe.airmass(10.0, "magic")


def test_geometry_round_trips_through_netcdf(canx1, tmp_path):
    _, g = canx1
    path = tmp_path / "geometry.nc"
    g.to_netcdf(path)
    with xr.open_dataset(path, decode_times=False) as raw:
        assert (
            raw.time.attrs["units"].startswith("seconds since")
            and raw.time.attrs["standard_name"] == "time"
        )
    with xr.open_dataset(path) as back:
        np.testing.assert_array_equal(back.time.values, g.time.values)
        xr.testing.assert_allclose(back.load(), g)
    series = att.QuaternionSeries.from_netcdf(path)
    np.testing.assert_allclose(
        np.abs(np.einsum("ni,ni->n", series.quaternions(g.time.values), g.quaternion.values)),
        1.0,
        atol=1e-12,
    )


def test_nadir_observation_points_at_the_geocentre(canx1):
    obs, _ = canx1
    nadir = observe.Observation(
        obs.orbit, obs.site, obs.times, att.Nadir(yaw=20.0, nadir_axis="+z")
    )
    to_earth = nadir.geometry().to_earth.values
    angle = np.arctan2(np.hypot(to_earth[:, 0], to_earth[:, 1]), to_earth[:, 2])
    assert angle.max() < 1e-9  # [rad]


def test_observation_from_toml_table():
    text = """
    [observation]
    orbit = "canx1-example"
    site = "mont-megantic"
    start = "2024-03-17T01:20:00"
    stop = "2024-03-17T01:25:00"
    step_s = 1.0
    [observation.attitude]
    law = "spin"
    axis_body = [0.3, 0.4, 0.866]
    rate_deg_s = 4.0
    initial = {law = "inertial", q = [0.2, -0.1, 0.3, 0.92736185]}
    """
    obs = observe.observation_from_dict(tomllib.loads(text)["observation"])
    ref = observe.canx1_pass()
    np.testing.assert_array_equal(obs.times, ref.times)
    xr.testing.assert_allclose(obs.geometry().drop_attrs(), ref.geometry().drop_attrs())
    # Explicit TLE lines and site coordinates.
    e = catalog.entry("canx1-example")
    lines = e.file.read_text().splitlines()
    table = {
        "tle": lines[1:3],
        "site": {"latitude_deg": 45.4555, "longitude_deg": -71.1526, "height_m": 1114.0},
        "times": ["2024-03-17T01:21:00", "2024-03-17T01:22:00"],
        "attitude": {"law": "nadir"},
    }
    g = observe.observation_from_dict(table).geometry()
    assert g.sizes["time"] == 2
    with pytest.raises(ObservationError, match="unknown key"):
        observe.observation_from_dict({**table, "sight": 1})
    with pytest.raises(ObservationError, match=r"\['stepp_s'\]; did you mean 'step_s'\?"):
        observe.observation_from_dict({**table, "stepp_s": 1.0})
    with pytest.raises(ObservationError, match="exactly one of"):
        observe.observation_from_dict({k: v for k, v in table.items() if k != "tle"})
    with pytest.raises(AttitudeError, match="unknown law"):
        observe.observation_from_dict({**table, "attitude": {"law": "wobble"}})


def test_omm_gives_the_same_orbit(tmp_path):
    from sgp4 import exporter

    tle = observe.Orbit.from_catalog("canx1-example")
    fields = exporter.export_omm(tle.satellite.model, "CANX-1")
    t = observe.times("2024-03-17T01:20:00", "2024-03-17T01:21:00", 10.0)
    path = tmp_path / "omm.json"
    path.write_text(json.dumps([fields]))
    for source in (fields, path):
        omm = observe.Orbit.from_omm(source)
        a = observe.Observation(tle, observe.Site(45, -71), t, None, min_elevation=-90).geometry(
            on_unobservable="keep"
        )
        b = observe.Observation(omm, observe.Site(45, -71), t, None, min_elevation=-90).geometry(
            on_unobservable="keep"
        )
        np.testing.assert_allclose(
            a.range.values, b.range.values, atol=1e-6
        )  # same elements: < 1 mm
    with pytest.raises(ObservationError, match="OMM"):
        observe.Orbit.from_omm({"OBJECT_NAME": "X"})


@pytest.mark.parametrize("norad", ["1e30", "9" * 5000])
def test_omm_with_an_out_of_range_catalogue_number_is_refused_by_name(tmp_path, norad):
    from sgp4 import exporter

    fields = exporter.export_omm(observe.Orbit.from_catalog("canx1-example").satellite.model, "X")
    text = json.dumps({**fields, "NORAD_CAT_ID": 0})
    path = tmp_path / "omm.json"
    path.write_text(text.replace('"NORAD_CAT_ID": 0', f'"NORAD_CAT_ID": {norad}'))
    with pytest.raises(ObservationError, match="omm") as info:
        observe.Orbit.from_omm(path)
    assert str(path) in str(info.value)


def test_times_helper():
    t = observe.times("2024-01-01T00:00:00Z", dt.datetime(2024, 1, 1, 0, 0, 3, tzinfo=dt.UTC), 0.5)
    assert t.dtype == np.dtype("datetime64[ns]") and t.size == 7
    assert t[-1] == np.datetime64("2024-01-01T00:00:03", "ns")
    with pytest.raises(ObservationError, match="positive"):
        observe.times("2024-01-01", "2024-01-02", 0)
    with pytest.raises(ObservationError, match="before start"):
        observe.times("2024-01-02", "2024-01-01", 1)


# ----------------------------------------------------------------- bad input


def tle_lines():
    lines = catalog.entry("canx1-example").file.read_text().splitlines()
    return lines[1], lines[2]


def with_checksum(line):
    return line[:68] + str(observe.tle_checksum(line))


def test_malformed_tles_raise_named_errors():
    l1, l2 = tle_lines()
    bad_sum = l1[:68] + str((int(l1[68]) + 1) % 10)
    with pytest.raises(ObservationError, match="checksum"):
        observe.Orbit.from_tle(bad_sum, l2)
    with pytest.raises(ObservationError, match="69"):
        observe.Orbit.from_tle(l1[:60], l2)
    with pytest.raises(ObservationError, match="must start with '2 '"):
        observe.Orbit.from_tle(l1, "3" + l2[1:])
    with pytest.raises(ObservationError, match="catalog numbers differ"):
        observe.Orbit.from_tle(l1, with_checksum(l2[:2] + "27848" + l2[7:]))
    with pytest.raises(
        ObservationError, match="field 'eccentricity' \\(columns 27-33\\) is '00X2000'"
    ):
        observe.Orbit.from_tle(l1, with_checksum(l2[:26] + "00X2000" + l2[33:]))
    with pytest.raises(ObservationError, match="SGP4 rejects the elements"):  # mean motion 0
        observe.Orbit.from_tle(l1, with_checksum(l2[:52] + " 0.00000000" + l2[63:]))
    assert issubclass(ObservationError, ValidationError)


def test_site_range_checks():
    with pytest.raises(ObservationError, match="latitude: got 91"):
        observe.Site(91.0, 0.0)
    with pytest.raises(ObservationError, match="site height: got 20000"):
        observe.Site(10.0, 0.0, 20000.0)
    with pytest.raises(ObservationError, match="expected a number"):
        observe.Site("north", 0.0)
    assert observe.Site(0.0, 350.0).longitude == pytest.approx(-10.0)
    with pytest.raises(ObservationError, match="not a site"):
        observe.Site.from_catalog("canx1-example")


def test_times_far_from_the_epoch_warn(canx1):
    obs, _ = canx1
    late = observe.times("2024-04-20T00:00:00", "2024-04-20T00:00:10", 1.0)
    with pytest.warns(EpochGapWarning, match=r"35\.5 days from the epoch"):
        observe.Observation(obs.orbit, obs.site, late, None)
    with pytest.raises(ObservationError, match="strictly increasing"):
        observe.Observation(obs.orbit, obs.site, obs.times[::-1], None)
    with pytest.raises(ObservationError, match="datetime64"):
        observe.Observation(obs.orbit, obs.site, np.arange(3.0), None)


def test_unobservable_windows(canx1):
    obs, _ = canx1
    below = observe.Observation(
        obs.orbit, obs.site, observe.times("2024-03-17T02:20", "2024-03-17T02:21", 1.0)
    )
    with pytest.raises(NotObservableError, match="below 0 deg elevation at every time"):
        below.geometry()
    empty = below.geometry(on_unobservable="empty")
    assert empty.sizes["time"] == 0 and "below" in empty.attrs["unobservable"]
    assert below.geometry(on_unobservable="keep").sizes["time"] == 61
    dark = observe.Observation(
        obs.orbit, obs.site, observe.times("2024-03-17T01:19:00", "2024-03-17T01:20:00", 1.0)
    )
    with pytest.raises(NotObservableError, match="umbra at every time"):
        dark.geometry()
    with pytest.raises(ObservationError, match="on_unobservable"):
        dark.geometry(on_unobservable="skip")


def test_catalog_ships_the_orbit_and_sites():
    assert "canx1-example" in catalog.names("orbit")
    assert {"mont-megantic", "haleakala"} <= set(catalog.names("site"))
    for name in catalog.names("site"):
        site = catalog.load(name)
        assert isinstance(site, observe.Site) and site.name == name
    orbit = catalog.load("canx1-example")
    assert orbit.epoch == np.datetime64("2024-03-15T12:00:00", "ns")
    assert "not a published element set" in orbit.provenance


def test_no_network_is_needed(tmp_path):
    code = (
        "import socket\n"
        "def refuse(*a, **k):\n    raise OSError('network disabled')\n"
        "socket.socket.connect = refuse\nsocket.create_connection = refuse\n"
        "from sbrdf_xr.observing import observe\n"
        "g = observe.canx1_pass().geometry()\n"
        "print(g.sizes['time'])\n"
    )
    res = subprocess.run(
        [sys.executable, "-W", "error::RuntimeWarning", "-c", code],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=False,
        env={"PYTHONPATH": str(REPO), "PATH": "/usr/bin:/bin", "HOME": str(tmp_path)},
    )
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == "301"
    assert not list(tmp_path.glob("*.bsp")) and not list(tmp_path.glob("finals*"))
