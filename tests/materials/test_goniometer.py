"""Tests of the virtual goniospectrometer (paper 000 Fig. 6 / Table 1)."""

from __future__ import annotations

import numpy as np
import pytest

from sbrdf_xr import testing
from sbrdf_xr.errors import ValidationError
from sbrdf_xr.materials import goniometer as G
from sbrdf_xr.materials import tables as material

TABLE1_PHI_MAX = (0.6, 1.2, 1.5, 2.1, 1.5, 0.9, 0.9)


def test_paper_scheme_reproduces_table1():
    """Aluminium at theta_i = 50 deg: rows and phi columns exactly as in Table 1."""
    dt, ph, ref = G.paper_scheme(50.0, -44.0, 38.0, TABLE1_PHI_MAX)
    assert dt.size == 30 and ref.sum() == 9
    rows = dt[:28].reshape(7, 4)
    np.testing.assert_allclose(rows[:, 0], [28.5, 19.0, 9.5, 0.0, -11.0, -22.0, -33.0])
    np.testing.assert_allclose(ph[:28].reshape(7, 4)[3], [0.0, 0.7, 1.4, 2.1])
    np.testing.assert_allclose(ph[:28].reshape(7, 4)[0], [0.0, 0.2, 0.4, 0.6])
    np.testing.assert_array_equal(ref[:28].reshape(7, 4)[:, 3], True)  # phi_max column
    np.testing.assert_allclose(dt[28:], [38.0, -44.0])
    assert ref[28:].all()


def test_extents_are_references_only_where_the_signal_is_in_the_noise():
    wl = np.linspace(400, 1100, 8)
    # A narrow lobe on a floor above the noise: phi and far-side extents hit the apparatus.
    f = testing.lobe_function(wl, diffuse=0.5, peak=2.0, width=3.0)
    dt_min, dt_max, phi_max, in_noise = G.scheme_extents(f, 40.0, noise_floor=0.01)
    assert dt_max == pytest.approx(88.0 - 40.0) and not in_noise.any()
    # Without a floor the lobe falls into the noise: every extent is a reference point.
    f0 = testing.lobe_function(wl, diffuse=0.0, peak=2.0, width=3.0)
    dt_min, dt_max, phi_max, in_noise = G.scheme_extents(f0, 40.0, noise_floor=0.02)
    assert in_noise.all() and 5 < dt_max < 20 and -20 < dt_min < -5
    assert np.all(phi_max < 20)


def test_measure_noise_and_references():
    wl = np.linspace(400, 1100, 50)
    f = testing.lobe_function(wl, diffuse=0.0, peak=2.0, width=4.0)
    clean = G.measure(f, wl, (20.0, 45.0), noise_floor=0.02)
    noisy = G.measure(f, wl, (20.0, 45.0), noise_floor=0.02, noise=0.05, seed=3)
    ref = clean.reference.values
    assert ref.sum() == 18 and np.all(clean.measured_sbrdf.values[ref] == 0)
    ratio = noisy.measured_sbrdf.values[~ref] / clean.measured_sbrdf.values[~ref]
    # 1050 samples of N(1, 0.05): the sample std is within 10 % of 0.05 (~ 4.6 sigma).
    assert np.std(ratio) == pytest.approx(0.05, rel=0.1)
    again = G.measure(f, wl, (20.0, 45.0), noise_floor=0.02, noise=0.05, seed=3)
    np.testing.assert_array_equal(again.measured_sbrdf.values, noisy.measured_sbrdf.values)
    material.validate_measurements(noisy)


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"noise": -0.1}, "noise"),
        ({"noise_floor": 0.0}, "noise_floor"),
        ({"dynamic_range": 2.0}, "dynamic_range"),
    ],
)
def test_measure_bad_input(kw, match):
    wl = np.linspace(400, 1100, 5)
    with pytest.raises(ValidationError, match=match):
        G.measure(testing.lobe_function(wl), wl, (30.0,), **kw)


def test_scheme_needs_room_on_both_sides_and_seven_rows():
    with pytest.raises(ValidationError, match="need one extent per row"):
        G.paper_scheme(30.0, -10.0, 10.0, [1.0, 2.0])
    with pytest.raises(ValidationError, match="min < 0 < max"):
        G.paper_scheme(30.0, 5.0, 10.0, TABLE1_PHI_MAX)
