"""Catalog observatories against the MPC parallax constants they cite, element files, and
the time an object below the horizon next rises."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

from sbrdf_xr import _catalog_index
from sbrdf_xr.errors import NotObservableError, ObservationError
from sbrdf_xr.observing.observation import Observation
from sbrdf_xr.observing.orbits import Orbit, Site, tle_checksum
from sbrdf_xr.observing.timescales import times

L1 = "1 27847U 03031H   24075.50000000  .00000015  00000-0  21000-4 0  9991"
L2 = "2 27847  98.7200 129.5000 0012000  95.0000 265.0000 14.21950000109836"


def _mpc_sites():
    entry = _catalog_index.entry("haleakala-amos")
    table = tomllib.loads(entry.file.read_text(encoding="utf-8"))
    return {k: v for k, v in table.items() if "mpc" in v}


def test_the_ssa_and_survey_observatories_are_in_the_catalog():
    sites = _mpc_sites()
    for key in (
        "haleakala-amos",
        "socorro-ets",
        "zimmerwald",
        "tenerife-ogs",
        "siding-spring",
        "cerro-pachon",
        "la-silla",
        "mount-lemmon",
        "atom-site-sst",
        "pan-starrs",
    ):
        assert key in sites, key
        site = Site.from_catalog(key)
        assert site.source.startswith("Minor Planet Center, List of Observatory Codes")
        assert _catalog_index.entry(key).provenance.startswith("Minor Planet Center")


@pytest.mark.parametrize("key", sorted(_mpc_sites()))
def test_each_site_reproduces_its_mpc_parallax_constants(key):
    """Forward: skyfield's WGS84 position of the stored geodetic coordinates, in Earth
    equatorial radii, against the MPC's rho cos phi' and rho sin phi' (the conversion that
    wrote them went the other way, with astropy)."""
    code, lon, rho_cos, rho_sin = _mpc_sites()[key]["mpc"]
    site = Site.from_catalog(key)
    xyz = site.position.itrs_xyz.km
    a = 6378.137
    assert np.hypot(xyz[0], xyz[1]) / a == pytest.approx(rho_cos, abs=6e-6)  # 5-decimal rounding
    assert xyz[2] / a == pytest.approx(rho_sin, abs=6e-6)
    assert np.mod(site.longitude - lon + 180.0, 360.0) - 180.0 == pytest.approx(0.0, abs=1e-5)
    assert -500.0 < site.height < 4500.0 and isinstance(code, str)


def test_element_files_with_one_or_many_sets(tmp_path):
    one = tmp_path / "one.tle"
    one.write_text(f"{L1}\n{L2}\n")
    assert Orbit.from_file(one).name == "27847"
    many = tmp_path / "group.txt"
    body1 = "1 00005U 58002B   24075.50000000  .00000023  00000-0  28098-4 0  999"
    body2 = "2 00005  34.2500 100.0000 1846000 200.0000 150.0000 10.8480000000000"
    l1b, l2b = (b + str(tle_checksum(b + "0")) for b in (body1, body2))
    many.write_text(f"CANX-1\n{L1}\n{L2}\nVANGUARD 1\n{l1b}\n{l2b}\n")
    with pytest.raises(ObservationError, match=r"holds 2 element sets \(CANX-1, VANGUARD 1\)"):
        Orbit.from_file(many)
    assert Orbit.from_file(many, "canx-1").name == "CANX-1"
    with pytest.raises(ObservationError, match="no satellite 'ISS'; it holds CANX-1, VANGUARD 1"):
        Orbit.from_file(many, "ISS")
    bad = tmp_path / "bad.tle"
    bad.write_text("hello\n")
    with pytest.raises(ObservationError, match=r"line 1 .* starts no element set"):
        Orbit.from_file(bad)


def test_an_object_below_the_horizon_all_window_says_when_it_rises():
    obs = Observation(
        Orbit.from_catalog("canx1-example"),
        Site.from_catalog("zimmerwald"),
        times("2024-03-17T01:20:00", "2024-03-17T01:25:00", 30.0),
    )
    with pytest.raises(
        NotObservableError,
        match=r"below 0 deg elevation at every time .*; it "
        r"next rises above 0 deg at 2024-03-1\dT\d\d:\d\d:\d\d UTC \(highest",
    ):
        obs.geometry()
    # the rise it names is real: the object is up a minute later
    text = obs.next_pass()
    rise = np.datetime64(text.split(" at ")[1].split(" UTC")[0], "ns")
    up = Observation(
        obs.orbit,
        obs.site,
        times(rise + np.timedelta64(60, "s"), rise + np.timedelta64(120, "s"), 30.0),
    )
    assert np.all(up.geometry(on_unobservable="keep").elevation.values > 0.0)
