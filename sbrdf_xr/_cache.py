"""A disk cache for catalog tables that are built on load.

Some catalog materials are built from their measurement sets when loaded (the paper 000
§3.2 construction, filled by a fitted model); that takes seconds per table.  The table
is written once to the user's cache directory and read from there afterwards.  The key
hashes the entry's inputs (its measurement file, its fit's file, its build options) and
the package's own source, so a change of either builds anew.

The directory is ``$SBRDF_XR_CACHE_DIR`` if set (``off`` disables the cache), else
``$XDG_CACHE_HOME/sbrdf_xr`` or ``~/.cache/sbrdf_xr``.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Callable, Iterable
from functools import cache
from pathlib import Path

import xarray as xr

__all__ = ["cache_dir", "cached_table", "source_digest"]


def cache_dir() -> Path | None:
    """The cache directory, or None when the cache is switched off."""
    env = os.environ.get("SBRDF_XR_CACHE_DIR")
    if env is not None:
        return None if env.strip().lower() in ("", "off", "0", "none") else Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "sbrdf_xr"


@cache
def source_digest() -> str:
    """SHA-256 of the package's Python sources (a code change invalidates the cache)."""
    root = Path(__file__).resolve().parent
    h = hashlib.sha256()
    for p in sorted(root.rglob("*.py")):
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
        except (OSError, ValueError):
            path.unlink(missing_ok=True)  # a damaged cache file: build again
    table = build()
    try:
        d.mkdir(parents=True, exist_ok=True)
        write(table, path)
        return read(path)
    except OSError:  # read-only or full: the built table, uncached
        return table
