"""Agreement of predicted with observed magnitudes: one zero point, then the statistics.

:func:`compare_magnitudes` is the comparison of a model with a table of measured
magnitudes taken at many geometries (many satellites, many nights), where no light curve
is followed in time: the only free parameter is one zero point, the mean of
``observed - predicted`` (the value that minimises the RMS residual), which absorbs the
absolute calibration of the model (albedo, band, area).  It returns the Pearson
correlation of predicted with observed magnitudes (unchanged by the zero point), the RMS
and the median absolute residual after it, and the residual of every row.
:func:`binned_residuals` gives the median residual in bins of a geometry coordinate
(phase angle, elevation, the Sun's elevation at the site).

A prediction that is not finite (no light: the Earth's umbra, or no lit and visible facet)
is not dropped silently: it is counted (``n_unpredicted``) and left out of the statistics,
and its residual is NaN.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from ..errors import ValidationError

__all__ = ["binned_residuals", "compare_magnitudes"]

_STATS = {
    "pearson_r": ("1", "Pearson correlation of predicted with observed magnitudes"),
    "zero_point": ("1", "zero point added to the predicted magnitudes (mean residual)"),
    "rms_residual": ("1", "root-mean-square residual after the zero point [mag]"),
    "median_abs_residual": ("1", "median absolute residual after the zero point [mag]"),
}


def _values(x: Any, name: str) -> np.ndarray:
    a = np.asarray(x.values if isinstance(x, xr.DataArray) else x, dtype=np.float64)
    if a.ndim != 1:
        raise ValidationError(f"{name}: expected a 1-D series of magnitudes, got shape {a.shape}")
    return a


def compare_magnitudes(
    predicted: ArrayLike | xr.DataArray,
    observed: ArrayLike | xr.DataArray,
    *,
    dim: str = "time",
) -> xr.Dataset:
    """Predicted against observed magnitudes after one free zero point.

    ``zero_point = mean(observed - predicted)`` over the rows with a finite prediction;
    ``residual = observed - predicted - zero_point``; ``rms_residual`` its root mean
    square and ``median_abs_residual`` the median of its absolute value; ``pearson_r``
    the Pearson correlation coefficient of the two series (Pearson 1895; scipy's
    ``pearsonr`` gives the same).

    Parameters
    ----------
    predicted, observed : array_like or DataArray, shape (n,)
        Magnitudes, in one system; a DataArray's coordinates along ``dim`` are kept.
    dim : str
        Name of the rows' dimension in the result.

    Returns
    -------
    xarray.Dataset
        ``residual`` (``dim``) and the scalars ``pearson_r``, ``zero_point``,
        ``rms_residual``, ``median_abs_residual``; attributes ``n_rows``,
        ``n_compared`` and ``n_unpredicted`` (rows without a finite prediction).

    Raises
    ------
    ValidationError
        Series of different lengths, a non-finite observed magnitude, or fewer than
        three rows to compare.

    Examples
    --------
    >>> obs = np.array([5.0, 6.0, 7.5, 6.5])
    >>> out = compare_magnitudes(obs - 2.0 + [0.1, -0.1, 0.1, -0.1], obs)
    >>> round(float(out.zero_point), 6), round(float(out.rms_residual), 6)
    (2.0, 0.1)
    >>> out = compare_magnitudes([1.0, np.inf, 2.0, 3.0], [5.0, 9.0, 6.0, 7.0])
    >>> out.attrs["n_unpredicted"], round(float(out.pearson_r), 6)  # the dark row counted
    (1, 1.0)
    """
    p, o = _values(predicted, "predicted"), _values(observed, "observed")
    if p.size != o.size:
        raise ValidationError(
            f"compare_magnitudes: predicted has {p.size} rows, observed {o.size}; "
            "give one prediction per observation"
        )
    bad = np.flatnonzero(~np.isfinite(o))
    if bad.size:
        raise ValidationError(
            f"compare_magnitudes: observed magnitude of row {bad[0]} is {o[bad[0]]}; "
            "allowed: finite values"
        )
    ok = np.isfinite(p)
    if ok.sum() < 3:
        raise ValidationError(
            f"compare_magnitudes: {int(ok.sum())} rows with a finite prediction; "
            "at least 3 are needed"
        )
    zp = float(np.mean(o[ok] - p[ok]))
    res = np.where(ok, o - p - zp, np.nan)
    r = float(np.corrcoef(p[ok], o[ok])[0, 1])
    values = {
        "pearson_r": r,
        "zero_point": zp,
        "rms_residual": float(np.sqrt(np.mean(res[ok] ** 2))),
        "median_abs_residual": float(np.median(np.abs(res[ok]))),
    }
    coords = {}
    for src in (observed, predicted):
        if isinstance(src, xr.DataArray) and src.ndim == 1:
            coords = {
                k: (dim, c.values, c.attrs) for k, c in src.coords.items() if c.dims == src.dims
            }
            break
    out = xr.Dataset(
        {
            "residual": (
                dim,
                res,
                {"units": "1", "long_name": "observed minus predicted magnitude minus zero point"},
            ),
            **{
                k: ((), v, {"units": _STATS[k][0], "long_name": _STATS[k][1]})
                for k, v in values.items()
            },
        },
        coords=coords,
    )
    out.attrs.update(n_rows=int(p.size), n_compared=int(ok.sum()), n_unpredicted=int((~ok).sum()))
    return out


def binned_residuals(
    residual: ArrayLike | xr.DataArray, x: ArrayLike | xr.DataArray, edges: ArrayLike
) -> xr.Dataset:
    """Median, 16th and 84th percentile and count of residuals in bins of ``x``.

    Parameters
    ----------
    residual : array_like or DataArray, shape (n,)
        Residuals, in magnitudes (NaN rows are left out).
    x : array_like or DataArray, shape (n,)
        The coordinate to bin by, in its own unit (a DataArray's ``units`` and
        ``long_name`` are kept on the bin centres).
    edges : array_like
        Increasing bin edges, in the unit of ``x``.

    Returns
    -------
    xarray.Dataset
        ``median``, ``p16``, ``p84`` (magnitudes) and ``count`` over the dimension ``bin``
        (coordinate: the bin centres).

    Examples
    --------
    >>> out = binned_residuals([0.1, 0.3, -0.2, 0.0], [10.0, 20.0, 60.0, 70.0], [0.0, 50.0, 100.0])
    >>> out["median"].values.round(6).tolist(), out["count"].values.tolist()
    ([0.2, -0.1], [2, 2])
    """
    r, v = _values(residual, "residual"), _values(x, "x")
    e = np.asarray(edges, dtype=np.float64)
    if e.ndim != 1 or e.size < 2 or np.any(np.diff(e) <= 0):
        raise ValidationError(f"edges: expected at least 2 increasing values, got {e!r}")
    if r.size != v.size:
        raise ValidationError(f"binned_residuals: residual has {r.size} rows, x {v.size}")
    k = np.digitize(v, e) - 1
    ok = np.isfinite(r) & (k >= 0) & (k < e.size - 1)
    stats = np.full((3, e.size - 1), np.nan)
    count = np.zeros(e.size - 1, dtype=np.int64)
    for b in range(e.size - 1):
        sel = r[ok & (k == b)]
        count[b] = sel.size
        if sel.size:
            stats[:, b] = np.percentile(sel, [50.0, 16.0, 84.0])
    xa = x.attrs if isinstance(x, xr.DataArray) else {}
    centre = {
        "units": xa.get("units", "1"),
        "long_name": f"bin centre of {xa.get('long_name', 'x')}",
    }
    mag = "residual after the zero point"
    return xr.Dataset(
        {
            "median": ("bin", stats[0], {"units": "1", "long_name": f"median {mag}"}),
            "p16": ("bin", stats[1], {"units": "1", "long_name": f"16th percentile of the {mag}"}),
            "p84": ("bin", stats[2], {"units": "1", "long_name": f"84th percentile of the {mag}"}),
            "count": ("bin", count, {"units": "1", "long_name": "rows in the bin"}),
        },
        coords={"bin": ("bin", 0.5 * (e[1:] + e[:-1]), centre)},
    )
