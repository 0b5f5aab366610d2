"""The ``sbrdf-xr`` command line.

Modules
-------
``parser``
    The parser and :func:`main`.
``commands``
    The sub-commands that list, run and draw.
``analysis``
    The sub-commands that analyse a cube or measured data.
``observe``
    The sub-command that simulates a real pass from elements, a site and a window.
``output``
    What the command line reads and prints.
``material`` and ``cache``
    Material tables built from measurement files; the table cache shown and pruned.
"""

from ..errors import renamed_attributes
from . import analysis, commands, observe, output, parser
from .analysis import cmd_invert, cmd_photometry
from .commands import (
    cmd_bench,
    cmd_catalog_list,
    cmd_catalog_show,
    cmd_info,
    cmd_knobs,
    cmd_plot,
    cmd_simulate,
    spacecraft_of,
)
from .observe import cmd_observe
from .output import escape, escaped_attrs, load_cube, open_dataset
from .parser import main

__all__ = [
    "analysis",
    "cmd_bench",
    "cmd_catalog_list",
    "cmd_catalog_show",
    "cmd_info",
    "cmd_invert",
    "cmd_knobs",
    "cmd_observe",
    "cmd_photometry",
    "cmd_plot",
    "cmd_simulate",
    "commands",
    "escape",
    "escaped_attrs",
    "load_cube",
    "main",
    "observe",
    "open_dataset",
    "output",
    "parser",
    "spacecraft_of",
]

# ``open_cube`` was this package's name for the loader: ``sbrdf_xr.store.open_cube`` now
# opens a cube lazily, so the command line's validating, eager loader is ``load_cube``.
__getattr__ = renamed_attributes(__name__, globals(), {"open_cube": "load_cube"})
