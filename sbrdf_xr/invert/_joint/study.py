"""Calibration study of :func:`sbrdf_xr.invert.fit_observation` over noise draws of a
simulated pass.

A pull ``(estimate - truth) / sigma`` of a calibrated estimator has mean 0 and width
(standard deviation) 1; its spread over ``n`` draws is about ``1 / sqrt(2 n)``.
"""

from __future__ import annotations

import dataclasses
import os
import time
import warnings
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from ...errors import ChainLengthWarning, FitQualityWarning, InversionError, renamed_keywords
from ...units import to_unit
from .._areas import material_areas
from .._spin.search import spin_model, vec
from .fit import fit_observation

__all__ = ["COVERAGE_2SIGMA", "observation_recovery", "simulated_light_curve"]

#: Probability of a Gaussian estimate within 2 sigma of the truth.
COVERAGE_2SIGMA = 0.9545


def simulated_light_curve(
    spacecraft: Any,
    observation: Any,
    spin: Mapping[str, Any],
    *,
    area_fraction: Mapping[str, float],
    extinction: Mapping[str, float],
    bands: Sequence[str] = ("V", "R", "I"),
    axis_body: ArrayLike = (0.0, 0.0, 1.0),
    system: str = "Vega",
    zero_point: Mapping[str, float] | None = None,
    brightness: Mapping[str, Any] | None = None,
    effects: Sequence[str] = (),
) -> tuple[xr.Dataset, float]:
    """Noise-free magnitudes of a pass, one band per time in turn, and the wall time [s] of
    the :func:`sbrdf_xr.engine.simulate` call.

    The pass is simulated with the spin (a mapping as :func:`fit_observation` takes it)
    and ``outputs=("signal", "per_material")``; the spectral signal of each material,
    its area scaled to ``area_fraction`` of the mesh's total, is band-integrated by
    :func:`sbrdf_xr.photometry.magnitudes` (the cube's range and Sun distance), and
    ``k_b X + z_b`` is added with the cube's air mass.  Times in the Earth's umbra or
    below the horizon are left out.  A truth other than the fit's model: ``brightness``
    scales a material's signal (``{"white-paint-a276": 1.1}``: its table 10 % too dark;
    ``{"white-paint-a276": {"V": 1.05, "I": 1.2}}``: per band, a colour too),
    ``effects`` adds effects of :func:`sbrdf_xr.engine.simulate` (``("shadowing",)``).

    Examples
    --------
    >>> from sbrdf_xr.body.spacecraft import canx1
    >>> from sbrdf_xr.invert import simulated_light_curve
    >>> from sbrdf_xr.observing.observe import canx1_pass
    >>> spin = {"axis_longitude": 215.0, "axis_latitude": 40.0, "period": 57.0, "phase": 30.0}
    >>> lc, seconds = simulated_light_curve(
    ...     canx1(), canx1_pass(), spin, extinction={"V": 0.2, "R": 0.1, "I": 0.05},
    ...     area_fraction={"aluminium-6061-t6": 0.15, "tjpv-cell": 0.30,
    ...                    "white-paint-a276": 0.55})
    >>> lc.sizes["obs"], lc.band.values[:4].tolist(), lc.attrs["magnitude_system"]
    (261, ['V', 'R', 'I', 'V'], 'Vega')
    """
    from ...engine import Scene, simulate
    from ...photometry import magnitudes

    epoch = spin.get("epoch")
    law = spin_model(
        axis_body,
        vec(float(spin["axis_longitude"]), float(spin["axis_latitude"])),
        float(spin["period"]),
        float(spin["phase"]),
        epoch=None if epoch is None else np.datetime64(str(epoch)),
    )
    obs = dataclasses.replace(observation, attitude=law)
    t0 = time.perf_counter()
    cube = simulate(
        Scene(
            spacecraft,
            observation=obs,
            outputs=("signal", "per_material"),
            effects=("sunlight", *effects),
        )
    )
    seconds = time.perf_counter() - t0
    areas = material_areas(spacecraft)
    missing = sorted(set(areas) - set(area_fraction))
    if missing:
        raise InversionError(f"area_fraction: no value for {missing}; have {sorted(area_fraction)}")
    total = sum(areas.values())
    names = [str(m) for m in cube["material"].values]
    gain = brightness or {}

    def gains(m: str) -> list[float]:  # a factor, or one per band {band: factor}
        g = gain.get(m, 1.0)
        return [float(g.get(b, 1.0)) if isinstance(g, Mapping) else float(g) for b in bands]

    scale = xr.DataArray(
        [[area_fraction[m] * total / areas[m] * f for f in gains(m)] for m in names],
        dims=("material", "band"),
        coords={"material": names, "band": list(bands)},
    )
    per = cube[["signal_material"]].rename(signal_material="signal")
    mm = magnitudes(per, list(bands), system=system)
    mixed = (10 ** (-0.4 * mm) * scale.sel(band=mm["band"])).sum("material")
    flux = mixed.transpose("time", "band").values
    with np.errstate(divide="ignore"):
        mix = -2.5 * np.log10(flux)
    x = cube["airmass"].values
    zp = zero_point or {}
    extra = np.array([[extinction[b] * xi + zp.get(b, 0.0) for b in bands] for xi in x])
    m = mix + extra
    ok = (cube["sunlit_fraction"].values > 0) & (cube["elevation"].values > 0)
    idx = np.flatnonzero(ok)
    band_i = np.arange(idx.size) % len(bands)
    vals = m[idx, band_i]
    lc = xr.Dataset(
        {
            "magnitude": ("obs", vals, {"units": "1", "long_name": "simulated magnitude"}),
            "uncertainty": ("obs", np.zeros(idx.size), {"units": "1", "long_name": "1-sigma"}),
        },
        coords={
            "time": ("obs", cube["time"].values[idx]),
            "band": ("obs", np.array(bands)[band_i]),
        },
        attrs={"magnitude_system": system},
    )
    return lc, seconds


def _wrap(d: float, period: float) -> float:
    return (d + 0.5 * period) % period - 0.5 * period


@renamed_keywords(noise_mag="noise", phase_symmetry_deg="phase_symmetry")
def observation_recovery(
    spacecraft: Any,
    observation: Any,
    spin: Mapping[str, Any],
    *,
    area_fraction: Mapping[str, float],
    extinction: Mapping[str, float],
    bands: Sequence[str] = ("V", "R", "I"),
    axis_body: ArrayLike = (0.0, 0.0, 1.0),
    noise: float = 0.02,
    n_draws: int = 20,
    seed: int = 0,
    start_offset: Mapping[str, float] | None = None,
    phase_symmetry: float = 360.0,
    brightness: Mapping[str, Any] | None = None,
    effects: Sequence[str] = (),
    **options: Any,
) -> xr.Dataset:
    """Pulls and coverage of :func:`fit_observation` over noise draws of a simulated pass.

    The truth (``spin``, ``area_fraction``, ``extinction``) is simulated once by
    :func:`simulated_light_curve`; every draw adds Gaussian noise of ``noise`` [mag]
    and is fitted by :func:`fit_observation` (``options`` passed on, ``check=False``)
    from the truth moved by ``start_offset``: ``axis`` [degree] towards the north,
    ``period`` [s], ``phase`` [degree] (default 2 deg, 0.05 s, 5 deg).  The phase is
    compared modulo ``phase_symmetry`` (180 for a body that looks the same turned half
    a turn about its spin axis; a Quantity is converted).  ``brightness`` and ``effects``
    make the truth other than the fit's model (see :func:`simulated_light_curve`): the
    pulls then measure what a model error does to the stated uncertainties, and
    ``quality_warnings`` how often the fit says so.  A spin parameter's pull divides by
    half its 2-sigma half-interval on the truth's side (``lower_2sigma``,
    ``upper_2sigma``: the profile's are asymmetric, ``intervals="profile"``), so that
    ``|pull| <= 2`` is the truth inside the interval.

    Parameters
    ----------
    spacecraft, observation, spin, area_fraction, extinction, bands, axis_body
        The truth, as for :func:`simulated_light_curve`.
    noise : float or Quantity
        Standard deviation of the Gaussian noise of each magnitude [mag].
    n_draws, seed : int
        Noise draws and the seed of the generator.
    start_offset : mapping, optional
        How far from the truth each fit starts.
    phase_symmetry : float or Quantity
        Period of the phase's symmetry [degree] (360, or 180 for a two-fold body).
    brightness, effects, **options
        See above.

    Returns
    -------
    xarray.Dataset
        Over ``parameter``: ``truth``, ``estimate_mean``, ``estimate_std``,
        ``uncertainty_median``, ``pull_mean``, ``pull_width``, ``coverage_1sigma``,
        ``coverage_2sigma`` and its binomial ``coverage_2sigma_uncertainty``; ``pull``
        over (``draw``, ``parameter``); ``axis_error`` [degree] over ``draw``; scalars
        ``n_draws``, ``quality_warnings``, ``chain_warnings`` and ``posterior_to_point``
        (with ``method="posterior"``: draws with a ChainLengthWarning, the median cost of
        the sampling over its point fit),
        ``seconds_per_fit`` (median), ``simulate_seconds`` (one
        :func:`sbrdf_xr.engine.simulate` of the measured times with the per-material
        output, best of 3 in the same run) and ``fit_to_simulate``.

    Examples
    --------
    Three draws on the built-in CanX-1 pass (more in the tests and docs/guide/inversion.md):

    >>> from sbrdf_xr.body.spacecraft import canx1
    >>> from sbrdf_xr.invert import observation_recovery
    >>> from sbrdf_xr.observing.observe import canx1_pass
    >>> study = observation_recovery(
    ...     canx1(), canx1_pass(),
    ...     {"axis_longitude": 215.0, "axis_latitude": 40.0, "period": 57.0, "phase": 30.0},
    ...     area_fraction={"aluminium-6061-t6": 0.15, "tjpv-cell": 0.30,
    ...                    "white-paint-a276": 0.55},
    ...     extinction={"V": 0.22, "R": 0.15, "I": 0.09}, n_draws=3, phase_symmetry=180.0)
    >>> int(study.n_draws), study.parameter.values[:4].tolist()
    (3, ['axis_longitude', 'axis_latitude', 'period', 'phase'])
    """
    phase_symmetry = to_unit(phase_symmetry, "deg", "phase_symmetry")
    noise = to_unit(noise, "mag", "noise")
    truth_spin = {k: float(spin[k]) for k in ("axis_longitude", "axis_latitude", "period", "phase")}
    epoch = spin.get("epoch", np.asarray(observation.times)[0])
    lc0, _ = simulated_light_curve(
        spacecraft,
        observation,
        {**truth_spin, "epoch": epoch},
        area_fraction=area_fraction,
        extinction=extinction,
        bands=bands,
        axis_body=axis_body,
        brightness=brightness,
        effects=effects,
    )
    obs_at = dataclasses.replace(observation, times=np.unique(lc0["time"].values))
    sim_s = min(  # the baseline: simulate of the measured times, warm, best of 3 in this run
        simulated_light_curve(
            spacecraft,
            obs_at,
            {**truth_spin, "epoch": epoch},
            area_fraction=area_fraction,
            extinction=extinction,
            bands=bands,
            axis_body=axis_body,
        )[1]
        for _ in range(3)
    )
    start, a0 = _offset_start(truth_spin, epoch, start_offset)
    truth = {**truth_spin}
    truth.update({f"extinction_{b}": float(extinction[b]) for b in bands})
    truth.update({f"area_fraction_{m}": float(v) for m, v in area_fraction.items()})
    rng = np.random.default_rng(seed)
    rows: list[dict[str, tuple[float, float]]] = []
    ax_err, secs = [], []
    n_warn = n_chain = 0
    post_cost: list[float] = []
    load0 = os.getloadavg()[0]
    for _ in range(n_draws):
        lc = lc0.copy()
        lc["magnitude"] = lc0["magnitude"] + rng.normal(0.0, noise, lc0.sizes["obs"])
        lc["uncertainty"] = lc0["uncertainty"] + noise
        t0 = time.perf_counter()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", FitQualityWarning)
            warnings.simplefilter("always", ChainLengthWarning)
            fit = fit_observation(lc, spacecraft, obs_at, start, check=False, **options)
        secs.append(time.perf_counter() - t0)
        n_warn += any(issubclass(w.category, FitQualityWarning) for w in caught)
        n_chain += any(issubclass(w.category, ChainLengthWarning) for w in caught)
        if "posterior_seconds" in fit.attrs:
            post_cost.append(fit.attrs["posterior_seconds"] / fit.attrs["fit_seconds"])
        rows.append(_draw_row(fit, truth, bands, phase_symmetry))
        cosang = float(np.clip(fit["axis_vector"].values @ a0, -1.0, 1.0))
        ax_err.append(float(np.degrees(np.arccos(cosang))))
    ds = _recovery_statistics(rows, truth, n_draws, ax_err)
    per_fit = float(np.median(secs)) if secs else float("nan")
    scalars = {
        "n_draws": (n_draws, "1", "noise draws"),
        "quality_warnings": (n_warn, "1", "draws with a FitQualityWarning"),
        "seconds_per_fit": (per_fit, "s", "median wall time of a fit"),
        "simulate_seconds": (
            sim_s,
            "s",
            "wall time of one simulate of the measured times (per material, best of 3)",
        ),
        "fit_to_simulate": (per_fit / sim_s, "1", "wall time per fit over that of one simulate"),
        "chain_warnings": (n_chain, "1", "draws with a ChainLengthWarning (method='posterior')"),
        "posterior_to_point": (
            float(np.median(post_cost)) if post_cost else float("nan"),
            "1",
            "median wall time of the posterior sampling over that of its point fit",
        ),
    }
    for k, (v, u, ln) in scalars.items():
        ds[k] = ((), v, {"units": u, "long_name": ln})
    ds.attrs = {
        "n_values": int(lc0.sizes["obs"]),
        "noise_mag": noise,
        "seed": seed,
        "start": ", ".join(f"{k} {v}" for k, v in start.items()),
        "phase_symmetry_deg": phase_symmetry,
        "load_average": f"{load0:.2f} before, {os.getloadavg()[0]:.2f} after",
        "options": repr(options),
    }
    return ds


def _offset_start(
    truth_spin: dict[str, float], epoch: Any, start_offset: Mapping[str, float] | None
) -> tuple[dict[str, Any], np.ndarray]:
    """The fits' start: the truth moved by ``start_offset`` (axis [degree] north, period
    [s], phase [degree]); and the true axis."""
    from .._spin.refine import tangent_frame

    off = {"axis": 2.0, "period": 0.05, "phase": 5.0, **(start_offset or {})}
    a0 = vec(truth_spin["axis_longitude"], truth_spin["axis_latitude"])
    a1 = a0 + np.radians(off["axis"]) * tangent_frame(a0)[1]
    lon = float(np.degrees(np.arctan2(a1[1], a1[0])) % 360.0)
    lat = float(np.degrees(np.arcsin(a1[2] / np.linalg.norm(a1))))
    start = {
        "axis_longitude": lon,
        "axis_latitude": lat,
        "period": truth_spin["period"] + off["period"],
        "phase": truth_spin["phase"] + off["phase"],
        "epoch": str(np.datetime64(str(epoch), "ns")),
    }
    return start, a0


def _draw_row(
    fit: xr.Dataset, truth: dict[str, float], bands: Sequence[str], phase_symmetry: float
) -> dict[str, tuple[float, float]]:
    """(estimate, uncertainty) of every parameter of one draw's fit (the posterior's
    median and sd when sampled); angles wrapped next to the truth."""
    spin_keys = ("axis_longitude", "axis_latitude", "period", "phase")
    row = {k: (float(fit[k]), float(fit[k + "_uncertainty"])) for k in spin_keys}
    for b in bands:
        row[f"extinction_{b}"] = (
            float(fit.extinction_coefficient.sel(band=b)),
            float(fit.extinction_coefficient_uncertainty.sel(band=b)),
        )
    for m in fit["material"].values:
        row[f"area_fraction_{m}"] = (
            float(fit.area_fraction.sel(material=m)),
            float(fit.area_fraction_uncertainty.sel(material=m)),
        )
    if "posterior_median" in fit:  # method="posterior": its median and sd
        post = fit.set_index(posterior_parameter="posterior_parameter")
        for k in list(row):
            key = k.replace("area_fraction_", "fraction_")
            row[k] = (
                float(post.posterior_median.sel(posterior_parameter=key)),
                float(post.posterior_sd.sel(posterior_parameter=key)),
            )
    for k, per in (("phase", phase_symmetry), ("axis_longitude", 360.0)):
        row[k] = (truth[k] + _wrap(row[k][0] - truth[k], per), row[k][1])
    if "lower_2sigma" in fit and "posterior_median" not in fit:  # the side's half-interval
        for k in spin_keys:
            est, fit_est = row[k][0], float(fit[k])
            side = "lower_2sigma" if est > truth[k] else "upper_2sigma"
            half = abs(float(fit[side].sel(parameter=k)) - fit_est) / 2.0
            row[k] = (est, half if half > 0 else row[k][1])
    return row


def _recovery_statistics(
    rows: list[dict[str, tuple[float, float]]],
    truth: dict[str, float],
    n_draws: int,
    ax_err: list[float],
) -> xr.Dataset:
    """Per parameter over the draws: truth, mean and spread of the estimates, pulls and
    coverage; the pull of every draw and the angle of its axis from the truth [degree]."""
    names = [k for k in truth if k in rows[0]] if rows else list(truth)
    values = np.array([[r[k] for k in names] for r in rows]).reshape(n_draws, len(names), 2)
    est, unc = values[..., 0], values[..., 1]
    tv = np.array([truth[k] for k in names])
    pull = (est - tv) / unc
    stats = {
        "truth": (tv, "true value"),
        "estimate_mean": (est.mean(0), "mean of the estimates"),
        "estimate_std": (est.std(0), "standard deviation of the estimates"),
        "uncertainty_median": (np.median(unc, 0), "median of the stated uncertainties"),
        "pull_mean": (pull.mean(0), "mean of (estimate - truth) / uncertainty"),
        "pull_width": (pull.std(0), "standard deviation of (estimate - truth) / uncertainty"),
        "coverage_1sigma": ((np.abs(pull) <= 1).mean(0), "fraction of draws within 1 sigma"),
        "coverage_2sigma": ((np.abs(pull) <= 2).mean(0), "fraction of draws within 2 sigma"),
        "coverage_2sigma_uncertainty": (
            np.full(len(names), np.sqrt(COVERAGE_2SIGMA * (1 - COVERAGE_2SIGMA) / max(n_draws, 1))),
            "binomial standard deviation of the 2-sigma coverage of a calibrated estimator "
            "over the draws, sqrt(p (1 - p) / n) with p = 0.9545",
        ),
    }
    units = ["degree", "degree", "s", "degree"] + ["1"] * (len(names) - 4)
    ds = xr.Dataset(
        {k: ("parameter", v, {"units": "1", "long_name": ln}) for k, (v, ln) in stats.items()},
        coords={
            "parameter": ("parameter", names, {"units": "1", "long_name": "fitted parameter"}),
            "parameter_units": ("parameter", units, {"units": "1", "long_name": "unit"}),
            "draw": ("draw", np.arange(n_draws), {"units": "1", "long_name": "noise draw"}),
        },
    )
    for k in ("truth", "estimate_mean", "estimate_std", "uncertainty_median"):
        ds[k].attrs["long_name"] += " (units: parameter_units)"
    ds["pull"] = (("draw", "parameter"), pull, {"units": "1", "long_name": "pull of the draw"})
    ds["axis_error"] = (
        "draw",
        np.asarray(ax_err),
        {"units": "degree", "long_name": "angle between the fitted and the true spin axis"},
    )
    return ds
