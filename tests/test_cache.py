"""The disk cache of catalog tables built on load (sbrdf_xr._cache)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import xarray as xr

from sbrdf_xr import _cache, catalog
from sbrdf_xr.errors import CacheWarning

ROOT = Path(__file__).resolve().parent.parent


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
    from sbrdf_xr.store.fingerprint import _table_sha

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
    model = catalog.load("aluminium-6061-t6-microfacet-fit")
    called: set[str] = set()

    def profile(frame, event, arg):
        if event == "call":
            called.add(frame.f_code.co_filename)

    sys.setprofile(profile)
    threading.setprofile(profile)
    try:
        material.build_lut(meas, material="plain")
        material.build_lut(
            meas, material="filled", model=model, extrapolation="model", below_noise="model"
        )
    finally:
        sys.setprofile(None)
        threading.setprofile(None)
    ran = {Path(f).resolve() for f in called if f.startswith(str(root))}
    assert len(ran) > 5  # the tracing saw the build
    assert ran <= set(_cache.build_modules())
    # ... and the engine is outside the key
    rel = {str(p.relative_to(root)) for p in _cache.build_modules()}
    assert not {n for n in rel if n.startswith(("engine/", "store/", "bench/", "cli/"))}
    assert "kernels/sums.py" not in rel


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
from sbrdf_xr.store.fingerprint import _table_sha
sys.stdin.readline()  # start together
print(_table_sha(catalog.load("example-lobe")))
"""


def test_two_processes_building_one_table_at_once_agree(tmp_path, monkeypatch):
    """Two processes that build the same table into one empty cache at the same time both
    get the table, and the cache holds one complete file and no temporary ones."""
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
    shas = {o.strip() for o, _ in outs}
    assert len(shas) == 1
    assert sorted(p.name for p in tmp_path.iterdir() if p.suffix != ".nc") == []
    assert len(list(tmp_path.glob("example-lobe-*.nc"))) == 1
    from sbrdf_xr.store.fingerprint import _table_sha

    monkeypatch.setenv("SBRDF_XR_CACHE_DIR", str(tmp_path))
    catalog._built_material.cache_clear()
    assert _table_sha(catalog.load("example-lobe")) == shas.pop()  # read from the cache
    catalog._built_material.cache_clear()
