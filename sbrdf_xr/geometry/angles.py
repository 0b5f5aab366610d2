"""Illumination/reflection geometry of a facet in the angles of paper 000, Fig. 4.

Pure, vectorised numpy: every function takes arrays whose last axis holds the
three Cartesian components of a vector and broadcasts over all leading axes.
The attitude (quaternion) helpers are in :mod:`sbrdf_xr.geometry.rotations`.  Angles
[degree] also come as astropy Quantities, converted first (:func:`sbrdf_xr.units.to_unit`;
another kind raises :class:`~sbrdf_xr.errors.UnitError`).

Angle convention (paper 000 §3.1, Fig. 4; DESIGN.md "Angle convention")
-----------------------------------------------------------------------
For the unit facet normal ``N``, the unit vector to the source ``s`` (``v_i``)
and to the observer ``o`` (``v_r``):

* ``cos(theta_i) = N.s``; the facet is *lit* if ``N.s > 0`` and *visible* if
  ``N.o > 0``.
* The in-plane forward unit vector ``e_f = -normalize(s - (N.s) N)`` is the
  direction of the specular ray's tangential part; ``p = N x e_f`` is the normal
  of the illumination plane.
* ``phi = arcsin(|o.p|)`` (unsigned: isotropy on both sides of the plane).
* ``theta_r,proj = atan2(o.e_f, o.N)`` and ``delta_theta = theta_r,proj - theta_i``:
  negative on the source side of the specular direction, positive beyond it.
  Specular reflection is ``(theta_i, 0, 0)``.

Every angle is computed with ``arctan2`` of well-conditioned components, never
``arccos`` of a dot product near +-1, so that the results are finite and accurate at
normal and grazing incidence and for dot products of exactly +-1.

Normal incidence
----------------
When ``theta_i -> 0`` the illumination plane is undefined.  When the tangential part
of ``s`` is shorter than :func:`normal_incidence_tolerance` (``1e4`` machine epsilons
of the working precision: ``2.2e-12`` in float64, i.e. ``theta_i < 1.3e-10 deg``;
``1.2e-3`` in float32, ``theta_i < 0.07 deg``) the plane is taken through the
observer instead, so that ``phi = 0`` and ``delta_theta = theta_r - theta_i``.  If the
observer is along the normal too, any plane gives the same answer and a fixed one
is used.  The three angles are then finite and ``theta_i`` and the observer's polar
angle ``theta_r`` (``cos theta_r = cos(phi) cos(theta_i + delta_theta)``) are
continuous through normal incidence.  ``delta_theta`` and ``phi`` themselves
cannot be continuous there (the plane rotates with the Sun's azimuth, as longitude
does at a pole); a physical material does not depend on the plane at
``theta_i = 0``, which makes the looked-up sBRDF continuous.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import ValidationError, renamed_keywords
from ..units import to_unit

__all__ = [
    "FacetAngles",
    "facet_angles",
    "facet_vectors",
    "from_conventional",
    "half_vector",
    "normal_incidence_tolerance",
    "normalize",
    "observation_plane",
    "phase_angle",
    "to_conventional",
]

#: Multiple of the working precision's machine epsilon below which the tangential
#: part of the Sun vector is considered zero (normal incidence).
NORMAL_INCIDENCE_EPS_FACTOR = 1.0e4


class FacetAngles(NamedTuple):
    """Angles of paper 000 Fig. 4 for a facet, with its lit/visible flags.

    Attributes
    ----------
    theta_i : ndarray
        Illumination polar angle from the normal [degree], in ``[0, 180]``.
    delta_theta : ndarray
        Signed difference-in-polar angle [degree].
    phi : ndarray
        Unsigned angle of the observer from the illumination plane [degree], in ``[0, 90]``.
    lit : ndarray of bool
        ``N.s > 0``.
    visible : ndarray of bool
        ``N.o > 0``.

    Examples
    --------
    The tuple :func:`facet_angles` returns; its fields are arrays (0-d for single vectors):

    >>> from sbrdf_xr.geometry import FacetAngles, facet_angles
    >>> a = facet_angles([0, 0, 1], [1, 0, 1], [0, 0, 1])
    >>> isinstance(a, FacetAngles), a._fields
    (True, ('theta_i', 'delta_theta', 'phi', 'lit', 'visible'))
    >>> round(float(a.theta_i), 6), bool(a.lit), bool(a.visible)
    (45.0, True, True)
    """

    theta_i: NDArray[np.floating]
    delta_theta: NDArray[np.floating]
    phi: NDArray[np.floating]
    lit: NDArray[np.bool_]
    visible: NDArray[np.bool_]


def _float_dtype(*arrays: ArrayLike) -> np.dtype:
    """Working precision: the widest floating dtype among the inputs, float64 otherwise."""
    dtypes = [np.asarray(a).dtype for a in arrays]
    floats = [d for d in dtypes if np.issubdtype(d, np.floating)]
    if not floats or len(floats) < len(dtypes):
        return np.dtype(np.float64)
    return np.result_type(*floats)


def _as_float(a: ArrayLike) -> np.ndarray:
    arr = np.asarray(a)
    return arr.astype(_float_dtype(arr), copy=False)


def normal_incidence_tolerance(dtype: np.dtype | type = np.float64) -> float:
    """Tangential length of the Sun vector below which incidence is normal.

    Parameters
    ----------
    dtype : numpy dtype
        Working precision.

    Returns
    -------
    float
        ``1e4 * eps(dtype)`` [1].

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.geometry import normal_incidence_tolerance
    >>> normal_incidence_tolerance()
    2.22...e-12
    >>> normal_incidence_tolerance(np.float32)
    0.00119...
    """
    return float(NORMAL_INCIDENCE_EPS_FACTOR * np.finfo(dtype).eps)


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("...k,...k->...", a, b)


def _check_vectors(v: ArrayLike, name: str) -> np.ndarray:
    arr = np.asarray(v)
    if arr.ndim == 0 or arr.shape[-1] != 3:
        raise ValidationError(
            f"{name}: expected an array whose last axis has 3 components, got shape {arr.shape}"
        )
    if not np.issubdtype(arr.dtype, np.number) or np.iscomplexobj(arr):
        raise ValidationError(f"{name}: expected real numbers, got dtype {arr.dtype}")
    if not np.all(np.isfinite(arr)):
        raise ValidationError(f"{name}: contains NaN or infinite components")
    return arr


def normalize(v: ArrayLike, name: str = "vector") -> NDArray[np.floating]:
    """Return unit vectors along ``v``.

    Parameters
    ----------
    v : array_like, shape (..., 3)
        Non-zero, finite vectors.
    name : str
        Name used in error messages.

    Returns
    -------
    ndarray, shape (..., 3)
        ``v / |v|`` in the floating dtype of ``v`` (at least float32).

    Raises
    ------
    ValidationError
        If a vector is zero, not finite, or the last axis is not of length 3.

    Examples
    --------
    >>> from sbrdf_xr.geometry import normalize
    >>> normalize([3.0, 0.0, 4.0])
    array([0.6, 0. , 0.8])
    >>> normalize([[0, 0, 2], [0, 5, 0]]).tolist()
    [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]
    >>> normalize([0, 0, 0], "to_sun")
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.ValidationError: to_sun: contains zero-length vectors; ...
    """
    arr = _check_vectors(v, name)
    arr = arr.astype(_float_dtype(arr), copy=False)
    norm = np.linalg.norm(arr, axis=-1, keepdims=True)
    if np.any(norm == 0):
        raise ValidationError(f"{name}: contains zero-length vectors; directions must be non-zero")
    return arr / norm


def _vectors(
    normal: ArrayLike, to_sun: ArrayLike, to_observer: ArrayLike, check: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The facet normal and the directions to the Sun and the observer as arrays, normalised
    and checked (finite, non-zero, last axis 3) when ``check``."""
    if not check:
        return np.asarray(normal), np.asarray(to_sun), np.asarray(to_observer)
    return (
        normalize(normal, "normal"),
        normalize(to_sun, "to_sun"),
        normalize(to_observer, "to_observer"),
    )


def _perpendicular(n: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to each unit vector ``n`` (deterministic)."""
    # Cross with the coordinate axis least aligned with n: well conditioned.
    axis = np.zeros_like(n)
    idx = np.argmin(np.abs(n), axis=-1)
    np.put_along_axis(axis, idx[..., None], 1.0, axis=-1)
    p = np.cross(n, axis)
    return p / np.linalg.norm(p, axis=-1, keepdims=True)


def _tangential(v: np.ndarray, n: np.ndarray, vn: np.ndarray) -> np.ndarray:
    """The part of ``v`` in the plane of the unit normal ``n`` (``vn = n.v``), projected twice.

    One projection ``v - (n.v) n`` leaves a normal component of the rounding of ``n.v``
    (about ``eps``), which near normal incidence is a large fraction of a short
    tangential part and tilts the frame built on it out of the plane (``e_f.N`` of
    ``eps / |v_t|``); a second projection brings it to ``eps |v_t|`` ("twice is enough",
    Giraud et al., Numer. Math. 101, 87, 2005).
    """
    v_t = v - vn[..., None] * n
    return v_t - _dot(v_t, n)[..., None] * n


def _forward_direction(
    n: np.ndarray, s: np.ndarray, o: np.ndarray, ns: np.ndarray, no: np.ndarray, tol: float
) -> tuple[np.ndarray, np.ndarray]:
    """The in-plane forward unit vector ``e_f`` of paper 000 Fig. 4 and ``|s_t|``.

    ``e_f = -s_t / |s_t|`` from the Sun's tangential part ``s_t``; at normal incidence
    (``|s_t| <= tol``) from the observer's, ``o_t / |o_t|`` (so ``phi = 0``); with the
    observer along the normal too, the fixed perpendicular of :func:`_perpendicular`.
    """
    s_t = _tangential(s, n, ns)
    s_t_len = np.linalg.norm(s_t, axis=-1)
    normal_inc = s_t_len <= tol
    o_t = _tangential(o, n, no)
    o_t_len = np.linalg.norm(o_t, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        e_sun = -s_t / np.where(normal_inc, 1.0, s_t_len)[..., None]
        e_obs = o_t / np.where(o_t_len > tol, o_t_len, 1.0)[..., None]
    e_obs = np.where((o_t_len > tol)[..., None], e_obs, _perpendicular(n))
    return np.where(normal_inc[..., None], e_obs, e_sun), s_t_len


def facet_angles(
    normal: ArrayLike,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    *,
    check: bool = True,
) -> FacetAngles:
    """Angles ``(theta_i, delta_theta, phi)`` of paper 000 Fig. 4 for facets.

    Implements the modified illumination and reflection geometry of paper 000
    §3.1 (Fig. 4) exactly as written in the module docstring.

    Parameters
    ----------
    normal : array_like, shape (..., 3)
        Facet normals [1]. Need not be unit length.
    to_sun : array_like, shape (..., 3)
        Directions from the facet to the source, ``v_i`` [1].
    to_observer : array_like, shape (..., 3)
        Directions from the facet to the observer, ``v_r`` [1].
    check : bool, default True
        Validate (finite, non-zero, 3 components) and normalise the inputs.
        With ``check=False`` the inputs must already be unit vectors.

    Returns
    -------
    FacetAngles
        ``theta_i``, ``delta_theta``, ``phi`` [degree] and the boolean ``lit`` and
        ``visible`` flags, broadcast over the leading axes of the inputs.  The
        working precision is that of the inputs (at least float32).

    Notes
    -----
    Angles are defined for every input, lit or not; callers mask with ``lit`` and
    ``visible``.  See the module docstring for the treatment of normal incidence.

    Examples
    --------
    Sun 30 deg from the normal, observer 40 deg on the far side of it in the same plane:
    10 deg beyond the specular direction, in the illumination plane.

    >>> import numpy as np
    >>> from sbrdf_xr.geometry import facet_angles
    >>> ti, tr = np.radians(30.0), np.radians(40.0)
    >>> a = facet_angles([0, 0, 1], [np.sin(ti), 0, np.cos(ti)], [-np.sin(tr), 0, np.cos(tr)])
    >>> round(float(a.theta_i), 6), round(float(a.delta_theta), 6), round(float(a.phi), 6)
    (30.0, 10.0, 0.0)
    >>> bool(a.lit), bool(a.visible)
    (True, True)

    Inputs broadcast over leading axes, here three facets seen under one geometry:

    >>> normals = [[0, 0, 1], [1, 0, 0], [0, 0, -1]]
    >>> a = facet_angles(normals, [0, 0, 1], [0, 1, 1])
    >>> np.round(a.theta_i, 6) + 0.0
    array([  0.,  90., 180.])
    >>> a.lit
    array([ True, False, False])
    """
    n, s, o = _vectors(normal, to_sun, to_observer, check)
    dtype = _float_dtype(n, s, o)
    n, s, o = np.broadcast_arrays(
        n.astype(dtype, copy=False), s.astype(dtype, copy=False), o.astype(dtype, copy=False)
    )

    ns = _dot(n, s)
    no = _dot(n, o)
    e_f, s_t_len = _forward_direction(n, s, o, ns, no, normal_incidence_tolerance(dtype))
    theta_i = np.arctan2(s_t_len, ns)
    p = np.cross(n, e_f)

    of = _dot(o, e_f)
    op = _dot(o, p)
    theta_r_proj = np.arctan2(of, no)
    phi = np.arctan2(np.abs(op), np.hypot(of, no))
    delta_theta = theta_r_proj - theta_i
    return FacetAngles(
        np.degrees(theta_i),
        np.degrees(delta_theta),
        np.degrees(phi),
        ns > 0,
        no > 0,
    )


def facet_vectors(
    theta_i: ArrayLike, delta_theta: ArrayLike, phi: ArrayLike
) -> tuple[NDArray[np.floating], NDArray[np.floating], NDArray[np.floating]]:
    """Unit vectors in the facet frame for angles ``(theta_i, delta_theta, phi)``.

    The inverse of :func:`facet_angles` (paper 000 Fig. 4).  The facet frame has
    the normal along ``+z`` and the Sun in the ``xz`` half-plane ``x >= 0``
    (conventional azimuth ``phi_i = 0``), so the forward direction is ``-x`` and
    the illumination-plane normal ``p = N x e_f = -y``; positive ``phi`` puts the
    observer on the ``-y`` side.

    Parameters
    ----------
    theta_i : array_like
        Illumination polar angle [degree].
    delta_theta : array_like
        Difference-in-polar angle [degree].
    phi : array_like
        Angle from the illumination plane [degree], ``>= 0``.

    Returns
    -------
    normal, to_sun, to_observer : ndarray, shape (..., 3)
        Unit vectors, broadcast over the inputs.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.geometry import facet_angles, facet_vectors
    >>> n, s, o = facet_vectors(30.0, 10.0, 0.0)
    >>> n, np.round(s, 4) + 0.0, np.round(o, 4) + 0.0
    (array([0., 0., 1.]), array([0.5  , 0.   , 0.866]), array([-0.6428,  0.    ,  0.766 ]))
    >>> [round(float(x), 6) for x in facet_angles(n, s, o)[:3]]
    [30.0, 10.0, 0.0]
    """
    named = {"theta_i": theta_i, "delta_theta": delta_theta, "phi": phi}
    ti, dt, ph = np.broadcast_arrays(*(_as_float(to_unit(a, "deg", k)) for k, a in named.items()))
    ti_r, ph_r = np.radians(ti), np.radians(ph)
    trp = ti_r + np.radians(dt)
    zeros = np.zeros_like(ti_r)
    normal = np.stack([zeros, zeros, zeros + 1], axis=-1)
    to_sun = np.stack([np.sin(ti_r), zeros, np.cos(ti_r)], axis=-1)
    cph = np.cos(ph_r)
    to_obs = np.stack([-cph * np.sin(trp), -np.sin(ph_r), cph * np.cos(trp)], axis=-1)
    return normal, to_sun, to_obs


def phase_angle(to_sun: ArrayLike, to_observer: ArrayLike) -> NDArray[np.floating]:
    """Phase angle ``beta`` between the Sun and observer directions.

    Parameters
    ----------
    to_sun, to_observer : array_like, shape (..., 3)
        Non-zero direction vectors [1].

    Returns
    -------
    ndarray
        ``beta = atan2(|s x o|, s.o)`` [degree], in ``[0, 180]``; exact at 0 and 180.

    Examples
    --------
    >>> from sbrdf_xr.geometry import phase_angle
    >>> phase_angle([1, 0, 0], [[1, 0, 0], [0, 1, 0], [-1, 0, 0]])
    array([  0.,  90., 180.])
    """
    s = normalize(to_sun, "to_sun")
    o = normalize(to_observer, "to_observer")
    s, o = np.broadcast_arrays(s, o)
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(s, o), axis=-1), _dot(s, o)))


def half_vector(to_sun: ArrayLike, to_observer: ArrayLike) -> NDArray[np.floating]:
    """Glint (half-angle) unit vector ``(o + s) / |o + s|`` (paper 001 Eq. 5).

    Parameters
    ----------
    to_sun, to_observer : array_like, shape (..., 3)
        Unit direction vectors [1].

    Returns
    -------
    ndarray, shape (..., 3)
        The bisector of ``s`` and ``o``.  At forward scatter (``|o + s|`` under
        :func:`normal_incidence_tolerance`, phase angle within about 1e-12 rad of
        180 deg, where ``(o + s) / |o + s|`` is rounding noise) the bisector is any
        unit vector perpendicular to ``s - o``; a deterministic one is returned
        instead of 0/0, and swapping ``s`` and ``o`` returns exactly its negative,
        so that every function of the bisector that is even in it (``(h.N)^2``,
        ``|h x N|^2``) stays reciprocal there.  Paper 001 writes
        the normalisation as ``sqrt(2 (1 + o.s))``, which equals ``|o + s|`` for
        unit vectors but cancels catastrophically near 180 deg; ``|o + s|`` is
        computed directly.

    Examples
    --------
    >>> from sbrdf_xr.geometry import half_vector
    >>> half_vector([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]).round(6)
    array([0.707107, 0.707107, 0.      ])

    At exact forward scatter a unit vector perpendicular to the Sun direction comes back:

    >>> h = half_vector([1.0, 0.0, 0.0], [-1.0, 0.0, 0.0])
    >>> float(h @ h), float(h[0])
    (1.0, 0.0)
    """
    s = np.asarray(to_sun)
    o = np.asarray(to_observer)
    dtype = _float_dtype(s, o)
    s, o = np.broadcast_arrays(s.astype(dtype, copy=False), o.astype(dtype, copy=False))
    g = s + o
    g_len = np.linalg.norm(g, axis=-1, keepdims=True)
    tiny = g_len <= normal_incidence_tolerance(dtype)
    out = g / np.where(tiny, 1.0, g_len)
    # s - o is 2 s there, and o - s is exactly -(s - o): the fallback is odd in the swap
    # (elsewhere s - o may be 0, at backscatter: s stands in for it, and is discarded)
    return np.where(tiny, _perpendicular(np.where(tiny, s - o, s)), out)


def to_conventional(
    theta_i: ArrayLike, delta_theta: ArrayLike, phi: ArrayLike
) -> tuple[NDArray[np.floating], NDArray[np.floating], NDArray[np.floating], NDArray[np.floating]]:
    """Convert paper-000 angles to conventional ``(theta_i, phi_i, theta_r, phi_r)``.

    Conventional angles (Nicodemus; paper 000 Fig. 2) are polar and azimuth
    angles of the source and observer in the facet frame of :func:`facet_vectors`,
    so ``phi_i = 0`` and the specular direction has ``phi_r = 180 deg``.

    Parameters
    ----------
    theta_i, delta_theta, phi : array_like
        Paper-000 angles [degree].

    Returns
    -------
    theta_i, phi_i, theta_r, phi_r : ndarray
        Conventional angles [degree]; azimuths in ``[0, 360)``.

    Examples
    --------
    The specular direction at 30 deg incidence has ``theta_r = 30`` and ``phi_r = 180``:

    >>> from sbrdf_xr.geometry import to_conventional
    >>> [round(float(x), 6) for x in to_conventional(30.0, 0.0, 0.0)]
    [30.0, 0.0, 30.0, 180.0]
    """
    _, s, o = facet_vectors(theta_i, delta_theta, phi)
    ti = np.degrees(np.arctan2(np.hypot(s[..., 0], s[..., 1]), s[..., 2]))
    pi_ = np.zeros_like(ti)
    tr = np.degrees(np.arctan2(np.hypot(o[..., 0], o[..., 1]), o[..., 2]))
    pr = np.mod(np.degrees(np.arctan2(o[..., 1], o[..., 0])), 360.0)
    # Keep 360 - tiny from rounding up to 360.
    pr = np.where(pr >= 360.0, 0.0, pr)
    return ti, pi_, tr, pr


def from_conventional(
    theta_i: ArrayLike, phi_i: ArrayLike, theta_r: ArrayLike, phi_r: ArrayLike
) -> tuple[NDArray[np.floating], NDArray[np.floating], NDArray[np.floating]]:
    """Convert conventional ``(theta_i, phi_i, theta_r, phi_r)`` to paper-000 angles.

    Parameters
    ----------
    theta_i, phi_i, theta_r, phi_r : array_like
        Polar and azimuth angles of the source and observer [degree].

    Returns
    -------
    theta_i, delta_theta, phi : ndarray
        Paper-000 angles [degree] from :func:`facet_angles`.

    Examples
    --------
    >>> from sbrdf_xr.geometry import from_conventional
    >>> [round(float(x), 6) for x in from_conventional(30.0, 0.0, 40.0, 180.0)]
    [30.0, 10.0, 0.0]
    """
    named = {"theta_i": theta_i, "phi_i": phi_i, "theta_r": theta_r, "phi_r": phi_r}
    ti, pi_, tr, pr = (np.radians(_as_float(to_unit(a, "deg", k))) for k, a in named.items())
    ti, pi_, tr, pr = np.broadcast_arrays(ti, pi_, tr, pr)
    s = np.stack([np.sin(ti) * np.cos(pi_), np.sin(ti) * np.sin(pi_), np.cos(ti)], axis=-1)
    o = np.stack([np.sin(tr) * np.cos(pr), np.sin(tr) * np.sin(pr), np.cos(tr)], axis=-1)
    n = np.zeros_like(s)
    n[..., 2] = 1.0
    ang = facet_angles(n, s, o, check=False)
    return ang.theta_i, ang.delta_theta, ang.phi


@renamed_keywords(phase_angle_deg="phase_angle")
def observation_plane(
    phase_angle: ArrayLike,
    bisector: ArrayLike = (1.0, 0.0, 0.0),
    plane_normal: ArrayLike = (0.0, 0.0, 1.0),
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Sun and observer directions symmetric about a bisector in a plane.

    The geometry of paper 000 Figs. 12-13: ``v_i`` and ``v_r`` lie in the plane
    with normal ``plane_normal`` (the xy-plane by default), at ``beta/2`` either
    side of ``bisector`` (+x by default), the Sun on the positive-rotation side.

    Parameters
    ----------
    phase_angle : array_like
        Phase angles beta [degree], in [0, 180].
    bisector, plane_normal : array_like, shape (3,)
        Perpendicular directions [1].

    Returns
    -------
    to_sun, to_observer : ndarray, shape beta.shape + (3,)

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.geometry import observation_plane, phase_angle
    >>> to_sun, to_observer = observation_plane([10.0, 90.0])
    >>> to_sun.shape, np.round(phase_angle(to_sun, to_observer), 6)
    ((2, 3), array([10., 90.]))
    >>> np.round(to_sun[1], 6), np.round(to_observer[1], 6)
    (array([0.707107, 0.707107, 0.      ]), array([ 0.707107, -0.707107,  0.      ]))
    """
    beta = np.asarray(to_unit(phase_angle, "deg", "phase_angle"), dtype=np.float64)
    if np.any((beta < 0) | (beta > 180)) or not np.all(np.isfinite(beta)):
        raise ValidationError(f"phase_angle: must lie in [0, 180] degree, got {beta.ravel()[:5]}")
    b = normalize(bisector, "bisector")
    n = normalize(plane_normal, "plane_normal")
    if abs(float(np.dot(b, n))) > 1e-9:
        raise ValidationError("bisector and plane_normal must be perpendicular")
    t = np.cross(n, b)
    half = np.radians(beta)[..., None] / 2.0
    to_sun = np.cos(half) * b + np.sin(half) * t
    to_obs = np.cos(half) * b - np.sin(half) * t
    return to_sun, to_obs
