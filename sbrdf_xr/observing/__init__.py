"""Observing: real orbits, observer sites, UTC times, attitude laws and the Earth's shadow.

Modules
-------
``timescales``
    UTC times and their skyfield counterparts, with the skyfield data shipped offline.
``orbits``
    SGP4 elements, WGS84 sites and the air mass seen from them.
``earth_shadow``
    The sunlit fraction of the solar disc seen from the spacecraft.
``attitude``
    Attitude laws: the orientation of a spacecraft as a function of time
    (:class:`AttitudeLaw`, the table :data:`LAWS`, the pointing laws, spin and
    composition); ``tumble`` and ``series`` hold the torque-free tumble and the
    user time series, and ``frames`` the body axes, triads, times and the
    :class:`Context` the laws read.
``observation`` and ``observe``
    :class:`Observation`: an orbit, a site, UTC times and an attitude law, as the
    body-frame geometry of a pass; observations from TOML tables.
"""

from ..errors import AttitudeError, EpochGapWarning, NotObservableError, ObservationError
from . import (
    attitude,
    earth_shadow,
    frames,
    observation,
    observe,
    orbits,
    series,
    timescales,
    tumble,
)
from .attitude import (
    LAWS,
    AttitudeLaw,
    Composed,
    Inertial,
    Nadir,
    Spin,
    SunPointing,
    compose,
    law_from_dict,
)
from .earth_shadow import (
    EARTH_MODELS,
    EARTH_RADIUS_KM,
    SUN_RADIUS_KM,
    disc_overlap_fraction,
    shadow_events,
    sunlit_fraction,
)
from .frames import Context, triad
from .observation import ATTRS, COMPONENT, TIME, UNOBSERVABLE, Observation
from .observe import canx1_pass, observation_from_dict
from .orbits import (
    AIRMASS_MODELS,
    AU_KM,
    EPOCH_GAP_DAYS,
    Orbit,
    Site,
    airmass,
    load_orbit_entry,
    load_site_entry,
    tle_checksum,
)
from .series import QuaternionSeries
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
from .tumble import TUMBLE_RTOL, Tumble

__all__ = [
    "AIRMASS_MODELS",
    "ATTRS",
    "AU_KM",
    "COMPONENT",
    "EARTH_MODELS",
    "EARTH_RADIUS_KM",
    "EPOCH_GAP_DAYS",
    "KNOT_S",
    "LAWS",
    "SUN_RADIUS_KM",
    "TIME",
    "TUMBLE_RTOL",
    "UNOBSERVABLE",
    "AttitudeError",
    "AttitudeLaw",
    "Composed",
    "Context",
    "EpochGapWarning",
    "Inertial",
    "Nadir",
    "NotObservableError",
    "Observation",
    "ObservationError",
    "Orbit",
    "QuaternionSeries",
    "Site",
    "Spin",
    "SunPointing",
    "Tumble",
    "airmass",
    "attitude",
    "canx1_pass",
    "check_times",
    "compose",
    "disc_overlap_fraction",
    "earth_shadow",
    "frames",
    "law_from_dict",
    "load_orbit_entry",
    "load_site_entry",
    "observation",
    "observation_from_dict",
    "observe",
    "orbits",
    "series",
    "shadow_events",
    "skyfield_data",
    "skyfield_time",
    "skyfield_utc",
    "spline_knots",
    "sunlit_fraction",
    "times",
    "timescales",
    "tle_checksum",
    "to_datetime64",
    "triad",
    "tumble",
]
