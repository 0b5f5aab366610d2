"""Figure: the built-in canx1-pass in V, R and I against UTC, with its colours, its geometry
and the Earth's shadow (the figure ``sbrdf-xr plot`` draws of a pass cube).

Run ``python docs/observation.py``; writes ``docs/img/canx1_pass.png``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from sbrdf_xr import plot
from sbrdf_xr.engine import builtin_scene
from sbrdf_xr.engine.run import simulate

OUT = Path(__file__).parent / "img"
DPI = 80


def figures() -> dict[str, Any]:
    """The figure by file name."""
    cube = simulate(builtin_scene("canx1-pass")).compute()
    return {"canx1_pass.png": plot.cube_figure(cube)}


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    for name, fig in figures().items():
        fig.savefig(OUT / name, dpi=DPI)
        plt.close(fig)
        print(f"wrote {OUT / name}")


if __name__ == "__main__":
    main()
