"""``python -m sbrdf_xr.cli``: the ``sbrdf-xr`` command, run as a module."""

import sys

from .parser import main

sys.exit(main())
