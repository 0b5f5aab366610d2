"""Write a lazy cube to a Zarr store block by block, each block stored by whoever computes it.

:func:`write_zarr` is the Zarr twin of :func:`sbrdf_xr.store.writer.write_cube`, with the
same blocks (one chunk of every chunked dimension, :func:`~sbrdf_xr.store.layout.layout_of`),
the same lock, the same fingerprint and the same overwrite and resume rules.  The
difference: a Dask worker (or a thread of this process) that computes a block also writes
it into the store, so adding workers to a cluster speeds the whole sweep up; this process
only creates the store, hands out the blocks and renames the store when it is complete.

On disk
    ``<path>.part/`` while the cube is written: a Zarr (format 2) store with consolidated
    metadata, carrying the package's marker :data:`~sbrdf_xr._output.MARKER` from the
    instant it is created (:func:`~sbrdf_xr._output.make_marked_dir`: the header of the
    netCDF writer's sidecar, with a ``state``: ``creating``, ``writing``, ``complete``),
    and ``.sbrdf_xr_blocks/``, one empty file per block stored.  The store's metadata and
    the numpy-backed variables (coordinates) are written and synced when it is created;
    a block is marked only after its chunks were written and synced, by the process
    that wrote them, so a writer killed at any instant leaves marks only for blocks that
    are on disk.  When every block is marked the store is marked ``complete``, the block
    marks are removed and ``<path>.part`` is renamed to ``path``.  The finished store
    keeps its marker: only a directory that carries it is ever replaced or deleted.

Lock (``<path>.lock``)
    As for netCDF (:mod:`sbrdf_xr.store.lock`): one writer per path.

Resume
    ``resume=True`` with a ``.part`` checks the marker's fingerprint against the cube (a
    changed table, mesh, setting, chunking or complevel is refused, naming what
    changed) and computes only the blocks not marked.  A ``.part`` still ``creating``
    holds no block and is created again.

Compression
    By default (``complevel=None``) Zarr's own default, Blosc's LZ4 with byte shuffle:
    fast, and Zarr's chunks are independent, so compression costs a resume nothing.
    ``complevel`` 0 stores chunks uncompressed, 1-9 compresses them with Blosc's zlib at
    that level and byte shuffle (netCDF's zlib and shuffle).  A resume keeps the level of
    the ``.part`` (``complevel=None``) or refuses another one.

Chunks
    Zarr chunks are the Dask chunks, so no two blocks share a chunk; Zarr needs them of
    equal size along each dimension (the last may be smaller).
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import shutil
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .._output import (
    MARKER,
    TORN,
    cli_style,
    fsync_dir,
    fsync_tree,
    holds_nothing,
    make_marked_dir,
    open_regular,
    option,
    read_marker,
    refuse_special,
    remove_marked_dir,
    rename_no_replace,
    replace_dir,
    write_marker,
)
from ..errors import CubeWriteError, ValidationError
from .disk import check_room, drop_behind, fix, reason
from .files import PART_SUFFIX, again_hint, destination_state, discard_hint, make_parent
from .layout import (
    BlockLayout,
    describe_chunks,
    difference,
    encode_times,
    layout_of,
    lazy_bytes,
)
from .lock import LOCK_SUFFIX, _Lock
from .progress import NoProgress, progress_bar
from .runners import BlockWritten, ClusterLost, Feed, _runner, check_arguments, lost_workers

__all__ = [
    "BLOCKS",
    "FORMAT",
    "FORMAT_VERSION",
    "check_destination",
    "marked_blocks",
    "store_block",
    "unfinished",
    "write_zarr",
]

#: Format name and version in the marker of a store being written.
FORMAT = "sbrdf_xr.write_zarr"
FORMAT_VERSION = 1
#: Directory of a store's ``.part`` holding one empty file per block stored.
BLOCKS = ".sbrdf_xr_blocks"

_log = logging.getLogger("sbrdf_xr.write_cube")
_FUNCTION = "write_zarr"


def write_zarr(
    ds: xr.Dataset,
    path: str | os.PathLike[str],
    *,
    overwrite: bool = False,
    resume: bool = False,
    client: Any = None,
    scheduler: str | None = None,
    max_in_flight: int | None = None,
    progress: bool = False,
    complevel: int | None = None,
    on_block: Callable[[BlockWritten], None] | None = None,
) -> Path:
    """Compute a lazy cube block by block into a Zarr store, each block stored by its worker.

    The arguments, returns and errors are those of
    :func:`sbrdf_xr.store.writer.write_cube` (see the module documentation for the
    store's files); ``path`` is a directory (``cube.zarr``), and ``complevel`` defaults
    to Zarr's own compression (see ``Compression`` above).  ``max_in_flight`` defaults to
    two blocks per worker thread and one more: a block's result never comes back to this
    process (its worker stores it), so blocks waiting in a worker's queue hold no memory,
    and a worker that finishes one starts the next at once instead of waiting for this
    process to hand it out.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> import dask.array as da
    >>> import numpy as np
    >>> import xarray as xr
    >>> from sbrdf_xr.store.zarr_store import write_zarr
    >>> radiance = da.random.default_rng(0).random((4, 3), chunks=(2, 3)).astype("f4")
    >>> ds = xr.Dataset(
    ...     {"radiance": (("attitude", "wavelength"), radiance, {"units": "W m-2 sr-1 nm-1"})},
    ...     coords={"attitude": np.arange(4), "wavelength": [500.0, 600.0, 700.0]},
    ... )
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = write_zarr(ds, Path(tmp) / "cube.zarr")  # 2 blocks of 2 attitudes
    ...     print(path.name, os.listdir(tmp))  # no .part or .lock left
    ...     with xr.open_zarr(path) as back:
    ...         print(back.identical(ds.compute()), back["radiance"].dtype)
    ...     print(write_zarr(ds, path, resume=True) == path)  # the same cube: nothing to do
    cube.zarr ['cube.zarr']
    True float32
    True
    """
    path = Path(path)
    if path.name in ("", ".", ".."):
        raise ValidationError(f"path: {str(path)!r} names no store; give a name for the cube")
    part = path.with_name(path.name + PART_SUFFIX)
    plan = _layout(ds)
    check_arguments(max_in_flight, complevel, client, scheduler)
    make_parent(path)
    lock = _Lock(path.with_name(path.name + LOCK_SUFFIX), path)
    lock.acquire()
    try:
        state = check_destination(path, overwrite, resume)
        if state == "finished":
            _check_finished(path, plan)
            return path
        kept = _resumable(part, plan, complevel) if state == "resume" else None
        if kept is None:  # a new store, or a .part that holds no block yet
            if state == "resume" and complevel is None:  # the level it was started with
                complevel = (read_marker(part) or {}).get("complevel")
            remove_marked_dir(part, empty_ok=True, error=CubeWriteError)
            _create(ds, part, plan, complevel)
        done = kept or set()
        return _stream(
            path,
            part,
            plan,
            done,
            overwrite=overwrite,
            client=client,
            scheduler=scheduler,
            max_in_flight=max_in_flight,
            progress=progress,
            on_block=on_block,
        )
    finally:
        lock.release()


def _layout(ds: xr.Dataset) -> BlockLayout:
    """The cube's blocks, checked for what a Zarr store can hold."""
    plan = layout_of(encode_times(ds) if isinstance(ds, xr.Dataset) else ds)
    for d, cs in plan.chunks.items():
        if len(cs) > 1 and (len(set(cs[:-1])) > 1 or cs[-1] > cs[0]):
            raise ValidationError(
                f"ds: a Zarr store needs chunks of equal size along {d} (the last may be "
                f"smaller), got {cs}; rechunk the cube (ds.chunk({d}={cs[0]})) or write netCDF"
            )
    return plan


def _header(plan: BlockLayout, complevel: int | None, state: str) -> dict[str, Any]:
    return {
        "format": FORMAT,
        "version": FORMAT_VERSION,
        "state": state,
        "fingerprint": plan.fingerprint,
        "n_blocks": plan.n_blocks,
        "block_dims": list(plan.block_dims),
        "complevel": None if complevel is None else int(complevel),
        "structure": plan.structure,
    }


def check_destination(path: Path, overwrite: bool, resume: bool) -> str:
    """The overwrite/resume rules of :func:`~sbrdf_xr.store.files.check_destination`, for a
    store: ``"new"``, ``"resume"`` or ``"finished"``; nothing is touched.

    A directory at ``path`` or at its ``.part`` that does not carry the package's marker
    is refused (an empty ``.part`` excepted: it holds nothing to lose).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.errors import CubeWriteError
    >>> from sbrdf_xr.store.zarr_store import check_destination
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = Path(tmp) / "cube.zarr"
    ...     print(check_destination(path, overwrite=False, resume=False))
    ...     path.mkdir()
    ...     _ = (path / "notes.txt").write_text("mine")
    ...     try:
    ...         check_destination(path, overwrite=True, resume=False)
    ...     except CubeWriteError as exc:
    ...         print(str(exc).replace(tmp, "<tmp>"))
    new
    <tmp>/cube.zarr is a directory that sbrdf_xr did not write (it holds no .sbrdf_xr.json);
    it was left as it is. Move or remove it yourself, or choose another output
    """
    part = path.with_name(path.name + PART_SUFFIX)
    refuse_special([path, part], directory=True, error=CubeWriteError)
    refuse_special([path.with_name(path.name + LOCK_SUFFIX)], error=CubeWriteError)
    has_path = path.is_dir()
    if has_path and read_marker(path) is None:
        raise _foreign(path)
    has_part = part.is_dir() and (read_marker(part) is not None or not holds_nothing(part))
    if has_part and read_marker(part) is None:
        raise _foreign(part)
    return destination_state(path, part, has_path, has_part, overwrite=overwrite, resume=resume)


def _foreign(d: Path) -> CubeWriteError:
    return CubeWriteError(
        f"{d} is a directory that sbrdf_xr did not write (it holds no {MARKER}); it was left "
        "as it is. Move or remove it yourself, or choose another output"
    )


def _check_finished(path: Path, plan: BlockLayout) -> None:
    marker = read_marker(path) or {}
    if marker.get("fingerprint") != plan.fingerprint:
        why = difference(marker.get("structure", {}), plan.structure)
        raise CubeWriteError(
            f"{path} is a finished cube of other inputs ({why.replace('the .part', 'the store')}"
            f"); nothing was resumed. Pass {option('overwrite')} to replace it"
        )
    _log.info("%s is already complete; there is nothing to resume", path)


def _resumable(part: Path, plan: BlockLayout, complevel: int | None) -> set[int] | None:
    """Blocks already stored in ``part`` (None: it holds none and is created again)."""
    marker = read_marker(part)
    if marker is not None and marker.get("state") == TORN:
        _log.warning(
            "%s: its marker %s was cut short (a disk that filled); what it holds is "
            "unknown, so it is created again in place",
            part,
            MARKER,
        )
    if marker is None or marker.get("state") in ("creating", TORN):
        return None
    if marker.get("format") != FORMAT:
        raise CubeWriteError(
            f"{part} was written as {marker.get('format')!r}, not as a Zarr cube of this "
            f"version; it was left untouched. {discard_hint()[0].upper()}{discard_hint()[1:]}"
        )
    if marker.get("fingerprint") != plan.fingerprint:
        why = difference(marker.get("structure", {}), plan.structure)
        raise CubeWriteError(
            f"{part} belongs to a different cube ({why}); it was left untouched. "
            f"Resume with the same inputs, or {discard_hint()}"
        )
    kept = marker.get("complevel")
    if complevel is not None and kept != int(complevel):
        how = "Zarr's default compression" if kept is None else f"complevel {kept}"
        again = "without --complevel" if cli_style() else "with complevel=None"
        if kept is not None:
            again = f"--complevel {kept}" if cli_style() else f"complevel={kept}"
        raise CubeWriteError(
            f"{part} was started with {how} and this write asks for complevel {complevel}: "
            f"its chunks keep their compression, so it is resumed only with the same. "
            f"Resume with {again}, or {discard_hint()}"
        )
    if marker.get("state") == "complete":  # stopped while it was being renamed
        return set(range(plan.n_blocks))
    return marked_blocks(part, plan.n_blocks)


def marked_blocks(part: Path, n_blocks: int) -> set[int]:
    """The blocks marked as stored in the ``.part`` of a Zarr cube (numbers below ``n_blocks``).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.store.zarr_store import BLOCKS, marked_blocks
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     (Path(tmp) / BLOCKS).mkdir()
    ...     for k in ("0", "3", "x", "99"):
    ...         _ = (Path(tmp) / BLOCKS / k).write_bytes(b"")
    ...     print(sorted(marked_blocks(Path(tmp), n_blocks=4)))
    [0, 3]
    """
    try:
        names = os.listdir(part / BLOCKS)
    except OSError:
        return set()
    return {int(n) for n in names if n.isdigit() and int(n) < n_blocks}


def _codecs(complevel: int | None) -> dict[str, Any]:
    """The encoding of every variable: Zarr's default (None), none (0), or Blosc's zlib with
    byte shuffle at ``complevel``."""
    import zarr

    if complevel is None:
        return {}
    if not complevel:
        codec = None
    else:
        from numcodecs import Blosc

        codec = Blosc(cname="zlib", clevel=int(complevel), shuffle=Blosc.SHUFFLE)
    if int(zarr.__version__.split(".")[0]) >= 3:
        return {"compressors": None if codec is None else [codec]}
    return {"compressor": codec}  # pragma: no cover - zarr 2


def _create(ds: xr.Dataset, part: Path, plan: BlockLayout, complevel: int | None) -> None:
    """Create the marked ``part``: metadata and numpy-backed variables, synced."""
    try:
        check_room(part, lazy_bytes(plan) if complevel == 0 else 0)
    except OSError as exc:
        why = reason(exc, part)
        raise CubeWriteError(
            f"cannot write {part.name[: -len(PART_SUFFIX)]}: {why}. Nothing was written; "
            f"{fix(why)} and write again"
        ) from exc
    meta = ds.copy()
    for v in meta.variables.values():
        v.encoding = {}
    codecs = _codecs(complevel)
    try:
        make_marked_dir(part, _header(plan, complevel, "creating"))
        os.mkdir(part / BLOCKS)
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=".*not recognized as a component of a")
            meta.to_zarr(
                part,
                mode="a",
                compute=False,
                consolidated=True,
                zarr_format=2,
                encoding={str(n): dict(codecs) for n in meta.variables},
            )
        fsync_tree(part)
        write_marker(part, _header(plan, complevel, "writing"))
    except Exception as exc:
        with contextlib.suppress(Exception):  # nothing recorded yet: nothing lost
            remove_marked_dir(part, empty_ok=True, error=CubeWriteError)
        if isinstance(exc, ValueError | NotImplementedError | TypeError):
            raise ValidationError(f"ds: cannot be stored as Zarr ({exc})") from exc
        why = reason(exc, part)
        raise CubeWriteError(
            f"cannot write {part.name[: -len(PART_SUFFIX)]}: creating {part} failed: {why}. "
            f"Nothing was written; {fix(why)} and write again"
        ) from exc


def store_block(
    part: str, k: int, regions: list[tuple[str, tuple[slice, ...]]], arrays: tuple[Any, ...]
) -> int:
    """Write block ``k`` (its pieces ``arrays`` at ``regions``) into the store ``part``,
    sync its chunks, then mark it stored; run by the worker that computed the block.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> import xarray as xr
    >>> from sbrdf_xr.store.zarr_store import BLOCKS, store_block
    >>> ds = xr.Dataset({"v": ("x", np.zeros(4))}).chunk(x=2)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     part = Path(tmp) / "cube.zarr.part"
    ...     _ = ds.to_zarr(part, compute=False, zarr_format=2, consolidated=True)
    ...     os.mkdir(part / BLOCKS)
    ...     print(store_block(str(part), 1, [("v", (slice(2, 4),))], (np.array([5.0, 6.0]),)))
    ...     print(os.listdir(part / BLOCKS), xr.open_zarr(part).v.values.tolist())
    1
    ['1'] [nan, nan, 5.0, 6.0]
    """
    import zarr

    root = Path(part)
    for (name, region), values in zip(regions, arrays, strict=True):
        values = np.asarray(values)
        expected = tuple(s.stop - s.start for s in region)
        if values.shape != expected:
            raise ValueError(
                f"block {k}: {name!r} computed with shape {values.shape}, expected {expected} "
                "from the chunks"
            )
        arr = zarr.open_array(store=str(root / name), mode="r+")
        arr[region] = values
        _sync_chunks(root / name, tuple(arr.chunks), region)
    # the mark is an empty file: its name in the synced directory is the record
    os.close(open_regular(root / BLOCKS / str(k), os.O_WRONLY | os.O_CREAT, error=CubeWriteError))
    fsync_dir(root / BLOCKS)
    return k


def _sync_chunks(array: Path, chunks: tuple[int, ...], region: tuple[slice, ...]) -> None:
    """``fsync`` the chunk files of ``array`` (a format-2 array) that ``region`` covers."""
    try:
        sep = json.loads((array / ".zarray").read_text()).get("dimension_separator") or "."
    except (OSError, ValueError):
        sep = "."
    ranges = [range(s.start // c, -(-s.stop // c)) for s, c in zip(region, chunks, strict=True)]
    for index in np.ndindex(*(len(r) for r in ranges)) if ranges else [()]:
        key = sep.join(str(r[i]) for r, i in zip(ranges, index, strict=True)) or "0"
        with contextlib.suppress(OSError, CubeWriteError):  # an all-fill chunk is not stored
            fd = open_regular(array / key, os.O_RDONLY, error=CubeWriteError)
            try:
                os.fsync(fd)
                # on disk: its pages are not needed again (disk.drop_behind); on this
                # project's 2-core machine a 648 MB store then wrote 1.5x faster
                drop_behind(fd)
            finally:
                os.close(fd)
    fsync_dir(array)


def _stream(
    path: Path,
    part: Path,
    plan: BlockLayout,
    done: set[int],
    *,
    overwrite: bool,
    client: Any,
    scheduler: str | None,
    max_in_flight: int | None,
    progress: bool,
    on_block: Callable[[BlockWritten], None] | None,
) -> Path:
    """Hand the missing blocks out to be computed and stored, then rename the store."""
    runner = _runner(client, scheduler)

    def wrap(k: int, task: tuple[dict[Any, Any], Any]) -> tuple[dict[Any, Any], Any]:
        graph, key = task
        regions = [(name, region) for name, region, _ in plan.pieces(k)]
        out = f"write_zarr-block-{k}-{plan.fingerprint[:16]}"
        return {**graph, out: (store_block, str(part), k, regions, key)}, out

    todo = [b for b in range(plan.n_blocks) if b not in done]
    feed = Feed(plan, runner, todo, int(max_in_flight or 2 * runner.n_workers + 1), wrap)
    if done:
        _log.info("resuming %s: %d of %d blocks are kept", part, len(done), plan.n_blocks)
    bar: Any = NoProgress()
    k = -1
    try:
        bar = progress_bar(progress and plan.n_blocks > 0, plan.n_blocks, len(done), path.name)
        while True:
            feed.fill()
            if not runner.pending:
                break
            k, handle = runner.next_done()
            runner.result(handle)
            feed.pieces.pop(k, None)
            done.add(k)
            bar.update(1)
            if on_block is not None:
                on_block(BlockWritten(k, plan.slices(k), len(done), plan.n_blocks, runner.pending))
            k = -1
        _finish(path, part, plan, overwrite)
    except ClusterLost as exc:
        n = len(marked_blocks(part, plan.n_blocks))
        raise lost_workers(path, part, exc, n, plan.n_blocks, _FUNCTION) from exc
    except CubeWriteError:
        raise
    except Exception as exc:
        n = len(marked_blocks(part, plan.n_blocks))
        where = f"at block {k} " if k >= 0 else ""
        why = reason(exc, part) if isinstance(exc, OSError) else f"{type(exc).__name__}: {exc}"
        raise CubeWriteError(
            f"writing {path} failed {where}after {n} of {plan.n_blocks} blocks: {why}. The "
            f"blocks written so far are kept in {part}; {fix(why)} and "
            f"{again_hint(_FUNCTION)} to compute only the missing blocks"
        ) from exc
    except BaseException as exc:
        n = len(marked_blocks(part, plan.n_blocks))
        exc.add_note(
            f"write_zarr: {n} of {plan.n_blocks} blocks of {path} are kept in {part}; "
            f"{again_hint(_FUNCTION)} to finish it"
        )
        raise
    finally:
        runner.close()
        bar.close()
    return path


def _finish(path: Path, part: Path, plan: BlockLayout, overwrite: bool) -> None:
    """Check every block is marked, mark the store complete, tidy it and rename it to
    ``path`` (a store already marked complete was stopped while this was done)."""
    marker = read_marker(part, strict=True) or {}
    if marker.get("fingerprint") != plan.fingerprint:  # never renamed without its record
        raise CubeWriteError(
            f"{part}: its marker {MARKER} cannot be read back; the blocks stored are kept, "
            f"{again_hint(_FUNCTION)} to finish it"
        )
    if marker.get("state") != "complete":
        missing = sorted(set(range(plan.n_blocks)) - marked_blocks(part, plan.n_blocks))
        if missing:
            raise CubeWriteError(
                f"{part}: blocks {missing[:8]} were computed but are not marked as stored; "
                f"{again_hint(_FUNCTION)} to store them"
            )
        write_marker(part, {**marker, "state": "complete"})
    if (part / BLOCKS).is_dir():
        shutil.rmtree(part / BLOCKS)
    for leftover in part.glob("*/*.partial"):  # Zarr's temporary chunks of a killed writer
        leftover.unlink(missing_ok=True)
    fsync_dir(part)
    refuse_special([path], directory=True, error=CubeWriteError)
    if path.exists():
        if not overwrite:
            raise CubeWriteError(
                f"{path} appeared while the cube was written; it was not replaced and the "
                f"finished cube is kept in {part}"
            )
        replace_dir(part, path, error=CubeWriteError)
    else:
        rename_no_replace(part, path)
    fsync_dir(path.parent)


def unfinished(path: str | os.PathLike[str]) -> str | None:
    """What an unfinished Zarr cube at ``path`` keeps (its ``.part``), or None without one.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.store.zarr_store import unfinished
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     print(unfinished(Path(tmp) / "cube.zarr"))
    None
    """
    path = Path(path)
    part = path.with_name(path.name + PART_SUFFIX)
    marker = read_marker(part) if part.is_dir() else None
    if marker is None:
        return None
    n = int(marker.get("n_blocks", 0))
    chunks = describe_chunks(marker.get("structure", {}).get("chunks", []))
    level = marker.get("complevel")
    how = "Zarr's default compression" if level is None else f"complevel {level}"
    return f"{part}: {len(marked_blocks(part, n))} of {n} blocks stored, {how}, {chunks}"
