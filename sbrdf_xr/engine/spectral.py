"""The spectral stage of :func:`sbrdf_xr.engine.plan.compile_plan`: the wavelength grid, the
bands, and the material tables packed for the kernel (or the materials' BRDF models for
analytic evaluation).

Pure functions of a scene; each appends its plan lines to ``steps``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np
import xarray as xr

from .. import catalog
from .._names import ANGLE_DIMS, BAND, PSI, WAVELENGTH
from ..errors import CatalogError, SceneError, ValidationError
from ..kernels import anisotropic as _aniso_kernels
from ..kernels.anisotropic import pack_anisotropic
from ..kernels.lut import table_edges, table_normal_blend
from ..kernels.sums import PackedTables, pack_tables
from ..materials import models
from ..photometry import band_weights
from .effects import SPECTRAL_OUTPUTS

#: The scene being compiled (:class:`sbrdf_xr.engine.Scene`).
Scene = Any


def common_wavelength(scene: Scene, used: list[str]) -> np.ndarray:
    """The wavelengths every used material's table covers (those of the first table)."""
    wl = np.asarray(scene.tables[used[0]][WAVELENGTH].values) if used else np.array([550.0])
    for m in used[1:]:
        other = np.asarray(scene.tables[m][WAVELENGTH].values)
        if other.shape != wl.shape or not np.allclose(other, wl, rtol=0, atol=1e-9):
            lo, hi = max(wl[0], other[0]), min(wl[-1], other[-1])
            if lo >= hi:
                raise SceneError(f"materials {used[0]!r} and {m!r} have no wavelengths in common")
            wl = wl[(wl >= lo) & (wl <= hi)]
    return wl


def band_weights_of(scene: Scene, wl: np.ndarray) -> xr.DataArray:
    """The scene's band weights (filter x Sun, normalised) on the wavelengths ``wl``."""
    try:
        return band_weights(
            list(scene.bands), wl, normalize=True, extrapolate=scene.band_extrapolate
        )
    except ValidationError as exc:
        raise SceneError(f"bands: {exc} (scene field band_extrapolate)") from None


def table_on(da: xr.DataArray, wl: np.ndarray, theta_step: float | None) -> xr.DataArray:
    """A table on the wavelengths ``wl``, its theta_i resampled every ``theta_step`` degree."""
    if not np.array_equal(da[WAVELENGTH].values, wl):
        da = da.interp({WAVELENGTH: wl})
    if theta_step is not None:
        ti = da["theta_i"].values
        new = np.arange(ti[0], ti[-1] + 1e-9, float(theta_step))
        if new[-1] < ti[-1]:
            new = np.append(new, ti[-1])
        da = da.interp(theta_i=new)
    return da


def material_models(scene: Scene, used: list[str]) -> dict[int, tuple[Any, Mapping[str, Any]]]:
    """BRDF model and parameters of every material, for analytic evaluation."""
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
    """What the spectral stage resolved: the grid, the bands and the tables."""

    wavelength: np.ndarray
    band_weights: np.ndarray | None
    band_coords: dict[str, Any]
    pre_integrated: bool
    dtype: np.dtype
    tables: PackedTables
    models: dict[int, tuple[Any, Mapping[str, Any]]]
    anisotropic: dict[int, Any]


def spectral_stage(
    scene: Scene, used: list[str], knobs: Mapping[str, Any], steps: list[tuple[str, str]]
) -> Spectral:
    """The wavelength grid, the band weights, and the tables (or models) of ``used``."""
    wl_full = common_wavelength(scene, used or list(scene.tables))
    wl = wl_full[:: knobs["wavelength_stride"]]
    bw = None
    band_coords: dict[str, Any] = {}
    if scene.bands:
        w = band_weights_of(scene, wl)
        bw = np.asarray(w.values)
        band_coords = {str(c): w[c] for c in w.coords if BAND in w[c].dims}
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
        tables = _packed(scene, used, wl, bw if pre else None, dtype, knobs, aniso)
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


def _packed(
    scene: Scene,
    used: list[str],
    wl: np.ndarray,
    bw: np.ndarray | None,
    dtype: np.dtype,
    knobs: Mapping[str, Any],
    aniso: dict[int, Any],
) -> PackedTables:
    """The used tables on ``wl`` (pre-integrated over the bands ``bw``), packed; the psi
    slices of anisotropic tables go into ``aniso`` by packed slot."""
    packed: list[tuple[Any, ...]] = []
    for m in used:
        da = table_on(scene.tables[m], wl, knobs["table_theta_step"])
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
    return pack_tables(packed, len(scene.bands) if bw is not None else wl.size, dtype)


def _bands_step(scene: Scene, pre: bool, spectral_asked: bool, n_wl: int) -> tuple[str, str]:
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
