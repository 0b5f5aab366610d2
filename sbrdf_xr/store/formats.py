"""The package's output formats: one entry each, the path's suffix choosing among them.

In the manner of xarray's backend entry points, every file the package writes is written
by the writer of one :class:`Format` entry of :data:`FORMATS`: what it writes (its
*kind*), the suffixes it owns, and its writer.  :func:`format_for` is the one place where
a path's suffix picks the entry; :func:`write` writes through it and :func:`check` refuses
an output before anything is computed.

* ``netcdf-cube`` (cube; ``.nc``, ``.nc4``, the default):
  :func:`~sbrdf_xr.store.writer.write_cube`, streamed by this process;
* ``zarr-cube`` (cube; ``.zarr``): :func:`~sbrdf_xr.store.zarr_store.write_zarr`, each
  block stored by the worker that computes it;
* ``material-netcdf`` (material): :func:`sbrdf_xr.materials.files.to_netcdf`;
* ``model-netcdf`` (model): :func:`sbrdf_xr.materials.models.to_netcdf`;
* ``photometry-netcdf`` (photometry; ``.nc``, the default) and ``photometry-csv``
  (``.csv``): :func:`sbrdf_xr.photometry.files.to_netcdf` and
  :func:`~sbrdf_xr.photometry.files.to_csv`;
* ``inversion-netcdf`` (inversion): :func:`~sbrdf_xr.materials.files.write_netcdf_atomic`;
* ``table-netcdf`` (table; ``.nc``, the default) and ``table-csv`` (``.csv``): a
  benchmark table, :func:`~sbrdf_xr.materials.files.write_netcdf_atomic`, :func:`table_to_csv`;
* ``figure`` (figure; ``.png``, ``.pdf``, ``.svg``, ...): :func:`save_figure`.

A path whose suffix no entry of its kind owns goes to the kind's default entry, unless
the suffix belongs to another kind (a cube named ``cube.csv`` or ``cube.png`` is refused,
not written as netCDF under that name).  Every writer puts its files on disk through the
package's safe output (:mod:`sbrdf_xr._output`): only regular files (and Zarr stores
the package wrote) are replaced, never a FIFO, socket, device, symbolic link or foreign
directory, at the output or at its siblings; nothing is written under the final name
until it is complete.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import xarray as xr

from .._output import (
    atomic_file,
    check_output,
    cli_style,
    error_words,
    file_kind,
    option,
    read_marker,
    refuse_special,
)
from ..errors import CubeWriteError, OutputError, ValidationError
from .derived import OUTPUTS, lean
from .files import LOG_SUFFIX, PART_SUFFIX, discard_hint, read_log
from .files import check_destination as cube_destination
from .layout import describe_chunks, encode_times, layout_of
from .lock import LOCK_SUFFIX
from .writer import write_cube
from .zarr_store import check_destination as zarr_destination
from .zarr_store import unfinished as zarr_unfinished
from .zarr_store import write_zarr

__all__ = [
    "FORMATS",
    "KINDS",
    "Format",
    "check",
    "format_for",
    "save_figure",
    "table_to_csv",
    "write",
    "write_netcdf_cube",
    "write_zarr_cube",
]

#: What the package writes, one kind per sort of object, and its name in messages.
KINDS = {
    "cube": "a cube",
    "material": "a material table",
    "model": "a model material",
    "photometry": "a photometry table",
    "inversion": "an inversion result",
    "table": "a benchmark table",
    "figure": "a figure",
}


@dataclasses.dataclass(frozen=True)
class Format:
    """One output format: what it writes, the suffixes it owns, its writer.

    Attributes
    ----------
    name : str
        The entry's name in :data:`FORMATS`.
    kind : str
        What it writes (one of :data:`KINDS`).
    suffixes : tuple of str
        Path suffixes it owns (lower case, with the dot).
    writer : callable
        ``writer(obj, path, *, overwrite=False, **options) -> Path``.
    label : str
        The format's name in messages (``netCDF``, ``Zarr``, ``CSV``, ``image``).
    description : str
        One line for messages and listings.
    default : bool
        The entry of its kind for a path whose suffix no entry of the kind owns.
    directory : bool
        The output is a directory (a Zarr store), not a file.
    siblings : tuple of str
        Suffixes of the files beside the output that the writer uses (``.part``, ...).
    destination : callable, optional
        ``destination(path, overwrite, resume)``: refuses what is at the output and its
        siblings before anything is computed (default
        :func:`sbrdf_xr._output.check_output`).
    unfinished : callable, optional
        ``unfinished(path) -> str | None``: what an interrupted write keeps for a resume.

    Examples
    --------
    >>> from sbrdf_xr.store.formats import FORMATS
    >>> f = FORMATS["zarr-cube"]
    >>> f.kind, f.suffixes, f.directory, f.siblings
    ('cube', ('.zarr',), True, ('.part', '.lock'))
    """

    name: str
    kind: str
    suffixes: tuple[str, ...]
    writer: Callable[..., Path]
    label: str
    description: str
    default: bool = False
    directory: bool = False
    siblings: tuple[str, ...] = ()
    destination: Callable[[Path, bool, bool], Any] | None = None
    unfinished: Callable[[str | os.PathLike[str]], str | None] | None = None


def write_netcdf_cube(
    cube: Any, path: str | os.PathLike[str], *, outputs: str | None = None, **options: Any
) -> Path:
    """:func:`~sbrdf_xr.store.writer.write_cube` of ``cube`` with its times encoded as CF
    numbers (:func:`~sbrdf_xr.store.layout.encode_times`), its derived variables left out
    unless ``outputs="all"`` (:func:`~sbrdf_xr.store.derived.lean`).

    ``outputs=None`` (the default) is ``"independent"``, except on a resume of a ``.part``
    started with every variable (by ``outputs="all"``, or by a version that wrote every
    variable): the resume keeps the variables the ``.part`` has.  An ``outputs`` given
    that differs from the ``.part``'s is refused (:class:`~sbrdf_xr.errors.CubeWriteError`
    naming the value to resume with).  A lazy cube is rechunked to the block sizes the
    ``.part`` was started with (an older default ``block_bytes``, or another value of it).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> import xarray as xr
    >>> from sbrdf_xr.store.formats import write_netcdf_cube
    >>> times = np.array(["2026-01-01T00:00", "2026-01-01T00:01"], dtype="datetime64[ns]")
    >>> cube = xr.Dataset({"v": ("time", [1.0, 2.0])}, coords={"time": times}).chunk(time=1)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = write_netcdf_cube(cube, Path(tmp) / "cube.nc")
    ...     with xr.open_dataset(path) as back:
    ...         print(back.time.values.tolist() == cube.time.values.tolist())
    True
    """
    cube = _as_part(cube, Path(path), outputs, bool(options.get("resume")), _log_header)
    return write_cube(encode_times(cube), path, **options)


def _as_part(
    cube: Any,
    path: Path,
    outputs: str | None,
    resume: bool,
    recorded: Callable[[Path], dict[str, Any] | None],
) -> Any:
    """The cube to write: its derived variables left out unless ``outputs="all"``; on a
    resume, the variables and the block sizes the ``.part`` was started with.

    A ``.part`` is recognised by its fingerprint (``recorded(part)``: the header of its
    record, None where there is none): a ``.part`` begun with every variable resumes with
    them (an ``outputs`` asked that differs is refused, naming the one to resume with);
    one begun with other block sizes (an older default ``block_bytes``) has the cube's
    chunks made its own.  Anything else is left to the writer, which names what differs.
    """
    part = path.with_name(path.name + PART_SUFFIX)
    header = recorded(part) if resume and isinstance(cube, xr.Dataset) else None
    if header is None or outputs not in (None, *OUTPUTS):
        return lean(cube, outputs or OUTPUTS[0])  # (an unknown value: lean says what is allowed)
    found = header.get("fingerprint")
    cubes = {o: _part_chunks(lean(cube, o), header) for o in OUTPUTS}
    prints = {o: layout_of(encode_times(c)).fingerprint for o, c in cubes.items()}
    started = next((o for o, f in prints.items() if f == found), None)
    if started is None or len(set(prints.values())) == 1 or outputs in (None, started):
        return cubes[started or outputs or OUTPUTS[0]]  # (another cube: the writer refuses it)
    how = {"all": "every variable written", "independent": "the derived variables left out"}
    again = f"--outputs {started}" if cli_style() else f"outputs={started!r}"
    raise CubeWriteError(
        f"{part} was started with outputs={started!r} ({how[started]}) and this write asks "
        f"for outputs={outputs!r}: its blocks keep their variables, so it is resumed only "
        f"with the same. Resume with {again} (or without it: a resume keeps the variables "
        f"the .part has), or {discard_hint()}"
    )


def _part_chunks(cube: xr.Dataset, header: dict[str, Any]) -> xr.Dataset:
    """``cube`` rechunked to the block sizes recorded in a ``.part``'s ``header`` where it
    is lazy and they tile its dimensions; unchanged otherwise."""
    chunks = dict((header.get("structure") or {}).get("chunks") or [])
    try:
        now = cube.chunks
    except ValueError:  # variables chunked differently along a dimension
        now = {"": ()}
    if not now or not chunks:
        return cube
    if any(
        d not in cube.sizes or not isinstance(c, list) or sum(c) != cube.sizes[d]
        for d, c in chunks.items()
    ):
        return cube
    if all(tuple(now.get(d, ())) == tuple(c) for d, c in chunks.items()):
        return cube

    lazy = {v.get("name") for v in header["structure"].get("variables", []) if v.get("lazy")}

    def own(names: Any) -> dict[Any, xr.Variable]:  # lazy or eager as in the .part
        return {  # (variables: a DataArray would rechunk its coordinates with it)
            n: cube[n].variable.chunk({d: tuple(chunks[d]) for d in cube[n].dims if d in chunks})
            if n in lazy
            else cube[n].variable.load()
            for n in names
            if n not in cube.indexes and (n in lazy or cube[n].chunks is not None)
        }

    out = cube.assign_coords(own(cube.coords)).assign(own(cube.data_vars))
    recorded = (header.get("structure") or {}).get("attrs") or {}
    out.attrs = {  # the attributes that describe the blocks: those of the .part's
        **cube.attrs,
        **{k: recorded[k] for k in _BLOCK_ATTRS if k in recorded and k in cube.attrs},
    }
    return out


#: Global attributes of a simulated cube that describe its blocks, not its values.
_BLOCK_ATTRS = ("knob_chunk", "plan")


def _log_header(part: Path) -> dict[str, Any] | None:
    """The header of the block log of a netCDF ``.part`` (None without one)."""
    try:
        header, _ = read_log(part.with_name(part.name[: -len(PART_SUFFIX)] + LOG_SUFFIX), part)
    except (OutputError, OSError):
        return None
    return dict(header)


def _marker_header(part: Path) -> dict[str, Any] | None:
    """The marker of a Zarr ``.part`` store (None without one)."""
    return read_marker(part)


def write_zarr_cube(
    cube: Any, path: str | os.PathLike[str], *, outputs: str | None = None, **options: Any
) -> Path:
    """:func:`~sbrdf_xr.store.zarr_store.write_zarr` of ``cube``, its derived variables left
    out unless ``outputs="all"`` (:func:`~sbrdf_xr.store.derived.lean`).

    A resume keeps the variables and the block sizes the ``.part`` store was started with,
    as :func:`write_netcdf_cube`.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import xarray as xr
    >>> from sbrdf_xr.store.formats import write_zarr_cube
    >>> cube = xr.Dataset({"signal_material": (("g", "material"), [[1.0, 2.0]]),
    ...                    "signal": ("g", [3.0])}).chunk(g=1)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = write_zarr_cube(cube, Path(tmp) / "cube.zarr")
    ...     with xr.open_zarr(path) as back:
    ...         print(list(back.data_vars))
    ['signal_material']
    """
    return write_zarr(
        _as_part(cube, Path(path), outputs, bool(options.get("resume")), _marker_header),
        path,
        **options,
    )


def _netcdf_unfinished(path: str | os.PathLike[str]) -> str | None:
    path = Path(path)
    part = path.with_name(path.name + PART_SUFFIX)
    log = path.with_name(path.name + LOG_SUFFIX)
    try:
        header, done = read_log(log, part)
    except (OutputError, OSError):
        return None
    n = int(header.get("n_blocks", 0))
    level = header.get("complevel", "as created")
    return (
        f"{part}: {len({k for k in done if 0 <= k < n})} of {n} blocks written, complevel "
        f"{level}, {describe_chunks(header.get('structure', {}).get('chunks', []))}"
    )


def table_to_csv(ds: Any, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
    """Write a table Dataset (one row per coordinate value) as CSV, atomically.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import xarray as xr
    >>> from sbrdf_xr.store.formats import table_to_csv
    >>> ds = xr.Dataset({"time_ratio": ("case", [1.0, 0.4])}, coords={"case": ["a", "b"]})
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     print(table_to_csv(ds, Path(tmp) / "bench.csv").read_text().splitlines())
    ['case,time_ratio', 'a,1.0', 'b,0.4']
    """
    with atomic_file(path, overwrite=overwrite) as tmp:
        ds.to_dataframe().to_csv(tmp)
    return Path(path)


#: Image formats that figures are saved in (those of Matplotlib's Agg and vector backends).
FIGURE_SUFFIXES: tuple[str, ...] = (".png", ".pdf", ".svg", ".svgz", ".eps", ".ps", ".jpg")
FIGURE_SUFFIXES += (".jpeg", ".tif", ".tiff", ".webp")


def save_figure(
    fig: Any, path: str | os.PathLike[str], *, overwrite: bool = False, dpi: float = 120
) -> Path:
    """Save a Matplotlib figure atomically, in the format of the path's suffix.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> from sbrdf_xr.store.formats import save_figure
    >>> fig, ax = plt.subplots()
    >>> _ = ax.plot([0, 1], [1, 0])
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     print(save_figure(fig, Path(tmp) / "curve.png").read_bytes()[1:4])
    b'PNG'
    >>> plt.close(fig)
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in FIGURE_SUFFIXES:
        raise ValidationError(
            f"{path}: a figure is saved as {', '.join(FIGURE_SUFFIXES)}, not "
            f"{suffix or 'without a suffix'}"
        )
    with atomic_file(path, overwrite=overwrite) as tmp, open(tmp, "wb") as f:
        fig.savefig(f, format=suffix[1:], dpi=dpi)
    return path


def _material(obj: Any, path: str | os.PathLike[str], **options: Any) -> Path:
    from ..materials.files import to_netcdf

    return to_netcdf(obj, path, **options)


def _model(obj: Any, path: str | os.PathLike[str], **options: Any) -> Path:
    from ..materials.models import to_netcdf

    return to_netcdf(obj, path, **options)


def _dataset(obj: Any, path: str | os.PathLike[str], **options: Any) -> Path:
    from ..materials.files import write_netcdf_atomic

    return write_netcdf_atomic(obj, path, **options)


def _photometry(obj: Any, path: str | os.PathLike[str], **options: Any) -> Path:
    from ..photometry.files import to_netcdf

    return to_netcdf(obj, path, **options)


def _photometry_csv(obj: Any, path: str | os.PathLike[str], **options: Any) -> Path:
    from ..photometry.files import to_csv

    return to_csv(obj, path, **options)


def _netcdf_destination(path: Path, overwrite: bool, resume: bool) -> None:
    refuse_special([path.with_name(path.name + LOCK_SUFFIX)], error=CubeWriteError)
    part, log = (path.with_name(path.name + s) for s in (PART_SUFFIX, LOG_SUFFIX))
    cube_destination(path, part, log, overwrite, resume)


def _zarr_destination(path: Path, overwrite: bool, resume: bool) -> None:
    zarr_destination(path, overwrite, resume)


#: Every output format, by name.
FORMATS: dict[str, Format] = {
    f.name: f
    for f in (
        Format(
            "netcdf-cube",
            "cube",
            (".nc", ".nc4"),
            write_netcdf_cube,
            "netCDF",
            "a cube as netCDF-4, streamed block by block by this process",
            default=True,
            siblings=(PART_SUFFIX, LOG_SUFFIX, LOCK_SUFFIX),
            destination=_netcdf_destination,
            unfinished=_netcdf_unfinished,
        ),
        Format(
            "zarr-cube",
            "cube",
            (".zarr",),
            write_zarr_cube,
            "Zarr",
            "a cube as a Zarr store, each block stored by the worker that computes it",
            directory=True,
            siblings=(PART_SUFFIX, LOCK_SUFFIX),
            destination=_zarr_destination,
            unfinished=zarr_unfinished,
        ),
        Format(
            "material-netcdf",
            "material",
            (".nc",),
            _material,
            "netCDF",
            "a material table or measurement set as netCDF",
            default=True,
        ),
        Format(
            "model-netcdf",
            "model",
            (".nc",),
            _model,
            "netCDF",
            "a BRDF model material as netCDF",
            default=True,
        ),
        Format(
            "photometry-netcdf",
            "photometry",
            (".nc",),
            _photometry,
            "netCDF",
            "band magnitudes and colours as CF-1.10 netCDF",
            default=True,
        ),
        Format(
            "photometry-csv",
            "photometry",
            (".csv",),
            _photometry_csv,
            "CSV",
            "band magnitudes and colours as a CSV table, one row per geometry",
        ),
        Format(
            "inversion-netcdf",
            "inversion",
            (".nc",),
            _dataset,
            "netCDF",
            "an inversion result as netCDF",
            default=True,
        ),
        Format(
            "table-netcdf",
            "table",
            (".nc",),
            _dataset,
            "netCDF",
            "a benchmark table as netCDF",
            default=True,
        ),
        Format("table-csv", "table", (".csv",), table_to_csv, "CSV", "a benchmark table as CSV"),
        Format("figure", "figure", FIGURE_SUFFIXES, save_figure, "image", "a Matplotlib figure"),
    )
}


def _suffix(path: str | os.PathLike[str]) -> str:
    return Path(str(path).rstrip("/" + os.sep)).suffix.lower()


def format_for(path: str | os.PathLike[str], kind: str, name: str | None = None) -> Format:
    """The entry that writes an object of ``kind`` to ``path``: the one place where the
    path's suffix picks the format (or ``name`` names it).

    Examples
    --------
    >>> from sbrdf_xr.store.formats import format_for
    >>> format_for("sweep.zarr", "cube").name, format_for("sweep.nc", "cube").name
    ('zarr-cube', 'netcdf-cube')
    >>> format_for("sweep", "cube").name  # no suffix: the kind's default
    'netcdf-cube'
    >>> format_for("mags.csv", "photometry").name
    'photometry-csv'
    >>> format_for("sweep.png", "cube")
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.ValidationError: sweep.png: a cube is written as netCDF (.nc, .nc4, or any \
other name) or Zarr (.zarr), not .png (the suffix of a figure)
    """
    if kind not in KINDS:
        raise ValidationError(f"kind: {kind!r} is not one of {', '.join(KINDS)}")
    entries = [f for f in FORMATS.values() if f.kind == kind]
    if name is not None:
        if name not in FORMATS or FORMATS[name].kind != kind:
            names = ", ".join(f.name for f in entries)
            raise ValidationError(
                f"format: {name!r} does not write {KINDS[kind]} (those that do: {names})"
            )
        return FORMATS[name]
    suffix = _suffix(path)
    for f in entries:
        if suffix in f.suffixes:
            return f
    others = [f for f in FORMATS.values() if f.kind != kind and suffix in f.suffixes]
    default = next((f for f in entries if f.default), None)
    if others or default is None:
        owned = " or ".join(
            f"{f.label} ({', '.join(f.suffixes)}{', or any other name' if f.default else ''})"
            for f in entries
        )
        kinds = dict.fromkeys(KINDS[f.kind] for f in others)
        owner = f" (the suffix of {' or '.join(kinds)})" if others else ""
        raise ValidationError(
            f"{path}: {KINDS[kind]} is written as {owned}, not {suffix or 'without a suffix'}"
            f"{owner}"
        )
    return default


def check(
    path: str | os.PathLike[str],
    kind: str,
    *,
    overwrite: bool = False,
    resume: bool = False,
    name: str | None = None,
) -> Format:
    """Refuse an output before anything is computed: a suffix of another kind, a special
    file or symbolic link at the output or its siblings, an existing output without
    ``overwrite`` (or ``resume``, for a cube).  Returns the format that will write it.

    Examples
    --------
    >>> import os
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.errors import OutputError
    >>> from sbrdf_xr.store.formats import check
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     print(check(Path(tmp) / "mags.csv", "photometry").name)
    ...     os.mkfifo(Path(tmp) / "pipe.csv")
    ...     try:
    ...         check(Path(tmp) / "pipe.csv", "photometry", overwrite=True)
    ...     except OutputError as exc:
    ...         print(str(exc).replace(tmp, "<tmp>"))
    photometry-csv
    <tmp>/pipe.csv is a FIFO (named pipe), not a regular file; outputs replace only regular
    files, even with overwrite=True. Remove it or choose another output
    """
    if str(path) == "-":
        raise ValidationError(
            "'-' names no file: outputs are written to files, not to standard output; give "
            "a file name"
        )
    fmt = format_for(path, kind, name)
    p = Path(path)
    if p.name in ("", ".", ".."):
        raise ValidationError(f"{str(path)!r} names no file; give a file name for the output")
    if fmt.destination is not None:
        fmt.destination(p, overwrite, resume)
    else:
        check_output(p, overwrite=overwrite)
    if resume and not overwrite:
        _resume_keeps_the_format(p, fmt)
    _check_writable(p)
    return fmt


def _check_writable(path: Path) -> None:
    """Refuse an output whose directory cannot be written (read-only, permissions, a
    file where a directory goes): a file created and removed in the nearest existing
    directory on its way proves it can."""
    import tempfile

    d = path.parent.absolute()
    while not d.exists() and d != d.parent:
        d = d.parent
    if not d.is_dir():
        raise ValidationError(f"cannot write {path}: {d} is not a directory")
    try:
        fd, probe = tempfile.mkstemp(prefix=".sbrdf_xr-probe-", dir=d)
    except OSError as exc:
        why = error_words(exc) or str(exc)
        raise ValidationError(f"cannot write {path}: {why} in {d}") from None
    os.close(fd)
    os.unlink(probe)


def _resume_keeps_the_format(path: Path, fmt: Format) -> None:
    """Refuse a resume of ``path`` that has nothing to resume while the same cube in
    another format (the same name, another suffix) is unfinished: a resume keeps the
    format it was started in, so the change is named instead of starting afresh."""
    if fmt.unfinished is None or file_kind(path) is not None or fmt.unfinished(path):
        return
    for other in FORMATS.values():
        if other.kind != fmt.kind or other is fmt or other.unfinished is None:
            continue
        for suffix in other.suffixes:
            candidate = path.with_name((path.stem if path.suffix else path.name) + suffix)
            kept = other.unfinished(candidate)
            if kept:
                raise CubeWriteError(
                    f"{path}: nothing to resume, but the {other.label} cube {candidate} is "
                    f"unfinished ({kept}); a resume keeps the format it was started in. "
                    f"Resume {candidate} instead, or write {path} afresh without "
                    f"{option('resume')}"
                )


def write(obj: Any, path: str | os.PathLike[str], *, kind: str = "cube", **options: Any) -> Path:
    """Write ``obj`` to ``path`` in the format its suffix picks among those of ``kind``.

    For a cube (the default kind): netCDF, streamed block by block by this process
    (atomic, resumable; :func:`~sbrdf_xr.store.writer.write_cube`), or for a path ending
    in ``.zarr`` a Zarr store whose blocks the Dask workers (or threads) that compute
    them store themselves (:func:`~sbrdf_xr.store.zarr_store.write_zarr`); both take
    ``overwrite``, ``resume``, ``client``, ``scheduler``, ``max_in_flight``, ``progress``,
    ``complevel`` and ``on_block``.  A cube is written with its independent variables
    only (``outputs="independent"``, the default): those computed from others
    (``brdf``, and ``signal`` beside ``signal_material``) are recorded and computed again
    on read by :func:`~sbrdf_xr.store.derived.open_cube`; ``outputs="all"`` writes every
    variable (:mod:`sbrdf_xr.store.derived`).

    Returns
    -------
    pathlib.Path
        ``path``.

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, geometry, load_spacecraft, simulate
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> turns = geometry.axis_rotation([0, 0, 1], [0.0, 45.0])  # two attitudes about z
    >>> scene = Scene(box, {"grey": grey}, attitudes=turns, phase_angles=[0.0, 60.0])
    >>> import tempfile, xarray as xr
    >>> from pathlib import Path
    >>> from sbrdf_xr import write
    >>> cube = simulate(scene)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     for name in ("cube.nc", "cube.zarr"):
    ...         path = write(cube, Path(tmp) / name)
    ...         with xr.open_dataset(path) as back:
    ...             print(path.name, back.signal.shape, round(float(back.signal[1, 0, 0]), 6))
    cube.nc (2, 2, 3) 0.159155
    cube.zarr (2, 2, 3) 0.159155
    """
    return format_for(path, kind).writer(obj, path, **options)
