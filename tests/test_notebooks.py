"""Execute every example notebook in notebooks/ and fail on any cell error or unreadable figure.

Each notebook runs from a temporary copy, in a fresh ``python3`` kernel of the interpreter
running pytest, with a temporary working directory (the xclim practice: notebooks are run in
CI so that they never rot).  Every figure the notebook shows is held to
:func:`sbrdf_xr.plot.figure_problems` (no overlapping text, axis labels with units) as it is
rendered: a cell put before the notebook's own wraps matplotlib's ``print_figure`` (through
which the inline backend renders), and a cell after them reports what it found.  The saved
outputs in the repository are refreshed with ``python notebooks/execute.py``.
"""

from __future__ import annotations

import json
import os
import shutil
import sys
from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")
pytest.importorskip("ipykernel")
pytest.importorskip("distributed")  # notebook 04 starts a LocalCluster

ROOT = Path(__file__).resolve().parent.parent
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
#: Seconds a single cell may run (generous: the notebooks take ~5-25 s each on two cores).
CELL_TIMEOUT = 300


#: Run first in the kernel: check every figure as the inline backend renders it.  Text
#: outside the figure is allowed (the inline backend saves with ``bbox_inches="tight"``).
CHECK_FIGURES = """\
import matplotlib.backend_bases as _backend_bases
from sbrdf_xr.plot import figure_problems as _figure_problems

_FIGURES = {"checked": 0, "problems": []}
_CELL = [0]  # the notebook's code cell being run, from 1
_print_figure = _backend_bases.FigureCanvasBase.print_figure


def _next_cell(*args):
    _CELL[0] += 1


def _checked_print_figure(self, *args, **kwargs):
    _FIGURES["checked"] += 1
    for problem in _figure_problems(self.figure, inside=False):
        _FIGURES["problems"].append(f"code cell {_CELL[0]}: {problem}")
    return _print_figure(self, *args, **kwargs)


get_ipython().events.register("pre_run_cell", _next_cell)
_backend_bases.FigureCanvasBase.print_figure = _checked_print_figure
"""
#: Run last: what was found, as one JSON line.
REPORT_FIGURES = "import json as _json\nprint(_json.dumps(_FIGURES))"


def _execute(nb, workdir: Path) -> dict:
    """Run ``nb`` with the figure check around it; the check's report (cells fail the test)."""
    nb.cells.insert(0, nbformat.v4.new_code_cell(CHECK_FIGURES))
    nb.cells.append(nbformat.v4.new_code_cell(REPORT_FIGURES))
    client = nbclient.NotebookClient(
        nb,
        timeout=CELL_TIMEOUT,
        kernel_name="python3",
        resources={"metadata": {"path": str(workdir)}},
    )
    try:
        client.execute()
    except nbclient.exceptions.CellExecutionError as exc:  # the failing cell, not the stack
        pytest.fail(f"a cell failed\n{exc}", pytrace=False)
    shown = [o for o in nb.cells[-1].outputs if o.get("output_type") == "stream"]
    return json.loads("".join(o["text"] for o in shown))


@pytest.fixture(scope="module", autouse=True)
def _kernel_environment(tmp_path_factory):
    """Run the kernel on this interpreter, with the package importable and no display.

    A ``python3`` kernel spec pointing at ``sys.executable`` is put first on ``JUPYTER_PATH``
    (so an unrelated ``python3`` spec installed elsewhere is not picked up), and the
    repository root is put on ``PYTHONPATH`` (the kernel and the Dask workers of notebook 04
    inherit the environment), so a source checkout works without installing the package.
    """
    jupyter = tmp_path_factory.mktemp("jupyter")
    spec = jupyter / "kernels" / "python3"
    spec.mkdir(parents=True)
    (spec / "kernel.json").write_text(
        json.dumps(
            {
                "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
                "display_name": "Python 3 (pytest)",
                "language": "python",
            }
        )
    )
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(
            "JUPYTER_PATH",
            os.pathsep.join(p for p in (str(jupyter), os.environ.get("JUPYTER_PATH")) if p),
        )
        mp.setenv(
            "PYTHONPATH", os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH")) if p)
        )
        mp.setenv("MPLBACKEND", "module://matplotlib_inline.backend_inline")
        yield


def test_there_are_notebooks():
    assert NOTEBOOKS, "no notebooks found in notebooks/"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_runs(path, tmp_path):
    copy = tmp_path / path.name
    shutil.copy(path, copy)
    nb = nbformat.read(copy, as_version=4)
    workdir = tmp_path / "cwd"
    workdir.mkdir()
    figures = _execute(nb, workdir)
    errors = [
        o
        for cell in nb.cells
        if cell.cell_type == "code"
        for o in cell.get("outputs", [])
        if o.get("output_type") == "error"
    ]
    assert not errors, f"{path.name}: error outputs {[(e['ename'], e['evalue']) for e in errors]}"
    images = sum("image/png" in o.get("data", {}) for c in nb.cells for o in c.get("outputs", []))
    assert figures["checked"] == images > 0, f"{path.name}: {images} images, {figures} checked"
    assert not figures["problems"], f"{path.name}: figures hard to read:\n" + "\n".join(
        figures["problems"]
    )
    assert not list(workdir.iterdir()), f"{path.name} left files in its working directory"


def test_the_figure_check_sees_a_bad_figure(tmp_path):
    nb = nbformat.v4.new_notebook()
    nb.cells.append(
        nbformat.v4.new_code_cell(
            "import matplotlib.pyplot as plt\n"
            "fig, ax = plt.subplots()\n"
            "ax.plot([0, 1], [0, 1])\n"
            "ax.set_xlabel('wavelength')\n"
            "ax.set_ylabel('albedo [1]')"
        )
    )
    figures = _execute(nb, tmp_path)
    assert figures == {
        "checked": 1,
        "problems": ["code cell 1: x axis of axes 0: label 'wavelength' has no unit in brackets"],
    }
