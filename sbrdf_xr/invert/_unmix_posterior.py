"""The posterior of an unmixing: the material scales sampled inside physics.

See :func:`sbrdf_xr.invert.unmix` (``method="posterior"``).  The signal is linear in the
scales ``a`` of the chosen model's materials, so with Gaussian errors the likelihood is
``exp(-chi2(a) / 2)``, ``chi2 = || W^1/2 (y - A a) ||^2``.  The prior is flat inside
physics: every scale ``>= 0`` and, when the nominal areas are known, no material's area
above the body's (``a_m A_m <= sum A``); with ``total_area`` the scales lie on the plane
``sum a_m A_m = total`` and are sampled in its coordinates (an orthonormal basis of the
constraint's null space).  A material never lit and seen has a flat likelihood, so its
posterior is its prior (uniform on ``[0, sum A / A_m]``), or, with the constraint and
no other such material, the total less the others' areas.  Without nominal areas such a
material's prior is improper: it is held out of the sampling and reported not
constrained (NaN, infinite sd).

The sampler is that of :func:`sbrdf_xr.invert.fit_observation`'s posterior
(:func:`sbrdf_xr.invert._joint.posterior.run_chain`: emcee, Student-t independence
proposals from the least-squares covariance mixed with differential evolution; Foreman-
Mackey et al. 2013, PASP 125, 306), the chain grown until it spans 50 autocorrelation
times unless ``steps`` is given; a shorter chain raises a
:class:`~sbrdf_xr.errors.ChainLengthWarning`.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr

from ._areas import nominal_areas
from ._joint.posterior import (
    CHUNK_STEPS,
    MAX_EVALUATIONS,
    check_budget,
    default_walkers,
    run_chain,
    warn_short,
)
from ._library import MATERIAL
from ._unseen import unseen_columns

__all__ = ["unmix_posterior"]


def _null_basis(c: np.ndarray) -> np.ndarray:
    """Orthonormal basis (k, k - 1) of the plane ``c . d = 0``."""
    q = np.linalg.svd(c[None, :])[2]
    return np.asarray(q[1:].T)


def unmix_posterior(
    ds: xr.Dataset,
    *,
    aw: np.ndarray,
    yw: np.ndarray,
    x: np.ndarray,
    cov: np.ndarray,
    cols: list[int],
    areas: Mapping[str, float] | None,
    con: tuple[np.ndarray, float] | None,
    point_seconds: float,
    walkers: int | None,
    steps: int | None,
    seed: int,
) -> xr.Dataset:
    """``ds`` (an :func:`unmix` result) with the posterior of its chosen model's scales
    (and area fractions): ``posterior_median``, ``posterior_sd``, ``posterior_low``,
    ``posterior_high`` (2.5 and 97.5 %) over ``material`` and, with ``areas``, the same
    of the area fraction (``posterior_fraction_*``).

    ``aw``, ``yw``: the weighted design and data; ``x`` the least-squares scales, ``cov``
    (k, k) and ``cols`` the chosen model's covariance and columns; ``con`` the area
    constraint ``(c, total)``.

    Examples
    --------
    Two materials seen at four values with unit errors, the truth (1, 2):

    >>> import numpy as np, xarray as xr
    >>> from sbrdf_xr.invert._unmix_posterior import unmix_posterior
    >>> a = np.array([[1.0, 0.2], [0.5, 1.0], [0.3, 0.7], [1.0, 1.0]])
    >>> y = a @ [1.0, 2.0] + np.random.default_rng(0).normal(0, 0.05, 4)
    >>> cov = np.linalg.inv(a.T @ a / 0.05**2)
    >>> ds = xr.Dataset(coords={"material": ["m1", "m2"]})
    >>> x = cov @ (a.T @ y / 0.05**2)
    >>> out = unmix_posterior(ds, aw=a / 0.05, yw=y / 0.05, x=x, cov=cov, cols=[0, 1],
    ...                       areas=None, con=None, point_seconds=1e-3, walkers=None,
    ...                       steps=None, seed=0)
    >>> bool(np.all(np.abs(out.posterior_median.values - [1, 2]) < 3 * out.posterior_sd.values))
    True
    """
    k = aw.shape[1]
    names = [str(m) for m in ds[MATERIAL].values]
    nominal = None if areas is None else nominal_areas(areas, names)
    body = None if nominal is None else float(nominal.sum())
    top = np.full(k, np.inf) if nominal is None else body / np.where(nominal > 0, nominal, np.inf)
    seen = ~unseen_columns(aw)
    # a material never seen is sampled whether the selection kept it or not: the data
    # cannot show it absent, so its prior stands
    sampled = sorted(set(cols) | set(np.flatnonzero(~seen).tolist()))
    improper = [j for j in sampled if not seen[j] and not np.isfinite(top[j])]
    use = [j for j in sampled if j not in improper]
    centre = np.nan_to_num(np.asarray(x, dtype=np.float64)[use])
    cv = cov[np.ix_(use, use)].copy()
    for i, j in enumerate(use):  # never seen: the proposal spans its prior
        if not seen[j]:
            centre[i] = 0.5 * top[j] if con is None else centre[i]
            cv[i, i] = max(cv[i, i], top[j] ** 2 / 12.0)
    lo, hi = np.zeros(len(use)), top[use]
    if con is not None:
        basis = _null_basis(con[0][use])
        to_a = _constrained_map(centre, basis)
        x0, cz = np.zeros(basis.shape[1]), basis.T @ cv @ basis
    else:
        to_a, x0, cz = (lambda z: z), centre, cv
    g = aw[:, use]

    def log_prob(z: np.ndarray) -> float:
        a = to_a(z)
        if np.any(a < lo) or np.any(a > hi):
            return -np.inf
        r = yw - g @ a
        return float(-0.5 * r @ r)

    x0 = _inside(x0, log_prob, to_a, lo, hi, con, nominal, use)
    n = x0.size
    walkers = max(default_walkers(n), 8) if walkers is None else walkers
    check_budget(walkers, CHUNK_STEPS if steps is None else steps, 1, 1e-5)
    t0 = time.perf_counter()
    chain, tau, acc = run_chain(
        x0, cz, log_prob, walkers, steps, MAX_EVALUATIONS // walkers, np.random.default_rng(seed)
    )
    warn_short([tau], ["unmix"], chain.shape[0], walkers)
    burn = min(chain.shape[0] // 2, max(int(np.ceil(5 * tau)), 1))
    flat = np.array([to_a(z) for z in chain[burn:].reshape(-1, n)])
    full = np.zeros((flat.shape[0], k))
    full[:, use] = flat
    full[:, improper] = np.nan
    seconds = time.perf_counter() - t0
    out = ds.copy()
    _add(out, "", full, "scale factor")
    if nominal is not None:
        summed = full @ nominal if con is None else np.full(full.shape[0], con[1])
        _add(out, "fraction_", full * nominal / summed[:, None], "area fraction")
    out.attrs.update(
        {
            "posterior": f"emcee ensemble of {walkers} walkers (Laplace-approximation "
            f"independence proposals and differential evolution), {chain.shape[0]} steps, "
            f"burn-in {burn}, autocorrelation time {tau:.3g} steps, acceptance {acc:.3g}, "
            f"{walkers * (chain.shape[0] - burn) / max(tau, 1.0):.0f} effective samples, "
            f"seed {seed}; prior flat with scales >= 0"
            + ("" if nominal is None else " and no area above the body's")
            + ("" if con is None else ", on the plane of total_area"),
            "posterior_unconstrained": ", ".join(names[j] for j in improper)
            if improper
            else "none",
            "posterior_seconds": seconds,
            "posterior_cost": f"{seconds / max(point_seconds, 1e-9):.3g} times the point "
            "fit's wall time",
        }
    )
    return out


def _constrained_map(centre: np.ndarray, basis: np.ndarray) -> Any:
    def to_a(z: np.ndarray) -> np.ndarray:
        return np.asarray(centre + basis @ z)

    return to_a


def _inside(
    x0: np.ndarray,
    log_prob: Any,
    to_a: Any,
    lo: np.ndarray,
    hi: np.ndarray,
    con: tuple[np.ndarray, float] | None,
    nominal: np.ndarray | None,
    use: list[int],
) -> np.ndarray:
    """A start inside the prior's support: the estimate, else moved inside the bounds
    (on the constraint's plane: towards the point of equal scales)."""
    if np.isfinite(log_prob(x0)):
        return x0
    if con is None:
        return np.asarray(np.clip(x0, lo + 1e-12, np.minimum(hi, 1e300)))
    c = con[0][use]
    even = np.full(len(use), con[1] / c.sum())  # every scale alike, on the plane
    a0 = to_a(x0)
    for t in np.linspace(0.0, 1.0, 21)[1:]:
        z = x0 + np.linalg.lstsq(_basis_of(to_a, x0.size), (1 - t) * a0 + t * even - a0)[0]
        if np.isfinite(log_prob(z)):
            return np.asarray(z)
    return np.asarray(x0 + np.linalg.lstsq(_basis_of(to_a, x0.size), even - a0)[0])


def _basis_of(to_a: Any, n: int) -> np.ndarray:
    base = to_a(np.zeros(n))
    return np.stack([to_a(np.eye(n)[i]) - base for i in range(n)], axis=1)


def _add(ds: xr.Dataset, prefix: str, x: np.ndarray, what: str) -> None:
    """Median, sd and 2.5 / 97.5 % points of the samples ``x`` (S, k) over material."""
    with np.errstate(invalid="ignore"):
        stats = {
            "median": (np.median(x, 0), "posterior median"),
            "sd": (np.where(np.isnan(x).any(0), np.inf, np.std(x, 0)), "posterior sd"),
            "low": (np.percentile(x, 2.5, axis=0), "posterior 2.5 % point"),
            "high": (np.percentile(x, 97.5, axis=0), "posterior 97.5 % point"),
        }
    for key, (v, ln) in stats.items():
        ds[f"posterior_{prefix}{key}"] = (
            MATERIAL,
            v,
            {"units": "1", "long_name": f"{ln} of the {what} (infinite sd: not constrained)"},
        )
