"""Figure: a brushed-aluminium panel's glint changes as its brushing direction turns.

A 1 m x 1 m panel of the catalog's ``brushed-aluminium-model`` (anisotropic GGX,
roughness 0.05 along the brushing, the facet tangent, and 0.30 across it; paper 000
section 5 names anisotropy as an open problem).  The Sun is 40 deg from the panel's
normal; the observer sits a few degrees off the specular direction.  Left: the signal as
the brushing direction turns about the normal, from the anisotropic table through the
engine (``simulate``) and from the analytic model evaluated directly.  Right: the glint
across the illumination plane with the brushing along it and across it.  Run
``python docs/anisotropy.py``; writes ``docs/img/brushed_panel.png``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import trimesh

from sbrdf_xr import catalog, geometry
from sbrdf_xr.body.spacecraft import Spacecraft
from sbrdf_xr.engine import Scene
from sbrdf_xr.engine.run import simulate
from sbrdf_xr.materials import models

OUT = Path(__file__).parent / "img"
DPI = 80
WAVELENGTH = 560.0  # [nm]
THETA_I = 40.0  # [degree]


def panel(chi: float) -> Spacecraft:
    """A 1 mm thick 1 m x 1 m panel (normal +z) brushed along azimuth ``chi`` [degree]."""
    box = trimesh.creation.box(extents=(1.0, 1.0, 0.001))
    a = np.radians(chi)
    return Spacecraft(
        box, ["brushed-aluminium"] * len(box.faces), name="panel", tangent=(np.cos(a), np.sin(a), 0)
    )


def signals(table, spec, chi, s, o, evaluation):
    out = []
    for c in chi:
        scene = Scene(
            panel(c),
            materials={"brushed-aluminium": table},
            models={"brushed-aluminium": spec},
            to_sun=s,
            to_observer=o,
            evaluation=evaluation,
            dtype="float64",
            outputs=("signal",),
        )
        out.append(simulate(scene, lazy=False).signal.sel(wavelength=WAVELENGTH).values)
    return np.array(out)


def figures() -> dict[str, Any]:
    """The figure by file name."""
    spec = catalog.load("brushed-aluminium-model").sel(wavelength=[WAVELENGTH])
    table = models.render_anisotropic(
        spec,
        np.arange(0.0, 91.0, 5.0),
        np.arange(-30.0, 30.5, 1.0),
        np.arange(0.0, 20.5, 1.0),
        np.arange(0.0, 180.5, 5.0),
    )
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4.0), layout="constrained")
    chi = np.arange(0.0, 180.1, 2.5)
    for (dt, ph), colour in (((4.0, 0.0), "tab:blue"), ((0.0, 4.0), "tab:orange")):
        _, s, o = geometry.facet_vectors(THETA_I, dt, ph)  # facet frame: the panel's top face
        tab = signals(table, spec, chi, s[None], o[None], "table")[:, 0]
        ana = signals(table, spec, chi, s[None], o[None], "analytic")[:, 0]
        print(f"dt={dt:g} phi={ph:g}: table vs model max |rel| {np.max(np.abs(tab / ana - 1)):.2e}")
        where = "delta_theta = 4 deg" if ph == 0 else "phi = 4 deg"
        ax.plot(chi, ana, color=colour, lw=1.5, label=f"model, observer at {where}")
        ax.plot(chi, tab, color=colour, lw=0, marker=".", ms=4, label="table, through simulate")
    ax.set_xlabel("brushing: tangent's azimuth from the Sun's plane [deg]")
    ax.set_ylabel(f"signal at {WAVELENGTH:g} nm [m2 sr-1]")
    ax.set_yscale("log")
    ax.set_xlim(0, 180)
    ax.set_title("turning the brushing of a panel, Sun 40 deg from its normal", fontsize=10)
    ax.set_ylim(1.3, 14.0)
    ax.legend(fontsize=7, ncol=2, loc="upper center")
    phi = np.arange(0.0, 15.1, 0.5)
    for c, colour, name in ((0.0, "k", "along the Sun's plane"), (90.0, "tab:red", "across it")):
        _, s, o = geometry.facet_vectors(np.full(phi.shape, THETA_I), 0.0 * phi, phi)
        sig = signals(table, spec, [c], s, o, "table")[0]
        ax2.plot(phi, sig, color=colour, lw=1.5, marker=".", ms=3, label=f"brushed {name}")
    ax2.set_xlabel("phi: observer's angle from the illumination plane [deg]")
    ax2.set_ylabel(f"signal at {WAVELENGTH:g} nm [m2 sr-1]")
    ax2.set_yscale("log")
    ax2.set_title("the glint across the plane (delta_theta = 0)", fontsize=10)
    ax2.legend(fontsize=8)
    return {"brushed_panel.png": fig}


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    for name, fig in figures().items():
        fig.savefig(OUT / name, dpi=DPI)
        plt.close(fig)
        print(f"wrote {OUT / name}")


if __name__ == "__main__":
    main()
