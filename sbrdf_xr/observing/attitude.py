"""Attitude laws: the orientation of a spacecraft as a function of time.

Every law is an :class:`AttitudeLaw`: ``law.quaternions(times, context=None) -> (n, 4)``,
unit quaternions, scalar-last ``(x, y, z, w)``, of the rotation that takes body-frame
vectors to the inertial reference frame (the convention of :mod:`sbrdf_xr.geometry`),
and ``outer * inner`` composes two laws.  The inertial frame of
:mod:`sbrdf_xr.observing.observe` is the GCRS (geocentric, ICRF axes).

Times are either ``datetime64`` (UTC) or float seconds.  Float seconds count from the
law's ``epoch``; a law without an ``epoch`` counts from ``context.epoch`` (the start of
the observation), or from the first requested time.  Laws that follow the orbit
(:class:`Nadir`, :class:`SunPointing`) need a :class:`~sbrdf_xr.observing.frames.Context`
with the spacecraft's position and velocity and the direction of the Sun at the
requested times.

Laws
----
==================  ========================================================================
Inertial(q)         fixed orientation
Nadir               LVLH: a body axis on the nadir, another toward the velocity, then a yaw
YawSteering         a body axis on the (geodetic or geocentric) nadir, a second one turned
                    toward the Sun about it: needs no velocity
SunPointing         a body axis on the Sun, a second body axis as close as possible to a
                    target direction (orbit normal, nadir, velocity, north or a vector)
Spin                rotation about a body axis at a constant rate from an initial attitude
                    (a quaternion or another law)
Composed            ``outer * inner``: ``R(t) = R_outer(t) R_inner(t)`` (:func:`compose`)
Tumble              torque-free rigid body: Euler's equations for an inertia tensor
                    (given, or :meth:`Spacecraft.inertia` at uniform density), integrated
                    with :func:`scipy.integrate.solve_ivp` (DOP853, rtol 1e-12)
QuaternionSeries    a user time series (arrays, CSV or netCDF), slerp-interpolated
==================  ========================================================================

This module holds the interface, the table of laws and every law but the last two,
which have their own modules (:mod:`sbrdf_xr.observing.tumble`,
:mod:`sbrdf_xr.observing.series`).  A law enters the table :data:`ATTITUDE_LAWS` by its class
definition (its ``law_name`` and ``law_parameters``), and :func:`law_from_dict` builds any
law of the table from a TOML table (``[observation.attitude]``) through the class's
``from_table``.  The frames, :class:`~sbrdf_xr.observing.frames.Context` and
:func:`~sbrdf_xr.observing.frames.triad` are in :mod:`sbrdf_xr.observing.frames`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from ..errors import (
    AttitudeError,
    did_you_mean,
    renamed_attributes,
    renamed_fields,
    renamed_keywords,
)
from ..units import to_unit
from .frames import (
    Context,
    axis_vector,
    check_epoch,
    check_quaternion,
    context_fields,
    perpendicular_pair,
    seconds_since,
    triad,
)

__all__ = [
    "ATTITUDE_LAWS",
    "VERTICALS",
    "AttitudeLaw",
    "Composed",
    "Inertial",
    "Nadir",
    "Spin",
    "SunPointing",
    "YawSteering",
    "compose",
    "geodetic_up",
    "law_from_dict",
]

#: Law name -> (class, allowed parameters); each law's class definition enters it
#: (:class:`AttitudeLaw`).
ATTITUDE_LAWS: dict[str, tuple[type[AttitudeLaw], tuple[str, ...]]] = {}


class AttitudeLaw:
    """Base of the attitude laws: ``law.quaternions(times, context) -> (n, 4)``.

    ``outer * inner`` composes two laws (:class:`Composed`).  A subclass that sets
    ``law_name`` (the ``law`` of a TOML table) and ``law_parameters`` (its other keys)
    enters :data:`ATTITUDE_LAWS`; :meth:`from_table` builds it from such a table, a key
    spelled with its unit (``rate_deg_s``) given to its bare field (``rate``) through
    ``table_keys``.

    Examples
    --------
    >>> law = Spin(axis_body="+z", rate=90.0)
    >>> isinstance(law, AttitudeLaw), law.quaternions([0.0, 1.0]).shape
    (True, (2, 4))
    """

    law_name: ClassVar[str] = ""
    law_parameters: ClassVar[tuple[str, ...]] = ()
    table_keys: ClassVar[Mapping[str, str]] = {}

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if cls.__dict__.get("law_name"):
            ATTITUDE_LAWS[cls.law_name] = (cls, cls.law_parameters)

    @classmethod
    def from_table(cls, params: dict[str, Any]) -> AttitudeLaw:
        """The law of a TOML table's parameters (its keys but ``law``, already checked
        against ``law_parameters``).

        Examples
        --------
        >>> Inertial.from_table({"q": [0.0, 0.0, 1.0, 0.0]})
        Inertial(q=(0.0, 0.0, 1.0, 0.0))
        """
        try:
            return cls(**{cls.table_keys.get(k, k): v for k, v in params.items()})
        except TypeError as exc:
            raise AttitudeError(f"attitude law {cls.law_name!r}: {exc}") from None

    def quaternions(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        """Attitudes (body -> inertial, scalar-last) at ``times``; shape ``(n, 4)``.

        Examples
        --------
        >>> np.round(Spin(rate=180.0).quaternions([0.0, 1.0]), 6)  # half a turn in 1 s
        array([[0., 0., 0., 1.],
               [0., 0., 1., 0.]])
        """
        raise NotImplementedError

    def __mul__(self, other: AttitudeLaw) -> Composed:
        if not isinstance(other, AttitudeLaw):
            return NotImplemented
        return Composed(self, other)


@dataclass(frozen=True)
class Inertial(AttitudeLaw):
    """A fixed orientation in the inertial frame.

    Parameters
    ----------
    q : array_like, shape (4,)
        Unit quaternion, scalar-last, body -> inertial [1].

    Examples
    --------
    >>> s = float(np.sqrt(0.5))
    >>> Inertial((0.0, 0.0, s, s)).quaternions(np.zeros(2)).round(6)  # 90 degree about z, always
    array([[0.      , 0.      , 0.707107, 0.707107],
           [0.      , 0.      , 0.707107, 0.707107]])
    """

    law_name: ClassVar[str] = "inertial"
    law_parameters: ClassVar[tuple[str, ...]] = ("q",)

    q: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)

    def __post_init__(self) -> None:
        object.__setattr__(self, "q", tuple(check_quaternion(self.q, "inertial q").tolist()))

    def quaternions(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        n = np.atleast_1d(np.asarray(times)).shape[0]
        return np.tile(np.asarray(self.q), (n, 1))


@renamed_fields(yaw_deg="yaw")
@dataclass(frozen=True)
class Nadir(AttitudeLaw):
    """Nadir pointing in the local-vertical local-horizontal (LVLH) frame, with a yaw.

    At yaw 0 the body ``nadir_axis`` points from the spacecraft to the Earth's centre
    (``-r/|r|``) and ``velocity_axis`` along the along-track direction (the part of
    the velocity perpendicular to ``r``).  The yaw then turns the body about the nadir
    axis by ``yaw`` (right-handed about ``nadir_axis``), so the nadir axis stays on
    the geocentre.

    Parameters
    ----------
    yaw : float
        Yaw about the nadir axis [degree].
    nadir_axis, velocity_axis : str or array_like
        Perpendicular body axes (``"+z"``, ``"-x"``, ... or 3 components).

    Examples
    --------
    >>> from scipy.spatial.transform import Rotation
    >>> from sbrdf_xr.observing import Context
    >>> ctx = Context(position=np.array([[7000.0, 0.0, 0.0]]),
    ...               velocity=np.array([[0.0, 7.5, 0.0]]))
    >>> q = Nadir(nadir_axis="+z", velocity_axis="+x").quaternions([0.0], ctx)
    >>> np.round(Rotation.from_quat(q).apply([0.0, 0.0, 1.0]), 6) + 0.0  # +z on the geocentre
    array([[-1.,  0.,  0.]])
    """

    law_name: ClassVar[str] = "nadir"
    law_parameters: ClassVar[tuple[str, ...]] = ("yaw_deg", "nadir_axis", "velocity_axis")
    table_keys: ClassVar[Mapping[str, str]] = {"yaw_deg": "yaw"}

    yaw: float = 0.0
    nadir_axis: Any = "+z"
    velocity_axis: Any = "+x"
    _axes: tuple[np.ndarray, np.ndarray] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "yaw", to_unit(self.yaw, "deg", "yaw"))
        if not np.isfinite(self.yaw):
            raise AttitudeError(f"nadir yaw: must be finite, got {self.yaw}")
        a, b = perpendicular_pair(
            axis_vector(self.nadir_axis, "nadir_axis"),
            axis_vector(self.velocity_axis, "velocity_axis"),
            "nadir",
        )
        object.__setattr__(self, "_axes", (a, b))

    def quaternions(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        n = np.atleast_1d(np.asarray(times)).shape[0]
        r, v = context_fields(context, n, "nadir", "position", "velocity")
        a, b = self._axes
        q = triad(a, b, -r, v)
        if self.yaw:
            yaw = Rotation.from_rotvec(np.radians(self.yaw) * a)
            q = (Rotation.from_quat(q) * yaw).as_quat().reshape(-1, 4)
        return q


#: Verticals of :class:`YawSteering`: the WGS84 ellipsoid's normal, or the geocentre.
VERTICALS = ("geodetic", "geocentric")


@renamed_keywords(position_itrs_km="position_itrs")
def geodetic_up(position_itrs: ArrayLike, iterations: int = 6) -> NDArray[np.float64]:
    """Unit normals of the WGS84 ellipsoid through ITRS points (geodetic zenith), (n, 3).

    The geodetic latitude by fixed-point iteration of
    ``tan(phi) = (z + e**2 N sin(phi)) / p`` with ``N = a / sqrt(1 - e**2 sin(phi)**2)``
    (e.g. Montenbruck & Gill 2000, *Satellite Orbits*, sect. 5.5.2), from the geocentric
    latitude; six steps reach 1e-12 rad above 100 km height.

    Parameters
    ----------
    position_itrs : array_like, shape (n, 3)
        Positions in the ITRS [km].
    iterations : int
        Fixed-point steps.

    Examples
    --------
    >>> geodetic_up([[7000.0, 0.0, 0.0], [0.0, 0.0, 7000.0]]).round(12) + 0.0
    array([[1., 0., 0.],
           [0., 0., 1.]])
    >>> r = [[5000.0, 0.0, 5000.0]]  # 45 deg geocentric: the geodetic latitude is larger
    >>> bool(np.degrees(np.arcsin(geodetic_up(r)[0, 2])) > 45.1)
    True
    """
    from .earth_shadow import EARTH_EQUATORIAL_RADIUS_KM, WGS84_FLATTENING

    x = np.asarray(to_unit(position_itrs, "km", "position_itrs"), dtype=np.float64)
    x = x.reshape(-1, 3)
    e2 = WGS84_FLATTENING * (2.0 - WGS84_FLATTENING)
    p = np.hypot(x[:, 0], x[:, 1])
    lat = np.arctan2(x[:, 2], p)
    for _ in range(iterations):
        s = np.sin(lat)
        n = EARTH_EQUATORIAL_RADIUS_KM / np.sqrt(1.0 - e2 * s**2)
        lat = np.arctan2(x[:, 2] + e2 * n * s, p)
    lon = np.arctan2(x[:, 1], x[:, 0])
    c = np.cos(lat)
    return np.stack([c * np.cos(lon), c * np.sin(lon), np.sin(lat)], axis=1)


@dataclass(frozen=True)
class YawSteering(AttitudeLaw):
    """A body axis on the nadir, a second one turned about it toward the Sun.

    ``nadir_axis`` points down the local vertical (``vertical="geodetic"``: the normal of
    the WGS84 ellipsoid through the spacecraft, computed in the ITRS and rotated to the
    GCRS by skyfield; ``"geocentric"``: to the Earth's centre), and ``sun_axis`` to the
    Sun's direction projected on the plane perpendicular to it (TRIAD, Black 1964).  The
    frame of Fankhauser et al. (2023, arXiv:2305.11123, sect. 2: ``z`` to geodetic zenith,
    ``y`` perpendicular to it toward the Sun) is ``YawSteering("-z", "+y")``.  Unlike
    :class:`Nadir` it needs no velocity, so it serves single-row tracks of a tracking
    table.  With the Sun on the vertical the yaw is undefined and an
    :class:`~sbrdf_xr.errors.AttitudeError` is raised.

    Parameters
    ----------
    nadir_axis, sun_axis : str or array_like
        Perpendicular body axes (``"+z"``, ``"-x"``, ... or 3 components).
    vertical : {"geodetic", "geocentric"}
        Which nadir.

    Examples
    --------
    >>> from scipy.spatial.transform import Rotation
    >>> from sbrdf_xr.observing import Context
    >>> ctx = Context(position=np.array([[7000.0, 0.0, 0.0]]),
    ...               sun=np.array([[-1e7, 1.5e8, 0.0]]))
    >>> law = YawSteering(nadir_axis="-z", sun_axis="+y", vertical="geocentric")
    >>> R = Rotation.from_quat(law.quaternions([0.0], ctx))
    >>> np.round(R.apply([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]), 6) + 0.0  # z up, y to the Sun
    array([[1., 0., 0.],
           [0., 1., 0.]])
    """

    law_name: ClassVar[str] = "yaw_steering"
    law_parameters: ClassVar[tuple[str, ...]] = ("nadir_axis", "sun_axis", "vertical")

    nadir_axis: Any = "-z"
    sun_axis: Any = "+y"
    vertical: str = "geodetic"
    _axes: tuple[np.ndarray, np.ndarray] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.vertical not in VERTICALS:
            raise AttitudeError(
                f"yaw_steering vertical: got {self.vertical!r}; allowed: {', '.join(VERTICALS)}"
            )
        a, b = perpendicular_pair(
            axis_vector(self.nadir_axis, "nadir_axis"),
            axis_vector(self.sun_axis, "sun_axis"),
            "yaw_steering",
        )
        object.__setattr__(self, "_axes", (a, b))

    def _up(self, times: ArrayLike, r: np.ndarray, context: Context | None) -> np.ndarray:
        if self.vertical == "geocentric":
            return r / np.linalg.norm(r, axis=1)[:, None]
        from skyfield.framelib import itrs

        from .timescales import skyfield_time

        t = np.atleast_1d(np.asarray(times))
        if not np.issubdtype(t.dtype, np.datetime64):
            epoch = None if context is None else context.epoch
            if epoch is None:
                raise AttitudeError(
                    "yaw_steering: a geodetic vertical needs UTC times (datetime64) or a "
                    "context epoch; got float times without one"
                )
            t = np.asarray(epoch, dtype="datetime64[ns]") + (t.astype(np.float64) * 1e9).astype(
                "m8[ns]"
            )
        rot = itrs.rotation_at(skyfield_time(t.astype("datetime64[ns]")))  # GCRS -> ITRS
        up_itrs = geodetic_up(np.einsum("ijn,nj->ni", rot, r))
        return np.einsum("jin,nj->ni", rot, up_itrs)

    def quaternions(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        n = np.atleast_1d(np.asarray(times)).shape[0]
        r, sun = context_fields(context, n, "yaw_steering", "position", "sun")
        up = self._up(times, r, context)
        s = sun / np.linalg.norm(sun, axis=1)[:, None]
        if np.any(np.linalg.norm(np.cross(up, s), axis=1) < 1e-12):
            raise AttitudeError("yaw_steering: the Sun is on the vertical; the yaw is undefined")
        a, b = self._axes
        return triad(a, b, -up, s)


_SECONDARY_TARGETS = ("orbit_normal", "nadir", "velocity", "north")


@dataclass(frozen=True)
class SunPointing(AttitudeLaw):
    """A body axis on the Sun, a second body axis as near a target direction as allowed.

    Parameters
    ----------
    axis : str or array_like
        Body axis pointed at the Sun.
    secondary_axis : str or array_like
        Body axis perpendicular to ``axis``, turned toward ``secondary_target``.
    secondary_target : str or array_like
        ``orbit_normal`` (``r x v``), ``nadir``, ``velocity``, ``north`` (inertial +z) or
        three components in the inertial frame.  Where the target is parallel to the Sun
        direction the attitude is undefined and an :class:`AttitudeError` is raised.

    Examples
    --------
    >>> from scipy.spatial.transform import Rotation
    >>> from sbrdf_xr.observing import Context
    >>> ctx = Context(position=np.array([[7000.0, 0.0, 0.0]]),
    ...               velocity=np.array([[0.0, 7.5, 0.0]]),
    ...               sun=np.array([[0.0, 1.5e8, 0.0]]))
    >>> q = SunPointing(axis="+z", secondary_axis="+x").quaternions([0.0], ctx)
    >>> R = Rotation.from_quat(q)
    >>> np.round(R.apply([0.0, 0.0, 1.0]), 6) + 0.0, np.round(R.apply([1.0, 0.0, 0.0]), 6) + 0.0
    (array([[0., 1., 0.]]), array([[0., 0., 1.]]))
    """

    law_name: ClassVar[str] = "sun_pointing"
    law_parameters: ClassVar[tuple[str, ...]] = ("axis", "secondary_axis", "secondary_target")

    axis: Any = "+z"
    secondary_axis: Any = "+x"
    secondary_target: Any = "orbit_normal"
    _axes: tuple[np.ndarray, np.ndarray, str | np.ndarray] = field(
        init=False, repr=False, compare=False
    )

    def __post_init__(self) -> None:
        a, b = perpendicular_pair(
            axis_vector(self.axis, "axis"),
            axis_vector(self.secondary_axis, "secondary_axis"),
            "sun_pointing",
        )
        tgt = self.secondary_target
        if isinstance(tgt, str):
            if tgt not in _SECONDARY_TARGETS:
                raise AttitudeError(
                    f"sun_pointing secondary_target: got {tgt!r}; "
                    f"allowed: {', '.join(_SECONDARY_TARGETS)} "
                    "or 3 components"
                )
        else:
            tgt = axis_vector(tgt, "secondary_target")
        object.__setattr__(self, "_axes", (a, b, tgt))

    def quaternions(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        n = np.atleast_1d(np.asarray(times)).shape[0]
        a, b, tgt = self._axes
        (sun,) = context_fields(context, n, "sun_pointing", "sun")
        if isinstance(tgt, str) and tgt != "north":
            r, v = context_fields(context, n, "sun_pointing", "position", "velocity")
            target = {"orbit_normal": np.cross(r, v), "nadir": -r, "velocity": v}[tgt]
        else:
            target = np.tile([0.0, 0.0, 1.0] if isinstance(tgt, str) else tgt, (n, 1))
        return triad(a, b, sun, target)


@renamed_fields(rate_deg_s="rate", phase_deg="phase")
@dataclass(frozen=True)
class Spin(AttitudeLaw):
    """Rotation about a body axis at a constant rate, after an initial attitude.

    ``R(t) = R_initial(t) R_axis(phase + rate t)``: the body turns about its own
    ``axis_body`` (right-handed) by the angle ``phase + rate * t``, starting
    from ``initial`` (a quaternion: the attitude at angle 0; or a law, e.g. :class:`Nadir`
    for a nadir-pointer spinning about its nadir axis).  With an inertial ``initial`` this
    equals :func:`sbrdf_xr.geometry.rotation_sweep` about the inertial axis
    ``R_initial axis_body``.

    Parameters
    ----------
    axis_body : str or array_like
        Spin axis in the body frame.
    rate : float
        Spin rate [degree s-1].
    phase : float
        Angle at the epoch [degree].
    initial : quaternion, law or table
        Attitude at angle 0 (default: identity).
    epoch : datetime64 or str, optional
        Time of ``phase`` (default: the start of the observation).

    Examples
    --------
    >>> spin = Spin(axis_body="+z", rate=10.0, phase=5.0)
    >>> spin.angles([0.0, 1.0, 2.0])  # [degree]
    array([ 5., 15., 25.])
    >>> np.round(spin.quaternions([0.0]), 6)
    array([[0.      , 0.      , 0.043619, 0.999048]])
    """

    law_name: ClassVar[str] = "spin"
    law_parameters: ClassVar[tuple[str, ...]] = (
        "axis_body",
        "rate_deg_s",
        "phase_deg",
        "initial",
        "epoch",
    )
    table_keys: ClassVar[Mapping[str, str]] = {"rate_deg_s": "rate", "phase_deg": "phase"}

    axis_body: Any = "+z"
    rate: float = 1.0
    phase: float = 0.0
    initial: Any = (0.0, 0.0, 0.0, 1.0)
    epoch: Any = None
    _axis_vec: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        for name, unit in (("rate", "deg / s"), ("phase", "deg")):
            val = to_unit(getattr(self, name), unit, name)
            object.__setattr__(self, name, val)
            if not isinstance(val, int | float | np.floating | np.integer) or not np.isfinite(val):
                raise AttitudeError(f"spin {name}: must be a finite number [degree], got {val!r}")
        object.__setattr__(self, "_axis_vec", axis_vector(self.axis_body, "axis_body"))
        object.__setattr__(self, "initial", _law_or_quaternion(self.initial, "initial"))
        object.__setattr__(self, "epoch", check_epoch(self.epoch))

    def angles(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        """Spin angle ``phase + rate t`` at ``times`` [degree].

        Examples
        --------
        >>> Spin(rate=2.0).angles([0.0, 0.5, 10.0])
        array([ 0.,  1., 20.])
        """
        return self.phase + self.rate * seconds_since(times, self.epoch, context)

    def quaternions(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        ang = np.radians(self.angles(times, context))
        spin = Rotation.from_rotvec(ang[:, None] * self._axis_vec[None, :])
        q0 = self.initial.quaternions(times, context)
        return (Rotation.from_quat(q0) * spin).as_quat().reshape(-1, 4)


@dataclass(frozen=True)
class Composed(AttitudeLaw):
    """``R(t) = R_outer(t) R_inner(t)``: the inner law expressed in the outer law's frame.

    Examples
    --------
    >>> s = float(np.sqrt(0.5))
    >>> law = Composed(Inertial((0.0, 0.0, s, s)), Spin(rate=90.0))
    >>> np.round(law.quaternions([1.0]), 6)  # 90 degree then 90 degree about z
    array([[0., 0., 1., 0.]])
    """

    law_name: ClassVar[str] = "compose"
    law_parameters: ClassVar[tuple[str, ...]] = ("outer", "inner")

    outer: AttitudeLaw
    inner: AttitudeLaw

    def __post_init__(self) -> None:
        for name in ("outer", "inner"):
            if not isinstance(getattr(self, name), AttitudeLaw):
                raise AttitudeError(
                    f"compose {name}: expected an attitude law, "
                    f"got {type(getattr(self, name)).__name__}"
                )

    def quaternions(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        a = Rotation.from_quat(self.outer.quaternions(times, context))
        b = Rotation.from_quat(self.inner.quaternions(times, context))
        return (a * b).as_quat().reshape(-1, 4)

    @classmethod
    def from_table(cls, params: dict[str, Any]) -> AttitudeLaw:
        """:func:`compose` of the table's ``outer`` and ``inner`` (laws, quaternions or
        tables).

        Examples
        --------
        >>> law = Composed.from_table({"outer": [0.0, 0.0, 1.0, 0.0], "inner": {"law": "spin"}})
        >>> type(law.outer).__name__, type(law.inner).__name__
        ('Inertial', 'Spin')
        """
        missing = [k for k in ("outer", "inner") if k not in params]
        if missing:
            raise AttitudeError(f"attitude law 'compose': needs {missing}")
        return compose(params["outer"], params["inner"])


def _law_or_quaternion(value: Any, name: str) -> AttitudeLaw:
    if isinstance(value, AttitudeLaw):
        return value
    if isinstance(value, Mapping):
        return law_from_dict(value)
    return Inertial(value)


def compose(outer: AttitudeLaw | ArrayLike, inner: AttitudeLaw | ArrayLike) -> Composed:
    """Compose two laws (or a law and a fixed quaternion): ``R_outer(t) R_inner(t)``.

    Examples
    --------
    >>> s = float(np.sqrt(0.5))
    >>> law = compose([0.0, 0.0, s, s], Spin(rate=90.0))
    >>> type(law).__name__, np.round(law.quaternions([1.0]), 6)
    ('Composed', array([[0., 0., 1., 0.]]))
    """
    return Composed(_law_or_quaternion(outer, "outer"), _law_or_quaternion(inner, "inner"))


def law_from_dict(table: Mapping[str, Any]) -> AttitudeLaw:
    """Build a law from a TOML table such as ``[observation.attitude]``.

    ``law`` names the law (a key of :data:`ATTITUDE_LAWS`); the other keys are its parameters.
    ``spin.initial`` and ``compose.outer``/``inner`` may be nested tables; a
    ``quaternion_series`` reads ``path`` (``.csv`` or ``.nc``).  Example::

        [observation.attitude]
        law = "spin"
        axis_body = "+z"
        rate_deg_s = 3.0
        initial = {law = "nadir", yaw_deg = 10.0}

    Raises
    ------
    AttitudeError
        For an unknown law or parameter, or bad parameter values.

    Examples
    --------
    >>> law = law_from_dict({"law": "spin", "axis_body": "+x", "rate_deg_s": 6.0})
    >>> law
    Spin(axis_body='+x', rate=6.0, phase=0.0,
         initial=Inertial(q=(0.0, 0.0, 0.0, 1.0)), epoch=None)
    >>> law_from_dict({"law": "wobble"})
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.AttitudeError: attitude: unknown law 'wobble'; allowed laws: ..., compose, ...
    """
    if not isinstance(table, Mapping) or "law" not in table:
        raise AttitudeError(
            "attitude: expected a table with a 'law' key "
            f"(one of {', '.join(sorted(ATTITUDE_LAWS))}), "
            f"got {table!r}"
        )
    name = table["law"]
    if name not in ATTITUDE_LAWS:
        raise AttitudeError(
            f"attitude: unknown law {name!r}; {did_you_mean(name, ATTITUDE_LAWS, 'allowed laws')}"
        )
    cls, allowed = ATTITUDE_LAWS[name]
    params = {k: v for k, v in table.items() if k != "law"}
    bad = sorted(set(params) - set(allowed))
    if bad:
        raise AttitudeError(
            f"attitude law {name!r}: unknown parameter(s) {bad}; "
            + did_you_mean(bad[0], allowed, "allowed parameters")
        )
    return cls.from_table(params)


#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(__name__, globals(), {"LAWS": "ATTITUDE_LAWS"})
