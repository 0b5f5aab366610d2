"""Helpers shared by every model module of :mod:`sbrdf_xr.brdf` (the common interface).

Parameter validation, facet cosines, the dtype policy and angle grids.  Precision
policy: all arithmetic is done in float64; results are returned in the working
precision of the geometric inputs (float32 if every floating input is float32,
float64 otherwise), clipped to the finite range of that dtype.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import geometry
from ..errors import ValidationError


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
    """Validate the wavelength grid [nm]: 1-D (or scalar), finite, positive."""
    wl = np.asarray(wavelength)
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


def _check_angles(*named: tuple[str, ArrayLike]) -> list[np.ndarray]:
    """Angles [degree] checked to be finite real numbers."""
    arrays = []
    for name, a in named:
        arr = np.asarray(a)
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


#: Nodes are evaluated at least this far inside the lit and visible hemisphere [degree]
#: by ``horizon="limit"`` rendering.
HORIZON_MARGIN_DEG = 1e-6
#: With ``horizon="limit"`` a ``theta_i = 90`` row is evaluated this far from grazing
#: incidence [degree]: the specular peak of a microfacet model diverges as both
#: directions graze, and a table node carries a value for the whole cell around it.
GRAZING_MARGIN_DEG = 0.5
#: The ways :func:`evaluate_grid` treats nodes that are not lit and visible.
HORIZONS = ("zero", "limit")


def tangent_from_azimuth(psi: ArrayLike) -> np.ndarray:
    """Facet tangent in the frame of :func:`sbrdf_xr.geometry.facet_vectors` for ``psi``.

    That frame has ``N = +z`` and the forward direction ``e_f = -x``; the tangent at
    azimuth ``psi`` [degree] from which ``e_f`` is reached counter-clockwise about
    ``N`` is ``(-cos psi, sin psi, 0)``.

    Parameters
    ----------
    psi : array_like
        Azimuth of the illumination plane from the tangent [degree].

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
    a = np.radians(np.asarray(psi, dtype=np.float64))
    return np.stack([-np.cos(a), np.sin(a), np.zeros_like(a)], axis=-1)


def evaluate_angles(
    brdf: Callable[..., np.ndarray],
    theta_i: ArrayLike,
    delta_theta: ArrayLike,
    phi: ArrayLike,
    wavelength: ArrayLike,
    *,
    psi: ArrayLike | None = None,
    **kwargs: Any,
) -> np.ndarray:
    """A model's ``brdf`` function evaluated at paper-000 angles (one for every model).

    The facet-frame vectors of :func:`sbrdf_xr.geometry.facet_vectors` are built from
    the angles; with ``psi`` the tangent of :func:`tangent_from_azimuth` is passed
    as ``tangent`` (anisotropic models).

    Parameters
    ----------
    brdf : callable
        ``brdf(normal, to_sun, to_observer, wavelength, **kwargs)``.
    theta_i, delta_theta, phi : array_like
        Paper-000 Fig. 4 angles [degree], broadcast together.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    psi : array_like, optional
        Azimuth of the illumination plane from the facet tangent [degree].
    **kwargs
        Passed to ``brdf``.

    Returns
    -------
    ndarray, shape broadcast(...) + (n_wl,)
        BRDF [sr-1].

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.brdf import lambert
    >>> f = evaluate_angles(lambert.brdf, [0.0, 95.0], 0.0, 0.0, [550.0], rho=np.pi / 10)
    >>> np.round(f, 6)
    array([[0.1],
           [0. ]])
    """
    n, s, o = _angles_to_vectors(theta_i, delta_theta, phi)
    if psi is None:
        return brdf(n, s, o, wavelength, **kwargs)
    t = tangent_from_azimuth(_check_angles(("psi", psi))[0])
    n, s, o, t = np.broadcast_arrays(n, s, o, t)
    return brdf(n, s, o, wavelength, tangent=t, **kwargs)


def evaluate_grid(
    brdf: Callable[..., np.ndarray],
    theta_i: ArrayLike,
    delta_theta: ArrayLike,
    phi: ArrayLike,
    wavelength: ArrayLike,
    *,
    psi: ArrayLike | None = None,
    horizon: str = "zero",
    **kwargs: Any,
) -> np.ndarray:
    """A model's ``brdf`` on the outer product of 1-D angle grids (one for every model).

    With ``horizon="limit"`` a node whose geometry is not lit and visible
    (``theta_i`` = 90 deg, the observer at or below the horizon: ``|theta_i +
    delta_theta| >= 90`` or ``phi >= 90``) carries the model's limit from inside the
    hemisphere: it is evaluated at the nearest lit and visible geometry,
    :data:`HORIZON_MARGIN_DEG` inside the horizon and :data:`GRAZING_MARGIN_DEG` from
    grazing incidence.  Interpolating between such a node and a visible one then
    never blends in a zero that the physics does not have (a Lambertian surface
    renders to ``rho / pi`` at every node).  ``horizon="zero"`` evaluates every node
    as it is.

    Parameters
    ----------
    brdf : callable
        ``brdf(normal, to_sun, to_observer, wavelength, **kwargs)``.
    theta_i, delta_theta, phi : array_like, 1-D
        Grids [degree].
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    psi : array_like, 1-D, optional
        Grid of the azimuth of the illumination plane from the tangent [degree]
        (anisotropic models): an axis before ``wavelength``.
    horizon : {"zero", "limit"}, default "zero"
        Treatment of nodes that are not lit and visible.
    **kwargs
        Passed to ``brdf``.

    Returns
    -------
    ndarray, shape (n_ti, n_dt, n_phi[, n_psi], n_wl)
        BRDF [sr-1].

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.brdf import lambert
    >>> g = evaluate_grid(lambert.brdf, [0.0, 90.0], [0.0], [0.0, 90.0], [550.0], rho=np.pi)
    >>> g.shape, g[..., 0].ravel().tolist()
    ((2, 1, 2, 1), [1.0, 0.0, 0.0, 0.0])
    >>> evaluate_grid(
    ...     lambert.brdf, [0.0, 90.0], [0.0], [0.0, 90.0], [550.0], horizon="limit", rho=np.pi
    ... )[..., 0].ravel().tolist()
    [1.0, 1.0, 1.0, 1.0]
    """
    if horizon not in HORIZONS:
        raise ValidationError(f"horizon: got {horizon!r}; allowed: {list(HORIZONS)}")
    named = [("theta_i", theta_i), ("delta_theta", delta_theta), ("phi", phi)]
    if psi is not None:
        named.append(("psi", psi))
    grids = []
    for name, a in named:
        arr = np.asarray(a)
        if arr.ndim != 1:
            raise ValidationError(f"{name}: expected a 1-D grid [degree], got shape {arr.shape}")
        grids.append(arr.astype(np.float64) if horizon == "limit" else arr)
    mesh = np.meshgrid(*grids, indexing="ij")
    t, d, p = mesh[:3]
    if horizon == "limit":
        m = HORIZON_MARGIN_DEG
        t_c = np.minimum(t, 90.0 - GRAZING_MARGIN_DEG)
        r_c = np.clip(t + d, -(90.0 - m), 90.0 - m)
        t, d, p = t_c, r_c - t_c, np.minimum(p, 90.0 - m)
    ps = mesh[3] if psi is not None else None
    return evaluate_angles(brdf, t, d, p, wavelength, psi=ps, **kwargs)


def _check_theta_i(theta_i: ArrayLike) -> np.ndarray:
    """Validate incidence angles [degree] in ``[0, 90]`` for hemispherical reflectances."""
    ti = np.asarray(theta_i)
    if not np.issubdtype(ti.dtype, np.number) or np.iscomplexobj(ti):
        raise ValidationError(f"theta_i: expected real angles [degree], got dtype {ti.dtype}")
    ti = ti.astype(np.float64)
    if not np.all(np.isfinite(ti)) or np.any((ti < 0) | (ti > 90)):
        bad = ti[~(np.isfinite(ti) & (ti >= 0) & (ti <= 90))]
        raise ValidationError(
            f"theta_i: got {bad.ravel()[:5].tolist()}; allowed domain is 0 <= theta_i <= 90 [degree]"
        )
    return ti
