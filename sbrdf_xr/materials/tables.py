"""Materials: spectral BRDF look-up tables as labelled xarray DataArrays.

A material is a ``DataArray`` named ``sbrdf`` with dims
``(theta_i, delta_theta, phi, wavelength)`` (paper 000 §3.2), values in ``sr-1``,
and attributes ``material`` (name), ``source`` (``measured`` | ``synthetic`` |
``model:<name>``), ``provenance`` and the construction parameters.

This module is the public face of the material tables; it wraps the pure-numpy kernels
of :mod:`sbrdf_xr.kernels.lut` and gathers the jobs of its sibling modules:

* :func:`lookup` / :func:`lookup_anisotropic` - spectra at arbitrary geometries
  (``nearest``, ``linear``, ``cubic``), here;
* :func:`build_lut_anisotropic` - anisotropic tables from sets at several sample
  rotations, here;
* :func:`~sbrdf_xr.materials.schema.validate_material` - schema checks with a message
  naming the problem (:mod:`sbrdf_xr.materials.schema`);
* :func:`~sbrdf_xr.materials.build.build_lut` - the look-up-table construction of paper
  000 §3.2 from a sparse measurement set (:mod:`sbrdf_xr.materials.build`);
* :func:`~sbrdf_xr.materials.energy.hemispherical_reflectance` - directional-hemispherical
  reflectance by quadrature, to flag non-physical tables (:mod:`sbrdf_xr.materials.energy`);
* :func:`~sbrdf_xr.materials.files.to_netcdf` / :func:`~sbrdf_xr.materials.files.open_material` -
  lossless netCDF round trip (:mod:`sbrdf_xr.materials.files`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from .._names import (
    ANGLE_DIMS,
    ANISO_LUT_DIMS,
    DELTA_THETA,
    LUT_DIMS,
    PHI,
    PSI,
    SBRDF,
    THETA_I,
    WAVELENGTH,
    attrs,
)
from ..errors import ValidationError
from ..geometry.anisotropy import PSI_PERIOD, psi_weights
from ..kernels import lut as _lut
from ..units import to_unit
from .build import build_lut
from .construction import paper_delta_theta_grid, paper_phi_grid
from .files import open_material, open_measurements, to_netcdf, write_netcdf_atomic
from .schema import (
    constant_material,
    lambertian,
    new_material,
    validate_material,
    validate_measurements,
)

__all__ = [
    "LOOKUP_METHODS",
    "build_lut",
    "build_lut_anisotropic",
    "constant_material",
    "lambertian",
    "lookup",
    "lookup_anisotropic",
    "new_material",
    "open_material",
    "open_measurements",
    "paper_delta_theta_grid",
    "paper_phi_grid",
    "sample_rotation",
    "to_netcdf",
    "validate_material",
    "validate_measurements",
    "write_netcdf_atomic",
]

LOOKUP_METHODS = _lut.LOOKUP_METHODS


def lookup(
    material: xr.DataArray,
    theta_i: ArrayLike | xr.DataArray,
    delta_theta: ArrayLike | xr.DataArray,
    phi: ArrayLike | xr.DataArray,
    method: str = "linear",
) -> xr.DataArray:
    """Spectra of a material at arbitrary geometries.

    A thin xarray wrapper around :func:`sbrdf_xr.kernels.lut.lookup_kernel` (through
    :func:`xarray.apply_ufunc`, lazy and parallel for Dask-backed angles).

    Parameters
    ----------
    material : xarray.DataArray
        Material look-up table (:func:`~sbrdf_xr.materials.schema.validate_material`).
    theta_i, delta_theta, phi : array_like or xarray.DataArray
        Angles [degree] (paper 000 Fig. 4).  DataArrays are broadcast by name;
        plain arrays are broadcast by position and get dims ``dim_0, dim_1, ...``.
    method : {"nearest", "linear", "cubic"}, default "linear"
        ``nearest`` is the paper's look-up (§3.4); ``linear`` is multilinear;
        ``cubic`` is tensor-product four-point Lagrange, clipped at zero.

    Returns
    -------
    xarray.DataArray
        Dims of the broadcast angles plus ``wavelength``; ``units = sr-1``.

    Notes
    -----
    Out-of-range policy: ``theta_i`` is clamped to the table (0-90 deg);
    beyond the table's ``delta_theta`` extent or above its largest ``phi`` the
    sBRDF is zero (paper 000's reference points), unless the table records that
    edge as a measured point (attribute ``edge_* = "hold"``, set by
    :func:`~sbrdf_xr.materials.build.build_lut` where the apparatus stopped before the
    noise): then the edge value is held.  Whether a facet is lit and visible is the
    caller's business.  A table with ``normal_incidence = "symmetric"`` (the default of
    :func:`~sbrdf_xr.materials.build.build_lut` and of :func:`sbrdf_xr.materials.models.render`)
    blends, below ``normal_incidence_blend`` degrees, towards its ``theta_i = 0``
    profile at the observer's polar angle, so the look-up does not depend on the Sun's
    azimuth as ``theta_i -> 0`` (:func:`sbrdf_xr.kernels.lut.lookup_matrix`).

    Examples
    --------
    A Lambertian table returns ``albedo / pi`` at every geometry and by every method:

    >>> import numpy as np
    >>> from sbrdf_xr.materials.tables import lambertian, lookup
    >>> grey = lambertian(0.5, [500.0, 600.0])
    >>> spectra = lookup(grey, [10.0, 30.0, 60.0], -5.0, 2.0)
    >>> spectra.dims, spectra.shape, spectra.attrs["units"]
    (('dim_0', 'wavelength'), (3, 2), 'sr-1')
    >>> np.round(spectra.values[:, 0], 6)
    array([0.159155, 0.159155, 0.159155])

    Named DataArrays of angles broadcast by name, here over a small ``(theta_i, phi)`` grid:

    >>> import xarray as xr
    >>> ti = xr.DataArray([0.0, 45.0], dims="incidence")
    >>> ph = xr.DataArray([0.0, 10.0, 20.0], dims="azimuth")
    >>> lookup(grey, ti, 0.0, ph, method="nearest").dims
    ('incidence', 'azimuth', 'wavelength')
    """
    _lut.check_method(method)
    material = validate_material(material, check_values=False)
    if len(material.dims) != len(LUT_DIMS):
        raise ValidationError(
            f"material: {material.attrs.get('material', '')!r} is anisotropic (dims "
            f"{material.dims}); look it up with lookup_anisotropic(..., psi=...)"
        )
    angles = []
    for name, a in ((THETA_I, theta_i), (DELTA_THETA, delta_theta), (PHI, phi)):
        a = to_unit(a, "deg", name)  # also a DataArray holding a Quantity
        if not isinstance(a, xr.DataArray):
            arr = np.asarray(a, dtype=np.float64)
            a = xr.DataArray(arr, dims=[f"dim_{k}" for k in range(arr.ndim)])
        if a.chunks is None and not np.all(np.isfinite(a.values)):
            raise ValidationError(f"{name}: query angles contain NaN or infinite values")
        angles.append(a)
    grids = [np.asarray(material[d].values) for d in ANGLE_DIMS]
    values = np.asarray(material.values)
    out = xr.apply_ufunc(
        _lookup_core,
        *angles,
        kwargs={
            "values": values,
            "theta_grid": grids[0],
            "delta_theta_grid": grids[1],
            "phi_grid": grids[2],
            "method": method,
            "zero_edges": _lut.table_edges(material.attrs),
            "normal_blend": _lut.table_normal_blend(material.attrs),
        },
        output_core_dims=[[WAVELENGTH]],
        dask="parallelized",
        output_dtypes=[values.dtype],
        dask_gufunc_kwargs={"output_sizes": {WAVELENGTH: material.sizes[WAVELENGTH]}},
    )
    out = out.assign_coords({WAVELENGTH: material[WAVELENGTH]})
    out.name = SBRDF
    out.attrs = attrs(SBRDF, material=material.attrs.get("material", ""), lookup_method=method)
    return out


def lookup_anisotropic(
    material: xr.DataArray,
    theta_i: ArrayLike,
    delta_theta: ArrayLike,
    phi: ArrayLike,
    psi: ArrayLike,
    method: str = "linear",
) -> np.ndarray:
    """Spectra of an anisotropic table (dims ``(theta_i, delta_theta, phi, psi, wavelength)``).

    The reference look-up of the layout of :func:`sbrdf_xr.materials.models.render_anisotropic`:
    every ``psi`` slice is looked up as an isotropic table (:func:`lookup`, with the
    table's edges; ``method`` in the three table angles) and the slices are
    interpolated linearly and periodically in ``psi`` (period 180 deg,
    :func:`sbrdf_xr.geometry.anisotropy.psi_weights`: a grid ``[0, ..., 180]`` is closed, any
    other wraps from its last node to its first).  No normal-incidence blend: an
    anisotropic material depends on the observer's azimuth at ``theta_i = 0``.

    Parameters
    ----------
    material : xarray.DataArray
        Anisotropic table.
    theta_i, delta_theta, phi, psi : array_like
        Angles [degree], broadcast together (``psi`` from
        :func:`sbrdf_xr.brdf.anisotropic.illumination_azimuth`).
    method : {"nearest", "linear", "cubic"}
        Look-up method in ``(theta_i, delta_theta, phi)``.

    Returns
    -------
    ndarray, shape broadcast + (n_wavelength,)
        sBRDF [sr-1].

    Examples
    --------
    A hand-made anisotropic table, uniform in the three table angles, that varies with the
    azimuth ``psi`` of the illumination plane (period 180 deg):

    >>> import numpy as np
    >>> import xarray as xr
    >>> from sbrdf_xr.materials.tables import lookup_anisotropic
    >>> psi = np.array([0.0, 90.0, 180.0])
    >>> values = np.broadcast_to(np.array([0.1, 0.3, 0.1])[:, None], (2, 2, 2, 3, 1)).copy()
    >>> table = xr.DataArray(
    ...     values,
    ...     dims=("theta_i", "delta_theta", "phi", "psi", "wavelength"),
    ...     coords={"theta_i": [0.0, 90.0], "delta_theta": [-180.0, 90.0], "phi": [0.0, 90.0],
    ...             "psi": psi, "wavelength": [550.0]},
    ... )
    >>> np.round(lookup_anisotropic(table, 30.0, 0.0, 5.0, [0.0, 45.0, 90.0, 225.0]), 6)
    array([[0.1],
           [0.2],
           [0.3],
           [0.2]])
    """
    _lut.check_method(method)
    if not isinstance(material, xr.DataArray) or set(material.dims) != set(ANISO_LUT_DIMS):
        raise ValidationError(
            f"material: an anisotropic table has dims {ANISO_LUT_DIMS}, "
            f"got {getattr(material, 'dims', type(material).__name__)}"
        )
    material = material.transpose(*ANISO_LUT_DIMS)
    named = {THETA_I: theta_i, DELTA_THETA: delta_theta, PHI: phi, PSI: psi}
    ti, dt, ph, ps = np.broadcast_arrays(
        *(np.asarray(to_unit(a, "deg", k), dtype=np.float64) for k, a in named.items())
    )
    grid = np.asarray(material[PSI].values, dtype=np.float64)
    idx, w = psi_weights(grid, ps.ravel())
    grids = [np.asarray(material[d].values) for d in ANGLE_DIMS]
    values = np.asarray(material.values)
    out = np.zeros((ps.size, material.sizes[WAVELENGTH]))
    edges = _lut.table_edges(material.attrs)
    for k in range(grid.size):
        wk = np.where(idx == k, w, 0.0).sum(axis=1)
        sel = np.flatnonzero(wk > 0)
        if sel.size:
            spec = _lut.lookup_kernel(
                values[:, :, :, k, :],
                grids[0],
                grids[1],
                grids[2],
                ti.ravel()[sel],
                dt.ravel()[sel],
                ph.ravel()[sel],
                method,
                zero_edges=edges,
            )
            out[sel] += wk[sel, None] * spec
    return out.reshape(*ti.shape, -1).astype(values.dtype, copy=False)


def _lookup_core(
    theta_i: np.ndarray, delta_theta: np.ndarray, phi: np.ndarray, **kw: Any
) -> np.ndarray:
    """apply_ufunc adapter: angles first, table as keywords."""
    return _lut.lookup_kernel(theta_i=theta_i, delta_theta=delta_theta, phi=phi, **kw)


#: Name of the attribute (or scalar coordinate) of a measurement set that says how
#: the sample was turned about its normal: the ``psi`` of its illumination plane.
SAMPLE_ROTATION = "sample_rotation"


def sample_rotation(measurements: xr.Dataset) -> float:
    """The ``sample_rotation`` [degree] of a measurement set (attribute or coordinate).

    Examples
    --------
    >>> sample_rotation(xr.Dataset(attrs={"sample_rotation": 30}))
    30.0
    """
    if SAMPLE_ROTATION in measurements.coords:
        value = measurements[SAMPLE_ROTATION].values
    elif SAMPLE_ROTATION in measurements.attrs:
        value = measurements.attrs[SAMPLE_ROTATION]
    else:
        raise ValidationError(
            f"measurements: a set of an anisotropic sample needs the attribute or scalar "
            f"coordinate {SAMPLE_ROTATION!r} [degree]; got attributes {sorted(measurements.attrs)}"
        )
    arr = np.asarray(value, dtype=np.float64)
    if arr.size != 1 or not np.isfinite(arr).all():
        raise ValidationError(
            f"{SAMPLE_ROTATION}: expected one finite angle [degree], got {value!r}"
        )
    return float(arr.reshape(-1)[0])


def _broadcast3(
    grid: list[xr.DataArray],
) -> tuple[xr.DataArray, xr.DataArray, xr.DataArray]:
    """The three angle grids broadcast against each other (for :func:`lookup`)."""
    a, b, c = xr.broadcast(*grid)
    return a, b, c


def build_lut_anisotropic(
    measurements: Sequence[xr.Dataset],
    *,
    n_phi: int = 41,
    n_delta_theta: int = 41,
    material: str | None = None,
    dtype: type | np.dtype = np.float64,
    normal_incidence: str = "paper",
    **options: Any,
) -> xr.DataArray:
    """Anisotropic table from measurement sets taken at several sample rotations.

    A goniospectrometer measures in a fixed illumination plane; turning an
    anisotropic sample (brushed metal) about its normal turns its tangent relative to
    that plane.  Each set is a measurement set as
    :func:`~sbrdf_xr.materials.build.build_lut` takes (one
    :func:`sbrdf_xr.materials.goniometer.measure` run) with the attribute or scalar coordinate
    ``sample_rotation`` [degree]: the azimuth ``psi`` of the illumination plane from
    the sample's tangent (:mod:`sbrdf_xr.geometry.anisotropy`), the observer on the ``+p``
    side of the plane (the side of :func:`sbrdf_xr.geometry.facet_vectors`).

    Construction: every set becomes an isotropic table by
    :func:`~sbrdf_xr.materials.build.build_lut`
    (``options`` are passed on); the tables are resampled by :func:`lookup` (linear,
    zero beyond each set's extents) onto common grids (``theta_i`` of the tables;
    ``delta_theta`` by :func:`sbrdf_xr.materials.construction.paper_delta_theta_grid` and
    ``phi`` uniform, over the extremes of all sets, finer than one set's grid by
    default since the lobe's extents change with the rotation); the slices are
    stacked along ``psi`` at the rotations modulo 180 deg.  The look-up
    (:func:`lookup_anisotropic`, the engine) interpolates linearly and periodically
    in ``psi`` between the rotations.

    Parameters
    ----------
    measurements : sequence of xarray.Dataset
        At least two sets, at distinct rotations modulo 180 deg.
    n_phi, n_delta_theta : int
        Points of the common ``phi`` and ``delta_theta`` grids (odd for
        ``delta_theta``).
    material : str, optional
        Name (default: the first set's).
    dtype : numpy dtype
    normal_incidence : {"paper", "symmetric"}
        Passed to :func:`~sbrdf_xr.materials.build.build_lut`; the anisotropic look-up itself has no
        normal-incidence blend.
    **options
        Other :func:`~sbrdf_xr.materials.build.build_lut` parameters (``theta_i``,
        ``below_noise``, ...).

    Returns
    -------
    xarray.DataArray
        Dims ``(theta_i, delta_theta, phi, psi, wavelength)``, validated.

    Examples
    --------
    A brushed metal measured (virtually) at two sample rotations, 0 and 90 deg:

    >>> from sbrdf_xr.materials import goniometer, models
    >>> spec = models.model_material(
    ...     "anisotropic_microfacet", [550.0], material="brushed", provenance="doc",
    ...     alpha_x=0.15, alpha_y=0.4, n=1.5, k=7.5, rho_d=0.01)
    >>> sets = []
    >>> for rot in (0.0, 90.0):
    ...     m = goniometer.measure(models.spectrum_function(spec, psi=rot), [550.0], [20.0, 40.0])
    ...     m.attrs["sample_rotation"] = rot
    ...     sets.append(m)
    >>> table = build_lut_anisotropic(sets, n_phi=11, n_delta_theta=11, check_energy=False)
    >>> table.dims, table.psi.values.tolist()
    (('theta_i', 'delta_theta', 'phi', 'psi', 'wavelength'), [0.0, 90.0])
    """
    sets = list(measurements)
    if len(sets) < 2:
        raise ValidationError(
            f"measurements: need sets at two or more sample rotations, got {len(sets)}"
        )
    rot = np.array([sample_rotation(m) for m in sets])
    psi = np.mod(rot, PSI_PERIOD)
    if np.unique(np.round(psi, 9)).size < psi.size:
        raise ValidationError(
            f"{SAMPLE_ROTATION}: rotations must differ modulo 180 deg, got {rot.tolist()}"
        )
    order = np.argsort(psi)
    tables = [
        build_lut(sets[k], n_phi=21, n_delta_theta=21, normal_incidence=normal_incidence, **options)
        for k in order
    ]
    ti = np.asarray(tables[0][THETA_I].values)
    wl = np.asarray(tables[0][WAVELENGTH].values)
    for t in tables[1:]:
        if not (np.array_equal(t[THETA_I].values, ti) and np.array_equal(t[WAVELENGTH].values, wl)):
            raise ValidationError(
                "measurements: every set must give the same theta_i grid and wavelengths"
            )
    lo = min(float(t[DELTA_THETA].values[0]) for t in tables)
    hi = max(float(t[DELTA_THETA].values[-1]) for t in tables)
    dt = paper_delta_theta_grid(lo, hi, n_delta_theta)
    ph = np.linspace(0.0, max(float(t[PHI].values[-1]) for t in tables), n_phi)
    grid = [xr.DataArray(g, dims=d) for g, d in ((ti, THETA_I), (dt, DELTA_THETA), (ph, PHI))]
    slices = [
        np.asarray(
            lookup(t, *_broadcast3(grid), method="linear").transpose(*ANGLE_DIMS, WAVELENGTH)
        )
        for t in tables
    ]
    values = np.stack(slices, axis=3).astype(dtype)
    edge_keys = ("edge_delta_theta_min", "edge_delta_theta_max", "edge_phi_max")
    edges = {
        k: "hold" if any(t.attrs.get(k, "zero") == "hold" for t in tables) else "zero"
        for k in edge_keys
    }
    first = sets[order[0]]
    coords = {
        THETA_I: (THETA_I, ti, attrs(THETA_I)),
        DELTA_THETA: (DELTA_THETA, dt, attrs(DELTA_THETA)),
        PHI: (PHI, ph, attrs(PHI)),
        PSI: (PSI, psi[order], attrs(PSI)),
        WAVELENGTH: (WAVELENGTH, wl, attrs(WAVELENGTH)),
    }
    a = attrs(
        SBRDF,
        material=material or first.attrs.get("material", "unnamed"),
        source=first.attrs.get("source", "measured"),
        provenance=(
            f"{first.attrs.get('provenance', '')}; built by "
            f"sbrdf_xr.materials.tables.build_lut_anisotropic from {len(sets)} sample rotations "
            f"{np.round(rot[order], 6).tolist()} deg"
        ),
        normal_incidence=normal_incidence,
        **edges,
    )
    out = xr.DataArray(values, dims=ANISO_LUT_DIMS, coords=coords, name=SBRDF, attrs=a)
    return validate_material(out)
