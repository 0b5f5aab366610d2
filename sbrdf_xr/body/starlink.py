"""A Starlink v1.5-class spacecraft: a nadir chassis and a sun-tracking solar array.

Built from the published description of the two primary surfaces (Fankhauser, Askari &
Tyson 2023, "Satellite Optical Brightness", arXiv:2305.11123, and their data file
``starlink_surface_descriptions.txt``, MIT licence): the chassis underside, 3.64 m2, whose
normal points to geodetic nadir, ``N = (0, 0, -1)`` in their satellite-centred frame
(``z`` to geodetic zenith); and the solar array, 22.68 m2, perpendicular to the chassis
and turned towards the Sun, ``N = (0, 1, 0)`` with ``y`` perpendicular to ``z`` towards
the Sun.  So the array turns about the zenith axis ``z`` to bring its normal closest to
the Sun (:class:`~sbrdf_xr.body.parts.SunTracking`), which leaves it facing the Sun's
direction projected on the chassis plane, as in their model.

The body frame is theirs: ``+z`` to zenith, the chassis facing ``-z``; with the nadir
attitude law (:class:`sbrdf_xr.observing.attitude.Nadir` with ``nadir_axis="-z"``) the
chassis faces geodetic nadir.  Dimensions the description does not give are chosen here
and stated: the chassis is a flat one-sided 2.8 m x 1.3 m plate at ``z = 0`` (3.64 m2);
the array a flat two-sided 8.1 m x 2.8 m plate (22.68 m2) in the plane ``y = 0`` at rest,
spanning ``z`` from 0.2 m to 3.0 m above the chassis, hinged about ``z`` through its
centre (so it never cuts the chassis).  Only the two surfaces of the description are
modelled.

Materials: ``starlink-chassis`` (chassis underside), ``starlink-solar-array`` (the cells,
front of the array) and ``starlink-array-back`` (the back of the array, not in the
description: give it a table, or ``back=False`` for a one-sided array).  Fill them with
tables (the laboratory scans of the same data set), e.g.
``Scene(starlink_v15(), materials={...})``;
:func:`sbrdf_xr.engine.builtin.starlink_materials` gives labelled Lambertian stand-ins
for the ones not given.

Examples
--------
>>> sc = starlink_v15()
>>> sc.n_facets, sc.materials
(4, ['starlink-array-back', 'starlink-chassis', 'starlink-solar-array'])
>>> f = sc.facets()
>>> round(float(f.area[f.material == "starlink-chassis"].sum()), 6)
3.64
>>> round(float(f.area[f.material == "starlink-solar-array"].sum()), 6)
22.68
>>> p = sc.moving_parts[0]
>>> p.name, p.axis.tolist(), p.normal.tolist()
('solar-array', [0.0, 0.0, 1.0], [0.0, 1.0, 0.0])
"""

from __future__ import annotations

import numpy as np
import trimesh

from .parts import Part, SunTracking
from .spacecraft import Spacecraft

__all__ = ["STARLINK_AREAS", "STARLINK_MATERIALS", "starlink_v15"]

#: Material names of the Starlink v1.5-class body: (chassis, array front, array back).
STARLINK_MATERIALS = ("starlink-chassis", "starlink-solar-array", "starlink-array-back")

#: Published areas of the two surfaces [m2] (starlink_surface_descriptions.txt).
STARLINK_AREAS = {"chassis": 3.64, "solar-array": 22.68}

_CHASSIS = (2.8, 1.3)  # [m], 3.64 m2
_ARRAY = (8.1, 2.8)  # [m], 22.68 m2
_ARRAY_Z = (0.2, 3.0)  # [m] above the chassis


def starlink_v15(
    *, back: bool = True, limits: tuple[float, float] | None = None, name: str = "starlink-v1.5"
) -> Spacecraft:
    """The Starlink v1.5-class spacecraft of the module docstring.

    Parameters
    ----------
    back : bool
        Give the array a back (material ``starlink-array-back``); False: one-sided.
    limits : (float, float), optional
        Limits of the array's tracking angle [degree] (default: none).
    name : str
        The spacecraft's name.

    Returns
    -------
    Spacecraft
        A chassis (the bus) and the part ``solar-array``.

    Examples
    --------
    >>> starlink_v15(back=False).n_sides
    4
    """
    cx, cy = (c / 2 for c in _CHASSIS)
    ax = _ARRAY[0] / 2
    z0, z1 = _ARRAY_Z
    vertices = np.array(
        [
            [-cx, -cy, 0.0],
            [cx, -cy, 0.0],
            [cx, cy, 0.0],
            [-cx, cy, 0.0],  # chassis, wound to face -z
            [-ax, 0.0, z0],
            [ax, 0.0, z0],
            [ax, 0.0, z1],
            [-ax, 0.0, z1],  # array, wound to face +y
        ]
    )
    faces = np.array([[0, 2, 1], [0, 3, 2], [4, 6, 5], [4, 7, 6]])
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    chassis, cells, backsheet = STARLINK_MATERIALS
    array = Part(
        "solar-array",
        [2, 3],
        axis=(0.0, 0.0, 1.0),
        point=(0.0, 0.0, (z0 + z1) / 2),
        law=SunTracking(limits=limits),
    )
    return Spacecraft(
        mesh,
        [chassis, chassis, cells, cells],
        name=name,
        back_material=["", "", backsheet, backsheet] if back else None,
        parts=[array],
        colors={chassis: (150, 150, 150), cells: (30, 40, 140), backsheet: (230, 230, 230)},
    )
