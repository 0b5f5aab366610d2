"""This machine's own ceilings, measured beside the engine rows
(:mod:`sbrdf_xr.bench.engine`): the rate at which its disk writes and syncs a file as
the cube writer does and the processor time that costs (:func:`disk_cost`, the floors
under any cube write), and how much
two threads gain over one on arithmetic that touches no memory (:func:`thread_scaling`,
the ceiling of any two-core speed-up).
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path
from typing import NamedTuple

import numba
import numpy as np

from ..engine.knobs import KNOBS
from ..store.disk import drop_behind
from .rows import best_time

__all__ = ["DiskCost", "disk_cost", "disk_rate", "thread_scaling"]


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


class DiskCost(NamedTuple):
    """What writing a file as the cube writer does cost (:func:`disk_cost`).

    Examples
    --------
    >>> from sbrdf_xr.bench.machine import DiskCost
    >>> cost = DiskCost(nbytes=2_000_000_000, seconds=1.6, cpu_seconds=0.7)
    >>> f"{cost.rate / 1e6:.0f} MB/s"
    '1250 MB/s'
    """

    #: bytes written
    nbytes: int
    #: wall time [s]
    seconds: float
    #: processor time of this process [s] (its copies into the page cache, the syncs and
    #: the page-cache drops; the kernel's own write-back threads are not counted)
    cpu_seconds: float

    @property
    def rate(self) -> float:
        """Bytes per second of wall time [byte/s]."""
        return self.nbytes / self.seconds


def disk_cost(where: str | None = None, nbytes: int = 512 * 2**20) -> DiskCost:
    """Time and processor time this machine takes to write ``nbytes`` to a new file in
    ``where`` (the temporary directory by default) as the cube writer does: a default
    block (the knob ``block_bytes``, 8 MiB) at a time, each flushed to disk (``fsync``)
    and dropped from the page cache.

    Both are floors under a cube write of that size there: the wall time when the disk
    is the bottleneck, the processor time when the cores are (on a machine whose cores
    all compute blocks, the writer's copies take their time from the kernel).

    Examples
    --------
    >>> from sbrdf_xr.bench.machine import disk_cost
    >>> cost = disk_cost(nbytes=2**20)
    >>> cost.nbytes >= 2**20, cost.rate > 0.0, cost.cpu_seconds >= 0.0
    (True, True, True)
    """
    block = np.ones(min(nbytes, KNOBS["block_bytes"].default) // 8)
    with tempfile.TemporaryDirectory(prefix="sbrdf-disk-", dir=where) as tmp:
        path = Path(tmp) / "probe.bin"
        t0, c0 = time.perf_counter(), time.process_time()
        with open(path, "wb") as f:
            done = 0
            while done < nbytes:
                block.tofile(f)
                done += block.nbytes
                f.flush()
                os.fsync(f.fileno())
                drop_behind(f.fileno())  # as the cube writer does after each block
        seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    return DiskCost(done, seconds, cpu)


def disk_rate(where: str | None = None, nbytes: int = 512 * 2**20) -> float:
    """Rate [byte/s] at which this machine writes ``nbytes`` to a new file in ``where``
    as the cube writer does (:func:`disk_cost`): the floor under any cube write of that
    size there when the disk is the bottleneck.

    Examples
    --------
    >>> from sbrdf_xr.bench.machine import disk_rate
    >>> disk_rate(nbytes=2**20) > 0.0
    True
    """
    return disk_cost(where, nbytes).rate
