"""Matplotlib figures of cubes and materials.

Every function takes labelled objects, returns the ``matplotlib.figure.Figure``
and never calls ``show()``; pass ``ax`` to draw into an existing axes.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

__all__ = ["colour_colour", "light_curve", "lut_slice", "magnitudes", "plot_cube", "spectra"]

#: Short axis labels of the package's variables (the long_name goes into titles and docs).
SHORT_LABELS: dict[str, str] = {
    "spacecraft_sbrdf": "overall sBRDF",
    "brdf": "broadband BRDF",
    "signal": "radiometric signal",
    "signal_material": "signal per material",
    "band_signal": "band signal",
    "magnitude": "magnitude",
    "standard_magnitude": "standard magnitude",
    "colour_index": "colour index",
    "wavelength": "wavelength",
    "attitude_angle": "attitude angle",
    "phase_angle": "phase angle",
    "rotation_angle": "rotation angle",
    "sbrdf": "sBRDF",
    "theta_i": "theta_i",
    "delta_theta": "delta_theta",
    "phi": "phi",
}
_UNIT_TEXT = {"degree": "deg", "1": ""}
#: Above this max/min ratio of positive data the y axis is logarithmic by default.
LOG_RATIO = 30.0
_STYLES = ("-", "--", "-.", ":")


def _axes(ax: Any = None, **fig_kw: Any) -> tuple[Any, Any]:
    import matplotlib.pyplot as plt

    if ax is None:
        fig, ax = plt.subplots(**({"figsize": (8, 4), "layout": "constrained"} | fig_kw))
        return fig, ax
    return ax.figure, ax


def _label(da: xr.DataArray) -> str:
    """A short axis label with units: ``short name [units]`` (never the long_name)."""
    name = SHORT_LABELS.get(str(da.name), str(da.name).replace("_", " "))
    units = str(da.attrs.get("units", ""))
    units = _UNIT_TEXT.get(units, units)
    return f"{name} [{units}]" if units else name


def _value_label(coord: str, value: Any, units: str | None) -> str:
    """``phase angle 5 deg`` for legends."""
    u = _UNIT_TEXT.get(units or "", units or "")
    name = SHORT_LABELS.get(coord, coord.replace("_", " "))
    return f"{name} {float(value):g} {u}".rstrip()


def _wants_log(values: Any) -> bool:
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v) & (v > 0)]
    return bool(v.size) and float(v.max() / v.min()) > LOG_RATIO


def light_curve(
    cube: xr.Dataset, variable: str = "brdf", ax: Any = None, log: bool | None = None
) -> Any:
    """Broadband BRDF (paper 000 Fig. 18) or another scalar variable versus attitude.

    Parameters
    ----------
    cube : xarray.Dataset
        A simulation cube over ``attitude`` (and ``phase_angle``).
    variable : str, default "brdf"
        Variable without a spectral dimension.
    ax : matplotlib axes, optional
    log : bool, optional
        Logarithmic y axis; default when the data span more than :data:`LOG_RATIO`.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> ang = np.arange(0.0, 360.0, 30.0)
    >>> s = 0.1 + 0.05 * np.cos(np.radians(ang))  # a broadband BRDF over a rotation [sr-1]
    >>> cube = xr.Dataset(
    ...     {"brdf": (("attitude", "phase_angle"), np.stack([s, s / 2], 1), {"units": "sr-1"}),
    ...      "spacecraft_sbrdf": (("attitude", "phase_angle", "wavelength"),
    ...                           np.stack([s, s / 2], 1)[..., None] * [0.8, 1.0, 1.1],
    ...                           {"units": "sr-1"})},
    ...     coords={"attitude_angle": ("attitude", ang, {"units": "degree"}),
    ...             "phase_angle": ("phase_angle", [10.0, 60.0], {"units": "degree"}),
    ...             "wavelength": ("wavelength", [450.0, 550.0, 650.0], {"units": "nm"})})
    >>> fig = light_curve(cube)
    >>> type(fig).__name__, [len(ax.lines) for ax in fig.axes]  # one line per phase angle
    ('Figure', [2])
    >>> plt.close(fig)
    """
    fig, ax = _axes(ax)
    da = cube[variable]
    x = cube["attitude_angle"] if "attitude_angle" in cube.coords else cube["attitude"]
    units = cube["phase_angle"].attrs.get("units", "degree")
    for k, beta in enumerate(np.atleast_1d(cube["phase_angle"].values)):
        ax.plot(
            x.values,
            da.sel(phase_angle=beta).values,
            _STYLES[k % len(_STYLES)],
            lw=1,
            label=_value_label("phase_angle", beta, units),
        )
    ax.set_xlabel(_label(x) if "units" in x.attrs else "attitude [index]")
    ax.set_ylabel(_label(da))
    if log or (log is None and _wants_log(da.values)):
        ax.set_yscale("log")
    ax.set_title(cube.attrs.get("scene", ""))
    ax.legend()
    return fig


def spectra(
    cube: xr.Dataset,
    variable: str = "spacecraft_sbrdf",
    ax: Any = None,
    log: bool | None = None,
    **sel: Any,
) -> Any:
    """Spectra of a cube (paper 000 Figs. 14 and 16), one line per remaining geometry.

    Parameters
    ----------
    cube : xarray.Dataset
    variable : str, default "spacecraft_sbrdf"
    ax : matplotlib axes, optional
    log : bool, optional
        Logarithmic y axis (Fig. 16); default when the data span more than :data:`LOG_RATIO`.
    **sel
        Selections applied first (for example ``attitude=0``).

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> ang = np.arange(0.0, 360.0, 30.0)
    >>> s = 0.1 + 0.05 * np.cos(np.radians(ang))  # a broadband BRDF over a rotation [sr-1]
    >>> cube = xr.Dataset(
    ...     {"brdf": (("attitude", "phase_angle"), np.stack([s, s / 2], 1), {"units": "sr-1"}),
    ...      "spacecraft_sbrdf": (("attitude", "phase_angle", "wavelength"),
    ...                           np.stack([s, s / 2], 1)[..., None] * [0.8, 1.0, 1.1],
    ...                           {"units": "sr-1"})},
    ...     coords={"attitude_angle": ("attitude", ang, {"units": "degree"}),
    ...             "phase_angle": ("phase_angle", [10.0, 60.0], {"units": "degree"}),
    ...             "wavelength": ("wavelength", [450.0, 550.0, 650.0], {"units": "nm"})})
    >>> fig = spectra(cube, attitude=0)
    >>> type(fig).__name__, len(fig.axes[0].lines)  # one line per phase angle
    ('Figure', 2)
    >>> plt.close(fig)
    """
    fig, ax = _axes(ax)
    da = cube[variable].sel(**sel) if sel else cube[variable]
    stacked = (
        da.stack(_line=[d for d in da.dims if d != "wavelength"])
        if da.ndim > 1
        else da.expand_dims(_line=[0])
    )
    varying = [
        c
        for c in ("attitude_angle", "attitude", "geometry", "phase_angle")
        if c in stacked.coords and stacked[c].size > 1 and "_line" in stacked[c].dims
    ]
    for k in range(stacked.sizes["_line"]):
        line = stacked.isel(_line=k)
        label = ", ".join(
            _value_label(c, line[c].values, cube[c].attrs.get("units")) for c in varying
        )
        ax.plot(
            line["wavelength"].values,
            line.values,
            _STYLES[(k // 10) % len(_STYLES)],
            lw=1,
            label=label or None,
        )
    ax.set_xlabel(_label(cube["wavelength"]))
    ax.set_ylabel(_label(cube[variable]))
    if log or (log is None and _wants_log(da.values)):
        ax.set_yscale("log")
    if stacked.sizes["_line"] <= 12:
        ax.legend()
    return fig


def lut_slice(
    material: xr.DataArray, theta_i: float, wavelength: float | None = None, ax: Any = None
) -> Any:
    """A slice of a material table over (delta_theta, phi) (paper 000 Figs. 8-9).

    Without ``wavelength`` the table is integrated over wavelength (the broadband
    BRDF of paper 000 Eq. 2).

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> fig = lut_slice(lambertian(0.5, wavelength=[500.0, 600.0]), theta_i=30.0)
    >>> type(fig).__name__, fig.axes[0].get_xlabel()
    ('Figure', 'delta_theta [deg]')
    >>> plt.close(fig)
    """
    fig, ax = _axes(ax, figsize=(6, 4))
    da = material.sel(theta_i=theta_i, method="nearest")
    if wavelength is None:
        da = da.integrate("wavelength")
        title = f"broadband BRDF, theta_i = {float(da.theta_i):g} deg [sr-1 nm]"
    else:
        da = da.sel(wavelength=wavelength, method="nearest")
        title = f"sBRDF at {float(da.wavelength):g} nm, theta_i = {float(da.theta_i):g} deg [sr-1]"
    m = ax.pcolormesh(
        da["delta_theta"].values,
        da["phi"].values,
        da.transpose("phi", "delta_theta").values,
        shading="nearest",
    )
    fig.colorbar(m, ax=ax)
    ax.set_xlabel(_label(material["delta_theta"]))
    ax.set_ylabel(_label(material["phi"]))
    ax.set_title(f"{material.attrs.get('material', '')}: {title}")
    return fig


def plot_cube(cube: xr.Dataset) -> Any:
    """The natural figure of a cube: a light curve for attitude sweeps, spectra otherwise.

    Axes are logarithmic where the data span more than :data:`LOG_RATIO` (a glinting
    light curve spans 100x).

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> ang = np.arange(0.0, 360.0, 30.0)
    >>> s = 0.1 + 0.05 * np.cos(np.radians(ang))  # a broadband BRDF over a rotation [sr-1]
    >>> cube = xr.Dataset(
    ...     {"brdf": (("attitude", "phase_angle"), np.stack([s, s / 2], 1), {"units": "sr-1"}),
    ...      "spacecraft_sbrdf": (("attitude", "phase_angle", "wavelength"),
    ...                           np.stack([s, s / 2], 1)[..., None] * [0.8, 1.0, 1.1],
    ...                           {"units": "sr-1"})},
    ...     coords={"attitude_angle": ("attitude", ang, {"units": "degree"}),
    ...             "phase_angle": ("phase_angle", [10.0, 60.0], {"units": "degree"}),
    ...             "wavelength": ("wavelength", [450.0, 550.0, 650.0], {"units": "nm"})})
    >>> fig = plot_cube(cube)  # an attitude sweep: its light curve
    >>> type(fig).__name__, fig.axes[0].get_xlabel()
    ('Figure', 'attitude angle [deg]')
    >>> plt.close(fig)
    """
    if "attitude" in cube.dims and cube.sizes["attitude"] > 1 and "brdf" in cube:
        return light_curve(cube)
    var = "spacecraft_sbrdf" if "spacecraft_sbrdf" in cube else "signal"
    return spectra(cube, var)


def _system_text(da: xr.DataArray) -> str:
    """``(Vega, 1000 km)`` from a magnitude's attributes."""
    sysname = da.attrs.get("magnitude_system")
    rng = da.attrs.get("range_km")
    parts = [str(sysname) if sysname else "", f"{rng:g} km" if rng else ""]
    inner = ", ".join(p for p in parts if p)
    return f"({inner})" if inner else ""


def magnitudes(mags: xr.DataArray, ax: Any = None, x: str | None = None, **sel: Any) -> Any:
    """Magnitudes per band against attitude (or rotation angle, or time), brighter up.

    Parameters
    ----------
    mags : xarray.DataArray
        Magnitudes over ``band`` and one other dimension (after ``sel``), e.g.
        :func:`sbrdf_xr.photometry.magnitudes` of a rotation sweep.
    ax : matplotlib axes, optional
    x : str, optional
        Coordinate for the x axis; default ``attitude_angle``, ``rotation_angle`` or
        ``time``, whichever exists.
    **sel
        Selections applied first (e.g. ``phase_angle=10``).

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> ang = np.arange(0.0, 360.0, 30.0)
    >>> s = 0.1 + 0.05 * np.cos(np.radians(ang))  # a broadband BRDF over a rotation [sr-1]
    >>> cube = xr.Dataset(
    ...     {"brdf": (("attitude", "phase_angle"), np.stack([s, s / 2], 1), {"units": "sr-1"}),
    ...      "spacecraft_sbrdf": (("attitude", "phase_angle", "wavelength"),
    ...                           np.stack([s, s / 2], 1)[..., None] * [0.8, 1.0, 1.1],
    ...                           {"units": "sr-1"})},
    ...     coords={"attitude_angle": ("attitude", ang, {"units": "degree"}),
    ...             "phase_angle": ("phase_angle", [10.0, 60.0], {"units": "degree"}),
    ...             "wavelength": ("wavelength", [450.0, 550.0, 650.0], {"units": "nm"})})
    >>> wave = np.cos(np.radians(ang))
    >>> mags = xr.DataArray(np.stack([12 - wave, 11.5 - wave], 1),
    ...                     dims=("attitude", "band"),
    ...                     attrs={"units": "1", "magnitude_system": "AB"},
    ...                     coords={"attitude_angle": ("attitude", ang, {"units": "degree"}),
    ...                             "band": ["B", "V"]})
    >>> fig = magnitudes(mags)
    >>> type(fig).__name__, len(fig.axes[0].lines), bool(fig.axes[0].yaxis_inverted())  # bright up
    ('Figure', 2, True)
    >>> plt.close(fig)
    """
    fig, ax = _axes(ax)
    da = mags.sel(**sel) if sel else mags
    if "phase_angle" in da.dims and da.sizes["phase_angle"] == 1:
        da = da.isel(phase_angle=0)
    other = [str(d) for d in da.dims if d != "band"]
    if len(other) != 1:
        raise ValueError(
            f"magnitudes: expected dims (band, one more) after selection, got {da.dims}; "
            "select the others, e.g. phase_angle=10"
        )
    if x is None:
        x = next(
            (c for c in ("attitude_angle", "rotation_angle", "time") if c in da.coords), other[0]
        )
    xc = da[x]
    for k, b in enumerate(da["band"].values):
        ax.plot(
            xc.values, da.sel(band=b).values, _STYLES[(k // 10) % len(_STYLES)], lw=1, label=str(b)
        )
    ax.invert_yaxis()
    ax.set_xlabel(_label(xc) if xc.dtype.kind != "M" else "time [UTC]")
    ax.set_ylabel(" ".join(p for p in ("magnitude", _system_text(mags)) if p))
    ax.legend(title="band", fontsize="small")
    return fig


def colour_colour(
    ds: xr.Dataset, x: str, y: str, ax: Any = None, sun: bool = True, c: str | None = None
) -> Any:
    """Colour-colour diagram of a photometry Dataset (one point per geometry/attitude).

    Parameters
    ----------
    ds : xarray.Dataset
        :func:`sbrdf_xr.photometry.photometry` output with ``colour_index``.
    x, y : str
        Colour labels, e.g. ``"B-V"`` and ``"V-R"`` (in ``ds.colour``).
    ax : matplotlib axes, optional
    sun : bool
        Mark the Sun's colours (a spectrally flat reflector) from the ``sun_magnitude``
        coordinate.
    c : str, optional
        Coordinate to colour the points by (default ``attitude_angle`` when present).

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> ang = np.arange(0.0, 360.0, 30.0)
    >>> s = 0.1 + 0.05 * np.cos(np.radians(ang))  # a broadband BRDF over a rotation [sr-1]
    >>> cube = xr.Dataset(
    ...     {"brdf": (("attitude", "phase_angle"), np.stack([s, s / 2], 1), {"units": "sr-1"}),
    ...      "spacecraft_sbrdf": (("attitude", "phase_angle", "wavelength"),
    ...                           np.stack([s, s / 2], 1)[..., None] * [0.8, 1.0, 1.1],
    ...                           {"units": "sr-1"})},
    ...     coords={"attitude_angle": ("attitude", ang, {"units": "degree"}),
    ...             "phase_angle": ("phase_angle", [10.0, 60.0], {"units": "degree"}),
    ...             "wavelength": ("wavelength", [450.0, 550.0, 650.0], {"units": "nm"})})
    >>> ph = xr.Dataset({"colour_index": (("attitude", "colour"),
    ...                                    np.stack([0.6 + 0.01 * np.cos(np.radians(ang)),
    ...                                              0.4 + 0.02 * np.sin(np.radians(ang))], 1),
    ...                                    {"units": "1"})},
    ...                 coords={"colour": ["B-V", "V-R"], "first": ("colour", ["B", "V"]),
    ...                         "second": ("colour", ["V", "R"])}, attrs={"magnitude_system": "AB"})
    >>> fig = colour_colour(ph, "B-V", "V-R")
    >>> type(fig).__name__, fig.axes[0].get_xlabel()
    ('Figure', 'B-V')
    >>> plt.close(fig)
    """
    fig, ax = _axes(ax, figsize=(5, 4.5))
    ci = ds["colour_index"]
    labels = [str(v) for v in ci["colour"].values]
    for want in (x, y):
        if want not in labels:
            raise ValueError(
                f"colour_colour: colour {want!r} not in {labels}; compute it with pairs=..."
            )
    xv = ci.sel(colour=x).values.ravel()
    yv = ci.sel(colour=y).values.ravel()
    cname = c or ("attitude_angle" if "attitude_angle" in ci.coords else None)
    if cname is not None:
        cv = np.broadcast_to(ci[cname].values, ci.sel(colour=x).shape).ravel()
        pts = ax.scatter(xv, yv, c=cv, s=12, cmap="viridis")
        fig.colorbar(pts, ax=ax, label=_label(ci[cname]))
    else:
        ax.scatter(xv, yv, s=12)
    if sun and "sun_magnitude" in ds.coords:
        m = {
            str(b): float(v)
            for b, v in zip(ds["band"].values, ds["sun_magnitude"].values, strict=True)
        }
        sx = [m[b] for b in x.split("-")]
        sy = [m[b] for b in y.split("-")]
        ax.plot(
            sx[0] - sx[1],
            sy[0] - sy[1],
            "*",
            ms=16,
            mfc="none",
            mec="orangered",
            mew=1.5,
            zorder=5,
            label="Sun (a grey body)",
        )
        ax.legend(fontsize="small")
    sysname = ci.attrs.get("magnitude_system", "")
    ax.set_xlabel(f"{x} [{sysname} mag]" if sysname else x)
    ax.set_ylabel(f"{y} [{sysname} mag]" if sysname else y)
    return fig
