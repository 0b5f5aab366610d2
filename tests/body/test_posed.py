"""Shadowing on posed bodies (sbrdf_xr.body.posed): the pair table against the grid kernel.

The pair table of a posed body holds the pairs within each rigid group once (their frame
coordinates do not change when the group turns) and finds those between groups per pose.
The grid kernel (:func:`sbrdf_xr.kernels.shadow.exact_kernel`, every facet tested per
direction) is the independent check: the two project and clip the same shadows, in other
frames and orders, so they agree to rounding (the fractions' tolerance of
``tests/kernels/test_shadow_pairs.py``, 1e-15 (1 + |s|) scale / l, is ~1e-13 on these
bodies).  Measured on 360 random geometries: at most 1.3e-13 apart on the box with a plate
(relative 1.02e-12 on a fraction of 0.13), 6.7e-16 on the GEO comsat; the geometries drawn
here hold rtol 1e-12 with no absolute tolerance.
"""

from __future__ import annotations

import numpy as np
import pytest

from sbrdf_xr.bench.shadowing import geometries
from sbrdf_xr.body import posed
from sbrdf_xr.body.geo_comsat import geo_comsat
from sbrdf_xr.body.parts import hinge_rotation
from sbrdf_xr.testing import box_with_plate_spacecraft


def tracking_poses(body, s):
    """Every part's rotation (G, P, 3, 3) as its pointing law turns it for the Suns s."""
    idx = np.arange(len(s))
    return np.stack([hinge_rotation(p.axis, p.law.angles(s, idx, p)) for p in body.parts], axis=1)


@pytest.mark.parametrize("factory", [box_with_plate_spacecraft, geo_comsat])
def test_sun_tracking_poses_pair_table_against_grid_kernel(factory):
    """A box with a Sun-tracking wing (a plate above it; a GEO bus with two wings) at the
    poses of 48 random Sun/observer geometries: the same fractions by both kernels, some
    partly shadowed."""
    body = factory(parts=True) if factory is box_with_plate_spacecraft else factory()
    s, o = geometries(48, seed=52)
    rot = tracking_poses(body, s)
    dirs = np.ascontiguousarray(np.stack([s, o], axis=1))
    tabled = posed._exact_posed(body, rot, dirs)
    grid = posed._exact_posed(body, rot, dirs, tabled=False)
    assert body._cache["posed:pairs"] is not None  # the table ran
    assert np.any((tabled > 0) & (tabled < 1))
    np.testing.assert_allclose(tabled, grid, rtol=1e-12, atol=0)


def test_fixed_poses_and_a_pose_that_shades_the_bus():
    """The plate above the box at several fixed angles, lit and seen from above at a
    slant: the flat plate hides most of the top face, edge-on it hides much less."""
    body = box_with_plate_spacecraft(parts=True)
    angles = np.radians([0.0, 15.0, 40.0, 75.0, 90.0, 130.0])
    rot = hinge_rotation([1.0, 0, 0], angles)[:, None]
    up = np.tile(np.array([0.1, -0.2, 1.0]) / np.linalg.norm([0.1, -0.2, 1.0]), (len(angles), 1))
    obs = np.tile(np.array([-0.3, 0.1, 1.0]) / np.linalg.norm([-0.3, 0.1, 1.0]), (len(angles), 1))
    dirs = np.ascontiguousarray(np.stack([up, obs], axis=1))
    tabled = posed.posed_fraction(body, rot, [up, obs])
    grid = posed._exact_posed(body, rot, dirs, tabled=False)
    np.testing.assert_allclose(tabled, grid, rtol=1e-12, atol=0)
    top = [4, 6]  # the two facets of the cube's +z face
    assert tabled[0, top].max() < 0.1 and tabled[4, top].min() > 0.6


def test_within_group_pairs_found_once():
    """The pairs within groups are cached with the body and reused for every pose."""
    body = geo_comsat()
    s, o = geometries(4, seed=53)
    rot = tracking_poses(body, s)
    posed.posed_fraction(body, rot, [s, o])
    first = body._cache["posed:pairs"]
    posed.posed_fraction(body, rot[::-1], [s[::-1], o[::-1]])
    assert body._cache["posed:pairs"] is first
