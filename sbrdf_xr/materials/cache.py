"""A disk cache for catalog tables that are built on load.

Some catalog materials are built from their measurement sets when loaded (the paper 000
§3.2 construction, filled by a fitted model); that takes seconds per table.  The table
is written once to the user's cache directory and read from there afterwards.  The key
hashes the entry's inputs (its measurement file, its fit's file, its build options) and
the sources of the modules that build tables (:func:`build_modules`), so a change of
either builds anew.

The directory is ``$SBRDF_XR_CACHE_DIR`` if set (``off`` disables the cache), else
``$XDG_CACHE_HOME/sbrdf_xr`` or ``~/.cache/sbrdf_xr``.

Every change of those sources (a new release installed) keys new tables, so the cache
keeps its upkeep here.  An entry is a table file ``{name}-{key}.nc`` (``key``: 32
hexadecimal digits) with the files the cache makes beside it: the mapped values and
their records (``.nc.float64.npy``, ``.nc.float64.meta``, also in ``float32``; older
versions left ``.nc.float64.meta.nc``), the temporaries of their atomic writes
(``<file>.<8 characters>.part``) and a marker ``.nc.used`` whose modification time is
set on every load from the cache: the entry's last use (the table and values files are
never touched: the values' record holds their times; their access times count the loads
of versions that set no marker).  No build-lock file is made: the lock is the
directory's own (:func:`cached_table`).  :func:`cache_entries` lists the
entries, :func:`prune` removes them, and every build of a table prunes the entries no
install sharing the directory used for :func:`keep_days` days.  Nothing else in the
directory is ever removed.
"""

from __future__ import annotations

import ast
import contextlib
import hashlib
import os
import re
import stat
import time
import warnings
from collections.abc import Callable, Iterable, Iterator
from functools import cache, partial
from pathlib import Path
from typing import Any, NamedTuple

import xarray as xr

from .._output import file_kind
from ..errors import CacheWarning, OutputError, ValidationError
from ..units import to_unit
from .mapped import mapped_table

__all__ = [
    "KEEP_DAYS",
    "KEEP_DAYS_ENV",
    "CacheEntry",
    "build_modules",
    "cache_dir",
    "cache_entries",
    "cache_file",
    "cached_table",
    "keep_days",
    "prune",
    "source_digest",
]


def cache_dir() -> Path | None:
    """The cache directory, or None when the cache is switched off.

    Returns
    -------
    pathlib.Path or None
        ``$SBRDF_XR_CACHE_DIR`` if set (None for ``off``, ``0``, ``none`` or empty),
        else ``$XDG_CACHE_HOME/sbrdf_xr`` or ``~/.cache/sbrdf_xr``.

    Examples
    --------
    >>> import os
    >>> os.environ["SBRDF_XR_CACHE_DIR"] = "off"
    >>> cache_dir() is None
    True
    >>> os.environ["SBRDF_XR_CACHE_DIR"] = "/tmp/tables"
    >>> str(cache_dir())
    '/tmp/tables'
    >>> del os.environ["SBRDF_XR_CACHE_DIR"]
    """
    env = os.environ.get("SBRDF_XR_CACHE_DIR")
    if env is not None:
        return None if env.strip().lower() in ("", "off", "0", "none") else Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "sbrdf_xr"


#: The modules whose code builds a catalog table from its entry: the import closure of
#: these (the construction, the models and their Fresnel terms, the table files).
_BUILD_ROOTS = (
    "sbrdf_xr.materials.tables",
    "sbrdf_xr.materials.models",
    "sbrdf_xr.materials.readers",  # a measurement entry in a laboratory's file format
    "sbrdf_xr._catalog_index",
)
#: Definitions of modules outside the closure that take part in a build: only their own
#: source counts (the catalog's loader that builds a table, not the rest of the catalog).
_BUILD_DEFINITIONS: dict[str, tuple[str, ...]] = {
    "catalog.py": (
        "LOADERS",
        "_FILE_ATTRS",
        "_built_material",
        "_load_material",
        "_progress_bar",
        "_table_dtype",
        "_table_inputs",
        "load",
    ),
}

_FROM = re.compile(r"^[ \t]*from[ \t]+([.\w]+)[ \t]+import[ \t]+(\([^)]*\)|[^\n]*)", re.M)
_IMPORT = re.compile(r"^[ \t]*import[ \t]+([^\n]*)", re.M)


def _module_file(root: Path, name: str) -> Path | None:
    """The source file of module ``name`` (``sbrdf_xr.a.b``) under the package ``root``."""
    p = root.joinpath(*name.split(".")[1:])
    for f in (p / "__init__.py", p.with_suffix(".py")):
        if f.is_file():
            return f
    return None


def _names(text: str) -> list[str]:
    """The names of an import list: ``a as b, c`` or ``(a,\n b)``."""
    return [n.split()[0] for n in text.strip("()\\ \n").split(",") if n.split()]


def _package_imports(root: Path, name: str) -> set[str]:
    """The package modules that module ``name`` imports, anywhere in its code.

    A textual scan (an ``import`` line at any indentation, comments dropped): it may
    find more than the code runs (an import in a docstring's prose), never less.
    """
    f = _module_file(root, name)
    if f is None:
        return set()
    pkg = name if f.name == "__init__.py" else name.rpartition(".")[0]
    text = re.sub(r"#[^\n]*", "", f.read_text(encoding="utf-8"))
    out: set[str] = set()
    for match in _IMPORT.finditer(text):
        out.update(
            n for n in _names(match[1]) if n.startswith("sbrdf_xr") and _module_file(root, n)
        )
    for match in _FROM.finditer(text):
        module, names = match[1], _names(match[2])
        level = len(module) - len(module.lstrip("."))
        if level:
            parts = pkg.split(".")[: len(pkg.split(".")) - level + 1]
            base = ".".join(parts + ([module[level:]] if module[level:] else []))
        elif module.startswith("sbrdf_xr"):
            base = module
        else:
            continue
        subs = [n for n in (f"{base}.{a}" for a in names) if _module_file(root, n)]
        out.update(subs)
        if len(subs) < len(names) and _module_file(root, base):
            out.add(base)  # names taken from the module itself
    return out


def build_modules(roots: Iterable[str] = _BUILD_ROOTS, root: Path | None = None) -> list[Path]:
    """Source files of the modules that can take part in building a catalog table.

    The import closure of ``roots`` (every ``import`` in a module's code, at its top or
    inside a function), plus the ``__init__.py`` of every subpackage on the way, whose
    code runs on any import below it.  The catalog (beyond its table loader,
    :data:`_BUILD_DEFINITIONS`), the spacecraft, the observing and photometry
    packages, the engine, the writers, the benchmarks and the command line are outside
    it, so changing them keeps the built tables.

    Parameters
    ----------
    roots : iterable of str
        Dotted names of the modules whose closure is wanted.
    root : pathlib.Path, optional
        The package directory to read (default: this installed package).

    Returns
    -------
    list of pathlib.Path
        The source files, sorted.

    Examples
    --------
    >>> files = build_modules()
    >>> folders = {f.parent.name for f in files}
    >>> sorted({"brdf", "geometry", "kernels", "materials", "sbrdf_xr"} - folders)
    []
    >>> sorted({"engine", "store", "cli"} & folders)
    []
    """
    root = Path(__file__).resolve().parent.parent if root is None else root
    seen: set[str] = set()
    todo = list(roots)
    while todo:
        name = todo.pop()
        if name not in seen:
            seen.add(name)
            todo.extend(_package_imports(root, name) - seen)
    files = {f for n in seen if (f := _module_file(root, n)) is not None}
    for n in seen:  # the subpackages' own __init__, without following their imports
        parts = n.split(".")
        for k in range(2, len(parts)):
            init = _module_file(root, ".".join(parts[:k]))
            if init is not None and init.name == "__init__.py":
                files.add(init)
    return sorted(files)


def _definitions(path: Path, names: tuple[str, ...]) -> str:
    """The source of the top-level definitions ``names`` of a module (function, class or
    assignment), in file order; a name that is missing counts as its absence."""
    src = path.read_text(encoding="utf-8")
    out: list[str] = []
    for node in ast.parse(src).body:
        targets = (
            [node.name]
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef)
            else [
                t.id
                for t in getattr(node, "targets", [getattr(node, "target", None)])
                if isinstance(t, ast.Name)
            ]
        )
        if any(t in names for t in targets):
            parts = [*getattr(node, "decorator_list", []), node]
            out.extend(ast.get_source_segment(src, p) or "" for p in parts)
    return "\n".join(out)


def _digest(root: Path) -> str:
    """:func:`source_digest` of the package at ``root``."""
    h = hashlib.sha256()
    for p in build_modules(root=root):
        h.update(str(p.relative_to(root)).encode())
        h.update(p.read_bytes())
    for rel, names in sorted(_BUILD_DEFINITIONS.items()):
        h.update(rel.encode())
        h.update(_definitions(root / rel, names).encode())
    return h.hexdigest()


@cache
def source_digest() -> str:
    """SHA-256 of the sources that build a table (:func:`build_modules` and the
    definitions of :data:`_BUILD_DEFINITIONS`): a change to one of them invalidates
    the cache.

    Returns
    -------
    str
        64 hexadecimal digits.

    Examples
    --------
    >>> len(source_digest())
    64
    """
    return _digest(Path(__file__).resolve().parent.parent)


def _file_digest(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(2**20), b""):
            h.update(chunk)
    return h.hexdigest()


def cache_file(name: str, inputs: Iterable[Path], options: str) -> Path | None:
    """The cache file of table ``name`` built from ``inputs`` with ``options`` (it may not
    exist yet), or None when the cache is switched off.

    Parameters
    ----------
    name : str
        The table's catalog name (the start of the file name).
    inputs : iterable of pathlib.Path
        The files the table is built from; their bytes are part of the key.
    options : str
        The build options as text; part of the key.

    Returns
    -------
    pathlib.Path or None

    Examples
    --------
    >>> import os, tempfile
    >>> os.environ["SBRDF_XR_CACHE_DIR"] = tempfile.mkdtemp()
    >>> a = cache_file("grey", [], "()")
    >>> a.name.startswith("grey-"), a == cache_file("grey", [], "()")
    (True, True)
    >>> a == cache_file("grey", [], "(dtype='float32')")
    False
    >>> del os.environ["SBRDF_XR_CACHE_DIR"]
    """
    d = cache_dir()
    if d is None:
        return None
    key = hashlib.sha256(
        "\n".join([name, options, source_digest(), *(_file_digest(p) for p in inputs)]).encode()
    ).hexdigest()[:32]
    return d / f"{name}-{key}.nc"


def cached_table(
    name: str,
    inputs: Iterable[Path],
    options: str,
    build: Callable[[], xr.DataArray],
    write: Callable[[xr.DataArray, Path], object],
    read: Callable[[Path], xr.DataArray],
    dtype: str | None = None,
) -> xr.DataArray:
    """The table ``build()`` would give, from the cache when it is there.

    The table returned is always the one read back from the cache file (when the cache
    works), so a first, building load and a later, cached load give identical tables
    (values and attributes), and so identical content fingerprints.  A damaged cache file
    is built again; an unusable directory builds the table with a
    :class:`~sbrdf_xr.errors.CacheWarning`.  One process builds at a time (an advisory
    lock of the directory); another waits and reads the file.

    Parameters
    ----------
    name, inputs, options
        The key, as for :func:`cache_file`.
    build : callable
        Builds the table (called only when no cache file is there).
    write, read : callable
        Write a table to a path (atomically) and read it back.
    dtype : str, optional
        Return the table with its values memory-mapped in this dtype (``float64`` or
        ``float32``) from a values file beside the cache file
        (:func:`sbrdf_xr.materials.mapped.mapped_table`): every process shares one copy of
        it in memory.  None: read into memory.

    Returns
    -------
    xarray.DataArray

    Examples
    --------
    >>> import os, tempfile
    >>> from sbrdf_xr.materials import constant_material, tables
    >>> os.environ["SBRDF_XR_CACHE_DIR"] = tempfile.mkdtemp()
    >>> calls = []
    >>> def build():
    ...     calls.append(1)
    ...     return constant_material(0.1, [500.0, 600.0], material="grey")
    >>> def write(table, path):
    ...     tables.to_netcdf(table, path, overwrite=True)
    >>> args = ("grey", [], "()", build, write, tables.open_material)
    >>> a = cached_table(*args)
    >>> b = cached_table(*args)
    >>> len(calls), bool((a == b).all())
    (1, True)
    >>> del os.environ["SBRDF_XR_CACHE_DIR"]
    """
    path = cache_file(name, inputs, options)
    if path is None:
        return build()
    d = path.parent
    if dtype is not None:  # mapped: the values file beside the table, or made from it
        read = partial(mapped_table, read=read, dtype=dtype)
    if file_kind(path) == "file":  # a symbolic link or special file there is not followed
        _record_use(path)
        try:
            return read(path)
        except (OSError, ValueError) as exc:  # a damaged cache file: build again
            warnings.warn(
                f"table cache file {path} could not be read ({type(exc).__name__}: {exc}); "
                f"building table {name} again",
                CacheWarning,
                stacklevel=2,
            )
            path.unlink(missing_ok=True)
    with _building(d):  # one builder at a time: another process's build is read, not redone
        if file_kind(path) == "file":
            try:
                return read(path)
            except (OSError, ValueError):  # a damaged file (warned above): build it anew
                path.unlink(missing_ok=True)
        table = build()
        try:
            d.mkdir(parents=True, exist_ok=True)
            write(table, path)  # atomic: a temporary file renamed, so two builders cannot clash
            _record_use(path)
            _auto_prune(d)  # a new table: the ones no install used for keep_days() go
            return read(path)
        except (OSError, OutputError) as exc:  # read-only, full or a special file in the way:
            _unusable(d, name, exc)  # the built table, uncached
            return table


def _unusable(d: Path, name: str, exc: Exception) -> None:
    warnings.warn(
        f"table cache {d} is not usable ({type(exc).__name__}: {exc}); table {name} "
        "was built but not kept (set SBRDF_XR_CACHE_DIR to a writable directory, or "
        "'off' to build every time without this warning)",
        CacheWarning,
        stacklevel=3,
    )


@contextlib.contextmanager
def _building(d: Path) -> Iterator[None]:
    """Hold the build lock of cache directory ``d`` (an advisory lock of the directory
    itself, released by the system if the process dies) while the block runs: a second
    process that wants a table being built waits for it and reads the file.  Without a
    usable directory (or ``fcntl``) the block runs unlocked; the atomic write keeps the
    file whole either way."""
    fd = None
    try:
        import fcntl

        d.mkdir(parents=True, exist_ok=True)
        fd = os.open(d, os.O_RDONLY)
        fcntl.flock(fd, fcntl.LOCK_EX)
    except (ImportError, OSError):
        if fd is not None:
            os.close(fd)
        fd = None
    try:
        yield
    finally:
        if fd is not None:
            os.close(fd)  # closing releases the lock


# --------------------------------------------------------------------------- upkeep

#: The environment variable that sets :func:`keep_days` (a number of days, or ``off``).
KEEP_DAYS_ENV = "SBRDF_XR_CACHE_KEEP_DAYS"
#: Days an entry no install used is kept when a table is built, unless
#: :data:`KEEP_DAYS_ENV` says otherwise [day].
KEEP_DAYS = 30.0
#: A temporary younger than this is a write in progress (a values file is written outside
#: the build lock): never removed [s].
_PART_AGE = 86400.0
_DAY = 86400.0
#: The files of an entry, as the cache names them: the table, a marker of its last use,
#: the mapped values and their records (``.meta.nc``: older versions), and the
#: temporaries of their atomic writes (:func:`sbrdf_xr._output.atomic_file`).
_ENTRY_FILE = re.compile(
    r"(?P<table>(?P<name>.+)-[0-9a-f]{32}\.nc)"
    r"(?:\.used|(?:\.float(?:32|64)\.(?:npy|meta|meta\.nc))?(?P<part>\.[a-z0-9_]{8}\.part)?)"
)


class CacheEntry(NamedTuple):
    """One table of the cache with the files the cache made beside it.

    Attributes
    ----------
    name : str
        The table's catalog name.
    table : pathlib.Path
        Its table file ``{name}-{key}.nc`` (it may be gone, its other files left).
    files : tuple of pathlib.Path
        Its files (for a pruned entry: those removed, or that a dry run would remove).
    size : int
        Their total size [byte].
    last_use : float
        When an install last loaded it, as POSIX time [s]: the newest modification or
        access time of its files but temporaries (0 if it has no other).  The marker's
        modification time is set on every load; the access times count the loads of
        versions that set no marker, where the file system records them (with
        ``relatime``, to within a day).
    current : bool or None
        Whether this installation loads it (None: not asked).

    Examples
    --------
    >>> from pathlib import Path
    >>> from sbrdf_xr.materials.cache import CacheEntry
    >>> e = CacheEntry("grey", Path("grey-" + "0" * 32 + ".nc"), (), 0, 0.0, None)
    >>> e.name, e.table.suffix
    ('grey', '.nc')
    """

    name: str
    table: Path
    files: tuple[Path, ...]
    size: int
    last_use: float
    current: bool | None


def _record_use(path: Path) -> None:
    """Set the modification time of ``path``'s marker ``.used`` to now (made if missing):
    its last use.  Anything but a regular file there, or a read-only cache: nothing."""
    used = path.with_name(path.name + ".used")
    with contextlib.suppress(OSError):
        kind = file_kind(used)
        if kind == "file":
            os.utime(used, follow_symlinks=False)
        elif kind is None:
            os.close(os.open(used, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o666))


def keep_days() -> float | None:
    """The days an entry no install used is kept when the cache builds a table.

    Returns
    -------
    float or None
        ``$SBRDF_XR_CACHE_KEEP_DAYS`` (a number of days > 0), :data:`KEEP_DAYS` when it is
        unset, or None (no automatic prune) for ``off``, ``never`` or ``none``.  Another
        value warns (:class:`~sbrdf_xr.errors.CacheWarning`) and keeps the default.

    Examples
    --------
    >>> import os
    >>> os.environ["SBRDF_XR_CACHE_KEEP_DAYS"] = "7"
    >>> keep_days()
    7.0
    >>> os.environ["SBRDF_XR_CACHE_KEEP_DAYS"] = "off"
    >>> keep_days() is None
    True
    >>> del os.environ["SBRDF_XR_CACHE_KEEP_DAYS"]
    >>> keep_days()
    30.0
    """
    text = os.environ.get(KEEP_DAYS_ENV, "").strip()
    if not text:
        return KEEP_DAYS
    if text.lower() in ("off", "never", "none"):
        return None
    try:
        days = float(text)
    except ValueError:
        days = float("nan")
    if days > 0 and days < float("inf"):
        return days
    warnings.warn(
        f"{KEEP_DAYS_ENV}: got {text!r}; allowed: a number of days > 0, or 'off'; "
        f"keeping tables {KEEP_DAYS:g} days",
        CacheWarning,
        stacklevel=2,
    )
    return KEEP_DAYS


def _directory(directory: str | os.PathLike[str] | None) -> Path:
    if directory is not None:
        return Path(directory)
    d = cache_dir()
    if d is None:
        raise ValidationError(
            f"the table cache is switched off (SBRDF_XR_CACHE_DIR="
            f"{os.environ.get('SBRDF_XR_CACHE_DIR', '')!r}): it has no entries; unset it, "
            "or set it to a directory, to use one"
        )
    return d


def _scan(d: Path) -> dict[Path, list[tuple[Path, os.stat_result, bool]]]:
    """table file -> (file, its stat, whether a temporary) of every regular file of the
    cache's naming in ``d``."""
    out: dict[Path, list[tuple[Path, os.stat_result, bool]]] = {}
    try:
        names = sorted(os.listdir(d))
    except FileNotFoundError:
        return out
    for n in names:
        m = _ENTRY_FILE.fullmatch(n)
        if m is None:
            continue
        with contextlib.suppress(OSError):
            st = os.lstat(d / n)
            if stat.S_ISREG(st.st_mode):  # a link or special file: not the cache's
                out.setdefault(d / m["table"], []).append((d / n, st, bool(m["part"])))
    return out


def _entry(table: Path, files: list[tuple[Path, Any, bool]], current: Any) -> CacheEntry:
    name = _ENTRY_FILE.fullmatch(table.name)["name"]  # type: ignore[index]
    return CacheEntry(
        name,
        table,
        tuple(f for f, _, _ in files),
        sum(st.st_size for _, st, _ in files),
        max([max(st.st_mtime, st.st_atime) for _, st, part in files if not part] or [0.0]),
        None if current is None else table in current,
    )


def cache_entries(
    current: Iterable[str | os.PathLike[str]] | None = None,
    directory: str | os.PathLike[str] | None = None,
) -> list[CacheEntry]:
    """The entries of the table cache, by name and then last use (newest first).

    Parameters
    ----------
    current : iterable of path-like, optional
        The table files this installation loads (:func:`sbrdf_xr.catalog.table_cache_files`):
        each entry's ``current`` says whether it is one.  None: not asked.
    directory : path-like, optional
        The cache directory (default :func:`cache_dir`).

    Returns
    -------
    list of CacheEntry

    Raises
    ------
    ValidationError
        The cache is switched off and no ``directory`` is given.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> d = Path(tempfile.mkdtemp())
    >>> table = d / ("grey-" + "ab" * 16 + ".nc")
    >>> for f in (table, d / (table.name + ".float64.npy"), d / "notes.txt"):
    ...     _ = f.write_bytes(b"12345")
    >>> [(e.name, len(e.files), e.size, e.current) for e in cache_entries([table], d)]
    [('grey', 2, 10, True)]
    """
    d = _directory(directory)
    keep = None if current is None else {d / Path(p).name for p in current}
    found = [_entry(t, files, keep) for t, files in _scan(d).items()]
    return sorted(found, key=lambda e: (e.name, -e.last_use, e.table.name))


def prune(
    older_than: Any = None,
    *,
    stale: bool = False,
    current: Iterable[str | os.PathLike[str]] | None = None,
    dry_run: bool = False,
    directory: str | os.PathLike[str] | None = None,
) -> list[CacheEntry]:
    """Remove entries of the table cache: those unused for a while, or not this install's.

    An entry goes when every criterion given holds.  It is removed whole (its table, its
    values files and records, its marker), except a temporary younger than a day (a
    write in progress); no other file is ever removed.  The cache's build lock is held
    while removing: a build in progress, in any process, finishes first.

    A process that loaded a pruned table keeps its values (a mapped file stays readable
    once removed), but a Dask worker that restores a plan made from it maps the file by
    name and raises :class:`~sbrdf_xr.errors.TableFileChangedError` (``gone``): restart
    the process that planned the scene and plan it again; loading the material builds
    the table anew.

    Parameters
    ----------
    older_than : float, optional
        Remove entries not used for this many days [day] (0: every entry).
    stale : bool
        Remove entries that are not among ``current``.  Another install sharing the
        directory may still use them: add ``older_than`` to spare its recent ones.
    current : iterable of path-like, optional
        The table files this installation loads
        (:func:`sbrdf_xr.catalog.table_cache_files`); required by ``stale``.
    dry_run : bool
        Remove nothing; return what would go.
    directory : path-like, optional
        The cache directory (default :func:`cache_dir`).

    Returns
    -------
    list of CacheEntry
        The entries removed (or that would be), with the files that went and their size.

    Raises
    ------
    ValidationError
        No criterion, ``older_than`` negative or not a number, ``stale`` without
        ``current``, or the cache switched off and no ``directory`` given.

    Examples
    --------
    >>> import os, tempfile
    >>> from pathlib import Path
    >>> d = Path(tempfile.mkdtemp())
    >>> old, new = (d / (f"grey-{k * 32}.nc") for k in "01")
    >>> for f in (old, new, d / "notes.txt"):
    ...     _ = f.write_bytes(b"12345")
    >>> os.utime(old, (0.0, 0.0))  # last used in 1970
    >>> [e.table.name[:6] for e in prune(older_than=30, directory=d)]
    ['grey-0']
    >>> sorted(p.name[:6] for p in d.iterdir())
    ['grey-1', 'notes.']
    >>> [e.size for e in prune(stale=True, current=[new], directory=d, dry_run=True)]
    []
    """
    d = _directory(directory)
    days = None if older_than is None else to_unit(older_than, "day", "older_than")
    try:
        days = None if days is None else float(days)
    except (TypeError, ValueError):
        days = float("nan")
    if days is not None and not 0 <= days < float("inf"):
        raise ValidationError(
            f"older_than: got {older_than!r}; allowed: a number of days >= 0 (0: every entry)"
        )
    if days is None and not stale:
        raise ValidationError(
            "prune: no entries chosen; give older_than (days unused, 0: every entry) "
            "and/or stale=True (not this installation's)"
        )
    if stale and current is None:
        raise ValidationError(
            "stale=True: give current=, the table files this installation loads "
            "(sbrdf_xr.catalog.table_cache_files())"
        )
    keep = list(current) if stale and current is not None else None
    if dry_run or not d.is_dir():
        return _prune(d, days, keep, dry_run=True)
    with _building(d):  # chosen and removed while no build runs
        return _prune(d, days, keep)


def _prune(d: Path, days: float | None, current: Any, dry_run: bool = False) -> list[CacheEntry]:
    """Remove the entries of ``d`` unused for ``days`` and not among ``current`` (None:
    either criterion not asked); the entries as removed (those of which something went)."""
    cutoff = None if days is None else time.time() - days * _DAY
    out = []
    for e in cache_entries(current, d):
        if (cutoff is None or e.last_use < cutoff) and not e.current:
            gone = _remove(e, dry_run)
            if gone.files:
                out.append(gone)
    return out


def _remove(entry: CacheEntry, dry_run: bool = False) -> CacheEntry:
    """Remove the files of ``entry`` (a young temporary stays); the entry as removed."""
    now = time.time()
    gone: list[tuple[Path, os.stat_result, bool]] = []
    for f in entry.files:
        try:
            st = os.lstat(f)
        except OSError:
            continue
        young = f.name.endswith(".part") and st.st_mtime > now - _PART_AGE
        if young or not stat.S_ISREG(st.st_mode):
            continue
        try:
            if not dry_run:
                f.unlink()
        except OSError:
            continue
        gone.append((f, st, False))
    size = sum(st.st_size for _, st, _ in gone)
    return entry._replace(files=tuple(f for f, _, _ in gone), size=size)


def _auto_prune(d: Path) -> None:
    """Within the build lock: remove the entries of ``d`` that no install used for
    :func:`keep_days` days (every install records its loads on the same markers)."""
    days = keep_days()
    if days is not None:
        with contextlib.suppress(OSError):
            _prune(d, days, None)
