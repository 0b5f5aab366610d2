"""Parameters and result Dataset of :func:`sbrdf_xr.invert.fit_observation`."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import xarray as xr

from ..._names import attrs as cf
from .._quality import quality_attrs
from .._spin.search import lonlat
from .._unseen import correlation
from .model import PassData
from .nuisance import table_scales, table_tilts

__all__ = ["Layout", "model_check", "reported_jacobian", "result_dataset"]


def _cf(units: str, long_name: str) -> dict[str, str]:
    return {"units": units, "long_name": long_name}


@dataclasses.dataclass
class Layout:
    """The fitted parameters, in order: east, north [degree] of the axis on the tangent
    plane of the start axis, period [s], phase at the reference time [degree]; then the
    extinction coefficients (``k_mode == "fit"``), the zero points or the common offset,
    and the area fractions (all materials but the last, ``"total"``) or scales
    (``"free"``)."""

    bands: tuple[str, ...]
    materials: tuple[str, ...]
    model_area: np.ndarray
    k_mode: Any  # "fit" or the given coefficients (B,)
    offset: str | None
    areas: str
    k_prior_sd: np.ndarray | None = None  # extinction held at its prior: the prior's width
    m_sd: np.ndarray | None = None  # prior widths of the tables' scales (nuisance), or None
    c_sd: np.ndarray | None = None  # prior widths of the tables' colour tilts, or None
    tilt_x: np.ndarray | None = None  # each band's mean wavelength less the bands' [100 nm]

    def __post_init__(self) -> None:
        nb, nm = len(self.bands), len(self.materials)
        sizes = {
            "k": nb if isinstance(self.k_mode, str) else 0,
            "z": {None: 0, "band": nb, "common": 1}[self.offset],
            "f": {"total": nm - 1, "free": nm, "fixed": 0}[self.areas],
            "s": 0 if self.m_sd is None else nm,
            "c": 0 if self.c_sd is None else nm,
        }
        i = 4
        self.sl: dict[str, slice] = {}
        for key, n in sizes.items():
            self.sl[key] = slice(i, i + n)
            i += n
        self.n = i
        self.total = float(self.model_area.sum())
        zn = [f"zero_point_{b}" for b in self.bands] if self.offset == "band" else []
        fn = {
            "total": [f"area_fraction_{m}" for m in self.materials[:-1]],
            "free": [f"scale_{m}" for m in self.materials],
            "fixed": [],
        }[self.areas]
        self.names = [
            "axis_longitude",
            "axis_latitude",
            "period",
            "phase",
            *([f"extinction_{b}" for b in self.bands] if sizes["k"] else []),
            *(zn if self.offset != "common" else ["magnitude_offset"]),
            *fn,
            *([f"table_scale_{m}" for m in self.materials] if sizes["s"] else []),
            *([f"table_tilt_{m}" for m in self.materials] if sizes["c"] else []),
        ]
        self.n_prior = sizes["s"] + sizes["c"]
        self.units = ["degree", "degree", "s", "degree"] + ["1"] * (i - 4)

    def fractions(self, p: np.ndarray) -> np.ndarray:
        """Area fraction of each material (of the mesh's total area)."""
        f = p[self.sl["f"]]
        if self.areas == "total":
            return np.append(f, 1.0 - f.sum())
        if self.areas == "free":
            return f * self.model_area / self.total
        return self.model_area / self.total

    def scales(self, p: np.ndarray) -> np.ndarray:
        """Scale of each material's signal: its area scale ``a_m`` times its table's scale
        (the nuisance parameter, 1 when not fitted)."""
        t = self.table_scales(p)
        if self.areas == "free":
            return np.asarray(p[self.sl["f"]], dtype=np.float64) * t
        a = self.fractions(p) * self.total / np.where(self.model_area > 0, self.model_area, 1)
        return np.asarray(a * t)

    def table_scales(self, p: np.ndarray) -> np.ndarray:
        """The fitted scale of each material's table (1 when not fitted)."""
        if self.m_sd is None:
            return np.ones(len(self.materials))
        return np.asarray(p[self.sl["s"]], dtype=np.float64)

    def prior_residuals(self, p: np.ndarray) -> np.ndarray:
        """``(s_m - 1) / w_m`` of the tables' scales (none when not fitted)."""
        out = [] if self.m_sd is None else [(p[self.sl["s"]] - 1.0) / self.m_sd]
        if self.c_sd is not None:
            out.append(p[self.sl["c"]] / self.c_sd)
        return np.concatenate(out) if out else np.zeros(0)

    def band_scales(self, p: np.ndarray) -> np.ndarray:
        """Scale of each material's signal in each band (B, M): :meth:`scales` times the
        colour tilt ``1 + t_m x_b`` (``x_b`` the band's mean wavelength less the bands'
        mean [100 nm]; 1 when not fitted)."""
        sc = self.scales(p)[None, :]
        if self.c_sd is None or self.tilt_x is None:
            return np.asarray(np.repeat(sc, len(self.bands), axis=0))
        return np.asarray(sc * (1.0 + self.tilt_x[:, None] * p[self.sl["c"]][None, :]))

    def area_scales(self, p: np.ndarray) -> np.ndarray:
        """Area scale ``a_m`` of each material (without its table's scale)."""
        return np.asarray(self.scales(p) / self.table_scales(p))

    def extinction(self, p: np.ndarray) -> np.ndarray:
        return p[self.sl["k"]] if isinstance(self.k_mode, str) else np.asarray(self.k_mode)

    def zero_points(self, p: np.ndarray) -> np.ndarray:
        z = p[self.sl["z"]]
        return (
            np.full(len(self.bands), z[0])
            if self.offset == "common"
            else (z if self.offset == "band" else np.zeros(len(self.bands)))
        )

    def extra(self, p: np.ndarray, data: PassData) -> np.ndarray:
        """``k_b X + z_b`` at every value."""
        return self.extinction(p)[data.band] * data.airmass + self.zero_points(p)[data.band]

    def start(self, period: float, phase_ref: float) -> np.ndarray:
        p = np.zeros(self.n)
        p[2], p[3] = period, phase_ref
        if self.areas == "total":
            p[self.sl["f"]] = (self.model_area / self.total)[:-1]
        elif self.areas == "free":
            p[self.sl["f"]] = 1.0
        p[self.sl["s"]] = 1.0
        return p

    def x_scale(self, period: float, span: float) -> np.ndarray:
        x = np.full(self.n, 0.01)
        x[:4] = [1.0, 1.0, period**2 / (360.0 * span), 1.0]
        return x

    def steps(self, period: float) -> np.ndarray:
        h = np.full(self.n, 1e-4)
        h[:4] = [1e-3, 1e-3, 1e-6 * period, 1e-3]
        h[self.sl["f"]] = 1e-5
        h[self.sl["s"]] = 1e-5
        h[self.sl["c"]] = 1e-5
        return h


def reported_jacobian(
    lay: Layout, p: np.ndarray, axis_of: Any, t_ref: float, dt_epoch: float
) -> np.ndarray:
    """d(output parameters) / d(fitted parameters): (lon, lat) from the tangent-plane
    offsets by central differences, the phase at the epoch ``phase_ref - 360 (t_ref -
    t_epoch) / P``; the rest as fitted."""
    t = np.eye(lay.n)
    h = 1e-4
    for j in range(2):
        d = np.zeros(lay.n)
        d[j] = h
        lo1, la1 = lonlat(axis_of(p + d))
        lo0, la0 = lonlat(axis_of(p - d))
        t[0, j] = ((float(lo1) - float(lo0) + 180.0) % 360.0 - 180.0) / (2 * h)
        t[1, j] = (float(la1) - float(la0)) / (2 * h)
    t[3, 2] = 360.0 * (t_ref - dt_epoch) / p[2] ** 2
    return t


def result_dataset(
    *,
    lay: Layout,
    data: PassData,
    light_curve: xr.Dataset,
    p: np.ndarray,
    cov: np.ndarray,
    free: np.ndarray,
    axis_of: Any,
    t_ref: float,
    dt_epoch: float,
    epoch: np.datetime64,
    residual: np.ndarray,
    chi2: float,
    dof: int,
    quality: Mapping[str, Any],
    attrs: Mapping[str, Any],
) -> xr.Dataset:
    """The result Dataset of the joint fit: estimates, their uncertainties and
    correlations (carried to the reported parameters), the spin, extinction, zero points,
    areas, table scales, the fit's statistics and the per-observation residuals."""
    axis = axis_of(p)
    lon, lat = (float(v) for v in lonlat(axis))
    phase = (p[3] - 360.0 * (t_ref - dt_epoch) / p[2]) % 360.0
    c_out, free_out, finite = _reported_covariance(lay, p, cov, free, axis_of, t_ref, dt_epoch)
    sd = np.sqrt(np.clip(np.diag(c_out), 0, None))
    est = np.array([lon, lat, p[2], phase, *p[4:]])
    ds = xr.Dataset(
        coords={
            "parameter": ("parameter", lay.names, _cf("1", "fitted parameter")),
            "parameter_b": ("parameter_b", lay.names, _cf("1", "fitted parameter")),
            "parameter_units": ("parameter", lay.units, _cf("1", "unit of the parameter")),
            "band": ("band", list(lay.bands), cf("band")),
            "material": ("material", list(lay.materials), cf("material")),
            "xyz": ("xyz", ["x", "y", "z"], _cf("1", "vector component")),
        }
    )
    ds["estimate"] = ("parameter", est, _cf("1", "estimate (units: parameter_units)"))
    ds["uncertainty"] = ("parameter", sd, _cf("1", "1-sigma uncertainty (units: parameter_units)"))
    ds["correlation"] = (
        ("parameter", "parameter_b"),
        correlation(c_out),
        _cf("1", "correlation of the estimates (Jacobian at the solution)"),
    )
    _spin_terms(ds, est, sd, c_out, free_out, finite, axis)
    k_how = _band_terms(ds, lay, p, sd)
    _areas(ds, lay, p, c_out)
    table_scales(ds, lay, p, sd)
    table_tilts(ds, lay, p, sd)
    scal = {
        "chi2": (chi2, "chi-square of the fit"),
        "degrees_of_freedom": (dof, "degrees of freedom (values minus fitted parameters)"),
        "reduced_chi_square": (chi2 / dof, "chi-square per degree of freedom"),
        "fit_probability": (
            quality["fit_probability"],
            "probability of a chi-square at least this large for a right model",
        ),
    }
    for key, (val, ln) in scal.items():
        ds[key] = ((), val, _cf("1", ln))
    ds = _per_observation(ds, light_curve, data, residual)
    ds.attrs = {
        **attrs,
        "epoch": str(np.asarray(epoch).astype("datetime64[ms]")),
        "phase_reference": "phase is the spin angle at the epoch (sbrdf_xr.invert.spin_model)",
        "bands": ", ".join(lay.bands),
        "magnitude_system": data.system,
        "extinction": k_how,
        "offset": str(lay.offset),
        "areas": {
            "total": "fractions of every material but the last fitted; the last takes the rest "
            "(the areas add up to the mesh's)",
            "free": "a free area scale per material",
            "fixed": "the model's areas",
        }[lay.areas],
        **quality_attrs(quality),
    }
    return ds


def _reported_covariance(
    lay: Layout,
    p: np.ndarray,
    cov: np.ndarray,
    free: np.ndarray,
    axis_of: Any,
    t_ref: float,
    dt_epoch: float,
) -> tuple[np.ndarray, np.ndarray, bool]:
    """The covariance of the reported parameters, which of them are unconstrained, and
    whether the constrained part is finite."""
    t = reported_jacobian(lay, p, axis_of, t_ref, dt_epoch)
    # a parameter the data do not constrain (free) carries an infinite variance into every
    # output that depends on it; the others' covariance is carried through t
    finite = bool(np.all(np.isfinite(cov[np.ix_(~free, ~free)])))
    c_out = t @ np.where(np.outer(free, free) | ~np.isfinite(cov), 0.0, cov) @ t.T
    if not finite:
        c_out = np.full_like(cov, np.nan)
    free_out = (np.abs(t) @ free.astype(float)) > 0
    c_out[free_out, :] = 0.0
    c_out[:, free_out] = 0.0
    c_out[free_out, free_out] = np.inf
    return c_out, free_out, finite


def _spin_terms(
    ds: xr.Dataset,
    est: np.ndarray,
    sd: np.ndarray,
    c_out: np.ndarray,
    free_out: np.ndarray,
    finite: bool,
    axis: np.ndarray,
) -> None:
    """The spin axis [degree], period [s] and phase [degree] with their uncertainties;
    the major semi-axis of the axis's 1-sigma ellipse; the axis vector."""
    lat = float(est[1])
    spin = {
        "axis_longitude": (float(est[0]), "degree", "longitude of the inertial spin axis"),
        "axis_latitude": (lat, "degree", "latitude of the inertial spin axis"),
        "period": (float(est[2]), "s", "spin period"),
        "phase": (float(est[3]), "degree", "spin angle at the epoch"),
    }
    for j, (key, (val, u, ln)) in enumerate(spin.items()):
        ds[key] = ((), val, _cf(u, ln))
        ds[key + "_uncertainty"] = ((), float(sd[j]), _cf(u, f"1-sigma uncertainty of the {ln}"))
    # the 1-sigma ellipse of the axis on the sphere: the east/north covariance, in degrees
    # of arc (the longitude step times cos latitude)
    c_ax = c_out[:2, :2] * np.outer([np.cos(np.radians(lat)), 1.0], [np.cos(np.radians(lat)), 1.0])
    if free_out[:2].any():
        c_ax = np.full((2, 2), np.inf)
    ev = np.linalg.eigvalsh(c_ax) if finite and np.isfinite(c_ax).all() else np.array([np.inf])
    ds["axis_uncertainty"] = (
        (),
        float(np.sqrt(max(ev.max(), 0.0))) if finite else float("nan"),  # nan: failed
        _cf("degree", "major semi-axis of the 1-sigma ellipse of the spin axis"),
    )
    ds["axis_vector"] = ("xyz", axis, _cf("1", "unit vector of the inertial spin axis"))


def _band_terms(ds: xr.Dataset, lay: Layout, p: np.ndarray, sd: np.ndarray) -> str:
    """Extinction coefficients and zero points (or the common offset) [mag] per band;
    returns how extinction was treated."""
    nb = len(lay.bands)
    k_sd = sd[lay.sl["k"]] if isinstance(lay.k_mode, str) else np.zeros(nb)
    k_how = "fitted" if isinstance(lay.k_mode, str) else "given (not fitted)"
    if lay.k_prior_sd is not None:
        k_sd = np.asarray(lay.k_prior_sd, dtype=np.float64)
        k_how = "held at its prior (the pass's air mass cannot tell it from a zero point)"
    ds["extinction_coefficient"] = (
        "band",
        lay.extinction(p),
        cf("magnitude", long_name=f"{k_how} first-order extinction coefficient (mag per airmass)"),
    )
    ds["extinction_coefficient_uncertainty"] = (
        "band",
        k_sd,
        cf(
            "magnitude",
            long_name="1-sigma uncertainty of the extinction coefficient (0: given; the "
            "prior's width: held at its prior)",
        ),
    )
    if lay.offset == "common":
        ds["magnitude_offset"] = (
            (),
            float(p[lay.sl["z"]][0]),
            cf("magnitude", long_name="fitted common magnitude offset (measured - model)"),
        )
        ds["magnitude_offset_uncertainty"] = (
            (),
            float(sd[lay.sl["z"]][0]),
            cf("magnitude", long_name="1-sigma uncertainty of the magnitude offset"),
        )
        return k_how
    z_how = "fitted" if lay.offset == "band" else "held at 0 (a calibrated table)"
    ds["zero_point"] = (
        "band",
        lay.zero_points(p),
        cf("magnitude", long_name=f"zero point, measured - model ({z_how})"),
    )
    ds["zero_point_uncertainty"] = (
        "band",
        sd[lay.sl["z"]] if lay.offset == "band" else np.zeros(nb),
        cf("magnitude", long_name="1-sigma uncertainty of the zero point (0: not fitted)"),
    )
    return k_how


def _per_observation(
    ds: xr.Dataset, light_curve: xr.Dataset, data: PassData, residual: np.ndarray
) -> xr.Dataset:
    """Model magnitude, residual [mag] and air mass of every observation, with its time
    and band."""
    obs = str(light_curve["magnitude"].dims[0])
    keep = {c: light_curve[c] for c in ("time", "band") if c in light_curve.coords}
    per_obs = {
        "model_magnitude": (data.magnitude - residual, "model magnitude at the measured value"),
        "residual": (residual, "measured - model magnitude"),
    }
    for key, (val, ln) in per_obs.items():
        ds[key] = xr.DataArray(val, dims=obs, attrs=cf("magnitude", long_name=ln))
    ds["airmass"] = xr.DataArray(data.airmass, dims=obs, attrs=cf("airmass"))
    return ds.assign_coords(
        {f"{k}_{obs}" if k == "band" else k: v.variable for k, v in keep.items()}
    )


def _areas(ds: xr.Dataset, lay: Layout, p: np.ndarray, c_out: np.ndarray) -> None:
    """Area fraction, scale and area of every material, with uncertainties: the fitted
    covariance carried through the linear map from the fitted area parameters."""
    nm = len(lay.materials)
    sl = lay.sl["f"]
    if lay.areas == "total":
        g = np.vstack([np.eye(nm - 1), -np.ones((1, nm - 1))])  # d fractions / d fitted
    elif lay.areas == "free":
        g = np.diag(lay.model_area / lay.total)
    else:
        g = np.zeros((nm, 0))
    f = lay.fractions(p)
    c_f = c_out[sl, sl]
    inf = np.isinf(np.diag(c_f))  # not constrained: inf in every fraction that holds it
    c_f = np.where(np.isinf(c_f), 0.0, c_f)
    f_sd = np.sqrt(np.clip(np.diag(g @ c_f @ g.T), 0, None)) if g.size else np.zeros(nm)
    if g.size:
        f_sd[(np.abs(g) @ inf.astype(float)) > 0] = np.inf
    per_area = lay.total / np.where(lay.model_area > 0, lay.model_area, 1)
    how = {
        "total": "of the mesh's total area (they add up to 1)",
        "free": "of the mesh's total area (free scales: they need not add up to 1)",
        "fixed": "of the mesh's total area (the model's, not fitted)",
    }[lay.areas]
    rows = {
        "area_fraction": (f, f_sd, "1", f"area fraction {how}"),
        "scale": (f * per_area, f_sd * per_area, "1", "area scale factor (area / model area)"),
        "area": (f * lay.total, f_sd * lay.total, "m2", "effective area of the material"),
    }
    for key, (val, s, u, ln) in rows.items():
        ds[key] = ("material", val, _cf(u, ln))
        ds[key + "_uncertainty"] = ("material", s, _cf(u, f"1-sigma uncertainty of the {ln}"))
    ds["model_area"] = ("material", lay.model_area, _cf("m2", "area of the material in the mesh"))


def model_check(
    ds: xr.Dataset,
    observation: Any,
    spacecraft: Any,
    materials: Mapping[str, Any] | None,
    axis_body: np.ndarray,
    data: PassData,
    lay: Layout,
    p: np.ndarray,
    labels: Sequence[str] | None = None,
) -> str:
    """The solution's magnitudes recomputed by :func:`sbrdf_xr.engine.simulate` (spectral
    signal per material) and :func:`sbrdf_xr.photometry.magnitudes`: the largest
    difference from the fitted model, in magnitudes and in sigma."""
    from ...engine import Scene, simulate
    from ...photometry import magnitudes
    from .._spin.search import spin_model

    law = spin_model(
        axis_body,
        ds["axis_vector"].values,
        float(ds["period"]),
        float(ds["phase"]),
        epoch=np.datetime64(ds.attrs["epoch"]),
    )
    obs = dataclasses.replace(observation, times=data.utc, attitude=law)
    cube = simulate(
        Scene(spacecraft, materials=materials, observation=obs, outputs=("signal", "per_material"))
    )
    per = cube[["signal_material"]].rename(signal_material="signal")
    mags = magnitudes(per, list(labels or lay.bands), system=data.system)
    # a material that reflects nothing at any time may be left out of the cube
    mags = mags.reindex(material=list(lay.materials), fill_value=np.inf)
    mm = mags.transpose("time", "material", "band").values
    flux = np.einsum(
        "nm,nm->n", 10 ** (-0.4 * mm[data.t_index, :, data.band]), lay.band_scales(p)[data.band]
    )
    m = -2.5 * np.log10(np.maximum(flux, 1e-300)) + lay.extra(p, data)
    d = np.abs(m - ds["model_magnitude"].values)
    return (
        f"simulate + photometry.magnitudes at the solution: largest difference "
        f"{d.max():.2g} mag ({(d / data.sigma).max():.2g} sigma) over {d.size} values"
    )
