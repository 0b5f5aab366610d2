"""Trajectories given as states instead of elements: tabulated states and CCSDS OEM files.

An :class:`Ephemeris` is the position and velocity of a spacecraft in the GCRS at the
times an :class:`~sbrdf_xr.observing.observation.Observation` asks for, like an
:class:`~sbrdf_xr.observing.orbits.Orbit`, but from data:

* :meth:`Ephemeris.from_states`: states (or positions only) at sample times, in a frame of
  :data:`FRAMES`, in one or more segments.  Between samples, positions are a piecewise
  cubic of time: with velocities, the cubic Hermite interpolant of the positions and
  velocities (:class:`scipy.interpolate.CubicHermiteSpline`); without, the not-a-knot
  cubic spline of the positions (:class:`scipy.interpolate.CubicSpline`), whose
  derivative gives the velocity.  A segment of one sample has no velocity (NaN): the
  laws that need it (nadir with its along-track axis) refuse it by name.  The error of
  that derivative is measured against SGP4's velocity in the tests (see
  ``tests/observing/test_tracking.py``).
* :func:`~sbrdf_xr.observing.oem_reader.read_oem`: a CCSDS Orbit Ephemeris Message
  (CCSDS 502.0-B-3), KVN or XML, read by the ``oem`` package, which also interpolates it
  as the message states (``INTERPOLATION`` Lagrange or Hermite of
  ``INTERPOLATION_DEGREE``; Lagrange of degree 5 when the message says nothing).
  Segments are kept apart: a time between two segments is refused
  (:class:`~sbrdf_xr.errors.EphemerisError`), as are epochs out of order and a step
  inside a segment more than ``max_step_factor`` times the segment's median step
  (a gap).

Frames (``REF_FRAME``): ``GCRF`` and ``ICRF`` (the GCRS axes), ``EME2000`` (rotated by
the IAU 2006 frame bias, skyfield's ``ICRS_to_J2000``), ``ITRF`` (any realisation, through
skyfield's ``itrs`` with polar motion, velocities with the Earth's rotation) and ``TEME``
(skyfield's SGP4 frame).  Times: ``UTC``, ``TAI``, ``TT``, ``GPS`` and ``TDB`` through
astropy's time scales.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from itertools import pairwise
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import EphemerisError, renamed_keywords
from ..units import to_unit
from .timescales import check_times, skyfield_time

__all__ = ["FRAMES", "TIME_SYSTEMS", "Ephemeris", "skyfield_frame", "to_gcrs"]


class _Bias:
    """The constant frame bias from the GCRS (ICRS axes) to EME2000, as a skyfield frame."""

    @staticmethod
    def rotation_at(t: Any) -> np.ndarray:
        from skyfield.framelib import ICRS_to_J2000

        return ICRS_to_J2000


def skyfield_frame(name: str) -> Any:
    """The skyfield frame of a CCSDS ``REF_FRAME`` name (None for the GCRS axes).

    Examples
    --------
    >>> skyfield_frame("GCRF") is None, type(skyfield_frame("ITRF2014")).__name__
    (True, 'itrs')
    >>> skyfield_frame("MOD")
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.EphemerisError: reference frame 'MOD': allowed: GCRF, ICRF, EME2000, ITRF, TEME
    """
    from skyfield.framelib import itrs
    from skyfield.sgp4lib import TEME

    key = name.upper()
    if key in ("GCRF", "ICRF"):
        return None
    if key == "EME2000":
        return _Bias()
    if key.startswith("ITRF") or key == "ITRS":
        return itrs
    if key == "TEME":
        return TEME
    raise EphemerisError(f"reference frame {name!r}: allowed: {', '.join(FRAMES)}")


#: Reference frames an ephemeris may be given in (ITRF stands for every realisation).
FRAMES = ("GCRF", "ICRF", "EME2000", "ITRF", "TEME")
#: Time systems of an OEM (astropy scale names).
TIME_SYSTEMS = {"UTC": "utc", "TAI": "tai", "TT": "tt", "GPS": "tai", "TDB": "tdb"}


@renamed_keywords(position_km="position", velocity_km_s="velocity")
def to_gcrs(
    frame: str, times: ArrayLike, position: ArrayLike, velocity: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """States in ``frame`` at UTC ``times`` as GCRS position [km] and velocity [km s-1].

    Through skyfield's :meth:`~skyfield.positionlib.ICRF.from_time_and_frame_vectors`
    (the rotation of the frame and, for the ITRF, its rate).

    Parameters
    ----------
    frame : str
        One of :data:`FRAMES`.
    times : array_like of datetime64
        UTC times.
    position : array_like, shape (n, 3)
        Position in ``frame`` [km].
    velocity : array_like, shape (n, 3)
        Velocity in ``frame`` [km s-1].

    Examples
    --------
    >>> t = np.array(["2024-03-17T01:20:00"], dtype="datetime64[ns]")
    >>> r, v = to_gcrs("ITRF", t, [[7000.0, 0.0, 0.0]], [[0.0, 0.0, 7.5]])
    >>> round(float(np.linalg.norm(r)), 9), round(float(np.linalg.norm(v)), 4)  # [km], [km s-1]
    (7000.0, 7.5174)
    """
    from skyfield.positionlib import ICRF
    from skyfield.units import Distance, Velocity

    t64 = check_times(times)
    r = np.asarray(to_unit(position, "km", "position"), dtype=np.float64).reshape(-1, 3)
    v = np.asarray(to_unit(velocity, "km / s", "velocity"), dtype=np.float64)
    v = v.reshape(-1, 3)
    fr = skyfield_frame(frame)
    if fr is None:
        return r.copy(), v.copy()
    t = skyfield_time(t64)
    pos = ICRF.from_time_and_frame_vectors(t, fr, Distance(km=r.T), Velocity(km_per_s=v.T))
    return pos.position.km.T.copy(), pos.velocity.km_per_s.T.copy()


def _segments(t64: np.ndarray, bounds: Sequence[int] | None) -> list[tuple[int, int]]:
    edges = [0, *(bounds or []), t64.size]
    return [(a, b) for a, b in pairwise(edges) if b > a]


def _tabulated(
    t64: np.ndarray, r: np.ndarray, v: np.ndarray | None, segs: list[tuple[int, int]]
) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """The evaluator of states tabulated in segments (see the module docstring)."""
    from scipy.interpolate import CubicHermiteSpline, CubicSpline

    fits: list[Any] = []
    for a, b in segs:
        secs = (t64[a:b] - t64[a]).astype(np.int64) / 1e9
        if b - a == 1:
            fits.append(None)
        elif v is not None:
            fits.append(CubicHermiteSpline(secs, r[a:b], v[a:b], axis=0))
        else:
            fits.append(CubicSpline(secs, r[a:b], axis=0, bc_type="not-a-knot"))

    def evaluate(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        pos = np.full((t.size, 3), np.nan)
        vel = np.full((t.size, 3), np.nan)
        for (a, b), fit in zip(segs, fits, strict=True):
            inside = (t >= t64[a]) & (t <= t64[b - 1])
            if fit is None:
                pos[inside] = r[a]
                if v is not None:
                    vel[inside] = v[a]
                continue
            s = (t[inside] - t64[a]).astype(np.int64) / 1e9
            pos[inside] = fit(s)
            vel[inside] = fit(s, 1)
            exact = np.searchsorted(t64[a:b], t[inside])  # samples are returned as given
            hit = (exact < b - a) & (t64[a:b][np.minimum(exact, b - a - 1)] == t[inside])
            idx = np.flatnonzero(inside)[hit]
            pos[idx] = r[a:b][exact[hit]]
        return pos, vel

    return evaluate


@dataclass(frozen=True)
class Ephemeris:
    """A spacecraft's GCRS states from data (tabulated states, a tracking table or an OEM).

    Build with :meth:`from_states`, :func:`~sbrdf_xr.observing.oem_reader.read_oem` (or
    :meth:`sbrdf_xr.observing.tracking.TrackingTable.ephemeris`); an
    :class:`~sbrdf_xr.observing.observation.Observation` takes it in place of an
    :class:`~sbrdf_xr.observing.orbits.Orbit`.

    Attributes
    ----------
    name : str
    spans : tuple of (datetime64, datetime64)
        The UTC intervals covered, one per segment.
    evaluate : callable
        ``evaluate(times) -> (position_km, velocity_km_s)`` in the GCRS, (n, 3) each.
    provenance : str
    method : str
        How states between samples and velocities are obtained (an attribute of the cube).

    Examples
    --------
    >>> t = np.array(["2024-03-17T01:20:00", "2024-03-17T01:20:10"], dtype="datetime64[ns]")
    >>> eph = Ephemeris.from_states(t, [[7000.0, 0.0, 0.0], [7000.0, 75.0, 0.0]],
    ...                             [[0.0, 7.5, 0.0], [0.0, 7.5, 0.0]], name="demo")
    >>> r, v = eph.state(np.array(["2024-03-17T01:20:04"], dtype="datetime64[ns]"))
    >>> r.round(6).tolist(), v.round(6).tolist()  # [km], [km s-1]
    ([[7000.0, 30.0, 0.0]], [[0.0, 7.5, 0.0]])
    """

    name: str
    spans: tuple[tuple[np.datetime64, np.datetime64], ...]
    evaluate: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
    provenance: str = ""
    method: str = ""

    @classmethod
    @renamed_keywords(position_km="position", velocity_km_s="velocity")
    def from_states(
        cls,
        times: ArrayLike,
        position: ArrayLike,
        velocity: ArrayLike | None = None,
        *,
        frame: str = "GCRF",
        segments: Sequence[int] | None = None,
        name: str = "ephemeris",
        provenance: str = "",
        method: str | None = None,
    ) -> Ephemeris:
        """An ephemeris from states (or positions) at strictly increasing UTC times.

        Parameters
        ----------
        times : array_like of datetime64
            UTC sample times, strictly increasing.
        position : array_like, shape (n, 3)
            Positions in ``frame`` [km].
        velocity : array_like, shape (n, 3), optional
            Velocities in ``frame`` [km s-1]; without them the velocity is the derivative
            of the positions' cubic spline.
        frame : str
            One of :data:`FRAMES`.
        segments : sequence of int, optional
            Indices where a new segment starts (no interpolation across them).
        name, provenance, method : str

        Examples
        --------
        >>> t = np.array(["2024-03-17T01:20:00", "2024-03-17T01:20:10", "2024-03-17T01:20:20",
        ...               "2024-03-17T01:20:30"], dtype="datetime64[ns]")
        >>> r = [[7000.0, 7.5 * s, 0.0] for s in (0.0, 10.0, 20.0, 30.0)]
        >>> eph = Ephemeris.from_states(t, r)
        >>> eph.state(t[1:2])[1].round(9).tolist()  # velocity from the spline [km s-1]
        [[0.0, 7.5, 0.0]]
        """
        t64 = check_times(times)
        r = np.asarray(to_unit(position, "km", "position"), dtype=np.float64)
        if r.shape != (t64.size, 3) or not np.all(np.isfinite(r)):
            raise EphemerisError(
                f"{name}: positions must be finite, shape ({t64.size}, 3); got {r.shape}"
            )
        v = None
        if velocity is not None:
            v = np.asarray(to_unit(velocity, "km / s", "velocity"), dtype=np.float64)
            if v.shape != r.shape or not np.all(np.isfinite(v)):
                raise EphemerisError(
                    f"{name}: velocities must be finite, shape {r.shape}; got {v.shape}"
                )
        fr = skyfield_frame(frame)
        if fr is not None:
            if v is None:
                raise EphemerisError(
                    f"{name}: positions in {frame} need velocities (or give them in GCRF)"
                )
            r, v = to_gcrs(frame, t64, r, v)
        segs = _segments(t64, segments)
        spans = tuple((t64[a], t64[b - 1]) for a, b in segs)
        if method is None:
            method = (
                "cubic Hermite interpolation of the positions and velocities per segment"
                if v is not None
                else "not-a-knot cubic spline of the positions per segment, velocity its "
                "derivative; none (NaN) for a segment of one sample"
            )
        return cls(name, spans, _tabulated(t64, r, v, segs), provenance, method)

    def check_covers(self, times: ArrayLike) -> NDArray[np.datetime64]:
        """The UTC ``times`` as datetime64[ns], checked to lie in a segment.

        Raises
        ------
        EphemerisError
            When a time lies outside every segment (the spans are listed).

        Examples
        --------
        >>> t = np.array(["2024-03-17T01:20:00", "2024-03-17T01:20:10"], dtype="datetime64[ns]")
        >>> eph = Ephemeris.from_states(t, [[7000.0, 0.0, 0.0], [7000.0, 75.0, 0.0]],
        ...                             [[0.0, 7.5, 0.0], [0.0, 7.5, 0.0]], name="demo")
        >>> eph.check_covers(t[:1])
        array(['2024-03-17T01:20:00.000000000'], dtype='datetime64[ns]')
        """
        t = check_times(times)
        covered = np.zeros(t.size, dtype=bool)
        for a, b in self.spans:
            covered |= (t >= a) & (t <= b)
        if not covered.all():
            bad = t[~covered][0]
            shown = ", ".join(f"{a} .. {b}" for a, b in self.spans[:5])
            more = f" (and {len(self.spans) - 5} more)" if len(self.spans) > 5 else ""
            raise EphemerisError(
                f"{self.name}: time {bad} is outside the ephemeris ({(~covered).sum()} of "
                f"{t.size} times are); it covers {shown}{more}"
            )
        return t

    def state(self, times: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """GCRS position [km] and velocity [km s-1] at UTC ``times``, (n, 3) each.

        Raises
        ------
        EphemerisError
            When a time lies outside every segment (the spans are listed).

        Examples
        --------
        >>> t = np.array(["2024-03-17T01:20:00", "2024-03-17T01:20:10"], dtype="datetime64[ns]")
        >>> eph = Ephemeris.from_states(t, [[7000.0, 0.0, 0.0], [7000.0, 75.0, 0.0]],
        ...                             [[0.0, 7.5, 0.0], [0.0, 7.5, 0.0]], name="demo")
        >>> eph.state(np.array(["2024-03-17T01:20:11"], dtype="datetime64[ns]"))
        Traceback (most recent call last):
            ...
        sbrdf_xr.errors.EphemerisError: demo: time 2024-03-17T01:20:11.000000000 is outside ...
        """
        t = self.check_covers(times)
        return self.evaluate(t)

    def attrs(self) -> dict[str, Any]:
        """Attributes an observation's cube carries for this ephemeris.

        Examples
        --------
        >>> t = np.array(["2024-03-17T01:20:00", "2024-03-17T01:20:10"], dtype="datetime64[ns]")
        >>> Ephemeris.from_states(t, np.zeros((2, 3)) + 7000.0, name="demo").attrs()["orbit_name"]
        'demo'
        """
        return {
            "orbit_name": self.name,
            "orbit_provenance": self.provenance,
            "propagator": f"ephemeris: {self.method}",
            "ephemeris_span": " ".join(f"{a}/{b}" for a, b in self.spans),
        }
