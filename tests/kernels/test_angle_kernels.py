"""The compiled angle convention (kernels.angles) against numpy, geometry.facet_angles and
anisotropy.illumination_azimuth."""

from __future__ import annotations

import numba
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from hypothesis_profiles import examples

from sbrdf_xr.geometry import facet_angles, normal_incidence_tolerance
from sbrdf_xr.geometry.anisotropy import PSI_PERIOD, illumination_azimuth
from sbrdf_xr.kernels.angles import atan2_pos, chunk_angles, facet_frame, tangent_azimuth


@numba.njit
def _atan2_many(y, x, out):
    for i in range(y.size):
        out[i] = atan2_pos(y[i], x[i])


def _ulps(got: np.ndarray, ref: np.ndarray) -> np.ndarray:
    return np.abs(got - ref) / np.spacing(np.maximum(np.abs(ref), np.finfo(float).tiny))


finite = st.floats(min_value=-1e300, max_value=1e300, width=64)
positive = st.floats(min_value=2.3e-308, max_value=1e300, width=64)


@settings(max_examples=examples(100), deadline=None)
@given(
    arrays(np.float64, 64, elements=finite),
    arrays(np.float64, 64, elements=positive),
)
def test_atan2_pos_is_within_one_ulp_of_numpy(y, x):
    """Cephes' arc tangent is good to about 1 ulp; numpy's (libm's) is correctly rounded
    or nearly so, so the two differ by at most 1 ulp of the result, over the whole range
    of ``|y|`` and ``x`` it serves (up to 1e300; no subnormal ``x``), overflowing and
    subnormal quotients included, and keeps the sign of a zero ``y``."""
    got = np.empty_like(y)
    _atan2_many(y, x, got)
    ref = np.arctan2(y, x)
    assert np.all(_ulps(got, ref) <= 1.0), (y, x, got, ref)
    assert np.all(np.signbit(got) == np.signbit(ref))


def test_atan2_pos_at_the_range_reduction_boundaries():
    """Either side of 0.66 and tan(3 pi / 8), where Cephes switches its reduction."""
    t = np.array([0.66, np.tan(3 * np.pi / 8), 1.0, 0.0, 1e-308, 1e300])
    y = np.concatenate([np.nextafter(t, -np.inf), t, np.nextafter(t, np.inf), -t])
    x = np.ones_like(y)
    got = np.empty_like(y)
    _atan2_many(y, x, got)
    assert np.all(_ulps(got, np.arctan2(y, x)) <= 1.0)


unit = arrays(np.float64, 3, elements=st.floats(-1, 1, width=64)).filter(
    lambda v: np.linalg.norm(v) > 1e-3
)


@settings(max_examples=examples(200), deadline=None)
@given(st.lists(unit, min_size=1, max_size=6), st.lists(st.tuples(unit, unit), min_size=1))
@example(  # found by hypothesis: delta_theta 1.34e-12 degree apart at -15.8 degree
    [np.array([-0.3125, 0.0, 0.42578125])],
    [(np.array([0.578125, -0.8984375, 0.546875]), np.array([-0.90625, -0.984375, -0.6640625]))],
)
def test_chunk_angles_equal_facet_angles(normals, geometries):
    """Every lit and seen pair away from normal incidence gets the angles of
    ``geometry.facet_angles`` to 1e-12 degree (arc tangents 1 ulp apart, angles up to
    180 degrees: 1e-13 degree; the margin covers the difference of two of them).

    ``delta_theta`` is the angle of ``(o.e, o.n)``, whose length is ``cos(phi)``: an
    observer near the out-of-plane direction (``phi`` near 90 degrees) amplifies the
    rounding of those two dot products by ``1 / cos(phi)`` in any implementation (1.7e-5
    degree apart at ``cos(phi) = 1e-9`` in a sweep of such observers), and
    ``delta_theta`` is the difference of two angles, each from rounded vectors: its
    bound grows by ``64 eps / cos(phi)`` radians (8e-13 degree at ``phi = 0``).
    ``theta_i`` and ``phi`` are angles of unit-length pairs and keep the plain bound."""
    n = np.array([v / np.linalg.norm(v) for v in normals])
    s = np.array([a / np.linalg.norm(a) for a, _ in geometries])
    o = np.array([b / np.linalg.norm(b) for _, b in geometries])
    bufs = [np.full((n.shape[0], s.shape[0]), np.nan) for _ in range(6)]
    chunk_angles(np.ascontiguousarray(s.T), np.ascontiguousarray(o.T), 0, s.shape[0], n, *bufs)
    ns, no, st_len, ti, dt, phi = bufs
    ref = facet_angles(n[:, None, :], s[None], o[None], check=False)
    # the flags agree away from the terminator (numpy does not fix the order of a
    # three-term dot product, so a sum within rounding of 0 may take either sign)
    clear_s, clear_o = np.abs(ns) > 1e-15, np.abs(no) > 1e-15
    np.testing.assert_array_equal((ns > 0)[clear_s], ref.lit[clear_s])
    np.testing.assert_array_equal((no > 0)[clear_o], ref.visible[clear_o])
    np.testing.assert_allclose(ns, np.einsum("tk,gk->tg", n, s), rtol=0, atol=1e-15)
    use = ref.lit & ref.visible & (st_len > normal_incidence_tolerance(np.float64))
    for got, want in ((ti, ref.theta_i), (phi, ref.phi)):
        np.testing.assert_allclose(got[use], want[use], rtol=0, atol=1e-12)
    conditioning = np.degrees(64 * np.finfo(float).eps) / np.cos(np.radians(ref.phi[use]))
    assert np.all(np.abs(dt[use] - ref.delta_theta[use]) <= 1e-12 + conditioning)


@settings(max_examples=examples(200), deadline=None)
@given(unit, unit, unit, unit, st.sampled_from(["any", "sun_on_normal", "both_on_normal"]))
def test_facet_frame_and_psi_equal_the_numpy_specification(n, s, o, t, case):
    """One lit and seen pair through ``facet_frame`` (the anisotropic kernel's and the
    normal-incidence path of the fused kernel) gets the angles of
    ``geometry.facet_angles``, and ``tangent_azimuth`` the ``psi`` of
    ``anisotropy.illumination_azimuth``, also at normal incidence (the plane through the
    observer, or through the axis least aligned with the normal).  Bounds as in
    :func:`test_chunk_angles_equal_facet_angles`; ``psi`` is an angle between unit
    vectors built from the same frame (1e-12 degree), compared modulo 180 degree."""
    n = n / np.linalg.norm(n)
    s = n if case != "any" else s / np.linalg.norm(s)
    o = n if case == "both_on_normal" else o / np.linalg.norm(o)
    ns, no = float(n @ s), float(n @ o)
    if not (ns > 1e-6 and no > 1e-6):
        return
    tol = normal_incidence_tolerance(np.float64)
    ti, dt, phi, e, op = facet_frame(tuple(n), tuple(s), tuple(o), ns, no, tol)
    ref = facet_angles(n, s, o, check=False)
    assert abs(ti - ref.theta_i) <= 1e-12 and abs(phi - ref.phi) <= 1e-12
    conditioning = np.degrees(64 * np.finfo(float).eps) / np.cos(np.radians(float(ref.phi)))
    assert abs(dt - ref.delta_theta) <= 1e-12 + conditioning
    tt = t - (t @ n) * n
    if np.linalg.norm(tt) < 1e-3:
        return
    psi = tangent_azimuth(tuple(n), tuple(t), e, op, tol)
    want = float(illumination_azimuth(n, t, s, o, check=False))
    gap = (psi - want) % PSI_PERIOD
    assert min(gap, PSI_PERIOD - gap) <= 1e-12 + conditioning


def test_chunk_angles_fills_only_its_chunk():
    """Geometries ``g0 .. g0 + nc - 1`` go to columns ``0 .. nc - 1``; the rest stay."""
    rng = np.random.default_rng(3)
    s = rng.normal(size=(3, 10))
    s /= np.linalg.norm(s, axis=0)
    o = rng.normal(size=(3, 10))
    o /= np.linalg.norm(o, axis=0)
    n = np.array([[0.0, 0.0, 1.0]])
    bufs = [np.full((1, 8), -7.0) for _ in range(6)]
    chunk_angles(s, o, 4, 3, n, *bufs)
    assert np.all(bufs[0][0, 3:] == -7.0)
    np.testing.assert_allclose(bufs[0][0, :3], s[2, 4:7], rtol=0, atol=1e-15)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_fused_kernel_normal_incidence_pairs_take_the_exact_path(dtype):
    """A Sun on the normal (in-plane component 0) is recomputed by ``facet_frame``:
    the fused kernel then agrees with the numpy reference (checked in test_kernels for
    random scenes; here the pair the vectorised stage cannot serve)."""
    from sbrdf_xr.kernels import fused_sums, material_sums, pack_tables

    th = np.array([0.0, 10.0, 30.0, 60.0, 89.0])
    dth = np.array([-40.0, -10.0, 0.0, 10.0, 40.0])
    ph = np.array([0.0, 30.0, 90.0])
    rng = np.random.default_rng(5)
    values = rng.uniform(0.1, 1.0, (th.size, dth.size, ph.size, 4)).astype(dtype)
    tables = pack_tables([(values, th, dth, ph, (False, False, False))], 4, dtype)
    normals = np.array([[0.0, 0.0, 1.0]])
    to_sun = np.array([[0.0, 0.0, 1.0], [0.0, np.sin(0.2), np.cos(0.2)]])
    to_obs = np.array([[np.sin(0.3), 0.0, np.cos(0.3)], [np.sin(0.3), 0.0, np.cos(0.3)]])
    got = fused_sums(to_sun, to_obs, normals, np.ones(1), np.zeros(1, int), tables)
    ref = material_sums(
        to_sun, to_obs, normals, np.ones(1), values, th, dth, ph, zero_edges=(False,) * 3
    )
    rtol = 1e-12 if dtype == np.float64 else 1e-5
    np.testing.assert_allclose(got.signal, ref.signal, rtol=rtol)
    np.testing.assert_allclose(got.area, ref.area, rtol=1e-12)
