"""Scenes: what to simulate.

A :class:`Scene` holds a spacecraft, its materials, the geometry of a sweep, the
outputs and effects asked for and the value of every numerical knob
(:mod:`sbrdf_xr.knobs`).  :meth:`Scene.plan` compiles it into a
:class:`~sbrdf_xr.plan.Plan` that states every step that will run and every step
skipped, and why (DESIGN.md principle 3: simulate only the effects a scene calls
for).  A scene does no I/O and computes nothing in its constructor beyond checking
its inputs.

Geometry is either a grid of attitudes (quaternions, body -> reference frame) times
phase angles in an observation plane (paper 000 Figs. 12-13) (:class:`GridGeometry`),
or an explicit list of ``(to_sun, to_observer)`` unit-vector pairs in the body frame
(:class:`PairGeometry`).
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from . import geometry
from .effects import SCENE_OUTPUTS, SPECTRAL_OUTPUTS
from .errors import CatalogError, SceneError, ValidationError
from .knobs import KNOBS, PRESETS, apply_preset, check_knob
from .material import validate_material
from .plan import Plan, compile_plan
from .sweep import GridGeometry, PairGeometry

__all__ = ["EFFECTS", "OUTPUTS", "PRESETS", "GridGeometry", "PairGeometry", "Scene",
           "builtin_scene", "builtin_scenes", "load_scene"]

#: Outputs a scene may ask for.
OUTPUTS = tuple(SCENE_OUTPUTS)
#: Effects a scene may ask for (the Earth's shadow comes with an observation).
EFFECTS = ("sunlight", "shadowing", "earthshine", "thermal")
_ = SPECTRAL_OUTPUTS  # re-exported


_UNIT_TOL = 1e-6


def _unit_vectors(v: ArrayLike, name: str) -> np.ndarray:
    try:
        arr = np.asarray(v, dtype=np.float64)
    except (ValueError, TypeError) as exc:
        raise SceneError(f"{name}: expected n vectors of 3 numbers (shape (n, 3)); {exc}") from None
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise SceneError(f"{name}: expected shape (n, 3), got {arr.shape}")
    if arr.shape[0] == 0:
        raise SceneError(f"{name}: needs at least one vector, got none")
    if not np.all(np.isfinite(arr)):
        raise SceneError(f"{name}: contains NaN or infinite components")
    with np.errstate(over="ignore"):  # a huge component: length inf, refused below
        norm = np.linalg.norm(arr, axis=1)
    bad = np.flatnonzero(~(np.abs(norm - 1.0) <= _UNIT_TOL))
    if bad.size:
        raise SceneError(
            f"{name}: vector {bad[0]} {arr[bad[0]].tolist()} has length {norm[bad[0]]:.6g}; "
            f"directions must be unit vectors (|length - 1| <= {_UNIT_TOL})"
        )
    return arr / norm[:, None]


@dataclass(frozen=True)
class Scene:
    """A spacecraft, its materials, a geometry sweep, and what to compute.

    Parameters
    ----------
    spacecraft : sbrdf_xr.spacecraft.Spacecraft
        The body.
    materials : mapping of str to DataArray, optional
        Material tables by name; default: every material of the spacecraft loaded
        from the catalog.
    attitudes : array_like, shape (n, 4), optional
        Attitudes (body -> reference frame, scalar-last unit quaternions).
    phase_angles : array_like, shape (m,), optional
        Phase angles [degree] of the observation plane (with ``attitudes``).
    bisector, plane_normal : array_like, shape (3,)
        Observation plane in the reference frame (default: bisector +x, plane xy).
    to_sun, to_observer : array_like, shape (n, 3), optional
        Explicit body-frame geometry pairs instead of a grid.
    observation : sbrdf_xr.observe.Observation, optional
        A real pass (orbit, site, times, attitude law) instead of a grid or pairs: the
        cube gets a ``time`` dimension with the observation's geometry as coordinates,
        the Earth's shadow scales the sunlight, and earthshine (when asked) follows the
        Earth's distance and phase at every time.  Its geometry is computed when the
        scene is planned.
    attitude_angle : array_like, shape (n,), optional
        A label per attitude (for example the sweep angle [degree]).
    outputs : sequence of str
        Among :data:`OUTPUTS`.
    effects : sequence of str
        Among :data:`EFFECTS`; ``sunlight`` is always on.
    method : str
        Look-up method (``nearest``, ``linear``, ``cubic``).
    dtype : str
        ``float64`` or ``float32`` for the spectra.
    merge : bool or None
        Merge facets sharing (normal, material); default: whenever allowed.
    shadow_method : {"exact", "sampled"}
        Self-shadowing by polygon clipping (area-exact) or by sub-facet ray sampling.
    shadow_density : int
        Sampled shadowing: samples per facet side.
    wavelength_stride, band_integration, table_theta_step, evaluation, kernel, block_bytes
        The other numerical knobs (:data:`sbrdf_xr.knobs.KNOBS` says what each trades).
    surface_tilt : float or mapping of str to float
        Surface imperfections (paper 000 §5): standard deviation [degree] of each
        tangent component of a Gaussian tilt of the facet normals, for all facets or
        per material (:mod:`sbrdf_xr.imperfections`); 0, the default, is the perfect
        CAD facet.  ``tilt_nodes`` sets the quadrature.
    chunk : int, optional
        Geometries per block along the attitude (or geometry) dimension; default from
        ``block_bytes``.  Given explicitly, :func:`~sbrdf_xr.simulate.simulate` always
        returns a Dask-backed cube with that chunking.
    bands : sequence of str
        Photometric bands of the ``band_signal`` output (see
        :func:`sbrdf_xr.photometry.filters`).
    band_extrapolate : {None, "zero", "constant"}
        How spectra continue past the materials' wavelengths inside a band
        (:func:`sbrdf_xr.photometry.band_weights`); by default a band the
        wavelengths do not cover is an error.
    earth_direction : array_like, shape (3,)
        Direction from the spacecraft to the Earth in the reference frame (grids),
        for the ``earthshine`` effect.
    to_earth : array_like, shape (n, 3), optional
        The same in the body frame, one per explicit geometry pair.
    earth_albedo : float
        Bond albedo of the Lambertian Earth [1].
    earth_range_km : float
        Distance from the spacecraft to the Earth's centre [km].
    earth_phase_angle : float
        Sun-Earth-spacecraft angle seen from the Earth's centre [degree] (0: the
        spacecraft sees a full Earth).
    temperature : float or mapping of str to float
        Facet temperature [K] of the ``thermal`` effect, one for all or per material.
    models : mapping of str to Dataset, optional
        BRDF model parameters per material for ``evaluation="analytic"`` (default:
        the catalog entry ``<material>-model``).
    size_limit : float
        Factor on the limits of output size and work beyond which a plan is refused
        (:data:`sbrdf_xr.plan.SIZE_LIMIT_BYTES`, :data:`sbrdf_xr.plan.WORK_LIMIT`).
    name, description : str
        Labels stored in the output.
    """

    spacecraft: Any
    materials: Mapping[str, xr.DataArray] | None = None
    attitudes: ArrayLike | None = None
    phase_angles: ArrayLike | None = None
    bisector: tuple[float, float, float] = (1.0, 0.0, 0.0)
    plane_normal: tuple[float, float, float] = (0.0, 0.0, 1.0)
    to_sun: ArrayLike | None = None
    to_observer: ArrayLike | None = None
    observation: Any = None
    attitude_angle: ArrayLike | None = None
    outputs: Sequence[str] = ("spacecraft_sbrdf", "signal", "brdf", "area")
    effects: Sequence[str] = ("sunlight",)
    method: str = "linear"
    dtype: str = "float64"
    merge: bool | None = None
    shadow_method: str = "exact"
    shadow_density: int = 4
    wavelength_stride: int = 1
    band_integration: str = "auto"
    table_theta_step: float | None = None
    evaluation: str = "table"
    kernel: str = "fused"
    tilt_nodes: int = 5
    surface_tilt: float | Mapping[str, float] = 0.0
    chunk: int | None = None
    block_bytes: int = 32 * 2**20
    bands: Sequence[str] = ()
    band_extrapolate: str | None = None
    earth_direction: tuple[float, float, float] = (0.0, -1.0, 0.0)
    to_earth: ArrayLike | None = None
    earth_albedo: float = 0.3
    earth_range_km: float = 42164.0
    earth_phase_angle: float = 90.0
    temperature: float | Mapping[str, float] = 300.0
    models: Mapping[str, xr.Dataset] | None = None
    size_limit: float = 1.0
    name: str = "scene"
    description: str = ""
    _cache: dict[str, Any] = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        bad = [o for o in self.outputs if o not in OUTPUTS]
        if bad:
            raise SceneError(f"outputs: unknown {bad}; allowed: {', '.join(OUTPUTS)}")
        bad = [e for e in self.effects if e not in EFFECTS]
        if bad:
            raise SceneError(f"effects: unknown {bad}; allowed: {', '.join(EFFECTS)}")
        for k in KNOBS:
            check_knob(k, getattr(self, k))
        tilts = self.surface_tilt.values() if isinstance(self.surface_tilt, Mapping) else [self.surface_tilt]
        if any(isinstance(x, bool) or not isinstance(x, int | float) or not (np.isfinite(x) and 0 <= x <= 45)
               for x in tilts):
            raise SceneError(f"surface_tilt: expected tilts in [0, 45] degree, got {self.surface_tilt!r}")
        if not (isinstance(self.size_limit, int | float) and np.isfinite(self.size_limit)
                and self.size_limit > 0):
            raise SceneError(f"size_limit: must be a positive factor, got {self.size_limit!r}")
        if "band_signal" in self.outputs and not self.bands:
            raise SceneError("bands: the band_signal output needs at least one band (e.g. bands=('B', 'V'))")
        if self.bands:
            from .photometry import filters

            try:
                filters(list(self.bands))
            except ValidationError as exc:
                raise SceneError(f"bands: {exc}") from None
        if not 0.0 <= self.earth_albedo <= 1.0:
            raise SceneError(f"earth_albedo: must lie in [0, 1], got {self.earth_albedo}")
        if not self.earth_range_km > 6371.0:
            raise SceneError(f"earth_range_km: must exceed the Earth's radius (6371 km), got {self.earth_range_km}")
        if not 0.0 <= self.earth_phase_angle <= 180.0:
            raise SceneError(f"earth_phase_angle: must lie in [0, 180] degree, got {self.earth_phase_angle}")
        temps = self.temperature.values() if isinstance(self.temperature, Mapping) else [self.temperature]
        if any(not (np.isfinite(x) and x > 0) for x in temps):
            raise SceneError(f"temperature: must be positive kelvin, got {self.temperature}")
        grid = self.attitudes is not None or self.phase_angles is not None
        explicit = self.to_sun is not None or self.to_observer is not None
        observed = self.observation is not None
        if grid + explicit + observed != 1:
            raise SceneError(
                "geometry: give either attitudes and phase_angles (a grid), to_sun and "
                "to_observer (explicit pairs) or an observation, not several and not neither"
            )
        if observed:
            from .observe import Observation

            if not isinstance(self.observation, Observation):
                raise SceneError(f"observation: expected a sbrdf_xr.observe.Observation, got "
                                 f"{type(self.observation).__name__}")
        elif grid:
            if self.attitudes is None or self.phase_angles is None:
                raise SceneError("geometry: a grid needs both attitudes and phase_angles")
            try:
                q = geometry.check_quaternions(self.attitudes)
                beta = np.atleast_1d(np.asarray(self.phase_angles, dtype=np.float64))
                geometry.observation_plane(beta, self.bisector, self.plane_normal)
            except ValidationError as exc:
                raise SceneError(str(exc)) from None
            if q.ndim != 2:
                raise SceneError(f"attitudes: expected shape (n, 4), got {q.shape}")
            object.__setattr__(self, "attitudes", q)
            object.__setattr__(self, "phase_angles", beta)
        else:
            if self.to_sun is None or self.to_observer is None:
                raise SceneError("geometry: explicit pairs need both to_sun and to_observer")
            s = _unit_vectors(self.to_sun, "to_sun")
            o = _unit_vectors(self.to_observer, "to_observer")
            if s.shape != o.shape:
                raise SceneError(f"to_sun {s.shape} and to_observer {o.shape} differ in shape")
            object.__setattr__(self, "to_sun", s)
            object.__setattr__(self, "to_observer", o)
            if self.to_earth is not None:
                e = _unit_vectors(self.to_earth, "to_earth")
                if e.shape != s.shape:
                    raise SceneError(f"to_earth {e.shape} and to_sun {s.shape} differ in shape")
                object.__setattr__(self, "to_earth", e)
            elif "earthshine" in self.effects:
                raise SceneError("to_earth: explicit geometry with earthshine needs body-frame to_earth vectors")
        if self.materials is None:
            from . import catalog

            object.__setattr__(self, "materials", {m: catalog.load(m) for m in self.spacecraft.materials})
        missing = [m for m in self.spacecraft.materials if m not in self.materials]
        if missing:
            raise SceneError(f"materials: no table for {missing}; given: {sorted(self.materials)}")
        for name, da in self.materials.items():
            try:
                validate_material(da, check_values=True)
            except ValidationError as exc:
                raise SceneError(f"material {name!r}: {exc}") from None

    # ----------------------------------------------------------- geometry
    @property
    def is_grid(self) -> bool:
        """True for an attitude x phase-angle grid, False for explicit pairs."""
        return self.attitudes is not None

    @property
    def n_geometries(self) -> int:
        """Number of (Sun, observer) geometries of the sweep."""
        return self.geometry.n_geometries

    @cached_property
    def geometry(self) -> GridGeometry | PairGeometry:
        """The sweep's geometry (:class:`GridGeometry` or :class:`PairGeometry`)."""
        if self.observation is not None:
            from .errors import ObservationError

            try:
                g = self.observation.geometry()
            except ObservationError as exc:
                raise SceneError(f"observation: {exc}") from exc
            return PairGeometry.from_observation(g, "earthshine" in self.effects, self.earth_albedo)
        if self.is_grid:
            s, o = geometry.observation_plane(self.phase_angles, self.bisector, self.plane_normal)
            e = None
            if "earthshine" in self.effects:
                e = geometry.normalize(self.earth_direction, "earth_direction")
                e = np.broadcast_to(e, (len(self.phase_angles), 3)).copy()
            return GridGeometry(self.attitudes, self.phase_angles, s, o, e, self.attitude_angle)
        return PairGeometry(self.to_sun, self.to_observer, self.to_earth)

    def body_vectors(self, attitude_slice: slice | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Sun and observer unit vectors in the body frame.

        Returns
        -------
        to_sun, to_observer : ndarray
            Shape ``(n_attitude, n_phase, 3)`` for a grid (optionally for a slice of
            attitudes) or ``(n_geometry, 3)`` for explicit pairs.
        """
        b = self.geometry.block(attitude_slice or slice(None))
        return b.to_sun.reshape(*b.lead_shape, 3), b.to_observer.reshape(*b.lead_shape, 3)

    def earth_vectors(self, attitude_slice: slice | None = None) -> np.ndarray:
        """Unit vectors to the Earth in the body frame (shaped like :meth:`body_vectors`)."""
        if not self.is_grid:
            return self.geometry.block(attitude_slice or slice(None)).to_earth
        q = self.attitudes if attitude_slice is None else self.attitudes[attitude_slice]
        e = geometry.normalize(self.earth_direction, "earth_direction")
        e = np.broadcast_to(e, (len(self.phase_angles), 3))
        return geometry.to_body_frame(q, e)

    @classmethod
    def knob_names(cls) -> tuple[str, ...]:
        """The numerical knobs, each a field of the scene (:data:`sbrdf_xr.knobs.KNOBS`)."""
        return tuple(KNOBS)

    def with_options(self, **changes: Any) -> Scene:
        """A copy with some fields changed; ``preset=`` sets the knobs of a preset first."""
        if "preset" in changes:
            changes = apply_preset(changes.pop("preset"), changes)
        try:
            return replace(self, **changes)
        except TypeError as exc:
            raise SceneError(f"with_options: {exc}") from None

    def plan(self) -> Plan:
        """The compiled :class:`~sbrdf_xr.plan.Plan` of this scene (computed once, then cached)."""
        if "plan" not in self._cache:
            self._cache["plan"] = compile_plan(self)
        return self._cache["plan"]


# ----------------------------------------------------------- scene files

_SCENE_KEYS = {
    "name": str, "description": str, "spacecraft": str, "materials": dict,
    "attitude": dict, "phase_angles": list, "bisector": list, "plane_normal": list,
    "geometry": dict, "outputs": list, "effects": list, "method": str, "dtype": str,
    "merge": bool, "shadow_method": str, "shadow_density": int, "chunk": int,
    "wavelength_stride": int, "band_integration": str, "table_theta_step": (int, float),
    "evaluation": str, "kernel": str, "block_bytes": int, "size_limit": (int, float),
    "tilt_nodes": int, "surface_tilt": (int, float, dict), "observation": dict, "bands": list, "band_extrapolate": str,
    "earth_direction": list, "earth_albedo": (int, float), "earth_range_km": (int, float),
    "earth_phase_angle": (int, float), "temperature": (int, float, dict),
}
_ATTITUDE_KEYS = {"kind": str, "axis": list, "start": (int, float), "stop": (int, float),
                  "step": (int, float), "initial_axis": list, "initial_angle": (int, float),
                  "n": int, "seed": int, "sequence": str, "angles": list, "quaternions": list}


def _check_keys(table: Any, allowed: Mapping[str, Any], where: str) -> None:
    if not isinstance(table, Mapping):
        raise SceneError(f"{where}: expected a table of keys, got {type(table).__name__}")
    for k, v in table.items():
        if k not in allowed:
            raise SceneError(f"{where}: unknown key {k!r}; allowed: {', '.join(sorted(allowed))}")
        types = allowed[k]
        if not isinstance(v, types) or (isinstance(v, bool) and types in (int, (int, float))):
            names = " or ".join(t.__name__ for t in (types if isinstance(types, tuple) else (types,)))
            raise SceneError(f"{where}: key {k!r} has type {type(v).__name__} ({_show(v)}); "
                             f"expected {names}")


#: Most attitudes or geometry pairs a scene file may list or generate.
MAX_SCENE_COUNT = 10_000_000
#: Largest magnitude of a direction's component in a scene file (its length must not overflow).
_MAX_COMPONENT = 1e100
#: Largest shadow-sampling density a scene file may ask for (sub-facet samples per side).
MAX_SHADOW_DENSITY = 64


def _show(v: Any) -> str:
    text = repr(v)
    return text if len(text) <= 60 else text[:57] + "..."


def _is_number(x: Any) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool)


def _number(v: Any, where: str) -> float:
    """A finite number from a scene file."""
    if not _is_number(v):
        raise SceneError(f"{where}: expected a number, got {_show(v)} ({type(v).__name__})")
    try:
        x = float(v)
    except OverflowError:
        raise SceneError(f"{where}: {_show(v)} is too large") from None
    if not np.isfinite(x):
        raise SceneError(f"{where}: must be finite, got {x}")
    return x


def _numbers(v: Any, where: str, *, allow_empty: bool = False) -> np.ndarray:
    """A flat list of finite numbers from a scene file."""
    if not isinstance(v, list):
        raise SceneError(f"{where}: expected a list of numbers, got {_show(v)}")
    if not v and not allow_empty:
        raise SceneError(f"{where}: the list is empty; give at least one value")
    if len(v) > MAX_SCENE_COUNT:
        raise SceneError(f"{where}: {len(v)} values; at most {MAX_SCENE_COUNT} are allowed")
    return np.array([_number(x, f"{where}[{i}]") for i, x in enumerate(v)], dtype=np.float64)


def _rows(v: Any, width: int, where: str) -> np.ndarray:
    """A non-empty list of rows of ``width`` finite numbers (vectors, quaternions)."""
    if not isinstance(v, list) or not v:
        raise SceneError(f"{where}: expected a non-empty list of [{', '.join(['x'] * width)}] rows, "
                         f"got {_show(v)}")
    if len(v) > MAX_SCENE_COUNT:
        raise SceneError(f"{where}: {len(v)} rows; at most {MAX_SCENE_COUNT} are allowed")
    out = np.empty((len(v), width))
    for i, row in enumerate(v):
        if not isinstance(row, list) or len(row) != width:
            raise SceneError(f"{where}[{i}]: expected {width} numbers, got {_show(row)}")
        out[i] = [_number(x, f"{where}[{i}][{j}]") for j, x in enumerate(row)]
    return out


def _vector(v: Any, where: str) -> tuple[float, float, float]:
    if not isinstance(v, list) or len(v) != 3:
        raise SceneError(f"{where}: expected a vector of 3 numbers, got {_show(v)}")
    x = tuple(_number(c, f"{where}[{i}]") for i, c in enumerate(v))
    if not any(x):
        raise SceneError(f"{where}: the zero vector has no direction")
    if max(map(abs, x)) > _MAX_COMPONENT:
        raise SceneError(f"{where}: components must not exceed {_MAX_COMPONENT:g} in magnitude, got {list(x)}")
    return x  # type: ignore[return-value]


def _strings(v: Any, where: str, *, allow_empty: bool = True) -> tuple[str, ...]:
    if not isinstance(v, list) or not all(isinstance(x, str) for x in v):
        raise SceneError(f"{where}: expected a list of strings, got {_show(v)}")
    if not v and not allow_empty:
        raise SceneError(f"{where}: the list is empty; give at least one")
    return tuple(v)


def _count(v: Any, where: str) -> int:
    if not isinstance(v, int) or isinstance(v, bool) or not 1 <= v <= MAX_SCENE_COUNT:
        raise SceneError(f"{where}: expected an integer from 1 to {MAX_SCENE_COUNT}, got {_show(v)}")
    return int(v)


def _attitudes_from_table(t: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray | None]:
    _check_keys(t, _ATTITUDE_KEYS, "[attitude]")
    kind = t.get("kind", "sweep")
    try:
        if kind == "sweep":
            if "stop" not in t:
                raise SceneError("[attitude]: a sweep needs 'stop' (and optionally 'start' and 'step') [degree]")
            start = _number(t.get("start", 0.0), "[attitude] start")
            stop = _number(t["stop"], "[attitude] stop")
            step = _number(t.get("step", 1.0), "[attitude] step")
            if step == 0:
                raise SceneError("[attitude] step: must not be 0")
            n = int(np.ceil((stop - start) / step))
            if n < 1:
                raise SceneError(f"[attitude]: a sweep from {start:g} to {stop:g} (excluded) in steps of "
                                 f"{step:g} degree has no attitude; stop must lie beyond start in the "
                                 "direction of step")
            if n > MAX_SCENE_COUNT:
                raise SceneError(f"[attitude]: the sweep has {n} attitudes; at most {MAX_SCENE_COUNT} are allowed")
            angles = np.arange(start, stop, step)
            initial = None
            if "initial_axis" in t:
                initial = geometry.axis_rotation(_vector(t["initial_axis"], "[attitude] initial_axis"),
                                                 _number(t.get("initial_angle", 0.0), "[attitude] initial_angle"))
            axis = _vector(t.get("axis", [0, 0, 1]), "[attitude] axis")
            return geometry.rotation_sweep(axis, angles, initial), angles
        if kind == "uniform":
            if "n" not in t:
                raise SceneError("[attitude]: kind 'uniform' needs 'n' (the number of attitudes)")
            seed = t.get("seed", 0)
            if not 0 <= seed < 2**63:
                raise SceneError(f"[attitude] seed: expected an integer from 0 to 2**63 - 1, got {seed}")
            return geometry.uniform_attitudes(_count(t["n"], "[attitude] n"), seed), None
        if kind == "euler":
            if "sequence" not in t or "angles" not in t:
                raise SceneError("[attitude]: kind 'euler' needs 'sequence' (e.g. 'zyx') and 'angles' [degree]")
            seq, ang = t["sequence"], t["angles"]
            if ang and all(isinstance(a, list) for a in ang):
                angles = _rows(ang, len(seq), "[attitude] angles")
            else:
                angles = _numbers(ang, "[attitude] angles")
            return geometry.euler_attitudes(seq, angles), None
        if kind == "quaternions":
            if "quaternions" not in t:
                raise SceneError("[attitude]: kind 'quaternions' needs 'quaternions' (rows of x, y, z, w)")
            return geometry.check_quaternions(_rows(t["quaternions"], 4, "[attitude] quaternions")), None
    except SceneError:
        raise
    except (ValidationError, ValueError, TypeError) as exc:
        raise SceneError(f"[attitude]: {exc}") from None
    raise SceneError(f"[attitude]: unknown kind {kind!r}; allowed: sweep, uniform, euler, quaternions")


def scene_from_dict(d: Mapping[str, Any], base_dir: str | Path | None = None) -> Scene:
    """Build a scene from the contents of a scene file (see :func:`load_scene`); relative
    file names in it (an ``[observation]``'s quaternion series) are taken from ``base_dir``.

    Raises
    ------
    SceneError
        For every key that is unknown, of the wrong type, out of its domain, empty where
        something is needed (``phase_angles``, ``outputs``), or larger than
        :data:`MAX_SCENE_COUNT`; :class:`~sbrdf_xr.errors.CatalogError` for catalog names
        that do not exist.
    """
    _check_keys(d, _SCENE_KEYS, "scene")
    from . import catalog
    from .spacecraft import Spacecraft

    kw: dict[str, Any] = {k: d[k] for k in ("name", "description", "method", "dtype", "merge",
                                               "band_extrapolate") if k in d}
    # the other numerical knobs (checked by the Scene against the knob table)
    kw.update({k: d[k] for k in KNOBS if k in d and k not in kw and k not in ("chunk", "shadow_density")})
    if "size_limit" in d:
        kw["size_limit"] = _number(d["size_limit"], "size_limit")
    if "surface_tilt" in d:
        st = d["surface_tilt"]
        kw["surface_tilt"] = ({str(m): _number(x, f"surface_tilt.{m}") for m, x in st.items()}
                              if isinstance(st, Mapping) else _number(st, "surface_tilt"))
    for k in ("earth_albedo", "earth_range_km", "earth_phase_angle"):
        if k in d:
            kw[k] = _number(d[k], k)
    if "chunk" in d:
        kw["chunk"] = _count(d["chunk"], "chunk")
    if "shadow_density" in d:
        sd = d["shadow_density"]
        if not 1 <= sd <= MAX_SHADOW_DENSITY:
            raise SceneError(f"shadow_density: expected an integer from 1 to {MAX_SHADOW_DENSITY}, got {sd}")
        kw["shadow_density"] = sd
    if "temperature" in d:
        t = d["temperature"]
        if isinstance(t, Mapping):
            kw["temperature"] = {str(m): _number(x, f"temperature.{m}") for m, x in t.items()}
        else:
            kw["temperature"] = _number(t, "temperature")
    if "outputs" in d:
        kw["outputs"] = _strings(d["outputs"], "outputs", allow_empty=False)
    for k in ("effects", "bands"):
        if k in d:
            kw[k] = _strings(d[k], k)
    for k in ("bisector", "plane_normal", "earth_direction"):
        if k in d:
            kw[k] = _vector(d[k], k)
    if "geometry" in d:
        g = d["geometry"]
        _check_keys(g, {"to_sun": list, "to_observer": list, "to_earth": list}, "[geometry]")
        for k in ("to_sun", "to_observer"):
            if k not in g:
                raise SceneError(f"[geometry]: key {k!r} is required (rows of 3 numbers)")
            kw[k] = _rows(g[k], 3, f"[geometry] {k}")
        if "to_earth" in g:
            kw["to_earth"] = _rows(g["to_earth"], 3, "[geometry] to_earth")
    if "observation" in d:
        from .observe import observation_from_dict

        if "attitude" in d or "geometry" in d or "phase_angles" in d:
            raise SceneError("scene: an [observation] gives the geometry; leave out [attitude], "
                             "[geometry] and phase_angles")
        try:
            kw["observation"] = observation_from_dict(d["observation"], base_dir)
        except (ValidationError, CatalogError) as exc:
            raise SceneError(f"[observation]: {exc}") from exc
    if "attitude" in d:
        if "geometry" in d:
            raise SceneError("scene: give either an [attitude] table (with phase_angles) or a "
                             "[geometry] table, not both")
        if "phase_angles" not in d:
            raise SceneError("scene: an [attitude] table needs 'phase_angles' [degree]")
        kw["attitudes"], angles = _attitudes_from_table(d["attitude"])
        if angles is not None:
            kw["attitude_angle"] = angles
        kw["phase_angles"] = _numbers(d["phase_angles"], "phase_angles")
    elif "phase_angles" in d:
        raise SceneError("scene: 'phase_angles' needs an [attitude] table")
    # Catalog entries are loaded last, once every cheap check has passed.
    sc_name = d.get("spacecraft")
    if sc_name is None:
        raise SceneError("scene: key 'spacecraft' is required (a catalog name)")
    sc = catalog.load(sc_name)
    if not isinstance(sc, Spacecraft):
        raise SceneError(f"spacecraft: catalog entry {sc_name!r} is not a spacecraft")
    materials = None
    if "materials" in d:
        materials = {}
        for mat, entry in d["materials"].items():
            if not isinstance(entry, str):
                raise SceneError(f"[materials]: {mat!r} must name a catalog entry (a string)")
            table = catalog.load(entry)
            if not isinstance(table, xr.DataArray):
                raise SceneError(f"[materials]: {mat!r} = {entry!r} is a {type(table).__name__} "
                                 "entry, not a material table")
            materials[mat] = table
    try:
        return Scene(sc, materials=materials, **kw)
    except SceneError:
        raise
    except (ValidationError, ValueError, TypeError) as exc:  # a check deeper in the package
        raise SceneError(f"scene: {exc}") from None


def load_scene(path: str | Path) -> Scene:
    """Load a scene from a TOML file.

    Example file::

        name = "my-rotation"
        spacecraft = "canx1"              # a catalog entry
        phase_angles = [10.0]             # degree
        outputs = ["spacecraft_sbrdf", "signal", "brdf", "area"]
        effects = ["sunlight"]
        method = "linear"

        [attitude]                        # or [geometry] with to_sun / to_observer lists
        kind = "sweep"                    # sweep | uniform | euler | quaternions
        axis = [0, 0, -1]
        start = 0
        stop = 360
        step = 1
        initial_axis = [0, 0, 1]
        initial_angle = 25

        [materials]                       # optional: material name -> catalog entry
        "white-paint-a276" = "white-paint-a276"

    Unknown keys and wrong types raise :class:`~sbrdf_xr.errors.SceneError`.
    """
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise SceneError(f"scene file {path}: cannot be read ({exc.strerror or exc})") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise SceneError(f"scene file {path}: not UTF-8 text (byte 0x{raw[exc.start]:02x} at offset "
                         f"{exc.start}); TOML files are UTF-8") from None
    try:
        d = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path}: invalid TOML: {exc}") from None
    except RecursionError:
        raise SceneError(f"{path}: invalid TOML: nested too deeply") from None
    return scene_from_dict(d, path.parent)


# --------------------------------------------------------- built-in scenes


def _canx1_plusx_specular() -> Scene:
    from .spacecraft import canx1

    return Scene(
        canx1(),
        attitudes=geometry.axis_rotation([0, 0, 1], [0.0]),
        phase_angles=[5.0, 30.0, 60.0, 90.0],
        outputs=("spacecraft_sbrdf", "signal", "brdf", "area", "per_material"),
        name="canx1-plusx-specular",
        description="CanX-1 +X side at specular geometry in the xy-plane, beta = 5, 30, 60, 90 deg "
        "(paper 000 section 4, Fig. 12)",
    )


def _canx1_rotation() -> Scene:
    from .spacecraft import canx1

    angles = np.arange(360.0)
    return Scene(
        canx1(),
        attitudes=geometry.rotation_sweep([0, 0, -1], angles, geometry.axis_rotation([0, 0, 1], 25.0)),
        attitude_angle=angles,
        phase_angles=[10.0],
        outputs=("spacecraft_sbrdf", "signal", "brdf", "area", "per_material"),
        name="canx1-rotation",
        description="CanX-1 initially rotated 25 deg about +z, then 360 steps of 1 deg about -z; "
        "v_i and v_r 5 deg either side of +x (beta = 10 deg) (paper 000 section 4, Fig. 13)",
    )


def _canx1_pass() -> Scene:
    from .observe import canx1_pass
    from .spacecraft import canx1

    return Scene(
        canx1(),
        observation=canx1_pass(),
        outputs=("spacecraft_sbrdf", "signal", "brdf", "area", "band_signal"),
        bands=("V", "R", "I"),
        name="canx1-pass",
        description="CanX-1 model on the shipped example elements over Mont Megantic, "
        "2024-03-17 01:20-01:25 UTC at 1 s, spinning; leaves the Earth's shadow in the window",
    )


_BUILTIN = {"canx1-plusx-specular": _canx1_plusx_specular, "canx1-rotation": _canx1_rotation,
            "canx1-pass": _canx1_pass}


def builtin_scenes() -> list[str]:
    """Names of the built-in scenes."""
    return list(_BUILTIN)


def builtin_scene(name: str) -> Scene:
    """A built-in scene by name (see :func:`builtin_scenes`)."""
    try:
        return _BUILTIN[name]()
    except KeyError:
        raise SceneError(f"unknown scene {name!r}; built-in scenes: {', '.join(_BUILTIN)}") from None


def resolve_scene(spec: str | Path | Scene) -> Scene:
    """A scene from a Scene, a built-in name or a TOML file path."""
    if isinstance(spec, Scene):
        return spec
    if not isinstance(spec, str | Path):
        raise SceneError(f"scene: expected a Scene, a built-in scene name or a TOML file path, "
                         f"got {type(spec).__name__}")
    if str(spec) in _BUILTIN:
        return builtin_scene(str(spec))
    if "\0" in str(spec):
        raise SceneError(f"unknown scene {str(spec)!r}: a name or path cannot contain a NUL character")
    path = Path(spec)
    if path.suffix == ".toml" or path.exists():
        if path.is_dir():
            raise SceneError(f"scene file {path} is a directory")
        if not path.exists():
            raise SceneError(f"scene file {path} does not exist")
        return load_scene(path)
    raise SceneError(f"unknown scene {str(spec)!r}; built-in scenes: {', '.join(_BUILTIN)}, or a .toml file")
