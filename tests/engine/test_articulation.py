"""Articulated parts: a bus plus a sun-tracking plate against closed forms and rigid poses."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from sbrdf_xr import Scene, simulate
from sbrdf_xr.body.parts import AngleSeries, Fixed, Part, SunTracking, tracking_angle
from sbrdf_xr.body.spacecraft import Spacecraft
from sbrdf_xr.errors import MeshError, SceneError, ValidationError
from sbrdf_xr.materials.schema import lambertian
from sbrdf_xr.testing import box_with_plate_spacecraft

WL = [500.0, 700.0]
ALBEDO = {"bus": 0.5, "cell": 0.3, "backsheet": 0.7}
MATS = {m: lambertian(a, WL, material=m) for m, a in ALBEDO.items()}
BOX_NORMALS = np.vstack([np.eye(3), -np.eye(3)])
# float64 rounding of a few dot products, one rotation and a constant-table look-up per
# term: the closed forms are met to a few ulp of the ~1 m2 sr-1 signal
TOL = 1e-12


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def random_pairs(n, seed):
    rng = np.random.default_rng(seed)
    return unit(rng.normal(size=(n, 3))), unit(rng.normal(size=(n, 3)))


def bus_plus_tracking_plate(s, o):
    """Independent closed form: the unit cube's six faces plus a 1 m2 two-sided plate
    hinged about x, whose normal is the Sun's direction projected on the yz plane."""
    bus = (np.clip(s @ BOX_NORMALS.T, 0, None) * np.clip(o @ BOX_NORMALS.T, 0, None)).sum(1)
    n = unit(np.column_stack([np.zeros(len(s)), s[:, 1], s[:, 2]]))
    ci, cr = (s * n).sum(1), (o * n).sum(1)
    plate = np.where(
        (ci > 0) & (cr > 0),
        ci * cr * ALBEDO["cell"],
        np.where((ci < 0) & (cr < 0), ci * cr * ALBEDO["backsheet"], 0.0),
    )
    return (bus * ALBEDO["bus"] + plate) / np.pi


@pytest.mark.parametrize("merge", [None, False])
def test_bus_plus_sun_tracking_plate_meets_the_closed_form(merge):
    s, o = random_pairs(300, 0)
    cube = simulate(
        Scene(box_with_plate_spacecraft(parts=True), MATS, to_sun=s, to_observer=o, merge=merge)
    )
    np.testing.assert_allclose(
        cube.signal.values[:, 0], bus_plus_tracking_plate(s, o), rtol=0, atol=TOL
    )


def test_a_grid_sweep_turns_the_plate_per_geometry():
    from sbrdf_xr import geometry

    scene = Scene(
        box_with_plate_spacecraft(parts=True),
        MATS,
        attitudes=geometry.uniform_attitudes(20, seed=2),
        phase_angles=[15.0, 80.0, 140.0],
        chunk=7,
    )
    cube = simulate(scene, lazy=False)
    s = cube.to_sun.values.reshape(-1, 3)
    o = cube.to_observer.values.reshape(-1, 3)
    np.testing.assert_allclose(
        cube.signal.values[..., 0].reshape(-1), bus_plus_tracking_plate(s, o), rtol=0, atol=TOL
    )
    # the cube says where the plate turned: the angle that faces it to the Sun
    theta = np.degrees(tracking_angle([1.0, 0, 0], [0, 0, 1.0], s)).reshape(20, 3)
    np.testing.assert_allclose(cube.part_angle.sel(part="array").values, theta, atol=1e-9)
    assert cube.part_angle.attrs["units"] == "degree"


def rigid_pose(angle):
    """The same body with the plate turned by ``angle`` [radian] and frozen (no parts)."""
    body = box_with_plate_spacecraft()
    v = np.array(body.mesh.vertices)
    c, sn = np.cos(angle), np.sin(angle)
    R = np.array([[1, 0, 0], [0, c, -sn], [0, sn, c]])
    p = np.array([0, 0, 1.5])
    v[8:] = p + (v[8:] - p) @ R.T
    mesh = trimesh.Trimesh(v, body.mesh.faces, process=False)
    return Spacecraft(mesh, body.facet_material, back_material=[""] * 12 + ["backsheet"] * 2)


@pytest.mark.parametrize("method", ["exact", "sampled"])
def test_shadowing_between_parts_equals_the_rigid_pose(method):
    s, o = random_pairs(12, 4)
    s[:4] = unit([[0.3, 0.0, 1.0], [0.2, 0.4, 1.0], [0.0, 0.1, -1.0], [0.5, -0.2, -1.0]])
    o[:4] = unit([[0.1, 0.2, 1.0], [0.0, 0.0, 1.0], [0.3, 0.0, -1.0], [0.0, 0.1, -1.0]])
    opts = {"effects": ("sunlight", "shadowing"), "shadow_method": method, "shadow_density": 6}
    art = simulate(
        Scene(box_with_plate_spacecraft(parts=True), MATS, to_sun=s, to_observer=o, **opts)
    )
    angles = tracking_angle([1.0, 0, 0], [0, 0, 1.0], s)
    for g in range(len(s)):
        one = Scene(
            rigid_pose(angles[g]), MATS, to_sun=s[g : g + 1], to_observer=o[g : g + 1], **opts
        )
        ref = simulate(one).signal.values[0, 0]
        # the same polygons (exact) or the same rays on the same posed mesh (sampled)
        assert art.signal.values[g, 0] == pytest.approx(ref, abs=TOL), g


def test_the_plate_shades_the_bus_top_by_its_closed_form():
    """Sun at tan(alpha) = 0.3 from +z in the xz plane: the tracking angle is 0, the plate
    lies flat 1 m above the top and leaves 0.3 of it lit."""
    s = o = unit([[0.3, 0.0, 1.0]])
    cube = simulate(
        Scene(
            box_with_plate_spacecraft(parts=True),
            MATS,
            to_sun=s,
            to_observer=o,
            effects=("shadowing",),
        )
    )
    ci = float(s[0, 2])
    sx = float(s[0, 0])
    expected = (0.3 * ci * ci + sx * sx) * ALBEDO["bus"] / np.pi + ci * ci * ALBEDO["cell"] / np.pi
    assert cube.signal.values[0, 0] == pytest.approx(expected, abs=TOL)


def test_limits_and_angle_series():
    s, o = random_pairs(40, 9)
    lim = SunTracking(limits=(-20.0, 30.0))
    body = box_with_plate_spacecraft(parts=True, law=lim)
    theta = tracking_angle([1.0, 0, 0], [0, 0, 1.0], s)
    assert np.all(
        np.degrees(tracking_angle([1.0, 0, 0], [0, 0, 1.0], s, np.radians((-20, 30)))) <= 30 + 1e-9
    )
    series = box_with_plate_spacecraft(
        parts=True, law=AngleSeries(np.degrees(np.clip(theta, -1, 1)))
    )
    clipped = box_with_plate_spacecraft(
        parts=True, law=SunTracking(limits=(-np.degrees(1), np.degrees(1)))
    )
    a = simulate(Scene(series, MATS, to_sun=s, to_observer=o)).signal.values
    b = simulate(Scene(clipped, MATS, to_sun=s, to_observer=o)).signal.values
    np.testing.assert_allclose(a, b, rtol=0, atol=TOL)
    assert simulate(Scene(body, MATS, to_sun=s, to_observer=o)).signal.shape == (40, 2)
    fixed = simulate(
        Scene(box_with_plate_spacecraft(parts=True, law=Fixed()), MATS, to_sun=s, to_observer=o)
    ).signal.values
    rigid = simulate(
        Scene(box_with_plate_spacecraft(), MATS, to_sun=s, to_observer=o)
    ).signal.values
    np.testing.assert_allclose(fixed, rigid, rtol=0, atol=TOL)


def test_bad_parts_are_named_errors():
    box = trimesh.creation.box()
    with pytest.raises(ValidationError, match=r"hinge axis .* zero length"):
        Part("a", [0], axis=[0, 0, 0])
    with pytest.raises(ValidationError, match="names no facets"):
        Part("a", [])
    with pytest.raises(ValidationError, match="exclude every angle"):
        SunTracking(limits=(30.0, -30.0))
    with pytest.raises(MeshError, match="belong to part 'a' already"):
        Spacecraft(box, ["p"] * 12, parts=[Part("a", [0, 1]), Part("b", [1, 2])])
    with pytest.raises(MeshError, match="do not exist"):
        Spacecraft(box, ["p"] * 12, parts=[Part("a", [11, 12])])
    with pytest.raises(ValidationError, match="series has 2 angles"):
        s, o = random_pairs(3, 1)
        body = box_with_plate_spacecraft(parts=True, law=AngleSeries([0.0, 1.0]))
        simulate(Scene(body, MATS, to_sun=s, to_observer=o))


def test_a_scene_file_describes_backs_and_parts(tmp_path):
    from sbrdf_xr.engine import load_scene
    from sbrdf_xr.materials.files import to_netcdf

    for m, table in MATS.items():
        to_netcdf(table, tmp_path / f"{m}.nc")
    body = box_with_plate_spacecraft()
    mesh = body.mesh.copy()
    mesh.visual.face_colors = [[200, 200, 200, 255]] * 12 + [[0, 0, 255, 255]] * 2
    mesh.export(tmp_path / "body.ply")
    (tmp_path / "scene.toml").write_text(
        """
name = "bus-and-array"
[materials]
bus = "bus.nc"
cell = "cell.nc"
backsheet = "backsheet.nc"
[spacecraft]
path = "body.ply"
material_map = {"#c8c8c8" = "bus", "#0000ff" = "cell"}
back_material = {cell = "backsheet"}
[[spacecraft.parts]]
name = "array"
materials = ["cell"]
axis = [1, 0, 0]
point = [0, 0, 1.5]
law = "sun-tracking"
[geometry]
to_sun = [[0, 0.6, 0.8], [0.6, 0, -0.8]]
to_observer = [[0, 0.8, 0.6], [0.0, 0.6, -0.8]]
"""
    )
    scene = load_scene(tmp_path / "scene.toml")
    assert "array (2 facets): sun-tracking" in dict(scene.plan().steps)["parts"]
    s, o = np.asarray(scene.to_sun), np.asarray(scene.to_observer)
    np.testing.assert_allclose(
        simulate(scene).signal.values[:, 0], bus_plus_tracking_plate(s, o), rtol=0, atol=TOL
    )
    bad = (tmp_path / "scene.toml").read_text().replace('law = "sun-tracking"', 'law = "spin"')
    (tmp_path / "bad.toml").write_text(bad)
    with pytest.raises(SceneError, match="law 'spin'; allowed: fixed, series, sun-tracking"):
        load_scene(tmp_path / "bad.toml")


def test_other_sources_see_the_plate_where_the_sun_turned_it():
    """Earthshine: the plate tracks the Sun, the Earth lights it; the signal is the closed
    form with the Earth in the Sun's place and the plate still facing the Sun, times the
    constant irradiance ratio."""
    s, o = random_pairs(60, 5)
    e, _ = random_pairs(60, 6)
    scene = Scene(
        box_with_plate_spacecraft(parts=True),
        MATS,
        to_sun=s,
        to_observer=o,
        to_earth=e,
        effects=("sunlight", "earthshine"),
        earth_model="point",  # the closed form is that of a distant Earth
    )
    plan = scene.plan()
    cube = simulate(plan)
    bus = (np.clip(e @ BOX_NORMALS.T, 0, None) * np.clip(o @ BOX_NORMALS.T, 0, None)).sum(1)
    n = unit(np.column_stack([np.zeros(len(s)), s[:, 1], s[:, 2]]))
    ci, cr = (e * n).sum(1), (o * n).sum(1)
    plate = np.where(
        (ci > 0) & (cr > 0),
        ci * cr * ALBEDO["cell"],
        np.where((ci < 0) & (cr < 0), ci * cr * ALBEDO["backsheet"], 0.0),
    )
    ratio = plan.effect_params["earthshine"]["ratio"]
    expected = ratio * (bus * ALBEDO["bus"] + plate) / np.pi
    np.testing.assert_allclose(
        cube.signal_earthshine.values[:, 0], expected, rtol=0, atol=TOL * ratio
    )
