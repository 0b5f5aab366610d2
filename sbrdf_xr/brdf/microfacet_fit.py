"""Least-squares fit of the microfacet model (:mod:`sbrdf_xr.brdf.microfacet`) to samples.

The model is Walter et al. 2007 Eq. 20 (GGX distribution, Smith height-correlated
masking-shadowing, exact Fresnel) plus a Lambertian term.  Fitted: the GGX roughness
``alpha`` (shared by all wavelengths), the substrate's refractive index ``n`` and the
Lambertian albedo ``rho_d`` per wavelength; the extinction coefficient is held at
``k = 0`` (a dielectric Fresnel curve, whose normal-incidence reflectance
``((n - 1) / (n + 1))**2`` spans 0 to 1 as ``n`` grows: ``n`` then stands for the
specular amplitude, and ``k`` could not be told from it by reflectance data alone).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import least_squares

from ..errors import ValidationError
from . import microfacet

__all__ = ["fit_microfacet"]

#: Roughness starts of the fit (the lobe's width spans decades).
_ALPHA_STARTS = (0.003, 0.01, 0.03, 0.1, 0.3)
#: Refractive-index bounds [1]: ``R(0)`` from 1e-8 to 0.99.
_N_BOUNDS = (1.0002, 400.0)


def fit_microfacet(
    theta_i: ArrayLike,
    delta_theta: ArrayLike,
    phi: ArrayLike,
    wavelength: ArrayLike,
    sbrdf: ArrayLike,
    *,
    reference: ArrayLike | None = None,
) -> dict[str, Any]:
    """Fit ``roughness``, ``n`` and ``rho_d`` of the microfacet model to sBRDF samples.

    Minimises ``sum (ln f_model - ln f_meas)**2`` over the usable samples (log residuals:
    every sample weighs by its relative error, so a mirror peak orders of magnitude
    above the diffuse floor does not swamp it, as in
    :func:`sbrdf_xr.brdf.robertson_sandford_fit.fit_robertson_sandford`) with a bounded
    trust-region fit (:func:`scipy.optimize.least_squares`) from each roughness of a
    coarse set of starts, keeping the best; ``ln alpha``, ``ln (n - 1)`` and
    ``ln rho_d`` are the free variables.

    Parameters
    ----------
    theta_i, delta_theta, phi : array_like, shape (n_samples,)
        Paper-000 angles of the samples [degree].
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    sbrdf : array_like, shape (n_samples, n_wl)
        Measured sBRDF [sr-1].
    reference : array_like of bool, shape (n_samples,), optional
        Reference points (no usable value): left out, as are non-positive or
        non-finite values and geometries with the observer at or below the horizon.

    Returns
    -------
    dict
        ``roughness`` (float), ``n``, ``k`` (zeros) and ``rho_d`` (ndarray (n_wl,)),
        ``rms_log`` (the root-mean-square log residual [1]), ``n_used`` and ``success``.

    Raises
    ------
    ValidationError
        Inconsistent shapes or fewer usable samples than parameters.

    Examples
    --------
    Noiseless samples of the model give back its parameters:

    >>> import numpy as np
    >>> from sbrdf_xr.brdf import microfacet
    >>> from sbrdf_xr.brdf.microfacet_fit import fit_microfacet
    >>> ti, dt, ph = (a.ravel() for a in np.meshgrid(
    ...     [20.0, 40.0, 60.0], [-40.0, -10.0, -2.0, 0.0, 3.0, 10.0], [0.0, 5.0], indexing="ij"))
    >>> truth = dict(roughness=0.05, n=3.0, k=0.0, rho_d=0.1)
    >>> samples = microfacet.brdf_angles(ti, dt, ph, [550.0], **truth)
    >>> fit = fit_microfacet(ti, dt, ph, [550.0], samples)
    >>> round(fit["roughness"], 6), round(float(fit["n"][0]), 6), round(float(fit["rho_d"][0]), 6)
    (0.05, 3.0, 0.1)
    """
    ti, dt, ph = (np.asarray(a, dtype=np.float64).ravel() for a in (theta_i, delta_theta, phi))
    wl = np.asarray(wavelength, dtype=np.float64).ravel()
    f = np.asarray(sbrdf, dtype=np.float64).reshape(ti.size, wl.size)
    if not ti.size == dt.size == ph.size:
        raise ValidationError(
            f"fit_microfacet: angle arrays of sizes {ti.size}, {dt.size}, {ph.size}; "
            "allowed: equal sizes"
        )
    ref = np.zeros(ti.size, bool) if reference is None else np.asarray(reference, bool).ravel()
    seen = np.cos(np.radians(ph)) * np.cos(np.radians(ti + dt)) > 1e-9
    use = ~ref & seen & np.all(np.isfinite(f) & (f > 0), axis=1)
    n_par = 1 + 2 * wl.size
    if use.sum() * wl.size < n_par + 1:
        raise ValidationError(
            f"fit_microfacet: {int(use.sum())} usable samples at {wl.size} wavelengths; "
            f"allowed: more residuals than the {n_par} parameters"
        )
    ti, dt, ph, log_f = ti[use], dt[use], ph[use], np.log(f[use])

    def unpack(x: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
        return float(np.exp(x[0])), 1.0 + np.exp(x[1 : 1 + wl.size]), np.exp(x[1 + wl.size :])

    def resid(x: np.ndarray) -> np.ndarray:
        alpha, n, rho = unpack(x)
        model = microfacet.brdf_angles(ti, dt, ph, wl, roughness=alpha, n=n, k=0.0, rho_d=rho)
        return (np.log(np.maximum(model, 1e-300)) - log_f).ravel()

    floor = np.exp(np.percentile(log_f, 10, axis=0)) * np.pi  # the diffuse level's albedo
    lo = np.concatenate([[np.log(1e-4)], np.full(wl.size, np.log(_N_BOUNDS[0] - 1))])
    hi = np.concatenate([[np.log(2.0)], np.full(wl.size, np.log(_N_BOUNDS[1] - 1))])
    lo = np.concatenate([lo, np.full(wl.size, np.log(1e-8))])
    hi = np.concatenate([hi, np.zeros(wl.size)])
    best = None
    for a0 in _ALPHA_STARTS:
        x0 = np.concatenate([[np.log(a0)], np.full(wl.size, np.log(0.5)),
                             np.log(np.clip(floor, 1e-7, 0.99))])  # fmt: skip
        sol = least_squares(resid, x0, bounds=(lo, hi), x_scale=1.0, method="trf")
        if best is None or sol.cost < best.cost:
            best = sol
    assert best is not None
    alpha, n, rho = unpack(best.x)
    return {
        "roughness": alpha,
        "n": n,
        "k": np.zeros(wl.size),
        "rho_d": rho,
        "rms_log": float(np.sqrt(np.mean(best.fun**2))),
        "n_used": int(best.fun.size),
        "success": bool(best.success),
    }
