"""Shared pytest configuration.

Hypothesis runs derandomized when ``CI`` is set, so a CI run is reproducible (the
examples are still many and varied; locally every run explores new ones), and without
deadlines, because shared machines are noisy.
"""

from __future__ import annotations

import os

import matplotlib
from hypothesis import settings

matplotlib.use("Agg")

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("dev", deadline=None, print_blob=True)
settings.load_profile("ci" if os.environ.get("CI") else "dev")
