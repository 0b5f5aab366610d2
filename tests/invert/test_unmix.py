"""Material unmixing: recovery of a known mixture, honest uncertainties, warnings, bad input.

The measured spectra are the forward model's per-material terms of CanX-1 mixed with known
scale factors, plus Gaussian noise; tolerances are stated where they are used.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import xarray as xr

from sbrdf_xr import invert
from sbrdf_xr.errors import FitQualityWarning, InversionError

AL, CELL, PAINT = "aluminium-6061-t6", "tjpv-cell", "white-paint-a276"


def _noisy(truth, rel, seed):
    rng = np.random.default_rng(seed)
    sigma = rel * np.abs(truth) + 1e-12
    return truth + sigma * rng.normal(size=truth.shape), sigma


def _mix(per_material, scales):
    return (per_material * xr.DataArray(scales, dims="material")).sum("material")


def test_unmix_recovers_areas(per_material, sc):
    scale = np.array([0.0, 1.2, 1.0])  # no aluminium
    y, sigma = _noisy(_mix(per_material, scale), 0.01, 3)
    r = invert.unmix(y, per_material, sigma, areas=invert.material_areas(sc), select=None)
    est, unc = r["scale"].values, r["scale_uncertainty"].values
    # linear least squares with the true sigma: every estimate within 4 sigma of the truth
    # (a 6e-5 chance per value for a calibrated estimator)
    assert np.all(np.abs(est - scale) < 4 * unc)
    assert r.attrs["fit_quality"] == "consistent"
    assert r["area"].attrs["units"] == "m2" and "long_name" in r["scale"].attrs
    # the fractions sum to one over the candidates, and say so
    assert float(r["area_fraction"].sum()) == pytest.approx(1.0)
    assert "candidate materials of this fit" in r["area_fraction"].attrs["normalisation"]


def test_unmix_equals_independent_least_squares(per_material):
    """The estimate and covariance of the full model are numpy's weighted least squares."""
    y, sigma = _noisy(_mix(per_material, [0.6, 1.0, 0.25]), 0.03, 11)
    r = invert.unmix(
        y.isel(geometry=0), per_material.isel(geometry=0), sigma.isel(geometry=0), select=None
    )
    a = per_material.isel(geometry=0).transpose("wavelength", "material").values
    s = sigma.isel(geometry=0).values
    x, *_ = np.linalg.lstsq(a / s[:, None], y.isel(geometry=0).values / s, rcond=None)
    cov = np.linalg.inv((a / s[:, None]).T @ (a / s[:, None]))
    np.testing.assert_allclose(r["scale"].values, x, rtol=1e-6)
    np.testing.assert_allclose(r["scale_uncertainty"].values, np.sqrt(np.diag(cov)), rtol=1e-6)


def test_selection_keeps_a_material_it_cannot_drop(per_material):
    """One geometry, paint poorly determined: dropping it would bias the aluminium by far
    more than its sigma, so the full model (with paint's large sigma) is kept."""
    y, sigma = _noisy(_mix(per_material, [0.6, 1.0, 0.25]), 0.03, 5)
    r = invert.unmix(y.isel(geometry=0), per_material.isel(geometry=0), sigma.isel(geometry=0))
    assert bool(r["selected"].all())
    sub = r.sel(subset=f"{AL}+{CELL}")
    assert float(sub["subset_bias_ratio"]) > invert.DROP_BIAS and not bool(sub["subset_admissible"])
    # the paint's uncertainty says the data cannot tell 0.25 from 0 or from 1
    assert float(r["scale_uncertainty"].sel(material=PAINT)) > 0.5


def test_selection_drops_an_absent_material(per_material):
    """Geometry 0, no cells: leaving them out costs the others less than DROP_BIAS sigma,
    so the BIC drops them (in 390 of 400 draws of a study of this case; >= 15 of 20 here
    fails with probability 2e-4); whenever the lowest-BIC subset is not the one chosen, it
    is because its omission could bias the others by more than DROP_BIAS sigma."""
    left_out = 0
    for seed in range(20):
        y, sigma = _noisy(_mix(per_material, [0.3, 0.0, 1.0]), 0.03, seed)
        r = invert.unmix(y.isel(geometry=0), per_material.isel(geometry=0), sigma.isel(geometry=0))
        assert r.sizes["subset"] == 7  # every non-empty subset of three
        lowest = str(r.subset.values[int(np.argmin(r.subset_bic.values))])
        chosen = r.attrs["selected_materials"].replace(", ", "+")
        if chosen != lowest:
            assert float(r["subset_bias_ratio"].sel(subset=lowest)) > invert.DROP_BIAS
        left_out += chosen == f"{AL}+{PAINT}"
    assert left_out >= 15
    assert float(r["scale"].sel(material=CELL)) == 0.0
    g = invert.unmix(
        y.isel(geometry=0), per_material.isel(geometry=0), sigma.isel(geometry=0), select="greedy"
    )
    assert g.attrs["selected_materials"] == r.attrs["selected_materials"]
    assert float(r["subset_weight"].sum()) == pytest.approx(1.0)


def test_selection_keeps_an_absent_material_it_cannot_drop_safely(per_material):
    """Six geometries, no aluminium: the cells' estimate is correlated with the aluminium's
    (dropping it could shift the cells by 2 of their sigma), so the aluminium stays in the
    model, its estimate consistent with zero."""
    y, sigma = _noisy(_mix(per_material, [0.0, 1.0, 0.25]), 0.03, 0)
    r = invert.unmix(y, per_material, sigma)
    assert bool(r["selected"].all())
    al = r.sel(material=AL)
    assert abs(float(al["scale"])) < 3 * float(al["scale_uncertainty"])
    assert float(r["subset_bias_ratio"].sel(subset=f"{CELL}+{PAINT}")) > invert.DROP_BIAS


def test_unmix_degeneracy_reported(per_material):
    a = per_material.isel(material=1)
    lib = {"cell": a, "cell-copy": a * 1.0001, "paint": per_material.isel(material=2)}
    y, sigma = _noisy(a + per_material.isel(material=2), 0.01, 5)
    r = invert.unmix(y, lib, sigma, select=None)
    assert "cell / cell-copy" in r.attrs["degenerate"]
    assert "paint" not in r.attrs["degenerate"]


def test_candidates_on_other_grids_are_interpolated(per_material):
    """A candidate on a coarser grid is interpolated to the measured one, with a note;
    the fit equals least squares on the candidate interpolated independently (np.interp)."""
    g0 = per_material.isel(geometry=4)
    coarse = g0.sel(material=CELL).isel(wavelength=slice(None, None, 4))  # 141 -> 36, ends kept
    lib = {AL: g0.sel(material=AL), CELL: coarse, PAINT: g0.sel(material=PAINT)}
    y, sigma = _noisy(_mix(g0, [0.6, 1.0, 0.25]), 0.01, 8)
    r = invert.unmix(y, lib, sigma, select=None)
    assert f"'{CELL}' interpolated linearly" in r.attrs["library_note"]
    wl = g0.wavelength.values
    cols = [
        g0.sel(material=AL).values,
        np.interp(wl, coarse.wavelength.values, coarse.values),
        g0.sel(material=PAINT).values,
    ]
    a = np.stack(cols, axis=-1) / sigma.values[:, None]
    x, *_ = np.linalg.lstsq(a, y.values / sigma.values, rcond=None)
    np.testing.assert_allclose(r["scale"].values, x, rtol=1e-6)
    # a candidate that does not cover the measured wavelengths is refused, named
    short = g0.sel(material=CELL).isel(wavelength=slice(0, 40))
    with pytest.raises(InversionError, match=f"'{CELL}' covers"):
        invert.unmix(y, {**lib, CELL: short}, sigma)


def test_missing_material_warns(per_material):
    y, sigma = _noisy(_mix(per_material, [0.6, 1.0, 0.25]), 0.01, 6)
    lib = {AL: per_material.sel(material=AL), CELL: per_material.sel(material=CELL)}
    with pytest.warns(FitQualityWarning, match="missing from the candidate library") as rec:
        r = invert.unmix(y, lib, sigma)
    assert "99.9 % point" in str(rec[0].message) and r.attrs["fit_quality"] == "poor"
    assert float(r["reduced_chi_square"]) > 5


def test_wrong_geometry_warns(per_material):
    y, sigma = _noisy(per_material.isel(geometry=4).sum("material"), 0.01, 7)
    with pytest.warns(FitQualityWarning, match="simulated geometry differs"):
        invert.unmix(y, per_material.isel(geometry=5), sigma)


def test_overstated_uncertainties_warn(per_material):
    y, sigma = _noisy(per_material.sum("material"), 0.01, 9)
    with pytest.warns(FitQualityWarning, match="overstated"):
        r = invert.unmix(y, per_material, 10 * sigma)
    assert r.attrs["fit_quality"] == "too good"


def test_zero_degrees_of_freedom_warn(per_material):
    """Three values for three materials: the fit is exact whatever the data's errors, so its
    chi-square tests nothing; said in a FitQualityWarning and the result's note (before:
    fit_quality 'undetermined' without a word)."""
    pm = per_material.isel(geometry=0)
    pm = pm.isel(wavelength=np.linspace(0, pm.sizes["wavelength"] - 1, 3).astype(int))
    y, sigma = _noisy(_mix(pm, [0.6, 1.0, 0.25]), 0.01, 4)
    with pytest.warns(FitQualityWarning, match="0 degrees of freedom") as rec:
        r = invert.unmix(y, pm, sigma, select=None)
    assert int(r["degrees_of_freedom"]) == 0 and r.attrs["fit_quality"] == "undetermined"
    assert "3 measured values for 3 free parameters" in str(rec[0].message)
    assert r.attrs["fit_quality_note"] == str(rec[0].message)
    # one value more: a fit with a degree of freedom to test, no such warning
    pm4 = per_material.isel(geometry=0)
    pm4 = pm4.isel(wavelength=np.linspace(0, pm4.sizes["wavelength"] - 1, 4).astype(int))
    y4, sigma4 = _noisy(_mix(pm4, [0.6, 1.0, 0.25]), 0.01, 4)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        invert.unmix(y4, pm4, sigma4, select=None)
    assert not [w for w in caught if "degrees of freedom, so" in str(w.message)]


@pytest.mark.parametrize("geoms", [[0], [0, 1, 2, 3, 4, 5]], ids=["one-geometry", "six"])
def test_calibration_small(per_material, geoms):
    """60 draws per case in the default run: pull widths 1 within 0.3 (the spread of a
    standard deviation of 60 unit normals is 0.09, so 0.3 is 3.3 sigma)."""
    terms = per_material.isel(geometry=geoms)
    study = invert.unmix_calibration(
        terms, {AL: 0.6, CELL: 1.0, PAINT: 0.25}, relative_noise=0.03, n_draws=60, seed=1
    )
    np.testing.assert_allclose(study["pull_width"].values, 1.0, atol=0.3)


@pytest.mark.slow
@pytest.mark.parametrize(
    "geoms",
    [[0], [2], [4], [0, 1, 2, 3, 4, 5]],
    ids=["geometry-0", "geometry-2", "geometry-4", "six"],
)
@pytest.mark.parametrize(
    "truth",
    [(0.6, 1.0, 0.25), (0.0, 1.0, 0.25), (0.3, 0.0, 1.0)],
    ids=["all-present", "no-aluminium", "no-cells"],
)
def test_calibration_study(per_material, geoms, truth):
    """400 draws per case: the pulls of the materials present have width 1 +- 0.15, and
    the stated 2-sigma intervals of every material cover the truth in >= 91.5 % of draws
    (95.4 % expected, binomial spread 1.05 %: 3.7 spreads below, for 36 such numbers)."""
    terms = per_material.isel(geometry=geoms)
    names = [AL, CELL, PAINT]
    study = invert.unmix_calibration(
        terms, dict(zip(names, truth, strict=True)), relative_noise=0.03, n_draws=400, seed=2
    )
    table = study.drop_vars(["n_draws", "quality_warnings", "seconds_per_fit"]).to_dataframe()
    print(f"\ngeometries {geoms}, truth {truth}, {int(study.n_draws)} draws:\n{table.to_string()}")
    present = np.array(truth) > 0
    np.testing.assert_allclose(study["pull_width"].values[present], 1.0, atol=0.15)
    assert np.all(study["coverage_2sigma"].values >= 0.915)


def test_unmix_bad_input(per_material):
    y = per_material.sum("material")
    with pytest.raises(InversionError, match="uncertainty"):
        invert.unmix(y, per_material, 0.0)
    with pytest.raises(InversionError, match="uncertainty"):
        invert.unmix(y, per_material, -1e-5)
    with pytest.raises(InversionError, match="uncertainty"):
        invert.unmix(y, per_material, np.nan)
    with pytest.raises(InversionError, match="NaN or infinite"):
        invert.unmix(y.where(y.wavelength != y.wavelength[3]), per_material, 1e-5)
    far = y.assign_coords(wavelength=y.wavelength + 2000.0)
    with pytest.raises(InversionError, match="outside the simulated range"):
        invert.unmix(far, per_material, 1e-5)
    with pytest.raises(InversionError, match="2 values for 3 material parameters"):
        invert.unmix(y.isel(geometry=0, wavelength=[0, 1]), per_material.isel(geometry=0), 1e-5)
    with pytest.raises(InversionError, match="select"):
        invert.unmix(y, per_material, 1e-5, select="some")
    with pytest.raises(InversionError, match="drop_bias"):
        invert.unmix(y, per_material, 1e-5, drop_bias=-1)
    with pytest.raises(InversionError, match="empty"):
        invert.unmix(y, {}, 1e-5)
    with pytest.raises(InversionError, match="geometry"):
        invert.unmix(y.isel(geometry=0), per_material, 1e-5)
    bands = xr.DataArray([1.0, 1.0], dims="band", coords={"band": ["V", "R"]})
    lib_b = xr.DataArray(
        np.ones((2, 1)), dims=("material", "band"), coords={"material": ["x", "y"], "band": ["V"]}
    )
    with pytest.raises(InversionError, match="bands"):
        invert.unmix(bands, lib_b, 0.1)


# ------------------------------------------------------------ areas adding up to a total


def _constrained_truth(sc, scales, free):
    """Scale factors with the one of index ``free`` set so that the areas add up to the
    mesh's."""
    names = [AL, CELL, PAINT]
    nominal = np.array([invert.material_areas(sc)[m] for m in names])
    x = np.array(scales, dtype=float)
    x[free] = 0.0
    x[free] = (nominal.sum() - nominal @ x) / nominal[free]
    return x, nominal


def _kkt(a, y, s, c, total):
    """Equality-constrained weighted least squares by the Lagrange (KKT) system, solved
    by numpy: estimate, covariance (the inverse's upper-left block), chi-square."""
    aw, yw = a / s[:, None], y / s
    k = a.shape[1]
    kkt = np.block([[aw.T @ aw, c[:, None]], [c[None, :], np.zeros((1, 1))]])
    inv = np.linalg.inv(kkt)
    x = np.linalg.solve(kkt, np.r_[aw.T @ yw, total])[:k]
    return x, inv[:k, :k], float(((yw - aw @ x) ** 2).sum())


def test_total_area_equals_independent_constrained_least_squares(per_material, sc):
    """With total_area the estimate, covariance and chi-square are those of the Lagrange
    system solved by numpy (to 1e-8: two routes of double-precision linear algebra on a
    design of condition ~1e3); dof one more than without; the area fractions add up to 1
    and say they are of the total."""
    truth, nominal = _constrained_truth(sc, [0.6, 1.0, 0.0], free=2)
    g = per_material.isel(geometry=0)
    y, sigma = _noisy(_mix(g, truth), 0.03, 21)
    areas = invert.material_areas(sc)
    r = invert.unmix(y, g, sigma, areas=areas, total_area=True, select=None)
    a = g.transpose("wavelength", "material").values
    x, cov, chi2 = _kkt(a, y.values, sigma.values, nominal, nominal.sum())
    np.testing.assert_allclose(r["scale"].values, x, rtol=1e-8)
    np.testing.assert_allclose(r["scale_uncertainty"].values, np.sqrt(np.diag(cov)), rtol=1e-8)
    assert float(r["chi2"]) == pytest.approx(chi2, rel=1e-8)
    assert (
        int(r["degrees_of_freedom"]) == y.size - 2
        and "area constraint" in r["degrees_of_freedom"].attrs["long_name"]
    )
    assert float(r["reduced_chi_square"]) == pytest.approx(chi2 / (y.size - 2))
    assert float(r["aic"]) == pytest.approx(chi2 + 2 * 2)  # two free parameters
    assert float(r["area"].sum()) == pytest.approx(nominal.sum(), rel=1e-12)
    assert float(r["area_fraction"].sum()) == pytest.approx(1.0, rel=1e-12)
    assert "total_area" in r["area_fraction"].attrs["normalisation"]
    assert float(r["total_area"]) == pytest.approx(nominal.sum())
    # the fractions' uncertainties are the areas' over the (exact) total
    np.testing.assert_allclose(
        r["area_fraction_uncertainty"].values,
        np.sqrt(np.diag(cov)) * nominal / nominal.sum(),
        rtol=1e-8,
    )
    # True is the sum of areas: the same fit as the number
    same = invert.unmix(y, g, sigma, areas=areas, total_area=float(nominal.sum()), select=None)
    np.testing.assert_allclose(same["scale"].values, r["scale"].values, rtol=1e-12)


def test_total_area_selection_fits_every_subset_with_the_constraint(per_material, sc):
    """Every subset scored obeys the constraint (its chi-square is that of the Lagrange
    system on its columns), counts one parameter less in its criteria, and the kept
    model's areas add up to the total; a subset whose omission the constraint turns into
    a bias (the others must fill the left-out area) is inadmissible."""
    truth, nominal = _constrained_truth(sc, [0.6, 1.0, 0.0], free=2)
    g = per_material.isel(geometry=[0, 4])
    y, sigma = _noisy(_mix(g, truth), 0.03, 22)
    r = invert.unmix(y, g, sigma, areas=invert.material_areas(sc), total_area=True)
    names = [AL, CELL, PAINT]
    a = g.transpose("geometry", "wavelength", "material").values.reshape(-1, 3)
    for label in r.subset.values:
        cols = [names.index(m) for m in str(label).split("+")]
        _, _, chi2 = _kkt(
            a[:, cols], y.values.ravel(), sigma.values.ravel(), nominal[cols], nominal.sum()
        )
        row = r.sel(subset=label)
        assert float(row["subset_chi2"]) == pytest.approx(chi2, rel=1e-8)
        assert float(row["subset_bic"]) == pytest.approx(chi2 + (len(cols) - 1) * np.log(y.size))
    assert float((r["scale"] * xr.DataArray(nominal, dims="material")).sum()) == pytest.approx(
        nominal.sum()
    )
    assert r.attrs["area_constraint"].startswith("the areas of the fitted materials add up")
    assert not bool(r["subset_admissible"].sel(subset=f"{AL}+{PAINT}"))


def test_total_area_bad_input(per_material, sc):
    y = per_material.isel(geometry=0).sum("material")
    g = per_material.isel(geometry=0)
    areas = invert.material_areas(sc)
    with pytest.raises(InversionError, match="total_area: True needs areas"):
        invert.unmix(y, g, 1e-5, total_area=True)
    for bad in (0.0, -1.0, np.nan, "big"):
        with pytest.raises(InversionError, match="total_area"):
            invert.unmix(y, g, 1e-5, areas=areas, total_area=bad)
    with pytest.raises(InversionError, match="every candidate has area 0"):
        invert.unmix(y, g, 1e-5, areas=dict.fromkeys(areas, 0.0), total_area=1.0)
    # False is no constraint
    y, sigma = _noisy(y, 0.01, 23)
    free = invert.unmix(y, g, sigma, areas=areas, total_area=False, select=None)
    assert free.attrs["area_constraint"] == "none" and "total_area" not in free


#: Held-out mixtures whose areas add up to the mesh's (the paint takes the rest), all
#: other than the model's own (scale 1 each).
CONSTRAINED = {
    "all-present": ([0.6, 1.0, 0.0], 2),
    "no-aluminium": ([0.0, 1.2, 0.0], 2),
    "no-cells": ([0.3, 0.0, 0.0], 2),
}


@pytest.mark.parametrize("geoms", [[0], [0, 1, 2, 3, 4, 5]], ids=["one-geometry", "six"])
def test_calibration_total_area_small(per_material, sc, geoms):
    """60 draws per case in the default run, areas constrained to the mesh's: pull widths
    1 within 0.3 (3.3 spreads of a standard deviation of 60 unit normals)."""
    truth, _ = _constrained_truth(sc, *CONSTRAINED["all-present"])
    study = invert.unmix_calibration(
        per_material.isel(geometry=geoms),
        dict(zip([AL, CELL, PAINT], truth, strict=True)),
        relative_noise=0.03,
        n_draws=60,
        seed=1,
        areas=invert.material_areas(sc),
        total_area=True,
    )
    np.testing.assert_allclose(study["pull_width"].values, 1.0, atol=0.3)
    assert np.all(study["coverage_2sigma"].values >= 0.85)  # 95.4 % expected, spread 2.7 %


@pytest.mark.slow
@pytest.mark.parametrize(
    "geoms",
    [[0], [2], [4], [0, 1, 2, 3, 4, 5]],
    ids=["geometry-0", "geometry-2", "geometry-4", "six"],
)
@pytest.mark.parametrize("mixture", list(CONSTRAINED))
def test_calibration_total_area_study(per_material, sc, geoms, mixture):
    """200 draws per case, areas constrained to the mesh's: the pulls of every material
    (present or not: with the constraint none is left out) have width 1 +- 0.15 (3
    spreads of 0.05), and the 2-sigma intervals cover the truth in >= 91 % of draws (95.4 %
    expected, binomial spread 1.5 %: 3 spreads)."""
    truth, _ = _constrained_truth(sc, *CONSTRAINED[mixture])
    study = invert.unmix_calibration(
        per_material.isel(geometry=geoms),
        dict(zip([AL, CELL, PAINT], truth, strict=True)),
        relative_noise=0.03,
        n_draws=200,
        seed=2,
        areas=invert.material_areas(sc),
        total_area=True,
    )
    table = study.drop_vars(["n_draws", "quality_warnings", "seconds_per_fit"]).to_dataframe()
    print(f"\ngeometries {geoms}, {mixture} {np.round(truth, 4)}, 200 draws:\n{table.to_string()}")
    np.testing.assert_allclose(study["pull_width"].values, 1.0, atol=0.15)
    assert np.all(study["coverage_2sigma"].values >= 0.91)


# ---------------------------------------------------------- a measured spectrum over time


def test_unmix_takes_a_spectrum_over_time(per_material, sc):
    """A measured spectrum over wavelength (no band dimension) on a spectrometer's grid
    (5 nm steps offset by 2.5 nm from the simulated one), at three times: the fit equals
    numpy's weighted least squares on the simulated terms interpolated by np.interp, every
    time and wavelength a row (to 1e-6: linear interpolation by two routes), free and
    with the areas constrained (the Lagrange system)."""
    g = per_material.isel(geometry=[0, 2, 4]).rename(geometry="time")
    g = g.assign_coords(
        time=np.array(
            ["2024-03-17T20:00:00", "2024-03-17T20:00:10", "2024-03-17T20:00:20"],
            dtype="datetime64[ns]",
        )
    )
    wl = np.arange(402.5, 1100.0, 5.0)
    truth, nominal = _constrained_truth(sc, [0.6, 1.0, 0.0], free=2)
    rng = np.random.default_rng(31)
    a = np.stack(
        [
            np.stack(
                [
                    np.interp(wl, g.wavelength.values, g.isel(time=t, material=m).values)
                    for m in range(3)
                ],
                axis=-1,
            )
            for t in range(3)
        ]
    )  # (time, wavelength, material)
    clean = a @ truth
    sigma = 0.02 * clean + 1e-12
    y = xr.DataArray(
        clean + sigma * rng.normal(size=clean.shape),
        dims=("time", "wavelength"),
        coords={"time": g.time.values, "wavelength": wl},
    )
    assert "band" not in y.dims
    r = invert.unmix(y, g, sigma, select=None)
    x, *_ = np.linalg.lstsq(
        a.reshape(-1, 3) / sigma.reshape(-1, 1), (y.values / sigma).ravel(), rcond=None
    )
    np.testing.assert_allclose(r["scale"].values, x, rtol=1e-6)
    assert int(r["n_samples"]) == 3 * wl.size
    tied = invert.unmix(y, g, sigma, areas=invert.material_areas(sc), total_area=True, select=None)
    xc, cov, _ = _kkt(a.reshape(-1, 3), y.values.ravel(), sigma.ravel(), nominal, nominal.sum())
    np.testing.assert_allclose(tied["scale"].values, xc, rtol=1e-6)
    np.testing.assert_allclose(tied["scale_uncertainty"].values, np.sqrt(np.diag(cov)), rtol=1e-6)


@pytest.fixture(scope="module")
def unseen_aluminium(sc):
    """Per-material spectra of CanX-1 at a geometry where the aluminium is never lit and
    seen (its column is exactly zero) and at one where every material is."""
    from sbrdf_xr.engine import Scene
    from sbrdf_xr.engine.run import simulate

    s = np.array([[0.0, 0.3, 1.0], [0.8564, 0.4945, 0.1483]])
    o = np.array([[0.3, 0.0, 1.0], [0.8375, -0.5233, -0.157]])
    s, o = (v / np.linalg.norm(v, axis=1)[:, None] for v in (s, o))
    cube = simulate(Scene(sc, to_sun=s, to_observer=o, outputs=("signal", "per_material")))
    g = cube["signal_material"].load().isel(geometry=0)
    assert float(g.sel(material=AL).max()) == 0.0 and float(g.min("wavelength").min()) == 0.0
    return g


def test_unseen_material_is_pinned_by_the_total_or_said_free(unseen_aluminium, sc):
    """A material never lit and seen: with total_area it is pinned by elimination (the
    estimate and covariance of the Lagrange system, which holds for a singular A^T W A)
    and its 2-sigma coverage over 200 draws is 0.95 +- 0.05 (3.3 binomial sigma of 200
    draws: 0.015 each); without, it is reported as not constrained (NaN +- inf) with a
    warning, never as 0 +- 0; correlations stay in [-1, 1]."""
    g = unseen_aluminium
    areas = invert.material_areas(sc)
    nominal = np.array([areas[m] for m in (AL, CELL, PAINT)])
    truth = np.array([0.8, 0.0, 1.0])
    truth[1] = (nominal.sum() - truth[0] * nominal[0] - truth[2] * nominal[2]) / nominal[1]
    clean = _mix(g, truth)
    rng = np.random.default_rng(5)
    inside = []
    for i in range(200):
        sigma = 0.02 * np.abs(clean) + 1e-12
        y = clean + sigma * rng.normal(size=clean.shape)
        with warnings.catch_warnings():  # 200 draws: a 0.1 % tail of chi2 now and then
            warnings.simplefilter("ignore", FitQualityWarning)
            r = invert.unmix(y, g, sigma, areas=areas, total_area=True)
        if i == 0:
            a = g.transpose("wavelength", "material").values
            x, cov, _ = _kkt(a, y.values, sigma.values, nominal, nominal.sum())
            np.testing.assert_allclose(r["scale"].values, x, rtol=1e-6)
            np.testing.assert_allclose(r["scale_uncertainty"], np.sqrt(np.diag(cov)), rtol=1e-6)
            assert r["constrained_by"].values.tolist() == ["total_area", "data", "data"]
            assert "by elimination" in r.attrs["unconstrained"]
        inside.append(np.abs(r["scale"].values - truth) <= 2 * r["scale_uncertainty"].values)
        corr = np.concatenate([r["correlation"].values, r["candidate_correlation"].values])
        assert np.all(np.abs(corr[np.isfinite(corr)]) <= 1.0)
    assert np.mean(inside, axis=0) == pytest.approx([0.95] * 3, abs=0.05)
    with pytest.warns(FitQualityWarning, match="not constrained by the data"):
        free = invert.unmix(y, g, sigma, areas=areas)
    assert np.isnan(float(free["scale"].sel(material=AL)))
    assert np.isinf(float(free["scale_uncertainty"].sel(material=AL)))
    assert str(free["constrained_by"].sel(material=AL).values) == "none"
    assert np.isinf(float(free["area_fraction_uncertainty"].sel(material=AL)))
    assert float(free["area_fraction"].sum(skipna=True)) == pytest.approx(1.0)
    assert AL in free.attrs["unconstrained"]
