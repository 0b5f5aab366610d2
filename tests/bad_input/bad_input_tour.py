"""The bad-input tour: run one bad input, classify how it ended, count it.

Every case of ``tests/bad_input`` goes through :func:`run_case` (the Python API) or
:func:`run_cli` (``sbrdf_xr.cli.main``).  A case ends in one of

``named``
    a :class:`~sbrdf_xr.errors.SbrdfError` (the API) or one line ``sbrdf-xr: error: ...``
    and exit status 2 (the command line);
``usage``
    argparse's usage message and exit status 2;
``warned``
    a result, with a :class:`~sbrdf_xr.errors.SbrdfWarning` saying what is implausible;
``accepted``
    a result without a warning, for an input that is allowed (the case's own check of
    the result passed);
``accepted wrongly``
    a result without a warning for an input the case knows to be wrong;
``misleading``
    a named error whose message shows a file's contents, does not say where (the case's
    file or field), or says something else than the case expects (``match``);
``traceback``
    any other exception;
``hang``
    no end within the case's time limit.

The counts by category are printed at the end of the run (``conftest.py``).  The last
three outcomes fail the test, unless ``SBRDF_XR_BAD_INPUT_TOUR=count`` asks only to
count them (to measure a tree that is not clean yet).
"""

from __future__ import annotations

import contextlib
import os
import re
import resource
import signal
import threading
import time
import warnings
from collections import Counter
from collections.abc import Callable, Iterable, Iterator
from typing import Any

from hypothesis import HealthCheck, settings
from hypothesis_profiles import examples

from sbrdf_xr.errors import SbrdfError, SbrdfWarning

COUNTS: Counter[tuple[str, str]] = Counter()
OUTCOMES = (
    "named",
    "usage",
    "warned",
    "accepted",
    "accepted wrongly",
    "misleading",
    "traceback",
    "hang",
)
BAD = ("accepted wrongly", "misleading", "traceback", "hang")
#: Set to "count" to count bad outcomes without failing.
MODE_VARIABLE = "SBRDF_XR_BAD_INPUT_TOUR"
#: A file to which every bad outcome is appended, one line each (to read in count mode).
LOG_VARIABLE = "SBRDF_XR_BAD_INPUT_LOG"
#: A secret-looking first line written into files given as every kind of input; no
#: message may show it.
SECRET = "SECRET_TOKEN = hunter2-7f3c9a"
SECRET_MARK = "hunter2"
#: Memory a case may take beyond what the process holds (a bomb ends in MemoryError
#: instead of swapping a shared machine).
CASE_MEMORY = 6 * 2**30


def tour_settings(n: int) -> settings:
    """Hypothesis settings of a tour test drawing ``n`` examples (times the deep factor)."""
    return settings(
        max_examples=examples(n),
        deadline=None,
        database=None,
        suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
    )


class Hang(BaseException):
    """Raised in the main thread when a case runs past its time limit."""


def counting_only() -> bool:
    return os.environ.get(MODE_VARIABLE, "") == "count"


def unblock_fifos(paths: Iterable[Any]) -> Callable[[], None]:
    """An unblocker for cases that may block opening a FIFO for reading: it opens each
    for writing and closes it again (the reader sees the end of the file)."""

    def unblock() -> None:
        for p in paths:
            with contextlib.suppress(OSError):
                os.close(os.open(p, os.O_WRONLY | os.O_NONBLOCK))

    return unblock


@contextlib.contextmanager
def _time_limit(seconds: float, unblock: Callable[[], None] | None = None) -> Iterator[None]:
    """SIGALRM raises :class:`Hang` in Python code; a call blocked in C (reading a FIFO)
    is first released by ``unblock``, from a watchdog thread."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def fire(signum: int, frame: Any) -> None:
        raise Hang(f"no end within {seconds:g} s")

    watchdog = None
    if unblock is not None:
        watchdog = threading.Timer(seconds + 0.5, unblock)
        watchdog.daemon = True
        watchdog.start()
    old = signal.signal(signal.SIGALRM, fire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
        if watchdog is not None:
            watchdog.cancel()


def _data_bytes() -> int:
    try:
        with open("/proc/self/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("VmData:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return 0


@contextlib.contextmanager
def _memory_limit() -> Iterator[None]:
    try:
        soft, hard = resource.getrlimit(resource.RLIMIT_DATA)
        want = _data_bytes() + CASE_MEMORY
        if hard != resource.RLIM_INFINITY:
            want = min(want, hard)
        resource.setrlimit(resource.RLIMIT_DATA, (want, hard))
    except (ValueError, OSError):
        yield
        return
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_DATA, (soft, hard))


def _leaks(texts: Iterable[str], secret: str | None) -> bool:
    return secret is not None and any(secret in t for t in texts)


def _names_where(texts: list[str], where: Iterable[str]) -> bool:
    wanted = [w for w in where if w]
    return not wanted or any(w in t for t in texts for w in wanted)


def _named(
    category: str,
    text: str,
    label: str,
    where: list[str],
    secret: str | None,
    match: str | None,
) -> str:
    if _leaks([text], secret):
        return record(category, "misleading", f"{label}: the message shows {text!r}")
    if not _names_where([text], where):
        return record(category, "misleading", f"{label}: {text!r} names none of {where}")
    if match is not None and not re.search(match, text, re.IGNORECASE):
        return record(category, "misleading", f"{label}: {text!r} does not match {match!r}")
    return record(category, "named", text)


def record(category: str, outcome: str, detail: str) -> str:
    COUNTS[(category, outcome)] += 1
    log = os.environ.get(LOG_VARIABLE)
    if log and outcome in BAD:
        with open(log, "a", encoding="utf-8") as f:
            f.write(f"[{category}] {outcome}: {detail}\n")
    if outcome in BAD and not counting_only():
        raise AssertionError(f"[{category}] {outcome}: {detail}")
    return outcome


def run_case(
    category: str,
    fn: Callable[[], Any],
    *,
    wrong: bool = False,
    where: Iterable[str] = (),
    secret: str | None = SECRET_MARK,
    check: Callable[[Any], None] | None = None,
    timeout: float = 60.0,
    label: str = "",
    unblock: Callable[[], None] | None = None,
    match: str | None = None,
) -> str:
    """Run ``fn()`` (one bad input through the Python API) and classify its end.

    Parameters
    ----------
    category : str
        The tour's category, for the counts.
    fn : callable
        The case.
    wrong : bool
        The input is wrong (implausible): a result without a warning is "accepted wrongly".
    where : iterable of str
        The file or field the input was given in: an error message (or warning) must
        name one of them.
    secret : str or None
        Text written in the case's files that no message may show.
    check : callable, optional
        Uses the result (compiles its plan, ...) and asserts it is right; a named error
        it raises counts as the case's.
    timeout : float
        Seconds before the case counts as a hang.
    label : str
        Shown when the case fails.
    unblock : callable, optional
        Releases a call blocked in C at the time limit (:func:`unblock_fifos`).
    match : str, optional
        A regular expression (any case) that a named error's message must match.
    """
    where = list(where)
    start = time.monotonic()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            try:
                with _time_limit(timeout, unblock), _memory_limit():
                    result = fn()
                    if check is not None:  # the result in use (a plan compiled, ...)
                        check(result)
            finally:
                if time.monotonic() - start >= timeout:
                    raise Hang(f"no end within {timeout:g} s")
        except Hang as exc:
            return record(category, "hang", f"{label}: {exc}")
        except SbrdfError as exc:
            return _named(category, str(exc), label, where, secret, match)
        except AssertionError as exc:  # a result not fit for use: fine only if warned
            warned = [str(w.message) for w in caught if issubclass(w.category, SbrdfWarning)]
            if warned and not _leaks(warned, secret):
                return record(category, "warned", warned[0])
            return record(category, "accepted wrongly", f"{label}: {exc}")
        except Exception as exc:
            return record(category, "traceback", f"{label}: {type(exc).__name__}: {exc}")
        ours = [str(w.message) for w in caught if issubclass(w.category, SbrdfWarning)]
        if _leaks(ours, secret):
            return record(category, "misleading", f"{label}: a warning shows {ours!r}")
        if ours:
            return record(category, "warned", ours[0])
        if wrong:
            return record(category, "accepted wrongly", f"{label}: accepted without a warning")
        return record(category, "accepted", label)


def run_cli(
    category: str,
    argv: list[str],
    capsys: Any,
    *,
    wrong: bool = False,
    where: Iterable[str] = (),
    secret: str | None = SECRET_MARK,
    check: Callable[[], None] | None = None,
    timeout: float = 120.0,
    unblock: Callable[[], None] | None = None,
    match: str | None = None,
) -> str:
    """Run ``sbrdf-xr argv`` in this process and classify its end (see :func:`run_case`).

    A named error is one line ``sbrdf-xr: error: ...`` on stderr and exit status 2; a
    warning, a line of stderr holding ``Warning`` or ``warning``.
    """
    from sbrdf_xr.cli import main

    where = list(where)
    label = " ".join(argv)
    capsys.readouterr()
    start = time.monotonic()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            try:
                with _time_limit(timeout, unblock), _memory_limit():
                    status = main(argv)
            finally:
                if time.monotonic() - start >= timeout:
                    raise Hang(f"no end within {timeout:g} s")
        except Hang as exc:
            return record(category, "hang", f"{label}: {exc}")
        except SystemExit as exc:
            err = capsys.readouterr().err
            if exc.code == 2 and "usage:" in err:
                if _leaks([err], secret):
                    return record(category, "misleading", f"{label}: usage shows {err!r}")
                return record(category, "usage", err.strip().splitlines()[-1])
            return record(category, "traceback", f"{label}: SystemExit {exc.code}: {err}")
        except BaseException as exc:
            return record(category, "traceback", f"{label}: {type(exc).__name__}: {exc}")
    out = capsys.readouterr()
    ours = [str(w.message) for w in caught if issubclass(w.category, SbrdfWarning)]
    texts = [out.err, *ours]
    if _leaks([*texts, out.out], secret):
        return record(category, "misleading", f"{label}: the output shows the secret")
    lines = [ln for ln in out.err.splitlines() if ln.strip()]
    if status != 0:
        if status == 2 and lines and lines[-1].startswith("sbrdf-xr: error: "):
            if "Traceback" in out.err:
                return record(category, "traceback", f"{label}: {out.err}")
            return _named(category, lines[-1], label, where, secret, match)
        return record(category, "traceback", f"{label}: status {status}: {out.err}")
    if check is not None:
        try:
            check()
        except AssertionError as exc:
            return record(category, "accepted wrongly", f"{label}: {exc}")
    if ours or any("warning" in ln.lower() for ln in lines):
        return record(category, "warned", (ours or lines)[0])
    if wrong:
        return record(category, "accepted wrongly", f"{label}: accepted without a warning")
    return record(category, "accepted", label)


def table() -> list[str]:
    """The counts by category, one line each, and the total."""
    cats = sorted({c for c, _ in COUNTS})
    if not cats:
        return []
    width = max(22, *(len(c) for c in cats))
    lines = [
        "",
        f"{'bad-input tour':<{width}}"
        + "".join(f"{o:>10}" if len(o) < 10 else f"{o:>18}" for o in ("cases", *OUTCOMES)),
    ]
    total: Counter[str] = Counter()
    for c in [*cats, "total"]:
        row = total if c == "total" else Counter({o: COUNTS[(c, o)] for o in OUTCOMES})
        if c != "total":
            total.update(row)
        n = sum(row[o] for o in OUTCOMES)
        lines.append(
            f"{c:<{width}}"
            + "".join(
                f"{v:>10}" if len(o) < 10 else f"{v:>18}"
                for o, v in (("cases", n), *((o, row[o]) for o in OUTCOMES))
            )
        )
    return lines
