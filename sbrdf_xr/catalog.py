"""The catalogs that ship with sbrdf_xr: materials, measurement sets, paint parameters, spacecraft.

The catalog directory holds ``index.toml``, one ``[[entry]]`` table per item::

    [[entry]]
    name = "lambertian-grey-50"          # unique, lower-case, used by load()
    kind = "material"                    # material | measurements | model
                                         # | paint_parameters | spacecraft
                                         # | orbit (a TLE file)
                                         # | site (a table of a TOML file of sites)
    path = "materials/lambertian-grey-50.nc"   # relative to the catalog directory
    source = "synthetic"                 # measured | synthetic | model:<name>
    description = "..."                  # what it is
    provenance = "..."                   # where its numbers come from

In a source checkout the directory is the top-level ``catalogs/``; an installed
package carries a copy at ``sbrdf_xr/catalogs`` (see ``pyproject.toml``).

The catalog sits above the domain modules: it imports them and maps every kind to
the function that builds its object from an entry (:data:`LOADERS`); none of them
imports it (they read an entry's file given the entry, from
:mod:`sbrdf_xr._catalog_index`).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import xarray as xr

from . import material, models, observe, spacecraft
from ._cache import cached_table
from ._catalog_index import (
    KINDS,
    SOURCES,
    CatalogEntry,
    _index,  # noqa: F401  (re-exported: tools clear its cache after writing the index)
    catalog_dir,
    data_path,
    entries,
    entry,
    names,
)
from .errors import CatalogError

__all__ = [
    "KINDS",
    "LOADERS",
    "SOURCES",
    "CatalogEntry",
    "catalog_dir",
    "data_path",
    "entries",
    "entry",
    "load",
    "names",
]


def _load_material(e: CatalogEntry) -> xr.DataArray:
    """A table file, or (``build_from`` set) a table built from a measurement entry."""
    source = e.extra.get("build_from")
    if source is None:
        return material.open_material(e.file)
    options = tuple(sorted(e.extra.get("build", {}).items()))
    return _built_material(e.name, source, options).copy(deep=True)


@functools.lru_cache(maxsize=16)
def _built_material(
    name: str, measurements: str, options: tuple[tuple[str, Any], ...]
) -> xr.DataArray:
    """A table built from a measurement entry, through the disk cache (:mod:`sbrdf_xr._cache`)."""
    kw = dict(options)
    inputs = [entry(measurements).file] + ([entry(kw["fit"]).file] if "fit" in kw else [])

    def build() -> xr.DataArray:
        opts = dict(kw)
        if "fit" in opts:  # a model entry that fills the unmeasurable range
            opts["model"] = load(opts.pop("fit"))
        return material.build_lut(load(measurements), material=name, **opts)

    def read(path: Any) -> xr.DataArray:
        da = material.open_material(path)
        for k in _FILE_ATTRS:  # what writing a file adds, not what the build made
            da.attrs.pop(k, None)
        return da

    return cached_table(
        name,
        inputs,
        repr(options),
        build,
        lambda da, path: material.to_netcdf(da, path, overwrite=True),
        read,
    )


#: Attributes the netCDF writer adds to a file (CF/ACDD basics) that a built table lacks.
_FILE_ATTRS = ("title", "history")


def _load_paint_parameters(e: CatalogEntry) -> xr.Dataset:
    with xr.open_dataset(e.file, engine="netcdf4") as ds:
        return ds.load()


#: Loader per kind: takes the entry, returns the loaded object.
LOADERS: dict[str, Callable[[CatalogEntry], Any]] = {
    "material": _load_material,
    "measurements": lambda e: material.open_measurements(e.file),
    "model": lambda e: models.open_model(e.file),
    "paint_parameters": _load_paint_parameters,
    "spacecraft": spacecraft.load_catalog_entry,
    "orbit": observe.load_orbit_entry,
    "site": observe.load_site_entry,
}
assert set(LOADERS) == set(KINDS)


def load(name: str) -> Any:
    """Load a catalog entry by name.

    Parameters
    ----------
    name : str
        Entry name (see :func:`names` or ``sbrdf-xr catalog list``).

    Returns
    -------
    object
        A material ``DataArray`` for ``material``; a measurement ``Dataset`` for
        ``measurements``; a parameter ``Dataset`` for ``model`` (see
        :mod:`sbrdf_xr.models`) and ``paint_parameters``; a
        :class:`~sbrdf_xr.spacecraft.Spacecraft` for ``spacecraft``; an
        :class:`~sbrdf_xr.observe.Orbit` for ``orbit``; a :class:`~sbrdf_xr.observe.Site`
        for ``site``.
    """
    e = entry(name)
    try:
        loader = LOADERS[e.kind]
    except KeyError:  # pragma: no cover - every kind has a loader (asserted above)
        raise CatalogError(f"no loader for catalog kind {e.kind!r}") from None
    return loader(e)
