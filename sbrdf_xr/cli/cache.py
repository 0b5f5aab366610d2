"""``sbrdf-xr cache info`` and ``sbrdf-xr cache prune``: the table cache, shown and pruned.

The catalog keeps the tables it builds on load in a cache directory
(:mod:`sbrdf_xr.materials.cache`); each change of the code that builds them (a new
release) keys new ones.  ``info`` lists the entries (name, size, last use, whether this
installation loads it); ``prune`` removes those unused for some days (``--older-than``),
those this installation does not load (``--stale``), or all (``--all``), and
``--dry-run`` shows what would go.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

__all__ = ["add_cache_parser", "cmd_cache_info", "cmd_cache_prune"]


def add_cache_parser(sub: Any) -> argparse.ArgumentParser:
    """Add ``cache info`` and ``cache prune`` to the sub-commands ``sub``.

    Parameters
    ----------
    sub : argparse sub-parsers
        The ``sbrdf-xr`` sub-commands.

    Returns
    -------
    argparse.ArgumentParser
        The ``cache`` parser.

    Examples
    --------
    >>> from sbrdf_xr.cli.parser import build_parser
    >>> args = build_parser().parse_args(["cache", "prune", "--older-than", "7", "--dry-run"])
    >>> args.older_than, args.stale, args.all, args.dry_run
    (7.0, False, False, True)
    """
    pc = sub.add_parser("cache", help="the table cache: its entries, and pruning them")
    csub = pc.add_subparsers(dest="cache_command", required=True)
    pi = csub.add_parser("info", help="the cache directory and its entries")
    pi.add_argument("-q", "--quiet", action="store_true", help="the totals only")
    pi.set_defaults(func=cmd_cache_info)
    pp = csub.add_parser("prune", help="remove entries: unused for DAYS, stale, or all")
    pp.add_argument(
        "--older-than", type=float, metavar="DAYS", help="entries no install used for DAYS days"
    )
    pp.add_argument("--stale", action="store_true", help="entries this installation does not load")
    pp.add_argument("--all", action="store_true", help="every entry")
    pp.add_argument("--dry-run", action="store_true", help="remove nothing, show what would go")
    pp.add_argument("-q", "--quiet", action="store_true", help="the totals only")
    pp.set_defaults(func=cmd_cache_prune)
    return pc


def _size(n: float) -> str:
    """A size in bytes, in kB, MB or GB (powers of 1000)."""
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= scale:
            return f"{n / scale:.1f} {unit}"
    return f"{int(n)} B"


def _when(t: float, now: float) -> str:
    """A POSIX time as UTC and its age in days."""
    stamp = time.strftime("%Y-%m-%d %H:%M", time.gmtime(t))
    return f"{stamp} UTC ({max(now - t, 0.0) / 86400.0:.1f} d ago)"


def _rows(found: list[Any], now: float) -> None:
    from .output import escape

    width = max((len(e.name) for e in found), default=4)
    print(f"{'name':<{width}}  {'key':<8}  {'size':>9}  {'last use':<34}  current")
    for e in found:
        key = e.table.name[len(e.name) + 1 :][:8]
        current = "" if e.current is None else ("yes" if e.current else "no")
        row = f"{e.name:<{width}}  {key:<8}  {_size(e.size):>9}  {_when(e.last_use, now):<34}"
        print(escape(f"{row}  {current}".rstrip()))


def cmd_cache_info(args: argparse.Namespace) -> int:
    """Run ``sbrdf-xr cache info``: the directory, its entries (name, key, size, last use,
    current), the totals and the automatic prune's setting; ``-q``: the totals only.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.

    Returns
    -------
    int
        0.

    Examples
    --------
    >>> import contextlib, io, os, tempfile
    >>> from sbrdf_xr.cli import main
    >>> os.environ["SBRDF_XR_CACHE_DIR"] = tempfile.mkdtemp()
    >>> out = io.StringIO()
    >>> with contextlib.redirect_stdout(out):
    ...     status = main(["cache", "info", "-q"])
    >>> status, out.getvalue().splitlines()[1]
    (0, '0 entries, 0 B; current for this installation: 0 (0 B), stale: 0 (0 B)')
    >>> del os.environ["SBRDF_XR_CACHE_DIR"]
    """
    from .. import catalog
    from ..materials import cache
    from .output import escape

    found = cache.cache_entries(catalog.table_cache_files())
    now = time.time()
    d = cache.cache_dir()
    print(escape(f"table cache: {d}{'' if d and d.is_dir() else ' (not made yet)'}"))
    if found and not args.quiet:
        _rows(found, now)
    cur = [e for e in found if e.current]
    stale = [e for e in found if not e.current]
    total = sum(e.size for e in found)
    print(
        f"{len(found)} entries, {_size(total)}; current for this installation: {len(cur)} "
        f"({_size(sum(e.size for e in cur))}), stale: {len(stale)} "
        f"({_size(sum(e.size for e in stale))})"
    )
    if not args.quiet:
        days = cache.keep_days()
        auto = "off" if days is None else f"entries no install used for {days:g} days"
        print(f"pruned on every table build: {auto} ({cache.KEEP_DAYS_ENV})")
    return 0


def cmd_cache_prune(args: argparse.Namespace) -> int:
    """Run ``sbrdf-xr cache prune``: remove the entries chosen (``--older-than DAYS``,
    ``--stale``, both: entries that are both; ``--all``), one line each (``-q``: none),
    then the total; ``--dry-run`` removes nothing.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.

    Returns
    -------
    int
        0.

    Raises
    ------
    ValidationError
        No choice, ``--all`` with another choice, negative days, or the cache switched
        off.

    Examples
    --------
    >>> import contextlib, io, os, tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.cli import main
    >>> d = Path(tempfile.mkdtemp())
    >>> os.environ["SBRDF_XR_CACHE_DIR"] = str(d)
    >>> _ = (d / ("old-table-" + "0" * 32 + ".nc")).write_bytes(b"12345")
    >>> out = io.StringIO()
    >>> with contextlib.redirect_stdout(out):
    ...     status = main(["cache", "prune", "--stale", "--dry-run", "-q"])
    >>> status, out.getvalue()
    (0, 'would remove 1 entries, 5 B (a dry run: nothing removed)\\n')
    >>> del os.environ["SBRDF_XR_CACHE_DIR"]
    """
    from .. import catalog
    from ..errors import ValidationError
    from ..materials import cache

    if args.all and (args.older_than is not None or args.stale):
        raise ValidationError("--all: every entry goes; give it without --older-than or --stale")
    if not (args.all or args.stale or args.older_than is not None):
        raise ValidationError("cache prune: say which entries: --older-than DAYS, --stale or --all")
    if args.older_than is not None and not 0 <= args.older_than < float("inf"):
        raise ValidationError(
            f"--older-than: got {args.older_than:g}; allowed: a number of days >= 0"
        )
    current = catalog.table_cache_files() if args.stale else None
    days = 0.0 if args.all else args.older_than
    gone = cache.prune(days, stale=args.stale, current=current, dry_run=args.dry_run)
    verb = "would remove" if args.dry_run else "removed"
    if gone and not args.quiet:
        _rows(gone, time.time())
    tail = " (a dry run: nothing removed)" if args.dry_run else ""
    print(f"{verb} {len(gone)} entries, {_size(sum(e.size for e in gone))}{tail}")
    return 0
