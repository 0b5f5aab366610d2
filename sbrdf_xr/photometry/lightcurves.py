"""Measured light curves: reading, fitting a simulated curve, the comparison figure."""

from __future__ import annotations

import os
from collections.abc import Sequence
from itertools import pairwise
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from .._names import ATTITUDE, BAND, PHASE_ANGLE, attrs
from ..errors import ValidationError
from .bands import BAND_ALIASES, _canonical, speclite_names

# -------------------------------------------------------------- light curves

LIGHT_CURVE_COLUMNS = ("band", "magnitude", "uncertainty")
LIGHT_CURVE_ABSCISSAE = ("time", "rotation_angle")


def read_light_curve(path: str | os.PathLike[str], *, bands: Sequence[str] | None = None) -> xr.Dataset:
    """Read a measured light curve from CSV or netCDF.

    Schema (one observation per row; CSV with a header line, extra columns ignored):

    ============== ========================================================================
    column         meaning
    ============== ========================================================================
    time           observation time: seconds [s] (any origin) or ISO 8601 timestamps;
                   **or** ``rotation_angle`` [degree], the body rotation angle (cumulative,
                   may exceed 360).  Exactly one of the two; non-decreasing down the file.
    band           band label: an alias (``B``, ``V``, ``g``, ...) or speclite filter name,
                   or one of ``bands`` when given
    magnitude      measured magnitude [mag]
    uncertainty    1-sigma uncertainty of the magnitude [mag], > 0
    ============== ========================================================================

    A netCDF file holds the same names as variables along one dimension.

    Parameters
    ----------
    path : str or path
        ``.csv`` (or any text file) or ``.nc``.
    bands : sequence of str, optional
        Allowed band labels; default any alias or speclite filter name.

    Returns
    -------
    xarray.Dataset
        Over ``obs``: ``magnitude``, ``uncertainty`` [mag], coords ``band`` and ``time``
        [s] (numeric times as given; ISO 8601 times as seconds since the first
        observation, attr ``time_origin``) or ``rotation_angle`` [degree].

    Raises
    ------
    ValidationError
        Naming the file and the column or row: missing columns, both or neither of
        time and rotation_angle, NaN or non-numeric values, non-positive uncertainty,
        unknown bands, times or angles that decrease.
    """
    import pandas as pd

    path = Path(path)
    if not path.is_file():
        raise ValidationError(f"light curve: file {path} does not exist")
    if path.suffix.lower() in (".nc", ".nc4", ".netcdf"):
        with xr.open_dataset(path, decode_times=True) as ds:
            ds = ds.load()
        if len(ds.dims) != 1:
            raise ValidationError(f"{path}: expected variables along one dimension, got dims {dict(ds.sizes)}")
        df = ds.reset_coords().to_dataframe().reset_index(drop=True)
        where = "netCDF record {}"
        offset = 0
    else:
        try:
            df = pd.read_csv(path, skipinitialspace=True, dtype=str, keep_default_na=False)
        except Exception as exc:  # pandas raises several types for malformed text
            raise ValidationError(f"{path}: cannot be read as CSV with a header: {exc}") from exc
        df.columns = [str(c).strip() for c in df.columns]
        where = "row {} (line {} of the file)"
        offset = 1
    cols = list(df.columns)
    missing = [c for c in LIGHT_CURVE_COLUMNS if c not in cols]
    absc = [c for c in LIGHT_CURVE_ABSCISSAE if c in cols]
    if missing:
        raise ValidationError(f"{path}: missing column(s) {missing}; required: band, magnitude, uncertainty "
                              f"and one of time, rotation_angle; found {cols}")
    if len(absc) != 1:
        raise ValidationError(f"{path}: need exactly one of the columns 'time' or 'rotation_angle', found "
                              f"{absc or 'neither'}")
    xname = absc[0]
    if len(df) == 0:
        raise ValidationError(f"{path}: no observations")

    def row_name(k: int) -> str:
        return where.format(k + 1, k + 1 + offset) if offset else where.format(k)

    def numeric(col: str) -> np.ndarray:
        v = pd.to_numeric(pd.Series(df[col]).astype(str).str.strip()
                          if df[col].dtype == object else df[col], errors="coerce").to_numpy(dtype=np.float64)
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            raise ValidationError(f"{path}: {row_name(int(bad[0]))}, column {col!r}: value "
                                  f"{df[col].iloc[bad[0]]!r} is not a finite number")
        return v

    mag = numeric("magnitude")
    unc = numeric("uncertainty")
    bad = np.flatnonzero(unc <= 0)
    if bad.size:
        raise ValidationError(f"{path}: {row_name(int(bad[0]))}, column 'uncertainty': must be > 0, got {unc[bad[0]]}")
    x_attrs: dict[str, Any]
    if xname == "time":
        raw = df["time"]
        if pd.api.types.is_datetime64_any_dtype(raw.dtype):
            tt = pd.to_datetime(raw, utc=True)
            x = None
        else:
            as_num = pd.to_numeric(raw.astype(str).str.strip(), errors="coerce")
            if as_num.notna().all():
                x = as_num.to_numpy(dtype=np.float64)
                tt = None
            else:
                tt = pd.to_datetime(raw.astype(str).str.strip(), utc=True, errors="coerce", format="ISO8601")
                x = None
        if x is None:
            nat = np.flatnonzero(tt.isna().to_numpy())
            if nat.size:
                raise ValidationError(f"{path}: {row_name(int(nat[0]))}, column 'time': value "
                                      f"{raw.iloc[nat[0]]!r} is neither a number of seconds nor an ISO 8601 time")
            origin = tt.iloc[0]
            x = (tt - origin).dt.total_seconds().to_numpy(dtype=np.float64)
            x_attrs = attrs("time_since_first", time_origin=origin.isoformat())
        else:
            x = numeric("time")
            x_attrs = attrs("time_since_first", long_name="observation time",
                            time_origin="as in the file (numeric seconds are kept unchanged)")
    else:
        x = numeric("rotation_angle")
        x_attrs = attrs("rotation_angle")
    back = np.flatnonzero(np.diff(x) < 0)
    if back.size:
        k = int(back[0]) + 1
        raise ValidationError(f"{path}: {row_name(k)}, column {xname!r}: values must be non-decreasing "
                              f"(sorted); it goes back from row {k} to row {k + 1}")
    band = [str(b).strip() for b in df["band"].tolist()]
    known = set(bands) if bands is not None else None
    for k, b in enumerate(band):
        ok = (b in known) if known is not None else (_canonical(b) in speclite_names())
        if not ok:
            allowed = sorted(known) if known is not None else f"aliases {list(BAND_ALIASES)} or speclite names"
            raise ValidationError(f"{path}: {row_name(k)}, column 'band': unknown band {b!r}; allowed: {allowed}")
    ds = xr.Dataset(
        {"magnitude": ("obs", mag, attrs("magnitude", long_name="measured magnitude")),
         "uncertainty": ("obs", unc, attrs("magnitude_uncertainty"))},
        coords={"obs": ("obs", np.arange(mag.size), attrs("obs")),
                BAND: ("obs", band, attrs(BAND)),
                xname: ("obs", x, x_attrs)})
    ds.attrs = {"source_file": str(path), "abscissa": xname}
    return ds


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
) -> xr.Dataset:
    """Fit a simulated light curve to a measured one: magnitude and rotation-phase offsets.

    Model: ``m_meas,i = m_sim,b_i(theta_i + phi) + dm`` with the simulated curve
    interpolated linearly in flux, periodic in 360 degrees.  For a given ``phi`` the
    offset is the analytic weighted mean ``dm = sum w r / sum w`` (``w = 1/sigma**2``,
    ``r = m_meas - m_sim``), minimising ``chi2 = sum w (r - dm)**2``.  ``phi`` is found
    by a scan of ``n_scan`` equally spaced values over [0, 360) and a bounded Brent
    refinement within one scan step of the best; it is reported in [0, 360).
    Observations where the model reflects nothing (infinite magnitude) are excluded
    and counted.

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
        Number of scan points.

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
    """
    from scipy.optimize import minimize_scalar

    if not isinstance(measured, xr.Dataset) or "magnitude" not in measured or "uncertainty" not in measured:
        raise ValidationError("measured: expected a light-curve Dataset from read_light_curve")
    sim = _simulated_curve(simulated_mags, phase_angle)
    if "rotation_angle" in measured.coords:
        theta = np.asarray(measured["rotation_angle"].values, dtype=np.float64)
    elif "time" in measured.coords:
        if period_s is None or not np.isfinite(period_s) or period_s <= 0:
            raise ValidationError("period_s: the measured light curve is indexed by time; give the rotation "
                                  "period [s] (> 0) to convert it to rotation angle")
        theta = 360.0 * np.asarray(measured["time"].values, dtype=np.float64) / period_s
    else:
        raise ValidationError("measured: needs a 'rotation_angle' or 'time' coordinate")
    m_obs = np.asarray(measured["magnitude"].values, dtype=np.float64)
    sig = np.asarray(measured["uncertainty"].values, dtype=np.float64)
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
            raise ValidationError(f"measured: observation {k} is in band {b!r}, which the simulation does "
                                  f"not have (bands {sim_labels})")
    angles = np.asarray(sim["attitude_angle"].values, dtype=np.float64)
    sim_m = np.asarray(sim.transpose(ATTITUDE, BAND).values, dtype=np.float64)
    with np.errstate(over="ignore"):
        flux = np.where(np.isfinite(sim_m), 10.0 ** (-0.4 * np.where(np.isfinite(sim_m), sim_m, 0.0)), 0.0)
    w = 1.0 / sig**2

    def model(phi: float) -> tuple[np.ndarray, np.ndarray]:
        f = np.empty(theta.size)
        for b in np.unique(col):
            sel = col == b
            f[sel] = _periodic_model_flux(angles, flux[:, b], theta[sel] + phi)
        ok = f > 0
        mm = np.full(theta.size, np.inf)
        mm[ok] = -2.5 * np.log10(f[ok])
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
            raise ValidationError("simulated_mags: the model reflects nothing at any measured angle")
        k = int(np.nanargmin(chi_scan))
        step = 360.0 / n_scan
        res = minimize_scalar(lambda p: fit(p)[0], bounds=(scan[k] - step, scan[k] + step), method="bounded",
                              options={"xatol": 1e-7})
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
    resid = np.where(ok, m_obs - (mm + dm), np.nan)
    labels_present = [lab for j, lab in enumerate(sim_labels) if np.any(col[ok] == j)]
    band_mean = []
    for lab in labels_present:
        sel = ok & (col == sim_labels.index(lab))
        band_mean.append(float(np.sum(w[sel] * resid[sel]) / np.sum(w[sel])))
    colours = [f"{a}-{b}" for a, b in pairwise(labels_present)]
    ci_diff = [band_mean[i] - band_mean[i + 1] for i in range(len(colours))]
    obs_coords = {("obs_band" if k == BAND else k): v for k, v in measured.coords.items()
                  if v.dims == ("obs",)}
    ds = xr.Dataset(
        {
            "measured_magnitude": ("obs", m_obs, attrs("magnitude", long_name="measured magnitude")),
            "uncertainty": ("obs", sig, attrs("magnitude_uncertainty")),
            "model_magnitude": ("obs", np.where(ok, mm + dm, np.inf),
                                attrs("magnitude", long_name="simulated magnitude with the fitted offsets")),
            "residual": ("obs", resid, attrs("magnitude", long_name="measured minus fitted simulated magnitude")),
            "normalized_residual": ("obs", resid / sig, {"units": "1", "long_name": "residual / uncertainty"}),
            "model_rotation_angle": ("obs", np.mod(theta + phi, 360.0),
                                     attrs("rotation_angle", long_name="simulated rotation angle matched to "
                                           "each observation (measured angle + phase offset, mod 360)")),
            "magnitude_offset": ((), dm, attrs("magnitude", long_name="fitted magnitude offset (measured - "
                                                "simulated), analytic weighted mean")),
            "magnitude_offset_uncertainty": ((), float(1.0 / np.sqrt(np.sum(w[ok]))),
                                             attrs("magnitude", long_name="1-sigma uncertainty of the "
                                                   "magnitude offset")),
            "phase_offset": ((), phi, attrs("rotation_angle", long_name="fitted rotation-phase offset "
                                            "(simulated angle = measured angle + offset), in [0, 360)")),
            "chi_square": ((), chi2, {"units": "1", "long_name": "chi-square of the fit"}),
            "alternative_phase_offset": ((), phi_alt, attrs("rotation_angle", long_name="best phase offset more "
                                                            "than 30 deg from the fitted one (scan resolution)")),
            "alternative_delta_chi_square": ((), dchi_alt, {"units": "1", "long_name": "chi-square at the "
                                                            "alternative phase minus the best; below ~4 the two "
                                                            "phases are not distinguished at 2 sigma"}),
            "degrees_of_freedom": ((), dof, {"units": "1", "long_name": "observations used minus fitted "
                                             "parameters"}),
            "reduced_chi_square": ((), chi2 / dof if dof > 0 else np.nan,
                                   {"units": "1", "long_name": "chi-square per degree of freedom"}),
            "n_excluded": ((), int((~ok).sum()), {"units": "1", "long_name": "observations where the model "
                                                  "reflects nothing (excluded)"}),
            "band_mean_residual": (BAND, np.array(band_mean),
                                   attrs("magnitude", long_name="weighted mean residual per band after the "
                                         "common offset")),
            "colour_index_difference": ("colour", np.array(ci_diff),
                                        attrs("colour_index", long_name="measured minus simulated colour index")),
            "chi_square_scan": ("phase_scan", chi_scan, {"units": "1", "long_name": "chi-square versus "
                                                         "trial phase offset"}),
        },
        coords={**obs_coords, BAND: (BAND, labels_present, attrs(BAND)),
                "colour": ("colour", colours, attrs("colour")),
                "phase_scan": ("phase_scan", scan, attrs("rotation_angle", long_name="trial phase offset"))},
    )
    ds.attrs = {"fit_phase": int(fit_phase), "title": "comparison of a measured and a simulated light curve",
                "model": "m_meas(theta) = m_sim(theta + phase_offset) + magnitude_offset",
                "abscissa": "rotation_angle" if "rotation_angle" in measured.coords
                else f"time converted with period_s = {period_s}"}
    return ds


def _simulated_curve(sim: xr.DataArray, phase_angle: float | None) -> xr.DataArray:
    if not isinstance(sim, xr.DataArray) or BAND not in sim.dims:
        raise ValidationError("simulated_mags: expected magnitudes over (attitude, band) from magnitudes()")
    if PHASE_ANGLE in sim.dims:
        if phase_angle is not None:
            sim = sim.sel({PHASE_ANGLE: phase_angle}, method="nearest")
        elif sim.sizes[PHASE_ANGLE] == 1:
            sim = sim.isel({PHASE_ANGLE: 0})
        else:
            raise ValidationError(f"phase_angle: the simulation has {sim.sizes[PHASE_ANGLE]} phase angles "
                                  f"{sim[PHASE_ANGLE].values.tolist()}; choose one")
    extra = [d for d in sim.dims if d not in (ATTITUDE, BAND)]
    if ATTITUDE not in sim.dims or extra:
        raise ValidationError(f"simulated_mags: expected dims (attitude, band), got {sim.dims}")
    if "attitude_angle" not in sim.coords:
        raise ValidationError("simulated_mags: needs the 'attitude_angle' coordinate of a rotation sweep")
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
        line = ax.errorbar(x[sel], comparison["measured_magnitude"].values[sel],
                           comparison["uncertainty"].values[sel], fmt="o", ms=3, label=f"{b} measured")
        ax.plot(x[sel][order], comparison["model_magnitude"].values[sel][order], "-",
                color=line[0].get_color(), label=f"{b} simulated")
        axr.plot(x[sel], comparison["residual"].values[sel], "o", ms=3, color=line[0].get_color())
    ax.invert_yaxis()
    ax.set_ylabel("magnitude [mag]")
    ax.legend(fontsize="small", ncol=2)
    axr.axhline(0.0, color="k", lw=0.8)
    axr.set_xlabel("simulated rotation angle [degree]")
    axr.set_ylabel("residual [mag]")
    ax.set_title(title or (f"offset {float(comparison.magnitude_offset):.3f} mag, phase "
                           f"{float(comparison.phase_offset):.2f} deg, reduced chi2 "
                           f"{float(comparison.reduced_chi_square):.2f}"))
    return fig

