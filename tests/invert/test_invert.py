"""Inversion: recovery of a known truth from data simulated with the forward model.

The spin search grids here are coarse (200 axes, 21 periods, 36 phases) to keep the run
short; the refinement by least squares does the rest.  Tolerances are those of the
specification: spin axis within 5 degree, period within 0.5 %, areas within 3 %, an absent
material within 3 sigma of zero.
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from sbrdf_xr import geometry, invert
from sbrdf_xr.body.spacecraft import canx1
from sbrdf_xr.engine import Scene
from sbrdf_xr.engine.run import simulate
from sbrdf_xr.errors import InversionError
from sbrdf_xr.invert import _spin_search

BANDS = ("V", "R", "I")


@pytest.fixture(scope="module")
def sc():
    return canx1()


@pytest.fixture(scope="module")
def per_material(sc):
    """Per-material spectra of CanX-1 at four geometries."""
    # near-specular on four side faces (the cells and the frame glint), two off-specular
    s = np.array(
        [
            [0.8564, 0.4945, 0.1483],
            [0.3412, 0.9375, 0.0682],
            [-0.7001, 0.7001, -0.14],
            [0.1258, -0.8991, 0.4193],
            [1.0, 0.3, 0.2],
            [-0.7, 0.6, 0.4],
        ]
    )
    o = np.array(
        [
            [0.8375, -0.5233, -0.157],
            [-0.2919, 0.9547, -0.0584],
            [-0.6487, -0.7463, 0.1493],
            [-0.1304, -0.8911, -0.4346],
            [0.8, 0.7, 0.1],
            [-0.9, 0.1, 0.2],
        ]
    )
    s /= np.linalg.norm(s, axis=1)[:, None]
    o /= np.linalg.norm(o, axis=1)[:, None]
    cube = simulate(Scene(sc, to_sun=s, to_observer=o, outputs=("signal", "per_material")))
    return cube["signal_material"]


def _noisy(truth, rel, seed):
    rng = np.random.default_rng(seed)
    sigma = rel * np.abs(truth) + 1e-12
    return truth + sigma * rng.normal(size=truth.shape), sigma


def test_unmix_recovers_areas(per_material, sc):
    scale = xr.DataArray(
        [0.8, 1.2, 1.0], dims="material", coords={"material": per_material.material}
    )
    # one material absent from the truth: aluminium
    scale[0] = 0.0
    truth = (per_material * scale).sum("material")
    y, sigma = _noisy(truth, 0.01, 3)
    r = invert.unmix(y, per_material, sigma, areas=invert.material_areas(sc), select=None)
    est, unc = r["scale"].values, r["scale_uncertainty"].values
    # 1 % noise on ~500 values: the present areas within 3 %
    np.testing.assert_allclose(est[1:], scale.values[1:], rtol=0.03)
    # absent material: consistent with zero (3 sigma)
    assert est[0] <= 3 * unc[0]
    assert 0.2 < float(r["reduced_chi2"]) < 5
    assert r["area"].attrs["units"] == "m2" and "long_name" in r["scale"].attrs


def test_unmix_selection_drops_absent(per_material):
    scale = np.array([0.0, 1.0, 1.0])
    truth = (per_material * xr.DataArray(scale, dims="material")).sum("material")
    y, sigma = _noisy(truth, 0.01, 4)
    r = invert.unmix(y, per_material, sigma, select="all", criterion="bic")
    assert "aluminium" not in r.attrs["selected_materials"]
    assert r.sizes["subset"] == 7  # every non-empty subset of three
    g = invert.unmix(y, per_material, sigma, select="greedy")
    assert g.attrs["selected_materials"] == r.attrs["selected_materials"]


def test_unmix_degeneracy_reported(per_material):
    a = per_material.isel(material=1)
    lib = {"cell": a, "cell-copy": a * 1.0001, "paint": per_material.isel(material=2)}
    truth = a + per_material.isel(material=2)
    y, sigma = _noisy(truth, 0.01, 5)
    r = invert.unmix(y, lib, sigma, select=None)
    assert "cell / cell-copy" in r.attrs["degenerate"]
    assert "paint" not in r.attrs["degenerate"]


def test_unmix_bad_input(per_material):
    y = per_material.sum("material")
    with pytest.raises(InversionError, match="uncertainty"):
        invert.unmix(y, per_material, 0.0)
    with pytest.raises(InversionError, match="uncertainty"):
        invert.unmix(y, per_material, np.nan)
    far = y.assign_coords(wavelength=y.wavelength + 2000.0)
    with pytest.raises(InversionError, match="outside the simulated range"):
        invert.unmix(far, per_material, 1e-5)
    with pytest.raises(InversionError, match="samples"):
        invert.unmix(y.isel(geometry=0, wavelength=[0, 1]), per_material.isel(geometry=0), 1e-5)
    lib = {
        "a": per_material.isel(material=0),
        "b": per_material.isel(material=1, wavelength=slice(0, 50)),
    }
    with pytest.raises(InversionError, match="same wavelength grid"):
        invert.unmix(y, lib, 1e-5)
    bands = xr.DataArray([1.0, 1.0], dims="band", coords={"band": ["V", "R"]})
    lib_b = xr.DataArray(
        np.ones((2, 1)), dims=("material", "band"), coords={"material": ["x", "y"], "band": ["V"]}
    )
    with pytest.raises(InversionError, match="bands"):
        invert.unmix(bands, lib_b, 0.1)


def _spin_curve(sc, axis_body, axis, period, phase, times, s_in, o_in, rel, seed):
    law = invert.spin_model(axis_body, axis, period, phase)
    rot = geometry.rotation_matrices(law.quaternions(times))  # body -> inertial

    def body(v):
        return np.einsum("nji,nj->ni", rot, np.broadcast_to(v, (times.size, 3)))

    cube = simulate(
        Scene(
            sc,
            to_sun=body(s_in),
            to_observer=body(o_in),
            outputs=("band_signal", "area"),
            bands=BANDS,
        )
    )
    f = cube["band_signal"].values
    rng = np.random.default_rng(seed)
    fn = f * (1 + rel * rng.normal(size=f.shape))
    return xr.Dataset(
        {"flux": ("obs", fn.ravel()), "flux_uncertainty": ("obs", rel * f.ravel())},
        coords={"time": ("obs", np.repeat(times, 3)), "band": ("obs", np.tile(BANDS, times.size))},
    )


@pytest.mark.parametrize("period", [30.0, 45.0])
def test_fit_spin_recovers_truth(sc, period):
    # A cube has isotropic inertia: a spin about a generic body axis is torque-free and
    # breaks the cube's symmetries (about a face normal the period would be ambiguous).
    axis_body = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
    truth = invert.axis_vector(40.0, 25.0)
    times = np.linspace(0.0, 2 * period, 100)  # two rotations
    s_in = np.array([1.0, 0.0, 0.0])
    # the observer moves 30 -> 50 deg in azimuth and 0 -> 15 deg in elevation: with fixed
    # directions the mirror pole would give the same light curve (a mirror-symmetric body)
    az, el = (
        np.radians(np.linspace(30.0, 50.0, times.size)),
        np.radians(np.linspace(0.0, 15.0, times.size)),
    )
    o_in = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=-1)
    lc = _spin_curve(sc, axis_body, truth, period, 50.0, times, s_in, o_in, 0.02, 7)
    # period step 0.5 %: over two rotations the phase slips 3.6 degree per step (< 10 deg)
    periods = period * np.linspace(0.95, 1.05, 21)
    r = invert.fit_spin(
        lc,
        sc,
        to_sun=s_in,
        to_observer=o_in,
        periods=periods,
        axis_body=axis_body,
        n_axes=200,
        n_phases=36,
    )
    assert invert.axis_separation(r["axis_vector"].values, truth) < 5.0
    assert abs(float(r["period"]) / period - 1) < 0.005
    assert 0.5 < float(r["reduced_chi2"]) < 2.0
    assert r.sizes["axis"] == 200 and np.isfinite(r["chi2_map"]).all()
    assert set(r["solution"].values) == {"antipode", "mirror", "half_period", "double_period"}
    assert float(r["chi2_gap"].sel(solution="half_period")) > 0
    assert float(r["chi2_gap"].sel(solution="mirror")) > -1e-6


def test_fixed_geometry_mirror_ambiguity(sc):
    """With fixed directions the mirror pole -M n fits as well as the truth (zero gap)."""
    axis_body = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
    truth = invert.axis_vector(40.0, 25.0)
    s_in, o_in = np.array([1.0, 0.0, 0.0]), np.array([np.cos(0.7), np.sin(0.7), 0.0])
    times = np.linspace(0.0, 60.0, 80)
    lc = _spin_curve(sc, axis_body, truth, 30.0, 50.0, times, s_in, o_in, 0.02, 2)
    r = invert.fit_spin(
        lc,
        sc,
        to_sun=s_in,
        to_observer=o_in,
        periods=30.0 * np.linspace(0.97, 1.03, 7),
        axis_body=axis_body,
        n_axes=200,
        n_phases=36,
    )
    both = [
        r["axis_vector"].values,
        invert.axis_vector(
            float(r["solution_axis_longitude"].sel(solution="mirror")),
            float(r["solution_axis_latitude"].sel(solution="mirror")),
        ),
    ]
    assert min(invert.axis_separation(v, truth) for v in both) < 5.0
    assert abs(float(r["chi2_gap"].sel(solution="mirror"))) < 1e-3 * float(r["chi2"])


def test_search_paths_agree(sc):
    """The shift path (one spin-angle grid per axis) equals the direct kernel path."""
    axis_body = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
    s_in, o_in = np.array([1.0, 0, 0]), np.array([0.0, 1.0, 0])
    times = np.linspace(0.0, 60.0, 40)
    lc = _spin_curve(
        sc, axis_body, invert.axis_vector(10.0, 60.0), 30.0, 0.0, times, s_in, o_in, 0.02, 1
    )
    prob = _spin_search.Problem(
        invert.light_curve_fluxes(lc), _spin_search.Kernel(sc, BANDS), s_in, o_in, axis_body, "band"
    )
    axes, periods, phases = (
        invert.fibonacci_sphere(5),
        np.array([29.0, 30.0]),
        np.array([0.0, 90.0]),
    )
    a = _spin_search.search(prob, axes, periods, phases, 1)
    b = _spin_search.search_shift(prob, axes, periods, phases, 1, n_angles=7200)
    # 0.05 degree angle grid with linear interpolation: chi-square within 2 %
    np.testing.assert_allclose(b, a, rtol=0.02)


def test_fit_spin_bad_input(sc):
    # five values, one band: four spin parameters and one scale leave no degree of freedom
    lc = xr.Dataset(
        {"flux": ("obs", np.ones(5)), "flux_uncertainty": ("obs", np.zeros(5))},
        coords={"time": ("obs", np.arange(5.0)), "band": ("obs", ["V"] * 5)},
    )
    with pytest.raises(InversionError, match="uncertainties"):
        invert.fit_spin(lc, sc, to_sun=[1, 0, 0], to_observer=[0, 1, 0], periods=[10.0])
    lc["flux_uncertainty"] = lc["flux"] * 0.1
    with pytest.raises(InversionError, match="parameters"):
        invert.fit_spin(lc, sc, to_sun=[1, 0, 0], to_observer=[0, 1, 0], periods=[10.0])


def test_cli_unmix_spectrum_and_bands(per_material, tmp_path, capsys):
    import pandas as pd

    from sbrdf_xr.cli import main
    from sbrdf_xr.photometry import sun_magnitudes
    from sbrdf_xr.store import write

    cube = xr.Dataset({"signal_material": per_material})
    write(cube, tmp_path / "cube.nc")
    truth = per_material.isel(geometry=0).sum("material")
    y, sigma = _noisy(truth, 0.01, 9)
    pd.DataFrame(
        {"wavelength": truth.wavelength.values, "signal": y.values, "uncertainty": sigma.values}
    ).to_csv(tmp_path / "spec.csv", index=False)
    out = tmp_path / "unmix.nc"
    assert (
        main(
            [
                "invert",
                "unmix",
                str(tmp_path / "spec.csv"),
                "--cube",
                str(tmp_path / "cube.nc"),
                "--isel",
                "geometry=0",
                "--select",
                "none",
                "-o",
                str(out),
            ]
        )
        == 0
    )
    text = capsys.readouterr().out
    assert "white-paint-a276" in text and out.exists()
    r = xr.open_dataset(out)
    np.testing.assert_allclose(r["scale"].values, 1.0, atol=4 * r["scale_uncertainty"].values.max())
    # band magnitudes of all four geometries' total at 1000 km, as a light-curve file
    sb = invert.band_terms(per_material.isel(geometry=0), BANDS).sum("material")
    mags = sun_magnitudes(list(BANDS)).values - 2.5 * np.log10(sb.values / 1e6**2)
    pd.DataFrame({"time": [0.0] * 3, "band": BANDS, "magnitude": mags, "uncertainty": 0.01}).to_csv(
        tmp_path / "mags.csv", index=False
    )
    assert (
        main(
            [
                "invert",
                "unmix",
                str(tmp_path / "mags.csv"),
                "--cube",
                str(tmp_path / "cube.nc"),
                "--isel",
                "geometry=0",
                "--range-km",
                "1000",
                "--select",
                "greedy",
            ]
        )
        == 0
    )
    assert "chi2" in capsys.readouterr().out
    # no range for magnitudes: a named error, exit status 2
    assert (
        main(
            [
                "invert",
                "unmix",
                str(tmp_path / "mags.csv"),
                "--cube",
                str(tmp_path / "cube.nc"),
                "--isel",
                "geometry=0",
            ]
        )
        == 2
    )
    assert "--range-km" in capsys.readouterr().err


def test_cli_spin(sc, tmp_path, capsys):
    import pandas as pd

    from sbrdf_xr.cli import main

    axis_body = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
    times = np.linspace(0.0, 60.0, 90)
    lc = _spin_curve(
        sc,
        axis_body,
        invert.axis_vector(40.0, 25.0),
        30.0,
        50.0,
        times,
        np.array([1.0, 0, 0]),
        np.array([np.cos(0.7), np.sin(0.7), 0.0]),
        0.02,
        3,
    )
    f = lc["flux"].values
    pd.DataFrame(
        {
            "time": lc.time.values,
            "band": lc.band.values,
            "magnitude": -2.5 * np.log10(f),
            "uncertainty": 0.02 / _spin_search.LN10_2P5,
        }
    ).to_csv(tmp_path / "lc.csv", index=False)
    out = tmp_path / "spin.nc"
    assert (
        main(
            [
                "invert",
                "spin",
                str(tmp_path / "lc.csv"),
                "--to-sun",
                "1",
                "0",
                "0",
                "--to-observer",
                str(np.cos(0.7)),
                str(np.sin(0.7)),
                "0",
                "--periods",
                "28.5",
                "31.5",
                "21",
                "--axis-body",
                "1",
                "2",
                "3",
                "--n-axes",
                "200",
                "-o",
                str(out),
            ]
        )
        == 0
    )
    assert "period" in capsys.readouterr().out
    r = xr.open_dataset(out)
    assert abs(float(r["period"]) - 30.0) < 0.15  # 0.5 %
