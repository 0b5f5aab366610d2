"""Spin-state fit: global search over candidate spin states and local refinement.

See the package docstring and :func:`fit_spin`.  The model, its chi-square and the grid
searches are in :mod:`sbrdf_xr.invert._spin.search`; refinement and the ambiguous twins in
:mod:`sbrdf_xr.invert._spin.refine`; the result Dataset in :mod:`sbrdf_xr.invert._spin.result`.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from ...errors import FitQualityWarning, InversionError, renamed_keywords
from ...units import to_unit
from .._quality import fit_quality
from .data import band_factors, light_curve_fluxes, spin_geometry
from .refine import Minimum, axis_angle, exact_minimum, symmetry_twins, twins
from .refine import refine as refine_state
from .result import result_dataset
from .search import (
    METHODS,
    Kernel,
    Problem,
    approximation_error,
    fibonacci_sphere,
    run_search,
    vec,
)

__all__ = [
    "AMBIGUITY_CHI2",
    "SEARCH_BYTES_LIMIT",
    "SEARCH_WORK_LIMIT",
    "axis_separation",
    "axis_vector",
    "check_search_size",
    "fit_spin",
    "period_grid",
    "search_size",
]

#: Spin searches whose chi-square grid and working memory would exceed this many bytes are
#: refused (raise with ``size_limit``, a factor).
SEARCH_BYTES_LIMIT = 2 * 2**30
#: Spin searches that would compute more model values than this (candidates x values, or
#: table entries) are refused, about a day on two cores (raise with ``size_limit``).
SEARCH_WORK_LIMIT = 1e11

#: A twin whose chi-square exceeds the solution's by less than this fits about as well (a
#: likelihood ratio above exp(-4.5) = 1.1 %): the fit warns that the solution is ambiguous.
AMBIGUITY_CHI2 = 9.0

#: Grid searches of :func:`fit_spin`: those of ``run_search`` and the branch and bound.
SEARCHES = (*METHODS, "bound")
#: Cost of a kernel geometry and of one interpolated model value, relative (for ``auto``).
_COST_KERNEL, _COST_GATHER = 1.0, 0.03

SPIN_CAUSES = (
    "the period lies outside the searched range, or the grid is too coarse for the time span "
    "(the search stopped in a local minimum: see local_minimum_chi2 and chi2_map)",
    "the attitude is not a uniform spin about axis_body (a tumble, another body axis, a "
    "changing rate)",
    "the spacecraft model (mesh, materials) does not describe the object",
    "the geometry (times, site, orbit) does not match the measurement, or effects the model "
    "leaves out matter (atmospheric extinction, earthshine, self-shadowing)",
    "the uncertainties are understated",
)


def search_size(
    n_axes: int,
    n_periods: int,
    n_phases: int,
    n_times: int,
    n_bands: int,
    n_values: int,
    method: str,
    n_angles: int = 360,
    n_threads: int = 1,
) -> dict[str, float]:
    """Memory [byte] and work (model values computed) of a spin search, before any allocation.

    Examples
    --------
    300 axes x 1e12 periods x 36 phases: the chi-square grid alone is 86 PB.

    >>> from sbrdf_xr.invert import search_size
    >>> size = search_size(300, 10**12, 36, 240, 3, 720, "direct")
    >>> f"{size['bytes']:.3g}", f"{size['work']:.3g}"
    ('8.64e+16', '7.78e+18')
    """
    cells = float(n_axes) * float(n_periods) * float(n_phases)
    grid = 8.0 * cells + 8.0 * n_axes
    if method == "direct":
        working = 8.0 * n_times * (6 + 2 * n_bands) + 32.0 * n_values
        work = cells * n_values
        geometries = cells * n_times
    elif method == "bound":
        from .bound import bound_angles

        grid = 25.0 * cells + 8.0 * n_axes  # chi-square, bound, approximation, flag
        n = bound_angles(n_angles)
        working = 8.0 * n_times * n * (2 * n_bands + 12)
        work = float(n_axes) * n_times * n * n_bands + cells * n_values
        geometries = float(n_axes) * n_times * n
    else:
        rows = 1 if method == "shift" else n_times
        working = 8.0 * rows * n_angles * (n_bands + 12) + 96.0 * n_phases * n_values
        work = float(n_axes) * rows * n_angles * n_bands + cells * n_values
        geometries = float(n_axes) * rows * n_angles
    return {
        "bytes": grid + max(1, n_threads) * working,
        "work": work,
        "cells": cells,
        "geometries": geometries,
    }


def _check_size(size: dict[str, float], what: str, size_limit: float) -> None:
    from ...engine.stages import describe_bytes

    lim_b, lim_w = size_limit * SEARCH_BYTES_LIMIT, size_limit * SEARCH_WORK_LIMIT
    if size["bytes"] > lim_b or size["work"] > lim_w:
        raise InversionError(
            f"spin search of {what} is beyond reason: it needs {describe_bytes(size['bytes'])} "
            f"(limit {describe_bytes(lim_b)}) and {size['work']:.3g} model values (limit "
            f"{lim_w:.3g}); reduce the periods (--periods MIN MAX N), --n-axes or --n-phases, "
            "or raise the limits with size_limit (--size-limit, a factor, default 1) if you "
            "mean it"
        )


def check_search_size(
    n_axes: int,
    n_periods: int,
    n_phases: int,
    n_times: int,
    n_bands: int,
    n_values: int,
    size_limit: float = 1.0,
    n_angles: int = 360,
) -> None:
    """Refuse a spin search whose every method would exceed the limits, before anything
    is allocated (:func:`search_size`; the limits times ``size_limit``).

    Raises
    ------
    InversionError
        With the estimate, the limits and the options that reduce or raise them.

    Examples
    --------
    >>> from sbrdf_xr.invert import check_search_size
    >>> check_search_size(300, 21, 36, 240, 3, 720)  # about 2 MB: fine
    >>> check_search_size(300, 10**12, 36, 240, 3, 720)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.InversionError: spin search of 300 axes x 1e+12 periods ... 8.64e+04 TB ...
    """
    if not (isinstance(size_limit, int | float) and np.isfinite(size_limit) and size_limit > 0):
        raise InversionError(
            f"size_limit (--size-limit): {size_limit!r}; allowed a finite number > 0"
        )
    sizes = [
        search_size(n_axes, n_periods, n_phases, n_times, n_bands, n_values, m, n_angles)
        for m in ("direct", "table")
    ]
    least = min(sizes, key=lambda z: (z["bytes"] > SEARCH_BYTES_LIMIT * size_limit, z["work"]))
    what = (
        f"{n_axes} axes x {n_periods:.4g} periods x {n_phases} phases x {n_times} times x "
        f"{n_bands} bands"
    )
    _check_size(least, what, size_limit)


def _positive_int(value: Any, name: str, low: int = 1) -> int:
    try:
        ok = float(value) == int(value) and int(value) >= low
    except (TypeError, ValueError, OverflowError):
        ok = False
    if not ok:
        raise InversionError(f"{name}: {value!r}; allowed an integer >= {low}")
    return int(value)


def _chain(
    method: str, fixed: bool, size: dict[str, dict[str, float]], n_times: int, n_values: int
) -> list[str]:
    """The searches to try in turn: an approximation first where it is cheaper, then exact."""
    if method in ("direct", "bound"):
        return [method]
    if method == "table":
        return ["table", "direct"]
    if method == "shift":
        return ["shift", "direct"] if fixed else ["shift", "table", "direct"]
    if fixed:
        return ["shift", "direct"]

    def cost(m: str) -> float:  # kernel geometries (every band at once) and table reads
        gather = 0.0 if m == "direct" else size[m]["cells"] * n_values * _COST_GATHER
        return size[m]["geometries"] * _COST_KERNEL + gather

    return ["bound"] if cost("bound") < cost("direct") else ["direct"]


def fit_spin(
    light_curve: xr.Dataset,
    spacecraft: Any,
    geometry: Any = None,
    *,
    to_sun: ArrayLike | None = None,
    to_observer: ArrayLike | None = None,
    periods: ArrayLike,
    axis_body: ArrayLike = (0.0, 0.0, 1.0),
    n_axes: int = 120,
    n_phases: int = 16,
    search_times: int = 80,
    offset: str = "band",
    materials: Mapping[str, xr.DataArray] | None = None,
    refine: bool = True,
    n_starts: int = 8,
    method: str = "auto",
    n_angles: int = 360,
    tolerance: float = 0.3,
    size_limit: float = 1.0,
    n_threads: int | None = None,
) -> xr.Dataset:
    """Spin axis, period and phase of a uniform spin fitted to a colour light curve.

    The model: the body turns about its ``axis_body`` (a principal axis, the spin being
    torque-free) at ``360/P`` degree s-1; ``axis_body`` points to the inertial direction
    (``axis_longitude``, ``axis_latitude``) of the frame of the geometry (the GCRS for an
    observation); the spin angle is ``phase`` at the ``epoch``.  The predicted flux of band
    b at time t is ``k_b S_b(t) f(t)``, with ``S_b`` the band signal of the compiled
    kernel, ``f`` the sunlit fraction times ``(r_ref / range)**2`` (an observation) or 1,
    and ``k_b`` (one per band, or one for all with ``offset="common"``) solved in closed
    form for every candidate.

    Search: ``n_axes`` Fibonacci-sphere axes x ``periods`` x ``n_phases`` phases (the
    phase at the middle of the light curve); ``method`` evaluates the grid exactly
    (``direct``) or from spin-angle tables (``table``: exact geometry at every time,
    ``shift``: the mean geometry), an approximation being used only when its model error
    at the best and at random candidates is below ``tolerance`` times the noise (rms over
    the values), else the next search is run (``shift`` -> ``table`` -> ``direct``);
    ``bound`` reads every candidate from per-axis spin-angle tables with an error
    estimate that gives it a lower bound of its chi-square, and evaluates exactly only the
    candidates that can still beat the best state of the ``n_starts`` best axes: those
    states are the ``direct`` search's (while the estimate holds), the tables'
    approximation elsewhere in ``chi2_map``; ``auto`` takes ``bound`` where its tables cost
    less than ``direct`` (``shift`` first at fixed directions).  Then
    :func:`scipy.optimize.least_squares` from the best grid state of each of the
    ``n_starts`` best axes, with the exact model.  The reported
    solution is the lowest chi-square found; its twins (antipode, mirror, half and double
    period) are searched in phase and refined too, and any twin that fits better becomes
    the solution.

    The period grid must be fine enough that the phase slips by less than a phase step
    over half the time span ``T``: ``dP <~ 2 P**2 / (n_phases T)``.

    Parameters
    ----------
    light_curve : Dataset
        :func:`sbrdf_xr.lightcurves.read_light_curve` output (magnitudes) or the same with
        ``flux`` and ``flux_uncertainty``; times UTC (datetime64) or seconds.
    spacecraft : Spacecraft
        The body (its materials from the catalog unless ``materials``).
    geometry : Observation or Dataset, optional
        An :class:`sbrdf_xr.observing.Observation` (recomputed at the measured times), or
        a cube over ``time`` with body-frame ``to_sun``, ``to_observer`` and
        ``quaternion`` (``simulate`` of an observation, or ``Observation.geometry()``),
        interpolated to them.  Measured times in seconds count from its first time, the
        ``epoch``.  Instead, ``to_sun`` and ``to_observer`` may be given.
    to_sun, to_observer : array_like, shape (3,) or (n_times, 3), optional
        Inertial directions from the spacecraft to the Sun and to the observer, fixed or
        one per distinct time (sorted).
    periods : array_like
        Candidate spin periods [s]; a Quantity is converted.
    axis_body : array_like, shape (3,)
        The body axis the spacecraft spins about (nonzero).
    n_axes, n_phases : int
        Search grid sizes.
    search_times : int
        The grid is evaluated on at most this many distinct times, spread evenly over the
        light curve (all the values at those times; the exact model): the chi-square of
        that subset of the data ranks the candidates, the refinements use every value.
    offset : {"band", "common"}
        A free flux scale per band, or one for all bands.  With one, the model's band
        colours are put in the light curve's magnitude system (its ``magnitude_system``
        attribute, AB or Vega; refused when unstated): the band signal times
        ``10**(-0.4 m_sun,b)``, the Sun's magnitude in each band.  Fluxes (``flux``) are
        taken as proportional to the band signal (the reflected band flux over the Sun's).
    refine : bool
        Refine the best candidates by least squares (else the grid's best, unrefined).
    n_starts : int
        Refinements started from the best grid state of the ``n_starts`` best axes.
    method : {"auto", "direct", "table", "shift", "bound"}
        Grid evaluation (see above).
    n_angles : int
        Spin angles of the ``table`` and ``shift`` searches.
    tolerance : float
        Largest rms model error of an approximate search, in units of the noise.
    size_limit : float
        Factor on :data:`SEARCH_BYTES_LIMIT` and :data:`SEARCH_WORK_LIMIT`.
    n_threads : int, optional
        Threads of the search (default: every core).

    Returns
    -------
    xarray.Dataset
        Scalars ``axis_longitude``, ``axis_latitude`` [degree], ``period`` [s], ``phase``
        [degree] with ``*_uncertainty``, ``axis_uncertainty`` [degree] (the major
        semi-axis of the axis's 1-sigma ellipse), ``chi2``, ``reduced_chi_square``,
        ``fit_probability``; ``chi2_map`` over ``axis``; the twins over ``solution`` with
        their ``chi2_gap``; the refined local minima over ``minimum``; attributes
        ``search_method`` (what was used), ``search_method_requested``, ``search_check``,
        ``epoch``, ``geometry_source``, ``fit_quality``.

    Warns
    -----
    FitQualityWarning
        When the chi-square lies beyond the 99.9 % point of its distribution (or below its
        0.1 % point), naming the likely causes; or when a twin (another axis or period)
        fits about as well as the solution (chi-square gap below :data:`AMBIGUITY_CHI2`),
        naming it (also in ``attrs["ambiguity"]``).

    Raises
    ------
    InversionError
        Bad light curve or geometry, fewer values than parameters, bad grid sizes, or a
        search beyond the size limits.

    Examples
    --------
    A 1 x 2 x 3 m box of the catalog's Lambertian grey spinning about its long axis with
    a period of 20 s, seen in V and R for 40 s at 30 deg phase with 1 % noise; a search
    over 30 axes x 11 periods x 12 phases (at fixed directions, by spin-angle tables
    checked against the exact model) and two refinements find the period.  A box at a
    fixed geometry cannot tell its axis from the antipode or the mirror twin, and the fit
    says so:

    >>> import warnings
    >>> import numpy as np, trimesh, xarray as xr
    >>> from sbrdf_xr import Scene, geometry, load_spacecraft, simulate
    >>> from sbrdf_xr.invert import axis_vector, fit_spin, spin_model
    >>> box = load_spacecraft(trimesh.creation.box(extents=(1.0, 2.0, 3.0)),
    ...                       material="lambertian-grey-50")
    >>> spin = spin_model([0, 0, 1], axis_vector(60.0, 30.0), period=20.0, phase=30.0)
    >>> t = np.arange(0.0, 40.0, 1.0)
    >>> scene = Scene(box, attitudes=spin.quaternions(t), phase_angles=[30.0],
    ...               outputs=("band_signal",), bands=("V", "R"))
    >>> flux = simulate(scene).band_signal.isel(phase_angle=0).values.ravel()  # (time, band)
    >>> noisy = flux * (1 + 0.01 * np.random.default_rng(0).normal(size=flux.size))
    >>> lc = xr.Dataset(
    ...     {"flux": ("obs", noisy), "flux_uncertainty": ("obs", 0.01 * flux)},
    ...     coords={"time": ("obs", np.repeat(t, 2)), "band": ("obs", ["V", "R"] * t.size)},
    ... )
    >>> to_sun, to_observer = geometry.observation_plane([30.0], (1, 0, 0), (0, 0, 1))
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     fit = fit_spin(lc, box, to_sun=to_sun[0], to_observer=to_observer[0],
    ...                    periods=np.linspace(15.0, 25.0, 11), n_axes=30, n_phases=12,
    ...                    n_starts=2, n_threads=1)
    >>> round(float(fit.period), 2), fit.attrs["n_candidates"], fit.attrs["search_method"]
    (19.99, 3960, 'shift')
    >>> fit.attrs["fit_quality"], bool(fit.chi2_gap.min() >= 0)
    ('consistent', True)
    >>> [w.category.__name__ for w in caught], fit.attrs["ambiguity"][:48]
    (['FitQualityWarning'], 'the data do not tell the solution from its twins')
    """
    periods = to_unit(periods, "s", "periods")
    t_start = time.perf_counter()
    if method not in ("auto", *SEARCHES):
        raise InversionError(
            f"method: {method!r}; allowed 'auto', {', '.join(map(repr, SEARCHES))}"
        )
    n_axes = _positive_int(n_axes, "n_axes (--n-axes)")
    n_phases = _positive_int(n_phases, "n_phases (--n-phases)")
    n_starts = _positive_int(n_starts, "n_starts")
    search_times = _positive_int(search_times, "search_times", low=2)
    n_angles = _positive_int(n_angles, "n_angles", low=8)
    for name, val in (("tolerance", tolerance), ("size_limit (--size-limit)", size_limit)):
        if not (isinstance(val, int | float) and np.isfinite(val) and val > 0):
            raise InversionError(f"{name}: {val!r}; allowed a finite number > 0")
    ab = np.asarray(axis_body, dtype=np.float64)
    if ab.shape != (3,) or not np.all(np.isfinite(ab)) or np.linalg.norm(ab) == 0:
        raise InversionError(
            f"axis_body (--axis-body): {np.asarray(axis_body).tolist()!r}; allowed a finite "
            "nonzero body vector of three components, e.g. 0 0 1"
        )
    per = np.atleast_1d(np.asarray(periods, dtype=np.float64))
    if per.ndim != 1 or per.size == 0 or not np.all(np.isfinite(per) & (per > 0)):
        raise InversionError(
            f"periods (--periods): must be a non-empty list of finite values > 0 [s], got "
            f"{per.size} values" + (f" from {per.min():g} to {per.max():g}" if per.size else "")
        )
    if offset not in ("band", "common"):
        raise InversionError(f"offset (--offset): {offset!r}; allowed 'band', 'common'")
    lc = light_curve_fluxes(light_curve)
    geo = spin_geometry(lc["time"], geometry, to_sun, to_observer)
    n_par = 4 + (1 if offset == "common" else len(lc["labels"]))
    if lc["flux"].size <= n_par:
        raise InversionError(
            f"light curve: {lc['flux'].size} values for {n_par} parameters (axis, period, "
            "phase and the flux scales); need more values than parameters"
        )
    n_search = min(search_times, geo.times.size)
    n_search_values = round(lc["flux"].size * n_search / geo.times.size)
    sizes = {
        m: search_size(
            n_axes,
            per.size,
            n_phases,
            n_search,
            len(lc["labels"]),
            n_search_values,
            m,
            n_angles,
            1 if n_threads is None else n_threads,
        )
        for m in SEARCHES
    }
    what = (
        f"{n_axes} axes x {per.size:.4g} periods x {n_phases} phases x {n_search} times x "
        f"{len(lc['labels'])} bands"
    )
    fixed = bool(
        np.allclose(geo.to_sun, geo.to_sun[0]) and np.allclose(geo.to_observer, geo.to_observer[0])
    )
    chain = _chain(method, fixed, sizes, n_search, n_search_values)
    _check_size(sizes[chain[0]], what, size_limit)  # before the kernel or any allocation
    factors, offset_note = band_factors(light_curve, list(lc["labels"]), offset)
    kern = Kernel(spacecraft, list(lc["labels"]), materials, band_factors=factors)
    prob = Problem(lc, geo, kern, ab, offset)
    grid_prob = prob.subset(n_search)
    axes = fibonacci_sphere(n_axes)
    phases = np.arange(n_phases) * 360.0 / n_phases
    t0 = time.perf_counter()
    checks: list[str] = []
    for used in chain:
        _check_size(sizes[used], what, size_limit)
        if used == "bound":
            grid, note = _bound_grid(grid_prob, axes, per, phases, n_threads, n_angles, n_starts)
            checks.append(note)
            break
        grid = run_search(used, grid_prob, axes, per, phases, n_threads, n_angles)
        if used == "direct":
            break
        err = approximation_error(
            used, grid_prob, axes, _check_cells(grid, per, phases, n_starts), n_angles
        )
        ok = err <= tolerance
        checks.append(
            f"{used} ({n_angles} spin angles): rms model error {err:.3g} sigma at the best and "
            f"at random candidates, {'within' if ok else 'beyond'} the tolerance {tolerance:g}"
        )
        if ok:
            break
    if checks and used != chain[0]:
        checks.append(f"the {used} search was run instead")
    t_search = time.perf_counter() - t0
    best, minima, alts = _solve(prob, axes, grid, per, phases, n_starts, n_phases, refine)
    dof = prob.y.size - n_par
    quality = fit_quality(best.chi2, dof, "spin fit", SPIN_CAUSES)
    ds = result_dataset(
        prob=prob,
        geo=geo,
        best=best,
        alts=alts,
        minima=minima,
        axes=axes,
        grid=grid,
        quality=quality,
        dof=dof,
        attrs={
            "axis_body": str(ab.tolist()),
            "offset": offset,
            "offset_note": offset_note,
            "n_candidates": int(grid.size),
            "search_times": (
                f"the grid ranked candidates by the chi-square of the values at {n_search} of "
                f"the {geo.times.size} distinct times (spread evenly); the refinements used all"
            ),
            "search_seconds": t_search,
            "fit_seconds": time.perf_counter() - t_start,
            "search_method": used,
            "search_method_requested": method,
            "search_check": "; ".join(checks) if checks else "exact search, nothing to check",
            "fixed_directions": int(prob.fixed),
            "n_values": int(prob.y.size),
            "bands": ", ".join(lc["labels"]),
        },
    )
    ds.attrs["ambiguity"] = _ambiguity(ds)
    if ds.attrs["ambiguity"] != "none":
        warnings.warn(f"spin fit: {ds.attrs['ambiguity']}", FitQualityWarning, stacklevel=2)
    ds.attrs["symmetry_twins"] = symmetry_twins(prob, best, ab)
    return ds


def _bound_grid(
    prob: Problem,
    axes: np.ndarray,
    periods: np.ndarray,
    phases: np.ndarray,
    n_threads: int | None,
    n_angles: int,
    n_starts: int,
) -> tuple[np.ndarray, str]:
    """The grid by branch and bound, exact at the best state of the ``n_starts`` best axes
    (where the refinements start), and what it did."""
    from .bound import SAFETY, bound_angles, search_bound

    n = bound_angles(n_angles)
    res = search_bound(prob, axes, periods, phases, n_threads, n, n_best=n_starts)
    note = (
        f"bound ({n} spin angles, error estimate {SAFETY:g} x the coarse tables' midpoint "
        f"error): {res.n_exact} of {res.grid.size} candidates evaluated exactly, every other "
        f"one's lower bound above the {min(n_starts, len(axes))}-th best axis's chi-square "
        f"{res.threshold:.6g}; the best states are the direct search's, the chi2_map of the "
        "other axes the tables' approximation"
    )
    return res.grid, note


def _ambiguity(ds: xr.Dataset) -> str:
    """The twins that fit about as well as the solution (chi-square gap below
    :data:`AMBIGUITY_CHI2`) and are other solutions (another axis or period)."""
    rows = []
    for name in ds["solution"].values:
        row = ds.sel(solution=name)
        sep = float(row["solution_axis_separation"])
        dper = abs(float(row["solution_period"]) - float(ds["period"]))
        other = sep > 1.0 or dper > 3 * max(float(ds["period_uncertainty"]), 1e-9 * dper)
        if float(row["chi2_gap"]) < AMBIGUITY_CHI2 and other:
            rows.append(
                f"{name} (axis {sep:.1f} deg away, period {float(row['solution_period']):.6g} s, "
                f"chi2 gap {float(row['chi2_gap']):.3g})"
            )
    if not rows:
        return "none"
    return (
        f"the data do not tell the solution from its twins {'; '.join(rows)}: they fit about "
        f"as well (chi2 gap < {AMBIGUITY_CHI2:g}); the stated uncertainties describe the "
        "neighbourhood of one solution only. More change of geometry (a longer pass, another "
        "pass or site) tells them apart"
    )


def _check_cells(
    grid: np.ndarray, periods: np.ndarray, phases: np.ndarray, n_best: int, n_random: int = 4
) -> list[tuple[int, float, float]]:
    """Candidates where an approximate search is checked: the best cell of each of the
    ``n_best`` best axes, and ``n_random`` cells drawn with a fixed seed."""
    flat = grid.reshape(grid.shape[0], -1)
    out = []
    for i in np.argsort(flat.min(axis=1))[:n_best]:
        jp, jq = np.unravel_index(int(np.argmin(flat[i])), grid.shape[1:])
        out.append((int(i), float(periods[jp]), float(phases[jq])))
    rng = np.random.default_rng(0)
    for c in rng.integers(0, grid.size, n_random):
        ia, jp, jq = np.unravel_index(int(c), grid.shape)
        out.append((int(ia), float(periods[jp]), float(phases[jq])))
    return out


def _solve(
    prob: Problem,
    axes: np.ndarray,
    grid: np.ndarray,
    periods: np.ndarray,
    phases: np.ndarray,
    n_starts: int,
    n_phases: int,
    do_refine: bool,
) -> tuple[Minimum, list[Minimum], list[Minimum]]:
    """The lowest chi-square over the refined starts and the twins (which may replace it)."""
    starts = _check_cells(grid, periods, phases, n_starts, n_random=0)
    if not do_refine:
        ia, per, ph = starts[0]
        best = exact_minimum(prob, axes[ia], per, np.array([ph]), "grid")
        return best, [best], twins(prob, best, n_phases, False)
    minima = [
        refine_state(prob, axes[ia], per, ph, f"start {j}")
        for j, (ia, per, ph) in enumerate(starts)
    ]
    best = min(minima, key=lambda m: m.chi2)
    for _ in range(6):  # a twin that fits better becomes the solution, and has its own twins
        alts = twins(prob, best, n_phases, True)
        minima.extend(alts)
        lowest = min(minima, key=lambda m: m.chi2)
        if lowest.chi2 >= best.chi2 - 1e-9 * max(1.0, best.chi2):
            break
        best = lowest
    best = min([best, *minima], key=lambda m: m.chi2)  # the lowest found, whatever the loop did
    return best, minima, alts


@renamed_keywords(span_s="span")
def period_grid(p_min: float, p_max: float, span: float, n_phases: int = 16) -> np.ndarray:
    """Candidate periods [s] from ``p_min`` to (at least) ``p_max``, spaced so that over a
    light curve of ``span`` seconds the phase slips by at most half a phase step of a
    ``n_phases`` grid between neighbours: ``dP = P**2 / (n_phases span)`` (the search
    defines the phase at the middle of the light curve), growing with ``P``.

    Parameters
    ----------
    p_min, p_max : float
        The range of periods [s].
    span : float
        Time span of the light curve [s].
    n_phases : int
        Phases of the search grid.

    A Quantity is converted.

    Examples
    --------
    >>> from sbrdf_xr.invert import period_grid
    >>> grid = period_grid(60.0, 70.0, 240.0)
    >>> grid.size, grid[:3].round(3).tolist()
    (11, [60.0, 60.938, 61.905])
    """
    p_min, p_max = to_unit(p_min, "s", "p_min"), to_unit(p_max, "s", "p_max")
    span = to_unit(span, "s", "span")
    if not (0 < p_min <= p_max and np.isfinite(p_max) and span > 0 and n_phases >= 1):
        raise InversionError(
            f"period_grid: need 0 < p_min <= p_max, span > 0 and n_phases >= 1, got "
            f"{p_min!r}, {p_max!r}, {span!r}, {n_phases!r}"
        )
    out = [float(p_min)]
    while out[-1] < p_max:
        if len(out) > 10**6:
            raise InversionError("period_grid: more than 1e6 periods; narrow the range")
        out.append(out[-1] + out[-1] ** 2 / (n_phases * span))
    return np.array(out)


def axis_vector(longitude: ArrayLike, latitude: ArrayLike) -> np.ndarray:
    """Unit vector(s) of an axis at ``longitude``, ``latitude`` [degree], shape (..., 3).

    Parameters
    ----------
    longitude, latitude : array_like
        Direction of the axis [degree] (a Quantity is converted), broadcast together.

    Examples
    --------
    >>> from sbrdf_xr.invert import axis_vector
    >>> axis_vector(90.0, 0.0).round(6).tolist()
    [0.0, 1.0, 0.0]
    >>> axis_vector([0.0, 0.0], [0.0, 90.0]).round(6).tolist()
    [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    """
    lon = np.asarray(to_unit(longitude, "deg", "longitude"), dtype=np.float64)
    return vec(lon, np.asarray(to_unit(latitude, "deg", "latitude"), dtype=np.float64))


def axis_separation(a: ArrayLike, b: ArrayLike) -> float:
    """Angle between two unit vectors [degree].

    Examples
    --------
    >>> from sbrdf_xr.invert import axis_separation
    >>> axis_separation([1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    90.0
    """
    return axis_angle(np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64))
