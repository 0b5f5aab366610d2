"""The fit of :func:`sbrdf_xr.lightcurves.comparison.compare` and the Dataset it returns.

:func:`fit_and_report` takes an :class:`~sbrdf_xr.lightcurves._alignment.Alignment`, finds
the shift of least profiled chi-square (:mod:`sbrdf_xr.lightcurves._fit`), checks that
the data determine every parameter, and writes the result with its covariance.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from .._names import BAND
from ..errors import LightCurveError
from . import _fit
from ._alignment import Alignment
from ._report import report

#: The smallest spread of air mass within a band that lets k be told from the zero point.
MIN_AIRMASS_SPREAD = 1e-3


def _plain(units: str, long_name: str) -> dict[str, str]:
    return {"units": units, "long_name": long_name}


def _design(
    col: np.ndarray, bands: list[int], x: np.ndarray | None, zero_points: str, labels: list[str]
) -> tuple[np.ndarray, list[str], list[int]]:
    """Columns of the linear terms: zero points (per band or one), k per band times X;
    named ``ZP_V`` (``ZP`` when common) and ``k_V``."""
    n = col.size
    cols, names, owner = [], [], []
    if zero_points == "common":
        cols.append(np.ones(n))
        names.append("ZP")
        owner.append(-1)
    else:
        for b in bands:
            cols.append((col == b).astype(np.float64))
            names.append(f"ZP_{labels[b]}")
            owner.append(b)
    if x is not None:
        for b in bands:
            cols.append(np.where(col == b, x, 0.0))
            names.append(f"k_{labels[b]}")
            owner.append(b)
    return np.column_stack(cols) if cols else np.zeros((n, 0)), names, owner


def fit_and_report(
    measured: xr.Dataset,
    sim: xr.DataArray,
    al: Alignment,
    col: np.ndarray,
    zero_points: str,
    fit_k: bool,
    fixed_k: np.ndarray | None,
    fit_x: bool,
    n_scan: int,
    system: str,
) -> xr.Dataset:
    """Fit the model of :func:`~sbrdf_xr.lightcurves.comparison.compare` and report it.

    Examples
    --------
    >>> from sbrdf_xr.lightcurves import compare  # the public entry point; see its examples
    >>> callable(compare)
    True
    """
    m = np.asarray(measured["magnitude"].values, dtype=np.float64)
    sig = np.asarray(measured["uncertainty"].values, dtype=np.float64)
    w = 1.0 / sig**2
    labels = [str(b) for b in sim[BAND].values]
    fixed = np.zeros(m.size) if al.fixed is None else al.fixed
    sweep = al.period is not None
    lo, hi = al.bounds
    x_ref = float(np.clip(0.0, lo, hi))
    ok_ref = al.magnitudes(x_ref, col)[1]

    def terms(x: float) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, np.ndarray]:
        s, ok = al.magnitudes(x, col)
        xa = al.airmass(x) if al.airmass is not None else None
        f = fixed + (fixed_k * xa if fixed_k is not None and xa is not None else 0.0)
        use = ok if sweep else ok_ref
        return s, use, xa, f

    def solve(x: float) -> tuple[Any, ...]:
        s, use, xa, f = terms(x)
        if not use.any() or (not sweep and not np.all(al.magnitudes(x, col)[1][use])):
            return (None, use, s, xa, f, None, [], [])
        present = [b for b in range(len(labels)) if np.any(col[use] == b)]
        a, names, owner = _design(
            col[use], present, xa[use] if fit_k and xa is not None else None, zero_points, labels
        )
        fit = _fit.solve_linear(m[use] - s[use] - f[use], a, w[use], names)
        return (fit, use, s, xa, f, a, names, owner)

    def chi2(x: float) -> float:
        fit = solve(x)[0]
        return np.inf if fit is None else fit.chi2

    scan = grid = None
    if sweep:
        grid = np.arange(n_scan) * (360.0 / n_scan)
        if fit_x:
            x, scan = _fit.profile_scan(chi2, grid, 360.0 / n_scan, -np.inf, np.inf)
            x = float(np.mod(x, 360.0))
        else:
            x, scan = 0.0, np.array([chi2(float(g)) for g in grid])
    elif fit_x:
        grid = np.linspace(lo, hi, max(2, n_scan)) if hi > lo else np.array([lo])
        step = float(grid[1] - grid[0]) if grid.size > 1 else 0.0
        x, scan = _fit.profile_scan(chi2, grid, step, lo, hi)
    else:
        x = 0.0
    fit, use, s, xa, f, a, names, owner = solve(x)
    _check_enough(use, col, labels, zero_points, fit_k, fit_x, xa, names, al.x_name)
    if fit is None:
        bad = _fit.degenerate(a, w[use], names) if a is not None else names
        raise LightCurveError(
            f"measured: the data cannot tell apart the parameters {bad}"
            + (
                "; with a zero point per band, an extinction fit needs each band over a range "
                "of air mass"
                if fit_k
                else ""
            )
        )
    deriv = None
    if fit_x:
        h = 0.5 * al.step()
        sp, sm = al.magnitudes(x + h, col)[0], al.magnitudes(x - h, col)[0]
        deriv = ((sp - sm) / (2.0 * h))[use]
        if not np.all(np.isfinite(deriv)):
            deriv = np.where(np.isfinite(deriv), deriv, ((sp - s) / h)[use])
            deriv = np.where(np.isfinite(deriv), deriv, ((s - sm) / h)[use])
    cov = _fit.gauss_newton_covariance(a, w[use], deriv)
    if cov is None:  # the shift is not determined: report the linear terms alone
        cov = np.pad(fit.covariance, (0, int(fit_x)), constant_values=np.nan)
    names_all = [*names, al.x_name] if fit_x else list(names)
    est = np.r_[fit.beta, x] if fit_x else fit.beta
    model = np.full(m.size, np.inf)
    model[use] = s[use] + f[use] + fit.model
    return report(
        measured,
        sim,
        al,
        col,
        labels,
        m,
        sig,
        w,
        use,
        s,
        xa,
        model,
        fit,
        x,
        names_all,
        est,
        cov,
        owner,
        zero_points,
        fit_k,
        fixed_k,
        fit_x,
        scan,
        grid,
        system,
    )


def _check_enough(
    use: np.ndarray,
    col: np.ndarray,
    labels: list[str],
    zero_points: str,
    fit_k: bool,
    fit_x: bool,
    xa: np.ndarray | None,
    names: list[str],
    x_name: str,
) -> None:
    """Refuse fits with fewer observations than parameters, overall or in a band."""
    n = int(use.sum())
    per_band = int(zero_points == "band") + int(fit_k)
    present = [b for b in range(len(labels)) if np.any(col[use] == b)]
    p = len(present) * per_band + int(zero_points == "common") + int(fit_x)
    if n < p + 1:
        what = ", ".join(
            filter(
                None,
                (
                    "a zero point per band" if zero_points == "band" else "a common zero point",
                    "k per band" if fit_k else "",
                    x_name if fit_x else "",
                ),
            )
        )
        raise LightCurveError(
            f"measured: {n} observation(s) where the model reflects light; fitting {p} "
            f"parameter(s) ({what}) needs at least {p + 1}"
        )
    for b in present:
        nb = int(np.sum(col[use] == b))
        if nb < per_band:
            raise LightCurveError(
                f"measured: band {labels[b]!r} has {nb} observation(s) for its {per_band} "
                "parameters (zero point and extinction); observe it more or fix k"
            )
        if fit_k and xa is not None:
            xb = xa[use & (col == b)]
            if xb.size and np.ptp(xb) < MIN_AIRMASS_SPREAD:
                raise LightCurveError(
                    f"extinction: in band {labels[b]!r} the air mass spans only "
                    f"{xb.min():.4f}-{xb.max():.4f}: k and the zero point cannot be told "
                    "apart; give k (extinction={band: k}) or observe over a range of air mass"
                )
