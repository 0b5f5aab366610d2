"""Observations: a real orbit, an observer site, UTC times and an attitude law.

From an :class:`Orbit` (a TLE or an OMM, propagated by SGP4 through skyfield's
:class:`~skyfield.sgp4lib.EarthSatellite`), a :class:`Site` and times,
:meth:`Observation.geometry` computes per time the body-frame unit vectors to the Sun,
the observer and the Earth under an attitude law (:mod:`sbrdf_xr.attitude`), and the
range, elevation, azimuth, phase angle, solar elongation, Sun distance, Earth-shadow
state (a sunlit fraction with penumbra) and airmass.

Frames and models
-----------------
* Inertial frame: the GCRS (geocentric, ICRF axes) of skyfield; attitudes rotate body
  vectors into it.  SGP4 states (TEME) are rotated to the GCRS by skyfield.
* Ephemeris ``de421.bsp`` and Earth orientation (UT1-UTC and polar motion from
  ``finals2000A.all``) come from the ``skyfield-data`` package, loaded from its
  directory by a skyfield :class:`~skyfield.iokit.Loader`: nothing is downloaded.
* The Sun direction is the apparent direction from the spacecraft: skyfield's geocentric
  apparent Sun (light time, aberration, deflection) on knots every 10 min, splined, moved
  to the spacecraft and aberrated by its geocentric velocity (within 1 mas of skyfield's
  ``(earth + satellite).at(t).observe(sun).apparent()``).  The observer
  direction is geometric (no light time: under 3 ms, a few arcseconds in LEO) and
  without refraction, as is skyfield's ``(satellite - site).at(t).altaz()``.
* Nutation: IAU 2000A and the equation of the equinoxes evaluated on 10-min knots and
  splined (they vary over days), so that one skyfield pass serves thousands of times.
* Elevation and azimuth (from north through east) are taken in the site's geodetic
  (WGS84) horizon.
* Earth shadow: a spherical Earth of radius :data:`EARTH_RADIUS_KM` and the Sun's finite
  disc (radius :data:`SUN_RADIUS_KM`); the sunlit fraction is the fraction of the
  apparent solar disc not covered by the apparent Earth disc, from the exact area of
  overlap of the two circles (Montenbruck & Gill, *Satellite Orbits*, 2000, §3.4.2,
  eqs. 3.85-3.89).  No atmosphere (refraction, absorption) is modelled.
* Airmass: relative airmass of the geometric elevation by a pvlib model
  (:func:`pvlib.atmosphere.get_relative_airmass`), Kasten & Young (1989) by default;
  NaN below the horizon.
"""

from __future__ import annotations

import datetime as _dt
import json
import time as _time
import tomllib
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike, NDArray

from . import _catalog_index
from . import attitude as _att
from ._names import VECTOR
from .errors import (
    AttitudeError,
    CatalogError,
    EpochGapWarning,
    NotObservableError,
    ObservationError,
)
from .geometry import rotation_matrices

__all__ = [
    "AIRMASS_MODELS",
    "ATTRS",
    "EARTH_RADIUS_KM",
    "EPOCH_GAP_DAYS",
    "SUN_RADIUS_KM",
    "TIME",
    "Observation",
    "Orbit",
    "Site",
    "airmass",
    "bench_geometry",
    "canx1_pass",
    "disc_overlap_fraction",
    "load_orbit_entry",
    "load_site_entry",
    "observation_from_dict",
    "sunlit_fraction",
    "times",
]

#: Name of the time dimension.
TIME = "time"
#: Name of the quaternion component dimension.
COMPONENT = "component"
#: Equatorial radius of the Earth (WGS84) used by the shadow model [km].
EARTH_RADIUS_KM = 6378.137
#: Nominal solar radius (IAU 2015 Resolution B3) [km].
SUN_RADIUS_KM = 695700.0
#: Astronomical unit (IAU 2012 Resolution B2) [km].
AU_KM = 149597870.700
#: Times farther than this from the element epoch raise an :class:`EpochGapWarning` [day]:
#: SGP4 errors of LEO elements grow by about 1-3 km per day from the epoch.
EPOCH_GAP_DAYS = 7.0
#: Relative airmass models of :func:`pvlib.atmosphere.get_relative_airmass`.
AIRMASS_MODELS = ("simple", "kasten1966", "youngirvine1967", "kastenyoung1989", "gueymard1993",
                  "young1994", "pickering2002", "gueymard2003")

#: CF attributes of every variable of :meth:`Observation.geometry`.
ATTRS: dict[str, dict[str, str]] = {
    TIME: {"long_name": "time (UTC)", "standard_name": "time"},
    COMPONENT: {"units": "1", "long_name": "quaternion component (scalar last)"},
    "to_sun": {"units": "1", "long_name": "unit vector toward the Sun in the body frame"},
    "to_observer": {"units": "1", "long_name": "unit vector toward the observer in the body frame"},
    "to_earth": {"units": "1", "long_name": "unit vector toward the Earth's centre in the body frame"},
    "quaternion": {"units": "1", "long_name": "attitude quaternion, body to GCRS, scalar last"},
    "range": {"units": "km", "long_name": "distance from the observer to the spacecraft"},
    "elevation": {"units": "degree", "long_name": "elevation of the spacecraft above the observer's geodetic horizon"},
    "azimuth": {"units": "degree", "long_name": "azimuth of the spacecraft from north through east"},
    "phase_angle": {"units": "degree", "long_name": "angle between the Sun and observer directions"},
    "solar_elongation": {"units": "degree", "long_name": "angle between the Sun and the spacecraft seen by the observer"},
    "sun_distance": {"units": "au", "long_name": "distance from the spacecraft to the Sun"},
    "sunlit_fraction": {"units": "1", "long_name": "fraction of the solar disc seen from the spacecraft not hidden by the Earth"},
    "airmass": {"units": "1", "long_name": "relative airmass along the line of sight"},
    "earth_distance": {"units": "km", "long_name": "distance from the spacecraft to the Earth's centre"},
    "earth_phase_angle": {"units": "degree", "long_name": "Sun-Earth-spacecraft angle seen from the Earth's centre"},
    "site_sun_elevation": {"units": "degree", "long_name": "elevation of the Sun above the observer's horizon"},
    VECTOR: {"units": "1", "long_name": "Cartesian component in the spacecraft body frame"},
}

_NS = np.dtype("datetime64[ns]")


# --------------------------------------------------------------------------- skyfield data


@cache
def _skyfield() -> tuple[Any, Any]:
    """Timescale (with polar motion) and ephemeris from the ``skyfield-data`` directory."""
    import skyfield_data
    from skyfield.api import Loader
    from skyfield.data import iers

    with warnings.catch_warnings():
        # skyfield-data warns when its finals file is past its nominal expiry date; the
        # measured values it holds are still the right ones for past dates, and later
        # dates fall back to skyfield's delta-T model.
        warnings.simplefilter("ignore", RuntimeWarning)
        path = skyfield_data.get_skyfield_data_path()
    loader = Loader(path, verbose=False)
    ts = loader.timescale(builtin=False)
    with loader.open("finals2000A.all") as f:
        iers.install_polar_motion_table(ts, iers.parse_x_y_dut1_from_finals_all(f))
    return ts, loader("de421.bsp")


#: Spacing of the knots at which the slowly varying parts of the Earth orientation and
#: the geocentric Sun are evaluated by skyfield, then cubic-spline interpolated [s].
#: Nutation's fastest sizeable term (13.66 d, 0.2 arcsec) and the Earth-Sun vector
#: (fourth derivative |r| (2 pi / yr)^4 ~ 2e-19 km s-4) are then exact to far below a
#: microarcsecond and a millimetre.
KNOT_S = 600.0


def _knots(t64: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Seconds of ``t64`` from its start, and spline knots covering them (>= 4)."""
    secs = (t64 - t64[0]).astype(np.int64) / 1e9
    span = float(secs[-1])
    n = max(4, int(np.ceil(span / KNOT_S)) + 3)
    return secs, np.linspace(-KNOT_S, span + KNOT_S, n)


def _utc(t64: np.ndarray) -> Any:
    ts, _ = _skyfield()
    day = t64.astype("datetime64[D]")
    month = day.astype("datetime64[M]")
    year = month.astype("datetime64[Y]")
    sec = (t64 - day).astype(np.int64) / 1e9
    return ts.utc(year.astype(np.int64) + 1970, month.astype(np.int64) % 12 + 1,
                  (day - month).astype(np.int64) + 1, 0, 0, sec)


def _skyfield_time(t64: np.ndarray) -> Any:
    """skyfield Time of a datetime64[ns] UTC array (one vectorised call).

    The IAU 2000A nutation angles and the complementary terms of the equation of the
    equinoxes, which vary over days, are evaluated on knots every :data:`KNOT_S` and
    splined; skyfield's own formula then gives the apparent sidereal time at every
    time (the pattern skyfield documents for supplying nutation angles).
    """
    from scipy.interpolate import CubicSpline
    from skyfield.nutationlib import equation_of_the_equinoxes_complimentary_terms

    t = _utc(t64)
    if t64.size <= 8:
        return t
    secs, knots = _knots(t64)
    tk = _utc(t64[0] + (knots * 1e9).astype("timedelta64[ns]"))
    d_psi_k, d_eps_k = tk._nutation_angles_radians
    c_terms_k = equation_of_the_equinoxes_complimentary_terms(tk.tt)
    spline = CubicSpline(knots, np.stack([d_psi_k, d_eps_k, c_terms_k], axis=1), axis=0)(secs)
    d_psi, d_eps, c_terms = spline.T
    t._nutation_angles_radians = (d_psi, d_eps)
    eq_eq = d_psi * np.cos(t._mean_obliquity_radians) + c_terms
    t.gast = (t.gmst + eq_eq / (2 * np.pi) * 24.0) % 24.0
    return t


def _to_datetime64(value: Any, name: str) -> np.datetime64:
    if isinstance(value, _dt.datetime) and value.tzinfo is not None:
        value = value.astimezone(_dt.UTC).replace(tzinfo=None)
    if isinstance(value, str) and value.endswith("Z"):
        value = value[:-1]
    try:
        out = np.datetime64(value, "ns")
    except (TypeError, ValueError):
        raise ObservationError(f"{name}: got {value!r}; expected a UTC time (ISO 8601, datetime or datetime64)") from None
    if np.isnat(out):
        raise ObservationError(f"{name}: got NaT")
    return out


def times(start: Any, stop: Any, step_s: float = 1.0) -> NDArray[np.datetime64]:
    """UTC times from ``start`` to ``stop`` (included when on the grid) every ``step_s``.

    Parameters
    ----------
    start, stop : str, datetime or datetime64
        UTC times (naive datetimes and ISO strings without a zone are UTC).
    step_s : float
        Step [s], > 0.

    Returns
    -------
    ndarray of datetime64[ns]
    """
    t0, t1 = _to_datetime64(start, "start"), _to_datetime64(stop, "stop")
    if not (np.isfinite(step_s) and step_s > 0):
        raise ObservationError(f"step_s: must be a positive number of seconds, got {step_s!r}")
    if t1 < t0:
        raise ObservationError(f"stop {t1} is before start {t0}")
    step = np.timedelta64(round(step_s * 1e9), "ns")
    n = int((t1 - t0) // step) + 1
    return t0 + step * np.arange(n)


def _check_times(value: Any) -> NDArray[np.datetime64]:
    t = np.atleast_1d(np.asarray(value))
    if t.dtype.kind in "US" or t.dtype == object:
        try:
            t = np.array([_to_datetime64(x, "times") for x in t.ravel()]).reshape(t.shape)
        except ObservationError:
            raise
    if not np.issubdtype(t.dtype, np.datetime64):
        raise ObservationError(f"times: expected datetime64 (UTC), got dtype {t.dtype}")
    t = t.astype(_NS)
    if t.ndim != 1 or t.size == 0:
        raise ObservationError(f"times: expected a non-empty 1-D array, got shape {t.shape}")
    if np.any(np.isnat(t)):
        raise ObservationError("times: contains NaT")
    if t.size > 1 and not np.all(np.diff(t) > np.timedelta64(0, "ns")):
        raise ObservationError("times: must be strictly increasing")
    return t


# --------------------------------------------------------------------------- orbit


def tle_checksum(line: str) -> int:
    """Checksum of a TLE line: digits summed, ``-`` counting 1, modulo 10."""
    return (sum(int(c) for c in line[:68] if c.isdigit()) + line[:68].count("-")) % 10


#: Numeric fields of the TLE lines: name, first and last column (0-based, end excluded).
_TLE_FIELDS_1 = (("catalog number", 2, 7), ("epoch", 18, 32), ("mean motion derivative", 33, 43))
_TLE_FIELDS_2 = (("catalog number", 2, 7), ("inclination", 8, 16), ("right ascension of the node", 17, 25),
                 ("eccentricity", 26, 33), ("argument of perigee", 34, 42), ("mean anomaly", 43, 51),
                 ("mean motion", 52, 63))


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _check_tle(line1: Any, line2: Any) -> tuple[str, str]:
    lines = []
    for i, line in ((1, line1), (2, line2)):
        if not isinstance(line, str):
            raise ObservationError(f"TLE line {i}: expected a string, got {type(line).__name__}")
        line = line.rstrip()
        if len(line) != 69:
            raise ObservationError(f"TLE line {i}: has {len(line)} characters; a TLE line has 69: {line!r}")
        if line[0] != str(i) or line[1] != " ":
            raise ObservationError(f"TLE line {i}: must start with '{i} ', got {line[:2]!r}")
        if not line[68].isdigit() or int(line[68]) != tle_checksum(line):
            raise ObservationError(
                f"TLE line {i}: checksum {line[68]!r} does not match the computed {tle_checksum(line)} "
                f"(digits summed, '-' counting 1, modulo 10): {line!r}"
            )
        lines.append(line)
    for i, fields in ((1, _TLE_FIELDS_1), (2, _TLE_FIELDS_2)):
        line = lines[i - 1]
        for fname, lo, hi in fields:
            text = line[lo:hi]
            ok = text.strip().isdigit() if fname == "eccentricity" else _is_number(text)
            if not ok:
                raise ObservationError(
                    f"TLE line {i}: field {fname!r} (columns {lo + 1}-{hi}) is {text!r}, not a number"
                )
    if lines[0][2:7] != lines[1][2:7]:
        raise ObservationError(f"TLE: catalog numbers differ between the lines ({lines[0][2:7]!r}, {lines[1][2:7]!r})")
    return lines[0], lines[1]


@dataclass(frozen=True)
class Orbit:
    """Orbital elements propagated by SGP4 (skyfield :class:`~skyfield.sgp4lib.EarthSatellite`).

    Build with :meth:`from_tle`, :meth:`from_omm` or :meth:`from_catalog`.

    Attributes
    ----------
    satellite : skyfield.sgp4lib.EarthSatellite
    line1, line2 : str
        The two-line elements (exported by :mod:`sgp4.exporter` for an OMM).
    name : str
    provenance : str
    """

    satellite: Any
    line1: str
    line2: str
    name: str = ""
    provenance: str = ""

    @classmethod
    def from_tle(cls, line1: str, line2: str, name: str | None = None, provenance: str = "") -> Orbit:
        """Orbit from the two lines of a TLE.

        Raises
        ------
        ObservationError
            For a line of the wrong length, start, checksum or catalog number, or a field
            SGP4 cannot read.
        """
        from skyfield.api import EarthSatellite

        l1, l2 = _check_tle(line1, line2)
        ts, _ = _skyfield()
        try:
            sat = EarthSatellite(l1, l2, name, ts)
        except (ValueError, IndexError) as exc:
            raise ObservationError(f"TLE: a field cannot be read: {exc}") from None
        _check_model(sat, name or l1[2:7])
        return cls(sat, l1, l2, name or sat.name or l1[2:7].strip(), provenance)

    @classmethod
    def from_omm(cls, omm: Mapping[str, Any] | str | Path, provenance: str = "") -> Orbit:
        """Orbit from an Orbit Mean-Elements Message (CCSDS 502.0-B).

        Parameters
        ----------
        omm : mapping or path
            The OMM fields (``OBJECT_NAME``, ``EPOCH``, ``MEAN_MOTION``, ... as in CelesTrak's
            JSON/CSV) or a ``.xml``, ``.csv`` or ``.json`` file holding one.
        """
        from sgp4 import exporter
        from sgp4 import omm as sgp4_omm
        from skyfield.api import EarthSatellite

        if not isinstance(omm, Mapping):
            path = Path(omm)
            try:
                with open(path, encoding="utf-8") as f:
                    if path.suffix.lower() == ".xml":
                        fields = next(iter(sgp4_omm.parse_xml(f)))
                    elif path.suffix.lower() == ".csv":
                        fields = next(iter(sgp4_omm.parse_csv(f)))
                    else:
                        data = json.load(f)
                        fields = data[0] if isinstance(data, list) else data
            except (OSError, ValueError, StopIteration, KeyError) as exc:
                raise ObservationError(f"OMM: cannot read {path}: {exc!r}") from None
        else:
            fields = dict(omm)
        ts, _ = _skyfield()
        try:
            sat = EarthSatellite.from_omm(ts, fields)
        except (KeyError, ValueError, TypeError) as exc:
            raise ObservationError(f"OMM: missing or bad field: {exc!r}; fields given: {sorted(fields)}") from None
        _check_model(sat, fields.get("OBJECT_NAME", "OMM"))
        l1, l2 = exporter.export_tle(sat.model)
        return cls(sat, l1, l2, str(fields.get("OBJECT_NAME", "")), provenance)

    @classmethod
    def from_catalog(cls, name: str) -> Orbit:
        """A shipped orbit (catalog kind ``orbit``)."""
        e = _catalog_index.entry(name)
        if e.kind != "orbit":
            raise ObservationError(f"catalog entry {name!r} is a {e.kind}, not an orbit")
        return load_orbit_entry(e)

    @property
    def epoch(self) -> np.datetime64:
        """Epoch of the elements (UTC)."""
        return np.datetime64(self.satellite.epoch.utc_datetime().replace(tzinfo=None), "ns")


def _check_model(sat: Any, label: str) -> None:
    from sgp4.api import SGP4_ERRORS

    err = getattr(sat.model, "error", 0)
    if err:
        raise ObservationError(f"orbit {label}: SGP4 rejects the elements (error {err}: "
                               f"{SGP4_ERRORS.get(err, 'unknown')})")


# --------------------------------------------------------------------------- site


@dataclass(frozen=True)
class Site:
    """An observer on the WGS84 ellipsoid.

    Parameters
    ----------
    latitude_deg : float
        Geodetic latitude [degree], in [-90, 90].
    longitude_deg : float
        East longitude [degree], in [-180, 360] (stored in [-180, 180)).
    height_m : float
        Height above the ellipsoid [m], in [-500, 9000].
    name : str
    """

    latitude_deg: float
    longitude_deg: float
    height_m: float = 0.0
    name: str = ""

    def __post_init__(self) -> None:
        checks = (("latitude_deg", -90.0, 90.0), ("longitude_deg", -180.0, 360.0), ("height_m", -500.0, 9000.0))
        for attr, lo, hi in checks:
            v = getattr(self, attr)
            try:
                x = float(v)
            except (TypeError, ValueError):
                raise ObservationError(f"site {attr}: expected a number, got {v!r}") from None
            if not (np.isfinite(x) and lo <= x <= hi):
                raise ObservationError(f"site {attr}: got {v!r}; allowed: [{lo:g}, {hi:g}]")
            object.__setattr__(self, attr, x)
        lon = (self.longitude_deg + 180.0) % 360.0 - 180.0
        object.__setattr__(self, "longitude_deg", lon)

    @classmethod
    def from_catalog(cls, name: str) -> Site:
        """A shipped observatory (catalog kind ``site``)."""
        e = _catalog_index.entry(name)
        if e.kind != "site":
            raise ObservationError(f"catalog entry {name!r} is a {e.kind}, not a site")
        return load_site_entry(e)

    @property
    def position(self) -> Any:
        """The skyfield WGS84 geographic position."""
        from skyfield.api import wgs84

        return wgs84.latlon(self.latitude_deg, self.longitude_deg, elevation_m=self.height_m)


# --------------------------------------------------------------------------- pure models


def disc_overlap_fraction(a: ArrayLike, b: ArrayLike, c: ArrayLike) -> NDArray[np.float64]:
    """Fraction of a disc of radius ``a`` not covered by a disc of radius ``b`` at distance ``c``.

    The exact area of intersection of two circles (Montenbruck & Gill 2000, eqs. 3.86-3.88),
    applied to the apparent discs of the Sun (radius ``a``) and the Earth (``b``) with
    centres ``c`` apart: ``1`` when they do not overlap, ``1 - b^2/a^2`` when the Earth
    disc lies inside the Sun's, ``0`` when it covers it.  A point Sun (``a = 0``) is
    ``1`` for ``c >= b`` and ``0`` otherwise.

    Parameters
    ----------
    a, b, c : array_like
        Angular radii and separation [rad], ``>= 0``.

    Returns
    -------
    ndarray
        In ``[0, 1]``.
    """
    a, b, c = np.broadcast_arrays(*(np.asarray(x, dtype=np.float64) for x in (a, b, c)))
    # The lens of the two discs, written with atan2 (never arccos near +-1, which loses
    # half the digits at the tangencies): the chord lies x1 = (c^2 + a^2 - b^2) / 2c from
    # the centre of disc a and x2 = c - x1 from that of disc b, its half-length is
    # y = sqrt(k) / 2c (Heron), and the area is a^2 atan2(y, x1) + b^2 atan2(y, x2) - c y.
    # Each factor of Heron's product under its own square root, and x1 without c^2, so that
    # nothing underflows for tiny separations of equal discs.
    safe_c = np.where(c > 0, c, 1.0)
    d = a - b
    roots = [np.sqrt(np.maximum(f, 0.0)) for f in (a + b - c, c + d, c - d, a + b + c)]
    y = roots[0] * roots[1] * roots[2] * roots[3] / (2 * safe_c)
    x1 = 0.5 * (c + d * (a + b) / safe_c)
    x2 = c - x1
    area = a * a * np.arctan2(y, x1) + b * b * np.arctan2(y, x2) - c * y
    safe_a2 = np.where(a > 0, a * a, 1.0)
    partial = 1.0 - area / (np.pi * safe_a2)
    nested = 1.0 - np.minimum(a, b) ** 2 / safe_a2  # the smaller disc inside the larger
    out = np.where(c >= a + b, 1.0, np.where(c <= np.abs(a - b), nested, partial))
    out = np.where(a > 0, out, np.where(c >= b, 1.0, 0.0))
    return np.clip(out, 0.0, 1.0)


def sunlit_fraction(
    position_km: ArrayLike,
    sun_km: ArrayLike,
    earth_radius_km: float = EARTH_RADIUS_KM,
    sun_radius_km: float = SUN_RADIUS_KM,
) -> NDArray[np.float64]:
    """Fraction of the solar disc seen from a spacecraft that the Earth does not hide.

    Apparent radii ``a = asin(R_sun/|s|)``, ``b = asin(R_earth/|r|)`` and separation ``c``
    (angle between ``s`` and ``-r``, by ``atan2``) enter :func:`disc_overlap_fraction`
    (Montenbruck & Gill 2000, §3.4.2): 0 in the umbra, the visible fraction of the disc
    in the penumbra, 1 in sunlight.

    Parameters
    ----------
    position_km : array_like, shape (..., 3)
        Geocentric position of the spacecraft [km].
    sun_km : array_like, shape (..., 3)
        Position of the Sun relative to the spacecraft [km].
    earth_radius_km, sun_radius_km : float
        Radii of the spheres [km]; ``sun_radius_km = 0`` gives a point Sun.

    Returns
    -------
    ndarray, shape (...)
    """
    r = np.asarray(position_km, dtype=np.float64)
    s = np.asarray(sun_km, dtype=np.float64)
    dr = np.linalg.norm(r, axis=-1)
    ds = np.linalg.norm(s, axis=-1)
    a = np.arcsin(np.minimum(sun_radius_km / ds, 1.0))
    b = np.arcsin(np.minimum(earth_radius_km / dr, 1.0))
    c = np.arctan2(np.linalg.norm(np.cross(s, -r), axis=-1), np.einsum("...i,...i->...", s, -r))
    return disc_overlap_fraction(a, b, c)


def airmass(elevation_deg: ArrayLike, model: str = "kastenyoung1989") -> NDArray[np.float64]:
    """Relative airmass at an elevation (pvlib ``get_relative_airmass``); NaN below the horizon.

    Parameters
    ----------
    elevation_deg : array_like
        Elevation [degree].
    model : str
        One of :data:`AIRMASS_MODELS`; ``kastenyoung1989`` is Kasten & Young, Appl. Opt. 28,
        4735 (1989), ``1 / (cos z + 0.50572 (96.07995 - z)^-1.6364)``.

    Returns
    -------
    ndarray
        Relative airmass [1].
    """
    if model not in AIRMASS_MODELS:
        raise ObservationError(f"airmass_model: got {model!r}; allowed: {', '.join(AIRMASS_MODELS)}")
    from pvlib.atmosphere import get_relative_airmass

    el = np.asarray(elevation_deg, dtype=np.float64)
    zen = np.where(el >= 0, 90.0 - el, 90.0)
    am = np.asarray(get_relative_airmass(zen, model=model), dtype=np.float64)
    return np.where(el >= 0, am, np.nan)


#: Speed of light [km s-1].
C_KM_S = 299792.458


def _sun_from_spacecraft(t64: np.ndarray, r: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Apparent position of the Sun from the spacecraft in the GCRS [km].

    skyfield's geocentric apparent Sun (light time, aberration by the Earth's velocity,
    deflection) on knots every :data:`KNOT_S`, cubic-spline interpolated, moved to the
    spacecraft (``- r``) and aberrated by its geocentric velocity ``v`` to first order
    (``u' = u + b - u (u.b)``, ``b = v/c``).  Against skyfield's own
    ``(earth + satellite).at(t).observe(sun).apparent()`` the direction differs by the
    cross term of the two aberrations, ``|v_earth| |v| / c^2 ~ 3e-9 rad`` (0.6 mas).
    """
    from scipy.interpolate import CubicSpline

    _, eph = _skyfield()
    secs, knots = _knots(t64)
    tk = _utc(t64[0] + (knots * 1e9).astype("timedelta64[ns]"))
    sun_k = eph["earth"].at(tk).observe(eph["sun"]).apparent().position.km.T
    sun_geo = CubicSpline(knots, sun_k, axis=0)(secs)
    rel = sun_geo - r
    d = np.linalg.norm(rel, axis=1, keepdims=True)
    u = rel / d
    b = v / C_KM_S
    u = u + b - u * np.einsum("ni,ni->n", u, b)[:, None]
    return d * _unit(u)


def _angle(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Angle between rows [degree], by atan2."""
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.einsum("ni,ni->n", u, v)))


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


# --------------------------------------------------------------------------- observation


def _as_law(value: Any) -> _att.AttitudeLaw:
    if value is None:
        return _att.Nadir()
    if isinstance(value, _att.AttitudeLaw):
        return value
    if isinstance(value, Mapping):
        return _att.law_from_dict(value)
    try:
        return _att.Inertial(value)
    except AttitudeError:
        raise AttitudeError(f"attitude: expected an attitude law, a table or a quaternion, got {value!r}") from None


UNOBSERVABLE = ("raise", "empty", "keep")


@dataclass(frozen=True)
class Observation:
    """A spacecraft on an orbit, seen from a site at UTC times, in an attitude law.

    Parameters
    ----------
    orbit : Orbit
    site : Site
    times : array_like of datetime64
        Strictly increasing UTC times (see :func:`times`).
    attitude : AttitudeLaw, table or quaternion, optional
        Attitude law (:mod:`sbrdf_xr.attitude`); default :class:`~sbrdf_xr.attitude.Nadir`.
    airmass_model : str
        One of :data:`AIRMASS_MODELS`.
    min_elevation_deg : float
        Elevation [degree] below which the object counts as not observable (for the
        whole-window check of :meth:`geometry`).
    name : str

    Warns
    -----
    EpochGapWarning
        When a time is more than :data:`EPOCH_GAP_DAYS` from the element epoch.
    """

    orbit: Orbit
    site: Site
    times: Any
    attitude: Any = None
    airmass_model: str = "kastenyoung1989"
    min_elevation_deg: float = 0.0
    name: str = "observation"
    _cache: dict[str, Any] = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not isinstance(self.orbit, Orbit):
            raise ObservationError(f"orbit: expected an Orbit, got {type(self.orbit).__name__}")
        if not isinstance(self.site, Site):
            raise ObservationError(f"site: expected a Site, got {type(self.site).__name__}")
        t = _check_times(self.times)
        t.setflags(write=False)
        object.__setattr__(self, "times", t)
        object.__setattr__(self, "attitude", _as_law(self.attitude))
        if self.airmass_model not in AIRMASS_MODELS:
            raise ObservationError(f"airmass_model: got {self.airmass_model!r}; allowed: {', '.join(AIRMASS_MODELS)}")
        if not -90.0 <= float(self.min_elevation_deg) <= 90.0:
            raise ObservationError(f"min_elevation_deg: must lie in [-90, 90], got {self.min_elevation_deg}")
        epoch = self.orbit.epoch
        gap = np.abs(t[[0, -1]] - epoch).max().astype(np.int64) / 86400e9
        if gap > EPOCH_GAP_DAYS:
            warnings.warn(
                f"observation times {t[0]} .. {t[-1]} reach {gap:.1f} days from the epoch {epoch} of the "
                f"elements of {self.orbit.name!r} (more than {EPOCH_GAP_DAYS:g} days): SGP4 errors grow "
                "by about 1-3 km per day in LEO; use elements nearer the observation",
                EpochGapWarning, stacklevel=2,
            )

    def __repr__(self) -> str:
        t = self.times
        step = f", step {(t[1] - t[0]) / np.timedelta64(1, 's'):g} s" if t.size > 1 else ""
        return (f"<Observation {self.name!r}: {self.orbit.name!r} from {self.site.name or 'site'} "
                f"({self.site.latitude_deg:.4f}, {self.site.longitude_deg:.4f}, {self.site.height_m:g} m), "
                f"{t.size} times {t[0]} .. {t[-1]}{step}, attitude {self.attitude!r}>")

    def _state(self) -> dict[str, np.ndarray]:
        """Inertial-frame (GCRS) vectors per time, from one vectorised skyfield pass."""
        if "state" in self._cache:
            return self._cache["state"]
        from skyfield.framelib import itrs

        t = _skyfield_time(self.times)
        sat = self.orbit.satellite
        geo = sat.at(t)
        r = geo.position.km.T
        v = geo.velocity.km_per_s.T
        if not np.all(np.isfinite(r)):
            bad = int(np.flatnonzero(~np.isfinite(r).all(axis=1))[0])
            msg = getattr(geo, "message", None)
            msg = msg[bad] if isinstance(msg, list | tuple | np.ndarray) else msg
            raise ObservationError(f"orbit {self.orbit.name!r}: SGP4 fails at {self.times[bad]}: {msg}")
        sun_rel = _sun_from_spacecraft(self.times, r, v)
        site_r = self.site.position.at(t).position.km.T
        rot = itrs.rotation_at(t)  # GCRS -> ITRS, (3, 3, n)
        state = {"r": r, "v": v, "sun": sun_rel, "site": site_r, "itrs": rot}
        self._cache["state"] = state
        return state

    def context(self) -> _att.Context:
        """The :class:`~sbrdf_xr.attitude.Context` the attitude law sees."""
        st = self._state()
        return _att.Context(epoch=self.times[0], position_km=st["r"], velocity_km_s=st["v"], sun_km=st["sun"])

    def quaternions(self) -> NDArray[np.float64]:
        """Attitudes (body -> GCRS) at the observation times, sign-continuous; (n, 4)."""
        q = np.asarray(self.attitude.quaternions(self.times, self.context()), dtype=np.float64)
        if q.shape != (self.times.size, 4):
            raise AttitudeError(f"attitude law returned shape {q.shape}, expected ({self.times.size}, 4)")
        # Flip signs so consecutive quaternions are in the same hemisphere (same rotations).
        if q.shape[0] > 1:
            flips = np.concatenate([[False], np.einsum("ni,ni->n", q[1:], q[:-1]) < 0])
            q = np.where((np.cumsum(flips) % 2 == 1)[:, None], -q, q)
        return q

    def geometry(self, on_unobservable: str = "raise") -> xr.Dataset:
        """Per-time geometry of the observation.

        Parameters
        ----------
        on_unobservable : {"raise", "empty", "keep"}
            What to do when the object is below ``min_elevation_deg`` at every time, or
            in the umbra at every time: raise :class:`NotObservableError`, return a
            Dataset with ``time`` of length 0 and the reason in ``attrs["unobservable"]``,
            or return the full Dataset anyway.

        Returns
        -------
        xarray.Dataset
            Over ``time`` (datetime64[ns] UTC), ``xyz`` and ``component``: ``to_sun``,
            ``to_observer``, ``to_earth`` (time, xyz) body-frame unit vectors and
            ``quaternion`` (time, component); coordinates on ``time``: ``range`` [km],
            ``elevation``, ``azimuth``, ``phase_angle``, ``solar_elongation`` [degree],
            ``sun_distance`` [au], ``sunlit_fraction`` [1], ``airmass`` [1] (NaN below the
            horizon), ``earth_distance`` [km], ``earth_phase_angle`` and
            ``site_sun_elevation`` [degree].  Attrs: ``tle_line1``, ``tle_line2``,
            ``site_latitude``, ``site_longitude`` [degree], ``site_height`` [m],
            ``site_name`` and the frames and models used.
        """
        if on_unobservable not in UNOBSERVABLE:
            raise ObservationError(f"on_unobservable: got {on_unobservable!r}; allowed: {', '.join(UNOBSERVABLE)}")
        st = self._state()
        r, sun, site_r, rot = st["r"], st["sun"], st["site"], st["itrs"]
        los = site_r - r  # spacecraft -> observer, GCRS
        rng = np.linalg.norm(los, axis=1)
        # Topocentric position in the ITRS, then the geodetic east-north-up frame.
        rel = np.einsum("ijn,nj->ni", rot, -los)
        lat, lon = np.radians(self.site.latitude_deg), np.radians(self.site.longitude_deg)
        east = np.array([-np.sin(lon), np.cos(lon), 0.0])
        north = np.array([-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)])
        up = np.array([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
        e, n_, u = rel @ east, rel @ north, rel @ up
        elevation = np.degrees(np.arctan2(u, np.hypot(e, n_)))
        azimuth = np.mod(np.degrees(np.arctan2(e, n_)), 360.0)
        sun_site = sun + r - site_r  # Sun from the observer
        sun_site_itrs = np.einsum("ijn,nj->ni", rot, sun_site)
        sun_el = np.degrees(np.arctan2(sun_site_itrs @ up, np.hypot(sun_site_itrs @ east, sun_site_itrs @ north)))
        sunlit = sunlit_fraction(r, sun)
        phase = _angle(sun, los)
        elong = _angle(sun_site, -los)
        earth_phase = _angle(sun + r, r)

        reasons = []
        if np.all(elevation < self.min_elevation_deg):
            i = int(np.argmax(elevation))
            reasons.append(f"below {self.min_elevation_deg:g} deg elevation at every time "
                           f"(highest {elevation[i]:.2f} deg at {self.times[i]})")
        if np.all(sunlit == 0):
            reasons.append(f"in the Earth's umbra at every time {self.times[0]} .. {self.times[-1]}")
        if reasons and on_unobservable == "raise":
            raise NotObservableError(f"observation {self.name!r} of {self.orbit.name!r} from "
                                     f"{self.site.name or 'the site'}: " + "; ".join(reasons))

        q = self.quaternions()
        rt = np.swapaxes(rotation_matrices(q), -1, -2)  # GCRS -> body
        body = {name: np.einsum("nij,nj->ni", rt, _unit(vec))
                for name, vec in (("to_sun", sun), ("to_observer", los), ("to_earth", -r))}
        coords = {
            TIME: (TIME, np.asarray(self.times), ATTRS[TIME]),
            VECTOR: (VECTOR, ["x", "y", "z"], ATTRS[VECTOR]),
            COMPONENT: (COMPONENT, ["x", "y", "z", "w"], ATTRS[COMPONENT]),
        }
        per_time = {
            "range": rng, "elevation": elevation, "azimuth": azimuth, "phase_angle": phase,
            "solar_elongation": elong, "sun_distance": np.linalg.norm(sun, axis=1) / AU_KM,
            "sunlit_fraction": sunlit, "airmass": airmass(elevation, self.airmass_model),
            "earth_distance": np.linalg.norm(r, axis=1), "earth_phase_angle": earth_phase,
            "site_sun_elevation": sun_el,
        }
        for k, val in per_time.items():
            coords[k] = (TIME, val, ATTRS[k])
        data = {k: ((TIME, VECTOR), val, ATTRS[k]) for k, val in body.items()}
        data["quaternion"] = ((TIME, COMPONENT), q, ATTRS["quaternion"])
        ds = xr.Dataset(data, coords=coords, attrs=self._attrs())
        ds[TIME].encoding.update(units="seconds since 1970-01-01 00:00:00", calendar="standard",
                                 dtype="float64")
        if reasons and on_unobservable == "empty":
            ds = ds.isel({TIME: slice(0, 0)})
            ds.attrs["unobservable"] = "; ".join(reasons)
        return ds

    def _attrs(self) -> dict[str, Any]:
        import skyfield
        import skyfield_data

        return {
            "observation": self.name,
            "orbit_name": self.orbit.name,
            "tle_line1": self.orbit.line1,
            "tle_line2": self.orbit.line2,
            "orbit_provenance": self.orbit.provenance,
            "site_name": self.site.name,
            "site_latitude": self.site.latitude_deg,
            "site_longitude": self.site.longitude_deg,
            "site_height": self.site.height_m,
            "site_coordinates": "WGS84 geodetic latitude and east longitude [degree], height above the ellipsoid [m]",
            "attitude_law": repr(self.attitude),
            "reference_frame": "GCRS (ICRF axes, geocentric); quaternions rotate body vectors into it",
            "propagator": f"SGP4 (sgp4 via skyfield {skyfield.__version__})",
            "ephemeris": f"de421.bsp and finals2000A.all from skyfield-data {getattr(skyfield_data, '__version__', '')}".strip(),
            "shadow_model": f"spherical Earth R = {EARTH_RADIUS_KM} km, solar disc R = {SUN_RADIUS_KM} km, "
                            "exact disc-overlap area (Montenbruck & Gill 2000, 3.4.2)",
            "airmass_model": self.airmass_model,
        }


def observation_from_dict(table: Mapping[str, Any], base_dir: str | Path | None = None) -> Observation:
    """An :class:`Observation` from a TOML ``[observation]`` table.

    Keys: the orbit as ``orbit`` (a catalog name), ``tle = [line1, line2]`` (or
    ``tle_line1``/``tle_line2``) or ``omm`` (a path or a table); ``site`` as a catalog name
    or a table ``{latitude_deg, longitude_deg, height_m, name}``; times as ``start``,
    ``stop``, ``step_s`` or a list ``times``; ``attitude`` a table for
    :func:`sbrdf_xr.attitude.law_from_dict`; optional ``airmass_model``,
    ``min_elevation_deg``, ``name``.  Relative paths are taken from ``base_dir``.
    Example::

        [observation]
        orbit = "canx1-example"
        site = "mont-megantic"
        start = "2024-03-17T01:20:00"
        stop = "2024-03-17T01:25:00"
        step_s = 1.0
        [observation.attitude]
        law = "nadir"
        yaw_deg = 0.0
    """
    allowed = {"orbit", "tle", "tle_line1", "tle_line2", "omm", "name", "site", "start", "stop", "step_s",
               "times", "attitude", "airmass_model", "min_elevation_deg"}
    if not isinstance(table, Mapping):
        raise ObservationError(f"[observation]: expected a table, got {type(table).__name__}")
    bad = sorted(set(table) - allowed)
    if bad:
        raise ObservationError(f"[observation]: unknown key(s) {bad}; allowed: {', '.join(sorted(allowed))}")
    base = Path(base_dir) if base_dir is not None else Path.cwd()

    def resolve(p: str) -> Path:
        path = Path(p)
        return path if path.is_absolute() else base / path

    orbit_keys = [k for k in ("orbit", "tle", "tle_line1", "omm") if k in table]
    if len(orbit_keys) != 1:
        raise ObservationError(f"[observation]: give exactly one of orbit, tle, tle_line1/tle_line2, omm; got {orbit_keys}")
    if "orbit" in table:
        orbit = Orbit.from_catalog(table["orbit"])
    elif "tle" in table:
        tle = table["tle"]
        if not isinstance(tle, Sequence) or isinstance(tle, str) or len(tle) != 2:
            raise ObservationError(f"[observation] tle: expected [line1, line2], got {tle!r}")
        orbit = Orbit.from_tle(tle[0], tle[1], table.get("name"))
    elif "tle_line1" in table:
        if "tle_line2" not in table:
            raise ObservationError("[observation]: tle_line1 needs tle_line2")
        orbit = Orbit.from_tle(table["tle_line1"], table["tle_line2"], table.get("name"))
    else:
        omm = table["omm"]
        orbit = Orbit.from_omm(omm if isinstance(omm, Mapping) else resolve(omm))

    site_v = table.get("site")
    if isinstance(site_v, str):
        site = Site.from_catalog(site_v)
    elif isinstance(site_v, Mapping):
        extra = sorted(set(site_v) - {"latitude_deg", "longitude_deg", "height_m", "name"})
        if extra or not {"latitude_deg", "longitude_deg"} <= set(site_v):
            raise ObservationError(f"[observation] site: needs latitude_deg, longitude_deg (and optional height_m, name); got {sorted(site_v)}")
        site = Site(**site_v)
    else:
        raise ObservationError(f"[observation] site: expected a catalog name or a table, got {site_v!r}")

    if "times" in table:
        if any(k in table for k in ("start", "stop", "step_s")):
            raise ObservationError("[observation]: give times or start/stop/step_s, not both")
        t = _check_times(table["times"])
    else:
        missing = [k for k in ("start", "stop") if k not in table]
        if missing:
            raise ObservationError(f"[observation]: needs times or start and stop (missing {missing})")
        t = times(table["start"], table["stop"], float(table.get("step_s", 1.0)))

    att = table.get("attitude")
    if isinstance(att, Mapping) and att.get("law") == "quaternion_series" and "path" in att:
        att = {**att, "path": str(resolve(att["path"]))}
    kw = {k: table[k] for k in ("airmass_model", "min_elevation_deg", "name") if k in table}
    return Observation(orbit, site, t, _as_law(att), **kw)


# --------------------------------------------------------------------------- catalog


def load_orbit_entry(entry: _catalog_index.CatalogEntry) -> Orbit:
    """A ``kind = "orbit"`` entry: a 2- or 3-line TLE file."""
    lines = [ln.rstrip() for ln in entry.file.read_text(encoding="utf-8").splitlines() if ln.strip()]
    if len(lines) == 3:
        name, l1, l2 = lines[0].removeprefix("0 ").strip(), lines[1], lines[2]
    elif len(lines) == 2:
        name, l1, l2 = entry.name, lines[0], lines[1]
    else:
        raise CatalogError(f"orbit entry {entry.name!r}: {entry.path} must hold 2 or 3 lines, has {len(lines)}")
    return Orbit.from_tle(l1, l2, name, provenance=entry.provenance)


def load_site_entry(entry: _catalog_index.CatalogEntry) -> Site:
    """A ``kind = "site"`` entry: the table of that name in a TOML file of sites."""
    sites = tomllib.loads(entry.file.read_text(encoding="utf-8"))
    key = entry.extra.get("key", entry.name)
    if key not in sites:
        raise CatalogError(f"site entry {entry.name!r}: {entry.path} has no table [{key}]")
    return Site(name=entry.name, **sites[key])


# --------------------------------------------------------------------------- examples

#: The built-in example: orbit and site catalog entries and the pass window (UTC), found
#: with ``tools/build_observe.py``: the site in astronomical darkness (Sun below
#: -25 deg), the spacecraft between 27 and 76 deg elevation, leaving the Earth's shadow
#: in the first minute (penumbra 01:20:46-01:21:00) and sunlit for the remaining four.
CANX1_PASS = {
    "orbit": "canx1-example",
    "site": "mont-megantic",
    "start": "2024-03-17T01:20:00",
    "stop": "2024-03-17T01:25:00",
    "step_s": 1.0,
}


def canx1_attitude() -> _att.AttitudeLaw:
    """Attitude of the built-in pass: a slow spin about a tilted body axis from a fixed start."""
    return _att.Spin(axis_body=(0.3, 0.4, 0.866), rate_deg_s=4.0, phase_deg=0.0,
                     initial=_att.Inertial((0.2, -0.1, 0.3, 0.92736185)))


def canx1_pass(attitude: _att.AttitudeLaw | None = None) -> Observation:
    """The built-in observation: CanX-1 over the Mont Mégantic Observatory for a few minutes at 1 s.

    Parameters
    ----------
    attitude : AttitudeLaw, optional
        Replaces the default :func:`canx1_attitude`.

    Returns
    -------
    Observation
    """
    p = CANX1_PASS
    return Observation(Orbit.from_catalog(p["orbit"]), Site.from_catalog(p["site"]),
                       times(p["start"], p["stop"], p["step_s"]),
                       attitude if attitude is not None else canx1_attitude(), name="canx1-pass")


def bench_geometry(n_times: int = 3600, step_s: float = 1.0, repeats: int = 3) -> dict[str, float]:
    """Time :meth:`Observation.geometry` of the built-in orbit and site over ``n_times`` steps.

    The first call in a process also pays the one-off imports and the loading of the
    skyfield data; it is reported apart from the best of ``repeats`` further calls on
    fresh observations (nothing cached between them).

    Returns
    -------
    dict
        ``n_times``, ``first_call_seconds``, ``seconds`` (best warm call) and
        ``seconds_per_time``.
    """
    p = CANX1_PASS
    t0 = _to_datetime64(p["start"], "start") - np.timedelta64(int(n_times * step_s / 2), "s")
    t = t0 + np.timedelta64(round(step_s * 1e9), "ns") * np.arange(n_times)
    start = _time.perf_counter()
    orbit, site = Orbit.from_catalog(p["orbit"]), Site.from_catalog(p["site"])
    Observation(orbit, site, t, canx1_attitude()).geometry(on_unobservable="keep")
    first = _time.perf_counter() - start
    best = np.inf
    for _ in range(max(1, repeats)):
        obs = Observation(orbit, site, t, canx1_attitude())
        start = _time.perf_counter()
        obs.geometry(on_unobservable="keep")
        best = min(best, _time.perf_counter() - start)
    return {"n_times": float(n_times), "first_call_seconds": first, "seconds": best,
            "seconds_per_time": best / n_times}
