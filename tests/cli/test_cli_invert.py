"""``sbrdf-xr invert``: the material areas and the spin state from measured files, and a
named error (exit status 2, one line naming the flag or file) for every bad input."""

from __future__ import annotations

import itertools
import re
import time
import warnings

import numpy as np
import pandas as pd
import pytest
import trimesh
import xarray as xr

from sbrdf_xr import Scene, geometry, invert, simulate, write
from sbrdf_xr.cli import main
from sbrdf_xr.errors import FitQualityWarning
from sbrdf_xr.observing import Observation, Orbit, Site
from sbrdf_xr.observing.timescales import times as utc_times
from sbrdf_xr.photometry import sun_magnitudes

BANDS = ("V", "R", "I")


@pytest.fixture(scope="module")
def unmix_files(tmp_path_factory):
    """A two-material box (grey sides, red caps) at three geometries, its per-material cube,
    and a measured spectrum of the first geometry (1 % noise)."""
    from sbrdf_xr import load_spacecraft
    from sbrdf_xr.materials.schema import lambertian

    tmp = tmp_path_factory.mktemp("unmix")
    mesh = trimesh.creation.box()
    caps = np.abs(mesh.face_normals[:, 2]) > 0.5
    mesh.visual.face_colors = np.where(caps[:, None], [255, 0, 0, 255], [128, 128, 128, 255])
    box = load_spacecraft(mesh, {(255, 0, 0): "red", (128, 128, 128): "grey"})
    wl = np.linspace(400.0, 1000.0, 31)
    tables = {
        "grey": lambertian(0.5, wl, material="grey"),
        "red": lambertian(np.linspace(0.1, 0.8, 31), wl, material="red"),
    }
    sun = [[0.6, 0.0, 0.8], [0.8, 0.0, 0.6], [0.0, 0.6, 0.8]]
    obs = [[0.8, 0.0, 0.6], [0.0, 0.6, 0.8], [0.6, 0.0, 0.8]]
    cube = simulate(
        Scene(box, tables, to_sun=sun, to_observer=obs, outputs=("signal", "per_material"))
    )
    write(cube, tmp / "cube.nc")
    mesh.export(tmp / "box.ply")
    (tmp / "map.toml").write_text(
        '[[material]]\nname = "red"\nrgb = [255, 0, 0]\n'
        '[[material]]\nname = "grey"\nrgb = [128, 128, 128]\n'
    )
    truth = cube.signal_material.isel(geometry=0).sum("material")
    sigma = 0.01 * truth
    y = truth + sigma * np.random.default_rng(0).normal(size=truth.shape)
    frame = pd.DataFrame({"wavelength": wl, "signal": y.values, "uncertainty": sigma.values})
    frame.to_csv(tmp / "spec.csv", index=False)
    return {
        "dir": tmp,
        "cube": tmp / "cube.nc",
        "spec": tmp / "spec.csv",
        "frame": frame,
        "terms": cube.signal_material,
    }


def _unmix(files, measured, *extra):
    return main(["invert", "unmix", str(measured), "--cube", str(files["cube"]), *extra])


def test_unmix_spectrum_and_band_magnitudes(unmix_files, capsys, tmp_path):
    out = tmp_path / "unmix.nc"
    assert _unmix(unmix_files, unmix_files["spec"], "--isel", "geometry=0", "-o", str(out)) == 0
    text = capsys.readouterr().out
    assert "grey" in text and "selection:" in text and out.exists()
    r = xr.open_dataset(out)
    np.testing.assert_allclose(r["scale"].values, 1.0, atol=4 * r["scale_uncertainty"].values.max())
    # band magnitudes of the first geometry at 1000 km, as a light-curve file
    sb = invert.band_terms(unmix_files["terms"].isel(geometry=0), BANDS).sum("material")
    mags = sun_magnitudes(list(BANDS)).values - 2.5 * np.log10(sb.values / 1e6**2)
    mags = mags + np.array([0.004, -0.006, 0.002])  # noise of 0.01 mag, drawn once
    pd.DataFrame({"time": [0.0] * 3, "band": BANDS, "magnitude": mags, "uncertainty": 0.01}).to_csv(
        tmp_path / "mags.csv", index=False
    )
    argv = ["--isel", "geometry=0", "--range-km", "1000", "--select", "greedy"]
    assert _unmix(unmix_files, tmp_path / "mags.csv", *argv) == 0
    assert "chi2" in capsys.readouterr().out
    assert _unmix(unmix_files, tmp_path / "mags.csv", "--isel", "geometry=0") == 2
    assert "--range-km" in capsys.readouterr().err


def test_unmix_with_the_spacecraft_s_areas_adding_up(unmix_files, capsys, tmp_path):
    """--spacecraft gives each material's area; --total-area makes the fitted areas add up
    to the body's (6 m2): the same fit as invert.unmix(total_area=True) on the same data."""
    body = ["--spacecraft", str(unmix_files["dir"] / "box.ply")]
    body += ["--material-map", str(unmix_files["dir"] / "map.toml")]
    out = tmp_path / "unmix.nc"
    argv = ["--isel", "geometry=0", "--total-area", "-o", str(out), *body]
    assert _unmix(unmix_files, unmix_files["spec"], *argv) == 0
    r = xr.open_dataset(out)
    np.testing.assert_allclose(float(r["area"].sum()), 6.0, rtol=1e-12)
    np.testing.assert_allclose(float(r["area_fraction"].sum()), 1.0, rtol=1e-12)
    f = unmix_files["frame"]
    wl = {"wavelength": f.wavelength.values}
    direct = invert.unmix(
        xr.DataArray(f.signal.values, dims="wavelength", coords=wl),
        unmix_files["terms"].isel(geometry=0),
        xr.DataArray(f.uncertainty.values, dims="wavelength", coords=wl),
        areas={"grey": 4.0, "red": 2.0},
        total_area=True,
        select="all",
    )
    np.testing.assert_allclose(r["scale"].values, direct["scale"].values, rtol=1e-10)
    assert _unmix(unmix_files, unmix_files["spec"], "--isel", "geometry=0", "--total-area") == 2
    assert "--total-area: needs --spacecraft" in capsys.readouterr().err


def _spectrum(tmp_path, text):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        (["--isel", "attitude=999"], r"--isel 'attitude=999': .* has no sample dimension"),
        (
            ["--isel", "geometry=999"],
            r"--isel 'geometry=999': index 999 is out of range; "
            r"geometry of .* has 3 entries \(0..2\)",
        ),
        (["--isel", "geometry"], r"--isel 'geometry': expected DIM=INDEX"),
        (["--isel", "geometry=one"], r"the index 'one' is not an integer \(0..2\)"),
        ([], r"simulated has dimensions \['geometry'\] that measured lacks.*--isel"),
    ],
)
def test_unmix_bad_isel(unmix_files, capsys, argv, match):
    assert _unmix(unmix_files, unmix_files["spec"], *argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("sbrdf-xr: error: ") and err.count("\n") == 1
    assert re.search(match, err), err


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("", r"bad.csv: empty; expected a spectrum"),
        ("wavelength,signal,uncertainty\n", r"bad.csv: no rows"),
        (
            "wavelength,signal,uncertainty\n500,abc,0.1\n",
            r"column signal has 1 values that are "
            r"not numbers \(data rows 1\)",
        ),
        (
            "wavelength,signal,uncertainty\n500,0.1,0.01\n600,nan,0.01\n",
            r"column signal has NaN or infinite values in data rows 2",
        ),
        (
            "wavelength,signal,uncertainty\n500,0.1,0.01\n600,0.1,-0.01\n",
            r"uncertainty must be finite and > 0; data rows 2 are not \(e.g. -0.01\)",
        ),
        (
            "wavelength,signal,uncertainty\n500,0.1,0.01\n500,0.1,0.01\n",
            r"wavelengths \[500.0\] appear more than once",
        ),
        ("wavelength,signal\n500,0.1\n", r"missing columns \['uncertainty'\]"),
        (
            "wavelength,signal,uncertainty\n500,0.1,0.01\n",
            r"measured: 1 values for 2 material parameters",
        ),
        ("colour,value\nred,1\n", r"neither a spectrum .* nor band magnitudes"),
    ],
    ids=[
        "empty",
        "header-only",
        "not-a-number",
        "nan-row",
        "negative-uncertainty",
        "repeated-wavelength",
        "missing-column",
        "fewer-values-than-parameters",
        "unknown-table",
    ],
)
def test_unmix_bad_spectrum_files(unmix_files, tmp_path, capsys, text, match):
    assert _unmix(unmix_files, _spectrum(tmp_path, text), "--isel", "geometry=0") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and re.search(match, err), err


def test_unmix_not_a_file(unmix_files, tmp_path, capsys):
    assert _unmix(unmix_files, tmp_path, "--isel", "geometry=0") == 2
    assert "is not a regular file" in capsys.readouterr().err
    assert _unmix(unmix_files, tmp_path / "none.csv", "--isel", "geometry=0") == 2
    assert "does not exist" in capsys.readouterr().err


@pytest.fixture(scope="module")
def spin_files(tmp_path_factory):
    """A 1 x 2 x 3 m grey box spinning about its long axis with a 20 s period over 60 s of
    a real pass (every 2 s), its observation cube, and V, R, I magnitudes (1 % noise) in
    a light-curve CSV with UTC times."""
    tmp = tmp_path_factory.mktemp("spin")
    mesh = trimesh.creation.box(extents=(1.0, 2.0, 3.0))
    mesh.export(tmp / "box.stl")
    from sbrdf_xr import load_spacecraft

    box = load_spacecraft(mesh, material="lambertian-grey-50")
    axis = invert.axis_vector(60.0, 30.0)
    law = invert.spin_model([0, 0, 1], axis, period=20.0, phase=30.0)
    obs = Observation(
        Orbit.from_catalog("canx1-example"),
        Site.from_catalog("mont-megantic"),
        utc_times("2024-03-17T01:22:00", "2024-03-17T01:22:59", 2.0),
        law,
    )
    cube = simulate(Scene(box, observation=obs, outputs=("band_signal",), bands=BANDS))
    write(cube, tmp / "cube.nc")
    rng_km = cube["range"].values[:, None]
    mags = -2.5 * np.log10(cube["band_signal"].values / rng_km**2)
    mags = mags + 0.01 * np.random.default_rng(1).normal(size=mags.shape)
    iso = [str(t)[:23] + "Z" for t in cube.time.values]
    pd.DataFrame(
        {
            "time": np.repeat(iso, 3),
            "band": np.tile(BANDS, len(iso)),
            "magnitude": mags.ravel(),
            "uncertainty": 0.01,
        }
    ).to_csv(tmp / "lc.csv", index=False)
    return {
        "dir": tmp,
        "cube": tmp / "cube.nc",
        "lc": tmp / "lc.csv",
        "axis": axis,
        "body": ["--spacecraft", str(tmp / "box.stl"), "--mesh-material", "lambertian-grey-50"],
    }


def _spin(files, *extra):
    return main(["invert", "spin", str(files["lc"]), *files["body"], *extra])


def test_spin_from_a_cube(spin_files, capsys, tmp_path):
    out = tmp_path / "spin.nc"
    argv = [
        "--cube",
        str(spin_files["cube"]),
        "--periods",
        "16",
        "24",
        "17",
        "--n-axes",
        "60",
        "-o",
        str(out),
    ]
    # the box's symmetry leaves the antipode nearly as good (a chi2 gap of about 10): if the
    # gap falls below AMBIGUITY_CHI2 the fit says so, and says nothing else
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", FitQualityWarning)
        assert _spin(spin_files, *argv) == 0
    assert all("from its twins antipode" in str(w.message) for w in caught)
    text = capsys.readouterr().out
    assert "epoch 2024-03-17T01:22:00.000" in text and "alternative mirror" in text
    r = xr.open_dataset(out)
    assert abs(float(r["period"]) - 20.0) < 3 * float(r["period_uncertainty"])
    # a box about its long axis: the axis or its twin through the box's symmetry
    seps = [
        invert.axis_separation(r["axis_vector"].values, s * spin_files["axis"]) for s in (1, -1)
    ]
    assert min(seps) < 1.0


def test_spin_from_inertial_vectors(spin_files, capsys):
    """Fixed directions (the pass's geometry at its middle): a valid run; the misfit of a
    fixed geometry on a moving pass is named in a warning, not hidden."""
    g = xr.open_dataset(spin_files["cube"]).isel(time=15)
    rot = geometry.rotation_matrices(g.quaternion.values[None])[0]
    s, o = rot @ g.to_sun.values, rot @ g.to_observer.values
    argv = [
        "--to-sun",
        *map(str, s),
        "--to-observer",
        *map(str, o),
        "--periods",
        "18",
        "22",
        "9",
        "--n-axes",
        "40",
        "--n-phases",
        "8",
    ]
    with pytest.warns(FitQualityWarning) as rec:
        assert _spin(spin_files, *argv) == 0
    assert any(re.search("the geometry .* does not match", str(w.message)) for w in rec)
    assert "spin fit of" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        (["--n-axes", "0"], r"n_axes \(--n-axes\): 0; allowed an integer >= 1"),
        (["--n-phases", "0"], r"n_phases \(--n-phases\): 0; allowed an integer >= 1"),
        (
            ["--axis-body", "0", "0", "0"],
            r"axis_body \(--axis-body\): \[0.0, 0.0, 0.0\]; "
            r"allowed a finite nonzero",
        ),
        (
            ["--periods", "10", "20", "1e12"],
            r"spin search of 120 axes x 1e\+12 periods .* is "
            r"beyond reason: .*--size-limit",
        ),
        (["--periods", "20", "10", "5"], r"--periods 20 10 5: MIN and MAX must be finite"),
        (["--periods", "10", "20", "2.5"], r"--periods 10 20 2.5: N must be an integer >= 1"),
        (["--periods", "-1", "20", "5"], r"MIN and MAX must be finite with 0 < MIN <= MAX"),
        (["--size-limit", "0"], r"size_limit \(--size-limit\): 0.0; allowed a finite number"),
    ],
    ids=[
        "n-axes",
        "n-phases",
        "axis-body",
        "huge-periods",
        "periods-order",
        "periods-n",
        "periods-negative",
        "size-limit",
    ],
)
def test_spin_bad_flags(spin_files, capsys, argv, match):
    base = ["--cube", str(spin_files["cube"])]
    if "--periods" not in argv:
        base += ["--periods", "16", "24", "5"]
    t0 = time.perf_counter()
    assert _spin(spin_files, *base, *argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and re.search(match, err), err
    # refused before any search, let alone an allocation of the 1e12 periods
    assert time.perf_counter() - t0 < 120


def test_spin_geometry_given_once(spin_files, capsys):
    assert _spin(spin_files, "--periods", "16", "24", "5") == 2
    assert "give the geometry once" in capsys.readouterr().err
    argv = [
        "--cube",
        str(spin_files["cube"]),
        "--to-sun",
        "1",
        "0",
        "0",
        "--to-observer",
        "0",
        "1",
        "0",
        "--periods",
        "16",
        "24",
        "5",
    ]
    assert _spin(spin_files, *argv) == 2
    assert "got --cube, --to-sun" in capsys.readouterr().err
    assert _spin(spin_files, "--scene", "canx1-rotation", "--periods", "16", "24", "5") == 2
    assert "--scene canx1-rotation: the scene has no observation" in capsys.readouterr().err


def test_unmix_bad_cube_and_range(unmix_files, tmp_path, capsys):
    spec = str(unmix_files["spec"])
    assert main(["invert", "unmix", spec, "--cube", str(tmp_path / "none.nc")]) == 2
    assert "none.nc" in capsys.readouterr().err
    (tmp_path / "text.nc").write_text("not netCDF")
    assert main(["invert", "unmix", spec, "--cube", str(tmp_path / "text.nc")]) == 2
    assert "text.nc" in capsys.readouterr().err
    xr.Dataset({"signal": ("wavelength", [1.0])}).to_netcdf(tmp_path / "plain.nc")
    assert main(["invert", "unmix", spec, "--cube", str(tmp_path / "plain.nc")]) == 2
    assert "no signal_material; simulate with the per_material output" in capsys.readouterr().err
    sb = invert.band_terms(unmix_files["terms"].isel(geometry=0), BANDS).sum("material")
    mags = sun_magnitudes(list(BANDS)).values - 2.5 * np.log10(sb.values / 1e6**2)
    pd.DataFrame({"time": [0.0] * 3, "band": BANDS, "magnitude": mags, "uncertainty": 0.01}).to_csv(
        tmp_path / "mags.csv", index=False
    )
    for bad, measured in itertools.product(("-5", "nan", "0"), (tmp_path / "mags.csv", spec)):
        argv = ["--isel", "geometry=0", "--range-km", bad]
        assert _unmix(unmix_files, measured, *argv) == 2  # a spectrum ignored it before
        assert "--range-km: must be finite and > 0 km" in capsys.readouterr().err
