"""Tests of sbrdf_xr.geometry.rotations: attitudes as unit quaternions."""

from __future__ import annotations

import numpy as np
import pytest

from sbrdf_xr import geometry
from sbrdf_xr.errors import ValidationError
from sbrdf_xr.geometry import rotations as r


def test_rotation_sweep_of_the_paper_rotation_scenario():
    """Paper 000 §4: 25 deg about +z, then steps about -z; v_i 5 deg off +x."""
    q = r.rotation_sweep([0, 0, -1], [0.0, 25.0, 115.0], r.axis_rotation([0, 0, 1], 25.0))
    s, o = geometry.observation_plane(10.0)
    sb = r.to_body_frame(q, s)
    ob = r.to_body_frame(q, o)
    # At 25 deg of rotation the body +x axis points along the bisector (+x): +X glints.
    np.testing.assert_allclose(
        (sb[1] + ob[1]) / np.linalg.norm(sb[1] + ob[1]), [1, 0, 0], atol=1e-12
    )
    # 90 deg later the bisector is along body +y.
    np.testing.assert_allclose(
        (sb[2] + ob[2]) / np.linalg.norm(sb[2] + ob[2]), [0, 1, 0], atol=1e-12
    )
    assert geometry.phase_angle(sb, ob) == pytest.approx(np.full(3, 10.0))


def test_euler_and_uniform_attitudes():
    q = r.euler_attitudes("z", [[90.0]])
    np.testing.assert_allclose(r.to_body_frame(q, [0.0, 1.0, 0.0]), [[1.0, 0.0, 0.0]], atol=1e-12)
    u = r.uniform_attitudes(2000, seed=1)
    # Uniform on SO(3): the body-frame image of a fixed direction is uniform on the
    # sphere, so its mean is ~0 (standard error 1/sqrt(3 n) ~ 0.013 per component).
    assert np.all(np.abs(r.to_body_frame(u, [0.0, 0.0, 1.0]).mean(axis=0)) < 0.06)
    with pytest.raises(ValidationError, match="euler"):
        r.euler_attitudes("abc", [[1.0, 2.0, 3.0]])


@pytest.mark.parametrize("q", [[0, 0, 0, 0], [1.0, 1.0, 0, 0], [0, 0, 0, np.nan], [1, 0, 0]])
def test_quaternions_that_are_not_rotations_are_rejected(q):
    with pytest.raises(ValidationError, match="quaternion"):
        r.check_quaternions(q)


def test_compose_matches_matrix_product():
    a = r.axis_rotation([1, 2, 3], 40.0)
    b = r.axis_rotation([0, 1, 0], -70.0)
    np.testing.assert_allclose(
        r.rotation_matrices(r.compose_quaternions(a, b)),
        r.rotation_matrices(a) @ r.rotation_matrices(b),
        atol=1e-12,
    )


@pytest.mark.parametrize("axis", [[0, 0, 0], [1, 0], [np.inf, 0, 0], ["a", "b", "c"]])
def test_bad_rotation_axes_are_rejected(axis):
    with pytest.raises(ValidationError, match="axis"):
        r.axis_rotation(axis, 10.0)
