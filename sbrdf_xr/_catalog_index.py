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
package carries a copy at ``sbrdf_xr/catalogs`` (see ``pyproject.toml``).  This module
reads the index only; the domain modules read an entry's file given the entry, and
:mod:`sbrdf_xr.catalog` maps every kind to its loader.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

from .errors import CatalogError

__all__ = [
    "KINDS",
    "SOURCES",
    "CatalogEntry",
    "catalog_dir",
    "data_path",
    "entries",
    "entry",
    "names",
]

KINDS = ("material", "measurements", "model", "paint_parameters", "spacecraft", "orbit", "site")
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
    """

    name: str
    kind: str
    path: str
    source: str
    description: str
    provenance: str
    extra: dict[str, Any]

    @property
    def file(self) -> Path:
        """Absolute path of the entry's file."""
        return data_path(self.path)


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
    """
    here = Path(__file__).resolve().parent
    for candidate in (here / "catalogs", here.parent / "catalogs"):
        if (candidate / "index.toml").is_file():
            return candidate
    raise CatalogError(
        f"no catalogs/index.toml found next to {here} or in its parent; "
        "reinstall the package with 'pip install .'"
    )


def data_path(relative: str | Path) -> Path:
    """Absolute path of a file inside the catalog directory.

    Parameters
    ----------
    relative : str or Path
        Path relative to the catalog directory.

    Returns
    -------
    pathlib.Path
        The absolute path.

    Raises
    ------
    CatalogError
        If the file does not exist.
    """
    path = catalog_dir() / relative
    if not path.is_file():
        raise CatalogError(f"catalog file {relative!s} does not exist in {catalog_dir()}")
    return path


@cache
def _index() -> tuple[CatalogEntry, ...]:
    path = catalog_dir() / "index.toml"
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:  # pragma: no cover - shipped file is tested
        raise CatalogError(f"{path}: invalid TOML: {exc}") from exc
    out = []
    required = ("name", "kind", "path", "source", "description", "provenance")
    for i, item in enumerate(raw.get("entry", [])):
        missing = [k for k in required if k not in item]
        if missing:
            raise CatalogError(f"{path}: entry {i} lacks the field(s) {missing}")
        if item["kind"] not in KINDS:
            raise CatalogError(
                f"{path}: entry {item['name']!r} has kind {item['kind']!r}; allowed: {KINDS}"
            )
        src = item["source"]
        if src not in SOURCES and not src.startswith("model:"):
            raise CatalogError(
                f"{path}: entry {item['name']!r} has source {src!r}; "
                "allowed: measured, synthetic, model:<name>"
            )
        extra = {k: v for k, v in item.items() if k not in required}
        out.append(
            CatalogEntry(
                name=item["name"],
                kind=item["kind"],
                path=item["path"],
                source=item["source"],
                description=item["description"],
                provenance=item["provenance"],
                extra=extra,
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
        One of :data:`KINDS`.

    Returns
    -------
    list of CatalogEntry
    """
    if kind is not None and kind not in KINDS:
        raise CatalogError(f"unknown catalog kind {kind!r}; allowed: {', '.join(KINDS)}")
    return [e for e in _index() if kind is None or e.kind == kind]


def names(kind: str | None = None) -> list[str]:
    """Names of the catalog entries, optionally of one kind."""
    return [e.name for e in entries(kind)]


def entry(name: str) -> CatalogEntry:
    """The catalog entry called ``name``.

    Raises
    ------
    CatalogError
        If there is no such entry; the message lists the known names.
    """
    for e in _index():
        if e.name == name:
            return e
    raise CatalogError(f"no catalog entry named {name!r}; known: {', '.join(names())}")
