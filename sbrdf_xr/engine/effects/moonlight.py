"""Moonlight: sunlight reflected by the Moon onto the spacecraft, a second distant source.

For an observation only: at every time the Moon's apparent position comes from the JPL
DE421 ephemeris of the ``skyfield-data`` package (skyfield's geocentric astrometric Moon
on the knots of :func:`~sbrdf_xr.observing.timescales.spline_knots`, moved to the
spacecraft, then aberrated by the spacecraft's barycentric velocity: within 0.01 arcsec
of astropy's ``get_body`` on the same ephemeris), and its light from its phase angle and
distance
(:func:`sbrdf_xr.sources.moonlight_irradiance_ratio`: Allen's phase law as used by
Krisciunas & Schaefer 1991, a grey Moon, so the solar spectrum scaled).  The Moon is a
distant source from its centre's direction (its radius is 0.26 degree from the Earth).
Its light is scaled by

* the fraction of the lunar disc the Earth does not hide from the spacecraft (the Moon
  below the spacecraft's horizon is dark), and
* the fraction of the solar disc seen from the Moon's centre (a lunar eclipse: 0 in the
  umbra; the light the Earth's atmosphere refracts into the umbra, a few ten-thousandths,
  is left out),

both by :func:`sbrdf_xr.observing.earth_shadow.sunlit_fraction` with the observation's
Earth model.  The light the facets reflect is ``signal_moonlight``, per unit solar
irradiance, and it adds to ``band_signal``.

>>> import trimesh
>>> from sbrdf_xr import Scene, load_spacecraft
>>> from sbrdf_xr.materials.schema import lambertian
>>> from sbrdf_xr.observing import canx1_pass
>>> box = load_spacecraft(trimesh.creation.box(), material="grey")
>>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
>>> scene = Scene(box, {"grey": grey}, observation=canx1_pass(), effects=("moonlight",))
>>> plan = scene.plan()
>>> plan.effects
('sunlight', 'eclipse', 'moonlight')
>>> print(dict(plan.steps)["moonlight"])  # a quarter Moon, 14 + 2.6 magnitudes below the Sun
... # doctest: +ELLIPSIS +NORMALIZE_WHITESPACE
the Moon of DE421 at every time, phase 92-92 deg: irradiance 2.16e-07-2.17e-07 of the Sun's
(Allen's phase law, Krisciunas & Schaefer 1991; grey), ...; hidden by the Earth at 0 times,
in its shadow at 0
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import constants

from ..._names import WAVELENGTH
from ...errors import renamed_keywords
from ...geometry import rotation_matrices
from ...sources import MOON_RADIUS_KM, moonlight_irradiance_ratio
from ...units import to_unit
from .base import BlockInputs, Decision, Effect, Output, PlanInputs, facet_fraction, reflected

if TYPE_CHECKING:
    import xarray as xr

    from ..views import PlanView, SceneView

__all__ = ["EFFECT", "SIGNAL", "moon_from_spacecraft"]

#: The light the facets reflect from the Moon.
SIGNAL = Output(
    "signal_moonlight",
    (WAVELENGTH,),
    True,
    "m2 sr-1",
    "radiometric signal of the sunlight reflected by the Moon (a grey Moon), per unit solar "
    "irradiance",
)

_C_KM_S = constants.c / 1e3


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _angle(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    cos = np.einsum("ni,ni->n", _unit(u), _unit(v))
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def _aberrated(u: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """Unit vectors ``u`` seen by an observer moving at ``beta = V / c`` (barycentric):
    the relativistic aberration formula (Explanatory Supplement to the Astronomical
    Almanac, Seidelmann 1992, section 3.252)."""
    ub = np.einsum("ni,ni->n", u, beta)[:, None]
    inv_gamma = np.sqrt(1.0 - np.einsum("ni,ni->n", beta, beta))[:, None]
    return _unit((inv_gamma * u + (1.0 + ub / (1.0 + inv_gamma)) * beta) / (1.0 + ub))


@renamed_keywords(position_km="position", sun_km="sun", velocity_km_s="velocity")
def moon_from_spacecraft(
    times: ArrayLike,
    position: ArrayLike,
    velocity: ArrayLike,
    sun: ArrayLike,
    earth: str = "wgs84",
) -> dict[str, NDArray[np.float64]]:
    """The Moon seen from a spacecraft, and its light there relative to the Sun's, per time.

    Parameters
    ----------
    times : array_like of datetime64, shape (n,)
        UTC times.
    position : array_like, shape (n, 3)
        Geocentric position of the spacecraft (GCRS) [km].
    velocity : array_like, shape (n, 3)
        Geocentric velocity of the spacecraft (GCRS) [km s-1].
    sun : array_like, shape (n, 3)
        Apparent position of the Sun relative to the spacecraft [km].
    earth : {"wgs84", "sphere"}
        The Earth that hides the Moon and casts its shadow.

    A Quantity is converted to the unit of its argument.

    Returns
    -------
    dict of str to ndarray
        ``moon_km`` (n, 3): apparent position of the Moon relative to the spacecraft
        [km]; ``phase_angle`` (n,): Sun-Moon-spacecraft angle [degree]; ``visible``: the
        fraction of the lunar disc above the Earth's limb [1]; ``sunlit``: the fraction of
        the solar disc seen from the Moon's centre [1] (0 in a total lunar eclipse);
        ``ratio``: the Moon's irradiance at the spacecraft over the Sun's, times
        ``visible`` and ``sunlit`` [1].

    Examples
    --------
    During the total lunar eclipse of 2022 November 8 (greatest at 10:59 UTC) the Moon is
    in the Earth's umbra; three hours earlier it is full and bright.  A spacecraft
    7000 km from the Earth's centre towards the Moon sees it, one on the other side does
    not:

    >>> import numpy as np
    >>> from sbrdf_xr.engine.effects.moonlight import moon_from_spacecraft
    >>> from sbrdf_xr.observing import skyfield_data
    >>> ts, eph = skyfield_data()
    >>> t = np.array(["2022-11-08T07:59", "2022-11-08T10:59"], dtype="datetime64[ns]")
    >>> earth = eph["earth"].at(ts.utc(2022, 11, 8, [7, 10], 59))
    >>> sun = earth.observe(eph["sun"]).apparent().position.km.T  # from the Earth [km]
    >>> moon = earth.observe(eph["moon"]).apparent().position.km.T
    >>> r = 7000.0 * moon / np.linalg.norm(moon, axis=1, keepdims=True)  # towards the Moon
    >>> near = moon_from_spacecraft(t, r, np.zeros((2, 3)), sun - r)
    >>> near["sunlit"].tolist(), near["visible"].tolist(), near["phase_angle"].round(1).tolist()
    ([1.0, 0.0], [1.0, 1.0], [1.5, 0.2])
    >>> [f"{x:.2e}" for x in near["ratio"]]  # full Moon, then eclipsed
    ['2.40e-06', '0.00e+00']
    >>> far = moon_from_spacecraft(t, -r, np.zeros((2, 3)), sun + r)
    >>> far["visible"].tolist(), far["ratio"].tolist()
    ([0.0, 0.0], [0.0, 0.0])
    """
    from scipy.interpolate import CubicSpline
    from skyfield.framelib import itrs

    from ...observing import skyfield_data, skyfield_utc, spline_knots, sunlit_fraction

    t64 = np.asarray(times, dtype="datetime64[ns]")
    r = np.asarray(to_unit(position, "km", "position"), dtype=np.float64)
    v = np.asarray(to_unit(velocity, "km / s", "velocity"), dtype=np.float64)
    sun_v = np.asarray(to_unit(sun, "km", "sun"), dtype=np.float64)
    _, eph = skyfield_data()
    start = t64.min()
    secs, knots = spline_knots(np.array([start, t64.max()]))
    if knots.size < t64.size:  # a dense series: skyfield on the knots, splined
        tk = skyfield_utc(start + (knots * 1e9).astype("timedelta64[ns]"))
    else:  # a few times (or far apart): skyfield at each
        tk = skyfield_utc(t64)
    earth_k = eph["earth"].at(tk)
    moon_k = earth_k.observe(eph["moon"]).position.km.T  # astrometric: light time only
    pole_k = np.moveaxis(itrs.rotation_at(tk)[2], 0, -1)  # the ITRS z axis in the GCRS
    earth_v = earth_k.velocity.km_per_s.T
    if knots.size < t64.size:
        secs = (t64 - start).astype(np.int64) / 1e9
        moon_k, earth_v, pole_k = (
            CubicSpline(knots, x, axis=0)(secs) for x in (moon_k, earth_v, pole_k)
        )
    moon_geo, pole = moon_k, _unit(pole_k)
    rel = moon_geo - r  # the parallax, then the aberration by the spacecraft's own motion
    d = np.linalg.norm(rel, axis=1)
    moon = d[:, None] * _aberrated(rel / d[:, None], (earth_v + v) / _C_KM_S)
    phase = _angle(sun_v - moon, -moon)
    visible = sunlit_fraction(r, moon, sun_radius=MOON_RADIUS_KM, earth=earth, pole=pole)
    sunlit = sunlit_fraction(moon_geo, sun_v + r - moon_geo, earth=earth, pole=pole)
    sun_ratio = np.linalg.norm(sun_v, axis=1) / np.linalg.norm(sun_v - moon, axis=1)
    ratio = moonlight_irradiance_ratio(phase, d, sun_ratio) * visible * sunlit
    return {
        "moon_km": moon,
        "phase_angle": phase,
        "visible": np.asarray(visible, dtype=np.float64),
        "sunlit": np.asarray(sunlit, dtype=np.float64),
        "ratio": np.asarray(ratio, dtype=np.float64),
    }


def _geometry(scene: SceneView, observed: xr.Dataset | None) -> dict[str, np.ndarray]:
    obs = scene.observation
    assert obs is not None and observed is not None  # the effect needs an observation
    ctx = obs.context()
    r, v, sun = ctx.position, ctx.velocity, ctx.sun
    assert r is not None and v is not None and sun is not None  # an observation's context has all
    m = moon_from_spacecraft(obs.times, r, v, sun, obs.earth)
    rot = rotation_matrices(observed["quaternion"].values)  # body -> GCRS
    to_moon = np.einsum("nji,nj->ni", rot, _unit(m["moon_km"]))
    return {
        "to_moon": np.ascontiguousarray(to_moon),
        "moon_scale": m["ratio"],
        "moon_phase_angle": m["phase_angle"],
        "moon_visible": m["visible"],
        "moon_sunlit": m["sunlit"],
    }


def _plan(inputs: PlanInputs) -> Decision:
    src = inputs.scene.geometry.sources
    scale, phase = src["moon_scale"], src["moon_phase_angle"]
    if not scale.size:
        return Decision(True, "the Moon of DE421: no time to evaluate")
    hidden = int(np.sum(src["moon_visible"] <= 0))
    dark = int(np.sum(src["moon_sunlit"] <= 0))
    return Decision(
        True,
        f"the Moon of DE421 at every time, phase {np.min(phase):.0f}-{np.max(phase):.0f} deg: "
        f"irradiance {np.min(scale):.3g}-{np.max(scale):.3g} of the Sun's (Allen's phase "
        "law, Krisciunas & Schaefer 1991; grey), a second distant source; "
        f"hidden by the Earth at {hidden} times, in its shadow at {dark}",
    )


def _contribute(plan: PlanView, block: BlockInputs) -> dict[str, np.ndarray]:
    to_moon = block.sources["to_moon"]
    frac = facet_fraction(plan, to_moon, block.to_observer)
    r = reflected(plan, block, to_moon, frac, False)
    scale = block.sources["moon_scale"]
    return {"signal_moonlight": (scale[:, None] * r.signal).astype(r.signal.dtype)}


#: Sunlight reflected by the Moon.
EFFECT = Effect(
    "moonlight",
    title="moonlight",
    description="sunlight reflected by the Moon (DE421, Allen's phase law), a second distant "
    "source; observations only",
    when="asked",
    source="moon",
    needs=("observation",),
    outputs=("signal_moonlight", "band_signal"),
    declares=(SIGNAL,),
    band=("signal_moonlight",),
    plan=_plan,
    contribute=_contribute,
    geometry=_geometry,
)
