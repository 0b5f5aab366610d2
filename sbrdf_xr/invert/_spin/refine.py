"""Local refinement of a spin state, and its ambiguous twins.

See :func:`sbrdf_xr.invert.fit_spin`.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy.optimize import least_squares

from .search import Problem, lonlat, vec

__all__ = ["Minimum", "axis_angle", "exact_minimum", "refine", "twins"]

#: Function evaluations allowed to one local refinement.
MAX_NFEV = 400


@dataclasses.dataclass(frozen=True)
class Minimum:
    """A spin state: inertial ``axis``, ``period`` [s], ``phase`` [degree] at the problem's
    reference time, its ``chi2``, and the covariance of (east, north [degree] of the axis on
    its tangent plane, period, phase) (NaN without refinement)."""

    axis: np.ndarray
    period: float
    phase: float
    chi2: float
    cov: np.ndarray
    label: str = "grid"


def axis_angle(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.degrees(np.arccos(np.clip(np.dot(a, b), -1, 1))))


def tangent_frame(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """East and north unit vectors at ``axis`` (an arbitrary pair at the poles)."""
    east = np.array([-axis[1], axis[0], 0.0])
    if np.linalg.norm(east) < 1e-9:
        east = np.array([0.0, 1.0, 0.0])
    east /= np.linalg.norm(east)
    return east, np.cross(axis, east)


def _residuals(prob: Problem, axis: np.ndarray, period: float, phase: float) -> np.ndarray:
    mdl = prob.model(axis[None, :], np.array([period]), np.array([phase]))
    return ((prob.y - prob.scales(mdl) * mdl) / prob.sigma)[0]


def _covariance(prob: Problem, axis: np.ndarray, period: float, phase: float) -> np.ndarray:
    """``(J^T J)^-1`` from central differences of the profiled residuals (the flux scales
    solved at every step) in (east, north, period, phase) at the solution."""
    e, n = tangent_frame(axis)
    steps = np.array([1e-3, 1e-3, 1e-6 * period, 1e-3])

    def at(d: np.ndarray) -> np.ndarray:
        a = axis + np.radians(d[0]) * e + np.radians(d[1]) * n
        return _residuals(prob, a / np.linalg.norm(a), period + d[2], phase + d[3])

    jac = np.empty((prob.y.size, 4))
    for j in range(4):
        d = np.zeros(4)
        d[j] = steps[j]
        jac[:, j] = (at(d) - at(-d)) / (2 * steps[j])
    try:
        return np.linalg.inv(jac.T @ jac)
    except np.linalg.LinAlgError:
        return np.full((4, 4), np.inf)


def refine(prob: Problem, axis0: np.ndarray, period0: float, phase0: float, label: str) -> Minimum:
    """Least squares (Levenberg-Marquardt) from a spin state, in tangent-plane coordinates of
    the axis (no singularity at the poles), with the exact model."""
    e, n = tangent_frame(axis0)

    def axis_of(p: np.ndarray) -> np.ndarray:
        a = axis0 + np.radians(p[0]) * e + np.radians(p[1]) * n
        return a / np.linalg.norm(a)

    span = max(float(np.ptp(prob.times)), 1e-9)
    res = least_squares(
        lambda p: _residuals(prob, axis_of(p), p[2], p[3]),
        np.array([0.0, 0.0, period0, phase0]),
        x_scale=np.array([1.0, 1.0, period0**2 / (360.0 * span), 1.0]),
        method="lm" if prob.y.size > 4 else "trf",
        diff_step=1e-7,
        max_nfev=MAX_NFEV,
    )
    axis, period, phase = axis_of(res.x), float(res.x[2]), float(res.x[3]) % 360.0
    if period <= 0:  # ran away through zero: keep the start
        axis, period, phase = axis0, period0, phase0
    chi2 = float(np.sum(_residuals(prob, axis, period, phase) ** 2))
    return Minimum(axis, period, phase, chi2, _covariance(prob, axis, period, phase), label)


def exact_minimum(
    prob: Problem, axis: np.ndarray, period: float, phases: np.ndarray, label: str
) -> Minimum:
    """The best of ``phases`` for one axis and period, by the exact model (no refinement)."""
    c2 = prob.chi2(np.repeat(axis[None, :], phases.size, 0), np.full(phases.size, period), phases)
    j = int(np.argmin(c2))
    return Minimum(
        axis, float(period), float(phases[j]), float(c2[j]), np.full((4, 4), np.nan), label
    )


def twins(prob: Problem, best: Minimum, n_phases: int, do_refine: bool) -> list[Minimum]:
    """The classical ambiguous solutions of a spin state, each searched in phase (and refined).

    ``antipode``: the opposite axis (the reversed sense of rotation); ``mirror``: the axial
    vector mirrored through the mean scattering plane (the plane of the Sun and observer
    directions), ``-M n``, which for a body equal to its mirror image and fixed directions
    gives the same light curve (Kaasalainen & Lamberg 2006, Inverse Problems 22, 749);
    ``half_period`` and ``double_period``: the period aliases of a light curve with (or
    without) a two-fold symmetry.
    """
    nplane = np.cross(prob.s.mean(0), prob.o.mean(0))
    norm = np.linalg.norm(nplane)
    nplane = nplane / norm if norm > 1e-9 else np.array([0.0, 0.0, 1.0])
    mirror = -(best.axis - 2 * np.dot(best.axis, nplane) * nplane)
    alts = {
        "antipode": (-best.axis, best.period),
        "mirror": (mirror, best.period),
        "half_period": (best.axis, best.period / 2),
        "double_period": (best.axis, best.period * 2),
    }
    dense = np.arange(4 * int(n_phases)) * 90.0 / int(n_phases)
    out = []
    for name, (ax, per) in alts.items():
        start = exact_minimum(prob, ax, per, dense, name)
        out.append(refine(prob, ax, per, start.phase, name) if do_refine else start)
    return out


def lonlat_covariance(m: Minimum) -> tuple[float, float, np.ndarray]:
    """Longitude, latitude [degree] of the axis and the covariance of (lon, lat, period,
    phase) from the tangent-plane one (``d lon = d east / cos lat``, ``d lat = d north``)."""
    lon, lat = (float(v) for v in lonlat(m.axis))
    e, n = tangent_frame(m.axis)
    east0 = np.array([-np.sin(np.radians(lon)), np.cos(np.radians(lon)), 0.0])
    north0 = np.cross(vec(lon, lat), east0)
    c = max(np.cos(np.radians(lat)), 1e-12)
    jac = np.eye(4)
    jac[0, :2] = [np.dot(e, east0) / c, np.dot(n, east0) / c]
    jac[1, :2] = [np.dot(e, north0), np.dot(n, north0)]
    with np.errstate(invalid="ignore"):  # an unconstrained parameter: inf stays inf or NaN
        return lon, lat, jac @ m.cov @ jac.T


def symmetry_twins(prob: Problem, best: Minimum, axis_body: np.ndarray) -> str:
    """The body's symmetry twins of a spin fit's solution (:mod:`._symmetry`): a turn by
    ``theta`` about the spin axis is the phase ``+ theta``, its chi-square evaluated on the
    data; a flip is the antipode with the other sense of rotation (outside the fit's
    parameters, identical for the unshadowed model).  ``"none"`` without symmetries."""
    from .symmetry import body_symmetries

    t = prob.kernel.plan.terms
    rows = []
    for sym in body_symmetries(t.normal, t.area, t.material, axis_body):
        if sym.kind == "turn":
            r = _residuals(prob, best.axis, best.period, best.phase + sym.angle)
            rows.append(f"{sym.name}: phase + {sym.angle:g} deg (chi2 gap {r @ r - best.chi2:.2g})")
        else:
            rows.append(f"{sym.name}: the axis antipode, the other sense of rotation")
    if not rows:
        return "none"
    return (
        "symmetry twins of the body (found from the mesh), which the light curve cannot tell "
        "from the solution: " + "; ".join(rows)
    )
