"""Tests of sbrdf_xr.observing.passes against skyfield's find_events and is_sunlit."""

from __future__ import annotations

import numpy as np
import pytest

from sbrdf_xr.errors import ObservationError
from sbrdf_xr.observing import Observation, Orbit, Site
from sbrdf_xr.observing.ephemeris import Ephemeris
from sbrdf_xr.observing.passes import visible_passes
from sbrdf_xr.observing.timescales import skyfield_data, skyfield_time, skyfield_utc, times

# skyfield's find_events refines its events to half a second (sgp4lib: half_second);
# ours to 1 ms.  Against skyfield's own altaz() at our edge times the elevation is the
# threshold to the edge tolerance times the elevation rate (< 1 deg s-1): 1e-3 deg.
FIND_EVENTS_TOL_S = 1.0
EDGE_ELEVATION_TOL_DEG = 1e-3
# is_sunlit (point Sun, sphere of 6378.1366 km) against the half-disc edge of the
# package's spherical Earth (6378.137 km, apparent Sun): the same edge to the 0.1-s grid
# the transitions are sampled on, plus the 0.4 mm of radius; 0.5 s.
SUNLIT_TOL_S = 0.5
WINDOW = ("2024-03-16T00:00:00", "2024-03-18T00:00:00")


@pytest.fixture(scope="module")
def canx1():
    return Orbit.from_catalog("canx1-example"), Site.from_catalog("mont-megantic")


@pytest.fixture(scope="module")
def all_passes(canx1):
    orbit, site = canx1
    return visible_passes(orbit, site, *WINDOW, include_invisible=True, earth="sphere")


def _s(a, b):
    return abs(float((np.datetime64(a, "ns") - np.datetime64(b, "ns")) / np.timedelta64(1, "ns")))


def test_rise_culmination_set_match_skyfield(canx1, all_passes):
    orbit, site = canx1
    a, b = skyfield_utc(np.array(WINDOW, dtype="datetime64[ns]"))
    when, kind = orbit.satellite.find_events(site.position, a, b, altitude_degrees=10.0)
    stamps = np.array([np.datetime64(w.replace(tzinfo=None), "ns") for w in when.utc_datetime()])
    p = all_passes
    ours = {0: p.rise.values, 1: p.culmination.values, 2: p.set.values}
    for k in (0, 1, 2):
        sky = stamps[kind == k]
        mine = ours[k][1:] if k == 0 else ours[k]  # the first pass is under way at the start
        assert sky.size == mine.size
        assert max(_s(x, y) for x, y in zip(sky, mine, strict=True)) / 1e9 < FIND_EVENTS_TOL_S
    edges = np.concatenate([p.rise.values[1:], p.set.values])
    alt = (orbit.satellite - site.position).at(skyfield_time(np.sort(edges))).altaz()[0].degrees
    assert np.abs(alt - 10.0).max() < EDGE_ELEVATION_TOL_DEG


def test_shadow_edges_match_is_sunlit_and_the_penumbra(canx1, all_passes):
    orbit, site = canx1
    _, eph = skyfield_data()
    exits = all_passes.shadow_exit.values
    exits = exits[~np.isnat(exits)]
    assert exits.size == 4
    for e in exits:
        grid = e + np.arange(-300, 301) * np.timedelta64(100, "ms")
        lit = orbit.satellite.at(skyfield_time(grid)).is_sunlit(eph)
        k = int(np.flatnonzero(~lit[:-1] & lit[1:])[0])
        assert _s(grid[k], e) / 1e9 < SUNLIT_TOL_S
        g = Observation(orbit, site, grid, earth="sphere").geometry(on_unobservable="keep")
        pen_in = np.datetime64(
            g.attrs["umbra_exit"].split()[0] if g.attrs["umbra_exit"] else grid[0]
        )
        pen_out = np.datetime64(g.attrs["penumbra_exit"].split()[0])
        assert pen_in <= e <= pen_out  # the half-disc edge lies inside the penumbra


def test_visible_part_dark_sunlit_and_up(canx1, all_passes):
    orbit, site = canx1
    p = all_passes.where(all_passes.visible_duration > 0, drop=True)
    assert p.sizes["pass"] == 3
    for k in range(3):
        t = times(p.visible_start.values[k], p.visible_stop.values[k], 5.0)
        g = Observation(orbit, site, t, min_elevation=-90).geometry(on_unobservable="keep")
        assert g.elevation.min() > 10.0 - 1e-3 and g.sunlit_fraction.min() > 0.5 - 1e-3
        assert g.site_sun_elevation.max() < -12.0 + 1e-3
    mags = p.peak_magnitude.values
    assert np.all((mags > 3) & (mags < 9))  # 1 m2, albedo 0.2, at 800-1700 km
    short = (WINDOW[0], "2024-03-16T02:00:00")  # the first two visible passes
    darker = visible_passes(orbit, site, *short, twilight="astronomical", earth="sphere")
    assert darker.sizes["pass"] <= 2
    assert darker.visible_duration.sum() <= p.visible_duration[:2].sum() + 1e-3


def test_passes_from_an_ephemeris_match_the_elements(canx1, all_passes):
    orbit, site = canx1
    t = times("2024-03-17T01:10:00", "2024-03-17T01:35:00", 30.0)
    geo = orbit.satellite.at(skyfield_time(t))
    eph = Ephemeris.from_states(t, geo.position.km.T, geo.velocity.km_per_s.T, name="canx1")
    p = visible_passes(eph, site, *WINDOW, earth="sphere")
    ref = all_passes.sel({"pass": 5})
    assert p.sizes["pass"] == 1
    for k in ("rise", "set", "visible_start", "visible_stop"):
        assert _s(p[k].values[0], ref[k].values) / 1e9 < 0.01, k  # Hermite at 30 s


def test_bad_arguments(canx1):
    orbit, site = canx1
    with pytest.raises(ObservationError, match="twilight: got 'dusk'"):
        visible_passes(orbit, site, *WINDOW, twilight="dusk")
    with pytest.raises(ObservationError, match="not after start"):
        visible_passes(orbit, site, WINDOW[1], WINDOW[0])
