"""Open surfaces and two-sided facets: the sides, their shadows and their closed forms."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from sbrdf_xr import Scene, simulate
from sbrdf_xr.body.sides import closed_facets
from sbrdf_xr.body.spacecraft import Spacecraft, load_spacecraft
from sbrdf_xr.body.visibility import lit_visible_fraction
from sbrdf_xr.errors import HiddenSideWarning, ValidationError
from sbrdf_xr.materials.schema import lambertian
from sbrdf_xr.testing import box_with_plate_spacecraft, plate_spacecraft

WL = [500.0, 700.0]
ALBEDO = {"cell": 0.3, "backsheet": 0.7, "bus": 0.5}
MATS = {m: lambertian(a, WL, material=m) for m, a in ALBEDO.items()}
# float64 rounding of a few dot products and one table look-up of a constant table:
# the closed form is met to a few ulp of 1 m2 sr-1
TOL = 1e-12


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


directions = st.tuples(*[st.floats(-1, 1) for _ in range(3)]).filter(
    lambda v: np.linalg.norm(v) > 1e-3
)


def plate_closed_form(s, o, area=2.0):
    """A cos(theta_i) cos(theta_r) f_r of a two-sided plate facing +z: the front where the
    Sun and the observer are above it, the back where both are below, else nothing."""
    ci, cr = s[:, 2], o[:, 2]
    front = (ci > 0) & (cr > 0)
    back = (ci < 0) & (cr < 0)
    f = np.where(front, ALBEDO["cell"], np.where(back, ALBEDO["backsheet"], 0.0)) / np.pi
    return area * np.abs(ci * cr) * f * (front | back)


@pytest.mark.filterwarnings("error::RuntimeWarning")
@pytest.mark.parametrize("effects", [("sunlight",), ("sunlight", "shadowing")])
@pytest.mark.parametrize("method", ["exact", "sampled"])
def test_flat_plate_meets_its_closed_form_front_and_back(effects, method):
    rng = np.random.default_rng(3)
    s, o = unit(rng.normal(size=(400, 3))), unit(rng.normal(size=(400, 3)))
    scene = Scene(
        plate_spacecraft(), MATS, to_sun=s, to_observer=o, effects=effects, shadow_method=method
    )
    cube = simulate(scene)
    expected = plate_closed_form(s, o)
    assert np.count_nonzero(expected) > 100  # both sides seen many times
    np.testing.assert_allclose(cube.signal.values[:, 0], expected, rtol=0, atol=TOL)


@settings(max_examples=60, deadline=None)
@given(s=directions, o=directions)
def test_flat_plate_closed_form_at_any_geometry(s, o):
    s, o = unit([s]), unit([o])
    scene = Scene(plate_spacecraft(), MATS, to_sun=s, to_observer=o, effects=("shadowing",))
    np.testing.assert_allclose(
        simulate(scene).signal.values[:, 0], plate_closed_form(s, o), rtol=0, atol=TOL
    )


def test_one_sided_plate_has_no_back():
    plate = plate_spacecraft(back=None)
    assert plate.n_sides == 2 and plate.sides.mesh is plate.mesh
    s = o = np.array([[0.0, 0.0, -1.0]])
    cube = simulate(Scene(plate, MATS, to_sun=s, to_observer=o))
    assert float(cube.signal.values[0, 0]) == 0.0


def test_a_plate_loads_from_a_sheet_without_repair():
    mesh = trimesh.Trimesh(
        [[0, 0, 0], [1, 0, 0], [1, 2, 0], [0, 2, 0]], [[0, 1, 2], [0, 2, 3]], process=False
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sc = load_spacecraft(mesh, material="cell", back_material={"cell": "backsheet"})
    assert sc.n_sides == 4 and sc.materials == ["backsheet", "cell"]
    with pytest.raises(ValidationError, match=r"front materials.*on no facet"):
        load_spacecraft(mesh, material="cell", back_material={"paint": "backsheet"})


def test_backs_on_a_closed_surface_warn_and_are_dropped():
    box = trimesh.creation.box()
    with pytest.warns(HiddenSideWarning, match=r"12 facets with a back material.*closed"):
        sc = Spacecraft(box, ["bus"] * 12, back_material="backsheet")
    assert sc.n_sides == 12 and sc.materials == ["bus"]
    mixed = box_with_plate_spacecraft()  # backs on the open plate only: no warning
    assert closed_facets(mixed.mesh).tolist() == [True] * 12 + [False] * 2


@pytest.mark.parametrize("tan", [0.0, 0.3, 0.75])
def test_mixed_body_shadows_both_ways(tan):
    """The plate 1 m above the cube's top: with the Sun at tan(alpha) = ``tan`` from +z,
    the plate leaves a fraction ``tan`` of the top lit; from -z the cube leaves a
    fraction ``tan`` of the plate's back lit (the shadow moves by tan per metre)."""
    body = box_with_plate_spacecraft()
    f = body.facets()
    top = np.flatnonzero((f.normal[:, 2] > 0.5) & (f.centroid[:, 2] < 1.0))
    back = np.flatnonzero(f.back.values)
    area = f.area.values
    down = unit([tan, 0.0, 1.0])
    up = unit([tan, 0.0, -1.0])
    for d, faces in ((down, top), (up, back)):
        for method, tol in (("exact", 1e-12), ("sampled", 0.03)):
            frac = lit_visible_fraction(body, d, d, method=method, density=24)
            lit = float(frac[faces] @ area[faces] / area[faces].sum())
            assert lit == pytest.approx(tan, abs=tol), (method, d)
