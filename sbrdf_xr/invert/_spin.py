"""Spin-state fit: global search over candidate spin states and local refinement.

See the package docstring.

The model, its chi-square and the grid search are in :mod:`sbrdf_xr.invert._spin_search`.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike
from scipy.optimize import least_squares

from ..errors import InversionError
from ._spin_search import (
    Kernel,
    Problem,
    fibonacci_sphere,
    light_curve_fluxes,
    lonlat,
    search,
    search_shift,
    vec,
)

__all__ = ["axis_separation", "axis_vector", "fit_spin"]


# ------------------------------------------------------------------------------ spin fit


def _refine(prob: Problem, p0: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Local least squares from ``p0`` (lon, lat, period, phase); parameters, sigma, chi2."""
    span = max(float(np.ptp(prob.times)), 1e-9)
    xs = np.array([1.0, 1.0, p0[2] ** 2 / (360.0 * span), 1.0])
    res = least_squares(
        prob.residuals, p0, x_scale=xs, diff_step=1e-6, method="lm" if prob.y.size > 4 else "trf"
    )
    j = res.jac
    try:
        cov = np.linalg.inv(j.T @ j)
        sig = np.sqrt(np.clip(np.diag(cov), 0, None))
    except np.linalg.LinAlgError:
        sig = np.full(4, np.inf)
    p = res.x.copy()
    if abs(p[1]) > 90:  # latitude past a pole: the same axis
        v = vec(p[0], p[1])
        p[0], p[1] = lonlat(v)
    p[0] %= 360.0
    p[3] %= 360.0
    return p, sig, float(2 * res.cost)


def _alternatives(
    prob: Problem, best: np.ndarray, n_phases: int, refine: bool
) -> dict[str, tuple[np.ndarray, Any, float]]:
    """The classical ambiguous solutions of a spin state, each searched in phase and refined.

    ``antipode``: the opposite axis (the reversed sense of rotation); ``mirror``: the axial
    vector mirrored through the mean scattering plane (the plane of the Sun and observer
    directions), ``-M n``, which for a body equal to its mirror image and fixed directions
    gives the same light curve (Kaasalainen & Lamberg 2006, Inverse Problems 22, 749);
    ``half_period`` and ``double_period``.
    """
    axis = vec(best[0], best[1])
    nplane = np.cross(prob.s.mean(0), prob.o.mean(0))
    nplane = (
        nplane / np.linalg.norm(nplane) if np.linalg.norm(nplane) > 1e-9 else np.array([0.0, 0, 1])
    )
    mirror = -(axis - 2 * np.dot(axis, nplane) * nplane)
    alts = {
        "antipode": (-axis, best[2]),
        "mirror": (mirror, best[2]),
        "half_period": (axis, best[2] / 2),
        "double_period": (axis, best[2] * 2),
    }
    dense = np.arange(4 * int(n_phases)) * 90.0 / int(n_phases)
    out = {}
    for name, (ax, per) in alts.items():
        c2 = prob.chi2(np.repeat(ax[None, :], dense.size, 0), np.full(dense.size, per), dense)
        lo, la = lonlat(ax)
        q0 = np.array([lo, la, per, dense[np.argmin(c2)]])
        out[name] = _refine(prob, q0) if refine else (q0, None, float(c2.min()))
    return out


def _axis_angle(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.degrees(np.arccos(np.clip(np.dot(a, b), -1, 1))))


def fit_spin(
    light_curve: xr.Dataset,
    spacecraft: Any,
    *,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    periods: ArrayLike,
    axis_body: ArrayLike = (0.0, 0.0, 1.0),
    n_axes: int = 300,
    n_phases: int = 36,
    offset: str = "band",
    materials: Mapping[str, xr.DataArray] | None = None,
    refine: bool = True,
    n_starts: int = 5,
    method: str = "shift",
    n_threads: int | None = None,
) -> xr.Dataset:
    """Spin axis, period and phase of a uniform spin fitted to a colour light curve.

    The model (:func:`spin_model`): the body turns about its ``axis_body`` (a principal
    axis, the spin being torque-free) at ``360/P`` degree s-1; ``axis_body`` points to the
    inertial direction (``axis_longitude``, ``axis_latitude``) of the frame of
    ``to_sun``/``to_observer``; the spin angle is ``phase`` at t = 0.  The predicted flux of
    band b is ``k_b S_b(t)`` with ``S_b`` the band signal of the compiled kernel and
    ``k_b`` (one per band, or one for all with ``offset="common"``) solved in closed form
    for every candidate.  Search: ``n_axes`` Fibonacci-sphere axes x ``periods`` x
    ``n_phases`` phases; then :func:`scipy.optimize.least_squares` from the best
    candidate (and from the alternative solutions below).

    The period grid must be fine enough that the phase slips by less than a phase step over
    the time span ``T``: ``dP <~ P**2 / (n_phases T)``.

    Parameters
    ----------
    light_curve : Dataset
        :func:`sbrdf_xr.photometry.read_light_curve` output (magnitudes) or the same with
        ``flux`` and ``flux_uncertainty``; times [s].
    spacecraft : Spacecraft
        The body (its materials from the catalog unless ``materials``).
    to_sun, to_observer : array_like, shape (3,) or (n_times, 3)
        Inertial directions from the spacecraft to the Sun and to the observer, fixed or
        one per distinct time (sorted).
    periods : array_like
        Candidate spin periods [s].
    axis_body : array_like, shape (3,)
        The body axis the spacecraft spins about.
    n_axes, n_phases : int
        Search grid sizes.
    offset : {"band", "common"}
        A free flux scale per band, or one for all bands (then the fluxes must be on one
        physical scale, e.g. magnitudes in one system).
    refine : bool
        Refine the best candidates by least squares.
    n_starts : int
        Refinements started from the best grid state of the ``n_starts`` best axes.
    method : {"shift", "direct"}
        Search: ``shift`` evaluates the kernel once per axis on a dense spin-angle grid
        (0.5 degree) and reads every (period, phase) from it, exact for fixed directions
        and, when they move, at their mean directions (the refinement is exact);
        ``direct`` runs every candidate at every time through the kernel.
    n_threads : int, optional
        Threads of the search (default: every core).

    Returns
    -------
    xarray.Dataset
        Scalars ``axis_longitude``, ``axis_latitude`` [degree], ``period`` [s], ``phase``
        [degree] with ``*_uncertainty``, ``chi2``, ``reduced_chi2``; the map
        ``chi2_map`` over ``axis`` (min over period and phase) with the axis coordinates;
        the alternative solutions over ``solution`` (mirror axis, antipode, half and double
        period) with their ``chi2_gap``.

    Examples
    --------
    A 1 x 2 x 3 m box of the catalog's Lambertian grey spinning about its long axis with
    a period of 20 s, seen in V and R for 40 s at 30 deg phase; the grid search alone
    (``refine=False``) over 30 axes x 11 periods x 12 phases finds the period:

    >>> import numpy as np, trimesh, xarray as xr
    >>> from sbrdf_xr import Scene, geometry, load_spacecraft, simulate
    >>> from sbrdf_xr.invert import axis_vector, fit_spin, spin_model
    >>> box = load_spacecraft(trimesh.creation.box(extents=(1.0, 2.0, 3.0)),
    ...                       material="lambertian-grey-50")
    >>> spin = spin_model([0, 0, 1], axis_vector(60.0, 30.0), period_s=20.0, phase_deg=30.0)
    >>> t = np.arange(0.0, 40.0, 1.0)
    >>> scene = Scene(box, attitudes=spin.quaternions(t), phase_angles=[30.0],
    ...               outputs=("band_signal",), bands=("V", "R"))
    >>> flux = simulate(scene).band_signal.isel(phase_angle=0).values  # (time, band)
    >>> lc = xr.Dataset(
    ...     {"flux": ("obs", flux.ravel()),
    ...      "flux_uncertainty": ("obs", np.full(flux.size, 0.01 * flux.mean()))},
    ...     coords={"time": ("obs", np.repeat(t, 2)), "band": ("obs", ["V", "R"] * t.size)},
    ... )
    >>> to_sun, to_observer = geometry.observation_plane([30.0], (1, 0, 0), (0, 0, 1))
    >>> fit = fit_spin(lc, box, to_sun=to_sun[0], to_observer=to_observer[0],
    ...                periods=np.linspace(15.0, 25.0, 11), n_axes=30, n_phases=12,
    ...                refine=False, n_threads=1)
    >>> float(fit.period), fit.attrs["n_candidates"], fit.sizes["axis"]
    (20.0, 3960, 30)
    >>> fit.solution.values.tolist()
    ['antipode', 'mirror', 'half_period', 'double_period']
    """
    if method not in ("shift", "direct"):
        raise InversionError(f"method: {method!r}; allowed 'shift', 'direct'")
    lc = light_curve_fluxes(light_curve)
    kern = Kernel(spacecraft, list(lc["labels"]), materials)
    prob = Problem(lc, kern, to_sun, to_observer, np.asarray(axis_body, dtype=np.float64), offset)
    periods = np.atleast_1d(np.asarray(periods, dtype=np.float64))
    if not np.all(np.isfinite(periods) & (periods > 0)):
        raise InversionError("periods: must be finite and > 0 [s]")
    n_par = 4 + prob.n_scales
    if prob.y.size <= n_par:
        raise InversionError(
            f"light curve: {prob.y.size} values for {n_par} parameters; need more values"
        )
    axes = fibonacci_sphere(int(n_axes))
    phases = np.arange(int(n_phases)) * 360.0 / int(n_phases)
    t0 = time.perf_counter()
    fixed = bool(np.allclose(prob.s, prob.s[0]) and np.allclose(prob.o, prob.o[0]))
    if method == "shift":
        # with moving directions the search reads the model at the mean directions (an
        # approximation for the global search only; the refinement uses the exact ones)
        search_prob = prob if fixed else prob.at_mean_directions()
        grid = search_shift(search_prob, axes, periods, phases, n_threads)
    else:
        grid = search(prob, axes, periods, phases, n_threads)
    t_search = time.perf_counter() - t0
    ia, ip, iq = np.unravel_index(np.argmin(grid), grid.shape)
    lon0, lat0 = lonlat(axes[ia])
    p0 = np.array([lon0, lat0, periods[ip], phases[iq]])
    if refine:
        # multi-start: the best grid state of each of the n_starts best axes
        best, sig, chi2 = _refine(prob, p0)
        per_axis = grid.reshape(len(axes), -1)
        for i in np.argsort(per_axis.min(axis=1))[1 : max(1, int(n_starts))]:
            jp, jq = np.unravel_index(np.argmin(per_axis[i]), grid.shape[1:])
            lo, la = lonlat(axes[i])
            q, sq, c = _refine(prob, np.array([lo, la, periods[jp], phases[jq]]))
            if c < chi2:
                best, sig, chi2 = q, sq, c
        # an alternative better than the first refinement becomes the solution (once)
        for q, _, c in _alternatives(prob, best, n_phases, refine).values():
            if c < chi2 - 1e-9:
                best, sig, chi2 = _refine(prob, q)
    else:
        best, sig, chi2 = p0, np.full(4, np.nan), float(grid[ia, ip, iq])
    best_axis = vec(best[0], best[1])
    rows = [
        (name, q, c, _axis_angle(vec(q[0], q[1]), best_axis))
        for name, (q, _, c) in _alternatives(prob, best, n_phases, refine).items()
    ]
    dof = prob.y.size - n_par
    chi_map = grid.min(axis=(1, 2))
    mlon, mlat = lonlat(axes)
    ds = xr.Dataset(
        coords={
            "axis": (
                "axis",
                np.arange(len(axes)),
                {"long_name": "candidate axis index", "units": "1"},
            ),
            "axis_longitude_grid": (
                "axis",
                mlon,
                {"long_name": "longitude of the candidate axis", "units": "degree"},
            ),
            "axis_latitude_grid": (
                "axis",
                mlat,
                {"long_name": "latitude of the candidate axis", "units": "degree"},
            ),
            "solution": (
                "solution",
                [r[0] for r in rows],
                {"long_name": "alternative solution", "units": "1"},
            ),
        }
    )
    meta = {
        "axis_longitude": ("degree", "longitude of the inertial spin axis"),
        "axis_latitude": ("degree", "latitude of the inertial spin axis"),
        "period": ("s", "spin period"),
        "phase": ("degree", "spin angle at t = 0"),
    }
    for j, (key, (u, ln)) in enumerate(meta.items()):
        ds[key] = ((), float(best[j]), {"units": u, "long_name": ln})
        ds[key + "_uncertainty"] = (
            (),
            float(sig[j]),
            {"units": u, "long_name": f"1-sigma uncertainty of {ln} (Jacobian of the refinement)"},
        )
    ds["axis_vector"] = (
        ("xyz",),
        best_axis,
        {"units": "1", "long_name": "unit vector of the inertial spin axis"},
    )
    ds["chi2"] = ((), chi2, {"units": "1", "long_name": "chi-square of the best spin state"})
    ds["reduced_chi2"] = (
        (),
        chi2 / dof,
        {"units": "1", "long_name": "chi-square per degree of freedom"},
    )
    ds["chi2_map"] = (
        "axis",
        chi_map,
        {
            "units": "1",
            "long_name": "chi-square of the axis, minimised over period and phase on the grid",
        },
    )
    ds["solution_chi2"] = (
        "solution",
        [r[2] for r in rows],
        {"units": "1", "long_name": "chi-square"},
    )
    ds["chi2_gap"] = (
        "solution",
        [r[2] - chi2 for r in rows],
        {"units": "1", "long_name": "chi-square above the best solution"},
    )
    ds["solution_period"] = (
        "solution",
        [r[1][2] for r in rows],
        {"units": "s", "long_name": "spin period"},
    )
    ds["solution_axis_longitude"] = (
        "solution",
        [r[1][0] for r in rows],
        {"units": "degree", "long_name": "longitude of the spin axis"},
    )
    ds["solution_axis_latitude"] = (
        "solution",
        [r[1][1] for r in rows],
        {"units": "degree", "long_name": "latitude of the spin axis"},
    )
    ds["solution_axis_separation"] = (
        "solution",
        [r[3] for r in rows],
        {"units": "degree", "long_name": "angle between the solution's axis and the best axis"},
    )
    ds.attrs = {
        "axis_body": str(list(np.asarray(axis_body, float))),
        "offset": offset,
        "n_candidates": int(grid.size),
        "search_seconds": t_search,
        "search_method": method,
        "fixed_directions": int(fixed),
        "n_values": int(prob.y.size),
        "bands": ", ".join(lc["labels"]),
    }
    return ds


def axis_vector(longitude: ArrayLike, latitude: ArrayLike) -> np.ndarray:
    """Unit vector(s) of an axis at ``longitude``, ``latitude`` [degree], shape (..., 3).

    Examples
    --------
    >>> from sbrdf_xr.invert import axis_vector
    >>> axis_vector(90.0, 0.0).round(6).tolist()
    [0.0, 1.0, 0.0]
    >>> axis_vector([0.0, 0.0], [0.0, 90.0]).round(6).tolist()
    [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    """
    return vec(np.asarray(longitude, dtype=np.float64), np.asarray(latitude, dtype=np.float64))


def axis_separation(a: ArrayLike, b: ArrayLike) -> float:
    """Angle between two unit vectors [degree].

    Examples
    --------
    >>> from sbrdf_xr.invert import axis_separation
    >>> axis_separation([1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    90.0
    """
    return _axis_angle(np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64))
