"""Re-execute the example notebooks in place, so that their saved outputs are current.

Usage (from the repository root)::

    python notebooks/execute.py                   # every notebook in notebooks/
    python notebooks/execute.py 03_colour_photometry.ipynb ...

Each notebook runs top to bottom in a fresh ``python3`` kernel of the running interpreter
(working directory: a temporary directory, so nothing is left behind), and is written back
with its outputs only if every cell succeeded.  The repository root is put on the kernel's
``PYTHONPATH`` so that a source checkout works without installing the package.  Needs
``nbformat``, ``nbclient`` and ``ipykernel``: ``pip install ".[notebooks]"`` (or the
``test`` extra).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

import nbformat
from nbclient import NotebookClient

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
#: Seconds a single cell may run before the execution is abandoned.
CELL_TIMEOUT = 300


@contextlib.contextmanager
def kernel_environment() -> Iterator[None]:
    """Run kernels on this interpreter, with the package importable and no display.

    A ``python3`` kernel spec pointing at ``sys.executable`` goes first on ``JUPYTER_PATH``;
    the repository root goes on ``PYTHONPATH`` (kernels and Dask workers inherit it).
    """
    saved = {k: os.environ.get(k) for k in ("JUPYTER_PATH", "PYTHONPATH", "MPLBACKEND")}
    with tempfile.TemporaryDirectory(prefix="sbrdf-jupyter-") as jupyter:
        spec = Path(jupyter) / "kernels" / "python3"
        spec.mkdir(parents=True)
        (spec / "kernel.json").write_text(json.dumps({
            "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
            "display_name": "Python 3", "language": "python",
        }))
        os.environ["JUPYTER_PATH"] = os.pathsep.join(p for p in (jupyter, saved["JUPYTER_PATH"]) if p)
        os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT), saved["PYTHONPATH"]) if p)
        os.environ["MPLBACKEND"] = "module://matplotlib_inline.backend_inline"
        try:
            yield
        finally:
            for k, v in saved.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v


def execute(path: Path, *, timeout: int = CELL_TIMEOUT) -> tuple[nbformat.NotebookNode, float]:
    """Execute one notebook in memory; return it with its outputs and the wall time [s].

    The working directory is a fresh temporary directory.  Raises
    :class:`nbclient.exceptions.CellExecutionError` on the first failing cell.
    """
    nb = nbformat.read(path, as_version=4)
    with kernel_environment(), tempfile.TemporaryDirectory(prefix="sbrdf-nb-") as cwd:
        client = NotebookClient(nb, timeout=timeout, kernel_name="python3", record_timing=False,
                                resources={"metadata": {"path": cwd}})
        t0 = time.perf_counter()
        client.execute()
        return nb, time.perf_counter() - t0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("notebooks", nargs="*", help="notebooks to run (default: all in notebooks/)")
    args = parser.parse_args(argv)
    paths = [Path(p) if Path(p).exists() else HERE / p for p in args.notebooks] or sorted(HERE.glob("*.ipynb"))
    failed = 0
    for path in paths:
        try:
            nb, seconds = execute(path)
        except Exception as exc:  # report and go on with the others
            failed += 1
            print(f"FAILED  {path.name}: {type(exc).__name__}: {str(exc)[-2000:]}", file=sys.stderr)
            continue
        nbformat.write(nb, path)
        print(f"ok      {path.name}  {seconds:6.1f} s")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
