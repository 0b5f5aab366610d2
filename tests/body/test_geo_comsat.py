"""The built-in GEO comsat-like body: its surfaces, its tracking arrays, a closed form."""

from __future__ import annotations

import numpy as np

from sbrdf_xr import Scene, simulate
from sbrdf_xr.body.geo_comsat import GEO_COMSAT_MATERIALS, geo_comsat
from sbrdf_xr.engine.builtin import geo_comsat_materials
from sbrdf_xr.materials import optical


def test_surfaces_and_parts():
    sc = geo_comsat()
    f = sc.facets()
    area = {m: float(f.area[f.material == m].sum()) for m in GEO_COMSAT_MATERIALS}
    # MLI: east, west (2.0 x 2.2), Earth and anti-Earth (2.4 x 2.0); OSR: north, south (2.4 x 2.2)
    np.testing.assert_allclose(
        [area["kapton-mli"], area["osr"], area["gaas-cell"]],
        [2 * 2.0 * 2.2 + 2 * 2.4 * 2.0, 2 * 2.4 * 2.2, 2 * 22.0],
        rtol=1e-12,
    )
    osr = f.normal.values[(f.material == "osr").values]
    np.testing.assert_array_equal(np.abs(osr[:, 1]), 1.0)  # the radiators face north and south
    assert [p.name for p in sc.moving_parts] == ["north-array", "south-array"]


def test_backscatter_at_nadir_is_the_closed_form():
    """Sun and observer at nadir (+z): the arrays turn to face them, and only the Earth deck
    (MLI, 2.4 x 2.0 m) and the cells (44 m2) are lit and seen, at normal incidence, where the
    GGX BRDF is F(0) / (4 pi alpha^2) (D(0) = 1 / (pi alpha^2), G2 = 1)."""
    wl = np.array([450.0, 550.0, 700.0])
    mats = geo_comsat_materials(wl)
    z = np.array([[0.0, 0.0, 1.0]])
    scene = Scene(geo_comsat(), mats, to_sun=z, to_observer=z, evaluation="analytic")
    cube = simulate(scene).compute()
    np.testing.assert_allclose(cube.part_angle.values, [[-90.0, -90.0]], atol=1e-9)

    def f0(name):
        alpha = optical.OPTICAL_MATERIALS[name].roughness
        return optical.specular_reflectance(name, wl) / (4.0 * np.pi * alpha**2)

    expected = 2.4 * 2.0 * f0("kapton-mli") + 44.0 * f0("gaas-cell")
    # the engine's angles at exact backscatter and normal incidence: ~1e-12 relative
    np.testing.assert_allclose(cube.signal.values[0], expected, rtol=1e-9)
