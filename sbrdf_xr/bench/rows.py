"""Benchmark rows: the record of one measurement, how it is timed, and how rows are shown.

A :class:`BenchRow` holds what was measured, its best wall time (:func:`best_time`) and
the ratio to a baseline measured in the same run; :func:`format_rows` prints rows as a
plain-text table, :func:`rows_to_dataset` labels them for netCDF or CSV, and
:func:`plot_front` draws the accuracy/time front.  The benchmarks of :mod:`sbrdf_xr.bench`
and :mod:`sbrdf_xr.bench.engine` report in these rows.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import xarray as xr

__all__ = [
    "LOADED_SPREAD",
    "BenchRow",
    "best_time",
    "format_rows",
    "load_average",
    "load_header",
    "load_warning",
    "plot_front",
    "rows_to_dataset",
    "timed_runs",
]

#: Median spread of the repeated timings (``max / min - 1``) above which a run is
#: reported as taken on a loaded machine: on a quiet one the repeats of a row agree to
#: a few per cent.
LOADED_SPREAD = 0.15


@dataclass
class BenchRow:
    """One benchmark result.

    Attributes
    ----------
    name : str
        What was measured (the knob and its setting).
    seconds : float
        Best wall time over the repeats [s].
    baseline : str
        Name of the baseline of the ratio.
    ratio : float
        ``seconds / baseline seconds``: the cost relative to the baseline
        (< 1 is faster).
    extra : str
        Throughput or notes, in words.
    sweep : str
        Which sweep.
    mmag_max, mmag_median, rel_p99 : float
        Error against the reference (NaN when not applicable).
    spread : float
        ``max / min - 1`` of the repeated timings (NaN for a single run): how far the
        machine moved the time of this row between repeats.
    model_mmag_max, model_mmag_median : float
        Error against the materials' generating models (NaN when not measured).
    goal : str
        The goal this row is held to, in words ("" for none; :mod:`sbrdf_xr.bench.goals`).
    met : bool or None
        Whether the measured value meets ``goal`` (None: no goal, or not measured).

    Examples
    --------
    >>> from sbrdf_xr.bench.rows import BenchRow
    >>> row = BenchRow("lookup method: linear", 0.6, "reference", 0.3, mmag_max=12.0)
    >>> row.ratio, row.mmag_max, row.rel_p99
    (0.3, 12.0, nan)
    """

    name: str
    seconds: float
    baseline: str
    ratio: float
    extra: str = ""
    sweep: str = ""
    mmag_max: float = float("nan")
    mmag_median: float = float("nan")
    rel_p99: float = float("nan")
    knob: str = field(default="", repr=False)
    spread: float = float("nan")
    model_mmag_max: float = float("nan")
    model_mmag_median: float = float("nan")
    goal: str = ""
    met: bool | None = None


def best_time(func: Callable[[], object], repeat: int = 3, number: int = 1) -> float:
    """Best of ``repeat`` wall times of ``number`` calls of ``func`` after a warm-up [s per call].

    Examples
    --------
    >>> from sbrdf_xr.bench.rows import best_time
    >>> calls = []
    >>> t = best_time(lambda: calls.append(1), repeat=3, number=2)
    >>> len(calls), 0.0 <= t < 1.0  # one warm-up call, then 3 x 2 timed calls
    (7, True)
    """
    func()
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(number):
            func()
        best = min(best, (time.perf_counter() - t0) / number)
    return float(best)


def timed_runs(
    funcs: dict[str, Callable[[], object]],
    repeat: int = 3,
    clock: Callable[[], float] = time.perf_counter,
) -> dict[str, tuple[float, float]]:
    """Best wall time (or time of ``clock``, e.g. ``time.thread_time`` for the CPU
    time of this thread) and spread of each function, the repeats interleaved.

    Every function runs once untimed (a warm-up), then ``repeat`` rounds time each of
    them in turn: a slow spell of a shared machine then slows every function of a
    round, not all the repeats of one, so the ratios of the best times hold.

    Returns
    -------
    dict of str to (float, float)
        ``(best seconds, max / min - 1)`` per function (spread NaN for one repeat).

    Examples
    --------
    >>> from sbrdf_xr.bench.rows import timed_runs
    >>> calls = []
    >>> out = timed_runs({"a": lambda: calls.append("a"), "b": lambda: calls.append("b")}, 2)
    >>> "".join(calls), sorted(out)  # warm-ups, then two interleaved rounds
    ('ababab', ['a', 'b'])
    >>> all(best >= 0.0 and spread >= 0.0 for best, spread in out.values())
    True
    """
    for f in funcs.values():
        f()
    times: dict[str, list[float]] = {k: [] for k in funcs}
    for _ in range(repeat):
        for k, f in funcs.items():
            t0 = clock()
            f()
            times[k].append(clock() - t0)
    return {
        k: (min(v), max(v) / min(v) - 1.0 if len(v) > 1 and min(v) > 0 else float("nan"))
        for k, v in times.items()
    }


def load_warning(rows: list[BenchRow], limit: float = LOADED_SPREAD) -> str | None:
    """A warning when the spread of the repeated timings says the machine was loaded, or
    None: the median spread of the rows that have one is above ``limit``, or a third of
    them are above twice ``limit``.  The message gives the spreads and the load average.

    Examples
    --------
    >>> from sbrdf_xr.bench.rows import BenchRow, load_warning
    >>> quiet = [BenchRow("a", 1.0, "a", 1.0, spread=s) for s in (0.03, 0.1)]
    >>> load_warning(quiet) is None
    True
    >>> busy = quiet + [BenchRow("c", 1.0, "a", 1.0, spread=0.9)] * 3
    >>> load_warning(busy).startswith("the machine was loaded")
    True
    """
    import os

    spreads = np.array([r.spread for r in rows if np.isfinite(r.spread)])
    if not spreads.size:
        return None
    median = float(np.median(spreads))
    wide = float(np.mean(spreads > 2 * limit))
    if median <= limit and wide < 1 / 3:
        return None
    try:
        load = "load average {:.1f}, {:.1f}, {:.1f}".format(*os.getloadavg())
    except OSError:  # pragma: no cover - not on every platform
        load = "load average unknown"
    return (
        f"the machine was loaded: the repeats of a row differ by {median:.0%} (median) and "
        f"{float(spreads.max()):.0%} (largest) over {spreads.size} rows ({wide:.0%} of them "
        f"above {2 * limit:.0%}; {load} on {os.cpu_count()} CPUs); the ratios are uncertain "
        "by about as much: run again on a quiet machine"
    )


def load_average() -> tuple[float, float, float] | None:
    """The load average over 1, 5 and 15 minutes (processes running or waiting), or
    None where the platform gives none.

    Examples
    --------
    >>> from sbrdf_xr.bench.rows import load_average
    >>> load = load_average()
    >>> load is None or (len(load) == 3 and min(load) >= 0.0)
    True
    """
    import os

    try:
        one, five, fifteen = os.getloadavg()
    except (OSError, AttributeError):  # pragma: no cover - not on every platform
        return None
    return (float(one), float(five), float(fifteen))


def load_header(
    start: tuple[float, float, float] | None, end: tuple[float, float, float] | None
) -> str:
    """The line above a benchmark table: the load average (1, 5, 15 minutes) at the start
    and at the end of the run, on this machine's CPUs.

    Examples
    --------
    >>> from sbrdf_xr.bench.rows import load_header
    >>> line = load_header((0.5, 0.4, 0.3), (2.0, 1.25, 0.5))
    >>> print(line.partition(" on ")[0])
    load average (1, 5, 15 min): 0.50, 0.40, 0.30 at the start, 2.00, 1.25, 0.50 at the end,
    """
    import os

    def text(load: tuple[float, float, float] | None) -> str:
        return "unknown" if load is None else ", ".join(f"{x:.2f}" for x in load)

    return (
        f"load average (1, 5, 15 min): {text(start)} at the start, {text(end)} at the end, "
        f"on {os.cpu_count()} CPUs"
    )


def format_rows(rows: list[BenchRow]) -> str:
    """A plain-text table of benchmark rows (time as a ratio to the row's baseline).

    Examples
    --------
    >>> from sbrdf_xr.bench.rows import BenchRow
    >>> rows = [
    ...     BenchRow("reference", 2.0, "reference", 1.0, sweep="demo",
    ...              mmag_max=0.0, mmag_median=0.0, rel_p99=0.0, spread=0.05),
    ...     BenchRow("lookup method: linear", 0.6, "reference", 0.3, sweep="demo",
    ...              mmag_max=12.0, mmag_median=0.4, rel_p99=0.01, spread=0.12),
    ...     BenchRow("preset: fast", 0.5, "reference", 0.25, sweep="demo", mmag_max=12.0,
    ...              mmag_median=0.4, model_mmag_max=900.0, model_mmag_median=40.0),
    ... ]
    >>> from sbrdf_xr.bench.rows import format_rows
    >>> print(format_rows(rows))
    [demo]
    case                   time/baseline spread    mmag max   mmag med   rel p99  notes
    reference                         1x +5%             0          0         0  vs reference
    lookup method: linear           0.3x +12%           12        0.4      0.01  vs reference
    preset: fast                   0.25x                12        0.4       nan  vs generating ...

    The spread is that of the repeated timings (:func:`timed_runs`).
    """
    w = max(len(r.name) for r in rows)
    out = []
    sweep = None
    for r in rows:
        if r.sweep != sweep:
            sweep = r.sweep
            out += [
                "",
                f"[{sweep}]",
                f"{'case':<{w}}  {'time/baseline':>13} {'spread':<6}  "
                f"{'mmag max':>9}  {'mmag med':>9}  {'rel p99':>8}  notes",
            ]
        err = (
            f"{r.mmag_max:>9.3g}  {r.mmag_median:>9.3g}  {r.rel_p99:>8.2g}"
            if np.isfinite(r.mmag_max)
            else f"{'':>9}  {'':>9}  {'':>8}"
        )
        note = r.extra or f"vs {r.baseline}"
        if np.isfinite(r.model_mmag_max):
            note = (
                f"vs generating models: {r.model_mmag_max:.3g} / {r.model_mmag_median:.3g} mmag "
                f"(worst / median); {note}"
            )
        spread = f"+{r.spread:.0%}" if np.isfinite(r.spread) else ""
        out.append(f"{r.name:<{w}}  {r.ratio:>12.3g}x {spread:<6}  {err}  {note}")
    return "\n".join(out).lstrip("\n")


def rows_to_dataset(rows: list[BenchRow]) -> xr.Dataset:
    """The rows as a labelled Dataset over ``case`` (for netCDF or CSV).

    Examples
    --------
    >>> from sbrdf_xr.bench.rows import BenchRow
    >>> rows = [
    ...     BenchRow("reference", 2.0, "reference", 1.0, sweep="demo",
    ...              mmag_max=0.0, mmag_median=0.0, rel_p99=0.0),
    ...     BenchRow("lookup method: linear", 0.6, "reference", 0.3, sweep="demo",
    ...              mmag_max=12.0, mmag_median=0.4, rel_p99=0.01),
    ... ]
    >>> from sbrdf_xr.bench.rows import rows_to_dataset
    >>> ds = rows_to_dataset(rows)
    >>> ds.case.values.tolist(), ds.time_ratio.values.tolist()
    (['reference', 'lookup method: linear'], [1.0, 0.3])
    >>> ds.mmag_max.attrs["units"]
    'mmag'
    """

    def col(name: str) -> list[Any]:
        return [getattr(r, name) for r in rows]

    return xr.Dataset(
        {
            "seconds": ("case", col("seconds"), {"units": "s", "long_name": "best wall time"}),
            "time_ratio": (
                "case",
                col("ratio"),
                {
                    "units": "1",
                    "long_name": "wall time / baseline wall time (or measured value / baseline "
                    "value, as the notes say)",
                },
            ),
            "mmag_max": (
                "case",
                col("mmag_max"),
                {"units": "mmag", "long_name": "largest band magnitude error"},
            ),
            "mmag_median": (
                "case",
                col("mmag_median"),
                {"units": "mmag", "long_name": "median band magnitude error"},
            ),
            "rel_p99": (
                "case",
                col("rel_p99"),
                {"units": "1", "long_name": "99th percentile relative spectral error"},
            ),
            "time_spread": (
                "case",
                col("spread"),
                {"units": "1", "long_name": "largest / smallest of the repeated wall times - 1"},
            ),
            "model_mmag_max": (
                "case",
                col("model_mmag_max"),
                {"units": "mmag", "long_name": "largest band error against the generating models"},
            ),
            "model_mmag_median": (
                "case",
                col("model_mmag_median"),
                {"units": "mmag", "long_name": "median band error against the generating models"},
            ),
            "baseline": ("case", col("baseline"), {"long_name": "baseline of the time ratio"}),
            "goal": ("case", col("goal"), {"long_name": "goal the case is held to"}),
            "goal_met": (
                "case",
                ["" if r.met is None else "met" if r.met else "not met" for r in rows],
                {"long_name": "whether the measured value meets the goal"},
            ),
            "sweep": ("case", col("sweep"), {"long_name": "sweep"}),
            "notes": ("case", col("extra"), {"long_name": "notes"}),
        },
        coords={"case": ("case", col("name"), {"long_name": "knob and setting"})},
        attrs={"title": "sbrdf_xr accuracy/cost benchmark"},
    )


def plot_front(rows: list[BenchRow], ax: Any = None) -> Any:
    """The accuracy/time figure of the rows (:func:`sbrdf_xr.plot.accuracy_front`).

    ``ax`` is not used (the figure has its own two panels); kept for callers that pass it.

    Examples
    --------
    >>> from sbrdf_xr.bench.rows import BenchRow
    >>> rows = [
    ...     BenchRow("reference", 2.0, "reference", 1.0, sweep="demo",
    ...              mmag_max=0.0, mmag_median=0.0, rel_p99=0.0),
    ...     BenchRow("lookup method: linear", 0.6, "reference", 0.3, sweep="demo",
    ...              mmag_max=12.0, mmag_median=0.4, rel_p99=0.01),
    ... ]
    >>> import matplotlib.pyplot as plt
    >>> from sbrdf_xr.bench.rows import plot_front
    >>> fig = plot_front(rows)
    >>> ax = fig.axes[0]
    >>> ax.get_xscale(), ax.get_xlabel()
    ('log', 'band error against the baseline [mmag]')
    >>> plt.close(fig)
    """
    from ..plot import accuracy_front

    return accuracy_front(rows_to_dataset(rows))
