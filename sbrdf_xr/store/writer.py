"""Stream a lazy cube to netCDF block by block: bounded memory, atomic, resumable.

:func:`write_cube` computes a Dask-backed :class:`xarray.Dataset` one *block* at a
time and writes each block into a netCDF-4 file as soon as it arrives, so peak
memory is set by the chunk size and ``max_in_flight``, never by the cube size.

Blocks
    A block is one chunk of every chunked dimension of the Dataset (for a
    spectral cube: one ``attitude`` x ``phase_angle`` chunk, or one ``geometry``
    chunk, the spectral dimension being a single chunk), with all the lazy
    variables that fall in it.  Blocks are numbered in C order over the grid of
    chunks.  A lazy variable that lacks one of the chunked dimensions is written
    with the block whose index along that dimension is 0.

Atomicity
    Everything is written to ``<path>.part`` in the same directory, which is
    renamed (:func:`os.replace`) to ``path`` only after every block is written,
    flushed and ``fsync``-ed.  A cube is never half-written under its final name,
    and with ``overwrite=True`` the old file stays intact until the new one is
    complete (without it, the rename refuses a file that appeared meanwhile).  Only
    regular files are ever replaced or reopened (:mod:`sbrdf_xr._output`): a FIFO,
    socket, symbolic link, device node or directory at ``path`` or at its ``.part``,
    ``.part.jsonl`` or ``.lock`` is refused, overwrite or not, and never opened.

Lock (``<path>.lock``)
    One writer per path: the lock file is created atomically (``O_CREAT |
    O_EXCL``), holds the writer's pid, host and start time, and carries a ``flock``
    for the life of the write; it is removed on every way out (success, error,
    interrupt).  A second writer gets :class:`CubeLockedError` naming the holder.
    A lock left by a writer that died on this host (its pid gone, its ``flock``
    released by the kernel) is stale: it is removed with a logged message and the
    write proceeds.  A lock from another host is never removed automatically.

Durability
    A block is reported (``on_block``, the sidecar) only after its data were
    written, the file flushed (``nc.sync``) and ``fsync``-ed.  The ``fsync`` of a
    block (then its line in the sidecar, synced too) runs in a thread of its own
    while the next block is written, and is waited for before that block is
    reported, before anything is cut back and before the file is closed
    (:class:`~sbrdf_xr.store.disk.SyncBehind`).  An uncompressed cube's streamed
    variables are stored contiguous and laid out whole when the ``.part`` is created
    (:func:`~sbrdf_xr.store.files.is_contiguous`): the room of the whole cube is
    checked (free space, ``RLIMIT_FSIZE``) before creation and reserved
    (``fallocate``, where supported) before the first block, so a full disk or a
    file-size limit stops the write before any block is computed, and the blocks
    write raw values at fixed offsets without touching HDF5's metadata: a writer
    killed at any instant leaves the metadata synced at creation, and a resume
    rewrites the blocks not logged.  A compressed cube's chunks are appended and
    indexed as blocks arrive: before each block the room it needs is checked and
    reserved (``fallocate`` past the end of the file), so that a full disk or a
    file-size limit stops the write *before* HDF5 writes anything: the ``.part``
    stays exactly as last synced and the error names the cause ("no space left on
    device", "file size limit exceeded").  Should HDF5's own write fail anyway,
    HDF5's descriptor is made read-only (nothing more reaches the file) and the
    file is cut back to its last synced size and superblock; if it then does not
    open, the message says that the ``.part`` was lost.

Memory
    At most ``max_in_flight`` blocks are computed or waiting to be written.  The first
    ones are submitted as soon as the room is checked, so they compute while the
    ``.part`` is created, its numpy-backed variables written and its space reserved.  The
    page cache of each block is dropped once the block is synced
    (:func:`~sbrdf_xr.store.disk.drop_behind`): a streamed cube occupies about one
    block of page cache whatever its size, and on virtual machines whose memory the
    host reclaims the next block reuses the same pages instead of faulting in new
    ones (on this project's 2-core machine a 2.4 GB cube was written 2.3x faster).
    Memory freed while preparing the cube is handed back before the blocks stream
    (:func:`~sbrdf_xr.store.runners.release_freed_memory`).

Bookkeeping (``<path>.part.jsonl``)
    A sidecar JSON-lines file next to the ``.part``.  Line 1 is a header object::

        {"format": "sbrdf_xr.write_cube", "version": 1, "fingerprint": "<sha256>",
         "n_blocks": 24, "block_dims": ["attitude", "phase_angle"], "complevel": 0,
         "structure": {...}}

    where ``structure`` describes the cube (dims and sizes, chunks of the block
    dimensions, every variable's dims, dtype, attributes, laziness, and a SHA-256
    of the values of every numpy-backed variable, global attributes except the
    volatile ones in :data:`VOLATILE_ATTRS`) and ``fingerprint`` is the SHA-256
    of its canonical JSON.  Every following line is ``{"block": k}``, appended
    and ``fsync``-ed only after block ``k``'s data were written to the ``.part``
    and flushed to disk; a torn last line (a crash mid-append) is ignored.  The
    final netCDF file therefore carries no bookkeeping at all; the sidecar is
    deleted after the rename.  (netCDF cannot delete a variable, so a
    ``_block_done`` variable could not be removed without copying the cube.)

Resume
    ``resume=True`` with an existing ``.part`` checks that the header's
    fingerprint equals the fingerprint of ``ds`` (same dims, sizes, chunking,
    variables, dtypes, attributes and coordinate values) and then computes only
    the blocks not listed.  The lazy values themselves are not hashed (that would
    need computing them); instead cubes of :func:`sbrdf_xr.engine.run.simulate`
    carry the content fingerprint of their scene (:mod:`sbrdf_xr.store.fingerprint`:
    table values, mesh, materials map, filters, settings, geometry, version) in
    their global attributes, so a resume with other inputs is refused with a
    message naming what changed.  The header also records ``complevel``: a resume
    with another level is refused (the blocks written keep their layout), naming the
    level to resume with.  ``resume=True`` with a finished ``path`` and no
    ``.part`` checks that it is the same cube and does nothing.  Global attributes in
    :data:`VOLATILE_ATTRS` (``history`` and the ACDD dates) may change between
    runs; they are rewritten from ``ds`` on resume.

Schedulers
    By default blocks are computed in-process by a pool of threads (Dask's
    synchronous scheduler within each block, ``dask.config`` ``num_workers`` or
    the CPU count blocks at a time).  With ``client`` (a
    :class:`distributed.Client`) or ``scheduler`` (an address), each block is
    submitted to the cluster with :meth:`~distributed.Client.compute` and the
    results are gathered, as they complete, by the calling process, which is the
    only writer.  A lost worker's tasks are recomputed by Dask; a block is
    written exactly once (the writer skips blocks already recorded).  A cluster left
    without any worker for :data:`~sbrdf_xr.store.runners.NO_WORKERS_TIMEOUT` (or whose
    scheduler is gone) stops the write with :class:`~sbrdf_xr.errors.WorkersLostError`;
    the blocks written stay in the ``.part`` for a resume.

Encoding
    Variables are stored in their in-memory dtype with no fill value and no
    packing (``encoding`` set on the variables is ignored); ``bool`` is stored as
    ``int8`` with the attribute ``dtype = "bool"`` and strings as variable-length
    strings, as xarray does, so that :func:`xarray.open_dataset` gives back the
    Dataset with identical values and attributes.  Non-dimension coordinates are
    listed in ``coordinates`` attributes (per variable, or global for those that
    belong to no variable), as xarray writes them.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, NoReturn

import netCDF4
import xarray as xr

from .._output import (
    cli_style,
    fsync_dir,
    open_regular,
    refuse_special,
)
from ..errors import (
    CubeLockedError,
    CubeWriteError,
    SchedulerError,
    ValidationError,
    WorkersLostError,
)
from . import _blocks as blocks
from .disk import (
    HEAD_BYTES,
    SyncBehind,
    cut_back,
    drop_behind,
    fix,
    let_go,
    reason,
    reserve_file,
)
from .files import (
    LOG_SUFFIX,
    PART_SUFFIX,
    again_hint,
    check_destination,
    check_finished,
    clear_leftovers,
    discard_hint,
    make_parent,
    part_complevel,
    publish,
    read_back_error,
    read_log,
    started_again,
)
from .layout import (
    VOLATILE_ATTRS,
    BlockLayout,
    difference,
    layout_of,
    storage_kind,
)
from .lock import LOCK_SUFFIX, _Lock
from .progress import NoProgress, progress_bar
from .runners import (
    BlockWritten,
    ClusterLost,
    Feed,
    _runner,
    check_arguments,
    connect,
    lost_workers,
    release_freed_memory,
)

__all__ = [
    "DEFAULT_COMPLEVEL",
    "LOCK_SUFFIX",
    "LOG_SUFFIX",
    "PART_SUFFIX",
    "VOLATILE_ATTRS",
    "BlockWritten",
    "CubeLockedError",
    "CubeWriteError",
    "SchedulerError",
    "WorkersLostError",
    "connect",
    "lost_workers",
    "write_cube",
]


#: Default zlib level of a cube: 0, uncompressed, the layout that a writer killed at any
#: instant leaves resumable (see Durability above) and the fastest to write.
DEFAULT_COMPLEVEL = 0


def write_cube(
    ds: xr.Dataset,
    path: str | os.PathLike[str],
    *,
    overwrite: bool = False,
    resume: bool = False,
    client: Any = None,
    scheduler: str | None = None,
    max_in_flight: int | None = None,
    progress: bool = False,
    complevel: int | None = DEFAULT_COMPLEVEL,
    on_block: Callable[[BlockWritten], None] | None = None,
) -> Path:
    """Compute a lazy cube block by block and stream it to a netCDF-4 file.

    The file is written as ``<path>.part`` and renamed to ``path`` when complete;
    the blocks already written are recorded in ``<path>.part.jsonl`` so that an
    interrupted write can be resumed, and ``<path>.lock`` is held meanwhile so that
    no two writers share a path (see the module documentation).

    Parameters
    ----------
    ds : xarray.Dataset
        The cube.  Dask-backed variables are computed block by block (one chunk
        of every chunked dimension at a time); numpy-backed variables (usually
        the coordinates) are written first.  Chunks must agree between variables.
    path : path-like
        Destination file.
    overwrite : bool, default False
        Replace an existing ``path`` (kept intact until the new cube is
        complete) and discard an unfinished ``.part`` when not resuming.  Only a
        regular file is ever replaced.
    resume : bool, default False
        Continue an unfinished ``<path>.part`` of the same cube (same content
        fingerprint), computing only the missing blocks; without a ``.part`` the
        write starts afresh, and with a finished ``path`` of the same cube it does
        nothing.
    client : distributed.Client, optional
        Compute the blocks on this cluster (left open).
    scheduler : str, optional
        Address of a Dask scheduler (``"tcp://host:port"``) to connect to for the
        duration of the write; or ``"threads"`` (the default, in-process) or
        ``"synchronous"`` (one block at a time in the calling thread, for
        debugging).
    max_in_flight : int, optional
        Largest number of blocks being computed or waiting to be written at any
        time; bounds memory at about ``max_in_flight`` block sizes.  Default
        one more than the number of worker threads (each computes a block while
        the last one finished is written).
    progress : bool, default False
        Show a progress bar of blocks on stderr (tqdm if installed).
    complevel : int or None, default :data:`DEFAULT_COMPLEVEL` (0)
        zlib level (1-9, with byte shuffle) for the numeric variables; 0 stores
        them uncompressed (contiguous, resumable after a kill at any instant).  None:
        the level of the ``.part`` when resuming, else the default.  A resume with
        another level than the ``.part``'s is refused.
    on_block : callable, optional
        Called with a :class:`BlockWritten` in the writing thread after each
        block is committed (written, flushed, synced and recorded).

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    FileExistsError
        ``path`` exists and ``overwrite`` is false, or an unfinished ``.part``
        exists and neither ``resume`` nor ``overwrite`` is given.  Nothing is
        touched.
    ValidationError
        ``ds`` cannot be written (inconsistent chunks, unsupported dtypes or
        attributes, no data variables or a dimension of size 0) or the arguments
        are invalid.  Nothing is touched.
    CubeLockedError
        Another writer holds ``<path>.lock``.  Nothing is touched.
    SchedulerError
        ``scheduler`` cannot be reached.
    CubeWriteError
        Something other than a regular file at ``path`` (a FIFO, symlink, device,
        directory); a ``.part`` that belongs to another cube (its fingerprint
        differs: the message names what changed) or cannot be read (it is left
        untouched); a finished ``path`` of another cube with ``resume``; or a
        block computation or write that failed.  A write that fails for lack of
        room (disk full, file size limit) is refused before the block is written
        when that can be foreseen, and the file is cut back to its last synced
        state otherwise: the message names the cause, the blocks written so far
        stay in the ``.part`` and ``resume=True`` continues from them.  The
        original exception is chained.

    Notes
    -----
    Only the calling process writes; workers only compute.  Tasks shared by
    several blocks (for example a lazily built look-up table) are recomputed
    for every block: persist or compute them first.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> import dask.array as da
    >>> import numpy as np
    >>> import xarray as xr
    >>> from sbrdf_xr.store.writer import write_cube
    >>> radiance = da.random.default_rng(0).random((4, 3), chunks=(2, 3)).astype("f4")
    >>> ds = xr.Dataset(
    ...     {"radiance": (("attitude", "wavelength"), radiance, {"units": "W m-2 sr-1 nm-1"})},
    ...     coords={"attitude": np.arange(4), "wavelength": [500.0, 600.0, 700.0]},
    ... )
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = write_cube(ds, Path(tmp) / "cube.nc")  # 2 blocks of 2 attitudes
    ...     print(path.name, os.listdir(tmp))  # no .part, .part.jsonl or .lock left
    ...     with xr.open_dataset(path) as back:
    ...         print(back.identical(ds.compute()), back["radiance"].dtype)
    ...     print(write_cube(ds, path, resume=True) == path)  # the same cube: nothing to do
    cube.nc ['cube.nc']
    True float32
    True
    """
    path = Path(path)
    if path.name in ("", ".", ".."):
        raise ValidationError(f"path: {str(path)!r} names no file; give a file name for the cube")
    part = path.with_name(path.name + PART_SUFFIX)
    log = path.with_name(path.name + LOG_SUFFIX)
    plan = layout_of(ds)
    check_arguments(max_in_flight, complevel, client, scheduler)
    make_parent(path)
    lock = _Lock(path.with_name(path.name + LOCK_SUFFIX), path)
    lock.acquire()
    try:
        return _write_locked(
            ds,
            path,
            part,
            log,
            plan,
            overwrite=overwrite,
            resume=resume,
            client=client,
            scheduler=scheduler,
            max_in_flight=max_in_flight,
            progress=progress,
            complevel=complevel,
            on_block=on_block,
        )
    finally:
        lock.release()


def _write_locked(
    ds: xr.Dataset,
    path: Path,
    part: Path,
    log: Path,
    plan: BlockLayout,
    *,
    overwrite: bool,
    resume: bool,
    client: Any,
    scheduler: str | None,
    max_in_flight: int | None,
    progress: bool,
    complevel: int | None,
    on_block: Callable[[BlockWritten], None] | None,
) -> Path:
    """:func:`write_cube` once the lock is held."""
    state = check_destination(path, part, log, overwrite, resume)
    clear_leftovers(log)
    if state == "finished":
        check_finished(path, ds)
        log.unlink(missing_ok=True)
        return path
    resuming = state == "resume" and not started_again(part, log)
    done: set[int] = set()
    if resuming:
        done, complevel = _resumed(part, log, plan, complevel)
    level = DEFAULT_COMPLEVEL if complevel is None else int(complevel)

    runner = _runner(client, scheduler)
    feed = Feed(
        plan,
        runner,
        [b for b in range(plan.n_blocks) if b not in done],
        int(max_in_flight or runner.n_workers + 1),
    )
    nc: netCDF4.Dataset | None
    nc, resuming = blocks.open_or_create(
        ds, path, part, log, plan, runner, feed, done, resuming, level
    )
    bar: Any = NoProgress()
    sync: SyncBehind | None = None
    fd = log_fd = -1
    cur = blocks.Cursor()  # where the writer is, for its error handling
    damaged: str | None = None
    try:
        cur.writing = True
        fd = open_regular(part, os.O_RDWR, error=CubeWriteError)
        os.fsync(fd)
        cur.good, cur.head = os.fstat(fd).st_size, os.pread(fd, HEAD_BYTES, 0)
        log_fd = open_regular(log, os.O_WRONLY | os.O_APPEND, error=CubeWriteError)
        # blocks grow the file only where a variable is chunked (compressed)
        grows = any(nc.variables[v.name].chunking() != "contiguous" for v in plan.lazy)
        if not grows:
            reserve_file(fd)
        cur.writing = False
        release_freed_memory()  # what preparing the cube freed, before the blocks stream
        # each block goes to disk (fsync, then the log) in a thread of its own while the
        # next one is computed and written; it is reported once it is there
        sync = SyncBehind(fd, log_fd)

        def report(kk: int) -> None:
            done.add(kk)
            bar.update(1)
            if on_block is not None:
                on_block(
                    BlockWritten(kk, plan.slices(kk), len(done), plan.n_blocks, runner.pending)
                )

        kinds = {str(n): storage_kind(n, v.dtype) for n, v in ds.variables.items()}
        # a cube held in memory is written with its header: no blocks to count
        bar = progress_bar(progress and plan.n_blocks > 0, plan.n_blocks, len(done), path.name)
        blocks.stream(cur, nc, fd, sync, feed, runner, plan, kinds, grows, part, done, report)
        cur.writing = cur.in_hdf5 = True
        nc.close()
        nc = None
        cur.in_hdf5 = False
        os.ftruncate(fd, os.fstat(fd).st_size)  # release room reserved past the end
        os.fsync(fd)
        cur.writing = False
        refuse_special([path, part], error=CubeWriteError)  # nothing else appeared meanwhile
        # a .part resumed, or one whose chunk index grew with its blocks, may carry HDF5
        # metadata torn by an earlier failure; a fresh uncompressed cube's were written
        # once, at creation, and closed without error
        if resuming or grows:
            damaged = read_back_error(part)
            drop_behind(fd)  # what reading it back brought into the page cache
        if damaged is None:  # never a cube that does not read under the final name
            publish(part, path, overwrite)
    except ClusterLost as exc:
        if sync is not None:
            done.update(sync.settle())
        raise lost_workers(path, part, exc, len(done), plan.n_blocks) from exc
    except Exception as exc:
        if sync is not None:  # before anything is cut back: the blocks synced behind count
            done.update(sync.settle())
        where = f"at block {cur.k} ({_describe(plan.slices(cur.k))}) " if cur.k >= 0 else ""
        why = (
            reason(exc, part)
            if isinstance(exc, OSError) or cur.writing
            else f"{type(exc).__name__}: {exc}"
        )
        lost = None
        if (
            cur.writing and cur.good >= 0
        ):  # an I/O failure: cut the file back to its last synced state
            let_go(nc, part, cur.in_hdf5)
            nc = None
            lost = cut_back(part, cur.good, cur.head)
        intro = f"writing {path} failed {where}after {len(done)} of {plan.n_blocks} blocks: {why}. "
        if lost is not None:
            raise CubeWriteError(
                f"{intro}{part} could not be kept ({lost}); {discard_hint()}"
            ) from exc
        if cur.writing and cur.good >= 0 and cur.in_hdf5:
            raise CubeWriteError(
                f"{intro}HDF5 failed in the middle of a block; {part} was cut back to its last "
                f"synced state, with the blocks written so far. "
                f"{fix(why)[0].upper()}{fix(why)[1:]} "
                f"and {again_hint()}; should HDF5 fail again at the same block, the file cannot be "
                f"continued: {discard_hint()}"
            ) from exc
        raise CubeWriteError(
            f"{intro}The blocks written so far are kept in {part}; {fix(why)} and {again_hint()} "
            "to compute only the missing blocks"
        ) from exc
    except BaseException as exc:
        if sync is not None:
            done.update(sync.settle())
        exc.add_note(
            f"write_cube: {len(done)} of {plan.n_blocks} blocks of {path} are kept in {part}; "
            f"{again_hint()} to finish it"
        )
        raise
    finally:
        if sync is not None:
            sync.close()
        runner.close()
        bar.close()
        if nc is not None:
            with contextlib.suppress(Exception):
                nc.close()
        if fd >= 0:  # release room reserved past the end (the size is unchanged)
            with contextlib.suppress(OSError):
                os.ftruncate(fd, os.fstat(fd).st_size)
        for f in (fd, log_fd):
            if f >= 0:
                os.close(f)
    if damaged is not None:
        raise CubeWriteError(
            f"{part} holds every block but does not read back ({damaged}): an earlier "
            f"failure damaged its HDF5 metadata, so it was not renamed to {path.name}; "
            f"{discard_hint()}"
        )
    log.unlink(missing_ok=True)
    fsync_dir(path.parent)
    return path


def _resumed(
    part: Path, log: Path, plan: BlockLayout, complevel: int | None
) -> tuple[set[int], int]:
    """The blocks a resumed ``.part`` holds and the level it was started with, checked
    against this write's cube and level."""
    header, done = read_log(log, part)
    if header.get("fingerprint") != plan.fingerprint:
        why = difference(header.get("structure", {}), plan.structure)
        raise CubeWriteError(
            f"{part} belongs to a different cube ({why}); it was left untouched. "
            f"Resume with the same inputs, or {discard_hint()}"
        )
    kept = header.get("complevel")
    if kept is None:  # a sidecar written before it recorded the level: read the file
        with contextlib.suppress(OSError), netCDF4.Dataset(part, mode="r") as nc_read:
            kept = part_complevel(nc_read, plan)
    if complevel is None:  # a resume keeps the level the cube was started with
        complevel = DEFAULT_COMPLEVEL if kept is None else int(kept)
    elif kept is not None and int(kept) != int(complevel):
        _refuse_complevel(part, int(kept), complevel)
    done = {k for k in done if 0 <= k < plan.n_blocks}
    return done, complevel


def _describe(slices: Mapping[str, slice]) -> str:
    return ", ".join(f"{d}[{s.start}:{s.stop}]" for d, s in slices.items())


def _refuse_complevel(part: Path, kept: int, asked: int) -> NoReturn:
    raise CubeWriteError(
        f"{part} was started with complevel {kept} and this write asks for {asked}: its blocks "
        f"keep their layout, so it is resumed only with the same level. Resume with "
        f"{f'--complevel {kept}' if cli_style() else f'complevel={kept}'}, or {discard_hint()}"
    )
