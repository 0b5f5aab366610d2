"""A geostationary communications satellite-like body: a box bus and two sun-tracking wings.

The classic three-axis-stabilised GEO bus (Wertz & Larson, *Space Mission Analysis and
Design*, 3rd ed., §11.5; Gilmore, *Spacecraft Thermal Control Handbook*, 2nd ed., ch. 2):
the Earth deck faces nadir, the north and south panels carry the optical solar reflector
(OSR) radiators (they see the Sun least), every other face is wrapped in gold-coloured
Kapton multi-layer insulation, and two solar-array wings extend north and south, each
turning about the north-south axis to face the Sun once per day.

Body frame: ``+z`` to nadir (the Earth deck), ``+y`` to the north (the orbit normal, the
arrays' axis), ``+x`` along the velocity (east); with the nadir attitude law
(:class:`sbrdf_xr.observing.attitude.Nadir`, ``nadir_axis="+z"``, ``velocity_axis="+x"``)
it flies as a GEO comsat does.  Dimensions are typical, chosen here and stated: a
2.4 m (x) x 2.0 m (y) x 2.2 m (z) bus; each wing a flat 2.2 m x 10 m plate of cells
(22 m2) from 1.0 m to 11.0 m off the bus's north or south face (its yoke), in the plane
``x = 0`` at rest (cells facing ``+x``), hinged about ``y``.  Antennas and thrusters are
not modelled.

Materials (:data:`GEO_COMSAT_MATERIALS`): ``kapton-mli`` (bus: east, west, Earth and
anti-Earth faces), ``osr`` (north and south faces), ``gaas-cell`` (array fronts); the
arrays are one-sided (their backs face away from the Sun while they track it).
:func:`sbrdf_xr.engine.builtin.geo_comsat_materials` gives them as the optical-constant
materials of :mod:`sbrdf_xr.materials.optical`.

Examples
--------
>>> sc = geo_comsat()
>>> sc.materials
['gaas-cell', 'kapton-mli', 'osr']
>>> f = sc.facets()
>>> round(float(f.area[f.material == "gaas-cell"].sum()), 6)
44.0
>>> [p.name for p in sc.moving_parts]
['north-array', 'south-array']
"""

from __future__ import annotations

import numpy as np
import trimesh

from .parts import Part, SunTracking
from .spacecraft import Spacecraft

__all__ = ["GEO_COMSAT_MATERIALS", "geo_comsat"]

#: Material names: (bus MLI, radiators, array cells).
GEO_COMSAT_MATERIALS = ("kapton-mli", "osr", "gaas-cell")

_BUS = (2.4, 2.0, 2.2)  # [m] x, y, z
_WING = (2.2, 10.0)  # [m] width (z), span (y)
_YOKE = 1.0  # [m] from the bus face to the wing's root


def _box(size: tuple[float, float, float]) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Vertices, outward-wound faces and the material of each face of a centred box."""
    h = np.asarray(size) / 2.0
    v = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * h
    quads = {  # outward normal -> corners, counter-clockwise seen from outside
        "+x": [4, 6, 7, 5],
        "-x": [0, 1, 3, 2],
        "+y": [2, 3, 7, 6],
        "-y": [0, 4, 5, 1],
        "+z": [1, 5, 7, 3],
        "-z": [0, 2, 6, 4],
    }
    mli, osr, _ = GEO_COMSAT_MATERIALS
    faces, mats = [], []
    for side, (a, b, c, d) in quads.items():
        faces += [[a, b, c], [a, c, d]]
        mats += [osr if side[1] == "y" else mli] * 2
    return v, np.array(faces), mats


def geo_comsat(*, name: str = "geo-comsat") -> Spacecraft:
    """The GEO communications satellite-like body of the module docstring.

    Parameters
    ----------
    name : str
        The spacecraft's name.

    Returns
    -------
    Spacecraft
        The bus and the parts ``north-array`` and ``south-array`` (sun-tracking about
        ``y``).

    Examples
    --------
    >>> sc = geo_comsat()
    >>> sc.n_facets, sc.parts[0].axis.tolist()
    (16, [0.0, 1.0, 0.0])
    """
    v, faces, mats = _box(_BUS)
    w, span = _WING
    y0 = _BUS[1] / 2 + _YOKE
    cells = GEO_COMSAT_MATERIALS[2]
    parts = []
    for sign, label in ((1.0, "north"), (-1.0, "south")):
        base = len(v)
        ys = sorted((sign * y0, sign * (y0 + span)))
        wing = np.array([[0.0, ys[0], -w / 2], [0.0, ys[1], -w / 2], [0.0, ys[1], w / 2]])
        wing = np.vstack([wing, [0.0, ys[0], w / 2]])
        v = np.vstack([v, wing])
        # wound to face +x: (y, z) counter-clockwise seen from +x
        faces = np.vstack([faces, [[base, base + 1, base + 2], [base, base + 2, base + 3]]])
        mats += [cells, cells]
        parts.append(
            Part(
                f"{label}-array",
                [len(mats) - 2, len(mats) - 1],
                axis=(0.0, 1.0, 0.0),
                point=(0.0, sign * (y0 + span / 2), 0.0),
                law=SunTracking(),
            )
        )
    mesh = trimesh.Trimesh(v, faces, process=False)
    mli, osr, _ = GEO_COMSAT_MATERIALS
    return Spacecraft(
        mesh,
        mats,
        name=name,
        parts=parts,
        colors={mli: (212, 160, 40), osr: (200, 205, 215), cells: (30, 40, 140)},
    )
