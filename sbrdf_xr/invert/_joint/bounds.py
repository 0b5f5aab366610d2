"""Physical bounds and identifiability of the parameters of a least-squares fit.

Area fractions lie in ``[0, 1]`` and add up to 1; area scales are ``>= 0``.  A fit whose
unconstrained minimum lies outside these bounds is refined again on a transform that
keeps them (the stick-breaking map of the fractions, Betancourt 2012, "Cruising the
simplex", AIP Conf. Proc. 1443, 157; a lower bound for the scales), by
:func:`scipy.optimize.least_squares` with box bounds (method ``"trf"``).  Inside the
bounds the transform changes nothing: the minimum and its first-order covariance are
those of the fractions (the covariance of a reparametrisation is ``G C G^T``, ``G`` the
map's Jacobian, Press et al., *Numerical Recipes*, 3rd ed., §15.6).

A parameter the data do not constrain (a column of the Jacobian that vanishes, or a
direction of its null space: a material never lit and seen, extinction and zero point
over a constant air mass) is found from the singular values of the column-equilibrated
Jacobian and reported as such, with an infinite variance, instead of the meaningless
value of an inverse of a singular matrix.
"""

from __future__ import annotations

import numpy as np

__all__ = ["NULL_TOL", "covariance", "fractions_of", "stick_breaking", "stick_breaking_inverse"]

#: Singular values of the column-equilibrated Jacobian below this fraction of the largest
#: span directions the data do not constrain.
NULL_TOL = 1e-8


def stick_breaking(u: np.ndarray) -> np.ndarray:
    """Fractions ``f`` (n + 1, adding up to 1, each in ``[0, 1]``) from ``u`` in ``[0, 1]^n``:
    ``f_i = u_i prod_{j<i} (1 - u_j)``, the last ``prod_j (1 - u_j)`` (Betancourt 2012).

    Examples
    --------
    >>> from sbrdf_xr.invert._joint.bounds import stick_breaking
    >>> stick_breaking(np.array([0.5, 0.5])).tolist()
    [0.5, 0.25, 0.25]
    """
    u = np.asarray(u, dtype=np.float64)
    rest = np.concatenate([[1.0], np.cumprod(1.0 - u)])
    return np.append(u * rest[:-1], rest[-1])


def stick_breaking_inverse(f: np.ndarray) -> np.ndarray:
    """``u`` (n) of the first n fractions ``f`` (their sum at most 1), clipped to ``[0, 1]``:
    ``u_i = f_i / (1 - sum_{j<i} f_j)`` (0 where nothing is left).

    Examples
    --------
    >>> from sbrdf_xr.invert._joint.bounds import stick_breaking_inverse
    >>> stick_breaking_inverse(np.array([0.5, 0.25])).tolist()
    [0.5, 0.5]
    """
    f = np.clip(np.asarray(f, dtype=np.float64), 0.0, 1.0)
    left = 1.0 - np.concatenate([[0.0], np.cumsum(f)[:-1]])
    with np.errstate(invalid="ignore", divide="ignore"):
        u = np.where(left > 0, f / np.where(left > 0, left, 1.0), 0.0)
    return np.asarray(np.clip(u, 0.0, 1.0))


def fractions_of(f_free: np.ndarray) -> np.ndarray:
    """Every fraction from all but the last (the last ``1 - sum``).

    Examples
    --------
    >>> from sbrdf_xr.invert._joint.bounds import fractions_of
    >>> fractions_of(np.array([0.25, 0.5])).tolist()
    [0.25, 0.5, 0.25]
    """
    f = np.asarray(f_free, dtype=np.float64)
    return np.append(f, 1.0 - f.sum())


def covariance(jac: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Covariance ``(J^T J)^-1`` of the parameters of normalised residuals, and which of them
    the data do not constrain.

    The columns of ``J`` are equilibrated (divided by their norms) and decomposed,
    ``J D^-1 = U S V^T``; singular values at most :data:`NULL_TOL` of the largest span the
    null space, and every parameter with a component above 1e-3 on it is not constrained:
    variance ``inf``, covariances 0.  The rest is ``D^-1 V S^-2 V^T D^-1`` over the
    constrained directions.

    Parameters
    ----------
    jac : ndarray, shape (n, p)
        Jacobian of the normalised residuals [1 per unit of each parameter].

    Returns
    -------
    cov : ndarray, shape (p, p)
    free : ndarray of bool, shape (p,)
        The parameters not constrained.

    Examples
    --------
    Two parameters of which the data see only the sum, and a third (its variance that of
    ``J^T J`` with the two replaced by their sum, ``[[6, 1], [1, 1]]^-1``, 6/5):

    >>> from sbrdf_xr.invert._joint.bounds import covariance
    >>> j = np.array([[1.0, 1.0, 0.0], [1.0, 1.0, 1.0], [2.0, 2.0, 0.0]])
    >>> cov, free = covariance(j)
    >>> free.tolist(), round(float(cov[2, 2]), 12)
    ([True, True, False], 1.2)
    """
    jac = np.asarray(jac, dtype=np.float64)
    p = jac.shape[1]
    norm = np.sqrt((jac**2).sum(axis=0))
    seen = norm > NULL_TOL * max(float(norm.max(initial=0.0)), 1e-300)
    free = ~seen
    cov = np.zeros((p, p))
    if seen.any():
        js = jac[:, seen] / norm[seen]
        _, sv, vt = np.linalg.svd(js, full_matrices=False)
        keep = sv > NULL_TOL * sv.max()
        null = vt[~keep]
        idx = np.flatnonzero(seen)
        if null.size:
            free[idx[np.any(np.abs(null) > 1e-3, axis=0)]] = True
        v = vt[keep]
        c = (v.T / sv[keep] ** 2) @ v / np.outer(norm[seen], norm[seen])
        cov[np.ix_(idx, idx)] = c
    cov[free, :] = 0.0
    cov[:, free] = 0.0
    cov[free, free] = np.inf
    return cov, free
