"""pytest configuration shared by the tests and the doctests of the package.

colour-science sets numpy's legacy (1.13) print style when it is imported, which
changes the repr of arrays (``array([ 0.6,  0. ])``); every doctest runs with numpy's
default style instead, whatever was imported before it.
"""

from __future__ import annotations

import numpy as np
import pytest
from _pytest.doctest import DoctestItem


@pytest.fixture(autouse=True)
def _numpy_default_print_style(request):
    if not isinstance(request.node, DoctestItem):
        yield
        return
    with np.printoptions(legacy=False):
        yield
