"""Attitude laws: the orientation of a spacecraft as a function of time.

Every law is an object with ``quaternions(times, context=None) -> (n, 4)``: unit
quaternions, scalar-last ``(x, y, z, w)``, of the rotation that takes body-frame
vectors to the inertial reference frame (the convention of :mod:`sbrdf_xr.geometry`).
The inertial frame of :mod:`sbrdf_xr.observe` is the GCRS (geocentric, ICRF axes).

Times are either ``datetime64`` (UTC) or float seconds.  Float seconds count from the
law's ``epoch``; a law without an ``epoch`` counts from ``context.epoch`` (the start of
the observation), or from the first requested time.  Laws that follow the orbit
(:class:`Nadir`, :class:`SunPointing`) need a :class:`Context` with the spacecraft's
position and velocity and the direction of the Sun at the requested times.

Laws
----
==================  ========================================================================
Inertial(q)         fixed orientation
Nadir               LVLH: a body axis on the nadir, another toward the velocity, then a yaw
SunPointing         a body axis on the Sun, a second body axis as close as possible to a
                    target direction (orbit normal, nadir, velocity, north or a vector)
Spin                rotation about a body axis at a constant rate from an initial attitude
                    (a quaternion or another law)
Tumble              torque-free rigid body: Euler's equations for an inertia tensor
                    (given, or :meth:`Spacecraft.inertia` at uniform density), integrated
                    with :func:`scipy.integrate.solve_ivp` (DOP853, rtol 1e-12)
QuaternionSeries    a user time series (arrays, CSV or netCDF), slerp-interpolated
Composed            ``outer * inner``: ``R(t) = R_outer(t) R_inner(t)``
==================  ========================================================================

:func:`law_from_dict` builds a law from a TOML table (``[observation.attitude]``).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation, Slerp

from .attitude_frames import (
    NS_PER_S,
    Context,
    axis_vector,
    check_epoch,
    check_quaternion,
    context_fields,
    perpendicular_pair,
    seconds_since,
    triad,
)
from .errors import AttitudeError
from .geometry import check_quaternions

__all__ = [
    "LAWS",
    "AttitudeLaw",
    "Composed",
    "Context",
    "Inertial",
    "Nadir",
    "QuaternionSeries",
    "Spin",
    "SunPointing",
    "Tumble",
    "compose",
    "law_from_dict",
    "triad",
]

#: Relative tolerance of the tumble integration (scipy ``solve_ivp``, DOP853).
TUMBLE_RTOL = 1e-12


# --------------------------------------------------------------------------- helpers


# --------------------------------------------------------------------------- laws


class AttitudeLaw:
    """Base of the attitude laws: ``law.quaternions(times, context) -> (n, 4)``.

    ``outer * inner`` composes two laws (:class:`Composed`).

    Examples
    --------
    >>> law = Spin(axis_body="+z", rate_deg_s=90.0)
    >>> isinstance(law, AttitudeLaw), law.quaternions([0.0, 1.0]).shape
    (True, (2, 4))
    """

    def quaternions(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        """Attitudes (body -> inertial, scalar-last) at ``times``; shape ``(n, 4)``.

        Examples
        --------
        >>> np.round(Spin(rate_deg_s=180.0).quaternions([0.0, 1.0]), 6)  # half a turn in 1 s
        array([[0., 0., 0., 1.],
               [0., 0., 1., 0.]])
        """
        raise NotImplementedError

    def __mul__(self, other: AttitudeLaw) -> Composed:
        if not isinstance(other, AttitudeLaw):
            return NotImplemented
        return Composed(self, other)


def _law_or_quaternion(value: Any, name: str) -> AttitudeLaw:
    if isinstance(value, AttitudeLaw):
        return value
    if isinstance(value, Mapping):
        return law_from_dict(value)
    return Inertial(value)


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
    >>> from sbrdf_xr.attitude_frames import Context
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
    >>> from sbrdf_xr.attitude_frames import Context
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
class Spin(AttitudeLaw):
    """Rotation about a body axis at a constant rate, after an initial attitude.

    ``R(t) = R_initial(t) R_axis(phase + rate t)``: the body turns about its own
    ``axis_body`` (right-handed) by the angle ``phase_deg + rate_deg_s * t``, starting
    from ``initial`` (a quaternion: the attitude at angle 0; or a law, e.g. :class:`Nadir`
    for a nadir-pointer spinning about its nadir axis).  With an inertial ``initial`` this
    equals :func:`sbrdf_xr.geometry.rotation_sweep` about the inertial axis
    ``R_initial axis_body``.

    Parameters
    ----------
    axis_body : str or array_like
        Spin axis in the body frame.
    rate_deg_s : float
        Spin rate [degree s-1].
    phase_deg : float
        Angle at the epoch [degree].
    initial : quaternion, law or table
        Attitude at angle 0 (default: identity).
    epoch : datetime64 or str, optional
        Time of ``phase_deg`` (default: the start of the observation).

    Examples
    --------
    >>> spin = Spin(axis_body="+z", rate_deg_s=10.0, phase_deg=5.0)
    >>> spin.angles([0.0, 1.0, 2.0])  # [degree]
    array([ 5., 15., 25.])
    >>> np.round(spin.quaternions([0.0]), 6)
    array([[0.      , 0.      , 0.043619, 0.999048]])
    """

    axis_body: Any = "+z"
    rate_deg_s: float = 1.0
    phase_deg: float = 0.0
    initial: Any = (0.0, 0.0, 0.0, 1.0)
    epoch: Any = None
    _axis_vec: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        for name in ("rate_deg_s", "phase_deg"):
            val = getattr(self, name)
            if not isinstance(val, int | float | np.floating | np.integer) or not np.isfinite(val):
                raise AttitudeError(f"spin {name}: must be a finite number [degree], got {val!r}")
        object.__setattr__(self, "_axis_vec", axis_vector(self.axis_body, "axis_body"))
        object.__setattr__(self, "initial", _law_or_quaternion(self.initial, "initial"))
        object.__setattr__(self, "epoch", check_epoch(self.epoch))

    def angles(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        """Spin angle ``phase + rate t`` at ``times`` [degree].

        Examples
        --------
        >>> Spin(rate_deg_s=2.0).angles([0.0, 0.5, 10.0])
        array([ 0.,  1., 20.])
        """
        return self.phase_deg + self.rate_deg_s * seconds_since(times, self.epoch, context)

    def quaternions(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        ang = np.radians(self.angles(times, context))
        spin = Rotation.from_rotvec(ang[:, None] * self._axis_vec[None, :])
        q0 = self.initial.quaternions(times, context)
        return (Rotation.from_quat(q0) * spin).as_quat().reshape(-1, 4)


def _inertia(value: ArrayLike) -> NDArray[np.float64]:
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise AttitudeError(
            f"tumble inertia: got {value!r}; expected 3 principal moments or a 3x3 tensor"
        ) from None
    if arr.shape == (3,):
        arr = np.diag(arr)
    if arr.shape != (3, 3) or not np.all(np.isfinite(arr)):
        raise AttitudeError(
            "tumble inertia: expected 3 principal moments or a finite 3x3 tensor [kg m2], "
            f"got shape {arr.shape}"
        )
    if not np.allclose(arr, arr.T, rtol=1e-9, atol=1e-12 * np.abs(arr).max()):
        raise AttitudeError("tumble inertia: the tensor must be symmetric")
    moments = np.linalg.eigvalsh(arr)
    if moments[0] <= 0:
        raise AttitudeError(
            f"tumble inertia: principal moments must be positive, got {moments.tolist()}"
        )
    if moments[0] + moments[1] < moments[2] * (1 - 1e-9):
        raise AttitudeError(
            f"tumble inertia: principal moments {moments.tolist()} break the triangle inequality "
            "I1 + I2 >= I3 of a physical body"
        )
    return 0.5 * (arr + arr.T)


@dataclass(frozen=True)
class Tumble(AttitudeLaw):
    """Torque-free rigid-body motion (Euler's equations).

    ``I dω/dt = -ω x (I ω)`` for the body angular velocity ``ω``, with the attitude
    kinematics ``dq/dt = ½ q ⊗ (ω, 0)`` (body -> inertial, scalar-last; Markley & Crassidis,
    *Fundamentals of Spacecraft Attitude Determination and Control*, 2014, eqs. 3.20 and
    3.81), integrated from the epoch forward and backward with
    :func:`scipy.integrate.solve_ivp` (DOP853, ``rtol`` = :data:`TUMBLE_RTOL`).  Kinetic
    energy ``½ ω·Iω`` and the inertial angular momentum ``R I ω`` are invariants of the
    exact motion; :meth:`states` lets one check them.

    Parameters
    ----------
    inertia : array_like, shape (3,) or (3, 3)
        Inertia tensor about the centre of mass in the body frame [kg m2] (or its
        principal moments), e.g. :meth:`sbrdf_xr.spacecraft.Spacecraft.inertia`.
    omega_deg_s : array_like, shape (3,)
        Body angular velocity at the epoch [degree s-1].
    initial : array_like, shape (4,)
        Attitude at the epoch.
    epoch : datetime64 or str, optional
        Time of the initial state (default: the start of the observation).

    Examples
    --------
    >>> law = Tumble(inertia=(1.0, 2.0, 3.0), omega_deg_s=(0.0, 0.0, 10.0))  # a principal axis
    >>> omega, q = law.states([0.0, 9.0])
    >>> np.round(np.degrees(omega), 9) + 0.0  # steady spin about z [degree s-1]
    array([[ 0.,  0., 10.],
           [ 0.,  0., 10.]])
    >>> np.round(q[-1], 9)  # 90 degree about z after 9 s
    array([0.        , 0.        , 0.70710678, 0.70710678])
    """

    inertia: Any = (1.0, 1.0, 1.0)
    omega_deg_s: Any = (0.0, 0.0, 1.0)
    initial: Any = (0.0, 0.0, 0.0, 1.0)
    epoch: Any = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "inertia", _inertia(self.inertia))
        w = np.asarray(self.omega_deg_s, dtype=np.float64)
        if w.shape != (3,) or not np.all(np.isfinite(w)):
            raise AttitudeError(
                "tumble omega_deg_s: expected 3 finite body rates [degree s-1], "
                f"got {self.omega_deg_s!r}"
            )
        object.__setattr__(self, "omega_deg_s", w)
        object.__setattr__(self, "initial", check_quaternion(self.initial, "tumble initial"))
        object.__setattr__(self, "epoch", check_epoch(self.epoch))

    @classmethod
    def from_spacecraft(
        cls,
        spacecraft: Any,
        density_kg_m3: float,
        omega_deg_s: ArrayLike,
        initial: ArrayLike = (0.0, 0.0, 0.0, 1.0),
        epoch: Any = None,
    ) -> Tumble:
        """A tumble of a spacecraft filled at uniform density (``spacecraft.inertia``).

        Parameters
        ----------
        spacecraft : sbrdf_xr.spacecraft.Spacecraft
            The body (a closed mesh).
        density_kg_m3 : float
            Uniform density [kg m-3].
        omega_deg_s, initial, epoch
            As for :class:`Tumble`.

        Examples
        --------
        >>> import trimesh
        >>> from sbrdf_xr.spacecraft import Spacecraft
        >>> cube = Spacecraft(trimesh.creation.box(extents=(0.1, 0.1, 0.1)), ["paint"] * 12)
        >>> law = Tumble.from_spacecraft(cube, 1000.0, (5.0, 0.0, 0.0))
        >>> np.round(np.diag(law.inertia), 9)  # a 1 kg cube of side 0.1 m [kg m2]
        array([0.00166667, 0.00166667, 0.00166667])
        """
        return cls(spacecraft.inertia(density_kg_m3), omega_deg_s, initial, epoch)

    def _rhs_function(self):
        """Right-hand side of Euler's equations and the kinematics, on plain floats (fast)."""
        (a, b, c), (d, e, f), (g, h, k) = self.inertia.tolist()
        (ia, ib, ic), (id_, ie, if_), (ig, ih, ik) = np.linalg.inv(self.inertia).tolist()

        def rhs(t: float, y: np.ndarray) -> list[float]:
            wx, wy, wz, x, yq, z, s = y.tolist()
            lx, ly, lz = (
                a * wx + b * wy + c * wz,
                d * wx + e * wy + f * wz,
                g * wx + h * wy + k * wz,
            )
            # I dw/dt = -w x (I w) = (I w) x w
            tx, ty, tz = ly * wz - lz * wy, lz * wx - lx * wz, lx * wy - ly * wx
            return [
                ia * tx + ib * ty + ic * tz,
                id_ * tx + ie * ty + if_ * tz,
                ig * tx + ih * ty + ik * tz,
                # dq/dt = 1/2 q (x) (w, 0), scalar-last Hamilton product.
                0.5 * (s * wx + yq * wz - z * wy),
                0.5 * (s * wy + z * wx - x * wz),
                0.5 * (s * wz + x * wy - yq * wx),
                -0.5 * (x * wx + yq * wy + z * wz),
            ]

        return rhs

    def states(
        self, times: ArrayLike, context: Context | None = None
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Body angular velocity [rad s-1] and attitude at ``times``.

        Returns
        -------
        omega : ndarray, shape (n, 3)
        quaternion : ndarray, shape (n, 4)

        Examples
        --------
        >>> omega, q = Tumble((1.0, 2.0, 3.0), (10.0, 0.0, 0.0)).states([0.0, 1.0, 2.0])
        >>> omega.shape, q.shape, np.round(np.linalg.norm(q, axis=1), 12)
        ((3, 3), (3, 4), array([1., 1., 1.]))
        """
        from scipy.integrate import solve_ivp

        t = seconds_since(times, self.epoch, context)
        rhs = self._rhs_function()
        y0 = np.concatenate([np.radians(self.omega_deg_s), self.initial])
        out = np.empty((t.size, 7))
        scale = max(float(np.linalg.norm(y0[:3])), 1e-12)
        atol = np.concatenate([np.full(3, 1e-14 * scale), np.full(4, 1e-14)])
        for sel in (t >= 0, t < 0):
            if not sel.any():
                continue
            ts = t[sel]
            order = np.argsort(ts) if ts[0] >= 0 else np.argsort(-ts)
            tq = ts[order]
            if np.all(tq == 0):
                out[np.flatnonzero(sel)] = y0
                continue
            sol = solve_ivp(
                rhs,
                (0.0, float(tq[-1])),
                y0,
                method="DOP853",
                t_eval=tq,
                rtol=TUMBLE_RTOL,
                atol=atol,
            )
            if not sol.success:  # pragma: no cover - smooth right-hand side
                raise AttitudeError(f"tumble: integration failed: {sol.message}")
            idx = np.flatnonzero(sel)[order]
            out[idx] = sol.y.T
        q = out[:, 3:] / np.linalg.norm(out[:, 3:], axis=1, keepdims=True)
        return out[:, :3], q

    def quaternions(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        return self.states(times, context)[1]


@dataclass(frozen=True)
class QuaternionSeries(AttitudeLaw):
    """A user attitude time series, interpolated by slerp (:class:`scipy.spatial.transform.Slerp`).

    Parameters
    ----------
    times : array_like
        Strictly increasing sample times: ``datetime64`` (UTC) or seconds from ``epoch``.
    samples : array_like, shape (n, 4)
        Unit quaternions, scalar-last, body -> inertial.
    epoch : datetime64 or str, optional
        Time origin of float sample times (default: the start of the observation).

    Requests outside the sampled interval raise :class:`AttitudeError`.

    Examples
    --------
    >>> series = QuaternionSeries([0.0, 10.0], [[0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 0.0]])
    >>> np.round(series.quaternions([5.0]), 6)  # halfway: 90 degree about z
    array([[0.      , 0.      , 0.707107, 0.707107]])
    >>> series.quaternions([11.0])
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.AttitudeError: quaternion_series: requested times span [11, 11] s, outside ...
    """

    times: Any
    samples: Any = None
    epoch: Any = None
    _secs: np.ndarray = field(init=False, repr=False, compare=False)
    _slerp: Slerp = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        t = np.atleast_1d(np.asarray(self.times))
        q = check_quaternions(self.samples) if self.samples is not None else None
        if q is None or q.ndim != 2 or q.shape[0] != t.shape[0] or t.ndim != 1 or t.size < 2:
            raise AttitudeError(
                f"quaternion_series: need >= 2 times and as many quaternions (n, 4); got times "
                f"{t.shape} and quaternions {None if q is None else q.shape}"
            )
        epoch = check_epoch(self.epoch)
        if np.issubdtype(t.dtype, np.datetime64):
            t = t.astype("datetime64[ns]")
            epoch = t[0] if epoch is None else epoch
            secs = (t - epoch).astype(np.int64) / NS_PER_S
        else:
            secs = t.astype(np.float64)
        if not np.all(np.diff(secs) > 0):
            raise AttitudeError("quaternion_series: times must be strictly increasing")
        object.__setattr__(self, "epoch", epoch)
        object.__setattr__(self, "_secs", secs)
        object.__setattr__(self, "_slerp", Slerp(secs, Rotation.from_quat(q)))

    @classmethod
    def from_csv(
        cls,
        path: str | Path,
        time_column: str = "time",
        columns: Sequence[str] = ("qx", "qy", "qz", "qw"),
        epoch: Any = None,
    ) -> QuaternionSeries:
        """Read a CSV: a time column (ISO 8601 UTC, or seconds), scalar-last quaternion columns.

        Examples
        --------
        >>> import tempfile
        >>> from pathlib import Path
        >>> path = Path(tempfile.mkdtemp()) / "att.csv"
        >>> rows = ["time,qx,qy,qz,qw", "2024-03-17T01:20:00Z,0,0,0,1",
        ...         "2024-03-17T01:20:10Z,0,0,1,0"]
        >>> _ = path.write_text("\\n".join(rows))
        >>> series = QuaternionSeries.from_csv(path)
        >>> series.epoch
        np.datetime64('2024-03-17T01:20:00.000000000')
        >>> np.round(series.quaternions([5.0]), 6)
        array([[0.      , 0.      , 0.707107, 0.707107]])
        """
        import pandas as pd

        try:
            df = pd.read_csv(path)
        except (OSError, ValueError) as exc:
            raise AttitudeError(f"quaternion_series: cannot read {path}: {exc}") from None
        missing = [c for c in (time_column, *columns) if c not in df.columns]
        if missing:
            raise AttitudeError(
                f"quaternion_series: {path} lacks the columns {missing}; has {list(df.columns)}"
            )
        tcol = df[time_column]
        if pd.api.types.is_numeric_dtype(tcol):
            t = tcol.to_numpy(np.float64)
        else:
            t = pd.to_datetime(tcol, utc=True).dt.tz_localize(None).to_numpy("datetime64[ns]")
        return cls(t, df[list(columns)].to_numpy(np.float64), epoch)

    @classmethod
    def from_netcdf(cls, path: str | Path, variable: str = "quaternion") -> QuaternionSeries:
        """Read ``variable(time, component)`` (components x, y, z, w) from a netCDF file.

        The ``quaternion`` of :meth:`sbrdf_xr.observe.Observation.geometry` reads back.

        Examples
        --------
        >>> import tempfile
        >>> import xarray as xr
        >>> from pathlib import Path
        >>> path = Path(tempfile.mkdtemp()) / "att.nc"
        >>> q = xr.DataArray([[0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 0.0]],
        ...                  dims=("time", "component"),
        ...                  coords={"time": [0.0, 10.0], "component": ["x", "y", "z", "w"]})
        >>> q.to_dataset(name="quaternion").to_netcdf(path)
        >>> np.round(QuaternionSeries.from_netcdf(path).quaternions([5.0]), 6)
        array([[0.      , 0.      , 0.707107, 0.707107]])
        """
        import xarray as xr

        try:
            with xr.open_dataset(path) as ds:
                da = ds[variable].load()
        except (OSError, KeyError, ValueError) as exc:
            raise AttitudeError(
                f"quaternion_series: cannot read {variable!r} from {path}: {exc}"
            ) from None
        if "component" in da.dims:
            da = da.transpose(..., "component").sel(component=["x", "y", "z", "w"])
        return cls(da[da.dims[0]].values, da.values)

    def quaternions(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        t = seconds_since(times, self.epoch, context)
        lo, hi = self._secs[0], self._secs[-1]
        if t.min() < lo or t.max() > hi:
            raise AttitudeError(
                f"quaternion_series: requested times span [{t.min():.6g}, {t.max():.6g}] s, "
                "outside the "
                f"series [{lo:.6g}, {hi:.6g}] s from its epoch {self.epoch}"
            )
        return self._slerp(t).as_quat().reshape(-1, 4)


@dataclass(frozen=True)
class Composed(AttitudeLaw):
    """``R(t) = R_outer(t) R_inner(t)``: the inner law expressed in the outer law's frame.

    Examples
    --------
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


def compose(outer: AttitudeLaw | ArrayLike, inner: AttitudeLaw | ArrayLike) -> Composed:
    """Compose two laws (or a law and a fixed quaternion): ``R_outer(t) R_inner(t)``.

    Examples
    --------
    >>> s = float(np.sqrt(0.5))
    >>> law = compose([0.0, 0.0, s, s], Spin(rate_deg_s=90.0))
    >>> type(law).__name__, np.round(law.quaternions([1.0]), 6)
    ('Composed', array([[0., 0., 1., 0.]]))
    """
    return Composed(_law_or_quaternion(outer, "outer"), _law_or_quaternion(inner, "inner"))


# --------------------------------------------------------------------------- tables

#: Law name -> (class, allowed parameters).
LAWS: dict[str, tuple[type[AttitudeLaw], tuple[str, ...]]] = {
    "inertial": (Inertial, ("q",)),
    "nadir": (Nadir, ("yaw_deg", "nadir_axis", "velocity_axis")),
    "sun_pointing": (SunPointing, ("axis", "secondary_axis", "secondary_target")),
    "spin": (Spin, ("axis_body", "rate_deg_s", "phase_deg", "initial", "epoch")),
    "tumble": (Tumble, ("inertia", "omega_deg_s", "initial", "epoch")),
    "quaternion_series": (
        QuaternionSeries,
        ("path", "time_column", "columns", "variable", "epoch"),
    ),
    "compose": (Composed, ("outer", "inner")),
}


def law_from_dict(table: Mapping[str, Any]) -> AttitudeLaw:
    """Build a law from a TOML table such as ``[observation.attitude]``.

    ``law`` names the law (a key of :data:`LAWS`); the other keys are its parameters.
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
    Spin(axis_body='+x', rate_deg_s=6.0, phase_deg=0.0,
         initial=Inertial(q=(0.0, 0.0, 0.0, 1.0)), epoch=None)
    >>> law_from_dict({"law": "wobble"})
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.AttitudeError: attitude: unknown law 'wobble'; allowed: inertial, nadir, ...
    """
    if not isinstance(table, Mapping) or "law" not in table:
        raise AttitudeError(
            f"attitude: expected a table with a 'law' key (one of {', '.join(LAWS)}), got {table!r}"
        )
    name = table["law"]
    if name not in LAWS:
        raise AttitudeError(f"attitude: unknown law {name!r}; allowed: {', '.join(LAWS)}")
    cls, allowed = LAWS[name]
    params = {k: v for k, v in table.items() if k != "law"}
    bad = sorted(set(params) - set(allowed))
    if bad:
        raise AttitudeError(
            f"attitude law {name!r}: unknown parameter(s) {bad}; allowed: {', '.join(allowed)}"
        )
    if name == "compose":
        missing = [k for k in ("outer", "inner") if k not in params]
        if missing:
            raise AttitudeError(f"attitude law 'compose': needs {missing}")
        return compose(params["outer"], params["inner"])
    if name == "quaternion_series":
        if "path" not in params:
            raise AttitudeError("attitude law 'quaternion_series': needs a path (.csv or .nc)")
        path = Path(params.pop("path"))
        if path.suffix.lower() == ".csv":
            kw: dict[str, Any] = {k: params[k] for k in ("time_column", "epoch") if k in params}
            if "columns" in params:
                kw["columns"] = tuple(params["columns"])
            return QuaternionSeries.from_csv(path, **kw)
        return QuaternionSeries.from_netcdf(
            path, **({"variable": params["variable"]} if "variable" in params else {})
        )
    try:
        return cls(**params)
    except TypeError as exc:
        raise AttitudeError(f"attitude law {name!r}: {exc}") from None
