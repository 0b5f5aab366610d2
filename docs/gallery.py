"""Draw the README gallery into docs/img (run from the repository root:
``python docs/gallery.py``; the accuracy/time front comes from ``sbrdf-xr bench --plot``)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from sbrdf_xr import geometry, plot
from sbrdf_xr.body.spacecraft import canx1
from sbrdf_xr.engine import builtin_scene
from sbrdf_xr.engine.run import simulate

OUT = Path(__file__).resolve().parent / "img"
DPI = 80


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    fig = canx1().plot()
    fig.savefig(OUT / "canx1_model.png", dpi=DPI)

    rot = simulate("canx1-rotation").compute()
    fig, axes = plt.subplots(2, 1, figsize=(8, 6), layout="constrained", sharex=True)
    plot.light_curve(rot, ax=axes[0])  # log axis: the glints span 100x
    axes[0].set_xlabel("")
    axes[0].set_title(
        "CanX-1 rotation, phase angle 10 deg (paper 000 Fig. 18): +X, +Y, -X, -Y glints"
    )
    mags = rot.sbrdf.magnitudes(["V", "R", "I"], range_km=1000.0, system="vega")
    plot.magnitudes(mags, ax=axes[1])
    axes[1].set_xlabel("rotation angle about -z [deg]")
    fig.savefig(OUT / "canx1_rotation.png", dpi=DPI)

    ph = rot.sbrdf.photometry(["V", "R", "I"], 1000.0, system="vega")  # the cube spans 400-1100 nm
    fig = plot.colour_colour(ph.isel(phase_angle=0), "V-R", "R-I")
    fig.axes[0].set_title("CanX-1 rotation: colours per attitude")
    fig.savefig(OUT / "canx1_colour_colour.png", dpi=DPI)

    spec = simulate("canx1-plusx-specular").compute()
    fig = plot.spectra(spec, attitude=0)
    fig.axes[0].set_title("CanX-1 +X side at specular (paper 000 Fig. 14)")
    fig.savefig(OUT / "canx1_plusx_spectra.png", dpi=DPI)

    off = simulate(
        builtin_scene("canx1-plusx-specular").with_options(
            attitudes=geometry.axis_rotation([0, 0, 1], [-6.0, -3.0, 3.0, 6.0]), phase_angles=[30.0]
        )
    ).compute()
    fig, ax = plt.subplots(figsize=(8, 4), layout="constrained")
    for k, a in enumerate([-6, -3, 3, 6]):
        ax.semilogy(
            off.wavelength,
            off.spacecraft_sbrdf.isel(attitude=k, phase_angle=0),
            ("-", "--", "-.", ":")[k],
            label=f"{a:+d} deg",
        )
    ax.set_xlabel("wavelength [nm]")
    ax.set_ylabel("overall sBRDF [sr-1]")
    ax.legend(title="off specular")
    ax.set_title(
        "Off specular, phase angle 30 deg: the aluminium 800 nm feature (paper 000 Fig. 16)"
    )
    fig.savefig(OUT / "canx1_off_specular.png", dpi=DPI)
    print(f"wrote {sorted(p.name for p in OUT.glob('*.png'))}")


if __name__ == "__main__":
    main()
