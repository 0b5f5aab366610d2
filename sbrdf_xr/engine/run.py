"""Execute a plan: blocks of geometries through the kernel into an xarray cube.

:func:`simulate` takes a scene (or its :class:`~sbrdf_xr.engine.plan.Plan`) and returns the
cube.  It derives nothing: everything it runs was resolved by the plan.  Small
scenes (outputs under :data:`IN_PROCESS_BYTES`) run at once, in this process, on a
few threads (the compiled kernel releases the GIL), without building a Dask graph:
the cube comes back numpy-backed.  Larger ones, or any call with ``chunk``,
``lazy=True`` or a ``client``, return a *lazy* cube: one Dask task per block, built
directly (the plan enters the graph once), chunked over the first geometry
dimension with the spectral dimension whole.  :func:`sbrdf_xr.store.write` writes a
cube (netCDF block by block, or a Zarr store whose blocks the Dask workers store
themselves; atomic, resumable).  This module and the writers are the only ones that
know about Dask scheduling.

The cube (DESIGN.md data model)
-------------------------------
``spacecraft_sbrdf``
    The paper's overall spacecraft sBRDF, paper 000 Eq. 4:
    ``sum_j a_2D,j f_r,j / sum_j a_2D,j`` with ``a_2D,j = A_j cos(theta_r,j)`` over
    the lit and visible facets [sr-1].  When nothing contributes (0/0) it is 0 and
    ``area`` is 0: the cube says "no contributing area" instead of NaN.
``signal``
    The radiometric signal ``S = sum_j A_j cos(theta_i,j) cos(theta_r,j) f_r,j``
    [m2 sr-1]: reflected intensity per unit solar irradiance.  Paper 000 Eq. 3
    leaves out ``cos(theta_i)``; ``signal`` keeps it, ``spacecraft_sbrdf`` follows
    the paper.  (Not named ``sbrdf``: ``cube.sbrdf`` is the Dataset accessor.)
``brdf``
    The paper's broadband BRDF, Eq. 2: ``spacecraft_sbrdf`` integrated over wavelength
    (trapezoid) [sr-1 nm].
``area``
    The contributing projected area, ``sum_j a_2D,j`` [m2].
``signal_material``
    ``signal`` per material (with the ``per_material`` output).

Coordinates carry the geometry: ``to_sun`` and ``to_observer`` (body frame),
the attitude quaternions and the phase angle.  In a lazy cube over attitudes x phase
angles the body-frame directions are lazy too, made by each block's task with its
outputs (the same rotation, the same bits): a sweep never holds them for every
attitude at once.  :data:`sbrdf_xr.engine.effects.OUTPUTS`
declares every variable and its attributes.
"""

from __future__ import annotations

import os
import threading
import uuid
from concurrent.futures import ThreadPoolExecutor
from functools import partial
from typing import Any

import dask.array as dsa
import numpy as np
import xarray as xr
from dask.highlevelgraph import HighLevelGraph
from dask.typing import Key
from xarray.indexes import PandasIndex

from .._names import FACET, WAVELENGTH, attrs
from ..errors import SceneError
from .articulation import articulated_sums
from .builtin import resolve_scene
from .effects import BlockInputs, finish
from .evaluator import block_outputs
from .plan import Plan
from .reuse import INDEXES
from .scene import Scene
from .sweep import GridGeometry

__all__ = ["IN_PROCESS_BYTES", "run_block", "simulate"]

#: Scenes whose outputs are smaller than this [byte] run in-process, without Dask
#: (unless ``chunk``, ``lazy=True`` or a client is given).
IN_PROCESS_BYTES = 64 * 2**20
#: Fewest geometries per thread when an in-process run is split across threads.
_MIN_PER_THREAD = 16


def run_block(plan: Plan, sl: slice) -> dict[str, np.ndarray]:
    """Every output of the plan for the geometries ``sl`` of its first dimension.

    Runs each effect of the plan (:data:`sbrdf_xr.engine.effects.EFFECTS`) on the block and
    combines their sums into the outputs (:func:`sbrdf_xr.engine.effects.finish`); a rigid
    body's sunlight-only plan runs through its compiled evaluator
    (:func:`sbrdf_xr.engine.evaluator.block_outputs`), bit for bit the same.

    Returns
    -------
    dict of str to ndarray
        Arrays shaped ``(block length, *other dims)`` per output variable.

    Examples
    --------
    The second attitude (45 deg about z) of a Lambertian unit cube: at phase 0 the
    +x and -y faces are each lit and seen at 45 deg, ``2 * cos(45 deg)**2 * 0.5 / pi``.

    >>> import trimesh
    >>> from sbrdf_xr import Scene, geometry, load_spacecraft, simulate
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> turns = geometry.axis_rotation([0, 0, 1], [0.0, 45.0])  # two attitudes about z
    >>> scene = Scene(box, {"grey": grey}, attitudes=turns, phase_angles=[0.0, 60.0])
    >>> from sbrdf_xr.engine import run_block
    >>> out = run_block(scene.plan(), slice(1, 2))
    >>> sorted((k, v.shape) for k, v in out.items())
    [('area', (1, 2)), ('brdf', (1, 2)), ('signal', (1, 2, 3)), ('spacecraft_sbrdf', (1, 2, 3))]
    >>> round(float(out["signal"][0, 0, 0]), 6)
    0.159155
    """
    return _outputs(plan, plan.geometry.block(sl), sl)


def _outputs(plan: Plan, block: BlockInputs, sl: slice) -> dict[str, np.ndarray]:
    if plan.articulation is not None:  # parts that turn: every group in its own frame
        return finish(plan, articulated_sums(plan, block, sl), block.lead_shape)
    return block_outputs(plan, block)  # the plan's evaluator where it allows


#: The coordinates a lazy cube over attitudes x phase angles makes by block (:func:`_lazy`).
_DIRECTIONS = ("to_sun", "to_observer")


def _block_task(plan: Plan, k: int, directions: bool = False) -> dict[str, np.ndarray]:
    """Block ``k``'s outputs and, with ``directions``, its body-frame directions."""
    sl = plan.block_slice(k)
    block = plan.geometry.block(sl)
    out = _outputs(plan, block, sl)
    if directions:
        shape = (*block.lead_shape, 3)
        out["to_sun"] = block.to_sun.reshape(shape)
        out["to_observer"] = block.to_observer.reshape(shape)
    return out


def _lazy_directions(plan: Plan) -> bool:
    """Whether a lazy cube makes its ``to_sun`` and ``to_observer`` by block: over
    attitudes x phase angles (explicit pairs carry their own) of a rigid body."""
    return isinstance(plan.geometry, GridGeometry) and plan.articulation is None


def default_n_threads() -> int:
    """Threads of an in-process simulation: ``SBRDF_XR_NUM_THREADS``, ``NUMBA_NUM_THREADS``
    or the number of CPUs.

    Examples
    --------
    >>> default_n_threads() >= 1
    True
    """
    n = os.environ.get("SBRDF_XR_NUM_THREADS") or os.environ.get("NUMBA_NUM_THREADS")
    return max(1, int(n)) if n else max(1, os.cpu_count() or 1)


def _in_process(plan: Plan, n_threads: int | None = None) -> dict[str, np.ndarray]:
    """All outputs at once in this process, split over threads (the kernel releases the GIL)."""
    n = plan.n_lead
    workers = max(1, min(n_threads or default_n_threads(), n // _MIN_PER_THREAD))
    if workers == 1:
        return run_block(plan, slice(0, n))
    edges = np.linspace(0, n, workers + 1).astype(int)
    pool = _pool(workers - 1)  # the calling thread computes the first part itself
    futures = [
        pool.submit(run_block, plan, slice(edges[i], edges[i + 1])) for i in range(1, workers)
    ]
    try:
        parts = [run_block(plan, slice(edges[0], edges[1]))]
    finally:
        parts += [f.result() for f in futures]
    return {k: np.concatenate([p[k] for p in parts], axis=0) for k in parts[0]}


_POOLS: dict[int, ThreadPoolExecutor] = {}
_POOL_LOCK = threading.Lock()


def _pool(workers: int) -> ThreadPoolExecutor:
    """A thread pool kept for the life of the process (starting threads per call would cost
    more than a small scene's whole kernel)."""
    with _POOL_LOCK:
        if workers not in _POOLS:
            _POOLS[workers] = ThreadPoolExecutor(workers, thread_name_prefix="sbrdf_xr")
        return _POOLS[workers]


def _lazy(plan: Plan, client: Any = None) -> dict[str, dsa.Array]:
    """One Dask task per block, and per output one array whose chunks select from it.

    The graph is written directly: the plan enters it once (scattered to the workers
    with ``client``), each block task refers to it by key, and nothing is tokenized
    per block.  Over attitudes x phase angles the block tasks also give the
    body-frame directions, as arrays under their coordinate names.
    """
    token = uuid.uuid4().hex
    plan_key = f"sbrdf-plan-{token}"
    block_name = f"sbrdf-block-{token}"
    if client is not None:  # the graph holds the future: the plan lives as long as the cube
        plan_ref: Any = client.scatter(plan, broadcast=True, hash=False)
        layer0: dict[Any, Any] = {}
    else:
        plan_ref = plan_key
        layer0 = {plan_key: plan}
    nb = plan.n_blocks
    directions = _lazy_directions(plan)
    blocks = {(block_name, k): (_block_task, plan_ref, k, directions) for k in range(nb)}
    block_layer = {**layer0, **blocks}
    lead = tuple(plan.block_slice(k).stop - plan.block_slice(k).start for k in range(nb))
    picked = [(o.name, o.shape, o.dtype) for o in plan.outputs]
    if directions:
        picked += [(d, (*plan.geometry.shape, 3), np.dtype(np.float64)) for d in _DIRECTIONS]
    out = {}
    for what, shape, dtype in picked:
        name = f"sbrdf-{what}-{token}"
        rest = (0,) * (len(shape) - 1)
        layer: dict[Key, Any] = {
            (name, k, *rest): (_pick, (block_name, k), what) for k in range(nb)
        }
        graph = HighLevelGraph(
            layers={block_name: block_layer, name: layer},
            dependencies={block_name: set(), name: {block_name}},
        )
        chunks = (lead, *((s,) for s in shape[1:]))
        out[what] = dsa.Array(graph, name, chunks, dtype=dtype)
    return out


def _pick(d: dict[str, np.ndarray], name: str) -> np.ndarray:
    return d[name]


def _template(plan: Plan) -> xr.Dataset:
    """The cube's coordinates and attributes (made once per plan)."""
    if "template" in plan.cache:
        return plan.cache["template"]
    plan.cache["template"] = _coordinates(plan)
    return plan.cache["template"]


def _coordinates(plan: Plan, directions: dict[str, Any] | None = None) -> xr.Dataset:
    """The cube's coordinates and attributes; ``directions``: a lazy cube's own
    ``to_sun`` and ``to_observer`` (:func:`_lazy`)."""
    geo = plan.geometry
    if directions is not None and isinstance(geo, GridGeometry):
        coords = geo.coords(directions)
    else:
        coords = geo.coords()
    coords["xyz"] = ("xyz", ["x", "y", "z"], attrs("xyz"))
    if plan.articulation is not None:  # the hinge angle of every part at every geometry
        sun = coords["to_sun"]
        values = sun.values if isinstance(sun, xr.DataArray) else sun[1]
        coords.update(plan.articulation.coords(values, plan.geometry.dims))
    dims = {d for o in plan.outputs for d in o.dims}
    if WAVELENGTH in dims:
        coords[WAVELENGTH] = (WAVELENGTH, plan.wavelength, attrs(WAVELENGTH))
    if "band" in dims:
        coords.update(plan.band_coords)
    if "material" in dims:
        coords["material"] = ("material", list(plan.materials), attrs("material"))
    if FACET in dims:  # the plan's terms: a facet, or the first of those merged into it
        coords[FACET] = (FACET, np.asarray(plan.terms.facet), attrs(FACET))
        coords["facet_normal"] = ((FACET, "xyz"), np.asarray(plan.terms.normal), attrs("normal"))
    return _coordinates_only(coords, dict(plan.attrs))


def _coordinates_only(coords: dict[str, Any], attributes: dict[str, Any]) -> xr.Dataset:
    """``xr.Dataset(coords=coords, attrs=attributes)`` built directly: a default (pandas)
    index for each dimension coordinate, no alignment or merging (the coordinates come
    from one geometry and agree by construction), in the same order."""
    arrays = [c.coords for c in coords.values() if isinstance(c, xr.DataArray)]
    if any(k not in coords for a in arrays for k in a):  # coordinates that come with them
        return xr.Dataset(coords=coords, attrs=attributes)
    variables: dict[str, xr.Variable] = {}
    indexes: dict[str, Any] = {}
    # xarray puts the coordinates of DataArray-valued entries first
    for name in dict.fromkeys([*(str(k) for a in arrays for k in a), *coords]):
        spec = coords[name]
        if isinstance(spec, xr.DataArray):
            var = spec.variable
        else:
            var = xr.as_variable(spec, name=name, auto_convert=False)
        if var.dims == (name,):
            index = INDEXES.get(_index_key(name, var), partial(_pandas_index, name, var))
            indexes[name] = index
            var = index.create_variables({name: var})[name]
        variables[name] = var
    return xr.Dataset._construct_direct(variables, set(variables), None, attributes, indexes)


def _pandas_index(name: str, var: xr.Variable) -> PandasIndex:
    """A default index over a copy of ``var``'s values (kept: it must own its memory)."""
    return PandasIndex.from_variables({name: var.copy(deep=True)}, options={})


#: Largest dimension coordinate whose index is kept for later cubes (:data:`INDEXES`).
_INDEX_KEEP_SIZE = 4096


def _index_key(name: str, var: xr.Variable) -> tuple | None:
    """The content of a small numeric or string dimension coordinate (None: not kept)."""
    values = var.values
    if values.size > _INDEX_KEEP_SIZE or values.dtype.kind not in "biufcmMUS":
        return None
    return (name, var.dims, values.dtype.str, values.shape, values.tobytes())


def _dataset(plan: Plan, arrays: dict[str, Any]) -> xr.Dataset:
    """The cube: every output with its dims and attributes, the geometry as coordinates.

    Assembled from the plan's template without re-deriving coordinates or indexes
    (xarray's direct constructor): a single-geometry call costs microseconds here.
    """
    directions = {d: arrays[d] for d in _DIRECTIONS if d in arrays}
    t = _coordinates(plan, directions) if directions else _template(plan)
    variables = dict(t.variables)
    for o in plan.outputs:
        variables[o.name] = xr.Variable(o.dims, arrays[o.name], attrs=dict(o.attrs))
    return xr.Dataset._construct_direct(
        variables, set(t.coords), None, dict(t.attrs), dict(t.xindexes)
    )


def simulate(
    scene: Scene | Plan | str | os.PathLike[str],
    plan: Plan | None = None,
    *,
    client: Any = None,
    lazy: bool | None = None,
    **options: Any,
) -> xr.Dataset:
    """Simulate a scene (or execute its plan) into a cube.

    Parameters
    ----------
    scene : Scene, Plan, str or path
        A scene, its compiled plan, a built-in scene name or a TOML scene file.
    plan : Plan, optional
        The scene's own plan (``scene.plan()``); kept for compatibility, pass the plan
        as the first argument instead.
    client : dask.distributed.Client, optional
        The cube will be computed on this cluster: the plan (with its tables) is
        scattered to every worker once.  Implies a lazy cube.
    lazy : bool, optional
        True: always a Dask-backed cube; False: always computed in-process now;
        default: in-process when the outputs are under :data:`IN_PROCESS_BYTES` and
        no ``chunk`` was set, lazy otherwise.
    **options
        Scene fields to change first (``preset="fast"``, ``method="cubic"``, ``chunk=...``).

    Returns
    -------
    xarray.Dataset
        The cube over ``(attitude, phase_angle, ...)`` for a grid, ``(geometry, ...)``
        for explicit pairs; see the module docstring for its variables.

    Raises
    ------
    SceneError
        A plan together with options or with another scene; or a bad scene.

    Examples
    --------
    A Lambertian unit cube (albedo 0.5) turned by 0 and 45 deg about z, at phase
    angles 0 and 60 deg.  At identity attitude the signal is
    ``0.5 / pi * cos(phase / 2)**2``; at 45 deg and phase 60 deg the +x and -y faces
    each give ``cos(15 deg) cos(75 deg) = 1/4`` of ``0.5 / pi``.

    >>> import trimesh
    >>> from sbrdf_xr import Scene, geometry, load_spacecraft, simulate
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> turns = geometry.axis_rotation([0, 0, 1], [0.0, 45.0])  # two attitudes about z
    >>> scene = Scene(box, {"grey": grey}, attitudes=turns, phase_angles=[0.0, 60.0])
    >>> cube = simulate(scene)
    >>> cube.signal.dims, cube.signal.shape
    (('attitude', 'phase_angle', 'wavelength'), (2, 2, 3))
    >>> cube.signal.attrs["units"]
    'm2 sr-1'
    >>> cube.signal.isel(wavelength=0).round(6).values.tolist()
    [[0.159155, 0.119366], [0.159155, 0.079577]]
    >>> cube.area.round(6).values.tolist()  # projected area [m2]
    [[1.0, 0.866025], [1.414214, 1.224745]]

    With a ``chunk`` the cube is Dask-backed, one task per block:

    >>> lazy = simulate(scene, chunk=1)
    >>> lazy.signal.chunks
    ((1, 1), (2,), (3,))
    >>> round(float(lazy.signal[1, 0, 0]), 6)
    0.159155
    """
    if isinstance(scene, Plan):
        if plan is not None or options:
            raise SceneError(
                "simulate(plan): a plan is already compiled; change the scene and "
                "plan it again instead of passing options"
            )
        the_plan = scene
    else:
        sc = resolve_scene(scene)
        if options:
            if plan is not None:
                raise SceneError("simulate: pass either a plan or scene options, not both")
            sc = sc.with_options(**options)
        the_plan = sc.plan()
        if plan is not None and plan is not the_plan:
            raise SceneError(
                "simulate(scene, plan): the plan is not this scene's own plan "
                "(scene.plan()); pass the plan alone: simulate(plan)"
            )
    if lazy is None:
        lazy = (
            client is not None
            or the_plan.knobs["chunk"] is not None
            or the_plan.estimate.output_bytes > IN_PROCESS_BYTES
        )
    if lazy:
        arrays: dict[str, Any] = _lazy(the_plan, client)
    else:
        if client is not None:
            raise SceneError(
                "simulate: lazy=False computes in this process; it cannot use a client"
            )
        arrays = _in_process(the_plan)
    return _dataset(the_plan, arrays)
