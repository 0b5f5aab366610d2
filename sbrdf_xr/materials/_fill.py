"""How :func:`sbrdf_xr.materials.build_lut` fills its table: the measured values splined
over the incidence angle (zero below the noise), or a fitted model times the measured
ratio to it; the model evaluated on the grid and at the samples.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import xarray as xr

from .._names import WAVELENGTH
from ..kernels import lut as _lut
from . import models
from ._jobs import _by_rows, _Done, _Job, _Parts
from .construction import _held_product, blend_weights, extend_grid, per_theta_tables
from .coverage import _ratio_across_theta, _ratio_tables


@dataclass
class Samples:
    """The measured samples: incidence angles measured, the snapped angles [degree] of
    every sample, the spectra (0 at reference points), the reference mask, whether the
    scans are rows, the wavelengths [nm]."""

    measured_ti: np.ndarray
    ti_s: np.ndarray
    dt_s: np.ndarray
    ph_s: np.ndarray
    spectra: np.ndarray
    ref: np.ndarray
    rows_only: bool
    wl: np.ndarray


@dataclass
class Grid:
    """The table's grid [degree] and the smoothing of its spline over ``theta_i``."""

    ti: np.ndarray
    dt: np.ndarray
    phi: np.ndarray
    lam: float


def zero_below_noise(
    s: Samples,
    g: Grid,
    extrapolation: str,
    fit_model: xr.Dataset | None,
    blend: float,
    report: Callable[[float, str], None],
) -> tuple[np.ndarray, dict[str, str]]:
    """The table of the measured values (zero below the noise) splined over ``theta_i``,
    the model blended in over ``blend`` [degree] beyond the measured incidence angles;
    and its edge policies."""
    measured_ti, ti_s, dt_s, ph_s, spectra, ref = (
        s.measured_ti,
        s.ti_s,
        s.dt_s,
        s.ph_s,
        s.spectra,
        s.ref,
    )
    ti_out, dt_grid, phi_grid, lam, wl = g.ti, g.dt, g.phi, g.lam, s.wl
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
            report(0.1, "model on the grid")
            filled = _model_rows(fit_model, ti_out[rows], dt_grid, phi_grid, wl)
            wr = w[rows][:, None, None, None]
            lut[rows] = (1.0 - wr) * lut[rows] + wr * filled
    return lut, edges


def model_ratio(
    s: Samples,
    g: Grid,
    extrapolation: str,
    fit_model: xr.Dataset,
    blend: float,
    report: Callable[[float, str], None],
    renormalise: str,
    rho_given: np.ndarray | None,
    parts: _Parts,
) -> tuple[np.ndarray, np.ndarray, dict[str, str], _Job | None, Grid]:
    """The model on the grid times the measured ratio to it (splined over ``theta_i``),
    the model alone towards grazing incidence; the model's grid values, the edge
    policies, the job computing the model's reflectance (for ``renormalise="model"``)
    and the grid extended to the horizon."""
    measured_ti, ti_s, dt_s, ph_s, spectra, ref = (
        s.measured_ti,
        s.ti_s,
        s.dt_s,
        s.ph_s,
        s.spectra,
        s.ref,
    )
    ti_out, dt_grid, phi_grid, lam, wl = g.ti, g.dt, g.phi, g.lam, s.wl
    rows_only = s.rows_only
    rho_job: _Job | None = None
    assert fit_model is not None  # fitted above whenever a model is used
    dt_grid = extend_grid(dt_grid, -180.0, 90.0)
    phi_grid = extend_grid(phi_grid, phi_grid[0], 90.0)
    # Beyond -180/90 and phi = 90 lies the far side of the horizon: nothing to hold.
    edges = {
        "edge_delta_theta_min": "zero",
        "edge_delta_theta_max": "zero",
        "edge_phi_max": "zero",
    }
    report(0.0, "ratio to the model")
    truth_s = _model_at(fit_model, ti_s, dt_s, ph_s, wl)
    ok = ~ref
    ratio = np.divide(spectra, truth_s, out=np.ones_like(spectra), where=truth_s > 0)
    per_theta, _ = _ratio_tables(
        measured_ti, ti_s[ok], dt_s[ok], ph_s[ok], ratio[ok], dt_grid, phi_grid
    )
    if rows_only:
        spline_mode = "constant" if extrapolation == "model" else extrapolation
        e = _lut.smoothing_spline_matrix(measured_ti, ti_out, lam, spline_mode)
        r_lut = np.tensordot(e, per_theta, axes=(1, 0))
        np.maximum(r_lut, 0.0, out=r_lut)
    else:  # orders of magnitude between incidence angles: no overshoot below zero
        r_lut = _ratio_across_theta(measured_ti, per_theta, ti_out)
    if extrapolation == "model":
        # Towards grazing incidence the measured ratio does not carry over (the
        # lobe meets the horizon): the model alone, reached over ``blend`` degrees.
        w = blend_weights(ti_out, -np.inf, measured_ti[-1], blend)[:, None, None, None]
        r_lut *= 1.0 - w  # in place: (1 - w) r + w, one table in memory
        r_lut += w
    if renormalise == "model" and rho_given is not None:
        rho_job = _Done(rho_given)
    elif renormalise == "model":  # the model's reflectance, while the grid is filled
        rho_job = _Job(_model_reflectance, fit_model, ti_out, wl, parts.part("model reflectance"))
    try:
        base = _model_rows(fit_model, ti_out, dt_grid, phi_grid, wl, parts.part("model grid"))
    except BaseException:
        if rho_job is not None:
            rho_job.cancel()
        raise
    lut = _held_product(base, r_lut, ti_out, dt_grid, renormalise == "model")
    if extrapolation == "model" and renormalise == "none":
        _bound_grazing_rows(lut, ti_out, dt_grid, phi_grid, wl, fit_model, measured_ti[-1])
    return lut, base, edges, rho_job, Grid(ti_out, dt_grid, phi_grid, lam)


def _model_reflectance(
    model: xr.Dataset,
    ti: np.ndarray,
    wl: np.ndarray,
    done: Callable[[float], None],
    stop: threading.Event | None = None,
) -> np.ndarray:
    """The model's directional-hemispherical reflectance at every row ``(ti, wl)``."""
    mod, _, kw = models.model_parameters(_model_for(model, wl))
    return _by_rows(
        lambda t: mod.directional_hemispherical_reflectance(np.minimum(t, 90.0), wl, **kw),
        ti,
        done,
        stop,
    )


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
    rho_job: _Job,
    zero_edges: tuple[bool, bool, bool],
    normal_blend: float,
    parts: _Parts,
) -> None:
    """Scale every row ``(theta_i, wavelength)`` of ``lut`` (in place) by the energy its
    model loses or gains on the grid: ``rho_model / rho_grid``, with ``rho_model`` the
    model's own directional-hemispherical reflectance and ``rho_grid`` that of ``base``
    (the model rendered on the table grid) by the quadrature of the look-up's
    interpolant (:func:`sbrdf_xr.kernels.lut.hemispherical_reflectance_kernel`), the
    model's computed by ``rho_job`` in the background."""
    ti = grids[0]
    tg, dg, pg = grids
    try:
        rho_g = _by_rows(
            lambda t: _lut.hemispherical_reflectance_kernel(
                base, tg, dg, pg, t, "linear", zero_edges=zero_edges, normal_blend=normal_blend
            ),
            ti,
            parts.part("table reflectance"),
        )
    except BaseException:
        rho_job.cancel()
        raise
    rho_m = rho_job.result(lambda: parts.part("model reflectance")(parts.done["model reflectance"]))
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
    model: xr.Dataset,
    ti: np.ndarray,
    dt: np.ndarray,
    ph: np.ndarray,
    wl: np.ndarray,
    done: Callable[[float], None] | None = None,
) -> np.ndarray:
    """A model material rendered on the table grid (rows ``ti``) at wavelengths ``wl``
    (below-horizon nodes carry the limit from the hemisphere,
    :func:`sbrdf_xr.materials.models.render`)."""
    mod, _, kw = models.model_parameters(_model_for(model, wl))
    out = np.empty((ti.size, dt.size, ph.size, wl.size))
    step = max(1, _RENDER_CHUNK // (dt.size * ph.size * wl.size))
    for a in range(0, ti.size, step):  # a few rows at a time: bounded temporaries
        if done is not None:
            done(a / ti.size)
        out[a : a + step] = models.render_values(mod, ti[a : a + step], dt, ph, wl, kw)
    if done is not None:
        done(1.0)
    return out


#: Table values rendered at once by :func:`_model_rows` (bounds its temporaries).
_RENDER_CHUNK = 2_000_000


def _model_at(
    model: xr.Dataset, ti: np.ndarray, dt: np.ndarray, ph: np.ndarray, wl: np.ndarray
) -> np.ndarray:
    """A model material's spectra at sample geometries (1-D angle arrays)."""
    return models.spectra(_model_for(model, wl), ti, dt, ph)
