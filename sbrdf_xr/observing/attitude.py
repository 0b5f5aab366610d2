"""Attitude laws: the orientation of a spacecraft as a function of time.

Every law is an object with ``quaternions(times, context=None) -> (n, 4)``: unit
quaternions, scalar-last ``(x, y, z, w)``, of the rotation that takes body-frame
vectors to the inertial reference frame (the convention of :mod:`sbrdf_xr.geometry`).
The inertial frame of :mod:`sbrdf_xr.observing.observe` is the GCRS (geocentric, ICRF axes).

Times are either ``datetime64`` (UTC) or float seconds.  Float seconds count from the
law's ``epoch``; a law without an ``epoch`` counts from ``context.epoch`` (the start of
the observation), or from the first requested time.  Laws that follow the orbit
(:class:`~sbrdf_xr.observing.pointing.Nadir`, :class:`~sbrdf_xr.observing.pointing.SunPointing`)
need a :class:`~sbrdf_xr.observing.frames.Context` with the spacecraft's position and
velocity and the direction of the Sun at the requested times.

Laws
----
==================  ========================================================================
Inertial(q)         fixed orientation
Nadir               LVLH: a body axis on the nadir, another toward the velocity, then a yaw
SunPointing         a body axis on the Sun, a second body axis as close as possible to a
                    target direction (orbit normal, nadir, velocity, north or a vector)
Spin                rotation about a body axis at a constant rate from an initial attitude
                    (a quaternion or another law)
Tumble              torque-free rigid body: Euler's equations for an inertia tensor
                    (given, or :meth:`Spacecraft.inertia` at uniform density), integrated
                    with :func:`scipy.integrate.solve_ivp` (DOP853, rtol 1e-12)
QuaternionSeries    a user time series (arrays, CSV or netCDF), slerp-interpolated
Composed            ``outer * inner``: ``R(t) = R_outer(t) R_inner(t)``
==================  ========================================================================

:func:`law_from_dict` builds a law from a TOML table (``[observation.attitude]``);
:func:`compose` and :class:`Spin` take a law, a quaternion or such a table, so they
stand here with it.  The other laws are defined by job and importable from here too:
the :class:`~sbrdf_xr.observing.pointing.AttitudeLaw` interface, its composition and the
pointing laws in :mod:`sbrdf_xr.observing.pointing`, the tumble in
:mod:`sbrdf_xr.observing.tumble`, the time series in :mod:`sbrdf_xr.observing.series`, and
the frames, :class:`~sbrdf_xr.observing.frames.Context` and :func:`triad` in
:mod:`sbrdf_xr.observing.frames`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from ..errors import AttitudeError, did_you_mean
from ..units import to_unit
from .frames import (
    Context,
    axis_vector,
    check_epoch,
    seconds_since,
    triad,
)
from .pointing import AttitudeLaw, Composed, Inertial, Nadir, SunPointing
from .series import QuaternionSeries
from .tumble import Tumble

__all__ = [
    "LAWS",
    "AttitudeLaw",
    "Composed",
    "Context",
    "Inertial",
    "Nadir",
    "QuaternionSeries",
    "Spin",
    "SunPointing",
    "Tumble",
    "compose",
    "law_from_dict",
    "triad",
]


def _law_or_quaternion(value: Any, name: str) -> AttitudeLaw:
    if isinstance(value, AttitudeLaw):
        return value
    if isinstance(value, Mapping):
        return law_from_dict(value)
    return Inertial(value)


@dataclass(frozen=True)
class Spin(AttitudeLaw):
    """Rotation about a body axis at a constant rate, after an initial attitude.

    ``R(t) = R_initial(t) R_axis(phase + rate t)``: the body turns about its own
    ``axis_body`` (right-handed) by the angle ``phase_deg + rate_deg_s * t``, starting
    from ``initial`` (a quaternion: the attitude at angle 0; or a law, e.g. :class:`Nadir`
    for a nadir-pointer spinning about its nadir axis).  With an inertial ``initial`` this
    equals :func:`sbrdf_xr.geometry.rotation_sweep` about the inertial axis
    ``R_initial axis_body``.

    Parameters
    ----------
    axis_body : str or array_like
        Spin axis in the body frame.
    rate_deg_s : float
        Spin rate [degree s-1].
    phase_deg : float
        Angle at the epoch [degree].
    initial : quaternion, law or table
        Attitude at angle 0 (default: identity).
    epoch : datetime64 or str, optional
        Time of ``phase_deg`` (default: the start of the observation).

    Examples
    --------
    >>> spin = Spin(axis_body="+z", rate_deg_s=10.0, phase_deg=5.0)
    >>> spin.angles([0.0, 1.0, 2.0])  # [degree]
    array([ 5., 15., 25.])
    >>> np.round(spin.quaternions([0.0]), 6)
    array([[0.      , 0.      , 0.043619, 0.999048]])
    """

    axis_body: Any = "+z"
    rate_deg_s: float = 1.0
    phase_deg: float = 0.0
    initial: Any = (0.0, 0.0, 0.0, 1.0)
    epoch: Any = None
    _axis_vec: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        for name, unit in (("rate_deg_s", "deg / s"), ("phase_deg", "deg")):
            val = to_unit(getattr(self, name), unit, name)
            object.__setattr__(self, name, val)
            if not isinstance(val, int | float | np.floating | np.integer) or not np.isfinite(val):
                raise AttitudeError(f"spin {name}: must be a finite number [degree], got {val!r}")
        object.__setattr__(self, "_axis_vec", axis_vector(self.axis_body, "axis_body"))
        object.__setattr__(self, "initial", _law_or_quaternion(self.initial, "initial"))
        object.__setattr__(self, "epoch", check_epoch(self.epoch))

    def angles(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        """Spin angle ``phase + rate t`` at ``times`` [degree].

        Examples
        --------
        >>> Spin(rate_deg_s=2.0).angles([0.0, 0.5, 10.0])
        array([ 0.,  1., 20.])
        """
        return self.phase_deg + self.rate_deg_s * seconds_since(times, self.epoch, context)

    def quaternions(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        ang = np.radians(self.angles(times, context))
        spin = Rotation.from_rotvec(ang[:, None] * self._axis_vec[None, :])
        q0 = self.initial.quaternions(times, context)
        return (Rotation.from_quat(q0) * spin).as_quat().reshape(-1, 4)


def compose(outer: AttitudeLaw | ArrayLike, inner: AttitudeLaw | ArrayLike) -> Composed:
    """Compose two laws (or a law and a fixed quaternion): ``R_outer(t) R_inner(t)``.

    Examples
    --------
    >>> s = float(np.sqrt(0.5))
    >>> law = compose([0.0, 0.0, s, s], Spin(rate_deg_s=90.0))
    >>> type(law).__name__, np.round(law.quaternions([1.0]), 6)
    ('Composed', array([[0., 0., 1., 0.]]))
    """
    return Composed(_law_or_quaternion(outer, "outer"), _law_or_quaternion(inner, "inner"))


# --------------------------------------------------------------------------- tables

#: Law name -> (class, allowed parameters).
LAWS: dict[str, tuple[type[AttitudeLaw], tuple[str, ...]]] = {
    "inertial": (Inertial, ("q",)),
    "nadir": (Nadir, ("yaw_deg", "nadir_axis", "velocity_axis")),
    "sun_pointing": (SunPointing, ("axis", "secondary_axis", "secondary_target")),
    "spin": (Spin, ("axis_body", "rate_deg_s", "phase_deg", "initial", "epoch")),
    "tumble": (Tumble, ("inertia", "omega_deg_s", "initial", "epoch")),
    "quaternion_series": (
        QuaternionSeries,
        ("path", "time_column", "columns", "variable", "epoch"),
    ),
    "compose": (Composed, ("outer", "inner")),
}


def law_from_dict(table: Mapping[str, Any]) -> AttitudeLaw:
    """Build a law from a TOML table such as ``[observation.attitude]``.

    ``law`` names the law (a key of :data:`LAWS`); the other keys are its parameters.
    ``spin.initial`` and ``compose.outer``/``inner`` may be nested tables; a
    ``quaternion_series`` reads ``path`` (``.csv`` or ``.nc``).  Example::

        [observation.attitude]
        law = "spin"
        axis_body = "+z"
        rate_deg_s = 3.0
        initial = {law = "nadir", yaw_deg = 10.0}

    Raises
    ------
    AttitudeError
        For an unknown law or parameter, or bad parameter values.

    Examples
    --------
    >>> law = law_from_dict({"law": "spin", "axis_body": "+x", "rate_deg_s": 6.0})
    >>> law
    Spin(axis_body='+x', rate_deg_s=6.0, phase_deg=0.0,
         initial=Inertial(q=(0.0, 0.0, 0.0, 1.0)), epoch=None)
    >>> law_from_dict({"law": "wobble"})
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.AttitudeError: attitude: unknown law 'wobble'; allowed laws: compose, ...
    """
    if not isinstance(table, Mapping) or "law" not in table:
        raise AttitudeError(
            f"attitude: expected a table with a 'law' key (one of {', '.join(LAWS)}), got {table!r}"
        )
    name = table["law"]
    if name not in LAWS:
        raise AttitudeError(
            f"attitude: unknown law {name!r}; {did_you_mean(name, LAWS, 'allowed laws')}"
        )
    cls, allowed = LAWS[name]
    params = {k: v for k, v in table.items() if k != "law"}
    bad = sorted(set(params) - set(allowed))
    if bad:
        raise AttitudeError(
            f"attitude law {name!r}: unknown parameter(s) {bad}; "
            + did_you_mean(bad[0], allowed, "allowed parameters")
        )
    if name == "compose":
        missing = [k for k in ("outer", "inner") if k not in params]
        if missing:
            raise AttitudeError(f"attitude law 'compose': needs {missing}")
        return compose(params["outer"], params["inner"])
    if name == "quaternion_series":
        if "path" not in params:
            raise AttitudeError("attitude law 'quaternion_series': needs a path (.csv or .nc)")
        path = Path(params.pop("path"))
        if path.suffix.lower() == ".csv":
            kw: dict[str, Any] = {k: params[k] for k in ("time_column", "epoch") if k in params}
            if "columns" in params:
                kw["columns"] = tuple(params["columns"])
            return QuaternionSeries.from_csv(path, **kw)
        return QuaternionSeries.from_netcdf(
            path, **({"variable": params["variable"]} if "variable" in params else {})
        )
    try:
        return cls(**params)
    except TypeError as exc:
        raise AttitudeError(f"attitude law {name!r}: {exc}") from None
