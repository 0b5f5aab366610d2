"""Hypothesis profiles of the suite, and the example counts they scale.

``SBRDF_XR_HYPOTHESIS_PROFILE`` selects one (the user guide's contributing page says how
to run each):

``ci`` (the default)
    Reproducible: derandomized, no example database, no deadline.  The same commit
    draws the same examples on every machine, so CI cannot turn red by the luck of a
    draw; the hard cases found so far stand in the tests as explicit ``@example``\\ s.
``dev``
    Random seeds and the local example database (``.hypothesis/``), the counts of the
    tests: everyday exploration that replays what it has found.
``deep``
    Random seeds, no database, every test's example count times
    ``SBRDF_XR_HYPOTHESIS_DEEP_FACTOR`` (default 10): run it over the property tests
    before resolving an issue that touches numerics, and keep what it finds as
    ``@example``\\ s.
"""

from __future__ import annotations

import os

from hypothesis import HealthCheck, settings

PROFILE_VARIABLE = "SBRDF_XR_HYPOTHESIS_PROFILE"
FACTOR_VARIABLE = "SBRDF_XR_HYPOTHESIS_DEEP_FACTOR"
PROFILES = ("ci", "dev", "deep")

settings.register_profile("ci", derandomize=True, database=None, deadline=None, print_blob=True)
settings.register_profile("dev", deadline=None, print_blob=True)
settings.register_profile(
    "deep",
    derandomize=False,
    database=None,
    deadline=None,
    print_blob=True,
    suppress_health_check=[HealthCheck.too_slow],
)


def profile() -> str:
    """The selected profile's name (``ci`` unless the environment says otherwise)."""
    name = os.environ.get(PROFILE_VARIABLE, "ci")
    if name not in PROFILES:
        raise ValueError(f"{PROFILE_VARIABLE}: got {name!r}; allowed: {list(PROFILES)}")
    return name


def examples(n: int) -> int:
    """A test's example count ``n``, scaled by the deep profile's factor."""
    if profile() != "deep":
        return n
    factor = os.environ.get(FACTOR_VARIABLE, "10")
    try:
        k = int(factor)
    except ValueError:
        raise ValueError(f"{FACTOR_VARIABLE}: got {factor!r}; expected a whole number") from None
    if k < 1:
        raise ValueError(f"{FACTOR_VARIABLE}: got {k}; expected at least 1")
    return n * k


settings.load_profile(profile())
