"""Reading a CCSDS Orbit Ephemeris Message into an :class:`~sbrdf_xr.observing.ephemeris.Ephemeris`.

The message is parsed and interpolated by the ``oem`` package (Lagrange or Hermite of the
degree the message states); this module checks what the package does not say plainly
(epochs out of order, named by line; gaps inside a segment; frames, centres and time
systems the package's states can be used in) and turns its states into GCRS states.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any, cast

import numpy as np

from ..errors import EphemerisError, input_file
from .ephemeris import FRAMES, TIME_SYSTEMS, Ephemeris, skyfield_frame, to_gcrs

__all__ = ["check_kvn_order", "is_oem_file", "read_oem"]

_EPOCH = re.compile(r"^\s*(\d{4}-\d{2}-\d{2}T[\d:.]+|\d{4}-\d{3}T[\d:.]+)\s")


def check_kvn_order(text: str, what: str) -> None:
    """Refuse data lines of a KVN ephemeris whose epochs do not increase, naming the line.

    Examples
    --------
    >>> check_kvn_order("META_STOP\\n2024-01-01T00:00:10 1 2 3\\n2024-01-01T00:00:05 1 2 3\\n",
    ...                 "demo")
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.EphemerisError: demo: line 3: epoch 2024-01-01T00:00:05 is not after ...
    """
    last = None
    for k, line in enumerate(text.splitlines(), start=1):
        if line.strip().startswith("META_START"):
            last = None
            continue
        m = _EPOCH.match(line + " ")
        if m is None:
            continue
        ep = m.group(1)
        if last is not None and ep <= last[0]:
            raise EphemerisError(
                f"{what}: line {k}: epoch {ep} is not after the previous one {last[0]} "
                f"(line {last[1]}); epochs of a segment must strictly increase"
            )
        last = (ep, k)


def is_oem_file(path: str | Path) -> bool:
    """Whether a file is a CCSDS OEM (by its suffix ``.oem`` or its first keyword).

    Examples
    --------
    >>> import tempfile
    >>> path = Path(tempfile.mkdtemp()) / "states.txt"
    >>> _ = path.write_text("CCSDS_OEM_VERS = 2.0\\n")
    >>> is_oem_file(path), is_oem_file(Path(tempfile.mkdtemp()) / "a.tle")
    (True, False)
    """
    p = Path(path)
    if p.suffix.lower() == ".oem":
        return True
    try:
        head = p.read_text(encoding="utf-8")[:400]
    except (OSError, UnicodeDecodeError):
        return False
    return "CCSDS_OEM_VERS" in head or "<oem" in head


def _utc64(times: Any) -> np.ndarray:
    return np.asarray(times.utc.datetime64, dtype="datetime64[ns]")


def _check_segment(seg: Any, where: str, factor: float) -> tuple[str, str]:
    meta = seg.metadata
    frame = str(meta["REF_FRAME"]).upper()
    try:
        skyfield_frame(frame)
    except EphemerisError:
        raise EphemerisError(
            f"{where}: REF_FRAME {frame!r} is not supported; allowed: {', '.join(FRAMES)}"
        ) from None
    center = str(meta["CENTER_NAME"]).upper()
    if center != "EARTH":
        raise EphemerisError(f"{where}: CENTER_NAME {center!r}; only EARTH is supported")
    system = str(meta["TIME_SYSTEM"]).upper()
    if system not in TIME_SYSTEMS:
        raise EphemerisError(f"{where}: TIME_SYSTEM {system!r}; allowed: {', '.join(TIME_SYSTEMS)}")
    states = list(seg.states)
    if len(states) < 2:
        raise EphemerisError(f"{where}: holds {len(states)} state; at least 2 are needed")
    from astropy.time import Time

    epochs = Time([s.epoch for s in states])
    steps = np.diff(epochs.tai.jd1 - epochs[0].tai.jd1 + (epochs.tai.jd2 - epochs[0].tai.jd2))
    steps = steps * 86400.0
    if np.any(steps <= 0):
        k = int(np.flatnonzero(steps <= 0)[0])
        raise EphemerisError(
            f"{where}: state {k + 2} ({states[k + 1].epoch.isot}) is not after state {k + 1}; "
            "epochs must strictly increase"
        )
    med = float(np.median(steps))
    if np.any(steps > factor * med):
        k = int(np.argmax(steps))
        raise EphemerisError(
            f"{where}: a gap of {steps[k]:.6g} s between states {k + 1} and {k + 2} "
            f"({states[k].epoch.isot} .. {states[k + 1].epoch.isot}), more than "
            f"{factor:g} x the median step {med:.6g} s; split it into segments or raise "
            "max_step_factor"
        )
    return frame, system


def read_oem(path: str | Path, *, max_step_factor: float = 10.0) -> Ephemeris:
    """An :class:`~sbrdf_xr.observing.ephemeris.Ephemeris` from a CCSDS OEM file (KVN or XML).

    Read and interpolated by the ``oem`` package as the message states (see the module
    docstring of :mod:`sbrdf_xr.observing.ephemeris`).

    Parameters
    ----------
    path : str or Path
    max_step_factor : float
        A step between two states of a segment longer than this many times the
        segment's median step is a gap [1].

    Raises
    ------
    EphemerisError
        For an unreadable file, states out of order, a gap, an unknown frame or time
        system, or a centre other than the Earth.

    Examples
    --------
    >>> import tempfile
    >>> path = Path(tempfile.mkdtemp()) / "demo.oem"
    >>> rows = [f"2024-03-17T01:20:{s:02d} {7000.0:.3f} {7.5 * s:.3f} 0 0 7.5 0"
    ...         for s in range(0, 60, 10)]
    >>> _ = path.write_text("\\n".join([
    ...     "CCSDS_OEM_VERS = 2.0", "CREATION_DATE = 2024-03-17T00:00:00",
    ...     "ORIGINATOR = DEMO", "META_START", "OBJECT_NAME = DEMO", "OBJECT_ID = 1",
    ...     "CENTER_NAME = EARTH", "REF_FRAME = GCRF", "TIME_SYSTEM = UTC",
    ...     "START_TIME = 2024-03-17T01:20:00", "STOP_TIME = 2024-03-17T01:20:50",
    ...     "META_STOP", *rows, ""]))
    >>> eph = read_oem(path)
    >>> eph.state(np.array(["2024-03-17T01:20:05"], dtype="datetime64[ns]"))[0].round(6)
    array([[7000. ,   37.5,    0. ]])
    >>> read_oem("no-such-file.oem")
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.EphemerisError: oem: file ...no-such-file.oem does not exist
    """
    from astropy.time import Time
    from oem import OrbitEphemerisMessage

    p = input_file(path, "oem", EphemerisError)
    text = p.read_text(encoding="utf-8", errors="replace")
    if not text.lstrip().startswith("<"):
        check_kvn_order(text, f"OEM {p}")
    try:
        msg = OrbitEphemerisMessage.open(p)
    except Exception as exc:  # the package raises bare ValueError / KeyError / XML errors
        raise EphemerisError(
            f"OEM {p}: cannot be read by the oem package ({type(exc).__name__}: {exc}); "
            "a truncated file, a missing keyword or a malformed data line"
        ) from None
    segs = list(msg.segments)
    if not segs:
        raise EphemerisError(f"OEM {p}: holds no segment")
    frames = [
        _check_segment(s, f"OEM {p} segment {i + 1}", max_step_factor) for i, s in enumerate(segs)
    ]
    spans = tuple((_utc64(s.useable_start_time)[()], _utc64(s.useable_stop_time)[()]) for s in segs)

    def evaluate(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        r = np.empty((t.size, 3))
        v = np.empty((t.size, 3))
        owner = np.full(t.size, -1)
        for i, (a, b) in enumerate(spans):
            owner[(owner < 0) & (t >= a) & (t <= b)] = i
        for i, seg in enumerate(segs):
            idx = np.flatnonzero(owner == i)
            if not idx.size:
                continue
            when = Time(t[idx], scale="utc")
            for j, k in enumerate(idx):
                st = seg(when[j])
                r[k], v[k] = st.position, st.velocity
            r[idx], v[idx] = to_gcrs(frames[i][0], t[idx], r[idx], v[idx])
        return r, v

    meta = segs[0].metadata
    method = segs[0].metadata.get("INTERPOLATION", "LAGRANGE") if hasattr(meta, "get") else ""
    degree = meta["INTERPOLATION_DEGREE"] if "INTERPOLATION_DEGREE" in meta else 5
    name = str(meta["OBJECT_NAME"])
    return Ephemeris(
        name,
        cast(Any, spans),
        evaluate,
        f"CCSDS OEM {p} (OBJECT_ID {meta['OBJECT_ID']}, REF_FRAME {frames[0][0]}, "
        f"TIME_SYSTEM {frames[0][1]}, {len(segs)} segment(s))",
        f"CCSDS OEM states interpolated by the oem package as the message states "
        f"({method} of degree {degree}), rotated to the GCRS by skyfield",
    )
