"""What the compiled kernels take, as a few typed bundles (numba named tuples).

* :class:`PackedTables`, the material tables (:func:`pack_tables`): one ``(nodes, L)``
  view per material, the concatenated grids with offsets, the out-of-range policy and
  normal-incidence blend per material, and bucket maps that find an axis cell without a
  binary search (:func:`bucket_map`); :class:`TableGrids` is all of it but the values,
  as the kernels read it (the values travel as a ``numba.typed.List``,
  :func:`typed_values`);
* :class:`Facets`, the terms of a block (normals, areas, materials, tangents, fractions);
* :class:`KernelOptions`, the look-up method and the tolerances.

The outputs travel as the named tuples the kernels return
(:class:`sbrdf_xr.kernels.sums.FusedSums`, :class:`sbrdf_xr.kernels.reference.MaterialSums`),
filled in place.
"""

from __future__ import annotations

import threading
from typing import Any, NamedTuple

import numba
import numba.typed
import numpy as np
from numpy.typing import DTypeLike, NDArray

__all__ = [
    "MAX_BUCKETS",
    "Facets",
    "KernelOptions",
    "PackedTables",
    "TableGrids",
    "bucket_map",
    "pack_tables",
    "typed_values",
]


#: Most buckets of an axis' bucket map (a grid with very uneven spacing gets fewer
#: buckets than nodes' spacing asks for, and a short scan within a bucket).
MAX_BUCKETS = 4096


def bucket_map(grid: np.ndarray) -> tuple[np.ndarray, float]:
    """Uniform buckets over ``grid`` and the cell at each bucket's start.

    Bucket ``k`` starts at ``grid[0] + k / inv``; ``map[k]`` is
    ``searchsorted(grid, start, "right") - 1``.  The bucket width is the smallest node
    spacing (at most :data:`MAX_BUCKETS` buckets), so a bucket holds at most one node
    and :func:`_axis` needs at most one correcting step.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.kernels.packing import bucket_map
    >>> grid = np.array([0.0, 1.0, 3.0])
    >>> bmap, inv = bucket_map(grid)
    >>> bmap.tolist(), inv
    ([0, 1, 1, 2], 1.0)
    >>> starts = grid[0] + np.arange(bmap.size) / inv
    >>> bool(np.array_equal(bmap, np.searchsorted(grid, starts, side="right") - 1))
    True

    A grid of one node has a single bucket:

    >>> bucket_map(np.array([5.0]))
    (array([0]), 0.0)
    """
    g = np.asarray(grid, dtype=np.float64)
    if g.size < 2 or g[-1] <= g[0]:
        return np.zeros(1, dtype=np.int64), 0.0
    span = g[-1] - g[0]
    width = max(float(np.min(np.diff(g))), span / MAX_BUCKETS)
    nb = int(np.ceil(span / width)) + 1
    inv = 1.0 / width
    starts = g[0] + np.arange(nb) / inv
    bmap = np.clip(np.searchsorted(g, starts, side="right") - 1, 0, g.size - 1)
    return bmap.astype(np.int64), inv


class TableGrids(NamedTuple):
    """The grids, offsets, policies and bucket maps of :class:`PackedTables`, the values
    left out: the bundle of table arrays a compiled kernel takes (material ``m``'s
    ``theta_i`` nodes are ``tgrid[t_off[m] : t_off[m + 1]]``, and so on).

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.kernels.packing import TableGrids, pack_tables
    >>> g = np.array([0.0, 90.0])
    >>> grids = pack_tables([(np.ones((2, 2, 2, 3)), g, g - 90, g, (True, True, True))]).grids
    >>> isinstance(grids, TableGrids), grids.dgrid.tolist(), grids.b_off.shape
    (True, [-90.0, 0.0], (3, 2))
    """

    tgrid: NDArray[np.float64]  #: theta_i nodes of every material [degree]
    t_off: NDArray[np.int64]  #: (M + 1,)
    dgrid: NDArray[np.float64]  #: delta_theta nodes [degree]
    d_off: NDArray[np.int64]
    pgrid: NDArray[np.float64]  #: phi nodes [degree]
    p_off: NDArray[np.int64]
    edges: NDArray[np.bool_]  #: (M, 3)
    blend: NDArray[np.float64]  #: (M,) [degree]
    bmap: NDArray[np.int64]  #: (3, total)
    b_off: NDArray[np.int64]  #: (3, M + 1)
    binv: NDArray[np.float64]  #: (3, M)


class Facets(NamedTuple):
    """The terms of a block as a compiled kernel takes them (float64 and int64, C order).

    Examples
    --------
    An empty tangent or fraction array stands for none (isotropic terms; every term
    wholly lit and visible):

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.packing import Facets
    >>> f = Facets.of(np.array([[0.0, 0, 1]]), np.array([2.0]))
    >>> f.row.tolist(), f.material.tolist(), f.tangent.shape, f.fraction.shape
    ([0], [0], (0, 3), (0, 0))
    """

    normal: NDArray[np.float64]  #: (T, 3) unit normals [1]
    area: NDArray[np.float64]  #: (T,) [m2]
    material: NDArray[np.int64]  #: (T,) material of each term, sorted
    row: NDArray[np.int64]  #: (T,) the term's row among the distinct normals
    tangent: NDArray[np.float64]  #: (T, 3) unit tangents [1], or (0, 3)
    fraction: NDArray[np.float64]  #: (G, T) lit-and-visible fraction [1], or (0, 0)

    @classmethod
    def of(
        cls,
        normal: NDArray[np.floating],
        area: NDArray[np.floating],
        material: NDArray[np.integer] | None = None,
        row: NDArray[np.integer] | None = None,
        tangent: NDArray[np.floating] | None = None,
        fraction: NDArray[np.floating] | None = None,
    ) -> Facets:
        """The bundle, arrays made contiguous in the kernels' dtypes; ``material`` and
        ``row`` default to 0 and to one row per term.

        Examples
        --------
        >>> import numpy as np
        >>> from sbrdf_xr.kernels.packing import Facets
        >>> Facets.of(np.array([[0.0, 0, 1], [1, 0, 0]]), np.ones(2)).row.tolist()
        [0, 1]
        """
        n = np.ascontiguousarray(normal, dtype=np.float64)
        t = n.shape[0]

        def ints(a: NDArray[np.integer] | None, default: NDArray[np.int64]) -> NDArray[np.int64]:
            return default if a is None else np.ascontiguousarray(a, dtype=np.int64)

        def floats(a: NDArray[np.floating] | None, empty: tuple[int, ...]) -> NDArray[np.float64]:
            return np.zeros(empty) if a is None else np.ascontiguousarray(a, dtype=np.float64)

        arrays = (
            n,
            np.ascontiguousarray(area, dtype=np.float64),
            ints(material, np.zeros(t, dtype=np.int64)),
            ints(row, np.arange(t, dtype=np.int64)),
            floats(tangent, (0, 3)),
            floats(fraction, (0, 0)),
        )
        return cls(*(_readonly(a) for a in arrays))


def _readonly(a: NDArray[Any]) -> NDArray[Any]:
    """A read-only view of ``a``: the kernels read their inputs, and numba compiles a
    kernel once per signature, read-only arrays being another type.  Every input in
    the same form (the catalog's tables and a plan's terms are read-only, a caller's
    arrays usually not) makes one compilation serve every call."""
    v = a.view()
    v.flags.writeable = False
    return v


class KernelOptions(NamedTuple):
    """How a compiled kernel looks up: the method code (0 nearest, 1 linear, 2 cubic),
    the normal-incidence tolerance [1] and the tolerance of the out-of-range policy
    [degree].

    Examples
    --------
    >>> from sbrdf_xr.kernels.packing import KernelOptions
    >>> KernelOptions(1, 1e-12, 1e-9).method
    1
    """

    method: int
    tol: float
    edge_tol: float


class PackedTables(NamedTuple):
    """Material tables as the fused kernel reads them.

    ``values[m]`` is material ``m``'s table as a ``(n_nodes, L)`` view (its
    ``(theta_i, delta_theta, phi)`` nodes in C order; no copy of a C-contiguous table in
    the right dtype); its grids are the slices ``t_off[m]:t_off[m + 1]`` (likewise
    ``d_off``, ``p_off``) of the concatenated grids.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.kernels.packing import pack_tables
    >>> g, g3 = np.array([0.0, 90.0]), np.array([0.0, 45.0, 90.0])
    >>> p = pack_tables(
    ...     [
    ...         (np.ones((2, 2, 2, 3)), g, g - 90, g, (True, True, True)),
    ...         (np.ones((3, 2, 2, 3)), g3, g - 90, g, (True, True, False)),
    ...     ]
    ... )
    >>> p.shapes, [v.shape for v in p.values]
    (((2, 2, 2), (3, 2, 2)), [(8, 3), (12, 3)])
    >>> p.t_off.tolist(), p.tgrid[p.t_off[1] : p.t_off[2]].tolist()
    ([0, 2, 5], [0.0, 45.0, 90.0])
    >>> p.edges.tolist()
    [[True, True, True], [True, True, False]]
    """

    values: tuple[NDArray[np.floating], ...]  #: per material (n_nodes, L) [sr-1]
    tgrid: NDArray[np.float64]
    t_off: NDArray[np.int64]
    dgrid: NDArray[np.float64]
    d_off: NDArray[np.int64]
    pgrid: NDArray[np.float64]
    p_off: NDArray[np.int64]
    edges: NDArray[np.bool_]  #: (M, 3) zero beyond delta_theta min, max, phi max
    blend: NDArray[np.float64]  #: (M,) normal-incidence blend [degree] (0: none)
    shapes: tuple[tuple[int, int, int], ...]  #: (n_theta, n_delta_theta, n_phi) per material
    n_spectral: int
    dtype: np.dtype
    #: bucket maps of the (theta_i, delta_theta, phi) axes (:func:`bucket_map`): the
    #: concatenated maps (3, total), offsets (3, M + 1) and inverse widths (3, M)
    bmap: NDArray[np.int64] = np.zeros((3, 1), dtype=np.int64)
    b_off: NDArray[np.int64] = np.zeros((3, 1), dtype=np.int64)
    binv: NDArray[np.float64] = np.zeros((3, 0))

    @property
    def grids(self) -> TableGrids:
        """Everything but the values, as the compiled kernels take it."""
        return TableGrids(
            self.tgrid,
            self.t_off,
            self.dgrid,
            self.d_off,
            self.pgrid,
            self.p_off,
            self.edges,
            self.blend,
            self.bmap,
            self.b_off,
            self.binv,
        )


def pack_tables(
    tables: list[tuple[Any, ...]],
    n_spectral: int = 1,
    dtype: DTypeLike = np.float64,
) -> PackedTables:
    """Pack ``(values, theta_grid, delta_theta_grid, phi_grid, zero_edges[, normal_blend])``
    per material.

    ``values`` has shape ``(n_theta, n_delta_theta, n_phi, L)``; every table has the
    same ``L`` and dtype.  ``n_spectral`` and ``dtype`` shape an empty packing (no
    tables).

    Examples
    --------
    A C-contiguous table in the packing's dtype is viewed, not copied; the sixth item
    is the normal-incidence blend [degree]:

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.packing import pack_tables
    >>> g = np.array([0.0, 90.0])
    >>> v = np.ones((2, 2, 2, 3))
    >>> p = pack_tables([(v, g, g - 90, g, (True, True, True), 5.0)])
    >>> p.n_spectral, p.dtype, p.blend.tolist(), bool(np.shares_memory(p.values[0], v))
    (3, dtype('float64'), [5.0], True)
    >>> pack_tables([(v, g, g - 90, g, (True, True, True))], dtype=np.float32).values[0].dtype
    dtype('float32')
    >>> e = pack_tables([], n_spectral=4, dtype=np.float32)
    >>> e.values, e.n_spectral, e.dtype, e.edges.shape
    ((), 4, dtype('float32'), (0, 3))
    """

    def cat(arrays: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        off = np.concatenate([[0], np.cumsum([a.size for a in arrays])]).astype(np.int64)
        return np.ascontiguousarray(np.concatenate(arrays), dtype=np.float64), off

    dt = np.dtype(dtype)
    if not tables:
        z = np.zeros(1, dtype=np.int64)
        return PackedTables(
            (),
            np.zeros(0),
            z,
            np.zeros(0),
            z,
            np.zeros(0),
            z,
            np.zeros((0, 3), dtype=bool),
            np.zeros(0),
            (),
            n_spectral,
            dt,
        )
    n_wl = tables[0][0].shape[-1]
    values = tuple(np.ascontiguousarray(v, dtype=dt).reshape(-1, n_wl) for v, *_ in tables)
    tgrid, t_off = cat([np.asarray(t[1]) for t in tables])
    dgrid, d_off = cat([np.asarray(t[2]) for t in tables])
    pgrid, p_off = cat([np.asarray(t[3]) for t in tables])
    edges = np.array([t[4] for t in tables], dtype=bool).reshape(-1, 3)
    blend = np.array([float(t[5]) if len(t) > 5 else 0.0 for t in tables], dtype=np.float64)
    shapes = tuple((int(v.shape[0]), int(v.shape[1]), int(v.shape[2])) for v, *_ in tables)
    maps = [[bucket_map(np.asarray(t[1 + a])) for t in tables] for a in range(3)]
    lengths = [[m.size for m, _ in axis] for axis in maps]
    width = max(sum(n) for n in lengths)
    bmap = np.zeros((3, width), dtype=np.int64)
    b_off = np.zeros((3, len(tables) + 1), dtype=np.int64)
    binv = np.zeros((3, len(tables)))
    for a, axis in enumerate(maps):
        b_off[a, 1:] = np.cumsum(lengths[a])
        bmap[a, : b_off[a, -1]] = np.concatenate([m for m, _ in axis])
        binv[a] = [inv for _, inv in axis]
    return PackedTables(
        values,
        tgrid,
        t_off,
        dgrid,
        d_off,
        pgrid,
        p_off,
        edges,
        blend,
        shapes,
        n_wl,
        dt,
        bmap,
        b_off,
        binv,
    )


#: The numba lists of the last few packings' values, by the identity of their tuple
#: (each entry keeps its tuple alive, so the identity cannot be reused meanwhile).
_TYPED: dict[int, tuple[tuple[NDArray[np.floating], ...], Any]] = {}
_TYPED_LOCK = threading.Lock()
_TYPED_KEEP = 8


@numba.njit(cache=True, nogil=True)
def _list_of(first):  # pragma: no cover - compiled
    out = numba.typed.List()
    out.append(first)
    return out


@numba.njit(cache=True, nogil=True)
def _append(values, item):  # pragma: no cover - compiled
    values.append(item)


def typed_values(tables: PackedTables) -> Any:
    """``tables.values`` as the ``numba.typed.List`` the kernels take, built once per
    packing (building it costs about 70 us, paid on every block otherwise).

    The list is made by two small compiled functions kept in numba's disk cache: a
    ``numba.typed.List`` made from Python compiles its methods in every new process
    (~2 s of CPU on the first list of each array type: each command, each Dask worker).

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.kernels.packing import pack_tables, typed_values
    >>> g = np.array([0.0, 90.0])
    >>> p = pack_tables([(np.ones((2, 2, 2, 3)), g, g - 90, g, (True, True, True))])
    >>> typed = typed_values(p)
    >>> type(typed).__name__, len(typed), typed[0].shape, typed_values(p) is typed
    ('List', 1, (8, 3), True)
    """
    key = id(tables.values)
    with _TYPED_LOCK:
        hit = _TYPED.get(key)
        if hit is not None and hit[0] is tables.values:
            return hit[1]
    values = [_readonly(v) for v in tables.values]
    typed = _list_of(values[0]) if values else numba.typed.List()
    for v in values[1:]:
        _append(typed, v)
    with _TYPED_LOCK:
        while len(_TYPED) >= _TYPED_KEEP:
            del _TYPED[next(iter(_TYPED))]
        _TYPED[key] = (tables.values, typed)
    return typed
