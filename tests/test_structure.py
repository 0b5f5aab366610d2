"""The package's imports flow one way.

The modules of ``sbrdf_xr`` stand in layers, lowest first; a module imports only from
its own layer or lower ones, and no set of modules imports itself round (within a
layer either).  Imports are read from the source with :mod:`ast`, at module level and
inside functions alike; only those under ``if TYPE_CHECKING:`` are left out (they do
not run).

* L0, kernels and names: ``_version``, ``_names``, ``errors``, ``rotations``, ``geometry``,
  ``_lut``, ``_kernels`` (with ``_angle_kernels``, its vectorised angle stage, and
  ``_lookup_kernels``, cells, weights and row sums),
  ``sources``, ``brdf`` (and its models), ``imperfections``, ``knobs``,
  ``_catalog_index`` (where the shipped files are; it loads nothing), ``_shadow_kernels``,
  ``_polygon_kernels``, ``_cache`` (tables built on load, cached on disk), ``anisotropy``
  (facet tangents,
  ``psi``) and ``_aniso_kernels`` (the anisotropic look-up).
* L1, the domain: ``material_schema``, ``material_io``, ``construction``, ``model_schema``,
  ``models``, ``material_energy`` (a table's hemispherical reflectance), ``material_build``
  (the construction's front end), ``material``, ``goniometer``, ``mesh_io``,
  ``mesh_repair``, ``spacecraft_facets``, ``spacecraft_plot``, ``spacecraft``,
  ``_visibility_rays`` (the sampled method), ``visibility``,
  ``attitude_frames``, ``attitude_pointing``, ``attitude_tumble``, ``attitude_series``,
  ``attitude``, ``timescales``, ``earth_shadow``, ``orbits``, ``observation``, ``observe``,
  ``photometry`` (and its modules), ``fingerprint``.
* L2: ``catalog`` (knows every kind's loader in L1).
* L3, the scene and its plan: ``effects``, ``plan`` (and its stages ``_plan_stages``,
  ``_plan_tables``), ``sweep``, ``scene_model`` (the :class:`Scene`), ``scene_file``
  (scene files), ``scene_io`` (built-in scenes, and scene files re-exported), ``scene``
  (re-exports both).
* L4, the cube: ``simulate``, ``_writer`` and its parts ``_write_common``, ``_write_layout``,
  ``_write_files``, ``_write_disk``, ``_write_progress``, ``_runners``, ``_lock``.
* L5, users of everything: ``invert`` (and its modules), ``bench_rows`` (the rows,
  their timing and output), ``bench`` and its sweep ``_bench_accuracy``, ``bench_engine``,
  ``shadow_bench``, ``plot``,
  ``accessors``, ``cli`` (the parser and ``main``) and its parts ``_cli_output``,
  ``_cli_commands``, ``_cli_analysis``, ``testing`` and the package's ``__init__``.

A new module must be given a layer here.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "sbrdf_xr"

LAYERS: tuple[tuple[str, ...], ...] = (
    (
        "_version",
        "_names",
        "errors",
        "rotations",
        "geometry",
        "_lut",
        "_kernels",
        "_angle_kernels",
        "_lookup_kernels",
        "_packed_tables",
        "_reference_kernel",
        "sources",
        "brdf",
        "imperfections",
        "knobs",
        "_catalog_index",
        "_shadow_kernels",
        "_polygon_kernels",
        "_cache",
        "anisotropy",
        "_aniso_kernels",
    ),
    (
        "material_schema",
        "material_io",
        "construction",
        "model_schema",
        "models",
        "material_energy",
        "material_build",
        "material",
        "goniometer",
        "mesh_io",
        "mesh_repair",
        "spacecraft_facets",
        "spacecraft_plot",
        "spacecraft",
        "_visibility_rays",
        "visibility",
        "attitude_frames",
        "attitude_pointing",
        "attitude_tumble",
        "attitude_series",
        "attitude",
        "timescales",
        "earth_shadow",
        "orbits",
        "observation",
        "observe",
        "photometry",
        "fingerprint",
    ),
    ("catalog",),
    (
        "effects",
        "plan",
        "_plan_stages",
        "_plan_tables",
        "sweep",
        "scene_model",
        "scene_file",
        "scene_io",
        "scene",
    ),
    (
        "simulate",
        "_writer",
        "_write_common",
        "_write_layout",
        "_write_files",
        "_write_disk",
        "_write_progress",
        "_runners",
        "_lock",
    ),
    (
        "invert",
        "bench_rows",
        "_bench_accuracy",
        "bench",
        "bench_engine",
        "shadow_bench",
        "plot",
        "accessors",
        "_cli_output",
        "_cli_commands",
        "_cli_analysis",
        "cli",
        "testing",
        "",
    ),
)


def _module_name(path: Path, root: Path) -> str:
    parts = path.relative_to(root).with_suffix("").parts
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _type_checking_nodes(tree: ast.AST) -> set[int]:
    """ids of the nodes under ``if TYPE_CHECKING:`` (or ``typing.TYPE_CHECKING``)."""
    skip: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If):
            t = node.test
            name = (
                t.id
                if isinstance(t, ast.Name)
                else t.attr
                if isinstance(t, ast.Attribute)
                else None
            )
            if name == "TYPE_CHECKING":
                for child in node.body:
                    skip.update(id(n) for n in ast.walk(child))
    return skip


def import_graph(root: Path = PACKAGE) -> dict[str, set[str]]:
    """Module -> the package modules it imports (names relative to the package, ``""`` for it)."""
    files = {_module_name(p, root): p for p in root.rglob("*.py")}
    graph: dict[str, set[str]] = {}
    for mod, path in files.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        skip = _type_checking_nodes(tree)
        pkg = mod.split(".") if path.name == "__init__.py" else mod.split(".")[:-1]
        if mod == "":
            pkg = []
        deps: set[str] = set()
        for node in ast.walk(tree):
            if id(node) in skip:
                continue
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
                if t != mod:
                    deps.add(t)
        graph[mod] = deps
    return graph


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


#: A module longer than this is doing more than one job: split it by job.
MAX_MODULE_LINES = 600


def test_no_module_is_over_the_line_limit():
    long = {
        str(p.relative_to(PACKAGE)): n
        for p in sorted(PACKAGE.rglob("*.py"))
        if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_MODULE_LINES
    }
    assert not long, f"modules over {MAX_MODULE_LINES} lines (split them by job): {long}"


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


def test_the_checks_catch_a_catalog_import_in_material(tmp_path):
    """The reading of the imports sees a function-level ``from .catalog import`` in material."""
    import shutil

    copy = tmp_path / "sbrdf_xr"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__", "catalogs"))
    mat = copy / "material.py"
    mat.write_text(
        mat.read_text(encoding="utf-8")
        + "\n\ndef _f():\n    from .catalog import load\n\n    return load\n",
        encoding="utf-8",
    )
    graph = import_graph(copy)
    assert "material (L1) -> catalog (L2)" in against_flow(graph)
    assert any({"material", "catalog"} <= set(c) for c in cycles(graph))


def test_type_checking_imports_are_left_out(tmp_path):
    pkg = tmp_path / "sbrdf_xr"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "errors.py").write_text(
        "from typing import TYPE_CHECKING\n\nif TYPE_CHECKING:\n"
        "    from .catalog import CatalogEntry\n"
    )
    (pkg / "catalog.py").write_text("from .errors import CatalogError\n")
    assert import_graph(pkg) == {"": set(), "errors": set(), "catalog": {"errors"}}


@pytest.mark.parametrize("mod", ["material", "models", "spacecraft", "observe"])
def test_domain_modules_do_not_import_the_catalog(mod):
    assert "catalog" not in import_graph()[mod]


# ----------------------------------------------------------------- private names
#
# A name with a leading underscore is private to where it is defined.  Outside it, a module
# uses (``from x import _n``, or ``x._n`` on an imported module ``x``) only:
#
# * the names of a private module (``_lut``, ``_write_common``, ``brdf._common``, ...),
#   public or not, from its own package: an implementation module has no public face;
# * the private names of a module of a subpackage (``photometry``, ``brdf``, ``invert``)
#   from another module of that subpackage: a subpackage is one unit split into files.
#
# Any other use is listed here, with the reason it stands, or fails the test.

#: (importer, "module._name" or "module") -> why the use stands.
PRIVATE_USES: dict[tuple[str, str], str] = {
    ("anisotropy", "geometry._forward_direction"): (
        "the facet azimuth psi measures from the in-plane forward direction of "
        "facet_angles (paper 000 Fig. 4): one function, so both use one convention"
    ),
}


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
