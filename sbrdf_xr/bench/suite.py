"""What accuracy costs in time: benchmarks users can run (``sbrdf-xr bench``).

Every approximation of a simulation is a named knob.  :func:`accuracy_cost`
changes one knob at a time away from the ``reference`` configuration and reports,
for the CanX-1 rotation and a larger sweep of random attitudes,

* the error against the reference in units users feel: the worst and median
  magnitude difference in V, R and I [mmag] where the reference signal is above
  1e-3 of its maximum, and the 99th-percentile relative spectral error;
* the wall time as a ratio to the reference's, measured in the same run (best of
  a few repeats), because absolute seconds on a shared machine mean little.

The knobs: look-up method, table resolution (theta_i step, delta_theta and phi
points), wavelength sampling versus band pre-integration, facet merging,
shadow-sampling density, tabulated versus analytic material evaluation (the
generating models of the synthetic catalog materials), float32 versus float64.

:func:`kernel_throughput` compares the simulation kernel with a straightforward
per-facet numpy evaluation and estimates the machine's limit for it.
"""

from __future__ import annotations

import time

import numpy as np
import xarray as xr

from ..errors import renamed_keywords
from ..kernels import lut as _lut
from ..materials import tables as material
from ..materials.goniometer import measure
from ..observing.observe import CANX1_PASS, Observation, Orbit, Site, canx1_attitude
from ..observing.timescales import to_datetime64
from ..testing import lobe_function
from .accuracy import CANX1_MATERIALS, accuracy_cost
from .rows import BenchRow, best_time, format_rows, rows_to_dataset, timed_runs

__all__ = [
    "BenchRow",
    "accuracy_cost",
    "bench_build_lut",
    "bench_lookup",
    "best_time",
    "format_rows",
    "kernel_throughput",
    "rows_to_dataset",
    "run",
]

# ------------------------------------------------------------- tables


def _example_measurements(n_wavelength: int = 131) -> xr.Dataset:
    wl = np.linspace(450.0, 1100.0, n_wavelength)
    return measure(lobe_function(wl, width=3.0), wl, noise_floor=0.05)


def bench_build_lut(n_wavelength: int = 131, repeat: int = 3) -> list[BenchRow]:
    """Time :func:`sbrdf_xr.materials.tables.build_lut` on a paper-sized measurement set.

    5 incidence angles x 30 geometries (105 measured spectra, 45 reference points)
    at ``n_wavelength`` wavelengths into the paper's 91 x 21 x 21 x n_wavelength
    table.  It is its own baseline: the row states the time.

    Examples
    --------
    Even at one wavelength the two builds (warm-up and timing) of the 91 x 21 x 21 table
    take about a second, so the call is not run here:

    >>> import inspect
    >>> from sbrdf_xr.bench import bench_build_lut
    >>> list(inspect.signature(bench_build_lut).parameters)
    ['n_wavelength', 'repeat']
    >>> rows = bench_build_lut(n_wavelength=3, repeat=1)  # doctest: +SKIP
    >>> rows[0].name, rows[0].baseline  # doctest: +SKIP
    ('build_lut (150 samples, 105 measured, 3 wl)', 'itself')
    """
    ds = _example_measurements(n_wavelength)
    t_build = best_time(lambda: material.build_lut(ds), repeat)
    n_meas = int((~ds.reference).sum())
    return [
        BenchRow(
            f"build_lut ({ds.sizes['sample']} samples, {n_meas} measured, {n_wavelength} wl)",
            t_build,
            "itself",
            1.0,
            f"{t_build * 1e3:.0f} ms for the 91 x 21 x 21 x {n_wavelength} table",
            sweep="tables",
        )
    ]


def bench_lookup(
    n_geometries: int = 20000, n_wavelength: int = 131, repeat: int = 3
) -> list[BenchRow]:
    """Spectra per second of the ``linear`` look-up against ``xarray.DataArray.interp``.

    Both interpolate multilinearly the same paper-sized table at the same random
    geometries (inside the table); the row notes their largest relative difference.

    Examples
    --------
    The call builds a paper-sized table first (about a second), so it is not run here:

    >>> import inspect
    >>> from sbrdf_xr.bench import bench_lookup
    >>> list(inspect.signature(bench_lookup).parameters)
    ['n_geometries', 'n_wavelength', 'repeat']
    >>> rows = bench_lookup(n_geometries=10, n_wavelength=3, repeat=1)  # doctest: +SKIP
    >>> [r.name for r in rows]  # doctest: +SKIP
    ['sbrdf_xr linear look-up kernel', 'xarray .interp (linear)']
    """
    lut = material.build_lut(_example_measurements(n_wavelength))
    rng = np.random.default_rng(0)
    ti = rng.uniform(0, 90, n_geometries)
    dt = rng.uniform(float(lut.delta_theta[0]), float(lut.delta_theta[-1]), n_geometries)
    ph = rng.uniform(0, float(lut.phi[-1]), n_geometries)
    dims = [xr.DataArray(a, dims="geom") for a in (ti, dt, ph)]
    tg, dg, pg = (np.asarray(lut[d].values) for d in ("theta_i", "delta_theta", "phi"))
    values = np.asarray(lut.values)

    def ours() -> np.ndarray:
        return _lut.lookup_kernel(values, tg, dg, pg, ti, dt, ph)

    def xr_interp() -> xr.DataArray:
        return lut.interp(theta_i=dims[0], delta_theta=dims[1], phi=dims[2], method="linear").load()

    a = ours()
    b = xr_interp().transpose("geom", "wavelength").values
    err = float(np.max(np.abs(a - b) / np.maximum(np.abs(b), 1e-300)))
    t_ours, t_xr = best_time(ours, repeat), best_time(xr_interp, repeat)
    return [
        BenchRow(
            "sbrdf_xr linear look-up kernel",
            t_ours,
            "xarray .interp (linear)",
            t_ours / t_xr,
            f"{n_geometries / t_ours:,.0f} spectra/s; max rel diff {err:.1e}",
            sweep="tables",
        ),
        BenchRow(
            "xarray .interp (linear)",
            t_xr,
            "xarray .interp (linear)",
            1.0,
            f"{n_geometries / t_xr:,.0f} spectra/s",
            sweep="tables",
        ),
    ]


# ------------------------------------------------------ kernel speed


def kernel_throughput(repeat: int = 3, attitude_step: int = 1) -> list[BenchRow]:
    """Geometry-facet-spectra per second of the simulation against a per-facet loop.

    The baseline is the straightforward numpy evaluation: for every facet, its angles
    for all geometries (:func:`sbrdf_xr.geometry.facet_angles`), its spectra by the
    public ``linear`` look-up (:func:`sbrdf_xr.materials.tables.lookup`) and the weighted sum.
    Both evaluate the CanX-1 rotation (360 geometries x 684 facets x 141 wavelengths;
    every ``attitude_step``-th attitude).  Times are the best of ``repeat`` interleaved
    runs (:func:`sbrdf_xr.bench.rows.timed_runs`).
    The machine limit is estimated from the bytes each geometry-facet must gather
    (8 table rows of the spectrum) and a measured memory bandwidth (a large
    ``numpy`` copy).

    Examples
    --------
    The comparison runs on the CanX-1 rotation with its measured tables (seconds to
    build) and a per-facet loop of many seconds; it is not run here:

    >>> import inspect
    >>> from sbrdf_xr.bench import kernel_throughput
    >>> list(inspect.signature(kernel_throughput).parameters)
    ['repeat', 'attitude_step']
    >>> rows = kernel_throughput(repeat=1)  # doctest: +SKIP
    >>> rows[0].name  # doctest: +SKIP
    'per-facet numpy loop (baseline)'
    """
    from .. import geometry
    from ..engine import builtin_scene
    from ..engine.run import simulate

    rot = builtin_scene("canx1-rotation")
    scene = rot.with_options(
        outputs=("signal", "area"),
        method="linear",
        attitudes=np.asarray(rot.attitudes)[::attitude_step],
        attitude_angle=np.asarray(rot.attitude_angle)[::attitude_step],
    )
    facets = scene.spacecraft.facets()
    s, o = scene.body_vectors()
    s2, o2 = s.reshape(-1, 3), o.reshape(-1, 3)
    tables = {m: scene.tables[m] for m in scene.spacecraft.materials}
    n_geom, n_fac = s2.shape[0], facets.sizes["facet"]
    n_wl = tables[next(iter(CANX1_MATERIALS))].sizes["wavelength"]

    def per_facet_loop() -> np.ndarray:
        out = np.zeros((n_geom, n_wl))
        for j in range(n_fac):
            n = facets.normal.values[j]
            ang = geometry.facet_angles(n, s2, o2)
            ok = ang.lit & ang.visible
            if not ok.any():
                continue
            spec = material.lookup(
                tables[str(facets.material.values[j])],
                ang.theta_i[ok],
                ang.delta_theta[ok],
                ang.phi[ok],
            ).values
            w = facets.area.values[j] * (s2[ok] @ n) * (o2[ok] @ n)
            out[ok] += w[:, None] * spec
        return out

    def sim(merge: bool) -> np.ndarray:
        return simulate(scene.with_options(merge=merge)).signal.compute(scheduler="sync").values

    out: dict[str, np.ndarray] = {}
    timing = timed_runs(
        {
            "loop": lambda: out.__setitem__("loop", per_facet_loop()),
            "merged": lambda: out.__setitem__("merged", sim(True)),
            "unmerged": lambda: out.__setitem__("unmerged", sim(False)),
        },
        repeat,
    )
    base, fast, unmerged = out["loop"], out["merged"], out["unmerged"]
    agree = float(np.max(np.abs(fast.reshape(base.shape) - base)) / np.abs(base).max())
    agree2 = float(np.max(np.abs(unmerged.reshape(base.shape) - base)) / np.abs(base).max())
    (t_base, s_base), (t_merged, s_merged) = timing["loop"], timing["merged"]
    t_unmerged, s_unmerged = timing["unmerged"]
    work = n_geom * n_fac  # geometry-facet pairs, each a full spectrum
    big = np.ones(2**25)  # 256 MiB
    t_copy = best_time(lambda: big.copy(), 2)
    bandwidth = 2 * big.nbytes / t_copy  # read + write
    limit = bandwidth / (
        8 * n_wl * 8
    )  # 8 gathered rows of n_wl float64 per geometry-facet, no cache reuse
    a = np.random.default_rng(0).random((1024, 1024))
    t_mm = best_time(lambda: a @ a, 2)
    flops = 2 * 1024**3 / t_mm  # dense matmul rate of this machine (BLAS, all cores)
    compute_limit = flops / (2 * 8 * n_wl)  # 8 multiply-adds per wavelength per pair
    rows = [
        BenchRow(
            "per-facet numpy loop (baseline)",
            t_base,
            "per-facet loop",
            1.0,
            f"{work / t_base:,.0f} geometry-facet-spectra/s",
            sweep="canx1-rotation",
            spread=s_base,
        ),
        BenchRow(
            "simulate, facets not merged",
            t_unmerged,
            "per-facet loop",
            t_unmerged / t_base,
            f"{work / t_unmerged:,.0f} g-f-spectra/s; speed-up {t_base / t_unmerged:.1f}x; "
            f"agrees to {agree2:.1e}",
            sweep="canx1-rotation",
            spread=s_unmerged,
        ),
        BenchRow(
            "simulate, merged (684 facets -> 20 terms)",
            t_merged,
            "per-facet loop",
            t_merged / t_base,
            f"{work / t_merged:,.0f} facet-equivalent g-f-spectra/s; "
            f"speed-up {t_base / t_merged:.1f}x; "
            f"agrees to {agree:.1e}",
            sweep="canx1-rotation",
            spread=s_merged,
        ),
        BenchRow(
            "DRAM-bandwidth estimate (no cache reuse)",
            work / limit,
            "per-facet loop",
            (work / limit) / t_base,
            f"{limit:,.0f} g-f-spectra/s at {bandwidth / 1e9:.1f} GB/s (measured copy), 8 x {n_wl} "
            "float64 gathered per pair; the unmerged kernel reaches "
            f"{(work / t_unmerged) / limit:.0%} "
            "of it (neighbouring geometries reuse table rows from cache)",
            sweep="canx1-rotation",
        ),
        BenchRow(
            "arithmetic estimate (dense-matmul rate)",
            work / compute_limit,
            "per-facet loop",
            (work / compute_limit) / t_base,
            f"{compute_limit:,.0f} g-f-spectra/s at {flops / 1e9:.1f} GFLOP/s, "
            f"16 x {n_wl} flops per "
            f"pair; the unmerged kernel reaches {(work / t_unmerged) / compute_limit:.0%} of it",
            sweep="canx1-rotation",
        ),
    ]
    return rows


@renamed_keywords(step_s="step")
def bench_geometry(n_times: int = 3600, step: float = 1.0, repeats: int = 3) -> dict[str, float]:
    """Time :meth:`~sbrdf_xr.observing.Observation.geometry` of the built-in CanX-1 orbit and
    site (:data:`~sbrdf_xr.observing.observe.CANX1_PASS`) over ``n_times`` steps.

    The first call in a process also pays the one-off imports and the loading of the
    skyfield data; it is reported apart from the best of ``repeats`` further calls on
    fresh observations (nothing cached between them).

    Parameters
    ----------
    n_times : int
        Number of times.
    step : float
        Time step [s].
    repeats : int
        Warm calls timed.

    Returns
    -------
    dict
        ``n_times``, ``first_call_seconds``, ``seconds`` (best warm call) and
        ``seconds_per_time``.

    Examples
    --------
    >>> row = bench_geometry(n_times=60, repeats=1)
    >>> sorted(row), row["n_times"]
    (['first_call_seconds', 'n_times', 'seconds', 'seconds_per_time'], 60.0)
    """
    p = CANX1_PASS
    t0 = to_datetime64(p["start"], "start") - np.timedelta64(int(n_times * step / 2), "s")
    t = t0 + np.timedelta64(round(step * 1e9), "ns") * np.arange(n_times)
    start = time.perf_counter()
    orbit, site = Orbit.from_catalog(p["orbit"]), Site.from_catalog(p["site"])
    Observation(orbit, site, t, canx1_attitude()).geometry(on_unobservable="keep")
    first = time.perf_counter() - start
    best = np.inf
    for _ in range(max(1, repeats)):
        obs = Observation(orbit, site, t, canx1_attitude())
        start = time.perf_counter()
        obs.geometry(on_unobservable="keep")
        best = min(best, time.perf_counter() - start)
    return {
        "n_times": float(n_times),
        "first_call_seconds": first,
        "seconds": best,
        "seconds_per_time": best / n_times,
    }


def run(quick: bool = False, repeat: int | None = None) -> list[BenchRow]:
    """All benchmarks (``quick``: smaller problems, a smoke run).

    ``repeat``: timing runs of every row of the accuracy/cost table (default 5, 3 with
    ``quick``; :func:`accuracy_cost`) and of the kernel throughput (default 3, 2 with
    ``quick``).

    Examples
    --------
    About a minute with ``quick`` (``sbrdf-xr bench --quick`` runs it); not run here:

    >>> from sbrdf_xr.bench import format_rows, run
    >>> rows = run(quick=True)  # doctest: +SKIP
    >>> rows[0].name  # doctest: +SKIP
    'build_lut (150 samples, 105 measured, 131 wl)'
    >>> print(format_rows(rows))  # doctest: +SKIP
    """
    rows = bench_build_lut(repeat=3)
    rows += bench_lookup(n_geometries=2000 if quick else 20000, repeat=3)
    rows += accuracy_cost(quick=quick, repeat=repeat or (3 if quick else 5))
    rows += kernel_throughput(repeat=repeat or (2 if quick else 3), attitude_step=4 if quick else 1)
    return rows


if __name__ == "__main__":  # pragma: no cover
    print(format_rows(run()))
