"""Tests of sbrdf_xr.materials.model_schema: model materials, their declared metadata and files."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from sbrdf_xr.brdf import optics
from sbrdf_xr.errors import ValidationError
from sbrdf_xr.materials import model_schema as schema
from sbrdf_xr.materials.models import spectra

WL = np.linspace(400.0, 1100.0, 15)


def paint(**kw):
    p = {"rho_D": 0.8, "epsilon": 0.12, "b": 0.1, "e": 0.35} | kw
    return schema.model_material("robertson_sandford", WL, material="p", provenance="test", **p)


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"b": -0.1}, "b"),
        ({"e": 0.0}, "e"),
        ({"rho_D": 0.95}, "rho_D \\+ epsilon"),
        ({"rho_D": -np.ones(15)}, "rho_D"),
    ],
)
def test_parameters_out_of_domain(kw, match):
    with pytest.raises(ValidationError, match=match):
        paint(**kw)


def test_layers_only_for_microfacet_and_round_trip(tmp_path):
    with pytest.raises(ValidationError, match="only the microfacet"):
        schema.model_material(
            "lambert", WL, material="x", provenance="t", layers=[(1.5, 100.0)], rho=0.5
        )
    al = optics.aluminium_index(WL)
    spec = schema.model_material(
        "microfacet",
        WL,
        material="c",
        provenance="t",
        layers=[(optics.silica_index(WL), 120.0)],
        roughness=0.1,
        n=al.real,
        k=al.imag,
        rho_d=0.01,
    )
    path = schema.to_netcdf(spec, tmp_path / "m.nc")
    back = schema.open_model(path)
    # the writer adds the file-level ACDD attributes title and history (CF/ACDD basics)
    assert back.attrs.pop("title") and back.attrs.pop("history")
    xr.testing.assert_identical(back, spec)
    np.testing.assert_allclose(spectra(back, 30.0, 0.0, 0.0), spectra(spec, 30.0, 0.0, 0.0))


def test_unknown_model_name():
    with pytest.raises(ValidationError, match="valid model names"):
        schema.model_material("phong", WL, material="x", provenance="t")


def test_model_parameters_checks_the_material_against_its_model():
    spec = paint()
    m, wl, kw = schema.model_parameters(spec)
    assert m.name == "robertson_sandford" and list(kw) == list(m.param_names)
    np.testing.assert_array_equal(wl, WL)
    with pytest.raises(ValidationError, match=r"missing \['e'\]"):
        schema.model_parameters(spec.drop_vars("e"))
    with pytest.raises(ValidationError, match="no thin-film stack"):
        schema.model_parameters(
            spec.assign(layer_n=(("layer", "wavelength"), np.ones((1, WL.size))))
            .assign(layer_k=(("layer", "wavelength"), np.zeros((1, WL.size))))
            .assign(layer_thickness=("layer", [100.0]))
        )
    with pytest.raises(ValidationError, match="'model' attribute"):
        schema.model_parameters(spec.rho_D)
