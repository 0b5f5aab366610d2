"""The fused compiled kernel against its numpy reference (sbrdf_xr.kernels.sums).

``material_sums`` (numpy + scipy.sparse, built on ``geometry.facet_angles`` and
``_lut.lookup_matrix``) is the specification; ``fused_sums`` must give the same sums
on random scenes and on the hard cases of DESIGN.md.

Tolerances: both evaluate the same products of float64 weights and table values and
differ only in the order of the additions.  With at most a few hundred terms of one
sign (nearest, linear) the difference is a few ulps of the largest partial sum: 1e-12
relative to the largest value leaves ~1e4 ulps of margin.  Cubic weights have both
signs, so the bound is taken relative to the sum of absolute contributions, which the
largest output bounds within the factor the Lagrange weights can reach (< 2 per axis).
float32: the reference rounds its weights to float32 before the product and the fused
kernel accumulates in float32: 1e-5 relative (~100 ulps) bounds both.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from hypothesis_profiles import examples

from sbrdf_xr import geometry
from sbrdf_xr import testing as T
from sbrdf_xr.kernels import fused_sums, material_sums, pack_tables

RTOL = {"float64": 1e-12, "float32": 1e-5}


def _tables(seed: int, n_mat: int, dtype: str, edges=None):
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n_mat):
        nt, nd, npp = rng.integers(2, 7), rng.integers(2, 7), rng.integers(2, 6)
        tg = np.sort(rng.choice(np.arange(0, 91), nt, replace=False)).astype(float)
        tg[0], tg[-1] = 0.0, 90.0
        dg = np.sort(rng.uniform(-60, 60, nd))
        pg = np.sort(rng.uniform(0, 40, npp))
        pg[0] = 0.0
        v = rng.uniform(0, 2, (nt, nd, npp, 5)).astype(dtype)
        e = tuple(bool(x) for x in rng.integers(0, 2, 3)) if edges is None else edges
        blend = float(rng.choice([0.0, 5.0, 20.0]))
        out.append((v, tg, dg, pg, e, blend))
    return out


def _unit(rng, n):
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _compare(s, o, normals, areas, mat, tables, method, dtype, fraction=None):
    packed = pack_tables(tables, 5, dtype)
    got = fused_sums(s, o, normals, areas, mat, packed, method, fraction, per_material=True)
    assert got.signal.dtype == np.dtype(dtype) and got.per_material.dtype == np.dtype(dtype)
    sig = np.zeros_like(got.signal, dtype=np.float64)
    pap = np.zeros_like(sig)
    area = np.zeros(s.shape[0])
    for m, (v, tg, dg, pg, e, blend) in enumerate(tables):
        sel = mat == m
        r = material_sums(
            s,
            o,
            normals[sel],
            areas[sel],
            v,
            tg,
            dg,
            pg,
            method,
            None if fraction is None else fraction[:, sel],
            e,
            blend,
        )
        scale = max(np.abs(r.signal).max(), 1e-300)
        np.testing.assert_allclose(
            got.per_material[:, m], r.signal, rtol=0, atol=RTOL[dtype] * scale
        )
        sig += r.signal
        pap += r.paper
        area += r.area
    for a, b in ((got.signal, sig), (got.paper, pap)):
        np.testing.assert_allclose(a, b, rtol=0, atol=RTOL[dtype] * max(np.abs(b).max(), 1e-300))
    np.testing.assert_allclose(got.area, area, rtol=1e-13, atol=1e-15)
    assert np.all(np.isfinite(got.signal)) and np.all(got.signal >= 0)


@settings(max_examples=examples(40), deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    method=st.sampled_from(["nearest", "linear", "cubic"]),
    dtype=st.sampled_from(["float64", "float32"]),
    n_mat=st.integers(1, 3),
    shadowed=st.booleans(),
)
def test_fused_kernel_equals_the_numpy_reference_on_random_scenes(
    seed, method, dtype, n_mat, shadowed
):
    rng = np.random.default_rng(seed)
    tables = _tables(seed, n_mat, dtype)
    n_terms, n_geom = int(rng.integers(1, 30)), int(rng.integers(1, 40))
    normals = _unit(rng, n_terms)
    areas = rng.uniform(0, 2, n_terms)
    mat = np.sort(rng.integers(0, n_mat, n_terms))
    frac = rng.uniform(0, 1, (n_geom, n_terms)) if shadowed else None
    _compare(
        _unit(rng, n_geom), _unit(rng, n_geom), normals, areas, mat, tables, method, dtype, frac
    )


@pytest.mark.parametrize("dtype", ["float64", "float32"])
@pytest.mark.parametrize("method", ["nearest", "linear", "cubic"])
def test_hard_geometries(method, dtype):
    """Normal incidence (and the observer on the normal too), exact specular, back-scatter,
    forward scatter, grazing, the horizon, zero-area facets, nothing contributing."""
    n = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    areas = np.array([1.0, 0.0, 2.0, 0.5])  # a zero-area facet
    tiny = 1e-9
    pairs = []
    for ti, dt, ph in [
        (0.0, 0.0, 0.0),
        (0.0, 30.0, 10.0),
        (1e-12, 5.0, 0.0),
        (40.0, 0.0, 0.0),
        (60.0, -60.0, 0.0),
        (89.999, 0.0, 0.0),
        (30.0, 59.9999, 0.0),
        (45.0, -3.0, 80.0),
    ]:
        _, s, o = geometry.facet_vectors(ti, dt, ph)
        pairs.append((s, o))
    z = np.array([0.0, 0.0, 1.0])
    pairs += [
        (z, z),
        (z, -z),
        (np.array([np.sin(tiny), 0, np.cos(tiny)]), z),
        (np.array([1.0, 0, 0]), np.array([-1.0, 0, 0])),
    ]
    s = np.array([p[0] for p in pairs])
    o = np.array([p[1] for p in pairs])
    tables = _tables(3, 2, dtype, edges=(True, True, True))
    _compare(s, o, n, areas, np.array([0, 0, 1, 1]), tables, method, dtype)


def test_normal_incidence_is_continuous_and_plane_follows_the_observer():
    """Below the normal-incidence tolerance the plane is taken through the observer, as
    geometry.facet_angles does; the fused kernel must match it on both sides."""
    tables = _tables(5, 1, "float64", edges=(False, False, False))
    o = np.array([[np.sin(0.5), 0.0, np.cos(0.5)]])
    n = np.array([[0.0, 0.0, 1.0]])
    for eps in (0.0, 1e-14, 1e-11, 1e-8, 1e-5):
        for az in np.linspace(0, 2 * np.pi, 7):
            s = np.array([[eps * np.cos(az), eps * np.sin(az), np.sqrt(1 - eps**2)]])
            _compare(s, o, n, np.ones(1), np.zeros(1, int), tables, "linear", "float64")


def test_merged_canx1_terms_match_on_a_rotation():
    """The real catalog tables and CanX-1 terms, through the whole engine and the reference."""
    from sbrdf_xr.engine import builtin_scene
    from sbrdf_xr.engine.run import simulate

    scene = builtin_scene("canx1-rotation").with_options(
        attitudes=geometry.rotation_sweep([0, 0, 1], np.arange(0, 360, 10.0)), attitude_angle=None
    )
    fused = simulate(scene).compute()
    ref = simulate(scene, kernel="numpy").compute()
    for v in ("signal", "spacecraft_sbrdf", "signal_material", "area"):
        scale = float(np.abs(ref[v]).max())
        np.testing.assert_allclose(fused[v], ref[v], rtol=0, atol=1e-12 * scale)


def test_unsorted_materials_are_refused():
    tables = _tables(1, 2, "float64")
    with pytest.raises(ValueError, match="contiguous"):
        fused_sums(
            np.eye(3)[:1],
            np.eye(3)[:1],
            np.eye(3)[:2],
            np.ones(2),
            np.array([1, 0]),
            pack_tables(tables, 5),
            "linear",
        )


def test_cube_spacecraft_through_both_kernels():
    from sbrdf_xr import catalog
    from sbrdf_xr.engine import Scene
    from sbrdf_xr.engine.run import simulate

    sc = T.cube_spacecraft(1.0, subdivisions=2)
    scene = Scene(
        sc,
        materials={T.TEST_SPACECRAFT_MATERIAL: catalog.load("example-lobe")},
        attitudes=geometry.uniform_attitudes(25, seed=2),
        phase_angles=[0.0, 30.0, 179.9],
        method="cubic",
        merge=False,
    )
    a = simulate(scene).compute()
    b = simulate(scene, kernel="numpy").compute()
    np.testing.assert_allclose(
        a.signal, b.signal, rtol=0, atol=1e-12 * float(np.abs(b.signal).max())
    )


@settings(max_examples=examples(200), deadline=None)
@given(
    st.lists(st.floats(-200, 200, allow_nan=False, allow_infinity=False), min_size=1, max_size=40),
    st.lists(st.floats(-250, 250, allow_nan=False, allow_infinity=False), max_size=30),
    st.integers(0, 2),
)
# found by the deep profile: two nodes 6.1e-5 apart among nodes 190 wide give cubic
# weights of 1e7 whose sum carries 4e-9 of rounding
@example(nodes=[0.0, 1.0, 6.103515625e-05, -190.0], xs=[-27.0], method=2)
def test_bucket_map_finds_the_same_cell_as_searchsorted(nodes, xs, method):
    """The kernel's axis look-up (bucket map + correcting steps) is exactly the clipped
    ``searchsorted(grid, x, "right") - 1`` of ``_lut.axis_weights``, also at nodes,
    between nodes closer than the bucket width and outside the grid."""
    from sbrdf_xr.kernels.lookup import _Axis, _axis
    from sbrdf_xr.kernels.packing import bucket_map

    # nodes at least 1e-6 degree apart (table grids are; closer nodes make the cubic
    # Lagrange weights themselves overflow, whatever finds the cell)
    grid = np.unique(np.round(np.asarray(nodes, dtype=float), 6))
    n = grid.size
    bmap, inv = bucket_map(grid)
    bmap = np.stack([np.zeros_like(bmap), bmap, np.zeros_like(bmap)])  # the delta_theta row
    probes = np.concatenate([np.asarray(xs, dtype=float), grid, np.nextafter(grid, -np.inf)])
    idx2, w2 = np.zeros((3, 4), dtype=np.int64), np.zeros((3, 4))
    idx, w = idx2[1], w2[1]
    for x in probes:
        k = _axis(grid, bmap, _Axis(1, 0, n, 0, bmap.shape[1], inv), x, method, idx2, w2)
        if n == 1:
            assert (k, idx[0]) == (1, 0)
            continue
        xc = min(max(x, grid[0]), grid[-1])
        i = int(np.clip(np.searchsorted(grid, xc, side="right") - 1, 0, n - 2))
        if method == 1:
            assert (idx[0], idx[1]) == (i, i + 1)
        elif method == 0:
            t = (xc - grid[i]) / (grid[i + 1] - grid[i])
            assert idx[0] == (i + 1 if t >= 0.5 else i)
        # Each Lagrange weight is a product of three ratios (<= 6 roundings: |dw| <= 3 eps |w|)
        # and the sum of four adds <= 3 eps sum|w|: the partition of unity holds to
        # 8 eps sum|w| (1e-9 where the weights are O(1)).
        tol = max(1e-9, 8 * np.finfo(float).eps * np.abs(w[:k]).sum())
        assert abs(w[:k].sum() - 1.0) <= tol
