"""Shared pieces of the figures: short labels with units, new axes, log-axis choice, colours."""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

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
    "elevation": "elevation",
    "sunlit_fraction": "sunlit fraction",
    "sbrdf": "sBRDF",
    "theta_i": "theta_i",
    "delta_theta": "delta_theta",
    "phi": "phi",
}
#: Above this max/min ratio of positive data the y axis is logarithmic by default.
LOG_RATIO = 30.0
#: Line colours of the usual bands (blue to near infrared); other bands take the cycle.
BAND_COLOURS: dict[str, str] = {
    "U": "tab:purple",
    "B": "tab:blue",
    "V": "tab:green",
    "R": "tab:red",
    "I": "black",
    "g": "tab:green",
    "r": "tab:red",
    "i": "black",
    "z": "tab:gray",
}
_UNIT_TEXT = {"degree": "deg", "1": "1"}
STYLES = ("-", "--", "-.", ":")


def new_axes(ax: Any = None, **fig_kw: Any) -> tuple[Any, Any]:
    """``(figure, axes)``: ``ax`` and its figure, or a new constrained-layout figure."""
    import matplotlib.pyplot as plt

    if ax is None:
        fig, ax = plt.subplots(**({"figsize": (8, 4), "layout": "constrained"} | fig_kw))
        return fig, ax
    return ax.figure, ax


def unit_text(units: str | None) -> str:
    """Units as printed in a label: ``degree`` -> ``deg``."""
    return _UNIT_TEXT.get(units or "", units or "")


def label(da: xr.DataArray, name: str | None = None) -> str:
    """A short axis label with units: ``short name [units]`` (never the long_name)."""
    short = name or SHORT_LABELS.get(str(da.name), str(da.name).replace("_", " "))
    units = unit_text(str(da.attrs.get("units", "")))
    return f"{short} [{units}]" if units else short


def value_label(coord: str, value: Any, units: str | None) -> str:
    """``phase angle 5 deg`` for legends (times as ``HH:MM:SS``)."""
    name = SHORT_LABELS.get(coord, coord.replace("_", " "))
    v = np.asarray(value)
    if v.dtype.kind == "M":
        return f"{name} {np.datetime_as_string(v, unit='s')[11:]}"
    if v.dtype.kind in "US":
        return f"{name} {v!s}"
    return f"{name} {float(v):.4g} {unit_text(units)}".rstrip()


def wants_log(values: Any) -> bool:
    """True when the positive finite values span more than :data:`LOG_RATIO`."""
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v) & (v > 0)]
    return bool(v.size) and float(v.max() / v.min()) > LOG_RATIO


def band_colour(band: str, k: int) -> str:
    """The colour of a band's line: :data:`BAND_COLOURS`, else the k-th of the cycle."""
    return BAND_COLOURS.get(band, f"C{k % 10}")


def finite(values: Any) -> np.ndarray:
    """Values as float with infinities (an unlit or unseen object's magnitude) as NaN."""
    v = np.asarray(values, dtype=np.float64)
    return np.where(np.isfinite(v), v, np.nan)


def spread_indices(n: int, k: int) -> np.ndarray:
    """``k`` indices spread evenly over ``range(n)``, first and last included (all if fewer)."""
    if n <= k:
        return np.arange(n)
    return np.unique(np.round(np.linspace(0, n - 1, k)).astype(int))


def outside_legend(ax: Any, handles: Any = None, labels: Any = None, **kw: Any) -> Any:
    """A legend to the right of the axes (never over the data); constrained layout makes room."""
    kw = {"loc": "upper left", "bbox_to_anchor": (1.01, 1.0), "borderaxespad": 0.0} | kw
    kw.setdefault("fontsize", "small")
    if handles is None:
        return ax.legend(**kw)
    return ax.legend(handles, labels, **kw)
