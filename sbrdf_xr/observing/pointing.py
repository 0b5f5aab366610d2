"""The attitude-law interface and the pointing laws.

:class:`AttitudeLaw` is what every law of :mod:`sbrdf_xr.observing.attitude` is:
``law.quaternions(times, context=None) -> (n, 4)``, scalar-last unit quaternions of the
rotation body -> inertial (GCRS), and ``outer * inner`` composes two laws
(:class:`Composed`).  The pointing laws hold a body axis on a direction: fixed in the
inertial frame (:class:`Inertial`), on the nadir with another axis along the velocity
(:class:`Nadir`), or on the Sun with a second axis toward a target
(:class:`SunPointing`); the last two read the orbit from a
:class:`~sbrdf_xr.observing.frames.Context`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from ..errors import AttitudeError
from ..units import to_unit
from .frames import (
    Context,
    axis_vector,
    check_quaternion,
    context_fields,
    perpendicular_pair,
    triad,
)

__all__ = ["AttitudeLaw", "Composed", "Inertial", "Nadir", "SunPointing"]


class AttitudeLaw:
    """Base of the attitude laws: ``law.quaternions(times, context) -> (n, 4)``.

    ``outer * inner`` composes two laws (:class:`Composed`).

    Examples
    --------
    >>> from sbrdf_xr.observing.attitude import Spin
    >>> law = Spin(axis_body="+z", rate_deg_s=90.0)
    >>> isinstance(law, AttitudeLaw), law.quaternions([0.0, 1.0]).shape
    (True, (2, 4))
    """

    def quaternions(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        """Attitudes (body -> inertial, scalar-last) at ``times``; shape ``(n, 4)``.

        Examples
        --------
        >>> from sbrdf_xr.observing.attitude import Spin
        >>> np.round(Spin(rate_deg_s=180.0).quaternions([0.0, 1.0]), 6)  # half a turn in 1 s
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

    q: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)

    def __post_init__(self) -> None:
        object.__setattr__(self, "q", tuple(check_quaternion(self.q, "inertial q").tolist()))

    def quaternions(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        n = np.atleast_1d(np.asarray(times)).shape[0]
        return np.tile(np.asarray(self.q), (n, 1))


@dataclass(frozen=True)
class Nadir(AttitudeLaw):
    """Nadir pointing in the local-vertical local-horizontal (LVLH) frame, with a yaw.

    At yaw 0 the body ``nadir_axis`` points from the spacecraft to the Earth's centre
    (``-r/|r|``) and ``velocity_axis`` along the along-track direction (the part of
    the velocity perpendicular to ``r``).  The yaw then turns the body about the nadir
    axis by ``yaw_deg`` (right-handed about ``nadir_axis``), so the nadir axis stays on
    the geocentre.

    Parameters
    ----------
    yaw_deg : float
        Yaw about the nadir axis [degree].
    nadir_axis, velocity_axis : str or array_like
        Perpendicular body axes (``"+z"``, ``"-x"``, ... or 3 components).

    Examples
    --------
    >>> from scipy.spatial.transform import Rotation
    >>> from sbrdf_xr.observing.frames import Context
    >>> ctx = Context(position_km=np.array([[7000.0, 0.0, 0.0]]),
    ...               velocity_km_s=np.array([[0.0, 7.5, 0.0]]))
    >>> q = Nadir(nadir_axis="+z", velocity_axis="+x").quaternions([0.0], ctx)
    >>> np.round(Rotation.from_quat(q).apply([0.0, 0.0, 1.0]), 6) + 0.0  # +z on the geocentre
    array([[-1.,  0.,  0.]])
    """

    yaw_deg: float = 0.0
    nadir_axis: Any = "+z"
    velocity_axis: Any = "+x"
    _axes: tuple[np.ndarray, np.ndarray] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "yaw_deg", to_unit(self.yaw_deg, "deg", "yaw_deg"))
        if not np.isfinite(self.yaw_deg):
            raise AttitudeError(f"nadir yaw_deg: must be finite, got {self.yaw_deg}")
        a, b = perpendicular_pair(
            axis_vector(self.nadir_axis, "nadir_axis"),
            axis_vector(self.velocity_axis, "velocity_axis"),
            "nadir",
        )
        object.__setattr__(self, "_axes", (a, b))

    def quaternions(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        n = np.atleast_1d(np.asarray(times)).shape[0]
        r, v = context_fields(context, n, "nadir", "position_km", "velocity_km_s")
        a, b = self._axes
        q = triad(a, b, -r, v)
        if self.yaw_deg:
            yaw = Rotation.from_rotvec(np.radians(self.yaw_deg) * a)
            q = (Rotation.from_quat(q) * yaw).as_quat().reshape(-1, 4)
        return q


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
    >>> from sbrdf_xr.observing.frames import Context
    >>> ctx = Context(position_km=np.array([[7000.0, 0.0, 0.0]]),
    ...               velocity_km_s=np.array([[0.0, 7.5, 0.0]]),
    ...               sun_km=np.array([[0.0, 1.5e8, 0.0]]))
    >>> q = SunPointing(axis="+z", secondary_axis="+x").quaternions([0.0], ctx)
    >>> R = Rotation.from_quat(q)
    >>> np.round(R.apply([0.0, 0.0, 1.0]), 6) + 0.0, np.round(R.apply([1.0, 0.0, 0.0]), 6) + 0.0
    (array([[0., 1., 0.]]), array([[0., 0., 1.]]))
    """

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
        (sun,) = context_fields(context, n, "sun_pointing", "sun_km")
        if isinstance(tgt, str) and tgt != "north":
            r, v = context_fields(context, n, "sun_pointing", "position_km", "velocity_km_s")
            target = {"orbit_normal": np.cross(r, v), "nadir": -r, "velocity": v}[tgt]
        else:
            target = np.tile([0.0, 0.0, 1.0] if isinstance(tgt, str) else tgt, (n, 1))
        return triad(a, b, sun, target)


@dataclass(frozen=True)
class Composed(AttitudeLaw):
    """``R(t) = R_outer(t) R_inner(t)``: the inner law expressed in the outer law's frame.

    Examples
    --------
    >>> from sbrdf_xr.observing.attitude import Spin
    >>> s = float(np.sqrt(0.5))
    >>> law = Composed(Inertial((0.0, 0.0, s, s)), Spin(rate_deg_s=90.0))
    >>> np.round(law.quaternions([1.0]), 6)  # 90 degree then 90 degree about z
    array([[0., 0., 1., 0.]])
    """

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
