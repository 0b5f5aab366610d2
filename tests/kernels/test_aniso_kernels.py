"""Anisotropic tables through Scene, the plan and the kernels (sbrdf_xr.kernels.anisotropic)."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_profiles import examples

from sbrdf_xr import catalog, geometry
from sbrdf_xr import testing as T
from sbrdf_xr.body.spacecraft import Spacecraft
from sbrdf_xr.brdf import anisotropic as A
from sbrdf_xr.engine import Scene
from sbrdf_xr.engine.plan import compile_plan
from sbrdf_xr.engine.run import simulate
from sbrdf_xr.geometry import anisotropy
from sbrdf_xr.kernels import anisotropic as AK
from sbrdf_xr.materials import energy, models
from sbrdf_xr.materials import tables as material

WL = np.array([500.0, 700.0])
OPT = {"n": [1.2, 1.5], "k": [6.0, 7.0], "rho_d": 0.01}
# A coarse grid keeps rendering fast; the tests below either compare two paths that
# interpolate the same nodes, or put the geometry on the nodes.
GRIDS = (np.arange(0, 91, 10.0), np.arange(-180, 91, 10.0), np.arange(0, 91, 10.0))
PSI = np.arange(0.0, 181.0, 20.0)
MAT = T.TEST_SPACECRAFT_MATERIAL


def aniso_spec(ax, ay):
    return models.model_material(
        "anisotropic_microfacet", WL, material=MAT, provenance="test", alpha_x=ax, alpha_y=ay, **OPT
    )


@pytest.fixture(scope="module")
def rough_table():
    return models.render_anisotropic(aniso_spec(0.2, 0.5), *GRIDS, PSI)


def random_pairs(n, seed=0):
    rng = np.random.default_rng(seed)
    s, o = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    return (
        s / np.linalg.norm(s, axis=1, keepdims=True),
        o / np.linalg.norm(o, axis=1, keepdims=True),
    )


def cube(tangent=None):
    sc = T.cube_spacecraft(1.0, subdivisions=1)
    return sc if tangent is None else sc.with_tangent(tangent)


def run(sc, table, s, o, **kw):
    kw.setdefault("dtype", "float64")
    return simulate(Scene(sc, materials={MAT: table}, to_sun=s, to_observer=o, **kw), lazy=False)


def test_equal_roughnesses_reproduce_the_isotropic_cube():
    """An anisotropic table with alpha_x = alpha_y gives the isotropic cube."""
    iso = models.model_material(
        "microfacet", WL, material=MAT, provenance="test", roughness=0.3, **OPT
    )
    iso_table = models.render(iso, *GRIDS)
    # the anisotropic look-up has no normal-incidence blend: compare with the
    # isotropic look-up without it (the paper's)
    iso_table.attrs["normal_incidence"] = "paper"
    an_table = models.render_anisotropic(aniso_spec(0.3, 0.3), *GRIDS, PSI)
    # every psi slice is the isotropic table (the models agree to 1e-12, see
    # tests/brdf/test_anisotropic.py)
    np.testing.assert_allclose(
        an_table.values, np.repeat(iso_table.values[:, :, :, None, :], PSI.size, 3), rtol=1e-12
    )
    s, o = random_pairs(200)
    sc = cube((0.3, 0.9, -0.2))
    for kernel in ("numpy", "fused"):
        want = run(sc, iso_table, s, o, kernel=kernel)
        got = run(sc, an_table, s, o, kernel=kernel)
        # psi weights sum to one: identical slices give the isotropic look-up up to
        # the rounding of a two-term sum, ~1e-15 relative; 1e-12 leaves margin.
        for v in ("signal", "spacecraft_sbrdf", "area"):
            np.testing.assert_allclose(got[v], want[v], rtol=1e-12, atol=1e-15)
    assert np.count_nonzero(want.signal.values) > 100


def test_numpy_and_fused_agree_and_match_the_reference_lookup(rough_table):
    s, o = random_pairs(150, seed=1)
    sc = cube((1.0, 2.0, 3.0))
    a = run(sc, rough_table, s, o, kernel="numpy")
    b = run(sc, rough_table, s, o, kernel="fused")
    np.testing.assert_allclose(b.signal, a.signal, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(b.area, a.area, rtol=1e-12, atol=1e-15)
    # independent path: material.lookup_anisotropic at each facet's angles and psi
    f = sc.facets()
    n, t, area = f.normal.values, f.tangent.values, f.area.values
    ang = geometry.facet_angles(n[None], s[:, None], o[:, None])
    psi = anisotropy.illumination_azimuth(n[None], t[None], s[:, None], o[:, None])
    fr = material.lookup_anisotropic(rough_table, ang.theta_i, ang.delta_theta, ang.phi, psi)
    on = ang.lit & ang.visible
    w = np.where(on, area * (s @ n.T) * (o @ n.T), 0.0)
    want = np.einsum("gf,gfl->gl", w, fr)
    np.testing.assert_allclose(a.signal, want, rtol=1e-12, atol=1e-15)


def test_plan_says_what_runs_and_merges_only_equal_tangents(rough_table):
    s, o = random_pairs(400)  # every term contributes somewhere: none dropped
    sc = T.cube_spacecraft(1.0, subdivisions=2)  # 48 facets, 8 per face
    tang = np.tile([1.0, 0.0, 0.0], (sc.n_facets, 1))
    tang[::2] = [0.0, 1.0, 1.0]  # two tangents per face (on the faces that contain them)
    plan = compile_plan(
        Scene(sc.with_tangent(tang), materials={MAT: rough_table}, to_sun=s, to_observer=o)
    )
    text = str(plan)
    assert "anisotropy" in text and f"{PSI.size} psi nodes" in text
    assert plan.terms.tangent.shape == (plan.terms.size, 3)
    # faces +-x: tangents y+z and (fallback) y; +-y: z and x; +-z: y and x: 12 terms
    assert plan.terms.size == 12
    # an isotropic table of the same scene merges by (normal, material) only
    iso = catalog.load("lambertian-grey-50")
    plan = compile_plan(Scene(sc.with_tangent(tang), materials={MAT: iso}, to_sun=s, to_observer=o))
    assert plan.terms.size == 6 and not plan.anisotropic


def test_tangent_turned_by_180_degrees_changes_nothing(rough_table):
    s, o = random_pairs(100, seed=2)
    d = np.array([0.4, -0.7, 0.2])
    a = run(cube(d), rough_table, s, o)
    b = run(cube(-d), rough_table, s, o)
    # t and -t give psi equal up to rounding (~1e-14 deg): 1e-10 relative
    np.testing.assert_allclose(a.signal, b.signal, rtol=1e-10, atol=1e-15)


def test_rendered_table_energy_and_reciprocity(rough_table):
    # Energy: reflectance <= 1 at every theta_i and psi, and close to the model's own
    # quadrature: the 10-degree grid's interpolation error, measured 0.42% up to 60 deg
    # and 4.9% at 80 deg (an isotropic table of roughness 0.3 on the same grid: 0.85%
    # and 4.4%): tolerances 0.6% and 6%.
    th = np.array([0.0, 20.0, 40.0, 60.0, 80.0])
    rho = energy.hemispherical_reflectance(rough_table, th)
    assert rho.dims == ("theta_i", "psi", "wavelength")
    assert float(rho.max()) <= 1.0
    spec = aniso_spec(0.2, 0.5)
    want = A.directional_hemispherical_reflectance(
        th[:, None], WL, psi=PSI[None, :], **{k: spec[k].values for k in A.PARAMS}
    )
    err = (np.abs(rho.values - want) / want).max(axis=(1, 2))
    assert err[:4].max() < 0.006 and err[4] < 0.06, err
    # Reciprocity through the engine: S(s, o) = S(o, s) (Eq. 3 is symmetric); the
    # table breaks it only through interpolation: within twice the table's error
    # against the model on the same geometries.  Geometries where a contributing facet
    # is lit or seen beyond 70 deg are left out: between the 80 and 90 deg rows linear
    # interpolation of the grazing Fresnel rise is off by up to 10x (isotropic tables
    # alike), which says nothing about psi.
    s, o = random_pairs(400, seed=3)
    sc = cube((0.2, 0.3, 0.9))
    n = sc.facets().normal.values
    ci, cr = s @ n.T, o @ n.T
    on = (ci > 0) & (cr > 0)
    steep = np.all(~on | ((ci > np.cos(np.radians(70))) & (cr > np.cos(np.radians(70)))), axis=1)
    s, o = s[steep], o[steep]
    a = run(sc, rough_table, s, o).signal.values
    b = run(sc, rough_table, o, s).signal.values
    ref = reference_signal(sc, s, o, spec)
    some = ref > 1e-3 * ref.max()
    assert some.sum() > 50
    tab_err = np.abs(a - ref)[some] / ref[some]
    recip = np.abs(a - b)[some] / ref[some]
    assert recip.max() <= 2 * tab_err.max() + 1e-12
    assert np.median(recip) <= 2 * np.median(tab_err) + 1e-12
    # measured: max 0.33, median 0.080 (a 10-degree grid on a lobe of roughness 0.2)
    assert tab_err.max() < 0.4 and np.median(tab_err) < 0.1, (tab_err.max(), np.median(tab_err))


def reference_signal(sc, s, o, spec):
    """sum_j A_j cos_i cos_r f_r with the anisotropic GGX evaluated at the facets."""
    f = sc.facets()
    kw = {k: spec[k].values for k in A.PARAMS}
    out = np.zeros((s.shape[0], spec.sizes["wavelength"]))
    for n, t, area in zip(f.normal.values, f.tangent.values, f.area.values, strict=True):
        ci, cr = s @ n, o @ n
        on = (ci > 0) & (cr > 0)
        if on.any():
            fr = A.brdf(n, s[on], o[on], spec.wavelength.values, tangent=t, **kw)
            out[on] += (area * ci[on] * cr[on])[:, None] * fr
    return out


def plate():
    """A 1 m x 1 m x 1 mm plate (top face +z)."""
    box = trimesh.creation.box(extents=(1.0, 1.0, 0.001))
    return Spacecraft(box, [MAT] * len(box.faces), name="plate")


def test_brushed_plate_glint_follows_the_anisotropic_model():
    """Brushed aluminium: the signal of a plate as its brushing turns, against the model."""
    spec = catalog.load("brushed-aluminium-model").isel(wavelength=[0, 10, 20])
    # Sun at theta_i = 30 deg in the xz-plane; observers on table nodes (specular and
    # off-specular).  Only the top face is lit and visible (+x is lit, -x seen).
    theta_i, obs = 30.0, [(0.0, 0.0), (-9.0, 12.0), (12.0, 6.0)]
    grids = (
        np.array([0.0, 30.0, 60.0, 90.0]),
        np.array([-180.0, -30.0, -9.0, 0.0, 12.0, 30.0, 90.0]),
        np.array([0.0, 6.0, 12.0, 45.0, 90.0]),
    )
    psi = np.arange(0.0, 181.0, 10.0)
    table = models.render_anisotropic(spec, *grids, psi)
    kw = {k: spec[k].values for k in A.PARAMS}
    chi = np.arange(0.0, 361.0, 5.0)  # brushing direction: azimuth about +z [degree]
    for dt, ph in obs:
        n, s, o = geometry.facet_vectors(theta_i, dt, ph)  # facet frame = body frame here
        got = []
        for c in chi:
            t = (np.cos(np.radians(c)), np.sin(np.radians(c)), 0.0)
            got.append(run(plate().with_tangent(t), table, s[None], o[None]).signal.values[0])
        got = np.array(got)
        tc = np.stack([np.cos(np.radians(chi)), np.sin(np.radians(chi)), 0 * chi], -1)
        nb, sb, ob = (np.broadcast_to(v, tc.shape) for v in (n, s, o))
        want = (
            np.cos(np.radians(theta_i))
            * (o @ n)
            * A.brdf(nb, sb, ob, spec.wavelength.values, tangent=tc, **kw)
        )
        # e_f = -x, so psi = 180 - chi (mod 180): chi on a 10-degree multiple is a psi
        # node, where the look-up is the rendered value: 1e-9 relative (the angles are
        # recomputed from vectors, ~1e-13 deg off the nodes, against a lobe of ~3 deg).
        on = np.mod(chi, 10.0) == 0
        np.testing.assert_allclose(got[on], want[on], rtol=1e-9)
        # between nodes the table is linear in psi
        mid = ~on
        lo, hi = np.searchsorted(chi, chi[mid] - 5.0), np.searchsorted(chi, chi[mid] + 5.0)
        np.testing.assert_allclose(got[mid], 0.5 * (want[lo] + want[hi]), rtol=1e-9)
        # off the specular direction the glint follows the brushing strongly; at the
        # specular direction h = N and D(N) = 1 / (pi alpha_x alpha_y) does not depend
        # on it (only the masking does, by a few per cent)
        ratio = want[on].max(axis=0) / want[on].min(axis=0)
        assert np.all(ratio > 3.0) if (dt, ph) != (0.0, 0.0) else np.all(ratio < 1.1), ratio
        # symmetric under chi -> chi + 180 (t ~ -t), and under the mirror chi -> -chi at phi = 0
        np.testing.assert_allclose(got[chi < 180], got[(chi >= 180) & (chi < 360)], rtol=1e-9)
        if ph == 0.0:
            np.testing.assert_allclose(got, got[::-1], rtol=1e-9)


def test_mixed_isotropic_and_anisotropic_materials(rough_table):
    box = trimesh.creation.box()
    labels = ["brushed"] * 6 + [MAT] * 6
    sc = Spacecraft(box, labels, tangent=(0.0, 1.0, 1.0))
    iso = material.lambertian(0.5, WL, material=MAT)
    brushed = rough_table.copy()
    brushed.attrs["material"] = "brushed"
    s, o = random_pairs(120, seed=5)
    mats = {"brushed": brushed, MAT: iso}
    out = {}
    for kernel in ("numpy", "fused"):
        out[kernel] = simulate(
            Scene(
                sc,
                materials=mats,
                to_sun=s,
                to_observer=o,
                kernel=kernel,
                dtype="float64",
                outputs=("signal", "area", "per_material"),
            ),
            lazy=False,
        )
    a, b = out["numpy"], out["fused"]
    np.testing.assert_allclose(b.signal, a.signal, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(b.signal_material, a.signal_material, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(a.signal_material.sum("material"), a.signal, rtol=1e-12, atol=1e-15)
    # the isotropic part is what it is alone
    alone = simulate(
        Scene(
            Spacecraft(box, labels),
            materials={"brushed": material.lambertian(0.5, WL, material="brushed"), MAT: iso},
            to_sun=s,
            to_observer=o,
            dtype="float64",
            outputs=("signal", "per_material"),
        ),
        lazy=False,
    )
    np.testing.assert_allclose(
        a.signal_material.sel(material=MAT),
        alone.signal_material.sel(material=MAT),
        rtol=1e-12,
        atol=1e-15,
    )


def test_analytic_evaluation_uses_the_tangents():
    spec = aniso_spec(0.1, 0.4)
    s, o = random_pairs(60, seed=6)
    sc = cube((0.5, 0.1, 0.8))
    table = models.render_anisotropic(spec, *GRIDS, PSI)
    got = simulate(
        Scene(
            sc,
            materials={MAT: table},
            models={MAT: spec},
            to_sun=s,
            to_observer=o,
            evaluation="analytic",
            dtype="float64",
        ),
        lazy=False,
    )
    # the same sum in a different order: 1e-12
    np.testing.assert_allclose(got.signal, reference_signal(sc, s, o, spec), rtol=1e-12, atol=1e-15)


def test_pack_rejects_a_table_without_its_psi_axis():
    g = np.array([0.0, 90.0])
    with pytest.raises(ValueError, match="expected"):
        AK.pack_anisotropic(np.ones((2, 2, 2, 1)), g, g - 90, g, np.array([0.0, 90.0]))


def test_band_pre_integration_is_exact_for_anisotropic_tables(rough_table):
    # The facet sum is linear in f_r, psi weights included: pre-integrating the psi
    # slices over the bands equals integrating the spectral signal (rounding only).
    wide = models.render_anisotropic(
        models.model_material(
            "anisotropic_microfacet",
            np.arange(400.0, 1001.0, 50.0),
            material=MAT,
            provenance="test",
            alpha_x=0.2,
            alpha_y=0.5,
            n=1.3,
            k=7.0,
            rho_d=0.01,
        ),
        *GRIDS,
        PSI,
    )
    s, o = random_pairs(60, seed=8)
    sc = cube((1.0, 2.0, 3.0))
    kw = dict(bands=("V", "R", "I"), outputs=("band_signal",))
    for kernel in ("numpy", "fused"):
        pre = run(sc, wide, s, o, kernel=kernel, **kw)
        spectral = run(sc, wide, s, o, kernel=kernel, band_integration="spectral", **kw)
        assert "pre-integrated" in pre.attrs["plan"]
        np.testing.assert_allclose(pre.band_signal, spectral.band_signal, rtol=1e-12, atol=1e-15)


_vec = st.tuples(*[st.floats(-1, 1, allow_nan=False)] * 3).filter(lambda v: np.linalg.norm(v) > 0.1)


@settings(max_examples=examples(40), deadline=None)
@given(
    s=st.lists(_vec, min_size=1, max_size=6),
    o=st.lists(_vec, min_size=1, max_size=6),
    t=_vec,
    method=st.sampled_from(["nearest", "linear", "cubic"]),
    dtype=st.sampled_from([np.float64, np.float32]),
    closed=st.booleans(),
)
def test_compiled_kernel_matches_the_numpy_reference(rough_table, s, o, t, method, dtype, closed):
    k = min(len(s), len(o))
    z = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])  # normal incidence on two faces
    s = np.vstack([np.array(s[:k]), z, z[:1]])
    o = np.vstack([np.array(o[:k]), z[:1], [[0.3, 0.0, 1.0]], [[0.0, 0.6, 0.8]]])
    s /= np.linalg.norm(s, axis=1, keepdims=True)
    o /= np.linalg.norm(o, axis=1, keepdims=True)
    table = rough_table if closed else rough_table.isel(psi=slice(0, -1))
    sc = cube(np.array(t))
    f = sc.facets()
    values = np.asarray(table.values)
    packed = AK.pack_anisotropic(
        values, *(table[d].values for d in ("theta_i", "delta_theta", "phi", "psi")), dtype=dtype
    )
    frac = np.random.default_rng(0).uniform(0.2, 1.0, (s.shape[0], f.sizes["facet"]))
    args = (s, o, f.normal.values, f.tangent.values, f.area.values, packed, method, frac)
    ref = AK.anisotropic_sums(*args, kernel="numpy")
    got = AK.anisotropic_sums(*args, kernel="fused")
    # float64: the same arithmetic in another order; float32 tables accumulate in float32
    rtol = 1e-11 if dtype == np.float64 else 2e-5
    scale = max(float(np.abs(ref.signal).max()), 1e-300)
    np.testing.assert_allclose(got.signal, ref.signal, rtol=rtol, atol=rtol * scale)
    np.testing.assert_allclose(got.paper, ref.paper, rtol=rtol, atol=rtol * scale)
    np.testing.assert_allclose(got.area, ref.area, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(got.lit_visible_area, ref.lit_visible_area, rtol=1e-12, atol=1e-15)
    assert got.signal.dtype == dtype
