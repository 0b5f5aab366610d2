"""The Earth's shadow on the WGS84 ellipsoid against an independent ray-ellipsoid computation."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.interpolate import CubicSpline
from scipy.optimize import brentq

from sbrdf_xr.errors import ObservationError
from sbrdf_xr.observing import earth_shadow as es
from sbrdf_xr.observing import observe
from sbrdf_xr.observing.timescales import skyfield_time, times

A = es.EARTH_EQUATORIAL_RADIUS_KM
B = A * (1 - es.WGS84_FLATTENING)
AXES = {"wgs84": np.array([A, A, B]), "sphere": np.array([A, A, A])}


def clearance(r, d, axes):
    """min over lambda >= 0 of Q(r + lambda d) - 1, Q the ellipsoid's quadratic form.

    Negative where the ray from ``r`` along ``d`` meets the ellipsoid (Earth-fixed axes).
    """
    w = 1.0 / axes**2
    qa = np.einsum("...i,...i->...", d * w, d)
    qb = np.einsum("...i,...i->...", d * w, r)
    qc = np.einsum("...i,...i->...", r * w, r)
    return np.where(qb < 0, qc - qb * qb / qa, qc) - 1.0


def disc_directions(u, angular_radius, rho, phi):
    """Unit directions at offsets ``rho * angular_radius`` [rad], azimuths ``phi``, from ``u``."""
    e1 = np.cross(u, [0.0, 0.0, 1.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(u, e1)
    off = angular_radius * rho
    return np.cos(off)[:, None] * u + np.sin(off)[:, None] * (
        np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2
    )


def test_point_sun_umbra_is_the_ray_ellipsoid_intersection():
    # A point Sun: the stretch maps lines to lines, so the model's step must be exactly
    # whether the ray to the Sun meets the ellipsoid (about a random pole).
    rng = np.random.default_rng(7)
    n = 20000
    pole = rng.normal(size=(n, 3))
    pole /= np.linalg.norm(pole, axis=1, keepdims=True)
    r = rng.normal(size=(n, 3))
    r *= (rng.uniform(6400.0, 12000.0, n) / np.linalg.norm(r, axis=1))[:, None]
    sun = rng.normal(size=(n, 3))
    sun *= 1.5e8 / np.linalg.norm(sun, axis=1, keepdims=True)
    f = es.sunlit_fraction(r, sun, sun_radius=0.0, pole=pole)
    # The same in a frame whose z is the pole (any x, y: the ellipsoid is axisymmetric).
    ex = np.cross(pole, rng.normal(size=(n, 3)))
    ex /= np.linalg.norm(ex, axis=1, keepdims=True)
    frame = np.stack([ex, np.cross(pole, ex), pole], axis=1)
    rf, sf = np.einsum("nij,nj->ni", frame, r), np.einsum("nij,nj->ni", frame, sun)
    g = clearance(rf, sf / np.linalg.norm(sf, axis=1, keepdims=True), AXES["wgs84"])
    inside = np.einsum("ni,ni->n", rf / AXES["wgs84"], rf / AXES["wgs84"]) < 1
    keep = (np.abs(g) > 1e-9) & ~inside
    assert keep.sum() > 0.9 * n and 0.05 < (g[keep] < 0).mean() < 0.95
    np.testing.assert_array_equal(f[keep], np.where(g[keep] < 0, 0.0, 1.0))


@pytest.fixture(scope="module")
def exit_window():
    """The shadow exit of the built-in pass, sampled at 1 s, with the GCRS -> ITRS rotation."""
    from skyfield.framelib import itrs

    base = observe.canx1_pass()
    t = times("2024-03-17T01:20:30", "2024-03-17T01:21:10", 1.0)
    obs = dataclasses.replace(base, times=t)
    ctx = obs.context()
    rot = np.moveaxis(itrs.rotation_at(skyfield_time(t)), -1, 0)  # (n, 3, 3)
    return obs, t, ctx.position, ctx.sun, rot


def independent_edges(t, r, sun, rot, earth):
    """Umbra and penumbra exit [s from t[0]] by rays to 4096 points of the solar limb."""
    secs = (t - t[0]).astype(np.int64) / 1e9
    spl = CubicSpline(secs, np.concatenate([r, sun, rot.reshape(-1, 9)], axis=1), axis=0)
    phi = np.linspace(0.0, 2 * np.pi, 4096, endpoint=False)

    def limb(x):
        v = spl(x)
        m = v[6:].reshape(3, 3)
        ri, si = m @ v[:3], m @ v[3:6]
        d = np.linalg.norm(si)
        dirs = disc_directions(si / d, np.arcsin(es.SUN_RADIUS_KM / d), np.ones_like(phi), phi)
        return clearance(ri, dirs, AXES[earth])

    umbra = brentq(lambda x: limb(x).max(), secs[0], secs[-1], xtol=1e-6)
    penumbra = brentq(lambda x: limb(x).min(), secs[0], secs[-1], xtol=1e-6)
    return umbra, penumbra, spl


def test_canx1_shadow_exit_against_ray_ellipsoid(exit_window):
    obs, t, r, sun, rot = exit_window
    secs = lambda w: (w - t[0]).astype(np.int64) / 1e9  # noqa: E731
    rows = {}
    for earth in es.EARTH_MODELS:
        g = dataclasses.replace(obs, earth=earth).geometry()
        model = (
            secs(np.datetime64(g.attrs["umbra_exit"])),
            secs(np.datetime64(g.attrs["penumbra_exit"])),
        )
        ev = es.shadow_events(t, r, sun, earth=earth, pole=rot[:, 2, :])
        exact = (secs(ev["umbra_exit"][0]), secs(ev["penumbra_exit"][0]))
        ind = independent_edges(t, r, sun, rot, earth)
        rows[earth] = (exact, ind[:2])
        print(
            f"{earth}: umbra exit {ev['umbra_exit'][0]} "
            f"(ray-ellipsoid {ind[0] - exact[0]:+.2e} s), "
            f"penumbra exit {ev['penumbra_exit'][0]} ({ind[1] - exact[1]:+.2e} s)"
        )
        # The attributes carry the same times to the millisecond.
        np.testing.assert_allclose(model, exact, atol=1e-3)
        # Edges where the tangent rays are: the first-order solar extent of the model
        # leaves 1.6e-5 of the Sun's radius (< 1e-4 s at 5e-4 rad s-1 of the discs' motion),
        # the 4096-point limb 3e-7 of it, the root finders 1e-6 s; found within 5e-6 s.
        np.testing.assert_allclose(exact, ind[:2], atol=1e-4)
        assert g.attrs["penumbra_entry"] == "" and g.attrs["umbra_entry"] == ""
    shift = np.subtract(rows["wgs84"][1], rows["sphere"][1])
    print(f"WGS84 - sphere: umbra exit {shift[0]:+.3f} s, penumbra exit {shift[1]:+.3f} s")
    assert np.all(np.abs(shift) > 1.0)  # the flattening matters at this level

    # The GCRS z axis as the pole (off the ITRS z by precession, 0.13 degree in 2024).
    ev = es.shadow_events(t, r, sun, earth="wgs84")
    off = [
        secs(ev[k][0]) - rows["wgs84"][0][i] for i, k in enumerate(("umbra_exit", "penumbra_exit"))
    ]
    print(f"pole = GCRS z instead of ITRS z: {off[0]:+.3f} s, {off[1]:+.3f} s")


def test_canx1_penumbra_fraction_against_ray_ellipsoid(exit_window):
    # Inside the penumbra: the visible fraction of 20000 rays spread evenly (by area) over
    # the solar disc.  The model takes the stretched Sun's slightly elliptic disc (axis
    # ratio k = a/b = 1.0034) as a circle of its extent towards the Earth: within
    # k - 1 of the disc's area; the sampling adds ~1e-3 (found: 4e-4).
    _, t, r, sun, rot = exit_window
    _, _, spl = independent_edges(t, r, sun, rot, "wgs84")
    n = 20000
    rho = np.sqrt((np.arange(n) + 0.5) / n)
    phi = np.arange(n) * np.pi * (3 - np.sqrt(5))
    worst = 0.0
    for x in np.linspace(10.5, 24.5, 15):
        v = spl(x)
        m = v[6:].reshape(3, 3)
        ri, si = m @ v[:3], m @ v[3:6]
        d = np.linalg.norm(si)
        dirs = disc_directions(si / d, np.arcsin(es.SUN_RADIUS_KM / d), rho, phi)
        truth = (clearance(ri, dirs, AXES["wgs84"]) > 0).mean()
        model = float(es.sunlit_fraction(v[:3], v[3:6], pole=m[2]))
        worst = max(worst, abs(model - truth))
    print(f"penumbra sunlit fraction, WGS84 model - ray-ellipsoid: worst {worst:.2e}")
    assert worst < 3e-3, worst


def test_bad_earth_model():
    with pytest.raises(ObservationError, match="allowed: wgs84, sphere"):
        es.sunlit_fraction([7000.0, 0, 0], [1.5e8, 0, 0], earth="oblate")
    with pytest.raises(ObservationError, match="earth"):
        dataclasses.replace(observe.canx1_pass(), earth="flat")
    obs = observe.observation_from_dict(
        {
            "orbit": "canx1-example",
            "site": "mont-megantic",
            "times": ["2024-03-17T01:22:00"],
            "earth": "sphere",
        }
    )
    assert obs.earth == "sphere"
