"""The Dataset of a light-curve comparison: data, fitted values, covariance, figure curve.

:func:`report` writes what :func:`sbrdf_xr.lightcurves._comparison.fit_and_report` found.
"""

from __future__ import annotations

from itertools import pairwise
from typing import Any

import numpy as np
import xarray as xr

from .._names import BAND, attrs
from . import _terms as terms
from ._alignment import Alignment

_plain = terms.plain


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
    """The result Dataset of a comparison: the observations, the fitted terms per band, the
    parameters and their covariance, extinction, colours, the shift and the model curve."""
    resid = np.where(use, m - model, np.nan)
    dof = int(use.sum()) - len(names)
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
    data = terms.observation_terms(m, sig, s, model, resid, use)
    data.update(terms.band_terms(zp, zero_points, col, use, present, mean_res))
    data.update(terms.parameter_terms(est, sd, cov, fit.chi2, dof, use))
    if fit_k or fixed_k is not None:
        if fit_k:
            kk = [param(f"k_{labels[b]}") for b in present]
        else:
            given = np.zeros(col.size) if fixed_k is None else fixed_k
            kk = [(float(given[np.flatnonzero(col == b)[0]]), 0.0) for b in present]
        data.update(terms.extinction_terms(kk, fit_k, xa))
    if zero_points == "common":
        data.update(terms.offset_terms(zp[0]))
    colours = [f"{a}-{b}" for a, b in pairwise(blabels)]
    data.update(
        terms.colour_terms(zp, mean_res, blabels, present, names, cov, w, use, col, zero_points)
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
    ds.attrs = _attributes(al, zero_points, fit_k, fixed_k, fit_x, system)
    if (~use).any():
        rows = measured["file_row"].values if "file_row" in measured.coords else np.arange(m.size)
        ds.attrs["excluded_rows"] = " ".join(str(int(r)) for r in rows[~use])
    return ds


def _attributes(
    al: Alignment,
    zero_points: str,
    fit_k: bool,
    fixed_k: np.ndarray | None,
    fit_x: bool,
    system: str,
) -> dict[str, Any]:
    """The comparison's attributes: its mode, the model written out, what was fitted."""
    return {
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
