"""The figure of a light-curve comparison: magnitudes and residuals, the fitted values.

:func:`plot_comparison` draws the result of :func:`sbrdf_xr.lightcurves.compare`: against
UTC for a pass (against the rotation angle for a sweep), the measured magnitudes with
their error bars and the fitted model per band above, the residuals below, and a box
with the magnitude system and the fitted values with their uncertainties.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from .._names import BAND
from ..errors import LightCurveError

__all__ = ["fitted_values_text", "plot_comparison"]


def fitted_values_text(comparison: xr.Dataset) -> str:
    """The fitted values of a comparison in a few lines (the figure's box).

    Examples
    --------
    >>> ds = xr.Dataset({"zero_point": ("band", [0.25]), "zero_point_uncertainty": ("band", [0.01]),
    ...                  "reduced_chi_square": 1.02, "degrees_of_freedom": 40},
    ...                 coords={"band": ["V"]}, attrs={"magnitude_system": "AB"})
    >>> print(fitted_values_text(ds))
    AB magnitudes
    ZP V = +0.250 +- 0.010
    reduced chi2 1.02 (40 dof)
    """
    lines = [f"{comparison.attrs.get('magnitude_system', 'unstated')} magnitudes"]
    common = "magnitude_offset" in comparison
    for i, b in enumerate(comparison[BAND].values):
        if common and i > 0:
            break
        zp, sz = float(comparison.zero_point[i]), float(comparison.zero_point_uncertainty[i])
        line = f"ZP {'(common)' if common else b} = {zp:+.3f} +- {sz:.3f}"
        if "extinction_coefficient" in comparison:
            k = float(comparison.extinction_coefficient[i])
            sk = float(comparison.extinction_coefficient_uncertainty[i])
            line += f", k = {k:.3f} +- {sk:.3f}" if sk > 0 else f", k = {k:.3f} (given)"
        lines.append(line)
    if common and "extinction_coefficient" in comparison:
        for i, b in enumerate(comparison[BAND].values):
            k = float(comparison.extinction_coefficient[i])
            sk = float(comparison.extinction_coefficient_uncertainty[i])
            lines.append(f"k {b} = {k:.3f} +- {sk:.3f}" if sk > 0 else f"k {b} = {k:.3f}")
    if float(comparison.get("time_shift_uncertainty", 0.0)) > 0:
        lines.append(
            f"time shift = {float(comparison.time_shift):+.3f} +- "
            f"{float(comparison.time_shift_uncertainty):.3f} s"
        )
    if float(comparison.get("phase_offset_uncertainty", 0.0)) > 0:
        lines.append(
            f"phase = {float(comparison.phase_offset):.2f} +- "
            f"{float(comparison.phase_offset_uncertainty):.2f} deg"
        )
    lines.append(
        f"reduced chi2 {float(comparison.reduced_chi_square):.2f} "
        f"({int(comparison.degrees_of_freedom)} dof)"
    )
    return "\n".join(lines)


def plot_comparison(comparison: xr.Dataset, *, title: str | None = None) -> Any:
    """Figure of a :func:`~sbrdf_xr.lightcurves.compare` result.

    Top: the measured magnitudes (error bars; hollow where excluded) and the fitted
    model per band, against UTC for a pass, against the simulated rotation angle for a
    sweep; bottom: the residuals.  A box states the magnitude system and the fitted
    values (:func:`fitted_values_text`).

    Parameters
    ----------
    comparison : xarray.Dataset
        From :func:`~sbrdf_xr.lightcurves.compare`.
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from sbrdf_xr.lightcurves import compare
    >>> ang = np.arange(0.0, 360.0, 10.0)
    >>> sim = xr.DataArray(np.stack([10 + np.cos(np.radians(2 * ang))], 1),
    ...                    dims=("attitude", "band"),
    ...                    coords={"attitude_angle": ("attitude", ang), "band": ["V"]})
    >>> lc = xr.Dataset({"magnitude": ("obs", 10.2 + np.cos(np.radians(2 * (ang + 20)))),
    ...                  "uncertainty": ("obs", np.full(ang.size, 0.01))},
    ...                 coords={"rotation_angle": ("obs", ang), "band": ("obs", ["V"] * ang.size)})
    >>> fig = plot_comparison(compare(lc, sim))
    >>> type(fig).__name__, len(fig.axes)
    ('Figure', 2)
    """
    from matplotlib.figure import Figure

    if not isinstance(comparison, xr.Dataset) or "residual" not in comparison:
        raise LightCurveError("comparison: expected the Dataset returned by compare")
    pass_ = comparison.attrs.get("mode") == "observation"
    fig = Figure(figsize=(9, 6.5), layout="constrained")
    ax, axr = fig.subplots(2, 1, sharex=True, height_ratios=(3, 1.2))
    x = comparison["time" if pass_ else "model_rotation_angle"].values
    obs_band = np.asarray([str(b) for b in comparison["obs_band"].values])
    excluded = np.asarray(comparison["excluded"].values, dtype=bool)
    curve_x = comparison["curve_time" if pass_ else "curve_angle"].values
    for i, b in enumerate(comparison[BAND].values):
        sel = obs_band == str(b)
        used, dropped = sel & ~excluded, sel & excluded
        line = ax.errorbar(
            x[used],
            comparison["measured_magnitude"].values[used],
            comparison["uncertainty"].values[used],
            fmt="o",
            ms=3,
            elinewidth=0.8,
            label=f"{b} measured",
        )
        colour = line[0].get_color()
        if dropped.any():
            ax.plot(
                x[dropped],
                comparison["measured_magnitude"].values[dropped],
                "o",
                ms=4,
                mfc="none",
                color=colour,
                label=f"{b} excluded (no light in the model)",
            )
        model = np.asarray(comparison["model_curve"].values[:, i], dtype=np.float64)
        ax.plot(
            curve_x,
            np.where(np.isfinite(model), model, np.nan),
            "-",
            lw=1.2,
            color=colour,
            label=f"{b} simulated + fit",
        )
        axr.errorbar(
            x[used],
            comparison["residual"].values[used],
            comparison["uncertainty"].values[used],
            fmt="o",
            ms=3,
            elinewidth=0.8,
            color=colour,
        )
    if pass_ and x.size:
        span = (x.max() - x.min()) if x.size > 1 else np.timedelta64(60, "s")
        ax.set_xlim(x.min() - span / 10, x.max() + span / 10)
    ax.invert_yaxis()
    system = comparison.attrs.get("magnitude_system", "unstated")
    ax.set_ylabel(f"magnitude ({system}) [mag]")
    ax.legend(fontsize="small", ncol=2, loc="upper left")
    ax.text(
        0.01,
        0.03,
        fitted_values_text(comparison),
        transform=ax.transAxes,
        ha="left",
        va="bottom",
        fontsize="small",
        family="monospace",
        bbox={"boxstyle": "round", "fc": "white", "ec": "0.6", "alpha": 0.9},
    )
    axr.axhline(0.0, color="k", lw=0.8)
    axr.set_ylabel("residual [mag]")
    if pass_:
        day = str(x.min())[:10] if x.size else ""
        axr.set_xlabel(f"time [UTC] on {day}")
        import matplotlib.dates as mdates

        axr.xaxis.set_major_formatter(mdates.DateFormatter("%H:%M:%S"))
    else:
        axr.set_xlabel("simulated rotation angle [degree]")
    ax.set_title(
        title
        or (
            f"measured vs simulated {'pass' if pass_ else 'rotation sweep'}: zero points "
            f"{comparison.attrs.get('zero_points', '')}, extinction "
            f"{comparison.attrs.get('extinction', 'none')}"
        )
    )
    return fig
