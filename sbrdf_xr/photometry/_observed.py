"""What a cube records about its observation, read for the magnitudes.

A cube of a pass carries, over ``time``, the observer ``range`` [km], the Sun distance
``sun_distance`` [au] and the relative ``airmass`` [1] (coordinates or variables).  The
magnitudes use them unless an argument overrides them; an override is noted in the
attributes with the value the cube had.  ``range_km`` and ``sun_distance_au`` accept
astropy Quantities of length (converted, :func:`sbrdf_xr.units.to_unit`); bare numbers
are in km and au, and warn when implausible for their unit
(:func:`sbrdf_xr.units.check_plausible`).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from .._names import BAND
from ..errors import ValidationError
from ..units import check_plausible, to_unit
from .band_lookup import extinction_for_band


def _recorded(cube: Any, name: str, unit: str | None) -> xr.DataArray | None:
    """The cube's variable or coordinate ``name`` in ``unit`` (from its ``units``), if any."""
    have = cube.variables if isinstance(cube, xr.Dataset) else getattr(cube, "coords", {})
    if name not in have:
        return None
    v = (cube[name] if isinstance(cube, xr.Dataset) else cube.coords[name]).reset_coords(drop=True)
    v = v.astype(np.float64)
    given = v.attrs.get("units")
    if unit is not None and given and given != unit:
        import astropy.units as u

        try:
            factor = u.Unit(given).to(u.Unit(unit))
        except (ValueError, u.UnitsError) as exc:
            raise ValidationError(
                f"cube: {name!r} has units {given!r}, which do not convert to {unit}"
            ) from exc
        v = v * factor
    return v


def _describe(v: Any, unit: str) -> str:
    vals = np.asarray(v.values if isinstance(v, xr.DataArray) else v, dtype=np.float64)
    if vals.size == 1:
        return f"{float(vals.ravel()[0]):.6g} {unit}"
    over = f" over {', '.join(map(str, v.dims))}" if isinstance(v, xr.DataArray) else ""
    return f"{np.nanmin(vals):.6g} to {np.nanmax(vals):.6g} {unit}{over}"


def _range_m(range_km: Any) -> xr.DataArray | np.ndarray:
    r: xr.DataArray | np.ndarray
    range_km = to_unit(range_km, "km", "range_km")
    if isinstance(range_km, xr.DataArray):
        vals = np.asarray(range_km.values, dtype=np.float64)
        r = range_km.astype(np.float64) * 1e3
    else:
        vals = np.asarray(range_km, dtype=np.float64)
        r = vals * 1e3
    if vals.size == 0 or not np.all(np.isfinite(vals)) or np.any(vals <= 0):
        raise ValidationError(f"range: must be finite and > 0 km, got {vals.ravel()[:5].tolist()}")
    return r


def _positive(value: Any, what: str) -> Any:
    value = to_unit(value, "au", what)
    vals = np.asarray(value.values if isinstance(value, xr.DataArray) else value, dtype=np.float64)
    if vals.size == 0 or not np.all(np.isfinite(vals)) or np.any(vals <= 0):
        raise ValidationError(f"{what}: must be finite and > 0, got {vals.ravel()[:5].tolist()}")
    return value.astype(np.float64) if isinstance(value, xr.DataArray) else vals


def _term(cube: Any, value: Any, name: str, unit: str, attrs: dict[str, str]) -> Any:
    """The argument ``name``'s value, else the cube's ``name`` (or None); notes into ``attrs``."""
    arg = name
    rec = _recorded(cube, name, unit)
    if value is None:
        if rec is not None:
            attrs[f"{name}_source"] = f"the cube's {name!r} ({_describe(rec, unit)})"
        return rec
    given = to_unit(value, unit, arg)
    check_plausible(given, f"{name}_{unit}", arg)
    attrs[f"{name}_source"] = f"argument {arg} ({_describe(given, unit)})"
    if rec is not None:
        attrs[f"{name}_override"] = (
            f"{arg} ({_describe(given, unit)}) overrides the cube's {name!r} "
            f"({_describe(rec, unit)})"
        )
    return given


def _distances(cube: Any, range_: Any, sun_distance: Any) -> tuple[Any, Any, dict[str, str]]:
    """Observer range [m], Sun distance [au] and notes: the cube's unless given."""
    notes: dict[str, str] = {}
    rng = _term(cube, range_, "range", "km", notes)
    if rng is None:
        raise ValidationError(
            "range: the observer range [km] is required: the cube records no 'range' "
            "(e.g. range=1000.0, or 1000 * u.km)"
        )
    sun = _term(cube, sun_distance, "sun_distance", "au", notes)
    if sun is None:
        sun = 1.0
        notes["sun_distance_source"] = "default 1 au (the cube records no 'sun_distance')"
    return _range_m(rng), _positive(sun, "sun_distance"), notes


def _with_extinction(mags: xr.DataArray, cube: Any, coefficients: Any) -> xr.DataArray:
    """``mags + k_band X`` with the cube's ``airmass`` ``X`` (first-order extinction)."""
    if not isinstance(coefficients, dict):
        raise ValidationError(
            "extinction: expected a mapping band -> k [mag per airmass], "
            f"got {type(coefficients).__name__}"
        )
    x = _recorded(cube, "airmass", None)
    if x is None:
        raise ValidationError(
            "extinction: the cube records no 'airmass' (only a cube of an observation does); "
            "use apply_extinction(mags, airmass, coefficients) with an air mass of your own"
        )
    labels = [str(b) for b in mags[BAND].values]
    k = np.array([extinction_for_band(mags, coefficients, b, i) for i, b in enumerate(labels)])
    if not np.all(np.isfinite(k)) or np.any(k < 0):
        raise ValidationError(
            f"extinction: coefficients must be finite and >= 0, "
            f"got {dict(zip(labels, k.tolist(), strict=True))}"
        )
    xv = np.asarray(x.values, dtype=np.float64)
    if np.any(xv[np.isfinite(xv)] < 1.0) or np.isinf(xv).any():
        raise ValidationError(
            f"cube: 'airmass' must be >= 1 (NaN below the horizon), got {xv.ravel()[:5].tolist()}"
        )
    kda = xr.DataArray(k, dims=(BAND,), coords={BAND: mags[BAND]})
    out = (mags + kda * x).transpose(*mags.dims, ...)
    out.name = mags.name
    out.attrs = dict(mags.attrs)
    out.attrs["extinction_coefficients"] = ", ".join(
        f"{b}: {v:g}" for b, v in zip(labels, k, strict=True)
    )
    out.attrs["extinction"] = "first-order law m(X) = m + k X, X the cube's 'airmass'"
    if np.isnan(xv).any():
        out.attrs["extinction_note"] = "NaN where the cube's airmass is NaN (below the horizon)"
    return out
