"""Materials: spectral BRDF look-up tables as labelled xarray DataArrays.

A material is a ``DataArray`` named ``sbrdf`` with dims
``(theta_i, delta_theta, phi, wavelength)`` (paper 000 §3.2), values in ``sr-1``,
and attributes ``material`` (name), ``source`` (``measured`` | ``synthetic`` |
``model:<name>``), ``provenance`` and the construction parameters.

This module wraps the pure-numpy kernels of :mod:`sbrdf_xr._lut`:

* :func:`validate_material` - schema checks with a message naming the problem;
* :func:`lookup` - spectra at arbitrary geometries (``nearest``, ``linear``, ``cubic``);
* :func:`build_lut` - the look-up-table construction of paper 000 §3.2 from a sparse
  measurement set (:func:`validate_measurements` describes its schema);
* :func:`hemispherical_reflectance` - directional-hemispherical reflectance by
  quadrature, to flag non-physical tables;
* :func:`to_netcdf` / :func:`open_material` - lossless netCDF round trip.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from . import _lut, models
from ._names import (
    ANGLE_DIMS,
    DELTA_THETA,
    LUT_DIMS,
    MEASURED,
    PHI,
    SAMPLE,
    SBRDF,
    THETA_I,
    WAVELENGTH,
    attrs,
)
from .construction import (
    azimuthal_average,
    blend_weights,
    extend_grid,
    lut_edges,
    paper_delta_theta_grid,
    paper_phi_grid,
    per_theta_tables,
)
from .errors import NonPhysicalWarning, ValidationError
from .material_io import open_material, open_measurements, to_netcdf, write_netcdf_atomic
from .material_schema import (
    DUPLICATES,  # noqa: F401  (re-exported)
    SOURCES,  # noqa: F401  (re-exported)
    average_duplicates,
    check_coord,
    constant_material,
    lambertian,
    new_material,
    reference_mask,
    validate_material,
    validate_measurements,
)

__all__ = [
    "LOOKUP_METHODS",
    "build_lut",
    "build_lut_anisotropic",
    "constant_material",
    "hemispherical_reflectance",
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

LOOKUP_METHODS = tuple(_lut.LOOKUP_METHODS)


def lookup(
    material: xr.DataArray,
    theta_i: ArrayLike | xr.DataArray,
    delta_theta: ArrayLike | xr.DataArray,
    phi: ArrayLike | xr.DataArray,
    method: str = "linear",
) -> xr.DataArray:
    """Spectra of a material at arbitrary geometries.

    A thin xarray wrapper around :func:`sbrdf_xr._lut.lookup_kernel` (through
    :func:`xarray.apply_ufunc`, lazy and parallel for Dask-backed angles).

    Parameters
    ----------
    material : xarray.DataArray
        Material look-up table (:func:`validate_material`).
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
    :func:`build_lut` where the apparatus stopped before the noise): then the edge
    value is held.  Whether a facet is lit and visible is the caller's business.
    A table with ``normal_incidence = "symmetric"`` (the default of :func:`build_lut`
    and of :func:`sbrdf_xr.models.render`) blends, below ``normal_incidence_blend``
    degrees, towards its ``theta_i = 0`` profile at the observer's polar angle, so
    the look-up does not depend on the Sun's azimuth as ``theta_i -> 0``
    (:func:`sbrdf_xr._lut.lookup_matrix`).

    Examples
    --------
    A Lambertian table returns ``albedo / pi`` at every geometry and by every method:

    >>> import numpy as np
    >>> from sbrdf_xr.material import lambertian, lookup
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

    The reference look-up of the layout of :func:`sbrdf_xr.models.render_anisotropic`:
    every ``psi`` slice is looked up as an isotropic table (:func:`lookup`, with the
    table's edges; ``method`` in the three table angles) and the slices are
    interpolated linearly and periodically in ``psi`` (period 180 deg,
    :func:`sbrdf_xr.anisotropy.psi_weights`: a grid ``[0, ..., 180]`` is closed, any
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
    >>> from sbrdf_xr.material import lookup_anisotropic
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
    from ._names import ANISO_LUT_DIMS, PSI

    _lut.check_method(method)
    if not isinstance(material, xr.DataArray) or set(material.dims) != set(ANISO_LUT_DIMS):
        raise ValidationError(
            f"material: an anisotropic table has dims {ANISO_LUT_DIMS}, "
            f"got {getattr(material, 'dims', type(material).__name__)}"
        )
    material = material.transpose(*ANISO_LUT_DIMS)
    ti, dt, ph, ps = np.broadcast_arrays(
        *(np.asarray(a, dtype=np.float64) for a in (theta_i, delta_theta, phi, psi))
    )
    from .anisotropy import psi_weights

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


# ----------------------------------------------------------- measurements


def build_lut(
    measurements: xr.Dataset,
    *,
    n_phi: int = 21,
    n_delta_theta: int = 21,
    theta_i: ArrayLike | None = None,
    smoothing: float | str = 0.0,
    extrapolation: str = "cubic",
    material: str | None = None,
    dtype: type | np.dtype = np.float64,
    blend: float = 10.0,
    model: xr.Dataset | None = None,
    normal_incidence: str = "symmetric",
    blend_normal: float = 5.0,
    below_noise: str = "zero",
    duplicates: str = "error",
    check_energy: bool = True,
    renormalise: str = "auto",
) -> xr.DataArray:
    """Look-up table from sparse measurements, by the construction of paper 000 §3.2.

    1. ``phi``: ``n_phi`` uniform points from 0 to the largest measured ``phi`` of
       the material; for every measured ``(theta_i, delta_theta)`` row, linear
       interpolation in ``phi`` (zero beyond the row's largest ``phi`` when it is a
       reference point, as in the paper).
    2. ``delta_theta``: ``n_delta_theta`` points with 0 at the median and steps
       ``delta_theta_min/10`` and ``delta_theta_max/10`` on either side (for the
       paper's 21), from the extremes over all ``theta_i``; for every measured
       ``theta_i`` and grid ``phi``, linear interpolation in ``delta_theta``
       (zero beyond that ``theta_i``'s measured extent when it is a reference
       point).


       Where an extent is a measured point rather than a reference point (the
       apparatus stopped before the signal reached the noise, as for diffuse
       materials), the edge value is held beyond it instead of dropping to zero; the
       paper's sets end in reference points, for which this is the paper's rule.
    3. ``theta_i``: a cubic smoothing spline over the measured incidence angles for
       every ``(delta_theta, phi, wavelength)``, evaluated at every integer degree
       0-90 (interpolating between and extrapolating beyond the measured angles).

    Values are clipped at zero after step 3 (a smoothing spline can undershoot,
    and a BRDF cannot be negative).  Everything is vectorised: each step is one
    linear operator applied to all wavelengths at once.

    ``below_noise="model"`` (beyond the paper) keeps the diffuse floor and the lobe's
    tails that the instrument cannot see: the same three steps interpolate the
    *ratio* of every measured spectrum to a fitted model (``model``), with every
    edge held and the reference points left out, and the table is the model
    rendered on the grid times that ratio.  Below-noise geometries (the reference
    points and everything beyond each incidence angle's extents, out to the
    horizon: the grids are extended to ``delta_theta`` -180..90 and ``phi`` 90 deg
    in steps of at most 5 deg) then carry the model scaled by the nearest measured
    ratio instead of zero, the ratio equals the measured one at the measured
    geometries, and between them the lobe keeps the model's shape (a needle lobe is
    not flattened by linear interpolation between samples a quarter of its extent
    apart).  Below the smallest measured incidence angle the ratio is held (the
    model carries the angular trend); above the largest, with
    ``extrapolation="model"``, it goes to one over ``blend`` degrees (the model alone
    near grazing, where a lobe meets the horizon and the measured ratio does not
    carry over), and a row whose directional-hemispherical reflectance exceeds the
    model's is scaled down to it (grazing extrapolation bounded by the model).

    Parameters
    ----------
    measurements : xarray.Dataset
        Measurement set (:func:`validate_measurements`).
    n_phi : int, default 21
        Points of the ``phi`` grid (paper: 21).
    n_delta_theta : int, default 21
        Points of the ``delta_theta`` grid, odd (paper: 21).
    theta_i : array_like, optional
        Output incidence angles [degree]; default every integer 0-90 (paper).
    smoothing : float or "csaps", default 0
        Smoothing parameter ``lam`` [degree**3] of the cubic smoothing spline in
        ``theta_i`` (:func:`sbrdf_xr._lut.smoothing_spline_matrix`).  Paper 000
        does not give it.  The default 0 makes the spline pass through the
        measurements (a natural cubic spline; ``p = 1`` in MATLAB's ``csaps``
        terms).  ``"csaps"`` is MATLAB's default ``lam = h**3/6``
        (:func:`sbrdf_xr._lut.csaps_default_lambda`), which with five incidence
        angles 10-15 deg apart smooths spectral features that move with angle
        (a solar cell's interference minima) by tens of nanometres.
    extrapolation : {"cubic", "linear", "constant", "model"}, default "cubic"
        How the table continues below the smallest and above the largest measured
        ``theta_i``.  ``cubic`` (default) continues the spline's end polynomial
        pieces, as the paper's spline evaluation did (the source of the
        discontinuities its §4.2 reports); ``linear`` and ``constant`` are milder.
        ``model`` (beyond the paper) fits the Robertson-Sandford model (paper 001)
        to the measurements (:func:`sbrdf_xr.brdf.robertson_sandford_fit.fit_robertson_sandford`)
        and lets it fill the unmeasurable range, blended into the linearly
        extrapolated spline over ``blend`` degrees with a smoothstep weight.  With
        ``below_noise="model"`` the model carries the table everywhere and this
        only chooses how the ratio continues: held (``constant``, ``model``) or as
        the spline says.
    blend : float, default 10
        Width of the blend zone of ``extrapolation="model"`` [degree].
    model : xarray.Dataset, optional
        The model material of ``extrapolation="model"`` and ``below_noise="model"``
        (:mod:`sbrdf_xr.models`); default: a Robertson-Sandford fit to the
        measurements (:func:`sbrdf_xr.models.fit_robertson_sandford`, a few seconds).
    normal_incidence : {"symmetric", "paper"}, default "symmetric"
        ``symmetric`` enforces what physics requires at ``theta_i = 0``: no
        dependence on the undefined illumination plane.  The ``theta_i = 0`` row
        becomes its own azimuthal average (for every node, the mean over the
        illumination-plane azimuth of the row at the same observer polar angle
        ``theta_r``, by 64-point Gauss-Legendre quadrature), and the table records
        ``normal_incidence_blend = blend_normal``: look-ups below that angle blend
        towards the row's in-plane profile at ``theta_r``
        (:func:`sbrdf_xr._lut.lookup_matrix`), so the look-up is independent of the
        Sun's azimuth as ``theta_i -> 0``.  ``paper`` leaves the row as extrapolated.
    blend_normal : float, default 5
        Width of that blend [degree].
    below_noise : {"zero", "model"}, default "zero"
        ``zero`` is the paper's: reference points and everything beyond an
        incidence angle's extents are zero.  ``model``: see above.
    duplicates : {"error", "mean"}, default "error"
        A geometry measured more than once is an error (:func:`validate_measurements`)
        or its repeats are averaged (``mean``: the mean of the measured repeats; a
        reference point only if all repeats are).
    renormalise : {"auto", "none", "model"}, default "auto"
        ``model`` (``auto`` with ``below_noise="model"``) is a flux-conserving
        correction of the interpolant.  A lobe sampled on nodes a few degrees apart,
        above all one meeting the horizon at grazing incidence, integrates under the
        look-up's multilinear interpolation to more or less energy than the lobe
        itself: a GGX lobe of roughness 0.15 rendered on such a grid gains 18 % at
        ``theta_i = 85`` deg.  Every row ``(theta_i, wavelength)`` is scaled by
        ``rho_model / rho_grid``, the factor that restores to the model rendered on
        the grid the model's own directional-hemispherical reflectance
        (``rho_grid`` by the quadrature of :func:`hemispherical_reflectance`), and
        keeps the ratio to the measurements: a table of the model itself has the
        model's energy exactly, and the rows beyond the measured angles, where the
        table is the model, are bounded by its reflectance.  It is the
        normalisation step of conservative remapping (P. W. Jones, Mon. Wea. Rev.
        127, 2204, 1999: rescale the interpolant so that it keeps the integral of
        the field it samples), applied per row.  ``none`` keeps the interpolant (and,
        with ``extrapolation="model"``, only scales rows above the measured angles
        down to the model's reflectance); ``auto`` is ``none`` with
        ``below_noise="zero"`` (the paper's construction).
    check_energy : bool, default True
        Compute the table's directional-hemispherical reflectance every 5 deg of
        ``theta_i`` (and at the last row) and issue a
        :class:`~sbrdf_xr.errors.NonPhysicalWarning` naming the incidence angle and
        wavelength where it exceeds 1.
    material : str, optional
        Name; default the ``material`` attribute of ``measurements``.
    dtype : numpy dtype, default float64
        dtype of the table values.

    Returns
    -------
    xarray.DataArray
        The material table with ``source`` and ``provenance`` copied from the
        measurement set and the construction parameters as attributes.

    Raises
    ------
    ValidationError
        For an invalid measurement set, fewer than two measured incidence angles,
        no measured extent in ``phi`` or ``delta_theta``, repeated geometries with
        ``duplicates="error"``.

    Examples
    --------
    The construction of paper 000 §3.2 from a small synthetic measurement set (two
    incidence angles, three wavelengths); the table reproduces the measured specular
    spectrum at a measured incidence angle:

    >>> import numpy as np
    >>> from sbrdf_xr.material import build_lut
    >>> from sbrdf_xr.testing import make_measurements
    >>> meas = make_measurements(n_wavelength=3, theta_i=(20.0, 50.0))
    >>> lut = build_lut(meas, n_phi=11, n_delta_theta=11)
    >>> lut.dims, lut.shape
    (('theta_i', 'delta_theta', 'phi', 'wavelength'), (91, 11, 11, 3))
    >>> lut.attrs["construction"], lut.attrs["measured_theta_i"].tolist()
    ('paper000-3.2', [20.0, 50.0])
    >>> at = (meas.theta_i == 20.0) & (meas.delta_theta == 0.0) & (meas.phi == 0.0)
    >>> measured = meas.measured_sbrdf.where(at, drop=True).values[0]
    >>> bool(np.allclose(lut.sel(theta_i=20.0, delta_theta=0.0, phi=0.0), measured))
    True
    """
    ds = validate_measurements(measurements, duplicates=duplicates)
    if duplicates == "mean":
        ds = average_duplicates(ds)
    if extrapolation not in EXTRAPOLATIONS:
        raise ValidationError(
            f"extrapolation: got {extrapolation!r}; allowed: {', '.join(EXTRAPOLATIONS)}"
        )
    if normal_incidence not in ("paper", "symmetric"):
        raise ValidationError(
            f"normal_incidence: got {normal_incidence!r}; allowed: symmetric, paper"
        )
    if below_noise not in BELOW_NOISE:
        raise ValidationError(
            f"below_noise: got {below_noise!r}; allowed: {', '.join(BELOW_NOISE)}"
        )
    if renormalise not in RENORMALISE:
        raise ValidationError(
            f"renormalise: got {renormalise!r}; allowed: {', '.join(RENORMALISE)}"
        )
    if renormalise == "auto":
        renormalise = "model" if below_noise == "model" else "none"
    elif renormalise == "model" and below_noise != "model":
        raise ValidationError(
            "renormalise: 'model' corrects a table made of a model times a ratio and needs "
            f"below_noise='model', got below_noise={below_noise!r}"
        )
    ref = reference_mask(ds)
    ti_s = np.asarray(ds[THETA_I].values, dtype=np.float64)
    dt_s = np.asarray(ds[DELTA_THETA].values, dtype=np.float64)
    ph_s = np.asarray(ds[PHI].values, dtype=np.float64)
    wl = np.asarray(ds[WAVELENGTH].values, dtype=np.float64)
    spectra = np.asarray(ds[MEASURED].transpose(SAMPLE, WAVELENGTH).values, dtype=np.float64).copy()
    spectra[ref] = 0.0
    measured_ti = np.unique(ti_s)
    if measured_ti.size < 2:
        raise ValidationError(
            "theta_i: need measurements at >= 2 incidence angles to build a table, "
            f"got {measured_ti.tolist()}"
        )
    phi_grid = paper_phi_grid(ph_s.max(), n_phi)
    dt_grid = paper_delta_theta_grid(dt_s.min(), dt_s.max(), n_delta_theta)
    ti_out = np.arange(0.0, 91.0) if theta_i is None else np.asarray(theta_i, dtype=np.float64)
    check_coord("theta_i", ti_out)
    lam = _lut.csaps_default_lambda(measured_ti) if smoothing == "csaps" else float(smoothing)
    extra: dict[str, Any] = {}
    fit_model = model
    if (extrapolation == "model" or below_noise == "model") and fit_model is None:
        fit_model = models.fit_robertson_sandford(ds)

    if below_noise == "zero":
        # Table edges: zero beyond them if the extreme samples are reference points.
        edges = {
            "edge_delta_theta_min": "zero" if np.all(ref[dt_s == dt_s.min()]) else "hold",
            "edge_delta_theta_max": "zero" if np.all(ref[dt_s == dt_s.max()]) else "hold",
            "edge_phi_max": "zero" if np.all(ref[ph_s == ph_s.max()]) else "hold",
        }
        per_theta = per_theta_tables(measured_ti, ti_s, dt_s, ph_s, spectra, ref, dt_grid, phi_grid)
        spline_mode = "linear" if extrapolation == "model" else extrapolation
        e = _lut.smoothing_spline_matrix(measured_ti, ti_out, lam, spline_mode)
        lut = np.tensordot(e, per_theta, axes=(1, 0))
        np.maximum(lut, 0.0, out=lut)
        if extrapolation == "model":
            assert fit_model is not None  # fitted above whenever a model is used
            w = blend_weights(ti_out, measured_ti[0], measured_ti[-1], blend)
            rows = np.flatnonzero(w > 0)
            if rows.size:
                filled = _model_rows(fit_model, ti_out[rows], dt_grid, phi_grid, wl)
                wr = w[rows][:, None, None, None]
                lut[rows] = (1.0 - wr) * lut[rows] + wr * filled
    else:
        assert fit_model is not None  # fitted above whenever a model is used
        dt_grid = extend_grid(dt_grid, -180.0, 90.0)
        phi_grid = extend_grid(phi_grid, phi_grid[0], 90.0)
        # Beyond -180/90 and phi = 90 lies the far side of the horizon: nothing to hold.
        edges = {
            "edge_delta_theta_min": "zero",
            "edge_delta_theta_max": "zero",
            "edge_phi_max": "zero",
        }
        truth_s = _model_at(fit_model, ti_s, dt_s, ph_s, wl)
        ok = ~ref
        ratio = np.divide(spectra, truth_s, out=np.ones_like(spectra), where=truth_s > 0)
        per_theta = per_theta_tables(
            measured_ti,
            ti_s[ok],
            dt_s[ok],
            ph_s[ok],
            ratio[ok],
            np.zeros(int(ok.sum()), dtype=bool),
            dt_grid,
            phi_grid,
            hold_all=True,
        )
        spline_mode = "constant" if extrapolation == "model" else extrapolation
        e = _lut.smoothing_spline_matrix(measured_ti, ti_out, lam, spline_mode)
        r_lut = np.tensordot(e, per_theta, axes=(1, 0))
        np.maximum(r_lut, 0.0, out=r_lut)
        if extrapolation == "model":
            # Towards grazing incidence the measured ratio does not carry over (the
            # lobe meets the horizon): the model alone, reached over ``blend`` degrees.
            w = blend_weights(ti_out, -np.inf, measured_ti[-1], blend)[:, None, None, None]
            r_lut = (1.0 - w) * r_lut + w
        base = _model_rows(fit_model, ti_out, dt_grid, phi_grid, wl)
        lut = base * r_lut
        if extrapolation == "model" and renormalise == "none":
            _bound_grazing_rows(lut, ti_out, dt_grid, phi_grid, wl, fit_model, measured_ti[-1])
    if fit_model is not None and (extrapolation == "model" or below_noise == "model"):
        extra = {
            "extrapolation_model": fit_model.attrs.get("model", ""),
            "extrapolation_model_provenance": fit_model.attrs.get("provenance", ""),
        }
        if extrapolation == "model" and below_noise == "zero":
            extra["blend_width"] = blend
    if normal_incidence == "symmetric" and ti_out[0] == 0.0:
        lut[0] = azimuthal_average(lut[0], dt_grid, phi_grid, lut_edges(edges))
        if renormalise == "model":
            base[0] = azimuthal_average(base[0], dt_grid, phi_grid, lut_edges(edges))
        extra["normal_incidence_blend"] = float(blend_normal)
    if renormalise == "model":
        if fit_model is None:  # pragma: no cover - below_noise="model" needs the model
            raise ValidationError("renormalise='model' needs the table's model")
        _renormalise_rows(
            lut,
            base,
            (ti_out, dt_grid, phi_grid),
            wl,
            fit_model,
            lut_edges(edges),
            extra.get("normal_incidence_blend", 0.0),
        )
        extra["renormalise"] = "model"

    name = material or ds.attrs.get("material", "unnamed")
    prov = ds.attrs.get("provenance", "")
    out = new_material(
        lut.astype(dtype),
        ti_out,
        dt_grid,
        phi_grid,
        wl,
        material=name,
        source=ds.attrs.get("source", "measured"),
        provenance=(prov + "; " if prov else "") + "look-up table built by sbrdf_xr.build_lut "
        "(paper 000 section 3.2)",
        construction="paper000-3.2",
        n_phi=n_phi,
        n_delta_theta=n_delta_theta,
        smoothing_lambda=lam,
        extrapolation=extrapolation,
        normal_incidence=normal_incidence,
        below_noise=below_noise,
        measured_theta_i=measured_ti,
        n_measurements=int(ds.sizes[SAMPLE]),
        **edges,
        **extra,
    )
    if check_energy:
        check_ti = np.unique(np.concatenate([ti_out[::5], ti_out[-1:]]))
        rho = hemispherical_reflectance(out, check_ti, warn=False).values
        if np.any(rho > 1.0 + ENERGY_TOL):
            bad = np.argwhere(rho > 1.0 + ENERGY_TOL)
            worst = np.unravel_index(np.argmax(rho), rho.shape)
            tis = sorted({float(check_ti[b[0]]) for b in bad})
            warnings.warn(
                f"build_lut: the table of {name!r} does not conserve energy: its directional-"
                f"hemispherical reflectance exceeds 1 at theta_i = {tis} deg (worst "
                f"{rho[worst]:.3f} at theta_i = {check_ti[worst[0]]} deg, wavelength = "
                f"{wl[worst[1]]} nm); consider below_noise='model' or extrapolation='model'",
                NonPhysicalWarning,
                stacklevel=2,
            )
    return out


#: Extrapolation policies of :func:`build_lut` beyond the measured incidence angles.
EXTRAPOLATIONS = ("cubic", "linear", "constant", "model")
#: Below-noise policies of :func:`build_lut`.
BELOW_NOISE = ("zero", "model")
#: Row renormalisations of :func:`build_lut`.
RENORMALISE = ("auto", "none", "model")
#: Reflectance above ``1 + ENERGY_TOL`` is reported by :func:`build_lut` (the
#: quadrature of a float32 table is good to ~1e-7).
ENERGY_TOL = 1e-6


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
    that plane.  Each set is a measurement set as :func:`build_lut` takes (one
    :func:`sbrdf_xr.goniometer.measure` run) with the attribute or scalar coordinate
    ``sample_rotation`` [degree]: the azimuth ``psi`` of the illumination plane from
    the sample's tangent (:mod:`sbrdf_xr.anisotropy`), the observer on the ``+p``
    side of the plane (the side of :func:`sbrdf_xr.geometry.facet_vectors`).

    Construction: every set becomes an isotropic table by :func:`build_lut`
    (``options`` are passed on); the tables are resampled by :func:`lookup` (linear,
    zero beyond each set's extents) onto common grids (``theta_i`` of the tables;
    ``delta_theta`` by :func:`sbrdf_xr.construction.paper_delta_theta_grid` and
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
        Passed to :func:`build_lut`; the anisotropic look-up itself has no
        normal-incidence blend.
    **options
        Other :func:`build_lut` parameters (``theta_i``, ``below_noise``, ...).

    Returns
    -------
    xarray.DataArray
        Dims ``(theta_i, delta_theta, phi, psi, wavelength)``, validated.

    Examples
    --------
    A brushed metal measured (virtually) at two sample rotations, 0 and 90 deg:

    >>> from sbrdf_xr import goniometer, models
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
    from ._names import ANISO_LUT_DIMS, PSI
    from .anisotropy import PSI_PERIOD

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
            f"sbrdf_xr.material.build_lut_anisotropic from {len(sets)} sample rotations "
            f"{np.round(rot[order], 6).tolist()} deg"
        ),
        normal_incidence=normal_incidence,
        **edges,
    )
    out = xr.DataArray(values, dims=ANISO_LUT_DIMS, coords=coords, name=SBRDF, attrs=a)
    return validate_material(out)


def _bound_grazing_rows(
    lut: np.ndarray,
    ti: np.ndarray,
    dt: np.ndarray,
    ph: np.ndarray,
    wl: np.ndarray,
    model: xr.Dataset,
    above: float,
) -> None:
    """Scale every row above the measured incidence angles whose reflectance exceeds the
    model's (in place), so that grazing extrapolation never creates energy: a glossy
    lobe meeting the horizon between grid nodes is overestimated by interpolation."""
    rows = np.flatnonzero(ti > above)
    if rows.size == 0:
        return
    mod, _, kw = models.model_parameters(_model_for(model, wl))
    rho_m = mod.directional_hemispherical_reflectance(np.minimum(ti[rows], 90.0), wl, **kw)
    rho_t = _lut.hemispherical_reflectance_kernel(
        lut, ti, dt, ph, ti[rows], "linear", zero_edges=(True, True, True)
    )
    scale = np.where(rho_t > rho_m, rho_m / np.maximum(rho_t, 1e-300), 1.0)
    lut[rows] *= scale[:, None, None, :]


def _renormalise_rows(
    lut: np.ndarray,
    base: np.ndarray,
    grids: tuple[np.ndarray, np.ndarray, np.ndarray],
    wl: np.ndarray,
    model: xr.Dataset,
    zero_edges: tuple[bool, bool, bool],
    normal_blend: float,
) -> None:
    """Scale every row ``(theta_i, wavelength)`` of ``lut`` (in place) by the energy its
    model loses or gains on the grid: ``rho_model / rho_grid``, with ``rho_model`` the
    model's own directional-hemispherical reflectance and ``rho_grid`` that of ``base``
    (the model rendered on the table grid) by the quadrature of the look-up's
    interpolant (:func:`sbrdf_xr._lut.hemispherical_reflectance_kernel`)."""
    ti = grids[0]
    mod, _, kw = models.model_parameters(_model_for(model, wl))
    rho_m = mod.directional_hemispherical_reflectance(np.minimum(ti, 90.0), wl, **kw)
    tg, dg, pg = grids
    rho_g = _lut.hemispherical_reflectance_kernel(
        base, tg, dg, pg, ti, "linear", zero_edges=zero_edges, normal_blend=normal_blend
    )
    scale = np.divide(rho_m, rho_g, out=np.ones_like(rho_m), where=rho_g > 0)
    # Below ``normal_blend`` a look-up mixes the row with the theta_i = 0 profile: with
    # that profile already scaled, the row's own part takes the rest.
    blended = np.flatnonzero((ti > 0) & (ti < normal_blend)) if ti[0] == 0.0 else np.zeros(0, int)
    if len(blended):
        idx = np.concatenate([[0], blended])
        sub = base[idx].copy()
        sub[0] *= scale[0]
        both = _lut.hemispherical_reflectance_kernel(
            sub, ti[idx], dg, pg, None, zero_edges=zero_edges, normal_blend=normal_blend
        )[1:]
        sub[1:] = 0.0
        part0 = _lut.hemispherical_reflectance_kernel(
            sub, ti[idx], dg, pg, None, zero_edges=zero_edges, normal_blend=normal_blend
        )[1:]
        own = both - part0
        scale[blended] = np.divide(rho_m[blended] - part0, own, out=scale[blended], where=own > 0)
    lut *= scale[:, None, None, :]


def _model_for(model: xr.Dataset, wl: np.ndarray) -> xr.Dataset:
    if not np.array_equal(np.asarray(model[WAVELENGTH].values), wl):
        model = model.interp({WAVELENGTH: wl})
    return model


def _model_rows(
    model: xr.Dataset, ti: np.ndarray, dt: np.ndarray, ph: np.ndarray, wl: np.ndarray
) -> np.ndarray:
    """A model material rendered on the table grid (rows ``ti``) at wavelengths ``wl``
    (below-horizon nodes carry the limit from the hemisphere, :func:`sbrdf_xr.models.render`)."""
    mod, _, kw = models.model_parameters(_model_for(model, wl))
    return models.render_values(mod, ti, dt, ph, wl, kw)


def _model_at(
    model: xr.Dataset, ti: np.ndarray, dt: np.ndarray, ph: np.ndarray, wl: np.ndarray
) -> np.ndarray:
    """A model material's spectra at sample geometries (1-D angle arrays)."""
    return models.spectra(_model_for(model, wl), ti, dt, ph)


# ------------------------------------------------------------- reflectance


def hemispherical_reflectance(
    material: xr.DataArray,
    theta_i: ArrayLike | None = None,
    *,
    method: str = "linear",
    warn: bool = True,
) -> xr.DataArray:
    """Directional-hemispherical reflectance ``rho(theta_i, wavelength)`` of a table.

    Quadrature over the visible hemisphere of the interpolated table
    (:func:`sbrdf_xr._lut.hemispherical_reflectance_kernel`).  Values above one
    are non-physical (energy is not conserved) and issue a
    :class:`~sbrdf_xr.errors.NonPhysicalWarning` when ``warn`` is true.

    Parameters
    ----------
    material : xarray.DataArray
        Material table.
    theta_i : array_like, optional
        Incidence angles [degree]; default the table's own.
    method : str, default "linear"
        Look-up method of the integrand.
    warn : bool, default True
        Warn when any reflectance exceeds 1.

    Returns
    -------
    xarray.DataArray
        Dims ``(theta_i, wavelength)``, ``units = 1``; for an anisotropic table
        ``(theta_i, psi, wavelength)`` at the table's ``psi`` nodes: an observer on
        the far side of the illumination plane sees the mirror geometry, whose tangent
        is at ``-psi`` (:mod:`sbrdf_xr.anisotropy`), so the reflectance at ``psi`` is
        the mean of the slice integrals at ``psi`` and ``-psi`` (each integrates one
        side of the plane twice), the latter interpolated periodically.

    Examples
    --------
    The directional-hemispherical reflectance of a Lambertian table is its albedo:

    >>> import numpy as np
    >>> from sbrdf_xr.material import hemispherical_reflectance, lambertian
    >>> rho = hemispherical_reflectance(lambertian(0.5, [550.0]), [0.0, 30.0, 60.0])
    >>> rho.dims, rho.attrs["units"]
    (('theta_i', 'wavelength'), '1')
    >>> np.round(rho.values[:, 0], 4)
    array([0.5, 0.5, 0.5])
    """
    from ._names import PSI

    material = validate_material(material, check_values=False)
    grids = [np.asarray(material[d].values) for d in ANGLE_DIMS]
    ti = grids[0] if theta_i is None else np.atleast_1d(np.asarray(theta_i, dtype=np.float64))

    def kernel(values: np.ndarray) -> np.ndarray:
        return _lut.hemispherical_reflectance_kernel(
            values,
            grids[0],
            grids[1],
            grids[2],
            ti,
            method,
            zero_edges=_lut.table_edges(material.attrs),
            normal_blend=_lut.table_normal_blend(material.attrs),
        )

    coords = {THETA_I: (THETA_I, ti, attrs(THETA_I)), WAVELENGTH: material[WAVELENGTH]}
    if PSI in material.dims:
        from .anisotropy import psi_weights

        values = np.asarray(material.values)
        psi = np.asarray(material[PSI].values, dtype=np.float64)
        half = np.stack([kernel(values[:, :, :, k, :]) for k in range(psi.size)], axis=1)
        idx, w = psi_weights(psi, -psi)
        mirror = np.einsum("tkpl,kp->tkl", half[:, idx, :], w)
        rho = 0.5 * (half + mirror)
        dims: tuple[str, ...] = (THETA_I, PSI, WAVELENGTH)
        coords[PSI] = material[PSI]
    else:
        rho = kernel(np.asarray(material.values))
        dims = (THETA_I, WAVELENGTH)
    out = xr.DataArray(
        rho,
        dims=dims,
        coords=coords,
        name="reflectance",
        attrs=attrs("reflectance", material=material.attrs.get("material", "")),
    )
    if warn and np.any(rho > 1.0):
        worst = np.unravel_index(np.argmax(rho), rho.shape)
        warnings.warn(
            f"material {material.attrs.get('material', '')!r}: "
            "directional-hemispherical reflectance "
            f"reaches {rho[worst]:.3f} > 1 at theta_i = {ti[worst[0]]} deg, wavelength = "
            f"{material[WAVELENGTH].values[worst[-1]]} nm; the table does not conserve energy",
            NonPhysicalWarning,
            stacklevel=2,
        )
    return out
