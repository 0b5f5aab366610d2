"""Orbits and observatories: SGP4 elements, WGS84 sites and the airmass seen from them.

:class:`Orbit` (SGP4 elements from a TLE, an OMM or a catalog entry), :class:`Site`
(a WGS84 observatory), the relative :func:`airmass` of a line of sight, and the catalog
loaders of both kinds.  The UTC times are those of :mod:`sbrdf_xr.observing.timescales`, the
Earth's shadow that of :mod:`sbrdf_xr.observing.earth_shadow` (both importable from here too).
:mod:`sbrdf_xr.observing.observe` combines them with an attitude law into an
:class:`~sbrdf_xr.observing.observation.Observation`.
"""

from __future__ import annotations

import json
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .. import _catalog_index
from .._names import AIRMASS_MODELS
from ..errors import (
    CatalogError,
    ObservationError,
    input_file,
    reading,
    renamed_attributes,
    renamed_fields,
)
from ..photometry.atmosphere import airmass
from ..units import to_unit
from .earth_shadow import (
    EARTH_EQUATORIAL_RADIUS_KM,
    SUN_RADIUS_KM,
    disc_overlap_fraction,
    sunlit_fraction,
)
from .timescales import (
    KNOT_S,
    check_times,
    skyfield_data,
    skyfield_time,
    skyfield_utc,
    spline_knots,
    times,
    to_datetime64,
)

__all__ = [
    "AIRMASS_MODELS",
    "AU_KM",
    "EARTH_EQUATORIAL_RADIUS_KM",
    "EPOCH_GAP_DAYS",
    "KNOT_S",
    "SUN_RADIUS_KM",
    "Orbit",
    "Site",
    "airmass",
    "check_times",
    "disc_overlap_fraction",
    "load_orbit_entry",
    "load_site_entry",
    "skyfield_data",
    "skyfield_time",
    "skyfield_utc",
    "spline_knots",
    "sunlit_fraction",
    "times",
    "tle_checksum",
    "to_datetime64",
]

#: Astronomical unit (IAU 2012 Resolution B2) [km].
AU_KM = 149597870.700


#: Times farther than this from the element epoch raise an :class:`EpochGapWarning` [day]:
#: SGP4 errors of LEO elements grow by about 1-3 km per day from the epoch.
EPOCH_GAP_DAYS = 7.0


def tle_checksum(line: str) -> int:
    """Checksum of a TLE line: digits summed, ``-`` counting 1, modulo 10.

    Examples
    --------
    >>> tle_checksum("1 27847U 03031H   24075.50000000  .00000015  00000-0  21000-4 0  9991")
    1
    """
    return (sum(int(c) for c in line[:68] if c.isdigit()) + line[:68].count("-")) % 10


#: Numeric fields of the TLE lines: name, first and last column (0-based, end excluded).
_TLE_FIELDS_1 = (("catalog number", 2, 7), ("epoch", 18, 32), ("mean motion derivative", 33, 43))


_TLE_FIELDS_2 = (
    ("catalog number", 2, 7),
    ("inclination", 8, 16),
    ("right ascension of the node", 17, 25),
    ("eccentricity", 26, 33),
    ("argument of perigee", 34, 42),
    ("mean anomaly", 43, 51),
    ("mean motion", 52, 63),
)


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _check_tle(line1: Any, line2: Any) -> tuple[str, str]:
    lines = []
    for i, line in ((1, line1), (2, line2)):
        if not isinstance(line, str):
            raise ObservationError(f"TLE line {i}: expected a string, got {type(line).__name__}")
        line = line.rstrip()
        if len(line) != 69:
            raise ObservationError(
                f"TLE line {i}: has {len(line)} characters; a TLE line has 69: {line!r}"
            )
        if line[0] != str(i) or line[1] != " ":
            raise ObservationError(f"TLE line {i}: must start with '{i} ', got {line[:2]!r}")
        if not line[68].isdigit() or int(line[68]) != tle_checksum(line):
            raise ObservationError(
                f"TLE line {i}: checksum {line[68]!r} does not match the computed "
                f"{tle_checksum(line)} "
                f"(digits summed, '-' counting 1, modulo 10): {line!r}"
            )
        lines.append(line)
    for i, fields in ((1, _TLE_FIELDS_1), (2, _TLE_FIELDS_2)):
        line = lines[i - 1]
        for fname, lo, hi in fields:
            text = line[lo:hi]
            ok = text.strip().isdigit() if fname == "eccentricity" else _is_number(text)
            if not ok:
                raise ObservationError(
                    f"TLE line {i}: field {fname!r} (columns {lo + 1}-{hi}) is {text!r}, "
                    "not a number"
                )
    if lines[0][2:7] != lines[1][2:7]:
        raise ObservationError(
            f"TLE: catalog numbers differ between the lines ({lines[0][2:7]!r}, {lines[1][2:7]!r})"
        )
    return lines[0], lines[1]


@dataclass(frozen=True)
class Orbit:
    """Orbital elements propagated by SGP4 (skyfield :class:`~skyfield.sgp4lib.EarthSatellite`).

    Build with :meth:`from_tle`, :meth:`from_omm` or :meth:`from_catalog`.

    Attributes
    ----------
    satellite : skyfield.sgp4lib.EarthSatellite
    line1, line2 : str
        The two-line elements (exported by :mod:`sgp4.exporter` for an OMM).
    name : str
    provenance : str

    Examples
    --------
    >>> l1 = "1 27847U 03031H   24075.50000000  .00000015  00000-0  21000-4 0  9991"
    >>> l2 = "2 27847  98.7200 129.5000 0012000  95.0000 265.0000 14.21950000109836"
    >>> orbit = Orbit.from_tle(l1, l2, "CANX-1")
    >>> orbit.name, orbit.epoch
    ('CANX-1', np.datetime64('2024-03-15T12:00:00.000000000'))
    """

    satellite: Any
    line1: str
    line2: str
    name: str = ""
    provenance: str = ""

    @classmethod
    def from_tle(
        cls, line1: str, line2: str, name: str | None = None, provenance: str = ""
    ) -> Orbit:
        """Orbit from the two lines of a TLE.

        Raises
        ------
        ObservationError
            For a line of the wrong length, start, checksum or catalog number, or a field
            SGP4 cannot read.

        Examples
        --------
        >>> l1 = "1 27847U 03031H   24075.50000000  .00000015  00000-0  21000-4 0  9991"
        >>> l2 = "2 27847  98.7200 129.5000 0012000  95.0000 265.0000 14.21950000109836"
        >>> Orbit.from_tle(l1, l2).name
        '27847'
        >>> Orbit.from_tle(l1, l2[:-1] + "0")
        Traceback (most recent call last):
            ...
        sbrdf_xr.errors.ObservationError: TLE line 2: checksum '0' does not match the computed ...
        """
        from skyfield.api import EarthSatellite

        l1, l2 = _check_tle(line1, line2)
        ts, _ = skyfield_data()
        try:
            sat = EarthSatellite(l1, l2, name, ts)
        except (ValueError, IndexError) as exc:
            raise ObservationError(f"TLE: a field cannot be read: {exc}") from None
        _check_model(sat, name or l1[2:7])
        return cls(sat, l1, l2, name or sat.name or l1[2:7].strip(), provenance)

    @classmethod
    def from_omm(cls, omm: Mapping[str, Any] | str | Path, provenance: str = "") -> Orbit:
        """Orbit from an Orbit Mean-Elements Message (CCSDS 502.0-B).

        Parameters
        ----------
        omm : mapping or path
            The OMM fields (``OBJECT_NAME``, ``EPOCH``, ``MEAN_MOTION``, ... as in CelesTrak's
            JSON/CSV) or a ``.xml``, ``.csv`` or ``.json`` file holding one.

        Examples
        --------
        >>> omm = {"OBJECT_NAME": "CANX-1", "OBJECT_ID": "2003-031H",
        ...        "EPOCH": "2024-03-15T12:00:00.000000", "MEAN_MOTION": 14.2195,
        ...        "ECCENTRICITY": 0.0012, "INCLINATION": 98.72, "RA_OF_ASC_NODE": 129.5,
        ...        "ARG_OF_PERICENTER": 95.0, "MEAN_ANOMALY": 265.0, "EPHEMERIS_TYPE": 0,
        ...        "CLASSIFICATION_TYPE": "U", "NORAD_CAT_ID": 27847, "ELEMENT_SET_NO": 999,
        ...        "REV_AT_EPOCH": 10983, "BSTAR": 2.1e-05, "MEAN_MOTION_DOT": 1.5e-07,
        ...        "MEAN_MOTION_DDOT": 0.0}
        >>> orbit = Orbit.from_omm(omm)
        >>> orbit.name, orbit.epoch
        ('CANX-1', np.datetime64('2024-03-15T12:00:00.000000000'))
        """
        from sgp4 import exporter
        from sgp4 import omm as sgp4_omm
        from skyfield.api import EarthSatellite

        where = "OMM"
        if not isinstance(omm, Mapping):
            path = input_file(omm, "omm", ObservationError)
            where = f"OMM {path}"
            kind = {".xml": "OMM XML", ".csv": "OMM CSV"}.get(path.suffix.lower(), "OMM JSON")
            with reading(path, "omm", kind, ObservationError), open(path, encoding="utf-8") as f:
                if kind == "OMM XML":
                    fields = next(iter(sgp4_omm.parse_xml(f)), None)
                elif kind == "OMM CSV":
                    fields = next(iter(sgp4_omm.parse_csv(f)), None)
                else:
                    data = json.load(f)
                    fields = data[0] if isinstance(data, list) and data else data
            if not isinstance(fields, dict) or not all(isinstance(k, str) for k in fields):
                raise ObservationError(f"omm: {path} holds no OMM record ({kind})")
        else:
            fields = dict(omm)
        ts, _ = skyfield_data()
        try:
            sat = EarthSatellite.from_omm(ts, fields)
        except (KeyError, ValueError, TypeError, OverflowError) as exc:  # fields not shown
            field = f" {exc.args[0]!r}" if isinstance(exc, KeyError) else ""
            given = "" if where != "OMM" else f"; fields given: {sorted(map(str, fields))}"
            raise ObservationError(
                f"{where}: missing or bad field{field} ({type(exc).__name__}){given}"
            ) from None
        _check_model(sat, fields.get("OBJECT_NAME", "OMM"))
        l1, l2 = exporter.export_tle(sat.model)
        return cls(sat, l1, l2, str(fields.get("OBJECT_NAME", "")), provenance)

    @classmethod
    def from_catalog(cls, name: str) -> Orbit:
        """A shipped orbit (catalog kind ``orbit``).

        Examples
        --------
        >>> Orbit.from_catalog("canx1-example").name
        'CANX-1 (example elements)'
        """
        e = _catalog_index.entry(name)
        if e.kind != "orbit":
            raise ObservationError(f"catalog entry {name!r} is a {e.kind}, not an orbit")
        return load_orbit_entry(e)

    @classmethod
    def from_file(cls, path: str | Path, name: str | None = None) -> Orbit:
        """An orbit from a file: TLEs (2- or 3-line sets, one or many) or an OMM.

        Parameters
        ----------
        path : str or Path
            ``.json``, ``.xml`` or ``.csv``: an Orbit Mean-Elements Message
            (:meth:`from_omm`); anything else: text of two-line element sets, each
            optionally preceded by a name line (CelesTrak's format).
        name : str, optional
            Which satellite of a file holding several: its name (any case) or catalog
            number.

        Raises
        ------
        ObservationError
            For an unreadable file, no or several element sets without ``name``, or a
            ``name`` the file does not hold (the names it holds are listed).

        Examples
        --------
        >>> import tempfile
        >>> l1 = "1 27847U 03031H   24075.50000000  .00000015  00000-0  21000-4 0  9991"
        >>> l2 = "2 27847  98.7200 129.5000 0012000  95.0000 265.0000 14.21950000109836"
        >>> path = Path(tempfile.mkdtemp()) / "canx1.tle"
        >>> _ = path.write_text(f"CANX-1\\n{l1}\\n{l2}\\n")
        >>> Orbit.from_file(path).name, Orbit.from_file(path, name="27847").name
        ('CANX-1', 'CANX-1')
        """
        path = Path(path)
        if path.suffix.lower() in (".json", ".xml", ".csv"):
            return cls.from_omm(path, provenance=f"OMM file {path}")
        try:
            lines = [ln.rstrip() for ln in path.read_text(encoding="utf-8").splitlines()]
        except (OSError, UnicodeDecodeError) as exc:
            raise ObservationError(f"orbit file {path}: cannot be read: {exc}") from None
        lines = [ln for ln in lines if ln.strip()]
        sets: list[tuple[str, str, str]] = []
        k = 0
        while k < len(lines):
            if lines[k].startswith("1 ") and k + 1 < len(lines) and lines[k + 1].startswith("2 "):
                sets.append((lines[k][2:7].strip(), lines[k], lines[k + 1]))
                k += 2
            elif k + 2 < len(lines) and lines[k + 1].startswith("1 "):
                sets.append((lines[k].removeprefix("0 ").strip(), lines[k + 1], lines[k + 2]))
                k += 3
            else:
                raise ObservationError(
                    f"orbit file {path}: line {k + 1} (not blank) starts no element "
                    "set; expected TLEs (an optional name line, then lines '1 ...' and "
                    "'2 ...') or an OMM file (.json, .xml, .csv)"
                )
        if not sets:
            raise ObservationError(f"orbit file {path}: holds no element set")
        if name is not None:
            want = str(name).strip().lower()
            hit = [s for s in sets if want in (s[0].lower(), s[1][2:7].strip().lower())]
            if not hit:
                raise ObservationError(
                    f"orbit file {path}: no satellite {name!r}; it holds "
                    f"{', '.join(s[0] for s in sets[:20])}{' ...' if len(sets) > 20 else ''}"
                )
            sets = hit[:1]
        if len(sets) > 1:
            raise ObservationError(
                f"orbit file {path}: holds {len(sets)} element sets "
                f"({', '.join(s[0] for s in sets[:10])}{' ...' if len(sets) > 10 else ''}); "
                "choose one by name or catalog number"
            )
        label, l1, l2 = sets[0]
        return cls.from_tle(l1, l2, label, provenance=f"TLE file {path}")

    @property
    def epoch(self) -> np.datetime64:
        """Epoch of the elements (UTC).

        Examples
        --------
        >>> Orbit.from_catalog("canx1-example").epoch
        np.datetime64('2024-03-15T12:00:00.000000000')
        """
        return np.datetime64(self.satellite.epoch.utc_datetime().replace(tzinfo=None), "ns")


def _check_model(sat: Any, label: str) -> None:
    from sgp4.api import SGP4_ERRORS

    err = getattr(sat.model, "error", 0)
    if err:
        raise ObservationError(
            f"orbit {label}: SGP4 rejects the elements (error {err}: "
            f"{SGP4_ERRORS.get(err, 'unknown')})"
        )


@renamed_fields(latitude_deg="latitude", longitude_deg="longitude", height_m="height")
@dataclass(frozen=True)
class Site:
    """An observer on the WGS84 ellipsoid.

    Parameters
    ----------
    latitude : float
        Geodetic latitude [degree], in [-90, 90].
    longitude : float
        East longitude [degree], in [-180, 360] (stored in [-180, 180)).
    height : float
        Height above the ellipsoid [m], in [-500, 9000].
    name : str
    source : str
        Where the coordinates come from (a catalog site cites its publication).

    Each coordinate may be an astropy Quantity (an ``Angle``, ``1.2 * u.km``), converted.

    Examples
    --------
    >>> site = Site(45.455, -71.1525, 1111.0, name="Mont Megantic")
    >>> site.longitude, Site(0.0, 270.0).longitude  # east longitude, stored in [-180, 180)
    (-71.1525, -90.0)
    >>> Site(95.0, 0.0)
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.ObservationError: site latitude: got 95.0; allowed: [-90, 90]
    """

    latitude: float
    longitude: float
    height: float = 0.0
    name: str = ""
    source: str = ""

    def __post_init__(self) -> None:
        checks = (
            ("latitude", -90.0, 90.0, "deg"),
            ("longitude", -180.0, 360.0, "deg"),
            ("height", -500.0, 9000.0, "m"),
        )
        for attr, lo, hi, unit in checks:
            v = to_unit(getattr(self, attr), unit, f"site {attr}")
            try:
                x = float(v)
            except (TypeError, ValueError):
                raise ObservationError(f"site {attr}: expected a number, got {v!r}") from None
            if not (np.isfinite(x) and lo <= x <= hi):
                raise ObservationError(f"site {attr}: got {v!r}; allowed: [{lo:g}, {hi:g}]")
            object.__setattr__(self, attr, x)
        lon = (self.longitude + 180.0) % 360.0 - 180.0
        object.__setattr__(self, "longitude", lon)

    @classmethod
    def from_catalog(cls, name: str) -> Site:
        """A shipped observatory (catalog kind ``site``).

        Examples
        --------
        >>> site = Site.from_catalog("mont-megantic")
        >>> site.name, round(site.latitude, 3)
        ('mont-megantic', 45.456)
        """
        e = _catalog_index.entry(name)
        if e.kind != "site":
            raise ObservationError(f"catalog entry {name!r} is a {e.kind}, not a site")
        return load_site_entry(e)

    @property
    def position(self) -> Any:
        """The skyfield WGS84 geographic position.

        Examples
        --------
        >>> Site(45.0, -71.0, 1000.0).position
        <GeographicPosition WGS84 latitude +45.0000 N longitude -71.0000 E elevation 1000.0 m>
        """
        from skyfield.api import wgs84

        return wgs84.latlon(self.latitude, self.longitude, elevation_m=self.height)


def load_orbit_entry(entry: _catalog_index.CatalogEntry) -> Orbit:
    """A ``kind = "orbit"`` entry: a 2- or 3-line TLE file.

    Examples
    --------
    >>> from sbrdf_xr import _catalog_index
    >>> load_orbit_entry(_catalog_index.entry("canx1-example")).name
    'CANX-1 (example elements)'
    """
    lines = [
        ln.rstrip() for ln in entry.file.read_text(encoding="utf-8").splitlines() if ln.strip()
    ]
    if len(lines) == 3:
        name, l1, l2 = lines[0].removeprefix("0 ").strip(), lines[1], lines[2]
    elif len(lines) == 2:
        name, l1, l2 = entry.name, lines[0], lines[1]
    else:
        raise CatalogError(
            f"orbit entry {entry.name!r}: {entry.path} must hold 2 or 3 lines, has {len(lines)}"
        )
    return Orbit.from_tle(l1, l2, name, provenance=entry.provenance)


#: Keys of a site in files (catalog TOML, ``[observation] site``) -> :class:`Site` fields.
SITE_FILE_KEYS = {"latitude_deg": "latitude", "longitude_deg": "longitude", "height_m": "height"}


def site_fields(table: Mapping[str, Any]) -> dict[str, Any]:
    """A site table as written in files (``latitude_deg``, ...) as :class:`Site` keywords.

    Files keep their keys, with the unit in the name; :class:`Site` takes bare names.

    Parameters
    ----------
    table : mapping
        Keys of :data:`SITE_FILE_KEYS` and other :class:`Site` fields.

    Returns
    -------
    dict
        The same values under the field names.

    Examples
    --------
    >>> site_fields({"latitude_deg": 45.0, "longitude_deg": -71.0, "name": "x"})
    {'latitude': 45.0, 'longitude': -71.0, 'name': 'x'}
    """
    return {SITE_FILE_KEYS.get(k, k): v for k, v in table.items()}


def load_site_entry(entry: _catalog_index.CatalogEntry) -> Site:
    """A ``kind = "site"`` entry: the table of that name in a TOML file of sites.

    Examples
    --------
    >>> from sbrdf_xr import _catalog_index
    >>> site = load_site_entry(_catalog_index.entry("haleakala"))
    >>> site.name, round(site.height)
    ('haleakala', 3058)
    """
    sites = tomllib.loads(entry.file.read_text(encoding="utf-8"))
    key = entry.extra.get("key", entry.name)
    if key not in sites:
        raise CatalogError(f"site entry {entry.name!r}: {entry.path} has no table [{key}]")
    table = dict(sites[key])
    table.pop("mpc", None)  # the published parallax constants the coordinates come from
    known = {"latitude_deg", "longitude_deg", "height_m", "source"}
    extra = sorted(set(table) - known)
    if extra:
        raise CatalogError(
            f"site entry {entry.name!r}: table [{key}] of {entry.path} has unknown key(s) "
            f"{extra}; allowed: {sorted(known | {'mpc'})}"
        )
    table.setdefault("source", entry.provenance)
    return Site(name=entry.name, **site_fields(table))


#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(
    __name__, globals(), {"EARTH_RADIUS_KM": "EARTH_EQUATORIAL_RADIUS_KM"}
)
