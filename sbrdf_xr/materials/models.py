"""Analytic materials as labelled parameter sets: evaluate, render to a table, measure.

A *model material* is an :class:`xarray.Dataset` holding the parameters of one of
the analytic models of :mod:`sbrdf_xr.brdf` over ``wavelength``
(:mod:`sbrdf_xr.materials.model_schema`).  This module is the xarray layer over the pure-numpy
models:

* :func:`model_material` - build and validate one (the metadata of each parameter is
  its model's declaration, :class:`sbrdf_xr.brdf.Parameter`);
* :func:`model_parameters` - the model and the keyword arguments of its functions;
* :func:`spectra` - evaluate at paper-000 angles (numpy);
* :func:`render` - a look-up table on any grid (paper 000's by default);
* :func:`measure` - sample it with the virtual goniospectrometer
  (:mod:`sbrdf_xr.materials.goniometer`), so that a table built from the measurements can
  be compared with its ground truth.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from .._names import ANISO_LUT_DIMS, DELTA_THETA, PHI, PSI, SBRDF, THETA_I, WAVELENGTH, attrs
from ..brdf import Model
from ..errors import ValidationError
from ..units import to_unit
from .model_schema import ModelParameters, model_material, model_parameters, open_model, to_netcdf
from .schema import new_material

__all__ = [
    "FITS",
    "ModelParameters",
    "fit_microfacet",
    "fit_model",
    "fit_robertson_sandford",
    "fit_robertson_sandford_core",
    "fit_robertson_sandford_halo",
    "measure",
    "model_material",
    "model_parameters",
    "open_model",
    "render",
    "render_anisotropic",
    "render_values",
    "spectra",
    "spectrum_function",
    "to_netcdf",
]


def _require_isotropic(m: Model) -> None:
    if m.anisotropic:
        raise ValidationError(
            f"model {m.name!r} is anisotropic: it needs the azimuth psi of the "
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
        the anisotropic models (:data:`sbrdf_xr.brdf.ANISOTROPIC_MODELS`), ignored by
        the isotropic ones.

    Returns
    -------
    ndarray, shape broadcast + (n_wavelength,)
        sBRDF [sr-1].

    Examples
    --------
    >>> import numpy as np
    >>> spec = model_material("lambert", [550.0], material="grey", provenance="doc", rho=0.5)
    >>> np.round(spectra(spec, [0.0, 60.0], 0.0, 0.0) * np.pi, 6)
    array([[0.5],
           [0.5]])
    """
    m, wl, kw = model_parameters(spec)
    if m.anisotropic and psi is not None:
        return m.brdf_angles(theta_i, delta_theta, phi, wl, psi=psi, **kw)
    _require_isotropic(m)
    return m.brdf_angles(theta_i, delta_theta, phi, wl, **kw)


def spectrum_function(spec: xr.Dataset, psi: float | None = None) -> Any:
    """``func(theta_i, delta_theta, phi) -> spectra`` of a model material (for the goniometer).

    Parameters
    ----------
    spec : Dataset
        A model material.
    psi : float, optional
        For an anisotropic model, the azimuth of the illumination plane from the
        sample's tangent [degree] (a sample rotation,
        :func:`sbrdf_xr.materials.tables.build_lut_anisotropic`); a Quantity is converted.

    Examples
    --------
    >>> import numpy as np
    >>> spec = model_material("lambert", [550.0], material="grey", provenance="doc", rho=0.5)
    >>> f = spectrum_function(spec)
    >>> np.round(f(np.array([30.0]), np.array([0.0]), np.array([0.0])) * np.pi, 6)
    array([[0.5]])
    """
    psi = to_unit(psi, "deg", "psi")

    def func(ti: np.ndarray, dt: np.ndarray, ph: np.ndarray) -> np.ndarray:
        if psi is None:
            return spectra(spec, ti, dt, ph)
        return spectra(spec, ti, dt, ph, psi=np.full(np.shape(ti), float(psi)))

    return func


def render(
    spec: xr.Dataset,
    theta_i: ArrayLike | None = None,
    delta_theta: ArrayLike | None = None,
    phi: ArrayLike | None = None,
    dtype: type | np.dtype = np.float64,
    progress: bool = True,
    max_bytes: float | None = None,
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
    progress : bool, default True
        Show a progress bar (tqdm.auto) while rendering a large table (2e7 values and
        more: seconds).
    max_bytes : float, optional
        Refuse (ValidationError, with the size) a table larger than this [byte], before
        allocating it.

    Returns
    -------
    xarray.DataArray
        Material table with ``source = model:<name>``.

    Examples
    --------
    >>> import numpy as np
    >>> spec = model_material("lambert", [550.0], material="grey", provenance="doc", rho=0.5)
    >>> lut = render(spec, [0.0, 45.0, 90.0], [-180.0, 0.0, 90.0], [0.0, 90.0])
    >>> lut.dims, lut.shape
    (('theta_i', 'delta_theta', 'phi', 'wavelength'), (3, 3, 2, 1))
    >>> bool(np.allclose(lut * np.pi, 0.5, rtol=1e-12))
    True
    """
    theta_i, phi = to_unit(theta_i, "deg", THETA_I), to_unit(phi, "deg", PHI)
    delta_theta = to_unit(delta_theta, "deg", DELTA_THETA)
    max_bytes = to_unit(max_bytes, "byte", "max_bytes")
    m, wl, kw = model_parameters(spec)
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
    _require_isotropic(m)
    size = float(ti.size) * dt.size * ph.size * wl.size * np.dtype(dtype).itemsize
    if max_bytes is not None and size > max_bytes:
        raise ValidationError(
            f"model {spec.attrs.get('material', '')!r}: its table would hold {size:.3g} bytes "
            f"({ti.size} x {dt.size} x {ph.size} angles x {wl.size} wavelengths), above the "
            f"limit of {max_bytes:.3g}; give the model fewer wavelengths or raise size_limit"
        )
    vals = np.empty((ti.size, dt.size, ph.size, wl.size), dtype=dtype)
    step = max(1, _RENDER_CHUNK // (dt.size * ph.size * wl.size))  # bounded temporaries
    from tqdm.auto import tqdm

    with tqdm(
        total=ti.size,
        desc=f"rendering model {spec.attrs['material']}",
        unit="row",
        disable=not progress or vals.size < _PROGRESS_MIN,
    ) as bar:
        for a in range(0, ti.size, step):
            vals[a : a + step] = m.render_grid(ti[a : a + step], dt, ph, wl, horizon="limit", **kw)
            bar.update(min(step, ti.size - a))
    # Where the grid stops inside the hemisphere the model goes on: hold the edge
    # (exact for a Lambertian surface) rather than drop to zero.
    blend = min(float(ti[1] - ti[0]), 1.0) if ti.size > 1 and ti[0] == 0.0 else 0.0
    return new_material(
        vals,
        ti,
        dt,
        ph,
        wl,
        material=spec.attrs["material"],
        source=spec.attrs["source"],
        provenance=(
            f"{spec.attrs.get('provenance', '')}; rendered by sbrdf_xr.materials.models.render"
        ),
        model=spec.attrs["model"],
        normal_incidence="symmetric",
        normal_incidence_blend=blend,
        **_edges(dt, ph),
    )


#: Table values :func:`render` computes at once (bounds its temporaries).
_RENDER_CHUNK = 2_000_000
#: Table values from which :func:`render` shows a progress bar (a few seconds' work).
_PROGRESS_MIN = 20_000_000


def _edges(dt: np.ndarray, ph: np.ndarray) -> dict[str, str]:
    """Edge policies of a rendered table: zero at the hemisphere's edge, else hold."""
    return {
        "edge_delta_theta_min": "zero" if dt[0] <= -180.0 else "hold",
        "edge_delta_theta_max": "zero" if dt[-1] >= 90.0 else "hold",
        "edge_phi_max": "zero" if ph[-1] >= 90.0 else "hold",
    }


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
    gives it for a geometry).  Look-up: :func:`sbrdf_xr.materials.tables.lookup_anisotropic`.

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

    Examples
    --------
    >>> spec = model_material("anisotropic_microfacet", [550.0], material="brushed",
    ...                       provenance="doc", alpha_x=0.1, alpha_y=0.3, n=1.0, k=6.0,
    ...                       rho_d=0.0)
    >>> tab = render_anisotropic(spec, [30.0], [0.0], [0.0, 10.0], [0.0, 90.0])
    >>> tab.dims, tab.shape
    (('theta_i', 'delta_theta', 'phi', 'psi', 'wavelength'), (1, 1, 2, 2, 1))
    """
    m, wl, kw = model_parameters(spec)
    if not m.anisotropic:
        raise ValidationError(f"model {m.name!r} is isotropic: use render")
    named = {THETA_I: theta_i, DELTA_THETA: delta_theta, PHI: phi, PSI: psi}
    grids = [np.asarray(to_unit(a, "deg", k), dtype=np.float64) for k, a in named.items()]
    for name, g in zip((THETA_I, DELTA_THETA, PHI, PSI), grids, strict=True):
        if g.ndim != 1 or g.size == 0 or np.any(np.diff(g) <= 0):
            raise ValidationError(
                f"{name}: expected a non-empty, strictly increasing 1-D grid [degree]"
            )
    ps = grids[3]
    if ps[0] < 0 or ps[-1] > 180:
        raise ValidationError(f"psi: must lie in [0, 180] degree, got [{ps[0]}, {ps[-1]}]")
    vals = m.render_grid(grids[0], grids[1], grids[2], wl, psi=ps, horizon="limit", **kw)
    a = attrs(
        SBRDF,
        material=spec.attrs["material"],
        source=spec.attrs["source"],
        provenance=(
            f"{spec.attrs.get('provenance', '')}; "
            "rendered by sbrdf_xr.materials.models.render_anisotropic"
        ),
        model=spec.attrs["model"],
        **_edges(grids[1], grids[2]),
    )
    coords = {
        n: (n, g, attrs(n)) for n, g in zip((THETA_I, DELTA_THETA, PHI, PSI), grids, strict=True)
    }
    coords[WAVELENGTH] = (WAVELENGTH, wl, attrs(WAVELENGTH))
    return xr.DataArray(vals.astype(dtype), dims=ANISO_LUT_DIMS, coords=coords, name=SBRDF, attrs=a)


def render_values(
    model: Model,
    ti: np.ndarray,
    dt: np.ndarray,
    ph: np.ndarray,
    wl: np.ndarray,
    kw: dict[str, Any],
) -> np.ndarray:
    """A model's sBRDF on the outer product of 1-D grids, every node inside the hemisphere.

    A node whose geometry is not lit and visible carries the model's limit from
    inside the hemisphere (``model.render_grid(..., horizon="limit")``,
    :meth:`sbrdf_xr.brdf.Model.render_grid`): interpolating between such a node
    and a visible one then never blends in a zero that the physics does not have.

    Parameters
    ----------
    model : Model
        A model of :data:`sbrdf_xr.brdf.BRDF_MODELS` (isotropic).
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

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.brdf import get_model
    >>> v = render_values(get_model("lambert"), np.array([0.0, 90.0]), np.array([0.0]),
    ...                   np.array([0.0, 90.0]), np.array([550.0]), {"rho": 0.5})
    >>> v.shape, np.round(v.ravel() * np.pi, 6).tolist()
    ((2, 1, 2, 1), [0.5, 0.5, 0.5, 0.5])
    """
    ti, dt, ph = (to_unit(a, "deg", k) for k, a in (("ti", ti), ("dt", dt), ("ph", ph)))
    wl = to_unit(wl, "nm", "wl", spectral=True)
    return model.render_grid(ti, dt, ph, wl, horizon="limit", **kw)


def measure(spec: xr.Dataset, theta_i: Sequence[float], **kwargs: Any) -> xr.Dataset:
    """Measure a model material with the virtual goniospectrometer.

    Parameters
    ----------
    spec : xarray.Dataset
        A model material (the ground truth).
    theta_i : sequence of float
        Incidence angles [degree].
    **kwargs
        Passed to :func:`sbrdf_xr.materials.goniometer.measure` (``noise``, ``seed``,
        ``noise_floor``, apparatus limits).

    Returns
    -------
    xarray.Dataset
        The measurement set, labelled ``synthetic`` with the model as provenance.

    Examples
    --------
    >>> spec = model_material("robertson_sandford", [500.0, 700.0], material="paint",
    ...                       provenance="doc", rho_D=0.6, epsilon=0.2, b=0.1, e=0.3)
    >>> meas = measure(spec, [20.0, 40.0, 60.0])
    >>> dict(meas.sizes), meas.attrs["source"]
    ({'sample': 90, 'wavelength': 2}, 'synthetic')
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
        A measurement set (:func:`sbrdf_xr.materials.tables.validate_measurements`).
    **kwargs
        Passed to the numpy fit (``sigma``, ``cutoff``).

    Returns
    -------
    xarray.Dataset
        The fitted model material.

    Examples
    --------
    >>> spec = model_material("robertson_sandford", [500.0, 700.0], material="paint",
    ...                       provenance="doc", rho_D=0.6, epsilon=0.2, b=0.1, e=0.3)
    >>> fit = fit_robertson_sandford(measure(spec, [20.0, 40.0, 60.0]))
    >>> round(float(fit.b[0]), 6), round(float(fit.e[0]), 6), fit.rho_D.values.round(6).tolist()
    (0.1, 0.3, [0.6, 0.6])
    """
    from .._names import MEASURED, SAMPLE
    from ..brdf import robertson_sandford as rs
    from ..brdf import robertson_sandford_fit
    from .schema import reference_mask, validate_measurements

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
    m = rs.MODEL
    p: dict[str, Any] = {k: np.asarray(fit[k], dtype=np.float64) for k in m.param_names}
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
    for k in m.param_names:
        u = np.broadcast_to(np.asarray(fit[f"u_{k}"], dtype=np.float64), wl.shape)
        u_attrs = {"units": m.parameter(k).units, "long_name": f"standard uncertainty of {k}"}
        out[f"u_{k}"] = (WAVELENGTH, np.array(u), u_attrs)
    out.attrs["chi2_reduced"] = float(fit["chi2_reduced"])
    out.attrs["source"] = "model:robertson_sandford"
    return out


def fit_microfacet(measurements: xr.Dataset) -> xr.Dataset:
    """Fit the microfacet model (Walter et al. 2007, GGX plus Lambert) to a measurement set.

    Wraps :func:`sbrdf_xr.brdf.microfacet_fit.fit_microfacet` (log-residual least
    squares: ``roughness`` shared, ``n`` and ``rho_d`` per wavelength, ``k = 0``).

    Parameters
    ----------
    measurements : xarray.Dataset
        A measurement set (:func:`sbrdf_xr.materials.tables.validate_measurements`).

    Returns
    -------
    xarray.Dataset
        The fitted model material (attribute ``rms_log``, the fit's root-mean-square
        log residual [1]).

    Examples
    --------
    >>> spec = model_material("microfacet", [550.0], material="paint", provenance="doc",
    ...                       roughness=0.05, n=3.0, k=0.0, rho_d=0.1)
    >>> fit = fit_microfacet(measure(spec, [20.0, 40.0, 60.0]))
    >>> round(float(fit.roughness[0]), 6), round(float(fit.n[0]), 6), round(float(fit.rho_d[0]), 6)
    (0.05, 3.0, 0.1)
    """
    from .._names import MEASURED, SAMPLE
    from ..brdf import microfacet_fit
    from .schema import reference_mask, validate_measurements

    ds = validate_measurements(measurements, duplicates="mean")
    wl = np.asarray(ds[WAVELENGTH].values, dtype=np.float64)
    spectra = np.asarray(ds[MEASURED].transpose(SAMPLE, WAVELENGTH).values, dtype=np.float64)
    angles = (ds[THETA_I].values, ds[DELTA_THETA].values, ds[PHI].values)
    fit = microfacet_fit.fit_microfacet(*angles, wl, spectra, reference=reference_mask(ds))
    name = ds.attrs.get("material", "unnamed")
    out = model_material(
        "microfacet", wl, material=name,
        provenance=f"microfacet (GGX) fit to the measurements of {name} (rms log residual "
        f"{fit['rms_log']:.3g}, {fit['n_used']} residuals)",
        roughness=fit["roughness"], n=fit["n"], k=fit["k"], rho_d=fit["rho_d"],
    )  # fmt: skip
    out.attrs["rms_log"] = fit["rms_log"]
    out.attrs["source"] = "model:microfacet"
    return out


def fit_robertson_sandford_core(measurements: xr.Dataset) -> xr.Dataset:
    """Fit the Robertson-Sandford model with a specular core to a measurement set.

    The body is :func:`fit_robertson_sandford`'s; the core (Beckmann, one rms slope,
    a reflectance per wavelength that follows the incidence angle and is bounded by the
    body's emissivity; :mod:`sbrdf_xr.brdf.specular_core`) is then fitted beside it to
    all the samples, in the values, each scan's core free to sit a fraction of a degree
    from specular (:func:`sbrdf_xr.brdf.specular_core.fit_core`).  The
    body is then fitted again without the samples where the fitted core exceeds it,
    and the core again beside it, until the core's rms slope changes by less than 0.1 %
    (at most :data:`_CORE_ITERATIONS` times): a body fitted to the core's samples
    widens to take part of the core.  For a
    near-mirror whose core is narrower than a broad lobe can follow (the Starlink
    chassis).

    Parameters
    ----------
    measurements : xarray.Dataset
        A measurement set (:func:`sbrdf_xr.materials.tables.validate_measurements`).

    Returns
    -------
    xarray.Dataset
        The fitted model material (``robertson_sandford_core``; attribute ``rms_log``,
        the core fit's root-mean-square log residual [1]).

    Examples
    --------
    >>> spec = model_material("robertson_sandford_core", [550.0], material="glint",
    ...                       provenance="doc", rho_D=0.3, epsilon=0.1, b=0.1, e=0.3,
    ...                       core_rho=0.2, core_roughness=0.01)
    >>> fit = fit_robertson_sandford_core(measure(spec, [20.0, 40.0, 60.0]))
    >>> fit.attrs["source"], bool(fit.core_rho[0] > 0)
    ('model:robertson_sandford_core', True)
    """
    return _fit_body_core(measurements, halo=False)


def fit_robertson_sandford_halo(measurements: xr.Dataset) -> xr.Dataset:
    """Fit the Robertson-Sandford model with a specular core and an ABg halo.

    As :func:`fit_robertson_sandford_core`, with the core and a Harvey-Shack ABg halo
    (:mod:`sbrdf_xr.brdf.halo`) fitted together beside the body, in the logarithm,
    after each fit of the core alone (:func:`sbrdf_xr.brdf.halo.fit_halo`); the body
    refitted without the samples where core and halo together exceed it, until the
    core's rms slope and the halo's power change by less than 0.1 %.  For a near-mirror
    whose measured peak falls to the body through a halo of a few degrees (the
    Starlink chassis).

    Parameters
    ----------
    measurements : xarray.Dataset
        A measurement set (:func:`sbrdf_xr.materials.tables.validate_measurements`).

    Returns
    -------
    xarray.Dataset
        The fitted model material (``robertson_sandford_halo``; attribute ``rms_log``,
        the fit's root-mean-square log residual [1]).

    Examples
    --------
    >>> spec = model_material("robertson_sandford_halo", [550.0], material="glint",
    ...                       provenance="doc", rho_D=0.3, epsilon=0.1, b=0.1, e=0.3,
    ...                       core_rho=0.2, core_roughness=0.01, halo_a=1e-3,
    ...                       halo_b=1e-5, halo_g=2.5)
    >>> fit = fit_robertson_sandford_halo(measure(spec, [20.0, 40.0, 60.0]))
    >>> fit.attrs["source"], bool(fit.halo_a[0] > 0)
    ('model:robertson_sandford_halo', True)
    """
    return _fit_body_core(measurements, halo=True)


def _fit_body_core(measurements: xr.Dataset, halo: bool) -> xr.Dataset:
    """The body, the core and (``halo``) the halo fitted in turn (the fits above)."""
    from .._names import MEASURED, SAMPLE
    from ..brdf import halo as halo_model
    from ..brdf import specular_core
    from ..geometry import facet_vectors
    from .schema import reference_mask, validate_measurements

    ds = validate_measurements(measurements, duplicates="mean")
    wl = np.asarray(ds[WAVELENGTH].values, dtype=np.float64)
    angles = (ds[THETA_I].values, ds[DELTA_THETA].values, ds[PHI].values)
    spectra_ = np.asarray(ds[MEASURED].transpose(SAMPLE, WAVELENGTH).values, dtype=np.float64)
    ref = reference_mask(ds)
    body_at = np.ones(ref.size, dtype=bool)  # the samples the body is fitted to
    last = np.array([np.inf, np.inf])
    vectors = facet_vectors(*angles)
    for _ in range(_CORE_ITERATIONS):
        body = fit_robertson_sandford(ds.isel({SAMPLE: np.flatnonzero(body_at)}))
        b_vals = spectra(body, *angles)
        core = specular_core.fit_core(*angles, spectra_, b_vals, reference=ref)
        if halo:
            core = halo_model.fit_halo(*angles, spectra_, b_vals, core, reference=ref)
        now = np.array([core["core_roughness"], core.get("halo_g", 1.0)])
        if np.all(np.abs(now / last - 1.0) < 1e-3):
            break
        last = now
        c_vals = specular_core.core_brdf(
            *vectors,
            core["core_rho"] * np.cos(np.radians(angles[0]))[:, None],  # its fitted law
            np.full(core["core_rho"].shape, core["core_roughness"]),
        )
        if halo:
            h = [np.broadcast_to(core[k], wl.shape) for k in ("halo_a", "halo_b", "halo_g")]
            c_vals = c_vals + halo_model.halo_brdf(*vectors, *h)
        body_at = np.all(c_vals < b_vals, axis=1) | ref  # the core's samples left to it
    name = ds.attrs.get("material", "unnamed")
    params: dict[str, Any] = {k: body[k].values for k in ("rho_D", "epsilon", "b", "e")}
    params.update(core_rho=core["core_rho"], core_roughness=core["core_roughness"])
    what, model = "a specular core", "robertson_sandford_core"
    if halo:
        params.update({k: core[k] for k in ("halo_a", "halo_b", "halo_g")})
        what = f"a specular core and an ABg halo (g {core['halo_g']:.3g}, B {core['halo_b']:.3g})"
        model = "robertson_sandford_halo"
    out = model_material(
        model, wl, material=name,
        provenance=f"Robertson-Sandford fit with {what} to the measurements of {name} "
        f"(core rms slope {core['core_roughness']:.3g}, core offsets "
        f"{', '.join(f'{x:.2f}' for x in core['core_offset'])} deg, rms log residual "
        f"{core['rms_log']:.3g}, {core['n_used']} residuals)",
        **params,
    )  # fmt: skip
    out.attrs["rms_log"] = core["rms_log"]
    out.attrs["source"] = f"model:{model}"
    return out


#: Most fits of the body and the core of :func:`fit_robertson_sandford_core`.
_CORE_ITERATIONS = 8

#: The model fits :func:`~sbrdf_xr.materials.build.build_lut` can fill a table with, by name.
FITS = {
    "robertson-sandford": fit_robertson_sandford,
    "microfacet": fit_microfacet,
    "robertson-sandford-core": fit_robertson_sandford_core,
    "robertson-sandford-halo": fit_robertson_sandford_halo,
}


def fit_model(measurements: xr.Dataset, name: str = "robertson-sandford") -> xr.Dataset:
    """The fit :data:`FITS` names, of a measurement set.

    Parameters
    ----------
    measurements : xarray.Dataset
        A measurement set.
    name : str
        The fit: ``"robertson-sandford"``, ``"microfacet"``, ``"robertson-sandford-core"``
        or ``"robertson-sandford-halo"``.

    Returns
    -------
    xarray.Dataset
        The fitted model material.

    Raises
    ------
    ValidationError
        An unknown name.

    Examples
    --------
    >>> spec = model_material("microfacet", [550.0], material="paint", provenance="doc",
    ...                       roughness=0.05, n=3.0, k=0.0, rho_d=0.1)
    >>> fit_model(measure(spec, [20.0, 40.0]), "microfacet").attrs["source"]
    'model:microfacet'
    """
    if name not in FITS:
        raise ValidationError(f"model: got {name!r}; allowed: {', '.join(FITS)} or a model")
    return FITS[name](measurements)
