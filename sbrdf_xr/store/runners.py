"""How the cube writer computes its blocks.

In the calling thread, in a thread pool, or on a Dask distributed cluster (and
connecting to one).
"""

from __future__ import annotations

import contextlib
from collections import deque
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from typing import TYPE_CHECKING, Any, Protocol

import dask
import numpy as np
from dask.system import CPU_COUNT

from ..errors import ValidationError
from .common import _STYLE, _SYNC_NAMES, _THREAD_NAMES, SchedulerError

if TYPE_CHECKING:
    from .layout import BlockLayout


class _Runner(Protocol):
    """What the writer asks of a runner: submit blocks, take them back as they finish."""

    n_workers: int

    @property
    def pending(self) -> int: ...

    def submit(self, k: int, task: tuple[dict[Any, Any], Any]) -> None: ...

    def next_done(self) -> tuple[int, Any]: ...

    def result(self, handle: Any) -> tuple[np.ndarray, ...]: ...

    def close(self) -> None: ...


class _SyncRunner:
    """Compute each block in the calling thread when its result is asked for."""

    def __init__(self) -> None:
        self.queue: deque[tuple[int, Any]] = deque()
        self.n_workers = 1

    @property
    def pending(self) -> int:
        return len(self.queue)

    def submit(self, k: int, task: tuple[dict[Any, Any], Any]) -> None:
        self.queue.append((k, task))

    def next_done(self) -> tuple[int, Any]:
        return self.queue.popleft()

    def result(self, task: tuple[dict[Any, Any], Any]) -> tuple[np.ndarray, ...]:
        return dask.get(*task)

    def close(self) -> None:
        self.queue.clear()


class _ThreadRunner:
    """A pool of threads, each computing whole blocks with Dask's synchronous scheduler."""

    def __init__(self, n_threads: int) -> None:
        self.n_workers = n_threads
        self.pool = ThreadPoolExecutor(n_threads, thread_name_prefix="write_cube")
        self.futures: dict[Future[Any], int] = {}

    @property
    def pending(self) -> int:
        return len(self.futures)

    def submit(self, k: int, task: tuple[dict[Any, Any], Any]) -> None:
        self.futures[self.pool.submit(dask.get, *task)] = k

    def next_done(self) -> tuple[int, Future[Any]]:
        done, _ = wait(self.futures, return_when=FIRST_COMPLETED)
        fut = min(done, key=self.futures.__getitem__)
        return self.futures.pop(fut), fut

    def result(self, fut: Future[Any]) -> tuple[np.ndarray, ...]:
        return fut.result()

    def close(self) -> None:
        self.pool.shutdown(wait=True, cancel_futures=True)
        self.futures.clear()


class _DistributedRunner:
    """Blocks submitted to a Dask cluster; results gathered by the writing process."""

    def __init__(self, client: Any, owned: bool) -> None:
        from distributed import as_completed

        self.client = client
        self.owned = owned
        self.done = as_completed(loop=client.loop)
        self.futures: dict[str, tuple[int, Any]] = {}
        self.n_workers = max(1, sum(client.nthreads().values()))

    @property
    def pending(self) -> int:
        return len(self.futures)

    def submit(self, k: int, task: tuple[dict[Any, Any], Any]) -> None:
        fut = self.client.get(task[0], task[1], sync=False)
        self.futures[fut.key] = (k, fut)
        self.done.add(fut)

    def next_done(self) -> tuple[int, Any]:
        fut = next(self.done)
        k, _ = self.futures.pop(fut.key)
        return k, fut

    def result(self, fut: Any) -> tuple[np.ndarray, ...]:
        try:
            return fut.result()
        finally:
            fut.release()

    def close(self) -> None:
        with contextlib.suppress(Exception):
            self.done.clear()
            if self.futures:
                self.client.cancel([f for _, f in self.futures.values()])
        self.futures.clear()
        if self.owned:
            self.client.close()


def _runner(client: Any, scheduler: str | None) -> _Runner:
    if client is not None and scheduler is not None:
        raise ValidationError("pass either client or scheduler, not both")
    if client is not None:
        return _DistributedRunner(client, owned=False)
    if scheduler is None or scheduler in _THREAD_NAMES:
        n = dask.config.get("num_workers", None) or CPU_COUNT
        return _ThreadRunner(max(1, int(n)))
    if scheduler in _SYNC_NAMES:
        return _SyncRunner()
    return _DistributedRunner(connect(scheduler), owned=True)


_SCHEMES = ("tcp", "tls", "ucx", "ws", "wss")


def _check_address(address: Any) -> str:
    """``address`` as a ``scheme://host:port`` string, or :class:`ValidationError`."""
    if _STYLE.get() == "cli":
        allowed = "expected the address of a Dask scheduler such as 'tcp://127.0.0.1:8786'"
        name = "--scheduler"
    else:
        allowed = (
            "allowed: None or 'threads' (in-process threads), 'synchronous', or the address "
            "of a Dask scheduler such as 'tcp://127.0.0.1:8786'"
        )
        name = "scheduler"
    if (
        not isinstance(address, str)
        or not address.isprintable()
        or any(c.isspace() for c in address)
    ):
        raise ValidationError(f"{name}: got {address!r}; {allowed}")
    scheme, sep, rest = address.rpartition("://")
    if not sep:
        scheme, rest = "tcp", address
    host, colon, port = rest.rpartition(":")
    if (
        scheme not in _SCHEMES
        or not colon
        or not host
        or not port.isdigit()
        or not 0 < int(port) < 65536
    ):
        raise ValidationError(f"{name}: got {address!r}; {allowed} (port 1-65535)")
    if host.startswith("[") != host.endswith("]"):
        raise ValidationError(f"{name}: got {address!r}; {allowed}")
    return f"{scheme}://{host}:{port}"


def connect(address: str, timeout: float | str | None = None) -> Any:
    """A :class:`distributed.Client` connected to the scheduler at ``address``.

    Parameters
    ----------
    address : str
        ``tcp://host:port`` (or ``host:port``; schemes ``tcp``, ``tls``, ``ucx``,
        ``ws``, ``wss``).
    timeout : float or str, optional
        Seconds (or a Dask time string) to wait for the scheduler; default the Dask
        setting ``distributed.comm.timeouts.connect``.

    Raises
    ------
    ValidationError
        A malformed address.
    SchedulerError
        No scheduler answers at that address in time, or ``distributed`` is missing.

    Examples
    --------
    >>> from sbrdf_xr.errors import ValidationError
    >>> from sbrdf_xr.store.common import SchedulerError
    >>> from sbrdf_xr.store.runners import connect
    >>> try:
    ...     connect("localhost")  # no port
    ... except ValidationError as exc:
    ...     print(str(exc).split(";")[0])
    scheduler: got 'localhost'
    >>> try:
    ...     connect("tcp://127.0.0.1:9", timeout=0.2)  # nothing listens on port 9
    ... except SchedulerError as exc:
    ...     print(str(exc).split(" (")[0])
    cannot connect to the Dask scheduler at tcp://127.0.0.1:9
    """
    address = _check_address(address)
    try:
        from distributed import Client
    except ImportError as exc:  # pragma: no cover - distributed is a test dependency
        raise SchedulerError(
            f"scheduler {address!r} needs the 'distributed' package "
            "(pip install sbrdf-xr[distributed])"
        ) from exc
    if timeout is None:
        timeout = dask.config.get("distributed.comm.timeouts.connect", "30s")
    try:
        return Client(address, set_as_default=False, timeout=timeout)
    except (OSError, ValueError, TypeError) as exc:
        what = "timed out" if isinstance(exc, TimeoutError) else type(exc).__name__
        raise SchedulerError(
            f"cannot connect to the Dask scheduler at {address} ({what}: {exc}); start one with "
            "'dask scheduler --host 127.0.0.1' or check the address"
        ) from exc


class Feed:
    """The blocks still to compute, handed to the runner so that at most ``limit`` are
    computed or waiting to be written at any time.

    Examples
    --------
    >>> import dask
    >>> import dask.array as da
    >>> import xarray as xr
    >>> from sbrdf_xr.store.layout import layout_of
    >>> from sbrdf_xr.store.runners import Feed
    >>> ds = xr.Dataset({"radiance": ("attitude", da.arange(6.0, chunks=2))})
    >>> class Runner:  # holds the submitted blocks, computes none
    ...     def __init__(self):
    ...         self.tasks = {}
    ...
    ...     @property
    ...     def pending(self):
    ...         return len(self.tasks)
    ...
    ...     def submit(self, k, task):
    ...         self.tasks[k] = task
    >>> runner = Runner()
    >>> feed = Feed(layout_of(ds), runner, todo=[0, 1, 2], limit=2)
    >>> feed.fill()
    >>> sorted(runner.tasks), list(feed.todo)
    ([0, 1], [2])
    >>> [(name, region) for name, region, _ in feed.pieces[1]]
    [('radiance', (slice(2, 4, None),))]
    >>> dask.get(*runner.tasks.pop(1))[0].tolist()  # block 1, computed
    [2.0, 3.0]
    >>> feed.fill()  # room for one more
    >>> sorted(runner.tasks), list(feed.todo)
    ([0, 2], [])
    """

    def __init__(self, plan: BlockLayout, runner: _Runner, todo: list[int], limit: int) -> None:
        self.plan = plan
        self.runner = runner
        self.todo = deque(todo)
        self.limit = limit
        #: ``(variable, region, Dask key)`` of every block submitted and not yet written
        self.pieces: dict[int, list[tuple[str, tuple[slice, ...], Any]]] = {}

    def fill(self) -> None:
        """Submit blocks until ``limit`` are pending or none is left."""
        while self.todo and self.runner.pending < self.limit:
            k = self.todo.popleft()
            self.pieces[k] = self.plan.pieces(k)
            self.runner.submit(k, self.plan.task(k, [p for _, _, p in self.pieces[k]]))
