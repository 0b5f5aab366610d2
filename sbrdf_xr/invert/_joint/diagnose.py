"""Which misfit the residuals of a joint fit show: the likely causes, ranked from the data.

A chi-square beyond its distribution says the model is wrong, not how.  The normalised
residuals ``r_i`` are regressed (weighted linear least squares, Press et al., *Numerical
Recipes*, 3rd ed., §15.4) on the patterns that each cause leaves, and the causes are
ranked by the chi-square each pattern explains over its expectation for pure noise (a
pattern of ``k`` columns takes out ``k`` of a right model's chi-square on average, with a
spread ``sqrt(2 k)``):

* a material's table too bright or dark, its colour or the calibration wrong: a constant
  per band;
* the extinction not first order, or a slow change over the pass that the model lacks
  (the phase angle changes slowly: self-shadowing, a material's phase function): a
  straight line in the air mass per band;
* the shape or self-shadowing (the body's appearance over a turn differs from the
  model's): a Fourier series of the spin angle, orders 1-4 (and per band constants);
* a local minimum or an attitude that is not a uniform spin: the same series with
  coefficients changing linearly over the pass (a slipping phase, a wrong period, a
  tumble).

Each score is ``(delta chi2 - k) / sqrt(2 k)``: about 0 +- 1 for noise, large for the
pattern the misfit follows.  The patterns overlap (the per-band constants are in all
but the first), so each is scored on top of the per-band constants except the first.
"""

from __future__ import annotations

import numpy as np

__all__ = ["CAUSES", "likely_causes"]

#: The causes a joint fit's residuals are scored for, and what to do about each.
CAUSES = {
    "material": "a material's table is too bright or too dark, or its colour is off (the "
    "residuals keep a mean per band): give the tables' scales room (material_scale) or "
    "check the materials",
    "extinction": "a slow trend over the pass (the residuals follow the air mass): the "
    "extinction is not first order, or the brightness changes with the phase angle unlike "
    "the model's (self-shadowing, a material's phase function): simulate with shadowing, "
    "try offset='band'",
    "shape": "the shape or self-shadowing differs from the model's (the residuals repeat "
    "with the spin): check the mesh and simulate with shadowing",
    "spin": "the fit stopped in a local minimum or the attitude is not a uniform spin "
    "(the residuals repeat with the spin but drift over the pass): start from fit_spin "
    "over the light curve or from more (starts='aliases'), or model a tumble",
}


def _explained(r: np.ndarray, a: np.ndarray) -> float:
    """Chi-square of ``r`` taken out by a least-squares fit on the columns of ``a``."""
    if a.shape[1] == 0:
        return 0.0
    coef = np.linalg.lstsq(a, r, rcond=None)[0]
    fit = a @ coef
    return float(fit @ fit)


def likely_causes(
    residual: np.ndarray,
    band: np.ndarray,
    spin_angle: np.ndarray,
    airmass: np.ndarray,
    seconds: np.ndarray,
) -> list[tuple[str, float]]:
    """The causes of :data:`CAUSES` ranked by how strongly the normalised residuals follow
    each one's pattern, with their scores ``(delta chi2 - k) / sqrt(2 k)``.

    Parameters
    ----------
    residual : ndarray, shape (n,)
        Normalised residuals ``(measured - model) / sigma`` [1].
    band : ndarray of int, shape (n,)
        Band index of each value.
    spin_angle : ndarray, shape (n,)
        Spin angle of the solution at each value [degree].
    airmass : ndarray, shape (n,)
        Air mass at each value [1].
    seconds : ndarray, shape (n,)
        Time of each value [s].

    Returns
    -------
    list of (str, float)
        Keys of :data:`CAUSES` and scores, highest first.

    Examples
    --------
    Residuals that are 3 sigma brighter in one band than the model, and noise:

    >>> from sbrdf_xr.invert._joint.diagnose import likely_causes
    >>> rng = np.random.default_rng(0)
    >>> n = 200
    >>> band = np.arange(n) % 2
    >>> r = rng.normal(size=n) + 3.0 * (band == 1)
    >>> t = np.linspace(0.0, 300.0, n)
    >>> ranked = likely_causes(r, band, 360 * t / 40.0, 1.2 + t / 300, t)
    >>> ranked[0][0]
    'material'
    """
    r = np.asarray(residual, dtype=np.float64)
    b = np.asarray(band)
    x = np.asarray(airmass, dtype=np.float64)
    t = np.asarray(seconds, dtype=np.float64)
    span = max(float(np.ptp(t)), 1e-9)
    tn = (t - t.min()) / span - 0.5
    ang = np.radians(np.asarray(spin_angle, dtype=np.float64))
    const = np.column_stack([(b == j).astype(float) for j in np.unique(b)])
    xc = x - x.mean()
    ramp = const * xc[:, None]
    fourier = np.column_stack([f(k * ang) for k in range(1, 5) for f in (np.cos, np.sin)])
    drift = fourier * tn[:, None]
    base = _explained(r, const)
    patterns = {
        "material": (base, const.shape[1]),
        "extinction": (_explained(r, np.hstack([const, ramp])) - base, ramp.shape[1]),
        "shape": (_explained(r, np.hstack([const, fourier])) - base, fourier.shape[1]),
        "spin": (
            _explained(r, np.hstack([const, fourier, drift]))
            - _explained(r, np.hstack([const, fourier])),
            drift.shape[1],
        ),
    }
    scores = [(key, (d - k) / np.sqrt(2.0 * k)) for key, (d, k) in patterns.items()]
    return sorted(scores, key=lambda s: -s[1])
