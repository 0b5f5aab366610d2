"""The content fingerprint a cube stores as global attributes, and what changed between two.

The engine hashes what a cube is computed from
(:func:`sbrdf_xr.engine.fingerprint.scene_fingerprint`); the store only writes the
result, flat string attributes whose names are valid netCDF/CF attribute names (letters,
digits and underscores, starting with a letter), and compares them::

    fingerprint                               the whole scene (SHA-256 of the parts below)
    fingerprint_material_<name>               one per material table: values, coords, attrs
    fingerprint_material_names                JSON: attribute suffix -> material name
    fingerprint_materials                     the materials map (name -> table identity)
    fingerprint_mesh                          vertices, faces and facet material labels
    fingerprint_filters                       responses of the filters of the scene's bands
    fingerprint_knobs                         every other scene field (method, dtype, ...)
    fingerprint_knobs_json                    those fields in canonical JSON (readable)
    fingerprint_geometry                      attitudes, phase angles, Sun/observer vectors
    fingerprint_package                       the sbrdf_xr version

:func:`sbrdf_xr.store.writer.write_cube` refuses to resume an unfinished cube whose
fingerprint differs, naming what changed (:func:`changes`).

``scene_fingerprint``, which lived here, is now
:func:`sbrdf_xr.engine.fingerprint.scene_fingerprint`; the old name is served one more
release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
"""

from __future__ import annotations

import importlib
import json
import warnings
from collections.abc import Mapping
from typing import Any

from ..errors import RenamedWarning

__all__ = [
    "KNOBS_JSON",
    "MATERIAL_NAMES",
    "MATERIAL_PREFIX",
    "MOVED",
    "PREFIX",
    "changes",
    "moved_name",
]

#: Prefix of every fingerprint attribute.
PREFIX = "fingerprint"
#: Prefix of the attribute of each material table (its suffix in :data:`MATERIAL_NAMES`).
MATERIAL_PREFIX = f"{PREFIX}_material_"
#: The attribute holding the JSON map of attribute suffix -> material name.
MATERIAL_NAMES = f"{PREFIX}_material_names"
#: The attribute holding the scene's knobs in canonical JSON (read for messages).
KNOBS_JSON = f"{PREFIX}_knobs_json"
#: What each single-hash part stands for, in messages.
_PARTS = {
    "materials": "the materials map (which table stands for each material)",
    "mesh": "the spacecraft mesh (vertices, faces or facet materials)",
    "filters": "the filters of the bands",
    "knobs": "the scene's numerical settings",
    "geometry": "the geometry (attitudes, phase angles or Sun/observer vectors)",
    "package": "the sbrdf_xr version",
}


def _names(attrs: Mapping[str, Any]) -> dict[str, str]:
    try:
        names = json.loads(str(attrs.get(MATERIAL_NAMES, "{}")))
        return {str(k): str(v) for k, v in names.items()} if isinstance(names, dict) else {}
    except ValueError:
        return {}


def changes(old: Mapping[str, Any], new: Mapping[str, Any]) -> list[str]:
    """What differs between two fingerprints (or two sets of global attributes), in words.

    Parameters
    ----------
    old, new : mapping
        Attributes holding :func:`sbrdf_xr.engine.fingerprint.scene_fingerprint`
        entries (other keys are ignored).

    Returns
    -------
    list of str
        For example ``["material 'white-paint-a276': table changed"]``; empty when the
        fingerprints agree (or neither has one).

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> scene = Scene(box, {"grey": grey}, attitudes=[[0, 0, 0, 1.0]], phase_angles=[0.0, 60.0])
    >>> from sbrdf_xr.engine.fingerprint import scene_fingerprint
    >>> from sbrdf_xr.store.fingerprint import changes
    >>> fp = scene_fingerprint(scene)
    >>> changes(fp, scene_fingerprint(scene.with_options(method="cubic")))
    ["setting 'method': 'linear' -> 'cubic'"]
    >>> brighter = lambertian(0.6, [500.0, 600.0, 700.0], material="grey")
    >>> changes(fp, scene_fingerprint(scene.with_options(materials={"grey": brighter})))
    ["material 'grey': table changed"]
    >>> changes(fp, fp)
    []
    """
    old = {k: str(v) for k, v in old.items() if str(k).startswith(PREFIX)}
    new = {k: str(v) for k, v in new.items() if str(k).startswith(PREFIX)}
    if old.get(PREFIX) == new.get(PREFIX):
        return []
    if not old or not new:
        which = "the new cube has" if not old else "the unfinished cube has"
        return [f"only {which} a content fingerprint"]
    out = []
    names = {**_names(old), **_names(new)}
    keys = sorted(
        {k for k in (*old, *new) if k.startswith(MATERIAL_PREFIX) and k != MATERIAL_NAMES}
    )
    for k in keys:
        label = names.get(k[len(MATERIAL_PREFIX) :], k[len(MATERIAL_PREFIX) :])
        if k not in old:
            out.append(f"material {label!r}: added")
        elif k not in new:
            out.append(f"material {label!r}: removed")
        elif old[k] != new[k]:
            out.append(f"material {label!r}: table changed")
    for part, what in _PARTS.items():
        k = f"{PREFIX}_{part}"
        if old.get(k) == new.get(k):
            continue
        if part == "knobs":
            out.append(_knob_changes(old.get(KNOBS_JSON), new.get(KNOBS_JSON)) or f"{what} changed")
        else:
            out.append(f"{what} changed")
    return out or ["the content fingerprint changed"]


def _knob_changes(old: str | None, new: str | None) -> str:
    try:
        a, b = json.loads(old or "{}"), json.loads(new or "{}")
    except ValueError:
        return ""
    diff = [k for k in sorted(set(a) | set(b)) if a.get(k) != b.get(k)]
    return "; ".join(f"setting {k!r}: {a.get(k)!r} -> {b.get(k)!r}" for k in diff)


#: Names that moved out of the store -> the module that holds them now.
MOVED = {"scene_fingerprint": "sbrdf_xr.engine.fingerprint"}


def moved_name(module: str, name: str) -> Any:
    """A name that moved to the engine, served under its old place one more release.

    Parameters
    ----------
    module : str
        The module the name is asked of (for the message).
    name : str
        The name asked for.

    Returns
    -------
    object
        The object from its new module (imported then, on this first use), with a
        :class:`~sbrdf_xr.errors.RenamedWarning`.

    Raises
    ------
    AttributeError
        If ``name`` did not move.

    Examples
    --------
    >>> import warnings
    >>> from sbrdf_xr.store.fingerprint import moved_name
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     f = moved_name("sbrdf_xr.store", "scene_fingerprint")
    >>> f.__module__, str(caught[0].message).split(";")[0]
    ('sbrdf_xr.engine.fingerprint', \
'sbrdf_xr.store.scene_fingerprint moved to sbrdf_xr.engine.fingerprint.scene_fingerprint')
    """
    if name not in MOVED:
        raise AttributeError(f"module {module!r} has no attribute {name!r}")
    warnings.warn(
        f"{module}.{name} moved to {MOVED[name]}.{name}; "
        "the old name will be removed in the next release",
        RenamedWarning,
        stacklevel=3,
    )
    # a one-release shim: the store itself never reads a scene
    return getattr(importlib.import_module(MOVED[name]), name)


def __getattr__(name: str) -> Any:
    return moved_name(__name__, name)
