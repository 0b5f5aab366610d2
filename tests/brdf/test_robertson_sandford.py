"""Tests of the Robertson–Sandford model (paper 001 §4, Eqs. 5–21)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_profiles import examples
from scipy import integrate

from sbrdf_xr.brdf import robertson_sandford as rs
from sbrdf_xr.errors import ValidationError

# --- tolerances (defined once) ---------------------------------------------
#: Hemispherical integral of the BRDF without cut-off vs 1 - eps(theta_i): smooth
#: integrands in glint-centred coordinates, Gauss-Legendre converges to ~1e-13; the
#: limit is the float64 evaluation of the BRDF from re-normalised vectors (relative
#: error of alpha ~1e-10 for e = 1e-6 lobes), hence 1e-8.
TOL_HEMISPHERE = 1e-8
#: Hemispherical integral with the cut-off vs directional_hemispherical_reflectance:
#: the test quadrature does not split at the 80-deg kink of Eq. 21, so Gauss-Legendre
#: converges only as N^-2 (~1e-6 of rho_s at N = 400); absolute tolerance.
TOL_CUTOFF = 2e-5

WL = np.array([500.0, 1000.0, 4000.0])  # [nm]
AFGL01 = {"rho_D": 0.07, "epsilon": 0.85, "b": 0.12, "e": 0.12}  # Table 4
AFGL10 = {"rho_D": 0.05, "epsilon": 0.88, "b": 0.08, "e": 0.012}  # Table 4


def _gl(n: int, a: float, b: float) -> tuple[np.ndarray, np.ndarray]:
    t, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (b - a) * t + 0.5 * (b + a), 0.5 * (b - a) * w


def glint_nodes(theta_i: float, e: float, n_phi: int = 128, n_x: int = 128):
    """Directions ``o`` and weights ``w`` with ``sum w f(o) ~ int f cos(theta_r) dOmega_r``.

    Half-vector coordinates centred on the glint: azimuth ``phi_h`` and ``x`` with
    ``tan(alpha) = e tan(x)``; for each ``phi_h`` the x-range ends exactly at the
    horizon (``cos theta_r = R cos(2 alpha - beta)``).  Symmetric in ``phi_h``.
    """
    ti = np.radians(theta_i)
    s = np.array([np.sin(ti), 0.0, np.cos(ti)])
    phis, wphis = [], []
    for a, b in ((0.0, np.pi / 2), (np.pi / 2, np.pi)):
        p, w = _gl(n_phi, a, b)
        phis.append(p)
        wphis.append(w)
    phi, wphi = np.concatenate(phis), 2.0 * np.concatenate(wphis)
    beta = np.arctan2(np.cos(phi) * np.sin(ti), np.cos(ti))
    x_max = np.arctan2(np.tan(0.5 * (beta + 0.5 * np.pi)), e)
    t, wt = _gl(n_x, 0.0, 1.0)
    x = x_max[:, None] * t
    wx = x_max[:, None] * wt
    tx = np.tan(x)
    alpha = np.arctan(e * tx)
    dalpha = e * (1 + tx**2) / (1 + (e * tx) ** 2)
    h = np.stack(
        [np.sin(alpha) * np.cos(phi)[:, None], np.sin(alpha) * np.sin(phi)[:, None], np.cos(alpha)],
        axis=-1,
    )
    hs = h @ s
    o = 2 * hs[..., None] * h - s
    w = wphi[:, None] * wx * 4 * hs * np.sin(alpha) * dalpha * o[..., 2]
    return s, o, w


def sphere_nodes(n: int = 200):
    """Product Gauss-Legendre nodes over the hemisphere for ``int f cos dOmega``."""
    th, wth = _gl(n, 0.0, np.pi / 2)
    ph, wph = _gl(2 * n, 0.0, 2 * np.pi)
    th, ph = np.meshgrid(th, ph, indexing="ij")
    o = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=-1)
    w = wth[:, None] * wph[None, :] * np.sin(th) * np.cos(th)
    return o, w


def _s(theta_i: float) -> np.ndarray:
    t = np.radians(theta_i)
    return np.array([np.sin(t), 0.0, np.cos(t)])


Z = np.array([0.0, 0.0, 1.0])


# --- Eqs. 11, 13, 15, 17: hemispherical integrals ------------------------------

CASES = [
    AFGL01,
    AFGL10,
    {"rho_D": 0.2, "epsilon": 0.3, "b": 0.0, "e": 1.0},
    {"rho_D": 0.1, "epsilon": 0.2, "b": 1.5, "e": 1e-6},
    {"rho_D": 0.0, "epsilon": 0.4, "b": 0.3, "e": 0.4},
]


@pytest.mark.parametrize("params", CASES)
@pytest.mark.parametrize("theta_i", [0.0, 30.0, 60.0, 85.0])
def test_hemispherical_integral_equals_one_minus_emissivity(params, theta_i):
    wl = WL[:1]
    o, w = sphere_nodes(150)
    s = _s(theta_i)
    diffuse = np.einsum("ij,ijk->k", w, rs.diffuse_brdf(Z, s, o, wl, **params))
    s, og, wg = glint_nodes(theta_i, params["e"])
    spec = np.einsum("ij,ijk->k", wg, rs.specular_brdf(Z, s, og, wl, cutoff=False, **params))
    expected = 1 - rs.directional_emissivity(theta_i, wl, **params)
    assert diffuse + spec == pytest.approx(expected, rel=TOL_HEMISPHERE)
    # and each part separately (Eq. 13 -> rho_D g/G, Eq. 15 -> rho_s)
    assert diffuse == pytest.approx(
        rs.diffuse_reflectance(theta_i, wl, **params), rel=TOL_HEMISPHERE, abs=1e-15
    )
    assert spec == pytest.approx(
        rs.specular_reflectance(theta_i, wl, **params), rel=TOL_HEMISPHERE, abs=1e-15
    )
    no_cut = rs.directional_hemispherical_reflectance(theta_i, wl, cutoff=False, **params)
    assert no_cut == pytest.approx(expected, rel=1e-14)


def test_diffuse_fraction_averages_to_rho_D():
    """rho_d(theta_i) = rho_D g/G has cosine-weighted hemispherical mean rho_D (Eq. 13)."""
    t, w = _gl(200, 0, 90)
    rho_d = rs.diffuse_reflectance(t, WL[:1], **AFGL01)[:, 0]
    mean = 2 * np.sum(w * np.radians(1) * rho_d * np.sin(np.radians(t)) * np.cos(np.radians(t)))
    assert mean == pytest.approx(AFGL01["rho_D"], rel=1e-10)


@pytest.mark.parametrize("params", [AFGL01, AFGL10])
@pytest.mark.parametrize("theta_i", [20.0, 60.0, 80.0, 86.0])
def test_cutoff_hemispherical_integral(params, theta_i):
    """With the Eq. 21 cut-off the BRDF integrates to rho_d + rho_s (1 - L)."""
    wl = WL[:1]
    o, w = sphere_nodes(150)
    s = _s(theta_i)
    diffuse = np.einsum("ij,ijk->k", w, rs.diffuse_brdf(Z, s, o, wl, **params))
    s, og, wg = glint_nodes(theta_i, params["e"], n_phi=200, n_x=400)
    spec = np.einsum("ij,ijk->k", wg, rs.specular_brdf(Z, s, og, wl, cutoff=True, **params))
    dhr = rs.directional_hemispherical_reflectance(theta_i, wl, **params)
    assert diffuse + spec == pytest.approx(dhr, abs=TOL_CUTOFF)
    total = rs.total_reflectance(theta_i, wl, **params)
    assert np.all(dhr <= total)


def test_cutoff_loss_by_independent_quadrature():
    """The lost fraction L by adaptive quadrature over the 80-90 deg band (plain angles)."""
    p = AFGL01
    ti = 60.0
    s = _s(ti)
    b, e = p["b"], p["e"]
    h_norm = rs.normalisation_H(ti, e)

    def f(phr, thr):
        o = np.array([np.sin(thr) * np.cos(phr), np.sin(thr) * np.sin(phr), np.cos(thr)])
        g = (o + s) / np.linalg.norm(o + s)
        h = 1.0 / (e**2 * g[2] ** 2 + g[0] ** 2 + g[1] ** 2) ** 2
        return np.sin(thr) * h * (1 - rs.cutoff_factor(np.degrees(thr), b))

    lost = integrate.dblquad(f, np.radians(80), np.pi / 2, 0, 2 * np.pi, epsabs=1e-12, epsrel=1e-9)[
        0
    ] / (4 * np.pi * h_norm)
    rho_s = rs.specular_reflectance(ti, WL[:1], **p)[0]
    no_cut = rs.directional_hemispherical_reflectance(ti, WL[:1], cutoff=False, **p)[0]
    cut = rs.directional_hemispherical_reflectance(ti, WL[:1], **p)[0]
    assert (no_cut - cut) / rho_s == pytest.approx(lost, rel=1e-6)


#: The cut-off reflectance against an adaptive cubature (scipy ``cubature``, GK21)
#: of the public specular BRDF over the 80-90 deg band, in coordinates logarithmic in
#: the distance from the mirror direction (so the needle lobe is a smooth feature of
#: unit width); the cubature is asked for 1e-12 relative, 1e-14 absolute, and the
#: two agree to ~1e-13 (measured): the issue's requirement is 1e-10.
TOL_CUTOFF_EXACT = 1e-10


def _cutoff_reference(theta_i: float, p: dict) -> float:
    """``1 - eps(theta_i)`` minus the band integral of ``(f_s uncut - f_s cut) cos dOmega``."""
    s = _s(theta_i)
    lo, hi = np.radians(80.0), np.pi / 2
    peak = min(max(np.radians(theta_i), lo), hi)

    def band(x, side):
        d, psi = np.exp(x[:, 0]), np.exp(x[:, 1])  # distance from the peak, pi - phi_r
        th = peak + side * d
        o = np.stack([-np.sin(th) * np.cos(psi), np.sin(th) * np.sin(psi), np.cos(th)], -1)
        f_uncut = rs.specular_brdf(Z, s, o, WL[2:], cutoff=False, **p)[:, 0]
        f_cut = rs.specular_brdf(Z, s, o, WL[2:], **p)[:, 0]
        return 2.0 * (f_uncut - f_cut) * np.cos(th) * np.sin(th) * d * psi

    lost = 0.0
    for side, length in ((-1.0, peak - lo), (1.0, hi - peak)):
        if length > 0:
            lower, upper = [np.log(1e-22)] * 2, [np.log(length), np.log(np.pi)]
            res = integrate.cubature(
                lambda x, side=side: band(x, side), lower, upper, rtol=1e-12, atol=1e-14
            )
            lost += res.estimate
    return float(rs.total_reflectance(theta_i, WL[2:], **p)[0] - lost)


NEEDLE = {"rho_D": 0.05, "epsilon": 0.3, "b": 0.6, "e": 1e-4}


@pytest.mark.parametrize(
    ("params", "theta_i"),
    [
        (AFGL01, 40.0),
        (AFGL01, 80.0),
        (AFGL01, 89.9),
        (AFGL10, 85.0),
        (AFGL10, 89.99),
        (NEEDLE, 79.9),
        pytest.param(AFGL01, 89.99, marks=pytest.mark.slow),
        pytest.param(AFGL10, 89.9, marks=pytest.mark.slow),
        pytest.param(NEEDLE, 85.0, marks=pytest.mark.slow),
    ],
)
def test_cutoff_reflectance_to_1e_10(params, theta_i):
    """The cut-off reflectance to 1e-10 up to 89.99 deg and for needle lobes (issue 46)."""
    got = rs.directional_hemispherical_reflectance(theta_i, WL[2:], **params)[0]
    assert got == pytest.approx(_cutoff_reference(theta_i, params), abs=TOL_CUTOFF_EXACT)


def _loss_glint_centred(theta_i: float, b: float, e: float) -> float:
    """The lost fraction L by nested adaptive quad in glint-centred coordinates.

    Azimuth ``phi_h`` of the glint vector and ``x`` with ``tan(alpha) = e tan(x)``
    (the lobe is smooth in x); the band ``theta_r > 80 deg`` is cut out in closed
    form (``cos(theta_r) = R cos(2 alpha - beta)``) and the azimuth range is split
    where the band boundary turns (square-root points) and around 90 deg, where
    the glint vector swings over ``~cot(theta_i)`` near grazing.
    """
    ti = np.radians(theta_i)
    ci, si, c80 = np.cos(ti), np.sin(ti), np.cos(np.radians(80.0))

    def x_of(a):
        return np.arctan2(np.tan(a), e)

    def inner(phi):
        bp = np.cos(phi) * si
        r, beta = np.hypot(ci, bp), np.arctan2(bp, ci)
        a_max = 0.5 * (beta + 0.5 * np.pi)
        gam = np.arccos(min(c80 / r, 1.0))
        a1 = min(max(0.5 * (beta - gam), 0.0), a_max)
        a2 = min(max(0.5 * (beta + gam), 0.0), a_max)

        def f(x):
            alpha = np.arctan(e * np.tan(x))
            cos_r = np.clip(ci * np.cos(2 * alpha) + bp * np.sin(2 * alpha), 0.0, 1.0)
            cut = rs.cutoff_factor(np.degrees(np.arccos(cos_r)), b)
            return (np.sin(x) * np.cos(x) * ci + e * np.sin(x) ** 2 * bp) * (1.0 - cut)

        pieces = [(lo, hi) for lo, hi in ((0.0, a1), (a2, a_max)) if hi > lo]
        return sum(
            integrate.quad(f, x_of(lo), x_of(hi), epsabs=1e-16, epsrel=1e-13, limit=400)[0]
            for lo, hi in pieces
        )

    pts = {0.5 * np.pi + k * ci / si for k in (-30, -10, -3, -1, 0, 1, 3, 10, 30)}
    if ci < c80:
        c_star = np.sqrt(c80**2 - ci**2) / si
        pts |= {np.arccos(c_star), np.arccos(-c_star)}
    edges = [0.0, *sorted(q for q in pts if 0 < q < np.pi), np.pi]
    total = sum(
        integrate.quad(inner, a, z, epsabs=1e-16, epsrel=1e-13, limit=400)[0]
        for a, z in itertools.pairwise(edges)
    )
    return (2.0 / np.pi) * total / (rs.normalisation_H(theta_i, e) * e * e)


@pytest.mark.parametrize(
    ("params", "theta_i"),
    [
        (NEEDLE, 89.9),
        (AFGL01, 89.99),
        pytest.param(NEEDLE, 89.99, marks=pytest.mark.slow),
        pytest.param({**NEEDLE, "e": 1e-3}, 89.99, marks=pytest.mark.slow),
        pytest.param(AFGL10, 89.9, marks=pytest.mark.slow),
    ],
)
def test_cutoff_reflectance_needle_at_grazing(params, theta_i):
    """A second, independent reference (glint-centred nested quad) near grazing."""
    rho_s = rs.specular_reflectance(theta_i, WL[2:], **params)[0]
    loss = _loss_glint_centred(theta_i, params["b"], params["e"])
    ref = rs.total_reflectance(theta_i, WL[2:], **params)[0] - rho_s * loss
    got = rs.directional_hemispherical_reflectance(theta_i, WL[2:], **params)[0]
    assert got == pytest.approx(ref, abs=TOL_CUTOFF_EXACT)


def test_cutoff_reflectance_issue_value_at_grazing():
    """AFGL-01 at 89.9 deg: 0.9148925146 by two independent quadratures (issue 46)."""
    got = rs.directional_hemispherical_reflectance(89.9, WL[2:], **AFGL01)[0]
    assert got == pytest.approx(0.9148925146, abs=1e-10)


def test_cutoff_loss_documented_values():
    """The cut-off removes little below 60 deg and more toward grazing (module notes)."""
    ti = np.array([0.0, 60.0, 80.0, 89.0])
    for p, at60, at80 in ((AFGL01, 0.0145, 0.0925), (AFGL10, 1.6e-4, 0.026)):
        lost = (
            rs.directional_hemispherical_reflectance(ti, WL[:1], cutoff=False, **p)
            - rs.directional_hemispherical_reflectance(ti, WL[:1], **p)
        )[:, 0]
        frac = lost / rs.specular_reflectance(ti, WL[:1], **p)[:, 0]
        assert np.all(np.diff(frac) > 0)
        assert frac[1] < at60 and frac[2] < at80 and frac[2] > 0.5 * at80


def test_cutoff_factor_shape():
    th = np.array([0.0, 45.0, 80.0, 85.0, 89.9, 90.0])
    c = rs.cutoff_factor(th, 0.12)
    assert np.all(c[:3] == 1.0)
    assert 0 < c[3] < 1 and c[4] < c[3] and c[5] == pytest.approx(0.0, abs=1e-20)
    assert np.all(rs.cutoff_factor(th, 0.0) == 1.0)
    # the specular BRDF goes to zero at the horizon with the cut-off, diverges without
    s = _s(60.0)
    graz = np.array([-1.0, 0.0, 1e-9])
    assert rs.specular_brdf(Z, s, graz, WL, **AFGL01)[0] < 1e-6
    assert rs.specular_brdf(Z, s, graz, WL, cutoff=False, **AFGL01)[0] > 1e3


# --- paper figures and tables ---------------------------------------------------


def test_fig9_total_reflectance_rises_toward_grazing_more_for_larger_b():
    ti = np.linspace(0, 89, 90)
    rises = []
    for b in (0.05, 0.12, 0.3):
        r = rs.total_reflectance(ti, WL[:1], rho_D=0.05, epsilon=0.75, b=b, e=0.1)[:, 0]
        assert np.all(np.diff(r) >= 0)
        rises.append(r[80] - r[0])
    assert rises[0] < rises[1] < rises[2]


def test_fig10_lobe_narrows_and_peak_rises_as_e_shrinks():
    """20 deg incidence, specular-only reflectivity 0.2 (paper 001 Fig. 10)."""
    b = 0.05
    g20 = rs.angular_g(20.0, b) / rs.normalisation_G(b)
    p = {"rho_D": 0.0, "epsilon": 0.8 / g20, "b": b}
    assert rs.specular_reflectance(20.0, WL[:1], e=0.1, **p)[0] == pytest.approx(0.2)
    dt = np.linspace(-60, 60, 24001)
    peaks, widths = [], []
    for e in (0.3, 0.12, 0.05):
        f = rs.brdf_angles(20.0, dt, 0.0, WL[:1], e=e, **p)[:, 0]
        peaks.append(f.max())
        above = dt[f >= f.max() / 2]
        widths.append(above.max() - above.min())
        # peak near the specular direction (broad lobes peak slightly off-specular,
        # pushed outward by the 1/cos(theta_r) of Eq. 15)
        assert abs(dt[np.argmax(f)]) < 20 * e
    assert peaks[0] < peaks[1] < peaks[2]
    assert widths[0] > widths[1] > widths[2]


def _fwhm_40(params: dict, blur: float = 0.0) -> float:
    """In-plane FWHM [degree] of the BRDF at 40 deg incidence, optionally blurred."""
    from scipy.ndimage import gaussian_filter1d

    dt = np.linspace(-60, 60, 240001)
    f = rs.brdf_angles(40.0, dt, 0.0, WL[2:], **params)[:, 0]
    if blur:
        f = gaussian_filter1d(f, blur / np.sqrt(8 * np.log(2)) / (dt[1] - dt[0]), mode="nearest")
    above = dt[f >= f.max() / 2]
    return above.max() - above.min()


def test_table3_lobe_widths_at_40_deg():
    """Table 3 (24 and 3 deg) against Table 4's parameters: the documented numbers.

    The 0.01-deg sampling of the scan bounds each width to 0.01 deg (tolerance 0.02).
    """
    assert _fwhm_40(AFGL01) == pytest.approx(19.25, abs=0.02)
    assert _fwhm_40(AFGL10) == pytest.approx(1.77, abs=0.02)
    # the e that would give Table 3's widths
    assert _fwhm_40({**AFGL01, "e": 0.144}) == pytest.approx(24.0, abs=0.05)
    assert _fwhm_40({**AFGL10, "e": 0.0203}) == pytest.approx(3.0, abs=0.02)
    # a 2.14-deg instrument response explains AFGL-10's 3 deg, not AFGL-01's 24 deg
    assert _fwhm_40(AFGL10, blur=2.14) == pytest.approx(3.0, abs=0.02)
    assert _fwhm_40(AFGL01, blur=2.14) == pytest.approx(19.46, abs=0.02)


def test_table3_solar_absorptance_is_not_a_4um_quantity():
    """Grey 4-um parameters absorb ~0.89-0.90, Table 3's solar values are 0.77 and 0.26."""
    a01 = 1 - rs.directional_hemispherical_reflectance(0.0, WL[2:], **AFGL01)[0]
    a10 = 1 - rs.directional_hemispherical_reflectance(0.0, WL[2:], **AFGL10)[0]
    assert a01 == pytest.approx(0.893, abs=5e-4) and a10 == pytest.approx(0.904, abs=5e-4)
    assert a01 - 0.77 > 0.1 and a10 - 0.26 > 0.6


def test_diffuse_reciprocity():
    rng = np.random.default_rng(1)
    s = rng.normal(size=(200, 3))
    o = rng.normal(size=(200, 3))
    s[:, 2] = np.abs(s[:, 2])
    o[:, 2] = np.abs(o[:, 2])
    p = {"rho_D": [0.05, 0.1, 0.2], "epsilon": 0.6, "b": 0.3, "e": 0.2}
    a = rs.diffuse_brdf(Z, s, o, WL, **p)
    b = rs.diffuse_brdf(Z, o, s, WL, **p)
    np.testing.assert_allclose(a, b, rtol=1e-13)
    assert np.all(a > 0)


# --- stability -------------------------------------------------------------------


@st.composite
def directions(draw):
    special = [
        (0.0, 0.0, 1.0),
        (1.0, 0.0, 0.0),
        (1.0, 0.0, 1e-9),
        (0.0, -1.0, 1e-300),
        (1e-12, 0.0, 1.0),
        (-1.0, 1e-12, 1e-8),
        (0.0, 0.0, -1.0),
    ]
    return draw(
        st.one_of(
            st.tuples(*[st.floats(-1, 1, allow_subnormal=False)] * 3).filter(
                lambda v: v[0] ** 2 + v[1] ** 2 + v[2] ** 2 > 1e-6
            ),
            st.sampled_from(special),
        )
    )


@st.composite
def rs_params(draw):
    b = draw(st.one_of(st.just(0.0), st.just(1.0), st.floats(0, 5)))
    e = draw(st.one_of(st.just(1e-6), st.just(1.0), st.floats(-6, 0).map(lambda x: 10**x)))
    g = float(rs.normalisation_G(b))
    t = draw(st.floats(0, 1))
    u = draw(st.floats(0, 1))
    return {"rho_D": t * u * g, "epsilon": t * (1 - u) * g, "b": b, "e": e}


@settings(max_examples=examples(100), deadline=None)
@given(
    s=directions(),
    o=directions(),
    p=rs_params(),
    dtype=st.sampled_from([np.float32, np.float64]),
    cutoff=st.booleans(),
    forward=st.booleans(),
)
def test_property_finite_nonnegative(s, o, p, dtype, cutoff, forward):
    s = np.array(s, dtype=dtype)
    o = -s if forward else np.array(o, dtype=dtype)  # phase angle 180 deg included
    n = np.array([0, 0, 1], dtype=dtype)
    f = rs.brdf(n, s, o, WL, cutoff=cutoff, **p)
    assert f.shape == (3,) and f.dtype == dtype
    assert np.all(np.isfinite(f)) and np.all(f >= 0)
    if not (s[2] > 0 and o[2] > 0):
        assert np.all(f == 0)


def test_phase_angle_180_and_grazing_glint():
    s = np.array([1.0, 0.0, 1e-8])
    o = np.array([-1.0, 1e-12, 1e-8])  # almost exactly forward scatter, both grazing
    for p in (AFGL01, AFGL10, {**AFGL10, "e": 1e-6, "b": 0.0}):
        f = rs.brdf(Z, s, o, WL, **p)
        assert np.all(np.isfinite(f)) and np.all(f >= 0)
    assert np.all(rs.brdf(Z, s, -s, WL, **AFGL01) == 0)


def test_needle_lobe_peak_is_finite_and_correct():
    p = {"rho_D": 0.0, "epsilon": 0.5, "b": 0.0, "e": 1e-6}
    f = rs.brdf_angles(30.0, 0.0, 0.0, WL[:1], cutoff=False, **p)[0]
    # h(0) = e^-4, H = cos30 / e^2 (1 + O(e^2)): f = rho_s / (4 pi e^2 cos^2 30)
    assert f == pytest.approx(0.5 / (4 * np.pi * 1e-12 * np.cos(np.radians(30)) ** 2), rel=1e-9)


def test_shapes_and_broadcasting():
    s = np.stack([_s(t) for t in (10, 30, 50, 70)])  # (4, 3)
    o = np.stack([[0.1, 0.2, 1.0]] * 5)[:, None, :]  # (5, 1, 3)
    f = rs.brdf(Z, s, o, WL, **AFGL01)
    assert f.shape == (5, 4, 3)
    p = {
        "rho_D": [0.05, 0.07, 0.1],
        "epsilon": [0.8, 0.85, 0.8],
        "b": [0.1, 0.12, 0.14],
        "e": [0.1, 0.12, 0.14],
    }
    f2 = rs.brdf(Z, s, o, WL, **p)
    for k in range(3):
        single = {name: v[k] for name, v in p.items()}
        np.testing.assert_allclose(
            f2[..., k], rs.brdf(Z, s, o, WL[k : k + 1], **single)[..., 0], rtol=1e-14
        )
    dhr = rs.directional_hemispherical_reflectance(np.array([[10.0, 20.0], [30.0, 89.0]]), WL, **p)
    assert dhr.shape == (2, 2, 3)


@pytest.mark.parametrize(
    ("update", "name"),
    [
        ({"rho_D": -0.1}, "rho_D"),
        ({"e": 0.0}, "e"),
        ({"b": -1.0}, "b"),
        ({"epsilon": 1.2}, "epsilon"),
        ({"epsilon": [0.8, np.nan, 0.8]}, "epsilon"),
        ({"rho_D": [0.1, 0.1]}, "rho_D"),
        ({"rho_D": 0.5, "epsilon": 0.49, "b": 0.5}, "G(b)"),
    ],
)
def test_validation_errors(update, name):
    with pytest.raises(ValidationError, match=name.replace("(", r"\(").replace(")", r"\)")):
        rs.check_params(WL, **{**AFGL01, **update})


def test_validation_missing_and_unknown():
    with pytest.raises(ValidationError, match="missing"):
        rs.check_params(WL, rho_D=0.1, epsilon=0.5, b=0.1)
    with pytest.raises(ValidationError, match="unexpected"):
        rs.check_params(WL, **AFGL01, rho=0.1)


@pytest.mark.parametrize("e", [1e-12, 1e-10, 1e-9])
def test_needle_lobe_evaluates_without_warnings(e):
    # e <= 1e-9 once hit a 1/0 in the unselected branch of Eq. 18's cancellation-free
    # form (S - A -> 0 for A > 0); pytest turns RuntimeWarning into errors.  Values: the
    # peak is rho_s / (4 pi e^2 cos^2 theta_i) to O(e^2) (the needle-lobe limit above).
    p = {"rho_D": 0.0, "epsilon": 0.5, "b": 0.0, "e": e}
    ti = np.array([0.0, 30.0, 60.0, 89.0])
    f = rs.brdf_angles(ti, 0.0, 0.0, WL[:1], cutoff=False, **p)[:, 0]
    np.testing.assert_allclose(f, 0.5 / (4 * np.pi * e**2 * np.cos(np.radians(ti)) ** 2), rtol=1e-9)
    off = rs.brdf_angles(ti, 5.0, 0.0, WL[:1], **{**p, "b": 0.1})
    assert np.all(np.isfinite(off)) and np.all(off >= 0)
    # Without the cut-off the hemispherical reflectance is 1 - epsilon (Eq. 11).
    rho = rs.directional_hemispherical_reflectance(ti, WL[:1], cutoff=False, **p)
    np.testing.assert_allclose(rho, 0.5, rtol=1e-12)
    h = rs.normalisation_H(ti, e)
    assert np.all(np.isfinite(h)) and np.all(h > 0)


def test_zero_lobe_width_is_a_named_error_and_its_normalisation_limit_is_finite():
    # e = 0 is a Dirac lobe, outside the model's domain (a named error, no warning);
    # the normalisation's cancellation-free core e^2 H tends to cos(theta_i) as e -> 0
    # (Eq. 18) and to 0 at grazing incidence, without dividing by zero.
    with pytest.raises(ValidationError, match="e: got"):
        rs.brdf_angles(30.0, 0.0, 0.0, WL, rho_D=0.1, epsilon=0.5, b=0.1, e=0.0)
    ci = np.cos(np.radians([0.0, 30.0, 60.0, 90.0]))
    np.testing.assert_allclose(rs._e2_h_norm(ci, np.zeros(4)), ci, atol=1e-15)
