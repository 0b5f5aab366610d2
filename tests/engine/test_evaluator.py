"""Tests of sbrdf_xr.engine.evaluator: a compiled plan as a function of the directions.

The claim is bit-identity with ``simulate`` (``np.array_equal``, no tolerance): the
evaluator runs the same compiled kernel on the same arrays and the same ``finish``.
Beside ``simulate`` (whose blocks now run through the evaluator too) every case is
also compared with the effects' own path (``block_outputs(..., fast=False)``: the
``reflected`` sums through ``fused_sums``), which shares nothing prepared with it.
"""

from __future__ import annotations

import copy

import cloudpickle
import numpy as np
import pytest

from sbrdf_xr import catalog, geometry
from sbrdf_xr import testing as T
from sbrdf_xr.engine import Evaluator, Scene, compile_evaluator, simulate
from sbrdf_xr.engine.evaluator import block_outputs, evaluator_of
from sbrdf_xr.errors import DirectionError, SceneError, StalePlanError


def _lobe_scene(spacecraft, **kw):
    mats = {T.TEST_SPACECRAFT_MATERIAL: T.make_material(n_wavelength=11)}
    return Scene(spacecraft, materials=mats, **kw)


def _pairs(n, seed):
    rng = np.random.default_rng(seed)
    s, o = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    o[: n // 4] = s[: n // 4]  # back-scatter (beta = 0) among them
    return s / np.linalg.norm(s, axis=1)[:, None], o / np.linalg.norm(o, axis=1)[:, None]


def _assert_identical(out, cube, names):
    for k in names:
        assert np.array_equal(out[k], cube[k].values), k


PAIRS = _pairs(24, 1)  # as given to the scenes (which normalise them, as the evaluator does)


def _cases():
    s, o = PAIRS
    cube = T.cube_spacecraft(1.0, subdivisions=2)
    ell = T.l_shaped_spacecraft()
    return {
        "cube, spectra": _lobe_scene(cube, to_sun=s, to_observer=o),
        "cube, per material": _lobe_scene(
            cube, to_sun=s, to_observer=o, outputs=("signal", "area", "per_material")
        ),
        "cube, bands only": Scene(
            cube,
            materials={T.TEST_SPACECRAFT_MATERIAL: catalog.load("lambertian-grey-50")},
            to_sun=s,
            to_observer=o,
            outputs=("band_signal", "area"),
            bands=("V", "R", "I"),
        ),
        "L, shadowing off": _lobe_scene(ell, to_sun=s, to_observer=o, merge=False),
        "L, exact shadowing": _lobe_scene(
            ell, to_sun=s, to_observer=o, effects=("sunlight", "shadowing")
        ),
        "L, sampled shadowing": _lobe_scene(
            ell,
            to_sun=s,
            to_observer=o,
            effects=("sunlight", "shadowing"),
            shadow_method="sampled",
        ),
        "cube, float32 cubic": _lobe_scene(
            cube, to_sun=s, to_observer=o, dtype="float32", method="cubic"
        ),
    }


CASES = _cases()


# the float32 cubic kernel compiles for ~40 s on a fresh machine: run with -m slow
@pytest.mark.parametrize(
    "name",
    [pytest.param(n, marks=pytest.mark.slow) if n == "cube, float32 cubic" else n for n in CASES],
)
def test_pairs_bit_identical_to_simulate(name):
    scene = CASES[name]
    plan = scene.plan()
    cube = simulate(plan)
    ev = Evaluator(plan)
    s, o = PAIRS
    out = ev(s, o)
    _assert_identical(out, cube, plan.output_names)
    # and to the effects' own path, which prepares nothing
    slow = block_outputs(plan, plan.geometry.block(slice(None)), fast=False)
    for k in plan.output_names:
        assert np.array_equal(out[k], slow[k]), k
    # one geometry at a time: the same numbers, no leading axis
    for g in (0, 5, 23):
        one = ev(s[g], o[g])
        for k in plan.output_names:
            assert np.array_equal(one[k], cube[k].values[g]), (k, g)


def test_fast_path_where_the_plan_allows():
    assert Evaluator(CASES["cube, spectra"].plan()).fast
    assert Evaluator(CASES["cube, bands only"].plan()).fast
    assert not Evaluator(CASES["L, exact shadowing"].plan()).fast  # per-facet fractions


@pytest.mark.parametrize("dtype", ["float64", "float32"])
def test_attitudes_bit_identical_to_the_grid(dtype):
    q = geometry.uniform_attitudes(40, seed=3)  # > 16 per thread: simulate splits blocks
    scene = _lobe_scene(
        T.cube_spacecraft(1.0, subdivisions=2),
        attitudes=q,
        phase_angles=[0.0, 35.0, 120.0, 180.0],
        dtype=dtype,
    )
    plan = scene.plan()
    cube = simulate(plan)
    g = plan.geometry
    out = Evaluator(plan)(g.sun_ref, g.obs_ref, attitudes=q)
    _assert_identical(out, cube, plan.output_names)
    one = Evaluator(plan)(g.sun_ref[1], g.obs_ref[1], attitudes=q[7])  # no leading axes
    for k in plan.output_names:
        assert np.array_equal(one[k], cube[k].values[7, 1]), k


def test_compiled_from_the_scene_keeps_every_term():
    """A one-geometry plan keeps only the terms it lights and shows; the scene's
    evaluator (directions over the whole sphere) keeps them all and agrees bit for bit
    with simulate of a scene at other directions."""
    s, o = _pairs(30, 7)
    base = _lobe_scene(T.l_shaped_spacecraft(), to_sun=s[:1], to_observer=o[:1])
    ev = compile_evaluator(base)
    assert ev.plan.terms.size > base.plan().terms.size
    cube = simulate(base.with_options(to_sun=s, to_observer=o))
    _assert_identical(ev(s, o), cube, base.plan().output_names)


def test_bad_directions_raise_named_errors():
    ev = Evaluator(CASES["cube, spectra"].plan())
    x = [1.0, 0.0, 0.0]
    for bad in ([1.0, 0.0], [[1.0, 0, 0, 0]], np.zeros((0, 3)), [[[1.0, 0, 0]]], "x"):
        with pytest.raises(DirectionError, match="to_sun"):
            ev(bad, x)
    with pytest.raises(DirectionError, match=r"length 1\.1"):
        ev(x, [1.1, 0.0, 0.0])
    with pytest.raises(DirectionError, match="NaN"):
        ev([np.nan, 0.0, 1.0], x)
    with pytest.raises(DirectionError, match="rows"):
        ev([x, x], [x])
    with pytest.raises(DirectionError, match="attitudes"):
        ev(x, x, attitudes=[0.0, 0.0, 0.0, 2.0])
    with pytest.raises(DirectionError, match="sun_scale"):
        ev(x, x, sun_scale=[1.5])
    with pytest.raises(SceneError, match="sources"):
        ev(x, x, sources={"to_earth": [x]})


def test_changed_tables_or_terms_are_detected():
    plan = _lobe_scene(T.cube_spacecraft(), to_sun=[[1.0, 0, 0]], to_observer=[[1.0, 0, 0]]).plan()
    ev = Evaluator(plan)
    ev([1.0, 0, 0], [1.0, 0, 0])
    ev.verify()
    tables = plan.tables
    object.__setattr__(
        plan, "tables", tables._replace(values=tuple(v.copy() for v in tables.values))
    )
    with pytest.raises(StalePlanError, match="changed"):
        ev([1.0, 0, 0], [1.0, 0, 0])
    object.__setattr__(plan, "tables", tables)
    ev([1.0, 0, 0], [1.0, 0, 0])  # as compiled again
    # a change in place is found by the sampled content
    values = tables.values[0]
    was = values.flags.writeable
    values.flags.writeable = True
    saved = values.copy()
    try:
        values[...] = values * 2.0 + 1.0
        if not was:  # read-only as compiled: the per-call identity check already sees it
            with pytest.raises(StalePlanError):
                ev.check()
        with pytest.raises(StalePlanError):
            ev.verify()
    finally:
        values[...] = saved
        values.flags.writeable = was
    ev.verify()


def test_plan_with_its_evaluator_pickles():
    """The evaluator is not sent with its plan (its kernel entry point cannot be): the
    copy compiles its own, with the same outputs."""
    plan = CASES["cube, spectra"].plan()
    ev = evaluator_of(plan)
    copy = cloudpickle.loads(cloudpickle.dumps(plan))  # as Dask sends it
    assert copy.cache.get("evaluator") is None
    x = PAIRS[0][:3], PAIRS[1][:3]
    a, b = ev(*x), Evaluator(copy)(*x)
    for k in plan.output_names:
        assert np.array_equal(a[k], b[k])


def test_body_with_parts_is_refused():
    sc = T.box_with_plate_spacecraft(parts=True)
    mats = {m: catalog.load("lambertian-grey-50") for m in sc.materials}
    plan = Scene(sc, materials=mats, to_sun=[[1.0, 0, 0]], to_observer=[[1.0, 0, 0]]).plan()
    with pytest.raises(SceneError, match="turning parts"):
        Evaluator(plan)


@pytest.mark.slow
def test_canx1_single_geometry_bit_identical():
    from sbrdf_xr.engine import builtin_scene

    rot = builtin_scene("canx1-rotation")
    for k in (0, 91, 200):
        one = rot.with_options(attitudes=np.asarray(rot.attitudes)[k : k + 1], attitude_angle=None)
        plan = one.plan()
        cube = simulate(plan)
        g = plan.geometry
        out = Evaluator(plan)(g.sun_ref[0], g.obs_ref[0], attitudes=g.attitudes[0])
        for name in plan.output_names:
            assert np.array_equal(out[name], cube[name].values[0, 0]), name
        slow = block_outputs(plan, g.block(slice(None)), fast=False)
        for name in plan.output_names:
            assert np.array_equal(out[name], slow[name][0, 0]), name


@pytest.mark.parametrize("name", ["cube, spectra", "cube, per material", "cube, bands only"])
def test_one_geometry_path_bit_identical_whatever_the_vector_type(name):
    """A single body-frame geometry runs through one compiled call (angles, look-up,
    sums and Eq. 4 together); lists, tuples and float32 rows give the bits of the
    general path and of simulate."""
    plan = CASES[name].plan()
    ev = Evaluator(plan)
    assert ev._lean is not None
    cube = simulate(plan)
    s, o = PAIRS
    for g in (0, 7, 19):
        general = ev(s[g : g + 1], o[g : g + 1])  # (1, 3): the general path
        for given in ((s[g], o[g]), (s[g].tolist(), tuple(o[g].tolist()))):
            one = ev(*given)
            for k in plan.output_names:
                assert one[k].shape == cube[k].values[g].shape, k
                assert np.array_equal(one[k], cube[k].values[g]), (k, g)
                assert np.array_equal(one[k], general[k][0]), (k, g)
        s32 = s[g].astype(np.float32)
        one = ev(s32, o[g])
        ref = ev(s32[None].astype(np.float64), o[g : g + 1])
        for k in plan.output_names:
            assert np.array_equal(one[k], ref[k][0]), k


def test_one_geometry_path_raises_the_named_errors():
    ev = Evaluator(CASES["cube, spectra"].plan())
    x = [1.0, 0.0, 0.0]
    for bad in (["a", 0.0, 0.0], [[1.0], [0.0], [0.0]], np.array([[1.0], [0.0], [0.0]])):
        with pytest.raises(DirectionError, match="to_sun"):
            ev(bad, x)
    with pytest.raises(DirectionError, match=r"length 1\.1"):
        ev(x, (1.1, 0.0, 0.0))
    with pytest.raises(DirectionError, match="NaN"):
        ev(x, np.array([np.nan, 0.0, 1.0]))
    with pytest.raises(DirectionError, match="NaN"):
        ev([np.inf, 0.0, 1.0], x)
    plan = ev.plan
    terms = plan.terms
    object.__setattr__(plan, "terms", copy.copy(terms))  # other terms: stale
    try:
        with pytest.raises(StalePlanError, match="changed"):
            ev(x, x)
    finally:
        object.__setattr__(plan, "terms", terms)
    assert float(ev(x, x)["area"]) > 0.0
