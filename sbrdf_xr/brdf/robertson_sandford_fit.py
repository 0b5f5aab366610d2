"""Least-squares fit of the Robertson-Sandford model (paper 001) to measured sBRDF samples.

The model itself (:mod:`sbrdf_xr.brdf.robertson_sandford`) stays apart from its fit;
:func:`sbrdf_xr.materials.models.fit_robertson_sandford` wraps this numpy fit for measurement sets.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy import optimize, sparse

from .. import geometry
from ..errors import ValidationError
from ._common import (
    _check_wavelength,
    _sin2,
)
from .robertson_sandford import _COS_FLOOR, _cutoff_over_cos, _e2_h_norm, _g_cs, normalisation_G


class _FitGeometry:
    """Per-sample geometric factors of the R-S model for a fixed set of angles."""

    def __init__(self, theta_i: np.ndarray, delta_theta: np.ndarray, phi: np.ndarray) -> None:
        n, s, o = geometry.facet_vectors(theta_i, delta_theta, phi)
        self.cos_i = np.einsum("...k,...k->...", n, s)
        self.cos_r = np.einsum("...k,...k->...", n, o)
        self.sin2_i = _sin2(n, s)
        self.sin2_r = _sin2(n, o)
        glint = geometry.half_vector(s, o)
        self.cos2_a = np.einsum("...k,...k->...", glint, n) ** 2
        self.sin2_a = _sin2(n, glint)
        self.valid = (self.cos_i > 0) & (self.cos_r > 0)

    def components(self, b: float, e: float, cutoff: bool) -> tuple[np.ndarray, ...]:
        """``(A, B, gi/G)`` with ``f = rho_D A + max(1 - (rho_D + eps) gi/G, 0) B``."""
        g_norm = float(normalisation_G(b))
        ci = np.clip(self.cos_i, 0.0, 1.0)
        cr = np.clip(self.cos_r, 0.0, 1.0)
        gi = _g_cs(ci**2, self.sin2_i, b) / g_norm
        gr = _g_cs(cr**2, self.sin2_r, b) / g_norm
        a_d = gi * gr / np.pi
        e2 = e * e
        h_over_h = e2 / ((e2 * self.cos2_a + self.sin2_a) ** 2 * _e2_h_norm(ci, np.float64(e)))
        geom = _cutoff_over_cos(cr, self.sin2_r, b) if cutoff else 1.0 / np.maximum(cr, _COS_FLOOR)
        b_s = h_over_h * geom / (4.0 * np.pi)
        return a_d, b_s, gi


def fit_robertson_sandford(
    theta_i: ArrayLike,
    delta_theta: ArrayLike,
    phi: ArrayLike,
    wavelength: ArrayLike,
    sbrdf: ArrayLike,
    *,
    reference: ArrayLike | None = None,
    sigma: ArrayLike | None = None,
    cutoff: bool = True,
) -> dict[str, Any]:
    """Least-squares fit of the R-S parameters to measured sBRDF samples.

    Fits ``rho_D(lambda)`` and ``epsilon(lambda)`` per wavelength and a shared ``b``
    and ``e`` by minimising ``sum ((ln f_model - ln f_meas) / sigma)^2`` over the
    usable samples: log residuals weight every sample by its relative error, so the
    glint peak (orders of magnitude brighter) does not swamp the diffuse background.
    ``e`` is fitted as ``ln e`` (its plausible range spans decades).  A coarse grid
    over ``(b, e)``, with the (then linear) relative-weighted least squares for
    ``rho_D, epsilon`` at each node, supplies the start; a bounded trust-region fit
    (:func:`scipy.optimize.least_squares`) follows.  Standard uncertainties come
    from the Jacobian at the solution, ``cov = (J^T J)^-1`` scaled by the reduced
    chi-square when ``sigma`` is not given.

    Parameters
    ----------
    theta_i, delta_theta, phi : array_like, shape (n_samples,)
        Paper-000 angles of the measured geometries [degree].
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    sbrdf : array_like, shape (n_samples, n_wl)
        Measured sBRDF [sr-1].
    reference : array_like of bool, shape (n_samples,) or (n_samples, n_wl), optional
        Reference points (paper 000: reflectance indistinguishable from noise).
        They carry no usable value, so they are excluded, as are non-positive,
        non-finite or geometrically impossible (unlit/unseen) samples.
    sigma : array_like, optional
        Relative standard uncertainty of each measurement [1] (scalar or
        broadcastable to ``(n_samples, n_wl)``), i.e. the standard deviation of
        ``ln f_meas``.  If omitted, unit weights are used and the covariance is
        scaled by the reduced chi-square.
    cutoff : bool, default True
        Use the grazing cut-off of Eq. 21 in the model.

    Returns
    -------
    dict
        ``rho_D``, ``epsilon`` (ndarray (n_wl,)), ``b``, ``e`` (float), their standard
        uncertainties ``u_rho_D``, ``u_epsilon``, ``u_b``, ``u_e``, the ``covariance``
        of ``(rho_D..., epsilon..., b, ln e)``, ``chi2_reduced``, ``n_used`` (number of
        residuals), ``success`` and ``message``.

    Raises
    ------
    ValidationError
        Inconsistent shapes, or fewer than 4 usable geometries (four parameters)
        or fewer than 2 usable samples at some wavelength.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.brdf import robertson_sandford as rs
    >>> ti, dt, ph = (a.ravel() for a in np.meshgrid(
    ...     [20.0, 40.0, 60.0], [-40.0, -20.0, 0.0, 10.0], [0.0, 20.0], indexing="ij"))
    >>> truth = {"rho_D": 0.6, "epsilon": 0.2, "b": 0.1, "e": 0.3}
    >>> samples = rs.brdf_angles(ti, dt, ph, [550.0], **truth)
    >>> fit = fit_robertson_sandford(ti, dt, ph, [550.0], samples)
    >>> {k: np.round(fit[k], 6).tolist() for k in truth}  # noiseless samples: the truth
    {'rho_D': [0.6], 'epsilon': [0.2], 'b': 0.1, 'e': 0.3}
    """
    wl = _check_wavelength(wavelength)
    ang, y, ref, sig = _checked_samples(theta_i, delta_theta, phi, wl.size, sbrdf, reference, sigma)
    geo = _FitGeometry(*ang)
    use = (~ref) & np.isfinite(y) & (y > 0) & geo.valid[:, None]
    n_geom = int(np.sum(np.any(use, axis=1)))
    per_wl = np.sum(use, axis=0)
    if n_geom < 4 or np.any(per_wl < 2):
        raise ValidationError(
            f"sbrdf: {n_geom} usable (non-reference, positive, lit and visible) geometries "
            f"and at least {int(per_wl.min())} per wavelength; need >= 4 geometries to "
            "constrain (rho_D, epsilon, b, e) and >= 2 per wavelength"
        )
    prob = _Problem(geo, cutoff, y, sig, use)
    sol = prob.solve(*prob.start())
    n_wl = wl.size
    chi2 = float(np.sum(sol.fun**2))
    dof = max(prob.n_res - (2 * n_wl + 2), 1)
    chi2_red = chi2 / dof
    jm = sol.jac
    cov = np.linalg.pinv(np.asarray((jm.T @ jm).todense()) if sparse.issparse(jm) else jm.T @ jm)
    if sigma is None:
        cov = cov * chi2_red
    u = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    rho, eps, b, e = prob.unpack(sol.x)
    return {
        "rho_D": rho.copy(),
        "epsilon": eps.copy(),
        "b": b,
        "e": e,
        "u_rho_D": u[:n_wl],
        "u_epsilon": u[n_wl : 2 * n_wl],
        "u_b": float(u[-2]),
        "u_e": float(e * u[-1]),
        "covariance": cov,
        "chi2_reduced": chi2_red,
        "n_used": prob.n_res,
        "success": bool(sol.success),
        "message": str(sol.message),
    }


def _checked_samples(
    theta_i: ArrayLike,
    delta_theta: ArrayLike,
    phi: ArrayLike,
    n_wl: int,
    sbrdf: ArrayLike,
    reference: ArrayLike | None,
    sigma: ArrayLike | None,
) -> tuple[list[np.ndarray], np.ndarray, np.ndarray, np.ndarray]:
    """The angles [degree], the sBRDF, the reference mask and the relative uncertainties
    of the samples, checked against one another's shapes."""
    ang = [np.asarray(a, dtype=np.float64) for a in (theta_i, delta_theta, phi)]
    names = ("theta_i", "delta_theta", "phi")
    for name, a in zip(names, ang, strict=True):
        if a.ndim != 1:
            raise ValidationError(f"{name}: expected a 1-D array over samples, got shape {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ValidationError(f"{name}: contains NaN or infinite angles [degree]")
    n_s = ang[0].size
    if ang[1].size != n_s or ang[2].size != n_s:
        raise ValidationError(
            f"theta_i, delta_theta, phi: lengths {[a.size for a in ang]} differ; "
            "expected one value per sample"
        )
    y = np.asarray(sbrdf, dtype=np.float64)
    if y.shape != (n_s, n_wl):
        raise ValidationError(
            f"sbrdf: expected shape (n_samples, n_wl) = {(n_s, n_wl)}, got {y.shape}"
        )
    ref = np.zeros((n_s, n_wl), dtype=bool)
    if reference is not None:
        r = np.asarray(reference, dtype=bool)
        if r.shape == (n_s,):
            r = r[:, None]
        try:
            ref = np.broadcast_to(r, (n_s, n_wl))
        except ValueError as exc:
            raise ValidationError(
                f"reference: expected shape ({n_s},) or ({n_s}, {n_wl}), got {r.shape}"
            ) from exc
    if sigma is None:
        return ang, y, ref, np.ones((n_s, n_wl))
    try:
        sig = np.broadcast_to(np.asarray(sigma, dtype=np.float64), (n_s, n_wl))
    except ValueError as exc:
        raise ValidationError(
            f"sigma: not broadcastable to {(n_s, n_wl)}, got shape {np.shape(sigma)}"
        ) from exc
    if not np.all(np.isfinite(sig)) or np.any(sig <= 0):
        raise ValidationError("sigma: relative uncertainties must be finite and > 0 [1]")
    return ang, y, ref, sig


class _Problem:
    """The least-squares problem in log sBRDF: parameters ``(rho_D[l], epsilon[l], b, ln e)``."""

    def __init__(
        self, geo: _FitGeometry, cutoff: bool, y: np.ndarray, sig: np.ndarray, use: np.ndarray
    ) -> None:
        self.geo, self.cutoff, self.y, self.sig, self.use = geo, cutoff, y, sig, use
        self.n_wl = y.shape[1]
        self.ly = np.log(np.where(use, y, 1.0))
        s_idx, l_idx = np.nonzero(use)  # residual order of resid() (row-major over samples)
        self.n_res = n_res = s_idx.size
        n_wl = self.n_wl
        self.rows = np.repeat(np.arange(n_res), 4)
        self.cols = np.stack(
            [l_idx, n_wl + l_idx, np.full(n_res, 2 * n_wl), np.full(n_res, 2 * n_wl + 1)], 1
        ).ravel()

    def model(self, rho: np.ndarray, eps: np.ndarray, b: float, e: float) -> tuple[np.ndarray, ...]:
        """The model sBRDF [sr-1] and its diffuse, specular and normalisation terms."""
        a_d, b_s, gi = self.geo.components(b, e, self.cutoff)
        rho_s = 1.0 - (rho + eps)[None, :] * gi[:, None]
        pos = rho_s > 0
        f = rho[None, :] * a_d[:, None] + np.where(pos, rho_s, 0.0) * b_s[:, None]
        return np.maximum(f, np.finfo(np.float64).tiny), a_d, b_s, gi, pos

    def start(self) -> tuple[np.ndarray, np.ndarray, float, float]:
        """Start: a grid over (b, e), linear relative-weighted LS for (rho_D, epsilon)."""
        y, sig, use, ly = self.y, self.sig, self.use, self.ly
        b_grid = np.array([0.0, 0.03, 0.08, 0.15, 0.3, 0.6, 1.0])
        e_grid = np.geomspace(1e-3, 1.0, 19)
        w = np.where(use, 1.0 / (np.where(use, y, 1.0) * sig), 0.0)
        best: tuple[float, np.ndarray, np.ndarray, float, float] | None = None
        for b0 in b_grid:  # a handful of start nodes, vectorised over samples and wavelengths
            for e0 in e_grid:
                a_d, b_s, gi = self.geo.components(b0, e0, self.cutoff)
                pcol = (a_d - gi * b_s)[:, None] * w
                qcol = (-gi * b_s)[:, None] * w
                rhs = (y - b_s[:, None]) * w
                a11, a12, a22 = (pcol**2).sum(0), (pcol * qcol).sum(0), (qcol**2).sum(0)
                r1, r2 = (pcol * rhs).sum(0), (qcol * rhs).sum(0)
                det = a11 * a22 - a12**2
                ok = np.abs(det) > 1e-300
                dsafe = np.where(ok, det, 1.0)
                rho0 = np.where(ok, (a22 * r1 - a12 * r2) / dsafe, 0.05)
                eps0 = np.where(ok, (a11 * r2 - a12 * r1) / dsafe, 0.5)
                rho0 = np.clip(rho0, 1e-4, 1.0)
                eps0 = np.clip(eps0, 1e-4, 1.0)
                g_b = float(normalisation_G(b0))
                scale = np.minimum(1.0, 0.999 * g_b / (rho0 + eps0))
                rho0, eps0 = rho0 * scale, eps0 * scale
                f0 = self.model(rho0, eps0, b0, e0)[0]
                cost = float(np.sum(np.where(use, ((np.log(f0) - ly) / sig) ** 2, 0.0)))
                if best is None or cost < best[0]:
                    best = (cost, rho0, eps0, b0, e0)
        assert best is not None
        return best[1], best[2], best[3], best[4]

    def unpack(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, float]:
        n_wl = self.n_wl
        return x[:n_wl], x[n_wl : 2 * n_wl], float(x[-2]), float(np.exp(x[-1]))

    def resid(self, x: np.ndarray) -> np.ndarray:
        f = self.model(*self.unpack(x))[0]
        return ((np.log(f) - self.ly) / self.sig)[self.use]

    def jac(self, x: np.ndarray) -> sparse.csr_matrix:
        """Sparse Jacobian: a residual at wavelength l depends on rho_D[l], epsilon[l], b, ln e."""
        n_wl, use, sig = self.n_wl, self.use, self.sig
        f, a_d, b_s, gi, pos = self.model(*self.unpack(x))
        spec = np.where(pos, gi[:, None] * b_s[:, None], 0.0)
        d_rho = (a_d[:, None] - spec) / f
        d_eps = -spec / f
        shared = []
        for k, step in ((2 * n_wl, 1e-6 * max(abs(x[-2]), 1e-3)), (2 * n_wl + 1, 1e-6)):
            xp, xm = x.copy(), x.copy()
            xp[k] += step
            xm[k] -= step
            fp = self.model(*self.unpack(xp))[0]
            fm = self.model(*self.unpack(xm))[0]
            shared.append((np.log(fp) - np.log(fm)) / (2 * step))
        vals = (
            np.stack([d_rho[use], d_eps[use], shared[0][use], shared[1][use]], 1)
            / sig[use][:, None]
        )
        return sparse.csr_matrix(
            (vals.ravel(), (self.rows, self.cols)), shape=(self.n_res, 2 * n_wl + 2)
        )

    def solve(self, rho0: np.ndarray, eps0: np.ndarray, b0: float, e0: float) -> Any:
        """Trust-region reflective least squares within the parameters' bounds."""
        n_wl = self.n_wl
        lower = np.concatenate([np.zeros(2 * n_wl), [0.0, np.log(1e-6)]])
        upper = np.concatenate([np.ones(2 * n_wl), [10.0, np.log(10.0)]])
        x0 = np.concatenate([rho0, eps0, [max(b0, 1e-3), np.log(e0)]])
        x0 = np.clip(x0, lower + 1e-9, upper - 1e-9)
        return optimize.least_squares(
            self.resid,
            x0,
            jac=self.jac,
            bounds=(lower, upper),
            method="trf",
            x_scale="jac",
            tr_solver="lsmr",
            xtol=1e-12,
            ftol=1e-12,
            gtol=1e-12,
            max_nfev=500,
        )
