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
from ..errors import NonPhysicalWarning
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
