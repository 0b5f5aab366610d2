"""Thermal emission of the facets: ``epsilon(lambda, theta_r) B(lambda, T)``.

The emission term of paper 001's signature model: each visible term emits
``A_j cos(theta_r) epsilon_j(lambda, theta_r) B(lambda, T_j)`` [W sr-1 nm-1], with the
directional emissivity ``epsilon = 1 - rho`` (Kirchhoff,
:func:`sbrdf_xr.sources.kirchhoff_emissivity`) from each table's hemispherical
reflectance at its ``theta_i`` nodes, linear in the emission angle, and Planck's
``B`` at the scene's ``temperature``.  It is skipped where it stays below
:data:`THERMAL_NEGLIGIBLE` of the reflected sunlight, and when only band outputs of
reflected light are asked for.  Its output is ``thermal_intensity``.

With ``temperature="equilibrium"`` every term has its own temperature at every
geometry, from radiative equilibrium in steady state (paper 001 Eqs. 2-4: absorbed
sunlight, earthshine and the Earth's emission equal the emission; no heat capacity, so
a facet entering the Earth's shadow is at once at its shadow temperature;
:func:`sbrdf_xr.sources.radiative_cooling` gives the time it takes):

``sides eps_IR sigma T^4 = alpha(theta_i) E_sun cos(theta_i) f_sun + alpha(theta_e) E_sun
E_es + eps_IR sigma T_E^4 V / pi``

with ``E_sun`` = :data:`SOLAR_CONSTANT`, ``f_sun`` the sunlit fraction of an
observation, ``E_es`` the finite Earth's reflected sunlight on the facet
(:func:`sbrdf_xr.sources.earthshine_facets`, when ``earthshine`` runs) and ``V`` its
view of the Earth (:func:`sbrdf_xr.sources.earth_view_facets`, when the scene has the
Earth's range: ``earth_thermal`` or the finite ``earthshine`` asked for).  The
directional solar absorptance ``alpha(theta_i) = 1 - rho(theta_i)`` is the mean over
the table's wavelengths weighted by the Sun's spectrum, the infrared emissivity
``eps_IR`` the hemispherical Kirchhoff emissivity weighted by Planck's spectrum at
:data:`EMISSIVITY_WEIGHT_K`: a table that covers only part of the Sun's or the
emission's spectrum gives the means over what it covers.  The knob ``conductance``
states the conductance model: ``none`` (each facet an insulated panel radiating from
its front, ``sides = 1``), ``two_sided`` (a thin plate radiating from both faces, its
back absorbing nothing) or ``isothermal`` (infinite conductance within a material: all
its facets, seen or not, share one temperature, ``sum_j A_j q_j = eps_IR sigma T^4
sum_j A_j``; a closed body radiating from its outer faces).  Self-shadowing does not cut
the absorbed sunlight.  The temperatures leave as ``facet_temperature`` [K] (geometry x
facet, the plan's terms: facets sharing a normal and a material are merged, facets never
seen are dropped).

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
(('sunlight', 'thermal'), ['emissivity', 'outputs', 'radiance', 'theta'])
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
from scipy import constants

from ... import sources
from ..._names import FACET, MATERIAL, PSI, WAVELENGTH
from ...errors import ValidationError
from ...geometry.anisotropy import psi_average
from ...materials.energy import hemispherical_reflectance
from ...photometry import solar_spectrum
from .base import BlockInputs, Decision, Effect, Output, PlanInputs, readonly, table_on

if TYPE_CHECKING:
    import xarray as xr

    from ..views import PlanView, SceneView

__all__ = [
    "EFFECT",
    "EMISSIVITY_WEIGHT_K",
    "INTENSITY",
    "MIN_EMISSIVITY",
    "SOLAR_CONSTANT",
    "TEMPERATURE",
    "THERMAL_NEGLIGIBLE",
    "equilibrium_properties",
    "temperature",
    "thermal_to_reflected",
]

#: Thermal emission below this fraction of the reflected sunlight is not computed.
THERMAL_NEGLIGIBLE = 1e-6
#: Total solar irradiance at 1 au [W m-2] (Kopp & Lean 2011), the sunlight a facet absorbs.
SOLAR_CONSTANT = 1361.0
#: Temperature [K] of the Planck spectrum that weights the infrared emissivity.
EMISSIVITY_WEIGHT_K = 300.0
#: The lowest infrared emissivity radiative equilibrium accepts [1].
MIN_EMISSIVITY = 1e-3

#: The light the facets emit.
INTENSITY = Output(
    "thermal_intensity",
    (WAVELENGTH,),
    True,
    "W sr-1 nm-1",
    "thermal emission intensity sum_j A_j cos(theta_r) epsilon(lambda, theta_r) B(lambda, T)",
)


#: The facet temperatures of radiative equilibrium.
TEMPERATURE = Output(
    "facet_temperature",
    (FACET,),
    False,
    "K",
    "facet temperature from radiative equilibrium (steady state, paper 001 Eqs. 2-4)",
)


def temperature(scene: SceneView, material: str, wl: np.ndarray | None = None) -> float:
    """The temperature [K] of a material: the scene's one value, or its entry in the
    scene's mapping (300 K if it has none); for ``temperature="equilibrium"`` the
    hottest the material may reach in equilibrium, a facet facing the Sun with all the
    Earth's light added (its properties from the table at ``wl`` [nm], default its own).

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
    >>> eq = Scene(box, {"grey": grey}, to_sun=x, to_observer=x, temperature="equilibrium")
    >>> round(temperature(eq, "grey"), 1)  # grey: T^4 = (1.3 S + eps sigma 255^4) / (eps sigma)
    433.9
    """
    t = scene.temperature
    if isinstance(t, Mapping):
        return float(t.get(material, 300.0))
    if t != "equilibrium":
        return float(t)
    _, alpha, eps = equilibrium_properties(scene.tables[material], wl)
    q = float(np.max(alpha)) * SOLAR_CONSTANT * (1.0 + scene.earth_albedo)
    q += eps * constants.sigma * scene.earth_temperature**4
    return float(sources.equilibrium_temperature(q, eps))


def equilibrium_properties(
    table: xr.DataArray, wl: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, float]:
    """A table's incidence angles [degree], its directional solar absorptance there [1]
    and its hemispherical infrared emissivity [1], for radiative equilibrium.

    ``alpha(theta_i) = 1 - rho(theta_i)`` averaged over the wavelengths ``wl`` [nm]
    (default the table's own) weighted by the Sun's spectrum (``astm_g173_extended``);
    ``eps_IR`` the hemispherical mean ``int eps(theta) sin(2 theta) dtheta`` of the
    Kirchhoff emissivity ``1 - rho`` averaged weighted by Planck's spectrum at
    :data:`EMISSIVITY_WEIGHT_K` (trapezoids over the wavelengths).

    Examples
    --------
    A grey Lambertian table absorbs and emits ``1 - albedo`` at every angle:

    >>> from sbrdf_xr.engine.effects.thermal import equilibrium_properties
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> th, alpha, eps = equilibrium_properties(lambertian(0.3, [500.0, 1000.0, 10_000.0]))
    >>> alpha.round(6).tolist() == [0.7] * len(th), round(eps, 6)
    (True, 0.7)
    """
    wl = np.asarray(table["wavelength"].values if wl is None else wl, dtype=np.float64)
    da = table_on(table, wl, None)
    th = np.asarray(da["theta_i"].values, dtype=np.float64)
    rho_da = hemispherical_reflectance(da, th, warn=False)
    rho = psi_average(rho_da.values, da[PSI].values, 1) if PSI in rho_da.dims else rho_da.values
    eps = sources.kirchhoff_emissivity(rho)  # (theta, wavelength)

    trap = np.ones(1) if wl.size == 1 else np.zeros(wl.size)
    if wl.size > 1:  # trapezoid weights
        trap[:-1] += np.diff(wl) / 2
        trap[1:] += np.diff(wl) / 2

    def weights(spectrum: np.ndarray) -> np.ndarray:
        w = spectrum * trap
        return w / w.sum() if w.sum() > 0 else np.full(wl.size, 1.0 / wl.size)

    alpha = eps @ weights(solar_spectrum(wl, solar="astm_g173_extended").values)
    grid = np.linspace(0.0, 90.0, 181)  # the hemispherical mean, 0.5 deg trapezoids
    shape = np.sin(2.0 * np.radians(grid))
    eps_h = np.trapezoid(sources.emissivity_at(eps, th, grid) * shape[:, None], grid, axis=0)
    eps_h /= np.trapezoid(shape, grid)
    eps_ir = float(eps_h @ weights(sources.planck(wl, EMISSIVITY_WEIGHT_K)))
    if not eps_ir >= MIN_EMISSIVITY:
        raise ValidationError(
            f"material {table.attrs.get('material', '')!r}: infrared emissivity {eps_ir:.3g} at "
            f"{wl[0]:g}-{wl[-1]:g} nm; radiative equilibrium needs one of at least "
            f"{MIN_EMISSIVITY:g} (below it a facet in sunlight passes 2000 K)"
        )
    return th, alpha, eps_ir


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
    b = np.max([sources.planck(wl, temperature(scene, m, wl)) for m in scene.material_data], axis=0)
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
        rad.append(readonly(sources.planck(wl, temperature(scene, m, wl))))
    params: dict[str, object] = {
        "emissivity": tuple(eps),
        "theta": tuple(thetas),
        "radiance": tuple(rad),
    }
    line = (
        "epsilon(lambda, theta) B(lambda, T) per term, epsilon = 1 - rho "
        "(Kirchhoff) from each table's hemispherical reflectance at its theta_i nodes, "
        f"linear in the emission angle; up to {worst:.1e} of reflected sunlight"
    )
    if scene.temperature == "equilibrium":
        props = [equilibrium_properties(scene.tables[m], wl) for m in inputs.materials]
        conductance = inputs.knobs["conductance"]
        sides = {"none": 1, "two_sided": 2, "isothermal": 1}[conductance]
        if conductance == "isothermal":  # every term of a material, seen or not
            params["isothermal"] = _isothermal_terms(scene, inputs.materials)
        params.update(
            absorptance=tuple((readonly(th), readonly(a)) for th, a, _ in props),
            emissivity_ir=tuple(e for _, _, e in props),
            sides=sides,
            earth_temperature=scene.earth_temperature,
            earthshine="earthshine" in scene.effects,
            outputs=("thermal_intensity", "facet_temperature"),
        )
        given = ", ".join(
            f"{m} {e:.3g}" for m, (_, _, e) in zip(inputs.materials, props, strict=True)
        )
        how = (
            "one temperature per material: its absorbed power equals its emission over "
            "all its facets"
            if conductance == "isothermal"
            else f"{sides} radiating face{'s' * (sides > 1)}"
        )
        line += (
            f"; facet temperatures from radiative equilibrium, steady state (conductance "
            f"{conductance}: {how}), infrared emissivity {given}"
        )
    else:
        params["outputs"] = ("thermal_intensity",)
    return Decision(True, line, params)


def _isothermal_terms(
    scene: SceneView, materials: tuple[str, ...]
) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
    """Per material, the normals (N_m, 3) and areas (N_m,) [m2] of all its facets, merged
    by normal, including those the plan drops (never seen): they absorb and emit too."""
    merged = scene.spacecraft.merged()
    names = np.asarray(merged[MATERIAL].values).astype(str)
    normal = np.asarray(merged["normal"].values, dtype=np.float64)
    area = np.asarray(merged["area"].values, dtype=np.float64)
    return tuple((readonly(normal[names == m]), readonly(area[names == m])) for m in materials)


def _absorbed(plan: PlanView, block: BlockInputs, m: int, normals: np.ndarray) -> np.ndarray:
    """Absorbed power per unit area (G, T_m) [W m-2] of material ``m``'s terms: sunlight,
    the finite Earth's reflected sunlight and its emission (paper 001 Eqs. 2-4)."""
    p = plan.effect_params["thermal"]
    th, alpha = p["absorptance"][m]

    def absorptance(cos: np.ndarray) -> np.ndarray:
        ang = np.degrees(np.arctan2(np.sqrt(np.clip(1 - cos**2, 0, None)), cos))
        return np.interp(np.clip(ang, 0.0, 90.0), th, alpha)

    cos_s = block.to_sun @ normals.T
    q = SOLAR_CONSTANT * absorptance(cos_s) * np.maximum(cos_s, 0.0)
    if block.sun_scale is not None:  # the Earth's shadow
        q *= block.sun_scale[:, None]
    src = block.sources
    if "to_earth" not in src:
        return q
    e = src["to_earth"]
    if p["earthshine"] and "earth_scale" in src:  # the point-source Earth of an observation
        q += (
            SOLAR_CONSTANT
            * absorptance(e @ normals.T)
            * src["earth_scale"][:, None]
            * np.maximum(e @ normals.T, 0.0)
        )
    if "earth_range" not in src:
        return q
    rng = src["earth_range"]
    view = sources.earth_view_facets(normals, e, rng)  # [sr]
    q += p["emissivity_ir"][m] * constants.sigma * p["earth_temperature"] ** 4 * view / np.pi
    if p["earthshine"] and "earth_phase" in src:
        from .earthshine import _earth_sun

        s_e = _earth_sun(e, block.to_sun, src["earth_phase"])
        albedo = plan.effect_params["earthshine"]["albedo"]
        ratio = sources.earthshine_facets(normals, e, s_e, rng, albedo)
        q += SOLAR_CONSTANT * absorptance(e @ normals.T) * ratio
    return q


def _contribute(plan: PlanView, block: BlockInputs) -> dict[str, np.ndarray]:
    """``sum_j A_j cos(theta_r) epsilon_j(lambda, theta_r) B(lambda, T_j)`` over the visible
    terms [W sr-1 nm-1] (the emission term of paper 001's signature model)."""
    t = plan.terms
    p = plan.effect_params["thermal"]
    o = block.to_observer
    out = np.zeros((o.shape[0], plan.wavelength.size))
    equilibrium = "sides" in p
    temps = np.zeros((o.shape[0], t.normal.shape[0])) if equilibrium else None
    for m in range(len(plan.materials)):
        sel = t.material == m
        cos_r = o @ t.normal[sel].T  # (G, T_m)
        vis = cos_r > 0
        theta_r = np.degrees(np.arctan2(np.sqrt(np.clip(1 - cos_r**2, 0, None)), cos_r))
        eps = sources.emissivity_at(p["emissivity"][m], p["theta"][m], np.where(vis, theta_r, 0.0))
        w = np.where(vis, cos_r, 0.0) * t.area[sel]
        if temps is None:
            out += np.einsum("gf,gfl->gl", w, eps) * p["radiance"][m]
            continue
        if "isothermal" in p:  # sum_j A_j q_j = eps sigma T^4 sum_j A_j over the material
            normal, area = p["isothermal"][m]
            q = (_absorbed(plan, block, m, normal) @ area / np.sum(area))[:, None]
        else:
            q = _absorbed(plan, block, m, t.normal[sel])
        q = np.broadcast_to(q, cos_r.shape)
        temps[:, sel] = (q / (p["sides"] * p["emissivity_ir"][m] * constants.sigma)) ** 0.25
        radiance = sources.planck(plan.wavelength, temps[:, sel])  # (G, T_m, L)
        out += np.einsum("gf,gfl,gfl->gl", w, eps, radiance)
    result = {"thermal_intensity": out.astype(np.dtype(plan.knobs["dtype"]))}
    if temps is not None:
        result["facet_temperature"] = temps
    return result


#: Thermal emission of the facets.
EFFECT = Effect(
    "thermal",
    title="thermal emission",
    description=(
        "thermal emission epsilon(lambda, theta) B(lambda, T), epsilon = 1 - rho (Kirchhoff)"
    ),
    when="asked",
    source="facets",
    outputs=("thermal_intensity", "facet_temperature"),
    declares=(INTENSITY, TEMPERATURE),
    reads=("temperature", "conductance", "earth_temperature"),
    plan=_plan,
    contribute=_contribute,
)
