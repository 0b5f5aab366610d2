"""Measured light curves in the forms observers keep them.

:func:`read_light_curve` reads CSV, ECSV, FITS, VOTable and netCDF tables, long (one
observation per row, a band column) or wide (one time per row, a column per band and
one for its uncertainty), in any row order, magnitudes or flux densities, with UTC
times as ISO 8601 strings, astropy ``Time`` columns or Julian dates in a stated scale;
filter names are mapped to the package's bands by
:func:`~sbrdf_xr.lightcurves.filter_names.band_label`.  Tables other than CSV and netCDF
are read with :class:`astropy.table.Table`, so their column units are honoured
(converted to the package's units) and astropy ``Time`` columns become UTC.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .._names import BAND, attrs
from ..errors import LightCurveError, ValidationError, input_file, reading
from ..photometry import MAGNITUDE_SYSTEMS, check_system
from . import _curve_forms as forms
from ._table_io import TABLE_FORMATS, in_unit, read_table
from .filter_names import band_label

__all__ = [
    "LIGHT_CURVE_ABSCISSAE",
    "LIGHT_CURVE_COLUMNS",
    "LIGHT_CURVE_OPTIONAL",
    "MIN_UNCERTAINTY",
    "TABLE_FORMATS",
    "read_light_curve",
]

LIGHT_CURVE_COLUMNS = ("band", "magnitude", "uncertainty")
LIGHT_CURVE_ABSCISSAE = ("time", "jd", "mjd", "rotation_angle")
#: Optional per-row columns: name -> (unit they are converted to, attribute table key).
LIGHT_CURVE_OPTIONAL = {
    "range_km": ("km", "range"),
    "phase_angle": ("deg", "phase_angle"),
    "airmass": ("", "airmass"),
}
#: Uncertainties below this [mag] are refused: no photometry is that precise, and their
#: weights 1/sigma**2 would overflow the fit.
MIN_UNCERTAINTY = 1e-6


def read_light_curve(
    path: str | os.PathLike[str],
    *,
    bands: Sequence[str] | None = None,
    system: str | None = None,
    time_scale: str | None = None,
    band_map: Mapping[str, str] | None = None,
) -> xr.Dataset:
    """Read a measured light curve, long or wide, in any row order.

    **Long** tables hold one observation per row; **wide** ones one time per row and,
    per band, a column and its uncertainty column (``V, V_err``; ``mag_V, e_mag_V``;
    ``Rmag, Rmag_err``; ``flux_g, flux_g_err``): each non-empty cell is an observation.
    Column names are matched without regard to case (the aliases of
    :data:`~sbrdf_xr.lightcurves._curve_forms.ROLES`):

    ============== ========================================================================
    column         meaning
    ============== ========================================================================
    time           UTC: ISO 8601 with a zone (``...Z``, ``+hh:mm``; without one with
                   ``time_scale``), an astropy ``Time`` column (ECSV, FITS), a netCDF
                   time; or numbers of seconds (any origin).  **Or**
    jd, mjd        Julian or modified Julian dates in the scale the name (``mjd_utc``,
                   ``jd_tai``), ``time_scale`` or the metadata (``time_scale``,
                   ``TIMESYS``) states; converted to UTC by astropy.  **Or**
    rotation_angle body rotation angle [degree] (cumulative, may exceed 360).
    band           (long) the filter, as written (``V``, ``Johnson V``, ``Bessell-V``,
                   ``Rc``, ``r'``, a speclite name; :func:`band_label`), or one of ``bands``
    magnitude      (long) measured magnitude (unit ``mag`` or none), **or**
    flux           (long) flux density with a unit (column unit or metadata
                   ``flux_unit``): AB magnitudes, ``-2.5 log10(f_nu / 3631 Jy)``
    uncertainty    1-sigma [mag] (``flux_err`` for fluxes), >= 1e-6 mag
    system         optional: ``AB`` or ``Vega`` (the same in every row), or state it in
                   the metadata ``magnitude_system`` or the ``system`` argument
    range_km       optional observer range (or ``range`` with a length unit) [km]
    phase_angle    optional Sun-object-observer angle [degree]
    airmass        optional air mass [1]
    ============== ========================================================================

    Rows are sorted by time (or angle), stably; the ``file_row`` coordinate keeps each
    observation's row in the file.  Formats by suffix: ``.csv`` (and other text; ``#``
    starts a comment), ``.ecsv``, ``.fits``/``.fit``, ``.vot``/``.votable``/``.xml``
    (VOTable), ``.nc``.  Columns with units are converted; other columns are ignored.

    Parameters
    ----------
    path : str or path
    bands : sequence of str, optional
        Labels accepted as written (user bandpasses of the simulation).
    system : {"AB", "Vega"}, optional
        The magnitude system when the table does not state it; a table that states
        another is an error.  Fluxes give AB magnitudes.
    time_scale : {"utc", "tai", "tt", "tdb", "tcg", "tcb"}, optional
        The scale of Julian dates and of ISO times without a zone (also the metadata
        ``time_scale`` or ``TIMESYS``); without it such times are an error.
    band_map : mapping, optional
        Filter names of your own -> band (``{"Clear": "V"}``).

    Returns
    -------
    xarray.Dataset
        Over ``obs``: ``magnitude``, ``uncertainty`` (``ancillary_variables`` of the
        magnitude), optional ``range_km``, ``phase_angle``, ``airmass``; coords ``band``
        (the package's label), ``filter_as_written``, ``file_row`` and ``time``
        (datetime64[ns] UTC, or seconds when numeric) or ``rotation_angle``; attrs
        ``magnitude_system`` (``unstated`` when unknown), ``table_form``, ``time_source``,
        ``row_order``.

    Raises
    ------
    LightCurveError
        Naming the file and the column or row: missing columns, several or no time
        columns, non-numeric values or wrong units, NaN rows, an uncertainty below 1e-6,
        unknown filters (listing the known bands), several systems, times without a
        zone or scale, heliocentric dates.

    Examples
    --------
    A wide table grouped by nothing in particular, Julian dates in UTC:

    >>> import tempfile
    >>> from pathlib import Path
    >>> path = Path(tempfile.mkdtemp()) / "night.csv"
    >>> _ = path.write_text("jd_utc,V,V_err,Rc,Rc_err\\n"
    ...                     "2460386.55,12.31,0.02,11.90,0.03\\n"
    ...                     "2460386.54,12.40,0.02,,\\n")
    >>> lc = read_light_curve(path, system="Vega")
    >>> lc.band.values.tolist(), lc.magnitude.values.tolist(), lc.file_row.values.tolist()
    (['V', 'V', 'R'], [12.4, 12.31, 11.9], [2, 1, 1])
    >>> str(lc.time.values[0])[:19], lc.attrs["table_form"], lc.attrs["magnitude_system"]
    ('2024-03-17T00:57:36', 'wide', 'Vega')
    """
    path = input_file(path, "light curve", LightCurveError)
    with reading(path, "light curve", f"a table ({path.suffix or 'no suffix'})", LightCurveError):
        df, units, meta, where, offset = read_table(path)
    return _build(path, df, units, meta, where, offset, bands, system, time_scale, band_map)


def _build(
    path: Path,
    df: Any,
    units: dict[str, Any],
    meta: dict[str, Any],
    where: str,
    offset: int,
    bands: Sequence[str] | None,
    system: str | None,
    time_scale: str | None,
    band_map: Mapping[str, str] | None,
) -> xr.Dataset:
    import pandas as pd

    def row_name(k: int) -> str:
        text = where.format(k + 1, k + 1 + offset) if offset else where.format(k + 1)
        return f"{path}: {text}"

    if len(df) == 0:
        raise LightCurveError(f"{path}: no observations")
    cols = [str(c) for c in df.columns]
    roles = forms.resolve_roles(cols, str(path))
    absc = [r for r in LIGHT_CURVE_ABSCISSAE if r in roles]
    if len(absc) != 1:
        raise LightCurveError(
            f"{path}: need exactly one column of time (time, jd or mjd, with UTC) or "
            f"rotation_angle, found {[roles[r] for r in absc] or 'none'} among its "
            f"{len(cols)} columns"
        )
    xrole = absc[0]

    def numeric(values: Any, col: str, rows: np.ndarray, allow_empty: bool = False) -> Any:
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
            raise LightCurveError(f"{row_name(int(rows[bad[0]]))}, column {col!r}: {shown}")
        return v

    all_rows = np.arange(len(df))
    parts: list[dict[str, Any]] = []  # per band column (wide) or the whole table (long)
    if "band" in roles:
        form = "long"
        kind = "flux" if "flux" in roles and "magnitude" not in roles else "mag"
        vcol = (
            roles["flux" if kind == "flux" else "magnitude"]
            if kind == "flux"
            else (roles.get("magnitude"))
        )
        ecol = roles.get("flux_uncertainty" if kind == "flux" else "uncertainty")
        missing = [n for n, c in (("magnitude (or flux)", vcol), ("uncertainty", ecol)) if not c]
        if missing:
            raise LightCurveError(
                f"{path}: missing column(s) {missing}; a long table needs band, magnitude "
                f"(or flux), uncertainty and a time; found {cols}"
            )
        written = [str(b).strip() for b in df[roles["band"]].tolist()]
        parts.append(
            dict(
                rows=all_rows,
                written=written,
                value=df[vcol],
                err=df[ecol],
                kind=kind,
                vcol=vcol,
                ecol=ecol,
                empty=False,
            )
        )
    else:
        form = "wide"
        taken = set(roles.values())

        def is_band(b: str) -> bool:
            try:
                band_label(b, band_map=band_map, bands=bands)
            except LightCurveError:
                return False
            return True

        found, _unused = forms.wide_columns([c for c in cols if c not in taken], is_band, str(path))
        if not found:
            raise LightCurveError(
                f"{path}: no band column: a long table needs a band column (band or filter) "
                "with magnitude and uncertainty; a wide one a column per band and its "
                f"uncertainty (V, V_err); found {cols}"
            )
        for b, vcol, ecol, kind in found:
            parts.append(
                dict(
                    rows=all_rows,
                    written=[b] * len(df),
                    value=df[vcol],
                    err=df[ecol],
                    kind=kind,
                    vcol=vcol,
                    ecol=ecol,
                    empty=True,
                )
            )
    labels: dict[str, str] = {}
    rows_l, band_l, written_l, mag_l, unc_l = [], [], [], [], []
    flux_note = ""
    for part in parts:
        v = numeric(part["value"], part["vcol"], part["rows"], part["empty"])
        keep = np.isfinite(v)
        e = numeric(part["err"], part["ecol"], part["rows"], part["empty"])
        lost = np.flatnonzero(keep & ~np.isfinite(e))
        if lost.size:
            raise LightCurveError(
                f"{row_name(int(part['rows'][lost[0]]))}, column {part['ecol']!r}: no "
                f"uncertainty for the value {v[lost[0]]:g} of column {part['vcol']!r}"
            )
        rows = part["rows"][keep]
        written = [w for w, k in zip(part["written"], keep, strict=True) if k]
        for w, r in zip(written, rows, strict=True):
            if w not in labels:
                try:
                    labels[w] = band_label(w, band_map=band_map, bands=bands)
                except LightCurveError as exc:
                    col = roles.get("band", part["vcol"])
                    raise LightCurveError(f"{row_name(int(r))}, column {col!r}: {exc}") from None
        lab = [labels[w] for w in written]
        v, e = v[keep], e[keep]
        if part["kind"] == "flux":
            unit = units.get(part["vcol"]) or meta.get("flux_unit")
            eunit = units.get(part["ecol"]) or unit
            if eunit is not None and unit is not None and eunit != unit:
                e = in_unit(path, part["ecol"], e, eunit, str(unit))
            v, e, flux_note = forms.flux_magnitudes(
                v, e, unit, _pivots(lab, bands), f"{path}: column {part['vcol']!r}"
            )
        else:
            v = in_unit(path, part["vcol"], v, units.get(part["vcol"]), "mag")
            e = in_unit(path, part["ecol"], e, units.get(part["ecol"]), "mag")
        rows_l.append(rows)
        band_l += lab
        written_l += written
        mag_l.append(v)
        unc_l.append(e)
    rows_all = np.concatenate(rows_l)
    mag, unc = np.concatenate(mag_l), np.concatenate(unc_l)
    if not mag.size:
        raise LightCurveError(f"{path}: no observations (every band cell is empty)")
    bad = np.flatnonzero(unc < MIN_UNCERTAINTY)
    if bad.size:
        k = int(bad[0])
        rule = (
            "must be > 0"
            if unc[k] <= 0
            else f"must be >= {MIN_UNCERTAINTY:g} mag (no photometry is that precise)"
        )
        raise LightCurveError(
            f"{row_name(int(rows_all[k]))}, column 'uncertainty': {rule}, got {unc[k]:g}"
        )
    scale = time_scale if time_scale is not None else meta.get("time_scale", meta.get("timesys"))
    if scale is not None:
        scale = str(scale).strip().lower()
        if scale not in forms.TIME_SCALES:
            raise LightCurveError(
                f"time_scale: got {scale!r}; allowed: {', '.join(forms.TIME_SCALES)} "
                "(UT1 needs Earth-rotation tables: convert to UTC first)"
            )
    xcol = roles[xrole]
    xraw = df[xcol].to_numpy()[rows_all]
    x_attrs: dict[str, Any]
    time_source = ""
    if xrole == "rotation_angle":
        x = in_unit(path, xcol, numeric(xraw, xcol, rows_all), units.get(xcol), "deg")
        x_attrs, xname = attrs("rotation_angle"), "rotation_angle"
    else:
        xname = "time"
        as_num = pd.to_numeric(pd.Series(xraw).astype(str).str.strip(), errors="coerce")
        if xrole == "time" and units.get(xcol) != "utc" and as_num.notna().all():
            x = as_num.to_numpy(dtype=np.float64)
            x = in_unit(path, xcol, x, units.get(xcol), "s")
            x_attrs = attrs(
                "time_since_first",
                long_name="observation time",
                time_origin="as in the file (numeric seconds are kept unchanged)",
            )
            time_source = f"numbers of seconds (column {xcol})"
        else:
            own = forms.jd_scale(xcol) if xrole != "time" else None
            x, time_source = forms.utc_times(
                xraw,
                xrole,
                xcol,
                units.get(xcol),
                own or scale,
                lambda k: row_name(int(rows_all[k])),
            )
            x_attrs = attrs("time", standard_name="time")
    key = x if x.dtype.kind != "M" else (x - x.min()) / np.timedelta64(1, "s")
    order = np.lexsort((rows_all, key))
    sorted_already = bool(np.all(order == np.arange(order.size)))
    stated = _stated_system(path, df, meta, row_name, roles.get("system"))
    if flux_note:
        if stated not in (None, "AB") or (system is not None and check_system(system) != "AB"):
            raise LightCurveError(
                f"{path}: fluxes give AB magnitudes, but the table or the argument states "
                f"{stated or system}; give magnitudes in that system instead"
            )
        stated = "AB"
    if system is not None:
        system = check_system(system)
        if stated is not None and stated != system:
            raise LightCurveError(
                f"{path}: the table states the {stated} system, not system={system!r}"
            )
    mag_system = stated or system or "unstated"
    data: dict[str, Any] = {
        "magnitude": (
            "obs",
            mag[order],
            attrs(
                "magnitude",
                long_name="measured magnitude",
                magnitude_system=mag_system,
                ancillary_variables="uncertainty",
            ),
        ),
        "uncertainty": (
            "obs",
            unc[order],
            attrs("magnitude_uncertainty", magnitude_system=mag_system),
        ),
    }
    for name, (unit, akey) in LIGHT_CURVE_OPTIONAL.items():
        col = roles.get(name) or (roles.get("range") if name == "range_km" else None)
        if col is None:
            continue
        if name == "range_km" and col == roles.get("range") and units.get(col) is None:
            raise LightCurveError(
                f"{path}: column 'range' has no length unit; give one (e.g. km) or name "
                "the column 'range_km'"
            )
        v = numeric(df[col].to_numpy()[rows_all], col, rows_all)
        v = in_unit(path, col, v, units.get(col), unit)
        ok = (
            (v > 0)
            if name == "range_km"
            else (v >= 1.0)
            if name == "airmass"
            else ((v >= 0) & (v <= 180))
        )
        bad = np.flatnonzero(~ok)
        if bad.size:
            k = int(bad[0])
            rules = {"range_km": "> 0 km", "airmass": ">= 1", "phase_angle": "in [0, 180] degree"}
            raise LightCurveError(
                f"{row_name(int(rows_all[k]))}, column {col!r}: must be {rules[name]}, got {v[k]:g}"
            )
        data[name] = ("obs", v[order], attrs(akey))
    ds = xr.Dataset(
        data,
        coords={
            "obs": ("obs", np.arange(mag.size), attrs("obs")),
            BAND: ("obs", np.array(band_l, dtype=object)[order].astype(str), attrs(BAND)),
            "filter_as_written": (
                "obs",
                np.array(written_l, dtype=object)[order].astype(str),
                {"long_name": "filter name as written in the file"},
            ),
            "file_row": (
                "obs",
                rows_all[order] + 1,
                {"units": "1", "long_name": f"row in {path.name}"},
            ),
            xname: ("obs", x[order], x_attrs),
        },
    )
    ds.attrs = {
        "source_file": str(path),
        "abscissa": xname,
        "table_form": form,
        "row_order": "as in the file"
        if sorted_already
        else (f"sorted by {xname} (the file lists them in another order, e.g. grouped by band)"),
        "magnitude_system": mag_system,
        "magnitude_system_description": MAGNITUDE_SYSTEMS.get(
            mag_system, "not stated in the table"
        ),
    }
    if time_source:
        ds.attrs["time_source"] = time_source
    if flux_note:
        ds.attrs["flux_conversion"] = flux_note
    return ds


def _pivots(labels: list[str], bands: Sequence[str] | None) -> np.ndarray:
    """Pivot wavelengths [nm] of the bands, ``sqrt(int T l dl / int T / l dl)``."""
    from ..photometry import filters

    f = filters(sorted(set(labels)))
    wl = f["wavelength"].values
    piv = {}
    for b in f[BAND].values:
        t = f.sel({BAND: b}).values
        piv[str(b)] = float(np.sqrt(np.trapezoid(t * wl, wl) / np.trapezoid(t / wl, wl)))
    return np.array([piv[b] for b in labels])


def _stated_system(
    path: Path, df: Any, meta: dict[str, Any], row_name: Any, col: str | None
) -> str | None:
    """The one magnitude system a table states (a ``system`` column, the table or column
    metadata ``magnitude_system``, a ``mag(AB)`` unit), or None."""
    found: str | None = None
    if str(meta.get("magnitude_system", "unstated")) != "unstated":
        try:
            found = check_system(str(meta["magnitude_system"]))
        except ValidationError as exc:
            raise LightCurveError(f"{path}: metadata magnitude_system: {exc}") from None
    if col is not None:
        vals = [str(v).strip() for v in df[col].tolist()]
        for k, v in enumerate(vals):
            try:
                canon = check_system(v)
            except ValidationError:
                raise LightCurveError(
                    f"{row_name(k)}, column {col!r}: unknown {v!r}; allowed: "
                    f"{', '.join(MAGNITUDE_SYSTEMS)}"
                ) from None
            if found is None:
                found = canon
            elif canon != found:
                raise LightCurveError(
                    f"{row_name(k)}, column {col!r}: {v!r} differs from {found!r} "
                    "above; a light curve must be in one magnitude system (convert first)"
                )
    return found
