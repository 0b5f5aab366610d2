"""Spin-state fit: global search over candidate spin states and local refinement.

See the package docstring.
"""

from __future__ import annotations

import os
import time
from collections.abc import Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike
from scipy.optimize import least_squares

from .. import _kernels
from ..errors import InversionError

__all__ = [
    "axis_separation",
    "axis_vector",
    "fibonacci_sphere",
    "fit_spin",
    "light_curve_fluxes",
    "spin_model",
]

_LN10_2P5 = np.log(10.0) / 2.5


# ------------------------------------------------------------------------------ spin fit


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


def _lonlat(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return (
        np.degrees(np.arctan2(v[..., 1], v[..., 0])) % 360.0,
        np.degrees(np.arcsin(np.clip(v[..., 2], -1, 1))),
    )


def _vec(lon: Any, lat: Any) -> np.ndarray:
    lo, la = np.radians(lon), np.radians(lat)
    return np.stack([np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la)], axis=-1)


def _align_matrices(axis_body: np.ndarray, axes: np.ndarray) -> np.ndarray:
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
    """The :class:`sbrdf_xr.attitude.Spin` law of a spin state: the body turns about
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

    from ..attitude import Spin

    m = _align_matrices(np.asarray(axis_body, float), np.asarray(axis, float)[None, :])[0]
    q = Rotation.from_matrix(m).as_quat()
    return Spin(
        axis_body=np.asarray(axis_body, float),
        rate_deg_s=360.0 / float(period_s),
        phase_deg=float(phase_deg),
        initial=q,
    )


def _body_vectors(v: np.ndarray, align: np.ndarray, k: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Body-frame ``R(t)^T v`` for ``R = align R_k(angle)``: ``u = align^T v`` rotated by
    ``-angle`` about ``k`` (Rodrigues).  Shapes: v (T, 3), align (C, 3, 3), angle (C, T) [rad]
    -> (C, T, 3)."""
    u = np.einsum("cji,tj->cti", align, v)
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    kd = u @ k
    return u * c - np.cross(k, u) * s + k * (kd[..., None] * (1 - c))


class _Kernel:
    """Band signal of a spacecraft for body-frame geometries, on pre-integrated tables."""

    def __init__(
        self,
        spacecraft: Any,
        bands: Sequence[str],
        materials: Mapping[str, Any] | None = None,
        method: str = "linear",
    ) -> None:
        from ..scene import Scene

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
        sf = f * _LN10_2P5 * sm
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


def _directions(v: Any, n_t: int, name: str) -> np.ndarray:
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


class _Problem:
    """A light curve, its geometry and the model: chi-square of spin states."""

    def __init__(
        self,
        lc: dict[str, np.ndarray],
        kernel: _Kernel,
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
        self.s = _directions(to_sun, self.times.size, "to_sun")
        self.o = _directions(to_observer, self.times.size, "to_observer")
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
        align = _align_matrices(self.k, axes)
        ang = np.radians(phases[:, None] + 360.0 * self.times[None, :] / periods[:, None])
        sb = _body_vectors(self.s, align, self.k, ang)
        ob = _body_vectors(self.o, align, self.k, ang)
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
        mdl = self.model(_vec(p[0], p[1])[None, :], np.array([p[2]]), np.array([p[3]]))
        return ((self.y - self.scales(mdl) * mdl) / self.sigma)[0]

    def at_mean_directions(self) -> _Problem:
        """The same problem with the Sun and observer fixed at their mean directions."""
        other = object.__new__(_Problem)
        other.__dict__.update(self.__dict__)
        for key in ("s", "o"):
            m = getattr(self, key).mean(0)
            setattr(other, key, np.broadcast_to(m / np.linalg.norm(m), getattr(self, key).shape))
        return other

    @property
    def n_scales(self) -> int:
        return 1 if self.offset == "common" else self.n_bands


def _search(
    prob: _Problem,
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


def _search_shift(
    prob: _Problem,
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
        align = _align_matrices(prob.k, axes[i : i + 1])
        ang = np.radians(grid_ang)[None, :]
        f = prob.kernel(
            _body_vectors(prob.s[:1], align, prob.k, ang),
            _body_vectors(prob.o[:1], align, prob.k, ang),
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


def _refine(prob: _Problem, p0: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Local least squares from ``p0`` (lon, lat, period, phase); parameters, sigma, chi2."""
    span = max(float(np.ptp(prob.times)), 1e-9)
    xs = np.array([1.0, 1.0, p0[2] ** 2 / (360.0 * span), 1.0])
    res = least_squares(
        prob.residuals, p0, x_scale=xs, diff_step=1e-6, method="lm" if prob.y.size > 4 else "trf"
    )
    j = res.jac
    try:
        cov = np.linalg.inv(j.T @ j)
        sig = np.sqrt(np.clip(np.diag(cov), 0, None))
    except np.linalg.LinAlgError:
        sig = np.full(4, np.inf)
    p = res.x.copy()
    if abs(p[1]) > 90:  # latitude past a pole: the same axis
        v = _vec(p[0], p[1])
        p[0], p[1] = _lonlat(v)
    p[0] %= 360.0
    p[3] %= 360.0
    return p, sig, float(2 * res.cost)


def _alternatives(
    prob: _Problem, best: np.ndarray, n_phases: int, refine: bool
) -> dict[str, tuple[np.ndarray, Any, float]]:
    """The classical ambiguous solutions of a spin state, each searched in phase and refined.

    ``antipode``: the opposite axis (the reversed sense of rotation); ``mirror``: the axial
    vector mirrored through the mean scattering plane (the plane of the Sun and observer
    directions), ``-M n``, which for a body equal to its mirror image and fixed directions
    gives the same light curve (Kaasalainen & Lamberg 2006, Inverse Problems 22, 749);
    ``half_period`` and ``double_period``.
    """
    axis = _vec(best[0], best[1])
    nplane = np.cross(prob.s.mean(0), prob.o.mean(0))
    nplane = (
        nplane / np.linalg.norm(nplane) if np.linalg.norm(nplane) > 1e-9 else np.array([0.0, 0, 1])
    )
    mirror = -(axis - 2 * np.dot(axis, nplane) * nplane)
    alts = {
        "antipode": (-axis, best[2]),
        "mirror": (mirror, best[2]),
        "half_period": (axis, best[2] / 2),
        "double_period": (axis, best[2] * 2),
    }
    dense = np.arange(4 * int(n_phases)) * 90.0 / int(n_phases)
    out = {}
    for name, (ax, per) in alts.items():
        c2 = prob.chi2(np.repeat(ax[None, :], dense.size, 0), np.full(dense.size, per), dense)
        lo, la = _lonlat(ax)
        q0 = np.array([lo, la, per, dense[np.argmin(c2)]])
        out[name] = _refine(prob, q0) if refine else (q0, None, float(c2.min()))
    return out


def _axis_angle(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.degrees(np.arccos(np.clip(np.dot(a, b), -1, 1))))


def fit_spin(
    light_curve: xr.Dataset,
    spacecraft: Any,
    *,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    periods: ArrayLike,
    axis_body: ArrayLike = (0.0, 0.0, 1.0),
    n_axes: int = 300,
    n_phases: int = 36,
    offset: str = "band",
    materials: Mapping[str, xr.DataArray] | None = None,
    refine: bool = True,
    n_starts: int = 5,
    method: str = "shift",
    n_threads: int | None = None,
) -> xr.Dataset:
    """Spin axis, period and phase of a uniform spin fitted to a colour light curve.

    The model (:func:`spin_model`): the body turns about its ``axis_body`` (a principal
    axis, the spin being torque-free) at ``360/P`` degree s-1; ``axis_body`` points to the
    inertial direction (``axis_longitude``, ``axis_latitude``) of the frame of
    ``to_sun``/``to_observer``; the spin angle is ``phase`` at t = 0.  The predicted flux of
    band b is ``k_b S_b(t)`` with ``S_b`` the band signal of the compiled kernel and
    ``k_b`` (one per band, or one for all with ``offset="common"``) solved in closed form
    for every candidate.  Search: ``n_axes`` Fibonacci-sphere axes x ``periods`` x
    ``n_phases`` phases; then :func:`scipy.optimize.least_squares` from the best
    candidate (and from the alternative solutions below).

    The period grid must be fine enough that the phase slips by less than a phase step over
    the time span ``T``: ``dP <~ P**2 / (n_phases T)``.

    Parameters
    ----------
    light_curve : Dataset
        :func:`sbrdf_xr.photometry.read_light_curve` output (magnitudes) or the same with
        ``flux`` and ``flux_uncertainty``; times [s].
    spacecraft : Spacecraft
        The body (its materials from the catalog unless ``materials``).
    to_sun, to_observer : array_like, shape (3,) or (n_times, 3)
        Inertial directions from the spacecraft to the Sun and to the observer, fixed or
        one per distinct time (sorted).
    periods : array_like
        Candidate spin periods [s].
    axis_body : array_like, shape (3,)
        The body axis the spacecraft spins about.
    n_axes, n_phases : int
        Search grid sizes.
    offset : {"band", "common"}
        A free flux scale per band, or one for all bands (then the fluxes must be on one
        physical scale, e.g. magnitudes in one system).
    refine : bool
        Refine the best candidates by least squares.
    n_starts : int
        Refinements started from the best grid state of the ``n_starts`` best axes.
    method : {"shift", "direct"}
        Search: ``shift`` evaluates the kernel once per axis on a dense spin-angle grid
        (0.5 degree) and reads every (period, phase) from it, exact for fixed directions
        and, when they move, at their mean directions (the refinement is exact);
        ``direct`` runs every candidate at every time through the kernel.
    n_threads : int, optional
        Threads of the search (default: every core).

    Returns
    -------
    xarray.Dataset
        Scalars ``axis_longitude``, ``axis_latitude`` [degree], ``period`` [s], ``phase``
        [degree] with ``*_uncertainty``, ``chi2``, ``reduced_chi2``; the map
        ``chi2_map`` over ``axis`` (min over period and phase) with the axis coordinates;
        the alternative solutions over ``solution`` (mirror axis, antipode, half and double
        period) with their ``chi2_gap``.

    Examples
    --------
    A 1 x 2 x 3 m box of the catalog's Lambertian grey spinning about its long axis with
    a period of 20 s, seen in V and R for 40 s at 30 deg phase; the grid search alone
    (``refine=False``) over 30 axes x 11 periods x 12 phases finds the period:

    >>> import numpy as np, trimesh, xarray as xr
    >>> from sbrdf_xr import Scene, geometry, load_spacecraft, simulate
    >>> from sbrdf_xr.invert import axis_vector, fit_spin, spin_model
    >>> box = load_spacecraft(trimesh.creation.box(extents=(1.0, 2.0, 3.0)),
    ...                       material="lambertian-grey-50")
    >>> spin = spin_model([0, 0, 1], axis_vector(60.0, 30.0), period_s=20.0, phase_deg=30.0)
    >>> t = np.arange(0.0, 40.0, 1.0)
    >>> scene = Scene(box, attitudes=spin.quaternions(t), phase_angles=[30.0],
    ...               outputs=("band_signal",), bands=("V", "R"))
    >>> flux = simulate(scene).band_signal.isel(phase_angle=0).values  # (time, band)
    >>> lc = xr.Dataset(
    ...     {"flux": ("obs", flux.ravel()),
    ...      "flux_uncertainty": ("obs", np.full(flux.size, 0.01 * flux.mean()))},
    ...     coords={"time": ("obs", np.repeat(t, 2)), "band": ("obs", ["V", "R"] * t.size)},
    ... )
    >>> to_sun, to_observer = geometry.observation_plane([30.0], (1, 0, 0), (0, 0, 1))
    >>> fit = fit_spin(lc, box, to_sun=to_sun[0], to_observer=to_observer[0],
    ...                periods=np.linspace(15.0, 25.0, 11), n_axes=30, n_phases=12,
    ...                refine=False, n_threads=1)
    >>> float(fit.period), fit.attrs["n_candidates"], fit.sizes["axis"]
    (20.0, 3960, 30)
    >>> fit.solution.values.tolist()
    ['antipode', 'mirror', 'half_period', 'double_period']
    """
    if method not in ("shift", "direct"):
        raise InversionError(f"method: {method!r}; allowed 'shift', 'direct'")
    lc = light_curve_fluxes(light_curve)
    kern = _Kernel(spacecraft, list(lc["labels"]), materials)
    prob = _Problem(lc, kern, to_sun, to_observer, np.asarray(axis_body, dtype=np.float64), offset)
    periods = np.atleast_1d(np.asarray(periods, dtype=np.float64))
    if not np.all(np.isfinite(periods) & (periods > 0)):
        raise InversionError("periods: must be finite and > 0 [s]")
    n_par = 4 + prob.n_scales
    if prob.y.size <= n_par:
        raise InversionError(
            f"light curve: {prob.y.size} values for {n_par} parameters; need more values"
        )
    axes = fibonacci_sphere(int(n_axes))
    phases = np.arange(int(n_phases)) * 360.0 / int(n_phases)
    t0 = time.perf_counter()
    fixed = bool(np.allclose(prob.s, prob.s[0]) and np.allclose(prob.o, prob.o[0]))
    if method == "shift":
        # with moving directions the search reads the model at the mean directions (an
        # approximation for the global search only; the refinement uses the exact ones)
        search_prob = prob if fixed else prob.at_mean_directions()
        grid = _search_shift(search_prob, axes, periods, phases, n_threads)
    else:
        grid = _search(prob, axes, periods, phases, n_threads)
    t_search = time.perf_counter() - t0
    ia, ip, iq = np.unravel_index(np.argmin(grid), grid.shape)
    lon0, lat0 = _lonlat(axes[ia])
    p0 = np.array([lon0, lat0, periods[ip], phases[iq]])
    if refine:
        # multi-start: the best grid state of each of the n_starts best axes
        best, sig, chi2 = _refine(prob, p0)
        per_axis = grid.reshape(len(axes), -1)
        for i in np.argsort(per_axis.min(axis=1))[1 : max(1, int(n_starts))]:
            jp, jq = np.unravel_index(np.argmin(per_axis[i]), grid.shape[1:])
            lo, la = _lonlat(axes[i])
            q, sq, c = _refine(prob, np.array([lo, la, periods[jp], phases[jq]]))
            if c < chi2:
                best, sig, chi2 = q, sq, c
        # an alternative better than the first refinement becomes the solution (once)
        for q, _, c in _alternatives(prob, best, n_phases, refine).values():
            if c < chi2 - 1e-9:
                best, sig, chi2 = _refine(prob, q)
    else:
        best, sig, chi2 = p0, np.full(4, np.nan), float(grid[ia, ip, iq])
    best_axis = _vec(best[0], best[1])
    rows = [
        (name, q, c, _axis_angle(_vec(q[0], q[1]), best_axis))
        for name, (q, _, c) in _alternatives(prob, best, n_phases, refine).items()
    ]
    dof = prob.y.size - n_par
    chi_map = grid.min(axis=(1, 2))
    mlon, mlat = _lonlat(axes)
    ds = xr.Dataset(
        coords={
            "axis": (
                "axis",
                np.arange(len(axes)),
                {"long_name": "candidate axis index", "units": "1"},
            ),
            "axis_longitude_grid": (
                "axis",
                mlon,
                {"long_name": "longitude of the candidate axis", "units": "degree"},
            ),
            "axis_latitude_grid": (
                "axis",
                mlat,
                {"long_name": "latitude of the candidate axis", "units": "degree"},
            ),
            "solution": (
                "solution",
                [r[0] for r in rows],
                {"long_name": "alternative solution", "units": "1"},
            ),
        }
    )
    meta = {
        "axis_longitude": ("degree", "longitude of the inertial spin axis"),
        "axis_latitude": ("degree", "latitude of the inertial spin axis"),
        "period": ("s", "spin period"),
        "phase": ("degree", "spin angle at t = 0"),
    }
    for j, (key, (u, ln)) in enumerate(meta.items()):
        ds[key] = ((), float(best[j]), {"units": u, "long_name": ln})
        ds[key + "_uncertainty"] = (
            (),
            float(sig[j]),
            {"units": u, "long_name": f"1-sigma uncertainty of {ln} (Jacobian of the refinement)"},
        )
    ds["axis_vector"] = (
        ("xyz",),
        best_axis,
        {"units": "1", "long_name": "unit vector of the inertial spin axis"},
    )
    ds["chi2"] = ((), chi2, {"units": "1", "long_name": "chi-square of the best spin state"})
    ds["reduced_chi2"] = (
        (),
        chi2 / dof,
        {"units": "1", "long_name": "chi-square per degree of freedom"},
    )
    ds["chi2_map"] = (
        "axis",
        chi_map,
        {
            "units": "1",
            "long_name": "chi-square of the axis, minimised over period and phase on the grid",
        },
    )
    ds["solution_chi2"] = (
        "solution",
        [r[2] for r in rows],
        {"units": "1", "long_name": "chi-square"},
    )
    ds["chi2_gap"] = (
        "solution",
        [r[2] - chi2 for r in rows],
        {"units": "1", "long_name": "chi-square above the best solution"},
    )
    ds["solution_period"] = (
        "solution",
        [r[1][2] for r in rows],
        {"units": "s", "long_name": "spin period"},
    )
    ds["solution_axis_longitude"] = (
        "solution",
        [r[1][0] for r in rows],
        {"units": "degree", "long_name": "longitude of the spin axis"},
    )
    ds["solution_axis_latitude"] = (
        "solution",
        [r[1][1] for r in rows],
        {"units": "degree", "long_name": "latitude of the spin axis"},
    )
    ds["solution_axis_separation"] = (
        "solution",
        [r[3] for r in rows],
        {"units": "degree", "long_name": "angle between the solution's axis and the best axis"},
    )
    ds.attrs = {
        "axis_body": str(list(np.asarray(axis_body, float))),
        "offset": offset,
        "n_candidates": int(grid.size),
        "search_seconds": t_search,
        "search_method": method,
        "fixed_directions": int(fixed),
        "n_values": int(prob.y.size),
        "bands": ", ".join(lc["labels"]),
    }
    return ds


def axis_vector(longitude: ArrayLike, latitude: ArrayLike) -> np.ndarray:
    """Unit vector(s) of an axis at ``longitude``, ``latitude`` [degree], shape (..., 3).

    Examples
    --------
    >>> from sbrdf_xr.invert import axis_vector
    >>> axis_vector(90.0, 0.0).round(6).tolist()
    [0.0, 1.0, 0.0]
    >>> axis_vector([0.0, 0.0], [0.0, 90.0]).round(6).tolist()
    [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    """
    return _vec(np.asarray(longitude, dtype=np.float64), np.asarray(latitude, dtype=np.float64))


def axis_separation(a: ArrayLike, b: ArrayLike) -> float:
    """Angle between two unit vectors [degree].

    Examples
    --------
    >>> from sbrdf_xr.invert import axis_separation
    >>> axis_separation([1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    90.0
    """
    return _axis_angle(np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64))
