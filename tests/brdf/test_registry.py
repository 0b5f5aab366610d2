"""Tests of the model registry and of the common model interface."""

from __future__ import annotations

import numpy as np
import pytest

from sbrdf_xr.brdf import MODELS, get_model
from sbrdf_xr.errors import ValidationError

WL = np.array([450.0, 650.0, 900.0])
_RS = {"rho_D": 0.07, "epsilon": [0.85, 0.8, 0.7], "b": 0.12, "e": 0.12}
_CORE = {**_RS, "core_rho": [0.2, 0.25, 0.3], "core_roughness": 0.05}
PARAMS = {
    "lambert": {"rho": [0.2, 0.4, 0.6]},
    "robertson_sandford": _RS,
    "microfacet": {"roughness": 0.2, "n": [1.5, 1.5, 1.48], "k": 0.0, "rho_d": 0.1},
    "robertson_sandford_core": _CORE,
    # each model extends the one before it: its parameters are the core's and the halo's
    "robertson_sandford_halo": {
        **_CORE,
        "halo_a": [1e-3, 2e-3, 3e-3],
        "halo_b": 1e-5,
        "halo_g": 2.5,
    },
}
#: render_grid and brdf_angles evaluate the same arithmetic on the same points.
TOL_SAME = 1e-14


def test_registry_names():
    assert set(MODELS) == {
        "lambert",
        "robertson_sandford",
        "microfacet",
        "robertson_sandford_core",
        "robertson_sandford_halo",
    }
    assert set(PARAMS) == set(MODELS)


def test_get_model_rejects_unknown_name_and_lists_valid_ones():
    with pytest.raises(ValidationError) as info:
        get_model("nope")
    msg = str(info.value)
    assert "nope" in msg
    for name in MODELS:
        assert name in msg
    with pytest.raises(ValidationError):
        get_model(3)  # type: ignore[arg-type]


@pytest.mark.parametrize("name", sorted(MODELS))
def test_interface_members(name):
    model = get_model(name)
    for attr in (
        "param_names",
        "check_params",
        "brdf",
        "brdf_angles",
        "render_grid",
        "directional_hemispherical_reflectance",
    ):
        assert hasattr(model, attr)
    checked = model.check_params(WL, **PARAMS[name])
    assert tuple(checked) == model.param_names
    for v in checked.values():
        assert v.shape == WL.shape and v.dtype == np.float64


@pytest.mark.parametrize("name", sorted(MODELS))
def test_render_grid_equals_brdf_angles(name):
    model = get_model(name)
    ti = np.array([0.0, 20.0, 55.0, 89.0])
    dt = np.array([-30.0, -1.0, 0.0, 0.5, 12.0])
    ph = np.array([0.0, 3.0, 60.0])
    grid = model.render_grid(ti, dt, ph, WL, **PARAMS[name])
    assert grid.shape == (4, 5, 3, 3)
    a, b, c = np.meshgrid(ti, dt, ph, indexing="ij")
    pts = model.brdf_angles(a.ravel(), b.ravel(), c.ravel(), WL, **PARAMS[name])
    np.testing.assert_allclose(grid.reshape(-1, 3), pts, rtol=TOL_SAME, atol=0)
    assert np.all(grid[ti < 90] >= 0) and np.any(grid > 0)


@pytest.mark.parametrize("name", sorted(MODELS))
def test_zero_when_unlit_or_unseen(name):
    model = get_model(name)
    n = np.array([0.0, 0.0, 1.0])
    s_lit = np.array([0.3, 0.0, 1.0])
    o_seen = np.array([-0.3, 0.1, 1.0])
    assert np.all(model.brdf(n, s_lit, o_seen, WL, **PARAMS[name]) > 0)
    for s, o in (
        (np.array([0.3, 0, -1.0]), o_seen),
        (s_lit, np.array([-0.3, 0, -1.0])),
        (np.array([1.0, 0, 0]), o_seen),
        (s_lit, np.array([0, 1.0, 0])),
    ):
        assert np.all(model.brdf(n, s, o, WL, **PARAMS[name]) == 0)
    # and from angles: unlit (theta_i >= 90) or unseen (theta_i + delta_theta >= 90)
    assert np.all(model.brdf_angles([95.0, 40.0], [0.0, 55.0], 0.0, WL, **PARAMS[name]) == 0)


@pytest.mark.parametrize("name", sorted(MODELS))
def test_hemispherical_reflectance_shape_and_bounds(name):
    model = get_model(name)
    r = model.directional_hemispherical_reflectance(
        np.array([[0.0, 30.0], [60.0, 85.0]]), WL, **PARAMS[name]
    )
    assert r.shape == (2, 2, 3)
    assert np.all((r >= 0) & (r <= 1))
