"""The microfacet fit: parameters recovered from noisy samples, bad input, and the fit as
the fill of an in-plane table (``sbrdf-xr material build --model microfacet``)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sbrdf_xr.brdf import microfacet
from sbrdf_xr.brdf.microfacet_fit import fit_microfacet
from sbrdf_xr.cli import main
from sbrdf_xr.errors import ValidationError
from sbrdf_xr.materials import open_material

WL = np.array([450.0, 650.0])


def _grid(theta_i=(10.0, 30.0, 50.0, 70.0), phi=(0.0,)):
    t, s, p = np.meshgrid(np.asarray(theta_i), np.arange(-85.0, 86.0, 1.0), phi, indexing="ij")
    t, s, p = t.ravel(), s.ravel(), p.ravel()
    return t, s - t, p


@settings(max_examples=8, deadline=None)
@given(
    alpha=st.floats(0.01, 0.4),
    n=st.floats(1.3, 8.0),
    rho=st.floats(0.01, 0.5),
    seed=st.integers(0, 2**16),
)
def test_the_fit_recovers_the_parameters_of_noisy_samples(alpha, n, rho, seed):
    """2 % log-normal noise on 1372 in-plane samples: the log-residual fit recovers the
    roughness within 2 % and n and rho_d within 5 % (the noise averages over hundreds of
    samples per parameter; n is the least constrained, through the Fresnel amplitude)."""
    t, d, p = _grid()
    truth = dict(roughness=alpha, n=[n, 0.8 * n + 0.3], k=0.0, rho_d=[rho, 0.5 * rho])
    f = microfacet.brdf_angles(t, d, p, WL, **truth)
    noisy = f * np.exp(np.random.default_rng(seed).normal(0.0, 0.02, f.shape))
    fit = fit_microfacet(t, d, p, WL, noisy)
    assert fit["roughness"] == pytest.approx(alpha, rel=0.02)
    np.testing.assert_allclose(fit["n"], truth["n"], rtol=0.05)
    np.testing.assert_allclose(fit["rho_d"], truth["rho_d"], rtol=0.05)
    assert fit["rms_log"] == pytest.approx(0.02, rel=0.2)


def test_too_few_samples_and_unequal_angles_are_named_errors():
    with pytest.raises(ValidationError, match="usable samples"):
        fit_microfacet([30.0, 30.0], [0.0, 5.0], [0.0, 0.0], WL, np.ones((2, 2)))
    with pytest.raises(ValidationError, match="angle arrays of sizes 2, 1, 2"):
        fit_microfacet([30.0, 30.0], [0.0], [0.0, 0.0], WL, np.ones((2, 2)))


@pytest.mark.slow
def test_material_build_with_the_microfacet_fit(tmp_path, capsys):
    """An in-plane scan of a microfacet material built with ``--model microfacet``: the
    leave-out check (its own refit) predicts held-out samples within the 2 % the issue
    sets for synthetic sets."""
    t, d, _ = _grid((20.0, 50.0))
    ok = np.abs(t + d) < 89.0
    t, d = t[ok], d[ok]
    f = microfacet.brdf_angles(t, d, 0.0, [550.0], roughness=0.1, n=2.5, k=0.0, rho_d=0.05)
    rows = ["theta_i,theta_s,brdf"] + [
        f"{a},{a + b},{float(v)!r}" for a, b, v in zip(t, d, f[:, 0], strict=True)
    ]
    src = tmp_path / "scan.csv"
    src.write_text("\n".join(rows) + "\n")
    out = tmp_path / "table.nc"
    assert main(["material", "build", str(src), "-o", str(out), "--format", "scan",
                 "--wavelength", "550", "--model", "microfacet"]) == 0  # fmt: skip
    table = open_material(out)
    assert table.attrs["extrapolation_model"] == "microfacet"
    assert table.attrs["holdout_check_median"] < 0.02
    assert "self-check over" in capsys.readouterr().out
