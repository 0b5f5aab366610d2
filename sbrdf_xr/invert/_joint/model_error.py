"""Model error as part of the model: each material's table may be off by a fractional scale.

A table built from a model or measured in a laboratory describes the flight surface only
to within its calibration, ageing and the model's fidelity.  Fitting a scale ``s_m`` per
material with the Gaussian prior ``s_m ~ N(1, w_m^2)`` (a pseudo-datum ``(s_m - 1) / w_m``
appended to the normalised residuals: the maximum a posteriori estimate of a linearised
Gaussian model, its covariance ``(J^T J)^-1`` over data and prior together; Sivia &
Skilling 2006, *Data Analysis: A Bayesian Tutorial*, §3.4) lets the areas absorb no more
than the data demand, and carries the tables' uncertainty into the areas' uncertainties:
a nuisance parameter marginalised to first order.  The widths default to the table's
``source``: a measured table :data:`PROVENANCE_WIDTH` ``["measured"]``, a model fitted to
measurements ``["model"]``, a synthetic one ``["synthetic"]``.

What no table scale absorbs (a shape, an effect or a colour the model lacks) can be stated
as a model-discrepancy floor per band, ``s_b`` [mag], added in quadrature to every
measured uncertainty of the band (``sigma'^2 = sigma^2 + s_b^2``: an independent Gaussian
model error, the simplest discrepancy term of Kennedy & O'Hagan 2001, J. R. Stat. Soc. B
63, 425, §4.2).  The chi-square, the warnings and the uncertainties are then those of the
model with its stated error.  Estimated (``"estimate"``), each band's floor is the method-
of-moments value ``s_b^2 = max(0, mean_b(r^2) N / (N - p) - mean_b(sigma^2))`` from the
residuals ``r`` of a fit without a floor (``N`` values, ``p`` parameters), and the pass is
fitted again with it.
"""

from __future__ import annotations

import dataclasses
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from ...errors import FitQualityWarning, InversionError
from ...units import to_unit

__all__ = [
    "PROVENANCE_WIDTH",
    "TILT_WIDTH",
    "band_offsets",
    "discrepancy_floor",
    "estimate_floor",
    "estimated_floor",
    "table_widths",
    "tilt_layout",
    "tilt_widths",
    "with_floor",
]

#: Default prior width of a table's scale by its ``source``: absolute BRDF calibration of a
#: laboratory measurement (a few per cent), a model fitted to measurements, and a table
#: made from a model alone (its parameters from the literature, not from the flight part).
PROVENANCE_WIDTH = {"measured": 0.05, "model": 0.1, "synthetic": 0.2}
#: Default prior width of a table's colour tilt: a fractional change of its signal of 5 %
#: per 100 nm (a white paint yellowed by ultraviolet, a cell's coating thicker than made).
TILT_WIDTH = 0.05
#: Most fits made to estimate the model-discrepancy floor (``model_discrepancy="estimate"``).
FLOOR_ROUNDS = 4


def table_widths(
    material_scale: str | Mapping[str, float] | None,
    materials: Sequence[str],
    sources: Mapping[str, str],
) -> np.ndarray | None:
    """Prior width of each material's table scale [1], or None (not fitted).

    ``None``: the tables are taken as exact.  ``"provenance"``: by each table's
    ``source`` attribute (:data:`PROVENANCE_WIDTH`; ``model:<name>`` counts as
    ``"model"``, an unknown source as ``"synthetic"``).  A mapping: a width per material
    (> 0), the others by provenance.

    Examples
    --------
    >>> from sbrdf_xr.invert._joint.model_error import table_widths
    >>> table_widths("provenance", ["paint", "cell"], {"paint": "synthetic",
    ...                                                "cell": "measured"}).tolist()
    [0.2, 0.05]
    >>> table_widths({"paint": 0.1}, ["paint", "cell"], {"cell": "model:phong"}).tolist()
    [0.1, 0.1]
    """
    if material_scale is None:
        return None

    def by_source(m: str) -> float:
        src = str(sources.get(m, ""))
        key = "model" if src.startswith("model") else src
        return PROVENANCE_WIDTH.get(key, PROVENANCE_WIDTH["synthetic"])

    if isinstance(material_scale, str):
        if material_scale != "provenance":
            raise InversionError(
                f"material_scale: {material_scale!r}; allowed None (exact tables), "
                "'provenance' (prior widths by each table's source) or a mapping "
                "{material: width}"
            )
        return np.array([by_source(m) for m in materials])
    if not isinstance(material_scale, Mapping):
        raise InversionError(
            f"material_scale: got {type(material_scale).__name__}; allowed None, "
            "'provenance' or a mapping {material: width}"
        )
    unknown = sorted(set(map(str, material_scale)) - set(materials))
    if unknown:
        raise InversionError(
            f"material_scale: {unknown} are not materials of the body; have {list(materials)}"
        )
    out = []
    for m in materials:
        w: Any = material_scale.get(m, by_source(m))
        w = float(w)
        if not (np.isfinite(w) and w > 0):
            raise InversionError(
                f"material_scale[{m!r}]: {w!r}; allowed a prior width > 0 (a fraction of the "
                "table's signal; leave the material out for its provenance's width)"
            )
        out.append(w)
    return np.array(out)


def tilt_widths(
    colour_tilt: bool | float | Mapping[str, float] | None, materials: Sequence[str]
) -> np.ndarray | None:
    """Prior width of each material's colour tilt [1 per 100 nm], or None (not fitted).

    The table of material ``m`` is scaled in band ``b`` by ``1 + t_m x_b``, ``x_b`` the
    band's mean wavelength less the mean over the fitted bands [100 nm], with the prior
    ``t_m ~ N(0, w_m^2)``.  ``None`` or False: not fitted; True: :data:`TILT_WIDTH` for
    every material; a number: that width for every material; a mapping: per material,
    the others :data:`TILT_WIDTH`.  Widths finite and > 0.

    Examples
    --------
    >>> from sbrdf_xr.invert._joint.model_error import tilt_widths
    >>> tilt_widths(True, ["paint", "cell"]).tolist()
    [0.05, 0.05]
    >>> tilt_widths({"cell": 0.1}, ["paint", "cell"]).tolist()
    [0.05, 0.1]
    """
    if colour_tilt is None or colour_tilt is False:
        return None
    if isinstance(colour_tilt, Mapping):
        unknown = sorted(set(map(str, colour_tilt)) - set(materials))
        if unknown:
            raise InversionError(
                f"colour_tilt: {unknown} are not materials of the body; have {list(materials)}"
            )
        given: dict[str, Any] = {str(k): v for k, v in colour_tilt.items()}
    elif colour_tilt is True:
        given = {}
    else:
        given = dict.fromkeys(materials, colour_tilt)
    out = []
    for m in materials:
        w: Any = given.get(m, TILT_WIDTH)
        try:
            w = float(w)
        except (TypeError, ValueError):
            w = float("nan")
        if not (np.isfinite(w) and w > 0):
            raise InversionError(
                f"colour_tilt[{m!r}]: {given.get(m)!r}; allowed a prior width > 0 (a "
                "fractional change of the table per 100 nm), True (0.05 each) or None"
            )
        out.append(w)
    return np.array(out)


def tilt_layout(
    colour_tilt: Any, materials: Sequence[str], labels: Sequence[str]
) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Prior widths of the tables' colour tilts (:func:`tilt_widths`) and the bands'
    offsets (:func:`band_offsets`), or ``(None, None)`` when not fitted.

    Examples
    --------
    >>> from sbrdf_xr.invert._joint.model_error import tilt_layout
    >>> tilt_layout(None, ["paint"], ["V", "R"])
    (None, None)
    """
    widths = tilt_widths(colour_tilt, materials)
    return widths, None if widths is None else band_offsets(labels)


def band_offsets(labels: Sequence[str]) -> np.ndarray:
    """Each band's mean wavelength ``int T l dl / int T dl`` (its filter response ``T``)
    less the mean over ``labels`` [100 nm].

    Examples
    --------
    >>> from sbrdf_xr.invert._joint.model_error import band_offsets
    >>> x = band_offsets(["V", "I"])
    >>> bool(abs(x.sum()) < 1e-12), bool(2.0 < x[1] - x[0] < 3.0)  # V 550, I 800 nm
    (True, True)
    """
    from ...photometry import filters

    f = filters(list(labels))
    wl = f["wavelength"].values
    t = f.values
    mean = np.trapezoid(t * wl, wl, axis=1) / np.trapezoid(t, wl, axis=1)
    return np.asarray((mean - mean.mean()) / 100.0)


def discrepancy_floor(
    model_discrepancy: float | Mapping[str, float] | None, labels: Sequence[str]
) -> np.ndarray | None:
    """The model-discrepancy floor of every band [mag], or None (the model taken as exact).

    A number (or a Quantity in mag): the same floor in every band; a mapping ``{band:
    floor}``: per band, bands left out 0.  Each floor finite and >= 0.

    Examples
    --------
    >>> from sbrdf_xr.invert._joint.model_error import discrepancy_floor
    >>> discrepancy_floor(0.01, ["V", "R"]).tolist()
    [0.01, 0.01]
    >>> discrepancy_floor({"R": 0.03}, ["V", "R"]).tolist()
    [0.0, 0.03]
    """
    if model_discrepancy is None:
        return None
    if isinstance(model_discrepancy, Mapping):
        unknown = sorted(set(map(str, model_discrepancy)) - set(labels))
        if unknown:
            raise InversionError(
                f"model_discrepancy: bands {unknown} are not fitted; have {list(labels)}"
            )
        given: dict[str, Any] = {str(k): v for k, v in model_discrepancy.items()}
    else:
        given = dict.fromkeys(labels, model_discrepancy)
    out = []
    for b in labels:
        v = to_unit(given.get(b, 0.0), "mag", f"model_discrepancy[{b!r}]")
        try:
            v = float(v)
        except (TypeError, ValueError):
            v = float("nan")
        if not (np.isfinite(v) and v >= 0):
            raise InversionError(
                f"model_discrepancy[{b!r}]: {given.get(b)!r}; allowed a floor >= 0 [mag] "
                "(a number, or a mapping {band: floor})"
            )
        out.append(v)
    return np.array(out)


def with_floor(data: Any, floor: np.ndarray | None) -> Any:
    """``data`` (a :class:`PassData`) with each band's floor [mag] added in quadrature to
    its uncertainties; unchanged for None.

    Examples
    --------
    >>> import dataclasses, numpy as np
    >>> from sbrdf_xr.invert._joint.model_error import with_floor
    >>> @dataclasses.dataclass(frozen=True)
    ... class D:
    ...     sigma: np.ndarray
    ...     band: np.ndarray
    >>> with_floor(D(np.array([0.03, 0.03]), np.array([0, 1])), np.array([0.04, 0.0])).sigma
    array([0.05, 0.03])
    """
    if floor is None:
        return data
    sigma = np.sqrt(np.asarray(data.sigma) ** 2 + floor[np.asarray(data.band)] ** 2)
    return dataclasses.replace(data, sigma=sigma)


def estimate_floor(
    residual: np.ndarray, sigma: np.ndarray, band: Sequence[str], n_parameters: int
) -> dict[str, float]:
    """Each band's model-discrepancy floor [mag] estimated from a fit's residuals [mag]
    and the measured uncertainties [mag] (method of moments, see the module).

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.invert._joint.model_error import estimate_floor
    >>> r = np.array([0.05, -0.05, 0.05, -0.05, 0.01, -0.01, 0.01, -0.01])
    >>> f = estimate_floor(r, np.full(8, 0.01), ["V"] * 4 + ["R"] * 4, 0)
    >>> {b: round(v, 4) for b, v in f.items()}  # V: sqrt(0.05^2 - 0.01^2); R: none
    {'V': 0.049, 'R': 0.0}
    """
    r = np.asarray(residual, dtype=np.float64)
    s2 = np.asarray(sigma, dtype=np.float64) ** 2
    labels = np.asarray(band).astype(str)
    n = r.size
    if n <= n_parameters:
        raise InversionError(
            f"model_discrepancy='estimate': {n} values for {n_parameters} parameters; "
            "allowed more values than parameters (or state the floor)"
        )
    scale = n / (n - n_parameters)  # residuals of a fit are smaller than the errors
    out = {}
    for b in dict.fromkeys(labels.tolist()):
        m = labels == b
        out[b] = float(np.sqrt(max(0.0, np.mean(r[m] ** 2) * scale - np.mean(s2[m]))))
    return out


def estimated_floor(fit_observation: Callable[..., Any], args: dict[str, Any]) -> Any:
    """``model_discrepancy="estimate"``: a point fit without a floor, each band's floor from
    its residuals (:func:`estimate_floor`), refitted with it until the floors
    settle (within 5 % or 0.001 mag, at most :data:`FLOOR_ROUNDS` fits), then the fit asked
    for with them (``fit_observation`` called with ``args``, its own arguments).

    Examples
    --------
    >>> from sbrdf_xr.invert._joint.model_error import estimated_floor
    >>> estimated_floor(print, {"model_discrepancy": "median"})
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.InversionError: model_discrepancy: 'median'; allowed 'estimate', ...
    """
    if args["model_discrepancy"] != "estimate":
        raise InversionError(
            f"model_discrepancy: {args['model_discrepancy']!r}; allowed 'estimate', a floor "
            ">= 0 [mag] or a mapping {band: floor}"
        )
    t0 = time.perf_counter()
    floor: dict[str, float] | None = None
    sigma = np.asarray(args["light_curve"]["uncertainty"].values)
    for _ in range(FLOOR_ROUNDS):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FitQualityWarning)
            fit = fit_observation(
                **{**args, "model_discrepancy": floor, "method": "point", "check": False}
            )
        res = fit["residual"]
        band = next(c for c in res.coords if str(c).startswith("band"))
        new = estimate_floor(
            res.values,
            sigma,
            res[band].values,
            fit.sizes["parameter"],
        )
        settled = floor is not None and all(
            abs(new[b] - floor[b]) <= max(0.05 * floor[b], 1e-3) for b in new
        )
        floor = new
        if settled:
            break
    first_s = time.perf_counter() - t0
    ds = fit_observation(**{**args, "model_discrepancy": floor})
    ds.attrs["model_discrepancy"] = (
        "estimated from the residuals (method of moments, iterated), "
        + ds.attrs["model_discrepancy"]
    )
    ds.attrs["model_discrepancy_seconds"] = first_s  # the estimating fits' cost, on top
    return ds
