"""Scene files and built-in scenes: the named scenes, and a scene from a name or a file.

:func:`builtin_scene` builds a named scene and :func:`resolve_scene` accepts a
:class:`~sbrdf_xr.engine.scene.Scene`, a built-in name or a TOML file path.  The scene
files themselves (their schema and checks, :func:`~sbrdf_xr.engine.scene_file.load_scene`,
:func:`~sbrdf_xr.engine.scene_file.scene_from_dict`) are read by :mod:`sbrdf_xr.engine.scene_file`
and re-exported here.  All are re-exported from :mod:`sbrdf_xr.engine`.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from .. import geometry
from ..errors import SceneError, ValidationError, renamed_attributes
from .scene import Scene
from .scene_file import (
    MAX_SCENE_COUNT,
    MAX_SHADOW_DENSITY,
    load_material_specs,
    load_scene,
    scene_from_dict,
    scene_material_tables,
)

__all__ = [
    "MAX_SCENE_COUNT",
    "MAX_SHADOW_DENSITY",
    "STARLINK_STAND_INS",
    "builtin_scene",
    "builtin_scenes",
    "geo_comsat_materials",
    "load_material_specs",
    "load_scene",
    "resolve_scene",
    "scene_from_dict",
    "scene_material_tables",
    "starlink_materials",
]

#: Albedos of the Lambertian stand-ins of :func:`starlink_materials` [1]: placeholders
#: chosen here (a grey chassis, dark cells, a light backsheet), not measurements.
STARLINK_STAND_INS = {
    "starlink-chassis": 0.3,
    "starlink-solar-array": 0.1,
    "starlink-array-back": 0.5,
}


def starlink_materials(
    tables: Mapping[str, Any] | None = None, wavelength: Any = (400.0, 550.0, 700.0, 900.0)
) -> dict[str, Any]:
    """Materials of :func:`sbrdf_xr.body.starlink.starlink_v15`: the tables given, and a
    labelled Lambertian stand-in (:data:`STARLINK_STAND_INS`) for each one not given.

    Parameters
    ----------
    tables : mapping of str to DataArray or Dataset, optional
        Tables (or BRDF models) for any of ``starlink-chassis``, ``starlink-solar-array``,
        ``starlink-array-back`` (e.g. built from the laboratory scans of the data set).
    wavelength : array_like
        Wavelengths of the stand-ins [nm].

    Returns
    -------
    dict of str to DataArray or Dataset
        For ``Scene(materials=...)``; a stand-in's ``provenance`` says it is one.

    Examples
    --------
    >>> mats = starlink_materials()
    >>> sorted(mats)
    ['starlink-array-back', 'starlink-chassis', 'starlink-solar-array']
    >>> mats["starlink-chassis"].attrs["provenance"].split(":")[0]
    'STAND-IN, not a measurement'
    >>> starlink_materials({"chassis": mats["starlink-chassis"]})
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.ValidationError: starlink_materials: 'chassis' is not a material of \
the Starlink v1.5 body; its materials: starlink-chassis, starlink-solar-array, starlink-array-back
    """
    from ..materials.schema import lambertian

    given = dict(tables or {})
    for name in given:
        if name not in STARLINK_STAND_INS:
            raise ValidationError(
                f"starlink_materials: {name!r} is not a material of the Starlink v1.5 body; "
                f"its materials: {', '.join(STARLINK_STAND_INS)}"
            )
    out = {}
    for name, albedo in STARLINK_STAND_INS.items():
        if name in given:
            out[name] = given[name]
            continue
        table = lambertian(albedo, wavelength, material=name)
        table.attrs["provenance"] = (
            f"STAND-IN, not a measurement: Lambertian of albedo {albedo:g} chosen by "
            "sbrdf_xr.engine.builtin.starlink_materials; give the measured table instead"
        )
        out[name] = table
    return out


def geo_comsat_materials(
    wavelength: Any = None, *, roughness: Mapping[str, float] | None = None
) -> dict[str, Any]:
    """Materials of :func:`sbrdf_xr.body.geo_comsat.geo_comsat`: the optical-constant
    materials of :mod:`sbrdf_xr.materials.optical` (model materials, measured optical
    constants with an assumed roughness).

    Parameters
    ----------
    wavelength : array_like, optional
        Wavelengths [nm] (default: 360-900 nm every 0.2 nm, which resolves the fringes of
        the 25 um Kapton film and, above ~450 nm, those of the 100 um silica layers).
    roughness : mapping of str to float, optional
        GGX roughness per material [1] (default: each material's).

    Returns
    -------
    dict of str to Dataset
        For ``Scene(materials=...)`` (evaluated with ``evaluation="analytic"``).

    Examples
    --------
    >>> mats = geo_comsat_materials([500.0, 600.0])
    >>> sorted(mats), mats["osr"].attrs["model"]
    (['gaas-cell', 'kapton-mli', 'osr'], 'microfacet')
    """
    from ..body.geo_comsat import GEO_COMSAT_MATERIALS
    from ..materials.optical import optical_material

    wl = np.linspace(360.0, 900.0, 2701) if wavelength is None else wavelength
    alpha = dict(roughness or {})
    return {m: optical_material(m, wl, roughness=alpha.get(m)) for m in GEO_COMSAT_MATERIALS}


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


#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(__name__, globals(), {"material_tables": "scene_material_tables"})
