"""Bodies with parts that turn: each rigid group evaluated in its own frame per geometry.

A spacecraft with parts (:mod:`sbrdf_xr.body.parts`) is split by the plan into groups:
the bus and every part, each with its own facet terms (facets of different groups are
never merged).  On every block, each part's hinge angle is set by its pointing law
(from the Sun's direction in the bus frame, or the geometry's place in the sweep) and
gives a rotation ``R`` (part frame -> bus frame) per geometry.  A direction ``d`` seen
from a part turned by ``R`` is ``R^T d`` in the part's own frame, so every effect runs
unchanged on each group, with the block's directions (Sun, observer, other sources)
turned into that group's frame, and the sums of the groups add up: the facet sum is
linear over facets.  Shadowing is the exception: it needs the whole posed body, so its
fraction (:func:`sbrdf_xr.body.posed.posed_fraction`) is computed once per block and
direction pair on the union in the bus frame and each group takes its own sides.

Examples
--------
>>> import numpy as np
>>> from sbrdf_xr import Scene
>>> from sbrdf_xr.materials.schema import lambertian
>>> from sbrdf_xr.testing import box_with_plate_spacecraft
>>> mats = {m: lambertian(0.5, [500.0, 600.0], material=m) for m in ("bus", "cell", "backsheet")}
>>> body = box_with_plate_spacecraft(parts=True)
>>> plan = Scene(body, mats, to_sun=[[0.0, 1.0, 0.0]], to_observer=[[0.0, 1.0, 0.0]]).plan()
>>> print(dict(plan.steps)["parts"])
array (2 facets): sun-tracking about [1.0, 0.0, 0.0] through [0.0, 0.0, 1.5] m, moves; \
each part evaluated in its own frame per geometry
>>> [g for g, _ in plan.articulation.groups]
[0, 1]
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from .effects import EFFECTS, BlockInputs

if TYPE_CHECKING:
    from ..body.parts import Part
    from .views import PlanView, Terms

__all__ = ["Articulation", "BoundGroup", "articulated_sums", "describe_parts", "group_terms"]


def describe_parts(parts: tuple[Part, ...]) -> str:
    """The plan line of a body's parts: which move, about what.

    Examples
    --------
    >>> from sbrdf_xr.body.parts import Fixed, Part
    >>> describe_parts((Part("boom", [0], law=Fixed(10.0)),))
    'boom (1 facets): fixed at 10 deg about [0.0, 0.0, 1.0] through [0.0, 0.0, 0.0] m'
    """
    lines = []
    for p in parts:
        law = type(p.law).__name__
        limits = getattr(p.law, "limits", None)
        what = {
            "Fixed": f"fixed at {getattr(p.law, 'angle', 0.0):g} deg",
            "SunTracking": "sun-tracking"
            + ("" if limits is None else f" within {list(limits)} deg"),
            "AngleSeries": "a given angle series",
        }[law]
        lines.append(
            f"{p.name} ({p.facets.size} facets): {what} about {p.axis.round(6).tolist()} "
            f"through {p.point.round(6).tolist()} m" + (", moves" if p.moving else "")
        )
    tail = "; each part evaluated in its own frame per geometry"
    return "; ".join(lines) + (tail if any(p.moving for p in parts) else "")


def group_terms(terms: Terms) -> tuple[tuple[int, Terms], ...]:
    """The terms of every group present (0: the bus, k + 1: part k), in term order.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.engine.plan import Terms
    >>> t = Terms(np.eye(3), np.ones(3), np.zeros(3, int), np.arange(3), np.ones(3, int),
    ...           np.eye(3), np.array([0, 1, 0]))
    >>> [(g, sub.facet.tolist()) for g, sub in group_terms(t)]
    [(0, [0, 2]), (1, [1])]
    """
    out = []
    assert terms.part is not None
    fields = ("normal", "area", "material", "facet", "n_facets", "tangent", "part")
    for g in np.unique(terms.part):
        sel = terms.part == g
        picked = {
            f: None if getattr(terms, f) is None else np.ascontiguousarray(getattr(terms, f)[sel])
            for f in fields
        }
        out.append((int(g), replace(terms, **picked)))  # type: ignore[arg-type]
    return tuple(out)


@dataclass(frozen=True, eq=False)
class Articulation:
    """A plan's parts and the terms of each group (see the module docstring).

    Examples
    --------
    >>> from sbrdf_xr.body.parts import Part, SunTracking
    >>> art = Articulation((Part("p", [0], axis=[0, 0, 1.0], normal=[1.0, 0, 0],
    ...                         law=SunTracking()),), ())
    >>> R = art.rotations(np.array([[0.0, 1.0, 0.0]]), np.arange(1))
    >>> (R[0, 0] @ [1.0, 0, 0]).round(12) + 0.0  # the normal turned onto the Sun
    array([0., 1., 0.])
    """

    parts: tuple[Part, ...]
    groups: tuple[tuple[int, Terms], ...]

    def angles(self, to_sun: np.ndarray, index: np.ndarray) -> np.ndarray:
        """Hinge angle of every part at every geometry [degree], (G, P)."""
        out = np.empty((len(index), len(self.parts)))
        for k, p in enumerate(self.parts):
            out[:, k] = np.degrees(p.law.angles(to_sun, index, p))
        return out

    def coords(self, to_sun: np.ndarray, dims: tuple[str, ...]) -> dict[str, Any]:
        """The cube's coordinates ``part`` (names) and ``part_angle`` (every geometry's
        hinge angles [degree]) from ``to_sun`` (lead dims + (3,))."""
        s = np.asarray(to_sun).reshape(-1, 3)
        a = self.angles(s, np.arange(s.shape[0])).reshape(*np.shape(to_sun)[:-1], -1)
        return {
            "part": (
                "part",
                [p.name for p in self.parts],
                {"units": "1", "long_name": "part name"},
            ),
            "part_angle": (
                (*dims, "part"),
                a,
                {"units": "degree", "long_name": "hinge angle of the part (its pointing law)"},
            ),
        }

    def rotations(self, to_sun: np.ndarray, index: np.ndarray) -> np.ndarray:
        """Rotation of every part at every geometry, part -> bus frame, (G, P, 3, 3)."""
        from ..body.parts import hinge_rotation

        out = np.empty((len(index), len(self.parts), 3, 3))
        for k, p in enumerate(self.parts):
            out[:, k] = hinge_rotation(p.axis, p.law.angles(to_sun, index, p))
        return out


@dataclass(frozen=True, eq=False)
class BoundGroup:
    """One group of an articulated plan on one block: its poses and the block's
    shadowing fractions, shared by the groups (``memo``).

    Examples
    --------
    >>> from sbrdf_xr.body.parts import hinge_rotation
    >>> rot = hinge_rotation([0, 0, 1.0], [np.pi / 2])[:, None]  # (G=1, P=1, 3, 3)
    >>> b = BoundGroup(None, 1, rot)
    >>> b.to_bus(np.array([[1.0, 0.0, 0.0]])).round(12) + 0.0  # part x is bus y
    array([[0., 1., 0.]])
    """

    articulation: Articulation
    group: int
    rotations: np.ndarray  #: (G, P, 3, 3)
    #: id(turned) -> (turned, bus): the block's directions in every group's frame, kept
    #: alive (so no id is reused while the block runs) with their bus-frame originals
    origin: Mapping[int, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    memo: dict[Any, np.ndarray] = field(default_factory=dict)

    def take(self, rows: np.ndarray) -> BoundGroup:
        """The same group on the geometries ``rows`` of the block."""
        return BoundGroup(self.articulation, self.group, self.rotations[rows])

    def to_bus(self, d: np.ndarray) -> np.ndarray:
        """Directions of this group's frame (G, 3) in the bus frame."""
        known = self.origin.get(id(d))
        if known is not None and known[0] is d:
            return known[1]
        if self.group == 0:
            return d
        return np.einsum("gij,gj->gi", self.rotations[:, self.group - 1], d)

    def fraction(
        self, plan: PlanView, to_source: np.ndarray, to_observer: np.ndarray, options: Mapping
    ) -> np.ndarray:
        """Lit-and-visible fraction (G, T) of this group's terms on the posed body."""
        from ..body.posed import posed_fraction

        s, o = self.to_bus(to_source), self.to_bus(to_observer)
        key = (id(s), id(o)) if id(s) in self.memo_ids and id(o) in self.memo_ids else None
        frac = None if key is None else self.memo.get(key)
        if frac is None:
            frac = posed_fraction(plan.spacecraft, self.rotations, [s, o], **options)
            if key is not None:
                self.memo[key] = frac
        return np.ascontiguousarray(frac[:, plan.terms.facet])

    @property
    def memo_ids(self) -> set[int]:
        """Ids of the block's own bus-frame arrays (safe memo keys for the block)."""
        return {id(v[1]) for v in self.origin.values()}


def _turned(
    block: BlockInputs, rot: np.ndarray | None, origin: dict[int, tuple[np.ndarray, np.ndarray]]
) -> BlockInputs:
    """The block's directions in a group's frame (``rot``: part -> bus per geometry)."""

    def turn(d: np.ndarray) -> np.ndarray:
        out = d if rot is None else np.ascontiguousarray(np.einsum("gji,gj->gi", rot, d))
        origin[id(out)] = (out, d)
        return out

    sources = {k: turn(v) if k.startswith("to_") else v for k, v in block.sources.items()}
    return BlockInputs(
        turn(block.to_sun), turn(block.to_observer), block.sun_scale, block.lead_shape, sources
    )


def articulated_sums(plan: PlanView, block: BlockInputs, sl: slice) -> dict[str, np.ndarray]:
    """Every effect's sums on one block of an articulated plan, summed over the groups.

    ``sl`` is the block's slice of the plan's first dimension (for angle series).

    Examples
    --------
    >>> from sbrdf_xr import Scene
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> from sbrdf_xr.testing import box_with_plate_spacecraft
    >>> mats = {m: lambertian(0.5, [500.0], material=m) for m in ("bus", "cell", "backsheet")}
    >>> x = [[0.0, 0.0, 1.0]]  # Sun and observer overhead: the top and the plate, head on
    >>> plan = Scene(box_with_plate_spacecraft(parts=True), mats, to_sun=x, to_observer=x).plan()
    >>> sums = articulated_sums(plan, plan.geometry.block(slice(0, 1)), slice(0, 1))
    >>> round(float(sums["signal"][0, 0] * np.pi), 12)  # 1 m2 top + 1 m2 plate, albedo 0.5
    1.0
    """
    art = plan.articulation
    per = plan.geometry.n_geometries // max(1, plan.n_lead)
    start = (sl.start or 0) * per
    index = np.arange(start, start + block.to_sun.shape[0])
    rot = art.rotations(block.to_sun, index)
    origin: dict[int, tuple[np.ndarray, np.ndarray]] = {}
    memo: dict[Any, np.ndarray] = {}
    sums: dict[str, np.ndarray] = {}
    groups = [(g, t) for g, t in art.groups if t.size] or list(art.groups[:1])
    for g, terms in groups:
        sub = _turned(block, None if g == 0 else rot[:, g - 1], origin)
        bound = BoundGroup(art, g, rot, origin, memo)
        view = replace(plan, terms=terms, articulation=bound)
        for name in plan.effects:
            contribute = EFFECTS[name].contribute
            if contribute is None:
                continue
            for k, v in contribute(view, sub).items():
                sums[k] = sums[k] + v if k in sums else v
    return sums
