"""Earthshine: sunlight reflected by the Earth onto the spacecraft, a second distant source.

The Earth is a Lambertian sphere of Bond albedo ``earth_albedo``
(:func:`sbrdf_xr.sources.earthshine_irradiance_ratio`) seen from its centre's direction.
For a grid or explicit pairs its distance and phase are the scene's ``earth_range_km``
and ``earth_phase_angle`` and its direction ``earth_direction`` (a grid, reference frame)
or ``to_earth`` (pairs, body frame); an observation gives all three at every time.
The light it reflects is ``signal_earthshine``, per unit solar irradiance, and it adds to
``band_signal``.

>>> import trimesh
>>> from sbrdf_xr import Scene, load_spacecraft
>>> from sbrdf_xr.materials.schema import lambertian
>>> box = load_spacecraft(trimesh.creation.box(), material="grey")
>>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
>>> x, y = [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]]
>>> scene = Scene(box, {"grey": grey}, to_sun=x, to_observer=y, to_earth=y,
...               effects=("sunlight", "earthshine"), earth_phase_angle=0.0)
>>> plan = scene.plan()
>>> plan.effects, round(plan.effect_params["earthshine"]["ratio"], 5)  # full Earth from GEO
(('sunlight', 'earthshine'), 0.00457)
>>> print(dict(plan.steps)["earthshine"])
Lambertian Earth (albedo 0.3, range 42164 km, phase 0 deg): irradiance 0.00457 of the \
Sun's, a second distant source
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ... import geometry
from ..._names import WAVELENGTH
from ...sources import earthshine_irradiance_ratio
from .base import BlockInputs, Decision, Effect, Output, PlanInputs, facet_fraction, reflected

if TYPE_CHECKING:
    import xarray as xr

    from ..plan import Plan
    from ..scene import Scene

__all__ = ["EFFECT", "SIGNAL"]

#: The light the facets reflect from the Earth.
SIGNAL = Output(
    "signal_earthshine",
    (WAVELENGTH,),
    True,
    "m2 sr-1",
    "radiometric signal of the light reflected from a Lambertian Earth, per unit solar irradiance",
)


def _geometry(scene: Scene, observed: xr.Dataset | None) -> dict[str, np.ndarray]:
    if observed is not None:  # the Earth's distance and phase at every time
        ratio = [
            earthshine_irradiance_ratio(scene.earth_albedo, r, a)
            for r, a in zip(
                observed["earth_distance"].values,
                observed["earth_phase_angle"].values,
                strict=True,
            )
        ]
        return {
            "to_earth": np.ascontiguousarray(observed["to_earth"].values),
            "earth_scale": np.array(ratio, dtype=np.float64),
        }
    if scene.is_grid:
        e = geometry.normalize(scene.earth_direction, "earth_direction")
        return {"to_earth": np.broadcast_to(e, (len(np.asarray(scene.phase_angles)), 3)).copy()}
    return {"to_earth": np.asarray(scene.to_earth)}


def _plan(inputs: PlanInputs) -> Decision:
    scene = inputs.scene
    es = scene.geometry.sources.get("earth_scale")
    if es is not None:  # an observation: per geometry
        return Decision(
            True,
            f"Lambertian Earth (albedo {scene.earth_albedo:g}) at the observation's "
            f"distance and phase at every time: irradiance {np.min(es):.3g}-{np.max(es):.3g} "
            "of the Sun's, a second distant source",
            {"ratio": float(np.max(es)) if es.size else 0.0},
        )
    ratio = earthshine_irradiance_ratio(
        scene.earth_albedo, scene.earth_range_km, scene.earth_phase_angle
    )
    return Decision(
        True,
        f"Lambertian Earth (albedo {scene.earth_albedo:g}, range "
        f"{scene.earth_range_km:g} km, phase {scene.earth_phase_angle:g} deg): irradiance "
        f"{ratio:.3g} of the Sun's, a second distant source",
        {"ratio": ratio},
    )


def _contribute(plan: Plan, block: BlockInputs) -> dict[str, np.ndarray]:
    to_earth = block.sources["to_earth"]
    frac = facet_fraction(plan, to_earth, block.to_observer)
    r = reflected(plan, block, to_earth, frac, False)
    scale = block.sources.get("earth_scale")
    if scale is not None:  # per geometry (an observation's Earth distance and phase)
        return {"signal_earthshine": (scale[:, None] * r.signal).astype(r.signal.dtype)}
    ratio = plan.effect_params["earthshine"]["ratio"]
    return {"signal_earthshine": (ratio * r.signal).astype(r.signal.dtype)}


#: Sunlight reflected by a Lambertian Earth.
EFFECT = Effect(
    "earthshine",
    title="earthshine",
    description="sunlight reflected by a Lambertian Earth, a second distant source",
    when="asked",
    source="earth",
    needs=("to_earth",),
    outputs=("signal_earthshine", "band_signal"),
    declares=(SIGNAL,),
    band=("signal_earthshine",),
    reads=("earth_direction", "to_earth", "earth_albedo", "earth_range_km", "earth_phase_angle"),
    plan=_plan,
    contribute=_contribute,
    geometry=_geometry,
)
