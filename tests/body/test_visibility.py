"""Tests of sbrdf_xr.body.visibility: exact and sampled self-shadowing and self-occlusion."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_profiles import examples
from shapely.geometry import MultiPoint, Polygon

from sbrdf_xr.body import rays
from sbrdf_xr.body import spacecraft as sc
from sbrdf_xr.body import visibility as vis
from sbrdf_xr.errors import ValidationError
from sbrdf_xr.kernels import polygon as pk
from sbrdf_xr.testing import (
    bus_with_panel_spacecraft,
    canx1_with_antennas,
    cube_spacecraft,
    l_shaped_spacecraft,
    plate_with_fin_spacecraft,
)

HAVE_EMBREE = "embree" in rays.available_engines()
needs_embree = pytest.mark.skipif(not HAVE_EMBREE, reason="embreex is not installed")

#: Agreement of the exact method with the independent reference below.  Both are float64
#: polygon clippings of the same shadows with O(10) operations per vertex, so they agree
#: to ~1e-15 of a facet; 1e-9 (the accuracy claimed) leaves room for grazing geometries
#: where a projection factor 1/N.d amplifies rounding.
EXACT_TOL = 1e-9

NONCONVEX = {
    "l-shape": l_shaped_spacecraft,
    "plate-with-fin": plate_with_fin_spacecraft,
    "bus-with-panel": bus_with_panel_spacecraft,
}


def random_directions(n: int, seed: int) -> np.ndarray:
    d = np.random.default_rng(seed).normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1, keepdims=True)


# ----------------------------------------------------------------------------- reference


def _front_part(tri: np.ndarray, n: np.ndarray, p0: np.ndarray) -> np.ndarray:
    """The part of a 3-D triangle on or in front of the plane (n, p0), as a vertex list."""
    h = (tri - p0) @ n
    out = []
    for a in range(3):
        b = (a + 1) % 3
        if h[a] >= 0:
            out.append(tri[a])
        if (h[a] >= 0) != (h[b] >= 0):
            out.append(tri[a] + (tri[b] - tri[a]) * h[a] / (h[a] - h[b]))
    return np.array(out)


def reference_fraction(craft, i: int, directions) -> float:
    """Fraction of facet ``i`` unobstructed along every direction, computed independently of
    the package: in the plane perpendicular to each direction ``d`` (not the facet's plane),
    every other facet (any orientation: no use of the closed surface) that rises in front of
    the facet's plane is cut to its front part and projected; shapely unites these with the
    projected facet's own outline and the result is carried back to the facet's plane by
    the affine map fixed by the three vertices (a 3x3 solve); there the shadows of all
    directions are united and subtracted from the facet."""
    mesh = craft.mesh
    tri = mesh.triangles[i]
    n = np.cross(tri[1] - tri[0], tri[2] - tri[0])
    n /= np.linalg.norm(n)
    scale = mesh.scale
    # facet-plane coordinates: project onto the two axes most orthogonal to n
    keep = np.argsort(np.abs(n))[:2]
    facet = Polygon(tri[:, keep])
    shadows = []
    for d in np.atleast_2d(directions):
        d = d / np.linalg.norm(d)
        if n @ d <= 0:
            return 0.0
        a = np.cross(d, [1.0, 0.0, 0.0] if abs(d[0]) < 0.9 else [0.0, 1.0, 0.0])
        a /= np.linalg.norm(a)
        b = np.cross(d, a)
        view = np.column_stack([a, b])  # 3-D -> view plane
        polys = []
        for j in range(len(mesh.faces)):
            if j == i:
                continue
            other = mesh.triangles[j]
            if ((other - tri[0]) @ n).max() <= 1e-9 * scale:
                continue
            part = _front_part(other, n, tri[0])
            poly = MultiPoint(part @ view).convex_hull
            if poly.area > 0:
                polys.append(poly)
        if not polys:
            continue
        inside = shapely.intersection(shapely.union_all(polys), Polygon(tri @ view))
        if inside.is_empty:
            continue
        # affine map from the view plane to the facet-plane coordinates
        src = np.column_stack([tri @ view, np.ones(3)])
        m = np.linalg.solve(src, tri[:, keep])
        shadows.append(
            shapely.transform(inside, lambda xy, m=m: np.column_stack([xy, np.ones(len(xy))]) @ m)
        )
    if not shadows:
        return 1.0
    return 1.0 - shapely.intersection(shapely.union_all(shadows), facet).area / facet.area


# ----------------------------------------------------------------------------- exact method


@pytest.mark.parametrize("name", sorted(NONCONVEX))
def test_exact_matches_independent_reference(name):
    """Random Sun and observer directions (not back-scatter), every facet, against the
    reference above: lit-and-visible, lit and visible fractions to EXACT_TOL."""
    craft = NONCONVEX[name]()
    s = random_directions(6, seed=21)
    o = random_directions(6, seed=22)
    joint = vis.lit_visible_fraction(craft, s, o)
    lit = vis.lit_fraction(craft, s)
    assert np.any((joint > 0) & (joint < 1)), "no partial shadow: the test would be vacuous"
    for g in range(len(s)):
        for i in range(craft.n_facets):
            ref = reference_fraction(craft, i, [s[g], o[g]])
            assert abs(joint[g, i] - ref) <= EXACT_TOL, (g, i, joint[g, i], ref)
            assert abs(lit[g, i] - reference_fraction(craft, i, s[g])) <= EXACT_TOL


def test_exact_matches_reference_on_canx1_with_antennas():
    """CanX-1 with antennas: the partly shadowed facets of 3 geometries and a sample of the
    rest (the reference is slow: O(facets) shapely operations per facet)."""
    craft = canx1_with_antennas()
    s = np.array([[0.3, 0.4, 0.9], [0.9, 0.1, 0.2], [-0.2, 0.9, 0.5]])
    o = np.array([[0.5, -0.3, 0.8], [0.8, -0.4, 0.3], [0.1, 0.7, 0.7]])
    joint = vis.lit_visible_fraction(craft, s, o)
    rng = np.random.default_rng(23)
    for g in range(len(s)):
        partial = np.flatnonzero((joint[g] > 0) & (joint[g] < 1))
        assert len(partial) >= 5
        front = np.flatnonzero(joint[g] == 1)
        for i in [*partial, *rng.choice(front, 10, replace=False)]:
            ref = reference_fraction(craft, i, [s[g], o[g]])
            assert abs(joint[g, i] - ref) <= EXACT_TOL, (g, i, joint[g, i], ref)


L_SUN = np.array([-0.37, 1.0, 0.23])


def l_floor(craft):
    n, c = craft.mesh.face_normals, craft.mesh.triangles_center
    return np.flatnonzero((n[:, 1] > 0.99) & np.isclose(c[:, 1], 1.0))


def test_l_shape_closed_form():
    """L-shaped prism, Sun s = (-0.37, 1, 0.23) (unnormalised).

    The floor y = 1, 1 <= x <= 2, 0 <= z <= 2 faces the Sun; the wall x = 1, 1 <= y <= 2
    stands on its edge x = 1.  A floor point (x, 1, z) is shadowed iff its ray p + t s meets
    the wall: t = (x - 1)/0.37 <= 1/s_y = 1 and 0 <= z + 0.23 t <= 2.  The shadow is the
    parallelogram with corners (1, 0), (1, 2), (1.37, 1.77), (1.37, -0.23) in (x, z), so the
    floor's lit fraction is 1 - a + a**2 s_z / (2 |s_x| H) with a = |s_x|/s_y = 0.37, H = 2:
    0.651275.  Every other facet is fully lit or faces away.
    """
    craft = l_shaped_spacecraft()
    floor = l_floor(craft)
    f = vis.lit_fraction(craft, L_SUN)
    area = craft.mesh.area_faces[floor]
    assert np.sum(f[floor] * area) / area.sum() == pytest.approx(
        1 - 0.37 + 0.37**2 * 0.23 / (2 * 0.37 * 2), rel=1e-12, abs=0
    )
    others = np.setdiff1d(np.arange(craft.n_facets), floor)
    np.testing.assert_array_equal(f[others], (craft.mesh.face_normals[others] @ L_SUN > 0) * 1.0)


def test_plate_with_fin_closed_form():
    """Plate [-1, 1] x [-0.1, 0] with a fin [-0.05, 0.05] x [0, 1] (xy), z in [0, 2]; Sun at
    40 deg from the plate normal toward +x.  The fin shadows the strip -0.05 - tan 40 <= x <=
    -0.05 of the left top (-1 <= x <= -0.05): lit fraction 1 - tan(40 deg)/0.95.  With the
    observer mirrored (toward -x) the right top loses the same strip and the left top its
    sun shadow; back-scatter (o = s) gives the lit fraction itself."""
    craft = plate_with_fin_spacecraft()
    t = np.radians(40.0)
    s = np.array([np.sin(t), np.cos(t), 0.0])
    o = np.array([-np.sin(t), np.cos(t), 0.0])
    n, c = craft.mesh.face_normals, craft.mesh.triangles_center
    top = (n[:, 1] > 0.99) & np.isclose(c[:, 1], 0.0)
    left, right = np.flatnonzero(top & (c[:, 0] < 0)), np.flatnonzero(top & (c[:, 0] > 0))
    a = craft.mesh.area_faces
    mean = lambda f, sel: np.sum(f[sel] * a[sel]) / a[sel].sum()  # noqa: E731
    expected = 1 - np.tan(t) / 0.95
    f = vis.lit_fraction(craft, s)
    assert mean(f, left) == pytest.approx(expected, rel=1e-12, abs=0)
    assert mean(f, right) == 1.0
    joint = vis.lit_visible_fraction(craft, s, o)
    assert mean(joint, left) == pytest.approx(expected, rel=1e-12, abs=0)
    assert mean(joint, right) == pytest.approx(expected, rel=1e-12, abs=0)
    np.testing.assert_array_equal(vis.lit_visible_fraction(craft, s, s), f)


def test_bus_with_panel_closed_form():
    """Bus [-0.5, 0.5]^3 with a panel x in [1.3, 1.34], z in [-0.9, 0.9] on a flat boom
    x in [0.5, 1.3], z in [-0.03, 0.03]; Sun s = (1, 0, tan e).  A point z of the bus's +x
    face (z in [-0.5, -0.03] or [0.03, 0.5], height 0.94) is shadowed by the panel iff
    -0.9 - 0.84 tan e <= z <= 0.9 - 0.8 tan e, and by the boom iff
    -0.03 - 0.8 tan e <= z < -0.03.  e = 10 deg: the panel covers the face, lit 0;
    e = 45 deg: lit above z = 0.1 only, (0.5 - 0.1) / 0.94; e = 70 deg: the panel's shadow
    falls below the bus (z <= -1.298) but the boom's covers the lower half, lit 0.47 / 0.94."""
    craft = bus_with_panel_spacecraft()
    n, c = craft.mesh.face_normals, craft.mesh.triangles_center
    face = np.flatnonzero((n[:, 0] > 0.99) & np.isclose(c[:, 0], 0.5) & (np.abs(c[:, 2]) > 0.03))
    a = craft.mesh.area_faces[face]
    # the +x face of the bus outside the boom's root (z in [-0.5, -0.03] and [0.03, 0.5])
    for deg, lit in ((10.0, 0.0), (45.0, (0.5 - 0.1) / 0.94), (70.0, 0.47 / 0.94)):
        s = np.array([1.0, 0.0, np.tan(np.radians(deg))])
        f = vis.lit_fraction(craft, s)[face]
        assert np.sum(f * a) / a.sum() == pytest.approx(lit, rel=1e-12, abs=1e-15), deg


# ----------------------------------------------------------------------------- properties

unit = (
    st.tuples(*[st.floats(-1, 1, allow_nan=False)] * 3)
    .filter(lambda v: 0.05 < np.linalg.norm(v))
    .map(lambda v: np.array(v) / np.linalg.norm(v))
)


@settings(max_examples=examples(40))
@given(name=st.sampled_from(sorted(NONCONVEX)), s=unit, o=unit)
def test_exact_properties(name, s, o):
    """0 <= fraction <= 1; 0 where N.s <= 0 or N.o <= 0; symmetric in Sun and observer; at
    most the lit and the visible fractions, and at least their sum minus 1."""
    craft = NONCONVEX[name]()
    f = vis.lit_visible_fraction(craft, s, o)
    assert np.all((f >= 0) & (f <= 1))
    n = craft.mesh.face_normals
    assert np.all(f[(n @ s <= 0) | (n @ o <= 0)] == 0)
    # the union of the two shadow sets is computed in another order when swapped
    np.testing.assert_allclose(vis.lit_visible_fraction(craft, o, s), f, rtol=0, atol=1e-12)
    lit, seen = vis.lit_fraction(craft, s), vis.visible_fraction(craft, o)
    assert np.all(f <= np.minimum(lit, seen) + 1e-12)
    assert np.all(f >= lit + seen - 1 - 1e-12)


@settings(max_examples=examples(25))
@given(s=unit, o=unit, subdivisions=st.integers(1, 2))
def test_exactly_one_on_convex_body(s, o, subdivisions):
    """On a convex body (coplanar facets included) nothing is shadowed: exactly 1 where the
    facet faces both directions, 0 elsewhere, with and without the convex shortcut."""
    cube = cube_spacecraft(subdivisions=subdivisions)
    n = cube.mesh.face_normals
    front = ((n @ s > 0) & (n @ o > 0)).astype(float)
    for shortcut in (True, False):
        np.testing.assert_array_equal(
            vis.lit_visible_fraction(cube, s, o, convex_shortcut=shortcut), front
        )


@settings(max_examples=examples(25))
@given(
    name=st.sampled_from(sorted(NONCONVEX)), s=unit, o=unit, step=st.tuples(*[st.floats(-1, 1)] * 3)
)
def test_signal_continuous_as_the_sun_moves(name, s, o, step):
    """The Lambertian signal S = sum A (N.s)+ (N.o)+ f is Lipschitz in the Sun direction
    (shadow edges move linearly; a facet's 1/N.s blow-up is tamed by its N.s factor): a
    1e-7 rad step changes S by at most 1e-5 of the body's total area.  (A jump, e.g. a lost
    occluder, would change it by a facet's share.)"""
    craft = NONCONVEX[name]()
    n, a = craft.mesh.face_normals, craft.mesh.area_faces

    def signal(sun):
        f = vis.lit_visible_fraction(craft, sun, o)
        return np.sum(a * np.clip(n @ sun, 0, None) * np.clip(n @ o, 0, None) * f)

    d = np.array(step)
    s2 = s + 1e-7 * d
    s2 /= np.linalg.norm(s2)
    assert abs(signal(s2) - signal(s)) <= 1e-5 * a.sum()


def test_one_sided_facets_and_own_back_faces():
    """A thin fin's two faces are back to back: the one facing the Sun is not shadowed by
    its own back face (which faces away, so it is no occluder, and lies behind its plane)."""
    craft = plate_with_fin_spacecraft(fin_thickness=1e-6)
    s = np.array([1.0, 0.3, 0.2])
    n, c = craft.mesh.face_normals, craft.mesh.triangles_center
    fin_right = np.flatnonzero((n[:, 0] > 0.99) & (c[:, 1] > 0.01) & (np.abs(c[:, 0]) < 1e-3))
    assert len(fin_right) == 2
    np.testing.assert_array_equal(vis.lit_fraction(craft, s)[fin_right], 1.0)


# ----------------------------------------------------------------------------- sampled method


def test_sampled_converges_to_exact_without_stall(capsys):
    """Sampled lit-and-visible fractions of the partly shadowed facets of the non-convex
    bodies, 24 random geometries, against the exact method: the mean error falls at every
    doubling of the density (the old lattice stalled at powers of two), roughly as
    density**-1.5 (scrambled-net rate N**-0.75; asserted: at least the O(1/density) rate,
    a factor 1.6 per doubling), and the worst error at density 32 is below 0.02."""
    s = random_directions(24, seed=31)
    o = random_directions(24, seed=32)
    rows = []
    for name in sorted(NONCONVEX):
        craft = NONCONVEX[name]()
        exact = vis.lit_visible_fraction(craft, s, o)
        partial = (exact > 0) & (exact < 1)
        for n in (2, 4, 8, 16, 32):
            f = vis.lit_visible_fraction(craft, s, o, method="sampled", density=n)
            err = np.abs(f - exact)[partial]
            rows.append((name, n, err.mean(), err.max()))
    with capsys.disabled():
        print("\nsampled vs exact, partly shadowed facets (24 geometries):")
        for name, n, mean, worst in rows:
            print(f"  {name:15s} density {n:3d}  mean |error| {mean:.5f}  max {worst:.5f}")
    for name in NONCONVEX:
        means = [m for b, _, m, _ in rows if b == name]
        assert all(b < a / 1.6 for a, b in itertools.pairwise(means)), (name, means)
        assert max(w for b, n, _, w in rows if b == name and n == 32) < 0.02


def test_sampled_error_estimate():
    """The binomial standard error is zero for the exact method and for unshadowed facets,
    and bounds the actual error of the scrambled points on average (it assumes independent
    samples; QMC does better)."""
    craft = l_shaped_spacecraft()
    s, o = random_directions(32, seed=33), random_directions(32, seed=34)
    exact = vis.lit_visible_fraction(craft, s, o)
    f, err = vis.lit_visible_fraction(craft, s, o, method="sampled", density=8, return_error=True)
    assert f.shape == err.shape == exact.shape
    np.testing.assert_array_equal(err[(f == 0) | (f == 1)], 0.0)
    partial = (exact > 0) & (exact < 1) & (err > 0)
    assert np.mean(np.abs(f - exact)[partial]) < np.mean(err[partial])
    _, err0 = vis.lit_visible_fraction(craft, s, o, return_error=True)
    np.testing.assert_array_equal(err0, 0.0)


def test_sample_triangle_points():
    """Independent, deterministic, area-uniform point sets inside the triangle."""
    b = rays.sample_triangle(64, n_facets=50, seed=1)
    assert b.shape == (50, 64, 3)
    np.testing.assert_allclose(b.sum(axis=-1), 1.0, rtol=1e-15)
    assert b.min() >= 0
    np.testing.assert_array_equal(b, rays.sample_triangle(64, n_facets=50, seed=1))
    assert not np.allclose(b[0], b[1])
    # area-uniform: the mean of the weights over all points is the centroid (1/3 each), the
    # standard error of the mean of 3200 points of variance 1/18 is 0.004
    np.testing.assert_allclose(b.reshape(-1, 3).mean(axis=0), 1 / 3, atol=0.02)
    # no lattice: a per-facet shift breaks every alignment, no two facets share a point
    assert len(np.unique(np.round(b[:, 0], 12), axis=0)) == 50


def test_fractions_are_sample_multiples():
    craft = l_shaped_spacecraft()
    for n in (1, 3, 5):
        f = vis.lit_fraction(craft, random_directions(5, seed=2), method="sampled", density=n)
        np.testing.assert_allclose(f * n * n, np.round(f * n * n), atol=1e-12)
        assert f.min() >= 0 and f.max() <= 1


# ----------------------------------------------------------------------------- engines

#: Directions whose rays from every shadowable facet of the L prism escape: the floor
#: y = 1 and the inner wall x = 1 look away from each other's part of the body.
MISS_ALL = np.array([[1.0, 0.2, 0.3], [0.3, 1.0, -0.2]])

ENGINE_PARAMS = [pytest.param("embree", marks=needs_embree), "triangle"]


@pytest.mark.parametrize("engine", ENGINE_PARAMS)
def test_engines_when_no_ray_hits(engine):
    """Rays of a direction that all escape (the triangle engine crashed on the empty hit
    list); the result is then exact: 1 on every facet facing the direction."""
    craft = l_shaped_spacecraft()
    for d in MISS_ALL:
        f = vis.lit_fraction(craft, d, method="sampled", density=3, engine=engine)
        np.testing.assert_array_equal(f, (craft.mesh.face_normals @ d > 0) * 1.0)
        np.testing.assert_array_equal(f, vis.lit_fraction(craft, d))
    f = vis.lit_visible_fraction(
        craft, MISS_ALL[0], MISS_ALL[1], method="sampled", density=2, engine=engine
    )
    np.testing.assert_array_equal(f, vis.lit_visible_fraction(craft, MISS_ALL[0], MISS_ALL[1]))


@pytest.mark.parametrize("engine", ENGINE_PARAMS)
def test_engines_converge_to_exact(engine):
    craft = bus_with_panel_spacecraft()
    s, o = random_directions(4, seed=35), random_directions(4, seed=36)
    exact = vis.lit_visible_fraction(craft, s, o)
    f = vis.lit_visible_fraction(craft, s, o, method="sampled", density=16, engine=engine)
    assert np.abs(f - exact).max() < 0.05


@needs_embree
@pytest.mark.parametrize("factory", [l_shaped_spacecraft, plate_with_fin_spacecraft])
def test_embree_and_triangle_agree(factory):
    craft = factory()
    d = random_directions(12, seed=3)
    f_e = vis.lit_fraction(craft, d, method="sampled", density=6, engine="embree")
    f_t = vis.lit_fraction(craft, d, method="sampled", density=6, engine="triangle")
    np.testing.assert_array_equal(f_e, f_t)


@needs_embree
def test_embree_and_triangle_agree_on_canx1():
    """Random, axis-aligned and grazing (1e-9 rad) Suns.  Rays could differ when they graze
    an edge within float32 rounding (embree): allow a difference of one sample in at most
    1 % of the (direction, facet) pairs (none is seen in practice)."""
    craft = sc.canx1()
    d = np.vstack([random_directions(3, seed=4), [[1, 0, 0], [1, 1e-9, 0], [1, 1, 1e-9]]])
    f_e = vis.lit_fraction(craft, d, method="sampled", density=2, engine="embree")
    f_t = vis.lit_fraction(craft, d, method="sampled", density=2, engine="triangle")
    diff = np.abs(f_e - f_t)
    assert diff.max() <= 0.25 + 1e-12 and np.mean(diff > 0) <= 0.01


# ----------------------------------------------------------------------------- CanX-1


def test_canx1_shadowing_is_small():
    """Raised cells (0.5 mm on +-X, 0.4-1.6 mm on +-Y) on a 100 mm cube shadow little.

    Projected-area-weighted shadowed fraction sum A mu (1 - f) / sum A mu (mu = N.s > 0)
    over 200 random Sun directions: a wall hides at most about its own area seen from the
    Sun (total wall area about 1400 mm2 against >= 10^4 mm2 projected), 1-3 % in practice;
    we require > 0 (the body is not convex) and < 5 %.
    """
    craft = sc.canx1()
    d = random_directions(200, seed=5)
    f = vis.lit_fraction(craft, d)
    mu = np.clip(d @ craft.mesh.face_normals.T, 0, None)
    a = craft.mesh.area_faces
    shadowed = 1 - (a * mu * f).sum(axis=1) / (a * mu).sum(axis=1)
    assert shadowed.min() >= 0
    assert 0 < shadowed.max() < 0.05
    # Sun straight along +x: the cells throw no shadow on the +X face
    f = vis.lit_fraction(craft, [1.0, 0.0, 0.0])
    plus_x = craft.mesh.face_normals[:, 0] > 0.5
    np.testing.assert_array_equal(f[plus_x], 1.0)
    np.testing.assert_array_equal(f[craft.mesh.face_normals[:, 0] <= 0], 0.0)


@pytest.mark.parametrize("method", ["exact", "sampled"])
def test_facet_visibility_dataset_and_joint_fraction(method):
    craft = sc.canx1()
    s = random_directions(6, seed=6)
    o = random_directions(6, seed=7)
    ds = vis.facet_visibility(craft, s, o, method=method, density=2)
    assert dict(ds.sizes) == {"geometry": 6, "facet": craft.n_facets, "xyz": 3}
    for name in [*ds.data_vars, *ds.coords]:
        assert {"units", "long_name"} <= set(ds[name].attrs), name
    assert ds.attrs["method"] == method
    if method == "sampled":
        assert ds.attrs["samples_per_facet"] == 4
    kw = {"method": method, "density": 2}
    np.testing.assert_array_equal(ds["lit_fraction"], vis.lit_fraction(craft, s, **kw))
    np.testing.assert_array_equal(ds["visible_fraction"], vis.visible_fraction(craft, o, **kw))
    joint = ds["lit_visible_fraction"].values
    np.testing.assert_array_equal(joint, vis.lit_visible_fraction(craft, s, o, **kw))
    assert np.all(joint <= np.minimum(ds["lit_fraction"], ds["visible_fraction"]) + 1e-12)
    # Sun and observer together (back-scatter): the joint fraction is the lit fraction
    np.testing.assert_allclose(
        vis.lit_visible_fraction(craft, s, s, **kw), ds["lit_fraction"].values, rtol=0, atol=1e-12
    )


# ----------------------------------------------------------------------------- input


def test_output_shapes():
    craft = l_shaped_spacecraft()
    for method in vis.METHODS:
        assert vis.lit_fraction(craft, [0, 1, 0], method=method, density=1).shape == (
            craft.n_facets,
        )
        d = random_directions(6, 8).reshape(2, 3, 3)
        assert vis.lit_fraction(craft, d, method=method).shape == (2, 3, craft.n_facets)
        assert vis.lit_fraction(craft.mesh, [0, 1, 0], method=method, density="fast").shape == (
            craft.n_facets,
        )


@pytest.mark.parametrize("method", ["exact", "sampled"])
@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"directions": [0.0, 0.0, 0.0]}, "zero-length"),
        ({"directions": [[1.0, 0.0, np.nan]]}, "NaN or infinite"),
        ({"directions": [1.0, 0.0]}, "3 components"),
        ({"density": 0}, "density"),
        ({"density": 1.5}, "density"),
        ({"density": "ultra"}, "presets"),
        ({"engine": "optix"}, "allowed: auto, embree, triangle"),
        ({"offset": -1.0}, "offset"),
    ],
)
def test_bad_input(kwargs, match, method):
    craft = l_shaped_spacecraft()
    args = {"directions": [0.0, 1.0, 0.0], "method": method, **kwargs}
    with pytest.raises(ValidationError, match=match):
        vis.lit_fraction(craft, **args)


def test_bad_method_and_spacecraft():
    with pytest.raises(ValidationError, match="allowed: exact, sampled"):
        vis.lit_fraction(l_shaped_spacecraft(), [0, 0, 1], method="raytraced")
    with pytest.raises(ValidationError, match=r"Spacecraft or trimesh\.Trimesh"):
        vis.lit_fraction("cube", [0, 0, 1])


# ----------------------------------------------------------------------------- union kernels


def _random_convex_polygons(rng, m):
    gx, gy = np.zeros((m, 8)), np.zeros((m, 8))
    gn = np.zeros(m, dtype=np.int64)
    polys = []
    for k in range(m):
        hull = MultiPoint(rng.uniform(0, 1, 2) + rng.normal(scale=0.15, size=(7, 2))).convex_hull
        xy = np.array(hull.exterior.coords)[:-1]
        if not hull.exterior.is_ccw:
            xy = xy[::-1]
        gx[k, : len(xy)], gy[k, : len(xy)], gn[k] = xy[:, 0], xy[:, 1], len(xy)
        polys.append(hull)
    return gx, gy, gn, polys


@pytest.mark.parametrize("m", [1, 2, 5, 12, 40])
def test_union_kernels_against_geos(m):
    """Both compiled union areas (inclusion-exclusion and vertical slabs) against GEOS on
    random overlapping convex polygons: equal to float rounding (1e-12 relative)."""
    rng = np.random.default_rng(m)
    for _ in range(20):
        gx, gy, gn, polys = _random_convex_polygons(rng, m)
        ref = shapely.union_all(polys).area
        assert pk.union_area_slabs(gx, gy, gn, m) == pytest.approx(ref, rel=1e-12)
        if m <= 12:  # inclusion-exclusion of heavily overlapping sets is exponential
            buf = pk.MAXM + 1
            area, ok = pk.union_area(
                gx,
                gy,
                gn,
                m,
                0.0,
                np.zeros((buf, pk.MAXV)),
                np.zeros((buf, pk.MAXV)),
                np.zeros(buf, np.int64),
                np.zeros(buf, np.int64),
                np.zeros(pk.MAXV),
                np.zeros(pk.MAXV),
            )
            assert ok and area == pytest.approx(ref, rel=1e-12)


def test_exact_on_finely_meshed_body_against_reference():
    """CanX-1 with antennas subdivided once (2928 facets): the antennas' shadows on the +Z
    face arrive in many pieces (up to 27 per facet here), so inclusion-exclusion runs deep."""
    craft = canx1_with_antennas(subdivisions=2)
    s, o = np.array([[0.5, 0.2, 0.8]]), np.array([[0.2, 0.6, 0.75]])
    joint = vis.lit_visible_fraction(craft, s, o)[0]
    partial = np.flatnonzero(
        (joint > 0) & (joint < 1) & (craft.mesh.triangles_center[:, 2] > 0.0499)
    )
    assert len(partial) >= 10
    for i in np.random.default_rng(24).choice(partial, 12, replace=False):
        ref = reference_fraction(craft, i, [s[0], o[0]])
        assert abs(joint[i] - ref) <= EXACT_TOL, (i, joint[i], ref)
