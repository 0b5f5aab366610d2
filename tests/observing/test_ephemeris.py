"""Tests of sbrdf_xr.observing.ephemeris and oem_reader: OEM files against the TLE route."""

from __future__ import annotations

import numpy as np
import pytest
from astropy.time import Time
from oem import OrbitEphemerisMessage
from oem.components import EphemerisSegment, HeaderSection, MetaDataSection
from skyfield.framelib import itrs
from skyfield.sgp4lib import TEME

from sbrdf_xr.errors import EphemerisError, ObservationError
from sbrdf_xr.observing import Observation, canx1_pass
from sbrdf_xr.observing.ephemeris import Ephemeris, to_gcrs
from sbrdf_xr.observing.oem_reader import read_oem
from sbrdf_xr.observing.timescales import skyfield_time, times

# An OEM of SGP4 states every 60 s, Hermite of degree 7 (4 states), reproduces SGP4
# positions to ~7e-5 km (measured 6.5e-5 km, 1e-8 relative; the 15 significant digits
# the oem package writes are 1e-11 km) and velocities to ~2e-5 km s-1.  Lagrange of
# degree 9 on positions and velocities does as well.
POS_ATOL_KM = 2e-4
VEL_ATOL_KM_S = 5e-5
# Cube quantities: a position error of 2e-4 km moves directions by <= 2e-4 / 800 rad
# at the 800-km ranges of the pass; angles in degree to 2e-5.
ANGLE_ATOL_DEG = 2e-5
RANGE_RTOL = 1e-9 * 1e3  # 2e-4 km in 800 km is 2.5e-7


def _states(obs, t, frame):
    geo = obs.orbit.satellite.at(skyfield_time(t))
    if frame == "GCRF":
        return geo.position.km.T, geo.velocity.km_per_s.T
    fr = {"ITRF": itrs, "TEME": TEME}[frame]
    r, v = geo.frame_xyz_and_velocity(fr)
    return r.km.T, v.km_per_s.T


def _write(path, t, r, v, frame="GCRF", interp=("HERMITE", "7"), system="UTC"):
    hdr = HeaderSection(
        {"CCSDS_OEM_VERS": "2.0", "CREATION_DATE": "2024-03-17T00:00:00", "ORIGINATOR": "TEST"}
    )
    meta = {
        "OBJECT_NAME": "CANX-1",
        "OBJECT_ID": "2003-031H",
        "CENTER_NAME": "EARTH",
        "REF_FRAME": frame,
        "TIME_SYSTEM": system,
        "START_TIME": str(t[0]),
        "STOP_TIME": str(t[-1]),
    }
    if interp:
        meta.update(INTERPOLATION=interp[0], INTERPOLATION_DEGREE=interp[1])
    ep = [Time(x, scale="utc") for x in t]
    seg = EphemerisSegment(MetaDataSection(meta), (ep, *r.T, *v.T))
    OrbitEphemerisMessage(hdr, [seg]).save_as(path, file_format="kvn")
    return path


@pytest.fixture(scope="module")
def tle():
    obs = canx1_pass()
    return obs, obs.geometry()


@pytest.mark.parametrize(
    "frame, interp", [("GCRF", ("HERMITE", "7")), ("ITRF", ("LAGRANGE", "9")), ("TEME", None)]
)
def test_oem_written_from_a_tle_pass_gives_the_tle_cube(tmp_path, tle, frame, interp):
    obs, g = tle
    t = times("2024-03-17T01:15:00", "2024-03-17T01:30:00", 60.0 if interp else 20.0)
    r, v = _states(obs, t, frame)
    path = _write(tmp_path / f"pass-{frame}.oem", t, r, v, frame, interp)
    eph = read_oem(path)
    rr, vv = eph.state(obs.times)
    st = obs._state()
    assert np.abs(rr - st["r"]).max() < POS_ATOL_KM
    assert np.abs(vv - st["v"]).max() < VEL_ATOL_KM_S
    g2 = Observation(eph, obs.site, obs.times, obs.attitude).geometry()
    for k in ("elevation", "azimuth", "phase_angle", "site_sun_elevation"):
        assert np.abs(g[k].values - g2[k].values).max() < ANGLE_ATOL_DEG, k
    assert np.abs(g.range.values / g2.range.values - 1).max() < RANGE_RTOL
    assert "CCSDS OEM" in g2.attrs["orbit_provenance"] and g2.attrs["orbit_name"] == "CANX-1"


def test_to_gcrs_inverts_skyfield_frames(tle):
    obs, _ = tle
    t = obs.times[:20]
    st = obs._state()
    for frame in ("ITRF", "TEME"):
        r, v = _states(obs, t, frame)
        rg, vg = to_gcrs(frame, t, r, v)
        assert np.abs(rg - st["r"][:20]).max() < 1e-8  # [km]: rounding of the rotations
        assert np.abs(vg - st["v"][:20]).max() < 1e-10


def test_oem_out_of_order_gap_truncated_and_outside(tmp_path, tle):
    obs, _ = tle
    t = times("2024-03-17T01:15:00", "2024-03-17T01:30:00", 60.0)
    r, v = _states(obs, t, "GCRF")
    text = _write(tmp_path / "ok.oem", t, r, v).read_text().splitlines()
    data = [k for k, ln in enumerate(text) if ln.startswith("2024-03-17T")]
    swapped = list(text)
    swapped[data[3]], swapped[data[4]] = text[data[4]], text[data[3]]
    (tmp_path / "order.oem").write_text("\n".join(swapped))
    with pytest.raises(EphemerisError, match=r"line \d+: epoch 2024-03-17T01:18:00.* not after"):
        read_oem(tmp_path / "order.oem")
    gap = [ln for k, ln in enumerate(text) if k not in data[5:15]]
    (tmp_path / "gap.oem").write_text("\n".join(gap))
    with pytest.raises(EphemerisError, match=r"a gap of 660 s between states 5 and 6"):
        read_oem(tmp_path / "gap.oem")
    (tmp_path / "cut.oem").write_text("\n".join(text[: data[0] - 3]))
    with pytest.raises(EphemerisError, match="cannot be read by the oem package"):
        read_oem(tmp_path / "cut.oem")
    eph = read_oem(tmp_path / "ok.oem")
    late = times("2024-03-17T01:29:00", "2024-03-17T01:31:00", 30.0)
    with pytest.raises(EphemerisError, match=r"outside the ephemeris \(2 of 5 times"):
        eph.state(late)
    with pytest.raises(EphemerisError, match="REF_FRAME 'MOD' is not supported"):
        (tmp_path / "mod.oem").write_text("\n".join(text).replace("= GCRF", "= MOD"))
        read_oem(tmp_path / "mod.oem")
    with pytest.raises(ObservationError, match="outside the ephemeris"):
        Observation(eph, obs.site, late).geometry()


def test_from_states_spline_velocity_and_segments():
    t = times("2024-03-17T01:20:00", "2024-03-17T01:20:30", 10.0)
    w = 2 * np.pi / 5800.0  # a circular orbit [rad s-1]
    s = np.arange(4) * 10.0
    r = 7000.0 * np.stack([np.cos(w * s), np.sin(w * s), 0 * s], axis=1)
    eph = Ephemeris.from_states(t, r, segments=[2])
    _, v = eph.state(t)
    assert np.isfinite(v).all() and np.abs(np.linalg.norm(v, axis=1) - 7000.0 * w).max() < 1e-3
    with pytest.raises(EphemerisError, match="outside the ephemeris"):
        eph.state(np.array(["2024-03-17T01:20:15"], dtype="datetime64[ns]"))
    with pytest.raises(EphemerisError, match="need velocities"):
        Ephemeris.from_states(t, r, frame="ITRF")
