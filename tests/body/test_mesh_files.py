"""Mesh files whose declared counts exceed their data or the size limit, and malformed
vertex rows, are refused by name before they are read (sbrdf_xr.body._mesh_files)."""

from __future__ import annotations

import pytest
import trimesh

from sbrdf_xr import load_spacecraft
from sbrdf_xr.errors import MeshError

PLY_HEAD = (
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face {n}\nproperty list uchar int vertex_indices\nend_header\n"
)
ROWS = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 1\n3 1 2 0\n3 2 1 0\n"


@pytest.mark.parametrize(
    ("name", "text", "message"),
    [
        ("huge.ply", PLY_HEAD.format(n=10**9) + ROWS, "about 22.4 GiB once read"),
        ("cut.ply", PLY_HEAD.format(n=100) + ROWS, "declares 103 rows of data, it holds 7"),
        (
            "cut.off",
            "OFF\n4 100 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n3 0 2 3\n3 1 2 3\n",
            "declares 4 vertices and 100 facets, it holds 8 rows",
        ),
        ("huge.off", "OFF\n3 1000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "22.4 GiB"),
        ("flat.obj", "v 0 0\nv 1 0\nv 0 1\nf 1 2 3\n", "line 1 is a vertex of 2 coordinates"),
        ("flat2.obj", "v 0 0\nv 1 0\nv 0 1\nv 1 1\nf 1 2 3\nf 2 3 4\n", "of 2 coordinates"),
        ("mixed.obj", "v 0 0 0\nv 1 0 0\nv 0 1\nf 1 2 3\n", "line 3 is a vertex of 2"),
    ],
)
def test_declared_counts_and_vertex_rows_are_checked(tmp_path, name, text, message):
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(MeshError, match=message) as info:
        load_spacecraft(path, material="paint")
    assert str(path) in str(info.value)


def test_a_binary_ply_cut_short_is_refused_and_a_whole_one_loads(tmp_path):
    whole = trimesh.exchange.ply.export_ply(trimesh.creation.box(), encoding="binary")
    (tmp_path / "box.ply").write_bytes(whole)
    assert load_spacecraft(tmp_path / "box.ply", material="paint").n_facets == 12
    (tmp_path / "cut.ply").write_bytes(whole.replace(b"element face 12", b"element face 1000"))
    with pytest.raises(MeshError, match="cut short"):
        load_spacecraft(tmp_path / "cut.ply", material="paint")


@pytest.mark.parametrize("name", ["box.obj", "box.off", "box.ply"])
def test_whole_files_of_each_format_load(tmp_path, name):
    path = tmp_path / name
    trimesh.creation.box().export(path)
    assert load_spacecraft(path, material="paint").n_facets == 12
