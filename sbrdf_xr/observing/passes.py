"""Visible passes: when an observer can measure a spacecraft (up, sunlit, sky dark).

:func:`visible_passes` finds, between two UTC times, the passes of a spacecraft (from
elements, an :class:`~sbrdf_xr.observing.orbits.Orbit`, or an ephemeris, an
:class:`~sbrdf_xr.observing.ephemeris.Ephemeris`) over a site, and the part of each an
observer can measure: the spacecraft above ``min_elevation_deg``, sunlit (at least half
of the solar disc seen from it: the centre of the Sun above the Earth's limb,
the edge of skyfield's ``is_sunlit`` and the middle of the penumbra of
:mod:`sbrdf_xr.observing.earth_shadow`), and the site's Sun below the twilight's
elevation (:data:`TWILIGHTS`).  The geometry is that of
:class:`~sbrdf_xr.observing.observation.Observation` on a grid of ``step_s``; every edge
(rise, set, shadow entry and exit, the twilight) is refined by bisection to
:data:`EDGE_TOL_S`, the culmination by golden-section search.

Peak magnitude: a stated model, a diffusely reflecting (Lambert) sphere of cross-section
``cross_section_m2`` and Bond albedo ``albedo`` (geometric albedo ``2 albedo / 3``),
``m = m_sun - 2.5 log10(p A Phi(alpha) f / d^2) + 5 log10(r_sun / 1 au)`` with the
Lambert phase function ``Phi`` (Russell 1916, ApJ 43, 173; :func:`~sbrdf_xr.photometry.
standard.lambert_sphere_phase`), the sunlit fraction ``f``, the range ``d`` [m] and the
Sun's V magnitude :data:`~sbrdf_xr.sources.SUN_V_MAGNITUDE`, the brightest value on a
1-s grid over the visible part.  A body and its materials give the real magnitude through
a scene; this is the planning number.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from ..errors import ObservationError, renamed_keywords
from ..photometry.standard import lambert_sphere_phase
from ..sources import SUN_V_MAGNITUDE
from ..units import to_unit
from .ephemeris import Ephemeris
from .observation import Observation
from .orbits import AU_KM, Orbit, Site
from .timescales import to_datetime64

__all__ = ["EDGE_TOL_S", "TWILIGHTS", "visible_passes"]

#: Sun elevation at the site below which the sky counts as dark enough [degree].
TWILIGHTS = {"civil": -6.0, "nautical": -12.0, "astronomical": -18.0, "night": -18.0}
#: Precision of the refined edge times [s].
EDGE_TOL_S = 1e-3

_NS = np.timedelta64(1, "ns")
_IDENTITY = {"law": "inertial", "q": [0.0, 0.0, 0.0, 1.0]}


def _geometry(source: Any, site: Any, t: np.ndarray) -> xr.Dataset:
    site, earth = site if isinstance(site, tuple) else (site, "wgs84")
    obs = Observation(source, site, t, _IDENTITY, min_elevation=-90.0, earth=earth)
    return obs.geometry(on_unobservable="keep")


def _conditions(g: xr.Dataset, min_el: float, dark: float) -> dict[str, np.ndarray]:
    return {
        "up": g.elevation.values - min_el,
        "sunlit": g.sunlit_fraction.values - 0.5,
        "dark": dark - g.site_sun_elevation.values,
    }


def _refine(source: Any, site: Any, lo: np.ndarray, hi: np.ndarray, key: str, args: Any) -> Any:
    """Bisection of the sign change of condition ``key`` in each [lo, hi] (datetime64)."""
    lo, hi = lo.copy(), hi.copy()
    if not lo.size:
        return lo
    f_lo = _conditions(_geometry(source, site, lo), *args)[key] > 0
    while ((hi - lo) / _NS).max() > EDGE_TOL_S * 1e9:
        mid = lo + (hi - lo) // 2
        keep = np.concatenate([[True], np.diff(mid) > np.timedelta64(0, "ns")])
        f = np.empty(mid.size, dtype=bool)
        f[keep] = _conditions(_geometry(source, site, mid[keep]), *args)[key] > 0
        f[~keep] = f[np.maximum.accumulate(np.where(keep, np.arange(mid.size), 0))][~keep]
        same = f == f_lo
        lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
    return lo + (hi - lo) // 2


def _intervals(t: np.ndarray, ok: np.ndarray, edges: dict[int, np.datetime64]) -> list[Any]:
    """Intervals where ``ok`` holds on the grid, with refined edges (by grid index)."""
    out = []
    k = 0
    while k < t.size:
        if not ok[k]:
            k += 1
            continue
        j = k
        while j + 1 < t.size and ok[j + 1]:
            j += 1
        out.append((edges.get(k - 1, t[k]) if k else t[0], edges.get(j, t[j])))
        k = j + 1
    return out


def _edges(source: Any, site: Any, t: np.ndarray, val: np.ndarray, key: str, args: Any) -> Any:
    ok = val > 0
    idx = np.flatnonzero(ok[1:] != ok[:-1])
    refined = _refine(source, site, t[idx], t[idx + 1], key, args)
    return ok, dict(zip(idx.tolist(), refined, strict=True))


def _culmination(source: Any, site: Any, a: np.datetime64, b: np.datetime64) -> np.datetime64:
    """Time of the highest elevation in [a, b] by golden-section search."""
    g = (np.sqrt(5.0) - 1.0) / 2.0
    lo, hi = a, b
    while (hi - lo) / _NS > EDGE_TOL_S * 1e9:
        span = (hi - lo) / _NS
        x1 = hi - np.timedelta64(int(g * span), "ns")
        x2 = lo + np.timedelta64(int(g * span), "ns")
        if x2 <= x1:
            break
        el = _geometry(source, site, np.array([x1, x2])).elevation.values
        lo, hi = (x1, hi) if el[1] > el[0] else (lo, x2)
    return lo + (hi - lo) // 2


def _intersect(a: list[Any], b: list[Any]) -> list[Any]:
    out = []
    for a0, a1 in a:
        for b0, b1 in b:
            lo, hi = max(a0, b0), min(a1, b1)
            if hi > lo:
                out.append((lo, hi))
    return out


def _magnitude(g: xr.Dataset, cross_section_m2: float, albedo: float) -> np.ndarray:
    p = 2.0 * albedo / 3.0
    d_m = g.range.values * 1e3
    flux = p * cross_section_m2 * lambert_sphere_phase(g.phase_angle.values)
    flux = flux * g.sunlit_fraction.values / d_m**2
    with np.errstate(divide="ignore"):
        m = SUN_V_MAGNITUDE - 2.5 * np.log10(flux) + 5.0 * np.log10(g.sun_distance.values)
    return np.where(flux > 0, m, np.inf)


def _window(source: Any, start: Any, stop: Any, step_s: float) -> np.ndarray:
    t0, t1 = to_datetime64(start, "start"), to_datetime64(stop, "stop")
    if isinstance(source, Ephemeris):
        t0 = max(t0, min(a for a, _ in source.spans))
        t1 = min(t1, max(b for _, b in source.spans))
    if t1 <= t0:
        raise ObservationError(f"visible_passes: stop {t1} is not after start {t0}")
    step = np.timedelta64(round(step_s * 1e9), "ns")
    t = t0 + step * np.arange(int((t1 - t0) // step) + 1)
    if isinstance(source, Ephemeris):
        cov = np.zeros(t.size, dtype=bool)
        for a, b in source.spans:
            cov |= (t >= a) & (t <= b)
        t = t[cov]
    return t if t[-1] == t1 else np.append(t, t1)


@renamed_keywords(
    cross_section_m2="cross_section", min_elevation_deg="min_elevation", step_s="step"
)
def visible_passes(
    source: Orbit | Ephemeris,
    site: Site,
    start: Any,
    stop: Any,
    *,
    min_elevation: float = 10.0,
    twilight: str = "nautical",
    step: float = 10.0,
    cross_section: float = 1.0,
    albedo: float = 0.2,
    include_invisible: bool = False,
    earth: str = "wgs84",
) -> xr.Dataset:
    """The passes of ``source`` over ``site`` between ``start`` and ``stop`` (UTC).

    Parameters
    ----------
    source : Orbit or Ephemeris
    site : Site
    start, stop : str, datetime or datetime64
        UTC window.
    min_elevation : float
        Lowest elevation that counts [degree].
    twilight : {"civil", "nautical", "astronomical", "night"}
        The site's Sun must be below this twilight's elevation (:data:`TWILIGHTS`).
    step : float
        Search grid [s]; events shorter than it may be missed (10 s suits LEO passes).
    cross_section : float
        Cross-section of the Lambert sphere of the peak magnitude [m2].
    albedo : float
        Its Bond albedo [1].
    include_invisible : bool
        Also list passes with no visible part (``visible_duration`` 0).
    earth : {"wgs84", "sphere"}
        The Earth of the shadow (:data:`~sbrdf_xr.observing.earth_shadow.EARTH_MODELS`).

    A pass already under way at ``start`` (or not set by ``stop``) is cut there.

    Returns
    -------
    xarray.Dataset
        Over ``pass``: ``rise``, ``culmination``, ``set`` (UTC), ``max_elevation``
        [degree], ``shadow_entry`` and ``shadow_exit`` (UTC; NaT when the pass has none),
        ``visible_start``, ``visible_stop`` (UTC, NaT when not visible),
        ``visible_duration`` [s], ``peak_magnitude`` (V [mag] of the model above),
        ``peak_time`` (UTC) and ``peak_range`` [km].

    Examples
    --------
    >>> from sbrdf_xr.observing.orbits import Orbit, Site
    >>> p = visible_passes(Orbit.from_catalog("canx1-example"), Site.from_catalog("mont-megantic"),
    ...                    "2024-03-17T01:00:00", "2024-03-17T01:40:00")
    >>> p.sizes["pass"], str(p.visible_start.values[0])[:19]  # leaves the shadow
    (1, '2024-03-17T01:20:47')
    >>> round(float(p.max_elevation[0]), 1), round(float(p.peak_magnitude[0]), 1)
    (76.0, 5.8)
    """
    min_el = float(to_unit(min_elevation, "deg", "min_elevation"))
    step = float(to_unit(step, "s", "step"))
    cross_section = float(to_unit(cross_section, "m2", "cross_section"))
    if twilight not in TWILIGHTS:
        raise ObservationError(f"twilight: got {twilight!r}; allowed: {', '.join(TWILIGHTS)}")
    if not (step > 0 and cross_section > 0 and 0 < albedo <= 1):
        raise ObservationError(
            f"visible_passes: step and cross_section must be > 0 and albedo in (0, 1]; got "
            f"{step}, {cross_section}, {albedo}"
        )
    args = (min_el, TWILIGHTS[twilight])
    site_earth = (site, earth)
    t = _window(source, start, stop, step)
    cond = _conditions(_geometry(source, site_earth, t), *args)
    found = {k: _edges(source, site_earth, t, v, k, args) for k, v in cond.items()}
    ups = _intervals(t, *found["up"])
    lit = _intervals(t, *found["sunlit"])
    dark = _intervals(t, *found["dark"])
    rows = []
    for rise, set_ in ups:
        culm = _culmination(source, site_earth, rise, set_)
        entry = [b for a, b in lit if rise < b < set_]
        exit_ = [a for a, b in lit if rise < a < set_]
        vis = _intersect(_intersect([(rise, set_)], lit), dark)
        row: dict[str, Any] = {"rise": rise, "culmination": culm, "set": set_}
        row["shadow_entry"] = entry[0] if entry else np.datetime64("NaT", "ns")
        row["shadow_exit"] = exit_[0] if exit_ else np.datetime64("NaT", "ns")
        row["max_elevation"] = _geometry(source, site_earth, np.array([culm])).elevation.values[0]
        row["visible_start"] = vis[0][0] if vis else np.datetime64("NaT", "ns")
        row["visible_stop"] = vis[-1][1] if vis else np.datetime64("NaT", "ns")
        row["visible_duration"] = sum((b - a) / _NS for a, b in vis) / 1e9
        row.update(peak_magnitude=np.nan, peak_time=np.datetime64("NaT", "ns"), peak_range=np.nan)
        if vis:
            grid = np.concatenate(
                [
                    a + np.arange(0, (b - a) // np.timedelta64(1, "s") + 1) * np.timedelta64(1, "s")
                    for a, b in vis
                ]
            )
            grid = np.unique(np.clip(grid, vis[0][0], vis[-1][1]))
            g = _geometry(source, site_earth, grid)
            m = _magnitude(g, cross_section, albedo)
            k = int(np.argmin(m))
            row.update(peak_magnitude=m[k], peak_time=grid[k], peak_range=g.range.values[k])
        if vis or include_invisible:
            rows.append(row)
    return _table(rows, min_el, twilight, cross_section, albedo, source, site, earth)


_ATTRS = {
    "rise": "time the spacecraft rises above the minimum elevation (UTC)",
    "culmination": "time of the highest elevation (UTC)",
    "set": "time the spacecraft sets below the minimum elevation (UTC)",
    "shadow_entry": "time half the solar disc is hidden by the Earth, entering (UTC)",
    "shadow_exit": "time half the solar disc is hidden by the Earth, leaving (UTC)",
    "visible_start": "start of the visible part: up, sunlit and the site dark (UTC)",
    "visible_stop": "end of the visible part (UTC)",
    "peak_time": "time of the brightest model magnitude in the visible part (UTC)",
}
_UNITS = {
    "max_elevation": ("degree", "highest elevation above the site's geodetic horizon"),
    "visible_duration": ("s", "time the spacecraft can be measured in the pass"),
    "peak_magnitude": ("1", "brightest V magnitude of a Lambert sphere (stated model)"),
    "peak_range": ("km", "range at the brightest model magnitude"),
}


def _table(
    rows: list[dict[str, Any]],
    min_el: float,
    twilight: str,
    a: float,
    albedo: float,
    source: Any,
    site: Site,
    earth: str,
) -> xr.Dataset:
    data: dict[str, Any] = {}
    for k, text in _ATTRS.items():
        vals = np.array([r[k] for r in rows], dtype="datetime64[ns]")
        data[k] = ("pass", vals, {"long_name": text, "standard_name": "time"})
    for k, (unit, text) in _UNITS.items():
        data[k] = (
            "pass",
            np.array([r[k] for r in rows], dtype=np.float64),
            {"units": unit, "long_name": text},
        )
    attrs = {
        "orbit_name": source.name,
        "site_name": site.name,
        "min_elevation_deg": min_el,
        "twilight": f"{twilight}: site Sun below {TWILIGHTS[twilight]:g} deg",
        "sunlit": "at least half the solar disc seen from the spacecraft (Earth shadow model "
        "of sbrdf_xr.observing.earth_shadow, "
        f"{earth})",
        "magnitude_model": f"Lambert sphere, cross-section {a:g} m2, Bond albedo {albedo:g} "
        f"(Russell 1916), Sun V = {SUN_V_MAGNITUDE} at {AU_KM:.1f} km",
    }
    ds = xr.Dataset(
        data,
        coords={"pass": ("pass", np.arange(len(rows)), {"long_name": "pass index", "units": "1"})},
        attrs=attrs,
    )
    return ds
