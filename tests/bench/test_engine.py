"""Engine benchmark helpers (sbrdf_xr.bench.engine) that need no sweep."""

from __future__ import annotations

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
