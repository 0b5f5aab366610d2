"""Facet sums for anisotropic materials: tables with a ``psi`` axis.

An anisotropic table (dims ``(theta_i, delta_theta, phi, psi, wavelength)``) is a
stack of isotropic tables, one per ``psi`` node (:mod:`sbrdf_xr.anisotropy`).  The
look-up interpolates each slice in ``(theta_i, delta_theta, phi)`` with the isotropic
method and the slices linearly and periodically in ``psi``.  The facet sums of
paper 000 Eqs. 3-4 are linear in ``f_r``, so

``sum_j a_j f_r(g, j) = sum_k sum_j (a_j w_k(g, j)) f_k(g, j)``

with ``w_k(g, j)`` the ``psi`` weight of node ``k`` (two non-zero per geometry and
facet, summing to one) and ``f_k`` the look-up in slice ``k``: each slice is an
isotropic material whose facets carry the extra area fraction ``w_k``.  That is
how the isotropic kernels are reused here, without a change: :func:`anisotropic_sums`
calls :func:`sbrdf_xr._kernels.material_sums` (the numpy reference) once per slice
that any facet needs, or :func:`sbrdf_xr._kernels.fused_sums` (compiled, ``nogil``)
once over the slices packed as materials.  Consequences, stated once:

* no normal-incidence blend (an anisotropic material depends on the observer's
  azimuth from the tangent at ``theta_i = 0``);
* with ``cubic`` look-up each slice's sums are clipped at zero (as each isotropic
  material's are);
* the cost is that of an isotropic look-up per slice the block needs (at most the
  number of ``psi`` nodes), so a table with ``n_psi`` nodes costs up to ``n_psi``
  times an isotropic one.

:func:`reflected` is the hook the engine calls for a plan with anisotropic tables:
isotropic materials go through the plan's kernel as before, anisotropic ones through
:func:`anisotropic_sums`.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from ._kernels import FusedSums, MaterialSums, PackedTables, fused_sums, material_sums, pack_tables
from .anisotropy import illumination_azimuth, psi_weights

__all__ = ["AnisotropicTable", "anisotropic_sums", "pack_anisotropic", "plan_step", "reflected"]


class AnisotropicTable(NamedTuple):
    """An anisotropic table as the kernels read it: one packed isotropic table per ``psi``."""

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
    dtype: np.dtype | str = np.float64,
) -> AnisotropicTable:
    """Pack a ``(n_theta, n_delta_theta, n_phi, n_psi, L)`` table (once per plan).

    Parameters
    ----------
    values : ndarray, shape (n_theta, n_delta_theta, n_phi, n_psi, L)
        sBRDF [sr-1] (or its band integrals).
    theta_grid, delta_theta_grid, phi_grid, psi_grid : ndarray
        Table coordinates [degree].
    zero_edges : tuple of 3 bool
        Out-of-range policy (:func:`sbrdf_xr._lut.lookup_matrix`).
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


def plan_step(materials: Any, tables: dict[int, AnisotropicTable]) -> tuple[str, str]:
    """The plan's line for its anisotropic tables."""
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
        :func:`sbrdf_xr._kernels.material_sums` per slice (the reference) or one
        :func:`sbrdf_xr._kernels.fused_sums` call over the slices.

    Returns
    -------
    MaterialSums
        In the dtype of the table; ``area`` and ``lit_visible_area`` in float64.
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
            values, grids = _slice(table, k)
            r = material_sums(
                s,
                o,
                n[cols],
                np.asarray(areas)[cols],
                values,
                *grids,
                method,
                wk,
                table.zero_edges,
                0.0,
            )
            sig += r.signal
            pap += r.paper
    return MaterialSums(sig, pap, area, lit)


def reflected(
    plan: Any,
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
    plan : sbrdf_xr.plan.Plan
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
        r = fused_sums(
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
        sig += r.signal
        pap += r.paper
        area += r.area
        lit += r.lit_visible_area
        if pm is not None:
            pm += r.per_material
    for m in range(len(plan.materials)):
        sel = t.material == m
        if not sel.any() or (m not in aniso and kernel == "fused"):
            continue
        frac = None if fraction is None else fraction[:, sel]
        if m in aniso:
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
            values, grids, edges, blend = plan.table(m)
            r = material_sums(
                to_source,
                to_observer,
                t.normal[sel],
                t.area[sel],
                values,
                *grids,
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
