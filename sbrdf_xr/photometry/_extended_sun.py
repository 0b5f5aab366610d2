"""The extra-terrestrial solar spectrum from 119.5 nm to 1 mm (``astm_g173_extended``).

Three published spectra joined, and a stated continuation:

* below 280 nm, CALSPEC ``sun_reference_stis_001`` (observed, shipped by pyphot), scaled
  to ASTM G173 over 280-300 nm;
* 280-4000 nm, ASTM G173-03 AM0 as shipped by pvlib (unchanged: in this range the
  spectrum is the ``astm_g173`` one node for node);
* 4000 nm to the first node at or past 10 um, the Kurucz (1993) model of the Sun
  (CALSPEC ``sun_kurucz93``), scaled to ASTM G173 over 3500-4000 nm (a factor 1.01);
* beyond, the Sun as a disc of solid angle ``pi (R_sun / 1 au)^2`` radiating Planck's
  law at the model's brightness temperature, interpolated linearly in ``log lambda``
  between the model's nodes (10-160 um, 4800-4300 K) and held at the last one beyond:
  a smooth continuum on a dense geometric grid (ratio 1.01), so the linear
  interpolation the band integrals assume is exact to ~1e-4.

References: Gueymard 2004 (Sol. Energy 76, 423) for G173; Bohlin et al. 2014 (PASP
126, 711) for CALSPEC; Kurucz 1993 (ATLAS9, CD-ROM 13); Prsa et al. 2016 (AJ 152, 41)
for the nominal solar radius.
"""

from __future__ import annotations

import numpy as np
from scipy import constants

#: Nominal solar radius [m] (IAU 2015 Resolution B3) and the astronomical unit [m].
SUN_RADIUS_M = 6.957e8
AU_M = 1.495_978_707e11
#: Solid angle of the solar disc at 1 au [sr].
SUN_SOLID_ANGLE = float(2.0 * np.pi * (1.0 - np.sqrt(1.0 - (SUN_RADIUS_M / AU_M) ** 2)))
#: Where the pieces join [nm], and where the continuation ends [nm].
JOIN_UV, JOIN_IR, PLANCK_FROM, END = 280.0, 4000.0, 10_000.0, 1.0e6
_C1 = 2.0 * constants.h * constants.c**2  # [W m2 sr-1]
_C2 = constants.h * constants.c / constants.k  # [m K]


def _blackbody(wl_nm: np.ndarray, temperature: np.ndarray) -> np.ndarray:
    """Spectral radiance [W m-2 sr-1 nm-1] (Planck's law; the same as sources.planck)."""
    lam = wl_nm * 1e-9
    return _C1 / lam**5 / np.expm1(_C2 / (lam * temperature)) * 1e-9


def _brightness_temperature(wl_nm: np.ndarray, radiance: np.ndarray) -> np.ndarray:
    """The inverse of :func:`_blackbody` [K]."""
    lam = wl_nm * 1e-9
    return _C2 / (lam * np.log1p(_C1 / lam**5 * 1e-9 / radiance))


def _mean(wl: np.ndarray, e: np.ndarray, lo: float, hi: float) -> float:
    grid = np.linspace(lo, hi, 2001)
    return float(np.trapezoid(np.interp(grid, wl, e), grid))


def extend(
    g173: tuple[np.ndarray, np.ndarray],
    uv: tuple[np.ndarray, np.ndarray],
    model: tuple[np.ndarray, np.ndarray],
) -> tuple[np.ndarray, np.ndarray]:
    """Join the three spectra (wavelength [nm], irradiance [W m-2 nm-1]) and continue.

    Examples
    --------
    >>> wl = np.linspace(200.0, 20_000.0, 400)
    >>> sun = SUN_SOLID_ANGLE * _blackbody(wl, 5772.0)
    >>> w, e = extend((wl[(wl >= 280) & (wl <= 4000)], sun[(wl >= 280) & (wl <= 4000)]),
    ...               (wl, sun), (wl, sun))
    >>> float(w[0]), round(float(w[-1]))
    (200.0, 1000000)
    >>> i = np.searchsorted(w, 15_000.0)
    >>> round(float(e[i] / (SUN_SOLID_ANGLE * _blackbody(w[i], 5772.0))), 6)
    1.0
    """
    gw, ge = g173
    uw, ue = uv
    mw, me = model
    k_uv = _mean(gw, ge, JOIN_UV, 300.0) / _mean(uw, ue, JOIN_UV, 300.0)
    k_ir = _mean(gw, ge, 3500.0, JOIN_IR) / _mean(mw, me, 3500.0, JOIN_IR)
    below = uw < gw[0]
    mid = (mw > gw[-1]) & (mw < PLANCK_FROM)
    last = int(np.searchsorted(mw, PLANCK_FROM))  # the first model node at or past 10 um
    tail_nodes = mw[last:]
    t_b = _brightness_temperature(tail_nodes, k_ir * me[last:] / SUN_SOLID_ANGLE)
    n = int(np.ceil(np.log(END / tail_nodes[0]) / np.log(1.01)))
    grid = tail_nodes[0] * np.exp(np.linspace(0.0, np.log(END / tail_nodes[0]), n + 1))
    t_grid = np.interp(np.log(grid), np.log(tail_nodes), t_b)
    tail = SUN_SOLID_ANGLE * _blackbody(grid, t_grid)
    wl = np.concatenate([uw[below], gw, mw[mid], grid])
    e = np.concatenate([k_uv * ue[below], ge, k_ir * me[mid], tail])
    return wl, e
