"""Ctrl-C while the ``sbrdf-xr`` command is starting: one line and exit status 130.

The command line takes a second or more to start (it imports xarray, Dask, numba,
trimesh...); an interrupt then would end in a ``KeyboardInterrupt`` traceback, before
the command line's own handler (:func:`sbrdf_xr.cli.parser.main`) is there. Imported
first by the package: when the running program is the ``sbrdf-xr`` command, an interrupt
until ``main`` takes over prints one line and exits with status 130, as one during the
command does. Nothing has been written by then, so nothing needs cleaning up.
"""

from __future__ import annotations

import os
import signal
import sys
from pathlib import Path

#: The name of the command-line program.
COMMAND = "sbrdf-xr"


def _interrupted(signum: int, frame: object) -> None:
    os.write(2, f"{COMMAND}: interrupted\n".encode())
    os._exit(130)


def starting_command_line() -> bool:
    """Whether the running program is the ``sbrdf-xr`` command (not a Python session).

    Examples
    --------
    >>> from sbrdf_xr._startup import starting_command_line
    >>> starting_command_line()  # the tests run under pytest
    False
    """
    return bool(sys.argv) and Path(sys.argv[0]).name == COMMAND


if starting_command_line() and signal.getsignal(signal.SIGINT) is signal.default_int_handler:
    signal.signal(signal.SIGINT, _interrupted)
