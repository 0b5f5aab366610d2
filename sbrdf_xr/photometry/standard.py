"""Standard magnitudes (to a range and a phase angle), the Sun's distance, spectral resolution.

A *standard magnitude* removes the observing geometry from an apparent magnitude so that
objects and passes can be compared:

    m_std = m - 5 log10(d / d_0) + 2.5 log10( Phi(alpha) / Phi(alpha_0) ) - 5 log10(r / r_0)

with the range ``d`` normalised to ``d_0`` (1000 km by default), optionally the phase
angle ``alpha`` to ``alpha_0`` through a stated phase function ``Phi``
(:data:`PHASE_FUNCTIONS`), and optionally the Sun-object distance ``r`` to 1 AU.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from .._names import WAVELENGTH, attrs
from ..errors import ValidationError, renamed_keywords
from ..units import check_plausible, to_unit
from .spectra import _check_grid, _choose, trapezoid_weights


@renamed_keywords(alpha_deg="alpha")
def lambert_sphere_phase(alpha: ArrayLike) -> np.ndarray:
    """Phase function of a diffusely (Lambert) reflecting sphere, 1 at zero phase.

    ``Phi(alpha) = ((pi - alpha) cos alpha + sin alpha) / pi`` (Russell 1916, ApJ 43,
    173; Lambert's law integrated over the lit and visible part of the disc).

    Parameters
    ----------
    alpha : array_like
        Phase angle [degree] in [0, 180].

    Returns
    -------
    ndarray
        [1]

    Examples
    --------
    >>> np.round(lambert_sphere_phase([0.0, 90.0, 180.0]), 6)  # 1, 1/pi, 0
    array([1.     , 0.31831, 0.     ])
    """
    a = np.radians(np.asarray(to_unit(alpha, "deg", "alpha"), dtype=np.float64))
    return ((np.pi - a) * np.cos(a) + np.sin(a)) / np.pi


@renamed_keywords(alpha_deg="alpha")
def specular_sphere_phase(alpha: ArrayLike) -> np.ndarray:
    """Phase function of a specular (mirror) sphere: 1 at every phase angle.

    A mirror sphere's glint has the same intensity in every direction (the
    reflected-ray density of a sphere is isotropic; e.g. van de Hulst 1957, *Light
    Scattering by Small Particles*, sect. 12.21).

    Parameters
    ----------
    alpha : array_like
        Phase angle [degree].

    Returns
    -------
    ndarray
        Phase function [1], normalised to 1 at zero phase.

    Examples
    --------
    >>> specular_sphere_phase([0.0, 90.0])
    array([1., 1.])
    """
    return np.ones_like(np.asarray(to_unit(alpha, "deg", "alpha"), dtype=np.float64))


#: Phase functions for standard magnitudes:
#: name -> (function of the phase angle [degree], description).
PHASE_FUNCTIONS: dict[str, Any] = {
    "lambert_sphere": (lambert_sphere_phase, "diffuse (Lambert) sphere, Russell 1916, ApJ 43, 173"),
    "specular_sphere": (specular_sphere_phase, "specular sphere (phase-independent)"),
}


def _positive(value: Any, what: str) -> np.ndarray:
    v = np.asarray(value.values if isinstance(value, xr.DataArray) else value, dtype=np.float64)
    if v.size == 0 or not np.all(np.isfinite(v)) or np.any(v <= 0):
        raise ValidationError(f"{what}: must be finite and > 0, got {v.ravel()[:5].tolist()}")
    return v


@renamed_keywords(sun_distance_au="sun_distance", range_km="range", to_range_km="to_range")
def standard_magnitude(
    mags: xr.DataArray,
    range: Any,
    *,
    to_range: float = 1000.0,
    phase_angle: Any = None,
    to_phase_angle: float | None = None,
    phase_function: str = "lambert_sphere",
    sun_distance: Any = None,
) -> xr.DataArray:
    """Magnitudes normalised to a standard range, optionally phase angle and 1 AU.

    Parameters
    ----------
    mags : xarray.DataArray
        Apparent magnitudes (any dims).
    range : float, array_like or DataArray
        Observer range of each magnitude [km], > 0; broadcast against ``mags``.
    to_range : float
        Standard range [km] (default 1000 km).
    phase_angle : float, array_like or DataArray, optional
        Phase angle of each magnitude [degree]; default the ``phase_angle``
        coordinate of ``mags`` when ``to_phase_angle`` is given.
    to_phase_angle : float, optional
        Standard phase angle [degree] (e.g. 0 or 90); default none (phase kept).
    phase_function : str
        A key of :data:`PHASE_FUNCTIONS` (the stated model of the brightness with phase).
    sun_distance : float, array_like or DataArray, optional
        Sun-object distance [AU]; when given the magnitudes are also normalised to 1 AU.

    Returns
    -------
    xarray.DataArray
        ``standard_magnitude`` [1], attrs state the normalisation.

    Examples
    --------
    >>> import xarray as xr
    >>> wl = np.arange(300.0, 1101.0, 10.0)
    >>> grey = np.full((2, wl.size), 0.1)  # 0.1 m2 sr-1 at every wavelength, two geometries
    >>> cube = xr.Dataset({"signal": (("geometry", "wavelength"), grey, {"units": "m2 sr-1"})},
    ...                   coords={"wavelength": ("wavelength", wl, {"units": "nm"})})
    >>> from sbrdf_xr.photometry import magnitudes
    >>> m = magnitudes(cube, ["V"], range=2000.0)
    >>> std = standard_magnitude(m, 2000.0)  # to 1000 km: 5 log10(2) brighter
    >>> round(float((m - std)[0, 0]), 6)
    1.50515
    """
    if not isinstance(mags, xr.DataArray):
        raise ValidationError(f"mags: expected a DataArray, got {type(mags).__name__}")
    range = to_unit(range, "km", "range")
    to_range = to_unit(to_range, "km", "to_range")
    phase_angle = to_unit(phase_angle, "deg", "phase_angle")
    to_phase_angle = to_unit(to_phase_angle, "deg", "to_phase_angle")
    sun_distance = to_unit(sun_distance, "au", "sun_distance")
    check_plausible(range, "range_km", "range")
    _positive(range, "range")
    _positive(to_range, "to_range")
    d = (
        range.astype(np.float64)
        if isinstance(range, xr.DataArray)
        else np.asarray(range, dtype=np.float64)
    )
    out = mags - 5.0 * np.log10(d / float(to_range))
    how = [f"range {to_range:g} km"]
    if to_phase_angle is not None:
        _choose(phase_function, PHASE_FUNCTIONS, "phase_function")
        fn, desc = PHASE_FUNCTIONS[phase_function]
        if phase_angle is None:
            if "phase_angle" not in mags.coords:
                raise ValidationError(
                    "phase_angle: give the phase angle of each magnitude [degree] "
                    "(mags has no 'phase_angle' coordinate)"
                )
            phase_angle = mags["phase_angle"]
        a = (
            phase_angle.astype(np.float64)
            if isinstance(phase_angle, xr.DataArray)
            else np.asarray(phase_angle, dtype=np.float64)
        )
        av = np.asarray(a.values if isinstance(a, xr.DataArray) else a)
        for what, v in (
            ("phase_angle", av),
            ("to_phase_angle", np.asarray(to_phase_angle, dtype=np.float64)),
        ):
            if not np.all(np.isfinite(v)) or np.any(v < 0) or np.any(v > 180):
                raise ValidationError(
                    f"{what}: must be in [0, 180] degree, got {v.ravel()[:5].tolist()}"
                )
        p0 = float(fn(to_phase_angle))
        pa = fn(av) if not isinstance(a, xr.DataArray) else a.copy(data=fn(av))
        if p0 <= 1e-12 or np.any(np.asarray(fn(av)) <= 1e-12):  # sin(pi) is 1e-16, not 0
            raise ValidationError(
                f"phase_function {phase_function!r} is zero at the given phase angles "
                "(a Lambert sphere is dark at 180 degree); choose other angles"
            )
        out = out + 2.5 * np.log10(pa / p0)
        how.append(f"phase angle {to_phase_angle:g} deg with the {desc} phase function")
    if sun_distance is not None:
        _positive(sun_distance, "sun_distance")
        r = sun_distance if isinstance(sun_distance, xr.DataArray) else np.asarray(sun_distance)
        out = out - 5.0 * np.log10(r)
        how.append("Sun-object distance 1 AU")
    out = out.transpose(*mags.dims, ...)
    out.name = "standard_magnitude"
    out.attrs = {
        **{k: v for k, v in mags.attrs.items() if k not in ("long_name", "range_km")},
        **attrs("magnitude", long_name="standard magnitude of the reflected sunlight"),
        "standardisation": "normalised to " + ", ".join(how),
        "standard_range_km": float(to_range),
    }
    if to_phase_angle is not None:
        out.attrs["standard_phase_angle"] = float(to_phase_angle)
        out.attrs["phase_function"] = phase_function
    return out


def sun_distance_au(time: Any) -> Any:
    """Sun-Earth distance at given UTC times [AU] (for objects near the Earth).

    The low-precision formula of the Astronomical Almanac (section C, "Sun, low
    precision"): ``R = 1.00014 - 0.01671 cos g - 0.00014 cos 2g`` with the mean anomaly
    ``g = 357.529 + 0.98560028 n`` [degree], ``n`` days from J2000.0; accurate to
    about 1e-5 AU for 1950-2050.  An Earth satellite is within 0.0003 AU of the Earth
    (geostationary), which changes its magnitude by under 0.001.

    Parameters
    ----------
    time : datetime64 array_like, str or DataArray
        UTC times.

    Returns
    -------
    float, ndarray or DataArray
        [AU]

    Examples
    --------
    >>> np.round(sun_distance_au(np.array(["2024-01-03", "2024-07-05"], dtype="datetime64[ns]")), 4)
    array([0.9833, 1.0167])
    """
    t = time.values if isinstance(time, xr.DataArray) else np.asarray(time)
    try:
        t64 = np.asarray(t, dtype="datetime64[ns]")
    except (TypeError, ValueError) as exc:
        raise ValidationError(
            f"time: expected UTC datetime64 values or ISO 8601 strings, got {t!r}"
        ) from exc
    if np.any(np.isnat(t64)):
        raise ValidationError("time: NaT (missing) times")
    n = (t64 - np.datetime64("2000-01-01T12:00:00", "ns")) / np.timedelta64(1, "D")
    g = np.radians(357.529 + 0.98560028 * n)
    r = 1.00014 - 0.01671 * np.cos(g) - 0.00014 * np.cos(2.0 * g)
    if isinstance(time, xr.DataArray):
        return (
            time.copy(data=r)
            .rename("sun_distance")
            .assign_attrs(
                units="au",
                long_name="Sun-object distance (Sun-Earth, Astronomical Almanac low precision)",
            )
        )
    return float(r) if np.ndim(r) == 0 else r


@renamed_keywords(fwhm_nm="fwhm")
def at_resolution(
    spectrum: xr.DataArray,
    *,
    resolving_power: float | None = None,
    fwhm: float | None = None,
    wavelength: ArrayLike | None = None,
) -> xr.DataArray:
    """A spectrum as a spectrograph of a given resolution records it, flux-conserving.

    Each element of the (piecewise-linear) spectrum carries its flux
    ``y_k w_k`` (``w_k`` the trapezoid weight of node ``k``) and spreads it with a
    Gaussian line-spread function of FWHM ``lambda_k / R`` (``resolving_power``) or
    ``fwhm``; the output at node ``t_j`` is the flux falling in its cell (edges
    halfway between nodes) divided by the cell width.  Hence the trapezoid integral of
    the output equals that of the input, exactly up to the flux spread past the ends
    of the output grid.

    Parameters
    ----------
    spectrum : xarray.DataArray
        Anything over ``wavelength`` [nm] (other dims are kept).
    resolving_power : float, optional
        ``R = lambda / FWHM`` [1], > 0.
    fwhm : float, optional
        Constant FWHM [nm], > 0.  Exactly one of the two.
    wavelength : array_like, optional
        Output grid [nm]; default the input grid.

    Returns
    -------
    xarray.DataArray
        Same name, units and dims; attrs ``spectral_resolution``.

    Examples
    --------
    >>> import xarray as xr
    >>> wl = np.arange(500.0, 600.01, 0.5)
    >>> line = xr.DataArray(np.exp(-0.5 * ((wl - 550.0) / 1.0) ** 2), dims="wavelength",
    ...                     coords={"wavelength": wl}, attrs={"units": "W m-2 nm-1"})
    >>> seen = at_resolution(line, fwhm=10.0)  # sigma 1 nm -> sqrt(1 + (10 / 2.3548)**2) nm
    >>> round(float(seen.max()), 4)
    0.2291
    >>> round(float(seen.integrate("wavelength")), 6), round(float(line.integrate("wavelength")), 6)
    (2.506628, 2.506628)
    """
    from scipy.special import ndtr

    if not isinstance(spectrum, xr.DataArray) or WAVELENGTH not in spectrum.dims:
        raise ValidationError(
            "spectrum: expected a DataArray with a 'wavelength' dimension and coordinate"
        )
    fwhm = to_unit(fwhm, "nm", "fwhm")
    if (resolving_power is None) == (fwhm is None):
        raise ValidationError("give exactly one of resolving_power (lambda / FWHM) and fwhm")
    x = _check_grid(spectrum[WAVELENGTH].values, "spectrum wavelength")
    t = x if wavelength is None else _check_grid(wavelength, "wavelength")
    if x.size < 2 or t.size < 2:
        raise ValidationError("spectrum and output grid need >= 2 wavelengths")
    if resolving_power is not None:
        _positive(resolving_power, "resolving_power")
        fwhm_grid = x / float(resolving_power)
        how = f"Gaussian line-spread function, resolving power R = {resolving_power:g}"
    else:
        fwhm_grid = np.full(x.size, float(_positive(fwhm, "fwhm")))
        how = f"Gaussian line-spread function, FWHM {fwhm:g} nm"
    sigma = fwhm_grid / (2.0 * np.sqrt(2.0 * np.log(2.0)))
    edges = np.concatenate([[t[0]], 0.5 * (t[1:] + t[:-1]), [t[-1]]])
    cdf = ndtr((edges[:, None] - x[None, :]) / sigma[None, :])  # (n_t + 1, n_x)
    m = np.diff(cdf, axis=0) * trapezoid_weights(x)[None, :] / trapezoid_weights(t)[:, None]
    mat = xr.DataArray(m, dims=("_out", WAVELENGTH), coords={WAVELENGTH: spectrum[WAVELENGTH]})
    out = xr.dot(spectrum, mat, dim=WAVELENGTH).rename({"_out": WAVELENGTH})
    out = out.assign_coords(
        {WAVELENGTH: (WAVELENGTH, t, spectrum[WAVELENGTH].attrs or attrs(WAVELENGTH))}
    )
    out = out.transpose(*spectrum.dims)
    out.name = spectrum.name
    out.attrs = {**spectrum.attrs, "spectral_resolution": how + " (flux-conserving)"}
    return out
