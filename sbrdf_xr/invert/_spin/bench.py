"""Timing of the spin-state search."""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

import numpy as np
import xarray as xr

from .data import light_curve_fluxes, spin_geometry
from .search import Kernel, Problem, fibonacci_sphere, run_search, vec

__all__ = ["benchmark_spin_bound", "benchmark_spin_search"]


# ------------------------------------------------------------------------------ benchmark


def benchmark_spin_search(
    n_candidates: Sequence[int] = (2500, 5000, 10000),
    n_samples: int = 300,
    bands: Sequence[str] = ("V", "R", "I"),
    n_threads: int | None = None,
    spacecraft: Any = None,
    methods: Sequence[str] = ("direct", "table", "shift"),
    n_angles: int = 360,
) -> list[dict[str, Any]]:
    """Wall time of the spin-state search of :func:`fit_spin`.

    A synthetic light curve of ``n_samples`` times in each band, the observer moving
    through 60 degrees; the candidates are Fibonacci axes x 10 periods x 10 phases
    (``n/100`` axes).  ``direct`` runs every candidate at every time through the kernel;
    ``table`` evaluates the kernel once per axis and time on ``n_angles`` spin angles;
    ``shift`` once per axis at the mean directions.  Returns one row per method and size:
    ``method``, ``candidates``, ``samples``, ``bands``, ``seconds``, ``per_candidate_ms``.

    Examples
    --------
    200 candidates (2 axes x 10 periods x 10 phases) on a box of the catalog's
    Lambertian grey, 20 samples in V (the default body is CanX-1 with its measured
    tables, which take seconds to build):

    >>> import trimesh
    >>> from sbrdf_xr import load_spacecraft
    >>> from sbrdf_xr.invert import benchmark_spin_search
    >>> box = load_spacecraft(trimesh.creation.box(extents=(1.0, 2.0, 3.0)),
    ...                       material="lambertian-grey-50")
    >>> rows = benchmark_spin_search(n_candidates=(200,), n_samples=20, bands=("V",),
    ...                              n_threads=1, spacecraft=box, methods=("shift",))
    >>> [(r["method"], r["candidates"], r["samples"], r["bands"]) for r in rows]
    [('shift', 200, 20, 1)]
    >>> sorted(rows[0])
    ['bands', 'candidates', 'method', 'per_candidate_ms', 'samples', 'seconds']
    """
    from ...body.spacecraft import canx1

    sc = spacecraft if spacecraft is not None else canx1()
    t = np.linspace(0.0, 300.0, n_samples)
    nb = len(bands)
    lc = xr.Dataset(
        {
            "flux": ("obs", np.ones(n_samples * nb)),
            "flux_uncertainty": ("obs", np.full(n_samples * nb, 0.02)),
        },
        coords={
            "time": ("obs", np.repeat(t, nb)),
            "band": ("obs", np.tile(list(bands), n_samples)),
        },
    )
    data = light_curve_fluxes(lc)
    kern = Kernel(sc, list(bands))
    az = np.radians(np.linspace(0.0, 60.0, n_samples))
    to_obs = np.stack([np.cos(az), np.sin(az), np.zeros_like(az)], axis=-1)
    geo = spin_geometry(data["time"], None, [0.3, 0.9, 0.3], to_obs)
    prob = Problem(data, geo, kern, np.array([0.0, 0, 1]), "band")
    periods = np.linspace(20.0, 40.0, 10)
    phases = np.arange(10) * 36.0
    run_search("direct", prob, fibonacci_sphere(2), periods[:1], phases[:1], n_threads, n_angles)
    rows = []
    for method in methods:
        for n in n_candidates:
            axes = fibonacci_sphere(max(1, int(n) // 100))
            t0 = time.perf_counter()
            run_search(method, prob, axes, periods, phases, n_threads, n_angles)
            dt = time.perf_counter() - t0
            nc = len(axes) * 100
            rows.append(
                {
                    "method": method,
                    "candidates": nc,
                    "samples": n_samples,
                    "bands": nb,
                    "seconds": dt,
                    "per_candidate_ms": 1e3 * dt / nc,
                }
            )
    return rows


def _spin_problem(sc: Any, bands: Sequence[str], n_samples: int, seed: int) -> Problem:
    """A light curve of ``sc`` spinning 30 s about body z (axis 40, 25 deg), the observer
    moving through 60 degrees over 300 s, with 2 % noise."""
    t = np.linspace(0.0, 300.0, n_samples)
    nb = len(bands)
    lc = xr.Dataset(
        {
            "flux": ("obs", np.ones(n_samples * nb)),
            "flux_uncertainty": ("obs", np.ones(n_samples * nb)),
        },
        coords={
            "time": ("obs", np.repeat(t, nb)),
            "band": ("obs", np.tile(list(bands), n_samples)),
        },
    )
    data = light_curve_fluxes(lc)
    az = np.radians(np.linspace(0.0, 60.0, n_samples))
    to_obs = np.stack([np.cos(az), np.sin(az), np.zeros_like(az)], axis=-1)
    geo = spin_geometry(data["time"], None, [0.3, 0.9, 0.3], to_obs)
    kern = Kernel(sc, list(bands))
    k = np.array([0.0, 0.0, 1.0])
    truth = vec(40.0, 25.0)[None, :]
    m = Problem(data, geo, kern, k, "band").model(truth, np.array([30.0]), np.array([50.0]))[0]
    sigma = 0.02 * float(np.mean(m))
    data["flux"] = m + sigma * np.random.default_rng(seed).normal(size=m.size)
    data["sigma"] = np.full(m.size, sigma)
    return Problem(data, geo, kern, k, "band")


def benchmark_spin_bound(
    n_candidates: Sequence[int] = (10_000, 100_000, 1_500_000),
    n_axes: int = 100,
    n_phases: int = 16,
    n_samples: int = 80,
    bands: Sequence[str] = ("V", "R", "I"),
    n_angles: int = 720,
    direct_up_to: int = 100_000,
    n_threads: int | None = None,
    spacecraft: Any = None,
) -> list[dict[str, Any]]:
    """Wall time of the branch-and-bound spin search against the exact ``direct`` one.

    A synthetic light curve (a 30 s spin about body z with 2 % noise, ``n_samples`` times
    over 300 s in each band, the observer moving through 60 degrees); the candidates are
    ``n_axes`` Fibonacci axes x periods from 20 to 40 s x ``n_phases`` phases (the periods
    fill ``n``).  ``bound`` runs every size; ``direct`` those up to ``direct_up_to``, and
    its time at a larger size is extrapolated from the largest measured rate (``measured``
    False).  Rows: ``method``, ``candidates``, ``samples``, ``bands``, ``seconds``,
    ``states_per_second``, ``measured``, ``n_exact`` (candidates through the kernel),
    ``chi2``, ``same_best`` (the bound's best state and chi-square equal the direct
    one's, to 1e-9, where both ran) and ``ratio`` (direct seconds over bound seconds).

    Examples
    --------
    A box of the catalog's Lambertian grey, 2 axes x 5 periods x 8 phases on 20 times in V
    (the default body is CanX-1 with its measured tables, which take seconds to build):

    >>> import trimesh
    >>> from sbrdf_xr import load_spacecraft
    >>> from sbrdf_xr.invert import benchmark_spin_bound
    >>> box = load_spacecraft(trimesh.creation.box(extents=(1.0, 2.0, 3.0)),
    ...                       material="lambertian-grey-50")
    >>> rows = benchmark_spin_bound(n_candidates=(80,), n_axes=2, n_phases=8, n_samples=20,
    ...                             bands=("V",), n_angles=64, n_threads=1, spacecraft=box)
    >>> [(r["method"], r["candidates"], r["measured"]) for r in rows]
    [('bound', 80, True), ('direct', 80, True)]
    >>> rows[0]["same_best"]
    True
    """
    from ...body.spacecraft import canx1
    from .bound import search_bound

    sc = spacecraft if spacecraft is not None else canx1()
    prob = _spin_problem(sc, bands, n_samples, 0)
    axes = fibonacci_sphere(n_axes)
    phases = np.arange(n_phases) * 360.0 / n_phases
    warm = np.array([25.0, 30.0])
    search_bound(prob, axes[:2], warm, phases[:2], n_threads, n_angles)  # compile
    run_search("direct", prob, axes[:2], warm[:1], phases[:1], n_threads, n_angles)
    rows: list[dict[str, Any]] = []
    rate = None
    for n in n_candidates:
        periods = np.linspace(20.0, 40.0, max(1, -(-int(n) // (n_axes * n_phases))))
        nc = n_axes * periods.size * n_phases
        t0 = time.perf_counter()
        found = search_bound(prob, axes, periods, phases, n_threads, n_angles)
        tb = time.perf_counter() - t0
        row = {"method": "bound", "candidates": nc, "samples": n_samples, "bands": len(bands)}
        row.update(seconds=tb, states_per_second=nc / tb, measured=True)
        row.update(n_exact=found.n_exact, chi2=float(found.grid.min()), same_best=None)
        if int(n) <= direct_up_to:
            t0 = time.perf_counter()
            grid = run_search("direct", prob, axes, periods, phases, n_threads, n_angles)
            td = time.perf_counter() - t0
            rate = nc / td
            same = int(np.argmin(grid)) == int(np.argmin(found.grid)) and bool(
                abs(grid.min() - found.grid.min()) <= 1e-9 * grid.min()
            )
            row["same_best"] = same
            direct: dict[str, Any] | None = {
                "seconds": td,
                "measured": True,
                "n_exact": nc,
                "chi2": float(grid.min()),
            }
        elif rate is not None:
            direct = {"seconds": nc / rate, "measured": False, "n_exact": nc, "chi2": None}
        else:
            direct = None
        rows.append(row)
        if direct is not None:
            row["ratio"] = direct["seconds"] / tb
            rows.append(
                {
                    "method": "direct",
                    "candidates": nc,
                    "samples": n_samples,
                    "bands": len(bands),
                    **direct,
                    "states_per_second": nc / direct["seconds"],
                    "same_best": row["same_best"],
                }
            )
    return rows
