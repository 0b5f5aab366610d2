"""Goodness of fit of an inversion: the chi-square against its distribution.

For Gaussian errors of known variance and a model that is right, the chi-square of a
least-squares fit with ``dof = n - p`` degrees of freedom follows the chi-square
distribution of ``dof`` degrees of freedom (Press et al., *Numerical Recipes*, 3rd ed.,
§15.1 and §15.2).  A value beyond its 99.9 % point says the model does not describe the
data within their uncertainties; one below its 0.1 % point, that the uncertainties are
overstated.  Either way the fitted uncertainties are not to be taken at face value, and
:class:`~sbrdf_xr.errors.FitQualityWarning` says so, naming the likely causes.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..errors import FitQualityWarning

__all__ = ["QUALITY_LEVEL", "fit_quality", "quality_attrs"]

#: Two-sided level of the chi-square check: a warning beyond the ``1 - QUALITY_LEVEL`` point
#: of the chi-square distribution (or below its ``QUALITY_LEVEL`` point).
QUALITY_LEVEL = 1e-3


def fit_quality(
    chi2: float,
    dof: int,
    what: str,
    causes: Sequence[str],
    *,
    level: float = QUALITY_LEVEL,
    warn: bool = True,
    stacklevel: int = 3,
) -> dict[str, Any]:
    """Check a chi-square against the chi-square distribution of ``dof`` degrees of freedom.

    Parameters
    ----------
    chi2 : float
        Chi-square of the fit [1].
    dof : int
        Degrees of freedom (values minus fitted parameters).
    what : str
        The fit, for the message (``"unmix"``, ``"spin fit"``).
    causes : sequence of str
        Likely causes of a chi-square that is too large, most likely first.
    level : float
        The tail probability of the check (default 0.1 %).
    warn : bool
        Issue :class:`~sbrdf_xr.errors.FitQualityWarning` when the check fails.

    Returns
    -------
    dict
        ``fit_probability`` (probability of a chi-square at least this large), ``fit_quality``
        (``"consistent"``, ``"poor"`` or ``"too good"``), ``chi2_limit_low``,
        ``chi2_limit_high`` (the ``level`` and ``1 - level`` points) and ``birge_ratio``
        (``sqrt(chi2 / dof)``); ``fit_quality_note`` when the check fails.

    Examples
    --------
    A chi-square of 100 for 90 degrees of freedom is well inside its distribution (its
    99.9 % point is 137.2); 200 is not:

    >>> import warnings
    >>> from sbrdf_xr.invert._quality import fit_quality
    >>> q = fit_quality(100.0, 90, "demo", ["a wrong model"])
    >>> q["fit_quality"], round(q["chi2_limit_high"], 1)
    ('consistent', 137.2)
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     q = fit_quality(200.0, 90, "demo", ["a wrong model"])
    >>> q["fit_quality"], caught[0].category.__name__
    ('poor', 'FitQualityWarning')
    >>> print(str(caught[0].message)[:78])
    demo: chi2 200 for 90 degrees of freedom (reduced 2.222) lies beyond the 99.9
    """
    from scipy.stats import chi2 as dist

    out: dict[str, Any] = {}
    if dof <= 0 or not np.isfinite(chi2):
        out.update(
            fit_probability=float("nan"),
            fit_quality="undetermined",
            chi2_limit_low=float("nan"),
            chi2_limit_high=float("nan"),
            birge_ratio=float("nan"),
        )
        return out
    lo, hi = (float(v) for v in dist.ppf([level, 1.0 - level], dof))
    out["fit_probability"] = float(dist.sf(chi2, dof))
    out["chi2_limit_low"], out["chi2_limit_high"] = lo, hi
    out["birge_ratio"] = float(np.sqrt(chi2 / dof))
    head = f"{what}: chi2 {chi2:.4g} for {dof} degrees of freedom (reduced {chi2 / dof:.4g}) lies "
    pct = f"{100 * (1 - level):g} %"
    if chi2 > hi:
        out["fit_quality"] = "poor"
        note = (
            f"{head}beyond the {pct} point {hi:.4g} of its chi-square distribution: the model "
            "does not describe the data within their uncertainties. Likely causes: "
            + "; ".join(causes)
            + ". The uncertainties assume a right model; scaled by the Birge ratio "
            f"sqrt(chi2/dof) = {out['birge_ratio']:.3g} they would allow for a random misfit, "
            "not for a wrong model"
        )
    elif chi2 < lo:
        out["fit_quality"] = "too good"
        note = (
            f"{head}below the {100 * level:g} % point {lo:.4g} of its chi-square distribution: "
            "the uncertainties are likely overstated (or the values are not independent), so "
            "the fitted uncertainties are too large"
        )
    else:
        out["fit_quality"] = "consistent"
        return out
    out["fit_quality_note"] = note
    if warn:
        warnings.warn(note, FitQualityWarning, stacklevel=stacklevel)
    return out


def quality_attrs(quality: Mapping[str, Any]) -> dict[str, Any]:
    """The attributes a fit's result carries from :func:`fit_quality`: ``fit_quality``,
    ``birge_ratio`` and, when the check failed, ``fit_quality_note``.

    Examples
    --------
    >>> from sbrdf_xr.invert._quality import fit_quality, quality_attrs
    >>> sorted(quality_attrs(fit_quality(100.0, 90, "demo", ["a wrong model"])))
    ['birge_ratio', 'fit_quality']
    """
    keys = ("fit_quality", "birge_ratio", "fit_quality_note")
    return {k: quality[k] for k in keys if k in quality}
