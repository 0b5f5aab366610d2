"""Tests of sbrdf_xr.simulate: the facet sums of paper 000 Eqs. 3-4, plans, lazy cubes."""

from __future__ import annotations

import warnings

import dask
import numpy as np
import pytest
import xarray as xr

from sbrdf_xr import catalog, geometry
from sbrdf_xr import testing as T
from sbrdf_xr.engine import Scene
from sbrdf_xr.engine.plan import compile_plan
from sbrdf_xr.engine.run import simulate
from sbrdf_xr.errors import SceneError
from sbrdf_xr.materials import tables as material

# Sums of a few float64 products: agreement with independent evaluations to 1e-12
# relative is ~1e4 ulps of margin for reordering.
RTOL = 1e-12


class _RaiseIfComputes:
    def __call__(self, dsk, keys, **kwargs):
        raise AssertionError("graph building triggered a dask computation")


def grey():
    return catalog.load("lambertian-grey-50")


def cube_scene(**kw):
    sc = T.cube_spacecraft(1.0, subdivisions=2)
    table = kw.pop("table", None)
    mats = {T.TEST_SPACECRAFT_MATERIAL: grey() if table is None else table}
    return Scene(sc, materials=mats, **kw)


def test_lambertian_cube_matches_closed_form():
    """Convex unit cube, Lambertian 0.5.

    S = (0.5/pi) sum_faces cos_i cos_r over lit+visible faces.
    """
    rng = np.random.default_rng(0)
    s = rng.normal(size=(40, 3))
    o = rng.normal(size=(40, 3))
    s /= np.linalg.norm(s, axis=1, keepdims=True)
    o /= np.linalg.norm(o, axis=1, keepdims=True)
    ds = simulate(cube_scene(to_sun=s, to_observer=o, chunk=16)).compute()
    faces = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
    ci, cr = s @ faces.T, o @ faces.T
    on = (ci > 0) & (cr > 0)
    expected = 0.5 / np.pi * np.where(on, ci * cr, 0).sum(1)
    area = np.where(on, cr, 0).sum(1)
    np.testing.assert_allclose(ds.signal.isel(wavelength=0), expected, rtol=1e-6)  # float32 table
    np.testing.assert_allclose(ds.area, area, rtol=RTOL, atol=1e-15)
    some = area > 0
    np.testing.assert_allclose(ds.spacecraft_sbrdf.isel(wavelength=3)[some], 0.5 / np.pi, rtol=1e-6)
    assert ds.signal.attrs["units"] == "m2 sr-1" and ds.spacecraft_sbrdf.attrs["units"] == "sr-1"
    np.testing.assert_allclose(ds.phase_angle, geometry.phase_angle(s, o))


def test_nothing_contributes_gives_zero_not_nan():
    """Forward scatter on a convex body: no facet is both lit and visible (0/0 of Eq. 4)."""
    s = np.array([[1.0, 0.0, 0.0], [0.0, 0.6, 0.8]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ds = simulate(cube_scene(to_sun=s, to_observer=-s)).compute()
    assert np.all(ds.area == 0) and np.all(ds.spacecraft_sbrdf == 0) and np.all(ds.signal == 0)
    assert np.all(np.isfinite(ds.brdf))


def test_merged_equals_per_facet_and_independent_numpy_loop():
    lobe = catalog.load("example-lobe")
    q = geometry.uniform_attitudes(30, seed=3)
    scene = cube_scene(table=lobe, attitudes=q, phase_angles=[10.0, 40.0, 100.0], chunk=7)
    merged = simulate(scene).compute()
    per_facet = simulate(scene, merge=False).compute()
    xr.testing.assert_allclose(merged, per_facet, rtol=RTOL, atol=1e-14)
    # Straightforward per-facet evaluation with the public lookup wrapper.
    f = scene.spacecraft.facets()
    s, o = scene.body_vectors()
    ref = np.zeros_like(merged.signal.values)
    for j in range(f.sizes["facet"]):
        n = f.normal.values[j]
        ang = geometry.facet_angles(n, s, o)
        spec = material.lookup(lobe, ang.theta_i, ang.delta_theta, ang.phi).values
        w = f.area.values[j] * np.clip(s @ n, 0, None) * np.clip(o @ n, 0, None)
        ref += (w * (ang.lit & ang.visible))[..., None] * spec
    np.testing.assert_allclose(merged.signal.values, ref, rtol=1e-10, atol=1e-14)


def test_simulate_builds_a_lazy_graph():
    scene = cube_scene(attitudes=geometry.uniform_attitudes(20), phase_angles=[30.0], chunk=5)
    with dask.config.set(scheduler=_RaiseIfComputes()):
        ds = simulate(scene)
    assert ds.signal.chunks[0] == (5, 5, 5, 5)
    assert len(ds.signal.chunks[-1]) == 1  # wavelength whole
    eager = simulate(scene).compute(scheduler="sync")
    threaded = ds.compute(scheduler="threads")
    xr.testing.assert_identical(eager, threaded)


def test_a_lazy_cube_makes_its_directions_by_block_with_the_same_bits():
    """Over attitudes x phase angles a lazy cube's body-frame directions come from the
    block tasks (no array over every attitude when it is built), equal bit for bit to
    those the in-process cube computes at once."""
    scene = cube_scene(
        attitudes=geometry.uniform_attitudes(23, seed=4), phase_angles=[10.0, 75.0], chunk=7
    )
    plan = scene.plan()
    with dask.config.set(scheduler=_RaiseIfComputes()):
        lazy = simulate(plan, lazy=True)
    assert "template" not in plan.cache  # nothing made for every attitude at once
    for name in ("to_sun", "to_observer"):
        assert lazy[name].chunks == ((7, 7, 7, 2), (2,), (3,))
        assert name in lazy.coords
    eager = simulate(plan, lazy=False)
    assert isinstance(eager.to_sun.data, np.ndarray)
    computed = lazy.compute(scheduler="threads")
    xr.testing.assert_identical(computed, eager)
    for name in ("to_sun", "to_observer"):
        assert computed[name].values.tobytes() == eager[name].values.tobytes()
    assert list(computed.variables) == list(eager.variables)  # the same order


def test_plan_says_what_runs_and_why():
    scene = cube_scene(
        attitudes=geometry.rotation_sweep([0, 0, 1], np.arange(0, 360, 30.0)),
        phase_angles=[20.0],
        effects=("sunlight", "shadowing"),
    )
    plan = scene.plan()
    text = str(plan)
    assert "skipped: the body is convex" in text
    assert "merged by (normal, material)" in text and "48 facets -> 6 terms" in text
    # A rotation about z in the xy-plane never lights the +-z faces: they are dropped.
    assert "2 terms that never contribute" in text
    assert plan.terms.size == 4


def test_shadowing_on_a_non_convex_body_runs_per_facet():
    sc = T.l_shaped_spacecraft()
    s = np.array([[2.0, -1.0, 0.0]]) / np.sqrt(5.0)
    scene = Scene(
        sc,
        materials={T.TEST_SPACECRAFT_MATERIAL: grey()},
        to_sun=s,
        to_observer=[[1.0, 0.0, 0.0]],
        effects=("sunlight", "shadowing"),
        shadow_method="sampled",
        shadow_density=6,
    )
    plan = compile_plan(scene)
    assert plan.shadowing and not plan.merged
    assert "sampled self-shadowing" in str(plan)
    with pytest.raises(SceneError, match="cannot be merged while self-shadowing"):
        compile_plan(scene.with_options(merge=True))
    shadowed = simulate(scene).compute()
    plain = simulate(scene.with_options(effects=("sunlight",))).compute()
    # Seen from +x, the outer face x = 2 and the inner face x = 1 (y in [1, 2]) each
    # project 2 m2 (depth 2 m).  Sun along (2, -1, 0): a point (1, y) of the inner face
    # is shadowed by the lower arm when y <= 1.5, so half of that face is dark.
    assert float(plain.area[0]) == pytest.approx(4.0, rel=RTOL)
    # Sub-facet sampling resolves the shadow edge to about one sample spacing.
    assert float(shadowed.area[0]) == pytest.approx(3.0, abs=0.2)


def test_presets_and_float32():
    scene = cube_scene(attitudes=geometry.uniform_attitudes(10), phase_angles=[45.0])
    fast = simulate(scene, preset="fast").compute()
    ref = simulate(scene, preset="balanced").compute()
    assert fast.signal.dtype == np.float32
    np.testing.assert_allclose(fast.signal, ref.signal, rtol=1e-5, atol=1e-7)
    with pytest.raises(SceneError, match="preset: unknown 'slow'"):
        scene.with_options(preset="slow")


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"outputs": ("spacecraft_sbrdf", "colour")}, "outputs: unknown"),
        ({"effects": ("sunlight", "moonshine")}, "effects: unknown"),
        ({"method": "quintic"}, "method: got .quintic.; allowed: nearest, linear, cubic"),
        ({"to_sun": [[2.0, 0, 0]], "to_observer": [[1.0, 0, 0]]}, "unit vectors"),
        ({"to_sun": [[0.0, 0, 0]], "to_observer": [[1.0, 0, 0]]}, "unit vectors"),
        ({"attitudes": [[0, 0, 0, 2.0]], "phase_angles": [10.0]}, "quaternion"),
        ({"attitudes": [[0, 0, 0, 1.0]]}, "needs both attitudes and phase_angles"),
        ({}, "give either attitudes and phase_angles"),
        (
            {
                "attitudes": [[0, 0, 0, 1.0]],
                "phase_angles": [10.0],
                "to_sun": [[1.0, 0, 0]],
                "to_observer": [[1.0, 0, 0]],
            },
            "not several",
        ),
    ],
)
def test_bad_scenes_raise_scene_errors(kw, match):
    with pytest.raises(SceneError, match=match):
        cube_scene(**kw)


def test_missing_material_table():
    sc = T.cube_spacecraft()
    with pytest.raises(SceneError, match="no table for"):
        Scene(sc, materials={"other": grey()}, to_sun=[[1.0, 0, 0]], to_observer=[[1.0, 0, 0]])


# ------------------------------------------------------------- bands, earthshine, thermal


def test_band_pre_integration_equals_spectral_path():
    """Band-only scenes integrate the tables over the bands before the sweep: exact."""
    q = geometry.uniform_attitudes(12, seed=4)
    common = dict(attitudes=q, phase_angles=[20.0, 70.0], bands=("V", "R", "I"))
    pre = cube_scene(outputs=("band_signal", "area"), **common)
    spectral = cube_scene(outputs=("signal", "band_signal", "area"), **common)
    assert "pre-integrated" in str(pre.plan()) and "from the spectral signal" in str(
        spectral.plan()
    )
    a = simulate(pre).compute()
    b = simulate(spectral).compute()
    assert "wavelength" not in a.dims and a.band_signal.dims == ("attitude", "phase_angle", "band")
    np.testing.assert_allclose(a.band_signal, b.band_signal, rtol=RTOL, atol=1e-15)
    # A grey Lambertian: the band mean of a flat signal is the signal itself.
    np.testing.assert_allclose(a.band_signal.isel(band=0), b.signal.isel(wavelength=10), rtol=1e-6)


def test_bands_outside_the_material_wavelengths_need_an_explicit_extrapolation():
    with pytest.raises(SceneError, match="bands: band 'U'"):
        cube_scene(
            to_sun=[[1.0, 0, 0]], to_observer=[[1.0, 0, 0]], outputs=("band_signal",), bands=("U",)
        ).plan()
    scene = cube_scene(
        to_sun=[[1.0, 0, 0]],
        to_observer=[[1.0, 0, 0]],
        outputs=("band_signal",),
        bands=("U",),
        band_extrapolate="constant",
    )
    assert np.isfinite(simulate(scene).compute().band_signal).all()


def test_earthshine_is_a_second_lambertian_source():
    """Earth straight behind the observer of a Lambertian cube: earthshine = ratio x the
    signal the cube would give with the Sun there (closed form of the Lambert sphere)."""
    from sbrdf_xr.sources import earthshine_irradiance_ratio

    s = np.array([[1.0, 0.0, 0.0]])
    o = np.array([[0.0, 1.0, 0.0]])
    e = np.array([[0.0, 0.6, 0.8]])
    es = simulate(
        cube_scene(
            to_sun=s,
            to_observer=o,
            to_earth=e,
            effects=("sunlight", "earthshine"),
            earth_albedo=0.3,
            earth_range=42164.0,
            earth_phase_angle=60.0,
            earth_model="point",  # the finite Earth: tests/engine/test_earthshine_finite.py
        )
    ).compute()
    ratio = earthshine_irradiance_ratio(0.3, 42164.0, 60.0)
    a = np.radians(60.0)
    assert ratio == pytest.approx(
        2 / 3 * 0.3 * (6371 / 42164) ** 2 * ((np.pi - a) * np.cos(a) + np.sin(a)) / np.pi
    )
    # faces +y (cos_e 0.6, cos_r 1) and +z (cos_e 0.8, cos_r 0) -> only +y counts
    np.testing.assert_allclose(
        es.signal_earthshine.isel(wavelength=0), ratio * 0.5 / np.pi * 0.6, rtol=1e-6
    )
    assert float(es.signal.isel(wavelength=0, geometry=0)) == 0.0  # the Sun lights +x, unseen
    with pytest.raises(SceneError, match="to_earth"):
        cube_scene(to_sun=s, to_observer=o, effects=("sunlight", "earthshine"))


def test_thermal_emission_is_kirchhoff_times_planck_and_skipped_when_negligible():
    from sbrdf_xr.sources import planck

    wl = np.array([5000.0, 10000.0])
    # Planck at 300 K peaks near 9.7 um: B(10 um) = 9.92 W m-2 sr-1 um-1 (tables).
    assert planck(wl, 300.0)[1] == pytest.approx(9.92e-3, rel=2e-3)
    assert planck(np.array([10.0]), 300.0)[0] == 0.0  # exp(-4800) underflows, no warning
    lam = catalog.load("lambertian-grey-50")
    base = dict(to_sun=[[1.0, 0, 0]], to_observer=[[1.0, 0, 0]], effects=("sunlight", "thermal"))
    plan = cube_scene(**base, temperature=300.0).plan()
    assert "skipped: negligible" in str(plan) and "thermal" not in plan.effects
    hot = cube_scene(**base, temperature=900.0)
    plan = hot.plan()
    assert "thermal" in plan.effects
    cube = simulate(hot).compute()
    # Only the +x face (1 m2) is seen, face on: I = 1 m2 x (1 - 0.5) x B(lambda, 900 K).
    expected = 0.5 * planck(cube.wavelength.values, 900.0)
    np.testing.assert_allclose(cube.thermal_intensity.isel(geometry=0), expected, rtol=1e-5)
    assert lam.attrs["material"]


def test_simulation_on_a_local_cluster_equals_the_threaded_run(tmp_path):
    """The tables are scattered to the workers once; the cube is identical to the threaded one."""
    distributed = pytest.importorskip("distributed")
    from sbrdf_xr.store import write

    scene = cube_scene(
        table=catalog.load("example-lobe"),
        attitudes=geometry.uniform_attitudes(40, seed=9),
        phase_angles=[15.0, 60.0],
        chunk=10,
    )
    threaded = write(simulate(scene), tmp_path / "threads.nc")
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        cube = simulate(scene, client=client)
        on_cluster = write(cube, tmp_path / "cluster.nc", client=client)
        # a cube made without the client: its graph holds the plan, which the writer
        # scatters to the workers once (with its tables as handles to their mapped files)
        plain = write(simulate(scene), tmp_path / "plain.nc", client=client)
    with xr.open_dataset(threaded) as a, xr.open_dataset(on_cluster) as b:
        xr.testing.assert_identical(a.load(), b.load())
    with xr.open_dataset(threaded) as a, xr.open_dataset(plain) as b:
        xr.testing.assert_identical(a.load(), b.load())


def test_materials_without_common_wavelengths_are_rejected():
    sc = T.cube_spacecraft()
    short = T.make_material(n_wavelength=3).assign_coords(
        wavelength=np.array([2000.0, 2100.0, 2200.0])
    )
    short.wavelength.attrs.update(units="nm", long_name="vacuum wavelength")
    other = T.make_material(n_wavelength=3)
    from sbrdf_xr.body.spacecraft import load_spacecraft

    mesh = sc.mesh.copy()
    mesh.visual.face_colors = np.where(
        np.arange(len(mesh.faces))[:, None] < 6, [255, 0, 0, 255], [0, 0, 255, 255]
    )
    two = load_spacecraft(mesh, {(255, 0, 0): "a", (0, 0, 255): "b"})
    scene = Scene(
        two, materials={"a": short, "b": other}, to_sun=[[1.0, 0, 0]], to_observer=[[0.0, 0, 1.0]]
    )
    with pytest.raises(SceneError, match="no wavelengths in common"):
        simulate(scene)


def _cube_coordinates_as_xarray_builds_them(plan):
    """The cube's coordinates through ``xr.Dataset(coords=...)`` (alignment and merging)."""
    from sbrdf_xr._names import attrs

    coords = plan.geometry.coords()
    coords["xyz"] = ("xyz", ["x", "y", "z"], attrs("xyz"))
    coords["wavelength"] = ("wavelength", plan.wavelength, attrs("wavelength"))
    coords.update(plan.band_coords)
    coords["material"] = ("material", list(plan.materials), attrs("material"))
    return coords, xr.Dataset(coords=coords, attrs=dict(plan.attrs))


@pytest.mark.parametrize("kind", ["grid", "pairs with bands", "observation"])
def test_cube_coordinates_are_those_xarray_would_build(kind):
    from sbrdf_xr.engine.builtin import builtin_scene
    from sbrdf_xr.engine.run import _coordinates_only

    if kind == "grid":
        scene = cube_scene(
            attitudes=geometry.axis_rotation([0, 0, 1], [0.0, 45.0]),
            phase_angles=[0.0, 60.0],
            attitude_angle=[0.0, 45.0],
        )
    elif kind == "pairs with bands":
        scene = cube_scene(
            to_sun=[[1.0, 0, 0], [0, 1.0, 0]],
            to_observer=[[1.0, 0, 0]] * 2,
            bands=("V", "R"),
            outputs=("signal", "band_signal"),
        )
    else:
        scene = builtin_scene("canx1-pass").with_options(
            materials={m: grey() for m in ("aluminium-6061-t6", "tjpv-cell", "white-paint-a276")}
        )
    coords, expected = _cube_coordinates_as_xarray_builds_them(scene.plan())
    built = _coordinates_only(coords, dict(expected.attrs))
    xr.testing.assert_identical(built, expected)
    assert list(built.variables) == list(expected.variables)  # the same order
    for k, v in expected.variables.items():
        assert type(built.variables[k]) is type(v) and built[k].dtype == v.dtype
        assert type(built.xindexes.get(k)) is type(expected.xindexes.get(k))
    again = _coordinates_only(coords, dict(expected.attrs))  # with the kept indexes
    xr.testing.assert_identical(again, expected)
