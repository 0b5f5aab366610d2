"""Photometry files: CF-1.10 netCDF that compliance checkers accept, and reading them back;
a CSV table of the magnitudes and colours.

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

from .._output import atomic_file, check_output, write_netcdf
from ..errors import ValidationError

__all__ = ["cf_decode", "cf_encode", "open_photometry", "to_csv", "to_netcdf"]

_SUFFIX = "_label"


def cf_encode(ds: xr.Dataset) -> xr.Dataset:
    """``ds`` with every string dimension coordinate ``d`` stored as ``d_label`` (no index).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.photometry import photometry
    >>> wl = np.arange(300.0, 1101.0, 10.0)
    >>> cube = xr.Dataset({"signal": (("geometry", "wavelength"), np.full((2, wl.size), 0.1),
    ...                               {"units": "m2 sr-1"})},
    ...                   coords={"wavelength": ("wavelength", wl, {"units": "nm"})})
    >>> ph = photometry(cube, ["B", "V"], 1000.0)
    >>> enc = cf_encode(ph)
    >>> "band" in enc.indexes, enc.band_label.values.tolist()
    (False, ['B', 'V'])
    """
    out = ds.copy()
    for dim in list(out.dims):
        if dim in out.coords and out[dim].dtype.kind in "OSU":
            attrs = dict(out[dim].attrs)
            out = out.reset_index(dim).rename_vars({dim: f"{dim}{_SUFFIX}"})
            out[f"{dim}{_SUFFIX}"].attrs = attrs
    return out


def cf_decode(ds: xr.Dataset) -> xr.Dataset:
    """Inverse of :func:`cf_encode`: ``d_label`` over ``d`` becomes the index of ``d``.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.photometry import photometry
    >>> wl = np.arange(300.0, 1101.0, 10.0)
    >>> cube = xr.Dataset({"signal": (("geometry", "wavelength"), np.full((2, wl.size), 0.1),
    ...                               {"units": "m2 sr-1"})},
    ...                   coords={"wavelength": ("wavelength", wl, {"units": "nm"})})
    >>> ph = photometry(cube, ["B", "V"], 1000.0)
    >>> back = cf_decode(cf_encode(ph))
    >>> back.indexes["band"].tolist(), back.identical(ph)
    (['B', 'V'], True)
    """
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

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.photometry import photometry
    >>> wl = np.arange(300.0, 1101.0, 10.0)
    >>> cube = xr.Dataset({"signal": (("geometry", "wavelength"), np.full((2, wl.size), 0.1),
    ...                               {"units": "m2 sr-1"})},
    ...                   coords={"wavelength": ("wavelength", wl, {"units": "nm"})})
    >>> ph = photometry(cube, ["B", "V"], 1000.0)
    >>> path = to_netcdf(ph, Path(tempfile.mkdtemp()) / "phot.nc")
    >>> path.name, open_photometry(path).attrs["Conventions"]
    ('phot.nc', 'CF-1.10')
    """
    if not isinstance(ds, xr.Dataset):
        raise ValidationError(f"ds: expected an xarray Dataset, got {type(ds).__name__}")
    enc = cf_encode(ds)
    for name in enc.variables:
        if enc[name].dtype.kind == "f" and not np.all(np.isfinite(enc[name].values)):
            enc[name].attrs.setdefault(
                "comment", "+inf where nothing reflects toward the observer; NaN where undefined"
            )
    return write_netcdf(enc, path, overwrite=overwrite)


def to_csv(ds: xr.Dataset, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
    """Write the magnitudes (``mag_<band>``) and colour indices of a
    :func:`~sbrdf_xr.photometry.photometry` Dataset as a CSV table, one row per geometry,
    atomically (a temporary file beside it, then a rename; only a regular file is replaced).

    Returns
    -------
    pathlib.Path

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.photometry import photometry
    >>> wl = np.arange(300.0, 1101.0, 10.0)
    >>> cube = xr.Dataset({"signal": (("geometry", "wavelength"), np.full((2, wl.size), 0.1),
    ...                               {"units": "m2 sr-1"})},
    ...                   coords={"wavelength": ("wavelength", wl, {"units": "nm"})})
    >>> ph = photometry(cube, ["B", "V"], 1000.0, pairs=[("B", "V")])
    >>> path = to_csv(ph, Path(tempfile.mkdtemp()) / "phot.csv")
    >>> path.read_text().splitlines()[0]
    'geometry,mag_B,mag_V,B-V'
    """
    if not isinstance(ds, xr.Dataset) or "magnitude" not in ds:
        raise ValidationError(
            f"ds: expected the Dataset of sbrdf_xr.photometry.photometry, got {type(ds).__name__}"
        )
    path = check_output(path, overwrite=overwrite)
    lead = set(ds.magnitude.dims) - {"band"}
    parts = [
        ds.magnitude.to_dataset(dim="band").rename({str(b): f"mag_{b}" for b in ds.band.values})
    ]
    if "colour_index" in ds:
        parts.append(ds.colour_index.to_dataset(dim="colour"))
    wide = xr.merge(parts, compat="override")
    wide = wide.drop_vars(
        [c for c in wide.coords if not set(wide[c].dims) <= lead or c in ("band", "colour")],
        errors="ignore",
    )
    with atomic_file(path, overwrite=overwrite) as tmp:
        wide.to_dataframe().to_csv(tmp)
    return path


def open_photometry(path: str | os.PathLike[str]) -> xr.Dataset:
    """Read a file written by :func:`to_netcdf` (loaded), band and colour labels as indexes.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.photometry import photometry
    >>> wl = np.arange(300.0, 1101.0, 10.0)
    >>> cube = xr.Dataset({"signal": (("geometry", "wavelength"), np.full((2, wl.size), 0.1),
    ...                               {"units": "m2 sr-1"})},
    ...                   coords={"wavelength": ("wavelength", wl, {"units": "nm"})})
    >>> ph = photometry(cube, ["B", "V"], 1000.0)
    >>> back = open_photometry(to_netcdf(ph, Path(tempfile.mkdtemp()) / "phot.nc"))
    >>> back.band.values.tolist(), bool(np.allclose(back.magnitude, ph.magnitude, rtol=0, atol=0))
    (['B', 'V'], True)
    """
    with xr.open_dataset(path, engine="netcdf4") as ds:
        ds = ds.load()
    return cf_decode(ds)
