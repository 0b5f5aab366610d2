"""Accuracy and cost of the shadowing methods, measured against the exact method.

Rows for the benchmark tables: the relative error of the Lambertian signal
``S = sum_j A_j (N_j.s)+ (N_j.o)+ f_j`` (a constant sBRDF, so only the lit-and-visible
fractions ``f_j`` differ) of the sampled method at several densities, against the exact
method (:func:`sbrdf_xr.body.visibility.lit_visible_fraction`, ``method="exact"``) on the
non-convex test bodies of :mod:`sbrdf_xr.testing`, with the time of each against the exact
method's, measured in the same run; and the cost of the exact method against the number of
facets, with the fitted scaling exponent.

Every function returns a list of plain dataclass rows; :func:`markdown` renders them.
Timings are the best of ``repeat`` runs (the machines are shared and noisy); compare the
ratios of one run, not absolute times across runs.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, fields
from functools import partial
from typing import TypeVar

import numpy as np

from .. import testing
from ..body.spacecraft import Spacecraft, canx1
from ..body.visibility import lit_visible_fraction, mesh_of

__all__ = [
    "ACCURACY_BODIES",
    "CostRow",
    "ShadowRow",
    "accuracy_rows",
    "canx1_sweep_rows",
    "geometries",
    "lambertian_signal",
    "markdown",
    "pairs_profile",
    "pairs_rows",
    "scaling_rows",
]

#: Non-convex bodies of the accuracy rows: name -> factory.
ACCURACY_BODIES: dict[str, Callable[[], Spacecraft]] = {
    "l-shape": testing.l_shaped_spacecraft,
    "plate-with-fin": testing.plate_with_fin_spacecraft,
    "bus-with-panel": testing.bus_with_panel_spacecraft,
    "canx1-antennas": testing.canx1_with_antennas,
}


@dataclass(frozen=True)
class ShadowRow:
    """One shadowing setting against the exact method.

    Attributes
    ----------
    label : str
        ``"exact"``, ``"sampled density n"`` or ``"off"`` (no shadowing).
    method : str
        ``"exact"``, ``"sampled"`` or ``"off"``.
    density : int
        Sampling density (samples per facet ``density**2``); 0 for exact and off.
    bodies : str
        Bodies measured (comma-separated).
    n_geometries : int
        Sun/observer geometries per body with a non-zero signal.
    ms_per_geometry : float
        Time of the fractions per geometry [ms], summed over the bodies.
    time_ratio : float
        Time over the exact method's, same run [1].
    worst_rel_error, median_rel_error : float
        Worst and median ``|S - S_exact| / S_exact`` over bodies and geometries [1].

    Examples
    --------
    >>> from sbrdf_xr.bench.shadowing import accuracy_rows
    >>> row = accuracy_rows(densities=(2,), n_geometries=4, bodies=("l-shape",), repeat=1)[-1]
    >>> row.label, row.method, row.density, row.bodies
    ('sampled density 2', 'sampled', 2, 'l-shape')
    """

    label: str
    method: str
    density: int
    bodies: str
    n_geometries: int
    ms_per_geometry: float
    time_ratio: float
    worst_rel_error: float
    median_rel_error: float


@dataclass(frozen=True)
class CostRow:
    """Cost of one method on one body.

    Attributes
    ----------
    label : str
        What was timed.
    body : str
        Spacecraft name.
    n_facets : int
        Number of facets.
    n_geometries : int
        Geometries timed.
    ms_per_geometry : float
        Time per geometry [ms].
    ratio : float
        Time over the reference named in ``ratio_to`` (same run) [1], or the fitted
        exponent ``b`` of ``time ~ n_facets**b`` on the scaling rows.
    ratio_to : str
        What ``ratio`` is relative to.

    Examples
    --------
    >>> from sbrdf_xr.bench.shadowing import CostRow
    >>> row = CostRow("exact", "canx1", 684, 360, 0.25, 1.0, "exact")
    >>> row.n_facets * row.n_geometries  # facet-geometry pairs timed
    246240
    """

    label: str
    body: str
    n_facets: int
    n_geometries: int
    ms_per_geometry: float
    ratio: float
    ratio_to: str


def geometries(n: int = 18, seed: int = 7) -> tuple[np.ndarray, np.ndarray]:
    """Sun and observer unit vectors in the body frame, ``n`` pairs, shape (n, 3) each.

    Suns uniform on the sphere; each observer at a phase angle uniform in 5-120 degree from
    its Sun (the range of ground-based photometry), at a random azimuth about it.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.bench.shadowing import geometries
    >>> s, o = geometries(3)
    >>> s.shape, np.linalg.norm(o, axis=1).round(12).tolist()
    ((3, 3), [1.0, 1.0, 1.0])
    >>> np.degrees(np.arccos((s * o).sum(axis=1))).round(3).tolist()  # phase angles
    [58.813, 39.849, 37.019]
    """
    rng = np.random.default_rng(seed)
    s = rng.normal(size=(n, 3))
    s /= np.linalg.norm(s, axis=1, keepdims=True)
    helper = np.where(np.abs(s[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    a = np.cross(s, helper)
    a /= np.linalg.norm(a, axis=1, keepdims=True)
    b = np.cross(s, a)
    phase = np.radians(rng.uniform(5.0, 120.0, n))
    az = rng.uniform(0.0, 2 * np.pi, n)
    o = np.cos(phase)[:, None] * s + np.sin(phase)[:, None] * (
        np.cos(az)[:, None] * a + np.sin(az)[:, None] * b
    )
    return s, o


def lambertian_signal(
    craft: Spacecraft, s: np.ndarray, o: np.ndarray, fraction: np.ndarray | None
) -> np.ndarray:
    """``sum_j A_j (N_j.s)+ (N_j.o)+ f_j`` per geometry [m2] (paper 000 Eq. 3 with a constant
    sBRDF of 1 sr-1); ``fraction`` None means 1 (no shadowing).

    Examples
    --------
    A unit cube with the Sun on +x: seen along +x, the +x face gives 1 m2; seen 60 deg
    away in the xy plane, ``cos(0) cos(60 deg) = 0.5`` (the +y face is not lit).

    >>> import numpy as np
    >>> from sbrdf_xr.bench.shadowing import lambertian_signal
    >>> from sbrdf_xr.testing import cube_spacecraft
    >>> sun = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    >>> obs = np.array([[1.0, 0.0, 0.0], [0.5, np.sqrt(0.75), 0.0]])
    >>> lambertian_signal(cube_spacecraft(), sun, obs, None).round(6).tolist()
    [1.0, 0.5]
    """
    n = np.asarray(craft.mesh.face_normals)
    w = craft.mesh.area_faces * np.clip(s @ n.T, 0, None) * np.clip(o @ n.T, 0, None)
    return (w if fraction is None else w * fraction).sum(axis=-1)


_T = TypeVar("_T")


def _timed(
    func: Callable[[], _T], repeat: int, clock: Callable[[], float] = time.perf_counter
) -> tuple[_T, float]:
    t0 = clock()
    out = func()
    best = clock() - t0
    for _ in range(max(1, repeat) - 1):
        t0 = clock()
        out = func()
        best = min(best, clock() - t0)
    return out, best


def accuracy_rows(
    densities: Sequence[int] = (2, 4, 8, 16, 32),
    n_geometries: int = 18,
    bodies: Sequence[str] | None = None,
    repeat: int = 2,
    seed: int = 7,
) -> list[ShadowRow]:
    """Signal error of no shadowing and of the sampled method at each density, against the
    exact method, on the non-convex bodies of :data:`ACCURACY_BODIES`.

    Parameters
    ----------
    densities : sequence of int
        Sampled densities.
    n_geometries : int
        Sun/observer pairs per body (:func:`geometries`); pairs with a zero exact signal are
        dropped.
    bodies : sequence of str, optional
        Keys of :data:`ACCURACY_BODIES` (default all).
    repeat : int
        Timing runs (best kept).
    seed : int
        Seed of the geometries.

    Returns
    -------
    list of ShadowRow
        ``exact``, ``off`` and one row per density.

    Examples
    --------
    Four geometries on the L-shaped prism (the first call compiles the shadowing
    kernels; later ones take milliseconds):

    >>> from sbrdf_xr.bench.shadowing import accuracy_rows
    >>> rows = accuracy_rows(densities=(2,), n_geometries=4, bodies=("l-shape",), repeat=1)
    >>> [(r.label, r.n_geometries) for r in rows]
    [('exact', 4), ('off (no shadowing)', 4), ('sampled density 2', 4)]
    >>> round(rows[1].worst_rel_error, 3)  # ignoring the shadow errs by this much
    0.475
    """
    names = list(ACCURACY_BODIES) if bodies is None else list(bodies)
    s, o = geometries(n_geometries, seed)
    crafts = {name: ACCURACY_BODIES[name]() for name in names}
    for craft in crafts.values():  # compile and fill the per-body caches outside the timings
        lit_visible_fraction(craft, s[:1], o[:1])
        lit_visible_fraction(craft, s[:1], o[:1], method="sampled", density=2)
    exact_t = 0.0
    ref: dict[str, np.ndarray] = {}
    keep: dict[str, np.ndarray] = {}
    for name, craft in crafts.items():
        f, t = _timed(partial(lit_visible_fraction, craft, s, o), repeat)
        exact_t += t
        sig = lambertian_signal(craft, s, o, f)
        keep[name] = sig > 1e-12 * craft.mesh.area.sum()
        ref[name] = sig
    n_used = min(int(k.sum()) for k in keep.values())
    label = ", ".join(names)

    def row(lbl: str, method: str, density: int, t: float, errs: list[np.ndarray]) -> ShadowRow:
        e = np.concatenate(errs)
        return ShadowRow(
            lbl,
            method,
            density,
            label,
            n_used,
            1e3 * t / len(s),
            t / exact_t,
            float(e.max()),
            float(np.median(e)),
        )

    rows = [row("exact", "exact", 0, exact_t, [np.zeros(1)])]
    errs = [
        np.abs(lambertian_signal(c, s, o, None) - ref[n])[keep[n]] / ref[n][keep[n]]
        for n, c in crafts.items()
    ]
    rows.append(row("off (no shadowing)", "off", 0, 0.0, errs))
    for d in densities:
        total = 0.0
        errs = []
        for name, craft in crafts.items():
            f, t = _timed(
                partial(lit_visible_fraction, craft, s, o, method="sampled", density=d), repeat
            )
            total += t
            sig = lambertian_signal(craft, s, o, f)
            errs.append(np.abs(sig - ref[name])[keep[name]] / ref[name][keep[name]])
        rows.append(row(f"sampled density {d}", "sampled", d, total, errs))
    return rows


def canx1_sweep_rows(n_attitudes: int = 360, density: int = 4, repeat: int = 2) -> list[CostRow]:
    """Exact against sampled shadowing of a CanX-1 rotation sweep, in the same run.

    The Sun along +x, the observer at 30 degree phase in the xy plane, the body spinning
    about z through ``n_attitudes`` equal steps (a light-curve sweep; directions rotated
    into the body frame).  The ``ratio`` of the sampled row is its time over the exact
    row's; the ``off`` row gives the largest relative change of the signal that shadowing
    makes (in its ``ratio``), the sampled row's ``ratio_to`` also carries its worst
    relative signal error against exact.

    Examples
    --------
    >>> from sbrdf_xr.bench.shadowing import canx1_sweep_rows
    >>> rows = canx1_sweep_rows(n_attitudes=4, density=2, repeat=1)
    >>> [(r.label, r.n_facets, r.n_geometries) for r in rows]
    [('exact', 684, 4), ('sampled density 2', 684, 4), ('off (no shadowing)', 684, 4)]
    """
    craft = canx1()
    ang = np.linspace(0.0, 2 * np.pi, n_attitudes, endpoint=False)
    c, sn = np.cos(ang), np.sin(ang)
    sun = np.array([1.0, 0.0, 0.0])
    obs = np.array([np.cos(np.radians(30.0)), np.sin(np.radians(30.0)), 0.0])

    def body(v: np.ndarray) -> np.ndarray:  # inverse rotation about z by ang
        return np.column_stack([c * v[0] + sn * v[1], -sn * v[0] + c * v[1], np.full_like(c, v[2])])

    s, o = body(sun), body(obs)
    lit_visible_fraction(craft, s[:2], o[:2])
    lit_visible_fraction(craft, s[:2], o[:2], method="sampled", density=density)
    fe, te = _timed(lambda: lit_visible_fraction(craft, s, o), repeat)
    fs, ts = _timed(
        lambda: lit_visible_fraction(craft, s, o, method="sampled", density=density), repeat
    )
    se, ss, s0 = (lambertian_signal(craft, s, o, f) for f in (fe, fs, None))
    err = float(np.max(np.abs(ss - se) / se))
    off = float(np.max(np.abs(s0 - se) / se))
    n = craft.n_facets
    return [
        CostRow("exact", craft.name, n, n_attitudes, 1e3 * te / n_attitudes, 1.0, "exact"),
        CostRow(
            f"sampled density {density}",
            craft.name,
            n,
            n_attitudes,
            1e3 * ts / n_attitudes,
            ts / te,
            f"exact (worst signal error {err:.2e})",
        ),
        CostRow(
            "off (no shadowing)",
            craft.name,
            n,
            n_attitudes,
            0.0,
            off,
            "largest |S_off - S_exact| / S_exact",
        ),
    ]


def _rotation(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Sun along +x, observer at 30 deg phase, CanX-1 spun about z in n steps (body frame)."""
    ang = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    c, sn = np.cos(ang), np.sin(ang)
    p = np.radians(30.0)
    s = np.column_stack([c, -sn, np.zeros(n)])
    o = np.column_stack([c * np.cos(p) + sn * np.sin(p), -sn * np.cos(p) + c * np.sin(p), 0 * c])
    return s, o


def pairs_rows(n_geometries: int = 360, n_sweep: int = 10_000, repeat: int = 3) -> list[CostRow]:
    """The exact method with its pair table against the grid kernel it replaced, same run.

    Rows: microseconds per geometry of :func:`~sbrdf_xr.body.visibility.lit_visible_fraction`
    on CanX-1, ``n_geometries`` of the :func:`canx1_sweep_rows` rotation batched in one
    call, by the grid kernel (``before``: a body whose cache holds no pair table) and by the
    pair table (``after``, its ``ratio`` over ``before``); the one-off cost of building the
    table; and ``simulate`` of ``n_sweep`` random attitudes of the ``canx1-rotation`` scene
    with exact shadowing over the same sweep without it, by each kernel.  Best of
    ``repeat``, the two kernels timed in turns so that a load falls on both alike.

    Examples
    --------
    Seconds even for a few geometries (the sweeps plan and compute CanX-1); not run here:

    >>> from sbrdf_xr.bench.shadowing import pairs_rows
    >>> rows = pairs_rows(n_geometries=8, n_sweep=100, repeat=1)  # doctest: +SKIP
    >>> [r.label for r in rows][:2]  # doctest: +SKIP
    ['grid kernel (before)', 'pair table (after)']
    """
    from .. import geometry
    from ..engine import builtin_scene
    from ..engine.run import simulate

    s, o = _rotation(n_geometries)
    grid, table = canx1(), canx1()
    mesh_of(grid)[1]["exact:pairs"] = None  # a cached None: no table, the grid kernel
    lit_visible_fraction(grid, s[:2], o[:2])
    t0 = time.perf_counter()
    lit_visible_fraction(table, s[:2], o[:2])  # builds the table (and compiles)
    build = time.perf_counter() - t0
    t0 = time.perf_counter()
    lit_visible_fraction(canx1(), s[:2], o[:2])  # the table alone, compiled
    build = min(build, time.perf_counter() - t0)
    tg = tp = np.inf
    cpu = time.process_time
    for _ in range(max(1, repeat)):
        tg = min(tg, _timed(partial(lit_visible_fraction, grid, s, o), 1, cpu)[1])
        tp = min(tp, _timed(partial(lit_visible_fraction, table, s, o), 1, cpu)[1])
    n = table.n_facets
    us = 1e3 / n_geometries  # ms per geometry per second
    rows = [
        CostRow("grid kernel (before)", table.name, n, n_geometries, us * tg, 1.0, "before"),
        CostRow("pair table (after)", table.name, n, n_geometries, us * tp, tp / tg, "before"),
        CostRow(
            "pair table build (once per body)",
            table.name,
            n,
            0,
            1e3 * build,
            build / tg,
            "before, all geometries",
        ),
    ]
    base = builtin_scene("canx1-rotation").with_options(
        attitudes=geometry.uniform_attitudes(n_sweep, seed=3), attitude_angle=None
    )
    plans = {
        e: base.with_options(effects=e, outputs=("signal",)).plan()
        for e in (("sunlight",), ("sunlight", "shadowing"))
    }
    cache = mesh_of(plans[("sunlight", "shadowing")].spacecraft)[1]
    times: dict[str, float] = {}
    for label in ("off", "grid", "pairs"):
        plan = plans[("sunlight",)] if label == "off" else plans[("sunlight", "shadowing")]
        if label == "grid":
            cache["exact:pairs"] = None
        elif label == "pairs":
            cache.pop("exact:pairs", None)
        simulate(plan, lazy=False)  # warm: tables, caches
        times[label] = min(
            _timed(partial(simulate, plan, lazy=False), 1)[1]
            for _ in range(max(1, repeat if label != "grid" else 1))
        )
    for label in ("grid", "pairs"):
        rows.append(
            CostRow(
                f"{n_sweep} random attitudes simulated, shadowing by {label}",
                table.name,
                n,
                n_sweep,
                1e3 * times[label] / n_sweep,
                times[label] / times["off"],
                "the same sweep without shadowing",
            )
        )
    return rows


def pairs_profile(n_geometries: int = 360, repeat: int = 5) -> list[CostRow]:
    """Where the pair kernel's time goes on CanX-1: CPU microseconds per geometry of each
    step of :data:`~sbrdf_xr.kernels.shadow_pairs.STAGES` (the kernel run to the end of a
    step, less the run to the end of the one before), for the :func:`canx1_sweep_rows`
    rotation and for random geometries (:func:`geometries`), ``n_geometries`` batched.

    Each row's ``ms_per_geometry`` is the step's time [ms] and its ``ratio`` its share of
    the whole kernel.  Best of ``repeat`` runs, the stages timed in turns.

    Examples
    --------
    >>> from sbrdf_xr.bench.shadowing import pairs_profile
    >>> rows = pairs_profile(n_geometries=8, repeat=1)
    >>> [r.label for r in rows[:4]]
    ['rotation: facing', 'rotation: walk', 'rotation: shadows', 'rotation: union']
    >>> round(sum(r.ratio for r in rows[:4]), 6)
    1.0
    """
    from ..body.occluders import pair_table
    from ..body.visibility import exact_frames
    from ..kernels.shadow_pairs import STAGES, pairs_kernel

    craft = canx1()
    mesh, cache = mesh_of(craft)
    frames = exact_frames(mesh, cache)
    pairs = pair_table(frames, cache)
    if pairs is None:  # pragma: no cover - CanX-1 is far under the table's bound
        return []
    occ = pairs["occluders"]
    normals = np.ascontiguousarray(mesh.face_normals, dtype=np.float64)
    head = (normals, frames["N"], frames["E1"], frames["E2"], frames["T2"], *pairs["table"])
    rows = []
    for name, (s, o) in {
        "rotation": _rotation(n_geometries),
        "random": geometries(n_geometries, seed=7),
    }.items():
        dirs = np.ascontiguousarray(np.stack([s, o], axis=1))
        args = (*head, occ["normal"], occ["open"], dirs)
        pairs_kernel(*args)  # compiled, warm
        best = [np.inf] * len(STAGES)
        for _ in range(max(1, repeat)):
            for k in range(len(STAGES)):
                upto = (*args, k + 1)  # the kernel stopped after step k + 1
                t = _timed(partial(pairs_kernel, *upto), 1, time.process_time)[1]
                best[k] = min(best[k], t)
        steps = np.diff([0.0, *best])
        for label, t in zip(STAGES, steps, strict=True):
            rows.append(
                CostRow(
                    f"{name}: {label}",
                    craft.name,
                    craft.n_facets,
                    n_geometries,
                    1e3 * max(float(t), 0.0) / n_geometries,
                    max(float(t), 0.0) / max(float(steps.clip(0.0).sum()), 1e-300),
                    "the whole kernel (CPU time)",
                )
            )
    return rows


def scaling_rows(
    subdivisions: Sequence[int] = (1, 2, 3, 4, 5),
    n_geometries: int = 6,
    repeat: int = 1,
    seed: int = 7,
    compare_density: int | None = 4,
) -> list[CostRow]:
    """Exact-method time per geometry against the facet count, on CanX-1 with antennas
    subdivided (732, 2928, 11712, 46848, 187392 facets).

    Each exact row's ``ratio`` is the local exponent from the previous count; the last
    exact row's the exponent ``b`` of the least-squares fit ``time ~ n_facets**b`` over all
    counts.  With ``compare_density``, a sampled row follows each exact row, its ``ratio``
    its time over the exact time at that count (same run).

    Examples
    --------
    One facet count (no exponent to fit) and two geometries:

    >>> from sbrdf_xr.bench.shadowing import scaling_rows
    >>> rows = scaling_rows(subdivisions=(1,), n_geometries=2, compare_density=None)
    >>> [(r.label, r.body, r.n_facets, r.ratio_to) for r in rows]
    [('exact', 'canx1-antennas', 732, 'local exponent')]
    """
    s, o = geometries(n_geometries, seed)
    rows: list[CostRow] = []
    pts: list[tuple[int, float]] = []
    for k in subdivisions:
        craft = testing.canx1_with_antennas(subdivisions=k)
        lit_visible_fraction(craft, s[:1], o[:1])  # caches (supporting planes, frames)
        _, t = _timed(partial(lit_visible_fraction, craft, s, o), repeat)
        ms = 1e3 * t / n_geometries
        local = (np.log(ms / pts[-1][1]) / np.log(craft.n_facets / pts[-1][0])) if pts else np.nan
        pts.append((craft.n_facets, ms))
        rows.append(
            CostRow(
                "exact",
                craft.name,
                craft.n_facets,
                n_geometries,
                ms,
                float(local),
                "local exponent",
            )
        )
        if compare_density:
            d = compare_density
            lit_visible_fraction(craft, s[:1], o[:1], method="sampled", density=d)
            _, ts = _timed(
                partial(lit_visible_fraction, craft, s, o, method="sampled", density=d), repeat
            )
            rows.append(
                CostRow(
                    f"sampled density {d}",
                    craft.name,
                    craft.n_facets,
                    n_geometries,
                    1e3 * ts / n_geometries,
                    ts / t,
                    "exact at this facet count",
                )
            )
    if len(pts) > 1:
        x, y = np.log([p[0] for p in pts]), np.log([p[1] for p in pts])
        b = float(np.polyfit(x, y, 1)[0])
        last = max(i for i, r in enumerate(rows) if r.label == "exact")
        r = rows[last]
        rows[last] = CostRow(
            r.label,
            r.body,
            r.n_facets,
            r.n_geometries,
            r.ms_per_geometry,
            b,
            "fitted exponent over all counts",
        )
    return rows


def markdown(rows: Sequence[ShadowRow | CostRow]) -> str:
    """The rows as a markdown table (floats to 3 significant digits).

    Examples
    --------
    >>> from sbrdf_xr.bench.shadowing import CostRow, markdown
    >>> print(markdown([CostRow("exact", "canx1", 684, 360, 0.2512, 1.0, "exact")]))
    | label | body | n_facets | n_geometries | ms_per_geometry | ratio | ratio_to |
    |---|---|---|---|---|---|---|
    | exact | canx1 | 684 | 360 | 0.251 | 1 | exact |
    """
    if not rows:
        return ""
    names = [f.name for f in fields(rows[0])]
    out = ["| " + " | ".join(names) + " |", "|" + "---|" * len(names)]
    for r in rows:
        vals = [f"{v:.3g}" if isinstance(v, float) else str(v) for v in asdict(r).values()]
        out.append("| " + " | ".join(vals) + " |")
    return "\n".join(out)
