"""Every figure can be read: the package's figure functions and the documentation's scripts.

Each figure is drawn and held to :func:`sbrdf_xr.plot.figure_problems`: no text (title,
axis label, tick label, annotation, legend as a whole) overlaps another by more than a
pixel, none reaches outside the figure, and every axis that shows tick labels has a label
with its unit in brackets, or a label unitless by design (a ratio ``a / b``, a count
``number of ...``; :data:`sbrdf_xr.plot.UNIT_RULE`).  The notebooks' figures are held to
the same check in ``tests/test_notebooks.py``.
"""

from __future__ import annotations

import importlib.util
import struct
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest
import xarray as xr

from sbrdf_xr import photometry, plot, testing
from sbrdf_xr.body.spacecraft import canx1
from sbrdf_xr.cli import main
from sbrdf_xr.materials.schema import lambertian

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"


def _docs_script(name: str):
    spec = importlib.util.spec_from_file_location(f"docs_{name}", DOCS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _geometry_cube():
    """30 spectra over a geometry dimension: more than a figure should draw."""
    rng = np.random.default_rng(3)
    wl = np.arange(400.0, 1101.0, 20.0)
    sig = rng.uniform(0.5, 2.0, (30, 1)) * (1.0 + 5e-4 * (wl - 400.0))
    sig[:4] = 0.0  # four geometries where nothing is lit and seen
    return xr.Dataset(
        {
            "spacecraft_sbrdf": (("geometry", "wavelength"), sig / 0.01, {"units": "sr-1"}),
            "signal": (("geometry", "wavelength"), sig, {"units": "m2 sr-1"}),
        },
        coords={"geometry": np.arange(30), "wavelength": ("wavelength", wl, {"units": "nm"})},
    )


def _band_only_cube():
    cube = testing.rotation_cube(n_attitudes=1)
    sb = photometry.band_signal(cube, ["V", "R"]).drop_vars("sun_magnitude")
    return xr.Dataset({"band_signal": sb.isel(attitude=0)}, attrs={"scene": "bands"})


def _bench_rows():
    return _docs_script("accuracy_front").read_table()


def _photometry_of_rotation():
    return photometry.photometry(testing.rotation_cube(), ["V", "R", "I"], 1000.0).isel(
        phase_angle=0
    )


FIGURES = {
    "light_curve": lambda: plot.light_curve(
        testing.rotation_cube(phase_angles=(5.0, 10.0, 30.0, 60.0, 90.0, 120.0))
    ),
    "spectra of a rotation": lambda: plot.spectrum_curves(testing.rotation_cube(), attitude=0),
    "spectra of a pass": lambda: plot.spectrum_curves(testing.pass_cube(), "signal"),
    "lut_slice broadband": lambda: plot.lut_slice(lambertian(0.5, [500.0, 600.0]), 30.0),
    "lut_slice at 550 nm": lambda: plot.lut_slice(lambertian(0.5, [500.0, 600.0]), 30.0, 550.0),
    "magnitudes": lambda: plot.magnitude_curves(
        plot.cube_magnitudes(testing.rotation_cube()), phase_angle=10.0
    ),
    "colour_colour": lambda: plot.colour_colour(_photometry_of_rotation(), "V-R", "R-I"),
    "cube_figure of a rotation": lambda: plot.cube_figure(
        testing.rotation_cube(phase_angles=(10.0, 40.0))
    ),
    "cube_figure of a pass": lambda: plot.cube_figure(testing.pass_cube()),
    "cube_figure of spectra": lambda: plot.cube_figure(_geometry_cube()),
    "cube_figure of band signals": lambda: plot.cube_figure(_band_only_cube()),
    "accuracy_front": lambda: plot.accuracy_front(_bench_rows()),
    "the canx1 model": lambda: canx1().plot(),
}


@pytest.mark.parametrize("name", FIGURES)
def test_package_figures_can_be_read(name):
    fig = FIGURES[name]()
    try:
        assert plot.figure_problems(fig) == []
    finally:
        plt.close(fig)


#: The documentation's figure scripts; those that take over 10 s warm are slow.
SCRIPTS = {
    "accuracy_front": [],
    "gallery": [],
    "observation": [],
    "comparison": [],
    "imperfections": [pytest.mark.slow],
    "anisotropy": [pytest.mark.slow],
    "starlink": [],
}


@pytest.mark.parametrize("script", [pytest.param(s, marks=m, id=s) for s, m in SCRIPTS.items()])
def test_documentation_figures_can_be_read(script):
    figures = _docs_script(script).figures()
    try:
        problems = {name: plot.figure_problems(fig) for name, fig in figures.items()}
        assert problems == {name: [] for name in figures}
        assert all((DOCS / "img" / name).is_file() for name in figures)  # the guide shows them
    finally:
        for fig in figures.values():
            plt.close(fig)


#: Which script draws each image of docs/img (checked by the test above).
IMAGES = {
    "accuracy_front.png": "accuracy_front",
    "brushed_panel.png": "anisotropy",
    "canx1_colour_colour.png": "gallery",
    "canx1_imperfections.png": "imperfections",
    "canx1_model.png": "gallery",
    "canx1_off_specular.png": "gallery",
    "canx1_pass.png": "observation",
    "canx1_pass_comparison.png": "comparison",
    "canx1_plusx_spectra.png": "gallery",
    "canx1_rotation.png": "gallery",
    "starlink_pass.png": "starlink",
}


def test_every_documentation_image_has_its_script():
    assert sorted(p.name for p in (DOCS / "img").glob("*.png")) == sorted(IMAGES)
    for image, script in IMAGES.items():
        assert f'"{image}"' in (DOCS / f"{script}.py").read_text(encoding="utf-8")


# ------------------------------------------------------------------ the check itself


def test_the_check_finds_overlaps_cut_off_text_and_missing_units():
    fig, ax = plt.subplots(figsize=(3, 2))
    ax.plot([0, 1], [0, 1])
    ax.set_xlabel("wavelength")  # no unit
    ax.set_ylabel("albedo [1]")
    ax.text(0.5, 0.5, "one label")
    ax.text(0.5, 0.5, "another")  # on top of it
    ax.set_title("a title far too long to fit in a figure three inches wide, so it is cut")
    ax.legend(["a curve"], loc="center")  # the legend box covers the two texts
    problems = plot.figure_problems(fig)
    plt.close(fig)
    assert "text 'one label' overlaps text 'another'" in problems
    assert "legend 'a curve' overlaps text 'one label'" in problems
    assert any("title of axes 0" in p and "outside the figure" in p for p in problems)
    assert "x axis of axes 0: label 'wavelength' has no unit in brackets" in problems
    assert not any("y axis" in p for p in problems)


def test_crowded_tick_labels_are_found():
    fig, ax = plt.subplots(figsize=(2, 2), layout="constrained")
    ax.plot(np.arange(30), np.arange(30))
    ax.set_xticks(np.arange(30), [f"label {k}" for k in range(30)])
    ax.set(xlabel="index [1]", ylabel="value [1]")
    problems = plot.figure_problems(fig)
    plt.close(fig)
    assert any("x tick label" in p and "overlaps x tick label" in p for p in problems)


def test_shared_axes_need_labels_only_where_ticks_show():
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, layout="constrained")
    for ax in (top, bottom):
        ax.plot([0, 1], [0, 1])
        ax.set_ylabel("value [1]")
    bottom.set_xlabel("time [s]")
    assert plot.figure_problems(fig) == []  # the top panel shows no x tick labels
    bottom.set_xlabel("")
    assert plot.figure_problems(fig) == ["x axis of axes 1: no label"]
    plt.close(fig)


# ------------------------------------------------------------------ the dispatch


def test_cube_kinds():
    assert plot.cube_kind(testing.pass_cube()) == "observation"
    assert plot.cube_kind(testing.rotation_cube()) == "rotation"
    assert plot.cube_kind(_geometry_cube()) == "spectra"
    assert plot.cube_kind(testing.rotation_cube(n_attitudes=1)) == "spectra"
    assert plot.cube_kind(_band_only_cube()) == "bands"
    with pytest.raises(ValueError, match="nothing to draw"):
        plot.cube_kind(xr.Dataset({"area": ("x", [1.0])}))


def test_the_observation_figure_marks_the_shadow():
    fig = plot.cube_figure(testing.pass_cube())
    mags, colours, geo = fig.axes[:3]
    assert mags.yaxis_inverted() and mags.get_xlabel() == ""
    assert geo.get_xlabel() == "time [UTC] on 2024-03-17"
    names = [t.get_text() for t in geo.get_legend().get_texts()]
    assert "umbra exit 01:20:20.000" in names and "penumbra exit 01:20:30.000" in names
    assert {"phase angle", "elevation", "umbra (no sunlight)", "penumbra"} <= set(names)
    edges = [line for line in mags.get_lines() if line.get_linestyle() == "--"]
    assert len(edges) == 2  # both edges drawn across the magnitudes too
    assert [t.get_text() for t in colours.get_legend().get_texts()][:2] == ["V-R", "R-I"]
    plt.close(fig)


def test_spectra_are_few_and_named():
    cube = _geometry_cube()
    fig = plot.spectrum_curves(cube, max_lines=5)
    legend = fig.axes[0].get_legend()
    assert len(fig.axes[0].lines) == 5
    assert legend.get_title().get_text().startswith("5 of 30 spectra, ranked by mean")
    assert "(4 dark" in legend.get_title().get_text()
    labels = [t.get_text() for t in legend.get_texts()]
    assert labels[0].startswith("brightest: geometry ")
    assert labels[-1].startswith("faintest lit: geometry ")
    brightest = int(labels[0].split()[-1])
    means = cube.spacecraft_sbrdf.mean("wavelength").values
    assert brightest == int(np.argmax(means))
    plt.close(fig)


def _png_size(path: Path) -> tuple[int, int]:
    width, height = struct.unpack(">II", path.read_bytes()[16:24])
    return width, height


@pytest.mark.parametrize(
    ("cube", "size"),
    [  # the figure sizes (inches) of the three kinds, at the command's 120 dpi
        (testing.pass_cube, (10, 8)),
        (testing.rotation_cube, (9, 7.4)),
        (_geometry_cube, (10, 4)),
    ],
    ids=["observation", "rotation", "spectra"],
)
def test_the_plot_command_draws_the_cube_s_figure(cube, size, tmp_path, capsys):
    path = tmp_path / "cube.nc"
    cube().to_netcdf(path)
    out = tmp_path / "fig.png"
    assert main(["plot", str(path), "-o", str(out)]) == 0
    assert _png_size(out) == (round(size[0] * 120), round(size[1] * 120))
    assert f"wrote {out}" in capsys.readouterr().out
