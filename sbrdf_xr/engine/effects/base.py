"""What every effect is made of: the :class:`Effect` record, the outputs of a cube, what
a block of geometries hands an effect, and the facet sums of a distant source.

An effect lives in its own module of :mod:`sbrdf_xr.engine.effects` as one
:class:`Effect`; the registry there lists them.  Every variable a cube can hold is one
:class:`Output`: the core ones here (:data:`CORE_OUTPUTS`), an effect's own in its
:attr:`Effect.declares`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ... import kernels as _kernels
from ..._names import BAND, MATERIAL, WAVELENGTH
from ...errors import ValidationError
from ...kernels import anisotropic as _aniso_kernels

if TYPE_CHECKING:
    import xarray as xr

    from ..views import PlanView, SceneView

__all__ = [
    "CORE_OUTPUTS",
    "SCENE_OUTPUTS",
    "SPECTRAL_OUTPUTS",
    "WHEN",
    "BlockInputs",
    "Decision",
    "Effect",
    "Output",
    "PlanInputs",
    "facet_fraction",
    "finish",
    "readonly",
    "reflected",
    "table_on",
    "trapezoid_weights",
]


@dataclass(frozen=True)
class BlockInputs:
    """Body-frame directions of one block of geometries, flattened to (G, 3).

    ``sources`` holds what the effects' geometry adds per geometry (their
    :attr:`Effect.geometry`): a source's direction as ``to_<source>`` (G, 3) and its
    irradiance relative to the Sun's as ``<source>_scale`` (G,).

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
    >>> block.sun_scale is None, dict(block.sources)  # no Earth shadow, no other source
    (True, {})
    >>> block.direction("sun") is block.to_sun, block.direction("earth")
    (True, None)
    """

    to_sun: np.ndarray
    to_observer: np.ndarray
    sun_scale: np.ndarray | None  #: (G,) sunlit fraction of the solar disc, or None (1)
    lead_shape: tuple[int, ...]  #: the block's geometry dimensions before flattening
    sources: Mapping[str, np.ndarray] = field(default_factory=dict)

    def direction(self, source: str) -> np.ndarray | None:
        """Unit vectors (G, 3) towards ``source`` (``"sun"`` or a key of :attr:`sources`)."""
        return self.to_sun if source == "sun" else self.sources.get(f"to_{source}")

    def scale(self, source: str) -> np.ndarray | None:
        """Irradiance of ``source`` relative to the Sun's unshadowed (G,), or None (constant)."""
        return self.sun_scale if source == "sun" else self.sources.get(f"{source}_scale")


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


#: The variables of a cube that no single effect owns (an effect's own are in its entry).
CORE_OUTPUTS: dict[str, Output] = {
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


# ------------------------------------------------------------------ the record


def readonly(a: np.ndarray) -> np.ndarray:
    """A C-contiguous, read-only copy (or view) of ``a``, for the frozen plan.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.engine.effects import readonly
    >>> every_other = np.arange(6).reshape(2, 3)[:, ::2]
    >>> r = readonly(every_other)
    >>> r.tolist(), r.flags.c_contiguous, r.flags.writeable
    ([[0, 2], [3, 5]], True, False)
    >>> r[0, 0] = 1
    Traceback (most recent call last):
    ...
    ValueError: assignment destination is read-only
    """
    a = np.ascontiguousarray(a)
    a.flags.writeable = False
    return a


@dataclass(frozen=True)
class PlanInputs:
    """What an effect's planner (:attr:`Effect.plan`) is given.

    Per-facet effects are planned before the facet terms exist (``wavelength`` None,
    ``materials`` empty); the others once the spectral axis is known.

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.engine.effects import EFFECTS, PlanInputs
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> x = [[1.0, 0.0, 0.0]]  # the Sun and the observer along +x
    >>> scene = Scene(box, {"grey": grey}, to_sun=x, to_observer=x, effects=("shadowing",))
    >>> inputs = PlanInputs(scene, {"shadow_method": "exact"})
    >>> EFFECTS["shadowing"].plan(inputs)  # a box is convex
    Decision(active=False, line='skipped: the body is convex, no facet can shadow another', \
params={})
    """

    scene: SceneView
    knobs: Mapping[str, Any]
    wavelength: np.ndarray | None = None  #: [nm], None before the spectral stage
    materials: tuple[str, ...] = ()  #: the materials of the contributing terms
    pre_integrated: bool = False  #: the tables are integrated over the bands


@dataclass(frozen=True)
class Decision:
    """What an effect's planner decided: whether it runs, its plan line, its parameters.

    Examples
    --------
    >>> from sbrdf_xr.engine.effects import Decision
    >>> Decision(True, "a second distant source", {"ratio": 0.01}).active
    True
    """

    active: bool
    line: str | None = None  #: the plan's line for the effect (None: none)
    params: Mapping[str, Any] = field(default_factory=dict)  #: ``plan.effect_params[name]``


def runs(inputs: PlanInputs) -> Decision:
    """The planner of an effect that always runs as asked, without a plan line."""
    return Decision(True)


#: Who turns an effect on: the engine always, the scene (``Scene(effects=...)``), or the
#: geometry (an observation brings the Earth's shadow).
WHEN = ("always", "asked", "automatic")


@dataclass(frozen=True)
class Effect:
    """One effect a simulation can include: everything the engine knows about it.

    Attributes
    ----------
    name : str
        Name used in ``Scene(effects=...)`` and in the plan.
    title : str
        A short name for sentences (``"self-shadowing"``).
    description : str
        What it computes, with the equation it follows.
    when : {"always", "asked", "automatic"}
        Who turns it on (:data:`WHEN`); an ``asked`` effect the scene does not ask for
        gets the plan line ``skipped: not requested``.
    source : str or None
        The light it adds: a distant source whose light the facets reflect (``"sun"``,
        ``"earth"``, ``"moon"``; one kernel pass per block each, its direction and scale
        in :class:`BlockInputs`), ``"facets"`` for their own emission (every visible
        term contributes), or None for an effect that changes the others (shadowing,
        the Earth's shadow).
    needs : tuple of str
        What it needs from the scene: ``"to_earth"`` (explicit geometry pairs must give
        body-frame Earth vectors), ``"observation"`` (only an observation's geometry
        will do), ``"mesh"``, ``"sunlit_fraction"``; :class:`~sbrdf_xr.engine.Scene`
        refuses a scene without them.
    outputs : tuple of str
        The :data:`OUTPUTS <sbrdf_xr.engine.effects.OUTPUTS>` it fills.
    declares : tuple of Output
        Its own variables, added to the cube whenever it runs (those over wavelength
        only when the plan keeps the spectrum).
    band : tuple of str
        Its sums that add up to ``band_signal``.
    plan : callable
        ``plan(PlanInputs) -> Decision``: whether it runs (asked, and not negligible),
        its plan line and its parameters (``plan.effect_params[name]``).
    contribute : callable or None
        ``contribute(plan, block) -> {name: array}`` on every block; sums of the same
        name from several effects add up.
    fraction : callable or None
        ``fraction(plan, to_source, to_observer) -> (G, T) array``: the lit-and-visible
        fraction of every term that it applies to every reflected source.  Such an
        effect is per facet: it is planned before the facet terms and facets are not
        merged while it runs.
    reads : tuple of str
        The scene fields (and scene-file keys) that are its parameters, for the
        reference of the scene files (:func:`sbrdf_xr.engine.schema.reference`).
    geometry : callable or None
        ``geometry(scene, observed) -> {name: array}``: its source's directions and
        scales for the sweep (``observed`` is the observation's geometry, or None for a
        grid or explicit pairs): (P, 3) reference-frame directions and (P,) scales per
        phase angle for a grid, (n, 3) body-frame directions and (n,) scales otherwise.

    Examples
    --------
    >>> from sbrdf_xr.engine.effects import EFFECTS
    >>> e = EFFECTS["earthshine"]
    >>> e.needs, e.source, e.when
    (('to_earth',), 'earth', 'asked')
    >>> e.outputs, e.reflects
    (('signal_earthshine', 'band_signal'), True)
    >>> EFFECTS["shadowing"].contribute is None, EFFECTS["shadowing"].per_facet
    (True, True)
    """

    name: str
    title: str
    description: str
    when: str
    source: str | None
    needs: tuple[str, ...] = ()
    outputs: tuple[str, ...] = ()
    declares: tuple[Output, ...] = ()
    band: tuple[str, ...] = ()
    reads: tuple[str, ...] = ()
    plan: Callable[[PlanInputs], Decision] = runs
    contribute: Callable[[PlanView, BlockInputs], Mapping[str, np.ndarray]] | None = None
    fraction: Callable[[PlanView, np.ndarray, np.ndarray], np.ndarray] | None = None
    geometry: Callable[[SceneView, xr.Dataset | None], Mapping[str, np.ndarray]] | None = None

    def __post_init__(self) -> None:
        if self.when not in WHEN:
            raise ValidationError(f"effect {self.name!r}: when={self.when!r}; allowed: {WHEN}")

    @property
    def reflects(self) -> bool:
        """Its light comes from a distant source and the facets reflect it (a kernel pass)."""
        return self.source is not None and self.source != "facets"

    @property
    def per_facet(self) -> bool:
        """It changes each facet's lit-and-visible fraction (facets are not merged)."""
        return self.fraction is not None


# ------------------------------------------------------------- contributions


def facet_fraction(
    plan: PlanView, to_source: np.ndarray, to_observer: np.ndarray
) -> np.ndarray | None:
    """The lit-and-visible fraction (G, T) of every term for a source in ``to_source``:
    the product of the plan's per-facet effects (:attr:`Effect.fraction`), or None (1).

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.engine.effects import facet_fraction
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> plan = Scene(box, {"grey": grey}, attitudes=[[0, 0, 0, 1.0]], phase_angles=[0]).plan()
    >>> block = plan.geometry.block(slice(None))
    >>> facet_fraction(plan, block.to_sun, block.to_observer) is None  # no shadowing
    True
    """
    frac = None
    for effect in plan.active_effects:
        if effect.fraction is not None:
            f = effect.fraction(plan, to_source, to_observer)
            frac = f if frac is None else frac * f
    return frac


def reflected(
    plan: PlanView,
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
        return _aniso_kernels.anisotropic_reflected(
            plan, to_source, block.to_observer, fraction, per_material
        )
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
    plan: PlanView, s: np.ndarray, o: np.ndarray, fraction: np.ndarray | None, per_material: bool
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
        tangent = {}
        if getattr(model, "anisotropic", False) and t.tangent is not None:
            tangent = {"tangent": t.tangent[j]}
        f = model.brdf(n, s[on], o[on], wl, **kw, **tangent)
        a2d = eff * cr[on]
        area[on] += a2d
        lit[on] += eff
        contrib = (a2d * ci[on])[:, None] * f
        sig[on] += contrib
        pap[on] += a2d[:, None] * f
        if pm is not None:
            pm[on, t.material[j]] += contrib
    if plan.pre_integrated and plan.band_weights is not None:
        bw = plan.band_weights
        sig, pap = sig @ bw.T, pap @ bw.T
        pm = None if pm is None else pm @ bw.T
    return _kernels.FusedSums(
        sig.astype(dt), pap.astype(dt), area, lit, None if pm is None else pm.astype(dt)
    )


def trapezoid_weights(plan: PlanView) -> np.ndarray:
    """Weights ``w`` [nm] with ``y @ w`` the trapezoid integral of ``y`` over the
    wavelength grid (paper 000 Eq. 2); a single wavelength has weight 1.  Made once per
    plan (kept in ``plan.cache``).

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.engine.effects.base import trapezoid_weights
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> x = [[1.0, 0.0, 0.0]]
    >>> trapezoid_weights(Scene(box, {"grey": grey}, to_sun=x, to_observer=x).plan()).tolist()
    [50.0, 100.0, 50.0]
    """
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
    plan: PlanView, sums: Mapping[str, np.ndarray], lead_shape: tuple[int, ...]
) -> dict[str, np.ndarray]:
    """The plan's outputs of one block from the effects' sums, shaped ``lead_shape + tail``.

    ``spacecraft_sbrdf`` is paper 000 Eq. 4 (0 where no area contributes, the 0/0 of
    Eq. 4), ``brdf`` its trapezoid integral over wavelength (Eq. 2), ``band_signal``
    the band-weighted total signal (the sums every running effect adds to it,
    :attr:`Effect.band`), or the pre-integrated sums; every other output is the sum of
    that name.

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
            out["brdf"] = np.einsum("gl,l->g", sbrdf, trapezoid_weights(plan)).astype(dt)
    for k in names:
        if k not in out and k in sums:
            out[k] = sums[k]
    if "band_signal" in names:
        band = [k for e in plan.active_effects for k in e.band if k in sums]
        total = sums[band[0]]
        for k in band[1:]:
            total = total + sums[k]
        if not plan.pre_integrated and plan.band_weights is not None:
            total = np.einsum("gl,bl->gb", total, plan.band_weights)
        out["band_signal"] = total.astype(dt)
    return {k: v.reshape(*lead_shape, *v.shape[1:]) for k, v in out.items()}


def table_on(da: xr.DataArray, wl: np.ndarray, theta_step: float | None) -> xr.DataArray:
    """A table on the wavelengths ``wl``, its theta_i resampled every ``theta_step`` degree.

    Examples
    --------
    The last node of theta_i is kept when the step does not reach it:

    >>> import numpy as np
    >>> from sbrdf_xr.engine.effects.base import table_on
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> grey.theta_i.values.tolist()
    [0.0, 90.0]
    >>> t = table_on(grey, np.array([550.0]), 40.0)
    >>> t.theta_i.values.tolist(), t.wavelength.values.tolist()
    ([0.0, 40.0, 80.0, 90.0], [550.0])
    >>> bool(np.allclose(t, 0.5 / np.pi))  # a Lambertian table stays albedo / pi
    True
    >>> table_on(grey, np.array([500.0, 600.0, 700.0]), None) is grey  # already on the grid
    True
    """
    if not np.array_equal(da[WAVELENGTH].values, wl):
        da = da.interp({WAVELENGTH: wl})
    if theta_step is not None:
        ti = da["theta_i"].values
        new = np.arange(ti[0], ti[-1] + 1e-9, float(theta_step))
        if new[-1] < ti[-1]:
            new = np.append(new, ti[-1])
        da = da.interp(theta_i=new)
    return da
