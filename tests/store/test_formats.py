"""Tests of sbrdf_xr.store.formats: the registry of output formats, and every writer
refusing every kind of special file at its output and at its siblings.

Each entry of :data:`~sbrdf_xr.store.formats.FORMATS` is called with ``overwrite`` false
and true on an output path (or a sibling: ``.part``, ``.part.jsonl``, ``.lock``) that
holds a FIFO, a symbolic link (to a file, to a directory, dangling, to ``/dev/null``), a
character device, a socket or a directory (a foreign directory, for a Zarr store): the
write must be refused with an :class:`~sbrdf_xr.errors.OutputError` naming the path,
without blocking and without changing anything on disk.  A foreign directory at
``<output>.part`` is refused by the cube writers and left alone by the others.  The
command line's outputs (``simulate -o/--plot``, ``observe -o/--plot``, ``photometry
-o/--csv``, ``invert -o``, ``bench -o/--csv/--plot``, ``plot -o``) and the table cache
are tried the same way.  A table of writers x kinds is printed at the end of the module.
"""

from __future__ import annotations

import contextlib
import os
import sys
import warnings
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from sbrdf_xr._output import file_kind
from sbrdf_xr.errors import OutputError, ValidationError
from sbrdf_xr.store import formats
from sbrdf_xr.store.formats import FORMATS, format_for

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent)]
from test_output import KINDS, make_special, no_hang  # noqa: E402
from test_writer import make_cube  # noqa: E402

#: (writer, where, kind) -> Counter of outcomes: "refused" (an OutputError naming the
#: path, nothing on disk changed), "written" (the output written beside an untouched
#: foreign directory), or a failure ("hang", "changed", "replaced", "named another path").
OUTCOMES: dict[tuple[str, str, str], Counter] = {}
#: A directory without the package's marker at ``<output>.part``.
FOREIGN_PART = "foreign-part-dir"


@pytest.fixture(scope="module", autouse=True)
def special_file_table(request):
    """Print writers x kinds of special file after the module: in each cell the trials
    whose outcome was the safe one (R: refused by name, nothing changed; W: written,
    the foreign directory left as it was) over all trials of the cell."""
    yield
    kinds = [*KINDS, FOREIGN_PART]
    rows = sorted({(w, where) for w, where, _ in OUTCOMES})
    short = {  # column heads
        "symlink": "link>file",
        "symlink-to-dir": "link>dir",
        "dangling-symlink": "dangling",
        "char-device": "chardev",
        "devnull-symlink": "link>null",
        "directory": "dir",
        FOREIGN_PART: "alien.part",
    }
    head = f"{'special files: writer':<30}{'where':<12}" + "".join(
        f"{short.get(k, k):>11}" for k in kinds
    )
    lines = [head]
    total = Counter()
    for writer, where in rows:
        cells = []
        for k in kinds:
            c = OUTCOMES.get((writer, where, k))
            if not c:
                cells.append(f"{'-':>11}")
                continue
            total += c
            good, tag = (c["written"], "W") if c["written"] else (c["refused"], "R")
            cells.append(f"{f'{tag} {good}/{sum(c.values())}':>11}")
        lines.append(f"{writer:<30}{where:<12}" + "".join(cells))
    bad = sum(total.values()) - total["refused"] - total["written"]
    lines.append(
        f"all: {total['refused']} refused, {total['written']} written beside a foreign "
        f"directory, {bad} other (hang, changed, replaced) of {sum(total.values())} trials"
    )
    reporter = request.config.pluginmanager.get_plugin("terminalreporter")
    capman = request.config.pluginmanager.getplugin("capturemanager")
    with capman.global_and_fixture_disabled() if capman else contextlib.nullcontext():
        for line in ["", *lines]:
            if reporter is not None:
                reporter.write_line(line)


def photometry_ds() -> xr.Dataset:
    from sbrdf_xr.photometry import photometry

    wl = np.arange(300.0, 1101.0, 10.0)
    cube = xr.Dataset(
        {"signal": (("geometry", "wavelength"), np.full((2, wl.size), 0.1), {"units": "m2 sr-1"})},
        coords={"wavelength": ("wavelength", wl, {"units": "nm"})},
    )
    return photometry(cube, ["B", "V"], 1000.0, pairs=[("B", "V")])


def table_ds() -> xr.Dataset:
    return xr.Dataset(
        {"time_ratio": ("case", [1.0, 0.4], {"units": "1", "long_name": "time ratio"})},
        coords={"case": ["reference", "fast"]},
    )


def figure():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    ax.plot([0, 1], [1, 0])
    return fig


def material():
    from sbrdf_xr.materials.schema import lambertian

    return lambertian(0.5, [500.0, 600.0], material="grey")


def model():
    from sbrdf_xr.materials.model_schema import model_material

    return model_material("lambert", [550.0], material="grey", provenance="test", rho=0.5)


#: entry -> (object factory, file name)
OBJECTS = {
    "netcdf-cube": (make_cube, "cube.nc"),
    "zarr-cube": (make_cube, "cube.zarr"),
    "material-netcdf": (material, "grey.nc"),
    "model-netcdf": (model, "model.nc"),
    "photometry-netcdf": (photometry_ds, "phot.nc"),
    "photometry-csv": (photometry_ds, "phot.csv"),
    "inversion-netcdf": (table_ds, "fit.nc"),
    "table-netcdf": (table_ds, "bench.nc"),
    "table-csv": (table_ds, "bench.csv"),
    "figure": (figure, "fig.png"),
}

CASES = [(name, "output") for name in OBJECTS] + [
    (name, sibling) for name, f in FORMATS.items() for sibling in f.siblings
]


def test_every_format_has_a_case():
    assert set(OBJECTS) == set(FORMATS)


def tree(d: Path) -> list[tuple[str, int, bytes | str | None]]:
    out = []
    for root, dirs, files in os.walk(d):
        for n in dirs + files:
            p = Path(root) / n
            st = os.lstat(p)
            if p.is_symlink():
                data: bytes | str | None = f"-> {os.readlink(p)}"
            elif p.is_file():
                data = p.read_bytes()
            else:
                data = None
            out.append((str(p.relative_to(d)), st.st_mode, data))
    return sorted(out)


@pytest.mark.parametrize("overwrite", [False, True])
@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize(("name", "where"), CASES, ids=[f"{n}-{w}" for n, w in CASES])
def test_every_writer_refuses_every_special_file(tmp_path, name, where, kind, overwrite):
    factory, filename = OBJECTS[name]
    obj = factory()
    out = tmp_path / filename
    target = out if where == "output" else out.with_name(out.name + where)
    keep = make_special(target, kind)
    before = tree(tmp_path)
    outcome = "replaced"
    try:
        with no_hang():
            FORMATS[name].writer(obj, out, overwrite=overwrite)
    except OutputError as exc:
        outcome = "refused" if str(target) in str(exc) else "named another path"
    except TimeoutError:
        outcome = "hang"
    finally:
        del keep
        if name == "figure":
            import matplotlib.pyplot as plt

            plt.close(obj)
    if outcome == "refused" and tree(tmp_path) != before:
        outcome = "changed"
    OUTCOMES.setdefault((name, where, kind), Counter())[outcome] += 1
    assert outcome == "refused"


@pytest.mark.parametrize("overwrite", [False, True])
@pytest.mark.parametrize("name", list(OBJECTS))
def test_a_foreign_part_directory_beside_every_output(tmp_path, name, overwrite):
    """A directory the package did not write at ``<output>.part``: the cube writers, whose
    ``.part`` it is, refuse it by name; the others write through a temporary file of
    their own and leave it as it is.  Nothing of it is ever deleted."""
    factory, filename = OBJECTS[name]
    obj = factory()
    out = tmp_path / filename
    part = out.with_name(out.name + ".part")
    part.mkdir()
    (part / "kept.txt").write_text("a user's file")
    before = tree(part)
    outcome = "replaced"
    try:
        with no_hang():
            FORMATS[name].writer(obj, out, overwrite=overwrite)
        outcome = "written" if file_kind(out) is not None else "nothing written"
    except OutputError as exc:
        outcome = "refused" if str(part) in str(exc) else "named another path"
    except TimeoutError:
        outcome = "hang"
    finally:
        if name == "figure":
            import matplotlib.pyplot as plt

            plt.close(obj)
    if tree(part) != before:
        outcome = "changed"
    OUTCOMES.setdefault((name, "output", FOREIGN_PART), Counter())[outcome] += 1
    assert outcome == ("refused" if FORMATS[name].kind == "cube" else "written"), outcome
    if outcome == "written":
        names = sorted(p.name for p in tmp_path.iterdir())
        assert names == sorted([out.name, part.name]), names  # no temporary file left


@pytest.mark.parametrize("kind", [*KINDS, FOREIGN_PART])
def test_the_table_cache_never_writes_through_a_special_file(tmp_path, monkeypatch, kind):
    """A special file at a table's cache file: the table is built and returned, with a
    CacheWarning naming the file, and the special file is left as it is."""
    from sbrdf_xr.errors import CacheWarning
    from sbrdf_xr.materials import cache as _cache
    from sbrdf_xr.materials import tables

    monkeypatch.setenv("SBRDF_XR_CACHE_DIR", str(tmp_path))
    built = material()
    path = _cache.cache_file("grey", [], "()")
    target = path.with_name(path.name + ".part") if kind == FOREIGN_PART else path
    if kind == FOREIGN_PART:
        target.mkdir()
        (target / "kept.txt").write_text("a user's file")
        keep = None
    else:
        keep = make_special(target, kind)
    before = tree(target if kind == FOREIGN_PART else tmp_path)

    def write(da, p):
        tables.to_netcdf(da, p, overwrite=True, complevel=0)

    with no_hang(), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        got = _cache.cached_table("grey", [], "()", lambda: built, write, tables.open_material)
    del keep
    warned = [str(w.message) for w in caught if issubclass(w.category, CacheWarning)]
    if kind == FOREIGN_PART:  # not the cache's name: the table is cached beside it
        ok = file_kind(path) == "file" and not warned and tree(target) == before
        outcome = "written" if ok else "changed"
    else:
        ok = len(warned) == 1 and str(path) in warned[0] and tree(tmp_path) == before
        outcome = "refused" if ok else "changed"
    assert np.array_equal(got.values, built.values)
    OUTCOMES.setdefault(("table-cache", "output", kind), Counter())[outcome] += 1
    assert ok, (warned, kind)


CLI_OUTPUTS = [
    ("simulate", "-o", "cube.nc"),
    ("simulate", "-o", "cube.zarr"),
    ("simulate", "--plot", "fig.png"),
    ("observe", "-o", "pass.nc"),
    ("observe", "--plot", "pass.png"),
    ("photometry", "-o", "phot.nc"),
    ("photometry", "--csv", "phot.csv"),
    ("invert", "-o", "fit.nc"),
    ("bench", "-o", "bench.nc"),
    ("bench", "--csv", "bench.csv"),
    ("bench", "--plot", "front.png"),
    ("plot", "-o", "fig.png"),
]
#: Commands that take minutes to run through (their refusals come first, in moments).
LONG_COMMANDS = ("simulate", "bench")
#: A short pass (5 times) for ``sbrdf-xr observe``.
OBSERVE = [
    "observe",
    "--elements",
    "canx1-example",
    "--site",
    "socorro-ets",
    "--start",
    "2024-03-17T03:02:20",
    "--duration",
    "20",
    "--step",
    "5",
    "--bands",
    "V",
    "-q",
]


@pytest.fixture(scope="module")
def analysis_files(tmp_path_factory):
    """A cube with per-material signal and a measured spectrum of it."""
    import trimesh

    from sbrdf_xr import Scene, load_spacecraft, simulate, write
    from sbrdf_xr.materials.schema import lambertian

    d = tmp_path_factory.mktemp("analysis")
    box = load_spacecraft(trimesh.creation.box(), material="grey")
    grey = lambertian(0.5, np.arange(300.0, 1101.0, 20.0), material="grey")
    x = [[1.0, 0.0, 0.0]]
    scene = Scene(
        box,
        {"grey": grey},
        to_sun=x,
        to_observer=x,
        outputs=("signal", "per_material"),
        kernel="numpy",
    )
    cube = write(simulate(scene), d / "cube.nc")
    # the cube's 1/pi [m2 sr-1] measured with scatter of about its uncertainty (an exact
    # spectrum would fit with a chi-square far below its distribution, which is warned of)
    rows = "wavelength,signal,uncertainty\n" + "".join(
        f"{wl},{v},0.01\n" for wl, v in ((500, 0.3283099), (600, 0.3083099), (700, 0.3183099))
    )
    (d / "spectrum.csv").write_text(rows)
    return d, cube


def cli_argv(command: str, flag: str, out: Path, d: Path, cube: Path) -> list[str]:
    if command == "photometry":
        return ["photometry", str(cube), "--bands", "V", "--range-km", "1000", "-q", flag, str(out)]
    if command == "invert":
        spectrum = str(d / "spectrum.csv")
        return [
            "invert",
            "unmix",
            spectrum,
            "--cube",
            str(cube),
            "--isel",
            "geometry=0",
            flag,
            str(out),
        ]
    if command == "simulate" and flag == "-o":
        return ["simulate", "canx1-rotation", "-o", str(out), "-q"]
    if command == "simulate":
        return ["simulate", "canx1-rotation", "-o", str(out.with_name("c.nc")), flag, str(out)]
    if command == "observe" and flag == "-o":
        return [*OBSERVE, "-o", str(out)]
    if command == "observe":
        return [*OBSERVE, "-o", str(out.with_name("c.nc")), flag, str(out)]
    if command == "bench":
        return ["bench", "--quick", flag, str(out)]
    return ["plot", str(cube), flag, str(out)]


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize(("command", "flag", "filename"), CLI_OUTPUTS)
def test_command_line_outputs_refuse_special_files(
    tmp_path, analysis_files, capsys, command, flag, filename, kind
):
    from sbrdf_xr.cli import main

    d, cube = analysis_files
    out = tmp_path / filename
    keep = make_special(out, kind)
    before = tree(tmp_path)
    argv = cli_argv(command, flag, out, d, cube)
    with no_hang():
        status = main([*argv, "--overwrite"])
    err = capsys.readouterr().err.strip().splitlines()
    del keep
    refused = status == 2 and len(err) == 1 and str(out) in err[0] and tree(tmp_path) == before
    outcome = "refused" if refused else "replaced"
    writer = f"cli {command} {flag} {Path(filename).suffix}"
    OUTCOMES.setdefault((writer, "output", kind), Counter())[outcome] += 1
    assert refused, (status, err)


def test_photometry_csv_onto_a_fifo_does_not_block(tmp_path, analysis_files, capsys):
    from sbrdf_xr.cli import main

    d, cube = analysis_files
    fifo = tmp_path / "phot.csv"
    os.mkfifo(fifo)
    with no_hang():
        status = main(cli_argv("photometry", "--csv", fifo, d, cube))
    assert status == 2 and "FIFO" in capsys.readouterr().err


def test_command_line_outputs_are_written_and_replaced_only_when_asked(
    tmp_path, analysis_files, capsys
):
    from sbrdf_xr.cli import main

    d, cube = analysis_files
    for command, flag, filename in CLI_OUTPUTS:
        if command in LONG_COMMANDS:
            continue
        out = tmp_path / filename
        argv = cli_argv(command, flag, out, d, cube)
        assert main(argv) == 0, capsys.readouterr().err
        first = out.read_bytes()
        assert main(argv) == 2 and "pass --overwrite" in capsys.readouterr().err
        assert out.read_bytes() == first
        assert main([*argv, "--overwrite"]) == 0
        assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(out.name)) == [
            out.name
        ]
        out.unlink()


# ------------------------------------------------------------------ the registry


@pytest.mark.parametrize(
    ("path", "kind", "name"),
    [
        ("c.nc", "cube", "netcdf-cube"),
        ("c.NC4", "cube", "netcdf-cube"),
        ("cube", "cube", "netcdf-cube"),
        ("c.cube", "cube", "netcdf-cube"),
        ("c.zarr", "cube", "zarr-cube"),
        ("c.zarr/", "cube", "zarr-cube"),
        ("m.nc", "material", "material-netcdf"),
        ("m.table", "material", "material-netcdf"),
        ("p.nc", "photometry", "photometry-netcdf"),
        ("p.csv", "photometry", "photometry-csv"),
        ("b.csv", "table", "table-csv"),
        ("b.nc", "table", "table-netcdf"),
        ("f.PDF", "figure", "figure"),
    ],
)
def test_the_suffix_picks_the_entry(path, kind, name):
    assert format_for(path, kind).name == name


@pytest.mark.parametrize(
    ("path", "kind", "match"),
    [
        ("c.csv", "cube", r"a cube is written as netCDF .* or Zarr .*not \.csv"),
        ("c.png", "cube", r"not \.png \(the suffix of a figure\)"),
        ("m.zarr", "material", r"not \.zarr \(the suffix of a cube\)"),
        ("f.nc", "figure", r"a figure is written as image .*not \.nc \(the suffix of a cube or"),
        ("p.zarr", "photometry", r"a photometry table is written as netCDF .*or CSV"),
        ("f", "figure", "without a suffix"),
        ("x.nc", "spectrum", "is not one of"),
    ],
)
def test_suffixes_of_other_kinds_are_refused(path, kind, match):
    with pytest.raises(ValidationError, match=match):
        format_for(path, kind)


def test_a_format_is_named_only_among_those_of_its_kind():
    assert format_for("anything.txt", "photometry", "photometry-csv").name == "photometry-csv"
    with pytest.raises(ValidationError, match="does not write a photometry table"):
        format_for("x.csv", "photometry", "table-csv")


def test_check_refuses_before_anything_is_computed(tmp_path):
    out = tmp_path / "c.nc"
    out.write_bytes(b"an older cube")
    with pytest.raises(FileExistsError):
        formats.check(out, "cube")
    assert formats.check(out, "cube", resume=True).name == "netcdf-cube"
    lock = tmp_path / "c.nc.lock"
    os.mkfifo(lock)
    with pytest.raises(OutputError, match=r"c\.nc\.lock is a FIFO"):
        formats.check(out, "cube", overwrite=True)


@pytest.mark.parametrize("bad", ["", ".", "..", "/"])
def test_names_that_name_no_file_are_refused_by_name(bad):
    for kind in ("cube", "photometry", "figure"):
        with pytest.raises(ValidationError):
            formats.check(bad, kind)
