"""Execute every example notebook in notebooks/ and fail on any cell error.

Each notebook runs from a temporary copy, in a fresh ``python3`` kernel of the interpreter
running pytest, with a temporary working directory (the xclim practice: notebooks are run in
CI so that they never rot).  The saved outputs in the repository are refreshed with
``python notebooks/execute.py``.
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
    client = nbclient.NotebookClient(
        nb,
        timeout=CELL_TIMEOUT,
        kernel_name="python3",
        resources={"metadata": {"path": str(workdir)}},
    )
    try:
        client.execute()
    except (
        nbclient.exceptions.CellExecutionError
    ) as exc:  # show the failing cell, not the kernel stack
        pytest.fail(f"{path.name}: a cell failed\n{exc}", pytrace=False)
    errors = [
        o
        for cell in nb.cells
        if cell.cell_type == "code"
        for o in cell.get("outputs", [])
        if o.get("output_type") == "error"
    ]
    assert not errors, f"{path.name}: error outputs {[(e['ename'], e['evalue']) for e in errors]}"
    assert not list(workdir.iterdir()), f"{path.name} left files in its working directory"
