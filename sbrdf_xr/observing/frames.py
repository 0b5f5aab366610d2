"""Frames and times shared by the attitude laws of :mod:`sbrdf_xr.observing.attitude`.

:func:`triad` (the rotation that aligns two body axes with two reference directions),
the orbital :class:`Context` a law is evaluated in, and the checks of axes,
quaternions and times.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from ..errors import AttitudeError, ValidationError, renamed_fields
from ..geometry import check_quaternions
from ..units import to_unit

#: Body axes by name.
_AXES = {
    "x": (1.0, 0.0, 0.0),
    "y": (0.0, 1.0, 0.0),
    "z": (0.0, 0.0, 1.0),
}


NS_PER_S = 1e9


def axis_vector(spec: str | ArrayLike, name: str) -> NDArray[np.float64]:
    """A unit vector from ``"+x"``, ``"-z"``, ``"y"`` or three components.

    Examples
    --------
    >>> axis_vector("-z", "axis") + 0.0, axis_vector([3.0, 0.0, 4.0], "axis")
    (array([ 0.,  0., -1.]), array([0.6, 0. , 0.8]))
    >>> axis_vector("+w", "axis")
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.AttitudeError: axis: got '+w'; allowed: +x, -x, +y, -y, +z, -z or 3 components
    """
    if isinstance(spec, str):
        s = spec.strip().lower()
        sign = -1.0 if s.startswith("-") else 1.0
        key = s.lstrip("+-")
        if key not in _AXES:
            raise AttitudeError(
                f"{name}: got {spec!r}; allowed: +x, -x, +y, -y, +z, -z or 3 components"
            )
        return sign * np.asarray(_AXES[key])
    try:
        v = np.asarray(spec, dtype=np.float64)
    except (TypeError, ValueError):
        raise AttitudeError(f"{name}: got {spec!r}; expected an axis name or 3 numbers") from None
    n = np.linalg.norm(v) if v.shape == (3,) else 0.0
    if v.shape != (3,) or not np.all(np.isfinite(v)) or n == 0:
        raise AttitudeError(f"{name}: got {spec!r}; expected 3 finite components, not all zero")
    return v / n


def check_quaternion(q: ArrayLike, name: str) -> NDArray[np.float64]:
    """One unit quaternion (scalar-last), normalised; :class:`AttitudeError` naming ``name``.

    Examples
    --------
    >>> check_quaternion([0, 0, 0, 1], "initial")
    array([0., 0., 0., 1.])
    >>> check_quaternion([0.0, 0.0, 0.0, 2.0], "initial")
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.AttitudeError: initial: quaternion: [0.0, 0.0, 0.0, 2.0] at index [] has ...
    >>> check_quaternion([[0.0, 0.0, 0.0, 1.0]] * 2, "initial")
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.AttitudeError: initial: expected one quaternion of 4 components, got shape ...
    """
    try:
        arr = check_quaternions(q)
    except ValidationError as exc:
        raise AttitudeError(f"{name}: {exc}") from None
    if arr.shape != (4,):
        raise AttitudeError(
            f"{name}: expected one quaternion of 4 components, got shape {arr.shape}"
        )
    return arr


def _unit_rows(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def triad(
    body_primary: ArrayLike,
    body_secondary: ArrayLike,
    ref_primary: ArrayLike,
    ref_secondary: ArrayLike,
) -> NDArray[np.float64]:
    """Rotations taking a body primary axis onto a reference direction (TRIAD).

    ``R b1 = r1`` exactly, and ``R b2`` is the unit vector nearest ``r2`` that is
    perpendicular to ``r1`` (Black 1964, the TRIAD algorithm).

    Parameters
    ----------
    body_primary, body_secondary : array_like, shape (3,)
        Perpendicular body axes [1].
    ref_primary, ref_secondary : array_like, shape (n, 3)
        Reference-frame directions [1]; ``ref_secondary`` must not be parallel to
        ``ref_primary``.

    Returns
    -------
    ndarray, shape (n, 4)
        Scalar-last unit quaternions, body -> reference.

    Examples
    --------
    >>> from scipy.spatial.transform import Rotation
    >>> q = triad([0, 0, 1], [1, 0, 0], [[0.0, -1.0, 0.0]], [[1.0, 0.0, 0.0]])
    >>> R = Rotation.from_quat(q)
    >>> np.round(R.apply([0.0, 0.0, 1.0]), 6) + 0.0, np.round(R.apply([1.0, 0.0, 0.0]), 6) + 0.0
    (array([[ 0., -1.,  0.]]), array([[1., 0., 0.]]))
    """
    b1 = np.asarray(body_primary, float)
    b2 = np.asarray(body_secondary, float)
    r1 = _unit_rows(np.atleast_2d(np.asarray(ref_primary, float)))
    r2 = np.atleast_2d(np.asarray(ref_secondary, float))
    r2 = r2 - np.einsum("ni,ni->n", r2, r1)[:, None] * r1
    norm = np.linalg.norm(r2, axis=-1)
    bad = np.flatnonzero(norm < 1e-9 * np.linalg.norm(np.atleast_2d(ref_secondary), axis=-1).max())
    if bad.size:
        raise AttitudeError(
            f"secondary direction parallel to the primary direction at time index {int(bad[0])}; "
            "choose another secondary target"
        )
    r2 = r2 / norm[:, None]
    m_body = np.stack([b1, b2, np.cross(b1, b2)], axis=-1)  # columns
    m_ref = np.stack([r1, r2, np.cross(r1, r2)], axis=-1)  # (n, 3, 3) columns
    return Rotation.from_matrix(m_ref @ m_body.T).as_quat().reshape(-1, 4)


def perpendicular_pair(
    primary: np.ndarray, secondary: np.ndarray, names: str
) -> tuple[np.ndarray, np.ndarray]:
    """Two body axes, checked to be perpendicular (``names`` labels the error).

    Examples
    --------
    >>> perpendicular_pair(np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]), "nadir")
    (array([0., 0., 1.]), array([1., 0., 0.]))
    >>> perpendicular_pair(np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.6, 0.8]), "nadir")
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.AttitudeError: nadir: the two body axes must be perpendicular, got [0.0, ...
    """
    a, b = primary, secondary
    if abs(float(np.dot(a, b))) > 1e-9:
        raise AttitudeError(
            f"{names}: the two body axes must be perpendicular, got {a.tolist()} and {b.tolist()}"
        )
    return a, b


@renamed_fields(position_km="position", velocity_km_s="velocity", sun_km="sun")
@dataclass(frozen=True)
class Context:
    """What orbit-following laws need: the spacecraft's state and the Sun, per time.

    Parameters
    ----------
    epoch : numpy.datetime64
        Time origin of float times (UTC).
    position : array_like, shape (n, 3)
        Geocentric position of the spacecraft in the inertial frame [km].
    velocity : array_like, shape (n, 3)
        Its velocity [km s-1].
    sun : array_like, shape (n, 3)
        Position of the Sun relative to the spacecraft [km].

    A Quantity is converted to the unit of its field.

    Examples
    --------
    >>> ctx = Context(epoch=np.datetime64("2024-03-17T01:20:00", "ns"),
    ...               position=np.array([[7000.0, 0.0, 0.0]]),
    ...               velocity=np.array([[0.0, 7.5, 0.0]]))
    >>> ctx.sun is None, ctx.position.shape
    (True, (1, 3))
    """

    epoch: np.datetime64 | None = None
    position: NDArray[np.float64] | None = None
    velocity: NDArray[np.float64] | None = None
    sun: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        for name, unit in (("position", "km"), ("velocity", "km / s"), ("sun", "km")):
            object.__setattr__(self, name, to_unit(getattr(self, name), unit, name))


def seconds_since(
    times: ArrayLike, epoch: np.datetime64 | None, context: Context | None
) -> NDArray[np.float64]:
    """Float seconds of ``times`` from the law's epoch (see the module docstring).

    Examples
    --------
    >>> t = np.array(["2024-03-17T01:20:00", "2024-03-17T01:20:30"], dtype="datetime64[ns]")
    >>> seconds_since(t, np.datetime64("2024-03-17T01:19:00", "ns"), None)
    array([60., 90.])
    >>> seconds_since(t, None, None)  # no epoch: from the first time
    array([ 0., 30.])
    """
    t = np.atleast_1d(np.asarray(times))
    if t.ndim != 1:
        raise AttitudeError(f"times: expected a 1-D array, got shape {t.shape}")
    if np.issubdtype(t.dtype, np.datetime64):
        t = t.astype("datetime64[ns]")
        origin = (
            epoch
            if epoch is not None
            else (context.epoch if context is not None and context.epoch is not None else t[0])
        )
        return (t - np.asarray(origin, dtype="datetime64[ns]")).astype(np.int64) / NS_PER_S
    if not np.issubdtype(t.dtype, np.number):
        raise AttitudeError(f"times: expected datetime64 or seconds, got dtype {t.dtype}")
    t = t.astype(np.float64)
    if epoch is not None and context is not None and context.epoch is not None:
        t = (
            t
            + (
                np.asarray(context.epoch, dtype="datetime64[ns]")
                - np.asarray(epoch, dtype="datetime64[ns]")
            ).astype(np.int64)
            / NS_PER_S
        )
    return t


def context_fields(context: Context | None, n: int, law: str, *fields: str) -> list[np.ndarray]:
    """The context arrays ``fields``, each checked to be of shape (n, 3); ``law`` labels the error.

    Examples
    --------
    >>> ctx = Context(position=np.array([[7000.0, 0.0, 0.0]]),
    ...               velocity=np.array([[0.0, 7.5, 0.0]]))
    >>> r, v = context_fields(ctx, 1, "nadir", "position", "velocity")
    >>> r.tolist(), v.tolist()
    ([[7000.0, 0.0, 0.0]], [[0.0, 7.5, 0.0]])
    >>> context_fields(ctx, 1, "sun_pointing", "sun")
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.AttitudeError: sun_pointing: the context lacks sun
    """
    if context is None:
        raise AttitudeError(
            f"{law}: needs an orbit context ({', '.join(fields)}); use it inside an Observation"
        )
    out = []
    for f in fields:
        v = getattr(context, f)
        if v is None:
            raise AttitudeError(f"{law}: the context lacks {f}")
        v = np.asarray(v, dtype=np.float64)
        if v.shape != (n, 3):
            raise AttitudeError(f"{law}: context {f} has shape {v.shape}, expected ({n}, 3)")
        out.append(v)
    return out


def check_epoch(epoch: Any) -> np.datetime64 | None:
    """The epoch of a law as datetime64[ns] UTC, or None.

    Examples
    --------
    >>> check_epoch("2024-03-17T01:20:00"), check_epoch(None)
    (np.datetime64('2024-03-17T01:20:00.000000000'), None)
    """
    if epoch is None:
        return None
    try:
        return np.datetime64(epoch, "ns")
    except (TypeError, ValueError):
        raise AttitudeError(
            f"epoch: got {epoch!r}; expected a UTC time (ISO 8601 or datetime64)"
        ) from None
