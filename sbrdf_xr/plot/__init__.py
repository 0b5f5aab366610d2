"""Matplotlib figures of cubes, materials and benchmarks, and a check that they can be read.

Every function takes labelled objects, returns the ``matplotlib.figure.Figure`` and never
calls ``show()``.

* :func:`cube_figure` - the figure of a cube, chosen by what the cube is
  (:data:`CUBE_KINDS`): an observation over time, a rotation sweep, or spectra.  The
  command line's ``simulate --plot`` and ``plot`` and ``cube.sbrdf.plot()`` draw it.
* :mod:`~sbrdf_xr.plot.curves` - single panels: :func:`light_curve`, :func:`spectrum_curves`,
  :func:`magnitude_curves`, :func:`colour_colour`, :func:`lut_slice`.
* :func:`accuracy_front` - the benchmark's error and cost per case (``sbrdf-xr bench
  --plot``).
* :func:`figure_problems` - overlapping or cut-off text and axis labels without units
  (:data:`UNIT_RULE`); the package's, the documentation's and the notebooks' figures are
  held to it by the tests.

Modules: ``curves``, ``cube``, ``front``, ``checks``.
"""

from ..errors import renamed_attributes
from . import checks, cube, curves, front
from ._labels import BAND_COLOURS, LOG_RATIO, SHORT_LABELS
from .checks import UNIT_RULE, figure_problems, label_has_unit
from .cube import (
    CUBE_KINDS,
    DEFAULT_RANGE_KM,
    cube_figure,
    cube_kind,
    cube_magnitudes,
    observation_figure,
    rotation_figure,
)
from .curves import (
    colour_colour,
    light_curve,
    lut_slice,
    magnitude_curves,
    magnitude_label,
    spectrum_curves,
)
from .front import accuracy_front, is_preset

__all__ = [
    "BAND_COLOURS",
    "CUBE_KINDS",
    "DEFAULT_RANGE_KM",
    "LOG_RATIO",
    "SHORT_LABELS",
    "UNIT_RULE",
    "accuracy_front",
    "checks",
    "colour_colour",
    "cube",
    "cube_figure",
    "cube_kind",
    "cube_magnitudes",
    "curves",
    "figure_problems",
    "front",
    "is_preset",
    "label_has_unit",
    "light_curve",
    "lut_slice",
    "magnitude_curves",
    "magnitude_label",
    "observation_figure",
    "rotation_figure",
    "spectrum_curves",
]

#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(
    __name__, globals(), {"magnitudes": "magnitude_curves", "spectra": "spectrum_curves"}
)
