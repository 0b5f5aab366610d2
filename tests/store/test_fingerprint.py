"""Digests of read-only arrays are kept; writeable arrays are hashed every time."""

import numpy as np
import xarray as xr

from sbrdf_xr.store import fingerprint as fp


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
