"""What the command line reads and prints: netCDF files opened with clear errors, and
text made safe for a terminal.

Attributes of files and catalog entries are printed through :func:`escape` (and
:func:`escaped_attrs` for a Dataset or DataArray), so that a terminal escape sequence
stored in a file prints as text instead of acting on the terminal.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..errors import ValidationError

__all__ = ["escape", "escaped_attrs", "load_cube", "open_dataset"]


def escape(text: Any, newlines: bool = False) -> str:
    """``text`` with control and other non-printable characters written as escapes.

    Attributes of files and catalog entries are printed through this, so that a
    terminal escape sequence in a file prints as ``\\x1b[...`` instead of acting on the
    terminal.  Newlines and tabs are kept unless ``newlines`` is true.

    Examples
    --------
    >>> from sbrdf_xr.cli import escape
    >>> print(escape("red " + chr(27) + "[31mtext"))  # the terminal's escape character
    red \\x1b[31mtext
    >>> print(escape("two" + chr(10) + "lines", newlines=True))
    two\\nlines
    """
    keep = "" if newlines else "\n\t"
    return "".join(c if c.isprintable() or c in keep else repr(c)[1:-1] for c in str(text))


def escaped_attrs(obj: Any) -> Any:
    """A shallow copy of a Dataset/DataArray whose attributes (and names) print safely.

    Examples
    --------
    >>> import xarray as xr
    >>> from sbrdf_xr.cli import escaped_attrs
    >>> esc = chr(27)  # the terminal's escape character
    >>> ds = xr.Dataset({"a" + esc: ("x", [1.0, 2.0])}, attrs={"title": esc + "[2Jcube"})
    >>> safe = escaped_attrs(ds)
    >>> print(safe.attrs["title"])
    \\x1b[2Jcube
    >>> print(*safe.data_vars)  # the variable's name too
    a\\x1b
    >>> ds.attrs["title"] == esc + "[2Jcube"  # the original is left as it was
    True
    >>> escaped_attrs([1, 2])  # anything else is returned unchanged
    [1, 2]
    """
    import xarray as xr

    def clean(attrs: dict[Any, Any]) -> dict[str, Any]:
        return {
            escape(k, True): escape(v, True) if isinstance(v, str) else v for k, v in attrs.items()
        }

    if isinstance(obj, xr.Dataset):
        out = obj.copy()
        out.attrs = clean(obj.attrs)
        for name in out.variables:
            out[name].attrs = clean(obj[name].attrs)
        return out.rename({n: escape(n, True) for n in out.variables if escape(n, True) != n})
    if isinstance(obj, xr.DataArray):
        arr = obj.copy()
        arr.attrs = clean(obj.attrs)
        for c in arr.coords:
            arr[c].attrs = clean(obj[c].attrs)
        return arr
    return obj


def open_dataset(path: str | Path, *, describe: bool = False) -> Any:
    """Open a netCDF file (or a Zarr store), turning "not netCDF" into a :class:`ValidationError`.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import xarray as xr
    >>> from sbrdf_xr.cli import open_dataset
    >>> from sbrdf_xr.errors import ValidationError
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     xr.Dataset({"v": ("x", [1.0, 2.0])}).to_netcdf(Path(tmp) / "ok.nc")
    ...     with open_dataset(Path(tmp) / "ok.nc") as ds:
    ...         print(ds.v.values.tolist())
    ...     _ = (Path(tmp) / "notes.nc").write_text("not netCDF")
    ...     try:
    ...         open_dataset(Path(tmp) / "notes.nc")
    ...     except ValidationError as exc:
    ...         print(str(exc).replace(tmp, "TMP"))
    [1.0, 2.0]
    TMP/notes.nc: not a readable netCDF file (unrecognised format)
    >>> open_dataset("no-such-file.nc")
    Traceback (most recent call last):
    ...
    FileNotFoundError: no-such-file.nc: no such file
    """
    p = Path(path)
    if not p.exists():
        raise FileNotFoundError(f"{path}: no such file")
    if not describe:  # the indexes read at opening: their declared size first
        with open_dataset(p, describe=True) as ds:
            axes = {d: ds.variables[d] for d in ds.dims if d in ds.variables}
            _check_declared(p, axes, "its axes")
    import xarray as xr

    # describe: the header only, no index read (a file's size says nothing of its axes')
    kw: dict[str, Any] = {"create_default_indexes": False} if describe else {}
    if p.is_dir() and any((p / m).is_file() for m in (".zgroup", "zarr.json")):
        try:
            return xr.open_zarr(p, **kw)  # a Zarr cube
        except (OSError, ValueError, TypeError, KeyError, RuntimeError) as exc:
            raise ValidationError(
                f"{path}: not a readable Zarr store ({type(exc).__name__}: {exc})"
            ) from None
    if not p.is_file():
        raise ValidationError(f"{path}: not a file")
    try:
        return xr.open_dataset(p, **kw)
    except (OSError, ValueError, TypeError, KeyError, RuntimeError) as exc:
        why = (
            "unrecognised format"
            if "did not find a match" in str(exc)
            else f"{type(exc).__name__}: {exc}"
        )
        raise ValidationError(f"{path}: not a readable netCDF file ({why})") from None


def _check_declared(path: Path, variables: Mapping[Any, Any], what: str) -> None:
    """A ValidationError if ``variables`` (of a file opened lazily) declare more than
    :data:`~sbrdf_xr.materials.files.MAX_FILE_BYTES` once read; nothing is read."""
    from ..materials.files import MAX_FILE_BYTES

    total = sum(int(v.size) * v.dtype.itemsize for v in variables.values())
    if total > MAX_FILE_BYTES:
        big = max(variables, key=lambda k: variables[k].size)
        raise ValidationError(
            f"{path}: {what} declare {total / 2**30:.3g} GiB once read (the largest, "
            f"{escape(str(big), True)!r}, of sizes {dict(variables[big].sizes)}); files of at "
            f"most {MAX_FILE_BYTES / 2**30:.3g} GiB are read"
        )


def load_cube(path: str | Path) -> Any:
    """A loaded simulation cube, or :class:`ValidationError` naming what is missing.

    The command line's loader: the cube is read whole and checked (to open one lazily,
    use :func:`sbrdf_xr.store.open_cube`).

    The variables its writer left out (``brdf``, ``signal`` beside ``signal_material``:
    :mod:`sbrdf_xr.store.derived`) are computed again.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import xarray as xr
    >>> from sbrdf_xr.cli import load_cube
    >>> from sbrdf_xr.errors import ValidationError
    >>> spectra = xr.Dataset({"signal": (("attitude", "wavelength"), [[0.1, 0.2]])},
    ...                      coords={"wavelength": [500.0, 600.0]})
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     spectra.to_netcdf(Path(tmp) / "cube.nc")
    ...     cube = load_cube(Path(tmp) / "cube.nc")  # loaded: usable after the file is gone
    ...     xr.Dataset({"area": ("x", [1.0])}).to_netcdf(Path(tmp) / "area.nc")
    ...     try:
    ...         load_cube(Path(tmp) / "area.nc")
    ...     except ValidationError as exc:
    ...         print(str(exc).split("; ")[-1])
    its variables: area)
    >>> cube.signal.values.tolist()
    [[0.1, 0.2]]
    """
    from ..store.derived import with_derived

    with open_dataset(path) as raw:
        ds = with_derived(raw)  # the variables its writer left out, computed again
        spectral = [
            v for v in ("spacecraft_sbrdf", "signal") if v in ds and "wavelength" in ds[v].dims
        ]
        curve = "brdf" in ds and "attitude" in ds.dims and "phase_angle" in ds.coords
        if not spectral and not curve:
            names = ", ".join(map(str, list(ds.data_vars)[:8])) or "none"
            raise ValidationError(
                f"{path}: not a simulation cube of 'sbrdf-xr simulate' "
                "(it needs 'spacecraft_sbrdf' or 'signal' over wavelength, or 'brdf' over "
                f"attitude; its variables: {escape(names, True)})"
            )
        _check_declared(Path(path), dict(ds.variables), "its variables")
        try:
            return ds.load()
        except (OSError, ValueError, RuntimeError) as exc:
            raise ValidationError(f"{path}: cannot be read ({exc})") from None
