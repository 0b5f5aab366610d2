"""The sub-commands of ``sbrdf-xr`` that list, run and draw: ``catalog``, ``info``,
``knobs``, ``bench``, ``simulate`` (with its spacecraft and material options) and
``plot``.  Each ``cmd_*`` takes the parsed arguments and returns the exit status.
"""

from __future__ import annotations

import argparse
import signal
import sys
import textwrap
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .. import catalog
from .._names import __version__
from .._output import file_kind
from ..errors import SbrdfError, ValidationError, did_you_mean
from ..store import PART_SUFFIX, formats
from .output import escape, escaped_attrs, load_cube, open_dataset

if TYPE_CHECKING:
    from ..engine import Scene

__all__ = [
    "cmd_bench",
    "cmd_catalog_list",
    "cmd_catalog_show",
    "cmd_info",
    "cmd_knobs",
    "cmd_plot",
    "cmd_simulate",
    "spacecraft_of",
]


def _catalog_label(e: catalog.CatalogEntry, users: list[Path]) -> str:
    """``shipped`` or ``user<i>`` (the i-th directory of SBRDF_XR_CATALOG_PATH)."""
    return "shipped" if e.root is None else f"user{users.index(e.root) + 1}"


def cmd_catalog_list(args: argparse.Namespace) -> int:
    """``sbrdf-xr catalog list``: one line per catalog entry (name, kind, source, catalog,
    description), then the catalog directories; returns 0.

    Examples
    --------
    >>> import contextlib
    >>> import io
    >>> from sbrdf_xr.cli import cmd_catalog_list
    >>> from sbrdf_xr.cli.parser import build_parser
    >>> args = build_parser().parse_args(["catalog", "list", "--kind", "spacecraft"])
    >>> out = io.StringIO()
    >>> with contextlib.redirect_stdout(out):
    ...     status = cmd_catalog_list(args)
    >>> lines = out.getvalue().splitlines()
    >>> status, lines[0].split()
    (0, ['name', 'kind', 'source', 'catalog', 'description'])
    >>> lines[1].split()[:4], lines[3]
    (['canx1', 'spacecraft', 'synthetic', 'shipped'], '1 entries; catalogs:')
    """
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


def cmd_catalog_show(args: argparse.Namespace) -> int:
    """``sbrdf-xr catalog show NAME``: the entry's fields, then a summary of its loaded
    contents; returns 0.

    Examples
    --------
    >>> import contextlib
    >>> import io
    >>> from sbrdf_xr.cli import cmd_catalog_show
    >>> from sbrdf_xr.cli.parser import build_parser
    >>> out = io.StringIO()
    >>> with contextlib.redirect_stdout(out):
    ...     status = cmd_catalog_show(build_parser().parse_args(["catalog", "show", "canx1"]))
    >>> lines = out.getvalue().splitlines()
    >>> status
    0
    >>> print(*lines[:4], sep="\\n")
    name:        canx1
    kind:        spacecraft
    source:      synthetic
    catalog:     shipped
    >>> print(lines[-1].split(":")[0])  # the loaded entry itself
    <Spacecraft 'canx1'
    """
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
    print(escape(escaped_attrs(catalog.load(e.name))))
    return 0


def cmd_info(args: argparse.Namespace) -> int:
    """``sbrdf-xr info [FILE]``: the versions of the package and its main dependencies and
    the catalogs, or the summary of a netCDF file (its attributes escaped); returns 0.

    Examples
    --------
    >>> import contextlib
    >>> import io
    >>> import tempfile
    >>> from pathlib import Path
    >>> import xarray as xr
    >>> import sbrdf_xr
    >>> from sbrdf_xr.cli import cmd_info
    >>> from sbrdf_xr.cli.parser import build_parser
    >>> out = io.StringIO()
    >>> with contextlib.redirect_stdout(out):
    ...     status = cmd_info(build_parser().parse_args(["info"]))
    >>> status, out.getvalue().splitlines()[0] == f"sbrdf_xr {sbrdf_xr.__version__}"
    (0, True)

    A file's attribute holding a terminal escape sequence prints as text:

    >>> ds = xr.Dataset({"v": ("x", [1.0])}, attrs={"title": chr(27) + "[2Jcube"})
    >>> out = io.StringIO()
    >>> with tempfile.TemporaryDirectory() as tmp, contextlib.redirect_stdout(out):
    ...     ds.to_netcdf(Path(tmp) / "t.nc")
    ...     status = cmd_info(build_parser().parse_args(["info", str(Path(tmp) / "t.nc")]))
    >>> text = out.getvalue()
    >>> status, "title:    \\\\x1b[2Jcube" in text, chr(27) in text
    (0, True, False)
    """
    if args.file:
        with open_dataset(args.file, describe=True) as ds:  # nothing read to describe it
            print(escape(escaped_attrs(ds)))
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


def cmd_bench(args: argparse.Namespace) -> int:
    """``sbrdf-xr bench``: the accuracy/cost benchmarks (:func:`sbrdf_xr.bench.run`; with
    ``--engine`` the engine rows), their table printed and written to the files of
    ``--output`` (netCDF), ``--csv`` and ``--plot`` (PNG); returns 0.

    With ``--quick`` the benchmarks run for about a minute, without it for many.  The
    table's first line gives the load average at the start and at the end of the run.

    Examples
    --------
    The options it reads, parsed from a command line:

    >>> from sbrdf_xr.cli import cmd_bench
    >>> from sbrdf_xr.cli.parser import build_parser
    >>> args = build_parser().parse_args(["bench", "--quick", "--csv", "bench.csv"])
    >>> args.func is cmd_bench
    True
    >>> args.quick, args.engine, args.output, args.csv, args.plot, args.record_presets
    (True, False, None, 'bench.csv', None, False)
    """
    from .. import bench

    for out, kind in ((args.output, "table"), (args.csv, "table"), (args.plot, "figure")):
        if out:  # refused before minutes of benchmarks, not after
            formats.check(out, kind, overwrite=args.overwrite)
    if args.repeat is not None and args.repeat < 1:
        raise ValidationError(f"--repeat: got {args.repeat}; expected a whole number >= 1")
    start = bench.rows.load_average()
    if args.engine:
        from ..bench.engine import engine_rows

        rows = engine_rows(quick=args.quick)
    else:
        rows = bench.run(quick=args.quick, repeat=args.repeat)
    header = bench.rows.load_header(start, bench.rows.load_average())
    print(header)
    print(bench.format_rows(rows))
    loaded = bench.rows.load_warning(rows)
    if loaded:
        print(f"warning: {loaded}", file=sys.stderr)
    if args.record_presets:
        command = "sbrdf-xr bench" + (" --quick" if args.quick else "")
        path = bench.write_presets(bench.presets_record(rows, command))
        print(f"wrote {path}")
    ds = bench.rows_to_dataset(rows).assign_attrs(load_average=header)
    if args.output:
        formats.write(ds, args.output, kind="table", overwrite=args.overwrite)
        print(f"wrote {args.output}")
    if args.csv:
        formats.write(ds, args.csv, kind="table", overwrite=args.overwrite)
        print(f"wrote {args.csv}")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        formats.write(bench.plot_front(rows), args.plot, kind="figure", overwrite=args.overwrite)
        print(f"wrote {args.plot}")
    return 0


def cmd_simulate(args: argparse.Namespace) -> int:
    """``sbrdf-xr simulate SCENE -o CUBE``: the scene (with the spacecraft, materials, preset
    and knobs of the options) is planned and its plan printed; unless ``--plan``, it is
    run and the cube written (overwritten or resumed as asked), with its figure for
    ``--plot``; returns 0.

    Examples
    --------
    A unit box of the catalog's Lambertian grey (albedo 0.5) at two attitudes and two
    phase angles; facing the Sun and the observer, it sends ``1 m2 x 0.5 / pi sr-1``:

    >>> import contextlib
    >>> import io
    >>> import tempfile
    >>> from pathlib import Path
    >>> import trimesh
    >>> import xarray as xr
    >>> from sbrdf_xr.cli import cmd_simulate
    >>> from sbrdf_xr.cli.parser import build_parser
    >>> text = '''
    ... name = "grey-box"
    ... spacecraft = { path = "box.stl", material = "lambertian-grey-50" }
    ... phase_angles = [0.0, 60.0]
    ... [attitude]
    ... kind = "sweep"
    ... axis = [0, 0, 1]
    ... stop = 90.0
    ... step = 45.0
    ... '''
    >>> out = io.StringIO()
    >>> with tempfile.TemporaryDirectory() as tmp, contextlib.redirect_stdout(out):
    ...     _ = trimesh.creation.box().export(Path(tmp) / "box.stl")
    ...     _ = (Path(tmp) / "box.toml").write_text(text)
    ...     cube = Path(tmp) / "cube.nc"
    ...     argv = ["simulate", str(Path(tmp) / "box.toml"), "-o", str(cube), "-q"]
    ...     planned = cmd_simulate(build_parser().parse_args([*argv, "--plan"]))
    ...     after_plan = cube.exists()
    ...     ran = cmd_simulate(build_parser().parse_args([*argv, "--set", "kernel=numpy"]))
    ...     with xr.open_dataset(cube) as ds:
    ...         signal = round(float(ds.signal.isel(attitude=0, phase_angle=0, wavelength=0)), 6)
    >>> planned, after_plan, ran, signal
    (0, False, 0, 0.159155)
    >>> lines = out.getvalue().splitlines()
    >>> lines[0], lines[1].split()
    ("plan for scene 'grey-box':", ['geometry', '2', 'attitudes', 'x', '2', 'phase', 'angles', \
'=', '4', 'geometries'])
    """
    from ..engine import resolve_scene
    from ..engine.builtin import builtin_scenes
    from ..engine.run import simulate

    out = Path(args.output)
    if not args.plan:  # every output is refused (a special file, ...) before the sweep runs
        fmt = formats.check(out, "cube", overwrite=args.overwrite, resume=args.resume)
        if args.plot:
            formats.check(args.plot, "figure", overwrite=args.overwrite)
    if not str(args.scene).strip():
        raise ValidationError(
            f"simulate SCENE: got {args.scene!r}; give a built-in scene name "
            f"({', '.join(builtin_scenes())}) or a scene TOML file"
        )
    scene = resolve_scene(args.scene)
    outputs = args.outputs or _scene_file_outputs(args.scene)
    scene = _with_body(scene, args)
    changes = _knob_values(args.set or [])
    given = [f"--preset {args.preset!r}"] if args.preset is not None else []
    given += [f"--set {s}" for s in args.set or []]
    try:
        if args.preset is not None:
            scene = scene.with_options(preset=args.preset, **changes)
        elif changes:
            scene = scene.with_options(**changes)
    except SbrdfError as exc:  # the option named, with the knob's own message
        raise ValidationError(f"{', '.join(given)}: {exc}") from None
    plan = scene.plan()  # the catalog's tables built as one batch, the kernel compiling meanwhile
    if args.plan or not args.quiet:  # --quiet: the result lines only
        print(plan)
    if args.plan:
        return 0
    part = out.with_name(out.name + PART_SUFFIX)
    finished = (
        args.resume
        and not args.overwrite
        and file_kind(out) is not None
        and file_kind(part) is None
    )
    # what a resume keeps, read before the write (which refuses a .part it cannot keep)
    kept = fmt.unfinished(out) if args.resume and fmt.unfinished is not None else None
    client = None
    if args.scheduler is not None:
        from ..store.writer import connect

        client = connect(args.scheduler)
    if hasattr(
        signal, "SIGXFSZ"
    ):  # past a file size limit, fail the write (named) instead of dying
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    try:
        cube = simulate(plan, client=client)
        path = fmt.writer(
            cube,
            out,
            overwrite=args.overwrite,
            resume=args.resume,
            client=client,
            progress=not args.quiet,
            complevel=args.complevel,
            outputs=outputs,
        )
    finally:
        if client is not None:
            client.close()
    if finished:
        print(f"{path} is already complete; nothing to resume")
    else:
        if kept:
            print(f"resumed {kept}; those were kept and only the missing blocks computed")
        print(f"wrote {path}")
    if args.plot:
        _save_figure(path, args.plot, overwrite=args.overwrite)
    return 0


def _scene_file_outputs(spec: str) -> str | None:
    """The ``outputs`` of a scene file's ``[write]`` table (None for a built-in scene or a
    file without one: the writer's default)."""
    from ..engine.builtin import builtin_scenes
    from ..engine.scene_file import write_options

    if spec in builtin_scenes() or not Path(spec).is_file():
        return None
    return write_options(spec).get("outputs")


def spacecraft_of(args: argparse.Namespace) -> Any:
    """The spacecraft of ``--spacecraft`` (a catalog name or a mesh file) and its options.

    Examples
    --------
    >>> from sbrdf_xr.cli import spacecraft_of
    >>> from sbrdf_xr.cli.parser import build_parser
    >>> parse = build_parser().parse_args
    >>> body = spacecraft_of(parse(["simulate", "s.toml", "-o", "c.nc", "--spacecraft", "canx1"]))
    >>> body.name, body.n_facets, body.materials
    ('canx1', 684, ['aluminium-6061-t6', 'tjpv-cell', 'white-paint-a276'])
    >>> spacecraft_of(parse(["simulate", "s.toml", "-o", "c.nc", "--spacecraft", "bus.stl"]))
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.ValidationError: --spacecraft bus.stl: a mesh file needs --mesh-material \
NAME (one material for every facet) or --material-map MAP.toml (facet colour or label -> material)
    """
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


def _with_body(scene: Scene, args: argparse.Namespace) -> Scene:
    """The scene with the spacecraft of ``--spacecraft`` and the tables (or models) of
    ``--material``."""
    from ..engine.builtin import load_material_specs

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
    body = scene.spacecraft if args.spacecraft is None and not mesh else spacecraft_of(args)
    unknown = sorted(set(specs) - set(body.materials))
    if unknown:
        raise ValidationError(
            f"--material: {unknown} are not materials of the spacecraft {body.name!r}; "
            + did_you_mean(unknown[0], body.materials, "its materials")
        )
    kept = {m: t for m, t in (scene.materials or {}).items() if m in body.materials}
    wanted = {m: specs.get(m, m) for m in body.materials if m in specs or m not in kept}
    named_in = (
        "--material-map"
        if args.material_map
        else "--mesh-material"
        if args.mesh_material
        else f"spacecraft {body.name!r}"
    )
    where = {m: "--material" if m in specs else named_in for m in wanted}
    found = load_material_specs(wanted, where=where)
    old_models = {m: v for m, v in (scene.models or {}).items() if m not in wanted}
    return scene.with_options(
        spacecraft=body, materials={**kept, **found}, models=old_models or None
    )


def _knob_values(items: list[str]) -> dict[str, object]:
    """``NAME=VALUE`` strings as knob values (TOML syntax for the value, else a string)."""
    import tomllib

    from ..engine.knobs import KNOBS
    from ..errors import SceneError

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
        except ValueError:  # not TOML (or an integer of over 4300 digits): the text
            value = text.strip()
        out[name] = None if value == "none" else value
    return out


def cmd_knobs(args: argparse.Namespace) -> int:
    """``sbrdf-xr knobs``: the table of :func:`sbrdf_xr.engine.knobs.knob_table`, then each
    preset's measured cost and error from the benchmark run recorded in the package
    (:func:`sbrdf_xr.bench.presets.presets_table`); returns 0.

    Examples
    --------
    >>> import contextlib
    >>> import io
    >>> from sbrdf_xr.cli import cmd_knobs
    >>> from sbrdf_xr.cli.parser import build_parser
    >>> from sbrdf_xr.engine.knobs import KNOBS
    >>> out = io.StringIO()
    >>> with contextlib.redirect_stdout(out):
    ...     status = cmd_knobs(build_parser().parse_args(["knobs"]))
    >>> lines = out.getvalue().splitlines()
    >>> status, lines[0].split()
    (0, ['knob', 'default', 'fast', '/', 'balanced', '/', 'reference', 'trades'])
    >>> [line.split()[0] for line in lines[1 : len(KNOBS) + 1]] == list(KNOBS)  # one per knob
    True
    >>> lines[len(KNOBS) + 2].startswith("presets as measured by `sbrdf-xr bench")
    True
    """
    from ..bench.presets import presets_table
    from ..engine.knobs import knob_table

    print(knob_table())
    print()
    print(presets_table())
    return 0


def _save_figure(
    cube_path: str | Path,
    figure_path: str,
    overwrite: bool = False,
    bands: tuple[str, ...] = ("V", "R", "I"),
) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..plot import cube_figure

    formats.check(figure_path, "figure", overwrite=overwrite)
    cube = load_cube(cube_path)
    try:
        fig = cube_figure(cube, bands=bands)
    except (KeyError, ValueError, IndexError) as exc:
        raise ValidationError(
            f"{cube_path}: cannot be drawn ({type(exc).__name__}: {exc})"
        ) from None
    try:
        formats.write(fig, figure_path, kind="figure", overwrite=overwrite)
    finally:
        plt.close(fig)
    print(f"wrote {figure_path}")


def cmd_plot(args: argparse.Namespace) -> int:
    """``sbrdf-xr plot CUBE -o FIG``: the cube's figure (:func:`sbrdf_xr.plot.cube_figure`,
    chosen by the cube: an observation, a rotation sweep or spectra) in an image file;
    returns 0.

    Examples
    --------
    >>> import contextlib
    >>> import io
    >>> import tempfile
    >>> from pathlib import Path
    >>> import trimesh
    >>> from sbrdf_xr import Scene, geometry, load_spacecraft, simulate, write
    >>> from sbrdf_xr.cli import cmd_plot
    >>> from sbrdf_xr.cli.parser import build_parser
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> turns = geometry.axis_rotation([0, 0, 1], [0.0, 45.0])
    >>> scene = Scene(box, {"grey": grey}, attitudes=turns, phase_angles=[0.0], kernel="numpy")
    >>> out = io.StringIO()
    >>> with tempfile.TemporaryDirectory() as tmp, contextlib.redirect_stdout(out):
    ...     cube, fig = Path(tmp) / "cube.nc", Path(tmp) / "cube.png"
    ...     _ = write(simulate(scene), cube)
    ...     status = cmd_plot(build_parser().parse_args(["plot", str(cube), "-o", str(fig)]))
    ...     png = fig.read_bytes()[1:4]
    >>> status, png, out.getvalue().startswith("wrote ")
    (0, b'PNG', True)
    """
    _save_figure(args.cube, args.output, overwrite=args.overwrite)
    return 0
