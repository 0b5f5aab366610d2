"""Tests of the BRDF model interface: a new model is one Model object and its registration."""

from __future__ import annotations

import dataclasses
import pickle

import cf_units
import numpy as np
import pytest

from sbrdf_xr import catalog, geometry
from sbrdf_xr import testing as T
from sbrdf_xr.brdf import (
    ANISOTROPIC_MODELS,
    BRDF_MODELS,
    MODELS,
    Model,
    Parameter,
    get_model,
    register_model,
    unregister_model,
)
from sbrdf_xr.errors import ValidationError
from sbrdf_xr.materials import models
from sbrdf_xr.materials import tables as material

WL = np.array([450.0, 650.0, 900.0])
RHO = np.array([0.2, 0.5, 0.9])
#: rho / pi is one float64 division; a look-up of a table whose nodes all hold it is
#: a weighted mean with weights summing to one: equal to a few ulp.
TOL_EXACT = 1e-14


def constant_brdf(normal, to_sun, to_observer, wavelength, **params):
    """A constant BRDF ``rho / pi`` where lit and visible (a newcomer's whole model)."""
    p = TOY.check_params(wavelength, **params)
    n = geometry.normalize(normal, "normal")
    lit = np.einsum("...k,...k->...", n, geometry.normalize(to_sun, "to_sun")) > 0
    seen = np.einsum("...k,...k->...", n, geometry.normalize(to_observer, "to_observer")) > 0
    return np.where((lit & seen)[..., None], p["rho"] / np.pi, 0.0)


def constant_reflectance(theta_i, wavelength, **params):
    """Its directional-hemispherical reflectance, ``rho`` (closed form)."""
    p = TOY.check_params(wavelength, **params)
    return np.broadcast_to(p["rho"], np.shape(theta_i) + p["rho"].shape).copy()


TOY = Model(
    name="toy_constant",
    long_name="a constant BRDF, rho / pi",
    brdf=constant_brdf,
    parameters=(Parameter("rho", "1", "albedo of the toy model", lower=0.0, upper=1.0),),
    citation="Lambert, Photometria (1760)",
    reflectance=constant_reflectance,
)


@pytest.fixture
def toy():
    register_model(TOY)
    try:
        yield TOY
    finally:
        unregister_model(TOY.name)


def test_a_registered_model_renders_to_a_table_of_rho_over_pi(toy):
    assert get_model("Toy-Constant") is toy and "toy_constant" in MODELS
    assert "toy_constant" not in ANISOTROPIC_MODELS
    spec = models.model_material("toy_constant", WL, material="toy", provenance="test", rho=RHO)
    assert spec.rho.attrs == {"units": "1", "long_name": "albedo of the toy model"}
    assert spec.attrs["source"] == "model:toy_constant"
    lut = models.render(spec, [0.0, 30.0, 60.0, 90.0], np.arange(-180.0, 91.0, 30.0), [0.0, 90.0])
    # Every node, below the horizon included, carries the limit from inside: rho / pi.
    np.testing.assert_allclose(lut.values, np.broadcast_to(RHO / np.pi, lut.shape), rtol=TOL_EXACT)
    got = material.lookup(lut, [10.0, 45.0], [-20.0, 5.0], [33.0, 80.0]).values
    np.testing.assert_allclose(got, np.broadcast_to(RHO / np.pi, got.shape), rtol=TOL_EXACT)
    np.testing.assert_allclose(models.spectra(spec, 20.0, 0.0, 0.0), RHO / np.pi, rtol=TOL_EXACT)
    m, wl, kw = models.model_parameters(spec)
    assert m is toy
    np.testing.assert_array_equal(
        m.directional_hemispherical_reflectance([0.0, 80.0], wl, **kw)[1], RHO
    )


def test_the_engine_evaluates_a_registered_model(toy):
    """evaluation="analytic" runs the toy model through Model.brdf with no engine change:
    a constant 0.5 / pi is the lambertian-grey-50 table, which is exact (as in test_plan)."""
    from sbrdf_xr.engine import Scene
    from sbrdf_xr.engine.run import simulate

    lam = catalog.load("lambertian-grey-50")
    spec = models.model_material(
        "toy_constant", lam.wavelength.values, material="grey", provenance="test", rho=0.5
    )
    s = Scene(
        T.cube_spacecraft(1.0, subdivisions=1),
        materials={T.TEST_SPACECRAFT_MATERIAL: lam},
        models={T.TEST_SPACECRAFT_MATERIAL: spec},
        attitudes=geometry.uniform_attitudes(8, seed=4),
        phase_angles=[20.0, 70.0],
    )
    a = simulate(s, evaluation="analytic")
    t = simulate(s)
    # float32 table sums against float64 model sums: 1e-6 (as tests/test_plan.py).
    np.testing.assert_allclose(a.signal, t.signal, rtol=1e-6)


def test_unregistering_removes_the_model():
    register_model(TOY)
    assert unregister_model("TOY_CONSTANT") is TOY
    assert "toy_constant" not in BRDF_MODELS and "toy_constant" not in MODELS
    with pytest.raises(ValidationError, match="valid model names"):
        get_model("toy_constant")


@pytest.mark.parametrize(
    ("parameter", "match"),
    [
        (Parameter("rho", "", "albedo"), "declares no units"),
        (Parameter("rho", "1", ""), "declares no long_name"),
        ("rho", "not a Parameter"),
        (Parameter("layers", "1", "reserved"), "reserved"),
        (Parameter("rho", "1", "albedo", lower=1.0, upper=0.0), "empty domain"),
    ],
)
def test_a_parameter_without_metadata_is_an_error_at_registration(parameter, match):
    with pytest.raises(ValidationError, match=match):
        register_model(dataclasses.replace(TOY, name="toy_bad", parameters=(parameter,)))
    assert "toy_bad" not in BRDF_MODELS


def test_registration_refuses_incomplete_or_clashing_models(toy):
    with pytest.raises(ValidationError, match="citation"):
        dataclasses.replace(TOY, name="toy_other", citation="")
    with pytest.raises(ValidationError, match="declared twice"):
        dataclasses.replace(TOY, name="toy_other", parameters=TOY.parameters * 2)
    with pytest.raises(ValidationError, match="model name"):
        dataclasses.replace(TOY, name="Toy Other")
    with pytest.raises(ValidationError, match=r"expected a sbrdf_xr\.brdf\.Model"):
        register_model(models)  # a module is not a model
    with pytest.raises(ValidationError, match="is registered; pass replace=True"):
        register_model(dataclasses.replace(TOY, long_name="again"))
    with pytest.raises(ValidationError, match="not in a view"):
        MODELS.register(TOY)
    new = register_model(dataclasses.replace(TOY, long_name="again"), replace=True)
    assert get_model("toy_constant") is new


def test_lookup_is_case_insensitive_and_errors_list_the_valid_names():
    assert get_model("LAMBERT") is get_model("lambert")
    assert get_model("Robertson-Sandford").name == "robertson_sandford"
    with pytest.raises(ValidationError) as info:
        get_model("phong")
    for name in BRDF_MODELS:
        assert name in str(info.value)
    assert BRDF_MODELS.get("phong") is None


@pytest.mark.parametrize("name", sorted(BRDF_MODELS))
def test_every_declared_parameter_has_udunits_units_and_a_long_name(name):
    m = get_model(name)
    assert m.citation and m.long_name
    for p in (*m.parameters, *m.stack):
        cf_units.Unit(p.units)  # raises on a string UDUNITS does not parse
        assert p.long_name.strip()
    assert all(cf_units.Unit(p.units).is_dimensionless() for p in m.parameters)


def test_a_model_material_carries_the_declared_metadata():
    spec = models.model_material(
        "microfacet",
        WL,
        material="coated",
        provenance="test",
        layers=[(1.45, 100.0)],
        roughness=0.1,
        n=1.5,
        k=0.0,
        rho_d=0.0,
    )
    m = get_model("microfacet")
    for v in spec.data_vars:
        assert spec[v].attrs == m.parameter(v).attrs
    assert spec.layer_thickness.attrs["units"] == "nm"
    with pytest.raises(ValidationError, match="layer_thickness"):
        models.model_material(
            "microfacet", WL, material="c", provenance="t", layers=[(1.45, -1.0)],
            roughness=0.1, n=1.5, k=0.0, rho_d=0.0,
        )  # fmt: skip


def test_parameter_errors_say_what_was_received_and_what_is_allowed():
    with pytest.raises(ValidationError) as info:
        TOY.check_params(WL, rho=[0.2, 1.5, 0.3])
    assert "[1.5]" in str(info.value) and "0.0 <= rho <= 1.0 [1]" in str(info.value)
    with pytest.raises(ValidationError, match=r"missing \['rho'\], unexpected \['albedo'\]"):
        TOY.check_params(WL, albedo=0.2)


def test_isotropic_models_refuse_psi_and_anisotropic_ones_need_it():
    with pytest.raises(ValidationError, match="isotropic"):
        get_model("lambert").brdf_angles(30.0, 0.0, 0.0, WL, psi=0.0, rho=0.5)
    aniso = get_model("anisotropic_microfacet")
    kw = {"alpha_x": 0.1, "alpha_y": 0.2, "n": 1.5, "k": 0.0, "rho_d": 0.0}
    with pytest.raises(ValidationError, match="anisotropic: give psi"):
        aniso.brdf_angles(30.0, 0.0, 0.0, WL, **kw)
    grid = aniso.render_grid([30.0], [0.0, 5.0], [0.0], WL, psi=[0.0, 45.0, 90.0], **kw)
    assert grid.shape == (1, 2, 1, 3, 3)
    with pytest.raises(ValidationError, match="horizon"):
        get_model("lambert").render_grid([0.0], [0.0], [0.0], WL, horizon="clip", rho=0.5)


@pytest.mark.parametrize("name", sorted(BRDF_MODELS))
def test_models_pickle_by_reference(name):
    """Dask workers receive the models in the plan: a model pickles to an equal model."""
    m = get_model(name)
    assert pickle.loads(pickle.dumps(m)) == m
