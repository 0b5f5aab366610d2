"""The Earth's atmosphere between the object and a ground telescope: air mass and extinction.

Two ways to put the atmosphere into simulated magnitudes:

* **per-band extinction coefficients** ``k`` [magnitudes per unit air mass], the
  observers' first-order law ``m(X) = m_0 + k X`` (:func:`apply_extinction`), with
  ``X`` from the elevation by a named model (:func:`airmass`);
* a **spectral transmission** ``A(lambda) = exp(-tau(lambda) X)`` (:func:`transmission`:
  Rayleigh scattering and an Angstrom aerosol law) passed as ``transmission=`` to the
  band functions (``band_weights``, ``band_signal``, ``magnitudes``, ``photometry``,
  ``sun_magnitudes``), where it multiplies the sunlight inside the band integral.  The
  zero-magnitude reference stays outside the atmosphere, so the result is the
  magnitude a telescope at that air mass measures before extinction correction, with
  the colour dependence of the extinction included.  :func:`extinction_coefficients`
  gives the ``k`` this implies for a solar-coloured source.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from .._names import AIRMASS_MODELS, BAND, WAVELENGTH, attrs
from ..errors import ValidationError, renamed_keywords
from ..units import to_unit
from .spectra import _check_grid, _choose

#: Standard sea-level pressure [hPa].
SEA_LEVEL_HPA = 1013.25


def _values(x: Any) -> np.ndarray:
    return np.asarray(x.values if isinstance(x, xr.DataArray) else x, dtype=np.float64)


def airmass(elevation: ArrayLike | xr.DataArray, model: str = "kastenyoung1989") -> Any:
    """Relative optical air mass from the object's elevation above the horizon.

    The one air-mass function of the package (also :func:`sbrdf_xr.observing.airmass`).
    Dispatches to :func:`pvlib.atmosphere.get_relative_airmass` with zenith
    ``90 - elevation``; the models and their papers are listed in
    :data:`AIRMASS_MODELS` (default Kasten & Young 1989, Appl. Opt. 28, 4735, eq. 3:
    ``1 / (cos z + 0.50572 (96.07995 - z)^-1.6364)``).  Most models expect the apparent
    (refracted) elevation.

    Below the horizon (elevation < 0) the air mass is not defined and is NaN, so that a
    pass sampled through rise and set keeps its shape; NaN elevations give NaN.  At the
    horizon itself most models are finite (Kasten & Young: 37.92).

    Parameters
    ----------
    elevation : float, array_like, DataArray or Quantity
        Elevation above the horizon [degree], in [-90, 90].
    model : str
        A key of :data:`AIRMASS_MODELS`.

    Returns
    -------
    float, ndarray or DataArray
        Air mass [1] (1 at the zenith, NaN below the horizon), the same shape (a
        DataArray keeps its coordinates and gets the ``airmass`` attributes).

    Raises
    ------
    ValidationError
        Unknown model; an elevation outside [-90, 90] degree or infinite.

    Examples
    --------
    >>> np.round(airmass([90.0, 30.0, 10.0, -5.0]), 4)  # Kasten and Young (1989)
    array([0.9997, 1.9943, 5.586 ,    nan])
    """
    from pvlib.atmosphere import get_relative_airmass

    _choose(model, AIRMASS_MODELS, "airmass model")
    el = _values(to_unit(elevation, "deg", "elevation"))
    bad = np.isinf(el) | (np.abs(el) > 90.0)
    if np.any(bad):
        first = el.ravel()[np.flatnonzero(bad.ravel())[0]]
        raise ValidationError(
            f"elevation: must be in [-90, 90] degree (NaN below the horizon); "
            f"{int(bad.sum())} value(s) are not, the first is {first}"
        )
    up = el >= 0.0  # NaN compares False: stays NaN
    zenith = np.where(up, 90.0 - np.where(up, el, 0.0), 0.0)
    x = np.asarray(get_relative_airmass(zenith, model=model), dtype=np.float64)
    x = np.where(up, x, np.nan)
    if isinstance(elevation, xr.DataArray):
        return (
            elevation.copy(data=x)
            .rename("airmass")
            .assign_attrs(
                attrs(
                    "airmass", airmass_model=model, airmass_model_description=AIRMASS_MODELS[model]
                )
            )
        )
    return float(x) if x.ndim == 0 else x


def apply_extinction(mags: xr.DataArray, airmass: Any, coefficients: Any) -> xr.DataArray:
    """Magnitudes observed through the atmosphere: ``m(X) = m + k_band X``.

    The first-order extinction law (e.g. Sterken & Manfroid 1992, *Astronomical
    Photometry*, ch. 9): each band dims by its coefficient ``k`` times the air mass.

    Parameters
    ----------
    mags : xarray.DataArray
        Magnitudes over ``band`` (above the atmosphere).
    airmass : float, array_like or DataArray
        Air mass [1], >= 1; broadcast against ``mags`` (a DataArray aligns by dims).
    coefficients : mapping or DataArray
        ``k`` per band [magnitudes per air mass], >= 0: a mapping band label -> k,
        or a DataArray over ``band``.  Every band of ``mags`` needs one.

    Returns
    -------
    xarray.DataArray
        ``mags`` plus ``k X``, with attrs ``airmass`` (when scalar) and
        ``extinction_coefficients``.

    Examples
    --------
    >>> import xarray as xr
    >>> wl = np.arange(300.0, 1101.0, 10.0)
    >>> grey = np.full((2, wl.size), 0.1)  # 0.1 m2 sr-1 at every wavelength, two geometries
    >>> cube = xr.Dataset({"signal": (("geometry", "wavelength"), grey, {"units": "m2 sr-1"})},
    ...                   coords={"wavelength": ("wavelength", wl, {"units": "nm"})})
    >>> from sbrdf_xr.photometry import magnitudes
    >>> m = magnitudes(cube, ["B", "V"], range=1000.0)
    >>> seen = apply_extinction(m, 2.0, {"B": 0.25, "V": 0.15})
    >>> np.round((seen - m).isel(geometry=0).values, 6)
    array([0.5, 0.3])
    """
    if not isinstance(mags, xr.DataArray) or BAND not in mags.dims:
        raise ValidationError("mags: expected a DataArray with a 'band' dimension")
    labels = [str(b) for b in mags[BAND].values]
    if isinstance(coefficients, xr.DataArray):
        have = {
            str(b): float(v)
            for b, v in zip(coefficients[BAND].values, coefficients.values, strict=True)
        }
    elif isinstance(coefficients, dict):
        have = {str(b): float(v) for b, v in coefficients.items()}
    else:
        raise ValidationError(
            f"coefficients: expected a mapping band -> k or a DataArray over band, "
            f"got {type(coefficients).__name__}"
        )
    missing = [b for b in labels if b not in have]
    if missing:
        raise ValidationError(
            f"coefficients: no extinction coefficient for band(s) {missing}; "
            f"given for {sorted(have)}"
        )
    k = np.array([have[b] for b in labels])
    if not np.all(np.isfinite(k)) or np.any(k < 0):
        raise ValidationError(
            f"coefficients: must be finite and >= 0, got {dict(zip(labels, k, strict=True))}"
        )
    x = (
        airmass.astype(np.float64)
        if isinstance(airmass, xr.DataArray)
        else np.asarray(airmass, dtype=np.float64)
    )
    xv = _values(airmass)
    if xv.size == 0 or not np.all(np.isfinite(xv)) or np.any(xv < 1.0):
        raise ValidationError(f"airmass: must be finite and >= 1, got {xv.ravel()[:5].tolist()}")
    kda = xr.DataArray(k, dims=(BAND,), coords={BAND: mags[BAND]})
    out = mags + kda * x
    out = out.transpose(*mags.dims, ...)
    out.name = mags.name
    out.attrs = dict(mags.attrs)
    out.attrs["extinction_coefficients"] = ", ".join(
        f"{b}: {v:g}" for b, v in zip(labels, k, strict=True)
    )
    out.attrs["extinction"] = "first-order law m(X) = m + k X"
    if xv.ndim == 0:
        out.attrs["airmass"] = float(xv)
    return out


@renamed_keywords(pressure_hpa="pressure")
def rayleigh_optical_depth(wavelength: ArrayLike, pressure: float = SEA_LEVEL_HPA) -> np.ndarray:
    """Rayleigh-scattering optical depth of the atmosphere at the zenith.

    ``tau_R = 0.008569 l**-4 (1 + 0.0113 l**-2 + 0.00013 l**-4) P / 1013.25 hPa`` with
    ``l`` in micrometres (Hansen & Travis 1974, Space Sci. Rev. 16, 527, Eq. 2.29).

    Parameters
    ----------
    wavelength : array_like
        [nm]
    pressure : float
        Surface pressure [hPa] (1013.25 at sea level; about 780 at 2 km).

    Returns
    -------
    ndarray
        [1]

    Examples
    --------
    >>> np.round(rayleigh_optical_depth([400.0, 550.0, 700.0]), 4)
    array([0.3601, 0.0973, 0.0365])
    """
    lam = np.asarray(to_unit(wavelength, "nm", "wavelength", spectral=True), np.float64) / 1000.0
    pressure = to_unit(pressure, "hPa", "pressure")
    return (
        0.008569 * lam**-4 * (1.0 + 0.0113 * lam**-2 + 0.00013 * lam**-4) * pressure / SEA_LEVEL_HPA
    )


@renamed_keywords(pressure_hpa="pressure")
def transmission(
    wavelength: ArrayLike,
    airmass: float,
    *,
    pressure: float = SEA_LEVEL_HPA,
    aerosol_optical_depth: float = 0.05,
    angstrom_exponent: float = 1.3,
) -> xr.DataArray:
    """Spectral transmission of a clear atmosphere along a line of sight of air mass ``X``.

    ``A = exp(-(tau_R + tau_a) X)`` with Rayleigh scattering
    (:func:`rayleigh_optical_depth`) and aerosols by the Angstrom (1929, Geogr. Ann.
    11, 156) law ``tau_a = tau_a(550 nm) (lambda / 550 nm)**-alpha``.  Molecular
    absorption bands (ozone Chappuis band, O2, H2O) are not included: give a measured
    transmission curve (a DataArray over ``wavelength`` in [0, 1]) for those.

    Parameters
    ----------
    wavelength : array_like
        Strictly increasing [nm].
    airmass : float
        [1], >= 1.
    pressure : float
        Surface pressure [hPa].
    aerosol_optical_depth : float
        Aerosol optical depth at 550 nm at the zenith [1] (0.05: a clear site).
    angstrom_exponent : float
        [1]

    Returns
    -------
    xarray.DataArray
        ``transmission`` over ``wavelength`` [1], attrs ``airmass`` and
        ``model_description``; pass it as ``transmission=`` to the band functions.

    Examples
    --------
    >>> t = transmission([400.0, 550.0, 700.0], airmass=1.5)
    >>> t.attrs["units"], np.round(t.values, 4)
    ('1', array([0.5202, 0.8018, 0.8962]))
    """
    wl = _check_grid(wavelength, "wavelength")
    pressure = to_unit(pressure, "hPa", "pressure")
    for name, v, lo in (
        ("airmass", airmass, 1.0),
        ("pressure", pressure, 0.0),
        ("aerosol_optical_depth", aerosol_optical_depth, 0.0),
    ):
        if not np.isfinite(v) or v < lo:
            raise ValidationError(f"{name}: must be finite and >= {lo:g}, got {v}")
    if not np.isfinite(angstrom_exponent):
        raise ValidationError(f"angstrom_exponent: must be finite, got {angstrom_exponent}")
    tau = (
        rayleigh_optical_depth(wl, pressure)
        + aerosol_optical_depth * (wl / 550.0) ** -angstrom_exponent
    )
    desc = (
        f"Rayleigh (Hansen & Travis 1974, P = {pressure:g} hPa) + Angstrom aerosols "
        f"(tau_550 = {aerosol_optical_depth:g}, alpha = {angstrom_exponent:g}) "
        f"at air mass {airmass:g}"
    )
    return xr.DataArray(
        np.exp(-tau * airmass),
        dims=(WAVELENGTH,),
        coords={WAVELENGTH: (WAVELENGTH, wl, attrs(WAVELENGTH))},
        name="transmission",
        attrs=attrs("transmission", airmass=float(airmass), model_description=desc),
    )


def extinction_coefficients(
    bands: Any, *, system: str = "AB", solar: str = "astm_g173", **atmosphere: Any
) -> xr.DataArray:
    """Extinction coefficients ``k`` of a solar-coloured source for :func:`transmission`.

    ``k_band = m_sun(X = 1) - m_sun(above the atmosphere)``, the band integral of the
    Sun through the transmission at air mass 1 (:func:`~sbrdf_xr.photometry.sun_magnitudes`).

    Parameters
    ----------
    bands : str, sequence, mapping or DataArray
        See :func:`~sbrdf_xr.photometry.filters`.
    system, solar
        See :func:`~sbrdf_xr.photometry.sun_magnitudes` (``k`` does not depend on the system).
    **atmosphere
        Keyword arguments of :func:`transmission` other than ``airmass``.

    Returns
    -------
    xarray.DataArray
        ``extinction_coefficient`` over ``band`` [magnitudes per air mass].

    Examples
    --------
    >>> k = extinction_coefficients(["B", "V"])
    >>> k.attrs["units"], np.round(k.values, 3)  # [mag per air mass]
    ('1', array([0.328, 0.162]))
    """
    from .magnitude import sun_magnitudes
    from .spectra import _solar_native

    ws = _solar_native(solar)[0]
    t = transmission(ws, 1.0, **atmosphere)
    above = sun_magnitudes(bands, system=system, solar=solar)
    through = sun_magnitudes(bands, system=system, solar=solar, transmission=t)
    k = (through - above).rename("extinction_coefficient")
    k.attrs = attrs(
        "extinction_coefficient",
        model_description=t.attrs["model_description"].replace(" at air mass 1", ""),
        solar_spectrum=solar,
    )
    return k
