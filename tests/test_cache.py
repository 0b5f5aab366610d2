"""The disk cache of catalog tables built on load (sbrdf_xr._cache)."""

from __future__ import annotations

import xarray as xr

from sbrdf_xr import _cache, catalog


def test_built_tables_are_cached_and_identical(tmp_path, monkeypatch):
    monkeypatch.setenv("SBRDF_XR_CACHE_DIR", str(tmp_path))
    catalog._built_material.cache_clear()
    first = catalog.load("example-lobe")  # builds, writes the cache, reads it back
    files = list(tmp_path.glob("example-lobe-*.nc"))
    assert len(files) == 1
    catalog._built_material.cache_clear()
    again = catalog.load("example-lobe")  # from the cache file
    xr.testing.assert_identical(first, again)
    files[0].write_bytes(b"not netCDF")  # a damaged cache file is built again
    catalog._built_material.cache_clear()
    rebuilt = catalog.load("example-lobe")
    xr.testing.assert_equal(rebuilt, first)
    # ... with the same content fingerprint (the write time in 'history' does not count)
    from sbrdf_xr.fingerprint import _table_sha

    assert _table_sha(rebuilt) == _table_sha(first)
    catalog._built_material.cache_clear()


def test_cache_can_be_switched_off(tmp_path, monkeypatch):
    monkeypatch.setenv("SBRDF_XR_CACHE_DIR", "off")
    assert _cache.cache_dir() is None
    monkeypatch.setenv("SBRDF_XR_CACHE_DIR", str(tmp_path / "c"))
    assert _cache.cache_dir() == tmp_path / "c"
    assert len(_cache.source_digest()) == 64
