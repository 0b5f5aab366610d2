"""The steps of :func:`sbrdf_xr.lightcurves.read_light_curve` between a parsed table and
its Dataset: the band columns found (long or wide form), their values as magnitudes
with their uncertainties, and the abscissa (times or rotation angles).

Every error names the file, the row (as the file counts it) and the column.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .._names import BAND, attrs
from ..errors import LightCurveError
from . import _curve_forms as forms
from ._table_io import in_unit
from .filter_names import band_label


@dataclass
class Table:
    """A table being read: its file, its frame, the roles, units and metadata of its columns."""

    path: Path
    df: Any
    units: dict[str, Any]
    meta: dict[str, Any]
    where: str
    offset: int
    bands: Sequence[str] | None
    band_map: Mapping[str, str] | None
    roles: dict[str, str] = field(default_factory=dict)

    def row_name(self, k: int) -> str:
        """``file: row n`` of data row ``k`` (0-based), as the file counts its rows."""
        text = (
            self.where.format(k + 1, k + 1 + self.offset)
            if self.offset
            else self.where.format(k + 1)
        )
        return f"{self.path}: {text}"

    def numeric(self, values: Any, col: str, rows: np.ndarray, allow_empty: bool = False) -> Any:
        """``values`` as float64, or the first cell that is not a finite number named."""
        import pandas as pd

        raw = pd.Series(values).reset_index(drop=True)
        text = raw.astype(str).str.strip() if raw.dtype == object else raw
        v = pd.to_numeric(text, errors="coerce").to_numpy(dtype=np.float64)
        bad = np.flatnonzero(~np.isfinite(v))
        if allow_empty:
            empty = raw.isna().to_numpy() | (
                raw.astype(str).str.strip().isin(["", "nan", "NaN", "--"]).to_numpy()
            )
            bad = np.flatnonzero(~np.isfinite(v) & ~empty)
        if bad.size:
            val = raw.iloc[bad[0]]
            val = val.item() if hasattr(val, "item") else val
            try:  # a number (NaN, inf) is shown; text is not (the file's contents)
                float(val)
                shown = f"value {val!r} is not a finite number"
            except (TypeError, ValueError):
                shown = f"holds text of {len(str(val))} characters, not a number"
            raise LightCurveError(f"{self.row_name(int(rows[bad[0]]))}, column {col!r}: {shown}")
        return v


@dataclass
class Values:
    """The observations of every band column, in file order of the parts."""

    rows: np.ndarray
    bands: list[str]
    written: list[str]
    magnitude: np.ndarray
    uncertainty: np.ndarray
    flux_note: str


def abscissa_role(t: Table, abscissae: Sequence[str]) -> str:
    """The one role of time or rotation angle among the table's columns."""
    absc = [r for r in abscissae if r in t.roles]
    if len(absc) != 1:
        raise LightCurveError(
            f"{t.path}: need exactly one column of time (time, jd or mjd, with UTC) or "
            f"rotation_angle, found {[t.roles[r] for r in absc] or 'none'} among its "
            f"{len(t.df.columns)} columns"
        )
    return absc[0]


def _part(t: Table, written: list[str], vcol: str, ecol: str, kind: str, empty: bool) -> dict:
    df = t.df
    return dict(
        rows=np.arange(len(df)),
        written=written,
        value=df[vcol],
        err=df[ecol],
        kind=kind,
        vcol=vcol,
        ecol=ecol,
        empty=empty,
    )


def band_parts(t: Table) -> tuple[str, list[dict[str, Any]]]:
    """The table's form (``long`` or ``wide``) and its band columns: the whole table
    (long: a band column) or one part per band column and its uncertainty (wide)."""
    roles, cols = t.roles, [str(c) for c in t.df.columns]
    if "band" in roles:
        kind = "flux" if "flux" in roles and "magnitude" not in roles else "mag"
        vcol = roles["flux"] if kind == "flux" else roles.get("magnitude")
        ecol = roles.get("flux_uncertainty" if kind == "flux" else "uncertainty")
        missing = [n for n, c in (("magnitude (or flux)", vcol), ("uncertainty", ecol)) if not c]
        if missing:
            raise LightCurveError(
                f"{t.path}: missing column(s) {missing}; a long table needs band, magnitude "
                f"(or flux), uncertainty and a time; found {cols}"
            )
        written = [str(b).strip() for b in t.df[roles["band"]].tolist()]
        return "long", [_part(t, written, str(vcol), str(ecol), kind, False)]
    taken = set(roles.values())

    def is_band(b: str) -> bool:
        try:
            band_label(b, band_map=t.band_map, bands=t.bands)
        except LightCurveError:
            return False
        return True

    found, _unused = forms.wide_columns([c for c in cols if c not in taken], is_band, str(t.path))
    if not found:
        raise LightCurveError(
            f"{t.path}: no band column: a long table needs a band column (band or filter) "
            "with magnitude and uncertainty; a wide one a column per band and its "
            f"uncertainty (V, V_err); found {cols}"
        )
    return "wide", [_part(t, [b] * len(t.df), v, e, kind, True) for b, v, e, kind in found]


def _labels(
    t: Table, part: dict[str, Any], written: list[str], rows: np.ndarray, labels: dict
) -> list[str]:
    """The package's band of every filter name as written (``labels`` caches them)."""
    for w, r in zip(written, rows, strict=True):
        if w not in labels:
            try:
                labels[w] = band_label(w, band_map=t.band_map, bands=t.bands)
            except LightCurveError as exc:
                col = t.roles.get("band", part["vcol"])
                raise LightCurveError(f"{t.row_name(int(r))}, column {col!r}: {exc}") from None
    return [labels[w] for w in written]


def band_values(t: Table, parts: list[dict[str, Any]]) -> Values:
    """Magnitudes and uncertainties [mag] of every part (fluxes converted to AB magnitudes),
    empty cells of a wide table left out."""
    labels: dict[str, str] = {}
    rows_l, band_l, written_l, mag_l, unc_l = [], [], [], [], []
    flux_note = ""
    for part in parts:
        v = t.numeric(part["value"], part["vcol"], part["rows"], part["empty"])
        keep = np.isfinite(v)
        e = t.numeric(part["err"], part["ecol"], part["rows"], part["empty"])
        lost = np.flatnonzero(keep & ~np.isfinite(e))
        if lost.size:
            raise LightCurveError(
                f"{t.row_name(int(part['rows'][lost[0]]))}, column {part['ecol']!r}: no "
                f"uncertainty for the value {v[lost[0]]:g} of column {part['vcol']!r}"
            )
        rows = part["rows"][keep]
        written = [w for w, k in zip(part["written"], keep, strict=True) if k]
        lab = _labels(t, part, written, rows, labels)
        v, e = v[keep], e[keep]
        if part["kind"] == "flux":
            unit = t.units.get(part["vcol"]) or t.meta.get("flux_unit")
            eunit = t.units.get(part["ecol"]) or unit
            if eunit is not None and unit is not None and eunit != unit:
                e = in_unit(t.path, part["ecol"], e, eunit, str(unit))
            v, e, flux_note = forms.flux_magnitudes(
                v, e, unit, pivots(lab), f"{t.path}: column {part['vcol']!r}"
            )
        else:
            v = in_unit(t.path, part["vcol"], v, t.units.get(part["vcol"]), "mag")
            e = in_unit(t.path, part["ecol"], e, t.units.get(part["ecol"]), "mag")
        rows_l.append(rows)
        band_l += lab
        written_l += written
        mag_l.append(v)
        unc_l.append(e)
    mag, unc = np.concatenate(mag_l), np.concatenate(unc_l)
    if not mag.size:
        raise LightCurveError(f"{t.path}: no observations (every band cell is empty)")
    return Values(np.concatenate(rows_l), band_l, written_l, mag, unc, flux_note)


def time_scale_of(time_scale: str | None, meta: dict[str, Any]) -> str | None:
    """The time scale of Julian dates: the argument, else the table's metadata."""
    scale = time_scale if time_scale is not None else meta.get("time_scale", meta.get("timesys"))
    if scale is not None:
        scale = str(scale).strip().lower()
        if scale not in forms.TIME_SCALES:
            raise LightCurveError(
                f"time_scale: got {scale!r}; allowed: {', '.join(forms.TIME_SCALES)} "
                "(UT1 needs Earth-rotation tables: convert to UTC first)"
            )
    return scale


def abscissa(
    t: Table, xrole: str, rows: np.ndarray, scale: str | None
) -> tuple[str, np.ndarray, dict[str, Any], str]:
    """``(name, values, attrs, time_source)`` of the abscissa: rotation angles [degree],
    numeric seconds kept as written, or UTC times."""
    import pandas as pd

    xcol = t.roles[xrole]
    xraw = t.df[xcol].to_numpy()[rows]
    if xrole == "rotation_angle":
        x = in_unit(t.path, xcol, t.numeric(xraw, xcol, rows), t.units.get(xcol), "deg")
        return "rotation_angle", x, attrs("rotation_angle"), ""
    as_num = pd.to_numeric(pd.Series(xraw).astype(str).str.strip(), errors="coerce")
    if xrole == "time" and t.units.get(xcol) != "utc" and as_num.notna().all():
        x = in_unit(t.path, xcol, as_num.to_numpy(dtype=np.float64), t.units.get(xcol), "s")
        x_attrs = attrs(
            "time_since_first",
            long_name="observation time",
            time_origin="as in the file (numeric seconds are kept unchanged)",
        )
        return "time", x, x_attrs, f"numbers of seconds (column {xcol})"
    own = forms.jd_scale(xcol) if xrole != "time" else None
    x, time_source = forms.utc_times(
        xraw, xrole, xcol, t.units.get(xcol), own or scale, lambda k: t.row_name(int(rows[k]))
    )
    return "time", x, attrs("time", standard_name="time"), time_source


def pivots(labels: list[str]) -> np.ndarray:
    """Pivot wavelengths [nm] of the bands, ``sqrt(int T l dl / int T / l dl)``."""
    from ..photometry import filters

    f = filters(sorted(set(labels)))
    wl = f["wavelength"].values
    piv = {}
    for b in f[BAND].values:
        r = f.sel({BAND: b}).values
        piv[str(b)] = float(np.sqrt(np.trapezoid(r * wl, wl) / np.trapezoid(r / wl, wl)))
    return np.array([piv[b] for b in labels])
