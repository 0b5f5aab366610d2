"""Photometry: solar spectrum, filter bands, band signals, magnitudes, colours, light curves.

The chain from a simulation cube to what a telescope measures:

1. :func:`solar_spectrum` - the extraterrestrial Sun at 1 AU [W m-2 nm-1], the
   ASTM G173-03 table shipped inside pvlib (no network).
2. :func:`filters` - standard bandpasses shipped inside speclite (Bessell UBVRI,
   SDSS ugriz, ...; short aliases in :data:`BAND_ALIASES`) and user bandpasses.
3. :func:`band_weights` - the ``(band, wavelength)`` matrix ``W`` with the Sun and
   the filter folded in, so that the band flux of any spectrum ``x`` sampled on a
   wavelength grid is ``W @ x``; :func:`pre_integrate` applies it along
   ``wavelength`` of any DataArray (material tables included).  Because the
   simulated signal is a sum over facets that is linear in the material tables,
   pre-integrating the tables and integrating the full-spectrum output give the same
   band numbers to float rounding.
4. :func:`band_signal` and :func:`magnitudes` from a cube; :func:`colour_indices`;
   :func:`srgb` swatches; :func:`photometry` bundles them (``ds.sbrdf.photometry``).
5. :func:`read_light_curve`, :func:`compare_light_curves`, :func:`plot_comparison`
   for measured light curves.

Conventions
-----------
Band-integrated flux of a spectral flux density ``f(lambda)`` [W m-2 nm-1] through a
filter response ``T(lambda)`` is

* photon counting (default): ``F = int f T lambda / (h c) dlambda`` [m-2 s-1], the
  rate of detected photons, for responses that are photon-detection probabilities
  (the speclite convention);
* energy weighting: ``F = int f T dlambda`` [W m-2], for energy-response curves.

The *band signal* of a cube is the solar-weighted band mean of its radiometric
signal ``S(lambda)`` [m2 sr-1] (reflected intensity per unit solar irradiance)::

    S_band = int E_sun T w S dlambda / int E_sun T w dlambda        [m2 sr-1]

with ``w = lambda`` (photon) or ``1`` (energy).  It keeps the units of ``S``; a grey
body of signal ``c`` has ``S_band = c`` exactly, in every band.  The reflected
band flux at range ``d`` [m] from an object ``r`` AU from the Sun is
``F = F_sun,band S_band / (d**2 r**2)``, hence the magnitude

    m = m_sun,band(1 AU) + 5 log10(r / 1 AU) - 2.5 log10(S_band / d**2)

where ``m_sun,band`` is the Sun's apparent magnitude at 1 AU in the same band,
computed from the same solar spectrum and filter (:func:`sun_magnitudes`).

Magnitudes are AB (Oke & Gunn 1983, ApJ 266, 713: a flat ``f_nu`` of 3631 Jy has
magnitude 0 in every band)::

    photon:  m_AB = -2.5 log10( int f_nu T dnu/nu / int 3631 Jy T dnu/nu )
                  = -2.5 log10( int f_lambda T lambda dlambda / int f_AB,lambda T lambda dlambda )
    energy:  m_AB = -2.5 log10( int f_lambda T dlambda / int f_AB,lambda T dlambda )

with ``f_AB,lambda = 3631 Jy * c / lambda**2``.  The Vega system is not offered:
neither speclite nor colour-science nor pvlib ships a Vega spectrum, and the
package must work without the network.

A body that reflects nothing (``S_band = 0``) has magnitude ``+inf`` (zero flux;
computed without floating-point warnings); colour indices involving an infinite
magnitude are NaN (the colour is undefined).  A negative band signal (possible only
with noisy tables) gives a NaN magnitude.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from functools import cache
from importlib import resources
from importlib.metadata import version as _pkg_version
from itertools import pairwise
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from ._names import ATTITUDE, BAND, PHASE_ANGLE, WAVELENGTH, attrs
from .errors import ValidationError

__all__ = [
    "AB_ZERO_POINT_JY",
    "BAND_ALIASES",
    "EXTRAPOLATIONS",
    "QUADRATURES",
    "WEIGHTINGS",
    "ab_reference_flux",
    "band_signal",
    "band_weights",
    "colour_indices",
    "compare_light_curves",
    "filters",
    "hat_integrals",
    "magnitudes",
    "photometry",
    "plot_comparison",
    "pre_integrate",
    "read_light_curve",
    "solar_spectrum",
    "srgb",
    "sun_magnitudes",
]

# ---------------------------------------------------------------- constants

#: AB zero point [Jy] (Oke & Gunn 1983, ApJ 266, 713: m_AB = -2.5 log10 f_nu - 48.60,
#: f_nu in erg s-1 cm-2 Hz-1, i.e. 3631 Jy at m = 0).
AB_ZERO_POINT_JY = 3631.0
_JY = 1e-26  # W m-2 Hz-1
_C_M_S = 299_792_458.0  # speed of light [m s-1] (exact, SI)
_H_J_S = 6.626_070_15e-34  # Planck constant [J s] (exact, SI)

#: Short band names -> speclite filter names.  Bessell (1990, PASP 102, 1181) UBVRI
#: realise the Johnson-Cousins system; SDSS ugriz are the Doi et al. (2010, AJ 139,
#: 1628) reference responses through airmass 1.3 (the ``sdss2010noatm-*`` curves,
#: without the atmosphere, are available by their full name).
BAND_ALIASES: dict[str, str] = {
    "U": "bessell-U", "B": "bessell-B", "V": "bessell-V", "R": "bessell-R", "I": "bessell-I",
    "u": "sdss2010-u", "g": "sdss2010-g", "r": "sdss2010-r", "i": "sdss2010-i", "z": "sdss2010-z",
}

#: Spectral weightings of the band integral: name -> description.
WEIGHTINGS: dict[str, str] = {
    "photon": "photon counting: F = int f T lambda/(h c) dlambda (T a photon-detection probability)",
    "energy": "energy weighting: F = int f T dlambda (T an energy response)",
}

#: Quadratures of :func:`band_weights`: name -> description.
QUADRATURES: dict[str, str] = {
    "trapezoid": "trapezoid rule on the given wavelength grid; the solar spectrum enters as its "
    "conservative (hat-weighted) average at each grid node, the filter and the weighting at the nodes",
    "linear": "the spectrum is taken as piecewise linear between the grid nodes and multiplied by "
    "solar spectrum x filter x weighting at their native resolution; exact for that interpolant "
    "up to the native sampling",
}

#: Allowed values of ``extrapolate`` (how a spectrum is continued past its grid into a band).
EXTRAPOLATIONS: dict[str | None, str] = {
    None: "no extrapolation: a spectrum that does not cover a band's support is an error",
    "zero": "the spectrum is zero beyond its grid (the band is truncated)",
    "constant": "the spectrum keeps its end values beyond its grid",
}

_SOLAR_FILE = "ASTMG173.csv"
_SOLAR_COLUMN = "extraterrestrial"
_CMFS = "CIE 1931 2 Degree Standard Observer"


def _choose(name: Any, table: Mapping[Any, str], what: str) -> Any:
    if name not in table:
        allowed = ", ".join(repr(k) for k in table)
        raise ValidationError(f"{what}: unknown {name!r}; allowed: {allowed}")
    return name


# ------------------------------------------------------- numerical kernels


def hat_integrals(x: ArrayLike, y: ArrayLike, t: ArrayLike) -> np.ndarray:
    """Integrals of a piecewise-linear function against the hat functions of a grid.

    ``out[..., k] = int y(lambda) h_k(lambda) dlambda`` where ``y`` is the linear
    interpolant of ``(x, y)`` (zero outside ``[x[0], x[-1]]``) and ``h_k`` is the
    piecewise-linear hat of node ``t[k]`` (1 at ``t[k]``, 0 at the other nodes and
    outside ``[t[0], t[-1]]``).  Exact: on every interval of the union grid both
    factors are linear and their product is integrated in closed form,
    ``L/6 (2 y_a h_a + y_a h_b + y_b h_a + 2 y_b h_b)``.

    ``sum_k out[..., k]`` is the exact integral of ``y`` over ``[t[0], t[-1]]``;
    ``out / trapezoid_weights(t)`` is the conservative resampling of ``y`` onto ``t``.

    Parameters
    ----------
    x : array_like, shape (n,)
        Strictly increasing abscissae of ``y`` [nm].
    y : array_like, shape (..., n)
        Values.
    t : array_like, shape (m,)
        Strictly increasing grid, ``m >= 2`` [nm].

    Returns
    -------
    ndarray, shape (..., m)
    """
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    t = np.asarray(t, dtype=np.float64)
    lead = y.shape[:-1]
    y2 = y.reshape(-1, x.size)
    out = np.zeros((y2.shape[0], t.size))
    a, b = max(x[0], t[0]), min(x[-1], t[-1])
    if b <= a:
        return out.reshape(*lead, t.size)
    u = np.unique(np.concatenate([x[(x > a) & (x < b)], t[(t > a) & (t < b)], [a, b]]))
    j = np.clip(np.searchsorted(x, u, side="right") - 1, 0, x.size - 2)
    frac = (u - x[j]) / (x[j + 1] - x[j])
    yu = y2[:, j] * (1.0 - frac) + y2[:, j + 1] * frac
    i = np.clip(np.searchsorted(t, u[:-1], side="right") - 1, 0, t.size - 2)
    dt = t[i + 1] - t[i]
    ha = (t[i + 1] - u[:-1]) / dt
    hb = (t[i + 1] - u[1:]) / dt
    length = np.diff(u)
    fa, fb = yu[:, :-1], yu[:, 1:]
    left = length / 6.0 * (2.0 * fa * ha + fa * hb + fb * ha + 2.0 * fb * hb)
    right = 0.5 * length * (fa + fb) - left
    for r in range(y2.shape[0]):
        out[r] = np.bincount(i, left[r], t.size) + np.bincount(i + 1, right[r], t.size)
    return out.reshape(*lead, t.size)


def _integral(x: np.ndarray, y: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Exact integral of the linear interpolant of (x, y) over [lo, hi] (zero outside x)."""
    if hi <= lo:
        return np.zeros(y.shape[:-1])
    return hat_integrals(x, y, np.array([lo, hi])).sum(axis=-1)


def trapezoid_weights(t: ArrayLike) -> np.ndarray:
    """Trapezoid-rule weights of a grid: ``int y dlambda ~= sum_k w_k y_k`` [nm]."""
    t = np.asarray(t, dtype=np.float64)
    w = np.zeros_like(t)
    d = np.diff(t)
    w[:-1] += d / 2.0
    w[1:] += d / 2.0
    return w


def _weighting(wl: np.ndarray, weighting: str) -> np.ndarray:
    """Spectral weight w(lambda): photons per joule [J-1] or 1 (energy)."""
    if weighting == "photon":
        return wl * 1e-9 / (_H_J_S * _C_M_S)
    return np.ones_like(wl)


# ---------------------------------------------------------- solar spectrum


@cache
def _solar_native() -> tuple[np.ndarray, np.ndarray, str]:
    import pvlib

    path = Path(pvlib.__file__).resolve().parent / "data" / _SOLAR_FILE
    with open(path, encoding="utf-8") as fh:
        fh.readline()
        header = [h.strip() for h in fh.readline().split(",")]
    col = header.index(_SOLAR_COLUMN)
    data = np.loadtxt(path, delimiter=",", skiprows=2, usecols=(0, col))
    wl, e = data[:, 0], data[:, 1]
    if np.any(np.diff(wl) <= 0) or np.any(~np.isfinite(e)) or np.any(e < 0):  # pragma: no cover
        raise ValidationError(f"{path}: the solar table is not a valid spectrum")
    wl.setflags(write=False)
    e.setflags(write=False)
    return wl, e, str(path)


def _solar_provenance() -> dict[str, str]:
    wl, e, _ = _solar_native()
    total = float(_integral(wl, e, wl[0], wl[-1]))
    return {
        "solar_spectrum": "ASTM G173-03 extraterrestrial (AM0) spectral irradiance at 1 AU",
        "solar_spectrum_file": f"pvlib/data/{_SOLAR_FILE} (pvlib {_pkg_version('pvlib')}), "
        f"column {_SOLAR_COLUMN!r}, {wl.size} rows, {wl[0]:g}-{wl[-1]:g} nm, "
        f"integral {total:.1f} W m-2",
        "solar_spectrum_reference": "ASTM G173-03, Standard Tables for Reference Solar Spectral "
        "Irradiances; SMARTS2 v2.9.2 (Gueymard 2004, Sol. Energy 76, 423), solar constant "
        "1366.1 W m-2",
    }


def solar_spectrum(wavelength: ArrayLike | None = None, *, method: str = "average") -> xr.DataArray:
    """The extraterrestrial solar spectral irradiance at 1 AU.

    The ``extraterrestrial`` column of the ASTM G173-03 table that ships with pvlib
    (``pvlib/data/ASTMG173.csv``; 280-4000 nm, 0.5 nm steps below 400 nm, 1 nm to
    1700 nm, then coarser).

    Parameters
    ----------
    wavelength : array_like, optional
        Strictly increasing wavelengths [nm] inside 280-4000 nm; default the native grid.
    method : {"average", "linear"}
        ``average`` (default): the conservative resampling - the value at node ``k``
        is the mean of the (linearly interpolated) native spectrum weighted by the
        hat function of node ``k``, so the trapezoid integral on the new grid equals
        the exact integral of the native spectrum over the same range and Fraunhofer
        lines are averaged, not aliased.  ``linear``: point-wise linear interpolation
        (pvlib's own method).

    Returns
    -------
    xarray.DataArray
        ``solar_irradiance`` over ``wavelength`` [W m-2 nm-1], with provenance attrs.
    """
    wl0, e0, _ = _solar_native()
    _choose(method, {"average": "", "linear": ""}, "method")
    if wavelength is None:
        wl, e = np.array(wl0), np.array(e0)
        how = "native grid"
    else:
        wl = _check_grid(wavelength, "wavelength")
        if wl[0] < wl0[0] or wl[-1] > wl0[-1]:
            raise ValidationError(
                f"wavelength: {wl[0]:g}-{wl[-1]:g} nm is outside the solar spectrum "
                f"({wl0[0]:g}-{wl0[-1]:g} nm)")
        if method == "linear" or wl.size == 1:
            e = np.interp(wl, wl0, e0)
            how = "linear interpolation of the native table"
        else:
            e = hat_integrals(wl0, e0, wl) / trapezoid_weights(wl)
            how = "conservative hat-weighted average of the native table (trapezoid-integral preserving)"
    return xr.DataArray(
        e, dims=(WAVELENGTH,), coords={WAVELENGTH: (WAVELENGTH, wl, attrs(WAVELENGTH))},
        name="solar_irradiance", attrs=attrs("solar_irradiance", resampling=how, **_solar_provenance()))


def ab_reference_flux(wavelength: ArrayLike) -> np.ndarray:
    """Spectral flux density of the AB reference source (3631 Jy) per unit wavelength.

    ``f_lambda = f_nu c / lambda**2`` with ``f_nu = 3631 Jy = 3.631e-23 W m-2 Hz-1``.

    Parameters
    ----------
    wavelength : array_like
        [nm]

    Returns
    -------
    ndarray
        [W m-2 nm-1]
    """
    lam_m = np.asarray(wavelength, dtype=np.float64) * 1e-9
    return AB_ZERO_POINT_JY * _JY * _C_M_S / lam_m**2 * 1e-9


# ------------------------------------------------------------------- bands


@dataclass(frozen=True)
class _Band:
    label: str
    filter: str
    wavelength: np.ndarray  # nm
    response: np.ndarray
    source: str

    @property
    def support(self) -> tuple[float, float]:
        """Wavelength range outside which the (linearly interpolated) response is zero [nm]."""
        pos = np.flatnonzero(self.response > 0)
        lo = self.wavelength[max(pos[0] - 1, 0)]
        hi = self.wavelength[min(pos[-1] + 1, self.wavelength.size - 1)]
        return float(lo), float(hi)


def _check_grid(wavelength: ArrayLike, what: str) -> np.ndarray:
    wl = np.atleast_1d(np.asarray(wavelength, dtype=np.float64))
    if wl.ndim != 1 or wl.size < 1:
        raise ValidationError(f"{what}: expected a 1-D array, got shape {wl.shape}")
    if not np.all(np.isfinite(wl)) or np.any(wl <= 0):
        raise ValidationError(f"{what}: wavelengths must be finite and > 0 nm")
    if np.any(np.diff(wl) <= 0):
        k = int(np.flatnonzero(np.diff(wl) <= 0)[0])
        raise ValidationError(f"{what}: must be strictly increasing; {wl[k]:g} nm is followed by {wl[k + 1]:g} nm")
    return wl


def _speclite_dir() -> Path:
    return Path(str(resources.files("speclite") / "data" / "filters"))


def speclite_names() -> list[str]:
    """Names of the filter curves shipped with speclite (``group-band``)."""
    return sorted(p.stem for p in _speclite_dir().glob("*.ecsv"))


@cache
def _speclite_band(name: str) -> tuple[np.ndarray, np.ndarray, str]:
    import speclite.filters

    if name not in speclite_names():
        raise ValidationError(
            f"band: unknown {name!r}; use an alias ({', '.join(BAND_ALIASES)}) or a speclite "
            f"filter name (e.g. {', '.join(speclite_names()[:6])}, ...; see "
            "sbrdf_xr.photometry.speclite_names())")
    f = speclite.filters.load_filter(name)
    wl = np.asarray(f.wavelength, dtype=np.float64) / 10.0  # speclite stores Angstrom
    resp = np.asarray(f.response, dtype=np.float64)
    desc = " ".join(str(f.meta.get("description", "")).split())
    src = (f"speclite {_pkg_version('speclite')} file speclite/data/filters/{name}.ecsv "
           f"({f.meta.get('url', '')}; airmass {f.meta.get('airmass', '?')}): {desc[:160]}")
    wl.setflags(write=False)
    resp.setflags(write=False)
    return wl, resp, src


def _canonical(name: str) -> str:
    return BAND_ALIASES.get(name, name)


def _user_band(label: str, spec: Any) -> _Band:
    if isinstance(spec, xr.DataArray):
        if spec.dims != (WAVELENGTH,) or WAVELENGTH not in spec.coords:
            raise ValidationError(f"band {label!r}: a bandpass DataArray needs the single dim "
                                  f"'{WAVELENGTH}' with its coordinate, got dims {spec.dims}")
        units = spec[WAVELENGTH].attrs.get("units", "nm")
        if units != "nm":
            raise ValidationError(f"band {label!r}: wavelength units must be 'nm', got {units!r}")
        wl, resp = spec[WAVELENGTH].values, spec.values
        src = spec.attrs.get("provenance", spec.attrs.get("source", "user-supplied bandpass"))
    else:
        try:
            wl, resp = spec
        except (TypeError, ValueError):
            raise ValidationError(f"band {label!r}: expected a DataArray or a (wavelength, response) "
                                  f"pair, got {type(spec).__name__}") from None
        src = "user-supplied bandpass"
    wl = _check_grid(wl, f"band {label!r} wavelength")
    resp = np.asarray(resp, dtype=np.float64)
    if resp.shape != wl.shape:
        raise ValidationError(f"band {label!r}: response shape {resp.shape} differs from wavelength {wl.shape}")
    if wl.size < 2 or not np.all(np.isfinite(resp)) or np.any(resp < 0) or not np.any(resp > 0):
        raise ValidationError(f"band {label!r}: response must have >= 2 finite, non-negative values, "
                              "not all zero")
    return _Band(label, f"user:{label}", wl, resp, str(src))


def _resolve_bands(bands: Any) -> list[_Band]:
    """Normalise every accepted form of ``bands`` to a list of _Band."""
    items: list[tuple[str, Any]] = []
    if isinstance(bands, str):
        items = [(bands, None)]
    elif isinstance(bands, xr.DataArray):
        if BAND in bands.dims:
            if set(bands.dims) != {BAND, WAVELENGTH}:
                raise ValidationError(f"bands: a filter DataArray must have dims (band, wavelength), got {bands.dims}")
            b = bands.transpose(BAND, WAVELENGTH)
            out = []
            for k, lab in enumerate(b[BAND].values.tolist()):
                row = b.isel({BAND: k}).drop_vars(BAND)
                band = _user_band(str(lab), row)
                filt = str(b["filter"].values[k]) if "filter" in b.coords else band.filter
                src = str(b["filter_source"].values[k]) if "filter_source" in b.coords else band.source
                out.append(_Band(band.label, filt, band.wavelength, band.response, src))
            return _unique(out)
        items = [(str(bands.name or "user"), bands)]
    elif isinstance(bands, Mapping):
        items = [(str(k), v) for k, v in bands.items()]
    elif isinstance(bands, Iterable):
        for it in bands:
            if isinstance(it, str):
                items.append((it, None))
            elif isinstance(it, xr.DataArray):
                items.append((str(it.name or "user"), it))
            elif isinstance(it, tuple) and len(it) == 2 and isinstance(it[0], str):
                items.append(it)
            else:
                raise ValidationError(f"bands: cannot interpret {type(it).__name__} {it!r}; give a band "
                                      "name, a (name, bandpass) pair or a named DataArray")
    else:
        raise ValidationError(f"bands: expected names or bandpasses, got {type(bands).__name__}")
    if not items:
        raise ValidationError("bands: no band given")
    out = []
    for label, spec in items:
        if spec is None:
            name = _canonical(label)
            wl, resp, src = _speclite_band(name)
            out.append(_Band(label, name, wl, resp, src))
        else:
            out.append(_user_band(label, spec))
    return _unique(out)


def _unique(bands: list[_Band]) -> list[_Band]:
    labels = [b.label for b in bands]
    dup = sorted({x for x in labels if labels.count(x) > 1})
    if dup:
        raise ValidationError(f"bands: duplicate band labels {dup}")
    return bands


def _band_coords(bands: list[_Band]) -> dict[str, Any]:
    return {
        BAND: (BAND, [b.label for b in bands], attrs(BAND)),
        "filter": (BAND, [b.filter for b in bands], attrs("filter")),
        "filter_source": (BAND, [b.source for b in bands], attrs("filter_source")),
    }


def filters(bands: Any, wavelength: ArrayLike | None = None) -> xr.DataArray:
    """Filter responses as a ``(band, wavelength)`` DataArray.

    Parameters
    ----------
    bands : str, sequence, mapping or DataArray
        Band names - short aliases (:data:`BAND_ALIASES`: ``U B V R I`` -> Bessell,
        ``u g r i z`` -> SDSS 2010) or any speclite filter name (``"bessell-V"``,
        ``"sdss2010-g"``, ``"decam2014-r"``, ...; :func:`speclite_names`) - and/or user
        bandpasses: ``(label, DataArray over wavelength [nm])`` or ``(label,
        (wavelength [nm], response))`` pairs, a mapping label -> bandpass, a named
        DataArray, or a ``(band, wavelength)`` DataArray from this function.
    wavelength : array_like, optional
        Common grid [nm]; default the union of the filters' own nodes.  Responses are
        interpolated linearly and are zero outside their tabulated range.

    Returns
    -------
    xarray.DataArray
        ``filter_response`` [1] with coords ``band`` (labels as given), ``filter``
        (speclite name or ``user:<label>``) and ``filter_source`` (file and reference).
        Responses are as shipped: speclite curves are photon-detection probabilities
        (use them with ``weighting="photon"``, the default of the band functions).
    """
    bl = _resolve_bands(bands)
    if wavelength is None:
        wl = np.unique(np.concatenate([b.wavelength for b in bl]))
    else:
        wl = _check_grid(wavelength, "wavelength")
    resp = np.stack([np.interp(wl, b.wavelength, b.response, left=0.0, right=0.0) for b in bl])
    coords = _band_coords(bl)
    coords[WAVELENGTH] = (WAVELENGTH, wl, attrs(WAVELENGTH))
    return xr.DataArray(resp, dims=(BAND, WAVELENGTH), coords=coords, name="filter_response",
                        attrs=attrs("filter_response",
                                    response_convention="as shipped; speclite responses are photon-"
                                    "detection probabilities (photon-counting integrals use T lambda)"))


def _coverage_error(band: _Band, lo: float, hi: float, what: str, extra: str = "") -> ValidationError:
    blo, bhi = band.support
    return ValidationError(
        f"band {band.label!r} ({band.filter}) has non-zero response over {blo:g}-{bhi:g} nm but the "
        f"{what} covers only {lo:g}-{hi:g} nm{extra}")


def _band_rows(
    bl: list[_Band], t: np.ndarray, weighting: str, quadrature: str, extrapolate: str | None
) -> tuple[np.ndarray, np.ndarray]:
    """Unnormalised weights (n_band, n_t) and the full-band solar integrals (n_band,)."""
    ws, es, _ = _solar_native()
    rows = np.zeros((len(bl), t.size))
    full = np.zeros(len(bl))
    for n, band in enumerate(bl):
        blo, bhi = band.support
        if blo < ws[0] or bhi > ws[-1]:
            raise _coverage_error(band, ws[0], ws[-1], "solar spectrum (ASTM G173-03)")
        if (t[0] > blo or t[-1] < bhi) and extrapolate is None:
            raise _coverage_error(
                band, t[0], t[-1], "spectrum",
                "; pass extrapolate='zero' or 'constant' to continue the spectrum past its grid")
        inside = lambda v, lo=blo, hi=bhi: v[(v > lo) & (v < hi)]  # noqa: E731
        g_grid = np.unique(np.concatenate([[blo, bhi], inside(ws), inside(band.wavelength), inside(t)]))
        g = (np.interp(g_grid, ws, es) * np.interp(g_grid, band.wavelength, band.response, left=0.0, right=0.0)
             * _weighting(g_grid, weighting))
        if t.size == 1:
            if t[0] < blo or t[0] > bhi:
                raise _coverage_error(band, t[0], t[0], "spectrum")
            below, above, row = 0.0, 0.0, np.zeros(1)
            below = float(_integral(g_grid, g, g_grid[0], g_grid[-1]))  # all of it: constant spectrum
        else:
            below = float(_integral(g_grid, g, g_grid[0], t[0]))
            above = float(_integral(g_grid, g, t[-1], g_grid[-1]))
            if quadrature == "linear":
                row = hat_integrals(g_grid, g, t)
            else:
                e_hat = hat_integrals(ws, es, t)  # = trapezoid weight x conservative solar average
                row = e_hat * np.interp(t, band.wavelength, band.response, left=0.0, right=0.0) * _weighting(t, weighting)
        full[n] = row.sum() + below + above
        if extrapolate == "constant" or t.size == 1:
            row = row.copy()
            row[0] += below
            row[-1] += above
        rows[n] = row
    return rows, full


def band_weights(
    bands: Any,
    wavelength: ArrayLike,
    *,
    weighting: str = "photon",
    quadrature: str = "trapezoid",
    extrapolate: str | None = None,
    normalize: bool = False,
) -> xr.DataArray:
    """The ``(band, wavelength)`` matrix that band-integrates a spectrum under sunlight.

    For any spectrum ``x`` sampled on ``wavelength`` (a signal [m2 sr-1], an sBRDF
    [sr-1], a reflectance [1]), ``W @ x`` approximates
    ``int E_sun(lambda) T(lambda) w(lambda) x(lambda) dlambda`` with the ASTM G173-03
    Sun at 1 AU ``E_sun`` [W m-2 nm-1], the filter response ``T`` and the weighting
    ``w`` (``lambda / (h c)`` for photon counting, 1 for energy).  Linear in ``x``,
    hence band outputs can be obtained by pre-integrating material tables exactly
    (to float rounding) relative to integrating the full-spectrum output on the same
    grid with the same ``W``.

    Quadrature (see :data:`QUADRATURES`): ``trapezoid`` (default) is the trapezoid rule
    on ``wavelength``, ``W[b, k] = Ehat_k T_b(lambda_k) w(lambda_k)``, where
    ``Ehat_k = int E_sun h_k dlambda`` is the trapezoid weight times the conservative
    average of the Sun around node ``k`` (:func:`hat_integrals`; Fraunhofer lines are
    averaged, never aliased); ``linear`` takes ``x`` piecewise linear and integrates it
    against ``E_sun T w`` at the native resolution (more accurate on coarse grids).

    Parameters
    ----------
    bands : str, sequence, mapping or DataArray
        See :func:`filters`.
    wavelength : array_like
        Strictly increasing grid of the spectra [nm].
    weighting : {"photon", "energy"}
    quadrature : {"trapezoid", "linear"}
    extrapolate : {None, "zero", "constant"}
        How a spectrum continues past its grid (:data:`EXTRAPOLATIONS`).  By default
        a grid that does not cover a band's non-zero response raises.
    normalize : bool
        Divide each row by the full-band solar integral ``int E_sun T w dlambda``
        (computed with the same quadrature, continuing the Sun past the grid): then
        ``W @ x`` is the solar-weighted band mean of ``x`` in the units of ``x``, and
        ``W @ 1 = 1`` whenever the grid covers the band or ``extrapolate="constant"``.

    Returns
    -------
    xarray.DataArray
        ``band_weight`` (band, wavelength); units ``m-2 s-1`` (photon) or ``W m-2``
        (energy) per unit of ``x``, or ``1`` when normalised; attrs state the weighting,
        quadrature, extrapolation and the solar and filter provenance.

    Raises
    ------
    ValidationError
        Unknown band, weighting, quadrature or extrapolation; a band not covered by
        the grid (without ``extrapolate``) or by the solar spectrum.
    """
    _choose(weighting, WEIGHTINGS, "weighting")
    _choose(quadrature, QUADRATURES, "quadrature")
    _choose(extrapolate, EXTRAPOLATIONS, "extrapolate")
    t = _check_grid(wavelength, "wavelength")
    bl = _resolve_bands(bands)
    rows, full = _band_rows(bl, t, weighting, quadrature, extrapolate)
    if normalize:
        rows = rows / full[:, None]
        units = "1"
    else:
        units = "m-2 s-1" if weighting == "photon" else "W m-2"
    coords = _band_coords(bl)
    coords[WAVELENGTH] = (WAVELENGTH, t, attrs(WAVELENGTH))
    return xr.DataArray(rows, dims=(BAND, WAVELENGTH), coords=coords, name="band_weight",
                        attrs=attrs("band_weight", units=units, **_method_attrs(weighting, quadrature, extrapolate),
                                    normalized=int(normalize)))


def _method_attrs(weighting: str, quadrature: str, extrapolate: str | None) -> dict[str, str]:
    return {
        "weighting": weighting,
        "weighting_description": WEIGHTINGS[weighting],
        "quadrature": quadrature,
        "quadrature_description": QUADRATURES[quadrature],
        "extrapolate": str(extrapolate),
        "extrapolate_description": EXTRAPOLATIONS[extrapolate],
        **_solar_provenance(),
    }


def pre_integrate(
    table: xr.DataArray,
    bands: Any,
    *,
    weighting: str = "photon",
    quadrature: str = "trapezoid",
    extrapolate: str | None = None,
    normalize: bool = True,
) -> xr.DataArray:
    """Apply :func:`band_weights` along ``wavelength`` of any DataArray.

    Parameters
    ----------
    table : xarray.DataArray
        Anything with a ``wavelength`` dimension and coordinate [nm]: a material table
        ``(theta_i, delta_theta, phi, wavelength)`` [sr-1], a cube's ``signal``
        [m2 sr-1], ... Dask-backed arrays stay lazy.
    bands : str, sequence, mapping or DataArray
        See :func:`filters`.
    weighting, quadrature, extrapolate
        See :func:`band_weights`.
    normalize : bool, default True
        Solar-weighted band means (same units as ``table``); ``False`` gives band
        fluxes per unit of ``table`` at 1 AU.

    Returns
    -------
    xarray.DataArray
        Same dims with ``band`` in place of ``wavelength``, same name and attrs
        (``units`` multiplied by the weight units when not normalised).
    """
    if not isinstance(table, xr.DataArray) or WAVELENGTH not in table.dims or WAVELENGTH not in table.coords:
        raise ValidationError(f"table: expected a DataArray with a '{WAVELENGTH}' dimension and coordinate")
    units = table[WAVELENGTH].attrs.get("units", "nm")
    if units != "nm":
        raise ValidationError(f"table: wavelength units must be 'nm', got {units!r}")
    w = band_weights(bands, table[WAVELENGTH].values, weighting=weighting, quadrature=quadrature,
                     extrapolate=extrapolate, normalize=normalize)
    w = w.astype(np.result_type(table.dtype, np.float32))
    dims = [BAND if d == WAVELENGTH else d for d in table.dims]
    out = xr.dot(table, w.drop_vars(WAVELENGTH).assign_coords({WAVELENGTH: table[WAVELENGTH]}), dim=WAVELENGTH)
    out = out.transpose(*dims)
    out.name = table.name
    out.attrs = dict(table.attrs)
    if not normalize:
        tu = table.attrs.get("units", "1")
        out.attrs["units"] = w.attrs["units"] if tu == "1" else f"{tu} {w.attrs['units']}"
    out.attrs.update({k: v for k, v in w.attrs.items() if k not in ("units", "long_name")})
    out.attrs["band_integration"] = ("solar-weighted band mean" if normalize
                                     else "band flux at 1 AU per unit of the spectrum")
    for c in ("filter", "filter_source"):
        out = out.assign_coords({c: w[c]})
    return out


def sun_magnitudes(bands: Any, *, weighting: str = "photon", system: str = "AB") -> xr.DataArray:
    """Apparent magnitudes of the Sun at 1 AU in each band.

    ``m_sun = -2.5 log10( int E_sun T w dlambda / int f_AB T w dlambda )``, both
    integrals on the union of the solar and filter nodes (native resolution).

    Parameters
    ----------
    bands : str, sequence, mapping or DataArray
        See :func:`filters`.
    weighting : {"photon", "energy"}
    system : {"AB"}
        Only AB: no Vega spectrum ships with the dependencies.

    Returns
    -------
    xarray.DataArray
        ``sun_magnitude`` over ``band`` [mag].
    """
    _choose(weighting, WEIGHTINGS, "weighting")
    _check_system(system)
    ws, es, _ = _solar_native()
    bl = _resolve_bands(bands)
    out = np.zeros(len(bl))
    for n, band in enumerate(bl):
        blo, bhi = band.support
        if blo < ws[0] or bhi > ws[-1]:
            raise _coverage_error(band, ws[0], ws[-1], "solar spectrum (ASTM G173-03)")
        grid = np.unique(np.concatenate([[blo, bhi], ws[(ws > blo) & (ws < bhi)],
                                         band.wavelength[(band.wavelength > blo) & (band.wavelength < bhi)]]))
        tw = np.interp(grid, band.wavelength, band.response, left=0.0, right=0.0) * _weighting(grid, weighting)
        sun = _integral(grid, np.interp(grid, ws, es) * tw, blo, bhi)
        ref = _integral(grid, ab_reference_flux(grid) * tw, blo, bhi)
        out[n] = -2.5 * np.log10(sun / ref)
    return xr.DataArray(out, dims=(BAND,), coords=_band_coords(bl), name="sun_magnitude",
                        attrs=attrs("sun_magnitude", magnitude_system=system, weighting=weighting,
                                    **_solar_provenance()))


def _check_system(system: str) -> None:
    if system != "AB":
        raise ValidationError(
            f"system: unknown {system!r}; allowed: 'AB' (Vega is not offered: no Vega spectrum ships "
            "with speclite, colour-science or pvlib)")


# ------------------------------------------------------------ from a cube


def _signal_of(cube: xr.Dataset | xr.DataArray, variable: str = "signal") -> xr.DataArray:
    if isinstance(cube, xr.Dataset):
        if variable not in cube:
            raise ValidationError(f"cube: no variable {variable!r}; has {sorted(map(str, cube.data_vars))}")
        da = cube[variable]
    elif isinstance(cube, xr.DataArray):
        da = cube
    else:
        raise ValidationError(f"cube: expected an xarray Dataset or DataArray, got {type(cube).__name__}")
    if WAVELENGTH not in da.dims:
        raise ValidationError(f"cube: {da.name!r} has no '{WAVELENGTH}' dimension (dims {da.dims})")
    return da


def band_signal(
    cube: xr.Dataset | xr.DataArray,
    bands: Any,
    *,
    variable: str = "signal",
    weighting: str = "photon",
    quadrature: str = "trapezoid",
    extrapolate: str | None = None,
) -> xr.DataArray:
    """Solar-weighted band mean of a cube's radiometric signal.

    ``S_band = int E_sun T w S dlambda / int E_sun T w dlambda`` [m2 sr-1] (module
    docstring): the reflected band intensity per unit solar band irradiance.  Times
    the Sun's band flux at the object and divided by the squared range it is the
    observed band flux.

    Parameters
    ----------
    cube : xarray.Dataset or DataArray
        A simulation cube (its ``variable``) or a spectrum over ``wavelength``.
    bands : str, sequence, mapping or DataArray
        See :func:`filters`.
    variable : str
        Cube variable to integrate (``signal`` or ``signal_material``).
    weighting, quadrature, extrapolate
        See :func:`band_weights`.

    Returns
    -------
    xarray.DataArray
        ``band_signal`` with ``band`` in place of ``wavelength`` [m2 sr-1], lazy if the
        cube is, with the Sun's band magnitudes as coordinate ``sun_magnitude``.
    """
    s = _signal_of(cube, variable)
    out = pre_integrate(s, bands, weighting=weighting, quadrature=quadrature, extrapolate=extrapolate,
                        normalize=True)
    sun = sun_magnitudes(bands, weighting=weighting)
    out = out.assign_coords(sun_magnitude=(BAND, sun.values, sun.attrs))
    out.name = "band_signal"
    out.attrs.update(attrs("band_signal", units=s.attrs.get("units", "m2 sr-1")))
    return out


def _range_m(range_km: Any) -> Any:
    if isinstance(range_km, xr.DataArray):
        vals = np.asarray(range_km.values, dtype=np.float64)
        r = range_km.astype(np.float64) * 1e3
    else:
        vals = np.asarray(range_km, dtype=np.float64)
        r = vals * 1e3
    if vals.size == 0 or not np.all(np.isfinite(vals)) or np.any(vals <= 0):
        raise ValidationError(f"range_km: must be finite and > 0 km, got {vals.ravel()[:5].tolist()}")
    return r


def magnitudes(
    cube: xr.Dataset | xr.DataArray,
    bands: Any = None,
    range_km: Any = None,
    *,
    system: str = "AB",
    sun_distance_au: float = 1.0,
    weighting: str = "photon",
    quadrature: str = "trapezoid",
    extrapolate: str | None = None,
) -> xr.DataArray:
    """Apparent magnitudes of the reflected sunlight.

    ``m = m_sun,band + 5 log10(r / 1 AU) - 2.5 log10(S_band / d**2)`` with ``d`` the
    observer range [m] (module docstring).  ``S_band = 0`` gives ``+inf`` (no
    warning), a negative ``S_band`` gives NaN.

    Parameters
    ----------
    cube : xarray.Dataset or DataArray
        A cube (or spectrum over ``wavelength``), or a :func:`band_signal` result
        (then ``bands`` is not needed).
    bands : str, sequence, mapping or DataArray
        See :func:`filters`.
    range_km : float, array_like or DataArray
        Observer range [km], > 0; broadcast against the cube (a DataArray aligns by dims).
    system : {"AB"}
    sun_distance_au : float
        Sun-object distance [AU].
    weighting, quadrature, extrapolate
        See :func:`band_weights`.

    Returns
    -------
    xarray.DataArray
        ``magnitude`` [mag] over the cube's dims with ``band`` in place of ``wavelength``.
    """
    _check_system(system)
    if range_km is None:
        raise ValidationError("range_km: the observer range [km] is required")
    d = _range_m(range_km)
    if not np.isfinite(sun_distance_au) or sun_distance_au <= 0:
        raise ValidationError(f"sun_distance_au: must be finite and > 0, got {sun_distance_au}")
    if isinstance(cube, xr.DataArray) and BAND in cube.dims and "sun_magnitude" in cube.coords:
        sb = cube
    else:
        if bands is None:
            raise ValidationError("bands: required unless a band_signal result is given")
        sb = band_signal(cube, bands, weighting=weighting, quadrature=quadrature, extrapolate=extrapolate)
    return _magnitudes_from(sb, d, sun_distance_au, system)


def _magnitudes_from(sb: xr.DataArray, d_m: Any, sun_distance_au: float, system: str) -> xr.DataArray:
    ratio = sb / d_m**2
    pos = ratio > 0
    safe = xr.where(pos, ratio, 1.0)
    m = sb["sun_magnitude"] + 5.0 * np.log10(sun_distance_au) - 2.5 * np.log10(safe)
    m = xr.where(pos, m, xr.where(ratio == 0, np.inf, np.nan))
    m = m.transpose(*sb.dims, ...)
    m.name = "magnitude"
    m.attrs = attrs("magnitude", magnitude_system=system, weighting=sb.attrs.get("weighting", ""),
                    sun_distance_au=float(sun_distance_au),
                    note="+inf where the band signal is 0 (nothing reflects toward the observer); "
                    "NaN where it is negative",
                    formula="m = m_sun,band(1 AU) + 5 log10(r/AU) - 2.5 log10(S_band / d^2), d in m")
    if not isinstance(d_m, xr.DataArray):
        d_arr = np.asarray(d_m)
        if d_arr.ndim == 0:
            m.attrs["range_km"] = float(d_arr) / 1e3
    return m


def colour_indices(mags: xr.DataArray, pairs: Sequence[tuple[str, str]] | None = None) -> xr.DataArray:
    """Colour indices ``m_a - m_b`` of band pairs.

    Parameters
    ----------
    mags : xarray.DataArray
        Magnitudes over ``band`` (:func:`magnitudes`).
    pairs : sequence of (str, str), optional
        Band labels (aliases and speclite names are matched through the ``filter``
        coordinate); default consecutive bands in the order given.

    Returns
    -------
    xarray.DataArray
        ``colour_index`` [mag] with dim ``colour`` (labels ``"a-b"``) and coords
        ``first``, ``second``; NaN where either magnitude is infinite or NaN.
    """
    if not isinstance(mags, xr.DataArray) or BAND not in mags.dims:
        raise ValidationError("mags: expected a DataArray with a 'band' dimension")
    labels = [str(b) for b in mags[BAND].values]
    if pairs is None:
        pairs = list(pairwise(labels))
    if not pairs:
        raise ValidationError("pairs: need at least two bands for a colour index")
    idx = [_band_index(mags, a) for a, _ in pairs], [_band_index(mags, b) for _, b in pairs]
    first = mags.isel({BAND: idx[0]})
    second = mags.isel({BAND: idx[1]})
    first = first.drop_vars([c for c in first.coords if BAND in first[c].dims]).rename({BAND: "colour"})
    second = second.drop_vars([c for c in second.coords if BAND in second[c].dims]).rename({BAND: "colour"})
    ok = np.isfinite(first) & np.isfinite(second)
    ci = xr.where(ok, xr.where(ok, first, 0.0) - xr.where(ok, second, 0.0), np.nan)
    names = [f"{a}-{b}" for a, b in pairs]
    ci = ci.assign_coords(colour=("colour", names, attrs("colour")),
                          first=("colour", [labels[i] for i in idx[0]]),
                          second=("colour", [labels[i] for i in idx[1]]))
    dims = [("colour" if d == BAND else d) for d in mags.dims]
    ci = ci.transpose(*dims)
    ci.name = "colour_index"
    ci.attrs = attrs("colour_index", magnitude_system=mags.attrs.get("magnitude_system", "AB"),
                     note="NaN where either magnitude is infinite (nothing reflects) or NaN")
    return ci


def _band_index(mags: xr.DataArray, label: str) -> int:
    labels = [str(b) for b in mags[BAND].values]
    if label in labels:
        return labels.index(label)
    if "filter" in mags.coords:
        filt = [str(f) for f in mags["filter"].values]
        if _canonical(label) in filt:
            return filt.index(_canonical(label))
    raise ValidationError(f"pairs: band {label!r} is not among the bands {labels}")


def photometry(
    cube: xr.Dataset | xr.DataArray,
    bands: Any,
    range_km: Any,
    *,
    pairs: Sequence[tuple[str, str]] | None = None,
    system: str = "AB",
    sun_distance_au: float = 1.0,
    weighting: str = "photon",
    quadrature: str = "trapezoid",
    extrapolate: str | None = None,
) -> xr.Dataset:
    """Band signal, magnitudes and colour indices of a cube, as one Dataset.

    Parameters are those of :func:`band_signal`, :func:`magnitudes` and
    :func:`colour_indices`.  Also ``ds.sbrdf.photometry(bands=..., range_km=...)``.

    Returns
    -------
    xarray.Dataset
        ``band_signal`` [m2 sr-1], ``magnitude`` [mag], ``colour_index`` [mag] (when
        there are two bands or more), with the cube's coordinates.
    """
    d = _range_m(range_km)
    _check_system(system)
    sb = band_signal(cube, bands, weighting=weighting, quadrature=quadrature, extrapolate=extrapolate)
    m = _magnitudes_from(sb, d, sun_distance_au, system)
    out = {"band_signal": sb, "magnitude": m}
    if sb.sizes[BAND] > 1 or pairs:
        out["colour_index"] = colour_indices(m, pairs)
    ds = xr.Dataset(out)
    src = cube.attrs if isinstance(cube, xr.Dataset) else {}
    ds.attrs = {
        "Conventions": "CF-1.10",
        "title": f"sbrdf_xr photometry of {src.get('title', 'a spectrum')}",
        "source": src.get("source", "sbrdf_xr"),
        "history": f"sbrdf_xr.photometry(bands={[str(b) for b in sb[BAND].values]}, "
        f"range_km={np.asarray(range_km).tolist() if not isinstance(range_km, xr.DataArray) else 'DataArray'}, "
        f"system={system}, weighting={weighting}, quadrature={quadrature}, extrapolate={extrapolate})",
        "magnitude_system": system,
        "sun_distance_au": float(sun_distance_au),
        **_method_attrs(weighting, quadrature, extrapolate),
    }
    if "range_km" in m.attrs:
        ds.attrs["range_km"] = m.attrs["range_km"]
    return ds


# ------------------------------------------------------------------- colour


def _interp_matrix(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """(n_dst, n_src) matrix of linear interpolation with constant extrapolation."""
    p = np.zeros((dst.size, src.size))
    if src.size == 1:
        p[:, 0] = 1.0
        return p
    d = np.clip(dst, src[0], src[-1])
    j = np.clip(np.searchsorted(src, d, side="right") - 1, 0, src.size - 2)
    f = (d - src[j]) / (src[j + 1] - src[j])
    rows = np.arange(dst.size)
    p[rows, j] = 1.0 - f
    p[rows, j + 1] += f
    return p


def srgb(
    source: xr.Dataset | xr.DataArray,
    *,
    variable: str = "signal",
    white: str = "sun",
    normalise: str = "each",
) -> xr.DataArray:
    """sRGB swatches of the reflected sunlight (signal x solar spectrum).

    The spectrum ``S(lambda)`` is resampled linearly to 360-830 nm in 5 nm steps (held
    constant past its ends), taken as the reflectance factor of an object lit by the
    ASTM G173-03 Sun, and converted to CIE XYZ with the CIE 1931 2-degree observer by
    colour-science (``colour.msds_to_XYZ``, the vectorised ``sd_to_XYZ``, method
    ``Integration``): ``XYZ = k int S E_sun cmf dlambda``, ``k`` such that ``S = 1``
    gives ``Y = 100``.  Then ``colour.XYZ_to_sRGB``:

    * ``white="sun"`` (default): chromatic adaptation (CAT02) from the Sun's white
      point to D65, as an eye adapted to sunlight sees it - a spectrally flat
      reflector is neutral grey;
    * ``white="D65"``: no adaptation - the colour of the reflected light itself on a
      D65 display (the Sun appears slightly warm).

    Parameters
    ----------
    source : xarray.Dataset or DataArray
        A cube (its ``variable``) or spectra over ``wavelength``.
    variable : str
        Cube variable.
    white : {"sun", "D65"}
    normalise : {"each", "global"}
        ``each``: every swatch scaled so its largest linear channel is 1 (hue and
        saturation only); ``global``: one factor for all, the largest channel of the
        set is 1 (relative brightness kept).  Negative (out-of-gamut) linear values
        are clipped to 0 before the sRGB transfer function.  Black for zero spectra.

    Returns
    -------
    xarray.DataArray
        ``srgb`` [1] over the spectra's other dims plus ``rgb`` (R, G, B), encoded
        with the sRGB transfer function, in [0, 1].  Computed eagerly (loads the data).
    """
    import colour

    _choose(white, {"sun": "", "D65": ""}, "white")
    _choose(normalise, {"each": "", "global": ""}, "normalise")
    s = _signal_of(source, variable)
    other = [d for d in s.dims if d != WAVELENGTH]
    s = s.transpose(*other, WAVELENGTH)
    wl = np.asarray(s[WAVELENGTH].values, dtype=np.float64)
    grid = np.arange(360.0, 831.0, 5.0)
    shape = colour.SpectralShape(360, 830, 5)
    vals = np.asarray(s.values, dtype=np.float64) @ _interp_matrix(wl, grid).T
    sun = solar_spectrum(grid, method="average").values
    cmfs = colour.MSDS_CMFS[_CMFS].copy().align(shape)  # 1931 CMFs at their 5 nm nodes (no warning)
    ill = colour.SpectralDistribution(sun, grid, name="ASTM G173-03 AM0")
    xyz = colour.msds_to_XYZ(vals, cmfs=cmfs, illuminant=ill, method="Integration", shape=shape) / 100.0
    d65 = colour.CCS_ILLUMINANTS[_CMFS]["D65"]
    if white == "sun":
        xyz_w = colour.msds_to_XYZ(np.ones((1, grid.size)), cmfs=cmfs, illuminant=ill,
                                   method="Integration", shape=shape)[0] / 100.0
        rgb = colour.XYZ_to_sRGB(xyz, illuminant=colour.XYZ_to_xy(xyz_w),
                                 chromatic_adaptation_transform="CAT02", apply_cctf_encoding=False)
    else:
        rgb = colour.XYZ_to_sRGB(xyz, illuminant=d65, chromatic_adaptation_transform=None,
                                 apply_cctf_encoding=False)
    rgb = np.clip(np.asarray(rgb, dtype=np.float64), 0.0, None)
    if normalise == "each":
        scale = rgb.max(axis=-1, keepdims=True)
    else:
        scale = np.full((*rgb.shape[:-1], 1), rgb.max() if rgb.size else 0.0)
    rgb = np.divide(rgb, scale, out=np.zeros_like(rgb), where=scale > 0)
    enc = np.asarray(colour.cctf_encoding(np.clip(rgb, 0.0, 1.0), function="sRGB"), dtype=np.float64)
    coords = {k: v for k, v in s.coords.items() if WAVELENGTH not in v.dims}
    coords["rgb"] = ("rgb", ["R", "G", "B"])
    return xr.DataArray(enc, dims=(*other, "rgb"), coords=coords, name="srgb",
                        attrs=attrs("srgb", white=white, normalise=normalise,
                                    colorimetry=f"{_CMFS}, CIE XYZ -> sRGB (IEC 61966-2-1) by colour-science "
                                    f"{_pkg_version('colour-science')}; illuminant: ASTM G173-03 AM0 Sun"))


# -------------------------------------------------------------- light curves

LIGHT_CURVE_COLUMNS = ("band", "magnitude", "uncertainty")
LIGHT_CURVE_ABSCISSAE = ("time", "rotation_angle")


def read_light_curve(path: str | os.PathLike[str], *, bands: Sequence[str] | None = None) -> xr.Dataset:
    """Read a measured light curve from CSV or netCDF.

    Schema (one observation per row; CSV with a header line, extra columns ignored):

    ============== ========================================================================
    column         meaning
    ============== ========================================================================
    time           observation time: seconds [s] (any origin) or ISO 8601 timestamps;
                   **or** ``rotation_angle`` [degree], the body rotation angle (cumulative,
                   may exceed 360).  Exactly one of the two; non-decreasing down the file.
    band           band label: an alias (``B``, ``V``, ``g``, ...) or speclite filter name,
                   or one of ``bands`` when given
    magnitude      measured magnitude [mag]
    uncertainty    1-sigma uncertainty of the magnitude [mag], > 0
    ============== ========================================================================

    A netCDF file holds the same names as variables along one dimension.

    Parameters
    ----------
    path : str or path
        ``.csv`` (or any text file) or ``.nc``.
    bands : sequence of str, optional
        Allowed band labels; default any alias or speclite filter name.

    Returns
    -------
    xarray.Dataset
        Over ``obs``: ``magnitude``, ``uncertainty`` [mag], coords ``band`` and ``time``
        [s] (numeric times as given; ISO 8601 times as seconds since the first
        observation, attr ``time_origin``) or ``rotation_angle`` [degree].

    Raises
    ------
    ValidationError
        Naming the file and the column or row: missing columns, both or neither of
        time and rotation_angle, NaN or non-numeric values, non-positive uncertainty,
        unknown bands, times or angles that decrease.
    """
    import pandas as pd

    path = Path(path)
    if not path.is_file():
        raise ValidationError(f"light curve: file {path} does not exist")
    if path.suffix.lower() in (".nc", ".nc4", ".netcdf"):
        with xr.open_dataset(path, decode_times=True) as ds:
            ds = ds.load()
        if len(ds.dims) != 1:
            raise ValidationError(f"{path}: expected variables along one dimension, got dims {dict(ds.sizes)}")
        df = ds.reset_coords().to_dataframe().reset_index(drop=True)
        where = "netCDF record {}"
        offset = 0
    else:
        try:
            df = pd.read_csv(path, skipinitialspace=True, dtype=str, keep_default_na=False)
        except Exception as exc:  # pandas raises several types for malformed text
            raise ValidationError(f"{path}: cannot be read as CSV with a header: {exc}") from exc
        df.columns = [str(c).strip() for c in df.columns]
        where = "row {} (line {} of the file)"
        offset = 1
    cols = list(df.columns)
    missing = [c for c in LIGHT_CURVE_COLUMNS if c not in cols]
    absc = [c for c in LIGHT_CURVE_ABSCISSAE if c in cols]
    if missing:
        raise ValidationError(f"{path}: missing column(s) {missing}; required: band, magnitude, uncertainty "
                              f"and one of time, rotation_angle; found {cols}")
    if len(absc) != 1:
        raise ValidationError(f"{path}: need exactly one of the columns 'time' or 'rotation_angle', found "
                              f"{absc or 'neither'}")
    xname = absc[0]
    if len(df) == 0:
        raise ValidationError(f"{path}: no observations")

    def row_name(k: int) -> str:
        return where.format(k + 1, k + 1 + offset) if offset else where.format(k)

    def numeric(col: str) -> np.ndarray:
        v = pd.to_numeric(pd.Series(df[col]).astype(str).str.strip()
                          if df[col].dtype == object else df[col], errors="coerce").to_numpy(dtype=np.float64)
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            raise ValidationError(f"{path}: {row_name(int(bad[0]))}, column {col!r}: value "
                                  f"{df[col].iloc[bad[0]]!r} is not a finite number")
        return v

    mag = numeric("magnitude")
    unc = numeric("uncertainty")
    bad = np.flatnonzero(unc <= 0)
    if bad.size:
        raise ValidationError(f"{path}: {row_name(int(bad[0]))}, column 'uncertainty': must be > 0, got {unc[bad[0]]}")
    x_attrs: dict[str, Any]
    if xname == "time":
        raw = df["time"]
        if pd.api.types.is_datetime64_any_dtype(raw.dtype):
            tt = pd.to_datetime(raw, utc=True)
            x = None
        else:
            as_num = pd.to_numeric(raw.astype(str).str.strip(), errors="coerce")
            if as_num.notna().all():
                x = as_num.to_numpy(dtype=np.float64)
                tt = None
            else:
                tt = pd.to_datetime(raw.astype(str).str.strip(), utc=True, errors="coerce", format="ISO8601")
                x = None
        if x is None:
            nat = np.flatnonzero(tt.isna().to_numpy())
            if nat.size:
                raise ValidationError(f"{path}: {row_name(int(nat[0]))}, column 'time': value "
                                      f"{raw.iloc[nat[0]]!r} is neither a number of seconds nor an ISO 8601 time")
            origin = tt.iloc[0]
            x = (tt - origin).dt.total_seconds().to_numpy(dtype=np.float64)
            x_attrs = attrs("time_since_first", time_origin=origin.isoformat())
        else:
            x = numeric("time")
            x_attrs = attrs("time_since_first", long_name="observation time",
                            time_origin="as in the file (numeric seconds are kept unchanged)")
    else:
        x = numeric("rotation_angle")
        x_attrs = attrs("rotation_angle")
    back = np.flatnonzero(np.diff(x) < 0)
    if back.size:
        k = int(back[0]) + 1
        raise ValidationError(f"{path}: {row_name(k)}, column {xname!r}: values must be non-decreasing "
                              f"(sorted); it goes back from row {k} to row {k + 1}")
    band = [str(b).strip() for b in df["band"].tolist()]
    known = set(bands) if bands is not None else None
    for k, b in enumerate(band):
        ok = (b in known) if known is not None else (_canonical(b) in speclite_names())
        if not ok:
            allowed = sorted(known) if known is not None else f"aliases {list(BAND_ALIASES)} or speclite names"
            raise ValidationError(f"{path}: {row_name(k)}, column 'band': unknown band {b!r}; allowed: {allowed}")
    ds = xr.Dataset(
        {"magnitude": ("obs", mag, attrs("magnitude", long_name="measured magnitude")),
         "uncertainty": ("obs", unc, attrs("magnitude_uncertainty"))},
        coords={"obs": ("obs", np.arange(mag.size), attrs("obs")),
                BAND: ("obs", band, attrs(BAND)),
                xname: ("obs", x, x_attrs)})
    ds.attrs = {"source_file": str(path), "abscissa": xname}
    return ds


def _periodic_model_flux(angles: np.ndarray, flux: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Linear interpolation of a light curve periodic in 360 degrees."""
    return np.interp(np.mod(at, 360.0), np.mod(angles, 360.0), flux, period=360.0)


def compare_light_curves(
    measured: xr.Dataset,
    simulated_mags: xr.DataArray,
    *,
    fit_phase: bool = True,
    period_s: float | None = None,
    phase_angle: float | None = None,
    n_scan: int = 720,
) -> xr.Dataset:
    """Fit a simulated light curve to a measured one: magnitude and rotation-phase offsets.

    Model: ``m_meas,i = m_sim,b_i(theta_i + phi) + dm`` with the simulated curve
    interpolated linearly in flux, periodic in 360 degrees.  For a given ``phi`` the
    offset is the analytic weighted mean ``dm = sum w r / sum w`` (``w = 1/sigma**2``,
    ``r = m_meas - m_sim``), minimising ``chi2 = sum w (r - dm)**2``.  ``phi`` is found
    by a scan of ``n_scan`` equally spaced values over [0, 360) and a bounded Brent
    refinement within one scan step of the best; it is reported in [0, 360).
    Observations where the model reflects nothing (infinite magnitude) are excluded
    and counted.

    Parameters
    ----------
    measured : xarray.Dataset
        From :func:`read_light_curve`.
    simulated_mags : xarray.DataArray
        Magnitudes over ``attitude`` (with the coordinate ``attitude_angle`` [degree],
        a rotation sweep) and ``band`` (and optionally a ``phase_angle`` dim).
    fit_phase : bool
        Fit the rotation-phase offset (else ``phi = 0``).
    period_s : float, optional
        Rotation period [s], needed when ``measured`` is indexed by time:
        ``theta = 360 t / period_s``.
    phase_angle : float, optional
        Selects the simulated phase angle [degree] (nearest) when there are several.
    n_scan : int
        Number of scan points.

    Returns
    -------
    xarray.Dataset
        Over ``obs``: ``measured_magnitude``, ``uncertainty``, ``model_magnitude``
        (offsets applied), ``residual``, ``normalized_residual``; scalars
        ``magnitude_offset`` (+ ``magnitude_offset_uncertainty``), ``phase_offset``,
        ``chi_square``, ``reduced_chi_square``, ``degrees_of_freedom``, ``n_excluded``;
        over ``band``: ``band_mean_residual``; over ``colour``:
        ``colour_index_difference`` (measured minus simulated, consecutive bands);
        over ``phase_scan``: ``chi_square_scan``.
    """
    from scipy.optimize import minimize_scalar

    if not isinstance(measured, xr.Dataset) or "magnitude" not in measured or "uncertainty" not in measured:
        raise ValidationError("measured: expected a light-curve Dataset from read_light_curve")
    sim = _simulated_curve(simulated_mags, phase_angle)
    if "rotation_angle" in measured.coords:
        theta = np.asarray(measured["rotation_angle"].values, dtype=np.float64)
    elif "time" in measured.coords:
        if period_s is None or not np.isfinite(period_s) or period_s <= 0:
            raise ValidationError("period_s: the measured light curve is indexed by time; give the rotation "
                                  "period [s] (> 0) to convert it to rotation angle")
        theta = 360.0 * np.asarray(measured["time"].values, dtype=np.float64) / period_s
    else:
        raise ValidationError("measured: needs a 'rotation_angle' or 'time' coordinate")
    m_obs = np.asarray(measured["magnitude"].values, dtype=np.float64)
    sig = np.asarray(measured["uncertainty"].values, dtype=np.float64)
    sim_labels = [str(b) for b in sim[BAND].values]
    sim_filters = [str(f) for f in sim["filter"].values] if "filter" in sim.coords else sim_labels
    obs_band = [str(b) for b in measured[BAND].values]
    col = np.empty(len(obs_band), dtype=np.int64)
    for k, b in enumerate(obs_band):
        if b in sim_labels:
            col[k] = sim_labels.index(b)
        elif _canonical(b) in sim_filters:
            col[k] = sim_filters.index(_canonical(b))
        else:
            raise ValidationError(f"measured: observation {k} is in band {b!r}, which the simulation does "
                                  f"not have (bands {sim_labels})")
    angles = np.asarray(sim["attitude_angle"].values, dtype=np.float64)
    sim_m = np.asarray(sim.transpose(ATTITUDE, BAND).values, dtype=np.float64)
    with np.errstate(over="ignore"):
        flux = np.where(np.isfinite(sim_m), 10.0 ** (-0.4 * np.where(np.isfinite(sim_m), sim_m, 0.0)), 0.0)
    w = 1.0 / sig**2

    def model(phi: float) -> tuple[np.ndarray, np.ndarray]:
        f = np.empty(theta.size)
        for b in np.unique(col):
            sel = col == b
            f[sel] = _periodic_model_flux(angles, flux[:, b], theta[sel] + phi)
        ok = f > 0
        mm = np.full(theta.size, np.inf)
        mm[ok] = -2.5 * np.log10(f[ok])
        return mm, ok

    def fit(phi: float) -> tuple[float, float, np.ndarray, np.ndarray]:
        mm, ok = model(phi)
        if not ok.any():
            return np.inf, np.nan, mm, ok
        r = m_obs[ok] - mm[ok]
        dm = float(np.sum(w[ok] * r) / np.sum(w[ok]))
        return float(np.sum(w[ok] * (r - dm) ** 2)), dm, mm, ok

    scan = np.arange(n_scan) * (360.0 / n_scan)
    if fit_phase:
        chi_scan = np.array([fit(p)[0] for p in scan])
        if not np.isfinite(chi_scan).any():
            raise ValidationError("simulated_mags: the model reflects nothing at any measured angle")
        k = int(np.nanargmin(chi_scan))
        step = 360.0 / n_scan
        res = minimize_scalar(lambda p: fit(p)[0], bounds=(scan[k] - step, scan[k] + step), method="bounded",
                              options={"xatol": 1e-7})
        phi = float(res.x) if res.fun <= chi_scan[k] else float(scan[k])
        phi = float(np.mod(phi, 360.0))
    else:
        chi_scan = np.array([fit(p)[0] for p in scan])
        phi = 0.0
    chi2, dm, mm, ok = fit(phi)
    if not ok.any():
        raise ValidationError("simulated_mags: the model reflects nothing at any measured angle")
    # The best phase farther than 30 deg from the fitted one: a symmetric body (a cube
    # turning about an axis) fits nearly as well half a turn away.
    far = np.abs(((scan - phi + 180.0) % 360.0) - 180.0) > 30.0
    if fit_phase and np.isfinite(chi_scan[far]).any():
        k_alt = int(np.nanargmin(np.where(far, chi_scan, np.nan)))
        phi_alt, dchi_alt = float(scan[k_alt]), float(chi_scan[k_alt] - chi2)
    else:
        phi_alt, dchi_alt = np.nan, np.nan
    n_par = 2 if fit_phase else 1
    dof = int(ok.sum()) - n_par
    resid = np.where(ok, m_obs - (mm + dm), np.nan)
    labels_present = [lab for j, lab in enumerate(sim_labels) if np.any(col[ok] == j)]
    band_mean = []
    for lab in labels_present:
        sel = ok & (col == sim_labels.index(lab))
        band_mean.append(float(np.sum(w[sel] * resid[sel]) / np.sum(w[sel])))
    colours = [f"{a}-{b}" for a, b in pairwise(labels_present)]
    ci_diff = [band_mean[i] - band_mean[i + 1] for i in range(len(colours))]
    obs_coords = {("obs_band" if k == BAND else k): v for k, v in measured.coords.items()
                  if v.dims == ("obs",)}
    ds = xr.Dataset(
        {
            "measured_magnitude": ("obs", m_obs, attrs("magnitude", long_name="measured magnitude")),
            "uncertainty": ("obs", sig, attrs("magnitude_uncertainty")),
            "model_magnitude": ("obs", np.where(ok, mm + dm, np.inf),
                                attrs("magnitude", long_name="simulated magnitude with the fitted offsets")),
            "residual": ("obs", resid, attrs("magnitude", long_name="measured minus fitted simulated magnitude")),
            "normalized_residual": ("obs", resid / sig, {"units": "1", "long_name": "residual / uncertainty"}),
            "model_rotation_angle": ("obs", np.mod(theta + phi, 360.0),
                                     attrs("rotation_angle", long_name="simulated rotation angle matched to "
                                           "each observation (measured angle + phase offset, mod 360)")),
            "magnitude_offset": ((), dm, attrs("magnitude", long_name="fitted magnitude offset (measured - "
                                                "simulated), analytic weighted mean")),
            "magnitude_offset_uncertainty": ((), float(1.0 / np.sqrt(np.sum(w[ok]))),
                                             attrs("magnitude", long_name="1-sigma uncertainty of the "
                                                   "magnitude offset")),
            "phase_offset": ((), phi, attrs("rotation_angle", long_name="fitted rotation-phase offset "
                                            "(simulated angle = measured angle + offset), in [0, 360)")),
            "chi_square": ((), chi2, {"units": "1", "long_name": "chi-square of the fit"}),
            "alternative_phase_offset": ((), phi_alt, attrs("rotation_angle", long_name="best phase offset more "
                                                            "than 30 deg from the fitted one (scan resolution)")),
            "alternative_delta_chi_square": ((), dchi_alt, {"units": "1", "long_name": "chi-square at the "
                                                            "alternative phase minus the best; below ~4 the two "
                                                            "phases are not distinguished at 2 sigma"}),
            "degrees_of_freedom": ((), dof, {"units": "1", "long_name": "observations used minus fitted "
                                             "parameters"}),
            "reduced_chi_square": ((), chi2 / dof if dof > 0 else np.nan,
                                   {"units": "1", "long_name": "chi-square per degree of freedom"}),
            "n_excluded": ((), int((~ok).sum()), {"units": "1", "long_name": "observations where the model "
                                                  "reflects nothing (excluded)"}),
            "band_mean_residual": (BAND, np.array(band_mean),
                                   attrs("magnitude", long_name="weighted mean residual per band after the "
                                         "common offset")),
            "colour_index_difference": ("colour", np.array(ci_diff),
                                        attrs("colour_index", long_name="measured minus simulated colour index")),
            "chi_square_scan": ("phase_scan", chi_scan, {"units": "1", "long_name": "chi-square versus "
                                                         "trial phase offset"}),
        },
        coords={**obs_coords, BAND: (BAND, labels_present, attrs(BAND)),
                "colour": ("colour", colours, attrs("colour")),
                "phase_scan": ("phase_scan", scan, attrs("rotation_angle", long_name="trial phase offset"))},
    )
    ds.attrs = {"fit_phase": int(fit_phase), "title": "comparison of a measured and a simulated light curve",
                "model": "m_meas(theta) = m_sim(theta + phase_offset) + magnitude_offset",
                "abscissa": "rotation_angle" if "rotation_angle" in measured.coords
                else f"time converted with period_s = {period_s}"}
    return ds


def _simulated_curve(sim: xr.DataArray, phase_angle: float | None) -> xr.DataArray:
    if not isinstance(sim, xr.DataArray) or BAND not in sim.dims:
        raise ValidationError("simulated_mags: expected magnitudes over (attitude, band) from magnitudes()")
    if PHASE_ANGLE in sim.dims:
        if phase_angle is not None:
            sim = sim.sel({PHASE_ANGLE: phase_angle}, method="nearest")
        elif sim.sizes[PHASE_ANGLE] == 1:
            sim = sim.isel({PHASE_ANGLE: 0})
        else:
            raise ValidationError(f"phase_angle: the simulation has {sim.sizes[PHASE_ANGLE]} phase angles "
                                  f"{sim[PHASE_ANGLE].values.tolist()}; choose one")
    extra = [d for d in sim.dims if d not in (ATTITUDE, BAND)]
    if ATTITUDE not in sim.dims or extra:
        raise ValidationError(f"simulated_mags: expected dims (attitude, band), got {sim.dims}")
    if "attitude_angle" not in sim.coords:
        raise ValidationError("simulated_mags: needs the 'attitude_angle' coordinate of a rotation sweep")
    ang = np.mod(np.asarray(sim["attitude_angle"].values, dtype=np.float64), 360.0)
    if np.unique(ang).size != ang.size:
        raise ValidationError("simulated_mags: attitude angles repeat modulo 360 degree")
    return sim.load()


def plot_comparison(comparison: xr.Dataset, *, title: str | None = None) -> Any:
    """Figure of a :func:`compare_light_curves` result.

    Top: measured magnitudes (error bars) and the fitted simulated curve against the
    simulated rotation angle, per band; bottom: residuals.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.figure import Figure

    if not isinstance(comparison, xr.Dataset) or "residual" not in comparison:
        raise ValidationError("comparison: expected the Dataset returned by compare_light_curves")
    fig = Figure(figsize=(8, 6), layout="constrained")
    ax, axr = fig.subplots(2, 1, sharex=True, height_ratios=(3, 1))
    x = comparison["model_rotation_angle"].values
    bands = [str(b) for b in comparison[BAND].values]
    obs_band = np.asarray([str(b) for b in comparison["obs_band"].values])
    for b in bands:
        sel = obs_band == b
        order = np.argsort(x[sel])
        line = ax.errorbar(x[sel], comparison["measured_magnitude"].values[sel],
                           comparison["uncertainty"].values[sel], fmt="o", ms=3, label=f"{b} measured")
        ax.plot(x[sel][order], comparison["model_magnitude"].values[sel][order], "-",
                color=line[0].get_color(), label=f"{b} simulated")
        axr.plot(x[sel], comparison["residual"].values[sel], "o", ms=3, color=line[0].get_color())
    ax.invert_yaxis()
    ax.set_ylabel("magnitude [mag]")
    ax.legend(fontsize="small", ncol=2)
    axr.axhline(0.0, color="k", lw=0.8)
    axr.set_xlabel("simulated rotation angle [degree]")
    axr.set_ylabel("residual [mag]")
    ax.set_title(title or (f"offset {float(comparison.magnitude_offset):.3f} mag, phase "
                           f"{float(comparison.phase_offset):.2f} deg, reduced chi2 "
                           f"{float(comparison.reduced_chi_square):.2f}"))
    return fig

