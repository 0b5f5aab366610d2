"""The numpy core of the table construction of paper 000 §3.2.

Grids, interpolation weights, steps 1 and 2 per measured incidence angle, the
model blend and the azimuthal average at normal incidence.

:func:`sbrdf_xr.materials.tables.build_lut` drives it on xarray objects; everything here takes and
returns plain arrays.  Angles [degree] also come as astropy Quantities, converted first
(:func:`sbrdf_xr.units.to_unit`; another kind raises :class:`~sbrdf_xr.errors.UnitError`).
"""

from __future__ import annotations

import numpy as np

from ..errors import ValidationError
from ..kernels import lut as _lut
from ..units import to_unit


def paper_phi_grid(phi_max: float, n: int = 21) -> np.ndarray:
    """Uniform ``phi`` grid of paper 000 §3.2: ``n`` points from 0 to ``phi_max`` [degree].

    Parameters
    ----------
    phi_max : float
        Largest measured ``phi`` of the material [degree], ``> 0``.
    n : int, default 21
        Number of grid points (the paper's 21).

    Returns
    -------
    ndarray, shape (n,)
        The grid [degree].

    Examples
    --------
    >>> from sbrdf_xr.materials.construction import paper_phi_grid
    >>> paper_phi_grid(10.0, 5)
    array([ 0. ,  2.5,  5. ,  7.5, 10. ])
    """
    phi_max = to_unit(phi_max, "deg", "phi_max")
    if not phi_max > 0:
        raise ValidationError(f"phi_max: must be > 0 degree, got {phi_max}")
    return np.linspace(0.0, float(phi_max), n)


def paper_delta_theta_grid(dt_min: float, dt_max: float, n: int = 21) -> np.ndarray:
    """``delta_theta`` grid of paper 000 §3.2: 0 at the median, uniform on either side.

    For the paper's ``n = 21`` the steps are ``dt_min/10`` below specular and
    ``dt_max/10`` above it.

    Parameters
    ----------
    dt_min, dt_max : float
        Measured extent of ``delta_theta`` over all incidence angles [degree],
        ``dt_min < 0 < dt_max``.
    n : int, default 21
        Number of grid points, odd and ``>= 3``.

    Returns
    -------
    ndarray, shape (n,)
        The grid [degree], with 0 at index ``n // 2``.

    Examples
    --------
    >>> from sbrdf_xr.materials.construction import paper_delta_theta_grid
    >>> paper_delta_theta_grid(-4.0, 8.0, 5)
    array([-4., -2.,  0.,  4.,  8.])
    >>> paper_delta_theta_grid(-40.0, 30.0).size
    21
    """
    dt_min, dt_max = to_unit(dt_min, "deg", "dt_min"), to_unit(dt_max, "deg", "dt_max")
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

    Parameters
    ----------
    x_data : ndarray, shape (m,)
        Abscissae of the data, in any order [degree].
    x_out : ndarray, shape (k,)
        Abscissae to interpolate to [degree].
    hold_lo, hold_hi : bool, default False
        Hold the edge value below / above the data instead of dropping to zero.

    Returns
    -------
    ndarray, shape (k, m)
        Weights: ``w @ y`` interpolates values ``y`` given at ``x_data``.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials.construction import interp_weights
    >>> w = interp_weights(np.array([0.0, 10.0]), np.array([-5.0, 2.5, 15.0]))
    >>> w
    array([[0.  , 0.  ],
           [0.75, 0.25],
           [0.  , 0.  ]])
    >>> interp_weights(np.array([0.0, 10.0]), np.array([15.0]), hold_hi=True)
    array([[0., 1.]])
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
    """``zero_edges`` of a table from its edge attributes (default: all zero, the paper's).

    Parameters
    ----------
    edges : dict
        Attributes ``edge_delta_theta_min``, ``edge_delta_theta_max`` and
        ``edge_phi_max``, each ``"zero"`` (a reference point) or ``"hold"`` (a
        measured point where the apparatus stopped); missing ones are ``"zero"``.

    Returns
    -------
    tuple of bool
        Whether the table drops to zero beyond its lower ``delta_theta``, upper
        ``delta_theta`` and upper ``phi`` edges.

    Examples
    --------
    >>> from sbrdf_xr.materials.construction import lut_edges
    >>> lut_edges({})
    (True, True, True)
    >>> lut_edges({"edge_phi_max": "hold"})
    (True, True, False)
    """
    return _lut.table_edges(edges)


def extend_grid(grid: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """``grid`` with nodes at most :data:`EXTENSION_STEP` apart added out to ``[lo, hi]``.

    Parameters
    ----------
    grid : ndarray, shape (n,)
        Increasing grid [degree].
    lo, hi : float
        Range to extend it to [degree]; a side already covered is left as it is.

    Returns
    -------
    ndarray
        The extended grid.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials.construction import extend_grid
    >>> extend_grid(np.array([0.0, 10.0, 20.0]), -12.0, 20.0)
    array([-12.,  -8.,  -4.,   0.,  10.,  20.])
    """
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

    Step 1 interpolates every measured ``delta_theta`` row linearly in ``phi``; step 2
    interpolates the rows linearly in ``delta_theta`` (paper 000 §3.2).

    Parameters
    ----------
    measured_ti : ndarray, shape (t,)
        The measured incidence angles [degree].
    ti_s, dt_s, ph_s : ndarray, shape (s,)
        Angles of every sample [degree].
    spectra : ndarray, shape (s, n_wavelength)
        The sBRDF of every sample [sr-1].
    ref : ndarray of bool, shape (s,)
        Whether a sample is a reference point (signal in the noise).
    dt_grid, phi_grid : ndarray
        The output grids [degree].
    hold_all : bool, default False
        Hold every edge (for interpolating ratios, which have no zero reference
        points).

    Returns
    -------
    ndarray, shape (t, len(dt_grid), len(phi_grid), n_wavelength)

    Examples
    --------
    Three rows measured at ``phi = 0`` and 5 deg, halving out of the plane:

    >>> import numpy as np
    >>> from sbrdf_xr.materials.construction import per_theta_tables
    >>> dt = np.array([-2.0, -2.0, 0.0, 0.0, 2.0, 2.0])
    >>> ph = np.array([0.0, 5.0, 0.0, 5.0, 0.0, 5.0])
    >>> spectra = np.array([[1.0], [0.5], [3.0], [1.5], [1.0], [0.5]])
    >>> out = per_theta_tables(
    ...     np.array([30.0]), np.full(6, 30.0), dt, ph, spectra, np.zeros(6, dtype=bool),
    ...     dt_grid=np.array([-2.0, -1.0, 0.0, 1.0, 2.0]), phi_grid=np.array([0.0, 2.5, 5.0]),
    ... )
    >>> out.shape
    (1, 5, 3, 1)
    >>> out[0, :, :, 0]
    array([[1.  , 0.75, 0.5 ],
           [2.  , 1.5 , 1.  ],
           [3.  , 2.25, 1.5 ],
           [2.  , 1.5 , 1.  ],
           [1.  , 0.75, 0.5 ]])
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
    """Weight of the fitted model: 0 inside ``[lo, hi]``, rising smoothly to 1 outside.

    The weight rises over ``width`` degrees as a cubic smoothstep, so the table stays
    continuous in ``theta_i``.

    Parameters
    ----------
    ti : ndarray
        Incidence angles [degree].
    lo, hi : float
        Measured range of the incidence angle [degree].
    width : float
        Width of the transition [degree]; 0 switches at once.

    Returns
    -------
    ndarray
        Weights in ``[0, 1]`` [1], shaped like ``ti``.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials.construction import blend_weights
    >>> blend_weights(np.array([5.0, 10.0, 15.0, 30.0, 45.0, 50.0]), 20.0, 40.0, 10.0)
    array([1. , 1. , 0.5, 0. , 0.5, 1. ])
    """
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

    Parameters
    ----------
    row : ndarray, shape (n_dt, n_phi, n_wavelength)
        The table at ``theta_i = 0`` [sr-1].
    dt, ph : ndarray
        Its ``delta_theta`` and ``phi`` grids [degree].
    zero_edges : tuple of bool
        As :func:`lut_edges` returns.

    Returns
    -------
    ndarray, shape (n_dt, n_phi, n_wavelength)
        The averaged row (Gauss-Legendre quadrature, :data:`N_AZIMUTH` nodes).

    Examples
    --------
    A row that is the same everywhere stays so when its edges are held:

    >>> import numpy as np
    >>> from sbrdf_xr.materials.construction import azimuthal_average
    >>> row = np.full((5, 3, 2), 0.3)
    >>> out = azimuthal_average(row, np.linspace(-10, 10, 5), np.linspace(0, 10, 3),
    ...                         (False, False, False))
    >>> out.shape, round(float(np.abs(out - 0.3).max()), 12)
    ((5, 3, 2), 0.0)
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


def _hold_horizon(lut: np.ndarray, ti: np.ndarray, dt: np.ndarray) -> None:
    """Nodes at or beyond the horizon (``|theta_i + delta_theta| >= 90`` deg, for every
    ``phi``: ``cos(theta_r) = cos(phi) cos(theta_i + delta_theta) <= 0``) take, in place,
    the value of the nearest node inside it in their row.

    No observer sees them; they enter only through the interpolation between them and the
    last visible nodes.  The model rendered there carries its limit at grazing exit, which
    for a specular lobe (``1 / cos(theta_r)``) is orders of magnitude above the measured
    grazing values (the Starlink array scan: 1e-3 sr-1 at 88 deg, the model's limit at 90
    deg 6e2 sr-1), and a look-up a fraction of a node from the horizon would return it.
    Holding the last visible value keeps the look-up continuous up to the horizon.
    """
    theta_r = ti[:, None] + dt[None, :]
    for a in range(ti.size):
        inside = np.flatnonzero(np.abs(theta_r[a]) < 90.0 - 1e-9)
        if inside.size == 0:
            continue
        lo, hi = inside[0], inside[-1]
        lut[a, :lo] = lut[a, lo]
        lut[a, hi + 1 :] = lut[a, hi]


def _held_product(
    base: np.ndarray, ratio: np.ndarray, ti: np.ndarray, dt: np.ndarray, hold_base: bool
) -> np.ndarray:
    """``base * ratio`` (written into ``ratio``) with its horizon nodes held, and those of
    ``base`` too when ``hold_base`` (it is integrated by the renormalisation):
    :func:`_hold_horizon`."""
    lut = np.multiply(base, ratio, out=ratio)
    _hold_horizon(lut, ti, dt)
    if hold_base:
        _hold_horizon(base, ti, dt)
    return lut
