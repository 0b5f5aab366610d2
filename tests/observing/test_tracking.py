"""Tests of sbrdf_xr.observing.tracking and tracking_io: geometry from an observer's table."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from astropy import units as u
from astropy.coordinates import EarthLocation
from skyfield.framelib import itrs

from sbrdf_xr.errors import AttitudeError, SbrdfWarning, TrackingTableError
from sbrdf_xr.observing import canx1_pass
from sbrdf_xr.observing.attitude import Nadir
from sbrdf_xr.observing.timescales import skyfield_time
from sbrdf_xr.observing.tracking import TrackingTable
from sbrdf_xr.observing.tracking_io import read_pomenis, read_tracking_table

HERE = Path(__file__).resolve().parent
EXCERPT = HERE / "data" / "pomenis" / "pomenis_observations_first40.csv"
FULL = [
    HERE.parents[1].parent / "shared" / "data" / "satellite-optical-brightness",
    Path("/work/shared/data/satellite-optical-brightness"),
]

# The table route inverts the observation's own topocentric geometry with the same
# rotations, so quantities that do not depend on the velocity agree to rounding
# (measured <= 3e-11 relative, site_sun_elevation the largest); the brief's bound is 1e-9.
RTOL = 1e-9
# Quantities that depend on the velocity through the Sun's aberration (v/c) or the
# attitude law: the spline-derivative velocity of 1-s samples differs from SGP4's by
# <= 1e-5 km s-1 (measured 9.5e-6, 1.3e-6 relative), which moves the aberrated Sun by
# ~3e-11 rad and a nadir attitude's along-track axis by ~1.3e-6 rad.
SUNLIT_ATOL = 1e-8
VELOCITY_ATOL_KM_S = 3e-5
NADIR_ATOL = 3e-6
NOT_VELOCITY = (
    "range",
    "elevation",
    "azimuth",
    "airmass",
    "earth_distance",
    "phase_angle",
    "solar_elongation",
    "site_sun_elevation",
)


@pytest.fixture(scope="module")
def tle_pass():
    obs = canx1_pass()
    return obs, obs.geometry()


def _rel(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return float(np.nanmax(np.abs(a - b) / np.maximum(np.abs(a), 1e-300)))


def test_altaz_range_table_gives_the_tle_cube(tle_pass):
    obs, g = tle_pass
    table = TrackingTable(
        obs.site,
        obs.times,
        elevation=g.elevation.values,
        azimuth=g.azimuth.values,
        range=g.range.values,
    )
    g2 = table.observation(obs.attitude).geometry()
    for k in NOT_VELOCITY:
        assert _rel(g[k], g2[k]) < RTOL, k
    for k in ("to_observer", "to_earth", "quaternion"):  # spin law: no velocity used
        assert np.abs(g[k].values - g2[k].values).max() < RTOL, k
    assert np.abs(g.to_sun.values - g2.to_sun.values).max() < 1e-9
    assert np.abs(g.sunlit_fraction.values - g2.sunlit_fraction.values).max() < SUNLIT_ATOL
    v_tle = obs._state()["v"]
    v_tab = table.observation(obs.attitude)._state()["v"]
    assert np.abs(v_tle - v_tab).max() < VELOCITY_ATOL_KM_S
    assert g2.attrs["orbit_name"] == "tracking table" and "tle_line1" not in g2.attrs


def test_nadir_law_through_the_spline_velocity(tle_pass):
    obs, g = tle_pass
    law = Nadir(yaw=10.0)
    ref = canx1_pass(law).geometry()
    table = TrackingTable(
        obs.site,
        obs.times,
        elevation=g.elevation.values,
        azimuth=g.azimuth.values,
        range=g.range.values,
    )
    g2 = table.observation(law).geometry()
    for k in ("to_sun", "to_observer", "quaternion"):
        assert np.abs(ref[k].values - g2[k].values).max() < NADIR_ATOL, k
    assert _rel(ref.phase_angle, g2.phase_angle) < RTOL


def _heights(obs):
    r = obs._state()["r"]
    rot = itrs.rotation_at(skyfield_time(obs.times))
    x = np.einsum("ijn,nj->ni", rot, r)
    loc = EarthLocation.from_geocentric(x[:, 0], x[:, 1], x[:, 2], unit=u.km)
    return loc.to_geodetic("WGS84").height.to_value(u.km)


def test_height_route_and_range_height_check(tle_pass):
    obs, g = tle_pass
    h = _heights(obs)  # astropy/ERFA geodetic heights of the SGP4 positions
    kw = {"elevation": g.elevation.values, "azimuth": g.azimuth.values}
    table = TrackingTable(obs.site, obs.times, height=h, **kw)
    assert _rel(g.range.values, table.ranges()) < RTOL
    g2 = table.observation(obs.attitude).geometry()
    assert _rel(g.phase_angle, g2.phase_angle) < RTOL
    TrackingTable(obs.site, obs.times, height=h, range=g.range.values, **kw)  # agree
    bad = h.copy()
    bad[7] += 5.0
    with pytest.raises(TrackingTableError, match=r"row 7: range .* disagrees with height"):
        TrackingTable(obs.site, obs.times, height=bad, range=g.range.values, **kw)


def test_radec_route(tle_pass):
    obs, g = tle_pass
    st = obs._state()
    los = st["r"] - st["site"]
    ra = np.degrees(np.arctan2(los[:, 1], los[:, 0])) % 360.0
    dec = np.degrees(np.arctan2(los[:, 2], np.hypot(los[:, 0], los[:, 1])))
    table = TrackingTable(obs.site, obs.times, ra=ra, dec=dec, range=g.range.values)
    assert np.abs(table.positions() - st["r"]).max() < RTOL * 7000.0
    assert np.abs(table.elevations() - g.elevation.values).max() < 1e-9


def test_bad_rows_are_named(tle_pass):
    obs, g = tle_pass
    kw = {"azimuth": g.azimuth.values, "range": g.range.values}
    el = g.elevation.values.copy()
    el[3] = -2.5
    with pytest.raises(TrackingTableError, match=r"row 3: elevation -2.5 deg is below -2"):
        TrackingTable(obs.site, obs.times, elevation=el, **kw)
    el[3] = np.nan
    with pytest.raises(TrackingTableError, match="row 3: elevation is nan"):
        TrackingTable(obs.site, obs.times, elevation=el, **kw)
    with pytest.raises(TrackingTableError, match="exactly one pair"):
        TrackingTable(obs.site, obs.times, range=g.range.values)
    with pytest.raises(TrackingTableError, match="range or height"):
        TrackingTable(obs.site, obs.times, elevation=g.elevation.values, azimuth=kw["azimuth"])


def _csv(tmp_path, body, header="time,el,az,rng"):
    p = tmp_path / "t.csv"
    p.write_text("# a comment\n" + header + "\n" + body)
    return p


def test_reader_checks_every_row(tmp_path, tle_pass):
    obs, _ = tle_pass
    site = obs.site
    ok = "2024-03-17T01:22:00Z,75.8,10.0,841.0\n"
    read = dict(elevation="el", azimuth="az", range_column="rng")
    t = read_tracking_table(_csv(tmp_path, ok), site, **read)
    assert t.rows.tolist() == [3] and t.times.size == 1
    cases = {
        "2024-03-17T01:22:05,75.9,12.0,840\n": "line 4: time .* has no time zone",
        "2024-03-17T01:22:05Z,,12.0,840\n": "line 4: column 'el' is empty",
        "2024-03-17T01:22:05Z,x,12.0,840\n": "line 4: column 'el' is 'x', not a number",
        "2024-03-17T01:22:05Z,-3,12.0,840\n": "line 4: elevation -3 deg is below",
        "2024-03-17T01:22:00Z,70,12.0,840\n": "lines 3 and 4 have the same time",
        ",70,12.0,840\n": "line 4: the time is missing",
    }
    for line, msg in cases.items():
        with pytest.raises(TrackingTableError, match=msg):
            read_tracking_table(_csv(tmp_path, ok + line), site, **read)
    with pytest.raises(TrackingTableError, match=r"lacks the column\(s\) \['rng'\]"):
        read_tracking_table(_csv(tmp_path, ok, "time,el,az,range"), site, **read)
    local = "2024-03-16T20:22:05-05:00,75.9,12.0,840\n"  # an offset is converted to UTC
    t2 = read_tracking_table(_csv(tmp_path, ok + local), site, **read)
    assert str(t2.times[1]) == "2024-03-17T01:22:05.000000000"
    assert (
        read_tracking_table(
            _csv(tmp_path, "2024-03-17T01:22:00,75.8,10.0,841.0\n"), site, time_zone="UTC", **read
        ).times.size
        == 1
    )
    bad = ok + "2024-03-17T01:22:05Z,x,12.0,840\n2024-03-17T01:22:09Z,70,12.0,\n"
    with pytest.warns(SbrdfWarning, match=r"2 row\(s\) dropped"):
        t3 = read_tracking_table(_csv(tmp_path, bad), site, on_bad="drop", **read)
    assert t3.times.size == 1 and [d[0] for d in t3.dropped] == [4, 5]


def test_pomenis_excerpt_is_utc_dark_site_sunlit_satellite():
    table = read_pomenis(EXCERPT)
    assert table.times.size == 40 and not table.dropped
    assert table.rows.min() == 19  # the first data line of the file
    obs = table.observation({"law": "inertial", "q": [0.0, 0.0, 0.0, 1.0]})
    g = obs.geometry()
    # Times read as UTC put the site in astronomical twilight or darker and every
    # satellite in sunlight (read as local time, 13:28 would be day at Mount Lemmon).
    assert g.site_sun_elevation.max() < -10.0 and g.sunlit_fraction.min() > 0.4
    assert np.abs(g.elevation.values - table.elevation).max() < 1e-9
    assert np.abs(g.azimuth.values - table.azimuth).max() < 1e-9
    assert table.tracks().max() == 39  # one satellite per row: no velocity
    with pytest.raises(AttitudeError, match="velocity is unknown"):
        table.observation(Nadir()).geometry()


def test_pomenis_header_must_state_utc(tmp_path):
    text = EXCERPT.read_text().replace("Observation Time : UTC", "Observation Time : MST")
    p = tmp_path / "p.csv"
    p.write_text(text)
    with pytest.raises(TrackingTableError, match="does not state 'Observation Time : UTC'"):
        read_pomenis(p)


@pytest.mark.slow
def test_full_pomenis_table():
    folder = next((f for f in FULL if (f / "pomenis_observations.csv").exists()), None)
    if folder is None:
        pytest.skip("the shared Pomenis data is not beside the repository")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        table = read_pomenis(folder / "pomenis_observations.csv")
    assert table.times.size == 1173 and not table.dropped
    g = table.observation({"law": "inertial", "q": [0.0, 0.0, 0.0, 1.0]}).geometry()
    assert float(g.site_sun_elevation.max()) < -10.0
    assert float(g.sunlit_fraction.min()) > 0.4


def test_radec_quantities_are_converted(tle_pass):
    from sbrdf_xr.errors import UnitError

    obs, g = tle_pass
    st = obs._state()
    los = st["r"] - st["site"]
    ra = np.degrees(np.arctan2(los[:, 1], los[:, 0])) % 360.0
    dec = np.degrees(np.arctan2(los[:, 2], np.hypot(los[:, 0], los[:, 1])))
    bare = TrackingTable(obs.site, obs.times, ra=ra, dec=dec, range=g.range.values)
    qty = TrackingTable(
        obs.site,
        obs.times,
        ra=np.radians(ra) * u.rad,
        dec=np.radians(dec) * u.rad,
        range=g.range.values * u.km,
    )
    np.testing.assert_allclose(qty.positions(), bare.positions(), rtol=1e-12)
    with pytest.raises(UnitError, match=r"\bdec\b"):
        TrackingTable(obs.site, obs.times, ra=ra, dec=dec * u.kg, range=[1.0])


def test_old_field_names_answer_with_a_warning(tle_pass):
    """The fields named with their unit (one release): same table, a RenamedWarning each."""
    from sbrdf_xr.errors import RenamedWarning, ValidationError

    obs, g = tle_pass
    new = TrackingTable(
        obs.site,
        obs.times,
        elevation=g.elevation.values,
        azimuth=g.azimuth.values,
        range=g.range.values,
        max_gap=60.0,
    )
    with pytest.warns(RenamedWarning) as caught:
        old = TrackingTable(
            obs.site,
            obs.times,
            elevation_deg=g.elevation.values,
            azimuth_deg=g.azimuth.values,
            range_km=g.range.values,
            max_gap_s=60.0,
        )
    said = " ".join(str(w.message) for w in caught)
    for name in ("elevation_deg", "azimuth_deg", "range_km", "max_gap_s"):
        assert f"'{name}' is renamed" in said
    np.testing.assert_array_equal(old.positions(), new.positions())
    assert old.max_gap == new.max_gap == 60.0
    for old_name, new_name in (
        ("elevation_deg", "elevation"),
        ("azimuth_deg", "azimuth"),
        ("ra_deg", "ra"),
        ("dec_deg", "dec"),
        ("range_km", "range"),
        ("height_km", "height"),
        ("max_gap_s", "max_gap"),
    ):
        with pytest.warns(RenamedWarning, match=f"TrackingTable.{old_name} is renamed"):
            value = getattr(new, old_name)
        assert value is getattr(new, new_name)
    with pytest.raises(ValidationError, match="received both 'range_km' and 'range'"):
        TrackingTable(obs.site, obs.times, range=[1.0], range_km=[1.0])


@pytest.mark.parametrize(
    "columns",
    [
        ("elevation", "azimuth", "range"),
        ("elevation_deg", "azimuth_deg", "range_km"),
        ("elevation", "azimuth_deg", "height"),
        ("elevation_deg", "azimuth", "height_km"),
    ],
)
def test_files_name_columns_bare_or_with_their_unit(tmp_path, tle_pass, columns):
    """A file's direction, range and height columns are read under either spelling, by the
    reader and by a scene file's [observation.tracking] table (which finds the range or
    height column itself)."""
    from sbrdf_xr.observing.tracking_io import tracking_from_dict

    obs, g = tle_pass
    g = g.isel(time=slice(60, 66))
    third = g.range.values if columns[2].startswith("range") else _heights(obs)[60:66]
    rows = [
        f"{str(t)[:23]}Z,{float(e)!r},{float(a)!r},{float(x)!r}"
        for t, e, a, x in zip(
            g.time.values, g.elevation.values, g.azimuth.values, third, strict=True
        )
    ]
    path = _csv(tmp_path, "\n".join(rows) + "\n", "time," + ",".join(columns))
    reference = TrackingTable(
        obs.site,
        g.time.values,
        elevation=g.elevation.values,
        azimuth=g.azimuth.values,
        range=g.range.values,
    )
    kind = "range_column" if columns[2].startswith("range") else "height_column"
    for name in (columns[2].removesuffix("_km"), columns[2].removesuffix("_km") + "_km"):
        read = read_tracking_table(path, obs.site, **{kind: name})
        assert _rel(read.ranges(), reference.ranges()) < RTOL
    found = tracking_from_dict({"path": str(path)}, obs.site)
    np.testing.assert_allclose(found.positions(), reference.positions(), rtol=RTOL, atol=0)
    read = read_tracking_table(
        path, obs.site, elevation="elevation_deg", azimuth="azimuth_deg", **{kind: columns[2]}
    )
    np.testing.assert_allclose(read.positions(), reference.positions(), rtol=RTOL, atol=0)
