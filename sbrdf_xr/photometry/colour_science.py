"""colour-science spectra in and out: ``SpectralDistribution`` and ``MultiSpectralDistributions``.

Wherever the photometry takes a filter (``bands=``), a solar spectrum (``solar=``) or a
spectrum over wavelength (:func:`~sbrdf_xr.photometry.pre_integrate`,
:func:`~sbrdf_xr.photometry.srgb`), a colour-science object is accepted and converted by
:func:`from_colour`: a ``SpectralDistribution`` is one curve (its ``name`` is the band's
label), a ``MultiSpectralDistributions`` one curve per label.  Their wavelengths are
taken in nm (colour-science's convention for spectral data) and the values as they are:
a filter's response [1], a solar spectrum's irradiance at 1 AU [W m-2 nm-1].
:func:`to_colour` goes the other way for any DataArray over ``wavelength``, a cube's
variable included (``cube.sbrdf.to_colour()``), with linear interpolation between the
nodes (the interpolant the band integrals assume).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr

from .._names import WAVELENGTH, attrs
from ..errors import ValidationError

__all__ = ["as_bands", "as_spectrum", "from_colour", "is_colour_spectrum", "to_colour"]


def _colour() -> Any:
    with np.printoptions():  # colour-science switches numpy to legacy printing on import
        import colour
    return colour


def is_colour_spectrum(obj: Any) -> bool:
    """True for a colour-science ``SpectralDistribution`` or ``MultiSpectralDistributions``.

    Tested without importing colour-science (its import takes a second).

    Examples
    --------
    >>> import colour
    >>> sd = colour.SpectralDistribution([0.1, 0.9], [500.0, 600.0])
    >>> is_colour_spectrum(sd), is_colour_spectrum(xr.DataArray([1.0]))
    (True, False)
    """
    mod = type(obj).__module__
    names = {c.__name__ for c in type(obj).__mro__}
    return mod.startswith("colour.") and bool(
        names & {"SpectralDistribution", "MultiSpectralDistributions"}
    )


def from_colour(obj: Any, *, dim: str = "band", units: str | None = None) -> xr.DataArray:
    """A colour-science spectrum as a DataArray over ``wavelength`` [nm].

    Parameters
    ----------
    obj : colour.SpectralDistribution or colour.MultiSpectralDistributions
        Its nodes are kept as they are (no interpolation).
    dim : str
        The dimension of a ``MultiSpectralDistributions``'s labels.
    units : str, optional
        The ``units`` attribute of the values (default none).

    Returns
    -------
    xarray.DataArray
        Over ``wavelength`` (a ``SpectralDistribution``; named after it) or over
        ``(dim, wavelength)`` (a ``MultiSpectralDistributions``; its labels along ``dim``).

    Examples
    --------
    >>> import colour
    >>> sd = colour.SpectralDistribution([0.0, 0.8, 0.0], [500.0, 550.0, 600.0], name="G")
    >>> da = from_colour(sd)
    >>> da.name, da.dims, da.wavelength.values.tolist(), da.values.tolist()
    ('G', ('wavelength',), [500.0, 550.0, 600.0], [0.0, 0.8, 0.0])
    >>> msds = colour.MultiSpectralDistributions([[0.1, 0.2], [0.3, 0.4]], [500.0, 600.0],
    ...                                          labels=["a", "b"])
    >>> from_colour(msds).sel(band="b").values.tolist()
    [0.2, 0.4]
    """
    if not is_colour_spectrum(obj):
        raise ValidationError(
            f"expected a colour-science SpectralDistribution or MultiSpectralDistributions, "
            f"got {type(obj).__name__}"
        )
    wl = np.asarray(obj.wavelengths, dtype=np.float64)
    values = np.asarray(obj.values, dtype=np.float64)
    extra = {"units": units} if units else {}
    source = f"colour-science {type(obj).__name__} {obj.name!r}"
    coords: dict[str, Any] = {WAVELENGTH: (WAVELENGTH, wl, attrs(WAVELENGTH))}
    if values.ndim == 1:
        return xr.DataArray(
            values, dims=(WAVELENGTH,), coords=coords, name=str(obj.name),
            attrs={"source": source, **extra},
        )  # fmt: skip
    coords[dim] = (dim, [str(s) for s in obj.labels])
    return xr.DataArray(
        values.T, dims=(dim, WAVELENGTH), coords=coords, name=str(obj.name),
        attrs={"source": source, **extra},
    )  # fmt: skip


def as_spectrum(obj: Any) -> Any:
    """``obj`` with a colour-science spectrum converted by :func:`from_colour` (labels along
    ``spectrum``); anything else unchanged.

    Examples
    --------
    >>> import colour
    >>> as_spectrum(colour.SpectralDistribution([0.5, 0.5], [400.0, 700.0])).dims
    ('wavelength',)
    >>> as_spectrum(3.0)
    3.0
    """
    return from_colour(obj, dim="spectrum") if is_colour_spectrum(obj) else obj


def as_bands(bands: Any) -> Any:
    """``bands`` with every colour-science filter converted by :func:`from_colour`.

    A ``SpectralDistribution`` is one band labelled by its ``name``; a
    ``MultiSpectralDistributions`` one band per label; inside a sequence or a mapping
    (``{"mine": sd}``, ``[("mine", sd), "V"]``) each is converted in place.

    Examples
    --------
    >>> import colour
    >>> sd = colour.SpectralDistribution([0.0, 1.0, 0.0], [500.0, 550.0, 600.0], name="G")
    >>> [type(b).__name__ for b in as_bands(["V", sd, ("mine", sd)])]
    ['str', 'DataArray', 'tuple']
    """
    if is_colour_spectrum(bands):
        return from_colour(bands, dim="band")
    if isinstance(bands, Mapping):
        return {k: as_bands(v) for k, v in bands.items()}
    if isinstance(bands, tuple) and len(bands) == 2 and isinstance(bands[0], str):
        return (bands[0], as_bands(bands[1]))
    if isinstance(bands, (list, tuple)):
        return [as_bands(b) for b in bands]
    return bands


def to_colour(obj: xr.Dataset | xr.DataArray, variable: str = "signal") -> Any:
    """A DataArray over ``wavelength`` (or a cube's ``variable``) as colour-science spectra.

    Parameters
    ----------
    obj : xarray.DataArray or Dataset
        Values over ``wavelength`` [nm]; a Dataset gives its ``variable``.
    variable : str
        The cube's variable (``signal``, ``spacecraft_sbrdf``, ``signal_material``).

    Returns
    -------
    colour.SpectralDistribution or colour.MultiSpectralDistributions
        One spectrum: a ``SpectralDistribution``; more: a ``MultiSpectralDistributions``
        whose labels name each spectrum's coordinates (``"attitude=3, phase_angle=10"``).
        Linear interpolation between the nodes; the name is the variable's.

    Examples
    --------
    >>> wl = np.array([400.0, 500.0, 600.0])
    >>> cube = xr.Dataset({"signal": (("attitude", "wavelength"), [[1.0, 2.0, 3.0],
    ...                                                            [4.0, 5.0, 6.0]])},
    ...                   coords={"attitude": [0, 1], "wavelength": wl})
    >>> msds = to_colour(cube)
    >>> type(msds).__name__, msds.labels, msds.values[:, 1].tolist()
    ('MultiSpectralDistributions', ['attitude=0', 'attitude=1'], [4.0, 5.0, 6.0])
    >>> float(to_colour(cube.signal.isel(attitude=0))[550.0])  # linear between the nodes
    2.5
    """
    colour = _colour()
    da = obj[variable] if isinstance(obj, xr.Dataset) else obj
    if not isinstance(da, xr.DataArray) or WAVELENGTH not in da.dims:
        raise ValidationError(
            f"to_colour: expected a DataArray (or cube variable) over '{WAVELENGTH}', "
            f"got {type(da).__name__}"
        )
    units = da[WAVELENGTH].attrs.get("units", "nm") if WAVELENGTH in da.coords else "nm"
    if units != "nm":
        raise ValidationError(f"to_colour: wavelength units must be 'nm', got {units!r}")
    wl = np.asarray(da[WAVELENGTH].values, dtype=np.float64)
    name = str(da.name) if da.name is not None else "spectrum"
    kw = {"interpolator": colour.LinearInterpolator, "name": name}
    other = [d for d in da.dims if d != WAVELENGTH]
    if not other:
        return colour.SpectralDistribution(np.asarray(da.values, np.float64), wl, **kw)
    flat = da.stack(_spectrum=other).transpose(WAVELENGTH, "_spectrum")
    labels = []
    for k in range(flat.sizes["_spectrum"]):
        one = flat.isel(_spectrum=k)
        labels.append(", ".join(f"{d}={one[d].values!s}" for d in other))
    return colour.MultiSpectralDistributions(
        np.asarray(flat.values, np.float64), wl, labels=labels, **kw
    )
