"""What accuracy costs in time: the benchmark's rows as one readable figure."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from ..errors import ValidationError
from ..units import to_unit

__all__ = ["accuracy_front", "is_preset"]

_FIELDS = {
    "case": "name",
    "time_ratio": "ratio",
    "mmag_max": "mmag_max",
    "mmag_median": "mmag_median",
    "sweep": "sweep",
    "baseline": "baseline",
}


def is_preset(case: str) -> bool:
    """True for a benchmark case that is one of the presets (``reference...``, ``preset...``).

    Examples
    --------
    >>> [is_preset(c) for c in ("reference: cubic look-up", "preset: fast", "lookup: linear")]
    [True, True, False]
    """
    c = case.strip().lower()
    return c.startswith(("reference", "preset"))


def _as_dataset(rows: Any) -> xr.Dataset:
    if isinstance(rows, xr.Dataset):
        missing = [k for k in ("time_ratio", "mmag_max", "sweep") if k not in rows]
        if missing or "case" not in rows.coords:
            raise ValidationError(f"rows: a benchmark Dataset needs 'case' and {missing}")
        return rows
    try:
        cols = {k: [getattr(r, a) for r in rows] for k, a in _FIELDS.items()}
    except AttributeError as exc:
        raise ValidationError(f"rows: expected benchmark rows or their Dataset ({exc})") from None
    case = cols.pop("case")
    return xr.Dataset({k: ("case", v) for k, v in cols.items()}, coords={"case": case})


def accuracy_front(rows: Any, *, zero_below: float = 1e-6) -> Any:
    """The benchmark's cases against their error and their cost, one row per case.

    Left: the worst (filled) and median (open) band error [mmag] of every case against
    its sweep's baseline (the reference; exact shadowing for the shadowing rows), one
    colour per sweep, on a log axis.  An error of 0, or below ``zero_below`` (float64
    rounding), is drawn as a bar at the axis's left edge, and the legend says so.  Right:
    the wall time as a ratio to the baseline's (a time too short to measure, 0, also at
    the left edge).  The presets' rows (:func:`is_preset`) are shaded, their names bold.

    Parameters
    ----------
    rows : xarray.Dataset or list of BenchRow
        :func:`sbrdf_xr.bench.rows_to_dataset` output, or the rows themselves.  Cases
        without an error (NaN) are left out.
    zero_below : float
        Errors below this [mmag] count as zero.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> rows = xr.Dataset(
    ...     {"time_ratio": ("case", [1.0, 0.35, 0.6]), "mmag_max": ("case", [0.0, 63.0, 0.002]),
    ...      "mmag_median": ("case", [0.0, 0.55, 0.0003]),
    ...      "sweep": ("case", ["demo"] * 3), "baseline": ("case", ["reference"] * 3)},
    ...     coords={"case": ["reference", "lookup: linear", "precision: float32"]})
    >>> fig = accuracy_front(rows)
    >>> [t.get_text() for t in fig.axes[0].get_yticklabels()]
    ['reference', 'lookup: linear', 'precision: float32']
    >>> fig.axes[0].get_xlabel(), fig.axes[1].get_xlabel()
    ('band error against the baseline [mmag]', 'wall time / baseline wall time')
    >>> plt.close(fig)
    """
    zero_below = to_unit(zero_below, "mmag", "zero_below")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    ds = _as_dataset(rows)
    worst = np.asarray(ds["mmag_max"].values, dtype=np.float64)
    ds = ds.isel(case=np.flatnonzero(np.isfinite(worst)))
    if ds.sizes["case"] == 0:
        raise ValidationError("rows: no case has a band error to draw")
    cases = list(dict.fromkeys(str(c) for c in ds["case"].values))
    sweeps = list(dict.fromkeys(str(s) for s in ds["sweep"].values))
    errs = np.concatenate([ds["mmag_max"].values, ds.get("mmag_median", ds["mmag_max"]).values])
    shown = errs[np.isfinite(errs) & (errs >= zero_below)]
    floor = float(shown.min()) / 3.0 if shown.size else zero_below
    times = np.asarray(ds["time_ratio"].values, dtype=np.float64)
    timed = times[np.isfinite(times) & (times > 0)]
    t_floor = float(timed.min()) / 2.0 if timed.size else 0.1
    fig, (ax, cost) = plt.subplots(1, 2, figsize=(10, 1.4 + 0.24 * len(cases)), sharey=True,
                                   layout="constrained", width_ratios=(3, 2))  # fmt: skip
    y_of = {c: i for i, c in enumerate(cases)}
    step = 0.5 / max(len(sweeps), 1)
    edge: dict[str, Any] = {"marker": "|", "ms": 9, "mew": 2, "ls": "none"}
    for k, sweep in enumerate(sweeps):
        sub = ds.isel(case=np.flatnonzero(ds["sweep"].values == sweep))
        shift = (k - (len(sweeps) - 1) / 2) * step  # the sweeps side by side in each row
        y = np.array([y_of[str(c)] for c in sub["case"].values]) + shift
        colour = f"C{k % 10}"
        for var, fill in (("mmag_max", colour), ("mmag_median", "none")):
            if var in sub:
                v = np.asarray(sub[var].values, dtype=np.float64)
                big, zero = v >= zero_below, (v >= 0) & (v < zero_below)
                ax.plot(v[big], y[big], "o", ms=5, mfc=fill, mec=colour, ls="none")
                ax.plot(np.full(zero.sum(), floor), y[zero], color=colour, **edge)
        t = np.asarray(sub["time_ratio"].values, dtype=np.float64)
        cost.plot(t[t > 0], y[t > 0], "o", ms=5, color=colour, ls="none")
        cost.plot(np.full((t == 0).sum(), t_floor), y[t == 0], color=colour, **edge)
    for c, i in y_of.items():
        if is_preset(c):
            for a in (ax, cost):
                a.axhspan(i - 0.45, i + 0.45, color="gold", alpha=0.6, lw=0, zorder=0)
    ax.set_xscale("log")
    ax.set_xlim(left=floor / 1.5)
    ax.set_yticks(range(len(cases)), cases, fontsize="small")
    for tick in ax.get_yticklabels():
        if is_preset(tick.get_text()):
            tick.set_fontweight("bold")
    ax.set_ylim(len(cases) - 0.5, -0.5)
    ax.set_xlabel("band error against the baseline [mmag]")
    cost.set_xscale("log")
    cost.set_xlim(left=t_floor / 1.3)
    cost.axvline(1.0, color="0.5", lw=0.8)
    cost.set_xlabel("wall time / baseline wall time")
    for a in (ax, cost):
        a.grid(axis="x", which="major", color="0.9", lw=0.6)
    baselines = ds["baseline"].values if "baseline" in ds else ["reference"] * ds.sizes["case"]
    base = {str(s): str(b) for s, b in zip(ds["sweep"].values, baselines, strict=True)}
    handles: list[Any] = [
        Line2D([], [], marker="o", ls="none", color=f"C{k % 10}", label=f"{s}: against {base[s]}")
        for k, s in enumerate(sweeps)
    ]
    handles += [
        Line2D([], [], marker="o", ls="none", color="k", label="worst band error"),
        Line2D([], [], marker="o", ls="none", mfc="none", mec="k", label="median band error"),
        Line2D([], [], color="k", **edge, label=f"0 (or error < {zero_below:g} mmag), at the edge"),
        Patch(color="gold", alpha=0.6, label="a preset"),
    ]
    fig.legend(handles=handles, loc="outside lower center", ncols=3, fontsize="small")
    return fig
