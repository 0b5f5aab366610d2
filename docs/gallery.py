"""Draw the gallery of the README and the user guide into docs/img (run from the repository root:
``python docs/gallery.py``).  The pass, the glints with tilted facets, the brushed panel and
the accuracy/time figure have their own scripts (``observation.py``, ``imperfections.py``,
``anisotropy.py``, ``accuracy_front.py``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from sbrdf_xr import geometry, plot
from sbrdf_xr.body.spacecraft import canx1
from sbrdf_xr.engine import builtin_scene
from sbrdf_xr.engine.run import simulate

OUT = Path(__file__).resolve().parent / "img"
DPI = 80
#: The colour figure counts the attitudes this close to the Sun's colours [mag].
NEAR_MAG = 0.05


def colour_colour_figure(rot: Any) -> Any:
    """The rotation's colours: their colour-colour track, and each against attitude."""
    ph = rot.sbrdf.photometry(["V", "R", "I"], 1000.0).isel(phase_angle=0)
    fig, (ax, per) = plt.subplots(1, 2, figsize=(10, 4.2), layout="constrained")
    plot.colour_colour(ph, "V-R", "R-I", ax=ax)
    sun = ph.sun_magnitude.values
    angle = ph.attitude_angle.values
    near = np.ones(angle.size, bool)
    for k, c in enumerate(["V-R", "R-I"]):
        ci = ph.colour_index.sel(colour=c).values
        sun_c = sun[k] - sun[k + 1]
        near &= np.abs(ci - sun_c) < NEAR_MAG
        per.plot(angle, ci, color=f"C{k}", lw=1, label=c)
        per.axhline(sun_c, color=f"C{k}", ls=":", lw=1)
    per.plot([], [], "k:", lw=1, label="the Sun's colours")
    per.set_xlabel("attitude angle [deg]")
    per.set_ylabel("colour index [AB mag]")
    per.legend(fontsize="small", loc="lower left")
    ax.set_title(f"CanX-1 rotation, {angle.size} attitudes: the glints turn it blue",
                 fontsize="medium")  # fmt: skip
    per.set_title(
        f"{int(near.sum())} of {angle.size} within {NEAR_MAG} mag of the Sun's colours",
        fontsize="medium",
    )
    return fig


def off_specular_figure() -> Any:
    """Paper 000 Fig. 16: the body turned off specular at beta = 30 deg."""
    offsets = [3.0, 6.0, 10.0]
    scene = builtin_scene("canx1-plusx-specular").with_options(
        attitudes=geometry.axis_rotation([0, 0, 1], offsets),
        attitude_angle=offsets,
        phase_angles=[30.0],
    )
    off = simulate(scene).compute().isel(phase_angle=0)
    fig, ax = plt.subplots(figsize=(8, 4), layout="constrained")
    ax.axvspan(780, 880, color="0.88", lw=0, zorder=0, label="aluminium absorption")
    colours = plt.get_cmap("viridis")(np.linspace(0.0, 0.8, len(offsets)))
    for k, (a, colour) in enumerate(zip(offsets, colours, strict=True)):
        ax.semilogy(
            off.wavelength,
            off.spacecraft_sbrdf.isel(attitude=k),
            ("-", "--", "-.")[k],
            color=colour,
            lw=1.5,
            label=f"turned {a:g} deg",
        )
    ax.set_xlabel("wavelength [nm]")
    ax.set_ylabel("overall sBRDF [sr-1]")
    ax.legend(
        title="off specular\n(-a gives the\nsame spectrum)",
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        fontsize="small",
    )
    ax.set_title(
        "Off specular, phase angle 30 deg: the aluminium 800 nm feature (paper 000 Fig. 16)",
        fontsize="medium",
    )
    return fig


def figures() -> dict[str, Any]:
    """The gallery's figures by file name."""
    out = {"canx1_model.png": canx1().plot()}
    rot = simulate("canx1-rotation").compute()
    out["canx1_rotation.png"] = plot.cube_figure(rot)  # what `simulate --plot` draws
    out["canx1_colour_colour.png"] = colour_colour_figure(rot)
    spec = simulate("canx1-plusx-specular").compute()
    fig = plot.spectrum_curves(spec, attitude=0)
    fig.axes[0].set_title("CanX-1 +X side at specular (paper 000 Fig. 14)", fontsize="medium")
    out["canx1_plusx_spectra.png"] = fig
    out["canx1_off_specular.png"] = off_specular_figure()
    return out


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    for name, fig in figures().items():
        fig.savefig(OUT / name, dpi=DPI)
        plt.close(fig)
        print(f"wrote {OUT / name}")


if __name__ == "__main__":
    main()
