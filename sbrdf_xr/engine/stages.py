"""The stages of :func:`sbrdf_xr.engine.plan.compile_plan`: facet terms, the spectral axis and
the material tables, thermal emission.

Pure functions of a scene; the plan module assembles their results into the frozen
:class:`~sbrdf_xr.engine.plan.Plan`.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

import numpy as np

from .. import sources
from .._names import MATERIAL, PSI
from ..anisotropy import psi_average
from ..body.imperfections import tilt_quadrature, tilted_normals
from ..errors import SceneError
from ..materials.tables import hemispherical_reflectance
from ..photometry import solar_spectrum
from .spectral import table_on

#: The scene being compiled (:class:`sbrdf_xr.engine.Scene`).
Scene = Any

#: Thermal emission below this fraction of the reflected sunlight is not computed.
THERMAL_NEGLIGIBLE = 1e-6
#: Largest number of (geometry x term) dot products evaluated at once when
#: searching for terms never lit and visible.
DROP_BLOCK = 2_000_000


def readonly(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.flags.writeable = False
    return a


def shadow_stage(
    scene: Scene, knobs: Mapping[str, Any], steps: list[tuple[str, str]]
) -> tuple[bool, dict[str, Any]]:
    """Whether the plan shadows (asked for, and the body is not convex), and how."""
    want_shadow = "shadowing" in scene.effects
    convex = bool(scene.spacecraft.is_convex) if want_shadow else None
    shadowing = want_shadow and not convex
    shadow_options: dict[str, Any] = {}
    if not want_shadow:
        steps.append(("shadowing", "skipped: not requested"))
    elif convex:
        steps.append(("shadowing", "skipped: the body is convex, no facet can shadow another"))
    else:
        shadow_options = {"method": knobs["shadow_method"]}
        if knobs["shadow_method"] == "sampled":
            shadow_options["density"] = knobs["shadow_density"]
            steps.append(
                (
                    "shadowing",
                    f"sampled self-shadowing and self-occlusion, "
                    f"{knobs['shadow_density']}**2 samples per facet (non-convex body)",
                )
            )
        else:
            steps.append(
                (
                    "shadowing",
                    "exact self-shadowing and self-occlusion by polygon clipping (non-convex body)",
                )
            )
    return shadowing, shadow_options


def facet_terms(
    scene: Scene,
    shadowing: bool,
    steps: list[tuple[str, str]],
    aniso: frozenset[str] = frozenset(),
) -> tuple[dict[str, np.ndarray], bool]:
    sc = scene.spacecraft
    may_merge = not shadowing
    merge = may_merge if scene.merge is None else bool(scene.merge)
    if merge and not may_merge:
        raise SceneError(
            "merge: facets cannot be merged while self-shadowing is on (a per-facet effect)"
        )
    f = sc.facets()
    n_fac = f.sizes["facet"]
    if merge:
        m = sc.merged(tangent_materials=aniso)
        term_of = np.asarray(m["facet_term"].values)
        first = np.full(m.sizes["term"], n_fac, dtype=np.int64)
        np.minimum.at(first, term_of, np.arange(n_fac))
        t = {
            "normal": np.asarray(m["normal"].values),
            "area": np.asarray(m["area"].values),
            "material": np.asarray(m[MATERIAL].values),
            "facet": first,
            "n_facets": np.asarray(m["n_facets"].values),
            "tangent": np.asarray(m["tangent"].values),
        }
        steps.append(
            (
                "facets",
                f"{n_fac} facets -> {m.sizes['term']} terms, merged by "
                "(normal, material): exact for flat facets, no per-facet effect is on",
            )
        )
    else:
        why = "self-shadowing is per facet" if shadowing else "merging disabled by the scene"
        t = {
            "normal": np.asarray(f["normal"].values),
            "area": np.asarray(f["area"].values),
            "material": np.asarray(f[MATERIAL].values),
            "facet": np.arange(n_fac),
            "n_facets": np.ones(n_fac, dtype=np.int64),
            "tangent": np.asarray(f["tangent"].values),
        }
        steps.append(("facets", f"{n_fac} facets evaluated one by one ({why})"))
    return t, merge


def tilted_terms(
    scene: Scene, raw: dict[str, np.ndarray], nodes: int, steps: list[tuple[str, str]]
) -> dict[str, np.ndarray]:
    """Terms replaced by their tilted copies where the scene asks for surface imperfections."""
    st = scene.surface_tilt
    sigma = np.array(
        [
            float(st.get(m, 0.0)) if isinstance(st, Mapping) else float(st)
            for m in raw["material"].tolist()
        ]
    )
    if not np.any(sigma > 0):
        steps.append(("imperfections", "none: perfect CAD facets (surface_tilt = 0)"))
        return raw
    parts: list[dict[str, np.ndarray]] = []
    for j in range(raw["area"].size):
        t, w = tilt_quadrature(sigma[j], nodes)
        part = {k: np.repeat(v[j : j + 1], w.size, axis=0) for k, v in raw.items()}
        part["normal"] = tilted_normals(raw["normal"][j : j + 1], t)[0]
        part["area"] = raw["area"][j] * w
        parts.append(part)
    out = {k: np.concatenate([p[k] for p in parts]) for k in raw}
    what = (
        f"sigma {float(st):g} deg"
        if not isinstance(st, Mapping)
        else ", ".join(f"{m} {float(v):g} deg" for m, v in st.items())
    )
    steps.append(
        (
            "imperfections",
            f"facet normals tilted by a Gaussian ({what}; paper 000 section 5), "
            f"{nodes}x{nodes} Gauss-Hermite copies per term: "
            f"{raw['area'].size} -> {out['area'].size} terms",
        )
    )
    return out


def contributing_terms(scene: Scene, normals: np.ndarray) -> np.ndarray:
    """Boolean per term: lit (by the Sun, or the Earth with earthshine) and visible for
    at least one geometry of the sweep; with thermal emission, visible is enough."""
    geo = scene.geometry
    keep = np.zeros(len(normals), dtype=bool)
    per = max(1, geo.n_geometries // max(1, geo.n_lead))
    step = max(1, DROP_BLOCK // max(1, per * len(normals)))
    thermal = "thermal" in scene.effects
    for start in range(0, geo.n_lead, step):
        b = geo.block(slice(start, start + step))
        visible = b.to_observer @ normals.T > 0
        if thermal:
            lit = True
        else:
            lit = b.to_sun @ normals.T > 0
            if b.sun_scale is not None:
                lit = lit & (b.sun_scale > 0)[:, None]
            if "earthshine" in scene.effects and b.to_earth is not None:
                lit = lit | (b.to_earth @ normals.T > 0)
        keep |= (visible & lit).any(axis=0)
        if keep.all():
            break
    return keep


def temperature(scene: Scene, material: str) -> float:
    t = scene.temperature
    return float(t.get(material, 300.0)) if isinstance(t, Mapping) else float(t)


def thermal_to_reflected(scene: Scene, wl: np.ndarray) -> float:
    """Largest ratio of blackbody radiance (emissivity 1) to the radiance of a white
    Lambertian surface in sunlight, E_sun / pi, over the scene's wavelengths."""
    e_sun = solar_spectrum(wl).values
    b = np.max([sources.planck(wl, temperature(scene, m)) for m in scene.tables], axis=0)
    return float(np.max(b / np.maximum(e_sun / np.pi, 1e-300)))


def describe_bytes(n: float) -> str:
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{n:.0f} B"


def effect_stage(
    scene: Scene,
    wl: np.ndarray,
    used: list[str],
    pre: bool,
    shadowing: bool,
    steps: list[tuple[str, str]],
) -> tuple[list[str], dict[str, Any]]:
    """The effects a scene calls for (:data:`sbrdf_xr.engine.effects.EFFECTS` names) and their
    parameters: sunlight always; shadowing, the Earth's shadow, earthshine and thermal
    emission only where asked for and not negligible.  Appends the plan's lines."""
    geo = scene.geometry
    active = ["sunlight"]
    params: dict[str, Mapping[str, Any]] = {}
    if shadowing:
        active.append("shadowing")
    if geo.sun_scale is not None:
        active.append("eclipse")
        dark = int(np.sum(geo.sun_scale <= 0))
        part = int(np.sum((geo.sun_scale > 0) & (geo.sun_scale < 1)))
        steps.append(
            (
                "eclipse",
                f"Earth shadow: {dark} geometries in umbra skipped (no sunlight), "
                f"{part} in penumbra scaled by the sunlit fraction of the solar disc",
            )
        )
    if "earthshine" in scene.effects and getattr(geo, "earth_scale", None) is not None:
        active.append("earthshine")
        es = geo.earth_scale
        params["earthshine"] = MappingProxyType({"ratio": float(np.max(es)) if es.size else 0.0})
        steps.append(
            (
                "earthshine",
                f"Lambertian Earth (albedo {scene.earth_albedo:g}) at the observation's "
                f"distance and phase at every time: irradiance {np.min(es):.3g}-{np.max(es):.3g} "
                "of the Sun's, a second distant source",
            )
        )
    elif "earthshine" in scene.effects:
        ratio = sources.earthshine_irradiance_ratio(
            scene.earth_albedo, scene.earth_range_km, scene.earth_phase_angle
        )
        active.append("earthshine")
        params["earthshine"] = MappingProxyType({"ratio": ratio})
        steps.append(
            (
                "earthshine",
                f"Lambertian Earth (albedo {scene.earth_albedo:g}, range "
                f"{scene.earth_range_km:g} km, phase {scene.earth_phase_angle:g} deg): irradiance "
                f"{ratio:.3g} of the Sun's, a second distant source",
            )
        )
    else:
        steps.append(("earthshine", "skipped: not requested"))
    if "thermal" not in scene.effects:
        steps.append(("thermal", "skipped: not requested"))
    else:
        worst = thermal_to_reflected(scene, wl)
        if worst < THERMAL_NEGLIGIBLE:
            steps.append(
                (
                    "thermal",
                    f"skipped: negligible, at most {worst:.1e} of reflected sunlight "
                    f"at {wl[0]:g}-{wl[-1]:g} nm",
                )
            )
        elif pre:
            steps.append(
                (
                    "thermal",
                    f"skipped: up to {worst:.1e} of reflected sunlight, but only band "
                    "outputs of reflected light are asked for; add the 'signal' output for "
                    "thermal_intensity",
                )
            )
        else:
            active.append("thermal")
            eps, thetas, rad = [], [], []
            for m in used:
                da = table_on(scene.tables[m], wl, None)
                th = np.asarray(da["theta_i"].values, dtype=np.float64)
                rho_da = hemispherical_reflectance(da, th, warn=False)
                rho = (
                    psi_average(rho_da.values, da[PSI].values, 1)
                    if PSI in rho_da.dims
                    else rho_da.values
                )
                eps.append(readonly(sources.kirchhoff_emissivity(rho)))
                thetas.append(readonly(th))
                rad.append(readonly(sources.planck(wl, temperature(scene, m))))
            params["thermal"] = MappingProxyType(
                {"emissivity": tuple(eps), "theta": tuple(thetas), "radiance": tuple(rad)}
            )
            steps.append(
                (
                    "thermal",
                    "epsilon(lambda, theta) B(lambda, T) per term, epsilon = 1 - rho "
                    "(Kirchhoff) from each table's hemispherical reflectance at its theta_i nodes, "
                    f"linear in the emission angle; up to {worst:.1e} of reflected sunlight",
                )
            )

    return active, params
