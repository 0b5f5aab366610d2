"""YawSteering: a body axis on the geodetic (or geocentric) nadir, another toward the Sun;
geodetic_up against astropy; the built-in Starlink array under it and under Nadir."""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest
from astropy.coordinates import EarthLocation
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from sbrdf_xr.body.starlink import starlink_v15
from sbrdf_xr.errors import AttitudeError
from sbrdf_xr.observing import Context, Nadir, Observation, Orbit, Site, YawSteering, times
from sbrdf_xr.observing.attitude import geodetic_up, law_from_dict

# Rotations and unit vectors in float64: 1e-9 is rounding after a few products, not method.
TOL = 1e-9


@settings(max_examples=60, deadline=None)
@given(st.floats(-89.9, 89.9), st.floats(-180.0, 180.0), st.floats(200.0, 36000.0))
def test_geodetic_up_matches_astropy(lat, lon, height_km):
    loc = EarthLocation.from_geodetic(lon * u.deg, lat * u.deg, height_km * u.km)
    x = np.array([[loc.x.to_value(u.km), loc.y.to_value(u.km), loc.z.to_value(u.km)]])
    la, lo = np.radians(lat), np.radians(lon)
    want = [np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la)]
    # astropy's ERFA gd2gc round trip is exact to ~1e-12 rad; the iteration reaches 1e-12.
    np.testing.assert_allclose(geodetic_up(x)[0], want, atol=1e-10)


def _ctx(r, sun):
    return Context(position=np.atleast_2d(r), sun=np.atleast_2d(sun))


def test_the_axes_go_down_the_vertical_and_toward_the_sun():
    rng = np.random.default_rng(0)
    r = rng.normal(size=(20, 3)) * 7000.0
    sun = rng.normal(size=(20, 3)) * 1.5e8
    q = YawSteering("-z", "+y", vertical="geocentric").quaternions(np.zeros(20), _ctx(r, sun))
    R = Rotation.from_quat(q)
    up = r / np.linalg.norm(r, axis=1)[:, None]
    np.testing.assert_allclose(R.apply([0.0, 0.0, 1.0]), up, atol=TOL)
    s = sun / np.linalg.norm(sun, axis=1)[:, None]
    horiz = s - np.sum(s * up, axis=1)[:, None] * up
    horiz /= np.linalg.norm(horiz, axis=1)[:, None]
    np.testing.assert_allclose(R.apply([0.0, 1.0, 0.0]), horiz, atol=TOL)


def test_geodetic_and_geocentric_verticals_differ_by_the_ellipsoid():
    site = Site.from_catalog("mount-lemmon")
    t = times("2024-03-17T01:20:00", "2024-03-17T01:20:10", 10.0)
    orbit = Orbit.from_catalog("canx1-example")
    geo = Observation(orbit, site, t, YawSteering(vertical="geodetic")).quaternions()
    cen = Observation(orbit, site, t, YawSteering(vertical="geocentric")).quaternions()
    z1 = Rotation.from_quat(geo).apply([0.0, 0.0, 1.0])
    z2 = Rotation.from_quat(cen).apply([0.0, 0.0, 1.0])
    sep = np.degrees(np.arccos(np.clip(np.sum(z1 * z2, axis=1), -1, 1)))
    # geodetic minus geocentric latitude is at most 0.19 deg (WGS84), 0 at the poles/equator
    assert np.all(sep < 0.2) and np.all(sep > 0.0)


def test_undefined_yaw_and_bad_parameters_are_refused():
    with pytest.raises(AttitudeError, match="on the vertical"):
        YawSteering(vertical="geocentric").quaternions([0.0], _ctx([7000.0, 0, 0], [1e8, 0, 0]))
    with pytest.raises(AttitudeError, match="allowed: geodetic, geocentric"):
        YawSteering(vertical="spherical")
    with pytest.raises(AttitudeError, match="needs UTC times"):
        YawSteering().quaternions([0.0], _ctx([7000.0, 0, 0], [0, 1e8, 0]))
    law = law_from_dict({"law": "yaw_steering", "vertical": "geocentric"})
    assert law == YawSteering(vertical="geocentric")


def _posed_array_normal(to_sun_body):
    """Normal of the built-in array after its sun-tracking law, in the body frame."""
    part = starlink_v15().moving_parts[0]
    theta = part.law.angles(to_sun_body, np.arange(len(to_sun_body)), part)
    return Rotation.from_rotvec(theta[:, None] * part.axis).apply(part.normal), theta


@pytest.mark.parametrize("law", [Nadir(nadir_axis="-z", velocity_axis="+x"), YawSteering()])
def test_the_builtin_array_faces_the_suns_azimuth_about_the_vertical(law):
    """ "Perpendicular to the chassis and towards the sun": horizontal, toward the Sun's
    azimuth, whatever the yaw about the nadir (Nadir: along-track; YawSteering: to the Sun)."""
    site = Site.from_catalog("mount-lemmon")
    t = times("2024-03-17T01:20:00", "2024-03-17T01:25:00", 30.0)
    g = Observation(Orbit.from_catalog("canx1-example"), site, t, law).geometry(
        on_unobservable="keep"
    )
    s = g.to_sun.values  # body frame: +z is the zenith for both laws
    n, theta = _posed_array_normal(s)
    horiz = s * [1.0, 1.0, 0.0]
    horiz /= np.linalg.norm(horiz, axis=1)[:, None]
    np.testing.assert_allclose(n, horiz, atol=TOL)
    if isinstance(law, YawSteering):  # the frame already faces the Sun: no turn
        np.testing.assert_allclose(theta, 0.0, atol=TOL)
    else:
        assert np.ptp(theta) > 0.0
