"""Bad material and measurement files: every one ends in a named error that names the file,
or loads with a warning when it is only implausible, and no message shows the file.

Files: netCDF tables, models and measurement sets spoilt in value (scaled, integer, NaN,
negative), coordinate (absurd angles and wavelengths, unsorted, wrong units), structure
(renamed, extra dimension, strings), bytes (empty, truncated, flipped, spliced, junk) and
kind (directory, FIFO, a link to /dev/zero, a dangling link, a secret text file); given
through :func:`sbrdf_xr.materials.files.open_material`, ``open_measurements``,
:func:`sbrdf_xr.materials.models.open_model` and :func:`sbrdf_xr.catalog.load_material_spec`
(what ``[materials]`` and ``--material`` use).
"""

from __future__ import annotations

import numpy as np
import pytest
from bad_input_files import (
    EXPECTED_SPECIAL,
    MATERIAL_SPOILS,
    MEASUREMENT_SPOILS,
    SPECIAL,
    material_dataset,
    special_file,
    spoil,
    spoilt_material,
    spoilt_measurements,
)
from bad_input_tour import run_case, tour_settings, unblock_fifos
from hypothesis import given
from hypothesis import strategies as st

CATEGORY = "material files"


def _open_material(path):
    from sbrdf_xr.materials.files import open_material

    return open_material(path)


def _open_measurements(path):
    from sbrdf_xr.materials.files import open_measurements

    return open_measurements(path)


def _open_model(path):
    from sbrdf_xr.materials.models import open_model

    return open_model(path)


def _load_spec(path):
    from sbrdf_xr.catalog import load_material_spec

    return load_material_spec(path)


READERS = {
    "open_material": _open_material,
    "open_measurements": _open_measurements,
    "open_model": _open_model,
    "load_material_spec": _load_spec,
}


def _table_is_usable(da) -> None:
    """A table that loaded holds finite, non-negative floats on sane axes."""
    import xarray as xr

    if isinstance(da, xr.Dataset):  # a model or a measurement set
        for v in da.data_vars.values():
            if np.issubdtype(v.dtype, np.number):
                assert np.issubdtype(v.dtype, np.floating) or v.dtype == bool, v.dtype
        return
    assert np.issubdtype(da.dtype, np.floating), f"values of dtype {da.dtype}"
    v = np.asarray(da.values)
    assert np.isfinite(v).all() and (v >= 0).all(), "NaN or negative values"
    assert -180 <= float(da.delta_theta.min()) and float(da.delta_theta.max()) <= 180, (
        f"delta_theta {float(da.delta_theta.min())}..{float(da.delta_theta.max())}"
    )
    wl = da.wavelength.values
    assert 10 <= wl.min() and wl.max() <= 1e6, f"wavelengths {wl.min()}..{wl.max()} nm"


#: Scales a coordinate or the values are spoilt by (1 is the value as written).
SCALES = [1e-9, 1e-3, -1.0, 0.0, 1.0, 2.0, 100.0, 1000.0, 1e6, 1e9, float("nan"), float("inf")]


def _wrong_material(kind: str, scale: float) -> bool:
    """Whether a table spoilt so is wrong (acceptance needs a warning)."""
    if kind in ("wrong-units", "renamed-variable", "renamed-dim", "extra-dim", "bad-source"):
        return True
    if kind in ("int-values", "nan-values", "negative-values", "string-values", "unsorted"):
        return True
    if kind == "string-coord":
        return True
    if kind == "wavelength-shift":  # nm added: wrong when it leaves the optical range
        return not np.isfinite(scale) or abs(scale) >= 1e5 or scale <= -450
    if not np.isfinite(scale) or scale <= 0:
        return scale != 1.0
    if kind == "scaled-values":
        return scale > 10.0  # an albedo of 0.3 times 10 reflects more than it receives
    if kind in ("theta_i", "phi"):
        return scale > 1.0  # beyond 90 degree
    if kind == "delta_theta":
        return scale > 1.0  # beyond -180
    if kind == "wavelength":
        return scale > 1e3 or scale < 1e-1  # beyond 1 mm, or below 45 nm
    return False


@tour_settings(60)
@given(
    kind=st.sampled_from(MATERIAL_SPOILS),
    scale=st.sampled_from(SCALES),
    reader=st.sampled_from(["open_material", "load_material_spec"]),
)
def test_spoilt_material_tables(tmp_path, kind, scale, reader):
    path = tmp_path / "table.nc"
    spoilt_material(kind, scale).to_netcdf(path)
    run_case(
        CATEGORY,
        lambda: READERS[reader](path),
        wrong=_wrong_material(kind, scale),
        where=[str(path), "sbrdf", kind, "theta_i", "delta_theta", "phi", "wavelength"],
        check=_table_is_usable,
        label=f"{reader} of a table spoilt by {kind} x {scale}",
    )


@tour_settings(40)
@given(kind=st.sampled_from(MEASUREMENT_SPOILS), scale=st.sampled_from(SCALES))
def test_spoilt_measurement_sets(tmp_path, kind, scale):
    path = tmp_path / "measurements.nc"
    # values of make_measurements are about 0.2 sr-1: a glossy sample may be 100 times
    # that (a mirror through a 1 degree aperture reaches 4e3 sr-1), 1e5 times is not;
    # every incidence at 0 degree (theta_i x 0) is a possible, if odd, set
    ds = spoilt_measurements(kind, scale)
    domain = {"theta_i": (0.0, 89.999), "phi": (0.0, 180.0), "delta_theta": (-180.0, 180.0)}
    if kind in domain:  # an angle is wrong outside its domain only
        lo, hi = domain[kind]
        v = ds[kind].values
        wrong = not (np.isfinite(v).all() and lo <= v.min() and v.max() <= hi)
    else:
        wrong = kind in ("int-values", "nan-values", "negative-values", "drop-variable") or (
            kind == "scaled-values" and not (np.isfinite(scale) and 0 <= scale <= 1e5)
        )
        wrong = wrong or (kind == "wavelength" and not (np.isfinite(scale) and 0.1 <= scale <= 100))
    ds.to_netcdf(path)
    run_case(
        CATEGORY,
        lambda: _open_measurements(path),
        wrong=wrong,
        where=[str(path), "measured_sbrdf", kind],
        check=_table_is_usable,
        label=f"open_measurements of a set spoilt by {kind} x {scale}",
    )


@tour_settings(60)
@given(
    how=st.sampled_from(["truncate", "flip", "splice", "junk"]),
    at=st.floats(0.0, 1.0),
    junk=st.binary(min_size=0, max_size=64),
    reader=st.sampled_from(sorted(READERS)),
    what=st.sampled_from(["table", "measurements", "model"]),
)
def test_spoilt_netcdf_bytes(tmp_path, how, at, junk, reader, what):
    from sbrdf_xr.materials import models

    good = tmp_path / "good.nc"
    if what == "table":
        material_dataset().to_netcdf(good)
    elif what == "measurements":
        spoilt_measurements("scaled-values", 1.0).to_netcdf(good)
    else:
        spec = models.model_material(
            "lambert", [450.0, 550.0], material="m", provenance="tour", rho=0.4
        )
        models.to_netcdf(spec, good, overwrite=True)
    path = tmp_path / "spoilt.nc"
    data = spoil(good.read_bytes(), how, at, junk)
    path.write_bytes(data)
    unchanged = data == good.read_bytes()
    run_case(
        CATEGORY,
        lambda: READERS[reader](path),
        wrong=False,
        where=[str(path)],
        check=_table_is_usable,
        label=f"{reader} of a {what} file, {how} at {at:.3f} ({'unchanged' if unchanged else ''})",
    )


@pytest.mark.parametrize("reader", sorted(READERS))
@pytest.mark.parametrize("kind", SPECIAL)
def test_special_material_files(tmp_path, reader, kind):
    path = special_file(tmp_path, kind, ".nc")
    run_case(
        CATEGORY,
        lambda: READERS[reader](path),
        wrong=True,
        where=[str(path)],
        label=f"{reader} of a {kind}",
        timeout=10,
        unblock=unblock_fifos([path]),
        match=EXPECTED_SPECIAL.get(kind),
    )


@tour_settings(30)
@given(
    rho=st.sampled_from([-0.1, 0.0, 0.5, 1.0, 1.5, 1e6, float("nan")]),
    n_wavelength=st.sampled_from([1, 3, 10**6]),
    wl_scale=st.sampled_from([1.0, 1e-3, 1e6]),
)
def test_spoilt_models_rendered_into_scenes(tmp_path, rho, n_wavelength, wl_scale):
    """A model file whose table would be huge, or whose parameters are absurd."""
    import xarray as xr

    from sbrdf_xr.engine import scene_from_dict

    wl = np.linspace(450.0, 650.0, n_wavelength) * wl_scale
    ds = xr.Dataset(
        {"rho": ("wavelength", np.full(n_wavelength, rho), {"units": "1", "long_name": "albedo"})},
        coords={"wavelength": ("wavelength", wl, {"units": "nm", "long_name": "wavelength"})},
        attrs={"model": "lambert", "material": "m", "source": "model:lambert", "provenance": "t"},
    )
    path = tmp_path / "model.nc"
    ds.to_netcdf(path)
    scene = {
        "spacecraft": "canx1",
        "phase_angles": [10.0],
        "attitude": {"stop": 10},
        "materials": {
            "aluminium-6061-t6": str(path),
            "tjpv-cell": str(path),
            "white-paint-a276": str(path),
        },
    }
    wrong = not (0 <= rho <= 1) or n_wavelength > 10**5 or wl_scale != 1.0
    run_case(
        CATEGORY,
        lambda: scene_from_dict(scene).plan(),
        wrong=wrong,
        where=[str(path), "rho", "wavelength", "size_limit"],
        label=f"model rho={rho}, {n_wavelength} wavelengths x {wl_scale}",
        timeout=60,
    )
