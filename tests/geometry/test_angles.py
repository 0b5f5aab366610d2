"""Tests of sbrdf_xr.geometry: the angle convention of paper 000 Fig. 4."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from hypothesis_profiles import examples

from sbrdf_xr import geometry as g
from sbrdf_xr.errors import ValidationError

# Round trips go through sin/cos/atan2 of O(1) values: a few ulps of a degree-sized
# quantity in float64.  1e-9 deg leaves room for the conditioning of atan2 near the
# poles of the parameterisation (phi -> 90 deg) without hiding real errors (the
# smallest angle differences tested are 1e-6 deg).
ATOL_DEG = 1e-9


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def rotation_matrix(axis, angle_deg):
    axis = unit(axis)
    a = np.radians(angle_deg)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(a) * k + (1 - np.cos(a)) * k @ k


# --------------------------------------------------------------------- basics


def test_specular_maps_to_theta_i_zero_zero():
    theta = np.array([1.0, 10.0, 30.0, 50.0, 75.0, 89.9])
    t = np.radians(theta)
    n = np.array([0.0, 0.0, 1.0])
    s = np.stack([np.sin(t), 0 * t, np.cos(t)], -1)
    o = np.stack([-np.sin(t), 0 * t, np.cos(t)], -1)
    a = g.facet_angles(n, s, o)
    np.testing.assert_allclose(a.theta_i, theta, atol=ATOL_DEG)
    np.testing.assert_allclose(a.delta_theta, 0.0, atol=ATOL_DEG)
    np.testing.assert_allclose(a.phi, 0.0, atol=ATOL_DEG)
    assert a.lit.all() and a.visible.all()


def test_backscatter_is_minus_two_theta_i():
    # Observer at the source: on the source side of specular, delta_theta = -2 theta_i.
    t = np.radians(40.0)
    s = np.array([np.sin(t), 0.0, np.cos(t)])
    a = g.facet_angles([0, 0, 1], s, s)
    assert a.delta_theta == pytest.approx(-80.0, abs=ATOL_DEG)
    assert a.phi == pytest.approx(0.0, abs=ATOL_DEG)


def test_angles_invariant_under_rotation_of_the_frame():
    rng = np.random.default_rng(1)
    n, s, o = (unit(rng.normal(size=(50, 3))) for _ in range(3))
    base = g.facet_angles(n, s, o)
    r = rotation_matrix([0.3, -1.0, 2.0], 73.0)
    rot = g.facet_angles(n @ r.T, s @ r.T, o @ r.T)
    for a, b in zip(base[:3], rot[:3], strict=True):
        np.testing.assert_allclose(a, b, atol=1e-9)


def test_paper_table1_geometries():
    """Table 1 (aluminium, theta_i = 50 deg): the rows and phi columns it lists.

    Each (delta_theta, phi) must give an observer whose projection onto the
    illumination plane is at polar angle theta_i + delta_theta on the far side of
    the normal for positive values (beyond specular), and whose elevation out of
    the plane is phi; reference rows (-44, +38 deg) are still inside the visible
    hemisphere (theta_r,proj = 6 and 88 deg).
    """
    rows = {28.5: 0.6, 19.0: 1.2, 9.5: 1.5, 0.0: 2.1, -11.0: 1.5, -22.0: 0.9, -33.0: 0.9}
    dts, phis = [], []
    for dt, pmax in rows.items():
        for k in range(4):
            dts.append(dt)
            phis.append(pmax * k / 3)
    dts += [-44.0, 38.0]
    phis += [0.0, 0.0]
    dts, phis = np.array(dts), np.array(phis)
    n, s, o = g.facet_vectors(50.0, dts, phis)
    # Sun at theta 50 deg azimuth 0; forward direction is -x, plane normal -y.
    trp = np.degrees(np.arctan2(-o[..., 0], o[..., 2]))
    np.testing.assert_allclose(trp, 50.0 + dts, atol=ATOL_DEG)
    np.testing.assert_allclose(np.degrees(np.arcsin(-o[..., 1])), phis, atol=ATOL_DEG)
    assert np.all(o[..., 2] > 0)  # every geometry of the table is visible
    a = g.facet_angles(n, s, o)
    np.testing.assert_allclose(a.theta_i, 50.0, atol=ATOL_DEG)
    np.testing.assert_allclose(a.delta_theta, dts, atol=ATOL_DEG)
    np.testing.assert_allclose(a.phi, phis, atol=ATOL_DEG)
    # delta_theta = -44 puts the observer 6 deg past the normal: 56 deg from the Sun;
    # specular is at phase angle 2 theta_i = 100 deg.
    i = np.flatnonzero(dts == -44.0)[0]
    assert g.phase_angle(s[i], o[i]) == pytest.approx(56.0, abs=1e-9)
    j = np.flatnonzero((dts == 0.0) & (phis == 0.0))[0]
    assert g.phase_angle(s[j], o[j]) == pytest.approx(100.0, abs=1e-9)


def test_conventional_round_trip_and_specular_azimuth():
    ti, pi_, tr, pr = g.to_conventional(35.0, 0.0, 0.0)
    assert (ti, pi_, tr, pr) == pytest.approx((35.0, 0.0, 35.0, 180.0), abs=ATOL_DEG)
    # Out of plane on the +y side maps to phi > 0 just as on the -y side.
    a1 = g.from_conventional(35.0, 0.0, 40.0, 170.0)
    a2 = g.from_conventional(35.0, 0.0, 40.0, 190.0)
    np.testing.assert_allclose(a1, a2, atol=ATOL_DEG)
    assert a1[2] > 0


def test_phase_angle_exact_extremes():
    assert g.phase_angle([1, 0, 0], [1, 0, 0]) == 0.0
    assert g.phase_angle([1, 0, 0], [-1, 0, 0]) == 180.0
    assert g.phase_angle([1, 0, 0], [0, 3, 0]) == pytest.approx(90.0)
    # Small angles are resolved (arccos of a dot product would return 0).
    t = np.radians(1e-7)
    assert g.phase_angle([1, 0, 0], [np.cos(t), np.sin(t), 0]) == pytest.approx(1e-7, rel=1e-6)


def test_half_vector_forward_scatter_is_finite_unit_and_perpendicular():
    s = unit(np.array([[1.0, 2.0, 3.0], [0.0, 0.0, 1.0]]))
    h = g.half_vector(s, -s)
    assert np.all(np.isfinite(h))
    np.testing.assert_allclose(np.linalg.norm(h, axis=-1), 1.0)
    np.testing.assert_allclose(np.einsum("ij,ij->i", h, s), 0.0, atol=1e-15)


@settings(max_examples=examples(100), deadline=None)
@given(
    s=arrays(np.float64, 3, elements=st.floats(-1, 1)).filter(lambda v: v @ v > 1e-6),
    k=st.floats(-20.0, 0.0),
    d=arrays(np.float64, 3, elements=st.floats(-1, 1)),
)
def test_property_half_vector_is_symmetric_and_odd_only_in_its_forward_fallback(s, k, d):
    # o near -s: within 10**k of it, down to below the fallback's tolerance
    s = unit(s)
    o = -s + 10.0**k * d
    if o @ o < 1e-30:
        o = -s
    o = unit(o)
    h1, h2 = g.half_vector(s, o), g.half_vector(o, s)
    np.testing.assert_allclose(np.linalg.norm(h1), 1.0, rtol=1e-15)
    if np.linalg.norm(s + o) <= g.normal_incidence_tolerance():
        # any unit vector perpendicular to s - o; the swap gives exactly its negative
        assert np.array_equal(h1, -h2)
        assert abs(h1 @ (s - o)) <= 4 * np.finfo(float).eps
    else:
        assert np.array_equal(h1, h2)


# ----------------------------------------------------------------- hard cases


def _no_warnings(func, *args, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return func(*args, **kw)


@pytest.mark.parametrize("theta_i_deg", [0.0, 1e-12])
def test_normal_incidence_is_finite_and_continuous(theta_i_deg):
    t = np.radians(theta_i_deg)
    n = np.array([0.0, 0.0, 1.0])
    s = np.array([np.sin(t), 0.0, np.cos(t)])
    # Observers all around the normal at 30 deg, and one along the normal.
    az = np.radians(np.arange(0, 360, 15.0))
    o = np.stack(
        [
            np.sin(np.radians(30)) * np.cos(az),
            np.sin(np.radians(30)) * np.sin(az),
            np.full_like(az, np.cos(np.radians(30))),
        ],
        -1,
    )
    o = np.vstack([o, n])
    a = _no_warnings(g.facet_angles, n, s, o)
    for x in a[:3]:
        assert np.all(np.isfinite(x))
    np.testing.assert_allclose(a.theta_i, theta_i_deg, atol=1e-15)
    # The plane is taken through the observer: phi = 0, delta_theta = theta_r - theta_i.
    np.testing.assert_allclose(a.phi, 0.0, atol=ATOL_DEG)
    np.testing.assert_allclose(a.delta_theta[:-1], 30.0 - theta_i_deg, atol=ATOL_DEG)
    assert a.delta_theta[-1] == pytest.approx(0.0, abs=ATOL_DEG)


def test_observer_polar_angle_continuous_through_normal_incidence():
    """theta_r from (theta_i, delta_theta, phi) is continuous as theta_i -> 0."""
    n = np.array([0.0, 0.0, 1.0])
    o = unit([0.3, 0.4, 0.8])
    theta_r = np.degrees(np.arccos(o[2]))
    for sun_az in np.radians([0.0, 77.0, 180.0, 260.0]):
        for ti in [1e-3, 1e-6, 1e-9, 1e-11, 1e-13, 0.0]:
            t = np.radians(ti)
            s = np.array([np.sin(t) * np.cos(sun_az), np.sin(t) * np.sin(sun_az), np.cos(t)])
            a = _no_warnings(g.facet_angles, n, s, o)
            c = np.cos(np.radians(a.phi)) * np.cos(np.radians(a.theta_i + a.delta_theta))
            assert np.degrees(np.arccos(c)) == pytest.approx(theta_r, abs=2e-3)


def test_grazing_and_horizon():
    n = np.array([0.0, 0.0, 1.0])
    s = np.array([1.0, 0.0, 0.0])  # Sun exactly on the horizon: theta_i = 90, not lit
    o = np.array([-1.0, 0.0, 0.0])  # observer on the horizon: not visible
    a = _no_warnings(g.facet_angles, n, s, o)
    assert a.theta_i == 90.0 and not a.lit and not a.visible
    assert a.delta_theta == pytest.approx(0.0) and a.phi == pytest.approx(0.0)
    # Observer on the horizon perpendicular to the plane: phi = 90.
    a = _no_warnings(g.facet_angles, n, unit([1, 0, 1]), [0, 1, 0])
    assert a.phi == pytest.approx(90.0)
    assert np.isfinite(a.delta_theta)


def test_exact_unit_dot_products():
    n = np.array([0.0, 0.0, 1.0])
    a = _no_warnings(g.facet_angles, n, n, n)  # all three equal: dot products exactly 1
    assert tuple(float(x) for x in a[:3]) == (0.0, 0.0, 0.0)
    a = _no_warnings(g.facet_angles, n, n, -n)  # observer behind: dot product exactly -1
    assert np.isfinite(a.delta_theta) and not a.visible
    a = _no_warnings(g.facet_angles, n, -n, n)  # Sun behind
    assert a.theta_i == 180.0 and not a.lit


def test_float32_input_gives_float32_finite_results():
    rng = np.random.default_rng(0)
    n, s, o = (unit(rng.normal(size=(200, 3))).astype(np.float32) for _ in range(3))
    s[0] = n[0]  # exact normal incidence in float32
    a = _no_warnings(g.facet_angles, n, s, o)
    assert a.theta_i.dtype == np.float32
    ref = g.facet_angles(n.astype(float), s.astype(float), o.astype(float))
    ok = ref.theta_i > 0.1  # away from the float32 normal-incidence tolerance
    for x, y in zip(a[:3], ref[:3], strict=True):
        assert np.all(np.isfinite(x))
        np.testing.assert_allclose(x[ok], y[ok], atol=5e-3)  # ~1e4 float32 ulps of a degree


def test_broadcasting_over_leading_dimensions():
    n = np.array([0.0, 0.0, 1.0])
    s = np.broadcast_to(unit([1.0, 0.0, 1.0]), (4, 1, 3))
    o = np.broadcast_to(unit([-1.0, 0.2, 1.0]), (1, 5, 3))
    a = g.facet_angles(n, s, o)
    assert a.theta_i.shape == (4, 5) and a.lit.shape == (4, 5)


@pytest.mark.parametrize(
    "bad",
    [np.zeros(3), np.array([np.nan, 0, 1]), np.array([1.0, 2.0]), np.array([np.inf, 0, 0])],
)
def test_bad_vectors_raise_validation_error(bad):
    with pytest.raises(ValidationError, match="to_sun"):
        g.facet_angles([0, 0, 1], bad, [0, 0, 1])


# -------------------------------------------------------- property-based tests

finite = st.floats(-1.0, 1.0, allow_nan=False, allow_infinity=False, width=64)
vec = arrays(np.float64, 3, elements=finite).filter(lambda v: np.linalg.norm(v) > 1e-3)


@settings(max_examples=examples(100), deadline=None)
@given(n=vec, s=vec, o=vec)
@example(  # near normal incidence (|s_t| = 1.2e-9): one projection tilted e_f by 2e-7
    n=np.array([0.0, 1.0, 1.0]),
    s=np.array([1.64787478e-09, 1.0, 1.0]),
    o=np.array([1.0, 1.0, 1.0]),
)
def test_round_trip_random_directions(n, s, o):
    """vectors -> angles -> facet-frame vectors reproduces every dot product."""
    n, s, o = unit(n), unit(s), unit(o)
    a = _no_warnings(g.facet_angles, n, s, o)
    for x in a[:3]:
        assert np.isfinite(x)
    assert 0.0 <= a.phi <= 90.0 and 0.0 <= a.theta_i <= 180.0
    n2, s2, o2 = g.facet_vectors(a.theta_i, a.delta_theta, a.phi)
    assert np.dot(n2, s2) == pytest.approx(np.dot(n, s), abs=1e-9)
    assert np.dot(n2, o2) == pytest.approx(np.dot(n, o), abs=1e-9)
    assert np.dot(s2, o2) == pytest.approx(np.dot(s, o), abs=1e-9)


@settings(max_examples=examples(100), deadline=None)
@given(ti=st.floats(1e-6, 89.999), trp=st.floats(-89.999, 89.999), ph=st.floats(0, 89.999))
def test_round_trip_random_angles(ti, trp, ph):
    dt = trp - ti
    n, s, o = g.facet_vectors(ti, dt, ph)
    a = _no_warnings(g.facet_angles, n, s, o)
    assert a.theta_i == pytest.approx(ti, abs=ATOL_DEG)
    assert a.phi == pytest.approx(ph, abs=1e-7)
    # delta_theta is ill-conditioned as phi -> 90 deg (the plane projection shrinks).
    assert a.delta_theta == pytest.approx(dt, abs=1e-7 / max(np.cos(np.radians(ph)), 1e-12))
    back = g.from_conventional(*g.to_conventional(ti, dt, ph))
    assert back[0] == pytest.approx(ti, abs=ATOL_DEG)
    assert back[2] == pytest.approx(ph, abs=1e-7)


def test_observation_plane_geometry():
    s, o = g.observation_plane([5.0, 30.0, 60.0, 90.0])
    np.testing.assert_allclose(g.phase_angle(s, o), [5.0, 30.0, 60.0, 90.0], atol=1e-12)
    np.testing.assert_allclose(s[:, 2], 0.0)
    np.testing.assert_allclose(s[:, 0], o[:, 0])  # equal angles to +x
    with pytest.raises(ValidationError, match="phase_angle"):
        g.observation_plane(181.0)


def test_attitude_helpers_are_importable_from_geometry():
    from sbrdf_xr.geometry import rotations

    for name in rotations.__all__:
        assert getattr(g, name) is getattr(rotations, name)
        assert name in g.__all__
