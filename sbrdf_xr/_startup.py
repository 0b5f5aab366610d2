"""What importing the package sets up: Ctrl-C while the command starts, and the accessors.

**Ctrl-C while the ``sbrdf-xr`` command is starting**: one line and exit status 130.  The
command line takes a second or more to start (it imports xarray, Dask, numba, trimesh...);
an interrupt then would end in a ``KeyboardInterrupt`` traceback, before the command line's
own handler (:func:`sbrdf_xr.cli.parser.main`) is there.  Imported first by the package:
when the running program is the ``sbrdf-xr`` command, an interrupt until ``main`` takes
over prints one line and exits with status 130, as one during the command does.  Nothing
has been written by then, so nothing needs cleaning up.

**A function run right after a module's first import** (:func:`when_imported`), wherever
that import happens.  ``import sbrdf_xr`` leaves xarray unimported (xarray alone takes
longer to import than the package's budget), yet the ``.sbrdf`` accessors must be on every
xarray object from the moment xarray exists, whoever imports it and in either order.
:func:`when_imported` calls a function at once if the module is imported already, or else
puts a finder first in :data:`sys.meta_path` that, for that one module, wraps its loader's
``exec_module``: the module runs as it would, its own loader is put back on it, the finder
takes itself out of ``sys.meta_path``, and the functions run.  A function that raises does
not break the import: it is reported as a :class:`~sbrdf_xr.errors.SbrdfWarning`.
"""

from __future__ import annotations

import os
import signal
import sys
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any, cast

from .errors import SbrdfWarning

if TYPE_CHECKING:
    from importlib.machinery import ModuleSpec

#: The name of the command-line program.
COMMAND = "sbrdf-xr"


def _interrupted(signum: int, frame: object) -> None:
    os.write(2, f"{COMMAND}: interrupted\n".encode())
    os._exit(130)


def starting_command_line() -> bool:
    """Whether the running program is the ``sbrdf-xr`` command (not a Python session).

    Examples
    --------
    >>> from sbrdf_xr._startup import starting_command_line
    >>> starting_command_line()  # the tests run under pytest
    False
    """
    return bool(sys.argv) and Path(sys.argv[0]).name == COMMAND


if starting_command_line() and signal.getsignal(signal.SIGINT) is signal.default_int_handler:
    signal.signal(signal.SIGINT, _interrupted)


# --- a function run after a module's first import ------------------------------

#: What :func:`when_imported` calls: a function of the imported module.
Callback = Callable[[ModuleType], object]


class _Loader:
    """The module's own loader, with the finder's functions run after ``exec_module``."""

    def __init__(self, loader: Any, finder: _AfterImport) -> None:
        self.loader = loader
        self.finder = finder

    def create_module(self, spec: ModuleSpec) -> ModuleType | None:
        return self.loader.create_module(spec)

    def exec_module(self, module: ModuleType) -> None:
        self.loader.exec_module(module)  # an error leaves the finder for the next try
        module.__loader__ = self.loader
        if module.__spec__ is not None:
            module.__spec__.loader = self.loader
        self.finder.fire(module)

    def __getattr__(self, name: str) -> Any:  # resource readers and the like: the loader's
        return getattr(self.loader, name)


class _AfterImport:
    """The finder of :func:`when_imported` for one module name."""

    def __init__(self, name: str) -> None:
        self.after_import_of = name  # how a finder of this kind is recognised, across reloads
        self.callbacks: dict[str, Callback] = {}

    def find_spec(
        self, fullname: str, path: Sequence[str] | None, target: ModuleType | None = None
    ) -> ModuleSpec | None:
        if fullname != self.after_import_of:
            return None
        for finder in sys.meta_path:
            find = getattr(finder, "find_spec", None)
            if getattr(finder, "after_import_of", None) is not None or find is None:
                continue
            spec = find(fullname, path, target)
            if spec is not None:
                break
        else:
            return None
        if spec.loader is not None and hasattr(spec.loader, "exec_module"):
            spec.loader = _Loader(spec.loader, self)
        return spec

    def fire(self, module: ModuleType) -> None:
        """Leave ``sys.meta_path`` and run the functions on the imported module."""
        if self in sys.meta_path:
            sys.meta_path.remove(self)
        for key, callback in self.callbacks.items():
            _run(key, callback, module)


def _run(key: str, callback: Callback, module: ModuleType) -> None:
    try:
        callback(module)
    except Exception as exc:  # the import itself must not fail
        warnings.warn(
            f"{key}, run after the import of {module.__name__}, failed: {exc!r}",
            SbrdfWarning,
            stacklevel=2,
        )


def pending(name: str) -> _AfterImport | None:
    """The finder waiting for ``name``'s first import, if any.

    Examples
    --------
    >>> from sbrdf_xr._startup import pending
    >>> pending("json") is None  # imported long ago: nothing waits for it
    True
    """
    found = (f for f in sys.meta_path if getattr(f, "after_import_of", None) == name)
    return cast("_AfterImport | None", next(found, None))


def when_imported(name: str, callback: Callback) -> None:
    """Call ``callback(module)`` now if module ``name`` is imported, else after its import.

    Parameters
    ----------
    name : str
        A top-level module name (``"xarray"``).
    callback : callable
        Called with the module.  One callback per ``module.qualname``: giving it again
        (``importlib.reload`` of its module) replaces the one waiting.

    Examples
    --------
    >>> import json
    >>> from sbrdf_xr._startup import when_imported
    >>> seen = []
    >>> when_imported("json", lambda m: seen.append(m.__name__))  # imported: called now
    >>> seen
    ['json']
    """
    module = sys.modules.get(name)
    if module is not None:
        callback(module)
        return
    finder = pending(name)
    if finder is None:
        finder = _AfterImport(name)
        sys.meta_path.insert(0, finder)
    key = f"{getattr(callback, '__module__', '?')}.{getattr(callback, '__qualname__', '?')}"
    finder.callbacks[key] = callback
