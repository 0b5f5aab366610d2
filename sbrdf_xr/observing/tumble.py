"""Torque-free tumbling: Euler's equations of a rigid body, integrated.

:class:`Tumble` integrates Euler's equations ``I dω/dt = -ω x (I ω)`` and the attitude
kinematics from a state at an epoch (scipy ``solve_ivp``, DOP853, ``rtol`` =
:data:`TUMBLE_RTOL`), for an inertia tensor given or computed from a spacecraft mesh at
uniform density (:meth:`Tumble.from_spacecraft`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import AttitudeError, renamed_fields, renamed_keywords
from ..units import to_unit
from .attitude import AttitudeLaw
from .frames import Context, check_epoch, check_quaternion, seconds_since

__all__ = ["TUMBLE_RTOL", "Tumble"]

#: The most turns a tumble is integrated over (the work grows with them: about 2 s a
#: thousand turns at the default tolerance).
MAX_TUMBLE_TURNS = 1e4
#: Relative tolerance of the tumble integration (scipy ``solve_ivp``, DOP853).
TUMBLE_RTOL = 1e-12


def _inertia(value: ArrayLike) -> NDArray[np.float64]:
    value = to_unit(value, "kg m2", "inertia")
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise AttitudeError(
            f"tumble inertia: got {value!r}; expected 3 principal moments or a 3x3 tensor"
        ) from None
    if arr.shape == (3,):
        arr = np.diag(arr)
    if arr.shape != (3, 3) or not np.all(np.isfinite(arr)):
        raise AttitudeError(
            "tumble inertia: expected 3 principal moments or a finite 3x3 tensor [kg m2], "
            f"got shape {arr.shape}"
        )
    if not np.allclose(arr, arr.T, rtol=1e-9, atol=1e-12 * np.abs(arr).max()):
        raise AttitudeError("tumble inertia: the tensor must be symmetric")
    moments = np.linalg.eigvalsh(arr)
    if moments[0] <= 0:
        raise AttitudeError(
            f"tumble inertia: principal moments must be positive, got {moments.tolist()}"
        )
    if moments[0] + moments[1] < moments[2] * (1 - 1e-9):
        raise AttitudeError(
            f"tumble inertia: principal moments {moments.tolist()} break the triangle inequality "
            "I1 + I2 >= I3 of a physical body"
        )
    return 0.5 * (arr + arr.T)


@renamed_fields(omega_deg_s="omega")
@dataclass(frozen=True)
class Tumble(AttitudeLaw):
    """Torque-free rigid-body motion (Euler's equations).

    ``I dω/dt = -ω x (I ω)`` for the body angular velocity ``ω``, with the attitude
    kinematics ``dq/dt = ½ q ⊗ (ω, 0)`` (body -> inertial, scalar-last; Markley & Crassidis,
    *Fundamentals of Spacecraft Attitude Determination and Control*, 2014, eqs. 3.20 and
    3.81), integrated from the epoch forward and backward with
    :func:`scipy.integrate.solve_ivp` (DOP853, ``rtol`` = :data:`TUMBLE_RTOL`).  Kinetic
    energy ``½ ω·Iω`` and the inertial angular momentum ``R I ω`` are invariants of the
    exact motion; :meth:`states` lets one check them.

    Parameters
    ----------
    inertia : array_like, shape (3,) or (3, 3)
        Inertia tensor about the centre of mass in the body frame [kg m2] (or its
        principal moments), e.g. :meth:`sbrdf_xr.body.spacecraft.Spacecraft.inertia`.
    omega : array_like, shape (3,)
        Body angular velocity at the epoch [degree s-1].
    initial : array_like, shape (4,)
        Attitude at the epoch.
    epoch : datetime64 or str, optional
        Time of the initial state (default: the start of the observation).

    Examples
    --------
    >>> law = Tumble(inertia=(1.0, 2.0, 3.0), omega=(0.0, 0.0, 10.0))  # a principal axis
    >>> omega, q = law.states([0.0, 9.0])
    >>> np.round(np.degrees(omega), 9) + 0.0  # steady spin about z [degree s-1]
    array([[ 0.,  0., 10.],
           [ 0.,  0., 10.]])
    >>> np.round(q[-1], 9)  # 90 degree about z after 9 s
    array([0.        , 0.        , 0.70710678, 0.70710678])
    """

    law_name: ClassVar[str] = "tumble"
    law_parameters: ClassVar[tuple[str, ...]] = ("inertia", "omega_deg_s", "initial", "epoch")
    table_keys: ClassVar[Mapping[str, str]] = {"omega_deg_s": "omega"}

    inertia: Any = (1.0, 1.0, 1.0)
    omega: Any = (0.0, 0.0, 1.0)
    initial: Any = (0.0, 0.0, 0.0, 1.0)
    epoch: Any = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "inertia", _inertia(self.inertia))
        w = np.asarray(to_unit(self.omega, "deg / s", "omega"), dtype=np.float64)
        if w.shape != (3,) or not np.all(np.isfinite(w)):
            raise AttitudeError(
                f"tumble omega: expected 3 finite body rates [degree s-1], got {self.omega!r}"
            )
        object.__setattr__(self, "omega", w)
        object.__setattr__(self, "initial", check_quaternion(self.initial, "tumble initial"))
        object.__setattr__(self, "epoch", check_epoch(self.epoch))

    @classmethod
    @renamed_keywords(density_kg_m3="density", omega_deg_s="omega")
    def from_spacecraft(
        cls,
        spacecraft: Any,
        density: float,
        omega: ArrayLike,
        initial: ArrayLike = (0.0, 0.0, 0.0, 1.0),
        epoch: Any = None,
    ) -> Tumble:
        """A tumble of a spacecraft filled at uniform density (``spacecraft.inertia``).

        Parameters
        ----------
        spacecraft : sbrdf_xr.body.spacecraft.Spacecraft
            The body (a closed mesh).
        density : float
            Uniform density [kg m-3].
        omega, initial, epoch
            As for :class:`Tumble`.

        Examples
        --------
        >>> import trimesh
        >>> from sbrdf_xr.body.spacecraft import Spacecraft
        >>> cube = Spacecraft(trimesh.creation.box(extents=(0.1, 0.1, 0.1)), ["paint"] * 12)
        >>> law = Tumble.from_spacecraft(cube, 1000.0, (5.0, 0.0, 0.0))
        >>> np.round(np.diag(law.inertia), 9)  # a 1 kg cube of side 0.1 m [kg m2]
        array([0.00166667, 0.00166667, 0.00166667])
        """
        density = to_unit(density, "kg m-3", "density")
        return cls(spacecraft.inertia(density), omega, initial, epoch)

    def _rhs_function(self):
        """Right-hand side of Euler's equations and the kinematics, on plain floats (fast)."""
        (a, b, c), (d, e, f), (g, h, k) = self.inertia.tolist()
        (ia, ib, ic), (id_, ie, if_), (ig, ih, ik) = np.linalg.inv(self.inertia).tolist()

        def rhs(t: float, y: np.ndarray) -> list[float]:
            wx, wy, wz, x, yq, z, s = y.tolist()
            lx, ly, lz = (
                a * wx + b * wy + c * wz,
                d * wx + e * wy + f * wz,
                g * wx + h * wy + k * wz,
            )
            # I dw/dt = -w x (I w) = (I w) x w
            tx, ty, tz = ly * wz - lz * wy, lz * wx - lx * wz, lx * wy - ly * wx
            return [
                ia * tx + ib * ty + ic * tz,
                id_ * tx + ie * ty + if_ * tz,
                ig * tx + ih * ty + ik * tz,
                # dq/dt = 1/2 q (x) (w, 0), scalar-last Hamilton product.
                0.5 * (s * wx + yq * wz - z * wy),
                0.5 * (s * wy + z * wx - x * wz),
                0.5 * (s * wz + x * wy - yq * wx),
                -0.5 * (x * wx + yq * wy + z * wz),
            ]

        return rhs

    def states(
        self, times: ArrayLike, context: Context | None = None
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Body angular velocity [rad s-1] and attitude at ``times``.

        Returns
        -------
        omega : ndarray, shape (n, 3)
        quaternion : ndarray, shape (n, 4)

        Examples
        --------
        >>> omega, q = Tumble((1.0, 2.0, 3.0), (10.0, 0.0, 0.0)).states([0.0, 1.0, 2.0])
        >>> omega.shape, q.shape, np.round(np.linalg.norm(q, axis=1), 12)
        ((3, 3), (3, 4), array([1., 1., 1.]))
        """
        from scipy.integrate import solve_ivp

        t = seconds_since(times, self.epoch, context)
        rhs = self._rhs_function()
        y0 = np.concatenate([np.radians(self.omega), self.initial])
        span = float(np.max(np.abs(t))) if t.size else 0.0
        turns = float(np.linalg.norm(self.omega)) * span / 360.0
        if not turns <= MAX_TUMBLE_TURNS:  # the integrator's work grows with the turns
            raise AttitudeError(
                f"tumble omega: {turns:.3g} turns at |omega| "
                f"{float(np.linalg.norm(self.omega)):.3g} degree s-1 over {span:.3g} s "
                f"from the epoch; allowed at most {MAX_TUMBLE_TURNS:g} turns (slower rates, "
                "or a shorter window nearer the epoch)"
            )
        out = np.empty((t.size, 7))
        scale = max(float(np.linalg.norm(y0[:3])), 1e-12)
        atol = np.concatenate([np.full(3, 1e-14 * scale), np.full(4, 1e-14)])
        for sel in (t >= 0, t < 0):
            if not sel.any():
                continue
            ts = t[sel]
            order = np.argsort(ts) if ts[0] >= 0 else np.argsort(-ts)
            tq = ts[order]
            if np.all(tq == 0):
                out[np.flatnonzero(sel)] = y0
                continue
            sol = solve_ivp(
                rhs,
                (0.0, float(tq[-1])),
                y0,
                method="DOP853",
                t_eval=tq,
                rtol=TUMBLE_RTOL,
                atol=atol,
            )
            if not sol.success:  # pragma: no cover - smooth right-hand side
                raise AttitudeError(f"tumble: integration failed: {sol.message}")
            idx = np.flatnonzero(sel)[order]
            out[idx] = sol.y.T
        q = out[:, 3:] / np.linalg.norm(out[:, 3:], axis=1, keepdims=True)
        return out[:, :3], q

    def quaternions(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        return self.states(times, context)[1]
