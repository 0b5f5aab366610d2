"""The plumbing of a table build's steps (:func:`sbrdf_xr.materials.build_lut`): the
progress of weighted steps, a step run in a background thread, a step run a few rows at
a time."""

from __future__ import annotations

import itertools
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np

__all__: list[str] = []


class _Parts:
    """The progress of a build made of weighted steps, one of which may run in a
    background thread: ``part(step)(fraction)`` records a step's fraction done and, from
    the building thread, reports the weighted total."""

    def __init__(self, report: Callable[[float, str], None], weights: dict[str, float]):
        self.report, self.weights = report, weights
        self.done = dict.fromkeys(weights, 0.0)
        self.thread = threading.get_ident()

    def part(self, step: str) -> Callable[[float], None]:
        def done(fraction: float) -> None:
            self.done[step] = fraction
            if threading.get_ident() == self.thread:
                total = sum(w * self.done[k] for k, w in self.weights.items())
                self.report(total / sum(self.weights.values()), step)

        return done


class _Job:
    """``func(*args, stop=event)`` in a background thread; :meth:`result` waits for it."""

    def __init__(self, func: Callable[..., np.ndarray], *args: Any) -> None:
        self.stop = threading.Event()
        self.pool = ThreadPoolExecutor(1, thread_name_prefix="sbrdf-build")
        self.future = self.pool.submit(func, *args, stop=self.stop)
        self.pool.shutdown(wait=False)

    def result(self, tick: Callable[[], None]) -> np.ndarray:
        """The result, calling ``tick()`` every quarter second while waiting."""
        while True:
            try:
                return self.future.result(timeout=0.25)
            except TimeoutError:
                tick()

    def cancel(self) -> None:
        """Stop the job at its next row group (the build failed)."""
        self.stop.set()


class _Done(_Job):
    """A :class:`_Job` whose result is known."""

    def __init__(self, value: np.ndarray) -> None:
        self.value = value

    def result(self, tick: Callable[[], None]) -> np.ndarray:
        """The value."""
        return self.value

    def cancel(self) -> None:
        """Nothing runs."""


def _by_rows(
    func: Callable[[np.ndarray], np.ndarray],
    ti: np.ndarray,
    done: Callable[[float], None],
    stop: threading.Event | None = None,
) -> np.ndarray:
    """``func(ti)`` (one result row per incidence angle) a few rows at a time, reporting the
    fraction done (and stopping when ``stop`` is set): the rows are computed
    independently, so the result is the same."""
    bounds = np.unique(np.linspace(0, ti.size, min(ti.size, 12) + 1).astype(int))
    out = []
    for a, b in itertools.pairwise(bounds):
        if stop is not None and stop.is_set():
            raise RuntimeError("build_lut: stopped (the build failed)")
        done(a / ti.size)
        out.append(func(ti[a:b]))
    done(1.0)
    return np.concatenate(out)
