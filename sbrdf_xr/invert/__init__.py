"""Inversion: what a measured spectrum or colour light curve says about the spacecraft.

Inverse problems built on the forward model:

:func:`unmix`
    The signal is linear in each material's effective area (paper 000 Eq. 3 is a sum
    over facets, grouped here by material: ``S = sum_m a_m S_m``), so a measured
    spectrum (or band fluxes), at one geometry or over a time series, gives the area
    scale factors ``a_m`` by weighted linear least squares on the per-material terms of
    a simulation, with the covariance ``(A^T W A)^-1`` (Press et al., *Numerical
    Recipes*, 3rd ed., §15.4).  Subsets of a candidate library are ranked by the Akaike
    or Bayesian information criterion (Burnham & Anderson 2002, §2.2, §6.4: ``AIC =
    chi2 + 2k``, ``BIC = chi2 + k ln n`` for Gaussian errors of known variance) and
    weighted; a material is left out only if its omission cannot bias the other
    estimates by more than :data:`DROP_BIAS` of their sigma, so that the uncertainties
    of the chosen model stay calibrated.  Pairs of materials whose estimates are
    correlated beyond a threshold are reported as degenerate.  ``total_area`` makes the
    fitted areas add up to a known total, the mesh's (equality-constrained least
    squares, Seber & Lee 2003, *Linear Regression Analysis*, §3.8).
:func:`fit_spin`
    Spin axis (two angles of the inertial axis of a known body axis), period and phase
    of a uniform spin (:class:`sbrdf_xr.observing.attitude.Spin`) fitted to a colour
    light curve, with the geometry of an observation, a cube over time, or inertial
    vectors: a global search over a Fibonacci sphere of axes x periods x phases, every
    candidate evaluated with the compiled kernel on band pre-integrated tables (exactly,
    or from spin-angle tables checked against the exact model), with the unknown flux
    scale of each band (or one common scale) solved analytically; then local refinement
    by :func:`scipy.optimize.least_squares` from the best candidates, the lowest
    chi-square reported with its ambiguous twins; uncertainties from the Jacobian.

:func:`fit_observation`
    The two together, with the atmosphere, on calibrated magnitudes measured over a pass
    (an :class:`sbrdf_xr.observing.Observation`): the spin state, the first-order
    extinction coefficient of each band against the pass's air mass, optionally zero
    points, and the area fraction of each material (adding up to the mesh's area, or
    free scales), fitted at once by :func:`scipy.optimize.least_squares` from a start such
    as :func:`fit_spin`'s, every material's band signal recomputed with the compiled
    kernel for each spin state; uncertainties and correlations from the Jacobian.

All three check their chi-square against its distribution and warn
(:class:`~sbrdf_xr.errors.FitQualityWarning`) when the fit is not to be taken at face
value.  :func:`unmix_calibration`, :func:`spin_recovery` and :func:`observation_recovery`
measure, over noise draws of a known truth, how well the stated uncertainties hold.

Measured fluxes are in any unit proportional to the band signal (the scale is fitted);
magnitudes are converted to relative fluxes ``10**(-0.4 m)`` with uncertainties
``sigma_F = F ln(10)/2.5 sigma_m`` (first order).  A spin fit with one scale for every
band (``offset="common"``) compares band colours, so it puts the model's in the
magnitude system the light curve states (AB or Vega).
"""

from ..errors import FitQualityWarning, InversionError
from ._areas import material_areas
from ._data import band_terms, magnitudes_to_signal, measured_kind, read_spectrum
from ._joint.fit import JOINT_CAUSES, fit_observation
from ._joint.study import observation_recovery, simulated_light_curve
from ._spin.bench import benchmark_spin_bound, benchmark_spin_search
from ._spin.data import light_curve_fluxes
from ._spin.fit import (
    AMBIGUITY_CHI2,
    SEARCH_BYTES_LIMIT,
    SEARCH_WORK_LIMIT,
    axis_separation,
    axis_vector,
    check_search_size,
    fit_spin,
    period_grid,
    search_size,
)
from ._spin.search import fibonacci_sphere, spin_model
from ._studies import spin_recovery, unmix_calibration
from ._unmix import DEGENERACY_THRESHOLD, DROP_BIAS, unmix

__all__ = [
    "AMBIGUITY_CHI2",
    "DEGENERACY_THRESHOLD",
    "DROP_BIAS",
    "JOINT_CAUSES",
    "SEARCH_BYTES_LIMIT",
    "SEARCH_WORK_LIMIT",
    "FitQualityWarning",
    "InversionError",
    "axis_separation",
    "axis_vector",
    "band_terms",
    "benchmark_spin_bound",
    "benchmark_spin_search",
    "check_search_size",
    "fibonacci_sphere",
    "fit_observation",
    "fit_spin",
    "light_curve_fluxes",
    "magnitudes_to_signal",
    "material_areas",
    "measured_kind",
    "observation_recovery",
    "period_grid",
    "read_spectrum",
    "search_size",
    "simulated_light_curve",
    "spin_model",
    "spin_recovery",
    "unmix",
    "unmix_calibration",
]
