"""Thermal emission of the facets: ``epsilon(lambda, theta_r) B(lambda, T)``.

The emission term of paper 001's signature model: each visible term emits
``A_j cos(theta_r) epsilon_j(lambda, theta_r) B(lambda, T_j)`` [W sr-1 nm-1], with the
directional emissivity ``epsilon = 1 - rho`` (Kirchhoff,
:func:`sbrdf_xr.sources.kirchhoff_emissivity`) from each table's hemispherical
reflectance at its ``theta_i`` nodes, linear in the emission angle, and Planck's
``B`` at the scene's ``temperature``.  It is skipped where it stays below
:data:`THERMAL_NEGLIGIBLE` of the reflected sunlight, and when only band outputs of
reflected light are asked for.  Its output is ``thermal_intensity``.

>>> import numpy as np
>>> import trimesh
>>> from sbrdf_xr import Scene, load_spacecraft
>>> from sbrdf_xr.materials.schema import lambertian
>>> box = load_spacecraft(trimesh.creation.box(), material="grey")
>>> grey = lambertian(0.5, [2000.0, 3000.0, 4000.0], material="grey")
>>> x = [[1.0, 0.0, 0.0]]  # the Sun and the observer along +x
>>> warm = Scene(box, {"grey": grey}, to_sun=x, to_observer=x, effects=("sunlight", "thermal"))
>>> plan = warm.plan()
>>> plan.effects, sorted(plan.effect_params["thermal"])
(('sunlight', 'thermal'), ['emissivity', 'radiance', 'theta'])
>>> eps = plan.effect_params["thermal"]["emissivity"][0]  # 1 - albedo, at theta_i 0 and 90
>>> eps.tolist()
[[0.5, 0.5, 0.5], [0.5, 0.5, 0.5]]
>>> print(dict(plan.steps)["thermal"].split("; ")[-1])
up to 1.8e-01 of reflected sunlight
>>> band_only = warm.with_options(outputs=("band_signal",), bands=("I",),
...                               band_extrapolate="constant").plan()
>>> band_only.effects, dict(band_only.steps)["thermal"].split(",")[0]
(('sunlight',), 'skipped: up to 1.8e-01 of reflected sunlight')
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from ... import sources
from ..._names import PSI, WAVELENGTH
from ...geometry.anisotropy import psi_average
from ...materials.energy import hemispherical_reflectance
from ...photometry import solar_spectrum
from .base import BlockInputs, Decision, Effect, Output, PlanInputs, readonly, table_on

if TYPE_CHECKING:
    from ..views import PlanView, SceneView

__all__ = ["EFFECT", "INTENSITY", "THERMAL_NEGLIGIBLE", "temperature", "thermal_to_reflected"]

#: Thermal emission below this fraction of the reflected sunlight is not computed.
THERMAL_NEGLIGIBLE = 1e-6

#: The light the facets emit.
INTENSITY = Output(
    "thermal_intensity",
    (WAVELENGTH,),
    True,
    "W sr-1 nm-1",
    "thermal emission intensity sum_j A_j cos(theta_r) epsilon(lambda, theta_r) B(lambda, T)",
)


def temperature(scene: SceneView, material: str) -> float:
    """The temperature [K] of a material: the scene's one value, or its entry in the
    scene's mapping (300 K if it has none).

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> from sbrdf_xr.engine.effects.thermal import temperature
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> x = [[1.0, 0.0, 0.0]]  # the Sun and the observer along +x
    >>> temperature(Scene(box, {"grey": grey}, to_sun=x, to_observer=x), "grey")
    300.0
    >>> hot = Scene(box, {"grey": grey}, to_sun=x, to_observer=x, temperature={"grey": 350.0})
    >>> temperature(hot, "grey"), temperature(hot, "paint")
    (350.0, 300.0)
    """
    t = scene.temperature
    return float(t.get(material, 300.0)) if isinstance(t, Mapping) else float(t)


def thermal_to_reflected(scene: SceneView, wl: np.ndarray) -> float:
    """Largest ratio of blackbody radiance (emissivity 1) to the radiance of a white
    Lambertian surface in sunlight, E_sun / pi, over the scene's wavelengths.

    Examples
    --------
    At 300 K the emission is negligible in the visible but not at 2-4 um; at 600 K it
    outshines the reflected sunlight there:

    >>> import numpy as np
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> from sbrdf_xr.engine.effects.thermal import THERMAL_NEGLIGIBLE, thermal_to_reflected
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> x = [[1.0, 0.0, 0.0]]  # the Sun and the observer along +x
    >>> scene = Scene(box, {"grey": grey}, to_sun=x, to_observer=x)
    >>> visible, infrared = np.array([500.0, 600.0, 700.0]), np.array([2000.0, 4000.0])
    >>> ratio = thermal_to_reflected(scene, visible)
    >>> f"{ratio:.1e}", ratio < THERMAL_NEGLIGIBLE
    ('2.6e-24', True)
    >>> round(thermal_to_reflected(scene, infrared), 3)
    0.106
    >>> hot = Scene(box, {"grey": grey}, to_sun=x, to_observer=x, temperature=600.0)
    >>> round(thermal_to_reflected(hot, infrared), 1)
    42.7
    """
    e_sun = solar_spectrum(wl, solar="astm_g173_extended").values  # 119.5 nm - 1 mm
    b = np.max([sources.planck(wl, temperature(scene, m)) for m in scene.material_data], axis=0)
    return float(np.max(b / np.maximum(e_sun / np.pi, 1e-300)))


def _plan(inputs: PlanInputs) -> Decision:
    scene, wl = inputs.scene, inputs.wavelength
    assert wl is not None  # planned after the spectral stage
    worst = thermal_to_reflected(scene, wl)
    if worst < THERMAL_NEGLIGIBLE:
        return Decision(
            False,
            f"skipped: negligible, at most {worst:.1e} of reflected sunlight "
            f"at {wl[0]:g}-{wl[-1]:g} nm",
        )
    if inputs.pre_integrated:
        return Decision(
            False,
            f"skipped: up to {worst:.1e} of reflected sunlight, but only band outputs of "
            "reflected light are asked for; add the 'signal' output for thermal_intensity",
        )
    eps, thetas, rad = [], [], []
    for m in inputs.materials:
        da = table_on(scene.tables[m], wl, None)
        th = np.asarray(da["theta_i"].values, dtype=np.float64)
        rho_da = hemispherical_reflectance(da, th, warn=False)
        rho = psi_average(rho_da.values, da[PSI].values, 1) if PSI in rho_da.dims else rho_da.values
        eps.append(readonly(sources.kirchhoff_emissivity(rho)))
        thetas.append(readonly(th))
        rad.append(readonly(sources.planck(wl, temperature(scene, m))))
    return Decision(
        True,
        "epsilon(lambda, theta) B(lambda, T) per term, epsilon = 1 - rho "
        "(Kirchhoff) from each table's hemispherical reflectance at its theta_i nodes, "
        f"linear in the emission angle; up to {worst:.1e} of reflected sunlight",
        {"emissivity": tuple(eps), "theta": tuple(thetas), "radiance": tuple(rad)},
    )


def _contribute(plan: PlanView, block: BlockInputs) -> dict[str, np.ndarray]:
    """``sum_j A_j cos(theta_r) epsilon_j(lambda, theta_r) B(lambda, T_j)`` over the visible
    terms [W sr-1 nm-1] (the emission term of paper 001's signature model)."""
    t = plan.terms
    p = plan.effect_params["thermal"]
    o = block.to_observer
    out = np.zeros((o.shape[0], plan.wavelength.size))
    for m in range(len(plan.materials)):
        sel = t.material == m
        cos_r = o @ t.normal[sel].T  # (G, T_m)
        vis = cos_r > 0
        theta_r = np.degrees(np.arctan2(np.sqrt(np.clip(1 - cos_r**2, 0, None)), cos_r))
        eps = sources.emissivity_at(p["emissivity"][m], p["theta"][m], np.where(vis, theta_r, 0.0))
        w = np.where(vis, cos_r, 0.0) * t.area[sel]
        out += np.einsum("gf,gfl->gl", w, eps) * p["radiance"][m]
    return {"thermal_intensity": out.astype(np.dtype(plan.knobs["dtype"]))}


#: Thermal emission of the facets.
EFFECT = Effect(
    "thermal",
    title="thermal emission",
    description=(
        "thermal emission epsilon(lambda, theta) B(lambda, T), epsilon = 1 - rho (Kirchhoff)"
    ),
    when="asked",
    source="facets",
    outputs=("thermal_intensity",),
    declares=(INTENSITY,),
    reads=("temperature",),
    plan=_plan,
    contribute=_contribute,
)
