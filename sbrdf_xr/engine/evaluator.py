"""Small calls near the kernel: a compiled plan as a function of the directions.

A :class:`Evaluator` takes a :class:`~sbrdf_xr.engine.plan.Plan` once and then maps Sun
and observer directions (body frame, or reference frame with attitudes) to the plan's
outputs as plain numpy arrays: no Scene, no plan, no fingerprint, no Dataset per call.
Everything that does not depend on the directions is prepared when it is compiled: the
terms bundle, the typed tables and the compiled kernel's entry point for exactly these
argument types (:class:`~sbrdf_xr.kernels.sums.BoundSums`).  Its outputs are those of
:func:`~sbrdf_xr.engine.simulate` bit for bit: the same kernel on the same arrays, and the
same :func:`~sbrdf_xr.engine.effects.finish`.

:func:`block_outputs` is the rigid-body step of every block of a sweep
(:func:`~sbrdf_xr.engine.run.run_block`): it runs through the plan's evaluator
(:func:`evaluator_of`) when the plan allows the fast path (the Sun the only source,
no per-facet effect, the fused kernel on isotropic tables), and through the effects
otherwise.  Fits that evaluate one geometry at a time (the inversions of
:mod:`sbrdf_xr.invert`, a per-observation loop) can call an evaluator instead of
building a scene per geometry; :func:`compile_evaluator` gives one that keeps every
term of the body, whatever the directions.

Bad input raises named errors: directions of the wrong shape, not finite or not of
unit length raise :class:`~sbrdf_xr.errors.DirectionError`; a plan whose tables or
terms changed since it was compiled raises :class:`~sbrdf_xr.errors.StalePlanError`
(per call a cheap identity check: the same table and term objects, still read-only;
:meth:`Evaluator.verify` also compares a sample of the table values, or the record
of a memory-mapped table's file, whose read-only pages cannot change in place).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from ..errors import DirectionError, SceneError, StalePlanError
from ..kernels.sums import BoundSums
from ..materials.mapped import TableFile, mapping_of
from .effects import EFFECTS, BlockInputs, finish
from .effects.base import trapezoid_weights
from .sweep import GridGeometry

if TYPE_CHECKING:
    from .plan import Plan
    from .scene import Scene

__all__ = ["UNIT_TOLERANCE", "Evaluator", "block_outputs", "compile_evaluator", "evaluator_of"]

#: Largest ``| |v| - 1 |`` of a direction or quaternion an evaluator accepts [1] (the
#: scene's own tolerance).
UNIT_TOLERANCE = 1e-6
#: Table values summed per material for the content sample of :meth:`Evaluator.verify`.
_SAMPLE = 4096
#: Directions spread over the sphere that light and show every term of a body
#: (:func:`compile_evaluator`): the nearest is within a few degrees of any normal.
_COVER = 2000


def _fast(plan: Plan) -> bool:
    """The plan's blocks are one pass of the fused kernel: the Sun the only source, no
    per-facet effect, tabulated isotropic materials."""
    contributing = [e for e in plan.active_effects if e.contribute is not None]
    return (
        plan.articulation is None
        and not any(e.per_facet for e in plan.active_effects)
        and len(contributing) == 1
        and contributing[0].source == "sun"
        and plan.knobs["evaluation"] == "table"
        and plan.knobs["kernel"] == "fused"
        and not plan.anisotropic
    )


def _flags(plan: Plan) -> tuple[bool, ...]:
    """Whether each table and the terms' arrays are writeable."""
    t = plan.terms
    return (*(v.flags.writeable for v in plan.tables.values), t.normal.flags.writeable)


def _sample(plan: Plan) -> tuple[float | TableFile, ...]:
    """Sums of an even sample of each table's values and of the terms' normals and areas.

    A table that views a memory-mapped values file of the table cache
    (:mod:`sbrdf_xr.materials.mapped`) gives the file's record instead: its mapping is
    read-only (no change in place is possible; a file changed on disk is refused by its
    recorded digest), and a sample spread over it would make every page of the table
    resident in this process (each read faults in the pages around it), where a sweep
    reads about a third of them.
    """
    out: list[float | TableFile] = []
    for v in plan.tables.values:
        file = mapping_of(v)
        if file is not None and not v.flags.writeable:
            out.append(file)
            continue
        flat = v.reshape(-1)
        out.append(float(np.sum(flat[:: max(1, flat.size // _SAMPLE)], dtype=np.float64)))
    out += [float(plan.terms.normal.sum()), float(plan.terms.area.sum())]
    return tuple(out)


def _vectors(v: Any, name: str, width: int = 3) -> np.ndarray:
    """``v`` as (n, width) float64 rows of unit length, or a named error.

    The length is ``np.linalg.norm(v, axis=1)`` as numpy computes it (the square root of
    the row sums of squares), written out: the scene normalises its pairs with it, and
    the evaluator must give the same bits.
    """
    try:
        arr = np.asarray(v, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise DirectionError(
            f"{name}: expected numbers of shape ({width},) or (n, {width}); {exc}"
        ) from None
    if arr.shape == (3,) and width == 3:  # one direction: in Python floats, the same bits
        x, y, z = arr.tolist()
        n = math.sqrt((x * x + y * y) + z * z)  # numpy's row sum adds in this order
        if abs(n - 1.0) <= UNIT_TOLERANCE:
            return np.array([[x / n, y / n, z / n]])
    if arr.shape == (width,):
        arr = arr[None]
    if arr.ndim != 2 or arr.shape[1] != width or arr.shape[0] == 0:
        raise DirectionError(
            f"{name}: expected shape ({width},) or (n, {width}) with n >= 1, got {arr.shape}"
        )
    norm = np.sqrt(np.add.reduce(arr * arr, axis=1))
    if not np.less_equal(np.abs(norm - 1.0), UNIT_TOLERANCE).all():  # NaN and inf too
        if not np.isfinite(arr).all():
            raise DirectionError(f"{name}: contains NaN or infinite components")
        bad = np.flatnonzero(~(np.abs(norm - 1.0) <= UNIT_TOLERANCE))
        raise DirectionError(
            f"{name}: row {bad[0]} {arr[bad[0]].tolist()} has length {norm[bad[0]]:.6g}; "
            f"allowed: unit length (| |v| - 1 | <= {UNIT_TOLERANCE})"
        )
    return arr if width == 4 else arr / norm[:, None]


def block_outputs(
    plan: Plan, block: BlockInputs, fast: bool | None = None
) -> dict[str, np.ndarray]:
    """Every output of a rigid body's plan for one block of body-frame directions.

    Each effect of the plan contributes its sums (:data:`sbrdf_xr.engine.effects.EFFECTS`)
    and :func:`~sbrdf_xr.engine.effects.finish` combines them; where the plan allows it
    (``fast`` None: whenever it does), the sums come from the plan's evaluator
    (:func:`evaluator_of`) instead, bit for bit the same.

    Returns
    -------
    dict of str to ndarray
        Arrays shaped ``block.lead_shape + tail`` per output variable.

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.engine.evaluator import block_outputs
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> import numpy as np
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> plan = Scene(box, {"grey": grey}, attitudes=[[0, 0, 0, 1.0]], phase_angles=[0, 60]).plan()
    >>> block = plan.geometry.block(slice(None))
    >>> fast, slow = block_outputs(plan, block), block_outputs(plan, block, fast=False)
    >>> fast["signal"][0, :, 0].round(6).tolist()  # 0.5 / pi, times cos(30 deg)**2
    [0.159155, 0.119366]
    >>> all(np.array_equal(fast[k], slow[k]) for k in fast)
    True
    """
    if fast is None:
        fast = _fast(plan) and block.sun_scale is None
    if fast:
        return evaluator_of(plan).outputs(block)
    sums: dict[str, np.ndarray] = {}
    for effect in plan.active_effects:
        if effect.contribute is None:
            continue
        for k, v in effect.contribute(plan, block).items():
            sums[k] = sums[k] + v if k in sums else v
    return finish(plan, sums, block.lead_shape)


class Evaluator:
    """A plan compiled into a function of the directions (see the module docstring).

    Parameters
    ----------
    plan : Plan
        A rigid body's plan (a body with turning parts is refused).  It evaluates the
        plan's terms: those its own sweep can light and show.  For directions beyond
        that sweep use :func:`compile_evaluator` on the scene, which keeps every term.

    Attributes
    ----------
    plan : Plan
    output_names : tuple of str
        The output names of every call, as :func:`~sbrdf_xr.engine.simulate` names them.
    fast : bool
        One pass of the prepared kernel per call (else the effects run per call, still
        without any Dataset).

    Raises
    ------
    SceneError
        A plan of a body with turning parts.

    Examples
    --------
    A Lambertian unit cube (albedo 0.5): Sun and observer along +x give ``0.5 / pi``;
    with attitudes the directions are in the reference frame, one row per phase angle:

    >>> import numpy as np
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.engine import Evaluator
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> x = [[1.0, 0.0, 0.0]]
    >>> scene = Scene(box, {"grey": grey}, to_sun=x, to_observer=x)
    >>> ev = Evaluator(scene.plan())
    >>> ev.output_names, ev.fast
    (('spacecraft_sbrdf', 'signal', 'brdf', 'area'), True)
    >>> out = ev([1.0, 0.0, 0.0], [1.0, 0.0, 0.0])  # one geometry: no leading axis
    >>> out["signal"].round(6).tolist(), float(out["area"])
    ([0.159155, 0.159155, 0.159155], 1.0)
    >>> ev(np.array(x * 4), np.array(x * 4))["signal"].shape  # four geometries
    (4, 3)
    >>> turn = [0.0, 0.0, 0.0, 1.0]  # identity attitude (scalar-last quaternion)
    >>> ev(x, x, attitudes=[turn, turn])["area"].tolist()  # (attitude, phase angle)
    [[1.0], [1.0]]

    Bad directions raise a named error:

    >>> ev([2.0, 0.0, 0.0], [1.0, 0.0, 0.0])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.DirectionError: to_sun: row 0 [2.0, 0.0, 0.0] has length 2; allowed: ...
    """

    def __init__(self, plan: Plan) -> None:
        if plan.articulation is not None:
            raise SceneError(
                "Evaluator: the plan is of a body with turning parts (each part in its own "
                "frame per geometry); allowed: a rigid body's plan; use simulate for this one"
            )
        self.plan = plan
        self.output_names = plan.output_names
        self.fast = _fast(plan)
        self._tables, self._terms = plan.tables, plan.terms
        self._values = plan.tables.values
        self._flags = _flags(plan)
        self._sample = _sample(plan)
        self._sources = tuple(plan.geometry.sources)
        self._bound: BoundSums | None = None
        if self.fast:
            t = plan.terms
            self._bound = BoundSums(
                t.normal,
                t.area,
                t.material,
                plan.tables,
                plan.knobs["method"],
                "signal_material" in self.output_names,
                t.normal_rows,
            )
        self._lean = _lean(plan) if self._bound is not None and self._bound.n_terms else None

    def __reduce__(self) -> tuple[Any, tuple[()]]:
        # an evaluator is not sent along with its plan (its kernel entry point cannot
        # be): the copy of a plan's cache holds None, and the evaluator is compiled anew
        return (_none, ())

    def check(self) -> None:
        """Raise :class:`~sbrdf_xr.errors.StalePlanError` if the plan's tables or terms
        are no longer the objects compiled (every call does: three identity tests).

        Examples
        --------
        >>> import trimesh
        >>> from sbrdf_xr import Scene, load_spacecraft
        >>> from sbrdf_xr.engine import Evaluator
        >>> from sbrdf_xr.materials.schema import lambertian
        >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
        >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
        >>> x = [[1.0, 0.0, 0.0]]
        >>> plan = Scene(box, {"grey": grey}, to_sun=x, to_observer=x).plan()
        >>> ev = Evaluator(plan)
        >>> ev.check()  # unchanged
        >>> object.__setattr__(plan, "tables", plan.tables._replace())  # other tables
        >>> ev.check()  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        sbrdf_xr.errors.StalePlanError: Evaluator: the plan's tables or terms changed ...
        """
        p = self.plan
        if p.tables is not self._tables or p.terms is not self._terms:
            self._stale("another object")
        if p.tables.values is not self._values:
            self._stale("other table arrays")

    def _stale(self, what: str) -> None:
        raise StalePlanError(
            f"Evaluator: the plan's tables or terms changed since it was compiled ({what}); "
            "allowed: the plan as compiled; compile a new Evaluator from the current plan"
        )

    def verify(self) -> None:
        """:meth:`check`, and compare whether the tables and terms are writeable and an
        even sample of every table's values (a memory-mapped table: its file's record)
        and of the terms' normals and areas with those taken when it was compiled (a
        change in place raises
        :class:`~sbrdf_xr.errors.StalePlanError`).

        Examples
        --------
        >>> import trimesh
        >>> from sbrdf_xr import Scene, load_spacecraft
        >>> from sbrdf_xr.engine import Evaluator
        >>> from sbrdf_xr.materials.schema import lambertian
        >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
        >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
        >>> x = [[1.0, 0.0, 0.0]]
        >>> plan = Scene(box, {"grey": grey}, to_sun=x, to_observer=x).plan()
        >>> Evaluator(plan).verify()
        """
        self.check()
        if _flags(self.plan) != self._flags:
            self._stale("an array made writeable")
        if _sample(self.plan) != self._sample:
            self._stale("their values: a sample of them differs")

    def outputs(self, block: BlockInputs) -> dict[str, np.ndarray]:
        """The outputs for a block of body-frame directions (unit vectors, not checked:
        what :func:`block_outputs` hands over from a plan's own geometry).

        Examples
        --------
        >>> import trimesh
        >>> from sbrdf_xr import Scene, load_spacecraft
        >>> from sbrdf_xr.engine import Evaluator
        >>> from sbrdf_xr.materials.schema import lambertian
        >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
        >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
        >>> x = [[1.0, 0.0, 0.0]]
        >>> plan = Scene(box, {"grey": grey}, to_sun=x, to_observer=x).plan()
        >>> Evaluator(plan).outputs(plan.geometry.block(slice(None)))["area"].tolist()
        [1.0]
        """
        self.check()
        if self._bound is None or block.sun_scale is not None:
            return block_outputs(self.plan, block, fast=False)
        r = self._bound(block.to_sun, block.to_observer)
        sums = {"signal": r.signal, "paper": r.paper, "area": r.area}
        if r.per_material is not None:
            sums["signal_material"] = r.per_material
        return finish(self.plan, sums, block.lead_shape)

    def __call__(
        self,
        to_sun: Any,
        to_observer: Any,
        attitudes: Any = None,
        *,
        sun_scale: Any = None,
        sources: Mapping[str, Any] | None = None,
    ) -> dict[str, np.ndarray]:
        """The plan's outputs at these directions, as numpy arrays.

        Parameters
        ----------
        to_sun, to_observer : array_like, shape (3,) or (n, 3)
            Unit vectors towards the Sun and the observer [1]: in the body frame, or
            with ``attitudes`` in the reference frame (one row per phase angle, used as
            given, as a sweep's grid uses them).  Body-frame rows are normalised as a
            scene normalises its pairs.
        attitudes : array_like, shape (4,) or (m, 4), optional
            Body -> reference unit quaternions (scalar last) [1]: every attitude at
            every row of directions, as a scene's attitude grid.
        sun_scale : array_like, shape (n,), optional
            Sunlit fraction of the solar disc per geometry [1] (body-frame pairs).
        sources : mapping, optional
            The other sources' directions and scales the plan's geometry carries
            (``to_earth``, ``earth_scale``, ...: the keys of ``plan.geometry.sources``).

        Returns
        -------
        dict of str to ndarray
            Per output: shape ``(n, *tail)`` for pairs, ``(m, n, *tail)`` with
            attitudes, each leading axis dropped where its input was a single vector.

        Raises
        ------
        DirectionError
            Directions or quaternions of the wrong shape, not finite or not of unit
            length; ``to_sun`` and ``to_observer`` of different lengths.
        StalePlanError
            The plan's tables or terms changed since it was compiled (:meth:`check`).
        SceneError
            ``sources`` other than the plan's geometry carries.

        Examples
        --------
        >>> import trimesh
        >>> from sbrdf_xr import Scene, load_spacecraft
        >>> from sbrdf_xr.engine import Evaluator
        >>> from sbrdf_xr.materials.schema import lambertian
        >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
        >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
        >>> x = [[1.0, 0.0, 0.0]]
        >>> plan = Scene(box, {"grey": grey}, to_sun=x, to_observer=x).plan()
        >>> ev = Evaluator(plan)
        >>> ev([[1.0, 0, 0]], [[0.6, 0.8, 0]])["signal"][:, 0].round(6).tolist()  # 0.5/pi * 0.6
        [0.095493]
        >>> ev([[1.0, 0, 0]], [[1.0, 0, 0], [0, 1.0, 0]])  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        sbrdf_xr.errors.DirectionError: to_sun has 1 rows and to_observer 2; allowed: ...
        """
        if self._lean is not None and attitudes is None and sun_scale is None and not sources:
            one = self._one(to_sun, to_observer)
            if one is not None:
                return one
        s = _vectors(to_sun, "to_sun")
        o = _vectors(to_observer, "to_observer")
        if s.shape != o.shape:
            raise DirectionError(
                f"to_sun has {s.shape[0]} rows and to_observer {o.shape[0]}; allowed: "
                "as many rows of each"
            )
        extra = self._extra(sources, s.shape[0])
        lead: tuple[int, ...]
        if attitudes is None:
            scale = None
            if sun_scale is not None:
                scale = np.asarray(sun_scale, dtype=np.float64).reshape(-1)
                if scale.shape != (s.shape[0],) or not np.all((scale >= 0) & (scale <= 1)):
                    raise DirectionError(
                        f"sun_scale: expected {s.shape[0]} values in [0, 1], got "
                        f"{np.asarray(sun_scale).tolist()}"
                    )
            block = BlockInputs(s, o, scale, (s.shape[0],), extra)
            lead = () if np.ndim(to_sun) == 1 else (s.shape[0],)
        else:
            s, o = np.asarray(to_sun, dtype=np.float64), np.asarray(to_observer, dtype=np.float64)
            s, o = s.reshape(-1, 3), o.reshape(-1, 3)  # reference frame, as given
            q = _vectors(attitudes, "attitudes", 4)
            grid = GridGeometry(q, np.zeros(len(s)), s, o, extra)
            block = grid.block(slice(None))
            lead = (() if np.ndim(attitudes) == 1 else (len(q),)) + (
                () if np.ndim(to_sun) == 1 else (len(s),)
            )
        out = self.outputs(block)
        if lead == block.lead_shape:
            return out
        n = len(block.lead_shape)
        return {k: v.reshape((*lead, *v.shape[n:])) for k, v in out.items()}

    def _one(self, to_sun: Any, to_observer: Any) -> dict[str, np.ndarray] | None:
        """One body-frame geometry in one compiled call (:meth:`BoundSums.one`) and the
        steps of :func:`~sbrdf_xr.engine.effects.finish` this plan needs; None where the
        input is not two plain vectors of unit length (the general path then raises the
        error that says why)."""
        lean, bound = self._lean, self._bound
        if lean is None or bound is None or not (_three(to_sun) and _three(to_observer)):
            return None
        self.check()
        try:
            got: Any = bound.one(to_sun, to_observer, UNIT_TOLERANCE, lean.eq4)
        except (TypeError, ValueError):
            return None
        ok, sig, pap, area, pm = got
        if not ok:
            return None
        out: dict[str, np.ndarray] = {}
        for name in self.output_names:
            if name == "signal":
                out[name] = sig[0]
            elif name == "spacecraft_sbrdf":
                out[name] = pap[0]
            elif name == "area":
                out[name] = area.reshape(())
            elif name == "brdf":
                out[name] = np.einsum("gl,l->g", pap, lean.trapezoid).astype(lean.dtype)[0]
            elif name == "signal_material":
                out[name] = pm[0]
            elif lean.band is None:  # band_signal, the tables pre-integrated
                out[name] = sig[0].astype(lean.dtype)
            else:
                out[name] = np.einsum("gl,bl->gb", sig, lean.band).astype(lean.dtype)[0]
        return out

    def _extra(self, sources: Mapping[str, Any] | None, n: int) -> dict[str, np.ndarray]:
        """The other sources' arrays, exactly the keys the plan's geometry carries."""
        if not sources and not self._sources:
            return {}
        given = dict(sources or {})
        if set(given) != set(self._sources):
            raise SceneError(
                f"Evaluator: sources {sorted(given)}; allowed: exactly the plan's "
                f"{sorted(self._sources)}"
            )
        return {k: np.asarray(v, dtype=np.float64) for k, v in given.items()}


class _Lean(NamedTuple):
    """What the one-geometry path needs of :func:`~sbrdf_xr.engine.effects.finish`: the
    division of Eq. 4, the trapezoid weights, the band weights (None when the tables
    are pre-integrated) and the outputs' dtype."""

    eq4: bool
    trapezoid: np.ndarray
    band: np.ndarray | None
    dtype: np.dtype


#: The outputs :meth:`Evaluator._one` computes as ``finish`` does.
_LEAN_OUTPUTS = frozenset(
    {"signal", "spacecraft_sbrdf", "area", "brdf", "signal_material", "band_signal"}
)


def _lean(plan: Plan) -> _Lean | None:
    """The one-geometry steps of a fast plan, or None if its outputs need others."""
    names = set(plan.output_names)
    if not names <= _LEAN_OUTPUTS or not plan.tables.values or plan.geometry.sources:
        return None
    if "band_signal" in names:
        keys = {"signal", "paper", "area", "signal_material"}
        if [k for e in plan.active_effects for k in e.band if k in keys] != ["signal"]:
            return None
    pre = plan.pre_integrated or plan.band_weights is None
    return _Lean(
        "spacecraft_sbrdf" in names or "brdf" in names,
        trapezoid_weights(plan),
        None if pre else plan.band_weights,
        np.dtype(plan.knobs["dtype"]),
    )


def _three(v: Any) -> bool:
    """``v`` is a list or tuple of three items or a float array of shape (3,)."""
    if type(v) is np.ndarray:
        return v.shape == (3,) and v.dtype.kind == "f"
    return type(v) in (list, tuple) and len(v) == 3


def _none() -> None:
    """What an evaluator becomes in a copy of its plan's cache (see ``__reduce__``)."""
    return None


def evaluator_of(plan: Plan) -> Evaluator:
    """The plan's own evaluator, compiled on first use and kept in ``plan.cache``.

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.engine.evaluator import evaluator_of
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> x = [[1.0, 0.0, 0.0]]
    >>> plan = Scene(box, {"grey": grey}, to_sun=x, to_observer=x).plan()
    >>> evaluator_of(plan) is evaluator_of(plan)
    True
    """
    ev = plan.cache.get("evaluator")
    if ev is None:
        ev = plan.cache["evaluator"] = Evaluator(plan)
    return ev


def compile_evaluator(scene: Scene) -> Evaluator:
    """An evaluator of a scene's body, materials, outputs and knobs that keeps every term,
    whatever the directions it is later called with.

    A plan keeps only the terms its own sweep can light and show; here the scene is
    planned over directions spread over the whole sphere (Sun and observer together),
    so no term is dropped.  The scene's own geometry is not used.

    Raises
    ------
    SceneError
        A scene whose effects need an observation's geometry (the Moon), or of a body
        with turning parts.

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.engine import compile_evaluator
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> x = [[1.0, 0.0, 0.0]]
    >>> scene = Scene(box, {"grey": grey}, to_sun=x, to_observer=x)
    >>> scene.plan().terms.size, compile_evaluator(scene).plan.terms.size  # +x only, all 6
    (1, 6)
    >>> float(compile_evaluator(scene)([0, 0, -1.0], [0, 0, -1.0])["area"])  # the -z face
    1.0
    """
    if any("observation" in EFFECTS[e].needs for e in scene.effects if e in EFFECTS):
        raise SceneError(
            f"compile_evaluator: effects {scene.effects} need an observation's geometry; "
            "allowed: effects that take explicit directions"
        )
    cover = _sphere(_COVER)
    changes: dict[str, Any] = {
        "attitudes": None,
        "phase_angles": None,
        "attitude_angle": None,
        "observation": None,
        "to_sun": cover,
        "to_observer": cover,
    }
    if any("to_earth" in EFFECTS[e].needs for e in scene.effects if e in EFFECTS):
        changes["to_earth"] = cover
    return Evaluator(scene.with_options(**changes).plan())


def _sphere(n: int) -> np.ndarray:
    """``n`` unit vectors spread evenly over the sphere (a Fibonacci lattice)."""
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    r = np.sqrt(1.0 - z * z)
    a = np.pi * (3.0 - np.sqrt(5.0)) * k
    v = np.stack([r * np.cos(a), r * np.sin(a), z], axis=1)
    return v / np.linalg.norm(v, axis=1)[:, None]
