"""Two steps of the netCDF cube writer (:func:`sbrdf_xr.store.writer.write_cube`): the
``.part`` file opened for a resume or created, and the blocks streamed into it, with
the writer's position kept in a :class:`Cursor` for its error handling.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NoReturn

import netCDF4
import numpy as np
import xarray as xr

from ..errors import CubeWriteError, SbrdfError
from .disk import HEAD_BYTES, SyncBehind, _NoRoom, check_held, check_room, fix, reason, reserve
from .files import (
    again_hint,
    create_part,
    open_part,
    started_again,
    to_storage,
    write_header,
)
from .layout import BlockLayout, block_bytes, lazy_bytes
from .runners import Feed


@dataclass
class Cursor:
    """Where the writer is: the block being written (-1: none), whether an I/O step is
    under way and inside HDF5 (its metadata in memory may be torn if it fails), and the
    size and head of the file at its last synced state."""

    k: int = -1
    writing: bool = False
    in_hdf5: bool = False
    good: int = -1
    head: bytes = b""


def open_or_create(
    ds: xr.Dataset,
    path: Path,
    part: Path,
    log: Path,
    plan: BlockLayout,
    runner: Any,
    feed: Feed,
    done: set[int],
    resuming: bool,
    level: int,
) -> tuple[netCDF4.Dataset, bool]:
    """The ``.part`` opened to resume it, or (nothing recorded, or not resuming) created
    with its bookkeeping first; whether it is resumed.  The first blocks compute
    meanwhile; the runner is closed on any failure."""
    nc: netCDF4.Dataset | None = None
    try:
        if resuming:
            size0 = part.stat().st_size
            check_held(part)
            try:
                check_room(part, block_bytes(plan))
                nc = open_part(part, ds, plan)
            except Exception as exc:
                if not done and not isinstance(exc, _NoRoom):
                    resuming = not started_again(part, log, exc)  # nothing recorded
                elif isinstance(exc, CubeWriteError):
                    raise
                else:
                    if not isinstance(exc, _NoRoom):
                        with contextlib.suppress(OSError):
                            os.truncate(part, size0)  # undo a half-written attribute update
                    why = reason(exc, part)
                    raise CubeWriteError(
                        f"cannot resume {path}: {why}. The {len(done)} of {plan.n_blocks} "
                        f"blocks written so far are kept in {part}; {fix(why)} and "
                        f"{again_hint()}"
                    ) from exc
            if resuming:
                feed.fill()
        if not resuming:
            log.unlink(missing_ok=True)
            part.unlink(missing_ok=True)
            # an uncompressed cube is laid out whole at creation: its room is needed now
            need = 0 if level else lazy_bytes(plan)

            def creation_failed(exc: BaseException) -> NoReturn:
                if nc is not None:
                    with contextlib.suppress(Exception):
                        nc.close()
                why = reason(exc, part, need) if isinstance(exc, Exception) else ""
                part.unlink(missing_ok=True)  # nothing recorded yet: nothing lost
                log.unlink(missing_ok=True)
                if not isinstance(exc, Exception) or isinstance(exc, SbrdfError):
                    raise exc
                raise CubeWriteError(
                    f"cannot write {path}: creating {part} failed: {why}. Nothing was "
                    f"written; {fix(why)} and write again"
                ) from exc

            try:
                check_room(part, need)  # before any block is computed
            except BaseException as exc:
                creation_failed(exc)
            feed.fill()  # the first blocks compute while the file is created and laid out
            try:
                # the bookkeeping first: a .part never exists without it, so a writer
                # killed at any instant leaves a .part that a resume continues
                write_header(log, plan, level)
                nc = create_part(part, ds, plan, level)
            except BaseException as exc:
                creation_failed(exc)
    except BaseException:
        runner.close()
        raise

    assert nc is not None  # opened (resumed) or created above, or an error was raised
    return nc, resuming


def stream(
    cur: Cursor,
    nc: netCDF4.Dataset,
    fd: int,
    sync: SyncBehind,
    feed: Feed,
    runner: Any,
    plan: BlockLayout,
    kinds: dict[str, Any],
    grows: bool,
    part: Path,
    done: set[int],
    report: Callable[[int], None],
) -> None:
    """Every pending block written as it is computed, each synced behind (in its own
    thread) while the next one is written, and reported once on disk (the last one
    waited for)."""
    while True:
        feed.fill()
        if not runner.pending:
            break
        cur.k, handle = runner.next_done()
        arrays = runner.result(handle)
        if cur.k in done:  # a block is written exactly once
            continue
        block = feed.pieces.pop(cur.k)
        nbytes = sum(np.asarray(a).nbytes for a in arrays)
        if grows:
            check_room(part, nbytes)
            reserve(fd, nbytes)
        cur.writing = cur.in_hdf5 = True
        for (name, region, _), values in zip(block, arrays, strict=True):
            expected = tuple(s.stop - s.start for s in region)
            if np.shape(values) != expected:
                raise CubeWriteError(
                    f"block {cur.k}: {name!r} computed with shape {np.shape(values)}, "
                    f"expected {expected} from the chunks"
                )
            nc.variables[name][region] = to_storage(values, kinds[name])
        del arrays
        nc.sync()
        cur.in_hdf5 = False
        cur.good, cur.head = os.fstat(fd).st_size, os.pread(fd, HEAD_BYTES, 0)
        sync.submit(cur.k)
        # the previous block, synced while this one was computed and written
        ready = sync.wait_oldest() if len(sync.pending) > 1 else None
        cur.writing = False
        if ready is not None:
            report(ready)
        cur.k = -1
    cur.writing = True
    ready = sync.wait_oldest() if sync.pending else None
    cur.writing = False
    if ready is not None:
        report(ready)
