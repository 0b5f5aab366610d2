"""sbrdf_xr: spectral BRDF simulation of unresolved spacecraft with xarray and Dask."""

from __future__ import annotations

__version__ = "0.1.0"

from . import errors, geometry  # noqa: F401
