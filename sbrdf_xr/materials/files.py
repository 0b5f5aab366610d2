"""netCDF I/O of material tables and measurement sets (lossless, atomic)."""

from __future__ import annotations

import os
from pathlib import Path

import xarray as xr

from .._names import SBRDF
from .._output import write_netcdf
from ..errors import ValidationError
from .schema import validate_material, validate_measurements

__all__ = ["open_material", "open_measurements", "to_netcdf", "write_netcdf_atomic"]


# --------------------------------------------------------------------- I/O


def write_netcdf_atomic(
    ds: xr.Dataset, path: str | os.PathLike[str], *, overwrite: bool = False, complevel: int = 4
) -> Path:
    """Write ``ds`` to ``path`` atomically (a temporary file beside it, then a rename).

    The package's safe output (:func:`sbrdf_xr._output.write_netcdf`): only a regular file
    is ever replaced; a FIFO, socket, device, symbolic link or directory at ``path`` is
    refused.

    Parameters
    ----------
    ds : xarray.Dataset
        Dataset to write.
    path : path-like
        Destination.
    overwrite : bool, default False
        Replace an existing file; otherwise an existing file is an error and is left
        untouched.
    complevel : int, default 4
        zlib level (with the shuffle filter) of the floating-point data variables; 0
        writes them uncompressed (several times faster to write and read, twice the size).

    Returns
    -------
    pathlib.Path

    Raises
    ------
    FileExistsError
        ``path`` exists and ``overwrite`` is false.
    OutputError
        Something other than a regular file at ``path``, or the write failed (nothing
        was replaced).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import xarray as xr
    >>> from sbrdf_xr.materials.files import write_netcdf_atomic
    >>> ds = xr.Dataset({"x": ("n", [1.0, 2.0], {"units": "1", "long_name": "an example"})})
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = write_netcdf_atomic(ds, Path(tmp) / "example.nc")
    ...     again = xr.load_dataset(path)
    ...     names = sorted(p.name for p in Path(tmp).iterdir())
    >>> names, again.x.values.tolist(), again.attrs["Conventions"]
    (['example.nc'], [1.0, 2.0], 'CF-1.10')
    """
    return write_netcdf(ds, path, overwrite=overwrite, complevel=complevel)


def to_netcdf(
    obj: xr.DataArray | xr.Dataset,
    path: str | os.PathLike[str],
    *,
    overwrite: bool = False,
    complevel: int = 4,
) -> Path:
    """Write a material table or a measurement set to netCDF, losslessly and atomically.

    Values, coordinates and attributes survive :func:`open_material` /
    :func:`open_measurements` exactly (no fill values are added; float64 stays
    float64).

    Parameters
    ----------
    obj : xarray.DataArray or xarray.Dataset
        A material table or a measurement set (validated first).
    path : path-like
        Destination.
    overwrite : bool, default False
        Replace an existing file.
    complevel : int, default 4
        As :func:`write_netcdf_atomic`.

    Returns
    -------
    pathlib.Path

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.materials.files import open_material, to_netcdf
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> grey = lambertian(0.5, [500.0, 600.0])
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = to_netcdf(grey, Path(tmp) / "grey.nc")
    ...     back = open_material(path)
    >>> path.name, back.equals(grey), back.attrs["material"]
    ('grey.nc', True, 'lambertian-0.5')
    """
    if isinstance(obj, xr.DataArray):
        obj = validate_material(obj).to_dataset()
    else:
        validate_measurements(obj, duplicates="mean")
    obj = obj.copy()
    obj.attrs.setdefault("Conventions", "CF-1.10")
    return write_netcdf_atomic(obj, path, overwrite=overwrite, complevel=complevel)


def open_material(path: str | os.PathLike[str]) -> xr.DataArray:
    """Read a material table written by :func:`to_netcdf` (loaded into memory).

    Parameters
    ----------
    path : path-like
        A netCDF file with an ``sbrdf`` variable.

    Returns
    -------
    xarray.DataArray
        The validated table, with the file's global attributes merged into its own.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.materials.files import open_material, to_netcdf
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     table = open_material(to_netcdf(lambertian(0.2, [550.0]), Path(tmp) / "dark.nc"))
    >>> table.dims, table.attrs["material"]
    (('theta_i', 'delta_theta', 'phi', 'wavelength'), 'lambertian-0.2')
    """
    with xr.open_dataset(path, engine="netcdf4") as ds:
        ds = ds.load()
    if SBRDF not in ds:
        raise ValidationError(f"{path}: no 'sbrdf' variable; not a material table")
    da = ds[SBRDF]
    da.attrs = {**{k: v for k, v in ds.attrs.items() if k != "Conventions"}, **da.attrs}
    return validate_material(da)


def open_measurements(path: str | os.PathLike[str]) -> xr.Dataset:
    """Read a measurement set written by :func:`to_netcdf` (loaded into memory).

    Parameters
    ----------
    path : path-like
        A netCDF measurement set.

    Returns
    -------
    xarray.Dataset
        The validated measurement set, ``reference`` as booleans.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.materials.files import open_measurements, to_netcdf
    >>> from sbrdf_xr.testing import make_measurements
    >>> meas = make_measurements(n_wavelength=3, theta_i=(20.0, 50.0))
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     back = open_measurements(to_netcdf(meas, Path(tmp) / "meas.nc"))
    >>> back.reference.dtype, bool((back.measured_sbrdf == meas.measured_sbrdf).all())
    (dtype('bool'), True)
    """
    with xr.open_dataset(path, engine="netcdf4") as ds:
        ds = ds.load()
    if "reference" in ds:
        ref = ds["reference"].astype(bool)
        for k in ("flag_values", "flag_meanings"):  # they describe the on-disk byte, not the bool
            ref.attrs.pop(k, None)
        ds["reference"] = ref
    return validate_measurements(ds, duplicates="mean")
