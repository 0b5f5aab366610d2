"""Measured data for the inversions: spectra, band magnitudes, per-material band terms."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from ..errors import InversionError, check_declared_size, renamed_keywords
from ..units import check_plausible, to_unit
from ._spin.data import LN10_2P5

__all__ = ["band_terms", "magnitudes_to_signal", "measured_kind", "read_spectrum"]


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


@renamed_keywords(range_km="range")
def magnitudes_to_signal(
    light_curve: xr.Dataset, range: float, *, system: str | None = None
) -> tuple[xr.DataArray, xr.DataArray]:
    """Band signal [m2 sr-1] and its uncertainty from measured magnitudes (one per band).

    Inverts :func:`sbrdf_xr.photometry.magnitudes` at 1 AU:
    ``S = d**2 10**(-0.4 (m - m_sun))``, ``sigma_S = S ln(10)/2.5 sigma_m``, with the
    Sun's magnitudes ``m_sun`` in the system of the magnitudes: ``system`` (AB or Vega),
    by default the light curve's attribute ``magnitude_system``, AB when it states none
    (recorded in the attribute ``magnitude_system_note``).  The band colours of the signal
    depend on it (the Sun's V - I is 0.73 in Vega, 0.29 in AB).

    Parameters
    ----------
    light_curve : Dataset
        ``magnitude`` and ``uncertainty`` over ``band``.
    range : float
        Observer range [km]; a Quantity is converted.

    Examples
    --------
    V = 8 at 1000 km with the Sun's V = -26.768: ``S = 1e12 * 10**(-0.4 * 34.768)``:

    >>> import xarray as xr
    >>> from sbrdf_xr.invert import magnitudes_to_signal
    >>> mags = xr.Dataset({"magnitude": ("band", [8.0, 7.6]),
    ...                    "uncertainty": ("band", [0.02, 0.02])}, coords={"band": ["V", "R"]})
    >>> signal, sigma = magnitudes_to_signal(mags, range=1000.0)
    >>> signal.round(6).values.tolist(), signal.attrs["units"]
    ([0.012381, 0.014961], 'm2 sr-1')
    >>> round(float(sigma[0] / signal[0]), 6)  # ln(10) / 2.5 * 0.02
    0.018421
    >>> signal.attrs["magnitude_system"], signal.attrs["magnitude_system_note"]
    ('AB', 'the light curve states no magnitude system: AB assumed')
    >>> vega, _ = magnitudes_to_signal(mags.assign_attrs(magnitude_system="Vega"), 1000.0)
    >>> vega.round(6).values.tolist()  # the Sun's V is -26.774 in Vega
    [0.012314, 0.01242]
    """
    from ..photometry import MAGNITUDE_SYSTEMS, sun_magnitudes

    range_km = to_unit(range, "km", "range")
    if not np.isfinite(range_km) or range_km <= 0:
        raise InversionError(f"range: must be finite and > 0, got {range_km}")
    check_plausible(range_km, "range_km", "range")
    bands = [str(b) for b in light_curve["band"].values]
    if len(set(bands)) != len(bands):
        raise InversionError(
            f"magnitudes: one value per band expected (a spectrum in bands), got bands {bands}"
        )
    stated = str(light_curve.attrs.get("magnitude_system", "unstated"))
    given = stated if system is None else str(system)
    known = {k.lower(): k for k in MAGNITUDE_SYSTEMS}
    if given.lower() in known:
        source = "stated by the light curve" if system is None else "the system argument"
        system = known[given.lower()]
        note = f"the Sun's magnitudes in the {system} system ({source})"
    elif system is None and given == "unstated":
        system, note = "AB", "the light curve states no magnitude system: AB assumed"
    else:
        raise InversionError(
            f"magnitudes: system {given!r} unknown; allowed {sorted(MAGNITUDE_SYSTEMS)} (the "
            "system argument or the light curve's attribute magnitude_system)"
        )
    msun = sun_magnitudes(bands, system=system).values
    m = np.asarray(light_curve["magnitude"].values, dtype=np.float64)
    sm = np.asarray(light_curve["uncertainty"].values, dtype=np.float64)
    if not np.all(np.isfinite(m)):
        raise InversionError(
            f"magnitudes: {int((~np.isfinite(m)).sum())} are NaN or infinite (bands "
            f"{[b for b, v in zip(bands, m, strict=True) if not np.isfinite(v)]})"
        )
    if not np.all(np.isfinite(sm) & (sm > 0)):
        raise InversionError(
            f"magnitudes: uncertainties must be finite and > 0 [mag], got {sm.tolist()}"
        )
    s = (range_km * 1e3) ** 2 * 10 ** (-0.4 * (m - msun))
    sig = s * LN10_2P5 * sm
    coords = {"band": bands}
    return (
        xr.DataArray(
            s,
            dims="band",
            coords=coords,
            attrs={
                "units": "m2 sr-1",
                "long_name": "band signal",
                "magnitude_system": system,
                "magnitude_system_note": note,
            },
        ),
        xr.DataArray(
            sig,
            dims="band",
            coords=coords,
            attrs={"units": "m2 sr-1", "long_name": "uncertainty of the band signal"},
        ),
    )


def measured_kind(path: str | os.PathLike[str]) -> str:
    """What a measured file holds: ``"spectrum"`` (a ``wavelength`` column or variable) or
    ``"light curve"`` (band magnitudes: a ``band`` column).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.invert import measured_kind
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     a, b = Path(tmp) / "a.csv", Path(tmp) / "b.csv"
    ...     _ = a.write_text("wavelength,signal,uncertainty\\n500,1,0.1\\n")
    ...     _ = b.write_text("time,band,magnitude,uncertainty\\n0,V,8.0,0.01\\n")
    ...     measured_kind(a), measured_kind(b)
    ('spectrum', 'light curve')
    """
    path = _regular_file(path, "measured")
    if path.suffix.lower() in (".nc", ".nc4"):
        try:
            with xr.open_dataset(path) as ds:
                names = set(map(str, ds.variables))
        except (OSError, ValueError) as exc:
            raise InversionError(
                f"{path}: not a readable netCDF file ({type(exc).__name__})"
            ) from None
    else:
        with open(path, encoding="utf-8", errors="replace") as fh:
            head = ""
            for line in fh:
                if line.strip() and not line.lstrip().startswith("#"):
                    head = line
                    break
        if not head:
            raise InversionError(
                f"{path}: empty; expected a spectrum (a header wavelength,signal,uncertainty "
                "and one row per wavelength) or band magnitudes (time,band,magnitude,uncertainty)"
            )
        names = {c.strip().strip('"').lower() for c in head.split(",")}
    if "wavelength" in names:
        return "spectrum"
    if "band" in names:
        return "light curve"
    raise InversionError(
        f"{path}: neither a spectrum (columns wavelength, signal, uncertainty) nor band "
        "magnitudes (columns time, band, magnitude, uncertainty): no wavelength or band column"
    )


def _regular_file(path: str | os.PathLike[str], what: str) -> Path:
    path = Path(path)
    if not path.exists():
        raise InversionError(f"{what}: file {path} does not exist")
    if not path.is_file():
        raise InversionError(f"{what}: {path} is not a regular file (a directory or a device)")
    return path


def _column(df: Any, name: str, path: Path) -> np.ndarray:
    import pandas as pd

    values = pd.to_numeric(df[name], errors="coerce").to_numpy(dtype=np.float64)
    text = df[name].fillna("nan").astype(str).str.strip()
    bad = np.isnan(values) & ~text.str.lower().isin(["nan", "", "none"]).to_numpy()
    if bad.any():
        rows = np.flatnonzero(bad)
        raise InversionError(
            f"{path}: column {name} has {rows.size} values that are not numbers (data rows "
            f"{', '.join(str(r + 1) for r in rows[:5])}); allowed: decimal numbers"
        )
    return values


def read_spectrum(path: str | os.PathLike[str]) -> tuple[xr.DataArray, xr.DataArray]:
    """A measured spectrum from CSV or netCDF: columns ``wavelength`` [nm], ``signal``
    [m2 sr-1] and ``uncertainty`` (same units, > 0), one row per wavelength.

    Raises
    ------
    InversionError
        A missing, empty or unreadable file, missing columns, values that are not numbers,
        NaN values, wavelengths not > 0 or repeated, uncertainties not > 0: naming the
        file, the column and the rows.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.errors import InversionError
    >>> from sbrdf_xr.invert import read_spectrum
    >>> rows = "wavelength,signal,uncertainty\\n500,0.10,0.01\\n600,0.12,0.01\\n700,0.11,0.01\\n"
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = Path(tmp) / "spectrum.csv"
    ...     _ = path.write_text(rows)
    ...     signal, sigma = read_spectrum(path)
    ...     _ = path.write_text(rows.replace("0.01\\n700", "-0.01\\n700"))
    ...     try:
    ...         read_spectrum(path)
    ...     except InversionError as exc:
    ...         error = str(exc).replace(tmp, "TMP")
    >>> signal.dims, signal.wavelength.values.tolist(), signal.values.tolist()
    (('wavelength',), [500.0, 600.0, 700.0], [0.1, 0.12, 0.11])
    >>> sigma.values.tolist()
    [0.01, 0.01, 0.01]
    >>> print(error)
    TMP/spectrum.csv: uncertainty must be finite and > 0; data rows 2 are not (e.g. -0.01)
    """
    import pandas as pd

    path = _regular_file(path, "spectrum")
    if path.suffix.lower() in (".nc", ".nc4"):
        check_declared_size(path, "spectrum", error=InversionError)
        try:
            with xr.open_dataset(path) as ds:
                df = ds.load().reset_coords().to_dataframe().reset_index()
        except (OSError, ValueError) as exc:
            raise InversionError(
                f"{path}: not a readable netCDF file ({type(exc).__name__})"
            ) from None
    else:
        try:
            df = pd.read_csv(
                path, skipinitialspace=True, comment="#", dtype=str, keep_default_na=False
            )
        except pd.errors.EmptyDataError:
            raise InversionError(
                f"{path}: empty; a spectrum needs a header wavelength,signal,uncertainty and "
                "one row per wavelength"
            ) from None
        except (pd.errors.ParserError, UnicodeDecodeError) as exc:
            raise InversionError(f"{path}: not a CSV table ({type(exc).__name__})") from None
        df.columns = [str(c).strip() for c in df.columns]
    missing = [c for c in ("wavelength", "signal", "uncertainty") if c not in df.columns]
    if missing:
        raise InversionError(
            f"{path}: missing columns {missing}; needs wavelength, signal, uncertainty"
        )
    if len(df) == 0:
        raise InversionError(f"{path}: no rows; a spectrum needs one row per wavelength")
    wl, y, sig = (_column(df, c, path) for c in ("wavelength", "signal", "uncertainty"))
    for name, v in (("wavelength", wl), ("signal", y)):
        bad = ~np.isfinite(v)
        if bad.any():
            raise InversionError(
                f"{path}: column {name} has NaN or infinite values in data rows {_rows(bad)}; "
                "drop those rows"
            )
    checks = (
        ("wavelength", wl, ~(wl > 0), "> 0 [nm]"),
        ("uncertainty", sig, ~(np.isfinite(sig) & (sig > 0)), "finite and > 0"),
    )
    for name, v, bad, allowed in checks:
        if bad.any():
            raise InversionError(
                f"{path}: {name} must be {allowed}; data rows {_rows(bad)} are not "
                f"(e.g. {v[bad][0]:g})"
            )
    uniq, counts = np.unique(wl, return_counts=True)
    if (counts > 1).any():
        raise InversionError(
            f"{path}: wavelengths {uniq[counts > 1][:5].tolist()} appear more than once; give "
            "one row per wavelength"
        )
    order = np.argsort(wl)
    y_da = xr.DataArray(
        y[order],
        dims="wavelength",
        coords={
            "wavelength": ("wavelength", wl[order], {"units": "nm", "long_name": "wavelength"})
        },
        attrs={"units": "m2 sr-1", "long_name": "measured signal"},
    )
    sig_da = y_da.copy(data=sig[order])
    sig_da.attrs = {"units": "m2 sr-1", "long_name": "1-sigma uncertainty of the measured signal"}
    return y_da, sig_da


def _rows(bad: np.ndarray) -> str:
    idx = np.flatnonzero(bad) + 1
    head = ", ".join(str(i) for i in idx[:5])
    return head + (f", ... ({idx.size} in all)" if idx.size > 5 else "")
