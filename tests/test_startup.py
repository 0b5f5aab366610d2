"""Tests of sbrdf_xr._startup.when_imported: a function run after a module's first import,
and the ``.sbrdf`` accessors registered through it whichever of sbrdf_xr and xarray comes
first."""

from __future__ import annotations

import importlib
import json
import subprocess
import sys
import textwrap
import uuid

import pytest

from sbrdf_xr._startup import pending, when_imported
from sbrdf_xr.errors import SbrdfWarning


@pytest.fixture
def module_file(tmp_path, monkeypatch):
    """A fresh module name on sys.path, and a function writing its source."""
    name = f"sbrdf_probe_{uuid.uuid4().hex}"
    monkeypatch.syspath_prepend(str(tmp_path))

    def write(source: str) -> None:
        (tmp_path / f"{name}.py").write_text(textwrap.dedent(source))
        importlib.invalidate_caches()

    yield name, write
    sys.modules.pop(name, None)
    finder = pending(name)
    if finder is not None:
        sys.meta_path.remove(finder)


def test_a_module_imported_already_is_handed_over_at_once():
    seen = []
    when_imported("json", seen.append)
    assert seen == [json] and pending("json") is None


def test_the_function_runs_after_the_first_import_and_the_finder_leaves(module_file):
    name, write = module_file
    write("VALUE = 42\n")
    seen = []
    when_imported(name, lambda m: seen.append(m.VALUE))  # runs on the executed module
    finder = pending(name)
    assert finder is not None and sys.meta_path[0] is finder and seen == []
    module = importlib.import_module(name)
    assert seen == [42] and pending(name) is None
    # the module keeps its own loader (resource readers, reloads), not the wrapper
    assert type(module.__loader__).__name__ == "SourceFileLoader"
    assert module.__spec__.loader is module.__loader__
    importlib.reload(module)
    assert seen == [42]  # once: the finder is gone


def test_one_function_per_name_waits_even_if_given_again(module_file):
    """A reload of the module that registers the function gives it again: it runs once."""
    name, write = module_file
    write("VALUE = 1\n")
    seen = []

    def record(m):
        seen.append(m.VALUE)

    when_imported(name, record)
    when_imported(name, record)
    assert len(pending(name).callbacks) == 1
    importlib.import_module(name)
    assert seen == [1]


def test_a_failing_function_warns_and_the_import_succeeds(module_file):
    name, write = module_file
    write("VALUE = 1\n")

    def broken(m):
        raise RuntimeError("no accessors today")

    when_imported(name, broken)
    with pytest.warns(SbrdfWarning, match=r"broken, run after the import of .*no accessors"):
        module = importlib.import_module(name)
    assert module.VALUE == 1 and sys.modules[name] is module


def test_a_failing_import_keeps_the_finder_for_the_next_try(module_file):
    name, write = module_file
    write("raise ImportError('not yet')\n")
    seen = []
    when_imported(name, lambda m: seen.append(m.VALUE))
    with pytest.raises(ImportError, match="not yet"):
        importlib.import_module(name)
    assert seen == [] and pending(name) is not None and name not in sys.modules
    write("VALUE = 2\n")
    importlib.import_module(name)
    assert seen == [2] and pending(name) is None


def _fresh(code: str) -> dict:
    """Run ``code`` in a fresh interpreter with warnings as errors; its last line, as JSON."""
    out = subprocess.run(
        [sys.executable, "-W", "error", "-c", textwrap.dedent(code)],
        capture_output=True,
        text=True,
        check=True,
        timeout=600,
    )
    return json.loads(out.stdout.splitlines()[-1])


CHECK = """
hooks = [f for f in sys.meta_path if getattr(f, "after_import_of", None)]
print(json.dumps({
    "dataset": hasattr(xr.Dataset().sbrdf, "photometry"),
    "dataarray": hasattr(xr.DataArray().sbrdf, "lookup"),
    "hooks": len(hooks),
    "loader": type(xr.__loader__).__name__,
}))
"""
ACCESSORS = {"dataset": True, "dataarray": True, "hooks": 0, "loader": "SourceFileLoader"}


@pytest.mark.parametrize(
    "first",
    [
        "import sbrdf_xr\nassert 'xarray' not in sys.modules\nimport xarray as xr\n",
        "import xarray as xr\nimport sbrdf_xr\n",
        # reloaded before and after xarray: one finder, and it still fires
        "import importlib, sbrdf_xr\nimportlib.reload(sbrdf_xr)\n"
        "assert len([f for f in sys.meta_path if getattr(f, 'after_import_of', None)]) == 1\n"
        "from xarray import DataArray\nimport xarray as xr\nimportlib.reload(sbrdf_xr)\n",
        # xarray reached through a package module that needs it
        "import sbrdf_xr.photometry\nimport xarray as xr\n",
    ],
    ids=["sbrdf_xr-first", "xarray-first", "reloaded", "through-a-subpackage"],
)
def test_the_accessors_are_there_whichever_comes_first(first):
    assert _fresh("import json, sys\n" + first + CHECK) == ACCESSORS
