"""Inversion: what a measured spectrum or colour light curve says about the spacecraft.

Two inverse problems built on the forward model:

:func:`unmix`
    The signal is linear in each material's effective area (paper 000 Eq. 3 is a sum
    over facets, grouped here by material: ``S = sum_m a_m S_m``), so a measured
    spectrum (or band fluxes), at one geometry or over a time series, gives the area
    scale factors ``a_m`` by weighted non-negative least squares on the per-material
    terms of a simulation (Lawson & Hanson 1974, *Solving Least Squares Problems*,
    ch. 23, as :func:`scipy.optimize.nnls`).  Uncertainties are the linearised
    covariance ``(A^T W A)^-1`` (Press et al., *Numerical Recipes*, 3rd ed., §15.4);
    which materials are present is chosen by the Akaike or Bayesian information
    criterion over subsets of a candidate library (Burnham & Anderson 2002, §2.2, §6.4:
    ``AIC = chi2 + 2k``, ``BIC = chi2 + k ln n`` for Gaussian errors of known variance);
    pairs of materials whose estimates are correlated beyond a threshold are reported
    as degenerate.
:func:`fit_spin`
    Spin axis (two angles of the inertial axis of a known body axis), period and phase
    of a uniform spin (:class:`sbrdf_xr.observing.attitude.Spin`) fitted to a colour light curve:
    a global search over a Fibonacci sphere of axes x periods x phases, evaluating every
    candidate with the compiled kernel on band pre-integrated tables (threads: the
    kernel releases the GIL), with the unknown flux scale of each band (or one common
    scale) solved analytically, then local refinement by
    :func:`scipy.optimize.least_squares`; uncertainties from its Jacobian.

Measured fluxes are in any unit proportional to the band signal (the scale is fitted);
magnitudes are converted to relative fluxes ``10**(-0.4 m)`` with uncertainties
``sigma_F = F ln(10)/2.5 sigma_m`` (first order).
"""

from ..errors import InversionError
from ._bench import benchmark_spin_search
from ._data import band_terms, magnitudes_to_signal, read_spectrum
from ._spin import axis_separation, axis_vector, fit_spin
from ._spin_search import fibonacci_sphere, light_curve_fluxes, spin_model
from ._unmix import DEGENERACY_THRESHOLD, material_areas, unmix

__all__ = [
    "DEGENERACY_THRESHOLD",
    "InversionError",
    "axis_separation",
    "axis_vector",
    "band_terms",
    "benchmark_spin_search",
    "fibonacci_sphere",
    "fit_spin",
    "light_curve_fluxes",
    "magnitudes_to_signal",
    "material_areas",
    "read_spectrum",
    "spin_model",
    "unmix",
]
