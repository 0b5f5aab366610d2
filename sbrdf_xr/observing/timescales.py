"""UTC times and their skyfield counterparts, and the skyfield data shipped with the package.

UTC time grids (:func:`times`) and checks (:func:`to_datetime64`, :func:`check_times`) as
``datetime64[ns]``; the skyfield timescale and ephemeris of the ``skyfield-data`` package
(:func:`skyfield_data`, loaded on first use, then cached: nothing is downloaded); skyfield
:class:`~skyfield.timelib.Time` of a ``datetime64`` array in one vectorised call, with the
slowly varying nutation splined on knots every :data:`KNOT_S` (:func:`skyfield_time`).
:mod:`sbrdf_xr.observing.orbits` and :mod:`sbrdf_xr.observing.observation` build on them.
"""

from __future__ import annotations

import datetime as _dt
import sys
import warnings
from functools import cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import ObservationError, renamed_keywords
from ..units import to_unit

__all__ = [
    "KNOT_S",
    "check_times",
    "skyfield_data",
    "skyfield_time",
    "skyfield_utc",
    "spline_knots",
    "times",
    "to_datetime64",
]

_NS = np.dtype("datetime64[ns]")


def _astropy_utc(value: Any) -> Any:
    """An astropy ``Time`` (any scale) as UTC datetime64[ns]; anything else unchanged."""
    time_mod = sys.modules.get("astropy.time")
    if time_mod is not None and isinstance(value, time_mod.Time):
        return np.asarray(value.utc.datetime64, dtype=_NS)
    return value


@cache
def skyfield_data() -> tuple[Any, Any]:
    """Timescale (with polar motion) and ephemeris from the ``skyfield-data`` directory.

    Examples
    --------
    >>> from sbrdf_xr.observing.timescales import skyfield_data
    >>> ts, eph = skyfield_data()
    >>> t = ts.utc(2024, 3, 17)
    >>> round(float((t.tt - t.ut1) * 86400), 3)  # TT - UT1 [s] from the shipped IERS table
    69.193
    >>> type(eph).__name__, 399 in eph  # the JPL DE421 kernel, with the Earth
    ('SpiceKernel', True)
    """
    import skyfield_data
    from skyfield.api import Loader
    from skyfield.data import iers

    with warnings.catch_warnings():
        # skyfield-data warns when its finals file is past its nominal expiry date; the
        # measured values it holds are still the right ones for past dates, and later
        # dates fall back to skyfield's delta-T model.
        warnings.simplefilter("ignore", RuntimeWarning)
        path = skyfield_data.get_skyfield_data_path()
    loader = Loader(path, verbose=False)
    ts = loader.timescale(builtin=False)
    with loader.open("finals2000A.all") as f:
        iers.install_polar_motion_table(ts, iers.parse_x_y_dut1_from_finals_all(f))
    return ts, loader("de421.bsp")


#: Spacing of the knots at which the slowly varying parts of the Earth orientation and
#: the geocentric Sun are evaluated by skyfield, then cubic-spline interpolated [s].
#: Nutation's fastest sizeable term (13.66 d, 0.2 arcsec) and the Earth-Sun vector
#: (fourth derivative ``|r|`` (2 pi / yr)^4 ~ 2e-19 km s-4) are then exact to far below a
#: microarcsecond and a millimetre.
KNOT_S = 600.0


def spline_knots(t64: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Seconds of ``t64`` from its start, and spline knots covering them (>= 4).

    Examples
    --------
    >>> secs, knots = spline_knots(times("2024-03-17T00:00:00", "2024-03-17T01:00:00", 600.0))
    >>> secs.tolist(), knots.size
    ([0.0, 600.0, 1200.0, 1800.0, 2400.0, 3000.0, 3600.0], 9)
    """
    secs = (t64 - t64[0]).astype(np.int64) / 1e9
    span = float(secs[-1])
    n = max(4, int(np.ceil(span / KNOT_S)) + 3)
    return secs, np.linspace(-KNOT_S, span + KNOT_S, n)


def skyfield_utc(t64: np.ndarray) -> Any:
    """skyfield Time of a datetime64[ns] UTC array (no nutation splines: :func:`skyfield_time`).

    Examples
    --------
    >>> t = skyfield_utc(np.array(["2024-03-17T01:20:00.5"], dtype="datetime64[ns]"))
    >>> [float(x[0]) for x in t.utc]  # year, month, day, hour, minute, second
    [2024.0, 3.0, 17.0, 1.0, 20.0, 0.5]
    """
    ts, _ = skyfield_data()
    day = t64.astype("datetime64[D]")
    month = day.astype("datetime64[M]")
    year = month.astype("datetime64[Y]")
    sec = (t64 - day).astype(np.int64) / 1e9
    return ts.utc(
        year.astype(np.int64) + 1970,
        month.astype(np.int64) % 12 + 1,
        (day - month).astype(np.int64) + 1,
        0,
        0,
        sec,
    )


def skyfield_time(t64: np.ndarray) -> Any:
    """skyfield Time of a datetime64[ns] UTC array (one vectorised call).

    The IAU 2000A nutation angles and the complementary terms of the equation of the
    equinoxes, which vary over days, are evaluated on knots every :data:`KNOT_S` and
    splined (unless the times are fewer than the knots, when skyfield evaluates them
    at every time); skyfield's own formula then gives the apparent sidereal time at every
    time (the pattern skyfield documents for supplying nutation angles).

    Examples
    --------
    >>> t = skyfield_time(times("2024-03-17T01:20:00", "2024-03-17T01:30:00", 60.0))
    >>> len(t), round(float(t.gast[0]), 6)  # apparent sidereal time [h]
    (11, 13.007692)
    """
    from scipy.interpolate import CubicSpline
    from skyfield.nutationlib import equation_of_the_equinoxes_complimentary_terms

    t = skyfield_utc(t64)
    if t64.size <= 8:
        return t
    secs, knots = spline_knots(t64)
    if knots.size >= t64.size:  # sparse times (a tracking table over months): direct
        return t
    tk = skyfield_utc(t64[0] + (knots * 1e9).astype("timedelta64[ns]"))
    d_psi_k, d_eps_k = tk._nutation_angles_radians
    c_terms_k = equation_of_the_equinoxes_complimentary_terms(tk.tt)
    spline = CubicSpline(knots, np.stack([d_psi_k, d_eps_k, c_terms_k], axis=1), axis=0)(secs)
    d_psi, d_eps, c_terms = spline.T
    t._nutation_angles_radians = (d_psi, d_eps)
    eq_eq = d_psi * np.cos(t._mean_obliquity_radians) + c_terms
    t.gast = (t.gmst + eq_eq / (2 * np.pi) * 24.0) % 24.0
    return t


def to_datetime64(value: Any, name: str) -> np.datetime64:
    """One UTC time (ISO 8601, ``Z`` allowed; datetime, naive is UTC; datetime64; astropy
    ``Time`` in any scale) as datetime64[ns].

    Examples
    --------
    >>> import datetime
    >>> to_datetime64("2024-03-17T01:20:00Z", "start")
    np.datetime64('2024-03-17T01:20:00.000000000')
    >>> cest = datetime.timezone(datetime.timedelta(hours=2))
    >>> to_datetime64(datetime.datetime(2024, 3, 17, 3, 20, tzinfo=cest), "start")
    np.datetime64('2024-03-17T01:20:00.000000000')
    >>> from astropy.time import Time
    >>> to_datetime64(Time("2024-03-17T01:20:37", scale="tai"), "start")  # TAI - UTC = 37 s
    np.datetime64('2024-03-17T01:20:00.000000000')
    >>> to_datetime64("yesterday", "start")
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.ObservationError: start: got 'yesterday'; expected a UTC time (ISO 8601, ...
    """
    value = _astropy_utc(value)
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, _dt.datetime) and value.tzinfo is not None:
        value = value.astimezone(_dt.UTC).replace(tzinfo=None)
    if isinstance(value, str) and value.endswith("Z"):
        value = value[:-1]
    if isinstance(value, bool | int | float | np.number):  # a count of what, from when?
        raise ObservationError(
            f"{name}: got the number {value!r}; expected a UTC time (ISO 8601, datetime or "
            "datetime64)"
        )
    try:
        out = np.datetime64(value, "ns")
    except (TypeError, ValueError, OverflowError):
        raise ObservationError(
            f"{name}: got {value!r}; expected a UTC time (ISO 8601, datetime or datetime64) "
            f"from {YEARS[0]} to {YEARS[1]}"
        ) from None
    if np.isnat(out):
        raise ObservationError(f"{name}: got NaT")
    year = out.astype("datetime64[Y]").astype(int) + 1970
    if not YEARS[0] <= year <= YEARS[1]:
        raise ObservationError(
            f"{name}: {out} is outside the years {YEARS[0]} to {YEARS[1]} that orbits, "
            "time scales and ephemerides cover"
        )
    return out


#: The years a UTC time may lie in (the ephemerides and time scales of the package).
YEARS = (1900, 2200)
#: The most times a start/stop/step axis may hold, times ``size_limit``.
MAX_TIMES = 10**7


@renamed_keywords(step_s="step")
def times(
    start: Any, stop: Any, step: float = 1.0, *, size_limit: float = 1.0
) -> NDArray[np.datetime64]:
    """UTC times from ``start`` to ``stop`` (included when on the grid) every ``step``.

    Parameters
    ----------
    start, stop : str, datetime, datetime64 or astropy Time
        UTC times (naive datetimes and ISO strings without a zone are UTC).
    step : float or Quantity
        Step [s], > 0 (a time Quantity is converted).

    Returns
    -------
    ndarray of datetime64[ns]

    Examples
    --------
    >>> t = times("2024-03-17T01:20:00", "2024-03-17T01:20:02", step=0.5)
    >>> t.size, str(t[0]), str(t[-1])
    (5, '2024-03-17T01:20:00.000000000', '2024-03-17T01:20:02.000000000')
    """
    t0, t1 = to_datetime64(start, "start"), to_datetime64(stop, "stop")
    step = to_unit(step, "s", "step")
    if isinstance(step, bool) or not isinstance(step, int | float | np.number):
        raise ObservationError(f"step: expected a number of seconds, got {step!r}")
    if not (np.isfinite(step) and step >= 1e-6):
        raise ObservationError(
            f"step: must be a positive number of seconds, at least 1e-6 (a microsecond), "
            f"got {step!r}"
        )
    if t1 < t0:
        raise ObservationError(f"stop {t1} is before start {t0}")
    step_td = np.timedelta64(round(step * 1e9), "ns")
    n = int((t1 - t0) // step_td) + 1
    if n > size_limit * MAX_TIMES:
        raise ObservationError(
            f"step: {t0} to {t1} every {step:g} s gives {n:.3g} times, beyond the "
            f"{size_limit * MAX_TIMES:.3g} allowed ({MAX_TIMES:.0e} x size_limit); give a "
            "larger step or a shorter window, or raise size_limit"
        )
    return t0 + step_td * np.arange(n)


def check_times(value: Any) -> NDArray[np.datetime64]:
    """The UTC times of ``value`` as a strictly increasing 1-D datetime64[ns] array.

    Examples
    --------
    >>> check_times(["2024-03-17T01:20:00Z", "2024-03-17T01:20:01"])
    array(['2024-03-17T01:20:00.000000000', '2024-03-17T01:20:01.000000000'],
          dtype='datetime64[ns]')
    >>> check_times(["2024-03-17T01:20:01", "2024-03-17T01:20:00"])
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.ObservationError: times: must be strictly increasing
    """
    t = np.atleast_1d(np.asarray(_astropy_utc(value)))
    if t.dtype.kind in "US" or t.dtype == object:
        try:
            t = np.array([to_datetime64(x, "times") for x in t.ravel()]).reshape(t.shape)
        except ObservationError:
            raise
    if not np.issubdtype(t.dtype, np.datetime64):
        raise ObservationError(f"times: expected datetime64 (UTC), got dtype {t.dtype}")
    t = t.astype(_NS)
    if t.ndim != 1 or t.size == 0:
        raise ObservationError(f"times: expected a non-empty 1-D array, got shape {t.shape}")
    if np.any(np.isnat(t)):
        raise ObservationError("times: contains NaT")
    if t.size > 1 and not np.all(np.diff(t) > np.timedelta64(0, "ns")):
        raise ObservationError("times: must be strictly increasing")
    return t
