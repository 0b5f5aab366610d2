"""Reference spectra and exact quadrature: the Sun, the AB source, hat-function integrals."""

from __future__ import annotations

from collections.abc import Mapping
from functools import cache
from importlib.metadata import version as _pkg_version
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from .._names import WAVELENGTH, attrs
from ..errors import ValidationError

# ---------------------------------------------------------------- constants

#: AB zero point [Jy] (Oke & Gunn 1983, ApJ 266, 713: m_AB = -2.5 log10 f_nu - 48.60,
#: f_nu in erg s-1 cm-2 Hz-1, i.e. 3631 Jy at m = 0).
AB_ZERO_POINT_JY = 3631.0
_JY = 1e-26  # W m-2 Hz-1
_C_M_S = 299_792_458.0  # speed of light [m s-1] (exact, SI)

_C_M_S = 299_792_458.0  # speed of light [m s-1] (exact, SI)
_H_J_S = 6.626_070_15e-34  # Planck constant [J s] (exact, SI)

_SOLAR_FILE = "ASTMG173.csv"
_SOLAR_COLUMN = "extraterrestrial"

def _choose(name: Any, table: Mapping[Any, str], what: str) -> Any:
    if name not in table:
        allowed = ", ".join(repr(k) for k in table)
        raise ValidationError(f"{what}: unknown {name!r}; allowed: {allowed}")
    return name


# ------------------------------------------------------- numerical kernels


def hat_integrals(x: ArrayLike, y: ArrayLike, t: ArrayLike) -> np.ndarray:
    """Integrals of a piecewise-linear function against the hat functions of a grid.

    ``out[..., k] = int y(lambda) h_k(lambda) dlambda`` where ``y`` is the linear
    interpolant of ``(x, y)`` (zero outside ``[x[0], x[-1]]``) and ``h_k`` is the
    piecewise-linear hat of node ``t[k]`` (1 at ``t[k]``, 0 at the other nodes and
    outside ``[t[0], t[-1]]``).  Exact: on every interval of the union grid both
    factors are linear and their product is integrated in closed form,
    ``L/6 (2 y_a h_a + y_a h_b + y_b h_a + 2 y_b h_b)``.

    ``sum_k out[..., k]`` is the exact integral of ``y`` over ``[t[0], t[-1]]``;
    ``out / trapezoid_weights(t)`` is the conservative resampling of ``y`` onto ``t``.

    Parameters
    ----------
    x : array_like, shape (n,)
        Strictly increasing abscissae of ``y`` [nm].
    y : array_like, shape (..., n)
        Values.
    t : array_like, shape (m,)
        Strictly increasing grid, ``m >= 2`` [nm].

    Returns
    -------
    ndarray, shape (..., m)
    """
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    t = np.asarray(t, dtype=np.float64)
    lead = y.shape[:-1]
    y2 = y.reshape(-1, x.size)
    out = np.zeros((y2.shape[0], t.size))
    a, b = max(x[0], t[0]), min(x[-1], t[-1])
    if b <= a:
        return out.reshape(*lead, t.size)
    u = np.unique(np.concatenate([x[(x > a) & (x < b)], t[(t > a) & (t < b)], [a, b]]))
    j = np.clip(np.searchsorted(x, u, side="right") - 1, 0, x.size - 2)
    frac = (u - x[j]) / (x[j + 1] - x[j])
    yu = y2[:, j] * (1.0 - frac) + y2[:, j + 1] * frac
    i = np.clip(np.searchsorted(t, u[:-1], side="right") - 1, 0, t.size - 2)
    dt = t[i + 1] - t[i]
    ha = (t[i + 1] - u[:-1]) / dt
    hb = (t[i + 1] - u[1:]) / dt
    length = np.diff(u)
    fa, fb = yu[:, :-1], yu[:, 1:]
    left = length / 6.0 * (2.0 * fa * ha + fa * hb + fb * ha + 2.0 * fb * hb)
    right = 0.5 * length * (fa + fb) - left
    for r in range(y2.shape[0]):
        out[r] = np.bincount(i, left[r], t.size) + np.bincount(i + 1, right[r], t.size)
    return out.reshape(*lead, t.size)


def _integral(x: np.ndarray, y: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Exact integral of the linear interpolant of (x, y) over [lo, hi] (zero outside x)."""
    if hi <= lo:
        return np.zeros(y.shape[:-1])
    return hat_integrals(x, y, np.array([lo, hi])).sum(axis=-1)


def trapezoid_weights(t: ArrayLike) -> np.ndarray:
    """Trapezoid-rule weights of a grid: ``int y dlambda ~= sum_k w_k y_k`` [nm]."""
    t = np.asarray(t, dtype=np.float64)
    w = np.zeros_like(t)
    d = np.diff(t)
    w[:-1] += d / 2.0
    w[1:] += d / 2.0
    return w


def _weighting(wl: np.ndarray, weighting: str) -> np.ndarray:
    """Spectral weight w(lambda): photons per joule [J-1] or 1 (energy)."""
    if weighting == "photon":
        return wl * 1e-9 / (_H_J_S * _C_M_S)
    return np.ones_like(wl)


def _check_grid(wavelength: ArrayLike, what: str) -> np.ndarray:
    wl = np.atleast_1d(np.asarray(wavelength, dtype=np.float64))
    if wl.ndim != 1 or wl.size < 1:
        raise ValidationError(f"{what}: expected a 1-D array, got shape {wl.shape}")
    if not np.all(np.isfinite(wl)) or np.any(wl <= 0):
        raise ValidationError(f"{what}: wavelengths must be finite and > 0 nm")
    if np.any(np.diff(wl) <= 0):
        k = int(np.flatnonzero(np.diff(wl) <= 0)[0])
        raise ValidationError(f"{what}: must be strictly increasing; {wl[k]:g} nm is followed by {wl[k + 1]:g} nm")
    return wl


# ---------------------------------------------------------- solar spectrum


@cache
def _solar_native() -> tuple[np.ndarray, np.ndarray, str]:
    import pvlib

    path = Path(pvlib.__file__).resolve().parent / "data" / _SOLAR_FILE
    with open(path, encoding="utf-8") as fh:
        fh.readline()
        header = [h.strip() for h in fh.readline().split(",")]
    col = header.index(_SOLAR_COLUMN)
    data = np.loadtxt(path, delimiter=",", skiprows=2, usecols=(0, col))
    wl, e = data[:, 0], data[:, 1]
    if np.any(np.diff(wl) <= 0) or np.any(~np.isfinite(e)) or np.any(e < 0):  # pragma: no cover
        raise ValidationError(f"{path}: the solar table is not a valid spectrum")
    wl.setflags(write=False)
    e.setflags(write=False)
    return wl, e, str(path)


def _solar_provenance() -> dict[str, str]:
    wl, e, _ = _solar_native()
    total = float(_integral(wl, e, wl[0], wl[-1]))
    return {
        "solar_spectrum": "ASTM G173-03 extraterrestrial (AM0) spectral irradiance at 1 AU",
        "solar_spectrum_file": f"pvlib/data/{_SOLAR_FILE} (pvlib {_pkg_version('pvlib')}), "
        f"column {_SOLAR_COLUMN!r}, {wl.size} rows, {wl[0]:g}-{wl[-1]:g} nm, "
        f"integral {total:.1f} W m-2",
        "solar_spectrum_reference": "ASTM G173-03, Standard Tables for Reference Solar Spectral "
        "Irradiances; SMARTS2 v2.9.2 (Gueymard 2004, Sol. Energy 76, 423), solar constant "
        "1366.1 W m-2",
    }


def solar_spectrum(wavelength: ArrayLike | None = None, *, method: str = "average") -> xr.DataArray:
    """The extraterrestrial solar spectral irradiance at 1 AU.

    The ``extraterrestrial`` column of the ASTM G173-03 table that ships with pvlib
    (``pvlib/data/ASTMG173.csv``; 280-4000 nm, 0.5 nm steps below 400 nm, 1 nm to
    1700 nm, then coarser).

    Parameters
    ----------
    wavelength : array_like, optional
        Strictly increasing wavelengths [nm] inside 280-4000 nm; default the native grid.
    method : {"average", "linear"}
        ``average`` (default): the conservative resampling - the value at node ``k``
        is the mean of the (linearly interpolated) native spectrum weighted by the
        hat function of node ``k``, so the trapezoid integral on the new grid equals
        the exact integral of the native spectrum over the same range and Fraunhofer
        lines are averaged, not aliased.  ``linear``: point-wise linear interpolation
        (pvlib's own method).

    Returns
    -------
    xarray.DataArray
        ``solar_irradiance`` over ``wavelength`` [W m-2 nm-1], with provenance attrs.
    """
    wl0, e0, _ = _solar_native()
    _choose(method, {"average": "", "linear": ""}, "method")
    if wavelength is None:
        wl, e = np.array(wl0), np.array(e0)
        how = "native grid"
    else:
        wl = _check_grid(wavelength, "wavelength")
        if wl[0] < wl0[0] or wl[-1] > wl0[-1]:
            raise ValidationError(
                f"wavelength: {wl[0]:g}-{wl[-1]:g} nm is outside the solar spectrum "
                f"({wl0[0]:g}-{wl0[-1]:g} nm)")
        if method == "linear" or wl.size == 1:
            e = np.interp(wl, wl0, e0)
            how = "linear interpolation of the native table"
        else:
            e = hat_integrals(wl0, e0, wl) / trapezoid_weights(wl)
            how = "conservative hat-weighted average of the native table (trapezoid-integral preserving)"
    return xr.DataArray(
        e, dims=(WAVELENGTH,), coords={WAVELENGTH: (WAVELENGTH, wl, attrs(WAVELENGTH))},
        name="solar_irradiance", attrs=attrs("solar_irradiance", resampling=how, **_solar_provenance()))


def ab_reference_flux(wavelength: ArrayLike) -> np.ndarray:
    """Spectral flux density of the AB reference source (3631 Jy) per unit wavelength.

    ``f_lambda = f_nu c / lambda**2`` with ``f_nu = 3631 Jy = 3.631e-23 W m-2 Hz-1``.

    Parameters
    ----------
    wavelength : array_like
        [nm]

    Returns
    -------
    ndarray
        [W m-2 nm-1]
    """
    lam_m = np.asarray(wavelength, dtype=np.float64) * 1e-9
    return AB_ZERO_POINT_JY * _JY * _C_M_S / lam_m**2 * 1e-9

