"""The ``sbrdf-xr`` command line.

Sub-commands::

    sbrdf-xr catalog list [--kind KIND]     the catalog entries (shipped and user), with origin
    sbrdf-xr catalog show NAME              one entry and a summary of its contents
    sbrdf-xr info [FILE.nc]                 package and dependency versions, or a file's summary
    sbrdf-xr bench [--quick]                accuracy/cost benchmarks, timings as ratios in one run
    sbrdf-xr simulate SCENE -o CUBE.nc      run a scene (built-in name or TOML file) into a cube
             [--scheduler ADDR] [--preset NAME] [--plot FIG.png] [--overwrite | --resume] [--plan]
             [--spacecraft NAME|MESH [--mesh-material M | --material-map MAP.toml]]
             [--material M=NAME|FILE.nc ...]
    sbrdf-xr plot CUBE.nc -o FIG.png        the cube's natural figure (light curve or spectra)
    sbrdf-xr photometry CUBE.nc [--bands V R I] [--range-km KM] [--colours V-R,R-I]
             [--system ab|vega] [-o PHOT.nc] [--csv PHOT.csv]
    sbrdf-xr invert unmix MEASURED --cube CUBE.nc [--range-km R] [-o OUT.nc]   material areas
    sbrdf-xr invert spin CURVE --spacecraft canx1 --to-sun X Y Z --to-observer X Y Z
             --periods MIN MAX N [-o OUT.nc]                                      spin state

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
import textwrap
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from . import catalog
from ._version import __version__
from ._writer import LOG_SUFFIX, PART_SUFFIX, command_line_messages
from .errors import SbrdfError, ValidationError

__all__ = ["main"]


def escape(text: Any, newlines: bool = False) -> str:
    """``text`` with control and other non-printable characters written as escapes.

    Attributes of files and catalog entries are printed through this, so that a
    terminal escape sequence in a file prints as ``\\x1b[...`` instead of acting on the
    terminal.  Newlines and tabs are kept unless ``newlines`` is true.

    Examples
    --------
    >>> from sbrdf_xr.cli import escape
    >>> print(escape("red " + chr(27) + "[31mtext"))  # the terminal's escape character
    red \\x1b[31mtext
    >>> print(escape("two" + chr(10) + "lines", newlines=True))
    two\\nlines
    """
    keep = "" if newlines else "\n\t"
    return "".join(c if c.isprintable() or c in keep else repr(c)[1:-1] for c in str(text))


def _escaped_attrs(obj: Any) -> Any:
    """A shallow copy of a Dataset/DataArray whose attributes (and names) print safely."""
    import xarray as xr

    def clean(attrs: dict[Any, Any]) -> dict[str, Any]:
        return {
            escape(k, True): escape(v, True) if isinstance(v, str) else v for k, v in attrs.items()
        }

    if isinstance(obj, xr.Dataset):
        out = obj.copy()
        out.attrs = clean(obj.attrs)
        for name in out.variables:
            out[name].attrs = clean(obj[name].attrs)
        return out.rename({n: escape(n, True) for n in out.variables if escape(n, True) != n})
    if isinstance(obj, xr.DataArray):
        arr = obj.copy()
        arr.attrs = clean(obj.attrs)
        for c in arr.coords:
            arr[c].attrs = clean(obj[c].attrs)
        return arr
    return obj


def _open_dataset(path: str | Path) -> Any:
    """Open a netCDF file, turning "not netCDF" into a :class:`ValidationError`."""
    import xarray as xr

    p = Path(path)
    if not p.exists():
        raise FileNotFoundError(f"{path}: no such file")
    if not p.is_file():
        raise ValidationError(f"{path}: not a file")
    try:
        return xr.open_dataset(p)
    except (OSError, ValueError, TypeError, KeyError, RuntimeError) as exc:
        why = (
            "unrecognised format"
            if "did not find a match" in str(exc)
            else f"{type(exc).__name__}: {exc}"
        )
        raise ValidationError(f"{path}: not a readable netCDF file ({why})") from None


def _open_cube(path: str | Path) -> Any:
    """A loaded simulation cube, or :class:`ValidationError` naming what is missing."""
    with _open_dataset(path) as ds:
        spectral = [
            v for v in ("spacecraft_sbrdf", "signal") if v in ds and "wavelength" in ds[v].dims
        ]
        curve = "brdf" in ds and "attitude" in ds.dims and "phase_angle" in ds.coords
        if not spectral and not curve:
            names = ", ".join(map(str, list(ds.data_vars)[:8])) or "none"
            raise ValidationError(
                f"{path}: not a simulation cube of 'sbrdf-xr simulate' "
                "(it needs 'spacecraft_sbrdf' or 'signal' over wavelength, or 'brdf' over "
                f"attitude; its variables: {escape(names, True)})"
            )
        try:
            return ds.load()
        except (OSError, ValueError, RuntimeError) as exc:
            raise ValidationError(f"{path}: cannot be read ({exc})") from None


def _catalog_label(e: catalog.CatalogEntry, users: list[Path]) -> str:
    """``shipped`` or ``user<i>`` (the i-th directory of SBRDF_XR_CATALOG_PATH)."""
    return "shipped" if e.root is None else f"user{users.index(e.root) + 1}"


def _cmd_catalog_list(args: argparse.Namespace) -> int:
    rows = catalog.entries(args.kind)
    users = catalog.user_catalog_dirs()
    width = max((len(e.name) for e in rows), default=4)
    print(f"{'name':<{width}}  {'kind':<16}  {'source':<12}  {'catalog':<8}  description")
    for e in rows:
        desc = textwrap.shorten(e.description, 72)
        label = _catalog_label(e, users)
        print(escape(f"{e.name:<{width}}  {e.kind:<16}  {e.source:<12}  {label:<8}  {desc}"))
    print(f"\n{len(rows)} entries; catalogs:")
    print(f"  shipped  {catalog.catalog_dir()}")
    for i, d in enumerate(users, 1):
        print(escape(f"  user{i:<4} {d}"))
    if not users:
        print(f"  (no user catalogs: set {catalog.CATALOG_PATH_ENV} to add some)")
    return 0


def _cmd_catalog_show(args: argparse.Namespace) -> int:
    e = catalog.entry(args.name)
    print(escape(f"name:        {e.name}\nkind:        {e.kind}\nsource:      {e.source}"))
    print(escape(f"catalog:     {e.origin}"))
    print(escape(f"file:        {e.file}"))
    print(
        "description: " + textwrap.fill(escape(e.description, True), 88, subsequent_indent=" " * 13)
    )
    print(
        "provenance:  " + textwrap.fill(escape(e.provenance, True), 88, subsequent_indent=" " * 13)
    )
    for k, v in e.extra.items():
        print(escape(f"{escape(k, True) + ':':<13}{escape(v, True)}"))
    print()
    print(escape(_escaped_attrs(catalog.load(e.name))))
    return 0


def _cmd_info(args: argparse.Namespace) -> int:
    if args.file:
        with _open_dataset(args.file) as ds:
            print(escape(_escaped_attrs(ds)))
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
    for d in catalog.user_catalog_dirs():
        print(escape(f"  user catalog {d}"))
    return 0


def _cmd_bench(args: argparse.Namespace) -> int:
    from . import bench

    if args.engine:
        from .bench_engine import engine_rows

        rows = engine_rows(quick=args.quick)
    else:
        rows = bench.run(quick=args.quick)
    print(bench.format_rows(rows))
    ds = bench.rows_to_dataset(rows)
    if args.output:
        from .material import write_netcdf_atomic

        write_netcdf_atomic(ds, args.output, overwrite=True)
        print(f"wrote {args.output}")
    if args.csv:
        ds.to_dataframe().to_csv(args.csv)
        print(f"wrote {args.csv}")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        bench.plot_front(rows).savefig(args.plot, dpi=120)
        print(f"wrote {args.plot}")
    return 0


def _cmd_simulate(args: argparse.Namespace) -> int:
    from .scene import resolve_scene
    from .simulate import simulate, write

    scene = resolve_scene(args.scene)
    scene = _with_body(scene, args)
    changes = _knob_values(args.set or [])
    if args.preset:
        scene = scene.with_options(preset=args.preset, **changes)
    elif changes:
        scene = scene.with_options(**changes)
    plan = scene.plan()
    print(plan)
    if args.plan:
        return 0
    out = Path(args.output)
    finished = (
        args.resume
        and not args.overwrite
        and out.is_file()
        and not out.with_name(out.name + PART_SUFFIX).exists()
    )
    client = None
    if args.scheduler is not None:
        from ._writer import connect

        client = connect(args.scheduler)
    if hasattr(
        signal, "SIGXFSZ"
    ):  # past a file size limit, fail the write (named) instead of dying
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    try:
        cube = simulate(plan, client=client)
        extra = {} if str(out).endswith(".zarr") else {"complevel": args.complevel}
        path = write(
            cube,
            out,
            overwrite=args.overwrite,
            resume=args.resume,
            client=client,
            progress=not args.quiet,
            **extra,
        )
    finally:
        if client is not None:
            client.close()
    if finished:
        print(f"{path} is already complete; nothing to resume")
    else:
        print(f"wrote {path}")
    if args.plot:
        _save_figure(path, args.plot)
    return 0


def _spacecraft_of(args: argparse.Namespace) -> Any:
    """The spacecraft of ``--spacecraft`` (a catalog name or a mesh file) and its options."""
    options: dict[str, Any] = {}
    if args.mesh_material is not None:
        options["material"] = args.mesh_material
    if args.material_map is not None:
        options["material_map"] = Path(args.material_map)
    if args.length_unit is not None:
        options["length_unit"] = args.length_unit
    if options and args.spacecraft is None:
        raise ValidationError(
            "--mesh-material, --material-map and --length-unit describe the mesh file of "
            "--spacecraft; give --spacecraft too"
        )
    if options and not catalog.is_file_spec(args.spacecraft):
        raise ValidationError(
            f"--spacecraft {args.spacecraft!r} is a catalog entry; --mesh-material, "
            "--material-map and --length-unit apply to a mesh file only"
        )
    if (
        args.spacecraft is not None
        and catalog.is_file_spec(args.spacecraft)
        and not ("material" in options or "material_map" in options)
    ):
        raise ValidationError(
            f"--spacecraft {args.spacecraft}: a mesh file needs --mesh-material NAME (one "
            "material for every facet) or --material-map MAP.toml (facet colour or label -> "
            "material)"
        )
    return catalog.load_spacecraft_spec(args.spacecraft, **options)


def _with_body(scene: Any, args: argparse.Namespace) -> Any:
    """The scene with the spacecraft of ``--spacecraft`` and the tables of ``--material``."""
    from .scene_io import material_tables

    specs: dict[str, str] = {}
    for item in args.material or []:
        mat, sep, spec = item.partition("=")
        if not sep or not mat.strip() or not spec.strip():
            raise ValidationError(
                f"--material: got {item!r}; expected MATERIAL=NAME or MATERIAL=FILE.nc"
            )
        specs[mat.strip()] = spec.strip()
    mesh = args.mesh_material or args.material_map or args.length_unit
    if args.spacecraft is None and not (mesh or specs):
        return scene
    body = scene.spacecraft if args.spacecraft is None and not mesh else _spacecraft_of(args)
    unknown = sorted(set(specs) - set(body.materials))
    if unknown:
        raise ValidationError(
            f"--material: {unknown} are not materials of the spacecraft {body.name!r}; "
            f"its materials: {body.materials}"
        )
    kept = {m: t for m, t in (scene.materials or {}).items() if m in body.materials}
    wanted = {m: specs.get(m, m) for m in body.materials if m in specs or m not in kept}
    tables, models = material_tables(wanted)
    old_models = {m: v for m, v in (scene.models or {}).items() if m not in wanted}
    return scene.with_options(
        spacecraft=body,
        materials={**kept, **tables},
        models={**old_models, **models} or None,
    )


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


def _knob_values(items: list[str]) -> dict[str, object]:
    """``NAME=VALUE`` strings as knob values (TOML syntax for the value, else a string)."""
    import tomllib

    from .errors import SceneError
    from .knobs import KNOBS

    out: dict[str, object] = {}
    for item in items:
        name, sep, text = item.partition("=")
        name = name.strip()
        if not sep or name not in KNOBS:
            raise SceneError(
                f"--set {item!r}: expected NAME=VALUE with NAME one of {', '.join(KNOBS)}"
            )
        try:
            value = tomllib.loads(f"v = {text.strip()}")["v"]
        except tomllib.TOMLDecodeError:
            value = text.strip()
        out[name] = None if value == "none" else value
    return out


def _cmd_knobs(args: argparse.Namespace) -> int:
    from .knobs import knob_table

    print(knob_table())
    return 0


def _save_figure(cube_path: str | Path, figure_path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")

    from .plot import plot_cube

    cube = _open_cube(cube_path)
    try:
        fig = plot_cube(cube)
    except (KeyError, ValueError, IndexError) as exc:
        raise ValidationError(
            f"{cube_path}: cannot be drawn ({type(exc).__name__}: {exc})"
        ) from None
    try:
        fig.savefig(figure_path, dpi=120)
    except ValueError as exc:  # an unknown image format
        raise ValidationError(f"{figure_path}: {exc}") from None
    print(f"wrote {figure_path}")


def _cmd_plot(args: argparse.Namespace) -> int:
    _save_figure(args.cube, args.output)
    return 0


def _cube_range_km(cube) -> float | None:
    """The observer range a cube records [km] (attribute or scalar variable), if any."""
    for name in ("range_km", "observer_range_km"):
        if name in cube.attrs:
            return float(cube.attrs[name])
        if name in cube.variables and cube[name].ndim == 0:
            return float(cube[name].values)
    return None


def _parse_colours(text: str | None) -> list[tuple[str, str]] | None:
    if not text:
        return None
    pairs = []
    for item in text.split(","):
        a, sep, b = item.strip().partition("-")
        if not sep or not a or not b:
            raise SbrdfError(
                f"--colours: {item.strip()!r} is not a band pair like V-R (give e.g. V-R,R-I)"
            )
        pairs.append((a, b))
    return pairs


def _cmd_photometry(args: argparse.Namespace) -> int:
    import numpy as np
    import xarray as xr
    from tqdm.dask import TqdmCallback

    from . import photometry as phot

    for out in (args.output, args.csv):
        if out and Path(out).exists() and not args.overwrite:
            raise FileExistsError(f"{out} exists; pass --overwrite to replace it")
    with _open_dataset(args.cube) as probe:
        if not any(
            v in probe and "wavelength" in probe[v].dims for v in ("signal", "spacecraft_sbrdf")
        ):
            raise ValidationError(
                f"{args.cube}: not a spectral simulation cube of 'sbrdf-xr simulate' "
                "(it needs 'signal' or 'spacecraft_sbrdf' over wavelength)"
            )
    colours = _parse_colours(args.colours)
    with xr.open_dataset(args.cube, chunks={}) as cube:
        range_km = args.range_km if args.range_km is not None else _cube_range_km(cube)
        if range_km is None:
            raise SbrdfError(
                f"{args.cube} records no observer range; give it with --range-km KM "
                "(e.g. --range-km 36000 for a geostationary object)"
            )
        lazy = phot.photometry(
            cube,
            args.bands,
            range_km,
            pairs=colours,
            system=args.system,
            weighting=args.weighting,
            quadrature=args.quadrature,
            extrapolate=args.extrapolate,
            solar=args.solar,
        )
        with TqdmCallback(desc="photometry", disable=args.quiet):
            ds = lazy.compute()
    print(
        f"photometry of {args.cube}: range {range_km:g} km, {ds.attrs['magnitude_system']} "
        f"magnitudes, {args.weighting} weighting, solar spectrum {args.solar}"
    )
    print(f"{'band':<8} {'filter':<14} {'m_sun':>8} {'min':>8} {'median':>8} {'max':>8}")
    for b in ds.band.values:
        m = np.asarray(ds.magnitude.sel(band=b).values).ravel()
        fin = m[np.isfinite(m)]
        stats = (
            f"{fin.min():8.3f} {np.median(fin):8.3f} {fin.max():8.3f}"
            if fin.size
            else f"{'inf':>8} {'inf':>8} {'inf':>8}"
        )
        print(
            f"{b!s:<8} {ds.filter.sel(band=b).item()!s:<14} "
            f"{float(ds.sun_magnitude.sel(band=b)):8.3f} {stats}"
        )
    if "colour_index" in ds:
        for c in ds.colour.values:
            v = np.asarray(ds.colour_index.sel(colour=c).values).ravel()
            v = v[np.isfinite(v)]
            med = f"{np.median(v):.3f}" if v.size else "nan"
            print(f"colour {c!s:<10} median {med} mag")
    if args.output:
        phot.to_netcdf(ds, args.output, overwrite=args.overwrite)
        print(f"wrote {args.output}")
    if args.csv:
        lead = set(ds.magnitude.dims) - {"band"}
        parts = [
            ds.magnitude.to_dataset(dim="band").rename({str(b): f"mag_{b}" for b in ds.band.values})
        ]
        if "colour_index" in ds:
            parts.append(ds.colour_index.to_dataset(dim="colour"))
        wide = xr.merge(parts, compat="override")
        wide = wide.drop_vars(
            [c for c in wide.coords if not set(wide[c].dims) <= lead or c in ("band", "colour")],
            errors="ignore",
        )
        wide.to_dataframe().to_csv(args.csv)
        print(f"wrote {args.csv}")
    return 0


def _cmd_invert(args: argparse.Namespace) -> int:
    import numpy as np
    import xarray as xr

    from . import invert
    from .errors import InversionError
    from .material import write_netcdf_atomic
    from .photometry import read_light_curve

    if args.invert_command == "unmix":
        with xr.open_dataset(args.cube) as cube:
            terms = cube.load()["signal_material"] if "signal_material" in cube else None
        if terms is None:
            raise InversionError(
                f"{args.cube}: no signal_material; simulate with the per_material output"
            )
        for item in args.isel or []:
            dim, _, idx = item.partition("=")
            terms = terms.isel({dim: int(idx)})
        try:
            y, sigma = invert.read_spectrum(args.measured)
        except InversionError:
            lc = read_light_curve(args.measured)
            if args.range_km is None:
                raise InversionError(
                    "--range-km: needed to turn measured magnitudes into signal"
                ) from None
            y, sigma = invert.magnitudes_to_signal(lc, args.range_km)
            terms = invert.band_terms(terms, [str(b) for b in y.band.values])
        ds = invert.unmix(
            y,
            terms,
            sigma,
            select=None if args.select == "none" else args.select,
            criterion=args.criterion,
        )
        print(
            f"unmix {args.measured}: chi2 {float(ds.chi2):.4g}, "
            f"reduced {float(ds.reduced_chi2):.4g}, "
            f"{args.criterion} selection: {ds.attrs['selected_materials']}"
        )
        for m in ds.material.values:
            print(
                f"  {m!s:<24} scale {float(ds.scale.sel(material=m)):.4f} "
                f"+- {float(ds.scale_uncertainty.sel(material=m)):.4f}"
            )
        print(f"  degenerate: {ds.attrs['degenerate']}")
    else:
        sc = _spacecraft_of(args)
        lo, hi, n = args.periods
        ds = invert.fit_spin(
            read_light_curve(args.measured),
            sc,
            to_sun=args.to_sun,
            to_observer=args.to_observer,
            periods=np.linspace(lo, hi, int(n)),
            axis_body=args.axis_body,
            n_axes=args.n_axes,
            n_phases=args.n_phases,
            offset=args.offset,
        )
        print(
            f"spin fit of {args.measured}: {ds.attrs['n_candidates']} candidates in "
            f"{ds.attrs['search_seconds']:.1f} s; chi2 {float(ds.chi2):.4g}, "
            f"reduced {float(ds.reduced_chi2):.4g}"
        )
        for k in ("axis_longitude", "axis_latitude", "period", "phase"):
            print(
                f"  {k:<15} {float(ds[k]):10.4f} +- {float(ds[k + '_uncertainty']):.4f} "
                f"{ds[k].attrs['units']}"
            )
        for sname in ds.solution.values:
            print(
                f"  alternative {sname!s:<14} "
                f"chi2 gap {float(ds.chi2_gap.sel(solution=sname)):10.2f}"
            )
    if args.output:
        write_netcdf_atomic(ds, args.output, overwrite=args.overwrite)
        print(f"wrote {args.output}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``sbrdf-xr``.

    Examples
    --------
    >>> from sbrdf_xr.cli import build_parser
    >>> args = build_parser().parse_args(
    ...     ["simulate", "canx1-rotation", "-o", "cube.nc", "--preset", "fast"]
    ... )
    >>> args.command, args.scene, args.output, args.preset, args.complevel
    ('simulate', 'canx1-rotation', 'cube.nc', 'fast', 4)
    """
    p = argparse.ArgumentParser(
        prog="sbrdf-xr", description="Spectral BRDF simulation of unresolved spacecraft."
    )
    p.add_argument("--version", action="version", version=f"sbrdf_xr {__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    pc = sub.add_parser(
        "catalog", help="list or show the catalog entries (shipped, and SBRDF_XR_CATALOG_PATH)"
    )
    csub = pc.add_subparsers(dest="catalog_command", required=True)
    pl = csub.add_parser("list", help="list the catalog entries and the catalog of each")
    pl.add_argument("--kind", choices=catalog.KINDS, help="only entries of this kind")
    pl.set_defaults(func=_cmd_catalog_list)
    ps = csub.add_parser("show", help="show one entry")
    ps.add_argument("name")
    ps.set_defaults(func=_cmd_catalog_show)

    pi = sub.add_parser("info", help="versions, or a summary of a netCDF file")
    pi.add_argument("file", nargs="?")
    pi.set_defaults(func=_cmd_info)

    pk = sub.add_parser("knobs", help="the numerical knobs, their defaults and the presets")
    pk.set_defaults(func=_cmd_knobs)

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
    pb.set_defaults(func=_cmd_bench)

    psim = sub.add_parser("simulate", help="run a scene into a netCDF cube")
    psim.add_argument(
        "scene", help="built-in scene name (canx1-rotation, canx1-plusx-specular) or a TOML file"
    )
    psim.add_argument("-o", "--output", required=True, help="netCDF file to write")
    psim.add_argument(
        "--scheduler", help="address of a dask.distributed scheduler (default: threads)"
    )
    psim.add_argument("--preset", help="numerical preset: fast, balanced or reference")
    psim.add_argument(
        "--set",
        action="append",
        metavar="KNOB=VALUE",
        help="set a numerical knob (repeatable; 'sbrdf-xr knobs' lists them), e.g. "
        "--set method=cubic --set dtype=float32",
    )
    psim.add_argument(
        "--complevel",
        type=int,
        default=4,
        choices=range(10),
        metavar="0-9",
        help="zlib compression level of the netCDF cube (default 4; 0: none, fastest)",
    )
    psim.add_argument("--plot", help="also write the cube's figure to this PNG file")
    psim.add_argument(
        "--overwrite",
        action="store_true",
        help="replace an existing output file (a regular file only)",
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
    psim.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    psim.set_defaults(func=_cmd_simulate)

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
        help="observer range [km] (default: the range the cube records, if any)",
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
    pph.set_defaults(func=_cmd_photometry)

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
    pspin = isub.add_parser("spin", help="spin axis, period and phase from a colour light curve")
    pspin.add_argument(
        "measured", help="light curve CSV/netCDF (read_light_curve format, times in s)"
    )
    pspin.add_argument(
        "--spacecraft", default="canx1", help="a catalog name (default canx1) or a mesh file"
    )
    _mesh_options(pspin)
    pspin.add_argument(
        "--to-sun", type=float, nargs=3, required=True, help="inertial direction to the Sun"
    )
    pspin.add_argument(
        "--to-observer",
        type=float,
        nargs=3,
        required=True,
        help="inertial direction to the observer",
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
    pspin.add_argument("--n-axes", type=int, default=300)
    pspin.add_argument("--n-phases", type=int, default=36)
    pspin.add_argument("--offset", choices=("band", "common"), default="band")
    for q in (pu, pspin):
        q.add_argument("-o", "--output", help="write the result Dataset to this netCDF file")
        q.add_argument("--overwrite", action="store_true", help="replace an existing output file")
        q.set_defaults(func=_cmd_invert)

    pp = sub.add_parser("plot", help="draw a cube's figure")
    pp.add_argument("cube")
    pp.add_argument("-o", "--output", required=True)
    pp.set_defaults(func=_cmd_plot)
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
    block_bytes        33554432    - / - / -                     memory budget of one block's ...
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
        with command_line_messages():
            return int(args.func(args))
    except (SbrdfError, OSError) as exc:
        print(f"sbrdf-xr: error: {_one_line(exc)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        out = getattr(args, "output", None)
        hint = ""
        if out and Path(str(out) + LOG_SUFFIX).exists():
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
