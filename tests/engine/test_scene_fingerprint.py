"""Digests of read-only arrays are kept; writeable arrays are hashed every time."""

import numpy as np
import xarray as xr

from sbrdf_xr.engine import fingerprint as fp


def _table(values: np.ndarray) -> xr.DataArray:
    return xr.DataArray(values, dims=("a", "b"), coords={"a": [0.0, 1.0, 2.0]})


def test_kept_digest_equals_the_digest_computed_afresh():
    v = np.arange(12.0).reshape(3, 4).copy()  # owns its memory
    fresh = fp._table_sha(_table(v.copy()))
    v.flags.writeable = False
    da = _table(v)
    assert fp._table_sha(da) == fresh  # computed, then kept
    assert id(da.values) in fp._DIGESTS
    assert fp._table_sha(da) == fresh  # from the kept digest
    assert fp._array_sha(v) == fp._array_sha_now(v)


def test_changed_values_change_the_fingerprint():
    v = np.arange(12.0).reshape(3, 4).copy()  # owns its memory
    w = v.copy()
    w[1, 2] += 1e-12
    v.flags.writeable = False
    w.flags.writeable = False
    assert fp._table_sha(_table(v)) != fp._table_sha(_table(w))


def test_in_place_change_of_a_writeable_array_is_seen():
    v = np.arange(12.0).reshape(3, 4).copy()  # owns its memory
    da = _table(v)
    before = fp._table_sha(da)
    assert id(v) not in fp._DIGESTS  # writeable: never kept
    da.values[0, 0] = -1.0
    assert fp._table_sha(da) != before


def test_read_only_view_of_a_writeable_array_is_not_kept():
    base = np.arange(12.0).reshape(3, 4).copy()  # owns its memory
    view = base.view()
    view.flags.writeable = False
    before = fp._array_sha(view)
    assert id(view) not in fp._DIGESTS
    base[2, 3] = 99.0  # writes through the base change the view's values
    assert fp._array_sha(view) != before


def test_different_tables_of_the_same_shape_differ():
    a = np.zeros((3, 4))
    b = np.ones((3, 4))
    a.flags.writeable = False
    b.flags.writeable = False
    assert fp._table_sha(_table(a)) != fp._table_sha(_table(b))


def test_kept_digest_is_forgotten_with_its_array():
    v = np.arange(6.0).reshape(3, 2).copy()
    v.flags.writeable = False
    fp._array_sha(v)
    key = id(v)
    assert key in fp._DIGESTS
    del v
    assert key not in fp._DIGESTS


def _read_only_table() -> xr.DataArray:
    v = np.arange(12.0).reshape(3, 4).copy()  # owns its memory
    v.flags.writeable = False
    da = _table(v)
    da.attrs.update(units="sr-1", measured=np.array([1.0, 2.0]), nested={"a": [1, 2]})
    return da


def test_kept_table_digest_equals_the_digest_computed_afresh():
    da = _read_only_table()
    digest = fp._table_sha(da)
    assert id(da) in fp._TABLES and fp._table_sha(da) == digest  # kept, then reused
    assert digest == fp._table_sha_now(da)
    assert fp._table_state(_table(np.zeros((3, 4)))) is None  # writeable: never kept


def test_every_change_to_a_kept_table_changes_its_digest():
    changes = [
        lambda da: da.attrs.update(units="m"),
        lambda da: da.attrs["measured"].__setitem__(0, 5.0),  # an attribute array in place
        lambda da: da.attrs["nested"]["a"].append(3),  # a nested list in place
        lambda da: da.attrs.update(measured=np.array([1, 2])),  # equal values, other dtype
        lambda da: da["a"].attrs.update(units="degree"),
        lambda da: da.coords.update({"a": [0.0, 1.0, 3.0]}),
        lambda da: setattr(da, "values", np.ones((3, 4))),
    ]
    for change in changes:
        da = _read_only_table()
        before = fp._table_sha(da)
        change(da)
        after = fp._table_sha(da)
        assert after != before
        assert after == fp._table_sha_now(da)


def test_the_parts_of_a_fingerprint_are_those_cubes_already_hold():
    """The digests written by the store's earlier ``scene_fingerprint`` (this box scene,
    computed before the function moved to the engine): unfinished cubes still resume.
    The knobs and package parts follow the Scene's fields and the version, so they are
    not pinned here."""
    import trimesh

    from sbrdf_xr import Scene, load_spacecraft
    from sbrdf_xr.materials.schema import lambertian

    box = load_spacecraft(trimesh.creation.box(), material="grey")
    grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    scene = Scene(
        box, {"grey": grey}, attitudes=[[0, 0, 0, 1.0]], phase_angles=[0.0, 60.0], bands=("V",)
    )
    got = fp.scene_fingerprint(scene)
    assert {k: got[k] for k in PINNED} == PINNED


PINNED = {
    "fingerprint_filters": "21e1942fe20caf6d9010cf0f89dbf73683046cefb398d565b54c7800357c8ed0",
    "fingerprint_geometry": "1031e722b170c62de0d7ebffbce97b0808da398d880d7104d47e23e5435beef1",
    "fingerprint_material_grey": "26d56fe37a97136fd2ec147fbf2a90e75fa936be4dca29a22c9a87c987b515a3",
    "fingerprint_material_names": '{"grey": "grey"}',
    "fingerprint_materials": "7a53b719791efdbb79d3811b17766d1c3784da77a6dde48ba299eceed4151fc7",
    "fingerprint_mesh": "2bb062f8b6878db9a016451670b81728b9bfba791983facc18939c9d934127cc",
}


def test_a_renamed_field_keeps_its_old_name_in_the_fingerprint():
    """``Scene.earth_range`` was ``earth_range_km``: the knobs JSON (and so the digest of a
    scene that did not change) still says ``earth_range_km``, whichever name built the
    scene, in Python or in a scene file (the old key with a RenamedWarning)."""
    import json

    import pytest
    import trimesh

    from sbrdf_xr import Scene, load_spacecraft
    from sbrdf_xr.engine import scene_from_dict
    from sbrdf_xr.errors import RenamedWarning
    from sbrdf_xr.materials.schema import lambertian

    box = load_spacecraft(trimesh.creation.box(), material="grey")
    grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    kw = dict(attitudes=[[0, 0, 0, 1.0]], phase_angles=[0.0, 60.0])
    new = fp.scene_fingerprint(Scene(box, {"grey": grey}, earth_range=7000.0, **kw))
    knobs = json.loads(new["fingerprint_knobs_json"])
    assert knobs["earth_range_km"] == "7000.0" and "earth_range" not in knobs
    assert '"earth_range_km":"7000.0"' in new["fingerprint_knobs_json"]  # the bytes hashed
    with pytest.warns(RenamedWarning, match="'earth_range_km' is renamed 'earth_range'"):
        old = fp.scene_fingerprint(Scene(box, {"grey": grey}, earth_range_km=7000.0, **kw))
    assert old == new
    table = {"spacecraft": "canx1", "attitude": {"kind": "sweep", "stop": 1}, "phase_angles": [0.0]}
    from_new = fp.scene_fingerprint(scene_from_dict({**table, "earth_range": 7000.0}))
    with pytest.warns(RenamedWarning, match="scene: the key 'earth_range_km' is renamed"):
        from_old = fp.scene_fingerprint(scene_from_dict({**table, "earth_range_km": 7000.0}))
    assert from_old == from_new
    assert fp.scene_fingerprint(scene_from_dict(table)) != from_new
