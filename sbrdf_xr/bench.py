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
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import partial
from typing import Any

import numpy as np
import xarray as xr

from . import _lut, catalog, material
from .goniometer import measure
from .testing import lobe_function

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

BANDS = ("V", "R", "I")
CANX1_MATERIALS = ("aluminium-6061-t6", "tjpv-cell", "white-paint-a276")


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

    Examples
    --------
    >>> from sbrdf_xr.bench import BenchRow
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


def best_time(func: Callable[[], object], repeat: int = 3, number: int = 1) -> float:
    """Best of ``repeat`` wall times of ``number`` calls of ``func`` after a warm-up [s per call].

    Examples
    --------
    >>> from sbrdf_xr.bench import best_time
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


# ------------------------------------------------------------- tables


def _example_measurements(n_wavelength: int = 131) -> xr.Dataset:
    wl = np.linspace(450.0, 1100.0, n_wavelength)
    return measure(lobe_function(wl, width=3.0), wl, noise_floor=0.05)


def bench_build_lut(n_wavelength: int = 131, repeat: int = 3) -> list[BenchRow]:
    """Time :func:`sbrdf_xr.material.build_lut` on a paper-sized measurement set.

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


# ---------------------------------------------------- accuracy and cost


def _paper_tables(**build: Any) -> dict[str, xr.DataArray]:
    """The CanX-1 tables rebuilt from their measurements as shipped (the catalog's build
    options), with other construction knobs."""
    out = {}
    for m in CANX1_MATERIALS:
        meas = catalog.load(f"{m}-measurements")
        build_opts = catalog.entry(m).extra.get("build", {})
        fit = build_opts.get("fit", f"{m}-fit")  # the model the shipped table is built with
        shipped = {k: v for k, v in build_opts.items() if k != "fit"}
        out[m] = material.build_lut(
            meas, model=catalog.load(fit), material=m, **{**shipped, **build}
        )
    return out


def _subsample_wavelengths(tables: dict[str, xr.DataArray], step: int) -> dict[str, xr.DataArray]:
    return {k: v.isel(wavelength=slice(None, None, step)) for k, v in tables.items()}


def _band_mags(signal: xr.DataArray) -> np.ndarray:
    from .photometry import pre_integrate

    b = pre_integrate(signal, list(BANDS), normalize=True).values
    with np.errstate(divide="ignore"):
        return -2.5 * np.log10(np.maximum(b, 1e-300))


def _errors(test: xr.DataArray, ref: xr.DataArray) -> tuple[float, float, float]:
    """(max mmag, median mmag, p99 relative spectral error) of ``test`` against ``ref``."""
    if "wavelength" in test.dims:
        mt, mr = _band_mags(test), _band_mags(ref)
        t_sp = (
            test.interp(wavelength=ref.wavelength)
            if test.sizes["wavelength"] != ref.sizes["wavelength"]
            else test
        )
        rel = np.abs(t_sp.values - ref.values) / np.maximum(np.abs(ref.values), 1e-300)
        keep_sp = np.abs(ref.values) > 1e-3 * np.abs(ref.values).max()
        p99 = float(np.percentile(rel[keep_sp], 99))
    else:  # band_signal over band
        mt = -2.5 * np.log10(np.maximum(test.values, 1e-300))
        mr = _band_mags(ref)
        p99 = float("nan")
    bref = 10 ** (-0.4 * mr)
    keep = bref > 1e-3 * bref.max()
    d = np.abs(mt - mr)[keep] * 1e3
    return float(d.max()), float(np.median(d)), p99


def accuracy_cost(quick: bool = False, repeat: int = 2) -> list[BenchRow]:
    """The accuracy/cost table: one knob at a time away from the reference.

    Parameters
    ----------
    quick : bool
        Smaller sweeps and fewer knob settings (a smoke run, for CI).
    repeat : int
        Timing repeats (the best is kept).

    Returns
    -------
    list of BenchRow

    Examples
    --------
    The table rebuilds the CanX-1 tables and runs minutes even with ``quick``; it is
    not run here:

    >>> import inspect
    >>> from sbrdf_xr.bench import accuracy_cost, format_rows
    >>> list(inspect.signature(accuracy_cost).parameters)
    ['quick', 'repeat']
    >>> rows = accuracy_cost(quick=True, repeat=1)  # doctest: +SKIP
    >>> rows[0].name  # doctest: +SKIP
    'reference: cubic look-up, 1-deg theta_i, 21x21, 5 nm, merged, float64'
    >>> print(format_rows(rows))  # doctest: +SKIP
    """
    from . import geometry
    from .scene import builtin_scene
    from .simulate import simulate

    rot = builtin_scene("canx1-rotation")
    n_big = 400 if quick else 5000
    big = rot.with_options(
        attitudes=geometry.uniform_attitudes(n_big, seed=7),
        attitude_angle=None,
        phase_angles=[10.0, 45.0, 90.0],
        chunk=500,
        name=f"random-{n_big}x3",
    )
    sweeps = {"canx1-rotation": rot} if quick else {"canx1-rotation": rot, big.name: big}
    if quick:
        sweeps[big.name] = big
    rows: list[BenchRow] = []
    base_tables = _paper_tables()
    reference = {
        "method": "cubic",
        "dtype": "float64",
        "merge": True,
        "materials": base_tables,
        "outputs": ("signal", "area"),
    }

    def run_cube(scene: Any, **opts: Any) -> xr.Dataset:
        return simulate(scene.with_options(**opts)).compute(scheduler="sync")

    for sweep_name, sweep in sweeps.items():
        ref_cube = run_cube(sweep, **reference)
        ref = ref_cube.signal
        t_ref = best_time(partial(run_cube, sweep, **reference), repeat)
        knobs: list[tuple[str, str, dict[str, Any]]] = [
            ("reference", "cubic look-up, 1-deg theta_i, 21x21, 5 nm, merged, float64", {}),
            ("lookup method", "nearest (the paper's)", {"method": "nearest"}),
            ("lookup method", "linear", {"method": "linear"}),
            ("precision", "float32", {"dtype": "float32"}),
            ("wavelength", "10 nm sampling", {"materials": _subsample_wavelengths(base_tables, 2)}),
            ("wavelength", "20 nm sampling", {"materials": _subsample_wavelengths(base_tables, 4)}),
            (
                "wavelength",
                "band pre-integration (V, R, I)",
                {"outputs": ("band_signal", "area"), "bands": BANDS},
            ),
            ("facets", "not merged (684 facets)", {"merge": False}),
        ]
        if not quick:
            knobs += [
                (
                    "table",
                    "theta_i every 2 deg",
                    {"materials": _paper_tables(theta_i=np.arange(0.0, 91.0, 2.0))},
                ),
                (
                    "table",
                    "theta_i every 5 deg",
                    {"materials": _paper_tables(theta_i=np.arange(0.0, 91.0, 5.0))},
                ),
                (
                    "table",
                    "11 x 11 delta_theta x phi",
                    {"materials": _paper_tables(n_phi=11, n_delta_theta=11)},
                ),
                (
                    "table",
                    "41 x 41 delta_theta x phi",
                    {"materials": _paper_tables(n_phi=41, n_delta_theta=41)},
                ),
            ]
        for knob, setting, opts in knobs:
            cfg = {**reference, **opts}
            if knob == "reference":
                cube, t = ref_cube, t_ref
            else:
                cube = run_cube(sweep, **cfg)
                t = best_time(partial(run_cube, sweep, **cfg), repeat)
            test = cube.band_signal if "band_signal" in cube else cube.signal
            mx, med, p99 = _errors(test, ref)
            rows.append(
                BenchRow(
                    f"{knob}: {setting}",
                    t,
                    "reference",
                    t / t_ref,
                    sweep=sweep_name,
                    mmag_max=mx,
                    mmag_median=med,
                    rel_p99=p99,
                    knob=knob,
                )
            )
        # Tabulated vs analytic: the table method's own error, against the generating models
        # (the simulation option evaluation="analytic", each material's catalog model).
        an_cfg = {**reference, "evaluation": "analytic"}
        an = run_cube(sweep, **an_cfg).signal
        t_an = best_time(partial(run_cube, sweep, **an_cfg), 1)
        mx, med, p99 = _errors(ref, an)
        rows.append(
            BenchRow(
                "materials: analytic generating models (ground truth)",
                t_an,
                "reference",
                t_an / t_ref,
                "error column: the tabulated reference against them",
                sweep=sweep_name,
                mmag_max=mx,
                mmag_median=med,
                rel_p99=p99,
                knob="materials",
            )
        )
    rows += shadow_rows(quick=quick, repeat=repeat)
    return rows


def shadow_rows(quick: bool = False, repeat: int = 2) -> list[BenchRow]:
    """Self-shadowing: the sampled method at several densities against the exact method
    (polygon clipping) on the package's non-convex test bodies (an L prism, a plate with a
    fin, a bus with a panel, CanX-1 with antennas), and the cost of both on a CanX-1 sweep
    (:mod:`sbrdf_xr.shadow_bench`).  Errors are of the Lambertian signal against exact.

    Examples
    --------
    Even ``quick`` takes over a second (four bodies, three densities, a CanX-1 sweep);
    :func:`sbrdf_xr.shadow_bench.accuracy_rows` runs the same comparison on one body
    in milliseconds.  Not run here:

    >>> from sbrdf_xr.bench import shadow_rows
    >>> rows = shadow_rows(quick=True, repeat=1)  # doctest: +SKIP
    >>> [r.name for r in rows][:2]  # doctest: +SKIP
    ['shadowing: exact', 'shadowing: off (no shadowing)']
    """
    from . import shadow_bench

    rows = []
    acc = shadow_bench.accuracy_rows(
        densities=(2, 4, 8) if quick else (2, 4, 8, 16, 32),
        n_geometries=8 if quick else 18,
        repeat=repeat,
    )
    for r in acc:
        mmag = 2500.0 * np.log10(1.0 + r.worst_rel_error)
        med = 2500.0 * np.log10(1.0 + r.median_rel_error)
        rows.append(
            BenchRow(
                f"shadowing: {r.label}",
                r.ms_per_geometry * 1e-3,
                "exact shadowing",
                r.time_ratio,
                f"worst {r.worst_rel_error:.2g}, median {r.median_rel_error:.2g} "
                f"relative ({r.bodies}; {r.n_geometries} geometries each)",
                sweep="shadowing, non-convex bodies",
                mmag_max=mmag,
                mmag_median=med,
                knob="shadowing",
            )
        )
    for c in shadow_bench.canx1_sweep_rows(n_attitudes=90 if quick else 360, repeat=repeat):
        rows.append(
            BenchRow(
                f"shadowing cost: {c.label}",
                c.ms_per_geometry * 1e-3,
                c.ratio_to,
                c.ratio,
                f"{c.ms_per_geometry:.2f} ms per geometry, {c.n_facets} facets",
                sweep="shadowing, CanX-1 sweep",
                knob="shadowing",
            )
        )
    return rows


# ------------------------------------------------------ kernel speed


def kernel_throughput(repeat: int = 3) -> list[BenchRow]:
    """Geometry-facet-spectra per second of the simulation against a per-facet loop.

    The baseline is the straightforward numpy evaluation: for every facet, its angles
    for all geometries (:func:`sbrdf_xr.geometry.facet_angles`), its spectra by the
    public ``linear`` look-up (:func:`sbrdf_xr.material.lookup`) and the weighted sum.
    Both evaluate the CanX-1 rotation (360 geometries x 684 facets x 141 wavelengths).
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
    ['repeat']
    >>> rows = kernel_throughput(repeat=1)  # doctest: +SKIP
    >>> rows[0].name  # doctest: +SKIP
    'per-facet numpy loop (baseline)'
    """
    from . import geometry
    from .scene import builtin_scene
    from .simulate import simulate

    scene = builtin_scene("canx1-rotation").with_options(
        outputs=("signal", "area"), method="linear"
    )
    facets = scene.spacecraft.facets()
    s, o = scene.body_vectors()
    s2, o2 = s.reshape(-1, 3), o.reshape(-1, 3)
    materials = scene.materials or {}
    tables = {m: materials[m] for m in scene.spacecraft.materials}
    n_geom, n_fac = s2.shape[0], facets.sizes["facet"]
    n_wl = tables[CANX1_MATERIALS[0]].sizes["wavelength"]

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

    base, fast, unmerged = per_facet_loop(), sim(True), sim(False)
    agree = float(np.max(np.abs(fast.reshape(base.shape) - base)) / np.abs(base).max())
    agree2 = float(np.max(np.abs(unmerged.reshape(base.shape) - base)) / np.abs(base).max())
    t_base = best_time(per_facet_loop, 1)
    t_merged = best_time(lambda: sim(True), repeat)
    t_unmerged = best_time(lambda: sim(False), repeat)
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
        ),
        BenchRow(
            "simulate, facets not merged",
            t_unmerged,
            "per-facet loop",
            t_unmerged / t_base,
            f"{work / t_unmerged:,.0f} g-f-spectra/s; speed-up {t_base / t_unmerged:.1f}x; "
            f"agrees to {agree2:.1e}",
            sweep="canx1-rotation",
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


# ------------------------------------------------------------ output


def format_rows(rows: list[BenchRow]) -> str:
    """A plain-text table of benchmark rows (time as a ratio to the row's baseline).

    Examples
    --------
    >>> from sbrdf_xr.bench import BenchRow
    >>> rows = [
    ...     BenchRow("reference", 2.0, "reference", 1.0, sweep="demo",
    ...              mmag_max=0.0, mmag_median=0.0, rel_p99=0.0),
    ...     BenchRow("lookup method: linear", 0.6, "reference", 0.3, sweep="demo",
    ...              mmag_max=12.0, mmag_median=0.4, rel_p99=0.01),
    ... ]
    >>> from sbrdf_xr.bench import format_rows
    >>> print(format_rows(rows))
    [demo]
    case                   time/baseline   mmag max   mmag med   rel p99  notes
    reference                         1x          0          0         0  vs reference
    lookup method: linear           0.3x         12        0.4      0.01  vs reference
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
                f"{'case':<{w}}  {'time/baseline':>13}  "
                f"{'mmag max':>9}  {'mmag med':>9}  {'rel p99':>8}  notes",
            ]
        err = (
            f"{r.mmag_max:>9.3g}  {r.mmag_median:>9.3g}  {r.rel_p99:>8.2g}"
            if np.isfinite(r.mmag_max)
            else f"{'':>9}  {'':>9}  {'':>8}"
        )
        note = r.extra or f"vs {r.baseline}"
        out.append(f"{r.name:<{w}}  {r.ratio:>12.3g}x  {err}  {note}")
    return "\n".join(out).lstrip("\n")


def rows_to_dataset(rows: list[BenchRow]) -> xr.Dataset:
    """The rows as a labelled Dataset over ``case`` (for netCDF or CSV).

    Examples
    --------
    >>> from sbrdf_xr.bench import BenchRow
    >>> rows = [
    ...     BenchRow("reference", 2.0, "reference", 1.0, sweep="demo",
    ...              mmag_max=0.0, mmag_median=0.0, rel_p99=0.0),
    ...     BenchRow("lookup method: linear", 0.6, "reference", 0.3, sweep="demo",
    ...              mmag_max=12.0, mmag_median=0.4, rel_p99=0.01),
    ... ]
    >>> from sbrdf_xr.bench import rows_to_dataset
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
                {"units": "1", "long_name": "wall time / baseline wall time"},
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
            "baseline": ("case", col("baseline"), {"long_name": "baseline of the time ratio"}),
            "sweep": ("case", col("sweep"), {"long_name": "sweep"}),
            "notes": ("case", col("extra"), {"long_name": "notes"}),
        },
        coords={"case": ("case", col("name"), {"long_name": "knob and setting"})},
        attrs={"title": "sbrdf_xr accuracy/cost benchmark"},
    )


def plot_front(rows: list[BenchRow], ax: Any = None) -> Any:
    """The accuracy/time front: worst band error against relative time, per sweep.

    Examples
    --------
    >>> from sbrdf_xr.bench import BenchRow
    >>> rows = [
    ...     BenchRow("reference", 2.0, "reference", 1.0, sweep="demo",
    ...              mmag_max=0.0, mmag_median=0.0, rel_p99=0.0),
    ...     BenchRow("lookup method: linear", 0.6, "reference", 0.3, sweep="demo",
    ...              mmag_max=12.0, mmag_median=0.4, rel_p99=0.01),
    ... ]
    >>> import matplotlib.pyplot as plt
    >>> from sbrdf_xr.bench import plot_front
    >>> fig = plot_front(rows)
    >>> ax = fig.axes[0]
    >>> ax.get_xscale(), ax.get_yscale(), ax.get_xlabel()
    ('log', 'log', 'wall time / reference wall time')
    >>> plt.close(fig)
    """
    import matplotlib.pyplot as plt

    if ax is None:
        fig, ax = plt.subplots(figsize=(7, 4.5), layout="constrained")
    else:
        fig = ax.figure
    for sweep in dict.fromkeys(r.sweep for r in rows if np.isfinite(r.mmag_max)):
        pts = [r for r in rows if r.sweep == sweep and np.isfinite(r.mmag_max)]
        ax.scatter([r.ratio for r in pts], [max(r.mmag_max, 1e-6) for r in pts], label=sweep)
        for r in pts:
            ax.annotate(r.name.split(": ", 1)[-1], (r.ratio, max(r.mmag_max, 1e-6)), fontsize=6)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time / reference wall time")
    ax.set_ylabel("largest band error [mmag]")
    ax.legend(fontsize=7)
    return fig


def run(quick: bool = False) -> list[BenchRow]:
    """All benchmarks (``quick``: smaller problems, a smoke run).

    Examples
    --------
    Minutes even with ``quick`` (``sbrdf-xr bench --quick`` runs it); not run here:

    >>> from sbrdf_xr.bench import format_rows, run
    >>> rows = run(quick=True)  # doctest: +SKIP
    >>> rows[0].name  # doctest: +SKIP
    'build_lut (150 samples, 105 measured, 131 wl)'
    >>> print(format_rows(rows))  # doctest: +SKIP
    """
    rows = bench_build_lut(repeat=1 if quick else 3)
    rows += bench_lookup(n_geometries=2000 if quick else 20000, repeat=1 if quick else 3)
    rows += accuracy_cost(quick=quick, repeat=1 if quick else 2)
    rows += kernel_throughput(repeat=1 if quick else 3)
    return rows


if __name__ == "__main__":  # pragma: no cover
    print(format_rows(run()))
