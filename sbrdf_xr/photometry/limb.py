"""Sunlight that reaches a spacecraft through the Earth's limb: refraction and extinction.

Near the edge of the Earth's shadow the ray from the Sun to a spacecraft grazes the
atmosphere.  A geometric shadow (a solid Earth, :mod:`sbrdf_xr.observing`) keeps such a
spacecraft in full sunlight; the atmosphere dims it by magnitudes, and refraction lets
light into the geometric shadow.  The model is the one of lunar-eclipse theory (Link
1969, *Eclipse Phenomena in Astronomy*, Springer, ch. 2-3), used for satellites by
Mallama (2021, arXiv:2112.08966):

* **the ray**: :func:`limb_ray` gives the height above the WGS84 ellipsoid of the
  straight (unrefracted) line from the spacecraft toward the Sun at its lowest point,
  ``h_app``, and the distance ``D`` from that point to the spacecraft;
* **the atmosphere**: a spherically stratified atmosphere with the densities of the US
  Standard Atmosphere 1976 (NOAA/NASA/USAF, Table I; 0-80 km, exponential above);
  refractivity proportional to density, ``N0 = 2.78e-4`` at sea level for 550 nm, 15 C
  (Edlen 1966, Metrologia 2, 71, Eq. 1), scaled by Edlen's dispersion; the Rayleigh
  optical depth (Hansen & Travis 1974, Eq. 2.29) distributed as the density; ozone's
  Chappuis band as a Gaussian layer at 22 km, 6 km wide (the mid-latitude profile's peak),
  with the zenith optical depth given (0.03 in V: 300 Dobson units);
* **refraction**: a ray whose lowest point is at ``h`` is bent by
  ``delta(h) = -2 r_h int N'(r) / sqrt(r^2 - r_h^2) dr`` (``r_h = R + h``; Link 1969,
  Eq. 2.9, small refractivity), toward the Earth, so the ray that reaches the
  spacecraft from the Sun passes at ``h`` with ``h_app = h - D delta(h)``;
* **transmission** of that ray: ``exp(-tau(h)) / (1 - D d(delta)/dh)``, the slant
  optical depth through the limb times the spreading of neighbouring rays (they are
  bent the more the lower they pass: defocusing; the horizontal focusing,
  ``1 + D delta / R`` < 1 %, is left out);
* **the Sun's disc**: averaged over a uniform disc of angular radius ``sun_radius``
  (each horizontal strip of the disc has its own ``h_app``); a ray below the ground
  (``h < 0``) is blocked, so the geometric penumbra is inside the average.

Left out: clouds and tropospheric aerosols (they matter below ~10 km, where the
transmission is already below 1e-2), limb darkening, and the colour of the transmitted
light (one wavelength).
"""

from __future__ import annotations

from functools import cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import ValidationError
from ..units import to_unit
from .atmosphere import rayleigh_optical_depth

__all__ = ["OZONE_OPTICAL_DEPTH_V", "limb_ray", "limb_transmission"]

#: Zenith optical depth of ozone's Chappuis band in V [1] (300 DU, sigma ~3.7e-21 cm2).
OZONE_OPTICAL_DEPTH_V = 0.03

_WGS84_A, _WGS84_B = 6378.137, 6356.752314245  # [km]
_R = 6371.0  # [km], mean radius: the sphere of the stratified atmosphere
#: US Standard Atmosphere 1976, density [kg m-3] at these heights [km] (Table I).
_Z = np.array([0.0, 5, 10, 15, 20, 25, 30, 35, 40, 45, 50, 60, 70, 80])
_RHO = np.array(
    [1.2250, 0.7364, 0.4135, 0.1948, 0.08891, 0.04008, 0.01841, 0.008463, 0.003996,
     0.001966, 0.001027, 3.097e-4, 8.283e-5, 1.846e-5]
)  # fmt: skip
_H_TOP = 5.6  # [km], density scale height above 80 km
_O3_Z, _O3_W = 22.0, 6.0  # [km]
#: Path from the lowest point of the ray [km]: fine near it, out to 1500 km (z ~ 170 km).
_S = np.concatenate([np.linspace(0.0, 50.0, 501)[:-1], np.linspace(50.0, 1500.0, 1451)])
#: Heights of the ray's lowest point at which the atmosphere is tabulated [km].
_HT = np.concatenate([np.linspace(0.0, 60.0, 1201), np.linspace(60.5, 150.0, 180)])


def _density(z: np.ndarray) -> np.ndarray:
    """Density relative to sea level [1] at height ``z`` [km] (>= 0)."""
    lr = np.interp(np.minimum(z, _Z[-1]), _Z, np.log(_RHO)) - np.maximum(z - _Z[-1], 0) / _H_TOP
    return np.exp(lr) / _RHO[0]


def _ozone(z: np.ndarray) -> np.ndarray:
    return np.exp(-0.5 * ((z - _O3_Z) / _O3_W) ** 2)


def _slant(h: np.ndarray, profile: object) -> np.ndarray:
    """The profile integrated along the ray whose lowest point is at ``h``, per its
    vertical column (the slant-to-zenith ratio)."""
    z = np.sqrt((_R + h[:, None]) ** 2 + _S**2) - _R
    zs = np.linspace(0.0, 200.0, 20001)
    return 2.0 * np.trapezoid(profile(z), _S, axis=1) / np.trapezoid(profile(zs), zs)  # type: ignore[operator]


def _bending(h: np.ndarray, n0: float) -> np.ndarray:
    """Bending [rad] of the ray whose lowest point is at ``h`` [km] (module docstring)."""
    rh = _R + h[:, None]
    r = np.sqrt(rh**2 + _S**2)  # dr / sqrt(r^2 - r_h^2) = ds / r
    dz = 1e-3
    dn = n0 * (_density(r - _R + dz) - _density(r - _R - dz)) / (2 * dz)
    return -2.0 * rh[:, 0] * np.trapezoid(dn / r, _S, axis=1)


@cache
def _tables(wavelength: float, ozone: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    s2 = (1000.0 / wavelength) ** 2  # Edlen 1966, Eq. 1 (sigma in um-1)
    n0 = 1e-8 * (8342.13 + 2406030.0 / (130.0 - s2) + 15997.0 / (38.9 - s2))
    delta = _bending(_HT, n0)
    tau = float(rayleigh_optical_depth(wavelength)) * _slant(_HT, _density)
    tau = tau + ozone * _slant(_HT, _ozone)
    return delta, np.gradient(delta, _HT), tau


def limb_ray(position: ArrayLike, to_sun: ArrayLike) -> tuple[NDArray[np.float64], ...]:
    """The straight ray from a spacecraft toward the Sun at its lowest point.

    Parameters
    ----------
    position : array_like, shape (N, 3)
        Spacecraft positions in an Earth-fixed frame (ITRS) [km].
    to_sun : array_like, shape (N, 3)
        Directions to the Sun in the same frame [1] (normalised here).

    Returns
    -------
    tangent_height, distance : ndarray, shape (N,)
        The least height of the ray above the WGS84 ellipsoid [km] and the distance
        from that point to the spacecraft [km].  A ray that climbs away from the Earth
        has its lowest point at the spacecraft: distance 0, the spacecraft's height.

    Examples
    --------
    A spacecraft 7000 km from the centre over the equator, the Sun along the equator at
    right angles: the ray's lowest point is the spacecraft's own point, 622 km up.

    >>> h, d = limb_ray([[7000.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    >>> round(float(h[0]), 3), float(d[0])
    (621.863, 0.0)

    The Sun 100 deg from the zenith: the ray passes 6893.6 km from the centre (515.5 km
    above the equator), 1215.5 km on.

    >>> a = np.radians(100.0)
    >>> h, d = limb_ray([[7000.0, 0.0, 0.0]], [[np.cos(a), np.sin(a), 0.0]])
    >>> round(float(h[0]), 1), round(float(d[0]), 1)
    (515.5, 1215.5)
    """
    p = np.atleast_2d(to_unit(position, "km", "position")).astype(np.float64)
    s = np.atleast_2d(np.asarray(to_sun, dtype=np.float64))
    if p.shape[-1] != 3 or s.shape != p.shape or not np.all(np.isfinite(p)):
        raise ValidationError(
            f"limb_ray: position and to_sun must be finite (N, 3) arrays of the same "
            f"shape; got {p.shape} and {s.shape}"
        )
    s = s / np.linalg.norm(s, axis=1, keepdims=True)

    def height(x: np.ndarray) -> np.ndarray:
        # above the ellipsoid along the radius (within metres of the geodetic height
        # at these heights)
        r = np.linalg.norm(x, axis=-1)
        sin2 = (x[..., 2] / r) ** 2
        return r - _WGS84_A * _WGS84_B / np.sqrt(_WGS84_B**2 * (1 - sin2) + _WGS84_A**2 * sin2)

    lam0 = np.maximum(-np.einsum("ni,ni->n", p, s), 0.0)  # the closest approach to the centre
    best = lam0
    for half in (300.0, 1.0, 0.01):  # steps of 1 km, 10 m, 0.1 m
        lam = np.maximum(best[:, None] + np.linspace(-half, half, 601 if half > 1 else 201), 0.0)
        h = height(p[:, None, :] + lam[..., None] * s[:, None, :])
        best = lam[np.arange(len(p)), np.argmin(h, axis=1)]
    d = np.where(lam0 > 0, best, 0.0)
    return height(p + d[:, None] * s), d


def limb_transmission(
    tangent_height: ArrayLike,
    distance: ArrayLike,
    *,
    wavelength: float = 550.0,
    ozone_optical_depth: float = OZONE_OPTICAL_DEPTH_V,
    sun_radius: float = 0.2666,
    nodes: int = 48,
) -> NDArray[np.float64]:
    """Sunlight reaching a spacecraft through the Earth's limb, per unit sunlight [1].

    The model of the module docstring: refraction, its defocusing and the extinction of
    Rayleigh scattering and ozone, averaged over the Sun's disc, with the ground's cut.

    Parameters
    ----------
    tangent_height : array_like
        Height of the straight ray toward the Sun's centre at its lowest point [km]
        (:func:`limb_ray`).
    distance : array_like
        Distance from that point to the spacecraft [km]; 0: the ray does not cross the
        atmosphere (transmission 1).
    wavelength : float
        [nm], for the Rayleigh optical depth and the refractivity.
    ozone_optical_depth : float
        Zenith optical depth of ozone at ``wavelength`` [1].
    sun_radius : float
        Angular radius of the Sun's disc [degree].
    nodes : int
        Gauss-Legendre strips across the disc.

    Returns
    -------
    ndarray
        The factor on the sunlight [1]: 1 far from the limb, 0 deep in the shadow.

    Examples
    --------
    A Starlink-like 2700 km beyond the lowest point of its ray: unaffected at 80 km, 0.55
    mag fainter at 30 km, 3.8 mag at the geometric shadow's edge (0 km), where the solid
    Earth alone would hide half the disc (0.75 mag).

    >>> t = limb_transmission([80.0, 30.0, 0.0], 2700.0)
    >>> np.round(-2.5 * np.log10(t), 2)
    array([0.  , 0.55, 3.79])
    >>> float(limb_transmission(300.0, 0.0))
    1.0
    """
    h = np.asarray(to_unit(tangent_height, "km", "tangent_height"), dtype=np.float64)
    d = np.asarray(to_unit(distance, "km", "distance"), dtype=np.float64)
    wl = float(to_unit(wavelength, "nm", "wavelength", spectral=True))
    rad = np.radians(float(to_unit(sun_radius, "deg", "sun_radius")))
    h, d = np.broadcast_arrays(h, d)
    if not (np.all(np.isfinite(h)) and np.all(np.isfinite(d)) and np.all(d >= 0)):
        raise ValidationError(
            "limb_transmission: tangent_height must be finite and distance finite and "
            f">= 0 [km]; got heights {np.nanmin(h):g}..{np.nanmax(h):g}, distances "
            f"{np.nanmin(d):g}..{np.nanmax(d):g}"
        )
    if not 0.0 <= ozone_optical_depth < 1.0 or nodes < 2:
        raise ValidationError(
            f"limb_transmission: ozone_optical_depth {ozone_optical_depth!r} (allowed "
            f"0 <= . < 1) or nodes {nodes!r} (allowed >= 2)"
        )
    delta, slope, tau = _tables(wl, float(ozone_optical_depth))
    y, w = np.polynomial.legendre.leggauss(nodes)
    w = w * np.sqrt(1.0 - y**2)
    w /= w.sum()
    flat_h, flat_d = h.ravel(), d.ravel()
    out = np.ones(flat_h.size)
    for k in np.flatnonzero(flat_d > 0):
        h_app = flat_h[k] + flat_d[k] * rad * y
        grid = _HT - flat_d[k] * delta  # h_app of the ray lowest at _HT: increasing
        ht = np.interp(h_app, grid, _HT, left=-1.0, right=np.nan)
        above = np.isnan(ht)  # above the table: a straight, clear ray
        ht = np.where(above, h_app, ht)
        t = np.exp(-np.interp(ht, _HT, tau, right=0.0))
        t /= 1.0 - flat_d[k] * np.interp(ht, _HT, slope, right=0.0)
        out[k] = float(np.sum(w * np.where(ht >= 0.0, t, 0.0)))
    return out.reshape(h.shape)
