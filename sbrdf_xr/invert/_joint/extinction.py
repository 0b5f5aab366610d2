"""Whether a pass's air mass can tell extinction from a zero point, and the extinction prior.

The first-order extinction ``k_b X`` of band ``b`` (Hardie 1962, in *Astronomical
Techniques*, ch. 8) is told apart from a constant offset of the band only by the
spread of the air mass ``X`` over the pass: with a free offset the least-squares
uncertainty of ``k_b`` is ``1 / sqrt(sum_i (X_i - Xbar)^2 / sigma_i^2)`` (the slope of a
straight line, Press et al., *Numerical Recipes*, 3rd ed., §15.2, ``Xbar`` the
weighted mean).  When that exceeds the prior width of ``k_b`` the pass cannot measure the
extinction: over a near-constant air mass (a geostationary object) ``k_b Xbar`` is a zero
point, and a fitted ``k_b`` would only restate the assumed absolute brightness.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ...errors import InversionError
from ...units import to_unit

__all__ = ["EXTINCTION_PRIOR_WIDTH", "extinction_prior", "separable_sd"]

#: Default prior width of an extinction coefficient [mag per air mass]: the spread of
#: nightly values at one site and between sites (0.1-0.3 mag in V, e.g. Burki et al.
#: 1995, A&AS 112, 383).
EXTINCTION_PRIOR_WIDTH = 0.1


def separable_sd(airmass: np.ndarray, sigma: np.ndarray, band: np.ndarray, nb: int) -> np.ndarray:
    """The uncertainty [mag per air mass] of each band's extinction coefficient with a free
    zero point: ``1 / sqrt(sum_i (X_i - Xbar)^2 / sigma_i^2)`` over the band's values
    (``inf`` for a band whose air mass does not change).

    Examples
    --------
    >>> from sbrdf_xr.invert._joint.extinction import separable_sd
    >>> x = np.array([1.0, 2.0, 5.7818, 5.7820])
    >>> separable_sd(x, np.full(4, 0.01), np.array([0, 0, 1, 1]), 2).round(5).tolist()
    [0.01414, 70.71068]
    """
    out = np.full(nb, np.inf)
    for b in range(nb):
        on = band == b
        w = 1.0 / sigma[on] ** 2
        if w.size < 2:
            continue
        xbar = float((w * airmass[on]).sum() / w.sum())
        s = float((w * (airmass[on] - xbar) ** 2).sum())
        if s > 0:
            out[b] = 1.0 / np.sqrt(s)
    return out


def extinction_prior(
    prior: Mapping[str, Any] | None, labels: Sequence[str]
) -> tuple[np.ndarray, np.ndarray, str]:
    """Prior value and width [mag per air mass] of each band's extinction coefficient, and
    where they come from.

    ``None``: the model atmosphere's coefficients at sea level
    (:func:`sbrdf_xr.photometry.extinction_coefficients`) with width
    :data:`EXTINCTION_PRIOR_WIDTH`; else a mapping ``{band: (k, width)}`` (Quantities
    converted), every width > 0.

    Examples
    --------
    >>> from sbrdf_xr.invert._joint.extinction import extinction_prior
    >>> k, sd, how = extinction_prior({"V": (0.2, 0.05)}, ["V"])
    >>> k.tolist(), sd.tolist(), how
    ([0.2], [0.05], 'given')
    """
    if prior is None:
        from ...photometry import extinction_coefficients

        k = np.asarray(extinction_coefficients(list(labels)).values, dtype=np.float64)
        how = (
            "the model atmosphere at sea level (photometry.extinction_coefficients), "
            f"+- {EXTINCTION_PRIOR_WIDTH} mag per air mass"
        )
        return k, np.full(len(labels), EXTINCTION_PRIOR_WIDTH), how
    if not isinstance(prior, Mapping):
        raise InversionError(
            f"extinction_prior: got {type(prior).__name__}; allowed None or a mapping "
            "{band: (k, width)} [mag per air mass]"
        )
    missing = [b for b in labels if b not in prior]
    if missing:
        raise InversionError(
            f"extinction_prior: no (k, width) for bands {missing}; give one per band {list(labels)}"
        )
    k, sd = np.zeros(len(labels)), np.zeros(len(labels))
    for i, b in enumerate(labels):
        try:
            kv, sv = prior[b]
        except (TypeError, ValueError):
            raise InversionError(
                f"extinction_prior[{b!r}]: {prior[b]!r}; allowed a pair (k, width) [mag per "
                "air mass]"
            ) from None
        k[i] = float(np.asarray(to_unit(kv, "mag", "extinction_prior k")))
        sd[i] = float(np.asarray(to_unit(sv, "mag", "extinction_prior width")))
        if not (np.isfinite(k[i]) and np.isfinite(sd[i]) and sd[i] > 0):
            raise InversionError(
                f"extinction_prior[{b!r}]: k {float(k[i])!r}, width {float(sd[i])!r}; allowed "
                "finite values with a width > 0 [mag per air mass] (a prior of zero width is "
                "a given coefficient: pass extinction={band: k})"
            )
    return k, sd, "given"
