"""The spectral stage of :func:`sbrdf_xr.engine.plan.compile_plan`: the wavelength grid, the
bands, and the material tables packed for the kernel (or the materials' BRDF models for
analytic evaluation).

Pure functions of a scene; each appends its plan lines to ``steps``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr

from .. import catalog
from .._names import ANGLE_DIMS, BAND, PSI, WAVELENGTH
from ..errors import CatalogError, SceneError, ValidationError
from ..kernels import PackedTables, pack_tables
from ..kernels import anisotropic as _aniso_kernels
from ..kernels.anisotropic import pack_anisotropic
from ..kernels.lut import table_edges, table_normal_blend
from ..materials import models
from ..photometry import band_weights, filters
from ..store.fingerprint import PREFIX
from .effects.base import SPECTRAL_OUTPUTS, readonly, table_on
from .reuse import GRIDS, TABLES, WEIGHTS, digest, immutable, table_digests

if TYPE_CHECKING:
    from .views import SceneView


def common_wavelength(scene: SceneView, used: list[str]) -> np.ndarray:
    """The wavelengths every used material's table covers (those of the first table).

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> from sbrdf_xr.engine.spectral import common_wavelength
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> x = [[1.0, 0.0, 0.0]]  # the Sun and the observer along +x
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> dark = lambertian(0.2, [400.0, 500.0, 600.0], material="dark")
    >>> far = lambertian(0.2, [800.0, 900.0], material="far")
    >>> scene = Scene(box, {"grey": grey, "dark": dark, "far": far}, to_sun=x, to_observer=x)
    >>> common_wavelength(scene, ["grey", "dark"]).tolist()  # the overlap, on grey's grid
    [500.0, 600.0]
    >>> common_wavelength(scene, []).tolist()  # no material: one visible wavelength
    [550.0]
    >>> common_wavelength(scene, ["grey", "far"])
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.SceneError: materials 'grey' and 'far' have no wavelengths in common
    """
    data = scene.material_data  # tables, or models (the tables they render to share the grid)
    wl = np.asarray(data[used[0]][WAVELENGTH].values) if used else np.array([550.0])
    for m in used[1:]:
        other = np.asarray(data[m][WAVELENGTH].values)
        if other.shape != wl.shape or not np.allclose(other, wl, rtol=0, atol=1e-9):
            lo, hi = max(wl[0], other[0]), min(wl[-1], other[-1])
            if lo >= hi:
                raise SceneError(f"materials {used[0]!r} and {m!r} have no wavelengths in common")
            wl = wl[(wl >= lo) & (wl <= hi)]
    return wl


#: The solar spectrum of the engine: ASTM G173 (280-4000 nm), and its extension
#: (:data:`sbrdf_xr.photometry.SOLAR_SPECTRA`, 119.5 nm - 1 mm) for grids or bands past it.
SOLAR, SOLAR_EXTENDED = "astm_g173", "astm_g173_extended"
_SOLAR_RANGE = (280.0, 4000.0)


def solar_for(wl: np.ndarray, bands: list[Any] | tuple[Any, ...] = ()) -> str:
    """The solar spectrum for wavelengths ``wl`` [nm] and ``bands``: ASTM G173 inside
    280-4000 nm (node for node the same as the extension there), the extension beyond.

    Examples
    --------
    >>> import numpy as np
    >>> solar_for(np.array([400.0, 900.0])), solar_for(np.array([3000.0, 15000.0]))
    ('astm_g173', 'astm_g173_extended')
    >>> solar_for(np.array([3000.0, 3900.0]), ["twomass-Ks"]), solar_for(np.array([3.0e3]), ["N"])
    ('astm_g173', 'astm_g173_extended')
    """
    lo, hi = float(np.min(wl)), float(np.max(wl))
    if bands:
        response = filters(list(bands))
        support = response[WAVELENGTH].values[(response.values > 0).any(axis=0)]
        lo, hi = min(lo, float(support[0])), max(hi, float(support[-1]))
    inside = _SOLAR_RANGE[0] <= lo and hi <= _SOLAR_RANGE[1]
    return SOLAR if inside else SOLAR_EXTENDED


def band_weights_of(scene: SceneView, wl: np.ndarray) -> xr.DataArray:
    """The scene's band weights (filter x Sun, normalised) on the wavelengths ``wl``.

    Examples
    --------
    >>> import numpy as np
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> from sbrdf_xr.engine.spectral import band_weights_of
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> x = [[1.0, 0.0, 0.0]]  # the Sun and the observer along +x
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> scene = Scene(box, {"grey": grey}, to_sun=x, to_observer=x, bands=("V", "R"))
    >>> w = band_weights_of(scene, np.arange(400.0, 901.0, 10.0))
    >>> w.dims, w.shape, w.filter.values.tolist()
    (('band', 'wavelength'), (2, 51), ['bessell-V', 'bessell-R'])
    >>> bool(np.allclose(w.sum("wavelength"), 1.0))  # each band's weights sum to one
    True

    A grid short of a band's response is an error unless the scene extrapolates:

    >>> band_weights_of(scene, np.array([500.0, 600.0, 700.0]))
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.SceneError: bands: band 'V' (bessell-V) has non-zero response over \
470-700 nm but the spectrum covers only 500-700 nm; pass extrapolate='zero' or 'constant' to \
continue the spectrum past its grid (scene field band_extrapolate)
    """
    try:
        bands = list(scene.bands)
        return band_weights(
            bands,
            wl,
            normalize=True,
            extrapolate=scene.band_extrapolate,
            solar=solar_for(wl, bands),
        )
    except ValidationError as exc:
        raise SceneError(f"bands: {exc} (scene field band_extrapolate)") from None


def material_models(scene: SceneView, used: list[str]) -> dict[int, tuple[Any, Mapping[str, Any]]]:
    """BRDF model and parameters of every material, for analytic evaluation.

    Examples
    --------
    The models come by material index, from ``Scene(models=...)`` or the catalog entry
    ``NAME-model``:

    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> from sbrdf_xr.engine.spectral import material_models
    >>> from sbrdf_xr.errors import SceneError
    >>> from sbrdf_xr.materials.models import model_material
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> x = [[1.0, 0.0, 0.0]]  # the Sun and the observer along +x
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> spec = model_material("lambert", [500.0, 600.0, 700.0], material="grey",
    ...                       provenance="albedo 0.5", rho=0.5)
    >>> scene = Scene(box, {"grey": grey}, to_sun=x, to_observer=x, models={"grey": spec})
    >>> found = material_models(scene, ["grey"])
    >>> model, params = found[0]
    >>> list(found), model.name, params["rho"].tolist()
    ([0], 'lambert', [0.5, 0.5, 0.5])
    >>> try:
    ...     material_models(Scene(box, {"grey": grey}, to_sun=x, to_observer=x), ["grey"])
    ... except SceneError as exc:
    ...     print(str(exc).split(" (")[0])
    evaluation='analytic': material 'grey' has no model; give Scene(models={'grey': ...}) or a \
catalog entry 'grey-model'
    """
    given = dict(scene.models or {})
    out: dict[int, tuple[Any, Mapping[str, Any]]] = {}
    for m, name in enumerate(used):
        spec = given.get(name)
        if spec is None:
            try:
                spec = catalog.load(f"{name}-model")
            except CatalogError as exc:
                raise SceneError(
                    f"evaluation='analytic': material {name!r} has no model; give "
                    f"Scene(models={{{name!r}: ...}}) or a catalog entry '{name}-model' ({exc})"
                ) from None
        mod, _, kw = models.model_parameters(spec)
        out[m] = (mod, MappingProxyType(dict(kw)))
    return out


@dataclass(frozen=True)
class Spectral:
    """What the spectral stage resolved: the grid, the bands and the tables.

    Examples
    --------
    A Lambertian grey in the V and R bands, only band outputs asked for: the tables are
    pre-integrated over the bands, so the packed values are two (one per band), each
    albedo / pi:

    >>> import numpy as np
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> from sbrdf_xr.engine.spectral import spectral_stage
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> x = [[1.0, 0.0, 0.0]]  # the Sun and the observer along +x
    >>> grey = lambertian(0.5, np.arange(400.0, 1001.0, 50.0), material="grey")
    >>> scene = Scene(box, {"grey": grey}, to_sun=x, to_observer=x, bands=("V", "R"),
    ...               outputs=("band_signal",))
    >>> knobs = {k: getattr(scene, k) for k in scene.knob_names()}
    >>> sx = spectral_stage(scene, ["grey"], knobs, [])
    >>> type(sx).__name__, sx.wavelength.size, sx.band_weights.shape, sx.pre_integrated
    ('Spectral', 13, (2, 13), True)
    >>> sx.dtype, sx.tables.n_spectral, bool(np.allclose(sx.tables.values[0], 0.5 / np.pi))
    (dtype('float64'), 2, True)
    >>> sx.models, sx.anisotropic, sorted(sx.band_coords)
    ({}, {}, ['band', 'filter', 'filter_source'])
    """

    wavelength: np.ndarray
    band_weights: np.ndarray | None
    band_coords: dict[str, Any]
    pre_integrated: bool
    dtype: np.dtype
    tables: PackedTables
    models: dict[int, tuple[Any, Mapping[str, Any]]]
    anisotropic: dict[int, Any]


def spectral_stage(
    scene: SceneView,
    used: list[str],
    knobs: Mapping[str, Any],
    steps: list[tuple[str, str]],
    fingerprint: Mapping[str, str] | None = None,
) -> Spectral:
    """The wavelength grid, the band weights, and the tables (or models) of ``used``.

    Given the scene's ``fingerprint`` (:func:`sbrdf_xr.engine.fingerprint.scene_fingerprint`),
    the band weights and the packed tables are kept by the content of what they are
    computed from (:mod:`sbrdf_xr.engine.reuse`) and reused by later plans.

    Examples
    --------
    The knob ``wavelength_stride`` keeps every n-th wavelength; the plan's lines say so:

    >>> import numpy as np
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> from sbrdf_xr.engine.spectral import spectral_stage
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> x = [[1.0, 0.0, 0.0]]  # the Sun and the observer along +x
    >>> grey = lambertian(0.5, [500.0, 550.0, 600.0, 650.0, 700.0], material="grey")
    >>> scene = Scene(box, {"grey": grey}, to_sun=x, to_observer=x, wavelength_stride=2)
    >>> knobs = {k: getattr(scene, k) for k in scene.knob_names()}
    >>> steps = []
    >>> sx = spectral_stage(scene, ["grey"], knobs, steps)
    >>> sx.wavelength.tolist(), sx.band_weights, sx.pre_integrated
    ([500.0, 600.0, 700.0], None, False)
    >>> sx.tables.n_spectral, bool(np.allclose(sx.tables.values[0], 0.5 / np.pi))
    (3, True)
    >>> for name, line in steps:
    ...     print(f"{name}: {line}")
    materials: 1 tabulated materials (grey), linear look-up, float64, fused kernel
    bands: skipped: no band output requested
    wavelength: 3 wavelengths 500-700 nm (every 2th)
    """
    digests = None if fingerprint is None else table_digests(fingerprint)
    names = used or list(scene.material_data)
    grid_key = None if digests is None else tuple((m, digests.get(m)) for m in names)
    wl_full = GRIDS.get(grid_key, lambda: readonly(np.array(common_wavelength(scene, names))))
    wl = wl_full[:: knobs["wavelength_stride"]]
    bw = None
    band_coords: dict[str, Any] = {}
    if scene.bands:

        def weigh() -> tuple[np.ndarray, dict[str, Any]]:
            w = band_weights_of(scene, wl).copy(deep=True)  # owns its memory
            return readonly(w.values), {str(c): w[c] for c in w.coords if BAND in w[c].dims}

        key = None
        if fingerprint is not None:
            filters = fingerprint[f"{PREFIX}_filters"]
            key = (tuple(scene.bands), scene.band_extrapolate, filters, digest(wl))
        bw, band_coords = WEIGHTS.get(key, weigh)
    spectral_asked = any(o in SPECTRAL_OUTPUTS for o in scene.outputs)
    pre = bool(scene.bands) and not spectral_asked and knobs["band_integration"] == "auto"
    dtype = np.dtype(knobs["dtype"])
    n_spectral = len(scene.bands) if pre else wl.size
    aniso: dict[int, Any] = {}
    if knobs["evaluation"] == "analytic":
        mods = material_models(scene, used)
        tables = pack_tables([], n_spectral, dtype)
        steps.append(
            (
                "materials",
                f"{len(used)} materials ({', '.join(used)}) evaluated by their "
                f"BRDF models (analytic, no table), {dtype.name}",
            )
        )
    else:
        mods = {}
        # kept only for read-only tables: the packing views their memory
        packing_key: tuple | None = None
        if digests is not None and all(_immutable_table(scene, m) for m in used):
            tables_key = tuple((m, digests[m]) for m in used)
            grid = digest(wl, bw if pre else None)
            packing_key = (tables_key, grid, dtype.str, knobs["table_theta_step"])
        tables, aniso = TABLES.get(
            packing_key, lambda: _packed(scene, used, wl, bw if pre else None, dtype, knobs)
        )
        if aniso:
            steps.append(_aniso_kernels.plan_step(used, aniso))
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
    steps.append(_bands_step(scene, pre, spectral_asked, wl.size))
    stride = "" if knobs["wavelength_stride"] == 1 else f" (every {knobs['wavelength_stride']}th)"
    steps.append(("wavelength", f"{wl.size} wavelengths {wl[0]:g}-{wl[-1]:g} nm{stride}"))
    return Spectral(wl, bw, band_coords, pre, dtype, tables, mods, aniso)


def _immutable_table(scene: SceneView, m: str) -> bool:
    """Whether material ``m`` is a table whose values no one can write (not a model)."""
    da = scene.material_data[m]
    return isinstance(da, xr.DataArray) and immutable(da.variable.data)


def _packed(
    scene: SceneView,
    used: list[str],
    wl: np.ndarray,
    bw: np.ndarray | None,
    dtype: np.dtype,
    knobs: Mapping[str, Any],
) -> tuple[PackedTables, dict[int, Any]]:
    """The used tables on ``wl`` (pre-integrated over the bands ``bw``), packed, and the psi
    slices of anisotropic tables by packed slot."""
    packed: list[tuple[Any, ...]] = []
    aniso: dict[int, Any] = {}
    step = knobs["table_theta_step"]
    sizes = {m: _table_bytes(scene.tables[m], wl.size, step) for m in used}
    if sum(sizes.values()) > scene.size_limit * TABLE_LIMIT_BYTES:
        big = max(sizes, key=lambda m: sizes[m])
        raise SceneError(
            f"scene {scene.name!r} is beyond reason: the tables on the plan's grid would hold "
            f"{_gib(sum(sizes.values()))} in memory (limit "
            f"{_gib(scene.size_limit * TABLE_LIMIT_BYTES)}; the largest, {big!r}, "
            f"{_gib(sizes[big])} for {wl.size} wavelengths"
            + ("" if step is None else f" and theta_i every {step:g} degree (table_theta_step)")
            + "); coarsen table_theta_step or wavelength_stride, or raise the limits with "
            "size_limit (a factor, default 1) if you mean it"
        )
    for m in used:
        da = table_on(scene.tables[m], wl, step)
        values = np.asarray(da.values)
        if bw is not None:
            values = np.asarray(values, dtype=np.float64) @ bw.T
        edges = table_edges(scene.tables[m].attrs)
        if PSI in da.dims:  # its psi slices; the packed slot (psi[0]) is never read
            tg, dg, pg, psg = (np.asarray(da[d].values) for d in (*ANGLE_DIMS, PSI))
            aniso[len(packed)] = pack_anisotropic(values, tg, dg, pg, psg, edges, dtype)
            values = values[:, :, :, 0, :]
        packed.append(
            (
                values,
                *(
                    np.asarray(da[d].values, dtype=np.float64)
                    for d in ("theta_i", "delta_theta", "phi")
                ),
                edges,
                table_normal_blend(scene.tables[m].attrs),
            )
        )
    n_spectral = len(scene.bands) if bw is not None else wl.size
    return pack_tables(packed, n_spectral, dtype), aniso


#: Memory the tables of a plan may hold [byte], times the scene's ``size_limit``.
TABLE_LIMIT_BYTES = 4 * 2**30


def _gib(n: float) -> str:
    return f"{n / 2**30:.3g} GiB"


def _table_bytes(da: xr.DataArray, n_wavelength: int, theta_step: float | None) -> float:
    """Bytes of a table resampled onto ``n_wavelength`` wavelengths and ``theta_step``."""
    n = float(n_wavelength) * 8.0
    for d in da.dims:
        if d == "theta_i" and theta_step is not None:
            ti = da["theta_i"].values
            n *= (float(ti[-1]) - float(ti[0])) / float(theta_step) + 2.0
        elif d != "wavelength":
            n *= da.sizes[d]
    return n


def _bands_step(scene: SceneView, pre: bool, spectral_asked: bool, n_wl: int) -> tuple[str, str]:
    if not scene.bands:
        return ("bands", "skipped: no band output requested")
    if pre:
        return (
            "bands",
            f"tables pre-integrated over {', '.join(scene.bands)} (filter x Sun, photon "
            "counting) before the sweep: exact, the facet sum is linear in f_r; the sweep "
            f"evaluates {len(scene.bands)} values per look-up instead of {n_wl}",
        )
    why = (
        "spectral outputs are requested too" if spectral_asked else "band_integration = 'spectral'"
    )
    return ("bands", f"{', '.join(scene.bands)} integrated from the spectral signal ({why})")
