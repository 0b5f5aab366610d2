"""Model error as part of the model: each material's table may be off by a fractional scale.

A table built from a model or measured in a laboratory describes the flight surface only
to within its calibration, ageing and the model's fidelity.  Fitting a scale ``s_m`` per
material with the Gaussian prior ``s_m ~ N(1, w_m^2)`` (a pseudo-datum ``(s_m - 1) / w_m``
appended to the normalised residuals: the maximum a posteriori estimate of a linearised
Gaussian model, its covariance ``(J^T J)^-1`` over data and prior together; Sivia &
Skilling 2006, *Data Analysis: A Bayesian Tutorial*, §3.4) lets the areas absorb no more
than the data demand, and carries the tables' uncertainty into the areas' uncertainties:
a nuisance parameter marginalised to first order.  The widths default to the table's
``source``: a measured table :data:`PROVENANCE_WIDTH` ``["measured"]``, a model fitted to
measurements ``["model"]``, a synthetic one ``["synthetic"]``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ...errors import InversionError

__all__ = ["PROVENANCE_WIDTH", "table_widths"]

#: Default prior width of a table's scale by its ``source``: absolute BRDF calibration of a
#: laboratory measurement (a few per cent), a model fitted to measurements, and a table
#: made from a model alone (its parameters from the literature, not from the flight part).
PROVENANCE_WIDTH = {"measured": 0.05, "model": 0.1, "synthetic": 0.2}


def table_widths(
    material_scale: str | Mapping[str, float] | None,
    materials: Sequence[str],
    sources: Mapping[str, str],
) -> np.ndarray | None:
    """Prior width of each material's table scale [1], or None (not fitted).

    ``None``: the tables are taken as exact.  ``"provenance"``: by each table's
    ``source`` attribute (:data:`PROVENANCE_WIDTH`; ``model:<name>`` counts as
    ``"model"``, an unknown source as ``"synthetic"``).  A mapping: a width per material
    (> 0), the others by provenance.

    Examples
    --------
    >>> from sbrdf_xr.invert._joint.model_error import table_widths
    >>> table_widths("provenance", ["paint", "cell"], {"paint": "synthetic",
    ...                                                "cell": "measured"}).tolist()
    [0.2, 0.05]
    >>> table_widths({"paint": 0.1}, ["paint", "cell"], {"cell": "model:phong"}).tolist()
    [0.1, 0.1]
    """
    if material_scale is None:
        return None

    def by_source(m: str) -> float:
        src = str(sources.get(m, ""))
        key = "model" if src.startswith("model") else src
        return PROVENANCE_WIDTH.get(key, PROVENANCE_WIDTH["synthetic"])

    if isinstance(material_scale, str):
        if material_scale != "provenance":
            raise InversionError(
                f"material_scale: {material_scale!r}; allowed None (exact tables), "
                "'provenance' (prior widths by each table's source) or a mapping "
                "{material: width}"
            )
        return np.array([by_source(m) for m in materials])
    if not isinstance(material_scale, Mapping):
        raise InversionError(
            f"material_scale: got {type(material_scale).__name__}; allowed None, "
            "'provenance' or a mapping {material: width}"
        )
    unknown = sorted(set(map(str, material_scale)) - set(materials))
    if unknown:
        raise InversionError(
            f"material_scale: {unknown} are not materials of the body; have {list(materials)}"
        )
    out = []
    for m in materials:
        w: Any = material_scale.get(m, by_source(m))
        w = float(w)
        if not (np.isfinite(w) and w > 0):
            raise InversionError(
                f"material_scale[{m!r}]: {w!r}; allowed a prior width > 0 (a fraction of the "
                "table's signal; leave the material out for its provenance's width)"
            )
        out.append(w)
    return np.array(out)
