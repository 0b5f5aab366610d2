"""The plan: a scene compiled into exactly what will be computed, and why.

:meth:`Plan.from_scene` (what :meth:`sbrdf_xr.engine.Scene.plan` returns) resolves
everything a simulation needs, once: the facet terms (merged by (normal, material)
when no per-facet effect is on, dropped when never lit and seen), the wavelength
grid or the bands, the material tables on that grid (pre-integrated over the bands
for band-only scenes), the effects with their sources and parameters, the value of
every knob (:mod:`sbrdf_xr.engine.knobs`), the outputs with their dimensions, shapes and
attributes, the block layout, and an estimate of memory and work.  The plan is
immutable data: tests assert on its fields; ``print(plan)`` renders its ``steps``
for people.  :mod:`sbrdf_xr.engine.run` executes a plan and derives nothing.

Principle (DESIGN.md 3): simulate only the effects a scene calls for.  Convex bodies
skip shadowing; band-only outputs pre-integrate each table against filter x Sun
(exact for nearest and linear look-up, because the facet sum is linear in f_r);
facets sharing (normal, material) are merged; facets never lit and seen are dropped;
thermal emission is skipped where it is negligible.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr

from .._names import BAND, FACET, MATERIAL, PSI, WAVELENGTH, __version__
from ..errors import SceneError
from ..kernels import PackedTables
from ..kernels.anisotropic import AnisotropicTable
from ..materials.mapped import restore, share
from ..materials.models import model_parameters
from ..store.fingerprint import PREFIX
from .articulation import Articulation, describe_parts, group_terms
from .effects import EFFECTS, OUTPUTS, SCENE_OUTPUTS, BlockInputs, Effect, PlanInputs, readonly
from .fingerprint import scene_fingerprint
from .reuse import FACETS, digest
from .spectral import spectral_stage
from .stages import contributing_terms, describe_bytes, effect_stage, facet_terms, tilted_terms
from .views import Terms

if TYPE_CHECKING:
    from ..body.spacecraft import Spacecraft
    from .sweep import GridGeometry, PairGeometry
    from .views import SceneView

__all__ = ["BlockInputs", "Estimate", "Plan", "PlannedOutput", "Terms", "compile_plan"]

#: Default blocks: at least this many per core (load balance), of at least MIN_CHUNK
#: geometries (task overhead), within the knob block_bytes (memory).
BLOCKS_PER_CORE = 4
MIN_CHUNK = 1024
#: Plans whose outputs would exceed this many bytes are refused (override with the
#: scene field ``size_limit``).
SIZE_LIMIT_BYTES = 2 * 2**40
#: Plans estimated to need more than this many (geometry x term x node x wavelength)
#: multiply-adds are refused (about a week on one core at 1e9 per second).
WORK_LIMIT = 6e14


@dataclass(frozen=True)
class PlannedOutput:
    """An output variable: its name, dimensions, shape, dtype and CF attributes.

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, geometry, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> turns = geometry.axis_rotation([0, 0, 1], [0.0, 45.0])  # two attitudes about z
    >>> scene = Scene(box, {"grey": grey}, attitudes=turns, phase_angles=[0.0, 60.0])
    >>> out = scene.plan().outputs[1]
    >>> out.name, out.dims, out.shape
    ('signal', ('attitude', 'phase_angle', 'wavelength'), (2, 2, 3))
    >>> out.dtype, out.nbytes, out.attrs["units"]
    (dtype('float64'), 96, 'm2 sr-1')
    """

    name: str
    dims: tuple[str, ...]
    shape: tuple[int, ...]
    dtype: np.dtype
    attrs: Mapping[str, str]

    @property
    def nbytes(self) -> int:
        """Size of the whole variable [byte]."""
        return math.prod(self.shape) * self.dtype.itemsize


@dataclass(frozen=True)
class Estimate:
    """What a plan will cost.

    Attributes
    ----------
    n_geometries, n_terms : int
        Geometries of the sweep and terms per geometry.
    output_bytes : int
        Size of every output together [byte].
    block_bytes : int
        Size of one block's outputs [byte] (about the peak memory per block in flight).
    multiply_adds : float
        Upper bound of the spectral multiply-adds (every term lit and seen).

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, geometry, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> turns = geometry.axis_rotation([0, 0, 1], [0.0, 45.0])  # two attitudes about z
    >>> scene = Scene(box, {"grey": grey}, attitudes=turns, phase_angles=[0.0, 60.0])
    >>> est = scene.plan().estimate
    >>> est.n_geometries, est.n_terms, est.output_bytes
    (4, 2, 256)
    """

    n_geometries: int
    n_terms: int
    output_bytes: int
    block_bytes: int
    multiply_adds: float


@dataclass(frozen=True, eq=False)
class Plan:
    """A compiled scene: everything a simulation computes (see the module docstring).

    Build with :meth:`from_scene` (or :meth:`sbrdf_xr.engine.Scene.plan`).  Fields are
    read-only; arrays are not writeable.  ``effects`` names the effects that run
    (:data:`sbrdf_xr.engine.effects.EFFECTS`), ``effect_params`` holds their parameters,
    and ``plan.<effect>`` (``plan.shadowing``, ``plan.thermal``, ...) says whether one runs.

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, geometry, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> turns = geometry.axis_rotation([0, 0, 1], [0.0, 45.0])  # two attitudes about z
    >>> scene = Scene(box, {"grey": grey}, attitudes=turns, phase_angles=[0.0, 60.0])
    >>> plan = scene.plan()
    >>> plan.n_blocks, plan.output_names
    (1, ('spacecraft_sbrdf', 'signal', 'brdf', 'area'))
    >>> plan.knobs["method"], plan.materials, plan.wavelength.tolist()
    ('linear', ('grey',), [500.0, 600.0, 700.0])
    >>> plan.merged, plan.shadowing, plan.effects
    (True, False, ('sunlight',))
    >>> plan.active_effects[0].description
    'reflected sunlight: paper 000 Eqs. 3-4 and the radiometric signal'
    >>> print(plan)  # doctest: +ELLIPSIS
    plan for scene 'scene':
      geometry       2 attitudes x 2 phase angles = 4 geometries
      shadowing      skipped: not requested
    ...
      outputs        spacecraft_sbrdf, signal, brdf, area
    ...

    A chunk of one attitude gives two blocks:

    >>> chunked = scene.with_options(chunk=1).plan()
    >>> chunked.n_blocks, chunked.block_slice(1)
    (2, slice(1, 2, None))
    """

    name: str
    description: str
    spacecraft: Spacecraft
    geometry: GridGeometry | PairGeometry
    terms: Terms
    materials: tuple[str, ...]
    tables: PackedTables
    wavelength: np.ndarray
    bands: tuple[str, ...]
    band_weights: np.ndarray | None
    band_coords: Mapping[str, Any]
    pre_integrated: bool
    merged: bool
    effects: tuple[str, ...]
    effect_params: Mapping[str, Mapping[str, Any]]
    models: Mapping[int, tuple[Any, Mapping[str, Any]]]
    knobs: Mapping[str, Any]
    outputs: tuple[PlannedOutput, ...]
    chunk: int
    estimate: Estimate
    steps: tuple[tuple[str, str], ...]
    attrs: Mapping[str, Any] = field(default_factory=dict)
    #: Anisotropic tables by material index (:func:`sbrdf_xr.kernels.anisotropic.pack_anisotropic`).
    anisotropic: Mapping[int, AnisotropicTable] = field(default_factory=dict)
    #: The parts and the terms of each group of a body with parts
    #: (:class:`~sbrdf_xr.engine.articulation.Articulation`), or one group bound to a
    #: block (:class:`~sbrdf_xr.engine.articulation.BoundGroup`); None for a rigid body.
    articulation: Any = None
    #: Products of the plan made on first use (the cube's coordinate template).
    cache: dict[str, Any] = field(default_factory=dict, init=False, repr=False, compare=False)

    # ----------------------------------------------------------- pickling
    def __getstate__(self) -> dict[str, Any]:
        """The plan as it travels to a Dask worker: each table that views a memory-mapped
        values file of the table cache as a handle to it (the file, its digest and which
        bytes: :func:`sbrdf_xr.materials.mapped.share`), not its values; the cache of
        products made on first use left behind."""
        state = dict(self.__dict__)
        state["tables"] = self.tables._replace(values=tuple(map(share, self.tables.values)))
        state["cache"] = {}
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        """A pickled plan restored: its mapped tables mapped in this process (once per file),
        a file changed on disk since it was recorded refused
        (:class:`~sbrdf_xr.errors.TableFileChangedError`)."""
        tables = state["tables"]
        state["tables"] = tables._replace(values=tuple(map(restore, tables.values)))
        self.__dict__.update(state)

    # ----------------------------------------------------------- derived
    def __getattr__(self, name: str) -> bool:
        """``plan.<effect>``: whether that effect runs (``plan.shadowing``)."""
        if name in EFFECTS:
            return name in self.__dict__.get("effects", ())
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    @cached_property
    def active_effects(self) -> tuple[Effect, ...]:
        """The entries of the effects that run (:data:`sbrdf_xr.engine.effects.EFFECTS`)."""
        return tuple(EFFECTS[e] for e in self.effects)

    @cached_property
    def output_names(self) -> tuple[str, ...]:
        """Names of the output variables (found once: every block reads them)."""
        return tuple(o.name for o in self.outputs)

    @property
    def n_lead(self) -> int:
        """Length of the blocked (first) dimension."""
        return int(self.geometry.n_lead)

    @property
    def n_blocks(self) -> int:
        """Number of blocks."""
        return max(1, -(-self.n_lead // self.chunk)) if self.n_lead else 0

    def block_slice(self, k: int) -> slice:
        """Slice of the first dimension covered by block ``k``."""
        return slice(k * self.chunk, min((k + 1) * self.chunk, self.n_lead))

    def table(
        self, m: int
    ) -> tuple[
        np.ndarray, tuple[np.ndarray, np.ndarray, np.ndarray], tuple[bool, bool, bool], float
    ]:
        """Table ``m`` unpacked: values (n_theta, n_delta_theta, n_phi, L), grids, zero edges,
        normal-incidence blend [degree]."""
        t = self.tables
        values = t.values[m].reshape(*t.shapes[m], -1)
        grids = (
            t.tgrid[t.t_off[m] : t.t_off[m + 1]],
            t.dgrid[t.d_off[m] : t.d_off[m + 1]],
            t.pgrid[t.p_off[m] : t.p_off[m + 1]],
        )
        lo, hi, phi = (bool(x) for x in t.edges[m])
        return values, grids, (lo, hi, phi), float(t.blend[m])

    @property
    def spectral_axis(self) -> np.ndarray:
        """Wavelengths [nm] of the tables, or band indices when pre-integrated."""
        if self.pre_integrated:
            return np.arange(len(self.bands), dtype=np.float64)
        return self.wavelength

    # ----------------------------------------------------------- display
    def __str__(self) -> str:
        w = max(len(a) for a, _ in self.steps)
        lines = [f"plan for scene {self.name!r}:"]
        lines += [f"  {a:<{w}}  {b}" for a, b in self.steps]
        return "\n".join(lines)

    def _repr_html_(self) -> str:  # pragma: no cover - Jupyter display
        import html

        rows = "".join(
            f"<tr><td>{html.escape(a)}</td><td style='text-align:left'>{html.escape(b)}</td></tr>"
            for a, b in self.steps
        )
        return f"<table><caption>plan for {html.escape(self.name)}</caption>{rows}</table>"

    @classmethod
    def from_scene(cls, scene: SceneView) -> Plan:
        """Compile ``scene`` (see the module docstring)."""
        return compile_plan(scene)


# ------------------------------------------------------------------ compiler


def _anisotropic(material: xr.DataArray | xr.Dataset) -> bool:
    """A table with a psi axis, or a model of an anisotropic BRDF."""
    if isinstance(material, xr.Dataset):
        return bool(getattr(model_parameters(material)[0], "anisotropic", False))
    return PSI in material.dims


def _facet_terms(
    scene: SceneView,
    per_facet: tuple[str, ...],
    steps: list[tuple[str, str]],
    aniso: frozenset[str],
    fingerprint: Mapping[str, str],
) -> tuple[dict[str, np.ndarray], bool]:
    """:func:`~sbrdf_xr.engine.stages.facet_terms`, kept by the content of the mesh, the
    tangents and the merging asked for (:data:`sbrdf_xr.engine.reuse.FACETS`)."""
    sc = scene.spacecraft
    tangent = getattr(sc, "facet_tangent", None)
    key = None
    if getattr(sc, "mesh", None) is not None and tangent is not None:
        key = (fingerprint[f"{PREFIX}_mesh"], digest(tangent), per_facet, scene.merge, aniso)

    def make() -> tuple[dict[str, np.ndarray], bool, list[tuple[str, str]]]:
        lines: list[tuple[str, str]] = []
        raw, merged = facet_terms(scene, per_facet, lines, aniso)
        return {k: readonly(np.array(v)) for k, v in raw.items()}, merged, lines  # own copies

    raw, merged, lines = FACETS.get(key, make)
    steps += lines
    return dict(raw), merged


def compile_plan(scene: SceneView) -> Plan:
    """Compile a scene into its :class:`Plan` (see the module docstring).

    Parameters
    ----------
    scene : SceneView

    Returns
    -------
    Plan

    Raises
    ------
    SceneError
        The scene cannot be simulated as asked (for example merging with shadowing
        on, bands the wavelengths do not cover), or its estimated size or work is
        beyond the limits (:data:`SIZE_LIMIT_BYTES`, :data:`WORK_LIMIT`; raise them
        with the scene field ``size_limit``).  Nothing is allocated before this check.

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, geometry, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> turns = geometry.axis_rotation([0, 0, 1], [0.0, 45.0])  # two attitudes about z
    >>> scene = Scene(box, {"grey": grey}, attitudes=turns, phase_angles=[0.0, 60.0])
    >>> from sbrdf_xr.engine.plan import compile_plan
    >>> plan = compile_plan(scene)
    >>> plan.estimate.n_geometries, plan.terms.size, plan.chunk
    (4, 2, 2)
    >>> compile_plan(scene.with_options(merge=False)).terms.size  # every lit and seen facet
    4
    """
    knobs = {k: getattr(scene, k) for k in scene.knob_names()}
    geo = scene.geometry
    steps: list[tuple[str, str]] = [("geometry", geo.describe())]
    # the content of every input, stored in the cube and keying what later plans reuse
    fingerprint = scene_fingerprint(scene)

    # ---- effects that change what terms are needed (per facet)
    early, params = effect_stage(PlanInputs(scene, knobs), True, steps)
    per_facet = tuple(EFFECTS[e].title for e in early)

    aniso_names = frozenset(m for m, v in scene.material_data.items() if _anisotropic(v))
    raw, merged = _facet_terms(scene, per_facet, steps, aniso_names, fingerprint)
    raw = tilted_terms(scene, raw, knobs["tilt_nodes"], steps)
    keep = contributing_terms(scene, raw["normal"])
    parts = tuple(getattr(scene.spacecraft, "parts", ()))
    if parts:  # a part's terms turn: where they face at rest says nothing
        keep |= raw["part"] > 0
    if not keep.all():
        raw = {k: v[keep] for k, v in raw.items()}
        steps.append(
            (
                "drop",
                f"{int((~keep).sum())} terms that never contribute (lit and visible) "
                "in this sweep are dropped",
            )
        )
    else:
        steps.append(("drop", "none: every term contributes somewhere in the sweep"))

    used = sorted(set(raw["material"].tolist()))
    index = {m: i for i, m in enumerate(used)}
    code = np.array([index[m] for m in raw["material"].tolist()], dtype=np.int64)
    order = np.argsort(code, kind="stable")
    normal, area, material, facet, n_facets, tangent = (
        readonly(a[order])
        for a in (
            raw["normal"],
            raw["area"],
            code,
            raw["facet"],
            raw["n_facets"],
            raw["tangent"],
        )
    )
    terms = Terms(
        normal,
        area,
        material,
        facet,
        n_facets,
        tangent,
        part=readonly(raw["part"][order]) if parts else None,
    )
    if parts:
        steps.append(("parts", describe_parts(parts)))

    # ---- spectral axis, bands and tables
    sx = spectral_stage(scene, used, knobs, steps, fingerprint)
    wl, bw, pre, dtype = sx.wavelength, sx.band_weights, sx.pre_integrated, sx.dtype

    # ---- the other effects
    late, late_params = effect_stage(PlanInputs(scene, knobs, wl, tuple(used), pre), False, steps)
    active = [e for e in EFFECTS if e in early or e in late]
    params.update(late_params)

    # ---- outputs: the scene's, then those of the effects that run
    outputs = _planned_outputs(scene, geo, active, params, terms.size, pre, wl, used, dtype, steps)

    # ---- blocks and estimate
    per_lead = sum(o.nbytes for o in outputs) / max(1, geo.n_lead)
    chunk = knobs["chunk"]
    if chunk is None:  # within the memory budget, and enough blocks to keep every core busy
        by_memory = int(knobs["block_bytes"] // max(1.0, per_lead))
        by_cores = -(-geo.n_lead // (BLOCKS_PER_CORE * (os.cpu_count() or 1)))
        chunk = max(1, min(by_memory, max(MIN_CHUNK, by_cores)))
    chunk = min(chunk, max(1, geo.n_lead))
    out_bytes = sum(o.nbytes for o in outputs)
    nodes = {"nearest": 1, "linear": 8, "cubic": 64}[knobs["method"]]
    n_spec = len(scene.bands) if pre else wl.size
    n_src = sum(EFFECTS[e].reflects for e in active)  # one kernel pass per reflected source
    work = float(geo.n_geometries) * terms.size * nodes * n_spec * n_src
    est = Estimate(geo.n_geometries, terms.size, int(out_bytes), int(per_lead * chunk), work)
    limit = scene.size_limit
    if out_bytes > limit * SIZE_LIMIT_BYTES or work > limit * WORK_LIMIT:
        raise SceneError(
            f"scene {scene.name!r} is beyond reason: {geo.n_geometries:.3g} geometries "
            f"x {terms.size} terms would write {describe_bytes(out_bytes)} "
            f"(limit {describe_bytes(limit * SIZE_LIMIT_BYTES)}) "
            f"and take up to {work:.3g} multiply-adds (limit {limit * WORK_LIMIT:.3g}); "
            "reduce the sweep, "
            "or raise the limits with size_limit (a factor, default 1) if you mean it"
        )
    n_blocks = max(1, -(-geo.n_lead // chunk)) if geo.n_lead else 0
    steps.append(
        (
            "blocks",
            f"{n_blocks} blocks of {chunk} {geo.dims[0]}s, {describe_bytes(per_lead * chunk)} "
            f"each; {describe_bytes(out_bytes)} of outputs, at most {work:.3g} multiply-adds",
        )
    )

    attrs = _cube_attrs(scene, geo, knobs, dtype, active, used, fingerprint)
    plan = Plan(
        name=scene.name,
        description=scene.description,
        spacecraft=scene.spacecraft,
        geometry=geo,
        terms=terms,
        materials=tuple(used),
        tables=sx.tables,
        wavelength=readonly(wl),
        bands=tuple(scene.bands),
        band_weights=None if bw is None else readonly(bw),
        band_coords=MappingProxyType(sx.band_coords),
        pre_integrated=pre,
        merged=merged,
        effects=tuple(active),
        effect_params=MappingProxyType(params),
        models=MappingProxyType(sx.models),
        knobs=MappingProxyType(knobs),
        outputs=tuple(outputs),
        chunk=int(chunk),
        estimate=est,
        steps=tuple(steps),
        attrs=MappingProxyType(attrs),
        anisotropic=MappingProxyType(sx.anisotropic),
        articulation=Articulation(parts, group_terms(terms)) if parts else None,
    )
    attrs["plan"] = str(plan)
    return plan


def _planned_outputs(
    scene: SceneView,
    geo: Any,
    active: list[str],
    params: dict[str, Any],
    n_terms: int,
    pre: bool,
    wl: np.ndarray,
    used: list[str],
    dtype: np.dtype,
    steps: list[tuple[str, str]],
) -> list[PlannedOutput]:
    """The cube's variables: the scene's outputs, then those of the effects that run
    (an effect's own, or those its planner names in ``params[effect]["outputs"]``; no
    spectral ones when the tables are pre-integrated over the bands)."""
    names = []
    wanted = [SCENE_OUTPUTS[o] for o in scene.outputs]
    for e in active:
        filled = params.get(e, {}).get("outputs")
        wanted += [o.name for o in EFFECTS[e].declares if filled is None or o.name in filled]
    for v in wanted:
        if pre and OUTPUTS[v].tail and OUTPUTS[v].tail[-1] == WAVELENGTH:
            continue
        if v not in names:
            names.append(v)
    sizes = {WAVELENGTH: wl.size, BAND: len(scene.bands), MATERIAL: len(used), FACET: n_terms}
    lead_dims, lead_shape = geo.dims, geo.shape
    outputs = []
    for v in names:
        spec = OUTPUTS[v]
        dt = dtype if spec.spectral else np.dtype(np.float64)
        outputs.append(
            PlannedOutput(
                v,
                (*lead_dims, *spec.tail),
                (*lead_shape, *(sizes[d] for d in spec.tail)),
                dt,
                MappingProxyType(spec.attrs),
            )
        )
    steps.append(("outputs", ", ".join(names)))
    return outputs


def _cube_attrs(
    scene: SceneView,
    geo: Any,
    knobs: dict[str, Any],
    dtype: np.dtype,
    active: list[str],
    used: list[str],
    fingerprint: dict[str, Any],
) -> dict[str, Any]:
    """The cube's global attributes: CF conventions, provenance, the knobs, the effects,
    the materials' provenance, the geometry's and the scene's fingerprint."""
    provenance = {m: scene.material_data[m].attrs.get("provenance", "") for m in used}
    attrs = {
        "Conventions": "CF-1.10",
        "title": f"sbrdf_xr simulation of scene {scene.name}",
        "source": f"sbrdf_xr {__version__}",
        "history": (
            f"sbrdf_xr.simulate(scene={scene.name!r}, method={knobs['method']}, dtype={dtype.name})"
        ),
        "references": (
            "Bedard et al., A novel approach to modeling spacecraft spectral reflectance; "
            "Sandford, Infrared reflectance properties of aircraft paints"
        ),
        "scene": scene.name,
        "scene_description": scene.description,
        "spacecraft": getattr(scene.spacecraft, "name", ""),
        "lookup_method": knobs["method"],
        **{
            f"knob_{k}": ("none" if v is None else v)
            for k, v in knobs.items()
            if k != "block_bytes"
        },
        "effects": ", ".join(active),
        "plan": "",
        **{f"material_provenance_{m.replace('-', '_')}": p for m, p in provenance.items()},
        "note_sbrdf_zero_area": (
            "spacecraft_sbrdf is 0 where area is 0 (no lit and visible facet; 0/0 of Eq. 4)"
        ),
        **geo.attrs,
        **fingerprint,  # checked when an interrupted write is resumed
    }
    return attrs
