"""The design of an unmixing: candidate library, measured values and their weights.

See :func:`sbrdf_xr.invert.unmix`.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr

from ..errors import InversionError

__all__ = ["MATERIAL", "design", "library"]

MATERIAL = "material"
WAVELENGTH = "wavelength"
BAND = "band"


def _describe(grid: np.ndarray | None) -> str:
    if grid is None:
        return "none"
    if grid.dtype.kind in "fi" and grid.size:
        return f"{grid.size} values {grid.min():g}..{grid.max():g}"
    return f"{list(grid)}"


def spectral_dim(da: xr.DataArray, what: str) -> str:
    dims = [d for d in (WAVELENGTH, BAND) if d in da.dims]
    if len(dims) != 1:
        raise InversionError(
            f"{what}: expected exactly one of the dimensions wavelength or band, got {da.dims}"
        )
    return dims[0]


def _on_measured_grid(
    name: str, da: xr.DataArray, measured: xr.DataArray, notes: list[str]
) -> xr.DataArray:
    """One candidate of a mapping on the spectral grid of the measurement."""
    if not isinstance(da, xr.DataArray):
        raise InversionError(
            f"candidate library: {name!r} is a {type(da).__name__}, expected a DataArray"
        )
    dim = spectral_dim(measured, "measured")
    if dim not in da.dims:
        raise InversionError(
            f"candidate library: {name!r} has dimensions {da.dims}; the measurement is over {dim}"
        )
    if dim == BAND:
        have = [str(b) for b in da[BAND].values] if BAND in da.coords else []
        missing = [str(b) for b in measured[BAND].values if str(b) not in have]
        if missing:
            raise InversionError(
                f"candidate library: {name!r} has no bands {missing} (it has {have})"
            )
        return da.sel({BAND: measured[BAND].values})
    wl = np.asarray(da[WAVELENGTH].values, dtype=np.float64)
    mw = np.asarray(measured[WAVELENGTH].values, dtype=np.float64)
    if wl.shape == mw.shape and np.allclose(wl, mw, rtol=0, atol=1e-9):
        return da.assign_coords({WAVELENGTH: mw})
    lo, hi = float(wl.min()), float(wl.max())
    out = mw[(mw < lo - 1e-9) | (mw > hi + 1e-9)]
    if out.size:
        raise InversionError(
            f"candidate library: {name!r} covers {lo:g}..{hi:g} nm, the measurement "
            f"{out.min():g}..{out.max():g} nm lies outside it; give the candidate on a grid "
            "that covers the measured wavelengths"
        )
    notes.append(
        f"{name!r} interpolated linearly from {_describe(wl)} nm to the measured grid "
        f"({_describe(mw)} nm)"
    )
    return da.interp({WAVELENGTH: mw})


def library(simulated: Any, measured: xr.DataArray) -> tuple[xr.DataArray, list[str]]:
    """Per-material terms as one DataArray with a ``material`` dimension, and notes on how
    candidates on other spectral grids were put on the measured one."""
    notes: list[str] = []
    if isinstance(simulated, xr.Dataset):
        if "signal_material" not in simulated:
            raise InversionError(
                "simulated: a Dataset needs the variable signal_material "
                f"(simulate with outputs=(..., 'per_material')); got {list(simulated.data_vars)}"
            )
        simulated = simulated["signal_material"]
    if isinstance(simulated, Mapping):
        items = [(str(k), v) for k, v in simulated.items()]
        if not items:
            raise InversionError("simulated: the candidate library is empty")
        names = [k for k, _ in items]
        dupes = sorted({k for k in names if names.count(k) > 1})
        if dupes:
            raise InversionError(f"candidate library: names {dupes} appear more than once")
        arrays = [_on_measured_grid(k, v, measured, notes) for k, v in items]
        try:
            arrays = list(xr.align(*arrays, join="exact"))
        except ValueError as exc:
            raise InversionError(
                "candidate library: the candidates differ in a non-spectral coordinate "
                f"(geometry, time, ...): {exc}; simulate every candidate at the same geometries"
            ) from None
        simulated = xr.concat(
            arrays, dim=xr.DataArray(names, dims=MATERIAL, name=MATERIAL), coords="minimal"
        )
    if not isinstance(simulated, xr.DataArray) or MATERIAL not in simulated.dims:
        raise InversionError(
            "simulated: expected a DataArray with a material dimension "
            "(signal_material), a Dataset holding one, or a mapping of name to DataArray"
        )
    if simulated.sizes[MATERIAL] == 0:
        raise InversionError("simulated: the candidate library is empty")
    return simulated, notes


def _align(measured: xr.DataArray, lib: xr.DataArray) -> xr.DataArray:
    """The library on the measured spectral grid (linear interpolation in wavelength)."""
    dim = spectral_dim(measured, "measured")
    if dim not in lib.dims:
        raise InversionError(
            f"measured is over {dim} but the simulation is over {spectral_dim(lib, 'simulated')}"
        )
    if dim == BAND:
        have = [str(b) for b in lib[BAND].values]
        missing = [str(b) for b in measured[BAND].values if str(b) not in have]
        if missing:
            raise InversionError(
                f"measured bands {missing} are not among the simulated bands {have}"
            )
        return lib.sel({BAND: measured[BAND].values})
    wl, mw = lib[WAVELENGTH].values, measured[WAVELENGTH].values
    lo, hi = float(wl.min()), float(wl.max())
    out = mw[(mw < lo - 1e-9) | (mw > hi + 1e-9)]
    if out.size:
        raise InversionError(
            f"measured wavelengths {out.min():g}..{out.max():g} nm lie outside the simulated "
            f"range {lo:g}..{hi:g} nm"
        )
    if wl.shape == mw.shape and np.allclose(wl, mw):
        return lib.assign_coords({WAVELENGTH: mw})
    return lib.interp({WAVELENGTH: mw})


def design(
    measured: xr.DataArray, uncertainty: Any, lib: xr.DataArray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rows (every sample and wavelength) of ``A``, ``y`` and ``sigma``."""
    lib = _align(measured, lib)
    sigma = (
        uncertainty
        if isinstance(uncertainty, xr.DataArray)
        else xr.DataArray(
            np.broadcast_to(np.asarray(uncertainty, dtype=np.float64), measured.shape),
            dims=measured.dims,
            coords=measured.coords,
        )
    )
    y, sigma = xr.broadcast(measured, sigma)
    extra = [d for d in lib.dims if d not in y.dims and d != MATERIAL]
    if extra:
        raise InversionError(
            f"simulated has dimensions {extra} that measured lacks; select one geometry "
            "(--isel DIM=INDEX) or give measurements over them"
        )
    sample_dims = list(y.dims)
    a = lib.transpose(*[d for d in sample_dims if d in lib.dims], MATERIAL)
    a = a.broadcast_like(y).transpose(*sample_dims, MATERIAL)
    yv, sv = y.values.reshape(-1).astype(np.float64), sigma.values.reshape(-1).astype(np.float64)
    if yv.size == 0:
        raise InversionError("measured: no values (an empty spectrum)")
    if not np.all(np.isfinite(yv)):
        raise InversionError(
            f"measured: {int((~np.isfinite(yv)).sum())} of {yv.size} values are NaN or "
            "infinite; every measured value must be finite (drop the rows that are not)"
        )
    bad = ~(np.isfinite(sv) & (sv > 0))
    if bad.any():
        raise InversionError(
            f"uncertainty: must be finite and > 0, got {int(bad.sum())} values that are not "
            f"(e.g. {sv[bad][0]!r})"
        )
    av = a.values.reshape(-1, lib.sizes[MATERIAL]).astype(np.float64)
    if not np.all(np.isfinite(av)):
        raise InversionError("simulated: per-material terms contain NaN or infinite values")
    return av, yv, sv
