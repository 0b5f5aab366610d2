"""Scenes: what to simulate.

A :class:`Scene` holds a spacecraft, its materials, the geometry of a sweep, the
outputs and effects asked for and the value of every numerical knob
(:mod:`sbrdf_xr.knobs`).  :meth:`Scene.plan` compiles it into a
:class:`~sbrdf_xr.plan.Plan` that states every step that will run and every step
skipped, and why (DESIGN.md principle 3: simulate only the effects a scene calls
for).  A scene does no I/O and computes nothing in its constructor beyond checking
its inputs.

Geometry is either a grid of attitudes (quaternions, body -> reference frame) times
phase angles in an observation plane (paper 000 Figs. 12-13) (:class:`GridGeometry`),
or an explicit list of ``(to_sun, to_observer)`` unit-vector pairs in the body frame
(:class:`PairGeometry`).

The class lives in :mod:`sbrdf_xr.scene_model`, the scene files and built-in scenes in
:mod:`sbrdf_xr.scene_io`; both are re-exported here.
"""

from __future__ import annotations

from .effects import SPECTRAL_OUTPUTS
from .scene_io import (
    MAX_SCENE_COUNT,
    MAX_SHADOW_DENSITY,
    builtin_scene,
    builtin_scenes,
    load_scene,
    resolve_scene,
    scene_from_dict,
)
from .scene_model import EFFECTS, OUTPUTS, PRESETS, GridGeometry, PairGeometry, Scene

__all__ = [
    "EFFECTS",
    "MAX_SCENE_COUNT",
    "MAX_SHADOW_DENSITY",
    "OUTPUTS",
    "PRESETS",
    "SPECTRAL_OUTPUTS",
    "GridGeometry",
    "PairGeometry",
    "Scene",
    "builtin_scene",
    "builtin_scenes",
    "load_scene",
    "resolve_scene",
    "scene_from_dict",
]
