"""The store compares fingerprints it is given; the old place of ``scene_fingerprint`` warns."""

import pytest

from sbrdf_xr.errors import RenamedWarning
from sbrdf_xr.store import fingerprint as fp


def test_changes_name_the_material_and_the_setting():
    old = {
        "fingerprint": "a",
        "fingerprint_material_names": '{"w": "white paint"}',
        "fingerprint_material_w": "1",
        "fingerprint_knobs": "k1",
        "fingerprint_knobs_json": '{"method": "linear"}',
        "title": "not a fingerprint",
    }
    new = {
        **old,
        "fingerprint": "b",
        "fingerprint_material_w": "2",
        "fingerprint_knobs": "k2",
        "fingerprint_knobs_json": '{"method": "cubic"}',
    }
    assert fp.changes(old, new) == [
        "material 'white paint': table changed",
        "setting 'method': 'linear' -> 'cubic'",
    ]
    assert fp.changes(old, {**old, "title": "other"}) == []
    assert fp.changes({}, new) == ["only the new cube has a content fingerprint"]


@pytest.mark.parametrize("where", ["sbrdf_xr.store", "sbrdf_xr.store.fingerprint"])
def test_scene_fingerprint_is_served_from_its_old_place_with_a_warning(where):
    import importlib

    from sbrdf_xr.engine.fingerprint import scene_fingerprint

    module = importlib.import_module(where)
    with pytest.warns(RenamedWarning, match=f"{where}.scene_fingerprint moved to sbrdf_xr.engine"):
        assert module.scene_fingerprint is scene_fingerprint
    with pytest.raises(AttributeError, match="no_such_name"):
        module.no_such_name
