"""What a plan computes from a scene's tables, spacecraft and knobs alone, kept for the next
plans.

A scene that differs from the last one in its geometry (or in knobs such a result does not
read) compiles without merging its facets or packing its tables again
(:func:`sbrdf_xr.engine.plan.compile_plan`).  Each result is kept under a key made of
*content* digests of everything it is computed from: the digests of the tables and of the
mesh in the scene's fingerprint (:func:`sbrdf_xr.engine.fingerprint.scene_fingerprint`,
which hashes a writeable table every time and a read-only one once), :func:`digest` of the
other arrays, and the values of the knobs it reads.  A changed table, mesh or knob is
therefore another key: a kept result is never served for inputs that differ from those it
was computed from.  Each :class:`Memo` keeps its :data:`KEEP` most recently used results,
so memory does not grow with the number of scenes.
"""

from __future__ import annotations

import hashlib
import json
import threading
from collections import OrderedDict
from collections.abc import Callable, Hashable, Mapping
from typing import Any, TypeVar

import numpy as np

from ..store.fingerprint import PREFIX

__all__ = [
    "FACETS",
    "GRIDS",
    "INDEXES",
    "KEEP",
    "MEMOS",
    "TABLES",
    "WEIGHTS",
    "Memo",
    "digest",
    "immutable",
    "table_digests",
]

T = TypeVar("T")

#: Results kept per kind (the most recently used).
KEEP = 4


class Memo:
    """A small, thread-safe store of results by key, keeping the ``size`` most recently used.

    Examples
    --------
    >>> from sbrdf_xr.engine.reuse import Memo
    >>> memo = Memo("squares", size=2)
    >>> calls = []
    >>> def square(x):
    ...     calls.append(x)
    ...     return x * x
    >>> [memo.get(x, lambda x=x: square(x)) for x in (2, 3, 2, 4, 2, 3)]
    [4, 9, 4, 16, 4, 9]
    >>> calls  # 3 was dropped when 4 came (2 was used more recently)
    [2, 3, 4, 3]
    >>> len(memo), memo.get(None, lambda: square(5)), len(memo)  # key None: not kept
    (2, 25, 2)
    """

    def __init__(self, name: str, size: int = KEEP) -> None:
        self.name = name
        self.size = int(size)
        self._items: OrderedDict[Hashable, Any] = OrderedDict()
        self._lock = threading.Lock()

    def get(self, key: Hashable | None, make: Callable[[], T]) -> T:
        """The result kept under ``key``, or ``make()`` kept under it (``key`` None: made
        and not kept).  Nothing is kept when ``make`` raises."""
        if key is None:
            return make()
        with self._lock:
            if key in self._items:
                self._items.move_to_end(key)
                return self._items[key]
        value = make()
        with self._lock:
            self._items[key] = value
            self._items.move_to_end(key)
            while len(self._items) > self.size:
                self._items.popitem(last=False)
        return value

    def __len__(self) -> int:
        return len(self._items)

    def clear(self) -> None:
        """Forget every kept result."""
        with self._lock:
            self._items.clear()

    def __repr__(self) -> str:
        return f"<Memo {self.name!r}: {len(self)} of {self.size} kept>"


#: Facet terms (normals, areas, materials, ... after merging) by mesh, tangents and the
#: merging asked for.
FACETS = Memo("facet terms")
#: Packed material tables (:func:`sbrdf_xr.kernels.sums.pack_tables`) by table digests,
#: wavelengths, band weights, dtype and theta_i resampling.
TABLES = Memo("packed tables")
#: The wavelengths the used tables share (:func:`sbrdf_xr.engine.spectral.common_wavelength`)
#: by table digests.
GRIDS = Memo("common wavelengths")
#: Band weights (filter x Sun) by bands, filter responses, wavelengths and extrapolation.
WEIGHTS = Memo("band weights")
#: The pandas indexes of a cube's dimension coordinates (immutable, shared between cubes)
#: by name and values (wavelengths, materials, attitude numbers, ...).
INDEXES = Memo("coordinate indexes", size=4 * KEEP)
#: Every memo of the engine.
MEMOS = (FACETS, GRIDS, TABLES, WEIGHTS, INDEXES)


def immutable(a: Any) -> bool:
    """Whether no one can write the values of array ``a``: it and every array it views are
    read-only, and the memory at the bottom is its own or an immutable buffer (the rule by
    which the fingerprint keeps an array's digest).  A result that views such an array can
    be kept; one that views writeable memory cannot (the memory may change under it).

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.engine.reuse import immutable
    >>> a = np.arange(4.0)
    >>> view = a[:2]
    >>> view.flags.writeable = False
    >>> immutable(a), immutable(view)  # the view's base can still be written
    (False, False)
    >>> a.flags.writeable = False
    >>> immutable(a), immutable(a[:2])
    (True, True)
    """
    base: Any = a
    while isinstance(base, np.ndarray):
        if base.flags.writeable:
            return False
        base = base.base
    if base is None:
        return isinstance(a, np.ndarray)
    try:
        return memoryview(base).readonly
    except TypeError:  # memory of an unknown kind (an mmap, a foreign buffer): may change
        return False


def digest(*arrays: Any) -> str:
    """A digest of the dtype, shape and values of each array (None allowed).

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.engine.reuse import digest
    >>> a = np.arange(3.0)
    >>> digest(a) == digest(a.copy()), digest(a) == digest(a.astype(np.float32))
    (True, False)
    >>> digest(a, None) == digest(a), len(digest(a))
    (False, 32)
    """
    h = hashlib.blake2b(digest_size=16)
    for a in arrays:
        if a is None:
            h.update(b"none\0")
            continue
        arr = np.ascontiguousarray(a)
        h.update(f"{arr.dtype.str}{arr.shape}\0".encode())
        h.update(arr.data.cast("B") if arr.dtype.kind != "O" else repr(arr.tolist()).encode())
    return h.hexdigest()


def table_digests(fingerprint: Mapping[str, str]) -> dict[str, str]:
    """Material name -> digest of its table (or model), read from a scene fingerprint.

    Examples
    --------
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> from sbrdf_xr.engine.reuse import table_digests
    >>> from sbrdf_xr.engine.fingerprint import scene_fingerprint
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> scene = Scene(box, {"grey": grey}, attitudes=[[0, 0, 0, 1.0]], phase_angles=[0.0])
    >>> fp = scene_fingerprint(scene)
    >>> table_digests(fp) == {"grey": fp["fingerprint_material_grey"]}
    True
    """
    names = json.loads(fingerprint[f"{PREFIX}_material_names"])
    return {str(n): fingerprint[f"{PREFIX}_material_{s}"] for s, n in names.items()}
