"""Pure-numpy kernels behind :mod:`sbrdf_xr.materials.tables`: look-up, smoothing splines,
quadrature.

Nothing here knows about xarray or files; every function takes and returns plain
arrays so that it can be tested against closed forms and reused by the simulation
layer.  Angles are in degrees, wavelengths in nanometres.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray

from ..errors import ValidationError

__all__ = [
    "LOOKUP_METHODS",
    "axis_weights",
    "hemispherical_reflectance_kernel",
    "lookup_kernel",
    "lookup_matrix",
    "normal_incidence_weight",
    "smoothing_spline_matrix",
    "table_edges",
    "table_normal_blend",
]

#: Look-up methods and the number of grid nodes each uses per axis.
LOOKUP_METHODS: dict[str, int] = {"nearest": 1, "linear": 2, "cubic": 4}

#: Queries this far beyond a zero-outside edge [degree] still count as on the edge:
#: it absorbs the rounding of angles computed from vectors (~1e-13 deg).
EDGE_TOL_DEG = 1e-9

Method = Literal["nearest", "linear", "cubic"]


def table_edges(attrs: dict) -> tuple[bool, bool, bool]:
    """``zero_edges`` of a table from its attributes (default: all zero, the paper's policy).

    :func:`sbrdf_xr.materials.tables.build_lut` records ``edge_delta_theta_min``,
    ``edge_delta_theta_max`` and ``edge_phi_max`` as ``"zero"`` (a reference point)
    or ``"hold"`` (a measured point where the apparatus stopped).

    Examples
    --------
    >>> from sbrdf_xr.kernels.lut import table_edges
    >>> table_edges({})
    (True, True, True)
    >>> table_edges({"edge_delta_theta_min": "zero", "edge_phi_max": "hold"})
    (True, True, False)
    """
    lo, hi, phi = (
        attrs.get(k, "zero") != "hold"
        for k in ("edge_delta_theta_min", "edge_delta_theta_max", "edge_phi_max")
    )
    return lo, hi, phi


def table_normal_blend(attrs: dict) -> float:
    """``normal_blend`` of a table from its attributes [degree] (0: none, the paper's look-up).

    :func:`sbrdf_xr.materials.tables.build_lut` (``normal_incidence="symmetric"``, its
    default) and :func:`sbrdf_xr.materials.models.render` record it as
    ``normal_incidence_blend``; see :func:`lookup_matrix`.

    Examples
    --------
    >>> from sbrdf_xr.kernels.lut import table_normal_blend
    >>> table_normal_blend({"normal_incidence": "symmetric", "normal_incidence_blend": 5.0})
    5.0
    >>> table_normal_blend({"normal_incidence": "paper", "normal_incidence_blend": 5.0})
    0.0
    """
    if attrs.get("normal_incidence", "paper") != "symmetric":
        return 0.0
    return float(attrs.get("normal_incidence_blend", 0.0))


def normal_incidence_weight(theta_i: ArrayLike, blend: float) -> NDArray[np.float64]:
    """Weight of the normal-incidence profile in a look-up: ``1 - smoothstep(theta_i / blend)``.

    One at ``theta_i = 0``, zero from ``theta_i = blend`` on, with zero slope at both
    ends (so the look-up stays smooth in ``theta_i``); ``1 - 3 x**2 + 2 x**3`` with
    ``x = theta_i / blend``.  Zero everywhere for ``blend <= 0``.

    Examples
    --------
    >>> from sbrdf_xr.kernels.lut import normal_incidence_weight
    >>> normal_incidence_weight([0.0, 2.5, 5.0, 10.0], 5.0).tolist()
    [1.0, 0.5, 0.0, 0.0]
    >>> normal_incidence_weight([0.0, 2.5], 0.0).tolist()
    [0.0, 0.0]
    """
    ti = np.asarray(theta_i, dtype=np.float64)
    if not blend > 0:
        return np.zeros(ti.shape)
    x = np.clip(ti / blend, 0.0, 1.0)
    return 1.0 - x * x * (3.0 - 2.0 * x)


def observer_polar_angle(
    theta_i: ArrayLike, delta_theta: ArrayLike, phi: ArrayLike
) -> NDArray[np.float64]:
    """Observer polar angle ``theta_r`` [degree] from paper-000 angles [degree].

    ``cos theta_r = cos(phi) cos(theta_i + delta_theta)`` and
    ``sin^2 theta_r = sin^2 phi + cos^2 phi sin^2(theta_i + delta_theta)`` (an arctan2
    of the two: accurate at ``theta_r`` -> 0).
    """
    t = np.radians(
        np.asarray(theta_i, dtype=np.float64) + np.asarray(delta_theta, dtype=np.float64)
    )
    p = np.radians(np.asarray(phi, dtype=np.float64))
    cp = np.cos(p)
    return np.degrees(np.arctan2(np.hypot(np.sin(p), cp * np.sin(t)), np.abs(cp * np.cos(t))))


def check_method(method: str) -> str:
    """Validate a look-up method name.

    Raises
    ------
    ValidationError
        If ``method`` is not one of :data:`LOOKUP_METHODS`.
    """
    if method not in LOOKUP_METHODS:
        raise ValidationError(
            f"method: unknown look-up method {method!r}; allowed: {', '.join(LOOKUP_METHODS)}"
        )
    return method


def axis_weights(
    grid: NDArray[np.floating], x: NDArray[np.floating], method: str
) -> tuple[NDArray[np.intp], NDArray[np.float64]]:
    """Node indices and weights interpolating along one strictly increasing axis.

    Values outside the grid are clamped to its ends (callers zero them where the
    out-of-range policy says so).

    Parameters
    ----------
    grid : ndarray, shape (n,)
        Strictly increasing node coordinates [degree].
    x : ndarray, shape (q,)
        Query coordinates [degree], finite.
    method : {"nearest", "linear", "cubic"}
        ``nearest``: the closest node (ties go up), the paper 000 look-up (§3.4).
        ``linear``: the two bracketing nodes.  ``cubic``: four-point Lagrange
        interpolation on the nodes around ``x`` (shifted inwards at the ends),
        exact for cubic polynomials on non-uniform grids.

    Returns
    -------
    idx : ndarray of int, shape (q, k)
        Node indices.
    w : ndarray of float64, shape (q, k)
        Weights summing to one on every row.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.kernels.lut import axis_weights
    >>> grid = np.array([0.0, 10.0, 20.0, 30.0])
    >>> idx, w = axis_weights(grid, np.array([4.0, 15.0]), "linear")
    >>> idx.tolist(), w.round(6).tolist()
    ([[0, 1], [1, 2]], [[0.6, 0.4], [0.5, 0.5]])
    >>> axis_weights(grid, np.array([4.0, 15.0, 99.0]), "nearest")[0].ravel().tolist()
    [0, 2, 3]

    ``cubic`` is exact for a cubic polynomial, here on a non-uniform grid:

    >>> grid = np.array([0.0, 5.0, 15.0, 30.0, 50.0])
    >>> x = np.array([2.0, 21.0, 44.0])
    >>> idx, w = axis_weights(grid, x, "cubic")
    >>> idx.shape, bool(np.allclose((w * grid[idx] ** 3).sum(axis=1), x**3))
    ((3, 4), True)
    """
    n = grid.size
    x = np.clip(np.asarray(x, dtype=np.float64), grid[0], grid[-1])
    if n == 1:
        return np.zeros((x.size, 1), dtype=np.intp), np.ones((x.size, 1))
    i = np.clip(np.searchsorted(grid, x, side="right") - 1, 0, n - 2)
    g0, g1 = grid[i], grid[i + 1]
    t = (x - g0) / (g1 - g0)
    if method == "nearest":
        return (i + (t >= 0.5))[:, None], np.ones((x.size, 1))
    if method == "linear":
        return np.stack([i, i + 1], axis=1), np.stack([1.0 - t, t], axis=1)
    k = min(4, n)
    j0 = np.clip(i - 1, 0, n - k)
    idx = j0[:, None] + np.arange(k)
    nodes = grid[idx]
    w = np.ones((x.size, k))
    for a in range(k):
        for b in range(k):
            if a != b:
                w[:, a] *= (x - nodes[:, b]) / (nodes[:, a] - nodes[:, b])
    return idx, w


def lookup_matrix(
    theta_grid: NDArray[np.floating],
    delta_theta_grid: NDArray[np.floating],
    phi_grid: NDArray[np.floating],
    theta_i: ArrayLike,
    delta_theta: ArrayLike,
    phi: ArrayLike,
    method: str = "linear",
    weights: ArrayLike | None = None,
    zero_edges: tuple[bool, bool, bool] = (True, True, True),
    normal_blend: float = 0.0,
) -> sp.csr_matrix:
    """Sparse matrix mapping look-up-table nodes to query geometries.

    Row ``q`` holds the interpolation weights of query ``q`` on the flattened
    ``(theta_i, delta_theta, phi)`` nodes, times ``weights[q]`` when given, so that
    ``lookup_matrix(...) @ lut.reshape(-1, n_wavelength)`` is the looked-up spectra
    and summing rows gives weighted sums of spectra (the facet sum of paper 000
    Eq. 3-4) without materialising each spectrum.

    Out-of-range policy
    -------------------
    ``theta_i`` is clamped to the grid (a table spans 0-90 deg).  Beyond the grid's
    ``delta_theta`` extent, or for ``phi`` above its largest value, the weights are
    zero: paper 000 §3.1 places reference points, where the reflectance is
    indistinguishable from noise and taken as zero, at the edges of the measured
    range.  An edge that is a measured point instead (the apparatus stopped before
    the noise; ``zero_edges`` False for it) is clamped, holding its value.  ``phi``
    below the first node is clamped.

    Parameters
    ----------
    theta_grid, delta_theta_grid, phi_grid : ndarray
        Strictly increasing table coordinates [degree].
    theta_i, delta_theta, phi : array_like
        Query angles [degree], broadcast together and flattened in C order.
    method : {"nearest", "linear", "cubic"}
        See :func:`axis_weights`.
    weights : array_like, optional
        Per-query factors (for example projected areas) [any unit].
    zero_edges : tuple of 3 bool
        Whether the table is zero beyond its smallest ``delta_theta``, its largest
        ``delta_theta`` and its largest ``phi`` (reference points), or holds the
        edge values there (:func:`table_edges`).
    normal_blend : float, default 0
        Width [degree] of the normal-incidence blend (:func:`table_normal_blend`);
        0 switches it off.

    Normal incidence
    ----------------
    At ``theta_i = 0`` the illumination plane is undefined, so a physical sBRDF
    depends on the observer through its polar angle ``theta_r`` only.  With
    ``normal_blend = b > 0`` (and ``theta_grid[0] == 0``) a query is

    ``f = w g(theta_r) + (1 - w) T(theta_i, delta_theta, phi)``

    with ``w = normal_incidence_weight(theta_i, b)``, ``T`` the interpolation above,
    ``gamma = observer_polar_angle(0, delta_theta, phi)`` the angle between the
    observer and the specular direction (``cos gamma = cos(phi) cos(delta_theta)``;
    the observer's polar angle ``theta_r`` at normal incidence, and it keeps the
    profile centred on specular across the blend, as a lobe is), and ``g`` the
    table's ``theta_i = 0`` row interpolated (with ``method``) along its in-plane
    profile: the mean of the row at ``(delta_theta, phi) = (+gamma, 0)`` and
    ``(-gamma, 0)``, of whichever of the two is inside the table (or beyond a held
    edge), zero if neither is.  At ``theta_i = 0`` ``g`` does not depend on the Sun's
    azimuth, so the look-up is continuous as the Sun crosses a facet normal.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (n_queries, n_theta * n_delta_theta * n_phi)

    Examples
    --------
    A 3 x 3 x 3 table; a linear look-up inside it has 8 weights summing to one, one
    beyond its largest ``delta_theta`` (a zero edge) none, unless that edge is held:

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.lut import lookup_matrix
    >>> t, d, p = np.array([0.0, 45, 90]), np.array([-60.0, 0, 60]), np.array([0.0, 45, 90])
    >>> m = lookup_matrix(t, d, p, [30.0, 30.0], [10.0, 70.0], [20.0, 20.0])
    >>> m.shape, np.diff(m.indptr).tolist(), m.sum(axis=1).round(12).ravel().tolist()
    ((2, 27), [8, 8], [1.0, 0.0])
    >>> held = lookup_matrix(t, d, p, 30.0, 70.0, 20.0, zero_edges=(True, False, True))
    >>> round(float(held.sum()), 12)
    1.0
    """
    check_method(method)
    arrays = [np.asarray(v, dtype=np.float64) for v in (theta_i, delta_theta, phi)]
    if weights is not None:
        arrays.append(np.asarray(weights, dtype=np.float64))
    arrays = [np.ravel(a) for a in np.broadcast_arrays(*arrays)]
    ti, dt, ph = arrays[:3]
    q = ti.size
    it, wt = axis_weights(theta_grid, ti, method)
    idt, wdt = axis_weights(delta_theta_grid, dt, method)
    iph, wph = axis_weights(phi_grid, ph, method)
    ndt, nph = delta_theta_grid.size, phi_grid.size
    idx = (it[:, :, None, None] * ndt + idt[:, None, :, None]) * nph + iph[:, None, None, :]
    w = wt[:, :, None, None] * wdt[:, None, :, None] * wph[:, None, None, :]
    z_lo, z_hi, z_phi = zero_edges
    outside = (
        (z_lo & (dt < delta_theta_grid[0] - EDGE_TOL_DEG))
        | (z_hi & (dt > delta_theta_grid[-1] + EDGE_TOL_DEG))
        | (z_phi & (ph > phi_grid[-1] + EDGE_TOL_DEG))
    )
    scale = np.where(outside, 0.0, 1.0)
    if weights is not None:
        scale = scale * arrays[3]
    wn = None
    if normal_blend > 0 and theta_grid[0] == 0.0:
        wn = normal_incidence_weight(ti, normal_blend)
        if not np.any(wn > 0):
            wn = None
    if wn is not None:
        scale = scale * (1.0 - wn)
    k = int(np.prod(w.shape[1:]))
    w = (w * scale[:, None, None, None]).reshape(q, k)
    n_nodes = theta_grid.size * ndt * nph
    m = sp.csr_matrix(
        (w.ravel(), idx.reshape(q, k).ravel(), np.arange(0, q * k + 1, k)),
        shape=(q, n_nodes),
    )
    if wn is None:
        return m
    rows = np.flatnonzero(wn > 0)
    # The angle from the specular direction (theta_r itself at normal incidence): the
    # profile stays centred on specular across the blend, as a lobe does.
    tr = observer_polar_angle(0.0, dt[rows], ph[rows])
    valid = [
        (tr <= delta_theta_grid[-1] + EDGE_TOL_DEG) | (not z_hi),
        (-tr >= delta_theta_grid[0] - EDGE_TOL_DEG) | (not z_lo),
    ]
    n_valid = valid[0].astype(float) + valid[1].astype(float)
    base = wn[rows] * np.divide(1.0, n_valid, out=np.zeros_like(n_valid), where=n_valid > 0)
    if weights is not None:
        base = base * arrays[3][rows]
    iph0, wph0 = axis_weights(phi_grid, np.zeros(1), method)
    data, cols, rr = [], [], []
    for sign, ok in zip((1.0, -1.0), valid, strict=True):
        i1, w1 = axis_weights(delta_theta_grid, sign * tr, method)
        ww = (base * ok)[:, None, None] * w1[:, :, None] * wph0[0][None, None, :]
        cc = i1[:, :, None] * nph + iph0[0][None, None, :]
        data.append(ww.ravel())
        cols.append(cc.ravel())
        rr.append(np.repeat(rows, ww.shape[1] * ww.shape[2]))
    g = sp.csr_matrix(
        (np.concatenate(data), (np.concatenate(rr), np.concatenate(cols))), shape=(q, n_nodes)
    )
    return m + g


def lookup_kernel(
    values: NDArray[np.floating],
    theta_grid: NDArray[np.floating],
    delta_theta_grid: NDArray[np.floating],
    phi_grid: NDArray[np.floating],
    theta_i: ArrayLike,
    delta_theta: ArrayLike,
    phi: ArrayLike,
    method: str = "linear",
    zero_edges: tuple[bool, bool, bool] = (True, True, True),
    normal_blend: float = 0.0,
) -> NDArray[np.floating]:
    """Spectra of a look-up table at arbitrary geometries (paper 000 §3.4).

    Parameters
    ----------
    values : ndarray, shape (n_theta, n_delta_theta, n_phi, n_wavelength)
        Table values [sr-1].
    theta_grid, delta_theta_grid, phi_grid : ndarray
        Table coordinates [degree].
    theta_i, delta_theta, phi : array_like
        Query angles [degree], broadcast together; finite.
    method : {"nearest", "linear", "cubic"}
        Interpolation method (:func:`axis_weights`).  ``cubic`` can overshoot below
        zero next to steep edges; results are clipped at 0 because a BRDF is
        non-negative.
    zero_edges : tuple of 3 bool
        See :func:`lookup_matrix`.
    normal_blend : float, default 0
        See :func:`lookup_matrix` [degree].

    Returns
    -------
    ndarray, shape broadcast(theta_i, delta_theta, phi) + (n_wavelength,)
        Spectra [sr-1] in the dtype of ``values``; out-of-range policy as in
        :func:`lookup_matrix`.

    Examples
    --------
    A linear look-up reproduces a table that is linear in the angles:

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.lut import lookup_kernel
    >>> t, d, p = np.array([0.0, 45, 90]), np.array([-60.0, 0, 60]), np.array([0.0, 45, 90])
    >>> T, D, P = np.meshgrid(t, d, p, indexing="ij")
    >>> values = (100 + T + 2 * D + 3 * P)[..., None] * [1.0, 2.0]  # two wavelengths
    >>> out = lookup_kernel(values, t, d, p, [10.0, 20.0], 5.0, 30.0)
    >>> out.shape, out.round(9).tolist()
    ((2, 2), [[210.0, 420.0], [220.0, 440.0]])
    >>> lookup_kernel(values.astype(np.float32), t, d, p, 10.0, 5.0, 30.0).dtype
    dtype('float32')
    """
    shape = np.broadcast_shapes(np.shape(theta_i), np.shape(delta_theta), np.shape(phi))
    m = lookup_matrix(
        theta_grid,
        delta_theta_grid,
        phi_grid,
        theta_i,
        delta_theta,
        phi,
        method,
        zero_edges=zero_edges,
        normal_blend=normal_blend,
    )
    v2 = values.reshape(-1, values.shape[-1])
    if v2.dtype != np.float64:
        m = m.astype(v2.dtype)
    out = np.asarray(m @ v2)
    if method == "cubic":
        np.maximum(out, 0, out=out)
    return out.reshape(*shape, values.shape[-1])


# ------------------------------------------------------------ smoothing splines


def smoothing_spline_matrix(
    x: ArrayLike,
    x_out: ArrayLike,
    lam: float,
    extrapolation: str = "cubic",
) -> NDArray[np.float64]:
    """Linear operator of a natural cubic smoothing spline, evaluated at ``x_out``.

    The cubic smoothing spline ``f`` minimises
    ``sum_i (y_i - f(x_i))**2 + lam * integral(f''(x)**2 dx)`` (Reinsch 1967;
    the same functional as :func:`scipy.interpolate.make_smoothing_spline`).  ``f``
    is linear in ``y``, so the whole fit-and-evaluate step is one matrix ``E``
    with ``f(x_out) = E @ y``, applied at once to every column of the table
    (paper 000 §3.2: a spline in ``theta_i`` for every ``phi``, ``delta_theta`` and
    wavelength).

    Parameters
    ----------
    x : array_like, shape (n,)
        Strictly increasing data sites [degree], ``n >= 2`` (two sites give the line
        through them).
    x_out : array_like, shape (m,)
        Evaluation points [degree].
    lam : float
        Smoothing parameter ``>= 0`` [degree**3]; 0 interpolates.
    extrapolation : {"cubic", "linear", "constant"}
        Beyond the end sites: ``cubic`` continues the end polynomial pieces (what a
        piecewise-polynomial evaluation does, and what produces the discontinuities
        paper 000 §4.2 reports); ``linear`` continues with the end slope (the natural
        spline's own extension, zero curvature); ``constant`` holds the end values.

    Returns
    -------
    ndarray, shape (m, n)

    Examples
    --------
    ``lam = 0`` interpolates (the operator at the sites is the identity); any ``lam``
    reproduces a straight line, which has no curvature to penalise:

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.lut import smoothing_spline_matrix
    >>> x = np.array([0.0, 10.0, 25.0, 40.0, 60.0])
    >>> bool(np.allclose(smoothing_spline_matrix(x, x, 0.0), np.eye(5)))
    True
    >>> e = smoothing_spline_matrix(x, [5.0, 50.0, 70.0], 300.0, extrapolation="linear")
    >>> e.shape, (e @ (2 * x + 1)).round(9).tolist()
    ((3, 5), [11.0, 101.0, 141.0])
    >>> smoothing_spline_matrix(x, x, -1.0)
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.ValidationError: lam: smoothing parameter must be finite and >= 0, got -1.0
    """
    x = np.asarray(x, dtype=np.float64)
    xo = np.asarray(x_out, dtype=np.float64)
    n = x.size
    if n < 2 or np.any(np.diff(x) <= 0):
        raise ValidationError(f"x: need at least 2 strictly increasing sites, got {x.tolist()}")
    if not (np.isfinite(lam) and lam >= 0):
        raise ValidationError(f"lam: smoothing parameter must be finite and >= 0, got {lam}")
    if extrapolation not in ("cubic", "linear", "constant"):
        raise ValidationError(
            f"extrapolation: got {extrapolation!r}; allowed: cubic, linear, constant"
        )
    h = np.diff(x)
    eye = np.eye(n)
    if n > 2:
        # Q: n x (n-2) second-difference operator; R: (n-2) x (n-2) tridiagonal.
        q = np.zeros((n, n - 2))
        r = np.zeros((n - 2, n - 2))
        for j in range(n - 2):
            q[j, j] = 1.0 / h[j]
            q[j + 1, j] = -1.0 / h[j] - 1.0 / h[j + 1]
            q[j + 2, j] = 1.0 / h[j + 1]
            r[j, j] = (h[j] + h[j + 1]) / 3.0
            if j + 1 < n - 2:
                r[j, j + 1] = r[j + 1, j] = h[j + 1] / 6.0
        gamma = np.linalg.solve(r + lam * q.T @ q, q.T @ eye)  # (n-2, n)
        f = eye - lam * q @ gamma  # fitted values at the sites, as operator on y
        c = np.zeros((n, n))
        c[1:-1] = gamma  # second derivatives (natural: zero at the ends)
    else:
        f, c = eye, np.zeros((n, n))
    # Evaluate the piecewise cubic with values f and second derivatives c.
    k = np.clip(np.searchsorted(x, xo, side="right") - 1, 0, n - 2)
    hk = h[k][:, None]
    a = (x[k + 1][:, None] - xo[:, None]) / hk
    b = (xo[:, None] - x[k][:, None]) / hk
    e = a * f[k] + b * f[k + 1] + ((a**3 - a) * c[k] + (b**3 - b) * c[k + 1]) * hk**2 / 6.0
    if extrapolation != "cubic":
        lo, hi = xo < x[0], xo > x[-1]
        slope0 = (f[1] - f[0]) / h[0] - h[0] * (2 * c[0] + c[1]) / 6.0
        slope1 = (f[-1] - f[-2]) / h[-1] + h[-1] * (c[-2] + 2 * c[-1]) / 6.0
        if extrapolation == "linear":
            e[lo] = f[0] + (xo[lo] - x[0])[:, None] * slope0
            e[hi] = f[-1] + (xo[hi] - x[-1])[:, None] * slope1
        else:
            e[lo] = f[0]
            e[hi] = f[-1]
    return e


def csaps_default_lambda(x: ArrayLike) -> float:
    """Default smoothing parameter: the choice of MATLAB's ``csaps``.

    ``csaps`` weighs ``p * sum(residual**2) + (1 - p) * integral(f''**2)`` with the
    default ``p = 1 / (1 + h**3 / 6)``, ``h`` the mean site spacing; in the
    ``lam`` form of :func:`smoothing_spline_matrix` this is ``lam = h**3 / 6``.
    Paper 000 §3.2 names cubic smoothing splines without the parameter; this is the
    default of the tool most used for them.

    Parameters
    ----------
    x : array_like
        Data sites [degree].

    Returns
    -------
    float
        ``lam`` [degree**3].
    """
    x = np.asarray(x, dtype=np.float64)
    h = (x[-1] - x[0]) / (x.size - 1)
    return float(h**3 / 6.0)


# ----------------------------------------------------------------- quadrature

_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(4)


#: Largest quadrature interval [degree]: four Gauss points on 5 degrees integrate
#: the cosines to ~1e-13 relative.
_MAX_STEP_DEG = 5.0


def _gauss_nodes(breaks: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Four-point Gauss-Legendre nodes and weights on every interval of ``breaks``,
    each interval split into pieces no wider than :data:`_MAX_STEP_DEG`."""
    pieces = np.maximum(np.ceil(np.diff(breaks) / _MAX_STEP_DEG).astype(int), 1)
    breaks = np.concatenate(
        [
            np.linspace(a, b, k + 1)[:-1]
            for a, b, k in zip(breaks[:-1], breaks[1:], pieces, strict=True)
        ]
        + [breaks[-1:]]
    )
    a, b = breaks[:-1, None], breaks[1:, None]
    nodes = (0.5 * (b - a) * _GL_NODES + 0.5 * (a + b)).ravel()
    weights = (0.5 * (b - a) * _GL_WEIGHTS).ravel()
    return nodes, weights


def hemispherical_reflectance_kernel(
    values: NDArray[np.floating],
    theta_grid: NDArray[np.floating],
    delta_theta_grid: NDArray[np.floating],
    phi_grid: NDArray[np.floating],
    theta_i: ArrayLike | None = None,
    method: str = "linear",
    zero_edges: tuple[bool, bool, bool] = (True, True, True),
    normal_blend: float = 0.0,
) -> NDArray[np.float64]:
    """Directional-hemispherical reflectance of a look-up table by quadrature.

    ``rho(theta_i, lambda) = integral over the visible hemisphere of
    f_r cos(theta_r) d omega`` (paper 001 Eq. 1).  In the coordinates of paper 000
    Fig. 4 the observer is ``o = cos(phi) (sin(t) e_f + cos(t) N) + sin(phi) p`` with
    ``t = theta_i + delta_theta``, so ``d omega = cos(phi) d phi d t`` and
    ``cos(theta_r) = cos(phi) cos(t)``; with isotropy about the plane,

    ``rho = 2 * integral_phi integral_t f_r(theta_i, t - theta_i, phi) cos(phi)**2 cos(t) dt dphi``

    over ``|t| < 90 deg``.  The integrand is integrated exactly as the table is
    interpolated: four-point Gauss-Legendre on every interval between table nodes
    (and the horizon ``t = +-90 deg``), which integrates the piecewise-multilinear
    interpolant times the smooth cosines to ~1e-12 relative.

    Parameters
    ----------
    values : ndarray, shape (n_theta, n_delta_theta, n_phi, n_wavelength)
        Table [sr-1].
    theta_grid, delta_theta_grid, phi_grid : ndarray
        Table coordinates [degree].
    theta_i : array_like, optional
        Incidence angles [degree]; default the table's ``theta_grid``.
    method : str
        Look-up method used for the integrand.
    zero_edges : tuple of 3 bool
        See :func:`lookup_matrix`; a held edge extends the integral to the horizon
        (and to ``phi`` = 90 deg).
    normal_blend : float, default 0
        See :func:`lookup_matrix` [degree].

    Returns
    -------
    ndarray, shape (n_theta_i, n_wavelength)
        Reflectance [1].

    Examples
    --------
    A Lambertian table ``f_r = 0.5 / pi`` with held edges (it extends to the horizon)
    reflects 0.5 at every incidence angle:

    >>> import numpy as np
    >>> from sbrdf_xr.kernels.lut import hemispherical_reflectance_kernel
    >>> t, d, p = np.array([0.0, 45, 90]), np.array([-90.0, 0, 90]), np.array([0.0, 90])
    >>> values = np.full((3, 3, 2, 1), 0.5 / np.pi)
    >>> rho = hemispherical_reflectance_kernel(
    ...     values, t, d, p, theta_i=[0.0, 30.0, 60.0], zero_edges=(False, False, False)
    ... )
    >>> rho.shape, rho.round(9).ravel().tolist()
    ((3, 1), [0.5, 0.5, 0.5])
    """
    ti_all = theta_grid if theta_i is None else np.atleast_1d(np.asarray(theta_i, float))
    if phi_grid.size == 1:
        raise ValidationError("phi: at least two phi nodes are needed for the quadrature")
    z_lo, z_hi, z_phi = zero_edges
    phi_breaks = np.asarray(phi_grid, dtype=np.float64)
    if not z_phi and phi_breaks[-1] < 90.0:
        phi_breaks = np.append(phi_breaks, 90.0)
    phi_full = phi_breaks if phi_breaks[-1] >= 90.0 else np.append(phi_breaks, 90.0)
    out = np.empty((ti_all.size, values.shape[-1]))
    v2 = values.reshape(-1, values.shape[-1]).astype(np.float64, copy=False)  # once, not per row
    for k, ti in enumerate(ti_all):
        # The normal-incidence profile reaches beyond the table's extents: integrate the
        # whole hemisphere where it has weight.
        whole = normal_blend > 0 and ti < normal_blend and theta_grid[0] == 0.0
        phi_nodes, phi_w = _gauss_nodes(phi_full if whole else phi_breaks)
        lo = -90.0 if (not z_lo or whole) else max(-90.0, ti + delta_theta_grid[0])
        hi = 90.0 if (not z_hi or whole) else min(90.0, ti + delta_theta_grid[-1])
        if hi <= lo:
            out[k] = 0.0
            continue
        inner = ti + delta_theta_grid
        breaks = np.unique(np.concatenate([[lo, hi], inner[(inner > lo) & (inner < hi)]]))
        t_nodes, t_w = _gauss_nodes(breaks)
        tt, pp = np.meshgrid(t_nodes, phi_nodes, indexing="ij")
        ww = np.outer(t_w, phi_w) * np.cos(np.radians(pp)) ** 2 * np.cos(np.radians(tt))
        m = lookup_matrix(
            theta_grid,
            delta_theta_grid,
            phi_grid,
            ti,
            tt - ti,
            pp,
            method,
            weights=ww,
            zero_edges=zero_edges,
            normal_blend=normal_blend,
        )
        w_nodes = np.asarray(m.sum(axis=0)).ravel()
        used = np.flatnonzero(w_nodes)  # the nodes around theta_i: a few rows of the table
        spectra = w_nodes[used] @ v2[used]
        out[k] = 2.0 * np.radians(1.0) ** 2 * spectra.ravel()
    return out
