"""The posterior of an unmixing (``unmix(..., method="posterior")``) and its sampler.

The sampler is checked against closed forms (a Gaussian and a truncated Gaussian); the
unmixing's posterior against least squares far from the bounds, against its prior for a
material never lit and seen, and over held-out noise draws (coverage).  Tolerances are
Monte Carlo errors of the chains' effective samples, stated where used.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import xarray as xr
from scipy import stats

from sbrdf_xr import invert
from sbrdf_xr.errors import ChainLengthWarning, FitQualityWarning, InversionError
from sbrdf_xr.invert._joint.posterior import run_chain

AL, CELL, PAINT = "aluminium-6061-t6", "tjpv-cell", "white-paint-a276"


def test_run_chain_samples_a_gaussian_from_a_misplaced_proposal():
    """A 3-d correlated Gaussian sampled with a proposal centred 1 sigma off and twice as
    wide: the chain's mean and covariance are the target's (Metropolis-Hastings corrects
    the proposal).  About 2000+ effective samples: the mean to 0.1 (4 standard errors of
    0.022), the variances to 15 %."""
    cov = np.array([[1.0, 0.6, 0.2], [0.6, 2.0, -0.3], [0.2, -0.3, 0.5]])
    icov = np.linalg.inv(cov)
    mu = np.array([1.0, -2.0, 0.5])
    chain, tau, _ = run_chain(
        mu + np.sqrt(np.diag(cov)),
        4.0 * cov,
        lambda p: -0.5 * (p - mu) @ icov @ (p - mu),
        16,
        None,
        20000,
        np.random.default_rng(3),
    )
    assert chain.shape[0] >= 50 * tau
    flat = chain[chain.shape[0] // 4 :].reshape(-1, 3)
    np.testing.assert_allclose(flat.mean(0), mu, atol=0.1)
    np.testing.assert_allclose(np.cov(flat.T), cov, rtol=0.15, atol=0.08)


def test_run_chain_respects_a_bound_like_the_closed_form():
    """N(0.5, 1) truncated at 0: mean mu + lambda, lambda = phi(a) / (1 - Phi(a)) with
    a = -0.5 (1.0092), variance 1 + a lambda - lambda^2 (0.4862); the proposal is the
    untruncated Gaussian, walkers starting outside pulled in.  32 walkers x 2000 steps
    (tau about 3: some 15000 effective samples, standard errors 0.006 and 0.006):
    tolerance 0.03."""
    a = -0.5
    lam = stats.norm.pdf(a) / stats.norm.sf(a)
    chain, _, _ = run_chain(
        np.array([0.5]),
        np.array([[1.0]]),
        lambda p: -0.5 * (p[0] - 0.5) ** 2 if p[0] >= 0 else -np.inf,
        32,
        2000,
        2000,
        np.random.default_rng(4),
    )
    x = chain[chain.shape[0] // 4 :].ravel()
    assert x.min() >= 0
    assert x.mean() == pytest.approx(0.5 + lam, abs=0.03)
    assert x.var() == pytest.approx(1 + a * lam - lam**2, abs=0.03)


@pytest.fixture(scope="module")
def unseen(sc):
    """CanX-1 at a geometry where its aluminium is never lit and seen (zero column)."""
    from sbrdf_xr.engine import Scene
    from sbrdf_xr.engine.run import simulate

    # a second geometry where it is seen keeps it in the cube
    s = np.array([[0.0, 0.3, 1.0], [0.8564, 0.4945, 0.1483]])
    o = np.array([[0.3, 0.0, 1.0], [0.8375, -0.5233, -0.157]])
    s, o = (v / np.linalg.norm(v, axis=1)[:, None] for v in (s, o))
    cube = simulate(Scene(sc, to_sun=s, to_observer=o, outputs=("signal", "per_material")))
    g = cube["signal_material"].load().isel(geometry=0)
    assert float(g.sel(material=AL).max()) == 0.0
    return g


def _truth(sc, al=0.8, paint=1.0):
    """Scales whose areas add up to the mesh's (the cells take the rest)."""
    areas = invert.material_areas(sc)
    nominal = np.array([areas[m] for m in (AL, CELL, PAINT)])
    cell = (nominal.sum() - al * nominal[0] - paint * nominal[2]) / nominal[1]
    return np.array([al, cell, paint]), nominal, areas


def _draw(terms, truth, seed, rel=0.02):
    clean = (terms * xr.DataArray(truth, dims="material")).sum("material")
    sigma = rel * np.abs(clean) + 1e-12
    return clean + sigma * np.random.default_rng(seed).normal(size=clean.shape), sigma


def test_a_material_never_seen_gets_its_prior(unseen, sc):
    """Without total_area the data say nothing of the aluminium: its posterior is its prior,
    uniform on [0, A / A_al] (no area above the body's): median A / 2 A_al, sd
    (A / A_al) / sqrt(12), 2.5 % point 0.025 A / A_al.  Tolerances: 0.1 and 0.05 of the
    range (4 standard errors of a median and a 2.5 % point of about 300 effective
    samples), the sd to 12 %."""
    truth, nominal, areas = _truth(sc)
    y, sigma = _draw(unseen, truth, 1)
    with pytest.warns(FitQualityWarning, match="not constrained by the data"):
        fit = invert.unmix(y, unseen, sigma, areas=areas, method="posterior")
    top = nominal.sum() / nominal[0]
    al = fit.sel(material=AL)
    assert float(al.posterior_median) == pytest.approx(top / 2, abs=0.1 * top)
    assert float(al.posterior_sd) == pytest.approx(top / np.sqrt(12), rel=0.12)
    assert float(al.posterior_low) == pytest.approx(0.025 * top, abs=0.05 * top)
    assert np.isnan(float(al.scale))  # the point fit still says: not constrained
    assert fit.attrs["posterior_unconstrained"] == "none"
    assert "times the point fit's wall time" in fit.attrs["posterior_cost"]
    # without the nominal areas its prior is improper: not sampled, said
    with pytest.warns(FitQualityWarning, match="not constrained by the data"):
        bare = invert.unmix(y, unseen, sigma, method="posterior")
    assert np.isnan(float(bare.posterior_median.sel(material=AL)))
    assert np.isinf(float(bare.posterior_sd.sel(material=AL)))
    assert bare.attrs["posterior_unconstrained"] == AL


def test_the_constraint_pins_a_material_never_seen(unseen, sc):
    """With total_area the aluminium is what the constraint leaves it: every fraction
    inside [0, 1], the 95 % intervals hold the truth, the chain converged (no warning)."""
    truth, _, areas = _truth(sc)
    y, sigma = _draw(unseen, truth, 2)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ChainLengthWarning)
        fit = invert.unmix(y, unseen, sigma, areas=areas, total_area=True, method="posterior")
    assert np.all(fit.posterior_fraction_low.values >= 0)
    assert np.all(fit.posterior_fraction_high.values <= 1)
    assert np.all((fit.posterior_low.values <= truth) & (truth <= fit.posterior_high.values))
    assert "on the plane of total_area" in fit.attrs["posterior"]


def test_far_from_the_bounds_the_posterior_is_least_squares(per_material, sc):
    """Six geometries, every material well seen: the likelihood is Gaussian and the bounds
    far (the estimates > 10 sigma from 0), so the posterior's median and sd are the least-
    squares estimate and sigma: to 0.15 sigma and 12 % (Monte Carlo error of about 500
    effective samples: 0.045 sigma and 3 %, 3-4 standard errors)."""
    truth, _, areas = _truth(sc, al=0.6, paint=0.9)
    y, sigma = _draw(per_material, truth, 3)
    fit = invert.unmix(y, per_material, sigma, areas=areas, select=None, method="posterior")
    est, sd = fit.scale.values, fit.scale_uncertainty.values
    assert np.all(est > 10 * sd)
    np.testing.assert_array_less(np.abs(fit.posterior_median.values - est), 0.15 * sd)
    np.testing.assert_allclose(fit.posterior_sd.values, sd, rtol=0.12)


def test_unmix_posterior_bad_input(unseen, sc):
    truth, _, areas = _truth(sc)
    y, sigma = _draw(unseen, truth, 1)
    with pytest.raises(InversionError, match="method: 'mcmc'; allowed 'point'"):
        invert.unmix(y, unseen, sigma, method="mcmc")
    with pytest.raises(InversionError, match="allowed positive integers"):
        invert.unmix(
            y, unseen, sigma, areas=areas, total_area=True, method="posterior", posterior_steps=0
        )
    with pytest.raises(InversionError, match=r"1000 walkers x 1000 steps .* exceed the bound"):
        invert.unmix(
            y,
            unseen,
            sigma,
            areas=areas,
            total_area=True,
            method="posterior",
            posterior_walkers=1000,
            posterior_steps=1000,
        )
    with pytest.warns(ChainLengthWarning, match=r"ask for posterior_steps >= \d+"):
        invert.unmix(
            y, unseen, sigma, areas=areas, total_area=True, method="posterior", posterior_steps=20
        )


def _study(terms, sc, n_draws, **options):
    truth, _, areas = (
        _truth(sc, al=0.8, paint=1.0)
        if "unseen" in options.pop("case")
        else (_truth(sc, al=0.6, paint=0.9))
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FitQualityWarning)
        return invert.unmix_calibration(
            terms,
            dict(zip([AL, CELL, PAINT], truth, strict=True)),
            relative_noise=0.02,
            n_draws=n_draws,
            seed=7,
            areas=areas,
            method="posterior",
            **options,
        )


@pytest.mark.parametrize("case", ["unseen-total", "six-total"])
def test_posterior_coverage_small(unseen, per_material, sc, case):
    """20 held-out draws: the 95 % intervals hold the truth in >= 80 % of them (95 %
    expected, binomial sigma 0.049: 3 sigma)."""
    terms = unseen if case.startswith("unseen") else per_material
    study = _study(terms, sc, 20, case=case, total_area=True)
    assert np.all(study.coverage_interval.values >= 0.80), study.to_dataframe()


@pytest.mark.slow
@pytest.mark.parametrize(
    ("case", "total"),
    [("unseen-total", True), ("unseen-free", None), ("six-total", True)],
)
def test_posterior_coverage_study(unseen, per_material, sc, case, total):
    """100 held-out draws per case (2 % noise), the posterior's 95 % intervals and its
    median +- 2 sd against the truth.  Asserted: >= 0.89 (0.95 less 3 binomial sigma of
    100 draws, 0.021); the unseen aluminium without the constraint is its prior, which
    holds the truth (0.8 of a range 0-6.5) in every draw."""
    terms = unseen if case.startswith("unseen") else per_material
    study = _study(terms, sc, 100, case=case, total_area=total)
    print(f"\n{case}:\n{study.to_dataframe().to_string()}")
    assert np.all(study.coverage_interval.values >= 0.89)
    assert np.all(study.coverage_2sigma.values >= 0.89)
