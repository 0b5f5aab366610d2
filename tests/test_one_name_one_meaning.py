"""One name, one meaning: no two packages export different objects under one name.

Every top-level package and public module of ``sbrdf_xr`` (``sbrdf_xr.<name>``) is
imported and its ``__all__`` read; a non-module name that two of them export must be
the same object (re-exporting is fine).  A script importing ``airmass`` or an Earth
radius from either package then gets the same physics.  The names renamed to end the
old collisions still answer under their old spelling for one release, with a
:class:`~sbrdf_xr.errors.RenamedWarning`.
"""

from __future__ import annotations

import importlib
import pkgutil
import types

import numpy as np
import pytest

import sbrdf_xr
from sbrdf_xr.errors import RenamedWarning


def _top_level_modules() -> dict[str, types.ModuleType]:
    """``sbrdf_xr`` and every public ``sbrdf_xr.<name>`` (package or module)."""
    out = {"sbrdf_xr": sbrdf_xr}
    for info in pkgutil.iter_modules(sbrdf_xr.__path__, "sbrdf_xr."):
        if not info.name.rpartition(".")[2].startswith("_"):
            out[info.name] = importlib.import_module(info.name)
    return out


def collisions(modules: dict[str, types.ModuleType]) -> dict[str, list[str]]:
    """Exported name -> the modules exporting it as different objects (two or more)."""
    owners: dict[str, list[tuple[str, object]]] = {}
    for mod_name, mod in sorted(modules.items()):
        for name in getattr(mod, "__all__", ()):
            obj = getattr(mod, name)
            if isinstance(obj, types.ModuleType):
                continue
            seen = owners.setdefault(name, [])
            if not any(obj is other for _, other in seen):
                seen.append((mod_name, obj))
    return {name: [m for m, _ in seen] for name, seen in owners.items() if len(seen) > 1}


def test_the_collision_finder_sees_a_collision():
    a, b = types.ModuleType("a"), types.ModuleType("b")
    a.__all__, b.__all__ = ["X", "same"], ["X", "same"]  # type: ignore[attr-defined]
    a.X, b.X = 1.0, 2.0  # type: ignore[attr-defined]
    a.same = b.same = print  # type: ignore[attr-defined]
    assert collisions({"a": a, "b": b}) == {"X": ["a", "b"]}


def test_no_name_is_exported_by_two_packages_as_different_objects():
    found = collisions(_top_level_modules())
    assert not found, "one name, two meanings: " + "; ".join(
        f"{name} in {', '.join(mods)}" for name, mods in sorted(found.items())
    )


def test_one_airmass_for_photometry_and_observing():
    from sbrdf_xr import observing, photometry

    # published by photometry, importable from observing as the same object
    assert observing.airmass is photometry.airmass and "airmass" in photometry.__all__
    assert observing.AIRMASS_MODELS is photometry.AIRMASS_MODELS


def test_earth_radii_are_named_by_meaning():
    from sbrdf_xr import observing, sources

    # WGS84 semi-major axis and IUGG mean radius R1, in km.
    assert observing.EARTH_EQUATORIAL_RADIUS_KM == 6378.137
    assert sources.EARTH_MEAN_RADIUS_KM == 6371.0


OLD_NAMES = [
    ("sbrdf_xr.observing", "EARTH_RADIUS_KM", "EARTH_EQUATORIAL_RADIUS_KM"),
    ("sbrdf_xr.observing.earth_shadow", "EARTH_RADIUS_KM", "EARTH_EQUATORIAL_RADIUS_KM"),
    ("sbrdf_xr.sources", "EARTH_RADIUS_KM", "EARTH_MEAN_RADIUS_KM"),
    ("sbrdf_xr.observing", "LAWS", "ATTITUDE_LAWS"),
    ("sbrdf_xr.body", "LAWS", "ARTICULATION_LAWS"),
    ("sbrdf_xr.catalog", "KINDS", "ENTRY_KINDS"),
    ("sbrdf_xr.bench", "KINDS", "WING_KINDS"),
    ("sbrdf_xr.photometry", "EXTRAPOLATIONS", "SPECTRUM_EXTRAPOLATIONS"),
    ("sbrdf_xr.geometry", "compose", "compose_quaternions"),
    ("sbrdf_xr.engine", "material_tables", "scene_material_tables"),
    ("sbrdf_xr.kernels", "reflected", "anisotropic_reflected"),
    ("sbrdf_xr.plot", "magnitudes", "magnitude_curves"),
    ("sbrdf_xr.plot", "spectra", "spectrum_curves"),
]


@pytest.mark.parametrize(("module", "old", "new"), OLD_NAMES)
def test_an_old_name_still_answers_with_a_warning(module, old, new):
    mod = importlib.import_module(module)
    assert old not in mod.__all__ and new in mod.__all__
    with pytest.warns(RenamedWarning, match=f"{module}.{old} is renamed {module}.{new}"):
        assert getattr(mod, old) is getattr(mod, new)


def test_airmass_is_nan_below_the_horizon_and_keeps_dataarrays():
    import xarray as xr
    from pvlib.atmosphere import get_relative_airmass

    from sbrdf_xr.observing import airmass

    el = xr.DataArray([90.0, 30.0, 0.0, -5.0, np.nan], dims="time")
    x = airmass(el)
    assert x.dims == ("time",) and x.attrs["units"] == "1"
    # pvlib is the reference: the same call above the horizon, bit for bit.
    np.testing.assert_array_equal(x.values[:3], get_relative_airmass(np.array([0.0, 60.0, 90.0])))
    assert np.isnan(x.values[3:]).all()
