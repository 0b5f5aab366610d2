"""The numpy reference kernel of the spacecraft sum of paper 000 §3.4 (Eqs. 3-4).

For a block of geometries (Sun and observer unit vectors in the body frame) and the
facets of one material, :func:`material_sums` returns, without materialising one
spectrum per facet:

* ``signal[g, l]  = sum_j A_j c_j cos(theta_i,gj) cos(theta_r,gj) f_r(gj, l)``
  [m2 sr-1], the radiometric quantity (reflected intensity per unit solar
  irradiance);
* ``paper[g, l]   = sum_j a_2D,gj f_r(gj, l)`` with ``a_2D = A_j c_j cos(theta_r,gj)``,
  the numerator of paper 000 Eq. 4 (Eq. 3 summed) [m2 sr-1];
* ``area[g]       = sum_j a_2D,gj``, the denominator of Eq. 4 [m2];

over the facets that are lit (``N.s > 0``) and visible (``N.o > 0``); ``c_j`` is
an optional per-geometry-and-facet fraction (lit-and-visible area fraction when
self-shadowing is on).  The sums are linear in ``f_r``, so each is one sparse
matrix (geometries x table nodes) times the table (nodes x wavelengths).

:func:`material_sums` (numpy and scipy.sparse) is the reference implementation
and the specification of :func:`sbrdf_xr.kernels.sums.fused_sums`, which computes the
same sums for all materials of a block in one compiled pass.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..geometry import facet_angles
from . import lut as _lut

__all__ = ["MaterialSums", "material_sums"]


class MaterialSums(NamedTuple):
    """Sums over the facets of one material for a block of geometries.

    Examples
    --------
    :func:`material_sums` keeps the table's dtype for the spectral sums and float64 for
    the areas:

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.reference import MaterialSums, material_sums
    >>> g, d, p = np.array([0.0, 90]), np.array([-90.0, 90]), np.array([0.0, 180])
    >>> values = np.full((2, 2, 2, 3), 0.5 / np.pi, dtype=np.float32)
    >>> s = o = np.array([[0.0, 0, 1], [0, 0.6, 0.8]])
    >>> r = material_sums(s, o, np.array([[0.0, 0, 1]]), np.array([2.0]), values, g, d, p)
    >>> MaterialSums._fields
    ('signal', 'paper', 'area', 'lit_visible_area')
    >>> r.signal.shape, r.signal.dtype, r.area.dtype, r.area.round(6).tolist()
    ((2, 3), dtype('float32'), dtype('float64'), [2.0, 1.6])
    """

    signal: NDArray[np.floating]  #: (G, L) [m2 sr-1]
    paper: NDArray[np.floating]  #: (G, L) [m2 sr-1]
    area: NDArray[np.float64]  #: (G,) [m2]
    lit_visible_area: NDArray[np.float64]  #: (G,) [m2], sum of A_j c_j over contributing facets


def material_sums(
    to_sun: NDArray[np.floating],
    to_observer: NDArray[np.floating],
    normals: NDArray[np.floating],
    areas: NDArray[np.floating],
    values: NDArray[np.floating],
    theta_grid: NDArray[np.floating],
    delta_theta_grid: NDArray[np.floating],
    phi_grid: NDArray[np.floating],
    method: str = "linear",
    fraction: NDArray[np.floating] | None = None,
    zero_edges: tuple[bool, bool, bool] = (True, True, True),
    normal_blend: float = 0.0,
) -> MaterialSums:
    """Facet sums of paper 000 Eqs. 3-4 and the radiometric signal for one material.

    Parameters
    ----------
    to_sun, to_observer : ndarray, shape (G, 3)
        Unit vectors to the Sun and the observer in the body frame [1].
    normals : ndarray, shape (F, 3)
        Unit facet normals [1].
    areas : ndarray, shape (F,)
        Facet areas [m2].
    values : ndarray, shape (n_theta, n_delta_theta, n_phi, L)
        The material's table [sr-1].
    theta_grid, delta_theta_grid, phi_grid : ndarray
        Table coordinates [degree].
    method : {"nearest", "linear", "cubic"}
        Look-up method.
    fraction : ndarray, shape (G, F), optional
        Fraction of each facet's area that is lit and visible [1] (self-shadowing
        and self-occlusion); default 1.
    zero_edges : tuple of 3 bool
        The table's out-of-range policy (:func:`sbrdf_xr.kernels.lut.lookup_matrix`).
    normal_blend : float
        The table's normal-incidence blend [degree]
        (:func:`sbrdf_xr.kernels.lut.table_normal_blend`).

    Returns
    -------
    MaterialSums
        ``signal`` and ``paper`` in the dtype of ``values``; ``area`` in float64.

    Examples
    --------
    A Lambertian table ``f_r = 0.5 / pi``; a facet of 2 m2 facing ``+z`` with the Sun 45 deg
    towards ``-x`` and the observer at the specular direction (``cos_i = cos_r =
    sqrt(0.5)``), and one of 1 m2 facing ``-z``, which is not lit and adds nothing:
    ``signal = 2 * 0.5 * 0.5 / pi``, ``area = 2 * sqrt(0.5)``.

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.reference import material_sums
    >>> g, d, p = np.array([0.0, 90]), np.array([-90.0, 90]), np.array([0.0, 180])
    >>> values = np.full((2, 2, 2, 1), 0.5 / np.pi)  # (n_theta, n_dt, n_phi, L)
    >>> h = np.sqrt(0.5)
    >>> s, o = np.array([[-h, 0, h]]), np.array([[h, 0, h]])
    >>> normals, areas = np.array([[0.0, 0, 1], [0, 0, -1]]), np.array([2.0, 1.0])
    >>> r = material_sums(s, o, normals, areas, values, g, d, p)
    >>> bool(np.allclose(r.signal, 0.5 / np.pi)), bool(np.allclose(r.paper, 2 * h * 0.5 / np.pi))
    (True, True)
    >>> r.area.round(6).tolist(), r.lit_visible_area.tolist()
    ([1.414214], [2.0])

    Half the first facet lit and seen halves every sum:

    >>> half = material_sums(s, o, normals, areas, values, g, d, p, fraction=np.array([[0.5, 1]]))
    >>> bool(np.allclose(half.signal, r.signal / 2)), half.lit_visible_area.tolist()
    (True, [1.0])
    """
    g, f = to_sun.shape[0], normals.shape[0]
    n_wl = values.shape[-1]
    out_dtype = values.dtype
    if f == 0 or g == 0:
        z = np.zeros((g, n_wl), dtype=out_dtype)
        return MaterialSums(z, z.copy(), np.zeros(g), np.zeros(g))
    ang = facet_angles(
        normals[None, :, :], to_sun[:, None, :], to_observer[:, None, :], check=False
    )
    cos_i = np.einsum("fk,gk->gf", normals, to_sun)
    cos_r = np.einsum("fk,gk->gf", normals, to_observer)
    contributing = ang.lit & ang.visible
    eff_area = np.where(contributing, areas[None, :], 0.0)
    if fraction is not None:
        eff_area = eff_area * fraction
    a2d = eff_area * cos_r
    w_signal = a2d * cos_i
    rows = np.flatnonzero(contributing.ravel())
    m = _lut.lookup_matrix(
        theta_grid,
        delta_theta_grid,
        phi_grid,
        ang.theta_i.ravel()[rows],
        ang.delta_theta.ravel()[rows],
        ang.phi.ravel()[rows],
        method,
        zero_edges=zero_edges,
        normal_blend=normal_blend,
    ).tocoo()
    geom = rows[m.row] // f
    v2 = values.reshape(-1, n_wl)
    mats = []
    for w in (w_signal, a2d):
        data = m.data * w.ravel()[rows][m.row]
        mats.append(sp.csr_matrix((data, (geom, m.col)), shape=(g, m.shape[1])))
    stacked = sp.vstack(mats, format="csr")
    if v2.dtype != np.float64:
        stacked = stacked.astype(v2.dtype)
    res = np.asarray(stacked @ v2)
    if method == "cubic":
        np.maximum(res, 0, out=res)
    return MaterialSums(
        res[:g].astype(out_dtype, copy=False),
        res[g:].astype(out_dtype, copy=False),
        a2d.sum(axis=1),
        eff_area.sum(axis=1),
    )
