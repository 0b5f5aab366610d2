"""The new geometry sources through scene tables and ``sbrdf-xr observe``: OEM, AEM, tracking."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from test_ephemeris import _states, _write
from test_tracking import EXCERPT

from sbrdf_xr.cli import main
from sbrdf_xr.errors import ObservationError, TrackingTableError
from sbrdf_xr.observing import canx1_pass, observation_from_dict
from sbrdf_xr.observing.timescales import times

# As in test_ephemeris: an OEM of SGP4 states every 60 s (Hermite 7) is within 2e-4 km.
POS_ATOL_KM = 2e-4


@pytest.fixture(scope="module")
def oem_file(tmp_path_factory):
    obs = canx1_pass()
    t = times("2024-03-17T01:15:00", "2024-03-17T01:30:00", 60.0)
    r, v = _states(obs, t, "GCRF")
    return obs, _write(tmp_path_factory.mktemp("oem") / "canx1.oem", t, r, v)


def test_scene_table_with_an_oem(oem_file):
    obs, path = oem_file
    table = {
        "oem": path.name,
        "site": "mont-megantic",
        "start": "2024-03-17T01:20:00",
        "stop": "2024-03-17T01:25:00",
        "step_s": 1.0,
        "attitude": {"law": "spin", "axis_body": [0.3, 0.4, 0.866], "rate_deg_s": 4.0},
    }
    o2 = observation_from_dict(table, base_dir=path.parent)
    assert np.abs(o2.context().position - obs.context().position).max() < POS_ATOL_KM
    with pytest.raises(ObservationError, match=r"exactly one of orbit, tle.*oem, tracking"):
        observation_from_dict({**table, "orbit": "canx1-example"}, base_dir=path.parent)


def test_scene_table_with_a_tracking_table():
    obs = observation_from_dict(
        {
            "tracking": {"path": str(EXCERPT), "format": "pomenis"},
            "attitude": {"law": "inertial", "q": [0.0, 0.0, 0.0, 1.0]},
        }
    )
    assert obs.times.size == 40 and obs.site.name == "pomenis-mount-lemmon"
    g = obs.geometry()
    assert g.attrs["orbit_name"] == "pomenis"
    with pytest.raises(ObservationError, match="the tracking table gives the times"):
        observation_from_dict(
            {"tracking": {"path": str(EXCERPT), "format": "pomenis"}, "start": "2022-01-25"}
        )
    with pytest.raises(TrackingTableError, match="format pomenis fixes its site"):
        observation_from_dict(
            {"tracking": {"path": str(EXCERPT), "format": "pomenis"}, "site": "mount-lemmon"}
        )
    with pytest.raises(TrackingTableError, match="a csv tracking table needs the site"):
        observation_from_dict({"tracking": {"path": str(EXCERPT)}})


def test_cli_observe_with_an_oem(oem_file, tmp_path):
    _, path = oem_file
    cube = tmp_path / "pass.nc"
    argv = [
        "observe",
        "--elements",
        str(path),
        "--site",
        "mont-megantic",
        "--start",
        "2024-03-17T01:21:00",
        "--duration",
        "20",
        "--step",
        "5",
        "--attitude",
        "spin",
        "--period",
        "90",
        "--bands",
        "V",
        "-o",
        str(cube),
        "-q",
    ]
    assert main(argv) == 0
    with xr.open_dataset(cube) as ds:
        assert ds.sizes["time"] == 5 and ds.attrs["orbit_name"] == "CANX-1"
        assert "CCSDS OEM" in ds.attrs["orbit_provenance"]


def test_cli_observe_with_a_tracking_table(tmp_path):
    obs = canx1_pass()
    g = obs.geometry().isel(time=slice(60, 70))
    rows = ["# a pass re-expressed as its own table", "time,elevation,azimuth,range_km"]
    rows += [
        f"{str(t)[:23]},{float(e)!r},{float(a)!r},{float(r)!r}"
        for t, e, a, r in zip(
            g.time.values, g.elevation.values, g.azimuth.values, g.range.values, strict=True
        )
    ]
    table = tmp_path / "track.csv"
    table.write_text("\n".join(rows) + "\n")
    cube = tmp_path / "track.nc"
    base = ["observe", "--tracking", str(table), "--site", "mont-megantic", "--utc"]
    law = ["--attitude", "spin", "--period", "90", "--spin-axis", "0.3,0.4,0.866"]
    assert main([*base, *law, "--bands", "V", "-o", str(cube), "-q"]) == 0
    with xr.open_dataset(cube) as ds:
        assert ds.sizes["time"] == 10
        # repr() round-trips the floats: the table route is the TLE route to rounding
        assert np.abs(ds.range.values / g.range.values - 1).max() < 1e-12
        # the phase angle rebuilt from the table: positions to rounding, the Sun through
        # the spline velocity's aberration (<= 3e-11 rad): 1e-8 degree leaves 100x.
        assert np.abs(ds.phase_angle.values - g.phase_angle.values).max() < 1e-8
    assert main([*base, "--start", "2024-03-17T01:21:00", "-o", str(cube)]) == 2
    assert main([*base[:3], "-o", str(cube)]) == 2  # a csv table needs the site
    assert main(["observe", "--site", "mont-megantic", "-o", str(cube)]) == 2
