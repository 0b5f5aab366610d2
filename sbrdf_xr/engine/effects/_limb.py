"""Light from the Earth on the facets that see only its limb, shared by the Earth's effects.

A facet whose horizon hides the Earth's centre may still see part of the Earth: up to
``90 deg + rho`` from the centre (``sin(rho) = R / r``; at 7200 km a facet sees part of the
Earth up to 152 deg from its centre).  The BRDF cannot be evaluated at the Earth's centre
for it (the centre is below its horizon), so the irradiance ``E_j`` it receives from the
visible Earth is reflected with its directional-hemispherical reflectance at the emission
angle, ``rho(theta_r) / pi`` (reciprocity: exact for a Lambertian facet, the diffuse-sky
approximation for a glossy one).  The reflected earthshine (``earthshine``) and the
Earth's emission (``earth_thermal``) both use it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ... import sources
from ..._names import PSI
from ...geometry.anisotropy import psi_average
from ...materials.energy import hemispherical_reflectance
from .base import PlanInputs, readonly, table_on

if TYPE_CHECKING:
    import xarray as xr

    from ..views import PlanView
    from .base import BlockInputs

__all__ = ["limb_reflectance", "limb_signal", "limb_tables"]

#: Per material, its theta_r grid [degree] and rho(theta_r, lambda) [1].
Reflectance = tuple[tuple[np.ndarray, np.ndarray], ...]


def limb_tables(inputs: PlanInputs) -> tuple[xr.DataArray, ...]:
    """The tables of the plan's materials, in its order: what :func:`limb_signal` reduces to
    hemispherical reflectances the first time a facet sees only the limb (a measured table
    takes about a second, so a plan with no such facet does not pay it)."""
    return tuple(inputs.scene.tables[m] for m in inputs.materials)


def limb_reflectance(tables: tuple[xr.DataArray, ...], wl: np.ndarray) -> Reflectance:
    """Each table's directional-hemispherical reflectance ``rho(theta, lambda)`` on the
    wavelengths ``wl``, averaged over the azimuth of an anisotropic table.

    Examples
    --------
    >>> import numpy as np
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.engine.effects._limb import limb_reflectance, limb_tables
    >>> from sbrdf_xr.engine.effects.base import PlanInputs
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> scene = Scene(box, {"grey": grey}, to_sun=[[1.0, 0, 0]], to_observer=[[0, 1.0, 0]])
    >>> tables = limb_tables(PlanInputs(scene, {}, None, ("grey",)))
    >>> ((theta, rho),) = limb_reflectance(tables, np.array([600.0]))
    >>> theta.tolist(), np.round(rho, 6).tolist()  # a Lambertian table: its albedo
    ([0.0, 90.0], [[0.5], [0.5]])
    """
    out = []
    for table in tables:
        da = table_on(table, wl, None)
        th = np.asarray(da["theta_i"].values, dtype=np.float64)
        rho_da = hemispherical_reflectance(da, th, warn=False)
        rho = psi_average(rho_da.values, da[PSI].values, 1) if PSI in rho_da.dims else rho_da.values
        out.append((readonly(th), readonly(np.asarray(rho, dtype=np.float64))))
    return tuple(out)


def limb_signal(
    plan: PlanView,
    block: BlockInputs,
    irradiance: np.ndarray,
    cos_i: np.ndarray,
    tables: tuple[xr.DataArray, ...],
    key: str,
) -> np.ndarray:
    """``sum_j A_j cos(theta_r) rho(theta_r) / pi E_j`` (G, L) over the facets that see the
    Earth's limb with its centre below their horizon (``E > 0``, ``cos(theta_i) <= 0``).

    ``irradiance`` (G, T) is what each facet receives from the visible Earth, ``cos_i``
    (G, T) the cosine of the Earth's centre from its normal, ``tables`` those of
    :func:`limb_tables`, reduced once per plan and kept in its cache under ``key``.  On the
    wavelength grid, or on
    the bands when the plan's tables are integrated over them.  Exact for a Lambertian
    facet (:func:`sbrdf_xr.sources.earthshine_facets` and
    :func:`sbrdf_xr.sources.earth_view_facets` give ``E``); tested through the effects in
    ``tests/engine/test_earthshine_finite.py`` and ``tests/engine/test_earth_thermal.py``.
    """
    t = plan.terms
    o = block.to_observer
    out = np.zeros((o.shape[0], plan.wavelength.size))
    limb = (cos_i <= 0) & (irradiance > 0)
    if limb.any():
        reflectance = plan.cache.get(key)
        if reflectance is None:
            reflectance = plan.cache[key] = limb_reflectance(tables, plan.wavelength)
        for m, (theta, rho) in enumerate(reflectance):
            sel = t.material == m
            cos_r = o @ t.normal[sel].T  # (G, T_m)
            w = np.where(limb[:, sel] & (cos_r > 0), cos_r * irradiance[:, sel], 0.0)
            w = w * t.area[sel]
            if not w.any():
                continue
            theta_r = np.degrees(np.arctan2(np.sqrt(np.clip(1 - cos_r**2, 0, None)), cos_r))
            out += np.einsum("gf,gfl->gl", w, sources.emissivity_at(rho, theta, theta_r)) / np.pi
    if plan.pre_integrated and plan.band_weights is not None:
        out = out @ np.asarray(plan.band_weights, dtype=np.float64).T
    return out
