"""The effects a simulation can include, each declared once, and the outputs of a cube.

Every effect is one :class:`Effect` entry of :data:`EFFECTS` (in the manner of
flox's ``Aggregation`` table): what it needs from the scene, the source it adds
(its direction and irradiance relative to the Sun), how a term contributes (a
function run on every block), the outputs it fills, and the line it writes in
the plan.  :mod:`sbrdf_xr.engine.plan` resolves the entries a scene asks for and
:mod:`sbrdf_xr.engine.run` runs them generically; adding an effect is one entry
here plus its tests.

Every variable a cube can hold is one :class:`Output` of :data:`OUTPUTS`, with its
dimensions and CF attributes, defined once.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .. import kernels as _kernels
from .. import sources
from .._names import BAND, MATERIAL, WAVELENGTH
from ..kernels import anisotropic as _aniso_kernels

#: The compiled plan effects run on (:class:`sbrdf_xr.engine.plan.Plan`, which imports this module).
Plan = Any


@dataclass(frozen=True)
class BlockInputs:
    """Body-frame directions of one block of geometries, flattened to (G, 3).

    Examples
    --------
    A block of a 1 attitude x 2 phase angle grid (what the plan's geometry hands to
    every effect):

    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> plan = Scene(box, {"grey": grey}, attitudes=[[0, 0, 0, 1.0]], phase_angles=[0, 60]).plan()
    >>> block = plan.geometry.block(slice(None))
    >>> block.lead_shape, block.to_sun.shape
    ((1, 2), (2, 3))
    >>> block.to_sun.round(4).tolist()  # phase 0 and 60 deg about the bisector +x
    [[1.0, 0.0, 0.0], [0.866, 0.5, 0.0]]
    >>> block.sun_scale is None  # no Earth shadow: the whole solar disc
    True
    """

    to_sun: np.ndarray
    to_observer: np.ndarray
    to_earth: np.ndarray | None
    sun_scale: np.ndarray | None  #: (G,) sunlit fraction of the solar disc, or None (1)
    lead_shape: tuple[int, ...]  #: the block's geometry dimensions before flattening
    earth_scale: np.ndarray | None = None  #: (G,) earthshine irradiance / the Sun's, or None


__all__ = [
    "EFFECTS",
    "OUTPUTS",
    "SPECTRAL_OUTPUTS",
    "BlockInputs",
    "Effect",
    "Output",
    "finish",
    "reflected",
]


@dataclass(frozen=True)
class Output:
    """One variable of a simulation cube.

    Attributes
    ----------
    name : str
        Variable name.
    tail : tuple of str
        Dimensions after the geometry dimensions (``wavelength``, ``band``,
        ``material``).
    spectral : bool
        Its values have the dtype of the spectra (else float64).
    units, long_name : str
        CF attributes.

    Examples
    --------
    >>> from sbrdf_xr.engine.effects import OUTPUTS
    >>> out = OUTPUTS["signal"]
    >>> out.tail, out.spectral
    (('wavelength',), True)
    >>> out.attrs["units"]
    'm2 sr-1'
    """

    name: str
    tail: tuple[str, ...]
    spectral: bool
    units: str
    long_name: str

    @property
    def attrs(self) -> dict[str, str]:
        """CF attributes."""
        return {"units": self.units, "long_name": self.long_name}


#: Every output variable a cube may hold.
OUTPUTS: dict[str, Output] = {
    o.name: o
    for o in (
        Output(
            "spacecraft_sbrdf",
            (WAVELENGTH,),
            True,
            "sr-1",
            "overall spacecraft spectral BRDF (paper 000 Eq. 4)",
        ),
        Output(
            "signal",
            (WAVELENGTH,),
            True,
            "m2 sr-1",
            "radiometric signal sum_j A_j cos(theta_i) cos(theta_r) f_r",
        ),
        Output(
            "brdf",
            (),
            True,
            "sr-1 nm",
            "broadband BRDF, sBRDF integrated over wavelength (paper 000 Eq. 2)",
        ),
        Output(
            "area",
            (),
            False,
            "m2",
            "contributing projected area sum_j A_j cos(theta_r) (paper 000 Eq. 4 denominator)",
        ),
        Output(
            "signal_material",
            (MATERIAL, WAVELENGTH),
            True,
            "m2 sr-1",
            "radiometric signal of each material's facets",
        ),
        Output(
            "signal_earthshine",
            (WAVELENGTH,),
            True,
            "m2 sr-1",
            "radiometric signal of the light reflected from a Lambertian Earth, per unit solar "
            "irradiance",
        ),
        Output(
            "thermal_intensity",
            (WAVELENGTH,),
            True,
            "W sr-1 nm-1",
            "thermal emission intensity "
            "sum_j A_j cos(theta_r) epsilon(lambda, theta_r) B(lambda, T)",
        ),
        Output(
            "band_signal",
            (BAND,),
            True,
            "m2 sr-1",
            "solar-weighted band mean of the radiometric signal (photon counting)",
        ),
    )
}

#: Scene output names and the cube variables they add (``per_material`` adds
#: ``signal_material``).
SCENE_OUTPUTS: dict[str, str] = {
    "spacecraft_sbrdf": "spacecraft_sbrdf",
    "signal": "signal",
    "brdf": "brdf",
    "area": "area",
    "per_material": "signal_material",
    "band_signal": "band_signal",
}
#: Scene outputs over wavelength: a scene asking for none of them (only band outputs)
#: has its tables pre-integrated over the bands.
SPECTRAL_OUTPUTS = ("spacecraft_sbrdf", "signal", "brdf", "per_material")


# ------------------------------------------------------------- contributions


def reflected(
    plan: Plan,
    block: BlockInputs,
    to_source: np.ndarray,
    fraction: np.ndarray | None,
    per_material: bool,
) -> _kernels.FusedSums:
    """Facet sums of light from a distant source in direction ``to_source`` (body frame).

    Runs the kernel the plan chose (fused or numpy reference) or, with analytic
    evaluation, each material's BRDF model.

    Examples
    --------
    A unit cube of Lambertian albedo 0.5 at identity attitude: at phase 0 only the +x
    face (1 m2) is lit and seen, head on, so the signal is ``0.5 / pi``; at phase 60 deg
    it is seen and lit at 30 deg, ``0.5 / pi * cos(30 deg)**2``.

    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> plan = Scene(box, {"grey": grey}, attitudes=[[0, 0, 0, 1.0]], phase_angles=[0, 60]).plan()
    >>> from sbrdf_xr.engine.effects import reflected
    >>> block = plan.geometry.block(slice(None))
    >>> sums = reflected(plan, block, block.to_sun, None, False)
    >>> sums.signal.shape  # (geometries, wavelengths)
    (2, 3)
    >>> sums.signal[:, 0].round(6).tolist()
    [0.159155, 0.119366]
    >>> sums.area.round(6).tolist()  # projected area, cos(phase / 2) [m2]
    [1.0, 0.866025]
    """
    t = plan.terms
    if plan.knobs["evaluation"] == "analytic":
        return _analytic_sums(plan, to_source, block.to_observer, fraction, per_material)
    if plan.anisotropic:  # tables with a psi axis (the isotropic ones keep their kernel)
        return _aniso_kernels.reflected(plan, to_source, block.to_observer, fraction, per_material)
    if plan.knobs["kernel"] == "fused":
        return _kernels.fused_sums(
            to_source,
            block.to_observer,
            t.normal,
            t.area,
            t.material,
            plan.tables,
            plan.knobs["method"],
            fraction,
            per_material,
            t.normal_rows,
        )
    g, n_wl = to_source.shape[0], plan.tables.n_spectral
    dt = plan.tables.dtype
    sig, pap = np.zeros((g, n_wl), dt), np.zeros((g, n_wl), dt)
    area, lit = np.zeros(g), np.zeros(g)
    pm = np.zeros((g, len(plan.materials), n_wl), dt) if per_material else None
    for m in range(len(plan.materials)):
        sel = t.material == m
        values, (tgrid, dgrid, pgrid), edges, blend = plan.table(m)
        r = _kernels.material_sums(
            to_source,
            block.to_observer,
            t.normal[sel],
            t.area[sel],
            values,
            tgrid,
            dgrid,
            pgrid,
            plan.knobs["method"],
            None if fraction is None else fraction[:, sel],
            edges,
            blend,
        )
        sig += r.signal
        pap += r.paper
        area += r.area
        lit += r.lit_visible_area
        if pm is not None:
            pm[:, m] = r.signal
    return _kernels.FusedSums(sig, pap, area, lit, pm)


def _analytic_sums(
    plan: Plan, s: np.ndarray, o: np.ndarray, fraction: np.ndarray | None, per_material: bool
) -> _kernels.FusedSums:
    """The facet sums with every material evaluated by its BRDF model (no table)."""
    t = plan.terms
    wl = plan.wavelength
    dt = np.dtype(plan.knobs["dtype"])
    g = s.shape[0]
    sig, pap = np.zeros((g, wl.size)), np.zeros((g, wl.size))
    pm = np.zeros((g, len(plan.materials), wl.size)) if per_material else None
    area, lit = np.zeros(g), np.zeros(g)
    for j in range(t.normal.shape[0]):
        n = t.normal[j]
        ci, cr = s @ n, o @ n
        on = (ci > 0) & (cr > 0)
        if not on.any():
            continue
        eff = t.area[j] * (1.0 if fraction is None else fraction[on, j])
        model, kw = plan.models[t.material[j]]
        tangent = {"tangent": t.tangent[j]} if getattr(model, "anisotropic", False) else {}
        f = model.brdf(n, s[on], o[on], wl, **kw, **tangent)
        a2d = eff * cr[on]
        area[on] += a2d
        lit[on] += eff
        contrib = (a2d * ci[on])[:, None] * f
        sig[on] += contrib
        pap[on] += a2d[:, None] * f
        if pm is not None:
            pm[on, t.material[j]] += contrib
    if plan.pre_integrated:
        sig, pap = sig @ plan.band_weights.T, pap @ plan.band_weights.T
        pm = None if pm is None else pm @ plan.band_weights.T
    return _kernels.FusedSums(
        sig.astype(dt), pap.astype(dt), area, lit, None if pm is None else pm.astype(dt)
    )


def _shadow_fraction(
    plan: Plan, to_source: np.ndarray, to_observer: np.ndarray
) -> np.ndarray | None:
    if not plan.shadowing:
        return None
    from ..body.visibility import lit_visible_fraction

    frac = lit_visible_fraction(plan.spacecraft, to_source, to_observer, **plan.shadow_options)
    return np.ascontiguousarray(np.asarray(frac)[:, plan.terms.facet])


def _sunlight(plan: Plan, block: BlockInputs) -> dict[str, np.ndarray]:
    """Reflected sunlight; in the Earth's umbra nothing is evaluated (the sums are 0), in
    the penumbra the signal is scaled by the sunlit fraction of the solar disc."""
    scale = block.sun_scale
    if scale is not None and not np.all(scale > 0):
        lit = np.flatnonzero(scale > 0)
        sub = BlockInputs(block.to_sun[lit], block.to_observer[lit], None, scale[lit], (lit.size,))
        part = _sunlight(plan, sub) if lit.size else None
        g, n = (
            block.to_sun.shape[0],
            plan.tables.n_spectral
            if plan.knobs["evaluation"] == "table"
            else (len(plan.bands) if plan.pre_integrated else plan.wavelength.size),
        )
        dt = np.dtype(plan.knobs["dtype"])
        out = {"signal": np.zeros((g, n), dt), "paper": np.zeros((g, n), dt), "area": np.zeros(g)}
        if "signal_material" in plan.output_names:
            out["signal_material"] = np.zeros((g, len(plan.materials), n), dt)
        if part is not None:
            for k in out:
                out[k][lit] = part[k]
        return out
    frac = _shadow_fraction(plan, block.to_sun, block.to_observer)
    r = reflected(plan, block, block.to_sun, frac, "signal_material" in plan.output_names)
    out = {"signal": r.signal, "paper": r.paper, "area": r.area}
    if r.per_material is not None:
        out["signal_material"] = r.per_material
    if scale is not None:  # the Earth's penumbra scales the irradiance, not the geometry
        sc = scale.astype(r.signal.dtype)
        out["signal"] = r.signal * sc[:, None]
        if r.per_material is not None:
            out["signal_material"] = r.per_material * sc[:, None, None]
    return out


def _earthshine(plan: Plan, block: BlockInputs) -> dict[str, np.ndarray]:
    to_earth = block.to_earth
    assert to_earth is not None  # blocks carry Earth vectors whenever earthshine is on
    frac = _shadow_fraction(plan, to_earth, block.to_observer)
    r = reflected(plan, block, to_earth, frac, False)
    if block.earth_scale is not None:  # per geometry (an observation's Earth distance and phase)
        return {"signal_earthshine": (block.earth_scale[:, None] * r.signal).astype(r.signal.dtype)}
    ratio = plan.effect_params["earthshine"]["ratio"]
    return {"signal_earthshine": (ratio * r.signal).astype(r.signal.dtype)}


def _thermal(plan: Plan, block: BlockInputs) -> dict[str, np.ndarray]:
    """``sum_j A_j cos(theta_r) epsilon_j(lambda, theta_r) B(lambda, T_j)`` over the visible
    terms [W sr-1 nm-1] (the emission term of paper 001's signature model)."""
    t = plan.terms
    p = plan.effect_params["thermal"]
    o = block.to_observer
    out = np.zeros((o.shape[0], plan.wavelength.size))
    for m in range(len(plan.materials)):
        sel = t.material == m
        cos_r = o @ t.normal[sel].T  # (G, T_m)
        vis = cos_r > 0
        theta_r = np.degrees(np.arctan2(np.sqrt(np.clip(1 - cos_r**2, 0, None)), cos_r))
        eps = sources.emissivity_at(p["emissivity"][m], p["theta"][m], np.where(vis, theta_r, 0.0))
        w = np.where(vis, cos_r, 0.0) * t.area[sel]
        out += np.einsum("gf,gfl->gl", w, eps) * p["radiance"][m]
    return {"thermal_intensity": out.astype(np.dtype(plan.knobs["dtype"]))}


# ------------------------------------------------------------------ registry


@dataclass(frozen=True)
class Effect:
    """One effect a scene may ask for.

    Attributes
    ----------
    name : str
        Name used in ``Scene(effects=...)``.
    needs : tuple of str
        Scene inputs it requires (``"to_earth"``: Earth directions; ``"mesh"``: the
        facets themselves rather than merged terms).
    source : str or None
        The light source it adds (``"sun"``, ``"earth"``, ``"facets"`` for emission),
        or None for an effect that modifies others (shadowing, eclipse).
    outputs : tuple of str
        The :data:`OUTPUTS` it fills.
    contribute : callable or None
        ``contribute(plan, block) -> {name: array}`` on every block.
    description : str
        The plan line when it runs (details are added by the planner).

    Examples
    --------
    >>> from sbrdf_xr.engine.effects import EFFECTS
    >>> e = EFFECTS["earthshine"]
    >>> e.needs, e.source
    (('to_earth',), 'earth')
    >>> e.outputs
    ('signal_earthshine', 'band_signal')
    >>> EFFECTS["shadowing"].contribute is None  # it modifies the others' sums
    True
    """

    name: str
    needs: tuple[str, ...]
    source: str | None
    outputs: tuple[str, ...]
    contribute: Callable[[Plan, BlockInputs], Mapping[str, np.ndarray]] | None
    description: str
    params: Mapping[str, Any] = field(default_factory=dict)


#: The effects, by name.
EFFECTS: dict[str, Effect] = {
    e.name: e
    for e in (
        Effect(
            "sunlight",
            (),
            "sun",
            ("spacecraft_sbrdf", "signal", "brdf", "area", "signal_material", "band_signal"),
            _sunlight,
            "reflected sunlight: paper 000 Eqs. 3-4 and the radiometric signal",
        ),
        Effect(
            "shadowing",
            ("mesh",),
            None,
            (),
            None,
            "self-shadowing and self-occlusion of the facets",
        ),
        Effect(
            "earthshine",
            ("to_earth",),
            "earth",
            ("signal_earthshine", "band_signal"),
            _earthshine,
            "sunlight reflected by a Lambertian Earth, a second distant source",
        ),
        Effect(
            "thermal",
            (),
            "facets",
            ("thermal_intensity",),
            _thermal,
            "thermal emission epsilon(lambda, theta) B(lambda, T), epsilon = 1 - rho (Kirchhoff)",
        ),
        Effect(
            "eclipse",
            ("sunlit_fraction",),
            None,
            (),
            None,
            "the Earth's shadow: sunlight scaled by the sunlit fraction of the solar disc",
        ),
    )
}


def _trapezoid_weights(plan: Plan) -> np.ndarray:
    """Weights ``w`` with ``y @ w`` the trapezoid integral of ``y`` over the wavelength grid
    (paper 000 Eq. 2); a single wavelength has weight 1.  Made once per plan."""
    w = plan.cache.get("trapezoid_weights")
    if w is None:
        wl = np.asarray(plan.wavelength, dtype=np.float64)
        w = np.ones(1) if wl.size == 1 else np.zeros(wl.size)
        if wl.size > 1:
            half = np.diff(wl) / 2
            w[:-1] += half
            w[1:] += half
        plan.cache["trapezoid_weights"] = w
    return w


def finish(
    plan: Plan, sums: Mapping[str, np.ndarray], lead_shape: tuple[int, ...]
) -> dict[str, np.ndarray]:
    """The plan's outputs of one block from the effects' sums, shaped ``lead_shape + tail``.

    ``spacecraft_sbrdf`` is paper 000 Eq. 4 (0 where no area contributes, the 0/0 of
    Eq. 4), ``brdf`` its trapezoid integral over wavelength (Eq. 2), ``band_signal``
    the band-weighted total signal (Sun plus Earth), or the pre-integrated sums.

    Examples
    --------
    For a Lambertian body ``spacecraft_sbrdf`` is ``albedo / pi`` at every geometry, and
    ``brdf`` its integral over 500-700 nm, ``200 * 0.5 / pi``:

    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> plan = Scene(box, {"grey": grey}, attitudes=[[0, 0, 0, 1.0]], phase_angles=[0, 60]).plan()
    >>> from sbrdf_xr.engine.effects import finish, reflected
    >>> block = plan.geometry.block(slice(None))
    >>> r = reflected(plan, block, block.to_sun, None, False)
    >>> out = finish(plan, {"signal": r.signal, "paper": r.paper, "area": r.area}, (1, 2))
    >>> sorted((k, v.shape) for k, v in out.items())
    [('area', (1, 2)), ('brdf', (1, 2)), ('signal', (1, 2, 3)), ('spacecraft_sbrdf', (1, 2, 3))]
    >>> out["spacecraft_sbrdf"][0, :, 0].round(6).tolist()
    [0.159155, 0.159155]
    >>> out["brdf"].round(4).tolist()
    [[31.831, 31.831]]
    """
    names = plan.output_names
    dt = np.dtype(plan.knobs["dtype"])
    # the spectral integrals are einsum, not BLAS: this runs on every engine thread at
    # once, and a threaded BLAS call starts threads of its own that then spin on the
    # cores the other blocks need
    area = sums["area"]
    out: dict[str, np.ndarray] = {}
    if "area" in names:
        out["area"] = area
    if "spacecraft_sbrdf" in names or "brdf" in names:
        paper = sums["paper"]
        # Eq. 4 in place where the kernel's buffer allows it (no block-sized temporaries);
        # where no area contributes the paper sum is 0 already and stays so
        if paper.dtype == dt and paper.flags.c_contiguous and paper.flags.writeable:
            sbrdf = paper
        else:
            sbrdf = np.zeros(paper.shape, dt)
        np.divide(paper, area[:, None], out=sbrdf, where=area[:, None] > 0)
        if "spacecraft_sbrdf" in names:
            out["spacecraft_sbrdf"] = sbrdf
        if "brdf" in names:
            out["brdf"] = np.einsum("gl,l->g", sbrdf, _trapezoid_weights(plan)).astype(dt)
    for k in ("signal", "signal_material", "signal_earthshine", "thermal_intensity"):
        if k in names:
            out[k] = sums[k]
    if "band_signal" in names:
        total = sums["signal"]
        if "signal_earthshine" in sums:
            total = total + sums["signal_earthshine"]
        if not plan.pre_integrated:
            total = np.einsum("gl,bl->gb", total, plan.band_weights)
        out["band_signal"] = total.astype(dt)
    return {k: v.reshape(*lead_shape, *v.shape[1:]) for k, v in out.items()}
