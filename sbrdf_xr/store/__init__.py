"""Storing cubes: the block-by-block netCDF writer, its lock, durability and fingerprint.

A cube is written block by block with bounded memory, atomically (a ``.part`` file
renamed at the end) and resumably; an exclusive lock keeps two writers apart; the
fingerprint records what a cube was computed from.

Modules
-------
``writer``
    :func:`write_cube`: stream a lazy cube to netCDF.
``layout``, ``files``, ``disk``, ``runners``, ``progress``, ``lock`` and ``common``
    The block layout, the files of a cube being written, disk-durability primitives,
    the block computation, progress bars, the writer lock and shared names.
``fingerprint``
    The content fingerprint of a scene, stored as global attributes.
"""

from . import common, disk, files, fingerprint, layout, lock, progress, runners, writer
from .common import (
    LOCK_SUFFIX,
    LOG_SUFFIX,
    PART_SUFFIX,
    BlockWritten,
    CubeLockedError,
    CubeWriteError,
    SchedulerError,
    command_line_messages,
)
from .disk import (
    CHECK_SPACE,
    FALLOC_FL_KEEP_SIZE,
    FALLOCATE,
    HEAD_BYTES,
    SyncBehind,
    check_opens,
    check_room,
    cut_back,
    drop_behind,
    fallocate_fn,
    fence,
    file_kind,
    fsync_dir,
    reserve,
)
from .files import (
    FORMAT,
    FORMAT_VERSION,
    HDF5_CHUNK_BYTES,
    check_destination,
    check_finished,
    coordinates_attrs,
    create_part,
    hdf5_chunks,
    nc_attr,
    open_part,
    read_log,
    set_attrs,
    set_global_attrs,
    to_storage,
    tune,
    write_header,
)
from .fingerprint import PREFIX, changes, scene_fingerprint
from .layout import (
    NUMERIC_KINDS,
    VOLATILE_ATTRS,
    BlockLayout,
    LazyVariable,
    attr_json,
    block_bytes,
    check_attrs,
    difference,
    layout_of,
    storage_kind,
    values_sha,
)
from .progress import NoProgress, TextProgress, progress_bar
from .runners import connect
from .writer import DEFAULT_COMPLEVEL, write_cube

__all__ = [
    "CHECK_SPACE",
    "DEFAULT_COMPLEVEL",
    "FALLOCATE",
    "FALLOC_FL_KEEP_SIZE",
    "FORMAT",
    "FORMAT_VERSION",
    "HDF5_CHUNK_BYTES",
    "HEAD_BYTES",
    "LOCK_SUFFIX",
    "LOG_SUFFIX",
    "NUMERIC_KINDS",
    "PART_SUFFIX",
    "PREFIX",
    "VOLATILE_ATTRS",
    "BlockLayout",
    "BlockWritten",
    "CubeLockedError",
    "CubeWriteError",
    "LazyVariable",
    "NoProgress",
    "SchedulerError",
    "SyncBehind",
    "TextProgress",
    "attr_json",
    "block_bytes",
    "changes",
    "check_attrs",
    "check_destination",
    "check_finished",
    "check_opens",
    "check_room",
    "command_line_messages",
    "common",
    "connect",
    "coordinates_attrs",
    "create_part",
    "cut_back",
    "difference",
    "disk",
    "drop_behind",
    "fallocate_fn",
    "fence",
    "file_kind",
    "files",
    "fingerprint",
    "fsync_dir",
    "hdf5_chunks",
    "layout",
    "layout_of",
    "lock",
    "nc_attr",
    "open_part",
    "progress",
    "progress_bar",
    "read_log",
    "reserve",
    "runners",
    "scene_fingerprint",
    "set_attrs",
    "set_global_attrs",
    "storage_kind",
    "to_storage",
    "tune",
    "values_sha",
    "write_cube",
    "write_header",
    "writer",
]
