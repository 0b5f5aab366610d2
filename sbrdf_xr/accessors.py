"""xarray accessors: ``da.sbrdf.<method>`` forwards to the module functions.

Compose, never subclass: every accessor method is a one-line call of the function
documented in :mod:`sbrdf_xr.materials.tables` or :mod:`sbrdf_xr.photometry`.  Importing
:mod:`sbrdf_xr` registers the accessors, at once if xarray is imported or else right after
xarray's first import (``sbrdf_xr._startup.when_imported``), so that they are on every
xarray object whichever of the two is imported first; each method imports the module it
calls on its first call, so that registering them loads nothing but xarray.
"""

from __future__ import annotations

from typing import Any

import xarray as xr
from numpy.typing import ArrayLike

from .errors import renamed_keywords

__all__ = ["SbrdfDataArrayAccessor", "SbrdfDatasetAccessor"]


@xr.register_dataarray_accessor("sbrdf")
class SbrdfDataArrayAccessor:
    """Methods of a material table, as ``da.sbrdf.lookup(...)`` and friends.

    Each method forwards to the function of the same name in :mod:`sbrdf_xr.materials.tables`.

    Examples
    --------
    Importing :mod:`sbrdf_xr` registers the accessor on every DataArray:

    >>> import numpy as np
    >>> import sbrdf_xr
    >>> grey = sbrdf_xr.lambertian(0.5, [500.0, 600.0])
    >>> spectrum = grey.sbrdf.lookup(30.0, -5.0, 2.0)
    >>> spectrum.dims, np.round(spectrum.values, 6)
    (('wavelength',), array([0.159155, 0.159155]))
    >>> np.round(grey.sbrdf.hemispherical_reflectance([0.0, 60.0]).values, 4)
    array([[0.5, 0.5],
           [0.5, 0.5]])
    """

    def __init__(self, da: xr.DataArray) -> None:
        self._da = da

    def validate(self, **kwargs: Any) -> xr.DataArray:
        """:func:`sbrdf_xr.materials.tables.validate_material`."""
        from .materials import tables as _material

        return _material.validate_material(self._da, **kwargs)

    def lookup(
        self,
        theta_i: ArrayLike | xr.DataArray,
        delta_theta: ArrayLike | xr.DataArray,
        phi: ArrayLike | xr.DataArray,
        method: str = "linear",
    ) -> xr.DataArray:
        """:func:`sbrdf_xr.materials.tables.lookup` on this table."""
        from .materials import tables as _material

        return _material.lookup(self._da, theta_i, delta_theta, phi, method=method)

    def hemispherical_reflectance(
        self, theta_i: ArrayLike | None = None, **kwargs: Any
    ) -> xr.DataArray:
        """:func:`sbrdf_xr.materials.energy.hemispherical_reflectance` of this table."""
        from .materials import energy as _energy

        return _energy.hemispherical_reflectance(self._da, theta_i, **kwargs)

    def to_netcdf(self, path: Any, **kwargs: Any) -> Any:
        """:func:`sbrdf_xr.materials.tables.to_netcdf` of this table."""
        from .materials import tables as _material

        return _material.to_netcdf(self._da, path, **kwargs)

    @property
    def plot(self) -> _Plotter:
        """Figures of this array.

        ``da.sbrdf.plot.magnitudes()``, ``da.sbrdf.plot.lut_slice(30)``.
        """
        return _Plotter(self._da, {"magnitudes": "magnitude_curves", "lut_slice": "lut_slice"})


class _Plotter:
    """Forwards to :mod:`sbrdf_xr.plot`; calling it draws the object's natural figure."""

    def __init__(self, obj: Any, methods: dict[str, str]) -> None:
        self._obj = obj
        self._methods = methods

    def __call__(self, **kwargs: Any) -> Any:
        from . import plot as _plot

        if isinstance(self._obj, xr.Dataset):
            return _plot.cube_figure(self._obj, **kwargs)
        if "band" in self._obj.dims:
            return _plot.magnitude_curves(self._obj, **kwargs)
        raise AttributeError(
            "no natural figure for this array; use .lut_slice(theta_i) for a material table"
        )

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_") or name not in self._methods:
            raise AttributeError(f"sbrdf.plot has no {name!r}; available: {sorted(self._methods)}")
        from functools import partial

        from . import plot as _plot

        return partial(getattr(_plot, self._methods[name]), self._obj)

    def __dir__(self) -> list[str]:
        return sorted(self._methods)


@xr.register_dataset_accessor("sbrdf")
class SbrdfDatasetAccessor:
    """Methods of a simulation cube, as ``ds.sbrdf.photometry(...)`` and friends.

    Each method forwards to the function of the same name in :mod:`sbrdf_xr.photometry`,
    on the cube with the variables its writer left out computed again
    (:meth:`with_derived`): a cube opened with :func:`xarray.open_dataset` works as one
    opened with :func:`sbrdf_xr.store.open_cube`.

    Examples
    --------
    On a simulation cube (here a hand-made one: a grey signal of ``1/pi`` m2 sr-1 at
    every wavelength), band means and magnitudes:

    >>> import numpy as np
    >>> import xarray as xr
    >>> import sbrdf_xr
    >>> wl = np.linspace(400.0, 1000.0, 61)
    >>> cube = xr.Dataset(
    ...     {"signal": (("geometry", "wavelength"), np.full((1, 61), 1 / np.pi))},
    ...     coords={"wavelength": ("wavelength", wl, {"units": "nm"})},
    ... )
    >>> cube.signal.attrs["units"] = "m2 sr-1"
    >>> band = cube.sbrdf.band_signal(["V"])
    >>> band.dims, round(float(band.squeeze()), 6)
    (('geometry', 'band'), 0.31831)
    >>> cube.sbrdf.magnitudes(["V", "R"], range=1000).round(3).values
    array([[4.475, 4.28 ]])
    """

    def __init__(self, ds: xr.Dataset) -> None:
        self._raw = ds

    @property
    def _ds(self) -> xr.Dataset:
        return self.with_derived()

    def with_derived(self) -> xr.Dataset:
        """:func:`sbrdf_xr.store.derived.with_derived` of this cube: the variables its
        writer left out (``signal``, ``brdf``; its attribute ``derived_variables``)
        computed again, so ``cube.sbrdf.with_derived().signal`` reads as before the write."""
        from .store import derived

        return derived.with_derived(self._raw)

    @renamed_keywords(range_km="range")
    def photometry(self, bands: Any, range: Any = None, **kwargs: Any) -> xr.Dataset:
        """:func:`sbrdf_xr.photometry.photometry` of this cube (its own ``range`` and
        ``sun_distance`` unless given).

        Parameters
        ----------
        bands : str, sequence, mapping or DataArray
            See :func:`sbrdf_xr.photometry.filters`.
        range : float, array_like, DataArray or astropy Quantity, optional
            Observer range [km], > 0; default the cube's ``range``.
        **kwargs
            The other keywords of :func:`sbrdf_xr.photometry.photometry`.
        """
        from . import photometry as _phot

        return _phot.photometry(self._ds, bands, range, **kwargs)

    def band_signal(self, bands: Any, **kwargs: Any) -> xr.DataArray:
        """:func:`sbrdf_xr.photometry.band_signal` of this cube."""
        from . import photometry as _phot

        return _phot.band_signal(self._ds, bands, **kwargs)

    @renamed_keywords(range_km="range")
    def magnitudes(self, bands: Any = None, range: Any = None, **kwargs: Any) -> xr.DataArray:
        """:func:`sbrdf_xr.photometry.magnitudes` of this cube (its own ``range`` and
        ``sun_distance`` unless given; ``extinction={band: k}`` with its ``airmass``).

        Parameters
        ----------
        bands : str, sequence, mapping or DataArray
            See :func:`sbrdf_xr.photometry.filters`.
        range : float, array_like, DataArray or astropy Quantity, optional
            Observer range [km], > 0; default the cube's ``range``.
        **kwargs
            The other keywords of :func:`sbrdf_xr.photometry.magnitudes`.
        """
        from . import photometry as _phot

        return _phot.magnitudes(self._ds, bands, range, **kwargs)

    def srgb(self, **kwargs: Any) -> xr.DataArray:
        """:func:`sbrdf_xr.photometry.srgb` of this cube."""
        from . import photometry as _phot

        return _phot.srgb(self._ds, **kwargs)

    def to_colour(self, variable: str = "signal") -> Any:
        """:func:`sbrdf_xr.photometry.to_colour` of this cube's ``variable``: colour-science
        spectra, one per geometry."""
        from . import photometry as _phot

        return _phot.to_colour(self._ds, variable)

    @property
    def plot(self) -> _Plotter:
        """Figures of this cube: ``ds.sbrdf.plot()`` (its natural figure), ``.light_curve()``,
        ``.spectra()``, ``.colour_colour("B-V", "V-R")`` (a photometry Dataset)."""
        return _Plotter(
            self._ds,
            {
                "light_curve": "light_curve",
                "spectra": "spectrum_curves",
                "colour_colour": "colour_colour",
            },
        )
