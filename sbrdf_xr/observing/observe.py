"""Observations from TOML tables, and the built-in CanX-1 pass.

:func:`observation_from_dict` builds an :class:`~sbrdf_xr.observing.observation.Observation` from
an ``[observation]`` table (an orbit, a site, UTC times and an attitude law);
:func:`canx1_pass` is the built-in example (:func:`sbrdf_xr.bench.suite.bench_geometry` times its
geometry).
The frames and models of the geometry are described in :mod:`sbrdf_xr.observing.observation`.
This module also gathers the observation API in one place: the :class:`Observation`,
the :class:`~sbrdf_xr.observing.orbits.Orbit` and :class:`~sbrdf_xr.observing.orbits.Site`, the UTC
times of
:mod:`sbrdf_xr.observing.timescales` and the models of :mod:`sbrdf_xr.observing.earth_shadow` and
:func:`~sbrdf_xr.observing.orbits.airmass` are importable from here.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, TypedDict

from ..errors import ObservationError, did_you_mean, renamed_attributes
from . import attitude as _att
from .earth_shadow import (
    EARTH_EQUATORIAL_RADIUS_KM,
    SUN_RADIUS_KM,
    disc_overlap_fraction,
    sunlit_fraction,
)
from .ephemeris import Ephemeris
from .observation import ATTRS, TIME, Observation
from .oem_reader import read_oem
from .orbits import (
    AIRMASS_MODELS,
    AU_KM,
    EPOCH_GAP_DAYS,
    Orbit,
    Site,
    airmass,
    load_orbit_entry,
    load_site_entry,
    site_fields,
    tle_checksum,
)
from .timescales import (
    check_times,
    times,
)
from .tracking_io import tracking_from_dict

__all__ = [
    "AIRMASS_MODELS",
    "ATTRS",
    "AU_KM",
    "EARTH_EQUATORIAL_RADIUS_KM",
    "EPOCH_GAP_DAYS",
    "OBSERVATION_KEYS",
    "SUN_RADIUS_KM",
    "TIME",
    "Observation",
    "Orbit",
    "Site",
    "airmass",
    "canx1_pass",
    "disc_overlap_fraction",
    "load_orbit_entry",
    "load_site_entry",
    "observation_from_dict",
    "sunlit_fraction",
    "times",
    "tle_checksum",
]


_NUMBER = (int, float)

#: The keys of an ``[observation]`` table that :func:`observation_from_dict` reads: name ->
#: (its TOML types, what it means with its unit, its default in TOML syntax or ``"-"``
#: for none, ``"required"`` when it must be given).  The scene-file reference of
#: :mod:`sbrdf_xr.engine.schema` is made from this table.
OBSERVATION_KEYS: dict[str, tuple[tuple[type, ...], str, str]] = {
    "orbit": ((str,), "the orbit: a catalog name (or tle, tle_line1/2, omm)", "-"),
    "tle": ((list,), "the orbit as [line1, line2]", "-"),
    "tle_line1": ((str,), "the orbit's first TLE line (with tle_line2)", "-"),
    "tle_line2": ((str,), "the orbit's second TLE line", "-"),
    "omm": ((str, dict), "the orbit as an OMM file or table", "-"),
    "oem": ((str,), "the orbit as a CCSDS OEM file (interpolated as it states)", "-"),
    "tracking": (
        (dict,),
        "an observer's tracking table {path, format = csv|pomenis, column names, "
        "time_zone, on_bad}: the orbit, times (and site for pomenis)",
        "-",
    ),
    "name": ((str,), "the observation's name", "-"),
    "site": (
        (str, dict),
        "a catalog name or {latitude_deg, longitude_deg, height_m, name}",
        "required (but with tracking format pomenis)",
    ),
    "start": ((str,), "first time, UTC (ISO 8601)", "-"),
    "stop": ((str,), "last time, UTC", "-"),
    "step_s": (_NUMBER, "time step [s]", "1"),
    "times": ((list,), "explicit UTC times instead of start/stop/step_s", "-"),
    "attitude": ((dict,), "[observation.attitude]: a law (the laws table below)", "-"),
    "airmass_model": (
        (str,),
        "the airmass formula (sbrdf_xr.observing.AIRMASS_MODELS)",
        '"kastenyoung1989"',
    ),
    "min_elevation_deg": (_NUMBER, "lowest elevation that counts as observable [degree]", "0.0"),
    "earth": ((str,), 'the Earth of the shadow: "wgs84" or "sphere"', '"wgs84"'),
}


#: Keys of an ``[observation]`` table that name a field differently (files keep the unit
#: in the key; :class:`Observation` takes the bare name).
_FIELD_OF_KEY = {"min_elevation_deg": "min_elevation"}


def _site(site_v: Any) -> Site:
    if isinstance(site_v, str):
        return Site.from_catalog(site_v)
    if isinstance(site_v, Mapping):
        extra = sorted(set(site_v) - {"latitude_deg", "longitude_deg", "height_m", "name"})
        if extra or not {"latitude_deg", "longitude_deg"} <= set(site_v):
            raise ObservationError(
                "[observation] site: needs latitude_deg, longitude_deg "
                f"(and optional height_m, name); got {sorted(site_v)}"
            )
        return Site(**site_fields(site_v))
    raise ObservationError(
        f"[observation] site: expected a catalog name or a table, got {site_v!r}"
    )


def observation_from_dict(
    table: Mapping[str, Any], base_dir: str | Path | None = None, *, size_limit: float = 1.0
) -> Observation:
    """An :class:`Observation` from a TOML ``[observation]`` table.

    Keys: the orbit as ``orbit`` (a catalog name), ``tle = [line1, line2]`` (or
    ``tle_line1``/``tle_line2``), ``omm`` (a path or a table), ``oem`` (a CCSDS OEM file,
    :func:`~sbrdf_xr.observing.oem_reader.read_oem`) or ``tracking`` (an
    observer's table, :func:`~sbrdf_xr.observing.tracking_io.tracking_from_dict`, which
    also gives the times); ``site`` as a catalog name
    or a table ``{latitude_deg, longitude_deg, height_m, name}``; times as ``start``,
    ``stop``, ``step_s`` or a list ``times``; ``attitude`` a table for
    :func:`sbrdf_xr.observing.attitude.law_from_dict`; optional ``airmass_model``,
    ``min_elevation_deg``, ``name`` and ``earth`` (``"wgs84"``, the default, or
    ``"sphere"``: the Earth of the shadow).  Relative paths are taken from ``base_dir``.
    A start/stop/step_s axis of more than ``size_limit`` times
    :data:`~sbrdf_xr.observing.timescales.MAX_TIMES` times is refused before it is made.
    Example::

        [observation]
        orbit = "canx1-example"
        site = "mont-megantic"
        start = "2024-03-17T01:20:00"
        stop = "2024-03-17T01:25:00"
        step_s = 1.0
        [observation.attitude]
        law = "nadir"
        yaw_deg = 0.0

    Examples
    --------
    >>> obs = observation_from_dict({"orbit": "canx1-example", "site": "mont-megantic",
    ...                              "start": "2024-03-17T01:20:00", "stop": "2024-03-17T01:21:00",
    ...                              "step_s": 30.0,
    ...                              "attitude": {"law": "spin", "rate_deg_s": 2.0}})
    >>> obs.times.size, type(obs.attitude).__name__
    (3, 'Spin')
    >>> observation_from_dict({"orbit": "canx1-example", "site": "mont-megantic", "when": "now"})
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.ObservationError: [observation]: unknown key(s) ['when']; allowed keys: ...
    """
    allowed = set(OBSERVATION_KEYS)
    if not isinstance(table, Mapping):
        raise ObservationError(f"[observation]: expected a table, got {type(table).__name__}")
    bad = sorted(set(table) - allowed)
    if bad:
        raise ObservationError(
            f"[observation]: unknown key(s) {bad}; " + did_you_mean(bad[0], allowed, "allowed keys")
        )
    base = Path(base_dir) if base_dir is not None else Path.cwd()

    def resolve(p: str) -> Path:
        path = Path(p)
        return path if path.is_absolute() else base / path

    orbit_keys = [k for k in ("orbit", "tle", "tle_line1", "omm", "oem", "tracking") if k in table]
    if len(orbit_keys) != 1:
        raise ObservationError(
            "[observation]: give exactly one of orbit, tle, tle_line1/tle_line2, omm, oem, "
            f"tracking; got {orbit_keys}"
        )
    site_v = table.get("site")
    tracking = None
    if "tracking" in table:
        site_given = _site(site_v) if site_v is not None else None
        tracking = tracking_from_dict(table["tracking"], site_given, base)
        orbit: Orbit | Ephemeris = tracking.ephemeris()
    elif "oem" in table:
        orbit = read_oem(resolve(table["oem"]))
    elif "orbit" in table:
        orbit = Orbit.from_catalog(table["orbit"])
    elif "tle" in table:
        tle = table["tle"]
        if not isinstance(tle, Sequence) or isinstance(tle, str) or len(tle) != 2:
            raise ObservationError(f"[observation] tle: expected [line1, line2], got {tle!r}")
        orbit = Orbit.from_tle(tle[0], tle[1], table.get("name"))
    elif "tle_line1" in table:
        if "tle_line2" not in table:
            raise ObservationError("[observation]: tle_line1 needs tle_line2")
        orbit = Orbit.from_tle(table["tle_line1"], table["tle_line2"], table.get("name"))
    else:
        omm = table["omm"]
        if not isinstance(omm, Mapping | str):
            raise ObservationError(
                f"[observation] omm: expected a file name or a table, got {omm!r}"
            )
        orbit = Orbit.from_omm(omm if isinstance(omm, Mapping) else resolve(omm))

    site = tracking.site if tracking is not None else _site(site_v)
    if tracking is not None:
        given = [k for k in ("times", "start", "stop", "step_s") if k in table]
        if given:
            raise ObservationError(
                f"[observation]: the tracking table gives the times; remove {given}"
            )
        t = tracking.times
    elif "times" in table:
        if any(k in table for k in ("start", "stop", "step_s")):
            raise ObservationError("[observation]: give times or start/stop/step_s, not both")
        t = check_times(table["times"])
    else:
        missing = [k for k in ("start", "stop") if k not in table]
        if missing:
            raise ObservationError(
                f"[observation]: needs times or start and stop (missing {missing})"
            )
        t = times(table["start"], table["stop"], table.get("step_s", 1.0), size_limit=size_limit)

    att = table.get("attitude")
    if att is not None and not isinstance(att, Mapping):
        raise ObservationError(f"[observation] attitude: expected a table (law = ...), got {att!r}")
    if (
        isinstance(att, Mapping)
        and att.get("law") in ("quaternion_series", "aem")
        and "path" in att
    ):
        att = {**att, "path": str(resolve(att["path"]))}
    kw = {
        _FIELD_OF_KEY.get(k, k): table[k]
        for k in ("airmass_model", "min_elevation_deg", "name", "earth")
        if k in table
    }
    return Observation(orbit, site, t, att, **kw)


# --------------------------------------------------------------------------- examples


class _PassWindow(TypedDict):
    orbit: str
    site: str
    start: str
    stop: str
    step_s: float


#: The built-in example: orbit and site catalog entries and the pass window (UTC), found
#: with ``tools/build_observe.py``: the site in astronomical darkness (Sun below
#: -25 deg), the spacecraft between 27 and 76 deg elevation, leaving the Earth's shadow
#: in the first minute (penumbra 01:20:40-01:20:55 on the WGS84 ellipsoid, 01:20:45-01:21:01
#: on a sphere) and sunlit for the remaining four.
CANX1_PASS: _PassWindow = {
    "orbit": "canx1-example",
    "site": "mont-megantic",
    "start": "2024-03-17T01:20:00",
    "stop": "2024-03-17T01:25:00",
    "step_s": 1.0,
}


def canx1_attitude() -> _att.AttitudeLaw:
    """Attitude of the built-in pass: a slow spin about a tilted body axis from a fixed start.

    Examples
    --------
    >>> law = canx1_attitude()
    >>> type(law).__name__, law.quaternions([0.0, 1.0]).shape
    ('Spin', (2, 4))
    """
    return _att.Spin(
        axis_body=(0.3, 0.4, 0.866),
        rate=4.0,
        phase=0.0,
        initial=_att.Inertial((0.2, -0.1, 0.3, 0.92736185)),
    )


def canx1_pass(attitude: _att.AttitudeLaw | None = None) -> Observation:
    """The built-in observation: CanX-1 over the Mont Mégantic Observatory for a few minutes at 1 s.

    Parameters
    ----------
    attitude : AttitudeLaw, optional
        Replaces the default :func:`canx1_attitude`.

    Returns
    -------
    Observation

    Examples
    --------
    >>> obs = canx1_pass()
    >>> obs.name, obs.times.size, str(obs.times[0])
    ('canx1-pass', 301, '2024-03-17T01:20:00.000000000')
    """
    p = CANX1_PASS
    return Observation(
        Orbit.from_catalog(p["orbit"]),
        Site.from_catalog(p["site"]),
        times(p["start"], p["stop"], p["step_s"]),
        attitude if attitude is not None else canx1_attitude(),
        name="canx1-pass",
    )


#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(
    __name__, globals(), {"EARTH_RADIUS_KM": "EARTH_EQUATORIAL_RADIUS_KM"}
)
