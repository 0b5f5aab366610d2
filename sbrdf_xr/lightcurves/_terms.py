"""The variables of a light-curve comparison's Dataset, by group: per observation, per
band, the parameters, extinction, the common offset and the colours.

Used by :func:`sbrdf_xr.lightcurves._report.report`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._names import BAND, attrs


def plain(units: str, long_name: str) -> dict[str, str]:
    """CF attributes of a variable without an entry in the attribute table."""
    return {"units": units, "long_name": long_name}


def observation_terms(
    m: np.ndarray,
    sig: np.ndarray,
    s: np.ndarray,
    model: np.ndarray,
    resid: np.ndarray,
    use: np.ndarray,
) -> dict[str, Any]:
    """Per observation: measured, simulated and model magnitudes [mag], residuals."""
    return {
        "measured_magnitude": ("obs", m, attrs("magnitude", long_name="measured magnitude")),
        "uncertainty": ("obs", sig, attrs("magnitude_uncertainty")),
        "simulated_magnitude": (
            "obs",
            s,
            attrs(
                "magnitude",
                long_name="simulated magnitude at the aligned time or angle, before "
                "the fitted terms (+inf: no light reflected)",
            ),
        ),
        "model_magnitude": (
            "obs",
            model,
            attrs("magnitude", long_name="simulated magnitude with the fitted and fixed terms"),
        ),
        "residual": (
            "obs",
            resid,
            attrs("magnitude", long_name="measured minus model magnitude (NaN: excluded)"),
        ),
        "normalized_residual": ("obs", resid / sig, plain("1", "residual / uncertainty")),
        "excluded": ("obs", ~use, plain("1", "excluded: the model reflects no light there")),
    }


def band_terms(
    zp: list[tuple[float, float]],
    zero_points: str,
    col: np.ndarray,
    use: np.ndarray,
    present: list[int],
    mean_res: list[float],
) -> dict[str, Any]:
    """Per band: zero point [mag] and its uncertainty, observations used, mean residual."""
    return {
        "zero_point": (
            BAND,
            [z[0] for z in zp],
            attrs(
                "magnitude",
                long_name="fitted zero point, measured minus simulated magnitude"
                + (" (one common to every band)" if zero_points == "common" else ""),
            ),
        ),
        "zero_point_uncertainty": (
            BAND,
            [z[1] for z in zp],
            attrs("magnitude", long_name="1-sigma uncertainty of the zero point"),
        ),
        "n_observations": (
            BAND,
            [int(np.sum(use & (col == b))) for b in present],
            plain("1", "observations used in the band"),
        ),
        "band_mean_residual": (
            BAND,
            mean_res,
            attrs("magnitude", long_name="weighted mean residual in the band after the fit"),
        ),
    }


def parameter_terms(
    est: np.ndarray, sd: np.ndarray, cov: np.ndarray, chi2: float, dof: int, use: np.ndarray
) -> dict[str, Any]:
    """The parameters, their covariance and the chi-square of the fit."""
    return {
        "estimate": (
            "parameter",
            est,
            plain(
                "1",
                "fitted parameter (zero points and k [mag], time_shift [s], phase_offset [degree])",
            ),
        ),
        "standard_error": ("parameter", sd, plain("1", "1-sigma uncertainty of the parameter")),
        "covariance": (
            ("parameter", "parameter_b"),
            cov,
            plain("1", "covariance of the parameters (Gauss-Newton, stated uncertainties)"),
        ),
        "chi_square": ((), chi2, plain("1", "chi-square of the fit")),
        "degrees_of_freedom": ((), dof, plain("1", "observations used minus parameters")),
        "reduced_chi_square": ((), chi2 / dof, plain("1", "chi-square per degree of freedom")),
        "n_excluded": (
            (),
            int((~use).sum()),
            plain("1", "observations where the model reflects no light (excluded)"),
        ),
    }


def extinction_terms(
    kk: list[tuple[float, float]], fit_k: bool, xa: np.ndarray | None
) -> dict[str, Any]:
    """Extinction coefficients [mag per airmass] per band, fitted or given; the air mass."""
    data: dict[str, Any] = {
        "extinction_coefficient": (
            BAND,
            [k[0] for k in kk],
            attrs(
                "magnitude",
                long_name=("fitted" if fit_k else "given")
                + " first-order extinction coefficient k (mag per airmass)",
            ),
        ),
        "extinction_coefficient_uncertainty": (
            BAND,
            [k[1] for k in kk],
            attrs("magnitude", long_name="1-sigma uncertainty of k (0: given, not fitted)"),
        ),
    }
    if xa is not None:
        data["airmass"] = ("obs", xa, attrs("airmass"))
    return data


def offset_terms(zp: tuple[float, float]) -> dict[str, Any]:
    """The one common magnitude offset [mag] and its uncertainty."""
    return {
        "magnitude_offset": (
            (),
            zp[0],
            attrs("magnitude", long_name="fitted common magnitude offset (measured - simulated)"),
        ),
        "magnitude_offset_uncertainty": (
            (),
            zp[1],
            attrs("magnitude", long_name="1-sigma uncertainty of the magnitude offset"),
        ),
    }


def colour_terms(
    zp: list[tuple[float, float]],
    mean_res: list[float],
    blabels: list[str],
    present: list[int],
    names: list[str],
    cov: np.ndarray,
    w: np.ndarray,
    use: np.ndarray,
    col: np.ndarray,
    zero_points: str,
) -> dict[str, Any]:
    """Measured minus simulated colour index of neighbouring bands, with its uncertainty."""
    ci, ci_sd = [], []
    for i in range(len(blabels) - 1):
        ci.append((zp[i][0] + mean_res[i]) - (zp[i + 1][0] + mean_res[i + 1]))
        if zero_points == "band":
            ja, jb = names.index(f"ZP_{blabels[i]}"), names.index(f"ZP_{blabels[i + 1]}")
            ci_sd.append(float(np.sqrt(cov[ja, ja] + cov[jb, jb] - 2 * cov[ja, jb])))
        else:
            wa = np.sum(w[use & (col == present[i])])
            wb = np.sum(w[use & (col == present[i + 1])])
            ci_sd.append(float(np.sqrt(1 / wa + 1 / wb)))
    return {
        "colour_index_difference": (
            "colour",
            ci,
            attrs("colour_index", long_name="measured minus simulated colour index"),
        ),
        "colour_index_difference_uncertainty": (
            "colour",
            ci_sd,
            attrs("colour_index", long_name="1-sigma uncertainty of the colour index difference"),
        ),
    }
