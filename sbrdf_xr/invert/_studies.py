"""Calibration studies: how the inversions do on data of a known truth, over noise draws.

A pull ``(estimate - truth) / sigma`` of a calibrated estimator has mean 0 and width
(standard deviation) 1; its spread over ``n`` draws is about ``1 / sqrt(2 n)``.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import xarray as xr

from ..errors import FitQualityWarning, InversionError, renamed_keywords
from ..units import to_unit
from ._unmix import MATERIAL, unmix

__all__ = ["spin_recovery", "unmix_calibration"]


def unmix_calibration(
    terms: xr.DataArray,
    truth: Mapping[str, float],
    *,
    relative_noise: float = 0.03,
    n_draws: int = 200,
    seed: int = 0,
    **options: Any,
) -> xr.Dataset:
    """Pulls of :func:`unmix` over noise draws of a known mixture.

    The measurement is ``sum_m truth_m terms_m`` plus Gaussian noise of standard deviation
    ``relative_noise`` times its absolute value, fitted by :func:`unmix` (``options``
    passed on) with the true uncertainties.

    Returns
    -------
    xarray.Dataset
        Over ``material``: ``truth``, ``estimate_mean``, ``estimate_std``,
        ``uncertainty_median``, ``pull_mean``, ``pull_width``, ``coverage_1sigma``,
        ``coverage_2sigma`` (fractions of draws within 1 and 2 sigma), its binomial
        ``coverage_2sigma_uncertainty``, ``selected_fraction`` and, with
        ``method="posterior"`` (the posterior's median and sd then stand for the estimate
        and its uncertainty), ``coverage_interval`` (draws whose 2.5-97.5 % interval holds
        the truth); scalars ``n_draws``, ``quality_warnings`` (draws whose chi2
        left the central 99.8 % of its distribution) and ``seconds_per_fit``.

    Examples
    --------
    A unit cube, grey sides and red caps, at two geometries; 50 draws of 1 % noise:

    >>> import numpy as np, trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft, simulate
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> from sbrdf_xr.invert import unmix_calibration
    >>> mesh = trimesh.creation.box()
    >>> caps = np.abs(mesh.face_normals[:, 2]) > 0.5
    >>> mesh.visual.face_colors = np.where(caps[:, None], [255, 0, 0, 255], [128, 128, 128, 255])
    >>> box = load_spacecraft(mesh, {(255, 0, 0): "red", (128, 128, 128): "grey"})
    >>> wl = np.linspace(400.0, 1000.0, 13)
    >>> tables = {"grey": lambertian(0.5, wl, material="grey"),
    ...           "red": lambertian(np.linspace(0.1, 0.8, 13), wl, material="red")}
    >>> cube = simulate(Scene(box, tables, to_sun=[[0.6, 0.0, 0.8], [0.8, 0.0, 0.6]],
    ...                       to_observer=[[0.8, 0.0, 0.6], [0.0, 0.6, 0.8]],
    ...                       outputs=("signal", "per_material")))
    >>> study = unmix_calibration(cube.signal_material, {"grey": 0.8, "red": 1.5},
    ...                           relative_noise=0.01, n_draws=50)
    >>> study.pull_width.round(2).values.tolist(), int(study.n_draws)
    ([1.05, 1.0], 50)
    """
    names = [str(m) for m in terms[MATERIAL].values]
    missing = sorted(set(names) - set(truth))
    if missing:
        raise InversionError(f"truth: no value for {missing}; have {sorted(truth)}")
    t = xr.DataArray([float(truth[m]) for m in names], dims=MATERIAL, coords={MATERIAL: names})
    y0 = (terms * t).sum(MATERIAL)
    sigma = relative_noise * np.abs(y0) + 1e-300
    rng = np.random.default_rng(seed)
    est, unc, sel = (np.empty((n_draws, len(names))) for _ in range(3))
    inside = np.full((n_draws, len(names)), np.nan)
    n_warn = 0
    t0 = time.perf_counter()
    for i in range(n_draws):
        y = y0 + sigma * rng.normal(size=y0.shape)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", FitQualityWarning)
            fit = unmix(y, terms, sigma, **options)
        n_warn += any(issubclass(w.category, FitQualityWarning) for w in caught)
        est[i], unc[i], sel[i] = fit.scale.values, fit.scale_uncertainty.values, fit.selected.values
        if "posterior_median" in fit:  # method="posterior": its median, sd and 95 % interval
            est[i], unc[i] = fit.posterior_median.values, fit.posterior_sd.values
            lo, hi = fit.posterior_low.values, fit.posterior_high.values
            inside[i] = (lo <= t.values) & (t.values <= hi)
    dt = (time.perf_counter() - t0) / max(1, n_draws)
    pull = (est - t.values) / unc
    within = np.abs(pull)
    out = {
        "truth": (t.values, "true scale factor"),
        "estimate_mean": (est.mean(0), "mean of the estimates"),
        "estimate_std": (est.std(0), "standard deviation of the estimates"),
        "uncertainty_median": (np.median(unc, 0), "median of the stated uncertainties"),
        "pull_mean": (pull.mean(0), "mean of (estimate - truth) / uncertainty"),
        "pull_width": (pull.std(0), "standard deviation of (estimate - truth) / uncertainty"),
        "coverage_1sigma": ((within <= 1).mean(0), "fraction of draws within 1 sigma"),
        "coverage_2sigma": ((within <= 2).mean(0), "fraction of draws within 2 sigma"),
        "selected_fraction": (sel.mean(0), "fraction of draws keeping the material"),
        "coverage_interval": (
            inside.mean(0),
            "fraction of draws whose posterior 2.5-97.5 % interval holds the truth "
            "(method='posterior'; else NaN)",
        ),
        "coverage_2sigma_uncertainty": (
            np.full(len(names), np.sqrt(0.9545 * 0.0455 / max(n_draws, 1))),
            "binomial standard deviation of the 2-sigma coverage of a calibrated estimator "
            "over the draws, sqrt(p (1 - p) / n) with p = 0.9545",
        ),
    }
    ds = xr.Dataset(
        {k: (MATERIAL, v, {"units": "1", "long_name": ln}) for k, (v, ln) in out.items()},
        coords={MATERIAL: (MATERIAL, names, {"long_name": "material", "units": "1"})},
    )
    ds["n_draws"] = ((), n_draws, {"units": "1", "long_name": "noise draws"})
    ds["quality_warnings"] = (
        (),
        n_warn,
        {"units": "1", "long_name": "draws with a FitQualityWarning"},
    )
    ds["seconds_per_fit"] = ((), dt, {"units": "s", "long_name": "wall time per fit"})
    ds.attrs = {"relative_noise": relative_noise, "seed": seed, "options": repr(options)}
    return ds


@renamed_keywords(axis_tolerance_deg="axis_tolerance")
def spin_recovery(
    spacecraft: Any,
    observation: Any,
    *,
    periods: Sequence[float],
    bands: Sequence[str] = ("V", "R", "I"),
    relative_noise: float = 0.02,
    n_draws: int = 20,
    seed: int = 0,
    times: Any = None,
    axis_tolerance: float = 1.0,
    period_tolerance_sigma: float = 3.0,
    **options: Any,
) -> xr.Dataset:
    """Recovery of a spin state by :func:`fit_spin` over noise draws of a simulated pass.

    ``observation`` is an :class:`sbrdf_xr.observing.Observation` whose attitude is the
    truth, a :class:`~sbrdf_xr.observing.attitude.Spin` with an inertial initial attitude
    (its inertial axis ``R_initial axis_body``, period ``360 / rate``).  Its cube is
    simulated once (``times``: the UTC times measured, default all of the observation's);
    the fluxes ``band_signal (r_ref / range)**2`` get Gaussian noise of standard
    deviation ``relative_noise`` times ``(flux + 0.1 median flux)`` and are fitted with
    the observation as geometry (``options`` passed on to :func:`fit_spin`).  A draw
    succeeds when the axis is within ``axis_tolerance`` and the period within
    ``period_tolerance_sigma`` of its stated uncertainty.

    Parameters
    ----------
    spacecraft : Spacecraft
        The body.
    observation : Observation
        The pass, its attitude the truth.
    periods : sequence of float
        Candidate periods of the fits [s].
    bands : sequence of str
        Bands simulated and fitted.
    relative_noise : float
        Noise relative to the flux (see above).
    n_draws, seed : int
        Noise draws and the seed of the first.
    times : array_like of datetime64, optional
        The times measured.
    axis_tolerance : float
        Largest axis error of a success [degree].
    period_tolerance_sigma : float
        Largest period error of a success, in its uncertainties.
    **options
        Passed on to :func:`fit_spin`.

    A Quantity is converted to the unit of its argument.

    Returns
    -------
    xarray.Dataset
        Over ``draw``: ``axis_error`` [degree], ``axis_uncertainty`` [degree], ``period``,
        ``period_uncertainty`` [s], ``period_pull`` [1], ``reduced_chi_square``, ``success``,
        ``ambiguous`` (a twin fitted about as well), ``seconds`` (wall time of the fit);
        attributes ``truth_axis``, ``truth_period``, ``success_rate``, ``search_methods``
        and ``load_average`` (1-minute, before and after).

    Examples
    --------
    Two draws on 40 s of the built-in pass with a coarse grid (see the tests for the
    full study):

    >>> import numpy as np
    >>> from sbrdf_xr.body.spacecraft import canx1
    >>> from sbrdf_xr.invert import spin_recovery
    >>> from sbrdf_xr.observing.observe import canx1_pass
    >>> obs = canx1_pass()
    >>> study = spin_recovery(canx1(), obs, periods=np.linspace(85.0, 95.0, 5),
    ...                       times=obs.times[100:140], n_draws=2, n_axes=60, n_phases=12)
    >>> study.sizes["draw"], study.attrs["truth_period"]
    (2, 90.0)
    """
    periods = to_unit(periods, "s", "periods")
    axis_tolerance = to_unit(axis_tolerance, "deg", "axis_tolerance")
    import os

    from ..engine import Scene, simulate
    from ..geometry import rotation_matrices
    from ..observing import Inertial, Spin
    from ..observing.frames import axis_vector as body_axis
    from ._spin.fit import axis_separation, fit_spin

    law = observation.attitude
    if not isinstance(law, Spin) or not isinstance(law.initial, Inertial):
        raise InversionError(
            "spin_recovery: the observation's attitude must be a Spin with an inertial "
            f"initial attitude (the truth), got {law!r}"
        )
    q0 = law.initial.quaternions([0.0])
    axis_b = body_axis(law.axis_body, "axis_body")
    truth_axis = rotation_matrices(q0)[0] @ (axis_b / np.linalg.norm(axis_b))
    truth_period = 360.0 / abs(law.rate)
    if law.rate < 0:
        truth_axis = -truth_axis
    obs = observation if times is None else _at_times(observation, times)
    cube = simulate(
        Scene(spacecraft, observation=obs, outputs=("band_signal",), bands=tuple(bands))
    )
    rng_km = cube["range"].values
    flux = cube["band_signal"].values * (np.median(rng_km) / rng_km[:, None]) ** 2
    sigma = relative_noise * (flux + 0.1 * np.median(flux))
    rng = np.random.default_rng(seed)
    rows: dict[str, list[float]] = {
        k: []
        for k in (
            "axis_error",
            "axis_uncertainty",
            "period",
            "period_uncertainty",
            "period_pull",
            "reduced_chi_square",
            "success",
            "ambiguous",
            "seconds",
        )
    }
    methods: list[str] = []
    load0 = os.getloadavg()[0]
    for _ in range(n_draws):
        noisy = flux + sigma * rng.normal(size=flux.shape)
        lc = xr.Dataset(
            {"flux": ("obs", noisy.ravel()), "flux_uncertainty": ("obs", sigma.ravel())},
            coords={
                "time": ("obs", np.repeat(cube["time"].values, len(bands))),
                "band": ("obs", np.tile(list(bands), cube.sizes["time"])),
            },
        )
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FitQualityWarning)
            fit = fit_spin(lc, spacecraft, obs, periods=periods, axis_body=axis_b, **options)
        dt = time.perf_counter() - t0
        err = axis_separation(fit["axis_vector"].values, truth_axis)
        pull = (float(fit["period"]) - truth_period) / float(fit["period_uncertainty"])
        ok = err <= axis_tolerance and abs(pull) <= period_tolerance_sigma
        methods.append(str(fit.attrs["search_method"]))
        for k, v in (
            ("axis_error", err),
            ("axis_uncertainty", float(fit["axis_uncertainty"])),
            ("period", float(fit["period"])),
            ("period_uncertainty", float(fit["period_uncertainty"])),
            ("period_pull", pull),
            ("reduced_chi_square", float(fit["reduced_chi_square"])),
            ("success", float(ok)),
            ("ambiguous", float(fit.attrs["ambiguity"] != "none")),
            ("seconds", dt),
        ):
            rows[k].append(v)
    units = {"axis_error": "degree", "axis_uncertainty": "degree", "period": "s"}
    units["period_uncertainty"] = units["seconds"] = "s"
    ds = xr.Dataset(
        {
            k: (
                "draw",
                np.asarray(v),
                {"units": units.get(k, "1"), "long_name": k.replace("_", " ")},
            )
            for k, v in rows.items()
        },
        coords={"draw": ("draw", np.arange(n_draws), {"long_name": "noise draw", "units": "1"})},
    )
    ds.attrs = {
        "truth_axis": str(np.round(truth_axis, 6).tolist()),
        "truth_period": truth_period,
        "success_rate": float(np.mean(rows["success"])) if n_draws else float("nan"),
        "load_average": f"{load0:.2f} before, {os.getloadavg()[0]:.2f} after",
        "n_values": int(flux.size),
        "relative_noise": relative_noise,
        "search_methods": ", ".join(f"{m} x {methods.count(m)}" for m in dict.fromkeys(methods)),
    }
    return ds


def _at_times(observation: Any, times: Any) -> Any:
    import dataclasses

    return dataclasses.replace(observation, times=np.asarray(times))
