"""Measured BRDFs as laboratories deliver them, read into the package's measurement set.

One entry point, :func:`read_measurements`, dispatches to a registry of readers
(:data:`READERS`, one :class:`Reader` each, chosen by name or by the file's suffix;
:func:`register_reader` adds one from outside the package, as xarray's backends):

``table``
    Long tables, one row a sample: CSV or whitespace text (``.csv``, ``.txt``,
    ``.dat``), ECSV (``.ecsv``, units per column), netCDF (``.nc``; a file that is
    already a measurement set is read as it is).  Angles conventional (incidence and
    scattering zenith and azimuth; which letter is the zenith is stated by the user,
    ``zenith="theta"`` or ``"phi"``, or by a header line such as ``(phi_i, theta_i)
    are the zenith and azimuth angles``) or paper-000 (``theta_i``, ``delta_theta``,
    ``phi``).  A negative scattering zenith with an azimuth is the in-plane scan's
    signed scattering angle (an observer on the source side).  Broadband (one
    wavelength, from ``wavelength=`` or a header ``lambda = 532 nm``) or per
    wavelength (a ``wavelength`` column).  The BRDF's unit from the file (ECSV, a
    header ``brdf [sr-1]``) or given (``units=``, a string or astropy unit); both, and
    different, is an error.
``scan``
    In-plane goniometer scans: columns ``theta_i`` and the signed scattering angle
    ``theta_s`` (positive beyond the normal, on the far side from the source) and
    ``brdf``.

Every reader returns a measurement set
(:func:`~sbrdf_xr.materials.schema.validate_measurements`) with its provenance (file,
reader, conventions) in the attributes; samples at or below ``noise_floor`` [sr-1] are
marked as reference points, and bad input raises a named
:class:`~sbrdf_xr.errors.ValidationError` saying what was received and what is allowed.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .._names import DELTA_THETA, MEASURED, PHI, SAMPLE, THETA_I, WAVELENGTH, attrs
from ..errors import UnitError, ValidationError
from ..geometry import from_conventional
from ..units import to_unit
from .coverage import _at_horizon, snap_angles
from .schema import validate_measurements

__all__ = ["READERS", "Reader", "measurement_set", "read_measurements", "register_reader"]


@dataclass(frozen=True)
class Reader:
    """One reader of measurement files.

    Attributes
    ----------
    name : str
        Its name (``format=`` of :func:`read_measurements`).
    suffixes : tuple of str
        File suffixes it is chosen for (lower case, with the dot).
    read : callable
        ``read(path, **options) -> xarray.Dataset``, a measurement set.
    description : str
        One line for people.

    Examples
    --------
    >>> from sbrdf_xr.materials.readers import READERS
    >>> READERS["table"].suffixes
    ('.csv', '.txt', '.dat', '.ecsv', '.nc')
    """

    name: str
    suffixes: tuple[str, ...]
    read: Callable[..., xr.Dataset]
    description: str


#: Every registered reader, by name.
READERS: dict[str, Reader] = {}


def register_reader(reader: Reader) -> Reader:
    """Add a reader to :data:`READERS` (replacing one of the same name).

    Parameters
    ----------
    reader : Reader
        The reader.

    Returns
    -------
    Reader
        ``reader``.

    Examples
    --------
    >>> from sbrdf_xr.materials.readers import READERS, Reader, register_reader
    >>> r = register_reader(Reader("mine", (".mine",), lambda path: None, "an example"))
    >>> "mine" in READERS
    True
    >>> del READERS["mine"]
    """
    if not isinstance(reader, Reader):
        raise ValidationError(f"reader: expected a Reader, got {type(reader).__name__}")
    READERS[reader.name] = reader
    return reader


def read_measurements(
    path: str | os.PathLike[str], *, format: str | None = None, **options: Any
) -> xr.Dataset:
    """A measurement set from a file, by the reader of its format.

    Parameters
    ----------
    path : str or path-like
        The file.
    format : str, optional
        A reader's name (:data:`READERS`); default: the reader of the file's suffix.
    **options
        The reader's options (for ``table``: ``angles``, ``zenith``, ``columns``,
        ``wavelength`` in nm, ``units``, ``angle_units``, ``noise_floor`` in sr-1,
        ``material``, ``provenance``, ``duplicates``; each reader converts Quantities).

    Returns
    -------
    xarray.Dataset
        A valid measurement set with its provenance.

    Raises
    ------
    ValidationError
        For a missing file, an unknown format, or bad content (named).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from sbrdf_xr.materials import read_measurements
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "scan.csv"
    >>> _ = p.write_text("theta_i,theta_s,brdf\\n30,-10,0.1\\n30,30,2.0\\n30,50,0.2\\n")
    >>> ds = read_measurements(p, format="scan", wavelength=532.0)
    >>> ds.delta_theta.values.tolist(), ds.measured_sbrdf.values.ravel().tolist()
    ([-40.0, 0.0, 20.0], [0.1, 2.0, 0.2])
    """
    path = Path(path)
    if not path.is_file():
        raise ValidationError(f"path: no such file {str(path)!r}")
    if format is None:
        suffix = path.suffix.lower()
        found = [r for r in READERS.values() if suffix in r.suffixes]
        if not found:
            known = sorted({s for r in READERS.values() for s in r.suffixes})
            raise ValidationError(
                f"format: no reader for suffix {suffix!r} of {path.name}; known suffixes: "
                f"{', '.join(known)}; or pass format= one of {', '.join(READERS)}"
            )
        reader = found[0]
    elif format in READERS:
        reader = READERS[format]
    else:
        raise ValidationError(f"format: got {format!r}; allowed: {', '.join(READERS)}")
    return reader.read(path, **options)


def measurement_set(
    theta_i: np.ndarray,
    delta_theta: np.ndarray,
    phi: np.ndarray,
    wavelength: np.ndarray,
    values: np.ndarray,
    *,
    material: str,
    provenance: str,
    noise_floor: float | None = None,
    duplicates: str = "error",
) -> xr.Dataset:
    """A validated measurement set from paper-000 angles and sample spectra.

    Parameters
    ----------
    theta_i, delta_theta, phi : ndarray, shape (s,)
        Angles of the samples [degree] (grouped within 1e-6 degree,
        :func:`~sbrdf_xr.materials.coverage.snap_angles`).
    wavelength : ndarray, shape (n,)
        Wavelengths [nm].
    values : ndarray, shape (s, n)
        sBRDF [sr-1].
    material, provenance : str
        Attributes.
    noise_floor : float, optional
        Samples at or below it [sr-1] (at every wavelength) are reference points, as are
        samples with the observer on the horizon (``theta_i + delta_theta = +-90`` deg in
        the plane), counted in the attribute ``n_horizon`` and said in the provenance.
    duplicates : {"error", "mean"}, default "error"
        As :func:`~sbrdf_xr.materials.schema.validate_measurements`.

    Returns
    -------
    xarray.Dataset

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials.readers import measurement_set
    >>> ds = measurement_set(np.array([30.0, 30.0]), np.array([0.0, 10.0]), np.zeros(2),
    ...                      np.array([550.0]), np.array([[2.0], [1e-4]]), material="m",
    ...                      provenance="doc", noise_floor=1e-4)
    >>> ds.reference.values.tolist()
    [False, True]
    """
    named = ((theta_i, THETA_I), (delta_theta, DELTA_THETA), (phi, PHI))
    ang = [snap_angles(np.asarray(to_unit(a, "deg", n), dtype=np.float64)) for a, n in named]
    v = np.asarray(to_unit(values, "sr-1", "values"), dtype=np.float64)
    wavelength = to_unit(wavelength, "nm", WAVELENGTH, spectral=True)
    if v.shape[0] == 0:
        raise ValidationError(f"measurements: {material!r} is empty (no samples)")
    ref = np.zeros(v.shape[0], dtype=bool)
    if noise_floor is not None:
        ref = np.all(v <= to_unit(noise_floor, "sr-1", "noise_floor"), axis=1)
    horizon = _at_horizon(*ang, known=ref)  # cos(theta_r) = 0: nothing measurable
    ref |= horizon
    if horizon.any():
        provenance += (
            f"; {int(horizon.sum())} samples with the observer on the horizon marked as "
            "reference points"
        )
    ds = xr.Dataset(
        {
            MEASURED: ((SAMPLE, WAVELENGTH), v, attrs(MEASURED)),
            "reference": (SAMPLE, ref, attrs("reference")),
        },
        coords={
            THETA_I: (SAMPLE, ang[0], attrs(THETA_I)),
            DELTA_THETA: (SAMPLE, ang[1], attrs(DELTA_THETA)),
            PHI: (SAMPLE, ang[2], attrs(PHI)),
            WAVELENGTH: (WAVELENGTH, np.asarray(wavelength, dtype=np.float64), attrs(WAVELENGTH)),
        },
        attrs={
            "material": material,
            "source": "measured",
            "provenance": provenance,
            "n_reference": int(ref.sum()),
            "n_horizon": int(horizon.sum()),
        },
    )
    return validate_measurements(ds, duplicates=duplicates)


# ------------------------------------------------------------------ long tables

_ZENITH_LINE = re.compile(r"\((\w+?)_i\s*,\s*(\w+?)_i\)\s*are\s+the\s+zenith\s+and\s+azimuth", re.I)
_LAMBDA_LINE = re.compile(r"(?:lambda|wavelength)\s*=\s*([0-9.eE+-]+)\s*nm", re.I)
_UNIT_IN_NAME = re.compile(r"^\s*([A-Za-z_]\w*)\s*[\[(]\s*([^\])]+?)\s*[\])]\s*$")


def _parse_text(path: Path) -> tuple[list[str], np.ndarray, dict[str, str], list[str]]:
    """Column names, data, units found in the names, and the comment lines of a text table."""
    lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    comments = [ln.lstrip("#").strip() for ln in lines if ln.lstrip().startswith("#")]
    body = [ln for ln in lines if ln.strip() and not ln.lstrip().startswith("#")]
    sep = "," if any("," in ln for ln in body[:5]) else None
    names: list[str] = []
    if body and not _is_numeric(body[0], sep):
        names = [n.strip() for n in (body[0].split(sep) if sep else body[0].split())]
        body = body[1:]
    elif comments:  # the last comment line names the columns
        names = comments[-1].replace(",", " ").split()
    rows = [[x.strip() for x in (ln.split(sep) if sep else ln.split())] for ln in body]
    if not rows:
        raise ValidationError(f"measurements: {path.name} has no data rows (an empty scan)")
    width = len(names) if names else len(rows[0])
    bad = [i for i, r in enumerate(rows) if len(r) != width]
    if bad:
        raise ValidationError(
            f"measurements: {path.name} row {bad[0] + 1} has {len(rows[bad[0]])} values, "
            f"expected {width} (columns {names})"
        )
    try:
        data = np.array(rows, dtype=np.float64)
    except ValueError as exc:
        raise ValidationError(f"measurements: {path.name} has a non-numeric value: {exc}") from exc
    units = {}
    clean = []
    for n in names:
        m = _UNIT_IN_NAME.match(n)
        clean.append(m.group(1) if m else n)
        if m:
            units[m.group(1)] = m.group(2)
    return clean, data, units, comments


def _is_numeric(line: str, sep: str | None) -> bool:
    try:
        [float(x) for x in (line.split(sep) if sep else line.split())]
    except ValueError:
        return False
    return True


def _read_columns(path: Path) -> tuple[dict[str, np.ndarray], dict[str, str], list[str]]:
    """Columns, their units and the header lines of a CSV/text, ECSV or netCDF table."""
    suffix = path.suffix.lower()
    if suffix == ".ecsv":
        from astropy.table import Table

        t = Table.read(path, format="ascii.ecsv")
        cols = {n: np.asarray(t[n], dtype=np.float64) for n in t.colnames}
        units = {n: str(t[n].unit) for n in t.colnames if t[n].unit is not None}
        return cols, units, [str(v) for v in t.meta.get("comments", [])]
    if suffix == ".nc":
        with xr.open_dataset(path) as ds:
            ds = ds.load()
        cols = {n: np.asarray(ds[n].values, dtype=np.float64).ravel() for n in ds.variables}
        units = {n: str(ds[n].attrs["units"]) for n in ds.variables if "units" in ds[n].attrs}
        return cols, units, [f"{k} = {v}" for k, v in ds.attrs.items()]
    names, data, units, comments = _parse_text(path)
    if not names:
        raise ValidationError(f"measurements: {path.name} names no columns (no header line)")
    return {n: data[:, k] for k, n in enumerate(names)}, units, comments


def _column(cols: dict[str, np.ndarray], names: tuple[str, ...], what: str, path: Path):
    for n in names:
        for k in cols:
            if k.lower() == n.lower():
                return k, cols[k]
    raise ValidationError(
        f"measurements: {path.name} lacks the {what} column (tried {', '.join(names)}); "
        f"its columns: {', '.join(cols)}; name them with columns={{...}}"
    )


def _brdf_values(values: np.ndarray, file_unit: str | None, units: Any, path: Path) -> np.ndarray:
    """The BRDF column in sr-1: the file's unit, the declared one, or sr-1."""
    import astropy.units as u

    declared = None if units is None else u.Unit(units)
    found = None
    if file_unit:
        try:
            found = u.Unit(file_unit.replace("sr-1", "1/sr"))
        except ValueError as exc:
            raise UnitError(f"brdf: unit {file_unit!r} of {path.name} is not a unit") from exc
    if declared is not None and found is not None and declared != found:
        raise UnitError(
            f"brdf: {path.name} states the unit {found}, declared {declared}; "
            "allowed: the same unit, or leave units= out"
        )
    unit = found or declared or u.Unit("1/sr")
    try:
        return np.asarray((values * unit).to_value(1 / u.sr), dtype=np.float64)
    except u.UnitConversionError as exc:
        raise UnitError(f"brdf: unit {unit} of {path.name} is not a BRDF unit (sr-1)") from exc


def read_table(
    path: str | os.PathLike[str],
    *,
    angles: str = "auto",
    zenith: str | None = None,
    columns: dict[str, str] | None = None,
    wavelength: Any = None,
    units: Any = None,
    angle_units: str = "degree",
    noise_floor: Any = None,
    material: str | None = None,
    provenance: str = "",
    duplicates: str = "error",
) -> xr.Dataset:
    """A long table (one row a sample) read into a measurement set.

    Parameters
    ----------
    path : str or path-like
        CSV/text, ECSV or netCDF file.
    angles : {"auto", "conventional", "paper"}, default "auto"
        Conventional ``(<z>_i, <a>_i, <z>_o, <a>_o)`` zenith and azimuth angles of the
        source and the observer, or paper-000 ``(theta_i, delta_theta, phi)``; ``auto``
        is ``paper`` when a ``delta_theta`` column exists.
    zenith : {"theta", "phi"}, optional
        Which letter names the zenith angles of conventional columns; default from a
        header line ``(phi_i, theta_i) are the zenith and azimuth angles``, else
        ``theta``.
    columns : dict, optional
        Renames columns of the file to ``theta_i``, ``phi_i``, ``theta_o``, ``phi_o``
        (or ``theta_r``, ``phi_r``), ``delta_theta``, ``phi``, ``wavelength``, ``brdf``.
    wavelength : float or Quantity, optional
        The wavelength of a broadband table [nm]; default a ``wavelength`` column or a
        header ``lambda = 532 nm``.
    units : str or astropy unit, optional
        The BRDF column's unit; default the file's, else sr-1.
    angle_units : str, default "degree"
        Unit of the angle columns (``"degree"`` or ``"rad"``).
    noise_floor : float or Quantity, optional
        Samples at or below it are reference points [sr-1].
    material, provenance : str, optional
        Attributes; default the file's stem and its path.
    duplicates : {"error", "mean"}, default "error"
        Repeated geometries: an error, or averaged.

    Returns
    -------
    xarray.Dataset

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from sbrdf_xr.materials.readers import read_table
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "gonio.csv"
    >>> _ = p.write_text("theta_i,phi_i,theta_r,phi_r,brdf\\n30,0,30,180,3.0\\n30,0,40,180,1.0\\n")
    >>> ds = read_table(p, wavelength=550.0)
    >>> [round(x, 9) for x in ds.delta_theta.values.tolist()]
    [0.0, 10.0]
    """
    path = Path(path)
    if path.suffix.lower() == ".nc":
        with xr.open_dataset(path) as probe:
            is_set = MEASURED in probe
        if is_set:  # already a measurement set
            from .files import open_measurements

            return open_measurements(path)
    cols, file_units, header = _read_columns(path)
    if columns:
        missing = [k for k in columns if k not in cols]
        if missing:
            raise ValidationError(
                f"columns: {missing} not in {path.name}; its columns: {', '.join(cols)}"
            )
        cols = {columns.get(k, k): v for k, v in cols.items()}
        file_units = {columns.get(k, k): v for k, v in file_units.items()}
    if angles == "auto":
        angles = "paper" if any(k.lower() == DELTA_THETA for k in cols) else "conventional"
    if angles not in ("conventional", "paper"):
        raise ValidationError(f"angles: got {angles!r}; allowed: auto, conventional, paper")
    text = " ".join(header)
    if zenith is None:
        m = _ZENITH_LINE.search(text)
        zenith = m.group(1).lower() if m else "theta"
    if zenith not in ("theta", "phi"):
        raise ValidationError(f"zenith: got {zenith!r}; allowed: theta, phi")
    scale = {"degree": 1.0, "deg": 1.0, "rad": 180.0 / np.pi}.get(angle_units)
    if scale is None:
        raise ValidationError(f"angle_units: got {angle_units!r}; allowed: degree, rad")
    bname, brdf = _column(cols, ("brdf", "sbrdf", "measured_sbrdf", "f_r"), "BRDF", path)
    if angles == "paper":
        ang = [_column(cols, (n,), n, path)[1] * scale for n in (THETA_I, DELTA_THETA, PHI)]
        how = "paper-000 angles"
    else:
        az = "theta" if zenith == "phi" else "phi"
        z_i = _column(cols, (f"{zenith}_i",), "incidence zenith", path)[1] * scale
        a_i = _column(cols, (f"{az}_i",), "incidence azimuth", path)[1] * scale
        z_o = _column(cols, (f"{zenith}_o", f"{zenith}_r", f"{zenith}_s"), "zenith", path)[1]
        a_o = _column(cols, (f"{az}_o", f"{az}_r", f"{az}_s"), "scattering azimuth", path)[1]
        _check_zenith(z_i, "incidence", path)
        _check_zenith(np.abs(z_o * scale), "scattering", path)
        ang = list(from_conventional(z_i, a_i, z_o * scale, a_o * scale))
        how = f"conventional angles ({zenith} the zenith)"
    n = brdf.size
    if "wavelength" in {k.lower() for k in cols}:
        wl_col = _column(cols, ("wavelength",), "wavelength", path)[1]
        return _per_wavelength(
            path,
            ang,
            wl_col,
            _brdf_values(brdf, file_units.get(bname), units, path),
            material,
            provenance,
            how,
            noise_floor,
            duplicates,
        )
    if wavelength is None:
        m = _LAMBDA_LINE.search(text)
        if m is None:
            raise ValidationError(
                f"wavelength: {path.name} has no wavelength column nor a header "
                "'lambda = ... nm'; pass wavelength= (a broadband table's wavelength) [nm]"
            )
        wavelength = float(m.group(1))
    wl = np.atleast_1d(np.asarray(to_unit(wavelength, "nm", "wavelength", spectral=True), float))
    values = _brdf_values(brdf, file_units.get(bname), units, path).reshape(n, 1)
    return measurement_set(
        ang[0], ang[1], ang[2], wl, values, material=material or path.stem,
        provenance=provenance or f"{path.name}, read by sbrdf_xr.materials.read_measurements "
        f"(table reader, {how}, {n} rows)",
        noise_floor=noise_floor, duplicates=duplicates,
    )  # fmt: skip


def _check_zenith(z: np.ndarray, what: str, path: Path) -> None:
    bad = ~np.isfinite(z) | (z < 0) | (z > 90)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValidationError(
            f"{what} zenith angles of {path.name}: row {k + 1} has {float(z[k])!r} degree; "
            "allowed: 0 to 90 (or state zenith='theta'/'phi' if the columns are swapped)"
        )


def _per_wavelength(path, ang, wl_col, values, material, provenance, how, floor, duplicates):
    """A table with a wavelength column pivoted to one spectrum per geometry."""
    wl = np.unique(wl_col)
    key = np.stack([snap_angles(a) for a in ang], 1)
    geo, inverse = np.unique(key, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    out = np.full((geo.shape[0], wl.size), np.nan)
    count = np.zeros_like(out)
    col = np.searchsorted(wl, wl_col)
    np.add.at(count, (inverse, col), 1.0)
    out[inverse, col] = values
    if np.any(count == 0):
        g, w = np.argwhere(count == 0)[0]
        raise ValidationError(
            f"measurements: {path.name} lacks {int((count == 0).sum())} (geometry, wavelength) "
            f"values (first: angles {geo[g].round(6).tolist()} deg at {wl[w]:g} nm); every "
            "geometry needs every wavelength"
        )
    if np.any(count > 1):
        g, w = np.argwhere(count > 1)[0]
        raise ValidationError(
            f"measurements: {path.name} repeats the geometry {geo[g].round(6).tolist()} deg at "
            f"{wl[w]:g} nm; allowed: one row per geometry and wavelength"
        )
    return measurement_set(
        geo[:, 0], geo[:, 1], geo[:, 2], wl, out, material=material or path.stem,
        provenance=provenance or f"{path.name}, read by sbrdf_xr.materials.read_measurements "
        f"(table reader, {how}, {wl.size} wavelengths)",
        noise_floor=floor, duplicates=duplicates,
    )  # fmt: skip


def read_scan(
    path: str | os.PathLike[str],
    *,
    wavelength: Any = None,
    units: Any = None,
    noise_floor: Any = None,
    material: str | None = None,
    provenance: str = "",
) -> xr.Dataset:
    """In-plane goniometer scans: columns ``theta_i``, signed ``theta_s`` and ``brdf``.

    ``theta_s`` is the signed scattering angle in the plane of incidence [degree],
    positive on the far side of the normal from the source (the specular ray is at
    ``theta_s = theta_i``), so ``delta_theta = theta_s - theta_i`` and ``phi = 0``.

    Parameters
    ----------
    path : str or path-like
        CSV/text, ECSV or netCDF file.
    wavelength, units, noise_floor, material, provenance
        As :func:`read_table`.

    Returns
    -------
    xarray.Dataset

    Examples
    --------
    See :func:`read_measurements`.
    """
    path = Path(path)
    cols, file_units, header = _read_columns(path)
    ti = _column(cols, (THETA_I,), "incidence angle", path)[1]
    ts = _column(cols, ("theta_s", "theta_o", "theta_r"), "signed scattering angle", path)[1]
    bname, brdf = _column(cols, ("brdf", "sbrdf", "measured_sbrdf"), "BRDF", path)
    _check_zenith(ti, "incidence", path)
    _check_zenith(np.abs(ts), "scattering", path)
    if wavelength is None:
        m = _LAMBDA_LINE.search(" ".join(header))
        if m is None:
            raise ValidationError(f"wavelength: {path.name} states none; pass wavelength= [nm]")
        wavelength = float(m.group(1))
    wl = np.atleast_1d(np.asarray(to_unit(wavelength, "nm", "wavelength", spectral=True), float))
    values = _brdf_values(brdf, file_units.get(bname), units, path).reshape(-1, 1)
    return measurement_set(
        ti, ts - ti, np.zeros_like(ti), wl, values, material=material or path.stem,
        provenance=provenance or f"{path.name}, read by sbrdf_xr.materials.read_measurements "
        f"(in-plane scan reader, {ti.size} samples)",
        noise_floor=noise_floor,
    )  # fmt: skip


register_reader(
    Reader(
        "table",
        (".csv", ".txt", ".dat", ".ecsv", ".nc"),
        read_table,
        "long tables, one row a sample (conventional or paper-000 angles)",
    )
)
register_reader(Reader("scan", (), read_scan, "in-plane scans (signed scattering angle)"))
