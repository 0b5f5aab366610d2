"""The joint posterior of a pass's fit, sampled where a point estimate misleads.

See :func:`sbrdf_xr.invert.fit_observation` (``method="posterior"``).  The posterior of
the fitted parameters ``p`` is ``exp(-chi2(p) / 2)`` (Gaussian errors, the priors of the
tables' scales as data, flat priors elsewhere) inside the physical bounds (area
fractions in ``[0, 1]``, scales ``>= 0``, period ``> 0``).  It is sampled by the affine-
invariant ensemble sampler of Goodman & Weare (2010, Comm. App. Math. Comp. Sci. 5, 65)
as implemented by emcee (Foreman-Mackey et al. 2013, PASP 125, 306), from every minimum
the point fit found within :data:`MODE_CHI2` of the best (period aliases, other axes),
its walkers drawn from the Gaussian of its own covariance (the typical set).  The moves
are mostly an independence Metropolis-Hastings proposal from that Laplace approximation
(a multivariate Student-t of :data:`PROPOSAL_DOF` degrees of freedom, heavier-tailed than
the Gaussian so the ratio of target to proposal stays bounded; Robert & Casella 2004,
*Monte Carlo Statistical Methods*, §7.4, emcee's ``MHMove``), mixed with emcee's
differential-evolution move (ter Braak 2006, Stat. Comput. 16, 239) for what the
Gaussian misses: near a Gaussian posterior its autocorrelation time is a few steps, where
the stretch move's grows with the dimension (tens of steps for a dozen parameters).  Each
mode's probability is its Laplace evidence ``exp(-chi2_i / 2) sqrt(det 2 pi C_i)``
(MacKay 2003, *Information Theory, Inference and Learning Algorithms*, §27.1),
normalised; the summary (median, standard deviation, 2.5 and 97.5 % points) is over the
modes' samples weighted so.  The body's symmetry
twins are exact copies of a mode (the same probability) and are listed, not sampled.

Convergence is checked per mode with the integrated autocorrelation time ``tau`` of the
chain (in steps; Goodman & Weare 2010, §3; emcee's ``get_autocorr_time``, the estimator
of Sokal 1997 with its automatic window).  A chain shorter than :data:`MIN_TAUS` ``tau``
steps gives neither a reliable ``tau`` nor a reliable width (emcee's own criterion), and
is reported with a :class:`~sbrdf_xr.errors.ChainLengthWarning` naming the steps to ask
for; the per-mode ``tau`` and effective sample size are part of the result.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import xarray as xr

from ...errors import ChainLengthWarning, InversionError
from .._spin.search import lonlat
from .bounds import covariance

__all__ = [
    "CHUNK_STEPS",
    "DE_SHARE",
    "MAX_EVALUATIONS",
    "MIN_TAUS",
    "MODE_CHI2",
    "PROPOSAL_DOF",
    "chain_convergence",
    "default_walkers",
    "laplace_move",
    "run_chain",
    "sample_posterior",
    "warn_short",
]

#: Minima within this chi-square of the best are sampled as modes.
MODE_CHI2 = 25.0
#: Largest number of model evaluations (walkers x steps x modes) a posterior may take.
MAX_EVALUATIONS = 200_000
#: A chain is long enough when it spans at least this many autocorrelation times (emcee's
#: ``get_autocorr_time`` default ``tol``: shorter chains misjudge ``tau`` and the widths).
MIN_TAUS = 50
#: Degrees of freedom of the Student-t independence proposal (its covariance is
#: ``PROPOSAL_DOF / (PROPOSAL_DOF - 2)`` times the Laplace one: sd 1.29 times wider).
PROPOSAL_DOF = 5.0
#: Share of the moves that are differential evolution (the rest: the Laplace proposal).
DE_SHARE = 0.3
#: With ``steps=None`` the chain grows by this many steps until it spans :data:`MIN_TAUS`
#: autocorrelation times (or the budget is spent).
CHUNK_STEPS = 50


def default_walkers(n_parameters: int) -> int:
    """Walkers of the ensemble for ``n_parameters`` [1]: ``2 n + 2`` (emcee's moves need
    at least ``2 n``; more walkers only add samples per step).

    Examples
    --------
    >>> from sbrdf_xr.invert._joint.posterior import default_walkers
    >>> default_walkers(12)
    26
    """
    return 2 * int(n_parameters) + 2


def laplace_move(mean: np.ndarray, cov: np.ndarray, dof: float = PROPOSAL_DOF) -> Any:
    """emcee ``MHMove``: independence proposals from the multivariate Student-t of centre
    ``mean``, scale matrix ``cov`` and ``dof`` degrees of freedom (directions of zero
    variance held), with the Hastings ratio ``ln q(x) - ln q(x')`` of an independence
    sampler (Robert & Casella 2004, §7.4).

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.invert._joint.posterior import laplace_move
    >>> move = laplace_move(np.zeros(2), np.diag([1.0, 4.0]))
    >>> x, log_ratio = move.get_proposal(np.zeros((3, 2)), np.random.RandomState(0))
    >>> x.shape, bool(np.all(log_ratio >= 0))  # q peaks at the centre: ratios favour leaving
    ((3, 2), True)
    """
    import emcee

    ev, vec = np.linalg.eigh(np.asarray(cov, dtype=np.float64))
    keep = ev > 1e-14 * max(float(ev.max(initial=0.0)), 1e-300)
    root = vec[:, keep] * np.sqrt(ev[keep])
    whiten = vec[:, keep] / np.sqrt(ev[keep])
    d = int(keep.sum())

    def log_q(x: np.ndarray) -> np.ndarray:
        z = (x - mean) @ whiten
        return np.asarray(-0.5 * (dof + d) * np.log1p(np.sum(z * z, axis=-1) / dof))

    def propose(coords: np.ndarray, random: Any) -> tuple[np.ndarray, np.ndarray]:
        k = coords.shape[0]
        z = random.standard_normal((k, d)) * np.sqrt(dof / random.chisquare(dof, k))[:, None]
        x = mean + z @ root.T
        return x, log_q(coords) - log_q(x)

    return emcee.moves.MHMove(propose)


def chain_convergence(chain: np.ndarray, discard: int) -> tuple[float, float]:
    """Longest integrated autocorrelation time [steps] over the parameters of an emcee
    chain ``(steps, walkers, parameters)`` and the effective number of independent samples
    [1] after ``discard`` steps of burn-in (walkers x kept steps / tau).

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.invert._joint.posterior import chain_convergence
    >>> rng = np.random.default_rng(0)
    >>> tau, n_eff = chain_convergence(rng.standard_normal((400, 8, 2)), 0)
    >>> bool(0.5 < tau < 2.0), bool(1500 < n_eff < 6500)  # white noise: tau = 1
    (True, True)
    """
    import emcee

    tau = float(np.max(emcee.autocorr.integrated_time(chain, tol=0, quiet=True)))
    kept = chain.shape[0] - discard
    return tau, chain.shape[1] * kept / max(tau, 1.0)


def _outputs(
    lay: Any, axis_of: Callable[[np.ndarray], np.ndarray], p: np.ndarray, shift: float
) -> np.ndarray:
    """The reported parameters of ``p`` (longitude, latitude, period, phase at the epoch,
    the rest as fitted) and every material's area fraction."""
    lon, lat = (float(v) for v in lonlat(axis_of(p)))
    phase = p[3] - shift / p[2]
    return np.concatenate([[lon, lat, p[2], phase], p[4:], lay.fractions(p)])


def check_budget(walkers: int, steps: int, n_modes: int, seconds_per_call: float) -> None:
    """Refuse a sampler budget beyond :data:`MAX_EVALUATIONS`, with its estimated time.

    Examples
    --------
    >>> from sbrdf_xr.invert._joint.posterior import check_budget
    >>> check_budget(32, 300, 2, 0.002)  # 19200 evaluations: allowed
    """
    if not (isinstance(walkers, int) and isinstance(steps, int) and walkers > 0 and steps > 0):
        raise InversionError(
            f"posterior: walkers {walkers!r}, steps {steps!r}; allowed positive integers"
        )
    n = walkers * steps * n_modes
    if n > MAX_EVALUATIONS:
        raise InversionError(
            f"posterior: {walkers} walkers x {steps} steps x {n_modes} modes = {n} model "
            f"evaluations (about {n * seconds_per_call:.0f} s at {seconds_per_call * 1e3:.2g} "
            f"ms each) exceed the bound {MAX_EVALUATIONS}; allowed fewer walkers or steps"
        )


def sample_posterior(
    lay: Any,
    local: Sequence[Any],
    best: int,
    chi2_of: Callable[[Any, np.ndarray], float],
    jacobian: Callable[[Any, np.ndarray], np.ndarray],
    shift: float,
    *,
    walkers: int | None,
    steps: int | None,
    seed: int,
    seconds_per_call: float,
) -> tuple[xr.Dataset, dict[str, Any]]:
    """Sample the posterior from every mode; the summary Dataset and attributes.

    ``local``: the minima (``x``, ``chi2``, ``axis_of``, ``label``); ``chi2_of(m, p)``
    the total chi-square of ``p`` in mode ``m``'s parametrisation, ``inf`` outside the
    bounds; ``jacobian(m, p)`` the normalised residuals' Jacobian; ``shift`` is ``360
    (t_ref - t_epoch)`` [degree s] (the phase at the epoch is ``p[3] - shift / P``).
    ``walkers=None``: :func:`default_walkers`; ``steps=None``: grown by
    :data:`CHUNK_STEPS` until the chain spans :data:`MIN_TAUS` autocorrelation times,
    within the budget :data:`MAX_EVALUATIONS`.  The burn-in discarded is five
    autocorrelation times (the walkers start in the typical set), at most half the chain.
    """
    chi_best = local[best].chi2
    modes = [
        i for i, m in enumerate(local) if np.isfinite(m.chi2) and m.chi2 - chi_best < MODE_CHI2
    ]
    # the same minimum reached from two starts: keep one
    kept: list[int] = []
    for i in modes:
        o = _outputs(lay, local[i].axis_of, local[i].x, shift)
        if not any(
            np.allclose(o, _outputs(lay, local[j].axis_of, local[j].x, shift), rtol=1e-6, atol=1e-6)
            for j in kept
        ):
            kept.append(i)
    walkers = default_walkers(lay.n) if walkers is None else walkers
    max_steps = steps
    if steps is None:
        check_budget(walkers, CHUNK_STEPS, len(kept), seconds_per_call)
        max_steps = max(CHUNK_STEPS, MAX_EVALUATIONS // (walkers * len(kept)))
    else:
        check_budget(walkers, steps, len(kept), seconds_per_call)
    if walkers < 2 * lay.n:
        raise InversionError(
            f"posterior: {walkers} walkers for {lay.n} parameters; allowed at least 2 x "
            f"{lay.n} = {2 * lay.n} (emcee's affine-invariant moves need them)"
        )
    rng = np.random.default_rng(seed)
    t0 = time.perf_counter()
    samples, log_z, accept, labels, taus, n_effs, ran = [], [], [], [], [], [], []
    for i in kept:
        m = local[i]
        cov, free = covariance(jacobian(m, m.x))
        cov = np.where(free[:, None] | free[None, :], 0.0, cov)
        sign, logdet = np.linalg.slogdet(2 * np.pi * cov[np.ix_(~free, ~free)])
        log_z.append(-0.5 * m.chi2 + 0.5 * (logdet if sign > 0 else -np.inf))

        def log_prob(p: np.ndarray, m: Any = m) -> float:
            c = chi2_of(m, p)
            return -0.5 * c if np.isfinite(c) else -np.inf

        chain, tau, accepted = run_chain(
            m.x, cov, log_prob, walkers, steps, int(max_steps or 0), rng
        )
        burn = min(chain.shape[0] // 2, max(int(np.ceil(5 * tau)), 1))
        taus.append(tau)
        n_effs.append(walkers * (chain.shape[0] - burn) / max(tau, 1.0))
        ran.append(chain.shape[0])
        flat = chain[burn:].reshape(-1, lay.n)
        samples.append(np.array([_outputs(lay, m.axis_of, p, shift) for p in flat]))
        accept.append(accepted)
        labels.append(m.label)
    warn_short(taus, labels, ran, walkers)
    lz = np.array(log_z)
    prob = np.exp(lz - lz.max())
    prob /= prob.sum()
    # the mixture: every mode's samples with its probability (equal sample counts)
    ref = samples[0][0]
    stacked = np.concatenate(samples)
    weights = np.concatenate(
        [np.full(len(s), w / len(s)) for s, w in zip(samples, prob, strict=True)]
    )
    stacked[:, 3] = ref[3] + (stacked[:, 3] - ref[3] + 180.0) % 360.0 - 180.0  # phase, unwrapped
    stacked[:, 0] = ref[0] + (stacked[:, 0] - ref[0] + 180.0) % 360.0 - 180.0  # longitude
    summary = _summary(stacked, weights)
    seconds = time.perf_counter() - t0
    names = [*lay.names, *(f"fraction_{m}" for m in lay.materials)]
    ds = xr.Dataset(
        {
            f"posterior_{k}": (
                "posterior_parameter",
                v,
                {
                    "units": "1",
                    "long_name": f"posterior {k} (units: parameter_units of the same name)",
                },
            )
            for k, v in summary.items()
        },
        coords={
            "posterior_parameter": (
                "posterior_parameter",
                names,
                {"units": "1", "long_name": "parameter (and every material's area fraction)"},
            ),
            "mode": ("mode", labels, {"units": "1", "long_name": "start whose minimum is sampled"}),
        },
    )
    ds["mode_probability"] = (
        "mode",
        prob,
        {"units": "1", "long_name": "probability of the mode (Laplace evidence, normalised)"},
    )
    ds["mode_acceptance"] = (
        "mode",
        np.array(accept),
        {"units": "1", "long_name": "mean acceptance fraction of the mode's walkers"},
    )
    ds["mode_autocorrelation_time"] = (
        "mode",
        np.array(taus),
        {"units": "1", "long_name": "integrated autocorrelation time of the mode's chain [steps]"},
    )
    ds["mode_steps"] = (
        "mode",
        np.array(ran),
        {"units": "1", "long_name": "steps run by the mode's chain"},
    )
    ds["mode_effective_samples"] = (
        "mode",
        np.array(n_effs),
        {"units": "1", "long_name": "effective number of independent samples of the mode"},
    )
    attrs = {
        "posterior": f"emcee ensemble of {walkers} walkers, Laplace-approximation "
        f"independence proposals ({1 - DE_SHARE:.0%}, Student-t {PROPOSAL_DOF:g} dof) and "
        f"differential evolution ({DE_SHARE:.0%}); steps per mode "
        f"{', '.join(map(str, ran))} ("
        + ("grown until 50 autocorrelation times" if steps is None else "as asked")
        + f"; burn-in of 5 autocorrelation times discarded), {len(kept)} modes, seed {seed}",
        "posterior_seconds": seconds,
    }
    return ds, attrs


def warn_short(
    taus: Sequence[float], labels: Sequence[str], steps: Sequence[int] | int, walkers: int
) -> None:
    """A :class:`~sbrdf_xr.errors.ChainLengthWarning` for the modes whose chains span fewer
    than :data:`MIN_TAUS` autocorrelation times, with the steps to ask for."""
    ran = [steps] * len(taus) if isinstance(steps, int) else list(steps)
    short = [(lab, t, n) for lab, t, n in zip(labels, taus, ran, strict=True) if n < MIN_TAUS * t]
    if short:
        need = int(np.ceil(MIN_TAUS * max(t for _, t, _ in short)))
        listed = ", ".join(f"{lab!s} (tau {t:.3g} steps)" for lab, t, _ in short)
        warnings.warn(
            f"posterior: chains of {max(n for _, _, n in short)} steps x {walkers} walkers "
            f"span fewer than {MIN_TAUS} autocorrelation times in mode(s) {listed}: the "
            f"widths and the 2.5 / 97.5 % points are not converged; ask for "
            f"posterior_steps >= {need}",
            ChainLengthWarning,
            stacklevel=4,
        )


def run_chain(
    x: np.ndarray,
    cov: np.ndarray,
    log_prob: Callable[[np.ndarray], float],
    walkers: int,
    steps: int | None,
    max_steps: int,
    rng: np.random.Generator,
) -> tuple[np.ndarray, float, float]:
    """One mode's emcee chain ``(steps, walkers, parameters)``, its autocorrelation time
    [steps] and mean acceptance fraction; ``steps=None``: grown by :data:`CHUNK_STEPS`
    until it spans :data:`MIN_TAUS` autocorrelation times or reaches ``max_steps``.

    The walkers start at draws of the Gaussian ``N(x, cov)`` (those outside the support
    of ``log_prob`` pulled next to ``x``); the moves are :func:`laplace_move` of ``(x,
    cov)`` and emcee's ``DEMove``.

    Examples
    --------
    A correlated Gaussian target is sampled with its own covariance as the proposal's:

    >>> import numpy as np
    >>> from sbrdf_xr.invert._joint.posterior import run_chain
    >>> cov = np.array([[1.0, 0.8], [0.8, 1.0]])
    >>> icov = np.linalg.inv(cov)
    >>> chain, tau, acc = run_chain(np.zeros(2), cov, lambda p: -0.5 * p @ icov @ p, 8,
    ...                             None, 2000, np.random.default_rng(0))
    >>> bool(tau < 5), bool(chain.shape[0] >= 50 * tau), bool(0.3 < acc < 1)
    (True, True, True)
    """
    import emcee

    n = x.size
    sd = np.sqrt(np.clip(np.diag(cov), 0, None))
    # walkers start in the typical set: draws of the Gaussian (Laplace) approximation
    ev, vec = np.linalg.eigh(cov)
    start = x + rng.standard_normal((walkers, n)) @ (vec * np.sqrt(np.clip(ev, 0, None))).T
    for w in range(walkers):  # a start outside the bounds: pulled next to (or onto) x
        if not np.isfinite(log_prob(start[w])):
            start[w] = x + 1e-3 * sd * rng.standard_normal(n)
            if not np.isfinite(log_prob(start[w])):
                start[w] = x
    moves = [(laplace_move(x, cov), 1.0 - DE_SHARE), (emcee.moves.DEMove(), DE_SHARE)]
    sampler = emcee.EnsembleSampler(walkers, n, log_prob, moves=moves)
    sampler.random_state = np.random.RandomState(int(rng.integers(2**31))).get_state()
    if steps is not None:
        sampler.run_mcmc(start, steps, progress=False)
    else:
        state: Any = start
        while True:
            state = sampler.run_mcmc(state, CHUNK_STEPS, progress=False)
            done = sampler.iteration
            tau = chain_convergence(sampler.get_chain(), 0)[0]
            if done >= MIN_TAUS * tau or done + CHUNK_STEPS > max_steps:
                break
    chain = sampler.get_chain()
    tau = chain_convergence(chain, 0)[0]
    return chain, tau, float(np.mean(sampler.acceptance_fraction))


def _summary(x: np.ndarray, w: np.ndarray) -> dict[str, np.ndarray]:
    """Weighted median, standard deviation and 2.5 / 97.5 % points of every column."""
    out: dict[str, list[float]] = {"median": [], "sd": [], "low": [], "high": []}
    for j in range(x.shape[1]):
        order = np.argsort(x[:, j])
        cw = np.cumsum(w[order])
        cw /= cw[-1]
        col = x[order, j]
        out["median"].append(float(np.interp(0.5, cw, col)))
        out["low"].append(float(np.interp(0.025, cw, col)))
        out["high"].append(float(np.interp(0.975, cw, col)))
        mean = float(np.sum(w * x[:, j]) / w.sum())
        out["sd"].append(float(np.sqrt(np.sum(w * (x[:, j] - mean) ** 2) / w.sum())))
    return {k: np.asarray(v) for k, v in out.items()}
