"""Tests of sbrdf_xr.observing.aem: CCSDS AEM attitude against the law it was written from."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from skyfield.framelib import ICRS_to_J2000

from sbrdf_xr.errors import EphemerisError
from sbrdf_xr.observing import Observation, canx1_pass, law_from_dict
from sbrdf_xr.observing.aem import read_aem
from sbrdf_xr.observing.attitude import Nadir
from sbrdf_xr.observing.timescales import times

pytest.importorskip("ccsds_ndm")

# A nadir attitude sampled every 10 s and slerped: the nadir frame turns about the orbit
# normal at a nearly constant rate (e = 0.0012), which slerp follows to ~1e-7 rad (the
# rate varies by 2e at most over 10 s); the 10 digits written add 1e-10.
SLERP_ATOL = 1e-6
# Records written and read back at the sample times: only the 10 digits written.
DIGITS_ATOL = 1e-9


def _aem(path, t, q, frame="GCRF", direction="A2B", first=False, stop=None, records=None):
    head = [
        "CCSDS_AEM_VERS = 1.0",
        "CREATION_DATE = 2024-03-17T00:00:00",
        "ORIGINATOR = TEST",
        "",
        "META_START",
        "OBJECT_NAME = CANX-1",
        "OBJECT_ID = 2003-031H",
        f"REF_FRAME_A = {frame if direction == 'A2B' else 'SC_BODY_1'}",
        f"REF_FRAME_B = {'SC_BODY_1' if direction == 'A2B' else frame}",
        "ATTITUDE_DIR = A2B",
        "TIME_SYSTEM = UTC",
        f"START_TIME = {str(t[0])[:23]}",
        f"STOP_TIME = {str(stop or t[-1])[:23]}",
        "ATTITUDE_TYPE = QUATERNION",
        f"QUATERNION_TYPE = {'FIRST' if first else 'LAST'}",
        "META_STOP",
        "",
        "DATA_START",
    ]
    rot = Rotation.from_quat(q)
    if frame == "EME2000":
        rot = Rotation.from_matrix(ICRS_to_J2000) * rot
    if direction == "B2A":
        rot = rot.inv()
    qq = rot.as_quat()
    if first:
        qq = qq[:, [3, 0, 1, 2]]
    rows = [
        f"{str(x)[:23]} " + " ".join(f"{c:.10f}" for c in r) for x, r in zip(t, qq, strict=True)
    ]
    body = rows if records is None else records(rows)
    path.write_text("\n".join([*head, *body, "DATA_STOP", ""]))
    return path


@pytest.fixture(scope="module")
def nadir():
    obs = canx1_pass(Nadir(yaw=20.0))
    return obs, obs.geometry()


@pytest.mark.parametrize(
    "frame, direction, first",
    [("GCRF", "A2B", False), ("EME2000", "B2A", True), ("ICRF", "B2A", False)],
)
def test_aem_of_a_nadir_pass_gives_its_cube(tmp_path, nadir, frame, direction, first):
    obs, g = nadir
    t = times("2024-03-17T01:19:50", "2024-03-17T01:25:10", 10.0)
    q = Observation(obs.orbit, obs.site, t, obs.attitude).quaternions()
    law = read_aem(_aem(tmp_path / "a.aem", t, q, frame, direction, first))
    sample = law.quaternions(t)
    same = np.minimum(np.abs(sample - q).max(axis=1), np.abs(sample + q).max(axis=1))
    assert same.max() < DIGITS_ATOL
    g2 = Observation(obs.orbit, obs.site, obs.times, law).geometry()
    for k in ("to_sun", "to_observer", "to_earth"):
        assert np.abs(g[k].values - g2[k].values).max() < SLERP_ATOL, k


def test_aem_law_in_a_scene_table(tmp_path, nadir):
    obs, g = nadir
    t = times("2024-03-17T01:19:50", "2024-03-17T01:25:10", 10.0)
    q = Observation(obs.orbit, obs.site, t, obs.attitude).quaternions()
    path = _aem(tmp_path / "a.aem", t, q)
    law = law_from_dict({"law": "aem", "path": str(path)})
    g2 = Observation(obs.orbit, obs.site, obs.times, law).geometry()
    assert np.abs(g.to_sun.values - g2.to_sun.values).max() < SLERP_ATOL


def test_truncated_out_of_order_and_unusable_aem(tmp_path):
    t = times("2024-03-17T01:19:50", "2024-03-17T01:20:50", 10.0)
    q = np.tile([0.0, 0.0, 0.0, 1.0], (t.size, 1))
    cut = _aem(tmp_path / "cut.aem", t, q).read_text()
    (tmp_path / "cut2.aem").write_text(cut[: cut.index("DATA_START") + 40])
    with pytest.raises(EphemerisError, match=r"truncated: the DATA_START of line 18 has no"):
        read_aem(tmp_path / "cut2.aem")
    (tmp_path / "cut3.aem").write_text(cut[: cut.index("META_STOP")])
    with pytest.raises(EphemerisError, match=r"cannot be parsed by ccsds-ndm|holds no AEM"):
        read_aem(tmp_path / "cut3.aem")
    short = _aem(tmp_path / "s.aem", t, q, records=lambda rows: rows[:4])
    with pytest.raises(EphemerisError, match=r"truncated: the last record is at .*01:20:20"):
        read_aem(short)
    swap = _aem(tmp_path / "o.aem", t, q, records=lambda rows: [rows[1], rows[0], *rows[2:]])
    with pytest.raises(
        EphemerisError, match=r"line 20: epoch .*01:19:50.000 is not after .* \(line 19\)"
    ):
        read_aem(swap)
    one = _aem(tmp_path / "1.aem", t[:1], q[:1])
    with pytest.raises(EphemerisError, match=r"holds 1 record\(s\)"):
        read_aem(one)
    body = _aem(tmp_path / "b.aem", t, q, frame="ITRF")
    with pytest.raises(EphemerisError, match="is an inertial frame"):
        read_aem(body)
