"""The Earth's shadow on a spacecraft: the sunlit fraction of the solar disc.

A spherical Earth and the Sun's finite disc: the fraction of the apparent solar disc seen
from the spacecraft that the apparent Earth disc does not cover (:func:`sunlit_fraction`),
from the exact area of overlap of two circles (:func:`disc_overlap_fraction`; Montenbruck &
Gill, *Satellite Orbits*, 2000, §3.4.2).  Pure vectorised numpy.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["EARTH_RADIUS_KM", "SUN_RADIUS_KM", "disc_overlap_fraction", "sunlit_fraction"]

#: Equatorial radius of the Earth (WGS84) used by the shadow model [km].
EARTH_RADIUS_KM = 6378.137


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
