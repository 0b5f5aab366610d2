"""The catalog index: where the shipped items are (no loading; :mod:`sbrdf_xr.catalog` loads).

The catalog directory holds ``index.toml``, one ``[[entry]]`` table per item::

    [[entry]]
    name = "lambertian-grey-50"          # unique, lower-case, used by load()
    kind = "material"                    # material | measurements | model
                                         # | paint_parameters | spacecraft
                                         # | orbit (a TLE file)
                                         # | site (a table of a TOML file of sites)
    path = "materials/lambertian-grey-50.nc"   # relative to the catalog directory
    source = "synthetic"                 # measured | synthetic | model:<name>
    description = "..."                  # what it is
    provenance = "..."                   # where its numbers come from

In a source checkout the directory is the top-level ``catalogs/``; an installed
package carries a copy at ``sbrdf_xr/catalogs`` (see ``pyproject.toml``).

User catalogs extend the shipped one: the environment variable ``SBRDF_XR_CATALOG_PATH``
(:data:`CATALOG_PATH_ENV`) lists directories, separated by :data:`os.pathsep`, each with an
``index.toml`` of the same format whose paths are relative to that directory.  Their
entries may add names; a name already in the shipped catalog or in an earlier user
catalog is refused with a :class:`~sbrdf_xr.errors.CatalogError` (a user entry never
silently replaces another).  :attr:`CatalogEntry.origin` says where an entry comes from.

This module reads the index only; the domain modules read an entry's file given the
entry, and :mod:`sbrdf_xr.catalog` maps every kind to its loader.
"""

from __future__ import annotations

import os
import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

from .errors import CatalogError, did_you_mean

__all__ = [
    "CATALOG_PATH_ENV",
    "ENTRY_KINDS",
    "SOURCES",
    "CatalogEntry",
    "catalog_dir",
    "data_path",
    "entries",
    "entry",
    "names",
    "user_catalog_dirs",
]

#: Environment variable listing user catalog directories (separated by :data:`os.pathsep`).
CATALOG_PATH_ENV = "SBRDF_XR_CATALOG_PATH"

ENTRY_KINDS = (
    "material",
    "measurements",
    "model",
    "paint_parameters",
    "spacecraft",
    "orbit",
    "site",
)
SOURCES = ("measured", "synthetic")


@dataclass(frozen=True)
class CatalogEntry:
    """One item of the catalog index.

    Attributes
    ----------
    name, kind, path, source, description, provenance : str
        Fields of the ``[[entry]]`` table (see the module docstring).
    extra : dict
        Any further fields of the table (for example the material of a model).
    root : Path or None
        Directory of the user catalog holding the entry; None for the shipped catalog.

    Examples
    --------
    >>> from sbrdf_xr import catalog
    >>> e = catalog.entry("canx1")
    >>> e.kind, e.path, e.file.name
    ('spacecraft', 'spacecraft/canx1.ply', 'canx1.ply')
    """

    name: str
    kind: str
    path: str
    source: str
    description: str
    provenance: str
    extra: dict[str, Any]
    root: Path | None = None

    @property
    def file(self) -> Path:
        """Absolute path of the entry's file."""
        return self.data_path(self.path)

    @property
    def origin(self) -> str:
        """Where the entry comes from: ``"shipped"`` or the user catalog's directory."""
        return "shipped" if self.root is None else str(self.root)

    def data_path(self, relative: str | Path) -> Path:
        """Absolute path of a file of this entry's catalog (see :func:`data_path`)."""
        return data_path(relative, self.root)


@cache
def catalog_dir() -> Path:
    """Directory holding the catalogs (installed copy first, then the source tree).

    Returns
    -------
    pathlib.Path
        Directory that contains ``index.toml``.

    Raises
    ------
    CatalogError
        If no catalog directory can be found.

    Examples
    --------
    >>> from sbrdf_xr import catalog
    >>> (catalog.catalog_dir() / "index.toml").is_file()
    True
    """
    here = Path(__file__).resolve().parent
    for candidate in (here / "catalogs", here.parent / "catalogs"):
        if (candidate / "index.toml").is_file():
            return candidate
    raise CatalogError(
        f"no catalogs/index.toml found next to {here} or in its parent; "
        "reinstall the package with 'pip install .'"
    )


def data_path(relative: str | Path, root: Path | None = None) -> Path:
    """Absolute path of a file inside the catalog directory.

    Parameters
    ----------
    relative : str or Path
        Path relative to the catalog directory.
    root : Path, optional
        A user catalog directory instead of the shipped one.

    Returns
    -------
    pathlib.Path
        The absolute path.

    Raises
    ------
    CatalogError
        If the file does not exist.

    Examples
    --------
    >>> from sbrdf_xr import catalog
    >>> catalog.data_path("spacecraft/canx1.ply").name
    'canx1.ply'
    >>> catalog.data_path("spacecraft/nothing.ply")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.CatalogError: catalog file spacecraft/nothing.ply does not exist in ...
    """
    base = catalog_dir() if root is None else root
    path = base / relative
    if not path.is_file():
        raise CatalogError(f"catalog file {relative!s} does not exist in {base}")
    return path


def user_catalog_dirs() -> list[Path]:
    """The user catalog directories named by ``SBRDF_XR_CATALOG_PATH``, in order.

    Returns
    -------
    list of pathlib.Path
        Absolute directories (empty items of the variable are skipped).

    Raises
    ------
    CatalogError
        If a directory does not exist or holds no ``index.toml``.

    Examples
    --------
    >>> import os, tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.catalog import user_catalog_dirs
    >>> d = Path(tempfile.mkdtemp())
    >>> _ = (d / "index.toml").write_text("")
    >>> os.environ["SBRDF_XR_CATALOG_PATH"] = str(d)
    >>> user_catalog_dirs() == [d.resolve()]
    True
    >>> del os.environ["SBRDF_XR_CATALOG_PATH"]
    >>> user_catalog_dirs()
    []
    """
    out = []
    for item in os.environ.get(CATALOG_PATH_ENV, "").split(os.pathsep):
        if not item.strip():
            continue
        d = Path(item).expanduser().resolve()
        if not (d / "index.toml").is_file():
            what = "has no index.toml" if d.is_dir() else "is not a directory"
            raise CatalogError(
                f"{CATALOG_PATH_ENV}: user catalog {d} {what}; each directory of the "
                "variable needs an index.toml of [[entry]] tables like the shipped catalog's"
            )
        out.append(d)
    return out


def _index() -> tuple[CatalogEntry, ...]:
    """The shipped entries, then those of every user catalog (names unique throughout)."""
    found = {e.name: e for e in _read_index(*_stamp(catalog_dir()), None)}
    out = list(found.values())
    for d in user_catalog_dirs():
        for e in _read_index(*_stamp(d), d):
            if e.name in found:
                first = found[e.name]
                where = "shipped catalog" if first.root is None else f"user catalog {first.root}"
                raise CatalogError(
                    f"user catalog {d}: entry {e.name!r} is already in the {where}; user "
                    "entries may add names, not replace them: give it another name"
                )
            found[e.name] = e
            out.append(e)
    return tuple(out)


def _stamp(directory: Path) -> tuple[Path, tuple[int, int]]:
    """The index file and its modification time and size (a changed file is read again)."""
    path = directory / "index.toml"
    try:
        st = path.stat()
        return path, (st.st_mtime_ns, st.st_size)
    except OSError as exc:
        raise CatalogError(f"{path}: cannot be read ({exc.strerror or exc})") from None


@cache
def _read_index(path: Path, stamp: tuple[int, int], root: Path | None) -> tuple[CatalogEntry, ...]:
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise CatalogError(f"{path}: cannot be read ({exc})") from None
    except ValueError as exc:  # TOMLDecodeError, or an integer of over 4300 digits
        raise CatalogError(f"{path}: invalid TOML: {exc}") from None
    out = []
    required = ("name", "kind", "path", "source", "description", "provenance")
    for i, item in enumerate(raw.get("entry", [])):
        missing = [k for k in required if k not in item]
        if missing:
            raise CatalogError(f"{path}: entry {i} lacks the field(s) {missing}")
        if item["kind"] not in ENTRY_KINDS:
            raise CatalogError(
                f"{path}: entry {item['name']!r} has kind {item['kind']!r}; allowed: {ENTRY_KINDS}"
            )
        src = item["source"]
        if src not in SOURCES and not src.startswith("model:"):
            raise CatalogError(
                f"{path}: entry {item['name']!r} has source {src!r}; "
                "allowed: measured, synthetic, model:<name>"
            )
        extra = {k: v for k, v in item.items() if k not in required}
        name, kind, path, source, description, provenance = (item[k] for k in required)
        out.append(
            CatalogEntry(
                str(name),
                str(kind),
                str(path),
                str(source),
                str(description),
                str(provenance),
                extra=extra,
                root=root,
            )
        )
    seen: set[str] = set()
    for e in out:
        if e.name in seen:
            raise CatalogError(f"{path}: duplicate entry name {e.name!r}")
        seen.add(e.name)
    return tuple(out)


def entries(kind: str | None = None) -> list[CatalogEntry]:
    """All catalog entries, optionally of one kind.

    Parameters
    ----------
    kind : str, optional
        One of :data:`ENTRY_KINDS`.

    Returns
    -------
    list of CatalogEntry

    Examples
    --------
    >>> from sbrdf_xr import catalog
    >>> [e.name for e in catalog.entries("spacecraft")]
    ['canx1']
    >>> catalog.entries("material")[0].kind
    'material'
    """
    if kind is not None and kind not in ENTRY_KINDS:
        raise CatalogError(f"unknown catalog kind {kind!r}; allowed: {', '.join(ENTRY_KINDS)}")
    return [e for e in _index() if kind is None or e.kind == kind]


def names(kind: str | None = None) -> list[str]:
    """Names of the catalog entries, optionally of one kind.

    Examples
    --------
    >>> from sbrdf_xr import catalog
    >>> "lambertian-grey-50" in catalog.names("material")
    True
    >>> catalog.names("site")[:2]
    ['mont-megantic', 'dominion-astrophysical']
    """
    return [e.name for e in entries(kind)]


def entry(name: str) -> CatalogEntry:
    """The catalog entry called ``name``.

    Raises
    ------
    CatalogError
        If there is no such entry; the message suggests the close names and lists all.

    Examples
    --------
    >>> from sbrdf_xr import catalog
    >>> e = catalog.entry("lambertian-grey-50")
    >>> e.kind, e.source
    ('material', 'synthetic')
    >>> catalog.entry("lambertian-grey-51")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.CatalogError: no catalog entry named 'lambertian-grey-51'; did you mean ...
    """
    for e in _index():
        if e.name == name:
            return e
    raise CatalogError(
        f"no catalog entry named {name!r}; {did_you_mean(name, names(), 'known entries')}"
    )
