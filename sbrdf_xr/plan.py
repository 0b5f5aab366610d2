"""The plan: a scene compiled into exactly what will be computed, and why.

:meth:`Plan.from_scene` (what :meth:`sbrdf_xr.scene.Scene.plan` returns) resolves
everything a simulation needs, once: the facet terms (merged by (normal, material)
when no per-facet effect is on, dropped when never lit and seen), the wavelength
grid or the bands, the material tables on that grid (pre-integrated over the bands
for band-only scenes), the effects with their sources and parameters, the value of
every knob (:mod:`sbrdf_xr.knobs`), the outputs with their dimensions, shapes and
attributes, the block layout, and an estimate of memory and work.  The plan is
immutable data: tests assert on its fields; ``print(plan)`` renders its ``steps``
for people.  :mod:`sbrdf_xr.simulate` executes a plan and derives nothing.

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
from types import MappingProxyType
from typing import Any

import numpy as np
import xarray as xr

from . import sources
from ._kernels import PackedTables, pack_tables
from ._lut import table_edges, table_normal_blend
from ._names import BAND, MATERIAL, WAVELENGTH
from ._version import __version__
from .effects import EFFECTS, OUTPUTS, SCENE_OUTPUTS, SPECTRAL_OUTPUTS, BlockInputs
from .errors import SceneError, ValidationError
from .fingerprint import scene_fingerprint

#: The scene being compiled (:class:`sbrdf_xr.scene.Scene`, which imports this module).
Scene = Any

__all__ = ["BlockInputs", "Estimate", "Plan", "PlannedOutput", "Terms", "compile_plan"]

#: Thermal emission below this fraction of the reflected sunlight is not computed.
THERMAL_NEGLIGIBLE = 1e-6
#: Largest number of (geometry x term) dot products evaluated at once when
#: searching for terms never lit and visible.
_DROP_BLOCK = 2_000_000
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
class Terms:
    """The facet terms a plan evaluates, sorted by material.

    Attributes
    ----------
    normal : ndarray, shape (T, 3)
        Unit normals [1].
    area : ndarray, shape (T,)
        Areas [m2] (summed over merged facets).
    material : ndarray of int, shape (T,)
        Index into :attr:`Plan.materials`.
    facet : ndarray of int, shape (T,)
        The facet of each term when facets are not merged (per-facet effects), else
        the first facet of the term.
    n_facets : ndarray of int, shape (T,)
        Facets merged into each term.
    """

    normal: np.ndarray
    area: np.ndarray
    material: np.ndarray
    facet: np.ndarray
    n_facets: np.ndarray

    @property
    def size(self) -> int:
        """Number of terms."""
        return int(self.area.size)


@dataclass(frozen=True)
class PlannedOutput:
    """An output variable: its name, dimensions, shape, dtype and CF attributes."""

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
    """

    n_geometries: int
    n_terms: int
    output_bytes: int
    block_bytes: int
    multiply_adds: float


@dataclass(frozen=True, eq=False)
class Plan:
    """A compiled scene: everything a simulation computes (see the module docstring).

    Build with :meth:`from_scene` (or :meth:`sbrdf_xr.scene.Scene.plan`).  Fields are
    read-only; arrays are not writeable.
    """

    name: str
    description: str
    spacecraft: Any
    geometry: Any
    terms: Terms
    materials: tuple[str, ...]
    tables: PackedTables
    wavelength: np.ndarray
    bands: tuple[str, ...]
    band_weights: np.ndarray | None
    band_coords: Mapping[str, Any]
    pre_integrated: bool
    shadowing: bool
    merged: bool
    shadow_options: Mapping[str, Any]
    effects: tuple[str, ...]
    effect_params: Mapping[str, Mapping[str, Any]]
    models: Mapping[int, tuple[Any, Mapping[str, Any]]]
    knobs: Mapping[str, Any]
    outputs: tuple[PlannedOutput, ...]
    chunk: int
    estimate: Estimate
    steps: tuple[tuple[str, str], ...]
    attrs: Mapping[str, Any] = field(default_factory=dict)
    #: Products of the plan made on first use (the cube's coordinate template).
    cache: dict[str, Any] = field(default_factory=dict, init=False, repr=False, compare=False)

    # ----------------------------------------------------------- derived
    @property
    def output_names(self) -> tuple[str, ...]:
        """Names of the output variables."""
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
    def from_scene(cls, scene: Scene) -> Plan:
        """Compile ``scene`` (see the module docstring)."""
        return compile_plan(scene)


# ------------------------------------------------------------------ compiler


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.flags.writeable = False
    return a


def _terms(
    scene: Scene, shadowing: bool, steps: list[tuple[str, str]]
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
        m = sc.merged()
        term_of = np.asarray(m["facet_term"].values)
        first = np.full(m.sizes["term"], n_fac, dtype=np.int64)
        np.minimum.at(first, term_of, np.arange(n_fac))
        t = {
            "normal": np.asarray(m["normal"].values),
            "area": np.asarray(m["area"].values),
            "material": np.asarray(m[MATERIAL].values),
            "facet": first,
            "n_facets": np.asarray(m["n_facets"].values),
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
        }
        steps.append(("facets", f"{n_fac} facets evaluated one by one ({why})"))
    return t, merge


def _tilt(
    scene: Scene, raw: dict[str, np.ndarray], nodes: int, steps: list[tuple[str, str]]
) -> dict[str, np.ndarray]:
    """Terms replaced by their tilted copies where the scene asks for surface imperfections."""
    from .imperfections import tilt_quadrature, tilted_normals

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


def _contributing(scene: Scene, normals: np.ndarray) -> np.ndarray:
    """Boolean per term: lit (by the Sun, or the Earth with earthshine) and visible for
    at least one geometry of the sweep; with thermal emission, visible is enough."""
    geo = scene.geometry
    keep = np.zeros(len(normals), dtype=bool)
    per = max(1, geo.n_geometries // max(1, geo.n_lead))
    step = max(1, _DROP_BLOCK // max(1, per * len(normals)))
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


def _common_wavelength(scene: Scene, used: list[str]) -> np.ndarray:
    wl = np.asarray(scene.materials[used[0]][WAVELENGTH].values) if used else np.array([550.0])
    for m in used[1:]:
        other = np.asarray(scene.materials[m][WAVELENGTH].values)
        if other.shape != wl.shape or not np.allclose(other, wl, rtol=0, atol=1e-9):
            lo, hi = max(wl[0], other[0]), min(wl[-1], other[-1])
            if lo >= hi:
                raise SceneError(f"materials {used[0]!r} and {m!r} have no wavelengths in common")
            wl = wl[(wl >= lo) & (wl <= hi)]
    return wl


def _band_weights(scene: Scene, wl: np.ndarray) -> xr.DataArray:
    from .photometry import band_weights

    try:
        return band_weights(
            list(scene.bands), wl, normalize=True, extrapolate=scene.band_extrapolate
        )
    except ValidationError as exc:
        raise SceneError(f"bands: {exc} (scene field band_extrapolate)") from None


def _table_on(da: xr.DataArray, wl: np.ndarray, theta_step: float | None) -> xr.DataArray:
    if not np.array_equal(da[WAVELENGTH].values, wl):
        da = da.interp({WAVELENGTH: wl})
    if theta_step is not None:
        ti = da["theta_i"].values
        new = np.arange(ti[0], ti[-1] + 1e-9, float(theta_step))
        if new[-1] < ti[-1]:
            new = np.append(new, ti[-1])
        da = da.interp(theta_i=new)
    return da


def _temperature(scene: Scene, material: str) -> float:
    t = scene.temperature
    return float(t.get(material, 300.0)) if isinstance(t, Mapping) else float(t)


def _thermal_to_reflected(scene: Scene, wl: np.ndarray) -> float:
    """Largest ratio of blackbody radiance (emissivity 1) to the radiance of a white
    Lambertian surface in sunlight, E_sun / pi, over the scene's wavelengths."""
    from .photometry import solar_spectrum

    e_sun = solar_spectrum(wl).values
    b = np.max([sources.planck(wl, _temperature(scene, m)) for m in scene.materials], axis=0)
    return float(np.max(b / np.maximum(e_sun / np.pi, 1e-300)))


def _models(scene: Scene, used: list[str]) -> dict[int, tuple[Any, Mapping[str, Any]]]:
    """BRDF model and parameters of every material, for analytic evaluation."""
    from . import models as models_mod

    given = dict(scene.models or {})
    out: dict[int, tuple[Any, Mapping[str, Any]]] = {}
    for m, name in enumerate(used):
        spec = given.get(name)
        if spec is None:
            from . import catalog

            try:
                spec = catalog.load(f"{name}-model")
            except Exception as exc:
                raise SceneError(
                    f"evaluation='analytic': material {name!r} has no model; give "
                    f"Scene(models={{{name!r}: ...}}) or a catalog entry '{name}-model' ({exc})"
                ) from None
        mod, _, kw = models_mod._params(spec)
        out[m] = (mod, MappingProxyType(dict(kw)))
    return out


def _describe_bytes(n: float) -> str:
    for unit, scale in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= scale:
            return f"{n / scale:.3g} {unit}"
    return f"{n:.0f} B"


def compile_plan(scene: Scene) -> Plan:
    """Compile a scene into its :class:`Plan` (see the module docstring).

    Parameters
    ----------
    scene : Scene

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
    """
    knobs = {k: getattr(scene, k) for k in scene.knob_names()}
    geo = scene.geometry
    steps: list[tuple[str, str]] = [("geometry", geo.describe())]

    # ---- effects that change what terms are needed
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

    raw, merged = _terms(scene, shadowing, steps)
    raw = _tilt(scene, raw, knobs["tilt_nodes"], steps)
    keep = _contributing(scene, raw["normal"])
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
    terms = Terms(
        *(
            _readonly(a[order])
            for a in (raw["normal"], raw["area"], code, raw["facet"], raw["n_facets"])
        )
    )

    # ---- spectral axis
    wl_full = _common_wavelength(scene, used or list(scene.materials))
    wl = wl_full[:: knobs["wavelength_stride"]]
    bw = None
    band_coords: dict[str, Any] = {}
    if scene.bands:
        w = _band_weights(scene, wl)
        bw = np.asarray(w.values)
        band_coords = {str(c): w[c] for c in w.coords if BAND in w[c].dims}
    spectral_asked = any(o in SPECTRAL_OUTPUTS for o in scene.outputs)
    pre = bool(scene.bands) and not spectral_asked and knobs["band_integration"] == "auto"
    dtype = np.dtype(knobs["dtype"])
    if knobs["evaluation"] == "analytic":
        models = _models(scene, used)
        tables = pack_tables([], len(scene.bands) if pre else wl.size, dtype)
        steps.append(
            (
                "materials",
                f"{len(used)} materials ({', '.join(used)}) evaluated by their "
                f"BRDF models (analytic, no table), {dtype.name}",
            )
        )
    else:
        models = {}
        packed = []
        for m in used:
            da = _table_on(scene.materials[m], wl, knobs["table_theta_step"])
            values = np.asarray(da.values)
            if pre and bw is not None:
                values = np.asarray(values, dtype=np.float64) @ bw.T
            packed.append(
                (
                    values,
                    *(
                        np.asarray(da[d].values, dtype=np.float64)
                        for d in ("theta_i", "delta_theta", "phi")
                    ),
                    table_edges(scene.materials[m].attrs),
                    table_normal_blend(scene.materials[m].attrs),
                )
            )
        tables = pack_tables(packed, len(scene.bands) if pre else wl.size, dtype)
        del packed
        res = (
            ""
            if knobs["table_theta_step"] is None
            else f", theta_i resampled every {knobs['table_theta_step']:g} deg"
        )
        steps.append(
            (
                "materials",
                f"{len(used)} tabulated materials ({', '.join(used)}), "
                f"{knobs['method']} look-up, {dtype.name}, {knobs['kernel']} kernel{res}",
            )
        )
    stride = "" if knobs["wavelength_stride"] == 1 else f" (every {knobs['wavelength_stride']}th)"
    if not scene.bands:
        steps.append(("bands", "skipped: no band output requested"))
    elif pre:
        steps.append(
            (
                "bands",
                f"tables pre-integrated over {', '.join(scene.bands)} (filter x Sun, photon "
                "counting) before the sweep: exact, the facet sum is linear in f_r; the sweep "
                f"evaluates {len(scene.bands)} values per look-up instead of {wl.size}",
            )
        )
    else:
        why = (
            "spectral outputs are requested too"
            if spectral_asked
            else "band_integration = 'spectral'"
        )
        steps.append(
            ("bands", f"{', '.join(scene.bands)} integrated from the spectral signal ({why})")
        )
    steps.append(("wavelength", f"{wl.size} wavelengths {wl[0]:g}-{wl[-1]:g} nm{stride}"))

    # ---- effects
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
        worst = _thermal_to_reflected(scene, wl)
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
            from .material import hemispherical_reflectance

            active.append("thermal")
            eps, thetas, rad = [], [], []
            for m in used:
                da = _table_on(scene.materials[m], wl, None)
                th = np.asarray(da["theta_i"].values, dtype=np.float64)
                rho = hemispherical_reflectance(da, th, warn=False).values
                eps.append(_readonly(sources.kirchhoff_emissivity(rho)))
                thetas.append(_readonly(th))
                rad.append(_readonly(sources.planck(wl, _temperature(scene, m))))
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

    # ---- outputs
    names = []
    for o in scene.outputs:
        v = SCENE_OUTPUTS[o]
        if pre and OUTPUTS[v].tail and OUTPUTS[v].tail[-1] == WAVELENGTH:
            continue
        names.append(v)
    for e in active:
        for v in EFFECTS[e].outputs:
            if v in ("signal_earthshine", "thermal_intensity") and not pre and v not in names:
                names.append(v)
    sizes = {WAVELENGTH: wl.size, BAND: len(scene.bands), MATERIAL: len(used)}
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
    n_src = 1 + ("earthshine" in active)
    work = float(geo.n_geometries) * terms.size * nodes * n_spec * n_src
    est = Estimate(geo.n_geometries, terms.size, int(out_bytes), int(per_lead * chunk), work)
    limit = scene.size_limit
    if out_bytes > limit * SIZE_LIMIT_BYTES or work > limit * WORK_LIMIT:
        raise SceneError(
            f"scene {scene.name!r} is beyond reason: {geo.n_geometries:.3g} geometries "
            f"x {terms.size} terms would write {_describe_bytes(out_bytes)} "
            f"(limit {_describe_bytes(limit * SIZE_LIMIT_BYTES)}) "
            f"and take up to {work:.3g} multiply-adds (limit {limit * WORK_LIMIT:.3g}); "
            "reduce the sweep, "
            "or raise the limits with size_limit (a factor, default 1) if you mean it"
        )
    n_blocks = max(1, -(-geo.n_lead // chunk)) if geo.n_lead else 0
    steps.append(
        (
            "blocks",
            f"{n_blocks} blocks of {chunk} {lead_dims[0]}s, {_describe_bytes(per_lead * chunk)} "
            f"each; {_describe_bytes(out_bytes)} of outputs, at most {work:.3g} multiply-adds",
        )
    )

    provenance = {m: scene.materials[m].attrs.get("provenance", "") for m in used}
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
        **scene_fingerprint(scene),  # checked when an interrupted write is resumed
    }
    plan = Plan(
        name=scene.name,
        description=scene.description,
        spacecraft=scene.spacecraft,
        geometry=geo,
        terms=terms,
        materials=tuple(used),
        tables=tables,
        wavelength=_readonly(wl),
        bands=tuple(scene.bands),
        band_weights=None if bw is None else _readonly(bw),
        band_coords=MappingProxyType(band_coords),
        pre_integrated=pre,
        shadowing=shadowing,
        merged=merged,
        shadow_options=MappingProxyType(shadow_options),
        effects=tuple(active),
        effect_params=MappingProxyType(params),
        models=MappingProxyType(models),
        knobs=MappingProxyType(knobs),
        outputs=tuple(outputs),
        chunk=int(chunk),
        estimate=est,
        steps=tuple(steps),
        attrs=MappingProxyType(attrs),
    )
    attrs["plan"] = str(plan)
    return plan
