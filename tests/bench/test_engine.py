"""Engine benchmark helpers (sbrdf_xr.bench.engine) that need no sweep."""

from __future__ import annotations

import pytest

from sbrdf_xr.bench import engine


def test_sizes_of_files_and_stores(tmp_path):
    (tmp_path / "a.nc").write_bytes(b"x" * 10)
    store = tmp_path / "c.zarr"
    (store / "v").mkdir(parents=True)
    (store / "v" / "0").write_bytes(b"y" * 7)
    (store / ".zattrs").write_bytes(b"{}")
    assert engine._size(tmp_path / "a.nc") == 10
    assert engine._size(store) == 9


def test_the_private_peak_is_sampled_and_below_the_peak_rss():
    peak = engine._PrivatePeak()
    block = bytearray(64 * 2**20)  # 64 MiB of private memory, touched
    block[::4096] = b"\1" * len(block[::4096])
    private = peak.stop()
    assert private >= 64 * 2**20
    assert private <= engine._peak_rss()  # private pages are a part of the resident ones
    # a private page counts whole in the proportional set size, a shared one in part
    assert 64 * 2**20 <= peak.pss <= engine._peak_rss()


def test_the_write_floor_is_the_slowest_of_kernel_disk_and_shared_cores():
    from sbrdf_xr.bench.machine import DiskCost
    from sbrdf_xr.errors import ValidationError

    disk = DiskCost(2_000_000_000, seconds=1.0, cpu_seconds=0.8)
    # kernel 2 s on 2 cores = 4 s of processor time, + 0.8 s writing: 2.4 s on 2 cores
    assert engine.write_floor(2.0, 4.0, disk, cores=2) == (2.4, 2.4)
    # one core: the sum of both processor times
    assert engine.write_floor(2.0, 4.0, disk, cores=1) == (4.8, 4.8)
    # a slow disk bounds it, a slow kernel too
    assert engine.write_floor(2.0, 4.0, disk._replace(seconds=3.0), cores=2)[0] == 3.0
    assert engine.write_floor(5.0, 4.0, disk, cores=8)[0] == 5.0
    with pytest.raises(ValidationError, match="cores: must be >= 1, got 0"):
        engine.write_floor(2.0, 4.0, disk, cores=0)


def test_the_disk_cost_writes_whole_blocks_and_counts_processor_time(tmp_path):
    from sbrdf_xr.bench.machine import disk_cost

    cost = disk_cost(str(tmp_path), nbytes=2**20 + 1)
    # blocks of min(nbytes, block_bytes) rounded down to float64: two of 1 MiB
    assert cost.nbytes == 2 * 2**20
    assert cost.seconds > 0.0 and cost.cpu_seconds >= 0.0
    assert cost.rate == cost.nbytes / cost.seconds
    assert list(tmp_path.iterdir()) == []  # the probe file is gone
