"""``python -m sbrdf_xr.cli`` runs the same command as the ``sbrdf-xr`` script."""

from __future__ import annotations

import subprocess
import sys


def test_the_package_runs_as_a_module():
    proc = subprocess.run(
        [sys.executable, "-m", "sbrdf_xr.cli", "catalog", "list"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "white-paint-a276" in proc.stdout


def test_an_unknown_command_is_a_usage_error_as_a_module():
    proc = subprocess.run(
        [sys.executable, "-m", "sbrdf_xr.cli", "no-such-command"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 2 and "invalid choice" in proc.stderr
