"""Sizes declared inside files (a few kB of header declaring tens of GiB) are refused by
name before anything is allocated, and ``info`` describes any file without reading data."""

from __future__ import annotations

import netCDF4
import pytest

from sbrdf_xr.cli import main
from sbrdf_xr.errors import ValidationError
from sbrdf_xr.materials.files import open_material


def sparse(path, dims, name, dtype="f8", coords=()):
    """A netCDF file whose header declares ``dims``; no value written (HDF5 allocates none)."""
    with netCDF4.Dataset(path, "w") as nc:
        for d, n in dims.items():
            nc.createDimension(d, n)
        for c in coords:
            nc.createVariable(c, "f8", (c,))
        nc.createVariable(name, dtype, tuple(dims))
    assert path.stat().st_size < 100_000
    return path


def test_a_material_table_declaring_71_gib_is_refused_with_the_estimate(tmp_path):
    path = sparse(tmp_path / "m.nc", {"a": 4, "b": 4, "c": 3, "wavelength": 2 * 10**8}, "sbrdf")
    with pytest.raises(ValidationError, match=r"declares 71\.5 GiB of arrays .*'sbrdf'"):
        open_material(path)


@pytest.mark.parametrize("axis", [True, False], ids=["attitude axis", "no attitude axis"])
@pytest.mark.parametrize("command", ["plot", "photometry"])
def test_a_cube_declaring_1e9_attitudes_is_refused(tmp_path, capsys, axis, command):
    dims = {"attitude": 10**9, "phase_angle": 2, "wavelength": 3}
    coords = ("attitude", "phase_angle", "wavelength") if axis else ("phase_angle", "wavelength")
    cube = sparse(tmp_path / "c.nc", dims, "spacecraft_sbrdf", "f4", coords)
    out = tmp_path / ("c.png" if command == "plot" else "p.nc")
    extra = ["--range-km", "36000"] if command == "photometry" else []
    status = main([command, str(cube), "-o", str(out), *extra])
    err = capsys.readouterr().err
    assert status == 2 and len(err.strip().splitlines()) == 1, err
    if axis or command == "plot":
        assert "GiB once read" in err, err
    assert not out.exists()


def test_info_describes_a_file_without_reading_its_data(tmp_path, capsys):
    path = sparse(
        tmp_path / "m.nc", {"a": 4, "wavelength": 2 * 10**8}, "sbrdf", coords=("wavelength",)
    )
    assert main(["info", str(path)]) == 0
    text = capsys.readouterr().out
    # the 1.6 GB axis is not read to be shown: its values are not in the summary
    assert "wavelength  (wavelength) float64 2GB ..." in text, text


@pytest.mark.parametrize(
    ("reader", "error"),
    [
        ("light curve", "LightCurveError"),
        ("quaternion_series", "AttitudeError"),
        ("spectrum", "InversionError"),
    ],
)
def test_a_measured_file_declaring_a_huge_dimension_is_refused(tmp_path, reader, error):
    """A light curve, a quaternion series and a measured spectrum: a sparse netCDF of a few
    kB declaring 2e9 rows (16 GiB of float64) is refused from its header, naming the
    estimate, with each reader's own error (before: xarray allocated until MemoryError)."""
    from sbrdf_xr import errors
    from sbrdf_xr.invert import read_spectrum
    from sbrdf_xr.lightcurves import read_light_curve
    from sbrdf_xr.observing.series import QuaternionSeries

    read = {
        "light curve": read_light_curve,
        "quaternion_series": QuaternionSeries.from_netcdf,
        "spectrum": read_spectrum,
    }[reader]
    name = {"light curve": "magnitude", "quaternion_series": "quaternion"}.get(reader, "signal")
    path = sparse(tmp_path / "big.nc", {"obs": 2 * 10**9}, name)
    with pytest.raises(getattr(errors, error), match=r"declares 14\.9 GiB of arrays") as info:
        read(path)
    assert str(path) in str(info.value) and reader in str(info.value)


def test_a_fits_light_curve_declaring_1e9_rows_is_refused(tmp_path):
    """A 4-row FITS table whose header is edited to declare 1e9 rows (22.4 GiB): refused
    from its headers (before: astropy allocated 22.4 GiB before finding the file short)."""
    import numpy as np
    from astropy.io import fits

    from sbrdf_xr.errors import LightCurveError
    from sbrdf_xr.lightcurves import read_light_curve

    path = tmp_path / "lc.fits"
    cols = [fits.Column(name=n, format="D", array=np.zeros(4)) for n in ("mjd_utc", "V", "V_err")]
    fits.BinTableHDU.from_columns(cols).writeto(path)
    raw = path.read_bytes()
    at = raw.index(b"NAXIS2  =")
    path.write_bytes(raw[:at] + b"NAXIS2  = %20d" % 10**9 + raw[at + 30 :])
    with pytest.raises(LightCurveError, match=r"declares 22\.4 GiB of data in its FITS headers"):
        read_light_curve(path, system="Vega")


def test_a_votable_light_curve_declaring_1e9_rows_is_refused(tmp_path):
    """A 2-row VOTable whose TABLE says nrows="1000000000": refused from that attribute
    (before: astropy allocated 22.4 GiB for the rows declared)."""
    from astropy.table import Table

    from sbrdf_xr.errors import LightCurveError
    from sbrdf_xr.lightcurves import read_light_curve

    path = tmp_path / "lc.vot"
    table = {"mjd_utc": [60000.0, 60000.1], "V": [10.0, 10.1], "V_err": [0.01, 0.01]}
    Table(table).write(path, format="votable")
    path.write_text(path.read_text().replace("<TABLE", '<TABLE nrows="1000000000"', 1))
    with pytest.raises(LightCurveError, match=r"declares 1000000000 rows of 3 fields .*22\.4 GiB"):
        read_light_curve(path, system="Vega")
    path.write_text(path.read_text().replace('nrows="1000000000"', 'nrows="2"'))
    assert read_light_curve(path, system="Vega").sizes["obs"] == 2  # a true count passes
