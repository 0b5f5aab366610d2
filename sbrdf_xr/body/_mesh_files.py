"""What a mesh file declares, checked against what it holds, before it is read.

A PLY or OFF file states its vertex and facet counts in its header: a count beyond the
data that follow (a file cut short) is refused, and so is a count whose arrays would
exceed :data:`MAX_MESH_BYTES` (times the ``size_limit`` factor), with the estimate in
the message, before anything is allocated.  An OBJ file's vertex rows must hold 3
coordinates (a 4th, ``w``, and 3 colour values are allowed): rows of 2 would otherwise
be read as a shifted flat list of numbers.
"""

from __future__ import annotations

import re
from pathlib import Path

from ..errors import MeshError

__all__ = ["MAX_MESH_BYTES", "check_mesh_file"]

#: Memory a mesh's vertices and facets may take [byte], times ``size_limit``.
MAX_MESH_BYTES = 4 * 2**30
#: Bytes of one vertex (3 float64) and one facet (3 int64 indices) once read.
_VERTEX_BYTES = 24
_FACET_BYTES = 24
#: Bytes of a PLY property of each type.
_PLY_SIZES = {
    **dict.fromkeys(("char", "uchar", "int8", "uint8"), 1),
    **dict.fromkeys(("short", "ushort", "int16", "uint16"), 2),
    **dict.fromkeys(("int", "uint", "float", "int32", "uint32", "float32"), 4),
    **dict.fromkeys(("double", "float64"), 8),
}


def _check_size(path: Path, n_vertices: int, n_facets: int, size_limit: float) -> None:
    need = n_vertices * _VERTEX_BYTES + n_facets * _FACET_BYTES
    if need > size_limit * MAX_MESH_BYTES:
        raise MeshError(
            f"mesh file {path}: its header declares {n_vertices} vertices and {n_facets} "
            f"facets, about {need / 2**30:.3g} GiB once read; meshes of at most "
            f"{size_limit * MAX_MESH_BYTES / 2**30:.3g} GiB are read"
        )


def _truncated(path: Path, what: str) -> MeshError:
    return MeshError(f"mesh file {path}: {what}; the file was cut short or is damaged")


def _check_ply(path: Path, size_limit: float) -> None:
    with open(path, "rb") as f:
        head = f.read(65536)
    end = head.find(b"end_header")
    if not head.startswith(b"ply") or end < 0:
        return  # not a PLY header this check understands: the reader decides
    body_start = head.index(b"\n", end) + 1 if b"\n" in head[end:] else len(head)
    lines = head[:end].decode("ascii", "replace").splitlines()
    fmt = next((ln.split()[1] for ln in lines if ln.startswith("format ")), "ascii")
    elements: list[list] = []  # [name, count, fixed bytes per item, has lists]
    for ln in lines:
        words = ln.split()
        if words[:1] == ["element"] and len(words) == 3 and words[2].isdigit():
            elements.append([words[1], int(words[2]), 0, False])
        elif words[:1] == ["property"] and elements:
            if words[1] == "list" and len(words) >= 5:
                elements[-1][3] = True
                # at least the count and 3 indices of a facet
                elements[-1][2] += _PLY_SIZES.get(words[2], 1) + 3 * _PLY_SIZES.get(words[3], 4)
            else:
                elements[-1][2] += _PLY_SIZES.get(words[1], 4)
    counts = {e[0]: e[1] for e in elements}
    _check_size(path, counts.get("vertex", 0), counts.get("face", 0), size_limit)
    size = path.stat().st_size - body_start
    if fmt == "ascii":
        with open(path, "rb") as f:
            f.seek(body_start)
            rows = sum(1 for line in f if line.strip())
        declared = sum(e[1] for e in elements)
        if rows < declared:
            raise _truncated(path, f"its header declares {declared} rows of data, it holds {rows}")
    else:
        least = sum(e[1] * e[2] for e in elements)
        if size < least:
            raise _truncated(
                path,
                f"its header declares "
                f"{', '.join(f'{e[1]} {e[0]}' for e in elements)} ({least} bytes at least), "
                f"it holds {size} bytes of data",
            )


def _check_off(path: Path, size_limit: float) -> None:
    with open(path, "rb") as f:
        text = (ln.split(b"#")[0].strip() for ln in f)
        rows = [ln for ln in text if ln]
    if not rows or not rows[0].endswith(b"OFF"):
        return
    counts = rows[0][:-3].split() or (rows[1].split() if len(rows) > 1 else [])
    first = 1 if rows[0][:-3].split() else 2
    if len(counts) < 2 or not all(c.isdigit() for c in counts[:2]):
        return
    n_vertices, n_facets = int(counts[0]), int(counts[1])
    _check_size(path, n_vertices, n_facets, size_limit)
    held = len(rows) - first
    if held < n_vertices + n_facets:
        raise _truncated(
            path,
            f"its header declares {n_vertices} vertices and {n_facets} facets, it holds "
            f"{held} rows",
        )


_OBJ_VERTEX = re.compile(rb"^v\s+(.*)$")


def _check_obj(path: Path) -> None:
    with open(path, "rb") as f:
        for i, line in enumerate(f, 1):
            m = _OBJ_VERTEX.match(line.strip())
            if m is None:
                continue
            n = len(m.group(1).split(b"#")[0].split())
            if n not in (3, 4, 6, 7):
                raise MeshError(
                    f"mesh file {path}: line {i} is a vertex of {n} coordinates; OBJ vertices "
                    "have 3 (x y z, with an optional w or r g b)"
                )


def check_mesh_file(path: Path, file_type: str | None = None, size_limit: float = 1.0) -> None:
    """Refuse a PLY, OFF or OBJ file whose declared counts exceed its data or the size
    limit, or whose vertex rows are malformed; other formats pass unchecked.

    Parameters
    ----------
    path : pathlib.Path
        The mesh file.
    file_type : str, optional
        Its format (``"ply"``, ``"off"``, ``"obj"``...); default from its suffix.
    size_limit : float, default 1
        Factor on :data:`MAX_MESH_BYTES` [1].

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from sbrdf_xr.body._mesh_files import check_mesh_file
    >>> from sbrdf_xr.errors import MeshError
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     off = Path(tmp) / "cut.off"
    ...     _ = off.write_text("OFF\\n3 1000000000 0\\n0 0 0\\n1 0 0\\n0 1 0\\n3 0 1 2\\n")
    ...     try:
    ...         check_mesh_file(off)
    ...     except MeshError as exc:
    ...         print(str(exc).replace(tmp, "<tmp>"))
    mesh file <tmp>/cut.off: its header declares 3 vertices and 1000000000 facets, about
    22.4 GiB once read; meshes of at most 4 GiB are read
    """
    kind = (file_type or path.suffix.lstrip(".")).lower()
    try:
        if kind == "ply":
            _check_ply(path, size_limit)
        elif kind == "off":
            _check_off(path, size_limit)
        elif kind == "obj":
            _check_obj(path)
    except OSError:
        return  # unreadable: the reader says why
