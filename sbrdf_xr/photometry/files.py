"""Photometry files: CF-1.10 netCDF that compliance checkers accept, and reading them back.

CF coordinate variables (a variable named after its dimension) are numeric; the band
and colour labels are strings.  In the file they are therefore auxiliary coordinates
``band_label`` and ``colour_label`` over the dimensions ``band`` and ``colour``;
:func:`open_photometry` restores the labelled index.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import xarray as xr

from ..errors import ValidationError

_SUFFIX = "_label"


def cf_encode(ds: xr.Dataset) -> xr.Dataset:
    """``ds`` with every string dimension coordinate ``d`` stored as ``d_label`` (no index)."""
    out = ds.copy()
    for dim in list(out.dims):
        if dim in out.coords and out[dim].dtype.kind in "OSU":
            attrs = dict(out[dim].attrs)
            out = out.reset_index(dim).rename_vars({dim: f"{dim}{_SUFFIX}"})
            out[f"{dim}{_SUFFIX}"].attrs = attrs
    return out


def cf_decode(ds: xr.Dataset) -> xr.Dataset:
    """Inverse of :func:`cf_encode`: ``d_label`` over ``d`` becomes the index of ``d``."""
    out = ds
    for name in list(out.coords):
        name = str(name)
        dim = name[: -len(_SUFFIX)] if name.endswith(_SUFFIX) else None
        if dim and out[name].dims == (dim,) and dim not in out.coords:
            out = out.rename_vars({name: dim}).set_xindex(dim)
    return out


def to_netcdf(ds: xr.Dataset, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
    """Write a :func:`~sbrdf_xr.photometry.photometry` Dataset as CF-1.10 netCDF, atomically.

    Magnitudes keep units ``1`` with ``magnitude_system`` stated; band and colour
    labels become auxiliary coordinates (:func:`cf_encode`); the global attributes get
    ``title``, ``source`` and a ``history`` line.

    Returns
    -------
    pathlib.Path
    """
    from ..material import write_netcdf_atomic

    if not isinstance(ds, xr.Dataset):
        raise ValidationError(f"ds: expected an xarray Dataset, got {type(ds).__name__}")
    enc = cf_encode(ds)
    for name in enc.variables:
        if enc[name].dtype.kind == "f" and not np.all(np.isfinite(enc[name].values)):
            enc[name].attrs.setdefault(
                "comment", "+inf where nothing reflects toward the observer; NaN where undefined"
            )
    return write_netcdf_atomic(enc, path, overwrite=overwrite)


def open_photometry(path: str | os.PathLike[str]) -> xr.Dataset:
    """Read a file written by :func:`to_netcdf` (loaded), band and colour labels as indexes."""
    with xr.open_dataset(path, engine="netcdf4") as ds:
        ds = ds.load()
    return cf_decode(ds)
