"""The engine's earthshine from a finite Earth (issue 46): a facet's irradiance from the
Lambertian Earth at its true size, cut by the facet's horizon, reflected with the BRDF at
the direction of the Earth's centre.  Checked against an adaptive surface integral over
the Earth (Lambertian facet: exact) and a fine quadrature of the full integral (glossy)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import integrate

from sbrdf_xr import testing as T
from sbrdf_xr.engine import Scene
from sbrdf_xr.engine.run import simulate
from sbrdf_xr.materials import models
from sbrdf_xr.materials.schema import lambertian
from sbrdf_xr.sources import EARTH_MEAN_RADIUS_KM, _earth_cap, earthshine_irradiance_ratio

R = EARTH_MEAN_RADIUS_KM
WL = [500.0, 600.0, 700.0]
DOWN = np.array([0.0, 0.0, -1.0])  # the facet looked at: the cube's -z face
#: the issue's requirement against the exact integral; the engine's quadrature
#: (earthshine_facets, 64 x 128 nodes) is measured at 2e-5 of the largest irradiance
TOL = 1e-3


def _reference(normal, to_earth, to_sun, r, albedo=0.3):
    """Nested adaptive quad over the Earth's surface about the sub-spacecraft point
    (``dOmega = cos(e) dA / D^2``), independent of the package's quadrature."""
    n, s = np.asarray(normal, float), np.asarray(to_sun, float)
    zp = -np.asarray(to_earth, float)
    xp = np.cross(zp, [0.0, 1.0, 0.0] if abs(zp[1]) < 0.9 else [1.0, 0.0, 0.0])
    xp /= np.linalg.norm(xp)
    yp = np.cross(zp, xp)

    def f(beta, gam):
        u = np.cos(gam) * zp + np.sin(gam) * (np.cos(beta) * xp + np.sin(beta) * yp)
        dvec = R * u - r * zp
        dist = np.linalg.norm(dvec)
        d = dvec / dist
        return max(u @ s, 0.0) * max(n @ d, 0.0) * max(-u @ d, 0.0) * R**2 * np.sin(gam) / dist**2

    g_max = np.arccos(R / r)
    return albedo / np.pi * integrate.dblquad(f, 0.0, g_max, 0.0, 2 * np.pi, epsrel=1e-9)[0]


def _geometry(tilt_deg, phase_deg):
    """The Earth at ``tilt`` from the -z face's normal, the Sun at the Earth's phase
    ``phase`` (``-s . e = cos(phase)``), the observer along -z (only that face is seen)."""
    t = np.radians(tilt_deg)
    e = np.array([np.sin(t), 0.0, -np.cos(t)])
    a = np.radians(phase_deg)
    p = np.array([0.0, 1.0, 0.0])  # perpendicular to e
    s = -np.cos(a) * e + np.sin(a) * p
    return e, s


def _scene(e, s, r, phase, material, **kw):
    sc = T.cube_spacecraft(1.0, subdivisions=1)
    return Scene(
        sc,
        materials={T.TEST_SPACECRAFT_MATERIAL: lambertian(0.5, WL, material="grey")},
        models={T.TEST_SPACECRAFT_MATERIAL: material},
        to_sun=[s],
        to_observer=[DOWN],
        to_earth=[e],
        effects=("sunlight", "earthshine"),
        earth_albedo=0.3,
        earth_range=r,
        earth_phase_angle=phase,
        evaluation="analytic",
        **kw,
    )


def _lambert():
    return models.model_material(
        "lambert", WL, rho=0.5, material=T.TEST_SPACECRAFT_MATERIAL, provenance="albedo 0.5"
    )


#: (tilt of the Earth from the face normal [deg], range [km], Earth phase [deg])
CASES = [
    (0.0, 42164.0, 0.0),  # GEO, full Earth, Earth-facing
    (30.0, 42164.0, 60.0),
    (0.0, 7000.0, 0.0),
    pytest.param(*(30.0, 7000.0, 80.0), marks=pytest.mark.slow),
    (87.0, 7000.0, 30.0),  # grazing: the horizon cuts the disc
    pytest.param(*(80.0, 6771.0, 45.0), marks=pytest.mark.slow),  # grazing, 400 km
    # limb only: the Earth's centre below the face's horizon, part of the day side above it
    # (reach 90 + rho: 98.7 deg at GEO, 155.5 at 7000 km, 160.2 at 6771 km)
    (95.0, 42164.0, 30.0),
    (100.0, 7000.0, 0.0),
    pytest.param(*(120.0, 7000.0, 60.0), marks=pytest.mark.slow),
    pytest.param(*(150.0, 7000.0, 30.0), marks=pytest.mark.slow),
    pytest.param(*(130.0, 6771.0, 45.0), marks=pytest.mark.slow),
]


@pytest.mark.parametrize(("tilt", "r", "phase"), CASES)
def test_lambertian_facet_against_the_exact_integral(tilt, r, phase):
    """A Lambertian face seen head on: ``signal = A (rho/pi) E_face`` exactly (the BRDF is
    the same in every direction, so the centre-direction approximation is exact)."""
    e, s = _geometry(tilt, phase)
    cube = simulate(_scene(e, s, r, phase, _lambert())).compute()
    got = float(cube.signal_earthshine.isel(geometry=0, wavelength=0))
    want = 0.5 / np.pi * _reference(DOWN, e, s, r)
    print(f"lambertian {(tilt, r, phase)}: rel {got / want - 1:+.2e}")
    assert got == pytest.approx(want, rel=TOL)


def test_limb_only_facet_is_kept_by_the_plan():
    """Only the -z face is seen, its horizon hides the Earth's centre (120 deg at 7000 km):
    the plan keeps it (the Earth reaches 90 + rho = 155.5 deg) and it gets earthshine."""
    e, s = _geometry(120.0, 0.0)
    s = np.array([0.0, 0.0, 1.0])  # the Sun lights only the +z face, which is not seen
    cube = simulate(_scene(e, s, 7000.0, 60.0, _lambert())).compute()
    assert float(cube.signal_earthshine.isel(geometry=0, wavelength=0)) > 0.0


@settings(max_examples=20, deadline=None)
@given(
    tilt=st.floats(0.0, 180.0),
    phase=st.floats(0.0, 180.0),
    r=st.sampled_from([6771.0, 7000.0, 42164.0]),
)
def test_finite_earth_is_never_negative_nor_above_the_full_cap(tilt, phase, r):
    """``0 <= E <= a sin^2(rho)``: the irradiance of a plate facing a fully lit visible cap
    (``(a/pi) int max(n.d, 0) dOmega`` is largest, ``pi sin^2(rho)``, for a facing plate and
    ``max(u.s, 0) <= 1``).  The face has area 1 and albedo 0.5: ``signal = 0.5/pi E``."""
    e, s = _geometry(tilt, phase)
    cube = simulate(_scene(e, s, r, phase, _lambert())).compute()
    got = float(cube.signal_earthshine.isel(geometry=0, wavelength=0)) / (0.5 / np.pi)
    assert got >= 0.0
    assert got <= 0.3 * (R / r) ** 2 * (1 + 1e-9)


def test_point_source_knob_keeps_the_old_light():
    e, s = _geometry(0.0, 0.0)
    cube = simulate(_scene(e, s, 7000.0, 0.0, _lambert(), earth_model="point")).compute()
    got = float(cube.signal_earthshine.isel(geometry=0, wavelength=0))
    ratio = earthshine_irradiance_ratio(0.3, 7000.0, 0.0)
    assert got == pytest.approx(0.5 / np.pi * ratio, rel=1e-9)
    # 32 % below the finite Earth at 7000 km (the figure)
    assert ratio / _reference(DOWN, e, s, 7000.0) == pytest.approx(0.68, abs=0.01)


def test_night_side_earth_gives_no_earthshine():
    e, s = _geometry(0.0, 120.0)  # 7000 km, phase 120 deg: the visible cap is all night
    cube = simulate(_scene(e, s, 7000.0, 120.0, _lambert())).compute()
    assert float(cube.signal_earthshine.isel(geometry=0, wavelength=0)) == 0.0


def _glossy_truth(plan, e, s, r):
    """``A cos_r int (a/pi) max(u.s, 0) f_r(d, o) max(n.d, 0) dOmega`` over the visible
    Earth, with the engine's own analytic BRDF, on 512 x 1024 Gauss nodes (that rule is
    within 1e-5 of the adaptive reference for the Lambertian integrand)."""
    d, u, cos_n, w = _earth_cap(DOWN, e, r, (512, 1024))
    d, lit = d.reshape(-1, 3), (w * np.maximum(u @ s, 0.0) * cos_n).ravel()
    on = lit > 0
    model, kw = plan.models[0]
    f = model.brdf(DOWN, d[on], np.broadcast_to(DOWN, d[on].shape), plan.wavelength, **kw)
    return 0.3 / np.pi * lit[on] @ f[:, 0]


#: the measured error of the centre-direction BRDF for a glossy paint (Robertson-Sandford,
#: glint lobe e = 0.35): (tilt, range, phase) -> bound on the relative error, about 1.5 x
#: the measured +3.0e-3, -1.0e-4 and +6.5e-2 (the lobe varies across the 8.7 deg disc at
#: GEO, across the 65 deg one at 7000 km)
GLOSSY = [((0.0, 42164.0, 0.0), 5e-3), ((30.0, 42164.0, 60.0), 1e-3), ((0.0, 7000.0, 0.0), 0.1)]


@pytest.mark.parametrize(("case", "bound"), GLOSSY)
def test_glossy_facet_centre_direction_error_is_measured(case, bound):
    tilt, r, phase = case
    paint = models.model_material(
        "robertson_sandford",
        WL,
        material=T.TEST_SPACECRAFT_MATERIAL,
        provenance="glossy test paint",
        rho_D=0.8,
        epsilon=0.12,
        b=0.1,
        e=0.35,
    )
    e, s = _geometry(tilt, phase)
    scene = _scene(e, s, r, phase, paint)
    got = float(simulate(scene).compute().signal_earthshine.isel(geometry=0, wavelength=0))
    want = _glossy_truth(scene.plan(), e, s, r)
    print(f"glossy {case}: engine {got:.6e} exact {want:.6e} rel {got / want - 1:+.2e}")
    assert abs(got / want - 1) < bound


#: the measured error of the diffuse-sky reflectance rho(theta_r)/pi for the same glossy
#: paint on a face that sees only the limb (the light arrives at grazing incidence, where
#: its lobe and Fresnel term are above their hemispherical average): the engine is low by
#: 14 % (GEO, 95 deg), 42 % (7000 km, 100 deg), 40 % (120 deg) and 19 % (150 deg); the
#: bound is about 1.2 x the measured error, the sign is asserted
GLOSSY_LIMB = [
    ((95.0, 42164.0, 30.0), 0.17),
    ((100.0, 7000.0, 0.0), 0.5),
    ((120.0, 7000.0, 60.0), 0.48),
    ((150.0, 7000.0, 30.0), 0.23),
]


@pytest.mark.slow
@pytest.mark.parametrize(("case", "bound"), GLOSSY_LIMB)
def test_glossy_limb_only_facet_error_is_measured(case, bound):
    tilt, r, phase = case
    paint = models.model_material(
        "robertson_sandford",
        WL,
        material=T.TEST_SPACECRAFT_MATERIAL,
        provenance="glossy test paint",
        rho_D=0.8,
        epsilon=0.12,
        b=0.1,
        e=0.35,
    )
    e, s = _geometry(tilt, phase)
    scene = _scene(e, s, r, phase, paint)
    got = float(simulate(scene).compute().signal_earthshine.isel(geometry=0, wavelength=0))
    want = _glossy_truth(scene.plan(), e, s, r)
    print(f"glossy limb {case}: engine {got:.6e} exact {want:.6e} rel {got / want - 1:+.2e}")
    assert -bound < got / want - 1 < 0.0
