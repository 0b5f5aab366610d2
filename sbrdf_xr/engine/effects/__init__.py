"""The effects a simulation can include, each declared once, and the outputs of a cube.

Every effect is one :class:`Effect` entry of :data:`EFFECTS`, written in its own module:

``sunlight``
    Reflected sunlight (paper 000 Eqs. 3-4), always on.
``shadowing``
    Self-shadowing and self-occlusion of the facets (per facet).
``eclipse``
    The Earth's shadow during an observation (comes with its geometry).
``earthshine``
    Sunlight reflected by a Lambertian Earth, a second distant source.
``thermal``
    Thermal emission of the facets, Kirchhoff emissivity times Planck.
``earth_thermal``
    The Earth's thermal emission (a disc at one brightness temperature) reflected by
    the facets.
``moonlight``
    Sunlight reflected by the Moon during an observation, a second distant source.

The engine reads nothing else about an effect: whether a scene may ask for it and what
it needs (:class:`~sbrdf_xr.engine.Scene`), the directions and scales of its source in the
sweep (:mod:`sbrdf_xr.engine.sweep`), whether it runs and its plan line, which terms its
light can reach, how many kernel passes it costs, the outputs it adds
(:mod:`sbrdf_xr.engine.plan`), and its sums on every block (:mod:`sbrdf_xr.engine.run`).
No other module of the engine names an effect, so adding one is one module and one line
of :data:`EFFECTS`, plus its tests.

Every variable a cube can hold is one :class:`Output` of :data:`OUTPUTS`, with its
dimensions and CF attributes, defined once: the core ones in :mod:`.base`, an effect's
own in its entry.

Examples
--------
>>> from sbrdf_xr.engine.effects import EFFECTS, SCENE_EFFECTS, scene_effects
>>> list(EFFECTS)
['sunlight', 'shadowing', 'eclipse', 'earthshine', 'thermal', 'earth_thermal', 'moonlight']
>>> SCENE_EFFECTS  # what Scene(effects=...) accepts
('sunlight', 'shadowing', 'earthshine', 'thermal', 'earth_thermal', 'moonlight')
>>> [e.name for e in scene_effects(["thermal"])]  # planned for a scene asking for thermal
['sunlight', 'eclipse', 'thermal']
"""

from collections.abc import Iterable

from . import base, earth_thermal, earthshine, eclipse, moonlight, shadowing, sunlight, thermal
from .base import (
    SCENE_OUTPUTS,
    SPECTRAL_OUTPUTS,
    BlockInputs,
    Decision,
    Effect,
    Output,
    PlanInputs,
    facet_fraction,
    finish,
    readonly,
    reflected,
)

__all__ = [
    "DEFAULT_EFFECTS",
    "EFFECTS",
    "OUTPUTS",
    "SCENE_EFFECTS",
    "SCENE_OUTPUTS",
    "SPECTRAL_OUTPUTS",
    "BlockInputs",
    "Decision",
    "Effect",
    "Output",
    "PlanInputs",
    "base",
    "earth_thermal",
    "earthshine",
    "eclipse",
    "facet_fraction",
    "finish",
    "moonlight",
    "readonly",
    "reflected",
    "scene_effects",
    "shadowing",
    "sunlight",
    "thermal",
]

#: The effects, by name, in the order they are planned.
EFFECTS: dict[str, Effect] = {
    e.name: e
    for e in (
        sunlight.EFFECT,
        shadowing.EFFECT,
        eclipse.EFFECT,
        earthshine.EFFECT,
        thermal.EFFECT,
        earth_thermal.EFFECT,
        moonlight.EFFECT,
    )
}

#: Every output variable a cube may hold: the core ones and each effect's own.
OUTPUTS: dict[str, Output] = {
    **base.CORE_OUTPUTS,
    **{o.name: o for e in EFFECTS.values() for o in e.declares},
}

#: Effects always on: the default of ``Scene(effects=...)``.
DEFAULT_EFFECTS: tuple[str, ...] = tuple(n for n, e in EFFECTS.items() if e.when == "always")
#: Effects a scene may ask for (``Scene(effects=...)``): all but those the geometry brings.
SCENE_EFFECTS: tuple[str, ...] = tuple(n for n, e in EFFECTS.items() if e.when != "automatic")


def scene_effects(asked: Iterable[str]) -> tuple[Effect, ...]:
    """The effects planned for a scene that asks for ``asked``: those always on, those the
    geometry may bring, and those asked for, in the order of :data:`EFFECTS`.

    Examples
    --------
    >>> from sbrdf_xr.engine.effects import scene_effects
    >>> [e.name for e in scene_effects(("earthshine", "sunlight"))]
    ['sunlight', 'eclipse', 'earthshine']
    """
    wanted = set(asked)
    return tuple(e for e in EFFECTS.values() if e.when != "asked" or e.name in wanted)
