"""sbrdf_xr: spectral BRDF simulation of unresolved spacecraft with xarray and Dask.

Importing the package registers the ``.sbrdf`` xarray accessors: at once if xarray is
imported, or else the moment it is (``sbrdf_xr._startup.when_imported``).  The main entry
points: :func:`build_lut` and :func:`lookup` (materials), :func:`load_spacecraft` and
:func:`canx1` (spacecraft), :class:`Scene`, :func:`simulate` and :func:`write`
(simulations), :mod:`sbrdf_xr.photometry` (colour photometry) and
:mod:`sbrdf_xr.catalog` (shipped data).

The packages are the layers, lowest first; a package imports only from lower ones:

* shared by every layer: :mod:`~sbrdf_xr.errors`, :mod:`~sbrdf_xr.units`,
  :mod:`~sbrdf_xr.geometry` (the angle convention, ``psi`` of anisotropic materials, and
  attitudes as quaternions), :mod:`~sbrdf_xr.sources`;
* :mod:`~sbrdf_xr.kernels` (compiled and numpy kernels), :mod:`~sbrdf_xr.brdf`
  (analytic BRDF models);
* :mod:`~sbrdf_xr.materials` (tables, models, measurements), :mod:`~sbrdf_xr.body`
  (spacecraft meshes, facets, shadowing), :mod:`~sbrdf_xr.photometry` (bands,
  magnitudes, colours), :mod:`~sbrdf_xr.lightcurves` (measured light curves read and
  compared with a simulation), :mod:`~sbrdf_xr.observing` (orbits, sites, times,
  attitude laws, the Earth's shadow);
* :mod:`~sbrdf_xr.catalog` (the shipped data, loaded by kind);
* :mod:`~sbrdf_xr.store` (the output formats and cube writers) and :mod:`~sbrdf_xr.engine` (scenes,
  plans, simulation);
* users of everything: :mod:`~sbrdf_xr.invert`, :mod:`~sbrdf_xr.bench`,
  :mod:`~sbrdf_xr.plot`, :mod:`~sbrdf_xr.accessors`, :mod:`~sbrdf_xr.testing` and
  :mod:`~sbrdf_xr.cli`.

``dir(sbrdf_xr)`` lists :data:`__all__`: the functions and classes above and every
public package and module, each imported on first use, so that ``import sbrdf_xr`` loads
none of xarray, pandas, NumPy, Dask, numba, trimesh, netCDF4 or SciPy.
"""

import importlib as _importlib
from typing import TYPE_CHECKING

from . import _startup  # first: Ctrl-C while the command line starts
from ._names import __version__

if TYPE_CHECKING:  # what __getattr__ serves, for type checkers
    from .body import Spacecraft, canx1, load_spacecraft
    from .engine import Scene, builtin_scene, load_scene, simulate
    from .materials import (
        build_lut,
        constant_material,
        hemispherical_reflectance,
        lambertian,
        lookup,
        open_material,
    )
    from .store import write

#: The functions and classes published here -> the package that defines them (imported on
#: first use).
_EXPORTS = {
    "Spacecraft": "body",
    "canx1": "body",
    "load_spacecraft": "body",
    "Scene": "engine",
    "builtin_scene": "engine",
    "load_scene": "engine",
    "simulate": "engine",
    "build_lut": "materials",
    "constant_material": "materials",
    "hemispherical_reflectance": "materials",
    "lambertian": "materials",
    "lookup": "materials",
    "open_material": "materials",
    "write": "store",
}

#: The public modules and packages, reachable as attributes (imported on first use).
_SUBMODULES = (
    "accessors",
    "bench",
    "body",
    "brdf",
    "catalog",
    "cli",
    "engine",
    "errors",
    "geometry",
    "invert",
    "kernels",
    "lightcurves",
    "materials",
    "observing",
    "photometry",
    "plot",
    "sources",
    "store",
    "testing",
    "units",
)

__all__ = [
    "Scene",
    "Spacecraft",
    "__version__",
    "accessors",
    "bench",
    "body",
    "brdf",
    "build_lut",
    "builtin_scene",
    "canx1",
    "catalog",
    "cli",
    "constant_material",
    "engine",
    "errors",
    "geometry",
    "hemispherical_reflectance",
    "invert",
    "kernels",
    "lambertian",
    "lightcurves",
    "load_scene",
    "load_spacecraft",
    "lookup",
    "materials",
    "observing",
    "open_material",
    "photometry",
    "plot",
    "simulate",
    "sources",
    "store",
    "testing",
    "units",
    "write",
]


assert set(_SUBMODULES) | set(_EXPORTS) <= set(__all__)


def _register_accessors(xarray: object) -> None:
    """Register the ``.sbrdf`` accessors (xarray is imported)."""
    _importlib.import_module(f"{__name__}.accessors")


_startup.when_imported("xarray", _register_accessors)


def __getattr__(name: str) -> object:
    if name in _SUBMODULES:
        return _importlib.import_module(f"{__name__}.{name}")
    if name in _EXPORTS:
        value = getattr(_importlib.import_module(f"{__name__}.{_EXPORTS[name]}"), name)
        globals()[name] = value  # found directly from now on
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return list(__all__)
