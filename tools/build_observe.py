"""Build the example orbit of the catalog and find the window of the built-in pass.

Run ``python tools/build_observe.py`` to write ``catalogs/observe/canx1-example.tle``
and print the passes of the window search (the chosen one is ``observe.CANX1_PASS``).

The elements are illustrative mean elements in the TLE format of NORAD 27847 (CanX-1,
international designator 2003-031H), not a published element set: a near-circular
sun-synchronous orbit of about 820 km (the Rockot launch of 2003-06-30), with the node
placed so that evening passes over Mont Mégantic end in the Earth's shadow.  The lines are
written by :func:`sgp4.exporter.export_tle` from an ``sgp4init`` record, so the format and
checksums are SGP4's own.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

#: Mean elements of the example (epoch 2024-03-15 12:00 UTC).
ELEMENTS = {
    "satnum": 27847,
    "epoch": "2024-03-15T12:00:00",
    "bstar": 2.1e-5,  # [earth radii-1]
    "ndot": 1.5e-7,  # [rev day-2] / 2, TLE convention
    "eccentricity": 0.0012,
    "argp_deg": 95.0,
    "inclination_deg": 98.72,
    "mean_anomaly_deg": 265.0,
    "mean_motion_rev_day": 14.2195,
    "raan_deg": 129.5,
}


def example_tle(elements: dict[str, float] = ELEMENTS) -> tuple[str, str]:
    """The two lines of the example elements, formatted by :mod:`sgp4.exporter`."""
    from sgp4 import exporter
    from sgp4.api import WGS72, Satrec

    e = elements
    epoch = np.datetime64(e["epoch"], "ns")
    days_1950 = (epoch - np.datetime64("1949-12-31T00:00:00", "ns")).astype(np.int64) / 86400e9
    sat = Satrec()
    sat.sgp4init(
        WGS72,
        "i",
        int(e["satnum"]),
        days_1950,
        e["bstar"],
        e["ndot"] * 2 * math.pi / 1440.0**2,
        0.0,
        e["eccentricity"],
        math.radians(e["argp_deg"]),
        math.radians(e["inclination_deg"]),
        math.radians(e["mean_anomaly_deg"]),
        e["mean_motion_rev_day"] * 2 * math.pi / 1440.0,
        math.radians(e["raan_deg"]),
    )
    sat.classification = "U"
    sat.intldesg = "03031H"
    sat.elnum = 999
    sat.revnum = 10983
    return exporter.export_tle(sat)


def find_passes(
    orbit,
    site,
    start: str,
    stop: str,
    step_s: float = 5.0,
    min_elevation_deg: float = 20.0,
    max_sun_elevation_deg: float = -18.0,
) -> list[dict]:
    """Passes above ``min_elevation_deg`` with the site dark and the shadow boundary crossed."""
    from sbrdf_xr.observing import observe

    t = observe.times(start, stop, step_s)
    obs = observe.Observation(orbit, site, t, None)
    g = obs.geometry(on_unobservable="keep")
    el = g["elevation"].values
    up = (el >= min_elevation_deg) & (g["site_sun_elevation"].values <= max_sun_elevation_deg)
    out = []
    edges = np.flatnonzero(np.diff(np.concatenate([[0], up.astype(int), [0]])))
    for i0, i1 in zip(edges[::2], edges[1::2], strict=True):
        frac = g["sunlit_fraction"].values[i0:i1]
        out.append(
            {
                "start": str(t[i0]),
                "stop": str(t[i1 - 1]),
                "max_elevation": float(el[i0:i1].max()),
                "sunlit_min": float(frac.min()),
                "sunlit_max": float(frac.max()),
                "shadow_edge": str(t[i0 + int(np.argmin(np.abs(frac - 0.5)))])
                if frac.min() < 0.5 < frac.max()
                else "",
            }
        )
    return out


def main() -> None:
    from sbrdf_xr import _catalog_index
    from sbrdf_xr.observing import observe

    l1, l2 = example_tle()
    path = Path(__file__).resolve().parent.parent / "catalogs" / "observe" / "canx1-example.tle"
    path.write_text(f"CANX-1 (example elements)\n{l1}\n{l2}\n", encoding="utf-8")
    print(path.read_text())
    _catalog_index._read_index.cache_clear()  # the index was just written
    orbit = observe.Orbit.from_tle(l1, l2, "CANX-1")
    site = observe.Site.from_catalog(observe.CANX1_PASS["site"])
    for p in find_passes(orbit, site, "2024-03-14T12:00", "2024-03-17T12:00"):
        print(p)


if __name__ == "__main__":
    main()
