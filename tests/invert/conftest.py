"""Shared fixtures of the inversion tests: CanX-1 and its per-material spectra."""

from __future__ import annotations

import numpy as np
import pytest

from sbrdf_xr.body.spacecraft import canx1
from sbrdf_xr.engine import Scene
from sbrdf_xr.engine.run import simulate

#: Six geometries of CanX-1: near-specular on four side faces (the cells and the frame
#: glint) and two off-specular.
SUN = np.array(
    [
        [0.8564, 0.4945, 0.1483],
        [0.3412, 0.9375, 0.0682],
        [-0.7001, 0.7001, -0.14],
        [0.1258, -0.8991, 0.4193],
        [1.0, 0.3, 0.2],
        [-0.7, 0.6, 0.4],
    ]
)
OBSERVER = np.array(
    [
        [0.8375, -0.5233, -0.157],
        [-0.2919, 0.9547, -0.0584],
        [-0.6487, -0.7463, 0.1493],
        [-0.1304, -0.8911, -0.4346],
        [0.8, 0.7, 0.1],
        [-0.9, 0.1, 0.2],
    ]
)


@pytest.fixture(scope="session")
def sc():
    return canx1()


@pytest.fixture(scope="session")
def per_material(sc):
    """Per-material spectra of CanX-1 at the six geometries."""
    s = SUN / np.linalg.norm(SUN, axis=1)[:, None]
    o = OBSERVER / np.linalg.norm(OBSERVER, axis=1)[:, None]
    cube = simulate(Scene(sc, to_sun=s, to_observer=o, outputs=("signal", "per_material")))
    return cube["signal_material"].load()


def box_wing_spacecraft():
    """A box-wing: a 1 x 1 x 1.4 m painted bus between two 2 x 1 m wings (4 cm thick) along
    y, with solar cells on the +x faces of both wings and bare aluminium elsewhere on them."""
    import trimesh

    from sbrdf_xr import load_spacecraft

    parts = [trimesh.creation.box(extents=(1.0, 1.0, 1.4))]
    for sign in (1, -1):
        wing = trimesh.creation.box(extents=(0.04, 2.0, 1.0))
        wing.apply_translation((0.0, sign * 1.6, 0.0))
        parts.append(wing)
    mesh = trimesh.util.concatenate(parts)
    on_wing = np.abs(mesh.triangles_center[:, 1]) > 0.55
    cells = on_wing & (mesh.face_normals[:, 0] > 0.5)
    colour = np.where(
        cells[:, None],
        [0, 0, 255, 255],
        np.where(on_wing[:, None], [200, 200, 200, 255], [255, 255, 255, 255]),
    )
    mesh.visual.face_colors = colour
    names = {
        (0, 0, 255): "tjpv-cell",
        (200, 200, 200): "aluminium-6061-t6",
        (255, 255, 255): "white-paint-a276",
    }
    return load_spacecraft(mesh, names, name="box-wing")


@pytest.fixture(scope="session")
def box_wing():
    return box_wing_spacecraft()
