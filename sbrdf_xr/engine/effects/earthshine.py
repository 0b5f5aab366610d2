"""Earthshine: sunlight reflected by the Earth onto the spacecraft.

The Earth is a Lambertian sphere of albedo ``earth_albedo``.  For a grid or explicit pairs
its distance and phase are the scene's ``earth_range`` and ``earth_phase_angle`` and
its direction ``earth_direction`` (a grid, reference frame) or ``to_earth`` (pairs, body
frame); an observation gives all three at every time.  The light it reflects is
``signal_earthshine``, per unit solar irradiance, and it adds to ``band_signal``.

The knob ``earth_model`` chooses the Earth:

``finite`` (default)
    The Earth at its true size (paper 001 §1): each facet receives
    :func:`sbrdf_xr.sources.earthshine_facets`, the integral of the lit day side over the
    part of the disc above the facet's horizon, and reflects it with its BRDF evaluated
    at the direction of the Earth's centre: ``A cos(theta_r) f_r(e, o) E_facet``.  This
    is exact for a Lambertian facet; for a glossy one it replaces the BRDF averaged over
    the disc by its value at the centre (measured in ``tests/engine/test_earthshine_finite.py``).
    A facet whose horizon hides the Earth's centre but still sees part of the lit Earth
    (up to ``90 deg + rho`` from the centre, ``sin(rho) = R / r``) reflects the irradiance
    it receives with its directional-hemispherical reflectance at the emission angle,
    ``rho(theta_r) / pi`` (reciprocity: exact for a Lambertian facet, the diffuse-sky
    approximation for a glossy one), as in the ``earth_thermal`` effect.  The Sun that
    lights the Earth is at the scene's ``earth_phase_angle`` from the spacecraft, on the
    side of the spacecraft's Sun (for an observation, the true one).
``point``
    A distant source from the Earth's centre with the diffuse-sphere phase law
    (:func:`sbrdf_xr.sources.earthshine_irradiance_ratio`): 9.8 % low at GEO for an
    Earth-facing plate, 32 % at 7000 km, and lit by a night-side Earth.

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
(('sunlight', 'earthshine'), 0.00506)
>>> print(dict(plan.steps)["earthshine"])
finite Lambertian Earth (albedo 0.3, range 42164 km, phase 0 deg): irradiance 0.00506 of \
the Sun's on an Earth-facing facet, on each facet cut by its horizon, the BRDF at the \
Earth's centre
>>> print(dict(scene.with_options(earth_model="point").plan().steps)["earthshine"])
Lambertian Earth (albedo 0.3, range 42164 km, phase 0 deg): irradiance 0.00457 of the \
Sun's, a second distant source
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ... import geometry
from ..._names import WAVELENGTH
from ...sources import EARTH_MEAN_RADIUS_KM, earthshine_facets, earthshine_irradiance_ratio
from ._limb import limb_signal, limb_tables
from .base import BlockInputs, Decision, Effect, Output, PlanInputs, facet_fraction, reflected

if TYPE_CHECKING:
    import xarray as xr

    from ..views import PlanView, SceneView

__all__ = ["EFFECT", "SIGNAL"]

#: The light the facets reflect from the Earth.
SIGNAL = Output(
    "signal_earthshine",
    (WAVELENGTH,),
    True,
    "m2 sr-1",
    "radiometric signal of the light reflected from a Lambertian Earth, per unit solar irradiance",
)


def _geometry(scene: SceneView, observed: xr.Dataset | None) -> dict[str, np.ndarray]:
    finite = scene.earth_model == "finite"
    if observed is not None:  # the Earth's distance and phase at every time
        dist = np.asarray(observed["earth_distance"].values, dtype=np.float64)
        phase = np.asarray(observed["earth_phase_angle"].values, dtype=np.float64)
        out = {"to_earth": np.ascontiguousarray(observed["to_earth"].values)}
        if finite:
            return {**out, **_finite(dist, phase)}
        ratio = [
            earthshine_irradiance_ratio(scene.earth_albedo, r, a)
            for r, a in zip(dist, phase, strict=True)
        ]
        return {**out, "earth_scale": np.array(ratio, dtype=np.float64)}
    if scene.is_grid:
        e = geometry.normalize(scene.earth_direction, "earth_direction")
        n = len(np.asarray(scene.phase_angles))
        out = {"to_earth": np.broadcast_to(e, (n, 3)).copy()}
    else:
        out = {"to_earth": np.asarray(scene.to_earth)}
        n = len(out["to_earth"])
    if finite:
        rng = np.full(n, float(scene.earth_range))
        out.update(_finite(rng, np.full(n, float(scene.earth_phase_angle))))
    return out


def _finite(rng: np.ndarray, phase: np.ndarray) -> dict[str, np.ndarray]:
    """The finite Earth's range [km] and phase [degree], and its reach ``sin(rho) = R / r``:
    facets up to ``90 deg + rho`` from its centre see part of it (so the plan keeps them)."""
    return {"earth_range": rng, "earth_phase": phase, "earth_reach": EARTH_MEAN_RADIUS_KM / rng}


def _plan(inputs: PlanInputs) -> Decision:
    scene = inputs.scene
    finite = scene.earth_model == "finite"
    what = "finite Lambertian Earth" if finite else "Lambertian Earth"
    how = (
        "on each facet cut by its horizon, the BRDF at the Earth's centre"
        if finite
        else "a second distant source"
    )
    es = scene.geometry.sources.get("earth_scale")
    if finite and "earth_range" in scene.geometry.sources and scene.observation is not None:
        return Decision(
            True,
            f"{what} (albedo {scene.earth_albedo:g}) at the observation's distance and phase "
            f"at every time: {how}",
            {"ratio": None, "albedo": scene.earth_albedo, "limb_tables": _limb(inputs)},
        )
    if es is not None:  # an observation: per geometry
        return Decision(
            True,
            f"{what} (albedo {scene.earth_albedo:g}) at the observation's "
            f"distance and phase at every time: irradiance {np.min(es):.3g}-{np.max(es):.3g} "
            f"of the Sun's, {how}",
            {"ratio": float(np.max(es)) if es.size else 0.0, "albedo": scene.earth_albedo},
        )
    ratio = earthshine_irradiance_ratio(
        scene.earth_albedo, scene.earth_range, scene.earth_phase_angle
    )
    if finite:  # an Earth-facing plate, the Sun in the x-z plane as seen from the Earth
        a = np.radians(scene.earth_phase_angle)
        down, sun = [0.0, 0.0, -1.0], [np.sin(a), 0.0, np.cos(a)]
        facing = earthshine_facets([down], [down], [sun], scene.earth_range, scene.earth_albedo)
        ratio = float(facing[0, 0])
    return Decision(
        True,
        f"{what} (albedo {scene.earth_albedo:g}, range "
        f"{scene.earth_range:g} km, phase {scene.earth_phase_angle:g} deg): irradiance "
        f"{ratio:.3g} of the Sun's{' on an Earth-facing facet' if finite else ''}, {how}",
        {"ratio": ratio, "albedo": scene.earth_albedo, "limb_tables": _limb(inputs)},
    )


def _limb(inputs: PlanInputs) -> tuple[xr.DataArray, ...]:
    """The materials' tables, for the facets that see only the limb."""
    return limb_tables(inputs) if inputs.scene.earth_model == "finite" else ()


def _earth_sun(to_earth: np.ndarray, to_sun: np.ndarray, phase_deg: np.ndarray) -> np.ndarray:
    """The Sun's direction (G, 3) that lights the Earth at its phase angle ``alpha``
    (``-s . e = cos(alpha)``), on the side of the spacecraft's Sun ``to_sun`` about ``e``."""
    e = to_earth / np.linalg.norm(to_earth, axis=1, keepdims=True)
    p = to_sun - np.einsum("gi,gi->g", to_sun, e)[:, None] * e
    norm = np.linalg.norm(p, axis=1)
    other = np.where(np.abs(e[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    p = np.where((norm > 1e-12)[:, None], p, np.cross(e, other))
    p /= np.linalg.norm(p, axis=1, keepdims=True)
    a = np.radians(phase_deg)[:, None]
    return -np.cos(a) * e + np.sin(a) * p


def _contribute(plan: PlanView, block: BlockInputs) -> dict[str, np.ndarray]:
    to_earth = block.sources["to_earth"]
    frac = facet_fraction(plan, to_earth, block.to_observer)
    if plan.knobs["earth_model"] == "finite":
        normals = plan.terms.normal
        s = _earth_sun(to_earth, block.to_sun, block.sources["earth_phase"])
        irr = earthshine_facets(
            normals,
            to_earth,
            s,
            block.sources["earth_range"],
            plan.effect_params["earthshine"]["albedo"],
        )
        cos_i = to_earth @ normals.T / np.linalg.norm(to_earth, axis=1)[:, None]
        # the kernel multiplies by cos(theta_i) at the Earth's centre: divide it out
        share = np.divide(irr, cos_i, out=np.zeros_like(irr), where=cos_i > 0)
        frac = share if frac is None else frac * share
        r = reflected(plan, block, to_earth, frac, False)
        p = plan.effect_params["earthshine"]
        limb = limb_signal(plan, block, irr, cos_i, p["limb_tables"], "earthshine_limb")
        return {"signal_earthshine": (r.signal + limb).astype(r.signal.dtype)}
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
    reads=(
        "earth_direction",
        "to_earth",
        "earth_albedo",
        "earth_range",
        "earth_phase_angle",
        "earth_model",
    ),
    plan=_plan,
    contribute=_contribute,
    geometry=_geometry,
)
