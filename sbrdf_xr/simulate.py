"""Run a scene's plan as a Dask graph into an xarray cube; write it to netCDF.

:func:`simulate` returns a *lazy* :class:`xarray.Dataset` (nothing is computed
until asked), chunked over attitude (or geometry) with the wavelength dimension
whole.  :func:`write` streams it to netCDF block by block, atomically and
resumably, with the threaded scheduler or on a ``dask.distributed`` cluster.
This is the only module that knows about Dask scheduling.

The cube (DESIGN.md data model)
-------------------------------
``spacecraft_sbrdf``
    The paper's overall spacecraft sBRDF, paper 000 Eq. 4:
    ``sum_j a_2D,j f_r,j / sum_j a_2D,j`` with ``a_2D,j = A_j cos(theta_r,j)`` over
    the lit and visible facets [sr-1].  When nothing contributes (0/0) it is 0 and
    ``area`` is 0: the cube says "no contributing area" instead of NaN.
``signal``
    The radiometric signal ``S = sum_j A_j cos(theta_i,j) cos(theta_r,j) f_r,j``
    [m2 sr-1]: reflected intensity per unit solar irradiance.  Paper 000 Eq. 3
    leaves out ``cos(theta_i)``; ``signal`` keeps it, ``spacecraft_sbrdf`` follows
    the paper.  (Not named ``sbrdf``: ``cube.sbrdf`` is the Dataset accessor.)
``brdf``
    The paper's broadband BRDF, Eq. 2: ``spacecraft_sbrdf`` integrated over wavelength
    (trapezoid) [sr-1 nm].
``area``
    The contributing projected area, ``sum_j a_2D,j`` [m2].
``signal_material``
    ``signal`` per material (with the ``per_material`` output).
Coordinates carry the geometry: ``to_sun`` and ``to_observer`` (body frame),
the attitude quaternions and the phase angle.
"""

from __future__ import annotations

import os
from typing import Any

import dask
import dask.array as dsa
import numpy as np
import xarray as xr

from . import __version__
from ._kernels import material_sums
from ._names import ATTITUDE, PHASE_ANGLE, VECTOR, WAVELENGTH, attrs
from .errors import SceneError
from .scene import Plan, Scene, resolve_scene

__all__ = ["compile_plan", "simulate", "write"]

GEOMETRY = "geometry"
MATERIAL_DIM = "material"
QUAT = "quaternion"

OUTPUT_ATTRS: dict[str, dict[str, str]] = {
    "spacecraft_sbrdf": {"units": "sr-1", "long_name": "overall spacecraft spectral BRDF (paper 000 Eq. 4)"},
    "signal": {"units": "m2 sr-1", "long_name": "radiometric signal sum_j A_j cos(theta_i) cos(theta_r) f_r"},
    "brdf": {"units": "sr-1 nm", "long_name": "broadband BRDF, sBRDF integrated over wavelength (paper 000 Eq. 2)"},
    "area": {"units": "m2", "long_name": "contributing projected area sum_j A_j cos(theta_r) (paper 000 Eq. 4 denominator)"},
    "signal_material": {"units": "m2 sr-1", "long_name": "radiometric signal of each material's facets"},
    "attitude": {"units": "1", "long_name": "attitude index"},
    "attitude_angle": {"units": "degree", "long_name": "rotation angle of the attitude sweep"},
    "quaternion": {"units": "1", "long_name": "attitude quaternion, body to reference frame, scalar last (x, y, z, w)"},
    "geometry": {"units": "1", "long_name": "geometry index"},
}

#: Largest number of (geometry x term) dot products evaluated at once when
#: searching for terms never lit and visible.
_DROP_BLOCK = 2_000_000


def _contributing_terms(scene: Scene, normals: np.ndarray) -> np.ndarray:
    """Boolean per term: lit and visible for at least one geometry of the sweep."""
    keep = np.zeros(len(normals), dtype=bool)
    n_att = len(scene.attitudes) if scene.is_grid else len(scene.to_sun)
    per = len(scene.phase_angles) if scene.is_grid else 1
    step = max(1, _DROP_BLOCK // max(1, per * len(normals)))
    for start in range(0, n_att, step):
        s, o = scene.body_vectors(slice(start, start + step))
        ok = (s.reshape(-1, 3) @ normals.T > 0) & (o.reshape(-1, 3) @ normals.T > 0)
        keep |= ok.any(axis=0)
        if keep.all():
            break
    return keep


def compile_plan(scene: Scene) -> Plan:
    """Compile a scene into the minimal plan (see :mod:`sbrdf_xr.scene`).

    Parameters
    ----------
    scene : Scene

    Returns
    -------
    Plan
    """
    sc = scene.spacecraft
    steps: list[tuple[str, str]] = []
    n_geom = scene.n_geometries
    if scene.is_grid:
        steps.append(("geometry", f"{len(scene.attitudes)} attitudes x {len(scene.phase_angles)} "
                      f"phase angles = {n_geom} geometries, in blocks of {scene.chunk} attitudes"))
    else:
        steps.append(("geometry", f"{n_geom} explicit (to_sun, to_observer) pairs, in blocks of {scene.chunk}"))

    want_shadow = "shadowing" in scene.effects
    convex = bool(sc.is_convex) if want_shadow else None
    shadowing = want_shadow and not convex
    if not want_shadow:
        steps.append(("shadowing", "skipped: not requested"))
    elif convex:
        steps.append(("shadowing", "skipped: the body is convex, no facet can shadow another"))
    else:
        steps.append(("shadowing", f"ray-cast self-shadowing and self-occlusion at sub-facet density "
                      f"{scene.shadow_density} (non-convex body)"))

    may_merge = not shadowing
    merge = may_merge if scene.merge is None else bool(scene.merge)
    if merge and not may_merge:
        raise SceneError("merge: facets cannot be merged while self-shadowing is on (a per-facet effect)")
    facets = sc.facets()
    if merge:
        terms = sc.merged()
        terms = terms.assign(facets_per_term=terms["n_facets"])
        steps.append(("facets", f"{facets.sizes['facet']} facets -> {terms.sizes['term']} terms, merged by "
                      "(normal, material): exact for flat facets, no per-facet effect is on"))
    else:
        why = "self-shadowing is per facet" if shadowing else "merging disabled by the scene"
        terms = facets.rename(facet="term").assign(
            facets_per_term=("term", np.ones(facets.sizes["facet"], dtype=np.int64)))
        steps.append(("facets", f"{facets.sizes['facet']} facets evaluated one by one ({why})"))

    keep = _contributing_terms(scene, np.asarray(terms["normal"].values))
    if not keep.all():
        dropped = int((~keep).sum())
        terms = terms.isel(term=np.flatnonzero(keep))
        steps.append(("drop", f"{dropped} terms never both lit and visible in this sweep are dropped"))
    else:
        steps.append(("drop", "none: every term is lit and visible somewhere in the sweep"))

    used = sorted(set(np.asarray(terms["material"].values).tolist()))
    steps.append(("materials", f"{len(used)} tabulated materials ({', '.join(used)}), "
                  f"{scene.method} look-up, {scene.dtype}"))
    steps.append(("outputs", ", ".join(scene.outputs)))
    return Plan(scene=scene, terms=terms, shadowing=shadowing, merged=merge, steps=steps)


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


def _tables(scene: Scene, used: list[str], wl: np.ndarray) -> dict[str, tuple[np.ndarray, ...]]:
    out = {}
    dtype = np.dtype(scene.dtype)
    for m in used:
        da = scene.materials[m]
        if not np.array_equal(da[WAVELENGTH].values, wl):
            da = da.interp({WAVELENGTH: wl})
        out[m] = (np.ascontiguousarray(da.values, dtype=dtype),
                  *(np.asarray(da[d].values) for d in ("theta_i", "delta_theta", "phi")))
    return out


def _block(
    plan: Plan, tables: dict[str, tuple[np.ndarray, ...]], wl: np.ndarray, sl: slice
) -> dict[str, np.ndarray]:
    """Compute every output for one block of attitudes (or explicit geometries)."""
    scene = plan.scene
    s, o = scene.body_vectors(sl)
    lead = s.shape[:-1]
    s2, o2 = s.reshape(-1, 3), o.reshape(-1, 3)
    g = s2.shape[0]
    normals = np.asarray(plan.terms["normal"].values)
    areas = np.asarray(plan.terms["area"].values)
    mats = np.asarray(plan.terms["material"].values)
    fraction = None
    if plan.shadowing:
        from .visibility import lit_visible_fraction

        facet_index = np.asarray(plan.terms["term"].values)
        fraction = lit_visible_fraction(scene.spacecraft, s2, o2,
                                        density=scene.shadow_density)[:, facet_index]
    dtype = np.dtype(scene.dtype)
    signal = np.zeros((g, wl.size), dtype=dtype)
    paper = np.zeros((g, wl.size), dtype=dtype)
    area = np.zeros(g)
    per_mat = []
    for m, (values, tg, dg, pg) in tables.items():
        sel = mats == m
        r = material_sums(s2, o2, normals[sel], areas[sel], values, tg, dg, pg, scene.method,
                          None if fraction is None else fraction[:, sel])
        signal += r.signal
        paper += r.paper
        area += r.area
        per_mat.append(r.signal)
    with np.errstate(invalid="ignore", divide="ignore"):
        sbrdf = np.where(area[:, None] > 0, paper / np.where(area > 0, area, 1.0)[:, None], 0.0).astype(dtype)
    out = {
        "spacecraft_sbrdf": sbrdf.reshape(*lead, wl.size),
        "signal": signal.reshape(*lead, wl.size),
        "area": area.reshape(lead),
        "brdf": np.trapezoid(sbrdf, wl, axis=-1).astype(dtype).reshape(lead)
        if wl.size > 1 else sbrdf[..., 0].reshape(lead),
    }
    if "per_material" in scene.outputs:
        pm = np.stack(per_mat, axis=-2) if per_mat else np.zeros((g, 0, wl.size), dtype=dtype)
        out["signal_material"] = pm.reshape(*lead, len(tables), wl.size)
    return out


def simulate(scene: Scene | str | os.PathLike[str], plan: Plan | None = None, **options: Any) -> xr.Dataset:
    """Build the lazy simulation cube of a scene.

    Parameters
    ----------
    scene : Scene, str or path
        A scene, a built-in scene name or a TOML scene file.
    plan : Plan, optional
        A compiled plan (default ``scene.plan()``).
    **options
        Scene fields to override (``preset="fast"``, ``method="cubic"``, ``chunk=...``).

    Returns
    -------
    xarray.Dataset
        Lazy (Dask-backed) cube over ``(attitude, phase_angle, wavelength)`` for a
        grid or ``(geometry, wavelength)`` for explicit pairs; see the module
        docstring for its variables.  Compute it, or :func:`write` it.
    """
    scene = resolve_scene(scene)
    if options:
        scene = scene.with_options(**options)
        plan = None
    plan = plan or compile_plan(scene)
    used = [m for m in scene.spacecraft.materials if m in set(plan.terms["material"].values.tolist())]
    wl = _common_wavelength(scene, used or list(scene.materials))
    tables = _tables(scene, used, wl)
    dtype = np.dtype(scene.dtype)

    n_lead = len(scene.attitudes) if scene.is_grid else len(scene.to_sun)
    lead_dim = ATTITUDE if scene.is_grid else GEOMETRY
    extra = (len(scene.phase_angles),) if scene.is_grid else ()
    extra_dims = (PHASE_ANGLE,) if scene.is_grid else ()
    outputs = [k for k in ("spacecraft_sbrdf", "signal", "brdf", "area") if k in scene.outputs]
    if "per_material" in scene.outputs:
        outputs.append("signal_material")
    shapes = {
        "spacecraft_sbrdf": ((wl.size,), (WAVELENGTH,), dtype),
        "signal": ((wl.size,), (WAVELENGTH,), dtype),
        "brdf": ((), (), dtype),
        "area": ((), (), np.dtype(np.float64)),
        "signal_material": ((len(tables), wl.size), (MATERIAL_DIM, WAVELENGTH), dtype),
    }
    blocks: dict[str, list[Any]] = {k: [] for k in outputs}
    for start in range(0, n_lead, scene.chunk):
        sl = slice(start, min(start + scene.chunk, n_lead))
        n = sl.stop - sl.start
        res = dask.delayed(_block, pure=True)(plan, tables, wl, sl,
                                              dask_key_name=f"sbrdf-block-{scene.name}-{start}-{id(plan)}")
        for k in outputs:
            tail, _, dt = shapes[k]
            blocks[k].append(dsa.from_delayed(res[k], shape=(n, *extra, *tail), dtype=dt))
    data_vars = {}
    for k in outputs:
        tail, tail_dims, _ = shapes[k]
        arr = dsa.concatenate(blocks[k], axis=0)
        data_vars[k] = xr.Variable((lead_dim, *extra_dims, *tail_dims), arr, attrs=OUTPUT_ATTRS[k])

    coords: dict[str, Any] = {WAVELENGTH: (WAVELENGTH, wl, attrs(WAVELENGTH)), VECTOR: (VECTOR, ["x", "y", "z"])}
    s, o = scene.body_vectors()
    if scene.is_grid:
        coords[ATTITUDE] = (ATTITUDE, np.arange(n_lead), OUTPUT_ATTRS["attitude"])
        coords[PHASE_ANGLE] = (PHASE_ANGLE, np.asarray(scene.phase_angles), attrs(PHASE_ANGLE))
        coords[QUAT] = ((ATTITUDE, "component"), scene.attitudes, OUTPUT_ATTRS["quaternion"])
        coords["component"] = ("component", ["x", "y", "z", "w"])
        if scene.attitude_angle is not None:
            coords["attitude_angle"] = (ATTITUDE, np.asarray(scene.attitude_angle, dtype=np.float64),
                                        OUTPUT_ATTRS["attitude_angle"])
        vec_dims = (ATTITUDE, PHASE_ANGLE, VECTOR)
    else:
        from .geometry import phase_angle

        coords[GEOMETRY] = (GEOMETRY, np.arange(n_lead), OUTPUT_ATTRS["geometry"])
        coords[PHASE_ANGLE] = (GEOMETRY, phase_angle(s, o), attrs(PHASE_ANGLE))
        vec_dims = (GEOMETRY, VECTOR)
    coords["to_sun"] = (vec_dims, s, attrs("to_sun"))
    coords["to_observer"] = (vec_dims, o, attrs("to_observer"))
    if "signal_material" in data_vars:
        coords[MATERIAL_DIM] = (MATERIAL_DIM, list(tables))
    ds = xr.Dataset(data_vars, coords=coords)
    provenance = {m: scene.materials[m].attrs.get("provenance", "") for m in tables}
    ds.attrs = {
        "Conventions": "CF-1.10",
        "title": f"sbrdf_xr simulation of scene {scene.name}",
        "source": f"sbrdf_xr {__version__}",
        "history": f"sbrdf_xr.simulate(scene={scene.name!r}, method={scene.method}, dtype={scene.dtype})",
        "scene": scene.name,
        "scene_description": scene.description,
        "spacecraft": getattr(scene.spacecraft, "name", ""),
        "lookup_method": scene.method,
        "plan": str(plan),
        **{f"material_provenance_{m}": p for m, p in provenance.items()},
        "note_sbrdf_zero_area": "spacecraft_sbrdf is 0 where area is 0 (no lit and visible facet; 0/0 of Eq. 4)",
    }
    return ds


def write(
    ds: xr.Dataset,
    path: str | os.PathLike[str],
    *,
    overwrite: bool = False,
    resume: bool = False,
    client: Any = None,
    scheduler: str | None = None,
    progress: bool = False,
    max_in_flight: int | None = None,
) -> os.PathLike[str]:
    """Stream a lazy cube to netCDF, block by block, atomically and resumably.

    See :func:`sbrdf_xr._writer.write_cube` for the guarantees (peak memory bounded
    by the block size, no half-written file under the final name, resume from the
    blocks already written, threaded scheduler by default or a Dask cluster).
    """
    from ._writer import write_cube

    return write_cube(ds, path, overwrite=overwrite, resume=resume, client=client,
                      scheduler=scheduler, progress=progress, max_in_flight=max_in_flight)
