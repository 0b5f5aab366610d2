"""Materials the data never see, and correlations that stay in [-1, 1].

A material never lit and seen at the measured geometries has a zero column in the design
of :func:`sbrdf_xr.invert.unmix`: the data say nothing about its area.  With the areas
constrained to a known total it is pinned by elimination (the Lagrange system of
equality-constrained least squares, Seber & Lee 2003, *Linear Regression Analysis*,
§3.8); without, it is not constrained and is reported so.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..errors import FitQualityWarning

__all__ = ["UNSEEN_TOL", "constrained_by", "correlation", "unconstrained_note", "unseen_columns"]

#: A material whose weighted column norm is below this fraction of the largest is never lit
#: and seen at the measured geometries: the data say nothing about it.
UNSEEN_TOL = 1e-9


def unseen_columns(aw: np.ndarray) -> np.ndarray:
    """Columns of the weighted design that the data do not see (a material never lit and
    seen): norm at most :data:`UNSEEN_TOL` of the largest.

    Examples
    --------
    >>> from sbrdf_xr.invert._unseen import unseen_columns
    >>> unseen_columns(np.array([[1.0, 0.0], [2.0, 0.0]])).tolist()
    [False, True]
    """
    norm = np.sqrt((aw**2).sum(axis=0))
    return np.asarray(norm <= UNSEEN_TOL * max(float(norm.max(initial=0.0)), 1e-300))


def correlation(cov: np.ndarray) -> np.ndarray:
    """Correlation matrix of a covariance, in [-1, 1]; NaN in the rows and columns of a
    parameter of zero or infinite variance (not estimated, or not constrained).

    Examples
    --------
    >>> from sbrdf_xr.invert._unseen import correlation
    >>> correlation(np.array([[4.0, 2.0, 0.0], [2.0, 4.0, 0.0], [0.0, 0.0, 0.0]])).tolist()
    [[1.0, 0.5, nan], [0.5, 1.0, nan], [nan, nan, nan]]
    """
    v = np.diag(cov)
    ok = np.isfinite(v) & (v > 0)
    d = np.sqrt(np.where(ok, v, 1.0))
    with np.errstate(invalid="ignore"):
        c = np.clip(cov / np.outer(d, d), -1.0, 1.0)
    c[~ok, :] = np.nan
    c[:, ~ok] = np.nan
    return np.asarray(c)


def constrained_by(unseen: np.ndarray, cols: list[int], constrained: bool) -> np.ndarray:
    """What pins each material: ``"data"`` (seen), ``"total_area"`` (never lit and seen,
    the only such material of the chosen model, pinned by the area constraint by
    elimination) or ``"none"`` (not constrained)."""
    out = np.where(unseen, "none", "data").astype(object)
    in_model = unseen & np.isin(np.arange(unseen.size), cols)
    if constrained and int(in_model.sum()) == 1:
        out[in_model] = "total_area"
    return out.astype(str)


def unconstrained_note(names: list[str], constrained_by: np.ndarray) -> str:
    """The note on materials the data do not see (and a warning when one is free)."""
    free = [m for m, c in zip(names, constrained_by, strict=True) if c == "none"]
    tied = [m for m, c in zip(names, constrained_by, strict=True) if c == "total_area"]
    parts = []
    if free:
        parts.append(
            f"{', '.join(free)}: never lit and seen at the measured geometries (zero column), "
            "not constrained by the data: scale reported NaN (or a share of total_area) with "
            "an infinite uncertainty; with every material of the body in the library, "
            "total_area pins one such material by elimination"
        )
        warnings.warn(f"unmix: {parts[-1]}", FitQualityWarning, stacklevel=4)
    if tied:
        parts.append(
            f"{', '.join(tied)}: never lit and seen; its area is total_area less the others' "
            "(by elimination), with their uncertainties"
        )
    return "; ".join(parts) if parts else "none: every material is lit and seen"
