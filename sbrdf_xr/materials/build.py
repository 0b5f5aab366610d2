"""Material tables from sparse measurements: the construction of paper 000 §3.2.

:func:`build_lut` is the xarray front end of the construction (validation, the
below-noise and extrapolation policies, the energy bounds); the numpy core of its steps
is :mod:`sbrdf_xr.materials.construction`.  Beyond the paper, a fitted model can carry the table
where the instrument sees nothing (``below_noise="model"``, ``extrapolation="model"``),
and every row can be renormalised to the model's directional-hemispherical reflectance
(``renormalise="model"``) so that the table keeps the model's energy.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from .._names import DELTA_THETA, MEASURED, PHI, SAMPLE, THETA_I, WAVELENGTH
from ..errors import ValidationError
from ..kernels import lut as _lut
from ..units import to_unit
from . import _fill as fill
from . import models
from ._jobs import _Job, _Parts
from .construction import (
    azimuthal_average,
    lut_edges,
    paper_delta_theta_grid,
    paper_phi_grid,
)
from .coverage import (
    _at_horizon,
    _coverage_attrs,
    _in_plane_phi_grid,
    _resolve_below_noise,
    _specular_nodes,
    scan_layout,
    snap_angles,
)
from .energy import _check_energy_conservation, _clamp_energy, _given_reflectance
from .schema import (
    average_duplicates,
    check_coord,
    new_material,
    reference_mask,
    validate_measurements,
)
from .selfcheck import CHECK_BOUND, CHECK_FLOOR, _holdout_check, _self_check

__all__ = ["BELOW_NOISE", "EXTRAPOLATIONS", "RENORMALISE", "build_lut"]

#: Extrapolation policies of :func:`build_lut` beyond the measured incidence angles.
EXTRAPOLATIONS = ("auto", "cubic", "linear", "constant", "model")
#: Below-noise policies of :func:`build_lut`.
BELOW_NOISE = ("auto", "zero", "model")
#: Row renormalisations of :func:`build_lut`.
RENORMALISE = ("auto", "none", "model")


def build_lut(
    measurements: xr.Dataset,
    *,
    n_phi: int = 21,
    n_delta_theta: int = 21,
    theta_i: ArrayLike | None = None,
    smoothing: float | str = 0.0,
    extrapolation: str = "auto",
    material: str | None = None,
    dtype: type | np.dtype = np.float64,
    blend: float = 10.0,
    model: xr.Dataset | str | None = None,
    normal_incidence: str = "symmetric",
    blend_normal: float = 5.0,
    below_noise: str = "auto",
    duplicates: str = "error",
    check_energy: bool | str = True,
    renormalise: str = "auto",
    progress: Callable[[float, str], None] | None = None,
    model_reflectance: xr.DataArray | None = None,
    check_floor: float = CHECK_FLOOR,
    check_bound: float = CHECK_BOUND,
    holdout: int = 4,
) -> xr.DataArray:
    """Look-up table from sparse measurements, by the construction of paper 000 §3.2.

    1. ``phi``: ``n_phi`` uniform points from 0 to the largest measured ``phi`` of
       the material; for every measured ``(theta_i, delta_theta)`` row, linear
       interpolation in ``phi`` (zero beyond the row's largest ``phi`` when it is a
       reference point, as in the paper).
    2. ``delta_theta``: ``n_delta_theta`` points with 0 at the median and steps
       ``delta_theta_min/10`` and ``delta_theta_max/10`` on either side (for the
       paper's 21), from the extremes over all ``theta_i``; for every measured
       ``theta_i`` and grid ``phi``, linear interpolation in ``delta_theta``
       (zero beyond that ``theta_i``'s measured extent when it is a reference
       point).


       Where an extent is a measured point rather than a reference point (the
       apparatus stopped before the signal reached the noise, as for diffuse
       materials), the edge value is held beyond it instead of dropping to zero; the
       paper's sets end in reference points, for which this is the paper's rule.
    3. ``theta_i``: a cubic smoothing spline over the measured incidence angles for
       every ``(delta_theta, phi, wavelength)``, evaluated at every integer degree
       0-90 (interpolating between and extrapolating beyond the measured angles).

    Values are clipped at zero after step 3 (a smoothing spline can undershoot,
    and a BRDF cannot be negative).  Everything is vectorised: each step is one
    linear operator applied to all wavelengths at once.

    ``below_noise="model"`` (beyond the paper) keeps the diffuse floor and the lobe's
    tails that the instrument cannot see: the same three steps interpolate the
    *ratio* of every measured spectrum to a fitted model (``model``), with every
    edge held and the reference points left out, and the table is the model
    rendered on the grid times that ratio.  Below-noise geometries (the reference
    points and everything beyond each incidence angle's extents, out to the
    horizon: the grids are extended to ``delta_theta`` -180..90 and ``phi`` 90 deg
    in steps of at most 5 deg) then carry the model scaled by the nearest measured
    ratio instead of zero, the ratio equals the measured one at the measured
    geometries, and between them the lobe keeps the model's shape (a needle lobe is
    not flattened by linear interpolation between samples a quarter of its extent
    apart).  Below the smallest measured incidence angle the ratio is held (the
    model carries the angular trend); above the largest, with
    ``extrapolation="model"``, it goes to one over ``blend`` degrees (the model alone
    near grazing, where a lobe meets the horizon and the measured ratio does not
    carry over), and a row whose directional-hemispherical reflectance exceeds the
    model's is scaled down to it (grazing extrapolation bounded by the model).

    Angles are grouped with a tolerance, never by float equality: sample angles closer
    than :data:`~sbrdf_xr.materials.coverage.ANGLE_TOL` (1e-6 degree) are one angle
    (:func:`~sbrdf_xr.materials.coverage.snap_angles`), so angles converted from
    conventional ones (:func:`sbrdf_xr.geometry.from_conventional`) group as measured.
    Data that do not come in the paper's rows (:func:`~sbrdf_xr.materials.coverage.scan_layout`)
    are built with ``below_noise="model"``: an in-plane scan (every ``phi = 0``) gives
    an isotropic table on the scan's own ``delta_theta`` nodes whose out-of-plane
    values are the fitted model times the measured ratio at the same angular distance
    from specular; samples scattered over ``(delta_theta, phi)`` have their ratio to
    the model interpolated on their triangulation.  The measured incidence angles are
    then rows of the table.  The attributes ``layout`` and ``modelled`` say what was
    measured and what comes from the model.

    Every build checks itself against its own samples
    (:mod:`sbrdf_xr.materials.selfcheck`): attributes ``self_check_median``,
    ``self_check_p95`` and ``self_check_worst`` (relative errors over the samples above
    ``check_floor`` of their incidence angle's peak); a median above ``check_bound``
    warns naming the worst geometries, a table zero where the samples are not raises.

    Parameters
    ----------
    measurements : xarray.Dataset
        Measurement set (:func:`~sbrdf_xr.materials.schema.validate_measurements`).
    n_phi : int, default 21
        Points of the ``phi`` grid (paper: 21).
    n_delta_theta : int, default 21
        Points of the ``delta_theta`` grid, odd (paper: 21).
    theta_i : array_like, optional
        Output incidence angles [degree]; default every integer 0-90 (paper).
    smoothing : float or "csaps", default 0
        Smoothing parameter ``lam`` [degree**3] of the cubic smoothing spline in
        ``theta_i`` (:func:`sbrdf_xr.kernels.lut.smoothing_spline_matrix`).  Paper 000
        does not give it.  The default 0 makes the spline pass through the
        measurements (a natural cubic spline; ``p = 1`` in MATLAB's ``csaps``
        terms).  ``"csaps"`` is MATLAB's default ``lam = h**3/6``
        (:func:`sbrdf_xr.kernels.lut.csaps_default_lambda`), which with five incidence
        angles 10-15 deg apart smooths spectral features that move with angle
        (a solar cell's interference minima) by tens of nanometres.
    extrapolation : {"auto", "cubic", "linear", "constant", "model"}, default "auto"
        How the table continues below the smallest and above the largest measured
        ``theta_i``.  ``auto`` is ``cubic`` for data in the paper's rows and ``model``
        otherwise (an in-plane scan's ratio to the model is not extrapolated by a
        polynomial).  ``cubic`` continues the spline's end polynomial
        pieces, as the paper's spline evaluation did (the source of the
        discontinuities its §4.2 reports); ``linear`` and ``constant`` are milder.
        ``model`` (beyond the paper) fits the Robertson-Sandford model (paper 001)
        to the measurements (:func:`sbrdf_xr.brdf.robertson_sandford_fit.fit_robertson_sandford`)
        and lets it fill the unmeasurable range, blended into the linearly
        extrapolated spline over ``blend`` degrees with a smoothstep weight.  With
        ``below_noise="model"`` the model carries the table everywhere and this
        only chooses how the ratio continues: held (``constant``, ``model``) or as
        the spline says.
    blend : float, default 10
        Width of the blend zone of ``extrapolation="model"`` [degree].
    model : xarray.Dataset or str, optional
        The model material of ``extrapolation="model"`` and ``below_noise="model"``
        (:mod:`sbrdf_xr.materials.models`), or the name of the fit that makes it from
        the measurements (:data:`sbrdf_xr.materials.models.FITS`: ``"microfacet"``,
        ``"robertson-sandford"``; the leave-out check refits it to the held-in
        samples); default: a Robertson-Sandford fit
        (:func:`sbrdf_xr.materials.models.fit_robertson_sandford`, a few seconds).
    normal_incidence : {"symmetric", "paper"}, default "symmetric"
        ``symmetric`` enforces what physics requires at ``theta_i = 0``: no
        dependence on the undefined illumination plane.  The ``theta_i = 0`` row
        becomes its own azimuthal average (for every node, the mean over the
        illumination-plane azimuth of the row at the same observer polar angle
        ``theta_r``, by 64-point Gauss-Legendre quadrature), and the table records
        ``normal_incidence_blend = blend_normal``: look-ups below that angle blend
        towards the row's in-plane profile at ``theta_r``
        (:func:`sbrdf_xr.kernels.lut.lookup_matrix`), so the look-up is independent of the
        Sun's azimuth as ``theta_i -> 0``.  ``paper`` leaves the row as extrapolated.
    blend_normal : float, default 5
        Width of that blend [degree].
    below_noise : {"auto", "zero", "model"}, default "auto"
        ``zero`` is the paper's: reference points and everything beyond an
        incidence angle's extents are zero.  ``model``: see above.  ``auto`` is
        ``zero`` for data in the paper's rows and ``model`` otherwise (in-plane or
        scattered samples); ``zero`` with such data is an error.
    duplicates : {"error", "mean"}, default "error"
        A geometry measured more than once is an error
        (:func:`~sbrdf_xr.materials.schema.validate_measurements`) or its repeats are
        averaged (``mean``: the mean of the measured repeats; a reference point only if
        all repeats are).
    renormalise : {"auto", "none", "model"}, default "auto"
        ``model`` (``auto`` with ``below_noise="model"``) is a flux-conserving
        correction of the interpolant.  A lobe sampled on nodes a few degrees apart,
        above all one meeting the horizon at grazing incidence, integrates under the
        look-up's multilinear interpolation to more or less energy than the lobe
        itself: a GGX lobe of roughness 0.15 rendered on such a grid gains 18 % at
        ``theta_i = 85`` deg.  Every row ``(theta_i, wavelength)`` is scaled by
        ``rho_model / rho_grid``, the factor that restores to the model rendered on
        the grid the model's own directional-hemispherical reflectance
        (``rho_grid`` by the quadrature of
        :func:`~sbrdf_xr.materials.energy.hemispherical_reflectance`), and
        keeps the ratio to the measurements: a table of the model itself has the
        model's energy exactly, and the rows beyond the measured angles, where the
        table is the model, are bounded by its reflectance.  It is the
        normalisation step of conservative remapping (P. W. Jones, Mon. Wea. Rev.
        127, 2204, 1999: rescale the interpolant so that it keeps the integral of
        the field it samples), applied per row.  ``none`` keeps the interpolant (and,
        with ``extrapolation="model"``, only scales rows above the measured angles
        down to the model's reflectance); ``auto`` is ``none`` with
        ``below_noise="zero"`` (the paper's construction).
    check_energy : bool or "clamp", default True
        Compute the table's directional-hemispherical reflectance every 5 deg of
        ``theta_i`` (and at the last row) and issue a
        :class:`~sbrdf_xr.errors.NonPhysicalWarning` naming the incidence angle and
        wavelength where it exceeds 1.  ``"clamp"`` first bounds it by 1 at every row
        (:func:`~sbrdf_xr.materials.energy._clamp_energy`): where a row reflects more
        than it receives, its values out of the plane of incidence (``phi > 0``; for
        in-plane scans the modelled extension) are scaled down until it reflects 1,
        and the plane keeps its samples (attributes ``energy_clamp_*``).
    material : str, optional
        Name; default the ``material`` attribute of ``measurements``.
    dtype : numpy dtype, default float64
        dtype of the table values.
    progress : callable, optional
        ``progress(fraction, step)``, called as the construction goes on with the
        fraction of its work done (0 to 1) and what it is doing (``"model on the
        grid"``, ``"model reflectance"``, ...): for a progress bar.
    model_reflectance : xarray.DataArray, optional
        The model's directional-hemispherical reflectance ``rho_model`` of
        ``renormalise="model"`` at the table's rows, dims ``(theta_i, wavelength)`` with
        the table's incidence angles and the measurements' wavelengths [1], when it is
        known: its quadrature is most of a build's work (the catalog ships it for its
        tables, :mod:`sbrdf_xr.materials.shipped`).  Computed when not given.

    check_floor : float, default 1e-3
        Noise floor of the self-check [1]: samples below this fraction of the peak of
        their incidence angle's samples are left out.
    check_bound : float, default 0.1
        Own-sample median relative error above which the build warns [1].
    holdout : int, default 4
        Leave-out check of a table filled by a fitted model (in-plane or scattered
        data): every ``holdout``-th sample of each incidence angle's scan (in
        ``delta_theta`` order, the ends kept) is left out, the table built again from
        the rest (its own fit) and looked up at them; attributes
        ``holdout_check_median``, ``_p95``, ``_worst`` and ``_n``.  0 skips it (it
        doubles the build's work).

    Returns
    -------
    xarray.DataArray
        The material table with ``source`` and ``provenance`` copied from the
        measurement set and the construction parameters as attributes.

    Raises
    ------
    ValidationError
        For an invalid measurement set, fewer than two measured incidence angles,
        no measured extent in ``phi`` or ``delta_theta``, repeated geometries with
        ``duplicates="error"``, in-plane or scattered data with ``below_noise="zero"``,
        a table zero where its samples are not.

    Examples
    --------
    The construction of paper 000 §3.2 from a small synthetic measurement set (two
    incidence angles, three wavelengths); the table reproduces the measured specular
    spectrum at a measured incidence angle:

    >>> import numpy as np
    >>> from sbrdf_xr.materials.tables import build_lut
    >>> from sbrdf_xr.testing import make_measurements
    >>> meas = make_measurements(n_wavelength=3, theta_i=(20.0, 50.0))
    >>> lut = build_lut(meas, n_phi=11, n_delta_theta=11)
    >>> lut.dims, lut.shape
    (('theta_i', 'delta_theta', 'phi', 'wavelength'), (91, 11, 11, 3))
    >>> lut.attrs["construction"], lut.attrs["measured_theta_i"].tolist()
    ('paper000-3.2', [20.0, 50.0])
    >>> at = (meas.theta_i == 20.0) & (meas.delta_theta == 0.0) & (meas.phi == 0.0)
    >>> measured = meas.measured_sbrdf.where(at, drop=True).values[0]
    >>> bool(np.allclose(lut.sel(theta_i=20.0, delta_theta=0.0, phi=0.0), measured))
    True
    """
    call = {k: v for k, v in locals().items() if k != "measurements"}  # for the holdout
    theta_i = to_unit(theta_i, "deg", "theta_i")
    smoothing = to_unit(smoothing, "deg3", "smoothing")  # "csaps" is kept
    blend, blend_normal = (
        to_unit(blend, "deg", "blend"),
        to_unit(blend_normal, "deg", "blend_normal"),
    )
    ds = validate_measurements(measurements, duplicates=duplicates)
    if duplicates == "mean":
        ds = average_duplicates(ds)
    _check_policies(extrapolation, normal_incidence, below_noise)
    ref = reference_mask(ds)
    ti_s, dt_s, ph_s = (snap_angles(ds[d].values) for d in (THETA_I, DELTA_THETA, PHI))
    measured_ti = np.unique(ti_s)
    horizon = _at_horizon(ti_s, dt_s, ph_s, warn=True, known=ref)  # cos(theta_r) = 0: out
    ref = ref | horizon
    layouts = [scan_layout(dt_s[ti_s == t], ph_s[ti_s == t]) for t in measured_ti]
    below_noise = _resolve_below_noise(below_noise, layouts, measured_ti)
    rows_only = all(lay == "rows" for lay in layouts)
    if extrapolation == "auto":
        extrapolation = "cubic" if rows_only else "model"
    renormalise = _resolve_renormalise(renormalise, below_noise, rows_only)
    report = progress or _no_progress
    report(0.0, "measurements")
    wl = np.asarray(ds[WAVELENGTH].values, dtype=np.float64)
    spectra = np.asarray(ds[MEASURED].transpose(SAMPLE, WAVELENGTH).values, dtype=np.float64).copy()
    spectra[ref] = 0.0
    if measured_ti.size < 2:
        raise ValidationError(
            "theta_i: need measurements at >= 2 incidence angles to build a table, "
            f"got {measured_ti.tolist()}"
        )
    dt_grid, phi_grid = _angle_grids(layouts, dt_s, ph_s, n_phi, n_delta_theta)
    ti_out = np.arange(0.0, 91.0) if theta_i is None else np.asarray(theta_i, dtype=np.float64)
    if theta_i is None and not rows_only:  # the measured incidence angles are rows
        ti_out = np.union1d(ti_out, measured_ti)
    check_coord("theta_i", ti_out)
    lam = _lut.csaps_default_lambda(measured_ti) if smoothing == "csaps" else float(smoothing)
    extra: dict[str, Any] = {}
    fit_model = model if isinstance(model, xr.Dataset) else None
    if (extrapolation == "model" or below_noise == "model") and not isinstance(model, xr.Dataset):
        fit_model = models.fit_model(ds, model or "robertson-sandford")

    rho_given = (
        None if model_reflectance is None else _given_reflectance(model_reflectance, ti_out, wl)
    )
    steps = {k: v for k, v in _MODEL_STEPS.items() if rho_given is None or k != "model reflectance"}
    parts = _Parts(report, steps)
    rho_job: _Job | None = None
    samples = fill.Samples(measured_ti, ti_s, dt_s, ph_s, spectra, ref, rows_only, wl)
    grid = fill.Grid(ti_out, dt_grid, phi_grid, lam)
    if below_noise == "zero":
        lut, edges = fill.zero_below_noise(samples, grid, extrapolation, fit_model, blend, report)
        base = lut  # not used: renormalise="model" needs below_noise="model"
    else:
        assert fit_model is not None  # fitted above whenever a model is used
        if not rows_only:
            extra.update(_coverage_attrs(layouts, measured_ti, fit_model))
        lut, base, edges, rho_job, grid = fill.model_ratio(
            samples, grid, extrapolation, fit_model, blend, report, renormalise, rho_given, parts
        )
        dt_grid, phi_grid = grid.dt, grid.phi
    if fit_model is not None and (extrapolation == "model" or below_noise == "model"):
        extra.update(
            extrapolation_model=fit_model.attrs.get("model", ""),
            extrapolation_model_provenance=fit_model.attrs.get("provenance", ""),
        )
        if extrapolation == "model" and below_noise == "zero":
            extra["blend_width"] = blend
    if normal_incidence == "symmetric" and ti_out[0] == 0.0:
        lut[0] = azimuthal_average(lut[0], dt_grid, phi_grid, lut_edges(edges))
        if renormalise == "model":
            base[0] = azimuthal_average(base[0], dt_grid, phi_grid, lut_edges(edges))
        extra["normal_incidence_blend"] = float(blend_normal)
    if renormalise == "model":
        if rho_job is None:  # pragma: no cover - below_noise="model" needs the model
            raise ValidationError("renormalise='model' needs the table's model")
        fill._renormalise_rows(
            lut,
            base,
            (ti_out, dt_grid, phi_grid),
            rho_job,
            lut_edges(edges),
            extra.get("normal_incidence_blend", 0.0),
            parts,
        )
        extra["renormalise"] = "model"

    if check_energy == "clamp":  # the checks see the table as shipped
        extra.update(_clamp_energy(lut, (ti_out, dt_grid, phi_grid), lut_edges(edges),
                                   extra.get("normal_incidence_blend", 0.0)))  # fmt: skip
    name = material or ds.attrs.get("material", "unnamed")
    prov = ds.attrs.get("provenance", "")
    out = new_material(
        lut.astype(dtype, copy=False),
        ti_out,
        dt_grid,
        phi_grid,
        wl,
        material=name,
        source=ds.attrs.get("source", "measured"),
        provenance=(prov + "; " if prov else "") + "look-up table built by sbrdf_xr.build_lut "
        "(paper 000 section 3.2)"
        + (
            f"; measured: {extra['layout']}; modelled: {extra['modelled']}"
            if "layout" in extra
            else ""
        ),
        construction="paper000-3.2",
        n_phi=n_phi,
        n_delta_theta=n_delta_theta,
        smoothing_lambda=lam,
        extrapolation=extrapolation,
        normal_incidence=normal_incidence,
        below_noise=below_noise,
        measured_theta_i=measured_ti,
        n_measurements=int(ds.sizes[SAMPLE]),
        n_dropped_horizon=int(horizon.sum()),
        **edges,
        **extra,
    )
    measured = (ds, (ti_s, dt_s, ph_s), spectra, ref)
    _check_table(out, measured, ti_out, call, report, check_floor, check_bound, check_energy)
    if holdout and not rows_only:  # a fitted fill: predict samples it has not seen
        _leave_out_check(out, measured, call, report, int(holdout), check_floor)
    # last: shown by print(table) beside the checks
    out.attrs.update({k: out.attrs.pop(k) for k in ("layout", "modelled") if k in out.attrs})
    report(1.0, "built")
    return out


def _leave_out_check(
    out: xr.DataArray,
    measured: tuple[Any, ...],
    call: dict[str, Any],
    report: Callable[[float, str], None],
    every: int,
    floor: float,
) -> None:
    """Every ``every``-th sample left out, the table rebuilt from the rest (a fit's name:
    the held-in samples' own fit) and compared with the samples it has not seen."""
    report(0.97, "leave-out check")
    clamp = call["check_energy"] == "clamp" and "clamp"
    opts = {**call, "holdout": 0, "check_energy": clamp, "progress": None}
    rebuild = functools.partial(build_lut, **opts)
    out.attrs.update(_holdout_check(rebuild, *measured, every=every, floor=floor))


def _check_table(
    out: xr.DataArray,
    measured: tuple[Any, ...],
    ti_out: np.ndarray,
    call: dict[str, Any],
    report: Callable[[float, str], None],
    floor: float,
    bound: float,
    check_energy: bool | str,
) -> None:
    """The table against its own samples, and (``check_energy``) its energy bound."""
    out.attrs.update(_self_check(out, *measured, floor=floor, bound=bound))
    if check_energy:
        report(0.95, "energy check")
        _check_energy_conservation(out, np.unique(np.concatenate([ti_out[::5], ti_out[-1:]])))


def _check_policies(extrapolation: str, normal_incidence: str, below_noise: str) -> None:
    """The policies of :func:`build_lut` are among those it knows."""
    if extrapolation not in EXTRAPOLATIONS:
        raise ValidationError(
            f"extrapolation: got {extrapolation!r}; allowed: {', '.join(EXTRAPOLATIONS)}"
        )
    if normal_incidence not in ("paper", "symmetric"):
        raise ValidationError(
            f"normal_incidence: got {normal_incidence!r}; allowed: symmetric, paper"
        )
    if below_noise not in BELOW_NOISE:
        raise ValidationError(
            f"below_noise: got {below_noise!r}; allowed: {', '.join(BELOW_NOISE)}"
        )


def _resolve_renormalise(renormalise: str, below_noise: str, rows_only: bool) -> str:
    """``renormalise`` checked, and ``"auto"`` resolved from the data's layout."""
    if renormalise not in RENORMALISE:
        raise ValidationError(
            f"renormalise: got {renormalise!r}; allowed: {', '.join(RENORMALISE)}"
        )
    if renormalise == "auto":  # keep measured values where the data are not in rows
        return "model" if below_noise == "model" and rows_only else "none"
    if renormalise == "model" and below_noise != "model":
        raise ValidationError(
            "renormalise: 'model' corrects a table made of a model times a ratio and needs "
            f"below_noise='model', got below_noise={below_noise!r}"
        )
    return renormalise


def _angle_grids(
    layouts: list[str], dt_s: np.ndarray, ph_s: np.ndarray, n_phi: int, n_delta_theta: int
) -> tuple[np.ndarray, np.ndarray]:
    """The ``delta_theta`` and ``phi`` grids [degree]: the in-plane scans' own nodes, or
    the paper's grids over the measured span."""
    if all(lay == "in-plane" for lay in layouts):  # the scans' own nodes
        dt_grid = _specular_nodes(dt_s)
        return dt_grid, _in_plane_phi_grid(float(np.median(np.diff(np.unique(dt_s)))))
    phi_grid = paper_phi_grid(ph_s.max(), n_phi)
    return paper_delta_theta_grid(dt_s.min(), dt_s.max(), n_delta_theta), phi_grid


def _no_progress(fraction: float, step: str) -> None:
    """The progress report of a build that shows none."""


#: The steps of a table made from a model (``below_noise="model"``) and their shares of
#: its work, for the progress report.
_MODEL_STEPS = {
    "ratio to the model": 0.05,
    "model grid": 0.2,
    "model reflectance": 0.5,
    "table reflectance": 0.2,
    "energy check": 0.05,
}
