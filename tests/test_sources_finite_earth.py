"""A finite Earth as a source (issue 46): reflected sunlight and thermal emission on a plate,
against an independent adaptive quadrature over the Earth's surface."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import integrate

from sbrdf_xr.errors import ValidationError
from sbrdf_xr.sources import (
    EARTH_MEAN_RADIUS_KM,
    earth_thermal_irradiance,
    earth_view_facets,
    earthshine_finite,
    earthshine_irradiance_ratio,
    planck,
)

#: The issue's requirement; the Gauss-Legendre rule of EARTH_NODES converges as N^-2
#: across the terminator and horizon kinks and is measured at ~1e-5 relative here.
TOL = 1e-3
R = EARTH_MEAN_RADIUS_KM


def _reference(normal, to_earth, to_sun, r, albedo=0.3, emitted=False):
    """Nested adaptive quad over the Earth's surface (geocentric angles about the
    sub-spacecraft point): ``dOmega = cos(e) dA / D^2``."""
    n, s = np.asarray(normal, float), np.asarray(to_sun, float)
    n, s = n / np.linalg.norm(n), s / np.linalg.norm(s)
    zp = -np.asarray(to_earth, float) / np.linalg.norm(to_earth)  # toward the spacecraft
    xp = np.cross(zp, [0.0, 1.0, 0.0] if abs(zp[1]) < 0.9 else [1.0, 0.0, 0.0])
    xp /= np.linalg.norm(xp)
    yp = np.cross(zp, xp)
    craft = r * zp

    def f(beta, gam):
        u = np.cos(gam) * zp + np.sin(gam) * (np.cos(beta) * xp + np.sin(beta) * yp)
        dvec = R * u - craft
        dist = np.linalg.norm(dvec)
        d = dvec / dist
        cos_e = -u @ d
        lit = 1.0 if emitted else max(u @ s, 0.0)
        return lit * max(n @ d, 0.0) * max(cos_e, 0.0) * R**2 * np.sin(gam) / dist**2

    g_max = np.arccos(R / r)
    val = integrate.dblquad(f, 0.0, g_max, 0.0, 2 * np.pi, epsabs=1e-13, epsrel=1e-9)[0]
    return val if emitted else albedo / np.pi * val


def _unit(deg):
    """Direction in the x-z plane at ``deg`` from +z (the Sun, as seen from the Earth)."""
    t = np.radians(deg)
    return [np.sin(t), 0.0, np.cos(t)]


DOWN = [0.0, 0.0, -1.0]  # the Earth below the spacecraft
CASES = [
    # (plate normal, range [km], Sun's angle from the zenith of the sub-spacecraft point)
    (DOWN, 42164.0, 0.0),  # GEO, full phase, Earth-facing
    (DOWN, 42164.0, 60.0),
    (DOWN, 42164.0, 120.0),
    (DOWN, 7000.0, 0.0),  # low orbit
    (DOWN, 7000.0, 80.0),
    ([1.0, 0.0, -0.05], 7000.0, 30.0),  # grazing: the plate's horizon cuts the Earth
    ([0.0, 1.0, 0.0], 42164.0, 90.0),  # edge-on plate, the terminator across the disc
]


@pytest.mark.parametrize(("normal", "r", "sun"), CASES)
def test_reflected_against_surface_integral(normal, r, sun):
    got = earthshine_finite(normal, DOWN, _unit(sun), r)
    ref = _reference(normal, DOWN, _unit(sun), r)
    assert got == pytest.approx(ref, rel=TOL, abs=1e-12)


@pytest.mark.parametrize(
    ("normal", "r"), [(DOWN, 42164.0), (DOWN, 7000.0), ([1.0, 0.0, -0.05], 7000.0)]
)
def test_emitted_view_factor_against_surface_integral(normal, r):
    got = earth_thermal_irradiance([10_000.0], normal, DOWN, r)[0] / planck(10_000.0, 255.0)
    assert got == pytest.approx(_reference(normal, DOWN, [0, 0, 1], r, emitted=True), rel=TOL)


VIEW_NORMALS = [DOWN, [1.0, 0.0, -0.05], [1.0, 0.0, 0.0], [1.0, 0.0, 0.1], [0.6, 0.0, -0.8]]


@pytest.mark.parametrize("r", [42164.0, 7000.0, pytest.param(6771.0, marks=pytest.mark.slow)])
def test_view_facets_against_surface_integral(r):
    """Many plates at once (whole cap, horizon-cut, edge-on, beyond the centre's horizon):
    the default 64 x 128 nodes are within 1e-3 of the largest value (the horizon kink
    converges as N^-2; measured 4e-6 at GEO, 4e-5 at 7000 and 6771 km)."""
    n = np.asarray(VIEW_NORMALS) / np.linalg.norm(VIEW_NORMALS, axis=1)[:, None]
    got = earth_view_facets(n, [DOWN], r)[0]
    want = np.array([_reference(m, DOWN, [0, 0, 1], r, emitted=True) for m in n])
    assert np.abs(got - want).max() < TOL * want.max()
    assert got[0] == pytest.approx(np.pi * (R / r) ** 2, rel=1e-12)  # the whole cap, exact


def test_view_facets_is_the_single_plate_quadrature_in_any_frame():
    """Turning the Earth and the normals together changes nothing; each geometry keeps
    its own range."""
    rot = np.array([[0.0, -1.0, 0.0], [0.6, 0.0, -0.8], [0.8, 0.0, 0.6]])  # a rotation
    n = np.asarray(VIEW_NORMALS) / np.linalg.norm(VIEW_NORMALS, axis=1)[:, None]
    e = np.array([DOWN, DOWN])
    got = earth_view_facets(n @ rot.T, e @ rot.T, [7000.0, 42164.0])
    for g, r in enumerate((7000.0, 42164.0)):
        single = [
            earth_thermal_irradiance([10_000.0], m, DOWN, r)[0] / planck(10_000.0, 255.0) for m in n
        ]
        # 64 x 128 against 256 x 512 nodes: the horizon kink, N^-2
        np.testing.assert_allclose(got[g], single, rtol=0, atol=1e-4 * max(single))


def test_night_side_gives_nothing_where_the_point_source_does():
    """7000 km at phase 120 deg: the visible cap is all night (the point source gives 1.8e-2)."""
    assert earthshine_finite(DOWN, DOWN, _unit(120.0), 7000.0) == 0.0
    assert earthshine_irradiance_ratio(0.3, 7000.0, 120.0) > 0.01


def test_far_away_the_finite_earth_is_the_point_source():
    """The near side is closer than the centre by ~R: the difference is O(R/r) (measured
    0.75 R/r at full phase, 2.2 R/r at 120 deg) and shrinks tenfold per decade of range."""
    for r in (1.0e6, 1.0e7):
        for sun in (0.0, 60.0, 120.0):
            got = earthshine_finite(DOWN, DOWN, _unit(sun), r)
            point = earthshine_irradiance_ratio(0.3, r, sun)
            assert abs(got / point - 1.0) < 3.0 * R / r


def test_bad_input_is_named():
    with pytest.raises(ValidationError, match="range: got 6000"):
        earthshine_finite(DOWN, DOWN, [0, 0, 1], 6000.0)
    with pytest.raises(ValidationError, match="temperature"):
        earth_thermal_irradiance([1e4], DOWN, DOWN, 7000.0, temperature=-5.0)
    with pytest.raises(ValidationError, match="temperature"):
        earth_thermal_irradiance([1e4], DOWN, DOWN, 7000.0, temperature=5000.0)


def test_equilibrium_temperature_balances_absorbed_and_emitted():
    """sigma T^4 eps sides = absorbed, to float64 rounding; bad input is named."""
    from scipy import constants

    from sbrdf_xr.sources import equilibrium_temperature

    q = np.array([0.0, 100.0, 1361.0])
    for eps, sides in ((1.0, 1), (0.85, 2)):
        t = equilibrium_temperature(q, eps, radiating_sides=sides)
        assert sides * eps * constants.sigma * t**4 == pytest.approx(q, rel=1e-14)
    with pytest.raises(ValidationError, match="absorbed"):
        equilibrium_temperature(-1.0, 0.5)
    with pytest.raises(ValidationError, match="emissivity"):
        equilibrium_temperature(1.0, 0.0)
    with pytest.raises(ValidationError, match="radiating_sides"):
        equilibrium_temperature(1.0, 0.5, radiating_sides=3)


def test_radiative_cooling_solves_the_energy_balance():
    """The closed form against scipy's ODE solver (rtol 1e-10) for C dT/dt = -eps sigma T^4."""
    from scipy import constants

    from sbrdf_xr.sources import radiative_cooling

    c, eps, t0 = 2430.0, 0.85, 300.0
    t = np.linspace(0.0, 7200.0, 13)
    sol = integrate.solve_ivp(
        lambda _, y: -2 * eps * constants.sigma * y**4 / c,
        (0.0, t[-1]),
        [t0],
        t_eval=t,
        rtol=1e-11,
        atol=1e-9,
    )
    got = radiative_cooling(t, t0, c, eps, radiating_sides=2)
    assert got == pytest.approx(sol.y[0], rel=1e-8)
    assert np.all(np.diff(got) < 0)
    for bad in (dict(time=-1.0), dict(initial_temperature=0.0), dict(heat_capacity=0.0)):
        args = dict(time=1.0, initial_temperature=300.0, heat_capacity=c) | bad
        with pytest.raises(ValidationError, match=next(iter(bad))):
            radiative_cooling(args["time"], args["initial_temperature"], args["heat_capacity"], eps)
