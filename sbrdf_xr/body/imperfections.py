"""Surface imperfections of CAD facets: a distribution of normal tilts (paper 000 §5).

Paper 000 §5 names "perfect" CAD facets as a limitation: real panels are slightly
warped, dented or misaligned, which spreads each glint.  Here every facet's normal is
taken as random, tilted from the CAD normal by a two-dimensional isotropic Gaussian
tilt vector ``t = (t_1, t_2)`` in the facet's tangent plane with standard deviation
``sigma`` per component (so the tilt angle ``|t|`` is Rayleigh distributed with mode
``sigma``), and the tilted normal is ``cos|t| N + sin|t| t/|t|`` (the exponential
map of the sphere).  The expected facet sum over the tilts is linear in the facet
contributions, so it is a weighted sum over tilted copies of every facet:
Gauss-Hermite quadrature with ``n`` nodes per tangent axis (``n**2`` copies),
deterministic, and exact for ``sigma = 0`` (one copy).  The facet area is kept (a
tilted facet keeps its own area); which facets shadow which is not changed.

Pure numpy.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import ValidationError, renamed_keywords
from ..units import to_unit

__all__ = ["tilt_quadrature", "tilted_normals"]


@renamed_keywords(sigma_deg="sigma")
def tilt_quadrature(sigma: float, n: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Nodes and weights of the Gaussian tilt distribution (product Gauss-Hermite rule).

    Parameters
    ----------
    sigma : float
        Standard deviation of each tangent component of the tilt [degree], >= 0; a
        Quantity is converted.
    n : int
        Nodes per tangent axis, >= 1.

    Returns
    -------
    tilts : ndarray, shape (K, 2)
        Tilt vectors [radian] (``K = n**2``, or 1 for ``sigma = 0``).
    weights : ndarray, shape (K,)
        Quadrature weights [1], summing to 1.

    Examples
    --------
    >>> t, w = tilt_quadrature(2.0, 3)
    >>> t.shape, round(float(w.sum()), 12)
    ((9, 2), 1.0)
    >>> round(float(np.degrees(np.sqrt((w * (t**2).sum(1)).sum()))), 9)  # rms tilt sqrt(2) sigma
    2.828427125
    """
    sigma = to_unit(sigma, "deg", "sigma")
    if not (np.isfinite(sigma) and sigma >= 0):
        raise ValidationError(f"sigma: expected a finite tilt >= 0 degree, got {sigma!r}")
    if isinstance(n, bool) or int(n) != n or n < 1:
        raise ValidationError(
            f"n: expected an integer >= 1 of quadrature nodes per axis, got {n!r}"
        )
    if sigma == 0 or n == 1:
        return np.zeros((1, 2)), np.ones(1)
    x, w = np.polynomial.hermite.hermgauss(int(n))
    t = np.sqrt(2.0) * np.radians(sigma) * x
    w = w / np.sqrt(np.pi)
    tx, ty = np.meshgrid(t, t, indexing="ij")
    ww = np.outer(w, w)
    return np.column_stack([tx.ravel(), ty.ravel()]), ww.ravel()


def tilted_normals(normals: ArrayLike, tilts: ArrayLike) -> NDArray[np.float64]:
    """Unit normals tilted by tangent-plane tilt vectors (exponential map).

    Parameters
    ----------
    normals : array_like, shape (F, 3)
        Unit normals [1].
    tilts : array_like, shape (K, 2) or (F, K, 2)
        Tilt vectors [radian] along a deterministic tangent basis ``(e_1, e_2)`` of
        each normal; a Quantity is converted.

    Returns
    -------
    ndarray, shape (F, K, 3)
        ``cos|t| N + sin|t| (t_1 e_1 + t_2 e_2) / |t|``.

    Examples
    --------
    Tilting the normal +z by 10 deg along the first tangent direction, and not at all:

    >>> import numpy as np
    >>> from sbrdf_xr.body.imperfections import tilted_normals
    >>> n = tilted_normals([[0.0, 0.0, 1.0]], [[0.0, 0.0], [np.radians(10.0), 0.0]])
    >>> n.shape
    (1, 2, 3)
    >>> np.round(n, 6) + 0.0
    array([[[0.      , 0.      , 1.      ],
            [0.      , 0.173648, 0.984808]]])
    >>> round(float(np.degrees(np.arccos(n[0, 1, 2]))), 6)
    10.0
    """
    n = np.asarray(normals, dtype=np.float64)
    t = np.asarray(to_unit(tilts, "rad", "tilts"), dtype=np.float64)
    if t.ndim == 2:
        t = np.broadcast_to(t, (n.shape[0], *t.shape))
    # tangent basis: cross with the axis least aligned with n
    axis = np.zeros_like(n)
    axis[np.arange(n.shape[0]), np.argmin(np.abs(n), axis=1)] = 1.0
    e1 = np.cross(n, axis)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(n, e1)
    ang = np.linalg.norm(t, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        sinc = np.where(ang > 0, np.sin(ang) / np.where(ang > 0, ang, 1.0), 1.0)
    tangent = t[..., 0:1] * e1[:, None, :] + t[..., 1:2] * e2[:, None, :]
    out = np.cos(ang)[..., None] * n[:, None, :] + sinc[..., None] * tangent
    return out / np.linalg.norm(out, axis=-1, keepdims=True)
