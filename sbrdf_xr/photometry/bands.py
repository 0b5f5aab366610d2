"""Filter bands: the speclite registry, user bandpasses, band weights under sunlight."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from functools import cache
from importlib import resources
from importlib.metadata import version as _pkg_version
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from .._names import BAND, WAVELENGTH, attrs
from ..errors import ValidationError, renamed_attributes
from .colour_science import as_bands, as_spectrum
from .infrared import INFRARED_BANDS, band_curve
from .spectra import (
    _check_grid,
    _choose,
    _illumination,
    _integral,
    _solar_provenance,
    _weighting,
    hat_integrals,
    solar_name,
)

#: Short band names -> speclite filter names.  Bessell (1990, PASP 102, 1181) UBVRI
#: realise the Johnson-Cousins system; SDSS ugriz are the Doi et al. (2010, AJ 139,
#: 1628) reference responses through airmass 1.3 (the ``sdss2010noatm-*`` curves,
#: without the atmosphere, are available by their full name).
BAND_ALIASES: dict[str, str] = {
    "U": "bessell-U",
    "B": "bessell-B",
    "V": "bessell-V",
    "R": "bessell-R",
    "I": "bessell-I",
    "u": "sdss2010-u",
    "g": "sdss2010-g",
    "r": "sdss2010-r",
    "i": "sdss2010-i",
    "z": "sdss2010-z",
    "J": "twomass-J",
    "H": "twomass-H",
    "Ks": "twomass-Ks",
}

#: Spectral weightings of the band integral: name -> description.
WEIGHTINGS: dict[str, str] = {
    "photon": (
        "photon counting: F = int f T lambda/(h c) dlambda (T a photon-detection probability)"
    ),
    "energy": "energy weighting: F = int f T dlambda (T an energy response)",
}

#: Quadratures of :func:`band_weights`: name -> description.
QUADRATURES: dict[str, str] = {
    "trapezoid": "trapezoid rule on the given wavelength grid; the solar spectrum enters as its "
    "conservative (hat-weighted) average at each grid node, "
    "the filter and the weighting at the nodes",
    "linear": "the spectrum is taken as piecewise linear between the grid nodes and multiplied by "
    "solar spectrum x filter x weighting at their native resolution; exact for that interpolant "
    "up to the native sampling",
}

#: Allowed values of ``extrapolate`` (how a spectrum is continued past its grid into a band).
SPECTRUM_EXTRAPOLATIONS: dict[str | None, str] = {
    None: "no extrapolation: a spectrum that does not cover a band's support is an error",
    "zero": "the spectrum is zero beyond its grid (the band is truncated)",
    "constant": "the spectrum keeps its end values beyond its grid",
}

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


def _speclite_dir() -> Path:
    return Path(str(resources.files("speclite") / "data" / "filters"))


def speclite_names() -> list[str]:
    """Names of the filter curves shipped with speclite (``group-band``).

    Examples
    --------
    >>> names = speclite_names()
    >>> "bessell-V" in names, "sdss2010-r" in names
    (True, True)
    """
    return sorted(p.stem for p in _speclite_dir().glob("*.ecsv"))


@cache
def _speclite_band(name: str) -> tuple[np.ndarray, np.ndarray, str]:
    import speclite.filters

    if name in INFRARED_BANDS:  # boxes and WISE (sbrdf_xr.photometry.infrared)
        return band_curve(name)
    if name not in speclite_names():
        raise ValidationError(
            f"band: unknown {name!r}; use an alias ({', '.join(BAND_ALIASES)}) or a speclite "
            f"filter name (e.g. {', '.join(speclite_names()[:6])}, ...; see "
            "sbrdf_xr.photometry.speclite_names())"
        )
    f = speclite.filters.load_filter(name)
    wl = np.asarray(f.wavelength, dtype=np.float64) / 10.0  # speclite stores Angstrom
    resp = np.asarray(f.response, dtype=np.float64)
    desc = " ".join(str(f.meta.get("description", "")).split())
    src = (
        f"speclite {_pkg_version('speclite')} file speclite/data/filters/{name}.ecsv "
        f"({f.meta.get('url', '')}; airmass {f.meta.get('airmass', '?')}): {desc[:160]}"
    )
    wl.setflags(write=False)
    resp.setflags(write=False)
    return wl, resp, src


def _canonical(name: str) -> str:
    return BAND_ALIASES.get(name, name)


def _user_band(label: str, spec: Any) -> _Band:
    if isinstance(spec, xr.DataArray):
        if spec.dims != (WAVELENGTH,) or WAVELENGTH not in spec.coords:
            raise ValidationError(
                f"band {label!r}: a bandpass DataArray needs the single dim "
                f"'{WAVELENGTH}' with its coordinate, got dims {spec.dims}"
            )
        units = spec[WAVELENGTH].attrs.get("units", "nm")
        if units != "nm":
            raise ValidationError(f"band {label!r}: wavelength units must be 'nm', got {units!r}")
        wl, resp = spec[WAVELENGTH].values, spec.values
        src = spec.attrs.get("provenance", spec.attrs.get("source", "user-supplied bandpass"))
    else:
        try:
            wl, resp = spec
        except (TypeError, ValueError):
            raise ValidationError(
                f"band {label!r}: expected a DataArray or a (wavelength, response) "
                f"pair, got {type(spec).__name__}"
            ) from None
        src = "user-supplied bandpass"
    wl = _check_grid(wl, f"band {label!r} wavelength")
    resp = np.asarray(resp, dtype=np.float64)
    if resp.shape != wl.shape:
        raise ValidationError(
            f"band {label!r}: response shape {resp.shape} differs from wavelength {wl.shape}"
        )
    if wl.size < 2 or not np.all(np.isfinite(resp)) or np.any(resp < 0) or not np.any(resp > 0):
        raise ValidationError(
            f"band {label!r}: response must have >= 2 finite, non-negative values, not all zero"
        )
    return _Band(label, f"user:{label}", wl, resp, str(src))


def _resolve_bands(bands: Any) -> list[_Band]:
    """Normalise every accepted form of ``bands`` to a list of _Band."""
    bands = as_bands(bands)  # colour-science filters
    items: list[tuple[str, Any]] = []
    if isinstance(bands, str):
        items = [(bands, None)]
    elif isinstance(bands, xr.DataArray):
        if BAND in bands.dims:
            if set(bands.dims) != {BAND, WAVELENGTH}:
                raise ValidationError(
                    f"bands: a filter DataArray must have dims (band, wavelength), got {bands.dims}"
                )
            b = bands.transpose(BAND, WAVELENGTH)
            out = []
            for k, lab in enumerate(b[BAND].values.tolist()):
                row = b.isel({BAND: k}).drop_vars(BAND)
                band = _user_band(str(lab), row)
                filt = str(b["filter"].values[k]) if "filter" in b.coords else band.filter
                src = (
                    str(b["filter_source"].values[k])
                    if "filter_source" in b.coords
                    else band.source
                )
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
                raise ValidationError(
                    f"bands: cannot interpret {type(it).__name__} {it!r}; give a band "
                    "name, a (name, bandpass) pair or a named DataArray"
                )
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
        DataArray, or a ``(band, wavelength)`` DataArray from this function.  A
        colour-science ``SpectralDistribution`` (labelled by its name) or
        ``MultiSpectralDistributions`` (one band per label) serves as a bandpass
        anywhere (:mod:`~sbrdf_xr.photometry.colour_science`).
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

    Examples
    --------
    >>> f = filters(["V", "sdss2010-r"], wavelength=np.arange(400.0, 801.0, 100.0))
    >>> f.band.values.tolist(), f.dims
    (['V', 'sdss2010-r'], ('band', 'wavelength'))
    >>> np.round(f.sel(band="V").values, 3)
    array([0.   , 0.458, 0.359, 0.   , 0.   ])
    """
    bl = _resolve_bands(bands)
    if wavelength is None:
        wl = np.unique(np.concatenate([b.wavelength for b in bl]))
    else:
        wl = _check_grid(wavelength, "wavelength")
    resp = np.stack([np.interp(wl, b.wavelength, b.response, left=0.0, right=0.0) for b in bl])
    coords = _band_coords(bl)
    coords[WAVELENGTH] = (WAVELENGTH, wl, attrs(WAVELENGTH))
    return xr.DataArray(
        resp,
        dims=(BAND, WAVELENGTH),
        coords=coords,
        name="filter_response",
        attrs=attrs(
            "filter_response",
            response_convention="as shipped; speclite responses are photon-"
            "detection probabilities (photon-counting integrals use T lambda)",
        ),
    )


def _coverage_error(
    band: _Band, lo: float, hi: float, what: str, extra: str = ""
) -> ValidationError:
    blo, bhi = band.support
    return ValidationError(
        f"band {band.label!r} ({band.filter}) has non-zero response over "
        f"{blo:g}-{bhi:g} nm but the "
        f"{what} covers only {lo:g}-{hi:g} nm{extra}"
    )


def _band_rows(
    bl: list[_Band],
    t: np.ndarray,
    weighting: str,
    quadrature: str,
    extrapolate: str | None,
    solar: str = "astm_g173",
    transmission: Any = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Unnormalised weights (n_band, n_t) and the full-band solar integrals (n_band,)."""
    ws, es = _illumination(solar, transmission)
    rows = np.zeros((len(bl), t.size))
    full = np.zeros(len(bl))
    for n, band in enumerate(bl):
        blo, bhi = band.support
        if blo < ws[0] or bhi > ws[-1]:
            raise _coverage_error(band, ws[0], ws[-1], f"solar spectrum ({solar})")
        if (t[0] > blo or t[-1] < bhi) and extrapolate is None:
            raise _coverage_error(
                band,
                t[0],
                t[-1],
                "spectrum",
                "; pass extrapolate='zero' or 'constant' to continue the spectrum past its grid",
            )
        inside = lambda v, lo=blo, hi=bhi: v[(v > lo) & (v < hi)]  # noqa: E731
        g_grid = np.unique(
            np.concatenate([[blo, bhi], inside(ws), inside(band.wavelength), inside(t)])
        )
        g = (
            np.interp(g_grid, ws, es)
            * np.interp(g_grid, band.wavelength, band.response, left=0.0, right=0.0)
            * _weighting(g_grid, weighting)
        )
        if t.size == 1:
            if t[0] < blo or t[0] > bhi:
                raise _coverage_error(band, t[0], t[0], "spectrum")
            below, above, row = 0.0, 0.0, np.zeros(1)
            below = float(
                _integral(g_grid, g, g_grid[0], g_grid[-1])
            )  # all of it: constant spectrum
        else:
            below = float(_integral(g_grid, g, g_grid[0], t[0]))
            above = float(_integral(g_grid, g, t[-1], g_grid[-1]))
            if quadrature == "linear":
                row = hat_integrals(g_grid, g, t)
            else:
                e_hat = hat_integrals(ws, es, t)  # = trapezoid weight x conservative solar average
                row = (
                    e_hat
                    * np.interp(t, band.wavelength, band.response, left=0.0, right=0.0)
                    * _weighting(t, weighting)
                )
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
    solar: str = "astm_g173",
    transmission: xr.DataArray | None = None,
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
        How a spectrum continues past its grid (:data:`SPECTRUM_EXTRAPOLATIONS`).  By default
        a grid that does not cover a band's non-zero response raises.
    normalize : bool
        Divide each row by the full-band solar integral ``int E_sun T w dlambda``
        (computed with the same quadrature, continuing the Sun past the grid): then
        ``W @ x`` is the solar-weighted band mean of ``x`` in the units of ``x``, and
        ``W @ 1 = 1`` whenever the grid covers the band or ``extrapolate="constant"``.
    solar : str, colour.SpectralDistribution or xarray.DataArray
        Solar spectrum, a key of :data:`~sbrdf_xr.photometry.SOLAR_SPECTRA` or a spectrum
        at 1 AU [W m-2 nm-1] (:func:`~sbrdf_xr.photometry.spectra.solar_name`).
    transmission : xarray.DataArray, optional
        Atmospheric transmission over ``wavelength`` [1]
        (:func:`sbrdf_xr.photometry.atmosphere.transmission`), folded into the weights
        as ``E_sun * transmission``; default none (above the atmosphere).

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

    Examples
    --------
    >>> wl = np.arange(300.0, 1101.0, 5.0)
    >>> W = band_weights(["B", "V"], wl, normalize=True)
    >>> W.dims, np.round(W.sum("wavelength").values, 12)  # normalised: a flat spectrum is kept
    (('band', 'wavelength'), array([1., 1.]))
    >>> np.round(W.values @ np.full(wl.size, 0.3), 12)  # the band means of a flat 0.3
    array([0.3, 0.3])
    """
    _choose(weighting, WEIGHTINGS, "weighting")
    _choose(quadrature, QUADRATURES, "quadrature")
    _choose(extrapolate, SPECTRUM_EXTRAPOLATIONS, "extrapolate")
    t = _check_grid(wavelength, "wavelength")
    bl = _resolve_bands(bands)
    solar = solar_name(solar)
    rows, full = _band_rows(bl, t, weighting, quadrature, extrapolate, solar, transmission)
    if normalize:
        rows = rows / full[:, None]
        units = "1"
    else:
        units = "m-2 s-1" if weighting == "photon" else "W m-2"
    coords = _band_coords(bl)
    coords[WAVELENGTH] = (WAVELENGTH, t, attrs(WAVELENGTH))
    return xr.DataArray(
        rows,
        dims=(BAND, WAVELENGTH),
        coords=coords,
        name="band_weight",
        attrs=attrs(
            "band_weight",
            units=units,
            **_method_attrs(weighting, quadrature, extrapolate, solar, transmission),
            normalized=int(normalize),
        ),
    )


def _method_attrs(
    weighting: str,
    quadrature: str,
    extrapolate: str | None,
    solar: str = "astm_g173",
    transmission: Any = None,
) -> dict[str, Any]:
    out: dict[str, Any] = {
        "weighting": weighting,
        "weighting_description": WEIGHTINGS[weighting],
        "quadrature": quadrature,
        "quadrature_description": QUADRATURES[quadrature],
        "extrapolate": str(extrapolate),
        "extrapolate_description": SPECTRUM_EXTRAPOLATIONS[extrapolate],
        **_solar_provenance(solar),
    }
    if transmission is not None:
        out["atmosphere"] = str(
            transmission.attrs.get("model_description", "user transmission curve")
        )
        if "airmass" in transmission.attrs:
            out["airmass"] = float(transmission.attrs["airmass"])
    return out


def pre_integrate(
    table: xr.DataArray,
    bands: Any,
    *,
    weighting: str = "photon",
    quadrature: str = "trapezoid",
    extrapolate: str | None = None,
    normalize: bool = True,
    solar: str = "astm_g173",
    transmission: xr.DataArray | None = None,
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
    weighting, quadrature, extrapolate, solar, transmission
        See :func:`band_weights`.
    normalize : bool, default True
        Solar-weighted band means (same units as ``table``); ``False`` gives band
        fluxes per unit of ``table`` at 1 AU.

    Returns
    -------
    xarray.DataArray
        Same dims with ``band`` in place of ``wavelength``, same name and attrs
        (``units`` multiplied by the weight units when not normalised).

    Examples
    --------
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> table = lambertian(0.3, wavelength=np.arange(300.0, 1101.0, 10.0))
    >>> banded = pre_integrate(table, ["B", "V"])
    >>> banded.dims, np.round(float(banded.max()), 6)  # 0.3 / pi in every band
    (('theta_i', 'delta_theta', 'phi', 'band'), np.float64(0.095493))
    """
    table = as_spectrum(table)  # a colour-science spectrum
    if (
        not isinstance(table, xr.DataArray)
        or WAVELENGTH not in table.dims
        or WAVELENGTH not in table.coords
    ):
        raise ValidationError(
            f"table: expected a DataArray with a '{WAVELENGTH}' dimension and coordinate"
        )
    units = table[WAVELENGTH].attrs.get("units", "nm")
    if units != "nm":
        raise ValidationError(f"table: wavelength units must be 'nm', got {units!r}")
    w = band_weights(
        bands,
        table[WAVELENGTH].values,
        weighting=weighting,
        quadrature=quadrature,
        extrapolate=extrapolate,
        normalize=normalize,
        solar=solar,
        transmission=transmission,
    )
    w = w.astype(np.result_type(table.dtype, np.float32))
    dims = [BAND if d == WAVELENGTH else d for d in table.dims]
    out = xr.dot(
        table,
        w.drop_vars(WAVELENGTH).assign_coords({WAVELENGTH: table[WAVELENGTH]}),
        dim=WAVELENGTH,
    )
    out = out.transpose(*dims)
    out.name = table.name
    out.attrs = dict(table.attrs)
    if not normalize:
        tu = table.attrs.get("units", "1")
        out.attrs["units"] = w.attrs["units"] if tu == "1" else f"{tu} {w.attrs['units']}"
    out.attrs.update({k: v for k, v in w.attrs.items() if k not in ("units", "long_name")})
    out.attrs["band_integration"] = (
        "solar-weighted band mean" if normalize else "band flux at 1 AU per unit of the spectrum"
    )
    for c in ("filter", "filter_source"):
        out = out.assign_coords({c: w[c]})
    return out


#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(__name__, globals(), {"EXTRAPOLATIONS": "SPECTRUM_EXTRAPOLATIONS"})
