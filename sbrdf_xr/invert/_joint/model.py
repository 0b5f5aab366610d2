"""The data and forward model of a joint fit: measured magnitudes over a pass, and the
magnitudes of a spinning spacecraft at their times, per material.

See :func:`sbrdf_xr.invert.fit_observation`.  The magnitude of value ``i`` (band ``b``,
time ``t``) of a body whose material ``m`` has its area scaled by ``a_m`` is

``m_i = c_i - 2.5 log10( sum_m a_m f_t S_m,b(t) ) + k_b X_t + z_b``

with ``S_m,b`` the band signal [m2 sr-1] of material ``m`` at the body-frame Sun and
observer directions of the spin state (the compiled kernel on the band pre-integrated
tables, as :func:`sbrdf_xr.engine.simulate` computes it), ``f_t`` the sunlit fraction of
the solar disc, ``c_i`` the magnitude of a unit band signal at the time's range and Sun
distance (:func:`sbrdf_xr.photometry.magnitudes`: ``m_sun,b + 5 log10(r / AU) - 2.5
log10(1 / d**2)``), ``X_t`` the air mass, ``k_b`` the first-order extinction coefficient
and ``z_b`` the zero point.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import xarray as xr

from ...errors import InversionError
from .._spin.data import check_window, light_curve_fluxes, measured_utc, row_list, seconds_since
from .._spin.search import Kernel, align_matrices, body_vectors

__all__ = ["PassData", "PassModel", "pass_data"]

_NS = "datetime64[ns]"


@dataclasses.dataclass(frozen=True)
class PassData:
    """Measured magnitudes and the pass geometry at their times.

    Per value (N): ``magnitude``, ``sigma`` [mag], ``band`` (index into ``labels``),
    ``t_index`` (index into the distinct times), ``airmass``, ``unit_magnitude`` (the
    magnitude of a band signal of 1 m2 sr-1 at that time and band).  Per distinct time (T):
    ``utc``, ``seconds`` since ``epoch``, inertial (GCRS) ``to_sun``, ``to_observer`` and
    ``sunlit_fraction``.
    """

    magnitude: np.ndarray
    sigma: np.ndarray
    band: np.ndarray
    labels: tuple[str, ...]
    t_index: np.ndarray
    airmass: np.ndarray
    unit_magnitude: np.ndarray
    utc: np.ndarray
    seconds: np.ndarray
    to_sun: np.ndarray
    to_observer: np.ndarray
    sunlit_fraction: np.ndarray
    epoch: np.datetime64
    system: str
    time_source: str


def _system(light_curve: xr.Dataset, system: str | None) -> str:
    from ...photometry import check_system

    have = light_curve.attrs.get("magnitude_system")
    if system is None and have is None:
        raise InversionError(
            "light curve: no magnitude_system attribute (read_light_curve sets it); pass "
            "system='Vega' or 'AB'"
        )
    if system is not None and have is not None and check_system(system) != check_system(have):
        raise InversionError(
            f"system: {system!r}, but the light curve's magnitudes are {have!r}; leave system "
            "out to use the light curve's"
        )
    return str(check_system(str(system if system is not None else have)))


def pass_data(
    light_curve: xr.Dataset,
    observation: Any,
    bands: Sequence[str] | None,
    system: str | None,
) -> PassData:
    """Check a measured light curve against an observation and compute the pass geometry
    at the measured times.

    Raises
    ------
    InversionError
        Not magnitudes, bands outside ``bands``, times outside the observation window,
        below the horizon or in the Earth's umbra (the model reflects no light there).
    """
    from ...observing import Inertial, Observation
    from ...photometry import magnitudes, sun_magnitudes

    if not isinstance(observation, Observation):
        raise InversionError(
            "observation: expected an sbrdf_xr.observing.Observation (orbit, site, times), got "
            f"{type(observation).__name__}"
        )
    if not isinstance(light_curve, xr.Dataset) or "magnitude" not in light_curve:
        got = (
            sorted(map(str, light_curve.data_vars))
            if isinstance(light_curve, xr.Dataset)
            else type(light_curve).__name__
        )
        raise InversionError(
            f"light curve: a joint fit needs calibrated magnitudes (magnitude, uncertainty), "
            f"got {got}; read the table with sbrdf_xr.lightcurves.read_light_curve"
        )
    have = [str(b) for b in dict.fromkeys(np.asarray(light_curve["band"].values).astype(str))]
    if bands is not None:
        bands = [str(b) for b in bands]
        extra = [b for b in have if b not in bands]
        if extra:
            raise InversionError(
                f"light curve: bands {extra} are not among the simulated bands {bands}; add "
                f"them to bands (the light curve has {have}) or drop those rows"
            )
    lc = light_curve_fluxes(light_curve, bands)  # validates times, values, uncertainties
    labels = tuple(str(b) for b in lc["labels"])
    sys_name = _system(light_curve, system)
    epoch = np.asarray(observation.times)[0].astype(_NS)
    utc, how = measured_utc(lc["time"], epoch, "observation")
    check_window(utc, observation.times[0], observation.times[-1], "observation window")
    uniq, t_index = np.unique(utc, return_inverse=True)
    g = dataclasses.replace(observation, times=uniq, attitude=Inertial((0.0, 0.0, 0.0, 1.0)))
    geo = g.geometry(on_unobservable="keep")
    elev = np.asarray(geo["elevation"].values, dtype=np.float64)
    lit = np.clip(np.asarray(geo["sunlit_fraction"].values, dtype=np.float64), 0.0, 1.0)
    for bad, what in (
        (~(elev > 0)[t_index], "below the site's horizon"),
        ((lit <= 0)[t_index], "in the Earth's umbra (the model reflects no light)"),
    ):
        if bad.any():
            raise InversionError(
                f"light curve: {int(bad.sum())} measured values (rows {row_list(bad)}, from "
                f"{utc[bad][0]}) fall where the object is {what}; drop those rows or check "
                f"the observation ({observation.name!r}: orbit, site, window)"
            )
    sun = sun_magnitudes(list(labels), system=sys_name)
    unit = xr.DataArray(
        np.ones((uniq.size, len(labels))),
        dims=("time", "band"),
        coords={"band": list(labels), "sun_magnitude": ("band", sun.values, sun.attrs)},
        attrs={"magnitude_system": sys_name},
    )
    c = magnitudes(
        unit,
        range=xr.DataArray(geo["range"].values, dims="time"),
        sun_distance=xr.DataArray(geo["sun_distance"].values, dims="time"),
        system=sys_name,
    ).values
    return PassData(
        magnitude=np.asarray(light_curve["magnitude"].values, dtype=np.float64),
        sigma=np.asarray(light_curve["uncertainty"].values, dtype=np.float64),
        band=np.asarray(lc["band"]),
        labels=labels,
        t_index=t_index,
        airmass=np.asarray(geo["airmass"].values, dtype=np.float64)[t_index],
        unit_magnitude=c[t_index, lc["band"]],
        utc=uniq,
        seconds=seconds_since(uniq, epoch),
        to_sun=np.asarray(geo["to_sun"].values, dtype=np.float64),
        to_observer=np.asarray(geo["to_observer"].values, dtype=np.float64),
        sunlit_fraction=lit,
        epoch=epoch,
        system=sys_name,
        time_source=how,
    )


class PassModel:
    """Band signal of each material at every measured value, for a spin state.

    ``terms(axis, period, phase)`` -> (N, M): ``f_t S_m,b(t)`` [m2 sr-1] for the body
    spinning about ``axis_body`` (a unit inertial ``axis``, ``period`` [s], ``phase``
    [degree] at ``t_ref`` seconds after the data's epoch), the rotation of
    :func:`sbrdf_xr.invert.spin_model`.
    """

    def __init__(
        self,
        data: PassData,
        spacecraft: Any,
        axis_body: np.ndarray,
        materials: Mapping[str, Any] | None = None,
    ) -> None:
        self.data = data
        self.kernel = Kernel(spacecraft, list(data.labels), materials)
        if self.kernel.bands != data.labels:
            raise InversionError(
                f"bands: the model computed {list(self.kernel.bands)} for the light curve's "
                f"{list(data.labels)}"
            )
        self.materials = self.kernel.materials
        self.k = axis_body / np.linalg.norm(axis_body)
        self.t_ref = 0.5 * float(data.seconds[0] + data.seconds[-1])
        self.n_calls = 0
        self._cache: tuple[tuple[float, ...], np.ndarray] | None = None

    def terms(
        self, axis: np.ndarray, period: float, phase: float, body_rotation: Any = None
    ) -> np.ndarray:
        """``f_t S_m,b(t)`` (N, M); with ``body_rotation`` ``F`` (3, 3), those of the
        attitude ``R(t) F`` (the body turned by ``F`` in its own frame)."""
        key = (*np.asarray(axis, dtype=np.float64).tolist(), float(period), float(phase))
        if body_rotation is None and self._cache is not None and self._cache[0] == key:
            return self._cache[1]
        d = self.data
        align = align_matrices(self.k, np.asarray(axis, dtype=np.float64)[None, :])
        ang = np.radians(phase + 360.0 * (d.seconds - self.t_ref) / period)[None, :]
        s = body_vectors(d.to_sun, align, self.k, ang)[0]
        o = body_vectors(d.to_observer, align, self.k, ang)[0]
        if body_rotation is not None:  # F^T v in the body frame, as rows: v F
            f = np.asarray(body_rotation, dtype=np.float64)
            sig = self.kernel(s @ f, o @ f, per_material=True) * d.sunlit_fraction[:, None, None]
            return np.asarray(sig[d.t_index, :, d.band])
        sig = self.kernel(s, o, per_material=True) * d.sunlit_fraction[:, None, None]  # (T, M, B)
        out = sig[d.t_index, :, d.band]  # (N, M)
        self.n_calls += 1
        self._cache = (key, out)
        return out

    def magnitudes(self, terms: np.ndarray, scales: np.ndarray) -> np.ndarray:
        """Model magnitudes (N,) of the body with each material's area scaled, ``scales``
        (M,) or per band (B, M) (no extinction or zero point); a non-positive summed
        signal is clipped to 1e-300 m2 sr-1."""
        if np.ndim(scales) == 2:
            flux = np.einsum("nm,nm->n", terms, scales[self.data.band])
        else:
            flux = terms @ scales
        return self.data.unit_magnitude - 2.5 * np.log10(np.maximum(flux, 1e-300))
