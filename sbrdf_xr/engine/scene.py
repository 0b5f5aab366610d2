"""The :class:`Scene`: what to simulate.

Re-exported, with the scene files, from :mod:`sbrdf_xr.engine`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import InitVar, dataclass, field, replace
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from .. import catalog, geometry
from ..errors import CatalogError, SceneError, ValidationError, did_you_mean, renamed_fields
from ..kernels.warm import compiling_ahead
from ..materials.tables import validate_material
from ..units import check_plausible, to_unit
from .attitude_table import _scene_attitudes, _unit_vectors
from .effects import DEFAULT_EFFECTS, SCENE_EFFECTS, SCENE_OUTPUTS, SPECTRAL_OUTPUTS, scene_effects
from .knobs import KNOBS, PRESETS, apply_preset, check_knob
from .plan import Plan, compile_plan
from .sweep import GridGeometry, PairGeometry

if TYPE_CHECKING:
    from ..body.spacecraft import Spacecraft
    from ..observing.observation import Observation

__all__ = ["EFFECTS", "OUTPUTS", "PRESETS", "GridGeometry", "PairGeometry", "Scene"]

#: Outputs a scene may ask for.
OUTPUTS = tuple(SCENE_OUTPUTS)
#: Effects a scene may ask for (:data:`sbrdf_xr.engine.effects.EFFECTS` but those the
#: geometry brings, such as the Earth's shadow of an observation).
EFFECTS = SCENE_EFFECTS
_ = SPECTRAL_OUTPUTS  # re-exported


def _needs_to_earth(scene: Scene, effect: str) -> None:
    if not scene.is_grid and scene.observation is None and scene.to_earth is None:
        raise SceneError(
            f"to_earth: explicit geometry with {effect} needs body-frame to_earth vectors"
        )


def _needs_observation(scene: Scene, effect: str) -> None:
    if scene.observation is None:
        raise SceneError(
            f"effects: {effect} needs an observation (Scene(observation=...) or an "
            "[observation] table): its source comes from the ephemeris at the observation's "
            "times"
        )


#: What an effect may need from a scene (:attr:`sbrdf_xr.engine.effects.Effect.needs`),
#: and the check that the scene has it.
_NEEDS = {"to_earth": _needs_to_earth, "observation": _needs_observation}


#: The hottest facet temperature a scene accepts [K].
MAX_TEMPERATURE_K = 1e4


#: Scene fields with a unit: a Quantity (or a mapping of them per material) is converted.
_UNITS = {
    "phase_angles": "deg",
    "attitude_angle": "deg",
    "surface_tilt": "deg",
    "earth_range": "km",
    "earth_phase_angle": "deg",
    "temperature": "K",
    "earth_temperature": "K",
    "materials": "sr-1",  # a table holding a Quantity; a model (Dataset) is kept
}


def _in_units(scene: Scene) -> None:
    for name, unit in _UNITS.items():
        v = getattr(scene, name)
        if isinstance(v, Mapping):
            v = {m: to_unit(x, unit, f"{name}[{m!r}]") for m, x in v.items()}
        object.__setattr__(scene, name, to_unit(v, unit, name))
    for k in KNOBS:  # in the knob's unit (table_theta_step [degree], block_bytes [byte])
        object.__setattr__(scene, k, check_knob(k, getattr(scene, k)))


def _optional_array(v: ArrayLike | None) -> np.ndarray | None:
    return None if v is None else np.asarray(v)


@renamed_fields(earth_range_km="earth_range")
@dataclass(frozen=True)
class Scene:
    """A spacecraft, its materials, a geometry sweep, and what to compute.

    Parameters
    ----------
    spacecraft : sbrdf_xr.body.spacecraft.Spacecraft
        The body.
    materials : mapping of str to DataArray or Dataset, optional
        Material tables by name, or BRDF models (a model material of
        :mod:`sbrdf_xr.materials.models`, as a scene file's model file), which move to
        ``models``: a model is rendered to a table when the plan needs one, and evaluated
        exactly with ``evaluation="analytic"``.  Default: every material of the
        spacecraft, loaded from the catalog when first needed (:attr:`tables`), not by
        the constructor.
    attitudes : array_like, shape (n, 4), optional
        Attitudes (body -> reference frame, scalar-last unit quaternions).
    attitude : mapping, optional
        The attitudes as a scene file's ``[attitude]`` table instead (the same keys,
        read by the same :func:`~sbrdf_xr.engine.attitude_table.attitudes_from_table`):
        ``dict(kind="sweep", axis=[0, 0, 1], stop=360, step=1)``, ``kind="uniform"``
        (``n``, ``seed``), ``"euler"`` (``sequence``, ``angles``) or ``"quaternions"``;
        angles [degree] may be Quantities.  A sweep's angles become ``attitude_angle``.
    phase_angles : array_like, shape (m,), optional
        Phase angles [degree] of the observation plane (with ``attitudes``).
    bisector, plane_normal : array_like, shape (3,)
        Observation plane in the reference frame (default: bisector +x, plane xy).
    to_sun, to_observer : array_like, shape (n, 3), optional
        Explicit body-frame geometry pairs instead of a grid.
    observation : sbrdf_xr.observing.observe.Observation, optional
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
        ``float64`` or ``float32`` for the spectra.  Catalog tables (``materials`` not
        given) are loaded in this dtype too, so ``float32`` halves the memory they hold.
    merge : bool or None
        Merge facets sharing (normal, material); default: whenever allowed.
    shadow_method : {"exact", "sampled"}
        Self-shadowing by polygon clipping (area-exact) or by sub-facet ray sampling.
    shadow_density : int
        Sampled shadowing: samples per facet side.
    wavelength_stride, band_integration, table_theta_step, evaluation, kernel, block_bytes
        The other numerical knobs (:data:`sbrdf_xr.engine.knobs.KNOBS` says what each trades).
    surface_tilt : float or mapping of str to float
        Surface imperfections (paper 000 §5): standard deviation [degree] of each
        tangent component of a Gaussian tilt of the facet normals, for all facets or
        per material (:mod:`sbrdf_xr.body.imperfections`); 0, the default, is the perfect
        CAD facet.  ``tilt_nodes`` sets the quadrature.
    chunk : int, optional
        Geometries per block along the attitude (or geometry) dimension; default from
        ``block_bytes``.  Given explicitly, :func:`~sbrdf_xr.engine.run.simulate` always
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
    earth_range : float
        Distance from the spacecraft to the Earth's centre [km] (formerly
        ``earth_range_km``, accepted and read for one release with a
        :class:`~sbrdf_xr.errors.RenamedWarning`).
    earth_phase_angle : float
        Sun-Earth-spacecraft angle seen from the Earth's centre [degree] (0: the
        spacecraft sees a full Earth).
    temperature : float or mapping of str to float or "equilibrium"
        Facet temperature [K] of the ``thermal`` effect, one for all or per material, or
        ``"equilibrium"``: each facet's from radiative equilibrium at every geometry (the
        knob ``conductance``; :mod:`sbrdf_xr.engine.effects.thermal`).
    earth_temperature : float
        The Earth's brightness temperature [K] of the ``earth_thermal`` effect, 0-400
        (default 255 K, its effective temperature).
    models : mapping of str to Dataset, optional
        BRDF model parameters per material for ``evaluation="analytic"`` (default:
        the catalog entry ``<material>-model``); a material with a model needs no table
        for analytic evaluation.
    size_limit : float
        Factor on the limits of output size and work beyond which a plan is refused
        (:data:`sbrdf_xr.engine.plan.SIZE_LIMIT_BYTES`, :data:`sbrdf_xr.engine.plan.WORK_LIMIT`).
    name, description : str
        Labels stored in the output.

    Every number with a unit (the angles [degree], ``earth_range`` [km],
    ``temperature`` [K], the knobs with a unit, a material table's sBRDF [sr-1] given as a
    DataArray holding a Quantity) also takes an astropy Quantity, converted when the
    scene is made; one of another kind raises :class:`~sbrdf_xr.errors.UnitError` naming
    the field.

    Examples
    --------
    A unit cube of one Lambertian material at one attitude and two phase angles:

    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> scene = Scene(box, {"grey": grey}, attitudes=[[0, 0, 0, 1.0]], phase_angles=[0.0, 60.0])
    >>> scene.is_grid, scene.n_geometries
    (True, 2)
    >>> to_sun, to_observer = scene.body_vectors()
    >>> to_sun.shape, to_observer.round(4).tolist()
    ((1, 2, 3), [[[1.0, 0.0, 0.0], [0.866, -0.5, 0.0]]])
    >>> scene.plan().n_blocks
    1

    The attitudes as a scene file's ``[attitude]`` table, read by the same code:

    >>> swept = Scene(box, {"grey": grey}, attitude={"kind": "sweep", "stop": 90, "step": 30},
    ...               phase_angles=[0.0])
    >>> swept.attitude_angle.tolist(), swept.n_geometries
    ([0.0, 30.0, 60.0], 3)

    Knobs and presets give changed copies; explicit body-frame pairs replace the grid:

    >>> fast = scene.with_options(preset="fast")
    >>> fast.dtype, fast.method
    ('float32', 'linear')
    >>> pairs = Scene(box, {"grey": grey}, to_sun=[[1.0, 0, 0]], to_observer=[[0, 1.0, 0]])
    >>> pairs.is_grid, pairs.n_geometries
    (False, 1)
    >>> Scene(box, {"grey": grey}, to_sun=[[1.0, 0, 0]], to_observer=[[0, 1.0, 0]],
    ...       outputs=("colour",))
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.SceneError: outputs: unknown ['colour']; allowed: spacecraft_sbrdf, signal, ...
    """

    spacecraft: Spacecraft
    materials: Mapping[str, xr.DataArray | xr.Dataset] | None = None
    attitudes: ArrayLike | None = None
    phase_angles: ArrayLike | None = None
    bisector: tuple[float, float, float] = (1.0, 0.0, 0.0)
    plane_normal: tuple[float, float, float] = (0.0, 0.0, 1.0)
    to_sun: ArrayLike | None = None
    to_observer: ArrayLike | None = None
    observation: Observation | None = None
    attitude_angle: ArrayLike | None = None
    outputs: Sequence[str] = ("spacecraft_sbrdf", "signal", "brdf", "area")
    effects: Sequence[str] = DEFAULT_EFFECTS
    method: str = KNOBS["method"].default
    dtype: str = KNOBS["dtype"].default
    merge: bool | None = None
    shadow_method: str = KNOBS["shadow_method"].default
    shadow_density: int = KNOBS["shadow_density"].default
    wavelength_stride: int = KNOBS["wavelength_stride"].default
    band_integration: str = KNOBS["band_integration"].default
    table_theta_step: float | None = KNOBS["table_theta_step"].default
    evaluation: str = KNOBS["evaluation"].default
    kernel: str = KNOBS["kernel"].default
    tilt_nodes: int = KNOBS["tilt_nodes"].default
    surface_tilt: float | Mapping[str, float] = 0.0
    chunk: int | None = KNOBS["chunk"].default
    block_bytes: int = KNOBS["block_bytes"].default
    bands: Sequence[str] = ()
    band_extrapolate: str | None = None
    earth_direction: tuple[float, float, float] = (0.0, -1.0, 0.0)
    to_earth: ArrayLike | None = None
    earth_albedo: float = 0.3
    earth_range: float = 42164.0
    earth_phase_angle: float = 90.0
    earth_model: str = KNOBS["earth_model"].default
    conductance: str = KNOBS["conductance"].default
    temperature: float | Mapping[str, float] | str = 300.0
    earth_temperature: float = 255.0
    models: Mapping[str, xr.Dataset] | None = None
    size_limit: float = 1.0
    name: str = "scene"
    description: str = ""
    attitude: InitVar[Mapping[str, Any] | None] = None
    _cache: dict[str, Any] = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self, attitude: Mapping[str, Any] | None) -> None:
        if attitude is not None:  # a scene file's [attitude] table
            q, angles = _scene_attitudes(attitude, self.attitudes, self.attitude_angle)
            object.__setattr__(self, "attitudes", q)
            object.__setattr__(self, "attitude_angle", angles)
        _in_units(self)
        bad = [o for o in self.outputs if o not in OUTPUTS]
        if bad:
            raise SceneError(f"outputs: unknown {bad}; allowed: {', '.join(OUTPUTS)}")
        bad = [e for e in self.effects if e not in EFFECTS]
        if bad:
            raise SceneError(f"effects: unknown {bad}; allowed: {', '.join(EFFECTS)}")
        tilts = (
            self.surface_tilt.values()
            if isinstance(self.surface_tilt, Mapping)
            else [self.surface_tilt]
        )
        if any(
            isinstance(x, bool)
            or not isinstance(x, int | float)
            or not (np.isfinite(x) and 0 <= x <= 45)
            for x in tilts
        ):
            raise SceneError(
                f"surface_tilt: expected tilts in [0, 45] degree, got {self.surface_tilt!r}"
            )
        if not (
            isinstance(self.size_limit, int | float)
            and np.isfinite(self.size_limit)
            and self.size_limit > 0
        ):
            raise SceneError(f"size_limit: must be a positive factor, got {self.size_limit!r}")
        if "band_signal" in self.outputs and not self.bands:
            raise SceneError(
                "bands: the band_signal output needs at least one band (e.g. bands=('B', 'V'))"
            )
        if self.bands:
            from ..photometry import filters

            try:
                filters(list(self.bands))
            except ValidationError as exc:
                raise SceneError(f"bands: {exc}") from None
        if not 0.0 <= self.earth_albedo <= 1.0:
            raise SceneError(f"earth_albedo: must lie in [0, 1], got {self.earth_albedo}")
        if not self.earth_range > 6371.0:
            raise SceneError(
                f"earth_range: must exceed the Earth's radius (6371 km), got {self.earth_range}"
            )
        if not 0.0 <= self.earth_phase_angle <= 180.0:
            raise SceneError(
                f"earth_phase_angle: must lie in [0, 180] degree, got {self.earth_phase_angle}"
            )
        t = self.temperature
        temps = t.values() if isinstance(t, Mapping) else [] if t == "equilibrium" else [t]
        if any(
            not (isinstance(x, int | float | np.number) and 0 < x <= MAX_TEMPERATURE_K)
            for x in temps
        ):
            raise SceneError(
                f"temperature: must be positive kelvin, at most {MAX_TEMPERATURE_K:g} K (every "
                f"material has melted long before), or 'equilibrium'; got {t!r}"
            )
        if not 0.0 < self.earth_temperature <= 400.0:  # sources.EARTH_TEMPERATURE_MAX
            raise SceneError(
                f"earth_temperature: must lie in (0, 400] K, got {self.earth_temperature}"
            )
        if self.band_extrapolate not in (None, "zero", "constant"):
            raise SceneError(
                f"band_extrapolate: got {self.band_extrapolate!r}; allowed: 'zero', 'constant' "
                "(or leave it out to refuse bands beyond the wavelengths)"
            )
        check_plausible(self.earth_range, "range_km", "earth_range")
        for key in ("temperature", "surface_tilt"):
            value = getattr(self, key)
            have = getattr(self.spacecraft, "materials", None)
            if isinstance(value, Mapping) and have is not None:
                for m in value:
                    if m not in have:
                        raise SceneError(
                            f"{key}: {m!r} is not a material of the spacecraft "
                            f"{self.spacecraft.name!r}; {did_you_mean(m, have, 'its materials')}"
                        )
        grid = self.attitudes is not None or self.phase_angles is not None
        explicit = self.to_sun is not None or self.to_observer is not None
        observed = self.observation is not None
        if grid + explicit + observed != 1:
            raise SceneError(
                "geometry: give either attitudes and phase_angles (a grid), to_sun and "
                "to_observer (explicit pairs) or an observation, not several and not neither"
            )
        if observed:
            from ..observing.observe import Observation

            if not isinstance(self.observation, Observation):
                raise SceneError(
                    f"observation: expected a sbrdf_xr.observing.Observation, got "
                    f"{type(self.observation).__name__}"
                )
        elif grid:
            if self.attitudes is None or self.phase_angles is None:
                raise SceneError("geometry: a grid needs both attitudes and phase_angles")
            try:
                q = geometry.check_quaternions(self.attitudes)
                beta = np.atleast_1d(np.asarray(self.phase_angles, dtype=np.float64))
                if beta.size and not np.all((beta >= 0) & (beta <= 180)):
                    raise SceneError(
                        "phase_angles: must lie in [0, 180] degree, got "
                        f"{beta[~((beta >= 0) & (beta <= 180))][:5].tolist()}"
                    )
                # checked here, kept for the geometry (computed once per scene)
                plane = geometry.observation_plane(beta, self.bisector, self.plane_normal)
                self._cache["plane"] = (beta.copy(), plane)
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
        for effect in scene_effects(self.effects):
            for need in effect.needs:
                if need in _NEEDS:
                    _NEEDS[need](self, effect.name)
        if self.materials is not None:
            self._check_tables(self.materials)
            given = {m: v for m, v in self.materials.items() if isinstance(v, xr.Dataset)}
            if given:  # a model given as a material is the material's model
                tables = {m: v for m, v in self.materials.items() if m not in given}
                object.__setattr__(self, "materials", tables)
                object.__setattr__(self, "models", {**(self.models or {}), **given})

    def _check_tables(self, materials: Mapping[str, xr.DataArray | xr.Dataset]) -> None:
        from ..materials.models import model_parameters

        given_models = self.models or {}
        missing = [
            m for m in self.spacecraft.materials if m not in materials and m not in given_models
        ]
        if missing:
            raise SceneError(
                f"materials: no table for {missing} (nor a model); given: {sorted(materials)}"
            )
        for name, da in materials.items():
            try:
                if isinstance(da, xr.Dataset):
                    if name in given_models:
                        raise SceneError(
                            f"material {name!r}: a model in both materials and models; give it once"
                        )
                    model_parameters(da)
                else:
                    validate_material(da, check_values=True)
            except ValidationError as exc:
                raise SceneError(f"material {name!r}: {exc}") from None

    @cached_property
    def material_data(self) -> Mapping[str, xr.DataArray | xr.Dataset]:
        """What stands for each material, without rendering anything: its table (given, or
        the catalog's when ``materials`` is not given) or, lacking one, its BRDF model
        (given in ``materials`` or ``models``).

        Raises
        ------
        SceneError
            When a material of the spacecraft has neither (:attr:`tables`).
        """
        if self.materials is not None:
            out = dict(self.materials)
            models = self.models or {}
            out.update({m: models[m] for m in self.spacecraft.materials if m not in out})
            return out
        out = {}
        known = set(catalog.names("material"))
        # the tables to build as one batch, the engine's kernel compiling meanwhile
        try:
            loaded = catalog.load_materials(
                [m for m in self.spacecraft.materials if m in known],
                self.dtype,
                while_building=compiling_ahead,
            )
        except CatalogError:  # named below, material by material
            loaded = {}
        for m in self.spacecraft.materials:
            try:  # in the scene's precision: a float32 scene holds no float64 copy of its tables
                out[m] = loaded[m] if m in loaded else catalog.load(m, dtype=self.dtype)
            except CatalogError as exc:
                if m in (self.models or {}):
                    out[m] = (self.models or {})[m]
                    continue
                raise SceneError(
                    f"materials: not given, and the catalog has no table for a material of "
                    f"{self.spacecraft.name!r}: {exc}"
                ) from None
        self._check_tables({m: v for m, v in out.items() if isinstance(v, xr.DataArray)})
        return out

    @cached_property
    def tables(self) -> Mapping[str, xr.DataArray]:
        """The material tables by name: ``materials`` as given, or else every material of
        the spacecraft loaded from the catalog on first use (the constructor reads no file);
        a material given only as a BRDF model (in ``materials`` or ``models``) is rendered
        to a table here, on first use (:func:`sbrdf_xr.materials.models.render`).

        Raises
        ------
        SceneError
            When a material of the spacecraft is neither given nor in the catalog.
        """
        from ..materials.models import render
        from .spectral import TABLE_LIMIT_BYTES

        out: dict[str, xr.DataArray] = {}
        limit = self.size_limit * TABLE_LIMIT_BYTES
        for m, v in self.material_data.items():
            if not isinstance(v, xr.Dataset):
                out[m] = v
                continue
            try:
                out[m] = render(v, dtype=np.dtype(self.dtype), max_bytes=limit)
            except ValidationError as exc:
                raise SceneError(f"material {m!r}: {exc}") from None
        return out

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
        observed = None
        if self.observation is not None:
            from ..errors import ObservationError

            try:
                observed = self.observation.geometry()
            except ObservationError as exc:
                raise SceneError(f"observation: {exc}") from exc
        # the other sources of the effects asked for (their entries' geometry)
        sources: dict[str, np.ndarray] = {}
        for effect in scene_effects(self.effects):
            if effect.geometry is not None:
                sources.update(effect.geometry(self, observed))
        if observed is not None:
            return PairGeometry.from_observation(observed, sources)
        if self.is_grid:
            phase = np.asarray(self.phase_angles)
            kept = self._cache.get("plane")
            if kept is not None and np.array_equal(kept[0], phase):
                s, o = kept[1]
            else:  # the phase angles were changed in place since the scene was made
                s, o = geometry.observation_plane(phase, self.bisector, self.plane_normal)
            return GridGeometry(
                np.asarray(self.attitudes),
                phase,
                s,
                o,
                sources,
                _optional_array(self.attitude_angle),
            )
        return PairGeometry(np.asarray(self.to_sun), np.asarray(self.to_observer), sources)

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

    def earth_vectors(self, attitude_slice: slice | None = None) -> np.ndarray | None:
        """Unit vectors to the Earth in the body frame (shaped like :meth:`body_vectors`)."""
        if not self.is_grid:
            if self.to_earth is not None:
                return np.asarray(self.to_earth)[attitude_slice or slice(None)]
            return self.geometry.block(attitude_slice or slice(None)).sources.get("to_earth")
        att = np.asarray(self.attitudes)
        q = att if attitude_slice is None else att[attitude_slice]
        e = geometry.normalize(self.earth_direction, "earth_direction")
        e = np.broadcast_to(e, (len(np.asarray(self.phase_angles)), 3))
        return geometry.to_body_frame(q, e)

    @classmethod
    def knob_names(cls) -> tuple[str, ...]:
        """The numerical knobs, each a field of the scene (:data:`sbrdf_xr.engine.knobs.KNOBS`)."""
        return tuple(KNOBS)

    def with_options(self, **changes: Any) -> Scene:
        """A copy with some fields changed; ``preset=`` sets the knobs of a preset first."""
        if "preset" in changes:
            changes = apply_preset(changes.pop("preset"), changes)
        try:
            new = replace(self, **changes)
        except TypeError as exc:
            raise SceneError(f"with_options: {exc}") from None
        same = not {"materials", "spacecraft"} & set(changes) and (
            self.materials is not None or new.dtype == self.dtype
        )
        for loaded in ("material_data", "tables"):
            if loaded in self.__dict__ and same and "models" not in changes:
                new.__dict__[loaded] = self.__dict__[loaded]  # loaded once per scene family
        return new

    def plan(self) -> Plan:
        """The compiled :class:`~sbrdf_xr.engine.plan.Plan` of this scene (computed once, then
        cached)."""
        if "plan" not in self._cache:
            self._cache["plan"] = compile_plan(self)
        return self._cache["plan"]


# ----------------------------------------------------------- scene files


# --------------------------------------------------------- built-in scenes
