"""Per-band values given by band: which entry of a user's ``{band: value}`` mapping
belongs to a band of a magnitude array (its label, or the filter behind an alias)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import xarray as xr

from .._names import BAND
from ..errors import ValidationError
from .bands import _canonical

__all__ = ["extinction_for_band"]


def extinction_for_band(
    mags: xr.DataArray, coefficients: Mapping[Any, Any], band: str, index: int
) -> float:
    """The extinction coefficient of one band of ``mags`` from a mapping given by band:
    by its label, or else by the filter behind an alias (the ``filter`` coordinate), the
    rule of ``magnitudes(extinction={band: k})``.

    Parameters
    ----------
    mags : xarray.DataArray
        Magnitudes over ``band`` (a ``filter`` coordinate names each band's filter).
    coefficients : mapping
        Band label or filter name -> coefficient.
    band : str
        The band's label.
    index : int
        Its position along ``band`` (for its ``filter``).

    Returns
    -------
    float
        The coefficient, as given [magnitudes per air mass].

    Raises
    ------
    ValidationError
        No coefficient for the band, under its label or its filter.

    Examples
    --------
    >>> import xarray as xr
    >>> filters = ("band", ["bessell-V", "sdss2010-g"])
    >>> m = xr.DataArray([10.0, 11.0], dims="band", coords={"band": ["V", "g"], "filter": filters})
    >>> extinction_for_band(m, {"V": 0.2, "sdss2010-g": 0.25}, "g", 1)
    0.25
    """
    have = {str(b): v for b, v in coefficients.items()}
    if band in have:
        return float(have[band])
    if "filter" in mags.coords:
        filt = str(mags["filter"].values[index])
        for b, v in have.items():
            if _canonical(b) == filt:
                return float(v)
    raise ValidationError(
        f"extinction: no coefficient for band {band!r}; given for {sorted(have)} "
        f"(every band of {[str(b) for b in mags[BAND].values]} needs one)"
    )
