"""The table cache's upkeep: last use recorded on every load, entries listed and pruned
(sbrdf_xr.materials.cache.cache_entries / prune, and the automatic prune of a build)."""

from __future__ import annotations

import os
import threading
import time
from pathlib import Path

import astropy.units as u
import numpy as np
import pytest
import xarray as xr

from sbrdf_xr import catalog
from sbrdf_xr.errors import CacheWarning, TableFileChangedError, UnitError, ValidationError
from sbrdf_xr.materials import cache, constant_material, mapped, tables

DAY = 86400.0


@pytest.fixture
def cache_path(tmp_path, monkeypatch):
    """An empty table cache of its own (the automatic prune at its default)."""
    d = tmp_path / "cache"
    monkeypatch.setenv("SBRDF_XR_CACHE_DIR", str(d))
    monkeypatch.delenv(cache.KEEP_DAYS_ENV, raising=False)
    return d


BUILDS: list[str] = []


def load(name: str, value: float = 0.1, build_wait: threading.Event | None = None):
    """A tiny table through the cache's own path (built on a miss, memory-mapped)."""

    def build() -> xr.DataArray:
        BUILDS.append(name)
        if build_wait is not None:
            assert build_wait.wait(60)
        return constant_material(value, [500.0, 600.0], material=name)

    def write(table: xr.DataArray, path: Path) -> None:
        tables.to_netcdf(table, path, overwrite=True)

    return cache.cached_table(
        name, [], repr(value), build, write, tables.open_material, dtype="float64"
    )


def files_of(name: str, d: Path) -> list[Path]:
    return sorted(d.glob(f"{name}-*"))


def age(paths, days: float) -> None:
    """Set the modification time of ``paths`` to ``days`` ago."""
    t = time.time() - days * DAY
    for p in paths:
        os.utime(p, (t, t))


def test_a_load_from_the_cache_records_its_use_and_touches_no_table_file(cache_path):
    load("grey")
    table = cache.cache_file("grey", [], repr(0.1))
    used = table.with_name(table.name + ".used")
    npy, meta = (table.with_name(f"{table.name}.float64.{s}") for s in ("npy", "meta"))
    assert {p.name for p in files_of("grey", cache_path)} == {
        f.name for f in (table, used, npy, meta)
    }
    age([used], 10.0)
    before = {p: p.stat().st_mtime_ns for p in (table, npy, meta)}
    n = len(BUILDS)
    again = load("grey")  # a hit: read from the cache, not built
    assert len(BUILDS) == n
    assert mapped.mapping_of(again.values) is not None  # still the mapped values file
    assert {p: p.stat().st_mtime_ns for p in (table, npy, meta)} == before
    assert time.time() - used.stat().st_mtime < DAY  # recorded now (10 days ago before)
    (entry,) = cache.cache_entries([table])
    assert entry.name == "grey" and entry.current is True
    assert entry.size == sum(p.stat().st_size for p in (table, used, npy, meta))
    assert entry.last_use >= used.stat().st_mtime  # (or a later access time of a file)


def test_prune_removes_old_entries_whole_and_nothing_else(cache_path, tmp_path):
    old = load("old")
    load("new")
    old_files = files_of("old", cache_path)
    table = old_files[0]
    assert table.name.endswith(".nc") and len(old_files) == 4  # table, values, record, marker
    legacy = cache_path / (table.name + ".float64.meta.nc")  # left by older versions
    stale_part = cache_path / (table.name + ".float64.npy.ab12cd_9.part")
    young_part = cache_path / (table.name + ".float32.npy.zz12cd_9.part")  # being written
    for p in (legacy, stale_part, young_part):
        p.write_bytes(b"x" * 10)
    age([*old_files, legacy, stale_part], 40.0)
    # files the cache did not make: another name, a link to a file elsewhere, a directory
    outside = tmp_path / "precious.nc"
    outside.write_bytes(b"keep")
    foreign = [
        cache_path / "notes.txt",
        cache_path / (table.name + ".backup"),
        cache_path / ("old-" + "0" * 31 + ".nc"),  # 31 digits: no key
    ]
    for p in foreign:
        p.write_bytes(b"mine")
    link = cache_path / ("linked-" + "1" * 32 + ".nc")
    link.symlink_to(outside)
    (cache_path / ("dir-" + "2" * 32 + ".nc")).mkdir()
    age([*foreign, outside], 400.0)
    listing = sorted(os.listdir(cache_path))
    sizes = sum(p.stat().st_size for p in (*old_files, legacy, stale_part))

    dry = cache.prune(older_than=30, dry_run=True)
    assert sorted(os.listdir(cache_path)) == listing  # a dry run removes nothing
    (gone,) = cache.prune(older_than=30)
    assert gone == dry[0]
    assert gone.name == "old" and gone.table == table
    assert set(gone.files) == {*old_files, legacy, stale_part}
    assert gone.size == sizes
    left = set(os.listdir(cache_path))
    assert left == set(listing) - {p.name for p in gone.files}
    assert young_part.name in left  # a write in progress stays
    assert all(p.read_bytes() == b"mine" for p in foreign) and outside.read_bytes() == b"keep"
    # the table the process loaded keeps its values (a mapped file unlinked stays readable)
    assert mapped.mapping_of(old.values) is not None
    np.testing.assert_array_equal(old.values, 0.1)
    # the entries kept still load, from the cache (not built again)
    n = len(BUILDS)
    xr.testing.assert_identical(load("new"), load("new"))
    assert len(BUILDS) == n
    assert cache.prune(older_than=30) == []  # nothing old is left


def test_the_sizes_reported_are_the_files_removed(cache_path):
    load("a")
    files = files_of("a", cache_path)
    sizes = sum(p.stat().st_size for p in files)
    age(files, 2.0)
    assert cache.prune(older_than=3) == []  # used 2 days ago: kept
    (dry,) = cache.prune(older_than=1, dry_run=True)
    assert dry.size == sizes and set(dry.files) == set(files)
    assert all(p.exists() for p in files)
    (gone,) = cache.prune(older_than=24 * u.h)  # a Quantity of time
    assert gone.size == sizes and not any(p.exists() for p in files)


def test_stale_entries_are_those_this_installation_does_not_load(cache_path):
    load("mine")
    load("theirs")
    load("forgotten")
    age(files_of("forgotten", cache_path), 40.0)
    current = [cache.cache_file("mine", [], repr(0.1))]
    entries = cache.cache_entries(current)
    assert [(e.name, e.current) for e in entries] == [
        ("forgotten", False),
        ("mine", True),
        ("theirs", False),
    ]
    # stale and unused for 30 days: another install's recent entry is spared
    assert [e.name for e in cache.prune(30, stale=True, current=current)] == ["forgotten"]
    assert [e.name for e in cache.prune(stale=True, current=current)] == ["theirs"]
    assert [e.name for e in cache.cache_entries()] == ["mine"]
    assert [e.name for e in cache.prune(0)] == ["mine"]  # 0 days: every entry
    assert cache.cache_entries() == []


def test_prune_waits_for_a_build_in_progress(cache_path, monkeypatch):
    """The build lock is held while a table builds: a prune in another thread (another
    open of the directory, so another lock holder) waits, and then keeps the new table."""
    monkeypatch.setenv(cache.KEEP_DAYS_ENV, "off")  # the build itself prunes nothing
    load("old")
    age(files_of("old", cache_path), 40.0)
    release = threading.Event()
    builder = threading.Thread(target=load, args=("building",), kwargs={"build_wait": release})
    builder.start()
    for _ in range(6000):  # until the builder holds the lock and waits in build()
        if "building" in BUILDS or not builder.is_alive():
            break
        time.sleep(0.01)
    assert "building" in BUILDS
    result: list = []
    pruner = threading.Thread(target=lambda: result.extend(cache.prune(older_than=30)))
    pruner.start()
    pruner.join(1.0)
    blocked = pruner.is_alive()
    old_left = files_of("old", cache_path)
    release.set()
    builder.join()
    pruner.join()
    assert blocked and len(old_left) == 4  # nothing removed while the build ran
    assert [e.name for e in result] == ["old"]
    assert len(files_of("building", cache_path)) == 4  # the new table, whole


def test_a_build_prunes_the_entries_no_install_used(cache_path, monkeypatch):
    load("forgotten")
    load("elsewhere")  # another install loads it: only its marker is recent
    age(files_of("forgotten", cache_path), 40.0)
    age(files_of("elsewhere", cache_path), 100.0)
    age(cache_path.glob("elsewhere-*.used"), 1.0)
    (cache_path / "notes.txt").write_bytes(b"mine")
    monkeypatch.setenv(cache.KEEP_DAYS_ENV, "off")
    load("first")  # a build, with the automatic prune off
    assert files_of("forgotten", cache_path)
    n = len(BUILDS)
    monkeypatch.delenv(cache.KEEP_DAYS_ENV)
    load("first")  # a hit: no prune
    assert files_of("forgotten", cache_path) and len(BUILDS) == n
    load("second")  # a build: the entries unused for 30 days go
    assert not files_of("forgotten", cache_path)
    assert len(files_of("elsewhere", cache_path)) == 4
    assert (cache_path / "notes.txt").read_bytes() == b"mine"
    monkeypatch.setenv(cache.KEEP_DAYS_ENV, "0.5")
    load("third")
    assert not files_of("elsewhere", cache_path)  # a day unused is more than half a day
    assert [e.name for e in cache.cache_entries()] == ["first", "second", "third"]


@pytest.mark.parametrize("value", ["0", "-3", "soon", "inf", "nan"])
def test_a_bad_keep_days_warns_and_keeps_the_default(monkeypatch, value):
    monkeypatch.setenv(cache.KEEP_DAYS_ENV, value)
    with pytest.warns(CacheWarning, match=f"{cache.KEEP_DAYS_ENV}: got '{value}'.*'off'"):
        assert cache.keep_days() == cache.KEEP_DAYS


def test_bad_requests_are_refused_with_what_is_allowed(cache_path, monkeypatch):
    with pytest.raises(ValidationError, match=r"older_than: got -1.*>= 0"):
        cache.prune(-1)
    with pytest.raises(ValidationError, match=r"older_than: got 'soon'"):
        cache.prune("soon")
    with pytest.raises(ValidationError, match=r"older_than: got nan"):
        cache.prune(float("nan"))
    with pytest.raises(UnitError, match="older_than"):
        cache.prune(3 * u.kg)
    with pytest.raises(ValidationError, match=r"no entries chosen.*older_than.*stale=True"):
        cache.prune()
    with pytest.raises(ValidationError, match=r"stale=True: give current=.*table_cache_files"):
        cache.prune(stale=True)
    assert cache.prune(1, dry_run=True) == [] and not cache_path.exists()  # nothing made
    monkeypatch.setenv("SBRDF_XR_CACHE_DIR", "off")
    with pytest.raises(ValidationError, match=r"switched off.*SBRDF_XR_CACHE_DIR='off'"):
        cache.prune(30)
    with pytest.raises(ValidationError, match="switched off"):
        cache.cache_entries()


def test_a_dask_worker_whose_table_file_was_pruned_is_told_what_to_do(cache_path):
    values = load("grey").values
    assert mapped.recorded_digest(values) is not None
    cache.prune(0)
    with pytest.raises(TableFileChangedError, match=r"gone.*pruned.*restart the process"):
        mapped.recorded_digest(values)  # checks the file, as a worker that maps it does


def test_the_catalog_tables_are_current_for_this_installation(cache_path):
    """The files table_cache_files() names are the ones loading the catalog makes."""
    catalog._built_material.cache_clear()
    try:
        catalog.load("example-lobe")
    finally:
        catalog._built_material.cache_clear()
    current = catalog.table_cache_files()
    built = {e.name for e in catalog.entries("material") if e.extra.get("build_from")}
    assert {p.name.rsplit("-", 1)[0] for p in current} == built
    assert [(e.name, e.current) for e in cache.cache_entries(current)] == [("example-lobe", True)]
    assert cache.prune(stale=True, current=current) == []


def test_a_load_by_a_version_that_sets_no_marker_counts_by_access_time(cache_path):
    """An older version reads the record and values without setting a marker: the files'
    access times (kept by the file system) are their last use."""
    load("legacy")
    table = cache.cache_file("legacy", [], repr(0.1))
    table.with_name(table.name + ".used").unlink()
    files = files_of("legacy", cache_path)
    now, then = time.time(), time.time() - 40 * DAY
    for p in files:
        os.utime(p, (then, then))
    meta = table.with_name(table.name + ".float64.meta")
    os.utime(meta, (now, then))  # read now, written 40 days ago
    assert cache.prune(30) == []
    os.utime(meta, (then, then))
    assert [e.name for e in cache.prune(30)] == ["legacy"]
