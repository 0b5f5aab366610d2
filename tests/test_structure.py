"""The package's imports flow one way, and its folders are its layers.

The packages and shared modules of ``sbrdf_xr`` stand in layers, lowest first; a module
imports only from its own layer or lower ones, and no set of modules imports itself round
(within a layer either).  A module of a subpackage has the layer of its package.
Imports are read from the source with :mod:`ast`, at module level, inside functions and
under ``if TYPE_CHECKING:`` alike: an import inside a function runs when it is called, and
a type-only import still says that one module needs to know another.  Importing
``a.b.c`` runs ``a/__init__`` and ``a/b/__init__`` first, so a module importing a module
of another package imports that package's ``__init__`` too (what the package's
``__init__`` imports in turn is then reached).

* L0, shared by every layer: ``_names`` (the version too), ``errors``, ``units`` (Quantities
  converted at the door, bare numbers checked against their unit), ``geometry`` (the
  angle convention, facet tangents and ``psi``, attitudes as quaternions), ``sources``,
  ``_catalog_index`` (where the shipped files are; it loads nothing) and ``_output`` (the
  safe output every writer goes through).
* L1, arithmetic: ``kernels`` (compiled and numpy kernels) and ``brdf`` (analytic models).
* L2, the domain: ``materials``, ``body`` (the spacecraft), ``photometry``,
  ``lightcurves`` (measured light curves, built on ``photometry``) and ``observing``
  (orbits, sites, times, attitude laws, the Earth's shadow).
* L3: ``catalog`` (knows every kind's loader in L2).
* L4, the output: ``store`` (the output formats and cube writers; it writes and compares
  the fingerprint the engine computes, and knows nothing of scenes).
* L5, the cube: ``engine`` (scenes, plans, simulation).
* L6, users of everything: ``invert``, ``bench``, ``plot``, ``accessors``, ``testing``,
  ``cli`` and the package's ``__init__``.

A new package or root module must be given a layer here.  With each package counted as
one node, the graph is held to the bounds of :data:`GRAPH_LIMITS`.
"""

from __future__ import annotations

import ast
from functools import cache
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "sbrdf_xr"

LAYERS: tuple[tuple[str, ...], ...] = (
    (
        "_names",
        "_startup",
        "errors",
        "geometry",
        "sources",
        "_catalog_index",
        "_output",
        "units",
    ),
    ("kernels", "brdf"),
    ("materials", "body", "photometry", "lightcurves", "observing"),
    ("catalog",),
    ("store",),
    ("engine",),
    ("invert", "bench", "plot", "accessors", "testing", "cli", ""),
)


def _module_name(path: Path, root: Path) -> str:
    parts = path.relative_to(root).with_suffix("").parts
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def import_graph(root: Path = PACKAGE) -> dict[str, set[str]]:
    """Module -> the package modules it imports (names relative to the package, ``""`` for it)."""
    files = {_module_name(p, root): p for p in root.rglob("*.py")}
    graph: dict[str, set[str]] = {}
    for mod, path in files.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        pkg = mod.split(".") if path.name == "__init__.py" else mod.split(".")[:-1]
        if mod == "":
            pkg = []
        deps: set[str] = set()
        for node in ast.walk(tree):
            targets: list[str] = []
            if isinstance(node, ast.Import):
                targets = [
                    a.name.removeprefix("sbrdf_xr").lstrip(".")
                    for a in node.names
                    if a.name == "sbrdf_xr" or a.name.startswith("sbrdf_xr.")
                ]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base_parts = pkg[: len(pkg) - node.level + 1] + (
                        [node.module] if node.module else []
                    )
                    base = ".".join(base_parts)
                elif node.module and (
                    node.module == "sbrdf_xr" or node.module.startswith("sbrdf_xr.")
                ):
                    base = node.module.removeprefix("sbrdf_xr").lstrip(".")
                else:
                    continue
                for a in node.names:
                    sub = f"{base}.{a.name}" if base else a.name
                    targets.append(sub if sub in files else base)
            for t in targets:
                while t and t not in files:
                    t = t.rpartition(".")[0]
                deps.update(_runs(t, mod))
        graph[mod] = deps
    return graph


def _runs(target: str, importer: str) -> set[str]:
    """The modules an import of ``target`` by ``importer`` runs: ``target`` and each package
    above it that is not above ``importer`` (those are running already)."""
    out = set()
    while target and not (importer == target or importer.startswith(target + ".")):
        out.add(target)
        target = target.rpartition(".")[0]
    return out


def layer_of(mod: str) -> int:
    """Layer of a module: that of its entry, or of its package's (``brdf.lambert`` -> ``brdf``)."""
    name = mod
    while True:
        for i, layer in enumerate(LAYERS):
            if name in layer:
                return i
        if not name or "." not in name:
            raise KeyError(mod)
        name = name.rpartition(".")[0]


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def against_flow(graph: dict[str, set[str]]) -> list[str]:
    """Imports of a module from a higher layer, as ``"a (L1) -> b (L2)"``."""
    bad = []
    for mod, deps in sorted(graph.items()):
        for dep in sorted(deps):
            if layer_of(dep) > layer_of(mod):
                bad.append(
                    f"{mod or 'sbrdf_xr'} (L{layer_of(mod)}) -> "
                    f"{dep or 'sbrdf_xr'} (L{layer_of(dep)})"
                )
    return bad


#: A module with more lines of code than this (docstrings, comments and blank lines not
#: counted) is doing more than one job: split it by job.
MAX_MODULE_CODE_LINES = 400


def _docstring_lines(tree: ast.AST) -> set[int]:
    """Line numbers inside the docstrings of the module, its classes and functions."""
    doc: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
        else:
            continue
        for stmt in body:
            if isinstance(stmt, ast.Expr) and isinstance(stmt.value, ast.Constant):
                if isinstance(stmt.value.value, str):
                    doc.update(range(stmt.lineno, (stmt.end_lineno or stmt.lineno) + 1))
    return doc


def _is_code(line: str, i: int, doc: set[int]) -> bool:
    text = line.strip()
    return bool(text) and not text.startswith("#") and i not in doc


def code_lines(path: Path) -> int:
    """Lines that hold code: not blank, not only a comment, not inside a docstring."""
    src = path.read_text(encoding="utf-8")
    doc = _docstring_lines(ast.parse(src))
    return sum(_is_code(line, i, doc) for i, line in enumerate(src.splitlines(), start=1))


#: A function with more lines of code than this tells more than one story: split it into
#: named steps.  Counted like a module's lines (no blank lines, no comment-only lines, no
#: docstring lines) from its ``def`` (decorators included) to its last line, so the lines
#: of functions nested in it count as its own (a closure is not a way out).
MAX_FUNCTION_CODE_LINES = 150


def function_lines(path: Path) -> dict[str, int]:
    """``"qualified.name:line" -> lines of code`` of every function and method in a file."""
    src = path.read_text(encoding="utf-8")
    tree = ast.parse(src)
    doc = _docstring_lines(tree)
    lines = src.splitlines()
    out: dict[str, int] = {}

    def visit(node: ast.AST, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                first = min([child.lineno] + [d.lineno for d in child.decorator_list])
                last = child.end_lineno or child.lineno
                out[f"{prefix}{child.name}:{child.lineno}"] = sum(
                    _is_code(lines[i - 1], i, doc) for i in range(first, last + 1)
                )
                visit(child, f"{prefix}{child.name}.")
            elif isinstance(child, ast.ClassDef):
                visit(child, f"{prefix}{child.name}.")
            else:
                visit(child, prefix)

    visit(tree, "")
    return out


def test_code_lines_leave_out_docstrings_and_comments(tmp_path):
    f = tmp_path / "m.py"
    f.write_text(
        '"""Doc\n\nlines."""\n\n# a comment\nx = 1  # code\n\n\ndef f():\n'
        '    """Doc."""\n    return x\n'
    )
    assert code_lines(f) == 3


def test_no_module_is_over_the_code_limit():
    long = {
        str(p.relative_to(PACKAGE)): n
        for p in sorted(PACKAGE.rglob("*.py"))
        if (n := code_lines(p)) > MAX_MODULE_CODE_LINES
    }
    assert not long, f"modules over {MAX_MODULE_CODE_LINES} lines of code (split by job): {long}"


def test_function_lines_count_code_of_nested_functions_too(tmp_path):
    f = tmp_path / "m.py"
    f.write_text(
        '@decorator\ndef f(x):\n    """Doc.\n\n    More."""\n\n    # a comment\n'
        "    def g():\n        return x\n\n    return g\n\n\nclass C:\n"
        "    def m(self):\n        pass\n"
    )
    assert function_lines(f) == {"f:2": 5, "f.g:8": 2, "C.m:15": 2}


def test_no_function_is_over_the_code_limit():
    long = {
        f"{p.relative_to(PACKAGE)}:{name}": n
        for p in sorted(PACKAGE.rglob("*.py"))
        for name, n in function_lines(p).items()
        if n > MAX_FUNCTION_CODE_LINES
    }
    assert not long, (
        f"functions over {MAX_FUNCTION_CODE_LINES} lines of code (split into named steps): {long}"
    )


def test_every_module_has_a_layer():
    with pytest.raises(KeyError):
        layer_of("a_new_module")
    missing = []
    for mod in import_graph():
        try:
            layer_of(mod)
        except KeyError:
            missing.append(mod)
    assert not missing, f"modules without a layer in tests/test_structure.py: {missing}"


def test_no_import_cycles():
    found = cycles(import_graph())
    assert not found, "import cycles: " + "; ".join(" <-> ".join(c) for c in found)


def test_no_imports_against_the_flow():
    bad = against_flow(import_graph())
    assert not bad, "imports against the flow:\n" + "\n".join(bad)


def test_the_checks_catch_a_catalog_import_in_materials(tmp_path):
    """The reading of the imports sees a function-level ``from .catalog import`` in material."""
    import shutil

    copy = tmp_path / "sbrdf_xr"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__", "catalogs"))
    mat = copy / "materials" / "tables.py"
    mat.write_text(
        mat.read_text(encoding="utf-8")
        + "\n\ndef _f():\n    from ..catalog import load\n\n    return load\n",
        encoding="utf-8",
    )
    graph = import_graph(copy)
    assert "materials.tables (L2) -> catalog (L3)" in against_flow(graph)
    assert any({"materials.tables", "catalog"} <= set(c) for c in cycles(graph))


def test_type_checking_and_function_imports_are_counted(tmp_path):
    pkg = tmp_path / "sbrdf_xr"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "errors.py").write_text(
        "from typing import TYPE_CHECKING\n\nif TYPE_CHECKING:\n"
        "    from .catalog import CatalogEntry\n"
    )
    (pkg / "catalog.py").write_text("def f():\n    from .errors import CatalogError\n")
    graph = import_graph(pkg)
    assert graph == {"": set(), "errors": {"catalog"}, "catalog": {"errors"}}
    assert cycles(graph) == [["catalog", "errors"]]


def test_a_type_only_import_of_the_engine_in_the_store_is_an_arrow_back(tmp_path):
    pkg = tmp_path / "sbrdf_xr"
    (pkg / "store").mkdir(parents=True)
    (pkg / "engine").mkdir()
    for init in (pkg, pkg / "store", pkg / "engine"):
        (init / "__init__.py").write_text("")
    (pkg / "store" / "fingerprint.py").write_text(
        "from typing import TYPE_CHECKING\n\nif TYPE_CHECKING:\n"
        "    from ..engine.scene import Scene\n"
    )
    (pkg / "engine" / "scene.py").write_text("from ..store.fingerprint import PREFIX\n")
    graph = import_graph(pkg)
    assert against_flow(graph) == [
        "store.fingerprint (L4) -> engine (L5)",
        "store.fingerprint (L4) -> engine.scene (L5)",
    ]
    assert cycles(package_graph(pkg)) == [["engine", "store"]]


def test_an_import_from_a_subpackage_runs_its_init(tmp_path):
    """``spectral`` imports ``effects.base``, which runs ``effects/__init__``; that imports
    ``thermal``, which imports ``spectral`` inside a function: a cycle."""
    pkg = tmp_path / "sbrdf_xr"
    (pkg / "engine" / "effects").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "engine" / "__init__.py").write_text("")
    (pkg / "engine" / "spectral.py").write_text("from .effects.base import readonly\n")
    (pkg / "engine" / "effects" / "__init__.py").write_text("from . import base, thermal\n")
    (pkg / "engine" / "effects" / "base.py").write_text("")
    (pkg / "engine" / "effects" / "thermal.py").write_text(
        "from .base import readonly\n\ndef f():\n    from ..spectral import table_on\n"
    )
    graph = import_graph(pkg)
    assert graph["engine.spectral"] == {"engine.effects", "engine.effects.base"}
    assert graph["engine.effects.thermal"] == {"engine.effects.base", "engine.spectral"}
    assert cycles(graph) == [["engine.effects", "engine.effects.thermal", "engine.spectral"]]


@pytest.mark.parametrize(
    "mod", ["materials.tables", "materials.models", "body.spacecraft", "observing.observe"]
)
def test_domain_modules_do_not_import_the_catalog(mod):
    assert "catalog" not in import_graph()[mod]


# ----------------------------------------------------------------- private names
#
# A name with a leading underscore is private to where it is defined.  Outside it, a module
# uses (``from x import _n``, or ``x._n`` on an imported module ``x``) only:
#
# * the names of a private module (``_names``, ``brdf._common``, ``invert._unmix``, ...),
#   public or not, from its own package: an implementation module has no public face;
# * the private names of a module of a subpackage (``kernels``, ``store``, ``engine``,
#   ...) from another module of that subpackage: a package is one unit split into files.
#
# So no package uses another package's private names: what one package takes from another
# is public there (and published by that package's ``__init__``).
#
# Any other use is listed here, with the reason it stands, or fails the test.

#: (importer, "module._name" or "module") -> why the use stands.
PRIVATE_USES: dict[tuple[str, str], str] = {}


def _is_private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _package_of(mod: str) -> str:
    return mod.rpartition(".")[0]


def _allowed_private(importer: str, owner: str) -> bool:
    """True if ``importer`` may use the private names of module ``owner`` (see above)."""
    if importer == owner:
        return True
    if _is_private(owner.rpartition(".")[2]):
        pkg = _package_of(owner)
        return not pkg or importer == pkg or importer.startswith(pkg + ".")
    pkg = _package_of(owner)
    return bool(pkg) and importer.startswith(pkg + ".")


def private_uses(root: Path = PACKAGE) -> list[tuple[str, str]]:
    """``(importer, "module._name")`` for every use of a private name outside its module.

    Read with :mod:`ast` from every import (``from x import _n``, ``from . import _mod``,
    anywhere, ``TYPE_CHECKING`` included) and every attribute ``x._n`` on a name bound to
    a package module by an import.  Names relative to the package.
    """
    files = {_module_name(p, root): p for p in root.rglob("*.py")}
    found: set[tuple[str, str]] = set()
    for mod, path in files.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        pkg = mod.split(".") if path.name == "__init__.py" else mod.split(".")[:-1]
        if mod == "":
            pkg = []
        bound: dict[str, str] = {}  # local name -> package module
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                if node.level:
                    base = ".".join(
                        pkg[: len(pkg) - node.level + 1] + ([node.module] if node.module else [])
                    )
                elif node.module and (
                    node.module == "sbrdf_xr" or node.module.startswith("sbrdf_xr.")
                ):
                    base = node.module.removeprefix("sbrdf_xr").lstrip(".")
                else:
                    continue
                for a in node.names:
                    sub = f"{base}.{a.name}" if base else a.name
                    if sub in files:  # a module
                        bound[a.asname or a.name] = sub
                        if _is_private(a.name) and not _allowed_private(mod, sub):
                            found.add((mod, sub))
                    elif _is_private(a.name) and not _allowed_private(mod, base):
                        found.add((mod, f"{base}.{a.name}" if base else a.name))
            elif isinstance(node, ast.Import):
                for a in node.names:
                    if a.name.startswith("sbrdf_xr.") and a.asname:
                        bound[a.asname] = a.name.removeprefix("sbrdf_xr.")
        for node in ast.walk(tree):
            if (
                isinstance(node, ast.Attribute)
                and _is_private(node.attr)
                and isinstance(node.value, ast.Name)
                and node.value.id in bound
            ):
                owner = bound[node.value.id]
                if not _allowed_private(mod, owner):
                    found.add((mod, f"{owner}.{node.attr}"))
    return sorted(found)


def _listed(use: tuple[str, str]) -> bool:
    importer, name = use
    return (importer, name) in PRIVATE_USES or (importer, name.rpartition(".")[0]) in PRIVATE_USES


def test_no_module_uses_another_modules_private_names():
    bad = [f"{m or 'sbrdf_xr'} uses {n}" for m, n in private_uses() if not _listed((m, n))]
    assert not bad, (
        "private names used outside their module (make the name public where it is "
        "defined, move it to a private module, or list the use with its reason in "
        "PRIVATE_USES):\n" + "\n".join(bad)
    )


def test_every_listed_private_use_is_still_made():
    made = set(private_uses())
    stale = [
        k
        for k in PRIVATE_USES
        if k not in made and not any(m == k[0] and n.startswith(k[1] + ".") for m, n in made)
    ]
    assert not stale, f"PRIVATE_USES entries no longer needed: {stale}"


def test_the_private_check_catches_imports_and_attributes(tmp_path):
    pkg = tmp_path / "sbrdf_xr"
    (pkg / "photometry").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "_impl.py").write_text("def _helper():\n    pass\n")
    (pkg / "material.py").write_text("from . import _impl\n\ndef _reference():\n    pass\n")
    (pkg / "photometry" / "__init__.py").write_text("")
    (pkg / "photometry" / "spectra.py").write_text("def _choose():\n    pass\n")
    (pkg / "photometry" / "bands.py").write_text("from .spectra import _choose\n")
    (pkg / "models.py").write_text(
        "from . import material\nfrom .material import _reference\n"
        "from ._impl import _helper\n\n"
        "def f():\n    from .photometry.spectra import _choose\n"
        "    return material._impl, _choose\n"
    )
    assert private_uses(pkg) == [
        ("models", "material._impl"),
        ("models", "material._reference"),
        ("models", "photometry.spectra._choose"),
    ]


# ------------------------------------------------------------------ the package graph

#: Bounds of the import graph with each package counted as one node.  The depth is that
#: of the chain cli -> bench -> engine -> store -> materials -> brdf -> geometry -> units
#: -> errors (9).  The edges include one from every package that writes a file
#: (materials, photometry, store, bench, cli) to ``_output``, the one safe output, and
#: one to ``units`` from every package whose public functions take an argument with a
#: unit (converted at the door).  The package's ``__init__`` imports only what it
#: publishes by name; its modules load on first use.  ``bench -> catalog``: the accuracy
#: study against the sky (``bench.starlink``) loads the shipped observations and scan
#: tables by name.  Type-only and function-level imports counted (the store no longer
#: imports the engine, since the scene fingerprint moved there, nor the version).
#: ``lightcurves``, split out of ``photometry`` by job, brings its own edges: down to
#: ``photometry``, ``_names``, ``errors`` and ``units``, and ``cli -> lightcurves`` (the
#: commands that read a measured light curve).  ``bench -> invert``: the spin-search goal
#: row of ``bench --engine`` (:mod:`sbrdf_xr.bench.goals`) times invert's branch-and-bound
#: search against the direct one (both in layer 6, no cycle: invert imports no bench).
GRAPH_LIMITS = {"nodes": 30, "depth": 12, "edges": 119}


def node_of(mod: str, root: Path = PACKAGE) -> str:
    """The node of a module: its top-level package, or the root module itself."""
    top = mod.split(".")[0]
    return top if (root / top).is_dir() else (mod or "sbrdf_xr")


def package_graph(root: Path = PACKAGE) -> dict[str, set[str]]:
    """The import graph with every package collapsed to one node (no self-edges)."""
    out: dict[str, set[str]] = {}
    for mod, deps in import_graph(root).items():
        a = node_of(mod, root)
        out.setdefault(a, set()).update(node_of(d, root) for d in deps)
        out[a].discard(a)
    return out


def graph_measures(graph: dict[str, set[str]]) -> dict[str, int]:
    """Nodes, edges and depth (the longest import chain, in nodes) of an acyclic graph."""

    @cache
    def depth(n: str) -> int:
        return 1 + max((depth(d) for d in graph.get(n, ())), default=0)

    return {
        "nodes": len(graph),
        "edges": sum(len(v) for v in graph.values()),
        "depth": max(map(depth, graph), default=0),
    }


def test_the_package_graph_is_small_and_acyclic():
    graph = package_graph()
    assert not cycles(graph), cycles(graph)
    measures = graph_measures(graph)
    print(
        f"package graph: {measures}, circles: 0, arrows back: {len(against_flow(import_graph()))}"
    )
    over = {k: (v, GRAPH_LIMITS[k]) for k, v in measures.items() if v > GRAPH_LIMITS[k]}
    assert not over, f"package graph over its bounds (value, bound): {over}"


def test_graph_measures_of_a_chain():
    assert graph_measures({"a": {"b"}, "b": {"c"}, "c": set(), "d": {"c"}}) == {
        "nodes": 4,
        "edges": 3,
        "depth": 3,
    }


def _packages(root: Path = PACKAGE) -> list[str]:
    return sorted(p.parent.name for p in root.glob("*/__init__.py"))


@pytest.mark.parametrize("pkg", _packages())
def test_every_package_states_its_job_and_publishes_its_own_names(pkg):
    """A package's ``__init__`` has a docstring and an ``__all__`` whose every name is a
    module of the package or is defined in one of them (not taken from elsewhere), the
    error types of :mod:`sbrdf_xr.errors` that its functions raise excepted."""
    import importlib
    import types

    mod = importlib.import_module(f"sbrdf_xr.{pkg}")
    assert (mod.__doc__ or "").strip(), f"sbrdf_xr.{pkg} has no docstring"
    assert hasattr(mod, "__all__"), f"sbrdf_xr.{pkg} has no __all__"
    foreign = []
    for name in mod.__all__:
        obj = getattr(mod, name)
        if isinstance(obj, types.ModuleType):
            where = obj.__name__
        elif isinstance(obj, (type, types.FunctionType)):
            where = obj.__module__
        else:  # a constant: its object's class says nothing of where it is defined
            continue
        if not where.startswith((f"sbrdf_xr.{pkg}", "sbrdf_xr.errors")):
            foreign.append(f"{name} ({where})")
    assert not foreign, f"sbrdf_xr.{pkg} publishes names defined elsewhere: {foreign}"


def test_the_public_names_are_what_dir_shows():
    import importlib

    import sbrdf_xr

    public = sorted(n for n in dir(sbrdf_xr) if not n.startswith("_"))
    assert public == sorted(n for n in sbrdf_xr.__all__ if not n.startswith("_"))
    for name in sbrdf_xr.__all__:
        assert getattr(sbrdf_xr, name) is not None
    for pkg in _packages():
        assert importlib.import_module(f"sbrdf_xr.{pkg}") is getattr(sbrdf_xr, pkg)


# ------------------------------------------------------------------ a light import

#: Heavy libraries that ``import sbrdf_xr`` leaves for first use.
LOADED_ON_FIRST_USE = (
    "xarray",
    "pandas",
    "numpy",
    "dask",
    "numba",
    "trimesh",
    "netCDF4",
    "scipy",
)


def test_importing_the_package_loads_no_heavy_library_and_registers_the_accessors():
    """``import sbrdf_xr`` in a fresh interpreter: the libraries of
    :data:`LOADED_ON_FIRST_USE` are not loaded, until a name that needs them is used, and
    the ``.sbrdf`` accessors are there as soon as xarray is (tests/test_startup.py
    imports the two in either order)."""
    import json
    import subprocess
    import sys

    code = (
        "import json, sys\n"
        "import sbrdf_xr\n"
        f"heavy = {LOADED_ON_FIRST_USE!r}\n"
        "before = sorted(m for m in heavy if m in sys.modules)\n"
        "import xarray as xr\n"
        "ok = hasattr(xr.Dataset().sbrdf, 'photometry')\n"
        "ok = ok and hasattr(xr.DataArray().sbrdf, 'lookup')\n"
        "sbrdf_xr.Scene\n"
        "after = sorted(m for m in heavy if m in sys.modules)\n"
        "print(json.dumps([before, ok, after, sbrdf_xr.Scene.__module__]))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=600
    )
    before, accessors, after, where = json.loads(out.stdout.splitlines()[-1])
    assert before == []
    assert accessors
    assert "numba" in after and where == "sbrdf_xr.engine.scene"  # served on first use
