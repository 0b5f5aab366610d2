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
from . import _rows as rows
from ._table_io import TABLE_FORMATS, in_unit, read_table

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
    """The light curve of a parsed table: its band columns, their values, the abscissa,
    the magnitude system and the optional columns, in the order of the abscissa."""
    t = rows.Table(path, df, units, meta, where, offset, bands, band_map)
    if len(df) == 0:
        raise LightCurveError(f"{path}: no observations")
    t.roles = forms.resolve_roles([str(c) for c in df.columns], str(path))
    xrole = rows.abscissa_role(t, LIGHT_CURVE_ABSCISSAE)
    form, parts = rows.band_parts(t)
    values = rows.band_values(t, parts)
    _check_uncertainties(t, values)
    scale = rows.time_scale_of(time_scale, meta)
    xname, x, x_attrs, time_source = rows.abscissa(t, xrole, values.rows, scale)
    key = x if x.dtype.kind != "M" else (x - x.min()) / np.timedelta64(1, "s")
    order = np.lexsort((values.rows, key))
    mag_system = _magnitude_system(t, system, values.flux_note)
    data = _observations(values, order, mag_system)
    data.update(_optional_columns(t, values.rows, order))
    ds = xr.Dataset(
        data,
        coords={
            "obs": ("obs", np.arange(values.magnitude.size), attrs("obs")),
            BAND: ("obs", np.array(values.bands, dtype=object)[order].astype(str), attrs(BAND)),
            "filter_as_written": (
                "obs",
                np.array(values.written, dtype=object)[order].astype(str),
                {"long_name": "filter name as written in the file"},
            ),
            "file_row": (
                "obs",
                values.rows[order] + 1,
                {"units": "1", "long_name": f"row in {path.name}"},
            ),
            xname: ("obs", x[order], x_attrs),
        },
    )
    sorted_already = bool(np.all(order == np.arange(order.size)))
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
    if values.flux_note:
        ds.attrs["flux_conversion"] = values.flux_note
    return ds


def _check_uncertainties(t: rows.Table, values: rows.Values) -> None:
    """Uncertainties of at least :data:`MIN_UNCERTAINTY` [mag], or the first row named."""
    unc = values.uncertainty
    bad = np.flatnonzero(unc < MIN_UNCERTAINTY)
    if bad.size:
        k = int(bad[0])
        rule = (
            "must be > 0"
            if unc[k] <= 0
            else f"must be >= {MIN_UNCERTAINTY:g} mag (no photometry is that precise)"
        )
        raise LightCurveError(
            f"{t.row_name(int(values.rows[k]))}, column 'uncertainty': {rule}, got {unc[k]:g}"
        )


def _magnitude_system(t: rows.Table, system: str | None, flux_note: str) -> str:
    """The system the table states (AB for fluxes), checked against ``system=``."""
    stated = _stated_system(t.path, t.df, t.meta, t.row_name, t.roles.get("system"))
    if flux_note:
        if stated not in (None, "AB") or (system is not None and check_system(system) != "AB"):
            raise LightCurveError(
                f"{t.path}: fluxes give AB magnitudes, but the table or the argument states "
                f"{stated or system}; give magnitudes in that system instead"
            )
        stated = "AB"
    if system is not None:
        system = check_system(system)
        if stated is not None and stated != system:
            raise LightCurveError(
                f"{t.path}: the table states the {stated} system, not system={system!r}"
            )
    return stated or system or "unstated"


def _observations(values: rows.Values, order: np.ndarray, mag_system: str) -> dict[str, Any]:
    """The ``magnitude`` and ``uncertainty`` variables, in the order of the abscissa."""
    return {
        "magnitude": (
            "obs",
            values.magnitude[order],
            attrs(
                "magnitude",
                long_name="measured magnitude",
                magnitude_system=mag_system,
                ancillary_variables="uncertainty",
            ),
        ),
        "uncertainty": (
            "obs",
            values.uncertainty[order],
            attrs("magnitude_uncertainty", magnitude_system=mag_system),
        ),
    }


def _optional_columns(t: rows.Table, rows_all: np.ndarray, order: np.ndarray) -> dict[str, Any]:
    """The optional per-row columns (:data:`LIGHT_CURVE_OPTIONAL`) present, checked."""
    data: dict[str, Any] = {}
    roles, units = t.roles, t.units
    for name, (unit, akey) in LIGHT_CURVE_OPTIONAL.items():
        col = roles.get(name) or (roles.get("range") if name == "range_km" else None)
        if col is None:
            continue
        if name == "range_km" and col == roles.get("range") and units.get(col) is None:
            raise LightCurveError(
                f"{t.path}: column 'range' has no length unit; give one (e.g. km) or name "
                "the column 'range_km'"
            )
        v = t.numeric(t.df[col].to_numpy()[rows_all], col, rows_all)
        v = in_unit(t.path, col, v, units.get(col), unit)
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
                f"{t.row_name(int(rows_all[k]))}, column {col!r}: must be {rules[name]}, "
                f"got {v[k]:g}"
            )
        data[name] = ("obs", v[order], attrs(akey))
    return data


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
