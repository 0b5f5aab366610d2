"""Figure: CanX-1's glints broaden and their peaks drop as the facets' normals are tilted.

The CanX-1 rotation of paper 000 (beta = 10 deg) with surface imperfections (paper 000
section 5): Gaussian normal tilts of sigma = 0 (perfect CAD facets), 0.5, 1 and 2 deg
per tangent axis.  Run ``python docs/imperfections.py``; writes
``docs/img/canx1_imperfections.png``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from sbrdf_xr.engine import builtin_scene
from sbrdf_xr.engine.run import simulate

OUT = Path(__file__).parent / "img"
DPI = 80
SIGMAS = ((0.0, "k"), (0.5, "tab:blue"), (1.0, "tab:orange"), (2.0, "tab:red"))  # [degree]


def figures() -> dict[str, Any]:
    """The figure by file name."""
    scene = builtin_scene("canx1-rotation").with_options(outputs=("signal", "area"))
    fig, (ax, zoom) = plt.subplots(
        1, 2, figsize=(10, 3.8), width_ratios=(2, 1), layout="constrained"
    )
    for sigma, colour in SIGMAS:
        cube = simulate(scene, surface_tilt=sigma, tilt_nodes=9)
        s = cube.signal.sel(wavelength=550.0).isel(phase_angle=0)
        label = "perfect facets" if sigma == 0 else f"sigma = {sigma:g} deg"
        ax.plot(cube.attitude_angle, s, color=colour, lw=1.2, label=label)
        near = (cube.attitude_angle >= 18) & (cube.attitude_angle <= 32)
        zoom.plot(cube.attitude_angle[near], s[near], color=colour, lw=1.2, marker=".", ms=3)
    ax.set_yscale("log")
    ax.set_xlabel("rotation angle [deg]")
    ax.set_ylabel("signal at 550 nm [m2 sr-1]")
    ax.set_title("CanX-1 rotation, beta = 10 deg: glints with tilted facet normals", fontsize=10)
    ax.legend(fontsize=8, loc="lower right")
    zoom.set_xlim(18, 32)
    zoom.set_ylim(0, None)
    zoom.set_xlabel("rotation angle [deg]")
    zoom.set_ylabel("signal at 550 nm [m2 sr-1]")
    zoom.set_title("the glint at 25 deg, linear axis", fontsize=10)
    return {"canx1_imperfections.png": fig}


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    for name, fig in figures().items():
        fig.savefig(OUT / name, dpi=DPI)
        plt.close(fig)
        print(f"wrote {OUT / name}")


if __name__ == "__main__":
    main()
