"""Tests of sbrdf_xr.engine.reuse: what plans keep for the next ones is never stale, and
there is little of it.

Every kept result is checked against the same scene simulated with nothing kept (every
memo cleared) and, for a Lambertian box, against the closed form of paper 000 Eq. 3: at
identity attitude, Sun and observer +-beta/2 either side of +x in the xy-plane, only the
+x face (area s**2) is lit and seen, so ``signal = s**2 cos(beta/2)**2 albedo / pi``.
"""

from __future__ import annotations

import gc
import weakref

import numpy as np
import pytest
import trimesh
import xarray as xr

from sbrdf_xr import catalog, geometry, load_spacecraft
from sbrdf_xr import testing as T
from sbrdf_xr.engine import Scene, reuse, simulate
from sbrdf_xr.materials.models import model_material
from sbrdf_xr.materials.schema import lambertian

# Sums of a few float64 products; the kept and the fresh evaluation run the same
# arithmetic, so they agree exactly; closed forms to 1e-12 relative.
RTOL = 1e-12
WL = [500.0, 600.0, 700.0]


def box(size: float = 1.0):
    return load_spacecraft(trimesh.creation.box(extents=(size,) * 3), material="grey")


def read_only(table: xr.DataArray) -> xr.DataArray:
    """``table`` over a read-only copy of its values (as the catalog's tables are)."""
    values = np.array(table.values)
    values.flags.writeable = False
    return table.copy(data=values)


def box_scene(table: xr.DataArray, spacecraft=None, **kw) -> Scene:
    kw.setdefault("attitudes", [[0.0, 0.0, 0.0, 1.0]])
    kw.setdefault("phase_angles", [20.0, 60.0])
    return Scene(spacecraft or box(), {"grey": table}, **kw)


def closed_form(beta, albedo: float, size: float = 1.0) -> np.ndarray:
    return size**2 * np.cos(np.radians(np.asarray(beta)) / 2) ** 2 * albedo / np.pi


def fresh(scene: Scene) -> xr.Dataset:
    """``scene`` simulated with nothing kept from earlier plans."""
    for memo in reuse.MEMOS:
        memo.clear()
    return simulate(scene.with_options())  # a new scene object: no plan of its own yet


def test_a_new_geometry_reuses_packed_tables_and_facet_terms():
    scene = box_scene(read_only(lambertian(0.5, WL, material="grey")))
    first = scene.plan()
    other = scene.with_options(phase_angles=[33.0])
    second = other.plan()
    assert second.tables is first.tables  # packed once
    assert np.array_equal(second.terms.normal, first.terms.normal)
    cube = simulate(other)
    xr.testing.assert_identical(cube, fresh(other))
    np.testing.assert_allclose(cube.signal[0, 0], closed_form(33.0, 0.5), rtol=RTOL)


@pytest.mark.parametrize(
    "change",
    [
        {"method": "nearest"},
        {"method": "cubic"},
        {"wavelength_stride": 2},
        {"dtype": "float32"},
        {"table_theta_step": 10.0},
        {"merge": False},
        {"surface_tilt": 5.0},
        {"evaluation": "analytic"},
    ],
    ids=lambda c: next(iter(c)),
)
def test_a_changed_knob_is_never_served_a_kept_result(change):
    lobe = catalog.load("example-lobe")  # angular structure: the look-up method matters
    sc = T.cube_spacecraft(1.0, subdivisions=2)
    mat = T.TEST_SPACECRAFT_MATERIAL
    grey = model_material("lambert", lobe.wavelength.values, material=mat, provenance="", rho=0.5)
    models = {mat: grey} if "evaluation" in change else None
    base = Scene(
        sc,
        {mat: lobe},
        attitudes=geometry.axis_rotation([0, 0, 1], np.linspace(0.0, 7.0, 8)),  # near specular
        phase_angles=[10.0, 30.0],
        models=models,
    )
    before = simulate(base)
    changed = base.with_options(**change)
    cube = simulate(changed)
    xr.testing.assert_identical(cube, fresh(changed))
    if "merge" not in change:  # merging is exact: the same sums over fewer terms
        assert not cube.signal.equals(before.signal)


def test_a_writeable_table_changed_in_place_changes_the_result():
    table = lambertian(0.5, WL, material="grey")  # writeable: hashed on every plan
    scene = box_scene(table)
    np.testing.assert_allclose(
        simulate(scene).signal[0, :, 0], closed_form([20.0, 60.0], 0.5), rtol=RTOL
    )
    table.values *= 0.5  # the same table object, new values
    moved = scene.with_options(phase_angles=[20.0, 60.0, 90.0])
    cube = simulate(moved)
    np.testing.assert_allclose(cube.signal[0, :, 0], closed_form([20, 60, 90], 0.25), rtol=RTOL)
    # a new table with the first values: the first result, not the memory of the changed one
    again = box_scene(lambertian(0.5, WL, material="grey"), phase_angles=[20.0, 60.0, 90.0])
    np.testing.assert_allclose(
        simulate(again).signal[0, :, 0], closed_form([20, 60, 90], 0.5), rtol=RTOL
    )


def test_a_read_only_table_in_place_of_another_changes_the_result():
    bright = box_scene(read_only(lambertian(0.5, WL, material="grey")))
    dark = bright.with_options(materials={"grey": read_only(lambertian(0.2, WL, material="grey"))})
    for scene, albedo in ((bright, 0.5), (dark, 0.2), (bright.with_options(), 0.5)):
        cube = simulate(scene)
        np.testing.assert_allclose(
            cube.signal[0, :, 1], closed_form([20.0, 60.0], albedo), rtol=RTOL
        )
    assert dark.plan().tables is not bright.plan().tables


def test_a_table_whose_attributes_change_is_packed_again():
    table = read_only(lambertian(0.5, WL, material="grey"))
    scene = box_scene(table)
    assert scene.plan().tables.blend.tolist() == [0.0]
    table.attrs["normal_incidence_blend"] = 5.0  # read by the packing
    assert box_scene(table).plan().tables.blend.tolist() == [5.0]


def test_a_changed_spacecraft_changes_the_result():
    table = read_only(lambertian(0.5, WL, material="grey"))
    scene = box_scene(table)
    np.testing.assert_allclose(simulate(scene).area[0], np.cos(np.radians([10.0, 30.0])))
    bigger = scene.with_options(spacecraft=box(2.0))
    cube = simulate(bigger)
    np.testing.assert_allclose(cube.signal[0, :, 0], closed_form([20, 60], 0.5, 2.0), rtol=RTOL)
    # the same spacecraft object, its mesh scaled in place: the new areas, not the kept ones
    sc = box()
    small = box_scene(table, sc)
    simulate(small)
    sc.mesh.vertices *= 3.0
    cube = simulate(box_scene(table, sc))
    np.testing.assert_allclose(cube.signal[0, :, 0], closed_form([20, 60], 0.5, 3.0), rtol=RTOL)
    xr.testing.assert_identical(cube, fresh(box_scene(table, sc)))


def test_band_weights_follow_the_bands():
    table = read_only(lambertian(0.5, np.arange(400.0, 1001.0, 10.0), material="grey"))
    v = box_scene(table, bands=("V",), outputs=("band_signal",))
    vr = v.with_options(bands=("V", "R"))
    assert simulate(v).band_signal.sizes["band"] == 1
    cube = simulate(vr)
    assert cube.band.values.tolist() == ["V", "R"]
    xr.testing.assert_identical(cube, fresh(vr))
    # a grey body in every band: the band signal is the grey signal
    np.testing.assert_allclose(cube.band_signal[0, :, :].T, [closed_form([20, 60], 0.5)] * 2)


def test_what_is_kept_is_bounded_and_let_go():
    for memo in reuse.MEMOS:
        memo.clear()
    first = read_only(lambertian(0.9, WL, material="grey"))
    gone = weakref.ref(first.variable.data)
    for i in range(12):  # more tables than any memo (or the kernel's typed lists) keeps
        table = first if i == 0 else read_only(lambertian(0.05 * i, WL, material="grey"))
        for beta in (10.0, 20.0, 30.0):
            simulate(box_scene(table, phase_angles=[beta + i]))
        for memo in reuse.MEMOS:
            assert len(memo) <= memo.size, memo
    assert len(reuse.TABLES) == reuse.KEEP
    del first, table
    gc.collect()
    assert gone() is None  # no memo holds the first table's memory any more


def test_phase_angles_changed_in_place_before_planning_are_used():
    beta = np.array([20.0, 60.0])
    scene = box_scene(read_only(lambertian(0.5, WL, material="grey")), phase_angles=beta)
    beta[0] = 40.0  # the scene holds this array: its plane, kept when checked, is stale
    cube = simulate(scene)
    np.testing.assert_allclose(cube.signal[0, :, 0], closed_form([40.0, 60.0], 0.5), rtol=RTOL)
