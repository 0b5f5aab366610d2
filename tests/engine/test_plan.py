"""Tests of sbrdf_xr.engine.plan, sbrdf_xr.engine.knobs and sbrdf_xr.engine.effects: the plan is
data."""

from __future__ import annotations

import dask
import numpy as np
import pytest
import xarray as xr

from sbrdf_xr import catalog, geometry
from sbrdf_xr import testing as T
from sbrdf_xr.engine import Scene, knobs
from sbrdf_xr.engine.effects import EFFECTS, OUTPUTS
from sbrdf_xr.engine.plan import Plan
from sbrdf_xr.engine.run import simulate
from sbrdf_xr.errors import SceneError
from sbrdf_xr.store import write

RTOL = 1e-12  # reordered float64 sums (see tests/test_kernels.py)


class _RaiseIfComputes:
    def __call__(self, dsk, keys, **kwargs):
        raise AssertionError("graph building triggered a dask computation")


def scene(**kw):
    sc = T.cube_spacecraft(1.0, subdivisions=2)
    table = kw.pop("table", None)
    mats = {T.TEST_SPACECRAFT_MATERIAL: catalog.load("example-lobe") if table is None else table}
    kw.setdefault("attitudes", geometry.uniform_attitudes(30, seed=4))
    kw.setdefault("phase_angles", [20.0, 70.0])
    return Scene(sc, materials=mats, **kw)


def test_plan_fields_describe_what_runs():
    p = scene().plan()
    assert isinstance(p, Plan)
    assert p.merged and not p.shadowing and p.effects == ("sunlight",)
    assert p.terms.size == 6 and int(p.terms.n_facets.sum()) == 48
    assert p.materials == (T.TEST_SPACECRAFT_MATERIAL,)
    assert p.output_names == ("spacecraft_sbrdf", "signal", "brdf", "area")
    out = {o.name: o for o in p.outputs}
    assert out["signal"].dims == ("attitude", "phase_angle", "wavelength")
    assert out["signal"].shape == (30, 2, p.wavelength.size)
    assert out["signal"].attrs["units"] == "m2 sr-1" and out["area"].dtype == np.float64
    assert p.knobs["method"] == "linear" and p.knobs["kernel"] == "fused"
    assert p.estimate.n_geometries == 60 and p.estimate.output_bytes == sum(
        o.nbytes for o in p.outputs
    )
    assert p.n_blocks == 1 and p.chunk == 30  # a small scene is one block
    with pytest.raises(AttributeError):
        p.chunk = 3  # frozen
    assert not p.terms.normal.flags.writeable


def test_plan_is_cached_and_options_make_a_new_one():
    s = scene()
    assert s.plan() is s.plan()
    assert s.with_options(method="cubic").plan() is not s.plan()


def test_band_only_scene_pre_integrates_and_equals_the_spectral_route():
    s = scene(outputs=("band_signal", "area"), bands=("V", "R", "I"))
    p = s.plan()
    assert p.pre_integrated and p.tables.n_spectral == 3
    assert p.output_names == ("band_signal", "area")
    assert any("pre-integrated" in why for _, why in p.steps)
    pre = simulate(s).compute()
    spectral = simulate(s, band_integration="spectral").compute()
    assert not spectral.attrs["plan"].count("pre-integrated over")
    # linear look-up and a linear band integral commute: exact to rounding
    np.testing.assert_allclose(pre.band_signal, spectral.band_signal, rtol=1e-11, atol=1e-18)


def test_in_process_and_lazy_cubes_are_identical():
    s = scene()
    eager = simulate(s)
    assert not any(isinstance(v.data, dask.array.Array) for v in eager.variables.values())
    with dask.config.set(scheduler=_RaiseIfComputes()):
        lazy = simulate(s, lazy=True)
    assert lazy.signal.chunks is not None
    xr.testing.assert_identical(eager, lazy.compute())
    xr.testing.assert_identical(eager, simulate(s.plan()))


def test_one_task_per_block_and_the_plan_once_in_the_graph():
    s = scene(chunk=7)
    cube = simulate(s)
    graph = dict(cube.__dask_graph__())
    blocks = [k for k in graph if isinstance(k, tuple) and str(k[0]).startswith("sbrdf-block-")]
    plans = [k for k, v in graph.items() if isinstance(v, Plan)]
    assert len(blocks) == 5 and len(plans) == 1  # 30 attitudes in blocks of 7


def test_knob_table_and_presets():
    assert set(knobs.PRESETS) == {"fast", "balanced", "reference"}
    for preset in knobs.PRESETS.values():
        for k, v in preset.items():
            assert knobs.check_knob(k, v) == v
    s = scene().with_options(preset="reference")
    assert s.method == "cubic" and s.shadow_method == "exact"
    assert "shadow_method" in knobs.knob_table()
    with pytest.raises(SceneError, match="shadow_density: got 100000"):
        scene(shadow_density=100_000)
    with pytest.raises(SceneError, match="preset: unknown 'slow'"):
        scene().with_options(preset="slow")
    with pytest.raises(SceneError, match="kernel: got 'gpu'; allowed: fused, numpy"):
        scene(kernel="gpu")


def test_a_plan_beyond_reason_is_refused_before_anything_is_allocated():
    # 1e6 attitudes x 2e5 "wavelengths" of a synthetic table: 3.2 TB of outputs
    big = T.make_material(n_wavelength=3)
    s = Scene(
        T.cube_spacecraft(),
        materials={T.TEST_SPACECRAFT_MATERIAL: big},
        attitudes=geometry.uniform_attitudes(200, seed=1),
        phase_angles=np.linspace(1, 179, 5000),
        outputs=("signal", "area"),
    )
    with pytest.raises(SceneError, match=r"beyond reason: .* raise the limits with size_limit"):
        s.with_options(size_limit=1e-9).plan()
    assert s.with_options(size_limit=1.0).plan().estimate.n_geometries == 1_000_000


def test_wavelength_stride_and_table_resolution_knobs():
    s = scene()
    full = s.plan()
    half = s.with_options(wavelength_stride=2).plan()
    np.testing.assert_array_equal(half.wavelength, full.wavelength[::2])
    coarse = s.with_options(table_theta_step=10.0).plan()
    assert coarse.tables.shapes[0][0] == 10  # 0, 10, ..., 90
    assert any("resampled every 10 deg" in why for _, why in coarse.steps)


def test_analytic_evaluation_is_a_simulation_option():
    """A Lambertian model against a Lambertian table: the same sums (the table is exact)."""
    lam = catalog.load("lambertian-grey-50")
    from sbrdf_xr.materials import models

    spec = models.model_material(
        "lambert",
        lam.wavelength.values,
        rho=0.5,
        material="grey",
        provenance="albedo 0.5, as the lambertian-grey-50 table",
    )
    s = scene(table=lam, models={T.TEST_SPACECRAFT_MATERIAL: spec})
    a = simulate(s, evaluation="analytic")
    t = simulate(s)
    np.testing.assert_allclose(a.signal, t.signal, rtol=1e-6)


def test_every_effect_and_output_is_declared_once_with_attrs():
    for o in OUTPUTS.values():
        assert o.units and o.long_name
    for e in EFFECTS.values():
        assert all(v in OUTPUTS for v in e.outputs)
    s = scene(effects=("sunlight", "earthshine"))
    cube = simulate(s)
    for v in cube.data_vars:
        assert cube[v].attrs == OUTPUTS[v].attrs


def test_zarr_store_by_blocks_equals_netcdf(tmp_path):
    pytest.importorskip("zarr")
    cube = simulate(scene(chunk=8))
    nc = write(cube, tmp_path / "c.nc")
    zs = write(cube, tmp_path / "c.zarr")
    assert not (tmp_path / "c.zarr.part").exists()
    with xr.open_dataset(nc) as a, xr.open_zarr(zs) as b:
        xr.testing.assert_identical(a.load(), b.load())
    with pytest.raises(FileExistsError):
        write(cube, tmp_path / "c.zarr")


def test_simulate_refuses_a_plan_mixed_with_options():
    s = scene()
    with pytest.raises(SceneError, match="already compiled"):
        simulate(s.plan(), method="cubic")
    with pytest.raises(SceneError, match="not this scene's own plan"):
        simulate(s, plan=scene(method="cubic").plan())


def test_tilt_quadrature_is_the_gaussian_expectation():
    """Moments of the product Gauss-Hermite rule: E[t] = 0, E[t_i t_j] = sigma^2 delta_ij,
    E[|t|^4] = 8 sigma^4 (exact for these polynomial moments with >= 3 nodes)."""
    from sbrdf_xr.body.imperfections import tilt_quadrature, tilted_normals

    sig = np.radians(3.0)
    t, w = tilt_quadrature(3.0, 4)
    np.testing.assert_allclose(w @ t, 0.0, atol=1e-15)
    np.testing.assert_allclose(
        (w[:, None, None] * t[:, :, None] * t[:, None, :]).sum(0),
        sig**2 * np.eye(2),
        rtol=1e-12,
        atol=1e-18,
    )
    np.testing.assert_allclose(w @ ((t**2).sum(1) ** 2), 8 * sig**4, rtol=1e-12)
    n = tilted_normals(np.array([[0.0, 0.0, 1.0]]), t)[0]
    np.testing.assert_allclose(
        np.degrees(np.arccos(np.clip(n[:, 2], -1, 1))), np.degrees(np.hypot(*t.T)), rtol=1e-9
    )
    t0, w0 = tilt_quadrature(0.0, 7)
    assert t0.shape == (1, 2) and w0[0] == 1.0


def test_surface_tilt_zero_is_exact_and_matches_monte_carlo_over_perturbed_facets():
    """The quadrature expectation against Monte Carlo over randomly tilted facets of the
    same mesh (independent random draws, not a denser quadrature)."""
    from sbrdf_xr.kernels.sums import fused_sums

    lobe = catalog.load("example-lobe")
    s = scene(
        table=lobe,
        attitudes=geometry.uniform_attitudes(12, seed=8),
        phase_angles=[8.0, 40.0],
        merge=False,
    )
    flat = simulate(s)
    same = simulate(s, surface_tilt=0.0, tilt_nodes=9)
    xr.testing.assert_identical(flat.signal, same.signal)
    sigma = 2.0
    rough = simulate(s, surface_tilt=sigma, tilt_nodes=12).signal.values
    p = s.plan()
    b = p.geometry.block(slice(None))
    rng = np.random.default_rng(0)
    from sbrdf_xr.body.imperfections import tilted_normals

    draws = []
    for _ in range(400):
        tilt = rng.normal(0.0, np.radians(sigma), (p.terms.size, 1, 2))
        nrm = tilted_normals(p.terms.normal, tilt)[:, 0]
        draws.append(
            fused_sums(
                b.to_sun, b.to_observer, nrm, p.terms.area, p.terms.material, p.tables, "linear"
            ).signal
        )
    draws = np.array(draws).reshape(400, *rough.shape)
    mean, se = draws.mean(0), draws.std(0) / np.sqrt(400)
    # 5 standard errors (plus the quadrature's own small error, 1e-3 of the peak)
    assert np.all(np.abs(rough - mean) <= 5 * se + 1e-3 * np.abs(mean).max())
    assert "Gauss-Hermite" in simulate(s, surface_tilt=sigma).attrs["plan"]


def test_workers_write_their_own_zarr_blocks_on_a_local_cluster(tmp_path):
    distributed = pytest.importorskip("distributed")
    pytest.importorskip("zarr")
    s = scene(chunk=6)
    ref = simulate(s).compute()
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        # every variable written (outputs="all"), to compare with the cube as simulated
        path = write(simulate(s, client=client), tmp_path / "c.zarr", client=client, outputs="all")
    with xr.open_zarr(path) as back:
        xr.testing.assert_identical(back.load(), ref)
