"""What a joint fit's result can be trusted for: its status, the causes of a poor fit,
the extinction held at its prior, and the posterior sampled from its minima.

See :func:`sbrdf_xr.invert.fit_observation`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import xarray as xr

from .diagnose import CAUSES
from .model import PassModel
from .posterior import sample_posterior
from .refine import Local, jacobian, outside_physics
from .result import Layout

__all__ = ["CAUSE_SCORE", "RECOVER", "causes", "held_note", "status_attrs", "with_posterior"]

RECOVER = (
    "recover: fit the spin first (fit_spin(light_curve, spacecraft, geometry=observation)) "
    "and start from its result with starts='aliases'; check the materials and the shape if "
    "that fails too. The values returned are the last iterate, not estimates"
)


#: Score of a residual pattern above which its cause is named first.

CAUSE_SCORE = 3.0


def causes(ranked: Sequence[tuple[str, float]]) -> list[str]:
    """The likely causes of a poor fit, from the residual patterns (:func:`likely_causes`):
    those scoring above :data:`CAUSE_SCORE`, highest first; else the understated
    uncertainties (no pattern stands out)."""
    out = [f"{CAUSES[k]} [score {v:.3g}]" for k, v in ranked if v > CAUSE_SCORE]
    if not out:
        out = ["no residual pattern stands out: the uncertainties are understated"]
    return out


def status_attrs(
    lay: Layout,
    loc: Local,
    unbounded: list[str],
    free: np.ndarray,
    quality: Mapping[str, Any],
    reduced: float,
) -> dict[str, str]:
    """``status`` ("ok" or "failed") with ``status_note`` (why it failed, or what bound
    holds), ``bounded`` and ``unconstrained_note``: what the result can be trusted for."""
    out: dict[str, str] = {"status": "ok"}
    why = []
    if loc.res.status <= 0:
        why.append(f"the optimizer stopped without converging ({loc.res.message})")
    if not np.all(np.isfinite(loc.x)):
        why.append("the parameters are not finite")
    if unbounded and quality.get("fit_quality") == "poor":
        why.append(
            f"the lowest minimum needs area fractions outside [0, 1] ({', '.join(unbounded)}) "
            f"and the fit inside the bounds does not describe the data (reduced chi-square "
            f"{reduced:.4g}): the spin state is likely wrong, not the areas"
        )
    if why:
        out["status"] = "failed"
        out["status_note"] = "the fit failed: " + "; ".join(why) + ". " + RECOVER
    out["bounded"] = (
        f"the unconstrained minimum lies outside physics ({', '.join(unbounded)}): refined "
        "with the area fractions held inside [0, 1] (stick-breaking transform); a fraction "
        "at 0 or 1 is at its bound, its uncertainty is the curvature's"
        if unbounded
        else "none: the minimum lies inside the physical bounds"
    )
    names = [n for n, f in zip(lay.names, free, strict=True) if f]
    if names:
        out["unconstrained_note"] = (
            f"the data do not constrain {', '.join(names)} (a null direction of the Jacobian: "
            "a material never lit and seen, extinction and zero point over a constant air "
            "mass): each is reported at its start value with an infinite uncertainty"
        )
    out["unconstrained"] = ", ".join(names) if names else "none"
    return out


def held_note(
    data: Any, k_sep: np.ndarray, prior: tuple[np.ndarray, np.ndarray, str], offset: Any, areas: str
) -> str:
    """Why the extinction is held at its prior, and what takes its place."""
    worst = int(np.argmax(k_sep / prior[1]))
    x = data.airmass
    took = (
        "its share k Xbar over the pass is fitted as a zero point per band"
        if offset is None and areas != "free"
        else "the fitted zero points take its share k Xbar"
        if offset is not None
        else "with free area scales no zero point can take its share k Xbar: the scales carry it"
    )
    return (
        f"extinction not constrained: the air mass spans only {x.min():.6g}-{x.max():.6g}, "
        f"so with a free zero point band {data.labels[worst]}'s coefficient would be known "
        f"to +- {k_sep[worst]:.3g} mag per air mass, no better than its prior +- "
        f"{prior[1][worst]:.3g} ({prior[2]}); every coefficient is held at its prior value "
        f"and reported with the prior's width, and {took}"
    )


def with_posterior(
    ds: xr.Dataset,
    lay: Layout,
    local: Sequence[Local],
    best: int,
    model: PassModel,
    dt_epoch: float,
    fit_s: float,
    walkers: int | None,
    steps: int | None,
    seed: int,
) -> xr.Dataset:
    """The result with the posterior sampled from every minimum (:mod:`._posterior`)."""

    def chi2_of(m: Local, p: np.ndarray) -> float:
        if not p[2] > 0 or outside_physics(lay, p):
            return np.inf
        r = m.residuals(p)
        return float(r @ r)

    def jac(m: Local, p: np.ndarray) -> np.ndarray:
        return jacobian(m.residuals, p, lay.steps(p[2]))

    post, attrs = sample_posterior(
        lay,
        local,
        best,
        chi2_of,
        jac,
        360.0 * (model.t_ref - dt_epoch),
        walkers=walkers,
        steps=steps,
        seed=seed,
        seconds_per_call=fit_s / max(model.n_calls, 1),
    )
    out = ds.merge(post)
    out.attrs.update(attrs)
    out.attrs["posterior_cost"] = (
        f"{attrs['posterior_seconds'] / fit_s:.3g} times the point fit's wall time"
    )
    return out
