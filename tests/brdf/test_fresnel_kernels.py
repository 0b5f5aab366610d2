"""The compiled Fresnel kernels (sbrdf_xr.brdf._fresnel_kernels) against the numpy reference.

The kernels evaluate the formulas of :mod:`sbrdf_xr.brdf.optics` one point at a time,
grouped differently (a transparent layer's matrix without its unit phase factor,
``|a / b|^2`` as ``|a|^2 / |b|^2``); the numpy functions kept there are the reference.
Tolerance: both evaluate the same closed form in float64, a few dozen operations per
layer, so they agree to a few hundred ulp of the reflectance at worst (rtol 1e-12; the
catalog tables built with either agree to 1.5e-14); absolute 1e-15 where the reflectance
itself is ~0 (an anti-reflection minimum), whose rounding is absolute.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from hypothesis_profiles import examples

from sbrdf_xr.brdf import _fresnel_kernels, microfacet, optics

RTOL, ATOL = 1e-12, 1e-15

cosines = st.lists(
    st.one_of(
        st.floats(0.0, 1.0),
        st.sampled_from([0.0, 1.0, 1e-300, 1e-9, 0.5]),
    ),
    min_size=1,
    max_size=6,
)
indices = st.tuples(
    st.floats(0.05, 5.0),
    st.one_of(st.just(0.0), st.floats(0.0, 10.0)),
)
layer = st.tuples(indices, st.one_of(st.just(0.0), st.floats(0.0, 3000.0)))


@settings(max_examples=examples(150))
@given(
    c=cosines,
    wl=st.lists(st.floats(200.0, 3000.0), min_size=1, max_size=4),
    layers=st.lists(layer, max_size=3),
    substrate=indices,
    ambient=st.floats(1.0, 1.8),
    per_wavelength=st.booleans(),
)
def test_stack_kernel_matches_the_numpy_reference(
    c, wl, layers, substrate, ambient, per_wavelength
):
    wl = np.array(wl)
    cos = np.array(c)[:, None]
    if per_wavelength:  # a cosine per wavelength (a quadrature whose nodes move with lambda)
        cos = np.clip(cos * np.linspace(1.0, 0.5, wl.size), 0.0, 1.0)
    stack = [(complex(n, k), d) for (n, k), d in layers]
    sub = complex(*substrate)
    assume(sub != ambient)  # no interface: 0 / 0 at grazing incidence in either
    got = optics._stack_reflectance(cos, wl, stack, sub, ambient)
    ref = optics._stack_reflectance_numpy(cos, wl, stack, sub, ambient)
    assert got.shape == ref.shape == (len(c), wl.size)
    np.testing.assert_allclose(got, ref, rtol=RTOL, atol=ATOL)


@settings(max_examples=examples(150))
@given(c=cosines, n=st.lists(indices, min_size=1, max_size=4))
def test_conductor_kernel_matches_the_numpy_reference(c, n):
    idx = np.array([complex(*v) for v in n])
    cos = np.array(c)[:, None]
    got = optics.fresnel_conductor(cos, idx)
    ref = optics._fresnel_conductor_numpy(optics._check_cos(cos), idx)
    np.testing.assert_allclose(got, ref, rtol=RTOL, atol=ATOL)


def test_the_kernels_on_the_catalog_coating_and_closed_forms():
    """The CanX-1 cell's coating (two transparent layers on absorbing GaAs) over the
    whole range of angles, and the closed forms of optics at normal and grazing incidence."""
    wl = np.linspace(400.0, 1100.0, 141)
    layers = [(optics.sapphire_index(wl), 135.0), (optics.titania_index(wl), 95.0)]
    sub = optics.gaas_index(wl)
    cos = np.linspace(0.0, 1.0, 501)[:, None]
    got = optics._stack_reflectance(cos, wl, layers, sub)
    np.testing.assert_allclose(
        got, optics._stack_reflectance_numpy(cos, wl, layers, sub), rtol=RTOL, atol=ATOL
    )
    np.testing.assert_array_equal(got[0], 1.0)  # grazing: total reflection
    # a quarter-wave layer at normal incidence: ((n0 ns - n1^2) / (n0 ns + n1^2))^2
    n1, ns = 1.38, 1.52
    r = optics._stack_reflectance(np.ones((1, 1)), [550.0], [(n1, 550.0 / (4 * n1))], ns)
    assert r[0, 0] == pytest.approx(((ns - n1**2) / (ns + n1**2)) ** 2, rel=1e-13)


def test_rows_split_between_threads_give_the_same_numbers(monkeypatch):
    """Rows are independent: the threaded call equals the single-threaded one bit for bit."""
    wl = np.linspace(400.0, 1100.0, 50)
    cos = np.random.default_rng(1).uniform(0.0, 1.0, (4000, 1))
    layers = [(optics.sapphire_index(wl), 135.0), (1.5 + 0.01j, 80.0)]
    monkeypatch.setattr(_fresnel_kernels, "_THREAD_MIN", 0)
    monkeypatch.setattr(_fresnel_kernels, "_workers", lambda: 2)
    threaded = optics._stack_reflectance(cos, wl, layers, optics.gaas_index(wl))
    monkeypatch.setattr(_fresnel_kernels, "_workers", lambda: 1)
    single = optics._stack_reflectance(cos, wl, layers, optics.gaas_index(wl))
    np.testing.assert_array_equal(threaded, single)


@pytest.mark.parametrize("layers", [None, [(1.77, 135.0), (2.4, 95.0)]])
def test_a_shared_roughness_gives_each_wavelengths_own_numbers(layers):
    """With one roughness for every wavelength the quadrature's geometry is computed once;
    each wavelength's reflectance and BRDF equal those of that wavelength alone."""
    wl = np.array([450.0, 700.0, 1000.0])
    p = {"roughness": 0.03, "n": np.array([4.8, 3.7, 3.4]), "k": np.array([0.4, 0.1, 0.02])}
    p["rho_d"] = 0.005
    both = microfacet.directional_hemispherical_reflectance(
        [0.0, 40.0, 89.0], wl, layers=layers, **p
    )
    n, s, o = [0.0, 0.0, 1.0], [0.3, 0.0, 1.0], [-0.25, 0.1, 1.0]
    f = microfacet.brdf(n, s, o, wl, layers=layers, **p)
    for j in range(wl.size):
        one = {k: v[j] if np.ndim(v) else v for k, v in p.items()}
        alone = microfacet.directional_hemispherical_reflectance(
            [0.0, 40.0, 89.0], wl[j : j + 1], layers=layers, **one
        )
        np.testing.assert_allclose(both[:, j : j + 1], alone, rtol=1e-13)
        f1 = microfacet.brdf(n, s, o, wl[j : j + 1], layers=layers, **one)
        np.testing.assert_allclose(f[..., j : j + 1], f1, rtol=1e-13)
