"""Scenes over a real pass: a time axis, the Earth's shadow, the observation's coordinates."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from sbrdf_xr.body.spacecraft import canx1
from sbrdf_xr.engine import Scene, builtin_scene, load_scene
from sbrdf_xr.engine.run import simulate
from sbrdf_xr.errors import SceneError
from sbrdf_xr.observing import observe
from sbrdf_xr.store import open_cube, write

PASS_TOML = """
name = "toml-pass"
spacecraft = "canx1"
outputs = ["signal", "area"]

[observation]
orbit = "canx1-example"
site = "mont-megantic"
start = "2024-03-17T01:20:30"
stop = "2024-03-17T01:21:30"
step_s = 1.0

[observation.attitude]
law = "inertial"
q = [0.0, 0.0, 0.0, 1.0]
"""


@pytest.fixture(scope="module")
def cube():
    return simulate(builtin_scene("canx1-pass"))


def test_cube_has_a_time_axis_with_the_observation_as_coordinates(cube):
    g = observe.canx1_pass().geometry()
    assert cube.signal.dims == ("time", "wavelength")
    np.testing.assert_array_equal(cube.time.values, g.time.values)
    for c in ("range", "elevation", "azimuth", "phase_angle", "sunlit_fraction", "airmass"):
        np.testing.assert_array_equal(cube[c].values, g[c].values)
        assert cube[c].attrs["long_name"]
    for a in ("tle_line1", "tle_line2", "site_latitude", "site_longitude", "site_height"):
        assert cube.attrs[a] == g.attrs[a]
    # The Earth's shadow edges crossed in the window (WGS84 ellipsoid), UTC to the ms.
    assert cube.attrs["umbra_exit"] == g.attrs["umbra_exit"] == "2024-03-17T01:20:39.966"
    assert cube.attrs["penumbra_exit"] == "2024-03-17T01:20:55.237"
    assert cube.attrs["umbra_entry"] == cube.attrs["penumbra_entry"] == ""
    # The body-frame directions are the observation's own.
    np.testing.assert_array_equal(cube.to_sun.values, g.to_sun.values)


def test_umbra_is_skipped_and_the_penumbra_scales_the_sunlight(cube):
    f = cube.sunlit_fraction.values
    assert (f == 0).any() and ((f > 0) & (f < 1)).any()  # the window leaves the shadow
    assert np.all(cube.signal.values[f == 0] == 0) and np.all(cube.area.values[f == 0] == 0)
    assert "in umbra skipped" in cube.attrs["plan"]
    # Penumbra: the same geometry in full sunlight, times the sunlit fraction.
    g = observe.canx1_pass().geometry()
    pen = np.flatnonzero((f > 0) & (f < 1))
    full = simulate(
        Scene(
            canx1(),
            to_sun=g.to_sun.values[pen],
            to_observer=g.to_observer.values[pen],
            outputs=("signal", "area", "band_signal"),
            bands=("V", "R", "I"),
        )
    )
    np.testing.assert_allclose(
        cube.signal.values[pen], f[pen, None] * full.signal.values, rtol=1e-12
    )
    np.testing.assert_allclose(cube.area.values[pen], full.area.values, rtol=1e-12)


def test_pass_round_trips_through_netcdf(cube, tmp_path):
    path = write(cube, tmp_path / "pass.nc", outputs="all")  # every variable
    with xr.open_dataset(path) as back:
        xr.testing.assert_identical(back.load(), cube)
    # by default the derived ones (brdf) are left out and computed again on read
    lean = write(cube, tmp_path / "lean.nc")
    with open_cube(lean) as back:
        xr.testing.assert_allclose(back.load(), cube, rtol=1e-12, atol=0)
        assert back.brdf.attrs == cube.brdf.attrs


def test_toml_observation_scene(tmp_path):
    p = tmp_path / "pass.toml"
    p.write_text(PASS_TOML)
    scene = load_scene(p)
    c = simulate(scene)
    assert c.sizes["time"] == 61 and "times of" in c.attrs["plan"]
    bad = PASS_TOML.replace('site = "mont-megantic"', 'site = "atlantis"')
    p.write_text(bad)
    with pytest.raises(SceneError, match=r"\[observation\]"):
        load_scene(p)
    p.write_text(PASS_TOML + '\n[attitude]\nkind = "uniform"\nn = 3\n')
    with pytest.raises(SceneError, match="an \\[observation\\] gives the geometry"):
        load_scene(p)


def test_observation_and_another_geometry_are_refused():
    with pytest.raises(SceneError, match="not several"):
        Scene(
            canx1(),
            observation=observe.canx1_pass(),
            to_sun=[[1.0, 0, 0]],
            to_observer=[[1.0, 0, 0]],
        )
    with pytest.raises(SceneError, match=r"expected a sbrdf_xr\.observing\.Observation"):
        Scene(canx1(), observation="canx1-pass")


def test_earthshine_follows_the_earth_at_every_time():
    scene = builtin_scene("canx1-pass").with_options(
        effects=("sunlight", "earthshine"), outputs=("signal", "area")
    )
    c = simulate(scene)
    assert "signal_earthshine" in c and np.all(np.isfinite(c.signal_earthshine))
    assert (c.signal_earthshine.values > 0).any()
    assert "at every time" in c.attrs["plan"]
