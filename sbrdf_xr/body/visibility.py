"""Self-shadowing and self-occlusion of a spacecraft: exact polygon clipping, or sampled rays.

A facet of a non-convex spacecraft can be hidden from the Sun (self-shadowing) or from the
observer (self-occlusion) by other parts of the spacecraft.  Paper 000 Eq. 3-4 sum over all
facets that face the Sun and the observer; with these effects the area ``A_j`` of facet ``j``
becomes ``A_j * f_j`` with the fractions computed here.  Facets are one-sided: only the
front (outward) side of a facet receives light or is seen.

Methods (:data:`METHODS`)
-------------------------
``"exact"`` (default)
    Area-exact, to float rounding.  A point ``p`` of facet ``i`` (``N_i.d > 0``) is shadowed
    along the direction ``d`` iff the ray ``p + t d``, ``t > 0``, meets the surface.  On a
    closed surface the first hit enters the solid, so the occluders are the facets with
    ``N_j.d < 0``, and those with ``N_j.d > 0`` that are one-sided facets of an open
    component (light meets their backs, which block it too); each is cut to its part in
    front of the plane of ``i`` (``N_i.(x - p_i) >= 0``) and projected along ``d`` onto that
    plane, ``x - d N_i.(x - p_i) / N_i.d`` (a parallel projection: the shadow volume of a
    triangle).  The shadows of every occluder along the Sun *and* the observer directions,
    clipped to the facet (Sutherland-Hodgman; convex against convex is exact), are united
    and the fraction is ``1 - area(union) / area(facet)``.  The union area is the
    inclusion-exclusion sum over the non-empty intersections of the convex shadows (each one
    again a convex clip; an empty intersection prunes all its supersets); past 64 shadows or
    a work budget it is summed over vertical slabs bounded by every vertex and edge
    crossing (in each slab the covered length is linear in x); a facet with more than
    :data:`~sbrdf_xr.kernels.shadow.MAX_SHADOWS` shadows is united by GEOS
    (:func:`shapely.union_all`).  Candidate
    occluders come from a uniform grid over the bounding boxes in the plane perpendicular
    to ``d`` (a facet whose box does not overlap,
    or that lies wholly behind the receiver along ``d``, cannot shadow it), so the cost grows
    nearly linearly with the number of facets.  Compiled with numba.
``"sampled"``
    ``density**2`` points per facet from a scrambled Sobol' sequence (seeded, so the result
    is deterministic), given an independent random shift modulo 1 on every facet and mapped
    to the triangle by the area-preserving map ``(1 - sqrt(u), sqrt(u) (1 - v), sqrt(u) v)``
    (Shirley and Chiu 1997); a ray is cast from each toward the direction asked and the
    fraction is the share of rays that hit nothing.  The points are irregular, so they
    cannot line up with the straight (often axis-aligned) edges of CAD shadows: the error of
    a facet crossed by a shadow edge falls as ``N**-0.75`` for ``N`` samples (randomised QMC
    for a discontinuous integrand in two dimensions, Owen 1997; i.e. ``density**-1.5``),
    with no stalls at special densities.  ``return_error=True`` also gives the binomial
    standard error ``sqrt(f (1 - f) / N)`` of every fraction (a bound for independent
    samples; the QMC error is usually smaller).  Ray origins are lifted off the facet along
    its normal by ``offset`` (default :data:`~sbrdf_xr.body.rays.OFFSET_FACTOR` = 1e-6 times
    the bounding-box diagonal) so that a ray never hits its own facet or a coplanar
    neighbour.  The densities, point sets and ray engines are in :mod:`sbrdf_xr.body.rays`.

In both methods a facet facing away from a direction (``N.d <= 0``) gets 0; a facet whose
plane supports the whole mesh (every vertex on or behind it, like every facet of a convex
body; :func:`supporting`) cannot be shadowed and gets 1 without further work, and a
convex spacecraft (:attr:`~sbrdf_xr.body.spacecraft.Spacecraft.is_convex`) skips the
computation entirely.

Ray engines of the sampled method (:data:`~sbrdf_xr.body.rays.ENGINES`): ``"embree"`` is
:mod:`trimesh.ray.ray_pyembree` (Intel Embree through the ``embreex`` package, float32,
fast); ``"triangle"`` is trimesh's pure-numpy :mod:`trimesh.ray.ray_triangle` (float64, slow;
only hits in front of the origin count); ``"auto"`` (or None) picks embree when installed.

This module holds both methods beside the mesh access they share (:func:`mesh_of`,
:func:`is_convex`, :func:`supporting`), then the public functions.  All functions take
directions in the body frame of the spacecraft.

References
----------
Shirley, P. and Chiu, K. (1997), A low distortion map between disk and square, J. Graphics
Tools 2(3), 45-52 (the triangle map, their Eq. 1 and §3).
Owen, A. B. (1997), Scrambled net variance for integrals of smooth functions, Ann. Statist.
25(4), 1541-1562; Sutherland, I. E. and Hodgman, G. W. (1974), Reentrant polygon clipping,
Comm. ACM 17(1), 32-42.
"""

from __future__ import annotations

import itertools
from typing import Any, Literal, overload

import numpy as np
import trimesh
import xarray as xr
from numpy.typing import ArrayLike, NDArray

from .._names import FACET, GEOMETRY, VECTOR, attrs
from ..errors import ValidationError
from ..geometry import normalize
from ..kernels.shadow import exact_kernel, facet_shadows
from ..kernels.shadow_pairs import pairs_kernel
from ..units import to_unit
from .occluders import pair_table
from .rays import (
    MAX_RAYS_PER_CALL,
    OFFSET_FACTOR,
    SEED,
    check_density,
    engine_name,
    intersector,
    sample_uv,
    samples_per_facet,
    to_triangle,
)
from .spacecraft import Spacecraft

__all__ = [
    "METHODS",
    "PLANE_TOLERANCE",
    "escape_masks",
    "exact_frames",
    "facet_visibility",
    "is_convex",
    "lit_fraction",
    "lit_visible_fraction",
    "mesh_of",
    "supporting",
    "visible_fraction",
]

#: Shadowing methods: name -> description.
METHODS: dict[str, str] = {
    "exact": "area-exact polygon clipping of the projected occluders (numba, GEOS fallback)",
    "sampled": "density**2 scrambled Sobol' rays per facet (ray engine: see ENGINES)",
}

#: Height above a facet's plane, as a fraction of the bounding-box diagonal, below which a
#: vertex counts as on the plane (exact method; float64 rounding of coplanar facets is ~1e-16).
PLANE_TOLERANCE = 1.0e-9


def _method(method: str) -> str:
    if method not in METHODS:
        raise ValidationError(f"method: got {method!r}; allowed: {', '.join(METHODS)}")
    return method


def _directions(directions: ArrayLike, name: str) -> tuple[np.ndarray, tuple[int, ...]]:
    d = normalize(np.asarray(directions, dtype=np.float64), name)
    return d.reshape(-1, 3), d.shape[:-1]


# ------------------------------------------------------------- the mesh both methods read


def mesh_of(spacecraft: Spacecraft | trimesh.Trimesh) -> tuple[trimesh.Trimesh, dict[str, Any]]:
    """The mesh of a spacecraft (or bare mesh) and its per-spacecraft cache.

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr.body.visibility import mesh_of
    >>> from sbrdf_xr.testing import cube_spacecraft
    >>> body = cube_spacecraft()
    >>> mesh, cache = mesh_of(body)
    >>> mesh is body.mesh, cache is body._cache
    (True, True)
    >>> box = trimesh.creation.box()
    >>> mesh_of(box)[0] is box, mesh_of(box)[1]  # a bare mesh gets a fresh, empty cache
    (True, {})
    >>> mesh_of("cube.stl")
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.ValidationError: spacecraft: expected a Spacecraft or trimesh.Trimesh, got str
    """
    if isinstance(spacecraft, Spacecraft):  # every side light can reach (fronts, backs)
        return spacecraft.sides.mesh, spacecraft._cache
    if isinstance(spacecraft, trimesh.Trimesh):
        return spacecraft, {}
    raise ValidationError(
        f"spacecraft: expected a Spacecraft or trimesh.Trimesh, got {type(spacecraft).__name__}"
    )


def is_convex(spacecraft: Spacecraft | trimesh.Trimesh) -> bool:
    """Whether the surface is convex (cached on a Spacecraft).

    Examples
    --------
    >>> from sbrdf_xr.body.visibility import is_convex
    >>> from sbrdf_xr.testing import cube_spacecraft, l_shaped_spacecraft
    >>> is_convex(cube_spacecraft()), is_convex(l_shaped_spacecraft())
    (True, False)
    >>> is_convex(l_shaped_spacecraft().mesh)  # a bare mesh too
    False
    """
    if isinstance(spacecraft, Spacecraft):
        return spacecraft.is_convex
    return bool(spacecraft.is_convex)


def supporting(mesh: trimesh.Trimesh, cache: dict[str, Any], tol: float) -> np.ndarray:
    """Facets whose plane has the whole mesh on or behind it (cannot be shadowed).

    Examples
    --------
    Every facet of a box supports it; of the L-shaped body's 20 facets, the four on the
    inner faces of the corner (the floor and the wall it shades) do not:

    >>> import trimesh
    >>> from sbrdf_xr.body.visibility import supporting
    >>> from sbrdf_xr.testing import l_shaped_spacecraft
    >>> bool(supporting(trimesh.creation.box(), {}, 1e-9).all())
    True
    >>> body = l_shaped_spacecraft()
    >>> s = supporting(body.mesh, {}, 1e-9)
    >>> s.shape, int((~s).sum())
    ((20,), 4)
    """
    key = f"supporting:{tol!r}"
    if key not in cache:
        try:  # a flat (open) surface has a hull of no volume: trimesh divides by it
            with np.errstate(invalid="ignore", divide="ignore"):
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


# ----------------------------------------------------------------------------- exact method


def exact_frames(mesh: trimesh.Trimesh, cache: dict[str, Any]) -> dict[str, Any]:
    """Per-facet arrays of the exact method (cached): vertices ``V``, faces ``F``, normals
    ``N`` from the winding, an in-plane orthonormal frame (``E1`` along the first edge,
    ``E2 = N x E1``) at the first vertex ``P0``, the triangle in that frame ``T2``
    (counter-clockwise), the ``receiver`` facets that can be shadowed, the plane tolerance
    ``eps`` [m], the body's size ``scale`` [m] and the ``open_facet`` flags.

    Examples
    --------
    >>> from sbrdf_xr.body.visibility import exact_frames
    >>> from sbrdf_xr.testing import l_shaped_spacecraft
    >>> body = l_shaped_spacecraft()
    >>> frames = exact_frames(body.mesh, body._cache)
    >>> frames["T2"].shape, int(frames["receiver"].sum())  # the floor and the inner wall
    ((20, 3, 2), 4)
    """
    if "exact:frames" in cache:
        return cache["exact:frames"]
    V = np.ascontiguousarray(mesh.vertices, dtype=np.float64)
    F = np.ascontiguousarray(mesh.faces, dtype=np.int64)
    tri = V[F]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norm = np.linalg.norm(cross, axis=1)
    ok = norm > 0
    N = np.zeros_like(cross)
    N[ok] = cross[ok] / norm[ok, None]
    e1 = tri[:, 1] - tri[:, 0]
    len1 = np.linalg.norm(e1, axis=1)
    E1 = np.zeros_like(e1)
    E1[ok] = e1[ok] / len1[ok, None]
    E2 = np.cross(N, E1)
    rel = tri - tri[:, :1]
    T2 = np.stack([np.einsum("fvx,fx->fv", rel, E1), np.einsum("fvx,fx->fv", rel, E2)], axis=-1)
    tol = PLANE_TOLERANCE * float(mesh.scale)
    receiver = ok & ~supporting(mesh, cache, tol)
    frames = {
        "V": V,
        "F": F,
        "N": N,
        "P0": np.ascontiguousarray(tri[:, 0]),
        "E1": E1,
        "E2": E2,
        "T2": np.ascontiguousarray(T2),
        "receiver": receiver,
        "eps": tol,
        "scale": float(mesh.scale),
        "open_facet": _open_facets(mesh),
    }
    cache["exact:frames"] = frames
    return frames


_plane_frames = exact_frames  # the name the posed bodies use


def _open_facets(mesh: trimesh.Trimesh) -> np.ndarray:
    """Facets that block light from behind too: one-sided facets of an open component (a
    closed component is entered through a facet facing the light first, and a two-sided
    facet's back is its own facet)."""
    if mesh.is_watertight and mesh.is_winding_consistent:
        return np.zeros(len(mesh.faces), dtype=bool)
    from .sides import closed_facets

    return np.ascontiguousarray(~closed_facets(mesh))


def _geos_fraction(frames: dict[str, Any], i: int, dirs: np.ndarray) -> float:
    """Fraction of facet i left by the GEOS union of its shadows (the kernel's fallback)."""
    import shapely

    xy, start = facet_shadows(
        i,
        dirs,
        frames["V"],
        frames["F"],
        frames["N"],
        frames["P0"],
        frames["E1"],
        frames["E2"],
        frames["T2"],
        frames["open_facet"],
        frames["eps"],
    )
    tri = shapely.Polygon(frames["T2"][i])
    rings = [xy[a:b] for a, b in itertools.pairwise(start)]
    shadow = shapely.union_all([shapely.Polygon(r) for r in rings])
    return float(min(1.0, max(0.0, 1.0 - shadow.area / tri.area)))


def _front(directions: list[np.ndarray], normals: np.ndarray) -> np.ndarray:
    """Facets facing every direction (an elementwise sum: a BLAS product spins its threads
    on a loaded machine), (n_geom, n_facets)."""
    return np.logical_and.reduce([np.einsum("gx,fx->gf", d, normals) > 0 for d in directions])


def _exact(
    spacecraft: Spacecraft | trimesh.Trimesh, directions: list[np.ndarray], convex_shortcut: bool
) -> np.ndarray:
    """Exact fraction unobstructed along every direction of the list, shape (n_geom, n_facets)."""
    mesh, cache = mesh_of(spacecraft)
    normals = np.ascontiguousarray(mesh.face_normals, dtype=np.float64)
    shortcut = convex_shortcut and is_convex(spacecraft)
    if shortcut or not exact_frames(mesh, cache)["receiver"].any():  # nothing is shadowed
        return _front(directions, normals).astype(np.float64)
    frames = exact_frames(mesh, cache)
    dirs = np.ascontiguousarray(np.stack(directions, axis=1), dtype=np.float64)  # (G, K, 3)
    pairs = pair_table(frames, cache)
    if pairs is not None:  # the pairs that can shadow each other, found once per body
        occ = pairs["occluders"]
        recv, pstart, pgroup, pcount, cut, box, r2 = pairs["table"]
        frame = (frames["N"], frames["E1"], frames["E2"], frames["T2"])
        args = (recv, pstart, pgroup, pcount, cut, box, r2, occ["normal"], occ["open"], dirs)
        frac = pairs_kernel(normals, *frame, *args)
    else:  # too many pairs to tabulate: candidate occluders by a grid per direction
        frac = np.where(_front(directions, normals), _grid_fractions(frames, dirs), 0.0)
    # a facet facing a direction per the stored normals but not per its winding (or
    # vice versa) gets 0, as the sampled method does
    for g, i in np.argwhere(np.isnan(frac)) if np.isnan(frac).any() else ():
        frac[g, i] = _geos_fraction(frames, int(i), dirs[g])
    return frac


def _grid_fractions(frames: dict[str, Any], dirs: np.ndarray) -> np.ndarray:
    """The fractions by :func:`~sbrdf_xr.kernels.shadow.exact_kernel` (a grid per direction)."""
    return exact_kernel(
        frames["V"],
        frames["F"],
        frames["N"],
        frames["P0"],
        frames["E1"],
        frames["E2"],
        frames["T2"],
        frames["receiver"],
        dirs,
        frames["open_facet"],
        frames["eps"],
    )


# ----------------------------------------------------------------------------- sampled method


def escape_masks(
    spacecraft: Spacecraft | trimesh.Trimesh,
    directions: list[np.ndarray],
    density: int | str,
    engine: str | None,
    offset: float | None,
    convex_shortcut: bool,
    seed: int,
) -> np.ndarray:
    """Per-sample escape flags, shape (len(directions), n_geometries, n_facets, n_samples).

    Examples
    --------
    The wall of the L-shaped body shades half of its floor for a Sun at ``(-1, 2, 0)``;
    at density 2 (four samples per facet) half the floor's samples escape towards it:

    >>> import numpy as np
    >>> from sbrdf_xr.body.rays import SEED
    >>> from sbrdf_xr.body.visibility import escape_masks
    >>> from sbrdf_xr.testing import l_shaped_spacecraft
    >>> body = l_shaped_spacecraft()
    >>> sun = np.array([[-1.0, 2.0, 0.0]]) / np.sqrt(5.0)
    >>> m = escape_masks(body, [sun], 2, "triangle", None, True, SEED)
    >>> m.shape, m.dtype
    ((1, 1, 20, 4), dtype('bool'))
    >>> floor = np.flatnonzero(np.isclose(body.facets().centroid[:, 1], 1.0)
    ...                        & np.isclose(body.mesh.face_normals[:, 1], 1.0))
    >>> float(m[0, 0, floor].mean())
    0.5
    >>> facing_away = body.mesh.face_normals @ sun[0] <= 0
    >>> bool(m[0, 0, facing_away].any())  # facets facing away from the Sun never escape
    False
    """
    mesh, cache = mesh_of(spacecraft)
    n = check_density(density)
    engine = engine_name(engine)
    scale = float(mesh.scale)
    offset = to_unit(offset, "m", "offset")
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
    if convex_shortcut and is_convex(spacecraft):
        return out
    candidates = np.flatnonzero(~supporting(mesh, cache, 0.1 * offset))
    if len(candidates) == 0:
        return out
    hits = intersector(mesh, cache, engine)
    key = f"samples:{n_s}:{seed}"
    if key not in cache:
        cache[key] = sample_uv(n_s, n_fac, seed)
    base, shift = cache[key]
    bary = to_triangle(base[None, :, :] + shift[candidates, None, :])
    tri = np.asarray(mesh.triangles, dtype=np.float64)[candidates]
    points = np.einsum("fsk,fkx->fsx", bary, tri) + offset * normals[candidates, None, :]
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


# ----------------------------------------------------------------------------- public API


def _fractions(
    spacecraft: Spacecraft | trimesh.Trimesh,
    directions: list[np.ndarray],
    method: str,
    density: int | str,
    engine: str | None,
    offset: float | None,
    convex_shortcut: bool,
    seed: int,
    return_error: bool,
) -> tuple[np.ndarray, np.ndarray | None]:
    """Fractions unobstructed along all ``directions`` at once, (n_geom, n_facets), and the
    standard error of the sampled estimate (zeros for the exact method) if asked."""
    offset = to_unit(offset, "m", "offset")
    mesh_of(spacecraft)
    if _method(method) == "exact":
        check_density(density)
        engine_name(engine)
        if offset is not None and not (np.isfinite(offset) and offset > 0):
            raise ValidationError(f"offset: got {offset!r}; expected a positive length [m]")
        f = _exact(spacecraft, directions, convex_shortcut)
        return f, (np.zeros_like(f) if return_error else None)
    masks = escape_masks(spacecraft, directions, density, engine, offset, convex_shortcut, seed)
    f = np.logical_and.reduce(masks, axis=0).mean(axis=-1)
    err = np.sqrt(f * (1.0 - f) / masks.shape[-1]) if return_error else None
    return f, err


def lit_fraction(
    spacecraft: Spacecraft | trimesh.Trimesh,
    directions: ArrayLike,
    *,
    method: str = "exact",
    density: int | str = 4,
    engine: str | None = None,
    offset: float | None = None,
    convex_shortcut: bool = True,
    seed: int = SEED,
) -> NDArray[np.float64]:
    """Fraction of each facet's area from which the direction is unobstructed.

    For the Sun direction this is the fraction not self-shadowed; for the observer
    direction the fraction not self-occluded (:func:`visible_fraction` is this function).

    Parameters
    ----------
    spacecraft : Spacecraft or trimesh.Trimesh
        A closed, outward-oriented surface [m].
    directions : array_like, shape (..., 3)
        Directions toward the Sun (or observer) in the body frame; normalised here, must be
        finite and non-zero.
    method : {"exact", "sampled"}
        Area-exact polygon clipping or sampled rays (see :data:`METHODS`).
    density : int or str
        Sampled method: ``density**2`` rays per facet (``density >= 1``) or a preset of
        :data:`~sbrdf_xr.body.rays.DENSITY_PRESETS`; checked but unused by the exact method.
    engine : {"auto", "embree", "triangle"} or None
        Ray engine of the sampled method (see :data:`~sbrdf_xr.body.rays.ENGINES`); None
        is ``"auto"``.
    offset : float, optional
        Sampled method: lift of the ray origins along the facet normal [m] (a Quantity
        is converted); default :data:`~sbrdf_xr.body.rays.OFFSET_FACTOR` times the
        bounding-box diagonal.
    convex_shortcut : bool
        Skip the computation for convex spacecraft (the result is the same; False forces it,
        for testing).
    seed : int
        Seed of the sampled method's points.

    Returns
    -------
    ndarray, shape (..., n_facets)
        Fractions in ``[0, 1]`` [1]; 0 for facets with ``N.d <= 0``.

    Raises
    ------
    ValidationError
        On zero or non-finite directions, an unknown method, a density below 1, an unknown or
        unavailable engine.

    Examples
    --------
    >>> from sbrdf_xr.testing import l_shaped_spacecraft
    >>> body = l_shaped_spacecraft()  # the wall x = 1 (1 m tall) shades the floor y = 1
    >>> floor = np.flatnonzero(np.isclose(body.facets().centroid[:, 1], 1.0)
    ...                        & np.isclose(body.mesh.face_normals[:, 1], 1.0))
    >>> area = body.mesh.area_faces[floor]
    >>> def on_floor(f):  # area-weighted mean over the floor's two facets
    ...     return round(float((f[..., floor] * area).sum(-1) / area.sum()), 6)
    >>> body.is_convex
    False
    >>> sun = [-1.0, 2.0, 0.0]  # from -x, shadow 0.5 m long on the 1 m wide floor
    >>> f = lit_fraction(body, sun)
    >>> f.shape, on_floor(f)
    ((20,), 0.5)
    >>> abs(on_floor(lit_fraction(body, sun, method="sampled", density=8)) - 0.5) < 0.02
    True
    """
    d, shape = _directions(directions, "directions")
    f, _ = _fractions(
        spacecraft, [d], method, density, engine, offset, convex_shortcut, seed, False
    )
    return f.reshape(*shape, -1)


def visible_fraction(
    spacecraft: Spacecraft | trimesh.Trimesh,
    directions: ArrayLike,
    *,
    method: str = "exact",
    density: int | str = 4,
    engine: str | None = None,
    offset: float | None = None,
    convex_shortcut: bool = True,
    seed: int = SEED,
) -> NDArray[np.float64]:
    """Fraction of each facet's area seen from each observer direction (not self-occluded).

    Identical to :func:`lit_fraction` with observer directions in place of Sun directions
    (occlusion toward a distant observer is shadowing by a light at the observer).

    Examples
    --------
    >>> from sbrdf_xr.testing import l_shaped_spacecraft
    >>> body = l_shaped_spacecraft()  # the wall x = 1 (1 m tall) shades the floor y = 1
    >>> floor = np.flatnonzero(np.isclose(body.facets().centroid[:, 1], 1.0)
    ...                        & np.isclose(body.mesh.face_normals[:, 1], 1.0))
    >>> area = body.mesh.area_faces[floor]
    >>> def on_floor(f):  # area-weighted mean over the floor's two facets
    ...     return round(float((f[..., floor] * area).sum(-1) / area.sum()), 6)
    >>> on_floor(visible_fraction(body, [-1.0, 3.0, 0.0]))  # the wall hides 1/3 m of the floor
    0.666667
    """
    return lit_fraction(
        spacecraft,
        directions,
        method=method,
        density=density,
        engine=engine,
        offset=offset,
        convex_shortcut=convex_shortcut,
        seed=seed,
    )


@overload
def lit_visible_fraction(
    spacecraft: Spacecraft | trimesh.Trimesh,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    *,
    method: str = ...,
    density: int | str = ...,
    engine: str | None = ...,
    offset: float | None = ...,
    convex_shortcut: bool = ...,
    seed: int = ...,
    return_error: Literal[False] = ...,
) -> NDArray[np.float64]: ...


@overload
def lit_visible_fraction(
    spacecraft: Spacecraft | trimesh.Trimesh,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    *,
    method: str = ...,
    density: int | str = ...,
    engine: str | None = ...,
    offset: float | None = ...,
    convex_shortcut: bool = ...,
    seed: int = ...,
    return_error: Literal[True],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]: ...


def lit_visible_fraction(
    spacecraft: Spacecraft | trimesh.Trimesh,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    *,
    method: str = "exact",
    density: int | str = 4,
    engine: str | None = None,
    offset: float | None = None,
    convex_shortcut: bool = True,
    seed: int = SEED,
    return_error: bool = False,
) -> NDArray[np.float64] | tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Fraction of each facet's area both lit by the Sun and seen by the observer.

    Exact method: one minus the area of the union of the Sun shadow and the occluded region
    over the facet area.  Sampled method: the share of sample points that see both.  Either
    way it is not the product of :func:`lit_fraction` and :func:`visible_fraction` when the
    shadow and the occluded region only partly overlap.

    Parameters
    ----------
    spacecraft : Spacecraft or trimesh.Trimesh
        A closed, outward-oriented surface [m].
    to_sun, to_observer : array_like, shape (..., 3)
        Directions toward the Sun and observer in the body frame, broadcast together.
    method, density, engine, offset, convex_shortcut, seed
        As in :func:`lit_fraction`.
    return_error : bool
        Also return the standard error of every fraction: the binomial
        ``sqrt(f (1 - f) / density**2)`` of the sampled method, zeros for the exact method.
        The standard error of a signal ``sum_j w_j f_j`` is then about
        ``sqrt(sum_j (w_j err_j)**2)`` (facets have independent point sets).

    Returns
    -------
    ndarray, shape (..., n_facets)
        Fractions in ``[0, 1]`` [1]; 0 where ``N.s <= 0`` or ``N.o <= 0``.  With
        ``return_error``, a pair (fraction, standard error) of that shape.

    Examples
    --------
    >>> from sbrdf_xr.testing import l_shaped_spacecraft
    >>> body = l_shaped_spacecraft()  # the wall x = 1 (1 m tall) shades the floor y = 1
    >>> floor = np.flatnonzero(np.isclose(body.facets().centroid[:, 1], 1.0)
    ...                        & np.isclose(body.mesh.face_normals[:, 1], 1.0))
    >>> area = body.mesh.area_faces[floor]
    >>> def on_floor(f):  # area-weighted mean over the floor's two facets
    ...     return round(float((f[..., floor] * area).sum(-1) / area.sum()), 6)
    >>> sun, observer = [-1.0, 2.0, 0.0], [-1.0, 3.0, 0.0]
    >>> on_floor(lit_visible_fraction(body, sun, observer))  # not 0.5 * 2/3: hidden is shadowed
    0.5
    """
    s, o = np.broadcast_arrays(
        np.asarray(to_sun, dtype=np.float64), np.asarray(to_observer, dtype=np.float64)
    )
    ds, shape = _directions(s, "to_sun")
    do, _ = _directions(o, "to_observer")
    f, err = _fractions(
        spacecraft, [ds, do], method, density, engine, offset, convex_shortcut, seed, return_error
    )
    if return_error and err is not None:
        return f.reshape(*shape, -1), err.reshape(*shape, -1)
    return f.reshape(*shape, -1)


def facet_visibility(
    spacecraft: Spacecraft,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    *,
    method: str = "exact",
    density: int | str = 4,
    engine: str | None = None,
    offset: float | None = None,
    seed: int = SEED,
) -> xr.Dataset:
    """Shadowing and occlusion fractions of every facet for a list of geometries.

    Parameters
    ----------
    spacecraft : Spacecraft
        The model.
    to_sun, to_observer : array_like, shape (n_geometry, 3) or (3,)
        Directions toward the Sun and observer in the body frame.
    method, density, engine, offset, seed
        As in :func:`lit_fraction`.

    Returns
    -------
    xarray.Dataset
        Over ``(geometry, facet)``: ``lit_fraction``, ``visible_fraction`` and
        ``lit_visible_fraction`` [1]; coordinates ``to_sun`` and ``to_observer``
        ``(geometry, xyz)``; attrs ``method`` and, for the sampled method, ``density``,
        ``samples_per_facet``, ``engine``.

    Examples
    --------
    >>> from sbrdf_xr.testing import l_shaped_spacecraft
    >>> body = l_shaped_spacecraft()  # the wall x = 1 (1 m tall) shades the floor y = 1
    >>> floor = np.flatnonzero(np.isclose(body.facets().centroid[:, 1], 1.0)
    ...                        & np.isclose(body.mesh.face_normals[:, 1], 1.0))
    >>> area = body.mesh.area_faces[floor]
    >>> def on_floor(f):  # area-weighted mean over the floor's two facets
    ...     return round(float((f[..., floor] * area).sum(-1) / area.sum()), 6)
    >>> ds = facet_visibility(body, [[-1.0, 2.0, 0.0]], [[-1.0, 3.0, 0.0]])
    >>> dict(ds.sizes), ds.attrs["method"]
    ({'geometry': 1, 'facet': 20, 'xyz': 3}, 'exact')
    >>> on_floor(ds.lit_fraction.values[0]), on_floor(ds.visible_fraction.values[0])
    (0.5, 0.666667)
    """
    s, o = np.broadcast_arrays(
        np.asarray(to_sun, dtype=np.float64), np.asarray(to_observer, dtype=np.float64)
    )
    ds, _ = _directions(s, "to_sun")
    do, _ = _directions(o, "to_observer")
    args = (method, density, engine, offset, True, seed, False)
    if _method(method) == "exact":
        lit = _fractions(spacecraft, [ds], *args)[0]
        vis = _fractions(spacecraft, [do], *args)[0]
        joint = _fractions(spacecraft, [ds, do], *args)[0]
        extra: dict[str, Any] = {}
    else:
        masks = escape_masks(spacecraft, [ds, do], density, engine, offset, True, seed)
        lit, vis, joint = masks[0].mean(-1), masks[1].mean(-1), (masks[0] & masks[1]).mean(-1)
        extra = {
            "density": check_density(density),
            "samples_per_facet": samples_per_facet(density),
            "engine": engine_name(engine),
            "seed": seed,
        }
    dims = (GEOMETRY, FACET)
    return xr.Dataset(
        {
            "lit_fraction": (dims, lit, attrs("lit_fraction")),
            "visible_fraction": (dims, vis, attrs("visible_fraction")),
            "lit_visible_fraction": (dims, joint, attrs("lit_visible_fraction")),
        },
        coords={
            "to_sun": ((GEOMETRY, VECTOR), ds, attrs("to_sun")),
            "to_observer": ((GEOMETRY, VECTOR), do, attrs("to_observer")),
            FACET: (FACET, np.arange(spacecraft.n_sides), attrs(FACET)),
            VECTOR: (VECTOR, ["x", "y", "z"], attrs(VECTOR)),
        },
        attrs={"spacecraft": spacecraft.name, "method": method, **extra},
    )
