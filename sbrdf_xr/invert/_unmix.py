"""Material unmixing: non-negative least squares on the per-material terms.

See the package docstring.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike
from scipy.optimize import nnls

from ..errors import InversionError

__all__ = ["DEGENERACY_THRESHOLD", "MATERIAL", "material_areas", "unmix"]

MATERIAL = "material"
#: Default ``|correlation|`` between two materials' estimates above which they are degenerate.
DEGENERACY_THRESHOLD = 0.95


# ----------------------------------------------------------------------------- unmixing


def material_areas(spacecraft: Any) -> dict[str, float]:
    """Total facet area of each material of a spacecraft [m2].

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import load_spacecraft
    >>> from sbrdf_xr.invert import material_areas
    >>> box = load_spacecraft(trimesh.creation.box(extents=(1.0, 2.0, 3.0)), material="grey")
    >>> material_areas(box)  # 2 (1 x 2 + 1 x 3 + 2 x 3)
    {'grey': 22.0}
    """
    areas = np.asarray(spacecraft.mesh.area_faces, dtype=np.float64)
    names = np.asarray(spacecraft.facet_material)
    return {str(m): float(areas[names == m].sum()) for m in np.unique(names)}


def _library(simulated: Any) -> xr.DataArray:
    """Per-material terms as one DataArray with a ``material`` dimension."""
    if isinstance(simulated, xr.Dataset):
        if "signal_material" not in simulated:
            raise InversionError(
                "simulated: a Dataset needs the variable signal_material "
                f"(simulate with outputs=(..., 'per_material')); got {list(simulated.data_vars)}"
            )
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
                            f"candidate library: {name!r} has {dim} {_describe(b)}, "
                            f"{ref_name!r} has "
                            f"{_describe(a)}; every candidate must be on the same {dim} grid"
                        )
        simulated = xr.concat(
            [da for _, da in items],
            dim=xr.DataArray([str(k) for k, _ in items], dims=MATERIAL, name=MATERIAL),
        )
    if not isinstance(simulated, xr.DataArray) or MATERIAL not in simulated.dims:
        raise InversionError(
            "simulated: expected a DataArray with a material dimension "
            "(signal_material), a Dataset holding one, or a mapping of name to DataArray"
        )
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
        raise InversionError(
            f"{what}: expected exactly one of the dimensions wavelength or band, got {da.dims}"
        )
    return dims[0]


def _align(measured: xr.DataArray, lib: xr.DataArray) -> xr.DataArray:
    """The library on the measured spectral grid (linear interpolation in wavelength)."""
    dim = _spectral_dim(measured, "measured")
    if dim not in lib.dims:
        raise InversionError(
            f"measured is over {dim} but the simulation is over {_spectral_dim(lib, 'simulated')}"
        )
    if dim == "band":
        have = [str(b) for b in lib["band"].values]
        missing = [str(b) for b in measured["band"].values if str(b) not in have]
        if missing:
            raise InversionError(
                f"measured bands {missing} are not among the simulated bands {have}"
            )
        return lib.sel(band=measured["band"].values)
    wl, mw = lib["wavelength"].values, measured["wavelength"].values
    lo, hi = float(wl.min()), float(wl.max())
    out = mw[(mw < lo - 1e-9) | (mw > hi + 1e-9)]
    if out.size:
        raise InversionError(
            f"measured wavelengths {out.min():g}..{out.max():g} nm lie outside the simulated "
            f"range {lo:g}..{hi:g} nm"
        )
    if wl.shape == mw.shape and np.allclose(wl, mw):
        return lib.assign_coords(wavelength=mw)
    return lib.interp(wavelength=mw)


def _design(
    measured: xr.DataArray, uncertainty: Any, lib: xr.DataArray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rows (every sample and wavelength) of ``A``, ``y`` and ``sigma``."""
    if not isinstance(measured, xr.DataArray):
        raise InversionError(
            f"measured: expected a DataArray over wavelength or band, got {type(measured).__name__}"
        )
    lib = _align(measured, lib)
    sigma = (
        uncertainty
        if isinstance(uncertainty, xr.DataArray)
        else xr.DataArray(
            np.broadcast_to(np.asarray(uncertainty, dtype=np.float64), measured.shape),
            dims=measured.dims,
            coords=measured.coords,
        )
    )
    y, sigma = xr.broadcast(measured, sigma)
    extra = [d for d in lib.dims if d not in y.dims and d != MATERIAL]
    if extra:
        raise InversionError(
            f"simulated has dimensions {extra} that measured lacks; select one geometry "
            "or give measurements over them"
        )
    sample_dims = list(y.dims)
    a = lib.transpose(*[d for d in sample_dims if d in lib.dims], MATERIAL)
    a = a.broadcast_like(y).transpose(*sample_dims, MATERIAL)
    yv, sv = y.values.reshape(-1).astype(np.float64), sigma.values.reshape(-1).astype(np.float64)
    if not np.all(np.isfinite(yv)):
        raise InversionError(f"measured: {int((~np.isfinite(yv)).sum())} NaN or infinite values")
    bad = ~(np.isfinite(sv) & (sv > 0))
    if bad.any():
        raise InversionError(
            f"uncertainty: must be finite and > 0, got {int(bad.sum())} values that are not "
            f"(e.g. {sv[bad][0]!r})"
        )
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
        ``|correlation|`` of two estimates above which the pair is reported as degenerate.

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

    Examples
    --------
    A unit cube with grey sides and red caps (albedo rising from 0.1 to 0.8), seen at
    two geometries.  At the first, the +x face (grey) and the +z face (red) are each
    lit at ``cos = 0.6`` and seen at ``cos = 0.8`` (or the reverse), so at 400 nm the
    per-material signals are ``0.48 * 0.5 / pi`` and ``0.48 * 0.1 / pi``:

    >>> import numpy as np, trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft, simulate
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> mesh = trimesh.creation.box()
    >>> caps = np.abs(mesh.face_normals[:, 2]) > 0.5  # the +z and -z faces are red
    >>> mesh.visual.face_colors = np.where(caps[:, None], [255, 0, 0, 255], [128, 128, 128, 255])
    >>> box = load_spacecraft(mesh, {(255, 0, 0): "red", (128, 128, 128): "grey"})
    >>> wl = np.linspace(400.0, 1000.0, 13)
    >>> tables = {"grey": lambertian(0.5, wl, material="grey"),
    ...           "red": lambertian(np.linspace(0.1, 0.8, 13), wl, material="red")}
    >>> sun = [[0.6, 0.0, 0.8], [0.8, 0.0, 0.6]]
    >>> obs = [[0.8, 0.0, 0.6], [0.0, 0.6, 0.8]]
    >>> cube = simulate(Scene(box, tables, to_sun=sun, to_observer=obs,
    ...                       outputs=("signal", "per_material")))
    >>> cube.signal_material.isel(geometry=0, wavelength=0).round(6).values.tolist()
    [0.076394, 0.015279]

    A spectrum made of 0.8 times the grey area and 1.5 times the red gives back those
    scale factors:

    >>> from sbrdf_xr.invert import material_areas, unmix
    >>> terms = cube.signal_material
    >>> measured = 0.8 * terms.sel(material="grey") + 1.5 * terms.sel(material="red")
    >>> fit = unmix(measured, cube, 0.01 * float(measured.max()), select=None,
    ...             areas=material_areas(box))
    >>> fit.scale.round(6).values.tolist(), fit.area.round(6).values.tolist()  # [1], [m2]
    ([0.8, 1.5], [3.2, 3.0])
    >>> fit.attrs["degenerate"]
    'none'
    """
    lib = _library(simulated)
    names = [str(m) for m in lib[MATERIAL].values]
    a, y, s = _design(measured, uncertainty, lib)
    n, k = a.shape
    if n < k:
        raise InversionError(
            f"measured: {n} samples for {k} material parameters; need at least as many samples "
            "as parameters"
        )
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
        results = {}
        chosen: tuple[int, ...] = ()
        best = chosen  # () until the first subset is scored
        while len(chosen) < kmax:
            trial = {tuple(sorted((*chosen, j))): None for j in range(k) if j not in chosen}
            for c in trial:
                results[c] = score(c)
            cand = min(trial, key=lambda c: results[c][crit])
            if best and results[cand][crit] >= results[best][crit]:
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
    degenerate = [
        f"{names[i]} / {names[j]} (correlation {cand_corr[i, j]:+.3f})"
        for i in range(k)
        for j in range(i + 1, k)
        if abs(cand_corr[i, j]) > degeneracy_threshold
    ]
    dof = n - int((xs > 0).sum())
    ds = xr.Dataset(
        coords={
            MATERIAL: (MATERIAL, names, {"long_name": "material", "units": "1"}),
            "material_b": ("material_b", names, {"long_name": "material", "units": "1"}),
        }
    )
    ds["scale"] = (
        MATERIAL,
        x,
        {
            "units": "1",
            "long_name": "effective area scale factor of the material (1: its area as simulated)",
        },
    )
    ds["scale_uncertainty"] = (
        MATERIAL,
        sig,
        {
            "units": "1",
            "long_name": "1-sigma uncertainty of the scale "
            "factor (active set: (A^T W A)^-1; at the bound: unconstrained; left out of the "
            "chosen model: with every candidate fitted)",
        },
    )
    ds["selected"] = (
        MATERIAL,
        np.isin(np.arange(k), cols) & (x > 0),
        {"units": "1", "long_name": "material present in the chosen model"},
    )
    ds["correlation"] = (
        (MATERIAL, "material_b"),
        corr,
        {"units": "1", "long_name": "correlation of the scale factors in the chosen model"},
    )
    ds["candidate_correlation"] = (
        (MATERIAL, "material_b"),
        cand_corr,
        {
            "units": "1",
            "long_name": "correlation of the scale factors with every "
            "candidate fitted (unconstrained)",
        },
    )
    if areas is not None:
        missing = [m for m in names if m not in areas]
        if missing:
            raise InversionError(f"areas: no area for {missing}; have {sorted(areas)}")
        nominal = np.array([float(areas[m]) for m in names])
        ds["area"] = (
            MATERIAL,
            x * nominal,
            {"units": "m2", "long_name": "effective area of the material"},
        )
        ds["area_uncertainty"] = (
            MATERIAL,
            sig * nominal,
            {"units": "m2", "long_name": "1-sigma uncertainty of the effective area"},
        )
        tot = float((x * nominal).sum())
        ds["area_fraction"] = (
            MATERIAL,
            x * nominal / tot if tot > 0 else np.zeros(k),
            {"units": "1", "long_name": "fraction of the total effective area"},
        )
    scal = {
        "chi2": (chi2, "chi-square of the chosen model"),
        "reduced_chi2": (chi2 / dof if dof > 0 else np.nan, "chi-square per degree of freedom"),
        "aic": (aic, "Akaike information criterion chi2 + 2k"),
        "bic": (bic, "Bayesian information criterion chi2 + k ln n"),
        "condition_number": (
            cond,
            "condition number of the weighted design matrix of all candidates",
        ),
    }
    for key, (val, ln) in scal.items():
        ds[key] = ((), float(val), {"units": "1", "long_name": ln})
    ds["n_samples"] = ((), n, {"units": "1", "long_name": "number of measured values"})
    ds = ds.assign_coords(
        subset=("subset", [t[0] for t in table], {"long_name": "materials fitted", "units": "1"})
    )
    for j, key in enumerate(("subset_chi2", "subset_aic", "subset_bic"), start=1):
        ds[key] = (
            "subset",
            np.array([t[j] for t in table]),
            {"units": "1", "long_name": f"{key[7:]} of the subset"},
        )
    ds.attrs = {
        "selected_materials": ", ".join(names[j] for j in cols if x[j] > 0),
        "criterion": criterion,
        "selection": str(select),
        "degenerate": "; ".join(degenerate) if degenerate else "none",
        "degeneracy_note": (
            f"the data cannot tell apart: {'; '.join(degenerate)}"
            if degenerate
            else f"no pair of candidates correlated beyond {degeneracy_threshold}"
        ),
    }
    return ds
