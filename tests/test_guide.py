"""The user guide runs as written, and every name it mentions exists.

Each page of ``docs/guide/`` (every ``*.md``: pages added later are picked up) has its
```` ```python ```` blocks extracted and run in order, in one fresh namespace per page, in a
temporary working directory; blocks that are deliberately not run use another fence
(```` ```text ````, ```` ```console ````, ```` ```bash ````, ```` ```toml ````).  A page whose
code is unavoidably long to run carries the comment ``<!-- guide-test: slow -->`` and runs
only with ``-m slow``.

Every dotted name the guide, the README and the getting-started page write in backticks
(``sbrdf_xr.engine.schema.reference``, ``invert.fit_spin``, ...) must resolve, so that a
rename cannot leave the prose pointing at a name that no longer exists.
"""

from __future__ import annotations

import importlib
import re
import warnings
from pathlib import Path

import pytest

from sbrdf_xr.errors import FitQualityWarning, RenamedWarning

ROOT = Path(__file__).resolve().parent.parent
GUIDE = ROOT / "docs" / "guide"
PAGES = sorted(GUIDE.glob("*.md"))
#: Where prose names package objects: the guide, the README and the getting-started page.
PROSE = [*PAGES, ROOT / "README.md", ROOT / "docs" / "getting_started.md"]
SLOW = "<!-- guide-test: slow -->"

_BLOCK = re.compile(r"^```python[ \t]*\n(.*?)^```[ \t]*$", re.DOTALL | re.MULTILINE)


def python_blocks(text: str) -> list[tuple[int, str]]:
    """``(first line, code)`` of every ```` ```python ```` block of a Markdown text."""
    return [(text.count("\n", 0, m.start(1)) + 1, m.group(1)) for m in _BLOCK.finditer(text)]


def test_python_blocks_are_found_with_their_lines():
    text = "# t\n\n```python\nx = 1\n```\n\n```text\nnot run\n```\n```python\ny = x\n```\n"
    assert python_blocks(text) == [(4, "x = 1\n"), (11, "y = x\n")]


def test_the_guide_has_its_pages_and_they_have_code():
    names = {p.stem for p in PAGES}
    for page in (
        "materials",
        "spacecraft-and-scenes",
        "observations",
        "light-curves-and-comparison",
        "inversion",
        "accuracy-and-cost",
        "scaling-out",
        "security",
        "scene-file-reference",
    ):
        assert page in names, page
        assert python_blocks((GUIDE / f"{page}.md").read_text(encoding="utf-8")), page


def _page_params() -> list:
    out = []
    for page in PAGES:
        slow = SLOW in page.read_text(encoding="utf-8")
        out.append(pytest.param(page, id=page.stem, marks=[pytest.mark.slow] if slow else []))
    return out


@pytest.mark.parametrize("page", _page_params())
def test_every_python_block_of_the_page_runs(page, tmp_path, monkeypatch):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    monkeypatch.chdir(tmp_path)
    namespace: dict = {"__name__": f"guide_{page.stem.replace('-', '_')}"}
    try:
        with warnings.catch_warnings():
            # A fit's verdict on its data is output the inversion page discusses (a spin fit
            # to magnitudes that still hold the extinction); every other warning of the
            # package (a renamed name, a unit taken for another) stays an error, as in the
            # rest of the suite.
            warnings.simplefilter("always", FitQualityWarning)
            for line, code in python_blocks(page.read_text(encoding="utf-8")):
                exec(compile(code, f"{page.relative_to(ROOT)}:{line}", "exec"), namespace)
    finally:
        plt.close("all")


def test_the_readme_code_is_guide_code():
    """The README's examples are run where the guide holds them, so they are run too."""
    guide = "\n".join(p.read_text(encoding="utf-8") for p in PAGES)
    for line, code in python_blocks((ROOT / "README.md").read_text(encoding="utf-8")):
        assert f"```python\n{code}```" in guide, f"README.md:{line} is in no guide page"


#: A name in backticks: ``sbrdf_xr.a.b`` or ``<package>.b`` for a package of sbrdf_xr.
_NAME = re.compile(r"`(sbrdf_xr(?:\.\w+)+|[a-z_]+\.\w+(?:\.\w+)*)(?:\([^`]*\))?`")


def _resolve(dotted: str) -> bool:
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        try:
            with warnings.catch_warnings():  # an old name of a rename table still answers
                warnings.simplefilter("ignore", RenamedWarning)
                for attr in parts[cut:]:
                    obj = getattr(obj, attr)
        except AttributeError:
            return False
        return True
    return False


def mentioned_names(text: str) -> set[str]:
    """The package names a Markdown text writes in backticks, as full dotted names."""
    import sbrdf_xr

    packages = {n for n in sbrdf_xr.__all__ if importlib.util.find_spec(f"sbrdf_xr.{n}")}
    out = set()
    for m in _NAME.finditer(text):
        name = m.group(1)
        head = name.split(".")[0]
        if head == "sbrdf_xr":
            out.add(name)
        elif head in packages | {"material"}:  # `material.x`: the old flat module's spelling
            out.add(f"sbrdf_xr.{name}")
    return out


def test_name_check_catches_a_stale_name():
    names = mentioned_names("`material.build_lut_anisotropic` and `invert.fit_spin(...)`")
    assert names == {"sbrdf_xr.material.build_lut_anisotropic", "sbrdf_xr.invert.fit_spin"}
    assert not _resolve("sbrdf_xr.material.build_lut_anisotropic")
    assert _resolve("sbrdf_xr.invert.fit_spin")


@pytest.mark.parametrize("page", PROSE, ids=lambda p: p.name)
def test_every_name_the_prose_mentions_exists(page):
    names = mentioned_names(page.read_text(encoding="utf-8"))
    missing = sorted(n for n in names if not _resolve(n))
    assert not missing, f"{page.name} names what does not exist: {missing}"
