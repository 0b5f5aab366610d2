"""Tests of the moonlight effect (sbrdf_xr.engine.effects.moonlight) and its physics
(sbrdf_xr.sources.moon_v_magnitude, moonlight_irradiance_ratio)."""

from __future__ import annotations

import os
import warnings

import numpy as np
import pytest
import trimesh

from sbrdf_xr import geometry, load_spacecraft
from sbrdf_xr.engine import Scene, simulate
from sbrdf_xr.engine.effects.moonlight import moon_from_spacecraft
from sbrdf_xr.errors import SceneError
from sbrdf_xr.materials.schema import lambertian
from sbrdf_xr.observing import canx1_pass, skyfield_data, skyfield_utc
from sbrdf_xr.sources import moon_v_magnitude, moonlight_irradiance_ratio


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _separation_arcsec(a, b):
    a, b = _unit(a), _unit(b)
    return (
        np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1)))
        * 3600.0
    )


def test_the_moon_is_where_astropy_puts_it():
    """The Moon from the spacecraft of the built-in pass (LEO, 7.5 km/s) and from a few
    made-up positions (GEO, at rest) against astropy's get_body on the same DE421 file,
    moved to the spacecraft by astropy's GCRS frame (parallax, then the aberration of the
    observer's barycentric velocity).  0.01 arcsec: the two libraries deflect the light
    by the Sun differently (sub-mas for the Moon) and skyfield's positions are splined
    on 600 s knots (micro-arcseconds); a first-order aberration on top of the geocentric
    apparent Moon would be off by 0.37 arcsec."""
    astropy_coords = pytest.importorskip("astropy.coordinates")
    pytest.importorskip("jplephem")
    import astropy.units as u
    import skyfield_data as data
    from astropy.time import Time
    from astropy.utils import iers

    with warnings.catch_warnings():  # the package's IERS file is past its nominal expiry
        warnings.simplefilter("ignore", RuntimeWarning)
        path = os.path.join(data.get_skyfield_data_path(), "de421.bsp")

    obs = canx1_pass()
    ctx = obs.context()
    t64 = np.concatenate([obs.times, np.array(["2022-11-08T10:59", "2020-06-01"], "M8[ns]")])
    r = np.concatenate([ctx.position, [[0.0, -42164.0, 0.0], [0.0, 0.0, 7000.0]]])
    v = np.concatenate([ctx.velocity, [[3.07, 0.0, 0.0], [0.0, 0.0, 0.0]]])
    sun = np.concatenate([ctx.sun, [[1.5e8, 0.0, 0.0]] * 2])
    ours = moon_from_spacecraft(t64, r, v, sun)["moon_km"]
    with (
        iers.conf.set_temp("auto_download", False),
        astropy_coords.solar_system_ephemeris.set(path),
    ):
        t = Time(t64, scale="utc")
        frame = astropy_coords.GCRS(
            obstime=t,
            obsgeoloc=astropy_coords.CartesianRepresentation(r.T * u.km),
            obsgeovel=astropy_coords.CartesianRepresentation(v.T * u.km / u.s),
        )
        theirs = astropy_coords.get_body("moon", t).transform_to(frame)
        theirs = theirs.cartesian.xyz.to_value(u.km).T
    assert _separation_arcsec(ours, theirs).max() < 0.01
    np.testing.assert_allclose(
        np.linalg.norm(ours, axis=1), np.linalg.norm(theirs, axis=1), atol=1e-3
    )


def _seen_from_near_the_earth(times: list[str]) -> dict[str, np.ndarray]:
    """The Moon from 7000 km towards it, with the Sun of the same ephemeris."""
    _, eph = skyfield_data()
    t64 = np.array(times, dtype="datetime64[ns]")
    earth = eph["earth"].at(skyfield_utc(t64))
    sun = earth.observe(eph["sun"]).apparent().position.km.T
    r = 7000.0 * _unit(earth.observe(eph["moon"]).apparent().position.km.T)
    return moon_from_spacecraft(t64, r, np.zeros_like(r), sun - r)


def test_lunar_eclipse_of_2022_november_8_at_the_published_contacts():
    """The Moon's centre enters the umbra halfway between the published first and second
    umbral contacts (U1 09:09:12, U2 10:16:39 UTC, NASA / Espenak) and leaves it halfway
    between U3 11:41:38 and U4 12:49:03.  Within 60 s: the published contacts use an
    umbra enlarged by about 1 % for the Earth's atmosphere (about 0.007 deg, 45 s of the
    Moon's motion), our shadow is the bare WGS84 ellipsoid's."""
    enter, leave = np.datetime64("2022-11-08T09:42:55.5"), np.datetime64("2022-11-08T12:15:20.5")
    minute = np.timedelta64(60, "s")
    times = [enter - minute, enter + minute, leave - minute, leave + minute]
    sunlit = _seen_from_near_the_earth([str(t) for t in times])["sunlit"]
    assert sunlit[0] > 0 and sunlit[1] == 0 and sunlit[2] == 0 and sunlit[3] > 0
    outside = _seen_from_near_the_earth(["2022-11-08T07:30", "2022-11-08T14:30"])
    assert outside["sunlit"].tolist() == [1.0, 1.0]  # before P1 08:02, after P4 13:56
    assert np.all(outside["ratio"] > 2e-6)  # a full Moon


def test_the_earth_hides_the_moon_from_a_spacecraft_behind_it():
    """In front of the Earth the whole lunar disc shows, behind it none; on a line from
    the Moon's centre that touches the Earth (a sphere here), half of it."""
    _, eph = skyfield_data()
    t64 = np.array(["2024-03-17T01:22"] * 3, dtype="datetime64[ns]")
    earth = eph["earth"].at(skyfield_utc(t64))
    moon = earth.observe(eph["moon"]).apparent().position.km.T[0]
    sun = earth.observe(eph["sun"]).apparent().position.km.T
    toward, dist, radius = _unit(moon), np.linalg.norm(moon), 6378.137
    side = _unit(np.cross(toward, [0.0, 0.0, 1.0]))
    touch = radius * (radius / dist * toward + np.sqrt(1 - (radius / dist) ** 2) * side)
    beyond = touch + 20000.0 * _unit(touch - moon)  # the tangent line, past the Earth
    r = np.array([7000.0 * toward, -7000.0 * toward, beyond])
    m = moon_from_spacecraft(t64, r, np.zeros_like(r), sun - r, earth="sphere")
    assert m["visible"][0] == 1.0 and m["visible"][1] == 0.0 and m["ratio"][1] == 0.0
    assert 0.4 < m["visible"][2] < 0.6  # centre on the limb (the light time moves it 1 %)


def test_the_phase_law_and_the_published_full_moon_illuminance():
    """The full Moon at its mean distance: the ratio to the Sun times the Sun's
    illuminance (the package's ASTM G173 spectrum weighted by the CIE 1924 photopic V of
    colour-science, 683 lm/W) against Krisciunas & Schaefer's own conversion of the same
    magnitude, I* = 10^(-0.4 (m + 16.57)) foot-candles = 0.313 lx.  Within 7 %: their
    constant puts the Sun (V = -26.74) at 1.26e5 lx, the ASTM spectrum at 1.33e5 lx.  The
    published full-Moon illuminance is 0.25-0.32 lx (after and before the atmosphere)."""
    colorimetry = pytest.importorskip("colour.colorimetry")
    from sbrdf_xr.photometry import solar_spectrum

    lef = colorimetry.SDS_LEFS["CIE 1924 Photopic Standard Observer"]
    wl = np.asarray(lef.wavelengths)
    sun_lux = 683.0 * np.trapezoid(solar_spectrum(wl).values * np.asarray(lef.values), wl)
    moon_lux = sun_lux * moonlight_irradiance_ratio(0.0, 384400.0)
    ks = 10 ** (-0.4 * (moon_v_magnitude(0.0) + 16.57)) * 10.7639  # foot-candle -> lux
    assert float(ks) == pytest.approx(0.3133, abs=1e-4)
    assert float(moon_lux) == pytest.approx(float(ks), rel=0.07)
    assert 0.25 < float(moon_lux) < 0.35
    # the law's own shape: quarter Moon 2.6 mag below full; twice as far, a quarter
    assert float(moon_v_magnitude(90.0) - moon_v_magnitude(0.0)) == pytest.approx(2.60244)
    assert float(
        moonlight_irradiance_ratio(30.0, 768800.0) / moonlight_irradiance_ratio(30.0, 384400.0)
    ) == pytest.approx(0.25)


def _box_scene(**kw) -> Scene:
    box = load_spacecraft(trimesh.creation.box(), material="grey")
    grey = lambertian(0.5, np.arange(400.0, 1001.0, 100.0), material="grey")
    return Scene(box, {"grey": grey}, **kw)


def test_moonlight_on_a_lambertian_cube_is_the_closed_form():
    """signal_moonlight = ratio x (0.5 / pi) sum over the six unit faces of
    max(0, m.n) max(0, o.n), with m the Moon and o the observer in the body frame; it
    adds to band_signal like the Sun's signal."""
    obs = canx1_pass()
    scene = _box_scene(
        observation=obs, effects=("moonlight",), outputs=("signal", "band_signal"), bands=("V",)
    )
    cube = simulate(scene)
    assert cube.signal_moonlight.attrs["units"] == "m2 sr-1"
    ctx = obs.context()
    m = moon_from_spacecraft(obs.times, ctx.position, ctx.velocity, ctx.sun)
    q = cube.quaternion.values
    to_moon = np.einsum("nji,nj->ni", geometry.rotation_matrices(q), _unit(m["moon_km"]))
    o = cube.to_observer.values
    faces = np.concatenate([np.eye(3), -np.eye(3)])
    lit = np.clip(to_moon @ faces.T, 0, None) * np.clip(o @ faces.T, 0, None)
    expected = m["ratio"] * 0.5 / np.pi * lit.sum(axis=1)
    assert np.all(m["ratio"] > 0) and (expected > 0).sum() > 100  # the quarter Moon is up
    for w in range(7):
        np.testing.assert_allclose(cube.signal_moonlight.isel(wavelength=w), expected, rtol=1e-6)
    plan = scene.plan()
    band = (cube.signal + cube.signal_moonlight).values @ plan.band_weights.T
    np.testing.assert_allclose(cube.band_signal.values, band, rtol=1e-12)
    assert "moonlight" in cube.attrs["effects"] and plan.estimate.multiply_adds > 0


def test_moonlight_needs_an_observation():
    x = [[1.0, 0.0, 0.0]]
    with pytest.raises(SceneError, match="moonlight needs an observation"):
        _box_scene(to_sun=x, to_observer=x, effects=("sunlight", "moonlight"))
    with pytest.raises(SceneError, match="moonlight needs an observation"):
        _box_scene(attitudes=[[0, 0, 0, 1.0]], phase_angles=[10.0], effects=("moonlight",))
