"""Tables read into plain columns: CSV, netCDF and what astropy reads (ECSV, FITS, VOTable).

:func:`read_table` returns the columns as a DataFrame, the astropy unit of each column
(``"utc"`` for times converted from astropy ``Time`` or netCDF), the metadata (a column's
``magnitude_system``, or a ``mag(AB)`` unit, recorded as the table's) and how rows are
named in messages; :func:`in_unit` converts a column to the package's unit.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from ..errors import MAX_FILE_BYTES, LightCurveError, check_declared_size

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


def _suffix(path: Path) -> str:
    name = path.name.lower()
    return ".fits.gz" if name.endswith(".fits.gz") else path.suffix.lower()


def _check_fits_size(path: Path) -> None:
    """Refuse a FITS file whose headers declare more than MAX_FILE_BYTES of data (read from
    the headers alone; astropy would allocate it before finding the file shorter)."""
    from astropy.io import fits

    total = 0
    with fits.open(path, lazy_load_hdus=True) as hdus:
        for hdu in hdus:
            h = hdu.header
            axes = [int(h.get(f"NAXIS{i}", 0)) for i in range(1, int(h.get("NAXIS", 0)) + 1)]
            if axes:
                total += abs(int(h.get("BITPIX", 8))) // 8 * math.prod(axes)
                total += int(h.get("PCOUNT", 0))
    if total > MAX_FILE_BYTES:
        raise LightCurveError(
            f"light curve: {path} declares {total / 2**30:.3g} GiB of data in its FITS headers; "
            f"files of at most {MAX_FILE_BYTES / 2**30:.3g} GiB are read"
        )


def _check_votable_rows(path: Path) -> None:
    """Refuse a VOTable whose ``TABLE nrows`` declare more than MAX_FILE_BYTES (8 bytes a
    FIELD a row; astropy allocates the rows declared before reading them)."""
    import mmap
    import re

    if path.stat().st_size == 0:
        return
    with open(path, "rb") as fh, mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as m:
        rows = sum(int(n) for n in re.findall(rb"<TABLE\b[^>]*?\bnrows\s*=\s*[\"'](\d{1,30})", m))
        fields = max(len(re.findall(rb"<FIELD\b", m)), 1)
    if rows * fields * 8 > MAX_FILE_BYTES:
        raise LightCurveError(
            f"light curve: {path} declares {rows} rows of {fields} fields in its VOTable "
            f"(about {rows * fields * 8 / 2**30:.3g} GiB); files of at most "
            f"{MAX_FILE_BYTES / 2**30:.3g} GiB are read"
        )


def _from_astropy(path: Path, fmt: str) -> tuple[Any, dict[str, Any], dict[str, Any]]:
    """Columns as a DataFrame of plain values, their astropy units, the table metadata."""
    import warnings

    import astropy.units as u
    import pandas as pd
    from astropy.table import Table
    from astropy.time import Time

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # VOTable/FITS readers warn about vendor keywords
            if fmt == "fits":
                _check_fits_size(path)
            elif fmt == "votable":
                _check_votable_rows(path)
            # astropy_native: FITS time columns come back as Time (with their scale)
            tab = Table.read(
                path, format=fmt, **({"astropy_native": True} if fmt == "fits" else {})
            )
    except LightCurveError:
        raise
    except Exception as exc:  # astropy raises many types for malformed files
        raise LightCurveError(f"{path}: cannot be read as {fmt}: {exc}") from exc
    cols: dict[str, Any] = {}
    units: dict[str, Any] = {}
    meta = {str(k).lower(): v for k, v in tab.meta.items() if isinstance(v, str | int | float)}
    if fmt == "fits" and "timesys" not in meta:  # astropy_native takes TIMESYS for Time columns
        from astropy.io import fits

        with fits.open(path) as hdus:
            said = next((h.header["TIMESYS"] for h in hdus[1:] if "TIMESYS" in h.header), None)
        if said is not None:
            meta["timesys"] = str(said)
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
            raise LightCurveError(
                f"{path}: column {key!r} is not one value per row (shape {col.shape})"
            )
        said = col.meta.get("magnitude_system") if getattr(col, "meta", None) else None
        unit = getattr(col, "unit", None)
        if unit is not None and str(unit) in ("mag(AB)", "mag(ST)"):
            said, unit = str(unit)[4:6], u.mag
        if said is not None:
            if meta.get("magnitude_system", said) != said:
                raise LightCurveError(
                    f"{path}: column {key!r} states the {said} system, another column or the "
                    f"table {meta['magnitude_system']}; a light curve is in one system"
                )
            meta["magnitude_system"] = said
        if col.dtype.kind in "fiu":
            cols[key] = np.ma.filled(np.ma.asarray(col, dtype=np.float64), np.nan)
            units[key] = unit
        else:
            cols[key] = [str(v.decode() if isinstance(v, bytes) else v) for v in np.asarray(col)]
    return pd.DataFrame(cols), units, meta


def in_unit(path: Path, col: str, values: np.ndarray, unit: Any, target: str) -> np.ndarray:
    """``values`` of a column with an astropy ``unit`` in ``target`` (``mag``: as is)."""
    import astropy.units as u

    if unit is None or unit == "utc":
        return values
    try:
        if target == "mag":
            if unit not in (u.mag, u.dimensionless_unscaled):
                raise u.UnitConversionError(str(unit))
            return values
        return (values * u.Unit(unit)).to_value(u.Unit(target) if target else u.one)
    except (u.UnitConversionError, u.UnitsError, ValueError, TypeError):
        raise LightCurveError(
            f"{path}: column {col!r} has unit {unit!s}, which cannot be converted "
            f"to {target or 'a dimensionless number'}"
        ) from None


def read_table(path: Path) -> tuple[Any, dict[str, Any], dict[str, Any], str, int]:
    import pandas as pd

    suffix = _suffix(path)
    units: dict[str, Any] = {}
    meta: dict[str, Any] = {}
    if suffix in (".nc", ".nc4", ".netcdf"):
        check_declared_size(path, "light curve", error=LightCurveError)
        try:
            with xr.open_dataset(path, decode_times=True) as ds:
                ds = ds.load()
        except Exception as exc:  # netCDF4/HDF raise several types
            raise LightCurveError(f"{path}: cannot be read as netCDF: {exc}") from exc
        if len(ds.dims) != 1:
            raise LightCurveError(
                f"{path}: expected variables along one dimension, got dims {dict(ds.sizes)}"
            )
        meta = {str(k).lower(): v for k, v in ds.attrs.items()}
        df = ds.reset_coords().to_dataframe().reset_index(drop=True)
        for c in df.columns:
            if pd.api.types.is_datetime64_any_dtype(df[c].dtype):
                df[c] = [t.isoformat() + "Z" if not pd.isna(t) else "NaT" for t in df[c]]
                units[c] = "utc"
        return df, units, meta, "netCDF record {}", 0
    if suffix in TABLE_FORMATS:
        df, units, meta = _from_astropy(path, TABLE_FORMATS[suffix])
        return df, units, meta, "row {}", 0
    try:
        df = pd.read_csv(path, skipinitialspace=True, dtype=str, keep_default_na=False, comment="#")
    except Exception as exc:  # pandas raises several types for malformed text
        raise LightCurveError(f"{path}: cannot be read as CSV with a header: {exc}") from exc
    df.columns = [str(c).strip() for c in df.columns]
    return df, units, meta, "row {} (line {} of the file)", 1
