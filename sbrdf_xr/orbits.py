"""Orbits, observatories and times; the pure models of the Earth's shadow and the airmass.

:class:`Orbit` (SGP4 elements from a TLE, an OMM or a catalog entry), :class:`Site`
(a WGS84 observatory), UTC time grids, the sunlit fraction of a spacecraft near the
Earth's shadow and the relative airmass.  :mod:`sbrdf_xr.observe` combines them with an
attitude law into an :class:`~sbrdf_xr.observe.Observation`.
"""

from __future__ import annotations

import datetime as _dt
import json
import tomllib
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _catalog_index
from .errors import (
    CatalogError,
    ObservationError,
)

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
AIRMASS_MODELS = (
    "simple",
    "kasten1966",
    "youngirvine1967",
    "kastenyoung1989",
    "gueymard1993",
    "young1994",
    "pickering2002",
    "gueymard2003",
)


_NS = np.dtype("datetime64[ns]")


@cache
def skyfield_data() -> tuple[Any, Any]:
    """Timescale (with polar motion) and ephemeris from the ``skyfield-data`` directory.

    Examples
    --------
    >>> from sbrdf_xr.orbits import skyfield_data
    >>> ts, eph = skyfield_data()
    >>> t = ts.utc(2024, 3, 17)
    >>> round(float((t.tt - t.ut1) * 86400), 3)  # TT - UT1 [s] from the shipped IERS table
    69.193
    >>> type(eph).__name__, 399 in eph  # the JPL DE421 kernel, with the Earth
    ('SpiceKernel', True)
    """
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
#: (fourth derivative ``|r|`` (2 pi / yr)^4 ~ 2e-19 km s-4) are then exact to far below a
#: microarcsecond and a millimetre.
KNOT_S = 600.0


def spline_knots(t64: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Seconds of ``t64`` from its start, and spline knots covering them (>= 4).

    Examples
    --------
    >>> secs, knots = spline_knots(times("2024-03-17T00:00:00", "2024-03-17T01:00:00", 600.0))
    >>> secs.tolist(), knots.size
    ([0.0, 600.0, 1200.0, 1800.0, 2400.0, 3000.0, 3600.0], 9)
    """
    secs = (t64 - t64[0]).astype(np.int64) / 1e9
    span = float(secs[-1])
    n = max(4, int(np.ceil(span / KNOT_S)) + 3)
    return secs, np.linspace(-KNOT_S, span + KNOT_S, n)


def skyfield_utc(t64: np.ndarray) -> Any:
    """skyfield Time of a datetime64[ns] UTC array (no nutation splines: :func:`skyfield_time`).

    Examples
    --------
    >>> t = skyfield_utc(np.array(["2024-03-17T01:20:00.5"], dtype="datetime64[ns]"))
    >>> [float(x[0]) for x in t.utc]  # year, month, day, hour, minute, second
    [2024.0, 3.0, 17.0, 1.0, 20.0, 0.5]
    """
    ts, _ = skyfield_data()
    day = t64.astype("datetime64[D]")
    month = day.astype("datetime64[M]")
    year = month.astype("datetime64[Y]")
    sec = (t64 - day).astype(np.int64) / 1e9
    return ts.utc(
        year.astype(np.int64) + 1970,
        month.astype(np.int64) % 12 + 1,
        (day - month).astype(np.int64) + 1,
        0,
        0,
        sec,
    )


def skyfield_time(t64: np.ndarray) -> Any:
    """skyfield Time of a datetime64[ns] UTC array (one vectorised call).

    The IAU 2000A nutation angles and the complementary terms of the equation of the
    equinoxes, which vary over days, are evaluated on knots every :data:`KNOT_S` and
    splined; skyfield's own formula then gives the apparent sidereal time at every
    time (the pattern skyfield documents for supplying nutation angles).

    Examples
    --------
    >>> t = skyfield_time(times("2024-03-17T01:20:00", "2024-03-17T01:30:00", 60.0))
    >>> len(t), round(float(t.gast[0]), 6)  # apparent sidereal time [h]
    (11, 13.007692)
    """
    from scipy.interpolate import CubicSpline
    from skyfield.nutationlib import equation_of_the_equinoxes_complimentary_terms

    t = skyfield_utc(t64)
    if t64.size <= 8:
        return t
    secs, knots = spline_knots(t64)
    tk = skyfield_utc(t64[0] + (knots * 1e9).astype("timedelta64[ns]"))
    d_psi_k, d_eps_k = tk._nutation_angles_radians
    c_terms_k = equation_of_the_equinoxes_complimentary_terms(tk.tt)
    spline = CubicSpline(knots, np.stack([d_psi_k, d_eps_k, c_terms_k], axis=1), axis=0)(secs)
    d_psi, d_eps, c_terms = spline.T
    t._nutation_angles_radians = (d_psi, d_eps)
    eq_eq = d_psi * np.cos(t._mean_obliquity_radians) + c_terms
    t.gast = (t.gmst + eq_eq / (2 * np.pi) * 24.0) % 24.0
    return t


def to_datetime64(value: Any, name: str) -> np.datetime64:
    """One UTC time (ISO 8601, ``Z`` allowed; datetime, naive is UTC; datetime64) as datetime64[ns].

    Examples
    --------
    >>> import datetime
    >>> to_datetime64("2024-03-17T01:20:00Z", "start")
    np.datetime64('2024-03-17T01:20:00.000000000')
    >>> cest = datetime.timezone(datetime.timedelta(hours=2))
    >>> to_datetime64(datetime.datetime(2024, 3, 17, 3, 20, tzinfo=cest), "start")
    np.datetime64('2024-03-17T01:20:00.000000000')
    >>> to_datetime64("yesterday", "start")
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.ObservationError: start: got 'yesterday'; expected a UTC time (ISO 8601, ...
    """
    if isinstance(value, _dt.datetime) and value.tzinfo is not None:
        value = value.astimezone(_dt.UTC).replace(tzinfo=None)
    if isinstance(value, str) and value.endswith("Z"):
        value = value[:-1]
    try:
        out = np.datetime64(value, "ns")
    except (TypeError, ValueError):
        raise ObservationError(
            f"{name}: got {value!r}; expected a UTC time (ISO 8601, datetime or datetime64)"
        ) from None
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

    Examples
    --------
    >>> t = times("2024-03-17T01:20:00", "2024-03-17T01:20:02", step_s=0.5)
    >>> t.size, str(t[0]), str(t[-1])
    (5, '2024-03-17T01:20:00.000000000', '2024-03-17T01:20:02.000000000')
    """
    t0, t1 = to_datetime64(start, "start"), to_datetime64(stop, "stop")
    if not (np.isfinite(step_s) and step_s > 0):
        raise ObservationError(f"step_s: must be a positive number of seconds, got {step_s!r}")
    if t1 < t0:
        raise ObservationError(f"stop {t1} is before start {t0}")
    step = np.timedelta64(round(step_s * 1e9), "ns")
    n = int((t1 - t0) // step) + 1
    return t0 + step * np.arange(n)


def check_times(value: Any) -> NDArray[np.datetime64]:
    """The UTC times of ``value`` as a strictly increasing 1-D datetime64[ns] array.

    Examples
    --------
    >>> check_times(["2024-03-17T01:20:00Z", "2024-03-17T01:20:01"])
    array(['2024-03-17T01:20:00.000000000', '2024-03-17T01:20:01.000000000'],
          dtype='datetime64[ns]')
    >>> check_times(["2024-03-17T01:20:01", "2024-03-17T01:20:00"])
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.ObservationError: times: must be strictly increasing
    """
    t = np.atleast_1d(np.asarray(value))
    if t.dtype.kind in "US" or t.dtype == object:
        try:
            t = np.array([to_datetime64(x, "times") for x in t.ravel()]).reshape(t.shape)
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


def tle_checksum(line: str) -> int:
    """Checksum of a TLE line: digits summed, ``-`` counting 1, modulo 10.

    Examples
    --------
    >>> tle_checksum("1 27847U 03031H   24075.50000000  .00000015  00000-0  21000-4 0  9991")
    1
    """
    return (sum(int(c) for c in line[:68] if c.isdigit()) + line[:68].count("-")) % 10


#: Numeric fields of the TLE lines: name, first and last column (0-based, end excluded).
_TLE_FIELDS_1 = (("catalog number", 2, 7), ("epoch", 18, 32), ("mean motion derivative", 33, 43))


_TLE_FIELDS_2 = (
    ("catalog number", 2, 7),
    ("inclination", 8, 16),
    ("right ascension of the node", 17, 25),
    ("eccentricity", 26, 33),
    ("argument of perigee", 34, 42),
    ("mean anomaly", 43, 51),
    ("mean motion", 52, 63),
)


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
            raise ObservationError(
                f"TLE line {i}: has {len(line)} characters; a TLE line has 69: {line!r}"
            )
        if line[0] != str(i) or line[1] != " ":
            raise ObservationError(f"TLE line {i}: must start with '{i} ', got {line[:2]!r}")
        if not line[68].isdigit() or int(line[68]) != tle_checksum(line):
            raise ObservationError(
                f"TLE line {i}: checksum {line[68]!r} does not match the computed "
                f"{tle_checksum(line)} "
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
                    f"TLE line {i}: field {fname!r} (columns {lo + 1}-{hi}) is {text!r}, "
                    "not a number"
                )
    if lines[0][2:7] != lines[1][2:7]:
        raise ObservationError(
            f"TLE: catalog numbers differ between the lines ({lines[0][2:7]!r}, {lines[1][2:7]!r})"
        )
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

    Examples
    --------
    >>> l1 = "1 27847U 03031H   24075.50000000  .00000015  00000-0  21000-4 0  9991"
    >>> l2 = "2 27847  98.7200 129.5000 0012000  95.0000 265.0000 14.21950000109836"
    >>> orbit = Orbit.from_tle(l1, l2, "CANX-1")
    >>> orbit.name, orbit.epoch
    ('CANX-1', np.datetime64('2024-03-15T12:00:00.000000000'))
    """

    satellite: Any
    line1: str
    line2: str
    name: str = ""
    provenance: str = ""

    @classmethod
    def from_tle(
        cls, line1: str, line2: str, name: str | None = None, provenance: str = ""
    ) -> Orbit:
        """Orbit from the two lines of a TLE.

        Raises
        ------
        ObservationError
            For a line of the wrong length, start, checksum or catalog number, or a field
            SGP4 cannot read.

        Examples
        --------
        >>> l1 = "1 27847U 03031H   24075.50000000  .00000015  00000-0  21000-4 0  9991"
        >>> l2 = "2 27847  98.7200 129.5000 0012000  95.0000 265.0000 14.21950000109836"
        >>> Orbit.from_tle(l1, l2).name
        '27847'
        >>> Orbit.from_tle(l1, l2[:-1] + "0")
        Traceback (most recent call last):
            ...
        sbrdf_xr.errors.ObservationError: TLE line 2: checksum '0' does not match the computed ...
        """
        from skyfield.api import EarthSatellite

        l1, l2 = _check_tle(line1, line2)
        ts, _ = skyfield_data()
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

        Examples
        --------
        >>> omm = {"OBJECT_NAME": "CANX-1", "OBJECT_ID": "2003-031H",
        ...        "EPOCH": "2024-03-15T12:00:00.000000", "MEAN_MOTION": 14.2195,
        ...        "ECCENTRICITY": 0.0012, "INCLINATION": 98.72, "RA_OF_ASC_NODE": 129.5,
        ...        "ARG_OF_PERICENTER": 95.0, "MEAN_ANOMALY": 265.0, "EPHEMERIS_TYPE": 0,
        ...        "CLASSIFICATION_TYPE": "U", "NORAD_CAT_ID": 27847, "ELEMENT_SET_NO": 999,
        ...        "REV_AT_EPOCH": 10983, "BSTAR": 2.1e-05, "MEAN_MOTION_DOT": 1.5e-07,
        ...        "MEAN_MOTION_DDOT": 0.0}
        >>> orbit = Orbit.from_omm(omm)
        >>> orbit.name, orbit.epoch
        ('CANX-1', np.datetime64('2024-03-15T12:00:00.000000000'))
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
        ts, _ = skyfield_data()
        try:
            sat = EarthSatellite.from_omm(ts, fields)
        except (KeyError, ValueError, TypeError) as exc:
            raise ObservationError(
                f"OMM: missing or bad field: {exc!r}; fields given: {sorted(fields)}"
            ) from None
        _check_model(sat, fields.get("OBJECT_NAME", "OMM"))
        l1, l2 = exporter.export_tle(sat.model)
        return cls(sat, l1, l2, str(fields.get("OBJECT_NAME", "")), provenance)

    @classmethod
    def from_catalog(cls, name: str) -> Orbit:
        """A shipped orbit (catalog kind ``orbit``).

        Examples
        --------
        >>> Orbit.from_catalog("canx1-example").name
        'CANX-1 (example elements)'
        """
        e = _catalog_index.entry(name)
        if e.kind != "orbit":
            raise ObservationError(f"catalog entry {name!r} is a {e.kind}, not an orbit")
        return load_orbit_entry(e)

    @property
    def epoch(self) -> np.datetime64:
        """Epoch of the elements (UTC).

        Examples
        --------
        >>> Orbit.from_catalog("canx1-example").epoch
        np.datetime64('2024-03-15T12:00:00.000000000')
        """
        return np.datetime64(self.satellite.epoch.utc_datetime().replace(tzinfo=None), "ns")


def _check_model(sat: Any, label: str) -> None:
    from sgp4.api import SGP4_ERRORS

    err = getattr(sat.model, "error", 0)
    if err:
        raise ObservationError(
            f"orbit {label}: SGP4 rejects the elements (error {err}: "
            f"{SGP4_ERRORS.get(err, 'unknown')})"
        )


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

    Examples
    --------
    >>> site = Site(45.455, -71.1525, 1111.0, name="Mont Megantic")
    >>> site.longitude_deg, Site(0.0, 270.0).longitude_deg  # east longitude, stored in [-180, 180)
    (-71.1525, -90.0)
    >>> Site(95.0, 0.0)
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.ObservationError: site latitude_deg: got 95.0; allowed: [-90, 90]
    """

    latitude_deg: float
    longitude_deg: float
    height_m: float = 0.0
    name: str = ""

    def __post_init__(self) -> None:
        checks = (
            ("latitude_deg", -90.0, 90.0),
            ("longitude_deg", -180.0, 360.0),
            ("height_m", -500.0, 9000.0),
        )
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
        """A shipped observatory (catalog kind ``site``).

        Examples
        --------
        >>> site = Site.from_catalog("mont-megantic")
        >>> site.name, round(site.latitude_deg, 3)
        ('mont-megantic', 45.456)
        """
        e = _catalog_index.entry(name)
        if e.kind != "site":
            raise ObservationError(f"catalog entry {name!r} is a {e.kind}, not a site")
        return load_site_entry(e)

    @property
    def position(self) -> Any:
        """The skyfield WGS84 geographic position.

        Examples
        --------
        >>> Site(45.0, -71.0, 1000.0).position
        <GeographicPosition WGS84 latitude +45.0000 N longitude -71.0000 E elevation 1000.0 m>
        """
        from skyfield.api import wgs84

        return wgs84.latlon(self.latitude_deg, self.longitude_deg, elevation_m=self.height_m)


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

    Examples
    --------
    >>> disc_overlap_fraction([1.0, 1.0, 1.0], [2.0, 0.5, 0.5], [5.0, 0.0, 1.0])
    array([1.        , 0.75      , 0.88834752])
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

    Examples
    --------
    >>> sun = [[1.5e8, 0.0, 0.0]] * 3  # the Sun along +x from each spacecraft [km]
    >>> pos = [[7000.0, 0.0, 0.0], [-7000.0, 0.0, 0.0], [-7000.0, 6378.137, 0.0]]
    >>> np.round(sunlit_fraction(pos, sun), 3)  # day side, umbra, near the shadow's edge
    array([1.   , 0.   , 0.501])
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

    Examples
    --------
    >>> np.round(airmass([90.0, 30.0, 10.0, -5.0]), 4)  # NaN below the horizon
    array([0.9997, 1.9943, 5.586 ,    nan])
    """
    if model not in AIRMASS_MODELS:
        raise ObservationError(
            f"airmass_model: got {model!r}; allowed: {', '.join(AIRMASS_MODELS)}"
        )
    from pvlib.atmosphere import get_relative_airmass

    el = np.asarray(elevation_deg, dtype=np.float64)
    zen = np.where(el >= 0, 90.0 - el, 90.0)
    am = np.asarray(get_relative_airmass(zen, model=model), dtype=np.float64)
    return np.where(el >= 0, am, np.nan)


def load_orbit_entry(entry: _catalog_index.CatalogEntry) -> Orbit:
    """A ``kind = "orbit"`` entry: a 2- or 3-line TLE file.

    Examples
    --------
    >>> from sbrdf_xr import _catalog_index
    >>> load_orbit_entry(_catalog_index.entry("canx1-example")).name
    'CANX-1 (example elements)'
    """
    lines = [
        ln.rstrip() for ln in entry.file.read_text(encoding="utf-8").splitlines() if ln.strip()
    ]
    if len(lines) == 3:
        name, l1, l2 = lines[0].removeprefix("0 ").strip(), lines[1], lines[2]
    elif len(lines) == 2:
        name, l1, l2 = entry.name, lines[0], lines[1]
    else:
        raise CatalogError(
            f"orbit entry {entry.name!r}: {entry.path} must hold 2 or 3 lines, has {len(lines)}"
        )
    return Orbit.from_tle(l1, l2, name, provenance=entry.provenance)


def load_site_entry(entry: _catalog_index.CatalogEntry) -> Site:
    """A ``kind = "site"`` entry: the table of that name in a TOML file of sites.

    Examples
    --------
    >>> from sbrdf_xr import _catalog_index
    >>> site = load_site_entry(_catalog_index.entry("haleakala"))
    >>> site.name, round(site.height_m)
    ('haleakala', 3058)
    """
    sites = tomllib.loads(entry.file.read_text(encoding="utf-8"))
    key = entry.extra.get("key", entry.name)
    if key not in sites:
        raise CatalogError(f"site entry {entry.name!r}: {entry.path} has no table [{key}]")
    return Site(name=entry.name, **sites[key])
