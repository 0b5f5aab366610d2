"""Facet tables of a spacecraft: one row per facet, or facets merged by (normal, material).

:meth:`sbrdf_xr.body.spacecraft.Spacecraft.facets` and
:meth:`~sbrdf_xr.body.spacecraft.Spacecraft.merged` return these tables for a spacecraft;
the functions here build them from the mesh, the facet materials and the facet
tangents.  Merging serves the unshadowed facet sum of paper 000 Eq. 3-4, whose summand
depends on a facet only through its normal, material and area.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
import trimesh
import xarray as xr
from numpy.typing import ArrayLike, NDArray

from .._names import FACET, MATERIAL, VECTOR, attrs
from ..errors import ValidationError
from ..geometry.anisotropy import project_tangents

__all__ = ["NORMAL_TOLERANCE", "check_facet_material", "facet_table", "merge_facets"]


#: Component tolerance below which two unit normals are the same in :func:`merge_facets`
#: (and :meth:`Spacecraft.merged <sbrdf_xr.body.spacecraft.Spacecraft.merged>`).
NORMAL_TOLERANCE = 1.0e-9


def check_facet_material(facet_material: Iterable[str], n_facets: int) -> NDArray[np.str_]:
    """The material names of the facets as a new array of str, one per facet.

    Parameters
    ----------
    facet_material : iterable of str
        Material name of every facet.
    n_facets : int
        Number of facets of the mesh.

    Returns
    -------
    ndarray of str, shape (n_facets,)
        A copy: changing it leaves ``facet_material`` alone.

    Raises
    ------
    ValidationError
        If there is not one name per facet.

    Examples
    --------
    >>> check_facet_material(("paint", "cell"), 2)
    array(['paint', 'cell'], dtype='<U5')
    >>> check_facet_material(["paint"], 2)
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.ValidationError: facet_material: expected 2 names (one per facet), ...
    """
    values = facet_material if isinstance(facet_material, np.ndarray) else list(facet_material)
    labels = np.array(values, dtype=str)
    if labels.shape != (n_facets,):
        raise ValidationError(
            f"facet_material: expected {n_facets} names (one per facet), got shape {labels.shape}"
        )
    return labels


def _facet_arrays(
    mesh: trimesh.Trimesh, facet_material: Iterable[str], facet_tangent: ArrayLike
) -> tuple[NDArray[np.str_], NDArray[np.float64]]:
    """The material names and tangents of the facets, checked against the mesh."""
    n = len(mesh.faces)
    labels = check_facet_material(facet_material, n)
    tangent = np.asarray(facet_tangent, dtype=np.float64)
    if tangent.shape != (n, 3):
        raise ValidationError(
            f"facet_tangent: expected one unit tangent per facet ({n}, 3), "
            f"got shape {tangent.shape}"
        )
    return labels, tangent


def facet_table(
    mesh: trimesh.Trimesh,
    facet_material: Iterable[str],
    facet_tangent: ArrayLike,
    name: str = "spacecraft",
) -> xr.Dataset:
    """Facet table: normal, area, centroid, material and tangent of every facet.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        Geometry in metres.
    facet_material : array_like of str, shape (n_facets,)
        Material name of every facet.
    facet_tangent : array_like, shape (n_facets, 3)
        Unit tangent of every facet [1]
        (:func:`sbrdf_xr.geometry.anisotropy.project_tangents`).
    name : str
        Name of the spacecraft (the ``spacecraft`` attribute).

    Returns
    -------
    xarray.Dataset
        As :meth:`sbrdf_xr.body.spacecraft.Spacecraft.facets`.

    Raises
    ------
    ValidationError
        If ``facet_material`` or ``facet_tangent`` does not have one row per facet.

    Examples
    --------
    >>> box = trimesh.creation.box()
    >>> ds = facet_table(box, ["paint"] * 12, project_tangents(box.face_normals), "cube")
    >>> dict(ds.sizes), ds.attrs["title"], round(float(ds.area.sum()), 6)
    ({'facet': 12, 'xyz': 3}, 'facets of cube', 6.0)
    """
    labels, tangent = _facet_arrays(mesh, facet_material, facet_tangent)
    ds = xr.Dataset(
        {
            "normal": (
                (FACET, VECTOR),
                np.asarray(mesh.face_normals, dtype=np.float64),
                attrs("normal"),
            ),
            "area": ((FACET,), np.asarray(mesh.area_faces, dtype=np.float64), attrs("area")),
            "centroid": (
                (FACET, VECTOR),
                np.asarray(mesh.triangles_center, dtype=np.float64),
                attrs("centroid"),
            ),
            MATERIAL: ((FACET,), labels, attrs(MATERIAL)),
            "tangent": ((FACET, VECTOR), tangent.copy(), attrs("tangent")),
        },
        coords={
            FACET: (FACET, np.arange(len(labels)), attrs(FACET)),
            VECTOR: (VECTOR, ["x", "y", "z"], attrs(VECTOR)),
        },
        attrs={"spacecraft": name, "title": f"facets of {name}"},
    )
    return ds


def merge_facets(
    mesh: trimesh.Trimesh,
    facet_material: Iterable[str],
    facet_tangent: ArrayLike,
    name: str = "spacecraft",
    tolerance: float = NORMAL_TOLERANCE,
    tangent_materials: Iterable[str] = (),
    groups: ArrayLike | None = None,
) -> xr.Dataset:
    """Collapse facets that share (normal, material) into terms with summed area.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        Geometry in metres.
    facet_material : array_like of str, shape (n_facets,)
        Material name of every facet.
    facet_tangent : array_like, shape (n_facets, 3)
        Unit tangent of every facet [1].
    name : str
        Name of the spacecraft (the ``spacecraft`` attribute).
    tolerance : float
        Grid spacing of the normal (and tangent) components [1]; see
        :meth:`sbrdf_xr.body.spacecraft.Spacecraft.merged`.
    tangent_materials : iterable of str
        Anisotropic materials, whose facets also need equal tangents to share a term.
    groups : array_like of int, shape (n_facets,), optional
        Facets of different groups (the bus and the parts that move against it) never
        share a term.

    Returns
    -------
    xarray.Dataset
        As :meth:`sbrdf_xr.body.spacecraft.Spacecraft.merged`.

    Raises
    ------
    ValidationError
        If ``tolerance`` is not a positive finite number, or ``facet_material`` or
        ``facet_tangent`` does not have one row per facet.

    Examples
    --------
    >>> box = trimesh.creation.box()
    >>> terms = merge_facets(box, ["paint"] * 12, project_tangents(box.face_normals))
    >>> terms.sizes["term"], terms.n_facets.values.tolist()  # 6 faces of 2 facets each
    (6, [2, 2, 2, 2, 2, 2])
    """
    if not (np.isfinite(tolerance) and tolerance > 0):
        raise ValidationError(f"tolerance: got {tolerance!r}; expected a positive finite number")
    labels, tang = _facet_arrays(mesh, facet_material, facet_tangent)
    normals = np.asarray(mesh.face_normals, dtype=np.float64)
    area = np.asarray(mesh.area_faces, dtype=np.float64)
    mat_names, mat_code = np.unique(labels, return_inverse=True)
    aniso = np.isin(labels, list(tangent_materials))
    # t and -t are the same tangent: the sign that makes the largest component positive
    sign = np.sign(tang[np.arange(len(tang)), np.argmax(np.abs(tang), axis=1)])
    t_key = np.where(aniso[:, None], np.round(sign[:, None] * tang / tolerance), 0)
    keys = np.column_stack(
        [
            mat_code.reshape(-1),
            np.round(normals / tolerance).astype(np.int64),
            t_key.astype(np.int64),
            np.zeros(len(labels), np.int64) if groups is None else np.asarray(groups, np.int64),
        ]
    )
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first, kind="stable")  # terms in order of first facet
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    term = rank[inverse.reshape(-1)]
    n_terms = len(order)
    t_area = np.bincount(term, weights=area, minlength=n_terms)
    t_normal = np.stack(
        [np.bincount(term, weights=area * normals[:, k], minlength=n_terms) for k in range(3)],
        axis=1,
    )
    norm = np.linalg.norm(t_normal, axis=1, keepdims=True)
    # A term of zero-area facets only (no normal) keeps a zero normal: it faces
    # nothing and contributes nothing, without 0/0.
    t_normal = np.divide(t_normal, norm, out=np.zeros_like(t_normal), where=norm > 0)
    n_facets = np.bincount(term, minlength=n_terms)
    t_material = mat_names[mat_code.reshape(-1)[np.asarray(first)[order]]]
    first_t = tang[np.asarray(first)[order]]
    t_tangent = (
        project_tangents(np.where(norm > 0, t_normal, [0.0, 0.0, 1.0]), first_t)
        if n_terms
        else np.zeros((0, 3))
    )
    return xr.Dataset(
        {
            "normal": (("term", VECTOR), t_normal, attrs("normal")),
            "area": (
                ("term",),
                t_area,
                attrs("area", long_name="summed facet area of the term"),
            ),
            MATERIAL: (("term",), t_material, attrs(MATERIAL)),
            "n_facets": (("term",), n_facets, attrs("n_facets")),
            "tangent": (("term", VECTOR), t_tangent, attrs("tangent")),
            "facet_term": ((FACET,), term, attrs("facet_term")),
        },
        coords={
            "term": ("term", np.arange(n_terms), attrs("term")),
            FACET: (FACET, np.arange(len(labels)), attrs(FACET)),
            VECTOR: (VECTOR, ["x", "y", "z"], attrs(VECTOR)),
        },
        attrs={
            "spacecraft": name,
            "normal_tolerance": tolerance,
            "title": f"merged facets of {name}",
        },
    )
