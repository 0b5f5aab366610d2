"""The figure of a cube, chosen by what the cube is (:func:`cube_figure`).

* an **observation** over ``time`` (a pass): magnitudes and colours against UTC, with the
  geometry (phase angle, elevation, sunlit fraction) and the Earth's shadow (umbra and
  penumbra shaded, the UTC times of its edges marked);
* a **rotation** (attitude) sweep: the broadband BRDF and the magnitudes in V, R, I;
* anything else: a few **spectra**, chosen to represent the cube and labelled.

``sbrdf-xr simulate --plot`` and ``sbrdf-xr plot`` draw this figure, and so does
``cube.sbrdf.plot()``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import xarray as xr

from .._names import SHADOW_EVENTS
from ..errors import ValidationError, renamed_keywords
from ..units import to_unit
from ._labels import STYLES, band_colour, finite, label, outside_legend, spread_indices
from .curves import light_curve, magnitude_label, spectrum_curves

__all__ = [
    "CUBE_KINDS",
    "DEFAULT_RANGE_KM",
    "cube_figure",
    "cube_kind",
    "cube_magnitudes",
    "observation_figure",
    "rotation_figure",
]

#: The kinds of cube :func:`cube_figure` tells apart, and the figure of each.
CUBE_KINDS: dict[str, str] = {
    "observation": "magnitudes and colours against UTC, with the geometry and the Earth's shadow",
    "rotation": "the broadband BRDF and the V, R, I magnitudes against the attitude angle",
    "spectra": "a few representative spectra, labelled",
    "bands": "the band magnitudes of each geometry",
}
#: Range [km] of the magnitudes of a cube that records none (a rotation sweep).
DEFAULT_RANGE_KM = 1000.0


def cube_kind(cube: xr.Dataset) -> str:
    """Which figure a cube gets: a key of :data:`CUBE_KINDS`.

    Examples
    --------
    >>> t = np.datetime64("2024-03-17T01:20:00") + np.arange(3) * np.timedelta64(1, "s")
    >>> cube_kind(xr.Dataset({"brdf": ("time", [1.0, 2.0, 3.0])}, coords={"time": t}))
    'observation'
    >>> cube_kind(xr.Dataset({"brdf": (("attitude", "phase_angle"), np.ones((4, 1)))}))
    'rotation'
    >>> cube_kind(xr.Dataset({"signal": (("geometry", "wavelength"), np.ones((2, 3)))}))
    'spectra'
    """
    if not isinstance(cube, xr.Dataset):
        raise ValidationError(f"cube: expected an xarray Dataset, got {type(cube).__name__}")
    if "time" in cube.dims and cube.sizes["time"] > 1:
        return "observation"
    if "attitude" in cube.dims and cube.sizes["attitude"] > 1:
        return "rotation"
    if "wavelength" in cube.dims and ({"spacecraft_sbrdf", "signal"} & set(cube.data_vars)):
        return "spectra"
    if "band_signal" in cube:
        return "bands"
    raise ValidationError(
        f"cube: nothing to draw; expected a 'time' or 'attitude' sweep, spectra over "
        f"'wavelength' or a 'band_signal', got dims {dict(cube.sizes)} and variables "
        f"{sorted(map(str, cube.data_vars))}"
    )


@renamed_keywords(range_km="range")
def cube_magnitudes(
    cube: xr.Dataset,
    bands: Sequence[str] = ("V", "R", "I"),
    range: float | None = None,
    system: str = "AB",
) -> xr.DataArray | None:
    """Magnitudes of a cube in those of ``bands`` its spectra cover (None if none).

    From ``signal`` over wavelength, else from a band-only cube's ``band_signal``; at the
    cube's own ``range`` unless ``range`` is given, :data:`DEFAULT_RANGE_KM` when the
    cube records none.

    Parameters
    ----------
    cube : xarray.Dataset
        A simulated cube.
    bands : sequence of str
        Band names.
    range : float, optional
        Observer range [km].
    system : str
        Magnitude system.

    Returns
    -------
    xarray.DataArray or None
        Magnitudes over ``band`` [mag].

    Examples
    --------
    >>> wl = np.arange(400.0, 1101.0, 10.0)
    >>> cube = xr.Dataset({"signal": (("geometry", "wavelength"), np.full((2, wl.size), 0.1),
    ...                               {"units": "m2 sr-1"})},
    ...                   coords={"wavelength": ("wavelength", wl, {"units": "nm"})})
    >>> m = cube_magnitudes(cube, ["B", "V", "R"])  # B starts at 360 nm: left out
    >>> m.band.values.tolist(), m.attrs["range_km"]
    (['V', 'R'], 1000.0)
    """
    from .. import photometry

    if range is None and "range" not in cube.variables:
        range = DEFAULT_RANGE_KM
    elif range is not None:
        range = to_unit(range, "km", "range")
    if "wavelength" in cube.dims and "signal" in cube:
        kept = []
        for b in bands:
            try:  # a band the spectra do not cover is left out
                photometry.band_weights([b], cube["wavelength"].values)
            except ValidationError:
                continue
            kept.append(b)
        return photometry.magnitudes(cube, kept, range, system=system) if kept else None
    if "band_signal" in cube:
        sb = cube["band_signal"]
        names = sb["filter"].values if "filter" in sb.coords else sb["band"].values
        sun = photometry.sun_magnitudes([str(n) for n in names], system=system)
        sb = sb.assign_coords(sun_magnitude=("band", sun.values))
        return photometry.magnitudes(sb, range=range, system=system)
    return None


def _phase_indices(cube: xr.Dataset, max_lines: int) -> np.ndarray:
    n = cube.sizes.get("phase_angle", 1) if "phase_angle" in cube.dims else 1
    return spread_indices(n, max_lines)


@renamed_keywords(range_km="range")
def rotation_figure(
    cube: xr.Dataset,
    bands: Sequence[str] = ("V", "R", "I"),
    *,
    range: float | None = None,
    system: str = "AB",
    max_lines: int = 4,
) -> Any:
    """A rotation sweep: broadband BRDF (top) and band magnitudes (bottom) against attitude.

    Up to ``max_lines`` phase angles are drawn (line style per phase angle, colour per
    band).  Magnitudes are at the cube's range, else :data:`DEFAULT_RANGE_KM`.

    Parameters
    ----------
    cube : xarray.Dataset
        The cube to draw.
    bands : sequence of str
        Band names.
    range : float, optional
        Observer range for the magnitudes [km]; default the cube's.
    system : str
        Magnitude system.
    max_lines : int
        Most phase angles drawn.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> from sbrdf_xr import testing
    >>> fig = rotation_figure(testing.rotation_cube())
    >>> [ax.get_ylabel() for ax in fig.axes]
    ['broadband BRDF [sr-1 nm]', 'magnitude at 1000 km [AB mag]']
    >>> plt.close(fig)
    """
    import matplotlib.pyplot as plt

    mags = cube_magnitudes(cube, bands, range, system)
    panels = ["brdf" in cube, mags is not None]
    if not any(panels):
        raise ValidationError(
            "cube: a rotation sweep needs 'brdf', a 'signal' over wavelength or a 'band_signal' "
            f"to draw; it has {sorted(map(str, cube.data_vars))}"
        )
    fig, axes = plt.subplots(
        sum(panels), 1, figsize=(9, 2.2 + 2.6 * sum(panels)), sharex=True, layout="constrained"
    )
    axes = list(np.atleast_1d(axes))
    keep = _phase_indices(cube, max_lines)
    if panels[0]:
        light_curve(cube, ax=axes[0], max_lines=max_lines)
    if mags is not None:
        ax = axes[-1]
        x = cube["attitude_angle"] if "attitude_angle" in cube.coords else cube["attitude"]
        for k, i in enumerate(keep):
            m = mags.isel(phase_angle=int(i)) if "phase_angle" in mags.dims else mags
            for j, b in enumerate(m["band"].values):
                style = STYLES[k % len(STYLES)]
                ax.plot(x.values, finite(m.sel(band=b).values), style, color=band_colour(b, j),
                        lw=1, label=str(b) if k == 0 else None)  # fmt: skip
        ax.invert_yaxis()
        ax.set_ylabel(magnitude_label(mags))
        ax.set_xlabel(label(x) if "units" in x.attrs else "attitude [index]")
        outside_legend(ax, title="band")
    if panels[0] and len(axes) > 1:
        axes[0].set_xlabel("")
    return fig


def _edges(cube: xr.Dataset) -> list[tuple[str, np.datetime64]]:
    out = []
    for name in SHADOW_EVENTS:
        for word in str(cube.attrs.get(name, "")).replace(",", " ").split():
            out.append((name.replace("_", " "), np.datetime64(word, "ms")))
    return sorted(out, key=lambda e: e[1])


def _shade_shadow(axes: Sequence[Any], cube: xr.Dataset) -> list[Any]:
    """Umbra and penumbra shaded on every panel, edges as dashed lines; legend handles."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    t = cube["time"].values
    handles: list[Any] = []
    if "sunlit_fraction" in cube.variables:
        f = np.asarray(cube["sunlit_fraction"].values, dtype=np.float64)
        for where, colour, name in (
            (f == 0, "0.82", "umbra (no sunlight)"),
            ((f > 0) & (f < 1), "khaki", "penumbra"),
        ):
            if np.any(where):
                for ax in axes:
                    ax.fill_between(t, 0, 1, where=where, transform=ax.get_xaxis_transform(),
                                    color=colour, lw=0, zorder=0)  # fmt: skip
                handles.append(Patch(color=colour, label=name))
    for name, when in _edges(cube):
        for ax in axes:
            ax.axvline(when, color="0.3", ls="--", lw=0.8, zorder=1)
        stamp = np.datetime_as_string(when, unit="ms")[11:]
        handles.append(Line2D([], [], color="0.3", ls="--", lw=0.8, label=f"{name} {stamp}"))
    return handles


@renamed_keywords(range_km="range")
def observation_figure(
    cube: xr.Dataset,
    bands: Sequence[str] = ("V", "R", "I"),
    *,
    range: float | None = None,
    system: str = "AB",
) -> Any:
    """A pass: magnitudes, colours and geometry against UTC, with the Earth's shadow.

    Top: the band magnitudes at the cube's own range (gaps where nothing is lit and seen);
    middle: the colour indices of consecutive bands, the Sun's colours dotted; bottom:
    phase angle and elevation [deg], and the sunlit fraction of the solar disc (right
    axis).  The umbra and penumbra are shaded on every panel and the UTC times of the
    shadow's edges (the cube's ``umbra_exit``, ... attributes) drawn dashed and listed.

    Parameters
    ----------
    cube : xarray.Dataset
        The cube to draw.
    bands : sequence of str
        Band names.
    range : float, optional
        Observer range for the magnitudes [km]; default the cube's.
    system : str
        Magnitude system.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> from sbrdf_xr import testing
    >>> fig = observation_figure(testing.pass_cube())
    >>> [ax.get_ylabel() for ax in fig.axes]
    ['magnitude [AB mag]', 'colour index [AB mag]', 'angle [deg]', 'sunlit fraction [1]']
    >>> plt.close(fig)
    """
    import matplotlib.dates as mdates
    import matplotlib.pyplot as plt

    from .. import photometry

    mags = cube_magnitudes(cube, bands, range, system)
    fig, axes = plt.subplots(3, 1, figsize=(10, 8), sharex=True, layout="constrained",
                             height_ratios=(3, 2, 2))  # fmt: skip
    t = cube["time"].values
    if mags is not None:
        for j, b in enumerate(mags["band"].values):
            axes[0].plot(t, finite(mags.sel(band=b).values), color=band_colour(b, j), lw=1,
                         label=str(b))  # fmt: skip
        axes[0].invert_yaxis()
        outside_legend(axes[0], title="band")
        axes[0].set_ylabel(magnitude_label(mags))
        if mags.sizes["band"] > 1:
            ci = photometry.colour_indices(mags)
            sun = photometry.sun_magnitudes(list(mags["filter"].values), system=system).values
            for k, c in enumerate(ci["colour"].values):
                colour = f"C{k % 10}"
                axes[1].plot(t, finite(ci.sel(colour=c).values), color=colour, lw=1, label=str(c))
                axes[1].axhline(sun[k] - sun[k + 1], color=colour, ls=":", lw=1)
            axes[1].plot([], [], "k:", lw=1, label="the Sun's colours")
            outside_legend(axes[1], title="colour")
    axes[1].set_ylabel(f"colour index [{system} mag]")
    geo = axes[2]
    for name, colour in (("phase_angle", "k"), ("elevation", "tab:blue")):
        if name in cube.variables:
            geo.plot(t, cube[name].values, color=colour, lw=1, label=name.replace("_", " "))
    geo.set_ylabel("angle [deg]")
    handles = _shade_shadow(axes, cube)
    lines, names = geo.get_legend_handles_labels()
    if "sunlit_fraction" in cube.variables:
        right = geo.twinx()
        right.plot(t, cube["sunlit_fraction"].values, color="tab:orange", lw=1)
        right.set_ylim(-0.05, 1.05)
        right.set_ylabel("sunlit fraction [1]", color="tab:orange")
        lines.append(right.lines[-1])
        names.append("sunlit fraction (right)")
    outside_legend(geo, [*lines, *handles], [*names, *(h.get_label() for h in handles)],
                   bbox_to_anchor=(1.09, 1.0))  # fmt: skip
    day = np.datetime_as_string(t[0], unit="D")
    geo.set_xlabel(f"time [UTC] on {day}")
    geo.xaxis.set_major_formatter(mdates.DateFormatter("%H:%M:%S"))
    where = " from ".join(
        str(cube.attrs[k]) for k in ("orbit_name", "site_name") if cube.attrs.get(k)
    )
    title = ": ".join(p for p in (str(cube.attrs.get("scene", "")), where) if p)
    axes[0].set_title(title, fontsize="medium")
    return fig


def _bands_figure(cube: xr.Dataset, bands: Sequence[str], system: str) -> Any:
    import matplotlib.pyplot as plt

    mags = cube_magnitudes(cube, bands, None, system)
    if mags is None:  # pragma: no cover - a band_signal always gives magnitudes
        raise ValidationError("cube: no band magnitudes to draw")
    other = [d for d in mags.dims if d != "band"]
    flat = mags.stack(_g=other).transpose("band", "_g") if other else mags.expand_dims(_g=[0])
    fig, ax = plt.subplots(figsize=(8, 4), layout="constrained")
    for j, b in enumerate(flat["band"].values):
        ax.plot(finite(flat.sel(band=b).values), "o", ms=4, color=band_colour(b, j), label=str(b))
    ax.invert_yaxis()
    ax.set_xlabel(f"geometry ({' x '.join(map(str, other)) or 'one'}) [index]")
    ax.set_ylabel(magnitude_label(mags))
    outside_legend(ax, title="band")
    ax.set_title(str(cube.attrs.get("scene", "")), fontsize="medium")
    return fig


@renamed_keywords(range_km="range")
def cube_figure(
    cube: xr.Dataset,
    *,
    bands: Sequence[str] = ("V", "R", "I"),
    range: float | None = None,
    system: str = "AB",
    max_lines: int = 6,
) -> Any:
    """The figure of a cube, chosen by :func:`cube_kind` (see :data:`CUBE_KINDS`).

    Parameters
    ----------
    cube : xarray.Dataset
        A simulation cube (in memory or opened from a file).
    bands : sequence of str
        Bands of the magnitudes (those the cube's spectra cover).
    range : float, optional
        Range of the magnitudes [km]; default the cube's ``range``, else
        :data:`DEFAULT_RANGE_KM` (said on the axis).
    system : {"AB", "Vega"}
        Magnitude system.
    max_lines : int
        Most spectra drawn for a cube of spectra (representative ones, labelled).

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> from sbrdf_xr import testing
    >>> fig = cube_figure(testing.rotation_cube())  # an attitude sweep: BRDF and magnitudes
    >>> len(fig.axes), fig.axes[-1].get_xlabel()
    (2, 'attitude angle [deg]')
    >>> plt.close(fig)
    """
    range = None if range is None else to_unit(range, "km", "range")
    kind = cube_kind(cube)
    if kind == "observation":
        return observation_figure(cube, bands, range=range, system=system)
    if kind == "rotation":
        return rotation_figure(cube, bands, range=range, system=system)
    if kind == "bands":
        return _bands_figure(cube, bands, system)
    var = "spacecraft_sbrdf" if "spacecraft_sbrdf" in cube else "signal"
    fig = spectrum_curves(cube, var, max_lines=max_lines)
    fig.axes[0].set_title(str(cube.attrs.get("scene", "")), fontsize="medium")
    return fig
