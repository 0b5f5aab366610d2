"""Measured data for the inversions: spectra, band magnitudes, per-material band terms."""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np
import xarray as xr

from ..errors import InversionError
from ._spin_search import LN10_2P5

__all__ = ["band_terms", "magnitudes_to_signal", "read_spectrum"]


# ------------------------------------------------------------------------------ measured data


def band_terms(per_material: xr.DataArray, bands: Sequence[str]) -> xr.DataArray:
    """Per-material band signals [m2 sr-1]: the solar-weighted band means of ``signal_material``
    (:func:`sbrdf_xr.photometry.band_weights` normalised), ``wavelength`` replaced by ``band``.

    Examples
    --------
    The grey sides (albedo 0.5 at every wavelength) of a unit cube have the same band
    signal in every band; the red caps (albedo rising with wavelength) are brighter in R:

    >>> import numpy as np, trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft, simulate
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> mesh = trimesh.creation.box()
    >>> caps = np.abs(mesh.face_normals[:, 2]) > 0.5  # the +z and -z faces are red
    >>> mesh.visual.face_colors = np.where(caps[:, None], [255, 0, 0, 255], [128, 128, 128, 255])
    >>> box = load_spacecraft(mesh, {(255, 0, 0): "red", (128, 128, 128): "grey"})
    >>> wl = np.linspace(400.0, 1000.0, 13)
    >>> tables = {"grey": lambertian(0.5, wl, material="grey"),
    ...           "red": lambertian(np.linspace(0.1, 0.8, 13), wl, material="red")}
    >>> sun = [[0.6, 0.0, 0.8], [0.8, 0.0, 0.6]]
    >>> obs = [[0.8, 0.0, 0.6], [0.0, 0.6, 0.8]]
    >>> cube = simulate(Scene(box, tables, to_sun=sun, to_observer=obs,
    ...                       outputs=("signal", "per_material")))
    >>> from sbrdf_xr.invert import band_terms
    >>> bands = band_terms(cube.signal_material, ["V", "R"])
    >>> bands.dims, bands.attrs["units"]
    (('geometry', 'material', 'band'), 'm2 sr-1')
    >>> bands.isel(geometry=0).round(6).values.tolist()
    [[0.076394, 0.076394], [0.042168, 0.061925]]
    """
    from ..photometry import band_weights

    w = band_weights(list(bands), per_material["wavelength"].values, normalize=True)
    out = xr.dot(
        per_material,
        w.rename({"wavelength": "_wl"})
        .assign_coords(_wl=per_material["wavelength"].values)
        .rename({"_wl": "wavelength"}),
        dim="wavelength",
    )
    out.attrs = {"units": "m2 sr-1", "long_name": "band signal of each material"}
    return out


def magnitudes_to_signal(
    light_curve: xr.Dataset, range_km: float
) -> tuple[xr.DataArray, xr.DataArray]:
    """Band signal [m2 sr-1] and its uncertainty from measured magnitudes (one per band).

    Inverts :func:`sbrdf_xr.photometry.magnitudes` at 1 AU:
    ``S = d**2 10**(-0.4 (m - m_sun))``, ``sigma_S = S ln(10)/2.5 sigma_m``.

    Examples
    --------
    V = 8 at 1000 km with the Sun's V = -26.768: ``S = 1e12 * 10**(-0.4 * 34.768)``:

    >>> import xarray as xr
    >>> from sbrdf_xr.invert import magnitudes_to_signal
    >>> mags = xr.Dataset({"magnitude": ("band", [8.0, 7.6]),
    ...                    "uncertainty": ("band", [0.02, 0.02])}, coords={"band": ["V", "R"]})
    >>> signal, sigma = magnitudes_to_signal(mags, range_km=1000.0)
    >>> signal.round(6).values.tolist(), signal.attrs["units"]
    ([0.012381, 0.014961], 'm2 sr-1')
    >>> round(float(sigma[0] / signal[0]), 6)  # ln(10) / 2.5 * 0.02
    0.018421
    """
    from ..photometry import sun_magnitudes

    if not np.isfinite(range_km) or range_km <= 0:
        raise InversionError(f"range_km: must be finite and > 0, got {range_km}")
    bands = [str(b) for b in light_curve["band"].values]
    if len(set(bands)) != len(bands):
        raise InversionError(
            f"magnitudes: one value per band expected (a spectrum in bands), got bands {bands}"
        )
    msun = sun_magnitudes(bands).values
    m = np.asarray(light_curve["magnitude"].values, dtype=np.float64)
    s = (range_km * 1e3) ** 2 * 10 ** (-0.4 * (m - msun))
    sig = s * LN10_2P5 * np.asarray(light_curve["uncertainty"].values, dtype=np.float64)
    coords = {"band": bands}
    return (
        xr.DataArray(
            s, dims="band", coords=coords, attrs={"units": "m2 sr-1", "long_name": "band signal"}
        ),
        xr.DataArray(
            sig,
            dims="band",
            coords=coords,
            attrs={"units": "m2 sr-1", "long_name": "uncertainty of the band signal"},
        ),
    )


def read_spectrum(path: str | os.PathLike[str]) -> tuple[xr.DataArray, xr.DataArray]:
    """A measured spectrum from CSV or netCDF: columns ``wavelength`` [nm], ``signal``
    [m2 sr-1] and ``uncertainty`` (same units, > 0).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.invert import read_spectrum
    >>> rows = "wavelength,signal,uncertainty\\n500,0.10,0.01\\n600,0.12,0.01\\n700,0.11,0.01\\n"
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = Path(tmp) / "spectrum.csv"
    ...     _ = path.write_text(rows)
    ...     signal, sigma = read_spectrum(path)
    >>> signal.dims, signal.wavelength.values.tolist(), signal.values.tolist()
    (('wavelength',), [500.0, 600.0, 700.0], [0.1, 0.12, 0.11])
    >>> sigma.values.tolist()
    [0.01, 0.01, 0.01]
    """
    from pathlib import Path

    import pandas as pd

    path = Path(path)
    if not path.is_file():
        raise InversionError(f"spectrum: file {path} does not exist")
    if path.suffix.lower() in (".nc", ".nc4"):
        with xr.open_dataset(path) as ds:
            df = ds.load().reset_coords().to_dataframe().reset_index()
    else:
        df = pd.read_csv(path, skipinitialspace=True)
        df.columns = [str(c).strip() for c in df.columns]
    missing = [c for c in ("wavelength", "signal", "uncertainty") if c not in df.columns]
    if missing:
        raise InversionError(
            f"{path}: missing columns {missing}; needs wavelength, signal, uncertainty"
        )
    wl = df["wavelength"].to_numpy(dtype=np.float64)
    y = xr.DataArray(
        df["signal"].to_numpy(dtype=np.float64),
        dims="wavelength",
        coords={"wavelength": wl},
        attrs={"units": "m2 sr-1", "long_name": "measured signal"},
    )
    return y, y.copy(data=df["uncertainty"].to_numpy(dtype=np.float64))
