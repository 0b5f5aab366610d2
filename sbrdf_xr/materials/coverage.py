"""How measurements cover the angles: grouping with a tolerance, scan layouts, model fills.

Angles that come from a conversion (:func:`sbrdf_xr.geometry.from_conventional`, a
goniometer's encoder) carry float noise of ~1e-12 degree: equal angles are never equal
floats.  Every grouping and matching of angles in the construction of a table
(:func:`sbrdf_xr.materials.build.build_lut`,
:func:`sbrdf_xr.materials.schema.validate_measurements`) therefore goes through
:func:`snap_angles`, which merges angles closer than :data:`ANGLE_TOL` (1e-6 degree).

A measured incidence angle's samples come in one of three layouts
(:func:`scan_layout`):

``rows``
    The scheme of paper 000 §3.2: rows of constant ``delta_theta`` sampled at several
    ``phi``.  The paper's construction applies.
``in-plane``
    Every sample in the plane of incidence (``phi = 0``): a goniometer scan of the
    signed scattering angle.  Out of the plane the table is the fitted model times the
    measured ratio to the model at the same angular distance from the specular
    direction (:func:`specular_distance`): a lobe keeps its measured width in every
    direction about the mirror direction.  Between samples the logarithm of the ratio
    is interpolated by a shape-preserving cubic (PCHIP, F. N. Fritsch & R. E. Carlson,
    SIAM J. Numer. Anal. 17, 238, 1980): a lobe falls by factors, and no overshoot.
``scattered``
    Samples spread over the ``(delta_theta, phi)`` plane without rows (a regular grid
    in conventional angles).  The ratio of the samples to the fitted model is
    interpolated linearly on their Delaunay triangulation (mirrored about ``phi = 0``)
    and held at its nearest sample outside it.

Angles are in degree (astropy Quantities are converted, :func:`sbrdf_xr.units.to_unit`).
"""

from __future__ import annotations

import itertools
import warnings
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.interpolate import LinearNDInterpolator, NearestNDInterpolator, PchipInterpolator

from ..errors import NonPhysicalWarning, ValidationError
from ..units import to_unit
from .construction import per_theta_tables

__all__ = [
    "ANGLE_TOL",
    "LAYOUTS",
    "scan_layout",
    "snap_angles",
    "specular_distance",
]

#: Angles closer than this are the same angle [degree]: far above the float noise of an
#: angle conversion (~1e-12 degree), far below any goniometer's step (~0.01 degree).
ANGLE_TOL = 1e-6

#: The layouts of a measured incidence angle's samples (:func:`scan_layout`).
LAYOUTS = ("rows", "in-plane", "scattered")

#: Fraction of an incidence angle's samples that must lie in rows of constant
#: ``delta_theta`` with >= 2 ``phi`` samples for the layout to be ``rows``.
ROW_FRACTION = 0.75


def snap_angles(values: ArrayLike, tol: float = ANGLE_TOL) -> np.ndarray:
    """Angles closer than ``tol`` replaced by the mean of their group.

    Sorted angles are grouped where consecutive ones differ by at most ``tol``; every
    angle becomes its group's mean (0 where that is within ``tol`` of 0), so equal angles
    compare equal afterwards.

    Parameters
    ----------
    values : array_like
        Angles [degree].
    tol : float, default :data:`ANGLE_TOL`
        Grouping tolerance [degree], ``>= 0``.

    Returns
    -------
    ndarray
        The snapped angles [degree], shaped like ``values``.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials.coverage import snap_angles
    >>> x = np.array([10.0, 10.0 + 1e-12, 20.0, 10.0 - 1e-12])
    >>> np.unique(x).size, np.unique(snap_angles(x)).size
    (4, 2)
    """
    tol = to_unit(tol, "deg", "tol")
    if not tol >= 0:
        raise ValidationError(f"tol: must be >= 0 degree, got {tol}")
    v = np.asarray(to_unit(values, "deg", "values"), dtype=np.float64)
    flat = v.ravel()
    if flat.size == 0:
        return v.copy()
    order = np.argsort(flat, kind="stable")
    s = flat[order]
    ids = np.cumsum(np.concatenate([[True], np.diff(s) > tol])) - 1
    means = np.bincount(ids, weights=s) / np.bincount(ids)
    means[np.abs(means) <= tol] = 0.0  # an angle within the tolerance of 0 is 0
    out = np.empty_like(flat)
    out[order] = means[ids]
    return out.reshape(v.shape)


def scan_layout(delta_theta: ArrayLike, phi: ArrayLike, tol: float = ANGLE_TOL) -> str:
    """The layout of one incidence angle's samples: ``rows``, ``in-plane`` or ``scattered``.

    Parameters
    ----------
    delta_theta, phi : array_like, shape (s,)
        The samples' angles [degree], already snapped (:func:`snap_angles`).
    tol : float, default :data:`ANGLE_TOL`
        A ``phi`` at most ``tol`` is in the plane of incidence [degree].

    Returns
    -------
    str
        One of :data:`LAYOUTS`: ``in-plane`` if every ``phi <= tol``; ``rows`` if at
        least :data:`ROW_FRACTION` of the samples lie in rows of one ``delta_theta``
        with >= 2 ``phi`` values; ``scattered`` otherwise.

    Examples
    --------
    >>> from sbrdf_xr.materials.coverage import scan_layout
    >>> scan_layout([-2.0, 0.0, 2.0], [0.0, 0.0, 0.0])
    'in-plane'
    >>> scan_layout([-2.0, -2.0, 0.0, 0.0], [0.0, 5.0, 0.0, 5.0])
    'rows'
    >>> scan_layout([-2.0, -1.0, 0.0, 1.0], [0.0, 5.0, 3.0, 7.0])
    'scattered'
    """
    dt = np.asarray(to_unit(delta_theta, "deg", "delta_theta"), dtype=np.float64)
    ph = np.asarray(to_unit(phi, "deg", "phi"), dtype=np.float64)
    tol = to_unit(tol, "deg", "tol")
    if np.all(ph <= tol):
        return "in-plane"
    _, inverse, counts = np.unique(dt, return_inverse=True, return_counts=True)
    in_rows = np.sum(counts[inverse.ravel()] >= 2)
    return "rows" if in_rows >= ROW_FRACTION * dt.size else "scattered"


def specular_distance(delta_theta: ArrayLike, phi: ArrayLike) -> np.ndarray:
    """The in-plane ``delta_theta`` at the same angular distance from specular.

    In paper-000 angles the observer is ``o = (cos phi sin(theta_i + delta_theta),
    sin phi, cos phi cos(theta_i + delta_theta))`` in the frame (forward, plane
    normal, facet normal) and the specular direction is ``(sin theta_i, 0, cos
    theta_i)``, so the angle ``gamma`` between them has ``cos gamma = cos phi cos
    delta_theta``, whatever ``theta_i``.  Computed with ``arctan2`` (exact near 0).

    Parameters
    ----------
    delta_theta, phi : array_like
        Angles [degree], broadcast together.

    Returns
    -------
    ndarray
        ``sign(delta_theta) * gamma`` [degree] (``+gamma`` at ``delta_theta = 0``);
        equal to ``delta_theta`` at ``phi = 0``.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials.coverage import specular_distance
    >>> specular_distance([-3.0, 0.0, 3.0], 0.0).tolist()
    [-3.0, 0.0, 3.0]
    >>> round(float(specular_distance(0.0, 4.0)), 12), round(float(specular_distance(-3.0, 4.0)), 3)
    (4.0, -4.998)
    """
    dt = np.radians(np.asarray(to_unit(delta_theta, "deg", "delta_theta"), dtype=np.float64))
    ph = np.radians(np.asarray(to_unit(phi, "deg", "phi"), dtype=np.float64))
    dt, ph = np.broadcast_arrays(dt, ph)
    sin_g = np.hypot(np.sin(ph), np.cos(ph) * np.sin(dt))
    gamma = np.degrees(np.arctan2(sin_g, np.cos(ph) * np.cos(dt)))
    return np.where(dt < 0, -gamma, gamma)


def _in_plane_phi_grid(step: float) -> np.ndarray:
    """The ``phi`` grid of a table built from in-plane scans: 0, then steps from the
    scan's own step halved :data:`SPECULAR_REFINE` times, doubling up to 10 degree, then
    every 10 degree to 90.

    Parameters
    ----------
    step : float
        The scans' ``delta_theta`` step [degree], ``> 0``.

    Returns
    -------
    ndarray
        Strictly increasing ``phi`` nodes [degree] from 0 to 90.

    Examples
    --------
    >>> from sbrdf_xr.materials.coverage import _in_plane_phi_grid
    >>> _in_plane_phi_grid(1.0).tolist()[:8]
    [0.0, 0.03125, 0.0625, 0.125, 0.25, 0.5, 1.0, 2.0]
    """
    step = to_unit(step, "deg", "step")
    if not step > 0:
        raise ValidationError(f"step: must be > 0 degree, got {step}")
    near = step * 2.0 ** np.arange(-SPECULAR_REFINE, 20)
    return np.unique(np.concatenate([[0.0], near[near < 10.0], np.arange(10.0, 90.1, 10.0)]))


#: Halvings of the scan's step by which the grids of an in-plane table are refined about
#: the specular direction (:func:`_specular_nodes`).
SPECULAR_REFINE = 5


#: Within this many scan steps of specular, the ``delta_theta`` nodes of an in-plane table
#: are at most :data:`SPECULAR_SUBSTEP` of a step apart (:func:`_specular_nodes`).
SPECULAR_STEPS = 10
#: The largest node spacing near specular, as a fraction of the scan's step.
SPECULAR_SUBSTEP = 0.25


def _specular_nodes(dt: np.ndarray) -> np.ndarray:
    """The ``delta_theta`` nodes of an in-plane table: the scans' own, nodes at
    ``+-step / 2**k`` (``k = 1..SPECULAR_REFINE``) about specular, and within
    :data:`SPECULAR_STEPS` steps of specular every gap between nodes split to at most
    :data:`SPECULAR_SUBSTEP` of a step.  The look-up interpolates linearly between nodes;
    a mirror core and its shoulders fall by orders of magnitude within one step of the
    scan, so nodes a step apart turn the fill's curve into chords far above it (a
    pyramid one step wide holds tens of times the energy of the peak it stands for, and
    misses the samples between nodes by tens of per cent).

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials.coverage import _specular_nodes
    >>> nodes = _specular_nodes(np.arange(-20.0, 21.0))
    >>> float(np.diff(nodes[np.abs(nodes) <= 10.0]).max()), float(np.diff(nodes).max())
    (0.25, 1.0)
    """
    nodes = np.unique(dt)
    step = float(np.median(np.diff(nodes))) if nodes.size > 1 else 1.0
    fine = step * 2.0 ** -np.arange(1, SPECULAR_REFINE + 1)
    nodes = np.unique(np.concatenate([nodes, fine, -fine]))
    near = nodes[np.abs(nodes) <= SPECULAR_STEPS * step + 1e-9]
    extra = [
        np.linspace(a, b, int(np.ceil((b - a) / (SPECULAR_SUBSTEP * step) - 1e-9)) + 1)[1:-1]
        for a, b in itertools.pairwise(near)
    ]
    return np.unique(np.concatenate([nodes, *extra])) if extra else nodes


def _in_plane(dt: np.ndarray, ratio: np.ndarray, dt_grid: np.ndarray, phi_grid: np.ndarray):
    """The ratio of one in-plane scan on the grid, taken at the same distance from specular.

    Out of the plane the two sides of the scan at that distance are mixed by the share of
    the observer's offset that lies along the plane (all of one side at ``phi = 0``, half
    of each at ``delta_theta = 0``): continuous across ``delta_theta = 0``."""
    order = np.argsort(dt)
    x = dt[order]
    # In the logarithm (a lobe falls by factors, not by steps), shape-preserving cubic
    # (PCHIP: no overshoot, each sample's value at its node), held beyond the scan's ends.
    log_r = np.log(np.maximum(ratio[order], np.finfo(np.float64).tiny))
    shape = (dt_grid.size, phi_grid.size, ratio.shape[1])
    if x.size == 1:
        return np.broadcast_to(np.exp(log_r[0]), shape).copy()
    gamma = np.abs(specular_distance(dt_grid[:, None], phi_grid[None, :])).ravel()
    d, p = np.meshgrid(np.radians(dt_grid), np.radians(phi_grid), indexing="ij")
    along = np.cos(p.ravel()) * np.sin(d.ravel())
    sin_g = np.sin(np.radians(gamma))
    share = np.divide(along, sin_g, out=np.zeros_like(along), where=sin_g > 0)
    w_plus = 0.5 * (1.0 + np.clip(share, -1.0, 1.0))[:, None]
    f = PchipInterpolator(x, log_r, axis=0)
    plus, minus = (f(np.clip(sign * gamma, x[0], x[-1])) for sign in (1.0, -1.0))
    return np.exp(w_plus * plus + (1.0 - w_plus) * minus).reshape(shape)


def _scattered(
    dt: np.ndarray, ph: np.ndarray, ratio: np.ndarray, dt_grid: np.ndarray, phi_grid: np.ndarray
) -> np.ndarray:
    """The ratio of one scattered set on the grid: linear on its (mirrored) triangulation,
    the nearest sample's outside it."""
    pts = np.concatenate([np.stack([dt, ph], 1), np.stack([dt, -ph], 1)[ph > 0]])
    vals = np.concatenate([ratio, ratio[ph > 0]])
    gd, gp = np.meshgrid(dt_grid, phi_grid, indexing="ij")
    q = np.stack([gd.ravel(), gp.ravel()], 1)
    out = LinearNDInterpolator(pts, vals)(q)
    miss = ~np.all(np.isfinite(out), axis=1)
    if miss.any():
        out[miss] = NearestNDInterpolator(pts, vals)(q[miss])
    return out.reshape(dt_grid.size, phi_grid.size, ratio.shape[1])


def _ratio_tables(
    measured_ti: np.ndarray,
    ti_s: np.ndarray,
    dt_s: np.ndarray,
    ph_s: np.ndarray,
    ratio: np.ndarray,
    dt_grid: np.ndarray,
    phi_grid: np.ndarray,
) -> tuple[np.ndarray, list[str]]:
    """The ratio of the samples to a model on the grid at every measured incidence angle.

    Each incidence angle by its own layout (:func:`scan_layout`): ``rows`` by steps 1
    and 2 of paper 000 §3.2 with every edge held
    (:func:`~sbrdf_xr.materials.construction.per_theta_tables`), ``in-plane`` at the
    same distance from specular, ``scattered`` on the triangulation.

    Parameters
    ----------
    measured_ti : ndarray, shape (t,)
        The measured incidence angles [degree] (snapped).
    ti_s, dt_s, ph_s : ndarray, shape (s,)
        Angles of the samples [degree] (snapped).
    ratio : ndarray, shape (s, n_wavelength)
        Sample over model [1].
    dt_grid, phi_grid : ndarray
        The table's grids [degree].

    Returns
    -------
    ratios : ndarray, shape (t, len(dt_grid), len(phi_grid), n_wavelength)
        The ratio on the grid [1].
    layouts : list of str
        The layout of every measured incidence angle.

    Examples
    --------
    An in-plane scan whose ratio is 2 everywhere gives 2 everywhere:

    >>> import numpy as np
    >>> from sbrdf_xr.materials.coverage import _ratio_tables
    >>> dt = np.array([-10.0, 0.0, 10.0])
    >>> r, layouts = _ratio_tables(np.array([30.0]), np.full(3, 30.0), dt, np.zeros(3),
    ...                           np.full((3, 1), 2.0), np.linspace(-20, 20, 5),
    ...                           np.array([0.0, 5.0]))
    >>> r.shape, layouts, float(r.min()), float(r.max())
    ((1, 5, 2, 1), ['in-plane'], 2.0, 2.0)
    """
    out = np.empty((measured_ti.size, dt_grid.size, phi_grid.size, ratio.shape[1]))
    layouts = []
    for a, t in enumerate(measured_ti):
        sel = np.flatnonzero(ti_s == t)
        layout = scan_layout(dt_s[sel], ph_s[sel])
        layouts.append(layout)
        if layout == "rows":
            out[a] = per_theta_tables(
                np.array([t]),
                ti_s[sel],
                dt_s[sel],
                ph_s[sel],
                ratio[sel],
                np.zeros(sel.size, dtype=bool),
                dt_grid,
                phi_grid,
                hold_all=True,
            )[0]
        elif layout == "in-plane":
            out[a] = _in_plane(dt_s[sel], ratio[sel], dt_grid, phi_grid)
        else:
            out[a] = _scattered(dt_s[sel], ph_s[sel], ratio[sel], dt_grid, phi_grid)
    return out, layouts


def _at_horizon(
    theta_i: ArrayLike,
    delta_theta: ArrayLike,
    phi: ArrayLike,
    *,
    warn: bool = False,
    known: np.ndarray | None = None,
) -> np.ndarray:
    """Which samples have the observer at or below the horizon (``cos theta_r <= 1e-8``).

    No reflectance can be measured there (``cos theta_r = 0``): a build leaves them out
    and, with ``warn``, says how many (:class:`~sbrdf_xr.errors.NonPhysicalWarning`).

    Parameters
    ----------
    theta_i, delta_theta, phi : array_like
        Sample angles [degree].
    warn : bool, default False
        Warn when there are any.
    known : ndarray of bool, optional
        Samples already left out (reference points): neither returned nor counted.

    Returns
    -------
    ndarray of bool

    Examples
    --------
    >>> from sbrdf_xr.materials.coverage import _at_horizon
    >>> _at_horizon([30.0, 30.0], [60.0, 10.0], [0.0, 0.0]).tolist()
    [True, False]
    """
    ti, dt, ph = (
        np.asarray(to_unit(a, "deg", n), dtype=np.float64)
        for a, n in ((theta_i, "theta_i"), (delta_theta, "delta_theta"), (phi, "phi"))
    )
    out = np.cos(np.radians(ph)) * np.cos(np.radians(ti + dt)) <= 1e-8
    if known is not None:
        out &= ~np.asarray(known, dtype=bool)
    if warn and out.any():
        warnings.warn(
            f"build_lut: {int(out.sum())} of {out.size} samples have the observer at or "
            "below the horizon (theta_i + delta_theta = +-90 deg in the plane); they are "
            "left out (attribute n_dropped_horizon)",
            NonPhysicalWarning,
            stacklevel=3,
        )
    return out


def _resolve_below_noise(below_noise: str, layouts: list[str], measured_ti: ArrayLike) -> str:
    """The below-noise policy of a build, ``auto`` resolved by the data's layouts.

    Parameters
    ----------
    below_noise : {"auto", "zero", "model"}
        As :func:`~sbrdf_xr.materials.build.build_lut`.
    layouts : list of str
        The layout of every measured incidence angle (:func:`scan_layout`).
    measured_ti : array_like
        The measured incidence angles [degree].

    Returns
    -------
    str
        ``zero`` or ``model``.

    Raises
    ------
    ValidationError
        ``zero`` with data not in rows: the paper's construction cannot build them.

    Examples
    --------
    >>> from sbrdf_xr.materials.coverage import _resolve_below_noise
    >>> _resolve_below_noise("auto", ["rows", "rows"], [10.0, 40.0])
    'zero'
    >>> _resolve_below_noise("auto", ["in-plane"], [10.0])
    'model'
    """
    rows_only = all(lay == "rows" for lay in layouts)
    if below_noise == "auto":
        return "zero" if rows_only else "model"
    if below_noise == "zero" and not rows_only:
        what = sorted({lay for lay in layouts if lay != "rows"})
        at = [
            float(t)
            for t, lay in zip(np.atleast_1d(measured_ti), layouts, strict=True)
            if lay != "rows"
        ]
        why = (
            "no sample out of the plane of incidence: phi = 0 everywhere"
            if what == ["in-plane"]
            else "not in rows of constant delta_theta"
        )
        raise ValidationError(
            f"below_noise: got 'zero', but the samples at theta_i = {at} deg are "
            f"{' and '.join(what)} ({why}): the paper's construction needs rows of constant "
            "delta_theta sampled in phi. Allowed: below_noise='model' or 'auto' (a model "
            "fitted to the samples fills what was not measured)"
        )
    return below_noise


def _coverage_attrs(layouts: list[str], measured_ti: ArrayLike, model: Any) -> dict[str, str]:
    """The attributes ``layout`` and ``modelled`` of a table: what was measured and what
    comes from the fitted model.

    Parameters
    ----------
    layouts : list of str
        The layout of every measured incidence angle (:func:`scan_layout`).
    measured_ti : array_like
        The measured incidence angles [degree].
    model : xarray.Dataset
        The fitted model material (its ``model`` attribute names it).

    Returns
    -------
    dict

    Examples
    --------
    >>> from sbrdf_xr.materials.coverage import _coverage_attrs
    >>> import xarray as xr
    >>> a = _coverage_attrs(["in-plane"], [30.0], xr.Dataset(attrs={"model": "robertson_sandford"}))
    >>> a["layout"]
    'in-plane at theta_i = 30 deg'
    """
    name = model.attrs.get("model", "model")
    ti = np.atleast_1d(np.asarray(to_unit(measured_ti, "deg", "measured_ti"), dtype=np.float64))
    parts = []
    for lay in LAYOUTS:
        at = [f"{t:g}" for t, la in zip(ti, layouts, strict=True) if la == lay]
        if at:
            parts.append(f"{lay} at theta_i = {', '.join(at)} deg")
    modelled = {
        "in-plane": "phi > 0 (out of the plane of incidence) is the fitted "
        f"{name} model times the measured ratio at the same angular distance from specular",
        "scattered": f"between the samples the fitted {name} model times their ratio "
        "interpolated on their triangulation",
        "rows": "beyond the measured extents the fitted model",
    }
    return {
        "layout": "; ".join(parts),
        "modelled": "; ".join(modelled[lay] for lay in dict.fromkeys(layouts))
        + "; between and beyond the measured incidence angles: the model times their "
        "ratio interpolated in theta_i (PCHIP of its logarithm, held beyond them)",
    }


def _ratio_across_theta(
    measured_ti: np.ndarray, ratios: np.ndarray, theta_i: np.ndarray
) -> np.ndarray:
    """The ratio tables of the measured incidence angles at the table's rows.

    A shape-preserving cubic (PCHIP) in the logarithm of the ratio, held beyond the
    measured angles: a near-mirror's ratio changes by orders of magnitude between
    incidence angles, where a cubic spline of the ratio itself overshoots below zero.

    Parameters
    ----------
    measured_ti : ndarray, shape (t,)
        Measured incidence angles [degree], increasing.
    ratios : ndarray, shape (t, ...)
        Their ratio tables [1] (:func:`_ratio_tables`).
    theta_i : ndarray, shape (n,)
        The table's rows [degree].

    Returns
    -------
    ndarray, shape (n, ...)
        [1], positive.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials.coverage import _ratio_across_theta
    >>> r = _ratio_across_theta(np.array([10.0, 50.0]), np.array([[1.0], [100.0]]),
    ...                        np.array([0.0, 30.0, 50.0, 80.0]))
    >>> np.round(r.ravel(), 6).tolist()
    [1.0, 10.0, 100.0, 100.0]
    """
    ti = np.clip(np.asarray(to_unit(theta_i, "deg", "theta_i"), dtype=np.float64),
                 measured_ti[0], measured_ti[-1])  # fmt: skip
    log_r = np.log(np.maximum(ratios, np.finfo(np.float64).tiny))
    if measured_ti.size == 1:
        return np.exp(np.broadcast_to(log_r, (ti.size, *log_r.shape[1:])))
    return np.exp(PchipInterpolator(measured_ti, log_r, axis=0)(ti))
