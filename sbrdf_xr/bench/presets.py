"""The presets' measured error and cost, as the last recorded benchmark run found them.

``sbrdf-xr bench --record-presets`` (run in a source checkout, then committed) writes the
preset rows of the accuracy/cost benchmark (:func:`sbrdf_xr.bench.accuracy_cost`) to
``presets.json`` next to this module, with the date, the machine and the command of the
run; the package ships that file, and ``sbrdf-xr knobs`` shows it
(:func:`presets_table`) under the knob table.
"""

from __future__ import annotations

import json
import os
import platform
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from .._output import atomic_file
from .rows import BenchRow

__all__ = [
    "PRESETS_FILE",
    "load_presets",
    "machine",
    "presets_record",
    "presets_table",
    "write_presets",
]

#: The shipped record of the presets' measured error and cost.
PRESETS_FILE = Path(__file__).resolve().parent / "presets.json"

_FIELDS = (
    ("time_ratio", "ratio"),
    ("time_spread", "spread"),
    ("mmag_max", "mmag_max"),
    ("mmag_median", "mmag_median"),
    ("model_mmag_max", "model_mmag_max"),
    ("model_mmag_median", "model_mmag_median"),
)


def _number(x: float) -> float | None:
    return float(f"{x:.4g}") if np.isfinite(x) else None


def machine() -> str:
    """This machine in a few words: cores, processor, system, Python and numpy.

    Examples
    --------
    >>> "cores" in machine()
    True
    """
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not on Linux
        cores = os.cpu_count() or 1
    cpu = platform.processor() or platform.machine()
    try:  # the processor's name where the system tells it (Linux)
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            names = [ln.split(":", 1)[1].strip() for ln in f if ln.startswith("model name")]
        cpu = names[0] if names else cpu
    except OSError:  # pragma: no cover - not on Linux
        pass
    return (
        f"{cores} cores, {cpu}, {platform.system()} {platform.release()}, "
        f"Python {platform.python_version()}, numpy {np.__version__}"
    )


def presets_record(rows: list[BenchRow], command: str) -> dict[str, Any]:
    """The preset rows of a benchmark run as a record (date, machine, command, rows).

    Examples
    --------
    >>> from sbrdf_xr.bench.rows import BenchRow
    >>> rows = [BenchRow("preset: fast", 0.5, "reference", 0.4, sweep="demo", mmag_max=12.0,
    ...                  mmag_median=0.5, spread=0.1, model_mmag_max=900.0,
    ...                  model_mmag_median=40.0, knob="preset"),
    ...         BenchRow("lookup method: linear", 0.5, "reference", 0.4, knob="lookup method")]
    >>> rec = presets_record(rows, "sbrdf-xr bench --record-presets")
    >>> rec["sweeps"]["demo"]["fast"]["time_ratio"], sorted(rec)
    (0.4, ['command', 'date', 'machine', 'sweeps'])
    """
    sweeps: dict[str, dict[str, dict[str, float | None]]] = {}
    for r in rows:
        if r.knob != "preset":
            continue
        name = r.name.split(": ", 1)[1]
        sweeps.setdefault(r.sweep, {})[name] = {
            key: _number(getattr(r, attr)) for key, attr in _FIELDS
        }
    return {
        "date": datetime.now(UTC).strftime("%Y-%m-%d"),
        "machine": machine(),
        "command": command,
        "sweeps": sweeps,
    }


def write_presets(record: dict[str, Any], path: str | os.PathLike[str] = PRESETS_FILE) -> Path:
    """Write a :func:`presets_record` as JSON (the shipped file by default).

    Examples
    --------
    >>> import tempfile
    >>> rec = {"date": "2026-01-01", "machine": "m", "command": "c", "sweeps": {}}
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = write_presets(rec, Path(tmp) / "presets.json")
    ...     back = load_presets(path)
    >>> back == rec
    True
    """
    path = Path(path)
    with atomic_file(path, overwrite=True) as tmp:  # a special file at path is refused
        tmp.write_text(json.dumps(record, indent=1) + "\n", encoding="utf-8")
    return path


def load_presets(path: str | os.PathLike[str] = PRESETS_FILE) -> dict[str, Any] | None:
    """The recorded presets (the shipped file by default), or None when there is none.

    Examples
    --------
    >>> rec = load_presets()
    >>> rec is None or sorted(rec) == ["command", "date", "machine", "sweeps"]
    True
    """
    try:
        return dict(json.loads(Path(path).read_text(encoding="utf-8")))
    except FileNotFoundError:
        return None


def _fmt(x: float | None, spec: str = ".3g") -> str:
    return "-" if x is None else format(x, spec)


def presets_table(record: dict[str, Any] | None = None) -> str:
    """The presets' measured cost and error as text (``sbrdf-xr knobs``).

    Examples
    --------
    >>> rec = {"date": "2026-01-01", "machine": "2 cores", "command": "sbrdf-xr bench",
    ...        "sweeps": {"demo": {"fast": {"time_ratio": 0.4, "time_spread": 0.1,
    ...        "mmag_max": 12.0, "mmag_median": 0.5, "model_mmag_max": 900.0,
    ...        "model_mmag_median": 40.0}}}}
    >>> print(presets_table(rec))  # doctest: +NORMALIZE_WHITESPACE
    presets as measured by `sbrdf-xr bench` on 2026-01-01 (2 cores); band errors in V, R, I,
    worst / median [mmag], against the reference and the materials' generating models:
    [demo]       time / reference   vs reference    vs models
      fast       0.4x (+10%)        12 / 0.5        900 / 40
    """
    record = load_presets() if record is None else record
    if not record:
        return "presets: no benchmark run recorded (sbrdf-xr bench --record-presets)"
    lines = [
        f"presets as measured by `{record['command']}` on {record['date']} "
        f"({record['machine']}); band errors in V, R, I,",
        "worst / median [mmag], against the reference and the materials' generating models:",
    ]
    for sweep, presets in record["sweeps"].items():
        lines.append(
            f"{'[' + sweep + ']':<11}  {'time / reference':<17}  {'vs reference':<14}  vs models"
        )
        for name, v in presets.items():
            spread = "" if v["time_spread"] is None else f" (+{v['time_spread']:.0%})"
            lines.append(
                f"  {name:<9}  {_fmt(v['time_ratio']) + 'x' + spread:<17}  "
                f"{_fmt(v['mmag_max']) + ' / ' + _fmt(v['mmag_median']):<14}  "
                f"{_fmt(v['model_mmag_max'])} / {_fmt(v['model_mmag_median'])}"
            )
    return "\n".join(lines)
