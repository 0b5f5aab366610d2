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

from typing import Any, NamedTuple, cast

import numba
import numpy as np
from numpy.typing import NDArray

from ..geometry import normal_incidence_tolerance
from . import lut as _lut
from .angles import _RAD2DEG, chunk_angles, facet_frame
from .lookup import (
    _axis,
    _cell,
    _gather,
    _gather8,
    _lookup_rows,
    _material_axes,
    _outside,
    _range_limits,
)
from .packing import Facets, KernelOptions, PackedTables, typed_values

__all__ = ["METHOD_CODES", "BoundSums", "FusedSums", "fused_sums", "normal_rows"]


# ---------------------------------------------------------------- fused kernel
#
# One compiled pass over (geometry x term) for a block: the angles of angles.py (the
# convention of geometry.facet_angles), the lit/visible test before any look-up, the
# out-of-range policy and interpolation weights of lookup.py (those of
# lut.lookup_matrix and lut.axis_weights), and the accumulation of the outputs of
# reference.material_sums, its specification (tests/kernels/test_kernels.py checks one
# against the other).

#: Look-up method codes of the fused kernel.
METHOD_CODES: dict[str, int] = {"nearest": 0, "linear": 1, "cubic": 2}

#: Geometries per chunk of the fused kernel's vectorised angle stage.
_CHUNK = 64


@numba.njit(nogil=True, cache=True, inline="always")
def _blend_weight(b_m: float, ti: float) -> float:  # pragma: no cover - compiled
    """Weight of the ``theta_i = 0`` profile in the normal-incidence blend of width
    ``b_m`` [degree] (``lut.lookup_matrix``)."""
    if b_m > 0.0 and ti < b_m:
        x = ti / b_m
        if x < 0.0:
            x = 0.0
        return 1.0 - x * x * (3.0 - 2.0 * x)
    return 0.0


@numba.njit(nogil=True, cache=True, inline="always")
def _blend_rows(
    dgrid, pgrid, bmap, axes, edges, m, dt, phi, method, idx, w, rows, wn, w_n, nk, edge_tol
):  # pragma: no cover - compiled
    """Append the rows of the normal-incidence blend: the ``theta_i = 0`` row along its
    in-plane profile at ``+-gamma``, the angle from the specular direction
    (``lut.observer_polar_angle(0, dt, phi)``), weight ``w_n`` shared by the sides in
    range; returns the new count."""
    pr = phi / _RAD2DEG
    tr = dt / _RAD2DEG
    cp = np.cos(pr)
    gam = np.arctan2(np.hypot(np.sin(pr), cp * np.sin(tr)), abs(cp * np.cos(tr))) * _RAD2DEG
    d = axes[1]
    ok_hi = (gam <= dgrid[d.lo + d.n - 1] + edge_tol) or not edges[m, 1]
    ok_lo = (-gam >= dgrid[d.lo] - edge_tol) or not edges[m, 0]
    n_ok = (1 if ok_hi else 0) + (1 if ok_lo else 0)
    if n_ok == 0:
        return nk
    base_w = w_n / n_ok
    npp = axes[2].n
    kp = _axis(pgrid, bmap, axes[2], 0.0, method, idx, w)
    for side in range(2):
        if (side == 0 and not ok_hi) or (side == 1 and not ok_lo):
            continue
        kd = _axis(dgrid, bmap, d, gam if side == 0 else -gam, method, idx, w)
        for b in range(kd):
            for c in range(kp):
                rows[nk] = idx[1, b] * npp + idx[2, c]
                wn[nk] = base_w * w[1, b] * w[2, c]
                nk += 1
    return nk


@numba.njit(nogil=True, cache=True)
def _fused_sums(s, o, facets, values, grids, opts, out):  # pragma: no cover - compiled
    # the bundles unpacked once: the loops below hand plain arrays to the helpers
    normals, area, term_mat, uniq, _, frac = facets
    tgrid, t_off, dgrid, d_off, pgrid, p_off, edges, blend, bmap, b_off, binv = grids
    method, tol, edge_tol = opts
    out_sig, out_pap, out_area, out_lit, out_pm = out
    n_geom = s.shape[0]
    n_term = normals.shape[0]
    n_wl = out_sig.shape[1]
    has_frac = frac.shape[0] > 0
    want_pm = out_pm.shape[0] > 0
    dtype = out_sig.dtype
    idx = np.empty((3, 4), dtype=np.int64)
    w = np.empty((3, 4))
    rows = np.empty(96, dtype=np.int64)
    wn = np.empty(96, dtype=dtype)
    f = np.empty(n_wl, dtype=dtype)
    acc_s = np.empty(n_wl, dtype=dtype)
    acc_p = np.empty(n_wl, dtype=dtype)
    # the pair's weights rounded to the tables' dtype, as the reference weights them
    wbuf = np.empty(2, dtype=dtype)
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
            vals = values[m]  # once per chunk and material (an item of a typed list costs)
            axes = _material_axes(t_off, d_off, p_off, b_off, binv, m)
            nd, npp = axes[1].n, axes[2].n
            linear8 = method == 1 and axes[0].n > 1 and nd > 1 and npp > 1
            b_m = blend[m] if tgrid[axes[0].lo] == 0.0 else 0.0
            limits = _range_limits(dgrid, pgrid, axes, edges, m)
            for j in range(nc):
                g = c0 + j
                any_lookup = False
                for tt in range(t, stop):
                    u = uniq[tt]
                    ns = b_ns[u, j]
                    no = b_no[u, j]
                    if not (ns > 0.0 and no > 0.0):
                        continue
                    a_eff = area[tt] * frac[g, tt] if has_frac else area[tt]
                    a2d = a_eff * no  # a_2D = a c cos(theta_r)
                    out_area[g] += a2d
                    out_lit[g] += a_eff
                    if b_st[u, j] > tol:
                        ti, dt, phi = b_ti[u, j], b_dt[u, j], b_ph[u, j]
                    else:  # normal incidence: the plane through the observer or an axis
                        ti, dt, phi, _, _ = facet_frame(
                            (normals[tt, 0], normals[tt, 1], normals[tt, 2]),
                            (s[g, 0], s[g, 1], s[g, 2]),
                            (o[g, 0], o[g, 1], o[g, 2]),
                            ns,
                            no,
                            tol,
                        )
                    outside = _outside(limits, dt, phi, edge_tol)
                    w_n = _blend_weight(b_m, ti)
                    wbuf[0] = a2d * ns
                    wbuf[1] = a2d
                    fast = linear8 and w_n == 0.0 and not outside
                    nk = 0
                    if not fast:
                        if not outside and w_n < 1.0:
                            nk = _lookup_rows(
                                tgrid, dgrid, pgrid, bmap, axes, ti, dt, phi, method, idx, w,
                                rows, wn, 1.0 - w_n,
                            )  # fmt: skip
                        if w_n > 0.0:
                            nk = _blend_rows(
                                dgrid, pgrid, bmap, axes, edges, m, dt, phi, method, idx, w,
                                rows, wn, w_n, nk, edge_tol,
                            )  # fmt: skip
                        if nk == 0:
                            continue
                    if not any_lookup:
                        acc_s[:] = 0.0
                        acc_p[:] = 0.0
                        any_lookup = True
                    if fast:
                        # linear in all three axes, no blend: the 8 rows straight from the cells
                        i0, u0 = _cell(tgrid, bmap, axes[0], ti)
                        i1, u1 = _cell(dgrid, bmap, axes[1], dt)
                        i2, u2 = _cell(pgrid, bmap, axes[2], phi)
                        r = (i0 * nd + i1) * npp + i2
                        wa0, wa1 = 1.0 - u0, u0
                        wb0, wb1 = 1.0 - u1, u1
                        wc0, wc1 = 1.0 - u2, u2
                        w00, w01, w10, w11 = wa0 * wb0, wa0 * wb1, wa1 * wb0, wa1 * wb1
                        wn[0], wn[1], wn[2], wn[3] = w00 * wc0, w00 * wc1, w01 * wc0, w01 * wc1
                        wn[4], wn[5], wn[6], wn[7] = w10 * wc0, w10 * wc1, w11 * wc0, w11 * wc1
                        _gather8(vals, r, npp, nd * npp, wn, acc_s, acc_p, wbuf[0], wbuf[1])
                    else:
                        _gather(vals, rows, wn, nk, f, acc_s, acc_p, wbuf[0], wbuf[1])
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


@numba.njit(nogil=True, cache=True)
def _one_geometry(
    sx, sy, sz, ox, oy, oz, unit_tol, eq4, facets, values, grids, opts, n_mat, want_pm
):  # pragma: no cover - compiled
    proto = values[0]  # the outputs' dtype is the tables'
    n_wl = proto.shape[1]
    sig = np.zeros((1, n_wl), dtype=proto.dtype)
    pap = np.zeros((1, n_wl), dtype=proto.dtype)
    area = np.zeros(1)
    pm = np.zeros((1, n_mat, n_wl) if want_pm else (0, 0, 0), dtype=proto.dtype)
    # the lengths as numpy's row norms give them, and the scene's normalisation
    ls = np.sqrt((sx * sx + sy * sy) + sz * sz)
    lo = np.sqrt((ox * ox + oy * oy) + oz * oz)
    if not (abs(ls - 1.0) <= unit_tol and abs(lo - 1.0) <= unit_tol):  # NaN too
        return False, sig, pap, area, pm
    s = np.empty((1, 3))
    o = np.empty((1, 3))
    s[0, 0], s[0, 1], s[0, 2] = sx / ls, sy / ls, sz / ls
    o[0, 0], o[0, 1], o[0, 2] = ox / lo, oy / lo, oz / lo
    if facets[0].shape[0]:
        _fused_sums(s, o, facets, values, grids, opts, (sig, pap, area, np.zeros(1), pm))
    if eq4 and area[0] > 0.0:  # paper 000 Eq. 4 in place, as effects.finish divides
        for k in range(n_wl):
            pap[0, k] = pap[0, k] / area[0]
    return True, sig, pap, area, pm


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
    >>> from sbrdf_xr.kernels.packing import pack_tables
    >>> from sbrdf_xr.kernels.sums import FusedSums, fused_sums
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
    """The facet sums of :func:`~sbrdf_xr.kernels.reference.material_sums`, over all
    materials at once, compiled.

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
        From :func:`~sbrdf_xr.kernels.packing.pack_tables`; its dtype is the dtype of the
        spectral outputs.
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
        sums are clipped at 0 as in :func:`~sbrdf_xr.kernels.reference.material_sums`.

    Examples
    --------
    The terms must come sorted by material, and a float32 packing gives float32 sums (a
    block without terms returns zeros without running the compiled kernel):

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.packing import pack_tables
    >>> from sbrdf_xr.kernels.sums import fused_sums
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
    n_wl, dt, n_mat = tables.n_spectral, tables.dtype, tables.edges.shape[0]
    out = FusedSums(
        np.zeros((g, n_wl), dtype=dt),
        np.zeros((g, n_wl), dtype=dt),
        np.zeros(g),
        np.zeros(g),
        np.zeros((g, n_mat, n_wl) if per_material else (0, 0, 0), dtype=dt),
    )
    if g and normals.shape[0]:
        nrm = np.ascontiguousarray(normals, dtype=np.float64)
        facets = Facets.of(
            nrm, areas, tm, normal_rows(nrm) if rows is None else rows, None, fraction
        )
        opts = KernelOptions(
            METHOD_CODES[method], normal_incidence_tolerance(np.float64), _lut.EDGE_TOL_DEG
        )
        _fused_sums(s, o, facets, typed_values(tables), tables.grids, opts, out)
    return out if per_material else out._replace(per_material=None)


class BoundSums:
    """:func:`fused_sums` with everything but the directions prepared once: the terms
    bundle, the typed table values, the options, and the compiled kernel's entry point
    for exactly these argument types (found on the first call), so that a call pays
    neither the bundling nor numba's dispatch on argument types.

    The sums are those of :func:`fused_sums` bit for bit (the same compiled kernel on
    the same arrays).  Not for a per-call ``fraction`` (the terms bundle holds none).

    Parameters
    ----------
    normals, areas, term_material, tables, method, per_material, rows
        As for :func:`fused_sums` (``rows`` computed when None).

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.kernels.packing import pack_tables
    >>> from sbrdf_xr.kernels.sums import BoundSums, fused_sums
    >>> g = np.array([0.0, 90.0])
    >>> tables = pack_tables([(np.ones((2, 2, 2, 3)), g, g - 90, g, (True, True, True))])
    >>> normals, areas = np.array([[0.0, 0, 1]]), np.array([2.0])
    >>> bound = BoundSums(normals, areas, np.zeros(1, dtype=np.int64), tables)
    >>> s = o = np.array([[0.0, 0.6, 0.8]])
    >>> r = bound(s, o)
    >>> r.signal.round(6).tolist(), r.area.tolist()  # 2 m2 x 0.8 x 0.8 x 1 sr-1
    ([[1.28, 1.28, 1.28]], [1.6])
    >>> same = fused_sums(s, o, normals, areas, np.zeros(1, dtype=np.int64), tables)
    >>> bool(np.array_equal(r.signal, same.signal))
    True
    """

    def __init__(
        self,
        normals: NDArray[np.floating],
        areas: NDArray[np.floating],
        term_material: NDArray[np.integer],
        tables: PackedTables,
        method: str = "linear",
        per_material: bool = False,
        rows: NDArray[np.int64] | None = None,
    ) -> None:
        tm = np.ascontiguousarray(term_material, dtype=np.int64)
        if tm.size and np.any(np.diff(tm) < 0):
            raise ValueError("term_material: terms of one material must be contiguous (sorted)")
        nrm = np.ascontiguousarray(normals, dtype=np.float64)
        self.n_terms = int(nrm.shape[0])
        self.per_material = per_material
        self._facets = Facets.of(nrm, areas, tm, normal_rows(nrm) if rows is None else rows)
        self._values = typed_values(tables) if self.n_terms else None
        self._grids = tables.grids
        self._opts = KernelOptions(
            METHOD_CODES[method], normal_incidence_tolerance(np.float64), _lut.EDGE_TOL_DEG
        )
        self._shape = (tables.n_spectral, tables.dtype, tables.edges.shape[0])
        self._entry: Any = None
        self._one: Any = None

    def __call__(self, to_sun: NDArray[np.float64], to_observer: NDArray[np.float64]) -> FusedSums:
        """The sums for ``(G, 3)`` unit vectors [1] (their length is not checked)."""
        to_sun, to_observer = _kernel_vectors(to_sun), _kernel_vectors(to_observer)
        g = to_sun.shape[0]
        n_wl, dt, n_mat = self._shape
        out = FusedSums(
            np.zeros((g, n_wl), dtype=dt),
            np.zeros((g, n_wl), dtype=dt),
            np.zeros(g),
            np.zeros(g),
            np.zeros((g, n_mat, n_wl) if self.per_material else (0, 0, 0), dtype=dt),
        )
        if g and self.n_terms:
            args = (to_sun, to_observer, self._facets, self._values, self._grids, self._opts, out)
            if self._entry is None:
                _fused_sums(*args)  # compiles (or loads) this signature
                sig = tuple(numba.typeof(a) for a in args)
                self._entry = getattr(_fused_sums.overloads[sig], "entry_point")  # noqa: B009
            else:
                self._entry(*args)
        return out if self.per_material else out._replace(per_material=None)

    def one(
        self, to_sun: Any, to_observer: Any, unit_tol: float, eq4: bool = False
    ) -> tuple[bool, NDArray[np.floating], NDArray[np.floating], NDArray[np.float64], Any]:
        """The sums of one geometry in one compiled call: both directions checked for
        unit length and normalised (as a scene normalises its pairs), the outputs
        allocated, the kernel run and, with ``eq4``, the paper sum divided by the area in
        place where it is positive (paper 000 Eq. 4, as
        :func:`~sbrdf_xr.engine.effects.finish` divides it).

        Parameters
        ----------
        to_sun, to_observer : sequence of 3 numbers
            Directions [1]; a length farther than ``unit_tol`` from 1 (or not finite)
            is no error here: the first value returned is then False.
        unit_tol : float
            Largest accepted ``| |v| - 1 |`` [1].
        eq4 : bool
            Divide the paper sum by the area.

        Returns
        -------
        tuple
            ``(ok, signal, paper, area, per_material)``: arrays shaped ``(1, L)``,
            ``(1, L)``, ``(1,)`` and ``(1, M, L)`` (``(0, 0, 0)`` unless
            ``per_material``), zeros unless ``ok``.

        Raises
        ------
        TypeError
            Components that are not numbers.

        Examples
        --------
        >>> import numpy as np
        >>> from sbrdf_xr.kernels.packing import pack_tables
        >>> from sbrdf_xr.kernels.sums import BoundSums
        >>> g = np.array([0.0, 90.0])
        >>> tables = pack_tables([(np.ones((2, 2, 2, 3)), g, g - 90, g, (True, True, True))])
        >>> bound = BoundSums(np.array([[0.0, 0, 1]]), np.array([2.0]), np.zeros(1, int), tables)
        >>> bound.one((0.0, 0.6, 0.8), (0.0, 0.0, 2.0), 1e-6)[0]  # not of unit length
        False
        >>> ok, sig, pap, area, _ = bound.one((0.0, 0.6, 0.8), (0.0, 0.6, 0.8), 1e-6, eq4=True)
        >>> sig.round(6).tolist(), pap.round(6).tolist(), area.tolist()  # Eq. 4: 1 sr-1
        ([[1.28, 1.28, 1.28]], [[1.0, 1.0, 1.0]], [1.6])
        """
        sx, sy, sz = to_sun
        ox, oy, oz = to_observer
        if self._one is None:  # compile (or load) the signature of floats, whatever came
            rest = (*self.bundle, self.per_material)
            probe = (0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1e-6, False, *rest)
            _one_geometry(*probe)
            sig = tuple(numba.typeof(a) for a in probe)
            self._one = getattr(_one_geometry.overloads[sig], "entry_point")  # noqa: B009
            self._one_rest = rest
        return cast(
            "tuple[bool, Any, Any, Any, Any]",
            self._one(sx, sy, sz, ox, oy, oz, unit_tol, eq4, *self._one_rest),
        )

    @property
    def bundle(self) -> tuple[Any, ...]:
        """The kernel's prepared arguments: terms, table values, grids, options and the
        number of materials."""
        return (self._facets, self._values, self._grids, self._opts, self._shape[2])


def _kernel_vectors(v: NDArray[np.floating]) -> NDArray[np.float64]:
    """``v`` as the kernel's entry point takes it: float64, C order, writeable (no copy
    when it already is)."""
    if v.dtype == np.float64 and v.flags.c_contiguous and v.flags.writeable:
        return cast("NDArray[np.float64]", v)
    return np.array(v, dtype=np.float64, order="C")
