"""The Dataset of a light-curve comparison: data, fitted values, covariance, figure curve.

:func:`report` writes what :func:`sbrdf_xr.lightcurves._comparison.fit_and_report` found.
"""

from __future__ import annotations

from itertools import pairwise
from typing import Any

import numpy as np
import xarray as xr

from .._names import BAND, attrs
from ._alignment import Alignment


def _plain(units: str, long_name: str) -> dict[str, str]:
    return {"units": units, "long_name": long_name}


def report(
    measured: xr.Dataset,
    sim: xr.DataArray,
    al: Alignment,
    col: np.ndarray,
    labels: list[str],
    m: np.ndarray,
    sig: np.ndarray,
    w: np.ndarray,
    use: np.ndarray,
    s: np.ndarray,
    xa: np.ndarray | None,
    model: np.ndarray,
    fit: Any,
    x: float,
    names: list[str],
    est: np.ndarray,
    cov: np.ndarray,
    owner: list[int],
    zero_points: str,
    fit_k: bool,
    fixed_k: np.ndarray | None,
    fit_x: bool,
    scan: Any,
    grid: Any,
    system: str,
) -> xr.Dataset:
    """The result Dataset of a comparison."""
    resid = np.where(use, m - model, np.nan)
    n_par = len(names)
    dof = int(use.sum()) - n_par
    present = [b for b in range(len(labels)) if np.any(col[use] == b)]
    blabels = [labels[b] for b in present]
    sd = np.sqrt(np.diag(cov))

    def param(name: str) -> tuple[float, float]:
        j = names.index(name)
        return float(est[j]), float(sd[j])

    zp = [param("ZP" if zero_points == "common" else f"ZP_{labels[b]}") for b in present]
    mean_res = []
    for b in present:
        sel = use & (col == b)
        mean_res.append(float(np.sum(w[sel] * resid[sel]) / np.sum(w[sel])))
    data: dict[str, Any] = {
        "measured_magnitude": ("obs", m, attrs("magnitude", long_name="measured magnitude")),
        "uncertainty": ("obs", sig, attrs("magnitude_uncertainty")),
        "simulated_magnitude": (
            "obs",
            s,
            attrs(
                "magnitude",
                long_name="simulated magnitude at the aligned time or angle, before "
                "the fitted terms (+inf: no light reflected)",
            ),
        ),
        "model_magnitude": (
            "obs",
            model,
            attrs("magnitude", long_name="simulated magnitude with the fitted and fixed terms"),
        ),
        "residual": (
            "obs",
            resid,
            attrs("magnitude", long_name="measured minus model magnitude (NaN: excluded)"),
        ),
        "normalized_residual": ("obs", resid / sig, _plain("1", "residual / uncertainty")),
        "excluded": ("obs", ~use, _plain("1", "excluded: the model reflects no light there")),
        "zero_point": (
            BAND,
            [z[0] for z in zp],
            attrs(
                "magnitude",
                long_name="fitted zero point, measured minus simulated magnitude"
                + (" (one common to every band)" if zero_points == "common" else ""),
            ),
        ),
        "zero_point_uncertainty": (
            BAND,
            [z[1] for z in zp],
            attrs("magnitude", long_name="1-sigma uncertainty of the zero point"),
        ),
        "n_observations": (
            BAND,
            [int(np.sum(use & (col == b))) for b in present],
            _plain("1", "observations used in the band"),
        ),
        "band_mean_residual": (
            BAND,
            mean_res,
            attrs("magnitude", long_name="weighted mean residual in the band after the fit"),
        ),
        "estimate": (
            "parameter",
            est,
            _plain(
                "1",
                "fitted parameter (zero points and k [mag], time_shift [s], phase_offset [degree])",
            ),
        ),
        "standard_error": ("parameter", sd, _plain("1", "1-sigma uncertainty of the parameter")),
        "covariance": (
            ("parameter", "parameter_b"),
            cov,
            _plain("1", "covariance of the parameters (Gauss-Newton, stated uncertainties)"),
        ),
        "chi_square": ((), fit.chi2, _plain("1", "chi-square of the fit")),
        "degrees_of_freedom": ((), dof, _plain("1", "observations used minus parameters")),
        "reduced_chi_square": ((), fit.chi2 / dof, _plain("1", "chi-square per degree of freedom")),
        "n_excluded": (
            (),
            int((~use).sum()),
            _plain("1", "observations where the model reflects no light (excluded)"),
        ),
    }
    if fit_k or fixed_k is not None:
        if fit_k:
            kk = [param(f"k_{labels[b]}") for b in present]
        else:
            given = np.zeros(col.size) if fixed_k is None else fixed_k
            kk = [(float(given[np.flatnonzero(col == b)[0]]), 0.0) for b in present]
        data["extinction_coefficient"] = (
            BAND,
            [k[0] for k in kk],
            attrs(
                "magnitude",
                long_name=("fitted" if fit_k else "given")
                + " first-order extinction coefficient k (mag per airmass)",
            ),
        )
        data["extinction_coefficient_uncertainty"] = (
            BAND,
            [k[1] for k in kk],
            attrs("magnitude", long_name="1-sigma uncertainty of k (0: given, not fitted)"),
        )
        if xa is not None:
            data["airmass"] = ("obs", xa, attrs("airmass"))
    if zero_points == "common":
        data["magnitude_offset"] = (
            (),
            zp[0][0],
            attrs("magnitude", long_name="fitted common magnitude offset (measured - simulated)"),
        )
        data["magnitude_offset_uncertainty"] = (
            (),
            zp[0][1],
            attrs("magnitude", long_name="1-sigma uncertainty of the magnitude offset"),
        )
    colours = [f"{a}-{b}" for a, b in pairwise(blabels)]
    ci, ci_sd = [], []
    for i in range(len(colours)):
        ci.append((zp[i][0] + mean_res[i]) - (zp[i + 1][0] + mean_res[i + 1]))
        if zero_points == "band":
            ja, jb = names.index(f"ZP_{blabels[i]}"), names.index(f"ZP_{blabels[i + 1]}")
            ci_sd.append(float(np.sqrt(cov[ja, ja] + cov[jb, jb] - 2 * cov[ja, jb])))
        else:
            wa = np.sum(w[use & (col == present[i])])
            wb = np.sum(w[use & (col == present[i + 1])])
            ci_sd.append(float(np.sqrt(1 / wa + 1 / wb)))
    data["colour_index_difference"] = (
        "colour",
        ci,
        attrs("colour_index", long_name="measured minus simulated colour index"),
    )
    data["colour_index_difference_uncertainty"] = (
        "colour",
        ci_sd,
        attrs("colour_index", long_name="1-sigma uncertainty of the colour index difference"),
    )
    coords: dict[str, Any] = {
        ("obs_band" if k == BAND else str(k)): v
        for k, v in measured.coords.items()
        if v.dims == ("obs",)
    }
    coords.update(
        {
            BAND: (BAND, blabels, attrs(BAND)),
            "colour": ("colour", colours, attrs("colour")),
            "parameter": ("parameter", names, _plain("1", "fitted parameter")),
            "parameter_b": ("parameter_b", names, _plain("1", "fitted parameter")),
        }
    )
    _shift_terms(data, coords, al, x, names, sd, fit_x, scan, grid, fit.chi2)
    _curve(data, coords, al, sim, present, blabels, x, est, names, zero_points, fit_k, fixed_k, col)
    ds = xr.Dataset(data, coords=coords)
    ds.attrs = {
        "title": "comparison of a measured and a simulated light curve",
        "mode": al.mode,
        "model": "m_obs = m_sim("
        + ("t + time_shift" if al.mode == "observation" else "angle + phase_offset")
        + ") + ZP_band"
        + (" + k_band X" if (fit_k or fixed_k is not None) else "")
        + (" + 5 log10(range / range_sim)" if "range_term" in al.notes else ""),
        "zero_points": "one per band" if zero_points == "band" else "one common offset",
        "extinction": "fitted" if fit_k else al.notes.get("extinction", "none"),
        "magnitude_system": system,
        "uncertainties": "from the stated measurement uncertainties (Gauss-Newton); scale "
        "by sqrt(reduced_chi_square) if those are understated",
        "fit_phase": int(fit_x and al.mode != "observation"),
        **{k: v for k, v in al.notes.items() if k != "extinction"},
    }
    if (~use).any():
        rows = measured["file_row"].values if "file_row" in measured.coords else np.arange(m.size)
        ds.attrs["excluded_rows"] = " ".join(str(int(r)) for r in rows[~use])
    return ds


def _shift_terms(
    data: dict[str, Any],
    coords: dict[str, Any],
    al: Alignment,
    x: float,
    names: list[str],
    sd: np.ndarray,
    fit_x: bool,
    scan: Any,
    grid: Any,
    chi: float,
) -> None:
    sx = float(sd[names.index(al.x_name)]) if fit_x else 0.0
    at = al.where(x)
    if al.mode == "observation":
        data["time_shift"] = (
            (),
            x,
            _plain(
                "s",
                "fitted time shift: the measurement at t matches the simulation at t + time_shift",
            ),
        )
        data["time_shift_uncertainty"] = (
            (),
            sx,
            _plain("s", "1-sigma uncertainty of the time shift (0: not fitted)"),
        )
        when = al.t0 + np.round(at * 1e9).astype("timedelta64[ns]")
        data["model_time"] = (
            "obs",
            when,
            attrs("time", long_name="simulated time matched to each observation"),
        )
        if scan is not None:
            data["chi_square_scan"] = (
                "shift_scan",
                scan,
                _plain("1", "chi-square versus trial time shift"),
            )
            coords["shift_scan"] = ("shift_scan", grid, _plain("s", "trial time shift"))
        return
    data["phase_offset"] = (
        (),
        x,
        attrs(
            "rotation_angle",
            long_name="fitted rotation-phase offset (simulated angle = measured angle + offset)",
        ),
    )
    data["phase_offset_uncertainty"] = (
        (),
        sx,
        attrs(
            "rotation_angle", long_name="1-sigma uncertainty of the phase offset (0: not fitted)"
        ),
    )
    data["model_rotation_angle"] = (
        "obs",
        np.mod(at, 360.0),
        attrs("rotation_angle", long_name="simulated rotation angle matched to each observation"),
    )
    data["chi_square_scan"] = ("phase_scan", scan, _plain("1", "chi-square versus trial phase"))
    coords["phase_scan"] = ("phase_scan", grid, attrs("rotation_angle", long_name="trial phase"))
    far = np.abs(((grid - x + 180.0) % 360.0) - 180.0) > 30.0
    if fit_x and np.isfinite(scan[far]).any():
        k = int(np.nanargmin(np.where(far & np.isfinite(scan), scan, np.nan)))
        alt, dchi = float(grid[k]), float(scan[k] - chi)
    else:
        alt, dchi = np.nan, np.nan
    data["alternative_phase_offset"] = (
        (),
        alt,
        attrs("rotation_angle", long_name="best phase offset more than 30 deg from the fitted one"),
    )
    data["alternative_delta_chi_square"] = (
        (),
        dchi,
        _plain(
            "1",
            "chi-square at the alternative phase minus the best; below ~4 the two phases "
            "are not distinguished at 2 sigma",
        ),
    )


def _curve(
    data: dict[str, Any],
    coords: dict[str, Any],
    al: Alignment,
    sim: xr.DataArray,
    present: list[int],
    blabels: list[str],
    x: float,
    est: np.ndarray,
    names: list[str],
    zero_points: str,
    fit_k: bool,
    fixed_k: np.ndarray | None,
    col: np.ndarray,
) -> None:
    """The fitted model at the simulated nodes, on the measured abscissa (for figures)."""
    with np.errstate(divide="ignore"):
        mag = -2.5 * np.log10(al.flux[:, present])
    zp = np.array(
        [est[names.index("ZP" if zero_points == "common" else f"ZP_{lab}")] for lab in blabels]
    )
    curve = mag + zp[None, :]
    if al.mode == "observation":
        if (fit_k or fixed_k is not None) and "airmass" in sim.coords:
            xs = np.asarray(sim["airmass"].values, dtype=np.float64)
            ks = np.array(
                [
                    est[names.index(f"k_{blabels[j]}")]
                    if fit_k or fixed_k is None
                    else fixed_k[np.flatnonzero(col == b)[0]]
                    for j, b in enumerate(present)
                ]
            )
            curve = curve + ks[None, :] * xs[:, None]
        t = al.t0 + np.round((al.grid - x) * 1e9).astype("timedelta64[ns]")
        data["model_curve"] = (
            ("curve", BAND),
            curve,
            attrs("magnitude", long_name="fitted model at the simulated times"),
        )
        coords["curve_time"] = (
            "curve",
            t,
            attrs("time", long_name="measured time of each simulated node (shifted)"),
        )
        return
    ang = np.mod(al.grid, 360.0)  # the figure's abscissa is the simulated angle
    order = np.argsort(ang)
    data["model_curve"] = (
        ("curve", BAND),
        curve[order],
        attrs("magnitude", long_name="fitted model at the simulated angles (no range term)"),
    )
    coords["curve_angle"] = (
        "curve",
        ang[order],
        attrs("rotation_angle", long_name="simulated rotation angle of each node"),
    )
