"""The documentation builds offline with warnings as errors.

Runs ``sphinx-build -W --keep-going -b html docs <tmp>`` (the API reference from the
docstrings, the user guide, the README as the getting-started page, the notebooks with their stored
outputs) and checks that the key pages exist.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
PACKAGE = ROOT / "sbrdf_xr"

#: What the build needs (the ``docs`` extra, also in the ``test`` extra).
DOCS_REQUIREMENTS = ("sphinx", "numpydoc", "myst_nb", "pydata_sphinx_theme")


def public_modules() -> list[str]:
    """Dotted names of the package's public modules (no part starts with ``_``)."""
    names = []
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(ROOT).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if not any(p.startswith("_") for p in parts[1:]):
            names.append(".".join(parts))
    return names


def test_every_public_module_has_an_api_page():
    missing = [m for m in public_modules() if not (DOCS / "api" / f"{m}.rst").is_file()]
    assert not missing, f"modules without a page in docs/api/ (and docs/api/index.md): {missing}"
    index = (DOCS / "api" / "index.md").read_text(encoding="utf-8")
    unlisted = [m for m in public_modules() if f"\n{m}\n" not in index]
    assert not unlisted, f"modules missing from the toctree of docs/api/index.md: {unlisted}"


@contextlib.contextmanager
def _locked(path: Path):
    """An exclusive lock on ``path`` (a lock file) while the block runs."""
    import fcntl

    with open(path, "a") as f:
        fcntl.flock(f, fcntl.LOCK_EX)
        yield


@pytest.fixture(scope="module")
def html(tmp_path_factory) -> Path:
    """The built documentation: built once per test run, also with ``-n`` (pytest-xdist):
    the first worker builds it into the run's shared temporary directory, under a lock,
    and the others wait for it and read it."""
    for name in DOCS_REQUIREMENTS:
        pytest.importorskip(name)
    base = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        base = base.parent  # the run's directory, shared by its workers
    out = base / "sphinx-html"
    with _locked(base / "sphinx-html.lock"):
        if (out / ".built").is_file():
            return out
        shutil.rmtree(out, ignore_errors=True)  # what a failed build left
        out.mkdir()
        _build(out)
        (out / ".built").touch()
    return out


def _build(out: Path) -> None:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    env["MPLBACKEND"] = "Agg"
    # sphinx-build -W --keep-going -b html docs <out>, with this interpreter.
    cmd = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html"]
    cmd += ["-d", str(out / ".doctrees"), str(DOCS), str(out)]
    proc = subprocess.run(
        cmd,
        capture_output=True,
        text=True,
        env=env,
        cwd=ROOT,
        timeout=900,
        check=False,
    )
    if proc.returncode != 0:
        print(proc.stdout[-5000:])
        print(proc.stderr)
    assert proc.returncode == 0, f"sphinx-build failed ({proc.returncode}):\n{proc.stderr[-5000:]}"


@pytest.mark.parametrize(
    "page",
    [
        "index.html",
        "guide/index.html",
        "guide/spacecraft-and-scenes.html",
        "guide/scene-file-reference.html",
        "getting_started.html",
        "api/index.html",
        "api/sbrdf_xr.geometry.html",
        "api/sbrdf_xr.materials.tables.html",
        "api/sbrdf_xr.brdf.robertson_sandford.html",
        "api/sbrdf_xr.photometry.magnitude.html",
        "api/sbrdf_xr.invert.html",
        "notebooks/01_paper000_reproduction.html",
        "notebooks/05_inversion.html",
    ],
)
def test_page_is_built(html, page):
    assert (html / page).is_file()


def test_the_guide_lists_its_pages_and_comes_first(html):
    index = (html / "index.html").read_text(encoding="utf-8")
    assert index.index("guide/index.html") < index.index("getting_started.html")
    guide = (html / "guide" / "index.html").read_text(encoding="utf-8")
    for page in sorted((DOCS / "guide").glob("*.md")):  # pages added later appear too
        assert page.stem == "index" or f"{page.stem}.html" in guide, page.name
    api = (html / "api" / "index.html").read_text(encoding="utf-8")
    assert api.index("sbrdf_xr.engine.scene.html") < api.index("sbrdf_xr.kernels.html")


def test_api_pages_document_the_functions(html):
    angles = (html / "api" / "sbrdf_xr.geometry.angles.html").read_text(encoding="utf-8")
    assert 'id="sbrdf_xr.geometry.angles.facet_angles"' in angles
    # A package's names are documented once, where they are defined, and linked.
    geometry = (html / "api" / "sbrdf_xr.geometry.html").read_text(encoding="utf-8")
    assert 'id="sbrdf_xr.geometry.axis_rotation"' not in geometry
    assert "sbrdf_xr.geometry.rotations.html#sbrdf_xr.geometry.rotations.axis_rotation" in geometry
    invert = (html / "api" / "sbrdf_xr.invert.html").read_text(encoding="utf-8")
    assert 'id="sbrdf_xr.invert.unmix"' in invert


def test_notebooks_are_rendered_with_their_stored_figures(html):
    page = (html / "notebooks" / "01_paper000_reproduction.html").read_text(encoding="utf-8")
    assert page.count("<img") >= 3
    start = (html / "getting_started.html").read_text(encoding="utf-8")
    assert "_images/canx1_rotation.png" in start
    assert (html / "_images" / "canx1_rotation.png").is_file()
