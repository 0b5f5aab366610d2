"""Matplotlib figures of cubes and materials.

Every function takes labelled objects, returns the ``matplotlib.figure.Figure``
and never calls ``show()``; pass ``ax`` to draw into an existing axes.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

__all__ = ["light_curve", "lut_slice", "plot_cube", "spectra"]


def _axes(ax: Any = None, **fig_kw: Any) -> tuple[Any, Any]:
    import matplotlib.pyplot as plt

    if ax is None:
        fig, ax = plt.subplots(**({"figsize": (8, 4), "layout": "constrained"} | fig_kw))
        return fig, ax
    return ax.figure, ax


def _label(da: xr.DataArray) -> str:
    return f"{da.attrs.get('long_name', da.name)} [{da.attrs.get('units', '')}]"


def light_curve(cube: xr.Dataset, variable: str = "brdf", ax: Any = None, log: bool = False) -> Any:
    """Broadband BRDF (paper 000 Fig. 18) or another scalar variable versus attitude.

    Parameters
    ----------
    cube : xarray.Dataset
        A simulation cube over ``attitude`` (and ``phase_angle``).
    variable : str, default "brdf"
        Variable without a spectral dimension.
    ax : matplotlib axes, optional
    log : bool
        Logarithmic y axis.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = _axes(ax)
    da = cube[variable]
    x = cube["attitude_angle"] if "attitude_angle" in cube.coords else cube["attitude"]
    for beta in np.atleast_1d(cube["phase_angle"].values):
        ax.plot(x.values, da.sel(phase_angle=beta).values, label=f"beta = {beta:g} deg", lw=1)
    ax.set_xlabel(_label(x) if "units" in x.attrs else "attitude")
    ax.set_ylabel(_label(da))
    if log:
        ax.set_yscale("log")
    ax.set_title(cube.attrs.get("scene", ""))
    ax.legend()
    return fig


def spectra(cube: xr.Dataset, variable: str = "spacecraft_sbrdf", ax: Any = None, log: bool = False, **sel: Any) -> Any:
    """Spectra of a cube (paper 000 Figs. 14 and 16), one line per remaining geometry.

    Parameters
    ----------
    cube : xarray.Dataset
    variable : str, default "spacecraft_sbrdf"
    ax : matplotlib axes, optional
    log : bool
        Logarithmic y axis (Fig. 16).
    **sel
        Selections applied first (for example ``attitude=0``).

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, ax = _axes(ax)
    da = cube[variable].sel(**sel) if sel else cube[variable]
    stacked = da.stack(_line=[d for d in da.dims if d != "wavelength"]) if da.ndim > 1 else da.expand_dims(_line=[0])
    varying = [c for c in ("attitude_angle", "attitude", "geometry", "phase_angle")
               if c in stacked.coords and stacked[c].size > 1 and "_line" in stacked[c].dims]
    for k in range(stacked.sizes["_line"]):
        line = stacked.isel(_line=k)
        label = ", ".join(f"{c} = {line[c].values:g}" for c in varying)
        ax.plot(line["wavelength"].values, line.values, lw=1, label=label or None)
    ax.set_xlabel(_label(cube["wavelength"]))
    ax.set_ylabel(_label(cube[variable]))
    if log:
        ax.set_yscale("log")
    if stacked.sizes["_line"] <= 12:
        ax.legend()
    return fig


def lut_slice(material: xr.DataArray, theta_i: float, wavelength: float | None = None, ax: Any = None) -> Any:
    """A slice of a material table over (delta_theta, phi) (paper 000 Figs. 8-9).

    Without ``wavelength`` the table is integrated over wavelength (the broadband
    BRDF of paper 000 Eq. 2).
    """
    fig, ax = _axes(ax, figsize=(6, 4))
    da = material.sel(theta_i=theta_i, method="nearest")
    if wavelength is None:
        da = da.integrate("wavelength")
        title = f"broadband BRDF, theta_i = {float(da.theta_i):g} deg [sr-1 nm]"
    else:
        da = da.sel(wavelength=wavelength, method="nearest")
        title = f"sBRDF at {float(da.wavelength):g} nm, theta_i = {float(da.theta_i):g} deg [sr-1]"
    m = ax.pcolormesh(da["delta_theta"].values, da["phi"].values, da.transpose("phi", "delta_theta").values,
                      shading="nearest")
    fig.colorbar(m, ax=ax)
    ax.set_xlabel(_label(material["delta_theta"]))
    ax.set_ylabel(_label(material["phi"]))
    ax.set_title(f"{material.attrs.get('material', '')}: {title}")
    return fig


def plot_cube(cube: xr.Dataset) -> Any:
    """The natural figure of a cube: a light curve for attitude sweeps, spectra otherwise."""
    if "attitude" in cube.dims and cube.sizes["attitude"] > 1 and "brdf" in cube:
        return light_curve(cube)
    var = "spacecraft_sbrdf" if "spacecraft_sbrdf" in cube else "signal"
    return spectra(cube, var)
