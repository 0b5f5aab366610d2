"""Facet tangents and the azimuth ``psi`` of anisotropic materials.  Pure numpy.

Arguments with a unit (``psi`` and its grids [degree]) also take an astropy Quantity,
converted first (:func:`sbrdf_xr.units.to_unit`; another kind raises
:class:`~sbrdf_xr.errors.UnitError`).

An anisotropic material (brushed metal) reflects differently depending on how the
illumination plane is turned about the facet normal relative to a direction fixed in
the surface, the facet tangent ``t`` (the brushing direction, the direction of the
roughness ``alpha_x`` of :mod:`sbrdf_xr.brdf.anisotropic`).  Its tables have a fifth
axis besides the paper-000 angles, ``psi``.

Convention (extends DESIGN.md "Angle convention", paper 000 Fig. 4)
--------------------------------------------------------------------
For the unit facet normal ``N``, tangent ``t`` (made orthogonal to ``N``), bitangent
``b = N x t``, and the forward direction ``e_f`` and illumination-plane normal
``p = N x e_f`` of :func:`sbrdf_xr.geometry.facet_angles`:

* ``psi = atan2(e_f . b, e_f . t)``: the angle about ``N``, counter-clockwise, from
  the tangent to the forward direction of the illumination plane (the plane that
  contains ``N`` and the Sun direction).
* The paper's ``phi`` is unsigned, so an observer on the ``-p`` side of the plane is
  described by the mirror image of the geometry across the plane, which maps the
  tangent's azimuth ``psi -> -psi``: ``psi`` is negated when ``o . p < 0``.
* ``t`` and ``-t`` are the same tangent (the anisotropic GGX depends on ``(v.t)^2``
  and ``(v.b)^2`` only): ``psi`` is taken modulo 180 degree.
* An observer within :func:`~sbrdf_xr.geometry.normal_incidence_tolerance` of the
  plane (``phi = 0`` up to rounding) is not mirrored, so rounding does not pick
  between ``psi`` and ``-psi`` (which describe the same reflectance there).

So ``psi`` lies in ``[0, 180)`` degree and ``(theta_i, delta_theta, phi, psi)`` covers
every geometry.  ``psi`` is periodic (180 is 0); it jumps from ``psi`` to ``-psi`` as
the observer crosses the illumination plane (``phi = 0``), where the two values
describe mirror-image geometries with equal reflectance, so a table rendered from a
model or measured is continuous there.

Normal incidence: when the Sun's tangential part is shorter than
:func:`sbrdf_xr.geometry.normal_incidence_tolerance`, ``e_f`` is taken from the
observer exactly as :func:`~sbrdf_xr.geometry.facet_angles` does (``phi = 0``; then
``psi`` is the observer's azimuth from the tangent, modulo 180), and if the observer is
along the normal too, from the same fixed perpendicular as
:func:`~sbrdf_xr.geometry.facet_angles` (any plane gives the same answer there).

Facet tangents
--------------
:func:`project_tangents` makes a unit tangent per facet from a direction (one for the
body or one per facet): the direction's component in the facet plane, normalised.
Where that component is shorter than :data:`TANGENT_TOLERANCE` (the direction is
within about 2e-4 degree of the normal, or zero), the fallback is the body axis least
aligned with the facet normal (the first of x, y, z on ties), projected onto the
facet: deterministic, and well conditioned (its projection is at least
``sqrt(2/3)`` long).  :data:`DEFAULT_TANGENT_DIRECTION` (body ``+x``) is the default
direction, so a box's ``+-x`` faces get the tangent ``y`` and its other faces ``x``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import ValidationError
from ..units import to_unit
from .angles import _forward_direction, _vectors, normal_incidence_tolerance

__all__ = [
    "DEFAULT_TANGENT_DIRECTION",
    "PSI_PERIOD",
    "TANGENT_TOLERANCE",
    "illumination_azimuth",
    "project_tangents",
    "psi_average",
    "psi_weights",
]

#: Body-frame direction projected onto facets that were given no tangent [1].
DEFAULT_TANGENT_DIRECTION: tuple[float, float, float] = (1.0, 0.0, 0.0)
#: A direction whose component in the facet plane is shorter than this (relative to
#: its length) is taken as parallel to the normal, and the fallback tangent is used [1].
TANGENT_TOLERANCE = 1.0e-6
#: Period of ``psi`` [degree]: ``t`` and ``-t`` are the same tangent.
PSI_PERIOD = 180.0


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("...k,...k->...", a, b)


def _least_aligned_axis(n: np.ndarray) -> np.ndarray:
    """The coordinate axis least aligned with each ``n`` (first of x, y, z on ties)."""
    axis = np.zeros_like(n)
    idx = np.argmin(np.abs(n), axis=-1)
    np.put_along_axis(axis, idx[..., None], 1.0, axis=-1)
    return axis


def project_tangents(normal: ArrayLike, direction: ArrayLike | None = None) -> NDArray[np.float64]:
    """Unit facet tangents: ``direction`` projected onto each facet plane.

    Parameters
    ----------
    normal : array_like, shape (..., 3)
        Unit facet normals [1].
    direction : array_like, shape (3,) or (..., 3), optional
        Tangent direction [1], one for every facet or one per facet (for example a
        mesh's per-face attribute); need not be unit length nor orthogonal to the
        normal.  Default :data:`DEFAULT_TANGENT_DIRECTION`.

    Returns
    -------
    ndarray, shape (..., 3)
        Unit tangents orthogonal to the normals [1], float64.  Where ``direction`` is
        parallel to the normal (its in-plane part shorter than
        :data:`TANGENT_TOLERANCE` times its length) or zero: the body axis least aligned
        with the normal, projected (module docstring).

    Examples
    --------
    >>> n = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
    >>> project_tangents(n).tolist()
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    >>> np.round(project_tangents(n, (1.0, 1.0, 1.0)), 4).tolist()
    [[0.7071, 0.7071, 0.0], [0.0, 0.7071, 0.7071]]
    """
    n = np.asarray(normal, dtype=np.float64)
    if n.ndim == 0 or n.shape[-1] != 3 or not np.all(np.isfinite(n)):
        raise ValidationError(f"normal: expected finite (..., 3) vectors, got shape {n.shape}")
    d = np.asarray(DEFAULT_TANGENT_DIRECTION if direction is None else direction, dtype=np.float64)
    if d.ndim == 0 or d.shape[-1] != 3 or not np.all(np.isfinite(d)):
        raise ValidationError(
            f"tangent: expected a finite direction of 3 components (or one per facet), got "
            f"{np.asarray(direction).tolist() if d.size <= 9 else f'shape {d.shape}'}"
        )
    try:
        n, d = np.broadcast_arrays(n, d)
    except ValueError:
        raise ValidationError(
            f"tangent: got shape {d.shape}; expected (3,) or one per facet, {n.shape}"
        ) from None
    t = d - _dot(d, n)[..., None] * n
    lt = np.linalg.norm(t, axis=-1)
    ld = np.linalg.norm(d, axis=-1)
    bad = lt <= TANGENT_TOLERANCE * np.maximum(ld, 1e-300)
    if np.any(bad):
        a = _least_aligned_axis(n)
        fb = a - _dot(a, n)[..., None] * n
        t = np.where(bad[..., None], fb, t)
        lt = np.linalg.norm(t, axis=-1)
    return t / lt[..., None]


def illumination_azimuth(
    normal: ArrayLike,
    tangent: ArrayLike,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    *,
    check: bool = True,
) -> NDArray[np.floating]:
    """``psi`` [degree]: azimuth of the illumination plane from the facet tangent.

    Implements the convention of the module docstring, with the forward direction
    ``e_f`` of :func:`sbrdf_xr.geometry.facet_angles` (arctan2 throughout, the same
    normal-incidence tolerance and fallbacks).

    Parameters
    ----------
    normal, tangent, to_sun, to_observer : array_like, shape (..., 3)
        Facet normal and tangent (its component along the normal is removed), unit
        vectors to the Sun and the observer [1]; broadcast together.
    check : bool, default True
        Validate and normalise ``normal``, ``to_sun`` and ``to_observer``; with
        ``check=False`` they must be unit vectors already (the tangent is always
        made orthogonal to the normal and normalised).

    Returns
    -------
    ndarray
        ``psi`` in ``[0, 180)`` degree, in the working precision of the inputs (at
        least float32).

    Examples
    --------
    >>> z, x, y = np.eye(3)[2], np.eye(3)[0], np.eye(3)[1]
    >>> s = np.array([-1.0, 0.0, 1.0])  # Sun on -x: the plane runs forward along +x
    >>> float(illumination_azimuth(z, x, s, np.array([1.0, 0.0, 1.0])))
    0.0
    >>> float(illumination_azimuth(z, y, s, np.array([1.0, 0.0, 1.0])))
    90.0
    >>> float(illumination_azimuth(z, x + y, s, np.array([1.0, 0.0, 1.0])))
    135.0
    """
    n, s, o = _vectors(normal, to_sun, to_observer, check)
    dtypes = [a.dtype for a in (n, s, o)]
    dtype = (
        np.result_type(*dtypes)
        if all(np.issubdtype(d, np.floating) for d in dtypes)
        else np.dtype(np.float64)
    )
    tg = np.asarray(tangent)
    if tg.ndim == 0 or tg.shape[-1] != 3 or not np.all(np.isfinite(tg)):
        raise ValidationError(f"tangent: expected finite (..., 3) vectors, got shape {tg.shape}")
    n, s, o, tg = np.broadcast_arrays(*(a.astype(dtype, copy=False) for a in (n, s, o, tg)))
    tol = normal_incidence_tolerance(dtype)
    t = tg - _dot(tg, n)[..., None] * n
    lt = np.linalg.norm(t, axis=-1)
    if np.any(lt <= tol):
        raise ValidationError(
            "tangent: must not be parallel to the facet normal (or zero); see "
            "sbrdf_xr.geometry.anisotropy.project_tangents"
        )
    t = t / lt[..., None]
    b = np.cross(n, t)
    e_f, _ = _forward_direction(n, s, o, _dot(n, s), _dot(n, o), tol)
    psi = np.degrees(np.arctan2(_dot(e_f, b), _dot(e_f, t)))
    op = _dot(o, np.cross(n, e_f))
    # the mirror only off the plane: an observer in it (phi = 0 up to rounding) keeps psi
    psi = np.where(op < -tol, -psi, psi)
    out = np.mod(psi, PSI_PERIOD)
    # mod of a tiny negative number rounds to the period itself
    return np.where(out >= PSI_PERIOD, 0.0, out).astype(dtype, copy=False)


def psi_weights(grid: ArrayLike, psi: ArrayLike) -> tuple[NDArray[np.intp], NDArray[np.float64]]:
    """Periodic linear interpolation weights in ``psi`` (period 180 degree).

    Parameters
    ----------
    grid : array_like, shape (n,)
        Strictly increasing ``psi`` nodes [degree] in ``[0, 180]``.  A grid spanning
        exactly 180 degree (``[0, ..., 180]``) is closed: its last node is its first
        one turned by a period, and both are read.  Otherwise the interval from the
        last node to the first node plus 180 wraps round.
    psi : array_like
        Query azimuths [degree], any real numbers (taken modulo 180).

    Returns
    -------
    idx : ndarray of int, shape psi.shape + (2,)
        Node indices.
    w : ndarray, shape psi.shape + (2,)
        Weights, non-negative, summing to one.

    Examples
    --------
    >>> idx, w = psi_weights([0.0, 60.0, 120.0], [30.0, 150.0, 180.0])
    >>> idx.tolist(), w.tolist()
    ([[0, 1], [2, 0], [0, 1]], [[0.5, 0.5], [0.5, 0.5], [1.0, 0.0]])
    """
    g = np.asarray(to_unit(grid, "deg", "grid"), dtype=np.float64)
    if g.ndim != 1 or g.size == 0 or np.any(np.diff(g) <= 0) or g[0] < 0 or g[-1] > PSI_PERIOD:
        raise ValidationError(
            f"psi: grid must be strictly increasing in [0, 180] degree, got {g.tolist()}"
        )
    x = np.asarray(to_unit(psi, "deg", "psi"), dtype=np.float64)
    shape = x.shape
    x = x.ravel()
    if g.size == 1:
        return np.zeros((*shape, 2), dtype=np.intp), np.tile([1.0, 0.0], (*shape, 1))
    closed = np.isclose(g[-1] - g[0], PSI_PERIOD, rtol=0.0, atol=1e-9)
    nodes = g if closed else np.append(g, g[0] + PSI_PERIOD)
    x = g[0] + np.mod(x - g[0], PSI_PERIOD)
    x = np.where(x >= g[0] + PSI_PERIOD, g[0], x)  # mod rounding up to the period
    i = np.clip(np.searchsorted(nodes, x, side="right") - 1, 0, nodes.size - 2)
    frac = np.clip((x - nodes[i]) / (nodes[i + 1] - nodes[i]), 0.0, 1.0)
    j = i + 1
    if not closed:
        j = np.where(j == g.size, 0, j)
    idx = np.stack([i, j], axis=-1).reshape(*shape, 2)
    w = np.stack([1.0 - frac, frac], axis=-1).reshape(*shape, 2)
    return idx.astype(np.intp), w


def psi_average(values: ArrayLike, grid: ArrayLike, axis: int = -1) -> NDArray[np.float64]:
    """Mean over a period of ``psi`` of values on ``psi`` nodes, linear between them.

    The exact mean of the periodic piecewise-linear interpolant of
    :func:`psi_weights`: trapezoidal weights over the closed or wrapped grid.

    Parameters
    ----------
    values : array_like
        Values on the nodes along ``axis``.
    grid : array_like, shape (n,)
        ``psi`` nodes [degree] (as :func:`psi_weights`).
    axis : int
        The ``psi`` axis of ``values``.

    Returns
    -------
    ndarray
        ``values`` without ``axis``.

    Examples
    --------
    >>> float(psi_average([1.0, 3.0], [0.0, 90.0]))
    2.0
    >>> float(psi_average([1.0, 3.0, 1.0], [0.0, 90.0, 180.0]))
    2.0
    """
    g = np.asarray(to_unit(grid, "deg", "grid"), dtype=np.float64)
    psi_weights(g, g[:1])  # validates the grid
    v = np.moveaxis(np.asarray(values, dtype=np.float64), axis, -1)
    if g.size == 1:
        return v[..., 0]
    closed = np.isclose(g[-1] - g[0], PSI_PERIOD, rtol=0.0, atol=1e-9)
    nodes = g if closed else np.append(g, g[0] + PSI_PERIOD)
    h = np.diff(nodes)
    w = np.zeros(nodes.size)
    w[:-1] += h / 2
    w[1:] += h / 2
    if not closed:
        w[0] += w[-1]
        w = w[:-1]
    return v @ (w / PSI_PERIOD)
