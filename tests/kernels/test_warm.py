"""Tests of sbrdf_xr.kernels.warm: the fused kernel compiled ahead, in a second process."""

from __future__ import annotations

import numpy as np
import pytest

from sbrdf_xr.kernels import sums
from sbrdf_xr.kernels.packing import pack_tables
from sbrdf_xr.kernels.warm import compile_ahead, warm_up


@pytest.mark.parametrize("dtype", ["float64", "float32"])
def test_warm_up_compiles_the_signature_of_the_engines_calls(dtype):
    # The engine calls fused_sums with its plan's normal rows and, for a cube with
    # signal_material, per_material=True (a shadowed scene adds a fraction array); each
    # of those calls must find the specialisation warm_up compiled, or the compilation
    # ahead would be wasted and the first run would compile again.
    warm_up(dtype)
    before = set(sums._fused_sums.signatures)
    g = np.array([0.0, 30.0, 60.0, 90.0])
    one = (np.full((4, 4, 4, 5), 0.1), g, g - 45.0, g, (True, False, True))
    tables = pack_tables([one, one, one], dtype=np.dtype(dtype))
    rng = np.random.default_rng(1)
    s, o = rng.normal(size=(50, 3)), rng.normal(size=(50, 3))
    s /= np.linalg.norm(s, axis=1)[:, None]
    o /= np.linalg.norm(o, axis=1)[:, None]
    normals = rng.normal(size=(7, 3))
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    material = np.array([0, 0, 1, 1, 1, 2, 2])
    for kw in (
        {"per_material": True, "rows": sums.normal_rows(normals)},
        {"per_material": False},
        {"method": "cubic", "fraction": rng.uniform(size=(50, 7))},
        {"method": "nearest"},
    ):
        sums.fused_sums(s, o, normals, np.ones(7), material, tables, **kw)
    assert set(sums._fused_sums.signatures) == before


@pytest.mark.slow
def test_compile_ahead_fills_numba_s_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    proc = compile_ahead("float64")
    assert proc is not None and proc.wait(timeout=600) == 0
    assert list(tmp_path.rglob("sums._fused_sums-*.nbi"))


def test_compile_ahead_is_off_without_the_jit(monkeypatch):
    monkeypatch.setenv("NUMBA_DISABLE_JIT", "1")
    assert compile_ahead("float64") is None


def test_compile_ahead_imports_this_package_not_the_working_directorys(tmp_path, monkeypatch):
    # a source checkout in the working directory (the README's main job runs from the
    # clone) must not be what the compiling process imports: its kernels would be cached
    # under another path and compiled a second time by the first simulation
    other = tmp_path / "sbrdf_xr"
    other.mkdir()
    (other / "__init__.py").write_text("raise SystemExit(3)\n")
    monkeypatch.chdir(tmp_path)
    proc = compile_ahead("float64")
    assert proc is not None and proc.wait(timeout=600) == 0
