"""Geometry from an observer's tracking table: UTC times, measured directions, range or height.

A :class:`TrackingTable` holds, per measurement, the UTC time and the topocentric direction
of the spacecraft seen from a :class:`~sbrdf_xr.observing.orbits.Site` (elevation and
azimuth in the site's geodetic WGS84 horizon, or right ascension and declination on the
GCRS axes), with its range or its height above the WGS84 ellipsoid.  Its
:meth:`~TrackingTable.ephemeris` is an :class:`~sbrdf_xr.observing.ephemeris.Ephemeris`,
and :meth:`~TrackingTable.observation` the :class:`~sbrdf_xr.observing.observation.Observation`
at the measured times: the same cube as from elements.

* Direction to position: the exact inverse of the observation's own geometry
  (:meth:`Observation.geometry <sbrdf_xr.observing.observation.Observation.geometry>`): the
  east-north-up vector of the measurement in the ITRS, rotated to the GCRS by skyfield's
  ``itrs`` (polar motion included), added to the site's GCRS position.  Elevations are
  geometric (no refraction), as the observation's.
* Height to range: the range along the measured direction at which the geodetic height
  (astropy's ``EarthLocation.to_geodetic``, ERFA ``gc2gd``) equals the given height, by a
  secant iteration from the spherical-Earth value, to 1e-9 km.
* Velocity: rows are grouped in tracks (a ``track`` label, or else consecutive rows at most
  ``max_gap`` apart whose positions imply a speed below :data:`MAX_SPEED_KM_S`); the
  velocity is the derivative of a not-a-knot cubic spline of each track's GCRS positions
  (:meth:`Ephemeris.from_states <sbrdf_xr.observing.ephemeris.Ephemeris.from_states>`), and
  is unknown (NaN) for a track of one row: the laws that need it refuse by name.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import TrackingTableError, renamed_fields, renamed_keywords
from ..units import to_unit
from .ephemeris import Ephemeris
from .observation import Observation
from .orbits import Site
from .timescales import skyfield_time

__all__ = [
    "HEIGHT_TOLERANCE_KM",
    "MAX_SPEED_KM_S",
    "MIN_ELEVATION_DEG",
    "TrackingTable",
    "range_for_height",
    "topocentric_to_gcrs",
]

#: Lowest measured elevation a row may have [degree] (refraction lifts objects up to ~0.6
#: deg near the horizon; lower than this is a sign error or a wrong column).
MIN_ELEVATION_DEG = -2.0
#: Largest difference between a given height and the height implied by a given range [km].
HEIGHT_TOLERANCE_KM = 1.0
#: Speed above which two consecutive rows cannot be one object in Earth orbit [km s-1]
#: (the escape speed at 100 km height is 11.1 km s-1).
MAX_SPEED_KM_S = 12.0


def _enu(site: Site) -> np.ndarray:
    lat, lon = np.radians(site.latitude), np.radians(site.longitude)
    east = [-np.sin(lon), np.cos(lon), 0.0]
    north = [-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)]
    up = [np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)]
    return np.array([east, north, up])


def _directions_itrs(
    site: Site, t: Any, el: np.ndarray | None, az: np.ndarray | None, ra: Any, dec: Any
) -> np.ndarray:
    """Unit line-of-sight vectors in the ITRS, (n, 3)."""
    from skyfield.framelib import itrs

    if el is not None and az is not None:
        e, a = np.radians(el), np.radians(az)
        enu = np.stack([np.cos(e) * np.sin(a), np.cos(e) * np.cos(a), np.sin(e)], axis=1)
        return enu @ _enu(site)
    d, a = np.radians(dec), np.radians(ra)
    u = np.stack([np.cos(d) * np.cos(a), np.cos(d) * np.sin(a), np.sin(d)], axis=1)
    return np.einsum("ijn,nj->ni", itrs.rotation_at(t), u)


@renamed_keywords(height_km="height")
def range_for_height(
    site: Site, direction_itrs: ArrayLike, height: ArrayLike
) -> NDArray[np.float64]:
    """Range [km] along ITRS unit directions from ``site`` to a geodetic height [km].

    Parameters
    ----------
    site : Site
    direction_itrs : array_like, shape (n, 3)
        Unit line-of-sight vectors in the ITRS [1].
    height : array_like, shape (n,)
        Heights above the WGS84 ellipsoid [km].

    Examples
    --------
    >>> site = Site(0.0, 0.0, 0.0)
    >>> range_for_height(site, [[1.0, 0.0, 0.0]], [550.0]).round(9)  # straight up [km]
    array([550.])
    """
    from astropy import units as u
    from astropy.coordinates import EarthLocation

    d = np.asarray(direction_itrs, dtype=np.float64).reshape(-1, 3)
    h = np.asarray(to_unit(height, "km", "height"), dtype=np.float64).reshape(-1)
    p = np.asarray(site.position.itrs_xyz.km, dtype=np.float64)
    r_loc = np.linalg.norm(p) - site.height / 1000.0
    pu = d @ p

    def height_of(rho: np.ndarray) -> np.ndarray:
        x = p + rho[:, None] * d
        loc = EarthLocation.from_geocentric(x[:, 0], x[:, 1], x[:, 2], unit=u.km)
        return np.asarray(loc.to_geodetic("WGS84").height.to_value(u.km))

    rho0 = -pu + np.sqrt(pu**2 - p @ p + (r_loc + h) ** 2)
    rho1 = rho0 + 1.0
    f0, f1 = height_of(rho0) - h, height_of(rho1) - h
    for _ in range(30):
        moving = np.abs(f1) > 1e-10
        if not moving.any():
            break
        slope = np.where(moving, (f1 - f0) / np.where(rho1 != rho0, rho1 - rho0, 1.0), 1.0)
        rho2 = np.where(moving, rho1 - f1 / slope, rho1)
        rho0, f0 = rho1, f1
        rho1, f1 = rho2, height_of(rho2) - h
    return rho1


@renamed_keywords(azimuth_deg="azimuth", elevation_deg="elevation", range_km="range")
def topocentric_to_gcrs(
    site: Site,
    times: Any,
    elevation: ArrayLike,
    azimuth: ArrayLike,
    range: ArrayLike,
) -> NDArray[np.float64]:
    """GCRS positions [km] of measured elevations, azimuths and ranges from ``site``.

    The exact inverse of the elevation, azimuth and range of
    :meth:`Observation.geometry <sbrdf_xr.observing.observation.Observation.geometry>`.

    Parameters
    ----------
    site : Site
    times : array_like of datetime64
        UTC times (the skyfield times are made from the whole array, as an observation does).
    elevation, azimuth : array_like
        Geodetic elevation and azimuth (north through east) [degree].
    range : array_like
        Range [km].

    Examples
    --------
    >>> t = np.array(["2024-03-17T01:20:00"], dtype="datetime64[ns]")
    >>> site = Site(0.0, 0.0, 0.0)
    >>> r = topocentric_to_gcrs(site, t, [90.0], [0.0], [500.0])
    >>> round(float(np.linalg.norm(r)), 3)  # 6378.137 km + 500 km [km]
    6878.137
    """
    t64 = np.asarray(times, dtype="datetime64[ns]")
    t = skyfield_time(t64)
    el = np.asarray(to_unit(elevation, "deg", "elevation"), dtype=np.float64)
    az = np.asarray(to_unit(azimuth, "deg", "azimuth"), dtype=np.float64)
    rng = np.asarray(to_unit(range, "km", "range"), dtype=np.float64)
    return _to_gcrs(site, t, _directions_itrs(site, t, el, az, None, None) * rng[:, None])


def _to_gcrs(site: Site, t: Any, rel_itrs: np.ndarray) -> np.ndarray:
    from skyfield.framelib import itrs

    site_r = site.position.at(t).position.km.T
    return site_r + np.einsum("jin,nj->ni", itrs.rotation_at(t), rel_itrs)


@renamed_fields(
    elevation_deg="elevation",
    azimuth_deg="azimuth",
    ra_deg="ra",
    dec_deg="dec",
    range_km="range",
    height_km="height",
    max_gap_s="max_gap",
)
@dataclass(frozen=True)
class TrackingTable:
    """An observer's measurements of one or more passes: times, directions, range or height.

    Parameters
    ----------
    site : Site
    times : array_like of datetime64
        UTC times, strictly increasing (a reader sorts them and keeps ``rows``).
    elevation, azimuth : array_like, optional
        Topocentric geodetic elevation and azimuth (north through east) [degree].
    ra, dec : array_like, optional
        Topocentric right ascension and declination on the GCRS axes [degree], instead.
    range : array_like, optional
        Range [km].
    height : array_like, optional
        Height above the WGS84 ellipsoid [km] (with ``range``, checked against it
        within :data:`HEIGHT_TOLERANCE_KM`).
    track : array_like, optional
        A label per row; rows of one label are one object's track.
    rows : array_like of int, optional
        Where each row comes from (a file's line numbers); errors name them.
    columns : mapping, optional
        Other columns per row (measured magnitudes, ...), kept.
    dropped : sequence of (int, str), optional
        Rows a reader left out and why.
    name, source : str
    max_gap : float
        Consecutive rows further apart than this start a new track [s].

    Every number with a unit also takes an astropy Quantity.  The old field names
    (``elevation_deg``, ``azimuth_deg``, ``ra_deg``, ``dec_deg``, ``range_km``,
    ``height_km``, ``max_gap_s``) are accepted, and read, for one release with a
    :class:`~sbrdf_xr.errors.RenamedWarning`.

    Examples
    --------
    >>> t = np.array(["2024-03-17T01:22:00", "2024-03-17T01:22:05"], dtype="datetime64[ns]")
    >>> table = TrackingTable(Site(45.455, -71.1525, 1111.0), t, elevation=[75.8, 75.9],
    ...                       azimuth=[10.0, 12.0], range=[841.0, 840.0])
    >>> table.positions().shape, table.tracks().tolist()
    ((2, 3), [0, 0])
    >>> TrackingTable(Site(45.0, -71.0), t, elevation=[-5.0, 10.0], azimuth=[0.0, 0.0],
    ...               range=[900.0, 900.0])
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.TrackingTableError: tracking table: row 0: elevation -5 deg is below ...
    """

    site: Site
    times: Any
    elevation: Any = None
    azimuth: Any = None
    ra: Any = None
    dec: Any = None
    range: Any = None
    height: Any = None
    track: Any = None
    rows: Any = None
    columns: Mapping[str, Any] = field(default_factory=dict)
    dropped: Sequence[tuple[int, str]] = ()
    name: str = "tracking table"
    source: str = ""
    max_gap: float = 30.0
    _cache: dict[str, Any] = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        from .timescales import check_times

        t = check_times(self.times)
        object.__setattr__(self, "times", t)
        gap = float(to_unit(self.max_gap, "s", "max_gap"))
        if not gap > 0:
            raise TrackingTableError(f"{self.name}: max_gap must be > 0 s, got {gap}")
        object.__setattr__(self, "max_gap", gap)
        n = t.size
        rows = np.arange(n) if self.rows is None else np.asarray(self.rows)
        object.__setattr__(self, "rows", rows)
        units = {"elevation": "deg", "azimuth": "deg", "ra": "deg", "dec": "deg"}
        units.update(range="km", height="km")
        for key, unit in units.items():
            val = getattr(self, key)
            if val is not None:
                arr = np.asarray(to_unit(val, unit, key), dtype=np.float64).reshape(-1)
                if arr.size != n:
                    raise TrackingTableError(f"{self.name}: {key} has {arr.size} values, times {n}")
                bad = np.flatnonzero(~np.isfinite(arr))
                if bad.size:
                    raise TrackingTableError(
                        f"{self.name}: row {rows[bad[0]]}: {key} is {arr[bad[0]]}, not a number"
                    )
                object.__setattr__(self, key, arr)
        altaz = self.elevation is not None and self.azimuth is not None
        radec = self.ra is not None and self.dec is not None
        if altaz == radec:
            raise TrackingTableError(
                f"{self.name}: give elevation and azimuth, or ra and dec (exactly one pair)"
            )
        if self.range is None and self.height is None:
            raise TrackingTableError(f"{self.name}: give range or height (or both)")
        el = self.elevations()
        low = np.flatnonzero(el < MIN_ELEVATION_DEG)
        if low.size:
            k = low[0]
            raise TrackingTableError(
                f"{self.name}: row {rows[k]}: elevation {el[k]:.6g} deg is below "
                f"{MIN_ELEVATION_DEG:g} deg ({low.size} row(s) are); allowed: "
                f">= {MIN_ELEVATION_DEG:g} (check the column and its sign)"
            )
        self._check_range_height()

    def _skyfield(self) -> Any:
        if "t" not in self._cache:
            self._cache["t"] = skyfield_time(self.times)
        return self._cache["t"]

    def _dirs(self) -> np.ndarray:
        if "dirs" not in self._cache:
            self._cache["dirs"] = _directions_itrs(
                self.site, self._skyfield(), self.elevation, self.azimuth, self.ra, self.dec
            )
        return self._cache["dirs"]

    def elevations(self) -> NDArray[np.float64]:
        """Measured (or, from RA/Dec, implied) geodetic elevations [degree].

        Examples
        --------
        >>> t = np.array(["2024-03-17T01:22:00"], dtype="datetime64[ns]")
        >>> TrackingTable(Site(45.0, -71.0), t, elevation=[30.0], azimuth=[0.0],
        ...               range=[900.0]).elevations()
        array([30.])
        """
        if self.elevation is not None:
            return np.asarray(self.elevation)
        up = self._dirs() @ _enu(self.site)[2]
        return np.degrees(np.arcsin(np.clip(up, -1.0, 1.0)))

    def ranges(self) -> NDArray[np.float64]:
        """The range of every row [km]: given, or from the height (:func:`range_for_height`).

        Examples
        --------
        >>> t = np.array(["2024-03-17T01:22:00"], dtype="datetime64[ns]")
        >>> table = TrackingTable(Site(0.0, 0.0, 0.0), t, elevation=[90.0],
        ...                       azimuth=[0.0], height=[550.0])
        >>> table.ranges().round(9)  # [km]
        array([550.])
        """
        if self.range is not None:
            return np.asarray(self.range)
        if "range" not in self._cache:
            self._cache["range"] = range_for_height(self.site, self._dirs(), self.height)
        return self._cache["range"]

    def _check_range_height(self) -> None:
        if self.range is None or self.height is None:
            return
        implied = range_for_height(self.site, self._dirs(), self.height)
        diff = np.abs(implied - np.asarray(self.range))
        # A kilometre of height is ~1 km of range near the zenith, more near the horizon.
        sin_el = np.maximum(np.sin(np.radians(np.maximum(self.elevations(), 1.0))), 0.05)
        bad = np.flatnonzero(diff * sin_el > HEIGHT_TOLERANCE_KM)
        if bad.size:
            k = bad[0]
            raise TrackingTableError(
                f"{self.name}: row {self.rows[k]}: range {self.range[k]:.6g} km disagrees "
                f"with height {self.height[k]:.6g} km (which gives a range of "
                f"{implied[k]:.6g} km) by more than {HEIGHT_TOLERANCE_KM:g} km of height "
                f"({bad.size} row(s) do)"
            )

    def positions(self) -> NDArray[np.float64]:
        """GCRS positions of the spacecraft at the table's times [km], (n, 3).

        Examples
        --------
        >>> t = np.array(["2024-03-17T01:22:00"], dtype="datetime64[ns]")
        >>> table = TrackingTable(Site(0.0, 0.0, 0.0), t, elevation=[90.0],
        ...                       azimuth=[0.0], range=[500.0])
        >>> round(float(np.linalg.norm(table.positions())), 3)  # [km]
        6878.137
        """
        if "r" not in self._cache:
            rel = self._dirs() * self.ranges()[:, None]
            self._cache["r"] = _to_gcrs(self.site, self._skyfield(), rel)
        return self._cache["r"]

    def tracks(self) -> NDArray[np.int64]:
        """Track index of every row (see the module docstring).

        Examples
        --------
        >>> t = np.array(["2024-03-17T01:22:00", "2024-03-17T03:00:00"], dtype="datetime64[ns]")
        >>> TrackingTable(Site(45.0, -71.0), t, elevation=[30.0, 40.0],
        ...               azimuth=[0.0, 0.0], range=[900.0, 800.0]).tracks().tolist()
        [0, 1]
        """
        n = self.times.size
        if self.track is not None:
            lab = np.asarray(self.track)
            new = np.concatenate([[True], lab[1:] != lab[:-1]])
        else:
            dt = np.diff(self.times).astype(np.int64) / 1e9
            r = self.positions()
            speed = np.linalg.norm(np.diff(r, axis=0), axis=1) / np.maximum(dt, 1e-9)
            new = np.concatenate([[True], (dt > self.max_gap) | (speed > MAX_SPEED_KM_S)])
        return (np.cumsum(new) - 1) if n else np.zeros(0, dtype=np.int64)

    def ephemeris(self) -> Ephemeris:
        """The :class:`~sbrdf_xr.observing.ephemeris.Ephemeris` of the rows, one segment a track.

        Examples
        --------
        >>> t = np.array(["2024-03-17T01:22:00"], dtype="datetime64[ns]")
        >>> eph = TrackingTable(Site(45.0, -71.0), t, elevation=[30.0],
        ...                     azimuth=[0.0], range=[900.0]).ephemeris()
        >>> bool(np.isnan(eph.state(t)[1]).all())  # one row: no velocity
        True
        """
        trk = self.tracks()
        starts = np.flatnonzero(np.diff(trk)) + 1
        return Ephemeris.from_states(
            self.times,
            self.positions(),
            segments=starts.tolist(),
            name=self.name,
            provenance=self.source or f"tracking table of {self.times.size} rows",
            method=(
                "tracking table: positions from the measured directions and ranges or heights; "
                "velocity the derivative of a not-a-knot cubic spline of each track's GCRS "
                f"positions ({len(starts) + 1} track(s)), unknown for a track of one row"
            ),
        )

    def observation(self, attitude: Any = None, **kwargs: Any) -> Observation:
        """The :class:`~sbrdf_xr.observing.observation.Observation` at the table's times.

        Examples
        --------
        >>> t = np.array(["2024-03-17T01:22:00"], dtype="datetime64[ns]")
        >>> table = TrackingTable(Site(45.0, -71.0), t, elevation=[30.0],
        ...                       azimuth=[0.0], range=[900.0])
        >>> obs = table.observation({"law": "inertial", "q": [0.0, 0.0, 0.0, 1.0]})
        >>> float(obs.geometry(on_unobservable="keep").range[0].round(9))  # [km]
        900.0
        """
        kwargs.setdefault("name", self.name)
        return Observation(self.ephemeris(), self.site, self.times, attitude, **kwargs)
