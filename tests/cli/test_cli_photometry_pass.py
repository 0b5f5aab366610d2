"""``sbrdf-xr photometry`` on a pass cube: its own range, Sun distance and airmass."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from sbrdf_xr import photometry as P
from sbrdf_xr.cli import main
from sbrdf_xr.materials.tables import write_netcdf_atomic
from sbrdf_xr.observing import observe
from sbrdf_xr.observing.orbits import Orbit, Site
from sbrdf_xr.observing.timescales import times


@pytest.fixture(scope="module")
def pass_path(tmp_path_factory):
    """A pass cube on disk: the real geometry of a sunlit CanX-1 pass, a grey signal per time."""
    g = observe.Observation(
        Orbit.from_catalog("canx1-example"),
        Site.from_catalog("mont-megantic"),
        times("2024-03-17T01:21:20", "2024-03-17T01:24:00", 20.0),
        observe.canx1_attitude(),
        name="short-pass",
    ).geometry()
    wl = np.arange(300.0, 1101.0, 10.0)
    c = np.linspace(0.01, 0.03, g.sizes["time"])
    cube = xr.Dataset(
        {
            "signal": (
                ("time", "wavelength"),
                np.repeat(c[:, None], wl.size, 1),
                {"units": "m2 sr-1"},
            )
        },
        coords={
            "time": g.time,
            "wavelength": ("wavelength", wl, {"units": "nm"}),
            **{k: g[k] for k in ("range", "sun_distance", "airmass", "elevation")},
        },
    )
    return write_netcdf_atomic(cube, tmp_path_factory.mktemp("pass") / "pass.nc"), cube, c


def test_photometry_of_a_pass_needs_no_range(pass_path, tmp_path, capsys):
    path, cube, c = pass_path
    out = tmp_path / "phot.nc"
    assert main(["photometry", str(path), "--bands", "V", "R", "-q", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "range the cube's 'range'" in text and "over time" in text
    with P.open_photometry(out) as ph:
        m = ph.magnitude.load()
    d, r = cube["range"].values, cube["sun_distance"].values
    msun = P.sun_magnitudes(["V", "R"]).values
    expect = msun[None, :] - 2.5 * np.log10(c[:, None] / r[:, None] ** 2 / (d[:, None] * 1e3) ** 2)
    np.testing.assert_allclose(m.transpose("time", "band").values, expect, rtol=0, atol=1e-12)


def test_range_override_and_extinction_flags(pass_path, tmp_path, capsys):
    path, cube, _ = pass_path
    base, seen = tmp_path / "a.nc", tmp_path / "b.nc"
    args = ["photometry", str(path), "--bands", "V", "R", "-q"]
    assert main([*args, "--range-km", "1300", "-o", str(base)]) == 0
    text = capsys.readouterr().out
    assert "range override: range (1300 km) overrides the cube's 'range'" in text
    assert (
        main([*args, "--range-km", "1300", "--extinction", "V=0.2", "R=0.1", "-o", str(seen)]) == 0
    )
    assert "extinction coefficients: V: 0.2, R: 0.1" in capsys.readouterr().out
    with P.open_photometry(base) as a, P.open_photometry(seen) as b:
        diff = (b.magnitude - a.magnitude).transpose("time", "band").values
        assert a.attrs["range_override"].startswith("range (1300 km)")
    x = cube["airmass"].values
    np.testing.assert_allclose(diff, x[:, None] * np.array([[0.2, 0.1]]), rtol=0, atol=1e-12)
    assert main([*args, "--extinction", "V=0.2"]) == 2
    assert "no coefficient for band 'R'" in capsys.readouterr().err
    assert main([*args, "--extinction", "V:0.2"]) == 2
    assert "is not BAND=K" in capsys.readouterr().err
