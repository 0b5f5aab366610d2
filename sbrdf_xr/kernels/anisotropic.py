"""Facet sums for anisotropic materials: tables with a ``psi`` axis.

An anisotropic table (dims ``(theta_i, delta_theta, phi, psi, wavelength)``) is a
stack of isotropic tables, one per ``psi`` node (:mod:`sbrdf_xr.geometry.anisotropy`).  The
look-up interpolates each slice in ``(theta_i, delta_theta, phi)`` with the isotropic
method and the slices linearly and periodically in ``psi``.  The facet sums of
paper 000 Eqs. 3-4 are linear in ``f_r``, so

``sum_j a_j f_r(g, j) = sum_k sum_j (a_j w_k(g, j)) f_k(g, j)``

with ``w_k(g, j)`` the ``psi`` weight of node ``k`` (two non-zero per geometry and
facet, summing to one) and ``f_k`` the look-up in slice ``k``: each slice is an
isotropic material whose facets carry the extra area fraction ``w_k``.  That is
how the isotropic kernels are reused here, without a change: :func:`anisotropic_sums`
calls :func:`sbrdf_xr.kernels.reference.material_sums` (the numpy reference) once per slice
that any facet needs, or :func:`sbrdf_xr.kernels.sums.fused_sums` (compiled, ``nogil``)
once over the slices packed as materials.  Consequences, stated once:

* no normal-incidence blend (an anisotropic material depends on the observer's
  azimuth from the tangent at ``theta_i = 0``);
* with ``cubic`` look-up each slice's sums are clipped at zero (as each isotropic
  material's are);
* the cost is that of an isotropic look-up per slice the block needs (at most the
  number of ``psi`` nodes), so a table with ``n_psi`` nodes costs up to ``n_psi``
  times an isotropic one.

:func:`anisotropic_reflected` is the hook the engine calls for a plan with anisotropic tables:
isotropic materials go through the plan's kernel as before, anisotropic ones through
:func:`anisotropic_sums`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, NamedTuple, Protocol, runtime_checkable

import numba
import numpy as np
from numpy.typing import DTypeLike, NDArray

from ..errors import SceneError, renamed_attributes
from ..geometry import normal_incidence_tolerance
from ..geometry.anisotropy import PSI_PERIOD, illumination_azimuth, psi_weights
from . import lut as _lut
from .angles import facet_frame, tangent_azimuth
from .lookup import _gather, _lookup_rows, _material_axes, _outside, _psi_cell, _range_limits
from .packing import Facets, KernelOptions, PackedTables, pack_tables, typed_values
from .reference import MaterialSums, material_sums
from .sums import METHOD_CODES, FusedSums, fused_sums

__all__ = [
    "AnisotropicTable",
    "FacetTerms",
    "TablePlan",
    "anisotropic_reflected",
    "anisotropic_sums",
    "pack_anisotropic",
    "plan_step",
]


class AnisotropicTable(NamedTuple):
    """An anisotropic table as the kernels read it: one packed isotropic table per ``psi``.

    Examples
    --------
    Slice ``k`` of the packing is the table at ``psi[k]``, one node per row:

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.anisotropic import pack_anisotropic
    >>> g = np.array([0.0, 90.0])
    >>> values = np.arange(2 * 2 * 2 * 3 * 1, dtype=float).reshape(2, 2, 2, 3, 1)
    >>> table = pack_anisotropic(values, g, g - 90, g, np.array([0.0, 60, 120]))
    >>> type(table).__name__, table.psi.tolist(), table.zero_edges
    ('AnisotropicTable', [0.0, 60.0, 120.0], (True, True, True))
    >>> table.slices.shapes, table.slices.values[1].shape
    (((2, 2, 2), (2, 2, 2), (2, 2, 2)), (8, 1))
    >>> bool(np.array_equal(table.slices.values[1], values[:, :, :, 1].reshape(8, 1)))
    True
    """

    slices: PackedTables  #: material k of the packing is the slice at psi[k]
    psi: NDArray[np.float64]  #: (n_psi,) [degree]
    zero_edges: tuple[bool, bool, bool]


def pack_anisotropic(
    values: NDArray[np.floating],
    theta_grid: NDArray[np.floating],
    delta_theta_grid: NDArray[np.floating],
    phi_grid: NDArray[np.floating],
    psi_grid: NDArray[np.floating],
    zero_edges: tuple[bool, bool, bool] = (True, True, True),
    dtype: DTypeLike = np.float64,
) -> AnisotropicTable:
    """Pack a ``(n_theta, n_delta_theta, n_phi, n_psi, L)`` table (once per plan).

    Parameters
    ----------
    values : ndarray, shape (n_theta, n_delta_theta, n_phi, n_psi, L)
        sBRDF [sr-1] (or its band integrals).
    theta_grid, delta_theta_grid, phi_grid, psi_grid : ndarray
        Table coordinates [degree].
    zero_edges : tuple of 3 bool
        Out-of-range policy (:func:`sbrdf_xr.kernels.lut.lookup_matrix`).
    dtype : numpy dtype
        dtype of the spectral outputs.

    Returns
    -------
    AnisotropicTable

    Examples
    --------
    >>> g = np.array([0.0, 90.0])
    >>> t = pack_anisotropic(np.ones((2, 2, 2, 3, 1)), g, g - 90, g, np.array([0.0, 60, 120]))
    >>> len(t.slices.values), t.psi.tolist()
    (3, [0.0, 60.0, 120.0])
    """
    v = np.asarray(values)
    psi = np.asarray(psi_grid, dtype=np.float64)
    if v.ndim != 5 or v.shape[3] != psi.size:
        raise ValueError(f"values: expected (n_theta, n_dt, n_phi, {psi.size}, L), got {v.shape}")
    grids = tuple(np.asarray(a, dtype=np.float64) for a in (theta_grid, delta_theta_grid, phi_grid))
    slices = pack_tables(
        [(v[:, :, :, k, :], *grids, zero_edges, 0.0) for k in range(psi.size)],
        v.shape[-1],
        dtype,
    )
    edges = tuple(bool(x) for x in zero_edges)
    return AnisotropicTable(slices, psi, edges)  # type: ignore[arg-type]


def plan_step(materials: Sequence[str], tables: Mapping[int, AnisotropicTable]) -> tuple[str, str]:
    """The plan's line for its anisotropic tables.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.kernels.anisotropic import pack_anisotropic, plan_step
    >>> g = np.array([0.0, 90.0])
    >>> brushed = pack_anisotropic(np.ones((2, 2, 2, 3, 1)), g, g - 90, g, np.array([0, 60, 120]))
    >>> name, text = plan_step(["paint", "brushed"], {1: brushed})
    >>> name, text[: text.index(":")]
    ('anisotropy', 'brushed (3 psi nodes)')
    """
    what = ", ".join(f"{materials[m]} ({t.psi.size} psi nodes)" for m, t in sorted(tables.items()))
    return (
        "anisotropy",
        f"{what}: psi of every term from its tangent, linear and periodic in psi over "
        "isotropic look-ups of the psi slices (terms merged only with equal tangents)",
    )


def _slice(table: AnisotropicTable, k: int) -> tuple[np.ndarray, tuple[np.ndarray, ...]]:
    p = table.slices
    values = p.values[k].reshape(*p.shapes[k], -1)
    grids = (
        p.tgrid[p.t_off[k] : p.t_off[k + 1]],
        p.dgrid[p.d_off[k] : p.d_off[k + 1]],
        p.pgrid[p.p_off[k] : p.p_off[k + 1]],
    )
    return values, grids


def anisotropic_sums(
    to_sun: NDArray[np.floating],
    to_observer: NDArray[np.floating],
    normals: NDArray[np.floating],
    tangents: NDArray[np.floating],
    areas: NDArray[np.floating],
    table: AnisotropicTable,
    method: str = "linear",
    fraction: NDArray[np.floating] | None = None,
    kernel: str = "numpy",
) -> MaterialSums:
    """Facet sums of paper 000 Eqs. 3-4 for one anisotropic material.

    Parameters
    ----------
    to_sun, to_observer : ndarray, shape (G, 3)
        Unit vectors to the Sun and the observer in the body frame [1].
    normals, tangents : ndarray, shape (F, 3)
        Unit facet normals and tangents [1] (tangents are made orthogonal to the
        normals).
    areas : ndarray, shape (F,)
        Facet areas [m2].
    table : AnisotropicTable
        From :func:`pack_anisotropic`.
    method : {"nearest", "linear", "cubic"}
        Look-up method in ``(theta_i, delta_theta, phi)``; ``psi`` is always linear
        (periodic).
    fraction : ndarray, shape (G, F), optional
        Lit-and-visible area fraction of each facet [1]; default 1.
    kernel : {"numpy", "fused"}
        :func:`sbrdf_xr.kernels.reference.material_sums` per slice (the reference), or
        compiled: for ``nearest`` and ``linear`` a dedicated ``nogil`` numba kernel
        (angles, ``psi``, the lit-and-visible test and the out-of-range policy per
        geometry and facet, then the two ``psi`` slices gathered; it is tested against
        the reference), for ``cubic`` one :func:`sbrdf_xr.kernels.sums.fused_sums` call
        over the slices (each clipped at zero as the reference).

    Returns
    -------
    MaterialSums
        In the dtype of the table; ``area`` and ``lit_visible_area`` in float64.

    Examples
    --------
    A table constant in the angles, 1, 2 and 3 sr-1 at ``psi`` = 0, 60 and 120 deg; two
    facets of 1 m2 facing ``+z`` with tangents ``+x`` and ``+y``, the Sun 45 deg towards
    ``-x`` and the observer at the specular direction.  The illumination plane runs along
    ``+x``: ``psi`` is 0 deg on the first facet (``f_r = 1``) and 90 deg on the second,
    halfway between 60 and 120 deg (``f_r = 2.5``); ``cos_i = cos_r = sqrt(0.5)``, so the
    signal is ``0.5 * (1 + 2.5)``:

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.anisotropic import anisotropic_sums, pack_anisotropic
    >>> g, d, p = np.array([0.0, 90]), np.array([-90.0, 90]), np.array([0.0, 180])
    >>> values = np.ones((2, 2, 2, 3, 1)) * np.array([1.0, 2.0, 3.0])[:, None]
    >>> table = pack_anisotropic(values, g, d, p, np.array([0.0, 60.0, 120.0]))
    >>> h = np.sqrt(0.5)
    >>> s, o = np.array([[-h, 0, h]]), np.array([[h, 0, h]])
    >>> normals, tangents = np.array([[0.0, 0, 1], [0, 0, 1]]), np.array([[1.0, 0, 0], [0, 1, 0]])
    >>> r = anisotropic_sums(s, o, normals, tangents, np.array([1.0, 1.0]), table)
    >>> r.signal.round(9).tolist(), r.area.round(6).tolist(), r.lit_visible_area.tolist()
    ([[1.75]], [1.414214], [2.0])
    >>> bool(np.allclose(r.paper, 3.5 * h))  # sum_j A_j cos_r f_r
    True

    A tangent turned by 180 deg is the same tangent (``psi`` has a period of 180 deg):

    >>> r2 = anisotropic_sums(s, o, normals, -tangents, np.array([1.0, 1.0]), table)
    >>> bool(np.allclose(r2.signal, r.signal))
    True
    """
    s = np.asarray(to_sun, dtype=np.float64)
    o = np.asarray(to_observer, dtype=np.float64)
    n = np.asarray(normals, dtype=np.float64)
    g, f = s.shape[0], n.shape[0]
    dt = table.slices.dtype
    n_wl = table.slices.n_spectral
    sig, pap = np.zeros((g, n_wl), dt), np.zeros((g, n_wl), dt)
    if f == 0 or g == 0:
        return MaterialSums(sig, pap, np.zeros(g), np.zeros(g))
    if kernel == "fused" and method != "cubic":
        return _compiled_sums(s, o, n, tangents, areas, table, method, fraction)
    cos_i, cos_r = s @ n.T, o @ n.T
    contributing = (cos_i > 0) & (cos_r > 0)
    base = np.where(contributing, 1.0, 0.0)
    if fraction is not None:
        base = base * np.asarray(fraction, dtype=np.float64)
    eff = base * np.asarray(areas, dtype=np.float64)[None, :]
    area, lit = (eff * cos_r).sum(axis=1), eff.sum(axis=1)
    psi = illumination_azimuth(
        n[None, :, :],
        np.asarray(tangents, dtype=np.float64)[None, :, :],
        s[:, None],
        o[:, None],
        check=False,
    )
    idx, w = psi_weights(table.psi, psi)  # (G, F, 2)
    w = w * base[..., None]
    used = np.unique(idx[w > 0])
    parts: list[tuple[int, np.ndarray, np.ndarray]] = []
    for k in used.tolist():
        wk = np.where(idx == k, w, 0.0).sum(axis=-1)
        cols = np.flatnonzero(wk.any(axis=0))
        parts.append((k, cols, wk[:, cols]))
    r: FusedSums | MaterialSums
    if kernel == "fused":
        if parts:
            r = fused_sums(
                s,
                o,
                np.concatenate([n[c] for _, c, _ in parts]),
                np.concatenate([np.asarray(areas)[c] for _, c, _ in parts]),
                np.concatenate([np.full(c.size, k, np.int64) for k, c, _ in parts]),
                table.slices,
                method,
                np.concatenate([wk for _, _, wk in parts], axis=1),
            )
            sig += r.signal
            pap += r.paper
    else:
        for k, cols, wk in parts:
            values, (tg, dg, pg) = _slice(table, k)
            r = material_sums(
                s,
                o,
                n[cols],
                np.asarray(areas)[cols],
                values,
                tg,
                dg,
                pg,
                method,
                wk,
                table.zero_edges,
                0.0,
            )
            sig += r.signal
            pap += r.paper
    return MaterialSums(sig, pap, area, lit)


@numba.njit(nogil=True, cache=True)
def _aniso_fused(s, o, facets, values, grids, psi, closed, opts, out):  # pragma: no cover
    """One anisotropic material, nearest or linear in the angles, linear in psi: the
    slices share the grids of material 0 of ``grids``."""
    # the bundles unpacked once: the loops below hand plain arrays to the helpers
    normals, area, _, _, tangents, frac = facets
    tgrid, t_off, dgrid, d_off, pgrid, p_off, edges, _, bmap, b_off, binv = grids
    method, tol, edge_tol = opts
    out_sig, out_pap, out_area, out_lit = out
    has_frac = frac.shape[0] > 0
    idx = np.empty((3, 4), dtype=np.int64)
    w = np.empty((3, 4))
    rows = np.empty(8, dtype=np.int64)
    wn = np.empty(8, dtype=out_sig.dtype)
    f = np.empty(out_sig.shape[1], dtype=out_sig.dtype)
    axes = _material_axes(t_off, d_off, p_off, b_off, binv, 0)
    limits = _range_limits(dgrid, pgrid, axes, edges, 0)
    for g in range(s.shape[0]):
        sg = (s[g, 0], s[g, 1], s[g, 2])
        og = (o[g, 0], o[g, 1], o[g, 2])
        for tt in range(normals.shape[0]):
            n = (normals[tt, 0], normals[tt, 1], normals[tt, 2])
            ns = n[0] * sg[0] + n[1] * sg[1] + n[2] * sg[2]
            no = n[0] * og[0] + n[1] * og[1] + n[2] * og[2]
            if not (ns > 0.0 and no > 0.0):
                continue
            a_eff = area[tt] * frac[g, tt] if has_frac else area[tt]
            a2d = a_eff * no  # a_2D = a c cos(theta_r)
            out_area[g] += a2d
            out_lit[g] += a_eff
            ti, dt, phi, e, op = facet_frame(n, sg, og, ns, no, tol)
            if _outside(limits, dt, phi, edge_tol):
                continue
            tangent = (tangents[tt, 0], tangents[tt, 1], tangents[tt, 2])
            k0, k1, w1 = _psi_cell(psi, closed, tangent_azimuth(n, tangent, e, op, tol))
            nk = _lookup_rows(
                tgrid, dgrid, pgrid, bmap, axes, ti, dt, phi, method, idx, w, rows, wn, 1.0
            )
            sig, pap = out_sig[g], out_pap[g]
            if w1 < 1.0:
                w0 = 1.0 - w1
                _gather(values[k0], rows, wn, nk, f, sig, pap, a2d * ns * w0, a2d * w0)
            if w1 > 0.0:
                _gather(values[k1], rows, wn, nk, f, sig, pap, a2d * ns * w1, a2d * w1)


def _compiled_sums(s, o, n, tangents, areas, table, method, fraction):
    """:func:`anisotropic_sums` with ``kernel="fused"`` and nearest or linear look-up."""
    p = table.slices
    g = s.shape[0]
    out = MaterialSums(
        np.zeros((g, p.n_spectral), p.dtype),
        np.zeros((g, p.n_spectral), p.dtype),
        np.zeros(g),
        np.zeros(g),
    )
    psi = np.ascontiguousarray(table.psi, dtype=np.float64)
    closed = bool(psi.size > 1 and np.isclose(psi[-1] - psi[0], PSI_PERIOD, rtol=0.0, atol=1e-9))
    facets = Facets.of(n, areas, tangent=tangents, fraction=fraction)
    opts = KernelOptions(
        METHOD_CODES[method], normal_incidence_tolerance(np.float64), _lut.EDGE_TOL_DEG
    )
    s, o = np.ascontiguousarray(s), np.ascontiguousarray(o)
    _aniso_fused(s, o, facets, typed_values(p), p.grids, psi, closed, opts, out)
    return out


@runtime_checkable
class FacetTerms(Protocol):
    """The facet terms :func:`anisotropic_reflected` evaluates
    (:class:`sbrdf_xr.engine.plan.Terms` is one): unit normals (T, 3) [1], areas (T,) [m2],
    material indices (T,) and, with
    anisotropic materials, unit tangents (T, 3) [1].

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0], material="grey")
    >>> plan = Scene(box, {"grey": grey}, to_sun=[[1, 0, 0]], to_observer=[[1, 0, 0]]).plan()
    >>> isinstance(plan.terms, FacetTerms)
    True
    """

    @property
    def normal(self) -> np.ndarray: ...
    @property
    def area(self) -> np.ndarray: ...
    @property
    def material(self) -> np.ndarray: ...
    @property
    def tangent(self) -> np.ndarray | None: ...


@runtime_checkable
class TablePlan(Protocol):
    """What :func:`anisotropic_reflected` reads of a compiled plan
    (:class:`sbrdf_xr.engine.plan.Plan` is one): its facet terms, material names, packed
    tables, knobs (``method``,
    ``kernel``), anisotropic tables by material index, and each table unpacked.

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0], material="grey")
    >>> plan = Scene(box, {"grey": grey}, to_sun=[[1, 0, 0]], to_observer=[[1, 0, 0]]).plan()
    >>> isinstance(plan, TablePlan)
    True
    """

    @property
    def terms(self) -> FacetTerms: ...
    @property
    def materials(self) -> tuple[str, ...]: ...
    @property
    def tables(self) -> PackedTables: ...
    @property
    def knobs(self) -> Mapping[str, Any]: ...
    @property
    def anisotropic(self) -> Mapping[int, AnisotropicTable]: ...
    def table(
        self, m: int
    ) -> tuple[
        np.ndarray, tuple[np.ndarray, np.ndarray, np.ndarray], tuple[bool, bool, bool], float
    ]: ...


def anisotropic_reflected(
    plan: TablePlan,
    to_source: NDArray[np.floating],
    to_observer: NDArray[np.floating],
    fraction: NDArray[np.floating] | None,
    per_material: bool,
) -> FusedSums:
    """Facet sums of a plan that has anisotropic tables (``plan.anisotropic``).

    The isotropic materials' terms run through the plan's kernel exactly as without
    anisotropic ones (``fused`` over all of them at once, or the numpy reference per
    material); each anisotropic material through :func:`anisotropic_sums` with the
    terms' tangents (``plan.terms.tangent``).

    Parameters
    ----------
    plan : sbrdf_xr.engine.plan.Plan
        A compiled plan with table evaluation.
    to_source, to_observer : ndarray, shape (G, 3)
        Body-frame unit vectors to the source and the observer [1].
    fraction : ndarray, shape (G, T), optional
        Lit-and-visible fraction of each term [1].
    per_material : bool
        Also return each material's signal.

    Returns
    -------
    FusedSums

    Examples
    --------
    A unit cube with a Lambertian table of albedo 0.5 repeated over two ``psi`` nodes
    gives the isotropic sums: at phase 0 the ``+x`` face (1 m2) is lit and seen head on,
    ``0.5 / pi``; at phase 60 deg at 30 deg, ``0.5 / pi * cos(30 deg)**2``:

    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.kernels.anisotropic import anisotropic_reflected
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> grey = lambertian(0.5, [500.0, 600.0], material="grey")
    >>> brushed = grey.expand_dims(psi=[0.0, 90.0], axis=3)
    >>> brushed.psi.attrs["units"] = "degree"
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> scene = Scene(
    ...     box, {"grey": brushed}, attitudes=[[0, 0, 0, 1.0]], phase_angles=[0, 60], kernel="numpy"
    ... )
    >>> plan = scene.plan()
    >>> sorted(plan.anisotropic), plan.anisotropic[0].psi.tolist()
    ([0], [0.0, 90.0])
    >>> block = plan.geometry.block(slice(None))
    >>> r = anisotropic_reflected(plan, block.to_sun, block.to_observer, None, True)
    >>> r.signal.shape, r.per_material.shape  # (G, L), (G, M, L)
    ((2, 2), (2, 1, 2))
    >>> r.signal[:, 0].round(6).tolist(), r.area.round(6).tolist()
    ([0.159155, 0.119366], [1.0, 0.866025])
    """
    t = plan.terms
    aniso = plan.anisotropic
    method, kernel = plan.knobs["method"], plan.knobs["kernel"]
    g, n_wl, dt = to_source.shape[0], plan.tables.n_spectral, plan.tables.dtype
    sig, pap = np.zeros((g, n_wl), dt), np.zeros((g, n_wl), dt)
    area, lit = np.zeros(g), np.zeros(g)
    pm = np.zeros((g, len(plan.materials), n_wl), dt) if per_material else None
    iso = ~np.isin(t.material, np.array(list(aniso), dtype=np.int64))
    if iso.any() and kernel == "fused":
        fr = fused_sums(
            to_source,
            to_observer,
            t.normal[iso],
            t.area[iso],
            t.material[iso],
            plan.tables,
            method,
            None if fraction is None else fraction[:, iso],
            per_material,
        )
        sig += fr.signal
        pap += fr.paper
        area += fr.area
        lit += fr.lit_visible_area
        if pm is not None and fr.per_material is not None:
            pm += fr.per_material
    for m in range(len(plan.materials)):
        sel = t.material == m
        if not sel.any() or (m not in aniso and kernel == "fused"):
            continue
        frac = None if fraction is None else fraction[:, sel]
        if m in aniso:
            if t.tangent is None:
                raise SceneError(
                    f"material {plan.materials[m]!r} is anisotropic but the plan's facet "
                    "terms carry no tangents; give the spacecraft facet tangents"
                )
            r = anisotropic_sums(
                to_source,
                to_observer,
                t.normal[sel],
                t.tangent[sel],
                t.area[sel],
                aniso[m],
                method,
                frac,
                kernel,
            )
        else:
            values, (tg, dg, pg), edges, blend = plan.table(m)
            r = material_sums(
                to_source,
                to_observer,
                t.normal[sel],
                t.area[sel],
                values,
                tg,
                dg,
                pg,
                method,
                frac,
                edges,
                blend,
            )
        sig += r.signal
        pap += r.paper
        area += r.area
        lit += r.lit_visible_area
        if pm is not None:
            pm[:, m] += r.signal
    return FusedSums(sig, pap, area, lit, pm)


#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(__name__, globals(), {"reflected": "anisotropic_reflected"})
