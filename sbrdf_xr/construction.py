"""The numpy core of the table construction of paper 000 §3.2.

Grids, interpolation weights, steps 1 and 2 per measured incidence angle, the
model blend and the azimuthal average at normal incidence.

:func:`sbrdf_xr.material.build_lut` drives it on xarray objects; everything here takes and
returns plain arrays.
"""

from __future__ import annotations

import numpy as np

from . import _lut
from .errors import ValidationError


def paper_phi_grid(phi_max: float, n: int = 21) -> np.ndarray:
    """Uniform ``phi`` grid of paper 000 §3.2: ``n`` points from 0 to ``phi_max`` [degree]."""
    if not phi_max > 0:
        raise ValidationError(f"phi_max: must be > 0 degree, got {phi_max}")
    return np.linspace(0.0, float(phi_max), n)


def paper_delta_theta_grid(dt_min: float, dt_max: float, n: int = 21) -> np.ndarray:
    """``delta_theta`` grid of paper 000 §3.2: 0 at the median, ``dt_min/10`` and
    ``dt_max/10`` steps on either side (for ``n = 21``) [degree]."""
    if not (dt_min < 0 < dt_max):
        raise ValidationError(
            "delta_theta: measured extent must straddle specular (min < 0 < max), "
            f"got [{dt_min}, {dt_max}]"
        )
    if n < 3 or n % 2 == 0:
        raise ValidationError(f"n_delta_theta: must be odd and >= 3, got {n}")
    half = n // 2
    return np.concatenate(
        [np.linspace(dt_min, 0.0, half + 1)[:-1], np.linspace(0.0, dt_max, half + 1)]
    )


def interp_weights(
    x_data: np.ndarray, x_out: np.ndarray, hold_lo: bool = False, hold_hi: bool = False
) -> np.ndarray:
    """Matrix (len(x_out), len(x_data)) of linear interpolation.

    Outside the data the result is zero (the edge is a reference point, where the
    signal is in the noise), or the edge value where ``hold_lo``/``hold_hi`` says the
    edge is a measured point that only the apparatus kept from going further.
    """
    order = np.argsort(x_data, kind="stable")
    xs = x_data[order]
    w = np.zeros((x_out.size, x_data.size))
    lo = x_out < xs[0] - _lut.EDGE_TOL_DEG
    hi = x_out > xs[-1] + _lut.EDGE_TOL_DEG
    rows = np.arange(x_out.size)
    if xs.size == 1:
        hit = ~lo & ~hi
    else:
        idx, wt = _lut.axis_weights(xs, x_out, "linear")
        hit = np.zeros(x_out.size, dtype=bool)
        inside = ~lo & ~hi
        for k in range(2):
            np.add.at(w, (rows[inside], order[idx[inside, k]]), wt[inside, k])
    if xs.size == 1:
        w[hit, order[0]] = 1.0
    if hold_lo:
        w[lo, order[0]] = 1.0
    if hold_hi:
        w[hi, order[-1]] = 1.0
    return w


#: Largest step of the nodes that extend a table's grids to the horizon [degree].
EXTENSION_STEP = 5.0


def lut_edges(edges: dict[str, str]) -> tuple[bool, bool, bool]:
    return _lut.table_edges(edges)


def extend_grid(grid: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """``grid`` with nodes at most :data:`EXTENSION_STEP` apart added out to ``[lo, hi]``."""
    parts = [grid]
    if grid[0] > lo:
        n = int(np.ceil((grid[0] - lo) / EXTENSION_STEP))
        parts.insert(0, np.linspace(lo, grid[0], n + 1)[:-1])
    if grid[-1] < hi:
        n = int(np.ceil((hi - grid[-1]) / EXTENSION_STEP))
        parts.append(np.linspace(grid[-1], hi, n + 1)[1:])
    return np.concatenate(parts)


def per_theta_tables(
    measured_ti: np.ndarray,
    ti_s: np.ndarray,
    dt_s: np.ndarray,
    ph_s: np.ndarray,
    spectra: np.ndarray,
    ref: np.ndarray,
    dt_grid: np.ndarray,
    phi_grid: np.ndarray,
    *,
    hold_all: bool = False,
) -> np.ndarray:
    """Steps 1 and 2 of the construction: every measured incidence angle on the grid.

    ``hold_all`` holds every edge (for interpolating ratios, which have no zero
    reference points).
    """
    n_wl = spectra.shape[1]
    per_theta = np.zeros((measured_ti.size, dt_grid.size, phi_grid.size, n_wl))
    for a, t in enumerate(measured_ti):
        in_t = np.flatnonzero(ti_s == t)
        rows = np.unique(dt_s[in_t])
        if rows.size < (1 if hold_all else 2):
            raise ValidationError(
                f"delta_theta: theta_i = {t} has measurements at a single delta_theta; need >= 2"
            )
        # Step 1: phi interpolation within every delta_theta row of this theta_i.
        row_vals = np.zeros((rows.size, phi_grid.size, n_wl))
        row_ref = np.zeros(rows.size, dtype=bool)
        row_n = np.zeros(rows.size, dtype=int)
        for r, d in enumerate(rows):
            sel = in_t[dt_s[in_t] == d]
            edge = sel[np.argmax(ph_s[sel])]
            # A row measured at phi = 0 only (the in-plane delta_theta extents of the
            # scheme) says nothing about phi > 0: it is not held out of the plane.
            hold = hold_all or (sel.size > 1 and not ref[edge])
            w = interp_weights(
                ph_s[sel], phi_grid, hold_lo=hold_all, hold_hi=hold
            )  # (n_phi, n_sel)
            row_vals[r] = w @ spectra[sel]
            row_ref[r] = bool(np.all(ref[sel]))
            row_n[r] = sel.size
        if not hold_all:
            # A measured (apparatus-limited) in-plane extent borrows the phi profile of the
            # nearest fully measured row, scaled to its own in-plane value.
            full = np.flatnonzero(row_n > 1)
            for lone in np.flatnonzero((row_n == 1) & ~row_ref):
                if full.size == 0:
                    break
                adj = full[np.argmin(np.abs(full - lone))]
                base = row_vals[adj, 0]
                scale = np.divide(row_vals[lone, 0], base, out=np.zeros_like(base), where=base > 0)
                row_vals[lone, 1:] = row_vals[adj, 1:] * scale
        # Step 2: delta_theta interpolation for every grid phi.
        w = interp_weights(
            rows, dt_grid, hold_lo=hold_all or not row_ref[0], hold_hi=hold_all or not row_ref[-1]
        )
        per_theta[a] = np.einsum("dr,rpl->dpl", w, row_vals)
    return per_theta


def blend_weights(ti: np.ndarray, lo: float, hi: float, width: float) -> np.ndarray:
    """Weight of the fitted model: 0 inside [lo, hi], rising smoothly to 1 over ``width``
    degrees outside (a cubic smoothstep, so the table stays continuous in theta_i)."""
    d = np.maximum(lo - ti, 0.0) + np.maximum(ti - hi, 0.0)
    x = np.clip(d / width, 0.0, 1.0) if width > 0 else (d > 0).astype(float)
    return x * x * (3.0 - 2.0 * x)


#: Gauss-Legendre nodes of the azimuthal average at normal incidence.
N_AZIMUTH = 64


def azimuthal_average(
    row: np.ndarray, dt: np.ndarray, ph: np.ndarray, zero_edges: tuple[bool, bool, bool]
) -> np.ndarray:
    """The ``theta_i = 0`` row replaced by its average over the illumination-plane azimuth.

    At normal incidence an observer at polar angle ``theta_r`` and azimuth ``psi``
    from the (arbitrary) plane has ``delta_theta = atan2(sin theta_r cos psi,
    cos theta_r)`` and ``phi = asin(sin theta_r |sin psi|)``; every node of the
    row becomes the mean over ``psi`` in ``[0, pi]`` of the linearly interpolated
    row along the contour of its own ``theta_r``.
    """
    x, w = np.polynomial.legendre.leggauss(N_AZIMUTH)
    psi = 0.5 * np.pi * (x + 1.0)
    w = w / 2.0  # mean over [0, pi]: the weights sum to 1
    tr = np.radians(_lut.observer_polar_angle(0.0, dt[:, None], ph[None, :]))  # (n_dt, n_phi)
    c_dt = np.degrees(np.arctan2(np.sin(tr)[..., None] * np.cos(psi), np.cos(tr)[..., None]))
    c_ph = np.degrees(np.arcsin(np.clip(np.sin(tr)[..., None] * np.sin(psi), 0.0, 1.0)))
    table = np.stack([row, row])
    vals = _lut.lookup_kernel(
        table, np.array([0.0, 1.0]), dt, ph, 0.0, c_dt, c_ph, "linear", zero_edges=zero_edges
    )  # (n_dt, n_phi, n_psi, n_wl)
    return np.einsum("dpql,q->dpl", vals, w)
