"""Compiled Fresnel reflectances: the formulas of :mod:`sbrdf_xr.brdf.optics`, element by element.

The numpy functions of :mod:`sbrdf_xr.brdf.optics` evaluate a thin-film stack with about
fifteen complex temporaries over the whole ``(geometry, wavelength)`` array; a catalog
table renders and integrates its model at some 2e8 such points.  The kernels here
compute the same quantities one point at a time (numba, ``nogil``), so that memory stays
at the output and the rows are shared between threads.  They agree with the numpy
reference (kept in :mod:`sbrdf_xr.brdf.optics` and checked against it in the tests) to a
few units in the last place: the arithmetic is the same, grouped differently (for a
non-absorbing layer the phase factor ``exp(2 i delta)`` is a pure rotation and is
written with one sine and cosine of ``delta``; ``|a / b|^2`` is ``|a|^2 / |b|^2``).

Layout: cosines ``c`` of shape ``(n, m)`` with ``m`` 1 (one cosine for every wavelength)
or ``n_wl`` (a cosine per wavelength), wavelength-aligned constants of shape
``(n_wl,)`` or ``(n_layers, n_wl)``, and an output of shape ``(n, n_wl)``.
"""

from __future__ import annotations

import itertools
import math
import os
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor

import numba
import numpy as np
from numpy.typing import NDArray

#: Points (rows x wavelengths) below which a call runs in the calling thread.
_THREAD_MIN = 200_000


@numba.njit(nogil=True, cache=True, inline="always", error_model="numpy")
def _q(n2: complex, sin2: float) -> complex:  # pragma: no cover - compiled
    """``sqrt(N^2 - n0^2 sin^2 theta_0)`` on the decaying branch (``Im >= 0``)."""
    root = np.sqrt(complex(n2.real - sin2, n2.imag))
    return -root if root.imag < 0 else root


@numba.njit(nogil=True, cache=True, error_model="numpy")
def _conductor_rows(
    c: np.ndarray, n2: np.ndarray, out: np.ndarray, start: int, stop: int
) -> None:  # pragma: no cover - compiled
    """Rows ``start:stop`` of the bare-interface reflectance (``fresnel_conductor``)."""
    n_wl = n2.size
    per_wl = c.shape[1] > 1
    for i in range(start, stop):
        for w in range(n_wl):
            cc = c[i, w] if per_wl else c[i, 0]
            m2 = n2[w]
            q = _q(m2, 1.0 - cc * cc)
            ns = cc - q
            ds = cc + q
            mc = m2 * cc
            np_ = mc - q
            dp = mc + q
            v = 0.5 * (
                (ns.real * ns.real + ns.imag * ns.imag) / (ds.real * ds.real + ds.imag * ds.imag)
                + (np_.real * np_.real + np_.imag * np_.imag)
                / (dp.real * dp.real + dp.imag * dp.imag)
            )
            out[i, w] = min(max(v, 0.0), 1.0)


@numba.njit(nogil=True, cache=True, error_model="numpy")
def _stack_rows(
    c: np.ndarray,
    kd: np.ndarray,
    n2l: np.ndarray,
    n2sub: np.ndarray,
    n0: float,
    out: np.ndarray,
    start: int,
    stop: int,
) -> None:  # pragma: no cover - compiled
    """Rows ``start:stop`` of the thin-film stack reflectance (``fresnel_thin_film_stack``).

    ``kd[j, w] = 2 k0 d_j`` (``k0 = 2 pi / lambda``), ``n2l[j, w] = N_j^2`` (ambient side
    first), ``n2sub[w] = N_sub^2``; the characteristic matrices of every layer, each
    multiplied by ``exp(i delta)``, applied to ``[B, C]`` from the substrate up.
    """
    n_layers, n_wl = kd.shape
    per_wl = c.shape[1] > 1
    n0sq = n0 * n0
    for i in range(start, stop):
        for w in range(n_wl):
            cc = c[i, w] if per_wl else c[i, 0]
            sin2 = n0sq * (1.0 - cc * cc)
            q0 = n0 * cc
            qs = _q(n2sub[w], sin2)
            # s: [B, C] = [1, q_sub]; p (scaled by q_sub): [q_sub, N_sub^2]
            bs = complex(1.0, 0.0)
            cs = qs
            bp = qs
            cp = n2sub[w]
            for jj in range(n_layers):
                j = n_layers - 1 - jj
                n2 = n2l[j, w]
                if n2.imag == 0.0 and n2.real > sin2:
                    # real q (a transparent layer above its critical angle): the matrix
                    # [[cos, -i sin/q], [-i q sin, cos]] itself, without the factor
                    # exp(i delta) of modulus 1 (which cancels in r)
                    qr = math.sqrt(n2.real - sin2)
                    delta = 0.5 * kd[j, w] * qr
                    sd = math.sin(delta)
                    cd = math.cos(delta)
                    soq = sd / qr
                    stq = sd * qr
                    eta2 = n2.real
                    bs, cs = (
                        complex(cd * bs.real + soq * cs.imag, cd * bs.imag - soq * cs.real),
                        complex(cd * cs.real + stq * bs.imag, cd * cs.imag - stq * bs.real),
                    )
                    soq_p = stq / eta2  # -i (q sin / N^2) for p
                    stq_p = eta2 * soq  # -i (N^2 sin / q)
                    bp, cp = (
                        complex(cd * bp.real + soq_p * cp.imag, cd * bp.imag - soq_p * cp.real),
                        complex(cd * cp.real + stq_p * bp.imag, cd * cp.imag - stq_p * bp.real),
                    )
                    continue
                # an absorbing layer (or beyond its critical angle): complex q, each matrix
                # times exp(i delta), |exp(i delta)| <= 1, so that a thick one cannot overflow
                q = _q(n2, sin2)
                z = kd[j, w] * q  # 2 delta; E = exp(i z)
                zr = -z.imag
                zi = z.real
                a = math.sin(0.5 * zi)
                em1 = complex(
                    math.expm1(zr) * math.cos(zi) - 2.0 * a * a, math.exp(zr) * math.sin(zi)
                )
                half_sum = 1.0 + 0.5 * em1
                st = complex(0.5 * em1.imag, -0.5 * em1.real)  # (E - 1) / (2 i)
                if abs(q) < 1e-150:
                    sin_over_q = complex(0.5 * kd[j, w], 0.0)  # the limit k0 d
                else:
                    sin_over_q = st / q
                sin_times_q = st * q
                mis = complex(sin_over_q.imag, -sin_over_q.real)  # -i sin/q
                mit = complex(sin_times_q.imag, -sin_times_q.real)  # -i q sin
                bs, cs = half_sum * bs + mis * cs, mit * bs + half_sum * cs
                bp, cp = half_sum * bp + mit / n2 * cp, n2 * mis * bp + half_sum * cp
            a1 = q0 * bs
            a2 = n0sq * bp
            a3 = q0 * cp
            ns = a1 - cs
            ds = a1 + cs
            np_ = a2 - a3
            dp = a2 + a3
            v = 0.5 * (
                (ns.real * ns.real + ns.imag * ns.imag) / (ds.real * ds.real + ds.imag * ds.imag)
                + (np_.real * np_.real + np_.imag * np_.imag)
                / (dp.real * dp.real + dp.imag * dp.imag)
            )
            out[i, w] = min(max(v, 0.0), 1.0)


def _workers() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not on Linux
        return max(1, os.cpu_count() or 1)


def _run_rows(kernel: Callable[..., None], n_rows: int, n_wl: int, *args: object) -> None:
    """``kernel(*args, start, stop)`` over the rows, split between the available cores."""
    k = _workers()
    if k == 1 or n_rows * n_wl < _THREAD_MIN:
        kernel(*args, 0, n_rows)
        return
    bounds = np.linspace(0, n_rows, 4 * k + 1).astype(int)
    with ThreadPoolExecutor(k) as pool:
        jobs: list[Future[None]] = [
            pool.submit(kernel, *args, int(a), int(b))
            for a, b in itertools.pairwise(bounds)
            if b > a
        ]
        for j in jobs:
            j.result()


def conductor_reflectance(
    c: NDArray[np.float64], n2: NDArray[np.complex128]
) -> NDArray[np.float64]:
    """Bare-interface reflectance at cosines ``c`` ``(n, 1 | n_wl)`` for ``N^2`` ``(n_wl,)``."""
    c = np.ascontiguousarray(c, dtype=np.float64)
    n2 = np.ascontiguousarray(n2, dtype=np.complex128)
    out = np.empty((c.shape[0], n2.size))
    _run_rows(_conductor_rows, c.shape[0], n2.size, c, n2, out)
    return out


def stack_reflectance(
    c: NDArray[np.float64],
    kd: NDArray[np.float64],
    n2l: NDArray[np.complex128],
    n2sub: NDArray[np.complex128],
    n0: float,
) -> NDArray[np.float64]:
    """Thin-film stack reflectance at cosines ``c`` ``(n, 1 | n_wl)`` (see :func:`_stack_rows`)."""
    c = np.ascontiguousarray(c, dtype=np.float64)
    kd = np.ascontiguousarray(kd, dtype=np.float64).reshape(-1, n2sub.size)
    n2l = np.ascontiguousarray(n2l, dtype=np.complex128).reshape(-1, n2sub.size)
    n2sub = np.ascontiguousarray(n2sub, dtype=np.complex128)
    out = np.empty((c.shape[0], n2sub.size))
    _run_rows(_stack_rows, c.shape[0], n2sub.size, c, kd, n2l, n2sub, float(n0), out)
    return out
