"""Tests of sbrdf_xr.engine.effects: the registry runs the engine.

Every effect is one entry of :data:`sbrdf_xr.engine.effects.EFFECTS`; the rest of the engine
reads the entries and names no effect.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import numpy as np
import pytest

from sbrdf_xr import testing as T
from sbrdf_xr.engine import Scene, simulate
from sbrdf_xr.engine.effects import EFFECTS, OUTPUTS, SCENE_EFFECTS, scene_effects
from sbrdf_xr.materials.schema import lambertian

ENGINE = Path(__file__).resolve().parents[2] / "sbrdf_xr" / "engine"


def _docstrings(tree: ast.AST) -> set[int]:
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                out.add(id(body[0].value))
    return out


def _words(text: str) -> set[str]:
    return set(re.findall(r"[a-z]+", text.lower()))


def effect_mentions(path: Path, names: set[str], root: Path = ENGINE) -> list[str]:
    """Every string (but docstrings) and every identifier of a module that holds one of
    ``names`` as a word (``"earthshine"``, ``f"... self-shadowing ..."``,
    ``signal_earthshine``, ``THERMAL_NEGLIGIBLE``), as ``file:line: text``, in the
    order of the source."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docs = _docstrings(tree)
    found = []
    for node in ast.walk(tree):
        texts: list[str] = []
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docs:
            texts = [node.value]
        elif isinstance(node, ast.Name):
            texts = [node.id]
        elif isinstance(node, ast.Attribute):
            texts = [node.attr]
        elif isinstance(node, ast.FunctionDef | ast.ClassDef | ast.AsyncFunctionDef):
            texts = [node.name]
        elif isinstance(node, ast.arg | ast.keyword) and node.arg:
            texts = [node.arg]
        elif isinstance(node, ast.alias):
            texts = [node.name, node.asname or ""]
        for text in texts:
            if _words(text) & names:
                found.append((node.lineno, node.col_offset, text))
    rel = path.relative_to(root)
    return [f"{rel}:{line}: {text!r}" for line, _, text in sorted(found)]


def test_no_engine_module_but_the_effects_names_an_effect():
    """Planning, the contributing mask, the number of sources, the outputs, the geometry of
    the sources and the scene's checks all come from the entries: outside
    ``engine/effects/`` no code (docstrings and comments aside) holds an effect's name."""
    files = [
        p for p in sorted(ENGINE.rglob("*.py")) if "effects" not in p.relative_to(ENGINE).parts
    ]
    assert len(files) >= 10
    found = [hit for p in files for hit in effect_mentions(p, set(EFFECTS))]
    assert not found, "effects named outside sbrdf_xr/engine/effects/:\n" + "\n".join(found)


def test_the_check_sees_a_name_in_code_not_in_docs(tmp_path):
    f = tmp_path / "m.py"
    f.write_text(
        '"""Earthshine in a docstring is fine."""\n'
        "def f(scene):\n"
        '    """And thermal here."""\n'
        "    # earthshine in a comment\n"
        '    return "earthshine" in scene.effects, scene.THERMAL_LIMIT, f"self-shadowing {scene}"\n'
    )
    hits = [h.split(": ", 1)[1] for h in effect_mentions(f, set(EFFECTS), tmp_path)]
    assert hits == ["'earthshine'", "'THERMAL_LIMIT'", "'self-shadowing '"]


def grey_box(**kw) -> Scene:
    grey = lambertian(0.5, [500.0, 600.0, 700.0], material=T.TEST_SPACECRAFT_MATERIAL)
    return Scene(T.cube_spacecraft(1.0), {T.TEST_SPACECRAFT_MATERIAL: grey}, **kw)


def test_every_entry_is_complete_and_its_outputs_are_declared_once():
    for name, e in EFFECTS.items():
        assert e.name == name and e.title and e.description
        assert all(v in OUTPUTS for v in e.outputs)
        assert {o.name for o in e.declares} <= set(e.outputs)
        assert set(e.band) <= {"signal"} | {o.name for o in e.declares}
        assert (name in SCENE_EFFECTS) == (e.when != "automatic")
        assert e.reflects == (e.source is not None and e.source != "facets")
        assert not (e.per_facet and e.contribute), "a per-facet effect changes the others"
    declared = [o.name for e in EFFECTS.values() for o in e.declares]
    assert len(declared) == len(set(declared))
    assert [e.name for e in scene_effects(())] == [
        n for n, e in EFFECTS.items() if e.when != "asked"
    ]


def test_a_source_is_a_kernel_pass_and_lights_terms():
    """The Earth behind the observer lights the face the Sun does not: that face is kept,
    and the work estimate counts one kernel pass per reflected source."""
    x, y = [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]]
    sun = grey_box(to_sun=x, to_observer=x)
    both = grey_box(to_sun=x, to_observer=x, to_earth=x, effects=("sunlight", "earthshine"))
    assert both.plan().terms.size == sun.plan().terms.size == 1
    assert both.plan().estimate.multiply_adds == 2 * sun.plan().estimate.multiply_adds
    unseen = grey_box(to_sun=x, to_observer=y, to_earth=y, effects=("sunlight", "earthshine"))
    plan = unseen.plan()
    np.testing.assert_array_equal(plan.terms.normal, [[0.0, 1.0, 0.0]])
    cube = simulate(plan)
    assert float(cube.signal.isel(geometry=0, wavelength=0)) == 0.0
    assert float(cube.signal_earthshine.isel(geometry=0, wavelength=0)) > 0.0


def test_plan_attributes_name_the_effects_that_run():
    x = [[1.0, 0.0, 0.0]]
    plan = grey_box(to_sun=x, to_observer=x, to_earth=x, effects=("earthshine",)).plan()
    assert plan.earthshine and plan.sunlight and not plan.thermal and not plan.shadowing
    assert [e.name for e in plan.active_effects] == list(plan.effects)
    with pytest.raises(AttributeError, match="moonshine"):
        _ = plan.moonshine
