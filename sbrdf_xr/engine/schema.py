"""The scene-file schema: every key of a TOML scene, its type, default and meaning, once.

:mod:`sbrdf_xr.engine.scene_file` checks a file against these tables, and
:func:`reference` renders them as the scene-file reference of the user guide
(``docs/guide/scene-file-reference.md``).  Nothing is written twice: a key that is a
numerical knob takes its TOML type,
default, domain and meaning from the knob table (:data:`sbrdf_xr.engine.knobs.KNOBS`); a key
that is a field of :class:`~sbrdf_xr.engine.Scene` takes its default from the field; the
values of ``effects`` and ``outputs`` come from the effect registry
(:data:`sbrdf_xr.engine.effects.EFFECTS`), and the attitude laws of ``[observation.attitude]``
from :data:`sbrdf_xr.observing.attitude.ATTITUDE_LAWS`.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from ..observing.observe import OBSERVATION_KEYS as _OBSERVATION
from .attitude_table import ATTITUDE_TABLE_KEYS as _ATTITUDE
from .effects import DEFAULT_EFFECTS, EFFECTS, SCENE_EFFECTS, SCENE_OUTPUTS
from .knobs import KNOBS
from .scene import Scene

__all__ = [
    "ATTITUDE_KEYS",
    "GEOMETRY_KEYS",
    "OBSERVATION_KEYS",
    "RENAMED_SCENE_KEYS",
    "SCENE_KEYS",
    "SPACECRAFT_KEYS",
    "WRITE_KEYS",
    "Key",
    "reference",
    "toml_types",
]

_NUMBER = (int, float)


@dataclass(frozen=True)
class Key:
    """One key of a scene file.

    Attributes
    ----------
    name : str
        The key.
    types : tuple of type
        The TOML types it may have (``dict`` for a table, ``list`` for an array).
    help : str
        What it means, its unit and its domain.
    default : str or None
        Its default as shown in the reference; None takes the default of the
        :class:`~sbrdf_xr.engine.Scene` field of the same name.

    Examples
    --------
    >>> from sbrdf_xr.engine.schema import SCENE_KEYS
    >>> key = SCENE_KEYS["earth_albedo"]
    >>> key.types, key.shown_default()
    ((<class 'int'>, <class 'float'>), '0.3')
    >>> SCENE_KEYS["method"].shown_default(), SCENE_KEYS["method"].help.split(";")[-1]
    ('"linear"', ' one of nearest, linear, cubic')
    """

    name: str
    types: tuple[type, ...]
    help: str
    default: str | None = None

    def shown_default(self) -> str:
        """The default in TOML syntax (a knob's or the Scene field's unless given)."""
        if self.default is not None:
            return self.default
        if self.name in KNOBS:
            return toml_value(KNOBS[self.name].default)
        field = {f.name: f for f in dataclasses.fields(Scene)}[self.name]
        return toml_value(field.default)


def toml_value(v: Any) -> str:
    """A value in TOML syntax, for the reference (None, which TOML lacks, as ``-``).

    Examples
    --------
    >>> from sbrdf_xr.engine.schema import toml_value
    >>> [toml_value(v) for v in ("linear", 4, 0.3, None, False, ("a", "b"), (1.0, 0.0))]
    ['"linear"', '4', '0.3', '-', 'false', '["a", "b"]', '[1.0, 0.0]']
    """
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, list | tuple):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    return repr(v)


def _knob_key(name: str) -> Key:
    k = KNOBS[name]
    one_of = "one of " if k.allowed is not None else ""
    return Key(name, k.toml, f"{k.trades}; {one_of}{k.domain()}")


def _table(keys: Iterable[Key]) -> dict[str, Key]:
    return {k.name: k for k in keys}


#: Keys at the top of a scene file; the numerical knobs among them come from the knob table.
SCENE_KEYS: dict[str, Key] = _table(
    [
        Key("name", (str,), "label stored in the cube"),
        Key("description", (str,), "label stored in the cube"),
        Key(
            "spacecraft",
            (str, dict),
            "a catalog name, a mesh file, or a [spacecraft] table (below)",
            "required",
        ),
        Key(
            "materials",
            (dict,),
            "[materials]: material name = catalog entry, netCDF table or model file (a "
            "model is rendered to a table, or evaluated exactly with evaluation = "
            '"analytic")',
            "each material's catalog entry",
        ),
        Key(
            "attitude",
            (dict,),
            "[attitude] table (below): the attitudes of a grid, with phase_angles",
            "-",
        ),
        Key("phase_angles", (list,), "phase angles of the grid [degree]", "-"),
        Key("bisector", (list,), "the grid's observation plane: Sun-observer bisector"),
        Key("plane_normal", (list,), "the grid's observation plane: its normal"),
        Key(
            "geometry",
            (dict,),
            "[geometry] table (below): explicit body-frame geometry pairs instead of a grid",
            "-",
        ),
        Key(
            "observation",
            (dict,),
            "[observation] table (below): a real pass instead of a grid or pairs",
            "-",
        ),
        Key(
            "outputs",
            (list,),
            f"among {', '.join(SCENE_OUTPUTS)} (per_material adds signal_material)",
        ),
        Key(
            "write",
            (dict,),
            "[write] table (below): how sbrdf-xr simulate writes the cube (not a part of "
            "the scene: the values computed do not depend on it)",
            "-",
        ),
        Key(
            "effects",
            (list,),
            f"among {', '.join(SCENE_EFFECTS)} (the effects table below; "
            f"{', '.join(DEFAULT_EFFECTS)} always on)",
        ),
        *(_knob_key(k) for k in ("method", "dtype")),
        Key(
            "merge",
            (bool,),
            "merge facets sharing (normal, material); unset: whenever no per-facet effect runs",
        ),
        *(_knob_key(k) for k in ("shadow_method", "shadow_density", "chunk")),
        *(_knob_key(k) for k in ("wavelength_stride", "band_integration", "table_theta_step")),
        *(_knob_key(k) for k in ("evaluation", "kernel", "block_bytes", "tilt_nodes")),
        _knob_key("earth_model"),
        Key(
            "size_limit",
            _NUMBER,
            "factor on the limits of output size and work beyond which a plan is refused",
        ),
        Key(
            "surface_tilt",
            (int, float, dict),
            "surface imperfections: standard deviation of the facet-normal tilt [degree], "
            "0-45, one value or a table by material",
        ),
        Key("bands", (list,), "photometric bands of band_signal (V, R, I, ... or speclite names)"),
        Key(
            "band_extrapolate",
            (str,),
            'how spectra continue past the materials\' wavelengths in a band: "zero" or '
            '"constant" (unset: an error)',
        ),
        Key(
            "earth_direction",
            (list,),
            "a grid's direction to the Earth in the reference frame",
        ),
        Key("earth_albedo", _NUMBER, "Bond albedo of the Lambertian Earth, 0-1"),
        Key(
            "earth_range",
            _NUMBER,
            "a grid's or pairs' distance to the Earth's centre [km], > 6371",
        ),
        Key(
            "earth_phase_angle",
            _NUMBER,
            "a grid's or pairs' Sun-Earth-spacecraft angle [degree], 0-180",
        ),
        Key(
            "temperature",
            (int, float, dict, str),
            'facet temperature [K], one value or a table by material, or "equilibrium" (each '
            "facet's from radiative equilibrium, the knob conductance)",
        ),
        Key(
            "earth_temperature",
            _NUMBER,
            "the Earth's brightness temperature [K] (its infrared emission), 0-400",
        ),
    ]
)
SCENE_KEYS.update({k: _knob_key(k) for k in KNOBS if k not in SCENE_KEYS})  # every knob a key
#: Top-level keys renamed: old key -> new key.  A scene file's old key is read as the new
#: one for one release, with a :class:`~sbrdf_xr.errors.RenamedWarning`.
RENAMED_SCENE_KEYS: dict[str, str] = {"earth_range_km": "earth_range"}

#: Keys of a ``[write]`` table: how ``sbrdf-xr simulate`` writes the cube (the keyword
#: arguments of :func:`sbrdf_xr.store.write` of the same names).
WRITE_KEYS: dict[str, Key] = _table(
    [
        Key(
            "outputs",
            (str,),
            'the cube\'s variables: "independent" (those no other gives; the derived ones, '
            "brdf and signal beside signal_material, recorded and computed on read) or "
            '"all" (every one written); the option --outputs overrides it',
            '"independent"',
        ),
    ]
)

#: Keys of a ``[spacecraft]`` table (a mesh file).
SPACECRAFT_KEYS: dict[str, Key] = _table(
    [
        Key("path", (str,), "the mesh file, relative to the scene file", "required"),
        Key("material", (str,), "one material for every facet", "-"),
        Key(
            "material_map",
            (str, dict),
            "facet colour or label -> material: a TOML file or an inline table",
            "-",
        ),
        Key("length_unit", (str,), 'the file\'s length unit ("mm", "cm", "m", ...)', '"m"'),
        Key("face_property", (str,), "the per-face property (PLY) holding the labels", "-"),
        Key(
            "repair",
            (bool,),
            "repair what sbrdf_xr.body.repair lists (with a warning) instead of refusing",
            "false",
        ),
        Key("name", (str,), "the spacecraft's name", "the file's stem"),
        Key(
            "back_material",
            (str, dict),
            "backs of the facets: one material, or front material -> back material",
            "none (one-sided)",
        ),
        Key(
            "parts",
            (list,),
            "[[spacecraft.parts]] tables: facets turning about a hinge "
            "(sbrdf_xr.body.parts.PART_KEYS: name, facets or materials, axis, point, law, "
            "angle, limits, normal, angles)",
            "none (rigid)",
        ),
    ]
)

#: Keys of an ``[attitude]`` table, as
#: :data:`sbrdf_xr.engine.attitude_table.ATTITUDE_TABLE_KEYS` declares them for
#: :func:`~sbrdf_xr.engine.attitude_table.attitudes_from_table`, the reader (of scene files
#: and of ``Scene(attitude=...)``); ``kind`` says which others apply.
ATTITUDE_KEYS: dict[str, Key] = _table(
    Key(name, types, text, default) for name, (types, text, default) in _ATTITUDE.items()
)

#: Keys of a ``[geometry]`` table (explicit pairs, body frame).
GEOMETRY_KEYS: dict[str, Key] = _table(
    [
        Key("to_sun", (list,), "unit vectors to the Sun, rows of 3 numbers", "required"),
        Key("to_observer", (list,), "unit vectors to the observer, rows of 3", "required"),
        Key("to_earth", (list,), "unit vectors to the Earth, rows of 3", "-"),
    ]
)

#: Keys of an ``[observation]`` table, as
#: :data:`sbrdf_xr.observing.observe.OBSERVATION_KEYS` declares them for
#: :func:`~sbrdf_xr.observing.observe.observation_from_dict`, the reader.
OBSERVATION_KEYS: dict[str, Key] = _table(
    Key(name, types, text, default) for name, (types, text, default) in _OBSERVATION.items()
)


def toml_types(keys: Mapping[str, Key]) -> dict[str, tuple[type, ...]]:
    """The TOML types of every key of a table, for checking a file.

    Examples
    --------
    >>> from sbrdf_xr.engine.schema import ATTITUDE_KEYS, toml_types
    >>> toml_types(ATTITUDE_KEYS)["n"], toml_types(ATTITUDE_KEYS)["step"]
    ((<class 'int'>,), (<class 'int'>, <class 'float'>))
    """
    return {k: v.types for k, v in keys.items()}


_TYPE_NAMES = {str: "string", int: "integer", float: "float", bool: "boolean"}
_TYPE_NAMES.update({dict: "table", list: "array"})


def _rows(keys: Mapping[str, Key]) -> list[str]:
    out = ["| key | type | default | meaning |", "|---|---|---|---|"]
    for k in keys.values():
        types = " or ".join(dict.fromkeys(_TYPE_NAMES[t] for t in k.types))
        default = k.shown_default()
        if default[:1] in '"[-0123456789' or default in ("true", "false"):
            default = f"`{default}`"  # a TOML value, not words
        readers = [e.name for e in EFFECTS.values() if k.name in e.reads]
        what = f"{' and '.join(readers)}: {k.help}" if readers else k.help
        out.append(f"| `{k.name}` | {types} | {default} | {_md(what)} |")
    return out


def _md(text: str) -> str:
    """Table-cell Markdown of a text (reST roles and literals become code)."""
    text = re.sub(r":[a-z]+:`~?([^`]+)`", r"`\1`", text).replace("``", "`")
    return text.replace("|", "\\|").replace("*", "\\*")


def reference() -> str:
    """Every key of a scene file as Markdown tables (the user guide's reference).

    Examples
    --------
    >>> from sbrdf_xr.engine.schema import reference
    >>> text = reference()
    >>> "| `seed` | integer | `0` |" in text, "| `n` | integer | required |" in text
    (True, True)
    >>> "| `moonlight` |" in text  # the effects, from the registry
    True
    """
    from ..observing.attitude import ATTITUDE_LAWS

    out = ["Top-level keys (the numerical knobs among them are `sbrdf-xr knobs`'s):", ""]
    out += _rows(SCENE_KEYS)
    renamed = ", ".join(f"`{old}` (now `{new}`)" for old, new in RENAMED_SCENE_KEYS.items())
    out += ["", f"Old keys, read for one release with a warning: {renamed}."]
    out += ["", "`effects`:", "", "| effect | asked for | what it adds |", "|---|---|---|"]
    for e in EFFECTS.values():
        asked = {"always": "always on", "asked": "when listed", "automatic": "by the geometry"}
        out.append(f"| `{e.name}` | {asked[e.when]} | {_md(e.description)} |")
    for title, keys in (
        ("`[spacecraft]` (a mesh file)", SPACECRAFT_KEYS),
        ("`[attitude]` (`kind` says which keys apply)", ATTITUDE_KEYS),
        ("`[geometry]`", GEOMETRY_KEYS),
        ("`[observation]`", OBSERVATION_KEYS),
        ("`[write]` (how `sbrdf-xr simulate` writes the cube)", WRITE_KEYS),
    ):
        out += ["", f"{title}:", "", *_rows(keys)]
    out += ["", "`[observation.attitude]`: `law` and its parameters:", ""]
    out += ["| law | parameters | what |", "|---|---|---|"]
    for law, (cls, params) in ATTITUDE_LAWS.items():
        what = (cls.__doc__ or "").strip().splitlines()[0]
        out.append(f"| `{law}` | {', '.join(f'`{p}`' for p in params)} | {_md(what)} |")
    return "\n".join(out) + "\n"
