"""Reading tracking tables from CSV files, and the Pomenis Starlink table.

:func:`read_tracking_table` reads a CSV of measurements (a time column, elevation and
azimuth or right ascension and declination, range or height, optional track label and
other numeric columns) into a :class:`~sbrdf_xr.observing.tracking.TrackingTable`,
checking every row: a missing or non-numeric field, a time without a time zone (unless the
table is declared UTC), an elevation below
:data:`~sbrdf_xr.observing.tracking.MIN_ELEVATION_DEG` or a range that disagrees with the
height raise :class:`~sbrdf_xr.errors.TrackingTableError` naming the file's line; with
``on_bad="drop"`` such rows are left out, counted in a
:class:`~sbrdf_xr.errors.SbrdfWarning` and listed in ``table.dropped``.

:func:`read_pomenis` reads the Pomenis observations of Starlink v1.5 satellites from
Mount Lemmon (Fankhauser, Askari & Tyson 2023, arXiv:2305.11123; MIT licence, data
repository ``Forrest-Fankhauser/satellite-optical-brightness``).
"""

from __future__ import annotations

import csv
import re
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SbrdfWarning, TrackingTableError, input_file
from ..units import to_unit
from .orbits import Site
from .timescales import to_datetime64
from .tracking import MIN_ELEVATION_DEG, TrackingTable

__all__ = [
    "POMENIS_SITE",
    "TRACKING_KEYS",
    "read_pomenis",
    "read_tracking_table",
    "tracking_from_dict",
]

#: The Pomenis telescope on Mount Lemmon: the latitude and longitude the data's header gives
#: (32.4434 N, 110.7881 W); the height (not given there) that of the Minor Planet Center's
#: Mt. Lemmon site G96 on the same summit, 2789 m above the WGS84 ellipsoid (the
#: package's catalog site ``mount-lemmon``).
POMENIS_SITE = Site(
    32.4434,
    -110.7881,
    2789.0,
    name="pomenis-mount-lemmon",
    source=(
        "Fankhauser et al. 2023 data header (32.4434 N, 110.7881 W); height 2789 m of "
        "MPC site G96 (Mt. Lemmon Survey) on the same summit"
    ),
)

_ZONE = re.compile(r"(Z|[+-]\d{2}:?\d{2})$")


def _parse_time(text: str, line: int, time_zone: str | None, what: str) -> np.datetime64:
    s = text.strip()
    if not s:
        raise TrackingTableError(f"{what}: line {line}: the time is missing")
    has_zone = bool(_ZONE.search(s)) and ("T" in s or " " in s)
    if not has_zone:
        if time_zone != "UTC":
            raise TrackingTableError(
                f"{what}: line {line}: time {s!r} has no time zone; give times with Z or an "
                "offset, or state time_zone='UTC' if the table's times are UTC"
            )
    else:
        import pandas as pd

        try:
            s = str(pd.Timestamp(s).tz_convert("UTC").tz_localize(None).isoformat())
        except ValueError:
            raise TrackingTableError(f"{what}: line {line}: time {s!r} cannot be read") from None
    try:
        return to_datetime64(s, f"{what}: line {line}: time")
    except Exception as exc:  # ObservationError with the reason
        raise TrackingTableError(str(exc)) from None


def _number(row: dict[str, str], col: str, line: int, what: str) -> float:
    text = (row.get(col) or "").strip()
    if not text:
        raise TrackingTableError(f"{what}: line {line}: column {col!r} is empty")
    try:
        x = float(text)
    except ValueError:
        raise TrackingTableError(
            f"{what}: line {line}: column {col!r} is {text!r}, not a number"
        ) from None
    if not np.isfinite(x):
        raise TrackingTableError(f"{what}: line {line}: column {col!r} is {text!r}")
    return x


#: The unit a column name may carry after its bare name (``elevation_deg``, ``range_km``).
_COLUMN_UNITS = {"elevation": "deg", "azimuth": "deg", "ra": "deg", "dec": "deg"}
_COLUMN_UNITS.update(range="km", height="km")


def _spelling(column: str | None, header: Sequence[str]) -> str | None:
    """The header's spelling of ``column``: as named, or else with (or without) its unit.

    A file may name its columns bare (``elevation``, ``range``) or with the unit the
    reader takes them in (``elevation_deg``, ``range_km``); either is read.
    """
    if column is None or column in header:
        return column
    bare, _, unit = column.rpartition("_")
    if _COLUMN_UNITS.get(bare) == unit and bare in header:
        return bare
    if column in _COLUMN_UNITS and f"{column}_{_COLUMN_UNITS[column]}" in header:
        return f"{column}_{_COLUMN_UNITS[column]}"
    return column


def read_tracking_table(
    path: str | Path,
    site: Site,
    *,
    time: str = "time",
    elevation: str | None = "elevation",
    azimuth: str | None = "azimuth",
    ra: str | None = None,
    dec: str | None = None,
    range_column: str | None = None,
    height_column: str | None = None,
    track: str | None = None,
    keep: tuple[str, ...] = (),
    time_zone: str | None = None,
    on_bad: str = "raise",
    name: str | None = None,
    source: str = "",
    min_elevation: float = MIN_ELEVATION_DEG,
) -> TrackingTable:
    """Read a CSV tracking table (``#`` comment lines allowed before the header).

    Parameters
    ----------
    path : str or Path
    site : Site
    time, elevation, azimuth, ra, dec, range_column, height_column, track : str
        Column names (``ra``/``dec`` replace ``elevation``/``azimuth``); the columns hold
        degrees (angles) and kilometres (range, height above the WGS84 ellipsoid).  A
        direction, range or height column named bare is also found under its name with
        the unit, and the other way round (``elevation`` reads a column
        ``elevation_deg``, ``range_km`` a column ``range``).
    keep : tuple of str
        Other numeric columns to keep (``table.columns``).
    time_zone : {None, "UTC"}
        ``"UTC"`` when times without a zone are UTC; else such a time is an error.
    on_bad : {"raise", "drop"}
        A bad row raises, or is left out, counted and listed in ``table.dropped``.
    min_elevation : float
        A row whose elevation is below this is bad [degree] (default
        :data:`~sbrdf_xr.observing.tracking.MIN_ELEVATION_DEG`, which leaves room for
        refraction; 0 for elevations that are apparent, as measured on an image).

    Examples
    --------
    >>> import tempfile
    >>> path = Path(tempfile.mkdtemp()) / "track.csv"
    >>> _ = path.write_text("# demo\\ntime,elevation,azimuth,range\\n"
    ...     "2024-03-17T01:22:00Z,75.8,10.0,841.0\\n2024-03-17T01:22:05Z,75.9,12.0,abc\\n")
    >>> site = Site(45.455, -71.1525, 1111.0)
    >>> read_tracking_table(path, site, range_column="range")
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.TrackingTableError: tracking table ...: line 4: column 'range' is 'abc', ...
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     table = read_tracking_table(path, site, range_column="range", on_bad="drop")
    >>> table.times.size, table.dropped, len(caught)  # counted, listed and warned
    (1, ((4, "column 'range' is 'abc', not a number"),), 1)
    """
    if on_bad not in ("raise", "drop"):
        raise TrackingTableError(f"on_bad: got {on_bad!r}; allowed: raise, drop")
    p = input_file(path, "tracking table", TrackingTableError)
    what = f"tracking table {p}"
    with open(p, encoding="utf-8", newline="") as f:
        lines = [(k, ln) for k, ln in enumerate(f, start=1) if not ln.lstrip().startswith("#")]
    lines = [(k, ln) for k, ln in lines if ln.strip()]
    if not lines:
        raise TrackingTableError(f"{what}: holds no header line")
    reader = csv.DictReader([ln for _, ln in lines])
    header = reader.fieldnames or []
    ra, dec, elevation, azimuth, range_column, height_column = (
        _spelling(c, header) for c in (ra, dec, elevation, azimuth, range_column, height_column)
    )
    angles = (ra, dec) if ra is not None else (elevation, azimuth)
    wanted = [time, *angles, range_column, height_column, track, *keep]
    missing = [c for c in wanted if c is not None and c not in header]
    if missing:
        raise TrackingTableError(f"{what}: lacks the column(s) {missing}; its header: {header}")
    numeric = [c for c in (*angles, range_column, height_column, *keep) if c is not None]
    lo = float(to_unit(min_elevation, "deg", "min_elevation"))
    good: list[tuple[int, np.datetime64, list[float], str]] = []
    dropped: list[tuple[int, str]] = []
    for (line, _), row in zip(lines[1:], reader, strict=True):
        try:
            t = _parse_time(row.get(time) or "", line, time_zone, what)
            vals = [_number(row, c, line, what) for c in numeric]
            if elevation is not None and ra is None:
                el = vals[numeric.index(elevation)]
                if el < lo:
                    raise TrackingTableError(
                        f"{what}: line {line}: elevation {el:g} deg is below the horizon "
                        f"limit {lo:g} deg"
                    )
        except TrackingTableError as exc:
            if on_bad == "raise":
                raise
            dropped.append((line, str(exc).split(f"line {line}: ", 1)[-1]))
            continue
        good.append((line, t, vals, row.get(track, "") if track else ""))
    if not good:
        raise TrackingTableError(f"{what}: no usable row ({len(dropped)} dropped)")
    order = np.argsort(np.array([g[1] for g in good]), kind="stable")
    good = [good[i] for i in order]
    tt = np.array([g[1] for g in good])
    dup = np.flatnonzero(np.diff(tt) == np.timedelta64(0, "ns"))
    if dup.size:
        k = dup[0]
        raise TrackingTableError(
            f"{what}: lines {good[k][0]} and {good[k + 1][0]} have the same time {tt[k]}; "
            "an observation needs distinct times (one object at a time)"
        )
    cols = {c: np.array([g[2][i] for g in good]) for i, c in enumerate(numeric)}
    if dropped:
        warnings.warn(
            f"{what}: {len(dropped)} row(s) dropped (first: line {dropped[0][0]}: "
            f"{dropped[0][1]}); table.dropped lists them",
            SbrdfWarning,
            stacklevel=2,
        )
    kw: dict[str, Any] = {
        "range": cols.get(range_column) if range_column else None,
        "height": cols.get(height_column) if height_column else None,
        "track": np.array([g[3] for g in good]) if track else None,
    }
    if ra is not None:
        kw.update(ra=cols[ra], dec=cols[dec] if dec else None)
    else:
        kw.update(elevation=cols[elevation] if elevation else None)
        kw.update(azimuth=cols[azimuth] if azimuth else None)
    return TrackingTable(
        site,
        tt,
        rows=np.array([g[0] for g in good]),
        columns={c: cols[c] for c in keep},
        dropped=tuple(dropped),
        name=name or what,
        source=source or f"CSV {p}",
        **kw,
    )


def read_pomenis(path: str | Path, *, on_bad: str = "raise") -> TrackingTable:
    """The Pomenis Starlink v1.5 table (``pomenis_observations.csv``) at Mount Lemmon.

    Times are UTC (the file's header says so, and is checked); ``satellite_height`` is the
    height above the WGS84 ellipsoid [km] (lumos-sat, the authors' code, calls it the
    geodetic height); ``satellite_altitude`` and ``satellite_azimuth`` are the elevation
    and azimuth [degree] (a row below the horizon, elevation < 0, is bad: a satellite
    imaged there cannot be); ``ab_magnitude`` is kept in ``table.columns``.  Every row is
    its own track (one measurement per satellite and time): the velocity is unknown.

    Examples
    --------
    >>> import tempfile
    >>> path = Path(tempfile.mkdtemp()) / "pomenis.csv"
    >>> _ = path.write_text("# Observation Time : UTC\\n"
    ...     "observation_time,satellite_height,satellite_altitude,satellite_azimuth,"
    ...     "ab_magnitude\\n2022-01-25T13:28:39,448.4444346,32.87386184,316.0661315,4.86\\n")
    >>> table = read_pomenis(path)
    >>> table.site.name, table.columns["ab_magnitude"].tolist(), round(float(table.ranges()[0]))
    ('pomenis-mount-lemmon', [4.86], 765)
    """
    p = input_file(path, "pomenis", TrackingTableError)
    head = [ln for ln in p.read_text(encoding="utf-8").splitlines()[:40] if ln.startswith("#")]
    if not any(re.search(r"Observation Time\s*:\s*UTC", ln) for ln in head):
        raise TrackingTableError(
            f"pomenis: {p}: its header does not state 'Observation Time : UTC'; read it with "
            "read_tracking_table and the time zone it uses"
        )
    return read_tracking_table(
        p,
        POMENIS_SITE,
        time="observation_time",
        elevation="satellite_altitude",
        azimuth="satellite_azimuth",
        height_column="satellite_height",
        keep=("ab_magnitude",),
        time_zone="UTC",
        on_bad=on_bad,
        min_elevation=0.0,
        name="pomenis",
        source=(
            f"Pomenis observations of Starlink v1.5 from Mount Lemmon, {p} (Fankhauser, "
            "Askari & Tyson 2023, arXiv:2305.11123; MIT licence)"
        ),
        track=None,
    )


#: Keys of a scene file's ``[observation.tracking]`` table besides ``path`` and ``format``:
#: the arguments of :func:`read_tracking_table`.
TRACKING_KEYS = (
    "time",
    "elevation",
    "azimuth",
    "ra",
    "dec",
    "range_column",
    "height_column",
    "track",
    "time_zone",
    "on_bad",
    "name",
)


def tracking_from_dict(
    spec: Any, site: Site | None, base_dir: str | Path | None = None
) -> TrackingTable:
    """A tracking table from a scene file's ``tracking`` table.

    ``path`` (relative to ``base_dir``), ``format`` (``"csv"``, the default, read by
    :func:`read_tracking_table` with the column names and options of
    :data:`TRACKING_KEYS`, at ``site``, the range or height from a column ``range`` or
    ``height`` (or ``range_km``, ``height_km``) unless named; or ``"pomenis"``,
    :func:`read_pomenis`, at its own site).

    Examples
    --------
    >>> tracking_from_dict({"format": "pomenis"}, None)
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.TrackingTableError: [observation.tracking]: needs a path
    >>> tracking_from_dict({"path": "t.csv", "colour": "red"}, None)
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.TrackingTableError: [observation.tracking]: unknown key(s) ['colour']; ...
    """
    if not isinstance(spec, dict) or "path" not in spec:
        raise TrackingTableError("[observation.tracking]: needs a path")
    bad = sorted(set(spec) - {"path", "format", *TRACKING_KEYS})
    if bad:
        raise TrackingTableError(
            f"[observation.tracking]: unknown key(s) {bad}; allowed: path, format, "
            + ", ".join(TRACKING_KEYS)
        )
    path = Path(spec["path"])
    if not path.is_absolute() and base_dir is not None:
        path = Path(base_dir) / path
    fmt = spec.get("format", "csv")
    opts = {k: v for k, v in spec.items() if k not in ("path", "format")}
    if fmt == "pomenis":
        if site is not None or set(opts) - {"on_bad"}:
            raise TrackingTableError(
                "[observation.tracking]: format pomenis fixes its site and columns; give "
                f"only path and on_bad (got site {site!r}, {sorted(opts)})"
            )
        return read_pomenis(path, **opts)
    if fmt != "csv":
        raise TrackingTableError(
            f"[observation.tracking] format: got {fmt!r}; allowed: csv, pomenis"
        )
    if site is None:
        raise TrackingTableError("[observation]: a csv tracking table needs the site")
    if "range_column" not in opts and "height_column" not in opts:
        header = _header(path)
        found = [c for c in ("range", "range_km", "height", "height_km") if c in header]
        if not found:
            raise TrackingTableError(
                f"[observation.tracking]: {path} has no column range or height (nor range_km, "
                "height_km); name the one it has with range_column or height_column (its "
                f"header: {header})"
            )
        opts[found[0].removesuffix("_km") + "_column"] = found[0]
    return read_tracking_table(path, site, **opts)


def _header(path: Path) -> list[str]:
    """The column names of a CSV file (its first line that is not a ``#`` comment)."""
    p = input_file(path, "tracking table", TrackingTableError)
    with open(p, encoding="utf-8", errors="replace") as f:
        for line in f:
            if line.strip() and not line.lstrip().startswith("#"):
                return [c.strip() for c in line.split(",")]
    return []
