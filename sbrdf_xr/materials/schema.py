"""The material schema: a spectral BRDF table and a measurement set as xarray objects.

:func:`validate_material`, :func:`new_material` (and its constant and Lambertian
forms) and :func:`validate_measurements` state and check the data model of
paper 000 §3.2 that :mod:`sbrdf_xr.materials.tables` (look-up and construction),
:mod:`sbrdf_xr.materials.models` and :mod:`sbrdf_xr.materials.files` share.
"""

from __future__ import annotations

import json
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from .._names import (
    ANISO_LUT_DIMS,
    DEGREE,
    DELTA_THETA,
    LUT_DIMS,
    MEASURED,
    NM,
    PER_SR,
    PHI,
    PSI,
    SAMPLE,
    SBRDF,
    THETA_I,
    WAVELENGTH,
    attrs,
)
from ..errors import NonPhysicalWarning, ValidationError
from ..units import check_wavelengths, to_unit
from .coverage import snap_angles

#: Tests that an array's values were checked already (finite, non-negative), so that
#: :func:`validate_material` need not read them: a table memory-mapped from the table
#: cache, checked when its file was written (registered by :mod:`sbrdf_xr.materials.mapped`).
VALUES_CHECKED: list[Callable[[Any], bool]] = []

__all__ = [
    "DUPLICATES",
    "SOURCES",
    "average_duplicates",
    "check_coord",
    "constant_material",
    "lambertian",
    "new_material",
    "reference_mask",
    "validate_material",
    "validate_measurements",
]

SOURCES = ("measured", "synthetic")
_UNITS = {THETA_I: DEGREE, DELTA_THETA: DEGREE, PHI: DEGREE, PSI: DEGREE, WAVELENGTH: NM}


# ------------------------------------------------------------------ schema


def _check_source(source: str) -> None:
    if source not in SOURCES and not str(source).startswith("model:"):
        raise ValidationError(
            f"source: got {source!r}; allowed: 'measured', 'synthetic' or 'model:<name>'"
        )


def check_coord(name: str, values: np.ndarray, *, strict: bool = True) -> None:
    """Check a 1-D coordinate of a table or measurement set.

    Parameters
    ----------
    name : str
        Name of the coordinate, for messages.
    values : ndarray
        Its values.
    strict : bool, default True
        Also require strictly increasing values.

    Raises
    ------
    ValidationError
        If the coordinate is not 1-D, is empty, has a non-finite or non-numeric value,
        or (``strict``) does not increase strictly.

    Examples
    --------
    >>> import numpy as np
    >>> check_coord("theta_i", np.array([0.0, 10.0, 20.0]))
    >>> check_coord("theta_i", np.array([0.0, 20.0, 10.0]))
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.ValidationError: theta_i: coordinate must be strictly increasing; ...
    """
    if values.ndim != 1:
        raise ValidationError(f"{name}: coordinate must be 1-D, got shape {values.shape}")
    if values.size == 0:
        raise ValidationError(f"{name}: coordinate is empty")
    if not np.issubdtype(values.dtype, np.number) or not np.all(np.isfinite(values)):
        raise ValidationError(f"{name}: coordinate must be finite numbers")
    if strict and np.any(np.diff(values) <= 0):
        bad = int(np.flatnonzero(np.diff(values) <= 0)[0])
        raise ValidationError(
            f"{name}: coordinate must be strictly increasing; "
            f"{values[bad]!r} is followed by {values[bad + 1]!r} at index {bad + 1}"
        )


def validate_material(da: xr.DataArray, *, check_values: bool = True) -> xr.DataArray:
    """Check that ``da`` is a valid material look-up table.

    Parameters
    ----------
    da : xarray.DataArray
        Candidate table.
    check_values : bool, default True
        Also check that every value is finite and non-negative (loads the values;
        tables are small).

    Returns
    -------
    xarray.DataArray
        ``da`` with its dims in the canonical order ``(theta_i, delta_theta, phi,
        wavelength)`` (a transpose, never a change of values; a table whose data is an
        astropy Quantity is converted to sr-1, another kind raises
        :class:`~sbrdf_xr.errors.UnitError`); an anisotropic table
        (:mod:`sbrdf_xr.geometry.anisotropy`) has the dims ``(theta_i, delta_theta, phi, psi,
        wavelength)``, ``psi`` strictly increasing in ``[0, 180]`` degree.

    Raises
    ------
    ValidationError
        Naming the first problem found: wrong type or dims, missing or
        non-monotonic coordinates, wrong units, angles out of their domain, NaN or
        negative values.

    Examples
    --------
    A table with its dims in another order comes back in the canonical order:

    >>> from sbrdf_xr.materials.schema import lambertian, validate_material
    >>> table = lambertian(0.5, [500.0, 600.0])
    >>> validate_material(table.transpose("wavelength", "phi", "delta_theta", "theta_i")).dims
    ('theta_i', 'delta_theta', 'phi', 'wavelength')
    >>> validate_material(table.rename(phi="azimuth"))
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.ValidationError: material: dims must be (...), got (..., 'azimuth', ...)
    """
    if not isinstance(da, xr.DataArray):
        raise ValidationError(f"material: expected an xarray.DataArray, got {type(da).__name__}")
    da = to_unit(da, PER_SR, "material")  # a table holding a Quantity: in sr-1
    dims = ANISO_LUT_DIMS if PSI in da.dims else LUT_DIMS
    if set(da.dims) != set(dims) or len(da.dims) != len(dims):
        raise ValidationError(
            f"material: dims must be {LUT_DIMS} (or {ANISO_LUT_DIMS} for an anisotropic "
            f"table), got {da.dims}"
        )
    da = da.transpose(*dims)
    for dim in dims:
        if dim not in da.coords:
            raise ValidationError(f"{dim}: coordinate is missing")
        check_coord(dim, np.asarray(da[dim].values))
        units = da[dim].attrs.get("units")
        if units != _UNITS[dim]:
            raise ValidationError(f"{dim}: units must be {_UNITS[dim]!r}, got {units!r}")
    if da.attrs.get("units") != PER_SR:
        raise ValidationError(f"sbrdf: units must be {PER_SR!r}, got {da.attrs.get('units')!r}")
    ti = da[THETA_I].values
    if ti[0] < 0 or ti[-1] > 90:
        raise ValidationError(f"theta_i: must lie in [0, 90] degree, got [{ti[0]}, {ti[-1]}]")
    ph = da[PHI].values
    if ph[0] < 0 or ph[-1] > 90:
        raise ValidationError(f"phi: must lie in [0, 90] degree, got [{ph[0]}, {ph[-1]}]")
    if PSI in da.dims:
        ps = da[PSI].values
        if ps[0] < 0 or ps[-1] > 180:
            raise ValidationError(f"psi: must lie in [0, 180] degree, got [{ps[0]}, {ps[-1]}]")
    if da[WAVELENGTH].values[0] <= 0:
        raise ValidationError("wavelength: must be positive")
    check_wavelengths(da[WAVELENGTH].values, "wavelength")
    _check_delta_theta(da[DELTA_THETA].values)
    if "source" in da.attrs:
        _check_source(da.attrs["source"])
    _check_float(da, SBRDF)
    if check_values and not any(checked(da.variable.data) for checked in VALUES_CHECKED):
        v = np.asarray(da.values)
        if not np.all(np.isfinite(v)):
            raise ValidationError(
                f"sbrdf: contains {int(np.sum(~np.isfinite(v)))} NaN or infinite values"
            )
        if np.any(v < 0):
            raise ValidationError(
                f"sbrdf: contains {int(np.sum(v < 0))} negative values (min {v.min():.3g}); "
                "a BRDF is >= 0"
            )
    return da


def new_material(
    values: ArrayLike,
    theta_i: ArrayLike,
    delta_theta: ArrayLike,
    phi: ArrayLike,
    wavelength: ArrayLike,
    *,
    material: str,
    source: str,
    provenance: str,
    **parameters: Any,
) -> xr.DataArray:
    """Build a validated material ``DataArray`` from plain arrays.

    Parameters
    ----------
    values : array_like, shape (n_theta_i, n_delta_theta, n_phi, n_wavelength)
        sBRDF [sr-1].
    theta_i, delta_theta, phi : array_like
        Strictly increasing coordinates [degree].
    wavelength : array_like
        Strictly increasing vacuum wavelengths [nm].
    material : str
        Material name.
    source : str
        ``measured``, ``synthetic`` or ``model:<name>``.
    provenance : str
        Where the numbers come from.
    **parameters
        Construction parameters stored as attributes (numbers, strings, or
        sequences of numbers; anything else is stored as JSON text).

    Returns
    -------
    xarray.DataArray

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials.schema import new_material
    >>> table = new_material(
    ...     np.full((2, 3, 2, 1), 0.1),
    ...     theta_i=[0.0, 90.0], delta_theta=[-90.0, 0.0, 90.0], phi=[0.0, 90.0],
    ...     wavelength=[550.0], material="grey", source="synthetic", provenance="an example",
    ... )
    >>> dict(table.sizes)
    {'theta_i': 2, 'delta_theta': 3, 'phi': 2, 'wavelength': 1}
    >>> table.attrs["units"], table.attrs["material"]
    ('sr-1', 'grey')
    """
    values = to_unit(values, PER_SR, "values")
    _check_source(source)
    coords = {
        name: (name, np.asarray(to_unit(v, unit, name, spectral=unit == NM), float), attrs(name))
        for name, v, unit in (
            (THETA_I, theta_i, DEGREE),
            (DELTA_THETA, delta_theta, DEGREE),
            (PHI, phi, DEGREE),
            (WAVELENGTH, wavelength, NM),
        )
    }
    a = attrs(SBRDF, material=material, source=source, provenance=provenance)
    a.update({k: _attr_value(v) for k, v in parameters.items()})
    v = np.asarray(values)
    v = v.astype(np.float64) if np.issubdtype(v.dtype, np.integer) else v
    da = xr.DataArray(v, dims=LUT_DIMS, coords=coords, name=SBRDF, attrs=a)
    return validate_material(da)


#: Grids of a constant table: two nodes per axis spanning every lit-and-visible geometry.
_CONSTANT_GRIDS = (np.array([0.0, 90.0]), np.array([-180.0, 90.0]), np.array([0.0, 90.0]))


def constant_material(
    value: ArrayLike,
    wavelength: ArrayLike,
    *,
    material: str,
    provenance: str = "",
    source: str = "synthetic",
    **parameters: Any,
) -> xr.DataArray:
    """A table whose sBRDF is the same spectrum at every geometry.

    Two nodes per angular axis spanning the whole lit-and-visible hemisphere
    (``theta_i`` 0-90, ``delta_theta`` -180..90, ``phi`` 0-90 deg), all equal, so every
    look-up method (``nearest``, ``linear``, ``cubic``: weights that sum to one)
    returns ``value`` exactly at every geometry.

    Parameters
    ----------
    value : array_like, scalar or shape (n_wavelength,)
        sBRDF [sr-1], >= 0.
    wavelength : array_like
        Strictly increasing wavelengths [nm] (a scalar gives a one-wavelength table).
    material : str
        Name.
    provenance, source : str
        Attributes (see :func:`new_material`).
    **parameters
        Further attributes.

    Returns
    -------
    xarray.DataArray

    Examples
    --------
    >>> from sbrdf_xr.materials.schema import constant_material
    >>> table = constant_material([0.1, 0.2], [500.0, 600.0], material="flat")
    >>> table.shape, table.attrs["source"]
    ((2, 2, 2, 2), 'synthetic')
    >>> table.sel(wavelength=600.0).values.ravel().tolist()
    [0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2]
    """
    value = to_unit(value, PER_SR, "value")
    wl = np.atleast_1d(np.asarray(to_unit(wavelength, NM, WAVELENGTH, spectral=True), float))
    v = np.asarray(value, dtype=np.float64)
    if v.ndim > 1 or (v.ndim == 1 and v.size not in (1, wl.size)):
        raise ValidationError(
            f"value: expected a scalar or one value per wavelength ({wl.size}), got shape {v.shape}"
        )
    spec = np.broadcast_to(v, wl.shape)
    grids = _CONSTANT_GRIDS
    vals = np.broadcast_to(spec, (2, 2, 2, wl.size)).copy()
    return new_material(
        vals,
        *grids,
        wl,
        material=material,
        source=source,
        provenance=provenance or "constant sBRDF at every geometry",
        normal_incidence="symmetric",
        normal_incidence_blend=0.0,
        **parameters,
    )


def lambertian(
    albedo: ArrayLike, wavelength: ArrayLike, *, material: str | None = None
) -> xr.DataArray:
    """An ideal Lambertian (perfectly diffuse) material: ``f_r = albedo / pi`` everywhere.

    Exact for every look-up method (:func:`constant_material`); its
    directional-hemispherical reflectance is ``albedo`` at every incidence angle
    (paper 001 §2: a perfectly diffuse, 100 % reflecting sample has a BRDF of
    ``1/pi`` sr-1).

    Parameters
    ----------
    albedo : array_like, scalar or shape (n_wavelength,)
        Directional-hemispherical reflectance [1], ``0 <= albedo <= 1``.
    wavelength : array_like
        Wavelengths [nm].
    material : str, optional
        Name; default ``lambertian-<albedo>`` for a scalar albedo, ``lambertian``
        otherwise.

    Returns
    -------
    xarray.DataArray

    Examples
    --------
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> grey = lambertian(0.5, [500.0, 600.0])
    >>> grey.attrs["material"], round(float(grey.max()), 6)
    ('lambertian-0.5', 0.159155)
    """
    from ..brdf import lambert

    wl = np.atleast_1d(np.asarray(to_unit(wavelength, NM, WAVELENGTH, spectral=True), float))
    rho = lambert.check_params(wl, rho=albedo)["rho"]
    alb = np.asarray(albedo, dtype=np.float64)
    scalar = alb.ndim == 0
    name = material or (f"lambertian-{float(alb):g}" if scalar else "lambertian")
    return constant_material(
        rho / np.pi,
        wl,
        material=name,
        source="model:lambert",
        provenance=(
            "ideal Lambertian reflector, f_r = albedo / pi "
            f"({'albedo ' + format(float(alb), 'g') if scalar else 'spectral albedo'})"
        ),
        model="lambert",
        albedo=float(alb) if scalar else rho,
    )


def _attr_value(v: Any) -> Any:
    """netCDF-storable form of an attribute value (bools and containers as JSON)."""
    if isinstance(v, bool) or v is None or isinstance(v, dict):
        return json.dumps(v)
    if isinstance(v, str | int | float | np.number):
        return v
    arr = np.asarray(v)
    if arr.ndim == 1 and np.issubdtype(arr.dtype, np.number):
        return arr
    return json.dumps(v, default=str)


# ------------------------------------------------------------------ lookup


#: Policies for repeated measurement geometries (:func:`validate_measurements`).
DUPLICATES = ("error", "mean")


def _geometry_groups(ds: xr.Dataset) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Group samples by geometry (angles within
    :data:`~sbrdf_xr.materials.coverage.ANGLE_TOL` are equal): the group of every sample,
    the first sample of every group and the group sizes."""
    key = np.stack([snap_angles(ds[d].values) for d in (THETA_I, DELTA_THETA, PHI)], axis=1)
    _, first, groups, counts = np.unique(
        key, axis=0, return_index=True, return_inverse=True, return_counts=True
    )
    return groups.ravel(), first, counts


def average_duplicates(ds: xr.Dataset) -> xr.Dataset:
    """One sample per geometry: the mean spectrum of its measured (non-reference) repeats;
    a reference point only if every repeat is one.

    Parameters
    ----------
    ds : xarray.Dataset
        A measurement set (see :func:`validate_measurements`).

    Returns
    -------
    xarray.Dataset
        ``ds`` itself if no geometry repeats, else the set with one sample per geometry,
        in the order of each geometry's first sample.

    Examples
    --------
    >>> import xarray as xr
    >>> from sbrdf_xr.testing import make_measurements
    >>> ds = make_measurements(n_wavelength=3, theta_i=(10.0, 40.0))
    >>> twice = xr.concat([ds, ds.isel(sample=[0])], "sample")
    >>> once = average_duplicates(twice)
    >>> twice.sizes["sample"] - ds.sizes["sample"], once.sizes["sample"] == ds.sizes["sample"]
    (1, True)
    """
    groups, first, counts = _geometry_groups(ds)
    if np.all(counts == 1):
        return ds
    ref = reference_mask(ds)
    spectra = np.asarray(ds[MEASURED].transpose(SAMPLE, WAVELENGTH).values, dtype=np.float64)
    n_meas = np.bincount(groups, weights=(~ref).astype(float), minlength=first.size)
    total = np.zeros((first.size, spectra.shape[1]))
    np.add.at(total, groups[~ref], spectra[~ref])
    mean = total / np.maximum(n_meas, 1.0)[:, None]
    order = np.sort(first)
    pos = np.searchsorted(order, first)  # group -> position of its first sample
    out = ds.isel({SAMPLE: order}).copy()
    out[MEASURED] = (
        (SAMPLE, WAVELENGTH),
        np.empty((order.size, spectra.shape[1])),
        ds[MEASURED].attrs,
    )
    out[MEASURED].values[pos] = mean
    out["reference"] = (SAMPLE, np.zeros(order.size, dtype=bool), attrs("reference"))
    out["reference"].values[pos] = n_meas == 0
    out.attrs["duplicates"] = f"mean of repeated geometries ({int(np.sum(counts > 1))} averaged)"
    return out


def validate_measurements(ds: xr.Dataset, *, duplicates: str = "error") -> xr.Dataset:
    """Check a goniospectrometer measurement set.

    Schema: dims ``sample`` and ``wavelength``; a data variable ``measured_sbrdf``
    ``(sample, wavelength)`` [sr-1]; coordinates ``theta_i``, ``delta_theta``,
    ``phi`` over ``sample`` [degree] and ``wavelength`` [nm]; an optional boolean
    ``reference`` over ``sample`` marking the reference points of paper 000 §3.1
    (where the reflectance is indistinguishable from noise and is taken as zero;
    their spectra are ignored and treated as zero).

    Parameters
    ----------
    ds : xarray.Dataset
        Candidate measurement set.
    duplicates : {"error", "mean"}, default "error"
        A geometry measured more than once is an error naming it (``"error"``),
        or allowed (``"mean"``: :func:`build_lut` averages the repeats).

    Returns
    -------
    xarray.Dataset
        ``ds`` unchanged.

    Raises
    ------
    ValidationError
        Naming the first problem found.

    Examples
    --------
    >>> from sbrdf_xr.materials.schema import validate_measurements
    >>> from sbrdf_xr.testing import make_measurements
    >>> meas = make_measurements(n_wavelength=3, theta_i=(20.0, 50.0))
    >>> validate_measurements(meas) is meas
    True
    >>> dict(meas.sizes), int(meas.reference.sum())
    ({'sample': 60, 'wavelength': 3}, 18)
    >>> validate_measurements(meas.drop_vars("measured_sbrdf"))
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.ValidationError: measurements: ...
    """
    if not isinstance(ds, xr.Dataset):
        raise ValidationError(f"measurements: expected an xarray.Dataset, got {type(ds).__name__}")
    if MEASURED not in ds:
        raise ValidationError(f"measurements: lacks the data variable {MEASURED!r}")
    da = ds[MEASURED]
    if set(da.dims) != {SAMPLE, WAVELENGTH}:
        raise ValidationError(f"{MEASURED}: dims must be ('sample', 'wavelength'), got {da.dims}")
    if da.attrs.get("units") != PER_SR:
        raise ValidationError(
            f"{MEASURED}: units must be {PER_SR!r}, got {da.attrs.get('units')!r}"
        )
    if ds.sizes[SAMPLE] == 0:
        raise ValidationError("measurements: the set is empty (no samples)")
    for name in (THETA_I, DELTA_THETA, PHI):
        if name not in ds.coords and name not in ds:
            raise ValidationError(f"{name}: coordinate over 'sample' is missing")
        c = ds[name]
        if c.dims != (SAMPLE,):
            raise ValidationError(f"{name}: must be over ('sample',), got {c.dims}")
        check_coord(name, np.asarray(c.values), strict=False)
        if c.attrs.get("units") != DEGREE:
            raise ValidationError(f"{name}: units must be 'degree', got {c.attrs.get('units')!r}")
    if WAVELENGTH not in ds.coords:
        raise ValidationError("wavelength: coordinate is missing")
    check_coord(WAVELENGTH, np.asarray(ds[WAVELENGTH].values))
    check_wavelengths(ds[WAVELENGTH].values, "wavelength")
    if ds[WAVELENGTH].attrs.get("units") != NM:
        raise ValidationError(
            f"wavelength: units must be 'nm', got {ds[WAVELENGTH].attrs.get('units')!r}"
        )
    ti = ds[THETA_I].values
    if np.any((ti < 0) | (ti >= 90)):
        raise ValidationError("theta_i: measured incidence angles must lie in [0, 90) degree")
    ph = ds[PHI].values
    if np.any((ph < 0) | (ph > 180)):
        raise ValidationError(
            f"phi: must lie in [0, 180] degree (unsigned angle from the illumination plane), "
            f"got [{ph.min():g}, {ph.max():g}]"
        )
    _check_delta_theta(ds[DELTA_THETA].values)
    _check_float(da, MEASURED)
    if duplicates not in DUPLICATES:
        raise ValidationError(f"duplicates: got {duplicates!r}; allowed: {', '.join(DUPLICATES)}")
    groups, first, counts = _geometry_groups(ds)
    if duplicates == "error" and np.any(counts > 1):
        dup = np.flatnonzero(counts > 1)
        k = int(first[dup[0]])
        where = np.flatnonzero(groups == dup[0])
        raise ValidationError(
            f"measurements: {int(np.sum(counts[dup]))} of {ds.sizes[SAMPLE]} samples repeat "
            f"{dup.size} geometr{'y' if dup.size == 1 else 'ies'} (first: theta_i = "
            f"{float(ds[THETA_I].values[k])}, delta_theta = {float(ds[DELTA_THETA].values[k])}, "
            f"phi = {float(ds[PHI].values[k])} deg in samples {where[:10].tolist()}); "
            "a geometry must be "
            "measured once, or pass duplicates='mean' to average the repeats"
        )
    ref = reference_mask(ds)
    v = np.asarray(da.transpose(SAMPLE, WAVELENGTH).values)[~ref]
    if not np.all(np.isfinite(v)):
        bad = np.flatnonzero(
            ~np.all(np.isfinite(np.asarray(da.transpose(SAMPLE, WAVELENGTH).values)), axis=1) & ~ref
        )
        raise ValidationError(
            f"{MEASURED}: NaN or infinite values in sample(s) {bad[:10].tolist()}"
        )
    if np.any(v < 0):
        raise ValidationError(f"{MEASURED}: contains negative values; a BRDF is >= 0")
    if v.size and v.max() > MAX_PLAUSIBLE_SBRDF:
        warnings.warn(
            f"{MEASURED}: values up to {v.max():.3g} sr-1, above the {MAX_PLAUSIBLE_SBRDF:g} "
            "sr-1 of a mirror seen through a 0.1 degree aperture: values in other units?",
            NonPhysicalWarning,
            stacklevel=2,
        )
    return ds


#: The largest plausible measured SBRDF [sr-1]: a perfect mirror seen by a detector of
#: 0.1 degree full aperture (1 / solid angle, about 4e5 sr-1), with margin.  A near-mirror
#: (a solar array's cover glass: 5.3e4 sr-1 in a 1-degree scan) is below it.
MAX_PLAUSIBLE_SBRDF = 1e6


def _check_delta_theta(dt: np.ndarray) -> None:
    if dt.size and (np.nanmin(dt) < -180 or np.nanmax(dt) > 180):
        raise ValidationError(
            f"delta_theta: must lie in [-180, 180] degree, got [{np.nanmin(dt):g}, "
            f"{np.nanmax(dt):g}]"
        )


def _check_float(da: xr.DataArray, name: str) -> None:
    if not np.issubdtype(da.dtype, np.floating):
        raise ValidationError(
            f"{name}: values of dtype {da.dtype}; expected floating-point reflectances [sr-1] "
            "(integers are most likely scaled counts)"
        )


def reference_mask(ds: xr.Dataset) -> np.ndarray:
    """Which samples of a measurement set are reference points (signal in the noise).

    Parameters
    ----------
    ds : xarray.Dataset
        A measurement set.

    Returns
    -------
    ndarray of bool, shape (n_sample,)
        Its ``reference`` variable, or all False if it has none.

    Examples
    --------
    >>> from sbrdf_xr.testing import make_measurements
    >>> ds = make_measurements(n_wavelength=3, theta_i=(10.0, 40.0))
    >>> mask = reference_mask(ds)
    >>> mask.dtype, mask.shape == (ds.sizes["sample"],)
    (dtype('bool'), True)
    """
    if "reference" in ds:
        ref = np.asarray(ds["reference"].values)
        if ref.dtype != bool:
            ref = ref.astype(bool)
        return ref
    return np.zeros(ds.sizes[SAMPLE], dtype=bool)
