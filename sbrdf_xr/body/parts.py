"""Articulated parts of a spacecraft: facets that turn about a hinge, and how they point.

A :class:`~sbrdf_xr.body.spacecraft.Spacecraft` is a bus plus named :class:`Part` s.  A part
is a set of facets of the mesh, a hinge (a unit axis ``a`` and a point ``p`` in the bus
frame [m]) and a pointing law giving its hinge angle ``theta`` at every geometry.  The
part's facets are drawn at ``theta = 0`` in the mesh; at angle ``theta`` a point ``x`` of
the part is at ``p + R(theta) (x - p)`` and a direction ``n`` is ``R(theta) n``, with
``R`` the right-handed rotation about ``a`` (Rodrigues' formula, :func:`hinge_rotation`).

Pointing laws
-------------
:class:`Fixed`
    A constant angle (0 by default): the part is rigid with the bus.
:class:`SunTracking`
    The angle that brings the part's normal ``n`` closest to the Sun ``s`` (bus frame):
    ``n(theta) . s = n_par . s + |n_perp| |s_perp| cos(theta - theta*)`` with
    ``theta* = atan2(s . (a x n), s . n_perp)`` (``n_perp``, ``s_perp``: the parts
    perpendicular to ``a``), so ``theta*`` maximises it (:func:`tracking_angle`); with
    limits ``[lo, hi]`` the angle is the limit nearest to ``theta*`` when ``theta*`` is
    outside them (the cosine falls monotonically with the angular distance).  A Sun
    along the axis leaves every angle equally good: ``theta = 0`` (then clipped).
:class:`AngleSeries`
    A given angle per geometry of the sweep, in the order of the cube's flattened
    geometry dimensions.

Angles are in degrees at the door and radians inside.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import MeshError, ValidationError, renamed_attributes
from ..units import to_unit

__all__ = [
    "ARTICULATION_LAWS",
    "PART_KEYS",
    "AngleSeries",
    "Fixed",
    "Part",
    "SunTracking",
    "check_parts",
    "hinge_rotation",
    "part_from_spec",
    "tracking_angle",
]


def hinge_rotation(axis: ArrayLike, angle: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrices about a unit axis by angles [radian] (Rodrigues' formula).

    ``R = I + sin(t) K + (1 - cos(t)) K**2`` with ``K`` the cross-product matrix of the
    axis; right-handed.

    Parameters
    ----------
    axis : array_like, shape (3,)
        Unit axis [1].
    angle : array_like, shape (G,)
        Angles [radian].

    Returns
    -------
    ndarray, shape (G, 3, 3)

    Examples
    --------
    >>> R = hinge_rotation([0.0, 0.0, 1.0], [np.pi / 2])
    >>> np.round(R[0] @ [1.0, 0.0, 0.0], 12) + 0.0  # x turns to y about z
    array([0., 1., 0.])
    """
    a = np.asarray(axis, dtype=np.float64)
    t = np.atleast_1d(np.asarray(to_unit(angle, "rad", "angle"), dtype=np.float64))
    K = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    s, c = np.sin(t)[:, None, None], np.cos(t)[:, None, None]
    return np.eye(3) + s * K + (1.0 - c) * (K @ K)


def tracking_angle(
    axis: ArrayLike,
    normal: ArrayLike,
    to_sun: ArrayLike,
    limits: tuple[float, float] | None = None,
) -> NDArray[np.float64]:
    """Hinge angle [radian] bringing ``normal`` closest to the Sun (module docstring).

    Parameters
    ----------
    axis, normal : array_like, shape (3,)
        Unit hinge axis and the part's unit normal at angle 0, bus frame [1].
    to_sun : array_like, shape (G, 3)
        Unit directions to the Sun, bus frame [1].
    limits : (float, float), optional
        Allowed angles ``lo <= theta <= hi`` [radian].

    Returns
    -------
    ndarray, shape (G,)
        In ``(-pi, pi]``, or within ``limits``.

    Examples
    --------
    A panel facing +x, hinged about z, with the Sun at 30 deg in the xy plane:

    >>> s = [[np.cos(np.radians(30)), np.sin(np.radians(30)), 0.0]]
    >>> np.degrees(tracking_angle([0, 0, 1.0], [1.0, 0, 0], s)).round(9).tolist()
    [30.0]
    >>> lim = (0.0, np.radians(10))
    >>> np.degrees(tracking_angle([0, 0, 1.0], [1.0, 0, 0], s, lim)).round(9).tolist()
    [10.0]
    """
    a = np.asarray(axis, dtype=np.float64)
    n = np.asarray(normal, dtype=np.float64)
    s = np.asarray(to_sun, dtype=np.float64).reshape(-1, 3)
    n_perp = n - (n @ a) * a
    y = s @ np.cross(a, n)
    x = s @ n_perp
    theta = np.where((x == 0.0) & (y == 0.0), 0.0, np.arctan2(y, x))
    if limits is None:
        return theta
    lo, hi = (float(to_unit(v, "rad", "limits")) for v in limits)
    inside = (theta >= lo) & (theta <= hi)
    # angular distance to either limit, the shorter way round the circle
    d_lo = np.abs(np.angle(np.exp(1j * (theta - lo))))
    d_hi = np.abs(np.angle(np.exp(1j * (theta - hi))))
    return np.where(inside, theta, np.where(d_lo <= d_hi, lo, hi))


# ------------------------------------------------------------------------------- laws


@dataclass(frozen=True)
class Fixed:
    """A constant hinge angle [degree]: the part does not move.

    Examples
    --------
    >>> Fixed(15.0).angles(np.zeros((2, 3)), np.arange(2), None).round(6).tolist()
    [0.261799, 0.261799]
    """

    angle: float = 0.0

    moving = False

    def angles(self, to_sun: np.ndarray, index: np.ndarray, part: Part | None) -> np.ndarray:
        """Angle [radian] at every geometry (``index``: their place in the sweep)."""
        return np.full(len(index), np.radians(self.angle))


@dataclass(frozen=True)
class SunTracking:
    """Turn about the hinge to bring the part's normal closest to the Sun.

    Parameters
    ----------
    normal : array_like, shape (3,), optional
        The part's normal at angle 0, bus frame [1]; default: the area-weighted mean of
        its facets' front normals.
    limits : (float, float), optional
        Allowed angles ``lo <= theta <= hi`` [degree], ``hi - lo < 360``.

    Examples
    --------
    >>> SunTracking(limits=(-90.0, 90.0)).limits
    (-90.0, 90.0)
    """

    normal: tuple[float, float, float] | None = None
    limits: tuple[float, float] | None = None

    moving = True

    def __post_init__(self) -> None:
        if self.limits is not None:
            # rounded: a Quantity in radians gives the same limits as the degrees it means
            lo, hi = (round(float(to_unit(v, "degree", "limits")), 9) for v in self.limits)
            if not (np.isfinite(lo) and np.isfinite(hi) and lo <= hi):
                raise ValidationError(
                    f"limits: got {self.limits!r}; they exclude every angle (expected "
                    "finite lo <= hi [degree])"
                )
            object.__setattr__(self, "limits", (lo, hi))
        if self.normal is not None:
            n = np.asarray(self.normal, dtype=np.float64)
            if n.shape != (3,) or not np.all(np.isfinite(n)) or not np.linalg.norm(n) > 0:
                raise ValidationError(f"normal: expected a non-zero 3-vector, got {self.normal!r}")
            object.__setattr__(self, "normal", tuple((n / np.linalg.norm(n)).tolist()))

    def angles(self, to_sun: np.ndarray, index: np.ndarray, part: Part | None) -> np.ndarray:
        """Angle [radian] at every geometry."""
        assert part is not None
        lim = None if self.limits is None else tuple(np.radians(self.limits))
        return tracking_angle(part.axis, part.normal, to_sun, lim)


@dataclass(frozen=True)
class AngleSeries:
    """A given hinge angle [degree] per geometry of the sweep (flattened in cube order).

    Examples
    --------
    >>> AngleSeries([0.0, 90.0]).angles(np.zeros((1, 3)), np.array([1]), None).tolist()
    [1.5707963267948966]
    """

    values: tuple[float, ...] = field(default=())

    moving = True

    def __post_init__(self) -> None:
        v = np.asarray(to_unit(self.values, "degree", "angles"), dtype=np.float64).reshape(-1)
        if v.size == 0 or not np.all(np.isfinite(v)):
            raise ValidationError(
                f"angles: expected a non-empty series of finite angles [degree], got {v!r}"
            )
        object.__setattr__(self, "values", tuple(v.tolist()))

    def angles(self, to_sun: np.ndarray, index: np.ndarray, part: Part | None) -> np.ndarray:
        """Angle [radian] at every geometry."""
        v = np.radians(np.asarray(self.values))
        if index.size and index.max() >= v.size:
            raise ValidationError(
                f"angles: the series has {v.size} angles, the sweep at least "
                f"{int(index.max()) + 1} geometries (one angle per geometry)"
            )
        return v[index]


#: Pointing laws by the name scene files use.
ARTICULATION_LAWS: dict[str, type] = {
    "fixed": Fixed,
    "sun-tracking": SunTracking,
    "series": AngleSeries,
}


@dataclass(frozen=True, eq=False)
class Part:
    """A named set of facets turning about a hinge with a pointing law.

    Parameters
    ----------
    name : str
        Name of the part.
    facets : array_like of int
        Indices of its facets in the mesh.
    axis : array_like, shape (3,)
        Hinge axis in the bus frame (normalised here) [1].
    point : array_like, shape (3,)
        A point of the hinge line in the bus frame [m].
    law : Fixed, SunTracking or AngleSeries
        How the hinge angle is set at every geometry.

    Examples
    --------
    >>> p = Part("array", [0, 1], axis=[0, 2.0, 0], point=[0, 0, 1.0], law=SunTracking())
    >>> p.axis.tolist(), p.moving
    ([0.0, 1.0, 0.0], True)
    """

    name: str
    facets: Any
    axis: Any = (0.0, 0.0, 1.0)
    point: Any = (0.0, 0.0, 0.0)
    law: Any = field(default_factory=Fixed)
    normal: Any = None  #: unit normal at angle 0 (set by the spacecraft)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise ValidationError(f"part name: expected a non-empty string, got {self.name!r}")
        f = np.unique(np.asarray(self.facets, dtype=np.int64).reshape(-1))
        if f.size == 0:
            raise ValidationError(f"part {self.name!r}: names no facets")
        a = np.asarray(self.axis, dtype=np.float64).reshape(-1)
        if a.shape != (3,) or not np.all(np.isfinite(a)) or not np.linalg.norm(a) > 0:
            raise ValidationError(
                f"part {self.name!r}: hinge axis {self.axis!r} has zero length or is not a "
                "finite 3-vector"
            )
        p = np.asarray(to_unit(self.point, "m", "point"), dtype=np.float64).reshape(-1)
        if p.shape != (3,) or not np.all(np.isfinite(p)):
            raise ValidationError(
                f"part {self.name!r}: hinge point {self.point!r} is not a finite 3-vector [m]"
            )
        if not isinstance(self.law, Fixed | SunTracking | AngleSeries):
            raise ValidationError(
                f"part {self.name!r}: law {self.law!r}; "
                f"expected one of {sorted(ARTICULATION_LAWS)} "
                "(Fixed, SunTracking, AngleSeries)"
            )
        object.__setattr__(self, "facets", f)
        object.__setattr__(self, "axis", a / np.linalg.norm(a))
        object.__setattr__(self, "point", p)

    @property
    def moving(self) -> bool:
        """Whether its angle can change from geometry to geometry."""
        return bool(self.law.moving)


def check_parts(
    parts: Iterable[Part] | Mapping[str, Part] | None,
    n_facets: int,
    normals: np.ndarray,
    areas: np.ndarray,
) -> tuple[Part, ...]:
    """Validate parts against a mesh and give each its normal at angle 0.

    A part's facets must exist and belong to no other part; a sun-tracking part without
    a stated normal gets the area-weighted mean of its facets' normals, which must not
    vanish or lie along the hinge.

    Examples
    --------
    >>> n = np.array([[1.0, 0, 0], [1.0, 0, 0], [0, 1.0, 0]])
    >>> parts = check_parts([Part("a", [0, 1], law=SunTracking())], 3, n, np.ones(3))
    >>> parts[0].normal.tolist()
    [1.0, 0.0, 0.0]
    >>> check_parts([Part("a", [0, 1]), Part("b", [1, 2])], 3, n, np.ones(3))
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.MeshError: part 'b': facets [1] belong to part 'a' already
    """
    if parts is None:
        return ()
    items = list(parts.values()) if isinstance(parts, Mapping) else list(parts)
    owner = np.full(n_facets, -1, dtype=np.int64)
    out = []
    for k, p in enumerate(items):
        if not isinstance(p, Part):
            raise ValidationError(f"parts: expected Part objects, got {type(p).__name__}")
        if p.name in (q.name for q in items[:k]):
            raise ValidationError(f"parts: the name {p.name!r} is used twice")
        bad = p.facets[(p.facets < 0) | (p.facets >= n_facets)]
        if bad.size:
            raise MeshError(
                f"part {p.name!r}: facets {bad[:5].tolist()} do not exist (the mesh has "
                f"{n_facets} facets, 0..{n_facets - 1})"
            )
        taken = p.facets[owner[p.facets] >= 0]
        if taken.size:
            other = items[int(owner[taken[0]])].name
            raise MeshError(
                f"part {p.name!r}: facets {taken[:5].tolist()} belong to part {other!r} already"
            )
        owner[p.facets] = k
        normal = p.normal
        if normal is None:
            law_n = getattr(p.law, "normal", None)
            normal = law_n if law_n is not None else (areas[p.facets] @ normals[p.facets])
        normal = np.asarray(normal, dtype=np.float64)
        along = np.linalg.norm(normal - (normal @ p.axis) * p.axis)
        if (
            p.moving
            and isinstance(p.law, SunTracking)
            and not along > 1e-9 * np.linalg.norm(normal)
        ):
            raise MeshError(
                f"part {p.name!r}: its normal {normal.round(6).tolist()} is zero or along the "
                "hinge axis, so no angle brings it nearer the Sun; give SunTracking(normal=...)"
            )
        unit = normal / np.linalg.norm(normal) if np.linalg.norm(normal) > 0 else normal
        q = Part(p.name, p.facets, p.axis, p.point, p.law, unit)
        out.append(q)
    return tuple(out)


#: Keys of a part in a scene file's ``[[spacecraft.parts]]`` table, and their meaning.
PART_KEYS: dict[str, str] = {
    "name": "the part's name (required)",
    "facets": "its facets: indices into the mesh as loaded",
    "materials": "or its facets by front material: every facet of these materials",
    "axis": "hinge axis in the bus frame [1], default [0, 0, 1]",
    "point": "a point of the hinge line in the bus frame [m], default [0, 0, 0]",
    "law": '"fixed", "sun-tracking" or "series", default "fixed"',
    "angle": "fixed: the hinge angle [degree], default 0",
    "limits": "sun-tracking: allowed angles [lo, hi] [degree]",
    "normal": "sun-tracking: the part's normal at angle 0, default its facets' mean",
    "angles": "series: one angle per geometry of the sweep [degree]",
}


def part_from_spec(spec: Mapping[str, Any], facet_material: np.ndarray) -> Part:
    """A :class:`Part` from a scene file's table (keys: :data:`PART_KEYS`).

    Examples
    --------
    >>> spec = {"name": "array", "materials": ["cell"], "axis": [0, 1, 0], "law": "sun-tracking"}
    >>> p = part_from_spec(spec, np.array(["bus", "cell", "cell"]))
    >>> p.facets.tolist(), type(p.law).__name__
    ([1, 2], 'SunTracking')
    >>> part_from_spec({"name": "x", "facets": [0], "law": "spin"}, np.array(["a"]))
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.ValidationError: part 'x': law 'spin'; allowed: fixed, series, sun-tracking
    """
    unknown = sorted(set(spec) - set(PART_KEYS))
    name = spec.get("name")
    if unknown:
        raise ValidationError(
            f"part {name!r}: unknown keys {unknown}; allowed: {sorted(PART_KEYS)}"
        )
    if ("facets" in spec) == ("materials" in spec):
        raise ValidationError(f"part {name!r}: give exactly one of 'facets' and 'materials'")
    if "materials" in spec:
        wanted = [spec["materials"]] if isinstance(spec["materials"], str) else spec["materials"]
        facets = np.flatnonzero(np.isin(facet_material, list(wanted)))
        if facets.size == 0:
            raise ValidationError(
                f"part {name!r}: no facet has the materials {list(wanted)}; the facets have "
                f"{sorted(set(facet_material.tolist()))}"
            )
    else:
        facets = np.asarray(spec["facets"])
    law_name = spec.get("law", "fixed")
    if law_name not in ARTICULATION_LAWS:
        raise ValidationError(
            f"part {name!r}: law {law_name!r}; allowed: {', '.join(sorted(ARTICULATION_LAWS))}"
        )
    own = {"fixed": ("angle",), "sun-tracking": ("limits", "normal"), "series": ("angles",)}
    for law, keys in own.items():
        stray = [k for k in keys if k in spec and law != law_name]
        if stray:
            raise ValidationError(f"part {name!r}: {stray} apply to law {law!r}, not {law_name!r}")
    if law_name == "fixed":
        pointing: Any = Fixed(float(spec.get("angle", 0.0)))
    elif law_name == "sun-tracking":
        lim = spec.get("limits")
        pointing = SunTracking(spec.get("normal"), None if lim is None else tuple(lim))
    else:
        if "angles" not in spec:
            raise ValidationError(f"part {name!r}: law 'series' needs 'angles'")
        pointing = AngleSeries(spec["angles"])
    return Part(
        name,  # type: ignore[arg-type]
        facets,
        axis=spec.get("axis", (0.0, 0.0, 1.0)),
        point=spec.get("point", (0.0, 0.0, 0.0)),
        law=pointing,
    )


#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(__name__, globals(), {"LAWS": "ARTICULATION_LAWS"})
