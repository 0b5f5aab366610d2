"""The benchmarks of sbrdf_xr.bench.suite that time one part of the package."""

from __future__ import annotations

from sbrdf_xr.bench.suite import bench_geometry


def test_bench_geometry_times_the_pass_geometry():
    out = bench_geometry(n_times=120, repeats=1)
    assert out["n_times"] == 120 and out["seconds"] > 0 and out["first_call_seconds"] > 0
    assert out["seconds_per_time"] == out["seconds"] / 120
