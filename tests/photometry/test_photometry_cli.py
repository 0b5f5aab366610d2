"""The photometry and plot sub-commands of ``sbrdf-xr``."""

from __future__ import annotations

import numpy as np
import pytest

from sbrdf_xr import photometry as P
from sbrdf_xr import testing as T
from sbrdf_xr.cli import main
from sbrdf_xr.engine import Scene
from sbrdf_xr.engine.run import simulate
from sbrdf_xr.materials import models
from sbrdf_xr.materials.tables import write_netcdf_atomic


@pytest.fixture(scope="module")
def cube_path(tmp_path_factory):
    wl = np.arange(290.0, 1201.0, 10.0)
    spec = models.model_material("lambert", wl, rho=0.5, material="white", provenance="test")
    table = models.render(
        spec,
        theta_i=np.arange(0.0, 91.0, 15.0),
        delta_theta=np.arange(-180.0, 91.0, 30.0),
        phi=np.arange(0.0, 91.0, 15.0),
    )
    scene = Scene(
        T.cube_spacecraft(1.0),
        materials={T.TEST_SPACECRAFT_MATERIAL: table},
        to_sun=[[1.0, 0.0, 0.0], [0.6, 0.8, 0.0]],
        to_observer=[[1.0, 0.0, 0.0]] * 2,
    )
    cube = simulate(scene).compute()
    return write_netcdf_atomic(cube, tmp_path_factory.mktemp("cli") / "cube.nc"), cube


def test_defaults_are_v_r_i_and_a_missing_range_names_the_option(cube_path, capsys):
    path, _ = cube_path
    assert main(["photometry", str(path), "-q"]) == 2
    err = capsys.readouterr().err
    assert "records no observer range" in err and "--range-km" in err
    assert main(["photometry", str(path), "--range-km", "1000", "-q"]) == 0
    out = capsys.readouterr().out
    assert (
        "bessell-V" in out
        and "bessell-R" in out
        and "bessell-I" in out
        and "V-R" in out
        and "R-I" in out
    )


def test_colours_system_and_output(cube_path, tmp_path, capsys):
    path, cube = cube_path
    out = tmp_path / "phot.nc"
    assert (
        main(
            [
                "photometry",
                str(path),
                "--bands",
                "B",
                "V",
                "R",
                "--range-km",
                "1000",
                "--colours",
                "B-V,V-R,B-R",
                "--system",
                "VEGA",
                "-o",
                str(out),
                "-q",
            ]
        )
        == 0
    )
    text = capsys.readouterr().out
    assert "Vega magnitudes" in text and "B-R" in text
    ph = P.open_photometry(out)
    assert (
        ph.colour.values.tolist() == ["B-V", "V-R", "B-R"]
        and ph.attrs["magnitude_system"] == "Vega"
    )
    ref = P.photometry(
        cube, ["B", "V", "R"], 1000.0, system="vega", pairs=[("B", "V"), ("V", "R"), ("B", "R")]
    )
    np.testing.assert_allclose(ph.colour_index.values, ref.colour_index.values, rtol=1e-12)
    assert main(["photometry", str(path), "--range-km", "1000", "--colours", "VR", "-q"]) == 2
    assert "is not a band pair like V-R" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["photometry", str(path), "--system", "st"])
