"""The accuracy/cost sweep of :func:`sbrdf_xr.bench.suite.accuracy_cost` and its shadowing rows.

One knob at a time away from the ``reference`` configuration, on the CanX-1 rotation and
a sweep of random attitudes: the band magnitude and spectral errors against the reference
and the wall time as a ratio to the reference's; the CanX-1 tables are rebuilt from
their shipped measurements with other construction knobs.  :func:`shadow_rows` adds the
self-shadowing comparison of :mod:`sbrdf_xr.bench.shadowing`.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr

from .. import catalog
from ..body.spacecraft import CANX1_MATERIALS
from ..engine.knobs import PRESETS
from ..materials import tables as material
from .rows import BenchRow, timed_runs

if TYPE_CHECKING:
    from ..engine.scene import Scene

__all__ = ["BANDS", "CANX1_MATERIALS", "accuracy_cost", "fixed_cost_rows", "shadow_rows"]

BANDS = ("V", "R", "I")

# ---------------------------------------------------- accuracy and cost


def _paper_tables(**build: Any) -> dict[str, xr.DataArray]:
    """The CanX-1 tables rebuilt from their measurements as shipped (the catalog's build
    options), with other construction knobs."""
    out = {}
    for m in CANX1_MATERIALS:
        meas = catalog.load(f"{m}-measurements")
        build_opts = catalog.entry(m).extra.get("build", {})
        fit = build_opts.get("fit", f"{m}-fit")  # the model the shipped table is built with
        shipped = {k: v for k, v in build_opts.items() if k != "fit"}
        out[m] = material.build_lut(
            meas, model=catalog.load(fit), material=m, **{**shipped, **build}
        )
    return out


def _subsample_wavelengths(tables: dict[str, xr.DataArray], step: int) -> dict[str, xr.DataArray]:
    return {k: v.isel(wavelength=slice(None, None, step)) for k, v in tables.items()}


def _band_mags(signal: xr.DataArray) -> np.ndarray:
    from ..photometry import pre_integrate

    b = pre_integrate(signal, list(BANDS), normalize=True).values
    with np.errstate(divide="ignore"):
        return -2.5 * np.log10(np.maximum(b, 1e-300))


def _errors(test: xr.DataArray, ref: xr.DataArray) -> tuple[float, float, float]:
    """(max mmag, median mmag, p99 relative spectral error) of ``test`` against ``ref``."""
    if "wavelength" in test.dims:
        mt, mr = _band_mags(test), _band_mags(ref)
        t_sp = (
            test.interp(wavelength=ref.wavelength)
            if test.sizes["wavelength"] != ref.sizes["wavelength"]
            else test
        )
        rel = np.abs(t_sp.values - ref.values) / np.maximum(np.abs(ref.values), 1e-300)
        keep_sp = np.abs(ref.values) > 1e-3 * np.abs(ref.values).max()
        p99 = float(np.percentile(rel[keep_sp], 99))
    else:  # band_signal over band
        mt = -2.5 * np.log10(np.maximum(test.values, 1e-300))
        mr = _band_mags(ref)
        p99 = float("nan")
    bref = 10 ** (-0.4 * mr)
    keep = bref > 1e-3 * bref.max()
    d = np.abs(mt - mr)[keep] * 1e3
    return float(d.max()), float(np.median(d)), p99


def _shipped_tables() -> dict[str, xr.DataArray]:
    """The CanX-1 tables as the catalog ships them (built once, then read from the cache)."""
    return catalog.load_materials(CANX1_MATERIALS)


def _knobs(quick: bool, base: dict[str, xr.DataArray]) -> list[tuple[str, str, dict[str, Any]]]:
    """``(knob, setting, options)`` of the sweep: one knob at a time, then the presets."""
    knobs: list[tuple[str, str, dict[str, Any]]] = [
        ("reference", "cubic look-up, 1-deg theta_i, 21x21, 5 nm, merged, float64", {}),
        ("lookup method", "nearest (the paper's)", {"method": "nearest"}),
        ("lookup method", "linear", {"method": "linear"}),
        ("precision", "float32", {"dtype": "float32"}),
        ("wavelength", "10 nm sampling", {"materials": _subsample_wavelengths(base, 2)}),
        ("wavelength", "20 nm sampling", {"materials": _subsample_wavelengths(base, 4)}),
        (
            "wavelength",
            "band pre-integration (V, R, I)",
            {"outputs": ("band_signal", "area"), "bands": BANDS},
        ),
        ("facets", "not merged (684 facets)", {"merge": False}),
    ]
    if not quick:
        for setting, build in (
            ("theta_i every 2 deg", {"theta_i": np.arange(0.0, 91.0, 2.0)}),
            ("theta_i every 5 deg", {"theta_i": np.arange(0.0, 91.0, 5.0)}),
            ("11 x 11 delta_theta x phi", {"n_phi": 11, "n_delta_theta": 11}),
            ("41 x 41 delta_theta x phi", {"n_phi": 41, "n_delta_theta": 41}),
        ):
            knobs.append(("table", setting, {"materials": _paper_tables(**build)}))
    # the presets themselves: only the preset's knobs, the rest as the scene has them
    knobs += [("preset", name, {"preset": name}) for name in PRESETS]
    return knobs


def accuracy_cost(quick: bool = False, repeat: int | None = None) -> list[BenchRow]:
    """The accuracy/cost table: one knob at a time away from the reference, and the presets.

    Every row's time is the best of ``repeat`` runs, the runs of all rows of a sweep
    interleaved (:func:`sbrdf_xr.bench.rows.timed_runs`), as a ratio to the reference's
    best, with the spread of its runs.  Errors are against the reference configuration;
    the presets' rows and the analytic row also give the errors against the materials'
    generating models (``evaluation="analytic"``: each material's catalog model).

    Parameters
    ----------
    quick : bool
        A smaller random sweep (400 attitudes x 3 phase angles against 5000 x 3) and no
        table-resolution knobs (which rebuild the CanX-1 tables).
    repeat : int, optional
        Timing runs of every row (default 3, or 5 without ``quick``).

    Returns
    -------
    list of BenchRow

    Examples
    --------
    Even ``quick`` runs every knob on two sweeps a few times (about half a minute); it is
    not run here:

    >>> import inspect
    >>> from sbrdf_xr.bench import accuracy_cost, format_rows
    >>> list(inspect.signature(accuracy_cost).parameters)
    ['quick', 'repeat']
    >>> rows = accuracy_cost(quick=True, repeat=1)  # doctest: +SKIP
    >>> rows[0].name  # doctest: +SKIP
    'reference: cubic look-up, 1-deg theta_i, 21x21, 5 nm, merged, float64'
    >>> print(format_rows(rows))  # doctest: +SKIP
    """
    from .. import geometry
    from ..engine import builtin_scene
    from ..engine.run import simulate

    repeat = (3 if quick else 5) if repeat is None else repeat
    rot = builtin_scene("canx1-rotation")
    n_big = 400 if quick else 5000
    big = rot.with_options(
        attitudes=geometry.uniform_attitudes(n_big, seed=7),
        attitude_angle=None,
        phase_angles=[10.0, 45.0, 90.0],
        chunk=500,
        name=f"random-{n_big}x3",
    )
    base = _shipped_tables()
    reference = {
        "method": "cubic",
        "dtype": "float64",
        "merge": True,
        "materials": base,
        "outputs": ("signal", "area"),
    }
    knobs = _knobs(quick, base)
    analytic = (
        "materials",
        "analytic generating models (ground truth)",
        {"evaluation": "analytic"},
    )
    rows: list[BenchRow] = []
    for sweep in (rot, big):
        cubes: dict[str, xr.Dataset] = {}
        cases = [*knobs, analytic]
        # each case planned once, outside the timing: the rows time the simulation, and
        # the fixed cost of a scene (planning, one call's overhead) is a row of its own
        plans = {f"{k}: {s}": _configured(sweep, reference, o).plan() for k, s, o in cases}
        timing = timed_runs(
            {name: partial(_run, simulate, plan, cubes, name) for name, plan in plans.items()},
            repeat,
        )
        ref_name = f"{knobs[0][0]}: {knobs[0][1]}"
        ref, truth = cubes[ref_name].signal, cubes[f"{analytic[0]}: {analytic[1]}"].signal
        t_ref = timing[ref_name][0]
        for knob, setting, _ in cases:
            name = f"{knob}: {setting}"
            cube = cubes[name]
            test = cube.band_signal if "band_signal" in cube else cube.signal
            model: tuple[float, ...] = (float("nan"),) * 3
            extra = ""
            if knob == "materials":  # the error column: the tabulated reference against them
                mx, med, p99 = _errors(ref, truth)
                extra = "error column: the tabulated reference against them"
            else:
                mx, med, p99 = _errors(test, ref)
                if knob in ("preset", "reference"):
                    model = _errors(test, truth)
            rows.append(
                BenchRow(
                    name,
                    timing[name][0],
                    "reference",
                    timing[name][0] / t_ref,
                    extra,
                    sweep=sweep.name,
                    mmag_max=mx,
                    mmag_median=med,
                    rel_p99=p99,
                    knob=knob,
                    spread=timing[name][1],
                    model_mmag_max=model[0],
                    model_mmag_median=model[1],
                )
            )
        rows += fixed_cost_rows(sweep, reference, t_ref, repeat)
    rows += shadow_rows(quick=quick, repeat=repeat)
    return rows


#: One-geometry ``simulate`` calls per timed repeat of :func:`fixed_cost_rows`.
_CALLS = 20

#: What a preset's row keeps of the reference configuration: the tables and the outputs.
_KEEP = ("materials", "outputs")


def _configured(scene: Scene, reference: dict[str, Any], opts: dict[str, Any]) -> Scene:
    """``scene`` with the reference configuration changed by ``opts`` (a preset keeps only
    :data:`_KEEP` of it)."""
    cfg = {k: v for k, v in reference.items() if "preset" not in opts or k in _KEEP}
    return scene.with_options(**{**cfg, **opts})


def _run(
    simulate: Callable[[Any], xr.Dataset], plan: Any, cubes: dict[str, xr.Dataset], name: str
) -> None:
    """Simulate a compiled ``plan`` into ``cubes[name]``."""
    cubes[name] = simulate(plan).compute(scheduler="sync")


def fixed_cost_rows(
    scene: Scene, reference: dict[str, Any], t_ref: float, repeat: int = 3
) -> list[BenchRow]:
    """The fixed cost of a scene in the reference configuration, beside the reference
    sweep's own time: planning a fresh scene (``with_options`` and ``plan``, its tables
    already loaded) and one ``simulate`` call of a single geometry (its overhead).

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.bench.accuracy import fixed_cost_rows
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> scene = Scene(box, {"grey": grey}, attitudes=[[0, 0, 0, 1.0]] * 4, phase_angles=[10.0])
    >>> rows = fixed_cost_rows(scene, {"method": "linear"}, t_ref=1.0, repeat=1)
    >>> [r.name for r in rows]
    ['fixed cost: a fresh scene planned', 'fixed cost: one simulate call, one geometry']
    """
    from ..engine.run import simulate

    base = _configured(scene, reference, {})
    base.plan()
    one = base.with_options(
        attitudes=np.asarray(base.attitudes)[:1], attitude_angle=None, chunk=None
    ).plan()
    count = iter(range(1 << 30))

    def fresh() -> None:  # another phase angle: a new scene and plan, tables reused
        base.with_options(phase_angles=[10.0 + 1e-9 * next(count)]).plan()

    def calls() -> None:  # a call is sub-millisecond: many per timed repeat
        for _ in range(_CALLS):
            simulate(one)

    timing = timed_runs({"plan": fresh, "call": calls}, repeat)
    timing["call"] = (timing["call"][0] / _CALLS, timing["call"][1])
    label = {
        "plan": "fixed cost: a fresh scene planned",
        "call": "fixed cost: one simulate call, one geometry",
    }
    return [
        BenchRow(
            label[k],
            t,
            "reference",
            t / t_ref,
            f"{t * 1e3:.2f} ms, not in the rows above (each case planned before timing)",
            sweep=scene.name,
            knob="fixed cost",
            spread=sp,
        )
        for k, (t, sp) in timing.items()
    ]


def shadow_rows(quick: bool = False, repeat: int = 2) -> list[BenchRow]:
    """Self-shadowing: the sampled method at several densities against the exact method
    (polygon clipping) on the package's non-convex test bodies (an L prism, a plate with a
    fin, a bus with a panel, CanX-1 with antennas), and the cost of both on a CanX-1 sweep
    (:mod:`sbrdf_xr.bench.shadowing`).  Errors are of the Lambertian signal against exact.

    Examples
    --------
    Even ``quick`` takes over a second (four bodies, three densities, a CanX-1 sweep);
    :func:`sbrdf_xr.bench.shadowing.accuracy_rows` runs the same comparison on one body
    in milliseconds.  Not run here:

    >>> from sbrdf_xr.bench import shadow_rows
    >>> rows = shadow_rows(quick=True, repeat=1)  # doctest: +SKIP
    >>> [r.name for r in rows][:2]  # doctest: +SKIP
    ['shadowing: exact', 'shadowing: off (no shadowing)']
    """
    from . import shadowing as shadow_bench

    rows = []
    acc = shadow_bench.accuracy_rows(
        densities=(2, 4, 8) if quick else (2, 4, 8, 16, 32),
        n_geometries=8 if quick else 18,
        repeat=repeat,
    )
    for r in acc:
        mmag = 2500.0 * np.log10(1.0 + r.worst_rel_error)
        med = 2500.0 * np.log10(1.0 + r.median_rel_error)
        rows.append(
            BenchRow(
                f"shadowing: {r.label}",
                r.ms_per_geometry * 1e-3,
                "exact shadowing",
                r.time_ratio,
                f"worst {r.worst_rel_error:.2g}, median {r.median_rel_error:.2g} "
                f"relative ({r.bodies}; {r.n_geometries} geometries each)",
                sweep="shadowing, non-convex bodies",
                mmag_max=mmag,
                mmag_median=med,
                knob="shadowing",
            )
        )
    for c in shadow_bench.canx1_sweep_rows(n_attitudes=90 if quick else 360, repeat=repeat):
        rows.append(
            BenchRow(
                f"shadowing cost: {c.label}",
                c.ms_per_geometry * 1e-3,
                c.ratio_to,
                c.ratio,
                f"{c.ms_per_geometry:.2f} ms per geometry, {c.n_facets} facets",
                sweep="shadowing, CanX-1 sweep",
                knob="shadowing",
            )
        )
    return rows
