"""Run a scene's plan as a Dask graph into an xarray cube; write it to netCDF.

:func:`simulate` returns a *lazy* :class:`xarray.Dataset` (nothing is computed
until asked), chunked over attitude (or geometry) with the wavelength dimension
whole.  :func:`write` streams it to netCDF block by block, atomically and
resumably, with the threaded scheduler or on a ``dask.distributed`` cluster
(:func:`sbrdf_xr._writer.write_cube`, re-exported here as ``write``).  This module
and its writer are the only ones that know about Dask scheduling.

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
from ._lut import table_edges
from ._names import ATTITUDE, BAND, PHASE_ANGLE, VECTOR, WAVELENGTH, attrs
from ._writer import write_cube as write
from .errors import SceneError
from .fingerprint import scene_fingerprint
from .scene import SPECTRAL_OUTPUTS, Plan, Scene, resolve_scene

__all__ = ["compile_plan", "earthshine_irradiance_ratio", "planck", "simulate", "write"]

GEOMETRY = "geometry"
MATERIAL_DIM = "material"
QUAT = "quaternion"

OUTPUT_ATTRS: dict[str, dict[str, str]] = {
    "spacecraft_sbrdf": {"units": "sr-1", "long_name": "overall spacecraft spectral BRDF (paper 000 Eq. 4)"},
    "signal": {"units": "m2 sr-1", "long_name": "radiometric signal sum_j A_j cos(theta_i) cos(theta_r) f_r"},
    "brdf": {"units": "sr-1 nm", "long_name": "broadband BRDF, sBRDF integrated over wavelength (paper 000 Eq. 2)"},
    "area": {"units": "m2", "long_name": "contributing projected area sum_j A_j cos(theta_r) (paper 000 Eq. 4 denominator)"},
    "signal_material": {"units": "m2 sr-1", "long_name": "radiometric signal of each material's facets"},
    "signal_earthshine": {"units": "m2 sr-1", "long_name": "radiometric signal of the light reflected "
                          "from a Lambertian Earth, per unit solar irradiance"},
    "thermal_intensity": {"units": "W sr-1 nm-1", "long_name": "thermal emission intensity "
                          "sum_j A_j cos(theta_r) epsilon(lambda, theta_r) B(lambda, T)"},
    "band_signal": {"units": "m2 sr-1", "long_name": "solar-weighted band mean of the radiometric signal "
                    "(photon counting)"},
    "attitude": {"units": "1", "long_name": "attitude index"},
    "attitude_angle": {"units": "degree", "long_name": "rotation angle of the attitude sweep"},
    "quaternion": {"units": "1", "long_name": "attitude quaternion, body to reference frame, scalar last (x, y, z, w)"},
    "geometry": {"units": "1", "long_name": "geometry index"},
}

#: Largest number of (geometry x term) dot products evaluated at once when
#: searching for terms never lit and visible.
_DROP_BLOCK = 2_000_000


def _contributing_terms(scene: Scene, normals: np.ndarray) -> np.ndarray:
    """Boolean per term: contributes for at least one geometry of the sweep.

    A term contributes when it is visible and lit by the Sun (or by the Earth, with
    earthshine); with thermal emission, visible is enough.
    """
    keep = np.zeros(len(normals), dtype=bool)
    n_att = len(scene.attitudes) if scene.is_grid else len(scene.to_sun)
    per = len(scene.phase_angles) if scene.is_grid else 1
    step = max(1, _DROP_BLOCK // max(1, per * len(normals)))
    for start in range(0, n_att, step):
        sl = slice(start, start + step)
        s, o = scene.body_vectors(sl)
        visible = o.reshape(-1, 3) @ normals.T > 0
        if "thermal" in scene.effects:
            lit = True
        else:
            lit = s.reshape(-1, 3) @ normals.T > 0
            if "earthshine" in scene.effects:
                lit = lit | (scene.earth_vectors(sl).reshape(-1, 3) @ normals.T > 0)
        keep |= (visible & lit).any(axis=0)
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
        steps.append(("drop", f"{dropped} terms that never contribute (lit and visible) in this sweep are dropped"))
    else:
        steps.append(("drop", "none: every term contributes somewhere in the sweep"))

    used = sorted(set(np.asarray(terms["material"].values).tolist()))
    steps.append(("materials", f"{len(used)} tabulated materials ({', '.join(used)}), "
                  f"{scene.method} look-up, {scene.dtype}"))

    pre = bool(scene.bands) and not any(o in SPECTRAL_OUTPUTS for o in scene.outputs)
    if scene.bands:
        _band_weights(scene, _common_wavelength(scene, used or list(scene.materials)))
    if not scene.bands:
        steps.append(("bands", "skipped: no band output requested"))
    elif pre:
        steps.append(("bands", f"tables pre-integrated over {', '.join(scene.bands)} (filter x Sun, photon "
                      "counting) before the sweep: exact, the facet sum is linear in f_r"))
    else:
        steps.append(("bands", f"{', '.join(scene.bands)} integrated from the spectral signal "
                      "(spectral outputs are requested too)"))

    ratio = None
    if "earthshine" in scene.effects:
        ratio = earthshine_irradiance_ratio(scene.earth_albedo, scene.earth_range_km, scene.earth_phase_angle)
        steps.append(("earthshine", f"Lambertian Earth (albedo {scene.earth_albedo:g}, range "
                      f"{scene.earth_range_km:g} km, phase {scene.earth_phase_angle:g} deg): irradiance "
                      f"{ratio:.3g} of the Sun's, a second distant source"))
    else:
        steps.append(("earthshine", "skipped: not requested"))

    thermal = False
    if "thermal" not in scene.effects:
        steps.append(("thermal", "skipped: not requested"))
    else:
        wl = _common_wavelength(scene, used or list(scene.materials))
        worst = _thermal_to_reflected(scene, wl)
        if worst < THERMAL_NEGLIGIBLE:
            steps.append(("thermal", f"skipped: negligible, at most {worst:.1e} of reflected sunlight "
                          f"at {wl[0]:g}-{wl[-1]:g} nm"))
        elif pre:
            steps.append(("thermal", f"skipped: up to {worst:.1e} of reflected sunlight, but only band "
                          "outputs of reflected light are asked for; add the 'signal' output for "
                          "thermal_intensity"))
        else:
            thermal = True
            steps.append(("thermal", f"epsilon(lambda, theta) B(lambda, T) per facet, epsilon = 1 - rho "
                          f"(Kirchhoff) from each table; up to {worst:.1e} of reflected sunlight"))
    steps.append(("outputs", ", ".join(scene.outputs)))
    return Plan(scene=scene, terms=terms, shadowing=shadowing, merged=merge, steps=steps,
                pre_integrate=pre, earthshine_ratio=ratio, thermal=thermal)


#: Thermal emission below this fraction of the reflected sunlight is not computed.
THERMAL_NEGLIGIBLE = 1e-6
#: Earth's mean radius [km].
EARTH_RADIUS_KM = 6371.0
_H, _C, _K = 6.62607015e-34, 299792458.0, 1.380649e-23


def planck(wavelength_nm: np.ndarray, temperature: float) -> np.ndarray:
    """Blackbody spectral radiance B(lambda, T) [W m-2 sr-1 nm-1] (Planck's law).

    Evaluated as ``2 h c^2 / lambda^5 * e^-x / (1 - e^-x)`` with ``x = h c / (lambda k T)``,
    which underflows to 0 instead of overflowing at short wavelengths.
    """
    lam = np.asarray(wavelength_nm, dtype=np.float64) * 1e-9
    x = _H * _C / (lam * _K * float(temperature))
    with np.errstate(under="ignore"):
        return 2.0 * _H * _C**2 / lam**5 * np.exp(-x) / -np.expm1(-x) * 1e-9


def earthshine_irradiance_ratio(albedo: float, range_km: float, phase_angle_deg: float) -> float:
    """Irradiance from a Lambertian Earth relative to the Sun's (at the same heliocentric distance).

    A Lambertian sphere of radius ``R`` and albedo ``a`` seen at phase angle ``alpha``
    from distance ``r`` gives ``E/E_sun = (2/3) a (R/r)^2 [(pi - alpha) cos alpha +
    sin alpha] / pi`` (the diffuse-sphere phase law).  The Earth is then treated as
    a distant source from its centre's direction: a good approximation when its
    angular radius ``asin(R/r)`` is small (8.7 deg at GEO), a rough one in low orbit.

    Parameters
    ----------
    albedo : float
        Bond albedo [1].
    range_km : float
        Distance to the Earth's centre [km].
    phase_angle_deg : float
        Sun-Earth-spacecraft angle [degree].

    Returns
    -------
    float
        ``E_earth / E_sun`` [1].
    """
    a = np.radians(phase_angle_deg)
    return float(2.0 / 3.0 * albedo * (EARTH_RADIUS_KM / range_km) ** 2
                 * ((np.pi - a) * np.cos(a) + np.sin(a)) / np.pi)


def _band_weights(scene: Scene, wl: np.ndarray) -> xr.DataArray:
    """Normalised band weights of the scene's bands on ``wl``; SceneError if not covered."""
    from .errors import ValidationError
    from .photometry import band_weights

    try:
        return band_weights(list(scene.bands), wl, normalize=True, extrapolate=scene.band_extrapolate)
    except ValidationError as exc:
        raise SceneError(f"bands: {exc} (scene field band_extrapolate)") from None


def _temperature(scene: Scene, material: str) -> float:
    t = scene.temperature
    return float(t.get(material, 300.0)) if isinstance(t, dict) else float(t)


def _emissivity_tables(scene: Scene, used: list[str], wl: np.ndarray) -> dict[str, np.ndarray]:
    """Directional emissivity epsilon(theta, lambda) = 1 - rho(theta, lambda) per material
    (Kirchhoff's law with the table's directional-hemispherical reflectance), on 0-90 deg."""
    from .material import hemispherical_reflectance

    out = {}
    for m in used:
        da = scene.materials[m]
        if not np.array_equal(da[WAVELENGTH].values, wl):
            da = da.interp({WAVELENGTH: wl})
        rho = hemispherical_reflectance(da, np.arange(0.0, 91.0), warn=False).values
        out[m] = np.clip(1.0 - rho, 0.0, 1.0)
    return out


def _thermal_to_reflected(scene: Scene, wl: np.ndarray) -> float:
    """Largest ratio of blackbody radiance (emissivity 1) to the radiance of a white
    Lambertian surface in sunlight, E_sun / pi, over the scene's wavelengths."""
    from .photometry import solar_spectrum

    e_sun = solar_spectrum(wl).values
    temps = [_temperature(scene, m) for m in scene.materials]
    b = np.max([planck(wl, t) for t in temps], axis=0)
    return float(np.max(b / np.maximum(e_sun / np.pi, 1e-300)))


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


def _tables(
    scene: Scene, used: list[str], wl: np.ndarray, weights: np.ndarray | None = None
) -> dict[str, tuple[np.ndarray, ...]]:
    """Material tables on the common grid; with ``weights`` (band, wavelength) the
    spectral axis is integrated into bands first (band pre-integration)."""
    out = {}
    dtype = np.dtype(scene.dtype)
    for m in used:
        da = scene.materials[m]
        if not np.array_equal(da[WAVELENGTH].values, wl):
            da = da.interp({WAVELENGTH: wl})
        values = np.asarray(da.values, dtype=np.float64)
        if weights is not None:
            values = values @ weights.T
        out[m] = (np.ascontiguousarray(values, dtype=dtype),
                  *(np.asarray(da[d].values) for d in ("theta_i", "delta_theta", "phi")),
                  table_edges(scene.materials[m].attrs))
    return out


def _block(
    plan: Plan, tables: dict[str, tuple[np.ndarray, ...]], wl: np.ndarray, sl: slice,
    weights: np.ndarray | None = None, emissivity: dict[str, np.ndarray] | None = None,
) -> dict[str, np.ndarray]:
    """Compute every output for one block of attitudes (or explicit geometries).

    ``wl`` is the spectral axis of the tables: wavelengths, or band indices when the
    tables are pre-integrated.  ``weights`` (band, wavelength) integrates the spectral
    signal into bands; ``emissivity`` turns on thermal emission.
    """
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
    for m, (values, tg, dg, pg, edges) in tables.items():
        sel = mats == m
        r = material_sums(s2, o2, normals[sel], areas[sel], values, tg, dg, pg, scene.method,
                          None if fraction is None else fraction[:, sel], edges)
        signal += r.signal
        paper += r.paper
        area += r.area
        per_mat.append(r.signal)
    with np.errstate(invalid="ignore", divide="ignore"):
        sbrdf = np.where(area[:, None] > 0, paper / np.where(area > 0, area, 1.0)[:, None], 0.0).astype(dtype)
    n = wl.size
    es = None
    if plan.earthshine_ratio is not None:
        e2 = scene.earth_vectors(sl).reshape(-1, 3)
        es = np.zeros((g, n), dtype=dtype)
        frac_e = None
        if plan.shadowing:
            from .visibility import lit_visible_fraction

            frac_e = lit_visible_fraction(scene.spacecraft, e2, o2, density=scene.shadow_density)[
                :, np.asarray(plan.terms["term"].values)]
        for m, (values, tg, dg, pg, edges) in tables.items():
            sel = mats == m
            es += material_sums(e2, o2, normals[sel], areas[sel], values, tg, dg, pg, scene.method,
                                None if frac_e is None else frac_e[:, sel], edges).signal
        es = (plan.earthshine_ratio * es).astype(dtype)
    out = {"area": area.reshape(lead)}
    if plan.pre_integrate:  # the spectral axis already is the band axis
        out["band_signal"] = (signal if es is None else signal + es).reshape(*lead, n)
        return out
    out["spacecraft_sbrdf"] = sbrdf.reshape(*lead, n)
    out["signal"] = signal.reshape(*lead, n)
    out["brdf"] = (np.trapezoid(sbrdf, wl, axis=-1) if n > 1 else sbrdf[..., 0]).astype(dtype).reshape(lead)
    if "per_material" in scene.outputs:
        pm = np.stack(per_mat, axis=-2) if per_mat else np.zeros((g, 0, n), dtype=dtype)
        out["signal_material"] = pm.reshape(*lead, len(tables), n)
    if es is not None:
        out["signal_earthshine"] = es.reshape(*lead, n)
    if emissivity is not None:
        out["thermal_intensity"] = _thermal(plan, o2, wl, emissivity).reshape(*lead, n)
    if weights is not None:
        total = signal if es is None else signal + es
        out["band_signal"] = (total @ weights.T).astype(dtype).reshape(*lead, weights.shape[0])
    return out


def _thermal(plan: Plan, o2: np.ndarray, wl: np.ndarray, emissivity: dict[str, np.ndarray]) -> np.ndarray:
    """Thermal intensity ``sum_j A_j cos(theta_r) epsilon_j(lambda, theta_r) B(lambda, T_j)``
    over the visible facets [W sr-1 nm-1] (the emission term of paper 001's signature model)."""
    scene = plan.scene
    normals = np.asarray(plan.terms["normal"].values)
    areas = np.asarray(plan.terms["area"].values)
    mats = np.asarray(plan.terms["material"].values)
    out = np.zeros((o2.shape[0], wl.size))
    for m, eps in emissivity.items():
        sel = mats == m
        cos_r = o2 @ normals[sel].T  # (G, F)
        vis = cos_r > 0
        theta_r = np.degrees(np.arctan2(np.sqrt(np.clip(1 - cos_r**2, 0, None)), cos_r))
        idx = np.clip(np.rint(np.where(vis, theta_r, 0.0)).astype(int), 0, 90)  # 1-degree table
        w = np.where(vis, cos_r, 0.0) * areas[sel]
        out += np.einsum("gf,gfl->gl", w, eps[idx]) * planck(wl, _temperature(scene, m))
    return out.astype(np.dtype(scene.dtype))


def simulate(
    scene: Scene | str | os.PathLike[str], plan: Plan | None = None, *, client: Any = None, **options: Any
) -> xr.Dataset:
    """Build the lazy simulation cube of a scene.

    Parameters
    ----------
    scene : Scene, str or path
        A scene, a built-in scene name or a TOML scene file.
    plan : Plan, optional
        A compiled plan (default ``scene.plan()``).
    client : dask.distributed.Client, optional
        When the cube will be computed on a cluster: the plan and the material
        tables (tens of MB) are scattered to every worker once instead of travelling
        inside each block's task.  The cube then refers to data on that cluster and
        must be computed (or written) with that client.
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
    weights = band_coords = None
    if scene.bands:
        bw = _band_weights(scene, wl)
        weights = np.asarray(bw.values)
        band_coords = {c: bw[c] for c in bw.coords if BAND in bw[c].dims}
    tables = _tables(scene, used, wl, weights if plan.pre_integrate else None)
    emissivity = _emissivity_tables(scene, used, wl) if plan.thermal else None
    spectral = np.arange(weights.shape[0], dtype=float) if plan.pre_integrate else wl
    dtype = np.dtype(scene.dtype)

    n_lead = len(scene.attitudes) if scene.is_grid else len(scene.to_sun)
    lead_dim = ATTITUDE if scene.is_grid else GEOMETRY
    extra = (len(scene.phase_angles),) if scene.is_grid else ()
    extra_dims = (PHASE_ANGLE,) if scene.is_grid else ()
    outputs = [k for k in ("spacecraft_sbrdf", "signal", "brdf", "area", "band_signal") if k in scene.outputs]
    if "per_material" in scene.outputs:
        outputs.append("signal_material")
    if plan.earthshine_ratio is not None and not plan.pre_integrate:
        outputs.append("signal_earthshine")
    if plan.thermal:
        outputs.append("thermal_intensity")
    n_band = 0 if weights is None else weights.shape[0]
    shapes = {
        "spacecraft_sbrdf": ((wl.size,), (WAVELENGTH,), dtype),
        "signal": ((wl.size,), (WAVELENGTH,), dtype),
        "brdf": ((), (), dtype),
        "area": ((), (), np.dtype(np.float64)),
        "signal_material": ((len(tables), wl.size), (MATERIAL_DIM, WAVELENGTH), dtype),
        "signal_earthshine": ((wl.size,), (WAVELENGTH,), dtype),
        "thermal_intensity": ((wl.size,), (WAVELENGTH,), dtype),
        "band_signal": ((n_band,), (BAND,), dtype),
    }
    blocks: dict[str, list[Any]] = {k: [] for k in outputs}
    shared = [plan, tables, None if plan.pre_integrate else weights, emissivity]
    if client is not None:
        shared = client.scatter(shared, broadcast=True, hash=False)
    token = dask.base.tokenize(id(plan), scene.name, n_lead, scene.chunk)
    for start in range(0, n_lead, scene.chunk):
        sl = slice(start, min(start + scene.chunk, n_lead))
        n = sl.stop - sl.start
        res = dask.delayed(_block, pure=True)(
            shared[0], shared[1], spectral, sl, shared[2], shared[3],
            dask_key_name=f"sbrdf-block-{scene.name}-{start}-{token}")
        for k in outputs:
            tail, _, dt = shapes[k]
            blocks[k].append(dsa.from_delayed(res[k], shape=(n, *extra, *tail), dtype=dt))
    data_vars = {}
    for k in outputs:
        tail, tail_dims, _ = shapes[k]
        arr = dsa.concatenate(blocks[k], axis=0)
        data_vars[k] = xr.Variable((lead_dim, *extra_dims, *tail_dims), arr, attrs=OUTPUT_ATTRS[k])

    coords: dict[str, Any] = {VECTOR: (VECTOR, ["x", "y", "z"])}
    if any(WAVELENGTH in shapes[k][1] for k in outputs):
        coords[WAVELENGTH] = (WAVELENGTH, wl, attrs(WAVELENGTH))
    if band_coords is not None and "band_signal" in outputs:
        coords.update(band_coords)
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
    ds.attrs.update(scene_fingerprint(scene))
    return ds
