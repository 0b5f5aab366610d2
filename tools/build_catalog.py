"""Regenerate the synthetic files of ``catalogs/materials`` (deterministic).

Run ``python tools/build_catalog.py`` from a source checkout.  Every file written
here is synthetic; its index entry in ``catalogs/index.toml`` says how it was made.
``python tools/build_catalog.py reflectances`` writes only the model reflectances that
ship beside the fits of the built tables (:mod:`sbrdf_xr.materials.shipped`); run it
after a change to the code that computes them (``tests/materials/test_shipped.py``
says when).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from sbrdf_xr import catalog, testing
from sbrdf_xr.brdf import get_model, optics
from sbrdf_xr.materials import goniometer, models, optical, shipped
from sbrdf_xr.materials import tables as material

ROOT = Path(__file__).resolve().parent.parent / "catalogs"

#: 450-1100 nm in 5 nm steps: the range of paper 000 Figs. 14 and 16 (131 samples).
WAVELENGTH_PAPER = np.arange(450.0, 1100.1, 5.0)
#: 400-1100 nm in 5 nm steps: the CanX-1 material set.
WAVELENGTH_CANX1 = np.arange(400.0, 1100.1, 5.0)
#: Relative noise of the virtual measurements of the CanX-1 materials.
CANX1_NOISE = 0.01
#: The Robertson-Sandford model (its parameters' metadata label Table 4).
RS = get_model("robertson_sandford")


def canx1_models() -> dict[str, xr.Dataset]:
    """Generating models of the CanX-1 material set (synthetic stand-ins).

    * aluminium 6061-T6: directional-diffuse metal; GGX roughness 0.15 over the
      exact Fresnel reflectance of aluminium (Lorentz-Drude optical constants of
      Rakic et al. 1998, with the interband absorption near 800 nm), plus a diffuse
      term 0.02 R(lambda) (R the normal-incidence reflectance) for the milled
      surface's scatter, which carries the same 800 nm feature;
    * Emcore-like triple-junction cell: GaAs substrate under a two-layer
      anti-reflection coating (Al2O3 135 nm on TiO2 95 nm), GGX roughness 0.03
      (highly specular), diffuse 0.005: thin-film interference features in
      600-800 nm that move to shorter wavelengths as the angle grows;
    * Aeroglaze A276-like white paint: Robertson-Sandford with rho_D 0.80 (0.55
      at 400 nm rising to the plateau by 450 nm, the titania edge), epsilon 0.12,
      b 0.1, e 0.35 (near-Lambertian with a faint sheen).
    """
    wl = WAVELENGTH_CANX1
    al = optics.aluminium_index(wl)
    r_al = optics.normal_incidence_reflectance(al)
    gaas = optics.gaas_index(wl)
    rho_paint = 0.80 - 0.25 * np.exp(-(wl - 400.0) / 20.0)
    return {
        "aluminium-6061-t6": models.model_material(
            "microfacet",
            wl,
            material="aluminium-6061-t6",
            provenance="synthetic: GGX roughness 0.15, Fresnel of aluminium from the Lorentz-Drude "
            "model of Rakic et al., Appl. Opt. 37, 5271 (1998), diffuse 0.02 R(lambda)",
            roughness=0.15,
            n=al.real,
            k=al.imag,
            rho_d=0.02 * r_al,
        ),
        "tjpv-cell": models.model_material(
            "microfacet",
            wl,
            material="tjpv-cell",
            provenance="synthetic: GaAs (sbrdf_xr.brdf.optics.gaas_index) under Al2O3 135 nm / "
            "TiO2 95 nm anti-reflection coating, GGX roughness 0.03, diffuse 0.005",
            layers=[(optics.sapphire_index(wl), 135.0), (optics.titania_index(wl), 95.0)],
            roughness=0.03,
            n=gaas.real,
            k=gaas.imag,
            rho_d=0.005,
        ),
        "white-paint-a276": models.model_material(
            "robertson_sandford",
            wl,
            material="white-paint-a276",
            provenance="synthetic: Robertson-Sandford (paper 001) rho_D 0.80 with a 400-450 nm "
            "edge, epsilon 0.12, b 0.1, e 0.35",
            rho_D=rho_paint,
            epsilon=0.12,
            b=0.1,
            e=0.35,
        ),
    }


#: Incidence angles of the virtual measurements (paper 000 §4.2: aluminium from
#: 30 deg, the cell and the paint from 10 deg).
CANX1_THETA_I = {
    "aluminium-6061-t6": (30.0, 40.0, 50.0, 60.0, 70.0),
    "tjpv-cell": (10.0, 25.0, 40.0, 55.0, 70.0),
    "white-paint-a276": (10.0, 25.0, 40.0, 55.0, 70.0),
}


def canx1_materials() -> None:
    """Write the CanX-1 models and their virtual measurement sets."""
    for k, (name, spec) in enumerate(canx1_models().items()):
        models.to_netcdf(spec, ROOT / "materials" / f"{name}-model.nc", overwrite=True)
        meas = models.measure(spec, CANX1_THETA_I[name], noise=CANX1_NOISE, seed=10 + k)
        material.to_netcdf(meas, ROOT / "materials" / f"{name}-measurements.nc", overwrite=True)
        fit = models.fit_robertson_sandford(meas)
        models.to_netcdf(fit, ROOT / "materials" / f"{name}-fit.nc", overwrite=True)


def fit_microfacet(
    meas: xr.Dataset,
    *,
    roughness: float,
    n: float,
    k: float,
    rho_d: float,
    spectral_diffuse: bool,
    coating: tuple[tuple[str, float], ...] = (),
) -> xr.Dataset:
    """GGX microfacet model (:mod:`sbrdf_xr.brdf.microfacet`) fitted to a measurement set.

    Least squares of the log residuals ``ln f_model - ln f_meas`` over the measured
    (non-reference, positive) samples, as the Robertson-Sandford fit does, so every
    sample counts by its relative error: a shared roughness, a substrate index
    ``n(lambda), k(lambda)`` and a diffuse albedo ``rho_d`` (per wavelength, or one
    for all when ``spectral_diffuse`` is false), all fitted in logarithm
    (:func:`scipy.optimize.least_squares`, trust region with bounds; the Jacobian's
    sparsity, every wavelength on its own but for the shared parameters, makes it a
    few evaluations per step).  The start values are the keyword arguments.

    ``coating`` names the thin-film layers over the substrate, ambient side first, as
    ``(material, start thickness [nm])`` with ``material`` a dispersion of
    :mod:`sbrdf_xr.brdf.optics` (``"sapphire"`` for ``optics.sapphire_index``); their
    thicknesses are fitted too, shared by all wavelengths.
    """
    import scipy.optimize as so
    import scipy.sparse as sp

    from sbrdf_xr.brdf import microfacet

    ok = ~meas["reference"].values
    ti, dt, ph = (
        np.asarray(meas[c].values, dtype=np.float64)[ok] for c in ("theta_i", "delta_theta", "phi")
    )
    y = np.asarray(meas["measured_sbrdf"].transpose("sample", "wavelength").values)[ok]
    wl = np.asarray(meas.wavelength.values, dtype=np.float64)
    m = wl.size
    good = y > 0
    ly = np.log(np.where(good, y, 1.0))
    n_layers = len(coating)
    indices = [getattr(optics, f"{name}_index")(wl) for name, _ in coating]
    n_shared = (1 if spectral_diffuse else 2) + n_layers
    n_spectral = 3 if spectral_diffuse else 2

    def unpack(x: np.ndarray) -> dict[str, Any]:
        e = np.exp(x)
        spec = e[n_shared:].reshape(n_spectral, m)
        p: dict[str, Any] = {
            "roughness": np.full(m, e[0]),
            "n": spec[0],
            "k": spec[1],
            "rho_d": spec[2] if spectral_diffuse else np.full(m, e[1]),
        }
        if n_layers:
            thick = e[n_shared - n_layers : n_shared]
            p["layers"] = [(idx, float(t)) for idx, t in zip(indices, thick, strict=True)]
        return p

    def residuals(x: np.ndarray) -> np.ndarray:
        f = microfacet.brdf_angles(ti, dt, ph, wl, **unpack(x))
        return np.where(good, np.log(np.maximum(f, 1e-300)) - ly, 0.0).ravel()

    rows = np.arange(ti.size * m)
    col = np.tile(np.arange(m), ti.size)
    pattern = sp.lil_matrix((rows.size, n_shared + n_spectral * m), dtype=np.int8)
    pattern[:, :n_shared] = 1
    for j in range(n_spectral):
        pattern[rows, n_shared + j * m + col] = 1
    start = [roughness] + ([] if spectral_diffuse else [rho_d]) + [t for _, t in coating]
    start_spec = [n, k] + ([rho_d] if spectral_diffuse else [])
    lo_s, hi_s = (
        [1e-3] + ([] if spectral_diffuse else [1e-6]) + [1.0] * n_layers,
        [1.0] + ([] if spectral_diffuse else [0.9]) + [1000.0] * n_layers,
    )
    lo_p, hi_p = (
        [0.05, 1e-4] + ([1e-6] if spectral_diffuse else []),
        [10.0, 20.0] + ([0.9] if spectral_diffuse else []),
    )
    x0 = np.log(np.concatenate([start, np.repeat(start_spec, m)]))
    lo = np.log(np.concatenate([lo_s, np.repeat(lo_p, m)]))
    hi = np.log(np.concatenate([hi_s, np.repeat(hi_p, m)]))
    sol = so.least_squares(
        residuals, x0, jac_sparsity=pattern.tocsr(), bounds=(lo, hi), x_scale="jac", max_nfev=200
    )
    p = unpack(sol.x)
    chi2 = float(2.0 * sol.cost / max(int(good.sum()) - sol.x.size, 1))
    spec = models.model_material(
        "microfacet",
        wl,
        material=meas.attrs["material"],
        provenance=(
            "GGX microfacet fit to the measurements of "
            f"{meas.attrs['material']} (log residuals, scipy.optimize.least_squares): roughness "
            f"{p['roughness'][0]:.4g}, substrate n, k per wavelength, diffuse "
            + ("per wavelength" if spectral_diffuse else f"{p['rho_d'][0]:.3g}")
            + "".join(
                f", {name} {t:.4g} nm"
                for (name, _), (_, t) in zip(coating, p.get("layers", ()), strict=True)
            )
        ),
        **p,
    )
    spec.attrs["chi2_reduced"] = chi2
    return spec


#: Start values of the microfacet fits (a metal; a dielectric under a coating, whose
#: diffuse term is one number, since a per-wavelength one takes up the thin-film
#: structure that a bare substrate's Fresnel reflectance cannot follow).
CANX1_MICROFACET_FITS = {
    "aluminium-6061-t6": {
        "roughness": 0.1,
        "n": 1.0,
        "k": 7.0,
        "rho_d": 0.01,
        "spectral_diffuse": True,
    },
    "tjpv-cell": {"roughness": 0.05, "n": 3.5, "k": 0.1, "rho_d": 0.003, "spectral_diffuse": False},
}


def canx1_microfacet_fits() -> None:
    """Write the microfacet fits of the CanX-1 metal and cell (their tables' models)."""
    for name, start in CANX1_MICROFACET_FITS.items():
        meas = material.open_measurements(ROOT / "materials" / f"{name}-measurements.nc")
        fit = fit_microfacet(meas, **start)
        models.to_netcdf(fit, ROOT / "materials" / f"{name}-microfacet-fit.nc", overwrite=True)


#: Layer thicknesses [nm] of the grid of :func:`coating_start`.
COATING_GRID = np.arange(10.0, 251.0, 10.0)


def coating_start(
    meas: xr.Dataset,
    *,
    substrate: str,
    coating: tuple[str, ...],
    roughness: float,
    rho_d: float,
    grid: np.ndarray = COATING_GRID,
) -> tuple[float, ...]:
    """Start thicknesses [nm] of a coating fit: the best point of a grid.

    A thin-film stack's reflectance is periodic in each layer's optical thickness, so
    the log-residual cost of :func:`fit_microfacet` has a minimum in every period;
    a local fit finds the one next to its start.  The grid (every ``grid`` thickness
    for every layer) evaluates that cost with the substrate's dispersion
    (``optics.<substrate>_index``) and the given roughness and diffuse albedo; the
    fit then starts from its best point.
    """
    from itertools import product

    from sbrdf_xr.brdf import microfacet

    ok = ~meas["reference"].values
    ti, dt, ph = (
        np.asarray(meas[c].values, dtype=np.float64)[ok] for c in ("theta_i", "delta_theta", "phi")
    )
    y = np.asarray(meas["measured_sbrdf"].transpose("sample", "wavelength").values)[ok]
    wl = np.asarray(meas.wavelength.values, dtype=np.float64)
    good = y > 0
    ly = np.log(np.where(good, y, 1.0))
    sub = getattr(optics, f"{substrate}_index")(wl)
    indices = [getattr(optics, f"{name}_index")(wl) for name in coating]
    common = {
        "roughness": np.full(wl.size, roughness),
        "n": sub.real,
        "k": sub.imag,
        "rho_d": np.full(wl.size, rho_d),
    }

    def cost(thick: tuple[float, ...]) -> float:
        layers = [(idx, t) for idx, t in zip(indices, thick, strict=True)]
        f = microfacet.brdf_angles(ti, dt, ph, wl, layers=layers, **common)
        return float(np.mean(np.where(good, np.log(np.maximum(f, 1e-300)) - ly, 0.0) ** 2))

    return min(product(*([[float(t) for t in grid]] * len(coating))), key=cost)


#: The cell's coated fit: GGX over a GaAs substrate (its n, k fitted per wavelength)
#: under the anti-reflection coating's two layers, sapphire over titania, whose
#: thicknesses are fitted too (started from :func:`coating_start`, with the roughness
#: and diffuse albedo of the bare fit).
CANX1_COATED_FITS = {
    "tjpv-cell": {"substrate": "gaas", "coating": ("sapphire", "titania")},
}


def canx1_coated_fits() -> None:
    """Write the coated microfacet fit of the CanX-1 cell (its table's model)."""
    for name, how in CANX1_COATED_FITS.items():
        meas = material.open_measurements(ROOT / "materials" / f"{name}-measurements.nc")
        bare = models.open_model(ROOT / "materials" / f"{name}-microfacet-fit.nc")
        roughness, rho_d = (float(bare[v].values.reshape(-1)[0]) for v in ("roughness", "rho_d"))
        start = coating_start(
            meas,
            substrate=how["substrate"],
            coating=how["coating"],
            roughness=roughness,
            rho_d=rho_d,
        )
        sub = getattr(optics, f"{how['substrate']}_index")(np.array([700.0]))[0]
        fit = fit_microfacet(
            meas,
            roughness=roughness,
            n=float(sub.real),
            k=float(sub.imag),
            rho_d=rho_d,
            spectral_diffuse=False,
            coating=tuple(zip(how["coating"], start, strict=True)),
        )
        fit.attrs["coating_start"] = np.array(start)
        models.to_netcdf(fit, ROOT / "materials" / f"{name}-coated-fit.nc", overwrite=True)


def table4_paints() -> None:
    """Paper 001 Table 4: Robertson-Sandford parameters at 4 um."""
    ds = xr.Dataset(
        {
            "rho_D": ("sample", [0.07, 0.05], RS.parameter("rho_D").attrs),
            "epsilon": ("sample", [0.85, 0.88], RS.parameter("epsilon").attrs),
            "b": ("sample", [0.12, 0.08], RS.parameter("b").attrs),
            "e": ("sample", [0.12, 0.012], RS.parameter("e").attrs),
        },
        coords={
            "sample": ("sample", ["AFGL-01", "AFGL-10"], {"long_name": "paint sample"}),
            "description": ("sample", ["camouflage", "white gloss"], {"long_name": "paint"}),
            "wavelength": (
                (),
                4000.0,
                {"units": "nm", "long_name": "wavelength of the parameters"},
            ),
        },
        attrs={
            "title": "Robertson-Sandford parameters, paper 001 Table 4 (4 um)",
            "source": "measured",
            "Conventions": "CF-1.10",
        },
    )
    material.write_netcdf_atomic(ds, ROOT / "materials" / "table4-paints.nc", overwrite=True)


def lambertian_grey() -> None:
    """A 50 % grey Lambertian table spanning the whole visible hemisphere."""
    wl = np.arange(400.0, 1100.1, 10.0)
    ti = np.arange(0.0, 91.0, 1.0)
    dt = np.array([-180.0, -90.0, 0.0, 90.0])
    ph = np.array([0.0, 45.0, 90.0])
    vals = np.full((ti.size, dt.size, ph.size, wl.size), 0.5 / np.pi, dtype=np.float32)
    da = material.new_material(
        vals,
        ti,
        dt,
        ph,
        wl,
        material="lambertian-grey-50",
        source="synthetic",
        provenance="f_r = 0.5/pi sr-1 everywhere (ideal Lambertian, albedo 0.5); "
        "generated by tools/build_catalog.py",
        model="lambert",
        albedo=0.5,
    )
    material.to_netcdf(da, ROOT / "materials" / "lambertian-grey-50.nc", overwrite=True)


def example_lobe_measurements() -> None:
    """The analytic lobe of sbrdf_xr.testing sampled on the paper-000 scheme."""
    ds = goniometer.measure(
        testing.lobe_function(WAVELENGTH_PAPER, width=3.0),
        WAVELENGTH_PAPER,
        (10.0, 25.0, 40.0, 55.0, 70.0),
        noise_floor=0.05,
        noise=0.01,
        seed=1,
        material="example-lobe",
        provenance="sbrdf_xr.testing.lobe_function(width=3) sampled by the virtual "
        "goniospectrometer with 1 % noise (seed 1); generated by tools/build_catalog.py",
    )
    material.to_netcdf(ds, ROOT / "materials" / "example-lobe-measurements.nc", overwrite=True)


def brushed_aluminium_model() -> xr.Dataset:
    """Brushed aluminium: anisotropic GGX (alpha 0.05 along the brushing, 0.30 across it)
    over the exact Fresnel reflectance of aluminium (Rakic et al. 1998), diffuse 0.01 R."""
    wl = WAVELENGTH_CANX1[::4]
    al = optics.aluminium_index(wl)
    r_al = optics.normal_incidence_reflectance(al)
    return models.model_material(
        "anisotropic_microfacet",
        wl,
        material="brushed-aluminium",
        provenance="synthetic: anisotropic GGX, alpha_x 0.05 along the brushing (facet tangent), "
        "alpha_y 0.30 across it, Fresnel of aluminium from the Lorentz-Drude model of "
        "Rakic et al., Appl. Opt. 37, 5271 (1998), diffuse 0.01 R(lambda)",
        alpha_x=0.05,
        alpha_y=0.30,
        n=al.real,
        k=al.imag,
        rho_d=0.01 * r_al,
    )


def brushed_aluminium() -> None:
    """Write the brushed-aluminium model (an anisotropic example)."""
    models.to_netcdf(
        brushed_aluminium_model(), ROOT / "materials" / "brushed-aluminium-model.nc", overwrite=True
    )


def optical_materials() -> None:
    """Write the materials from measured optical constants (``optical-<name>.nc``), each at
    every tabulated wavelength of its sources (:func:`sbrdf_xr.materials.optical_material`
    with its defaults)."""
    for name in optical.OPTICAL_MATERIALS:
        spec = optical.optical_material(name)
        models.to_netcdf(spec, ROOT / "materials" / f"optical-{name}.nc", overwrite=True)


def shipped_reflectances() -> list[tuple[Path, np.ndarray, np.ndarray]]:
    """The model file, rows and wavelengths of every built catalog table whose build
    renormalises to its fit's reflectance (the default with ``below_noise="model"``)."""
    out = {}
    for e in catalog.entries():
        build = e.extra.get("build", {})
        if e.kind != "material" or "fit" not in build or build.get("below_noise") != "model":
            continue
        if build.get("renormalise", "auto") not in ("auto", "model"):
            continue
        ti = np.asarray(build.get("theta_i", np.arange(0.0, 91.0)), dtype=np.float64)
        meas = catalog.load(e.extra["build_from"])
        wl = np.asarray(meas.wavelength.values, dtype=np.float64)
        out[catalog.entry(build["fit"]).file] = (ti, wl)
    return [(f, ti, wl) for f, (ti, wl) in out.items()]


def model_reflectances() -> None:
    """Write the model reflectances shipped beside the fits (``<fit>-reflectance.nc``)."""
    for fit, ti, wl in shipped_reflectances():
        print("wrote", shipped.write_reflectance(fit, ti, wl))


def main() -> None:
    if sys.argv[1:] == ["reflectances"]:
        model_reflectances()
        return
    (ROOT / "materials").mkdir(parents=True, exist_ok=True)
    brushed_aluminium()
    lambertian_grey()
    example_lobe_measurements()
    canx1_materials()
    canx1_microfacet_fits()
    canx1_coated_fits()
    table4_paints()
    optical_materials()
    model_reflectances()


if __name__ == "__main__":
    main()
