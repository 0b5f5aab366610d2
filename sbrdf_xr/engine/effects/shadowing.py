"""Shadowing: facets that hide each other from the Sun (self-shadowing) or from the
observer (self-occlusion).

A per-facet effect: each term's lit-and-visible fraction
(:func:`sbrdf_xr.body.visibility.lit_visible_fraction`, exact polygon clipping or
sub-facet ray sampling, the knobs ``shadow_method`` and ``shadow_density``) multiplies
its contribution from every reflected source, so facets are evaluated one by one.  A
convex body cannot shadow itself: there the effect is skipped.

>>> import trimesh
>>> from sbrdf_xr import Scene, load_spacecraft
>>> from sbrdf_xr.materials.schema import lambertian
>>> from sbrdf_xr.testing import l_shaped_spacecraft
>>> paint = {"white-paint-a276": lambertian(0.8, [500.0, 600.0], material="white-paint-a276")}
>>> x = [[1.0, 0.0, 0.0]]  # the Sun and the observer along +x
>>> scene = Scene(l_shaped_spacecraft(), paint, to_sun=x, to_observer=x,
...               effects=("sunlight", "shadowing"), shadow_method="sampled")
>>> plan = scene.plan()
>>> plan.effects, dict(plan.effect_params["shadowing"]), plan.merged
(('sunlight', 'shadowing'), {'method': 'sampled', 'density': 4}, False)
>>> print(dict(plan.steps)["shadowing"])
sampled self-shadowing and self-occlusion, 4**2 samples per facet (non-convex body)
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from .base import Decision, Effect, PlanInputs

if TYPE_CHECKING:
    from ..views import PlanView

__all__ = ["EFFECT"]


def _plan(inputs: PlanInputs) -> Decision:
    if inputs.scene.spacecraft.is_convex:  # (a body with moving parts never is)
        return Decision(False, "skipped: the body is convex, no facet can shadow another")
    knobs = inputs.knobs
    options: dict[str, Any] = {"method": knobs["shadow_method"]}
    if knobs["shadow_method"] == "sampled":
        options["density"] = knobs["shadow_density"]
        line = (
            f"sampled self-shadowing and self-occlusion, "
            f"{knobs['shadow_density']}**2 samples per facet (non-convex body)"
        )
    else:
        line = "exact self-shadowing and self-occlusion by polygon clipping (non-convex body)"
    return Decision(True, line, options)


def _fraction(plan: PlanView, to_source: np.ndarray, to_observer: np.ndarray) -> np.ndarray:
    from ...body.visibility import lit_visible_fraction

    options = plan.effect_params["shadowing"]
    if plan.articulation is not None:  # a group of a body with parts: the posed union
        return plan.articulation.fraction(plan, to_source, to_observer, options)
    frac = lit_visible_fraction(plan.spacecraft, to_source, to_observer, **options)
    return np.ascontiguousarray(np.asarray(frac)[:, plan.terms.facet])


#: Self-shadowing and self-occlusion.
EFFECT = Effect(
    "shadowing",
    title="self-shadowing",
    description="self-shadowing and self-occlusion of the facets",
    when="asked",
    source=None,
    needs=("mesh",),
    reads=("shadow_method", "shadow_density"),
    plan=_plan,
    fraction=_fraction,
)
