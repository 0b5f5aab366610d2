"""Every built table checked against its own samples.

A table is looked up (linear, :func:`sbrdf_xr.kernels.lut.lookup_kernel`) at every
measured geometry and compared with the sample there: the relative error
``|table - sample| / sample`` over the samples above the noise floor (every
non-reference sample at or above :data:`CHECK_FLOOR` times the peak of its own
incidence angle's samples, per wavelength).  Its median, 95th percentile and worst
value, and the geometry of the worst, are the table's attributes ``self_check_*``
(:func:`check_attrs`).  A median above the stated bound warns
(:class:`~sbrdf_xr.errors.NonPhysicalWarning`) naming the worst geometries; a table
that is zero where samples above the floor are not is an error
(:class:`~sbrdf_xr.errors.ValidationError`): the guard against a table of zeros.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np
import xarray as xr

from .._names import DELTA_THETA, PHI, SAMPLE, THETA_I, WAVELENGTH
from ..errors import NonPhysicalWarning, ValidationError
from ..kernels import lut as _lut
from ..units import to_unit

__all__ = [
    "CHECK_BOUND",
    "CHECK_FLOOR",
    "check_attrs",
    "sample_errors",
]

#: Samples below this fraction of the peak of their incidence angle's samples (per
#: wavelength) are in the noise and left out of the check [1].
CHECK_FLOOR = 1e-3
#: Own-sample median relative error above which a build warns [1].
CHECK_BOUND = 0.1
#: A table zero at more than this fraction of the samples above the floor is an error [1].
ZERO_FRACTION = 0.01


def sample_errors(
    table: xr.DataArray,
    theta_i: np.ndarray,
    delta_theta: np.ndarray,
    phi: np.ndarray,
    spectra: np.ndarray,
    reference: np.ndarray | None = None,
    floor: float = CHECK_FLOOR,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The table at sample geometries against the samples.

    Parameters
    ----------
    table : xarray.DataArray
        A material table (dims ``(theta_i, delta_theta, phi, wavelength)``).
    theta_i, delta_theta, phi : ndarray, shape (s,)
        Sample geometries [degree].
    spectra : ndarray, shape (s, n_wavelength)
        The samples [sr-1].
    reference : ndarray of bool, shape (s,), optional
        Reference points (left out).
    floor : float, default :data:`CHECK_FLOOR`
        Relative noise floor [1]: samples below ``floor`` times the peak of their
        incidence angle's samples at that wavelength are left out.

    Returns
    -------
    rel : ndarray, shape (s, n_wavelength)
        ``|table - sample| / sample`` [1] (NaN where left out).
    looked_up : ndarray, shape (s, n_wavelength)
        The table's values [sr-1].
    used : ndarray of bool, shape (s, n_wavelength)
        Which entries are above the floor.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials import lambertian
    >>> from sbrdf_xr.materials.selfcheck import sample_errors
    >>> table = lambertian(0.5, [500.0])
    >>> rel, _, used = sample_errors(table, np.array([30.0]), np.array([0.0]),
    ...                              np.array([0.0]), np.array([[0.5 / np.pi]]))
    >>> float(rel[0, 0]), bool(used[0, 0])
    (0.0, True)
    """
    theta_i, delta_theta, phi = (
        np.asarray(to_unit(a, "deg", n), dtype=np.float64)
        for a, n in ((theta_i, THETA_I), (delta_theta, DELTA_THETA), (phi, PHI))
    )
    spectra = np.asarray(to_unit(spectra, "sr-1", "spectra"), dtype=np.float64)
    table = table.transpose(THETA_I, DELTA_THETA, PHI, WAVELENGTH)
    got = _lut.lookup_kernel(
        np.asarray(table.values, dtype=np.float64),
        np.asarray(table[THETA_I].values),
        np.asarray(table[DELTA_THETA].values),
        np.asarray(table[PHI].values),
        theta_i,
        delta_theta,
        phi,
        "linear",
        zero_edges=_lut.table_edges(table.attrs),
        normal_blend=_lut.table_normal_blend(table.attrs),
    )
    ref = np.zeros(theta_i.size, dtype=bool) if reference is None else np.asarray(reference)
    peak = np.zeros_like(spectra)
    for t in np.unique(theta_i):
        at = (theta_i == t) & ~ref
        if at.any():
            peak[theta_i == t] = spectra[at].max(axis=0)
    used = (spectra >= floor * peak) & (spectra > 0) & ~ref[:, None]
    rel = np.full(spectra.shape, np.nan)
    rel[used] = np.abs(got[used] - spectra[used]) / spectra[used]
    return rel, got, used


def _summary(rel: np.ndarray) -> dict[str, float]:
    ok = rel[np.isfinite(rel)]
    if ok.size == 0:
        return {"median": np.nan, "p95": np.nan, "worst": np.nan, "n": 0}
    return {
        "median": float(np.median(ok)),
        "p95": float(np.percentile(ok, 95)),
        "worst": float(ok.max()),
        "n": int(ok.size),
    }


def check_attrs(prefix: str, rel: np.ndarray) -> dict[str, Any]:
    """The attributes ``<prefix>_median``, ``_p95``, ``_worst`` and ``_n`` of relative errors.

    Parameters
    ----------
    prefix : str
        ``self_check`` or ``holdout_check``.
    rel : ndarray
        Relative errors [1], NaN where left out.

    Returns
    -------
    dict

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials.selfcheck import check_attrs
    >>> check_attrs("self_check", np.array([0.0, 0.1, np.nan, 0.2]))["self_check_median"]
    0.1
    """
    return {f"{prefix}_{k}": v for k, v in _summary(rel).items()}


def _worst(rel: np.ndarray, ti, dt, ph, wl, k: int = 3) -> str:
    flat = np.where(np.isfinite(rel), rel, -1.0).ravel()
    idx = np.argsort(flat)[::-1][:k]
    parts = []
    for i in idx:
        s, w = np.unravel_index(i, rel.shape)
        parts.append(
            f"(theta_i, delta_theta, phi) = ({ti[s]:.4g}, {dt[s]:.4g}, {ph[s]:.4g}) deg at "
            f"{wl[w]:g} nm: {flat[i]:.3g}"
        )
    return "; ".join(parts)


def _self_check(
    table: xr.DataArray,
    ds: xr.Dataset,
    angles: tuple[np.ndarray, np.ndarray, np.ndarray],
    spectra: np.ndarray,
    reference: np.ndarray,
    *,
    floor: float = CHECK_FLOOR,
    bound: float = CHECK_BOUND,
) -> dict[str, Any]:
    """Check a built table against its own samples; warn or raise as the module says.

    Parameters
    ----------
    table : xarray.DataArray
        The built table.
    ds : xarray.Dataset
        Its measurement set (for the material's name).
    angles : tuple of ndarray
        ``(theta_i, delta_theta, phi)`` of the samples [degree].
    spectra : ndarray, shape (s, n_wavelength)
        The samples [sr-1].
    reference : ndarray of bool
        Reference points.
    floor : float, default :data:`CHECK_FLOOR`
        Relative noise floor [1].
    bound : float, default :data:`CHECK_BOUND`
        Median relative error above which the build warns [1].

    Returns
    -------
    dict
        The ``self_check_*`` attributes, with ``self_check_floor`` and
        ``self_check_bound``.

    Raises
    ------
    ValidationError
        If the table is zero at more than 1 % of the samples above the floor.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials import build_lut
    >>> from sbrdf_xr.testing import make_measurements
    >>> table = build_lut(make_measurements(n_wavelength=2, theta_i=(20.0, 50.0)))
    >>> bool(table.attrs["self_check_median"] < table.attrs["self_check_bound"])
    True
    """
    floor, bound = to_unit(floor, "1", "check_floor"), to_unit(bound, "1", "check_bound")
    ti, dt, ph = angles
    rel, got, used = sample_errors(table, ti, dt, ph, spectra, reference, floor)
    name = ds.attrs.get("material", "unnamed")
    wl = np.asarray(table[WAVELENGTH].values)
    zero = used & (got <= 0)
    if zero.sum() > ZERO_FRACTION * max(int(used.sum()), 1):
        s, w = np.argwhere(zero)[0]
        raise ValidationError(
            f"build_lut: the table of {name!r} is zero at {int(zero.sum())} of the "
            f"{int(used.sum())} sample values above the noise floor, where the samples are not "
            f"(first: theta_i = {ti[s]:.6g}, delta_theta = {dt[s]:.6g}, phi = {ph[s]:.6g} deg, "
            f"{wl[w]:g} nm, sample {spectra[s, w]:.4g} sr-1); allowed: at most "
            f"{ZERO_FRACTION:.0%}. The construction lost the samples: check their angles"
        )
    out = check_attrs("self_check", rel)
    out.update(self_check_floor=floor, self_check_bound=bound)
    if out["self_check_n"] and out["self_check_median"] > bound:
        warnings.warn(
            f"build_lut: the table of {name!r} misses its own samples: median relative "
            f"error {out['self_check_median']:.3g} above the bound {bound:g} (95th percentile "
            f"{out['self_check_p95']:.3g}, worst {out['self_check_worst']:.3g}); worst at "
            + _worst(rel, ti, dt, ph, wl),
            NonPhysicalWarning,
            stacklevel=3,
        )
    return out


def _holdout_check(
    build: Callable[[xr.Dataset], xr.DataArray],
    ds: xr.Dataset,
    angles: tuple[np.ndarray, np.ndarray, np.ndarray],
    spectra: np.ndarray,
    reference: np.ndarray,
    *,
    every: int = 4,
    floor: float = CHECK_FLOOR,
    folds: Iterable[int] | None = None,
) -> dict[str, Any]:
    """The leave-out check: held-out samples predicted by a table built without them.

    Every ``every``-th sample of each incidence angle's scan (in ``delta_theta`` order,
    its two ends kept in) is left out; ``build`` makes a table from the rest (with its
    own fit), which is looked up at them.  The floor is that of the whole scan.  Fold
    ``j`` holds out the samples whose index among the scan's inner samples is ``j``
    modulo ``every``.  The build's own check is fold ``every // 2`` (``folds`` not
    given); ``folds=range(every)`` holds every inner sample out once (``every``
    builds) and pools the relative errors of all folds: about ``every`` times the
    held-out samples, so one sample moves the median far less.

    Parameters
    ----------
    build : callable
        ``build(measurements) -> table``.
    ds : xarray.Dataset
        The measurement set.
    angles : tuple of ndarray
        ``(theta_i, delta_theta, phi)`` of its samples [degree] (snapped).
    spectra : ndarray, shape (s, n_wavelength)
        Its samples [sr-1].
    reference : ndarray of bool
        Reference points (left out of the statistics).
    every : int, default 4
        Hold out every ``every``-th sample, ``>= 2``.
    floor : float, default :data:`CHECK_FLOOR`
        Relative noise floor [1].
    folds : iterable of int, optional
        Which folds, each ``0 <= j < every``; default the one fold ``every // 2``.

    Returns
    -------
    dict
        Without ``folds``: ``holdout_check_median``, ``_p95``, ``_worst``, ``_n`` and
        ``holdout_every`` (the build's attributes).  With ``folds``: the same statistics
        pooled over the folds as ``holdout_kfold_*``, ``holdout_every``,
        ``holdout_fold_medians`` (one per fold) and the relative errors ``rel`` (NaN
        where not held out).

    Examples
    --------
    A constant table predicts constant samples exactly:

    >>> import numpy as np
    >>> import xarray as xr
    >>> from sbrdf_xr.materials import constant_material
    >>> from sbrdf_xr.materials.selfcheck import _holdout_check
    >>> ti, dt, ph = np.full(9, 30.0), np.linspace(-20.0, 20.0, 9), np.zeros(9)
    >>> args = (lambda m: constant_material(0.1, [550.0], material="c"), xr.Dataset(),
    ...         (ti, dt, ph), np.full((9, 1), 0.1), np.zeros(9, bool))
    >>> out = _holdout_check(*args)
    >>> out["holdout_check_n"], out["holdout_check_worst"]
    (2, 0.0)
    >>> out = _holdout_check(*args, folds=range(4))
    >>> out["holdout_kfold_n"], out["holdout_kfold_worst"], out["holdout_fold_medians"]
    (7, 0.0, [0.0, 0.0, 0.0, 0.0])
    """
    if int(every) < 2:
        raise ValidationError(f"holdout: must be >= 2 (or 0 for none), got {every}")
    chosen = [every // 2] if folds is None else [int(j) for j in folds]
    for j in chosen:
        if not 0 <= j < every:
            raise ValidationError(f"folds: each must lie in [0, {every - 1}], got {j}")
    rel = np.full(np.shape(spectra), np.nan)
    medians = []
    for j in chosen:
        one = _one_fold(build, ds, angles, spectra, reference, every, floor, j)
        medians.append(_summary(one)["median"])
        rel = np.where(np.isfinite(one), one, rel)
    if folds is None:
        return {**check_attrs("holdout_check", rel), "holdout_every": int(every)}
    return {
        **check_attrs("holdout_kfold", rel),
        "holdout_every": int(every),
        "holdout_fold_medians": medians,
        "rel": rel,
    }


def _one_fold(
    build: Callable[[xr.Dataset], xr.DataArray],
    ds: xr.Dataset,
    angles: tuple[np.ndarray, np.ndarray, np.ndarray],
    spectra: np.ndarray,
    reference: np.ndarray,
    every: int,
    floor: float,
    j: int,
) -> np.ndarray:
    """Fold ``j`` of :func:`_holdout_check`: the relative errors [1] at its held-out
    samples, NaN elsewhere."""
    ti, dt, _ = angles
    hold = np.zeros(ti.size, dtype=bool)
    for t in np.unique(ti):
        at = np.flatnonzero(ti == t)
        at = at[np.argsort(dt[at], kind="stable")]
        hold[at[1:-1][np.arange(at.size - 2) % every == j]] = True
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NonPhysicalWarning)
        table = build(ds.isel({SAMPLE: np.flatnonzero(~hold)}) if SAMPLE in ds.dims else ds)
    rel, _, _ = sample_errors(table, *angles, spectra, reference, floor)
    rel[~hold] = np.nan
    return rel
