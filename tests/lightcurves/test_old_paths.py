"""The names that moved from ``sbrdf_xr.photometry`` to ``sbrdf_xr.lightcurves`` still
answer under their old path for one release, each with a RenamedWarning naming the new one."""

from __future__ import annotations

import pytest

import sbrdf_xr.lightcurves as L
import sbrdf_xr.photometry as P
from sbrdf_xr.errors import RenamedWarning

# (old name under photometry, its name under lightcurves)
MOVED = [
    ("read_light_curve", "read_light_curve"),
    ("compare", "compare"),
    ("compare_light_curves", "compare_light_curves"),
    ("plot_comparison", "plot_comparison"),
    ("compare_magnitudes", "compare_magnitudes"),
    ("binned_residuals", "binned_residuals"),
    ("band_label", "band_label"),
    ("TABLE_FORMATS", "TABLE_FORMATS"),
    ("LIGHT_CURVE_ABSCISSAE", "LIGHT_CURVE_ABSCISSAE"),
    ("LIGHT_CURVE_COLUMNS", "LIGHT_CURVE_COLUMNS"),
    ("LIGHT_CURVE_OPTIONAL", "LIGHT_CURVE_OPTIONAL"),
    ("measured", "tables"),
    ("lightcurves", "comparison"),
    ("comparison_figure", "figure"),
    ("agreement", "agreement"),
    ("filter_names", "filter_names"),
]


@pytest.mark.parametrize(("old", "new"), MOVED)
def test_an_old_path_serves_the_moved_object_and_warns(old, new):
    with pytest.warns(RenamedWarning, match=rf"photometry\.{old} is renamed .*lightcurves\.{new}"):
        got = getattr(P, old)
    assert got is getattr(L, new)


def test_from_import_of_an_old_name_works_and_warns():
    with pytest.warns(RenamedWarning, match="sbrdf_xr.lightcurves.read_light_curve"):
        from sbrdf_xr.photometry import read_light_curve
    assert read_light_curve is L.read_light_curve


def test_every_public_name_of_the_old_place_is_served():
    """Every public name lightcurves took from photometry is in the table of old names."""
    served = {old for old, _ in MOVED}
    assert served == set(P._MOVED_TO_LIGHTCURVES)
    assert not served & set(P.__all__)  # the old names are no longer published there


def test_an_unknown_name_is_still_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        P.no_such_name
