"""Self-shadowing and self-occlusion of a spacecraft by ray casting.

A facet of a non-convex spacecraft can be hidden from the Sun (self-shadowing) or from the
observer (self-occlusion) by other parts of the spacecraft.  Paper 000 Eq. 3-4 sum over all
facets that face the Sun and the observer; with these effects the area ``A_j`` of facet ``j``
becomes ``A_j * f_j`` with the fractions computed here.

Method
------
Every facet is split into ``density**2`` congruent sub-triangles (a regular barycentric
subdivision of level ``density``); a ray is cast from the centroid of each toward the
direction asked, and the fraction of the facet area whose ray escapes to infinity is the
fraction of rays that hit nothing (the midpoint rule on equal-area cells).  So ``density`` is
the accuracy-versus-cost knob: the cost grows as ``density**2`` and the error of a facet
crossed by a straight shadow edge is at most ``(3 density - 2) / density**2 < 3/density``
(the edge crosses at most ``3 (density - 1) + 1`` sub-triangles), in practice much less.
Named presets: :data:`DENSITY_PRESETS`.

* Ray origins are lifted off the facet along its normal by ``offset`` (default
  :data:`OFFSET_FACTOR` = 1e-6 times the bounding-box diagonal: well above the float32
  resolution of the embree engine, well below any real feature) so that a ray never hits its
  own facet or a coplanar neighbour.
* Facets facing away from the direction (``N.d <= 0``) get 0; facets whose plane supports the
  whole mesh (every vertex on or behind it, like every facet of a convex body) cannot be
  shadowed and get 1 without casting rays; a convex spacecraft
  (:attr:`~sbrdf_xr.spacecraft.Spacecraft.is_convex`) skips ray casting entirely.
* Engines (:data:`ENGINES`): ``"embree"`` is :mod:`trimesh.ray.ray_pyembree` (Intel Embree
  through the ``embreex`` package, float32, fast); ``"triangle"`` is trimesh's pure-numpy
  :mod:`trimesh.ray.ray_triangle` (float64, slow; only hits in front of the origin count);
  ``"auto"`` picks embree when it is installed.

All functions take directions in the body frame of the spacecraft.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import trimesh
import xarray as xr
from numpy.typing import ArrayLike, NDArray

from ._names import FACET, GEOMETRY, VECTOR, attrs
from .errors import ValidationError
from .geometry import normalize
from .spacecraft import Spacecraft

__all__ = [
    "DENSITY_PRESETS",
    "ENGINES",
    "OFFSET_FACTOR",
    "available_engines",
    "facet_visibility",
    "lit_fraction",
    "lit_visible_fraction",
    "sample_barycentric",
    "samples_per_facet",
    "visible_fraction",
]

#: Ray engines: name -> description.
ENGINES: dict[str, str] = {
    "auto": "embree if the embreex package is installed, triangle otherwise",
    "embree": "Intel Embree via trimesh.ray.ray_pyembree (embreex package; float32)",
    "triangle": "trimesh.ray.ray_triangle, pure numpy (float64; slow)",
}

#: Named sub-facet sampling densities (subdivision level; samples per facet = level**2).
DENSITY_PRESETS: dict[str, int] = {"fast": 1, "balanced": 4, "reference": 16}

#: Default ray-origin offset along the facet normal, as a fraction of the bounding-box diagonal.
OFFSET_FACTOR = 1.0e-6

#: Upper bound on the rays cast in one engine call (memory ~ 100 bytes per ray).
MAX_RAYS_PER_CALL = 1 << 20


def available_engines() -> list[str]:
    """Ray engines usable in this environment (``"triangle"`` always; ``"embree"`` if installed)."""
    out = ["triangle"]
    try:
        import trimesh.ray.ray_pyembree  # noqa: F401
    except ImportError:
        return out
    return ["embree", *out]


def _engine_name(engine: str) -> str:
    if engine not in ENGINES:
        raise ValidationError(f"engine: got {engine!r}; allowed: {', '.join(ENGINES)}")
    avail = available_engines()
    if engine == "auto":
        return avail[0]
    if engine not in avail:
        raise ValidationError(
            f"engine: {engine!r} is not available here (install the 'embreex' package, "
            f"extra [shadows]); available: {', '.join(avail)}"
        )
    return engine


def _density(density: int | str) -> int:
    if isinstance(density, str):
        if density not in DENSITY_PRESETS:
            raise ValidationError(f"density: got {density!r}; presets: {DENSITY_PRESETS}")
        return DENSITY_PRESETS[density]
    if isinstance(density, bool) or not isinstance(density, int | np.integer) or density < 1:
        raise ValidationError(
            f"density: got {density!r}; expected an integer subdivision level >= 1 "
            f"or a preset name {list(DENSITY_PRESETS)}"
        )
    return int(density)


def samples_per_facet(density: int | str) -> int:
    """Number of rays per facet and direction at a sampling density (``density**2``)."""
    return _density(density) ** 2


def sample_barycentric(density: int | str) -> NDArray[np.float64]:
    """Barycentric coordinates of the centroids of the ``density**2`` sub-triangles.

    The level-``n`` subdivision cuts a triangle by ``n - 1`` lines parallel to each side
    into ``n**2`` congruent triangles (``n (n + 1) / 2`` upright, ``n (n - 1) / 2``
    inverted); their centroids are a stratified, equal-weight quadrature of the facet.

    Parameters
    ----------
    density : int or str
        Subdivision level ``n >= 1`` or a key of :data:`DENSITY_PRESETS`.

    Returns
    -------
    ndarray, shape (n**2, 3)
        Weights of the three vertices; each row sums to 1.
    """
    n = _density(density)
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    up = i + j <= n - 1
    down = i + j <= n - 2
    u = np.concatenate([(i[up] + 1 / 3) / n, (i[down] + 2 / 3) / n])
    v = np.concatenate([(j[up] + 1 / 3) / n, (j[down] + 2 / 3) / n])
    return np.column_stack([1.0 - u - v, u, v])


def _mesh_of(spacecraft: Spacecraft | trimesh.Trimesh) -> tuple[trimesh.Trimesh, dict[str, Any]]:
    if isinstance(spacecraft, Spacecraft):
        return spacecraft.mesh, spacecraft._cache
    if isinstance(spacecraft, trimesh.Trimesh):
        return spacecraft, {}
    raise ValidationError(
        f"spacecraft: expected a Spacecraft or trimesh.Trimesh, got {type(spacecraft).__name__}"
    )


def _intersector(
    mesh: trimesh.Trimesh, cache: dict[str, Any], engine: str
) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    """A function (origins, unit directions) -> bool hit, cached per spacecraft and engine."""
    key = f"ray:{engine}"
    if key in cache:
        return cache[key]
    if engine == "embree":
        from trimesh.ray import ray_pyembree

        rmi = ray_pyembree.RayMeshIntersector(mesh)

        def hits(origins: np.ndarray, directions: np.ndarray) -> np.ndarray:
            return rmi.intersects_first(origins, directions) >= 0

    else:
        from trimesh.ray import ray_triangle

        rmi = ray_triangle.RayMeshIntersector(mesh)

        def hits(origins: np.ndarray, directions: np.ndarray) -> np.ndarray:
            # trimesh counts hits up to 1e-6 model units *behind* the origin; keep only
            # hits strictly in front of it (own-plane hits are at -offset / N.d < 0).
            _, index_ray, loc = rmi.intersects_id(
                origins, directions, multiple_hits=True, return_locations=True
            )
            ahead = np.einsum("ij,ij->i", loc - origins[index_ray], directions[index_ray]) > 0
            out = np.zeros(len(origins), dtype=bool)
            out[index_ray[ahead]] = True
            return out

    cache[key] = hits
    return hits


def _supporting(mesh: trimesh.Trimesh, cache: dict[str, Any], tol: float) -> np.ndarray:
    """Facets whose plane has the whole mesh on or behind it (cannot be shadowed)."""
    key = f"supporting:{tol!r}"
    if key not in cache:
        try:
            pts = np.asarray(mesh.convex_hull.vertices)
        except Exception:  # pragma: no cover - degenerate (flat) meshes
            pts = np.asarray(mesh.vertices)
        normals = np.asarray(mesh.face_normals)
        origin = np.asarray(mesh.triangles[:, 0])
        height = np.full(len(normals), -np.inf)
        step = max(1, (1 << 22) // max(len(pts), 1))
        for s in range(0, len(normals), step):  # chunks of facets, bounded memory
            n, o = normals[s : s + step], origin[s : s + step]
            height[s : s + step] = (pts @ n.T - np.einsum("ij,ij->i", n, o)).max(axis=0)
        cache[key] = height <= tol
    return cache[key]


def _directions(directions: ArrayLike, name: str) -> tuple[np.ndarray, tuple[int, ...]]:
    d = normalize(np.asarray(directions, dtype=np.float64), name)
    return d.reshape(-1, 3), d.shape[:-1]


def _escape_masks(
    spacecraft: Spacecraft | trimesh.Trimesh,
    directions: list[np.ndarray],
    density: int | str,
    engine: str,
    offset: float | None,
    convex_shortcut: bool,
) -> np.ndarray:
    """Per-sample escape flags, shape (len(directions), n_geometries, n_facets, n_samples)."""
    mesh, cache = _mesh_of(spacecraft)
    n = _density(density)
    engine = _engine_name(engine)
    scale = float(mesh.scale)
    if offset is None:
        offset = OFFSET_FACTOR * scale
    if not (np.isfinite(offset) and offset > 0):
        raise ValidationError(f"offset: got {offset!r}; expected a positive length [m]")
    normals = np.asarray(mesh.face_normals, dtype=np.float64)
    n_geom = len(directions[0])
    n_fac = len(normals)
    n_s = n * n
    front = [d @ normals.T > 0 for d in directions]  # (n_geom, n_facets) each
    out = np.stack([np.broadcast_to(f[:, :, None], (n_geom, n_fac, n_s)) for f in front]).copy()
    convex = spacecraft.is_convex if isinstance(spacecraft, Spacecraft) else bool(mesh.is_convex)
    if convex_shortcut and convex:
        return out
    candidates = np.flatnonzero(~_supporting(mesh, cache, 0.1 * offset))
    if len(candidates) == 0:
        return out
    hits = _intersector(mesh, cache, engine)
    bary = sample_barycentric(n)
    tri = np.asarray(mesh.triangles, dtype=np.float64)[candidates]
    points = np.einsum("sk,fkx->fsx", bary, tri) + offset * normals[candidates, None, :]
    per_geom = max(1, len(candidates) * n_s)
    chunk = max(1, MAX_RAYS_PER_CALL // per_geom)
    for k, d in enumerate(directions):
        for g0 in range(0, n_geom, chunk):  # chunks of directions, not facets
            sub = front[k][g0 : g0 + chunk][:, candidates]
            gi, fi = np.nonzero(sub)
            if len(gi) == 0:
                continue
            origins = points[fi].reshape(-1, 3)
            dirs = np.repeat(d[g0 + gi], n_s, axis=0)
            escaped = ~hits(origins, dirs).reshape(len(gi), n_s)
            out[k, g0 + gi, candidates[fi], :] = escaped
    return out


def lit_fraction(
    spacecraft: Spacecraft | trimesh.Trimesh,
    directions: ArrayLike,
    *,
    density: int | str = 4,
    engine: str = "auto",
    offset: float | None = None,
    convex_shortcut: bool = True,
) -> NDArray[np.float64]:
    """Fraction of each facet's area from which a ray toward each direction escapes.

    For the Sun direction this is the fraction not self-shadowed; for the observer
    direction the fraction not self-occluded (:func:`visible_fraction` is this function).

    Parameters
    ----------
    spacecraft : Spacecraft or trimesh.Trimesh
        A closed, outward-oriented surface [m].
    directions : array_like, shape (..., 3)
        Directions toward the Sun (or observer) in the body frame; normalised here, must be
        finite and non-zero.
    density : int or str
        Sub-facet sampling level ``n >= 1`` (``n**2`` rays per facet) or a preset of
        :data:`DENSITY_PRESETS`.
    engine : {"auto", "embree", "triangle"}
        Ray engine (see :data:`ENGINES`).
    offset : float, optional
        Lift of the ray origins along the facet normal [m]; default :data:`OFFSET_FACTOR`
        times the bounding-box diagonal.
    convex_shortcut : bool
        Skip ray casting for convex spacecraft (the result is the same; False forces rays,
        for testing).

    Returns
    -------
    ndarray, shape (..., n_facets)
        Fractions in ``[0, 1]`` [1]; 0 for facets with ``N.d <= 0``, multiples of
        ``1 / n**2``.

    Raises
    ------
    ValidationError
        On zero or non-finite directions, a density below 1, an unknown or unavailable engine.
    """
    d, shape = _directions(directions, "directions")
    masks = _escape_masks(spacecraft, [d], density, engine, offset, convex_shortcut)[0]
    return masks.mean(axis=-1).reshape(*shape, -1)


def visible_fraction(
    spacecraft: Spacecraft | trimesh.Trimesh,
    directions: ArrayLike,
    *,
    density: int | str = 4,
    engine: str = "auto",
    offset: float | None = None,
    convex_shortcut: bool = True,
) -> NDArray[np.float64]:
    """Fraction of each facet's area seen from each observer direction (not self-occluded).

    Identical to :func:`lit_fraction` with observer directions in place of Sun directions
    (occlusion toward a distant observer is shadowing by a light at the observer).
    """
    return lit_fraction(
        spacecraft,
        directions,
        density=density,
        engine=engine,
        offset=offset,
        convex_shortcut=convex_shortcut,
    )


def lit_visible_fraction(
    spacecraft: Spacecraft | trimesh.Trimesh,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    *,
    density: int | str = 4,
    engine: str = "auto",
    offset: float | None = None,
    convex_shortcut: bool = True,
) -> NDArray[np.float64]:
    """Fraction of each facet's area both lit by the Sun and seen by the observer.

    Computed sample by sample (a point must see both), so it is not the product of
    :func:`lit_fraction` and :func:`visible_fraction` when the shadow and the occluded
    region only partly overlap.

    Parameters
    ----------
    spacecraft : Spacecraft or trimesh.Trimesh
        A closed, outward-oriented surface [m].
    to_sun, to_observer : array_like, shape (..., 3)
        Directions toward the Sun and observer in the body frame, broadcast together.
    density, engine, offset, convex_shortcut
        As in :func:`lit_fraction`.

    Returns
    -------
    ndarray, shape (..., n_facets)
        Fractions in ``[0, 1]`` [1].
    """
    s, o = np.broadcast_arrays(
        np.asarray(to_sun, dtype=np.float64), np.asarray(to_observer, dtype=np.float64)
    )
    ds, shape = _directions(s, "to_sun")
    do, _ = _directions(o, "to_observer")
    masks = _escape_masks(spacecraft, [ds, do], density, engine, offset, convex_shortcut)
    return (masks[0] & masks[1]).mean(axis=-1).reshape(*shape, -1)


def facet_visibility(
    spacecraft: Spacecraft,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    *,
    density: int | str = 4,
    engine: str = "auto",
    offset: float | None = None,
) -> xr.Dataset:
    """Shadowing and occlusion fractions of every facet for a list of geometries.

    Parameters
    ----------
    spacecraft : Spacecraft
        The model.
    to_sun, to_observer : array_like, shape (n_geometry, 3) or (3,)
        Directions toward the Sun and observer in the body frame.
    density, engine, offset
        As in :func:`lit_fraction`.

    Returns
    -------
    xarray.Dataset
        Over ``(geometry, facet)``: ``lit_fraction``, ``visible_fraction`` and
        ``lit_visible_fraction`` [1]; coordinates ``to_sun`` and ``to_observer``
        ``(geometry, xyz)``; attrs ``density``, ``samples_per_facet``, ``engine``.
    """
    s, o = np.broadcast_arrays(
        np.asarray(to_sun, dtype=np.float64), np.asarray(to_observer, dtype=np.float64)
    )
    ds, _ = _directions(s, "to_sun")
    do, _ = _directions(o, "to_observer")
    masks = _escape_masks(spacecraft, [ds, do], density, engine, offset, True)
    dims = (GEOMETRY, FACET)
    return xr.Dataset(
        {
            "lit_fraction": (dims, masks[0].mean(-1), attrs("lit_fraction")),
            "visible_fraction": (dims, masks[1].mean(-1), attrs("visible_fraction")),
            "lit_visible_fraction": (
                dims,
                (masks[0] & masks[1]).mean(-1),
                attrs("lit_visible_fraction"),
            ),
        },
        coords={
            "to_sun": ((GEOMETRY, VECTOR), ds, attrs("to_sun")),
            "to_observer": ((GEOMETRY, VECTOR), do, attrs("to_observer")),
            FACET: (FACET, np.arange(spacecraft.n_facets), attrs(FACET)),
            VECTOR: (VECTOR, ["x", "y", "z"], attrs(VECTOR)),
        },
        attrs={
            "spacecraft": spacecraft.name,
            "density": _density(density),
            "samples_per_facet": samples_per_facet(density),
            "engine": _engine_name(engine),
        },
    )
