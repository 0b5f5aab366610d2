"""In-band quantities: a spectral density integrated over a band's response.

The in-band radiance, irradiance or intensity ``int S(lambda) R(lambda) dlambda`` in SI
units, for any band :func:`~sbrdf_xr.photometry.filters` accepts (the infrared boxes of
:mod:`sbrdf_xr.photometry.infrared` have a response of 1, so their in-band quantity is
the plain integral over the box).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from .._names import BAND, WAVELENGTH
from ..errors import ValidationError
from .bands import filters
from .spectra import _check_grid, _integral

__all__ = ["in_band"]


def in_band(spectrum: xr.DataArray, bands: Any) -> xr.DataArray:
    """In-band quantity ``int S(lambda) R(lambda) dlambda`` of a spectrum in each band.

    Parameters
    ----------
    spectrum : xarray.DataArray
        A spectral density over ``wavelength`` (nm; any other dims too), with a
        ``units`` attribute per nm (``W m-2 nm-1`` irradiance, ``W m-2 sr-1 nm-1``
        radiance, ``W sr-1 nm-1`` intensity).
    bands : str, sequence or mapping
        Band names or bandpasses (:func:`~sbrdf_xr.photometry.filters`); responses
        are used as given (peak 1 for the boxes and the WISE curves).

    Returns
    -------
    xarray.DataArray
        Over ``band`` (first) and the spectrum's other dims, in the spectrum's units
        times nm (``W m-2``, ``W m-2 sr-1``, ``W sr-1``): the product of spectrum and
        response integrated by the trapezoid rule on the union of their nodes.
        A band reaching past the spectrum's grid is a :class:`ValidationError`.

    Examples
    --------
    >>> from sbrdf_xr.sources import planck
    >>> wl = np.linspace(7000.0, 14000.0, 701)
    >>> bb = xr.DataArray(planck(wl, 300.0), dims="wavelength", coords={"wavelength": wl},
    ...                   attrs={"units": "W m-2 sr-1 nm-1"})
    >>> out = in_band(bb, ["LWIR"])
    >>> round(float(out[0]), 2), out.attrs["units"]  # 38.50 in 8-12 um less 0.01 (ramps)
    (38.49, 'W m-2 sr-1')
    """
    units = str(spectrum.attrs.get("units", ""))
    if WAVELENGTH not in spectrum.dims or not units.endswith(" nm-1"):
        raise ValidationError(
            f"spectrum: expected a DataArray over '{WAVELENGTH}' with units per nm "
            f"(e.g. 'W m-2 nm-1'), got dims {spectrum.dims} and units {units!r}"
        )
    wl = _check_grid(spectrum[WAVELENGTH].values, "spectrum wavelength")
    resp = filters(bands)
    s = spectrum.transpose(..., WAVELENGTH)
    values = np.asarray(s.values, dtype=np.float64)
    out = []
    for k in range(resp.sizes[BAND]):
        r = resp.isel({BAND: k})
        rw = r[WAVELENGTH].values
        on = rw[r.values > 0]
        lo, hi = (
            rw[max(np.searchsorted(rw, on[0]) - 1, 0)],
            rw[min(np.searchsorted(rw, on[-1]) + 1, rw.size - 1)],
        )
        if lo < wl[0] or hi > wl[-1]:
            raise ValidationError(
                f"bands: {str(r[BAND].values)!r} responds over {lo:g}-{hi:g} nm but the "
                f"spectrum covers {wl[0]:g}-{wl[-1]:g} nm"
            )
        grid = np.unique(
            np.concatenate([[lo, hi], wl[(wl > lo) & (wl < hi)], rw[(rw > lo) & (rw < hi)]])
        )
        weight = np.interp(grid, rw, r.values)
        rows = np.stack([np.interp(grid, wl, v) for v in values.reshape(-1, wl.size)])
        out.append(_integral(grid, rows * weight, lo, hi).reshape(values.shape[:-1]))
    dims = (BAND, *s.dims[:-1])
    coords = {d: s[d] for d in s.dims[:-1] if d in s.coords}
    coords[BAND] = resp[BAND]
    return xr.DataArray(
        np.array(out),
        dims=dims,
        coords=coords,
        name="in_band",
        attrs={
            "units": units[: -len(" nm-1")],
            "long_name": f"in-band integral of {spectrum.attrs.get('long_name', spectrum.name)}",
        },
    )
