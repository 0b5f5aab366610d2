"""The bench rows of open surfaces and articulated parts run and say what they compare."""

from __future__ import annotations

import numpy as np
import pytest

from sbrdf_xr.bench.parts import WING_KINDS, canx1_with_wing, parts_rows


def test_the_three_wings_are_the_same_wing():
    slab, sheet, tracking = (canx1_with_wing(k) for k in WING_KINDS)
    assert slab.mesh.is_watertight and not sheet.mesh.is_watertight
    assert sheet.n_sides == tracking.n_sides == 684 + 4
    assert [p.name for p in tracking.moving_parts] == ["wing"]
    # the sheet is the slab's top face: 0.1 m x 0.2 m, cells in front, paint behind
    f = sheet.facets()
    wing = f.isel(facet=np.flatnonzero(f.mesh_facet.values >= 684))
    assert float(wing.area.sum()) == pytest.approx(2 * 0.02, rel=1e-12)  # two sides
    assert sorted(set(wing.material.values.tolist())) == ["tjpv-cell", "white-paint-a276"]


@pytest.mark.slow  # ~45 s on a fresh machine (the wing tables built and compiled)
def test_rows_compare_each_wing_with_the_slab():
    rows = parts_rows(40, 4, repeat=1)
    assert len(rows) == 6
    assert all(r.baseline.startswith("slab") for r in rows)
    assert rows[0].ratio == 1.0 and rows[3].ratio == 1.0
    assert all(np.isfinite(r.seconds) and r.seconds > 0 for r in rows)
