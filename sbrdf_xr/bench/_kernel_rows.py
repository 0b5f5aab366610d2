"""Kernel throughput rows of the engine benchmarks (:func:`kernel_rows`, shown by
:mod:`sbrdf_xr.bench.engine`) and the random-attitude sweep scene they share."""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from .rows import BenchRow, best_time, timed_runs

#: Random attitudes of the band-only kernel row (its full-spectrum twin has as many).
BAND_ROW_ATTITUDES = 100_000


def _sweep_scene(n: int, bands: bool = False) -> Any:
    from .. import geometry
    from ..engine import builtin_scene

    scene = builtin_scene("canx1-rotation").with_options(
        attitudes=geometry.uniform_attitudes(n, seed=11),
        attitude_angle=None,
        outputs=("spacecraft_sbrdf", "signal", "brdf", "area"),
        name=f"random-{n}",
    )
    if bands:
        scene = scene.with_options(outputs=("band_signal", "area"), bands=("V", "R", "I"))
    return scene


def _matmul_rate(threads: int = 1) -> float:
    """Dense float64 matmul rate [flop/s] of this machine on ``threads`` BLAS threads."""
    from threadpoolctl import threadpool_limits

    a = np.random.default_rng(0).random((1024, 1024))
    with threadpool_limits(threads):
        t = best_time(lambda: a @ a, 3)
    return 2 * 1024**3 / t


def kernel_rows(repeat: int = 3) -> list[BenchRow]:
    """Kernel throughput (linear, 141 wavelengths, unmerged CanX-1 rotation, one thread),
    and the band-only kernel against the full-spectrum one on the same
    :data:`BAND_ROW_ATTITUDES` random CanX-1 attitudes, timed in turn.

    Examples
    --------
    The rows time the CanX-1 rotation with its measured tables; not run here:

    >>> import inspect
    >>> from sbrdf_xr.bench.engine import kernel_rows
    >>> list(inspect.signature(kernel_rows).parameters)
    ['repeat']
    >>> [r.name for r in kernel_rows(repeat=1)][:2]  # doctest: +SKIP
    ['kernel: numpy reference (sparse matrix)', 'kernel: fused (numba)']
    """
    from ..engine import builtin_scene
    from ..engine.run import run_block
    from ..kernels.sums import fused_sums

    scene = builtin_scene("canx1-rotation").with_options(merge=False, outputs=("signal", "area"))
    plan = scene.plan()
    numpy_plan = scene.with_options(kernel="numpy").plan()
    b = plan.geometry.block(slice(None))
    t = plan.terms
    n_wl = plan.tables.n_spectral

    def fused() -> None:
        fused_sums(b.to_sun, b.to_observer, t.normal, t.area, t.material, plan.tables, "linear")

    t_fused = best_time(fused, repeat)
    t_numpy = best_time(lambda: run_block(numpy_plan, slice(None)), max(1, repeat - 1))
    pairs = b.to_sun.shape[0] * t.size
    lit = int(np.sum((b.to_sun @ t.normal.T > 0) & (b.to_observer @ t.normal.T > 0)))
    rate = _matmul_rate(1)
    ceiling = rate / (
        2 * 8 * n_wl
    )  # 8 weighted table rows of n_wl multiply-adds per facet-spectrum
    # band-only against full spectrum, kernel alone: 1e5 random CanX-1 attitudes (merged
    # terms), the two timed in turn (timed_runs) so that the machine's load drifts for both
    kernels: dict[str, Any] = {}
    per_lit: dict[bool, tuple[float, float, float]] = {}
    lit_counts: dict[bool, tuple[int, int]] = {}
    for bands in (False, True):
        sp = _sweep_scene(BAND_ROW_ATTITUDES, bands).plan()
        sb, st = sp.geometry.block(slice(None)), sp.terms

        def sweep_kernel(sp: Any = sp, sb: Any = sb, st: Any = st) -> None:
            fused_sums(
                sb.to_sun, sb.to_observer, st.normal, st.area, st.material, sp.tables, "linear"
            )

        kernels["band" if bands else "full"] = sweep_kernel
        n_lit = int(np.sum((sb.to_sun @ st.normal.T > 0) & (sb.to_observer @ st.normal.T > 0)))
        lit_counts[bands] = (n_lit, len(sb.to_sun))
    timing = timed_runs(kernels, repeat)
    # the kernel runs in this thread: its CPU time is what a loaded machine does not inflate
    cpu = timed_runs(kernels, repeat, clock=time.thread_time)
    for bands in (False, True):
        sec = timing["band" if bands else "full"][0]
        n_lit, n_geo = lit_counts[bands]
        per_lit[bands] = (sec, sec / n_lit, n_lit / n_geo)
    band_row = BenchRow(
        f"kernel: band-only (V, R, I), {BAND_ROW_ATTITUDES:.0e} random attitudes",
        per_lit[True][0],
        "full spectrum, same geometries",
        per_lit[True][0] / per_lit[False][0],
        f"{per_lit[True][1] * 1e9:.0f} ns against {per_lit[False][1] * 1e9:.0f} ns per lit "
        f"and seen facet, every cost included ({per_lit[True][2]:.1f} per attitude): "
        f"{per_lit[False][0] / per_lit[True][0]:.1f}x faster (CPU time: "
        f"{cpu['full'][0] / cpu['band'][0]:.1f}x)",
        sweep="kernel, canx1 sweep, merged, linear, 1 thread",
        spread=max(timing["band"][1], timing["full"][1]),
    )
    # the same in CPU time of this thread (the kernel runs in it): what a loaded machine's
    # other processes do not inflate, unlike the wall time
    cpu_row = BenchRow(
        f"kernel: band-only (V, R, I), {BAND_ROW_ATTITUDES:.0e} random attitudes, CPU time",
        cpu["band"][0],
        "full spectrum, same geometries, CPU time",
        cpu["band"][0] / cpu["full"][0],
        f"{cpu['full'][0] / cpu['band'][0]:.1f}x faster in this thread's CPU time",
        sweep="kernel, canx1 sweep, merged, linear, 1 thread",
        spread=max(cpu["band"][1], cpu["full"][1]),
    )
    return [
        BenchRow(
            "kernel: numpy reference (sparse matrix)",
            t_numpy,
            "numpy reference",
            1.0,
            f"{lit / t_numpy:,.0f} facet-spectra/s ({pairs} pairs, {lit} lit and seen)",
            sweep="kernel, canx1-rotation unmerged, linear, 141 nm, 1 thread",
        ),
        BenchRow(
            "kernel: fused (numba)",
            t_fused,
            "numpy reference",
            t_fused / t_numpy,
            f"{lit / t_fused:,.0f} facet-spectra/s = {(lit / t_fused) / ceiling:.0%} of the "
            f"dense-matmul ceiling ({ceiling:,.0f}/s at {rate / 1e9:.1f} GFLOP/s, 1 thread)",
            sweep="kernel, canx1-rotation unmerged, linear, 141 nm, 1 thread",
        ),
        band_row,
        cpu_row,
    ]
