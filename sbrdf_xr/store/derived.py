"""Cube variables computed from others: written only when asked, computed again on read.

A cube's writer (:func:`sbrdf_xr.store.write`) stores by default only the variables no
other variable of the cube gives, and records in the global attribute
``derived_variables`` how to compute the others; :func:`open_cube` (and
``cube.sbrdf.with_derived()``) puts them back, lazily, so code that reads
``cube.signal`` or ``cube.brdf`` of a written cube keeps working.
``write(cube, path, outputs="all")`` writes them too.

What is derivable, exactly (:data:`DERIVED`):

``brdf``
    The paper's broadband BRDF (paper 000 Eq. 2) is ``spacecraft_sbrdf`` integrated over
    wavelength by the trapezoid rule: the engine computes it so, from the same values.
``signal``
    The radiometric signal is the sum over materials of ``signal_material`` (the same
    facet sums, grouped by material), when the cube holds it (the ``per_material``
    output): equal to rounding (a few units of the last place: the order of the sum
    differs).

Not derivable: ``spacecraft_sbrdf`` (paper 000 Eq. 4 weighs each facet's f_r by
``A cos(theta_r)``, the signal by ``A cos(theta_i) cos(theta_r)``: no variable of the cube
gives one from the other), ``area``, ``signal_material`` and the band signals (they need
the filters); these are always written.

Examples
--------
>>> import numpy as np
>>> import xarray as xr
>>> from sbrdf_xr.store import derived
>>> cube = xr.Dataset(
...     {
...         "spacecraft_sbrdf": (("attitude", "wavelength"), [[1.0, 3.0]], {"units": "sr-1"}),
...         "brdf": ("attitude", [100.0], {"units": "sr-1 nm", "long_name": "broadband BRDF"}),
...     },
...     coords={"wavelength": [500.0, 600.0]},
... )
>>> lean = derived.lean(cube)
>>> list(lean.data_vars), sorted(derived.recorded(lean))
(['spacecraft_sbrdf'], ['brdf'])
>>> back = derived.with_derived(lean)
>>> back.brdf.values.tolist(), back.brdf.attrs["units"]
([200.0], 'sr-1 nm')
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .._names import MATERIAL, WAVELENGTH
from ..errors import ValidationError

__all__ = ["ATTR", "DERIVED", "OUTPUTS", "Derived", "lean", "open_cube", "recorded", "with_derived"]

#: The global attribute that records the variables left out and how to compute them.
ATTR = "derived_variables"
#: What the writers' ``outputs`` takes: the independent variables only, or every one.
OUTPUTS = ("independent", "all")


def _trapezoid(ds: xr.Dataset) -> xr.DataArray:
    """``spacecraft_sbrdf`` integrated over wavelength (trapezoid), in float64."""
    wl = np.asarray(ds[WAVELENGTH].values, dtype=np.float64)
    w = np.zeros(wl.size)
    if wl.size > 1:
        half = np.diff(wl) / 2
        w[:-1] += half
        w[1:] += half
    weights = xr.DataArray(w, dims=(WAVELENGTH,))
    return xr.dot(ds["spacecraft_sbrdf"].astype(np.float64), weights, dim=WAVELENGTH)


def _material_sum(ds: xr.Dataset) -> xr.DataArray:
    """``signal_material`` summed over materials."""
    return ds["signal_material"].sum(MATERIAL)


@dataclass(frozen=True)
class Derived:
    """A cube variable computed from others.

    Attributes
    ----------
    name : str
        The variable.
    needs : tuple of str
        The variables (and coordinates) it is computed from.
    rule : str
        How, in words (recorded in the file).
    compute : callable
        Dataset -> DataArray.

    Examples
    --------
    >>> from sbrdf_xr.store.derived import DERIVED
    >>> DERIVED["signal"].needs, DERIVED["signal"].rule
    (('signal_material',), 'sum over material of signal_material')
    """

    name: str
    needs: tuple[str, ...]
    rule: str
    compute: Callable[[xr.Dataset], xr.DataArray]


#: Every derivable variable, by name.
DERIVED: dict[str, Derived] = {
    d.name: d
    for d in (
        Derived(
            "brdf",
            ("spacecraft_sbrdf", WAVELENGTH),
            "trapezoid integral over wavelength of spacecraft_sbrdf (paper 000 Eq. 2)",
            _trapezoid,
        ),
        Derived(
            "signal", ("signal_material",), "sum over material of signal_material", _material_sum
        ),
    )
}


def lean(ds: xr.Dataset, outputs: str = "independent") -> xr.Dataset:
    """``ds`` without the variables it can compute again (:data:`DERIVED`), which are
    recorded in its attribute ``derived_variables``; ``outputs="all"`` keeps every one.

    Parameters
    ----------
    ds : xarray.Dataset
        A cube.
    outputs : {"independent", "all"}
        What to keep.

    Returns
    -------
    xarray.Dataset

    Raises
    ------
    ValidationError
        ``outputs`` is not one of :data:`OUTPUTS`.

    Examples
    --------
    >>> import xarray as xr
    >>> from sbrdf_xr.store.derived import lean
    >>> cube = xr.Dataset({"signal_material": (("g", "material"), [[1.0, 2.0]]),
    ...                    "signal": ("g", [3.0])})
    >>> list(lean(cube).data_vars), list(lean(cube, "all").data_vars)
    (['signal_material'], ['signal_material', 'signal'])
    >>> lean(cube, "some")
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.ValidationError: outputs: got 'some'; allowed: 'independent' (the \
derived variables computed on read), 'all'
    """
    if outputs not in OUTPUTS:
        raise ValidationError(
            f"outputs: got {outputs!r}; allowed: 'independent' (the derived variables "
            "computed on read), 'all'"
        )
    if outputs == "all":
        return ds
    record = recorded(ds)
    for name, d in DERIVED.items():
        if name in ds.data_vars and all(n in ds.variables for n in d.needs):
            v = ds[name]
            record[name] = {
                "from": list(d.needs),
                "rule": d.rule,
                "dtype": v.dtype.str,
                "attrs": {str(k): _plain(a) for k, a in v.attrs.items()},
            }
    if not record:
        return ds
    out = ds.drop_vars([n for n in record if n in ds.data_vars])
    out.attrs = {**ds.attrs, ATTR: json.dumps(record, sort_keys=True)}
    return out


def _plain(a: Any) -> Any:
    """An attribute value as JSON can hold it."""
    if isinstance(a, np.ndarray):
        return a.tolist()
    if isinstance(a, np.generic):
        return a.item()
    return a


def recorded(ds: xr.Dataset) -> dict[str, dict[str, Any]]:
    """The variables ``ds`` records as left out (name -> how), from ``derived_variables``.

    Examples
    --------
    >>> import xarray as xr
    >>> from sbrdf_xr.store.derived import recorded
    >>> recorded(xr.Dataset())
    {}
    """
    text = ds.attrs.get(ATTR)
    if not text:
        return {}
    try:
        record = json.loads(text)
    except (TypeError, ValueError) as exc:
        raise ValidationError(f"{ATTR}: not readable JSON ({exc})") from None
    if not isinstance(record, dict):
        raise ValidationError(f"{ATTR}: expected an object of variables, got {record!r}")
    return record


def with_derived(ds: xr.Dataset) -> xr.Dataset:
    """``ds`` with the variables it records as left out computed again (lazily when its
    variables are Dask-backed), each with its recorded dtype and attributes.

    Raises
    ------
    ValidationError
        A recorded variable is not one this version can compute, or what it is computed
        from is missing.

    Examples
    --------
    >>> import xarray as xr
    >>> from sbrdf_xr.store.derived import lean, with_derived
    >>> cube = xr.Dataset({"signal_material": (("g", "material"), [[1.0, 2.0]]),
    ...                    "signal": ("g", [3.0], {"units": "m2 sr-1"})})
    >>> back = with_derived(lean(cube))
    >>> back.signal.values.tolist(), back.signal.attrs, "derived_variables" in back.attrs
    ([3.0], {'units': 'm2 sr-1'}, False)
    """
    record = recorded(ds)
    if not record:
        return ds
    out = ds.copy()
    for name, how in record.items():
        d = DERIVED.get(name)
        if d is None:
            raise ValidationError(
                f"{ATTR}: {name!r} cannot be computed here; known: {', '.join(DERIVED)}"
            )
        missing = [n for n in d.needs if n not in ds.variables]
        if missing:
            raise ValidationError(f"{ATTR}: {name!r} needs {missing}, which the cube lacks")
        v = d.compute(ds).astype(np.dtype(how.get("dtype", "f8")))
        v.attrs = dict(how.get("attrs", {}))
        out[name] = v
    out.attrs = {k: a for k, a in ds.attrs.items() if k != ATTR}
    return out


def open_cube(path: str | os.PathLike[str], **kwargs: Any) -> xr.Dataset:
    """A written cube (netCDF or Zarr) opened lazily, its derived variables put back.

    Parameters
    ----------
    path : path-like
        A cube written by :func:`sbrdf_xr.store.write`.
    **kwargs
        Passed to :func:`xarray.open_dataset` (``chunks={}`` by default: Dask arrays over
        the file's chunks, so nothing is read before it is used).

    Returns
    -------
    xarray.Dataset
        The cube as simulated: ``cube.signal``, ``cube.brdf`` as before the write.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft, simulate, write
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> from sbrdf_xr.store import open_cube
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> cube = simulate(Scene(box, {"grey": grey}, attitudes=[[0, 0, 0, 1.0]], phase_angles=[0]))
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = write(cube, Path(tmp) / "cube.nc")
    ...     back = open_cube(path).load()
    >>> sorted(back.data_vars), round(float(back.brdf[0, 0]), 4)
    (['area', 'brdf', 'signal', 'spacecraft_sbrdf'], 31.831)
    """
    p = Path(path)
    kwargs.setdefault("chunks", {})
    if p.is_dir():
        kwargs.setdefault("engine", "zarr")
    return with_derived(xr.open_dataset(p, **kwargs))
