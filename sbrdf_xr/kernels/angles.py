"""The angle convention of paper 000 Fig. 4 in compiled code: the one place the kernels
compute a facet's frame and angles.

:func:`sbrdf_xr.geometry.facet_angles` (numpy) is the specification; here are its
compiled parts, shared by the isotropic and the anisotropic kernels:

* :func:`in_plane`, the part of a vector in the facet plane (projected twice);
* :func:`forward_direction`, the in-plane forward vector ``e_f`` (at normal incidence
  through the observer, or through the axis least aligned with the normal);
* :func:`observer_components`, the observer's components along ``e_f`` and out of the
  plane, and :func:`frame_angles`, the angles from them (branch-free arc tangents for
  the vectorised loop, ``libm``'s for one pair);
* :func:`facet_frame`, the three together for one lit and seen pair;
* :func:`chunk_angles`, the same for a chunk of geometries x terms in one vectorisable
  pass (the first stage of :func:`sbrdf_xr.kernels.sums.fused_sums`);
* :func:`tangent_azimuth`, the azimuth ``psi`` of the illumination plane from a facet
  tangent (:func:`sbrdf_xr.geometry.anisotropy.illumination_azimuth`).

Vectors travel as 3-tuples of floats (numba keeps them in registers).

``libm``'s ``atan2`` is a scalar call (about 60 ns here) and three of them per
(geometry, term) pair were most of the fused kernel's wavelength-independent time.
:func:`atan2_pos` is the arc tangent of Cephes' ``atan.c`` (S. L. Moshier, Cephes
Mathematical Library, 1984-2000: a ``P(z)/Q(z)`` rational of degree 4/5 after a
three-way range reduction, relative error about 1e-16) written without branches, so
that LLVM turns :func:`chunk_angles`' inner loop over geometries into SIMD code.
Every quotient it takes has a positive denominator in the kernel (``N.s > 0``,
``N.o > 0`` for a lit and seen pair), which is the only case it serves.
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = [
    "atan2_pos",
    "chunk_angles",
    "facet_frame",
    "forward_direction",
    "frame_angles",
    "in_plane",
    "observer_components",
    "tangent_azimuth",
]

Vec = tuple[float, float, float]

# Cephes atan.c, double precision
_P0 = -8.750608600031904122785e-1
_P1 = -1.615753718733365076637e1
_P2 = -7.500855792314704667340e1
_P3 = -1.228866684490136173410e2
_P4 = -6.485021904942025371773e1
_Q0 = 2.485846490142306297962e1
_Q1 = 1.650270098316988542046e2
_Q2 = 4.328810604912902668951e2
_Q3 = 4.853903996359136964868e2
_Q4 = 1.945506571482613964425e2
_T3P8 = 2.41421356237309504880  # tan(3 pi / 8)
_MOREBITS = 6.123233995736765886130e-17  # pi / 2 - float(pi / 2)
_PIO2 = np.pi / 2
_PIO4 = np.pi / 4
_RAD2DEG = 180.0 / np.pi


@numba.njit(nogil=True, cache=True, error_model="numpy", inline="always")
def atan2_pos(y: float, x: float) -> float:  # pragma: no cover - compiled
    """``arctan2(y, x)`` [rad] for ``x > 0``, without branches (Cephes ``atan``).

    The range reduction of Cephes picks ``|y| / x``, ``(|y| - x) / (|y| + x)`` or
    ``-x / |y|`` by the size of ``|y| / x`` (below 0.66, up to ``tan(3 pi / 8)``,
    beyond), each formed from ``y`` and ``x`` directly (one rounding) and selected
    rather than branched to.  The kernel's arguments are at most 1 in size; the
    function serves ``|y|`` and ``x`` from 2.2e-308 (no subnormal ``x``) to 1e300 (their
    sum must not overflow).  ``x <= 0`` gives an unspecified value (no exception).

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.kernels.angles import atan2_pos
    >>> y = np.array([0.0, 0.3, 1.0, 5.0, -2.0, 1e-300, 1e300])
    >>> got = np.array([atan2_pos(v, 1.0) for v in y])
    >>> bool(np.all(np.abs(got - np.arctan2(y, 1.0)) <= 2.3e-16 * np.abs(np.arctan2(y, 1.0))))
    True
    """
    a = abs(y)
    big = a > _T3P8 * x
    small = a <= 0.66 * x
    num = -x if big else (a if small else a - x)
    den = a if big else (x if small else a + x)
    base = _PIO2 if big else (0.0 if small else _PIO4)
    more = _MOREBITS if big else (0.0 if small else 0.5 * _MOREBITS)
    r = num / den
    z = r * r
    p = (((_P0 * z + _P1) * z + _P2) * z + _P3) * z + _P4
    q = ((((z + _Q0) * z + _Q1) * z + _Q2) * z + _Q3) * z + _Q4
    v = base + ((r * (z * p / q) + more) + r)
    return math.copysign(v, y)


@numba.njit(nogil=True, cache=True, inline="always")
def _dot(a: Vec, b: Vec) -> float:  # pragma: no cover - compiled
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@numba.njit(nogil=True, cache=True, inline="always")
def _cross(a: Vec, b: Vec) -> Vec:  # pragma: no cover - compiled
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@numba.njit(nogil=True, cache=True, inline="always")
def in_plane(n: Vec, v: Vec, vn: float) -> tuple[Vec, float]:  # pragma: no cover - compiled
    """The part of ``v`` in the plane of the unit normal ``n`` (``vn = n.v``) and its
    length, projected twice as :func:`sbrdf_xr.geometry.facet_angles` does (the second
    projection brings the normal component left by rounding to ``eps |v_t|``).

    Examples
    --------
    >>> from sbrdf_xr.kernels.angles import in_plane
    >>> in_plane((0.0, 0.0, 1.0), (0.6, 0.0, 0.8), 0.8)
    ((0.6, 0.0, 0.0), 0.6)
    """
    tx, ty, tz = v[0] - vn * n[0], v[1] - vn * n[1], v[2] - vn * n[2]
    d = tx * n[0] + ty * n[1] + tz * n[2]
    tx, ty, tz = tx - d * n[0], ty - d * n[1], tz - d * n[2]
    return (tx, ty, tz), np.sqrt(tx * tx + ty * ty + tz * tz)


@numba.njit(nogil=True, cache=True, inline="always")
def forward_direction(
    n: Vec, s_t: Vec, s_t_len: float, o: Vec, no: float, tol: float
) -> Vec:  # pragma: no cover - compiled
    """The in-plane forward unit vector ``e_f`` of paper 000 Fig. 4.

    ``-s_t / |s_t|`` from the Sun's in-plane part :func:`in_plane`; at normal incidence
    (``|s_t| <= tol``) the observer's in-plane direction (so ``phi = 0``), or with the
    observer on the normal too the perpendicular through the axis least aligned with
    ``n`` (as :func:`sbrdf_xr.geometry.facet_angles`).

    Examples
    --------
    >>> from sbrdf_xr.kernels.angles import forward_direction
    >>> z = (0.0, 0.0, 1.0)
    >>> def e_f(s_t, s_t_len, o, no):
    ...     return [v + 0.0 for v in forward_direction(z, s_t, s_t_len, o, no, 1e-12)]
    >>> e_f((0.5, 0.0, 0.0), 0.5, (0.0, 0.6, 0.8), 0.8)  # away from the Sun
    [-1.0, 0.0, 0.0]
    >>> e_f((0.0, 0.0, 0.0), 0.0, (0.0, 0.6, 0.8), 0.8)  # towards the observer
    [0.0, 1.0, 0.0]
    >>> e_f((0.0, 0.0, 0.0), 0.0, z, 1.0)  # z x (the axis least aligned with z, +x)
    [0.0, 1.0, 0.0]
    """
    if s_t_len > tol:
        inv = 1.0 / s_t_len
        return (-s_t[0] * inv, -s_t[1] * inv, -s_t[2] * inv)
    o_t, o_t_len = in_plane(n, o, no)
    if o_t_len > tol:
        return (o_t[0] / o_t_len, o_t[1] / o_t_len, o_t[2] / o_t_len)
    # a perpendicular: cross with the axis least aligned with n
    ax, ay, az = abs(n[0]), abs(n[1]), abs(n[2])
    if ax <= ay and ax <= az:
        e = (0.0, n[2], -n[1])
    elif ay <= az:
        e = (-n[2], 0.0, n[0])
    else:
        e = (n[1], -n[0], 0.0)
    el = np.sqrt(_dot(e, e))
    return (e[0] / el, e[1] / el, e[2] / el)


@numba.njit(nogil=True, cache=True, inline="always")
def observer_components(n: Vec, e: Vec, o: Vec) -> tuple[float, float]:  # pragma: no cover
    """The observer's components along the forward vector ``e_f`` and out of the plane
    ``(e_f, N)``, along ``p = N x e_f`` [1].

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.kernels.angles import observer_components
    >>> h = float(np.sqrt(0.5))
    >>> [round(v, 12) for v in observer_components((0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (0.0, h, h))]
    [0.0, 0.707106781187]
    """
    return _dot(o, e), _dot(o, _cross(n, e))


@numba.njit(nogil=True, cache=True, inline="always")
def frame_angles(
    st_len: float, ns: float, of: float, op: float, no: float, simd: bool
) -> tuple[float, float, float]:  # pragma: no cover - compiled
    """``theta_i``, the observer's polar angle projected on the plane ``(e_f, N)`` and
    ``phi`` [rad] of a lit and seen pair (``ns = N.s > 0``, ``no = N.o > 0``) from the
    Sun's in-plane length ``|s_t|`` and :func:`observer_components`: the arc tangents of
    :func:`sbrdf_xr.geometry.facet_angles`.

    ``simd`` picks the arc tangent: :func:`atan2_pos` (branch-free, so a loop over
    geometries vectorises) or ``libm``'s (faster one pair at a time).

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.kernels.angles import frame_angles
    >>> h = float(np.sqrt(0.5))
    >>> a = frame_angles(0.5, np.sqrt(0.75), 0.0, h, h, False)
    >>> b = frame_angles(0.5, np.sqrt(0.75), 0.0, h, h, True)
    >>> [round(float(np.degrees(v)), 9) for v in a], bool(np.allclose(a, b, rtol=1e-15))
    ([30.0, 0.0, 45.0], True)
    """
    if simd:
        return (
            atan2_pos(st_len, ns),
            atan2_pos(of, no),
            atan2_pos(abs(op), np.sqrt(of * of + no * no)),
        )
    return np.arctan2(st_len, ns), np.arctan2(of, no), np.arctan2(abs(op), np.hypot(of, no))


@numba.njit(nogil=True, cache=True, error_model="numpy")
def chunk_angles(
    s_t: np.ndarray,
    o_t: np.ndarray,
    g0: int,
    nc: int,
    normals: np.ndarray,
    ns_out: np.ndarray,
    no_out: np.ndarray,
    st_out: np.ndarray,
    ti_out: np.ndarray,
    dt_out: np.ndarray,
    phi_out: np.ndarray,
) -> None:  # pragma: no cover - compiled
    """``N.s``, ``N.o``, the in-plane Sun component's length and the angles
    ``(theta_i, delta_theta, phi)`` [degree] of geometries ``g0 .. g0 + nc - 1`` against
    every term, into ``(T, nc)`` buffers.

    ``s_t``, ``o_t`` are the Sun and observer unit vectors as ``(3, G)`` rows.  The
    angles are those of :func:`facet_frame` away from normal incidence
    (in-plane Sun component above the tolerance); callers recompute the other pairs,
    and skip pairs that are not lit and seen, whose values here are unspecified.

    Examples
    --------
    The Sun 30 deg from the normal ``+z``; the observer at the specular direction, at
    the zenith, and 45 deg out of the plane of incidence:

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.angles import chunk_angles
    >>> c, s, h = np.cos(np.radians(30)), np.sin(np.radians(30)), np.sqrt(0.5)
    >>> s_t = np.ascontiguousarray(np.array([[s, 0, c]] * 3).T)  # (3, G)
    >>> o_t = np.ascontiguousarray(np.array([[-s, 0, c], [0, 0, 1.0], [0, h, h]]).T)
    >>> normals = np.array([[0.0, 0.0, 1.0]])
    >>> ns, no, st, ti, dt, phi = (np.empty((1, 3)) for _ in range(6))
    >>> chunk_angles(s_t, o_t, 0, 3, normals, ns, no, st, ti, dt, phi)
    >>> ti.round(6).tolist(), (dt.round(6) + 0.0).tolist(), (phi.round(6) + 0.0).tolist()
    ([[30.0, 30.0, 30.0]], [[0.0, -30.0, -30.0]], [[0.0, 0.0, 45.0]])
    >>> ns.round(6).tolist(), st.round(6).tolist()
    ([[0.866025, 0.866025, 0.866025]], [[0.5, 0.5, 0.5]])

    A chunk starting at geometry ``g0 = 1`` fills its first ``nc`` columns:

    >>> chunk_angles(s_t, o_t, 1, 2, normals, ns, no, st, ti, dt, phi)
    >>> (dt[:, :2].round(6) + 0.0).tolist(), (phi[:, :2].round(6) + 0.0).tolist()
    ([[-30.0, -30.0]], [[0.0, 45.0]])
    """
    for t in range(normals.shape[0]):
        n = (normals[t, 0], normals[t, 1], normals[t, 2])
        for j in range(nc):
            g = g0 + j
            s = (s_t[0, g], s_t[1, g], s_t[2, g])
            o = (o_t[0, g], o_t[1, g], o_t[2, g])
            ns = _dot(n, s)
            no = _dot(n, o)
            st, st_len = in_plane(n, s, ns)
            # e_f away from normal incidence, without forward_direction's branches (SIMD)
            inv = 1.0 / st_len
            of, op = observer_components(n, (-st[0] * inv, -st[1] * inv, -st[2] * inv), o)
            ti, trp, phi = frame_angles(st_len, ns, of, op, no, True)
            ns_out[t, j] = ns
            no_out[t, j] = no
            st_out[t, j] = st_len
            ti_out[t, j] = ti * _RAD2DEG
            dt_out[t, j] = trp * _RAD2DEG - ti * _RAD2DEG
            phi_out[t, j] = phi * _RAD2DEG


@numba.njit(nogil=True, cache=True, inline="always")
def facet_frame(
    n: Vec, s: Vec, o: Vec, ns: float, no: float, tol: float
) -> tuple[float, float, float, Vec, float]:  # pragma: no cover - compiled
    """The angles of paper 000 Fig. 4 of one lit and seen pair, as
    :func:`sbrdf_xr.geometry.facet_angles`: ``(theta_i, delta_theta, phi)`` [degree], the
    forward in-plane unit vector ``e_f`` and the observer's out-of-plane component ``o.p``.

    ``ns``, ``no`` are ``N.s`` and ``N.o`` (both positive); at normal incidence (in-plane
    Sun component under ``tol``) the plane is taken through the observer, or through the
    axis least aligned with ``N`` when the observer is on the normal too
    (:func:`forward_direction`).

    Examples
    --------
    The Sun 30 deg from the normal ``+z`` and the observer at the specular direction:
    ``delta_theta = phi = 0`` and the forward vector ``e_f`` points away from the Sun.

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.angles import facet_frame
    >>> c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    >>> ti, dt, phi, e, op = facet_frame((0.0, 0.0, 1.0), (s, 0.0, c), (-s, 0.0, c), c, c, 1e-12)
    >>> [round(v, 6) + 0.0 for v in (ti, dt, phi, *e, op)]
    [30.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0]

    At normal incidence the plane goes through the observer (here 40 deg off the normal
    towards ``+x``), so ``delta_theta`` is the observer's polar angle:

    >>> c4, s4 = np.cos(np.radians(40)), np.sin(np.radians(40))
    >>> z = (0.0, 0.0, 1.0)
    >>> ti, dt, phi, e, op = facet_frame(z, z, (s4, 0.0, c4), 1.0, c4, 1e-12)
    >>> [round(v, 6) + 0.0 for v in (ti, dt, phi, *e, op)]
    [0.0, 40.0, 0.0, 1.0, 0.0, 0.0, 0.0]
    """
    st, st_len = in_plane(n, s, ns)
    e = forward_direction(n, st, st_len, o, no, tol)
    of, op = observer_components(n, e, o)
    ti, trp, phi = frame_angles(st_len, ns, of, op, no, False)
    return ti * _RAD2DEG, trp * _RAD2DEG - ti * _RAD2DEG, phi * _RAD2DEG, e, op


@numba.njit(nogil=True, cache=True, inline="always")
def tangent_azimuth(
    n: Vec, tangent: Vec, e: Vec, op: float, tol: float
) -> float:  # pragma: no cover - compiled
    """``psi`` [degree], the azimuth of the illumination plane (``e_f`` of
    :func:`facet_frame`) from the facet tangent, before its reduction to ``[0, 180)``:
    :func:`sbrdf_xr.geometry.anisotropy.illumination_azimuth` (the tangent made orthogonal to the
    normal; mirrored when the observer is below the plane, ``o.p < -tol``).

    Examples
    --------
    The plane runs along ``+x``; tangents ``+x``, ``+y`` and along the diagonal:

    >>> from sbrdf_xr.kernels.angles import tangent_azimuth
    >>> z, x = (0.0, 0.0, 1.0), (1.0, 0.0, 0.0)
    >>> tangents = (x, (0.0, 1.0, 0.0), (1.0, 1.0, 0.3))
    >>> [round(tangent_azimuth(z, t, x, 0.0, 1e-12), 9) + 0.0 for t in tangents]
    [0.0, -90.0, -45.0]
    """
    tn = _dot(tangent, n)
    t = (tangent[0] - tn * n[0], tangent[1] - tn * n[1], tangent[2] - tn * n[2])
    t_len = np.sqrt(_dot(t, t))
    t = (t[0] / t_len, t[1] / t_len, t[2] / t_len)
    psi = np.arctan2(_dot(e, _cross(n, t)), _dot(e, t)) * _RAD2DEG
    return -psi if op < -tol else psi
