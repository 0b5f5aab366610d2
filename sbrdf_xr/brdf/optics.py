r"""Optical constants and exact Fresnel reflectances (bare interfaces and thin-film stacks).

Conventions: complex refractive index ``N = n + i k`` with ``k >= 0`` (absorbing),
time dependence ``exp(-i omega t)``; angles of incidence are given by their cosine
in the (real, non-absorbing) ambient medium.  Reflectances are for unpolarised
light, the mean of the s (TE) and p (TM) power reflectances.

Optical constants
-----------------
* :func:`aluminium_index`: Lorentz–Drude model of Rakić, Djurišić, Elazar and
  Majewski, Appl. Opt. 37, 5271 (1998), Table 1 (Al).
* :func:`gaas_index`: a documented *simple* dispersion model (see its docstring):
  Wemple–DiDomenico single-oscillator real index plus a parabolic direct-gap
  absorption edge.  Adequate for the reflectance of AR-coated GaAs cells (which is
  governed by ``n``), not for absorption calculations.
* :func:`silica_index` (Malitson 1965), :func:`sapphire_index` (Malitson & Dodge
  1972, ordinary ray), :func:`titania_index` (DeVore 1951, rutile ordinary ray):
  Sellmeier formulas of the bulk crystals/glass.  Deposited AR films are usually
  less dense than the bulk; :data:`FILM_INDEX` lists typical constant film
  indices (Macleod, *Thin-Film Optical Filters*, 4th ed., 2010, ch. 15).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import ValidationError, renamed_keywords
from ..units import to_unit
from . import _fresnel_kernels
from ._model import Parameter

__all__ = [
    "FILM_INDEX",
    "HC_EV_NM",
    "THIN_FILM_STACK",
    "aluminium_index",
    "fresnel_conductor",
    "fresnel_thin_film_stack",
    "gaas_index",
    "normal_incidence_reflectance",
    "sapphire_index",
    "silica_index",
    "titania_index",
]

#: h c in [eV nm] (CODATA 2018: 1239.841984...).
HC_EV_NM = 1239.8419843320026

#: Typical refractive indices of evaporated/sputtered AR-coating films in the
#: visible and near infrared [1] (Macleod 2010, ch. 15; Pulker, *Coatings on Glass*).
FILM_INDEX: dict[str, float] = {
    "MgF2": 1.38,
    "SiO2": 1.46,
    "Al2O3": 1.65,
    "Si3N4": 2.0,
    "Ta2O5": 2.1,
    "ZnS": 2.35,
    "TiO2": 2.4,
}

# Rakić et al. (1998) Table 1, aluminium, Lorentz–Drude (LD) model.
_AL_OMEGA_P = 14.98  # [eV]
_AL_F0 = 0.523
_AL_GAMMA0 = 0.047  # [eV]
_AL_OSC = np.array(  # f_j, Gamma_j [eV], omega_j [eV]
    [
        [0.227, 0.333, 0.162],
        [0.050, 0.312, 1.544],
        [0.166, 1.351, 1.808],
        [0.030, 3.382, 3.473],
    ]
)


def _check_wl(wavelength: ArrayLike) -> NDArray[np.float64]:
    wl = np.asarray(to_unit(wavelength, "nm", "wavelength", spectral=True))
    if not np.issubdtype(wl.dtype, np.number) or np.iscomplexobj(wl):
        raise ValidationError(f"wavelength: expected real numbers [nm], got dtype {wl.dtype}")
    wl = wl.astype(np.float64)
    if not np.all(np.isfinite(wl)) or np.any(wl <= 0):
        raise ValidationError(
            f"wavelength: got {wl[~(np.isfinite(wl) & (wl > 0))].ravel()[:5].tolist()}; "
            "allowed domain is finite wavelength > 0 [nm]"
        )
    return wl


def _sqrt_k_positive(eps: np.ndarray) -> np.ndarray:
    """``n + i k = sqrt(eps)`` on the branch with ``k >= 0``."""
    root = np.sqrt(eps.astype(np.complex128))
    return np.where(root.imag < 0, -root, root)


@renamed_keywords(wavelength_nm="wavelength")
def aluminium_index(wavelength: ArrayLike) -> NDArray[np.complex128]:
    """Complex refractive index of aluminium, Lorentz–Drude model of Rakić et al. (1998).

    ``eps(w) = 1 - f0 wp^2 / (w (w + i G0)) + sum_j f_j wp^2 / (w_j^2 - w^2 - i w G_j)``
    with ``w = hc / lambda`` [eV] and the Al parameters of Rakić et al., Appl. Opt.
    37, 5271 (1998), Table 1: ``wp = 14.98 eV``, ``f0 = 0.523``, ``G0 = 0.047 eV`` and
    four oscillators (f, G [eV], w [eV]) = (0.227, 0.333, 0.162), (0.050, 0.312,
    1.544), (0.166, 1.351, 1.808), (0.030, 3.382, 3.473).  The paper fits
    0.1–6 eV (about 200 nm – 12 µm).

    Parameters
    ----------
    wavelength : array_like
        Vacuum wavelength [nm].

    Returns
    -------
    ndarray of complex128
        ``n + i k`` [1] with ``k >= 0``.  Normal-incidence reflectance is ~0.92 in the
        visible with the interband absorption dip near 800 nm (1.5 eV).

    Examples
    --------
    >>> import numpy as np
    >>> np.round(aluminium_index([500.0, 800.0]), 3)  # the interband absorption near 800 nm
    array([0.761+5.9j  , 2.674+8.335j])
    """
    w = HC_EV_NM / _check_wl(wavelength)
    wp2 = _AL_OMEGA_P**2
    eps = 1.0 - _AL_F0 * wp2 / (w * (w + 1j * _AL_GAMMA0))
    f, gam, w0 = (_AL_OSC[:, k] for k in range(3))
    wj = w[..., None]
    eps = eps + np.sum(f * wp2 / (w0**2 - wj**2 - 1j * wj * gam), axis=-1)
    return _sqrt_k_positive(eps)


#: GaAs model constants: Wemple–DiDomenico oscillator energy and dispersion
#: energy [eV] (Wemple & DiDomenico, Phys. Rev. B 3, 1338 (1971), Table I), the
#: room-temperature direct gap [eV] (Blakemore, J. Appl. Phys. 53, R123 (1982)) and
#: the absorption-edge amplitude [1/cm/eV^0.5] (order of magnitude of the
#: measured edge, alpha ~ 1e4 cm-1 at 1.5 eV and ~4e4 cm-1 at 2 eV).
_GAAS_E0 = 3.55
_GAAS_ED = 33.5
_GAAS_EG = 1.424
_GAAS_A = 5.6e4
#: Photon energy above which the Wemple–DiDomenico n is held constant [eV].
_GAAS_E_CLIP = 2.7


@renamed_keywords(wavelength_nm="wavelength")
def gaas_index(wavelength: ArrayLike) -> NDArray[np.complex128]:
    """Complex refractive index of GaAs from a simple documented dispersion model.

    * Real part: Wemple–DiDomenico single-oscillator model,
      ``n^2 = 1 + E_d E_0 / (E_0^2 - E^2)`` with ``E_0 = 3.55 eV``, ``E_d = 33.5 eV``
      (Wemple & DiDomenico, Phys. Rev. B 3, 1338 (1971)); within ~2 % of measured
      data (Skauli et al. 2003 below the gap; Aspnes et al. 1986 above) from about
      480 nm to 2 µm.  The oscillator pole at ``E_0`` makes the formula diverge in
      the blue, so the photon energy is clipped at 2.7 eV (459 nm, ``n = 4.84``):
      below ~460 nm ``n`` is held constant (the measured ``n`` stays between 4.4
      and 5.0 down to 370 nm).
    * Imaginary part: parabolic direct-gap edge ``alpha = A sqrt(E - E_g)``,
      ``k = alpha lambda / (4 pi)``, ``E_g = 1.424 eV``, ``A = 5.6e4 cm-1 eV^-1/2``;
      ``k = 0`` below the gap.  It reproduces the magnitude of ``k`` (~0.1–0.2)
      between 1.5 and 2.5 eV and underestimates it near the E1 critical point
      (~3 eV, below ~450 nm).

    This is deliberately simple (no tabulated data ship with the package); use a
    measured table where absorption in the GaAs matters.

    Parameters
    ----------
    wavelength : array_like
        Vacuum wavelength [nm].

    Returns
    -------
    ndarray of complex128
        ``n + i k`` [1].

    Examples
    --------
    >>> import numpy as np
    >>> np.round(gaas_index([800.0]), 3)
    array([3.558+0.126j])
    """
    wl = _check_wl(wavelength)
    energy = np.minimum(HC_EV_NM / wl, _GAAS_E_CLIP)
    n = np.sqrt(1.0 + _GAAS_ED * _GAAS_E0 / (_GAAS_E0**2 - energy**2))
    alpha_cm = _GAAS_A * np.sqrt(np.maximum(HC_EV_NM / wl - _GAAS_EG, 0.0))
    k = alpha_cm * (wl * 1e-7) / (4.0 * np.pi)
    return n + 1j * k


def _sellmeier(wl_um: np.ndarray, b: Sequence[float], c: Sequence[float]) -> np.ndarray:
    n2 = 1.0 + sum(bi * wl_um**2 / (wl_um**2 - ci**2) for bi, ci in zip(b, c, strict=True))
    return np.sqrt(n2)


@renamed_keywords(wavelength_nm="wavelength")
def silica_index(wavelength: ArrayLike) -> NDArray[np.float64]:
    """Refractive index of fused silica, Sellmeier fit of Malitson, JOSA 55, 1205 (1965).

    Parameters
    ----------
    wavelength : array_like
        Vacuum wavelength [nm] (fit range 210–3710 nm).

    Returns
    -------
    ndarray
        ``n`` [1] (1.4585 at 587.6 nm).

    Examples
    --------
    >>> import numpy as np
    >>> np.round(silica_index([589.3]), 4)  # the sodium D line
    array([1.4584])
    """
    wl = _check_wl(wavelength) * 1e-3
    return _sellmeier(wl, (0.6961663, 0.4079426, 0.8974794), (0.0684043, 0.1162414, 9.896161))


@renamed_keywords(wavelength_nm="wavelength")
def sapphire_index(wavelength: ArrayLike) -> NDArray[np.float64]:
    """Ordinary index of sapphire (Al2O3), Malitson & Dodge, JOSA 62, 1405 (1972).

    Parameters
    ----------
    wavelength : array_like
        Vacuum wavelength [nm] (fit range 200–5500 nm).

    Returns
    -------
    ndarray
        ``n_o`` [1] (about 1.77 at 589 nm; deposited alumina films: ~1.65,
        :data:`FILM_INDEX`).

    Examples
    --------
    >>> import numpy as np
    >>> np.round(sapphire_index([589.3]), 4)
    array([1.7681])
    """
    wl = _check_wl(wavelength) * 1e-3
    return _sellmeier(wl, (1.4313493, 0.65054713, 5.3414021), (0.0726631, 0.1193242, 18.028251))


@renamed_keywords(wavelength_nm="wavelength")
def titania_index(wavelength: ArrayLike) -> NDArray[np.float64]:
    """Ordinary index of rutile TiO2, DeVore, JOSA 41, 416 (1951).

    ``n_o^2 = 5.913 + 0.2441 / (lambda^2 - 0.0803)`` with ``lambda`` in µm.

    Parameters
    ----------
    wavelength : array_like
        Vacuum wavelength [nm] (fit range 430–1530 nm).

    Returns
    -------
    ndarray
        ``n_o`` [1] (~2.65 at 550 nm; deposited films: 2.3–2.5, :data:`FILM_INDEX`).

    Examples
    --------
    >>> import numpy as np
    >>> np.round(titania_index([589.3]), 4)
    array([2.6129])
    """
    wl = _check_wl(wavelength) * 1e-3
    return np.sqrt(5.913 + 0.2441 / (wl**2 - 0.0803))


# --------------------------------------------------------------------------
# Fresnel
# --------------------------------------------------------------------------


def _check_cos(cos_theta: ArrayLike) -> NDArray[np.float64]:
    c = np.asarray(cos_theta)
    if not np.issubdtype(c.dtype, np.number) or np.iscomplexobj(c):
        raise ValidationError(f"cos_theta: expected real numbers [1], got dtype {c.dtype}")
    c = c.astype(np.float64)
    if not np.all(np.isfinite(c)) or np.any((c < 0) | (c > 1)):
        raise ValidationError(
            f"cos_theta: got {c[~(np.isfinite(c) & (c >= 0) & (c <= 1))].ravel()[:5].tolist()}; "
            "allowed domain is 0 <= cos_theta <= 1 [1]"
        )
    return c


def _check_index(index: ArrayLike, name: str) -> NDArray[np.complex128]:
    arr = np.asarray(index)
    if not np.issubdtype(arr.dtype, np.number):
        raise ValidationError(f"{name}: expected a (complex) refractive index, got {arr.dtype}")
    arr = arr.astype(np.complex128)
    if (not np.all(np.isfinite(arr))) or np.any(arr.real <= 0) or np.any(arr.imag < 0):
        flat = arr.ravel()
        raise ValidationError(
            f"{name}: got values with n <= 0, k < 0 or NaN (first: "
            f"{flat[~(np.isfinite(flat) & (flat.real > 0) & (flat.imag >= 0))][:3].tolist()}); "
            f"allowed domain is n > 0, k >= 0 for {name} = n + ik [1]"
        )
    return arr


def _q(index2: np.ndarray, sin2: np.ndarray) -> np.ndarray:
    """``N cos(theta_N) = sqrt(N^2 - n0^2 sin^2 theta_0)`` on the decaying branch."""
    root = np.sqrt(index2 - sin2 + 0j)
    return np.where(root.imag < 0, -root, root)


def fresnel_conductor(cos_theta: ArrayLike, n_complex: ArrayLike) -> NDArray[np.float64]:
    """Exact unpolarised Fresnel reflectance of a bare interface from vacuum/air.

    ``r_s = (cos t - q) / (cos t + q)``, ``r_p = (N^2 cos t - q) / (N^2 cos t + q)`` with
    ``q = sqrt(N^2 - sin^2 t)`` (``Im q >= 0``); ``R = (|r_s|^2 + |r_p|^2) / 2``.  Valid
    for any complex ``N = n + ik`` (dielectrics, ``k = 0``, included); at normal
    incidence ``R = ((n-1)^2 + k^2) / ((n+1)^2 + k^2)``, at grazing incidence ``R = 1``.

    Parameters
    ----------
    cos_theta : array_like
        Cosine of the angle of incidence [1], ``0 <= cos_theta <= 1``.
    n_complex : array_like
        Complex refractive index of the substrate ``n + ik`` [1]; broadcasts with
        ``cos_theta``.

    Returns
    -------
    ndarray
        Reflectance [1] in ``[0, 1]``.

    References
    ----------
    Born & Wolf, *Principles of Optics*, 7th ed., §1.5.2 and §14.2.

    Examples
    --------
    >>> import numpy as np
    >>> np.round(fresnel_conductor([1.0, 0.0], 1.5), 6)  # glass: 4 % at normal incidence, 1 grazing
    array([0.04, 1.  ])
    """
    c = _check_cos(cos_theta)
    n_c = _check_index(n_complex, "n_complex")
    if n_c.ndim == 1 and c.ndim >= 1 and c.shape[-1] in (1, n_c.size):
        # cosines (..., 1 | n_wl) against a spectrum: the compiled kernel, row by row
        flat = c.reshape(-1, c.shape[-1])
        out = _fresnel_kernels.conductor_reflectance(flat, n_c * n_c)
        return out.reshape(*c.shape[:-1], n_c.size)
    return _fresnel_conductor_numpy(c, n_c)


def _fresnel_conductor_numpy(c: np.ndarray, n_c: np.ndarray) -> NDArray[np.float64]:
    """:func:`fresnel_conductor` in numpy on checked inputs: the reference of the kernel."""
    c, n_c = np.broadcast_arrays(c, n_c)
    n2 = n_c * n_c
    q = _q(n2, 1.0 - c * c)
    r_s = (c - q) / (c + q)
    r_p = (n2 * c - q) / (n2 * c + q)
    return np.clip(0.5 * (np.abs(r_s) ** 2 + np.abs(r_p) ** 2), 0.0, 1.0)


def normal_incidence_reflectance(n_complex: ArrayLike) -> NDArray[np.float64]:
    """``((n-1)^2 + k^2) / ((n+1)^2 + k^2)`` [1] for ``N = n + ik`` [1] (Born & Wolf §14.2).

    Examples
    --------
    >>> round(float(normal_incidence_reflectance(1.5)), 6)
    0.04
    """
    n_c = _check_index(n_complex, "n_complex")
    return np.abs((n_c - 1) / (n_c + 1)) ** 2


#: The variables of a thin-film stack in a model material (:func:`fresnel_thin_film_stack`'s
#: ``layers``): the complex index of each layer ``(layer, wavelength)`` and its thickness.
THIN_FILM_STACK = (
    Parameter(
        "layer_n",
        "1",
        "thin-film layer refractive index (ambient side first)",
        lower=0.0,
        lower_open=True,
    ),
    Parameter("layer_k", "1", "thin-film layer extinction coefficient", lower=0.0),
    Parameter("layer_thickness", "nm", "thin-film layer thickness", lower=0.0, spectral=False),
)


def fresnel_thin_film_stack(
    cos_theta: ArrayLike,
    wavelength: ArrayLike,
    layers: Sequence[tuple[ArrayLike, float]],
    substrate: ArrayLike,
    ambient: float = 1.0,
) -> NDArray[np.float64]:
    """Exact unpolarised reflectance of a multilayer stack (characteristic matrices).

    For each polarisation the characteristic matrix of layer ``j`` (index ``N_j``,
    thickness ``d_j``, phase ``delta_j = 2 pi d_j q_j / lambda`` with
    ``q_j = sqrt(N_j^2 - n_0^2 sin^2 theta_0)``) is
    ``M_j = [[cos delta, -i sin delta / eta], [-i eta sin delta, cos delta]]``, with the
    tilted admittances ``eta = q`` (s) and ``eta = N^2 / q`` (p);
    ``[B, C] = prod_j M_j [1, eta_sub]`` and ``r = (eta_0 B - C) / (eta_0 B + C)``
    (Macleod, *Thin-Film Optical Filters*, 4th ed., §2.2–2.4, written there for
    ``N = n - ik``; the signs of the off-diagonal terms are conjugated here for the
    ``n + ik`` convention; Born & Wolf §1.6).
    Each matrix is multiplied by ``exp(i delta_j)`` (``|.| <= 1`` for absorbing layers),
    which cancels in ``r`` but keeps thick absorbing layers from overflowing, and the
    p-polarisation vectors are scaled by ``q`` so that no admittance is divided by a
    vanishing ``q`` at grazing incidence.

    Parameters
    ----------
    cos_theta : array_like
        Cosine of the angle of incidence in the ambient medium [1], in ``[0, 1]``.
    wavelength : array_like, shape (n_wl,)
        Vacuum wavelength [nm].
    layers : sequence of (index, thickness)
        From the ambient side down: complex index ``n + ik`` [1] (scalar or array
        of shape (n_wl,)) and physical thickness [nm] (``>= 0``).
    substrate : array_like
        Complex index of the substrate [1], scalar or shape (n_wl,).
    ambient : float, default 1.0
        Real index of the incidence medium [1].

    Returns
    -------
    ndarray, shape cos_theta.shape + (n_wl,)
        Unpolarised reflectance [1] in ``[0, 1]``.  With no layers (or only
        zero-thickness ones) this is :func:`fresnel_conductor`.  Interference
        extrema move to shorter wavelengths as the angle grows (``delta`` scales
        with ``cos theta_j``).

    Examples
    --------
    >>> import numpy as np
    >>> quarter_wave = [(1.38, 550.0 / (4 * 1.38))]  # MgF2 on glass, quarter-wave at 550 nm
    >>> np.round(fresnel_thin_film_stack([1.0], [550.0], quarter_wave, 1.5), 6)
    array([[0.01411]])
    """
    c = _check_cos(cos_theta)[..., None]
    return _stack_reflectance(c, wavelength, layers, substrate, ambient)


def _stack_inputs(
    wavelength: ArrayLike,
    layers: Sequence[tuple[ArrayLike, float]],
    substrate: ArrayLike,
    ambient: float,
) -> tuple[np.ndarray, list[tuple[np.ndarray, float]], np.ndarray, float]:
    """The checked inputs of a stack: wavelengths, ``(index, thickness)`` per layer (ambient
    side first, indices broadcast to the wavelengths), the substrate's index and ``n0``."""
    wl = np.atleast_1d(
        np.asarray(to_unit(wavelength, "nm", "wavelength", spectral=True), dtype=np.float64)
    )
    if wl.ndim != 1 or not np.all(np.isfinite(wl)) or np.any(wl <= 0):
        raise ValidationError(
            f"wavelength: expected a 1-D array of positive values [nm], got {wl!r}"
        )
    n_wl = wl.size
    if not (np.isfinite(ambient) and ambient > 0):
        raise ValidationError(f"ambient: got {ambient!r}; allowed domain is ambient > 0 [1]")

    def spectral(value: ArrayLike, name: str) -> np.ndarray:
        arr = _check_index(value, name)
        if arr.ndim > 1 or (arr.ndim == 1 and arr.size not in (1, n_wl)):
            raise ValidationError(
                f"{name}: expected a scalar or shape ({n_wl},) aligned with wavelength, "
                f"got shape {arr.shape}"
            )
        return np.broadcast_to(arr, (n_wl,))

    checked = []
    for j, layer in enumerate(layers):
        try:
            index, thickness = layer
        except (TypeError, ValueError) as exc:
            raise ValidationError(
                f"layers[{j}]: expected (index, thickness [nm]), got {layer!r}"
            ) from exc
        d = float(to_unit(thickness, "nm", f"layers[{j}] thickness"))
        if not (np.isfinite(d) and d >= 0):
            raise ValidationError(
                f"layers[{j}] thickness: got {thickness!r}; allowed domain is thickness >= 0 [nm]"
            )
        checked.append((spectral(index, f"layers[{j}] index"), d))
    return wl, checked, spectral(substrate, "substrate"), float(ambient)


def _stack_reflectance(
    c: np.ndarray,
    wavelength: ArrayLike,
    layers: Sequence[tuple[ArrayLike, float]],
    substrate: ArrayLike,
    ambient: float = 1.0,
) -> NDArray[np.float64]:
    """Stack reflectance for cosines ``c`` whose last axis is 1 or aligned with wavelength
    (the compiled kernel, :mod:`sbrdf_xr.brdf._fresnel_kernels`)."""
    wl, checked, n_sub, n0 = _stack_inputs(wavelength, layers, substrate, ambient)
    c = np.asarray(c, dtype=np.float64)
    if c.ndim == 0 or c.shape[-1] not in (1, wl.size):
        raise ValidationError(
            f"cos_theta: expected a last axis of 1 or {wl.size} (the wavelengths), got shape "
            f"{c.shape}"
        )
    k0 = 2.0 * np.pi / wl
    kd = np.array([2.0 * k0 * d for _, d in checked]).reshape(len(checked), wl.size)
    n2l = np.array([n * n for n, _ in checked], dtype=np.complex128).reshape(kd.shape)
    out = _fresnel_kernels.stack_reflectance(c.reshape(-1, c.shape[-1]), kd, n2l, n_sub**2, n0)
    return out.reshape(*c.shape[:-1], wl.size)


def _stack_reflectance_numpy(
    c: np.ndarray,
    wavelength: ArrayLike,
    layers: Sequence[tuple[ArrayLike, float]],
    substrate: ArrayLike,
    ambient: float = 1.0,
) -> NDArray[np.float64]:
    """:func:`_stack_reflectance` in numpy over whole arrays: the reference of the kernel."""
    wl, checked, n_sub, n0 = _stack_inputs(wavelength, layers, substrate, ambient)
    n_wl = wl.size
    sin2 = (n0 * n0) * (1.0 - c * c)  # n0^2 sin^2 theta0, shape (..., 1)
    q0 = n0 * c + 0j
    n2_sub = n_sub * n_sub
    q_sub = _q(n2_sub, sin2)
    # initial vectors [B, C]: s: [1, q_sub]; p: q_sub * [1, N^2/q_sub] = [q_sub, N^2]
    shape = np.broadcast_shapes(c.shape, (n_wl,))
    bs = np.ones(shape, dtype=np.complex128)
    cs = np.broadcast_to(q_sub, shape).astype(np.complex128)
    bp = np.broadcast_to(q_sub, shape).astype(np.complex128)
    cp = np.broadcast_to(n2_sub, shape).astype(np.complex128)
    k0 = 2.0 * np.pi / wl
    for n_j, d in reversed(checked):  # loop over layers, not samples
        n2 = n_j * n_j
        q = _q(n2, sin2)
        two_i_delta = 2j * k0 * d * q
        em1 = np.expm1(two_i_delta)  # E - 1, E = exp(2 i delta), |E| <= 1
        half_sum = 1.0 + 0.5 * em1  # (1 + E) / 2 = e^{i delta} cos(delta)
        small = np.abs(q) < 1e-150
        q_safe = np.where(small, 1.0, q)
        # e^{i delta} sin(delta) / q = (E - 1) / (2 i q) -> k0 d as q -> 0
        sin_over_q = np.where(small, k0 * d + 0j, em1 / (2j * q_safe))
        sin_times_q = em1 / 2j * q  # e^{i delta} sin(delta) * q
        # s: M = [[cos, -i sin/q], [-i q sin, cos]]
        bs, cs = half_sum * bs - 1j * sin_over_q * cs, -1j * sin_times_q * bs + half_sum * cs
        # p (eta = N^2/q): M = [[cos, -i q sin / N^2], [-i N^2 sin / q, cos]]
        bp, cp = (
            half_sum * bp - 1j * sin_times_q / n2 * cp,
            -1j * n2 * sin_over_q * bp + half_sum * cp,
        )
    r_s = (q0 * bs - cs) / (q0 * bs + cs)
    # p: eta_0 = n0^2 / q0; multiply numerator and denominator by q0
    r_p = (n0 * n0 * bp - q0 * cp) / (n0 * n0 * bp + q0 * cp)
    return np.clip(0.5 * (np.abs(r_s) ** 2 + np.abs(r_p) ** 2), 0.0, 1.0)
