"""The stages of :func:`sbrdf_xr.engine.plan.compile_plan`: the effects, the facet terms and
the terms that contribute.

Pure functions of a scene; the plan module assembles their results into the frozen
:class:`~sbrdf_xr.engine.plan.Plan`.  What each effect does is read from its entry of
:data:`sbrdf_xr.engine.effects.EFFECTS`; no effect is named here.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

from .._names import MATERIAL
from ..body.imperfections import tilt_quadrature, tilted_normals
from ..errors import SceneError
from .effects import EFFECTS, PlanInputs, scene_effects

if TYPE_CHECKING:
    from .views import SceneView

__all__ = [
    "DROP_BLOCK",
    "contributing_terms",
    "describe_bytes",
    "effect_stage",
    "facet_terms",
    "tilted_terms",
]

#: Largest number of (geometry x term) dot products evaluated at once when
#: searching for terms never lit and visible.
DROP_BLOCK = 2_000_000


def effect_stage(
    inputs: PlanInputs, per_facet: bool, steps: list[tuple[str, str]]
) -> tuple[list[str], dict[str, Mapping[str, Any]]]:
    """Plan the per-facet effects (``per_facet=True``: they decide how the facets are
    evaluated, so they come before the facet terms) or the others (after the spectral
    axis): each effect's :attr:`~sbrdf_xr.engine.effects.Effect.plan` decides whether it
    runs and gives its plan line and parameters; an effect the scene could ask for and
    does not gets ``skipped: not requested``.

    Returns
    -------
    active : list of str
        The effects that run, in the order of :data:`~sbrdf_xr.engine.effects.EFFECTS`.
    params : dict
        Their parameters (read-only), by name.

    Examples
    --------
    Thermal emission at 2-4 um, asked for, is not negligible: it runs with its
    emissivity tables; earthshine, which the scene could ask for, is skipped:

    >>> import numpy as np
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.engine.effects import PlanInputs
    >>> from sbrdf_xr.engine.stages import effect_stage
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> wl = np.array([2000.0, 3000.0, 4000.0])
    >>> grey = lambertian(0.5, wl, material="grey")
    >>> x = [[1.0, 0.0, 0.0]]  # the Sun and the observer along +x
    >>> warm = Scene(box, {"grey": grey}, to_sun=x, to_observer=x, effects=("sunlight", "thermal"))
    >>> steps = []
    >>> active, params = effect_stage(PlanInputs(warm, {}, wl, ("grey",)), False, steps)
    >>> active, sorted(params)
    (['sunlight', 'thermal'], ['thermal'])
    >>> lines = dict(steps)
    >>> lines["earthshine"], lines["thermal"].split("; ")[-1]
    ('skipped: not requested', 'up to 1.8e-01 of reflected sunlight')
    """
    scene = inputs.scene
    active: list[str] = []
    params: dict[str, Mapping[str, Any]] = {}
    for e in EFFECTS.values():
        if e.per_facet != per_facet:
            continue
        if e.when == "asked" and e.name not in scene.effects:
            steps.append((e.name, "skipped: not requested"))
            continue
        d = e.plan(inputs)
        if d.line:
            steps.append((e.name, d.line))
        if d.active:
            active.append(e.name)
            if d.params:
                params[e.name] = MappingProxyType(dict(d.params))
    return active, params


def facet_terms(
    scene: SceneView,
    per_facet: Sequence[str],
    steps: list[tuple[str, str]],
    aniso: frozenset[str] = frozenset(),
) -> tuple[dict[str, np.ndarray], bool]:
    """The facet terms (normal, area, material, first facet, facet count, tangent) and
    whether the facets were merged by (normal, material); merging is the default unless
    a per-facet effect runs (``per_facet``: their titles).

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
    >>> terms, merged = facet_terms(scene, (), steps)
    >>> merged, sorted(terms), terms["area"].tolist(), terms["n_facets"].tolist()
    (True, ['area', 'facet', 'material', 'n_facets', 'normal', 'tangent'], \
[1.0, 1.0, 1.0, 1.0, 1.0, 1.0], [2, 2, 2, 2, 2, 2])
    >>> steps[0][1]
    '12 facets -> 6 terms, merged by (normal, material): exact for flat facets, no per-facet \
effect is on'
    >>> facet_terms(scene, ("self-shadowing",), [])[0]["area"].shape  # one term per facet
    (12,)
    >>> merging = Scene(box, {"grey": grey}, to_sun=x, to_observer=x, merge=True)
    >>> facet_terms(merging, ("self-shadowing",), [])
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.SceneError: merge: facets cannot be merged while self-shadowing is on \
(a per-facet effect)
    """
    sc = scene.spacecraft
    may_merge = not per_facet
    merge = may_merge if scene.merge is None else bool(scene.merge)
    if merge and not may_merge:
        raise SceneError(
            f"merge: facets cannot be merged while {' and '.join(per_facet)} is on "
            "(a per-facet effect)"
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
        why = (
            f"{' and '.join(per_facet)} is per facet"
            if per_facet
            else "merging disabled by the scene"
        )
        t = {
            "normal": np.asarray(f["normal"].values),
            "area": np.asarray(f["area"].values),
            "material": np.asarray(f[MATERIAL].values),
            "facet": np.arange(n_fac),
            "n_facets": np.ones(n_fac, dtype=np.int64),
            "tangent": np.asarray(f["tangent"].values),
        }
        steps.append(("facets", f"{n_fac} facets evaluated one by one ({why})"))
    if getattr(sc, "parts", ()):  # the group of every term: the bus or a part
        t["part"] = np.asarray(sc.sides.group)[t["facet"]]
    return t, merge


def tilted_terms(
    scene: SceneView, raw: dict[str, np.ndarray], nodes: int, steps: list[tuple[str, str]]
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
    >>> raw, _ = facet_terms(flat, (), [])
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


def contributing_terms(scene: SceneView, normals: np.ndarray) -> np.ndarray:
    """Boolean per term: lit by a source of the scene's effects and visible for at least
    one geometry of the sweep; an emitting source (``source="facets"``) needs only
    visible.

    A distant source lights a term where its direction (:meth:`BlockInputs.direction
    <sbrdf_xr.engine.effects.BlockInputs.direction>`) is above the term and its scale,
    if any, is above 0 (the Sun in the Earth's umbra lights nothing).

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
    >>> raw, _ = facet_terms(scene, (), [])
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
    lights = [e.source for e in scene_effects(scene.effects) if e.source is not None]
    emits = "facets" in lights
    for start in range(0, geo.n_lead, step):
        b = geo.block(slice(start, start + step))
        visible = b.to_observer @ normals.T > 0
        lit: np.ndarray | bool = emits
        if not emits:
            for source in lights:
                d = b.direction(source)
                if d is None:
                    continue
                # a source of angular radius rho lights facets up to 90 deg + rho from its
                # centre: its geometry may give sin(rho) per geometry as <source>_reach
                reach = b.sources.get(f"{source}_reach")
                on = d @ normals.T > (0.0 if reach is None else -reach[:, None])
                scale = b.scale(source)
                if scale is not None:
                    on = on & (scale > 0)[:, None]
                lit = lit | on
        keep |= (visible & lit).any(axis=0)
        if keep.all():
            break
    return keep


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
