"""Physics of the light sources besides the Sun's spectrum: Planck, earthshine, moonlight,
Kirchhoff.

Pure numpy (no xarray, no I/O).  The Sun's spectral irradiance lives with the
photometry (it is a data set); here are the closed forms the effects of a
simulation need:

* :func:`planck`: blackbody spectral radiance (thermal emission of the facets);
* :func:`earthshine_irradiance_ratio`: light reflected by a Lambertian Earth onto the
  spacecraft, relative to the Sun's;
* :func:`moon_v_magnitude` and :func:`moonlight_irradiance_ratio`: the Moon's brightness
  against its phase angle (Allen's law as used by Krisciunas & Schaefer 1991) and its
  light at the spacecraft, relative to the Sun's;
* :func:`kirchhoff_emissivity`: directional emissivity from directional-hemispherical
  reflectance, and :func:`emissivity_at`, its linear interpolation in the emission
  angle;
* :func:`earthshine_finite` and :func:`earth_thermal_irradiance`: the Earth at its true
  size, reflected sunlight and thermal emission on a plate (quadrature over the disc);
* :func:`equilibrium_temperature`: a facet's radiative-equilibrium temperature, and
  :func:`radiative_cooling`: its cooling in the shadow.

Arguments with a unit (wavelengths [nm], temperatures [K], angles [degree], distances
[km]) also take an astropy Quantity, converted first (:func:`sbrdf_xr.units.to_unit`;
another kind raises :class:`~sbrdf_xr.errors.UnitError`).
"""

from __future__ import annotations

import functools

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import constants

from .errors import ValidationError, renamed_attributes, renamed_keywords
from .units import check_plausible, to_unit

__all__ = [
    "EARTH_MEAN_RADIUS_KM",
    "EARTH_NODES",
    "EARTH_TEMPERATURE_MAX",
    "MOON_MEAN_DISTANCE_KM",
    "MOON_RADIUS_KM",
    "SUN_V_MAGNITUDE",
    "earth_thermal_irradiance",
    "earth_view_facets",
    "earthshine_facets",
    "earthshine_finite",
    "earthshine_irradiance_ratio",
    "emissivity_at",
    "equilibrium_temperature",
    "kirchhoff_emissivity",
    "moon_v_magnitude",
    "moonlight_irradiance_ratio",
    "planck",
    "radiative_cooling",
]

#: Earth's mean radius [km].
EARTH_MEAN_RADIUS_KM = 6371.0
#: The Moon's mean distance from the Earth's centre [km], the distance its magnitude law
#: refers to (Allen 1973; Krisciunas & Schaefer 1991).
MOON_MEAN_DISTANCE_KM = 384400.0
#: The Moon's mean radius [km] (IAU).
MOON_RADIUS_KM = 1737.4
#: The Sun's apparent V magnitude at 1 au (Allen 1973, *Astrophysical Quantities*, 3rd ed.),
#: the zero point of the Moon's magnitude law.
SUN_V_MAGNITUDE = -26.74


@renamed_keywords(wavelength_nm="wavelength")
def planck(wavelength: ArrayLike, temperature: ArrayLike) -> NDArray[np.float64]:
    """Blackbody spectral radiance ``B(lambda, T)`` [W m-2 sr-1 nm-1] (Planck's law).

    ``B = 2 h c^2 / lambda^5 / (exp(h c / (lambda k T)) - 1)``, evaluated as
    ``2 h c^2 / lambda^5 * e^-x / (1 - e^-x)`` with ``x = h c / (lambda k T)`` so
    that it underflows to 0 instead of overflowing at short wavelengths.  Constants
    from :mod:`scipy.constants` (CODATA, exact SI values of h, c and k).

    Parameters
    ----------
    wavelength : array_like
        Vacuum wavelength [nm], > 0.
    temperature : float or array_like
        Temperature [K], >= 0 (0 K radiates nothing).  An array of temperatures gives
        one spectrum each: the result has shape ``temperature.shape + wavelength.shape``.

    Returns
    -------
    ndarray
        Radiance per nanometre of wavelength [W m-2 sr-1 nm-1].

    Examples
    --------
    >>> from sbrdf_xr.sources import planck
    >>> float(planck(10_000.0, 300.0))  # 10 um, 300 K: ~9.9 W m-2 sr-1 um-1
    0.009924...
    >>> planck([4000.0, 10_000.0], [[0.0], [300.0]]).shape  # (2, 1) temperatures
    (2, 1, 2)
    >>> float(planck(10_000.0, [0.0, 300.0])[0, 0])
    0.0
    """
    h, c, k = constants.h, constants.c, constants.k
    wl = to_unit(wavelength, "nm", "wavelength", spectral=True)
    lam = np.asarray(wl, dtype=np.float64) * 1e-9
    t = np.asarray(to_unit(temperature, "K", "temperature"), dtype=np.float64)
    with np.errstate(divide="ignore"):
        x = h * c / (lam * k * (t if t.ndim == 0 else t[..., None]))
    with np.errstate(under="ignore", over="ignore", invalid="ignore"):
        return 2.0 * h * c**2 / lam**5 * np.exp(-x) / -np.expm1(-x) * 1e-9


@renamed_keywords(range_km="range", phase_angle_deg="phase_angle")
def earthshine_irradiance_ratio(albedo: float, range: float, phase_angle: float) -> float:
    """Irradiance from a Lambertian Earth relative to the Sun's (same heliocentric distance).

    A Lambertian sphere of radius ``R`` and Bond albedo ``a`` seen at phase angle
    ``alpha`` from distance ``r`` gives ``E/E_sun = (2/3) a (R/r)^2 [(pi - alpha)
    cos(alpha) + sin(alpha)] / pi`` (the diffuse-sphere phase law; Russell 1916,
    Lester et al. 1979).  The Earth is then treated as a distant source from its
    centre's direction: good when its angular radius ``asin(R/r)`` is small (8.7 deg
    at GEO), rough in low orbit.

    Parameters
    ----------
    albedo : float
        Bond albedo [1].
    range : float
        Distance to the Earth's centre [km].
    phase_angle : float
        Sun-Earth-spacecraft angle [degree].

    Returns
    -------
    float
        ``E_earth / E_sun`` [1].

    Examples
    --------
    >>> from sbrdf_xr.sources import earthshine_irradiance_ratio
    >>> round(earthshine_irradiance_ratio(0.3, 42164.0, 0.0), 5)  # full Earth from GEO
    0.00457
    """
    a = np.radians(to_unit(phase_angle, "deg", "phase_angle"))
    range = to_unit(range, "km", "range")
    check_plausible(range, "range_km", "range")
    return float(
        2.0
        / 3.0
        * albedo
        * (EARTH_MEAN_RADIUS_KM / range) ** 2
        * ((np.pi - a) * np.cos(a) + np.sin(a))
        / np.pi
    )


@renamed_keywords(phase_angle_deg="phase_angle")
def moon_v_magnitude(phase_angle: ArrayLike) -> NDArray[np.float64]:
    """The Moon's V magnitude at its mean distance and 1 au from the Sun, by phase angle.

    ``m(alpha) = -12.73 + 0.026 |alpha| + 4e-9 alpha^4`` (``alpha`` in degree), the fit of
    Allen (1973, *Astrophysical Quantities*, 3rd ed., p. 144) to the lunar phase curve
    that Krisciunas & Schaefer (1991, PASP 103, 1033, §3) use for moonlight.  It does not
    follow the opposition surge within a few degrees of full Moon, nor the difference
    between waxing and waning phases (a few tenths of a magnitude).

    Parameters
    ----------
    phase_angle : array_like
        Sun-Moon-observer angle [degree], 0 at full Moon.

    Returns
    -------
    ndarray
        V magnitude [mag].

    Examples
    --------
    >>> from sbrdf_xr.sources import moon_v_magnitude
    >>> moon_v_magnitude([0.0, 90.0, -90.0]).round(2).tolist()  # full and quarter Moons
    [-12.73, -10.13, -10.13]
    """
    a = np.abs(np.asarray(to_unit(phase_angle, "deg", "phase_angle"), dtype=np.float64))
    return -12.73 + 0.026 * a + 4e-9 * a**4


@renamed_keywords(distance_km="distance", phase_angle_deg="phase_angle")
def moonlight_irradiance_ratio(
    phase_angle: ArrayLike,
    distance: ArrayLike,
    sun_distance_ratio: ArrayLike = 1.0,
) -> NDArray[np.float64]:
    """Irradiance from the Moon relative to the Sun's at the observer.

    ``E_moon / E_sun = 10^(-0.4 (m(alpha) - m_sun)) (D / d)^2 (r_obs / r_moon)^2``: the
    Moon's V magnitude law (:func:`moon_v_magnitude`) against the Sun's
    (:data:`SUN_V_MAGNITUDE`), moved from the mean distance ``D``
    (:data:`MOON_MEAN_DISTANCE_KM`) to the observer's distance ``d``, and from the
    observer's distance to the Sun to the Moon's (``sun_distance_ratio = r_obs /
    r_moon``).  The ratio holds at every wavelength for a grey Moon; the real Moon is
    redder than the Sun (B - V 0.92 against 0.65, Allen 1973), which a V-band ratio
    leaves out.

    Parameters
    ----------
    phase_angle : array_like
        Sun-Moon-observer angle [degree].
    distance : array_like
        Moon-observer distance (centre to centre) [km].
    sun_distance_ratio : array_like
        Sun-observer distance over Sun-Moon distance [1].

    Returns
    -------
    ndarray
        ``E_moon / E_sun`` [1].

    Examples
    --------
    The full Moon at its mean distance gives 2.5 millionths of the Sun's light (14.01
    magnitudes fainter); a quarter Moon gives 9 % of that:

    >>> from sbrdf_xr.sources import moonlight_irradiance_ratio
    >>> full, quarter = moonlight_irradiance_ratio([0.0, 90.0], 384400.0)
    >>> f"{full:.3e}", round(float(quarter / full), 3)
    ('2.489e-06', 0.091)
    """
    d = np.asarray(to_unit(distance, "km", "distance"), dtype=np.float64)
    m = moon_v_magnitude(phase_angle)
    ratio = 10.0 ** (-0.4 * (m - SUN_V_MAGNITUDE))
    return ratio * (MOON_MEAN_DISTANCE_KM / d) ** 2 * np.asarray(sun_distance_ratio) ** 2


def kirchhoff_emissivity(reflectance: ArrayLike) -> NDArray[np.float64]:
    """Directional emissivity ``epsilon(theta, lambda) = 1 - rho(theta, lambda)``.

    Kirchhoff's law for an opaque surface in thermal equilibrium: the directional
    emissivity equals the directional absorptance, one minus the
    directional-hemispherical reflectance (paper 001 Eq. 1 and §2; by reciprocity
    the reflectance for illumination from ``theta`` is that for emission into it).
    Clipped to [0, 1] so that a table that does not conserve energy cannot emit
    negatively.

    Parameters
    ----------
    reflectance : array_like
        Directional-hemispherical reflectance [1].

    Returns
    -------
    ndarray
        Emissivity [1].

    Examples
    --------
    >>> from sbrdf_xr.sources import kirchhoff_emissivity
    >>> kirchhoff_emissivity([0.2, 0.9, 1.05]).round(6).tolist()  # 1.05: clipped to 0
    [0.8, 0.1, 0.0]
    """
    return np.clip(1.0 - np.asarray(reflectance, dtype=np.float64), 0.0, 1.0)


def emissivity_at(
    emissivity: NDArray[np.floating], theta_grid: NDArray[np.floating], theta: ArrayLike
) -> NDArray[np.float64]:
    """Emissivity at emission angles ``theta``, linear in angle between the table's nodes.

    Parameters
    ----------
    emissivity : ndarray, shape (n_theta, n_wavelength)
        Emissivity on ``theta_grid`` [1].
    theta_grid : ndarray, shape (n_theta,)
        Strictly increasing emission angles [degree].
    theta : array_like, shape (...)
        Emission angles [degree]; clamped to the grid.

    Returns
    -------
    ndarray, shape (..., n_wavelength)

    Examples
    --------
    Two wavelengths tabulated at 0 and 90 degree; 45 degree lies halfway, 120 degree is
    clamped to the last node:

    >>> import numpy as np
    >>> from sbrdf_xr.sources import emissivity_at
    >>> eps = np.array([[0.8, 0.5], [0.6, 0.3]])  # (n_theta, n_wavelength)
    >>> emissivity_at(eps, np.array([0.0, 90.0]), [45.0, 120.0]).round(6).tolist()
    [[0.7, 0.4], [0.6, 0.3]]
    """
    grid = np.asarray(to_unit(theta_grid, "deg", "theta_grid"), dtype=np.float64)
    t = np.clip(np.asarray(to_unit(theta, "deg", "theta"), dtype=np.float64), grid[0], grid[-1])
    if grid.size == 1:
        return np.broadcast_to(emissivity[0], (*t.shape, emissivity.shape[-1])).copy()
    i = np.clip(np.searchsorted(grid, t, side="right") - 1, 0, grid.size - 2)
    w = ((t - grid[i]) / (grid[i + 1] - grid[i]))[..., None]
    return (1.0 - w) * emissivity[i] + w * emissivity[i + 1]


#: Gauss-Legendre nodes of the finite-Earth quadrature (radial, azimuthal): the integrand
#: has kinks at the terminator and the plate's horizon, so it converges as N^-2 (measured
#: 1e-5 relative at the default against an adaptive quadrature over the Earth's surface).
EARTH_NODES = (256, 512)
#: Upper bound of a plausible brightness temperature of the Earth [K].
EARTH_TEMPERATURE_MAX = 400.0


@functools.lru_cache(maxsize=8)
def _leggauss(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on [-1, 1], made once per order."""
    return np.polynomial.legendre.leggauss(n)


def _earth_cap(
    plate_normal: ArrayLike, to_earth: ArrayLike, range: float, nodes: tuple[int, int]
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Directions ``d`` toward the visible Earth, the surface normals ``u`` they hit, the
    plate's ``max(n.d, 0)`` and the solid-angle weights [sr] (``sum w f = int f dOmega``)."""
    r = float(to_unit(range, "km", "range"))
    if not np.isfinite(r) or r <= EARTH_MEAN_RADIUS_KM:
        raise ValidationError(
            f"range: got {r:g}; allowed: a distance from the Earth's centre above its "
            f"radius, {EARTH_MEAN_RADIUS_KM:g} km"
        )
    n = np.asarray(plate_normal, dtype=np.float64)
    z = np.asarray(to_earth, dtype=np.float64)
    n, z = n / np.linalg.norm(n), z / np.linalg.norm(z)
    x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    sin_rho = EARTH_MEAN_RADIUS_KM / r
    # sin(psi) = sin(rho) sin(chi): smooth up to the limb (chi = pi/2)
    tc, wc = _leggauss(nodes[0])
    chi, w_chi = 0.25 * np.pi * (tc + 1.0), 0.25 * np.pi * wc
    tw, ww = _leggauss(nodes[1])
    om, w_om = np.pi * (tw + 1.0), np.pi * ww
    sin_psi = sin_rho * np.sin(chi)
    cos_psi = np.sqrt(1.0 - sin_psi**2)
    dpsi = sin_rho * np.cos(chi) / cos_psi  # d psi / d chi
    d = cos_psi[:, None, None] * z + sin_psi[:, None, None] * (
        np.cos(om)[None, :, None] * x + np.sin(om)[None, :, None] * y
    )
    # the nearer intersection with the sphere, t = r cos(psi) - sqrt(R^2 - r^2 sin^2 psi)
    t = r * cos_psi - r * sin_rho * np.cos(chi)
    u = (-r * z + t[:, None, None] * d) / EARTH_MEAN_RADIUS_KM
    w = (w_chi * sin_psi * dpsi)[:, None] * w_om[None, :]
    return d, u, np.maximum(d @ n, 0.0), w


@renamed_keywords(range_km="range")
def earthshine_finite(
    plate_normal: ArrayLike,
    to_earth: ArrayLike,
    to_sun: ArrayLike,
    range: float,
    albedo: float = 0.3,
    *,
    nodes: tuple[int, int] = EARTH_NODES,
) -> float:
    """Sunlight reflected by a finite Lambertian Earth onto a plate, relative to the Sun's.

    ``E/E_sun = (a/pi) int max(u.s, 0) max(n.d, 0) dOmega`` over the directions ``d`` from
    the plate to the visible Earth (``u`` the Earth's surface normal where ``d`` hits, ``s``
    the direction to the Sun, ``n`` the plate's normal): the Earth's day side at its true
    size, cut by the plate's own horizon (paper 001's earthshine, §1, for a Lambertian
    ground).  The Sun is at infinity.

    Parameters
    ----------
    plate_normal, to_earth, to_sun : array_like, shape (3,)
        The plate's normal, the direction to the Earth's centre and to the Sun [1], in
        one frame.
    range : float
        Distance from the Earth's centre [km], above the Earth's radius.
    albedo : float
        The Earth's Lambertian albedo [1].
    nodes : tuple of int
        Gauss-Legendre nodes (radial, azimuthal) over the Earth's disc.

    Returns
    -------
    float
        ``E_earth / E_sun`` [1].

    Examples
    --------
    >>> from sbrdf_xr.sources import earthshine_finite, earthshine_irradiance_ratio
    >>> z = [0.0, 0.0, -1.0]  # the Earth below; the Sun behind the spacecraft (+z)
    >>> round(earthshine_finite(z, z, [0.0, 0.0, 1.0], 42164.0), 5)  # full phase
    0.00506
    >>> round(earthshine_irradiance_ratio(0.3, 42164.0, 0.0), 5)  # a point source
    0.00457
    """
    s = np.asarray(to_sun, dtype=np.float64)
    s = s / np.linalg.norm(s)
    _, u, cos_plate, w = _earth_cap(plate_normal, to_earth, range, nodes)
    return float(albedo / np.pi * np.sum(w * np.maximum(u @ s, 0.0) * cos_plate))


@renamed_keywords(range_km="range")
def earth_thermal_irradiance(
    wavelength: ArrayLike,
    plate_normal: ArrayLike,
    to_earth: ArrayLike,
    range: float,
    temperature: float = 255.0,
    *,
    nodes: tuple[int, int] = EARTH_NODES,
) -> NDArray[np.float64]:
    """The Earth's thermal emission on a plate: a Lambertian disc at one brightness temperature.

    ``E(lambda) = B(lambda, T) int max(n.d, 0) dOmega`` over the visible Earth (the view
    factor of a finite sphere, cut by the plate's horizon); 255 K is the Earth's effective
    (radiative-equilibrium) temperature.

    Parameters
    ----------
    wavelength : array_like
        Vacuum wavelength [nm].
    plate_normal, to_earth : array_like, shape (3,)
        The plate's normal and the direction to the Earth's centre [1].
    range : float
        Distance from the Earth's centre [km].
    temperature : float
        The Earth's brightness temperature [K], 0 < T <= :data:`EARTH_TEMPERATURE_MAX`.
    nodes : tuple of int
        Gauss-Legendre nodes (radial, azimuthal).

    Returns
    -------
    ndarray
        Spectral irradiance [W m-2 nm-1].

    Examples
    --------
    >>> from sbrdf_xr.sources import earth_thermal_irradiance
    >>> z = [0.0, 0.0, -1.0]
    >>> e = earth_thermal_irradiance([10_000.0], z, z, 42164.0)  # pi sin^2(rho) B
    >>> round(float(e[0] / (np.pi * (6371 / 42164) ** 2 * planck(10_000.0, 255.0))), 9)
    1.0
    """
    t = float(to_unit(temperature, "K", "temperature"))
    if not (0.0 < t <= EARTH_TEMPERATURE_MAX):
        raise ValidationError(
            f"temperature: got {t:g} K; allowed: 0 < T <= {EARTH_TEMPERATURE_MAX:g} K "
            "(the Earth's brightness temperature)"
        )
    wl = to_unit(wavelength, "nm", "wavelength", spectral=True)
    _, _, cos_plate, w = _earth_cap(plate_normal, to_earth, range, nodes)
    return np.sum(w * cos_plate) * planck(wl, t)


def equilibrium_temperature(
    absorbed: ArrayLike, emissivity: ArrayLike, *, radiating_sides: float = 1.0
) -> NDArray[np.float64]:
    """Radiative-equilibrium temperature of a facet with no conduction.

    The conductance model is stated: none.  Each facet is a thin plate insulated from the
    rest of the body that emits from ``radiating_sides`` faces (1: an insulated panel
    such as a blanket; 2: a thin conductive plate, both faces at one temperature), so
    ``absorbed = radiating_sides * epsilon * sigma * T^4`` (paper 001 Eqs. 2-4: absorbed
    sunlight, earthshine and Earth emission equal the emission).

    Parameters
    ----------
    absorbed : array_like
        Absorbed power per unit area [W m-2] (e.g. ``alpha_solar E_sun cos(theta_i)`` plus
        the absorbed Earth light), >= 0.
    emissivity : array_like
        Hemispherical infrared emissivity [1], ``0 < epsilon <= 1``.
    radiating_sides : float
        Number of faces that radiate, 1 or 2 [1].

    Returns
    -------
    ndarray
        Temperature [K]; 0 where nothing is absorbed (no internal heat).

    Examples
    --------
    >>> from sbrdf_xr.sources import equilibrium_temperature
    >>> round(float(equilibrium_temperature(1361.0, 1.0)), 1)  # a black plate facing the Sun
    393.6
    >>> round(float(equilibrium_temperature(0.26 * 1361.0, 0.88)), 1)  # white paint (Table 3)
    290.2
    """
    q = np.asarray(to_unit(absorbed, "W m-2", "absorbed"), dtype=np.float64)
    eps = np.asarray(emissivity, dtype=np.float64)
    if np.any(~np.isfinite(q)) or np.any(q < 0):
        raise ValidationError(f"absorbed: got {np.ravel(q)[:5].tolist()}; allowed: >= 0 W m-2")
    if np.any(~(eps > 0)) or np.any(eps > 1):
        raise ValidationError(f"emissivity: got {np.ravel(eps)[:5].tolist()}; allowed: 0 < e <= 1")
    if radiating_sides not in (1, 2, 1.0, 2.0):
        raise ValidationError(f"radiating_sides: got {radiating_sides!r}; allowed: 1 or 2")
    return (q / (radiating_sides * eps * constants.sigma)) ** 0.25


@renamed_keywords(time_s="time")
def radiative_cooling(
    time: ArrayLike,
    initial_temperature: float,
    heat_capacity: float,
    emissivity: float,
    *,
    radiating_sides: float = 1.0,
) -> NDArray[np.float64]:
    """Temperature of a facet cooling by radiation alone (in the Earth's shadow).

    ``C dT/dt = -sides epsilon sigma T^4`` (no absorbed power, no conduction: the model of
    :func:`equilibrium_temperature` with the Sun gone) has the closed form
    ``T(t) = (T0^-3 + 3 sides epsilon sigma t / C)^(-1/3)``.

    Parameters
    ----------
    time : array_like
        Time since entering the shadow [s], >= 0.
    initial_temperature : float
        Temperature at ``t = 0`` [K], > 0.
    heat_capacity : float
        Heat capacity per unit area [J m-2 K-1] (e.g. 1 mm of aluminium: 2430), > 0.
    emissivity : float
        Hemispherical infrared emissivity [1], ``0 < epsilon <= 1``.
    radiating_sides : float
        Number of faces that radiate, 1 or 2 [1].

    Returns
    -------
    ndarray
        Temperature [K].

    Examples
    --------
    >>> from sbrdf_xr.sources import radiative_cooling
    >>> np.round(radiative_cooling([0.0, 600.0, 3600.0], 300.0, 2430.0, 0.85), 1).tolist()
    [300.0, 239.6, 158.5]
    """
    t = np.asarray(to_unit(time, "s", "time"), dtype=np.float64)
    t0 = float(to_unit(initial_temperature, "K", "initial_temperature"))
    c = float(to_unit(heat_capacity, "J m-2 K-1", "heat_capacity"))
    if np.any(~np.isfinite(t)) or np.any(t < 0):
        raise ValidationError(f"time: got {np.ravel(t)[:5].tolist()}; allowed: >= 0 s")
    if not (0.0 < t0 <= 10_000.0):
        raise ValidationError(f"initial_temperature: got {t0:g} K; allowed: 0 < T <= 10000 K")
    if not (c > 0 and np.isfinite(c)):
        raise ValidationError(f"heat_capacity: got {c:g} J m-2 K-1; allowed: > 0")
    if not (0.0 < emissivity <= 1.0):
        raise ValidationError(f"emissivity: got {emissivity!r}; allowed: 0 < e <= 1")
    if radiating_sides not in (1, 2, 1.0, 2.0):
        raise ValidationError(f"radiating_sides: got {radiating_sides!r}; allowed: 1 or 2")
    rate = 3.0 * radiating_sides * emissivity * constants.sigma / c
    return (t0**-3 + rate * t) ** (-1.0 / 3.0)


def _canonical_cap(
    range: float, cos_sun: float, nodes: tuple[int, int]
) -> tuple[np.ndarray, np.ndarray]:
    """Directions (K, 3) toward the visible Earth and their weights ``w max(u.s, 0)`` [sr] in
    the frame with the Earth's centre on +z and the Sun in the x-z half-plane ``x >= 0``."""
    s = np.array([np.sqrt(max(0.0, 1.0 - cos_sun**2)), 0.0, cos_sun])
    d, u, _, w = _earth_cap([0.0, 0.0, 1.0], [0.0, 0.0, 1.0], range, nodes)
    lw = (w * np.maximum(u @ s, 0.0)).ravel()
    keep = lw > 0.0  # the night side adds nothing
    return d.reshape(-1, 3)[keep], lw[keep]


@renamed_keywords(range_km="range")
def earthshine_facets(
    normals: ArrayLike,
    to_earth: ArrayLike,
    to_sun: ArrayLike,
    range: ArrayLike,
    albedo: float = 0.3,
    *,
    nodes: tuple[int, int] = (64, 128),
) -> NDArray[np.float64]:
    """:func:`earthshine_finite` for many plates and geometries at once, ``E/E_sun`` (G, T).

    The same integral, evaluated in the frame of the Earth's centre and the Sun: a plate
    that sees the whole visible cap (its normal within ``90 deg - rho`` of the Earth's
    centre, ``sin(rho) = R / r``) receives ``n . V`` with ``V = (a/pi) int max(u.s, 0) d
    dOmega`` one vector per geometry; a plate that sees none of it (normal beyond ``90 deg
    + rho``) receives 0; only the plates whose horizon cuts the Earth are integrated node
    by node.  Geometries sharing a range and a solar angle share their nodes.

    Parameters
    ----------
    normals : array_like, shape (T, 3)
        Unit plate normals [1].
    to_earth, to_sun : array_like, shape (G, 3)
        Unit directions to the Earth's centre and to the Sun [1], in the normals' frame.
    range : array_like, shape (G,) or scalar
        Distance from the Earth's centre [km], above the Earth's radius.
    albedo : float
        The Earth's Lambertian albedo [1].
    nodes : tuple of int
        Gauss-Legendre nodes (radial, azimuthal) over the Earth's disc; the default is
        measured at 2e-5 of the largest irradiance against :func:`earthshine_finite` on
        (512, 1024) nodes, at GEO, 7000 and 6471 km.

    Returns
    -------
    ndarray, shape (G, T)
        ``E_earth / E_sun`` [1] of every plate in every geometry.

    Examples
    --------
    >>> from sbrdf_xr.sources import earthshine_facets, earthshine_finite
    >>> n = [[0.0, 0.0, -1.0], [0.995037, 0.0, -0.0995037]]  # Earth-facing; nearly edge-on
    >>> e, s = [[0.0, 0.0, -1.0]], [[0.6, 0.0, 0.8]]
    >>> earthshine_facets(n, e, s, 7000.0).round(5).tolist()
    [[0.1972, 0.07328]]
    >>> round(earthshine_finite(n[1], e[0], s[0], 7000.0), 5)  # the single-plate integral
    0.07328
    """
    nrm = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    e = np.asarray(to_earth, dtype=np.float64).reshape(-1, 3)
    s = np.asarray(to_sun, dtype=np.float64).reshape(-1, 3)
    rng = np.broadcast_to(np.asarray(to_unit(range, "km", "range"), float), e.shape[:1])
    e = e / np.linalg.norm(e, axis=1, keepdims=True)
    s = s / np.linalg.norm(s, axis=1, keepdims=True)
    cz = np.clip(np.einsum("gi,gi->g", s, e), -1.0, 1.0)
    x = s - cz[:, None] * e
    nx = np.linalg.norm(x, axis=1)
    other = np.where(np.abs(e[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    alt = np.cross(e, other)
    x = np.where((nx > 1e-12)[:, None], x, alt)
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    y = np.cross(e, x)
    # the normals in every geometry's frame (x toward the Sun, z toward the Earth)
    nc = np.stack([x @ nrm.T, y @ nrm.T, e @ nrm.T], axis=-1)  # (G, T, 3)
    out = np.zeros(nc.shape[:2])
    cache: dict[tuple[float, float], tuple[np.ndarray, np.ndarray]] = {}
    for g in np.arange(e.shape[0]):
        key = (float(rng[g]), round(float(cz[g]), 12))
        if key not in cache:
            cache[key] = _canonical_cap(key[0], key[1], nodes)
        d, lw = cache[key]
        if lw.size == 0:
            continue
        sin_rho = EARTH_MEAN_RADIUS_KM / key[0]
        nz = nc[g, :, 2]
        whole, cut = nz >= sin_rho, np.abs(nz) < sin_rho
        out[g, whole] = nc[g, whole] @ (lw @ d)
        idx = np.flatnonzero(cut)
        for k in np.arange(0, idx.size, 64):  # (64, K) at a time
            j = idx[k : k + 64]
            out[g, j] = np.maximum(nc[g, j] @ d.T, 0.0) @ lw
    return albedo / np.pi * out


def earth_view_facets(
    normals: ArrayLike,
    to_earth: ArrayLike,
    range: ArrayLike,
    *,
    nodes: tuple[int, int] = (64, 128),
) -> NDArray[np.float64]:
    """The solid angle of the visible Earth weighted by each plate's cosine (G, T) [sr].

    ``V = int max(n.d, 0) dOmega`` over the directions ``d`` from the plate to the visible
    Earth: a Lambertian Earth of radiance ``L`` gives the plate the irradiance ``L V`` (so
    ``V / pi`` is the view factor of the finite sphere, cut by the plate's horizon; the
    Earth's thermal emission of :func:`earth_thermal_irradiance` for many plates).  A plate
    that sees the whole cap (normal within ``90 deg - rho`` of the Earth's centre,
    ``sin(rho) = R / r``) has ``V = pi sin^2(rho) n.e`` exactly; one that sees none of it
    (beyond ``90 deg + rho``) 0; those whose horizon cuts the Earth are integrated on the
    Gauss-Legendre nodes of :func:`earthshine_finite`.

    Parameters
    ----------
    normals : array_like, shape (T, 3)
        Unit plate normals [1].
    to_earth : array_like, shape (G, 3)
        Unit directions to the Earth's centre [1], in the normals' frame.
    range : array_like, shape (G,) or scalar
        Distance from the Earth's centre [km], above the Earth's radius.
    nodes : tuple of int
        Gauss-Legendre nodes (radial, azimuthal) over the Earth's disc.

    Returns
    -------
    ndarray, shape (G, T)
        ``V`` [sr] of every plate in every geometry.

    Examples
    --------
    >>> from sbrdf_xr.sources import earth_view_facets
    >>> n = [[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]  # facing, edge-on, away
    >>> v = earth_view_facets(n, [[0.0, 0.0, -1.0]], 42164.0)
    >>> round(float(v[0, 0] / (np.pi * (6371 / 42164) ** 2)), 12)  # pi sin^2(rho)
    1.0
    >>> float(v[0, 2])  # facing away
    0.0
    >>> h = 42164.0 / 6371.0  # edge-on: V = atan(1/sqrt(H^2-1)) - sqrt(H^2-1)/H^2 (Howell)
    >>> round(float(v[0, 1] / (np.arctan(1 / np.sqrt(h**2 - 1)) - np.sqrt(h**2 - 1) / h**2)), 3)
    1.0
    """
    nrm = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    e = np.asarray(to_earth, dtype=np.float64).reshape(-1, 3)
    rng = np.broadcast_to(np.asarray(to_unit(range, "km", "range"), float), e.shape[:1])
    e = e / np.linalg.norm(e, axis=1, keepdims=True)
    nz = e @ nrm.T  # (G, T) the cosine of the Earth's centre from each normal
    out = np.zeros(nz.shape)
    for r in np.unique(rng):
        rows = np.flatnonzero(rng == r)
        sin_rho = EARTH_MEAN_RADIUS_KM / float(r)
        whole = nz[rows] >= sin_rho
        out[rows] = np.where(whole, np.pi * sin_rho**2 * nz[rows], 0.0)
        g_cut, t_cut = np.nonzero(np.abs(nz[rows]) < sin_rho)
        if g_cut.size == 0:
            continue
        d, _, _, w = _earth_cap([0.0, 0.0, 1.0], [0.0, 0.0, 1.0], float(r), nodes)
        d, w = d.reshape(-1, 3), w.ravel()
        for k in np.arange(0, g_cut.size, 64):  # (64, K) at a time
            g, t = rows[g_cut[k : k + 64]], t_cut[k : k + 64]
            # each normal in the cap's frame: only its angle from the centre matters
            c = nz[g, t]
            local = np.stack([np.sqrt(np.clip(1.0 - c**2, 0.0, None)), 0 * c, c], axis=1)
            out[g, t] = np.maximum(local @ d.T, 0.0) @ w
    return out


#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(__name__, globals(), {"EARTH_RADIUS_KM": "EARTH_MEAN_RADIUS_KM"})
