"""Attitude tables: the ``[attitude]`` of a scene file, also ``Scene(attitude=...)``.

One reader, :func:`attitudes_from_table`, turns a table (``kind`` = ``sweep``,
``uniform``, ``euler`` or ``quaternions`` and its keys) into the attitudes of a grid, for
scene files (:func:`sbrdf_xr.engine.scene_file.scene_from_dict`) and for Python
(:class:`sbrdf_xr.engine.Scene`'s ``attitude``) alike; :data:`ATTITUDE_TABLE_KEYS`
declares its keys once (:data:`sbrdf_xr.engine.schema.ATTITUDE_KEYS` renders them).  The
checks of a scene file's numbers, vectors and rows live here too, so both readers name a
bad value the same way.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .. import geometry
from ..errors import SceneError, ValidationError, did_you_mean
from ..units import to_unit

__all__ = ["ATTITUDE_KINDS", "ATTITUDE_TABLE_KEYS", "MAX_SCENE_COUNT", "attitudes_from_table"]

_NUMBER = (int, float)

#: Keys of an attitude table: name -> (TOML types, meaning, default as shown); ``kind`` says
#: which others apply.
ATTITUDE_TABLE_KEYS: dict[str, tuple[tuple[type, ...], str, str]] = {
    "kind": ((str,), "sweep, uniform, euler or quaternions", '"sweep"'),
    "axis": ((list,), "sweep: rotation axis", "[0, 0, 1]"),
    "start": (_NUMBER, "sweep: first angle [degree]", "0"),
    "stop": (_NUMBER, "sweep: end angle, excluded [degree]", "required"),
    "step": (_NUMBER, "sweep: angle step [degree], not 0", "1"),
    "initial_axis": ((list,), "sweep: axis of an initial rotation", "-"),
    "initial_angle": (_NUMBER, "sweep: angle of the initial rotation [degree]", "0"),
    "n": ((int,), "uniform: number of random attitudes (uniform on SO(3))", "required"),
    "seed": ((int,), "uniform: random seed, 0 to 2**63 - 1", "0"),
    "sequence": ((str,), 'euler: axis sequence, e.g. "zyx"', "required"),
    "angles": ((list,), "euler: angles [degree], one row per attitude", "required"),
    "quaternions": ((list,), "quaternions: rows of x, y, z, w", "required"),
}

#: The kinds of attitude table, each a function of :mod:`sbrdf_xr.geometry.rotations`.
ATTITUDE_KINDS = ("sweep", "uniform", "euler", "quaternions")

_TYPES = {k: types for k, (types, _, _) in ATTITUDE_TABLE_KEYS.items()}

#: Most attitudes or geometry pairs a scene file may list or generate.
MAX_SCENE_COUNT = 10_000_000

#: Largest magnitude of a direction's component in a scene file (its length must not overflow).
_MAX_COMPONENT = 1e100


def _show(v: Any) -> str:
    text = repr(v)
    return text if len(text) <= 60 else text[:57] + "..."


def _is_number(x: Any) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool)


def _check_keys(table: Any, allowed: Mapping[str, Any], where: str) -> None:
    if not isinstance(table, Mapping):
        raise SceneError(f"{where}: expected a table of keys, got {type(table).__name__}")
    for k, v in table.items():
        if k not in allowed:
            raise SceneError(
                f"{where}: unknown key {k!r}; {did_you_mean(k, allowed, 'allowed keys')}"
            )
        types = allowed[k]
        types = types if isinstance(types, tuple) else (types,)
        if not isinstance(v, types) or (isinstance(v, bool) and bool not in types):
            names = " or ".join(t.__name__ for t in types)
            raise SceneError(
                f"{where}: key {k!r} has type {type(v).__name__} ({_show(v)}); expected {names}"
            )


def _number(v: Any, where: str) -> float:
    """A finite number from a scene file."""
    if not _is_number(v):
        raise SceneError(f"{where}: expected a number, got {_show(v)} ({type(v).__name__})")
    try:
        x = float(v)
    except OverflowError:
        raise SceneError(f"{where}: {_show(v)} is too large") from None
    if not np.isfinite(x):
        raise SceneError(f"{where}: must be finite, got {x}")
    return x


def _numbers(v: Any, where: str, *, allow_empty: bool = False) -> np.ndarray:
    """A flat list of finite numbers from a scene file."""
    if not isinstance(v, list):
        raise SceneError(f"{where}: expected a list of numbers, got {_show(v)}")
    if not v and not allow_empty:
        raise SceneError(f"{where}: the list is empty; give at least one value")
    if len(v) > MAX_SCENE_COUNT:
        raise SceneError(f"{where}: {len(v)} values; at most {MAX_SCENE_COUNT} are allowed")
    return np.array([_number(x, f"{where}[{i}]") for i, x in enumerate(v)], dtype=np.float64)


def _rows(v: Any, width: int, where: str) -> np.ndarray:
    """A non-empty list of rows of ``width`` finite numbers (vectors, quaternions)."""
    if not isinstance(v, list) or not v:
        raise SceneError(
            f"{where}: expected a non-empty list of [{', '.join(['x'] * width)}] rows, "
            f"got {_show(v)}"
        )
    if len(v) > MAX_SCENE_COUNT:
        raise SceneError(f"{where}: {len(v)} rows; at most {MAX_SCENE_COUNT} are allowed")
    out = np.empty((len(v), width))
    for i, row in enumerate(v):
        if not isinstance(row, list) or len(row) != width:
            raise SceneError(f"{where}[{i}]: expected {width} numbers, got {_show(row)}")
        out[i] = [_number(x, f"{where}[{i}][{j}]") for j, x in enumerate(row)]
    return out


def _vector(v: Any, where: str) -> tuple[float, float, float]:
    if not isinstance(v, list) or len(v) != 3:
        raise SceneError(f"{where}: expected a vector of 3 numbers, got {_show(v)}")
    x = (_number(v[0], f"{where}[0]"), _number(v[1], f"{where}[1]"), _number(v[2], f"{where}[2]"))
    if not any(x):
        raise SceneError(f"{where}: the zero vector has no direction")
    if max(map(abs, x)) > _MAX_COMPONENT:
        raise SceneError(
            f"{where}: components must not exceed {_MAX_COMPONENT:g} in magnitude, got {list(x)}"
        )
    return x


def _count(v: Any, where: str) -> int:
    if not isinstance(v, int) or isinstance(v, bool) or not 1 <= v <= MAX_SCENE_COUNT:
        raise SceneError(
            f"{where}: expected an integer from 1 to {MAX_SCENE_COUNT}, got {_show(v)}"
        )
    return int(v)


#: Keys whose values are angles [degree]: a Quantity is converted.
_DEGREE_KEYS = ("start", "stop", "step", "initial_angle", "angles")


def _toml_value(v: Any) -> Any:
    """A Python value as TOML gives it: arrays and tuples as lists, numpy scalars as numbers."""
    if isinstance(v, np.ndarray | tuple | list):
        return [_toml_value(x) for x in v]
    if isinstance(v, np.generic):
        return v.item()
    return v


def _as_toml(table: Any, where: str) -> Any:
    """``table`` with angle Quantities in degree and arrays as lists (a file's are already)."""
    if not isinstance(table, Mapping):
        return table
    out = {}
    for k, v in table.items():
        if k in _DEGREE_KEYS:
            v = to_unit(v, "deg", f"{where} {k}")
        out[k] = _toml_value(v)
    return out


def attitudes_from_table(
    table: Mapping[str, Any], where: str = "[attitude]"
) -> tuple[np.ndarray, np.ndarray | None]:
    """The attitudes of an attitude table (a scene file's ``[attitude]``).

    ``kind = "sweep"`` (the default) is :func:`sbrdf_xr.geometry.rotation_sweep` over
    ``start, start + step, ...`` up to ``stop`` (excluded), after an optional rotation of
    ``initial_angle`` about ``initial_axis``; ``"uniform"`` is
    :func:`sbrdf_xr.geometry.uniform_attitudes` (``n``, ``seed``); ``"euler"`` is
    :func:`sbrdf_xr.geometry.euler_attitudes` (``sequence``, ``angles``); ``"quaternions"``
    lists them (rows of x, y, z, w).

    Parameters
    ----------
    table : mapping of str to TOML values
        The keys of :data:`ATTITUDE_TABLE_KEYS`: strings, numbers (angles [degree]) and
        lists, as a TOML file gives them; from Python also numpy arrays and tuples (taken
        as lists) and astropy angle Quantities (converted to degree).
    where : str
        How errors name the table (``"[attitude]"`` in a scene file, ``"attitude"`` for
        :class:`~sbrdf_xr.engine.Scene`).

    Returns
    -------
    attitudes : ndarray, shape (n, 4)
        Scalar-last unit quaternions (body -> reference frame).
    angles : ndarray, shape (n,), or None
        A sweep's angles [degree] (the cube's ``attitude_angle``); None for other kinds.

    Raises
    ------
    sbrdf_xr.errors.SceneError
        An unknown kind or key, a value of the wrong type, a missing key, an empty or
        oversized sweep; the message names the key, what it got and what is allowed.

    Examples
    --------
    >>> from sbrdf_xr.engine.attitude_table import attitudes_from_table
    >>> q, angles = attitudes_from_table({"kind": "sweep", "stop": 90, "step": 30})
    >>> q.shape, angles.tolist()
    ((3, 4), [0.0, 30.0, 60.0])
    >>> attitudes_from_table({"kind": "uniform", "n": 5, "seed": 1})[0].shape
    (5, 4)
    >>> attitudes_from_table({"kind": "sweep", "stpo": 90}, "attitude")
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.SceneError: attitude: unknown key 'stpo'; did you mean 'stop' or 'step'? ...
    """
    t = _as_toml(table, where)
    _check_keys(t, _TYPES, where)
    kind = t.get("kind", "sweep")

    def key(k: str) -> str:
        return f"{where} {k}"

    try:
        if kind == "sweep":
            if "stop" not in t:
                raise SceneError(
                    f"{where}: a sweep needs 'stop' (and optionally 'start' and 'step') [degree]"
                )
            start = _number(t.get("start", 0.0), key("start"))
            stop = _number(t["stop"], key("stop"))
            step = _number(t.get("step", 1.0), key("step"))
            if step == 0:
                raise SceneError(f"{key('step')}: must not be 0")
            n = int(np.ceil((stop - start) / step))
            if n < 1:
                raise SceneError(
                    f"{where}: a sweep from {start:g} to {stop:g} (excluded) in steps of "
                    f"{step:g} degree has no attitude; stop must lie beyond start in the "
                    "direction of step"
                )
            if n > MAX_SCENE_COUNT:
                raise SceneError(
                    f"{where}: the sweep has {n} attitudes; at most {MAX_SCENE_COUNT} are allowed"
                )
            angles = np.arange(start, stop, step)
            initial = None
            if "initial_axis" in t:
                initial = geometry.axis_rotation(
                    _vector(t["initial_axis"], key("initial_axis")),
                    _number(t.get("initial_angle", 0.0), key("initial_angle")),
                )
            axis = _vector(t.get("axis", [0, 0, 1]), key("axis"))
            return geometry.rotation_sweep(axis, angles, initial), angles
        if kind == "uniform":
            if "n" not in t:
                raise SceneError(f"{where}: kind 'uniform' needs 'n' (the number of attitudes)")
            seed = t.get("seed", 0)
            if not 0 <= seed < 2**63:
                raise SceneError(
                    f"{key('seed')}: expected an integer from 0 to 2**63 - 1, got {seed}"
                )
            return geometry.uniform_attitudes(_count(t["n"], key("n")), seed), None
        if kind == "euler":
            if "sequence" not in t or "angles" not in t:
                raise SceneError(
                    f"{where}: kind 'euler' needs 'sequence' (e.g. 'zyx') and 'angles' [degree]"
                )
            seq, ang = t["sequence"], t["angles"]
            if ang and all(isinstance(a, list) for a in ang):
                angles = _rows(ang, len(seq), key("angles"))
            else:
                angles = _numbers(ang, key("angles"))
            return geometry.euler_attitudes(seq, angles), None
        if kind == "quaternions":
            if "quaternions" not in t:
                raise SceneError(
                    f"{where}: kind 'quaternions' needs 'quaternions' (rows of x, y, z, w)"
                )
            return geometry.check_quaternions(_rows(t["quaternions"], 4, key("quaternions"))), None
    except SceneError:
        raise
    except (ValidationError, ValueError, TypeError) as exc:
        raise SceneError(f"{where}: {exc}") from None
    raise SceneError(f"{where}: unknown kind {kind!r}; allowed: {', '.join(ATTITUDE_KINDS)}")


def _scene_attitudes(
    table: Mapping[str, Any], attitudes: Any, attitude_angle: Any
) -> tuple[np.ndarray, Any]:
    """``Scene(attitude=table)``: the attitudes, and the sweep's angles unless labels are given."""
    if attitudes is not None:
        raise SceneError(
            "attitude: give either attitude (a table, as a scene file's [attitude]) or "
            "attitudes (quaternions), not both"
        )
    q, angles = attitudes_from_table(table, "attitude")
    return q, angles if attitude_angle is None else attitude_angle


_UNIT_TOL = 1e-6


def _unit_vectors(v: ArrayLike, name: str) -> np.ndarray:
    try:
        arr = np.asarray(v, dtype=np.float64)
    except (ValueError, TypeError) as exc:
        raise SceneError(f"{name}: expected n vectors of 3 numbers (shape (n, 3)); {exc}") from None
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise SceneError(f"{name}: expected shape (n, 3), got {arr.shape}")
    if arr.shape[0] == 0:
        raise SceneError(f"{name}: needs at least one vector, got none")
    if not np.all(np.isfinite(arr)):
        raise SceneError(f"{name}: contains NaN or infinite components")
    with np.errstate(over="ignore"):  # a huge component: length inf, refused below
        norm = np.linalg.norm(arr, axis=1)
    bad = np.flatnonzero(~(np.abs(norm - 1.0) <= _UNIT_TOL))
    if bad.size:
        raise SceneError(
            f"{name}: vector {bad[0]} {arr[bad[0]].tolist()} has length {norm[bad[0]]:.6g}; "
            f"directions must be unit vectors (|length - 1| <= {_UNIT_TOL})"
        )
    return arr / norm[:, None]
