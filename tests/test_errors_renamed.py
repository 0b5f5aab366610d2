"""The one mechanism for renamed names: old keywords and attributes still work, warn, and
name the new spelling; passing an old and a new name together is an error."""

import warnings

import pytest

from sbrdf_xr.errors import (
    RenamedWarning,
    SbrdfWarning,
    ValidationError,
    renamed_attributes,
    renamed_keywords,
)


@renamed_keywords(period_s="period", phase_deg="phase")
def _spin(period=1.0, phase=0.0):
    return period, phase


def test_old_keyword_is_passed_on_with_a_warning_naming_the_new_one():
    with pytest.warns(RenamedWarning, match="'period_s' is renamed 'period'"):
        assert _spin(period_s=3.0) == (3.0, 0.0)


def test_new_keyword_does_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert _spin(period=2.0, phase=5.0) == (2.0, 5.0)


def test_old_and_new_keyword_together_is_refused():
    with pytest.raises(ValidationError, match="both 'period_s' and 'period'"):
        _spin(period_s=1.0, period=2.0)


def test_renamed_warning_is_a_package_and_a_future_warning():
    assert issubclass(RenamedWarning, SbrdfWarning)
    assert issubclass(RenamedWarning, FutureWarning)


def test_old_attribute_returns_the_same_object():
    marker = object()
    getter = renamed_attributes("demo", {"NEW": marker}, {"OLD": "NEW"})
    with pytest.warns(RenamedWarning, match="demo.OLD is renamed demo.NEW"):
        assert getter("OLD") is marker
    with pytest.raises(AttributeError, match="no attribute 'MISSING'"):
        getter("MISSING")


def test_old_site_fields_still_work_with_a_warning():
    from sbrdf_xr.observing import Site

    with pytest.warns(RenamedWarning, match=r"Site.__init__\(\): the keyword 'height_m'"):
        site = Site(45.0, -71.0, height_m=1000.0)
    assert (site.latitude, site.longitude, site.height) == (45.0, -71.0, 1000.0)
    with pytest.warns(RenamedWarning, match="Site.height_m is renamed Site.height"):
        assert site.height_m == 1000.0
    with pytest.raises(AttributeError):
        site.latitude_deg = 3.0  # type: ignore[misc]  # read-only, as the field is
