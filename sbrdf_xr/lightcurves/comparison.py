"""A measured light curve against a simulated one: one fit for passes and rotation sweeps.

:func:`compare` aligns the measured observations with the simulation - UTC times along a
simulated pass (a cube over ``time``), or rotation angles (or times over a period) along
a rotation sweep (over ``attitude``) - and fits, by weighted linear least squares, a
zero point per band (or one common offset) and optionally first-order extinction
coefficients, profiled over a time shift or a rotation-phase offset when asked:

    m_obs,i = m_sim,b(i)(t_i + dt) + ZP_b(i) + k_b(i) X_i + f_i

(``X`` the air mass, ``f`` fixed terms: a per-row range for a sweep, extinction with
given coefficients).  Uncertainties are the Gauss-Newton covariance of all fitted
parameters with the stated measurement uncertainties.  :func:`plot_comparison` draws
the result.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr

from .._names import ATTITUDE, BAND, PHASE_ANGLE
from ..errors import LightCurveError, renamed_keywords
from ..photometry import BAND_ALIASES, extinction_for_band
from ..units import to_unit
from . import _alignment as align
from ._comparison import fit_and_report
from .figure import plot_comparison
from .tables import MIN_UNCERTAINTY

__all__ = ["compare", "compare_light_curves", "plot_comparison"]

ZERO_POINTS = ("band", "common")
AIRMASS_SOURCES = ("auto", "measured", "simulated")


def _check_measured(measured: Any) -> None:
    if not isinstance(measured, xr.Dataset) or not {"magnitude", "uncertainty"} <= set(measured):
        raise LightCurveError("measured: expected a light-curve Dataset from read_light_curve")
    if BAND not in measured.coords:
        raise LightCurveError("measured: needs a 'band' coordinate over its observations")
    m = np.asarray(measured["magnitude"].values, dtype=np.float64)
    s = np.asarray(measured["uncertainty"].values, dtype=np.float64)
    rows = measured["file_row"].values if "file_row" in measured.coords else np.arange(m.size)
    for what, bad, rule in (
        ("magnitude", ~np.isfinite(m), "is not a finite number (a NaN row)"),
        ("uncertainty", ~np.isfinite(s), "is not a finite number (a NaN row)"),
        ("uncertainty", s < 0, "is negative"),
        ("uncertainty", (s >= 0) & (s < MIN_UNCERTAINTY), f"is below {MIN_UNCERTAINTY:g} mag"),
    ):
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            v = (m if what == "magnitude" else s)[k]
            raise LightCurveError(
                f"measured: observation {k} (row {int(rows[k])}) has {what} {v:g}, which "
                f"{rule}; {int(bad.sum())} such observation(s): drop them "
                "(measured.where(np.isfinite(...), drop=True)) or fix the uncertainties "
                f"(finite, >= {MIN_UNCERTAINTY:g} mag)"
            )


def _simulated(simulated: Any, measured: xr.Dataset, phase_angle: Any) -> xr.DataArray:
    """Magnitudes over (time or attitude, band): given, or computed from a cube."""
    if isinstance(simulated, xr.Dataset):
        from ..photometry import magnitudes

        labels = sorted({str(b) for b in measured[BAND].values})
        system = str(measured.attrs.get("magnitude_system", "unstated"))
        simulated = magnitudes(
            simulated, labels, system=system if system in ("AB", "Vega") else "AB"
        )
    if not isinstance(simulated, xr.DataArray) or BAND not in simulated.dims:
        raise LightCurveError(
            "simulated: expected magnitudes over (time, band) or (attitude, band) from "
            f"magnitudes(), or a cube; got {type(simulated).__name__}"
            + (f" with dims {simulated.dims}" if hasattr(simulated, "dims") else "")
        )
    sim = simulated
    if PHASE_ANGLE in sim.dims:
        if phase_angle is not None:
            sim = sim.sel({PHASE_ANGLE: to_unit(phase_angle, "deg", "phase_angle")}, "nearest")
        elif sim.sizes[PHASE_ANGLE] == 1:
            sim = sim.isel({PHASE_ANGLE: 0})
        else:
            raise LightCurveError(
                f"phase_angle: the simulation has {sim.sizes[PHASE_ANGLE]} phase angles "
                f"{sim[PHASE_ANGLE].values.tolist()}; choose one"
            )
    main = [d for d in (align.TIME, ATTITUDE) if d in sim.dims]
    extra = [d for d in sim.dims if d not in (align.TIME, ATTITUDE, BAND)]
    if len(main) != 1 or extra:
        raise LightCurveError(
            f"simulated: expected dims (time, band) of a pass or (attitude, band) of a "
            f"rotation sweep, got {sim.dims}"
        )
    return sim.load()


def _band_columns(measured: xr.Dataset, sim: xr.DataArray) -> np.ndarray:
    labels = [str(b) for b in sim[BAND].values]
    filters = [str(f) for f in sim["filter"].values] if "filter" in sim.coords else labels
    obs = [str(b) for b in measured[BAND].values]
    col = np.empty(len(obs), dtype=np.int64)
    missing: list[str] = []
    for k, b in enumerate(obs):
        if b in labels:
            col[k] = labels.index(b)
        elif BAND_ALIASES.get(b, b) in filters:
            col[k] = filters.index(BAND_ALIASES.get(b, b))
        elif b not in missing:
            missing.append(b)
    if missing:
        raise LightCurveError(
            f"simulated: the measured bands {missing} are not simulated (simulated bands: "
            f"{labels}); compute the magnitudes in every measured band "
            f"(bands={sorted(set(obs))}) or pass the cube itself"
        )
    return col


def _system(measured: xr.Dataset, sim: xr.DataArray) -> str:
    have = str(measured.attrs.get("magnitude_system", "unstated"))
    want = str(sim.attrs.get("magnitude_system", "unstated"))
    if "unstated" not in (have, want) and have != want:
        raise LightCurveError(
            f"measured: magnitudes are in the {have} system but the simulation is in {want}; "
            f"simulate with system={have!r}"
        )
    return have if have != "unstated" else want


@renamed_keywords(max_time_shift_s="max_time_shift", period_s="period")
def compare(
    measured: xr.Dataset,
    simulated: xr.DataArray | xr.Dataset,
    *,
    zero_points: str = "band",
    extinction: str | Mapping[str, float] | None = None,
    airmass: str = "auto",
    fit_time_shift: bool = False,
    max_time_shift: Any = 10.0,
    fit_phase: bool = True,
    period: Any = None,
    epoch: Any = None,
    phase_angle: Any = None,
    n_scan: int = 720,
) -> xr.Dataset:
    """Fit a simulated light curve - a pass or a rotation sweep - to a measured one.

    Model (per observation ``i`` in band ``b``, weights ``1 / sigma_i^2``)::

        m_obs,i = m_sim,b(t_i + dt) + ZP_b + k_b X_i + f_i

    * a **pass** (``simulated`` over ``time``): the simulated flux is interpolated
      linearly in time at the measured UTC times; a measured time outside the simulated
      window is an error.  ``dt`` is fitted when ``fit_time_shift`` (within
      ``max_time_shift``, the shifted times inside the window), else 0.
    * a **rotation sweep** (over ``attitude`` with ``attitude_angle``): the curve is
      periodic in 360 degree, the measured rotation angles (or times times
      ``360 / period``) are offset by a fitted phase (``fit_phase``); a ``range_km``
      column adds ``5 log10(range / range_sim)``.

    ``ZP_b`` is a zero point per band (``zero_points="band"``; their differences are
    the colour offsets) or one for all (``"common"``).  ``k_b X_i`` is first-order
    extinction: fitted (``extinction="fit"``), given (``{band: k}``) or absent; ``X`` is
    the measured ``airmass`` column or the pass's own (``airmass``).  The linear terms
    are solved exactly for each trial shift (``chi2`` profiled over them); the shift is
    found on a scan of ``n_scan`` points refined by bounded Brent.  Where the model
    reflects no light (the Earth's umbra) observations are excluded and counted.  The
    uncertainties are the Gauss-Newton covariance of every fitted parameter with the
    stated measurement uncertainties (not rescaled by the reduced chi-square).

    Parameters
    ----------
    measured : xarray.Dataset
        From :func:`~sbrdf_xr.lightcurves.read_light_curve` (or alike: ``magnitude``,
        ``uncertainty`` and coordinates ``band`` and ``time`` or ``rotation_angle``).
    simulated : xarray.DataArray or xarray.Dataset
        Magnitudes from :func:`~sbrdf_xr.photometry.magnitudes` over ``(time, band)``
        or ``(attitude, band)``, or a simulated cube (its magnitudes are computed in the
        measured bands and system).
    zero_points : {"band", "common"}
    extinction : {"fit"} or mapping of band -> k [mag per airmass], optional
    airmass : {"auto", "measured", "simulated"}
        Where ``X`` comes from: ``auto`` is the measured column if there is one, else
        the simulated pass's ``airmass`` coordinate.
    fit_time_shift : bool
        A pass: fit ``dt`` [s].
    max_time_shift : float or Quantity
        Bound of ``|dt|`` [s].
    fit_phase : bool
        A rotation sweep: fit the phase offset [degree].
    period : float or Quantity, optional
        A rotation sweep compared over times: the rotation period [s].
    epoch : datetime64 or str, optional
        A rotation sweep compared over UTC times: the time of rotation angle 0
        (default the first observation).
    phase_angle : float, optional
        Selects the simulated phase angle [degree] (nearest) when there are several.
    n_scan : int
        Points of the scan of the shift, >= 1.

    Returns
    -------
    xarray.Dataset
        Over ``obs``: ``measured_magnitude``, ``uncertainty``, ``simulated_magnitude``
        (aligned, before the fitted terms), ``model_magnitude``, ``residual``,
        ``normalized_residual``, ``excluded``, ``model_time`` (pass) or
        ``model_rotation_angle`` (sweep), ``airmass`` (with extinction).  Over
        ``band``: ``zero_point``, ``extinction_coefficient`` and their
        ``*_uncertainty``, ``n_observations``, ``band_mean_residual``.  Over ``colour``
        (consecutive bands): ``colour_index_difference`` (measured minus simulated) and
        its uncertainty.  Over ``parameter``: ``estimate``, ``standard_error``,
        ``covariance``.  Scalars: ``chi_square``, ``degrees_of_freedom``,
        ``reduced_chi_square``, ``n_excluded``; ``time_shift`` or ``phase_offset``
        (with uncertainties); ``magnitude_offset`` for a common zero point.  Over
        ``curve_time`` or ``curve_angle``: ``model_curve`` (the fitted model at the
        simulated nodes, for the figure), and ``chi_square_scan`` when a shift is fitted.

    Raises
    ------
    LightCurveError
        Measured times outside the simulated window (or no overlap), bands not
        simulated, NaN rows, negative or too small uncertainties, different magnitude
        systems, fewer observations than fitted parameters (or a band with fewer than
        its own), parameters the data cannot tell apart (an extinction fit over a
        constant air mass).

    Examples
    --------
    A pass of 60 s seen in V and R: the measurements are the simulation plus a zero
    point per band and 0.1 mag per airmass in V.

    >>> t = np.datetime64("2024-03-17T01:21:00", "ns") + np.arange(61) * np.timedelta64(1, "s")
    >>> x = np.linspace(1.9, 1.1, 61)  # the pass rises: airmass falls
    >>> curve = 12.0 + 0.3 * np.sin(np.arange(61) / 5.0)
    >>> sim = xr.DataArray(np.stack([curve, curve - 0.4], 1), dims=("time", "band"),
    ...                    coords={"time": t, "band": ["V", "R"], "airmass": ("time", x)},
    ...                    attrs={"magnitude_system": "AB"})
    >>> k = np.arange(0, 60, 3)
    >>> measured = xr.Dataset(
    ...     {"magnitude": ("obs", np.r_[curve[k] + 0.25 + 0.1 * x[k], curve[k] - 0.4 - 0.1]),
    ...      "uncertainty": ("obs", np.full(2 * k.size, 0.01))},
    ...     coords={"time": ("obs", np.r_[t[k], t[k]]),
    ...             "band": ("obs", ["V"] * k.size + ["R"] * k.size)},
    ...     attrs={"magnitude_system": "AB"})
    >>> fit = compare(measured, sim, extinction="fit")
    >>> np.round(fit.zero_point.values, 6).tolist()  # V, R [mag]
    [0.25, -0.1]
    >>> (np.round(fit.extinction_coefficient.values, 6) + 0.0).tolist()  # [mag per airmass]
    [0.1, 0.0]
    >>> int(fit.degrees_of_freedom), float(fit.chi_square) < 1e-20
    (36, True)
    >>> compare(measured, sim.isel(time=slice(0, 30)))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.LightCurveError: measured: 20 observation(s) outside the simulated window ...
    """
    _check_measured(measured)
    if zero_points not in ZERO_POINTS:
        raise LightCurveError(f"zero_points: got {zero_points!r}; allowed: {ZERO_POINTS}")
    if airmass not in AIRMASS_SOURCES:
        raise LightCurveError(f"airmass: got {airmass!r}; allowed: {AIRMASS_SOURCES}")
    if extinction is not None and extinction != "fit" and not isinstance(extinction, Mapping):
        raise LightCurveError(
            f"extinction: expected None, 'fit' or a mapping band -> k, got {extinction!r}"
        )
    if isinstance(n_scan, bool) or not isinstance(n_scan, int | np.integer) or n_scan < 1:
        raise LightCurveError(
            f"n_scan: must be an integer >= 1 (trial shifts of the scan), got {n_scan!r}"
        )
    max_shift = float(to_unit(max_time_shift, "s", "max_time_shift"))
    if not (np.isfinite(max_shift) and max_shift > 0):
        raise LightCurveError(f"max_time_shift: must be > 0 s, got {max_time_shift!r}")
    phase_angle = to_unit(phase_angle, "deg", "phase_angle")
    period = to_unit(period, "s", "period")
    sim = _simulated(simulated, measured, phase_angle)
    system = _system(measured, sim)
    col = _band_columns(measured, sim)
    if align.TIME in sim.dims:
        al = align.observation(measured, sim, fit_time_shift, max_shift)
        fit_x = bool(fit_time_shift)
    else:
        if fit_time_shift:
            raise LightCurveError(
                "fit_time_shift: a rotation sweep has no time axis; its phase offset is "
                "fitted with fit_phase"
            )
        period = None if period is None else float(period)
        al = align.sweep(measured, sim, period, epoch)
        fit_x = bool(fit_phase)
    fixed_k = None
    if extinction is not None:
        align.with_airmass(al, measured, sim, airmass)
    if isinstance(extinction, Mapping):
        labels = [str(b) for b in sim[BAND].values]
        ks = np.full(len(labels), np.nan)
        for i in np.unique(col):  # the measured bands need a coefficient, the others not
            ks[i] = extinction_for_band(
                sim.isel({BAND: np.unique(col)}),
                dict(extinction),
                labels[i],
                int(np.flatnonzero(np.unique(col) == i)[0]),
            )
        used = ks[np.unique(col)]
        if not np.all(np.isfinite(used)) or np.any(used < 0):
            raise LightCurveError(f"extinction: coefficients must be finite and >= 0, got {used}")
        fixed_k = ks[col]
        al.notes["extinction"] = "given: " + ", ".join(
            f"{labels[i]}: {ks[i]:g}" for i in np.unique(col)
        )
    return fit_and_report(
        measured, sim, al, col, zero_points, extinction == "fit", fixed_k, fit_x, n_scan, system
    )


def compare_light_curves(measured: xr.Dataset, simulated_mags: xr.DataArray, **kwargs: Any) -> Any:
    """Deprecated: :func:`compare` with one common zero point (``zero_points="common"``).

    Examples
    --------
    >>> import warnings
    >>> ang = np.arange(0.0, 360.0, 10.0)
    >>> sim = xr.DataArray(np.stack([10 + np.cos(np.radians(ang))], 1),
    ...                    dims=("attitude", "band"),
    ...                    coords={"attitude_angle": ("attitude", ang), "band": ["V"]})
    >>> lc = xr.Dataset({"magnitude": ("obs", 10.5 + np.cos(np.radians(ang[:9]))),
    ...                  "uncertainty": ("obs", np.full(9, 0.01))},
    ...                 coords={"rotation_angle": ("obs", ang[:9]), "band": ("obs", ["V"] * 9)})
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     fit = compare_light_curves(lc, sim, fit_phase=False)
    >>> round(float(fit.magnitude_offset), 6), caught[0].category.__name__
    (0.5, 'DeprecationWarning')
    """
    warnings.warn(
        "compare_light_curves is deprecated: use sbrdf_xr.lightcurves.compare (with "
        "zero_points='common' for one offset)",
        DeprecationWarning,
        stacklevel=2,
    )
    kwargs.setdefault("zero_points", "common")
    return compare(measured, simulated_mags, **kwargs)
