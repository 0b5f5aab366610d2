"""The nuisance parameters of a joint fit's result: each material table's fitted scale
and colour tilt, with their uncertainties and prior widths.

See :func:`sbrdf_xr.invert.fit_observation` (``material_scale``, ``colour_tilt``) and
:mod:`sbrdf_xr.invert._joint.model_error`.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

__all__ = ["table_scales", "table_tilts"]


def _cf(units: str, long_name: str) -> dict[str, str]:
    return {"units": units, "long_name": long_name}


def table_scales(ds: xr.Dataset, lay: Any, p: np.ndarray, sd: np.ndarray) -> None:
    """The fitted scale of each material's table over ``material`` in ``ds``, when model
    error is fitted (``lay.m_sd``): estimate, uncertainty and prior width.

    Examples
    --------
    >>> import numpy as np, xarray as xr
    >>> from sbrdf_xr.invert._joint.nuisance import table_scales
    >>> from sbrdf_xr.invert._joint.result import Layout
    >>> lay = Layout(("V",), ("a", "b"), np.ones(2), "fit", None, "total", None,
    ...              np.array([0.1, 0.2]))
    >>> ds = xr.Dataset(coords={"material": ["a", "b"]})
    >>> p = np.array([0, 0, 10, 0, 0.1, 0.5, 1.02, 0.97])
    >>> table_scales(ds, lay, p, np.full(8, 0.01))
    >>> ds.table_scale.values.tolist(), ds.table_scale_prior_width.values.tolist()
    ([1.02, 0.97], [0.1, 0.2])
    """
    if lay.m_sd is None:
        return
    sl = lay.sl["s"]
    ds["table_scale"] = (
        "material",
        p[sl],
        _cf("1", "fitted scale of the material's table (nuisance parameter: model error)"),
    )
    ds["table_scale_uncertainty"] = (
        "material",
        sd[sl],
        _cf("1", "1-sigma uncertainty of the table's scale"),
    )
    ds["table_scale_prior_width"] = (
        "material",
        lay.m_sd,
        _cf("1", "prior width of the table's scale (prior 1 +- width)"),
    )


def table_tilts(ds: xr.Dataset, lay: Any, p: np.ndarray, sd: np.ndarray) -> None:
    """The fitted colour tilt of each material's table over ``material`` in ``ds``, when
    fitted (``lay.c_sd``): estimate, uncertainty and prior width [1 per 100 nm].

    Examples
    --------
    >>> import numpy as np, xarray as xr
    >>> from sbrdf_xr.invert._joint.nuisance import table_tilts
    >>> from sbrdf_xr.invert._joint.result import Layout
    >>> lay = Layout(("V", "I"), ("a",), np.ones(1), "fit", None, "fixed", None, None,
    ...              np.array([0.05]), np.array([-1.0, 1.0]))
    >>> ds = xr.Dataset(coords={"material": ["a"]})
    >>> p = np.array([0, 0, 10, 0, 0.2, 0.1, 0.03])
    >>> table_tilts(ds, lay, p, np.full(7, 0.01))
    >>> ds.table_tilt.values.tolist(), lay.band_scales(p).ravel().round(6).tolist()
    ([0.03], [0.97, 1.03])
    """
    if lay.c_sd is None:
        return
    sl = lay.sl["c"]
    per = "per 100 nm of band mean wavelength"
    ds["table_tilt"] = (
        "material",
        p[sl],
        _cf("1", f"fitted colour tilt of the material's table, fractional {per} (nuisance)"),
    )
    ds["table_tilt_uncertainty"] = (
        "material",
        sd[sl],
        _cf("1", f"1-sigma uncertainty of the table's colour tilt, {per}"),
    )
    ds["table_tilt_prior_width"] = (
        "material",
        lay.c_sd,
        _cf("1", f"prior width of the table's colour tilt (prior 0 +- width), {per}"),
    )
