"""Tests of sbrdf_xr.body.spacecraft: loading and checking meshes, facet tables, merging, CanX-1."""

from __future__ import annotations

import importlib.util
import warnings
from pathlib import Path

import matplotlib
import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis_profiles import examples

from sbrdf_xr import catalog
from sbrdf_xr.body import spacecraft as sc
from sbrdf_xr.errors import MeshError, ValidationError
from sbrdf_xr.testing import cube_spacecraft, l_shaped_spacecraft


def _tool(name: str):
    """A build script of ``tools/`` (not part of the package), imported by path."""
    path = Path(__file__).resolve().parents[2] / "tools" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"tools_{name}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


_build_canx1 = _tool("build_canx1")

matplotlib.use("Agg")

ALU, CELL, PAINT = "aluminium-6061-t6", "tjpv-cell", "white-paint-a276"
#: Areas of the CanX-1 model are sums of products of half-millimetre multiples in metres:
#: exact up to float64 rounding of ~700 terms, so 1e-12 relative is ample and still sharp.
AREA_RTOL = 1e-12


_CANX1 = sc.canx1()
_MERGED = _CANX1.merged()


@pytest.fixture
def canx1() -> sc.Spacecraft:
    return _CANX1


def coloured_box(colours: np.ndarray | None = None) -> trimesh.Trimesh:
    """A unit box whose 12 facets are red (first 6) and blue (last 6)."""
    box = trimesh.creation.box()
    if colours is None:
        colours = np.repeat([[255, 0, 0, 255], [0, 0, 255, 255]], 6, axis=0)
    box.visual.face_colors = colours
    return box


BOX_MAP = {(255, 0, 0): ALU, (0, 0, 255): CELL}


# ----------------------------------------------------------------------------- CanX-1


def test_canx1_geometry(canx1):
    mesh = canx1.mesh
    assert canx1.n_facets == 684
    assert canx1.materials == [ALU, CELL, PAINT]
    assert mesh.is_watertight and mesh.is_winding_consistent
    assert mesh.volume > 0
    assert not canx1.is_convex  # raised cells
    # 10 cm cube plus 0.5 mm cells on +-X and tilted cells up to 1 + 35 tan(1 deg) mm on +-Y [m]
    y_top = 0.050 + 1e-3 * (_build_canx1.CELL_HEIGHT_Y + 35.0 * np.tan(np.radians(1.0)))
    np.testing.assert_allclose(
        mesh.bounds, [[-0.0505, -y_top, -0.05], [0.0505, y_top, 0.05]], rtol=0, atol=1e-9
    )


def side_area(craft, material, axis, sign):
    """Area of the facets of a material facing a side, projected onto that side [m2]."""
    n = craft.mesh.face_normals
    on_side = (
        craft.mesh.triangles_center[:, axis] * sign >= 0.05 - 1e-9
    )  # not the cell walls of other sides
    sel = (craft.facet_material == material) & (n[:, axis] * sign > 0.5) & on_side
    return (craft.mesh.area_faces[sel] * np.abs(n[sel, axis])).sum()


def test_canx1_materials_per_side(canx1):
    """Same cell coverage on the four sides, more aluminium on +-Y (paper 000 §4.2)."""
    cells = [side_area(canx1, CELL, ax, s) for ax in (0, 1) for s in (1, -1)]
    np.testing.assert_allclose(cells, 2 * 0.040 * 0.070, rtol=AREA_RTOL)
    alu_x = [side_area(canx1, ALU, 0, s) for s in (1, -1)]
    alu_y = [side_area(canx1, ALU, 1, s) for s in (1, -1)]
    np.testing.assert_allclose(alu_x, 1900e-6, rtol=AREA_RTOL)
    np.testing.assert_allclose(alu_y, 2800e-6, rtol=AREA_RTOL)
    for ax in (0, 1, 2):
        for s in (1, -1):
            total = sum(side_area(canx1, m, ax, s) for m in canx1.materials)
            np.testing.assert_allclose(total, 0.01, rtol=AREA_RTOL)  # each face is 10 cm x 10 cm
    assert side_area(canx1, ALU, 2, 1) == 0  # top and bottom are painted


def test_canx1_cell_layout(canx1):
    """+-X cells side by side along y and flush (one normal, glint in unison); +-Y cells
    stacked along z, each tilted 1 deg about z the other way (they glint in turn)."""
    c = canx1.mesh.triangles_center
    n = canx1.mesh.face_normals
    tilt = np.radians(_build_canx1.Y_CELL_TILT)
    for axis, spread_axis in ((0, 1), (1, 2)):
        for sign in (1, -1):
            top = (
                (canx1.facet_material == CELL)
                & (n[:, axis] * sign > 0.99)
                & (c[:, axis] * sign > 0.0502)
            )
            if axis == 0:
                # equal normals up to the rounding of trimesh's normalisation (1 ulp), one term
                np.testing.assert_allclose(
                    n[top], np.tile(np.eye(3)[axis] * sign, (top.sum(), 1)), rtol=0, atol=2e-16
                )
                assert len(set(_MERGED["facet_term"].values[top])) == 1
            else:
                # upper cell (z > 0) rotated by +tilt about z, lower by -tilt
                rot = np.where(c[top, 2] > 0, tilt, -tilt)
                expected = sign * np.stack([-np.sin(rot), np.cos(rot), 0 * rot], axis=1)
                # the PLY stores 9 significant digits of mm: normals to ~1e-8
                np.testing.assert_allclose(n[top], expected, rtol=0, atol=1e-7)
                assert len(set(_MERGED["facet_term"].values[top])) == 2
            # two cells, separated by a 4 mm gap along the spreading axis only
            coord = canx1.mesh.triangles[top][:, :, spread_axis]
            assert np.all(
                (coord.max(axis=1) <= -0.002 + 1e-12) | (coord.min(axis=1) >= 0.002 - 1e-12)
            )
            other = 3 - axis - spread_axis
            assert np.ptp(canx1.mesh.triangles[top][:, :, other]) == pytest.approx(0.070, rel=1e-12)


def test_canx1_shipped_file_is_regenerated_identically():
    assert (
        catalog.data_path("spacecraft/canx1.ply").read_text(encoding="ascii")
        == _build_canx1.ply_text()
    )
    assert (
        catalog.data_path("spacecraft/canx1.toml").read_text(encoding="ascii")
        == _build_canx1.MAP_TEXT
    )
    assert sc.read_material_map(catalog.data_path("spacecraft/canx1.toml")) == {
        v: k for k, v in sc.CANX1_MATERIALS.items()
    }


def test_canx1_builder_writes_files(tmp_path):
    assert _build_canx1.main([str(tmp_path)]) == 0
    craft = sc.load_spacecraft(tmp_path / "canx1.ply", tmp_path / "canx1.toml", length_unit="mm")
    assert craft.n_facets == 684 and craft.name == "canx1"


def test_canx1_catalog_entry(canx1):
    e = catalog.entry("canx1")
    assert (e.kind, e.source, e.path) == ("spacecraft", "synthetic", "spacecraft/canx1.ply")
    assert e.extra["length_unit"] == "mm" and e.description and e.provenance
    loaded = catalog.load("canx1")
    assert isinstance(loaded, sc.Spacecraft)
    np.testing.assert_array_equal(loaded.facet_material, canx1.facet_material)
    np.testing.assert_array_equal(loaded.mesh.vertices, canx1.mesh.vertices)


def test_canx1_plot(canx1):
    import matplotlib.pyplot as plt

    fig = canx1.plot()
    try:
        fig.canvas.draw()
        ax = fig.axes[0]
        assert ax.name == "3d"
        assert len(ax.collections[0].get_paths()) == canx1.n_facets
        assert [t.get_text() for t in fig.legends[0].get_texts()] == canx1.materials
        # facets coloured by material with the paper's colours, red, blue and white,
        # shaded by their orientation (each a darker or equal shade of its colour)
        shades = np.asarray(ax.collections[0].get_facecolor())[:, :3]
        kinds = {tuple(c > 1e-3) for c in shades}
        assert kinds == {(True, False, False), (False, False, True), (True, True, True)}
        white = shades[np.all(shades > 1e-3, axis=1)]
        assert np.allclose(white, white[:, :1]) and 0.2 < white.min() < white.max() <= 1.0
        assert ax.get_zlabel() == "z [m]" and not ax.zaxis.get_rotate_label(ax.get_zlabel())
    finally:
        plt.close(fig)
    fig, ax = plt.subplots(subplot_kw={"projection": "3d"})
    assert canx1.plot(ax=ax, legend=False, colors={ALU: "k"}) is fig
    plt.close(fig)


# ----------------------------------------------------------------------------- facet table


def test_facets_dataset(canx1):
    ds = canx1.facets()
    assert dict(ds.sizes) == {"facet": 684, "xyz": 3}
    assert list(ds["xyz"].values) == ["x", "y", "z"]
    for name in [*ds.data_vars, *ds.coords]:
        assert {"units", "long_name"} <= set(ds[name].attrs), name
    assert ds["area"].attrs["units"] == "m2" and ds["centroid"].attrs["units"] == "m"
    np.testing.assert_allclose(np.linalg.norm(ds["normal"].values, axis=1), 1.0, rtol=1e-15)
    np.testing.assert_allclose(ds["area"].sum(), canx1.mesh.area, rtol=AREA_RTOL)
    assert ds["material"].dtype.kind == "U"
    assert canx1.facet_material.dtype.kind == "U"
    with pytest.raises(ValueError):
        canx1.facet_material[0] = "x"  # read-only labels


def test_is_convex_tolerates_coplanar_facets():
    assert cube_spacecraft(subdivisions=3).is_convex
    assert not l_shaped_spacecraft().is_convex


# ----------------------------------------------------------------------------- merging


def test_merged_canx1_reduction(canx1):
    """684 facets -> 20 terms: 3 materials x 4 sides, paint on +-Z, cell walls facing +-Z,
    and one more cell term on each of +-Y (its two cells are tilted apart), plus the two
    +-Y cell walls facing +-x that the tilt turns away from the axes."""
    m = canx1.merged()
    assert canx1.n_facets == 684 and m.sizes["term"] == 20
    assert int(m["n_facets"].sum()) == canx1.n_facets
    np.testing.assert_allclose(m["area"].sum(), canx1.mesh.area, rtol=AREA_RTOL)
    term = m["facet_term"].values
    np.testing.assert_allclose(
        np.bincount(term, weights=canx1.mesh.area_faces), m["area"].values, rtol=AREA_RTOL
    )
    np.testing.assert_array_equal(m["material"].values[term], canx1.facet_material)
    # term normals are the facet normals up to rounding (trimesh normals are within 1 ulp
    # of the axes)
    np.testing.assert_allclose(
        m["normal"].values[term], canx1.mesh.face_normals, rtol=0, atol=1e-15
    )
    for name in [*m.data_vars, *m.coords]:
        assert {"units", "long_name"} <= set(m[name].attrs), name


WEIGHT = {ALU: 0.3, CELL: 1.7, PAINT: 0.8}


@settings(max_examples=examples(60), deadline=None)
@given(
    st.lists(st.floats(-1, 1), min_size=3, max_size=3).filter(lambda v: np.linalg.norm(v) > 1e-3),
    st.lists(st.floats(-1, 1), min_size=3, max_size=3).filter(lambda v: np.linalg.norm(v) > 1e-3),
)
def test_merged_sum_equals_facet_sum(s, o):
    """sum_j A_j max(N_j.s,0) max(N_j.o,0) w(m_j) is the same over facets and over terms.

    Summands depend on (normal, material) only and the merged normals equal the facet normals
    to 1e-16, so the two sums differ by rounding only: rtol 1e-12 (rounding of ~700
    positive terms is ~1e-14 relative; the sum can be 0 when nothing faces both directions).
    """
    craft = _CANX1
    s = np.asarray(s) / np.linalg.norm(s)
    o = np.asarray(o) / np.linalg.norm(o)
    n, a = craft.mesh.face_normals, craft.mesh.area_faces
    w = np.array([WEIGHT[k] for k in craft.facet_material])
    per_facet = np.sum(a * np.maximum(n @ s, 0) * np.maximum(n @ o, 0) * w)
    m = _MERGED
    wt = np.array([WEIGHT[k] for k in m["material"].values])
    nt = m["normal"].values
    per_term = np.sum(m["area"].values * np.maximum(nt @ s, 0) * np.maximum(nt @ o, 0) * wt)
    np.testing.assert_allclose(per_term, per_facet, rtol=1e-12, atol=1e-300)


def test_merged_tolerance_on_rotated_body():
    """A rotated cube has normals equal only to rounding (~1e-16): still one term per face.

    The area-weighted term normal is within 1e-15 of each facet normal (rounding only).
    """
    rot = trimesh.transformations.rotation_matrix(0.3, [1, 2, 3])
    box = trimesh.creation.box()
    box.apply_transform(rot)
    box.visual.face_colors = [9, 9, 9, 255]
    craft = sc.load_spacecraft(box, {(9, 9, 9): PAINT})
    m = craft.merged()
    assert m.sizes["term"] == 6
    np.testing.assert_allclose(
        m["normal"].values[m["facet_term"].values], craft.mesh.face_normals, atol=1e-15
    )
    assert craft.merged(tolerance=1e-18).sizes["term"] >= 6
    with pytest.raises(ValidationError, match="tolerance"):
        craft.merged(tolerance=0)


def test_merged_keeps_materials_apart():
    craft = sc.load_spacecraft(
        coloured_box(np.tile([[255, 0, 0, 255], [0, 0, 255, 255]], (6, 1))), BOX_MAP
    )
    m = craft.merged()
    expected = {
        (tuple(np.round(n).astype(int)), mat)
        for n, mat in zip(craft.mesh.face_normals, craft.facet_material, strict=True)
    }
    assert m.sizes["term"] == len(expected) > 6  # some faces carry both materials
    assert sorted(set(m["material"].values)) == [ALU, CELL]


# ----------------------------------------------------------------------------- formats


def write_binary_stl(path, mesh: trimesh.Trimesh, rgb: np.ndarray) -> None:
    """Binary STL with VisCAM/SolidView colours (bit 15 valid, 5 bits per channel R, G, B)."""
    dt = np.dtype([("normals", "<f4", 3), ("vertices", "<f4", (3, 3)), ("attributes", "<u2")])
    rec = np.zeros(len(mesh.faces), dtype=dt)
    rec["normals"] = mesh.face_normals
    rec["vertices"] = mesh.triangles
    c5 = np.round(np.asarray(rgb) * 31 / 255).astype(np.uint16)
    rec["attributes"] = 0x8000 | (c5[:, 0] << 10) | (c5[:, 1] << 5) | c5[:, 2]
    with open(path, "wb") as f:
        f.write(b"\0" * 80)
        f.write(np.uint32(len(rec)).tobytes())
        f.write(rec.tobytes())


def test_load_binary_stl_colours_in_mm(tmp_path):
    box = trimesh.creation.box(extents=(100, 100, 100))  # a CAD export in mm
    rgb = np.repeat([[255, 0, 0], [0, 0, 255]], 6, axis=0)
    write_binary_stl(tmp_path / "box.stl", box, rgb)
    craft = sc.load_spacecraft(tmp_path / "box.stl", BOX_MAP, length_unit="mm")
    assert craft.name == "box"
    np.testing.assert_allclose(craft.mesh.extents, 0.1, rtol=1e-7)  # float32 file
    np.testing.assert_array_equal(craft.facet_material, [ALU] * 6 + [CELL] * 6)
    assert craft.mesh.is_watertight  # STL vertices merged
    np.testing.assert_allclose(craft.mesh.area, 0.06, rtol=1e-6)


def test_load_stl_without_colours_is_unmapped(tmp_path):
    box = trimesh.creation.box()
    box.export(tmp_path / "plain.stl")
    with pytest.raises(MeshError, match="unmapped"):
        sc.load_spacecraft(tmp_path / "plain.stl", BOX_MAP)


def test_one_material_body_needs_no_labels(tmp_path):
    box = trimesh.creation.box()
    box.export(tmp_path / "plain.stl")
    craft = sc.load_spacecraft(tmp_path / "plain.stl", material=PAINT)
    assert craft.facet_material.tolist() == [PAINT] * 12
    np.testing.assert_allclose(craft.mesh.area, 6.0, rtol=1e-6)
    with pytest.raises(ValidationError, match="exactly one of material_map"):
        sc.load_spacecraft(tmp_path / "plain.stl")
    with pytest.raises(ValidationError, match="exactly one of material_map"):
        sc.load_spacecraft(tmp_path / "plain.stl", BOX_MAP, material=PAINT)
    with pytest.raises(ValidationError, match="does not exist"):
        sc.load_spacecraft(tmp_path / "plain.stl", material="unobtainium", known_materials=[PAINT])


def test_load_obj_material_groups(tmp_path):
    box = trimesh.creation.box()
    lines = ["mtllib box.mtl"] + [f"v {x} {y} {z}" for x, y, z in box.vertices]
    lines += ["g frame", "usemtl alu"] + [f"f {a} {b} {c}" for a, b, c in box.faces[:6] + 1]
    lines += ["g panels", "usemtl cell"] + [f"f {a} {b} {c}" for a, b, c in box.faces[6:] + 1]
    (tmp_path / "box.obj").write_text("\n".join(lines) + "\n")
    (tmp_path / "box.mtl").write_text("newmtl alu\nKd 1 0 0\nnewmtl cell\nKd 0 0 1\n")
    craft = sc.load_spacecraft(tmp_path / "box.obj", {"alu": ALU, "cell": CELL}, length_unit="cm")
    assert craft.mesh.is_watertight
    np.testing.assert_allclose(craft.mesh.extents, 0.01)
    alu = craft.facet_material == ALU
    assert alu.sum() == 6
    # the aluminium facets are the first six of the file, wherever trimesh put them
    np.testing.assert_allclose(
        np.sort(craft.mesh.triangles_center[alu], axis=0),
        np.sort(box.triangles_center[:6] * 0.01, axis=0),
        atol=1e-15,
    )


def test_load_ply_face_colours_and_property(tmp_path):
    box = coloured_box()
    box.export(tmp_path / "box.ply")
    craft = sc.load_spacecraft(
        tmp_path / "box.ply", {"#ff0000": ALU, (0, 0, 255): CELL}, length_unit="in"
    )
    np.testing.assert_array_equal(craft.facet_material, [ALU] * 6 + [CELL] * 6)
    np.testing.assert_allclose(craft.mesh.extents, 0.0254, rtol=1e-7)
    header = (
        "ply\nformat ascii 1.0\nelement vertex 8\n"
        "property float x\nproperty float y\nproperty float z\n"
        "element face 12\nproperty list uchar int vertex_indices\n"
        "property int material_id\nend_header\n"
    )
    body = "".join(f"{x} {y} {z}\n" for x, y, z in box.vertices)
    body += "".join(f"3 {a} {b} {c} {i // 6}\n" for i, (a, b, c) in enumerate(box.faces))
    (tmp_path / "prop.ply").write_text(header + body)
    craft = sc.load_spacecraft(
        tmp_path / "prop.ply", {0: ALU, 1: CELL}, face_property="material_id"
    )
    np.testing.assert_array_equal(craft.facet_material, [ALU] * 6 + [CELL] * 6)
    with pytest.raises(MeshError, match=r"no face property 'colour'.*material_id"):
        sc.load_spacecraft(tmp_path / "prop.ply", {0: ALU}, face_property="colour")


def test_load_glb_materials(tmp_path):
    box = trimesh.creation.box()
    scene = trimesh.Scene()
    for name, faces, colour in (
        ("alu", box.faces[:6], [255, 0, 0, 255]),
        ("cell", box.faces[6:], [0, 0, 255, 255]),
    ):
        part = trimesh.Trimesh(box.vertices, faces, process=False)
        part.visual = trimesh.visual.TextureVisuals(
            material=trimesh.visual.material.PBRMaterial(name=name, baseColorFactor=colour)
        )
        scene.add_geometry(part, geom_name=f"part-{name}")
    scene.export(tmp_path / "box.glb")
    by_name = sc.load_spacecraft(tmp_path / "box.glb", {"alu": ALU, "cell": CELL})
    by_colour = sc.load_spacecraft(tmp_path / "box.glb", BOX_MAP)
    for craft in (by_name, by_colour):
        assert craft.n_facets == 12 and craft.mesh.is_watertight
        assert sorted(craft.facet_material.tolist()) == [ALU] * 6 + [CELL] * 6
        assert craft.materials == [ALU, CELL]
    np.testing.assert_array_equal(by_name.facet_material, by_colour.facet_material)


def test_load_trimesh_object_and_scene_transform():
    box = coloured_box()
    scene = trimesh.Scene()
    scene.add_geometry(
        box, geom_name="body", transform=trimesh.transformations.translation_matrix([5, 0, 0])
    )
    craft = sc.load_spacecraft(scene, BOX_MAP, name="moved")
    assert craft.name == "moved"
    np.testing.assert_allclose(craft.mesh.centroid, [5, 0, 0], atol=1e-12)


# ----------------------------------------------------------------------------- bad input


@pytest.mark.parametrize("unit", ["parsec", "", "M M", 3])
def test_bad_length_unit(unit):
    with pytest.raises(ValidationError, match=r"length_unit.*(allowed: m, meter|length unit name)"):
        sc.load_spacecraft(coloured_box(), BOX_MAP, length_unit=unit)


def test_no_length_unit_is_the_files_own_else_metres():
    box = sc.load_spacecraft(coloured_box(), BOX_MAP)  # a trimesh object states none
    assert (
        box.mesh.extents.tolist()
        == sc.load_spacecraft(coloured_box(), BOX_MAP, length_unit="m").mesh.extents.tolist()
    )


def test_length_units_convert():
    assert sc.length_factor("MM") == 1e-3 and sc.length_factor("in") == 0.0254


def test_unmapped_colour_is_named():
    with pytest.raises(MeshError, match=r"6 of 12 facets are unmapped.*\(0, 0, 255\)"):
        sc.load_spacecraft(coloured_box(), {(255, 0, 0): ALU})


def test_unknown_material_in_map():
    with pytest.raises(
        ValidationError, match=r"\['tjpv-cell'\] that do not exist; known materials"
    ):
        sc.load_spacecraft(coloured_box(), BOX_MAP, known_materials=[ALU, PAINT])
    craft = sc.load_spacecraft(coloured_box(), BOX_MAP, known_materials=[ALU, CELL, PAINT])
    assert craft.materials == [ALU, CELL]


@pytest.mark.parametrize(
    ("mapping", "match"),
    [
        ({(256, 0, 0): ALU}, "0-255"),
        ({(1.5, 0, 0): ALU}, "0-255"),
        ({(1, 2): ALU}, "neither a colour"),
        ({(1, 2, 3): ""}, "non-empty"),
        ({}, "non-empty mapping"),
    ],
)
def test_bad_material_map(mapping, match):
    with pytest.raises(ValidationError, match=match):
        sc.load_spacecraft(coloured_box(), mapping)


def test_not_a_mesh(tmp_path):
    (tmp_path / "notes.txt").write_text("not a mesh\n")
    with pytest.raises(MeshError, match="could not be read as a mesh"):
        sc.load_spacecraft(tmp_path / "notes.txt", BOX_MAP)
    (tmp_path / "junk.stl").write_bytes(b"\x01\x02garbage")
    with pytest.raises(MeshError):
        sc.load_spacecraft(tmp_path / "junk.stl", BOX_MAP)
    with pytest.raises(MeshError, match="does not exist"):
        sc.load_spacecraft(tmp_path / "missing.ply", BOX_MAP)
    with pytest.raises(MeshError, match="expected a triangle mesh"):
        sc.load_spacecraft(trimesh.PointCloud(np.random.default_rng(0).random((5, 3))), BOX_MAP)


def test_empty_mesh():
    with pytest.raises(MeshError, match="empty"):
        sc.load_spacecraft(trimesh.Trimesh(np.zeros((0, 3)), np.zeros((0, 3), int)), BOX_MAP)
    with pytest.raises(MeshError, match="empty scene"):
        sc.load_spacecraft(trimesh.Scene(), BOX_MAP)


def broken(kind: str) -> trimesh.Trimesh:
    """A coloured box with one defect."""
    box = trimesh.creation.box()
    v, f = np.array(box.vertices), np.array(box.faces)
    c = np.repeat([[255, 0, 0, 255], [0, 0, 255, 255]], 6, axis=0)
    if kind == "nan":
        v = np.vstack([v, [np.nan, 0, 0]])
        f = np.vstack([f, [[0, 1, 8]]])
        c = np.vstack([c, [255, 0, 0, 255]])
    elif kind == "zero_area":
        v = np.vstack([v, (v[0] + v[1]) / 2])  # a point on an edge: a collinear sliver
        f = np.vstack([f, [[0, 8, 1]]])
        c = np.vstack([c, [255, 0, 0, 255]])
    elif kind == "duplicate":
        f = np.vstack([f, f[3][::-1]])
        c = np.vstack([c, c[3]])
    elif kind == "open":
        f, c = f[1:], c[1:]
    elif kind == "winding":
        f[4] = f[4][::-1]
    elif kind == "inside_out":
        f = f[:, ::-1]
    mesh = trimesh.Trimesh(v, f, process=False, validate=False)
    mesh.visual.face_colors = c
    return mesh


@pytest.mark.parametrize(
    ("kind", "match"),
    [
        ("nan", "not finite"),
        ("zero_area", "zero area"),
        ("duplicate", "duplicate"),
        ("winding", "not consistently wound"),
        ("inside_out", "inside-out"),
    ],
)
def test_mesh_defects_raise_or_are_repaired_with_a_warning(kind, match):
    with pytest.raises(MeshError, match=f"{match}.*repair=True"):
        sc.load_spacecraft(broken(kind), BOX_MAP)
    with pytest.warns(sc.MeshRepairWarning, match=match):
        craft = sc.load_spacecraft(broken(kind), BOX_MAP, repair=True)
    mesh = craft.mesh
    assert mesh.is_watertight and mesh.is_winding_consistent
    np.testing.assert_allclose(mesh.volume, 1.0, rtol=1e-12)
    assert craft.n_facets == 12 and len(craft.facet_material) == 12
    np.testing.assert_array_equal(np.sort(craft.facet_material), [ALU] * 6 + [CELL] * 6)


def test_an_open_surface_loads_without_repair_and_refuses_a_volume():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        craft = sc.load_spacecraft(broken("open"), BOX_MAP)
        repaired = sc.load_spacecraft(broken("open"), BOX_MAP, repair=True)
    assert craft.n_facets == repaired.n_facets == 11
    assert not craft.is_convex
    with pytest.raises(MeshError, match=r"inertia: needs a volume.*open"):
        craft.inertia()


def test_repair_never_warns_repaired_before_failing():
    mesh = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [np.nan, 0, 0]], [[0, 1, 2]], process=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a warning here would fail the test
        with pytest.raises(MeshError, match="empty after removing"):
            sc.load_spacecraft(mesh, material="paint", repair=True)


def test_repair_on_clean_mesh_is_silent():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        craft = sc.load_spacecraft(coloured_box(), BOX_MAP, repair=True)
    assert craft.n_facets == 12


def test_spacecraft_constructor_validates():
    box = trimesh.creation.box()
    with pytest.raises(ValidationError, match="one per facet"):
        sc.Spacecraft(box, ["a"] * 11)
    with pytest.raises(ValidationError, match=r"trimesh\.Trimesh"):
        sc.Spacecraft("box", ["a"] * 12)
    assert "12 facets" in repr(sc.Spacecraft(box, ["a"] * 12, name="b"))


def test_read_material_map_errors(tmp_path):
    (tmp_path / "bad.toml").write_text("[[material]]\nrgb = [1, 2, 3]\n")
    with pytest.raises(ValidationError, match="lacks a 'name'"):
        sc.read_material_map(tmp_path / "bad.toml")
    (tmp_path / "none.toml").write_text("x = 1\n")
    with pytest.raises(ValidationError, match=r"\[\[material\]\]"):
        sc.read_material_map(tmp_path / "none.toml")
    (tmp_path / "labels.toml").write_text(
        '[[material]]\nname = "a"\nlabels = ["alu", 3]\nrgb = [[1, 2, 3], [4, 5, 6]]\n'
    )
    assert sc.read_material_map(tmp_path / "labels.toml") == {
        (1, 2, 3): "a",
        (4, 5, 6): "a",
        "alu": "a",
        3: "a",
    }


# --------------------------------------------------------------------------- tangents


def _tangent_box() -> trimesh.Trimesh:
    box = trimesh.creation.box()
    rng = np.random.default_rng(7)
    box.face_attributes["tangent"] = rng.normal(size=(len(box.faces), 3))
    return box


def _projected(normals, d):
    t = d - np.einsum("fk,fk->f", d, normals)[:, None] * normals
    return t / np.linalg.norm(t, axis=1, keepdims=True)


def test_tangents_default_direction_and_per_facet():
    box = trimesh.creation.box()
    n = box.face_normals
    craft = sc.load_spacecraft(box, material="paint")
    assert craft.tangent_source == "default"
    # body x projected; on the +-x faces the fallback: y (the axis least aligned with x)
    want = np.where(np.abs(n[:, :1]) > 0.5, [0.0, 1.0, 0.0], [1.0, 0.0, 0.0])
    np.testing.assert_array_equal(craft.facet_tangent, want)
    craft = sc.load_spacecraft(box, material="paint", tangent=(1.0, 2.0, 3.0))
    assert craft.tangent_source == "direction"
    np.testing.assert_allclose(
        craft.facet_tangent, _projected(n, np.array([[1.0, 2, 3]])), rtol=1e-14
    )
    ds = craft.facets()
    assert ds.tangent.dims == ("facet", "xyz") and ds.tangent.attrs["units"] == "1"
    assert np.abs(np.einsum("fk,fk->f", ds.tangent.values, ds.normal.values)).max() < 1e-15
    with pytest.raises(ValidationError, match="tangent"):
        sc.load_spacecraft(box, material="paint", tangent=np.ones((5, 3)))


def test_tangents_from_a_mesh_attribute_and_a_ply_file(tmp_path):
    box = _tangent_box()
    want = _projected(box.face_normals, np.asarray(box.face_attributes["tangent"]))
    craft = sc.load_spacecraft(box, material="paint")
    assert craft.tangent_source == "mesh attribute"
    np.testing.assert_allclose(craft.facet_tangent, want, rtol=1e-14)
    for encoding in ("binary", "ascii"):
        path = tmp_path / f"box-{encoding}.ply"
        path.write_bytes(box.export(file_type="ply", encoding=encoding))
        craft = sc.load_spacecraft(path, material="paint")
        # ASCII PLY keeps about 8 significant digits
        rtol = 1e-12 if encoding == "binary" else 1e-6
        np.testing.assert_allclose(craft.facet_tangent, want, rtol=rtol, atol=rtol)
    # an explicit direction wins over the file's attribute
    craft = sc.load_spacecraft(box, material="paint", tangent=(0.0, 0.0, 1.0))
    assert craft.tangent_source == "direction"


def test_tangents_follow_their_facets_through_repairs():
    box = _tangent_box()
    faces = np.vstack([box.faces, box.faces[:1]])  # a duplicate of facet 0
    tang = np.vstack([box.face_attributes["tangent"], [[5.0, 5.0, 5.0]]])
    dup = trimesh.Trimesh(box.vertices, faces, process=False)
    dup.face_attributes["tangent"] = tang
    with pytest.warns(sc.MeshRepairWarning, match="duplicate"):
        craft = sc.load_spacecraft(dup, material="paint", repair=True)
    assert craft.n_facets == 12
    np.testing.assert_allclose(
        craft.facet_tangent,
        _projected(craft.mesh.face_normals, np.asarray(box.face_attributes["tangent"])),
        rtol=1e-12,
    )


def test_merging_keeps_facets_of_different_tangents_apart_for_anisotropic_materials():
    craft = cube_spacecraft(1.0, subdivisions=2)  # 8 facets per face
    tang = np.tile([1.0, 0.0, 0.0], (craft.n_facets, 1))
    tang[::2] = [0.0, 1.0, 1.0]
    craft = craft.with_tangent(tang)
    assert craft.tangent_source == "per facet"
    mat = craft.materials[0]
    assert craft.merged().sizes["term"] == 6
    m = craft.merged(tangent_materials=[mat])
    assert m.sizes["term"] == 12
    # every term's tangent is its members' (t and -t alike) and orthogonal to its normal
    tt, ft = m.tangent.values[m.facet_term.values], craft.facet_tangent
    np.testing.assert_allclose(np.abs(np.einsum("fk,fk->f", tt, ft)), 1.0, rtol=1e-12)
    # t and -t merge
    flipped = craft.with_tangent(
        tang * np.where(np.arange(craft.n_facets) % 4 == 0, -1, 1)[:, None]
    )
    assert flipped.merged(tangent_materials=[mat]).sizes["term"] == 12


def test_fingerprint_sees_tangents_only_when_they_are_given():
    from sbrdf_xr.engine.fingerprint import _mesh_sha

    craft = cube_spacecraft(1.0)
    assert _mesh_sha(craft.with_tangent((0.0, 0.0, 1.0))) != _mesh_sha(craft)
    assert _mesh_sha(craft.with_tangent((0.0, 0.0, 1.0))) != _mesh_sha(
        craft.with_tangent((0.0, 1.0, 0.0))
    )
