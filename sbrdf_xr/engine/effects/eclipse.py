"""Eclipse: the Earth's shadow on the spacecraft during an observation.

An observation's geometry carries the sunlit fraction of the solar disc at every time
(:func:`sbrdf_xr.observing.earth_shadow.sunlit_fraction`); the ``sunlight`` effect skips
the times in the umbra and scales the penumbra.  This entry states it in the plan; it
comes with the geometry and is not asked for.

>>> import trimesh
>>> from sbrdf_xr import Scene, load_spacecraft
>>> from sbrdf_xr.materials.schema import lambertian
>>> from sbrdf_xr.observing import canx1_pass
>>> box = load_spacecraft(trimesh.creation.box(), material="grey")
>>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
>>> plan = Scene(box, {"grey": grey}, observation=canx1_pass()).plan()  # leaves the shadow
>>> plan.effects
('sunlight', 'eclipse')
>>> print(dict(plan.steps)["eclipse"])  # doctest: +ELLIPSIS
Earth shadow: ... geometries in umbra skipped (no sunlight), ... in penumbra scaled by ...
"""

from __future__ import annotations

import numpy as np

from .base import Decision, Effect, PlanInputs

__all__ = ["EFFECT"]


def _plan(inputs: PlanInputs) -> Decision:
    scale = inputs.scene.geometry.sun_scale
    if scale is None:
        return Decision(False)
    dark = int(np.sum(scale <= 0))
    part = int(np.sum((scale > 0) & (scale < 1)))
    return Decision(
        True,
        f"Earth shadow: {dark} geometries in umbra skipped (no sunlight), "
        f"{part} in penumbra scaled by the sunlit fraction of the solar disc",
    )


#: The Earth's shadow.
EFFECT = Effect(
    "eclipse",
    title="the Earth's shadow",
    description="the Earth's shadow: sunlight scaled by the sunlit fraction of the solar disc",
    when="automatic",
    source=None,
    needs=("sunlit_fraction",),
    plan=_plan,
)
