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
from ..materials.energy import hemispherical_reflectance
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
    """A C-contiguous, read-only copy (or view) of ``a``, for the frozen plan.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.engine.stages import readonly
    >>> every_other = np.arange(6).reshape(2, 3)[:, ::2]
    >>> r = readonly(every_other)
    >>> r.tolist(), r.flags.c_contiguous, r.flags.writeable
    ([[0, 2], [3, 5]], True, False)
    >>> r[0, 0] = 1
    Traceback (most recent call last):
    ...
    ValueError: assignment destination is read-only
    """
    a = np.ascontiguousarray(a)
    a.flags.writeable = False
    return a


def shadow_stage(
    scene: Scene, knobs: Mapping[str, Any], steps: list[tuple[str, str]]
) -> tuple[bool, dict[str, Any]]:
    """Whether the plan shadows (asked for, and the body is not convex), and how.

    Examples
    --------
    >>> from sbrdf_xr import Scene
    >>> from sbrdf_xr.engine.stages import shadow_stage
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> from sbrdf_xr.testing import cube_spacecraft, l_shaped_spacecraft
    >>> paint = {"white-paint-a276": lambertian(0.8, [500.0, 600.0], material="white-paint-a276")}
    >>> x = [[1.0, 0.0, 0.0]]  # the Sun and the observer along +x
    >>> def shadows(body):
    ...     scene = Scene(body, paint, to_sun=x, to_observer=x, effects=("sunlight", "shadowing"))
    ...     steps = []
    ...     knobs = {k: getattr(scene, k) for k in scene.knob_names()}
    ...     return shadow_stage(scene, knobs, steps), steps[0][1]
    >>> shadows(cube_spacecraft())
    ((False, {}), 'skipped: the body is convex, no facet can shadow another')
    >>> shadows(l_shaped_spacecraft())
    ((True, {'method': 'exact'}), 'exact self-shadowing and self-occlusion by polygon clipping \
(non-convex body)')
    """
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
    """The facet terms (normal, area, material, first facet, facet count, tangent) and
    whether the facets were merged by (normal, material); merging is the default unless
    the plan shadows.

    Examples
    --------
    The twelve triangles of a box merge into its six faces, two facets each:

    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> from sbrdf_xr.engine.stages import facet_terms
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> x = [[1.0, 0.0, 0.0]]  # the Sun and the observer along +x
    >>> scene = Scene(box, {"grey": grey}, to_sun=x, to_observer=x)
    >>> steps = []
    >>> terms, merged = facet_terms(scene, False, steps)
    >>> merged, sorted(terms), terms["area"].tolist(), terms["n_facets"].tolist()
    (True, ['area', 'facet', 'material', 'n_facets', 'normal', 'tangent'], \
[1.0, 1.0, 1.0, 1.0, 1.0, 1.0], [2, 2, 2, 2, 2, 2])
    >>> steps[0][1]
    '12 facets -> 6 terms, merged by (normal, material): exact for flat facets, no per-facet \
effect is on'
    >>> facet_terms(scene, True, [])[0]["area"].shape  # shadowing: one term per facet
    (12,)
    >>> merging = Scene(box, {"grey": grey}, to_sun=x, to_observer=x, merge=True)
    >>> facet_terms(merging, True, [])
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.SceneError: merge: facets cannot be merged while self-shadowing is on \
(a per-facet effect)
    """
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
    """Terms replaced by their tilted copies where the scene asks for surface imperfections.

    Examples
    --------
    With 3 x 3 quadrature nodes each face of a box becomes nine tilted unit-normal copies
    whose areas add up to the face's:

    >>> import numpy as np
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> from sbrdf_xr.engine.stages import facet_terms, tilted_terms
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> x = [[1.0, 0.0, 0.0]]  # the Sun and the observer along +x
    >>> flat = Scene(box, {"grey": grey}, to_sun=x, to_observer=x)
    >>> raw, _ = facet_terms(flat, False, [])
    >>> tilted_terms(flat, raw, 3, []) is raw  # no tilt: the terms as they were
    True
    >>> rough = Scene(box, {"grey": grey}, to_sun=x, to_observer=x, surface_tilt=5.0)
    >>> steps = []
    >>> out = tilted_terms(rough, raw, 3, steps)
    >>> out["area"].shape, out["area"].reshape(6, 9).sum(axis=1).round(12).tolist()
    ((54,), [1.0, 1.0, 1.0, 1.0, 1.0, 1.0])
    >>> bool(np.allclose(np.linalg.norm(out["normal"], axis=1), 1.0))
    True
    >>> print(steps[0][1].split(": ")[-1])
    6 -> 54 terms
    """
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
    at least one geometry of the sweep; with thermal emission, visible is enough.

    Examples
    --------
    With the Sun along +x and the observer along +y no face of a box is both lit and
    seen; with thermal emission the face seen (+y) contributes:

    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> from sbrdf_xr.engine.stages import contributing_terms, facet_terms
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> x = [[1.0, 0.0, 0.0]]  # the Sun and the observer along +x
    >>> y = [[0.0, 1.0, 0.0]]
    >>> scene = Scene(box, {"grey": grey}, to_sun=x, to_observer=y)
    >>> raw, _ = facet_terms(scene, False, [])
    >>> raw["normal"].tolist()
    [[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0], \
[1.0, 0.0, 0.0]]
    >>> contributing_terms(scene, raw["normal"]).tolist()
    [False, False, False, False, False, False]
    >>> warm = Scene(box, {"grey": grey}, to_sun=x, to_observer=y, effects=("sunlight", "thermal"))
    >>> contributing_terms(warm, raw["normal"]).tolist()
    [False, False, False, False, True, False]
    >>> facing = Scene(box, {"grey": grey}, to_sun=x, to_observer=x)
    >>> contributing_terms(facing, raw["normal"]).tolist()  # only +x faces both
    [False, False, False, False, False, True]
    """
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
    """The temperature [K] of a material: the scene's one value, or its entry in the
    scene's mapping (300 K if it has none).

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> from sbrdf_xr.engine.stages import temperature
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


def thermal_to_reflected(scene: Scene, wl: np.ndarray) -> float:
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
    >>> from sbrdf_xr.engine.stages import THERMAL_NEGLIGIBLE, thermal_to_reflected
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
    e_sun = solar_spectrum(wl).values
    b = np.max([sources.planck(wl, temperature(scene, m)) for m in scene.tables], axis=0)
    return float(np.max(b / np.maximum(e_sun / np.pi, 1e-300)))


def describe_bytes(n: float) -> str:
    """A byte count in decimal units (B, kB, MB, GB, TB), three significant digits.

    Examples
    --------
    >>> from sbrdf_xr.engine.stages import describe_bytes
    >>> [describe_bytes(n) for n in (999, 1000, 1_234_567, 2.5e9, 3e13)]
    ['999 B', '1 kB', '1.23 MB', '2.5 GB', '30 TB']
    """
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
    emission only where asked for and not negligible.  Appends the plan's lines.

    Examples
    --------
    Thermal emission at 2-4 um: its emissivity is ``1 - rho`` (Kirchhoff), 0.5 for
    a Lambertian of albedo 0.5; it is skipped when only bands of reflected light are
    computed (``pre=True``):

    >>> import numpy as np
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> from sbrdf_xr.engine.stages import effect_stage
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> wl = np.array([2000.0, 3000.0, 4000.0])
    >>> grey = lambertian(0.5, wl, material="grey")
    >>> x = [[1.0, 0.0, 0.0]]  # the Sun and the observer along +x
    >>> warm = Scene(box, {"grey": grey}, to_sun=x, to_observer=x, effects=("sunlight", "thermal"))
    >>> steps = []
    >>> active, params = effect_stage(warm, wl, ["grey"], False, False, steps)
    >>> active, sorted(params["thermal"])
    (['sunlight', 'thermal'], ['emissivity', 'radiance', 'theta'])
    >>> params["thermal"]["emissivity"][0].tolist(), params["thermal"]["theta"][0].tolist()
    ([[0.5, 0.5, 0.5], [0.5, 0.5, 0.5]], [0.0, 90.0])
    >>> effect_stage(warm, wl, ["grey"], True, False, [])
    (['sunlight'], {})
    >>> for name, line in steps:
    ...     print(f"{name}: {line.split('; ')[-1]}")
    earthshine: skipped: not requested
    thermal: up to 1.8e-01 of reflected sunlight
    """
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
