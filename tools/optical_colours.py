"""Solar absorptance and colour indices of the optical-constant materials.

Run ``python tools/optical_colours.py``: prints the table and writes it into
``docs/guide/optical-materials.md`` between the ``<!-- colour-table -->`` markers.

For each material of :data:`sbrdf_xr.materials.optical.OPTICAL_MATERIALS` (default
films), from its smooth, flat sample's specular reflectance ``R(lambda, theta)``
(:func:`sbrdf_xr.materials.optical.specular_reflectance`) on a 0.05 nm grid, fine enough
to resolve the fringes of its thickest film (0.3 nm apart for 100 um of silica at 300 nm),
so that band integrals average them as a real, slightly non-uniform film does:

* solar absorptance ``alpha_s = 1 - int R(lambda, 0) E dlambda / int E dlambda`` (opaque
  sample: absorptance = 1 - reflectance), ``E`` the ASTM G173-03 extraterrestrial
  spectrum, over the part of 280-4000 nm the material's optical constants cover (that
  part's share of the solar irradiance is given);
* colour indices B-V, V-R (Johnson-Cousins, Vega system) and g-r (SDSS, AB system) of the
  sunlight it reflects at the mirror direction of 30 degrees incidence: a rough sample's
  BRDF there is ``F(lambda, 30 deg) D G2 / (4 cos^2 30 deg)`` with a wavelength-independent
  ``D G2``, so the colour is the Sun's plus ``-2.5 log10`` of the ratio of the
  solar-weighted band means of ``R(lambda, 30 deg)`` (photon counting).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from sbrdf_xr.materials import optical
from sbrdf_xr.photometry import band_weights, solar_spectrum, sun_magnitudes

GUIDE = Path(__file__).resolve().parent.parent / "docs" / "guide" / "optical-materials.md"
#: Incidence angle of the colour geometry (the mirror direction) [degree].
THETA_COLOUR = 30.0
#: Grid step of the spectra [nm].
STEP = 0.05
#: The ASTM G173-03 extraterrestrial spectrum's range [nm].
SOLAR_RANGE = (280.0, 4000.0)
BANDS = ("B", "V", "R", "g", "r")


def solar_absorptance(name: str) -> tuple[float, float]:
    """``(alpha_s, covered share of the solar irradiance)`` of a material."""
    lo, hi = optical.OPTICAL_MATERIALS[name].wavelength_range()
    n = round((SOLAR_RANGE[1] - SOLAR_RANGE[0]) / STEP) + 1
    full = np.linspace(SOLAR_RANGE[0], SOLAR_RANGE[1], n)
    e_full = solar_spectrum(full).values
    inside = (full >= lo) & (full <= hi)
    wl, e = full[inside], e_full[inside]
    r = optical.specular_reflectance(name, wl)
    w = np.gradient(wl)  # trapezoid-like weights on a uniform grid
    alpha = 1.0 - np.sum(r * e * w) / np.sum(e * w)
    return float(alpha), float(np.sum(e * w) / np.sum(e_full * np.gradient(full)))


def colours(name: str) -> dict[str, float]:
    """B-V, V-R (Vega) and g-r (AB) of the sunlight reflected at the colour geometry."""
    wl = np.linspace(330.0, 900.0, round(570.0 / STEP) + 1)  # every band's support
    r = optical.specular_reflectance(name, wl, THETA_COLOUR)
    mean = band_weights(list(BANDS), wl, normalize=True).values @ r
    vega = sun_magnitudes(["B", "V", "R"], system="Vega").values
    ab = sun_magnitudes(["g", "r"], system="AB").values
    mag = dict(zip(BANDS, np.r_[vega, ab] - 2.5 * np.log10(mean), strict=True))
    return {"B-V": mag["B"] - mag["V"], "V-R": mag["V"] - mag["R"], "g-r": mag["g"] - mag["r"]}


def sun_colours() -> dict[str, float]:
    """The Sun's own colour indices in the same systems (a perfect mirror's)."""
    vega = sun_magnitudes(["B", "V", "R"], system="Vega").values
    ab = sun_magnitudes(["g", "r"], system="AB").values
    return {"B-V": vega[0] - vega[1], "V-R": vega[1] - vega[2], "g-r": ab[0] - ab[1]}


def table() -> str:
    """The Markdown table."""
    rows = [
        "| material | range [nm] | alpha_s | solar share | B-V | V-R | g-r |",
        "|---|---|---|---|---|---|---|",
    ]
    sun = sun_colours()
    rows.append(
        f"| the Sun (a perfect mirror) | - | - | - | {sun['B-V']:.3f} | {sun['V-R']:.3f} "
        f"| {sun['g-r']:.3f} |"
    )
    for name, m in optical.OPTICAL_MATERIALS.items():
        lo, hi = m.wavelength_range()
        alpha, share = solar_absorptance(name)
        c = colours(name)
        rows.append(
            f"| `{name}` | {lo:.0f}-{hi:.0f} | {alpha:.3f} | {share:.3f} | {c['B-V']:.3f} "
            f"| {c['V-R']:.3f} | {c['g-r']:.3f} |"
        )
    return "\n".join(rows)


def write(text: str, path: Path = GUIDE) -> None:
    """Put ``text`` between the colour-table markers of the guide page."""
    page = path.read_text(encoding="utf-8")
    new = re.sub(
        r"(<!-- colour-table -->\n)(?:.*?\n)?(<!-- /colour-table -->)",
        lambda m: m.group(1) + text + "\n" + m.group(2),
        page,
        flags=re.S,
    )
    path.write_text(new, encoding="utf-8")


if __name__ == "__main__":
    t = table()
    print(t)
    write(t)
