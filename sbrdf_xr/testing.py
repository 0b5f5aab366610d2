"""Factories of small labelled objects for tests, notebooks and benchmarks.

Importable as ``sbrdf_xr.testing`` so that every user of the package can build the
same tiny materials, measurement sets and spacecraft the test-suite uses.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

# ----------------------------------------------------------------- materials


def lobe_function(
    wavelength: np.ndarray,
    *,
    diffuse: float = 0.02,
    peak: float = 2.0,
    width: float = 6.0,
):
    """A smooth analytic sBRDF: a diffuse floor plus a Gaussian specular lobe.

    ``f = diffuse * s(lambda) + peak * s(lambda) * exp(-(dt**2 + phi**2) / (2 w(ti)**2))``
    with ``w(ti) = width * (1 + ti/90)`` [degree] and a gentle spectral slope
    ``s(lambda)`` (0.8-1.2 over 400-1100 nm).  Not a physical model: a
    ground truth with known structure for tests of the table machinery.

    Parameters
    ----------
    wavelength : ndarray
        Wavelengths [nm].
    diffuse, peak : float
        Diffuse and peak sBRDF [sr-1].
    width : float
        Lobe standard deviation at normal incidence [degree].

    Returns
    -------
    callable
        ``func(theta_i, delta_theta, phi) -> (n, n_wavelength)`` [sr-1].
    """
    wl = np.asarray(wavelength, dtype=np.float64)
    s = 0.8 + 0.4 * (wl - 400.0) / 700.0

    def func(ti: np.ndarray, dt: np.ndarray, ph: np.ndarray) -> np.ndarray:
        ti, dt, ph = (np.asarray(a, dtype=np.float64)[..., None] for a in (ti, dt, ph))
        w = width * (1.0 + ti / 90.0)
        return diffuse * s + peak * s * np.exp(-(dt**2 + ph**2) / (2.0 * w**2))

    return func


def make_measurements(
    n_wavelength: int = 31,
    theta_i: tuple[float, ...] = (10.0, 25.0, 40.0, 55.0, 70.0),
    noise: float = 0.0,
    **kwargs: float,
) -> xr.Dataset:
    """A small measurement set of :func:`lobe_function` on the paper-000 scheme.

    Parameters
    ----------
    n_wavelength : int
        Number of wavelengths between 400 and 1100 nm.
    theta_i : tuple of float
        Incidence angles [degree].
    noise : float
        Relative noise [1].
    **kwargs
        Passed to :func:`lobe_function`.

    Returns
    -------
    xarray.Dataset
    """
    from .goniometer import measure

    wl = np.linspace(400.0, 1100.0, n_wavelength)
    return measure(lobe_function(wl, **kwargs), wl, theta_i, noise=noise,
                   noise_floor=0.05, material="test-lobe",
                   provenance="sbrdf_xr.testing.lobe_function")


def make_material(
    n_wavelength: int = 11,
    *,
    value: float | None = None,
    theta_i: np.ndarray | None = None,
    delta_theta: np.ndarray | None = None,
    phi: np.ndarray | None = None,
    dtype: type = np.float64,
) -> xr.DataArray:
    """A small material table: constant ``value`` or :func:`lobe_function` on a grid.

    Parameters
    ----------
    n_wavelength : int
        Wavelengths between 400 and 1100 nm.
    value : float, optional
        Constant sBRDF [sr-1] everywhere (a Lambertian table when the grid spans
        the hemisphere); default the lobe function.
    theta_i, delta_theta, phi : ndarray, optional
        Grids [degree]; defaults 0-90 step 10, -60..40 step 10, 0..30 step 5.
    dtype : numpy dtype
        dtype of the values.

    Returns
    -------
    xarray.DataArray
    """
    from .material import new_material

    wl = np.linspace(400.0, 1100.0, n_wavelength)
    ti = np.arange(0.0, 91.0, 10.0) if theta_i is None else np.asarray(theta_i, float)
    dt = np.arange(-60.0, 41.0, 10.0) if delta_theta is None else np.asarray(delta_theta, float)
    ph = np.arange(0.0, 31.0, 5.0) if phi is None else np.asarray(phi, float)
    if value is None:
        g = np.meshgrid(ti, dt, ph, indexing="ij")
        vals = lobe_function(wl)(*(a.ravel() for a in g)).reshape(ti.size, dt.size, ph.size, -1)
    else:
        vals = np.full((ti.size, dt.size, ph.size, wl.size), value)
    return new_material(vals.astype(dtype), ti, dt, ph, wl, material="test-material",
                        source="synthetic", provenance="sbrdf_xr.testing.make_material")

# ---------------------------------------------------------------- spacecraft
