"""Benchmarks users can run: what accuracy costs in time.

Every timing is reported as a ratio to a baseline measured in the same run, because
absolute seconds on a shared machine mean little.  Run ``sbrdf-xr bench`` (or
``python -m sbrdf_xr.bench``).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import xarray as xr

from . import material
from .goniometer import measure
from .testing import lobe_function

__all__ = ["BenchRow", "bench_build_lut", "bench_lookup", "best_time", "format_rows", "run"]


@dataclass
class BenchRow:
    """One benchmark result.

    Attributes
    ----------
    name : str
        What was measured.
    seconds : float
        Best wall time over the repeats [s].
    baseline : str
        Name of the baseline row of the ratio.
    ratio : float
        ``baseline seconds / seconds``: > 1 is faster than the baseline.
    extra : str
        Throughput or error, in words.
    """

    name: str
    seconds: float
    baseline: str
    ratio: float
    extra: str = ""


def best_time(func: Callable[[], object], repeat: int = 5, number: int = 1) -> float:
    """Best of ``repeat`` wall times of ``number`` calls of ``func`` [s per call]."""
    func()  # warm-up
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(number):
            func()
        best = min(best, (time.perf_counter() - t0) / number)
    return float(best)


def _example_measurements(n_wavelength: int = 131) -> xr.Dataset:
    wl = np.linspace(450.0, 1100.0, n_wavelength)
    return measure(lobe_function(wl, width=3.0), wl, noise_floor=0.05)


def bench_build_lut(n_wavelength: int = 131, repeat: int = 3) -> list[BenchRow]:
    """Time :func:`sbrdf_xr.material.build_lut` on a paper-sized measurement set.

    The set has 5 incidence angles x 30 geometries (105 measured spectra and 45
    reference points) at ``n_wavelength`` wavelengths; the table is the paper's
    91 x 21 x 21 x n_wavelength.  It is its own baseline: the row states the time.
    """
    ds = _example_measurements(n_wavelength)
    t_build = best_time(lambda: material.build_lut(ds), repeat)
    n_meas = int((~ds.reference).sum())
    return [
        BenchRow(
            f"build_lut ({ds.sizes['sample']} samples, {n_meas} measured, {n_wavelength} wl)",
            t_build, "itself", 1.0, "91 x 21 x 21 table",
        ),
    ]


def bench_lookup(n_geometries: int = 20000, n_wavelength: int = 131, repeat: int = 3) -> list[BenchRow]:
    """Spectra per second of the ``linear`` look-up against ``xarray.DataArray.interp``.

    Both interpolate multilinearly the same paper-sized table at the same random
    geometries (inside the table); their results agree to 1e-12 relative.
    """
    lut = material.build_lut(_example_measurements(n_wavelength))
    rng = np.random.default_rng(0)
    ti = rng.uniform(0, 90, n_geometries)
    dt = rng.uniform(float(lut.delta_theta[0]), float(lut.delta_theta[-1]), n_geometries)
    ph = rng.uniform(0, float(lut.phi[-1]), n_geometries)
    dims = [xr.DataArray(a, dims="geom") for a in (ti, dt, ph)]

    def ours() -> np.ndarray:
        return material._lut.lookup_kernel(np.asarray(lut.values), lut.theta_i.values,
                                           lut.delta_theta.values, lut.phi.values, ti, dt, ph)

    def xr_interp() -> xr.DataArray:
        return lut.interp(theta_i=dims[0], delta_theta=dims[1], phi=dims[2], method="linear").load()

    a = ours()
    b = xr_interp().transpose("geom", "wavelength").values
    err = float(np.max(np.abs(a - b) / np.maximum(np.abs(b), 1e-300)))
    rows = []
    rows_t = {name: best_time(f, repeat) for name, f in
              (("sbrdf_xr linear kernel", ours), ("xarray .interp (linear)", xr_interp))}
    base = rows_t["xarray .interp (linear)"]
    for name, t in rows_t.items():
        rows.append(BenchRow(name, t, "xarray .interp (linear)", base / t,
                             f"{n_geometries / t:,.0f} spectra/s; max rel diff {err:.1e}"))
    return rows


def format_rows(rows: list[BenchRow]) -> str:
    """A plain-text table of benchmark rows."""
    w = max(len(r.name) for r in rows)
    wb = max(len(r.baseline) for r in rows)
    lines = [f"{'case':<{w}}  {'time [ms]':>10}  {'speed-up':>9}  {'baseline':<{wb}}  notes"]
    for r in rows:
        lines.append(f"{r.name:<{w}}  {r.seconds * 1e3:>10.2f}  {r.ratio:>8.2f}x  "
                     f"{r.baseline:<{wb}}  {r.extra}")
    return "\n".join(lines)


def run(quick: bool = False) -> list[BenchRow]:
    """Run the benchmarks and return their rows (``quick``: smaller problems)."""
    n = 2000 if quick else 20000
    rows = bench_build_lut(repeat=2 if quick else 3)
    rows += bench_lookup(n_geometries=n, repeat=2 if quick else 3)
    return rows


if __name__ == "__main__":  # pragma: no cover
    print(format_rows(run()))
