"""Measured data for the inversions: magnitudes back to band signal, in their system."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from sbrdf_xr import invert
from sbrdf_xr.errors import InversionError
from sbrdf_xr.photometry import band_signal, magnitudes

BANDS = ["V", "R", "I"]


@pytest.mark.parametrize("system", ["AB", "Vega"])
def test_magnitudes_to_signal_inverts_magnitudes(per_material, system):
    """Magnitudes of a simulated spectrum (:func:`magnitudes` at 1500 km, in ``system``)
    turn back into its band signal (:func:`band_signal`) to rounding, with the system
    the light curve states; read in the other system, the colours are off by the
    difference of the Sun's colours in the two (tenths of a magnitude)."""
    spectrum = per_material.isel(geometry=4).sum("material")
    mags = magnitudes(spectrum, BANDS, range=1500.0, system=system)
    lc = xr.Dataset(
        {"magnitude": ("band", mags.values), "uncertainty": ("band", np.full(len(BANDS), 0.01))},
        coords={"band": BANDS},
        attrs={"magnitude_system": system},
    )
    signal, sigma = invert.magnitudes_to_signal(lc, 1500.0)
    np.testing.assert_allclose(signal.values, band_signal(spectrum, BANDS).values, rtol=1e-12)
    assert signal.attrs["magnitude_system"] == system
    np.testing.assert_allclose(sigma.values, signal.values * np.log(10) / 2.5 * 0.01)
    other = "AB" if system == "Vega" else "Vega"
    wrong, _ = invert.magnitudes_to_signal(lc, 1500.0, system=other)
    colour_error = 2.5 * np.log10(wrong.values / signal.values)
    assert np.ptp(colour_error) > 0.3
    with pytest.raises(InversionError, match="system 'ST' unknown"):
        invert.magnitudes_to_signal(lc, 1500.0, system="ST")
