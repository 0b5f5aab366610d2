"""The pair-table shadow kernel (sbrdf_xr.kernels.shadow_pairs) against an exact reference
and against the grid kernel it replaces (sbrdf_xr.kernels.shadow.exact_kernel).

The reference is independent of both kernels: every shadow polygon is computed in exact
rational arithmetic (``fractions.Fraction`` of the float64 vertices and directions) in
the affine coordinates of the receiving facet (``x = P0 + a e1 + b e2``; areas divide
out, so the facet is the unit right triangle and no square root is taken); any facet
rising above the receiver's plane is an occluder (no closed-surface rule); the shadows
are rounded once to float64 and united and clipped by GEOS (shapely).  Its error is a
few ulps of the facet's area: the rounding of the polygons (relative 1e-16) and GEOS's
float64 overlay.

Tolerances.  The kernels project in the facet's orthonormal frame with slopes
``s = (E1.d, E2.d) / N.d``: a vertex at height ``h`` moves by ``h s``, so a shadow's
corner is rounded by ~1e-16 (|u| + h |s|) <= 1e-16 (1 + |s|) ``scale`` (the body's size,
which bounds |u| and h), and the fraction, relative to a facet of size
``l = sqrt(2 area)``, by that over ``l`` times the few edges it moves.  ``tol`` is
1e-15 (1 + |s|) max(1, scale / l): the unit 1e-16 (1 + |s|) scale / l times 10.  Measured
on 360 geometries of CanX-1 and CanX-1 with antennas, the pair kernel's worst error
against the reference is 0.43 of the unit and the grid kernel's 0.73 (a fully shadowed
wall facet 0.5 mm tall, |s| = 31, 4.6e-14 and 9.0e-14); on a facet of the body's size
seen at 45 degree ``tol`` is 2e-15.  The two kernels are compared with twice ``tol``.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
import shapely
import shapely.affinity
from hypothesis import example, given, settings
from hypothesis import strategies as st
from hypothesis_profiles import examples
from shapely.geometry.polygon import orient

from sbrdf_xr.bench.shadowing import geometries
from sbrdf_xr.body import spacecraft as sc
from sbrdf_xr.body import visibility as vis
from sbrdf_xr.body.occluders import pair_table
from sbrdf_xr.kernels import coverage
from sbrdf_xr.kernels.polygon import signed_area
from sbrdf_xr.kernels.shadow_pairs import pairs_kernel
from sbrdf_xr.testing import (
    bus_with_panel_spacecraft,
    canx1_with_antennas,
    l_shaped_spacecraft,
    plate_with_fin_spacecraft,
)

BODIES = {
    "l-shape": l_shaped_spacecraft,  # concave
    "plate-with-fin": plate_with_fin_spacecraft,
    "bus-with-panel": bus_with_panel_spacecraft,  # a box-wing
    "canx1": sc.canx1,
    "canx1-antennas": canx1_with_antennas,
}
_CRAFT: dict = {}


def body(name):
    if name not in _CRAFT:
        _CRAFT[name] = BODIES[name]()
    return _CRAFT[name]


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def random_directions(n, seed):
    return unit(np.random.default_rng(seed).normal(size=(n, 3)))


# ----------------------------------------------------------------------------- reference


def _q(x):
    return [Fraction(float(c)) for c in x]


def _sub(a, b):
    return [x - y for x, y in zip(a, b, strict=True)]


def _dot(a, b):
    return sum(x * y for x, y in zip(a, b, strict=True))


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def exact_shadows(tri, others, d, eps, rational=False):
    """Shadows of the triangles ``others`` on the triangle ``tri`` along d, exactly, in the
    affine coordinates (a, b) of ``tri``: a list of vertex lists (rounded to float64 unless
    ``rational``)."""
    p0, p1, p2 = (_q(v) for v in tri)
    e1, e2 = _sub(p1, p0), _sub(p2, p0)
    n = _cross(e1, e2)
    dq = _q(d)
    nd = _dot(n, dq)
    nn = _dot(n, n)
    out = []
    for other in others:
        pts = [_q(v) for v in other]
        h = [_dot(n, _sub(x, p0)) for x in pts]
        # the kernels' tolerance: no vertex more than eps (a length) above the plane
        if max(float(x) for x in h) <= eps * float(nn) ** 0.5:
            continue
        front = []
        for a in range(3):
            b = (a + 1) % 3
            if h[a] >= 0:
                front.append(pts[a])
            if (h[a] >= 0) != (h[b] >= 0):
                t = h[a] / (h[a] - h[b])
                front.append([xa + t * (xb - xa) for xa, xb in zip(pts[a], pts[b], strict=True)])
        poly = []
        for x in front:
            y = [xc - dc * _dot(n, _sub(x, p0)) / nd for xc, dc in zip(x, dq, strict=True)]
            r = _sub(y, p0)  # r = a e1 + b e2: a = (r x e2).n / nn, b = (e1 x r).n / nn
            ab = (_dot(_cross(r, e2), n) / nn, _dot(_cross(e1, r), n) / nn)
            poly.append(ab if rational else (float(ab[0]), float(ab[1])))
        if len(poly) >= 3:
            out.append(poly)
    return out


def exact_overlap(poly) -> bool:
    """Whether the rational convex polygon (vertices in cyclic order) meets the unit right
    triangle in some area: no edge line of either has the other wholly on its outer side
    (separating axes), all in exact arithmetic."""
    area2 = sum(
        poly[k][0] * poly[(k + 1) % len(poly)][1] - poly[(k + 1) % len(poly)][0] * poly[k][1]
        for k in range(len(poly))
    )
    if area2 == 0:
        return False
    order = poly if area2 > 0 else poly[::-1]
    tri = [(Fraction(0), Fraction(0)), (Fraction(1), Fraction(0)), (Fraction(0), Fraction(1))]
    for shape, other in ((tri, order), (order, tri)):
        for k in range(len(shape)):
            (ax, ay), (bx, by) = shape[k], shape[(k + 1) % len(shape)]
            if all((bx - ax) * (y - ay) - (by - ay) * (x - ax) <= 0 for x, y in other):
                return False
    return True


def reference_fraction(craft, i, directions, eps):
    """Fraction of facet i unobstructed along every direction (see the module docstring)."""
    tri = craft.mesh.triangles[i]
    n = np.cross(tri[1] - tri[0], tri[2] - tri[0])
    others = np.delete(craft.mesh.triangles, i, axis=0)
    # only those rising near or above the tolerance in float64 can pass the exact test
    rise = ((others - tri[0]) @ (n / np.linalg.norm(n))).max(axis=1)
    others = others[rise > 0.5 * eps]
    polys = []
    for d in np.atleast_2d(directions):
        if n @ d <= 0:
            return 0.0
        polys += [shapely.Polygon(p).convex_hull for p in exact_shadows(tri, others, d, eps)]
    unit_tri = shapely.Polygon([(0, 0), (1, 0), (0, 1)])
    if not polys:
        return 1.0
    return 1.0 - shapely.intersection(shapely.union_all(polys), unit_tri).area / 0.5


def slope_bound(craft, i, directions):
    n = craft.mesh.face_normals[i]
    mu = np.clip(np.atleast_2d(directions) @ n, 1e-300, None)
    return float(np.max(np.sqrt(np.clip(1.0 - mu**2, 0, None)) / mu))


def tol(craft, i, directions):
    """1e-15 (1 + |s|) scale / l: see the module docstring."""
    size = np.sqrt(2.0 * craft.mesh.area_faces[i])
    return 1e-15 * (1.0 + slope_bound(craft, i, directions)) * max(1.0, craft.mesh.scale / size)


def tolerances(craft, s, o):
    """:func:`tol` of every facet and geometry, (G, n_facets)."""
    n = craft.mesh.face_normals
    mu = np.clip(np.minimum(np.atleast_2d(s) @ n.T, np.atleast_2d(o) @ n.T), 1e-300, None)
    slope = np.sqrt(np.clip(1.0 - mu**2, 0, None)) / mu
    size = np.sqrt(2.0 * craft.mesh.area_faces)
    return 1e-15 * (1.0 + slope) * np.maximum(1.0, craft.mesh.scale / size)


# ----------------------------------------------------------------------------- helpers


def grid_fractions(craft, s, o):
    """The grid kernel through the same wrapper: a body with no pair table."""
    mesh, cache = vis.mesh_of(craft)
    frames = vis.exact_frames(mesh, cache)
    dirs = np.ascontiguousarray(np.stack([np.atleast_2d(s), np.atleast_2d(o)], axis=1))
    normals = np.asarray(mesh.face_normals)
    front = (dirs[:, 0] @ normals.T > 0) & (dirs[:, 1] @ normals.T > 0)
    return np.where(front, vis._grid_fractions(frames, dirs), 0.0)


def check_against_reference(craft, s, o, facets=None):
    joint = vis.lit_visible_fraction(craft, s, o)
    eps = vis.exact_frames(*vis.mesh_of(craft))["eps"]
    worst = 0.0
    for g in range(len(s)):
        these = range(craft.n_facets) if facets is None else facets(joint[g])
        for i in these:
            ref = reference_fraction(craft, i, [s[g], o[g]], eps)
            err = abs(joint[g, i] - ref)
            assert err <= tol(craft, i, [s[g], o[g]]), (g, i, joint[g, i], ref)
            worst = max(worst, err)
    return worst


# ----------------------------------------------------------------------------- exactness


@pytest.mark.parametrize("name", ["l-shape", "plate-with-fin", "bus-with-panel"])
def test_every_facet_against_exact_reference(name):
    """Six random geometries, every facet of the small non-convex bodies."""
    craft = body(name)
    s, o = geometries(6, seed=41)
    assert np.any((lambda f: (f > 0) & (f < 1))(vis.lit_visible_fraction(craft, s, o)))
    check_against_reference(craft, s, o)


def _canx1_against_reference(name, n_geometries, n_partial):
    craft = body(name)
    s, o = geometries(n_geometries, seed=43)  # phase angles 5-120 degree
    rng = np.random.default_rng(45)

    def facets(f):
        partial = np.flatnonzero((f > 0) & (f < 1))
        assert len(partial) >= min(5, n_partial)
        some = rng.choice(partial, min(n_partial, len(partial)), replace=False)
        return [*some, *rng.choice(np.flatnonzero(f == 1), 3, replace=False)]

    check_against_reference(craft, s, o, facets)


@pytest.mark.parametrize("name", ["canx1", "canx1-antennas"])
def test_canx1_partial_facets_against_exact_reference(name):
    """CanX-1 (684 facets) and with antennas, one geometry: six partly shadowed facets and
    three unshadowed ones (the reference costs O(facets) rational operations per facet)."""
    _canx1_against_reference(name, 1, 6)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["canx1", "canx1-antennas"])
def test_canx1_every_partial_facet_against_exact_reference(name):
    """Three geometries, every partly shadowed facet."""
    _canx1_against_reference(name, 3, 10_000)


def test_agrees_with_grid_kernel_on_many_geometries():
    """360 random geometries on every body: the pair kernel and the grid kernel agree to
    twice ``tol`` per facet."""
    s, o = geometries(360, seed=46)
    for name in BODIES:
        craft = body(name)
        new = vis.lit_visible_fraction(craft, s, o)
        old = grid_fractions(craft, s, o)
        bad = np.abs(new - old) > 2 * tolerances(craft, s, o)  # both err
        assert not bad.any(), (name, np.argwhere(bad)[:5], np.abs(new - old).max())


# ----------------------------------------------------------------------------- edge cases

EDGE_DIRECTIONS = {
    # along the axes: shadow edges fall exactly on facet edges and shared edges
    "axes": (
        unit([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]]),
        unit([[0, 0, 1.0], [1.0, 0, 0], [0, 1.0, 0]]),
    ),
    # diagonals: walls' shadows end exactly at the corners of neighbouring cells
    "diagonals": (
        unit([[1.0, 1, 1], [1.0, -1, 1], [-1.0, 1, 1]]),
        unit([[1.0, 1, 0], [0, 1, 1], [1, 0, 1]]),
    ),
    # grazing: 1e-6 rad and 1e-3 rad above the faces' planes
    "grazing": (
        unit([[1.0, 1e-6, 0.3], [0.3, 1.0, 1e-3], [1e-6, 0.2, 1.0]]),
        unit([[1.0, 0.4, 1e-3], [1e-3, 1.0, 0.5], [0.5, 1e-6, 1.0]]),
    ),
}


@pytest.mark.parametrize("case", sorted(EDGE_DIRECTIONS))
@pytest.mark.parametrize("name", ["l-shape", "bus-with-panel", "canx1"])
def test_edge_cases_against_grid_and_reference(name, case):
    """Axis-aligned, diagonal and grazing directions: the grid kernel to twice ``tol`` on
    every facet, the exact reference to ``tol`` on the partly shadowed ones."""
    craft = body(name)
    s, o = EDGE_DIRECTIONS[case]
    new = vis.lit_visible_fraction(craft, s, o)
    old = grid_fractions(craft, s, o)
    eps = vis.exact_frames(*vis.mesh_of(craft))["eps"]
    for g in range(len(s)):
        for i in np.flatnonzero(new[g] != old[g]):
            if abs(new[g, i] - old[g, i]) > 2 * tol(craft, i, [s[g], o[g]]):
                ref = reference_fraction(craft, i, [s[g], o[g]], eps)  # the grid kernel errs?
                assert abs(new[g, i] - ref) <= tol(craft, i, [s[g], o[g]]), (g, i, old[g, i])
        for i in np.flatnonzero((new[g] > 0) & (new[g] < 1))[:25]:
            ref = reference_fraction(craft, i, [s[g], o[g]], eps)
            assert abs(new[g, i] - ref) <= tol(craft, i, [s[g], o[g]]), (g, i, new[g, i], ref)


unit_vectors = (
    st.tuples(*[st.floats(-1, 1, allow_nan=False)] * 3)
    .filter(lambda v: 0.05 < np.linalg.norm(v))
    .map(lambda v: unit(v))
)


@settings(max_examples=examples(40))
@given(
    name=st.sampled_from(["l-shape", "plate-with-fin", "bus-with-panel", "canx1"]),
    s=unit_vectors,
    o=unit_vectors,
)
@example(name="canx1", s=unit([1.0, 0.0, 0.0]), o=unit([1.0, 1e-9, 0.0]))
@example(name="l-shape", s=unit([-1.0, 1.0, 0.0]), o=unit([-1.0, 1.0, 1e-12]))
def test_random_directions_against_grid_kernel(name, s, o):
    """Hypothesis directions: the same fractions as the grid kernel, every facet."""
    craft = body(name)
    new = vis.lit_visible_fraction(craft, s, o)
    old = grid_fractions(craft, s, o)[0]
    eps = vis.exact_frames(*vis.mesh_of(craft))["eps"]
    for i in np.flatnonzero(np.abs(new - old) > 2 * tolerances(craft, s, o)[0]):
        # the grid kernel's own rounding at grazing incidence: the reference decides
        ref = reference_fraction(craft, i, [s, o], eps)
        assert abs(new[i] - ref) <= tol(craft, i, [s, o]), (name, s, o, i, new[i], old[i], ref)


@settings(max_examples=examples(15))
@given(s=unit_vectors, seed=st.integers(0, 2**32 - 1))
@example(s=unit((1.0, -1.0, -4.468198529266746e-28)), seed=21613)  # grazing the z faces
def test_skipped_pairs_cast_no_shadow(s, seed):
    """The slope box and the edge thresholds never drop a shadow: for random receivers of
    CanX-1 and a direction, every occluder facet whose pair they reject (or whose box lies
    past the |s| bound) casts a shadow that meets the facet in no area, in exact
    arithmetic."""
    craft = body("canx1")
    mesh, cache = vis.mesh_of(craft)
    frames = vis.exact_frames(mesh, cache)
    table = pair_table(frames, cache)
    recv, pstart, pgroup, _, _, box, r2 = table["table"]
    occ = table["occluders"]
    N, E1, E2 = frames["N"], frames["E1"], frames["E2"]
    edges = np.roll(frames["T2"], -1, axis=1) - frames["T2"]
    edges /= np.linalg.norm(edges, axis=2, keepdims=True)
    rng = np.random.default_rng(seed)
    for r in rng.choice(len(recv), 12, replace=False):
        i = recv[r]
        nd = N[i] @ s
        if nd <= 0:
            continue
        with np.errstate(over="ignore"):  # a direction 1e-230 off a facet's plane
            slope = np.array([E1[i] @ s, E2[i] @ s]) / nd
            far = r2[pstart[r] : pstart[r + 1]] > slope @ slope
        for p in range(pstart[r], pstart[r + 1]):
            g = pgroup[p]
            if occ["normal"][g] @ s >= 0:
                continue
            inside = box[p, 0] <= slope[0] <= box[p, 1] and box[p, 2] <= slope[1] <= box[p, 3]
            for e, w in enumerate(edges[i]):  # the facet's edges as separating axes
                inside = inside and w[0] * slope[1] - w[1] * slope[0] <= box[p, 4 + e]
            if inside and not far[p - pstart[r]]:
                continue
            members = occ["members"][occ["start"][g] : occ["start"][g + 1]]
            if np.count_nonzero(pgroup[pstart[r] : pstart[r + 1]] == g) > 1:
                members = [_member_of(frames, i, table["table"], p, members)]
            tri = mesh.triangles[i]
            for poly in exact_shadows(tri, mesh.triangles[members], s, frames["eps"], True):
                assert not exact_overlap(poly), (i, members, s)


def _member_of(frames, i, table, p, members):
    """The facet of a merged occluder that pair p stands for, when the occluder is split
    into its facets for receiver i (one of them a sliver in the plane's tolerance band):
    the member whose vertices in the frame of i hold the pair's cut vertices above the
    plane."""
    cut, count = table[4][p], table[3][p]
    up = cut[:count][cut[:count, 2] > 0.0]
    for f in members:
        rel = frames["V"][frames["F"][f]] - frames["P0"][i]
        uvh = np.stack([rel @ frames["E1"][i], rel @ frames["E2"][i], rel @ frames["N"][i]], 1)
        if all(np.isclose(uvh, x, rtol=0, atol=1e-15).all(axis=1).any() for x in up):
            return f
    raise AssertionError((i, p, members))


convex_polygons = st.lists(
    st.tuples(st.floats(-2, 2, allow_nan=False), st.floats(-2, 2, allow_nan=False)),
    min_size=3,
    max_size=7,
).map(lambda pts: shapely.MultiPoint(pts).convex_hull)


@settings(max_examples=examples(60))
@given(polys=st.lists(convex_polygons, min_size=1, max_size=6), repeat=st.integers(0, 3))
def test_covered_area_and_hulls_against_geos(polys, repeat):
    """The union of up to six convex shadows as positive pieces (each less those before
    it), with a vertex repeated and an edge's midpoint added (as clipping leaves them), and
    the hull by a scan in polygon order: GEOS's union area to 1e-12 of the total (float64
    overlays, a few ulps of each of the few dozen pieces)."""
    polys = [orient(p) for p in polys if p.geom_type == "Polygon" and p.area > 1e-6]
    if not polys:
        return
    poly, count, work, wn = coverage.workspace(len(polys))
    for k, p in enumerate(polys):
        xy = np.asarray(p.exterior.coords)[:-1]
        xy = np.insert(xy, 1, 0.5 * (xy[0] + xy[1]), axis=0)  # a collinear vertex
        xy = np.insert(xy, repeat % len(xy), xy[repeat % len(xy)], axis=0)  # a duplicate
        poly[k, 0, : len(xy)], poly[k, 1, : len(xy)], count[k] = xy[:, 0], xy[:, 1], len(xy)
    area = coverage.covered_area(poly, count, len(polys), 0.0, work, wn)
    total = sum(p.area for p in polys)
    assert abs(area - shapely.union_all(polys).area) <= 1e-12 * total
    for k, p in enumerate(polys[:-1]):  # the scan gave the hull: strictly convex, its area
        x, y = poly[k, 0, : count[k]], poly[k, 1, : count[k]]
        turn = (x - np.roll(x, 1)) * (np.roll(y, -1) - y) - (y - np.roll(y, 1)) * (
            np.roll(x, -1) - x
        )
        assert np.all(turn > 0) and count[k] <= len(p.exterior.coords)  # the midpoint at most
        assert abs(signed_area(x.copy(), y.copy(), count[k]) - p.area) <= 1e-12 * p.area


@settings(max_examples=examples(60))
@given(
    shadow=convex_polygons,
    height=st.floats(0.1, 2.0),
    slope=st.tuples(st.floats(-3, 3), st.floats(-3, 3)),
    flip=st.booleans(),
)
def test_clipped_shadow_against_geos(shadow, height, slope, flip):
    """A convex occluder at a height, projected with a slope and clipped to a triangle, in
    either winding: GEOS's intersection area to 1e-12 of the triangle's, its count 0 when
    they meet in no area, -1 only when the shadow covers the triangle."""
    if shadow.geom_type != "Polygon" or shadow.area < 1e-6 or len(shadow.exterior.coords) > 9:
        return
    xy = np.asarray(orient(shadow).exterior.coords)[:-1]
    xy = xy[::-1] if flip else xy
    cut = np.zeros((1, 9, 3))
    cut[0, : len(xy), :2], cut[0, : len(xy), 2] = xy, height
    tri = np.array([[0.0, 0.0], [1.5, -0.25], [0.25, 1.0]])
    poly = coverage.workspace(1)[0]
    args = (cut, 0, len(xy), slope[0], slope[1], *tri.ravel(), 0.0, True, poly, 0)
    n = coverage.clipped_shadow(*args)
    moved = shapely.affinity.translate(shadow, -height * slope[0], -height * slope[1])
    area = shapely.Polygon(tri).area  # 0.78125
    want = moved.intersection(shapely.Polygon(tri)).area
    if n == -1:
        assert want >= (1 - 1e-12) * area
    elif n == 0:
        assert want <= 1e-12
    else:
        got = signed_area(poly[0, 0].copy(), poly[0, 1].copy(), n)
        assert abs(got - want) <= 1e-12 * area


def test_kernel_flags_and_fallbacks():
    """Facets facing away get 0 by either normal; non-receivers facing both get 1."""
    craft = body("l-shape")
    mesh, cache = vis.mesh_of(craft)
    frames = vis.exact_frames(mesh, cache)
    table = pair_table(frames, cache)
    s = unit([[-0.37, 1.0, 0.23]])
    dirs = np.ascontiguousarray(np.stack([s, s], axis=1))
    normals = np.asarray(mesh.face_normals)
    args = (frames["N"], frames["E1"], frames["E2"], frames["T2"], *table["table"])
    occ = (table["occluders"]["normal"], table["occluders"]["open"], dirs)
    f = pairs_kernel(normals, *args, *occ)
    facing = normals @ s[0] > 0
    np.testing.assert_array_equal(f[0, ~facing], 0.0)
    np.testing.assert_array_equal(f[0, facing & ~frames["receiver"]], 1.0)
    flipped = pairs_kernel(-normals, *args, *occ)  # stored normals decide
    np.testing.assert_array_equal(flipped[0, facing], 0.0)


def test_a_shadow_covering_the_facet_with_a_corner_on_its_edge():
    """The case hypothesis found: the facet inside the shadow, one corner shared and one
    on the shadow's edge: covered (-1), GEOS's intersection the whole facet."""
    shadow = shapely.Polygon([(0.0, 0.0), (2.0, -1.0), (0.0, 2.0)])
    xy = np.asarray(orient(shadow).exterior.coords)[:-1]
    cut = np.zeros((1, 9, 3))
    cut[0, : len(xy), :2], cut[0, : len(xy), 2] = xy, 1.0
    tri = np.array([[0.0, 0.0], [1.5, -0.25], [0.25, 1.0]])
    poly = coverage.workspace(1)[0]
    n = coverage.clipped_shadow(cut, 0, len(xy), 0.0, 0.0, *tri.ravel(), 0.0, True, poly, 0)
    assert n == -1
    assert shadow.intersection(shapely.Polygon(tri)).area == shapely.Polygon(tri).area
