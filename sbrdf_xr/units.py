"""Units at the door: astropy Quantities converted, bare numbers in the documented unit.

Every public argument of the package that carries a unit is named bare and states the
unit in brackets in its docstring (``range`` [km], ``wavelength`` [nm], ``step`` [s],
``latitude`` [degree]; docs/guide/conventions.md) and passes through :func:`to_unit`
before anything else:

* an astropy :class:`~astropy.units.Quantity` is converted to that unit (``1e6 * u.m``
  given as ``range`` is 1000 km; ``0.5 * u.rad`` as ``phase_angle`` is 28.6479 degree;
  wavelengths also from frequencies and wavenumbers, by astropy's spectral equivalency);
* temperatures also from degrees Celsius or Fahrenheit (astropy's ``temperature``
  equivalency);
* an xarray DataArray whose data is a Quantity (xarray keeps one as it is) is returned
  with its data converted, its dims and coordinates kept and its ``units`` attribute
  stating the unit (a material table in ``1 / deg2`` becomes one in ``sr-1``);
* a Quantity of another kind (a time given for a length) is refused with
  :class:`~sbrdf_xr.errors.UnitError`, naming the argument, the unit received and the
  unit expected;
* anything else is returned unchanged: a bare number is in the documented unit.

Bare numbers far outside the plausible span of their unit warn with the likely mistake
(:class:`~sbrdf_xr.errors.UnitWarning`): :func:`check_wavelengths` (a nanometre axis
holding micrometres or metres), :func:`check_plausible` (ranges, distances, mesh sizes
against the bounds of :data:`PLAUSIBLE`).  Length units of files (:func:`metres_per`)
are read case-sensitively where SI prefixes differ only by case (``Mm`` is the
megametre, ``mm`` the millimetre).

astropy is imported only when a Quantity can exist, that is once the caller has
imported :mod:`astropy.units` itself.
"""

from __future__ import annotations

import sys
import warnings
from typing import Any

import numpy as np

from .errors import UnitError, UnitWarning

__all__ = [
    "LENGTH_UNITS",
    "PLAUSIBLE",
    "check_plausible",
    "check_wavelengths",
    "is_quantity",
    "metres_per",
    "to_unit",
]

#: Plausible spans of bare numbers: name -> (unit, low, high, what a value below ``low``
#: most likely is and the factor that would turn it into ``unit``, the same above
#: ``high``).  A value outside warns (:func:`check_plausible`); the span is wide on
#: purpose: it catches a unit mistaken by a factor of 1000, not an unusual case.
PLAUSIBLE: dict[str, tuple[str, float, float, tuple[str, float], tuple[str, float]]] = {
    # observer-object ranges: a lab bench (1 m) to beyond the Moon's orbit (1e7 km)
    "range_km": ("km", 1e-3, 1e7, ("", 1.0), ("metres", 1e-3)),
    # Sun-object distances: from inside Mercury's orbit to beyond the planets
    "sun_distance_au": ("au", 0.05, 100.0, ("", 1.0), ("km", 1.0 / 149597870.7)),
    # the largest side of a spacecraft mesh: 1 mm to 500 m (the ISS spans 109 m)
    "mesh_size_m": ("m", 1e-3, 500.0, ("km", 1e3), ("millimetres", 1e-3)),
}

#: Length units of mesh files and their size in metres [m].  Symbols are matched exactly
#: first; otherwise without regard to case, except ``Mm`` (the megametre, never the
#: millimetre).
LENGTH_UNITS: dict[str, float] = {
    "m": 1.0,
    "meter": 1.0,
    "metre": 1.0,
    "meters": 1.0,
    "metres": 1.0,
    "km": 1.0e3,
    "cm": 1.0e-2,
    "centimeter": 1.0e-2,
    "centimetre": 1.0e-2,
    "centimeters": 1.0e-2,
    "centimetres": 1.0e-2,
    "mm": 1.0e-3,
    "millimeter": 1.0e-3,
    "millimetre": 1.0e-3,
    "millimeters": 1.0e-3,
    "millimetres": 1.0e-3,
    "um": 1.0e-6,
    "micrometer": 1.0e-6,
    "micrometre": 1.0e-6,
    "in": 0.0254,
    "inch": 0.0254,
    "inches": 0.0254,
    "ft": 0.3048,
    "foot": 0.3048,
    "feet": 0.3048,
}

#: Symbols whose case changes their meaning (SI prefixes): symbol -> what it is.
_CASE_SENSITIVE = {"Mm": "the megametre (1e6 m); the millimetre is 'mm'"}


def is_quantity(value: Any) -> bool:
    """True if ``value`` is an astropy Quantity (without importing astropy).

    Examples
    --------
    >>> import astropy.units as u
    >>> is_quantity(3.0 * u.km), is_quantity(3.0), is_quantity(np.array([1.0]))
    (True, False, False)
    """
    units_mod = sys.modules.get("astropy.units")
    return units_mod is not None and isinstance(value, units_mod.Quantity)


def to_unit(value: Any, unit: str, what: str, *, spectral: bool = False) -> Any:
    """``value`` in ``unit``: a Quantity converted, anything else returned unchanged.

    Parameters
    ----------
    value : Any
        The argument as given.
    unit : str
        Its documented unit, an astropy unit string (``"km"``, ``"nm"``, ``"deg"``,
        ``"deg / s"``, ``"s"``, ``"au"``, ``"m"``, ``""`` for a dimensionless number).
    what : str
        The argument's name, for the message.
    spectral : bool
        A wavelength: frequencies, wavenumbers and photon energies convert too
        (astropy's ``spectral`` equivalency).

    Returns
    -------
    Any
        A float (scalar Quantity) or a float64 array in ``unit``, a DataArray holding a
        Quantity with its data so converted (its ``units`` attribute set to ``unit``), or
        ``value`` itself.

    Raises
    ------
    UnitError
        For a Quantity whose unit does not convert to ``unit``.

    Examples
    --------
    >>> import astropy.units as u
    >>> to_unit(1e6 * u.m, "km", "range_km"), to_unit(1000.0, "km", "range_km")
    (1000.0, 1000.0)
    >>> to_unit([0.4, 0.5] * u.um, "nm", "wavelength")
    array([400., 500.])
    >>> to_unit(5e14 * u.Hz, "nm", "wavelength", spectral=True)
    599.584916
    >>> round(to_unit(0.5 * u.rad, "deg", "phase_deg"), 4)
    28.6479
    >>> import xarray as xr
    >>> to_unit(xr.DataArray([0.5, 1.0] * u.rad, dims="x"), "deg", "theta_i").round(4).values
    array([28.6479, 57.2958])
    >>> to_unit(xr.DataArray([1.0] / u.deg**2, dims="x"), "sr-1", "sbrdf").attrs["units"]
    'sr-1'
    >>> to_unit(1.0 / u.deg**2, "sr-1", "sbrdf")
    3282.806350011744
    >>> to_unit(3.0 * u.s, "km", "range_km")
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.UnitError: range_km: got 3.0 s (time), which is not in km (length); ...
    """
    if not is_quantity(value):
        data = getattr(value, "data", None) if hasattr(value, "dims") else None
        if not is_quantity(data):
            return value
        out = value.copy(data=np.asarray(to_unit(data, unit, what, spectral=spectral)))
        return out.assign_attrs(units=unit or "1")
    import astropy.units as u

    target = u.Unit(unit) if unit else u.dimensionless_unscaled
    equiv = [*(u.spectral() if spectral else []), *u.temperature()]
    try:
        out = value.to_value(target, equivalencies=equiv)
    except (u.UnitConversionError, u.UnitsError, TypeError, ValueError):
        got, kind = value.unit.physical_type, target.physical_type
        shown = (
            value
            if value.size <= 8
            else f"{value.size} values of shape {value.shape} in {value.unit}"
        )
        raise UnitError(
            f"{what}: got {shown}{f' ({got})' if got != 'unknown' else ''}, which is not in "
            f"{unit or 'a dimensionless number'}{f' ({kind})' if kind != 'unknown' else ''}; "
            f"give a Quantity convertible to {unit or 'a number'} or a bare number in "
            f"{unit or 'no unit'}"
        ) from None
    arr = np.asarray(out, dtype=np.float64)
    return float(arr) if arr.ndim == 0 else arr


def _span(values: Any) -> tuple[float, float] | None:
    v = np.asarray(values.values if hasattr(values, "dims") else values, dtype=np.float64)
    v = v[np.isfinite(v) & (v > 0)]
    return (float(v.min()), float(v.max())) if v.size else None


def _warn(message: str) -> None:
    warnings.warn(message, UnitWarning, stacklevel=3)


def check_plausible(values: Any, kind: str, what: str, fix: str | None = None) -> bool:
    """Warn when positive ``values`` lie all below or all above the span of :data:`PLAUSIBLE`.

    Parameters
    ----------
    values : array_like or DataArray
        Bare numbers in the unit of ``kind`` (non-finite and non-positive values are
        ignored: other checks refuse them).
    kind : str
        A key of :data:`PLAUSIBLE`.
    what : str
        The argument's name, for the message.
    fix : str, optional
        How to state the unit, ending the message (default: give a Quantity).

    Returns
    -------
    bool
        True when the values are plausible (no warning).

    Warns
    -----
    UnitWarning
        Naming the values, the unit they are read in and the unit they most likely are.

    Examples
    --------
    >>> check_plausible([800.0, 1500.0], "range_km", "range_km")
    True
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     check_plausible(1.2e9, "range_km", "range_km")
    False
    >>> print(caught[0].message)  # doctest: +NORMALIZE_WHITESPACE
    range_km: 1.2e+09 km is above the plausible 1e+07 km: metres? the value is read in km
    (1.2e+06 km if it were metres); give a Quantity (e.g. 1000 * u.km) to be explicit
    """
    unit, low, high, below, above = PLAUSIBLE[kind]
    span = _span(values)
    if span is None:
        return True
    lo, hi = span
    shown = f"{lo:g}" if lo == hi else f"{lo:g}-{hi:g}"
    for bad, bound, side, (guess, factor) in (
        (hi < low, low, "below", below),
        (lo > high, high, "above", above),
    ):
        if bad:
            likely = (
                f": {guess}? the value is read in {unit} ("
                + (f"{lo * factor:g}" if lo == hi else f"{lo * factor:g}-{hi * factor:g}")
                + f" {unit} if it were {guess})"
                if guess
                else f"; the value is read in {unit}"
            )
            _warn(
                f"{what}: {shown} {unit} is {side} the plausible {bound:g} {unit}{likely}; "
                + (fix or f"give a Quantity (e.g. 1000 * u.{unit}) to be explicit")
            )
            return False
    return True


def check_wavelengths(values: Any, what: str) -> bool:
    """Warn when a wavelength axis in nanometres most likely holds micrometres or metres.

    An axis whose largest value is below 30 nm (no spacecraft reflectance is modelled in
    the extreme ultraviolet) is taken for micrometres (below 3e-5: metres); one whose
    smallest value is above 1e5 nm (100 micrometres) is beyond the thermal infrared.

    Parameters
    ----------
    values : array_like
        Wavelengths [nm], finite and > 0 (others are ignored here).
    what : str
        The axis's name, for the message.

    Returns
    -------
    bool
        True when no warning was issued.

    Examples
    --------
    >>> check_wavelengths([400.0, 1100.0], "wavelength")
    True
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     check_wavelengths([0.4, 0.7, 1.1], "wavelength")
    False
    >>> print(caught[0].message)  # doctest: +NORMALIZE_WHITESPACE
    wavelength: wavelengths 0.4-1.1: micrometres? the axis is in nm (400-1100 nm if
    they were micrometres); give a Quantity (e.g. [0.4, 1.1] * u.um) to be explicit
    """
    span = _span(values)
    if span is None:
        return True
    lo, hi = span
    for bad, guess, factor, sym in (
        (hi < 3e-5, "metres", 1e9, "m"),
        (3e-5 <= hi < 30.0, "micrometres", 1e3, "um"),
    ):
        if bad:
            _warn(
                f"{what}: wavelengths {lo:g}-{hi:g}: {guess}? the axis is in nm "
                f"({lo * factor:g}-{hi * factor:g} nm if they were {guess}); give a "
                f"Quantity (e.g. [{lo:g}, {hi:g}] * u.{sym}) to be explicit"
            )
            return False
    if lo > 1e5:
        _warn(
            f"{what}: wavelengths {lo:g}-{hi:g} nm lie beyond 100 micrometres; the axis is "
            "in nm: give a Quantity (e.g. [400, 1100] * u.nm) to be explicit"
        )
        return False
    return True


def metres_per(unit: Any, what: str = "length_unit") -> float:
    """Size of one length unit in metres: a name of :data:`LENGTH_UNITS` or an astropy unit.

    Parameters
    ----------
    unit : str, astropy unit or Quantity
        ``"mm"``, ``"in"``, ... (exact symbols first, then any case except where case
        changes the meaning: ``"Mm"`` is the megametre and is refused for a mesh), an
        astropy length unit (``u.mm``) or a length Quantity (one file unit, e.g.
        ``25.4 * u.mm``).
    what : str
        The argument's name, for the message.

    Returns
    -------
    float
        Metres per unit [m].

    Raises
    ------
    UnitError
        For an unknown or non-length unit, or the megametre.

    Examples
    --------
    >>> import astropy.units as u
    >>> metres_per("mm"), metres_per("MM"), metres_per("in"), metres_per(u.cm)
    (0.001, 0.001, 0.0254, 0.01)
    >>> metres_per("Mm")
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.UnitError: length_unit: 'Mm' is the megametre (1e6 m); the millimetre ...
    """
    if isinstance(unit, str):
        key = unit.strip()
        if key in LENGTH_UNITS:
            return LENGTH_UNITS[key]
        if key in _CASE_SENSITIVE:
            raise UnitError(
                f"{what}: {key!r} is {_CASE_SENSITIVE[key]} (SI prefixes are case-sensitive); "
                "a spacecraft mesh in megametres is implausible: write 'mm' for millimetres"
            )
        if key.lower() in LENGTH_UNITS:
            return LENGTH_UNITS[key.lower()]
        raise UnitError(
            f"{what}: got {unit!r}, which is not a length unit; allowed: "
            f"{', '.join(LENGTH_UNITS)} (or an astropy length unit)"
        )
    units_mod = sys.modules.get("astropy.units")
    if units_mod is not None and isinstance(unit, units_mod.UnitBase | units_mod.Quantity):
        one = unit if isinstance(unit, units_mod.Quantity) else 1.0 * unit
        return float(to_unit(one, "m", what))
    raise UnitError(
        f"{what}: expected a length unit name ({', '.join(list(LENGTH_UNITS)[:8])}, ...) or "
        f"an astropy length unit, got {type(unit).__name__}"
    )
