"""Attitudes of a body as unit quaternions: validation, rotation matrices, sweeps.

Pure, vectorised numpy over :class:`scipy.spatial.transform.Rotation`.

An attitude is the rotation ``R`` that takes body-frame vectors to the reference
(inertial / laboratory) frame, stored as a unit quaternion in scalar-last order
``(x, y, z, w)``, the convention of :class:`scipy.spatial.transform.Rotation`.  Sun and
observer directions given in the reference frame reach the body frame as ``R^T v``
(:func:`to_body_frame`).  The names here are also importable from
:mod:`sbrdf_xr.geometry`.

Arguments with a unit (angles [degree]) also take an astropy Quantity, converted first
(:func:`sbrdf_xr.units.to_unit`; another kind raises :class:`~sbrdf_xr.errors.UnitError`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from ..errors import ValidationError, renamed_attributes
from ..units import to_unit

__all__ = [
    "QUATERNION_NORM_TOL",
    "axis_rotation",
    "check_quaternions",
    "compose_quaternions",
    "euler_attitudes",
    "rotation_matrices",
    "rotation_sweep",
    "to_body_frame",
    "uniform_attitudes",
]

#: Largest accepted deviation of a quaternion's norm from 1.
QUATERNION_NORM_TOL = 1e-6


def check_quaternions(q: ArrayLike) -> NDArray[np.float64]:
    """Validate unit quaternions (scalar-last ``x, y, z, w``).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternions [1].

    Returns
    -------
    ndarray, shape (..., 4)
        The quaternions, renormalised (their norms are within
        :data:`QUATERNION_NORM_TOL` of 1).

    Raises
    ------
    ValidationError
        If the last axis is not 4 long, a value is not finite, or a norm differs
        from 1 by more than the tolerance (not a rotation).

    Examples
    --------
    >>> from sbrdf_xr.geometry.rotations import check_quaternions
    >>> check_quaternions([0.0, 0.0, 0.0, 1.0])
    array([0., 0., 0., 1.])
    >>> check_quaternions([0.0, 0.0, 1.0, 1.0])
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.ValidationError: quaternion: [0.0, 0.0, 1.0, 1.0] ... has norm 1.41421356; ...
    """
    arr = np.asarray(q, dtype=np.float64)
    if arr.ndim == 0 or arr.shape[-1] != 4:
        raise ValidationError(f"quaternion: expected shape (..., 4), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValidationError("quaternion: contains NaN or infinite components")
    norm = np.linalg.norm(arr, axis=-1, keepdims=True)
    bad = np.abs(norm[..., 0] - 1.0) > QUATERNION_NORM_TOL
    if np.any(bad):
        idx = np.argwhere(bad)[0]
        raise ValidationError(
            f"quaternion: {arr[tuple(idx)].tolist()} at index {idx.tolist()} has norm "
            f"{float(norm[tuple(idx)][0]):.9g}; a rotation needs a unit quaternion "
            f"(|norm - 1| <= {QUATERNION_NORM_TOL})"
        )
    return arr / norm


def _unit_axis(axis: ArrayLike) -> NDArray[np.float64]:
    """The unit vector along a rotation axis (3 finite components, not all zero)."""
    arr = np.asarray(axis)
    if arr.ndim == 0 or arr.shape[-1] != 3:
        raise ValidationError(
            f"axis: expected an array whose last axis has 3 components, got shape {arr.shape}"
        )
    if not np.issubdtype(arr.dtype, np.number) or np.iscomplexobj(arr):
        raise ValidationError(f"axis: expected real numbers, got dtype {arr.dtype}")
    arr = arr.astype(np.float64)
    if not np.all(np.isfinite(arr)):
        raise ValidationError("axis: contains NaN or infinite components")
    norm = np.linalg.norm(arr, axis=-1, keepdims=True)
    if np.any(norm == 0):
        raise ValidationError("axis: contains zero-length vectors; directions must be non-zero")
    return arr / norm


def rotation_matrices(q: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrices (body -> reference) of unit quaternions.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Unit quaternions, scalar-last [1].

    Returns
    -------
    ndarray, shape (..., 3, 3)

    Examples
    --------
    A quarter turn about +z takes the body +x axis to the reference +y axis:

    >>> import numpy as np
    >>> from sbrdf_xr.geometry.rotations import axis_rotation, rotation_matrices
    >>> r = rotation_matrices(axis_rotation([0, 0, 1], 90.0))
    >>> np.round(r, 6) + 0.0
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    >>> rotation_matrices(axis_rotation([0, 0, 1], [0.0, 45.0, 90.0])).shape
    (3, 3, 3)
    """
    arr = check_quaternions(q)
    return Rotation.from_quat(arr.reshape(-1, 4)).as_matrix().reshape(*arr.shape[:-1], 3, 3)


def to_body_frame(q: ArrayLike, v: ArrayLike) -> NDArray[np.float64]:
    """Express reference-frame directions in the body frame of attitudes ``q``.

    Parameters
    ----------
    q : array_like, shape (n, 4)
        Attitudes (body -> reference), scalar-last unit quaternions [1].
    v : array_like, shape (..., 3)
        Directions in the reference frame [1], broadcast against the attitudes as
        ``(n, ..., 3)`` when ``v`` has leading dimensions.

    Returns
    -------
    ndarray, shape (n, ..., 3)
        ``R(q)^T v``.

    Examples
    --------
    For a body turned by 90 deg about +z, the reference +x direction is body -y:

    >>> import numpy as np
    >>> from sbrdf_xr.geometry.rotations import axis_rotation, to_body_frame
    >>> q = axis_rotation([0, 0, 1], [0.0, 90.0])
    >>> np.round(to_body_frame(q, [1.0, 0.0, 0.0]), 6) + 0.0
    array([[ 1.,  0.,  0.],
           [ 0., -1.,  0.]])
    """
    r = rotation_matrices(q)
    vv = np.asarray(v, dtype=np.float64)
    extra = vv.ndim - 1
    rt = np.swapaxes(r, -1, -2).reshape(r.shape[0], *([1] * extra), 3, 3)
    return np.einsum("...ij,...j->...i", rt, vv)


def axis_rotation(axis: ArrayLike, angle: ArrayLike) -> NDArray[np.float64]:
    """Quaternions of rotations by ``angle`` about ``axis`` (right-handed).

    Parameters
    ----------
    axis : array_like, shape (3,)
        Rotation axis [1], any non-zero length.
    angle : array_like
        Rotation angles [degree].

    Returns
    -------
    ndarray, shape angle.shape + (4,)
        Scalar-last unit quaternions.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.geometry.rotations import axis_rotation
    >>> axis_rotation([0, 0, 2], 90.0).round(6)
    array([0.      , 0.      , 0.707107, 0.707107])
    >>> axis_rotation([1, 0, 0], np.zeros((2, 5))).shape
    (2, 5, 4)
    """
    a = _unit_axis(axis)
    half = np.radians(np.asarray(to_unit(angle, "deg", "angle"), dtype=np.float64)) / 2.0
    return np.concatenate([np.sin(half)[..., None] * a, np.cos(half)[..., None]], axis=-1)


def compose_quaternions(q_outer: ArrayLike, q_inner: ArrayLike) -> NDArray[np.float64]:
    """Quaternion of the rotation ``q_inner`` followed by ``q_outer`` (``R_outer R_inner``).

    Parameters
    ----------
    q_outer, q_inner : array_like, shape (..., 4)
        Unit quaternions, scalar-last [1], broadcast against each other.

    Returns
    -------
    ndarray, shape (..., 4)
        Scalar-last unit quaternions of the composed rotations.

    Examples
    --------
    Turning by 30 deg and then by 60 deg about the same axis is a 90 deg turn:

    >>> import numpy as np
    >>> from sbrdf_xr.geometry.rotations import axis_rotation, compose_quaternions
    >>> q = compose_quaternions(axis_rotation([0, 0, 1], 60.0), axis_rotation([0, 0, 1], 30.0))
    >>> np.allclose(q, axis_rotation([0, 0, 1], 90.0))
    True
    """
    a, b = np.broadcast_arrays(check_quaternions(q_outer), check_quaternions(q_inner))
    shape = a.shape
    out = Rotation.from_quat(a.reshape(-1, 4)) * Rotation.from_quat(b.reshape(-1, 4))
    return out.as_quat().reshape(shape)


def rotation_sweep(
    axis: ArrayLike,
    angles: ArrayLike,
    initial: ArrayLike | None = None,
) -> NDArray[np.float64]:
    """Attitudes of a body rotated about a fixed reference-frame axis.

    Parameters
    ----------
    axis : array_like, shape (3,)
        Rotation axis in the reference frame [1].
    angles : array_like, shape (n,)
        Rotation angles about ``axis`` [degree].
    initial : array_like, shape (4,), optional
        Initial attitude applied first (scalar-last quaternion).

    Returns
    -------
    ndarray, shape (n, 4)

    Examples
    --------
    Paper 000 §4, second scenario: an initial 25 deg about +z, then 360 steps of 1 deg
    about -z; the body +x axis returns to the reference +x direction after 25 steps:

    >>> import numpy as np
    >>> from sbrdf_xr.geometry.rotations import axis_rotation, rotation_sweep, to_body_frame
    >>> q = rotation_sweep([0, 0, -1], np.arange(360), axis_rotation([0, 0, 1], 25))
    >>> q.shape
    (360, 4)
    >>> np.round(to_body_frame(q[25:26], [1.0, 0.0, 0.0]), 6) + 0.0
    array([[1., 0., 0.]])
    """
    q = axis_rotation(axis, np.atleast_1d(to_unit(angles, "deg", "angles")))
    if initial is None:
        return q
    return compose_quaternions(q, np.asarray(initial, dtype=np.float64))


def euler_attitudes(sequence: str, angles: ArrayLike) -> NDArray[np.float64]:
    """Attitudes from Euler angles (``scipy.spatial.transform.Rotation.from_euler``).

    Parameters
    ----------
    sequence : str
        Axis sequence: up to three of ``xyz`` (extrinsic) or ``XYZ`` (intrinsic).
    angles : array_like, shape (n, len(sequence))
        Angles [degree].

    Returns
    -------
    ndarray, shape (n, 4)

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.geometry.rotations import euler_attitudes
    >>> euler_attitudes("z", [[90.0]]).round(6)
    array([[0.      , 0.      , 0.707107, 0.707107]])
    >>> euler_attitudes("ZYX", [[10.0, 20.0, 30.0], [0.0, 0.0, 0.0]]).shape
    (2, 4)
    """
    angles = to_unit(angles, "deg", "angles")
    try:
        r = Rotation.from_euler(sequence, np.atleast_2d(np.asarray(angles, float)), degrees=True)
    except ValueError as exc:
        raise ValidationError(f"euler: {exc}") from exc
    return r.as_quat().reshape(-1, 4)


def uniform_attitudes(n: int, seed: int | None = 0) -> NDArray[np.float64]:
    """``n`` attitudes drawn uniformly from all orientations (Haar measure on SO(3)).

    Parameters
    ----------
    n : int
        Number of attitudes.
    seed : int, optional
        Seed of the generator (``scipy.spatial.transform.Rotation.random``).

    Returns
    -------
    ndarray, shape (n, 4)

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.geometry.rotations import uniform_attitudes
    >>> q = uniform_attitudes(1000, seed=1)
    >>> q.shape, bool(np.allclose(np.linalg.norm(q, axis=1), 1.0))
    ((1000, 4), True)
    """
    if n < 1:
        raise ValidationError(f"n: need at least one attitude, got {n}")
    return Rotation.random(n, random_state=seed).as_quat().reshape(-1, 4)


#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(__name__, globals(), {"compose": "compose_quaternions"})
