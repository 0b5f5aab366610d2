"""Recovery of held-out spin states on real passes, over noise draws.

Two cases whose truths were drawn once (seeded) and never used to choose the fit's
defaults: CanX-1 over Mont Mégantic on the built-in pass (the sunlit four minutes, the
observer direction swinging 91 degrees), and a box-wing over the Dominion Astrophysical
Observatory on another pass of the same orbit (four minutes, fully sunlit).  Fluxes in V,
R, I at 1 s with 2 % noise (plus 0.2 % of the median, so that dark moments keep a finite
uncertainty).  The candidate periods span +-15 % around a guess within 10 % of the truth.
The specification: axis within 1 degree and period within 3 sigma in >= 95 % of draws.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from sbrdf_xr import invert
from sbrdf_xr.geometry import rotation_matrices
from sbrdf_xr.observing import Inertial, Observation, Orbit, Site, Spin
from sbrdf_xr.observing.observe import canx1_pass
from sbrdf_xr.observing.timescales import times as utc_times


def _truth(seed: int, axis_body) -> tuple[Spin, np.ndarray, float]:
    """A spin law of random inertial axis, period in [60, 120] s and phase; a guess of the
    period within 10 % of it."""
    rng = np.random.default_rng(seed)
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    period, phase = rng.uniform(60.0, 120.0), rng.uniform(0.0, 360.0)
    law = invert.spin_model(axis_body, axis, period, phase)
    return law, axis, period * rng.uniform(0.9, 1.1)


def _case(name: str, box_wing=None):
    if name == "canx1":
        axis_body = np.random.default_rng(17).normal(size=3)
        axis_body /= np.linalg.norm(axis_body)
        law, axis, guess = _truth(7, axis_body)
        obs = dataclasses.replace(canx1_pass(), attitude=law)
        obs = dataclasses.replace(obs, times=obs.times[61:301])  # sunlit: 240 s
    else:
        law, axis, guess = _truth(8, (0.0, 0.0, 1.0))
        obs = Observation(
            Orbit.from_catalog("canx1-example"),
            Site.from_catalog("dominion-astrophysical"),
            utc_times("2024-03-15T03:46:00", "2024-03-15T03:49:59", 1.0),
            law,
            name="dao-pass",
        )
    q = law.initial.quaternions([0.0])
    assert isinstance(law.initial, Inertial)
    truth_axis = rotation_matrices(q)[0] @ (
        np.asarray(law.axis_body) / np.linalg.norm(law.axis_body)
    )
    np.testing.assert_allclose(truth_axis, axis, atol=1e-9)
    periods = invert.period_grid(0.85 * guess, 1.15 * guess, 240.0, 16)
    return obs, periods


@pytest.mark.parametrize("name", ["canx1", "box-wing"])
def test_recovery_two_draws(name, sc, box_wing):
    """The default run: two draws of each held-out case."""
    obs, periods = _case(name)
    body = sc if name == "canx1" else box_wing
    study = invert.spin_recovery(body, obs, periods=periods, n_draws=2, seed=11)
    assert study.attrs["success_rate"] == 1.0, study.to_dataframe()


@pytest.mark.slow
@pytest.mark.parametrize("name", ["canx1", "box-wing"])
def test_recovery_study(name, sc, box_wing):
    """20 draws of each held-out case: success in >= 95 % (19 of 20)."""
    obs, periods = _case(name)
    body = sc if name == "canx1" else box_wing
    study = invert.spin_recovery(body, obs, periods=periods, n_draws=20, seed=12)
    table = study.to_dataframe()
    print(
        f"\n{name}: truth {study.attrs['truth_axis']}, P = {study.attrs['truth_period']:.4f} s; "
        f"load {study.attrs['load_average']}\n{table.to_string()}"
    )
    assert study.attrs["success_rate"] >= 0.95, table
