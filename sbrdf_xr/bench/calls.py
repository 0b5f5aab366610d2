"""What a small call costs: one geometry through the compiled evaluator, ``simulate`` and
the bare kernel, measured in one run (rows of ``sbrdf-xr bench --engine``).

Every function is timed over many calls per repeat (a call is microseconds), the
repeats interleaved (:func:`~sbrdf_xr.bench.rows.timed_runs`), so that a slow spell of
a shared machine slows every function of a round and the ratios hold.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np

from .rows import BenchRow, timed_runs

__all__ = ["single_call_rows", "single_call_times"]

#: Calls per timed repeat: a repeat lasts milliseconds, far above the clock's resolution.
_CALLS = 200
#: Calls per repeat and repeats of :func:`single_call_rows` (short windows, many).
_SHORT, _ROUNDS = 20, 30


def _looped(f: Callable[[], object], n: int) -> Callable[[], None]:
    def run() -> None:
        for _ in range(n):
            f()

    return run


def single_call_times(
    plan: Any,
    repeat: int = 5,
    calls: int = _CALLS,
    clock: Callable[[], float] = time.perf_counter,
) -> dict[str, tuple[float, float]]:
    """Seconds per call (best repeat) and spread of one geometry of ``plan`` (its first)
    through each path: the evaluator on body-frame directions (one vector each: its
    one-call path; one row each: its general path) and on an attitude, the
    block step before the evaluator (the effects' path), ``run_block``, ``simulate`` of
    the plan, and the bare fused kernel with its arguments bundled per call and bound
    once (:class:`~sbrdf_xr.kernels.sums.BoundSums`).  ``clock``: wall time, or
    ``time.thread_time`` for the CPU time of the calling thread (what a loaded
    machine's other processes do not add to).

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.bench.calls import single_call_times
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> plan = Scene(box, {"grey": grey}, attitudes=[[0, 0, 0, 1.0]], phase_angles=[10.0]).plan()
    >>> times = single_call_times(plan, repeat=1, calls=2)
    >>> len(times), sorted(times)[3:6]
    (8, ['evaluator, attitude', 'evaluator, body frame', 'evaluator, body frame, general path'])
    """
    from ..engine.evaluator import Evaluator, block_outputs
    from ..engine.run import run_block, simulate
    from ..kernels.sums import BoundSums, fused_sums

    ev = Evaluator(plan)
    g = plan.geometry
    block = g.block(slice(0, 1))
    s, o = block.to_sun[:1].copy(), block.to_observer[:1].copy()
    t = plan.terms
    method = plan.knobs["method"]
    bound = BoundSums(t.normal, t.area, t.material, plan.tables, method, False, t.normal_rows)
    funcs: dict[str, Callable[[], object]] = {
        "evaluator, body frame": lambda: ev(s[0], o[0]),
        "evaluator, body frame, general path": lambda: ev(s, o),
        "effects path (before the evaluator)": lambda: block_outputs(plan, block, fast=False),
        "run_block": lambda: run_block(plan, slice(0, 1)),
        "simulate(plan)": lambda: simulate(plan),
        "bare kernel, bundled per call (fused_sums)": lambda: fused_sums(
            s, o, t.normal, t.area, t.material, plan.tables, method, None, False, t.normal_rows
        ),
        "bare kernel, bound once (BoundSums)": lambda: bound(s, o),
    }
    if hasattr(g, "attitudes"):
        q, s_ref, o_ref = g.attitudes[0], g.sun_ref[0], g.obs_ref[0]
        funcs["evaluator, attitude"] = lambda: ev(s_ref, o_ref, attitudes=q)
    timing = timed_runs({k: _looped(f, calls) for k, f in funcs.items()}, repeat, clock)
    return {k: (best / calls, spread) for k, (best, spread) in timing.items()}


def single_call_rows(repeat: int = 5) -> list[BenchRow]:
    """One warm CanX-1 geometry (first attitude of the rotation, phase 10 deg, 141
    wavelengths, every default output) through each path of :func:`single_call_times`,
    as ratios to ``simulate(plan)`` of the same one-geometry plan.

    Examples
    --------
    CanX-1 with its measured tables (seconds to load); not run here:

    >>> from sbrdf_xr.bench.calls import single_call_rows
    >>> rows = single_call_rows(repeat=3)  # doctest: +SKIP
    >>> rows[0].name  # doctest: +SKIP
    'single geometry: evaluator, body frame'
    """
    from ..engine import builtin_scene

    rot = builtin_scene("canx1-rotation")
    one = rot.with_options(attitudes=np.asarray(rot.attitudes)[:1], attitude_angle=None)
    plan = one.plan()
    # short repeats, many of them: on a loaded machine the best of many short windows
    # is the one no other process preempted
    rounds = max(repeat, _ROUNDS)
    times = single_call_times(plan, rounds, _SHORT)
    cpu = single_call_times(plan, rounds, _SHORT, clock=time.thread_time)
    base = times["simulate(plan)"][0]
    kernel = times["bare kernel, bound once (BoundSums)"][0]
    order = [
        "evaluator, body frame",
        "evaluator, body frame, general path",
        "evaluator, attitude",
        "effects path (before the evaluator)",
        "run_block",
        "simulate(plan)",
        "bare kernel, bundled per call (fused_sums)",
        "bare kernel, bound once (BoundSums)",
    ]
    return [
        BenchRow(
            f"single geometry: {name}",
            times[name][0],
            "simulate(plan), same plan",
            times[name][0] / base,
            f"{times[name][0] * 1e6:.1f} us per call ({cpu[name][0] * 1e6:.1f} us CPU), "
            f"{times[name][0] / kernel:.2g}x the bound kernel",
            sweep="single calls, canx1 one geometry, warm, 141 nm",
            spread=times[name][1],
        )
        for name in order
        if name in times
    ]
