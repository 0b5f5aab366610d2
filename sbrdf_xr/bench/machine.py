"""This machine's own ceilings, measured beside the engine rows
(:mod:`sbrdf_xr.bench.engine`): the rate at which its disk writes and syncs a file as
the cube writer does (:func:`disk_rate`, the floor under any cube write), and how much
two threads gain over one on arithmetic that touches no memory (:func:`thread_scaling`,
the ceiling of any two-core speed-up).
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

from ..engine.knobs import KNOBS
from ..store.disk import drop_behind
from .rows import best_time

__all__ = ["disk_rate", "thread_scaling"]


@numba.njit(nogil=True, cache=True)
def _scalar_loop(n: int) -> float:  # pragma: no cover - compiled
    """Square roots and additions only: arithmetic that touches no memory."""
    s = 0.0
    for i in range(n):
        s += np.sqrt(i + 1.0) * 1e-9
    return s


def thread_scaling(n: int = 50_000_000, jobs: int = 4, repeat: int = 3) -> tuple[float, float]:
    """Seconds for ``jobs`` equal compute-bound jobs (:func:`_scalar_loop`: no memory
    traffic, the GIL released) on one thread and on two.  Their ratio is this machine's
    own ceiling for any two-thread speed-up.

    Examples
    --------
    >>> from sbrdf_xr.bench.machine import thread_scaling
    >>> one, two = thread_scaling(n=200_000, repeat=1)
    >>> one > 0.0 and two > 0.0  # their ratio is a measurement, not a property to assert
    True
    """
    from concurrent.futures import ThreadPoolExecutor

    _scalar_loop(10)

    def run(threads: int) -> None:
        with ThreadPoolExecutor(threads) as pool:
            list(pool.map(_scalar_loop, [n] * jobs))

    return best_time(lambda: run(1), repeat), best_time(lambda: run(2), repeat)


def disk_rate(where: str | None = None, nbytes: int = 512 * 2**20) -> float:
    """Rate [byte/s] at which this machine writes ``nbytes`` to a new file in ``where``
    (the temporary directory by default) as the cube writer does: a default block
    (the knob ``block_bytes``, 8 MiB) at a time, each flushed to disk (``fsync``) and
    dropped from the page cache.  The floor under any cube write of that size there.

    Examples
    --------
    >>> from sbrdf_xr.bench.machine import disk_rate
    >>> disk_rate(nbytes=2**20) > 0.0
    True
    """
    block = np.ones(min(nbytes, KNOBS["block_bytes"].default) // 8)
    with tempfile.TemporaryDirectory(prefix="sbrdf-disk-", dir=where) as tmp:
        path = Path(tmp) / "probe.bin"
        t0 = time.perf_counter()
        with open(path, "wb") as f:
            done = 0
            while done < nbytes:
                block.tofile(f)
                done += block.nbytes
                f.flush()
                os.fsync(f.fileno())
                drop_behind(f.fileno())  # as the cube writer does after each block
        seconds = time.perf_counter() - t0
    return done / seconds
