"""The geometry of a sweep: where the Sun and the observer are, in the body frame.

A scene's geometry is one of

* :class:`GridGeometry`: attitudes (body -> reference quaternions) times phase angles
  in an observation plane (paper 000 Figs. 12-13);
* :class:`PairGeometry`: explicit ``(to_sun, to_observer)`` unit-vector pairs in the
  body frame, one per geometry, or per time of an observation (with the sunlit
  fraction of the Earth's shadow and the observation's coordinates).

Both hand the engine blocks of body-frame directions (:meth:`block`), with the other
sources' directions and scales that the effects put in their ``sources``
(:attr:`sbrdf_xr.engine.effects.Effect.geometry`), and the cube its coordinates
(:meth:`coords`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.spatial.transform import Rotation

from .. import geometry
from .._names import ATTITUDE, GEOMETRY, PHASE_ANGLE, VECTOR, attrs
from .effects.base import BlockInputs

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["QUATERNION_COMPONENTS", "GridGeometry", "PairGeometry"]

#: Component names of the attitude quaternions (scalar last).
QUATERNION_COMPONENTS = ("x", "y", "z", "w")


@dataclass(frozen=True)
class GridGeometry:
    """Attitudes x phase angles in an observation plane (paper 000 Figs. 12-13).

    Sun and observer directions lie in the reference-frame plane of ``bisector`` and
    ``plane_normal``, ``phase_angle / 2`` either side of the bisector; each attitude
    (body -> reference quaternion) turns them into the body frame.

    Examples
    --------
    Three attitudes (quarter turns about +z) at two phase angles in the xy-plane:

    >>> import numpy as np
    >>> from sbrdf_xr.geometry import axis_rotation, observation_plane
    >>> from sbrdf_xr.engine.sweep import GridGeometry
    >>> to_sun, to_observer = observation_plane([10.0, 90.0])
    >>> grid = GridGeometry(axis_rotation([0, 0, 1], [0.0, 90.0, 180.0]), np.array([10.0, 90.0]),
    ...                     to_sun, to_observer, {"to_moon": to_sun[::-1]})
    >>> grid.dims, grid.shape, grid.describe()
    (('attitude', 'phase_angle'), (3, 2), '3 attitudes x 2 phase angles = 6 geometries')
    >>> block = grid.block(slice(1, 2))  # the second attitude, in the body frame
    >>> block.lead_shape, np.round(block.to_sun[1], 6) + 0.0
    ((1, 2), array([ 0.707107, -0.707107,  0.      ]))
    >>> np.round(block.sources["to_moon"][0], 6) + 0.0  # turned like the Sun
    array([ 0.707107, -0.707107,  0.      ])
    >>> sorted(grid.coords())
    ['attitude', 'component', 'phase_angle', 'quaternion', 'to_observer', 'to_sun']
    """

    attitudes: np.ndarray  #: (n, 4) scalar-last quaternions
    phase_angles: np.ndarray  #: (P,) [degree]
    sun_ref: np.ndarray  #: (P, 3)
    obs_ref: np.ndarray  #: (P, 3)
    #: Other sources per phase angle: (P, 3) reference-frame directions, (P,) scales.
    sources: Mapping[str, np.ndarray] = field(default_factory=dict)
    attitude_angle: np.ndarray | None = None
    sun_scale: None = None

    @property
    def dims(self) -> tuple[str, str]:
        return (ATTITUDE, PHASE_ANGLE)

    @property
    def shape(self) -> tuple[int, int]:
        return (len(self.attitudes), len(self.phase_angles))

    @property
    def n_lead(self) -> int:
        return len(self.attitudes)

    @property
    def n_geometries(self) -> int:
        return len(self.attitudes) * len(self.phase_angles)

    @property
    def attrs(self) -> dict[str, Any]:
        return {}

    def describe(self) -> str:
        return (
            f"{self.n_lead} attitudes x {len(self.phase_angles)} phase angles = "
            f"{self.n_geometries} geometries"
        )

    def block(self, sl: slice) -> BlockInputs:
        """Body-frame directions of the attitudes in ``sl`` (flattened to (n * P, 3))."""
        q = self.attitudes[sl]  # unit quaternions, checked by the Scene
        p = len(self.phase_angles)
        # v_body = R^T v for every attitude, as row vectors: v^T R, written out per
        # reference direction (a stacked matmul of 3 x 3 matrices costs twice as much)
        rot = Rotation.from_quat(q).as_matrix() if len(q) else np.zeros((0, 3, 3))
        r0, r1, r2 = rot[:, 0, None, :], rot[:, 1, None, :], rot[:, 2, None, :]

        def body(ref: np.ndarray) -> np.ndarray:
            v = ref[None, :, :, None]  # (1, P, 3, 1)
            return (v[:, :, 0] * r0 + v[:, :, 1] * r1 + v[:, :, 2] * r2).reshape(-1, 3)

        s, o = body(self.sun_ref), body(self.obs_ref)
        extra = {
            k: body(v) if v.ndim == 2 else np.broadcast_to(v, (len(q), p)).reshape(-1)
            for k, v in self.sources.items()
        }
        return BlockInputs(s, o, None, (len(q), p), extra)

    def coords(self, directions: Mapping[str, Any] | None = None) -> dict[str, Any]:
        """Coordinates of a cube over this geometry.

        ``directions``: the body-frame ``to_sun`` and ``to_observer``, shaped
        ``(attitude, phase_angle, 3)``, made elsewhere (a lazy cube's, block by block with
        its outputs) instead of computed here for every attitude at once.
        """
        if directions is None:
            b = self.block(slice(None))
            s, o = b.to_sun.reshape(*self.shape, 3), b.to_observer.reshape(*self.shape, 3)
        else:
            s, o = directions["to_sun"], directions["to_observer"]
        c: dict[str, Any] = {
            ATTITUDE: (ATTITUDE, np.arange(self.n_lead), attrs("attitude")),
            PHASE_ANGLE: (PHASE_ANGLE, np.asarray(self.phase_angles), attrs(PHASE_ANGLE)),
            "quaternion": ((ATTITUDE, "component"), self.attitudes, attrs("quaternion")),
            "component": ("component", list(QUATERNION_COMPONENTS), attrs("component")),
            "to_sun": ((ATTITUDE, PHASE_ANGLE, VECTOR), s, attrs("to_sun")),
            "to_observer": ((ATTITUDE, PHASE_ANGLE, VECTOR), o, attrs("to_observer")),
        }
        if self.attitude_angle is not None:
            c["attitude_angle"] = (
                ATTITUDE,
                np.asarray(self.attitude_angle, dtype=np.float64),
                attrs("attitude_angle"),
            )
        return c


@dataclass(frozen=True)
class PairGeometry:
    """Explicit ``(to_sun, to_observer)`` pairs in the body frame, one per geometry.

    ``sources`` are the other sources' body-frame directions (n, 3) and scales (n,);
    ``dim`` names the dimension (``geometry``, or ``time`` for an observation);
    ``sun_scale`` is the sunlit fraction of the solar disc per geometry (the Earth's
    shadow), or None; ``extra_coords`` are further coordinates along ``dim``.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.engine.sweep import PairGeometry
    >>> pairs = PairGeometry(np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]),
    ...                      np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]))
    >>> pairs.dims, pairs.shape, pairs.describe()
    (('geometry',), (2,), '2 explicit (to_sun, to_observer) pairs')
    >>> dims, phase, attrs = pairs.coords()["phase_angle"]
    >>> dims, np.round(phase, 6), attrs["units"]
    ('geometry', array([ 0., 90.]), 'degree')
    """

    to_sun: np.ndarray
    to_observer: np.ndarray
    sources: Mapping[str, np.ndarray] = field(default_factory=dict)
    sun_scale: np.ndarray | None = None
    dim: str = GEOMETRY
    index: Any = None
    extra_coords: Mapping[str, Any] = field(default_factory=dict)
    extra_attrs: Mapping[str, Any] = field(default_factory=dict)

    @property
    def dims(self) -> tuple[str]:
        return (self.dim,)

    @property
    def shape(self) -> tuple[int]:
        return (len(self.to_sun),)

    @property
    def n_lead(self) -> int:
        return len(self.to_sun)

    @property
    def n_geometries(self) -> int:
        return len(self.to_sun)

    @property
    def attrs(self) -> dict[str, Any]:
        return dict(self.extra_attrs)

    def describe(self) -> str:
        if self.dim == GEOMETRY:
            return f"{self.n_lead} explicit (to_sun, to_observer) pairs"
        what = self.extra_attrs.get("observation", "an observation")
        return (
            f"{self.n_lead} times of {what} ({self.extra_attrs.get('orbit_name', '')} from "
            f"{self.extra_attrs.get('site_name', 'a site')})"
        )

    def block(self, sl: slice) -> BlockInputs:
        sc = None if self.sun_scale is None else self.sun_scale[sl]
        s = self.to_sun[sl]
        extra = {k: v[sl] for k, v in self.sources.items()}
        return BlockInputs(s, self.to_observer[sl], sc, (s.shape[0],), extra)

    def coords(self) -> dict[str, Any]:
        """Coordinates of a cube over these geometries (an observation adds its own)."""
        d = self.dim
        c: dict[str, Any] = {
            d: (d, np.arange(self.n_lead), attrs(GEOMETRY)) if self.index is None else self.index,
            PHASE_ANGLE: (
                d,
                geometry.phase_angle(self.to_sun, self.to_observer),
                attrs(PHASE_ANGLE),
            ),
            "to_sun": ((d, VECTOR), self.to_sun, attrs("to_sun")),
            "to_observer": ((d, VECTOR), self.to_observer, attrs("to_observer")),
        }
        c.update(self.extra_coords)
        return c

    @classmethod
    def from_observation(cls, g: xr.Dataset, sources: Mapping[str, np.ndarray]) -> PairGeometry:
        """The geometry of an observation (:meth:`sbrdf_xr.observing.observe.Observation.geometry`):
        a ``time`` dimension, the sunlit fraction as the Sun's scale, and the other
        sources per time (from the effects that ask for them)."""
        dim = "time"
        extra = {str(k): g[k].variable for k in g.coords if k not in ("xyz", "component")}
        extra["quaternion"] = g["quaternion"].variable
        extra["component"] = g["component"].variable
        return cls(
            np.ascontiguousarray(g["to_sun"].values),
            np.ascontiguousarray(g["to_observer"].values),
            dict(sources),
            np.asarray(g["sunlit_fraction"].values, dtype=np.float64),
            dim,
            g[dim].variable,
            extra,
            dict(g.attrs),
        )
