"""Cube variables computed from others (sbrdf_xr.store.derived): left out by the writers,
computed again on read."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
import xarray as xr

from sbrdf_xr import Scene, geometry, load_spacecraft, simulate, write
from sbrdf_xr.errors import CubeWriteError, ValidationError
from sbrdf_xr.materials.schema import lambertian
from sbrdf_xr.store import derived, open_cube
from sbrdf_xr.testing import l_shaped_spacecraft, make_material

#: The derived variables equal those the engine computed to rounding: the same sums in
#: another order (signal) or the same trapezoid weights through another einsum (brdf).
#: 1e-12 relative to the largest value is a thousand units of float64's last place.
RTOL = 1e-12


def _two_materials(mesh: trimesh.Trimesh) -> object:
    """``mesh`` with its first half of facets grey and the rest lobe."""
    n = len(mesh.faces)
    colours = np.tile([200, 200, 200, 255], (n, 1))
    colours[n // 2 :] = [100, 100, 100, 255]
    mesh.visual.face_colors = colours
    return load_spacecraft(mesh, {(200, 200, 200): "grey", (100, 100, 100): "lobe"})


def _scene(dtype: str = "float64", shadowing: bool = False) -> Scene:
    """Two materials on a body (with shadowing, a non-convex one), per-material outputs."""
    mesh = l_shaped_spacecraft().mesh.copy() if shadowing else trimesh.creation.box()
    mats = {
        "grey": lambertian(0.5, np.linspace(400.0, 1100.0, 7), material="grey"),
        "lobe": make_material(n_wavelength=7),
    }
    return Scene(
        _two_materials(mesh),
        mats,
        attitudes=geometry.uniform_attitudes(12, seed=5),
        phase_angles=[0.0, 35.0, 120.0],
        outputs=("spacecraft_sbrdf", "signal", "brdf", "area", "per_material"),
        effects=("sunlight", "shadowing") if shadowing else ("sunlight",),
        dtype=dtype,
    )


def _close(a: xr.DataArray, b: xr.DataArray, rtol: float = RTOL) -> None:
    scale = float(np.max(np.abs(a.values))) or 1.0
    assert a.dtype == b.dtype and a.dims == b.dims and a.attrs == b.attrs
    np.testing.assert_allclose(a.values, b.values, rtol=0, atol=rtol * scale)


@pytest.mark.parametrize("shadowing", [False, True])
def test_derived_values_equal_those_written_before(tmp_path, shadowing):
    cube = simulate(_scene(shadowing=shadowing))
    for name in ("cube.nc", "cube.zarr"):
        path = write(cube, tmp_path / name)
        with xr.open_dataset(path, engine="zarr" if name.endswith("zarr") else None) as raw:
            assert sorted(raw.data_vars) == ["area", "signal_material", "spacecraft_sbrdf"]
            assert sorted(derived.recorded(raw)) == ["brdf", "signal"]
        back = open_cube(path).load()
        assert sorted(back.data_vars) == sorted(cube.data_vars)
        for v in ("signal", "brdf"):
            _close(cube[v], back[v])
        assert "derived_variables" not in back.attrs
        # every variable, written when asked: the same values, bit for bit
        full = write(cube, tmp_path / f"all-{name}", outputs="all")
        with open_cube(full) as every:
            assert "derived_variables" not in every.attrs
            xr.testing.assert_identical(every.load(), cube)


def test_float32_cubes_derive_in_their_precision(tmp_path):
    cube = simulate(_scene("float32"))
    back = open_cube(write(cube, tmp_path / "cube.nc")).load()
    # float32 sums in another order: a few units of float32's last place (6e-8)
    for v in ("signal", "brdf"):
        _close(cube[v], back[v], rtol=1e-6)


def test_without_per_material_signal_is_written(tmp_path):
    box = load_spacecraft(trimesh.creation.box(), material="grey")
    grey = lambertian(0.5, np.linspace(400.0, 1100.0, 8), material="grey")
    cube = simulate(Scene(box, {"grey": grey}, attitudes=[[0, 0, 0, 1.0]], phase_angles=[0, 60]))
    with xr.open_dataset(write(cube, tmp_path / "cube.nc")) as raw:
        # spacecraft_sbrdf (Eq. 4, A cos(theta_r) weights) and signal (A cos(theta_i)
        # cos(theta_r) weights) are independent: both written
        assert sorted(raw.data_vars) == ["area", "signal", "spacecraft_sbrdf"]
        # the accessor computes the rest on an xarray-opened cube
        _close(raw.sbrdf.with_derived().brdf.load(), cube.brdf)
        band = raw.sbrdf.band_signal(["V"])
        assert band.dims == ("attitude", "phase_angle", "band")


def test_lazy_cubes_are_written_lean(tmp_path):
    scene = _scene()
    cube = simulate(scene, chunk=7)
    back = open_cube(write(cube, tmp_path / "cube.nc"))
    assert back.signal.chunks is not None  # computed on read, lazily
    _close(simulate(scene).signal, back.signal.load())


def test_bad_records_and_options_are_named(tmp_path):
    cube = simulate(_scene())
    with pytest.raises(ValidationError, match="outputs: got 'lean'; allowed"):
        write(cube, tmp_path / "cube.nc", outputs="lean")
    bad = derived.lean(cube).drop_vars("signal_material")
    with pytest.raises(ValidationError, match="'signal' needs \\['signal_material'\\]"):
        derived.with_derived(bad)
    bad.attrs["derived_variables"] = '{"colour": {}}'
    with pytest.raises(ValidationError, match="'colour' cannot be computed here"):
        derived.with_derived(bad)
    bad.attrs["derived_variables"] = "{not json"
    with pytest.raises(ValidationError, match="not readable JSON"):
        derived.with_derived(bad)


class _Stop(Exception):
    """Raised after the first stored block: a write cut short, its ``.part`` kept."""


def _cut_after_one_block(event: object) -> None:
    raise _Stop


@pytest.mark.parametrize("name", ["cube.nc", "cube.zarr"])
def test_a_part_begun_with_every_variable_resumes_with_them(tmp_path, name):
    """A ``.part`` started with ``outputs="all"`` (or by a version that wrote every
    variable) resumes with every variable when ``outputs`` is not given; another
    ``outputs`` is refused, naming the one to resume with."""
    scene = _scene()
    path = tmp_path / name
    with pytest.raises(Exception) as info:  # the writer wraps what stopped it
        write(simulate(scene, chunk=4), path, outputs="all", on_block=_cut_after_one_block)
    assert isinstance(info.value, _Stop) or isinstance(info.value.__cause__, _Stop)
    assert not path.exists() and path.with_name(name + ".part").exists()
    with pytest.raises(CubeWriteError, match=r"started with outputs='all'.*outputs='all'"):
        write(simulate(scene, chunk=4), path, outputs="independent", resume=True)
    write(simulate(scene, chunk=4), path, resume=True)
    opened = xr.open_zarr(path) if name.endswith(".zarr") else xr.open_dataset(path)
    with opened as back:
        assert {"signal", "brdf", "signal_material"} <= set(back.data_vars)
        _close(simulate(scene).signal, back.signal.load())


@pytest.mark.parametrize("name", ["cube.nc", "cube.zarr"])
def test_a_part_begun_with_other_block_sizes_resumes_with_them(tmp_path, name):
    """A ``.part`` begun with other blocks (an older default ``block_bytes``) is finished
    with its own: the resumed cube is rechunked to them, and equals one written whole."""
    scene = _scene()
    path = tmp_path / name
    with pytest.raises(Exception):  # noqa: B017 - the writer wraps what stopped it
        write(simulate(scene, chunk=4), path, on_block=_cut_after_one_block)
    write(simulate(scene, chunk=7), path, resume=True)
    opened = xr.open_zarr(path) if name.endswith(".zarr") else xr.open_dataset(path)
    with opened as back:
        _close(simulate(scene).signal_material, back.signal_material.load())
        if name.endswith(".zarr"):
            assert back.signal_material.encoding["chunks"][0] == 4  # the .part's blocks
