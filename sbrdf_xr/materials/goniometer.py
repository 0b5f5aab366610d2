"""A virtual goniospectrometer: samples any material with the scheme of paper 000.

Paper 000 §3.1 (Fig. 6, Table 1) measures a material at a few fixed incidence
angles; at each, 28 reflection geometries are tabulated: seven ``delta_theta``
rows (three quarters, half and a quarter of the extent on the far side of
specular, specular itself, and a quarter, half and three quarters of the extent
on the source side) times four ``phi`` columns (0, a third, two thirds of the
row's extent, and the extent itself).  The extents are *reference points*, where
the signal has fallen into the noise and the reflectance is taken as zero: the
``phi`` extent of every row, and the two ``delta_theta`` extents (in the plane).
That makes 21 measured spectra and 9 reference points per incidence angle for a
specular material; where the apparatus limit comes before the noise (diffuse
materials), the extent is measured instead of being a zero reference point.

The extents are found as the paper's operator found them: walking away from
specular until the signal falls below the noise floor, within what the apparatus
can reach (the observer above ``max_theta_r`` is too close to the horizon; closer
than ``min_phase_angle`` to the source it obscures the beam).

Angles [degree] and wavelengths [nm] also come as astropy Quantities, converted first
(:func:`sbrdf_xr.units.to_unit`; another kind raises :class:`~sbrdf_xr.errors.UnitError`).

The sampled material is the ground truth, so the error of a look-up table built
from the measurement set (:func:`sbrdf_xr.materials.tables.build_lut`) is measurable.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from .._names import DELTA_THETA, MEASURED, PHI, SAMPLE, THETA_I, WAVELENGTH, attrs
from ..errors import ValidationError
from ..units import to_unit

__all__ = ["PAPER_THETA_I", "measure", "paper_scheme", "scheme_extents"]

#: Incidence angles [degree] used in the examples: aluminium was measured from 30
#: deg, the solar cell and the paint from 10 deg (paper 000 §4.2).
PAPER_THETA_I = {
    "aluminium": (30.0, 40.0, 50.0, 60.0, 70.0),
    "default": (10.0, 25.0, 40.0, 55.0, 70.0),
}

#: Table 1's fractions of the extents along the rows and columns.
ROW_FRACTIONS_FAR = (0.75, 0.5, 0.25)
ROW_FRACTIONS_NEAR = (0.25, 0.5, 0.75)
COLUMN_FRACTIONS = (0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0)

#: A callable returning spectra [sr-1], shape (n, n_wavelength), for 1-D angle arrays.
SpectrumFunc = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]


def paper_scheme(
    theta_i: float,
    dt_min: float,
    dt_max: float,
    phi_max: Sequence[float] | ArrayLike,
    in_noise: Sequence[bool] | ArrayLike | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Reflection geometries of paper 000 Table 1 at one incidence angle.

    Parameters
    ----------
    theta_i : float
        Incidence angle [degree].
    dt_min, dt_max : float
        ``delta_theta`` extents (reference points) on the source side (< 0) and
        the far side (> 0) [degree].
    phi_max : sequence of 7 floats
        ``phi`` extent of each row, in the row order ``0.75, 0.5, 0.25`` of
        ``dt_max``, 0, ``0.25, 0.5, 0.75`` of ``dt_min`` [degree].
    in_noise : sequence of 9 bools, optional
        Which extents are reference points (see :func:`scheme_extents`); default
        all, as in the paper's Table 1.

    Returns
    -------
    delta_theta, phi : ndarray, shape (30,)
        Geometries [degree]: 7 rows x 4 columns, then the two in-plane extents.
    reference : ndarray of bool, shape (30,)
        True for the reference points (9 when every extent is in the noise).

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials.goniometer import paper_scheme
    >>> dt, ph, ref = paper_scheme(30.0, -20.0, 30.0, [10, 12, 14, 16, 14, 12, 10])
    >>> dt.shape, int(ref.sum())
    ((30,), 9)
    >>> dt[:4], np.round(ph[:4], 4)
    (array([22.5, 22.5, 22.5, 22.5]), array([ 0.    ,  3.3333,  6.6667, 10.    ]))
    >>> ref[:4]
    array([False, False, False,  True])
    """
    theta_i = to_unit(theta_i, "deg", "theta_i")
    dt_min, dt_max = to_unit(dt_min, "deg", "dt_min"), to_unit(dt_max, "deg", "dt_max")
    phi_max = np.asarray(to_unit(phi_max, "deg", "phi_max"), dtype=np.float64)
    if phi_max.shape != (7,):
        raise ValidationError(f"phi_max: need one extent per row (7), got shape {phi_max.shape}")
    if not (dt_min < 0 < dt_max):
        raise ValidationError(
            f"delta_theta extents must satisfy min < 0 < max, got {dt_min}, {dt_max}"
        )
    rows = np.array(
        [f * dt_max for f in ROW_FRACTIONS_FAR] + [0.0] + [f * dt_min for f in ROW_FRACTIONS_NEAR]
    )
    cols = np.asarray(COLUMN_FRACTIONS)
    dt = np.concatenate([np.repeat(rows, cols.size), [dt_max, dt_min]])
    ph = np.concatenate([(phi_max[:, None] * cols).ravel(), [0.0, 0.0]])
    flags = np.ones(9, dtype=bool) if in_noise is None else np.asarray(in_noise, dtype=bool)
    if flags.shape != (9,):
        raise ValidationError(
            f"in_noise: need 9 flags (7 phi extents, dt_max, dt_min), got {flags.shape}"
        )
    ref = np.concatenate([((cols == 1.0)[None, :] & flags[:7, None]).ravel(), flags[7:]])
    return dt, ph, ref


def _walk_out(
    signal: Callable[[np.ndarray], np.ndarray], limit: float, floor: float, step: float
) -> tuple[float, bool]:
    """First coordinate from 0 towards ``limit`` where ``signal`` drops below ``floor``.

    Returns the coordinate and whether the signal fell into the noise there (True:
    a reference point) or the apparatus limit was reached first (False: a
    measured point).
    """
    n = max(int(np.ceil(abs(limit) / step)), 1)
    xs = np.linspace(0.0, limit, n + 1)[1:]
    below = signal(xs) < floor
    if not np.any(below):
        return float(limit), False
    return float(xs[np.argmax(below)]), True


def scheme_extents(
    func: SpectrumFunc,
    theta_i: float,
    *,
    noise_floor: float,
    max_theta_r: float = 88.0,
    min_phase_angle: float = 5.0,
    max_phi: float = 89.0,
    step: float = 0.1,
) -> tuple[float, float, np.ndarray, np.ndarray]:
    """Extents of the sampling scheme where the signal falls below the noise.

    Parameters
    ----------
    func : callable
        Ground-truth spectra ``func(theta_i, delta_theta, phi) -> (n, n_wavelength)``
        [sr-1].
    theta_i : float
        Incidence angle [degree].
    noise_floor : float
        Band-averaged sBRDF below which the signal is noise [sr-1].
    max_theta_r : float, default 88
        Largest reachable in-plane observer angle from the normal [degree].
    min_phase_angle : float, default 5
        Smallest source-observer separation that does not obscure the beam [degree].
    max_phi : float, default 89
        Largest reachable angle from the illumination plane [degree].
    step : float, default 0.1
        Search step [degree].

    Returns
    -------
    dt_min, dt_max : float
        ``delta_theta`` extents [degree].
    phi_max : ndarray, shape (7,)
        ``phi`` extent of each row [degree].
    in_noise : ndarray of bool, shape (9,)
        Whether each extent (the 7 ``phi`` extents, then ``dt_max`` and ``dt_min``)
        is where the signal fell into the noise (a reference point, zero) rather
        than an apparatus limit (a measured point).

    Examples
    --------
    A Gaussian lobe falls below a noise floor of 0.05 sr-1 at about 23 deg either side of
    specular, long before the apparatus limits: every extent is a reference point.

    >>> import numpy as np
    >>> from sbrdf_xr.materials.goniometer import scheme_extents
    >>> from sbrdf_xr.testing import lobe_function
    >>> dt_min, dt_max, phi_max, in_noise = scheme_extents(
    ...     lobe_function(np.array([500.0, 700.0])), 30.0, noise_floor=0.05
    ... )
    >>> round(dt_min, 6), round(dt_max, 6), phi_max.shape, bool(in_noise.all())
    (-22.8, 22.8, (7,), True)
    """
    noise_floor = float(to_unit(noise_floor, "sr-1", "noise_floor"))
    theta_i = float(to_unit(theta_i, "deg", "theta_i"))
    max_theta_r = float(to_unit(max_theta_r, "deg", "max_theta_r"))
    min_phase_angle = float(to_unit(min_phase_angle, "deg", "min_phase_angle"))
    max_phi = float(to_unit(max_phi, "deg", "max_phi"))
    step = float(to_unit(step, "deg", "step"))

    def band(ti: float, dt: np.ndarray, ph: np.ndarray) -> np.ndarray:
        return np.mean(func(np.full(dt.shape, ti), dt, ph), axis=-1)

    def row(d: float) -> Callable[[np.ndarray], np.ndarray]:
        return lambda x: band(theta_i, np.full(x.shape, d), x)

    far_limit = max_theta_r - theta_i
    near_limit = max(-max_theta_r - theta_i, -2.0 * theta_i + min_phase_angle)
    if not (near_limit < 0 < far_limit):
        raise ValidationError(
            f"theta_i = {theta_i}: the apparatus limits leave no room on both sides of specular"
        )
    dt_max, ref_max = _walk_out(lambda x: band(theta_i, x, 0 * x), far_limit, noise_floor, step)
    dt_min, ref_min = _walk_out(lambda x: band(theta_i, x, 0 * x), near_limit, noise_floor, step)
    rows = np.array(
        [f * dt_max for f in ROW_FRACTIONS_FAR] + [0.0] + [f * dt_min for f in ROW_FRACTIONS_NEAR]
    )
    walks = [_walk_out(row(d), max_phi, noise_floor, step) for d in rows]
    phi_max = np.array([w[0] for w in walks])
    in_noise = np.array([w[1] for w in walks] + [ref_max, ref_min])
    return dt_min, dt_max, phi_max, in_noise


def measure(
    func: SpectrumFunc,
    wavelength: ArrayLike,
    theta_i: Sequence[float] = PAPER_THETA_I["default"],
    *,
    noise_floor: float | None = None,
    dynamic_range: float = 1e-2,
    noise: float = 0.0,
    seed: int | None = 0,
    material: str = "unnamed",
    source: str = "synthetic",
    provenance: str = "",
    **limits: float,
) -> xr.Dataset:
    """Measure a material with the virtual goniospectrometer.

    Parameters
    ----------
    func : callable
        Ground truth ``func(theta_i, delta_theta, phi) -> spectra (n, n_wavelength)``
        [sr-1] for 1-D angle arrays [degree].
    wavelength : array_like
        Wavelengths of ``func``'s spectra [nm].
    theta_i : sequence of float
        Fixed incidence angles [degree] (paper: five).
    noise_floor : float, optional
        Band-averaged sBRDF below which the signal is indistinguishable from noise
        [sr-1] (the reference points).  Default: ``dynamic_range`` times the
        specular (``delta_theta = phi = 0``) band-averaged sBRDF at each incidence
        angle, as for an instrument whose gain is set on the specular peak.
    dynamic_range : float, default 1e-2
        Ratio of the noise floor to the specular signal when ``noise_floor`` is
        not given [1].
    noise : float, default 0
        Relative standard deviation of multiplicative Gaussian noise on the
        measured spectra [1] (clipped at zero).
    seed : int, optional
        Seed of the noise generator.
    material, source, provenance : str
        Attributes of the measurement set.
    **limits
        Apparatus limits passed to :func:`scheme_extents`.

    Returns
    -------
    xarray.Dataset
        The measurement set consumed by :func:`sbrdf_xr.materials.tables.build_lut`.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials.goniometer import measure
    >>> from sbrdf_xr.testing import lobe_function
    >>> wl = np.array([500.0, 700.0])
    >>> meas = measure(lobe_function(wl), wl, (20.0, 50.0), noise_floor=0.05, material="lobe")
    >>> dict(meas.sizes), int(meas.reference.sum()), meas.attrs["material"]
    ({'sample': 60, 'wavelength': 2}, 18, 'lobe')
    >>> sorted(meas.coords)
    ['delta_theta', 'phi', 'reference', 'theta_i', 'wavelength']
    """
    noise_floor = to_unit(noise_floor, "sr-1", "noise_floor")
    wl = np.asarray(to_unit(wavelength, "nm", "wavelength", spectral=True), dtype=np.float64)
    tis = np.asarray(to_unit(theta_i, "deg", "theta_i"), dtype=np.float64)
    if tis.size == 0:
        raise ValidationError("theta_i: need at least one incidence angle")
    if noise < 0:
        raise ValidationError(f"noise: relative noise must be >= 0, got {noise}")
    if noise_floor is not None and not noise_floor > 0:
        raise ValidationError(f"noise_floor: must be > 0 sr-1, got {noise_floor}")
    if not 0 < dynamic_range < 1:
        raise ValidationError(f"dynamic_range: must lie in (0, 1), got {dynamic_range}")
    specular = np.mean(func(tis, np.zeros_like(tis), np.zeros_like(tis)), axis=-1)
    floors = (
        np.full(tis.shape, noise_floor) if noise_floor is not None else dynamic_range * specular
    )
    ti_all, dt_all, ph_all, ref_all = [], [], [], []
    for t, floor in zip(tis, floors, strict=True):
        dt_min, dt_max, phi_max, in_noise = scheme_extents(
            func, float(t), noise_floor=float(floor), **limits
        )
        dt, ph, ref = paper_scheme(float(t), dt_min, dt_max, phi_max, in_noise)
        ti_all.append(np.full(dt.shape, t))
        dt_all.append(dt)
        ph_all.append(ph)
        ref_all.append(ref)
    ti_s, dt_s, ph_s, ref = (np.concatenate(a) for a in (ti_all, dt_all, ph_all, ref_all))
    spectra = np.asarray(func(ti_s, dt_s, ph_s), dtype=np.float64)
    if spectra.shape != (ti_s.size, wl.size):
        raise ValidationError(
            f"func: returned shape {spectra.shape}, expected {(ti_s.size, wl.size)}"
        )
    if noise > 0:
        rng = np.random.default_rng(seed)
        spectra = np.maximum(spectra * (1.0 + noise * rng.standard_normal(spectra.shape)), 0.0)
    spectra[ref] = 0.0
    return xr.Dataset(
        {MEASURED: ((SAMPLE, WAVELENGTH), spectra, attrs(MEASURED))},
        coords={
            THETA_I: (SAMPLE, ti_s, attrs(THETA_I)),
            DELTA_THETA: (SAMPLE, dt_s, attrs(DELTA_THETA)),
            PHI: (SAMPLE, ph_s, attrs(PHI)),
            "reference": (SAMPLE, ref, attrs("reference")),
            WAVELENGTH: (WAVELENGTH, wl, attrs(WAVELENGTH)),
        },
        attrs={
            "material": material,
            "source": source,
            "provenance": provenance,
            "scheme": "paper 000 Fig. 6 / Table 1 (virtual goniospectrometer)",
            "noise_floor": floors,
            "relative_noise": noise,
        },
    )
