"""Model reflectances shipped beside the catalog's fits: a table build's costliest step, done once.

A catalog table built with ``renormalise="model"`` (:func:`sbrdf_xr.materials.build_lut`)
scales every row ``(theta_i, wavelength)`` by its model's directional-hemispherical
reflectance, a quadrature of some 1e8 Fresnel evaluations for a microfacet model (two
thirds of the build).  It depends only on the model file, the rows, the wavelengths and
the code that computes it, so ``tools/build_catalog.py`` computes it once and ships it
as ``<fit>-reflectance.nc`` beside the fit.  The file records a digest of those inputs
(:func:`reflectance_digest`); :func:`read_reflectance` returns it only when the digest
is current, so a table built with it is the table built without it, value for value,
and a changed model or code falls back to the quadrature.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import xarray as xr

from .._names import THETA_I, WAVELENGTH
from .._output import write_netcdf
from . import models
from ._fill import _model_reflectance
from .cache import build_modules

__all__ = ["REFLECTANCE_SUFFIX", "read_reflectance", "reflectance_digest", "write_reflectance"]

#: The shipped reflectance of ``<fit>.nc`` is ``<fit>-reflectance.nc``.
REFLECTANCE_SUFFIX = "-reflectance.nc"

#: The modules whose code computes a model's reflectance for a build (their import
#: closure): the models, their BRDFs and Fresnel terms, and the build's own step.
_ROOTS = ("sbrdf_xr.materials.models", "sbrdf_xr.materials.build")


def reflectance_file(fit_file: Path) -> Path:
    """Where the shipped reflectance of model file ``fit_file`` lives.

    Examples
    --------
    >>> from pathlib import Path
    >>> reflectance_file(Path("materials/tjpv-cell-coated-fit.nc")).name
    'tjpv-cell-coated-fit-reflectance.nc'
    """
    return fit_file.with_name(fit_file.stem + REFLECTANCE_SUFFIX)


def reflectance_digest(fit_file: Path, theta_i: np.ndarray, wavelength: np.ndarray) -> str:
    """SHA-256 of what a model's reflectance depends on: the model file's bytes, the rows
    ``theta_i`` [degree] and ``wavelength`` [nm] (float64), and the sources of the code
    that computes it.

    Parameters
    ----------
    fit_file : pathlib.Path
        The model's netCDF file.
    theta_i, wavelength : ndarray
        The table's incidence angles [degree] and wavelengths [nm].

    Returns
    -------
    str

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.catalog import entry
    >>> fit = entry("white-paint-a276-fit").file
    >>> a = reflectance_digest(fit, np.arange(91.0), np.array([500.0]))
    >>> b = reflectance_digest(fit, np.arange(91.0), np.array([501.0]))
    >>> len(a), a == b
    (64, False)
    """
    h = hashlib.sha256(Path(fit_file).read_bytes())
    for a in (theta_i, wavelength):
        h.update(np.ascontiguousarray(a, dtype=np.float64).tobytes())
        h.update(b"|")
    for f in build_modules(_ROOTS):
        h.update(f.name.encode() + b"\0" + f.read_bytes())
    return h.hexdigest()


def write_reflectance(fit_file: Path, theta_i: np.ndarray, wavelength: np.ndarray) -> Path:
    """Compute the reflectance of model file ``fit_file`` at ``theta_i`` x ``wavelength``
    (the build's own computation) and write it beside the file with its digest.

    Parameters
    ----------
    fit_file : pathlib.Path
        The model's netCDF file.
    theta_i, wavelength : ndarray
        The table's incidence angles [degree] and wavelengths [nm].

    Returns
    -------
    pathlib.Path
        The file written (:func:`reflectance_file`).

    Examples
    --------
    ``tools/build_catalog.py`` writes the catalog's (tens of seconds for a thin-film model):

    >>> from sbrdf_xr.materials.shipped import write_reflectance
    >>> write_reflectance  # doctest: +ELLIPSIS
    <function write_reflectance at 0x...>
    """
    ti = np.asarray(theta_i, dtype=np.float64)
    wl = np.asarray(wavelength, dtype=np.float64)
    model = models.open_model(fit_file)
    rho = _model_reflectance(model, ti, wl, lambda fraction: None)
    da = xr.DataArray(
        rho,
        dims=(THETA_I, WAVELENGTH),
        coords={
            THETA_I: (THETA_I, ti, {"units": "degree", "long_name": "incidence angle"}),
            WAVELENGTH: (WAVELENGTH, wl, {"units": "nm", "long_name": "wavelength"}),
        },
        name="model_reflectance",
        attrs={
            "units": "1",
            "long_name": "directional-hemispherical reflectance of the model",
            "model_file": Path(fit_file).name,
            "digest": reflectance_digest(fit_file, ti, wl),
        },
    )
    out = reflectance_file(Path(fit_file))
    write_netcdf(da.to_dataset(), out, overwrite=True)  # CF-clean: no fill values
    return out


def read_reflectance(
    fit_file: Path, theta_i: np.ndarray, wavelength: np.ndarray
) -> xr.DataArray | None:
    """The shipped reflectance of model file ``fit_file`` at ``theta_i`` x ``wavelength``,
    or None when there is none or its digest is not current (changed model, rows,
    wavelengths or code).

    Parameters
    ----------
    fit_file : pathlib.Path
        The model's netCDF file.
    theta_i, wavelength : ndarray
        The table's incidence angles [degree] and wavelengths [nm].

    Returns
    -------
    xarray.DataArray or None
        Dims ``(theta_i, wavelength)`` [1].

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.catalog import entry
    >>> fit = entry("white-paint-a276-fit").file
    >>> read_reflectance(fit, np.arange(91.0), np.array([500.0])) is None  # other rows
    True
    """
    path = reflectance_file(Path(fit_file))
    if not path.is_file():
        return None
    with xr.open_dataarray(path, engine="netcdf4") as da:
        if da.attrs.get("digest") != reflectance_digest(fit_file, theta_i, wavelength):
            return None
        return da.load()
