"""The built-in Starlink v1.5-class body at the Pomenis observations (bench.starlink).

The shipped table, the scene, a 12-row prediction checked against closed forms, bad
input, and the 1,173 rows with the correlation bound of the run (~10 s).
"""

from __future__ import annotations

import numpy as np
import pytest

from sbrdf_xr.bench import limb_sunlight, pomenis_table, predict_starlink, starlink_scene
from sbrdf_xr.errors import TrackingTableError, ValidationError
from sbrdf_xr.lightcurves import compare_magnitudes
from sbrdf_xr.observing import read_pomenis
from sbrdf_xr.photometry import (
    lambert_sphere_phase,
    limb_ray,
    sun_distance_au,
    sun_magnitudes,
)

HEADER = (
    "# Observation Time : UTC\n"
    "observation_time,satellite_height,satellite_altitude,satellite_azimuth,ab_magnitude\n"
)
GOOD = "2022-01-25T13:28:39,448.4444346,32.87386184,316.0661315,4.864597228\n"


@pytest.fixture(scope="module")
def twelve():
    return predict_starlink(pomenis_table(rows=slice(0, 12)))


def test_the_shipped_table_is_whole():
    table = pomenis_table()
    assert table.times.size == 1173 and table.dropped == ()
    assert table.columns["ab_magnitude"].size == 1173
    assert table.site.latitude == 32.4434 and table.site.longitude == -110.7881


def test_the_scene_has_the_effects_and_the_tracking_array():
    plan = starlink_scene(pomenis_table(rows=slice(0, 3))).plan()
    assert plan.effects == ("sunlight", "shadowing", "eclipse", "earthshine")
    plan = starlink_scene(pomenis_table(rows=slice(0, 3)), earthshine=False, shadowing=False).plan()
    assert plan.effects == ("sunlight", "eclipse")


def test_the_sphere_control_is_russells_phase_law(twelve):
    """m_sphere + 2.5 log10(0.65/pi Phi(alpha) / d**2) - 5 log10(r_sun) is the Sun's AB V
    magnitude at 1 AU: the same at every row to the Almanac formula's 1e-5 au (5e-5 mag)
    and the spacecraft's offset from the Earth (<1e-4 mag)."""
    phi = lambert_sphere_phase(twelve.phase_angle.values)
    d_m = twelve.range.values * 1e3
    r_au = np.asarray(sun_distance_au(twelve.time.values))
    c = twelve.magnitude_sphere.values + 2.5 * np.log10(0.65 / np.pi * phi / d_m**2)
    c -= 5.0 * np.log10(r_au)
    assert np.ptp(c) < 2e-4
    assert c.mean() == pytest.approx(sun_magnitudes("V", system="AB").item(), abs=1e-3)


def test_the_prediction_is_complete_and_labelled(twelve):
    for v in twelve.data_vars:
        assert twelve[v].attrs["units"] and twelve[v].attrs["long_name"]
        assert np.isfinite(twelve[v]).all(), v
    # earthshine only adds light
    assert np.all(twelve.magnitude_model <= twelve.magnitude_sunlight + 1e-12)
    # the sunlight magnitude is -2.5 log10 of the two surfaces' signal / (d r_sun)**2,
    # times the limb's transmission in place of the solid Earth's sunlit fraction
    total = (twelve.signal_chassis + twelve.signal_array).values
    total = total * (twelve.limb_transmission / twelve.sunlit_fraction).values
    d, r = twelve.range.values, np.asarray(sun_distance_au(twelve.time.values))
    m = -2.5 * np.log10(total / (d * r) ** 2)
    dm = twelve.magnitude_sunlight.values - m
    assert np.ptp(dm) < 2e-4  # the Almanac's r_sun to 1e-5 au against the cube's
    np.testing.assert_allclose(
        twelve.magnitude_observed, pomenis_table(rows=slice(0, 12)).columns["ab_magnitude"]
    )


def _skyfield_geometry(table):
    """Satellite and Sun (ITRS, km) and the phase angle from skyfield alone: the row's
    altitude and azimuth from the site, the range that puts it at the row's height above
    WGS84 (bisection), DE421's Sun."""
    from skyfield.api import wgs84
    from skyfield.constants import AU_KM
    from skyfield.framelib import itrs
    from skyfield.positionlib import Geocentric
    from skyfield.units import Distance

    from sbrdf_xr.observing.timescales import skyfield_data

    ts, eph = skyfield_data()
    site = wgs84.latlon(table.site.latitude, table.site.longitude, table.site.height)
    sats, suns, phase = [], [], []
    for k, when in enumerate(table.times.astype("datetime64[us]").tolist()):
        t = ts.utc(when.year, when.month, when.day, when.hour, when.minute,
                   when.second + when.microsecond * 1e-6)  # fmt: skip
        here = site.at(t)
        lo, hi = 0.0, 4000.0
        for _ in range(60):
            rho = 0.5 * (lo + hi)
            rel = here.from_altaz(
                alt_degrees=table.elevation[k], az_degrees=table.azimuth[k],
                distance=Distance(km=rho),
            )  # fmt: skip
            sat = Geocentric((here.position.km + rel.position.km) / AU_KM, t=t, center=399)
            high = wgs84.height_of(sat).km > table.height[k]
            lo, hi = (lo, rho) if high else (rho, hi)
        sun = (eph["sun"] - eph["earth"]).at(t).position.km
        r = sat.position.km
        u, v = sun - r, here.position.km - r
        phase.append(np.degrees(np.arccos(u @ v / np.linalg.norm(u) / np.linalg.norm(v))))
        rot = itrs.rotation_at(t)
        sats.append(rot @ r)
        suns.append(rot @ sun)
    return np.array(sats), np.array(suns), np.array(phase)


def test_the_geometry_against_skyfield_alone(twelve):
    """An independent computation of each row (skyfield's altaz inversion and heights
    above WGS84): the cube's phase angle to 0.01 deg (the Sun here is DE421's geometric
    one, without the 8.3 min light time that moves it by 20.5 arcsec = 0.0057 deg) and
    the limb's ray to 1 m of height."""
    table = pomenis_table(rows=slice(0, 12))
    sat, sun, phase = _skyfield_geometry(table)
    np.testing.assert_allclose(twelve.phase_angle, phase, atol=0.01)
    h, d = limb_ray(sat, sun - sat)
    limb = limb_sunlight(table)
    np.testing.assert_allclose(limb.tangent_height, h, atol=1e-3)
    np.testing.assert_allclose(limb.limb_distance, d, atol=0.5)


def test_the_limb_dims_only_the_rays_that_graze_the_atmosphere(twelve):
    t, h = twelve.limb_transmission.values, twelve.tangent_height.values
    assert np.all(t[h > 80.0] > 1 - 1e-4) and np.all((0 < t) & (t <= 1))
    assert np.all(t[h < 30.0] < 0.7)  # 0.4 mag or more below 30 km
    assert "refraction" in twelve.attrs["atmosphere"]
    plain = predict_starlink(pomenis_table(rows=slice(0, 12)), atmosphere=False)
    assert "tangent_height" not in plain.coords
    np.testing.assert_allclose(
        plain.magnitude_sunlight - twelve.magnitude_sunlight,
        2.5 * np.log10((twelve.limb_transmission / twelve.sunlit_fraction).values),
        atol=1e-9,
    )


def test_a_table_without_magnitudes_is_refused():
    table = pomenis_table(rows=slice(0, 3))
    bare = type(table)(
        table.site, table.times, elevation=table.elevation,
        azimuth=table.azimuth, height=table.height,
    )  # fmt: skip
    with pytest.raises(ValidationError, match="no column 'ab_magnitude'"):
        predict_starlink(bare)
    with pytest.raises(ValidationError, match=r"no table for \['starlink-solar-array'\]"):
        starlink_scene(table, materials={"starlink-chassis": None})


@pytest.mark.parametrize(
    "line, why",
    [
        ("2022-01-26T13:04:48,448.06,,128.22,5.67\n", "column 'satellite_altitude' is empty"),
        ("2022-01-26T13:04:48,448.06,45.8,north,5.67\n", "'north', not a number"),
        ("2022-01-26T13:04:48,448.06,-0.5,128.22,5.67\n", "elevation -0.5 deg is below"),
        ("2022-01-26T13:04:48,448.06,45.8,128.22,\n", "column 'ab_magnitude' is empty"),
    ],
)
def test_bad_rows_are_named_or_counted(tmp_path, line, why):
    p = tmp_path / "p.csv"
    p.write_text(HEADER + GOOD + line)
    with pytest.raises(TrackingTableError, match=f"line 4: .*{why}"):
        read_pomenis(p)
    with pytest.warns(UserWarning, match="1 row"):
        table = read_pomenis(p, on_bad="drop")
    assert table.times.size == 1 and table.dropped[0][0] == 4


def test_a_file_that_does_not_state_utc_is_refused(tmp_path):
    p = tmp_path / "p.csv"
    p.write_text(HEADER.replace("UTC", "local") + GOOD)
    with pytest.raises(TrackingTableError, match="does not state 'Observation Time : UTC'"):
        read_pomenis(p)


#: The package's model over the 1,173 rows (the shipped tables, the chassis with its
#: specular core that follows the incidence angle and its ABg halo): with the sunlight
#: through the Earth's limb (refraction, Rayleigh and ozone; nothing fitted) r = 0.776,
#: RMS 0.682 mag, median |residual| 0.36 (0.778, 0.678, 0.37 with the core alone; 0.771,
#: 0.682, 0.36 with one constant core); with the solid Earth's
#: shadow only r = 0.709, RMS 0.769 (earthshine from the finite Lambertian Earth
#: changes r by < 0.002 either way); the diffuse sphere 0.470 (published 0.47).  The r
#: bound sits 0.03 below the run (a table rebuilt with other options moved r by
#: 0.005-0.03 before); the RMS bound is the run plus 0.1 mag, well under the two-slab
#: baseline's 1.19.
R_MODEL_MIN, RMS_MODEL_MAX = 0.75, 0.78


def test_the_correlation_over_all_rows():
    out = predict_starlink()
    model = compare_magnitudes(out.magnitude_model, out.magnitude_observed)
    sphere = compare_magnitudes(out.magnitude_sphere, out.magnitude_observed)
    assert model.attrs["n_unpredicted"] == 0
    assert float(model.pearson_r) >= R_MODEL_MIN
    assert float(model.rms_residual) < RMS_MODEL_MAX
    assert float(sphere.pearson_r) == pytest.approx(0.47, abs=0.005)
    assert float(model.pearson_r) > float(sphere.pearson_r) + 0.25
    # the limb's share: the solid Earth's shadow alone (the sunlit fraction back in
    # place of the limb's transmission) is 0.07 lower
    solid = out.magnitude_sunlight + 2.5 * np.log10(out.limb_transmission / out.sunlit_fraction)
    plain = compare_magnitudes(solid, out.magnitude_observed)
    assert float(model.pearson_r) - float(plain.pearson_r) > 0.05
