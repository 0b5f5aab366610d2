"""Bad mesh files: every one ends in a named error that names the file (and says what is
wrong with it: not a file, not a mesh, not manifold), or loads with a warning
when it is only implausible; no message shows the file.

Files: a box in every format spoilt in its bytes (truncated, flipped, spliced, junk),
broken surfaces (a fin of three facets on one edge, an open box, NaN and huge vertices,
flat, inside out, duplicate and degenerate facets), special files, and length units
(case-sensitive SI prefixes); given to :func:`sbrdf_xr.body.spacecraft.load_spacecraft`
and :func:`sbrdf_xr.catalog.load_spacecraft_spec` (what ``[spacecraft]`` and
``--spacecraft`` use).
"""

from __future__ import annotations

import numpy as np
import pytest
from bad_input_files import (
    BROKEN_OBJ,
    EXPECTED_SPECIAL,
    MESH_FORMATS,
    SPECIAL,
    mesh_bytes,
    special_file,
    spoil,
)
from bad_input_tour import run_case, tour_settings, unblock_fifos
from hypothesis import given
from hypothesis import strategies as st

CATEGORY = "mesh files"


def _load(path, **kw):
    from sbrdf_xr.body.spacecraft import load_spacecraft

    return load_spacecraft(path, material="grey", **kw)


def _load_spec(path, **kw):
    from sbrdf_xr.catalog import load_spacecraft_spec

    return load_spacecraft_spec(path, material="grey", **kw)


LOADERS = {"load_spacecraft": _load, "load_spacecraft_spec": _load_spec}


def _usable(sc) -> None:
    """A spacecraft that loaded is a surface (closed or open) of finite facets, 1 mm to 1 km
    across, whose every edge joins at most two facets."""
    v = np.asarray(sc.mesh.vertices)
    assert sc.n_facets >= 1, f"{sc.n_facets} facets"
    assert np.isfinite(v).all(), "non-finite vertices"
    _, counts = np.unique(np.sort(sc.mesh.edges_sorted, axis=1), axis=0, return_counts=True)
    assert counts.max() <= 2, "a non-manifold surface"
    side = float(np.ptp(v, axis=0).max())
    assert 1e-3 <= side <= 1e3, f"largest side {side:g} m"


@tour_settings(60)
@given(
    suffix=st.sampled_from(MESH_FORMATS),
    how=st.sampled_from(["truncate", "flip", "splice", "junk"]),
    at=st.floats(0.0, 1.0),
    junk=st.binary(min_size=0, max_size=48),
    loader=st.sampled_from(sorted(LOADERS)),
)
def test_spoilt_mesh_bytes(tmp_path, suffix, how, at, junk, loader):
    path = tmp_path / f"box{suffix}"
    data = spoil(mesh_bytes(suffix), how, at, junk)
    path.write_bytes(data)
    run_case(
        CATEGORY,
        lambda: LOADERS[loader](path),
        where=[str(path)],
        check=_usable,
        label=f"{loader} of a {suffix} box, {how} at {at:.3f}",
        timeout=30,
    )


@pytest.mark.parametrize("repair", [False, True])
@pytest.mark.parametrize("broken", sorted(BROKEN_OBJ))
def test_broken_surfaces(tmp_path, broken, repair):
    path = tmp_path / f"{broken}.obj"
    path.write_text(BROKEN_OBJ[broken])
    run_case(
        CATEGORY,
        lambda: _load_spec(path, repair=repair),
        wrong=broken not in ("tetra", "open-box", "one-triangle"),  # open surfaces are fine
        where=[str(path)],
        check=_usable,
        label=f"{broken} (repair={repair})",
        # the message says what the surface is
        match="manifold|more than two facets" if broken == "fin" else None,
    )


@pytest.mark.parametrize("loader", sorted(LOADERS))
@pytest.mark.parametrize("suffix", [".stl", ".obj", ".ply"])
@pytest.mark.parametrize("kind", SPECIAL)
def test_special_mesh_files(tmp_path, kind, suffix, loader):
    path = special_file(tmp_path, kind, suffix)
    run_case(
        CATEGORY,
        lambda: LOADERS[loader](path),
        wrong=True,
        where=[str(path)],
        label=f"{loader} of a {kind} named {path.name}",
        timeout=10,
        unblock=unblock_fifos([path]),
        match=EXPECTED_SPECIAL.get(kind),
    )


#: Length units as users write them, and whether each is wrong.
UNITS = {
    "m": False,
    "mm": False,
    "MM": False,
    "cm": False,
    "km": True,  # a 1-unit box in km is 1 km across: at the plausible limit, warned
    "Mm": True,
    "um": True,
    "nm": True,
    "furlong": True,
    "": True,
    " ": True,
    "m2": True,
    "metre ": False,
    "-1": True,
    "1e9": True,
    "M": True,
    "pc": True,
    "au": True,
    "s": True,
}


@tour_settings(40)
@given(
    unit=st.one_of(
        st.sampled_from(sorted(UNITS)),
        st.text(max_size=5),
        st.sampled_from([5, 0.001, -1.0, float("nan"), True, [], {}]),
    ),
    size=st.sampled_from([1.0, 1e-6, 1e6]),
    loader=st.sampled_from(sorted(LOADERS)),
)
def test_length_units(tmp_path, unit, size, loader):
    import trimesh

    path = tmp_path / "box.stl"
    trimesh.creation.box(extents=(size, size, size)).export(path)
    known = {"m": 1.0, "mm": 1e-3, "MM": 1e-3, "cm": 1e-2, "metre ": 1.0}
    metres = known.get(unit) if isinstance(unit, str) else None
    side = None if metres is None else size * metres
    wrong = side is None or not (1e-3 <= side <= 1e3)
    run_case(
        CATEGORY,
        lambda: LOADERS[loader](path, length_unit=unit),
        wrong=wrong,
        where=["length_unit", str(path), "mesh"],
        check=_usable,
        label=f"{loader}, a {size:g} box, length_unit={unit!r}",
    )
