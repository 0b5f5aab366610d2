"""Symmetries of a body that a light curve cannot see: rotations mapping it onto itself.

The inversions' model of an unresolved body (no self-shadowing) is the sum over its
facets, merged by normal and material, of ``A cos(theta_i) cos(theta_r) f_r`` (paper 000
Eq. 3): it depends on the facets' normals, areas and materials, not on where they are.
A rotation ``F`` of the body frame that maps this set onto itself, every (normal,
material) onto one of the same material and area, leaves every magnitude unchanged: the
attitude ``R(t) F`` is indistinguishable from ``R(t)``.  For a spin ``R(t) = A R_k(phi +
w t)`` (``A`` taking the body axis ``k`` to the inertial axis ``a``):

* ``F = R_k(theta)``, a turn about the spin axis: the twin is the phase ``phi + theta``;
* ``F`` a half turn about an axis perpendicular to ``k``: ``R(t) F = A' R_k(psi - phi - w
  t)`` with ``A'`` taking ``k`` to ``-a``: the twin spins about ``-a`` the other way
  round (the same motion, the body upside down), phase ``psi - phi``.

The candidates are turns about ``k`` by ``360 / n`` degree (``n`` = 2 to 12) and half
turns about the perpendicular axes that the facet normals (and the bisectors of
neighbouring ones) give; each is accepted when the merged facets match to
``tolerance`` (the largest normal mismatch [1, a chord] and area mismatch relative to the
total area).
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numpy.typing import ArrayLike

from ...errors import InversionError

__all__ = ["SYMMETRY_TOL", "Symmetry", "body_symmetries", "flip_phase"]

#: Default tolerance of a symmetry: normals within this chord, areas within this fraction of
#: the body's total area.
SYMMETRY_TOL = 1e-6
#: Turns about the spin axis tried: 360 / n degree.
ORDERS = tuple(range(2, 13))


@dataclasses.dataclass(frozen=True)
class Symmetry:
    """A rotation of the body frame that maps the body (normals, areas, materials) onto
    itself: ``name``, ``matrix`` (3, 3), ``kind`` (``"turn"`` about the spin axis by
    ``angle`` [degree], or ``"flip"``, a half turn about ``axis`` perpendicular to it)."""

    name: str
    matrix: np.ndarray
    kind: str
    angle: float
    axis: np.ndarray


def _rotation(axis: np.ndarray, angle_deg: float) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    u = axis / np.linalg.norm(axis)
    return np.asarray(Rotation.from_rotvec(np.radians(angle_deg) * u).as_matrix())


def _maps_onto_itself(
    rot: np.ndarray, normal: np.ndarray, area: np.ndarray, material: np.ndarray, tol: float
) -> bool:
    """Every merged facet, rotated, lands on one of the same material and area."""
    from scipy.spatial import cKDTree

    total = float(area.sum())
    turned = normal @ rot.T
    for m in np.unique(material):
        on = material == m
        tree = cKDTree(normal[on])
        d, j = tree.query(turned[on])
        if np.any(d > tol) or np.any(np.abs(area[on][j] - area[on]) > tol * total):
            return False
    return True


def _merged(
    normal: np.ndarray, area: np.ndarray, material: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Facets merged by (normal to 1e-9, material): the model's terms."""
    key = np.column_stack([np.round(normal, 9), material.astype(np.float64)])
    uniq, inv = np.unique(key, axis=0, return_inverse=True)
    summed = np.bincount(inv.reshape(-1), weights=area, minlength=uniq.shape[0])
    nrm = uniq[:, :3] / np.linalg.norm(uniq[:, :3], axis=1)[:, None]
    return nrm, summed, uniq[:, 3]


def _flip_axes(normal: np.ndarray, k: np.ndarray) -> np.ndarray:
    """Candidate axes perpendicular to ``k``: the facet normals projected on its plane and
    the bisectors of neighbouring projections (unique to 1e-9 in angle, modulo 180 deg)."""
    e1 = np.cross(k, [1.0, 0.0, 0.0] if abs(k[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(k, e1)
    x, y = normal @ e1, normal @ e2
    keep = np.hypot(x, y) > 1e-9
    ang = np.unique(np.round(np.arctan2(y[keep], x[keep]) % np.pi, 9))
    if ang.size:
        mids = (ang + np.diff(np.append(ang, ang[0] + np.pi)) / 2) % np.pi
        ang = np.unique(np.concatenate([ang, mids]))
    return np.cos(ang)[:, None] * e1 + np.sin(ang)[:, None] * e2


def body_symmetries(
    normal: ArrayLike,
    area: ArrayLike,
    material: ArrayLike,
    axis_body: ArrayLike,
    tolerance: float = SYMMETRY_TOL,
) -> list[Symmetry]:
    """The rotations of the body frame that map a body's merged facets onto themselves and
    give twin states of a spin about ``axis_body``.

    Parameters
    ----------
    normal : array_like, shape (n, 3)
        Unit facet normals (merged by normal and material: a plan's terms) [1].
    area : array_like, shape (n,)
        Their areas [m2].
    material : array_like, shape (n,)
        Their material indices.
    axis_body : array_like, shape (3,)
        The body's spin axis.
    tolerance : float
        Largest normal mismatch (a chord) and area mismatch (a fraction of the total
        area) of a symmetry, in ``(0, 0.1]``.

    Returns
    -------
    list of Symmetry
        The turn about ``axis_body`` by the smallest angle that maps the body onto itself
        and its multiples (``"turn 180 deg"``), and the half turns about perpendicular
        axes (``"flip about [x, y, z]"``).

    Raises
    ------
    InversionError
        A tolerance out of range, a zero axis, mismatched shapes.

    Examples
    --------
    A 1 x 2 x 3 box, one material: half turns about z (and about x and y, the flips):

    >>> import trimesh
    >>> from sbrdf_xr.invert._spin.symmetry import body_symmetries
    >>> box = trimesh.creation.box(extents=(1.0, 2.0, 3.0))
    >>> syms = body_symmetries(box.face_normals, box.area_faces, np.zeros(12, int), [0, 0, 1])
    >>> [s.name for s in syms]
    ['turn 180 deg', 'flip about [0, 1, 0]', 'flip about [1, 0, 0]']
    """
    if not (isinstance(tolerance, (int, float)) and 0 < float(tolerance) <= 0.1):
        raise InversionError(
            f"symmetry_tolerance: {tolerance!r}; allowed a number in (0, 0.1] (a chord "
            "between normals and a fraction of the total area)"
        )
    n = np.asarray(normal, dtype=np.float64).reshape(-1, 3)
    a = np.asarray(area, dtype=np.float64).reshape(-1)
    mat = np.asarray(material).reshape(-1)
    if not (a.size == mat.size == n.shape[0]):
        raise InversionError(
            f"body_symmetries: {n.shape[0]} normals, {a.size} areas, {mat.size} materials; "
            "allowed one of each per facet"
        )
    k = np.asarray(axis_body, dtype=np.float64).reshape(3)
    if not np.linalg.norm(k) > 0:
        raise InversionError(f"axis_body: {axis_body!r}; allowed a nonzero 3-vector")
    k = k / np.linalg.norm(k)
    n, a, mat = _merged(n, a, mat)
    out: list[Symmetry] = []
    smallest = None
    for order in ORDERS:
        if _maps_onto_itself(_rotation(k, 360.0 / order), n, a, mat, tolerance):
            smallest = 360.0 / order
    if smallest is not None:
        for j in range(1, round(360.0 / smallest)):
            ang = j * smallest
            out.append(Symmetry(f"turn {ang:g} deg", _rotation(k, ang), "turn", ang, k))
    seen: list[np.ndarray] = []
    for u in _flip_axes(n, k):
        rot = _rotation(u, 180.0)
        if any(abs(float(u @ v)) > 1 - 1e-9 for v in seen):
            continue
        if _maps_onto_itself(rot, n, a, mat, tolerance):
            seen.append(u)
            lead = u[np.flatnonzero(np.abs(u) > 1e-9)[0]]
            u = u * np.sign(lead)
            label = np.round(u, 3) + 0.0
            text = ", ".join(f"{v:g}" for v in label)
            out.append(Symmetry(f"flip about [{text}]", rot, "flip", 180.0, u))
    return out


def flip_phase(sym: Symmetry, align: np.ndarray, k: np.ndarray, phase: float) -> float:
    """Phase [degree] of a flip's twin: ``psi - phase`` with ``R_k(psi) = A'^T A F``, ``A``
    the alignment of the spin (``k`` to the inertial axis), ``A'`` that of ``k`` to its
    antipode.

    Examples
    --------
    The twin's attitude ``A' R_k(phase')`` equals the spin's turned by the flip, ``A
    R_k(phase) F``:

    >>> from sbrdf_xr.invert._spin.search import align_matrices
    >>> from sbrdf_xr.invert._spin.symmetry import Symmetry, _rotation, flip_phase
    >>> k = np.array([0.0, 0.0, 1.0])
    >>> flip = Symmetry("flip", _rotation(np.array([1.0, 1.0, 0]), 180.0), "flip", 180.0, k)
    >>> a = align_matrices(k, np.array([[0.0, 0.6, 0.8]]))[0]
    >>> twin = flip_phase(flip, a, k, 30.0)
    >>> a2 = align_matrices(k, -np.array([[0.0, 0.6, 0.8]]))[0]
    >>> bool(np.allclose(a2 @ _rotation(k, twin), a @ _rotation(k, 30.0) @ flip.matrix))
    True
    """
    from .search import align_matrices

    axis = align @ k
    a2 = align_matrices(k, -axis[None, :])[0]
    m = a2.T @ align @ sym.matrix
    e = np.cross(k, [1.0, 0.0, 0.0] if abs(k[0]) < 0.9 else [0.0, 1.0, 0.0])
    e /= np.linalg.norm(e)
    me = m @ e
    psi = float(np.degrees(np.arctan2(np.cross(e, me) @ k, e @ me)))
    return (psi - phase) % 360.0
