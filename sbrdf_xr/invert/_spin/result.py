"""The result Dataset of :func:`sbrdf_xr.invert.fit_spin`."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from .._quality import quality_attrs
from .data import SpinGeometry
from .refine import Minimum, axis_angle, lonlat_covariance
from .search import Problem, lonlat

__all__ = ["result_dataset"]


def _at_epoch(prob: Problem, m: Minimum) -> tuple[float, np.ndarray]:
    """Phase at the epoch (t = 0) from the one at the reference time, and the covariance of
    (lon, lat, period, phase) with it: ``phase_0 = phase_ref - 360 t_ref / P``."""
    _, _, cov = lonlat_covariance(m)
    phase0 = (m.phase - 360.0 * prob.t_ref / m.period) % 360.0
    jac = np.eye(4)
    jac[3, 2] = 360.0 * prob.t_ref / m.period**2
    with np.errstate(invalid="ignore"):  # an unconstrained parameter: inf stays inf or NaN
        return phase0, jac @ cov @ jac.T


def _gap(chi2: float, best: float) -> float:
    """``chi2 - best``, 0 when they agree to 1e-9 (a twin that fits exactly as well)."""
    gap = chi2 - best
    return 0.0 if abs(gap) <= 1e-9 * max(1.0, abs(best)) else gap


def result_dataset(
    *,
    prob: Problem,
    geo: SpinGeometry,
    best: Minimum,
    alts: list[Minimum],
    minima: list[Minimum],
    axes: np.ndarray,
    grid: np.ndarray,
    quality: dict[str, Any],
    dof: int,
    attrs: dict[str, Any],
) -> xr.Dataset:
    """The result Dataset of the spin fit: the solution with its uncertainties, the fit's
    statistics, the chi-square map of the axes, the ambiguous twins and the minima."""
    ds = _solution(prob, best, axes, alts, minima)
    scal = {
        "chi2": (best.chi2, "chi-square of the solution"),
        "degrees_of_freedom": (
            dof,
            "degrees of freedom (values minus spin parameters and flux scales)",
        ),
        "reduced_chi_square": (
            best.chi2 / dof if dof > 0 else np.nan,
            "chi-square per degree of freedom",
        ),
        "fit_probability": (
            quality["fit_probability"],
            "probability of a chi-square at least this large for a right model",
        ),
    }
    for key, (val, ln) in scal.items():
        ds[key] = ((), val, {"units": "1", "long_name": ln})
    ds["chi2_map"] = (
        "axis",
        grid.min(axis=(1, 2)),
        {
            "units": "1",
            "long_name": "chi-square of the axis, minimised over the period and phase grid",
        },
    )
    _twins_and_minima(ds, prob, best, alts, minima)
    epoch = (
        str(geo.epoch.astype("datetime64[ms]"))
        if geo.epoch is not None
        else "t = 0 s of the light curve"
    )
    ds.attrs = {
        **attrs,
        "epoch": epoch,
        "phase_reference": (
            f"phase is the spin angle at the epoch; the search defined it at {prob.t_ref:.6g} s "
            "after the epoch (the middle of the light curve)"
        ),
        "geometry_source": geo.source,
        "geometry_notes": "; ".join(geo.notes),
        **quality_attrs(quality),
    }
    return ds


def _solution(
    prob: Problem, best: Minimum, axes: np.ndarray, alts: list[Minimum], minima: list[Minimum]
) -> xr.Dataset:
    """The coordinates, and the solution's axis [degree], period [s] and phase [degree]
    at the epoch with their uncertainties and the axis's 1-sigma ellipse."""
    lon, lat, _ = lonlat_covariance(best)
    phase0, cov = _at_epoch(prob, best)
    sig = np.sqrt(np.clip(np.diag(cov), 0, None)) if np.all(np.isfinite(cov)) else np.diag(cov)
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
                [a.label for a in alts],
                {"long_name": "ambiguous twin of the solution", "units": "1"},
            ),
            "minimum": (
                "minimum",
                [m.label for m in minima],
                {"long_name": "refined local minimum (start or twin)", "units": "1"},
            ),
            "xyz": ("xyz", ["x", "y", "z"], {"long_name": "vector component", "units": "1"}),
        }
    )
    meta = {
        "axis_longitude": (lon, "degree", "longitude of the inertial spin axis"),
        "axis_latitude": (lat, "degree", "latitude of the inertial spin axis"),
        "period": (best.period, "s", "spin period"),
        "phase": (phase0, "degree", "spin angle at the epoch"),
    }
    for j, (key, (val, u, ln)) in enumerate(meta.items()):
        ds[key] = ((), float(val), {"units": u, "long_name": ln})
        ds[key + "_uncertainty"] = (
            (),
            float(sig[j]),
            {"units": u, "long_name": f"1-sigma uncertainty of the {ln} (Jacobian of the fit)"},
        )
    ev = np.linalg.eigvalsh(best.cov[:2, :2]) if np.all(np.isfinite(best.cov[:2, :2])) else [np.nan]
    ds["axis_uncertainty"] = (
        (),
        float(np.sqrt(max(ev))) if np.all(np.isfinite(ev)) else float("nan"),
        {"units": "degree", "long_name": "major semi-axis of the 1-sigma ellipse of the spin axis"},
    )
    ds["axis_vector"] = (
        ("xyz",),
        best.axis,
        {"units": "1", "long_name": "unit vector of the inertial spin axis"},
    )
    return ds


def _twins_and_minima(
    ds: xr.Dataset, prob: Problem, best: Minimum, alts: list[Minimum], minima: list[Minimum]
) -> None:
    """The ambiguous twins of the solution and every refined local minimum."""
    rows = {
        "solution_chi2": ([a.chi2 for a in alts], "1", "chi-square of the twin"),
        "chi2_gap": (
            [_gap(a.chi2, best.chi2) for a in alts],
            "1",
            "chi-square above the solution (0: the twin fits as well, within 1e-9)",
        ),
        "solution_period": ([a.period for a in alts], "s", "spin period of the twin"),
        "solution_phase": (
            [_at_epoch(prob, a)[0] for a in alts],
            "degree",
            "spin angle at the epoch",
        ),
        "solution_axis_longitude": (
            [float(lonlat(a.axis)[0]) for a in alts],
            "degree",
            "longitude of the twin's axis",
        ),
        "solution_axis_latitude": (
            [float(lonlat(a.axis)[1]) for a in alts],
            "degree",
            "latitude of the twin's axis",
        ),
        "solution_axis_separation": (
            [axis_angle(a.axis, best.axis) for a in alts],
            "degree",
            "angle between the twin's axis and the solution's",
        ),
    }
    for key, (values, u, ln) in rows.items():
        ds[key] = ("solution", np.asarray(values, dtype=float), {"units": u, "long_name": ln})
    local = {
        "local_minimum_chi2": ([m.chi2 for m in minima], "1", "chi-square of the local minimum"),
        "local_minimum_period": (
            [m.period for m in minima],
            "s",
            "spin period of the local minimum",
        ),
        "local_minimum_axis_separation": (
            [axis_angle(m.axis, best.axis) for m in minima],
            "degree",
            "angle between the local minimum's axis and the solution's",
        ),
    }
    for key, (values, u, ln) in local.items():
        ds[key] = ("minimum", np.asarray(values, dtype=float), {"units": u, "long_name": ln})
