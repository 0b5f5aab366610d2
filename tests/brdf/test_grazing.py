"""Hard cases at and near the horizon, for every registered BRDF model and the kernels.

Directions are drawn with their cosine to the normal log-uniform down to the smallest
normal float (and exactly 0, -0, negative), and pairs near forward scatter (``o`` within
1e-17..1 of ``-s``), where the half vector is rounding noise.

Tolerances:

* ``TOL_RECIPROCITY``: a model that claims reciprocity evaluates ``f(s, o)`` and
  ``f(o, s)`` with the same operations on swapped (commuting) operands; measured: bit
  identical on every example.  1e-13 relative (about 500 ulp) leaves room for a future
  rearrangement of the algebra, and is still 1e9 times below the 1e4 the forward-scatter
  fallback of the half vector once gave.
* ``TOL_SUM``: the fused kernel's ``S(s, o)`` and ``S(o, s)`` for a constant table are
  sums of the same products ``A N.s N.o f`` in another multiplication order and with
  look-up weights (summing to 1) at other nodes: a few ulp each, 1e-13 relative.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from hypothesis_profiles import examples

from sbrdf_xr import geometry
from sbrdf_xr.brdf import BRDF_MODELS, get_model, optics
from sbrdf_xr.brdf import robertson_sandford as RS
from sbrdf_xr.errors import ValidationError
from sbrdf_xr.kernels import fused_sums, pack_tables

TOL_RECIPROCITY = 1e-13
TOL_SUM = 1e-13
WL = np.array([450.0, 650.0, 900.0])
Z = np.array([0.0, 0.0, 1.0])
TINY = float(np.finfo(np.float64).tiny)  # smallest normal float, 2.2e-308

#: Parameters of each shipped model (a metal, a coated cell, a paint of Table 4).
PARAMS = {
    "lambert": {"rho": [0.2, 0.5, 0.9]},
    "microfacet": {"roughness": 0.1, "n": 1.3, "k": 6.0, "rho_d": 0.05},
    "anisotropic_microfacet": {
        "alpha_x": 0.05,
        "alpha_y": 0.3,
        "n": [1.2, 1.4, 2.0],
        "k": [6.0, 7.5, 8.5],
        "rho_d": 0.01,
    },
    "robertson_sandford": dict(RS.TABLE4["AFGL-01"]),
    "robertson_sandford_core": {**RS.TABLE4["AFGL-01"], "core_rho": 0.2, "core_roughness": 0.01},
    "robertson_sandford_halo": {
        **RS.TABLE4["AFGL-01"],
        "core_rho": 0.2,
        "core_roughness": 0.01,
        "halo_a": 1e-3,
        "halo_b": 1e-5,
        "halo_g": 2.5,
    },
}
RECIPROCAL = sorted(name for name, m in BRDF_MODELS.items() if m.reciprocal)
TANGENT = np.array([np.cos(0.4), np.sin(0.4), 0.0])


def evaluate(name, s, o, **update):
    m = get_model(name)
    kw = {**PARAMS[name], **update}
    if m.anisotropic:
        kw["tangent"] = TANGENT
    return m.brdf(Z, s, o, WL, **kw)


def test_every_shipped_model_has_test_parameters_and_the_claims_are_the_expected_ones():
    assert set(PARAMS) == set(BRDF_MODELS)
    # Robertson-Sandford is not reciprocal by construction (1/cos theta_r and H(theta_i)
    # in Eq. 15); the other three are.
    assert RECIPROCAL == ["anisotropic_microfacet", "lambert", "microfacet"]


#: cosine to the normal: log-uniform over the whole normal range, both signs, and 0, -0
cosines = st.one_of(
    st.floats(np.log10(TINY), 0.0).map(lambda x: 10.0**x),
    st.floats(np.log10(TINY), 0.0).map(lambda x: -(10.0**x)),
    st.sampled_from([0.0, -0.0, TINY, 1e-300, 1e-17, 1.0]),
)
azimuths = st.floats(0.0, 2 * np.pi)


def direction(cos_z, az):
    sin_z = np.sqrt(max(0.0, 1.0 - cos_z * cos_z))
    return np.array([sin_z * np.cos(az), sin_z * np.sin(az), cos_z])


@st.composite
def pairs(draw):
    """(s, o): independent directions, or o near -s (forward scatter), either grazing."""
    s = direction(draw(cosines), draw(azimuths))
    if draw(st.booleans()):
        return s, direction(draw(cosines), draw(azimuths))
    # forward scatter: o = -s turned by up to 10**k back into the upper hemisphere
    k = draw(st.floats(-17.0, 0.0))
    o = -s + 10.0**k * direction(draw(cosines), draw(azimuths))
    if np.linalg.norm(o) < 1e-6:
        o = -s + np.array([0.0, 0.0, 2 * abs(s[2]) + 1e-6])
    return s, o / np.linalg.norm(o)


@pytest.mark.parametrize("name", RECIPROCAL)
@settings(max_examples=examples(300), deadline=None)
@given(pair=pairs(), log_a=st.floats(-6.0, 3.0))
@example(  # doubly grazing forward scatter: once f(s, o) / f(o, s) = 1e4
    pair=((0.0, 1.0, 1e-300), (2.220446049250313e-16, -1.0, 2.076445471370354e-178)),
    log_a=-1.0,
)
def test_property_reciprocity_over_the_whole_domain(name, pair, log_a):
    s, o = (np.asarray(v, dtype=float) for v in pair)
    update = {}
    if name == "microfacet":
        update = {"roughness": 10.0**log_a}
    elif name == "anisotropic_microfacet":
        update = {"alpha_x": 10.0**log_a, "alpha_y": 10.0 ** min(log_a + 1.0, 3.0)}
    a = evaluate(name, s, o, **update)
    b = evaluate(name, o, s, **update)
    assert np.all(np.isfinite(a)) and np.all(a >= 0)
    np.testing.assert_allclose(a, b, rtol=TOL_RECIPROCITY, atol=0)


@pytest.mark.parametrize("name", sorted(PARAMS))
@settings(max_examples=examples(200), deadline=None)
@given(pair=pairs(), f32=st.booleans())
@example(pair=((0.0, 1.0, 0.0), (0.0, -1.0, 0.0)), f32=False)  # both on the horizon
@example(pair=((0.0, 1.0, -0.0), (0.0, 0.6, 0.8)), f32=False)
@example(pair=((0.0, 1.0, -TINY), (0.0, -1.0, TINY)), f32=True)
def test_property_zero_at_and_below_the_horizon_finite_above(name, pair, f32):
    dtype = np.float32 if f32 else np.float64
    s, o = (np.asarray(v, dtype=dtype) for v in pair)
    f = get_model(name).brdf(
        Z.astype(dtype),
        s,
        o,
        WL,
        **PARAMS[name],
        **({"tangent": TANGENT} if get_model(name).anisotropic else {}),
    )
    assert f.dtype == dtype and np.all(np.isfinite(f)) and np.all(f >= 0)
    if not (s[2] > 0 and o[2] > 0):
        assert np.all(f == 0), f


@settings(max_examples=examples(200), deadline=None)
@given(pair=pairs())
@example(pair=((0.0, 1.0, 1e-300), (2.220446049250313e-16, -1.0, 2.076445471370354e-178)))
def test_property_robertson_sandford_diffuse_term_is_reciprocal(pair):
    s, o = (np.asarray(v, dtype=float) for v in pair)
    p = PARAMS["robertson_sandford"]
    a = RS.diffuse_brdf(Z, s, o, WL, **p)
    b = RS.diffuse_brdf(Z, o, s, WL, **p)
    np.testing.assert_allclose(a, b, rtol=TOL_RECIPROCITY, atol=0)


@pytest.mark.parametrize("alpha", [1e-6, 1e-3, 0.1, 1.0, 1e3])
def test_the_signal_of_a_doubly_grazing_microfacet_glint_goes_to_zero(alpha):
    # s and o mirror each other through N at cosine c (the specular glint, D at its
    # peak): N.s N.o f_r = c^2 D F / (2 (c S + c S)) + c^2 rho_d / pi with S -> alpha,
    # bounded by c / (4 pi alpha^3) + c^2 rho_d / pi (D <= 1 / (pi alpha^2), F <= 1).
    p = {"roughness": alpha, "n": 1.3, "k": 6.0, "rho_d": 0.05}
    c = 10.0 ** -np.arange(1.0, 308.0)
    sin = np.sqrt(1.0 - c * c)
    s = np.stack([sin, np.zeros_like(c), c], axis=-1)
    o = np.stack([-sin, np.zeros_like(c), c], axis=-1)
    f = get_model("microfacet").brdf(Z, s, o, WL, **p)
    signal = (c * c)[:, None] * f
    bound = (c / (4 * np.pi * alpha**3) + c * c * 0.05 / np.pi)[:, None]
    assert np.all(np.isfinite(f)) and np.all(signal <= bound * (1 + 1e-12))
    # below c = alpha / 10 (S ~ alpha) the signal falls monotonically to 0
    flat = signal[c < alpha / 10, 0]
    assert flat.size > 200 and np.all(np.diff(flat) <= 0) and flat[-1] < 1e-280


def test_fresnel_reflectance_is_finite_and_tends_to_one_at_grazing():
    # F(cos) = 1 - O(cos) at grazing for any n + ik: |1 - F| <= 4 n cos / |n|^2-ish; a
    # bound of 10 cos holds for the indices here (n in 1.3-3.5, k in 0-8).
    c = np.concatenate([[0.0, 5e-324, TINY], 10.0 ** -np.arange(1.0, 300.0, 7.0)])
    for index in (1.3, 3.5 + 0.1j, 1.2 + 6.0j, 2.0 + 8.0j):
        f = optics.fresnel_conductor(c, index)
        assert np.all(np.isfinite(f)) and np.all((f >= 0) & (f <= 1))
        assert np.all(np.abs(1.0 - f) <= 10.0 * c), index


@settings(max_examples=examples(100), deadline=None)
@given(seed=st.integers(0, 2**32 - 1), method=st.sampled_from(["nearest", "linear", "cubic"]))
def test_property_fused_kernel_is_reciprocal_for_a_constant_table(seed, method):
    # A table holding one value at every node (a Lambertian surface) makes S(s, o) =
    # sum_j A_j N.s N.o f symmetric: the kernel's lit and seen tests must be too, down
    # to cosines of the smallest normal float.
    rng = np.random.default_rng(seed)
    normals = rng.normal(size=(12, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    areas = rng.uniform(0.1, 1.0, 12)
    s = rng.normal(size=(40, 3))
    s /= np.linalg.norm(s, axis=1, keepdims=True)
    o = rng.normal(size=(40, 3))
    o /= np.linalg.norm(o, axis=1, keepdims=True)
    # half the geometries graze facet 0 from both sides, at cosines down to TINY
    k = np.arange(0, 40, 2)
    t = geometry.normalize(np.cross(normals[0], rng.normal(size=(k.size, 3))))
    eps = 10.0 ** rng.uniform(np.log10(TINY), -1, (2, k.size))
    s[k] = geometry.normalize(t + eps[0][:, None] * normals[0])
    o[k] = geometry.normalize(-t + eps[1][:, None] * normals[0])
    grid = (np.array([0.0, 30.0, 60.0, 90.0]), np.linspace(-90, 90, 5), np.array([0, 45, 90.0]))
    values = np.full((4, 5, 3, 2), 0.3 / np.pi)
    packed = pack_tables([(values, *grid, (False, False, False), 0.0)], 2, "float64")
    mat = np.zeros(12, dtype=np.int64)
    a = fused_sums(s, o, normals, areas, mat, packed, method).signal
    b = fused_sums(o, s, normals, areas, mat, packed, method).signal
    # the cosines summed in the kernel's order (a BLAS product rounds cosines of 1e-17,
    # the rounding of the unit vectors themselves, to other values and signs)
    ns, no = ((v[:, None, :] * normals[None]).sum(-1) for v in (s, o))
    want = (areas * np.where((ns > 0) & (no > 0), ns * no, 0.0)).sum(1)
    np.testing.assert_allclose(a, b, rtol=TOL_SUM, atol=0)
    np.testing.assert_allclose(a[:, 0], 0.3 / np.pi * want, rtol=TOL_SUM, atol=0)


@pytest.mark.parametrize("name", sorted(PARAMS))
def test_bad_directions_keep_their_named_errors_and_lengths_do_not_matter(name):
    s, o = np.array([0.3, 0.1, 0.9]), np.array([-0.2, 0.4, 0.8])
    np.testing.assert_allclose(
        evaluate(name, 7.0 * s, 0.01 * o), evaluate(name, s, o), rtol=1e-14, atol=0
    )
    for bad in ([0.0, 0.0, 0.0], [np.nan, 0.0, 1.0], [np.inf, 0.0, 1.0]):
        with pytest.raises(ValidationError, match="to_sun"):
            evaluate(name, np.array(bad), o)
        with pytest.raises(ValidationError, match="to_observer"):
            evaluate(name, s, np.array(bad))
