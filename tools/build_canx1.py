"""Build the CanX-1 Engineering Model-like mesh shipped as ``catalogs/spacecraft/canx1.ply``.

Run ``python tools/build_canx1.py`` to regenerate the file (deterministic, byte for byte).

Geometry (derived from paper 000 §4 and §4.2; dimensions in mm, to half a millimetre as in
the paper's own model): a 100 mm cube centred at the origin, faces normal to +-x, +-y, +-z.

* Solar cells (Emcore triple-junction, ``tjpv-cell``, blue): two 40 mm x 70 mm cells per
  side face, raised 0.5 mm above the face (their 0.5 mm side walls are cell material too).
  On +-X they are arrayed horizontally (side by side along y: y in [-42, -2] and [2, 42],
  z in [-35, 35]); on +-Y vertically (stacked along z: z in [-42, -2] and [2, 42],
  x in [-35, 35]).  Every side has the same cell area (paper: "All four sides are known to
  possess the same coverage").  The two cells of a +-X side are flush and share the side's
  normal, so during a rotation about z they glint in unison.  The cells of a +-Y side are
  mounted non-flush (paper 000 §4.2 and Fig. 17: the real cells are "not flat nor flush"):
  each is tilted by :data:`Y_CELL_TILT` = 1 deg about z, the upper cell one way and the lower
  the other, so that they glint one after the other, 2 deg of rotation apart, and the +-Y
  glints are weaker than the +-X ones, as the paper observes.  Their top faces rise from
  0.39 to 1.61 mm above the face (mean :data:`CELL_HEIGHT_Y` = 1 mm).
* Frame rails (``aluminium-6061-t6``, red): flush border strips of the side faces along the
  cube edges, 5 mm wide on +-X; on +-Y the vertical rails are 10 mm and the horizontal ones
  5 mm wide, so the Y sides carry more aluminium (2800 mm2 vs 1900 mm2 per side) as the
  paper states ("the X-sides have less aluminum than the Y-sides").
* White paint (``white-paint-a276``, white): the rest of the side faces and all of +-Z.

Each face is cut into rectangles by the breakpoints of the features along its two axes (one
set of breakpoints per axis shared by every face, so that neighbouring faces meet without
T-junctions); each rectangle is two triangles.  The result is a closed, consistently wound,
outward-facing surface of 684 triangles (the paper's model has 698) and 344 vertices.
Facet colours are the paper's (Fig. 11): aluminium red, solar cell blue, paint white.
Coordinates are written in millimetres, as CAD exports usually are; the catalog entry says
``length_unit = "mm"``.
"""

from __future__ import annotations

import itertools
import sys
from pathlib import Path

import numpy as np

HALF = 50.0  #: half the cube edge [mm]
CELL_HEIGHT = 0.5  #: height of the +-X cells above the face [mm]
CELL_HEIGHT_Y = 1.0  #: mean height of the tilted +-Y cells above the face [mm]
Y_CELL_TILT = 1.0  #: azimuth tilt of the +-Y cells about z, upper +, lower - [degree]
ALU, CELL, PAINT = "aluminium-6061-t6", "tjpv-cell", "white-paint-a276"
COLORS = {ALU: (255, 0, 0), CELL: (0, 0, 255), PAINT: (255, 255, 255)}

#: Cells on each side face: ((lo, hi) along the first in-plane axis, (lo, hi) along z) [mm].
#: For +-X the first axis is y; for +-Y it is x.
CELLS = {
    0: [((-42.0, -2.0), (-35.0, 35.0)), ((2.0, 42.0), (-35.0, 35.0))],  # side by side along y
    1: [((-35.0, 35.0), (-42.0, -2.0)), ((-35.0, 35.0), (2.0, 42.0))],  # stacked along z
}
#: Rail widths on each side face: (along the first in-plane axis, along z) [mm].
RAILS = {0: (5.0, 5.0), 1: (10.0, 5.0)}


def _breakpoints() -> list[np.ndarray]:
    """Sorted breakpoints along x, y, z shared by every face."""
    bp: list[set[float]] = [{-HALF, HALF} for _ in range(3)]
    for side in (0, 1):  # side faces normal to x (0) or y (1); in-plane axes (other, z)
        other = 1 - side
        w_other, w_z = RAILS[side]
        bp[other] |= {-HALF + w_other, HALF - w_other}
        bp[2] |= {-HALF + w_z, HALF - w_z}
        for (a0, a1), (z0, z1) in CELLS[side]:
            bp[other] |= {a0, a1}
            bp[2] |= {z0, z1}
    return [np.array(sorted(b)) for b in bp]


class _Builder:
    def __init__(self) -> None:
        self.index: dict[tuple[int, int, int], int] = {}
        self.vertices: list[tuple[float, float, float]] = []
        self.faces: list[tuple[int, int, int]] = []
        self.material: list[str] = []

    def vertex(self, p: np.ndarray) -> int:
        # Flat features lie on a 0.5 mm grid; tilted cell tops are computed by one function,
        # so a shared corner always gets the same floats.  1e-6 mm keys merge them.
        key = tuple(round(1e6 * c) for c in p)
        if key not in self.index:
            self.index[key] = len(self.vertices)
            self.vertices.append(tuple(float(c) for c in p))
        return self.index[key]

    def quad(self, corners: list[np.ndarray], outward: np.ndarray, material: str) -> None:
        """Two triangles of a planar quad (corners in cyclic order), wound to face ``outward``."""
        p = [np.asarray(c, dtype=float) for c in corners]
        if np.dot(np.cross(p[1] - p[0], p[2] - p[0]), outward) < 0:
            p = p[::-1]
        i = [self.vertex(c) for c in p]
        self.faces += [(i[0], i[1], i[2]), (i[0], i[2], i[3])]
        self.material += [material, material]


def build() -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Vertices [mm], facets and facet materials of the CanX-1-like model."""
    bp = _breakpoints()
    b = _Builder()
    for axis in range(3):
        a_ax, b_ax = [k for k in range(3) if k != axis]
        for sign in (1.0, -1.0):
            normal = np.zeros(3)
            normal[axis] = sign
            cells = CELLS.get(axis, [])
            rails = RAILS.get(axis)

            def point(
                u: float,
                v: float,
                h: float,
                a_ax: int = a_ax,
                b_ax: int = b_ax,
                axis: int = axis,
                sign: float = sign,
            ) -> np.ndarray:
                p = np.zeros(3)
                p[a_ax], p[b_ax], p[axis] = u, v, sign * (HALF + h)
                return p

            def in_cell(u: float, v: float, cells: list = cells) -> bool:
                return any(a0 < u < a1 and z0 < v < z1 for (a0, a1), (z0, z1) in cells)

            def height(u: float, v: float, axis: int = axis, sign: float = sign) -> float:
                """Height of a cell top above the face at in-plane (u, v) [mm]."""
                if axis != 1:
                    return CELL_HEIGHT
                # Rotation by +-tilt about z of a +-Y face: the outward offset varies along x.
                tilt = np.radians(Y_CELL_TILT) * (1.0 if v > 0 else -1.0)
                return CELL_HEIGHT_Y + sign * np.tan(tilt) * u

            us, vs = bp[a_ax], bp[b_ax]
            for u0, u1 in itertools.pairwise(us):
                for v0, v1 in itertools.pairwise(vs):
                    uc, vc = (u0 + u1) / 2, (v0 + v1) / 2
                    raised = in_cell(uc, vc)
                    if raised:
                        material = CELL
                    elif rails and (abs(uc) > HALF - rails[0] or abs(vc) > HALF - rails[1]):
                        material = ALU
                    else:
                        material = PAINT
                    vm = (v0 + v1) / 2  # which cell (upper or lower) the rectangle belongs to

                    def h(u: float, raised: bool = raised, vm: float = vm) -> float:
                        return height(u, vm) if raised else 0.0

                    b.quad(
                        [
                            point(u0, v0, h(u0)),
                            point(u1, v0, h(u1)),
                            point(u1, v1, h(u1)),
                            point(u0, v1, h(u0)),
                        ],
                        normal,
                        material,
                    )
                    if not raised:
                        continue
                    # side walls where the neighbouring rectangle is not raised
                    for (du, dv), edge in (
                        ((-1, 0), ((u0, v0), (u0, v1))),
                        ((1, 0), ((u1, v0), (u1, v1))),
                        ((0, -1), ((u0, v0), (u1, v0))),
                        ((0, 1), ((u0, v1), (u1, v1))),
                    ):
                        # a point just across this edge (breakpoints are >= 0.5 mm apart)
                        nu = uc + du * ((u1 - u0) / 2 + 0.1)
                        nv = vc + dv * ((v1 - v0) / 2 + 0.1)
                        if in_cell(nu, nv):
                            continue
                        out = np.zeros(3)
                        out[a_ax], out[b_ax] = du, dv
                        (pu0, pv0), (pu1, pv1) = edge
                        b.quad(
                            [
                                point(pu0, pv0, 0.0),
                                point(pu1, pv1, 0.0),
                                point(pu1, pv1, h(pu1)),
                                point(pu0, pv0, h(pu0)),
                            ],
                            out,
                            CELL,
                        )
    return np.array(b.vertices), np.array(b.faces, dtype=np.int64), b.material


def ply_text() -> str:
    """The ASCII PLY file: vertices in mm, faces with the paper's red/green/blue colours."""
    vertices, faces, material = build()
    lines = [
        "ply",
        "format ascii 1.0",
        "comment CanX-1 Engineering Model-like nanosatellite (paper 000 section 4), units mm",
        "comment generated by python tools/build_canx1.py; colours: aluminium 255 0 0, "
        "TJPV cell 0 0 255, white paint 255 255 255",
        f"element vertex {len(vertices)}",
        "property float x",
        "property float y",
        "property float z",
        f"element face {len(faces)}",
        "property list uchar int vertex_indices",
        "property uchar red",
        "property uchar green",
        "property uchar blue",
        "end_header",
    ]
    lines += [" ".join(f"{c:.9g}" for c in v) for v in vertices]
    lines += [
        "3 {} {} {} {} {} {}".format(*f, *COLORS[m])
        for f, m in zip(faces.tolist(), material, strict=True)
    ]
    return "\n".join(lines) + "\n"


MAP_TEXT = """\
# Facet colour -> material of canx1.ply (the colours of paper 000, Fig. 11).
# Read by sbrdf_xr.body.spacecraft.read_material_map; written by python tools/build_canx1.py.

[[material]]
name = "aluminium-6061-t6"
rgb = [255, 0, 0]

[[material]]
name = "tjpv-cell"
rgb = [0, 0, 255]

[[material]]
name = "white-paint-a276"
rgb = [255, 255, 255]
"""


def main(argv: list[str] | None = None) -> int:
    """Write ``canx1.ply`` and ``canx1.toml`` into ``catalogs/spacecraft``.

    Or into the given directory.
    """
    argv = sys.argv[1:] if argv is None else argv
    out = (
        Path(argv[0])
        if argv
        else Path(__file__).resolve().parent.parent / "catalogs" / "spacecraft"
    )
    out.mkdir(parents=True, exist_ok=True)
    (out / "canx1.ply").write_text(ply_text(), encoding="ascii", newline="\n")
    (out / "canx1.toml").write_text(MAP_TEXT, encoding="ascii", newline="\n")
    vertices, faces, _ = build()
    print(f"wrote {out / 'canx1.ply'}: {len(vertices)} vertices, {len(faces)} facets")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
