"""Scene files and built-in scenes: the named scenes, and a scene from a name or a file.

:func:`builtin_scene` builds a named scene and :func:`resolve_scene` accepts a
:class:`~sbrdf_xr.engine.scene.Scene`, a built-in name or a TOML file path.  The scene
files themselves (their schema and checks, :func:`~sbrdf_xr.engine.scene_file.load_scene`,
:func:`~sbrdf_xr.engine.scene_file.scene_from_dict`) are read by :mod:`sbrdf_xr.engine.scene_file`
and re-exported here.  All are re-exported from :mod:`sbrdf_xr.engine`.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .. import geometry
from ..errors import SceneError
from .scene import Scene
from .scene_file import (
    MAX_SCENE_COUNT,
    MAX_SHADOW_DENSITY,
    load_material_specs,
    load_scene,
    material_tables,
    scene_from_dict,
)

__all__ = [
    "MAX_SCENE_COUNT",
    "MAX_SHADOW_DENSITY",
    "builtin_scene",
    "builtin_scenes",
    "load_material_specs",
    "load_scene",
    "material_tables",
    "resolve_scene",
    "scene_from_dict",
]


def _canx1_plusx_specular() -> Scene:
    from ..body.spacecraft import canx1

    return Scene(
        canx1(),
        attitudes=geometry.axis_rotation([0, 0, 1], [0.0]),
        phase_angles=[5.0, 30.0, 60.0, 90.0],
        outputs=("spacecraft_sbrdf", "signal", "brdf", "area", "per_material"),
        name="canx1-plusx-specular",
        description="CanX-1 +X side at specular geometry in the xy-plane, beta = 5, 30, 60, 90 deg "
        "(paper 000 section 4, Fig. 12)",
    )


def _canx1_rotation() -> Scene:
    from ..body.spacecraft import canx1

    angles = np.arange(360.0)
    return Scene(
        canx1(),
        attitudes=geometry.rotation_sweep(
            [0, 0, -1], angles, geometry.axis_rotation([0, 0, 1], 25.0)
        ),
        attitude_angle=angles,
        phase_angles=[10.0],
        outputs=("spacecraft_sbrdf", "signal", "brdf", "area", "per_material"),
        name="canx1-rotation",
        description="CanX-1 initially rotated 25 deg about +z, then 360 steps of 1 deg about -z; "
        "v_i and v_r 5 deg either side of +x (beta = 10 deg) (paper 000 section 4, Fig. 13)",
    )


def _canx1_pass() -> Scene:
    from ..body.spacecraft import canx1
    from ..observing.observe import canx1_pass

    return Scene(
        canx1(),
        observation=canx1_pass(),
        outputs=("spacecraft_sbrdf", "signal", "brdf", "area", "band_signal"),
        bands=("V", "R", "I"),
        name="canx1-pass",
        description="CanX-1 model on the shipped example elements over Mont Megantic, "
        "2024-03-17 01:20-01:25 UTC at 1 s, spinning; leaves the Earth's shadow in the window",
    )


_BUILTIN = {
    "canx1-plusx-specular": _canx1_plusx_specular,
    "canx1-rotation": _canx1_rotation,
    "canx1-pass": _canx1_pass,
}


def builtin_scenes() -> list[str]:
    """Names of the built-in scenes.

    Examples
    --------
    >>> from sbrdf_xr.engine import builtin_scenes
    >>> builtin_scenes()
    ['canx1-plusx-specular', 'canx1-rotation', 'canx1-pass']
    """
    return list(_BUILTIN)


def builtin_scene(name: str) -> Scene:
    """A built-in scene by name (see :func:`builtin_scenes`).

    Examples
    --------
    The built-in scenes simulate CanX-1 with its measured material tables, which are
    built (or read from the cache) on first use; that takes seconds to a minute:

    >>> from sbrdf_xr.engine import builtin_scene
    >>> scene = builtin_scene("canx1-rotation")  # doctest: +SKIP
    >>> scene.n_geometries  # doctest: +SKIP
    360
    >>> builtin_scene("canx1-spin")
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.SceneError: unknown scene 'canx1-spin'; built-in scenes: ...
    """
    try:
        return _BUILTIN[name]()
    except KeyError:
        raise SceneError(
            f"unknown scene {name!r}; built-in scenes: {', '.join(_BUILTIN)}"
        ) from None


def resolve_scene(spec: str | os.PathLike[str] | Scene) -> Scene:
    """A scene from a Scene, a built-in name or a TOML file path (read by
    :func:`~sbrdf_xr.engine.scene_file.load_scene`, whose example writes one).

    Examples
    --------
    >>> from sbrdf_xr.engine import resolve_scene
    >>> scene = resolve_scene("canx1-rotation")  # a built-in name; its tables load on first use
    >>> scene.name, scene.n_geometries, resolve_scene(scene) is scene
    ('canx1-rotation', 360, True)
    >>> resolve_scene("no-such-scene")
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.SceneError: unknown scene 'no-such-scene'; built-in scenes: ...
    """
    if isinstance(spec, Scene):
        return spec
    if not isinstance(spec, str | os.PathLike):
        raise SceneError(
            f"scene: expected a Scene, a built-in scene name or a TOML file path, "
            f"got {type(spec).__name__}"
        )
    text = os.fspath(spec)
    if text in _BUILTIN:
        return builtin_scene(text)
    if "\0" in text:
        raise SceneError(f"unknown scene {text!r}: a name or path cannot contain a NUL character")
    path = Path(text)
    if path.suffix == ".toml" or path.exists():
        if path.is_dir():
            raise SceneError(f"scene file {path} is a directory")
        if not path.exists():
            raise SceneError(f"scene file {path} does not exist")
        return load_scene(path)
    raise SceneError(
        f"unknown scene {text!r}; built-in scenes: {', '.join(_BUILTIN)}, or a .toml file"
    )
