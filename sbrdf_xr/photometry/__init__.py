"""Photometry: solar spectrum, filter bands, band signals, magnitudes, colours, light curves.

The chain from a simulation cube to what a telescope measures:

1. :func:`solar_spectrum` - the extraterrestrial Sun at 1 AU [W m-2 nm-1]: the
   ASTM G173-03 table shipped inside pvlib by default, or (``solar=``) the CALSPEC
   ``sun_reference_stis_001`` spectrum or the Kurucz 1993 solar model shipped inside
   pyphot (:data:`SOLAR_SPECTRA`; no network).  :func:`vega_spectrum` - CALSPEC
   ``alpha_lyr_stis_011``, also from pyphot.
2. :func:`filters` - standard bandpasses shipped inside speclite (Bessell UBVRI,
   SDSS ugriz, ...; short aliases in :data:`BAND_ALIASES`) and user bandpasses.
3. :func:`band_weights` - the ``(band, wavelength)`` matrix ``W`` with the Sun and
   the filter folded in, so that the band flux of any spectrum ``x`` sampled on a
   wavelength grid is ``W @ x``; :func:`pre_integrate` applies it along
   ``wavelength`` of any DataArray (material tables included).  Because the
   simulated signal is a sum over facets that is linear in the material tables,
   pre-integrating the tables and integrating the full-spectrum output give the same
   band numbers to float rounding.
4. :func:`band_signal` and :func:`magnitudes` from a cube; :func:`colour_indices`;
   :func:`srgb` swatches; :func:`photometry` bundles them (``ds.sbrdf.photometry``).
5. Measured light curves (reading observers' tables, the comparison with a simulation,
   its figure) are the package :mod:`sbrdf_xr.lightcurves`, which builds on this one.
6. :mod:`~sbrdf_xr.photometry.atmosphere` - air mass (:func:`airmass`, pvlib's
   models), extinction (:func:`apply_extinction`, :func:`transmission` folded into
   the band weights); :func:`standard_magnitude` (to a range, a phase angle, 1 AU),
   :func:`sun_distance_au`, :func:`at_resolution` (a spectrograph's resolution).
7. :func:`to_netcdf` / :func:`open_photometry` - CF-1.10 photometry files.
8. :mod:`~sbrdf_xr.photometry.colour_science` - colour-science spectra in and out: a
   ``SpectralDistribution`` or ``MultiSpectralDistributions`` is accepted as a filter,
   a solar spectrum (:func:`solar_name`) or a spectrum, and :func:`to_colour` exports
   any spectrum or cube variable to them.

Which library does what: speclite ships the filter curves; pvlib (ASTM G173) and pyphot
(CALSPEC, Kurucz) ship the solar and Vega spectra; the band integrals are this package's
own exact quadrature (:func:`hat_integrals`, cross-checked against colour-science's
integration in the tests); colour-science does the colorimetry of :func:`srgb` and the
conversions of ``colour_science``.

Units: every argument with a unit (wavelengths [nm], ranges [km], distances [au], angles
[degree], times [s], pressures [hPa]) also takes an astropy Quantity, converted first
(:func:`sbrdf_xr.units.to_unit`; another kind raises :class:`~sbrdf_xr.errors.UnitError`
naming the argument); bare wavelength axes and ranges far outside their unit's span warn
with the likely mistake.

Modules: ``spectra`` (reference spectra, quadrature), ``bands``, ``magnitude``,
``atmosphere``, ``limb`` (sunlight through the Earth's limb to a spacecraft:
:func:`limb_ray`, :func:`limb_transmission`), ``standard``, ``colour``,
``colour_science``, ``inband``, ``infrared``,
``files``.  The names of the measured-light-curve workflow that lived here
(``read_light_curve``, ``compare``, ``plot_comparison``,
``compare_magnitudes``, ...) are served under this old path until the next release, with a
:class:`~sbrdf_xr.errors.RenamedWarning` naming their new place in
:mod:`sbrdf_xr.lightcurves`.

Conventions
-----------
Band-integrated flux of a spectral flux density ``f(lambda)`` [W m-2 nm-1] through a
filter response ``T(lambda)`` is

* photon counting (default): ``F = int f T lambda / (h c) dlambda`` [m-2 s-1], the
  rate of detected photons, for responses that are photon-detection probabilities
  (the speclite convention);
* energy weighting: ``F = int f T dlambda`` [W m-2], for energy-response curves.

The *band signal* of a cube is the solar-weighted band mean of its radiometric
signal ``S(lambda)`` [m2 sr-1] (reflected intensity per unit solar irradiance)::

    S_band = int E_sun T w S dlambda / int E_sun T w dlambda        [m2 sr-1]

with ``w = lambda`` (photon) or ``1`` (energy).  It keeps the units of ``S``; a grey
body of signal ``c`` has ``S_band = c`` exactly, in every band.  The reflected
band flux at range ``d`` [m] from an object ``r`` AU from the Sun is
``F = F_sun,band S_band / (d**2 r**2)``, hence the magnitude

    m = m_sun,band(1 AU) + 5 log10(r / 1 AU) - 2.5 log10(S_band / d**2)

where ``m_sun,band`` is the Sun's apparent magnitude at 1 AU in the same band,
computed from the same solar spectrum and filter (:func:`sun_magnitudes`).

Magnitude systems (``system=``, any case, recorded in the attribute
``magnitude_system``; magnitudes have CF units ``"1"``):

* **AB** (default; Oke & Gunn 1983, ApJ 266, 713): a flat ``f_nu`` of 3631 Jy has
  magnitude 0 in every band::

    photon:  m_AB = -2.5 log10( int f_lambda T lambda dlambda / int f_AB,lambda T lambda dlambda )
    energy:  m_AB = -2.5 log10( int f_lambda T dlambda / int f_AB,lambda T dlambda )

  with ``f_AB,lambda = 3631 Jy * c / lambda**2``;
* **Vega**: the same with ``f_AB`` replaced by the CALSPEC spectrum of alpha Lyr
  (``alpha_lyr_stis_011``; Bohlin et al. 2020, AJ 160, 21), so Vega has magnitude 0
  in every band (the synthetic-photometry convention of synphot's VEGAMAG and
  pyphot).  The file ships inside the package pyphot (``pyphot/libs``); STScI
  CALSPEC data are public.

The Sun's magnitudes and colours (photon counting, ASTM G173-03; ``sun_magnitudes``)
against published values:

======  ========  =========  ================================================================
colour  AB        Vega       published
======  ========  =========  ================================================================
V       -26.768   -26.774    -26.76 +- 0.02 Vega (Willmer 2018, ApJS 236, 47)
B-V     0.525     0.651      0.653 +- 0.003 Vega (Ramirez et al. 2012, ApJ 752, 5)
U-B     1.007     0.121      0.166 +- 0.022 Vega (Ramirez et al. 2012)
V-R     0.194     0.391      0.356 +- 0.003 Vega, Cousins R (Ramirez et al. 2012)
V-I     0.289     0.732      0.701 +- 0.003 Vega, Cousins I (Ramirez et al. 2012)
g-r     0.476     0.733      0.44 +- 0.02 AB-like SDSS (Holmberg et al. 2006, MNRAS 367, 449);
                             0.45 AB, synthetic (Willmer 2018, Table 3)
r-i     0.115     0.336      0.11 +- 0.02 (Holmberg et al. 2006)
i-z     0.030     0.187      0.03 +- 0.02 (Holmberg et al. 2006)
======  ========  =========  ================================================================

The Sun's g-r: 0.476 here (Doi et al. 2010 SDSS responses at air mass 1.3, AB).  The
difference to the published 0.44 +- 0.02 is not in the integration, the solar
spectrum or the AB convention: pyphot's independent code with its own SDSS curves
gives 0.476 on the same Sun, the CALSPEC and Kurucz Suns 0.479 and 0.477, and the
SDSS g and r are AB to 0.01.  The 0.44 is empirical - Johnson-Cousins colours of
solar analogues transformed to SDSS (Holmberg et al. 2006) - and Willmer's
synthetic value from his composite Sun is 0.45; without the atmosphere
(``sdss2010noatm-*``) the synthetic value is 0.491 (the atmosphere at air mass 1.3
dims g more than r).  Synthetic g-r thus depends on the filter realisation by
0.02-0.04 mag, about the size of the empirical uncertainty; the tests hold it
to 0.05 of the published value.  Likewise the synthetic V-R and V-I with the
Bessell (1990) curves are 0.03 redder than Ramirez et al.'s solar-twin values.

A body that reflects nothing (``S_band = 0``) has magnitude ``+inf`` (zero flux;
computed without floating-point warnings); colour indices involving an infinite
magnitude are NaN (the colour is undefined).  A negative band signal (possible only
with noisy tables) gives a NaN magnitude.
"""

import importlib as _importlib
from typing import Any as _Any

from ..errors import renamed_attributes as _renamed_attributes
from . import (
    atmosphere,
    band_lookup,
    bands,
    colour,
    colour_science,
    files,
    inband,
    infrared,
    limb,
    magnitude,
    spectra,
    standard,
)
from .atmosphere import (
    AIRMASS_MODELS,
    airmass,
    apply_extinction,
    extinction_coefficients,
    rayleigh_optical_depth,
    transmission,
)
from .band_lookup import extinction_for_band
from .bands import (
    BAND_ALIASES,
    QUADRATURES,
    SPECTRUM_EXTRAPOLATIONS,
    WEIGHTINGS,
    band_weights,
    filters,
    pre_integrate,
    speclite_names,
)
from .colour import srgb
from .colour_science import from_colour, to_colour
from .files import cf_decode, cf_encode, open_photometry, to_netcdf
from .inband import in_band
from .limb import OZONE_OPTICAL_DEPTH_V, limb_ray, limb_transmission
from .magnitude import band_signal, colour_indices, magnitudes, photometry, sun_magnitudes
from .spectra import (
    AB_ZERO_POINT_JY,
    MAGNITUDE_SYSTEMS,
    SOLAR_SPECTRA,
    ab_reference_flux,
    check_system,
    hat_integrals,
    reference_flux,
    solar_name,
    solar_spectrum,
    trapezoid_weights,
    vega_spectrum,
)
from .standard import (
    PHASE_FUNCTIONS,
    at_resolution,
    lambert_sphere_phase,
    specular_sphere_phase,
    standard_magnitude,
    sun_distance_au,
)

__all__ = [
    "AB_ZERO_POINT_JY",
    "AIRMASS_MODELS",
    "BAND_ALIASES",
    "MAGNITUDE_SYSTEMS",
    "OZONE_OPTICAL_DEPTH_V",
    "PHASE_FUNCTIONS",
    "QUADRATURES",
    "SOLAR_SPECTRA",
    "SPECTRUM_EXTRAPOLATIONS",
    "WEIGHTINGS",
    "ab_reference_flux",
    "airmass",
    "apply_extinction",
    "at_resolution",
    "atmosphere",
    "band_lookup",
    "band_signal",
    "band_weights",
    "bands",
    "cf_decode",
    "cf_encode",
    "check_system",
    "colour",
    "colour_indices",
    "colour_science",
    "extinction_coefficients",
    "extinction_for_band",
    "files",
    "filters",
    "from_colour",
    "hat_integrals",
    "in_band",
    "inband",
    "infrared",
    "lambert_sphere_phase",
    "limb",
    "limb_ray",
    "limb_transmission",
    "magnitude",
    "magnitudes",
    "open_photometry",
    "photometry",
    "pre_integrate",
    "rayleigh_optical_depth",
    "reference_flux",
    "solar_name",
    "solar_spectrum",
    "speclite_names",
    "spectra",
    "specular_sphere_phase",
    "srgb",
    "standard",
    "standard_magnitude",
    "sun_distance_au",
    "sun_magnitudes",
    "to_colour",
    "to_netcdf",
    "transmission",
    "trapezoid_weights",
    "vega_spectrum",
]

#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
_RENAMED = _renamed_attributes(__name__, globals(), {"EXTRAPOLATIONS": "SPECTRUM_EXTRAPOLATIONS"})

#: Old name under ``sbrdf_xr.photometry`` -> its name in :mod:`sbrdf_xr.lightcurves`, where
#: the measured-light-curve workflow moved; served here with a RenamedWarning until the
#: next release.  The modules keep their old attribute names (``photometry.measured`` is
#: ``lightcurves.tables``).
_MOVED_TO_LIGHTCURVES = {
    "LIGHT_CURVE_ABSCISSAE": "LIGHT_CURVE_ABSCISSAE",
    "LIGHT_CURVE_COLUMNS": "LIGHT_CURVE_COLUMNS",
    "LIGHT_CURVE_OPTIONAL": "LIGHT_CURVE_OPTIONAL",
    "TABLE_FORMATS": "TABLE_FORMATS",
    "agreement": "agreement",
    "band_label": "band_label",
    "binned_residuals": "binned_residuals",
    "compare": "compare",
    "compare_light_curves": "compare_light_curves",
    "compare_magnitudes": "compare_magnitudes",
    "comparison_figure": "figure",
    "filter_names": "filter_names",
    "lightcurves": "comparison",
    "measured": "tables",
    "plot_comparison": "plot_comparison",
    "read_light_curve": "read_light_curve",
}


def __getattr__(name: str) -> _Any:
    if name in _MOVED_TO_LIGHTCURVES:
        # By name, on first use: photometry stands below lightcurves and imports nothing of it.
        moved = _importlib.import_module("sbrdf_xr.lightcurves")
        serve = _renamed_attributes(
            __name__, vars(moved), _MOVED_TO_LIGHTCURVES, new_module=moved.__name__
        )
        return serve(name)
    return _RENAMED(name)
