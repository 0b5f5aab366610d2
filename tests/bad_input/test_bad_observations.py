"""Bad ``[observation]`` tables and measured light curves: every one ends in a named error
that names the key (or the file), or loads with a warning when it is only implausible;
no message shows a file.

Observation tables: orbits (TLE lines spoilt, OMM files that are not XML, JSON or CSV,
special files), sites (unknown names, latitudes beyond the poles, heights of 1e9 m), UTC
windows (years 99999, stop before start, no zone, nonsense) and steps (zero, negative,
NaN, 1e-9 s: a time axis beyond the plan's size limit), given to
:func:`sbrdf_xr.engine.load_scene`.  Light curves: CSV and ECSV files spoilt in their
bytes, columns and values, given to :func:`sbrdf_xr.lightcurves.read_light_curve`.
"""

from __future__ import annotations

import pytest
from bad_input_files import (
    BASE,
    EXPECTED_SPECIAL,
    OBSERVATION,
    SPECIAL,
    copy_of,
    special_file,
    spoil,
    write_toml,
)
from bad_input_tour import SECRET, run_case, tour_settings, unblock_fifos
from hypothesis import given
from hypothesis import strategies as st

from sbrdf_xr.engine import load_scene

CATEGORY = "[observation] tables"

TLE = (
    "1 27847U 03031H   24075.50000000  .00000015  00000-0  21000-4 0  9991",
    "2 27847  98.7200 129.5000 0012000  95.0000 265.0000 14.21950000109836",
)

#: Bad values of each key of [observation] (the TOML types it takes, and others).
OBSERVATION_VALUES = {
    "orbit": ["nope", "canx1", "", 5, "mont-megantic", ["canx1"]],
    "tle": [
        [TLE[0]],
        [TLE[1], TLE[0]],
        [TLE[0], TLE[1][:40]],
        [TLE[0].replace("9991", "9999"), TLE[1]],
        ["x", "y"],
        [TLE[0], TLE[1], TLE[1]],
        "1 2",
        5,
        [],
    ],
    "site": [
        "nope",
        "mont-megantic ",
        "",
        5,
        {"latitude_deg": 91.0, "longitude_deg": 0.0},
        {"latitude_deg": 45.0, "longitude_deg": 1e9},
        {"latitude_deg": 45.0, "longitude_deg": 0.0, "height_m": 1e9},
        {"latitude_deg": float("nan"), "longitude_deg": 0.0},
        {"latitude_deg": 45.0},
        {"latitude_deg": "north", "longitude_deg": 0.0},
        {"lat": 45.0, "lon": 0.0},
    ],
    "start": [
        "99999-01-01T00:00:00",
        "2024-13-01T00:00:00",
        "yesterday",
        "",
        5,
        "2024-03-17T01:24:00",
        "1900-01-01T00:00:00",
        "2024-03-17",
    ],
    "stop": ["2024-03-17T01:21:00", "99999-01-01T00:00:00", "abc", 5, "2124-03-17T01:23:00"],
    "step_s": [0, -1.0, 1e-9, 1e-3, float("nan"), float("inf"), "abc", 1e9, [10.0], True],
    "times": [[], ["abc"], [5], ["2024-03-17T01:22:00", "2024-03-17T01:22:00"], "x"],
    "attitude": [
        {"law": "bogus"},
        {"law": "spin"},
        {"law": 5},
        {},
        "nadir",
        {"law": "nadir", "x": 1},
    ],
    "unknown_key": [1, "x"],
}


def _wrong(key: str, value) -> bool:
    """Values the TOML type allows that are wrong for their key (refused or warned)."""
    if key == "start" and value == "1900-01-01T00:00:00":
        return True  # 124 years from the elements' epoch: SGP4 is meaningless
    if key == "stop" and value == "2124-03-17T01:23:00":
        return True
    if key == "site" and isinstance(value, dict):
        return value.get("height_m", 0.0) > 1e5 or abs(value.get("longitude_deg", 0.0)) > 360
    return False


def _plan_fits(scene) -> None:
    assert scene.n_geometries >= 1
    scene.plan()


def _scene_with(observation: dict) -> dict:
    d = copy_of(BASE)
    del d["attitude"], d["phase_angles"]
    d["observation"] = observation
    return d


@tour_settings(80)
@given(data=st.data())
def test_observation_tables(tmp_path, data):
    key = data.draw(st.sampled_from(sorted(OBSERVATION_VALUES)))
    value = data.draw(st.sampled_from(OBSERVATION_VALUES[key]))
    obs = copy_of(OBSERVATION)
    if key in ("tle", "omm"):
        del obs["orbit"]
    if key == "times":
        del obs["start"], obs["stop"], obs["step_s"]
    obs[key] = value
    path = write_toml(tmp_path / "scene.toml", _scene_with(obs))
    run_case(
        CATEGORY,
        lambda: load_scene(path),
        wrong=_wrong(key, value),
        where=[key, "observation", str(path), "size_limit"],
        check=_plan_fits,
        label=f"[observation] {key} = {value!r}",
        timeout=60,
    )


OMM_SPOILS = {
    "not-xml": "this is not an OMM\n",
    "xml-junk": "<?xml version='1.0'?><omm><body>",
    "json-junk": '{"OBJECT_NAME": 5',
    "json-fields": '[{"OBJECT_NAME": "X", "MEAN_MOTION": "fast"}]',
    "csv-secret": f"{SECRET}\n1,2,3\n",
    "kvn-secret": f"{SECRET}\nCCSDS_OMM_VERS = 2.0\n",
}


@pytest.mark.parametrize("suffix", [".xml", ".json", ".csv", ".txt"])
@pytest.mark.parametrize("spoilt", sorted(OMM_SPOILS))
def test_omm_files(tmp_path, spoilt, suffix):
    omm = tmp_path / f"orbit{suffix}"
    omm.write_text(OMM_SPOILS[spoilt], encoding="utf-8")
    obs = copy_of(OBSERVATION)
    del obs["orbit"]
    obs["omm"] = omm.name  # relative to the scene file
    path = write_toml(tmp_path / "scene.toml", _scene_with(obs))
    run_case(
        CATEGORY,
        lambda: load_scene(path),
        wrong=True,
        where=[str(omm), "omm"],
        check=_plan_fits,
        label=f"omm {spoilt} {suffix}",
    )


@pytest.mark.parametrize("kind", SPECIAL)
def test_special_omm_files(tmp_path, kind):
    omm = special_file(tmp_path, kind, ".xml")
    obs = copy_of(OBSERVATION)
    del obs["orbit"]
    obs["omm"] = str(omm)
    path = write_toml(tmp_path / "scene.toml", _scene_with(obs))
    run_case(
        CATEGORY,
        lambda: load_scene(path),
        wrong=True,
        where=[str(omm)],
        label=f"omm {kind}",
        timeout=10,
        unblock=unblock_fifos([omm]),
        match=EXPECTED_SPECIAL.get(kind),
    )


# ------------------------------------------------------------------ light curves

CURVES = "light curves"

GOOD_CURVE = (
    "time,band,mag,mag_err\n"
    "2024-03-17T01:22:00Z,V,8.1,0.05\n"
    "2024-03-17T01:22:10Z,V,8.2,0.05\n"
    "2024-03-17T01:22:20Z,V,8.3,0.05\n"
)

#: Spoilt light curves: text, and whether it may load (with a check of what loaded).
CURVE_SPOILS = {
    "empty-rows": "time,band,mag,mag_err\n",
    "no-header": "2024-03-17T01:22:00Z,V,8.1,0.05\n",
    "nan-mag": GOOD_CURVE.replace("8.2", "nan"),
    "inf-mag": GOOD_CURVE.replace("8.2", "inf"),
    "text-mag": GOOD_CURVE.replace("8.2", "bright"),
    "negative-err": GOOD_CURVE.replace("0.05\n", "-0.05\n", 1),
    "zero-err": GOOD_CURVE.replace("0.05", "0"),
    "huge-mag": GOOD_CURVE.replace("8.2", "1e30"),
    "year-99999": GOOD_CURVE.replace("2024-03-17T01:22:10Z", "99999-03-17T01:22:10Z"),
    "bad-time": GOOD_CURVE.replace("2024-03-17T01:22:10Z", "noon"),
    "no-zone": GOOD_CURVE.replace("Z,", ","),
    "bogus-band": GOOD_CURVE.replace(",V,", ",bogus,"),
    "ragged": GOOD_CURVE + "2024-03-17T01:22:30Z,V\n",
    "extra-column": GOOD_CURVE.replace("mag_err\n", "mag_err,x\n"),
    "duplicate-columns": GOOD_CURVE.replace("mag_err", "mag"),
    "secret-header": f"{SECRET}\n" + GOOD_CURVE,
    "secret-cell": GOOD_CURVE.replace("8.2", SECRET.replace(",", "")),
    "semicolons": GOOD_CURVE.replace(",", ";"),
    "binary": "\x00\x01\x02" * 20,
}


def _curve_usable(ds) -> None:
    import numpy as np

    for v in ds.data_vars.values():
        if np.issubdtype(v.dtype, np.floating):
            assert np.isfinite(v.values).all(), f"{v.name}: non-finite values"


@tour_settings(60)
@given(
    spoilt=st.sampled_from(sorted(CURVE_SPOILS)),
    suffix=st.sampled_from([".csv", ".ecsv", ".txt"]),
    how=st.sampled_from(["as-is", "truncate", "splice"]),
    at=st.floats(0.0, 1.0),
    junk=st.binary(max_size=16),
)
def test_light_curve_files(tmp_path, spoilt, suffix, how, at, junk):
    from sbrdf_xr.lightcurves import read_light_curve

    path = tmp_path / f"curve{suffix}"
    data = CURVE_SPOILS[spoilt].encode("utf-8")
    if how != "as-is":
        data = spoil(data, how, at, junk)
    path.write_bytes(data)
    run_case(
        CURVES,
        lambda: read_light_curve(path),
        where=[str(path), "light curve"],
        check=_curve_usable,
        label=f"{spoilt}{suffix} {how} at {at:.2f}: {data[:120]!r}",
        timeout=30,
    )


@pytest.mark.parametrize("kind", SPECIAL)
@pytest.mark.parametrize("suffix", [".csv", ".ecsv", ".nc"])
def test_special_light_curve_files(tmp_path, kind, suffix):
    from sbrdf_xr.lightcurves import read_light_curve

    path = special_file(tmp_path, kind, suffix)
    run_case(
        CURVES,
        lambda: read_light_curve(path),
        wrong=True,
        where=[str(path)],
        label=f"light curve {kind}{suffix}",
        timeout=10,
        unblock=unblock_fifos([path]),
        match=EXPECTED_SPECIAL.get(kind),
    )
