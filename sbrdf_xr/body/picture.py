"""A 3-D picture of a spacecraft model, each facet coloured by its material (paper 000 Fig. 11).

:meth:`sbrdf_xr.body.spacecraft.Spacecraft.plot` draws a spacecraft with :func:`plot_facets`.
Needs matplotlib (with its ``mplot3d`` toolkit).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np
import trimesh

from ..units import to_unit
from .facets import check_facet_material

__all__ = ["plot_facets"]


def plot_facets(
    mesh: trimesh.Trimesh,
    facet_material: Iterable[str],
    ax: Any = None,
    *,
    name: str = "spacecraft",
    colors: Mapping[str, Any] | None = None,
    rgb: Mapping[str, tuple[int, int, int]] | None = None,
    edgecolor: Any = "0.3",
    linewidth: float = 0.2,
    legend: bool = True,
    elev: float = 25.0,
    azim: float = 35.0,
) -> Any:
    """Draw a triangulated model in 3-D, each facet coloured by its material.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        Geometry in metres.
    facet_material : array_like of str, shape (n_facets,)
        Material name of every facet.
    ax : mpl_toolkits.mplot3d.Axes3D, optional
        Axes to draw in; a new figure is made otherwise.
    name : str
        Name of the model, in the title.
    colors : mapping of str to colour, optional
        Colour of each material (any matplotlib colour); first choice.
    rgb : mapping of str to (r, g, b), optional
        Colour of each material as integers 0-255 (the colours of a material map);
        second choice, then a matplotlib cycle.
    edgecolor, linewidth
        Facet edges.
    legend : bool
        Add a legend of the materials.
    elev, azim : float
        View angles [degree]; a Quantity is converted.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValidationError
        If ``facet_material`` does not have one name per facet.

    Notes
    -----
    Facets are shaded by their orientation to a light from the upper left of the view (so
    that white paint shows as light greys against the pale blue-grey panes), and the
    legend sits below the model.

    Examples
    --------
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> fig = plot_facets(trimesh.creation.box(), ["paint"] * 12, name="cube",
    ...                   rgb={"paint": (255, 255, 255)})
    >>> fig.axes[0].get_title(), len(fig.legends[0].get_texts()), fig.axes[0].get_zlabel()
    ('cube: 12 facets', 1, 'z [m]')
    >>> plt.close(fig)
    """
    import matplotlib.pyplot as plt
    from matplotlib.colors import LightSource, to_rgba
    from matplotlib.patches import Patch
    from matplotlib.ticker import MaxNLocator
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    elev, azim = float(to_unit(elev, "deg", "elev")), float(to_unit(azim, "deg", "azim"))
    labels = check_facet_material(facet_material, len(mesh.faces))
    materials = sorted(set(labels.tolist()))
    if ax is None:
        fig = plt.figure(figsize=(6, 6))
        ax = fig.add_subplot(projection="3d")
    else:
        fig = ax.figure
    cycle = plt.rcParams["axes.prop_cycle"].by_key().get("color", ["C0"])
    palette: dict[str, Any] = {}
    for i, m in enumerate(materials):
        if colors and m in colors:
            palette[m] = to_rgba(colors[m])
        elif rgb and m in rgb:
            r, g, b = rgb[m]
            palette[m] = to_rgba((r / 255.0, g / 255.0, b / 255.0))
        else:
            palette[m] = to_rgba(cycle[i % len(cycle)])
    names, code = np.unique(labels, return_inverse=True)
    face_rgba = np.array([palette[n] for n in names])[code.reshape(-1)]
    tri = np.asarray(mesh.triangles)
    light = LightSource(azdeg=azim + 135.0, altdeg=45.0)
    coll = Poly3DCollection(
        tri,
        facecolors=face_rgba,
        edgecolors=edgecolor,
        linewidths=linewidth,
        shade=True,
        lightsource=light,
    )
    ax.add_collection3d(coll)
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_pane_color((0.78, 0.82, 0.88, 1.0))
    lo, hi = mesh.bounds
    centre, half = (lo + hi) / 2, float(np.max(hi - lo)) / 2
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1, 1, 1))
    for axis, c in zip((ax.xaxis, ax.yaxis, ax.zaxis), centre, strict=True):
        # ticks short of the box's corners, where the labels of two axes would meet
        ticks = MaxNLocator(nbins=4).tick_values(c - 0.8 * half, c + 0.8 * half)
        axis.set_ticks(ticks[np.abs(ticks - c) <= 0.8 * half])
    ax.set_xlabel("x [m]", labelpad=8)
    ax.set_ylabel("y [m]", labelpad=8)
    ax.zaxis.set_rotate_label(False)  # mplot3d would turn "z [m]" upside down
    ax.set_zlabel("z [m]", rotation=90, labelpad=8)
    ax.view_init(elev=elev, azim=azim)
    ax.set_title(f"{name}: {len(labels)} facets")
    if legend:
        fig.legend(
            handles=[Patch(facecolor=palette[m], edgecolor="0.3", label=m) for m in materials],
            loc="lower center",
            ncols=min(len(materials), 3),
            fontsize="small",
        )
    return fig
