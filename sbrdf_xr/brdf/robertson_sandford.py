r"""Robertson–Sandford (R-S) semi-empirical spectral BRDF (paper 001, §4).

Four parameters: the diffuse spectral reflectance ``rho_D(lambda)``, the spectral
(hemispherical) emissivity ``epsilon(lambda)``, the grazing-angle parameter ``b`` and
the specular lobe width ``e`` (paper 001 §4, Table 4).  The BRDF is the sum of a
diffuse term (Eq. 13) and a Trowbridge–Reitz specular lobe (Eqs. 15–16) with a
grazing cut-off (Eq. 21).  The least-squares fit to measured samples is
:mod:`sbrdf_xr.brdf.robertson_sandford_fit`.

How the equations are read (the text of paper 001 is an extraction with mangled
symbols; every reading below is checked by quadrature in the tests)
-------------------------------------------------------------------------------

* **Eq. 10**, ``G(b) = (1/pi) int cos(theta) g(theta) dOmega`` over the hemisphere.
  The printed closed form ``[1 - b^2/(1-b^2) log(1/b^2)] / (1-b^2)`` equals that
  integral (substitute ``u = cos^2 theta``: ``G = int_0^1 u du / (b^2 + (1-b^2) u)``).
  It has ``G(0) = 1`` (Lambertian), a removable singularity at ``b = 1`` (``G = 1/2``)
  and is valid for ``b > 1`` (``G ~ log(b^2)/b^2``).  Near ``b = 1`` the printed form
  cancels catastrophically (relative error ~ ``eps / (1-b^2)^2``); there the series
  ``G = sum_n c^n / ((n+1)(n+2))``, ``c = 1 - b^2``, is used.
* **Eq. 11** reads ``rho(lambda, theta_i) = rho_s(lambda, theta_i) + rho_d(lambda,
  theta_i) = 1 - epsilon(lambda, theta_i)``: the directional-hemispherical
  reflectance (the bar is the integral of ``f_r cos(theta_r) dOmega_r``).
* **Eq. 13**, ``f_d = g(theta_r) rho_D g(theta_i) / (pi G(b)^2)`` with ``rho_d(lambda)``
  read as ``rho_D``.  Integrating over the reflection hemisphere gives the diffusely
  scattered fraction ``rho_d(lambda, theta_i) = rho_D g(theta_i) / G(b)`` (not
  ``rho_D g(theta_i)`` as the sentence after Eq. 13 says: the extra ``1/G`` comes from
  Eq. 13's ``G^2``).  Its cosine-weighted average over incidence directions is
  ``rho_D``, so ``rho_D`` is the bihemispherical diffuse reflectance, just as
  ``epsilon(lambda)`` is the hemispherical emissivity of Eq. 8.  The term is
  reciprocal (Eq. 12).
* **Eq. 17**, ``rho_s(lambda, theta_i) = 1 - rho_d(lambda, theta_i) - epsilon(lambda,
  theta_i) = 1 - (rho_D + epsilon) g(theta_i) / G(b)``, so that the diffuse plus
  specular reflectance is exactly ``1 - epsilon(lambda, theta_i)`` (Eq. 11).
  ``rho_s >= 0`` at every incidence (the worst case is normal incidence, where
  ``g = 1``) requires ``rho_D + epsilon <= G(b)``; this is the domain enforced by
  the parameter check of :data:`MODEL`.  It implies ``rho_D + epsilon <= 1`` (``G <= 1``), which is
  only the incidence-averaged version of the same condition.
* **Eq. 18**, ``H(theta_i) = (1/4 pi) int h(alpha) dOmega_r`` over the reflection
  hemisphere.  The printed closed form equals this integral (checked by quadrature
  to 1e-12), so Eq. 15 integrates (``f_s cos(theta_r) dOmega_r``) to ``rho_s``
  exactly.  It is evaluated in the algebraically equivalent, cancellation-free form
  ``H = (S + A)^2 / (4 e^2 S)`` (``A >= 0``), ``H = 4 e^2 / (S (S - A)^2)`` (``A < 0``),
  with ``A = (1 - e^2) cos(theta_i)`` and ``S = sqrt(A^2 + 4 e^2)``, which is stable
  for needle lobes (``e -> 0``) and for ``e > 1``.
* **Eq. 21** with ``delta = b``, "normalised to 1.0 at theta = 80 deg", is read as
  the factor ``c(theta_r) = 1`` for ``theta_r <= 80 deg`` and
  ``c(theta_r) = d(theta_r) / d(80 deg)`` above, multiplying the *specular* term
  only (the diffuse term already falls to zero at grazing through ``g(theta_r)``).
  It is continuous at 80 deg, removes the ``1/cos(theta_r)`` divergence of Eq. 15,
  and makes ``f_s -> 0`` at the horizon (for ``b > 0``).  As in the paper, ``H`` is
  *not* renormalised ("very messy normalization integrals"), so with the cut-off the
  hemispherical integral is ``1 - epsilon(lambda, theta_i) - rho_s L(theta_i)``
  where ``L`` is the fraction of the lobe removed above 80 deg.  For the Table 4
  paints ``L`` is 0.3 % (AFGL-01) and 0.003 % (AFGL-10) at normal incidence,
  1.4 % and 0.015 % at 60 deg, 9 % and 2.6 % at 80 deg, and grows toward grazing.
  ``cutoff=False`` gives the uncut model, whose integral is exactly
  ``1 - epsilon(lambda, theta_i)``.

Table 3 against Table 4 (measured in the tests; the user guide page
``paper001`` has the numbers)
-------------------------------------------------------------------

* **Glint widths.**  Table 3 lists the *measured* full width at half peak of the
  glint lobe at 40 deg incidence: 24 deg (AFGL-01) and 3 deg (AFGL-10) at 4 um.
  The model with the Table 4 parameters gives 19.25 deg and 1.77 deg in the plane
  of incidence (for a narrow lobe ``4 e sqrt(sqrt(2) - 1)`` rad = 147.5 ``e`` deg,
  from Eq. 16).  The widths of Table 3 would need ``e = 0.144`` and ``e = 0.0203``.
  The Table 4 values are not a fit to those widths but to the log-scale lobes of
  Figs. 11 and 13 at three incidence angles, and the measured widths include the
  angular resolution of the SOC apparatus: the glossy paints of Table 3 (AFGL-02,
  -03, -06, -08, -10, -18) all measure 2.3-3.5 deg, a floor consistent with an
  instrument response of ~2.1 deg FWHM (convolving the model lobe of AFGL-10 with
  a 2.14 deg Gaussian gives 3.0 deg).  That resolution explains AFGL-10 but not
  AFGL-01 (19.25 deg becomes 19.46 deg): for AFGL-01 the fitted ``e`` is 17 %
  narrower than the measured half-peak width, the compromise of a one-parameter
  lobe fitted to three incidence angles.  The model is kept as printed.
* **Solar absorptance.**  Table 3's solar absorptances (0.77 for AFGL-01, 0.26
  for the white AFGL-10) are integrals over the solar spectrum, 0.3-2.5 um, where
  the paint's colour decides; the Table 4 parameters describe 4 um, where "the IR
  reflectance ... is independent of a sample's color" (§3.2).  Grey 4 um
  parameters give ``1 - rho(theta_i)`` of 0.893 and 0.904 at normal incidence, so
  the absorptances cannot be reproduced from Table 4: they need ``rho_D(lambda)``
  and ``epsilon(lambda)`` over the solar range (paper 001 Fig. 4 shows them only as
  curves).

References
----------
Sandford, B. P., "Infrared reflectance properties of aircraft paints" (paper 001),
§2.1 (Eqs. 5–6) and §4 (Eqs. 7–21, Tables 3–4).
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import geometry
from ..errors import ValidationError
from ._common import _cast_out, _check_theta_i, _facet_frame, _sin2
from ._model import Model, Parameter
from .robertson_sandford_angular import (
    _COS_FLOOR,
    CUTOFF_ANGLE,
    _cutoff_loss,
    _cutoff_over_cos,
    _e2_h_norm,
    _g_cs,
    angular_g,
    cutoff_factor,
    normalisation_G,
    normalisation_H,
    structure_h,
)

__all__ = [
    "CUTOFF_ANGLE",
    "MODEL",
    "PARAMS",
    "TABLE4",
    "angular_g",
    "brdf",
    "brdf_angles",
    "check_params",
    "cutoff_factor",
    "diffuse_brdf",
    "diffuse_reflectance",
    "directional_emissivity",
    "directional_hemispherical_reflectance",
    "normalisation_G",
    "normalisation_H",
    "render_grid",
    "specular_brdf",
    "specular_reflectance",
    "structure_h",
    "total_reflectance",
]

#: Domain of the lobe width e [1]: below 1e-12 the lobe is narrower than float64
#: unit vectors resolve (and h ~ e^-4 approaches the float64 range).
E_MIN = 1.0e-12
E_MAX = 1.0e6
B_MAX = 1.0e6

#: Paper 001 Table 4: the parameters of two aircraft paints at 4 um.
TABLE4: Mapping[str, Mapping[str, float]] = MappingProxyType(
    {
        "AFGL-01": MappingProxyType({"rho_D": 0.07, "epsilon": 0.85, "b": 0.12, "e": 0.12}),
        "AFGL-10": MappingProxyType({"rho_D": 0.05, "epsilon": 0.88, "b": 0.08, "e": 0.012}),
    }
)

#: The parameters: diffuse reflectance rho_D and emissivity epsilon (spectral),
#: grazing parameter b and lobe width e (scalar or per band); paper 001 Table 4.
PARAMETERS = (
    Parameter("rho_D", "1", "diffuse spectral reflectance (Robertson-Sandford rho_D)", lower=0.0),
    Parameter(
        "epsilon",
        "1",
        "spectral hemispherical emissivity (Robertson-Sandford)",
        lower=0.0,
        upper=1.0,
    ),
    Parameter(
        "b",
        "1",
        "grazing-angle parameter (Robertson-Sandford b)",
        lower=0.0,
        upper=B_MAX,
        spectral=False,
    ),
    Parameter(
        "e",
        "1",
        "specular lobe width (Robertson-Sandford e)",
        lower=E_MIN,
        upper=E_MAX,
        spectral=False,
    ),
)


# --------------------------------------------------------------------------
# parameters and directional quantities (Eqs. 8, 11, 17)
# --------------------------------------------------------------------------


def _rho_s_non_negative(p: dict[str, NDArray[np.float64]]) -> None:
    """The joint domain ``rho_D + epsilon <= G(b)``: Eq. 17's ``rho_s >= 0`` at every incidence."""
    g_b = normalisation_G(p["b"])
    total = p["rho_D"] + p["epsilon"]
    bad = total > g_b * (1.0 + 1e-12)
    if np.any(bad):
        raise ValidationError(
            f"rho_D + epsilon: got {total[bad][:5].tolist()} with G(b) = "
            f"{g_b[bad][:5].tolist()}; allowed domain is rho_D + epsilon <= G(b) "
            "(<= 1 for b = 0) so that rho_s of Eq. 17 is >= 0 at every incidence [1]"
        )


def directional_emissivity(
    theta: ArrayLike, wavelength: ArrayLike, **params: Any
) -> NDArray[np.float64]:
    """Directional spectral emissivity, paper 001 Eq. 8.

    Parameters
    ----------
    theta : array_like
        Polar angle [degree], ``0 <= theta <= 90``.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    **params
        ``rho_D``, ``epsilon``, ``b``, ``e`` (see :data:`MODEL`).

    Returns
    -------
    ndarray, shape theta.shape + (n_wl,)
        ``epsilon(lambda, theta) = epsilon(lambda) g(theta) / G(b)`` [1]; its
        cosine-weighted hemispherical mean is ``epsilon(lambda)``.

    Examples
    --------
    >>> p = TABLE4["AFGL-01"]
    >>> np.round(directional_emissivity([0.0, 60.0, 89.0], [4000.0], **p), 4).tolist()
    [[0.8931], [0.8561], [0.0185]]
    """
    p = MODEL.check_params(wavelength, **params)
    t = _check_theta_i(theta, "theta")[..., None]
    return p["epsilon"] * angular_g(t, p["b"]) / normalisation_G(p["b"])


def diffuse_reflectance(
    theta_i: ArrayLike, wavelength: ArrayLike, **params: Any
) -> NDArray[np.float64]:
    """Diffusely scattered fraction ``rho_d(lambda, theta_i)`` (integral of Eq. 13).

    Parameters
    ----------
    theta_i : array_like
        Incidence angle [degree], ``0 <= theta_i <= 90``.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    **params
        ``rho_D``, ``epsilon``, ``b``, ``e``.

    Returns
    -------
    ndarray, shape theta_i.shape + (n_wl,)
        ``rho_D g(theta_i) / G(b)`` [1]: the hemispherical integral of
        ``f_d cos(theta_r)`` of Eq. 13 (see the module notes on Eq. 13).

    Examples
    --------
    >>> np.round(diffuse_reflectance([0.0, 60.0], [4000.0], **TABLE4["AFGL-01"]), 4).tolist()
    [[0.0735], [0.0705]]
    """
    p = MODEL.check_params(wavelength, **params)
    t = _check_theta_i(theta_i)[..., None]
    return p["rho_D"] * angular_g(t, p["b"]) / normalisation_G(p["b"])


def specular_reflectance(
    theta_i: ArrayLike, wavelength: ArrayLike, **params: Any
) -> NDArray[np.float64]:
    """Specularly reflected fraction ``rho_s(lambda, theta_i)``, paper 001 Eq. 17.

    Parameters
    ----------
    theta_i : array_like
        Incidence angle [degree], ``0 <= theta_i <= 90``.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    **params
        ``rho_D``, ``epsilon``, ``b``, ``e``.

    Returns
    -------
    ndarray, shape theta_i.shape + (n_wl,)
        ``1 - (rho_D + epsilon) g(theta_i) / G(b)`` [1], ``>= 0`` on the domain.

    Examples
    --------
    >>> np.round(specular_reflectance([0.0, 60.0], [4000.0], **TABLE4["AFGL-01"]), 4).tolist()
    [[0.0334], [0.0734]]
    """
    p = MODEL.check_params(wavelength, **params)
    t = _check_theta_i(theta_i)[..., None]
    gi = angular_g(t, p["b"]) / normalisation_G(p["b"])
    return np.maximum(1.0 - (p["rho_D"] + p["epsilon"]) * gi, 0.0)


def total_reflectance(
    theta_i: ArrayLike, wavelength: ArrayLike, **params: Any
) -> NDArray[np.float64]:
    """Total (directional-hemispherical) reflectance without cut-off, paper 001 Eq. 11.

    Parameters
    ----------
    theta_i : array_like
        Incidence angle [degree], ``0 <= theta_i <= 90``.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    **params
        ``rho_D``, ``epsilon``, ``b``, ``e``.

    Returns
    -------
    ndarray, shape theta_i.shape + (n_wl,)
        ``rho_s + rho_d = 1 - epsilon(lambda, theta_i)`` [1] (paper 001 Fig. 9).

    Examples
    --------
    >>> np.round(total_reflectance([0.0, 60.0], [4000.0], **TABLE4["AFGL-01"]), 4).tolist()
    [[0.1069], [0.1439]]
    """
    return 1.0 - directional_emissivity(_check_theta_i(theta_i), wavelength, **params)


# --------------------------------------------------------------------------
# the BRDF (Eqs. 13, 15)
# --------------------------------------------------------------------------


def _terms(
    n: np.ndarray,
    s: np.ndarray,
    o: np.ndarray,
    cos_i: np.ndarray,
    cos_r: np.ndarray,
    p: dict[str, np.ndarray],
    cutoff: bool,
) -> tuple[np.ndarray, np.ndarray]:
    """Diffuse and specular BRDF [sr-1] (…, n_wl) for unit vectors (no masking)."""
    b, e = p["b"], p["e"]
    cos_i = np.clip(cos_i, 0.0, 1.0)[..., None]
    cos_r_c = np.clip(cos_r, 0.0, 1.0)[..., None]
    sin2_i = _sin2(n, s)[..., None]
    sin2_r = _sin2(n, o)[..., None]
    g_norm = normalisation_G(b)
    gi = _g_cs(cos_i**2, sin2_i, b)
    gr = _g_cs(cos_r_c**2, sin2_r, b)
    f_d = p["rho_D"] * gi * gr / (np.pi * g_norm**2)  # Eq. 13

    glint = geometry.half_vector(s, o)  # Eq. 5
    cos_a = np.einsum("...k,...k->...", glint, n)[..., None]  # Eq. 6
    sin2_a = _sin2(n, glint)[..., None]
    # h / H with h from Eq. 16 and e^2 H from Eq. 18: h/H = e^2 / ((e^2 cos^2 + sin^2)^2 e^2 H)
    e2 = e * e
    h_over_h = e2 / ((e2 * cos_a**2 + sin2_a) ** 2 * _e2_h_norm(cos_i, e))
    rho_s = np.maximum(1.0 - (p["rho_D"] + p["epsilon"]) * gi / g_norm, 0.0)  # Eq. 17
    if cutoff:
        geom = _cutoff_over_cos(cos_r_c, sin2_r, b)  # Eq. 21 / cos(theta_r)
    else:
        geom = 1.0 / np.maximum(cos_r_c, _COS_FLOOR)
    f_s = rho_s / (4.0 * np.pi) * h_over_h * geom  # Eq. 15
    return f_d, f_s


def _evaluate(
    normal: ArrayLike,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    wavelength: ArrayLike,
    params: dict[str, Any],
    cutoff: bool,
    which: str,
) -> np.ndarray:
    p = MODEL.check_params(wavelength, **params)
    n, s, o, cos_i, cos_r, mask, dtype = _facet_frame(normal, to_sun, to_observer)
    f_d, f_s = _terms(n, s, o, cos_i, cos_r, p, cutoff)
    f = {"diffuse": f_d, "specular": f_s, "total": f_d + f_s}[which]
    return _cast_out(np.where(mask[..., None], f, 0.0), dtype)


def diffuse_brdf(
    normal: ArrayLike,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    wavelength: ArrayLike,
    **params: Any,
) -> np.ndarray:
    """Diffuse R-S BRDF, paper 001 Eq. 13 (reciprocal, Eq. 12).

    Parameters
    ----------
    normal, to_sun, to_observer : array_like, shape (..., 3)
        Facet normal and directions to the source and observer [1].
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    **params
        ``rho_D``, ``epsilon``, ``b``, ``e`` (see :data:`MODEL`).

    Returns
    -------
    ndarray, shape broadcast(...) + (n_wl,)
        ``f_d = rho_D g(theta_i) g(theta_r) / (pi G(b)^2)`` [sr-1]; zero where unlit
        or unseen.

    Examples
    --------
    >>> n, s, o = [0.0, 0.0, 1.0], [0.5, 0.0, 1.0], [-0.5, 0.0, 1.0]
    >>> np.round(diffuse_brdf(n, s, o, [4000.0], **TABLE4["AFGL-01"]), 5).tolist()
    [0.02442]
    """
    return _evaluate(normal, to_sun, to_observer, wavelength, params, True, "diffuse")


def specular_brdf(
    normal: ArrayLike,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    wavelength: ArrayLike,
    *,
    cutoff: bool = True,
    **params: Any,
) -> np.ndarray:
    """Specular R-S BRDF, paper 001 Eqs. 15–18 with the cut-off of Eq. 21.

    Parameters
    ----------
    normal, to_sun, to_observer : array_like, shape (..., 3)
        Facet normal and directions to the source and observer [1].
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    cutoff : bool, default True
        Apply the grazing cut-off (Eq. 21, module notes).
    **params
        ``rho_D``, ``epsilon``, ``b``, ``e``.

    Returns
    -------
    ndarray, shape broadcast(...) + (n_wl,)
        ``f_s = rho_s(lambda, theta_i) h(alpha) c(theta_r) / (4 pi H(theta_i)
        cos(theta_r))`` [sr-1], with the glint vector of Eq. 5
        (:func:`sbrdf_xr.geometry.half_vector`, defined at phase angle 180 deg).  For
        ``b = 0`` (no cut-off) ``cos(theta_r)`` is floored at 1e-150, the only
        departure from Eq. 15, to keep the divergence at the horizon finite.

    Examples
    --------
    >>> n, s, o = [0.0, 0.0, 1.0], [0.5, 0.0, 1.0], [-0.5, 0.0, 1.0]
    >>> np.round(specular_brdf(n, s, o, [4000.0], **TABLE4["AFGL-01"]), 3).tolist()
    [0.258]
    """
    return _evaluate(normal, to_sun, to_observer, wavelength, params, cutoff, "specular")


def brdf(
    normal: ArrayLike,
    to_sun: ArrayLike,
    to_observer: ArrayLike,
    wavelength: ArrayLike,
    *,
    cutoff: bool = True,
    **params: Any,
) -> np.ndarray:
    """Robertson–Sandford spectral BRDF ``f_d + f_s`` (paper 001 Eqs. 13 and 15).

    Parameters
    ----------
    normal, to_sun, to_observer : array_like, shape (..., 3)
        Facet normal and directions to the source and observer [1]; need not be
        unit length; broadcast against each other.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    cutoff : bool, default True
        Apply the grazing cut-off of Eq. 21 to the specular term.
    rho_D, epsilon : array_like, scalar or shape (n_wl,)
        Diffuse reflectance and hemispherical emissivity [1].
    b, e : array_like, scalar or shape (n_wl,)
        Grazing-angle parameter and specular lobe width [1].

    Returns
    -------
    ndarray, shape broadcast(...) + (n_wl,)
        BRDF [sr-1]; exactly zero where ``N.s <= 0`` or ``N.o <= 0``.  Integrated
        over the hemisphere (``f_r cos(theta_r) dOmega_r``) it gives
        ``1 - epsilon(lambda, theta_i)`` (Eq. 11) without the cut-off, and
        :func:`directional_hemispherical_reflectance` with it.  Not reciprocal,
        as the paper's model is not: the specular term of Eq. 15 carries
        ``1 / cos(theta_r)`` and the incidence normalisation ``H(theta_i)`` of Eq. 18
        (the diffuse term, Eq. 13, is reciprocal, Eq. 12).

    Examples
    --------
    >>> n, s, o = [0.0, 0.0, 1.0], [0.5, 0.0, 1.0], [-0.5, 0.0, 1.0]
    >>> p = TABLE4["AFGL-01"]
    >>> np.round(brdf(n, s, o, [4000.0], **p), 3).tolist()  # the glint: diffuse + specular
    [0.282]
    """
    return _evaluate(normal, to_sun, to_observer, wavelength, params, cutoff, "total")


def directional_hemispherical_reflectance(
    theta_i: ArrayLike,
    wavelength: ArrayLike,
    *,
    cutoff: bool = True,
    **params: Any,
) -> NDArray[np.float64]:
    """Directional-hemispherical reflectance of the R-S model.

    Parameters
    ----------
    theta_i : array_like
        Incidence angle [degree], ``0 <= theta_i <= 90``.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    cutoff : bool, default True
        Include the grazing cut-off of Eq. 21 (as :func:`brdf` does).
    **params
        ``rho_D``, ``epsilon``, ``b``, ``e``.

    Returns
    -------
    ndarray, shape theta_i.shape + (n_wl,)
        Without the cut-off, the closed form of Eq. 11, ``1 - epsilon(lambda,
        theta_i)``.  With it, ``rho_d + rho_s (1 - L(theta_i))`` where the lost
        fraction ``L`` is computed by Gauss–Legendre quadrature on panels graded
        geometrically toward the lobe's peak and the horizon, over the band
        ``80 < theta_r < 90 deg`` in ``(theta_r, phi_r)``; it agrees with an
        adaptive cubature to ~1e-13 for the Table 4 paints and for needle lobes
        (``e = 1e-4``) at every ``theta_i`` up to 89.99 deg.

    Examples
    --------
    >>> p = TABLE4["AFGL-01"]
    >>> np.round(directional_hemispherical_reflectance([0.0, 60.0], [4000.0], **p), 4).tolist()
    [[0.1068], [0.1428]]
    >>> p = TABLE4["AFGL-01"]
    >>> r = directional_hemispherical_reflectance([0.0, 60.0], [4000.0], cutoff=False, **p)
    >>> np.round(r, 4).tolist()  # Eq. 11: 1 - epsilon(theta_i)
    [[0.1069], [0.1439]]
    """
    p = MODEL.check_params(wavelength, **params)
    ti = _check_theta_i(theta_i)
    rho_d = p["rho_D"] * angular_g(ti[..., None], p["b"]) / normalisation_G(p["b"])
    eps = p["epsilon"] * angular_g(ti[..., None], p["b"]) / normalisation_G(p["b"])
    rho_s = np.maximum(1.0 - rho_d - eps, 0.0)
    if not cutoff:
        return rho_d + rho_s
    # The loss depends on (theta_i, b, e) only: evaluate on the distinct (b, e) pairs.
    pairs, inverse = np.unique(np.stack([p["b"], p["e"]], axis=-1), axis=0, return_inverse=True)
    ti_rad = np.radians(ti.ravel())
    loss_pairs = np.stack([_cutoff_loss(ti_rad, bj, ej) for bj, ej in pairs], axis=-1)
    loss = loss_pairs[:, inverse.ravel()].reshape((*ti.shape, p["b"].size))
    # b = 0: no cut-off at all (d == 1).
    loss = np.where(p["b"] > 0, loss, 0.0)
    return rho_d + rho_s * (1.0 - loss)


#: The Robertson-Sandford model.
MODEL = Model(
    name="robertson_sandford",
    long_name="Robertson-Sandford semi-empirical paint model",
    brdf=brdf,
    parameters=PARAMETERS,
    citation="Sandford, paper 001, section 4, Eqs. 7-21 and Table 4",
    reflectance=directional_hemispherical_reflectance,
    constraint=_rho_s_non_negative,
)
PARAMS = MODEL.param_names
check_params, brdf_angles, render_grid = MODEL.check_params, MODEL.brdf_angles, MODEL.render_grid
