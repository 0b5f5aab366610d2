"""Figure: the built-in canx1-pass light curve in V, R and I, with the Earth's shadow and
the elevation marked.

Run ``python docs/observation.py``; writes ``docs/img/canx1_pass.png``.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from sbrdf_xr.engine import builtin_scene
from sbrdf_xr.engine.run import simulate
from sbrdf_xr.photometry import magnitudes

OUT = Path(__file__).parent / "img" / "canx1_pass.png"


def main() -> None:
    cube = simulate(builtin_scene("canx1-pass"))
    mags = magnitudes(cube.signal, ["V", "R", "I"], range_km=cube["range"])  # the cube's own range
    t = cube.time.values
    fig, (ax, el) = plt.subplots(
        2, 1, figsize=(9, 5.5), sharex=True, gridspec_kw={"height_ratios": [3, 1]}
    )
    f = cube.sunlit_fraction.values
    for a in (ax, el):
        a.fill_between(
            t,
            0,
            1,
            where=f == 0,
            transform=a.get_xaxis_transform(),
            color="0.85",
            label="umbra" if a is ax else None,
        )
        a.fill_between(
            t,
            0,
            1,
            where=(f > 0) & (f < 1),
            transform=a.get_xaxis_transform(),
            color="khaki",
            label="penumbra" if a is ax else None,
        )
    for band, colour in (("V", "tab:green"), ("R", "tab:red"), ("I", "darkred")):
        m = mags.sel(band=band).values
        ax.plot(t, np.where(np.isfinite(m), m, np.nan), color=colour, lw=1, label=band)
    ax.invert_yaxis()
    ax.set_ylabel("AB magnitude")
    ax.set_title(
        f"{cube.attrs['scene']}: CanX-1 model, {cube.attrs['orbit_name']} from "
        f"{cube.attrs['site_name']} (spinning)",
        fontsize=10,
    )
    ax.legend(fontsize=8, ncol=5, loc="lower right")
    el.plot(t, cube.elevation, color="k", lw=1)
    el.set_ylabel("elevation [degree]")
    el.set_xlabel("time (UTC), 2024-03-17")
    import matplotlib.dates as mdates

    el.xaxis.set_major_formatter(mdates.DateFormatter("%H:%M:%S"))
    fig.tight_layout()
    OUT.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(OUT, dpi=110)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
