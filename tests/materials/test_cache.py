"""The disk cache of catalog tables built on load (sbrdf_xr.materials.cache)."""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest
import xarray as xr

from sbrdf_xr import catalog
from sbrdf_xr.errors import CacheWarning, NonPhysicalWarning
from sbrdf_xr.materials import cache as _cache

ROOT = Path(__file__).resolve().parents[2]


def test_built_tables_are_cached_and_identical(tmp_path, monkeypatch):
    monkeypatch.setenv("SBRDF_XR_CACHE_DIR", str(tmp_path))
    catalog._built_material.cache_clear()
    first = catalog.load("example-lobe")  # builds, writes the cache, reads it back
    files = list(tmp_path.glob("example-lobe-*.nc"))
    assert len(files) == 1
    catalog._built_material.cache_clear()
    again = catalog.load("example-lobe")  # from the cache file
    xr.testing.assert_identical(first, again)
    files[0].write_bytes(b"not netCDF")  # a damaged cache file is built again, with a warning
    catalog._built_material.cache_clear()
    with pytest.warns(CacheWarning, match="could not be read.*building table example-lobe"):
        rebuilt = catalog.load("example-lobe")
    xr.testing.assert_equal(rebuilt, first)
    # ... with the same content fingerprint (the write time in 'history' does not count)
    from sbrdf_xr.engine.fingerprint import _table_sha

    assert _table_sha(rebuilt) == _table_sha(first)
    catalog._built_material.cache_clear()


def test_cache_can_be_switched_off(tmp_path, monkeypatch):
    monkeypatch.setenv("SBRDF_XR_CACHE_DIR", "off")
    assert _cache.cache_dir() is None
    monkeypatch.setenv("SBRDF_XR_CACHE_DIR", str(tmp_path / "c"))
    assert _cache.cache_dir() == tmp_path / "c"
    assert len(_cache.source_digest()) == 64


def test_the_cache_key_covers_every_module_a_build_runs(monkeypatch):
    """The key hashes only the modules that can build a table (so an engine or writer
    change keeps the cache); every package function a build calls must be among them."""
    import sys
    import threading
    from pathlib import Path

    import sbrdf_xr
    from sbrdf_xr.materials import tables as material

    monkeypatch.setenv("SBRDF_XR_CACHE_DIR", "off")
    root = Path(sbrdf_xr.__file__).resolve().parent
    meas = catalog.load("example-lobe-measurements").isel(wavelength=slice(0, 131, 40))
    wl = meas.wavelength.values
    called: set[tuple[str, int]] = set()

    def profile(frame, event, arg):
        if event == "call":
            called.add((frame.f_code.co_filename, frame.f_code.co_firstlineno))

    sys.setprofile(profile)
    threading.setprofile(profile)
    try:
        material.build_lut(meas, material="plain")
        for fit in ("aluminium-6061-t6-microfacet-fit", "tjpv-cell-coated-fit"):  # bare, coated
            model = catalog.load(fit).interp(wavelength=wl)
            with pytest.warns(NonPhysicalWarning):  # another material's model: the self-check
                material.build_lut(
                    meas,
                    material="filled",
                    model=model,
                    extrapolation="model",
                    below_noise="model",
                    theta_i=[0.0, 3.0, 40.0, 89.0],
                )
        # the catalog's own part of a build (the cache is off: no file is read or written)
        e = catalog.entry("example-lobe")
        catalog._built_material.__wrapped__(e.name, e.extra["build_from"], ())
    finally:
        sys.setprofile(None)
        threading.setprofile(None)
    ran = {Path(f).resolve() for f, _ in called if f.startswith(str(root))}
    key = set(_cache.build_modules())
    assert len(ran) > 5  # the tracing saw the build
    assert root / "brdf" / "_fresnel_kernels.py" in ran
    # the cache's own code stores and reads the table; what it stores is the build's
    # (test_built_tables_are_cached_and_identical): it need not be in the key; nor need
    # the mapped tables' test that values were checked already (schema.VALUES_CHECKED),
    # False for every array a build makes: it changes nothing a build computes
    outside = ran - key - {root / "materials" / "cache.py", root / "materials" / "mapped.py"}
    assert outside == {root / "catalog.py"}
    # ... of the catalog, only the definitions hashed in the key ran
    src = (root / "catalog.py").read_text()
    spans = [
        (
            min([node.lineno] + [d.lineno for d in getattr(node, "decorator_list", [])]),
            node.end_lineno,
        )
        for node in ast.parse(src).body
        if any(n in _cache._BUILD_DEFINITIONS["catalog.py"] for n in _defined(node))
    ]
    lines = {line for f, line in called if Path(f).resolve() == root / "catalog.py"}
    assert lines and all(any(a <= x <= b for a, b in spans) for x in lines), (lines, spans)
    # ... and the engine, the catalog's other kinds and the writers are outside the key
    rel = {str(p.relative_to(root)) for p in key}
    for pkg in ("engine/", "store/", "bench/", "cli/", "observing/", "photometry/", "body/"):
        assert not {n for n in rel if n.startswith(pkg)}, pkg
    assert not {"kernels/sums.py", "catalog.py", "__init__.py", "plot.py"} & rel


def _defined(node):
    """The names a top-level statement defines."""
    if isinstance(node, ast.FunctionDef | ast.ClassDef):
        return [node.name]
    targets = getattr(node, "targets", [getattr(node, "target", None)])
    return [t.id for t in targets if isinstance(t, ast.Name)]


def _edited(tmp_path, rel, old, new):
    """The digest of a copy of the package with ``old`` replaced by ``new`` in file ``rel``."""
    import shutil

    import sbrdf_xr

    copy = tmp_path / "pkg"
    if not copy.exists():
        shutil.copytree(
            Path(sbrdf_xr.__file__).parent, copy, ignore=shutil.ignore_patterns("__pycache__")
        )
    path = copy / rel
    text = path.read_text()
    assert text.count(old) >= 1, (rel, old)
    path.write_text(text.replace(old, new, 1))
    try:
        return _cache._digest(copy)
    finally:
        path.write_text(text)


@pytest.mark.parametrize(
    ("rel", "old", "new", "changes"),
    [
        # code that makes the values: a new key
        ("brdf/optics.py", "HC_EV_NM = 1239.8", "HC_EV_NM = 1239.9", True),
        ("brdf/_fresnel_kernels.py", "0.5 * kd[j, w] * qr", "0.5 * qr * kd[j, w]", True),
        ("materials/build.py", "blend: float = 10.0", "blend: float = 11.0", True),
        ("kernels/lut.py", "_MAX_STEP_DEG = 5.0", "_MAX_STEP_DEG = 4.0", True),
        ("_output.py", '"_FillValue": None', '"_FillValue": 0.0', True),
        ("catalog.py", "complevel=0)", "complevel=1)", True),
        ("catalog.py", "_FILE_ATTRS = (", "_FILE_ATTRS = ('x', ", True),
        ("_catalog_index.py", "def ", "def  ", True),
        # code that does not: the same key
        ("observing/orbits.py", "def ", "def  ", False),
        ("photometry/bands.py", "def ", "def  ", False),
        ("body/spacecraft.py", "def ", "def  ", False),
        ("engine/run.py", "def ", "def  ", False),
        ("__init__.py", '"""', '""" ', False),
        ("catalog.py", "def load_spacecraft_spec(", "def  load_spacecraft_spec(", False),
    ],
)
def test_a_change_that_can_change_a_table_changes_the_key(tmp_path, rel, old, new, changes):
    import sbrdf_xr

    assert _cache._digest(Path(sbrdf_xr.__file__).parent) == _cache.source_digest()
    assert (_edited(tmp_path, rel, old, new) != _cache.source_digest()) is changes


def test_an_unusable_cache_directory_builds_the_table_with_a_warning(tmp_path, monkeypatch):
    blocker = tmp_path / "a-file"  # a cache "directory" that is a regular file
    blocker.write_text("x")
    monkeypatch.setenv("SBRDF_XR_CACHE_DIR", str(blocker / "cache"))
    catalog._built_material.cache_clear()
    with pytest.warns(CacheWarning, match="is not usable.*example-lobe.*built but not kept"):
        table = catalog.load("example-lobe")
    catalog._built_material.cache_clear()
    monkeypatch.setenv("SBRDF_XR_CACHE_DIR", "off")
    xr.testing.assert_equal(table, catalog.load("example-lobe"))
    catalog._built_material.cache_clear()


_BUILD = """
import sys
from sbrdf_xr import catalog
from sbrdf_xr.engine.fingerprint import _table_sha
sys.stdin.readline()  # start together
print(_table_sha(catalog.load("example-lobe")))
"""


def test_two_processes_building_one_table_at_once_agree(tmp_path, monkeypatch):
    """Two processes that load the same table from one empty cache at the same time both
    get the table, built once, and the cache holds one complete file and no temporary ones."""
    env = {**os.environ, "SBRDF_XR_CACHE_DIR": str(tmp_path), "PYTHONPATH": str(ROOT)}
    env.pop("SBRDF_XR_CATALOG_PATH", None)
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", _BUILD],
            env=env,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for _ in range(2)
    ]
    outs = [p.communicate("go\n", timeout=300) for p in procs]
    assert [p.returncode for p in procs] == [0, 0], [e for _, e in outs]
    assert not [e for _, e in outs if "CacheWarning" in e]  # neither fell back to uncached
    # one built it (its progress bar), the other waited for the build lock and read the file
    assert sorted("building table example-lobe" in e for _, e in outs) == [False, True]
    shas = {o.strip() for o, _ in outs}
    assert len(shas) == 1
    # beside the table, its memory-mapped values and their record (sbrdf_xr.materials.mapped)
    # and the marker of its last use (cache.prune)
    suffixes = sorted(p.suffix for p in tmp_path.iterdir() if p.suffix != ".nc")
    assert suffixes == [".meta", ".npy", ".used"]
    assert len(list(tmp_path.glob("example-lobe-*.nc"))) == 1
    from sbrdf_xr.engine.fingerprint import _table_sha

    monkeypatch.setenv("SBRDF_XR_CACHE_DIR", str(tmp_path))
    catalog._built_material.cache_clear()
    assert _table_sha(catalog.load("example-lobe")) == shas.pop()  # read from the cache
    catalog._built_material.cache_clear()
