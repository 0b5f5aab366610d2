"""Tests of sbrdf_xr.bench.calls and the loaded-machine warning of sbrdf_xr.bench.rows."""

from __future__ import annotations

import time

import numpy as np
import pytest
import trimesh

from sbrdf_xr import Scene, load_spacecraft
from sbrdf_xr.bench.accuracy import fixed_cost_rows
from sbrdf_xr.bench.calls import single_call_times
from sbrdf_xr.bench.rows import LOADED_SPREAD, BenchRow, load_warning
from sbrdf_xr.materials.schema import lambertian


def _scene():
    box = load_spacecraft(trimesh.creation.box(), material="grey")
    grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    return Scene(box, {"grey": grey}, attitudes=[[0, 0, 0, 1.0]] * 3, phase_angles=[10.0])


# ~30 s on a fresh machine; the evaluator's results: tests/engine/test_evaluator.py
@pytest.mark.slow
def test_single_call_times_every_path():
    times = single_call_times(_scene().plan(), repeat=2, calls=3)
    assert len(times) == 8
    for best, spread in times.values():
        assert best > 0.0 and spread >= 0.0


def test_single_call_times_in_cpu_time():
    """The CPU time of this thread (a loaded machine's other processes do not add to
    it): every path costs some, and never more than a second for three calls."""
    cpu = single_call_times(_scene().plan(), repeat=2, calls=3, clock=time.thread_time)
    assert all(0.0 < best < 1.0 for best, _ in cpu.values())


def test_fixed_cost_rows_are_their_own_rows():
    rows = fixed_cost_rows(_scene(), {"method": "linear"}, t_ref=2.0, repeat=2)
    assert [r.knob for r in rows] == ["fixed cost", "fixed cost"]
    for r in rows:
        assert r.ratio == r.seconds / 2.0 and np.isfinite(r.spread)


def test_load_warning_from_the_spread():
    def rows(*spreads):
        return [BenchRow(str(i), 1.0, "0", 1.0, spread=s) for i, s in enumerate(spreads)]

    assert load_warning(rows(0.02, 0.05, 0.1, float("nan"))) is None
    assert load_warning(rows(float("nan"))) is None  # nothing repeated: nothing to say
    msg = load_warning(rows(0.3, 0.4, 0.5))  # every row's repeats differ by a third or more
    assert msg is not None and "loaded" in msg and "50%" in msg
    # a few wild rows among quiet ones: a third of them above twice the limit
    assert load_warning(rows(0.02, 0.03, 3 * LOADED_SPREAD)) is not None
    assert load_warning(rows(0.02, 0.03, 0.04, 3 * LOADED_SPREAD)) is None
