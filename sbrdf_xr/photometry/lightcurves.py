"""Measured light curves: reading, fitting a simulated curve, the comparison figure."""

from __future__ import annotations

from itertools import pairwise
from typing import Any

import numpy as np
import xarray as xr

from .._names import ATTITUDE, BAND, PHASE_ANGLE, attrs
from ..errors import ValidationError
from .bands import _canonical
from .measured import MIN_UNCERTAINTY


def _periodic_model_flux(angles: np.ndarray, flux: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Linear interpolation of a light curve periodic in 360 degrees."""
    return np.interp(np.mod(at, 360.0), np.mod(angles, 360.0), flux, period=360.0)


def compare_light_curves(
    measured: xr.Dataset,
    simulated_mags: xr.DataArray,
    *,
    fit_phase: bool = True,
    period_s: float | None = None,
    phase_angle: float | None = None,
    n_scan: int = 720,
    epoch: Any = None,
    extinction: Any = None,
) -> xr.Dataset:
    """Fit a simulated light curve to a measured one: magnitude and rotation-phase offsets.

    Model: ``m_meas,i = m_sim,b_i(theta_i + phi) + dm`` with the simulated curve
    interpolated linearly in flux, periodic in 360 degrees.  For a given ``phi`` the
    offset is the analytic weighted mean ``dm = sum w r / sum w`` (``w = 1/sigma**2``,
    ``r = m_meas - m_sim``), minimising ``chi2 = sum w (r - dm)**2``.  ``phi`` is found
    by a scan of ``n_scan`` equally spaced values over [0, 360) and a bounded Brent
    refinement within one scan step of the best; it is reported in [0, 360).
    Observations where the model reflects nothing (infinite magnitude) are excluded
    and counted.  Per-row geometry in ``measured`` enters the model: a ``range_km``
    column adds ``5 log10(range / range_sim)`` (``range_sim`` the ``range_km``
    attribute of the simulated magnitudes), an ``airmass`` column with ``extinction``
    adds ``k_band X``; absolute times from several nights share one rotation phase.

    Parameters
    ----------
    measured : xarray.Dataset
        From :func:`read_light_curve`.
    simulated_mags : xarray.DataArray
        Magnitudes over ``attitude`` (with the coordinate ``attitude_angle`` [degree],
        a rotation sweep) and ``band`` (and optionally a ``phase_angle`` dim).
    fit_phase : bool
        Fit the rotation-phase offset (else ``phi = 0``).
    period_s : float, optional
        Rotation period [s], needed when ``measured`` is indexed by time:
        ``theta = 360 t / period_s``.
    phase_angle : float, optional
        Selects the simulated phase angle [degree] (nearest) when there are several.
    n_scan : int
        Number of scan points, >= 1.
    epoch : datetime64 or str, optional
        Time of rotation angle 0 for absolute (UTC) times; default the first observation.
    extinction : mapping or DataArray, optional
        Extinction coefficients per band (:func:`~sbrdf_xr.photometry.apply_extinction`)
        applied with the ``airmass`` column of ``measured``.

    Returns
    -------
    xarray.Dataset
        Over ``obs``: ``measured_magnitude``, ``uncertainty``, ``model_magnitude``
        (offsets applied), ``residual``, ``normalized_residual``; scalars
        ``magnitude_offset`` (+ ``magnitude_offset_uncertainty``), ``phase_offset``,
        ``chi_square``, ``reduced_chi_square``, ``degrees_of_freedom``, ``n_excluded``;
        over ``band``: ``band_mean_residual``; over ``colour``:
        ``colour_index_difference`` (measured minus simulated, consecutive bands);
        over ``phase_scan``: ``chi_square_scan``.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> rows = ["rotation_angle,band,magnitude,uncertainty,system"]
    >>> for a in (0, 30, 60, 90):  # a double-peaked curve, 0.2 mag fainter, 20 degree later
    ...     for b, m0 in (("B", 10.2), ("V", 9.8)):
    ...         rows.append(f"{a},{b},{m0 + 0.5 * np.cos(np.radians(2 * (a + 20))):.4f},0.01,AB")
    >>> path = Path(tempfile.mkdtemp()) / "curve.csv"
    >>> _ = path.write_text("\\n".join(rows))
    >>> from sbrdf_xr.photometry import read_light_curve
    >>> ang = np.arange(0.0, 360.0, 10.0)
    >>> wave = 0.5 * np.cos(np.radians(2 * ang))
    >>> simulated = xr.DataArray(np.stack([10 + wave, 9.6 + wave], 1), dims=("attitude", "band"),
    ...                          coords={"attitude_angle": ("attitude", ang), "band": ["B", "V"]},
    ...                          attrs={"units": "1"})
    >>> fit = compare_light_curves(read_light_curve(path), simulated)
    >>> round(float(fit.magnitude_offset), 3), round(float(fit.phase_offset), 1)
    (0.2, 20.0)
    >>> int(fit.degrees_of_freedom), bool(fit.reduced_chi_square < 1)
    (6, True)
    """
    from scipy.optimize import minimize_scalar

    if (
        not isinstance(measured, xr.Dataset)
        or "magnitude" not in measured
        or "uncertainty" not in measured
    ):
        raise ValidationError("measured: expected a light-curve Dataset from read_light_curve")
    if isinstance(n_scan, bool) or not isinstance(n_scan, int | np.integer) or n_scan < 1:
        raise ValidationError(
            f"n_scan: must be an integer >= 1 (trial phase offsets over 360 degree), got {n_scan!r}"
        )
    sim = _simulated_curve(simulated_mags, phase_angle)
    have = str(
        measured.attrs.get(
            "magnitude_system", measured["magnitude"].attrs.get("magnitude_system", "unstated")
        )
    )
    want = str(sim.attrs.get("magnitude_system", "unstated"))
    if "unstated" not in (have, want) and have != want:
        raise ValidationError(
            f"measured: magnitudes are in the {have} system but the simulation is in {want}; "
            f"simulate with system={have!r}"
        )
    if "rotation_angle" in measured.coords:
        theta = np.asarray(measured["rotation_angle"].values, dtype=np.float64)
    elif "time" in measured.coords:
        if period_s is None or not np.isfinite(period_s) or period_s <= 0:
            raise ValidationError(
                "period_s: the measured light curve is indexed by time; give the rotation "
                "period [s] (> 0) to convert it to rotation angle"
            )
        tv = measured["time"].values
        if np.issubdtype(tv.dtype, np.datetime64):
            t0 = tv[0] if epoch is None else np.datetime64(epoch, "ns")
            secs = (tv.astype("datetime64[ns]") - t0) / np.timedelta64(1, "s")
        else:
            secs = np.asarray(tv, dtype=np.float64)
        theta = 360.0 * np.asarray(secs, dtype=np.float64) / period_s
    else:
        raise ValidationError("measured: needs a 'rotation_angle' or 'time' coordinate")
    m_obs = np.asarray(measured["magnitude"].values, dtype=np.float64)
    sig = np.asarray(measured["uncertainty"].values, dtype=np.float64)
    bad = np.flatnonzero(~np.isfinite(sig) | (sig < MIN_UNCERTAINTY))
    if bad.size:
        raise ValidationError(
            f"measured: observation {int(bad[0])} has uncertainty {sig[bad[0]]:g}; must be "
            f"finite and >= {MIN_UNCERTAINTY:g} mag"
        )
    sim_labels = [str(b) for b in sim[BAND].values]
    sim_filters = [str(f) for f in sim["filter"].values] if "filter" in sim.coords else sim_labels
    obs_band = [str(b) for b in measured[BAND].values]
    col = np.empty(len(obs_band), dtype=np.int64)
    for k, b in enumerate(obs_band):
        if b in sim_labels:
            col[k] = sim_labels.index(b)
        elif _canonical(b) in sim_filters:
            col[k] = sim_filters.index(_canonical(b))
        else:
            raise ValidationError(
                f"measured: observation {k} is in band {b!r}, which the simulation does "
                f"not have (bands {sim_labels})"
            )
    angles = np.asarray(sim["attitude_angle"].values, dtype=np.float64)
    sim_m = np.asarray(sim.transpose(ATTITUDE, BAND).values, dtype=np.float64)
    with np.errstate(over="ignore"):
        flux = np.where(
            np.isfinite(sim_m), 10.0 ** (-0.4 * np.where(np.isfinite(sim_m), sim_m, 0.0)), 0.0
        )
    w = 1.0 / sig**2
    extra = np.zeros(theta.size)  # per-observation geometry terms of the model [mag]
    if "range_km" in measured:
        if "range_km" not in sim.attrs:
            raise ValidationError(
                "measured: has a range_km column but simulated_mags has no range_km "
                "attribute (the range it was computed at); compute it at one range"
            )
        extra += 5.0 * np.log10(
            np.asarray(measured["range_km"].values, dtype=np.float64) / float(sim.attrs["range_km"])
        )
    if extinction is not None:
        if "airmass" not in measured:
            raise ValidationError("extinction: the measured light curve has no airmass column")
        from .atmosphere import apply_extinction

        labels = sorted({str(b) for b in measured[BAND].values})
        zero = xr.DataArray(np.zeros(len(labels)), dims=(BAND,), coords={BAND: labels})
        k_band = apply_extinction(zero, 1.0, extinction)
        kb = dict(zip(labels, k_band.values.tolist(), strict=True))
        extra += np.array([kb[str(b)] for b in measured[BAND].values]) * np.asarray(
            measured["airmass"].values, dtype=np.float64
        )

    def model(phi: float) -> tuple[np.ndarray, np.ndarray]:
        f = np.empty(theta.size)
        for b in np.unique(col):
            sel = col == b
            f[sel] = _periodic_model_flux(angles, flux[:, b], theta[sel] + phi)
        ok = f > 0
        mm = np.full(theta.size, np.inf)
        mm[ok] = -2.5 * np.log10(f[ok]) + extra[ok]
        return mm, ok

    def fit(phi: float) -> tuple[float, float, np.ndarray, np.ndarray]:
        mm, ok = model(phi)
        if not ok.any():
            return np.inf, np.nan, mm, ok
        r = m_obs[ok] - mm[ok]
        dm = float(np.sum(w[ok] * r) / np.sum(w[ok]))
        return float(np.sum(w[ok] * (r - dm) ** 2)), dm, mm, ok

    scan = np.arange(n_scan) * (360.0 / n_scan)
    if fit_phase:
        chi_scan = np.array([fit(p)[0] for p in scan])
        if not np.isfinite(chi_scan).any():
            raise ValidationError(
                "simulated_mags: the model reflects nothing at any measured angle"
            )
        k = int(np.nanargmin(chi_scan))
        step = 360.0 / n_scan
        res = minimize_scalar(
            lambda p: fit(p)[0],
            bounds=(scan[k] - step, scan[k] + step),
            method="bounded",
            options={"xatol": 1e-7},
        )
        phi = float(res.x) if res.fun <= chi_scan[k] else float(scan[k])
        phi = float(np.mod(phi, 360.0))
    else:
        chi_scan = np.array([fit(p)[0] for p in scan])
        phi = 0.0
    chi2, dm, mm, ok = fit(phi)
    if not ok.any():
        raise ValidationError("simulated_mags: the model reflects nothing at any measured angle")
    # The best phase farther than 30 deg from the fitted one: a symmetric body (a cube
    # turning about an axis) fits nearly as well half a turn away.
    far = np.abs(((scan - phi + 180.0) % 360.0) - 180.0) > 30.0
    if fit_phase and np.isfinite(chi_scan[far]).any():
        k_alt = int(np.nanargmin(np.where(far, chi_scan, np.nan)))
        phi_alt, dchi_alt = float(scan[k_alt]), float(chi_scan[k_alt] - chi2)
    else:
        phi_alt, dchi_alt = np.nan, np.nan
    n_par = 2 if fit_phase else 1
    dof = int(ok.sum()) - n_par
    if dof < 1:
        raise ValidationError(
            f"measured: {int(ok.sum())} observation(s) where the model reflects light; fitting "
            f"{n_par} parameter(s) (magnitude{' and phase' if fit_phase else ''} offset) needs "
            f"at least {n_par + 1}"
        )
    resid = np.where(ok, m_obs - (mm + dm), np.nan)
    labels_present = [lab for j, lab in enumerate(sim_labels) if np.any(col[ok] == j)]
    band_mean = []
    for lab in labels_present:
        sel = ok & (col == sim_labels.index(lab))
        band_mean.append(float(np.sum(w[sel] * resid[sel]) / np.sum(w[sel])))
    colours = [f"{a}-{b}" for a, b in pairwise(labels_present)]
    ci_diff = [band_mean[i] - band_mean[i + 1] for i in range(len(colours))]
    obs_coords = {
        ("obs_band" if k == BAND else k): v
        for k, v in measured.coords.items()
        if v.dims == ("obs",)
    }
    ds = xr.Dataset(
        {
            "measured_magnitude": (
                "obs",
                m_obs,
                attrs("magnitude", long_name="measured magnitude"),
            ),
            "uncertainty": ("obs", sig, attrs("magnitude_uncertainty")),
            "model_magnitude": (
                "obs",
                np.where(ok, mm + dm, np.inf),
                attrs("magnitude", long_name="simulated magnitude with the fitted offsets"),
            ),
            "residual": (
                "obs",
                resid,
                attrs("magnitude", long_name="measured minus fitted simulated magnitude"),
            ),
            "normalized_residual": (
                "obs",
                resid / sig,
                {"units": "1", "long_name": "residual / uncertainty"},
            ),
            "model_rotation_angle": (
                "obs",
                np.mod(theta + phi, 360.0),
                attrs(
                    "rotation_angle",
                    long_name="simulated rotation angle matched to "
                    "each observation (measured angle + phase offset, mod 360)",
                ),
            ),
            "magnitude_offset": (
                (),
                dm,
                attrs(
                    "magnitude",
                    long_name="fitted magnitude offset (measured - "
                    "simulated), analytic weighted mean",
                ),
            ),
            "magnitude_offset_uncertainty": (
                (),
                float(1.0 / np.sqrt(np.sum(w[ok]))),
                attrs("magnitude", long_name="1-sigma uncertainty of the magnitude offset"),
            ),
            "phase_offset": (
                (),
                phi,
                attrs(
                    "rotation_angle",
                    long_name="fitted rotation-phase offset "
                    "(simulated angle = measured angle + offset), in [0, 360)",
                ),
            ),
            "chi_square": ((), chi2, {"units": "1", "long_name": "chi-square of the fit"}),
            "alternative_phase_offset": (
                (),
                phi_alt,
                attrs(
                    "rotation_angle",
                    long_name="best phase offset more "
                    "than 30 deg from the fitted one (scan resolution)",
                ),
            ),
            "alternative_delta_chi_square": (
                (),
                dchi_alt,
                {
                    "units": "1",
                    "long_name": "chi-square at the "
                    "alternative phase minus the best; below ~4 the two "
                    "phases are not distinguished at 2 sigma",
                },
            ),
            "degrees_of_freedom": (
                (),
                dof,
                {"units": "1", "long_name": "observations used minus fitted parameters"},
            ),
            "reduced_chi_square": (
                (),
                chi2 / dof if dof > 0 else np.nan,
                {"units": "1", "long_name": "chi-square per degree of freedom"},
            ),
            "n_excluded": (
                (),
                int((~ok).sum()),
                {
                    "units": "1",
                    "long_name": "observations where the model reflects nothing (excluded)",
                },
            ),
            "band_mean_residual": (
                BAND,
                np.array(band_mean),
                attrs(
                    "magnitude", long_name="weighted mean residual per band after the common offset"
                ),
            ),
            "colour_index_difference": (
                "colour",
                np.array(ci_diff),
                attrs("colour_index", long_name="measured minus simulated colour index"),
            ),
            "chi_square_scan": (
                "phase_scan",
                chi_scan,
                {"units": "1", "long_name": "chi-square versus trial phase offset"},
            ),
        },
        coords={
            **obs_coords,
            BAND: (BAND, labels_present, attrs(BAND)),
            "colour": ("colour", colours, attrs("colour")),
            "phase_scan": (
                "phase_scan",
                scan,
                attrs("rotation_angle", long_name="trial phase offset"),
            ),
        },
    )
    ds.attrs = {
        "fit_phase": int(fit_phase),
        "title": "comparison of a measured and a simulated light curve",
        "model": "m_meas(theta) = m_sim(theta + phase_offset) + magnitude_offset",
        "abscissa": "rotation_angle"
        if "rotation_angle" in measured.coords
        else f"time converted with period_s = {period_s}",
    }
    return ds


def _simulated_curve(sim: xr.DataArray, phase_angle: float | None) -> xr.DataArray:
    if not isinstance(sim, xr.DataArray) or BAND not in sim.dims:
        raise ValidationError(
            "simulated_mags: expected magnitudes over (attitude, band) from magnitudes()"
        )
    if PHASE_ANGLE in sim.dims:
        if phase_angle is not None:
            sim = sim.sel({PHASE_ANGLE: phase_angle}, method="nearest")
        elif sim.sizes[PHASE_ANGLE] == 1:
            sim = sim.isel({PHASE_ANGLE: 0})
        else:
            raise ValidationError(
                f"phase_angle: the simulation has {sim.sizes[PHASE_ANGLE]} phase angles "
                f"{sim[PHASE_ANGLE].values.tolist()}; choose one"
            )
    extra = [d for d in sim.dims if d not in (ATTITUDE, BAND)]
    if ATTITUDE not in sim.dims or extra:
        raise ValidationError(f"simulated_mags: expected dims (attitude, band), got {sim.dims}")
    if "attitude_angle" not in sim.coords:
        raise ValidationError(
            "simulated_mags: needs the 'attitude_angle' coordinate of a rotation sweep"
        )
    ang = np.mod(np.asarray(sim["attitude_angle"].values, dtype=np.float64), 360.0)
    if np.unique(ang).size != ang.size:
        raise ValidationError("simulated_mags: attitude angles repeat modulo 360 degree")
    return sim.load()


def plot_comparison(comparison: xr.Dataset, *, title: str | None = None) -> Any:
    """Figure of a :func:`compare_light_curves` result.

    Top: measured magnitudes (error bars) and the fitted simulated curve against the
    simulated rotation angle, per band; bottom: residuals.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> rows = ["rotation_angle,band,magnitude,uncertainty,system"]
    >>> for a in (0, 30, 60, 90):  # a double-peaked curve, 0.2 mag fainter, 20 degree later
    ...     for b, m0 in (("B", 10.2), ("V", 9.8)):
    ...         rows.append(f"{a},{b},{m0 + 0.5 * np.cos(np.radians(2 * (a + 20))):.4f},0.01,AB")
    >>> path = Path(tempfile.mkdtemp()) / "curve.csv"
    >>> _ = path.write_text("\\n".join(rows))
    >>> from sbrdf_xr.photometry import read_light_curve
    >>> ang = np.arange(0.0, 360.0, 10.0)
    >>> wave = 0.5 * np.cos(np.radians(2 * ang))
    >>> simulated = xr.DataArray(np.stack([10 + wave, 9.6 + wave], 1), dims=("attitude", "band"),
    ...                          coords={"attitude_angle": ("attitude", ang), "band": ["B", "V"]},
    ...                          attrs={"units": "1"})
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> fig = plot_comparison(compare_light_curves(read_light_curve(path), simulated))
    >>> type(fig).__name__, len(fig.axes)
    ('Figure', 2)
    """
    from matplotlib.figure import Figure

    if not isinstance(comparison, xr.Dataset) or "residual" not in comparison:
        raise ValidationError("comparison: expected the Dataset returned by compare_light_curves")
    fig = Figure(figsize=(8, 6), layout="constrained")
    ax, axr = fig.subplots(2, 1, sharex=True, height_ratios=(3, 1))
    x = comparison["model_rotation_angle"].values
    bands = [str(b) for b in comparison[BAND].values]
    obs_band = np.asarray([str(b) for b in comparison["obs_band"].values])
    for b in bands:
        sel = obs_band == b
        order = np.argsort(x[sel])
        line = ax.errorbar(
            x[sel],
            comparison["measured_magnitude"].values[sel],
            comparison["uncertainty"].values[sel],
            fmt="o",
            ms=3,
            label=f"{b} measured",
        )
        ax.plot(
            x[sel][order],
            comparison["model_magnitude"].values[sel][order],
            "-",
            color=line[0].get_color(),
            label=f"{b} simulated",
        )
        axr.plot(x[sel], comparison["residual"].values[sel], "o", ms=3, color=line[0].get_color())
    ax.invert_yaxis()
    ax.set_ylabel("magnitude [mag]")
    ax.legend(fontsize="small", ncol=2)
    axr.axhline(0.0, color="k", lw=0.8)
    axr.set_xlabel("simulated rotation angle [degree]")
    axr.set_ylabel("residual [mag]")
    ax.set_title(
        title
        or (
            f"offset {float(comparison.magnitude_offset):.3f} mag, phase "
            f"{float(comparison.phase_offset):.2f} deg, reduced chi2 "
            f"{float(comparison.reduced_chi_square):.2f}"
        )
    )
    return fig
