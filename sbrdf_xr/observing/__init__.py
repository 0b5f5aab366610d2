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
    (:class:`AttitudeLaw`, the table :data:`ATTITUDE_LAWS`, the pointing laws, spin and
    composition); ``tumble`` and ``series`` hold the torque-free tumble and the
    user time series, and ``frames`` the body axes, triads, times and the
    :class:`Context` the laws read.
``observation`` and ``observe``
    :class:`Observation`: an orbit, a site, UTC times and an attitude law, as the
    body-frame geometry of a pass; observations from TOML tables.
``ephemeris``, ``oem_reader`` and ``aem``
    :class:`Ephemeris`: states from data (tabulated, or a CCSDS OEM read by the ``oem``
    package) in place of elements; attitude from a CCSDS AEM (``ccsds-ndm``).
``tracking`` and ``tracking_io``
    :class:`TrackingTable`: an observer's measured directions with range or height
    as an ephemeris and an observation; CSV and Pomenis readers.
``passes``
    :func:`visible_passes`: the passes a site can measure (up, sunlit, sky dark).
"""

from ..errors import (
    AttitudeError,
    EpochGapWarning,
    NotObservableError,
    ObservationError,
    renamed_attributes,
)
from . import (
    aem,
    attitude,
    earth_shadow,
    ephemeris,
    frames,
    observation,
    observe,
    oem_reader,
    orbits,
    passes,
    series,
    timescales,
    tracking,
    tracking_io,
    tumble,
)
from .aem import AemSeries, read_aem
from .attitude import (
    ATTITUDE_LAWS,
    AttitudeLaw,
    Composed,
    Inertial,
    Nadir,
    Spin,
    SunPointing,
    YawSteering,
    compose,
    law_from_dict,
)
from .earth_shadow import (
    EARTH_EQUATORIAL_RADIUS_KM,
    EARTH_MODELS,
    SUN_RADIUS_KM,
    disc_overlap_fraction,
    shadow_events,
    sunlit_fraction,
)
from .ephemeris import Ephemeris
from .frames import Context, triad
from .observation import ATTRS, COMPONENT, TIME, UNOBSERVABLE, Observation
from .observe import canx1_pass, observation_from_dict
from .oem_reader import read_oem
from .orbits import (
    AIRMASS_MODELS,
    AU_KM,
    EPOCH_GAP_DAYS,
    Orbit,
    Site,
    load_orbit_entry,
    load_site_entry,
    tle_checksum,
)
from .orbits import (
    airmass as airmass,  # photometry.airmass, the one air mass (published there)
)
from .passes import TWILIGHTS, visible_passes
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
from .tracking import TrackingTable
from .tracking_io import POMENIS_SITE, read_pomenis, read_tracking_table
from .tumble import TUMBLE_RTOL, Tumble

__all__ = [
    "AIRMASS_MODELS",
    "ATTITUDE_LAWS",
    "ATTRS",
    "AU_KM",
    "COMPONENT",
    "EARTH_EQUATORIAL_RADIUS_KM",
    "EARTH_MODELS",
    "EPOCH_GAP_DAYS",
    "KNOT_S",
    "POMENIS_SITE",
    "SUN_RADIUS_KM",
    "TIME",
    "TUMBLE_RTOL",
    "TWILIGHTS",
    "UNOBSERVABLE",
    "AemSeries",
    "AttitudeError",
    "AttitudeLaw",
    "Composed",
    "Context",
    "Ephemeris",
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
    "TrackingTable",
    "Tumble",
    "YawSteering",
    "aem",
    "attitude",
    "canx1_pass",
    "check_times",
    "compose",
    "disc_overlap_fraction",
    "earth_shadow",
    "ephemeris",
    "frames",
    "law_from_dict",
    "load_orbit_entry",
    "load_site_entry",
    "observation",
    "observation_from_dict",
    "observe",
    "oem_reader",
    "orbits",
    "passes",
    "read_aem",
    "read_oem",
    "read_pomenis",
    "read_tracking_table",
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
    "tracking",
    "tracking_io",
    "triad",
    "tumble",
    "visible_passes",
]

#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(
    __name__, globals(), {"EARTH_RADIUS_KM": "EARTH_EQUATORIAL_RADIUS_KM", "LAWS": "ATTITUDE_LAWS"}
)
