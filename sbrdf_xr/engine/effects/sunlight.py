"""Sunlight: the Sun's light reflected by the facets, the source of every simulation.

The facet sums of paper 000 Eqs. 3-4 and the radiometric signal, with the Sun as a
distant source.  In the Earth's umbra (an observation's sunlit fraction 0) nothing is
evaluated and the sums are 0; in the penumbra the signal is scaled by the sunlit
fraction of the solar disc (the Earth's shadow is the ``eclipse`` effect's plan line).

>>> from sbrdf_xr.engine.effects import EFFECTS
>>> sun = EFFECTS["sunlight"]
>>> sun.when, sun.source, sun.band
('always', 'sun', ('signal',))
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from .base import BlockInputs, Effect, facet_fraction, reflected

if TYPE_CHECKING:
    from ..views import PlanView

__all__ = ["EFFECT"]


def _contribute(plan: PlanView, block: BlockInputs) -> dict[str, np.ndarray]:
    """Reflected sunlight; in the Earth's umbra nothing is evaluated (the sums are 0), in
    the penumbra the signal is scaled by the sunlit fraction of the solar disc."""
    scale = block.sun_scale
    if scale is not None and not np.all(scale > 0):
        lit = np.flatnonzero(scale > 0)
        sub = BlockInputs(block.to_sun[lit], block.to_observer[lit], scale[lit], (lit.size,))
        if plan.articulation is not None:  # one group of a body with parts: its poses too
            plan = replace(plan, articulation=plan.articulation.take(lit))
        part = _contribute(plan, sub) if lit.size else None
        g, n = (
            block.to_sun.shape[0],
            plan.tables.n_spectral
            if plan.knobs["evaluation"] == "table"
            else (len(plan.bands) if plan.pre_integrated else plan.wavelength.size),
        )
        dt = np.dtype(plan.knobs["dtype"])
        out = {"signal": np.zeros((g, n), dt), "paper": np.zeros((g, n), dt), "area": np.zeros(g)}
        if "signal_material" in plan.output_names:
            out["signal_material"] = np.zeros((g, len(plan.materials), n), dt)
        if part is not None:
            for k in out:
                out[k][lit] = part[k]
        return out
    frac = facet_fraction(plan, block.to_sun, block.to_observer)
    r = reflected(plan, block, block.to_sun, frac, "signal_material" in plan.output_names)
    out = {"signal": r.signal, "paper": r.paper, "area": r.area}
    if r.per_material is not None:
        out["signal_material"] = r.per_material
    if scale is not None:  # the Earth's penumbra scales the irradiance, not the geometry
        sc = scale.astype(r.signal.dtype)
        out["signal"] = r.signal * sc[:, None]
        if r.per_material is not None:
            out["signal_material"] = r.per_material * sc[:, None, None]
    return out


#: Reflected sunlight.
EFFECT = Effect(
    "sunlight",
    title="sunlight",
    description="reflected sunlight: paper 000 Eqs. 3-4 and the radiometric signal",
    when="always",
    source="sun",
    outputs=("spacecraft_sbrdf", "signal", "brdf", "area", "signal_material", "band_signal"),
    band=("signal",),
    contribute=_contribute,
)
