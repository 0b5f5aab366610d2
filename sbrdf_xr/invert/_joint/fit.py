"""Joint fit of a measured light curve over a pass: spin, extinction, zero points and the
material areas at once.

See :func:`fit_observation`; the data and the forward model are in
:mod:`sbrdf_xr.invert._joint.model`, the result Dataset in
:mod:`sbrdf_xr.invert._joint.result`.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from ...errors import FitQualityWarning, InversionError
from .._areas import material_areas
from .._quality import fit_quality
from .._spin.fit import AMBIGUITY_CHI2
from .._spin.search import vec
from .._spin.symmetry import SYMMETRY_TOL, body_symmetries
from .bounds import covariance
from .diagnose import likely_causes
from .extinction import extinction_prior as _k_prior
from .extinction import separable_sd
from .model import PassModel, pass_data
from .model_error import discrepancy_floor, estimated_floor, table_widths, tilt_layout, with_floor
from .posterior import CHUNK_STEPS, check_budget
from .profile import INTERVALS, point_intervals
from .refine import Local, jacobian, outside_physics, refine
from .result import Layout, model_check, result_dataset
from .starts import axis_body_of, minima_dataset, read_start, start_states
from .status import RECOVER, causes, held_note, status_attrs, with_posterior
from .twins import twin_dataset

if TYPE_CHECKING:
    from ...body import Spacecraft
    from ...observing import Observation

__all__ = ["JOINT_CAUSES", "fit_observation"]

#: Likely causes of a poor joint fit (the warning ranks them from the residuals: see
#: :mod:`sbrdf_xr.invert._joint.diagnose`).
JOINT_CAUSES = (
    "the fit stopped in a local minimum: start from a better spin state (fit_spin over the "
    "light curve) or from more (starts='aliases': the period aliases and fit_spin's twins)",
    "the attitude is not a uniform spin about axis_body",
    "a material of the object is missing from the model, or the shape is wrong",
    "the extinction is not first order in the air mass, or the table is not calibrated "
    "(try offset='band')",
    "the uncertainties are understated",
)


def _options(extinction: Any, offset: str | None, areas: str, labels: Sequence[str]) -> Any:
    if offset not in (None, "band", "common"):
        raise InversionError(
            f"offset: {offset!r}; allowed None (a calibrated table: no zero point), 'band' "
            "(a zero point per band) or 'common' (one offset for all bands)"
        )
    if areas not in ("total", "free", "fixed"):
        raise InversionError(
            f"areas: {areas!r}; allowed 'total' (fractions adding up to the mesh's area), "
            "'free' (a scale per material) or 'fixed' (the model's areas)"
        )
    if areas == "free" and offset is not None:
        raise InversionError(
            f"areas='free' with offset={offset!r}: free area scales and a zero point both set "
            "the brightness, so neither is determined; use areas='total' (the areas add up to "
            "the mesh's) or offset=None (a calibrated table)"
        )
    if isinstance(extinction, str) and extinction == "fit":
        return "fit"
    if extinction is None:
        return np.zeros(len(labels))
    if isinstance(extinction, Mapping):
        missing = [b for b in labels if b not in extinction]
        if missing:
            raise InversionError(
                f"extinction: no coefficient for bands {missing}; give one per band "
                f"{list(labels)} [mag per airmass], 'fit' or None"
            )
        return np.array([float(extinction[b]) for b in labels])
    raise InversionError(
        f"extinction: {extinction!r}; allowed 'fit', None (no extinction) or a mapping "
        "{band: k} [mag per airmass]"
    )


def fit_observation(
    light_curve: xr.Dataset,
    spacecraft: Spacecraft,
    observation: Observation,
    spin: Any,
    *,
    axis_body: ArrayLike | None = None,
    extinction: str | Mapping[str, float] | None = "fit",
    offset: str | None = None,
    areas: str = "total",
    bands: Sequence[str] | None = None,
    system: str | None = None,
    materials: Mapping[str, xr.DataArray] | None = None,
    scale_uncertainties: bool = False,
    starts: str | Sequence[Mapping[str, Any]] = "given",
    check: bool = True,
    extinction_prior: Mapping[str, Any] | None = None,
    symmetry_tolerance: float = SYMMETRY_TOL,
    material_scale: str | Mapping[str, float] | None = None,
    colour_tilt: bool | float | Mapping[str, float] | None = None,
    model_discrepancy: str | float | Mapping[str, float] | None = None,
    method: str = "point",
    intervals: str = "quadratic",
    posterior_walkers: int | None = None,
    posterior_steps: int | None = None,
    seed: int = 0,
) -> xr.Dataset:
    """Spin state, extinction, zero points and material areas fitted jointly to the
    calibrated magnitudes measured over a pass.

    The model of the magnitude measured at time ``t`` in band ``b`` is

    ``m = c_b(t) - 2.5 log10( sum_m a_m f(t) S_m,b(t; spin) ) + k_b X(t) + z_b``

    with ``S_m,b`` the band signal [m2 sr-1] of material ``m`` (the compiled kernel of
    :func:`sbrdf_xr.engine.simulate` on band pre-integrated tables, at the body-frame Sun
    and observer directions of a uniform spin, :func:`spin_model`), ``f`` the sunlit
    fraction, ``c_b`` the magnitude of a unit band signal at the time's range and Sun
    distance (:func:`sbrdf_xr.photometry.magnitudes`), ``a_m`` the area scale of material
    ``m``, ``X`` the pass's air mass, ``k_b`` the first-order extinction coefficient and
    ``z_b`` the zero point.  Fitted by :func:`scipy.optimize.least_squares`
    (Levenberg-Marquardt) on ``(m_measured - m) / sigma`` from ``spin``:

    * the spin: the inertial axis of ``axis_body`` (two angles, fitted on the tangent plane
      of the start axis, reported as longitude and latitude), the period and the phase
      at the epoch;
    * ``extinction="fit"``: ``k_b`` per band (``None``: no extinction; a mapping: given);
    * ``offset``: ``None`` (a calibrated table, ``z_b = 0``), ``"band"`` (a zero point per
      band) or ``"common"`` (one offset for all bands);
    * ``areas="total"``: the area fractions ``F_m = a_m A_m / A`` of every material but
      the last, the last taking ``1 - sum`` (the areas add up to the mesh's ``A``, every
      facet being of one of the materials); ``"free"``: a free scale ``a_m`` per material
      (needs ``offset=None``); ``"fixed"``: the model's areas (``a_m = 1``).

    The uncertainties are ``sqrt(diag(J^T J)^-1)`` from a central-difference Jacobian of
    the normalised residuals at the solution, unscaled (the measured uncertainties taken
    as right; ``scale_uncertainties=True`` multiplies the covariance by the reduced
    chi-square).  Over 1000 noise draws of a CanX-1 pass (0.02 mag; the user guide's
    inversion page, docs/guide/inversion.md) their pulls had widths 0.98 to 1.04, and
    1.10 for the axis longitude, which is not linear over a sigma (1.05 at 0.005 mag).
    They describe the neighbourhood of the minimum reached.
    The fit is local: from a start too far off (for a period ``P`` over a span ``T``, a
    phase slip of a quarter turn or more over the pass, ``|dP| > P**2 / (4 T)``) it stops
    in another minimum; ``starts="aliases"`` refines from the period aliases and the spin's
    twins too and keeps the lowest chi-square, listing every minimum found.

    Parameters
    ----------
    light_curve : Dataset
        :func:`sbrdf_xr.lightcurves.read_light_curve` output: ``magnitude``, ``uncertainty``
        [mag] over ``obs``, with ``band`` and UTC ``time`` (or seconds from the start of
        the observation); ``attrs["magnitude_system"]`` unless ``system``.
    spacecraft : Spacecraft
        The body (materials from the catalog unless ``materials``).
    observation : Observation
        Orbit, site and a window covering the measured times (its attitude is not used).
    spin : Dataset or mapping
        The start: :func:`fit_spin` output, or a mapping with ``axis_longitude``,
        ``axis_latitude`` [degree], ``period`` [s], ``phase`` [degree] (Quantities
        converted) and ``epoch`` (UTC of the phase; default the observation's first time).
    axis_body : array_like, shape (3,), optional
        The body axis of the spin (default the ``fit_spin`` result's, else z).
    extinction, offset, areas
        See above.
    bands : sequence of str, optional
        The bands simulated (default those of the light curve, which must be among them).
    system : {"Vega", "AB"}, optional
        Magnitude system (default the light curve's).
    materials : mapping, optional
        Material tables by name, instead of the catalog's.
    scale_uncertainties : bool
        Scale the covariance by the reduced chi-square (Birge ratio squared).
    starts : {"given", "aliases"} or sequence of mappings
        Where the fit starts: ``"given"`` from ``spin`` only; ``"aliases"`` from ``spin``,
        its period aliases (a half and a whole turn more and fewer over the measured
        span ``T``: ``P' = T / (T / P + j / 2)``, ``j = -2, -1, 1, 2``, the phase at the
        middle of the pass kept) and, for a :func:`fit_spin` result, its twins (antipode,
        mirror, half and double period); a sequence: from ``spin`` and each mapping (as
        ``spin``).  The lowest chi-square is the solution.
    check : bool
        Recompute the solution's magnitudes through :func:`sbrdf_xr.engine.simulate` and
        :func:`sbrdf_xr.photometry.magnitudes` (spectral signal, band-integrated): the
        largest difference is ``attrs["model_check"]``.
    extinction_prior : mapping of str to (float, float), optional
        ``{band: (k, width)}`` [mag per air mass], the prior of each extinction coefficient
        (default: :func:`sbrdf_xr.photometry.extinction_coefficients` +- 0.1).  Used when
        the pass's air mass cannot tell the extinction from a zero point: with a free zero
        point a band's ``k`` would be known to ``1 / sqrt(sum (X - Xbar)^2 / sigma^2)``;
        when that is wider than the prior (a geostationary object: a near-constant air
        mass), every ``k`` is held at its prior value, reported with the prior's width,
        and its share ``k Xbar`` is fitted as a zero point per band (``offset="band"``
        unless set), with a warning.
    symmetry_tolerance : float
        Tolerance of the body's symmetries, in ``(0, 0.1]`` (normals within this chord,
        areas within this fraction of the total): every rotation of the body frame that
        maps the body's facets (normals, areas, materials: the model's terms) onto
        themselves gives a twin state of the solution, evaluated on the data and listed
        over ``twin`` and in ``ambiguity`` (:mod:`sbrdf_xr.invert._spin.symmetry`).
    colour_tilt : bool, float or mapping of str to float, optional
        Fit a colour tilt of each material's table as a nuisance parameter too: the table
        scaled in band ``b`` by ``1 + t_m x_b`` (``x_b`` the band's mean wavelength less
        the bands' mean, counted in hundreds of nanometres) with the prior ``t_m ~ N(0,
        w_m^2)``; True: ``w_m`` 0.05 per 100 nm, a number or ``{material: width}`` given
        (> 0).  Default None: the
        tables' colours taken as exact.  Reported as ``table_tilt`` over ``material``.
    model_discrepancy : "estimate", float or mapping of str to float, optional
        A model-discrepancy floor [mag] (one for every band, or ``{band: floor}``, bands
        left out 0), added in quadrature to the measured uncertainties
        (:mod:`sbrdf_xr.invert._joint.model_error`): the model's own error where the
        tables' scales do not absorb it; ``"estimate"``: each band's floor estimated from
        the residuals of a point fit without one, then the pass fitted again with it
        (twice the cost).  Default None: the model taken as exact.
    method : {"point", "posterior"}
        ``"posterior"``: the joint posterior sampled by emcee from every minimum within a
        chi-square of 25 of the best (:mod:`sbrdf_xr.invert._joint.posterior`): the
        point fit's covariance sets the walkers' start and the independence proposal;
        medians, standard deviations and 2.5 / 97.5 % points per parameter, each mode's
        probability, autocorrelation time and cost (``posterior_cost``).
    intervals : {"quadratic", "profile"}
        How the spin parameters' intervals are found: ``"quadratic"`` from ``(J^T J)^-1``
        (the chi-square's curvature at the minimum); ``"profile"``: the profile
        likelihood's ``Delta chi2 = 1`` and 4 crossings of the axis longitude and
        latitude, the period and the phase, every other parameter refitted
        (:mod:`sbrdf_xr.invert._joint.profile`: asymmetric where the model is not linear
        over the interval, the outermost crossing of a rippled chi-square; 15-80 times
        the point fit's wall time), with the quadratic check's miss.  Reported as
        ``lower_2sigma``, ``upper_2sigma`` (and ``quadratic_miss``) over ``parameter``
        and ``attrs["intervals"]``.  At 0.05 mag of noise neither is calibrated for the
        spin (pull widths 1.09-1.14 over 60 held-out draws; the user guide's inversion
        page, docs/guide/inversion.md): the estimates scatter more than the likelihood's
        width.
    posterior_walkers : int, optional
        Walkers of the ensemble (default ``2 n + 2`` for ``n`` fitted parameters).
    posterior_steps : int, optional
        Steps per mode (default: grown 50 at a time until the chain spans 50
        autocorrelation times, within the budget).  Chains shorter than that raise a
        :class:`~sbrdf_xr.errors.ChainLengthWarning`; a budget beyond 200000 model
        evaluations is refused with its estimated time.
    seed : int
        Seed of the sampler's generator.

    Returns
    -------
    xarray.Dataset
        Scalars ``axis_longitude``, ``axis_latitude``, ``period``, ``phase`` (at
        ``attrs["epoch"]``) with ``*_uncertainty``, ``axis_uncertainty``, ``axis_vector``;
        over ``band``: ``extinction_coefficient``, ``zero_point`` (or the scalar
        ``magnitude_offset``) with uncertainties; over ``material``: ``area_fraction``,
        ``scale``, ``area`` [m2] with uncertainties and ``model_area``; over
        ``parameter``: ``estimate``, ``uncertainty``, ``correlation``; over ``twin`` the
        body's symmetry twins of the solution (``twin_chi2_gap``, ``twin_phase``,
        ``twin_axis_longitude``, ``twin_axis_latitude``, ``twin_sense``); ``chi2``, ``dof``,
        ``reduced_chi_square``, ``fit_probability``; over ``obs``: ``model_magnitude``,
        ``residual``, ``airmass``; over ``start``: the minimum refined from each start
        (``start_chi2``, ``start_chi2_gap`` above the solution's, ``start_period``,
        ``start_phase``, ``start_axis_longitude``, ``start_axis_latitude``,
        ``start_axis_separation``).  Attributes say what was fitted, how the uncertainties
        are scaled, the ``fit_quality``, the ``ambiguity``, the model check and the timing,
        and what the result can be trusted for: ``status`` (``"ok"`` or ``"failed"``, then
        ``status_note`` says why and how to recover), ``bounded`` (whether the area
        fractions were held inside ``[0, 1]``) and ``unconstrained`` (the parameters the
        data do not constrain, reported at their start or prior value with an infinite
        or the prior's uncertainty; ``unconstrained_note``, ``extinction_note``).

    Notes
    -----
    Results stay inside physics: when the lowest minimum needs area fractions outside
    ``[0, 1]`` (or negative scales), every start whose minimum does is refined again on
    the stick-breaking transform of the fractions with box bounds
    (:mod:`sbrdf_xr.invert._joint.bounds`); if that fit is poor the result is marked
    ``"failed"``: impossible areas mean the spin state is wrong.  A parameter whose
    Jacobian column vanishes or lies in its null space (a material never lit and seen,
    extinction and zero point over a constant air mass) is reported as not constrained
    (infinite uncertainty, NaN correlations), never with the value of an inverse of a
    singular matrix; no uncertainty is NaN in a result not marked ``"failed"``.

    Warns
    -----
    FitQualityWarning
        When the chi-square lies beyond the 99.9 % point of its distribution (or below its
        0.1 % point), naming the likely causes; or when a minimum from another start, at
        another spin state (period more than 3 sigma or axis more than 3 times its
        uncertainty away), fits within a chi-square of :data:`AMBIGUITY_CHI2` of the
        solution; when the fit failed, a parameter is not constrained or the extinction
        is held at its prior.

    Raises
    ------
    InversionError
        A light curve that is not calibrated magnitudes, bands outside ``bands``, times
        outside the observation window (below the horizon, in the Earth's umbra), fewer
        values than parameters, contradictory options.

    Examples
    --------
    A 1 x 2 x 3 m box, its sides grey and its caps white, spinning over the built-in pass
    (air mass 1.03 to 2.2): V and R every 4 s for 4 minutes with 0.01 mag of noise and an
    extinction of 0.2 and 0.1 mag per air mass, fitted from a start about 1 deg, 0.05 s and
    2 deg off (a start as close as a :func:`fit_spin` gives; from farther the fit can stop
    in a local minimum, and says so):

    >>> import numpy as np, trimesh, xarray as xr
    >>> from sbrdf_xr import Scene, load_spacecraft, simulate
    >>> from sbrdf_xr.invert import axis_vector, fit_observation, spin_model
    >>> from sbrdf_xr.observing import Observation
    >>> from sbrdf_xr.observing.observe import canx1_pass
    >>> from sbrdf_xr.photometry import magnitudes
    >>> mesh = trimesh.creation.box(extents=(1.0, 2.0, 3.0))
    >>> caps = np.abs(mesh.face_normals[:, 2]) > 0.5
    >>> white, grey = (255, 255, 255), (128, 128, 128)
    >>> mesh.visual.face_colors = np.where(caps[:, None], [*white, 255], [*grey, 255])
    >>> box = load_spacecraft(mesh, {white: "white-paint-a276", grey: "lambertian-grey-50"})
    >>> obs = canx1_pass()
    >>> obs = Observation(obs.orbit, obs.site, obs.times[60:300:4],
    ...                   spin_model([0, 0, 1], axis_vector(60.0, 30.0), 40.0, 20.0))
    >>> m = magnitudes(simulate(Scene(box, observation=obs)), ["V", "R"], system="Vega",
    ...                extinction={"V": 0.2, "R": 0.1})
    >>> rng = np.random.default_rng(1)
    >>> lc = xr.Dataset(
    ...     {"magnitude": ("obs", m.values.ravel() + rng.normal(0.0, 0.01, m.size)),
    ...      "uncertainty": ("obs", np.full(m.size, 0.01))},
    ...     coords={"time": ("obs", np.repeat(obs.times, 2)), "band": ("obs", ["V", "R"] * 60)},
    ...     attrs={"magnitude_system": "Vega"})
    >>> start = {"axis_longitude": 61.0, "axis_latitude": 30.5, "period": 40.05, "phase": 22.0}
    >>> fit = fit_observation(lc, box, obs, start)
    >>> round(float(fit.period), 2), fit.extinction_coefficient.round(1).values.tolist()
    (40.0, [0.2, 0.1])
    >>> fit.area_fraction.round(2).values.tolist(), fit.attrs["fit_quality"]
    ([0.82, 0.18], 'consistent')
    """
    if isinstance(model_discrepancy, str):  # estimated: a fit without, then with
        return estimated_floor(fit_observation, dict(locals()))
    t_start = time.perf_counter()
    _check_method(method, intervals)
    start, epoch = read_start(spin)
    ab = axis_body_of(spin, axis_body)
    data = pass_data(light_curve, observation, bands, system)
    floor = discrepancy_floor(model_discrepancy, data.labels)
    data = with_floor(data, floor)
    k_mode, k_prior, held, offset = _extinction_mode(
        data, extinction, offset, areas, extinction_prior
    )
    model = PassModel(data, spacecraft, ab, materials)
    terms = model.kernel.plan.terms
    syms = body_symmetries(terms.normal, terms.area, terms.material, ab, symmetry_tolerance)
    names = model.materials
    if method == "posterior":  # refuse a budget beyond the bound before fitting
        t0 = time.perf_counter()
        model.terms(vec(start["axis_longitude"], start["axis_latitude"]), start["period"], 0.0)
        check_budget(
            1 if posterior_walkers is None else posterior_walkers,
            CHUNK_STEPS if posterior_steps is None else posterior_steps,
            1,
            time.perf_counter() - t0,
        )
    area_of = material_areas(spacecraft)
    lay = Layout(
        data.labels,
        names,
        np.array([area_of.get(m, 0.0) for m in names]),
        k_mode,
        offset,
        areas,
        None if held is None else k_prior[1],
        table_widths(material_scale, names, model.kernel.sources),
        *tilt_layout(colour_tilt, names, data.labels),
    )
    _check_counts(method, posterior_walkers, data, lay)
    if epoch is None:
        epoch = data.epoch
    dt_epoch, local, best, unbounded = _minimise(model, lay, data, spin, start, starts, epoch)
    p = local[best].x
    stats = _statistics(model, lay, data, local[best], unbounded, scale_uncertainties, held)
    fit_s = time.perf_counter() - t_start
    ds = result_dataset(
        lay=lay,
        data=data,
        light_curve=light_curve,
        p=p,
        cov=stats.cov,
        free=stats.free,
        axis_of=local[best].axis_of,
        t_ref=model.t_ref,
        dt_epoch=dt_epoch,
        epoch=epoch,
        residual=stats.r * data.sigma,
        chi2=stats.chi2,
        dof=stats.dof,
        quality=stats.quality,
        attrs={
            "axis_body": str(ab.tolist()),
            "start": ", ".join(f"{k} {v:.6g}" for k, v in start.items()),
            "uncertainty_scaling": (
                "scaled by the reduced chi-square" if scale_uncertainties else "unscaled"
            )
            + ": covariance (J^T J)^-1 of the normalised residuals, J by central differences "
            "at the solution",
            "optimizer": f"scipy least_squares ({'trf, bounded' if local[best].bounded else 'lm'})"
            f": {local[best].res.message} ({local[best].res.nfev} evaluations)",
            **stats.status,
            "likely_causes": "residual patterns, (delta chi2 - k) / sqrt(2 k), about 0 +- 1 "
            "for noise: " + ", ".join(f"{k} {v:.3g}" for k, v in stats.ranked),
            "n_model_evaluations": int(model.n_calls),
            "fit_seconds": fit_s,  # the fit, without the check
            "time_source": data.time_source,
            "model_discrepancy": "none (the model taken as exact)"
            if floor is None
            else "floor added in quadrature to the uncertainties: "
            + ", ".join(f"{b} {f:.3g} mag" for b, f in zip(data.labels, floor, strict=True)),
        },
    )
    ds = _with_warnings_and_twins(ds, stats, local, best, model, lay, syms, dt_epoch)
    ds = point_intervals(
        ds,
        local[best],
        (stats.cov, stats.free, stats.chi2, stats.dof),
        lay,
        model.t_ref,
        dt_epoch,
        intervals,
        scale_uncertainties,
    )
    if method == "posterior":
        ds = with_posterior(
            ds, lay, local, best, model, dt_epoch, fit_s, posterior_walkers, posterior_steps, seed
        )
    if check:
        t0 = time.perf_counter()
        ds.attrs["model_check"] = model_check(
            ds, observation, spacecraft, materials, ab, data, lay, p
        )
        ds.attrs["check_seconds"] = time.perf_counter() - t0
    return ds


def _check_method(method: str, intervals: str) -> None:
    if method not in ("point", "posterior"):
        raise InversionError(
            f"method: {method!r}; allowed 'point' (least squares, uncertainties from the "
            "Jacobian) or 'posterior' (emcee from every minimum)"
        )
    if intervals not in INTERVALS:
        raise InversionError(
            f"intervals: {intervals!r}; allowed 'quadratic' (the Jacobian's) or 'profile' "
            "(the profile likelihood's, the others refitted)"
        )


def _extinction_mode(
    data: Any,
    extinction: Any,
    offset: str | None,
    areas: str,
    extinction_prior: Mapping[str, Any] | None,
) -> tuple[Any, Any, str | None, str | None]:
    """How extinction enters (fitted, given or held at its prior), the prior, the note
    when it is held (a pass too short to separate it from a zero point), the offset."""
    k_mode = _options(extinction, offset, areas, data.labels)
    k_prior = _k_prior(extinction_prior, data.labels)
    k_sep = separable_sd(data.airmass, data.sigma, data.band, len(data.labels))
    held = None
    if isinstance(k_mode, str) and bool(np.any(k_sep > k_prior[1])):
        k_mode, held = k_prior[0], held_note(data, k_sep, k_prior, offset, areas)
        if offset is None and areas != "free":
            offset = "band"  # k Xbar over the pass is a zero point: fitted as one
    return k_mode, k_prior, held, offset


def _check_counts(method: str, walkers: Any, data: Any, lay: Layout) -> None:
    """Enough walkers for the posterior and more values than parameters."""
    if method == "posterior" and isinstance(walkers, int) and walkers < 2 * lay.n:
        raise InversionError(
            f"posterior: {walkers} walkers for {lay.n} parameters; allowed at "
            f"least 2 x {lay.n} = {2 * lay.n} (emcee's affine-invariant moves need them)"
        )
    if data.magnitude.size <= lay.n - lay.n_prior:
        raise InversionError(
            f"light curve: {data.magnitude.size} values for {lay.n} parameters "
            f"({', '.join(lay.names)}); need more values than parameters (fix some: "
            "extinction=None or a mapping, offset=None, areas='fixed')"
        )


def _minimise(
    model: PassModel,
    lay: Layout,
    data: Any,
    spin: Any,
    start: dict[str, float],
    starts: Any,
    epoch: Any,
) -> tuple[float, list[Local], int, list[str]]:
    """Refine from every start (inside the bounds where a minimum left physics); the
    epoch [s from the data's], the minima, the best one, and the parameters the lowest
    minimum left outside physics."""

    def seconds_of(t: Any) -> float:
        return float((t - data.epoch) / np.timedelta64(1, "ns")) * 1e-9

    def read(s: Any) -> tuple[dict[str, float], float | None]:
        values, t = read_start(s)
        return values, None if t is None else seconds_of(t)

    dt_epoch = seconds_of(epoch)
    span = max(float(np.ptp(data.seconds)), 1e-9)
    states = start_states(starts, spin, start, dt_epoch, model.t_ref, span, read)
    local = [refine(model, lay, st, span) for st in states]
    lowest = min(local, key=lambda m: m.chi2)
    unbounded = outside_physics(lay, lowest.x)
    for i, st in enumerate(states):  # a minimum outside physics: refined inside the bounds
        if outside_physics(lay, local[i].x):
            local[i] = refine(model, lay, st, span, bounded=True)
    best = min(range(len(local)), key=lambda i: local[i].chi2)
    p = local[best].x
    if not p[2] > 0:
        raise InversionError(
            f"the fit ran to a period of {p[2]:.4g} s from {start['period']:.4g} s: start "
            "from a better spin state (fit_spin)"
        )
    return dt_epoch, local, best, unbounded


@dataclass
class _Statistics:
    r: np.ndarray
    chi2: float
    dof: int
    cov: np.ndarray
    free: Any
    ranked: Any
    quality: Any
    status: dict[str, Any]


def _statistics(
    model: PassModel,
    lay: Layout,
    data: Any,
    solution: Local,
    unbounded: list[str],
    scale_uncertainties: bool,
    held: str | None,
) -> _Statistics:
    """Chi-square, degrees of freedom, covariance, the likely causes of a misfit, status."""
    p = solution.x
    r_all = solution.residuals(p)
    r = r_all[: data.magnitude.size]
    chi2 = float(r_all @ r_all)  # with the priors' terms, each a datum: dof counts them
    dof = data.magnitude.size + lay.n_prior - lay.n
    jac = jacobian(solution.residuals, p, lay.steps(p[2]))
    cov, free = covariance(jac)
    if scale_uncertainties:
        cov = cov * chi2 / dof
    ranked = likely_causes(
        r,
        data.band,
        p[3] + 360.0 * (data.seconds[data.t_index] - model.t_ref) / p[2],
        data.airmass,
        data.seconds[data.t_index],
    )
    quality = fit_quality(chi2, dof, "joint fit", causes(ranked))
    status = status_attrs(lay, solution, unbounded, free, quality, chi2 / dof)
    if held is not None:
        status["unconstrained"] = ", ".join(
            [f"extinction_{b}" for b in lay.bands]
            + [n for n in [status["unconstrained"]] if n != "none"]
        )
        status["extinction_note"] = held
    return _Statistics(r, chi2, dof, cov, free, ranked, quality, status)


def _with_warnings_and_twins(
    ds: xr.Dataset,
    stats: _Statistics,
    local: list[Local],
    best: int,
    model: PassModel,
    lay: Layout,
    syms: Any,
    dt_epoch: float,
) -> xr.Dataset:
    """The status checked against the covariance and warned; the other minima, the
    ambiguity and the symmetry twins added."""
    status = stats.status
    if ds.attrs["status"] == "ok" and bool(np.isnan(ds["uncertainty"].values).any()):
        ds.attrs["status"] = "failed"
        ds.attrs["status_note"] = f"the fit failed: its covariance is not finite. {RECOVER}"
        status["status_note"] = ds.attrs["status_note"]
    for key in ("status_note", "unconstrained_note", "extinction_note"):
        if key in status:
            warnings.warn(f"joint fit: {status[key]}", FitQualityWarning, stacklevel=3)
    ds = ds.merge(_minima(local, best, model.t_ref, dt_epoch))
    ds.attrs["ambiguity"] = _ambiguity(ds)
    if ds.attrs["ambiguity"] != "none":
        warnings.warn(f"joint fit: {ds.attrs['ambiguity']}", FitQualityWarning, stacklevel=3)
    p = local[best].x
    twins, twin_text = twin_dataset(
        model, lay, local[best], p, stats.chi2, syms, float(ds["phase"])
    )
    ds = ds.merge(twins)
    ds.attrs["symmetry_twins"] = twin_text
    if twin_text != "none":
        have = ds.attrs["ambiguity"]
        ds.attrs["ambiguity"] = twin_text if have == "none" else f"{have}; {twin_text}"
    return ds


def _minima(local: Sequence[Local], best: int, t_ref: float, dt_epoch: float) -> xr.Dataset:
    """The table of the minima refined from every start (phases at the epoch)."""
    x = np.array([m.x[:4] for m in local])
    phase = (x[:, 3] - 360.0 * (t_ref - dt_epoch) / np.where(x[:, 2] > 0, x[:, 2], np.nan)) % 360
    return minima_dataset(
        [m.label for m in local],
        np.array([m.chi2 for m in local]),
        np.array([m.axis_of(m.x) for m in local]),
        x[:, 2],
        phase,
        best,
    )


def _ambiguity(ds: xr.Dataset) -> str:
    """The minima from other starts that fit about as well as the solution (chi-square gap
    below :data:`AMBIGUITY_CHI2`) at another spin state (period more than 3 sigma away,
    or axis more than 3 times its uncertainty, and 0.1 deg, away)."""
    sig_p = 3 * float(ds["period_uncertainty"])
    sig_a = max(3 * float(ds["axis_uncertainty"]), 0.1)
    rows = []
    for name in ds["start"].values:
        row = ds.sel(start=name)
        gap = float(row["start_chi2_gap"])
        dper = abs(float(row["start_period"]) - float(ds["period"]))
        sep = float(row["start_axis_separation"])
        if gap < AMBIGUITY_CHI2 and (dper > sig_p or sep > sig_a):
            rows.append(
                f"{name} (period {float(row['start_period']):.6g} s, axis {sep:.2g} deg away, "
                f"chi2 gap {gap:.3g})"
            )
    if not rows:
        return "none"
    return (
        f"minima at other spin states fit about as well: {'; '.join(rows)} (chi2 gap < "
        f"{AMBIGUITY_CHI2:g}); the stated uncertainties describe the neighbourhood of the "
        "solution only"
    )
