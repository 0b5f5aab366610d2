"""Analytic materials as labelled parameter sets: evaluate, render to a table, measure.

A *model material* is an :class:`xarray.Dataset` holding the parameters of one of
the analytic models of :mod:`sbrdf_xr.brdf` over ``wavelength``: spectral
parameters as variables over ``wavelength`` (scalars broadcast), an optional
thin-film stack as ``layer_n``, ``layer_k`` ``(layer, wavelength)`` and
``layer_thickness`` ``(layer,)`` [nm], and the attributes ``model``, ``material``,
``source = model:<name>`` and ``provenance``.  It is the xarray layer over the
pure-numpy models:

* :func:`model_material` - build and validate one;
* :func:`spectra` - evaluate at paper-000 angles (numpy);
* :func:`render` - a look-up table on any grid (paper 000's by default);
* :func:`measure` - sample it with the virtual goniospectrometer
  (:mod:`sbrdf_xr.goniometer`), so that a table built from the measurements can
  be compared with its ground truth.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from . import brdf as _brdf
from ._names import ANISO_LUT_DIMS, DELTA_THETA, PHI, PSI, SBRDF, THETA_I, WAVELENGTH, attrs
from .errors import ValidationError
from .material_io import write_netcdf_atomic
from .material_schema import new_material

__all__ = [
    "PARAM_ATTRS",
    "fit_robertson_sandford",
    "measure",
    "model_material",
    "open_model",
    "render",
    "render_anisotropic",
    "render_values",
    "spectra",
    "spectrum_function",
    "to_netcdf",
]

PARAM_ATTRS: dict[str, dict[str, str]] = {
    "rho": {"units": "1", "long_name": "Lambertian albedo"},
    "rho_D": {"units": "1", "long_name": "diffuse spectral reflectance (Robertson-Sandford rho_D)"},
    "epsilon": {
        "units": "1",
        "long_name": "spectral hemispherical emissivity (Robertson-Sandford)",
    },
    "b": {"units": "1", "long_name": "grazing-angle parameter (Robertson-Sandford b)"},
    "e": {"units": "1", "long_name": "specular lobe width (Robertson-Sandford e)"},
    "roughness": {"units": "1", "long_name": "GGX roughness alpha"},
    "n": {"units": "1", "long_name": "substrate refractive index"},
    "k": {"units": "1", "long_name": "substrate extinction coefficient"},
    "rho_d": {"units": "1", "long_name": "Lambertian albedo added to the microfacet term"},
    "layer_n": {"units": "1", "long_name": "thin-film layer refractive index (ambient side first)"},
    "layer_k": {"units": "1", "long_name": "thin-film layer extinction coefficient"},
    "layer_thickness": {"units": "nm", "long_name": "thin-film layer thickness"},
    "alpha_x": {"units": "1", "long_name": "GGX roughness along the facet tangent"},
    "alpha_y": {"units": "1", "long_name": "GGX roughness across the facet tangent"},
}


def model_material(
    model: str,
    wavelength: ArrayLike,
    *,
    material: str,
    provenance: str,
    layers: Sequence[tuple[ArrayLike, float]] | None = None,
    **params: ArrayLike,
) -> xr.Dataset:
    """A validated model material.

    Parameters
    ----------
    model : str
        A name of :data:`sbrdf_xr.brdf.MODELS`.
    wavelength : array_like
        Wavelengths [nm].
    material : str
        Material name.
    provenance : str
        Where the parameters come from.
    layers : sequence of (complex index, thickness [nm]), optional
        Thin-film stack (``microfacet`` only), ambient side first.
    **params
        The model's parameters (see the model's ``check_params``).

    Returns
    -------
    xarray.Dataset
    """
    mod = _brdf.get_model(model)
    wl = np.asarray(wavelength, dtype=np.float64)
    checked = mod.check_params(wl, **params)
    data: dict[str, tuple[str | tuple[str, ...], np.ndarray, dict[str, str]]] = {
        k: (
            WAVELENGTH,
            np.asarray(v, dtype=np.float64),
            PARAM_ATTRS.get(k, {"units": "1", "long_name": k}),
        )
        for k, v in checked.items()
    }
    if layers:
        if model != "microfacet":
            raise ValidationError(
                f"layers: only the microfacet model has a thin-film stack, not {model!r}"
            )
        idx = np.stack(
            [np.broadcast_to(np.asarray(n, dtype=np.complex128), wl.shape) for n, _ in layers]
        )
        data["layer_n"] = (("layer", WAVELENGTH), idx.real, PARAM_ATTRS["layer_n"])
        data["layer_k"] = (("layer", WAVELENGTH), idx.imag, PARAM_ATTRS["layer_k"])
        thick = np.array([float(t) for _, t in layers])
        if np.any(thick < 0) or not np.all(np.isfinite(thick)):
            raise ValidationError(
                f"layers: thicknesses must be finite and >= 0 nm, got {thick.tolist()}"
            )
        data["layer_thickness"] = ("layer", thick, PARAM_ATTRS["layer_thickness"])
    ds = xr.Dataset(data, coords={WAVELENGTH: (WAVELENGTH, wl, attrs(WAVELENGTH))})
    ds.attrs = {
        "model": model,
        "material": material,
        "source": f"model:{model}",
        "provenance": provenance,
        "Conventions": "CF-1.10",
    }
    return ds


def _params(spec: xr.Dataset) -> tuple[Any, np.ndarray, dict[str, Any]]:
    if not isinstance(spec, xr.Dataset) or "model" not in spec.attrs:
        raise ValidationError("model material: expected a Dataset with a 'model' attribute")
    mod = _brdf.get_model(spec.attrs["model"])
    wl = np.asarray(spec[WAVELENGTH].values)
    kw: dict[str, Any] = {k: np.asarray(spec[k].values) for k in mod.PARAMS}
    if "layer_thickness" in spec:
        idx = np.asarray(spec["layer_n"].values) + 1j * np.asarray(spec["layer_k"].values)
        kw["layers"] = [(idx[j], float(t)) for j, t in enumerate(spec["layer_thickness"].values)]
    return mod, wl, kw


def _isotropic(mod: Any, spec: xr.Dataset) -> None:
    if getattr(mod, "ANISOTROPIC", False):
        raise ValidationError(
            f"model {spec.attrs['model']!r} is anisotropic: it needs the azimuth psi of the "
            "illumination plane from the facet tangent (render_anisotropic, spectra(..., psi=...))"
        )


def spectra(
    spec: xr.Dataset,
    theta_i: ArrayLike,
    delta_theta: ArrayLike,
    phi: ArrayLike,
    psi: ArrayLike | None = None,
) -> np.ndarray:
    """The model's spectra at paper-000 angles.

    Parameters
    ----------
    spec : xarray.Dataset
        A model material.
    theta_i, delta_theta, phi : array_like
        Angles [degree], broadcast together.
    psi : array_like, optional
        Azimuth of the illumination plane from the facet tangent [degree]: required by
        the anisotropic models (:data:`sbrdf_xr.brdf.ANISOTROPIC_MODELS`).

    Returns
    -------
    ndarray, shape broadcast + (n_wavelength,)
        sBRDF [sr-1].
    """
    mod, wl, kw = _params(spec)
    if psi is not None and getattr(mod, "ANISOTROPIC", False):
        return mod.brdf_angles(theta_i, delta_theta, phi, wl, psi=psi, **kw)
    _isotropic(mod, spec)
    return mod.brdf_angles(theta_i, delta_theta, phi, wl, **kw)


def spectrum_function(spec: xr.Dataset) -> Any:
    """``func(theta_i, delta_theta, phi) -> spectra`` of a model material (for the goniometer)."""

    def func(ti: np.ndarray, dt: np.ndarray, ph: np.ndarray) -> np.ndarray:
        return spectra(spec, ti, dt, ph)

    return func


def render(
    spec: xr.Dataset,
    theta_i: ArrayLike | None = None,
    delta_theta: ArrayLike | None = None,
    phi: ArrayLike | None = None,
    dtype: type | np.dtype = np.float64,
) -> xr.DataArray:
    """Render a model material to a look-up table.

    Parameters
    ----------
    spec : xarray.Dataset
        A model material.
    theta_i, delta_theta, phi : array_like, optional
        Grids [degree]; defaults: every integer 0-90, and -180..90 and 0-90 in
        3-degree steps (the whole visible hemisphere; with 141 wavelengths that is
        already 290 MB in float64: pass narrower grids for narrow lobes).
    dtype : numpy dtype

    Returns
    -------
    xarray.DataArray
        Material table with ``source = model:<name>``.
    """
    mod, wl, kw = _params(spec)
    ti = np.arange(0.0, 91.0) if theta_i is None else np.asarray(theta_i, dtype=np.float64)
    dt = (
        np.arange(-180.0, 91.0, 3.0)
        if delta_theta is None
        else np.asarray(delta_theta, dtype=np.float64)
    )
    ph = np.arange(0.0, 91.0, 3.0) if phi is None else np.asarray(phi, dtype=np.float64)
    for name, g in ((THETA_I, ti), (DELTA_THETA, dt), (PHI, ph)):
        if g.ndim != 1 or g.size == 0:
            raise ValidationError(
                f"{name}: expected a non-empty 1-D grid [degree], got shape {g.shape}"
            )
    _isotropic(mod, spec)
    vals = render_values(mod, ti, dt, ph, wl, kw)
    # Where the grid stops inside the hemisphere the model goes on: hold the edge
    # (exact for a Lambertian surface) rather than drop to zero.
    edges = {
        "edge_delta_theta_min": "zero" if dt[0] <= -180.0 else "hold",
        "edge_delta_theta_max": "zero" if dt[-1] >= 90.0 else "hold",
        "edge_phi_max": "zero" if ph[-1] >= 90.0 else "hold",
    }
    blend = min(float(ti[1] - ti[0]), 1.0) if ti.size > 1 and ti[0] == 0.0 else 0.0
    return new_material(
        vals.astype(dtype),
        ti,
        dt,
        ph,
        wl,
        material=spec.attrs["material"],
        source=spec.attrs["source"],
        provenance=f"{spec.attrs.get('provenance', '')}; rendered by sbrdf_xr.models.render",
        model=spec.attrs["model"],
        normal_incidence="symmetric",
        normal_incidence_blend=blend,
        **edges,
    )


def render_anisotropic(
    spec: xr.Dataset,
    theta_i: ArrayLike,
    delta_theta: ArrayLike,
    phi: ArrayLike,
    psi: ArrayLike,
    dtype: type | np.dtype = np.float64,
) -> xr.DataArray:
    """Render an anisotropic model material to a table with a ``psi`` axis.

    Layout: a ``DataArray`` named ``sbrdf`` with dims ``(theta_i, delta_theta, phi,
    psi, wavelength)`` (:data:`sbrdf_xr._names.ANISO_LUT_DIMS`), every ``psi`` slice an
    isotropic table on the same grids (same attributes, edges and below-horizon
    treatment as :func:`render`).  ``psi`` [degree] is the azimuth of the
    illumination plane from the facet tangent, in ``[0, 180]`` (periodic:
    ``psi = 180`` is ``psi = 0``; :func:`sbrdf_xr.brdf.anisotropic.illumination_azimuth`
    gives it for a geometry).  Look-up: :func:`sbrdf_xr.material.lookup_anisotropic`.

    Parameters
    ----------
    spec : xarray.Dataset
        A model material of an anisotropic model.
    theta_i, delta_theta, phi, psi : array_like
        1-D grids [degree].
    dtype : numpy dtype

    Returns
    -------
    xarray.DataArray
    """
    mod, wl, kw = _params(spec)
    if not getattr(mod, "ANISOTROPIC", False):
        raise ValidationError(f"model {spec.attrs['model']!r} is isotropic: use render")
    grids = [np.asarray(a, dtype=np.float64) for a in (theta_i, delta_theta, phi, psi)]
    for name, g in zip((THETA_I, DELTA_THETA, PHI, PSI), grids, strict=True):
        if g.ndim != 1 or g.size == 0 or np.any(np.diff(g) <= 0):
            raise ValidationError(
                f"{name}: expected a non-empty, strictly increasing 1-D grid [degree]"
            )
    ps = grids[3]
    if ps[0] < 0 or ps[-1] > 180:
        raise ValidationError(f"psi: must lie in [0, 180] degree, got [{ps[0]}, {ps[-1]}]")
    m = HORIZON_MARGIN_DEG
    t4, d4, p4, s4 = np.meshgrid(*grids, indexing="ij")
    t_c = np.minimum(t4, 90.0 - GRAZING_MARGIN_DEG)
    r_c = np.clip(t4 + d4, -(90.0 - m), 90.0 - m)
    vals = mod.brdf_angles(t_c, r_c - t_c, np.minimum(p4, 90.0 - m), wl, psi=s4, **kw)
    dt, ph = grids[1], grids[2]
    a = attrs(
        SBRDF,
        material=spec.attrs["material"],
        source=spec.attrs["source"],
        provenance=(
            f"{spec.attrs.get('provenance', '')}; rendered by sbrdf_xr.models.render_anisotropic"
        ),
        model=spec.attrs["model"],
        edge_delta_theta_min="zero" if dt[0] <= -180.0 else "hold",
        edge_delta_theta_max="zero" if dt[-1] >= 90.0 else "hold",
        edge_phi_max="zero" if ph[-1] >= 90.0 else "hold",
    )
    coords = {
        n: (n, g, attrs(n)) for n, g in zip((THETA_I, DELTA_THETA, PHI, PSI), grids, strict=True)
    }
    coords[WAVELENGTH] = (WAVELENGTH, wl, attrs(WAVELENGTH))
    out = xr.DataArray(vals.astype(dtype), dims=ANISO_LUT_DIMS, coords=coords, name=SBRDF, attrs=a)
    return out


#: Nodes are evaluated at least this far inside the lit and visible hemisphere [degree].
HORIZON_MARGIN_DEG = 1e-6
#: A ``theta_i = 90`` row is evaluated this far from grazing incidence [degree]: the
#: specular peak of a microfacet model diverges as both directions graze, and a
#: table node carries a value for the whole cell around it.
GRAZING_MARGIN_DEG = 0.5


def render_values(
    mod: Any, ti: np.ndarray, dt: np.ndarray, ph: np.ndarray, wl: np.ndarray, kw: dict[str, Any]
) -> np.ndarray:
    """A model's sBRDF on the outer product of 1-D grids, every node inside the hemisphere.

    A node whose geometry is not lit and visible (``theta_i`` = 90 deg, the observer
    at or below the horizon: ``|theta_i + delta_theta| >= 90`` or ``phi >= 90``)
    carries the model's limit from inside the hemisphere: it is evaluated at the
    nearest lit and visible geometry, :data:`HORIZON_MARGIN_DEG` inside the horizon
    and :data:`GRAZING_MARGIN_DEG` from grazing incidence.  Interpolating
    between such a node and a visible one then never blends in a zero that the
    physics does not have (a Lambertian surface renders to ``rho / pi`` at every node).

    Parameters
    ----------
    mod : module
        A model of :data:`sbrdf_xr.brdf.MODELS`.
    ti, dt, ph : ndarray, 1-D
        Grids [degree].
    wl : ndarray
        Wavelengths [nm].
    kw : dict
        The model's parameters.

    Returns
    -------
    ndarray, shape (n_ti, n_dt, n_phi, n_wl)
        sBRDF [sr-1].
    """
    m = HORIZON_MARGIN_DEG
    t3, d3, p3 = np.meshgrid(
        np.asarray(ti, float), np.asarray(dt, float), np.asarray(ph, float), indexing="ij"
    )
    t_c = np.minimum(t3, 90.0 - GRAZING_MARGIN_DEG)
    r_c = np.clip(t3 + d3, -(90.0 - m), 90.0 - m)
    p_c = np.minimum(p3, 90.0 - m)
    return mod.brdf_angles(t_c, r_c - t_c, p_c, wl, **kw)


def measure(spec: xr.Dataset, theta_i: Sequence[float], **kwargs: Any) -> xr.Dataset:
    """Measure a model material with the virtual goniospectrometer.

    Parameters
    ----------
    spec : xarray.Dataset
        A model material (the ground truth).
    theta_i : sequence of float
        Incidence angles [degree].
    **kwargs
        Passed to :func:`sbrdf_xr.goniometer.measure` (``noise``, ``seed``,
        ``noise_floor``, apparatus limits).

    Returns
    -------
    xarray.Dataset
        The measurement set, labelled ``synthetic`` with the model as provenance.
    """
    from .goniometer import measure as _measure

    wl = np.asarray(spec[WAVELENGTH].values)
    prov = (
        f"virtual goniospectrometer measurement of model {spec.attrs['model']!r} "
        f"({spec.attrs.get('provenance', '')})"
    )
    return _measure(
        spectrum_function(spec),
        wl,
        theta_i,
        material=spec.attrs["material"],
        source="synthetic",
        provenance=prov,
        **kwargs,
    )


def fit_robertson_sandford(measurements: xr.Dataset, **kwargs: Any) -> xr.Dataset:
    """Fit the Robertson-Sandford model (paper 001) to a measurement set.

    Wraps :func:`sbrdf_xr.brdf.robertson_sandford_fit.fit_robertson_sandford`
    (log-residual least squares; ``rho_D`` and ``epsilon`` per wavelength, shared
    ``b`` and ``e``) and returns a model material with the standard uncertainties
    as variables ``u_rho_D``, ``u_epsilon``, ``u_b``, ``u_e`` and the reduced
    chi-square as an attribute.  Where the fit lands marginally outside
    ``rho_D + epsilon <= G(b)`` (Eq. 17's ``rho_s >= 0``; the fit bounds each
    parameter, not their sum), ``epsilon`` gives way.

    Parameters
    ----------
    measurements : xarray.Dataset
        A measurement set (:func:`sbrdf_xr.material.validate_measurements`).
    **kwargs
        Passed to the numpy fit (``sigma``, ``cutoff``).

    Returns
    -------
    xarray.Dataset
        The fitted model material.
    """
    from ._names import MEASURED, SAMPLE
    from .brdf import robertson_sandford as rs
    from .brdf import robertson_sandford_fit
    from .material_schema import reference_mask, validate_measurements

    ds = validate_measurements(measurements, duplicates="mean")
    wl = np.asarray(ds[WAVELENGTH].values, dtype=np.float64)
    spectra = np.asarray(ds[MEASURED].transpose(SAMPLE, WAVELENGTH).values, dtype=np.float64)
    fit = robertson_sandford_fit.fit_robertson_sandford(
        ds[THETA_I].values,
        ds[DELTA_THETA].values,
        ds[PHI].values,
        wl,
        spectra,
        reference=reference_mask(ds),
        **kwargs,
    )
    p: dict[str, Any] = {k: np.asarray(fit[k], dtype=np.float64) for k in rs.PARAMS}
    g_b = float(rs.normalisation_G(p["b"]))
    p["epsilon"] = np.minimum(
        np.broadcast_to(p["epsilon"], wl.shape), np.maximum(g_b - p["rho_D"], 0.0)
    )
    name = ds.attrs.get("material", "unnamed")
    out = model_material(
        "robertson_sandford",
        wl,
        material=name,
        provenance=f"Robertson-Sandford fit to the measurements of {name} "
        f"(reduced chi-square {fit['chi2_reduced']:.3g}, {fit['n_used']} residuals)",
        **p,
    )
    for k in rs.PARAMS:
        u = np.broadcast_to(np.asarray(fit[f"u_{k}"], dtype=np.float64), wl.shape)
        out[f"u_{k}"] = (
            WAVELENGTH,
            np.array(u),
            {"units": "1", "long_name": f"standard uncertainty of {k}"},
        )
    out.attrs["chi2_reduced"] = float(fit["chi2_reduced"])
    out.attrs["source"] = "model:robertson_sandford"
    return out


def to_netcdf(spec: xr.Dataset, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
    """Write a model material to netCDF (atomic, lossless)."""
    _params(spec)
    return write_netcdf_atomic(spec, path, overwrite=overwrite)


def open_model(path: str | os.PathLike[str]) -> xr.Dataset:
    """Read a model material written by :func:`to_netcdf`."""
    with xr.open_dataset(path, engine="netcdf4") as ds:
        ds = ds.load()
    _params(ds)
    return ds
