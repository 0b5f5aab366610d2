"""The facet angles of paper 000 Fig. 4 for a chunk of geometries x terms, in one
vectorisable pass (the first stage of :func:`sbrdf_xr.kernels.sums.fused_sums`).

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

__all__ = ["atan2_pos", "chunk_angles", "facet_frame"]

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
    sx, sy, sz = s_t[0], s_t[1], s_t[2]
    ox, oy, oz = o_t[0], o_t[1], o_t[2]
    for t in range(normals.shape[0]):
        nx, ny, nz = normals[t, 0], normals[t, 1], normals[t, 2]
        for j in range(nc):
            g = g0 + j
            a, b, c = sx[g], sy[g], sz[g]
            u, v, w = ox[g], oy[g], oz[g]
            ns = nx * a + ny * b + nz * c
            no = nx * u + ny * v + nz * w
            stx, sty, stz = a - ns * nx, b - ns * ny, c - ns * nz
            # projected twice, as geometry._tangential: in the plane to eps |s_t|
            d = stx * nx + sty * ny + stz * nz
            stx, sty, stz = stx - d * nx, sty - d * ny, stz - d * nz
            st = np.sqrt(stx * stx + sty * sty + stz * stz)
            ti = atan2_pos(st, ns)
            inv = 1.0 / st
            ex, ey, ez = -stx * inv, -sty * inv, -stz * inv
            px = ny * ez - nz * ey
            py = nz * ex - nx * ez
            pz = nx * ey - ny * ex
            of = u * ex + v * ey + w * ez
            op = u * px + v * py + w * pz
            trp = atan2_pos(of, no)
            phi = atan2_pos(abs(op), np.sqrt(of * of + no * no))
            ns_out[t, j] = ns
            no_out[t, j] = no
            st_out[t, j] = st
            ti_out[t, j] = ti * _RAD2DEG
            dt_out[t, j] = trp * _RAD2DEG - ti * _RAD2DEG
            phi_out[t, j] = phi * _RAD2DEG


@numba.njit(nogil=True, cache=True, inline="always")
def facet_frame(
    nx: float,
    ny: float,
    nz: float,
    sx: float,
    sy: float,
    sz: float,
    ox: float,
    oy: float,
    oz: float,
    ns: float,
    no: float,
    tol: float,
) -> tuple[float, float, float, float, float, float, float]:  # pragma: no cover - compiled
    """The angles of paper 000 Fig. 4 of one lit and seen pair, as
    :func:`sbrdf_xr.geometry.facet_angles`: ``(theta_i, delta_theta, phi)`` [degree], the
    forward in-plane unit vector ``e`` and the observer's out-of-plane component ``o.p``.

    ``ns``, ``no`` are ``N.s`` and ``N.o``; at normal incidence (in-plane Sun component
    under ``tol``) the plane is taken through the observer, or through the axis least
    aligned with ``N`` when the observer is on the normal too.

    Examples
    --------
    The Sun 30 deg from the normal ``+z`` and the observer at the specular direction:
    ``delta_theta = phi = 0`` and the forward vector ``e`` points away from the Sun.

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.angles import facet_frame
    >>> c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    >>> r = facet_frame(0.0, 0.0, 1.0, s, 0.0, c, -s, 0.0, c, c, c, 1e-12)
    >>> [round(v, 6) + 0.0 for v in r]  # theta_i, delta_theta, phi, e, o.p
    [30.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0]

    At normal incidence the plane goes through the observer (here 40 deg off the normal
    towards ``+x``), so ``delta_theta`` is the observer's polar angle:

    >>> c4, s4 = np.cos(np.radians(40)), np.sin(np.radians(40))
    >>> r = facet_frame(0.0, 0.0, 1.0, 0.0, 0.0, 1.0, s4, 0.0, c4, 1.0, c4, 1e-12)
    >>> [round(v, 6) + 0.0 for v in r]
    [0.0, 40.0, 0.0, 1.0, 0.0, 0.0, 0.0]
    """
    stx, sty, stz = sx - ns * nx, sy - ns * ny, sz - ns * nz
    d = stx * nx + sty * ny + stz * nz  # projected twice, as geometry._tangential
    stx, sty, stz = stx - d * nx, sty - d * ny, stz - d * nz
    st_len = np.sqrt(stx * stx + sty * sty + stz * stz)
    theta_i = np.arctan2(st_len, ns)
    if st_len <= tol:
        otx, oty, otz = ox - no * nx, oy - no * ny, oz - no * nz
        d = otx * nx + oty * ny + otz * nz
        otx, oty, otz = otx - d * nx, oty - d * ny, otz - d * nz
        ot_len = np.sqrt(otx * otx + oty * oty + otz * otz)
        if ot_len > tol:
            ex, ey, ez = otx / ot_len, oty / ot_len, otz / ot_len
        else:
            # a perpendicular: cross with the axis least aligned with n
            ax, ay, az = abs(nx), abs(ny), abs(nz)
            if ax <= ay and ax <= az:
                ex, ey, ez = 0.0, nz, -ny
            elif ay <= az:
                ex, ey, ez = -nz, 0.0, nx
            else:
                ex, ey, ez = ny, -nx, 0.0
            el = np.sqrt(ex * ex + ey * ey + ez * ez)
            ex, ey, ez = ex / el, ey / el, ez / el
    else:
        ex, ey, ez = -stx / st_len, -sty / st_len, -stz / st_len
    px = ny * ez - nz * ey
    py = nz * ex - nx * ez
    pz = nx * ey - ny * ex
    of = ox * ex + oy * ey + oz * ez
    op = ox * px + oy * py + oz * pz
    trp = np.arctan2(of, no)
    phi = np.arctan2(abs(op), np.hypot(of, no)) * _RAD2DEG
    dt = trp * _RAD2DEG - theta_i * _RAD2DEG
    return theta_i * _RAD2DEG, dt, phi, ex, ey, ez, op
