"""The Earth's thermal emission reflected by the spacecraft.

The Earth is a Lambertian emitter at one brightness temperature, the scene's
``earth_temperature`` (default 255 K, its effective radiative-equilibrium temperature),
so its radiance is Planck's ``B(lambda, T_E)`` over the whole disc, day and night side
alike (paper 001 §1 counts the Earth's emission among the sources a surface scatters).
Its distance and direction are those of the ``earthshine`` effect (the scene's
``earth_range`` and ``earth_direction`` or ``to_earth``, an observation's at every
time).  Each facet receives ``E_j(lambda) = B(lambda, T_E) V_j`` with ``V_j`` the
cosine-weighted solid angle of the part of the Earth above its horizon
(:func:`sbrdf_xr.sources.earth_view_facets`, the knob ``earth_model="finite"``, default)
or ``pi sin^2(rho) cos(theta_i)`` of a distant source at the Earth's centre
(``earth_model="point"``), and reflects it with its BRDF at the direction of the
Earth's centre, as the reflected earthshine does: the output ``earth_thermal_intensity``
``sum_j A_j cos(theta_r) f_r(e, o) E_j(lambda)`` [W sr-1 nm-1].  It is exact for a
Lambertian facet.  A facet that sees only the Earth's limb, its centre below the facet's
horizon (common below a few Earth radii: at 7200 km a facet sees part of the Earth up to
152 deg from its centre), reflects ``E_j`` with its directional-hemispherical reflectance
at the emission angle, ``rho(theta_r) / pi`` (reciprocity: exact for a Lambertian facet,
the diffuse-sky approximation for a glossy one).

Like ``thermal_intensity`` it is an intensity, not a signal per unit solar irradiance,
so it does not add to ``band_signal`` (``photometry.inband.in_band`` integrates it over a
band).  It is skipped where it stays below
:data:`~sbrdf_xr.engine.effects.thermal.THERMAL_NEGLIGIBLE` of the reflected sunlight
(the visible) and when only band outputs are asked for.

>>> import trimesh
>>> from sbrdf_xr import Scene, load_spacecraft
>>> from sbrdf_xr.materials.schema import lambertian
>>> box = load_spacecraft(trimesh.creation.box(), material="grey")
>>> grey = lambertian(0.5, [8000.0, 10000.0, 12000.0], material="grey")
>>> x, y = [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]]
>>> scene = Scene(box, {"grey": grey}, to_sun=x, to_observer=y, to_earth=y,
...               effects=("sunlight", "earth_thermal"), earth_range=7000.0)
>>> plan = scene.plan()
>>> plan.effects
('sunlight', 'earth_thermal')
>>> print(dict(plan.steps)["earth_thermal"])
the finite Earth's emission at 255 K (range 7000 km): irradiance up to 75.7 of the \
Sun's on an Earth-facing facet at 8000-12000 nm, on each facet cut by its horizon, \
the BRDF at the Earth's centre
>>> visible = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
>>> print(dict(scene.with_options(materials={"grey": visible}).plan().steps)["earth_thermal"])
skipped: negligible, at most 1.2e-29 of the Sun's irradiance at 500-700 nm
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ... import geometry, sources
from ..._names import WAVELENGTH
from ...photometry import solar_spectrum
from ._limb import limb_signal, limb_tables
from .base import (
    BlockInputs,
    Decision,
    Effect,
    Output,
    PlanInputs,
    facet_fraction,
    readonly,
)
from .base import reflected as _reflected
from .thermal import THERMAL_NEGLIGIBLE

if TYPE_CHECKING:
    import xarray as xr

    from ..views import PlanView, SceneView

__all__ = ["EFFECT", "INTENSITY"]

#: The Earth's emission the facets reflect.
INTENSITY = Output(
    "earth_thermal_intensity",
    (WAVELENGTH,),
    True,
    "W sr-1 nm-1",
    "intensity of the Earth's thermal emission reflected by the facets, "
    "sum_j A_j cos(theta_r) f_r E_earth,j(lambda)",
)


def _geometry(scene: SceneView, observed: xr.Dataset | None) -> dict[str, np.ndarray]:
    if observed is not None:  # the Earth's distance at every time
        to_earth = np.ascontiguousarray(observed["to_earth"].values)
        rng = np.asarray(observed["earth_distance"].values, dtype=np.float64)
    else:
        if scene.is_grid:
            e = geometry.normalize(scene.earth_direction, "earth_direction")
            n = len(np.asarray(scene.phase_angles))
            to_earth = np.broadcast_to(e, (n, 3)).copy()
        else:
            to_earth = np.asarray(scene.to_earth)
        rng = np.full(len(to_earth), float(scene.earth_range))
    out = {"to_earth": to_earth, "earth_range": rng}
    if scene.earth_model == "finite":  # facets up to 90 deg + rho from the centre see it
        out["earth_reach"] = sources.EARTH_MEAN_RADIUS_KM / rng
    return out


def _plan(inputs: PlanInputs) -> Decision:

    scene, wl = inputs.scene, inputs.wavelength
    assert wl is not None  # planned after the spectral stage
    ranges = np.asarray(scene.geometry.sources["earth_range"], dtype=np.float64)
    nearest = float(np.min(ranges)) if ranges.size else float(scene.earth_range)
    radiance = sources.planck(wl, scene.earth_temperature)  # [W m-2 sr-1 nm-1]
    full = np.pi * (sources.EARTH_MEAN_RADIUS_KM / nearest) ** 2  # an Earth-facing facet [sr]
    e_sun = solar_spectrum(wl, solar="astm_g173_extended").values
    worst = float(np.max(full * radiance / np.maximum(e_sun, 1e-300)))
    if worst < THERMAL_NEGLIGIBLE:
        return Decision(
            False,
            f"skipped: negligible, at most {worst:.1e} of the Sun's irradiance "
            f"at {wl[0]:g}-{wl[-1]:g} nm",
        )
    if inputs.pre_integrated:
        return Decision(
            False,
            f"skipped: up to {worst:.1e} of the Sun's irradiance, but only band outputs are "
            "asked for; add the 'signal' output for earth_thermal_intensity",
        )
    finite = inputs.knobs["earth_model"] == "finite"
    where = "the observation's distance" if scene.observation is not None else "range"
    dist = "" if scene.observation is not None else f" {nearest:g} km"
    how = (
        "on each facet cut by its horizon, the BRDF at the Earth's centre"
        if finite
        else "a distant source at the Earth's centre"
    )
    return Decision(
        True,
        f"the {'finite ' if finite else ''}Earth's emission at {scene.earth_temperature:g} K "
        f"({where}{dist}): irradiance up to {worst:.3g} of the Sun's on an Earth-facing facet "
        f"at {wl[0]:g}-{wl[-1]:g} nm, {how}",
        {"radiance": readonly(radiance), "limb_tables": limb_tables(inputs)},
    )


def _contribute(plan: PlanView, block: BlockInputs) -> dict[str, np.ndarray]:
    to_earth = block.sources["to_earth"]
    rng = block.sources["earth_range"]
    frac = facet_fraction(plan, to_earth, block.to_observer)
    normals = plan.terms.normal
    cos_i = to_earth @ normals.T / np.linalg.norm(to_earth, axis=1)[:, None]
    view = np.zeros_like(cos_i)
    if plan.knobs["earth_model"] == "finite":
        view = sources.earth_view_facets(normals, to_earth, rng)
        # the kernel multiplies by cos(theta_i) at the Earth's centre: divide it out
        share = np.divide(view, cos_i, out=np.zeros_like(view), where=cos_i > 0)
    else:  # a distant source: pi sin^2(rho) times the kernel's cos(theta_i)
        solid = np.pi * (sources.EARTH_MEAN_RADIUS_KM / np.asarray(rng, dtype=np.float64)) ** 2
        share = np.broadcast_to(solid[:, None], (len(to_earth), len(normals)))
    frac = share if frac is None else frac * share
    p = plan.effect_params["earth_thermal"]
    out = _reflected(plan, block, to_earth, frac, False).signal.astype(np.float64)
    if plan.knobs["earth_model"] == "finite":
        out = out + limb_signal(plan, block, view, cos_i, p["limb_tables"], "earth_thermal_limb")
    out = out * p["radiance"]
    return {"earth_thermal_intensity": out.astype(np.dtype(plan.knobs["dtype"]))}


#: The Earth's thermal emission reflected by the facets.
EFFECT = Effect(
    "earth_thermal",
    title="the Earth's thermal emission",
    description=(
        "the Earth's thermal emission (a Lambertian disc at earth_temperature) reflected by "
        "the facets, a second source from the Earth"
    ),
    when="asked",
    source="earth",
    needs=("to_earth",),
    outputs=("earth_thermal_intensity",),
    declares=(INTENSITY,),
    reads=(
        "earth_direction",
        "to_earth",
        "earth_range",
        "earth_temperature",
        "earth_model",
    ),
    plan=_plan,
    contribute=_contribute,
    geometry=_geometry,
)
