"""Write the example night's light curve: a simulated measurement of CanX-1 over Zimmerwald.

No measured light curve of CanX-1 ships with the package, so the example night is
simulated: the CanX-1 model on the shipped example elements (``canx1-example``) flown over
the Zimmerwald observatory (``zimmerwald``, MPC 026) on 2024-03-17, leaving the Earth's
shadow at 19:55:26 UTC and sunlit until it sets.  The truth below (a uniform spin, a
material mix other than the model's, zero points, first-order extinction and noise) is
written into the table's metadata (``simulated_truth``) so that an analysis can be judged
against it, and is used nowhere else.

The observer's table is a long ECSV file, one exposure per row, the Johnson V, Cousins R
and Cousins I filters in turn every second, rows grouped by filter as a reduction
pipeline writes them; UTC mid-exposure times, Vega magnitudes calibrated on standard stars
(zero points 0) but not corrected for extinction, and their 1-sigma uncertainties.

Run ``python tools/build_night.py``; writes ``catalogs/observe/canx1-zimmerwald-night.ecsv``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from astropy.table import Table

OUT = (
    Path(__file__).resolve().parent.parent / "catalogs" / "observe" / "canx1-zimmerwald-night.ecsv"
)

SITE = "zimmerwald"
#: The simulated window (UTC) and the observer's exposures (one per second, in it).
WINDOW = ("2024-03-17T19:55:00", "2024-03-17T20:00:40")
FIRST, LAST = "2024-03-17T19:55:40", "2024-03-17T20:00:19"
FILTERS = {"V": "Johnson V", "R": "Cousins R", "I": "Cousins I"}

#: The held-out truth.
SPIN_AXIS_BODY = (0.0, 0.0, 1.0)
SPIN_AXIS_LONGITUDE_DEG = 215.0  # of the inertial (GCRS) spin axis
SPIN_AXIS_LATITUDE_DEG = 40.0
SPIN_PERIOD_S = 57.0
SPIN_PHASE_DEG = 30.0  # at the epoch
SPIN_EPOCH = "2024-03-17T19:55:00"
#: Area fractions of the materials (the model has 0.153, 0.387, 0.460); total area kept.
AREA_FRACTION = {"aluminium-6061-t6": 0.15, "tjpv-cell": 0.30, "white-paint-a276": 0.55}
#: The magnitudes are calibrated on standard stars: no zero-point error in any band.
ZERO_POINT_MAG = 0.0
EXTINCTION = {"V": 0.22, "R": 0.15, "I": 0.09}  # [mag per airmass]
NOISE_MAG = 0.02
SEED = 27847


def truth_attitude():
    """The spin about body +z, from the attitude that takes body +z to the inertial axis by the
    shortest arc (:func:`sbrdf_xr.invert.spin_model`), angle ``SPIN_PHASE_DEG`` at
    ``SPIN_EPOCH``."""
    from sbrdf_xr import invert

    axis = invert.axis_vector(SPIN_AXIS_LONGITUDE_DEG, SPIN_AXIS_LATITUDE_DEG)
    return invert.spin_model(
        SPIN_AXIS_BODY, axis, SPIN_PERIOD_S, SPIN_PHASE_DEG, epoch=np.datetime64(SPIN_EPOCH)
    )


def measured_table(seed: int = SEED) -> Table:
    """The observer's table, from the truth."""
    from astropy.time import Time

    from sbrdf_xr import catalog, invert
    from sbrdf_xr.body.spacecraft import canx1
    from sbrdf_xr.engine import Scene, simulate
    from sbrdf_xr.observing import Observation, Orbit, Site, times
    from sbrdf_xr.photometry import magnitudes

    sc = canx1()
    orbit = Orbit.from_file(catalog.data_path("observe/canx1-example.tle"))
    obs = Observation(
        orbit, Site.from_catalog(SITE), times(*WINDOW, 1.0), truth_attitude(), name="truth"
    )
    cube = simulate(Scene(sc, observation=obs, outputs=("signal", "per_material")))
    areas = invert.material_areas(sc)
    total = sum(areas.values())
    scale = {m: AREA_FRACTION[m] * total / a for m, a in areas.items()}
    mixed = cube.copy()
    mixed["signal"] = (
        cube["signal_material"]
        * cube["material"].copy(data=[scale[str(m)] for m in cube["material"].values])
    ).sum("material")
    mixed["signal"].attrs = cube["signal"].attrs
    sim = magnitudes(mixed, list(FILTERS), system="Vega")

    rng = np.random.default_rng(seed)
    t = cube["time"].values
    take = np.flatnonzero((t >= np.datetime64(FIRST)) & (t <= np.datetime64(LAST)))
    band = np.array(list(FILTERS))[np.arange(take.size) % len(FILTERS)]
    rows = []
    for b in FILTERS:
        i = take[band == b]
        m = (
            sim.sel(band=b).values[i]
            + ZERO_POINT_MAG
            + EXTINCTION[b] * cube["airmass"].values[i]
            + rng.normal(0.0, NOISE_MAG, i.size)
        )
        rows += [(t[k], FILTERS[b], mk) for k, mk in zip(i, m, strict=True)]
    tab = Table(
        {
            "utc": Time([r[0] for r in rows], scale="utc").isot,
            "filter": [r[1] for r in rows],
            "mag": np.round([r[2] for r in rows], 4),
            "mag_err": np.full(len(rows), NOISE_MAG),
        }
    )
    tab["utc"] = [s + "Z" for s in tab["utc"]]
    tab["mag"].unit = "mag"
    tab["mag_err"].unit = "mag"
    tab.meta.update(
        {
            "object": "CANX-1 (example elements), NORAD 27847 format",
            "site": f"{SITE} (MPC 026)",
            "magnitude_system": "Vega",
            "calibration": (
                "Vega magnitudes calibrated on standard stars; not corrected for extinction"
            ),
            "comment": (
                "SIMULATED MEASUREMENT, not an observation: written by python "
                "tools/build_night.py from the truth in simulated_truth (sbrdf_xr forward "
                "model of the canx1 spacecraft on the canx1-example elements)."
            ),
            "simulated_truth": {
                "spin_axis_body": list(SPIN_AXIS_BODY),
                "spin_axis_longitude_deg": SPIN_AXIS_LONGITUDE_DEG,
                "spin_axis_latitude_deg": SPIN_AXIS_LATITUDE_DEG,
                "spin_axis_frame": "GCRS",
                "spin_convention": (
                    "sbrdf_xr.invert.spin_model: from the attitude that takes the body axis to "
                    "the inertial axis by the shortest arc, spin angle phase at the epoch"
                ),
                "spin_period_s": SPIN_PERIOD_S,
                "spin_phase_deg": SPIN_PHASE_DEG,
                "spin_epoch_utc": SPIN_EPOCH,
                "area_fraction": AREA_FRACTION,
                "zero_point_mag": {b: ZERO_POINT_MAG for b in FILTERS},
                "extinction_mag_per_airmass": EXTINCTION,
                "noise_mag": NOISE_MAG,
                "seed": seed,
            },
        }
    )
    return tab


def main() -> None:
    tab = measured_table()
    tab.write(OUT, overwrite=True)
    print(f"wrote {OUT} ({len(tab)} rows)")


if __name__ == "__main__":
    main()
