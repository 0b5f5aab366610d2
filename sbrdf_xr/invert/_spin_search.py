"""The spin-state model and its chi-square, and the global search over candidate spin states.

A spin state (inertial axis, period, phase) turns the Sun and observer directions into
body-frame geometries; :class:`Kernel` gives the band signal there from pre-integrated
tables; :class:`Problem` holds a light curve with its geometry and returns the chi-square
of candidates, the flux scale of each band solved in closed form; :func:`search` and
:func:`search_shift` evaluate it over a grid of candidates (see :func:`sbrdf_xr.invert.fit_spin`).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from ..errors import InversionError
from ..kernels import sums as _kernels

__all__ = [
    "LN10_2P5",
    "Kernel",
    "Problem",
    "align_matrices",
    "body_vectors",
    "directions",
    "fibonacci_sphere",
    "light_curve_fluxes",
    "lonlat",
    "search",
    "search_shift",
    "spin_model",
    "vec",
]

#: ln(10) / 2.5: d(flux) / flux per magnitude.
LN10_2P5 = np.log(10.0) / 2.5


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


def spin_model(axis_body: ArrayLike, axis: ArrayLike, period_s: float, phase_deg: float) -> Any:
    """The :class:`sbrdf_xr.observing.attitude.Spin` law of a spin state: the body turns about
    ``axis_body`` at ``360/period_s`` degree s-1 from the attitude that takes
    ``axis_body`` to the inertial ``axis`` by the shortest arc, angle ``phase_deg`` at t = 0.

    Examples
    --------
    A body spinning about its z axis once a minute, that axis pointing along inertial x:

    >>> from sbrdf_xr import geometry
    >>> from sbrdf_xr.invert import spin_model
    >>> spin = spin_model([0, 0, 1], [1.0, 0.0, 0.0], period_s=60.0, phase_deg=0.0)
    >>> spin.rate_deg_s, spin.phase_deg
    (6.0, 0.0)
    >>> q = spin.quaternions([0.0, 15.0])
    >>> geometry.to_body_frame(q, [1.0, 0.0, 0.0]).round(6).tolist()  # inertial x: body z
    [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]
    """
    from scipy.spatial.transform import Rotation

    from ..observing.attitude import Spin

    m = align_matrices(np.asarray(axis_body, float), np.asarray(axis, float)[None, :])[0]
    q = Rotation.from_matrix(m).as_quat()
    return Spin(
        axis_body=np.asarray(axis_body, float),
        rate_deg_s=360.0 / float(period_s),
        phase_deg=float(phase_deg),
        initial=q,
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
    """Band signal of a spacecraft for body-frame geometries, on pre-integrated tables."""

    def __init__(
        self,
        spacecraft: Any,
        bands: Sequence[str],
        materials: Mapping[str, Any] | None = None,
        method: str = "linear",
    ) -> None:
        from ..engine import Scene

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
        if not plan.pre_integrated:
            raise InversionError("spin fit: the band tables could not be pre-integrated")
        self.bands = tuple(str(b) for b in plan.bands)
        self.method = method

    def __call__(self, s: np.ndarray, o: np.ndarray) -> np.ndarray:
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
            False,
        )
        return np.asarray(r.signal, dtype=np.float64).reshape(*s.shape[:-1], len(self.bands))


def light_curve_fluxes(
    light_curve: xr.Dataset, bands: Sequence[str] | None = None
) -> dict[str, np.ndarray]:
    """Times [s], band index, relative flux and its uncertainty from a light curve.

    ``light_curve`` is what :func:`sbrdf_xr.photometry.read_light_curve` returns (over
    ``obs``: ``magnitude``, ``uncertainty`` [mag], coords ``band``, ``time`` [s]) or the
    same with ``flux`` and ``flux_uncertainty`` instead of magnitudes.

    Examples
    --------
    Magnitudes become fluxes relative to the median magnitude (9.75 here),
    ``10**(-0.4 (m - 9.75))``:

    >>> import xarray as xr
    >>> from sbrdf_xr.invert import light_curve_fluxes
    >>> lc = xr.Dataset(
    ...     {"magnitude": ("obs", [10.0, 9.5, 10.0, 9.0]), "uncertainty": ("obs", [0.01] * 4)},
    ...     coords={"time": ("obs", [0.0, 0.0, 10.0, 10.0]), "band": ("obs", ["V", "R"] * 2)},
    ... )
    >>> d = light_curve_fluxes(lc)
    >>> d["labels"].tolist(), d["band"].tolist()
    (['V', 'R'], [0, 1, 0, 1])
    >>> d["flux"].round(6).tolist()
    [0.794328, 1.258925, 0.794328, 1.995262]
    """
    if not isinstance(light_curve, xr.Dataset) or (
        "time" not in light_curve.coords and "time" not in light_curve
    ):
        raise InversionError(
            "light curve: expected a Dataset with a time coordinate [s] (read_light_curve)"
        )
    t = np.asarray(light_curve["time"].values, dtype=np.float64)
    band = np.asarray(light_curve["band"].values).astype(str)
    labels = list(dict.fromkeys(band)) if bands is None else [str(b) for b in bands]
    unknown = sorted(set(band) - set(labels))
    if unknown:
        raise InversionError(f"light curve bands {unknown} are not among the model bands {labels}")
    if "flux" in light_curve:
        f = np.asarray(light_curve["flux"].values, dtype=np.float64)
        sf = np.asarray(light_curve["flux_uncertainty"].values, dtype=np.float64)
    elif "magnitude" in light_curve:
        m = np.asarray(light_curve["magnitude"].values, dtype=np.float64)
        sm = np.asarray(light_curve["uncertainty"].values, dtype=np.float64)
        if not np.all(np.isfinite(m)):
            raise InversionError("light curve: magnitudes must be finite")
        f = 10 ** (-0.4 * (m - np.nanmedian(m)))
        sf = f * LN10_2P5 * sm
    else:
        raise InversionError(
            f"light curve: needs magnitude/uncertainty or flux/flux_uncertainty, got "
            f"{list(light_curve.data_vars)}"
        )
    bad = ~(np.isfinite(sf) & (sf > 0))
    if bad.any():
        raise InversionError(
            f"light curve: {int(bad.sum())} uncertainties that are not finite and > 0"
        )
    if not np.all(np.isfinite(t)) or not np.all(np.isfinite(f)):
        raise InversionError("light curve: times and values must be finite")
    return {
        "time": t,
        "band": np.array([labels.index(b) for b in band]),
        "flux": f,
        "sigma": sf,
        "labels": np.array(labels),
    }


def directions(v: Any, n_t: int, name: str) -> np.ndarray:
    arr = np.asarray(v, dtype=np.float64)
    if arr.shape == (3,):
        arr = np.broadcast_to(arr, (n_t, 3))
    if arr.shape != (n_t, 3):
        raise InversionError(
            f"{name}: expected shape (3,) or ({n_t}, 3) (one per distinct time), got {arr.shape}"
        )
    nrm = np.linalg.norm(arr, axis=-1)
    if not np.all(nrm > 0):
        raise InversionError(f"{name}: zero-length direction")
    return arr / nrm[:, None]


class Problem:
    """A light curve, its geometry and the model: chi-square of spin states."""

    def __init__(
        self,
        lc: dict[str, np.ndarray],
        kernel: Kernel,
        to_sun: Any,
        to_observer: Any,
        axis_body: np.ndarray,
        offset: str,
    ) -> None:
        self.times, self.t_index = np.unique(lc["time"], return_inverse=True)
        self.band = lc["band"]
        self.y, self.sigma = lc["flux"], lc["sigma"]
        self.w = 1.0 / self.sigma**2
        self.kernel = kernel
        self.s = directions(to_sun, self.times.size, "to_sun")
        self.o = directions(to_observer, self.times.size, "to_observer")
        self.k = axis_body / np.linalg.norm(axis_body)
        if offset not in ("band", "common"):
            raise InversionError(
                f"offset: {offset!r}; allowed 'band' (a free scale per band), 'common'"
            )
        self.offset = offset
        self.n_bands = len(lc["labels"])

    def model(self, axes: np.ndarray, periods: np.ndarray, phases: np.ndarray) -> np.ndarray:
        """Band signal at every observation (C, N).

        For candidates (C,) of axis (C, 3), period, phase.
        """
        align = align_matrices(self.k, axes)
        ang = np.radians(phases[:, None] + 360.0 * self.times[None, :] / periods[:, None])
        sb = body_vectors(self.s, align, self.k, ang)
        ob = body_vectors(self.o, align, self.k, ang)
        sig = self.kernel(sb, ob)  # (C, T, B)
        return sig[:, self.t_index, self.band]

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

    def chi2(self, axes: np.ndarray, periods: np.ndarray, phases: np.ndarray) -> np.ndarray:
        mdl = self.model(axes, periods, phases)
        r = (self.y - self.scales(mdl) * mdl) / self.sigma
        return (r * r).sum(-1)

    def residuals(self, p: np.ndarray) -> np.ndarray:
        mdl = self.model(vec(p[0], p[1])[None, :], np.array([p[2]]), np.array([p[3]]))
        return ((self.y - self.scales(mdl) * mdl) / self.sigma)[0]

    def at_mean_directions(self) -> Problem:
        """The same problem with the Sun and observer fixed at their mean directions."""
        other = object.__new__(Problem)
        other.__dict__.update(self.__dict__)
        for key in ("s", "o"):
            m = getattr(self, key).mean(0)
            setattr(other, key, np.broadcast_to(m / np.linalg.norm(m), getattr(self, key).shape))
        return other

    @property
    def n_scales(self) -> int:
        return 1 if self.offset == "common" else self.n_bands


def search(
    prob: Problem,
    axes: np.ndarray,
    periods: np.ndarray,
    phases: np.ndarray,
    n_threads: int | None,
    chunk: int = 256,
) -> np.ndarray:
    """Chi-square over the grid (axes, periods, phases), threads over chunks of candidates."""
    ia, ip, iq = (
        g.ravel()
        for g in np.meshgrid(
            np.arange(len(axes)), np.arange(len(periods)), np.arange(len(phases)), indexing="ij"
        )
    )
    out = np.empty(ia.size)
    edges = [*list(range(0, ia.size, chunk)), ia.size]

    def run(j: int) -> None:
        sl = slice(edges[j], edges[j + 1])
        out[sl] = prob.chi2(axes[ia[sl]], periods[ip[sl]], phases[iq[sl]])

    workers = max(1, n_threads or os.cpu_count() or 1)
    if workers == 1:
        for j in range(len(edges) - 1):
            run(j)
    else:
        with ThreadPoolExecutor(workers, thread_name_prefix="sbrdf_xr-invert") as pool:
            list(pool.map(run, range(len(edges) - 1)))
    return out.reshape(len(axes), len(periods), len(phases))


def search_shift(
    prob: Problem,
    axes: np.ndarray,
    periods: np.ndarray,
    phases: np.ndarray,
    n_threads: int | None,
    n_angles: int = 720,
) -> np.ndarray:
    """The same grid for fixed directions: the model depends on the spin angle only, so it
    is evaluated once per axis on ``n_angles`` angles and every (period, phase) reads it
    by linear interpolation at ``phase + 360 t / P``."""
    grid_ang = np.arange(n_angles) * 360.0 / n_angles
    step = 360.0 / n_angles
    out = np.empty((len(axes), len(periods), len(phases)))
    t = prob.times[prob.t_index]

    def run(i: int) -> None:
        align = align_matrices(prob.k, axes[i : i + 1])
        ang = np.radians(grid_ang)[None, :]
        f = prob.kernel(
            body_vectors(prob.s[:1], align, prob.k, ang),
            body_vectors(prob.o[:1], align, prob.k, ang),
        )[0]
        f = np.concatenate([f, f[:1]], axis=0)  # (n_angles + 1, B), periodic
        theta = (phases[None, :, None] + 360.0 * t[None, None, :] / periods[:, None, None]) % 360.0
        x = theta / step
        j = np.minimum(x.astype(np.int64), n_angles - 1)
        w = x - j
        mdl = f[j, prob.band] * (1 - w) + f[j + 1, prob.band] * w
        mdl = mdl.reshape(-1, t.size)
        r = (prob.y - prob.scales(mdl) * mdl) / prob.sigma
        out[i] = (r * r).sum(-1).reshape(len(periods), len(phases))

    workers = max(1, n_threads or os.cpu_count() or 1)
    if workers == 1:
        for i in range(len(axes)):
            run(i)
    else:
        with ThreadPoolExecutor(workers, thread_name_prefix="sbrdf_xr-invert") as pool:
            list(pool.map(run, range(len(axes))))
    return out
