"""Shared pytest configuration.

Hypothesis runs under the profiles of ``hypothesis_profiles`` (reproducible unless
``SBRDF_XR_HYPOTHESIS_PROFILE`` asks for ``dev`` or ``deep``), without deadlines,
because shared machines are noisy.
"""

from __future__ import annotations

import hypothesis_profiles  # noqa: F401  (registers and loads the profile)
import matplotlib
import pytest

matplotlib.use("Agg")

#: conftest files hold fixtures, not doctests: collecting them as doctest modules would
#: import this one under the name ``conftest`` after a subdirectory's (tests/bad_input)
#: took it, which pytest refuses as an import file mismatch.
collect_ignore = ["conftest.py"]
collect_ignore_glob = ["*/conftest.py"]


@pytest.fixture(autouse=True)
def _no_user_catalogs(monkeypatch):
    """Tests see the shipped catalog only, whatever the environment says."""
    monkeypatch.delenv("SBRDF_XR_CATALOG_PATH", raising=False)


@pytest.fixture
def user_files(tmp_path):
    """A user catalog directory and loose files: a 1 m box mesh (``box.stl``), a Lambertian
    table of albedo 0.3 (``grey30.nc``) and a Lambertian model of albedo 0.4 (``model40.nc``)
    in ``tmp_path/files``, and ``tmp_path/usercat`` whose ``index.toml`` names the table
    ``user-grey-30`` and the box (all facets ``user-grey-30``) ``user-box``."""
    import numpy as np
    import trimesh

    from sbrdf_xr.materials import files as material_io
    from sbrdf_xr.materials import models
    from sbrdf_xr.materials import schema as material_schema

    wl = [450.0, 550.0, 650.0]
    files = tmp_path / "files"
    cat = tmp_path / "usercat"
    for d in (files, cat / "meshes", cat / "tables"):
        d.mkdir(parents=True)
    box = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
    box.export(files / "box.stl")
    box.visual.face_colors = [128, 128, 128, 255]
    box.export(cat / "meshes" / "box.ply")
    grey = material_schema.lambertian(0.3, wavelength=wl, material="user-grey-30")
    material_io.to_netcdf(grey, files / "grey30.nc")
    material_io.to_netcdf(grey, cat / "tables" / "grey30.nc")
    spec = models.model_material(
        "lambert", np.array(wl), material="model-40", provenance="test: rho = 0.4", rho=0.4
    )
    models.to_netcdf(spec, files / "model40.nc")
    (cat / "meshes" / "box.toml").write_text(
        '[[material]]\nname = "user-grey-30"\nrgb = [128, 128, 128]\n', encoding="utf-8"
    )
    (cat / "index.toml").write_text(
        """
[[entry]]
name = "user-grey-30"
kind = "material"
path = "tables/grey30.nc"
source = "synthetic"
description = "Lambertian, albedo 0.3"
provenance = "test"

[[entry]]
name = "user-box"
kind = "spacecraft"
path = "meshes/box.ply"
source = "synthetic"
description = "1 m cube"
provenance = "test"
material_map = "meshes/box.toml"
""",
        encoding="utf-8",
    )
    return tmp_path
