"""Attitude from a CCSDS Attitude Ephemeris Message (AEM, CCSDS 504.0-B-2), as a quaternion series.

The message (KVN or XML) is parsed by the ``ccsds-ndm`` package (an optional dependency,
GPL-3.0: ``pip install ccsds-ndm``); :func:`read_aem` checks it and returns a
:class:`~sbrdf_xr.observing.series.QuaternionSeries` (slerp between the records), and the
law ``aem`` (:class:`AemSeries`) reads one from a scene file's ``[observation.attitude]``
table (``law = "aem"``, ``path = "..."``).

Convention: ``ATTITUDE_DIR = A2B`` with the inertial frame as ``REF_FRAME_A`` and the body
as ``REF_FRAME_B`` is the attitude quaternion of Shuster (1993, J. Astronaut. Sci. 41,
439), ``v_B = A(q) v_A``: its active rotation takes body vectors into the inertial frame,
the convention of :mod:`sbrdf_xr.observing.attitude`; ``B2A`` (or the inertial frame as
``REF_FRAME_B``) is its inverse.  ``QUATERNION_TYPE`` (scalar ``FIRST`` or ``LAST``) is
applied by ``ccsds-ndm``.
Inertial frames: ``GCRF``, ``ICRF`` and ``EME2000`` (turned to the GCRS by the frame bias).
Only ``ATTITUDE_TYPE = QUATERNION`` records are read.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from scipy.spatial.transform import Rotation

from ..errors import EphemerisError, input_file
from .oem_reader import check_kvn_order
from .series import QuaternionSeries

__all__ = ["INERTIAL_FRAMES", "AemSeries", "read_aem"]

#: Inertial frames an AEM may refer its quaternions to.
INERTIAL_FRAMES = ("GCRF", "ICRF", "EME2000")


def _value(x: Any) -> str:
    return str(getattr(x, "value", x)).upper()


def _quaternions(seg: Any, where: str) -> tuple[np.ndarray, np.ndarray]:
    meta = seg.metadata
    kind = _value(meta.attitude_type)
    if kind != "QUATERNION":
        raise EphemerisError(f"{where}: ATTITUDE_TYPE {kind}; only QUATERNION is read")
    states = list(getattr(seg.data, "attitude_state", []) or [])
    rows: list[list[float]] = []
    epochs: list[Any] = []
    for s in states:
        qs = s.quaternion_state
        if qs is None or qs.quaternion is None:
            raise EphemerisError(f"{where}: record {len(rows) + 1} holds no quaternion")
        q = qs.quaternion
        rows.append([q.q1, q.q2, q.q3, q.qc])
        epochs.append(qs.epoch)
    if len(rows) < 2:
        raise EphemerisError(f"{where}: holds {len(rows)} record(s); at least 2 are needed")
    try:
        t = np.array([np.datetime64(str(e).rstrip("Z"), "ns") for e in epochs])
        q = np.asarray(rows, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise EphemerisError(f"{where}: a record cannot be read ({exc})") from None
    return t, q


def _to_body_gcrs(meta: Any, q: np.ndarray, where: str) -> np.ndarray:
    a, b = str(meta.ref_frame_a).upper(), str(meta.ref_frame_b).upper()
    direction = _value(meta.attitude_dir).replace("_", "")
    if a in INERTIAL_FRAMES:
        frame, invert = a, direction == "B2A"
    elif b in INERTIAL_FRAMES:
        frame, invert = b, direction == "A2B"
    else:
        raise EphemerisError(
            f"{where}: neither REF_FRAME_A {a!r} nor REF_FRAME_B {b!r} is an inertial frame "
            f"this reader knows ({', '.join(INERTIAL_FRAMES)})"
        )
    rot = Rotation.from_quat(q)
    if invert:
        rot = rot.inv()
    if frame == "EME2000":
        from skyfield.framelib import ICRS_to_J2000

        rot = Rotation.from_matrix(ICRS_to_J2000.T) * rot
    return rot.as_quat().reshape(-1, 4)


def _check_blocks(text: str, what: str) -> None:
    """Every ``DATA_START`` of a KVN message closed by a ``DATA_STOP`` (else truncated)."""
    opened = None
    for k, line in enumerate(text.splitlines(), start=1):
        key = line.strip()
        if key == "DATA_START":
            opened = k
        elif key == "DATA_STOP":
            opened = None
    if opened is not None:
        raise EphemerisError(f"{what}: truncated: the DATA_START of line {opened} has no DATA_STOP")


def read_aem(path: str | Path) -> QuaternionSeries:
    """The attitude (body -> GCRS) of an AEM file as a :class:`QuaternionSeries`.

    Raises
    ------
    EphemerisError
        For a file ``ccsds-ndm`` cannot parse (a truncated one), records out of order,
        records that stop before the metadata's ``STOP_TIME`` (truncated data), fewer than
        two records, another attitude type, or no inertial frame.

    Examples
    --------
    >>> import tempfile
    >>> path = Path(tempfile.mkdtemp()) / "demo.aem"
    >>> _ = path.write_text("\\n".join([
    ...     "CCSDS_AEM_VERS = 1.0", "CREATION_DATE = 2024-03-17T00:00:00", "ORIGINATOR = DEMO",
    ...     "META_START", "OBJECT_NAME = DEMO", "OBJECT_ID = 1", "REF_FRAME_A = GCRF",
    ...     "REF_FRAME_B = SC_BODY_1", "ATTITUDE_DIR = A2B", "TIME_SYSTEM = UTC",
    ...     "START_TIME = 2024-03-17T01:20:00", "STOP_TIME = 2024-03-17T01:20:10",
    ...     "ATTITUDE_TYPE = QUATERNION", "QUATERNION_TYPE = LAST", "META_STOP",
    ...     "DATA_START", "2024-03-17T01:20:00 0 0 0 1", "2024-03-17T01:20:10 0 0 1 0",
    ...     "DATA_STOP", ""]))
    >>> law = read_aem(path)
    >>> t = np.array(["2024-03-17T01:20:05"], dtype="datetime64[ns]")
    >>> np.round(law.quaternions(t), 6)  # halfway: 90 degree about z
    array([[0.      , 0.      , 0.707107, 0.707107]])
    """
    try:
        from ccsds_ndm.ndm_io import NdmIo
    except ImportError:
        raise EphemerisError(
            "reading an AEM needs the ccsds-ndm package: pip install ccsds-ndm"
        ) from None
    p = input_file(path, "aem", EphemerisError)
    text = p.read_text(encoding="utf-8", errors="replace")
    if not text.lstrip().startswith("<"):
        check_kvn_order(text, f"AEM {p}")
        _check_blocks(text, f"AEM {p}")
    try:
        msg = NdmIo().from_string(text)
    except Exception as exc:  # the parser raises its own error types
        raise EphemerisError(
            f"AEM {p}: cannot be parsed by ccsds-ndm ({type(exc).__name__}: {exc}); "
            "a truncated file or a missing keyword"
        ) from None
    segs = list(getattr(getattr(msg, "body", None), "segment", []) or [])
    if type(msg).__name__ != "Aem" or not segs:
        raise EphemerisError(
            f"AEM {p}: holds no AEM segment (parsed as {type(msg).__name__}): empty or truncated"
        )
    times, quats = [], []
    for i, seg in enumerate(segs):
        where = f"AEM {p} segment {i + 1}"
        t, q = _quaternions(seg, where)
        if not np.all(np.diff(t) > np.timedelta64(0, "ns")):
            raise EphemerisError(f"{where}: epochs must strictly increase")
        stop = np.datetime64(str(seg.metadata.stop_time).rstrip("Z"), "ns")
        if t[-1] < stop:
            raise EphemerisError(
                f"{where}: truncated: the last record is at {t[-1]}, the metadata's STOP_TIME "
                f"{stop}"
            )
        times.append(t)
        quats.append(_to_body_gcrs(seg.metadata, q, where))
    t_all, q_all = np.concatenate(times), np.concatenate(quats)
    if not np.all(np.diff(t_all) > np.timedelta64(0, "ns")):
        raise EphemerisError(f"AEM {p}: segments overlap or are out of order")
    return QuaternionSeries(t_all, q_all)


@dataclass(frozen=True)
class AemSeries(QuaternionSeries):
    """The attitude law ``aem``: a :class:`QuaternionSeries` read from an AEM file.

    Examples
    --------
    >>> from sbrdf_xr.observing.attitude import ATTITUDE_LAWS
    >>> ATTITUDE_LAWS["aem"][1]
    ('path',)
    """

    law_name: ClassVar[str] = "aem"
    law_parameters: ClassVar[tuple[str, ...]] = ("path",)

    @classmethod
    def from_table(cls, params: dict[str, Any]) -> QuaternionSeries:
        """Read ``params["path"]`` (:func:`read_aem`).

        Examples
        --------
        >>> AemSeries.from_table({})
        Traceback (most recent call last):
            ...
        sbrdf_xr.errors.EphemerisError: attitude law 'aem': needs a path (an AEM file)
        """
        if "path" not in params:
            raise EphemerisError("attitude law 'aem': needs a path (an AEM file)")
        return read_aem(params["path"])
