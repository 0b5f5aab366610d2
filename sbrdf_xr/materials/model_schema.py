"""Model materials: the labelled parameter set of an analytic BRDF model, and its file.

A *model material* is an :class:`xarray.Dataset` holding the parameters of one of
the models of :mod:`sbrdf_xr.brdf` over ``wavelength``: each parameter a variable
over ``wavelength`` (scalars broadcast) with the ``units`` and ``long_name`` its
model declares (:class:`sbrdf_xr.brdf.Parameter`), an optional thin-film stack as
``layer_n``, ``layer_k`` ``(layer, wavelength)`` and ``layer_thickness`` ``(layer,)``
[nm], and the attributes ``model``, ``material``, ``source = model:<name>`` and
``provenance``.

* :func:`model_material` - build and validate one;
* :func:`model_parameters` - its model and the keyword arguments of the model's
  functions;
* :func:`to_netcdf`, :func:`open_model` - write and read one (lossless).

Evaluating, rendering, measuring and fitting them is :mod:`sbrdf_xr.materials.models`.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from .. import brdf as _brdf
from .._names import WAVELENGTH, attrs
from ..brdf import Model
from ..errors import ValidationError
from ..units import check_wavelengths, to_unit
from .files import naming_file, read_netcdf, write_netcdf_atomic

__all__ = [
    "ModelParameters",
    "model_material",
    "model_parameters",
    "open_model",
    "to_netcdf",
]


def model_material(
    model: str,
    wavelength: ArrayLike,
    *,
    material: str,
    provenance: str,
    layers: Sequence[tuple[ArrayLike, float]] | None = None,
    **params: ArrayLike,
) -> xr.Dataset:
    """A validated model material.

    Each parameter becomes a variable over ``wavelength`` with the ``units`` and
    ``long_name`` its model declares (:class:`sbrdf_xr.brdf.Parameter`).

    Parameters
    ----------
    model : str
        A name of :data:`sbrdf_xr.brdf.BRDF_MODELS` (case-insensitive).
    wavelength : array_like
        Wavelengths [nm].
    material : str
        Material name.
    provenance : str
        Where the parameters come from.
    layers : sequence of (complex index, thickness [nm]), optional
        Thin-film stack, ambient side first (models with a ``stack``, such as
        ``microfacet``).
    **params
        The model's parameters (:attr:`sbrdf_xr.brdf.Model.parameters`).

    Returns
    -------
    xarray.Dataset

    Raises
    ------
    ValidationError
        Unknown model, parameters missing, unexpected or outside their domains, or
        ``layers`` for a model without a thin-film stack.

    Examples
    --------
    >>> spec = model_material("lambert", [450.0, 650.0], material="grey", provenance="doc",
    ...                       rho=[0.2, 0.4])
    >>> spec.rho.dims, spec.rho.attrs["units"], spec.attrs["source"]
    (('wavelength',), '1', 'model:lambert')
    """
    m = _brdf.get_model(model)
    wl = np.asarray(to_unit(wavelength, "nm", "wavelength", spectral=True), dtype=np.float64)
    check_wavelengths(wl, "wavelength")
    checked = m.check_params(wl, **params)
    data: dict[str, Any] = {k: (WAVELENGTH, v, m.parameter(k).attrs) for k, v in checked.items()}
    if layers:
        data.update(_stack_variables(m, layers, wl))
    ds = xr.Dataset(data, coords={WAVELENGTH: (WAVELENGTH, wl, attrs(WAVELENGTH))})
    ds.attrs = {
        "model": m.name,
        "material": material,
        "source": f"model:{m.name}",
        "provenance": provenance,
        "Conventions": "CF-1.10",
    }
    return ds


def _stack_variables(
    m: Model, layers: Sequence[tuple[ArrayLike, float]], wl: np.ndarray
) -> dict[str, Any]:
    """The ``layer_n``, ``layer_k``, ``layer_thickness`` variables of a thin-film stack."""
    if not m.thin_film:
        with_stack = [k for k, x in _brdf.BRDF_MODELS.items() if x.thin_film]
        raise ValidationError(
            f"layers: only the {' and '.join(with_stack)} model"
            f"{' has' if len(with_stack) == 1 else 's have'} a thin-film stack, not {m.name!r}"
        )
    idx = np.stack([np.broadcast_to(np.asarray(n, np.complex128), wl.shape) for n, _ in layers])
    thick = np.array(
        [float(to_unit(t, "nm", f"layers[{j}] thickness")) for j, (_, t) in enumerate(layers)]
    )
    rows = {"layer_n": idx.real, "layer_k": idx.imag, "layer_thickness": thick[None]}
    out = {}
    for name, v in rows.items():
        p = m.parameter(name)
        checked = np.stack([p.validate(r, r.size) for r in v])
        dims = "layer" if name == "layer_thickness" else ("layer", WAVELENGTH)
        out[name] = (dims, checked.reshape(-1) if dims == "layer" else checked, p.attrs)
    return out


class ModelParameters(NamedTuple):
    """A model material unpacked for the numpy functions of its model.

    Examples
    --------
    >>> spec = model_material("lambert", [550.0], material="grey", provenance="doc", rho=0.5)
    >>> p = model_parameters(spec)
    >>> p.model.name, list(p.params)
    ('lambert', ['rho'])
    """

    #: The model (:class:`sbrdf_xr.brdf.Model`).
    model: Model
    #: Wavelengths [nm].
    wavelength: np.ndarray
    #: Keyword arguments of the model's functions: its parameters (and ``layers``).
    params: dict[str, Any]


def model_parameters(spec: xr.Dataset) -> ModelParameters:
    """The model, wavelengths and keyword arguments of a model material.

    Parameters
    ----------
    spec : xarray.Dataset
        A model material (:func:`model_material`).

    Returns
    -------
    ModelParameters
        ``(model, wavelength, params)``: ``model.brdf(normal, to_sun, to_observer,
        wavelength, **params)`` evaluates the material.

    Raises
    ------
    ValidationError
        Not a model material, or a model that is not registered.

    Examples
    --------
    >>> spec = model_material("lambert", [550.0], material="grey", provenance="doc", rho=0.5)
    >>> m, wl, kw = model_parameters(spec)
    >>> m.name, wl.tolist(), {k: v.tolist() for k, v in kw.items()}
    ('lambert', [550.0], {'rho': [0.5]})
    """
    if not isinstance(spec, xr.Dataset) or "model" not in spec.attrs:
        raise ValidationError("model material: expected a Dataset with a 'model' attribute")
    m = _brdf.get_model(spec.attrs["model"])
    wl = np.asarray(spec[WAVELENGTH].values)
    missing = [k for k in m.param_names if k not in spec]
    if missing:
        raise ValidationError(
            f"model material: model {m.name!r} needs the variables {list(m.param_names)}; "
            f"missing {missing}"
        )
    kw: dict[str, Any] = {k: np.asarray(spec[k].values) for k in m.param_names}
    if "layer_thickness" in spec:
        if not m.thin_film:
            raise ValidationError(
                f"model material: model {m.name!r} has no thin-film stack, but the "
                "material has layer variables"
            )
        idx = np.asarray(spec["layer_n"].values) + 1j * np.asarray(spec["layer_k"].values)
        kw["layers"] = [(idx[j], float(t)) for j, t in enumerate(spec["layer_thickness"].values)]
    return ModelParameters(m, wl, kw)


def to_netcdf(spec: xr.Dataset, path: str | os.PathLike[str], *, overwrite: bool = False) -> Path:
    """Write a model material to netCDF (atomic, lossless).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> spec = model_material("lambert", [550.0], material="grey", provenance="doc", rho=0.5)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     to_netcdf(spec, pathlib.Path(tmp) / "grey.nc").name
    'grey.nc'

    """
    model_parameters(spec)
    return write_netcdf_atomic(spec, path, overwrite=overwrite)


def open_model(path: str | os.PathLike[str]) -> xr.Dataset:
    """Read a model material written by :func:`to_netcdf`.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> spec = model_material("lambert", [550.0], material="grey", provenance="doc", rho=0.5)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     back = open_model(to_netcdf(spec, pathlib.Path(tmp) / "grey.nc"))
    >>> back.rho.attrs["long_name"], float(back.rho[0])
    ('Lambertian albedo', 0.5)
    """
    path, ds = read_netcdf(path, "model material")
    with naming_file(path, "model material"):
        model_parameters(ds)
    return ds
