"""sbrdf_xr: spectral BRDF simulation of unresolved spacecraft with xarray and Dask.

Importing the package registers the ``.sbrdf`` xarray accessors.  The main entry
points: :func:`build_lut` and :func:`lookup` (materials), :func:`load_spacecraft` and
:func:`canx1` (spacecraft), :class:`Scene`, :func:`simulate` and :func:`write`
(simulations), :mod:`sbrdf_xr.photometry` (colour photometry) and
:mod:`sbrdf_xr.catalog` (shipped data).
"""

from __future__ import annotations

from . import accessors, catalog, errors, geometry, material  # noqa: F401
from ._version import __version__
from .material import (
    build_lut,
    constant_material,
    hemispherical_reflectance,
    lambertian,
    lookup,
    open_material,
)
from .scene import Scene, builtin_scene, load_scene
from .simulate import simulate, write
from .spacecraft import Spacecraft, canx1, load_spacecraft

__all__ = [
    "Scene",
    "Spacecraft",
    "__version__",
    "build_lut",
    "builtin_scene",
    "canx1",
    "catalog",
    "constant_material",
    "errors",
    "geometry",
    "hemispherical_reflectance",
    "lambertian",
    "load_scene",
    "load_spacecraft",
    "lookup",
    "material",
    "open_material",
    "simulate",
    "write",
]
