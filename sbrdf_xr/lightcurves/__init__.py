"""Measured light curves: observers' tables read, compared with a simulation, drawn.

The workflow from what a telescope recorded to how well the model explains it:

1. :func:`read_light_curve` (module :mod:`~sbrdf_xr.lightcurves.tables`) reads CSV,
   ECSV, FITS, VOTable and netCDF tables, long or wide, in any row order, magnitudes or
   flux densities, UTC times or Julian dates; filter names as observers write them are
   mapped to the package's bands by :func:`band_label`
   (:mod:`~sbrdf_xr.lightcurves.filter_names`).
2. :func:`compare` (:mod:`~sbrdf_xr.lightcurves.comparison`) fits a measured light curve
   against a simulated pass or rotation sweep: zero points, extinction, time shift or
   rotation phase, with uncertainties; :func:`plot_comparison`
   (:mod:`~sbrdf_xr.lightcurves.figure`) draws the result.
3. :func:`compare_magnitudes` and :func:`binned_residuals`
   (:mod:`~sbrdf_xr.lightcurves.agreement`): predicted against observed magnitudes at
   many geometries after one zero point.

The synthetic photometry these compare with (bands, magnitudes, colours, the atmosphere)
is :mod:`sbrdf_xr.photometry`; this package builds on it and it knows nothing of this
one.  Until the next release the names here are also served, with a
:class:`~sbrdf_xr.errors.RenamedWarning`, under their old path ``sbrdf_xr.photometry``.

Units: every argument with a unit (times [s], angles [degree]) also takes an astropy
Quantity, converted first (:func:`sbrdf_xr.units.to_unit`).
"""

from . import agreement, comparison, figure, filter_names, tables
from .agreement import binned_residuals, compare_magnitudes
from .comparison import compare, compare_light_curves
from .figure import plot_comparison
from .filter_names import band_label
from .tables import (
    LIGHT_CURVE_ABSCISSAE,
    LIGHT_CURVE_COLUMNS,
    LIGHT_CURVE_OPTIONAL,
    TABLE_FORMATS,
    read_light_curve,
)

__all__ = [
    "LIGHT_CURVE_ABSCISSAE",
    "LIGHT_CURVE_COLUMNS",
    "LIGHT_CURVE_OPTIONAL",
    "TABLE_FORMATS",
    "agreement",
    "band_label",
    "binned_residuals",
    "compare",
    "compare_light_curves",
    "compare_magnitudes",
    "comparison",
    "figure",
    "filter_names",
    "plot_comparison",
    "read_light_curve",
    "tables",
]
