"""Inversion: what a measured spectrum or colour light curve says about the spacecraft.

Two inverse problems built on the forward model:

:func:`unmix`
    The signal is linear in each material's effective area (paper 000 Eq. 3 is a sum
    over facets, grouped here by material: ``S = sum_m a_m S_m``), so a measured
    spectrum (or band fluxes), at one geometry or over a time series, gives the area
    scale factors ``a_m`` by weighted non-negative least squares on the per-material
    terms of a simulation (Lawson & Hanson 1974, *Solving Least Squares Problems*,
    ch. 23, as :func:`scipy.optimize.nnls`).  Uncertainties are the linearised
    covariance ``(A^T W A)^-1`` (Press et al., *Numerical Recipes*, 3rd ed., §15.4);
    which materials are present is chosen by the Akaike or Bayesian information
    criterion over subsets of a candidate library (Burnham & Anderson 2002, §2.2, §6.4:
    ``AIC = chi2 + 2k``, ``BIC = chi2 + k ln n`` for Gaussian errors of known variance);
    pairs of materials whose estimates are correlated beyond a threshold are reported
    as degenerate.
:func:`fit_spin`
    Spin axis (two angles of the inertial axis of a known body axis), period and phase
    of a uniform spin (:class:`sbrdf_xr.attitude.Spin`) fitted to a colour light curve:
    a global search over a Fibonacci sphere of axes x periods x phases, evaluating every
    candidate with the compiled kernel on band pre-integrated tables (threads: the
    kernel releases the GIL), with the unknown flux scale of each band (or one common
    scale) solved analytically, then local refinement by
    :func:`scipy.optimize.least_squares`; uncertainties from its Jacobian.

Measured fluxes are in any unit proportional to the band signal (the scale is fitted);
magnitudes are converted to relative fluxes ``10**(-0.4 m)`` with uncertainties
``sigma_F = F ln(10)/2.5 sigma_m`` (first order).
"""

from __future__ import annotations

import itertools
import os
import time
from collections.abc import Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike
from scipy.optimize import least_squares, nnls

from . import _kernels
from .errors import InversionError

__all__ = ["band_terms", "benchmark_spin_search", "fibonacci_sphere", "fit_spin", "light_curve_fluxes",
           "magnitudes_to_signal", "material_areas", "read_spectrum", "spin_model", "unmix"]

MATERIAL = "material"
#: Default |correlation| between two materials' estimates above which they are degenerate.
DEGENERACY_THRESHOLD = 0.95
_LN10_2P5 = np.log(10.0) / 2.5


# ----------------------------------------------------------------------------- unmixing


def material_areas(spacecraft: Any) -> dict[str, float]:
    """Total facet area of each material of a spacecraft [m2]."""
    areas = np.asarray(spacecraft.mesh.area_faces, dtype=np.float64)
    names = np.asarray(spacecraft.facet_material)
    return {str(m): float(areas[names == m].sum()) for m in np.unique(names)}


def _library(simulated: Any) -> xr.DataArray:
    """Per-material terms as one DataArray with a ``material`` dimension."""
    if isinstance(simulated, xr.Dataset):
        if "signal_material" not in simulated:
            raise InversionError("simulated: a Dataset needs the variable signal_material "
                                 f"(simulate with outputs=(..., 'per_material')); got {list(simulated.data_vars)}")
        simulated = simulated["signal_material"]
    if isinstance(simulated, Mapping):
        items = list(simulated.items())
        if not items:
            raise InversionError("simulated: the candidate library is empty")
        ref_name, ref = items[0]
        for name, da in items[1:]:
            for dim in ("wavelength", "band"):
                if dim in ref.dims or dim in da.dims:
                    a = ref[dim].values if dim in ref.coords else None
                    b = da[dim].values if dim in da.coords else None
                    if a is None or b is None or a.shape != b.shape or not np.array_equal(a, b):
                        raise InversionError(
                            f"candidate library: {name!r} has {dim} {_describe(b)}, {ref_name!r} has "
                            f"{_describe(a)}; every candidate must be on the same {dim} grid")
        simulated = xr.concat([da for _, da in items], dim=xr.DataArray(
            [str(k) for k, _ in items], dims=MATERIAL, name=MATERIAL))
    if not isinstance(simulated, xr.DataArray) or MATERIAL not in simulated.dims:
        raise InversionError("simulated: expected a DataArray with a material dimension "
                             "(signal_material), a Dataset holding one, or a mapping of name to DataArray")
    return simulated


def _describe(grid: np.ndarray | None) -> str:
    if grid is None:
        return "none"
    if grid.dtype.kind in "fi" and grid.size:
        return f"{grid.size} values {grid.min():g}..{grid.max():g}"
    return f"{list(grid)}"


def _spectral_dim(da: xr.DataArray, what: str) -> str:
    dims = [d for d in ("wavelength", "band") if d in da.dims]
    if len(dims) != 1:
        raise InversionError(f"{what}: expected exactly one of the dimensions wavelength or band, got {da.dims}")
    return dims[0]


def _align(measured: xr.DataArray, lib: xr.DataArray) -> xr.DataArray:
    """The library on the measured spectral grid (linear interpolation in wavelength)."""
    dim = _spectral_dim(measured, "measured")
    if dim not in lib.dims:
        raise InversionError(f"measured is over {dim} but the simulation is over {_spectral_dim(lib, 'simulated')}")
    if dim == "band":
        have = [str(b) for b in lib["band"].values]
        missing = [str(b) for b in measured["band"].values if str(b) not in have]
        if missing:
            raise InversionError(f"measured bands {missing} are not among the simulated bands {have}")
        return lib.sel(band=measured["band"].values)
    wl, mw = lib["wavelength"].values, measured["wavelength"].values
    lo, hi = float(wl.min()), float(wl.max())
    out = mw[(mw < lo - 1e-9) | (mw > hi + 1e-9)]
    if out.size:
        raise InversionError(f"measured wavelengths {out.min():g}..{out.max():g} nm lie outside the simulated "
                             f"range {lo:g}..{hi:g} nm")
    if wl.shape == mw.shape and np.allclose(wl, mw):
        return lib.assign_coords(wavelength=mw)
    return lib.interp(wavelength=mw)


def _design(measured: xr.DataArray, uncertainty: Any, lib: xr.DataArray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rows (every sample and wavelength) of ``A``, ``y`` and ``sigma``."""
    if not isinstance(measured, xr.DataArray):
        raise InversionError(f"measured: expected a DataArray over wavelength or band, got {type(measured).__name__}")
    lib = _align(measured, lib)
    sigma = (uncertainty if isinstance(uncertainty, xr.DataArray)
             else xr.DataArray(np.broadcast_to(np.asarray(uncertainty, dtype=np.float64), measured.shape),
                               dims=measured.dims, coords=measured.coords))
    y, sigma = xr.broadcast(measured, sigma)
    extra = [d for d in lib.dims if d not in y.dims and d != MATERIAL]
    if extra:
        raise InversionError(f"simulated has dimensions {extra} that measured lacks; select one geometry "
                             "or give measurements over them")
    sample_dims = list(y.dims)
    a = lib.transpose(*[d for d in sample_dims if d in lib.dims], MATERIAL)
    a = a.broadcast_like(y).transpose(*sample_dims, MATERIAL)
    yv, sv = y.values.reshape(-1).astype(np.float64), sigma.values.reshape(-1).astype(np.float64)
    if not np.all(np.isfinite(yv)):
        raise InversionError(f"measured: {int((~np.isfinite(yv)).sum())} NaN or infinite values")
    bad = ~(np.isfinite(sv) & (sv > 0))
    if bad.any():
        raise InversionError(f"uncertainty: must be finite and > 0, got {int(bad.sum())} values that are not "
                             f"(e.g. {sv[bad][0]!r})")
    av = a.values.reshape(-1, lib.sizes[MATERIAL]).astype(np.float64)
    if not np.all(np.isfinite(av)):
        raise InversionError("simulated: per-material terms contain NaN or infinite values")
    return av, yv, sv


def _nnls_fit(aw: np.ndarray, yw: np.ndarray) -> tuple[np.ndarray, float]:
    x, rnorm = nnls(aw, yw, maxiter=50 * aw.shape[1] + 100)
    return x, float(rnorm) ** 2


def _covariance(aw: np.ndarray, active: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Covariance of the active set, and marginal sigma of every column from the full matrix."""
    k = aw.shape[1]
    cov = np.full((k, k), np.nan)
    if active.any():
        fa = aw[:, active].T @ aw[:, active]
        cov[np.ix_(active, active)] = np.linalg.pinv(fa)
    sig = np.sqrt(np.clip(np.diag(np.linalg.pinv(aw.T @ aw)), 0, None))
    sig[active] = np.sqrt(np.clip(np.diag(cov)[active], 0, None))
    return cov, sig


def unmix(
    measured: xr.DataArray,
    simulated: xr.DataArray | xr.Dataset | Mapping[str, xr.DataArray],
    uncertainty: ArrayLike | xr.DataArray,
    *,
    areas: Mapping[str, float] | None = None,
    select: str | None = "all",
    max_materials: int | None = None,
    criterion: str = "bic",
    degeneracy_threshold: float = DEGENERACY_THRESHOLD,
) -> xr.Dataset:
    """Effective area scale factor of each material from a measured spectrum or band fluxes.

    Solves ``min || W^1/2 (y - A a) ||^2`` subject to ``a >= 0`` (NNLS), where the
    columns of ``A`` are the simulated per-material signals (``signal_material``) at the
    measured wavelengths or bands and samples, ``W = diag(sigma^-2)``.  ``a_m = 1``
    means the material's area as simulated.

    Parameters
    ----------
    measured : DataArray
        Over ``wavelength`` [nm] or ``band``, optionally with sample dimensions (e.g.
        ``time``, ``geometry``) shared with ``simulated``; in the units of the simulated
        signal [m2 sr-1] (or any multiple of them, then ``a`` carries the factor).
    simulated : DataArray, Dataset or mapping of str to DataArray
        Per-material terms with a ``material`` dimension (``simulate(..., outputs=(...,
        "per_material"))``), or a candidate library: name to a term each, on one grid.
        Simulated wavelengths are interpolated linearly to the measured ones.
    uncertainty : array_like or DataArray
        1-sigma measurement errors, broadcast against ``measured``; > 0.
    areas : mapping of str to float, optional
        Nominal area of each material [m2] (:func:`material_areas`): adds ``area`` [m2]
        and ``area_fraction`` [1].
    select : {"all", "greedy", None}
        Choose the materials present: every subset up to ``max_materials``, forward
        greedy addition, or keep every candidate.
    max_materials : int, optional
        Largest subset tried (default: all candidates).
    criterion : {"bic", "aic"}
        Information criterion minimised by the selection.
    degeneracy_threshold : float
        |correlation| of two estimates above which the pair is reported as degenerate.

    Returns
    -------
    xarray.Dataset
        Over ``material``: ``scale`` and ``scale_uncertainty`` [1], ``selected`` (bool),
        ``area``, ``area_uncertainty`` [m2] and ``area_fraction`` (with ``areas``),
        ``correlation`` (material, material_b); scalars ``chi2``, ``reduced_chi2``,
        ``aic``, ``bic``, ``condition_number``; over ``subset``: the criterion table;
        attribute ``degenerate``: the pairs the data cannot tell apart.

    Raises
    ------
    InversionError
        Measured wavelengths outside the simulated range or bands not simulated, fewer
        samples than parameters, candidates on different grids, uncertainties not > 0,
        NaN data.
    """
    lib = _library(simulated)
    names = [str(m) for m in lib[MATERIAL].values]
    a, y, s = _design(measured, uncertainty, lib)
    n, k = a.shape
    if n < k:
        raise InversionError(f"measured: {n} samples for {k} material parameters; need at least as many samples "
                             "as parameters")
    if criterion not in ("aic", "bic"):
        raise InversionError(f"criterion: {criterion!r}; allowed 'aic', 'bic'")
    if select not in ("all", "greedy", None):
        raise InversionError(f"select: {select!r}; allowed 'all', 'greedy', None")
    aw, yw = a / s[:, None], y / s
    kmax = k if max_materials is None else max(1, min(int(max_materials), k))

    def score(cols: tuple[int, ...]) -> tuple[float, float, float, np.ndarray]:
        x, chi2 = _nnls_fit(aw[:, list(cols)], yw)
        npar = int((x > 0).sum())
        return chi2, chi2 + 2 * npar, chi2 + npar * np.log(n), x

    table: list[tuple[str, float, float, float]] = []
    crit = 1 if criterion == "aic" else 2
    if select == "all":
        subsets = [c for r in range(1, kmax + 1) for c in itertools.combinations(range(k), r)]
        results = {c: score(c) for c in subsets}
        best = min(results, key=lambda c: results[c][crit])
    elif select == "greedy":
        results, chosen, best = {}, (), None
        while len(chosen) < kmax:
            trial = {tuple(sorted((*chosen, j))): None for j in range(k) if j not in chosen}
            for c in trial:
                results[c] = score(c)
            cand = min(trial, key=lambda c: results[c][crit])
            if best is not None and results[cand][crit] >= results[best][crit]:
                break
            best = chosen = cand
    else:
        best = tuple(range(k))
        results = {best: score(best)}
    for c, (chi2, aic, bic, _) in results.items():
        table.append(("+".join(names[j] for j in c), chi2, aic, bic))
    cols = list(best)
    chi2, aic, bic, xs = results[best]
    x = np.zeros(k)
    x[cols] = xs
    sub = aw[:, cols]
    _cov_s, sig_s = _covariance(sub, xs > 0)
    sig = np.full(k, np.nan)
    sig[cols] = sig_s
    # Correlations from the unconstrained covariance of the selected columns: it says
    # whether the data could tell the materials apart, whatever the bound did.
    full = np.linalg.pinv(sub.T @ sub)
    d = np.sqrt(np.clip(np.diag(full), 1e-300, None))
    corr = np.full((k, k), np.nan)
    corr[np.ix_(cols, cols)] = full / np.outer(d, d)
    # Degeneracy over every candidate (the columns' cosine similarity in the weighted metric
    # and the parameter correlation of all candidates together).
    cand_full = np.linalg.pinv(aw.T @ aw)
    dc = np.sqrt(np.clip(np.diag(cand_full), 1e-300, None))
    cand_corr = cand_full / np.outer(dc, dc)
    out_of_model = ~np.isin(np.arange(k), cols)
    sig[out_of_model] = dc[out_of_model]  # left out: its sigma with every candidate fitted
    sv = np.linalg.svd(aw, compute_uv=False)
    cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else np.inf
    degenerate = [f"{names[i]} / {names[j]} (correlation {cand_corr[i, j]:+.3f})"
                  for i in range(k) for j in range(i + 1, k) if abs(cand_corr[i, j]) > degeneracy_threshold]
    dof = n - int((xs > 0).sum())
    ds = xr.Dataset(coords={MATERIAL: (MATERIAL, names, {"long_name": "material", "units": "1"}),
                            "material_b": ("material_b", names, {"long_name": "material", "units": "1"})})
    ds["scale"] = (MATERIAL, x, {"units": "1", "long_name": "effective area scale factor of the material "
                                 "(1: its area as simulated)"})
    ds["scale_uncertainty"] = (MATERIAL, sig, {"units": "1", "long_name": "1-sigma uncertainty of the scale "
                                               "factor (active set: (A^T W A)^-1; at the bound: unconstrained; left out of the "
                                               "chosen model: with every candidate fitted)"})
    ds["selected"] = (MATERIAL, np.isin(np.arange(k), cols) & (x > 0),
                      {"units": "1", "long_name": "material present in the chosen model"})
    ds["correlation"] = ((MATERIAL, "material_b"), corr,
                         {"units": "1", "long_name": "correlation of the scale factors in the chosen model"})
    ds["candidate_correlation"] = ((MATERIAL, "material_b"), cand_corr,
                                   {"units": "1", "long_name": "correlation of the scale factors with every "
                                    "candidate fitted (unconstrained)"})
    if areas is not None:
        missing = [m for m in names if m not in areas]
        if missing:
            raise InversionError(f"areas: no area for {missing}; have {sorted(areas)}")
        nominal = np.array([float(areas[m]) for m in names])
        ds["area"] = (MATERIAL, x * nominal, {"units": "m2", "long_name": "effective area of the material"})
        ds["area_uncertainty"] = (MATERIAL, sig * nominal, {"units": "m2", "long_name": "1-sigma uncertainty of "
                                                            "the effective area"})
        tot = float((x * nominal).sum())
        ds["area_fraction"] = (MATERIAL, x * nominal / tot if tot > 0 else np.zeros(k),
                               {"units": "1", "long_name": "fraction of the total effective area"})
    scal = {"chi2": (chi2, "chi-square of the chosen model"),
            "reduced_chi2": (chi2 / dof if dof > 0 else np.nan, "chi-square per degree of freedom"),
            "aic": (aic, "Akaike information criterion chi2 + 2k"),
            "bic": (bic, "Bayesian information criterion chi2 + k ln n"),
            "condition_number": (cond, "condition number of the weighted design matrix of all candidates")}
    for key, (val, ln) in scal.items():
        ds[key] = ((), float(val), {"units": "1", "long_name": ln})
    ds["n_samples"] = ((), n, {"units": "1", "long_name": "number of measured values"})
    ds = ds.assign_coords(subset=("subset", [t[0] for t in table], {"long_name": "materials fitted",
                                                                      "units": "1"}))
    for j, key in enumerate(("subset_chi2", "subset_aic", "subset_bic"), start=1):
        ds[key] = ("subset", np.array([t[j] for t in table]), {"units": "1", "long_name": f"{key[7:]} of the subset"})
    ds.attrs = {"selected_materials": ", ".join(names[j] for j in cols if x[j] > 0),
                "criterion": criterion, "selection": str(select),
                "degenerate": "; ".join(degenerate) if degenerate else "none",
                "degeneracy_note": (f"the data cannot tell apart: {'; '.join(degenerate)}" if degenerate
                                    else f"no pair of candidates correlated beyond {degeneracy_threshold}")}
    return ds


# ------------------------------------------------------------------------------ spin fit


def fibonacci_sphere(n: int) -> np.ndarray:
    """``n`` nearly uniform unit vectors (the Fibonacci lattice, Gonzalez 2010, Math.
    Geosci. 42, 49), shape (n, 3)."""
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    r = np.sqrt(np.clip(1.0 - z * z, 0, None))
    phi = np.pi * (3.0 - np.sqrt(5.0)) * i
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)


def _lonlat(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return (np.degrees(np.arctan2(v[..., 1], v[..., 0])) % 360.0,
            np.degrees(np.arcsin(np.clip(v[..., 2], -1, 1))))


def _vec(lon: Any, lat: Any) -> np.ndarray:
    lo, la = np.radians(lon), np.radians(lat)
    return np.stack([np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la)], axis=-1)


def _align_matrices(axis_body: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """Rotation matrices (n, 3, 3) taking ``axis_body`` to each inertial ``axes`` (shortest arc)."""
    from scipy.spatial.transform import Rotation

    b = axis_body / np.linalg.norm(axis_body)
    c = np.cross(b, axes)
    s = np.linalg.norm(c, axis=-1)
    d = axes @ b
    ang = np.arctan2(s, d)
    perp = np.cross(b, [1.0, 0, 0] if abs(b[0]) < 0.9 else [0, 1.0, 0])
    perp /= np.linalg.norm(perp)
    u = np.where(s[:, None] > 1e-12, c / np.where(s > 1e-12, s, 1)[:, None], perp)
    return Rotation.from_rotvec(u * ang[:, None]).as_matrix()


def spin_model(axis_body: ArrayLike, axis: ArrayLike, period_s: float, phase_deg: float) -> Any:
    """The :class:`sbrdf_xr.attitude.Spin` law of a spin state: the body turns about
    ``axis_body`` at ``360/period_s`` degree s-1 from the attitude that takes
    ``axis_body`` to the inertial ``axis`` by the shortest arc, angle ``phase_deg`` at t = 0."""
    from scipy.spatial.transform import Rotation

    from .attitude import Spin

    m = _align_matrices(np.asarray(axis_body, float), np.asarray(axis, float)[None, :])[0]
    q = Rotation.from_matrix(m).as_quat()
    return Spin(axis_body=np.asarray(axis_body, float), rate_deg_s=360.0 / float(period_s),
                phase_deg=float(phase_deg), initial=q)


def _body_vectors(v: np.ndarray, align: np.ndarray, k: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Body-frame ``R(t)^T v`` for ``R = align R_k(angle)``: ``u = align^T v`` rotated by
    ``-angle`` about ``k`` (Rodrigues).  Shapes: v (T, 3), align (C, 3, 3), angle (C, T) [rad]
    -> (C, T, 3)."""
    u = np.einsum("cji,tj->cti", align, v)
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    kd = u @ k
    return u * c - np.cross(k, u) * s + k * (kd[..., None] * (1 - c))


class _Kernel:
    """Band signal of a spacecraft for body-frame geometries, on pre-integrated tables."""

    def __init__(self, spacecraft: Any, bands: Sequence[str], materials: Mapping[str, Any] | None = None,
                 method: str = "linear") -> None:
        from .scene import Scene

        f = fibonacci_sphere(256)
        scene = Scene(spacecraft, materials=materials, to_sun=f, to_observer=f,
                      outputs=("band_signal", "area"), bands=tuple(bands), method=method)
        self.plan = plan = scene.plan()
        if not plan.pre_integrated:
            raise InversionError("spin fit: the band tables could not be pre-integrated")
        self.bands = tuple(str(b) for b in plan.bands)
        self.method = method

    def __call__(self, s: np.ndarray, o: np.ndarray) -> np.ndarray:
        t = self.plan.terms
        r = _kernels.fused_sums(s.reshape(-1, 3), o.reshape(-1, 3), t.normal, t.area, t.material,
                                self.plan.tables, self.method, None, False)
        return np.asarray(r.signal, dtype=np.float64).reshape(*s.shape[:-1], len(self.bands))


def light_curve_fluxes(light_curve: xr.Dataset, bands: Sequence[str] | None = None) -> dict[str, np.ndarray]:
    """Times [s], band index, relative flux and its uncertainty from a light curve.

    ``light_curve`` is what :func:`sbrdf_xr.photometry.read_light_curve` returns (over
    ``obs``: ``magnitude``, ``uncertainty`` [mag], coords ``band``, ``time`` [s]) or the
    same with ``flux`` and ``flux_uncertainty`` instead of magnitudes.
    """
    if not isinstance(light_curve, xr.Dataset) or ("time" not in light_curve.coords and "time" not in light_curve):
        raise InversionError("light curve: expected a Dataset with a time coordinate [s] (read_light_curve)")
    t = np.asarray(light_curve["time"].values, dtype=np.float64)
    band = np.asarray(light_curve["band"].values).astype(str)
    labels = list(dict.fromkeys(band)) if bands is None else [str(b) for b in bands]
    unknown = sorted(set(band) - set(labels))
    if unknown:
        raise InversionError(f"light curve bands {unknown} are not among the model bands {labels}")
    if "flux" in light_curve:
        f = np.asarray(light_curve["flux"].values, dtype=np.float64)
        sf = np.asarray(light_curve["flux_uncertainty"].values, dtype=np.float64)
    elif "magnitude" in light_curve:
        m = np.asarray(light_curve["magnitude"].values, dtype=np.float64)
        sm = np.asarray(light_curve["uncertainty"].values, dtype=np.float64)
        if not np.all(np.isfinite(m)):
            raise InversionError("light curve: magnitudes must be finite")
        f = 10 ** (-0.4 * (m - np.nanmedian(m)))
        sf = f * _LN10_2P5 * sm
    else:
        raise InversionError(f"light curve: needs magnitude/uncertainty or flux/flux_uncertainty, got "
                             f"{list(light_curve.data_vars)}")
    bad = ~(np.isfinite(sf) & (sf > 0))
    if bad.any():
        raise InversionError(f"light curve: {int(bad.sum())} uncertainties that are not finite and > 0")
    if not np.all(np.isfinite(t)) or not np.all(np.isfinite(f)):
        raise InversionError("light curve: times and values must be finite")
    return {"time": t, "band": np.array([labels.index(b) for b in band]), "flux": f, "sigma": sf,
            "labels": np.array(labels)}


def _directions(v: Any, n_t: int, name: str) -> np.ndarray:
    arr = np.asarray(v, dtype=np.float64)
    if arr.shape == (3,):
        arr = np.broadcast_to(arr, (n_t, 3))
    if arr.shape != (n_t, 3):
        raise InversionError(f"{name}: expected shape (3,) or ({n_t}, 3) (one per distinct time), got {arr.shape}")
    nrm = np.linalg.norm(arr, axis=-1)
    if not np.all(nrm > 0):
        raise InversionError(f"{name}: zero-length direction")
    return arr / nrm[:, None]


class _Problem:
    """A light curve, its geometry and the model: chi-square of spin states."""

    def __init__(self, lc: dict[str, np.ndarray], kernel: _Kernel, to_sun: Any, to_observer: Any,
                 axis_body: np.ndarray, offset: str) -> None:
        self.times, self.t_index = np.unique(lc["time"], return_inverse=True)
        self.band = lc["band"]
        self.y, self.sigma = lc["flux"], lc["sigma"]
        self.w = 1.0 / self.sigma**2
        self.kernel = kernel
        self.s = _directions(to_sun, self.times.size, "to_sun")
        self.o = _directions(to_observer, self.times.size, "to_observer")
        self.k = axis_body / np.linalg.norm(axis_body)
        if offset not in ("band", "common"):
            raise InversionError(f"offset: {offset!r}; allowed 'band' (a free scale per band), 'common'")
        self.offset = offset
        self.n_bands = len(lc["labels"])

    def model(self, axes: np.ndarray, periods: np.ndarray, phases: np.ndarray) -> np.ndarray:
        """Band signal at every observation (C, N) for candidates (C,) of axis (C, 3), period, phase."""
        align = _align_matrices(self.k, axes)
        ang = np.radians(phases[:, None] + 360.0 * self.times[None, :] / periods[:, None])
        sb = _body_vectors(self.s, align, self.k, ang)
        ob = _body_vectors(self.o, align, self.k, ang)
        sig = self.kernel(sb, ob)  # (C, T, B)
        return sig[:, self.t_index, self.band]

    def scales(self, mdl: np.ndarray) -> np.ndarray:
        """Analytic weighted least-squares flux scale per band (C, N)."""
        wy, wm = self.w * self.y, self.w * mdl
        if self.offset == "common":
            k = (wm * self.y).sum(-1) / np.maximum((wm * mdl).sum(-1), 1e-300)
            return np.broadcast_to(k[:, None], mdl.shape)
        num = np.zeros((mdl.shape[0], self.n_bands))
        den = np.zeros_like(num)
        for b in range(self.n_bands):
            sel = self.band == b
            num[:, b] = (wy[sel] * mdl[:, sel]).sum(-1)
            den[:, b] = (wm[:, sel] * mdl[:, sel]).sum(-1)
        return (num / np.maximum(den, 1e-300))[:, self.band]

    def chi2(self, axes: np.ndarray, periods: np.ndarray, phases: np.ndarray) -> np.ndarray:
        mdl = self.model(axes, periods, phases)
        r = (self.y - self.scales(mdl) * mdl) / self.sigma
        return (r * r).sum(-1)

    def residuals(self, p: np.ndarray) -> np.ndarray:
        mdl = self.model(_vec(p[0], p[1])[None, :], np.array([p[2]]), np.array([p[3]]))
        return ((self.y - self.scales(mdl) * mdl) / self.sigma)[0]

    def at_mean_directions(self) -> _Problem:
        """The same problem with the Sun and observer fixed at their mean directions."""
        other = object.__new__(_Problem)
        other.__dict__.update(self.__dict__)
        for key in ("s", "o"):
            m = getattr(self, key).mean(0)
            setattr(other, key, np.broadcast_to(m / np.linalg.norm(m), getattr(self, key).shape))
        return other

    @property
    def n_scales(self) -> int:
        return 1 if self.offset == "common" else self.n_bands


def _search(prob: _Problem, axes: np.ndarray, periods: np.ndarray, phases: np.ndarray,
            n_threads: int | None, chunk: int = 256) -> np.ndarray:
    """Chi-square over the grid (axes, periods, phases), threads over chunks of candidates."""
    ia, ip, iq = np.meshgrid(np.arange(len(axes)), np.arange(len(periods)), np.arange(len(phases)), indexing="ij")
    ia, ip, iq = ia.ravel(), ip.ravel(), iq.ravel()
    out = np.empty(ia.size)
    edges = [*list(range(0, ia.size, chunk)), ia.size]

    def run(j: int) -> None:
        sl = slice(edges[j], edges[j + 1])
        out[sl] = prob.chi2(axes[ia[sl]], periods[ip[sl]], phases[iq[sl]])

    workers = max(1, n_threads or os.cpu_count() or 1)
    if workers == 1:
        for j in range(len(edges) - 1):
            run(j)
    else:
        with ThreadPoolExecutor(workers, thread_name_prefix="sbrdf_xr-invert") as pool:
            list(pool.map(run, range(len(edges) - 1)))
    return out.reshape(len(axes), len(periods), len(phases))


def _search_shift(prob: _Problem, axes: np.ndarray, periods: np.ndarray, phases: np.ndarray,
                  n_threads: int | None, n_angles: int = 720) -> np.ndarray:
    """The same grid for fixed directions: the model depends on the spin angle only, so it
    is evaluated once per axis on ``n_angles`` angles and every (period, phase) reads it
    by linear interpolation at ``phase + 360 t / P``."""
    grid_ang = np.arange(n_angles) * 360.0 / n_angles
    step = 360.0 / n_angles
    out = np.empty((len(axes), len(periods), len(phases)))
    t = prob.times[prob.t_index]

    def run(i: int) -> None:
        align = _align_matrices(prob.k, axes[i:i + 1])
        ang = np.radians(grid_ang)[None, :]
        f = prob.kernel(_body_vectors(prob.s[:1], align, prob.k, ang), _body_vectors(prob.o[:1], align, prob.k, ang))[0]
        f = np.concatenate([f, f[:1]], axis=0)  # (n_angles + 1, B), periodic
        theta = (phases[None, :, None] + 360.0 * t[None, None, :] / periods[:, None, None]) % 360.0
        x = theta / step
        j = np.minimum(x.astype(np.int64), n_angles - 1)
        w = x - j
        mdl = f[j, prob.band] * (1 - w) + f[j + 1, prob.band] * w
        mdl = mdl.reshape(-1, t.size)
        r = (prob.y - prob.scales(mdl) * mdl) / prob.sigma
        out[i] = (r * r).sum(-1).reshape(len(periods), len(phases))

    workers = max(1, n_threads or os.cpu_count() or 1)
    if workers == 1:
        for i in range(len(axes)):
            run(i)
    else:
        with ThreadPoolExecutor(workers, thread_name_prefix="sbrdf_xr-invert") as pool:
            list(pool.map(run, range(len(axes))))
    return out


def _refine(prob: _Problem, p0: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Local least squares from ``p0`` (lon, lat, period, phase); parameters, sigma, chi2."""
    span = max(float(np.ptp(prob.times)), 1e-9)
    xs = np.array([1.0, 1.0, p0[2] ** 2 / (360.0 * span), 1.0])
    res = least_squares(prob.residuals, p0, x_scale=xs, diff_step=1e-6, method="lm" if prob.y.size > 4 else "trf")
    j = res.jac
    try:
        cov = np.linalg.inv(j.T @ j)
        sig = np.sqrt(np.clip(np.diag(cov), 0, None))
    except np.linalg.LinAlgError:
        sig = np.full(4, np.inf)
    p = res.x.copy()
    if abs(p[1]) > 90:  # latitude past a pole: the same axis
        v = _vec(p[0], p[1])
        p[0], p[1] = _lonlat(v)
    p[0] %= 360.0
    p[3] %= 360.0
    return p, sig, float(2 * res.cost)


def _alternatives(prob: _Problem, best: np.ndarray, n_phases: int,
                  refine: bool) -> dict[str, tuple[np.ndarray, Any, float]]:
    """The classical ambiguous solutions of a spin state, each searched in phase and refined.

    ``antipode``: the opposite axis (the reversed sense of rotation); ``mirror``: the axial
    vector mirrored through the mean scattering plane (the plane of the Sun and observer
    directions), ``-M n``, which for a body equal to its mirror image and fixed directions
    gives the same light curve (Kaasalainen & Lamberg 2006, Inverse Problems 22, 749);
    ``half_period`` and ``double_period``.
    """
    axis = _vec(best[0], best[1])
    nplane = np.cross(prob.s.mean(0), prob.o.mean(0))
    nplane = nplane / np.linalg.norm(nplane) if np.linalg.norm(nplane) > 1e-9 else np.array([0.0, 0, 1])
    mirror = -(axis - 2 * np.dot(axis, nplane) * nplane)
    alts = {"antipode": (-axis, best[2]), "mirror": (mirror, best[2]),
            "half_period": (axis, best[2] / 2), "double_period": (axis, best[2] * 2)}
    dense = np.arange(4 * int(n_phases)) * 90.0 / int(n_phases)
    out = {}
    for name, (ax, per) in alts.items():
        c2 = prob.chi2(np.repeat(ax[None, :], dense.size, 0), np.full(dense.size, per), dense)
        lo, la = _lonlat(ax)
        q0 = np.array([lo, la, per, dense[np.argmin(c2)]])
        out[name] = _refine(prob, q0) if refine else (q0, None, float(c2.min()))
    return out


def _axis_angle(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.degrees(np.arccos(np.clip(np.dot(a, b), -1, 1))))


def fit_spin(
    light_curve: xr.Dataset,
    spacecraft: Any,
    *,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    periods: ArrayLike,
    axis_body: ArrayLike = (0.0, 0.0, 1.0),
    n_axes: int = 300,
    n_phases: int = 36,
    offset: str = "band",
    materials: Mapping[str, xr.DataArray] | None = None,
    refine: bool = True,
    n_starts: int = 5,
    method: str = "shift",
    n_threads: int | None = None,
) -> xr.Dataset:
    """Spin axis, period and phase of a uniform spin fitted to a colour light curve.

    The model (:func:`spin_model`): the body turns about its ``axis_body`` (a principal
    axis, the spin being torque-free) at ``360/P`` degree s-1; ``axis_body`` points to the
    inertial direction (``axis_longitude``, ``axis_latitude``) of the frame of
    ``to_sun``/``to_observer``; the spin angle is ``phase`` at t = 0.  The predicted flux of
    band b is ``k_b S_b(t)`` with ``S_b`` the band signal of the compiled kernel and
    ``k_b`` (one per band, or one for all with ``offset="common"``) solved in closed form
    for every candidate.  Search: ``n_axes`` Fibonacci-sphere axes x ``periods`` x
    ``n_phases`` phases; then :func:`scipy.optimize.least_squares` from the best
    candidate (and from the alternative solutions below).

    The period grid must be fine enough that the phase slips by less than a phase step over
    the time span ``T``: ``dP <~ P**2 / (n_phases T)``.

    Parameters
    ----------
    light_curve : Dataset
        :func:`sbrdf_xr.photometry.read_light_curve` output (magnitudes) or the same with
        ``flux`` and ``flux_uncertainty``; times [s].
    spacecraft : Spacecraft
        The body (its materials from the catalog unless ``materials``).
    to_sun, to_observer : array_like, shape (3,) or (n_times, 3)
        Inertial directions from the spacecraft to the Sun and to the observer, fixed or
        one per distinct time (sorted).
    periods : array_like
        Candidate spin periods [s].
    axis_body : array_like, shape (3,)
        The body axis the spacecraft spins about.
    n_axes, n_phases : int
        Search grid sizes.
    offset : {"band", "common"}
        A free flux scale per band, or one for all bands (then the fluxes must be on one
        physical scale, e.g. magnitudes in one system).
    refine : bool
        Refine the best candidates by least squares.
    n_starts : int
        Refinements started from the best grid state of the ``n_starts`` best axes.
    method : {"shift", "direct"}
        Search: ``shift`` evaluates the kernel once per axis on a dense spin-angle grid
        (0.5 degree) and reads every (period, phase) from it, exact for fixed directions
        and, when they move, at their mean directions (the refinement is exact);
        ``direct`` runs every candidate at every time through the kernel.
    n_threads : int, optional
        Threads of the search (default: every core).

    Returns
    -------
    xarray.Dataset
        Scalars ``axis_longitude``, ``axis_latitude`` [degree], ``period`` [s], ``phase``
        [degree] with ``*_uncertainty``, ``chi2``, ``reduced_chi2``; the map
        ``chi2_map`` over ``axis`` (min over period and phase) with the axis coordinates;
        the alternative solutions over ``solution`` (mirror axis, antipode, half and double
        period) with their ``chi2_gap``.
    """
    if method not in ("shift", "direct"):
        raise InversionError(f"method: {method!r}; allowed 'shift', 'direct'")
    lc = light_curve_fluxes(light_curve)
    kern = _Kernel(spacecraft, list(lc["labels"]), materials)
    prob = _Problem(lc, kern, to_sun, to_observer, np.asarray(axis_body, dtype=np.float64), offset)
    periods = np.atleast_1d(np.asarray(periods, dtype=np.float64))
    if not np.all(np.isfinite(periods) & (periods > 0)):
        raise InversionError("periods: must be finite and > 0 [s]")
    n_par = 4 + prob.n_scales
    if prob.y.size <= n_par:
        raise InversionError(f"light curve: {prob.y.size} values for {n_par} parameters; need more values")
    axes = fibonacci_sphere(int(n_axes))
    phases = np.arange(int(n_phases)) * 360.0 / int(n_phases)
    t0 = time.perf_counter()
    fixed = bool(np.allclose(prob.s, prob.s[0]) and np.allclose(prob.o, prob.o[0]))
    if method == "shift":
        # with moving directions the search reads the model at the mean directions (an
        # approximation for the global search only; the refinement uses the exact ones)
        search_prob = prob if fixed else prob.at_mean_directions()
        grid = _search_shift(search_prob, axes, periods, phases, n_threads)
    else:
        grid = _search(prob, axes, periods, phases, n_threads)
    t_search = time.perf_counter() - t0
    ia, ip, iq = np.unravel_index(np.argmin(grid), grid.shape)
    lon0, lat0 = _lonlat(axes[ia])
    p0 = np.array([lon0, lat0, periods[ip], phases[iq]])
    if refine:
        # multi-start: the best grid state of each of the n_starts best axes
        best, sig, chi2 = _refine(prob, p0)
        per_axis = grid.reshape(len(axes), -1)
        for i in np.argsort(per_axis.min(axis=1))[1:max(1, int(n_starts))]:
            jp, jq = np.unravel_index(np.argmin(per_axis[i]), grid.shape[1:])
            lo, la = _lonlat(axes[i])
            q, sq, c = _refine(prob, np.array([lo, la, periods[jp], phases[jq]]))
            if c < chi2:
                best, sig, chi2 = q, sq, c
        # an alternative better than the first refinement becomes the solution (once)
        for q, _, c in _alternatives(prob, best, n_phases, refine).values():
            if c < chi2 - 1e-9:
                best, sig, chi2 = _refine(prob, q)
    else:
        best, sig, chi2 = p0, np.full(4, np.nan), float(grid[ia, ip, iq])
    best_axis = _vec(best[0], best[1])
    rows = [(name, q, c, _axis_angle(_vec(q[0], q[1]), best_axis))
            for name, (q, _, c) in _alternatives(prob, best, n_phases, refine).items()]
    dof = prob.y.size - n_par
    chi_map = grid.min(axis=(1, 2))
    mlon, mlat = _lonlat(axes)
    ds = xr.Dataset(coords={
        "axis": ("axis", np.arange(len(axes)), {"long_name": "candidate axis index", "units": "1"}),
        "axis_longitude_grid": ("axis", mlon, {"long_name": "longitude of the candidate axis", "units": "degree"}),
        "axis_latitude_grid": ("axis", mlat, {"long_name": "latitude of the candidate axis", "units": "degree"}),
        "solution": ("solution", [r[0] for r in rows], {"long_name": "alternative solution", "units": "1"})})
    meta = {"axis_longitude": ("degree", "longitude of the inertial spin axis"),
            "axis_latitude": ("degree", "latitude of the inertial spin axis"),
            "period": ("s", "spin period"), "phase": ("degree", "spin angle at t = 0")}
    for j, (key, (u, ln)) in enumerate(meta.items()):
        ds[key] = ((), float(best[j]), {"units": u, "long_name": ln})
        ds[key + "_uncertainty"] = ((), float(sig[j]), {"units": u, "long_name": f"1-sigma uncertainty of {ln} "
                                                        "(Jacobian of the refinement)"})
    ds["axis_vector"] = (("xyz",), best_axis, {"units": "1", "long_name": "unit vector of the inertial spin axis"})
    ds["chi2"] = ((), chi2, {"units": "1", "long_name": "chi-square of the best spin state"})
    ds["reduced_chi2"] = ((), chi2 / dof, {"units": "1", "long_name": "chi-square per degree of freedom"})
    ds["chi2_map"] = ("axis", chi_map, {"units": "1", "long_name": "chi-square of the axis, minimised over "
                                        "period and phase on the grid"})
    ds["solution_chi2"] = ("solution", [r[2] for r in rows], {"units": "1", "long_name": "chi-square"})
    ds["chi2_gap"] = ("solution", [r[2] - chi2 for r in rows],
                      {"units": "1", "long_name": "chi-square above the best solution"})
    ds["solution_period"] = ("solution", [r[1][2] for r in rows], {"units": "s", "long_name": "spin period"})
    ds["solution_axis_longitude"] = ("solution", [r[1][0] for r in rows], {"units": "degree",
                                     "long_name": "longitude of the spin axis"})
    ds["solution_axis_latitude"] = ("solution", [r[1][1] for r in rows], {"units": "degree",
                                    "long_name": "latitude of the spin axis"})
    ds["solution_axis_separation"] = ("solution", [r[3] for r in rows], {"units": "degree",
                                      "long_name": "angle between the solution's axis and the best axis"})
    ds.attrs = {"axis_body": str(list(np.asarray(axis_body, float))), "offset": offset,
                "n_candidates": int(grid.size), "search_seconds": t_search,
                "search_method": method, "fixed_directions": int(fixed),
                "n_values": int(prob.y.size), "bands": ", ".join(lc["labels"])}
    return ds


# ------------------------------------------------------------------------------ benchmark


def benchmark_spin_search(
    n_candidates: Sequence[int] = (2500, 5000, 10000),
    n_samples: int = 300,
    bands: Sequence[str] = ("V", "R", "I"),
    n_threads: int | None = None,
    spacecraft: Any = None,
    methods: Sequence[str] = ("direct", "shift"),
) -> list[dict[str, Any]]:
    """Wall time of the spin-state search of :func:`fit_spin`.

    A synthetic light curve of ``n_samples`` times in each band at fixed directions; the
    candidates are Fibonacci axes x 10 periods x 10 phases (``n/100`` axes).  ``direct``
    runs every candidate at every time through the kernel; ``shift`` evaluates the kernel
    once per axis on the spin-angle grid.  Returns one row per method and size:
    ``method``, ``candidates``, ``samples``, ``bands``, ``seconds``, ``per_candidate_ms``.
    """
    from .spacecraft import canx1

    sc = spacecraft if spacecraft is not None else canx1()
    t = np.linspace(0.0, 300.0, n_samples)
    nb = len(bands)
    lc = xr.Dataset({"flux": ("obs", np.ones(n_samples * nb)), "flux_uncertainty": ("obs", np.full(n_samples * nb, 0.02))},
                    coords={"time": ("obs", np.repeat(t, nb)), "band": ("obs", np.tile(list(bands), n_samples))})
    data = light_curve_fluxes(lc)
    kern = _Kernel(sc, list(bands))
    prob = _Problem(data, kern, [1.0, 0, 0], [np.cos(0.5), np.sin(0.5), 0.0], np.array([0.0, 0, 1]), "band")
    periods = np.linspace(20.0, 40.0, 10)
    phases = np.arange(10) * 36.0
    _search(prob, fibonacci_sphere(2), periods[:1], phases[:1], n_threads)  # compile, warm caches
    rows = []
    for method in methods:
        run = {"direct": _search, "shift": _search_shift}[method]
        for n in n_candidates:
            axes = fibonacci_sphere(max(1, int(n) // 100))
            t0 = time.perf_counter()
            run(prob, axes, periods, phases, n_threads)
            dt = time.perf_counter() - t0
            nc = len(axes) * 100
            rows.append({"method": method, "candidates": nc, "samples": n_samples, "bands": nb,
                         "seconds": dt, "per_candidate_ms": 1e3 * dt / nc})
    return rows


# ------------------------------------------------------------------------------ measured data


def band_terms(per_material: xr.DataArray, bands: Sequence[str]) -> xr.DataArray:
    """Per-material band signals [m2 sr-1]: the solar-weighted band means of ``signal_material``
    (:func:`sbrdf_xr.photometry.band_weights` normalised), ``wavelength`` replaced by ``band``."""
    from .photometry import band_weights

    w = band_weights(list(bands), per_material["wavelength"].values, normalize=True)
    out = xr.dot(per_material, w.rename({"wavelength": "_wl"}).assign_coords(_wl=per_material["wavelength"].values)
                 .rename({"_wl": "wavelength"}), dim="wavelength")
    out.attrs = {"units": "m2 sr-1", "long_name": "band signal of each material"}
    return out


def magnitudes_to_signal(light_curve: xr.Dataset, range_km: float) -> tuple[xr.DataArray, xr.DataArray]:
    """Band signal [m2 sr-1] and its uncertainty from measured magnitudes (one per band).

    Inverts :func:`sbrdf_xr.photometry.magnitudes` at 1 AU:
    ``S = d**2 10**(-0.4 (m - m_sun))``, ``sigma_S = S ln(10)/2.5 sigma_m``.
    """
    from .photometry import sun_magnitudes

    if not np.isfinite(range_km) or range_km <= 0:
        raise InversionError(f"range_km: must be finite and > 0, got {range_km}")
    bands = [str(b) for b in light_curve["band"].values]
    if len(set(bands)) != len(bands):
        raise InversionError(f"magnitudes: one value per band expected (a spectrum in bands), got bands {bands}")
    msun = sun_magnitudes(bands).values
    m = np.asarray(light_curve["magnitude"].values, dtype=np.float64)
    s = (range_km * 1e3) ** 2 * 10 ** (-0.4 * (m - msun))
    sig = s * _LN10_2P5 * np.asarray(light_curve["uncertainty"].values, dtype=np.float64)
    coords = {"band": bands}
    return (xr.DataArray(s, dims="band", coords=coords, attrs={"units": "m2 sr-1", "long_name": "band signal"}),
            xr.DataArray(sig, dims="band", coords=coords, attrs={"units": "m2 sr-1",
                                                                   "long_name": "uncertainty of the band signal"}))


def read_spectrum(path: str | os.PathLike[str]) -> tuple[xr.DataArray, xr.DataArray]:
    """A measured spectrum from CSV or netCDF: columns ``wavelength`` [nm], ``signal``
    [m2 sr-1] and ``uncertainty`` (same units, > 0)."""
    from pathlib import Path

    import pandas as pd

    path = Path(path)
    if not path.is_file():
        raise InversionError(f"spectrum: file {path} does not exist")
    if path.suffix.lower() in (".nc", ".nc4"):
        with xr.open_dataset(path) as ds:
            df = ds.load().reset_coords().to_dataframe().reset_index()
    else:
        df = pd.read_csv(path, skipinitialspace=True)
        df.columns = [str(c).strip() for c in df.columns]
    missing = [c for c in ("wavelength", "signal", "uncertainty") if c not in df.columns]
    if missing:
        raise InversionError(f"{path}: missing columns {missing}; needs wavelength, signal, uncertainty")
    wl = df["wavelength"].to_numpy(dtype=np.float64)
    y = xr.DataArray(df["signal"].to_numpy(dtype=np.float64), dims="wavelength", coords={"wavelength": wl},
                     attrs={"units": "m2 sr-1", "long_name": "measured signal"})
    return y, y.copy(data=df["uncertainty"].to_numpy(dtype=np.float64))
