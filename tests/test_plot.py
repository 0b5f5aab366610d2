"""Figures.

Short labels with units, log axes for large ranges, magnitudes, colour-colour, accessor.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest
import xarray as xr

from sbrdf_xr import photometry as P
from sbrdf_xr import plot
from sbrdf_xr import testing as T
from sbrdf_xr.cli import main
from sbrdf_xr.engine import Scene
from sbrdf_xr.engine.run import simulate
from sbrdf_xr.materials import models
from sbrdf_xr.materials.tables import write_netcdf_atomic

MAX_LABEL = 40  # characters: an axis label that fits a 4-inch axis at the default font size


@pytest.fixture(scope="module")
def sweep():
    """A rotating grey cube over 400-1100 nm at two phase angles (glints: a 100x range)."""
    from sbrdf_xr import geometry

    wl = np.arange(400.0, 1101.0, 10.0)
    spec = models.model_material("lambert", wl, rho=0.5, material="grey", provenance="test")
    table = models.render(
        spec,
        theta_i=np.arange(0.0, 91.0, 15.0),
        delta_theta=np.arange(-180.0, 91.0, 30.0),
        phi=np.arange(0.0, 91.0, 15.0),
    )
    scene = Scene(
        T.cube_spacecraft(1.0),
        materials={T.TEST_SPACECRAFT_MATERIAL: table},
        attitudes=geometry.axis_rotation([0, 0, 1], np.arange(0.0, 360.0, 10.0)),
        attitude_angle=np.arange(0.0, 360.0, 10.0),
        phase_angles=[10.0, 60.0],
    )
    return simulate(scene).compute()


def _labels(fig):
    ax = fig.axes[0]
    return ax.get_xlabel(), ax.get_ylabel()


def test_cube_figures_have_short_labels_with_units(sweep):
    for fig in (
        plot.light_curve(sweep),
        plot.spectrum_curves(sweep, "signal", attitude=0),
    ):
        for text in _labels(fig):
            assert 0 < len(text) <= MAX_LABEL and "[" in text, text
        legend = fig.axes[0].get_legend()
        if legend is not None:
            assert all("deg" in t.get_text() for t in legend.get_texts())
    fig = plot.cube_figure(sweep)  # the rotation's BRDF and magnitudes
    assert [ax.get_ylabel() for ax in fig.axes] == [
        "broadband BRDF [sr-1 nm]",
        "magnitude at 1000 km [AB mag]",
    ]
    assert plot.figure_problems(fig) == []


def test_log_axis_where_the_range_is_large():
    ds = xr.Dataset(
        {
            "brdf": (
                ("attitude", "phase_angle"),
                np.array([[1.0], [200.0], [3.0]]),
                {"units": "sr-1 nm", "long_name": "x"},
            )
        },
        coords={
            "attitude_angle": ("attitude", [0.0, 10.0, 20.0], {"units": "degree"}),
            "phase_angle": ("phase_angle", [5.0], {"units": "degree"}),
        },
    )
    assert plot.light_curve(ds).axes[0].get_yscale() == "log"
    flat = ds.copy()
    flat["brdf"] = flat.brdf.copy(data=np.array([[1.0], [2.0], [3.0]]))
    assert plot.light_curve(flat).axes[0].get_yscale() == "linear"
    assert plot.light_curve(flat, log=True).axes[0].get_yscale() == "log"


def test_magnitudes_per_band_brighter_up_and_the_accessor(sweep):
    mags = P.magnitudes(sweep, ["V", "R", "I"], 1000.0, system="vega")
    fig = plot.magnitude_curves(mags, phase_angle=10.0)
    ax = fig.axes[0]
    assert ax.yaxis_inverted() and [t.get_text() for t in ax.get_legend().get_texts()] == [
        "V",
        "R",
        "I",
    ]
    assert ax.get_ylabel() == "magnitude at 1000 km [Vega mag]"
    with pytest.raises(ValueError, match="select the others"):
        plot.magnitude_curves(mags)
    f2 = mags.sbrdf.plot(phase_angle=10.0)
    assert f2.axes[0].yaxis_inverted()
    assert sweep.sbrdf.plot().axes[0].get_yscale() in ("log", "linear")
    assert sweep.sbrdf.plot.light_curve().axes[0].get_legend() is not None
    with pytest.raises(AttributeError, match="available"):
        sweep.sbrdf.plot.nothing


def test_colour_colour_marks_the_sun(sweep):
    ph = P.photometry(sweep, ["V", "R", "I"], 1000.0, system="vega").isel(phase_angle=0)
    fig = ph.sbrdf.plot.colour_colour("V-R", "R-I")
    ax = fig.axes[0]
    assert ax.get_xlabel() == "V-R [Vega mag]" and ax.get_ylabel() == "R-I [Vega mag]"
    sun = next(line for line in ax.get_lines() if line.get_label().startswith("the Sun"))
    sm = P.sun_magnitudes(["V", "R", "I"], system="vega").values
    assert sun.get_xdata()[0] == pytest.approx(sm[0] - sm[1]) and sun.get_ydata()[
        0
    ] == pytest.approx(sm[1] - sm[2])
    # a grey body has the Sun's colours: every point sits on the star
    ci = ph.colour_index
    finite = np.isfinite(ci.sel(colour="V-R").values)
    np.testing.assert_allclose(ci.sel(colour="V-R").values[finite], sm[0] - sm[1], atol=1e-9)
    with pytest.raises(ValueError, match="not in"):
        plot.colour_colour(ph, "B-V", "V-R")


def test_cli_plot_draws_the_log_light_curve(sweep, tmp_path, capsys):
    cube = write_netcdf_atomic(sweep, tmp_path / "cube.nc")
    out = tmp_path / "fig.png"
    assert main(["plot", str(cube), "-o", str(out)]) == 0
    assert out.stat().st_size > 10_000 and f"wrote {out}" in capsys.readouterr().out
