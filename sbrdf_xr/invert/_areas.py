"""The areas of an unmixing: nominal areas, the constraint on their sum, the fractions.

See :func:`sbrdf_xr.invert.unmix`.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr

from ..errors import InversionError
from ._library import MATERIAL

__all__ = ["add_areas", "area_constraint", "material_areas", "nominal_areas"]


def material_areas(spacecraft: Any) -> dict[str, float]:
    """Total facet area of each material of a spacecraft [m2].

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import load_spacecraft
    >>> from sbrdf_xr.invert import material_areas
    >>> box = load_spacecraft(trimesh.creation.box(extents=(1.0, 2.0, 3.0)), material="grey")
    >>> material_areas(box)  # 2 (1 x 2 + 1 x 3 + 2 x 3)
    {'grey': 22.0}
    """
    areas = np.asarray(spacecraft.mesh.area_faces, dtype=np.float64)
    names = np.asarray(spacecraft.facet_material)
    return {str(m): float(areas[names == m].sum()) for m in np.unique(names)}


def area_constraint(
    total_area: float | bool | None, areas: Mapping[str, float] | None, names: list[str]
) -> tuple[np.ndarray, float] | None:
    """``(c, total)`` of the area constraint ``sum_m a_m A_m = total``, or None."""
    if total_area is None or total_area is False:
        return None
    if areas is None:
        raise InversionError(
            f"total_area: {total_area!r} needs areas (the nominal area of each material, "
            "material_areas(spacecraft)) to turn scale factors into areas"
        )
    nominal = nominal_areas(areas, names)
    if total_area is True:
        total = float(sum(float(v) for v in areas.values()))
    else:
        try:
            total = float(total_area)
        except (TypeError, ValueError):
            total = np.nan
    if not (np.isfinite(total) and total > 0):
        raise InversionError(
            f"total_area: {total_area!r}; allowed a finite area > 0 [m2], True (the sum of "
            "areas) or None"
        )
    if not nominal.any():
        raise InversionError(f"total_area: every candidate has area 0 in areas ({names})")
    return nominal, total


def nominal_areas(areas: Mapping[str, float], names: list[str]) -> np.ndarray:
    """The nominal area of each candidate [m2], checked."""
    missing = [m for m in names if m not in areas]
    if missing:
        raise InversionError(f"areas: no area for {missing}; have {sorted(areas)}")
    nominal = np.array([float(areas[m]) for m in names])
    bad = ~(np.isfinite(nominal) & (nominal >= 0))
    if bad.any():
        given = {m: float(v) for m, v, b in zip(names, nominal, bad, strict=True) if b}
        raise InversionError(f"areas: must be finite and >= 0 [m2], got {given}")
    return nominal


def add_areas(
    ds: xr.Dataset,
    names: list[str],
    x: np.ndarray,
    sig: np.ndarray,
    cov: np.ndarray,
    areas: Mapping[str, float],
    total: float | None,
) -> None:
    """``area``, ``area_fraction`` and their uncertainties (first-order propagation).

    The fractions are of the summed fitted area, or of ``total`` when the areas are
    constrained to add up to it (then exactly, with the constrained covariance)."""
    nominal = nominal_areas(areas, names)
    area = x * nominal
    ds["area"] = (MATERIAL, area, {"units": "m2", "long_name": "effective area of the material"})
    ds["area_uncertainty"] = (
        MATERIAL,
        sig * nominal,
        {"units": "m2", "long_name": "1-sigma uncertainty of the effective area"},
    )
    free = ~np.isfinite(sig)  # not constrained: left out of the sum, fraction unknown
    tot = float(np.nansum(np.where(free, 0.0, area)))
    cov_a = np.where(np.outer(free, free) | ~np.isfinite(cov), 0.0, cov) * np.outer(
        nominal, nominal
    )
    if total is not None:  # a constant: the fractions are the areas over it
        frac, frac_sig = area / total, sig * nominal / total
        long_name = "fraction of total_area, the constrained sum of the areas"
        normalised = (
            f"total_area = {total:.6g} m2, to which the fitted areas of the candidate "
            f"materials ({', '.join(names)}) are constrained to add up"
        )
    else:
        if tot > 0:
            a_in = np.where(free, 0.0, area)
            jac = (np.eye(len(names)) * tot - a_in[:, None]) / tot**2  # d f_i / d area_j
            frac = np.where(free, np.nan, a_in / tot)
            frac_sig = np.sqrt(np.clip(np.diag(jac @ cov_a @ jac.T), 0, None))
            frac_sig[free] = np.inf
        else:
            frac = frac_sig = np.full(len(names), np.nan)
        long_name = "fraction of the summed effective area of the fitted candidate materials"
        normalised = (
            "the summed effective area of the candidate materials of this fit "
            f"({', '.join(names)}): the spacecraft's total only if the library holds all of "
            "its materials"
        )
    ds["area_fraction"] = (
        MATERIAL,
        frac,
        {"units": "1", "long_name": long_name, "normalisation": normalised},
    )
    if total is not None:
        ds["total_area"] = ((), total, {"units": "m2", "long_name": "total area (constraint)"})
    ds["area_fraction_uncertainty"] = (
        MATERIAL,
        frac_sig,
        {"units": "1", "long_name": "1-sigma uncertainty of the area fraction (first order)"},
    )
    ds.attrs["area_fraction_normalisation"] = normalised
