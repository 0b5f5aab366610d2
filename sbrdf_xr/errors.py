"""Exceptions and warnings raised by sbrdf_xr.

A small hierarchy: :class:`SbrdfError` is the base of everything the package
raises on purpose; :class:`ValidationError` (also a :class:`ValueError`) is raised
for bad input, with a message that names the field, what was received and what
is allowed.  Warnings derive from :class:`SbrdfWarning` so users can filter them.
:func:`did_you_mean` words the close matches of an unknown name, the same way everywhere.
"""

from __future__ import annotations

import contextlib
import difflib
import functools
import math
import os
import stat
import warnings
from collections.abc import Callable, Iterable, Iterator, Mapping
from pathlib import Path
from typing import Any, TypeVar

__all__ = [
    "MAX_FILE_BYTES",
    "AttitudeError",
    "CacheWarning",
    "CatalogError",
    "ChainLengthWarning",
    "CubeLockedError",
    "CubeWriteError",
    "DirectionError",
    "EphemerisError",
    "EpochGapWarning",
    "FitQualityWarning",
    "HiddenSideWarning",
    "InversionError",
    "LightCurveError",
    "MeshError",
    "MeshRepairWarning",
    "NonPhysicalWarning",
    "NotObservableError",
    "ObservationError",
    "OpticalConstantsError",
    "OutputError",
    "RenamedWarning",
    "SbrdfError",
    "SbrdfWarning",
    "SceneError",
    "SchedulerError",
    "StalePlanError",
    "TableFileChangedError",
    "TrackingTableError",
    "UnitError",
    "UnitWarning",
    "ValidationError",
    "WorkersLostError",
    "check_declared_size",
    "did_you_mean",
    "input_file",
    "reading",
    "renamed_attributes",
    "renamed_fields",
    "renamed_keywords",
]


def did_you_mean(name: str, known: Iterable[str], kind: str = "known names") -> str:
    """The tail of a message about an unknown name: its close matches, then the known names.

    Close matches are those of :func:`difflib.get_close_matches` (at most three, ratio at
    least 0.6), best first.  Pass only the names of the right kind (materials for a
    material, keys of that table for a key), so that the suggestion fits where the name
    was written.

    Parameters
    ----------
    name : str
        The unknown name, as given.
    known : iterable of str
        The names that would have been accepted there.
    kind : str, default "known names"
        What they are, in the plural, heading their list (``"allowed keys"``,
        ``"known materials"``).

    Returns
    -------
    str
        ``"did you mean 'a'? known materials: a, b, c"``, or ``"known materials: a, b,
        c"`` when nothing is close (``"no known materials"`` when there are none); the
        known names sorted.

    Examples
    --------
    >>> from sbrdf_xr.errors import did_you_mean
    >>> did_you_mean("phase_angle", ["bisector", "phase_angles"], "allowed keys")
    "did you mean 'phase_angles'? allowed keys: bisector, phase_angles"
    >>> did_you_mean("colour", ["bisector", "phase_angles"], "allowed keys")
    'allowed keys: bisector, phase_angles'
    """
    names = sorted({str(k) for k in known})
    if not names:
        return f"no {kind}"
    listed = f"{kind}: {', '.join(names)}"
    close = difflib.get_close_matches(str(name), names, n=3, cutoff=0.6)
    if not close:
        return listed
    return f"did you mean {' or '.join(repr(c) for c in close)}? {listed}"


def input_file(
    path: str | os.PathLike[str],
    what: str,
    error: type[Exception] | None = None,
    *,
    base_dir: str | os.PathLike[str] | None = None,
    empty_ok: bool = False,
) -> Path:
    """A file given as input, resolved and checked before anything opens it.

    ``~`` is expanded, a relative path is taken from ``base_dir`` (when given), and the
    result is made absolute with ``..`` resolved, as every message shows it.  A path that
    does not exist, a dangling symbolic link, a directory, a FIFO, a socket, a device or
    (unless ``empty_ok``) an empty file is refused with a message that names the path and
    what it is, never what it holds.

    Parameters
    ----------
    path : path-like
        The path as given.
    what : str
        Where it was given (a field or flag), heading the message.
    error : type, default ValidationError
        The error raised (a subclass of :class:`SbrdfError`).
    base_dir : path-like, optional
        Directory that relative paths are taken from (a scene file's).
    empty_ok : bool, default False
        Accept an empty file.

    Returns
    -------
    pathlib.Path
        The absolute path of a regular file (``..`` resolved as written, symbolic links
        kept, so that messages show the name the user gave).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.errors import input_file
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     _ = (Path(tmp) / "a.csv").write_text("x\\n1\\n")
    ...     ok = input_file("sub/../a.csv", "spectrum", base_dir=tmp) == Path(tmp, "a.csv")
    ...     try:
    ...         input_file(tmp, "spectrum")
    ...     except ValidationError as exc:
    ...         said = str(exc).endswith("is a directory, not a file")
    >>> ok, said
    (True, True)
    """
    err = error or ValidationError
    p = Path(os.fspath(path)).expanduser()
    if base_dir is not None and not p.is_absolute():
        p = Path(base_dir).expanduser() / p
    p = Path(os.path.normpath(os.path.abspath(p)))  # ".." taken as written
    resolved = p.resolve()
    if p.is_symlink() and not p.exists():
        raise err(f"{what}: {p} is a dangling symbolic link (its target does not exist)")
    if not p.exists():
        where = f" (relative paths are taken from {base_dir})" if base_dir is not None else ""
        raise err(f"{what}: file {p} does not exist{where}")
    mode = p.stat().st_mode
    kinds = (
        (stat.S_ISDIR, "a directory"),
        (stat.S_ISFIFO, "a FIFO (named pipe)"),
        (stat.S_ISSOCK, "a socket"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
    )
    for test, kind in kinds:
        if test(mode):
            via = f" (a link to {resolved})" if resolved != p else ""
            raise err(f"{what}: {p}{via} is {kind}, not a file")
    if not empty_ok and p.stat().st_size == 0:
        raise err(f"{what}: {p} is empty")
    if not os.access(p, os.R_OK):
        raise err(f"{what}: {p} is not readable (permission denied)")
    return resolved


def _reason(exc: BaseException) -> str:
    """What went wrong in reading, without anything the file holds."""
    if isinstance(exc, UnicodeDecodeError):
        return f"not UTF-8 text (byte {exc.object[exc.start]:#04x} at offset {exc.start})"
    if isinstance(exc, OSError) and exc.strerror:
        return str(exc.strerror)
    text = str(exc)
    if isinstance(exc, RuntimeError | OSError) and text.startswith("NetCDF:"):
        return text.split(":", 2)[1].strip() if text.count(":") > 1 else text
    return type(exc).__name__


@contextlib.contextmanager
def reading(
    path: str | os.PathLike[str], what: str, as_: str, error: type[Exception] | None = None
) -> Iterator[None]:
    """Turn a library's failure to read ``path`` into a named error that shows none of it.

    Errors of the package pass through; ``OSError``, ``RuntimeError``, ``ValueError``,
    ``KeyError``, ``IndexError``, ``TypeError``, ``EOFError``, ``StopIteration``,
    ``SyntaxError`` (XML parse errors) and ``UnicodeDecodeError``
    raised inside become ``error`` (default :class:`ValidationError`) naming the file, what
    it was read as and the kind of failure (never the library's message, which may quote
    the file's lines).

    Parameters
    ----------
    path : path-like
        The file being read.
    what : str
        Where it was given (a field or flag), heading the message.
    as_ : str
        What it was read as (``"netCDF"``, ``"a mesh"``).
    error : type, default ValidationError
        The error raised.

    Yields
    ------
    None

    Examples
    --------
    >>> from sbrdf_xr.errors import reading
    >>> try:
    ...     with reading("/tmp/x.csv", "spectrum", "CSV"):
    ...         float("SECRET")
    ... except ValidationError as exc:
    ...     print(exc)
    spectrum: /tmp/x.csv cannot be read as CSV (ValueError)
    """
    try:
        yield
    except SbrdfError:
        raise
    except (
        OSError,
        RuntimeError,
        ValueError,
        KeyError,
        IndexError,
        TypeError,
        EOFError,
        StopIteration,
        SyntaxError,  # xml.etree's ParseError
        UnicodeDecodeError,
        AttributeError,
        AssertionError,
    ) as exc:
        raise (error or ValidationError)(
            f"{what}: {path} cannot be read as {as_} ({_reason(exc)})"
        ) from None


#: Memory the arrays of a netCDF input (material table, measurement set, light curve,
#: quaternion series) may take once read [byte], times ``size_limit``.
MAX_FILE_BYTES = 4 * 2**30


def check_declared_size(
    path: Path, what: str, size_limit: float = 1.0, error: type[Exception] | None = None
) -> int:
    """The bytes the variables of the netCDF file ``path`` declare (read from its header,
    no data read); over ``size_limit`` x :data:`MAX_FILE_BYTES` a ValidationError with
    the estimate and the largest variable (``error``, default :class:`ValidationError`).
    Every reader of a netCDF input calls it first (material tables, measurement sets,
    light curves, quaternion series, measured spectra).

    Parameters
    ----------
    path : pathlib.Path
        The netCDF file.
    what : str
        What it is (``"light curve"``), heading the message.
    size_limit : float, default 1
        Factor on :data:`MAX_FILE_BYTES` [1].
    error : type, default ValidationError
        The error raised.

    Returns
    -------
    int
        The declared bytes.

    Examples
    --------
    A 2e8-long wavelength axis in a file of a few kB (the header only; HDF5 allocates
    nothing for values never written):

    >>> import tempfile
    >>> from pathlib import Path
    >>> import netCDF4
    >>> from sbrdf_xr.errors import check_declared_size
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = Path(tmp) / "sparse.nc"
    ...     with netCDF4.Dataset(path, "w") as nc:
    ...         for d, n in zip("abcw", (4, 4, 3, 200_000_000)):
    ...             _ = nc.createDimension(d, n)
    ...         _ = nc.createVariable("sbrdf", "f8", tuple("abcw"))
    ...     try:
    ...         check_declared_size(path, "material table")
    ...     except ValidationError as exc:
    ...         print(str(exc).replace(tmp, "<tmp>"))
    material table: <tmp>/sparse.nc declares 71.5 GiB of arrays (the largest, 'sbrdf', of
    shape (4, 4, 3, 200000000) float64); files of at most 4 GiB are read (size_limit 1)
    """
    import netCDF4

    with reading(path, what, "netCDF", error), netCDF4.Dataset(path, mode="r") as nc:
        sizes = {
            str(name): (tuple(v.shape), v.dtype, math.prod(float(n) for n in v.shape))
            for name, v in nc.variables.items()
        }
    nbytes = {k: n * getattr(dt, "itemsize", 16) for k, (_, dt, n) in sizes.items()}
    total = sum(nbytes.values())
    if total > size_limit * MAX_FILE_BYTES:
        big = max(nbytes, key=nbytes.__getitem__)
        raise (error or ValidationError)(
            f"{what}: {path} declares {total / 2**30:.3g} GiB of arrays (the largest, {big!r}, "
            f"of shape {sizes[big][0]} {sizes[big][1]}); files of at most "
            f"{size_limit * MAX_FILE_BYTES / 2**30:.3g} GiB are read (size_limit {size_limit:g})"
        )
    return int(total)


class SbrdfError(Exception):
    """Base class of every exception raised on purpose by sbrdf_xr."""


class ValidationError(SbrdfError, ValueError):
    """Input that does not satisfy the documented schema or domain."""


class CatalogError(SbrdfError, LookupError):
    """A catalog entry that does not exist or cannot be loaded."""


class OpticalConstantsError(ValidationError):
    """A wavelength outside the range of measured optical constants (no extrapolation)."""


class MeshError(ValidationError):
    """A spacecraft mesh that cannot be used as given."""


class SceneError(ValidationError):
    """A scene definition that cannot be compiled into a plan."""


class DirectionError(ValidationError):
    """Directions handed to a compiled evaluator (:class:`sbrdf_xr.engine.Evaluator`) that
    it cannot use: not of shape (3,) or (n, 3), NaN or infinite, or not of unit length."""


class StalePlanError(SbrdfError):
    """A compiled evaluator whose plan no longer holds the tables or terms it was compiled
    with (a field replaced, a table array made writeable, or its sampled content changed):
    compile it again from the plan."""


class TableFileChangedError(SbrdfError):
    """A memory-mapped table values file of the table cache
    (:mod:`sbrdf_xr.materials.mapped`) that changed on disk, or is gone, since its digest
    was recorded: its values are no longer those a plan or a fingerprint was made from."""


class ObservationError(ValidationError):
    """An orbit (TLE/OMM), site, time axis or observation definition that cannot be used."""


class NotObservableError(ObservationError):
    """An observation whose object is below the horizon, or in shadow, at every time."""


class EphemerisError(ObservationError):
    """A CCSDS orbit or attitude ephemeris message (OEM, AEM) that cannot be used: unreadable,
    truncated, with gaps or epochs out of order, or not covering the times asked for."""


class TrackingTableError(ObservationError):
    """An observer's tracking table (times, altitude/azimuth or RA/Dec, range or height)
    with a row that cannot be used; the message names the row."""


class AttitudeError(ValidationError):
    """An unknown attitude law or bad law parameters."""


class InversionError(ValidationError):
    """Measured data, uncertainties or a model library that an inversion cannot use."""


class OutputError(SbrdfError):
    """An output that cannot be written where asked: a special file, a symbolic link or a
    directory the package did not write at the output path (or at one of its siblings
    ``.part``, ``.lock``, ...), which is never replaced, or a write that failed."""


class CubeWriteError(OutputError):
    """A cube could not be written, or an unfinished ``.part`` cannot be resumed."""


class CubeLockedError(CubeWriteError):
    """Another writer holds the lock of this cube (``<path>.lock``)."""


class WorkersLostError(CubeWriteError):
    """The Dask cluster computing a cube lost every worker (or its scheduler); the blocks
    written so far are kept in the ``.part`` for a resume."""


class SchedulerError(SbrdfError):
    """A Dask scheduler address that is malformed or cannot be reached."""


class LightCurveError(ValidationError):
    """A measured light curve that cannot be read, or compared with a simulation as given:
    times outside the simulated window, bands not simulated, NaN rows, bad uncertainties,
    fewer observations than fitted parameters."""


class UnitError(ValidationError):
    """An astropy Quantity whose unit cannot be converted to the unit of the argument
    (a mass for a length, an ambiguous length unit)."""


class SbrdfWarning(UserWarning):
    """Base class of the warnings issued by sbrdf_xr."""


class RenamedWarning(SbrdfWarning, FutureWarning):
    """A name (keyword argument or module attribute) used under its old spelling: it still
    works for one release; the message gives the new name."""


class NonPhysicalWarning(SbrdfWarning):
    """A quantity that violates a physical bound (for example reflectance > 1)."""


class MeshRepairWarning(SbrdfWarning):
    """A spacecraft mesh was repaired as documented in :mod:`sbrdf_xr.body.spacecraft`."""


class HiddenSideWarning(SbrdfWarning):
    """Back materials on facets of a closed surface: those sides face the inside of a solid,
    can never be lit or seen, and are dropped."""


class CacheWarning(SbrdfWarning):
    """The table cache could not be used: a damaged file was built again, or the directory
    is not writable (or full), so the table was built without being kept."""


class UnitWarning(SbrdfWarning):
    """A bare number outside the plausible bounds of its documented unit: most likely a
    value in another unit (wavelengths in micrometres on a nanometre axis, a range in
    metres given in kilometres)."""


class EpochGapWarning(SbrdfWarning):
    """Observation times far from the epoch of the orbital elements (SGP4 accuracy degrades)."""


class FitQualityWarning(SbrdfWarning):
    """A fit not to be taken at face value: its chi-square lies beyond the 99.9 % point of
    its chi-square distribution (the model does not describe the data within their
    uncertainties) or below its 0.1 % point (the uncertainties are overstated), or another
    solution (a mirror or period-alias twin) fits about as well as the one reported."""


class ChainLengthWarning(SbrdfWarning):
    """A posterior sample from Markov chains shorter than 50 of their integrated
    autocorrelation times (emcee's criterion): the reported widths and percentiles are not
    converged; the message names the number of steps to ask for."""


# --- renamed names, kept for one release ---------------------------------------

_F = TypeVar("_F", bound=Callable[..., Any])


def renamed_keywords(**old_to_new: str) -> Callable[[_F], _F]:
    """Accept the old keyword names of a function for one release, with a warning.

    Parameters
    ----------
    **old_to_new
        Old keyword name -> new keyword name.

    Returns
    -------
    callable
        A decorator; the wrapped function takes the new names, and the old ones with a
        :class:`~sbrdf_xr.errors.RenamedWarning`.

    Raises
    ------
    ValidationError
        An old and its new name passed together.

    Examples
    --------
    >>> import warnings
    >>> @renamed_keywords(period_s="period")
    ... def spin(period=1.0):
    ...     return period
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     spin(period_s=3.0), caught[0].category.__name__
    (3.0, 'RenamedWarning')
    """

    def decorate(func: _F) -> _F:
        @functools.wraps(func)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            for old, new in old_to_new.items():
                if old in kwargs:
                    if new in kwargs:
                        raise ValidationError(
                            f"{func.__qualname__}() received both {old!r} and {new!r}; "
                            f"{old!r} is the old name of {new!r}: pass only {new!r}"
                        )
                    warnings.warn(
                        f"{func.__qualname__}(): the keyword {old!r} is renamed {new!r}; "
                        f"the old name will be removed in the next release",
                        RenamedWarning,
                        stacklevel=2,
                    )
                    kwargs[new] = kwargs.pop(old)
            return func(*args, **kwargs)

        return wrapper  # type: ignore[return-value]

    return decorate


def renamed_attributes(
    module: str,
    namespace: Mapping[str, Any],
    old_to_new: Mapping[str, str],
    *,
    new_module: str | None = None,
) -> Callable[[str], Any]:
    """A module ``__getattr__`` that serves renamed attributes under their old names.

    Parameters
    ----------
    module : str
        The module's name (``__name__``), for the messages.
    namespace : mapping
        The module's globals (``globals()``), where the new names live.
    old_to_new : mapping
        Old attribute name -> new attribute name.
    new_module : str, optional
        Where the new names live when they moved to another module (``namespace`` is
        then that module's globals); default ``module``.

    Returns
    -------
    callable
        ``__getattr__(name)``: the object under its new name, with a
        :class:`~sbrdf_xr.errors.RenamedWarning`, or :class:`AttributeError`.

    Examples
    --------
    >>> import warnings
    >>> getter = renamed_attributes("demo", {"EARTH_RADIUS_MEAN": 6371.0},
    ...                             {"EARTH_RADIUS_KM": "EARTH_RADIUS_MEAN"})
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     getter("EARTH_RADIUS_KM"), "EARTH_RADIUS_MEAN" in str(caught[0].message)
    (6371.0, True)
    """

    def __getattr__(name: str) -> Any:
        if name in old_to_new:
            new = old_to_new[name]
            warnings.warn(
                f"{module}.{name} is renamed {new_module or module}.{new}; "
                f"the old name will be removed in the next release",
                RenamedWarning,
                stacklevel=2,
            )
            return namespace[new]
        raise AttributeError(f"module {module!r} has no attribute {name!r}")

    return __getattr__


_C = TypeVar("_C", bound=type)


def renamed_fields(**old_to_new: str) -> Callable[[_C], _C]:
    """Accept the old field names of a (data)class for one release, with a warning.

    The constructor takes the old names as keywords (:func:`renamed_keywords`), and each
    old name stays a read-only property that returns the new field, both with a
    :class:`~sbrdf_xr.errors.RenamedWarning`.

    Parameters
    ----------
    **old_to_new
        Old field name -> new field name.

    Returns
    -------
    callable
        A class decorator.

    Examples
    --------
    >>> import warnings
    >>> from dataclasses import dataclass
    >>> @renamed_fields(height_m="height")
    ... @dataclass(frozen=True)
    ... class Post:
    ...     height: float
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     p = Post(height_m=2.0)
    ...     p.height, p.height_m, [w.category.__name__ for w in caught]
    (2.0, 2.0, ['RenamedWarning', 'RenamedWarning'])
    """

    def decorate(cls: _C) -> _C:
        cls.__init__ = renamed_keywords(**old_to_new)(cls.__init__)  # type: ignore[misc]

        def alias(old: str, new: str) -> property:
            def get(self: Any) -> Any:
                warnings.warn(
                    f"{type(self).__name__}.{old} is renamed {type(self).__name__}.{new}; "
                    f"the old name will be removed in the next release",
                    RenamedWarning,
                    stacklevel=2,
                )
                return getattr(self, new)

            return property(get, doc=f"Old name of :attr:`{new}` (deprecated).")

        for old, new in old_to_new.items():
            setattr(cls, old, alias(old, new))
        return cls

    return decorate
