"""Figure: the built-in Starlink v1.5-class body, chassis to nadir, its array tracking the Sun,
flown on the shipped example elements over Mont Megantic, against the same body with the
array held at its rest angle; and the array's hinge angle.

Run ``python docs/starlink.py``; writes ``docs/img/starlink_pass.png``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from sbrdf_xr import Scene, simulate
from sbrdf_xr.body.parts import Fixed, Part
from sbrdf_xr.body.starlink import starlink_v15
from sbrdf_xr.engine.builtin import starlink_materials
from sbrdf_xr.observing.attitude import Nadir
from sbrdf_xr.observing.observe import canx1_pass

OUT = Path(__file__).parent / "img"
DPI = 80


def cubes() -> dict[str, Any]:
    """The pass with the array tracking the Sun, and held at 0 deg."""
    obs = canx1_pass(attitude=Nadir(nadir_axis="-z", velocity_axis="+x"))
    tracking = starlink_v15()
    p = tracking.parts[0]
    held = tracking.with_parts([Part(p.name, p.facets, p.axis, p.point, Fixed(0.0))])
    mats = starlink_materials()
    out = {}
    for name, body in (("tracking", tracking), ("held", held)):
        scene = Scene(body, mats, observation=obs, effects=("sunlight", "shadowing"))
        out[name] = simulate(scene).compute()
    return out


def figures() -> dict[str, Any]:
    """The figure by file name."""
    c = cubes()
    t = c["tracking"]
    minutes = (t.time - t.time[0]).values / np.timedelta64(1, "s") / 60.0
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(7.0, 5.2), sharex=True, layout="constrained")
    for name, label in (("tracking", "array tracking the Sun"), ("held", "array held at 0 deg")):
        s = c[name].signal.sel(wavelength=550.0, method="nearest")
        ax.plot(minutes, s, label=label)
    ax.set_ylabel("signal at 550 nm [m2 sr-1]")
    ax.set_yscale("symlog", linthresh=1e-3)
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title("Starlink v1.5-class body, chassis to nadir (Lambertian stand-ins)", fontsize=9)
    bx.plot(minutes, t.part_angle.sel(part="solar-array"), color="C2")
    bx.set_ylabel("array hinge angle [degree]")
    bx.set_xlabel("time since 01:20 UTC [min]")
    return {"starlink_pass.png": fig}


if __name__ == "__main__":
    OUT.mkdir(exist_ok=True)
    for name, fig in figures().items():
        fig.savefig(OUT / name, dpi=DPI)
        plt.close(fig)
        print("wrote", OUT / name)
