"""The data of a spin fit: measured fluxes, and the inertial geometry at their times.

See :func:`sbrdf_xr.invert.fit_spin`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any

import numpy as np
import xarray as xr

from ...errors import InversionError

__all__ = [
    "LN10_2P5",
    "SpinGeometry",
    "band_factors",
    "directions",
    "light_curve_fluxes",
    "spin_geometry",
]

#: ln(10) / 2.5: d(flux) / flux per magnitude.
LN10_2P5 = np.log(10.0) / 2.5
_NS = "datetime64[ns]"


def light_curve_fluxes(
    light_curve: xr.Dataset, bands: Sequence[str] | None = None
) -> dict[str, np.ndarray]:
    """Times, band index, relative flux and its uncertainty from a light curve.

    ``light_curve`` is what :func:`sbrdf_xr.lightcurves.read_light_curve` returns (over
    ``obs``: ``magnitude``, ``uncertainty`` [mag], coords ``band``, ``time`` [s] or UTC
    datetime64) or the same with ``flux`` and ``flux_uncertainty`` instead of magnitudes.
    ``time`` is returned as given (float seconds, or datetime64[ns]).

    Examples
    --------
    Magnitudes become fluxes relative to the median magnitude (9.75 here),
    ``10**(-0.4 (m - 9.75))``:

    >>> import xarray as xr
    >>> from sbrdf_xr.invert import light_curve_fluxes
    >>> lc = xr.Dataset(
    ...     {"magnitude": ("obs", [10.0, 9.5, 10.0, 9.0]), "uncertainty": ("obs", [0.01] * 4)},
    ...     coords={"time": ("obs", [0.0, 0.0, 10.0, 10.0]), "band": ("obs", ["V", "R"] * 2)},
    ... )
    >>> d = light_curve_fluxes(lc)
    >>> d["labels"].tolist(), d["band"].tolist()
    (['V', 'R'], [0, 1, 0, 1])
    >>> d["flux"].round(6).tolist()
    [0.794328, 1.258925, 0.794328, 1.995262]
    """
    if not isinstance(light_curve, xr.Dataset):
        raise InversionError(
            f"light curve: expected a Dataset (read_light_curve), got {type(light_curve).__name__}"
        )
    if "time" not in light_curve.coords and "time" not in light_curve:
        what = "rotation angles" if "rotation_angle" in light_curve.variables else "no times"
        raise InversionError(
            f"light curve: has {what}; a spin fit needs a time coordinate (UTC or seconds)"
        )
    raw = np.asarray(light_curve["time"].values)
    if raw.ndim != 1 or raw.size == 0:
        raise InversionError(f"light curve: expected 1-D times with values, got shape {raw.shape}")
    if np.issubdtype(raw.dtype, np.datetime64):
        t: np.ndarray = raw.astype(_NS)
        bad_t = np.isnat(t)
    else:
        try:
            t = raw.astype(np.float64)
        except (TypeError, ValueError):
            raise InversionError(
                f"light curve: times of dtype {raw.dtype} are neither UTC datetimes nor seconds"
            ) from None
        bad_t = ~np.isfinite(t)
    if bad_t.any():
        raise InversionError(
            f"light curve: {int(bad_t.sum())} times are NaN/NaT (rows {row_list(bad_t)}); "
            "drop those rows"
        )
    if "band" not in light_curve.variables:
        raise InversionError("light curve: no band coordinate (one band label per value)")
    band = np.asarray(light_curve["band"].values).astype(str)
    labels = list(dict.fromkeys(band)) if bands is None else [str(b) for b in bands]
    unknown = sorted(set(band) - set(labels))
    if unknown:
        raise InversionError(f"light curve bands {unknown} are not among the model bands {labels}")
    if "flux" in light_curve:
        if "flux_uncertainty" not in light_curve:
            raise InversionError("light curve: flux without flux_uncertainty")
        f = np.asarray(light_curve["flux"].values, dtype=np.float64)
        sf = np.asarray(light_curve["flux_uncertainty"].values, dtype=np.float64)
        what = "flux"
    elif "magnitude" in light_curve:
        if "uncertainty" not in light_curve:
            raise InversionError("light curve: magnitude without uncertainty [mag]")
        m = np.asarray(light_curve["magnitude"].values, dtype=np.float64)
        sm = np.asarray(light_curve["uncertainty"].values, dtype=np.float64)
        if not np.all(np.isfinite(m)):
            bad = ~np.isfinite(m)
            raise InversionError(
                f"light curve: {int(bad.sum())} magnitudes are NaN or infinite (rows "
                f"{row_list(bad)}); every magnitude must be finite (drop those rows)"
            )
        f = 10 ** (-0.4 * (m - np.median(m)))
        sf = f * LN10_2P5 * sm
        what = "magnitude"
    else:
        raise InversionError(
            f"light curve: needs magnitude/uncertainty or flux/flux_uncertainty, got "
            f"{list(light_curve.data_vars)}"
        )
    if not np.all(np.isfinite(f)):
        bad = ~np.isfinite(f)
        raise InversionError(
            f"light curve: {int(bad.sum())} {what} values are NaN or infinite "
            f"(rows {row_list(bad)})"
        )
    bad = ~(np.isfinite(sf) & (sf > 0))
    if bad.any():
        raise InversionError(
            f"light curve: {int(bad.sum())} uncertainties that are not finite and > 0 (rows "
            f"{row_list(bad)}, e.g. {sf[bad][0]!r}); allowed: finite values > 0"
        )
    return {
        "time": t,
        "band": np.array([labels.index(b) for b in band]),
        "flux": f,
        "sigma": sf,
        "labels": np.array(labels),
    }


def band_factors(
    light_curve: xr.Dataset, labels: Sequence[str], offset: str
) -> tuple[np.ndarray, str]:
    """Factors that put the model's band signal in the units of the measured fluxes.

    With a free scale per band (``offset="band"``) any factor is absorbed: all 1.  With
    one scale for every band (``"common"``) the model's band colours must be those of the
    data.  Magnitudes ``m_b = m_sun,b + 5 log10(r / AU) - 2.5 log10(S_b / d**2)``
    (:func:`sbrdf_xr.photometry.magnitudes`) make fluxes ``10**(-0.4 m_b)`` proportional
    to ``S_b 10**(-0.4 m_sun,b)``, with the Sun's magnitudes ``m_sun,b`` of the light
    curve's system (AB or Vega: its ``magnitude_system`` attribute), so the factors are
    ``10**(-0.4 (m_sun,b - m_sun,0))``.  Fluxes (``flux``) are taken as proportional to
    the band signal itself (the reflected band flux over the Sun's): all 1.

    Examples
    --------
    The Sun (ASTM G173) is redder than Vega: V - R = 0.39 and V - I = 0.73 in the Vega
    system, so the fluxes of a body of the Sun's colour are 1.43 and 1.96 times those in V:

    >>> import xarray as xr
    >>> from sbrdf_xr.invert._spin.data import band_factors
    >>> lc = xr.Dataset({"magnitude": ("obs", [9.0, 8.6, 8.3]),
    ...                  "uncertainty": ("obs", [0.02] * 3)},
    ...                 coords={"band": ("obs", ["V", "R", "I"])},
    ...                 attrs={"magnitude_system": "Vega"})
    >>> factors, note = band_factors(lc, ["V", "R", "I"], "common")
    >>> factors.round(3).tolist()
    [1.0, 1.433, 1.962]
    >>> band_factors(lc, ["V", "R", "I"], "band")[0].tolist()
    [1.0, 1.0, 1.0]
    """
    ones = np.ones(len(labels))
    if offset == "band":
        return ones, "a free flux scale per band"
    if "magnitude" not in light_curve or "flux" in light_curve:
        return ones, "one flux scale for every band; fluxes proportional to the band signal"
    from ...photometry import MAGNITUDE_SYSTEMS, sun_magnitudes

    system = str(
        light_curve.attrs.get(
            "magnitude_system", light_curve["magnitude"].attrs.get("magnitude_system", "unstated")
        )
    )
    known = {k.lower(): k for k in MAGNITUDE_SYSTEMS}
    if system.lower() not in known:  # "unstated", or anything else
        raise InversionError(
            f"light curve: offset='common' fits one scale to every band, so the model's band "
            f"colours must be in the magnitude system of the data, but the light curve states "
            f"{system!r} (attribute magnitude_system); allowed {sorted(MAGNITUDE_SYSTEMS)}: "
            "state it (read_light_curve(..., system=...)) or use offset='band'"
        )
    system = known[system.lower()]
    msun = sun_magnitudes(list(labels), system=system).values
    return (
        10 ** (-0.4 * (msun - msun[0])),
        f"one flux scale for every band; the model's band colours in the {system} system "
        "(the band signal times 10**(-0.4 m_sun,band), the Sun's magnitudes)",
    )


def row_list(bad: np.ndarray) -> str:
    idx = np.flatnonzero(bad)
    head = ", ".join(str(i) for i in idx[:5])
    return head + (f", ... ({idx.size} in all)" if idx.size > 5 else "")


def directions(v: Any, n_t: int, name: str) -> np.ndarray:
    """Unit vectors (n_t, 3) from one vector or one per time."""
    arr = np.asarray(v, dtype=np.float64)
    if arr.shape == (3,):
        arr = np.broadcast_to(arr, (n_t, 3))
    if arr.shape != (n_t, 3):
        raise InversionError(
            f"{name}: expected shape (3,) or ({n_t}, 3) (one per distinct time), got {arr.shape}"
        )
    nrm = np.linalg.norm(arr, axis=-1)
    if not np.all(np.isfinite(nrm) & (nrm > 0)):
        raise InversionError(f"{name}: zero-length or non-finite direction")
    return arr / nrm[:, None]


@dataclasses.dataclass(frozen=True)
class SpinGeometry:
    """Inertial geometry at the distinct times of a light curve.

    ``times`` [s] since ``epoch`` (UTC, or None when the light curve's seconds are the
    clock); ``t_index`` maps every value to its time; ``to_sun``, ``to_observer`` (T, 3)
    inertial unit vectors; ``factor`` (T,) multiplies the model (the sunlit fraction of
    the solar disc times ``(r_ref / range)**2``); ``source`` and ``notes`` describe it.
    """

    times: np.ndarray
    t_index: np.ndarray
    to_sun: np.ndarray
    to_observer: np.ndarray
    factor: np.ndarray
    epoch: np.datetime64 | None
    source: str
    notes: tuple[str, ...] = ()


def seconds_since(t: np.ndarray, epoch: np.datetime64) -> np.ndarray:
    return np.asarray((t - epoch) / np.timedelta64(1, "ns"), dtype=np.float64) * 1e-9


def measured_utc(t: np.ndarray, start: np.datetime64, what: str) -> tuple[np.ndarray, str]:
    """Measured times as UTC: as given, or seconds counted from the geometry's first time."""
    if np.issubdtype(t.dtype, np.datetime64):
        return t.astype(_NS), "UTC times"
    off = np.round(t * 1e9).astype(np.int64).astype("timedelta64[ns]")
    return start + off, f"light-curve seconds counted from the first time of the {what}"


def check_window(t: np.ndarray, lo: np.datetime64, hi: np.datetime64, what: str) -> None:
    out = (t < lo) | (t > hi)
    if out.any():
        raise InversionError(
            f"light curve: {int(out.sum())} measured times ({t[out][0]} ..) lie outside the "
            f"{what} {lo} .. {hi}; give the geometry over the measured times (or drop those rows)"
        )


def spin_geometry(
    times: np.ndarray, geometry: Any = None, to_sun: Any = None, to_observer: Any = None
) -> SpinGeometry:
    """The inertial geometry of a spin fit at the distinct measured ``times``.

    ``geometry`` is an :class:`sbrdf_xr.observing.Observation` (recomputed at the measured
    times with a fixed attitude, so its body frame is the GCRS) or a Dataset over ``time``
    with body-frame ``to_sun``, ``to_observer`` and the ``quaternion`` of each time (a cube
    of ``simulate`` for an observation, or :meth:`Observation.geometry`), interpolated
    linearly to the measured times; or ``to_sun``, ``to_observer`` give inertial vectors
    directly (one, or one per distinct time).
    """
    from ...geometry import rotation_matrices
    from ...observing import Inertial, Observation

    if geometry is not None and (to_sun is not None or to_observer is not None):
        raise InversionError(
            "fit_spin: give either an observation/cube (geometry) or to_sun and to_observer, "
            "not both"
        )
    notes: list[str] = []
    if geometry is None:
        if to_sun is None or to_observer is None:
            raise InversionError(
                "fit_spin: no geometry; give an Observation or a cube over time, or the "
                "inertial to_sun and to_observer directions"
            )
        epoch = times[0] if np.issubdtype(times.dtype, np.datetime64) else None
        secs = seconds_since(times, epoch) if epoch is not None else times.astype(np.float64)
        uniq, idx = np.unique(secs, return_inverse=True)
        return SpinGeometry(
            uniq,
            idx,
            directions(to_sun, uniq.size, "to_sun"),
            directions(to_observer, uniq.size, "to_observer"),
            np.ones(uniq.size),
            epoch,
            "inertial directions given",
            ("model flux: band signal times a fitted scale (no range or shadow factor)",),
        )
    if isinstance(geometry, Observation):
        epoch = geometry.times[0].astype(_NS)
        utc, how = measured_utc(times, epoch, "observation")
        check_window(utc, geometry.times[0], geometry.times[-1], "observation window")
        uniq = np.unique(utc)
        g = dataclasses.replace(geometry, times=uniq, attitude=Inertial((0.0, 0.0, 0.0, 1.0)))
        geo = g.geometry(on_unobservable="keep")
        s, o = geo["to_sun"].values, geo["to_observer"].values  # body = GCRS
        rng, lit = geo["range"].values, geo["sunlit_fraction"].values
        source = f"observation {geometry.name!r} recomputed at the measured times ({how})"
    elif isinstance(geometry, xr.Dataset):
        need = [v for v in ("to_sun", "to_observer", "quaternion") if v not in geometry.variables]
        if need or "time" not in geometry.dims:
            raise InversionError(
                f"geometry: a Dataset over time with to_sun, to_observer and quaternion (a cube "
                f"of an observation, or Observation.geometry()); missing {need or ['time']}"
            )
        gt = np.asarray(geometry["time"].values)
        if not np.issubdtype(gt.dtype, np.datetime64):
            raise InversionError(f"geometry: time must be UTC datetime64, got {gt.dtype}")
        epoch = gt[0].astype(_NS)
        utc, how = measured_utc(times, epoch, "cube")
        check_window(utc, gt[0], gt[-1], "cube's time span")
        uniq = np.unique(utc)
        q = geometry["quaternion"].transpose("time", ...).values
        if "component" in geometry["quaternion"].dims and "component" in geometry.coords:
            order = [list(geometry["component"].values).index(c) for c in "xyzw"]
            q = q[:, order]
        rot = rotation_matrices(q)
        x, xi = seconds_since(gt, epoch), seconds_since(uniq, epoch)

        def inertial(name: str) -> np.ndarray:
            v = np.einsum("nij,nj->ni", rot, geometry[name].transpose("time", ...).values)
            w = np.stack([np.interp(xi, x, v[:, j]) for j in range(3)], axis=-1)
            return w / np.linalg.norm(w, axis=-1, keepdims=True)

        s, o = inertial("to_sun"), inertial("to_observer")

        def coord(name: str, default: float) -> np.ndarray:
            if name not in geometry.variables:
                notes.append(f"the cube has no {name}: taken as {default:g}")
                return np.full(xi.size, default)
            return np.interp(xi, x, np.asarray(geometry[name].values, dtype=np.float64))

        rng, lit = coord("range", 1.0), coord("sunlit_fraction", 1.0)
        source = f"cube over time interpolated linearly to the measured times ({how})"
    else:
        raise InversionError(
            "geometry: expected an sbrdf_xr.observing.Observation or a Dataset over time, got "
            f"{type(geometry).__name__}"
        )
    secs = seconds_since(utc, epoch)
    uniq_s = seconds_since(uniq, epoch)
    idx = np.searchsorted(uniq_s, secs)
    r_ref = float(np.median(rng))
    if not np.all(np.isfinite(rng) & (rng > 0)):
        raise InversionError("geometry: ranges must be finite and > 0 [km]")
    lit = np.clip(np.asarray(lit, dtype=np.float64), 0.0, 1.0)
    notes.append(
        "model flux: band signal x sunlit fraction x (r_ref / range)**2 x a fitted scale, "
        f"r_ref = {r_ref:.6g} km; no atmospheric extinction, earthshine or self-shadowing"
    )
    if np.any(lit < 1):
        notes.append(f"{int((lit < 1).sum())} times in the Earth's penumbra or umbra")
    return SpinGeometry(uniq_s, idx, s, o, lit * (r_ref / rng) ** 2, epoch, source, tuple(notes))
