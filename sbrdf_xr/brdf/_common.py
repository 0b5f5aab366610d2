"""Helpers shared by every model module of :mod:`sbrdf_xr.brdf` (the common interface).

Parameter validation, facet cosines, the dtype policy and angle grids.  Precision
policy: all arithmetic is done in float64; results are returned in the working
precision of the geometric inputs (float32 if every floating input is float32,
float64 otherwise), clipped to the finite range of that dtype.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import geometry
from ..errors import ValidationError
from ..units import to_unit


def _out_dtype(*arrays: ArrayLike) -> np.dtype:
    """Working precision of the inputs: float32 if all floating inputs are float32."""
    dts = [np.asarray(a).dtype for a in arrays]
    floats = [d for d in dts if np.issubdtype(d, np.floating)]
    if floats and all(d == np.float32 for d in floats) and len(floats) == len(dts):
        return np.dtype(np.float32)
    return np.dtype(np.float64)


def _cast_out(values: np.ndarray, dtype: np.dtype) -> np.ndarray:
    """Cast float64 ``values`` to ``dtype`` without overflowing to inf."""
    if dtype == np.float64:
        return values
    big = float(np.finfo(dtype).max)
    return np.clip(values, -big, big).astype(dtype)


def _check_wavelength(wavelength: ArrayLike) -> NDArray[np.float64]:
    """Validate the wavelength grid [nm] (a Quantity is converted): 1-D (or scalar), finite,
    positive."""
    wl = np.asarray(to_unit(wavelength, "nm", "wavelength", spectral=True))
    if not (np.issubdtype(wl.dtype, np.number) and not np.iscomplexobj(wl)):
        raise ValidationError(f"wavelength: expected real numbers [nm], got dtype {wl.dtype}")
    wl = np.atleast_1d(wl).astype(np.float64)
    if wl.ndim != 1 or wl.size == 0:
        raise ValidationError(
            f"wavelength: expected a non-empty 1-D array [nm], got shape {np.shape(wavelength)}"
        )
    if not np.all(np.isfinite(wl)) or np.any(wl <= 0):
        raise ValidationError(
            f"wavelength: must be finite and > 0 [nm], got min {np.nanmin(wl)!r}, "
            f"{int(np.sum(~np.isfinite(wl)))} non-finite value(s)"
        )
    return wl


def _band_param(
    name: str,
    value: Any,
    n_wl: int,
    *,
    lower: float | None = None,
    upper: float | None = None,
    lower_open: bool = False,
    unit: str = "1",
) -> NDArray[np.float64]:
    """Validate a scalar or per-band parameter and broadcast it to ``(n_wl,)`` float64."""
    arr = np.asarray(value)
    if not np.issubdtype(arr.dtype, np.number) or np.iscomplexobj(arr):
        raise ValidationError(f"{name}: expected real numbers [{unit}], got dtype {arr.dtype}")
    if arr.ndim > 1 or (arr.ndim == 1 and arr.shape[0] not in (1, n_wl)):
        raise ValidationError(
            f"{name}: expected a scalar or an array of shape ({n_wl},) aligned with "
            f"wavelength, got shape {arr.shape}"
        )
    arr = np.broadcast_to(arr.astype(np.float64), (n_wl,)).copy()
    if not np.all(np.isfinite(arr)):
        raise ValidationError(f"{name}: contains NaN or infinite values; must be finite [{unit}]")
    bad = np.zeros(n_wl, dtype=bool)
    if lower is not None:
        bad |= (arr <= lower) if lower_open else (arr < lower)
    if upper is not None:
        bad |= arr > upper
    if np.any(bad):
        lo = "" if lower is None else (f"{lower} < " if lower_open else f"{lower} <= ")
        hi = "" if upper is None else f" <= {upper}"
        raise ValidationError(
            f"{name}: got {arr[bad][:5].tolist()} (first out-of-domain values); "
            f"allowed domain is {lo}{name}{hi} [{unit}]"
        )
    return arr


def _check_names(params: Mapping[str, Any], names: tuple[str, ...], model: str) -> None:
    missing = [p for p in names if p not in params]
    extra = [p for p in params if p not in names]
    if missing or extra:
        raise ValidationError(
            f"{model}: parameters must be exactly {list(names)}; "
            f"missing {missing}, unexpected {extra}"
        )


def _facet_frame(
    normal: ArrayLike, to_sun: ArrayLike, to_observer: ArrayLike
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.dtype]:
    """Normalised, broadcast float64 vectors, the cosines ``N.s``, ``N.o`` and the mask.

    Returns ``n, s, o, cos_i, cos_r, mask, out_dtype`` where ``mask`` is
    ``(N.s > 0) & (N.o > 0)`` (lit and visible).
    """
    dtype = _out_dtype(normal, to_sun, to_observer)
    n = geometry.normalize(normal, "normal").astype(np.float64)
    s = geometry.normalize(to_sun, "to_sun").astype(np.float64)
    o = geometry.normalize(to_observer, "to_observer").astype(np.float64)
    n, s, o = np.broadcast_arrays(n, s, o)
    cos_i = np.einsum("...k,...k->...", n, s)
    cos_r = np.einsum("...k,...k->...", n, o)
    mask = (cos_i > 0) & (cos_r > 0)
    return n, s, o, cos_i, cos_r, mask, dtype


def _sin2(n: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``sin^2`` of the angle between unit vectors, from ``|n x v|^2`` (accurate near 0)."""
    c = np.cross(n, v)
    return np.einsum("...k,...k->...", c, c)


def _cos_half(s: np.ndarray, o: np.ndarray) -> np.ndarray:
    """``h.s = h.o = |s + o| / 2`` for unit ``s``, ``o`` (the microfacet cosine).

    ``h.s`` and ``h.o`` are equal in exact arithmetic, but computed as dot products
    they differ by the rounding of ``|s|^2 - |o|^2`` over ``|s + o|``, which is large
    near forward scatter; ``|s + o| / 2`` is symmetric in ``s`` and ``o`` to the bit
    and accurate everywhere.
    """
    return 0.5 * np.linalg.norm(s + o, axis=-1)


def _check_angles(*named: tuple[str, ArrayLike]) -> list[np.ndarray]:
    """Angles [degree] (Quantities converted) checked to be finite real numbers."""
    arrays = []
    for name, a in named:
        arr = np.asarray(to_unit(a, "deg", name))
        if not np.issubdtype(arr.dtype, np.number) or np.iscomplexobj(arr):
            raise ValidationError(f"{name}: expected real angles [degree], got dtype {arr.dtype}")
        if not np.all(np.isfinite(arr)):
            raise ValidationError(f"{name}: contains NaN or infinite angles [degree]")
        arrays.append(arr)
    return arrays


def _angles_to_vectors(
    theta_i: ArrayLike, delta_theta: ArrayLike, phi: ArrayLike
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Facet-frame unit vectors for paper-000 angles [degree] (``geometry.facet_vectors``)."""
    arrays = _check_angles(("theta_i", theta_i), ("delta_theta", delta_theta), ("phi", phi))
    return geometry.facet_vectors(*arrays)


def tangent_from_azimuth(psi: ArrayLike) -> np.ndarray:
    """Facet tangent in the frame of :func:`sbrdf_xr.geometry.facet_vectors` for ``psi``.

    That frame has ``N = +z`` and the forward direction ``e_f = -x``; the tangent at
    azimuth ``psi`` [degree] from which ``e_f`` is reached counter-clockwise about
    ``N`` is ``(-cos psi, sin psi, 0)``.

    Parameters
    ----------
    psi : array_like
        Azimuth of the illumination plane from the tangent [degree]; a Quantity is
        converted.

    Returns
    -------
    ndarray, shape psi.shape + (3,)
        Unit tangents [1].

    Examples
    --------
    >>> import numpy as np
    >>> (np.round(tangent_from_azimuth([0.0, 90.0]), 6) + 0.0).tolist()
    [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    """
    a = np.radians(np.asarray(to_unit(psi, "deg", "psi"), dtype=np.float64))
    return np.stack([-np.cos(a), np.sin(a), np.zeros_like(a)], axis=-1)


def _check_theta_i(theta_i: ArrayLike, name: str = "theta_i") -> np.ndarray:
    """Validate incidence angles [degree] (a Quantity is converted) in ``[0, 90]`` for
    hemispherical reflectances."""
    ti = np.asarray(to_unit(theta_i, "deg", name))
    if not np.issubdtype(ti.dtype, np.number) or np.iscomplexobj(ti):
        raise ValidationError(f"{name}: expected real angles [degree], got dtype {ti.dtype}")
    ti = ti.astype(np.float64)
    if not np.all(np.isfinite(ti)) or np.any((ti < 0) | (ti > 90)):
        bad = ti[~(np.isfinite(ti) & (ti >= 0) & (ti <= 90))]
        raise ValidationError(
            f"{name}: got {bad.ravel()[:5].tolist()}; allowed domain is 0 <= {name} <= 90 [degree]"
        )
    return ti
