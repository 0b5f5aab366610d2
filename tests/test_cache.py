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
