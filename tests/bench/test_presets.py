"""The presets' measured cost and error shipped with the package (sbrdf_xr.bench.presets)."""

from __future__ import annotations

import math
from pathlib import Path

from sbrdf_xr.bench import presets
from sbrdf_xr.bench.rows import BenchRow
from sbrdf_xr.engine.knobs import PRESETS

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "guide" / "accuracy-and-cost.md"


def test_the_shipped_record_has_every_preset_measured():
    rec = presets.load_presets()
    assert rec is not None, (
        "sbrdf_xr/bench/presets.json is missing (sbrdf-xr bench --record-presets)"
    )
    assert rec["command"].startswith("sbrdf-xr bench") and rec["date"] and "cores" in rec["machine"]
    assert rec["sweeps"]
    for sweep, found in rec["sweeps"].items():
        assert list(found) == list(PRESETS), sweep
        for name, v in found.items():
            assert v["time_ratio"] > 0 and v["time_spread"] >= 0, (sweep, name)
            assert v["mmag_max"] >= v["mmag_median"] >= 0, (sweep, name)
            assert v["model_mmag_max"] >= v["model_mmag_median"] > 0, (sweep, name)
        assert found["reference"]["mmag_max"] == 0.0  # the reference against itself
    # the guide's accuracy table is the recorded run's: same date and machine
    text = " ".join(GUIDE.read_text(encoding="utf-8").split())  # lines wrap anywhere
    assert rec["date"] in text and rec["machine"] in text


def test_a_record_round_trips_and_prints(tmp_path):
    rows = [
        BenchRow(
            f"preset: {p}",
            0.5,
            "reference",
            0.4 + k,
            sweep="demo",
            mmag_max=10.0 * k,
            mmag_median=k,
            spread=0.1,
            model_mmag_max=100.0,
            model_mmag_median=5.0,
            knob="preset",
        )
        for k, p in enumerate(PRESETS)
    ]
    rows.append(BenchRow("lookup method: linear", 0.5, "reference", 0.3, knob="lookup method"))
    rec = presets.presets_record(rows, "sbrdf-xr bench --quick")
    path = presets.write_presets(rec, tmp_path / "p.json")
    back = presets.load_presets(path)
    assert back == rec and list(back["sweeps"]["demo"]) == list(PRESETS)
    assert presets.load_presets(tmp_path / "none.json") is None
    text = presets.presets_table(back)
    assert "sbrdf-xr bench --quick" in text and "[demo]" in text
    assert [line.split()[0] for line in text.splitlines()[3:]] == list(PRESETS)
    assert math.isclose(back["sweeps"]["demo"]["balanced"]["time_ratio"], 1.4)
