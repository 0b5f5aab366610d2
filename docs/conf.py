"""Sphinx configuration of the sbrdf_xr documentation.

Build (from the repository root, offline; warnings are errors)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

The API reference is read from the docstrings (numpydoc); the notebooks in
``notebooks/`` are rendered with their stored outputs and are never executed here.
"""

from __future__ import annotations

import inspect
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
# A source checkout documents itself without being installed.
sys.path.insert(0, str(ROOT))

import sbrdf_xr  # noqa: E402

project = "sbrdf_xr"
author = "sbrdf_xr developers"
copyright = "sbrdf_xr developers"
release = sbrdf_xr.__version__
version = ".".join(release.split(".")[:2])

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_nb",
]

source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
root_doc = "index"
exclude_patterns = ["_build", "**.ipynb_checkpoints", "img/README*"]
templates_path: list[str] = []

# -- autodoc / numpydoc -------------------------------------------------------
autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "signature"
autodoc_preserve_defaults = True
autosummary_generate = False
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
# Intersphinx is not used: the build must work offline.

# -- MyST / notebooks ---------------------------------------------------------
nb_execution_mode = "off"  # the notebooks are stored executed
myst_enable_extensions = ["dollarmath", "amsmath"]
myst_heading_anchors = 3
suppress_warnings = ["myst.header"]

# -- HTML ---------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"sbrdf_xr {release}"
html_static_path: list[str] = []
html_theme_options = {"navigation_with_keys": False, "show_toc_level": 2}


# -- re-exported names ---------------------------------------------------------
# Several modules re-export names defined in other public modules (``sbrdf_xr``,
# ``scene``, ``geometry``, ``material``, ``photometry``...).  Each object is documented
# once, in the public module that defines it; a re-exporting module's page lists the
# names it re-exports with links to them.  Names defined in private modules
# (``invert._unmix``, ``_catalog_index``) are documented where they are re-exported.


def _is_public_module(name: str | None) -> bool:
    return (
        bool(name)
        and name.split(".")[0] == "sbrdf_xr"
        and not any(part.startswith("_") for part in name.split("."))
    )


def _current_module(app) -> str | None:
    docname = app.env.current_document.docname
    if docname.startswith("api/"):
        return docname.removeprefix("api/")
    return None


def _skip_reexports(app, what, name, obj, skip, options):
    if what != "module":
        return None
    if inspect.ismodule(obj):
        return True
    current = _current_module(app)
    home = getattr(obj, "__module__", None)
    if current and (inspect.isclass(obj) or callable(obj)) and home != current:
        if _is_public_module(home):
            return True
    return None


def _list_reexports(app, what, name, obj, options, lines):
    if what != "module":
        return
    names = []
    for attr in getattr(obj, "__all__", ()):
        member = getattr(obj, attr, None)
        home = getattr(member, "__module__", None)
        if inspect.ismodule(member):
            names.append(f":py:mod:`{attr} <{member.__name__}>`")
        elif (inspect.isclass(member) or callable(member)) and home != name:
            if _is_public_module(home):
                target = f"{home}.{member.__qualname__}"
                names.append(f":py:obj:`{attr} <{target}>`")
    if names:
        lines += ["", ".. rubric:: Also importable from this module", "", ", ".join(names), ""]


def _bound_method_signature(app, obj, bound_method):
    """Undo what ``autodoc_preserve_defaults`` does to a bound method documented as a
    module's function (``brdf_angles = MODEL.brdf_angles``): it stores the method's
    signature, ``self`` already dropped, on the function all models share, so every
    such alias would show one parameter fewer than the one before.  ``self`` is put back
    in front of the stored signature."""
    func = getattr(obj, "__func__", None)
    if not inspect.ismethod(obj) or "__signature__" not in getattr(func, "__dict__", {}):
        return
    sig = func.__dict__["__signature__"]
    first = func.__code__.co_varnames[0]
    if first not in sig.parameters:
        own = inspect.Parameter(first, inspect.Parameter.POSITIONAL_OR_KEYWORD)
        func.__signature__ = sig.replace(parameters=[own, *sig.parameters.values()])


def setup(app):
    app.connect("autodoc-before-process-signature", _bound_method_signature)
    app.connect("autodoc-skip-member", _skip_reexports)
    app.connect("autodoc-process-docstring", _list_reexports)
