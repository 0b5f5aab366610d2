"""Figure: CanX-1's glints broaden and their peaks drop as the facets' normals are tilted.

The CanX-1 rotation of paper 000 (beta = 10 deg) with surface imperfections (paper 000
section 5): Gaussian normal tilts of sigma = 0 (perfect CAD facets), 0.5, 1 and 2 deg
per tangent axis.  Run ``python docs/imperfections.py``; writes
``docs/img/canx1_imperfections.png``.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from sbrdf_xr.engine import builtin_scene
from sbrdf_xr.engine.run import simulate

OUT = Path(__file__).parent / "img" / "canx1_imperfections.png"


def main() -> None:
    scene = builtin_scene("canx1-rotation").with_options(outputs=("signal", "area"))
    fig, (ax, zoom) = plt.subplots(1, 2, figsize=(10, 3.8), gridspec_kw={"width_ratios": [2, 1]})
    for sigma, colour in ((0.0, "k"), (0.5, "tab:blue"), (1.0, "tab:orange"), (2.0, "tab:red")):
        cube = simulate(scene, surface_tilt=sigma, tilt_nodes=9)
        s = cube.signal.sel(wavelength=550.0).isel(phase_angle=0)
        label = "perfect facets" if sigma == 0 else f"sigma = {sigma:g} deg"
        ax.plot(cube.attitude_angle, s * 1e4, color=colour, lw=1.2, label=label)
        near = (cube.attitude_angle >= 18) & (cube.attitude_angle <= 32)
        zoom.plot(cube.attitude_angle[near], s[near] * 1e4, color=colour, lw=1.2, marker=".", ms=3)
    ax.set_yscale("log")
    ax.set_xlabel("rotation angle [degree]")
    ax.set_ylabel("signal at 550 nm [cm2 sr-1]")
    ax.set_title("CanX-1 rotation, beta = 10 deg: glints with tilted facet normals", fontsize=10)
    ax.legend(fontsize=8, loc="lower right")
    zoom.set_xlim(18, 32)
    zoom.set_ylim(0, None)
    zoom.set_xlabel("rotation angle [degree]")
    zoom.set_ylabel("signal at 550 nm [cm2 sr-1]")
    zoom.set_title("the glint at 25 deg (linear axis, 1 deg steps)", fontsize=10)
    fig.tight_layout()
    OUT.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(OUT, dpi=110)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
