"""The symmetry twins of a joint fit's solution, each evaluated on the data.

See :mod:`sbrdf_xr.invert._spin.symmetry`: a rotation ``F`` of the body frame that maps the
body onto itself gives the twin attitude ``R(t) F``; its chi-square is computed with the
fit's model at the body-frame directions ``F^T v`` (the same areas, extinction and zero
points), so an exact symmetry shows a gap of rounding size and an approximate one its
real cost.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import xarray as xr

from .._spin.search import align_matrices, lonlat
from .._spin.symmetry import Symmetry, flip_phase

__all__ = ["twin_dataset"]


def _cf(units: str, long_name: str) -> dict[str, str]:
    return {"units": units, "long_name": long_name}


def twin_dataset(
    model: Any,
    lay: Any,
    local: Any,
    p: np.ndarray,
    chi2: float,
    symmetries: Sequence[Symmetry],
    phase_epoch: float,
) -> tuple[xr.Dataset, str]:
    """Over ``twin``: ``twin_chi2_gap``, ``twin_axis_longitude``, ``twin_axis_latitude``,
    ``twin_phase`` (at the epoch), ``twin_sense`` (+1 the solution's sense of rotation about
    the twin's axis, -1 reversed: outside the fit's parameters, whose period is > 0); and
    the text naming them (``"none"`` without symmetries)."""
    data = model.data
    axis = local.axis_of(p)
    rows = []
    for sym in symmetries:
        if sym.kind == "turn":
            q = np.array(p, dtype=np.float64)
            q[3] += sym.angle
            r = local.residuals(q)
            tw_axis, phase, sense = axis, (phase_epoch + sym.angle) % 360.0, 1
        else:
            terms = model.terms(axis, p[2], p[3], body_rotation=sym.matrix)
            m = model.magnitudes(terms, lay.band_scales(p)) + lay.extra(p, data)
            r = np.append((data.magnitude - m) / data.sigma, lay.prior_residuals(p))
            align = align_matrices(model.k, axis[None, :])[0]
            tw_axis, sense = -axis, -1
            phase = flip_phase(sym, align, model.k, phase_epoch)
        lon, lat = (float(v) for v in lonlat(tw_axis))
        rows.append((sym.name, float(r @ r) - chi2, lon, lat, phase, sense))
    names = [r[0] for r in rows]
    cols = np.array([r[1:] for r in rows], dtype=np.float64).reshape(len(rows), 5)
    ds = xr.Dataset(
        {
            "twin_chi2_gap": (
                "twin",
                cols[:, 0],
                _cf("1", "chi-square of the symmetry twin above the solution's"),
            ),
            "twin_axis_longitude": ("twin", cols[:, 1], _cf("degree", "twin's spin axis")),
            "twin_axis_latitude": ("twin", cols[:, 2], _cf("degree", "twin's spin axis")),
            "twin_phase": ("twin", cols[:, 3], _cf("degree", "twin's spin angle at the epoch")),
            "twin_sense": (
                "twin",
                cols[:, 4].astype(int),
                _cf("1", "sense of rotation about the twin's axis (-1: reversed, period -P)"),
            ),
        },
        coords={"twin": ("twin", names, _cf("1", "symmetry of the body giving the twin"))},
    )
    if not rows:
        return ds, "none"
    text = "; ".join(
        f"{n} (axis {lo:.4g}, {la:.4g} deg, phase {ph:.4g} deg"
        f"{', the other sense of rotation' if se < 0 else ''}: chi2 gap {gap:.2g})"
        for n, gap, lo, la, ph, se in rows
    )
    return ds, (
        f"symmetry twins of the body (rotations mapping it with its materials onto itself, "
        f"found from the mesh): {text}; the light curve cannot tell them from the solution"
    )
