"""The ``sbrdf-xr`` command line.

Modules
-------
``parser``
    The parser and :func:`main`.
``commands``
    The sub-commands that list, run and draw.
``analysis``
    The sub-commands that analyse a cube or measured data.
``output``
    What the command line reads and prints.
"""

from . import analysis, commands, output, parser
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
from .output import escape, escaped_attrs, open_cube, open_dataset
from .parser import main

__all__ = [
    "analysis",
    "cmd_bench",
    "cmd_catalog_list",
    "cmd_catalog_show",
    "cmd_info",
    "cmd_invert",
    "cmd_knobs",
    "cmd_photometry",
    "cmd_plot",
    "cmd_simulate",
    "commands",
    "escape",
    "escaped_attrs",
    "main",
    "open_cube",
    "open_dataset",
    "output",
    "parser",
    "spacecraft_of",
]
