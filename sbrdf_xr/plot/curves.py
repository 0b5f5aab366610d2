"""Single-axes figures: light curves, spectra, table slices, magnitudes, colour-colour.

Every function takes labelled objects, returns the ``matplotlib.figure.Figure`` and never
calls ``show()``; pass ``ax`` to draw into an existing axes.  No figure draws more than a
handful of lines: where a cube holds more, representative ones are picked and the legend
says which.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from ..errors import ValidationError, renamed_attributes
from ..units import to_unit
from ._labels import (
    SHORT_LABELS,
    STYLES,
    band_colour,
    finite,
    label,
    new_axes,
    outside_legend,
    spread_indices,
    unit_text,
    value_label,
    wants_log,
)

__all__ = [
    "colour_colour",
    "light_curve",
    "lut_slice",
    "magnitude_curves",
    "magnitude_label",
    "spectrum_curves",
]

#: Coordinates that name a geometry in legends, in order of preference.
_GEOMETRY_COORDS = ("time", "attitude_angle", "attitude", "geometry", "phase_angle", "material")


def _x_of(obj: xr.DataArray | xr.Dataset) -> xr.DataArray:
    for name in ("attitude_angle", "rotation_angle", "time"):
        if name in obj.coords:
            return obj[name]
    return obj["attitude"]


def _x_label(x: xr.DataArray) -> str:
    if x.dtype.kind == "M":
        return "time [UTC]"
    return label(x) if "units" in x.attrs else f"{x.name} [index]"


def light_curve(
    cube: xr.Dataset,
    variable: str = "brdf",
    ax: Any = None,
    log: bool | None = None,
    max_lines: int = 4,
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
        Logarithmic y axis; default when the data span more than
        :data:`~sbrdf_xr.plot.LOG_RATIO`.
    max_lines : int
        At most this many phase angles are drawn, spread evenly over those of the cube
        (the legend says how many of how many).

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
    ...     {"brdf": (("attitude", "phase_angle"), np.stack([s, s / 2], 1), {"units": "sr-1"})},
    ...     coords={"attitude_angle": ("attitude", ang, {"units": "degree"}),
    ...             "phase_angle": ("phase_angle", [10.0, 60.0], {"units": "degree"})})
    >>> fig = light_curve(cube)
    >>> [len(ax.lines) for ax in fig.axes], fig.axes[0].get_ylabel()  # one line per phase angle
    ([2], 'broadband BRDF [sr-1]')
    >>> plt.close(fig)
    """
    fig, ax = new_axes(ax)
    da = cube[variable]
    x = _x_of(cube)
    betas = np.atleast_1d(cube["phase_angle"].values) if "phase_angle" in da.dims else [None]
    keep = spread_indices(len(betas), max_lines)
    units = cube["phase_angle"].attrs.get("units", "degree") if "phase_angle" in cube else None
    for k, i in enumerate(keep):
        line = da if betas[i] is None else da.isel(phase_angle=int(i))
        tag = None if betas[i] is None else value_label("phase_angle", betas[i], units)
        ax.plot(x.values, finite(line.values), STYLES[k % len(STYLES)], lw=1, label=tag)
    ax.set_xlabel(_x_label(x))
    ax.set_ylabel(label(da))
    if log or (log is None and wants_log(da.values)):
        ax.set_yscale("log")
    title = str(cube.attrs.get("scene", ""))
    if len(keep) == 1 and betas[0] is not None:
        title = ", ".join(t for t in (title, value_label("phase_angle", betas[0], units)) if t)
    elif len(keep) > 1:
        more = f"{len(keep)} of {len(betas)}" if len(keep) < len(betas) else None
        outside_legend(ax, title=more and f"{more} phase angles")
    ax.set_title(title, fontsize="medium")
    return fig


def _representatives(values: np.ndarray, k: int) -> tuple[np.ndarray, list[str], int]:
    """Indices of ``k`` lines spread over the ranking of ``values``, their roles, the dark count."""
    lit = np.flatnonzero(np.isfinite(values) & (values > 0))
    order = lit[np.argsort(values[lit], kind="stable")[::-1]]  # brightest first
    if order.size <= k:
        roles = ["" for _ in order]
        return order, roles, values.size - lit.size
    pos = spread_indices(order.size, k)
    roles = []
    for p in pos:
        if p == 0:
            roles.append("brightest")
        elif p == order.size - 1:
            roles.append("faintest lit")
        else:
            roles.append(f"rank {p + 1}")
    return order[pos], roles, values.size - lit.size


def _line_name(line: xr.DataArray, cube: xr.Dataset | xr.DataArray) -> str:
    names = []
    for c in _GEOMETRY_COORDS:
        if c == "attitude" and "attitude_angle" in line.coords:
            continue
        if c in line.coords and line[c].ndim == 0 and c in cube.coords and cube[c].size > 1:
            names.append(value_label(c, line[c].values, cube[c].attrs.get("units")))
    return ", ".join(names)


def spectrum_curves(
    cube: xr.Dataset,
    variable: str = "spacecraft_sbrdf",
    ax: Any = None,
    log: bool | None = None,
    max_lines: int = 6,
    **sel: Any,
) -> Any:
    """Spectra of a cube (paper 000 Figs. 14 and 16), one labelled line per geometry.

    A cube of more than ``max_lines`` spectra is represented by ``max_lines`` of them,
    spread evenly over their ranking by the mean over wavelength: the brightest, the
    faintest lit one and equally spaced ranks between (``rank 51`` is the 51st
    brightest); the legend's title says how many of how many, and how many are dark
    (zero: nothing lit and seen).

    Parameters
    ----------
    cube : xarray.Dataset
    variable : str, default "spacecraft_sbrdf"
    ax : matplotlib axes, optional
    log : bool, optional
        Logarithmic y axis (Fig. 16); default when the data span more than
        :data:`~sbrdf_xr.plot.LOG_RATIO`.
    max_lines : int
        Most lines drawn.
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
    >>> rng = np.random.default_rng(1)
    >>> cube = xr.Dataset(  # 100 geometries: far more than a figure can show
    ...     {"spacecraft_sbrdf": (("geometry", "wavelength"), rng.uniform(0.1, 1.0, (100, 3)),
    ...                           {"units": "sr-1"})},
    ...     coords={"geometry": np.arange(100),
    ...             "wavelength": ("wavelength", [450.0, 550.0, 650.0], {"units": "nm"})})
    >>> fig = spectrum_curves(cube)
    >>> ax = fig.axes[0]
    >>> len(ax.lines), ax.get_legend().get_title().get_text()
    (6, '6 of 100 spectra, ranked by mean overall sBRDF')
    >>> ax.get_legend().get_texts()[0].get_text()[:9]
    'brightest'
    >>> plt.close(fig)
    """
    fig, ax = new_axes(ax, figsize=(10, 4))
    da = cube[variable].sel(**sel) if sel else cube[variable]
    other = [d for d in da.dims if d != "wavelength"]
    stacked = da.stack(_line=other) if other else da.expand_dims(_line=[0])
    stacked = stacked.transpose("_line", "wavelength")
    n = stacked.sizes["_line"]
    mean = np.asarray(stacked.mean("wavelength").values, dtype=np.float64)
    if n <= max_lines:
        picks, roles, dark = np.arange(n), [""] * n, 0
    else:
        picks, roles, dark = _representatives(mean, max_lines)
    wl = stacked["wavelength"].values
    for k, (i, role) in enumerate(zip(picks, roles, strict=True)):
        line = stacked.isel(_line=int(i))
        name = ": ".join(p for p in (role, _line_name(line, cube)) if p)
        ax.plot(wl, finite(line.values), STYLES[(k // 10) % len(STYLES)], lw=1, label=name or None)
    ax.set_xlabel(label(cube["wavelength"]))
    ax.set_ylabel(label(cube[variable]))
    if log or (log is None and wants_log(stacked.isel(_line=picks).values)):
        ax.set_yscale("log")
    if n > max_lines:
        short = SHORT_LABELS.get(variable, variable)
        title = f"{len(picks)} of {n} spectra, ranked by mean {short}"
        outside_legend(ax, title=title + (f"\n({dark} dark: nothing lit and seen)" if dark else ""))
    elif any(line.get_label() and not line.get_label().startswith("_") for line in ax.lines):
        outside_legend(ax)
    return fig


def lut_slice(
    material: xr.DataArray, theta_i: float, wavelength: float | None = None, ax: Any = None
) -> Any:
    """A slice of a material table over (delta_theta, phi) (paper 000 Figs. 8-9).

    Without ``wavelength`` the table is integrated over wavelength (the broadband
    BRDF of paper 000 Eq. 2).

    Parameters
    ----------
    material : DataArray
        A material table.
    theta_i : float
        Incidence angle of the slice [degree] (the nearest node).
    wavelength : float, optional
        Wavelength of the slice [nm] (the nearest node).
    ax : matplotlib Axes, optional
        Where to draw.

    A Quantity is converted to the unit of its argument.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> fig = lut_slice(lambertian(0.5, wavelength=[500.0, 600.0]), theta_i=30.0)
    >>> fig.axes[0].get_xlabel(), fig.axes[1].get_ylabel()  # the colour bar carries the unit
    ('delta_theta [deg]', 'broadband BRDF [sr-1 nm]')
    >>> plt.close(fig)
    """
    theta_i = to_unit(theta_i, "deg", "theta_i")
    wavelength = to_unit(wavelength, "nm", "wavelength", spectral=True)
    fig, ax = new_axes(ax, figsize=(6, 4))
    da = material.sel(theta_i=theta_i, method="nearest")
    units = unit_text(str(material.attrs.get("units", "sr-1")))
    if wavelength is None:
        da = da.integrate("wavelength")
        title, bar = f"theta_i = {float(da.theta_i):g} deg", f"broadband BRDF [{units} nm]"
    else:
        da = da.sel(wavelength=wavelength, method="nearest")
        title = f"{float(da.wavelength):g} nm, theta_i = {float(da.theta_i):g} deg"
        bar = f"sBRDF [{units}]"
    m = ax.pcolormesh(
        da["delta_theta"].values,
        da["phi"].values,
        da.transpose("phi", "delta_theta").values,
        shading="nearest",
    )
    fig.colorbar(m, ax=ax, label=bar)
    ax.set_xlabel(label(material["delta_theta"]))
    ax.set_ylabel(label(material["phi"]))
    name = material.attrs.get("material", "")
    ax.set_title(f"{name}: {title}" if name else title, fontsize="medium")
    return fig


def magnitude_label(mags: xr.DataArray) -> str:
    """``magnitude at 1000 km [Vega mag]`` from a magnitude's attributes.

    Examples
    --------
    >>> mags = xr.DataArray([1.0], attrs={"magnitude_system": "Vega", "range_km": 1000.0})
    >>> magnitude_label(mags)
    'magnitude at 1000 km [Vega mag]'
    """
    system = str(mags.attrs.get("magnitude_system", "")).strip()
    rng = mags.attrs.get("range_km")
    at = f" at {float(rng):g} km" if isinstance(rng, (int, float)) and np.isfinite(rng) else ""
    return f"magnitude{at} [{system + ' ' if system else ''}mag]"


def magnitude_curves(mags: xr.DataArray, ax: Any = None, x: str | None = None, **sel: Any) -> Any:
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
    >>> wave = np.cos(np.radians(ang))
    >>> mags = xr.DataArray(np.stack([12 - wave, 11.5 - wave], 1),
    ...                     dims=("attitude", "band"),
    ...                     attrs={"units": "1", "magnitude_system": "AB", "range_km": 1000.0},
    ...                     coords={"attitude_angle": ("attitude", ang, {"units": "degree"}),
    ...                             "band": ["B", "V"]})
    >>> fig = magnitude_curves(mags)
    >>> ax = fig.axes[0]
    >>> len(ax.lines), bool(ax.yaxis_inverted()), ax.get_ylabel()  # brighter up
    (2, True, 'magnitude at 1000 km [AB mag]')
    >>> plt.close(fig)
    """
    fig, ax = new_axes(ax)
    da = mags.sel(**sel) if sel else mags
    if "phase_angle" in da.dims and da.sizes["phase_angle"] == 1:
        da = da.isel(phase_angle=0)
    other = [str(d) for d in da.dims if d != "band"]
    if len(other) != 1:
        raise ValidationError(
            f"magnitudes: expected dims (band, one more) after selection, got {da.dims}; "
            "select the others, e.g. phase_angle=10"
        )
    if x is None:
        names = ("attitude_angle", "rotation_angle", "time")
        x = next((c for c in names if c in da.coords), other[0])
    xc = da[x]
    for k, b in enumerate(da["band"].values):
        ax.plot(xc.values, finite(da.sel(band=b).values), lw=1, color=band_colour(str(b), k))
        ax.lines[-1].set_label(str(b))
    if not ax.yaxis_inverted():
        ax.invert_yaxis()
    ax.set_xlabel(_x_label(xc))
    ax.set_ylabel(magnitude_label(mags))
    outside_legend(ax, title="band")
    return fig


def colour_colour(
    ds: xr.Dataset,
    x: str,
    y: str,
    ax: Any = None,
    sun: bool = True,
    c: str | None = None,
    colorbar: bool = True,
    track: bool = True,
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
        Coordinate to colour the points by (default ``attitude_angle`` when present,
        in a cyclic colour map).
    colorbar : bool
        Add a colour bar for ``c``.
    track : bool
        Join the points in order with a thin line (the path of a sweep).

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> ang = np.arange(0.0, 360.0, 30.0)
    >>> ph = xr.Dataset({"colour_index": (("attitude", "colour"),
    ...                                    np.stack([0.6 + 0.01 * np.cos(np.radians(ang)),
    ...                                              0.4 + 0.02 * np.sin(np.radians(ang))], 1),
    ...                                    {"units": "1"})},
    ...                 coords={"colour": ["B-V", "V-R"], "first": ("colour", ["B", "V"]),
    ...                         "second": ("colour", ["V", "R"])}, attrs={"magnitude_system": "AB"})
    >>> fig = colour_colour(ph, "B-V", "V-R")
    >>> fig.axes[0].get_xlabel()
    'B-V [AB mag]'
    >>> plt.close(fig)
    """
    fig, ax = new_axes(ax, figsize=(5, 4.5))
    ci = ds["colour_index"]
    labels = [str(v) for v in ci["colour"].values]
    for want in (x, y):
        if want not in labels:
            raise ValidationError(
                f"colour_colour: colour {want!r} not in {labels}; compute it with pairs=..."
            )
    xv = ci.sel(colour=x).values.ravel()
    yv = ci.sel(colour=y).values.ravel()
    if track:
        ax.plot(xv, yv, "-", color="0.6", lw=0.6, zorder=1)
    cname = c or ("attitude_angle" if "attitude_angle" in ci.coords else None)
    if cname is not None:
        cv = np.broadcast_to(ci[cname].values, ci.sel(colour=x).shape).ravel()
        cmap = "twilight" if cname in ("attitude_angle", "rotation_angle") else "viridis"
        pts = ax.scatter(xv, yv, c=cv, s=10, cmap=cmap, zorder=2, linewidths=0)
        if colorbar:
            fig.colorbar(pts, ax=ax, label=label(ci[cname]))
    else:
        ax.scatter(xv, yv, s=10, zorder=2, linewidths=0)
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
            ms=15,
            mfc="none",
            mec="orangered",
            mew=1.5,
            zorder=5,
            label="the Sun (a grey body)",
        )
        ax.legend(fontsize="small")
    sysname = ds.attrs.get("magnitude_system", ci.attrs.get("magnitude_system", ""))
    unit = f"{sysname} mag" if sysname else "mag"
    ax.set_xlabel(f"{x} [{unit}]")
    ax.set_ylabel(f"{y} [{unit}]")
    return fig


#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(
    __name__, globals(), {"magnitudes": "magnitude_curves", "spectra": "spectrum_curves"}
)
