"""The extended solar spectrum ``astm_g173_extended`` (119.5 nm - 1 mm, issue 46)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import constants

from sbrdf_xr.errors import ValidationError
from sbrdf_xr.photometry import solar_spectrum, spectra
from sbrdf_xr.photometry._extended_sun import SUN_SOLID_ANGLE, _brightness_temperature
from sbrdf_xr.photometry.magnitude import sun_magnitudes
from sbrdf_xr.sources import planck

NAME = "astm_g173_extended"


def test_covers_0p25_to_25_um_and_equals_g173_inside_its_range():
    w, e, _ = spectra._solar_native(NAME)
    g, ge, _ = spectra._solar_native("astm_g173")
    assert w[0] < 250.0 and w[-1] >= 1e6
    assert np.all(np.diff(w) > 0) and np.all(e > 0)
    assert np.array_equal(np.interp(g, w, e), ge)  # node for node


def test_total_irradiance_is_the_g173_stated_total():
    """ASTM G173-03 states 1366.1 W m-2 for the whole AM0 spectrum; the 280-4000 nm
    table has 1347.9 of it, the extension supplies the rest to 0.1 %."""
    w, e, _ = spectra._solar_native(NAME)
    assert np.trapezoid(e, w) == pytest.approx(1366.1, rel=1e-3)


def test_continuation_is_planck_at_a_smooth_brightness_temperature():
    w, e, _ = spectra._solar_native(NAME)
    far = w > 10_500.0
    t_b = _brightness_temperature(w[far], e[far] / SUN_SOLID_ANGLE)
    assert np.all((t_b > 4000.0) & (t_b < 5100.0))  # the solar minimum-temperature region
    assert np.max(np.abs(np.diff(t_b))) < 5.0  # smooth: < 5 K per 1 % step in wavelength
    # the continuation is Planck's law (sources.planck) at that temperature
    i = np.searchsorted(w, 20_000.0)
    assert e[i] == pytest.approx(SUN_SOLID_ANGLE * planck(w[i], t_b[i - far.argmax()]), rel=1e-12)


def test_solid_angle_of_the_sun():
    r = 6.957e8 / constants.au
    assert SUN_SOLID_ANGLE == pytest.approx(np.pi * r**2, rel=1e-5)


def test_sun_v_minus_ks_against_willmer_2018():
    """V - Ks of the Sun (Vega): Willmer 2018 (ApJS 236, 47) gives M_V 4.81, M_Ks 3.27."""
    m = sun_magnitudes(["V", "twomass-Ks"], system="vega", solar=NAME).values
    assert m[0] - m[1] == pytest.approx(4.81 - 3.27, abs=0.03)


def test_g173_refusal_names_the_extended_spectrum():
    with pytest.raises(ValidationError, match="astm_g173_extended"):
        solar_spectrum([3000.0, 15000.0])
    sun = solar_spectrum([3000.0, 8000.0, 15000.0, 25000.0], solar=NAME)
    assert np.all(np.diff(sun.values) < 0) and sun.attrs["units"] == "W m-2 nm-1"
