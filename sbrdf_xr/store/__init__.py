"""Writing outputs: one registry of formats, the block-by-block cube writers (netCDF and
Zarr), their lock, durability and fingerprint.

Every file the package writes is written by one entry of :data:`formats.FORMATS`, chosen
by the path's suffix in :func:`formats.format_for`, through the package's safe output
(only regular files, and Zarr stores it wrote, are ever replaced; nothing appears under
the final name until it is complete).  A cube is written block by block with bounded
memory, atomically (a ``.part`` renamed at the end) and resumably; an exclusive lock
keeps two writers apart; the fingerprint records what a cube was computed from.

Modules
-------
``formats``
    The registry: :func:`write`, :func:`~formats.check`, :func:`~formats.format_for`.
``writer``
    :func:`write_cube`: stream a lazy cube to netCDF, the calling process writing.
``zarr_store``
    :func:`write_zarr`: a lazy cube to a Zarr store, each block stored by its worker.
``layout``, ``files``, ``disk``, ``runners``, ``progress``, ``lock``
    The block layout, the files of a netCDF cube being written, disk durability and the
    words for its failures, the block computation, progress bars, the writer lock.
``derived``
    The variables computed from others: left out by the writers unless asked, put back on
    read by :func:`open_cube`.
``fingerprint``
    The content fingerprint a cube stores as global attributes (computed by the engine,
    :mod:`sbrdf_xr.engine.fingerprint`), and what changed between two.
"""

from ..errors import (
    CubeLockedError,
    CubeWriteError,
    OutputError,
    SchedulerError,
    WorkersLostError,
)
from . import (
    derived,
    disk,
    files,
    fingerprint,
    formats,
    layout,
    lock,
    progress,
    runners,
    writer,
    zarr_store,
)
from .derived import open_cube
from .files import LOG_SUFFIX, PART_SUFFIX
from .formats import FORMATS, Format, check, format_for, save_figure, write
from .layout import BlockLayout, layout_of
from .lock import LOCK_SUFFIX
from .runners import BlockWritten, connect
from .writer import DEFAULT_COMPLEVEL, write_cube
from .zarr_store import write_zarr

__all__ = [
    "DEFAULT_COMPLEVEL",
    "FORMATS",
    "LOCK_SUFFIX",
    "LOG_SUFFIX",
    "PART_SUFFIX",
    "BlockLayout",
    "BlockWritten",
    "CubeLockedError",
    "CubeWriteError",
    "Format",
    "OutputError",
    "SchedulerError",
    "WorkersLostError",
    "check",
    "connect",
    "derived",
    "disk",
    "files",
    "fingerprint",
    "format_for",
    "formats",
    "layout",
    "layout_of",
    "lock",
    "open_cube",
    "progress",
    "runners",
    "save_figure",
    "write",
    "write_cube",
    "write_zarr",
    "writer",
    "zarr_store",
]


def __getattr__(name: str) -> object:
    """Names that moved to the engine, served one more release (see
    :func:`sbrdf_xr.store.fingerprint.moved_name`)."""
    return fingerprint.moved_name(__name__, name)
