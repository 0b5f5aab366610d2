"""Material unmixing: weighted linear least squares on the per-material terms.

See the package docstring.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from ..errors import FitQualityWarning, InversionError
from ..units import to_unit
from ._areas import add_areas, area_constraint, material_areas
from ._library import MATERIAL, design, library
from ._quality import fit_quality
from ._selection import DROP_Z, bias_ratio, subsets_to_score
from ._unmix_posterior import unmix_posterior
from ._unseen import constrained_by as _pinned_by
from ._unseen import correlation, unconstrained_note, unseen_columns

__all__ = [
    "DEGENERACY_THRESHOLD",
    "DROP_BIAS",
    "DROP_Z",
    "MATERIAL",
    "material_areas",
    "unmix",
]

#: Default ``|correlation|`` between two materials' estimates above which they are degenerate.
DEGENERACY_THRESHOLD = 0.95
#: A material is left out of the model only if the bias its omission can cause on every other
#: estimate stays below this fraction of that estimate's uncertainty.
DROP_BIAS = 0.5

UNMIX_CAUSES = (
    "the simulated geometry differs from that of the measurement (attitude, Sun or observer "
    "direction: --isel or the cube)",
    "a material of the spacecraft is missing from the candidate library",
    "the material tables or the mesh do not describe the spacecraft",
    "the uncertainties are understated (calibration, atmosphere, systematic errors)",
)


def _wls(
    aw: np.ndarray,
    yw: np.ndarray,
    cols: list[int],
    con: tuple[np.ndarray, float] | None = None,
) -> tuple[np.ndarray, np.ndarray, float]:
    """Weighted least squares on the columns ``cols``: estimate, covariance, chi-square.

    With ``con = (c, total)`` the estimate obeys ``c[cols] . x = total`` (Seber & Lee
    2003, *Linear Regression Analysis*, §3.8), solved through the Lagrange (KKT) system
    ``[[A^T A, c], [c^T, 0]] [x, l] = [A^T y, total]`` whose inverse's upper-left block is
    the covariance: it holds when ``A^T A`` is singular, so a material the data never see
    is pinned by the constraint (by elimination), with the others' uncertainties.  Columns
    never seen (:func:`unseen_columns`) are tied to one common scale (the data cannot split
    them); without the constraint they keep scale 0 and variance 0 here and are reported
    as unconstrained by :func:`unmix`.  A subset whose ``c`` is 0 cannot meet the
    constraint (chi-square infinite).
    """
    a = aw[:, cols]
    k = len(cols)
    x = np.zeros(k)
    cov = np.zeros((k, k))
    unseen = unseen_columns(aw)[cols]
    seen = np.flatnonzero(~unseen)
    if con is None:
        if seen.size:
            g = a[:, seen]
            cov[np.ix_(seen, seen)] = np.linalg.pinv(g.T @ g)
            x[seen] = np.linalg.lstsq(g, yw, rcond=None)[0]
    else:
        c = con[0][cols]
        if not np.any(c != 0):
            return x, cov, np.inf
        # the unseen columns as one (tied) scale: a column of zeros with their summed area
        tie = np.flatnonzero(unseen & (c != 0))
        g = a[:, seen]
        cs = c[seen]
        if tie.size:
            g = np.hstack([g, np.zeros((a.shape[0], 1))])
            cs = np.append(cs, c[tie].sum())
        m = g.shape[1]
        kkt = np.block([[g.T @ g, cs[:, None]], [cs[None, :], np.zeros((1, 1))]])
        try:
            inv = np.linalg.inv(kkt)
        except np.linalg.LinAlgError:
            inv = np.linalg.pinv(kkt)
        sol = inv @ np.append(g.T @ yw, con[1])
        idx = np.append(seen, tie[:1]) if tie.size else seen
        x[idx] = sol[:m]
        cov[np.ix_(idx, idx)] = inv[:m, :m]
        if tie.size > 1:  # every tied column the same scale, fully correlated
            x[tie] = sol[m - 1]
            cov[np.ix_(tie, tie)] = inv[m - 1, m - 1]
            cov[np.ix_(tie, seen)] = inv[m - 1, : m - 1]
            cov[np.ix_(seen, tie)] = inv[: m - 1, m - 1][:, None]
    r = yw - a @ x
    return x, cov, float(r @ r)


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
    drop_bias: float = DROP_BIAS,
    total_area: float | bool | None = None,
    method: str = "point",
    posterior_walkers: int | None = None,
    posterior_steps: int | None = None,
    seed: int = 0,
) -> xr.Dataset:
    """Effective area scale factor of each material from a measured spectrum or band fluxes.

    Solves ``min || W^1/2 (y - A a) ||^2`` (weighted linear least squares), where the
    columns of ``A`` are the simulated per-material signals (``signal_material``) at the
    measured wavelengths or bands and samples, ``W = diag(sigma^-2)``; ``a_m = 1`` means
    the material's area as simulated.  The covariance is ``(A^T W A)^-1``.  The estimates
    are not bounded below: a negative one says the material is not detected (bounding it
    at zero, as NNLS does, makes the other uncertainties conditional on the bound and no
    longer calibrated).

    Which materials are in the model: subsets of the candidates are scored by the
    information criterion (``AIC = chi2 + 2k``, ``BIC = chi2 + k ln n``; Burnham &
    Anderson 2002, §2.2, §6.4), with their Akaike or BIC weights ``exp(-delta/2)``
    normalised (§2.9, §6.4).  A subset that leaves materials out is admissible only if
    the bias that their omission can cause on every kept estimate (the leave-out shift
    ``-C_SD C_DD^-1 x_D`` of the full fit, with each left-out scale up to its
    ``|estimate| + 2 sigma``) stays below ``drop_bias`` times that estimate's uncertainty;
    the chosen model is the admissible subset of lowest criterion (the full set is always
    admissible).  So a material the data cannot pin down is kept, with the large
    uncertainty it brings, rather than dropped with a confident and biased remainder.

    With ``total_area`` the areas ``a_m A_m`` (``A_m`` from ``areas``) must add up to a
    known total, e.g. the mesh's: equality-constrained weighted least squares (Seber &
    Lee 2003, *Linear Regression Analysis*, §3.8), ``x_c = x - C c^T (c C c^T)^-1 (c x -
    A)``, ``C_c = C - C c^T (c C c^T)^-1 c C`` with ``c = (A_m)``.  It holds for the
    materials of every subset scored: a left-out material has area 0 and the kept ones
    fill the total.  The selection accounts for it: each subset is fitted with the
    constraint, the leave-out bias is that of the constrained full fit (adding ``x_D =
    0`` to the constraint shifts the kept estimates by ``-C_c,SD C_c,DD^-1 x_c,D``, the
    same formula on the constrained covariance), and the criteria, ``dof`` and
    ``reduced_chi_square`` count one free parameter less.  Use it when the library holds every
    material of the body and the data are calibrated: the total then pins down a
    material the spectrum hardly sees (dark, or never lit), by elimination.

    Parameters
    ----------
    measured : DataArray
        Over ``wavelength`` [nm] or ``band``, optionally with sample dimensions (e.g.
        ``time``, ``geometry``) shared with ``simulated``; in the units of the simulated
        signal [m2 sr-1] (or any multiple of them, then ``a`` carries the factor).
    simulated : DataArray, Dataset or mapping of str to DataArray
        Per-material terms with a ``material`` dimension (``simulate(..., outputs=(...,
        "per_material"))``), or a candidate library: name to a term each.  Simulated
        wavelengths are interpolated linearly to the measured ones (candidates of a
        library on other wavelength grids too, with a note in ``attrs["library_note"]``).
    uncertainty : array_like or DataArray
        1-sigma measurement errors, broadcast against ``measured``; > 0.
    areas : mapping of str to float, optional
        Nominal area of each material [m2] (:func:`material_areas`): adds ``area`` [m2]
        and ``area_fraction`` [1] with their uncertainties.  ``area_fraction`` is the
        fraction of the summed fitted area of the candidates (without ``total_area``) or
        of ``total_area`` (with it); its attribute ``normalisation`` says which.
    total_area : float, True or None
        Constrain the fitted areas to add up to this [m2] (True: the sum of every value
        of ``areas``, the mesh's total area when they come from :func:`material_areas`);
        needs ``areas``.  Default None: unconstrained.
    select : {"all", "greedy", None}
        Subsets scored: every subset up to ``max_materials``, a forward greedy path, or
        only the full set of candidates.
    max_materials : int, optional
        Largest subset tried (default: all candidates); the full set is always scored.
    criterion : {"bic", "aic"}
        Information criterion minimised by the selection.
    degeneracy_threshold : float
        ``|correlation|`` of two estimates above which the pair is reported as degenerate.
    drop_bias : float
        Largest bias, in units of the kept estimates' uncertainties, that leaving
        materials out may cause (default :data:`DROP_BIAS`).
    method : {"point", "posterior"}
        ``"posterior"``: the chosen model's scales also sampled by emcee inside physics
        (scales >= 0, no area above the body's, on the plane of ``total_area``;
        :mod:`sbrdf_xr.invert._unmix_posterior`), adding ``posterior_median``,
        ``posterior_sd``, ``posterior_low``, ``posterior_high`` (and
        ``posterior_fraction_*`` with ``areas``) over ``material``; a material never lit
        and seen gets its prior (or what the constraint leaves it).
    posterior_walkers, posterior_steps, seed
        The sampler's walkers (default ``2 n + 2``, at least 8), steps (default: grown
        until the chain spans 50 autocorrelation times) and seed; a budget beyond 200000
        evaluations is refused.

    Returns
    -------
    xarray.Dataset
        Over ``material``: ``scale``, ``scale_uncertainty`` and ``significance`` [1],
        ``selected`` (bool), ``importance`` (the summed weights of the subsets holding the
        material), ``area``, ``area_uncertainty`` [m2], ``area_fraction`` and
        ``area_fraction_uncertainty`` [1] (with ``areas``), ``correlation`` (material,
        material_b); scalars ``chi2``, ``reduced_chi_square``, ``degrees_of_freedom``,
        ``fit_probability``, ``aic``, ``bic``, ``condition_number``; over ``subset``:
        ``subset_chi2``, ``subset_aic``, ``subset_bic``, ``subset_weight``,
        ``subset_bias_ratio``, ``subset_admissible``; ``total_area`` [m2] (with the
        constraint); attributes ``selected_materials``, ``selection_note``,
        ``degenerate``, ``fit_quality`` (and ``fit_quality_note``), ``library_note``,
        ``area_constraint``.

    Warns
    -----
    FitQualityWarning
        When the chi-square lies beyond the 99.9 % point of its distribution (the model
        does not describe the data: wrong geometry, a material missing from the library)
        or below its 0.1 % point (uncertainties overstated); and when the fit has 0 degrees
        of freedom (as many free parameters as measured values: nothing is tested).

    Raises
    ------
    InversionError
        Measured wavelengths outside the simulated range or bands not simulated, fewer
        samples than parameters, uncertainties not > 0, NaN data.

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

    A spectrum made of 0.8 times the grey area and 1.5 times the red, with 1 % noise,
    gives back those scale factors within their uncertainties:

    >>> from sbrdf_xr.invert import material_areas, unmix
    >>> terms = cube.signal_material
    >>> truth = 0.8 * terms.sel(material="grey") + 1.5 * terms.sel(material="red")
    >>> sigma = 0.01 * float(truth.max())
    >>> measured = truth + sigma * np.random.default_rng(1).normal(size=truth.shape)
    >>> fit = unmix(measured, cube, sigma, areas=material_areas(box))
    >>> fit.scale.round(3).values.tolist(), fit.scale_uncertainty.round(3).values.tolist()
    ([0.816, 1.488], [0.012, 0.008])
    >>> fit.attrs["selected_materials"], fit.attrs["degenerate"], fit.attrs["fit_quality"]
    ('grey, red', 'none', 'consistent')
    >>> fit.area_fraction.attrs["long_name"]
    'fraction of the summed effective area of the fitted candidate materials'

    Grey covers 4 m2 and red 2 m2 of the cube, so the truth above has areas of 3.2 and
    3.0 m2, 6.2 m2 in all.  Constrained to that total, the fit keeps one free parameter
    and the fractions add up to 1 exactly:

    >>> tied = unmix(measured, cube, sigma, areas=material_areas(box), total_area=6.2)
    >>> tied.scale.round(3).values.tolist()
    [0.805, 1.491]
    >>> int(tied.degrees_of_freedom), int(fit.degrees_of_freedom)
    (25, 24)
    >>> round(float(tied.area_fraction.sum()), 12), tied.area_fraction.attrs["long_name"]
    (1.0, 'fraction of total_area, the constrained sum of the areas')
    """
    t_point = time.perf_counter()
    if isinstance(areas, Mapping):
        areas = {k: to_unit(v, "m2", "areas") for k, v in areas.items()}
    total_area = to_unit(total_area, "m2", "total_area")
    _check_options(measured, criterion, select, drop_bias, method)
    lib, notes = library(simulated, measured)
    names = [str(m) for m in lib[MATERIAL].values]
    con = area_constraint(total_area, areas, names)
    n_con = 0 if con is None else 1
    a, y, s = design(measured, uncertainty, lib)
    n, k = a.shape
    _check_sizes(n, k, n_con, names, max_materials)
    aw, yw = a / s[:, None], y / s
    kmax = k if max_materials is None else min(int(max_materials), k)
    x_full, cov_full, _ = _wls(aw, yw, list(range(k)), con)
    pen = 2.0 if criterion == "aic" else float(np.log(n))
    unseen = unseen_columns(aw)

    def npar(c: tuple[int, ...]) -> int:
        """Free parameters of a subset: its seen materials (and one for its unseen ones,
        tied, with the constraint), less the constraint."""
        u = unseen[list(c)]
        return int((~u).sum()) + int(con is not None and bool(u.any())) - n_con

    fits: dict[tuple[int, ...], tuple[np.ndarray, np.ndarray, float, float]] = {}

    def score(c: tuple[int, ...]) -> float:
        if c not in fits:
            x, cov, chi2 = _wls(aw, yw, list(c), con)
            bias = bias_ratio(x_full, cov_full, list(c), cov) if np.isfinite(chi2) else np.inf
            fits[c] = (x, cov, chi2, bias)
        return fits[c][2] + pen * npar(c)

    subsets = subsets_to_score(select, k, kmax, score)
    for c in subsets:
        score(c)
    admissible = [c for c in subsets if fits[c][3] <= drop_bias]
    best = min(admissible, key=score)
    crit = np.array([score(c) for c in subsets])
    w = np.exp(-(crit - crit.min()) / 2)  # 0 for a subset that cannot meet the constraint
    w /= w.sum()
    lowest = subsets[int(np.argmin(crit))]
    cols = list(best)
    xs, cov_s, chi2, _ = fits[best]
    x = np.zeros(k)
    x[cols] = xs
    cov = np.zeros((k, k))
    cov[np.ix_(cols, cols)] = cov_s
    sig = np.sqrt(np.clip(np.diag(cov_full), 0, None))  # left out: sigma of the full fit
    sig[cols] = np.sqrt(np.clip(np.diag(cov_s), 0, None))
    dof = n - npar(best)
    constrained_by = _pinned_by(unseen, cols, con is not None)
    free = constrained_by == "none"
    if con is None:
        x[free] = np.nan
    sig[free] = np.inf

    def label(c: tuple[int, ...]) -> str:
        return "+".join(names[j] for j in c)

    if best == lowest:
        sel_note = f"the subset of lowest {criterion.upper()} ({label(best)})"
    else:
        sel_note = (
            f"{label(best)}: the subset of lowest {criterion.upper()} ({label(lowest)}) leaves "
            f"out materials whose omission could bias the others by {fits[lowest][3]:.3g} sigma "
            f"(more than drop_bias = {drop_bias:g}); the lowest admissible subset is used"
        )
    quality = fit_quality(chi2, dof, "unmix", UNMIX_CAUSES)
    if dof <= 0:  # as many free parameters as values: an exact fit that tests nothing
        quality["fit_quality_note"] = (
            f"unmix: {n} measured values for {npar(best)} free parameters ({label(best)}): "
            "0 degrees of freedom, so the fit passes through the data whatever their errors "
            "and its chi-square tests nothing; add wavelengths, bands or geometries, or "
            "fewer candidate materials, to test the model"
        )
        warnings.warn(quality["fit_quality_note"], FitQualityWarning, stacklevel=2)
    ds = _result(
        names=names,
        x=x,
        sig=sig,
        cov=cov,
        cols=cols,
        aw=aw,
        areas=areas,
        subsets=[
            (
                label(c),
                fits[c][2],
                fits[c][3],
                fits[c][2] + 2 * npar(c),
                fits[c][2] + npar(c) * np.log(n),
                wi,
            )
            for c, wi in zip(subsets, w, strict=True)
        ],
        scalars={"chi2": chi2, "dof": dof, "n": n, "npar": npar(best)},
        constrained_by=constrained_by,
        total=None if con is None else con[1],
        importance=np.array(
            [sum(wi for c, wi in zip(subsets, w, strict=True) if j in c) for j in range(k)]
        ),
        attrs={
            "selected_materials": ", ".join(names[j] for j in cols),
            "criterion": criterion,
            "selection": str(select),
            "selection_note": sel_note,
            "drop_bias": drop_bias,
            "area_constraint": (
                "none"
                if con is None
                else f"the areas of the fitted materials add up to total_area = {con[1]:.6g} m2 "
                "(equality-constrained least squares; the information criteria count one "
                "parameter less, the degrees of freedom one more)"
            ),
            "library_note": "; ".join(notes) if notes else "every candidate on the measured grid",
            **{k_: v for k_, v in quality.items() if k_.startswith("fit_quality")},
        },
        quality=quality,
        degeneracy_threshold=degeneracy_threshold,
    )
    if method == "posterior":
        opts: dict[str, Any] = {"walkers": posterior_walkers, "steps": posterior_steps}
        t_point = time.perf_counter() - t_point
        fit: dict[str, Any] = {"aw": aw, "yw": yw, "x": x, "cov": cov, "cols": cols, "con": con}
        ds = unmix_posterior(ds, areas=areas, point_seconds=t_point, seed=seed, **fit, **opts)
    return ds


def _check_options(
    measured: Any, criterion: str, select: Any, drop_bias: float, method: str
) -> None:
    """Refuse options outside their allowed values."""
    if method not in ("point", "posterior"):
        raise InversionError(
            f"method: {method!r}; allowed 'point' (least squares) or 'posterior' (emcee)"
        )
    if not isinstance(measured, xr.DataArray):
        raise InversionError(
            f"measured: expected a DataArray over wavelength or band, got {type(measured).__name__}"
        )
    if criterion not in ("aic", "bic"):
        raise InversionError(f"criterion: {criterion!r}; allowed 'aic', 'bic'")
    if select not in ("all", "greedy", None):
        raise InversionError(f"select: {select!r}; allowed 'all', 'greedy', None")
    if not (np.isfinite(drop_bias) and drop_bias >= 0):
        raise InversionError(f"drop_bias: {drop_bias!r}; allowed a finite number >= 0")


def _check_sizes(n: int, k: int, n_con: int, names: list[str], max_materials: Any) -> None:
    """Enough values for the parameters; a largest subset of at least one material."""
    if n < k - n_con:
        raise InversionError(
            f"measured: {n} values for {k - n_con} material parameters ({', '.join(names)}"
            f"{', their areas summing to total_area' if n_con else ''}); need at least as many "
            "values as parameters (more wavelengths, bands or geometries, or fewer candidates)"
        )
    if max_materials is not None and int(max_materials) < 1:
        raise InversionError(f"max_materials: {max_materials!r}; allowed an integer >= 1")


def _result(
    *,
    constrained_by: np.ndarray,
    names: list[str],
    x: np.ndarray,
    sig: np.ndarray,
    cov: np.ndarray,
    cols: list[int],
    aw: np.ndarray,
    areas: Mapping[str, float] | None,
    subsets: list[tuple[Any, ...]],
    scalars: dict[str, Any],
    importance: np.ndarray,
    attrs: dict[str, Any],
    quality: dict[str, Any],
    degeneracy_threshold: float,
    total: float | None,
) -> xr.Dataset:
    """The result Dataset of :func:`unmix`."""
    k = len(names)
    corr = np.full((k, k), np.nan)
    corr[np.ix_(cols, cols)] = correlation(cov)[np.ix_(cols, cols)]
    seen = constrained_by == "data"
    cand_full = np.zeros((k, k))
    cand_full[np.ix_(seen, seen)] = np.linalg.pinv(aw[:, seen].T @ aw[:, seen])
    cand_corr = correlation(cand_full)
    sv = np.linalg.svd(aw, compute_uv=False)
    cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else np.inf
    degenerate = [
        f"{names[i]} / {names[j]} (correlation {cand_corr[i, j]:+.3f})"
        for i in range(k)
        for j in range(i + 1, k)
        if np.isfinite(cand_corr[i, j]) and abs(cand_corr[i, j]) > degeneracy_threshold
    ]
    selected = np.isin(np.arange(k), cols)
    ds = xr.Dataset(
        coords={
            MATERIAL: (MATERIAL, names, {"long_name": "material", "units": "1"}),
            "material_b": ("material_b", names, {"long_name": "material", "units": "1"}),
            "subset": (
                "subset",
                [t[0] for t in subsets],
                {"long_name": "materials fitted", "units": "1"},
            ),
        }
    )
    per_material = {
        "scale": (x, "effective area scale factor of the material (1: its area as simulated)"),
        "scale_uncertainty": (
            sig,
            "1-sigma uncertainty of the scale factor (the chosen model's (A^T W A)^-1; "
            "left out of it: with every candidate fitted)",
        ),
        "significance": (
            np.where(
                selected & np.isfinite(x), np.nan_to_num(x) / np.where(sig > 0, sig, np.inf), 0.0
            ),
            "scale factor over its uncertainty (0 when left out or not constrained)",
        ),
        "constrained_by": (
            constrained_by,
            "what pins the scale factor: data (the material is lit and seen), total_area (never "
            "lit and seen: by elimination through the area constraint) or none (not "
            "constrained: NaN, or a tied share of the constraint, with an infinite uncertainty)",
        ),
        "selected": (selected, "material in the chosen model"),
        "importance": (
            importance,
            "summed information-criterion weights of the subsets holding the material",
        ),
    }
    for key, (val, ln) in per_material.items():
        ds[key] = (MATERIAL, val, {"units": "1", "long_name": ln})
    ds["correlation"] = (
        (MATERIAL, "material_b"),
        corr,
        {"units": "1", "long_name": "correlation of the scale factors in the chosen model"},
    )
    ds["candidate_correlation"] = (
        (MATERIAL, "material_b"),
        cand_corr,
        {"units": "1", "long_name": "correlation of the scale factors with every candidate fitted"},
    )
    if areas is not None:
        add_areas(ds, names, x, sig, cov, areas, total)
    chi2, dof, n, npar = (scalars[k_] for k_ in ("chi2", "dof", "n", "npar"))
    scal = {
        "chi2": (chi2, "chi-square of the chosen model"),
        "degrees_of_freedom": (
            dof,
            "degrees of freedom (values minus fitted scale factors, plus one for the area "
            "constraint)"
            if total is not None
            else "degrees of freedom (values minus fitted scale factors)",
        ),
        "reduced_chi_square": (
            chi2 / dof if dof > 0 else np.nan,
            "chi-square per degree of freedom",
        ),
        "fit_probability": (
            quality["fit_probability"],
            "probability of a chi-square at least this large for a right model",
        ),
        "aic": (chi2 + 2 * npar, "Akaike information criterion chi2 + 2k (k free parameters)"),
        "bic": (chi2 + npar * np.log(n), "Bayesian information criterion chi2 + k ln n"),
        "condition_number": (cond, "condition number of the weighted design of all candidates"),
        "n_samples": (n, "number of measured values"),
    }
    for key, (val, ln) in scal.items():
        ds[key] = ((), val, {"units": "1", "long_name": ln})
    table = {
        "subset_chi2": (1, "chi-square of the subset"),
        "subset_bias_ratio": (
            2,
            "largest bias its left-out materials can cause on a kept estimate, in sigma",
        ),
        "subset_aic": (3, "Akaike information criterion of the subset"),
        "subset_bic": (4, "Bayesian information criterion of the subset"),
        "subset_weight": (5, "information-criterion weight of the subset (of the criterion used)"),
    }
    for key, (j, ln) in table.items():
        ds[key] = (
            "subset",
            np.array([t[j] for t in subsets], dtype=float),
            {"units": "1", "long_name": ln},
        )
    ds["subset_admissible"] = (
        "subset",
        ds["subset_bias_ratio"].values <= attrs["drop_bias"],
        {
            "units": "1",
            "long_name": "left-out materials bias the others by at most drop_bias sigma",
        },
    )
    ds.attrs = {
        **attrs,
        "unconstrained": unconstrained_note(names, constrained_by),
        "degenerate": "; ".join(degenerate) if degenerate else "none",
        "degeneracy_note": (
            f"the data cannot tell apart: {'; '.join(degenerate)}"
            if degenerate
            else f"no pair of candidates correlated beyond {degeneracy_threshold}"
        ),
    }
    return ds
