"""Figure: a measured light curve of a pass against its simulation, fitted.

The observation of the built-in ``canx1-pass`` is simulated every 0.1 s; an observer's wide
ECSV table (UTC times, V, R and I with their uncertainties, one band per second in turn) is
made from it with a zero point per band, extinction ``k X`` and a clock 0.6 s late injected
(the truth taken on the simulated nodes), and 0.02 mag of noise; it is read back with
``read_light_curve``, fitted with ``compare`` (zero points, extinction coefficients and the
time shift) and drawn with ``plot_comparison``.

Run ``python docs/comparison.py``; writes ``docs/img/canx1_pass_comparison.png`` and prints
the fitted values.
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import numpy as np
from astropy.table import Table
from astropy.time import Time

from sbrdf_xr.engine import builtin_scene
from sbrdf_xr.engine.run import simulate
from sbrdf_xr.lightcurves import compare, plot_comparison, read_light_curve
from sbrdf_xr.observing.observe import Observation, times
from sbrdf_xr.photometry import magnitudes

OUT = Path(__file__).parent / "img" / "canx1_pass_comparison.png"
ZP = {"V": 0.30, "R": 0.15, "I": -0.05}
K = {"V": 0.20, "R": 0.12, "I": 0.07}
LATE_S = 0.6  # the observer's clock: a measurement stamped t saw the pass at t + 0.6 s


def measured_table(sim, path: Path, seed: int = 0) -> None:
    """A wide table: one row per second, the band of that second filled in."""
    rng = np.random.default_rng(seed)
    t = sim.time.values
    secs = (t - t[0]) / np.timedelta64(1, "s")
    rows = np.flatnonzero((np.round(secs * 10) % 10 == 0) & (secs >= 70) & (secs <= 290))
    rows = rows[np.isfinite(sim.values[rows + round(LATE_S * 10)]).all(axis=1)]  # lit, seen
    seen = rows + round(LATE_S * 10)  # the node 0.6 s later
    cols = {"time": Time(t[rows], scale="utc")}
    for j, b in enumerate(("V", "R", "I")):
        mag = sim.values[seen, j] + ZP[b] + K[b] * sim.airmass.values[seen]
        mag = mag + rng.normal(0.0, 0.02, rows.size)
        mine = (np.arange(rows.size) % 3) == j  # V, R, I in turn
        cols[b] = np.where(mine, mag, np.nan)
        cols[f"{b}_err"] = np.where(mine, 0.02, np.nan)
    tab = Table(cols)
    tab.meta["magnitude_system"] = "AB"
    tab.write(path, overwrite=True)


def fitted() -> Any:
    """The comparison of the measured table with the simulated pass (``compare``'s result)."""
    scene = builtin_scene("canx1-pass")
    o = scene.observation
    fine = Observation(o.orbit, o.site, times(o.times[0], o.times[-1], 0.1), o.attitude)
    cube = simulate(scene.with_options(observation=fine))
    sim = magnitudes(cube, ["V", "R", "I"])
    path = Path(tempfile.mkdtemp()) / "canx1-pass-measured.ecsv"
    measured_table(sim, path)
    measured = read_light_curve(path)
    return compare(measured, sim, extinction="fit", fit_time_shift=True, max_time_shift=5.0)


def figures(fit: Any = None) -> dict[str, Any]:
    """The figure by file name."""
    fit = fitted() if fit is None else fit
    title = "canx1-pass: a measured V, R, I table against the simulation"
    return {OUT.name: plot_comparison(fit, title=title)}


def main() -> None:
    fit = fitted()
    for p, e, s in zip(
        fit.parameter.values, fit.estimate.values, fit.standard_error.values, strict=True
    ):
        truth = {
            **{f"ZP_{b}": v for b, v in ZP.items()},
            **{f"k_{b}": v for b, v in K.items()},
            "time_shift": LATE_S,
        }[str(p)]
        print(f"{p:10s} {e:+.4f} +- {s:.4f} (injected {truth:+.3f})")
    print(f"reduced chi2 {float(fit.reduced_chi_square):.3f} ({int(fit.degrees_of_freedom)} dof)")
    for name, fig in figures(fit).items():
        fig.savefig(OUT.parent / name, dpi=110)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
