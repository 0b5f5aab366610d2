"""Catalog tables memory-mapped from the table cache (sbrdf_xr.materials.mapped)."""

from __future__ import annotations

import os
import pickle

import cloudpickle
import numpy as np
import pytest
import trimesh
import xarray as xr

from sbrdf_xr import Scene, catalog, geometry, load_spacecraft
from sbrdf_xr.engine.fingerprint import _array_sha_now, _table_sha, scene_fingerprint
from sbrdf_xr.engine.run import run_block
from sbrdf_xr.errors import TableFileChangedError, ValidationError
from sbrdf_xr.materials import mapped, schema
from sbrdf_xr.materials.files import open_material, to_netcdf
from sbrdf_xr.materials.schema import validate_material
from sbrdf_xr.testing import make_material


@pytest.fixture
def table_file(tmp_path):
    """A small table file, as the cache keeps one."""
    return to_netcdf(make_material(n_wavelength=3), tmp_path / "grey.nc")


def test_a_mapped_table_is_the_table_read(table_file):
    table = mapped.mapped_table(table_file, open_material, "float64")
    read = open_material(table_file)
    xr.testing.assert_identical(table, read)
    assert mapped.mapping_of(table.values) is not None  # mapped, not read into memory
    assert not table.values.flags.writeable
    # the same content fingerprint as the table read into memory, without reading it
    assert _table_sha(table) == _table_sha(read)
    assert mapped.recorded_digest(table.values) == _array_sha_now(read.values)
    # a second load maps the same file again (once per process), nothing written anew
    npy = table_file.with_name(table_file.name + ".float64.npy")
    stamp = npy.stat().st_mtime_ns
    again = mapped.mapped_table(table_file, open_material, "float64")
    assert npy.stat().st_mtime_ns == stamp
    address = table.values.__array_interface__["data"][0]
    assert again.values.__array_interface__["data"][0] == address


def test_float32_has_its_own_file(table_file):
    table = mapped.mapped_table(table_file, open_material, "float32")
    assert table.dtype == np.float32
    np.testing.assert_array_equal(table.values, open_material(table_file).values.astype("f4"))
    assert table_file.with_name(table_file.name + ".float32.npy").is_file()


def test_mapped_values_are_not_read_to_validate(table_file):
    table = mapped.mapped_table(table_file, open_material, "float64")
    assert mapped.validated(table.values)
    # validate_material skips reading the values of a mapped table (checked when its file
    # was written): reading them would make every page of it resident in this process
    assert any(checked(table.variable.data) for checked in schema.VALUES_CHECKED)
    copy = table.copy(deep=True)
    assert not any(checked(copy.variable.data) for checked in schema.VALUES_CHECKED)
    copy.values[0, 0, 0, 0] = np.nan
    with pytest.raises(ValidationError, match="NaN"):
        validate_material(copy, check_values=True)
    validate_material(table, check_values=True)


def test_share_and_restore_by_position(table_file):
    values = mapped.mapped_table(table_file, open_material, "float64").values
    for view in (values, values[2:], values.reshape(-1, 3)[5:], values[..., ::2]):
        handle = mapped.share(view)
        assert isinstance(handle, mapped.MappedSlice)
        back = mapped.restore(pickle.loads(pickle.dumps(handle)))
        np.testing.assert_array_equal(back, view)
        assert not back.flags.writeable


def test_a_changed_file_is_named(table_file):
    table = mapped.mapped_table(table_file, open_material, "float64")
    handle = mapped.share(table.values)
    npy = table_file.with_name(table_file.name + ".float64.npy")
    # rewritten with other values (a new file renamed over it, a later modification time)
    other = np.load(npy) * 2.0
    np.save(str(npy) + ".new.npy", other)
    os.replace(str(npy) + ".new.npy", npy)
    st = npy.stat()
    os.utime(npy, ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))
    with pytest.raises(TableFileChangedError, match=r"grey\.nc\.float64\.npy: changed on disk"):
        mapped.recorded_digest(table.values)
    mapped._BY_FILE.clear()  # as a fresh worker process that maps it anew
    with pytest.raises(TableFileChangedError, match="changed on disk"):
        mapped.restore(handle)
    # the same values written again (another process caching the table at once) are fine
    np.save(str(npy) + ".new.npy", other / 2.0)
    os.replace(str(npy) + ".new.npy", npy)
    np.testing.assert_array_equal(mapped.restore(handle), table.values)
    # the table file changed: its values file is made anew from it
    to_netcdf(open_material(table_file) * 0.5, table_file, overwrite=True)
    anew = mapped.mapped_table(table_file, open_material, "float64")
    np.testing.assert_allclose(anew.values, table.values * 0.5, rtol=0, atol=0)


def test_a_read_only_cache_reads_into_memory(table_file, monkeypatch):
    def refuse(*args, **kwargs):
        raise OSError("read-only file system")

    monkeypatch.setattr(mapped, "_write_table", refuse)
    table = mapped.mapped_table(table_file, open_material, "float32")
    assert mapped.mapping_of(table.values) is None and table.dtype == np.float32


@pytest.fixture
def cached_lobe(tmp_path, monkeypatch):
    """The small built catalog table ``example-lobe`` through a cache of its own."""
    monkeypatch.setenv("SBRDF_XR_CACHE_DIR", str(tmp_path))
    catalog._built_material.cache_clear()
    yield catalog.load("example-lobe")
    catalog._built_material.cache_clear()


def test_a_plan_travels_with_handles_not_tables(cached_lobe):
    assert mapped.mapping_of(cached_lobe.values) is not None
    box = load_spacecraft(trimesh.creation.box(), material="lobe")
    scene = Scene(
        box,
        {"lobe": cached_lobe},
        attitudes=geometry.uniform_attitudes(40, seed=1),
        phase_angles=[10.0, 60.0],
    )
    plan = scene.plan()
    assert all(mapped.mapping_of(v) is not None for v in plan.tables.values)
    blob = cloudpickle.dumps(plan)
    # the tables stay behind: the pickle is smaller than their values
    assert len(blob) < sum(v.nbytes for v in plan.tables.values) + 200_000
    assert b"MappedSlice" in blob
    back = cloudpickle.loads(blob)
    got, want = run_block(back, slice(0, 40)), run_block(plan, slice(0, 40))
    for k in want:
        np.testing.assert_array_equal(got[k], want[k])  # the same values, bit for bit
    assert scene_fingerprint(scene)["fingerprint"]  # hashed without reading the values


def test_the_catalog_fingerprint_is_that_of_the_table_read(cached_lobe, tmp_path):
    (nc,) = tmp_path.glob("example-lobe-*.nc")
    in_memory = cached_lobe.copy(deep=True)  # writeable: hashed from its values
    assert _table_sha(in_memory) == _table_sha(cached_lobe)
    assert sorted(p.name.removeprefix(nc.name) for p in tmp_path.glob(nc.name + "*")) == [
        "",
        ".float64.meta",
        ".float64.npy",
        ".used",  # the marker of its last use (cache.prune)
    ]


def _resident(path) -> int:
    """Resident bytes of this process's mappings of ``path`` (``/proc/self/smaps``)."""
    total, inside = 0, False
    with open("/proc/self/smaps", encoding="ascii", errors="replace") as f:
        for line in f:
            head = line.split()
            if head and "-" in head[0] and not head[0].endswith(":"):  # a mapping's header
                inside = len(head) > 5 and head[5] == str(path)
            elif inside and head[0] == "Rss:":
                total += int(head[1]) * 1024
    return total


@pytest.mark.skipif(not os.path.exists("/proc/self/smaps"), reason="Linux's /proc")
def test_compiling_an_evaluator_reads_no_page_of_a_mapped_table(cached_lobe):
    """The evaluator's record of the tables (for ``verify``) is the mapped file's, not a
    sample spread over its values: a sample faults in the pages around every value it
    reads, which made every page of the tables resident in each process and worker."""
    from sbrdf_xr.engine.evaluator import Evaluator

    (npy,) = {mapped.mapping_of(v).path for v in (cached_lobe.values,)}
    box = load_spacecraft(trimesh.creation.box(), material="lobe")
    scene = Scene(box, {"lobe": cached_lobe}, to_sun=[[1.0, 0, 0]], to_observer=[[1.0, 0, 0]])
    plan = scene.plan()
    assert all(mapped.mapping_of(v) is not None for v in plan.tables.values)
    before = _resident(npy)
    ev = Evaluator(plan)
    ev.verify()
    # one geometry reads a few cells; the table is cached_lobe.values.nbytes (42 MB)
    ev([1.0, 0, 0], [1.0, 0, 0])
    assert _resident(npy) - before < 0.05 * cached_lobe.values.nbytes
