"""The engine's compiled kernel, compiled ahead of its first use in a second process.

The first run of a scene pays twice before the first result: the catalog builds its
tables (:mod:`sbrdf_xr.materials`) and numba compiles the fused kernel
(:func:`sbrdf_xr.kernels.sums.fused_sums`, about 10 CPU seconds).  The two do not depend
on each other, so :func:`compile_ahead` starts a second Python process that compiles the
kernel into numba's disk cache (every kernel is ``cache=True``) while this process
builds; the first call then loads the machine code from the cache (half a second).  On
a machine with two cores the compilation costs no wall time as long as the builds last.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import numpy as np

__all__ = ["compile_ahead", "compiling_ahead", "warm_up"]


def warm_up(dtype: str = "float64") -> None:
    """Compile the fused kernel for tables of ``dtype`` (or load it from numba's cache):
    one call on a small problem with the argument types of the engine's calls.

    Parameters
    ----------
    dtype : {"float64", "float32"}
        The dtype of the material tables.

    Examples
    --------
    >>> from sbrdf_xr.kernels.warm import warm_up
    >>> warm_up("float64")  # from the cache once compiled
    """
    from .packing import pack_tables
    from .sums import fused_sums, normal_rows

    g = np.array([0.0, 45.0, 90.0])
    table = (np.ones((3, 3, 3, 2)), g, g - 45.0, g, (True, True, True))
    tables = pack_tables([table, table], dtype=np.dtype(dtype))
    s = o = np.array([[0.0, 0.0, 1.0], [0.6, 0.0, 0.8]])
    normals = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    fused_sums(
        s,
        o,
        normals,
        np.ones(2),
        np.array([0, 1]),
        tables,
        "linear",
        None,
        True,
        normal_rows(normals),
    )


def compile_ahead(dtype: str = "float64") -> subprocess.Popen[bytes] | None:
    """Start a Python process that runs :func:`warm_up` for ``dtype``, or None when the
    process cannot be started (the kernel then compiles on its first call).

    Its output is discarded; wait for it (``proc.wait()``) before the first call, so that
    the call loads the cached kernel instead of compiling it a second time.

    Parameters
    ----------
    dtype : {"float64", "float32"}
        The dtype of the material tables.

    Returns
    -------
    subprocess.Popen or None

    Examples
    --------
    >>> from sbrdf_xr.kernels.warm import compile_ahead
    >>> proc = compile_ahead("float64")
    >>> proc is None or proc.wait() == 0
    True
    """
    if os.environ.get("NUMBA_DISABLE_JIT", "0") not in ("", "0"):
        return None
    package = str(Path(__file__).resolve().parents[1])  # this sbrdf_xr
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        p for p in (str(Path(package).parent), env.get("PYTHONPATH")) if p
    )
    # The package stands in sys.modules without running its __init__ (which imports the
    # engine, xarray and the rest: a second of the first run's critical path); the kernels
    # import only what they use.  The modules, so numba's cache, are this package's.
    code = (
        "import sys, types\n"
        f"package = types.ModuleType('sbrdf_xr'); package.__path__ = [{package!r}]\n"
        "sys.modules['sbrdf_xr'] = package\n"
        f"from sbrdf_xr.kernels.warm import warm_up; warm_up({str(np.dtype(dtype))!r})"
    )
    try:
        return subprocess.Popen(  # -P: not the working directory's sbrdf_xr, this one
            [sys.executable, "-P", "-c", code],
            env=env,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
    except OSError:  # pragma: no cover - no second process here
        return None


@contextlib.contextmanager
def compiling_ahead(dtype: str = "float64", progress: bool = True) -> Iterator[None]:
    """Compile the kernel for ``dtype`` in a second process while the block runs
    (:func:`compile_ahead`), and wait for it when the block ends, with a progress bar
    "compiling the engine's kernel" while it still runs (none when it is done already).

    The engine holds it while the catalog builds a scene's tables
    (:func:`sbrdf_xr.catalog.load_materials`).

    Parameters
    ----------
    dtype : {"float64", "float32"}
        The dtype of the material tables.
    progress : bool, default True
        Show the progress bar of the wait.

    Examples
    --------
    >>> from sbrdf_xr.kernels.warm import compiling_ahead, warm_up
    >>> with compiling_ahead("float64", progress=False):
    ...     pass  # the tables would build here
    >>> warm_up("float64")  # loads the compiled kernel from numba's cache
    """
    proc = compile_ahead(dtype)
    try:
        yield
    finally:
        if proc is not None:
            _wait(proc, progress)


def _wait(proc: subprocess.Popen[bytes], progress: bool) -> None:
    """Wait for the process compiling the kernel, with a progress bar while it runs."""
    if proc.poll() is not None:
        return
    from tqdm.auto import tqdm

    with tqdm(
        desc="compiling the engine's kernel", bar_format="{desc}: {elapsed}", disable=not progress
    ) as bar:
        while True:
            try:
                proc.wait(timeout=0.25)
                break
            except subprocess.TimeoutExpired:
                bar.refresh()
