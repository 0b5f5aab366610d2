"""The spin model, its chi-square, and the searches over a grid of candidate spin states.

See :func:`sbrdf_xr.invert.fit_spin`.  Three ways to evaluate the grid:

``direct``
    Every candidate (axis, period, phase) at every time through the compiled kernel: exact.
``table``
    Per axis, the kernel at every distinct time on ``n_angles`` spin angles; each (period,
    phase) reads the band signal at its angle ``phase + 360 t / P`` by periodic cubic
    (Catmull-Rom) interpolation.  The geometry is exact; only the spin angle is
    interpolated.  Cheaper than ``direct`` when periods x phases exceed ``n_angles``.
``shift``
    One such table per axis at the mean Sun and observer directions: exact in the
    geometry only when the directions are fixed.
``bound``
    Such tables with an error estimate give every candidate a lower bound of its
    chi-square; only candidates that can still beat the best go through the kernel
    (:mod:`sbrdf_xr.invert._spin.bound`): the best state is the ``direct`` one's.

An approximate search is checked against the exact model (:func:`approximation_error`).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ...errors import InversionError, renamed_keywords
from ...kernels import sums as _kernels
from ...units import to_unit
from .data import SpinGeometry

__all__ = [
    "METHODS",
    "Kernel",
    "Problem",
    "align_matrices",
    "approximation_error",
    "body_vectors",
    "fibonacci_sphere",
    "lonlat",
    "run_search",
    "spin_model",
    "vec",
]

#: Grid evaluations of :func:`run_search`.
METHODS = ("direct", "table", "shift")
#: Working memory of one block of the search (candidates x times, or periods x values).
BLOCK_BYTES = 64 * 2**20


def fibonacci_sphere(n: int) -> np.ndarray:
    """``n`` nearly uniform unit vectors (the Fibonacci lattice, Gonzalez 2010, Math.
    Geosci. 42, 49), shape (n, 3).

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.invert import fibonacci_sphere
    >>> v = fibonacci_sphere(4)
    >>> v[:, 2].tolist()  # z in equal steps from 1 - 1/n to -(1 - 1/n)
    [0.75, 0.25, -0.25, -0.75]
    >>> v[0].round(4).tolist()
    [0.2397, 0.6165, 0.75]
    >>> np.allclose(np.linalg.norm(fibonacci_sphere(100), axis=1), 1.0)
    True
    """
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    r = np.sqrt(np.clip(1.0 - z * z, 0, None))
    phi = np.pi * (3.0 - np.sqrt(5.0)) * i
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)


def lonlat(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return (
        np.degrees(np.arctan2(v[..., 1], v[..., 0])) % 360.0,
        np.degrees(np.arcsin(np.clip(v[..., 2], -1, 1))),
    )


def vec(lon: Any, lat: Any) -> np.ndarray:
    lo, la = np.radians(lon), np.radians(lat)
    return np.stack([np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la)], axis=-1)


def align_matrices(axis_body: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """Rotation matrices (n, 3, 3) taking ``axis_body`` to each inertial ``axes`` (shortest arc)."""
    from scipy.spatial.transform import Rotation

    b = axis_body / np.linalg.norm(axis_body)
    c = np.cross(b, axes)
    s = np.linalg.norm(c, axis=-1)
    d = axes @ b
    ang = np.arctan2(s, d)
    perp = np.cross(b, [1.0, 0, 0] if abs(b[0]) < 0.9 else [0, 1.0, 0])
    perp /= np.linalg.norm(perp)
    u = np.where(s[:, None] > 1e-12, c / np.where(s > 1e-12, s, 1)[:, None], perp)
    return Rotation.from_rotvec(u * ang[:, None]).as_matrix()


@renamed_keywords(period_s="period", phase_deg="phase")
def spin_model(
    axis_body: ArrayLike, axis: ArrayLike, period: float, phase: float, epoch: Any = None
) -> Any:
    """The :class:`sbrdf_xr.observing.attitude.Spin` law of a spin state: the body turns about
    ``axis_body`` at ``360/period`` degree s-1 from the attitude that takes
    ``axis_body`` to the inertial ``axis`` by the shortest arc, angle ``phase`` at
    ``epoch`` (UTC; default t = 0, or the start of an observation).

    Parameters
    ----------
    axis_body : array_like, shape (3,)
        The body's spin axis.
    axis : array_like, shape (3,)
        Its inertial direction.
    period : float
        Spin period [s]; a Quantity is converted.
    phase : float
        Spin angle at ``epoch`` [degree]; a Quantity is converted.
    epoch : optional
        UTC time of ``phase``.

    Examples
    --------
    A body spinning about its z axis once a minute, that axis pointing along inertial x:

    >>> from sbrdf_xr import geometry
    >>> from sbrdf_xr.invert import spin_model
    >>> spin = spin_model([0, 0, 1], [1.0, 0.0, 0.0], period=60.0, phase=0.0)
    >>> spin.rate, spin.phase
    (6.0, 0.0)
    >>> q = spin.quaternions([0.0, 15.0])
    >>> geometry.to_body_frame(q, [1.0, 0.0, 0.0]).round(6).tolist()  # inertial x: body z
    [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]
    """
    from scipy.spatial.transform import Rotation

    from ...observing.attitude import Spin

    m = align_matrices(np.asarray(axis_body, float), np.asarray(axis, float)[None, :])[0]
    q = Rotation.from_matrix(m).as_quat()
    return Spin(
        axis_body=np.asarray(axis_body, float),
        rate=360.0 / float(to_unit(period, "s", "period")),
        phase=float(to_unit(phase, "deg", "phase")),
        initial=q,
        epoch=epoch,
    )


def body_vectors(v: np.ndarray, align: np.ndarray, k: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Body-frame ``R(t)^T v`` for ``R = align R_k(angle)``: ``u = align^T v`` rotated by
    ``-angle`` about ``k`` (Rodrigues).  Shapes: v (T, 3), align (C, 3, 3), angle (C, T) [rad]
    -> (C, T, 3)."""
    u = np.einsum("cji,tj->cti", align, v)
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    kd = u @ k
    return u * c - np.cross(k, u) * s + k * (kd[..., None] * (1 - c))


class Kernel:
    """Band signal of a spacecraft for body-frame geometries, on pre-integrated tables,
    times ``band_factors`` (one per band, default 1: see
    :func:`sbrdf_xr.invert._spin.data.band_factors`)."""

    def __init__(
        self,
        spacecraft: Any,
        bands: Sequence[str],
        materials: Mapping[str, Any] | None = None,
        method: str = "linear",
        band_factors: ArrayLike | None = None,
    ) -> None:
        from ...engine import Scene

        f = fibonacci_sphere(256)
        scene = Scene(
            spacecraft,
            materials=materials,
            to_sun=f,
            to_observer=f,
            outputs=("band_signal", "area"),
            bands=tuple(bands),
            method=method,
        )
        self.plan = plan = scene.plan()
        #: Where each material's table comes from (its ``source`` attribute).
        self.sources = {
            str(m): str(scene.material_data[m].attrs.get("source", ""))
            for m in plan.materials
            if m in scene.material_data
        }
        if not plan.pre_integrated:
            raise InversionError("spin fit: the band tables could not be pre-integrated")
        self.bands = tuple(str(b) for b in plan.bands)
        self.method = method
        self.band_factors = (
            np.ones(len(self.bands))
            if band_factors is None
            else np.asarray(band_factors, dtype=np.float64).reshape(len(self.bands))
        )

    @property
    def materials(self) -> tuple[str, ...]:
        """The materials of the plan, in the order of ``per_material`` outputs."""
        return tuple(str(m) for m in self.plan.materials)

    def __call__(self, s: np.ndarray, o: np.ndarray, per_material: bool = False) -> np.ndarray:
        """Band signal (..., B) [m2 sr-1] at body-frame directions (..., 3); with
        ``per_material`` the signal of each material, (..., M, B) (:attr:`materials`)."""
        t = self.plan.terms
        r = _kernels.fused_sums(
            s.reshape(-1, 3),
            o.reshape(-1, 3),
            t.normal,
            t.area,
            t.material,
            self.plan.tables,
            self.method,
            None,
            per_material,
        )
        if per_material:
            shape = (*s.shape[:-1], len(self.materials), len(self.bands))
            return np.asarray(r.per_material, dtype=np.float64).reshape(shape) * self.band_factors
        sig = np.asarray(r.signal, dtype=np.float64).reshape(*s.shape[:-1], len(self.bands))
        return sig * self.band_factors


class Problem:
    """A light curve, its geometry and the model: chi-square of spin states.

    Times are counted from ``t_ref`` (the middle of the light curve), where the phase of
    the search is defined: this halves the phase slip of a period step and decorrelates
    period and phase.
    """

    def __init__(
        self,
        lc: Mapping[str, np.ndarray],
        geo: SpinGeometry,
        kernel: Kernel,
        axis_body: np.ndarray,
        offset: str,
    ) -> None:
        if offset not in ("band", "common"):
            raise InversionError(
                f"offset: {offset!r}; allowed 'band' (a free scale per band), 'common'"
            )
        self.t_ref = 0.5 * float(geo.times[0] + geo.times[-1])
        self.times = geo.times - self.t_ref
        self.t_index = geo.t_index
        self.band = np.asarray(lc["band"])
        self.y, self.sigma = np.asarray(lc["flux"]), np.asarray(lc["sigma"])
        self.w = 1.0 / self.sigma**2
        self.kernel = kernel
        self.s, self.o, self.factor = geo.to_sun, geo.to_observer, geo.factor
        self.k = axis_body / np.linalg.norm(axis_body)
        self.offset = offset
        self.n_bands = len(lc["labels"])
        self.fixed = bool(np.allclose(self.s, self.s[0]) and np.allclose(self.o, self.o[0]))

    @property
    def n_scales(self) -> int:
        return 1 if self.offset == "common" else self.n_bands

    def subset(self, max_times: int) -> Problem:
        """The same problem on at most ``max_times`` distinct times spread evenly over the
        light curve (every value at those times; the same reference time)."""
        n = self.times.size
        if n <= max_times:
            return self
        keep = np.unique(np.round(np.linspace(0, n - 1, max_times)).astype(np.int64))
        rows = np.isin(self.t_index, keep)
        other = object.__new__(Problem)
        other.__dict__.update(self.__dict__)
        other.times, other.s, other.o, other.factor = (
            a[keep] for a in (self.times, self.s, self.o, self.factor)
        )
        other.t_index = np.searchsorted(keep, self.t_index[rows])
        other.band, other.y, other.sigma, other.w = (
            a[rows] for a in (self.band, self.y, self.sigma, self.w)
        )
        return other

    def model(self, axes: np.ndarray, periods: np.ndarray, phases: np.ndarray) -> np.ndarray:
        """Band signal at every value (C, N) for candidates (C,) of axis (C, 3), period, phase."""
        align = align_matrices(self.k, axes)
        ang = np.radians(phases[:, None] + 360.0 * self.times[None, :] / periods[:, None])
        sig = self.kernel(
            body_vectors(self.s, align, self.k, ang), body_vectors(self.o, align, self.k, ang)
        )  # (C, T, B)
        return sig[:, self.t_index, self.band] * self.factor[self.t_index]

    def scales(self, mdl: np.ndarray) -> np.ndarray:
        """Analytic weighted least-squares flux scale per band (C, N)."""
        wy, wm = self.w * self.y, self.w * mdl
        if self.offset == "common":
            k = (wm * self.y).sum(-1) / np.maximum((wm * mdl).sum(-1), 1e-300)
            return np.broadcast_to(k[:, None], mdl.shape)
        num = np.zeros((mdl.shape[0], self.n_bands))
        den = np.zeros_like(num)
        for b in range(self.n_bands):
            sel = self.band == b
            num[:, b] = (wy[sel] * mdl[:, sel]).sum(-1)
            den[:, b] = (wm[:, sel] * mdl[:, sel]).sum(-1)
        return (num / np.maximum(den, 1e-300))[:, self.band]

    def chi2_of(self, mdl: np.ndarray) -> np.ndarray:
        r = (self.y - self.scales(mdl) * mdl) / self.sigma
        return (r * r).sum(-1)

    def chi2(self, axes: np.ndarray, periods: np.ndarray, phases: np.ndarray) -> np.ndarray:
        return self.chi2_of(self.model(axes, periods, phases))


def _threads(n_threads: int | None) -> int:
    return max(1, n_threads or os.cpu_count() or 1)


def _map(fn: Callable[[int], None], n: int, n_threads: int | None) -> None:
    workers = _threads(n_threads)
    if workers == 1 or n == 1:
        for j in range(n):
            fn(j)
    else:
        with ThreadPoolExecutor(workers, thread_name_prefix="sbrdf_xr-invert") as pool:
            list(pool.map(fn, range(n)))


def search_direct(
    prob: Problem,
    axes: np.ndarray,
    periods: np.ndarray,
    phases: np.ndarray,
    n_threads: int | None,
) -> np.ndarray:
    """Chi-square over the grid (axes, periods, phases), every candidate through the kernel."""
    shape = (len(axes), len(periods), len(phases))
    total = int(np.prod(shape))
    per = 8 * prob.times.size * (6 + 2 * prob.n_bands) + 8 * 4 * prob.y.size
    chunk = max(1, min(4096, BLOCK_BYTES // per))
    out = np.empty(total)
    edges = [*range(0, total, chunk), total]

    def run(j: int) -> None:
        ia, ip, iq = np.unravel_index(np.arange(edges[j], edges[j + 1]), shape)
        out[edges[j] : edges[j + 1]] = prob.chi2(axes[ia], periods[ip], phases[iq])

    _map(run, len(edges) - 1, n_threads)
    return out.reshape(shape)


def _tables(prob: Problem, axis: np.ndarray, n_angles: int, mean: bool) -> np.ndarray:
    """Band signal (T or 1, n_angles, B) of one axis on the spin-angle grid."""
    align = align_matrices(prob.k, axis[None, :])[0]
    ang = np.arange(n_angles) * (2 * np.pi / n_angles)
    c, s = np.cos(ang)[None, :, None], np.sin(ang)[None, :, None]

    def body(v: np.ndarray) -> np.ndarray:
        if mean:
            m = v.mean(0)
            v = (m / np.linalg.norm(m))[None, :]
        u = (v @ align)[:, None, :]  # align^T v, (T, 1, 3)
        kd = (u @ prob.k)[..., None]
        return u * c - np.cross(prob.k, u) * s + prob.k * (kd * (1 - c))

    return prob.kernel(body(prob.s), body(prob.o))


def _interpolate(
    f: np.ndarray, prob: Problem, periods: np.ndarray, phases: np.ndarray, mean: bool
) -> np.ndarray:
    """The model of every (period, phase) from the tables ``f``: (P * Q, N)."""
    n = f.shape[1]
    rows = np.zeros_like(prob.t_index) if mean else prob.t_index
    fo = f[rows, :, prob.band]  # (N, n_angles)
    t = prob.times[prob.t_index]
    x = ((phases[None, :, None] + 360.0 * t / periods[:, None, None]) % 360.0) * (n / 360.0)
    j = np.floor(x).astype(np.int64)
    w = x - j
    i = np.arange(t.size)
    p0, p1, p2, p3 = (fo[i, (j + d) % n] for d in (-1, 0, 1, 2))
    m = p1 + 0.5 * w * (
        p2 - p0 + w * (2 * p0 - 5 * p1 + 4 * p2 - p3 + w * (3 * (p1 - p2) + p3 - p0))
    )
    return m.reshape(-1, t.size) * prob.factor[prob.t_index]


def search_table(
    prob: Problem,
    axes: np.ndarray,
    periods: np.ndarray,
    phases: np.ndarray,
    n_threads: int | None,
    n_angles: int,
    mean: bool,
) -> np.ndarray:
    """Chi-square over the grid from per-axis spin-angle tables (``table``, or ``shift``)."""
    out = np.empty((len(axes), len(periods), len(phases)))
    per_period = 8 * 12 * len(phases) * prob.y.size
    step = max(1, BLOCK_BYTES // per_period)

    def run(i: int) -> None:
        f = _tables(prob, axes[i], n_angles, mean)
        for p0 in range(0, len(periods), step):
            ps = periods[p0 : p0 + step]
            out[i, p0 : p0 + step] = prob.chi2_of(_interpolate(f, prob, ps, phases, mean)).reshape(
                ps.size, len(phases)
            )

    _map(run, len(axes), n_threads)
    return out


def run_search(
    method: str,
    prob: Problem,
    axes: np.ndarray,
    periods: np.ndarray,
    phases: np.ndarray,
    n_threads: int | None,
    n_angles: int,
) -> np.ndarray:
    """The chi-square grid by ``method`` (one of :data:`METHODS`)."""
    if method == "direct":
        return search_direct(prob, axes, periods, phases, n_threads)
    return search_table(prob, axes, periods, phases, n_threads, n_angles, method == "shift")


def approximation_error(
    method: str,
    prob: Problem,
    axes: np.ndarray,
    cells: Sequence[tuple[int, float, float]],
    n_angles: int,
) -> float:
    """Largest rms over the values of ``(approximate - exact model) / sigma`` at the
    candidate ``cells`` (axis index, period, phase), each model with its exact flux scales.
    """
    worst = 0.0
    for ia, per, ph in cells:
        p, q = np.array([per]), np.array([ph])
        exact = prob.model(axes[ia : ia + 1], p, q)
        f = _tables(prob, axes[ia], n_angles, method == "shift")
        approx = _interpolate(f, prob, p, q, method == "shift")
        d = prob.scales(exact) * (approx - exact) / prob.sigma
        worst = max(worst, float(np.sqrt(np.mean(d * d))))
    return worst
