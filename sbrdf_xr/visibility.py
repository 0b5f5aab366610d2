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
    ``N_j.d < 0`` (on an open surface: every facet not edge-on); each is cut to its part in
    front of the plane of ``i`` (``N_i.(x - p_i) >= 0``) and projected along ``d`` onto that
    plane, ``x - d N_i.(x - p_i) / N_i.d`` (a parallel projection: the shadow volume of a
    triangle).  The shadows of every occluder along the Sun *and* the observer directions,
    clipped to the facet (Sutherland-Hodgman; convex against convex is exact), are united
    and the fraction is ``1 - area(union) / area(facet)``.  The union area is the
    inclusion-exclusion sum over the non-empty intersections of the convex shadows (each one
    again a convex clip; an empty intersection prunes all its supersets); past 64 shadows or
    a work budget it is summed over vertical slabs bounded by every vertex and edge
    crossing (in each slab the covered length is linear in x); a facet with more than
    :data:`MAX_SHADOWS` shadows is united by GEOS (:func:`shapely.union_all`).  Candidate occluders come from a uniform grid over the
    bounding boxes in the plane perpendicular to ``d`` (a facet whose box does not overlap,
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
    its normal by ``offset`` (default :data:`OFFSET_FACTOR` = 1e-6 times the bounding-box
    diagonal) so that a ray never hits its own facet or a coplanar neighbour.

In both methods a facet facing away from a direction (``N.d <= 0``) gets 0; a facet whose
plane supports the whole mesh (every vertex on or behind it, like every facet of a convex
body) cannot be shadowed and gets 1 without further work, and a convex spacecraft
(:attr:`~sbrdf_xr.spacecraft.Spacecraft.is_convex`) skips the computation entirely.

Ray engines of the sampled method (:data:`ENGINES`): ``"embree"`` is
:mod:`trimesh.ray.ray_pyembree` (Intel Embree through the ``embreex`` package, float32,
fast); ``"triangle"`` is trimesh's pure-numpy :mod:`trimesh.ray.ray_triangle` (float64, slow;
only hits in front of the origin count); ``"auto"`` (or None) picks embree when installed.

All functions take directions in the body frame of the spacecraft.

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
from collections.abc import Callable
from typing import Any

import numba as nb
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
    "MAX_SHADOWS",
    "METHODS",
    "OFFSET_FACTOR",
    "available_engines",
    "facet_visibility",
    "lit_fraction",
    "lit_visible_fraction",
    "sample_triangle",
    "samples_per_facet",
    "visible_fraction",
]

#: Shadowing methods: name -> description.
METHODS: dict[str, str] = {
    "exact": "area-exact polygon clipping of the projected occluders (numba, GEOS fallback)",
    "sampled": "density**2 scrambled Sobol' rays per facet (ray engine: see ENGINES)",
}

#: Ray engines of the sampled method: name -> description.
ENGINES: dict[str, str] = {
    "auto": "embree if the embreex package is installed, triangle otherwise",
    "embree": "Intel Embree via trimesh.ray.ray_pyembree (embreex package; float32)",
    "triangle": "trimesh.ray.ray_triangle, pure numpy (float64; slow)",
}

#: Named sampling densities of the sampled method (samples per facet = density**2).
DENSITY_PRESETS: dict[str, int] = {"fast": 1, "balanced": 4, "reference": 16}

#: Default ray-origin offset along the facet normal, as a fraction of the bounding-box diagonal.
OFFSET_FACTOR = 1.0e-6

#: Height above a facet's plane, as a fraction of the bounding-box diagonal, below which a
#: vertex counts as on the plane (exact method; float64 rounding of coplanar facets is ~1e-16).
PLANE_TOLERANCE = 1.0e-9

#: Upper bound on the rays cast in one engine call (memory ~ 100 bytes per ray).
MAX_RAYS_PER_CALL = 1 << 20

#: Seed of the sampled method's point sets.
SEED = 20240601


def available_engines() -> list[str]:
    """Ray engines usable in this environment (``"triangle"`` always; ``"embree"`` if installed)."""
    out = ["triangle"]
    try:
        import trimesh.ray.ray_pyembree  # noqa: F401
    except ImportError:
        return out
    return ["embree", *out]


def _method(method: str) -> str:
    if method not in METHODS:
        raise ValidationError(f"method: got {method!r}; allowed: {', '.join(METHODS)}")
    return method


def _engine_name(engine: str | None) -> str:
    if engine is None:
        engine = "auto"
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
            f"density: got {density!r}; expected an integer sampling density >= 1 "
            f"or a preset name {list(DENSITY_PRESETS)}"
        )
    return int(density)


def samples_per_facet(density: int | str) -> int:
    """Number of rays per facet and direction at a sampling density (``density**2``)."""
    return _density(density) ** 2


def sample_triangle(n_samples: int, n_facets: int = 1, seed: int = SEED) -> NDArray[np.float64]:
    """Low-discrepancy barycentric sample points, an independent set for every facet.

    A scrambled Sobol' sequence (:class:`scipy.stats.qmc.Sobol`, its first ``n_samples``
    points) is shifted modulo 1 by a random vector per facet (Cranley-Patterson rotation)
    and mapped to the triangle by ``(u, v) -> (1 - sqrt(u), sqrt(u) (1 - v), sqrt(u) v)``,
    which preserves area (Shirley and Chiu 1997), so each point stands for an equal share of
    the facet.  Deterministic for a given ``seed``.

    Parameters
    ----------
    n_samples : int
        Points per facet (>= 1).
    n_facets : int
        Number of independent point sets.
    seed : int
        Seed of the scrambling and of the shifts.

    Returns
    -------
    ndarray, shape (n_facets, n_samples, 3)
        Weights of the three vertices; each row sums to 1 and is positive or zero.
    """
    if isinstance(n_samples, bool) or int(n_samples) != n_samples or n_samples < 1 or n_facets < 0:
        raise ValidationError(
            f"n_samples, n_facets: got {n_samples!r}, {n_facets!r}; expected integers >= 1 and >= 0"
        )
    base, shift = _sample_uv(int(n_samples), int(n_facets), seed)
    return _to_triangle(base[None, :, :] + shift[:, None, :])


def _sample_uv(n_samples: int, n_facets: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """The scrambled Sobol' points (n_samples, 2) and the per-facet shifts (n_facets, 2)."""
    from scipy.stats import qmc

    rng = np.random.default_rng(seed)
    m = max(0, int(np.ceil(np.log2(n_samples))))
    base = qmc.Sobol(d=2, scramble=True, seed=rng).random_base2(m)[:n_samples]
    return base, rng.random((n_facets, 2))


def _to_triangle(uv: np.ndarray) -> np.ndarray:
    """Barycentric weights of unit-square points (shifted modulo 1), area-preserving map."""
    uv = uv % 1.0
    r = np.sqrt(uv[..., 0])
    return np.stack([1.0 - r, r * (1.0 - uv[..., 1]), r * uv[..., 1]], axis=-1)


def _mesh_of(spacecraft: Spacecraft | trimesh.Trimesh) -> tuple[trimesh.Trimesh, dict[str, Any]]:
    if isinstance(spacecraft, Spacecraft):
        return spacecraft.mesh, spacecraft._cache
    if isinstance(spacecraft, trimesh.Trimesh):
        return spacecraft, {}
    raise ValidationError(
        f"spacecraft: expected a Spacecraft or trimesh.Trimesh, got {type(spacecraft).__name__}"
    )


def _is_convex(spacecraft: Spacecraft | trimesh.Trimesh) -> bool:
    if isinstance(spacecraft, Spacecraft):
        return spacecraft.is_convex
    return bool(spacecraft.is_convex)


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
            out = np.zeros(len(origins), dtype=bool)
            _, index_ray, loc = rmi.intersects_id(
                origins, directions, multiple_hits=True, return_locations=True
            )
            index_ray = np.asarray(index_ray, dtype=np.int64)
            if len(index_ray) == 0:  # no ray hit anything (locations come back as shape (0,))
                return out
            loc = np.asarray(loc, dtype=np.float64).reshape(-1, 3)
            ahead = np.einsum("ij,ij->i", loc - origins[index_ray], directions[index_ray]) > 0
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


# ----------------------------------------------------------------------------- sampled method


def _escape_masks(
    spacecraft: Spacecraft | trimesh.Trimesh,
    directions: list[np.ndarray],
    density: int | str,
    engine: str | None,
    offset: float | None,
    convex_shortcut: bool,
    seed: int,
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
    if convex_shortcut and _is_convex(spacecraft):
        return out
    candidates = np.flatnonzero(~_supporting(mesh, cache, 0.1 * offset))
    if len(candidates) == 0:
        return out
    hits = _intersector(mesh, cache, engine)
    key = f"samples:{n_s}:{seed}"
    if key not in cache:
        cache[key] = _sample_uv(n_s, n_fac, seed)
    base, shift = cache[key]
    bary = _to_triangle(base[None, :, :] + shift[candidates, None, :])
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


# ----------------------------------------------------------------------------- exact kernels
# Plain-array numba kernels (nogil, cached).  Polygons are (x, y) float arrays plus a count.

_MAXV = 96  #: vertex capacity of one clipped polygon
#: Shadow polygons per facet united by inclusion-exclusion (more, or past the work budget:
#: vertical slabs).
_MAXM = 64
#: Shadow polygons per facet held by the compiled kernel; a facet with more goes to GEOS.
MAX_SHADOWS = 1024
_BUDGET = 20000  #: polygon intersections per facet before falling back to the GEOS union


@nb.njit(cache=True, nogil=True)
def _signed_area(px, py, n):
    s = 0.0
    for k in range(n):
        k1 = k + 1 if k + 1 < n else 0
        s += px[k] * py[k1] - px[k1] * py[k]
    return 0.5 * s


@nb.njit(cache=True, nogil=True)
def _clip(sx, sy, ns, cx, cy, nc, ox, oy, tx, ty):
    """Sutherland-Hodgman: subject polygon (sx, sy, ns) clipped by the convex counter-clockwise
    polygon (cx, cy, nc), written to (ox, oy); (tx, ty) is scratch.  Returns the vertex count
    (-1 if the capacity would be exceeded).  Exact for convex subjects (the intersection of two
    convex sets is the clipped polygon)."""
    n = ns
    for k in range(n):
        ox[k] = sx[k]
        oy[k] = sy[k]
    for e in range(nc):
        if n == 0:
            return 0
        ax = cx[e]
        ay = cy[e]
        e1 = e + 1 if e + 1 < nc else 0
        bx = cx[e1] - ax
        by = cy[e1] - ay
        for k in range(n):
            tx[k] = ox[k]
            ty[k] = oy[k]
        m = 0
        px = tx[n - 1]
        py = ty[n - 1]
        dp = bx * (py - ay) - by * (px - ax)
        for k in range(n):
            qx = tx[k]
            qy = ty[k]
            dq = bx * (qy - ay) - by * (qx - ax)
            if m + 2 >= ox.shape[0]:
                return -1
            if dq >= 0.0:
                if dp < 0.0:
                    t = dp / (dp - dq)
                    ox[m] = px + t * (qx - px)
                    oy[m] = py + t * (qy - py)
                    m += 1
                ox[m] = qx
                oy[m] = qy
                m += 1
            elif dp > 0.0:
                t = dp / (dp - dq)
                ox[m] = px + t * (qx - px)
                oy[m] = py + t * (qy - py)
                m += 1
            px = qx
            py = qy
            dp = dq
        n = m
    return n



@nb.njit(cache=True, nogil=True)
def _hull(px, py, n, ox, oy, idx):
    """Convex hull (Andrew's monotone chain, counter-clockwise, collinear points dropped) of n
    points, written to (ox, oy); idx is integer scratch.  Returns the vertex count.  Clipped
    polygons are convex only up to rounding; their hull is exactly convex, so every edge line
    of it supports it, and near-duplicate vertices cannot leave a stray edge direction."""
    for k in range(n):
        idx[k] = k
    for k in range(1, n):  # insertion sort by (x, y)
        v = idx[k]
        q = k - 1
        while q >= 0 and (px[idx[q]] > px[v] or (px[idx[q]] == px[v] and py[idx[q]] > py[v])):
            idx[q + 1] = idx[q]
            q -= 1
        idx[q + 1] = v
    m = 0
    for k in range(n):  # lower chain
        v = idx[k]
        while m >= 2 and ((ox[m - 1] - ox[m - 2]) * (py[v] - oy[m - 2])
                          - (oy[m - 1] - oy[m - 2]) * (px[v] - ox[m - 2])) <= 0.0:
            m -= 1
        ox[m] = px[v]
        oy[m] = py[v]
        m += 1
    low = m + 1
    for k in range(n - 2, -1, -1):  # upper chain
        v = idx[k]
        while m >= low and ((ox[m - 1] - ox[m - 2]) * (py[v] - oy[m - 2])
                            - (oy[m - 1] - oy[m - 2]) * (px[v] - ox[m - 2])) <= 0.0:
            m -= 1
        ox[m] = px[v]
        oy[m] = py[v]
        m += 1
    return m - 1 if m > 1 else m


@nb.njit(cache=True, nogil=True)
def _bounds(px, py, n, out):
    out[0] = out[2] = np.inf
    out[1] = out[3] = -np.inf
    for k in range(n):
        out[0] = min(out[0], px[k])
        out[1] = max(out[1], px[k])
        out[2] = min(out[2], py[k])
        out[3] = max(out[3], py[k])


@nb.njit(cache=True, nogil=True)
def _union_area(gx, gy, gn, m, tiny, stack_x, stack_y, stack_n, nxt, tx, ty):
    """Area of the union of m convex counter-clockwise polygons (gx[k], gy[k], gn[k]) by
    inclusion-exclusion over the non-empty intersections, depth first (an empty intersection
    prunes every superset; bounding boxes that do not overlap skip the clip).  Returns
    (area, ok); ok is False past the work budget."""
    box = np.empty((m, 4))
    sbox = np.empty((m + 1, 4))
    for k in range(m):
        _bounds(gx[k], gy[k], gn[k], box[k])
    total = 0.0
    ops = 0
    for a in range(m):
        n0 = gn[a]
        for k in range(n0):
            stack_x[0, k] = gx[a, k]
            stack_y[0, k] = gy[a, k]
        stack_n[0] = n0
        sbox[0] = box[a]
        total += _signed_area(gx[a], gy[a], n0)
        nxt[0] = a + 1
        d = 0
        while d >= 0:
            if nxt[d] >= m:
                d -= 1
                continue
            b = nxt[d]
            nxt[d] += 1
            if (box[b, 0] >= sbox[d, 1] or box[b, 1] <= sbox[d, 0]
                    or box[b, 2] >= sbox[d, 3] or box[b, 3] <= sbox[d, 2]):
                continue
            ops += 1
            if ops > _BUDGET:
                return 0.0, False
            nq = _clip(stack_x[d], stack_y[d], stack_n[d], gx[b], gy[b], gn[b],
                       stack_x[d + 1], stack_y[d + 1], tx, ty)
            if nq < 0:
                return 0.0, False
            if nq < 3:
                continue
            area = _signed_area(stack_x[d + 1], stack_y[d + 1], nq)
            if area <= tiny:
                continue
            total += area if (d % 2 == 1) else -area  # subset size d + 2
            stack_n[d + 1] = nq
            _bounds(stack_x[d + 1], stack_y[d + 1], nq, sbox[d + 1])
            nxt[d + 1] = b + 1
            d += 1
    return total, True


@nb.njit(cache=True, nogil=True)
def _union_area_slabs(gx, gy, gn, m):
    """Area of the union of m convex polygons by vertical slabs.

    The slab boundaries are every vertex abscissa and every abscissa where edges of two
    polygons cross; inside a slab each polygon covers a y-interval whose ends move linearly
    with x and never cross another end, so the length of the union of the intervals is
    linear in x and its value at the slab's middle times the slab's width is the slab's
    area, exactly.  O(E**2) for E edges in all: used past the inclusion-exclusion budget.
    """
    nv = 0
    for k in range(m):
        nv += gn[k]
    ne = 0
    xs = np.empty(0)
    n_cross = 0
    for sweep in range(2):  # count the crossings, then store them
        if sweep == 1:
            xs = np.empty(nv + n_cross)
            for k in range(m):
                for v in range(gn[k]):
                    xs[ne] = gx[k, v]
                    ne += 1
        ne = 0 if sweep == 0 else ne
        for k in range(m):
            for v in range(gn[k]):
                v1 = v + 1 if v + 1 < gn[k] else 0
                ax, ay = gx[k, v], gy[k, v]
                rx, ry = gx[k, v1] - ax, gy[k, v1] - ay
                for q in range(k + 1, m):
                    for w in range(gn[q]):
                        w1 = w + 1 if w + 1 < gn[q] else 0
                        bx, by = gx[q, w], gy[q, w]
                        sx, sy = gx[q, w1] - bx, gy[q, w1] - by
                        den = rx * sy - ry * sx
                        if den == 0.0:
                            continue  # parallel: their ends never swap inside a slab
                        t = ((bx - ax) * sy - (by - ay) * sx) / den
                        u = ((bx - ax) * ry - (by - ay) * rx) / den
                        if 0.0 < t < 1.0 and 0.0 < u < 1.0:
                            if sweep == 0:
                                n_cross += 1
                            else:
                                xs[ne] = ax + t * rx
                                ne += 1
    xs = np.sort(xs[:ne])
    lo = np.empty(m)
    hi = np.empty(m)
    total = 0.0
    for e in range(ne - 1):
        x0 = xs[e]
        x1 = xs[e + 1]
        if x1 <= x0:
            continue
        xm = 0.5 * (x0 + x1)
        n_int = 0
        for k in range(m):
            ylo = np.inf
            yhi = -np.inf
            for v in range(gn[k]):
                v1 = v + 1 if v + 1 < gn[k] else 0
                xa, xb = gx[k, v], gx[k, v1]
                if (xa < xm) != (xb < xm):
                    y = gy[k, v] + (xm - xa) * (gy[k, v1] - gy[k, v]) / (xb - xa)
                    ylo = min(ylo, y)
                    yhi = max(yhi, y)
            if yhi > ylo:
                lo[n_int] = ylo
                hi[n_int] = yhi
                n_int += 1
        if n_int == 0:
            continue
        order = np.argsort(lo[:n_int])
        length = 0.0
        cur_lo = lo[order[0]]
        cur_hi = hi[order[0]]
        for q in range(1, n_int):
            a = lo[order[q]]
            b = hi[order[q]]
            if a > cur_hi:
                length += cur_hi - cur_lo
                cur_lo = a
                cur_hi = b
            elif b > cur_hi:
                cur_hi = b
        length += cur_hi - cur_lo
        total += (x1 - x0) * length
    return total


@nb.njit(cache=True, nogil=True)
def _view_grid(d, V, F, occluder):
    """Bounding boxes of every facet in the plane perpendicular to ``d``, depth ranges along
    ``d``, and a uniform grid binning the occluders (CSR: start, items)."""
    ax = 0
    if abs(d[1]) < abs(d[ax]):
        ax = 1
    if abs(d[2]) < abs(d[ax]):
        ax = 2
    e = np.zeros(3)
    e[ax] = 1.0
    a = np.array([d[1] * e[2] - d[2] * e[1], d[2] * e[0] - d[0] * e[2], d[0] * e[1] - d[1] * e[0]])
    a /= np.sqrt(a[0] ** 2 + a[1] ** 2 + a[2] ** 2)
    b = np.array([d[1] * a[2] - d[2] * a[1], d[2] * a[0] - d[0] * a[2], d[0] * a[1] - d[1] * a[0]])
    nv = V.shape[0]
    nf = F.shape[0]
    U = np.empty(nv)
    W = np.empty(nv)
    D = np.empty(nv)
    for v in range(nv):
        U[v] = V[v, 0] * a[0] + V[v, 1] * a[1] + V[v, 2] * a[2]
        W[v] = V[v, 0] * b[0] + V[v, 1] * b[1] + V[v, 2] * b[2]
        D[v] = V[v, 0] * d[0] + V[v, 1] * d[1] + V[v, 2] * d[2]
    box = np.empty((nf, 6))  # u0 u1 w0 w1 t0 t1
    g0u = np.inf
    g1u = -np.inf
    g0w = np.inf
    g1w = -np.inf
    n_occ = 0
    for f in range(nf):
        i0, i1, i2 = F[f, 0], F[f, 1], F[f, 2]
        box[f, 0] = min(U[i0], U[i1], U[i2])
        box[f, 1] = max(U[i0], U[i1], U[i2])
        box[f, 2] = min(W[i0], W[i1], W[i2])
        box[f, 3] = max(W[i0], W[i1], W[i2])
        box[f, 4] = min(D[i0], D[i1], D[i2])
        box[f, 5] = max(D[i0], D[i1], D[i2])
        if occluder[f]:
            n_occ += 1
            g0u = min(g0u, box[f, 0])
            g1u = max(g1u, box[f, 1])
            g0w = min(g0w, box[f, 2])
            g1w = max(g1w, box[f, 3])
    ng = max(1, min(1024, int(np.sqrt(n_occ))))
    if n_occ == 0:
        g0u = g1u = g0w = g1w = 0.0
    su = (g1u - g0u) / ng if g1u > g0u else 1.0
    sw = (g1w - g0w) / ng if g1w > g0w else 1.0
    grid = np.array([g0u, g0w, 1.0 / su, 1.0 / sw, float(ng)])
    count = np.zeros(ng * ng + 1, dtype=np.int64)
    for f in range(nf):
        if not occluder[f]:
            continue
        c0 = min(ng - 1, max(0, int((box[f, 0] - g0u) / su)))
        c1 = min(ng - 1, max(0, int((box[f, 1] - g0u) / su)))
        r0 = min(ng - 1, max(0, int((box[f, 2] - g0w) / sw)))
        r1 = min(ng - 1, max(0, int((box[f, 3] - g0w) / sw)))
        for r in range(r0, r1 + 1):
            for c in range(c0, c1 + 1):
                count[r * ng + c + 1] += 1
    start = np.cumsum(count)
    items = np.empty(start[-1], dtype=np.int64)
    fill = start[:-1].copy()
    for f in range(nf):
        if not occluder[f]:
            continue
        c0 = min(ng - 1, max(0, int((box[f, 0] - g0u) / su)))
        c1 = min(ng - 1, max(0, int((box[f, 1] - g0u) / su)))
        r0 = min(ng - 1, max(0, int((box[f, 2] - g0w) / sw)))
        r1 = min(ng - 1, max(0, int((box[f, 3] - g0w) / sw)))
        for r in range(r0, r1 + 1):
            for c in range(c0, c1 + 1):
                items[fill[r * ng + c]] = f
                fill[r * ng + c] += 1
    return box, grid, start, items



@nb.njit(cache=True, nogil=True)
def _shadow_polygon(i, j, d0, d1, d2, ndi, V, F, N, P0, E1, E2, cx, cy, eps_h, hh, px, py, qx,
                    qy, tx, ty, idx):
    """Shadow that facet j casts on facet i along d = (d0, d1, d2), clipped to facet i, in
    the plane frame of i (written to qx, qy; counter-clockwise).  Returns its vertex count (0
    if none).  Scalar indexing only (array views cost more than the arithmetic here)."""
    hmax = -np.inf
    for v in range(3):
        f = F[j, v]
        hh[v] = (N[i, 0] * (V[f, 0] - P0[i, 0]) + N[i, 1] * (V[f, 1] - P0[i, 1])
                 + N[i, 2] * (V[f, 2] - P0[i, 2]))
        hmax = max(hmax, hh[v])
    if hmax <= eps_h:
        return 0  # on or behind the plane of i
    s1 = (E1[i, 0] * d0 + E1[i, 1] * d1 + E1[i, 2] * d2) / ndi
    s2 = (E2[i, 0] * d0 + E2[i, 1] * d1 + E2[i, 2] * d2) / ndi
    n_p = 0
    for v in range(3):  # cut to h >= 0, project along d onto the plane: x - d h / N.d
        w = v + 1 if v < 2 else 0
        fv = F[j, v]
        fw = F[j, w]
        if hh[v] >= 0.0:
            y0 = V[fv, 0] - P0[i, 0]
            y1 = V[fv, 1] - P0[i, 1]
            y2 = V[fv, 2] - P0[i, 2]
            px[n_p] = E1[i, 0] * y0 + E1[i, 1] * y1 + E1[i, 2] * y2 - hh[v] * s1
            py[n_p] = E2[i, 0] * y0 + E2[i, 1] * y1 + E2[i, 2] * y2 - hh[v] * s2
            n_p += 1
        if (hh[v] >= 0.0) != (hh[w] >= 0.0):
            t = hh[v] / (hh[v] - hh[w])
            y0 = V[fv, 0] + t * (V[fw, 0] - V[fv, 0]) - P0[i, 0]
            y1 = V[fv, 1] + t * (V[fw, 1] - V[fv, 1]) - P0[i, 1]
            y2 = V[fv, 2] + t * (V[fw, 2] - V[fv, 2]) - P0[i, 2]
            px[n_p] = E1[i, 0] * y0 + E1[i, 1] * y1 + E1[i, 2] * y2
            py[n_p] = E2[i, 0] * y0 + E2[i, 1] * y1 + E2[i, 2] * y2
            n_p += 1
    for e in range(3):  # all of it outside one edge of the facet: no overlap
        e1 = e + 1 if e < 2 else 0
        ex = cx[e1] - cx[e]
        ey = cy[e1] - cy[e]
        outside = True
        for v in range(n_p):
            if ex * (py[v] - cy[e]) - ey * (px[v] - cx[e]) > 0.0:
                outside = False
                break
        if outside:
            return 0
    if _signed_area(px, py, n_p) < 0.0:  # make it counter-clockwise
        for v in range(n_p // 2):
            px[v], px[n_p - 1 - v] = px[n_p - 1 - v], px[v]
            py[v], py[n_p - 1 - v] = py[n_p - 1 - v], py[v]
    nc = _clip(px, py, n_p, cx, cy, 3, tx, ty, qx, qy)
    if nc < 3:
        return 0
    nq = _hull(tx, ty, nc, qx, qy, idx)
    if nq < 3 or _signed_area(qx, qy, nq) <= 1e-15 * _signed_area(cx, cy, 3):
        return 0
    return nq


@nb.njit(cache=True, nogil=True)
def _exact_kernel(V, F, N, P0, E1, E2, T2, receiver, dirs, watertight, eps_h):
    """Lit (and visible) fraction of every facet for every geometry, exactly.

    ``dirs`` (G, K, 3): K directions per geometry that must all be unobstructed.  For facet i
    and direction d (N_i.d > 0) a point p of the facet is shadowed iff the ray p + t d
    (t > 0) meets the surface; on a closed surface the first hit enters the solid, so the
    occluders are the facets with N_j.d < 0 (every facet with N_j.d != 0 on an open surface),
    cut to their part in front of the plane of i and projected along d onto it.  The union of
    these convex polygons over the K directions, clipped to the facet, is its shadowed area,
    computed by inclusion-exclusion over convex intersections; facets past the work budget
    get NaN (the caller unions their polygons with GEOS).  Candidate occluders come from a
    uniform grid over the bounding boxes in the plane perpendicular to d, then a depth test.
    """
    G = dirs.shape[0]
    K = dirs.shape[1]
    nf = F.shape[0]
    frac = np.zeros((G, nf))
    gx = np.empty((MAX_SHADOWS, 8))  # a shadow clipped to a triangle has at most 7 vertices
    gy = np.empty((MAX_SHADOWS, 8))
    gn = np.empty(MAX_SHADOWS, dtype=np.int64)
    stack_x = np.empty((_MAXM + 1, _MAXV))
    stack_y = np.empty((_MAXM + 1, _MAXV))
    stack_n = np.empty(_MAXM + 1, dtype=np.int64)
    nxt = np.empty(_MAXM + 1, dtype=np.int64)
    tx = np.empty(_MAXV)
    ty = np.empty(_MAXV)
    px = np.empty(8)
    py = np.empty(8)
    hh = np.empty(3)
    qx = np.empty(_MAXV)
    qy = np.empty(_MAXV)
    idx = np.empty(_MAXV, dtype=np.int64)
    cx = np.empty(3)
    cy = np.empty(3)
    nd = np.empty((K, nf))
    stamp = np.empty((K, nf), dtype=np.int64)
    for g in range(G):
        for k in range(K):
            for f in range(nf):
                nd[k, f] = N[f, 0] * dirs[g, k, 0] + N[f, 1] * dirs[g, k, 1] + N[f, 2] * dirs[g, k, 2]
                stamp[k, f] = -1
        boxes = []
        grids = []
        starts = []
        itemss = []
        for k in range(K):
            occ = (nd[k] < 0.0) if watertight else (nd[k] != 0.0)
            box, grid, start, items = _view_grid(dirs[g, k], V, F, occ)
            boxes.append(box)
            grids.append(grid)
            starts.append(start)
            itemss.append(items)
        for i in range(nf):
            facing = True
            for k in range(K):
                if nd[k, i] <= 0.0:
                    facing = False
            if not facing:
                continue  # fraction 0
            if not receiver[i]:
                frac[g, i] = 1.0
                continue
            for c in range(3):
                cx[c] = T2[i, c, 0]
                cy[c] = T2[i, c, 1]
            area_t = _signed_area(cx, cy, 3)
            m = 0
            too_many = False
            for k in range(K):
                box = boxes[k]
                grid = grids[k]
                start = starts[k]
                items = itemss[k]
                ng = int(grid[4])
                dk0 = dirs[g, k, 0]
                dk1 = dirs[g, k, 1]
                dk2 = dirs[g, k, 2]
                c0 = int(np.floor((box[i, 0] - grid[0]) * grid[2]))
                c1 = int(np.floor((box[i, 1] - grid[0]) * grid[2]))
                r0 = int(np.floor((box[i, 2] - grid[1]) * grid[3]))
                r1 = int(np.floor((box[i, 3] - grid[1]) * grid[3]))
                if c1 < 0 or r1 < 0 or c0 >= ng or r0 >= ng:
                    continue
                for r in range(max(r0, 0), min(r1, ng - 1) + 1):
                    for c in range(max(c0, 0), min(c1, ng - 1) + 1):
                        cell = r * ng + c
                        for q in range(start[cell], start[cell + 1]):
                            j = items[q]
                            if j == i or stamp[k, j] == i:
                                continue
                            stamp[k, j] = i
                            if (box[j, 0] >= box[i, 1] or box[j, 1] <= box[i, 0]
                                    or box[j, 2] >= box[i, 3] or box[j, 3] <= box[i, 2]
                                    or box[j, 5] <= box[i, 4]):
                                continue  # apart across d, or wholly behind i along d
                            nq = _shadow_polygon(i, j, dk0, dk1, dk2, nd[k, i], V, F, N, P0, E1,
                                                 E2, cx, cy, eps_h, hh, px, py, qx, qy, tx, ty,
                                                 idx)
                            if nq == 0:
                                continue
                            if m == MAX_SHADOWS or nq > 8:
                                too_many = True
                                continue
                            for v in range(nq):
                                gx[m, v] = qx[v]
                                gy[m, v] = qy[v]
                            gn[m] = nq
                            m += 1
            if m == 0:
                frac[g, i] = 1.0
                continue
            if too_many:
                frac[g, i] = np.nan
                continue
            ok = False
            shadow = 0.0
            if m <= _MAXM:
                shadow, ok = _union_area(gx, gy, gn, m, 1e-15 * area_t, stack_x, stack_y,
                                         stack_n, nxt, tx, ty)
            if not ok:
                shadow = _union_area_slabs(gx, gy, gn, m)
            frac[g, i] = min(1.0, max(0.0, 1.0 - shadow / area_t))
    return frac


@nb.njit(cache=True, nogil=True)
def _facet_shadows(i, dirs, V, F, N, P0, E1, E2, T2, watertight, eps_h):
    """Every shadow polygon on facet i for the K directions ``dirs`` (K, 3), by testing every
    facet (no grid): vertices (n, 2) and CSR offsets.  For the GEOS fallback."""
    nf = F.shape[0]
    K = dirs.shape[0]
    cx = T2[i, :, 0].copy()
    cy = T2[i, :, 1].copy()
    tx = np.empty(_MAXV)
    ty = np.empty(_MAXV)
    px = np.empty(8)
    py = np.empty(8)
    hh = np.empty(3)
    qx = np.empty(_MAXV)
    qy = np.empty(_MAXV)
    idx = np.empty(_MAXV, dtype=np.int64)
    xy = np.empty((8 * 64, 2))
    start = [0]
    n = 0
    for k in range(K):
        d = dirs[k]
        ndi = N[i, 0] * d[0] + N[i, 1] * d[1] + N[i, 2] * d[2]
        for j in range(nf):
            if j == i:
                continue
            ndj = N[j, 0] * d[0] + N[j, 1] * d[1] + N[j, 2] * d[2]
            if (watertight and ndj >= 0.0) or ndj == 0.0:
                continue
            nq = _shadow_polygon(i, j, d[0], d[1], d[2], ndi, V, F, N, P0, E1, E2, cx, cy, eps_h,
                                 hh, px, py, qx, qy, tx, ty, idx)
            if nq == 0:
                continue
            if n + nq > xy.shape[0]:
                bigger = np.empty((2 * xy.shape[0] + nq, 2))
                bigger[:n] = xy[:n]
                xy = bigger
            for v in range(nq):
                xy[n + v, 0] = qx[v]
                xy[n + v, 1] = qy[v]
            n += nq
            start.append(n)
    return xy[:n].copy(), np.array(start, dtype=np.int64)


# ----------------------------------------------------------------------------- exact method


def _plane_frames(mesh: trimesh.Trimesh, cache: dict[str, Any]) -> dict[str, Any]:
    """Per-facet arrays of the exact method: vertices, faces, normals from the winding, an
    in-plane orthonormal frame (E1 along the first edge, E2 = N x E1), the triangle in that
    frame (counter-clockwise), the receivers that can be shadowed and the surface type."""
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
    receiver = ok & ~_supporting(mesh, cache, tol)
    frames = {
        "V": V, "F": F, "N": N, "P0": np.ascontiguousarray(tri[:, 0]), "E1": E1, "E2": E2,
        "T2": np.ascontiguousarray(T2), "receiver": receiver, "eps": tol,
        "watertight": bool(mesh.is_watertight) and bool(mesh.is_winding_consistent),
    }
    cache["exact:frames"] = frames
    return frames


def _geos_fraction(frames: dict[str, Any], i: int, dirs: np.ndarray) -> float:
    """Fraction of facet i left by the GEOS union of its shadows (the kernel's fallback)."""
    import shapely

    xy, start = _facet_shadows(i, dirs, frames["V"], frames["F"], frames["N"], frames["P0"],
                               frames["E1"], frames["E2"], frames["T2"], frames["watertight"],
                               frames["eps"])
    tri = shapely.Polygon(frames["T2"][i])
    rings = [xy[a:b] for a, b in itertools.pairwise(start)]
    shadow = shapely.union_all([shapely.Polygon(r) for r in rings])
    return float(min(1.0, max(0.0, 1.0 - shadow.area / tri.area)))


def _exact(
    spacecraft: Spacecraft | trimesh.Trimesh, directions: list[np.ndarray], convex_shortcut: bool
) -> np.ndarray:
    """Exact fraction unobstructed along every direction of the list, shape (n_geom, n_facets)."""
    mesh, cache = _mesh_of(spacecraft)
    normals = np.asarray(mesh.face_normals, dtype=np.float64)
    front = np.logical_and.reduce([d @ normals.T > 0 for d in directions])
    if convex_shortcut and _is_convex(spacecraft):
        return front.astype(np.float64)
    frames = _plane_frames(mesh, cache)
    dirs = np.ascontiguousarray(np.stack(directions, axis=1), dtype=np.float64)  # (G, K, 3)
    if not frames["receiver"].any():
        return front.astype(np.float64)
    frac = _exact_kernel(frames["V"], frames["F"], frames["N"], frames["P0"], frames["E1"],
                         frames["E2"], frames["T2"], frames["receiver"], dirs,
                         frames["watertight"], frames["eps"])
    for g, i in np.argwhere(np.isnan(frac)):
        frac[g, i] = _geos_fraction(frames, int(i), dirs[g])
    # a facet facing a direction per the stored normals but not per its winding (or
    # vice versa) keeps the stored normals' verdict, as the sampled method does
    return np.where(front, frac, 0.0)


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
    _mesh_of(spacecraft)
    if _method(method) == "exact":
        _density(density)
        _engine_name(engine)
        if offset is not None and not (np.isfinite(offset) and offset > 0):
            raise ValidationError(f"offset: got {offset!r}; expected a positive length [m]")
        f = _exact(spacecraft, directions, convex_shortcut)
        return f, (np.zeros_like(f) if return_error else None)
    masks = _escape_masks(spacecraft, directions, density, engine, offset, convex_shortcut, seed)
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
        :data:`DENSITY_PRESETS`; checked but unused by the exact method.
    engine : {"auto", "embree", "triangle"} or None
        Ray engine of the sampled method (see :data:`ENGINES`); None is ``"auto"``.
    offset : float, optional
        Sampled method: lift of the ray origins along the facet normal [m]; default
        :data:`OFFSET_FACTOR` times the bounding-box diagonal.
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
    """
    d, shape = _directions(directions, "directions")
    f, _ = _fractions(spacecraft, [d], method, density, engine, offset, convex_shortcut, seed, False)
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
    """
    return lit_fraction(spacecraft, directions, method=method, density=density, engine=engine,
                        offset=offset, convex_shortcut=convex_shortcut, seed=seed)


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
    """
    s, o = np.broadcast_arrays(
        np.asarray(to_sun, dtype=np.float64), np.asarray(to_observer, dtype=np.float64)
    )
    ds, shape = _directions(s, "to_sun")
    do, _ = _directions(o, "to_observer")
    f, err = _fractions(spacecraft, [ds, do], method, density, engine, offset, convex_shortcut,
                        seed, return_error)
    if return_error:
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
        masks = _escape_masks(spacecraft, [ds, do], density, engine, offset, True, seed)
        lit, vis, joint = masks[0].mean(-1), masks[1].mean(-1), (masks[0] & masks[1]).mean(-1)
        extra = {"density": _density(density), "samples_per_facet": samples_per_facet(density),
                 "engine": _engine_name(engine), "seed": seed}
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
            FACET: (FACET, np.arange(spacecraft.n_facets), attrs(FACET)),
            VECTOR: (VECTOR, ["x", "y", "z"], attrs(VECTOR)),
        },
        attrs={"spacecraft": spacecraft.name, "method": method, **extra},
    )
