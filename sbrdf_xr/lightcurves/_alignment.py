"""Where each measured observation falls on a simulated light curve.

An :class:`Alignment` evaluates the simulated magnitudes at the measured observations
for a trial shift ``x``: a time shift [s] along a simulated pass (:func:`observation`:
the simulated flux interpolated linearly in time, no time outside the simulated window)
or a rotation-phase offset [degree] along a rotation sweep (:func:`sweep`: periodic in
360 degree, measured angles or times over a rotation period).  Used by
:func:`sbrdf_xr.lightcurves.comparison.compare`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import xarray as xr

from .._names import ATTITUDE, BAND
from ..errors import LightCurveError

TIME = "time"


@dataclass
class Alignment:
    """The simulated magnitudes at the observations as a function of a shift."""

    mode: str  # "observation" or "rotation sweep"
    x_name: str  # "time_shift" [s] or "phase_offset" [degree]
    flux: np.ndarray  # (n_sim, n_band) simulated flux relative to magnitude 0
    where: Callable[[float], np.ndarray]  # x -> positions of the observations on the grid
    grid: np.ndarray  # simulated abscissa: seconds from the first time, or angles [degree]
    period: float | None  # 360 for a sweep
    bounds: tuple[float, float]  # allowed x
    airmass: Callable[[float], np.ndarray] | None = None
    fixed: np.ndarray | None = None  # per-observation fixed terms [mag]
    notes: dict[str, str] = field(default_factory=dict)
    t0: Any = None  # datetime64 of grid 0 (observation)

    def magnitudes(self, x: float, col: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Simulated magnitudes at shift ``x`` (``+inf`` where the flux is 0), and where
        the model reflects light."""
        at = self.where(x)
        f = np.empty(at.size)
        for b in np.unique(col):
            sel = col == b
            if self.period is None:
                f[sel] = np.interp(at[sel], self.grid, self.flux[:, b])
            else:
                f[sel] = np.interp(
                    np.mod(at[sel], self.period), self.grid, self.flux[:, b], period=self.period
                )
        ok = f > 0
        m = np.full(at.size, np.inf)
        m[ok] = -2.5 * np.log10(f[ok])
        return m, ok

    def step(self) -> float:
        """The median spacing of the simulated abscissa."""
        return float(np.median(np.diff(np.sort(self.grid)))) if self.grid.size > 1 else 1.0


def _flux(sim: xr.DataArray, dim: str) -> np.ndarray:
    m = np.asarray(sim.transpose(dim, BAND).values, dtype=np.float64)
    with np.errstate(over="ignore", invalid="ignore"):
        return np.where(np.isfinite(m), 10.0 ** (-0.4 * np.where(np.isfinite(m), m, 0.0)), 0.0)


def _describe_times(t: np.ndarray) -> str:
    return f"{str(t.min())[:23]} .. {str(t.max())[:23]} UTC"


def observation(
    measured: xr.Dataset,
    sim: xr.DataArray,
    fit_shift: bool,
    max_shift_s: float,
) -> Alignment:
    """The alignment of measured UTC times with a simulated pass (dims ``time, band``)."""
    if "time" not in measured.coords or not np.issubdtype(measured["time"].dtype, np.datetime64):
        raise LightCurveError(
            "measured: a simulated pass is compared over UTC times, but the measured light "
            "curve has "
            + (
                "numbers of seconds without an origin"
                if "time" in measured.coords
                else "rotation angles"
            )
            + "; give UTC times (ISO 8601, astropy Time, or jd_utc / mjd_utc columns)"
        )
    ts = np.asarray(sim[TIME].values, dtype="datetime64[ns]")
    if ts.size < 2 or np.any(np.diff(ts) <= np.timedelta64(0, "ns")):
        raise LightCurveError(
            f"simulated: needs at least two strictly increasing times to interpolate, got {ts.size}"
        )
    t0 = ts[0]
    grid = (ts - t0) / np.timedelta64(1, "s")
    tm = (np.asarray(measured["time"].values, dtype="datetime64[ns]") - t0) / np.timedelta64(1, "s")
    window = f"simulated window {_describe_times(ts)}"
    outside = (tm < grid[0]) | (tm > grid[-1])
    if outside.all():
        raise LightCurveError(
            f"measured: no overlap: the measured times {_describe_times(measured.time.values)} "
            f"lie outside the {window}; simulate the night of the measurements "
            "(start/stop covering them)"
        )
    lo, hi = 0.0, 0.0
    if fit_shift:
        lo = max(-max_shift_s, grid[0] - tm.min())
        hi = min(max_shift_s, grid[-1] - tm.max())
        if hi <= lo:
            raise LightCurveError(
                f"fit_time_shift: the measured times {_describe_times(measured.time.values)} "
                f"leave no room for a shift of up to {max_shift_s:g} s inside the {window}; "
                f"simulate a window {max_shift_s:g} s longer at each end"
            )
    elif outside.any():
        k = np.flatnonzero(outside)
        first = (
            f"row {int(measured['file_row'].values[k[0]])}"
            if "file_row" in measured.coords
            else f"observation {int(k[0])}"
        )
        raise LightCurveError(
            f"measured: {k.size} observation(s) outside the {window}, first at "
            f"{str(measured.time.values[k[0]])[:23]} UTC ({first}); simulate a "
            "window covering every measured time, or select the measurements inside it"
        )
    al = Alignment(
        "observation",
        "time_shift",
        _flux(sim, TIME),
        lambda x: tm + x,
        grid,
        None,
        (lo, hi),
        t0=t0,
    )
    al.notes["window"] = window
    return al


def with_airmass(al: Alignment, measured: xr.Dataset, sim: xr.DataArray, source: str) -> None:
    """Attach the air mass of each observation: the measured column or the simulation's."""
    have = "airmass" in measured
    if source == "measured" or (source == "auto" and have):
        if not have:
            raise LightCurveError(
                "airmass='measured': the measured light curve has no airmass column"
            )
        x = np.asarray(measured["airmass"].values, dtype=np.float64)
        al.airmass = lambda shift: x
        al.notes["airmass_source"] = "the measured airmass column"
        return
    if al.mode != "observation" or "airmass" not in sim.coords:
        raise LightCurveError(
            "extinction: needs the air mass of each observation: an airmass column in the "
            "measured light curve"
            + ("" if al.mode == "observation" else " (a rotation sweep has none of its own)")
            + (" or the simulated pass's 'airmass' coordinate" if al.mode == "observation" else "")
        )
    xs = np.asarray(sim["airmass"].values, dtype=np.float64)
    grid, where = al.grid, al.where

    def airmass(shift: float) -> np.ndarray:
        return np.interp(where(shift), grid, xs)

    bad = ~np.isfinite(airmass(0.0))
    if bad.any():
        raise LightCurveError(
            f"extinction: {int(bad.sum())} observation(s) at times the simulated pass is "
            "below the horizon (airmass NaN); they cannot have been observed"
        )
    al.airmass = airmass
    al.notes["airmass_source"] = "the simulated pass's airmass, interpolated in time"


def sweep(
    measured: xr.Dataset,
    sim: xr.DataArray,
    period_s: float | None,
    epoch: Any,
) -> Alignment:
    """The alignment of measured angles (or times over a period) with a rotation sweep."""
    if "attitude_angle" not in sim.coords:
        raise LightCurveError(
            "simulated: a rotation sweep needs the 'attitude_angle' coordinate (degree)"
        )
    if "rotation_angle" in measured.coords:
        theta = np.asarray(measured["rotation_angle"].values, dtype=np.float64)
        how = "rotation_angle"
    elif "time" in measured.coords:
        if period_s is None or not np.isfinite(period_s) or period_s <= 0:
            raise LightCurveError(
                "period_s: the measured light curve is indexed by time; give the rotation "
                "period [s] (> 0) to convert it to rotation angle"
            )
        tv = measured["time"].values
        if np.issubdtype(tv.dtype, np.datetime64):
            t0 = tv.min() if epoch is None else np.datetime64(epoch, "ns")
            secs = (tv.astype("datetime64[ns]") - t0) / np.timedelta64(1, "s")
        else:
            secs = np.asarray(tv, dtype=np.float64)
        theta = 360.0 * np.asarray(secs, dtype=np.float64) / period_s
        how = f"time converted with period_s = {period_s}"
    else:
        raise LightCurveError("measured: needs a 'rotation_angle' or 'time' coordinate")
    ang = np.mod(np.asarray(sim["attitude_angle"].values, dtype=np.float64), 360.0)
    if np.unique(ang).size != ang.size:
        raise LightCurveError("simulated: attitude angles repeat modulo 360 degree")
    al = Alignment(
        "rotation sweep",
        "phase_offset",
        _flux(sim, ATTITUDE),
        lambda x: theta + x,
        ang,
        360.0,
        (-np.inf, np.inf),
    )
    al.notes["abscissa"] = how
    fixed = np.zeros(theta.size)
    if "range_km" in measured:
        if "range_km" not in sim.attrs:
            raise LightCurveError(
                "measured: has a range_km column but the simulated magnitudes have no "
                "range_km attribute (the range they were computed at); compute them at one "
                "range"
            )
        fixed += 5.0 * np.log10(
            np.asarray(measured["range_km"].values, dtype=np.float64) / float(sim.attrs["range_km"])
        )
        al.notes["range_term"] = "5 log10(range_km / the simulated range) per observation"
    al.fixed = fixed
    return al
