"""Tests of sbrdf_xr.geometry.anisotropy: facet tangents, the azimuth psi and its interpolation."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from hypothesis_profiles import examples

from sbrdf_xr import geometry
from sbrdf_xr.brdf import anisotropic as A
from sbrdf_xr.errors import ValidationError
from sbrdf_xr.geometry import anisotropy as AN

unit = (
    st.tuples(*[st.floats(-1, 1, allow_nan=False)] * 3)
    .map(np.array)
    .filter(lambda v: np.linalg.norm(v) > 0.1)
    .map(lambda v: v / np.linalg.norm(v))
)


def circ(a, b):
    """Distance of two psi values on the circle of period 180 [degree]."""
    d = np.mod(np.asarray(a) - np.asarray(b), 180.0)
    return np.minimum(d, 180.0 - d)


def rotation(axis, angle):
    return geometry.rotation_matrices(geometry.axis_rotation(axis, angle))


def frame_geometry(n, t, s, o):
    """Upper-hemisphere Sun and observer for normal n, tangent in the facet plane."""
    s = s if s @ n > 0 else s - 2 * (s @ n) * n
    o = o if o @ n > 0 else o - 2 * (o @ n) * n
    return s, o


# ------------------------------------------------------------------ tangents


def test_project_tangents_unit_orthogonal_and_default():
    rng = np.random.default_rng(0)
    n = rng.normal(size=(200, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    for d in (None, (0.3, -1.0, 2.0), rng.normal(size=(200, 3))):
        t = AN.project_tangents(n, d)
        np.testing.assert_allclose(np.linalg.norm(t, axis=1), 1.0, rtol=1e-14)
        assert np.abs(np.einsum("fk,fk->f", t, n)).max() < 1e-14
    # the default is body +x projected: unchanged on facets that contain x
    z = np.array([[0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
    np.testing.assert_array_equal(AN.project_tangents(z), [[1.0, 0, 0], [1.0, 0, 0]])


def test_project_tangents_fallback_when_parallel_to_the_normal():
    n = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [1.0, 1.0, 1.0]])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    t = AN.project_tangents(n, n * 3.0)  # every direction along its normal
    # the body axis least aligned with the normal (first on ties), projected
    np.testing.assert_allclose(t[0], [0.0, 1.0, 0.0], atol=0)
    np.testing.assert_allclose(t[1], [1.0, 0.0, 0.0], atol=0)
    np.testing.assert_allclose(t[2], np.array([2.0, -1.0, -1.0]) / np.sqrt(6.0), rtol=1e-14)
    # a zero direction takes the fallback too; within 1e-6 rad of the normal as well
    np.testing.assert_allclose(AN.project_tangents(n[:1], [0.0, 0.0, 0.0]), [[0.0, 1.0, 0.0]])
    np.testing.assert_allclose(AN.project_tangents(n[:1], [1.0, 0.0, 1e-7]), [[0.0, 1.0, 0.0]])
    # ... but not 1e-5 rad away: that direction is kept
    np.testing.assert_allclose(
        AN.project_tangents(n[:1], [1.0, 0.0, 1e-5]), [[0.0, 0.0, 1.0]], atol=1e-12
    )
    with pytest.raises(ValidationError, match="tangent"):
        AN.project_tangents(n, [1.0, np.nan, 0.0])
    with pytest.raises(ValidationError, match="tangent"):
        AN.project_tangents(n, np.ones((2, 3)))


# ------------------------------------------------------------------ psi


def test_psi_closed_form_in_the_facet_frame():
    # facet_vectors puts N = z, e_f = -x, the observer on the +p side; the tangent of
    # tangent_from_azimuth(psi) is reached from e_f by -psi: psi comes back exactly.
    psi = np.arange(0.0, 180.0, 7.5)
    n, s, o = geometry.facet_vectors(35.0, -10.0, 20.0)
    got = AN.illumination_azimuth(n, A.tangent_from_azimuth(psi), s, o)
    np.testing.assert_allclose(got, psi, atol=1e-12)
    # t and -t are the same tangent
    got = AN.illumination_azimuth(n, -A.tangent_from_azimuth(psi), s, o)
    np.testing.assert_allclose(circ(got, psi), 0.0, atol=1e-12)
    # the brdf module's function is this one
    np.testing.assert_array_equal(
        A.illumination_azimuth(n, A.tangent_from_azimuth(psi), s, o),
        AN.illumination_azimuth(n, A.tangent_from_azimuth(psi), s, o),
    )


def test_psi_mirror_across_the_illumination_plane():
    # An observer on the -p side is the mirror image: psi -> -psi (mod 180).
    n, s, o = geometry.facet_vectors(40.0, 15.0, 25.0)
    o_mirror = o * np.array([1.0, -1.0, 1.0])  # p = -y
    t = A.tangent_from_azimuth(30.0)
    assert float(AN.illumination_azimuth(n, t, s, o)) == pytest.approx(30.0, abs=1e-12)
    assert float(AN.illumination_azimuth(n, t, s, o_mirror)) == pytest.approx(150.0, abs=1e-12)


def test_psi_at_normal_incidence_follows_the_observer():
    # Below the tolerance the plane goes through the observer, as in facet_angles.
    n = np.array([0.0, 0.0, 1.0])
    s = np.array([1e-13, 0.0, 1.0])
    t = np.array([1.0, 0.0, 0.0])
    for az in (0.0, 30.0, 100.0, 250.0):
        a = np.radians(az)
        o = np.array([np.cos(a) * 0.6, np.sin(a) * 0.6, 0.8])
        ang = geometry.facet_angles(n, s, o)
        assert float(ang.phi) < 1e-12
        assert float(circ(AN.illumination_azimuth(n, t, s, o), az)) < 1e-9
    # Sun and observer along the normal: finite, in range
    psi = AN.illumination_azimuth(n, t, n, n)
    assert np.isfinite(psi) and 0 <= psi < 180


@settings(max_examples=examples(100), deadline=None)
@given(n=unit, t=unit, s=unit, o=unit)
def test_psi_range_and_dtype(n, t, s, o):
    n, t = n / np.linalg.norm(n), t / np.linalg.norm(t)
    # tangents the float32 working precision can tell from the normal (it refuses others)
    assume(np.linalg.norm(np.cross(n, t)) > 2 * geometry.normal_incidence_tolerance(np.float32))
    s, o = frame_geometry(n, t, s, o)
    for dt in (np.float64, np.float32):
        psi = AN.illumination_azimuth(n.astype(dt), t, s.astype(dt), o.astype(dt))
        assert psi.dtype == dt
        assert 0.0 <= float(psi) < 180.0


def test_tangent_near_the_normal_is_refused_only_where_the_precision_cannot_tell_it():
    # found by the deep profile: a tangent 1.0e-3 rad from the normal is within the float32
    # normal-incidence tolerance (1.19e-3) and far outside the float64 one (2.2e-12)
    n = np.array([-0.89437939, 0.0, 0.44730918])
    t = np.array([-0.89484013, 0.0, 0.44638676])
    n, t = n / np.linalg.norm(n), t / np.linalg.norm(t)
    z = np.array([0.0, 0.0, 1.0])
    assert 0.0 <= float(AN.illumination_azimuth(n, t, z, z)) < 180.0
    with pytest.raises(ValidationError, match="tangent: must not be parallel"):
        AN.illumination_azimuth(n.astype(np.float32), t, z.astype(np.float32), z.astype(np.float32))


@settings(max_examples=examples(100), deadline=None)
@given(n=unit, t=unit, s=unit, o=unit, axis_angle=st.floats(-360, 360), full=unit)
def test_psi_invariant_under_rotations(n, t, s, o, axis_angle, full):
    assume(np.linalg.norm(np.cross(n, t)) > 1e-3)
    s, o = frame_geometry(n, t, s, o)
    assume(np.linalg.norm(s - (s @ n) * n) > 1e-6)
    psi = AN.illumination_azimuth(n, t, s, o)
    # rotating the whole scene about the facet normal, tangent included
    r = rotation(n, axis_angle)
    got = AN.illumination_azimuth(n, r @ t, r @ s, r @ o)
    assert float(circ(got, psi)) < 1e-8
    # and about any axis
    r = rotation(full, axis_angle)
    got = AN.illumination_azimuth(r @ n, r @ t, r @ s, r @ o)
    assert float(circ(got, psi)) < 1e-8


@settings(max_examples=examples(100), deadline=None)
@given(n=unit, t=unit, s=unit, o=unit, ds=unit, do=unit)
def test_psi_continuous_away_from_normal_incidence(n, t, s, o, ds, do):
    # Lipschitz away from normal incidence (theta_i > 1 deg) and from the
    # illumination plane (where psi flips to its mirror value, of equal reflectance):
    # a 1e-9 move of the Sun and the observer moves psi by at most ~1e-9 / sin(theta_i)
    # rad; 1e-5 deg is a wide margin that a jump (>= degrees) cannot pass.
    assume(np.linalg.norm(np.cross(n, t)) > 1e-3)
    s, o = frame_geometry(n, t, s, o)
    s_t = s - (s @ n) * n
    assume(np.linalg.norm(s_t) > np.sin(np.radians(1.0)))
    p = np.cross(n, -s_t / np.linalg.norm(s_t))
    assume(abs(o @ p) > 1e-3)
    eps = 1e-9
    psi0 = AN.illumination_azimuth(n, t, s, o)
    psi1 = AN.illumination_azimuth(n, t, s + eps * ds, o + eps * do)
    assert float(circ(psi0, psi1)) < 1e-5


def test_psi_rejects_a_tangent_along_the_normal():
    z = np.array([0.0, 0.0, 1.0])
    with pytest.raises(ValidationError, match="parallel"):
        AN.illumination_azimuth(z, z, z, z)


# ------------------------------------------------------------------ weights


@settings(max_examples=examples(200), deadline=None)
@given(x=st.floats(-1e4, 1e4), step=st.sampled_from([10.0, 15.0, 30.0, 45.0]), closed=st.booleans())
def test_psi_weights_periodic_and_partition_of_unity(x, step, closed):
    grid = np.arange(0.0, 180.0 + (step / 2 if closed else 0.0), step)
    idx, w = AN.psi_weights(grid, [x, x + 180.0, x - 540.0])
    assert np.all(w >= 0) and np.allclose(w.sum(-1), 1.0, rtol=0, atol=1e-15)
    assert idx.min() >= 0 and idx.max() < grid.size
    # the interpolant of a periodic function sampled on the grid: same for x + k 180
    f = np.cos(np.radians(2 * grid))
    if closed:
        f[-1] = f[0]
    vals = (f[idx] * w).sum(-1)
    np.testing.assert_allclose(vals, vals[0], atol=1e-9)


def test_psi_weights_exact_at_nodes_and_wrap():
    grid = np.array([10.0, 70.0, 130.0])
    idx, w = AN.psi_weights(grid, [10.0, 70.0, 160.0, 190.0, 5.0])
    f = np.array([1.0, 2.0, 4.0])
    vals = (f[idx] * w).sum(-1)
    # 160 is halfway from 130 to 190 = 10 + 180; 5 is 5/60 of the way back from 190
    np.testing.assert_allclose(vals, [1.0, 2.0, 2.5, 1.0, 4.0 - 3.0 * 55.0 / 60.0], rtol=1e-14)
    with pytest.raises(ValidationError, match="psi"):
        AN.psi_weights([0.0, 200.0], [1.0])


def test_psi_average_is_the_mean_of_the_interpolant():
    grid = np.array([0.0, 20.0, 50.0, 120.0])
    f = np.array([1.0, 3.0, -2.0, 5.0])
    x = np.linspace(0.0, 180.0, 180001)[:-1]
    idx, w = AN.psi_weights(grid, x)
    brute = float(np.mean((f[idx] * w).sum(-1)))
    assert float(AN.psi_average(f, grid)) == pytest.approx(brute, abs=1e-6)
