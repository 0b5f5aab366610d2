"""Engine benchmarks (``sbrdf-xr bench --engine``): what a sweep costs end to end.

The table opens with the goals of issue 47, each a row (:mod:`sbrdf_xr.bench.goals`).

Every row is a ratio or a rate measured in one run on this machine, never an
absolute claim:

* ``canx1-rotation`` warm, full spectrum: microseconds per attitude-spectrum of
  ``simulate(scene).compute()`` (the scene's plan already compiled);
* the same for a fresh scene on every call (``scene.with_options(phase_angles=...)``,
  planned anew; its tables loaded), as a ratio to the warm time;
* a single-geometry call, warm; and one geometry through the compiled evaluator, the
  effects' path, ``run_block``, ``simulate`` and the bare kernel
  (:mod:`sbrdf_xr.bench.calls`);
* sweeps of 1e4, 1e5 (and, without ``quick``, 1e6) random attitudes x 141
  wavelengths written to netCDF at default settings, each in a fresh process: the
  wall time, its growth exponent between sizes, the ratio to the bare kernel time
  over the same geometries, the ratio to its floor (the slowest of the bare kernel, the
  disk writing and syncing as many bytes, and the processor time of both shared by the
  cores, :func:`~sbrdf_xr.bench.machine.disk_cost`), and the peak resident memory;
* band-only (V, R, I) against full spectrum on the 1e5 sweep;
* two cores against one (one thread everywhere: ``SBRDF_XR_NUM_THREADS=1``, and the
  process, its writer thread too, pinned to one CPU), written, computed only (every
  output, nothing written) and the bare kernel alone, and
  two process workers against one on a ``LocalCluster`` writing a Zarr store by
  blocks; beside them the machine's own two-thread ceiling
  (:func:`~sbrdf_xr.bench.machine.thread_scaling`);
* open surfaces and sun-tracking parts against the rigid closed path
  (:mod:`sbrdf_xr.bench.parts`);
* kernel throughput (facet-spectra per second, linear, 141 wavelengths, unmerged)
  against the dense-matmul arithmetic rate of this machine and against the numpy
  reference kernel, measured first, before the sweeps load the machine.
"""

from __future__ import annotations

import itertools
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from ..errors import ValidationError
from ._kernel_rows import _sweep_scene, kernel_rows
from .machine import DiskCost, disk_cost, thread_scaling
from .rows import BenchRow, best_time

__all__ = ["engine_rows", "sweep_job", "write_floor"]

#: The sweeps: canx1 at random attitudes, phase angle 10 deg, default outputs.
_SIZES_QUICK = (10_000, 100_000)
_SIZES = (10_000, 100_000, 1_000_000)
_WRITTEN = "sweeps written to netCDF, default settings, 141 wavelengths"


def sweep_job(
    n: int,
    path: str,
    bands: bool = False,
    mode: str = "write",
    workers: int = 0,
    outputs: str = "independent",
) -> dict[str, float]:
    """Run one sweep in this process (the subprocess side of :func:`engine_rows`).

    ``mode``: ``write`` (netCDF at default settings), ``kernel`` (the bare fused
    kernel over the same geometries and threads, outputs discarded), ``compute``
    (every block's outputs computed in full, :func:`~sbrdf_xr.engine.run.run_block`,
    on the same threads, nothing written), ``zarr`` (a LocalCluster of ``workers``
    single-threaded processes writing a Zarr store; ``workers=0``: this process's threads).
    ``outputs``: the writer's (:mod:`sbrdf_xr.store.derived`), ``all`` for every variable.
    Returns seconds (after planning and a warm-up of the compiled kernel) and the
    processor time of this process over them, the peak RSS,
    private memory and PSS [byte] (:class:`_PrivatePeak`) and the bytes written.

    Examples
    --------
    Every sweep is CanX-1 with its measured tables (seconds to build on first use), so
    the call is not run here:

    >>> import inspect
    >>> from sbrdf_xr.bench.engine import sweep_job
    >>> list(inspect.signature(sweep_job).parameters)
    ['n', 'path', 'bands', 'mode', 'workers', 'outputs']
    >>> sorted(sweep_job(1000, "cube.nc"))  # doctest: +SKIP
    ['blocks', 'bytes', 'cpu', 'pss', 'rss', 'rss_private', 'seconds']
    """

    from ..engine.run import default_n_threads, run_block, simulate
    from ..store import write

    private = _PrivatePeak()  # the peak of this process's own memory, sampled
    scene = _sweep_scene(n, bands)
    plan = scene.plan()
    run_block(plan, slice(0, min(8, n)))  # load the compiled kernel
    if mode in ("kernel", "compute"):
        from concurrent.futures import ThreadPoolExecutor

        from ..kernels.sums import fused_sums

        t = plan.terms
        blocks = [plan.block_slice(k) for k in range(plan.n_blocks)]

        def one(sl: slice) -> None:
            if mode == "compute":
                run_block(plan, sl)
                return
            b = plan.geometry.block(sl)
            fused_sums(
                b.to_sun,
                b.to_observer,
                t.normal,
                t.area,
                t.material,
                plan.tables,
                plan.knobs["method"],
            )

        t0, c0 = time.perf_counter(), time.process_time()
        with ThreadPoolExecutor(default_n_threads()) as pool:
            list(pool.map(one, blocks))
        seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    elif mode == "zarr" and not workers:
        t0, c0 = time.perf_counter(), time.process_time()
        write(simulate(plan, lazy=True), path, overwrite=True, outputs=outputs)
        seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    elif mode == "zarr":
        from distributed import Client, LocalCluster

        with (
            LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                env={"SBRDF_XR_NUM_THREADS": "1"},
            ) as cluster,
            Client(cluster) as client,
        ):
            client.run(lambda: run_block(plan, slice(0, 8)))  # compile on the workers
            t0, c0 = time.perf_counter(), time.process_time()
            cube = simulate(plan, client=client)
            write(cube, path, overwrite=True, client=client, outputs=outputs)
            seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    else:
        t0, c0 = time.perf_counter(), time.process_time()
        write(simulate(plan), path, overwrite=True, outputs=outputs)
        seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    out = {
        "seconds": seconds,
        "cpu": cpu,
        "rss": float(_peak_rss()),
        "blocks": float(plan.n_blocks),
    }
    out["rss_private"] = float(private.stop())
    out["pss"] = float(private.pss)
    if mode in ("write", "zarr"):
        out["bytes"] = float(_size(Path(path)))
    return out


def _size(path: Path) -> int:
    """Bytes of a file, or of every file under a directory (a Zarr store)."""
    if path.is_file():
        return path.stat().st_size
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file())


class _PrivatePeak:
    """The peak of this process's anonymous (private) resident memory [byte], sampled
    every 5 ms in a thread: what the peak RSS is less the pages of files it maps (the
    memory-mapped tables, shared by every process that maps them); and the peak of its
    proportional set size (``pss``, every 0.5 s: each shared page counted once over the
    processes that map it, ``/proc/self/smaps_rollup``; reading it costs ~9 ms of CPU with
    the tables mapped, so sampled every 50 ms it took ~18 % of a core from the run it
    measured)."""

    def __init__(self) -> None:
        import threading

        self.peak = self.pss = 0
        self.done = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        for i in itertools.count():
            if self.done.wait(0.005):
                break
            self.peak = max(self.peak, _status("RssAnon"))
            if i % 100 == 0:
                self.pss = max(self.pss, _status("Pss", "/proc/self/smaps_rollup"))

    def stop(self) -> int:
        self.done.set()
        self.thread.join()
        self.pss = max(self.pss, _status("Pss", "/proc/self/smaps_rollup"))
        return max(self.peak, _status("RssAnon"))


def _status(field: str, where: str = "/proc/self/status") -> int:
    """A memory field of ``/proc/self/status`` (or ``where``) [byte] (0 where there is none)."""
    try:
        with open(where, encoding="ascii") as f:
            return next((int(x.split()[1]) * 1024 for x in f if x.startswith(field + ":")), 0)
    except OSError:
        return 0


def _peak_rss() -> int:
    """Peak resident memory of this process [byte].

    Linux's ``ru_maxrss`` keeps the parent's peak across ``fork`` + ``exec``, so a
    benchmark subprocess would report its parent's; ``VmHWM`` is this process's own.
    """
    import resource

    return _status("VmHWM") or resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def _subprocess(
    n: int,
    bands: bool = False,
    mode: str = "write",
    workers: int = 0,
    threads: int | None = None,
    where: str | None = None,
    outputs: str = "independent",
) -> dict[str, float]:
    with tempfile.TemporaryDirectory(prefix="sbrdf-bench-", dir=where) as tmp:
        path = str(Path(tmp) / ("cube.zarr" if mode == "zarr" else "cube.nc"))
        env = dict(os.environ)
        if threads is not None:
            env.update(
                SBRDF_XR_NUM_THREADS=str(threads),
                DASK_NUM_WORKERS=str(threads),
                NUMBA_NUM_THREADS=str(threads),
                OMP_NUM_THREADS=str(threads),
            )
        # one core means one: the process (its writer thread too) is pinned to one CPU
        pin = (
            "import os; os.sched_setaffinity(0, sorted(os.sched_getaffinity(0))[:1]); "
            if threads == 1 and hasattr(os, "sched_setaffinity")
            else ""
        )
        code = (
            f"{pin}import json, sys; from sbrdf_xr.bench.engine import sweep_job; "
            f"print(json.dumps(sweep_job({n}, {path!r}, {bands}, {mode!r}, {workers}, "
            f"{outputs!r})))"
        )
        out = subprocess.run(
            [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=False
        )
        if out.returncode:
            raise RuntimeError(f"benchmark subprocess failed: {out.stderr[-2000:]}")
        return json.loads(out.stdout.strip().splitlines()[-1])


def engine_rows(quick: bool = False, repeat: int = 3) -> list[BenchRow]:
    """All engine rows (see the module docstring), the goals of issue 47 first
    (:mod:`sbrdf_xr.bench.goals`); ``quick`` leaves out 1e6 and the cluster.

    Examples
    --------
    Minutes even with ``quick`` (sweeps of 1e4 and 1e5 attitudes in fresh processes;
    ``sbrdf-xr bench --engine`` runs it); not run here:

    >>> import inspect
    >>> from sbrdf_xr.bench.engine import engine_rows
    >>> list(inspect.signature(engine_rows).parameters)
    ['quick', 'repeat']
    >>> rows = engine_rows(quick=True, repeat=1)  # doctest: +SKIP
    >>> rows[0].name  # doctest: +SKIP
    'canx1-rotation, full spectrum, per attitude-spectrum'
    """
    # the kernel rows first, in a process and on a machine that the sweeps (gigabytes
    # written, a cluster started and stopped) have not loaded yet
    kernel = kernel_rows(repeat)
    rows = _warm_rows(repeat)
    sizes = _SIZES_QUICK if quick else _SIZES
    results = {n: _subprocess(n) for n in sizes}
    rows += _sweep_rows(sizes, results)
    rows += _lean_rows(sizes, results)
    rows += _core_rows(results, repeat)
    if not quick:
        rows += _cluster_rows(results)
    # one geometry: the compiled evaluator against simulate and the bare kernel
    from .calls import single_call_rows

    rows += single_call_rows(repeat=max(repeat, 5))
    # open surfaces and articulated parts against the rigid closed path
    from .parts import parts_rows

    rows += parts_rows(repeat=max(repeat, 5))
    # each goal of issue 47 a row, first in the table (bench.goals)
    from .goals import engine_goals

    return engine_goals(rows + kernel, results, quick, repeat) + rows + kernel


def _warm_rows(repeat: int) -> list[BenchRow]:
    """CanX-1 rotation warm, a fresh scene, and one geometry (end to end, in this process)."""
    from ..engine import builtin_scene
    from ..engine.run import simulate

    rows: list[BenchRow] = []
    rot = builtin_scene("canx1-rotation")
    simulate(rot).compute()
    # many repeats: the best of a few short calls is at the mercy of the machine's load
    t_rot = best_time(lambda: simulate(rot).compute(), max(repeat, 20))
    # a new scene on every call (another phase angle), its tables already loaded and hashed:
    # what an interactive change of the geometry or a knob costs
    angles = itertools.count()
    t_fresh = best_time(
        lambda: simulate(rot.with_options(phase_angles=[10.0 + 1e-6 * next(angles)])).compute(),
        max(repeat, 20),
    )
    one = rot.with_options(attitudes=np.asarray(rot.attitudes)[:1], attitude_angle=None)
    simulate(one).compute()
    t_one = best_time(lambda: simulate(one).compute(), max(repeat, 5), number=20)
    sweep = "end to end, warm"
    rows.append(
        BenchRow(
            "canx1-rotation, full spectrum, per attitude-spectrum",
            t_rot / 360,
            "canx1-rotation total",
            1 / 360,
            f"{t_rot / 360 * 1e6:.1f} us per attitude ({t_rot * 1e3:.1f} ms for 360 x 141)",
            sweep=sweep,
        )
    )
    rows.append(
        BenchRow(
            "canx1-rotation, a fresh scene (new phase angle), warm tables",
            t_fresh / 360,
            "canx1-rotation, warm (same scene)",
            t_fresh / t_rot,
            f"{t_fresh / 360 * 1e6:.1f} us per attitude ({t_fresh * 1e3:.1f} ms for 360 x 141, "
            "scene.with_options and planning included)",
            sweep=sweep,
        )
    )
    rows.append(
        BenchRow(
            "single geometry, simulate(scene).compute()",
            t_one,
            "canx1-rotation total",
            t_one / t_rot,
            f"{t_one * 1e3:.2f} ms",
            sweep=sweep,
        )
    )

    return rows


def write_floor(
    kernel_seconds: float, kernel_cpu: float, disk: DiskCost, cores: int
) -> tuple[float, float]:
    """The shortest time [s] a cube write can take, and its processor-bound part [s].

    The write computes the blocks (the bare kernel: ``kernel_seconds`` of wall time,
    ``kernel_cpu`` of processor time) and writes their bytes (``disk``,
    :func:`~sbrdf_xr.bench.machine.disk_cost`).  It takes at least as long as either
    alone, and at least as long as both processor times spread over ``cores``.

    Examples
    --------
    >>> from sbrdf_xr.bench.engine import write_floor
    >>> from sbrdf_xr.bench.machine import DiskCost
    >>> write_floor(2.0, 4.0, DiskCost(2_000_000_000, 1.5, 1.0), cores=2)  # the cores bound
    (2.5, 2.5)
    >>> write_floor(2.0, 4.0, DiskCost(2_000_000_000, 3.0, 1.0), cores=2)  # the disk bounds
    (3.0, 2.5)
    """
    if cores < 1:
        raise ValidationError(f"cores: must be >= 1, got {cores}")
    shared = (kernel_cpu + disk.cpu_seconds) / cores
    return max(kernel_seconds, disk.seconds, shared), shared


def _sweep_rows(sizes: tuple[int, ...], results: dict[int, dict[str, float]]) -> list[BenchRow]:
    """Each sweep written, against the bare kernel and against its floor; band-only."""
    rows: list[BenchRow] = []
    kernels = {n: _subprocess(n, mode="kernel") for n in sizes}
    prev = None
    for n in sizes:
        r, k = results[n], kernels[n]
        exp = ""
        if prev is not None:
            growth = np.log(r["seconds"] / results[prev]["seconds"]) / np.log(n / prev)
            exp = f"; exponent {growth:.3f} from {prev:.0e}"
        rows.append(
            BenchRow(
                f"{n:.0e} attitudes, write",
                r["seconds"],
                "bare kernel, same geometries",
                r["seconds"] / k["seconds"],
                f"{r['seconds']:.2f} s in {int(r['blocks'])} blocks, peak RSS "
                f"{r['rss'] / 1e9:.2f} GB (private {r['rss_private'] / 1e9:.2f} GB, the rest "
                "file pages: libraries and the mapped tables every process shares; PSS "
                f"{r.get('pss', 0.0) / 1e9:.2f} GB){exp}",
                sweep=_WRITTEN,
            )
        )
        # the disk's rate for as many bytes as the cube (a virtual disk's write-back cache
        # makes small writes look faster than a large one can be), and the processor time
        # writing them takes, which the cores that compute the blocks also have to give
        disk = disk_cost(nbytes=int(r["bytes"]))
        cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else 1
        floor, shared = write_floor(k["seconds"], k["cpu"], disk, cores)
        rows.append(
            BenchRow(
                f"{n:.0e} attitudes, write, against its floor",
                r["seconds"],
                "the slowest of the bare kernel, the disk and the cores shared",
                r["seconds"] / floor,
                f"{r['bytes'] / 1e6:.0f} MB file: the disk writes and syncs as many bytes in "
                f"{disk.seconds:.2f} s ({disk.rate / 1e6:.0f} MB/s) with {disk.cpu_seconds:.2f} s "
                f"of processor time, the kernel takes {k['seconds']:.2f} s ({k['cpu']:.2f} s of "
                f"processor time), both on {cores} cores at best {shared:.2f} s; the write used "
                f"{r['cpu']:.2f} s of processor time (the kernel's write-back threads not "
                "counted)",
                sweep=_WRITTEN,
            )
        )
        prev = n
    return rows


def _core_rows(results: dict[int, dict[str, float]], repeat: int) -> list[BenchRow]:
    """Band-only against full spectrum at 1e5; two cores against one (written, computed,
    bare kernel) and the machine's two-thread ceiling."""
    rows: list[BenchRow] = []
    n5 = 100_000
    band = _subprocess(n5, bands=True)
    rows.append(
        BenchRow(
            "band-only (V, R, I), 1e5 attitudes, write",
            band["seconds"],
            "full spectrum, same sweep",
            band["seconds"] / results[n5]["seconds"],
            f"{results[n5]['seconds'] / band['seconds']:.1f}x faster",
            sweep=_WRITTEN,
        )
    )
    runs = max(1, repeat)

    def paired(mode: str) -> tuple[dict[str, float], dict[str, float]]:
        """Fastest of ``runs`` sweeps on two cores and on one, alternated: the machine's
        load drifts between runs, and a single pair moved by 30 % from one run to the next."""
        two: list[dict[str, float]] = []
        one: list[dict[str, float]] = []
        for _ in range(runs):  # two, one, two, one, ...
            two.append(_subprocess(n5, mode=mode))
            one.append(_subprocess(n5, mode=mode, threads=1))
        return min(two, key=lambda r: r["seconds"]), min(one, key=lambda r: r["seconds"])

    w2, w1 = paired("write")
    rows.append(
        BenchRow(
            "1e5 attitudes, one core (one thread everywhere, pinned to one CPU)",
            w1["seconds"],
            "two cores",
            w1["seconds"] / w2["seconds"],
            f"two cores are {w1['seconds'] / w2['seconds']:.2f}x one core "
            f"(fastest of {runs} alternated runs each)",
            sweep=_WRITTEN,
        )
    )
    one_t, two_t = thread_scaling()
    ceiling = one_t / two_t
    rows.append(
        BenchRow(
            "this machine: compute-bound numba loop, one thread",
            one_t,
            "two threads",
            ceiling,
            f"two threads are {ceiling:.2f}x one: the ceiling of any two-core speed-up here",
            sweep="compute only, default settings, 141 wavelengths",
        )
    )
    c2, c1 = paired("compute")
    rows.append(
        BenchRow(
            "1e5 attitudes computed, nothing written, one core",
            c1["seconds"],
            "two cores",
            c1["seconds"] / c2["seconds"],
            f"two cores are {c1['seconds'] / c2['seconds']:.2f}x one core "
            f"({c2['seconds']:.2f} s against {c1['seconds']:.2f} s)",
            sweep="compute only, default settings, 141 wavelengths",
        )
    )
    k2, k1 = paired("kernel")
    rows.append(
        BenchRow(
            "1e5 attitudes, bare kernel, one core",
            k1["seconds"],
            "two cores",
            k1["seconds"] / k2["seconds"],
            f"two cores are {k1['seconds'] / k2['seconds']:.2f}x one core for the "
            "kernel alone (its table rows come from memory both cores share)",
            sweep="compute only, default settings, 141 wavelengths",
        )
    )
    return rows


def _lean_rows(sizes: tuple[int, ...], results: dict[int, dict[str, float]]) -> list[BenchRow]:
    """Bytes written with the derived variables left out (the default) against every
    variable written (``outputs="all"``), on the largest sweep."""
    n = sizes[-1]
    full = _subprocess(n, outputs="all")
    lean = results[n]
    return [
        BenchRow(
            f"{n:.0e} attitudes, bytes written, derived variables left out",
            lean["bytes"],
            'every variable written (outputs="all")',
            lean["bytes"] / full["bytes"],
            f"{lean['bytes'] / 1e6:.0f} MB against {full['bytes'] / 1e6:.0f} MB; "
            f"{lean['seconds']:.2f} s against {full['seconds']:.2f} s",
            sweep=_WRITTEN,
        )
    ]


def _cluster_rows(results: dict[int, dict[str, float]]) -> list[BenchRow]:
    """1e6 attitudes on a LocalCluster of two process workers against one, and against
    the threaded default (netCDF, and Zarr written by this process's threads)."""
    rows: list[BenchRow] = []
    # the plan travels to each worker once, its tables as handles to their memory-mapped
    # files (sbrdf_xr.materials.mapped): each worker maps the pages every process shares
    n6 = _SIZES[-1]
    z1 = _subprocess(n6, mode="zarr", workers=1)
    z2 = _subprocess(n6, mode="zarr", workers=2)
    zt = _subprocess(n6, mode="zarr")
    nc = results[n6]
    rows.append(
        BenchRow(
            f"{n6:.0e} attitudes, threaded default (netCDF)",
            nc["seconds"],
            "LocalCluster, 2 process workers, Zarr by blocks",
            nc["seconds"] / z2["seconds"],
            f"2 workers are {nc['seconds'] / z2['seconds']:.2f}x the threaded netCDF write "
            f"({z2['seconds']:.2f} s against {nc['seconds']:.2f} s) and "
            f"{zt['seconds'] / z2['seconds']:.2f}x the threaded Zarr write ({zt['seconds']:.2f} s)",
            sweep=_WRITTEN,
        )
    )
    rows.append(
        BenchRow(
            f"{n6:.0e} attitudes, LocalCluster, 1 process worker, Zarr by blocks",
            z1["seconds"],
            "2 process workers",
            z1["seconds"] / z2["seconds"],
            f"2 workers are {z1['seconds'] / z2['seconds']:.2f}x one worker",
            sweep=_WRITTEN,
        )
    )
    return rows
