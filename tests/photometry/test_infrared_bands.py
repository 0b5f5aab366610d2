"""Infrared bands and in-band quantities (sbrdf_xr.photometry.infrared, issue 46)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import integrate

from sbrdf_xr.errors import ValidationError
from sbrdf_xr.photometry import filters, solar_spectrum
from sbrdf_xr.photometry.inband import in_band
from sbrdf_xr.photometry.infrared import BOXES, INFRARED_BANDS, band_curve
from sbrdf_xr.photometry.magnitude import sun_magnitudes


def test_every_infrared_band_resolves():
    f = filters(["J", "H", "Ks", *INFRARED_BANDS])
    assert f.sizes["band"] == 3 + len(INFRARED_BANDS)
    assert f["filter"].values[:3].tolist() == ["twomass-J", "twomass-H", "twomass-Ks"]
    for name, (lo, hi, _) in BOXES.items():
        wl, r, _ = band_curve(name)
        assert wl[0] == lo and wl[-1] == hi and r.max() == 1.0


def test_unknown_band_is_a_named_error():
    with pytest.raises(ValidationError, match="not an infrared band"):
        band_curve("Q")


def test_in_band_solar_irradiance_in_mwir_against_quadrature():
    """The Sun's irradiance in 3-5 um [W m-2]: trapezoid on 10-nm steps vs adaptive quad
    of the same (linear) spectrum; the ramps remove 1 nm x E at each edge (half each)."""
    sun = solar_spectrum(
        np.arange(3000.0, 5001.0, 10.0), solar="astm_g173_extended", method="linear"
    )
    got = float(in_band(sun, ["MWIR"])[0])
    wl, e = sun.wavelength.values, sun.values
    ref = integrate.quad(lambda x: np.interp(x, wl, e), 3000, 5000, limit=400, points=wl[1:-1])[0]
    ref -= 0.5 * (e[0] + e[-1])
    assert got == pytest.approx(ref, rel=1e-6)
    assert 20.0 < got < 30.0  # ~1.8 % of the solar constant
    assert in_band(sun, ["MWIR"]).attrs["units"] == "W m-2"


def test_in_band_needs_a_spectral_density():
    sun = solar_spectrum(np.arange(3000.0, 5001.0, 10.0), solar="astm_g173_extended")
    sun.attrs["units"] = "W m-2"
    with pytest.raises(ValidationError, match="units per nm"):
        in_band(sun, ["MWIR"])


def test_infrared_magnitudes_of_the_sun_are_defined():
    """AB and Vega magnitudes past 4 um (Vega's CALSPEC spectrum reaches 300 um)."""
    ab = sun_magnitudes(["LWIR", "W1"], system="AB", solar="astm_g173_extended").values
    vega = sun_magnitudes(["LWIR", "W1"], system="vega", solar="astm_g173_extended").values
    assert np.all(np.isfinite(ab)) and np.all(np.isfinite(vega))
    # the Sun is redder than Vega: V - W1 (Vega) ~ 1.6 (Willmer 2018: M_V 4.81, M_W1 3.26)
    v = sun_magnitudes(["V"], system="vega", solar="astm_g173_extended").values[0]
    assert v - vega[1] == pytest.approx(4.81 - 3.26, abs=0.05)
