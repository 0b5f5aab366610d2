"""Profile-likelihood intervals of the spin parameters of a joint fit.

See :func:`sbrdf_xr.invert.fit_observation` (``intervals="profile"``).  The Jacobian's
covariance ``(J^T J)^-1`` is the curvature of the chi-square at its minimum: it gives the
right intervals only where the chi-square is quadratic over them, i.e. where the model is
linear in the parameters over a few sigma.  The profile likelihood does not need that:
the interval of a parameter ``q_j`` is where the chi-square minimised over all the other
parameters stays within ``Delta chi2 = 1`` (1 sigma) or 4 (2 sigma) of the minimum
(Bates & Watts 1988, *Nonlinear Regression Analysis and Its Applications*, §6.1;
Venzon & Moolgavkar 1988, Appl. Statist. 37, 87: the crossings found on the profile,
each point a refit of the others).  It is invariant to the parametrisation, and exact
for a model linear in the other parameters.

The quadratic check is the chi-square along the line the quadratic approximation gives
for the profile (``q_hat + s C e_j / sqrt(C_jj)``, the other parameters at their
conditional optimum) at ``s = +-2 sigma_j``: 4 where the approximation holds; its signed
root ``r`` is compared with 2 (``quadratic_miss = max |r -+ 2|``).  A spin's chi-square is
rippled (the flat facets' glints and terminators): on held-out box-wing passes the miss
is 0.15-0.45 (median) at 0.02 and 0.05 mag alike and does not single out the draws whose
estimates land beyond 2 sigma, so it is reported, not used to choose; and the profile's
intervals came out as wide as the quadratic's (docs/guide/inversion.md).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from .result import reported_jacobian

__all__ = [
    "INTERVALS",
    "PROFILE_GRID",
    "QUADRATIC_TOL",
    "SPIN_PROFILED",
    "point_intervals",
    "profile_crossing",
    "quadratic_check",
    "reported_map",
    "spin_intervals",
    "with_intervals",
]

#: A miss of the quadratic check (``|r -+ 2|`` at 2 sigma) above this is said in the
#: result's ``intervals`` note: the 2-sigma bound of the quadratic off by 5 %.
QUADRATIC_TOL = 0.1
#: The reported parameters that may be profiled (indices of the reported vector).
SPIN_PROFILED = (0, 1, 2, 3)


def quadratic_check(
    chi2_of: Callable[[np.ndarray], float], q: np.ndarray, cov: np.ndarray, chi2_min: float, j: int
) -> tuple[float, float]:
    """The signed roots ``r = sign(s) sqrt(chi2 - chi2_min)`` of the chi-square along the
    quadratic approximation's profile line of parameter ``j`` at ``s = -2`` and ``+2``
    sigma; ``(-2, 2)`` where the approximation holds.

    Examples
    --------
    A model linear in its parameters has a quadratic chi-square: the roots are -2, 2.

    >>> import numpy as np
    >>> from sbrdf_xr.invert._joint.profile import quadratic_check
    >>> a = np.array([[1.0, 0.5], [0.0, 2.0], [1.0, 1.0]])
    >>> cov = np.linalg.inv(a.T @ a)
    >>> lo, hi = quadratic_check(lambda q: float((a @ q) @ (a @ q)), np.zeros(2), cov, 0.0, 1)
    >>> round(lo, 9), round(hi, 9)
    (-2.0, 2.0)
    """
    sd = float(np.sqrt(cov[j, j]))
    line = cov[:, j] / sd
    out = []
    for s in (-2.0, 2.0):
        d = chi2_of(q + s * line) - chi2_min
        out.append(float(np.sign(s) * np.sqrt(max(d, 0.0))) if np.isfinite(d) else np.inf)
    return out[0], out[1]


def _profile_chi2(
    residuals_of: Callable[[np.ndarray], np.ndarray],
    q: np.ndarray,
    cov: np.ndarray,
    j: int,
    value: float,
    x_scale: np.ndarray,
) -> tuple[float, int]:
    """The chi-square minimised over every parameter but ``j`` held at ``value`` (from the
    quadratic approximation's conditional optimum), and the model evaluations spent."""
    others = np.arange(q.size) != j
    start = q + (value - q[j]) * cov[:, j] / cov[j, j]

    def fun(x: np.ndarray) -> np.ndarray:
        full = start.copy()
        full[others] = x
        full[j] = value
        return residuals_of(full)

    res = least_squares(
        fun,
        start[others],
        x_scale=x_scale[others],
        method="lm",
        diff_step=1e-7,
        ftol=1e-8,
        xtol=1e-8,
        max_nfev=400,
    )
    return float(2.0 * res.cost), int(res.nfev)


#: Offsets [sigma of the quadratic approximation] at which the profile is evaluated on
#: each side, outwards until it has stayed above the highest level twice.
PROFILE_GRID = (0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 5.0, 6.0)


def profile_crossing(
    residuals_of: Callable[[np.ndarray], np.ndarray],
    q: np.ndarray,
    cov: np.ndarray,
    chi2_min: float,
    j: int,
    levels: Sequence[float] = (1.0, 2.0),
    grid: Sequence[float] = PROFILE_GRID,
) -> dict[str, Any]:
    """Where the profile of parameter ``j`` crosses each level of the signed root
    ``r = sign(s) sqrt(Delta chi2)`` (1: ``Delta chi2 = 1``, 2: ``Delta chi2 = 4``) for the
    last time, on both sides: the profile evaluated outwards on ``grid`` [sigma of the
    quadratic approximation] (each point a refit of the others, Levenberg-Marquardt from
    the quadratic approximation's conditional optimum) until it has stayed above the
    highest level at two points, the crossing interpolated linearly between the grid's
    points.  The outermost crossing, not the first: a spin's chi-square is rippled (flat
    facets), its profile not monotone.

    Returns ``{"low": [...], "high": [...], "evaluations": n, "converged": bool, "dip":
    float}``: the crossings [units of ``q_j``] for each level (low ones below ``q_j``),
    whether every level was crossed within the grid (else its last point), and the
    lowest ``Delta chi2`` the profile reached (below 0: a lower minimum nearby).

    Examples
    --------
    A linear model: the crossings are the Jacobian's 1 and 2 sigma.

    >>> import numpy as np
    >>> from sbrdf_xr.invert._joint.profile import profile_crossing
    >>> a = np.array([[1.0, 0.5], [0.0, 2.0], [1.0, 1.0]])
    >>> y = np.array([1.0, 2.0, 0.5])
    >>> q = np.linalg.lstsq(a, y, rcond=None)[0]
    >>> cov = np.linalg.inv(a.T @ a)
    >>> res = lambda p: a @ p - y
    >>> out = profile_crossing(res, q, cov, float(res(q) @ res(q)), 0)
    >>> sd = np.sqrt(cov[0, 0])
    >>> np.round((np.array(out["high"]) - q[0]) / sd, 6).tolist()
    [1.0, 2.0]
    """
    sd = float(np.sqrt(cov[j, j]))
    scale = np.sqrt(np.clip(np.diag(cov), 1e-300, None))
    n_eval = 0
    converged = True
    dip = 0.0
    out: dict[str, Any] = {"low": [], "high": []}
    for side, sign in (("low", -1.0), ("high", 1.0)):
        s_pts, r_pts = [0.0], [0.0]  # offsets [sigma] and roots, the minimum first
        above = 0
        for s in grid:
            c, n = _profile_chi2(residuals_of, q, cov, j, q[j] + sign * s * sd, scale)
            n_eval += n
            dip = min(dip, c - chi2_min)
            s_pts.append(s)
            r_pts.append(float(np.sqrt(max(c - chi2_min, 0.0))))
            above = above + 1 if r_pts[-1] >= max(levels) else 0
            if above == 2:
                break
        r = np.asarray(r_pts)
        for level in levels:
            k = int(np.flatnonzero(r < level)[-1])  # the last point below the level
            if k + 1 == r.size:
                converged = False
                out[side].append(q[j] + sign * s_pts[-1] * sd)
                continue
            (sa, ra), (sb, rb) = (s_pts[k], r[k]), (s_pts[k + 1], r[k + 1])
            s_cross = sa + (level - ra) * (sb - sa) / (rb - ra)
            # one step of regula falsi inside the bracket
            c, n = _profile_chi2(residuals_of, q, cov, j, q[j] + sign * s_cross * sd, scale)
            n_eval += n
            rc = float(np.sqrt(max(c - chi2_min, 0.0)))
            if rc < level:
                sa, ra = s_cross, rc
            else:
                sb, rb = s_cross, rc
            s_cross = sa + (level - ra) * (sb - sa) / (rb - ra) if rb > ra else s_cross
            out[side].append(q[j] + sign * s_cross * sd)
    out["evaluations"] = n_eval
    out["converged"] = bool(converged)
    out["dip"] = float(dip)
    return out


#: The ways a point fit's intervals are found (``fit_observation(intervals=...)``).
INTERVALS = ("quadratic", "profile")


def reported_map(
    residuals: Callable[[np.ndarray], np.ndarray],
    axis_of: Callable[[np.ndarray], np.ndarray],
    shift: float,
) -> Callable[[np.ndarray], np.ndarray]:
    """The normalised residuals as a function of the reported parameters ``q`` (axis
    longitude and latitude [degree], period [s], phase at the epoch [degree] unwrapped,
    the rest as fitted), from those of the fitted ``p`` (the axis on the tangent plane of
    the start axis, the phase at the reference time; ``shift = 360 (t_ref - t_epoch)``
    [degree s]): the axis by the gnomonic projection that ``axis_of`` inverts."""
    from .._spin.refine import tangent_frame
    from .._spin.search import vec

    e0 = axis_of(np.zeros(4))
    east, north = tangent_frame(e0)

    def of_q(q: np.ndarray) -> np.ndarray:
        u = vec(float(q[0]), float(q[1]))
        c = max(float(u @ e0), 1e-12)  # the axis within 90 deg of the start's
        p = np.array(q, dtype=np.float64)
        p[0], p[1] = np.degrees(u @ east / c), np.degrees(u @ north / c)
        p[3] = q[3] + shift / q[2]
        return residuals(p)

    return of_q


def spin_intervals(
    residuals: Callable[[np.ndarray], np.ndarray],
    axis_of: Callable[[np.ndarray], np.ndarray],
    shift: float,
    q: np.ndarray,
    cov_q: np.ndarray,
    chi2_min: float,
    mode: str,
) -> dict[str, Any]:
    """The 1- and 2-sigma intervals of the spin parameters (reported ones: longitude,
    latitude, period, phase at the epoch): with ``mode="profile"`` the profile's crossings
    (:func:`profile_crossing`), else the quadratic's ``q_j +- sigma_j`` and ``+- 2
    sigma_j``; :func:`quadratic_check`'s miss of each either way.

    Returns ``{"low1", "high1", "low2", "high2"}`` arrays over the four parameters, the
    ``miss`` of the check (``max |r -+ 2|``), which were ``profiled``, the model
    ``evaluations`` spent and whether every search ``converged``.
    """
    of_q = reported_map(residuals, axis_of, shift)
    sd = np.sqrt(np.clip(np.diag(cov_q)[:4], 0, None))
    out: dict[str, Any] = {
        "low1": q[:4] - sd,
        "high1": q[:4] + sd,
        "low2": q[:4] - 2 * sd,
        "high2": q[:4] + 2 * sd,
        "miss": np.full(4, np.nan),
        "profiled": np.zeros(4, bool),
        "q": q[:4].copy(),
        "mode": mode,
        "evaluations": 0,
        "converged": True,
        "dip": 0.0,
    }

    def chi2_of(x: np.ndarray) -> float:
        r = of_q(x)
        return float(r @ r)

    for j in SPIN_PROFILED:
        lo, hi = quadratic_check(chi2_of, q, cov_q, chi2_min, j)
        out["evaluations"] += 2
        out["miss"][j] = max(abs(lo + 2.0), abs(hi - 2.0))
        if mode == "profile":
            prof = profile_crossing(of_q, q, cov_q, chi2_min, j)
            out["evaluations"] += prof["evaluations"]
            out["converged"] &= prof["converged"]
            out["dip"] = min(out["dip"], prof["dip"])
            out["low1"][j], out["low2"][j] = prof["low"]
            out["high1"][j], out["high2"][j] = prof["high"]
            out["profiled"][j] = True
    return out


_SPIN_KEYS = ("axis_longitude", "axis_latitude", "period", "phase")


def with_intervals(ds: Any, ints: dict[str, Any] | None, note: str) -> Any:
    """The result with its 2-sigma bounds over ``parameter`` (``lower_2sigma``,
    ``upper_2sigma``: the profile's where profiled, else ``estimate -+ 2 uncertainty``),
    the quadratic check's miss, and the profiled spin parameters' uncertainties (half
    their 1-sigma interval; the axis's ellipse scaled alike); ``attrs["intervals"]``
    says how each was found."""
    est = ds["estimate"].values
    unc = ds["uncertainty"].values.copy()
    lo, hi = est - 2 * unc, est + 2 * unc
    miss = np.full(est.size, np.nan)
    said = []
    grow = 1.0  # the axis's ellipse scaled as its widest angle
    if ints is not None:
        miss[:4] = ints["miss"]
        for j in np.flatnonzero(ints["profiled"]):  # the bounds about the estimate
            unc_j = 0.5 * (ints["high1"][j] - ints["low1"][j])
            lo[j] = est[j] - (ints["q"][j] - ints["low2"][j])
            hi[j] = est[j] + (ints["high2"][j] - ints["q"][j])
            if unc[j] > 0 and j < 2:
                grow = max(grow, unc_j / unc[j])
            unc[j] = unc_j
            key = _SPIN_KEYS[j] + "_uncertainty"
            ds[key] = ds[key].copy(data=np.float64(unc_j))
            said.append(_SPIN_KEYS[j])
    ds["uncertainty"] = ds["uncertainty"].copy(data=unc)
    ds["axis_uncertainty"] = ds["axis_uncertainty"].copy(data=float(ds["axis_uncertainty"]) * grow)
    for key, val, ln in (
        ("lower_2sigma", lo, "lower 2-sigma bound (Delta chi2 = 4 where profiled)"),
        ("upper_2sigma", hi, "upper 2-sigma bound (Delta chi2 = 4 where profiled)"),
    ):
        ds[key] = ("parameter", val, {"units": "1", "long_name": f"{ln} (units: parameter_units)"})
    ds["quadratic_miss"] = (
        "parameter",
        miss,
        {
            "units": "1",
            "long_name": "miss |r -+ 2| of the signed root of the chi-square along the "
            "quadratic approximation's profile line at 2 sigma (nan: not checked)",
        },
    )
    ds.attrs["intervals"] = note if ints is None else _note(ints, said)
    return ds


def _note(ints: dict[str, Any], said: list[str]) -> str:
    """How the intervals were found, the check's misses and the profile's cost."""
    check = ", ".join(f"{k} {m:.2g}" for k, m in zip(_SPIN_KEYS, ints["miss"], strict=True))
    how = (
        "the quadratic approximation (J^T J)^-1 for every parameter"
        + (" (intervals='quadratic')" if ints["mode"] == "quadratic" else "")
        if not said
        else "the profile likelihood (Delta chi2 = 1 and 4 crossings, the others refitted) "
        f"for {', '.join(said)}; the quadratic approximation (J^T J)^-1 elsewhere"
    )
    return (
        f"{how}; the quadratic check's miss at 2 sigma (|r -+ 2|, 0 for a quadratic "
        f"chi-square): {check}"
        + (
            f" (above {QUADRATIC_TOL:g}: the chi-square is not quadratic over the 2-sigma interval)"
            if np.nanmax(ints["miss"]) > QUADRATIC_TOL
            else ""
        )
        + f"; {ints['evaluations']} model evaluations"
        + ("" if ints["converged"] else "; a level not crossed within 6 sigma")
        + (
            f"; the profile found a chi-square {-ints['dip']:.3g} below the solution's (a "
            "rippled chi-square: other minima within the interval)"
            if ints["dip"] < -0.1
            else ""
        )
    )


def point_intervals(
    ds: Any,
    sol: Any,
    stats: tuple[np.ndarray, np.ndarray, float, int],
    lay: Any,
    t_ref: float,
    dt_epoch: float,
    mode: str,
    scaled: bool,
) -> Any:
    """The point fit's result with its spin parameters' intervals: the quadratic's, or
    (``mode="profile"``) the profile likelihood's; ``sol`` the solution's minimum
    (``x``, ``residuals``, ``axis_of``, ``bounded``), ``stats`` its covariance, the
    unconstrained parameters, chi-square and degrees of freedom."""
    cov, free, chi2, dof = stats
    quad = "the quadratic approximation (J^T J)^-1"
    if mode == "quadratic":
        return with_intervals(ds, None, f"{quad} (intervals='quadratic')")
    if ds.attrs["status"] != "ok" or sol.bounded or bool(np.any(free)):
        return with_intervals(
            ds, None, f"{quad}: no profile of a failed, bounded or partly unconstrained fit"
        )
    p = sol.x
    shift = 360.0 * (t_ref - dt_epoch)
    t = reported_jacobian(lay, p, sol.axis_of, t_ref, dt_epoch)
    birge = chi2 / dof if scaled else 1.0  # scaled uncertainties: the levels scaled alike
    lon, lat = float(ds["axis_longitude"]), float(ds["axis_latitude"])
    q = np.concatenate([[lon, lat, p[2], p[3] - shift / p[2]], p[4:]])
    ints = spin_intervals(
        lambda x: sol.residuals(x) / np.sqrt(birge),
        sol.axis_of,
        shift,
        q,
        t @ cov @ t.T,
        chi2 / birge,
        mode,
    )
    return with_intervals(ds, ints, quad)
