"""The tools of the sampled shadow method: sampling densities, point sets on facets and
ray engines.

:mod:`sbrdf_xr.body.visibility` documents the method and casts the rays
(:func:`~sbrdf_xr.body.visibility.escape_masks`); here are the named densities
(:data:`DENSITY_PRESETS`), the scrambled Sobol' points mapped to a triangle
(:func:`sample_triangle`, Shirley and Chiu 1997) and the ray engines (:data:`ENGINES`,
:func:`intersector`), cached per spacecraft.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import trimesh
from numpy.typing import NDArray

from ..errors import ValidationError

__all__ = [
    "DENSITY_PRESETS",
    "ENGINES",
    "MAX_RAYS_PER_CALL",
    "OFFSET_FACTOR",
    "SEED",
    "available_engines",
    "check_density",
    "engine_name",
    "intersector",
    "sample_triangle",
    "sample_uv",
    "samples_per_facet",
    "to_triangle",
]

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

#: Upper bound on the rays cast in one engine call (memory ~ 100 bytes per ray).
MAX_RAYS_PER_CALL = 1 << 20

#: Seed of the sampled method's point sets.
SEED = 20240601


def available_engines() -> list[str]:
    """Ray engines usable in this environment (``"triangle"`` always; ``"embree"`` if installed).

    Examples
    --------
    >>> "triangle" in available_engines()
    True
    """
    out = ["triangle"]
    try:
        import trimesh.ray.ray_pyembree  # noqa: F401
    except ImportError:
        return out
    return ["embree", *out]


def engine_name(engine: str | None) -> str:
    """The ray engine to use for ``engine`` (None or ``"auto"``: the best available).

    Examples
    --------
    >>> from sbrdf_xr.body.rays import available_engines, engine_name
    >>> engine_name("triangle"), engine_name(None) == available_engines()[0]
    ('triangle', True)
    >>> engine_name("optix")
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.ValidationError: engine: got 'optix'; allowed: auto, embree, triangle
    """
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


def check_density(density: int | str) -> int:
    """The sampling density of an integer >= 1 or a preset name of :data:`DENSITY_PRESETS`.

    Examples
    --------
    >>> from sbrdf_xr.body.rays import check_density
    >>> check_density(3), check_density("balanced")
    (3, 4)
    >>> check_density(0)
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.ValidationError: density: got 0; expected an integer sampling density >= 1 \
or a preset name ['fast', 'balanced', 'reference']
    """
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
    """Number of rays per facet and direction at a sampling density (``density**2``).

    Examples
    --------
    >>> samples_per_facet(4), samples_per_facet("reference")
    (16, 256)
    """
    return check_density(density) ** 2


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

    Examples
    --------
    >>> w = sample_triangle(16, n_facets=2, seed=1)
    >>> w.shape, bool(np.allclose(w.sum(axis=-1), 1.0)), bool((w >= 0).all())
    ((2, 16, 3), True, True)
    """
    if isinstance(n_samples, bool) or int(n_samples) != n_samples or n_samples < 1 or n_facets < 0:
        raise ValidationError(
            f"n_samples, n_facets: got {n_samples!r}, {n_facets!r}; expected integers >= 1 and >= 0"
        )
    base, shift = sample_uv(int(n_samples), int(n_facets), seed)
    return to_triangle(base[None, :, :] + shift[:, None, :])


def sample_uv(n_samples: int, n_facets: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """The scrambled Sobol' points (n_samples, 2) and the per-facet shifts (n_facets, 2).

    Examples
    --------
    Eight points of a base-2 Sobol' set fall one in each eighth of either axis:

    >>> from sbrdf_xr.body.rays import sample_uv
    >>> base, shift = sample_uv(8, 3, seed=1)
    >>> base.shape, shift.shape
    ((8, 2), (3, 2))
    >>> sorted((base[:, 0] * 8).astype(int).tolist()) == list(range(8))
    True
    >>> sorted((base[:, 1] * 8).astype(int).tolist()) == list(range(8))
    True
    """
    from scipy.stats import qmc

    rng = np.random.default_rng(seed)
    m = max(0, int(np.ceil(np.log2(n_samples))))
    base = qmc.Sobol(d=2, scramble=True, seed=rng).random_base2(m)[:n_samples]
    return base, rng.random((n_facets, 2))


def to_triangle(uv: np.ndarray) -> np.ndarray:
    """Barycentric weights of unit-square points (shifted modulo 1), area-preserving map.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.body.rays import to_triangle
    >>> uv = np.array([[0.0, 0.0], [0.25, 0.5], [1.25, 1.5]])  # the last is the second, mod 1
    >>> to_triangle(uv).round(6).tolist()
    [[1.0, 0.0, 0.0], [0.5, 0.25, 0.25], [0.5, 0.25, 0.25]]
    """
    uv = uv % 1.0
    r = np.sqrt(uv[..., 0])
    return np.stack([1.0 - r, r * (1.0 - uv[..., 1]), r * uv[..., 1]], axis=-1)


def intersector(
    mesh: trimesh.Trimesh, cache: dict[str, Any], engine: str
) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    """A function (origins, unit directions) -> bool hit, cached per spacecraft and engine.

    Examples
    --------
    A ray from above the unit box hits it going down and misses it going up:

    >>> import numpy as np
    >>> import trimesh
    >>> from sbrdf_xr.body.rays import intersector
    >>> cache = {}
    >>> hits = intersector(trimesh.creation.box(), cache, "triangle")
    >>> origins = np.array([[0.0, 0.0, 2.0], [0.0, 0.0, 2.0]])
    >>> hits(origins, np.array([[0.0, 0.0, -1.0], [0.0, 0.0, 1.0]])).tolist()
    [True, False]
    >>> list(cache), intersector(trimesh.creation.box(), cache, "triangle") is hits
    (['ray:triangle'], True)
    """
    key = f"ray:{engine}"
    if key in cache:
        return cache[key]
    if engine == "embree":
        from trimesh.ray import ray_pyembree

        rmi: Any = ray_pyembree.RayMeshIntersector(mesh)

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
