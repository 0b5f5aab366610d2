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
    """Sums over the facets of one material for a block of geometries."""

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
