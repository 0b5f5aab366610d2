"""Timing of the spin-state search."""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

import numpy as np
import xarray as xr

from .data import light_curve_fluxes, spin_geometry
from .search import Kernel, Problem, fibonacci_sphere, run_search

__all__ = ["benchmark_spin_search"]


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
