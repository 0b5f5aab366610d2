"""Facet temperatures from radiative equilibrium inside the cube (issue 46, item 2):
``temperature="equilibrium"`` with the conductance models ``none``, ``two_sided`` and
``isothermal``, against the closed forms of
:func:`sbrdf_xr.sources.equilibrium_temperature` and Planck."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import constants

from sbrdf_xr import testing as T
from sbrdf_xr.engine import Scene
from sbrdf_xr.engine.run import simulate
from sbrdf_xr.errors import SceneError, ValidationError
from sbrdf_xr.materials.schema import lambertian
from sbrdf_xr.photometry import solar_spectrum
from sbrdf_xr.sources import EARTH_MEAN_RADIUS_KM, equilibrium_temperature, planck

WL = np.array([400.0, 700.0, 1500.0, 4000.0, 8000.0, 12_000.0])
X = [[1.0, 0.0, 0.0]]  # the Sun and the observer along +x: the +x face faces both
MAT = T.TEST_SPACECRAFT_MATERIAL
S = 1361.0  # W m-2, the engine's SOLAR_CONSTANT (Kopp & Lean 2011)


def _scene(albedo, **kw):
    kw.setdefault("to_sun", X)
    kw.setdefault("to_observer", X)
    kw.setdefault("effects", ("sunlight", "thermal"))
    return Scene(
        T.cube_spacecraft(1.0, subdivisions=1),
        {MAT: lambertian(albedo, WL, material=MAT)},
        temperature="equilibrium",
        outputs=("signal",),
        **kw,
    )


def _face(cube, normal):
    """The temperature [K] of the term with this normal, at every geometry."""
    n = cube.facet_normal.values
    j = int(np.flatnonzero(np.all(np.abs(n - normal) < 1e-12, axis=1))[0])
    return cube.facet_temperature.isel(facet=j).values


@pytest.mark.parametrize(("conductance", "sides"), [("none", 1), ("two_sided", 2)])
def test_grey_plate_facing_the_sun_is_the_closed_form(conductance, sides):
    """Grey (alpha = eps = 0.7): ``T = (S / (sides sigma))^(1/4)``, and the emission of the
    Sun-facing face is ``A eps B(lambda, T)`` (only that face is seen)."""
    cube = simulate(_scene(0.3, conductance=conductance)).compute()
    t = _face(cube, [1.0, 0.0, 0.0])[0]
    want = float(equilibrium_temperature(0.7 * S, 0.7, radiating_sides=sides))
    assert t == pytest.approx(want, rel=1e-12)  # the same closed form, to rounding
    np.testing.assert_allclose(
        cube.thermal_intensity.isel(geometry=0).values, 0.7 * planck(WL, want), rtol=1e-9
    )
    assert cube.facet_temperature.attrs["units"] == "K"
    assert cube.facet_temperature.dims == ("geometry", "facet")


@pytest.mark.parametrize(
    ("to_sun", "projected"),
    [([1.0, 0.0, 0.0], 1.0), (np.ones(3) / np.sqrt(3.0), np.sqrt(3.0))],
)
def test_isothermal_cube_is_the_closed_form(to_sun, projected):
    """One temperature for the whole (grey, alpha = eps = 0.7) unit cube: absorbed
    ``alpha S A_proj`` (its area projected toward the Sun: 1 face-on, sqrt(3) along a
    diagonal) equals ``eps sigma T^4 6``, so ``T = (S A_proj / (6 sigma))^(1/4)``, on the
    seen faces and on the faces the plan drops alike; the seen face emits ``eps B(T)``."""
    cube = simulate(_scene(0.3, to_sun=[to_sun], conductance="isothermal")).compute()
    temps = cube.facet_temperature.isel(geometry=0).values
    want = (S * projected / (6.0 * constants.sigma)) ** 0.25
    np.testing.assert_allclose(temps, want, rtol=1e-12)  # the same closed form, to rounding
    assert float(equilibrium_temperature(0.7 * S * projected / 6.0, 0.7)) == pytest.approx(want)
    np.testing.assert_allclose(
        cube.thermal_intensity.isel(geometry=0).values, 0.7 * planck(WL, want), rtol=1e-9
    )
    line = dict(_scene(0.3, conductance="isothermal").plan().steps)["thermal"]
    assert "isothermal: one temperature per material" in line


def test_oblique_sun_scales_the_absorbed_power_by_cos_theta_i():
    c = np.cos(np.radians(60.0))
    cube = simulate(_scene(0.3, to_sun=[[c, np.sqrt(1 - c**2), 0.0]])).compute()
    want = float(equilibrium_temperature(0.7 * S * c, 0.7))
    assert _face(cube, [1.0, 0.0, 0.0])[0] == pytest.approx(want, rel=1e-12)


def test_spectral_paint_uses_solar_and_planck_weighted_means():
    """A white paint: reflective in the solar range, black in the infrared; alpha and
    eps computed here independently (trapezoids of the Sun's and Planck's spectra)."""
    albedo = np.array([0.9, 0.85, 0.8, 0.1, 0.05, 0.05])
    cube = simulate(_scene(albedo)).compute()
    sun = solar_spectrum(WL, solar="astm_g173_extended").values
    alpha = np.trapezoid((1 - albedo) * sun, WL) / np.trapezoid(sun, WL)
    b = planck(WL, 300.0)
    eps = np.trapezoid((1 - albedo) * b, WL) / np.trapezoid(b, WL)
    want = float(equilibrium_temperature(alpha * S, eps))
    # the hemispherical mean of a Lambertian table's emissivity is exact to the
    # table's own quadrature (its hemispherical reflectance, ~1e-6)
    assert _face(cube, [1.0, 0.0, 0.0])[0] == pytest.approx(want, rel=1e-5)
    assert 250.0 < want < 300.0  # a white paint in sunlight stays cool


def test_earth_alone_in_the_shadow_of_the_body():
    """The Sun behind the face, the Earth in front at GEO (earth_thermal asked, so the
    scene has the Earth's range): ``T = T_E sin(rho)^(1/2)`` (view pi sin^2 rho)."""
    down = [[-1.0, 0.0, 0.0]]
    cube = simulate(
        _scene(
            0.3,
            to_sun=down,
            to_earth=X,
            effects=("sunlight", "thermal", "earth_thermal"),
            earth_temperature=255.0,
        )
    ).compute()
    want = 255.0 * np.sqrt(EARTH_MEAN_RADIUS_KM / 42164.0)
    assert _face(cube, [1.0, 0.0, 0.0])[0] == pytest.approx(want, rel=1e-9)


def test_given_temperatures_add_no_variable():
    sc = _scene(0.3).with_options(temperature=320.0)
    assert "facet_temperature" not in simulate(sc).data_vars


def test_bad_input_is_named():
    with pytest.raises(SceneError, match="temperature"):
        _scene(0.3).with_options(temperature="hot")
    with pytest.raises(SceneError, match="conductance"):
        _scene(0.3, conductance="conduction")
    with pytest.raises(ValidationError, match="emissivity"):
        simulate(_scene(1.0))


def test_the_earths_shadow_scales_the_absorbed_sunlight():
    """An observation's sunlit fraction f (the block's sun_scale) multiplies the absorbed
    sunlight only: ``T(f)^4 - T(0)^4 = f (T(1)^4 - T(0)^4)``, and in the umbra the face
    keeps the Earth's emission alone (steady state)."""
    import dataclasses

    from sbrdf_xr.engine.effects import EFFECTS

    plan = _scene(
        0.3, to_earth=[[0.0, 0.0, -1.0]], effects=("sunlight", "thermal", "earth_thermal")
    ).plan()
    block = plan.geometry.block(slice(None))
    t = {
        f: EFFECTS["thermal"].contribute(plan, dataclasses.replace(block, sun_scale=np.array([f])))[
            "facet_temperature"
        ][0]
        for f in (0.0, 0.5, 1.0)
    }
    np.testing.assert_allclose(t[0.5] ** 4 - t[0.0] ** 4, 0.5 * (t[1.0] ** 4 - t[0.0] ** 4))
    assert np.all(t[0.0] < t[0.5]) and np.all(t[0.5] < t[1.0])
    # the +x face sees the Earth below edge-on: the edge-on view of a GEO Earth
    h = 42164.0 / EARTH_MEAN_RADIUS_KM
    edge = np.arctan(1 / np.sqrt(h**2 - 1)) - np.sqrt(h**2 - 1) / h**2  # Howell, [sr]
    j = int(np.flatnonzero(np.all(np.isclose(plan.terms.normal, [1.0, 0.0, 0.0]), axis=1))[0])
    assert t[0.0][j] == pytest.approx(255.0 * (edge / np.pi) ** 0.25, rel=1e-3)
