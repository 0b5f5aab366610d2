"""The :class:`Observation`: a real orbit, an observer site, UTC times and an attitude law.

From an :class:`~sbrdf_xr.observing.orbits.Orbit` (a TLE or an OMM, propagated by SGP4 through
skyfield's :class:`~skyfield.sgp4lib.EarthSatellite`), a :class:`~sbrdf_xr.observing.orbits.Site`
and UTC times (:mod:`sbrdf_xr.observing.timescales`), :meth:`Observation.geometry` computes per
time the body-frame unit vectors to the Sun, the observer and the Earth under an
attitude law (:mod:`sbrdf_xr.observing.attitude`), and the range, elevation, azimuth, phase angle,
solar elongation, Sun distance, Earth-shadow state (a sunlit fraction with penumbra) and
airmass.  :mod:`sbrdf_xr.observing.observe` builds observations from TOML tables.

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
* Earth shadow (:mod:`sbrdf_xr.observing.earth_shadow`): the WGS84 ellipsoid (pole the ITRS
  ``z`` axis, polar motion included), or with ``earth="sphere"`` a sphere of radius
  :data:`~sbrdf_xr.observing.earth_shadow.EARTH_EQUATORIAL_RADIUS_KM`, and the Sun's finite disc
  (radius
  :data:`~sbrdf_xr.observing.earth_shadow.SUN_RADIUS_KM`); the sunlit fraction is the fraction of
  the apparent solar disc not covered by the apparent Earth disc, from the exact area of
  overlap of the two circles (Montenbruck & Gill, *Satellite Orbits*, 2000, §3.4.2,
  eqs. 3.85-3.89).  The UTC times of the edges of the penumbra and the umbra crossed in the
  window are attributes (``penumbra_entry``, ``umbra_entry``, ``umbra_exit``,
  ``penumbra_exit``).  No atmosphere (refraction, absorption) is modelled.
* Airmass: relative airmass of the geometric elevation by a pvlib model
  (:func:`pvlib.atmosphere.get_relative_airmass`), Kasten & Young (1989) by default;
  NaN below the horizon.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from .. import errors as _errors
from .._names import VECTOR, attrs
from ..errors import AttitudeError, EpochGapWarning, NotObservableError, ObservationError
from ..geometry import rotation_matrices
from ..units import to_unit
from . import attitude as _att
from .earth_shadow import (
    EARTH_EQUATORIAL_RADIUS_KM,
    EARTH_MODELS,
    SUN_RADIUS_KM,
    WGS84_FLATTENING,
    shadow_events,
    sunlit_fraction,
)
from .ephemeris import Ephemeris
from .orbits import AIRMASS_MODELS, AU_KM, EPOCH_GAP_DAYS, Orbit, Site, airmass
from .timescales import check_times, skyfield_data, skyfield_time, skyfield_utc, spline_knots

__all__ = ["ATTRS", "COMPONENT", "TIME", "UNOBSERVABLE", "Observation"]

#: Name of the time dimension.
TIME = "time"
#: Name of the quaternion component dimension.
COMPONENT = "component"

_PRECISE: dict[str, dict[str, str]] = {
    "quaternion": {"long_name": "attitude quaternion, body to GCRS, scalar last"},
    "range": {"long_name": "distance from the observer to the spacecraft"},
    "elevation": {"long_name": "elevation of the spacecraft above the observer's geodetic horizon"},
    "airmass": {"long_name": "relative airmass along the line of sight"},
}

#: CF attributes of every variable of :meth:`Observation.geometry`: the package's entries
#: (:data:`sbrdf_xr._names.ATTRS`, where every name is declared once), with the long names
#: an observation can state more precisely (its frame is the GCRS, its horizon geodetic).
ATTRS: dict[str, dict[str, Any]] = {
    k: attrs(k, **_PRECISE.get(k, {}))
    for k in (
        TIME,
        COMPONENT,
        "to_sun",
        "to_observer",
        "to_earth",
        "quaternion",
        "range",
        "elevation",
        "azimuth",
        "phase_angle",
        "solar_elongation",
        "sun_distance",
        "sunlit_fraction",
        "airmass",
        "earth_distance",
        "earth_phase_angle",
        "site_sun_elevation",
        VECTOR,
    )
}


#: Speed of light [km s-1].
C_KM_S = 299792.458


def _sun_from_spacecraft(t64: np.ndarray, r: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Apparent position of the Sun from the spacecraft in the GCRS [km].

    skyfield's geocentric apparent Sun (light time, aberration by the Earth's velocity,
    deflection) on knots every :data:`~sbrdf_xr.observing.timescales.KNOT_S`, cubic-spline
    interpolated (or at every time when the times are fewer than the knots), moved to
    the spacecraft (``- r``) and aberrated by its geocentric velocity ``v`` to first
    order (``u' = u + b - u (u.b)``, ``b = v/c``).  Against skyfield's own
    ``(earth + satellite).at(t).observe(sun).apparent()`` the direction differs by the
    cross term of the two aberrations, ``|v_earth| |v| / c^2 ~ 3e-9 rad``
    (0.6 mas).
    """
    from scipy.interpolate import CubicSpline

    _, eph = skyfield_data()
    secs, knots = spline_knots(t64)
    if knots.size >= t64.size:  # sparse times (a tracking table over months): direct
        sun_geo = eph["earth"].at(skyfield_utc(t64)).observe(eph["sun"]).apparent().position.km.T
    else:
        tk = skyfield_utc(t64[0] + (knots * 1e9).astype("timedelta64[ns]"))
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
    return np.degrees(
        np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.einsum("ni,ni->n", u, v))
    )


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
        raise AttitudeError(
            f"attitude: expected an attitude law, a table or a quaternion, got {value!r}"
        ) from None


UNOBSERVABLE = ("raise", "empty", "keep")


@_errors.renamed_fields(min_elevation_deg="min_elevation")
@dataclass(frozen=True)
class Observation:
    """A spacecraft on an orbit, seen from a site at UTC times, in an attitude law.

    Parameters
    ----------
    orbit : Orbit or Ephemeris
        Elements propagated by SGP4, or states from data
        (:class:`~sbrdf_xr.observing.ephemeris.Ephemeris`: tabulated states, a CCSDS OEM,
        an observer's tracking table).
    site : Site
    times : array_like of datetime64
        Strictly increasing UTC times (see :func:`~sbrdf_xr.observing.timescales.times`).
    attitude : AttitudeLaw, table or quaternion, optional
        Attitude law (:mod:`sbrdf_xr.observing.attitude`); default
        :class:`~sbrdf_xr.observing.attitude.Nadir`.
    airmass_model : str
        One of :data:`~sbrdf_xr.observing.orbits.AIRMASS_MODELS`.
    min_elevation : float
        Elevation [degree] below which the object counts as not observable (for the
        whole-window check of :meth:`geometry`).
    name : str
    earth : {"wgs84", "sphere"}
        Shape of the Earth for its shadow (:data:`~sbrdf_xr.observing.earth_shadow.EARTH_MODELS`).

    Warns
    -----
    EpochGapWarning
        When a time is more than :data:`~sbrdf_xr.observing.orbits.EPOCH_GAP_DAYS` from the
        element epoch.

    Examples
    --------
    >>> from sbrdf_xr.observing.attitude import Spin
    >>> from sbrdf_xr.observing.timescales import times
    >>> obs = Observation(Orbit.from_catalog("canx1-example"), Site.from_catalog("mont-megantic"),
    ...                   times("2024-03-17T01:22:00", "2024-03-17T01:22:10", 5.0),
    ...                   Spin(rate=10.0))
    >>> obs.times.size, obs.attitude.rate
    (3, 10.0)
    >>> g = obs.geometry()
    >>> sorted(g.data_vars)
    ['quaternion', 'to_earth', 'to_observer', 'to_sun']
    >>> np.round(g.elevation.values, 2)  # [degree]
    array([75.85, 75.93, 75.55])
    """

    orbit: Orbit | Ephemeris
    site: Site
    times: Any
    attitude: Any = None
    airmass_model: str = "kastenyoung1989"
    min_elevation: float = 0.0
    name: str = "observation"
    earth: str = "wgs84"
    _cache: dict[str, Any] = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not isinstance(self.orbit, Orbit | Ephemeris):
            raise ObservationError(
                f"orbit: expected an Orbit or an Ephemeris, got {type(self.orbit).__name__}"
            )
        if not isinstance(self.site, Site):
            raise ObservationError(f"site: expected a Site, got {type(self.site).__name__}")
        t = check_times(self.times)
        t.setflags(write=False)
        object.__setattr__(self, "times", t)
        object.__setattr__(self, "attitude", _as_law(self.attitude))
        if self.airmass_model not in AIRMASS_MODELS:
            raise ObservationError(
                f"airmass_model: got {self.airmass_model!r}; allowed: {', '.join(AIRMASS_MODELS)}"
            )
        if self.earth not in EARTH_MODELS:
            raise ObservationError(f"earth: got {self.earth!r}; allowed: {', '.join(EARTH_MODELS)}")
        min_el = to_unit(self.min_elevation, "deg", "min_elevation")
        object.__setattr__(self, "min_elevation", min_el)
        if not -90.0 <= float(self.min_elevation) <= 90.0:
            raise ObservationError(
                f"min_elevation: must lie in [-90, 90], got {self.min_elevation}"
            )
        if isinstance(self.orbit, Ephemeris):
            self.orbit.check_covers(t)
            return
        epoch = self.orbit.epoch
        gap = np.abs(t[[0, -1]] - epoch).max().astype(np.int64) / 86400e9
        if gap > EPOCH_GAP_DAYS:
            warnings.warn(
                f"observation times {t[0]} .. {t[-1]} reach {gap:.1f} days from the epoch "
                f"{epoch} of the elements of {self.orbit.name!r} "
                f"(more than {EPOCH_GAP_DAYS:g} days): SGP4 errors grow "
                "by about 1-3 km per day in LEO; use elements nearer the observation",
                EpochGapWarning,
                stacklevel=2,
            )

    def __repr__(self) -> str:
        t = self.times
        step = f", step {(t[1] - t[0]) / np.timedelta64(1, 's'):g} s" if t.size > 1 else ""
        return (
            f"<Observation {self.name!r}: {self.orbit.name!r} from {self.site.name or 'site'} "
            f"({self.site.latitude:.4f}, {self.site.longitude:.4f}, "
            f"{self.site.height:g} m), "
            f"{t.size} times {t[0]} .. {t[-1]}{step}, attitude {self.attitude!r}>"
        )

    def _state(self) -> dict[str, np.ndarray]:
        """Inertial-frame (GCRS) vectors per time, from one vectorised skyfield pass."""
        if "state" in self._cache:
            return self._cache["state"]
        from skyfield.framelib import itrs

        t = skyfield_time(self.times)
        if isinstance(self.orbit, Ephemeris):
            r, v = self.orbit.state(self.times)
            geo = None
        else:
            geo = self.orbit.satellite.at(t)
            r = geo.position.km.T
            v = geo.velocity.km_per_s.T
        if not np.all(np.isfinite(r)):
            bad = int(np.flatnonzero(~np.isfinite(r).all(axis=1))[0])
            msg = getattr(geo, "message", None)
            msg = msg[bad] if isinstance(msg, list | tuple | np.ndarray) else msg
            raise ObservationError(
                f"orbit {self.orbit.name!r}: SGP4 fails at {self.times[bad]}: {msg}"
            )
        # A velocity an ephemeris cannot give (NaN) leaves out the Sun's aberration by it.
        sun_rel = _sun_from_spacecraft(self.times, r, np.nan_to_num(v))
        site_r = self.site.position.at(t).position.km.T
        rot = itrs.rotation_at(t)  # GCRS -> ITRS, (3, 3, n)
        state = {"r": r, "v": v, "sun": sun_rel, "site": site_r, "itrs": rot}
        self._cache["state"] = state
        return state

    def context(self) -> _att.Context:
        """The :class:`~sbrdf_xr.observing.frames.Context` the attitude law sees.

        Examples
        --------
        >>> from sbrdf_xr.observing.attitude import Spin
        >>> from sbrdf_xr.observing.timescales import times
        >>> orbit, site = Orbit.from_catalog("canx1-example"), Site.from_catalog("mont-megantic")
        >>> obs = Observation(orbit, site, times("2024-03-17T01:22:00", "2024-03-17T01:22:10", 5.0),
        ...                   Spin(rate=10.0))
        >>> ctx = obs.context()
        >>> ctx.position.shape, round(float(np.linalg.norm(ctx.position[0])), 0)  # [km]
        ((3, 3), 7187.0)
        """
        st = self._state()
        return _att.Context(epoch=self.times[0], position=st["r"], velocity=st["v"], sun=st["sun"])

    def quaternions(self) -> NDArray[np.float64]:
        """Attitudes (body -> GCRS) at the observation times, sign-continuous; (n, 4).

        Examples
        --------
        >>> from sbrdf_xr.observing.attitude import Spin
        >>> from sbrdf_xr.observing.timescales import times
        >>> orbit, site = Orbit.from_catalog("canx1-example"), Site.from_catalog("mont-megantic")
        >>> obs = Observation(orbit, site, times("2024-03-17T01:22:00", "2024-03-17T01:22:10", 5.0),
        ...                   Spin(rate=10.0))
        >>> np.round(obs.quaternions(), 6)  # 10 degree s-1 about +z
        array([[0.      , 0.      , 0.      , 1.      ],
               [0.      , 0.      , 0.422618, 0.906308],
               [0.      , 0.      , 0.766044, 0.642788]])
        """
        ctx = self.context()
        unknown = ~np.isfinite(np.asarray(ctx.velocity)).all(axis=1)
        try:
            with np.errstate(invalid="ignore"):
                q = np.asarray(self.attitude.quaternions(self.times, ctx), dtype=np.float64)
        except (np.linalg.LinAlgError, ValueError):
            if not unknown.any():
                raise
            q = np.full((self.times.size, 4), np.nan)
        if q.shape != (self.times.size, 4):
            raise AttitudeError(
                f"attitude law returned shape {q.shape}, expected ({self.times.size}, 4)"
            )
        if not np.all(np.isfinite(q)) and unknown.any():
            bad = np.flatnonzero(~np.isfinite(q).all(axis=1) | unknown)
            raise AttitudeError(
                f"attitude law {self.attitude!r} gives no attitude at {bad.size} time(s), "
                f"first {self.times[bad[0]]}: the spacecraft's velocity is unknown there "
                f"({getattr(self.orbit, 'method', '')}); use a law that needs no velocity "
                "(inertial, spin, sun_pointing with target nadir or north) or give the times "
                "as tracks of several rows"
            )
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
            What to do when the object is below ``min_elevation`` at every time, or
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

        Examples
        --------
        >>> from sbrdf_xr.observing.attitude import Spin
        >>> from sbrdf_xr.observing.timescales import times
        >>> orbit, site = Orbit.from_catalog("canx1-example"), Site.from_catalog("mont-megantic")
        >>> obs = Observation(orbit, site, times("2024-03-17T01:22:00", "2024-03-17T01:22:10", 5.0),
        ...                   Spin(rate=10.0))
        >>> g = obs.geometry()
        >>> dict(g.sizes)
        {'time': 3, 'xyz': 3, 'component': 4}
        >>> np.round(g.phase_angle.values, 2), np.round(g.range.values, 1)
        (array([73.74, 75.3 , 76.87]), array([840.9, 840.7, 841.9]))
        """
        if on_unobservable not in UNOBSERVABLE:
            raise ObservationError(
                f"on_unobservable: got {on_unobservable!r}; allowed: {', '.join(UNOBSERVABLE)}"
            )
        st = self._state()
        r, sun, site_r, rot = st["r"], st["sun"], st["site"], st["itrs"]
        los = site_r - r  # spacecraft -> observer, GCRS
        rng = np.linalg.norm(los, axis=1)
        # Topocentric position in the ITRS, then the geodetic east-north-up frame.
        rel = np.einsum("ijn,nj->ni", rot, -los)
        lat, lon = np.radians(self.site.latitude), np.radians(self.site.longitude)
        east = np.array([-np.sin(lon), np.cos(lon), 0.0])
        north = np.array([-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)])
        up = np.array([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
        e, n_, u = rel @ east, rel @ north, rel @ up
        elevation = np.degrees(np.arctan2(u, np.hypot(e, n_)))
        azimuth = np.mod(np.degrees(np.arctan2(e, n_)), 360.0)
        sun_site = sun + r - site_r  # Sun from the observer
        sun_site_itrs = np.einsum("ijn,nj->ni", rot, sun_site)
        sun_el = np.degrees(
            np.arctan2(sun_site_itrs @ up, np.hypot(sun_site_itrs @ east, sun_site_itrs @ north))
        )
        pole = np.moveaxis(rot[2], 0, -1)  # the ITRS z axis in the GCRS, (n, 3)
        sunlit = sunlit_fraction(r, sun, earth=self.earth, pole=pole)
        phase = _angle(sun, los)
        elong = _angle(sun_site, -los)
        earth_phase = _angle(sun + r, r)

        reasons = []
        if np.all(elevation < self.min_elevation):
            i = int(np.argmax(elevation))
            reasons.append(
                f"below {self.min_elevation:g} deg elevation at every time "
                f"(highest {elevation[i]:.2f} deg at {self.times[i]}); " + self.next_pass()
            )
        if np.all(sunlit == 0):
            reasons.append(
                f"in the Earth's umbra at every time {self.times[0]} .. {self.times[-1]}"
            )
        if reasons and on_unobservable == "raise":
            raise NotObservableError(
                f"observation {self.name!r} of {self.orbit.name!r} from "
                f"{self.site.name or 'the site'}: " + "; ".join(reasons)
            )

        q = self.quaternions()
        rt = np.swapaxes(rotation_matrices(q), -1, -2)  # GCRS -> body
        body = {
            name: np.einsum("nij,nj->ni", rt, _unit(vec))
            for name, vec in (("to_sun", sun), ("to_observer", los), ("to_earth", -r))
        }
        coords = {
            TIME: (TIME, np.asarray(self.times), ATTRS[TIME]),
            VECTOR: (VECTOR, ["x", "y", "z"], ATTRS[VECTOR]),
            COMPONENT: (COMPONENT, ["x", "y", "z", "w"], ATTRS[COMPONENT]),
        }
        per_time = {
            "range": rng,
            "elevation": elevation,
            "azimuth": azimuth,
            "phase_angle": phase,
            "solar_elongation": elong,
            "sun_distance": np.linalg.norm(sun, axis=1) / AU_KM,
            "sunlit_fraction": sunlit,
            "airmass": airmass(elevation, self.airmass_model),
            "earth_distance": np.linalg.norm(r, axis=1),
            "earth_phase_angle": earth_phase,
            "site_sun_elevation": sun_el,
        }
        for k, val in per_time.items():
            coords[k] = (TIME, val, ATTRS[k])
        data = {k: ((TIME, VECTOR), val, ATTRS[k]) for k, val in body.items()}
        data["quaternion"] = ((TIME, COMPONENT), q, ATTRS["quaternion"])
        ds = xr.Dataset(data, coords=coords, attrs=self._attrs())
        for k, when in shadow_events(self.times, r, sun, earth=self.earth, pole=pole).items():
            ms = (when + np.timedelta64(500_000, "ns")).astype("datetime64[ms]")  # rounded
            ds.attrs[k] = " ".join(str(w) for w in ms)
        ds[TIME].encoding.update(
            units="seconds since 1970-01-01 00:00:00", calendar="standard", dtype="float64"
        )
        if reasons and on_unobservable == "empty":
            ds = ds.isel({TIME: slice(0, 0)})
            ds.attrs["unobservable"] = "; ".join(reasons)
        return ds

    @_errors.renamed_keywords(twilight_deg="twilight")
    def next_pass(self, days: float = 3.0, twilight: float = -12.0) -> str:
        """When the object next rises above ``min_elevation``, and whether it can be seen.

        From skyfield's :meth:`~skyfield.sgp4lib.EarthSatellite.find_events` over
        ``days`` from the first time of the observation; each pass is then sampled every
        10 s for the Sun: visible where the object is sunlit (half the solar disc or
        more) and the site's Sun is below ``twilight``.  When the next pass is not
        visible, the next visible one is named.  The table of passes, with refined
        edges, is :func:`sbrdf_xr.observing.passes.visible_passes`.

        Parameters
        ----------
        days : float
            How far ahead to look [day]; a Quantity is converted.
        twilight : float
            Site Sun elevation below which the sky is dark enough [degree] (nautical
            twilight by default).

        Returns
        -------
        str
            ``"it rises above 0 deg at ... UTC (highest ... deg at ... UTC, sets at ...
            UTC); visible ..."``, or that it does not within ``days``.

        Examples
        --------
        >>> from sbrdf_xr.observing.timescales import times
        >>> obs = Observation(Orbit.from_catalog("canx1-example"), Site.from_catalog("haleakala"),
        ...                   times("2024-03-17T01:20:00", "2024-03-17T01:25:00", 60.0))
        >>> print(obs.next_pass())  # doctest: +NORMALIZE_WHITESPACE
        it next rises above 0 deg at 2024-03-17T06:13:16 UTC (highest 22.0 deg at
        2024-03-17T06:20:04 UTC, sets at 2024-03-17T06:26:51 UTC); visible from
        2024-03-17T06:24:46 to 2024-03-17T06:26:46 UTC
        """
        from .timescales import skyfield_utc

        if isinstance(self.orbit, Ephemeris):
            return "sbrdf_xr.observing.passes.visible_passes finds the passes of an ephemeris"
        days = float(to_unit(days, "day", "days"))
        twilight = float(to_unit(twilight, "deg", "twilight"))
        t64 = np.array([self.times[0], self.times[0] + np.timedelta64(round(days * 86400), "s")])
        t0, t1 = skyfield_utc(t64)
        when, kind = self.orbit.satellite.find_events(
            self.site.position, t0, t1, altitude_degrees=float(self.min_elevation)
        )
        if not len(when):
            return (
                f"it does not rise above {self.min_elevation:g} deg within {days:g} days "
                f"after {self.times[0]}"
            )
        stamps = [str(np.datetime64(t.replace(tzinfo=None), "s")) for t in when.utc_datetime()]
        kinds = [int(k) for k in kind]
        start = kinds.index(0) if 0 in kinds else 0
        text = f"it next rises above {self.min_elevation:g} deg at {stamps[start]} UTC"
        rest = list(zip(kinds[start + 1 :], stamps[start + 1 :], strict=True))
        culm = next((s for k, s in rest if k == 1), None)
        sets = next((s for k, s in rest if k == 2), None)
        if culm is not None:
            alt = self._altitude_at(when[kinds.index(1, start)])
            text += f" (highest {alt:.1f} deg at {culm} UTC"
            text += f", sets at {sets} UTC)" if sets is not None else ")"
        rises = [i for i in range(start, len(kinds)) if kinds[i] == 0]
        for n, i in enumerate(rises):
            end = next((stamps[j] for j in range(i + 1, len(kinds)) if kinds[j] == 2), None)
            seen, why = self._visible(stamps[i], end or str(t64[1]), twilight)
            if seen and n == 0:
                return text + f"; visible {seen}"
            if n == 0:
                text += f"; not visible ({why})"
            elif seen:
                return text + f"; the next visible pass rises at {stamps[i]} UTC (visible {seen})"
        return text + f"; no visible pass within {days:g} days"

    def _visible(self, start: str, stop: str, twilight_deg: float) -> tuple[str, str]:
        """When a pass is visible (sunlit, site dark) on a 10-s grid, else why not."""
        from .timescales import times

        grid = times(start, stop, 10.0)
        law = _att.Inertial((0.0, 0.0, 0.0, 1.0))
        obs = Observation(self.orbit, self.site, grid, law, min_elevation=-90.0, earth=self.earth)
        g = obs.geometry(on_unobservable="keep")
        lit = g.sunlit_fraction.values >= 0.5
        dark = g.site_sun_elevation.values < twilight_deg
        ok = np.flatnonzero(lit & dark)
        if ok.size:
            a, b = (str(grid[k].astype("datetime64[s]")) for k in (ok[0], ok[-1]))
            return f"from {a} to {b} UTC", ""
        if not dark.any():
            sun = float(g.site_sun_elevation.values.min())
            return "", f"the site's Sun is at {sun:.1f} deg, above {twilight_deg:g} deg"
        return "", "in the Earth's shadow"

    def _altitude_at(self, t: Any) -> float:
        sat = getattr(self.orbit, "satellite", None)  # an Orbit: only it has find_events
        topo = (sat - self.site.position).at(t)
        return float(topo.altaz()[0].degrees)

    def _attrs(self) -> dict[str, Any]:
        import skyfield
        import skyfield_data

        orbit = self.orbit
        out = {
            "observation": self.name,
            "orbit_name": self.orbit.name,
            "tle_line1": orbit.line1 if isinstance(orbit, Orbit) else "",
            "tle_line2": orbit.line2 if isinstance(orbit, Orbit) else "",
            "orbit_provenance": self.orbit.provenance,
            "site_name": self.site.name,
            "site_latitude": self.site.latitude,
            "site_longitude": self.site.longitude,
            "site_height": self.site.height,
            "site_source": self.site.source,
            "site_coordinates": (
                "WGS84 geodetic latitude and east longitude [degree], "
                "height above the ellipsoid [m]"
            ),
            "attitude_law": repr(self.attitude),
            "reference_frame": (
                "GCRS (ICRF axes, geocentric); quaternions rotate body vectors into it"
            ),
            "propagator": f"SGP4 (sgp4 via skyfield {skyfield.__version__})",
            "ephemeris": (
                "de421.bsp and finals2000A.all from skyfield-data "
                f"{getattr(skyfield_data, '__version__', '')}"
            ).strip(),
            "shadow_model": (
                (
                    f"WGS84 ellipsoid a = {EARTH_EQUATORIAL_RADIUS_KM} km, "
                    f"1/f = {1 / WGS84_FLATTENING:.9f}"
                    if self.earth == "wgs84"
                    else f"spherical Earth R = {EARTH_EQUATORIAL_RADIUS_KM} km"
                )
                + f", solar disc R = {SUN_RADIUS_KM} km, "
                "exact disc-overlap area (Montenbruck & Gill 2000, 3.4.2); "
                "edge times UTC [ms], space-separated, empty when none"
            ),
            "airmass_model": self.airmass_model,
        }
        if isinstance(orbit, Ephemeris):
            del out["tle_line1"], out["tle_line2"]
            out.update(orbit.attrs())
        return out
