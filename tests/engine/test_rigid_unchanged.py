"""A rigid closed scene runs exactly as before bodies could be open or have parts.

The digests are those of the cubes computed by the code of commit 244925b (before open
surfaces, two-sided facets and articulated parts), on the project's machine: every output
variable's bytes must be the same (bit-identical cubes, not merely close).
"""

from __future__ import annotations

import hashlib

import numpy as np
import pytest

from sbrdf_xr import geometry, simulate
from sbrdf_xr.engine import builtin_scene

GOLDEN = {
    "canx1-rotation": {
        "area": "49dba4c4cee84b4f",
        "brdf": "62cb97d268bcd7b2",
        "signal": "273ea5fbd2acb7a9",
        "signal_material": "6aaa8cacb5931678",
        "spacecraft_sbrdf": "b2bb8bb76a6072b9",
    },
    "canx1-shadowing-exact": {
        "area": "546b13641f222bfd",
        "brdf": "0e21bdc5cc99c499",
        "signal": "e41da8ff284d6d2d",
        "signal_material": "d77e77d06d5f49a6",
        "spacecraft_sbrdf": "e64d7a39d8e26f2b",
    },
    "canx1-shadowing-sampled": {
        "area": "9523c7102ce927b8",
        "brdf": "cbfb6d7f65258cd3",
        "signal": "4a8c53cfe72f3826",
        "signal_material": "734ebdc213e2e694",
        "spacecraft_sbrdf": "bb40bf0c7c64cd15",
    },
    "canx1-bands": {"area": "49dba4c4cee84b4f", "band_signal": "adc986b4143c2ed3"},
}


def digest(cube):
    return {
        k: hashlib.sha256(np.ascontiguousarray(cube[k].values).tobytes()).hexdigest()[:16]
        for k in sorted(cube.data_vars)
    }


def scene(name):
    rot = builtin_scene("canx1-rotation")
    att = geometry.uniform_attitudes(24, seed=5)
    return {
        "canx1-rotation": lambda: rot,
        "canx1-shadowing-exact": lambda: rot.with_options(
            attitudes=att,
            attitude_angle=None,
            phase_angles=[10.0, 75.0],
            effects=("sunlight", "shadowing"),
        ),
        "canx1-shadowing-sampled": lambda: rot.with_options(
            attitudes=att,
            attitude_angle=None,
            phase_angles=[40.0],
            effects=("sunlight", "shadowing"),
            shadow_method="sampled",
            shadow_density=3,
        ),
        "canx1-bands": lambda: rot.with_options(outputs=("band_signal", "area"), bands=("V", "R")),
    }[name]()


@pytest.mark.parametrize("name", sorted(GOLDEN))
def test_rigid_closed_cubes_are_bit_identical_to_before(name):
    sc = scene(name)
    assert sc.plan().articulation is None
    assert digest(simulate(sc)) == GOLDEN[name]
