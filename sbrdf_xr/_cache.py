"""A disk cache for catalog tables that are built on load.

Some catalog materials are built from their measurement sets when loaded (the paper 000
§3.2 construction, filled by a fitted model); that takes seconds per table.  The table
is written once to the user's cache directory and read from there afterwards.  The key
hashes the entry's inputs (its measurement file, its fit's file, its build options) and
the sources of the modules that build tables (:func:`build_modules`), so a change of
either builds anew.

The directory is ``$SBRDF_XR_CACHE_DIR`` if set (``off`` disables the cache), else
``$XDG_CACHE_HOME/sbrdf_xr`` or ``~/.cache/sbrdf_xr``.
"""

from __future__ import annotations

import ast
import hashlib
import os
import warnings
from collections.abc import Callable, Iterable
from functools import cache
from pathlib import Path

import xarray as xr

from .errors import CacheWarning

__all__ = ["build_modules", "cache_dir", "cached_table", "source_digest"]


def cache_dir() -> Path | None:
    """The cache directory, or None when the cache is switched off."""
    env = os.environ.get("SBRDF_XR_CACHE_DIR")
    if env is not None:
        return None if env.strip().lower() in ("", "off", "0", "none") else Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "sbrdf_xr"


#: The modules whose code builds a catalog table: the import closure of these.
_BUILD_ROOTS = ("sbrdf_xr.catalog",)


def _module_file(root: Path, name: str) -> Path | None:
    """The source file of module ``name`` (``sbrdf_xr.a.b``) under the package ``root``."""
    p = root.joinpath(*name.split(".")[1:])
    for f in (p / "__init__.py", p.with_suffix(".py")):
        if f.is_file():
            return f
    return None


def _package_imports(root: Path, name: str) -> set[str]:
    """The package modules that module ``name`` imports, anywhere in its code (``ast``)."""
    f = _module_file(root, name)
    if f is None:
        return set()
    pkg = name if f.name == "__init__.py" else name.rpartition(".")[0]
    out: set[str] = set()
    for node in ast.walk(ast.parse(f.read_bytes())):
        if isinstance(node, ast.Import):
            out.update(
                a.name
                for a in node.names
                if a.name.startswith("sbrdf_xr") and _module_file(root, a.name)
            )
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = pkg.split(".")[: len(pkg.split(".")) - node.level + 1]
                base = ".".join(parts + ([node.module] if node.module else []))
            elif node.module and node.module.startswith("sbrdf_xr"):
                base = node.module
            else:
                continue
            subs = [f"{base}.{a.name}" for a in node.names]
            subs = [n for n in subs if _module_file(root, n)]
            out.update(subs)
            if len(subs) < len(node.names) and _module_file(root, base):
                out.add(base)  # names taken from the module itself
    return out


def build_modules(roots: Iterable[str] = _BUILD_ROOTS) -> list[Path]:
    """Source files of the modules that can take part in building a catalog table.

    The import closure of ``roots`` (every ``import`` in a module's code, at its top or
    inside a function), plus the ``__init__.py`` of every package on the way, whose code
    runs on any import below it.  The engine, the writers, the benchmarks and the
    command line are outside it, so changing them keeps the built tables.
    """
    root = Path(__file__).resolve().parent
    seen: set[str] = set()
    todo = list(roots)
    while todo:
        name = todo.pop()
        if name not in seen:
            seen.add(name)
            todo.extend(_package_imports(root, name) - seen)
    files = {f for n in seen if (f := _module_file(root, n)) is not None}
    for n in seen:  # the packages' own __init__, without following their imports
        parts = n.split(".")
        for k in range(1, len(parts)):
            init = _module_file(root, ".".join(parts[:k]))
            if init is not None and init.name == "__init__.py":
                files.add(init)
    return sorted(files)


@cache
def source_digest() -> str:
    """SHA-256 of the sources that build a table (:func:`build_modules`): a change to
    one of them invalidates the cache."""
    root = Path(__file__).resolve().parent
    h = hashlib.sha256()
    for p in build_modules():
        h.update(str(p.relative_to(root)).encode())
        h.update(p.read_bytes())
    return h.hexdigest()


def _file_digest(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(2**20), b""):
            h.update(chunk)
    return h.hexdigest()


def cached_table(
    name: str,
    inputs: Iterable[Path],
    options: str,
    build: Callable[[], xr.DataArray],
    write: Callable[[xr.DataArray, Path], object],
    read: Callable[[Path], xr.DataArray],
) -> xr.DataArray:
    """The table ``build()`` would give, from the cache when it is there.

    The table returned is always the one read back from the cache file (when the cache
    works), so a first, building load and a later, cached load give identical tables
    (values and attributes), and so identical content fingerprints.
    """
    d = cache_dir()
    if d is None:
        return build()
    key = hashlib.sha256(
        "\n".join([name, options, source_digest(), *(_file_digest(p) for p in inputs)]).encode()
    ).hexdigest()[:32]
    path = d / f"{name}-{key}.nc"
    if path.is_file():
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
    table = build()
    try:
        d.mkdir(parents=True, exist_ok=True)
        write(table, path)  # atomic: a temporary file renamed, so two builders cannot clash
        return read(path)
    except OSError as exc:  # read-only or full: the built table, uncached
        warnings.warn(
            f"table cache {d} is not usable ({type(exc).__name__}: {exc}); table {name} "
            "was built but not kept (set SBRDF_XR_CACHE_DIR to a writable directory, or "
            "'off' to build every time without this warning)",
            CacheWarning,
            stacklevel=2,
        )
        return table
