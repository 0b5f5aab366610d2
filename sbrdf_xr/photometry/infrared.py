"""Infrared bands and in-band quantities (0.25-25 um and beyond).

Band names that :func:`~sbrdf_xr.photometry.filters` and every ``bands=`` of the package
accept, next to the speclite curves:

* ``J``, ``H``, ``Ks``: 2MASS (Cohen, Wheaton & Megeath 2003, AJ 126, 1090), the speclite
  ``twomass-*`` curves (aliases in :data:`~sbrdf_xr.photometry.bands.BAND_ALIASES`);
* ``W1``-``W4``: the WISE relative spectral responses (Wright et al. 2010, AJ 140, 1868;
  Jarrett et al. 2011, ApJ 735, 112) shipped by pyphot;
* ``L'``, ``M'``: the MKO filters as boxes between their half-power points (Tokunaga,
  Simons & Vacca 2002, PASP 114, 180); ``N``: the 8-13 um atmospheric window; ``MWIR``
  (3-5 um) and ``LWIR`` (8-12 um): the sensor bands of infrared signature work.  Boxes
  have a response of 1 between their edges, with 1-nm linear ramps inside them (a
  grid from edge to edge covers the band).

Magnitudes follow wherever a zero point is defined: AB everywhere, Vega through the
CALSPEC alpha Lyr spectrum (90 nm - 300 um).  :func:`sbrdf_xr.photometry.inband.in_band`
gives the in-band SI quantity ``int S(lambda) R(lambda) dlambda`` of a spectrum.
"""

from __future__ import annotations

from collections.abc import Mapping
from functools import cache
from types import MappingProxyType

import numpy as np

from ..errors import ValidationError

__all__ = ["BOXES", "INFRARED_BANDS", "WISE", "band_curve"]

#: Box bands: label -> (lower edge [nm], upper edge [nm], definition).
BOXES: Mapping[str, tuple[float, float, str]] = MappingProxyType(
    {
        "L'": (3420.0, 4120.0, "MKO L' half-power points (Tokunaga et al. 2002, PASP 114, 180)"),
        "M'": (4570.0, 4790.0, "MKO M' half-power points (Tokunaga et al. 2002, PASP 114, 180)"),
        "N": (8000.0, 13000.0, "N: the 8-13 um atmospheric window"),
        "MWIR": (3000.0, 5000.0, "mid-wave infrared sensor band, 3-5 um"),
        "LWIR": (8000.0, 12000.0, "long-wave infrared sensor band, 8-12 um"),
    }
)
#: WISE bands: label -> pyphot filter name.
WISE: Mapping[str, str] = MappingProxyType({f"W{k}": f"WISE_RSR_W{k}" for k in (1, 2, 3, 4)})
#: Every band name this module defines.
INFRARED_BANDS = (*BOXES, *WISE)
#: Width of the linear ramps of a box inside its edges [nm].
RAMP_NM = 1.0


@cache
def band_curve(name: str) -> tuple[np.ndarray, np.ndarray, str]:
    """Wavelength [nm], response [1] and provenance of an infrared band.

    Parameters
    ----------
    name : str
        One of :data:`INFRARED_BANDS`.

    Returns
    -------
    tuple of (ndarray, ndarray, str)
        Read-only wavelengths [nm], the response [1] and where it comes from.

    Examples
    --------
    >>> wl, r, src = band_curve("LWIR")
    >>> wl.tolist(), r.tolist()
    ([8000.0, 8001.0, 11999.0, 12000.0], [0.0, 1.0, 1.0, 0.0])
    >>> wl, r, src = band_curve("W3")
    >>> round(float(wl[r.argmax()]), -2), src.split(" (")[0]
    (14400.0, 'pyphot WISE_RSR_W3')
    """
    if name in BOXES:
        lo, hi, what = BOXES[name]
        wl = np.array([lo, lo + RAMP_NM, hi - RAMP_NM, hi])
        resp = np.array([0.0, 1.0, 1.0, 0.0])
        src = f"box {lo:g}-{hi:g} nm: {what}"
    elif name in WISE:
        import pyphot

        f = pyphot.get_library()[WISE[name]]
        wl = np.asarray(f.wavelength.to("nm").value, dtype=np.float64)
        resp = np.asarray(f.transmit, dtype=np.float64)
        resp = resp / resp.max()
        src = (
            f"pyphot {WISE[name]} (pyphot/libs/new_filters.hd5, {f.dtype} response, "
            "peak-normalised): Jarrett et al. 2011, ApJ 735, 112"
        )
    else:
        raise ValidationError(
            f"band: {name!r} is not an infrared band; allowed: {', '.join(INFRARED_BANDS)}"
        )
    wl.setflags(write=False)
    resp.setflags(write=False)
    return wl, resp, src
