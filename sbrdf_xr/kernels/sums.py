"""The fused kernel of the spacecraft sum of paper 000 §3.4 (Eqs. 3-4).

:func:`fused_sums` computes the sums that :func:`sbrdf_xr.kernels.reference.material_sums`
specifies (its docstring states them: the signal, the numerator and the denominator of
Eq. 4, over the lit and visible facets) for all materials of a block in one compiled
pass (numba, ``nogil`` so that threads run blocks in parallel): angles, the
lit-and-visible test before any look-up, the out-of-range policy, the interpolation
weights and the accumulation straight into the outputs, in the table's dtype (float32
stays float32).
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
from numpy.typing import NDArray

from ..geometry import normal_incidence_tolerance
from . import lut as _lut
from .angles import _RAD2DEG, chunk_angles, facet_frame
from .lookup import _axis, _cell, _gather, _gather8
from .packing import PackedTables, pack_tables, typed_values
from .reference import MaterialSums, material_sums

__all__ = [
    "METHOD_CODES",
    "FusedSums",
    "MaterialSums",
    "PackedTables",
    "fused_sums",
    "material_sums",
    "normal_rows",
    "pack_tables",
]


# ---------------------------------------------------------------- fused kernel
#
# One compiled pass over (geometry x term) for a block: the angles exactly as
# geometry.facet_angles (arctan2 throughout, the same normal-incidence rule), the
# lit/visible test before any look-up, the out-of-range policy of
# _lut.lookup_matrix, the interpolation weights of _lut.axis_weights, and the
# accumulation of the outputs of material_sums.  material_sums above is its
# specification; tests/test_kernels.py checks one against the other.

#: Look-up method codes of the fused kernel.
METHOD_CODES: dict[str, int] = {"nearest": 0, "linear": 1, "cubic": 2}

#: Geometries per chunk of the fused kernel's vectorised angle stage.
_CHUNK = 64


@numba.njit(nogil=True, cache=True)
def _fused_sums(
    s,
    o,
    normals,
    uniq,
    areas,
    term_mat,
    frac,
    tables,
    tgrid,
    t_off,
    dgrid,
    d_off,
    pgrid,
    p_off,
    edges,
    blend,
    bmap,
    b_off,
    binv,
    method,
    tol,
    edge_tol,
    out_sig,
    out_pap,
    out_area,
    out_lit,
    out_pm,
):  # pragma: no cover - compiled
    n_geom = s.shape[0]
    n_term = normals.shape[0]
    n_wl = out_sig.shape[1]
    has_frac = frac.shape[0] > 0
    want_pm = out_pm.shape[0] > 0
    f = np.empty(n_wl, dtype=out_sig.dtype)
    acc_s = np.empty(n_wl, dtype=out_sig.dtype)
    acc_p = np.empty(n_wl, dtype=out_sig.dtype)
    wbuf = np.empty(2, dtype=out_sig.dtype)
    rows = np.empty(96, dtype=np.int64)
    wn = np.empty(96, dtype=out_sig.dtype)
    it = np.empty(4, dtype=np.int64)
    idt = np.empty(4, dtype=np.int64)
    iph = np.empty(4, dtype=np.int64)
    wt = np.empty(4)
    wdt = np.empty(4)
    wph = np.empty(4)
    bt, bd, bp = bmap[0], bmap[1], bmap[2]
    # stage 1 (chunk_angles): the angles of a chunk of geometries against every term in
    # one vectorised pass; stage 2: per material of the chunk, per geometry, the look-ups
    # of its lit and seen pairs (terms in order, so that terms of one face read the same
    # table rows from cache).  Each output element receives its terms in term order, as
    # in material_sums, whatever the chunking.
    s_t = np.ascontiguousarray(s.T)
    o_t = np.ascontiguousarray(o.T)
    n_chunk = min(_CHUNK, n_geom)
    # the angles depend on the normal only: terms of one face (its materials) share a row
    u_norm = np.empty((uniq.max() + 1, 3))
    for tt in range(n_term):
        u_norm[uniq[tt]] = normals[tt]
    n_u = u_norm.shape[0]
    b_ns = np.empty((n_u, n_chunk))
    b_no = np.empty((n_u, n_chunk))
    b_st = np.empty((n_u, n_chunk))
    b_ti = np.empty((n_u, n_chunk))
    b_dt = np.empty((n_u, n_chunk))
    b_ph = np.empty((n_u, n_chunk))
    for c0 in range(0, n_geom, _CHUNK):
        nc = min(_CHUNK, n_geom - c0)
        chunk_angles(s_t, o_t, c0, nc, u_norm, b_ns, b_no, b_st, b_ti, b_dt, b_ph)
        t = 0
        while t < n_term:
            m = term_mat[t]
            stop = t
            while stop < n_term and term_mat[stop] == m:
                stop += 1
            values = tables[m]  # once per chunk and material (an item of a typed list costs)
            d0 = d_off[m]
            nd = d_off[m + 1] - d0
            p0 = p_off[m]
            npp = p_off[m + 1] - p0
            t0 = t_off[m]
            nt = t_off[m + 1] - t0
            bt0, nbt, bit = b_off[0, m], b_off[0, m + 1] - b_off[0, m], binv[0, m]
            bd0, nbd, bid = b_off[1, m], b_off[1, m + 1] - b_off[1, m], binv[1, m]
            bp0, nbp, bip = b_off[2, m], b_off[2, m + 1] - b_off[2, m], binv[2, m]
            linear8 = method == 1 and nt > 1 and nd > 1 and npp > 1
            # the material's edges: delta_theta below, above; phi above; the blend width
            e_dlo, e_dhi, e_phi = edges[m, 0], edges[m, 1], edges[m, 2]
            d_lo, d_hi, p_hi = dgrid[d0], dgrid[d0 + nd - 1], pgrid[p0 + npp - 1]
            b_m = blend[m] if tgrid[t0] == 0.0 else 0.0
            for j in range(nc):
                g = c0 + j
                any_lookup = False
                for tt in range(t, stop):
                    u = uniq[tt]
                    ns = b_ns[u, j]
                    no = b_no[u, j]
                    if not (ns > 0.0 and no > 0.0):
                        continue
                    a_eff = areas[tt]
                    if has_frac:
                        a_eff = a_eff * frac[g, tt]
                    a2d = a_eff * no
                    out_area[g] += a2d
                    out_lit[g] += a_eff
                    # angles of paper 000 Fig. 4, as geometry.facet_angles
                    if b_st[u, j] > tol:
                        ti, dt, phi = b_ti[u, j], b_dt[u, j], b_ph[u, j]
                    else:  # normal incidence: the plane through the observer or an axis
                        ti, dt, phi, _, _, _, _ = facet_frame(
                            normals[tt, 0],
                            normals[tt, 1],
                            normals[tt, 2],
                            s[g, 0],
                            s[g, 1],
                            s[g, 2],
                            o[g, 0],
                            o[g, 1],
                            o[g, 2],
                            ns,
                            no,
                            tol,
                        )
                    outside = (
                        (e_dlo and dt < d_lo - edge_tol)
                        or (e_dhi and dt > d_hi + edge_tol)
                        or (e_phi and phi > p_hi + edge_tol)
                    )
                    # normal-incidence blend (_lut.lookup_matrix): weight of the theta_i = 0 profile
                    w_n = 0.0
                    if b_m > 0.0 and ti < b_m:
                        x = ti / b_m
                        if x < 0.0:
                            x = 0.0
                        w_n = 1.0 - x * x * (3.0 - 2.0 * x)
                    if linear8 and w_n == 0.0 and not outside:
                        # linear in all three axes, no blend: the 8 rows straight from the cells
                        i0, u0 = _cell(tgrid, t0, nt, ti, bt, bt0, nbt, bit)
                        i1, u1 = _cell(dgrid, d0, nd, dt, bd, bd0, nbd, bid)
                        i2, u2 = _cell(pgrid, p0, npp, phi, bp, bp0, nbp, bip)
                        r = (i0 * nd + i1) * npp + i2
                        wa0, wa1 = 1.0 - u0, u0
                        wb0, wb1 = 1.0 - u1, u1
                        wc0, wc1 = 1.0 - u2, u2
                        w00, w01, w10, w11 = wa0 * wb0, wa0 * wb1, wa1 * wb0, wa1 * wb1
                        wn[0], wn[1], wn[2], wn[3] = w00 * wc0, w00 * wc1, w01 * wc0, w01 * wc1
                        wn[4], wn[5], wn[6], wn[7] = w10 * wc0, w10 * wc1, w11 * wc0, w11 * wc1
                        if not any_lookup:
                            acc_s[:] = 0.0
                            acc_p[:] = 0.0
                            any_lookup = True
                        wbuf[0] = a2d * ns
                        wbuf[1] = a2d
                        _gather8(values, r, npp, nd * npp, wn, acc_s, acc_p, wbuf[0], wbuf[1])
                        continue
                    nk = 0
                    if not outside and w_n < 1.0:
                        kt = _axis(tgrid, t0, nt, ti, method, it, wt, bt, bt0, nbt, bit)
                        kd = _axis(dgrid, d0, nd, dt, method, idt, wdt, bd, bd0, nbd, bid)
                        kp = _axis(pgrid, p0, npp, phi, method, iph, wph, bp, bp0, nbp, bip)
                        for a in range(kt):
                            for b in range(kd):
                                row0 = (it[a] * nd + idt[b]) * npp
                                wab = wt[a] * wdt[b] * (1.0 - w_n)
                                for c in range(kp):
                                    rows[nk] = row0 + iph[c]
                                    wn[nk] = wab * wph[c]
                                    nk += 1
                    if w_n > 0.0:
                        # the theta_i = 0 row along its in-plane profile at +-gamma, the angle from
                        # the specular direction (_lut.observer_polar_angle(0, dt, phi))
                        pr = phi / _RAD2DEG
                        tr = dt / _RAD2DEG
                        cp = np.cos(pr)
                        gam = (
                            np.arctan2(np.hypot(np.sin(pr), cp * np.sin(tr)), abs(cp * np.cos(tr)))
                            * _RAD2DEG
                        )
                        ok_hi = (gam <= d_hi + edge_tol) or not e_dhi
                        ok_lo = (-gam >= d_lo - edge_tol) or not e_dlo
                        n_ok = (1 if ok_hi else 0) + (1 if ok_lo else 0)
                        if n_ok > 0:
                            base_w = w_n / n_ok
                            kp = _axis(pgrid, p0, npp, 0.0, method, iph, wph, bp, bp0, nbp, bip)
                            for side in range(2):
                                if (side == 0 and not ok_hi) or (side == 1 and not ok_lo):
                                    continue
                                kd = _axis(
                                    dgrid,
                                    d0,
                                    nd,
                                    gam if side == 0 else -gam,
                                    method,
                                    idt,
                                    wdt,
                                    bd,
                                    bd0,
                                    nbd,
                                    bid,
                                )
                                for b in range(kd):
                                    for c in range(kp):
                                        rows[nk] = idt[b] * npp + iph[c]
                                        wn[nk] = base_w * wdt[b] * wph[c]
                                        nk += 1
                    if nk == 0:
                        continue
                    if not any_lookup:
                        acc_s[:] = 0.0
                        acc_p[:] = 0.0
                        any_lookup = True
                    wbuf[0] = a2d * ns
                    wbuf[1] = a2d
                    ws = wbuf[0]
                    wp = wbuf[1]
                    _gather(values, rows, wn, nk, f, acc_s, acc_p, ws, wp)
                if any_lookup:
                    if method == 2:
                        for k in range(n_wl):
                            if acc_s[k] < 0.0:
                                acc_s[k] = 0.0
                            if acc_p[k] < 0.0:
                                acc_p[k] = 0.0
                    for k in range(n_wl):
                        out_sig[g, k] += acc_s[k]
                        out_pap[g, k] += acc_p[k]
                    if want_pm:
                        for k in range(n_wl):
                            out_pm[g, m, k] += acc_s[k]
            t = stop


def normal_rows(normals: NDArray[np.floating]) -> NDArray[np.int64]:
    """The row of each term's normal among the distinct ones: terms whose normals are
    bit-identical (one face, several materials) share the fused kernel's angles.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.kernels.sums import normal_rows
    >>> rows = normal_rows(np.array([[0.0, 0, 1], [1, 0, 0], [0, 0, 1]]))
    >>> bool(rows[0] == rows[2] != rows[1]), sorted(set(rows.tolist()))
    (True, [0, 1])
    """
    nrm = np.ascontiguousarray(normals, dtype=np.float64)
    _, inverse = np.unique(nrm.view(np.dtype((np.void, 24))).ravel(), return_inverse=True)
    return inverse.astype(np.int64).ravel()


class FusedSums(NamedTuple):
    """Outputs of :func:`fused_sums` for a block of geometries.

    Examples
    --------
    The fields of :class:`~sbrdf_xr.kernels.reference.MaterialSums` and the signal of each
    material, ``None`` unless asked for (a block without terms, so nothing to compile):

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.sums import FusedSums, fused_sums, pack_tables
    >>> g = np.array([0.0, 90.0])
    >>> tables = pack_tables([(np.ones((2, 2, 2, 3)), g, g - 90, g, (True, True, True))])
    >>> s = o = np.array([[0.0, 0, 1], [1, 0, 0]])
    >>> no_terms = np.empty((0, 3)), np.empty(0), np.empty(0, dtype=np.int64)
    >>> FusedSums._fields
    ('signal', 'paper', 'area', 'lit_visible_area', 'per_material')
    >>> fused_sums(s, o, *no_terms, tables).per_material is None
    True
    >>> r = fused_sums(s, o, *no_terms, tables, per_material=True)
    >>> r.signal.shape, r.per_material.shape  # (G, L), (G, M, L)
    ((2, 3), (2, 1, 3))
    """

    signal: NDArray[np.floating]  #: (G, L) [m2 sr-1]
    paper: NDArray[np.floating]  #: (G, L) [m2 sr-1]
    area: NDArray[np.float64]  #: (G,) [m2]
    lit_visible_area: NDArray[np.float64]  #: (G,) [m2]
    per_material: NDArray[np.floating] | None  #: (G, M, L) [m2 sr-1]


def fused_sums(
    to_sun: NDArray[np.floating],
    to_observer: NDArray[np.floating],
    normals: NDArray[np.floating],
    areas: NDArray[np.floating],
    term_material: NDArray[np.integer],
    tables: PackedTables,
    method: str = "linear",
    fraction: NDArray[np.floating] | None = None,
    per_material: bool = False,
    rows: NDArray[np.int64] | None = None,
) -> FusedSums:
    """The facet sums of :func:`material_sums`, over all materials at once, compiled.

    Parameters
    ----------
    to_sun, to_observer : ndarray, shape (G, 3)
        Unit vectors in the body frame [1] (computed in float64).
    normals : ndarray, shape (T, 3)
        Unit term normals [1].
    areas : ndarray, shape (T,)
        Term areas [m2].
    term_material : ndarray of int, shape (T,)
        Material index of each term into ``tables``; terms of one material must be
        contiguous (sorted).
    tables : PackedTables
        From :func:`pack_tables`; its dtype is the dtype of the spectral outputs.
    method : {"nearest", "linear", "cubic"}
        Look-up method.
    fraction : ndarray, shape (G, T), optional
        Lit-and-visible area fraction of each term [1].
    per_material : bool
        Also return the signal of each material.
    rows : ndarray of int, shape (T,), optional
        :func:`normal_rows` of ``normals``, when the caller keeps it (a plan's terms do);
        computed here otherwise.

    Returns
    -------
    FusedSums
        The spectral sums in the dtype of the tables (no promotion of float32);
        ``area`` and ``lit_visible_area`` in float64.  For ``cubic`` each material's
        sums are clipped at 0 as in :func:`material_sums`.

    Examples
    --------
    The terms must come sorted by material, and a float32 packing gives float32 sums (a
    block without terms returns zeros without running the compiled kernel):

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.sums import fused_sums, pack_tables
    >>> g = np.array([0.0, 90.0])
    >>> one = (np.ones((2, 2, 2, 3)), g, g - 90, g, (True, True, True))
    >>> tables = pack_tables([one, one], dtype=np.float32)
    >>> s = o = np.array([[0.0, 0, 1]])
    >>> normals = np.array([[0.0, 0, 1], [0, 0, 1]])
    >>> fused_sums(s, o, normals, np.ones(2), np.array([1, 0]), tables)
    Traceback (most recent call last):
        ...
    ValueError: term_material: terms of one material must be contiguous (sorted)
    >>> r = fused_sums(s, o, np.empty((0, 3)), np.empty(0), np.empty(0, dtype=np.int64), tables)
    >>> r.signal.dtype, r.area.dtype, r.signal.tolist()
    (dtype('float32'), dtype('float64'), [[0.0, 0.0, 0.0]])
    """
    tm = np.ascontiguousarray(term_material, dtype=np.int64)
    if tm.size and np.any(np.diff(tm) < 0):
        raise ValueError("term_material: terms of one material must be contiguous (sorted)")
    s = np.ascontiguousarray(to_sun, dtype=np.float64)
    o = np.ascontiguousarray(to_observer, dtype=np.float64)
    g = s.shape[0]
    n_wl = tables.n_spectral
    dt = tables.dtype
    n_mat = tables.edges.shape[0]
    out_sig = np.zeros((g, n_wl), dtype=dt)
    out_pap = np.zeros((g, n_wl), dtype=dt)
    out_area = np.zeros(g)
    out_lit = np.zeros(g)
    out_pm = np.zeros((g, n_mat, n_wl) if per_material else (0, 0, 0), dtype=dt)
    frac = (
        np.zeros((0, 0)) if fraction is None else np.ascontiguousarray(fraction, dtype=np.float64)
    )
    if g and normals.shape[0]:
        typed = typed_values(tables)
        nrm = np.ascontiguousarray(normals, dtype=np.float64)
        _fused_sums(
            s,
            o,
            nrm,
            normal_rows(nrm) if rows is None else rows,
            np.ascontiguousarray(areas, dtype=np.float64),
            tm,
            frac,
            typed,
            tables.tgrid,
            tables.t_off,
            tables.dgrid,
            tables.d_off,
            tables.pgrid,
            tables.p_off,
            tables.edges,
            tables.blend,
            tables.bmap,
            tables.b_off,
            tables.binv,
            METHOD_CODES[method],
            normal_incidence_tolerance(np.float64),
            _lut.EDGE_TOL_DEG,
            out_sig,
            out_pap,
            out_area,
            out_lit,
            out_pm,
        )
    return FusedSums(out_sig, out_pap, out_area, out_lit, out_pm if per_material else None)
