"""Start states of a joint fit and the table of the minima refined from them.

See :func:`sbrdf_xr.invert.fit_observation` (``starts``).  A start is an inertial spin
axis, a period [s] and the phase [degree] at the middle of the measured times, the
parametrisation of the fit.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike

from ...errors import InversionError
from ...units import to_unit
from .._spin.refine import axis_angle
from .._spin.search import lonlat, vec

__all__ = ["Start", "axis_body_of", "minima_dataset", "read_start", "start_states"]


def read_start(spin: Any) -> tuple[dict[str, float], Any]:
    """Start values (axis_longitude, axis_latitude, period, phase) and their epoch (UTC or
    None), from a :func:`fit_spin` result or a mapping."""
    keys = ("axis_longitude", "axis_latitude", "period", "phase")
    have: Mapping[Any, Any]
    attrs: Mapping[Any, Any]
    if isinstance(spin, xr.Dataset):
        have, attrs = {k: spin[k].values for k in spin.variables}, spin.attrs
    elif isinstance(spin, Mapping):
        have, attrs = spin, spin
    else:
        raise InversionError(
            f"spin: expected the Dataset of fit_spin or a mapping of {list(keys)} (and epoch), "
            f"got {type(spin).__name__}"
        )
    missing = [k for k in keys if k not in have]
    if missing:
        raise InversionError(f"spin: missing {missing}; a start needs {list(keys)}")
    units = {"axis_longitude": "deg", "axis_latitude": "deg", "period": "s", "phase": "deg"}
    out = {k: float(np.asarray(to_unit(have[k], units[k], f"spin {k}"))) for k in keys}
    if not all(np.isfinite(v) for v in out.values()) or out["period"] <= 0:
        raise InversionError(f"spin: start values must be finite with period > 0 [s], got {out}")
    epoch = attrs.get("epoch")
    if epoch is not None:
        try:
            epoch = np.datetime64(str(epoch)).astype("datetime64[ns]")
        except ValueError:
            raise InversionError(
                f"spin: epoch {epoch!r} is not a UTC time; the spin must be fitted to the "
                "observation (fit_spin(..., geometry=observation)) or give epoch as UTC"
            ) from None
    return out, epoch


def axis_body_of(spin: Any, axis_body: ArrayLike | None) -> np.ndarray:
    """The body axis of the spin: given, else the :func:`fit_spin` result's, else z."""
    attrs = spin.attrs if isinstance(spin, xr.Dataset) else spin
    ab = axis_body
    if ab is None:
        ab = attrs.get("axis_body", (0.0, 0.0, 1.0))
        if isinstance(ab, str):
            ab = [float(v) for v in ab.strip("[]()").split(",")]
    abv = np.asarray(ab, dtype=np.float64)
    if abv.shape != (3,) or not np.all(np.isfinite(abv)) or np.linalg.norm(abv) == 0:
        raise InversionError(f"axis_body: {ab!r}; allowed a finite nonzero 3-vector")
    return abv


#: Half turns more and fewer over the measured span tried by ``starts="aliases"``.
ALIAS_HALF_TURNS = (-2, -1, 1, 2)


@dataclasses.dataclass(frozen=True)
class Start:
    """A start: ``label``, unit inertial ``axis``, ``period`` [s] and ``phase_ref``
    [degree], the phase at ``t_ref`` (the middle of the measured times)."""

    label: str
    axis: np.ndarray
    period: float
    phase_ref: float


def _at_ref(label: str, values: Mapping[str, float], dt: float, t_ref: float) -> Start:
    """A start from longitude, latitude [degree], period [s] and the phase [degree] at
    ``dt`` seconds after the data's epoch."""
    period = float(values["period"])
    if not (np.isfinite(period) and period > 0):
        raise InversionError(f"starts: {label}: period {period!r} [s]; allowed finite > 0")
    axis = vec(float(values["axis_longitude"]), float(values["axis_latitude"]))
    return Start(label, axis, period, float(values["phase"]) + 360.0 * (t_ref - dt) / period)


def start_states(
    starts: str | Sequence[Mapping[str, Any]],
    spin: Any,
    given: Mapping[str, float],
    dt_epoch: float,
    t_ref: float,
    span: float,
    read: Any,
) -> list[Start]:
    """The start states of a fit: the given one first, then ``starts``'s.

    ``"given"``: the given start only.  ``"aliases"``: also the period aliases of the
    given start, a half and a whole turn more and fewer over the measured ``span`` [s]
    (``P' = span / (span / P + j / 2)``, the phase at ``t_ref`` kept), and the twins of a
    :func:`sbrdf_xr.invert.fit_spin` result (its ``solution_*`` rows).  A sequence: the
    given start and those (mappings as ``spin``, read by ``read(mapping) -> (values,
    seconds of its epoch after the data's epoch or None)``).
    """
    out = [_at_ref("given", given, dt_epoch, t_ref)]
    if isinstance(starts, str):
        if starts not in ("given", "aliases"):
            raise InversionError(
                f"starts: {starts!r}; allowed 'given' (the spin only), 'aliases' (the spin, "
                "its period aliases and fit_spin's twins) or a sequence of start mappings"
            )
        if starts == "given":
            return out
        first = out[0]
        turns = span / first.period
        for j in ALIAS_HALF_TURNS:
            if turns + 0.5 * j > 0.25:
                p = span / (turns + 0.5 * j)
                out.append(Start(f"alias {j:+d}/2 turn", first.axis, p, first.phase_ref))
        if isinstance(spin, xr.Dataset) and "solution" in spin.dims:
            for name in spin["solution"].values:
                row = spin.sel(solution=name)
                values = {
                    k: float(row[f"solution_{k}"])
                    for k in ("axis_longitude", "axis_latitude", "period", "phase")
                }
                out.append(_at_ref(f"twin {name}", values, dt_epoch, t_ref))
        return out
    if isinstance(starts, Mapping) or not isinstance(starts, Sequence):
        raise InversionError(
            f"starts: got a {type(starts).__name__}; allowed 'given', 'aliases' or a sequence "
            "of start mappings (axis_longitude, axis_latitude, period, phase, epoch)"
        )
    for i, s in enumerate(starts):
        values, dt = read(s)
        out.append(_at_ref(f"start {i}", values, dt_epoch if dt is None else dt, t_ref))
    return out


def minima_dataset(
    labels: Sequence[str],
    chi2: np.ndarray,
    axes: np.ndarray,
    periods: np.ndarray,
    phases: np.ndarray,
    best: int,
) -> xr.Dataset:
    """The minimum refined from every start, over ``start``: chi-square, its gap above
    the solution's, period, phase at the epoch, axis and its angle from the solution's."""
    lon, lat = (np.atleast_1d(v) for v in lonlat(axes))
    sep = [axis_angle(a, axes[best]) for a in axes]

    def cf(u: str, ln: str) -> dict[str, str]:
        return {"units": u, "long_name": ln}

    rows = {
        "start_chi2": (chi2, cf("1", "chi-square of the minimum refined from the start")),
        "start_chi2_gap": (chi2 - chi2[best], cf("1", "chi-square above the solution's")),
        "start_period": (periods, cf("s", "spin period of the minimum")),
        "start_phase": (phases, cf("degree", "spin angle at the epoch of the minimum")),
        "start_axis_longitude": (lon, cf("degree", "longitude of the minimum's spin axis")),
        "start_axis_latitude": (lat, cf("degree", "latitude of the minimum's spin axis")),
        "start_axis_separation": (
            np.asarray(sep),
            cf("degree", "angle between the minimum's spin axis and the solution's"),
        ),
    }
    return xr.Dataset(
        {k: ("start", np.asarray(v, dtype=float), a) for k, (v, a) in rows.items()},
        coords={"start": ("start", list(labels), cf("1", "start state of the refinement"))},
    )
