r"""Anisotropic GGX microfacet spectral BRDF with Smith masking (brushed metals).

``f_r = F(h.s) D(h) G2(s, o) / (4 |N.s| |N.o|) + rho_d(lambda) / pi``

in the facet frame ``(t, b, N)``: ``t`` the facet tangent (the direction of
roughness ``alpha_x``), ``b = N x t`` (roughness ``alpha_y``).

* ``D``: anisotropic GGX, ``D(h) = 1 / (pi alpha_x alpha_y (h_x^2/alpha_x^2 +
  h_y^2/alpha_y^2 + h_z^2)^2)`` (Heitz, JCGT 3(2), 2014, Eq. 85).
* ``G2``: Smith height-correlated masking-shadowing ``1 / (1 + Lambda(s) +
  Lambda(o))`` with ``Lambda(v) = (sqrt(1 + (alpha_x^2 v_x^2 + alpha_y^2 v_y^2) /
  v_z^2) - 1) / 2`` (Heitz 2014, Eqs. 86 and 99).  ``G2 / (4 N.s N.o)`` is evaluated
  as ``1 / (2 (N.o S_s + N.s S_o))`` with ``S_v = sqrt(v_z^2 + alpha_x^2 v_x^2 +
  alpha_y^2 v_y^2)``, finite at grazing angles (for ``alpha_x = alpha_y = alpha``,
  ``S_v = sqrt(alpha^2 + (1 - alpha^2) v_z^2)``: the isotropic form of
  :mod:`sbrdf_xr.brdf.microfacet`, which this model then equals).
* ``F``: exact unpolarised Fresnel reflectance of the substrate ``n + ik``
  (:mod:`sbrdf_xr.brdf.optics`).

Geometry: besides the paper-000 angles ``(theta_i, delta_theta, phi)`` the
reflection depends on ``psi`` [degree], the azimuth of the illumination plane from
the facet tangent: the angle about ``N``, counter-clockwise, from ``t`` to the
in-plane forward direction ``e_f`` (paper 000 Fig. 4; :func:`illumination_azimuth`).
``D`` and ``G2`` depend on the tangent through ``(v.t)^2`` and ``(v.b)^2`` only, so
``t`` and ``-t`` are the same tangent (``psi ~ psi + 180``).  The paper's ``phi`` is
unsigned: an observer on the ``-p`` side of the illumination plane is its mirror
image, and mirroring the geometry across the plane maps ``psi -> -psi``, so
:func:`illumination_azimuth` returns ``psi`` in ``[0, 180)`` with that fold, and
``(theta_i, delta_theta, phi, psi)`` covers every geometry.

References
----------
Heitz, E., "Understanding the masking-shadowing function in microfacet-based
BRDFs", JCGT 3(2), 48 (2014).
Walter, B., Marschner, S. R., Li, H., Torrance, K. E., EGSR 2007.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import geometry
from ..errors import ValidationError
from . import optics
from ._common import (
    _cast_out,
    _check_angles,
    _check_theta_i,
    _check_wavelength,
    _cos_half,
    _facet_frame,
    tangent_from_azimuth,
)
from ._model import Model, Parameter
from .microfacet import PARAMETERS as _ISOTROPIC
from .microfacet import ROUGHNESS_MAX, ROUGHNESS_MIN

__all__ = [
    "MODEL",
    "PARAMS",
    "brdf",
    "brdf_angles",
    "check_params",
    "directional_hemispherical_reflectance",
    "distribution",
    "illumination_azimuth",
    "render_grid",
    "tangent_from_azimuth",
]

#: The parameters: roughness along the tangent ``alpha_x`` and across it ``alpha_y``,
#: and the microfacet model's substrate index ``n``, extinction ``k`` and albedo ``rho_d``.
PARAMETERS = (
    *(
        Parameter(
            f"alpha_{axis}",
            "1",
            f"GGX roughness {where} the facet tangent",
            lower=ROUGHNESS_MIN,
            upper=ROUGHNESS_MAX,
            spectral=False,
        )
        for axis, where in (("x", "along"), ("y", "across"))
    ),
    *_ISOTROPIC[1:],
)

_VIS_FLOOR = 1.0e-150
_N_PHI = 128
_N_U = 128


def distribution(h_local: ArrayLike, alpha_x: ArrayLike, alpha_y: ArrayLike) -> np.ndarray:
    """Anisotropic GGX distribution of normals (Heitz 2014 Eq. 85).

    Parameters
    ----------
    h_local : array_like, shape (..., 3)
        Unit half vectors in the facet frame ``(t, b, N)`` [1].
    alpha_x, alpha_y : array_like
        Roughness along ``t`` and ``b`` [1]; broadcast against ``h_local[..., 0]``.

    Returns
    -------
    ndarray
        ``D`` [sr-1]; ``int D cos(theta_h) d omega = 1``.

    Examples
    --------
    >>> import numpy as np
    >>> round(float(distribution([0.0, 0.0, 1.0], 0.1, 0.3) * np.pi * 0.1 * 0.3), 6)
    1.0
    """
    h = np.asarray(h_local, dtype=np.float64)
    ax = np.asarray(alpha_x, dtype=np.float64)
    ay = np.asarray(alpha_y, dtype=np.float64)
    q = (h[..., 0] / ax) ** 2 + (h[..., 1] / ay) ** 2 + h[..., 2] ** 2
    return 1.0 / (np.pi * ax * ay * q * q)


def _s_term(v_local: np.ndarray, ax: np.ndarray, ay: np.ndarray) -> np.ndarray:
    """``S_v = sqrt(v_z^2 + alpha_x^2 v_x^2 + alpha_y^2 v_y^2)`` (``v_z Lambda`` form)."""
    vz = np.clip(v_local[..., 2], 0.0, 1.0)
    return np.sqrt(vz * vz + (ax * v_local[..., 0]) ** 2 + (ay * v_local[..., 1]) ** 2)


def _local(v: np.ndarray, t: np.ndarray, b: np.ndarray, n: np.ndarray) -> np.ndarray:
    return np.stack([np.einsum("...k,...k->...", v, e) for e in (t, b, n)], axis=-1)


def _frame(normal: np.ndarray, tangent: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Unit tangent (Gram-Schmidt against the normal) and bitangent ``N x t``."""
    t = np.asarray(tangent, dtype=np.float64)
    t = np.broadcast_to(t, np.broadcast_shapes(t.shape, normal.shape))
    t = t - np.einsum("...k,...k->...", t, normal)[..., None] * normal
    length = np.linalg.norm(t, axis=-1, keepdims=True)
    if np.any(length <= 1e-12):
        raise ValidationError("tangent: must not be parallel to the facet normal (or zero)")
    t = t / length
    return t, np.cross(normal, t)


def brdf(
    normal: ArrayLike,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    wavelength: ArrayLike,
    *,
    tangent: ArrayLike,
    **params: Any,
) -> np.ndarray:
    """Anisotropic GGX spectral BRDF plus a Lambertian term.

    Parameters
    ----------
    normal, to_sun, to_observer : array_like, shape (..., 3)
        Facet normal and directions to the source and observer [1]; broadcast.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    tangent : array_like, shape (..., 3)
        Facet tangent, the direction of ``alpha_x`` [1] (its component along the
        normal is removed).
    **params
        ``alpha_x``, ``alpha_y``, ``n``, ``k``, ``rho_d`` (:func:`check_params`).

    Returns
    -------
    ndarray, shape broadcast(...) + (n_wl,)
        BRDF [sr-1]; zero where ``N.s <= 0`` or ``N.o <= 0`` (at and below the
        horizon).  Reciprocal to the bit over the whole domain, as
        :func:`sbrdf_xr.brdf.microfacet.brdf` (finite near the horizon likewise).

    Examples
    --------
    >>> import numpy as np
    >>> n, s, o = [0.0, 0.0, 1.0], [0.5, 0.0, 1.0], [-0.5, 0.0, 1.0]
    >>> kw = {"n": 1.5, "k": 0.0, "rho_d": 0.0}
    >>> np.round(brdf(n, s, o, [550.0], tangent=[1.0, 0.0, 0.0], alpha_x=0.2, alpha_y=0.2, **kw), 4)
    array([0.1012])
    """
    wl = _check_wavelength(wavelength)
    p = MODEL.check_params(wl, **params)
    n, s, o, cos_i, cos_r, mask, dtype = _facet_frame(normal, to_sun, to_observer)
    t, b = _frame(n, tangent)
    h = geometry.half_vector(s, o).astype(np.float64)
    hl = _local(h, t, b, n)[..., None, :]
    sl = _local(s, t, b, n)[..., None, :]
    ol = _local(o, t, b, n)[..., None, :]
    ax, ay = p["alpha_x"], p["alpha_y"]
    d = distribution(hl, ax, ay)
    ci = np.clip(cos_i, 0.0, 1.0)[..., None]
    cr = np.clip(cos_r, 0.0, 1.0)[..., None]
    vis = 1.0 / np.maximum(2.0 * (cr * _s_term(sl, ax, ay) + ci * _s_term(ol, ax, ay)), _VIS_FLOOR)
    cos_hs = np.clip(_cos_half(s, o), 0.0, 1.0)
    fres = optics.fresnel_conductor(cos_hs[..., None], p["n"] + 1j * p["k"])
    f = fres * d * vis + p["rho_d"] / np.pi
    return _cast_out(np.where(mask[..., None], f, 0.0), dtype)


def illumination_azimuth(
    normal: ArrayLike, tangent: ArrayLike, to_sun: ArrayLike, to_observer: ArrayLike
) -> NDArray[np.float64]:
    """``psi`` [degree] of a geometry: azimuth of the illumination plane from the tangent.

    :func:`sbrdf_xr.geometry.anisotropy.illumination_azimuth` (its convention), in float64.

    Parameters
    ----------
    normal, tangent, to_sun, to_observer : array_like, shape (..., 3)
        Facet normal and tangent, directions to the Sun and the observer [1].

    Returns
    -------
    ndarray
        ``psi`` in ``[0, 180)`` degree.

    Examples
    --------
    >>> import numpy as np
    >>> n, s, o = [0.0, 0.0, 1.0], [0.5, 0.0, 1.0], [-0.5, 0.0, 1.0]
    >>> across = [0.0, 1.0, 0.0]  # a tangent across the illumination plane
    >>> float(np.round(illumination_azimuth(n, across, s, o), 6))
    90.0
    """
    from ..geometry import anisotropy

    f64 = [np.asarray(a, dtype=np.float64) for a in (normal, to_sun, to_observer)]
    return anisotropy.illumination_azimuth(f64[0], tangent, f64[1], f64[2]).astype(np.float64)


def directional_hemispherical_reflectance(
    theta_i: ArrayLike, wavelength: ArrayLike, *, psi: ArrayLike = 0.0, **params: Any
) -> NDArray[np.float64]:
    """Directional-hemispherical reflectance by quadrature over the half vector.

    With the slopes of the visible microfacet ``(-h_x/h_z, -h_y/h_z) = r (alpha_x cos
    f, alpha_y sin f)`` and ``u = r^2 / (1 + r^2)``, ``D cos(theta_h) d omega_h =
    du df / (2 pi)`` (the anisotropic GGX is a stretched isotropic one), and
    ``d omega_o = 4 (h.s) d omega_h``:
    ``rho_spec = int F G2 (h.s) / (N.s cos theta_h) [N.o > 0] du df / (2 pi)``,
    Gauss-Legendre in ``x`` (``u = sin^2 x``) and ``f`` (128 x 128 nodes); the
    horizon cut ``[N.o > 0]`` is not aligned with the nodes, hence ~1e-3 accuracy.

    Parameters
    ----------
    theta_i : array_like
        Incidence angles [degree].
    wavelength : array_like
        Wavelengths [nm].
    psi : array_like, default 0
        Azimuth of the illumination plane from the tangent [degree]; broadcast with
        ``theta_i``.
    **params
        As :func:`brdf`.

    Returns
    -------
    ndarray, shape broadcast(theta_i, psi) + (n_wl,)
        Reflectance [1].

    Examples
    --------
    >>> import numpy as np
    >>> r = directional_hemispherical_reflectance([0.0], [550.0], psi=0.0, alpha_x=0.2, alpha_y=0.2,
    ...                                           n=1.5, k=0.0, rho_d=0.0)
    >>> np.round(r, 3).tolist()  # the isotropic microfacet value, to the quadrature's 1e-3
    [[0.038]]
    """
    wl = _check_wavelength(wavelength)
    p = MODEL.check_params(wl, **params)
    ti = _check_theta_i(theta_i)
    ti, ps = np.broadcast_arrays(ti, _check_angles(("psi", psi))[0].astype(np.float64))
    tx, wx = np.polynomial.legendre.leggauss(_N_U)
    x = 0.25 * np.pi * (tx + 1.0)  # [0, pi/2]
    wx = 0.25 * np.pi * wx
    u = np.sin(x) ** 2
    du = np.sin(2 * x) * wx
    tf, wf = np.polynomial.legendre.leggauss(_N_PHI)
    f = np.pi * (tf + 1.0)  # [0, 2 pi]
    wf = np.pi * wf
    r = np.sqrt(u / np.maximum(1.0 - u, 1e-300))[:, None, None]  # (u, f, wl)
    ax, ay = p["alpha_x"], p["alpha_y"]
    sx = r * ax * np.cos(f)[None, :, None]
    sy = r * ay * np.sin(f)[None, :, None]
    hz = 1.0 / np.sqrt(1.0 + sx * sx + sy * sy)
    h = np.stack([-sx * hz, -sy * hz, hz], axis=-1)  # (u, f, wl, 3)
    out = np.empty((*ti.shape, wl.size))
    for idx in np.ndindex(ti.shape):
        a = np.radians(ti[idx])
        t = tangent_from_azimuth(ps[idx])
        b = np.cross([0.0, 0.0, 1.0], t)
        s_world = np.array([np.sin(a), 0.0, np.cos(a)])
        s = np.array([s_world @ t, s_world @ b, s_world[2]])
        hs = np.einsum("...k,k->...", h, s)
        o = 2.0 * hs[..., None] * h - s
        co = o[..., 2]
        ci = s[2]
        ok = (co > 0) & (hs > 0)
        s_s = np.sqrt(ci * ci + (ax * s[0]) ** 2 + (ay * s[1]) ** 2)
        s_o = np.sqrt(np.clip(co, 0, 1) ** 2 + (ax * o[..., 0]) ** 2 + (ay * o[..., 1]) ** 2)
        # G2 / N.s = 2 N.o / (N.o S_s + N.s S_o)
        g2_ci = 2.0 * np.clip(co, 0, 1) / np.maximum(co * s_s + ci * s_o, 1e-300)
        fres = optics.fresnel_conductor(np.clip(hs, 0.0, 1.0), p["n"] + 1j * p["k"])
        integrand = np.where(ok, fres * g2_ci * np.clip(hs, 0, 1) / hz, 0.0)
        out[idx] = np.einsum("ufw,u,f->w", integrand, du, wf) / (2 * np.pi) + p["rho_d"]
    return out


#: The anisotropic microfacet model.
MODEL = Model(
    name="anisotropic_microfacet",
    long_name="anisotropic GGX microfacet model with Smith masking, plus a Lambertian term",
    brdf=brdf,
    parameters=PARAMETERS,
    citation="Heitz, JCGT 3(2) 2014, Eqs. 85, 86 and 99; Walter et al., EGSR 2007",
    reflectance=directional_hemispherical_reflectance,
    anisotropic=True,
    reciprocal=True,
)
PARAMS = MODEL.param_names
check_params, brdf_angles, render_grid = MODEL.check_params, MODEL.brdf_angles, MODEL.render_grid
