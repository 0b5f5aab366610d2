"""Energy and accuracy of the catalog's tables against their generating models.

Run ``python tools/energy_table.py [name ...]`` from a source checkout (default: every
material of the catalog).  For every table it prints

* the relative error of its directional-hemispherical reflectance against the
  generating model's, worst over wavelengths (signed), at theta_i = 0, 10, ..., 80, 85
  deg: the table's by the package's own quadrature
  (:func:`sbrdf_xr.materials.energy.hemispherical_reflectance`), the model's by direct
  quadrature of the model function (:func:`sbrdf_xr.testing.reference_reflectance`,
  independent of any table grid; ``--fast`` uses the model's own half-vector
  quadrature instead);
* the largest reflectance of the table over all its rows and wavelengths;
* the median and 99th percentile of the node-wise relative error ``|T - M| / M`` over
  the lit and visible nodes (``theta_i < 90``, ``|theta_i + delta_theta| < 90``,
  ``phi < 90``) and all wavelengths, and the number of zeroed entries where the model
  exceeds 1 % of the table's maximum over its row (``theta_i``, wavelength).

The generating model of ``<base>`` and ``<base>-paper`` is the entry ``<base>-model``;
``example-lobe`` is :func:`sbrdf_xr.testing.lobe_function` with ``width = 3`` (its
provenance) and ``lambertian-grey-50`` is ``0.5 / pi``.
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

from sbrdf_xr import catalog, testing
from sbrdf_xr.errors import NonPhysicalWarning
from sbrdf_xr.materials import energy, models

#: Incidence angles of the report [degree].
THETA_I = np.array([0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 85.0])


def generating_function(name: str, wl: np.ndarray):
    """``(func, dhr)`` of the model a table was made from: the sBRDF function and, when the
    model has one, its own directional-hemispherical reflectance ``dhr(theta_i)``."""
    if name == "lambertian-grey-50":
        return (lambda ti, dt, ph: np.full((np.size(ti), wl.size), 0.5 / np.pi)), (
            lambda ti: np.full((np.size(ti), wl.size), 0.5)
        )
    if name == "example-lobe":
        return testing.lobe_function(wl, width=3.0), None
    spec = catalog.load(name.removesuffix("-paper") + "-model")
    if not np.array_equal(spec.wavelength.values, wl):
        spec = spec.interp(wavelength=wl)
    mod, _, kw = models.model_parameters(spec)
    return models.spectrum_function(spec), (
        lambda ti: mod.directional_hemispherical_reflectance(np.asarray(ti), wl, **kw)
    )


def node_errors(table, func) -> tuple[float, float, int]:
    """(median, p99 of ``|T - M| / M``, zeroed entries where ``M > 1 %`` of the row max)."""
    ti, dt, ph = (np.asarray(table[d].values, dtype=np.float64) for d in table.dims[:3])
    rel, zeroed = [], 0
    for k, t in enumerate(ti):
        if t >= 90.0:
            continue
        d3, p3 = np.meshgrid(dt, ph, indexing="ij")
        ok = (np.abs(t + d3) < 90.0) & (p3 < 90.0)
        m = np.asarray(func(np.full(ok.sum(), t), d3[ok], p3[ok]))
        v = np.asarray(table.values[k], dtype=np.float64)[ok]
        good = m > 0
        rel.append((np.abs(v - m)[good] / m[good]).ravel())
        row_max = np.asarray(table.values[k], dtype=np.float64).max(axis=(0, 1))
        zeroed += int(np.sum((v == 0) & (m > 0.01 * row_max)))
    r = np.concatenate(rel)
    return float(np.median(r)), float(np.percentile(r, 99)), zeroed


def report(name: str, fast: bool = False) -> dict:
    table = catalog.load(name)
    wl = np.asarray(table.wavelength.values, dtype=np.float64)
    func, dhr = generating_function(name, wl)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NonPhysicalWarning)
        rho_t = energy.hemispherical_reflectance(table, THETA_I, warn=False).values
        rho_all = energy.hemispherical_reflectance(table, warn=False).values
    rho_m = (
        dhr(THETA_I) if (fast and dhr is not None) else testing.reference_reflectance(func, THETA_I)
    )
    rel = rho_t / rho_m - 1.0
    worst = rel[np.arange(rel.shape[0]), np.argmax(np.abs(rel), axis=1)]
    med, p99, zeroed = node_errors(table, func)
    return {
        "name": name,
        "worst": worst,
        "rho_max": float(rho_all.max()),
        "rho_max_at": float(
            table.theta_i.values[np.unravel_index(rho_all.argmax(), rho_all.shape)[0]]
        ),
        "median": med,
        "p99": p99,
        "zeroed": zeroed,
        "size_mb": table.nbytes / 1e6,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("names", nargs="*")
    ap.add_argument("--fast", action="store_true", help="the model's own quadrature")
    args = ap.parse_args()
    names = args.names or [e.name for e in catalog.entries() if e.kind == "material"]
    head = " ".join(f"{t:>6.0f}" for t in THETA_I)
    print(f"{'table':<24} {head}  {'rho_max':>8} {'median':>7} {'p99':>7} {'zeroed':>7} {'MB':>6}")
    for n in names:
        r = report(n, args.fast)
        row = " ".join(f"{x:>+6.3f}" for x in r["worst"])
        print(
            f"{n:<24} {row}  {r['rho_max']:>8.3f} {r['median']:>7.4f} {r['p99']:>7.3f} "
            f"{r['zeroed']:>7d} {r['size_mb']:>6.0f}",
            flush=True,
        )


if __name__ == "__main__":
    main()
