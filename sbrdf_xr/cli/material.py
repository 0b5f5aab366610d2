"""``sbrdf-xr material build``: a measurement file to a material table.

Reads the file with :func:`sbrdf_xr.materials.read_measurements` (the reader chosen by
its suffix or ``--format``), builds the table with
:func:`sbrdf_xr.materials.build_lut` (a fitted model fills what was not measured), writes
it with :func:`sbrdf_xr.materials.files.to_netcdf`, and prints what was measured, what
was modelled and the table's check against its own samples.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

__all__ = ["MODELS", "add_material_parser", "cmd_material_build"]

#: The fitted models ``--model`` names (or a model netCDF file).
MODELS = (
    "robertson-sandford",
    "microfacet",
    "robertson-sandford-core",
    "robertson-sandford-halo",
)


def add_material_parser(sub: Any) -> argparse.ArgumentParser:
    """Add ``material build`` to the sub-commands ``sub``.

    Parameters
    ----------
    sub : argparse sub-parsers
        The ``sbrdf-xr`` sub-commands.

    Returns
    -------
    argparse.ArgumentParser
        The ``material`` parser.

    Examples
    --------
    >>> from sbrdf_xr.cli.parser import build_parser
    >>> args = build_parser().parse_args(["material", "build", "scan.csv", "-o", "t.nc"])
    >>> args.measurements, args.output, args.model
    ('scan.csv', 't.nc', 'robertson-sandford')
    """
    pm = sub.add_parser("material", help="material tables from measurement files")
    msub = pm.add_subparsers(dest="material_command", required=True)
    pb = msub.add_parser(
        "build",
        help="build a table from a measurement file (long table, in-plane scan, netCDF)",
    )
    pb.add_argument("measurements", help="the measurement file")
    pb.add_argument("-o", "--output", required=True, help="the table's netCDF file")
    pb.add_argument(
        "--model",
        default="robertson-sandford",
        help="the model fitted to fill what was not measured: "
        f"{', '.join(MODELS)}, or a model netCDF file (default robertson-sandford)",
    )
    pb.add_argument("--format", help="the reader (default: by the file's suffix)")
    pb.add_argument("--wavelength", type=float, help="a broadband file's wavelength [nm]")
    pb.add_argument("--zenith", choices=("theta", "phi"), help="which letter is the zenith")
    pb.add_argument("--noise-floor", type=float, help="samples at or below it [sr-1] are noise")
    pb.add_argument("--material", help="the table's material name")
    pb.add_argument("--overwrite", action="store_true", help="replace an existing table file")
    pb.set_defaults(func=cmd_material_build)
    return pm


def cmd_material_build(args: argparse.Namespace) -> int:
    """Run ``sbrdf-xr material build``.

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
    >>> from sbrdf_xr.cli.material import cmd_material_build
    >>> callable(cmd_material_build)
    True
    """
    from ..errors import ValidationError
    from ..materials import build_lut, models, read_measurements
    from ..materials.files import to_netcdf

    options: dict[str, Any] = {}
    for key in ("wavelength", "zenith", "noise_floor", "material"):
        if getattr(args, key, None) is not None:
            options[key] = getattr(args, key)
    if args.format == "scan":
        options.pop("zenith", None)
    ds = read_measurements(args.measurements, format=args.format, **options)
    model: Any = args.model  # a fit's name (refitted by the leave-out check) or a model file
    if args.model not in MODELS:
        if not Path(args.model).is_file():
            raise ValidationError(
                f"--model: got {args.model!r}; allowed: {', '.join(MODELS)} or a model netCDF file"
            )
        model = models.open_model(args.model)
    table = build_lut(ds, model=model)
    out = to_netcdf(table, args.output, overwrite=args.overwrite)
    a = table.attrs
    print(f"{out}: {a['material']} {dict(table.sizes)}")
    print(f"  measured: {a.get('layout', 'rows of the paper 000 scheme')}")
    if "modelled" in a:
        print(f"  modelled: {a['modelled']}")
    print(
        f"  self-check over {a['self_check_n']} sample values above {a['self_check_floor']:g} "
        f"of their scan's peak: median {a['self_check_median']:.3g}, 95th percentile "
        f"{a['self_check_p95']:.3g}, worst {a['self_check_worst']:.3g} (relative)"
    )
    return 0
