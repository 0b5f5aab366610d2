"""Measured light curves from the tables observers keep: CSV, ECSV, FITS, VOTable, netCDF.

Tables other than CSV and netCDF are read with :class:`astropy.table.Table`, so their
column units are honoured (converted to the package's units) and astropy ``Time``
columns become UTC.
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .._names import BAND, attrs
from ..errors import ValidationError
from .bands import BAND_ALIASES, _canonical, speclite_names
from .spectra import MAGNITUDE_SYSTEMS, check_system

LIGHT_CURVE_COLUMNS = ("band", "magnitude", "uncertainty")
LIGHT_CURVE_ABSCISSAE = ("time", "rotation_angle")
#: Optional per-row columns: name -> (unit they are converted to, attribute table key).
LIGHT_CURVE_OPTIONAL = {
    "range_km": ("km", "range"),
    "phase_angle": ("deg", "phase_angle"),
    "airmass": ("", "airmass"),
}
#: Suffix -> astropy Table format.
TABLE_FORMATS = {
    ".ecsv": "ascii.ecsv",
    ".fits": "fits",
    ".fit": "fits",
    ".fits.gz": "fits",
    ".vot": "votable",
    ".votable": "votable",
    ".xml": "votable",
}
#: Uncertainties below this [mag] are refused: no photometry is that precise, and their
#: weights 1/sigma**2 would overflow the fit.
MIN_UNCERTAINTY = 1e-6

_TZ = re.compile(r"(Z|[+-]\d\d:?\d\d)$", re.IGNORECASE)


def _suffix(path: Path) -> str:
    name = path.name.lower()
    return ".fits.gz" if name.endswith(".fits.gz") else path.suffix.lower()


def _from_astropy(path: Path, fmt: str) -> tuple[Any, dict[str, Any], dict[str, Any]]:
    """Columns as a DataFrame of plain values, converted units, and the table metadata."""
    import warnings

    import astropy.units as u
    import pandas as pd
    from astropy.table import Table
    from astropy.time import Time

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # VOTable/FITS readers warn about vendor keywords
            # astropy_native: FITS time columns come back as Time (with their scale)
            tab = Table.read(
                path, format=fmt, **({"astropy_native": True} if fmt == "fits" else {})
            )
    except Exception as exc:  # astropy raises many types for malformed files
        raise ValidationError(f"{path}: cannot be read as {fmt}: {exc}") from exc
    cols: dict[str, Any] = {}
    units: dict[str, Any] = {}
    want = {
        "magnitude": "mag",
        "uncertainty": "mag",
        "rotation_angle": "deg",
        "time": "s",
        "range_km": "km",
        "range": "km",
        "phase_angle": "deg",
        "airmass": "",
    }
    for name in tab.colnames:
        col = tab[name]
        key = name.strip()
        if isinstance(col, Time):
            t = col.utc
            t.precision = 9  # ISO strings to the ns (the default is ms)
            cols[key] = [v + "Z" for v in t.isot]
            units[key] = "utc"
            continue
        if getattr(col, "ndim", 1) != 1:
            raise ValidationError(
                f"{path}: column {key!r} is not one value per row (shape {col.shape})"
            )
        unit = getattr(col, "unit", None)
        data: np.ndarray | list[str] = (
            np.ma.filled(np.ma.asarray(col), np.nan) if col.dtype.kind in "fiu" else np.asarray(col)
        )
        if key in want and unit is not None and col.dtype.kind in "fiu":
            target = want[key]
            try:
                if target == "mag":
                    if unit not in (u.mag, u.dimensionless_unscaled):
                        raise u.UnitConversionError(str(unit))
                    data = np.asarray(data, dtype=np.float64)
                else:
                    data = (np.asarray(data, dtype=np.float64) * unit).to_value(
                        u.Unit(target) if target else u.dimensionless_unscaled
                    )
            except (u.UnitConversionError, u.UnitsError, ValueError, TypeError):
                raise ValidationError(
                    f"{path}: column {key!r} has unit {unit!s}, which cannot be converted "
                    f"to {target or 'a dimensionless number'}"
                ) from None
            units[key] = target
        elif col.dtype.kind in "SU" or col.dtype == object:
            data = [str(v.decode() if isinstance(v, bytes) else v) for v in data]
        cols[key] = data
    if "range" in cols and "range_km" not in cols:
        if units.get("range") != "km":
            raise ValidationError(
                f"{path}: column 'range' has no length unit; give one (e.g. km) or name "
                "the column 'range_km'"
            )
        cols["range_km"] = cols.pop("range")
    meta = {str(k).lower(): v for k, v in tab.meta.items() if isinstance(v, str | int | float)}
    return pd.DataFrame(cols), units, meta


def read_light_curve(
    path: str | os.PathLike[str],
    *,
    bands: Sequence[str] | None = None,
    system: str | None = None,
    time_scale: str | None = None,
) -> xr.Dataset:
    """Read a measured light curve (one observation per row).

    ============== ========================================================================
    column         meaning
    ============== ========================================================================
    time           UTC observation time: ISO 8601 with a time zone (``...Z`` or
                   ``+hh:mm``), an astropy ``Time`` column (ECSV, FITS), a netCDF
                   time; or numbers of seconds (any origin).  **Or**
    rotation_angle body rotation angle [degree] (cumulative, may exceed 360).  Exactly one
                   of the two, non-decreasing down the table.
    band           an alias (``B``, ``V``, ``g``, ...), a speclite filter name, or one of
                   ``bands`` when given
    magnitude      measured magnitude (unit ``mag`` or none)
    uncertainty    1-sigma uncertainty [mag], >= 1e-6
    system         optional: ``AB`` or ``Vega`` (the same in every row), or state it in
                   the table metadata ``magnitude_system`` or the ``system`` argument
    range_km       optional observer range (or ``range`` with a length unit) [km]
    phase_angle    optional Sun-object-observer angle [degree]
    airmass        optional air mass [1]
    ============== ========================================================================

    Formats by suffix: ``.csv`` (and other text), ``.ecsv``, ``.fits``/``.fit``,
    ``.vot``/``.votable``/``.xml`` (VOTable), ``.nc``.  Columns with units (ECSV,
    FITS, VOTable) are converted; extra columns are ignored.  Several nights and bands
    may share one table.

    Parameters
    ----------
    path : str or path
    bands : sequence of str, optional
        Allowed band labels; default any alias or speclite filter name.
    system : {"AB", "Vega"}, optional
        The magnitude system when the table does not state it; a table that states
        another is an error.
    time_scale : {"utc"}, optional
        Read ISO times without a time zone as UTC (also the table metadata
        ``time_scale``); by default such times are an error.

    Returns
    -------
    xarray.Dataset
        Over ``obs``: ``magnitude``, ``uncertainty`` (``ancillary_variables`` of the
        magnitude), optional ``range_km``, ``phase_angle``, ``airmass``; coords
        ``band`` and ``time`` (datetime64[ns] UTC, or seconds when numeric) or
        ``rotation_angle``; attrs ``magnitude_system`` (``unstated`` when unknown).

    Raises
    ------
    ValidationError
        Naming the file and the column or row: missing columns, both or neither of time
        and rotation_angle, non-numeric values or wrong units, an uncertainty below
        1e-6, unknown bands, several systems, times without a time zone, decreasing
        times or angles.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> rows = ["rotation_angle,band,magnitude,uncertainty,system"]
    >>> for a in (0, 30, 60, 90):  # a double-peaked curve, 0.2 mag fainter, 20 degree later
    ...     for b, m0 in (("B", 10.2), ("V", 9.8)):
    ...         rows.append(f"{a},{b},{m0 + 0.5 * np.cos(np.radians(2 * (a + 20))):.4f},0.01,AB")
    >>> path = Path(tempfile.mkdtemp()) / "curve.csv"
    >>> _ = path.write_text("\\n".join(rows))
    >>> lc = read_light_curve(path)
    >>> dict(lc.sizes), lc.attrs["abscissa"], lc.attrs["magnitude_system"]
    ({'obs': 8}, 'rotation_angle', 'AB')
    >>> lc.band.values[:4].tolist(), lc.magnitude.values[:2].tolist()
    (['B', 'V', 'B', 'V'], [10.583, 10.183])
    """
    import pandas as pd

    path = Path(path)
    if not path.is_file():
        raise ValidationError(f"light curve: file {path} does not exist")
    suffix = _suffix(path)
    units: dict[str, Any] = {}
    meta: dict[str, Any] = {}
    if suffix in (".nc", ".nc4", ".netcdf"):
        try:
            with xr.open_dataset(path, decode_times=True) as ds:
                ds = ds.load()
        except Exception as exc:  # netCDF4/HDF raise several types
            raise ValidationError(f"{path}: cannot be read as netCDF: {exc}") from exc
        if len(ds.dims) != 1:
            raise ValidationError(
                f"{path}: expected variables along one dimension, got dims {dict(ds.sizes)}"
            )
        meta = {str(k).lower(): v for k, v in ds.attrs.items()}
        df = ds.reset_coords().to_dataframe().reset_index(drop=True)
        for c in df.columns:
            if pd.api.types.is_datetime64_any_dtype(df[c].dtype):
                df[c] = [t.isoformat() + "Z" if not pd.isna(t) else "NaT" for t in df[c]]
                units[c] = "utc"
        where, offset = "netCDF record {}", 0
    elif suffix in TABLE_FORMATS:
        df, units, meta = _from_astropy(path, TABLE_FORMATS[suffix])
        where, offset = "row {}", 0
    else:
        try:
            df = pd.read_csv(path, skipinitialspace=True, dtype=str, keep_default_na=False)
        except Exception as exc:  # pandas raises several types for malformed text
            raise ValidationError(f"{path}: cannot be read as CSV with a header: {exc}") from exc
        df.columns = [str(c).strip() for c in df.columns]
        where, offset = "row {} (line {} of the file)", 1
    if "range" in df.columns and "range_km" not in df.columns and suffix not in TABLE_FORMATS:
        raise ValidationError(f"{path}: column 'range' has no unit here; name it 'range_km' [km]")
    return _validate(path, df, units, meta, where, offset, bands, system, time_scale)


def _validate(
    path: Path,
    df: Any,
    units: dict[str, Any],
    meta: dict[str, Any],
    where: str,
    offset: int,
    bands: Sequence[str] | None,
    system: str | None,
    time_scale: str | None,
) -> xr.Dataset:
    import pandas as pd

    cols = list(df.columns)
    missing = [c for c in LIGHT_CURVE_COLUMNS if c not in cols]
    absc = [c for c in LIGHT_CURVE_ABSCISSAE if c in cols]
    if missing:
        raise ValidationError(
            f"{path}: missing column(s) {missing}; required: band, magnitude, uncertainty "
            f"and one of time, rotation_angle; found {cols}"
        )
    if len(absc) != 1:
        raise ValidationError(
            f"{path}: need exactly one of the columns 'time' or 'rotation_angle', found "
            f"{absc or 'neither'}"
        )
    xname = absc[0]
    if len(df) == 0:
        raise ValidationError(f"{path}: no observations")

    def row_name(k: int) -> str:
        return (
            where.format(k + 1, k + 1 + offset)
            if offset
            else where.format(k + 1 if "row" in where else k)
        )

    def numeric(col: str) -> np.ndarray:
        raw = df[col]
        v = pd.to_numeric(
            pd.Series(raw).astype(str).str.strip() if raw.dtype == object else raw, errors="coerce"
        ).to_numpy(dtype=np.float64)
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            raise ValidationError(
                f"{path}: {row_name(int(bad[0]))}, column {col!r}: value "
                f"{raw.iloc[bad[0]]!r} is not a finite number"
            )
        return v

    mag = numeric("magnitude")
    unc = numeric("uncertainty")
    bad = np.flatnonzero(unc < MIN_UNCERTAINTY)
    if bad.size:
        k = int(bad[0])
        rule = (
            "must be > 0"
            if unc[k] <= 0
            else f"must be >= {MIN_UNCERTAINTY:g} mag (no photometry is that precise)"
        )
        raise ValidationError(
            f"{path}: {row_name(k)}, column 'uncertainty': {rule}, got {unc[k]:g}"
        )
    scale = time_scale if time_scale is not None else meta.get("time_scale")
    if scale is not None and str(scale).lower() != "utc":
        raise ValidationError(f"time_scale: only 'utc' is accepted, got {scale!r}")
    x_attrs: dict[str, Any]
    if xname == "time":
        raw = df["time"].astype(str).str.strip()
        as_num = pd.to_numeric(raw, errors="coerce")
        if units.get("time") != "utc" and as_num.notna().all():
            x = as_num.to_numpy(dtype=np.float64)
            x_attrs = attrs(
                "time_since_first",
                long_name="observation time",
                time_origin="as in the file (numeric seconds are kept unchanged)",
            )
            order = x
        else:
            tt = pd.to_datetime(raw, utc=True, errors="coerce", format="ISO8601")
            nat = np.flatnonzero(tt.isna().to_numpy())
            if nat.size:
                raise ValidationError(
                    f"{path}: {row_name(int(nat[0]))}, column 'time': value "
                    f"{raw.iloc[nat[0]]!r} is neither a number of seconds nor an ISO 8601 time"
                )
            naive = [k for k, v in enumerate(raw) if not _TZ.search(v)]
            if naive and scale is None:
                k = naive[0]
                raise ValidationError(
                    f"{path}: {row_name(k)}, column 'time': {raw.iloc[k]!r} has no time zone "
                    "and cannot be read as UTC; write it as ISO 8601 with 'Z' or an offset "
                    "(2024-01-01T00:00:00Z), or "
                    "pass time_scale='utc' (table metadata time_scale: utc)"
                )
            x = tt.dt.tz_convert("UTC").dt.tz_localize(None).to_numpy(dtype="datetime64[ns]")
            x_attrs = attrs("time", standard_name="time")
            order = (x - x[0]) / np.timedelta64(1, "s")
    else:
        x = numeric("rotation_angle")
        x_attrs = attrs("rotation_angle")
        order = x
    back = np.flatnonzero(np.diff(order) < 0)
    if back.size:
        k = int(back[0]) + 1
        raise ValidationError(
            f"{path}: {row_name(k)}, column {xname!r}: values must be non-decreasing "
            f"(sorted); it goes back from the previous row"
        )
    band = [str(b).strip() for b in df["band"].tolist()]
    known = set(bands) if bands is not None else None
    for k, b in enumerate(band):
        ok = (b in known) if known is not None else (_canonical(b) in speclite_names())
        if not ok:
            allowed = (
                sorted(known)
                if known is not None
                else f"aliases {list(BAND_ALIASES)} or speclite names"
            )
            raise ValidationError(
                f"{path}: {row_name(k)}, column 'band': unknown band {b!r}; allowed: {allowed}"
            )
    stated = _stated_system(path, df, meta, row_name)
    if system is not None:
        system = check_system(system)
        if stated is not None and stated != system:
            raise ValidationError(
                f"{path}: the table states the {stated} system, not system={system!r}"
            )
    mag_system = stated or system or "unstated"
    mag_attrs = attrs(
        "magnitude",
        long_name="measured magnitude",
        magnitude_system=mag_system,
        ancillary_variables="uncertainty",
    )
    data: dict[str, Any] = {
        "magnitude": ("obs", mag, mag_attrs),
        "uncertainty": ("obs", unc, attrs("magnitude_uncertainty", magnitude_system=mag_system)),
    }
    for name, (_unit, key) in LIGHT_CURVE_OPTIONAL.items():
        if name in df.columns:
            v = numeric(name)
            lo_ok = (
                (v > 0)
                if name == "range_km"
                else (v >= 1.0)
                if name == "airmass"
                else (v >= 0) & (v <= 180)
            )
            bad = np.flatnonzero(~lo_ok)
            if bad.size:
                k = int(bad[0])
                rule = {
                    "range_km": "> 0 km",
                    "airmass": ">= 1",
                    "phase_angle": "in [0, 180] degree",
                }[name]
                raise ValidationError(
                    f"{path}: {row_name(k)}, column {name!r}: must be {rule}, got {v[k]:g}"
                )
            data[name] = ("obs", v, attrs(key))
    ds = xr.Dataset(
        data,
        coords={
            "obs": ("obs", np.arange(mag.size), attrs("obs")),
            BAND: ("obs", band, attrs(BAND)),
            xname: ("obs", x, x_attrs),
        },
    )
    ds.attrs = {
        "source_file": str(path),
        "abscissa": xname,
        "magnitude_system": mag_system,
        "magnitude_system_description": MAGNITUDE_SYSTEMS.get(
            mag_system, "not stated in the table"
        ),
    }
    return ds


def _stated_system(path: Path, df: Any, meta: dict[str, Any], row_name: Any) -> str | None:
    """The one magnitude system a table states (column ``system`` or metadata), or None."""
    found: str | None = None
    if str(meta.get("magnitude_system", "unstated")) != "unstated":
        try:
            found = check_system(str(meta["magnitude_system"]))
        except ValidationError as exc:
            raise ValidationError(f"{path}: metadata magnitude_system: {exc}") from None
    if "system" in df.columns:
        vals = [str(v).strip() for v in df["system"].tolist()]
        for k, v in enumerate(vals):
            try:
                canon = check_system(v)
            except ValidationError:
                raise ValidationError(
                    f"{path}: {row_name(k)}, column 'system': unknown {v!r}; allowed: "
                    f"{', '.join(MAGNITUDE_SYSTEMS)}"
                ) from None
            if found is None:
                found = canon
            elif canon != found:
                raise ValidationError(
                    f"{path}: {row_name(k)}, column 'system': {v!r} differs from {found!r} "
                    "above; a light curve must be in one magnitude system (convert first)"
                )
    return found
