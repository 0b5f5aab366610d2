"""The ``sbrdf-xr`` command line.

Sub-commands::

    sbrdf-xr catalog list [--kind KIND]     what ships in the catalogs, with provenance
    sbrdf-xr catalog show NAME              one entry and a summary of its contents
    sbrdf-xr info [FILE.nc]                 package and dependency versions, or a file's summary
    sbrdf-xr bench [--quick]                accuracy/cost benchmarks, timings as ratios in one run
"""

from __future__ import annotations

import argparse
import sys
import textwrap
from collections.abc import Sequence

from . import __version__, catalog
from .errors import SbrdfError

__all__ = ["main"]


def _cmd_catalog_list(args: argparse.Namespace) -> int:
    rows = catalog.entries(args.kind)
    width = max((len(e.name) for e in rows), default=4)
    print(f"{'name':<{width}}  {'kind':<16}  {'source':<12}  description")
    for e in rows:
        desc = textwrap.shorten(e.description, 80)
        print(f"{e.name:<{width}}  {e.kind:<16}  {e.source:<12}  {desc}")
    print(f"\n{len(rows)} entries in {catalog.catalog_dir()}")
    return 0


def _cmd_catalog_show(args: argparse.Namespace) -> int:
    e = catalog.entry(args.name)
    print(f"name:        {e.name}\nkind:        {e.kind}\nsource:      {e.source}")
    print(f"file:        {e.file}")
    print("description: " + textwrap.fill(e.description, 88, subsequent_indent=" " * 13))
    print("provenance:  " + textwrap.fill(e.provenance, 88, subsequent_indent=" " * 13))
    for k, v in e.extra.items():
        print(f"{k + ':':<13}{v}")
    print()
    print(catalog.load(e.name))
    return 0


def _cmd_info(args: argparse.Namespace) -> int:
    if args.file:
        import xarray as xr

        with xr.open_dataset(args.file) as ds:
            print(ds)
        return 0
    import dask
    import numpy
    import scipy
    import trimesh
    import xarray

    print(f"sbrdf_xr {__version__}")
    for mod in (numpy, scipy, xarray, dask, trimesh):
        print(f"  {mod.__name__:<8} {mod.__version__}")
    print(f"  catalogs {catalog.catalog_dir()} ({len(catalog.names())} entries)")
    return 0


def _cmd_bench(args: argparse.Namespace) -> int:
    from . import bench

    print(bench.format_rows(bench.run(quick=args.quick)))
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``sbrdf-xr``."""
    p = argparse.ArgumentParser(prog="sbrdf-xr", description="Spectral BRDF simulation of unresolved spacecraft.")
    p.add_argument("--version", action="version", version=f"sbrdf_xr {__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    pc = sub.add_parser("catalog", help="list or show what ships in the catalogs")
    csub = pc.add_subparsers(dest="catalog_command", required=True)
    pl = csub.add_parser("list", help="list the catalog entries")
    pl.add_argument("--kind", choices=catalog.KINDS, help="only entries of this kind")
    pl.set_defaults(func=_cmd_catalog_list)
    ps = csub.add_parser("show", help="show one entry")
    ps.add_argument("name")
    ps.set_defaults(func=_cmd_catalog_show)

    pi = sub.add_parser("info", help="versions, or a summary of a netCDF file")
    pi.add_argument("file", nargs="?")
    pi.set_defaults(func=_cmd_info)

    pb = sub.add_parser("bench", help="accuracy/cost benchmarks (timings as ratios)")
    pb.add_argument("--quick", action="store_true", help="small problems, for a smoke run")
    pb.set_defaults(func=_cmd_bench)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``sbrdf-xr``; returns the exit status."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args))
    except (SbrdfError, FileExistsError, FileNotFoundError) as exc:
        print(f"sbrdf-xr: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
