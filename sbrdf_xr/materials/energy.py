"""The energy of a material table: its directional-hemispherical reflectance.

:func:`hemispherical_reflectance` integrates the look-up's interpolant over the visible
hemisphere (:func:`sbrdf_xr.kernels.lut.hemispherical_reflectance_kernel`); a value above one
means the table creates energy.  :func:`sbrdf_xr.materials.build.build_lut` checks the
tables it builds with it (tolerance :data:`ENERGY_TOL`).
"""

from __future__ import annotations

import warnings

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from .._names import ANGLE_DIMS, PSI, THETA_I, WAVELENGTH, attrs
from ..errors import NonPhysicalWarning, ValidationError
from ..geometry.anisotropy import psi_weights
from ..kernels import lut as _lut
from ..units import to_unit
from .schema import validate_material

__all__ = ["ENERGY_TOL", "hemispherical_reflectance"]

#: Reflectance above ``1 + ENERGY_TOL`` is reported by
#: :func:`sbrdf_xr.materials.build.build_lut` (the quadrature of a float32 table is good
#: to ~1e-7).
ENERGY_TOL = 1e-6


def hemispherical_reflectance(
    material: xr.DataArray,
    theta_i: ArrayLike | None = None,
    *,
    method: str = "linear",
    warn: bool = True,
) -> xr.DataArray:
    """Directional-hemispherical reflectance ``rho(theta_i, wavelength)`` of a table.

    Quadrature over the visible hemisphere of the interpolated table
    (:func:`sbrdf_xr.kernels.lut.hemispherical_reflectance_kernel`).  Values above one
    are non-physical (energy is not conserved) and issue a
    :class:`~sbrdf_xr.errors.NonPhysicalWarning` when ``warn`` is true.

    Parameters
    ----------
    material : xarray.DataArray
        Material table.
    theta_i : array_like, optional
        Incidence angles [degree]; default the table's own.
    method : str, default "linear"
        Look-up method of the integrand.
    warn : bool, default True
        Warn when any reflectance exceeds 1.

    Returns
    -------
    xarray.DataArray
        Dims ``(theta_i, wavelength)``, ``units = 1``; for an anisotropic table
        ``(theta_i, psi, wavelength)`` at the table's ``psi`` nodes: an observer on
        the far side of the illumination plane sees the mirror geometry, whose tangent
        is at ``-psi`` (:mod:`sbrdf_xr.geometry.anisotropy`), so the reflectance at ``psi`` is
        the mean of the slice integrals at ``psi`` and ``-psi`` (each integrates one
        side of the plane twice), the latter interpolated periodically.

    Examples
    --------
    The directional-hemispherical reflectance of a Lambertian table is its albedo:

    >>> import numpy as np
    >>> from sbrdf_xr.materials import hemispherical_reflectance, lambertian
    >>> rho = hemispherical_reflectance(lambertian(0.5, [550.0]), [0.0, 30.0, 60.0])
    >>> rho.dims, rho.attrs["units"]
    (('theta_i', 'wavelength'), '1')
    >>> np.round(rho.values[:, 0], 4)
    array([0.5, 0.5, 0.5])
    """
    material = validate_material(material, check_values=False)
    grids = [np.asarray(material[d].values) for d in ANGLE_DIMS]
    theta_i = to_unit(theta_i, "deg", "theta_i")
    ti = grids[0] if theta_i is None else np.atleast_1d(np.asarray(theta_i, dtype=np.float64))

    def kernel(values: np.ndarray) -> np.ndarray:
        return _lut.hemispherical_reflectance_kernel(
            values,
            grids[0],
            grids[1],
            grids[2],
            ti,
            method,
            zero_edges=_lut.table_edges(material.attrs),
            normal_blend=_lut.table_normal_blend(material.attrs),
        )

    coords = {THETA_I: (THETA_I, ti, attrs(THETA_I)), WAVELENGTH: material[WAVELENGTH]}
    if PSI in material.dims:
        values = np.asarray(material.values)
        psi = np.asarray(material[PSI].values, dtype=np.float64)
        half = np.stack([kernel(values[:, :, :, k, :]) for k in range(psi.size)], axis=1)
        idx, w = psi_weights(psi, -psi)
        mirror = np.einsum("tkpl,kp->tkl", half[:, idx, :], w)
        rho = 0.5 * (half + mirror)
        dims: tuple[str, ...] = (THETA_I, PSI, WAVELENGTH)
        coords[PSI] = material[PSI]
    else:
        rho = kernel(np.asarray(material.values))
        dims = (THETA_I, WAVELENGTH)
    out = xr.DataArray(
        rho,
        dims=dims,
        coords=coords,
        name="reflectance",
        attrs=attrs("reflectance", material=material.attrs.get("material", "")),
    )
    if warn and np.any(rho > 1.0):
        worst = np.unravel_index(np.argmax(rho), rho.shape)
        warnings.warn(
            f"material {material.attrs.get('material', '')!r}: "
            "directional-hemispherical reflectance "
            f"reaches {rho[worst]:.3f} > 1 at theta_i = {ti[worst[0]]} deg, wavelength = "
            f"{material[WAVELENGTH].values[worst[-1]]} nm; the table does not conserve energy",
            NonPhysicalWarning,
            stacklevel=2,
        )
    return out


def _check_energy_conservation(table: xr.DataArray, theta_i: ArrayLike) -> np.ndarray:
    """Warn when a table's directional-hemispherical reflectance exceeds 1.

    Parameters
    ----------
    table : xarray.DataArray
        A material table.
    theta_i : array_like
        Incidence angles to check [degree].

    Returns
    -------
    ndarray, shape (n_theta_i, n_wavelength)
        The reflectance [1] (:func:`hemispherical_reflectance`); a
        :class:`~sbrdf_xr.errors.NonPhysicalWarning` names the incidence angles and the
        worst wavelength where it exceeds ``1 + ENERGY_TOL``.

    Examples
    --------
    >>> from sbrdf_xr.materials.energy import _check_energy_conservation
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> _check_energy_conservation(lambertian(0.5, [550.0]), [0.0, 45.0]).round(3).tolist()
    [[0.5], [0.5]]
    """
    ti = np.atleast_1d(np.asarray(to_unit(theta_i, "deg", "theta_i"), dtype=np.float64))
    rho = hemispherical_reflectance(table, ti, warn=False).values
    if np.any(rho > 1.0 + ENERGY_TOL):
        bad = np.argwhere(rho > 1.0 + ENERGY_TOL)
        worst = np.unravel_index(np.argmax(rho), rho.shape)
        tis = sorted({float(ti[b[0]]) for b in bad})
        wl = table[WAVELENGTH].values
        warnings.warn(
            f"build_lut: the table of {table.attrs.get('material', '')!r} does not conserve "
            f"energy: its directional-hemispherical reflectance exceeds 1 at theta_i = {tis} "
            f"deg (worst {rho[worst]:.3f} at theta_i = {ti[worst[0]]} deg, wavelength = "
            f"{wl[worst[1]]} nm); "
            + (
                "the measured values hold it (a lobe narrower than the scan's step, or one "
                "taken as isotropic about specular)"
                if table.attrs.get("below_noise") == "model"
                else "consider below_noise='model' or extrapolation='model'"
            ),
            NonPhysicalWarning,
            stacklevel=3,
        )
    return rho


def _given_reflectance(rho: xr.DataArray, ti: np.ndarray, wl: np.ndarray) -> np.ndarray:
    """``model_reflectance`` of :func:`build_lut` as an array, checked against the table's
    rows ``ti`` and wavelengths ``wl``."""
    if not isinstance(rho, xr.DataArray) or set(rho.dims) != {THETA_I, WAVELENGTH}:
        raise ValidationError(
            "model_reflectance: expected an xarray.DataArray with dims (theta_i, wavelength), "
            f"got {type(rho).__name__} with dims {getattr(rho, 'dims', None)}"
        )
    rho = rho.transpose(THETA_I, WAVELENGTH)
    for dim, want in ((THETA_I, ti), (WAVELENGTH, wl)):
        got = np.asarray(rho[dim].values, dtype=np.float64)
        if not np.array_equal(got, want):
            raise ValidationError(
                f"model_reflectance: its {dim} ({got.size} values, {got[:1]}..{got[-1:]}) "
                f"is not the table's ({want.size} values, {want[:1]}..{want[-1:]})"
            )
    return np.array(rho.values, dtype=np.float64)


def _clamp_energy(
    lut: np.ndarray,
    grids: tuple[np.ndarray, np.ndarray, np.ndarray],
    zero_edges: tuple[bool, bool, bool],
    normal_blend: float,
    bound: float = 1.0,
) -> dict[str, object]:
    """Bound every row's directional-hemispherical reflectance by ``bound`` (in place).

    A row ``(theta_i, wavelength)`` of ``lut`` whose reflectance (the quadrature of the
    look-up's interpolant, :func:`sbrdf_xr.kernels.lut.hemispherical_reflectance_kernel`)
    exceeds ``bound`` has its values at ``phi > 0`` scaled by
    ``s = (bound - rho_plane) / (rho - rho_plane)``, with ``rho_plane`` the part its
    ``phi = 0`` nodes carry (the reflectance is linear in the values, so the row then
    reflects ``bound``).  For an in-plane scan those values are the modelled extension
    out of the plane (a mirror core taken as isotropic about specular) and the measured
    plane keeps its samples.  A row whose plane alone reflects more than ``bound`` (the
    ``theta_i = 0`` row, which the look-up reads from its in-plane profile) is scaled
    as a whole.  Rows below ``normal_blend`` mix with the ``theta_i = 0`` row in the
    look-up; further passes (three at most) take up what the first left.

    Parameters
    ----------
    lut : ndarray, shape (n_theta_i, n_delta_theta, n_phi, n_wavelength)
        The table's values [sr-1], scaled in place.
    grids : tuple of ndarray
        Its ``theta_i``, ``delta_theta`` and ``phi`` nodes [degree].
    zero_edges : tuple of bool
        The table's edges (:func:`~sbrdf_xr.materials.construction.lut_edges`).
    normal_blend : float
        The look-up's normal-incidence blend [degree].
    bound : float, default 1
        The largest reflectance [1].

    Returns
    -------
    dict
        ``energy_clamp_theta_i`` (the rows scaled [degree]) and ``energy_clamp_min_scale``
        (the smallest factor [1]), empty when no row exceeds ``bound``.

    Examples
    --------
    A constant 0.5 sr-1 (reflectance pi / 2) is scaled out of the plane to reflect 1:

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.lut import hemispherical_reflectance_kernel as rho
    >>> from sbrdf_xr.materials.energy import _clamp_energy
    >>> g = (np.array([0.0, 30.0]), np.linspace(-180.0, 90.0, 55), np.linspace(0.0, 90.0, 19))
    >>> lut = np.full((2, 55, 19, 1), 0.5)
    >>> out = _clamp_energy(lut, g, (True, True, True), 0.0)
    >>> out["energy_clamp_theta_i"], np.round(rho(lut, *g, None, zero_edges=(True,) * 3), 9)
    ([0.0, 30.0], array([[1.],
           [1.]]))
    """
    tg, dg, pg = grids
    out_of_plane = pg > 0

    def rho(values: np.ndarray, rows: np.ndarray) -> np.ndarray:
        return _lut.hemispherical_reflectance_kernel(
            values, tg, dg, pg, tg[rows], zero_edges=zero_edges, normal_blend=normal_blend
        )

    scale = np.ones((tg.size, lut.shape[-1]))
    rows = np.arange(tg.size)  # every row once, then those the normal-incidence blend mixes
    for _ in range(3):
        total = rho(lut, rows)
        over = total > bound * (1.0 + 1e-9)
        if not over.any():
            break
        rows, total = rows[over.any(axis=1)], total[over.any(axis=1)]
        over = total > bound * (1.0 + 1e-9)
        plane = lut.copy()
        plane[:, :, out_of_plane] = 0.0
        part = rho(plane, rows)
        fits = over & (part < bound * (1.0 - 1e-6))
        s = np.divide(bound - part, total - part, out=np.ones_like(total), where=fits)
        whole = np.where(over & ~fits, bound / np.maximum(total, 1e-300), 1.0)
        sub = lut[rows]
        sub[:, :, out_of_plane] *= s[:, None, None, :]
        sub *= whole[:, None, None, :]  # the plane alone reflects too much: all of the row
        lut[rows] = sub
        scale[rows] *= s * whole
        rows = np.flatnonzero(tg < normal_blend)  # the others reflect ``bound`` now
        if rows.size == 0:
            break
    done = np.flatnonzero(np.any(scale < 1.0, axis=1))
    if done.size == 0:
        return {}
    return {
        "energy_clamp_theta_i": [float(t) for t in tg[done]],
        "energy_clamp_min_scale": float(scale.min()),
    }
