"""The engine: what to simulate (a :class:`Scene`), its plan, and running it into a cube.

DESIGN.md principle 3: a scene is compiled into a :class:`~sbrdf_xr.engine.plan.Plan`
that states every step that will run and every step skipped, and why; only the
effects a scene calls for are simulated.

Modules
-------
``knobs``
    Every numerical knob of a simulation, and the presets, in one table.
``effects``
    The effects a simulation can include, one module and one registry entry each, and
    the outputs of a cube; the rest of the engine reads the entries.
``sweep``
    The geometry of a sweep: where the Sun and the observer are, in the body frame.
``scene``, ``scene_file``, ``schema``, ``attitude_table`` and ``builtin``
    :class:`Scene`, scene files (TOML), every key of a scene file (its type, default and
    meaning, and the reference rendered from them), the attitude tables that scene files
    and ``Scene(attitude=...)`` share, and the built-in scenes.
``plan``, ``stages`` and ``spectral``
    The plan and its stages.
``articulation``
    Bodies with parts that turn: each rigid group evaluated in its own frame.
``reuse``
    What a plan computes from the tables, the spacecraft and the knobs alone (packed
    tables, merged facets), kept by content for the next plans.
``fingerprint``
    The content fingerprint of a scene (:func:`scene_fingerprint`), stored in its cubes.
``views``
    What the plan's stages and the effects read of a scene and a plan (protocols), and
    the facet terms.
``evaluator``
    A compiled plan as a function of the directions: numpy in, numpy out, for small
    calls (one geometry, a fit's inner loop).
``run``
    Executing a plan: blocks of geometries through the kernel into an xarray cube
    (:func:`simulate`; :func:`sbrdf_xr.store.write` writes it).
"""

from ..errors import SceneError, renamed_attributes
from . import (
    articulation,
    attitude_table,
    builtin,
    effects,
    evaluator,
    fingerprint,
    knobs,
    plan,
    reuse,
    run,
    scene,
    scene_file,
    schema,
    spectral,
    stages,
    sweep,
    views,
)
from .articulation import Articulation, BoundGroup
from .attitude_table import attitudes_from_table
from .builtin import (
    STARLINK_STAND_INS,
    builtin_scene,
    builtin_scenes,
    resolve_scene,
    starlink_materials,
)
from .effects import SPECTRAL_OUTPUTS, BlockInputs, Effect, Output, finish, reflected
from .evaluator import Evaluator, compile_evaluator
from .fingerprint import scene_fingerprint
from .knobs import KNOBS, PRESETS, Knob, apply_preset, check_knob, knob_table
from .plan import Estimate, Plan, PlannedOutput, Terms, compile_plan
from .run import IN_PROCESS_BYTES, run_block, simulate
from .scene import EFFECTS, OUTPUTS, Scene
from .scene_file import (
    MAX_SCENE_COUNT,
    MAX_SHADOW_DENSITY,
    load_material_specs,
    load_scene,
    scene_from_dict,
    scene_material_tables,
)
from .sweep import QUATERNION_COMPONENTS, GridGeometry, PairGeometry

__all__ = [
    "EFFECTS",
    "IN_PROCESS_BYTES",
    "KNOBS",
    "MAX_SCENE_COUNT",
    "MAX_SHADOW_DENSITY",
    "OUTPUTS",
    "PRESETS",
    "QUATERNION_COMPONENTS",
    "SPECTRAL_OUTPUTS",
    "STARLINK_STAND_INS",
    "Articulation",
    "BlockInputs",
    "BoundGroup",
    "Effect",
    "Estimate",
    "Evaluator",
    "GridGeometry",
    "Knob",
    "Output",
    "PairGeometry",
    "Plan",
    "PlannedOutput",
    "Scene",
    "SceneError",
    "Terms",
    "apply_preset",
    "articulation",
    "attitude_table",
    "attitudes_from_table",
    "builtin",
    "builtin_scene",
    "builtin_scenes",
    "check_knob",
    "compile_evaluator",
    "compile_plan",
    "effects",
    "evaluator",
    "fingerprint",
    "finish",
    "knob_table",
    "knobs",
    "load_material_specs",
    "load_scene",
    "plan",
    "reflected",
    "resolve_scene",
    "reuse",
    "run",
    "run_block",
    "scene",
    "scene_file",
    "scene_fingerprint",
    "scene_from_dict",
    "scene_material_tables",
    "schema",
    "simulate",
    "spectral",
    "stages",
    "starlink_materials",
    "sweep",
    "views",
]

#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(__name__, globals(), {"material_tables": "scene_material_tables"})
