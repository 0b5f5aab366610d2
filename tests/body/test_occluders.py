"""Tests of sbrdf_xr.body.occluders: merged coplanar occluders and the per-body pair table."""

from __future__ import annotations

import numpy as np
import shapely
import trimesh

from sbrdf_xr.body import occluders
from sbrdf_xr.body import spacecraft as sc
from sbrdf_xr.body import visibility as vis
from sbrdf_xr.testing import bus_with_panel_spacecraft, l_shaped_spacecraft


def _frames(mesh):
    return vis.exact_frames(mesh, {})


def test_box_faces_merge_into_squares():
    occ = occluders.occluder_polygons(_frames(trimesh.creation.box()))
    assert occ["count"].tolist() == [4] * 6
    assert sorted(occ["members"].tolist()) == list(range(12))


def test_merged_polygons_are_the_union_of_their_facets():
    """On CanX-1 and a box-wing: every polygon is strictly convex, its facets coplanar with
    it, and its area (in its own plane) the sum of its facets' areas: the union is exact."""
    for craft in (sc.canx1(), bus_with_panel_spacecraft()):
        frames = _frames(craft.mesh)
        occ = occluders.occluder_polygons(frames)
        V, N, area = frames["V"], frames["N"], craft.mesh.area_faces
        assert len(occ["count"]) < craft.n_facets  # something merged
        assert sorted(occ["members"].tolist()) == list(range(craft.n_facets))
        for g in range(len(occ["count"])):
            idx = occ["poly"][g, : occ["count"][g]]
            members = occ["members"][occ["start"][g] : occ["start"][g + 1]]
            n = occ["normal"][g]
            assert np.abs((V[idx] - V[idx[0]]) @ n).max() <= 1e-15 * frames["scale"]
            e1 = V[idx[1]] - V[idx[0]]
            e1 /= np.linalg.norm(e1)
            xy = np.column_stack(
                [(V[idx] - V[idx[0]]) @ e1, (V[idx] - V[idx[0]]) @ np.cross(n, e1)]
            )
            poly = shapely.Polygon(xy)
            assert poly.is_valid and poly.exterior.is_ccw
            assert np.isclose(poly.convex_hull.area, poly.area, rtol=1e-12, atol=0)
            assert np.isclose(poly.area, area[members].sum(), rtol=1e-12, atol=0)
            assert np.all(N[members] @ n > 0)


def test_table_is_cached_and_sorted():
    craft = sc.canx1()
    mesh, cache = vis.mesh_of(craft)
    frames = vis.exact_frames(mesh, cache)
    first = occluders.pair_table(frames, cache)
    assert occluders.pair_table(frames, cache) is first
    recv, pstart, _, pcount, cut, box, r2 = first["table"]
    assert set(recv.tolist()) == set(np.flatnonzero(frames["receiver"]).tolist())
    for r in range(len(recv)):
        assert np.all(np.diff(r2[pstart[r] : pstart[r + 1]]) >= 0)
    assert np.all(cut[np.arange(len(pcount)), :, 2][:, 0] >= 0)  # cut: on or above the plane
    assert np.all(box[:, 0] <= box[:, 1]) and np.all(box[:, 2] <= box[:, 3])


def test_past_the_work_bound_the_grid_kernel_runs(monkeypatch):
    """No table past MAX_PAIR_WORK (a cached None), and the same fractions by the grid."""
    craft = l_shaped_spacecraft()
    s = np.array([[-0.37, 1.0, 0.23], [0.2, 1.0, 0.9]])
    o = np.array([[-1.0, 3.0, 0.0], [0.5, 1.0, 0.2]])
    with_table = vis.lit_visible_fraction(craft, s, o)
    other = l_shaped_spacecraft()
    monkeypatch.setattr(occluders, "MAX_PAIR_WORK", 0)
    without = vis.lit_visible_fraction(other, s, o)
    assert vis.mesh_of(other)[1]["exact:pairs"] is None
    np.testing.assert_allclose(without, with_table, rtol=0, atol=1e-15)


def test_a_sliver_in_the_tolerance_band_is_not_merged_for_that_receiver():
    """An occluder quad (plane z = x) whose thin triangle lies within the plane tolerance
    above the floor z = 0: the grid kernel ignores that triangle, so the pair table uses
    the quad's facets one by one for the floor, not the merged quad, and the floor's lit
    fraction is that of the grid kernel.  (The merged quad would add a shadow 1e-10 high,
    long at a low Sun.)"""
    floor = [[-2.0, -2, 0], [3, -2, 0], [3, 3, 0], [-2, 3, 0]]
    quad = [[0.0, 0, 0], [1e-10, 0, 1e-10], [1, 1, 1], [0, 1, 0]]
    V = np.array(floor + quad)
    F = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 7], [5, 6, 7]])  # quad normal: -x + z
    mesh = trimesh.Trimesh(V, F, process=False)
    frames = _frames(mesh)
    occ = occluders.occluder_polygons(frames)
    assert 4 in occ["count"].tolist()  # the quad is merged
    assert frames["eps"] > 1e-10  # its thin triangle is inside the band above the floor
    d = np.array([[-1.0, 0.3, 0.05]]) / np.linalg.norm([-1.0, 0.3, 0.05])
    f = vis.lit_fraction(mesh, d)
    dirs = np.ascontiguousarray(np.stack([d], axis=1))
    normals = np.asarray(mesh.face_normals)
    grid = np.where(normals @ d[0] > 0, vis._grid_fractions(frames, dirs)[0], 0.0)
    np.testing.assert_allclose(f[0], grid, rtol=0, atol=1e-15)
    assert 0 < f[0, 0] < 1 or 0 < f[0, 1] < 1  # the floor is partly shadowed
