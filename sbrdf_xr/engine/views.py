"""What the engine's stages see of a scene and of a plan, and the facet terms they share.

The scene (:class:`~sbrdf_xr.engine.scene.Scene`) compiles itself into a plan
(:class:`~sbrdf_xr.engine.plan.Plan`), whose stages (:mod:`~sbrdf_xr.engine.spectral`,
:mod:`~sbrdf_xr.engine.stages`, :mod:`~sbrdf_xr.engine.articulation`, the effects of
:mod:`~sbrdf_xr.engine.effects`) and the fingerprint (:mod:`~sbrdf_xr.engine.fingerprint`)
read both.  So that the imports flow one way (scene above plan above its stages), the
stages do not import the scene or the plan, not even for their types: they read them
through the protocols here, :class:`SceneView` and :class:`PlanView`, which the
:class:`~sbrdf_xr.engine.scene.Scene` and the :class:`~sbrdf_xr.engine.plan.Plan` meet
(checked by mypy where a scene or a plan is passed).  The facet terms (:class:`Terms`),
built by the plan and grouped by the articulation, live here too.  Members whose types
are defined above this module (the geometry of the sweep, the articulation) are typed
``Any``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, Any, ClassVar, Protocol

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from ..kernels import PackedTables, normal_rows

if TYPE_CHECKING:
    from ..body.spacecraft import Spacecraft
    from ..kernels.anisotropic import AnisotropicTable
    from ..observing.observation import Observation

__all__ = ["PlanView", "SceneView", "Terms"]


@dataclass(frozen=True)
class Terms:
    """The facet terms a plan evaluates, sorted by material.

    Attributes
    ----------
    normal : ndarray, shape (T, 3)
        Unit normals [1].
    area : ndarray, shape (T,)
        Areas [m2] (summed over merged facets).
    material : ndarray of int, shape (T,)
        Index into :attr:`~sbrdf_xr.engine.plan.Plan.materials`.
    facet : ndarray of int, shape (T,)
        The facet of each term when facets are not merged (per-facet effects), else
        the first facet of the term.
    n_facets : ndarray of int, shape (T,)
        Facets merged into each term.
    tangent : ndarray, shape (T, 3), optional
        Unit tangents [1] (anisotropic materials; :mod:`sbrdf_xr.geometry.anisotropy`).
    part : ndarray of int, shape (T,), optional
        The group of each term on a body with parts: 0 for the bus, ``k + 1`` for part
        ``k`` (:mod:`sbrdf_xr.engine.articulation`).

    Examples
    --------
    A unit cube turned by 0 and 45 deg about z, Sun and observer in the xy plane: its
    12 triangles merge into 6 faces, of which only +x and -y are ever lit and seen.

    >>> import trimesh
    >>> from sbrdf_xr import Scene, geometry, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> turns = geometry.axis_rotation([0, 0, 1], [0.0, 45.0])  # two attitudes about z
    >>> scene = Scene(box, {"grey": grey}, attitudes=turns, phase_angles=[0.0, 60.0])
    >>> terms = scene.plan().terms
    >>> terms.size
    2
    >>> terms.normal.tolist(), terms.area.tolist(), terms.n_facets.tolist()
    ([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0]], [1.0, 1.0], [2, 2])
    """

    normal: np.ndarray
    area: np.ndarray
    material: np.ndarray
    facet: np.ndarray
    n_facets: np.ndarray
    tangent: np.ndarray | None = None
    part: np.ndarray | None = None

    @property
    def size(self) -> int:
        """Number of terms."""
        return int(self.area.size)

    @cached_property
    def normal_rows(self) -> np.ndarray:
        """Each term's row among the distinct normals (:func:`~sbrdf_xr.kernels.sums.normal_rows`),
        found once per plan rather than once per block."""
        return normal_rows(self.normal)


class SceneView(Protocol):
    """What the plan, its stages, the effects and the fingerprint read of a scene: the
    fields and properties of :class:`~sbrdf_xr.engine.scene.Scene` (see there for their
    meaning and units), read-only.

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.engine.views import SceneView
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> x = [[1.0, 0.0, 0.0]]
    >>> scene: SceneView = Scene(box, {"grey": grey}, to_sun=x, to_observer=x)
    >>> scene.bands, sorted(scene.material_data)
    ((), ['grey'])
    """

    __dataclass_fields__: ClassVar[dict[str, Any]]

    @property
    def spacecraft(self) -> Spacecraft: ...

    @property
    def materials(self) -> Mapping[str, xr.DataArray | xr.Dataset] | None: ...

    @property
    def attitudes(self) -> ArrayLike | None: ...

    @property
    def phase_angles(self) -> ArrayLike | None: ...

    @property
    def bisector(self) -> tuple[float, float, float]: ...

    @property
    def plane_normal(self) -> tuple[float, float, float]: ...

    @property
    def to_sun(self) -> ArrayLike | None: ...

    @property
    def to_observer(self) -> ArrayLike | None: ...

    @property
    def observation(self) -> Observation | None: ...

    @property
    def attitude_angle(self) -> ArrayLike | None: ...

    @property
    def outputs(self) -> Sequence[str]: ...

    @property
    def effects(self) -> Sequence[str]: ...

    @property
    def method(self) -> str: ...

    @property
    def dtype(self) -> str: ...

    @property
    def merge(self) -> bool | None: ...

    @property
    def shadow_method(self) -> str: ...

    @property
    def shadow_density(self) -> int: ...

    @property
    def wavelength_stride(self) -> int: ...

    @property
    def band_integration(self) -> str: ...

    @property
    def table_theta_step(self) -> float | None: ...

    @property
    def evaluation(self) -> str: ...

    @property
    def kernel(self) -> str: ...

    @property
    def tilt_nodes(self) -> int: ...

    @property
    def surface_tilt(self) -> float | Mapping[str, float]: ...

    @property
    def chunk(self) -> int | None: ...

    @property
    def block_bytes(self) -> int: ...

    @property
    def bands(self) -> Sequence[str]: ...

    @property
    def band_extrapolate(self) -> str | None: ...

    @property
    def earth_direction(self) -> tuple[float, float, float]: ...

    @property
    def to_earth(self) -> ArrayLike | None: ...

    @property
    def earth_albedo(self) -> float: ...

    @property
    def earth_range(self) -> float: ...

    @property
    def earth_phase_angle(self) -> float: ...

    @property
    def earth_model(self) -> str: ...

    @property
    def temperature(self) -> float | str | Mapping[str, float]: ...

    @property
    def earth_temperature(self) -> float: ...

    @property
    def models(self) -> Mapping[str, xr.Dataset] | None: ...

    @property
    def size_limit(self) -> float: ...

    @property
    def name(self) -> str: ...

    @property
    def description(self) -> str: ...

    @property
    def material_data(self) -> Mapping[str, xr.DataArray | xr.Dataset]: ...

    @property
    def tables(self) -> Mapping[str, xr.DataArray]: ...

    @property
    def is_grid(self) -> bool: ...

    @property
    def n_geometries(self) -> int: ...

    @property
    def geometry(self) -> Any: ...  # sbrdf_xr.engine.sweep.GridGeometry or PairGeometry

    def body_vectors(self, attitude_slice: slice | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Sun and observer directions in the body frame."""

    def earth_vectors(self, attitude_slice: slice | None = None) -> np.ndarray | None:
        """Earth directions in the body frame, if the scene has an Earth."""

    def knob_names(self) -> tuple[str, ...]:
        """The names of the scene's knobs."""

    def with_options(self, **changes: Any) -> SceneView:
        """The scene with some fields changed."""

    def plan(self) -> PlanView:
        """The compiled plan of the scene."""


class PlanView(Protocol):
    """What the stages and the effects read of a plan: the fields and properties of
    :class:`~sbrdf_xr.engine.plan.Plan` (see there for their meaning), read-only;
    ``plan.<effect>`` says whether an effect runs.

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.engine.views import PlanView
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> scene = Scene(box, {"grey": grey}, attitudes=[[0, 0, 0, 1.0]], phase_angles=[0])
    >>> plan: PlanView = scene.plan()
    >>> plan.materials, plan.shadowing
    (('grey',), False)
    """

    __dataclass_fields__: ClassVar[dict[str, Any]]

    @property
    def name(self) -> str: ...

    @property
    def spacecraft(self) -> Spacecraft: ...

    @property
    def geometry(self) -> Any: ...  # sbrdf_xr.engine.sweep.GridGeometry or PairGeometry

    @property
    def cache(self) -> dict[str, Any]: ...

    @property
    def terms(self) -> Terms: ...

    @property
    def materials(self) -> tuple[str, ...]: ...

    @property
    def tables(self) -> PackedTables: ...

    @property
    def wavelength(self) -> np.ndarray: ...

    @property
    def bands(self) -> tuple[str, ...]: ...

    @property
    def band_weights(self) -> np.ndarray | None: ...

    @property
    def pre_integrated(self) -> bool: ...

    @property
    def merged(self) -> bool: ...

    @property
    def effects(self) -> tuple[str, ...]: ...

    @property
    def effect_params(self) -> Mapping[str, Mapping[str, Any]]: ...

    @property
    def models(self) -> Mapping[int, tuple[Any, Mapping[str, Any]]]: ...

    @property
    def knobs(self) -> Mapping[str, Any]: ...

    @property
    def chunk(self) -> int: ...

    @property
    def steps(self) -> tuple[tuple[str, str], ...]: ...

    @property
    def anisotropic(self) -> Mapping[int, AnisotropicTable]: ...

    @property
    def articulation(self) -> Any: ...  # sbrdf_xr.engine.articulation.Articulation or None

    @property
    def active_effects(self) -> tuple[Any, ...]: ...  # sbrdf_xr.engine.effects.Effect

    @property
    def output_names(self) -> tuple[str, ...]: ...

    @property
    def n_lead(self) -> int: ...

    def table(
        self, m: int
    ) -> tuple[
        np.ndarray, tuple[np.ndarray, np.ndarray, np.ndarray], tuple[bool, bool, bool], float
    ]:
        """Table ``m`` unpacked: values, grids, zero edges, normal-incidence blend [degree]."""

    def __getattr__(self, name: str) -> bool:
        """Whether the effect ``name`` runs."""
