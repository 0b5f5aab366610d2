"""The ``sbrdf-xr`` command line.

Sub-commands::

    sbrdf-xr catalog list [--kind KIND]     the catalog entries (shipped and user), with origin
    sbrdf-xr catalog show NAME              one entry and a summary of its contents
    sbrdf-xr info [FILE.nc]                 package and dependency versions, or a file's summary
    sbrdf-xr bench [--quick]                accuracy/cost benchmarks, timings as ratios in one run
    sbrdf-xr simulate SCENE -o CUBE.nc      run a scene (built-in name or TOML file) into a cube
             [--scheduler ADDR] [--preset NAME] [--plot FIG.png] [--overwrite | --resume] [--plan]
             [--outputs independent|all]
             [--spacecraft NAME|MESH [--mesh-material M | --material-map MAP.toml]]
             [--material M=NAME|FILE.nc ...]
    sbrdf-xr observe -o CUBE.nc             a real pass: elements, a site, a UTC window, an
             --elements TLE|OMM|NAME (--site NAME | --lat D --lon D [--height M])
             --start UTC (--stop UTC | --duration S) [--step S] [--attitude LAW ...]
             [--spacecraft NAME|MESH] [--bands V R I] [--plot FIG.png]   attitude law
    sbrdf-xr plot CUBE.nc -o FIG.png        the cube's figure: a pass against UTC, a rotation's
                                            BRDF and magnitudes, or a few labelled spectra
    sbrdf-xr photometry CUBE.nc [--bands V R I] [--range-km KM] [--extinction V=0.2 ...]
                        [--colours V-R,R-I]
             [--system ab|vega] [-o PHOT.nc] [--csv PHOT.csv]
    sbrdf-xr invert unmix MEASURED --cube CUBE.nc [--range-km R] [-o OUT.nc]   material areas
             [--spacecraft NAME|MESH --total-area]
    sbrdf-xr material build MEASUREMENTS -o TABLE.nc [--model robertson-sandford|MODEL.nc]
             [--format table|scan] [--wavelength NM] [--zenith theta|phi]   a measured table
    sbrdf-xr invert spin CURVE (--cube CUBE.nc | --scene SCENE | --to-sun X Y Z --to-observer X Y Z)
             --periods MIN MAX N [-o OUT.nc]                                      spin state
    sbrdf-xr cache info [-q]                the table cache: entries, sizes, last use, current
    sbrdf-xr cache prune (--older-than DAYS | --stale | --all) [--dry-run] [-q]   remove entries

Wherever a spacecraft or a material is named, a file may stand instead: a mesh file
(``--mesh-material`` or ``--material-map`` label its facets) or a netCDF material table
or model; relative paths are taken from the current directory.  Catalog names include
the user catalogs of ``SBRDF_XR_CATALOG_PATH`` (see :mod:`sbrdf_xr.catalog`).
"""

from __future__ import annotations

import argparse
import logging
import signal
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from .. import _startup, catalog
from .._names import __version__
from .._output import command_line_messages
from ..engine.builtin import builtin_scenes
from ..engine.knobs import KNOBS, PRESETS
from ..errors import SbrdfError
from ..store import DEFAULT_COMPLEVEL, PART_SUFFIX
from ..store.derived import OUTPUTS
from .analysis import cmd_invert, cmd_photometry
from .cache import add_cache_parser
from .commands import (
    cmd_bench,
    cmd_catalog_list,
    cmd_catalog_show,
    cmd_info,
    cmd_knobs,
    cmd_plot,
    cmd_simulate,
)
from .material import add_material_parser
from .observe import add_observe_parser
from .output import escape

__all__ = ["main"]


def _mesh_options(q: argparse.ArgumentParser) -> None:
    """The options that describe a mesh file given to ``--spacecraft``."""
    q.add_argument(
        "--mesh-material",
        metavar="NAME",
        help="with a mesh file: the one material of every facet (a catalog name)",
    )
    q.add_argument(
        "--material-map",
        metavar="MAP.toml",
        help="with a mesh file: facet colour or label -> material (TOML [[material]] tables)",
    )
    q.add_argument(
        "--length-unit", metavar="UNIT", help="with a mesh file: its length unit (default m)"
    )


def _add_catalog(sub: Any) -> None:
    """``catalog list`` and ``catalog show``."""
    pc = sub.add_parser(
        "catalog", help="list or show the catalog entries (shipped, and SBRDF_XR_CATALOG_PATH)"
    )
    csub = pc.add_subparsers(dest="catalog_command", required=True)
    pl = csub.add_parser("list", help="list the catalog entries and the catalog of each")
    pl.add_argument("--kind", choices=catalog.ENTRY_KINDS, help="only entries of this kind")
    pl.set_defaults(func=cmd_catalog_list)
    ps = csub.add_parser("show", help="show one entry")
    ps.add_argument("name")
    ps.set_defaults(func=cmd_catalog_show)


def _add_info_and_knobs(sub: Any) -> None:
    """``info`` and ``knobs``."""
    pi = sub.add_parser("info", help="versions, or a summary of a netCDF file")
    pi.add_argument("file", nargs="?")
    pi.set_defaults(func=cmd_info)

    pk = sub.add_parser(
        "knobs", help="the numerical knobs, their defaults, the presets and their measured cost"
    )
    pk.set_defaults(func=cmd_knobs)


def _add_bench(sub: Any) -> None:
    """``bench``: the accuracy and cost tables."""
    pb = sub.add_parser("bench", help="accuracy/cost benchmarks (timings as ratios)")
    pb.add_argument("--quick", action="store_true", help="small problems, for a smoke run")
    pb.add_argument(
        "--engine",
        action="store_true",
        help="engine rows: end-to-end sweeps, scaling, cores, kernel throughput",
    )
    pb.add_argument("-o", "--output", help="write the table to this netCDF file")
    pb.add_argument("--csv", help="write the table to this CSV file")
    pb.add_argument("--plot", help="draw the accuracy/time front to this PNG file")
    pb.add_argument("--overwrite", action="store_true", help="replace existing output files")
    pb.add_argument(
        "--repeat",
        type=int,
        help="timing runs of every row, the best kept (default 5, 3 with --quick)",
    )
    pb.add_argument(
        "--record-presets",
        action="store_true",
        help="write the presets' rows to the package's sbrdf_xr/bench/presets.json, which "
        "'sbrdf-xr knobs' shows (run it in a source checkout and commit the file)",
    )
    pb.set_defaults(func=cmd_bench)


def _add_simulate(sub: Any) -> None:
    """``simulate``: a scene into a cube, with its knobs, output and resume options."""
    psim = sub.add_parser("simulate", help="run a scene into a netCDF cube")
    psim.add_argument(
        "scene", help=f"built-in scene name ({', '.join(builtin_scenes())}) or a TOML file"
    )
    psim.add_argument(
        "-o",
        "--output",
        required=True,
        help="the cube to write: netCDF (CUBE.nc), or a Zarr store (CUBE.zarr) whose blocks "
        "the Dask workers store themselves",
    )
    psim.add_argument(
        "--scheduler", help="address of a dask.distributed scheduler (default: threads)"
    )
    psim.add_argument(
        "--preset",
        help=f"numerical preset: {', '.join(PRESETS)} (knob values; 'sbrdf-xr knobs' shows them)",
    )
    psim.add_argument(
        "--set",
        action="append",
        metavar="KNOB=VALUE",
        help="set a numerical knob (repeatable; 'sbrdf-xr knobs' says what each trades): "
        + "; ".join(
            f"{k.name}: {k.domain()} (default {'none' if k.default is None else k.default})"
            for k in KNOBS.values()
        )
        + "; e.g. --set method=cubic --set dtype=float32",
    )
    psim.add_argument(
        "--complevel",
        type=int,
        default=None,
        choices=range(10),
        metavar="0-9",
        help=f"compression of the cube: 0 none, 1-9 zlib with byte shuffle (default: netCDF "
        f"{DEFAULT_COMPLEVEL}, uncompressed, the fastest and resumable after a kill at any "
        "instant; Zarr its own LZ4); a resume keeps the level the cube was started with",
    )
    psim.add_argument(
        "--outputs",
        choices=OUTPUTS,
        default=None,
        help="the cube's variables: independent (those no other gives; brdf, and signal "
        "beside signal_material, recorded and computed on read) or all (every one written); "
        "default: the scene file's [write] outputs, else independent; a resume keeps the "
        "variables the .part was started with",
    )
    psim.add_argument(
        "--plot",
        help="also write the cube's figure to this PNG (PDF, SVG) file (chosen by the cube: a pass "
        "against UTC, a rotation's BRDF and V, R, I magnitudes, or a few spectra)",
    )
    psim.add_argument(
        "--overwrite",
        action="store_true",
        help="replace existing output files (regular files, and Zarr stores sbrdf-xr wrote, only)",
    )
    psim.add_argument(
        "--resume",
        action="store_true",
        help="resume an interrupted run from its .part file (with --overwrite: and "
        "replace the existing output); a finished output of the same scene is left as is",
    )
    psim.add_argument(
        "--spacecraft",
        metavar="NAME|MESH",
        help="replace the scene's spacecraft: a catalog name or a mesh file",
    )
    _mesh_options(psim)
    psim.add_argument(
        "--material",
        action="append",
        metavar="MATERIAL=NAME|FILE.nc",
        help="the table of a material: a catalog name or a netCDF table or model file (repeatable)",
    )
    psim.add_argument("--plan", action="store_true", help="print the plan and stop")
    psim.add_argument(
        "-q", "--quiet", action="store_true", help="no plan (unless --plan) and no progress bar"
    )
    psim.set_defaults(func=cmd_simulate)


def _add_photometry(sub: Any) -> None:
    """``photometry``: band magnitudes and colours of a cube."""
    pph = sub.add_parser("photometry", help="band magnitudes and colours of a cube")
    pph.add_argument("cube", help="netCDF cube written by 'sbrdf-xr simulate'")
    pph.add_argument(
        "--bands",
        nargs="+",
        default=["V", "R", "I"],
        help="bands: aliases U B V R I u g r i z or speclite filter names (default V R I)",
    )
    pph.add_argument(
        "--range-km",
        type=float,
        help="observer range [km] (default: the cube's 'range' per time, or the range it records)",
    )
    pph.add_argument(
        "--sun-distance-au",
        type=float,
        help="Sun-object distance [au] (default: the cube's 'sun_distance', else 1)",
    )
    pph.add_argument(
        "--extinction",
        nargs="+",
        metavar="BAND=K",
        help="first-order extinction k [mag per airmass] per band, with the cube's airmass "
        "(e.g. --extinction V=0.2 R=0.1 I=0.05; every band needs one)",
    )
    pph.add_argument(
        "--colours", help="colour indices as band pairs, e.g. V-R,R-I (default consecutive bands)"
    )
    pph.add_argument(
        "--system",
        type=str.lower,
        choices=("ab", "vega"),
        default="ab",
        help="magnitude system (default ab)",
    )
    pph.add_argument(
        "--solar",
        default="astm_g173",
        choices=("astm_g173", "calspec", "kurucz1993"),
        help="solar spectrum",
    )
    pph.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    pph.add_argument("--weighting", choices=("photon", "energy"), default="photon")
    pph.add_argument("--quadrature", choices=("trapezoid", "linear"), default="trapezoid")
    pph.add_argument(
        "--extrapolate",
        choices=("zero", "constant"),
        help="continue spectra past their grid into bands they do not cover",
    )
    pph.add_argument("-o", "--output", help="write the photometry Dataset to this netCDF file")
    pph.add_argument("--csv", help="write magnitudes and colour indices to this CSV file")
    pph.add_argument("--overwrite", action="store_true", help="replace existing output files")
    pph.set_defaults(func=cmd_photometry)


def _add_invert(sub: Any) -> None:
    """``invert unmix`` and ``invert spin``."""
    pinv = sub.add_parser("invert", help="materials or spin state from measured data")
    isub = pinv.add_subparsers(dest="invert_command", required=True)
    pu = isub.add_parser("unmix", help="material areas from a measured spectrum or band magnitudes")
    pu.add_argument(
        "measured",
        help="spectrum CSV/netCDF (wavelength, signal, uncertainty) or a light-curve "
        "file of band magnitudes (read_light_curve format, one row per band)",
    )
    pu.add_argument(
        "--cube", required=True, help="netCDF cube with signal_material at the measured geometry"
    )
    pu.add_argument(
        "--isel", action="append", metavar="DIM=INDEX", help="select the geometry in the cube"
    )
    pu.add_argument("--range-km", type=float, help="observer range [km] (band magnitudes)")
    pu.add_argument("--select", choices=("all", "greedy", "none"), default="all")
    pu.add_argument("--criterion", choices=("bic", "aic"), default="bic")
    pu.add_argument(
        "--spacecraft",
        help="a catalog name or a mesh file: the nominal area of each material, to report "
        "areas [m2] and for --total-area",
    )
    _mesh_options(pu)
    pu.add_argument(
        "--total-area",
        action="store_true",
        help="the fitted material areas add up to the spacecraft's (needs --spacecraft; "
        "every material of the body must be in the cube)",
    )
    pspin = isub.add_parser("spin", help="spin axis, period and phase from a colour light curve")
    pspin.add_argument(
        "measured", help="light curve CSV/ECSV/netCDF (read_light_curve format; UTC times or s)"
    )
    pspin.add_argument(
        "--spacecraft",
        default=None,
        help="a catalog name or a mesh file (default: the --scene's, else canx1)",
    )
    _mesh_options(pspin)
    pspin.add_argument(
        "--cube",
        help="the geometry: a netCDF cube over time with to_sun, to_observer, quaternion "
        "(simulate of an observation)",
    )
    pspin.add_argument(
        "--scene",
        help="the geometry: a built-in scene name or a scene TOML file with an observation",
    )
    pspin.add_argument(
        "--to-sun", type=float, nargs=3, help="the geometry: inertial direction to the Sun"
    )
    pspin.add_argument(
        "--to-observer", type=float, nargs=3, help="inertial direction to the observer"
    )
    pspin.add_argument(
        "--periods",
        type=float,
        nargs=3,
        required=True,
        metavar=("MIN", "MAX", "N"),
        help="candidate periods [s]",
    )
    pspin.add_argument(
        "--axis-body", type=float, nargs=3, default=(0.0, 0.0, 1.0), help="body spin axis"
    )
    pspin.add_argument("--n-axes", type=int, default=120, help="axes of the search grid")
    pspin.add_argument("--n-phases", type=int, default=16, help="phases of the search grid")
    pspin.add_argument("--offset", choices=("band", "common"), default="band")
    pspin.add_argument(
        "--method",
        choices=("auto", "direct", "table", "shift", "bound"),
        default="auto",
        help="grid evaluation: exact (direct), spin-angle tables checked against it, or "
        "tables bounding the chi-square with exact evaluation where a candidate can win (bound)",
    )
    pspin.add_argument(
        "--size-limit",
        type=float,
        default=1.0,
        help="factor on the size and work limits of the search (default 1)",
    )
    for q in (pu, pspin):
        q.add_argument("-o", "--output", help="write the result Dataset to this netCDF file")
        q.add_argument("--overwrite", action="store_true", help="replace an existing output file")
        q.set_defaults(func=cmd_invert)


def _add_plot(sub: Any) -> None:
    """``plot``: a cube's figure."""
    pp = sub.add_parser(
        "plot",
        help="draw a cube's figure",
        description="Draw the figure of a cube, chosen by what it is: an observation over "
        "time (magnitudes and colours against UTC with the geometry and the Earth's shadow), "
        "a rotation sweep (broadband BRDF and V, R, I magnitudes), or a few labelled spectra.",
    )
    pp.add_argument("cube", help="a cube file (netCDF or Zarr)")
    pp.add_argument("-o", "--output", required=True, help="the image file (PNG, PDF, SVG, ...)")
    pp.add_argument("--overwrite", action="store_true", help="replace an existing image file")
    pp.set_defaults(func=cmd_plot)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``sbrdf-xr``.

    Examples
    --------
    >>> from sbrdf_xr.cli.parser import build_parser
    >>> args = build_parser().parse_args(
    ...     ["simulate", "canx1-rotation", "-o", "cube.nc", "--preset", "fast"]
    ... )
    >>> args.command, args.scene, args.output, args.preset, args.complevel
    ('simulate', 'canx1-rotation', 'cube.nc', 'fast', None)
    """
    p = argparse.ArgumentParser(
        prog="sbrdf-xr", description="Spectral BRDF simulation of unresolved spacecraft."
    )
    p.add_argument("--version", action="version", version=f"sbrdf_xr {__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    _add_catalog(sub)
    _add_info_and_knobs(sub)
    _add_bench(sub)
    _add_simulate(sub)
    _add_photometry(sub)
    _add_invert(sub)
    add_observe_parser(sub, _mesh_options)
    add_material_parser(sub)
    add_cache_parser(sub)
    _add_plot(sub)
    return p


class _OneLine(logging.Formatter):
    def format(self, record: logging.LogRecord) -> str:
        return "sbrdf-xr: " + escape(record.getMessage(), True)


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split("\n")).strip() or type(exc).__name__
    if isinstance(exc, OSError) and exc.filename and str(exc.filename) not in text:
        text = f"{exc.filename}: {text}"
    return escape(text, True)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``sbrdf-xr``; returns the exit status.

    Usage errors end in argparse's usage message (exit status 2); every error of the
    package (:class:`~sbrdf_xr.errors.SbrdfError`) and of the operating system
    (:class:`OSError`: missing files, permissions, a full disk) in one line
    ``sbrdf-xr: error: ...`` on stderr and exit status 2; an interrupt in exit status
    130.  Messages name command-line options (``--overwrite``, ``--resume``).

    Examples
    --------
    >>> from sbrdf_xr.cli import main
    >>> main(["knobs"])  # doctest: +ELLIPSIS
    knob               default     fast / balanced / reference   trades
    method             linear      linear / linear / cubic       look-up interpolation order: ...
    ...
    block_bytes        8388608     - / - / -                     memory budget of one block's ...
    0
    >>> main(["catalog", "list", "--kind", "spacecraft"])  # doctest: +ELLIPSIS
    name   kind              source        catalog   description
    canx1  spacecraft        synthetic     shipped   CanX-1 Engineering Model-like 10 cm cube ...
    <BLANKLINE>
    1 entries; catalogs:
      shipped  ...catalogs
      (no user catalogs: set SBRDF_XR_CATALOG_PATH to add some)
    0
    """
    args = build_parser().parse_args(argv)
    logger = logging.getLogger("sbrdf_xr")
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(_OneLine())
    logger.addHandler(handler)
    level = logger.level
    logger.setLevel(logging.WARNING)
    try:
        if signal.getsignal(signal.SIGINT) is _startup._interrupted:  # main takes over
            signal.signal(signal.SIGINT, signal.default_int_handler)
        # --quiet: no progress bars, of the writer nor of the tables the command builds
        with command_line_messages(), catalog.showing_progress(not getattr(args, "quiet", False)):
            return int(args.func(args))
    except (SbrdfError, OSError) as exc:
        print(f"sbrdf-xr: error: {_one_line(exc)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        out = getattr(args, "output", None)
        hint = ""
        if out and Path(str(out) + PART_SUFFIX).exists():
            hint = (
                f"; the blocks written so far are kept in {out}{PART_SUFFIX}: "
                "run again with --resume"
            )
        print(f"sbrdf-xr: interrupted{hint}", file=sys.stderr)
        return 130
    finally:
        logger.removeHandler(handler)
        logger.setLevel(level)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
