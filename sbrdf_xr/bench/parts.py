"""What open surfaces and articulated parts cost against the rigid closed path.

Three CanX-1-size bodies, the same sweep (random attitudes, phase angle 10 deg, the
CanX-1 tables), timed in turns so that the machine's load falls on each alike (the best
of the repeats is kept):

* ``slab``: the rigid closed baseline, CanX-1 with a 0.1 m x 0.2 m solar wing beside its
  +Y face modelled as a closed 1 mm slab (the workaround before open surfaces);
* ``open``: the same wing as an open two-sided sheet (cells in front, paint behind);
* ``tracking``: that sheet as a part turning about its long axis (y) to track the Sun.

Each unshadowed (merged terms) and with exact self-shadowing.  The rows give the time
per geometry and the ratio to ``slab``.
"""

from __future__ import annotations

import itertools
from functools import partial
from typing import Any

import numpy as np

from ..errors import renamed_attributes
from .rows import BenchRow, best_time

__all__ = ["WING_KINDS", "canx1_with_wing", "parts_rows"]

#: The bodies compared (see the module docstring).
WING_KINDS = ("slab", "open", "tracking")


def canx1_with_wing(kind: str) -> Any:
    """CanX-1 with a 0.1 m x 0.2 m wing beside its +Y face, as ``kind`` (:data:`WING_KINDS`).

    Examples
    --------
    >>> [canx1_with_wing(k).n_sides for k in WING_KINDS]
    [696, 688, 688]
    """
    import trimesh

    from ..body.parts import Part, SunTracking
    from ..body.spacecraft import Spacecraft, canx1

    c = canx1()
    v0, f0 = np.asarray(c.mesh.vertices), np.asarray(c.mesh.faces)
    n, cells = len(v0), "tjpv-cell"
    if kind == "slab":
        slab = trimesh.creation.box(extents=(0.1, 0.2, 0.001))
        slab.apply_translation((0.0, 0.16, 0.0))
        mesh = trimesh.Trimesh(
            np.vstack([v0, slab.vertices]), np.vstack([f0, slab.faces + n]), process=False
        )
        return Spacecraft(mesh, [*c.facet_material, *[cells] * 12], name="canx1-slab")
    wing = [[-0.05, 0.06, 0.0], [0.05, 0.06, 0.0], [0.05, 0.26, 0.0], [-0.05, 0.26, 0.0]]
    mesh = trimesh.Trimesh(
        np.vstack([v0, wing]),
        np.vstack([f0, [[n, n + 1, n + 2], [n, n + 2, n + 3]]]),
        process=False,
    )
    parts = None
    if kind == "tracking":
        law = SunTracking()
        parts = [Part("wing", [len(f0), len(f0) + 1], (0, 1.0, 0), (0, 0.16, 0), law)]
    return Spacecraft(
        mesh,
        [*c.facet_material, cells, cells],
        name=f"canx1-{kind}",
        back_material=[""] * len(f0) + ["white-paint-a276"] * 2,
        parts=parts,
    )


def parts_rows(n_attitudes: int = 2000, n_shadowed: int = 200, repeat: int = 5) -> list[BenchRow]:
    """The rows of the module docstring.

    Parameters
    ----------
    n_attitudes, n_shadowed : int
        Random attitudes of the unshadowed and of the shadowed sweeps.
    repeat : int
        Turns of timing (best kept).

    Examples
    --------
    Seconds to minutes; ``sbrdf-xr bench --engine`` runs it:

    >>> rows = parts_rows(200, 20, repeat=1)  # doctest: +SKIP
    >>> [r.name for r in rows][:2]  # doctest: +SKIP
    ['slab (closed 1 mm wing), unshadowed', 'open two-sided wing, unshadowed']
    """
    from .. import geometry
    from ..engine import builtin_scene
    from ..engine.run import simulate

    base = builtin_scene("canx1-rotation")
    names = {
        "slab": "slab (closed 1 mm wing)",
        "open": "open two-sided wing",
        "tracking": "sun-tracking two-sided wing",
    }
    rows: list[BenchRow] = []
    for shadow, n in ((False, n_attitudes), (True, n_shadowed)):
        effects = ("sunlight", "shadowing") if shadow else ("sunlight",)
        plans = {
            k: base.with_options(
                spacecraft=canx1_with_wing(k),
                attitudes=geometry.uniform_attitudes(n, seed=3),
                attitude_angle=None,
                effects=effects,
                outputs=("signal", "area"),
                name=f"wing-{k}",
            ).plan()
            for k in WING_KINDS
        }
        best = {k: np.inf for k in WING_KINDS}
        for _, k in itertools.product(range(repeat), WING_KINDS):  # in turns: load falls alike
            p = plans[k]
            best[k] = min(best[k], best_time(partial(simulate, p, lazy=False), 1))
        what = "exact shadowing" if shadow else "unshadowed"
        for k in WING_KINDS:
            rows.append(
                BenchRow(
                    f"{names[k]}, {what}",
                    best[k],
                    f"{names['slab']}, {what}",
                    best[k] / best["slab"],
                    f"{best[k] / n * 1e6:.0f} us per geometry, {plans[k].terms.size} terms",
                    sweep=f"canx1 + wing, {n} random attitudes, phase 10 deg, 71 nm",
                )
            )
    return rows


#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(__name__, globals(), {"KINDS": "WING_KINDS"})
