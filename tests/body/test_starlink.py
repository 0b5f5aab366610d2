"""The built-in Starlink v1.5-class body against its published description and closed forms."""

from __future__ import annotations

import numpy as np
import pytest

from sbrdf_xr import Scene, simulate
from sbrdf_xr.body.starlink import STARLINK_AREAS, starlink_v15
from sbrdf_xr.engine.builtin import STARLINK_STAND_INS, starlink_materials
from sbrdf_xr.errors import ValidationError
from sbrdf_xr.materials.schema import lambertian

# a few float64 dot products and one rotation per geometry on a ~1 m2 sr-1 signal
TOL = 1e-12


def unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def test_the_published_surfaces():
    sc = starlink_v15()
    f = sc.facets()
    front = ~f.back.values
    chassis = front & (f.material.values == "starlink-chassis")
    array = front & (f.material.values == "starlink-solar-array")
    assert float(f.area[chassis].sum()) == pytest.approx(STARLINK_AREAS["chassis"], rel=1e-12)
    assert float(f.area[array].sum()) == pytest.approx(STARLINK_AREAS["solar-array"], rel=1e-12)
    np.testing.assert_allclose(f.normal.values[chassis], [[0, 0, -1]] * 2, atol=1e-15)
    np.testing.assert_allclose(f.normal.values[array], [[0, 1, 0]] * 2, atol=1e-15)
    part = sc.moving_parts[0]
    assert part.axis.tolist() == [0.0, 0.0, 1.0]  # the chassis normal: zenith-nadir


def test_signal_meets_the_two_surface_closed_form():
    """Chassis 3.64 m2 facing -z; array 22.68 m2 facing the Sun's direction projected on
    the chassis plane (cells in front, the backsheet behind); Lambertian stand-ins."""
    rng = np.random.default_rng(8)
    s, o = unit(rng.normal(size=(300, 3))), unit(rng.normal(size=(300, 3)))
    cube = simulate(Scene(starlink_v15(), starlink_materials(), to_sun=s, to_observer=o))
    a = STARLINK_STAND_INS
    chassis = np.where((s[:, 2] < 0) & (o[:, 2] < 0), s[:, 2] * o[:, 2], 0.0) * 3.64
    n = unit(np.column_stack([s[:, 0], s[:, 1], np.zeros(len(s))]))
    ci, cr = (s * n).sum(1), (o * n).sum(1)
    front = np.where((ci > 0) & (cr > 0), ci * cr, 0.0) * a["starlink-solar-array"]
    back = np.where((ci < 0) & (cr < 0), ci * cr, 0.0) * a["starlink-array-back"]
    expected = (chassis * a["starlink-chassis"] + 22.68 * (front + back)) / np.pi
    np.testing.assert_allclose(cube.signal.values[:, 0], expected, rtol=0, atol=TOL)


def test_a_user_table_replaces_a_stand_in():
    wl = [400.0, 550.0, 700.0, 900.0]
    cells = lambertian(0.02, wl, material="starlink-solar-array")
    mats = starlink_materials({"starlink-solar-array": cells})
    assert mats["starlink-solar-array"] is cells
    assert "STAND-IN" in mats["starlink-chassis"].attrs["provenance"]
    with pytest.raises(ValidationError, match="not a material of the Starlink"):
        starlink_materials({"solar-array": cells})


def test_nadir_law_points_the_chassis_to_nadir():
    from scipy.spatial.transform import Rotation

    from sbrdf_xr.observing import Context
    from sbrdf_xr.observing.attitude import Nadir

    r = np.array([[7000.0, 1000.0, -300.0]])
    ctx = Context(position=r, velocity=np.array([[0.0, 7.5, 1.0]]))
    q = Nadir(nadir_axis="-z", velocity_axis="+x").quaternions([0.0], ctx)
    chassis_normal = Rotation.from_quat(q).apply([0.0, 0.0, -1.0])
    np.testing.assert_allclose(chassis_normal[0], -r[0] / np.linalg.norm(r), atol=1e-12)
