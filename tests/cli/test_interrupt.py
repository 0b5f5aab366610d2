"""Ctrl-C while the ``sbrdf-xr`` command starts (the package importing, before ``main``'s
handler is there) ends in one line and exit status 130, as during the command."""

from __future__ import annotations

import subprocess
import sys
import textwrap

START = textwrap.dedent(
    """
    import os, signal, sys, time
    sys.argv[0] = "/usr/local/bin/sbrdf-xr"  # as the command's own script
    import sbrdf_xr  # its first line installs the start-up handler
    {then}
    os.kill(os.getpid(), signal.SIGINT)  # a Ctrl-C at this instant
    time.sleep(30)
    print("not interrupted")
    """
)


def run(then: str) -> subprocess.CompletedProcess:
    code = START.format(then=then)
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)


def test_ctrl_c_while_the_command_starts_exits_130_with_one_line():
    r = run("")
    assert r.returncode == 130 and r.stderr == "sbrdf-xr: interrupted\n", r.stderr[-2000:]
    assert "not interrupted" not in r.stdout


def test_main_takes_the_interrupt_over():
    """Once ``main`` runs, an interrupt is a KeyboardInterrupt again (main's own handler
    prints the line naming the ``.part`` to resume)."""
    r = run(
        "from sbrdf_xr.cli import main\n"
        "assert main(['knobs']) == 0\n"
        "assert signal.getsignal(signal.SIGINT) is signal.default_int_handler\n"
        "try:\n    os.kill(os.getpid(), signal.SIGINT); time.sleep(30)\n"
        "except KeyboardInterrupt:\n    print('KeyboardInterrupt'); sys.exit(0)"
    )
    assert r.returncode == 0 and "KeyboardInterrupt" in r.stdout, r.stderr[-2000:]


def test_a_python_session_keeps_its_own_interrupt():
    code = "import signal, sbrdf_xr; print(signal.getsignal(2) is signal.default_int_handler)"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.stdout.strip() == "True", r.stderr[-2000:]
