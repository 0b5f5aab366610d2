"""The Earth's shadow on a spacecraft: the sunlit fraction of the solar disc.

The WGS84 ellipsoid (or a sphere) and the Sun's finite disc: the fraction of the apparent
solar disc seen from the spacecraft that the apparent Earth disc does not cover
(:func:`sunlit_fraction`), from the exact area of overlap of two circles
(:func:`disc_overlap_fraction`; Montenbruck & Gill, *Satellite Orbits*, 2000, §3.4.2), and
the times the spacecraft crosses the edges of the umbra and the penumbra
(:func:`shadow_events`).  Pure vectorised numpy.

The ellipsoid is made a sphere of radius ``a`` by stretching space along the polar axis by
``k = a/b``.  The map sends lines to lines, so whether a ray from the spacecraft meets the
Earth is unchanged: the Earth's disc and the direction of the Sun's centre are exact.  The
stretched Sun is a spheroid; its apparent disc is taken as a circle of its angular extent
towards the Earth's centre, ``asin(R_sun |M e| / |s'|)`` (``M`` the stretch, ``e`` that
direction), which puts the edges of the umbra and the penumbra where the tangent rays are
(to the order of the Sun's angular radius times ``k - 1``, ``1.6e-5`` of it) and leaves the
sunlit fraction inside the penumbra within ``k - 1 = 0.34 %`` of the solar disc's area.

Positions and radii are in km, the angles of the discs in radians; an astropy Quantity
is converted first (:func:`sbrdf_xr.units.to_unit`; another kind raises
:class:`~sbrdf_xr.errors.UnitError`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._names import SHADOW_EVENTS
from ..errors import ObservationError, renamed_attributes, renamed_keywords
from ..units import to_unit

__all__ = [
    "EARTH_EQUATORIAL_RADIUS_KM",
    "EARTH_MODELS",
    "SHADOW_EVENTS",
    "SUN_RADIUS_KM",
    "WGS84_FLATTENING",
    "disc_overlap_fraction",
    "shadow_angles",
    "shadow_events",
    "sunlit_fraction",
]

#: Equatorial radius of the Earth (WGS84) used by the shadow model [km].
EARTH_EQUATORIAL_RADIUS_KM = 6378.137

#: Flattening of the WGS84 ellipsoid, ``f = 1/298.257223563`` (polar radius ``a (1 - f)``).
WGS84_FLATTENING = 1.0 / 298.257223563

#: Shapes of the Earth the shadow model knows: the WGS84 ellipsoid, or a sphere of the
#: equatorial radius.
EARTH_MODELS = ("wgs84", "sphere")


#: Nominal solar radius (IAU 2015 Resolution B3) [km].
SUN_RADIUS_KM = 695700.0


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
    a, b, c = np.broadcast_arrays(
        *(
            np.asarray(to_unit(x, "rad", k), dtype=np.float64)
            for k, x in zip("abc", (a, b, c), strict=True)
        )
    )
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


def _stretch(x: NDArray[np.float64], pole: NDArray[np.float64], k: float) -> NDArray[np.float64]:
    """``x + (k - 1) (x . p) p``: the stretch by ``k`` along the unit vector ``p``."""
    return x + (k - 1.0) * np.einsum("...i,...i->...", x, pole)[..., None] * pole


@renamed_keywords(
    position_km="position", sun_km="sun", earth_radius_km="earth_radius", sun_radius_km="sun_radius"
)
def shadow_angles(
    position: ArrayLike,
    sun: ArrayLike,
    earth: str = "wgs84",
    pole: ArrayLike = (0.0, 0.0, 1.0),
    earth_radius: float = EARTH_EQUATORIAL_RADIUS_KM,
    sun_radius: float = SUN_RADIUS_KM,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Apparent radii of the Sun and the Earth and their separation [rad] (see the module).

    The arguments are those of :func:`sunlit_fraction`; returns ``(a, b, c)`` for
    :func:`disc_overlap_fraction`.  The umbra is ``c < b - a``, the penumbra
    ``b - a < c < a + b``.

    Parameters
    ----------
    position : array_like, shape (3,) or (n, 3)
        The spacecraft's geocentric position [km].
    sun : array_like, shape (3,) or (n, 3)
        The Sun as seen from the spacecraft [km].
    earth : {"wgs84", "sphere"}
        The Earth's shape.
    pole : array_like, shape (3,) or (n, 3)
        The Earth's rotation axis (unit vector) [1].
    earth_radius : float
        Radius of the spherical Earth, equatorial radius of the ellipsoid [km].
    sun_radius : float
        Radius of the Sun [km].

    Returns
    -------
    tuple of ndarray
        ``(a, b, c)`` [rad].

    Examples
    --------
    7000 km from the Earth's centre, straight behind it, 1 AU from the Sun: for a spherical
    Earth ``b = asin(R_earth / 7000 km)`` = 65.6665 deg, the Sun's disc 0.2664 deg, and the
    spacecraft is in the umbra; a quarter turn of the orbit later it is in full sunlight.
    Over the pole the WGS84 angles are those of the stretched space (see the module), in
    which the polar distance grows by ``a/b`` and the Earth's disc looks smaller.

    >>> import numpy as np
    >>> from sbrdf_xr.observing.earth_shadow import shadow_angles
    >>> a, b, c = shadow_angles([-7000.0, 0.0, 0.0], [1.496e8, 0.0, 0.0], earth="sphere")
    >>> print(np.degrees([a, b, c]).round(4), bool(c < b - a))
    [ 0.2664 65.6665  0.    ] True
    >>> a, b, c = shadow_angles([0.0, 7000.0, 0.0], [1.496e8, 0.0, 0.0])
    >>> print(np.degrees(c).round(4), bool(c > a + b))
    90.0 True
    >>> a, b, c = shadow_angles([0.0, 0.0, -7000.0], [0.0, 0.0, 1.496e8])
    >>> print(np.degrees(b).round(4))
    65.2451
    """
    if earth not in EARTH_MODELS:
        raise ObservationError(f"earth: got {earth!r}; allowed: {', '.join(EARTH_MODELS)}")
    r = np.asarray(to_unit(position, "km", "position"), dtype=np.float64)
    s = np.asarray(to_unit(sun, "km", "sun"), dtype=np.float64)
    earth_radius = to_unit(earth_radius, "km", "earth_radius")
    sun_radius = to_unit(sun_radius, "km", "sun_radius")
    factor: NDArray[np.float64] | float = 1.0
    if earth == "wgs84":
        p = np.asarray(pole, dtype=np.float64)
        p = p / np.linalg.norm(p, axis=-1, keepdims=True)
        k = 1.0 / (1.0 - WGS84_FLATTENING)
        r, s = _stretch(r, p, k), _stretch(s, p, k)
        # Unit vector across the line of sight towards the Earth's centre (any one on the
        # axis of the shadow, where the factor does not matter: the discs are concentric).
        e = (
            -r
            - np.einsum("...i,...i->...", -r, s)[..., None]
            * s
            / np.einsum("...i,...i->...", s, s)[..., None]
        )
        ne = np.linalg.norm(e, axis=-1)
        e = e / np.where(ne > 0, ne, 1.0)[..., None]
        factor = np.where(ne > 0, np.linalg.norm(_stretch(e, p, k), axis=-1), 1.0)
    dr = np.linalg.norm(r, axis=-1)
    ds = np.linalg.norm(s, axis=-1)
    a = np.arcsin(np.minimum(sun_radius * factor / ds, 1.0))
    b = np.arcsin(np.minimum(earth_radius / dr, 1.0))
    c = np.arctan2(np.linalg.norm(np.cross(s, -r), axis=-1), np.einsum("...i,...i->...", s, -r))
    return a, b, c


@renamed_keywords(
    position_km="position", sun_km="sun", earth_radius_km="earth_radius", sun_radius_km="sun_radius"
)
def sunlit_fraction(
    position: ArrayLike,
    sun: ArrayLike,
    earth_radius: float = EARTH_EQUATORIAL_RADIUS_KM,
    sun_radius: float = SUN_RADIUS_KM,
    *,
    earth: str = "wgs84",
    pole: ArrayLike = (0.0, 0.0, 1.0),
) -> NDArray[np.float64]:
    """Fraction of the solar disc seen from a spacecraft that the Earth does not hide.

    Apparent radii ``a`` (Sun) and ``b`` (Earth) and separation ``c`` enter
    :func:`disc_overlap_fraction` (Montenbruck & Gill 2000, §3.4.2): 0 in the umbra, the
    visible fraction of the disc in the penumbra, 1 in sunlight.  For a sphere
    ``a = asin(R_sun/|s|)``, ``b = asin(R_earth/|r|)`` and ``c`` the angle between ``s`` and
    ``-r``; for the WGS84 ellipsoid the same after the stretch along the pole of the module
    description.

    Parameters
    ----------
    position : array_like, shape (..., 3)
        Geocentric position of the spacecraft [km].
    sun : array_like, shape (..., 3)
        Position of the Sun relative to the spacecraft [km].
    earth_radius, sun_radius : float
        Equatorial radius of the Earth and radius of the Sun [km]; ``sun_radius = 0``
        gives a point Sun.
    earth : {"wgs84", "sphere"}
        The WGS84 ellipsoid (polar radius ``earth_radius (1 - f)``,
        :data:`WGS84_FLATTENING`) or a sphere of radius ``earth_radius``.
    pole : array_like, shape (..., 3)
        The Earth's rotation axis in the frame of the vectors (the ITRS ``z`` axis; the
        GCRS ``z`` axis is off it by precession and nutation, 0.13 degree in 2024).

    Returns
    -------
    ndarray, shape (...)

    Raises
    ------
    ObservationError
        For an unknown ``earth``.

    Examples
    --------
    >>> sun = [[1.5e8, 0.0, 0.0]] * 3  # the Sun along +x from each spacecraft [km]
    >>> pos = [[7000.0, 0.0, 0.0], [-7000.0, 0.0, 0.0], [-7000.0, 6378.137, 0.0]]
    >>> np.round(sunlit_fraction(pos, sun, earth="sphere"), 3)  # day, umbra, shadow's edge
    array([1.   , 0.   , 0.501])
    >>> over_pole = [-7000.0, 0.0, 6380.0]  # a sphere hides more than the ellipsoid here
    >>> np.round([sunlit_fraction(over_pole, sun[0], earth=e) for e in EARTH_MODELS], 3)
    array([0.913, 0.537])
    """
    return disc_overlap_fraction(
        *shadow_angles(position, sun, earth, pole, earth_radius, sun_radius)
    )


@renamed_keywords(
    position_km="position", sun_km="sun", earth_radius_km="earth_radius", sun_radius_km="sun_radius"
)
def shadow_events(
    times: ArrayLike,
    position: ArrayLike,
    sun: ArrayLike,
    *,
    earth: str = "wgs84",
    pole: ArrayLike = (0.0, 0.0, 1.0),
    earth_radius: float = EARTH_EQUATORIAL_RADIUS_KM,
    sun_radius: float = SUN_RADIUS_KM,
) -> dict[str, NDArray[np.datetime64]]:
    """UTC times the spacecraft crosses the edges of the penumbra and the umbra.

    The vectors sampled at ``times`` are interpolated by cubic splines in time; an edge is
    a sign change of ``c - (a + b)`` (penumbra) or ``c - (b - a)`` (umbra) of
    :func:`shadow_angles` between two samples, refined by Brent's method to 1 µs.  Two
    crossings of one edge within one step are not seen.

    Parameters
    ----------
    times : array_like of datetime64, shape (n,)
        Strictly increasing UTC times.
    position, sun : array_like, shape (n, 3)
        As in :func:`sunlit_fraction`, at ``times`` [km].
    earth, pole
        As in :func:`sunlit_fraction`; ``pole`` of shape (3,) or (n, 3).
    earth_radius, sun_radius : float
        As in :func:`sunlit_fraction` [km].

    Returns
    -------
    dict
        For each name of :data:`SHADOW_EVENTS` the datetime64[ns] times of that event,
        in order (empty when there is none).

    Examples
    --------
    >>> t = np.datetime64("2024-01-01T00:00:00", "ns") + np.arange(0, 121, 10) * 10**9
    >>> w = 2 * np.pi / 5900.0  # a circular orbit of 7000 km in the Sun's plane [rad s-1]
    >>> phase = 1.95 + w * np.arange(0, 121, 10)
    >>> pos = 7000.0 * np.stack([np.cos(phase), np.sin(phase), 0 * phase], axis=1)
    >>> ev = shadow_events(t, pos, [1.5e8, 0.0, 0.0] - pos, earth="sphere")
    >>> for k, v in ev.items():  # entering the shadow
    ...     print(k, v.astype("datetime64[ms]"))
    penumbra_entry ['2024-01-01T00:00:38.326']
    umbra_entry ['2024-01-01T00:00:47.036']
    umbra_exit []
    penumbra_exit []
    """
    from scipy.interpolate import CubicSpline
    from scipy.optimize import brentq

    t = np.asarray(times).astype("datetime64[ns]")
    out: dict[str, NDArray[np.datetime64]] = {k: t[:0] for k in SHADOW_EVENTS}
    if t.size < 2:
        return out
    secs = (t - t[0]).astype(np.int64) / 1e9
    r = np.asarray(to_unit(position, "km", "position"), dtype=np.float64)
    s = np.broadcast_to(np.asarray(to_unit(sun, "km", "sun"), dtype=np.float64), r.shape)
    earth_radius = to_unit(earth_radius, "km", "earth_radius")
    sun_radius = to_unit(sun_radius, "km", "sun_radius")
    p = np.broadcast_to(np.asarray(pole, dtype=np.float64), r.shape)
    spline = CubicSpline(secs, np.concatenate([r, s, p], axis=1), axis=0)

    def edges(x: ArrayLike) -> NDArray[np.float64]:
        v = spline(x)
        a, b, c = shadow_angles(
            v[..., 0:3], v[..., 3:6], earth, v[..., 6:9], earth_radius, sun_radius
        )
        return np.stack([c - (a + b), c - (b - a)], axis=-1)

    g = edges(secs)
    for j, (entry, leave) in enumerate(
        (("penumbra_entry", "penumbra_exit"), ("umbra_entry", "umbra_exit"))
    ):
        inside = g[:, j] < 0
        found: dict[str, list[float]] = {entry: [], leave: []}
        for i in np.flatnonzero(inside[1:] != inside[:-1]):
            root = brentq(lambda x, j=j: float(edges(x)[j]), secs[i], secs[i + 1], xtol=1e-6)
            found[entry if inside[i + 1] else leave].append(root)
        for k, v in found.items():
            out[k] = t[0] + np.round(np.asarray(v) * 1e9).astype("timedelta64[ns]")
    return out


#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(
    __name__, globals(), {"EARTH_RADIUS_KM": "EARTH_EQUATORIAL_RADIUS_KM"}
)
