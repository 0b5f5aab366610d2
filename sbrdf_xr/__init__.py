"""sbrdf_xr: spectral BRDF simulation of unresolved spacecraft with xarray and Dask.

Importing the package registers the ``.sbrdf`` xarray accessors.
"""

from __future__ import annotations

__version__ = "0.1.0"

from . import accessors, catalog, errors, geometry, material  # noqa: F401
from .material import build_lut, hemispherical_reflectance, lookup, open_material

__all__ = [
    "__version__",
    "build_lut",
    "catalog",
    "errors",
    "geometry",
    "hemispherical_reflectance",
    "lookup",
    "material",
    "open_material",
]
