"""The bad-input tour's counts, printed at the end of the run (gathered from every xdist
worker), and the files its cases share."""

from __future__ import annotations

import bad_input_tour as tour
import pytest


def pytest_sessionfinish(session):
    workeroutput = getattr(session.config, "workeroutput", None)
    if workeroutput is not None:  # an xdist worker: hand the counts to the controller
        workeroutput["bad_input_counts"] = [[c, o, n] for (c, o), n in tour.COUNTS.items()]


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    for c, o, n in getattr(node, "workeroutput", {}).get("bad_input_counts", []):
        tour.COUNTS[(c, o)] += n


def pytest_terminal_summary(terminalreporter):
    for line in tour.table():
        terminalreporter.write_line(line)


@pytest.fixture(scope="session")
def secret_files(tmp_path_factory):
    """Files whose first line is the secret, one per suffix the tour gives files in."""
    d = tmp_path_factory.mktemp("secret")
    out = {}
    for suffix in (
        ".toml",
        ".nc",
        ".csv",
        ".ecsv",
        ".xml",
        ".json",
        ".tle",
        ".txt",
        ".stl",
        ".obj",
        ".ply",
        ".off",
        ".glb",
    ):
        p = d / f"secret{suffix}"
        p.write_text(f"{tour.SECRET}\n{tour.SECRET}\n", encoding="utf-8")
        out[suffix] = p
    return out
