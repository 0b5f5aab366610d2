"""Benchmarks: what accuracy costs in time (``sbrdf-xr bench``).

Every benchmark returns rows (:class:`BenchRow`) timed against a baseline measured in
the same run, so their ratios are comparable on a shared machine.

Modules
-------
``rows``
    The record of one measurement, how it is timed and how rows are shown.
``suite``
    The benchmarks users run: table construction, look-up, kernel throughput, the
    geometry of a pass.
``accuracy``
    The accuracy/cost sweep of the knobs and presets.
``engine``
    What a sweep costs end to end.
``goals``
    The goals of issue 47, each a row: value, baseline, ratio, goal, met.
``machine``
    This machine's own ceilings: its disk's write rate, two threads against one.
``calls``
    What a small call costs: one geometry through the compiled evaluator, ``simulate``
    and the bare kernel.
``shadowing``
    Accuracy and cost of the shadowing methods against the exact method.
``presets``
    The presets' measured error and cost, recorded from a run and shipped.
``parts``
    What open surfaces and sun-tracking parts cost against the rigid closed path.
``starlink``
    Accuracy against the sky: the built-in Starlink v1.5-class body at 1,173 measured
    magnitudes, beside the diffuse-sphere control (:func:`predict_starlink`).
"""

from ..errors import renamed_attributes
from . import (
    accuracy,
    calls,
    engine,
    goals,
    machine,
    parts,
    presets,
    rows,
    shadowing,
    starlink,
    suite,
)
from .accuracy import BANDS, CANX1_MATERIALS, accuracy_cost, shadow_rows
from .engine import engine_rows, sweep_job
from .machine import DiskCost, disk_cost, disk_rate, thread_scaling
from .parts import WING_KINDS, canx1_with_wing, parts_rows
from .presets import load_presets, presets_record, presets_table, write_presets
from .rows import (
    BenchRow,
    best_time,
    format_rows,
    load_warning,
    plot_front,
    rows_to_dataset,
    timed_runs,
)
from .shadowing import (
    ACCURACY_BODIES,
    CostRow,
    ShadowRow,
    accuracy_rows,
    canx1_sweep_rows,
    geometries,
    lambertian_signal,
    markdown,
    scaling_rows,
)
from .starlink import limb_sunlight, pomenis_table, predict_starlink, starlink_scene
from .suite import bench_build_lut, bench_geometry, bench_lookup, kernel_throughput, run

__all__ = [
    "ACCURACY_BODIES",
    "BANDS",
    "CANX1_MATERIALS",
    "WING_KINDS",
    "BenchRow",
    "CostRow",
    "DiskCost",
    "ShadowRow",
    "accuracy",
    "accuracy_cost",
    "accuracy_rows",
    "bench_build_lut",
    "bench_geometry",
    "bench_lookup",
    "best_time",
    "calls",
    "canx1_sweep_rows",
    "canx1_with_wing",
    "disk_cost",
    "disk_rate",
    "engine",
    "engine_rows",
    "format_rows",
    "geometries",
    "goals",
    "kernel_throughput",
    "lambertian_signal",
    "limb_sunlight",
    "load_presets",
    "load_warning",
    "machine",
    "markdown",
    "parts",
    "parts_rows",
    "plot_front",
    "pomenis_table",
    "predict_starlink",
    "presets",
    "presets_record",
    "presets_table",
    "rows",
    "rows_to_dataset",
    "run",
    "scaling_rows",
    "shadow_rows",
    "shadowing",
    "starlink",
    "starlink_scene",
    "suite",
    "sweep_job",
    "thread_scaling",
    "timed_runs",
    "write_presets",
]

#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(__name__, globals(), {"KINDS": "WING_KINDS"})
