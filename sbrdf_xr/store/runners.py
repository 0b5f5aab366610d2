"""How the cube writers compute their blocks, and what they report after each.

In the calling thread, in a thread pool, or on a Dask distributed cluster (and
connecting to one).  A cluster that has had no worker for
:data:`NO_WORKERS_TIMEOUT` (or whose scheduler went away) stops the write with
:class:`~sbrdf_xr.errors.WorkersLostError` instead of waiting for ever.
"""

from __future__ import annotations

import contextlib
import dataclasses
import time
from collections import deque
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import dask
import numpy as np
from dask.core import istask
from dask.system import CPU_COUNT

from .._output import cli_style, libc_function
from ..errors import SchedulerError, ValidationError, WorkersLostError
from .files import again_hint

if TYPE_CHECKING:
    from .layout import BlockLayout

#: Graph values sent as they are (a key, a number, a small literal), never scattered.
_PLAIN = (str, bytes, int, float, complex, bool, tuple, list, type(None))
_SYNC_NAMES = ("sync", "synchronous", "single-threaded")
_THREAD_NAMES = ("threads", "threading")

#: Seconds a Dask cluster may have no worker before the write stops with
#: :class:`~sbrdf_xr.errors.WorkersLostError` (Dask setting ``sbrdf_xr.no-workers-timeout``,
#: e.g. ``DASK_SBRDF_XR__NO_WORKERS_TIMEOUT=300s``, overrides it).
NO_WORKERS_TIMEOUT = 60.0
#: Seconds between two checks of a cluster's workers while no block arrives.
_POLL = 1.0


class ClusterLost(Exception):
    """Raised by a runner whose cluster has no worker left, or whose scheduler is gone;
    the writers turn it into :class:`~sbrdf_xr.errors.WorkersLostError` with their context."""


@dataclasses.dataclass(frozen=True)
class BlockWritten:
    """What the cube writers pass to ``on_block`` after each block is committed.

    Attributes
    ----------
    index : int
        Block number (C order over the grid of chunks).
    slices : dict of str to slice
        Position of the block along each chunked dimension.
    n_written : int
        Blocks committed so far, including those of an earlier, resumed run.
    n_blocks : int
        Blocks in the cube.
    in_flight : int
        Blocks submitted for computation but not yet written, after this one.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import dask.array as da
    >>> import xarray as xr
    >>> from sbrdf_xr.store.writer import write_cube
    >>> ds = xr.Dataset({"radiance": (("attitude", "wavelength"), da.ones((4, 3), chunks=(2, 3)))})
    >>> events = []
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = Path(tmp) / "cube.nc"
    ...     _ = write_cube(ds, path, scheduler="synchronous", on_block=events.append)
    >>> for e in events:
    ...     print(e.index, e.slices["attitude"], f"{e.n_written}/{e.n_blocks}", e.in_flight)
    0 slice(0, 2, None) 1/2 0
    1 slice(2, 4, None) 2/2 0
    """

    index: int
    slices: dict[str, slice]
    n_written: int
    n_blocks: int
    in_flight: int


def check_arguments(max_in_flight: Any, complevel: Any, client: Any, scheduler: Any) -> None:
    """Refuse the writers' arguments that cannot work, before anything is touched.

    Examples
    --------
    >>> from sbrdf_xr.errors import ValidationError
    >>> from sbrdf_xr.store.runners import check_arguments
    >>> check_arguments(None, 4, None, "threads") is None
    True
    >>> try:
    ...     check_arguments(0, 0, None, None)
    ... except ValidationError as exc:
    ...     print(exc)
    max_in_flight: must be an integer >= 1, got 0
    """
    if max_in_flight is not None and (
        not isinstance(max_in_flight, int | np.integer) or max_in_flight < 1
    ):
        raise ValidationError(f"max_in_flight: must be an integer >= 1, got {max_in_flight!r}")
    if complevel is not None and (
        isinstance(complevel, bool)
        or not isinstance(complevel, int | np.integer)
        or not 0 <= int(complevel) <= 9
    ):
        raise ValidationError(f"complevel: must be 0 (no compression) to 9, got {complevel!r}")
    if client is not None and scheduler is not None:
        raise ValidationError("pass either client or scheduler, not both")
    if scheduler is not None and scheduler not in _THREAD_NAMES + _SYNC_NAMES:
        _check_address(scheduler)


def _malloc_trim() -> Any:
    import ctypes

    return libc_function("malloc_trim", [ctypes.c_size_t], ctypes.c_int)


_MALLOC_TRIM = _malloc_trim()


def release_freed_memory() -> None:
    """Hand the memory this process has freed back to the operating system (glibc's
    ``malloc_trim(0)``; nothing elsewhere).

    Preparing a cube (the plan's geometry, the coordinates, the fingerprint's hashes)
    frees many block-sized temporaries that glibc keeps in its heap, where they count
    in the resident memory for the whole write.  The writer calls this once, before
    it streams the blocks; Dask's documentation recommends the same call for memory
    that was freed but not released.  On this project's 2-core machine it lowered a
    1e6-attitude write's peak resident memory by about 50 MiB.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.store.runners import release_freed_memory
    >>> temporaries = [np.ones(2**16) for _ in range(16)]
    >>> del temporaries
    >>> release_freed_memory() is None  # nothing to return, and safe on any platform
    True
    """
    if _MALLOC_TRIM is not None:
        _MALLOC_TRIM(0)


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
    """Blocks submitted to a Dask cluster; results gathered by the writing process.

    While no block arrives the cluster's workers are counted every :data:`_POLL`
    seconds: with none for :data:`NO_WORKERS_TIMEOUT` (the scheduler would keep the
    blocks waiting for a worker for ever), or a scheduler that no longer answers,
    :class:`ClusterLost` is raised.
    """

    def __init__(self, client: Any, owned: bool) -> None:
        from distributed import as_completed

        self.client = client
        self.owned = owned
        self.done = as_completed(loop=client.loop)
        self.futures: dict[str, tuple[int, Any]] = {}
        #: data values of the graphs, scattered once (:meth:`_shared`), by key
        self.shared: dict[Any, Any] = {}
        self.n_workers = max(1, sum(client.nthreads().values()))

    @property
    def pending(self) -> int:
        return len(self.futures)

    def submit(self, k: int, task: tuple[dict[Any, Any], Any]) -> None:
        graph = {key: self._shared(key, value) for key, value in task[0].items()}
        fut = self.client.get(graph, task[1], sync=False)
        self.futures[fut.key] = (k, fut)
        self.done.add(fut)

    def _shared(self, key: Any, value: Any) -> Any:
        """A value the graph holds as data (the plan of a cube computed without this
        client) sent to every worker once, by key; each block's graph then names it
        instead of carrying it (a task or a plain value is left as it is)."""
        if istask(value) or isinstance(value, _PLAIN):
            return value
        if key not in self.shared:
            try:
                self.shared[key] = self.client.scatter(value, broadcast=True, hash=False)
            except Exception as exc:
                if type(exc).__name__ != "CommClosedError":
                    raise
                raise ClusterLost(
                    f"the Dask scheduler no longer answers ({type(exc).__name__}: {exc})"
                ) from exc
        return self.shared[key]

    def _workers(self) -> int:
        try:
            return len(self.client.nthreads())
        except Exception as exc:  # the comm errors of a scheduler that went away
            raise ClusterLost(
                f"the Dask scheduler no longer answers ({type(exc).__name__}: {exc})"
            ) from exc

    def _alone(self, since: float | None, timeout: float) -> float | None:
        """Since when the cluster has had no worker (None while it has some); ClusterLost
        once that lasts ``timeout`` seconds."""
        if self._workers():
            return None
        now = time.monotonic()
        since = now if since is None else since
        if now - since >= timeout:
            raise ClusterLost(
                f"the Dask cluster has had no worker for {timeout:g} s (every worker died or left)"
            )
        return since

    def next_done(self) -> tuple[int, Any]:
        timeout = no_workers_timeout()
        alone_since: float | None = None
        checked = time.monotonic()
        while not self.done.has_ready():
            time.sleep(0.005)
            now = time.monotonic()
            if now - checked < _POLL:
                continue
            checked = now
            alone_since = self._alone(alone_since, timeout)
        fut = next(self.done)
        k, _ = self.futures.pop(fut.key)
        return k, fut

    def _wait(self, fut: Any) -> tuple[np.ndarray, ...]:
        # A block computed on a worker that died before its result was fetched goes back
        # to waiting for a worker: with none left it would wait for ever.
        timeout = no_workers_timeout()
        alone_since: float | None = None
        while True:
            try:
                return fut.result(timeout=_POLL)
            except TimeoutError:
                if fut.done():  # the block's own error, not the wait's
                    raise
                alone_since = self._alone(alone_since, timeout)

    def result(self, fut: Any) -> tuple[np.ndarray, ...]:
        try:
            return self._wait(fut)
        except ClusterLost:
            raise
        except Exception as exc:
            if type(exc).__name__ in ("FutureCancelledError", "CancelledError"):
                first = (str(exc).splitlines() or [""])[0]
                raise ClusterLost(
                    f"the Dask cluster cancelled the block ({type(exc).__name__}: {first}); its "
                    "scheduler or every worker went away"
                ) from exc
            if type(exc).__name__ == "CommClosedError":  # the result's fetch lost the scheduler
                first = (str(exc).splitlines() or [""])[0]
                raise ClusterLost(
                    f"the Dask scheduler no longer answers ({type(exc).__name__}: {first})"
                ) from exc
            raise
        finally:
            fut.release()

    def close(self) -> None:
        with contextlib.suppress(Exception):
            self.done.clear()
            if self.futures:
                self.client.cancel([f for _, f in self.futures.values()])
        self.futures.clear()
        self.shared.clear()  # the scattered values, released
        if self.owned:
            with contextlib.suppress(Exception):
                self.client.close()


def no_workers_timeout() -> float:
    """Seconds a cluster may have no worker before a write stops (:data:`NO_WORKERS_TIMEOUT`,
    or the Dask setting ``sbrdf_xr.no-workers-timeout``).

    Examples
    --------
    >>> import dask
    >>> from sbrdf_xr.store.runners import no_workers_timeout
    >>> no_workers_timeout()
    60.0
    >>> with dask.config.set({"sbrdf_xr.no-workers-timeout": "2 minutes"}):
    ...     no_workers_timeout()
    120.0
    """
    value = dask.config.get("sbrdf_xr.no-workers-timeout", None)
    if value is None:
        return NO_WORKERS_TIMEOUT
    return float(dask.utils.parse_timedelta(value, default="s"))


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
    if cli_style():
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
    >>> from sbrdf_xr.errors import SchedulerError
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

    def __init__(
        self,
        plan: BlockLayout,
        runner: _Runner,
        todo: list[int],
        limit: int,
        wrap: Callable[[int, tuple[dict[Any, Any], Any]], tuple[dict[Any, Any], Any]] | None = None,
    ) -> None:
        self.plan = plan
        self.runner = runner
        self.todo = deque(todo)
        self.limit = limit
        #: turns a block's task (the tuple of its pieces) into the task submitted
        self.wrap = wrap
        #: ``(variable, region, Dask key)`` of every block submitted and not yet written
        self.pieces: dict[int, list[tuple[str, tuple[slice, ...], Any]]] = {}

    def fill(self) -> None:
        """Submit blocks until ``limit`` are pending or none is left."""
        while self.todo and self.runner.pending < self.limit:
            k = self.todo.popleft()
            self.pieces[k] = self.plan.pieces(k)
            task = self.plan.task(k, [p for _, _, p in self.pieces[k]])
            self.runner.submit(k, self.wrap(k, task) if self.wrap is not None else task)


def lost_workers(
    path: Path,
    part: Path,
    exc: BaseException,
    n_done: int,
    n_blocks: int,
    function: str = "write_cube",
) -> WorkersLostError:
    """The error of a write whose Dask cluster lost every worker (or its scheduler).

    Examples
    --------
    >>> from pathlib import Path
    >>> from sbrdf_xr.store.runners import ClusterLost
    >>> from sbrdf_xr.store.runners import lost_workers
    >>> lost = ClusterLost("the Dask cluster has had no worker for 60 s")
    >>> print(lost_workers(Path("cube.nc"), Path("cube.nc.part"), lost, 3, 20))
    writing cube.nc stopped after 3 of 20 blocks: the Dask cluster has had no worker for 60 s.
    The 3 blocks written are kept in cube.nc.part; start workers (or use no scheduler) and
    call write_cube again with resume=True
    """
    return WorkersLostError(
        f"writing {path} stopped after {n_done} of {n_blocks} blocks: {exc}. The {n_done} blocks "
        f"written are kept in {part}; start workers (or use no scheduler) and "
        f"{again_hint(function)}"
    )
