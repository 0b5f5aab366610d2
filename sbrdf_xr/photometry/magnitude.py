"""Magnitudes and colour indices of the reflected sunlight, from a cube or a spectrum."""

from __future__ import annotations

from collections.abc import Sequence
from itertools import pairwise
from typing import Any

import numpy as np
import xarray as xr

from .._names import BAND, WAVELENGTH, attrs
from ..errors import ValidationError, renamed_keywords
from ._observed import _distances, _with_extinction
from .bands import (
    WEIGHTINGS,
    _band_coords,
    _canonical,
    _coverage_error,
    _method_attrs,
    _resolve_bands,
    pre_integrate,
)
from .colour_science import as_spectrum
from .spectra import (
    MAGNITUDE_SYSTEMS,
    SOLAR_SPECTRA,
    _choose,
    _illumination,
    _integral,
    _weighting,
    check_system,
    reference_flux,
    reference_nodes,
)


def sun_magnitudes(
    bands: Any,
    *,
    weighting: str = "photon",
    system: str = "AB",
    solar: str = "astm_g173",
    transmission: xr.DataArray | None = None,
) -> xr.DataArray:
    """Apparent magnitudes of the Sun at 1 AU in each band.

    ``m_sun = -2.5 log10( int E_sun A T w dlambda / int f_ref T w dlambda )``, both
    integrals exact for the linear interpolants on the union of the solar, filter and
    reference-spectrum nodes (native resolution); ``f_ref`` is the zero-magnitude
    source of ``system`` (3631 Jy for AB, alpha Lyr for Vega) and ``A`` the
    atmospheric transmission (1 above the atmosphere).

    Parameters
    ----------
    bands : str, sequence, mapping or DataArray
        See :func:`filters`.
    weighting : {"photon", "energy"}
    system : {"AB", "Vega"}
        Any case (:data:`~sbrdf_xr.photometry.MAGNITUDE_SYSTEMS`).
    solar : str
        Solar spectrum (:data:`~sbrdf_xr.photometry.SOLAR_SPECTRA`).
    transmission : xarray.DataArray, optional
        Atmospheric transmission over ``wavelength`` [1] applied to the sunlight (not
        to the reference): the Sun observed through that atmosphere.

    Returns
    -------
    xarray.DataArray
        ``sun_magnitude`` over ``band`` [1, magnitudes], attrs ``magnitude_system``.

    Examples
    --------
    >>> np.round(sun_magnitudes(["B", "V"]).values, 3)  # AB, ASTM G173 Sun at 1 AU
    array([-26.243, -26.768])
    >>> np.round(sun_magnitudes(["V"], system="vega").values, 3)
    array([-26.774])
    """
    _choose(weighting, WEIGHTINGS, "weighting")
    system = check_system(system)
    ws, es = _illumination(solar, transmission)
    vn = reference_nodes(system)
    bl = _resolve_bands(bands)
    out = np.zeros(len(bl))
    for n, band in enumerate(bl):
        blo, bhi = band.support
        if blo < ws[0] or bhi > ws[-1]:
            raise _coverage_error(band, ws[0], ws[-1], f"solar spectrum ({solar})")

        def inside(v: np.ndarray, lo: float = blo, hi: float = bhi) -> np.ndarray:
            return v[(v > lo) & (v < hi)]

        grid = np.unique(
            np.concatenate([[blo, bhi], inside(ws), inside(band.wavelength), inside(vn)])
        )
        tw = np.interp(grid, band.wavelength, band.response, left=0.0, right=0.0) * _weighting(
            grid, weighting
        )
        sun = _integral(grid, np.interp(grid, ws, es) * tw, blo, bhi)
        ref = _integral(grid, reference_flux(system, grid) * tw, blo, bhi)
        out[n] = -2.5 * np.log10(sun / ref)
    return xr.DataArray(
        out,
        dims=(BAND,),
        coords=_band_coords(bl),
        name="sun_magnitude",
        attrs=attrs(
            "sun_magnitude",
            **_system_attrs(system),
            **_method_attrs(weighting, "linear", None, solar, transmission),
        ),
    )


def _system_attrs(system: str) -> dict[str, str]:
    return {"magnitude_system": system, "magnitude_system_description": MAGNITUDE_SYSTEMS[system]}


# ------------------------------------------------------------ from a cube


def _signal_of(cube: xr.Dataset | xr.DataArray, variable: str = "signal") -> xr.DataArray:
    cube = as_spectrum(cube)  # a colour-science spectrum, labelled along ``spectrum``
    if isinstance(cube, xr.Dataset):
        if variable not in cube:
            raise ValidationError(
                f"cube: no variable {variable!r}; has {sorted(map(str, cube.data_vars))}"
            )
        da = cube[variable]
    elif isinstance(cube, xr.DataArray):
        da = cube
    else:
        raise ValidationError(
            f"cube: expected an xarray Dataset or DataArray, got {type(cube).__name__}"
        )
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
    system: str = "AB",
    solar: str = "astm_g173",
    transmission: xr.DataArray | None = None,
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
    weighting, quadrature, extrapolate, solar, transmission
        See :func:`band_weights`.
    system : {"AB", "Vega"}
        System of the Sun's magnitudes carried in the coordinate ``sun_magnitude``.

    Returns
    -------
    xarray.DataArray
        ``band_signal`` with ``band`` in place of ``wavelength`` [m2 sr-1], lazy if the
        cube is, with the Sun's band magnitudes as coordinate ``sun_magnitude``.

    Examples
    --------
    >>> import xarray as xr
    >>> wl = np.arange(300.0, 1101.0, 10.0)
    >>> grey = np.full((2, wl.size), 0.1)  # 0.1 m2 sr-1 at every wavelength, two geometries
    >>> cube = xr.Dataset({"signal": (("geometry", "wavelength"), grey, {"units": "m2 sr-1"})},
    ...                   coords={"wavelength": ("wavelength", wl, {"units": "nm"})})
    >>> s = band_signal(cube, ["B", "V"])
    >>> s.dims, np.round(s.values, 12)  # a grey body keeps its signal in every band
    (('geometry', 'band'), array([[0.1, 0.1],
           [0.1, 0.1]]))
    """
    s = _signal_of(cube, variable)
    out = pre_integrate(
        s,
        bands,
        weighting=weighting,
        quadrature=quadrature,
        extrapolate=extrapolate,
        normalize=True,
        solar=solar,
        transmission=transmission,
    )
    sun = sun_magnitudes(
        bands, weighting=weighting, system=system, solar=solar, transmission=transmission
    )
    out = out.assign_coords(sun_magnitude=(BAND, sun.values, sun.attrs))
    out.name = "band_signal"
    out.attrs.update(attrs("band_signal", units=s.attrs.get("units", "m2 sr-1")))
    out.attrs.update(_system_attrs(sun.attrs["magnitude_system"]))
    return out


@renamed_keywords(range_km="range", sun_distance_au="sun_distance")
def magnitudes(
    cube: xr.Dataset | xr.DataArray,
    bands: Any = None,
    range: Any = None,
    *,
    system: str = "AB",
    sun_distance: Any = None,
    extinction: dict[str, float] | None = None,
    weighting: str = "photon",
    quadrature: str = "trapezoid",
    extrapolate: str | None = None,
    solar: str = "astm_g173",
    transmission: xr.DataArray | None = None,
) -> xr.DataArray:
    """Apparent magnitudes of the reflected sunlight.

    ``m = m_sun,band + 5 log10(r / 1 AU) - 2.5 log10(S_band / d**2)`` with ``d`` the
    observer range [m] (module docstring).  ``S_band = 0`` gives ``+inf`` (no
    warning), a negative ``S_band`` gives NaN.

    A cube of an observation records ``range`` [km] and ``sun_distance`` [au] (per time
    or scalar, coordinates or variables, converted from their ``units``): they are used
    unless ``range`` or ``sun_distance`` is given.  The attributes
    ``range_source`` and ``sun_distance_source`` say where each came from;
    ``range_override`` / ``sun_distance_override`` note an argument that replaced the
    cube's value, and which value that was.

    Parameters
    ----------
    cube : xarray.Dataset or DataArray
        A cube (or spectrum over ``wavelength``), or a :func:`band_signal` result
        (then ``bands`` is not needed).
    bands : str, sequence, mapping or DataArray
        See :func:`filters`.
    range : float, array_like, DataArray or astropy Quantity, optional
        Observer range [km], > 0; broadcast against the cube (a DataArray aligns by
        dims).  A Quantity of length is converted (``1e6 * u.m`` is 1000 km), any other
        Quantity refused.  Default the cube's ``range``; required if it has none.
    system : {"AB", "Vega"}
        Magnitude system, any case (:data:`~sbrdf_xr.photometry.MAGNITUDE_SYSTEMS`);
        recorded in the attribute ``magnitude_system``.  A :func:`band_signal` input
        must have been made in the same system.
    sun_distance : float, array_like, DataArray or astropy Quantity, optional
        Sun-object distance [AU], > 0 (e.g. :func:`sun_distance_au` of the
        observation times); broadcast like ``range``.  Default the cube's
        ``sun_distance``, else 1 AU.
    extinction : mapping, optional
        ``{band: k}`` [mag per airmass], >= 0, for every band: adds ``k X`` with ``X``
        the cube's ``airmass`` (first-order extinction; NaN where ``X`` is NaN, below
        the horizon).  A cube without ``airmass`` is refused.
    weighting, quadrature, extrapolate, solar, transmission
        See :func:`band_weights`.

    Returns
    -------
    xarray.DataArray
        ``magnitude`` [1] over the cube's dims with ``band`` in place of ``wavelength``.

    Examples
    --------
    >>> import xarray as xr
    >>> wl = np.arange(300.0, 1101.0, 10.0)
    >>> grey = np.full((2, wl.size), 0.1)  # 0.1 m2 sr-1 at every wavelength, two geometries
    >>> cube = xr.Dataset({"signal": (("geometry", "wavelength"), grey, {"units": "m2 sr-1"})},
    ...                   coords={"wavelength": ("wavelength", wl, {"units": "nm"})})
    >>> m = magnitudes(cube, ["B", "V"], range=1000.0)
    >>> m.dims, np.round(m.isel(geometry=0).values, 4)
    (('geometry', 'band'), array([6.257 , 5.7318]))
    >>> round(float(magnitudes(cube, ["V"], range=2000.0)[0, 0] - m[0, 1]), 6)  # 5 log10 2
    1.50515
    >>> import astropy.units as u
    >>> round(float(magnitudes(cube, ["V"], range=2e6 * u.m)[0, 0] - m[0, 1]), 6)  # 2000 km
    1.50515
    """
    system = check_system(system)
    d, r, notes = _distances(cube, range, sun_distance)
    if isinstance(cube, xr.DataArray) and BAND in cube.dims and "sun_magnitude" in cube.coords:
        sb = cube
        have = sb.attrs.get(
            "magnitude_system", sb["sun_magnitude"].attrs.get("magnitude_system", "AB")
        )
        if have != system:
            raise ValidationError(
                f"system: the band_signal was made in the {have} system, not {system}; "
                f"pass system={have!r} or recompute band_signal(..., system={system!r})"
            )
    else:
        if bands is None:
            raise ValidationError("bands: required unless a band_signal result is given")
        sb = band_signal(
            cube,
            bands,
            weighting=weighting,
            quadrature=quadrature,
            extrapolate=extrapolate,
            system=system,
            solar=solar,
            transmission=transmission,
        )
    m = _magnitudes_from(sb, d, r, system, notes)
    return m if extinction is None else _with_extinction(m, cube, extinction)


def _magnitudes_from(
    sb: xr.DataArray, d_m: Any, sun_distance_au: Any, system: str, notes: dict[str, str]
) -> xr.DataArray:
    ratio = sb / d_m**2
    pos = ratio > 0
    safe = xr.where(pos, ratio, 1.0)
    m = sb["sun_magnitude"] + 5.0 * np.log10(sun_distance_au) - 2.5 * np.log10(safe)
    m = xr.where(pos, m, xr.where(ratio == 0, np.inf, np.nan))
    m = m.transpose(*sb.dims, ...)
    m.name = "magnitude"
    m.attrs = attrs(
        "magnitude",
        **_system_attrs(system),
        weighting=sb.attrs.get("weighting", ""),
        note="+inf where the band signal is 0 (nothing reflects toward the observer); "
        "NaN where it is negative",
        formula="m = m_sun,band(1 AU) + 5 log10(r/AU) - 2.5 log10(S_band / d^2), d in m",
        **notes,
    )
    if not isinstance(sun_distance_au, xr.DataArray) and np.ndim(sun_distance_au) == 0:
        m.attrs["sun_distance_au"] = float(sun_distance_au)
    if not isinstance(d_m, xr.DataArray):
        d_arr = np.asarray(d_m)
        if d_arr.ndim == 0:
            m.attrs["range_km"] = float(d_arr) / 1e3
    return m


def colour_indices(
    mags: xr.DataArray, pairs: Sequence[tuple[str, str]] | None = None
) -> xr.DataArray:
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

    Examples
    --------
    >>> import xarray as xr
    >>> wl = np.arange(300.0, 1101.0, 10.0)
    >>> grey = np.full((2, wl.size), 0.1)  # 0.1 m2 sr-1 at every wavelength, two geometries
    >>> cube = xr.Dataset({"signal": (("geometry", "wavelength"), grey, {"units": "m2 sr-1"})},
    ...                   coords={"wavelength": ("wavelength", wl, {"units": "nm"})})
    >>> ci = colour_indices(magnitudes(cube, ["B", "V", "R"], range=1000.0))
    >>> ci.colour.values.tolist(), np.round(ci.isel(geometry=0).values, 4)  # the Sun's AB colours
    (['B-V', 'V-R'], array([0.5252, 0.1944]))
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
    first = first.drop_vars([c for c in first.coords if BAND in first[c].dims]).rename(
        {BAND: "colour"}
    )
    second = second.drop_vars([c for c in second.coords if BAND in second[c].dims]).rename(
        {BAND: "colour"}
    )
    ok = np.isfinite(first) & np.isfinite(second)
    ci = xr.where(ok, xr.where(ok, first, 0.0) - xr.where(ok, second, 0.0), np.nan)
    names = [f"{a}-{b}" for a, b in pairs]
    ci = ci.assign_coords(
        colour=("colour", names, attrs("colour")),
        first=(
            "colour",
            [labels[i] for i in idx[0]],
            {"long_name": "band of the first magnitude of the colour index"},
        ),
        second=(
            "colour",
            [labels[i] for i in idx[1]],
            {"long_name": "band of the magnitude subtracted in the colour index"},
        ),
    )
    dims = [("colour" if d == BAND else d) for d in mags.dims]
    ci = ci.transpose(*dims)
    ci.name = "colour_index"
    ci.attrs = attrs(
        "colour_index",
        magnitude_system=mags.attrs.get("magnitude_system", "AB"),
        note="NaN where either magnitude is infinite (nothing reflects) or NaN",
    )
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


@renamed_keywords(range_km="range", sun_distance_au="sun_distance")
def photometry(
    cube: xr.Dataset | xr.DataArray,
    bands: Any,
    range: Any = None,
    *,
    pairs: Sequence[tuple[str, str]] | None = None,
    system: str = "AB",
    sun_distance: Any = None,
    extinction: dict[str, float] | None = None,
    weighting: str = "photon",
    quadrature: str = "trapezoid",
    extrapolate: str | None = None,
    solar: str = "astm_g173",
    transmission: xr.DataArray | None = None,
) -> xr.Dataset:
    """Band signal, magnitudes and colour indices of a cube, as one Dataset.

    The other parameters are those of :func:`band_signal`, :func:`magnitudes` and
    :func:`colour_indices`.  Also ``ds.sbrdf.photometry(bands=..., range=...)``.

    Parameters
    ----------
    cube : xarray.Dataset or DataArray
        A cube (or spectrum over ``wavelength``).
    bands : str, sequence, mapping or DataArray
        See :func:`filters`.
    range : float, array_like, DataArray or astropy Quantity, optional
        Observer range [km], > 0; default the cube's ``range`` (see :func:`magnitudes`).
    sun_distance : float, array_like, DataArray or astropy Quantity, optional
        Sun-object distance [AU], > 0; default the cube's ``sun_distance``, else 1 AU.

    Returns
    -------
    xarray.Dataset
        ``band_signal`` [m2 sr-1], ``magnitude`` [mag], ``colour_index`` [mag] (when
        there are two bands or more), with the cube's coordinates.

    Examples
    --------
    >>> import xarray as xr
    >>> wl = np.arange(300.0, 1101.0, 10.0)
    >>> grey = np.full((2, wl.size), 0.1)  # 0.1 m2 sr-1 at every wavelength, two geometries
    >>> cube = xr.Dataset({"signal": (("geometry", "wavelength"), grey, {"units": "m2 sr-1"})},
    ...                   coords={"wavelength": ("wavelength", wl, {"units": "nm"})})
    >>> ph = photometry(cube, ["B", "V"], 1000.0)
    >>> sorted(ph.data_vars), ph.attrs["magnitude_system"]
    (['band_signal', 'colour_index', 'magnitude'], 'AB')
    """
    system = check_system(system)
    d, r, notes = _distances(cube, range, sun_distance)
    sb = band_signal(
        cube,
        bands,
        weighting=weighting,
        quadrature=quadrature,
        extrapolate=extrapolate,
        system=system,
        solar=solar,
        transmission=transmission,
    )
    m = _magnitudes_from(sb, d, r, system, notes)
    if extinction is not None:
        m = _with_extinction(m, cube, extinction)
    out = {"band_signal": sb, "magnitude": m}
    if sb.sizes[BAND] > 1 or pairs:
        out["colour_index"] = colour_indices(m, pairs)
    ds = xr.Dataset(out)
    src = cube.attrs if isinstance(cube, xr.Dataset) else {}
    range_text = notes["range_source"]
    ds.attrs = {
        "Conventions": "CF-1.10",
        "title": f"sbrdf_xr photometry of {src.get('title', 'a spectrum')}",
        "source": src.get("source", "sbrdf_xr"),
        "history": f"sbrdf_xr.photometry(bands={[str(b) for b in sb[BAND].values]}, "
        f"range: {range_text}, "
        f"system={system}, weighting={weighting}, quadrature={quadrature}, "
        f"extrapolate={extrapolate}, solar={solar})",
        "references": "AB: Oke & Gunn 1983, ApJ 266, 713; Vega: CALSPEC alpha_lyr_stis_011, "
        "Bohlin et al. 2020, AJ 160, 21; filters: speclite (Bessell 1990, PASP 102, 1181; "
        f"Doi et al. 2010, AJ 139, 1628); Sun: {SOLAR_SPECTRA[solar]}",
        **_system_attrs(system),
        **_method_attrs(weighting, quadrature, extrapolate, solar, transmission),
    }
    if "sun_distance_au" in m.attrs:
        ds.attrs["sun_distance_au"] = m.attrs["sun_distance_au"]
    if "range_km" in m.attrs:
        ds.attrs["range_km"] = m.attrs["range_km"]
    for k, v in m.attrs.items():
        if k.endswith(("_source", "_override")) or k.startswith("extinction"):
            ds.attrs[k] = v
    return ds
