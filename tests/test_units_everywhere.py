"""Every public argument with a unit takes an astropy Quantity.

The public callables of every package (``__all__`` of each package and of the public
modules it lists, classes through their constructor) are walked; an argument carries a
unit when its numpydoc description states one in brackets (``[nm]``, ``[degree]``,
``[s]``, ``[km]``, ``[au]``, ``[m]``, ``[K]``, ``[hPa]``, ``[degree s-1]``, ...) or its
name ends in a unit (``_km``, ``_deg``, ``_s``, ``_nm``, ``_au``, ``_m``).  Each such
argument has a row in :data:`CASES` (a call taking the argument's value) or in
:data:`EXEMPT` (with the reason); a new argument with a unit and neither fails
:func:`test_every_unit_argument_has_a_case`.  Every case checks that

* a Quantity in another unit of the same kind gives the result of the bare number in
  the documented unit (``0.5 * u.um`` for ``500`` nm, radians for degrees, minutes for
  seconds, metres for kilometres), and
* a Quantity of another kind (a mass) raises :class:`~sbrdf_xr.errors.UnitError` naming
  the argument.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import inspect
import re
import types
import warnings
from collections.abc import Callable, Mapping
from typing import Any

import astropy.units as u
import numpy as np
import pytest
import xarray as xr
from numpydoc.docscrape import NumpyDocString

from sbrdf_xr.errors import UnitError

PACKAGES = (
    "bench",
    "body",
    "brdf",
    "cli",
    "engine",
    "geometry",
    "invert",
    "kernels",
    "lightcurves",
    "materials",
    "observing",
    "photometry",
    "plot",
    "store",
)
MODULES = ("accessors", "catalog", "sources", "units")

#: Physical kinds of the units converted at the door (astropy's names; a unit of several
#: names, such as ``km s-1`` "speed/velocity", is of a kind when one of them is here).
#: Dimensionless numbers (``[1]``: reflectances, fractions, emissivities) have no unit to
#: convert and are left out.
KINDS = {
    "length",
    "angle",
    "time",
    "angular speed",
    "angular frequency",
    "temperature",
    "pressure",
    "speed",
    "frequency",
    "area",
    "volume",
    "mass",
    "mass density",
    "moment of inertia",
    "data quantity",
    "energy",
    "power",
    "energy flux",
    "radiance",
    "radiant intensity",
    "spectral flux density",
    "spectral flux density wav",
    "surface brightness wav",
    "particle flux",
}
#: Kinds astropy has no name for ("unknown"), each by a unit of it: a unit that converts
#: to it is of the kind.
UNNAMED_KINDS = {
    "inverse solid angle": "sr-1",  # an sBRDF
    "area per solid angle": "m2 sr-1",  # a signal
    "spectral intensity wav": "W sr-1 nm-1",  # a signal under sunlight
    "magnitude": "mag",
    "cubed angle": "deg3",  # a smoothing spline's parameter over angles in degrees
}
#: Units named by an argument's ending.
SUFFIXES = {
    "_kg_m3": "kg m-3",
    "_bytes": "byte",
    "_mag": "mag",
    "_deg_s": "deg / s",
    "_km_s": "km / s",
    "_hpa": "hPa",
    "_km": "km",
    "_deg": "deg",
    "_nm": "nm",
    "_au": "au",
    "_s": "s",
    "_m": "m",
}
_BRACKET = re.compile(r"\[([^\]\[]+)\]")


def kind(unit: Any) -> str | None:
    """The kind of ``unit`` among :data:`KINDS` and :data:`UNNAMED_KINDS`, or None."""
    named = set(unit.physical_type) & KINDS
    if named:
        return min(named)
    return next((k for k, ref in UNNAMED_KINDS.items() if unit.is_equivalent(ref)), None)


def _unit_in(text: str) -> str | None:
    for s in _BRACKET.findall(text):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                unit = u.Unit(s.strip(), parse_strict="raise")
        except (ValueError, TypeError):
            continue
        if kind(unit) is not None:
            return s.strip()
    return None


def public_callables() -> dict[str, Any]:
    """Canonical name -> every public function and class of the package's ``__all__``s
    (bound methods exported as functions, such as a model's ``brdf_angles``, by the name
    they are exported under)."""
    found: dict[str, Any] = {}
    visited: set[str] = set()

    def walk(mod: types.ModuleType) -> None:
        for n in getattr(mod, "__all__", ()):
            obj = getattr(mod, n, None)
            if isinstance(obj, types.ModuleType):
                if obj.__name__.startswith("sbrdf_xr.") and obj.__name__ not in visited:
                    visited.add(obj.__name__)
                    walk(obj)
            elif (
                inspect.isclass(obj) or inspect.isfunction(obj) or inspect.ismethod(obj)
            ) and getattr(obj, "__module__", "").startswith("sbrdf_xr"):
                name = (
                    f"{mod.__name__}.{n}"
                    if inspect.ismethod(obj)
                    else f"{obj.__module__}.{obj.__qualname__}"
                )
                found.setdefault(name, obj)
                if inspect.isclass(obj):  # and its public methods, taking ``self=`` by name
                    for m, attr in vars(obj).items():
                        if not m.startswith("_") and isinstance(
                            attr, types.FunctionType | classmethod | staticmethod
                        ):
                            found.setdefault(f"{name}.{m}", getattr(obj, m))

    for name in PACKAGES + MODULES:
        mod = importlib.import_module(f"sbrdf_xr.{name}")
        visited.add(mod.__name__)
        walk(mod)
    return found


def unit_arguments() -> dict[tuple[str, str], str]:
    """(callable, argument) -> its unit, for every public argument that has one."""
    out = {}
    for name, obj in public_callables().items():
        try:
            sig = inspect.signature(obj)
        except (TypeError, ValueError):
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            doc = NumpyDocString(inspect.getdoc(obj) or "")
        described: dict[str, str] = {}
        sections = ("Parameters", "Other Parameters") + (
            ("Attributes",) if inspect.isclass(obj) else ()
        )
        for sec in sections:
            for p in doc[sec]:
                for arg in p.name.split(","):
                    described.setdefault(arg.strip().lstrip("*"), f"{p.type} {' '.join(p.desc)}")
        for arg, param in sig.parameters.items():
            if param.annotation in (bool, "bool"):
                continue  # a flag whose description names the unit of what it fits
            # the unit a name ends in, else the first one its description states
            unit = next((v for s, v in SUFFIXES.items() if arg.endswith(s)), None)
            if unit is None:
                unit = _unit_in(described.get(arg, ""))
            if unit is not None:
                out[(name, arg)] = unit
    from sbrdf_xr.engine.knobs import KNOBS

    for knob in KNOBS.values():  # the scene's numerical knobs, documented in their table
        if knob.unit:
            out[("sbrdf_xr.engine.scene.Scene", knob.name)] = knob.unit
    return out


# ------------------------------------------------------------------ the inputs of the cases
WL = np.array([500.0, 600.0, 700.0])  # [nm]
NORMAL, TO_SUN, TO_OBS = [0.0, 0.0, 1.0], [0.5, 0.0, 1.0], [-0.4, 0.1, 1.0]
T0 = np.datetime64("2024-03-17T01:20:00", "ns")
_T2 = np.array(["2024-03-17T01:20:00", "2024-03-17T01:20:10"], dtype="datetime64[ns]")


def _rs() -> dict[str, Any]:
    from sbrdf_xr.brdf.robertson_sandford import TABLE4

    return dict(TABLE4["AFGL-01"])


def _fit_core_case() -> dict[str, Any]:
    """A Beckmann core 0.3 deg off specular on a sloping body it cannot take, 0.2-deg steps:
    a residual far from zero and every parameter far from zero, so the fit is well
    conditioned and compared relatively."""
    from sbrdf_xr.brdf.specular_core import core_brdf
    from sbrdf_xr.geometry import facet_vectors

    t, d, p = np.full(41, 30.0), np.linspace(-4.0, 4.0, 41), np.zeros(41)
    core = core_brdf(*facet_vectors(t, d - 0.3, p), [0.3], [0.008])
    spectra = 0.2 + 0.02 * d[:, None] + core
    return dict(theta_i=t, delta_theta=d, phi=p, spectra=spectra, body=np.full((41, 1), 0.2))


def _core() -> dict[str, Any]:
    return {**_rs(), "core_rho": 0.2, "core_roughness": 0.01}


def _halo() -> dict[str, Any]:
    return {**_core(), "halo_a": 1e-3, "halo_b": 1e-5, "halo_g": 2.5}


def _fit_halo_case() -> dict[str, Any]:
    """Core and halo 0.3 deg off specular on a flat body, the model itself (the fit
    converges to rounding), and one sample below the horizon the model cannot take
    (rms_log far from zero, no parameter moved by it); the core alone fitted as the start."""
    from sbrdf_xr.brdf.halo import halo_brdf
    from sbrdf_xr.brdf.specular_core import core_brdf, fit_core
    from sbrdf_xr.geometry import facet_vectors

    t, d, p = np.full(82, 30.0), np.append(np.linspace(-8.0, 8.0, 81), 70.0), np.zeros(82)
    vec = facet_vectors(t, d - 0.3, p)
    spectra = 0.2 + core_brdf(*vec, [0.3 * np.cos(np.radians(30.0))], [0.008])
    spectra = spectra + halo_brdf(*vec, [1e-2], [0.03**2.5], [2.5])
    spectra[-1] = 0.3
    case = dict(theta_i=t, delta_theta=d, phi=p, spectra=spectra, body=np.full((82, 1), 0.2))
    return {**case, "core": fit_core(**case)}


_MICRO = {"roughness": 0.2, "n": 1.5, "k": 0.0, "rho_d": 0.1}
_ANISO = {"alpha_x": 0.2, "alpha_y": 0.3, "n": 1.5, "k": 0.0, "rho_d": 0.1}
_LAMBERT = {"rho": 0.4}


def _model(name: str) -> Any:
    return importlib.import_module(f"sbrdf_xr.brdf.{name}").MODEL


def _box(material: str = "grey") -> Any:
    import trimesh

    from sbrdf_xr import load_spacecraft

    return load_spacecraft(trimesh.creation.box(), material=material)


def _grey() -> xr.DataArray:
    from sbrdf_xr.materials.schema import lambertian

    return lambertian(0.5, WL, material="grey")


def _table() -> xr.DataArray:
    """A small table with structure in every angle (a lobe measured and built)."""
    from sbrdf_xr.materials.tables import build_lut
    from sbrdf_xr.testing import make_measurements

    return build_lut(
        make_measurements(n_wavelength=2, theta_i=(20.0, 50.0)),
        n_phi=7,
        n_delta_theta=7,
        check_energy=False,
        check_bound=1.0,  # a deliberately coarse table: its self-check is not the point
    )


def _spec(model: str = "lambert", **params: Any) -> xr.Dataset:
    from sbrdf_xr.materials.models import model_material

    return model_material(model, [550.0], material="m", provenance="test", **(params or _LAMBERT))


def _aniso_spec() -> xr.Dataset:
    return _spec("anisotropic_microfacet", **{**_ANISO, "n": 1.0, "k": 6.0, "rho_d": 0.0})


def _lobe() -> Any:
    from sbrdf_xr.testing import lobe_function

    return lobe_function(np.array([500.0, 700.0]))


def _cube() -> xr.Dataset:
    wl = np.arange(400.0, 1101.0, 10.0)
    return xr.Dataset(
        {"signal": (("geometry", "wavelength"), np.full((2, wl.size), 0.1), {"units": "m2 sr-1"})},
        coords={"wavelength": ("wavelength", wl, {"units": "nm"})},
    )


def _rotation_cube() -> xr.Dataset:
    from sbrdf_xr import Scene, simulate

    ang = np.arange(0.0, 360.0, 30.0)
    from sbrdf_xr.geometry import rotation_sweep

    scene = Scene(
        _box(),
        {"grey": _grey_wide()},
        attitudes=rotation_sweep([0, 0, 1], ang),
        phase_angles=[30.0],
        attitude_angle=ang,
    )
    return simulate(scene).compute()


def _grey_wide() -> xr.DataArray:
    from sbrdf_xr.materials.schema import lambertian

    return lambertian(0.5, np.arange(400.0, 1101.0, 50.0), material="grey")


def _observation(**kw: Any) -> Any:
    from sbrdf_xr.observing.observe import canx1_pass

    obs = canx1_pass()
    return dataclasses.replace(obs, times=obs.times[100:104], **kw)


def _light_curve() -> xr.Dataset:
    return xr.Dataset(
        {"magnitude": ("band", [8.0, 7.6]), "uncertainty": ("band", [0.02, 0.02])},
        coords={"band": ["V", "R"]},
    )


def _compare_inputs() -> dict[str, Any]:
    ang = np.arange(0.0, 360.0, 10.0)
    sim = xr.DataArray(
        np.stack([10 + np.cos(np.radians(ang))], 1),
        dims=("attitude", "band"),
        coords={"attitude_angle": ("attitude", ang), "band": ["V"]},
    )
    t = 3.0 * np.arange(9)
    lc = xr.Dataset(
        {
            "magnitude": ("obs", 10.5 + np.cos(np.radians(ang[:9] + 7.0))),
            "uncertainty": ("obs", np.full(9, 0.01)),
        },
        coords={"time": ("obs", t), "band": ("obs", ["V"] * 9)},
    )
    return {"measured": lc, "simulated": sim, "period": 360.0 / 10.0 * 3.0}


def _time_curve() -> dict[str, Any]:
    t = T0 + np.arange(61) * np.timedelta64(1, "s")
    curve = 12.0 + 0.3 * np.sin(np.arange(61) / 5.0)
    sim = xr.DataArray(curve[:, None], dims=("time", "band"), coords={"time": t, "band": ["V"]})
    k = np.arange(0, 60, 3)
    lc = xr.Dataset(
        {
            "magnitude": ("obs", curve[k] + 0.1 + 0.01 * np.sin(k)),
            "uncertainty": ("obs", np.full(k.size, 0.01)),
        },
        coords={"time": ("obs", t[k] + np.timedelta64(2, "s")), "band": ("obs", ["V"] * k.size)},
    )
    return {"measured": lc, "simulated": sim}


def _spin_lc() -> dict[str, Any]:
    from sbrdf_xr import Scene, geometry, simulate
    from sbrdf_xr.invert import axis_vector, spin_model

    spin = spin_model([0, 0, 1], axis_vector(60.0, 30.0), period=20.0, phase=30.0)
    t = np.arange(0.0, 24.0, 1.0)
    box = _box()
    scene = Scene(
        box,
        {"grey": _grey_wide()},
        attitudes=spin.quaternions(t),
        phase_angles=[30.0],
        outputs=("band_signal",),
        bands=("V",),
    )
    flux = simulate(scene).band_signal.isel(phase_angle=0).values.ravel()
    lc = xr.Dataset(
        {"flux": ("obs", flux), "flux_uncertainty": ("obs", 0.01 * flux)},
        coords={"time": ("obs", t), "band": ("obs", ["V"] * t.size)},
    )
    s, o = geometry.observation_plane([30.0], (1, 0, 0), (0, 0, 1))
    return dict(
        light_curve=lc,
        spacecraft=box,
        to_sun=s[0],
        to_observer=o[0],
        materials={"grey": _grey_wide()},
        periods=np.linspace(18.0, 22.0, 5),
        n_axes=6,
        n_phases=6,
        n_starts=1,
        refine=False,
        method="direct",
        n_threads=1,
    )


def _brdf_case(params: Any, wl: Any = WL, **extra: Any) -> Callable:
    return lambda: dict(
        normal=NORMAL,
        to_sun=TO_SUN,
        to_observer=TO_OBS,
        wavelength=wl,
        **(params() if callable(params) else params),
        **extra,
    )


def _angles_case(module: str, params: Any) -> Callable:
    def make() -> dict[str, Any]:
        p = params() if callable(params) else params
        wl = [4000.0] if module == "robertson_sandford" else WL
        psi = {"psi": [30.0]} if module == "anisotropic" else {}
        return dict(theta_i=[20.0, 40.0], delta_theta=[5.0], phi=[10.0], wavelength=wl, **psi, **p)

    return make


#: (callable, its keyword arguments): every argument with a unit is checked by replacing
#: its value.  ``slow``: the comparison runs with ``--runslow`` only (the refusal always).
def _cache_with_entries() -> Any:
    """A table cache directory with an entry last used 3 days ago and one used now: a
    prune of entries unused for 2 days (48 h) takes the first only."""
    import os
    import tempfile
    import time
    from pathlib import Path

    d = Path(tempfile.mkdtemp(prefix="sbrdf-cache-"))
    for key, days in (("0", 3.0), ("1", 0.0)):
        table = d / f"grey-{key * 32}.nc"
        table.write_bytes(b"table")
        t = time.time() - days * 86400.0
        os.utime(table, (t, t))
    return d


CASES: dict[str, Callable[[], dict[str, Any]]] = {
    # --- articulated parts and the Starlink body
    "sbrdf_xr.body.parts.Part": lambda: dict(
        name="array", facets=[0], axis=[0, 0, 1.0], point=[0.0, 0.0, 1.5]
    ),
    "sbrdf_xr.body.parts.SunTracking": lambda: dict(limits=(-30.0, 45.0)),
    "sbrdf_xr.body.parts.hinge_rotation": lambda: dict(axis=[0, 0, 1.0], angle=[0.3, 1.2]),
    "sbrdf_xr.body.parts.tracking_angle": lambda: dict(
        axis=[0, 0, 1.0], normal=[1.0, 0, 0], to_sun=[[0.0, 1.0, 0.0]], limits=(-0.5, 0.5)
    ),
    "sbrdf_xr.engine.builtin.starlink_materials": lambda: dict(wavelength=[450.0, 650.0]),
    # --- sbrdf_xr (modules)
    "sbrdf_xr.geometry.anisotropy.psi_average": lambda: dict(
        values=[1.0, 3.0, 2.0], grid=[0.0, 90.0, 180.0]
    ),
    "sbrdf_xr.geometry.anisotropy.psi_weights": lambda: dict(
        grid=[0.0, 60.0, 120.0], psi=[30.0, 150.0]
    ),
    "sbrdf_xr.geometry.angles.facet_vectors": lambda: dict(
        theta_i=[20.0], delta_theta=[5.0], phi=[10.0]
    ),
    "sbrdf_xr.geometry.angles.from_conventional": lambda: dict(
        theta_i=[20.0], phi_i=[180.0], theta_r=[30.0], phi_r=[10.0]
    ),
    "sbrdf_xr.geometry.angles.to_conventional": lambda: dict(
        theta_i=[20.0], delta_theta=[5.0], phi=[10.0]
    ),
    "sbrdf_xr.geometry.angles.observation_plane": lambda: dict(phase_angle=[20.0, 75.0]),
    "sbrdf_xr.geometry.rotations.axis_rotation": lambda: dict(axis=[0, 0, 1], angle=[30.0, 60.0]),
    "sbrdf_xr.geometry.rotations.euler_attitudes": lambda: dict(
        sequence="zyx", angles=[[10.0, 20.0, 30.0]]
    ),
    "sbrdf_xr.geometry.rotations.rotation_sweep": lambda: dict(axis=[0, 0, 1], angles=[0.0, 45.0]),
    "sbrdf_xr.sources.earthshine_irradiance_ratio": lambda: dict(
        albedo=0.3, range=42164.0, phase_angle=30.0
    ),
    "sbrdf_xr.sources.earthshine_finite": lambda: dict(
        plate_normal=[0, 0, -1],
        to_earth=[0, 0, -1],
        to_sun=[0, 0, 1],
        range=42164.0,
        nodes=(16, 32),
    ),
    "sbrdf_xr.sources.earthshine_facets": lambda: dict(
        normals=[[0, 0, -1], [1, 0, 0]],
        to_earth=[[0, 0, -1]],
        to_sun=[[0, 0, 1]],
        range=[7000.0],
        nodes=(16, 32),
    ),
    "sbrdf_xr.sources.earth_thermal_irradiance": lambda: dict(
        wavelength=[8000.0, 10_000.0],
        plate_normal=[0, 0, -1],
        to_earth=[0, 0, -1],
        range=42164.0,
        temperature=255.0,
        nodes=(16, 32),
    ),
    "sbrdf_xr.sources.earth_view_facets": lambda: dict(
        normals=[[0, 0, -1], [1, 0, 0]], to_earth=[[0, 0, -1]], range=[7000.0], nodes=(16, 32)
    ),
    "sbrdf_xr.sources.equilibrium_temperature": lambda: dict(
        absorbed=[100.0, 1361.0], emissivity=0.8
    ),
    "sbrdf_xr.sources.radiative_cooling": lambda: dict(
        time=[0.0, 600.0], initial_temperature=300.0, heat_capacity=2430.0, emissivity=0.85
    ),
    "sbrdf_xr.sources.emissivity_at": lambda: dict(
        emissivity=np.array([[0.8, 0.5], [0.6, 0.3]]),
        theta_grid=np.array([0.0, 90.0]),
        theta=[45.0, 70.0],
    ),
    "sbrdf_xr.sources.moon_v_magnitude": lambda: dict(phase_angle=[10.0, 90.0]),
    "sbrdf_xr.sources.moonlight_irradiance_ratio": lambda: dict(
        phase_angle=[10.0, 90.0], distance=384400.0
    ),
    "sbrdf_xr.sources.planck": lambda: dict(wavelength=[800.0, 10_000.0], temperature=300.0),
    # --- body
    "sbrdf_xr.body.imperfections.tilt_quadrature": lambda: dict(sigma=2.0, n=3),
    "sbrdf_xr.body.imperfections.tilted_normals": lambda: dict(
        normals=[[0.0, 0.0, 1.0]], tilts=[[0.0, 0.0], [0.1, 0.05]]
    ),
    "sbrdf_xr.body.picture.plot_facets": lambda: dict(
        mesh=_box().mesh, facet_material=["grey"] * 12, elev=25.0, azim=35.0
    ),
    "sbrdf_xr.body.visibility.lit_fraction": lambda: dict(
        spacecraft=_l_body(), directions=[[0.3, 0.4, 0.866]], offset=1e-6
    ),
    # --- brdf
    "sbrdf_xr.brdf.lambert.brdf": _brdf_case(_LAMBERT),
    "sbrdf_xr.brdf.lambert.directional_hemispherical_reflectance": lambda: dict(
        theta_i=[20.0, 60.0], wavelength=WL, **_LAMBERT
    ),
    "sbrdf_xr.brdf.lambert.check_params": lambda: dict(wavelength=WL, **_LAMBERT),
    "sbrdf_xr.brdf.lambert.brdf_angles": _angles_case("lambert", _LAMBERT),
    "sbrdf_xr.brdf.lambert.render_grid": _angles_case("lambert", _LAMBERT),
    "sbrdf_xr.brdf.microfacet.brdf": _brdf_case(_MICRO, layers=[(1.38, 100.0)]),
    "sbrdf_xr.brdf.microfacet.directional_hemispherical_reflectance": lambda: dict(
        theta_i=[20.0, 60.0], wavelength=WL, layers=[(1.38, 100.0)], **_MICRO
    ),
    "sbrdf_xr.brdf.microfacet.check_params": lambda: dict(wavelength=WL, **_MICRO),
    "sbrdf_xr.brdf.microfacet.brdf_angles": _angles_case("microfacet", _MICRO),
    "sbrdf_xr.brdf.microfacet.render_grid": _angles_case("microfacet", _MICRO),
    "sbrdf_xr.brdf.anisotropic.brdf": _brdf_case(_ANISO, tangent=[1.0, 0.0, 0.0]),
    "sbrdf_xr.brdf.anisotropic.directional_hemispherical_reflectance": lambda: dict(
        theta_i=[20.0], wavelength=[550.0], psi=30.0, **_ANISO
    ),
    "sbrdf_xr.brdf.anisotropic.check_params": lambda: dict(wavelength=WL, **_ANISO),
    "sbrdf_xr.brdf.anisotropic.brdf_angles": _angles_case("anisotropic", _ANISO),
    "sbrdf_xr.brdf.anisotropic.render_grid": _angles_case("anisotropic", _ANISO),
    "sbrdf_xr.brdf._common.tangent_from_azimuth": lambda: dict(psi=[0.0, 30.0]),
    "sbrdf_xr.brdf.optics.aluminium_index": lambda: dict(wavelength=WL),
    "sbrdf_xr.brdf.optics.gaas_index": lambda: dict(wavelength=[900.0, 1000.0]),
    "sbrdf_xr.brdf.optics.silica_index": lambda: dict(wavelength=WL),
    "sbrdf_xr.brdf.optics.sapphire_index": lambda: dict(wavelength=WL),
    "sbrdf_xr.brdf.optics.titania_index": lambda: dict(wavelength=WL),
    "sbrdf_xr.brdf.optics.fresnel_thin_film_stack": lambda: dict(
        cos_theta=[1.0, 0.5], wavelength=WL, layers=[(1.38, 100.0)], substrate=1.5
    ),
    "sbrdf_xr.brdf.robertson_sandford.brdf": _brdf_case(_rs, wl=[4000.0]),
    "sbrdf_xr.brdf.robertson_sandford.diffuse_brdf": _brdf_case(_rs, wl=[4000.0]),
    "sbrdf_xr.brdf.robertson_sandford.specular_brdf": _brdf_case(_rs, wl=[4000.0]),
    "sbrdf_xr.brdf.robertson_sandford.diffuse_reflectance": lambda: dict(
        theta_i=[20.0, 60.0], wavelength=[4000.0], **_rs()
    ),
    "sbrdf_xr.brdf.robertson_sandford.specular_reflectance": lambda: dict(
        theta_i=[20.0, 60.0], wavelength=[4000.0], **_rs()
    ),
    "sbrdf_xr.brdf.robertson_sandford.total_reflectance": lambda: dict(
        theta_i=[20.0, 60.0], wavelength=[4000.0], **_rs()
    ),
    "sbrdf_xr.brdf.robertson_sandford.directional_hemispherical_reflectance": lambda: dict(
        theta_i=[20.0, 60.0], wavelength=[4000.0], **_rs()
    ),
    "sbrdf_xr.brdf.robertson_sandford.directional_emissivity": lambda: dict(
        theta=[20.0, 60.0], wavelength=[4000.0], **_rs()
    ),
    "sbrdf_xr.brdf.robertson_sandford.check_params": lambda: dict(wavelength=[4000.0], **_rs()),
    "sbrdf_xr.brdf.robertson_sandford.brdf_angles": _angles_case("robertson_sandford", _rs),
    "sbrdf_xr.brdf.robertson_sandford.render_grid": _angles_case("robertson_sandford", _rs),
    "sbrdf_xr.brdf.specular_core.brdf": _brdf_case(_core, wl=[4000.0]),
    "sbrdf_xr.brdf.specular_core.directional_hemispherical_reflectance": lambda: dict(
        theta_i=[20.0, 60.0], wavelength=[4000.0], **_core()
    ),
    "sbrdf_xr.brdf.specular_core.check_params": lambda: dict(wavelength=[4000.0], **_core()),
    "sbrdf_xr.brdf.specular_core.brdf_angles": _angles_case("specular_core", _core),
    "sbrdf_xr.brdf.specular_core.render_grid": _angles_case("specular_core", _core),
    "sbrdf_xr.brdf.specular_core.core_loss": lambda: dict(theta_i=[0.0, 60.0], core_roughness=0.2),
    "sbrdf_xr.brdf.specular_core.energy_scale": lambda: dict(
        theta_i=[20.0, 60.0], wavelength=[4000.0], **_core()
    ),
    "sbrdf_xr.brdf.specular_core.fit_core": _fit_core_case,
    "sbrdf_xr.brdf.halo.brdf": _brdf_case(_halo, wl=[4000.0]),
    "sbrdf_xr.brdf.halo.check_params": lambda: dict(wavelength=[4000.0], **_halo()),
    "sbrdf_xr.brdf.halo.brdf_angles": _angles_case("halo", _halo),
    "sbrdf_xr.brdf.halo.render_grid": _angles_case("halo", _halo),
    "sbrdf_xr.brdf.halo.directional_hemispherical_reflectance": lambda: dict(
        theta_i=[20.0, 60.0], wavelength=[4000.0], **_halo()
    ),
    "sbrdf_xr.brdf.halo.energy_scale": lambda: dict(
        theta_i=[20.0, 60.0], wavelength=[4000.0], **_halo()
    ),
    "sbrdf_xr.brdf.halo.halo_reflectance": lambda: dict(
        theta_i=[0.0, 60.0], halo_a=[1e-3], halo_b=[1e-5], halo_g=[2.5]
    ),
    "sbrdf_xr.brdf.halo.fit_halo": _fit_halo_case,
    "sbrdf_xr.brdf.halo.halo_brdf": lambda: dict(
        normal=[0.0, 0.0, 1.0],
        to_sun=[0.5, 0.0, 0.866],
        to_observer=[-0.52, 0.0, 0.85],
        halo_a=[1e-3],
        halo_b=[1e-5],
        halo_g=[2.5],
    ),
    "sbrdf_xr.brdf.robertson_sandford_angular.angular_g": lambda: dict(theta=[20.0, 45.0], b=0.5),
    "sbrdf_xr.brdf.robertson_sandford_angular.cutoff_factor": lambda: dict(
        theta_r=[45.0, 85.0], b=0.12
    ),
    "sbrdf_xr.brdf.robertson_sandford_angular.normalisation_H": lambda: dict(theta_i=30.0, e=1.0),
    "sbrdf_xr.brdf.robertson_sandford_angular.structure_h": lambda: dict(alpha=[10.0, 80.0], e=0.5),
    "sbrdf_xr.brdf._model.Model.brdf_angles": lambda: dict(
        self=_model("anisotropic"), **_angles_case("anisotropic", _ANISO)()
    ),
    "sbrdf_xr.brdf._model.Model.render_grid": lambda: dict(
        self=_model("anisotropic"), **_angles_case("anisotropic", _ANISO)()
    ),
    "sbrdf_xr.brdf._model.Model.check_params": lambda: dict(
        self=_model("lambert"), wavelength=WL, **_LAMBERT
    ),
    "sbrdf_xr.body.spacecraft.Spacecraft.plot": lambda: dict(self=_box(), elev=25.0, azim=35.0),
    "sbrdf_xr.body.spacecraft.Spacecraft.inertia": lambda: dict(self=_box(), density=100.0),
    "sbrdf_xr.accessors.SbrdfDatasetAccessor.magnitudes": lambda: dict(
        self=_cube().sbrdf, bands=["V"], range=1000.0
    ),
    "sbrdf_xr.accessors.SbrdfDatasetAccessor.photometry": lambda: dict(
        self=_cube().sbrdf, bands=["V", "R"], range=1000.0
    ),
    "sbrdf_xr.observing.observation.Observation.next_pass": lambda: dict(
        self=_observation(), days=0.5, twilight=-12.0
    ),
    "sbrdf_xr.observing.tumble.Tumble.from_spacecraft": lambda: dict(
        spacecraft=_box(), density=100.0, omega=(1.0, 2.0, 3.0)
    ),
    # --- engine
    "sbrdf_xr.engine.scene.Scene": lambda: dict(
        spacecraft=_box(),
        materials={"grey": _grey()},
        attitudes=[[0, 0, 0, 1.0]],
        phase_angles=[20.0, 60.0],
        attitude_angle=[15.0],
        surface_tilt=2.0,
        earth_range=42164.0,
        earth_phase_angle=60.0,
        temperature=300.0,
        earth_temperature=255.0,
        table_theta_step=5.0,
        block_bytes=2**20,
    ),
    "sbrdf_xr.engine.effects.moonlight.moon_from_spacecraft": lambda: _moon_inputs(),
    # --- invert
    "sbrdf_xr.invert._data.magnitudes_to_signal": lambda: dict(
        light_curve=_light_curve(), range=1000.0
    ),
    "sbrdf_xr.invert._spin.fit.fit_spin": _spin_lc,
    "sbrdf_xr.invert._unmix.unmix": lambda: _unmix_inputs(),
    "sbrdf_xr.invert._spin.fit.period_grid": lambda: dict(p_min=60.0, p_max=70.0, span=240.0),
    "sbrdf_xr.invert._spin.fit.axis_vector": lambda: dict(
        longitude=[30.0, 60.0], latitude=[20.0, -5.0]
    ),
    "sbrdf_xr.invert._studies.spin_recovery": lambda: _recovery_inputs(),
    "sbrdf_xr.invert._joint.fit.fit_observation": lambda: {
        **_joint_inputs(),
        "model_discrepancy": 0.01,
    },
    "sbrdf_xr.invert._joint.study.observation_recovery": lambda: dict(
        spacecraft=_box("lambertian-grey-50"),
        observation=_joint_inputs()["observation"],
        spin=dict(_SPIN),
        area_fraction={"lambertian-grey-50": 1.0},
        extinction={"V": 0.2},
        bands=("V",),
        n_draws=1,
        noise=0.02,
        phase_symmetry=180.0,
    ),
    "sbrdf_xr.invert._spin.search.spin_model": lambda: dict(
        axis_body=[0, 0, 1], axis=[1.0, 0.0, 0.0], period=60.0, phase=30.0
    ),
    # --- materials
    "sbrdf_xr.materials.schema.lambertian": lambda: dict(albedo=0.5, wavelength=WL),
    "sbrdf_xr.materials.schema.constant_material": lambda: dict(
        value=0.1, wavelength=WL, material="c"
    ),
    "sbrdf_xr.materials.schema.new_material": lambda: dict(
        values=np.full((2, 2, 2, 3), 0.1),
        theta_i=[0.0, 60.0],
        delta_theta=[-10.0, 10.0],
        phi=[0.0, 30.0],
        wavelength=WL,
        material="n",
        source="synthetic",
        provenance="test",
    ),
    "sbrdf_xr.materials.tables.lookup": lambda: dict(
        material=_table(), theta_i=[25.0, 42.0], delta_theta=[3.0, -7.0], phi=[4.0, 11.0]
    ),
    "sbrdf_xr.materials.tables.lookup_anisotropic": lambda: dict(
        material=_aniso_table(), theta_i=[30.0], delta_theta=[0.0], phi=[4.0], psi=[25.0]
    ),
    "sbrdf_xr.materials.merl.read_merl": lambda: dict(
        path=_merl_file(), theta_i=[20.0, 50.0], step=10.0
    ),
    "sbrdf_xr.materials.rgl.read_rgl": lambda: dict(
        path=_rgl_file(), theta_i=[20.0, 50.0], step=10.0, max_zenith=70.0
    ),
    "sbrdf_xr.materials.rgl.write_rgl": lambda: dict(
        path=_rgl_file().with_name("again.bsdf"),
        brdf=_grey_rgl,
        wavelengths=[500.0],
        theta_i=[0.0, 40.0, 80.0],
        resolution=8,
        ndf_resolution=8,
    ),
    "sbrdf_xr.materials.coverage.snap_angles": lambda: dict(
        values=[10.0, 10.0 + 1e-12, 20.0], tol=1e-6
    ),
    "sbrdf_xr.materials.coverage.scan_layout": lambda: dict(
        delta_theta=[-2.0, -2.0, 0.0, 0.0], phi=[0.0, 5.0, 0.0, 5.0], tol=1e-6
    ),
    "sbrdf_xr.materials.coverage.specular_distance": lambda: dict(
        delta_theta=[3.0, -3.0], phi=[4.0, 4.0]
    ),
    "sbrdf_xr.materials.readers.measurement_set": lambda: dict(
        theta_i=np.array([30.0, 30.0]),
        delta_theta=np.array([0.0, 10.0]),
        phi=np.array([0.0, 5.0]),
        wavelength=np.array([550.0]),
        values=np.array([[2.0], [1e-4]]),
        material="m",
        provenance="test",
        noise_floor=2e-4,  # not at a sample: a conversion's rounding does not move it
    ),
    "sbrdf_xr.materials.selfcheck.sample_errors": lambda: dict(
        table=_grey(),
        theta_i=np.array([30.0, 60.0]),
        delta_theta=np.array([0.0, -10.0]),
        phi=np.array([0.0, 5.0]),
        spectra=np.full((2, 3), 0.2),
    ),
    "sbrdf_xr.materials.cache.prune": lambda: dict(
        older_than=2.0, dry_run=True, directory=_cache_with_entries()
    ),
    "sbrdf_xr.materials.build.build_lut": lambda: dict(
        measurements=_measurements((20.0, 35.0, 55.0)),
        n_phi=7,
        n_delta_theta=7,
        theta_i=[20.0, 35.0, 50.0],
        smoothing=300.0,
        blend=10.0,
        blend_normal=5.0,
        check_energy=False,
    ),
    "sbrdf_xr.materials.construction.paper_delta_theta_grid": lambda: dict(
        dt_min=-4.0, dt_max=8.0, n=5
    ),
    "sbrdf_xr.materials.construction.paper_phi_grid": lambda: dict(phi_max=10.0, n=5),
    "sbrdf_xr.materials.energy.hemispherical_reflectance": lambda: dict(
        material=_table(), theta_i=[25.0, 45.0], warn=False
    ),
    "sbrdf_xr.materials.goniometer.measure": lambda: dict(
        func=_lobe(),
        wavelength=np.array([500.0, 700.0]),
        theta_i=(20.0, 50.0),
        noise_floor=0.05,
    ),
    "sbrdf_xr.materials.goniometer.paper_scheme": lambda: dict(
        theta_i=30.0, dt_min=-20.0, dt_max=30.0, phi_max=[10, 12, 14, 16, 14, 12, 10]
    ),
    "sbrdf_xr.materials.goniometer.scheme_extents": lambda: dict(
        func=_lobe(),
        theta_i=30.0,
        noise_floor=0.05,
        max_theta_r=80.0,
        min_phase_angle=5.0,
        max_phi=80.0,
        step=0.5,
    ),
    "sbrdf_xr.materials.model_schema.model_material": lambda: dict(
        model="microfacet",
        wavelength=WL,
        material="m",
        provenance="test",
        layers=[(1.38, 100.0)],
        **_MICRO,
    ),
    "sbrdf_xr.materials.models.measure": lambda: dict(
        spec=_spec("robertson_sandford", rho_D=0.6, epsilon=0.2, b=0.1, e=0.3),
        theta_i=[20.0, 40.0],
    ),
    "sbrdf_xr.materials.optical.optical_constants": lambda: dict(
        source="au-olmon-ev", wavelength=[500.0, 600.0]
    ),
    "sbrdf_xr.materials.optical.specular_reflectance": lambda: dict(
        name="gold", wavelength=[500.0, 600.0], theta=[0.0, 30.0]
    ),
    "sbrdf_xr.materials.optical.optical_material": lambda: dict(
        name="gold", wavelength=[500.0, 600.0]
    ),
    "sbrdf_xr.engine.builtin.geo_comsat_materials": lambda: dict(wavelength=[500.0, 600.0]),
    "sbrdf_xr.materials.models.render": lambda: dict(
        spec=_spec(),
        theta_i=[0.0, 45.0],
        delta_theta=[-10.0, 10.0],
        phi=[0.0, 30.0],
        progress=False,
        max_bytes=1e6,
    ),
    "sbrdf_xr.materials.models.render_anisotropic": lambda: dict(
        spec=_aniso_spec(), theta_i=[30.0], delta_theta=[0.0], phi=[0.0, 10.0], psi=[0.0, 90.0]
    ),
    "sbrdf_xr.materials.models.render_values": lambda: dict(
        model=_model("microfacet"),
        ti=np.array([20.0, 40.0]),
        dt=np.array([0.0, 5.0]),
        ph=np.array([0.0, 10.0]),
        wl=WL,
        kw=dict(_MICRO),
    ),
    "sbrdf_xr.materials.models.spectrum_function": lambda: dict(spec=_aniso_spec(), psi=30.0),
    "sbrdf_xr.materials.models.spectra": lambda: dict(
        spec=_aniso_spec(), theta_i=[30.0, 40.0], delta_theta=[5.0], phi=[10.0], psi=[20.0]
    ),
    # --- observing
    "sbrdf_xr.observing.attitude.Nadir": lambda: dict(yaw=30.0),
    "sbrdf_xr.observing.attitude.geodetic_up": lambda: dict(
        position_itrs=[[5000.0, 100.0, 5000.0]]
    ),
    "sbrdf_xr.observing.tracking_io.read_tracking_table": lambda: dict(
        path=_POMENIS40,
        site=_pomenis_site(),
        time="observation_time",
        elevation="satellite_altitude",
        azimuth="satellite_azimuth",
        height_column="satellite_height",
        time_zone="UTC",
        min_elevation=25.0,
        on_bad="drop",
    ),
    "sbrdf_xr.observing.attitude.Spin": lambda: dict(rate=2.0, phase=30.0),
    "sbrdf_xr.observing.tumble.Tumble": lambda: dict(
        inertia=(1.0, 2.0, 3.0), omega=(1.0, 2.0, 3.0)
    ),
    "sbrdf_xr.observing.orbits.Site": lambda: dict(latitude=20.7, longitude=-156.3, height=3058.0),
    "sbrdf_xr.observing.observation.Observation": lambda: dict(
        **{f.name: getattr(_observation(), f.name) for f in _observation_fields()},
        min_elevation=5.0,
    ),
    "sbrdf_xr.observing.timescales.times": lambda: dict(
        start="2024-03-17T01:20:00", stop="2024-03-17T01:21:00", step=20.0
    ),
    "sbrdf_xr.observing.earth_shadow.disc_overlap_fraction": lambda: dict(
        a=[0.01, 0.01], b=[0.02, 0.005], c=[0.015, 0.001]
    ),
    "sbrdf_xr.observing.earth_shadow.shadow_angles": lambda: dict(
        position=[-7000.0, 100.0, 0.0],
        sun=[1.496e8, 0.0, 0.0],
        earth_radius=6378.137,
        sun_radius=695700.0,
    ),
    "sbrdf_xr.observing.earth_shadow.sunlit_fraction": lambda: dict(
        position=[[-7000.0, 6378.137, 0.0]],
        sun=[[1.5e8, 0.0, 0.0]],
        earth_radius=6378.137,
        sun_radius=695700.0,
    ),
    "sbrdf_xr.observing.earth_shadow.shadow_events": lambda: _shadow_inputs(),
    "sbrdf_xr.observing.frames.Context": lambda: dict(
        epoch=T0,
        position=np.array([[7000.0, 0.0, 0.0]]),
        velocity=np.array([[0.0, 7.5, 0.0]]),
        sun=np.array([[1.496e8, 0.0, 0.0]]),
    ),
    "sbrdf_xr.observing.ephemeris.Ephemeris.from_states": lambda: dict(
        times=_T2,
        position=[[7000.0, 0.0, 0.0], [7000.0, 75.0, 0.0]],
        velocity=[[0.0, 7.5, 0.0], [0.0, 7.5, 0.0]],
    ),
    "sbrdf_xr.observing.ephemeris.to_gcrs": lambda: dict(
        frame="ITRF",
        times=_T2[:1],
        position=[[7000.0, 0.0, 0.0]],
        velocity=[[0.0, 0.0, 7.5]],
    ),
    "sbrdf_xr.observing.passes.visible_passes": lambda: dict(
        source=_observation().orbit,
        site=_observation().site,
        start="2024-03-17T01:18:00",
        stop="2024-03-17T01:24:00",
        min_elevation=15.0,
        step=30.0,
        cross_section=2.0,
    ),
    "sbrdf_xr.observing.tracking.TrackingTable": lambda: dict(
        site=_observation().site,
        times=_T2,
        elevation=[90.0, 90.0],
        azimuth=[0.0, 30.0],
        range=[500.0, 570.0],
        height=[501.111, 571.111],  # at the zenith of a site 1111 m up
        max_gap=30.0,
    ),
    "sbrdf_xr.observing.tracking.range_for_height": lambda: dict(
        site=_observation().site, direction_itrs=[[1.0, 0.0, 0.0]], height=[550.0]
    ),
    "sbrdf_xr.observing.tracking.topocentric_to_gcrs": lambda: dict(
        site=_observation().site,
        times=_T2,
        elevation=[30.0, 40.0],
        azimuth=[10.0, 20.0],
        range=[900.0, 800.0],
    ),
    # --- photometry
    "sbrdf_xr.photometry.atmosphere.airmass": lambda: dict(elevation=[30.0, 60.0]),
    "sbrdf_xr.photometry.atmosphere.rayleigh_optical_depth": lambda: dict(
        wavelength=WL, pressure=700.0
    ),
    "sbrdf_xr.photometry.limb.limb_ray": lambda: dict(
        position=[[7000.0, 0.0, 0.0]], to_sun=[[-0.2, 0.98, 0.0]]
    ),
    "sbrdf_xr.photometry.limb.limb_transmission": lambda: dict(
        tangent_height=[25.0, 40.0], distance=2700.0, wavelength=550.0, sun_radius=0.2666
    ),
    "sbrdf_xr.photometry.atmosphere.transmission": lambda: dict(
        wavelength=WL, airmass=1.5, pressure=700.0
    ),
    "sbrdf_xr.photometry.bands.band_weights": lambda: dict(
        bands=["V"], wavelength=np.arange(400.0, 1101.0, 10.0), solar=_sun()
    ),
    "sbrdf_xr.photometry.bands.filters": lambda: dict(
        bands=["V"], wavelength=np.arange(400.0, 1101.0, 10.0)
    ),
    "sbrdf_xr.lightcurves.comparison.compare": lambda: dict(
        **_compare_inputs(), max_time_shift=10.0, phase_angle=None, fit_phase=True
    ),
    "sbrdf_xr.photometry.magnitude.magnitudes": lambda: dict(
        cube=_cube(), bands=["V"], range=1000.0, sun_distance=1.01
    ),
    "sbrdf_xr.photometry.magnitude.photometry": lambda: dict(
        cube=_cube(), bands=["V", "R"], range=1000.0, sun_distance=1.01
    ),
    "sbrdf_xr.photometry.spectra.ab_reference_flux": lambda: dict(wavelength=WL),
    "sbrdf_xr.photometry.spectra.reference_flux": lambda: dict(system="Vega", wavelength=WL),
    "sbrdf_xr.photometry.spectra.hat_integrals": lambda: dict(
        x=np.array([400.0, 500.0, 600.0]), y=np.array([1.0, 2.0, 1.5]), t=np.array([450.0, 550.0])
    ),
    "sbrdf_xr.photometry.spectra.solar_spectrum": lambda: dict(wavelength=WL, solar=_sun()),
    "sbrdf_xr.photometry.spectra.vega_spectrum": lambda: dict(wavelength=WL),
    "sbrdf_xr.photometry.standard.at_resolution": lambda: dict(
        spectrum=_solar(), fwhm=5.0, wavelength=WL
    ),
    "sbrdf_xr.photometry.standard.lambert_sphere_phase": lambda: dict(alpha=[10.0, 90.0]),
    "sbrdf_xr.photometry.standard.specular_sphere_phase": lambda: dict(alpha=[10.0, 90.0]),
    "sbrdf_xr.photometry.standard.standard_magnitude": lambda: dict(
        mags=_mags(),
        range=2000.0,
        to_range=1000.0,
        phase_angle=40.0,
        to_phase_angle=90.0,
        sun_distance=1.01,
    ),
    # --- plot
    "sbrdf_xr.plot.front.accuracy_front": lambda: dict(rows=_bench_rows(), zero_below=1e-3),
    "sbrdf_xr.plot.curves.lut_slice": lambda: dict(
        material=_table(), theta_i=35.0, wavelength=600.0
    ),
    "sbrdf_xr.plot.cube.cube_magnitudes": lambda: dict(cube=_cube(), bands=["V"], range=1000.0),
    "sbrdf_xr.plot.cube.cube_figure": lambda: dict(
        cube=_rotation_cube(), bands=["V"], range=1000.0
    ),
    "sbrdf_xr.plot.cube.rotation_figure": lambda: dict(
        cube=_rotation_cube(), bands=["V"], range=1000.0
    ),
    "sbrdf_xr.plot.cube.observation_figure": lambda: dict(
        cube=_observation_cube(), bands=["V"], range=1000.0
    ),
}

#: Arguments with a unit that no case replaces, and why.
EXEMPT: dict[tuple[str, str], str] = {}
_CONTAINER = "a container: the unit is its coordinate's CF attribute, a Quantity cannot be one"
for _name, _arg in (
    ("sbrdf_xr.body.visibility.lit_fraction", "spacecraft"),
    ("sbrdf_xr.body.visibility.lit_visible_fraction", "spacecraft"),
    ("sbrdf_xr.invert._unmix.unmix", "measured"),
    ("sbrdf_xr.photometry.bands.pre_integrate", "table"),
    ("sbrdf_xr.photometry.colour_science.to_colour", "obj"),
    ("sbrdf_xr.photometry.standard.at_resolution", "spectrum"),
    ("sbrdf_xr.photometry.bands.filters", "bands"),
    ("sbrdf_xr.materials.goniometer.measure", "func"),
    ("sbrdf_xr.materials.goniometer.scheme_extents", "func"),
    ("sbrdf_xr.invert._joint.fit.fit_observation", "light_curve"),
):
    EXEMPT[(_name, _arg)] = _CONTAINER
for _arg in ("ra", "dec"):
    EXEMPT[("sbrdf_xr.observing.tracking.TrackingTable", _arg)] = (
        "exclusive with elevation/azimuth, whose case runs the same conversion; "
        "tests/observing/test_tracking.py converts RA/Dec Quantities"
    )
EXEMPT[("sbrdf_xr.body.starlink.starlink_v15", "limits")] = (
    "handed to SunTracking(limits=...), whose case checks the conversion (a Spacecraft has "
    "no equality to compare the results by)"
)
EXEMPT[("sbrdf_xr.bench.suite.bench_geometry", "step")] = (
    "a benchmark's problem size: the timing tools take bare numbers"
)
EXEMPT[("sbrdf_xr.materials.optical.optical_material", "thickness")] = EXEMPT[
    ("sbrdf_xr.materials.optical.specular_reflectance", "thickness")
] = "a mapping of layer name to thickness: each value is converted (tests/materials/test_optical)"
for _name, _arg in (
    ("sbrdf_xr.engine.attitude_table.attitudes_from_table", "table"),
    ("sbrdf_xr.engine.scene.Scene", "attitude"),
):
    EXEMPT[(_name, _arg)] = (
        "a table (a scene file's [attitude]): its angle keys take Quantities one by one, "
        "checked in tests/engine/test_attitude_table.py (radians for degrees, metres refused)"
    )
EXEMPT[("sbrdf_xr.units.check_wavelengths", "values")] = (
    "the check of bare numbers itself: a Quantity is converted before it"
)
for _row, _arg in (
    ("sbrdf_xr.bench.rows.BenchRow", "seconds"),
    ("sbrdf_xr.bench.shadowing.CostRow", "ms_per_geometry"),
    ("sbrdf_xr.bench.shadowing.ShadowRow", "ms_per_geometry"),
    ("sbrdf_xr.geometry.angles.FacetAngles", "theta_i"),
    ("sbrdf_xr.geometry.angles.FacetAngles", "delta_theta"),
    ("sbrdf_xr.geometry.angles.FacetAngles", "phi"),
    ("sbrdf_xr.engine.plan.Estimate", "output_bytes"),
    ("sbrdf_xr.engine.plan.Estimate", "block_bytes"),
    ("sbrdf_xr.engine.views.Terms", "area"),
    ("sbrdf_xr.materials.mapped.TableFile", "size"),
    ("sbrdf_xr.materials.mapped.TableFile", "mtime_ns"),
    ("sbrdf_xr.materials.mapped.MappedSlice", "offset"),
    ("sbrdf_xr.materials.mapped.MappedSlice", "strides"),
    ("sbrdf_xr.materials.cache.CacheEntry", "size"),
    ("sbrdf_xr.materials.cache.CacheEntry", "last_use"),
):
    EXEMPT[(_row, _arg)] = "a result record the package fills, not an input"

EXEMPT[("sbrdf_xr.materials.merl.write_merl", "brdf")] = (
    "a function (a BRDF of directions), not a value: its results are in sr-1 by contract"
)

EXEMPT[("sbrdf_xr.materials.rgl.write_rgl", "brdf")] = EXEMPT[
    ("sbrdf_xr.materials.merl.write_merl", "brdf")
]

EXEMPT[("sbrdf_xr.brdf._model.Model", "brdf")] = (
    "a function (the model's sBRDF), not a value: its results are in sr-1 by contract"
)

for _model_name in ("lambert", "microfacet", "robertson_sandford", "specular_core", "halo"):
    for _method in ("brdf_angles", "render_grid"):
        EXEMPT[(f"sbrdf_xr.brdf.{_model_name}.{_method}", "psi")] = "an isotropic model refuses psi"

#: The compiled layer: its functions take the grids and angles that the layers above
#: (materials.tables, engine) have converted; a Quantity never reaches them.
KERNELS = "sbrdf_xr.kernels."


_POMENIS40 = (
    __import__("pathlib").Path(__file__).parent
    / "observing/data/pomenis/pomenis_observations_first40.csv"
)


def _pomenis_site() -> Any:
    from sbrdf_xr.observing.tracking_io import POMENIS_SITE

    return POMENIS_SITE


def _l_body() -> Any:
    from sbrdf_xr.testing import l_shaped_spacecraft

    return l_shaped_spacecraft()


@functools.cache
def _merl_file() -> Any:
    """A MERL file of a constant BRDF (0.1, 0.2, 0.3 sr-1), written once per session."""
    import tempfile
    from pathlib import Path

    from sbrdf_xr.materials.merl import write_merl

    path = Path(tempfile.mkdtemp(prefix="sbrdf-merl-")) / "grey.binary"
    return write_merl(path, lambda s, o: np.tile([0.3, 0.2, 0.1], (len(s), 1)))


def _grey_rgl(s: np.ndarray, o: np.ndarray) -> np.ndarray:
    return np.full((len(s), 1), 0.1)


@functools.cache
def _rgl_file() -> Any:
    """An RGL file of a constant BRDF (0.1 sr-1 at 500 nm), written once per session."""
    import tempfile
    from pathlib import Path

    from sbrdf_xr.materials.rgl import write_rgl

    path = Path(tempfile.mkdtemp(prefix="sbrdf-rgl-")) / "grey.bsdf"
    return write_rgl(path, _grey_rgl, wavelengths=[500.0], theta_i=[0.0, 40.0, 80.0],
                     resolution=8, ndf_resolution=8)  # fmt: skip


def _measurements(theta_i: tuple[float, ...] = (20.0, 50.0)) -> xr.Dataset:
    from sbrdf_xr.testing import make_measurements

    return make_measurements(n_wavelength=2, theta_i=theta_i)


def _aniso_table() -> xr.DataArray:
    from sbrdf_xr.materials.models import render_anisotropic

    return render_anisotropic(
        _aniso_spec(), [20.0, 40.0], [-10.0, 10.0], [0.0, 20.0], [0.0, 90.0, 180.0]
    )


def _moon_inputs() -> dict[str, Any]:
    t = np.array(["2022-11-08T07:59", "2022-11-08T08:59"], dtype="datetime64[ns]")
    r = np.array([[7000.0, 0.0, 0.0], [6990.0, 300.0, 0.0]])
    return dict(
        times=t,
        position=r,
        velocity=np.array([[0.0, 7.5, 0.0]] * 2),
        sun=np.array([[1.4e8, 5e7, 0.0]] * 2) - r,
    )


def _shadow_inputs() -> dict[str, Any]:
    t = T0 + np.arange(0, 121, 10) * np.timedelta64(1, "s")
    phase = 1.95 + 2 * np.pi / 5900.0 * np.arange(0, 121, 10)
    pos = 7000.0 * np.stack([np.cos(phase), np.sin(phase), 0 * phase], axis=1)
    return dict(
        times=t,
        position=pos,
        sun=np.array([1.5e8, 0.0, 0.0]) - pos,
        earth="sphere",
        earth_radius=6378.137,
        sun_radius=695700.0,
    )


def _observation_fields() -> list[Any]:
    return [f for f in dataclasses.fields(_observation()) if f.init and f.name != "min_elevation"]


def _observation_cube() -> xr.Dataset:
    from sbrdf_xr import Scene, simulate

    obs = _observation()
    return simulate(Scene(_box(), {"grey": _grey_wide()}, observation=obs)).compute()


def _recovery_inputs() -> dict[str, Any]:
    from sbrdf_xr.body.spacecraft import canx1
    from sbrdf_xr.observing.observe import canx1_pass

    obs = canx1_pass()
    return dict(
        spacecraft=canx1(),
        observation=obs,
        periods=np.linspace(85.0, 95.0, 5),
        times=obs.times[100:120],
        n_draws=1,
        n_axes=12,
        n_phases=8,
        n_starts=1,
        axis_tolerance=1.0,
        n_threads=1,
    )


_SPIN = {"axis_longitude": 60.0, "axis_latitude": 30.0, "period": 40.0, "phase": 20.0}


@functools.cache
def _joint_light_curve() -> tuple[Any, xr.Dataset]:
    from sbrdf_xr import Scene, simulate
    from sbrdf_xr.invert import axis_vector, spin_model
    from sbrdf_xr.observing import Observation
    from sbrdf_xr.observing.observe import canx1_pass
    from sbrdf_xr.photometry import magnitudes

    full = canx1_pass()
    spin = spin_model([0, 0, 1], axis_vector(60.0, 30.0), 40.0, 20.0)
    obs = Observation(full.orbit, full.site, full.times[60:120:4], spin)
    m = magnitudes(
        simulate(Scene(_box(), {"grey": _grey_wide()}, observation=obs)), ["V"], system="Vega"
    )
    lc = xr.Dataset(
        {"magnitude": ("obs", m.values.ravel()), "uncertainty": ("obs", np.full(m.size, 0.01))},
        coords={"time": ("obs", obs.times), "band": ("obs", ["V"] * m.size)},
        attrs={"magnitude_system": "Vega"},
    )
    return obs, lc


def _joint_inputs() -> dict[str, Any]:
    obs, lc = _joint_light_curve()
    return dict(
        light_curve=lc,
        spacecraft=_box(),
        observation=obs,
        spin=dict(_SPIN),
        materials={"grey": _grey_wide()},
    )


def _unmix_inputs() -> dict[str, Any]:
    wl = np.linspace(400.0, 1000.0, 7)
    paint = xr.DataArray(np.linspace(0.5, 0.2, 7), dims="wavelength", coords={"wavelength": wl})
    cell = xr.DataArray(np.linspace(0.1, 0.4, 7), dims="wavelength", coords={"wavelength": wl})
    truth = 0.8 * paint + 1.2 * cell + 1e-3 * np.sin(wl)
    return dict(
        measured=truth,
        simulated={"paint": paint, "cell": cell},
        uncertainty=1e-3,
        areas={"paint": 2.0, "cell": 3.0},
        total_area=5.0,
    )


def _sun() -> xr.DataArray:
    """A solar spectrum of the user's [W m-2 nm-1] over 300-1200 nm."""
    wl = np.arange(300.0, 1201.0, 5.0)
    e = 1.8 + 0.1 * np.sin(wl / 50.0)
    return xr.DataArray(e, dims="wavelength", coords={"wavelength": wl}, name="test-sun")


def _bench_rows() -> xr.Dataset:
    return xr.Dataset(
        {
            "time_ratio": ("case", [1.0, 0.35, 0.6]),
            "mmag_max": ("case", [0.0, 63.0, 0.002]),
            "mmag_median": ("case", [0.0, 0.55, 0.0003]),
            "sweep": ("case", ["demo"] * 3),
            "baseline": ("case", ["reference"] * 3),
        },
        coords={"case": ["reference", "lookup: linear", "precision: float32"]},
    )


def _solar() -> xr.DataArray:
    from sbrdf_xr.photometry.spectra import solar_spectrum

    return solar_spectrum(np.arange(400.0, 800.0, 1.0))


def _mags() -> xr.DataArray:
    from sbrdf_xr.photometry import magnitudes

    return magnitudes(_cube(), ["V"], range=2000.0)


#: Cases whose comparison is long (a fit or a simulation): ``-m slow`` runs it; the
#: refusal of a wrong unit, at the door, always runs.
SLOW = {
    "sbrdf_xr.invert._joint.fit.fit_observation",
    "sbrdf_xr.invert._joint.study.observation_recovery",
    "sbrdf_xr.invert._spin.fit.fit_spin",
    "sbrdf_xr.invert._studies.spin_recovery",
    "sbrdf_xr.plot.cube.cube_figure",
    "sbrdf_xr.plot.cube.rotation_figure",
    "sbrdf_xr.observing.passes.visible_passes",
    "sbrdf_xr.plot.cube.observation_figure",
}
#: Cases whose result is a figure or a timing: the Quantity must be accepted, the
#: results are not compared.
NOT_COMPARED = {
    "sbrdf_xr.body.picture.plot_facets",
    "sbrdf_xr.plot.curves.lut_slice",
    "sbrdf_xr.body.spacecraft.Spacecraft.plot",
    "sbrdf_xr.plot.cube.cube_figure",
    "sbrdf_xr.plot.cube.rotation_figure",
    "sbrdf_xr.plot.cube.observation_figure",
    "sbrdf_xr.plot.front.accuracy_front",
}

#: What of a result is compared (a study's wall times are not; a function's values are).
POST = {
    "sbrdf_xr.observing.ephemeris.Ephemeris.from_states": lambda e: e.state(_T2),
    "sbrdf_xr.invert._studies.spin_recovery": lambda ds: ds.drop_vars("seconds"),
    "sbrdf_xr.invert._joint.study.observation_recovery": lambda ds: ds.drop_vars(
        ["seconds_per_fit", "simulate_seconds", "fit_to_simulate"]
    ),
    "sbrdf_xr.materials.models.spectrum_function": lambda f: f(*np.array([[30.0], [0.0], [5.0]])),
}

#: The same quantity in another unit than the documented one (the case's conversion).
OTHER = {
    "nm": u.um,
    "degree": u.rad,
    "deg": u.rad,
    "radian": u.deg,
    "rad": u.deg,
    "s": u.min,
    "km": u.m,
    "m": u.mm,
    "au": u.km,
    "AU": u.km,
    "K": u.deg_C,
    "hPa": u.Pa,
    "day": u.h,
    "byte": u.Unit("KiB"),
    "degree s-1": u.rad / u.s,
    "deg / s": u.rad / u.s,
    "km / s": u.m / u.s,
    "km s-1": u.m / u.s,
    "kg m-3": u.g / u.cm**3,
    "kg m2": u.g * u.cm**2,
    "m2": u.cm**2,
    "sr-1": u.deg**-2,
    "degree**3": u.rad**3,
    "W m-2 nm-1": u.mW / u.cm**2 / u.um,
    "W m-2": u.mW / u.cm**2,
    "mag": u.mmag,
    "mmag": u.mag,
}
#: Arguments whose value is a structure holding the number with a unit: its Quantity form.
FORMS: dict[str, Callable[[Any, Any], Any]] = {
    "spin": lambda value, unit: {
        k: np.float64(v) * u.Unit(unit)
        if unit.physical_type != "angle"
        else (np.float64(v) * (u.s if k == "period" else u.deg)).to(
            u.min if k == "period" else unit
        )
        for k, v in value.items()
    },
    "layers": lambda value, unit: [
        (n, (d * u.nm).to(unit) if unit.physical_type == "length" else d * unit) for n, d in value
    ],
}


def _quantity(arg: str, value: Any, doc_unit: str, unit: Any) -> Any:
    if arg in FORMS:
        return FORMS[arg](value, unit)
    if isinstance(value, xr.DataArray):  # a DataArray holding the Quantity
        return value.copy(data=_quantity(arg, value.values, doc_unit, unit))
    if isinstance(value, Mapping):  # one Quantity per key
        return {k: _quantity(arg, v, doc_unit, unit) for k, v in value.items()}
    q = np.asarray(value, dtype=np.float64) * u.Unit(doc_unit)
    if not q.unit.is_equivalent(unit, equivalencies=u.temperature()):
        return q.value * unit  # a Quantity of another kind
    return q.to(unit, equivalencies=u.temperature())


def _same(a: Any, b: Any, where: str = "result") -> None:
    """Equal to within float rounding of a unit conversion (rtol 1e-9)."""
    if isinstance(a, xr.Dataset | xr.DataArray):
        xr.testing.assert_allclose(a, b, rtol=1e-9, atol=0.0)
    elif isinstance(a, Mapping):
        assert set(a) == set(b), where
        for k in a:
            _same(a[k], b[k], f"{where}[{k!r}]")
    elif isinstance(a, tuple | list) and not all(isinstance(x, int | float | np.number) for x in a):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _same(x, y, f"{where}[{i}]")
    elif dataclasses.is_dataclass(a) and not isinstance(a, type):
        for f in dataclasses.fields(a):
            if f.compare:
                _same(getattr(a, f.name), getattr(b, f.name), f"{where}.{f.name}")
    elif isinstance(a, np.ndarray | float | int | np.number | list):
        arr = np.asarray(a)
        if arr.dtype.kind in "fciu":
            np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-300, err_msg=where)
        else:
            np.testing.assert_array_equal(a, b, err_msg=where)
    else:
        assert a == b, where


def _cases() -> list[Any]:
    out = []
    for (name, arg), unit in sorted(unit_arguments().items()):
        if name.startswith(KERNELS) or (name, arg) in EXEMPT:
            continue
        marks = [pytest.mark.slow] if name in SLOW else []
        out.append(pytest.param(name, arg, unit, marks=marks, id=f"{name[9:]}:{arg}"))
    return out


def test_every_unit_argument_has_a_case():
    found = unit_arguments()
    missing = sorted(
        f"{name}({arg}) [{unit}]"
        for (name, arg), unit in found.items()
        if not name.startswith(KERNELS) and (name, arg) not in EXEMPT and name not in CASES
    )
    assert not missing, f"arguments with a unit without a case in CASES: {missing}"
    stale = sorted(set(CASES) - {name for name, _ in found}) + sorted(set(EXEMPT) - set(found))
    assert not stale, f"cases of no argument with a unit: {stale}"


def _call(name: str, kwargs: dict[str, Any]) -> Any:
    import matplotlib

    matplotlib.use("Agg")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return public_callables()[name](**kwargs)


@pytest.mark.parametrize(("name", "arg", "unit"), _cases())
def test_a_quantity_is_converted(name, arg, unit):
    kwargs = CASES[name]()
    bare = _call(name, kwargs)
    given = _call(name, {**kwargs, arg: _quantity(arg, kwargs[arg], unit, OTHER[unit])})
    if name not in NOT_COMPARED:
        keep = POST.get(name, lambda r: r)
        _same(keep(given), keep(bare))
    if name == "sbrdf_xr.plot.cube.cube_figure" or "figure" in name or "plot" in name:
        import matplotlib.pyplot as plt

        plt.close("all")


@pytest.mark.parametrize(
    ("name", "arg", "unit"), [pytest.param(*p.values, id=p.id) for p in _cases()]
)
def test_a_quantity_of_another_kind_is_refused_by_name(name, arg, unit):
    kwargs = CASES[name]()
    with pytest.raises(UnitError, match=rf"\b{re.escape(arg)}\b"):
        wrong = _quantity(arg, kwargs[arg], unit, u.Unit(unit) * u.kg)
        _call(name, {**kwargs, arg: wrong})


def test_a_dataarray_holding_a_quantity_is_converted():
    """xarray keeps a Quantity as a DataArray's data: converted too, never read as bare."""
    from sbrdf_xr.materials.tables import lookup
    from sbrdf_xr.photometry import band_weights

    table, ti = _table(), np.array([25.0, 42.0])
    angles = xr.DataArray(np.radians(ti) * u.rad, dims="x")
    _same(lookup(table, angles, 3.0, 4.0), lookup(table, xr.DataArray(ti, dims="x"), 3.0, 4.0))
    wl = np.arange(400.0, 1101.0, 10.0)
    in_um = xr.DataArray(wl / 1e3 * u.um, dims="wavelength")
    a, b = band_weights(["V"], in_um).values, band_weights(["V"], wl).values
    # 0.7 um is 700.0000000000001 nm, where the V curve ends: a weight 1e-16 of the largest
    np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-12 * b.max())
    with pytest.raises(UnitError, match="theta_i"):
        lookup(table, xr.DataArray(ti * u.s, dims="x"), 3.0, 4.0)


def test_a_material_table_holding_a_quantity_is_converted():
    """A table whose data is an sBRDF Quantity (in 1 / deg2) is that table in sr-1, in a
    look-up and in a simulation; a table of another kind is refused by name."""
    from sbrdf_xr import Scene, simulate
    from sbrdf_xr.materials.tables import lookup

    table = _grey()
    in_deg2 = table.copy(data=(table.values / u.sr).to(u.deg**-2))
    in_deg2.attrs.pop("units")  # the Quantity states it
    angles = ([25.0, 60.0], [3.0, -20.0], [4.0, 30.0])
    _same(lookup(in_deg2, *angles), lookup(table, *angles))

    def run(t: xr.DataArray) -> xr.DataArray:
        scene = Scene(_box(), {"grey": t}, attitudes=[[0, 0, 0, 1.0]], phase_angles=[30.0, 70.0])
        return simulate(scene).signal

    _same(run(in_deg2), run(table))
    in_kg = table.copy(data=table.values * u.kg)
    with pytest.raises(UnitError, match=r"materials\['grey'\]"):
        run(in_kg)
    with pytest.raises(UnitError, match=r"\bmaterial\b"):
        lookup(in_kg, *angles)


# ------------------------------------------------------------------ one unit convention in names
#: Endings that name a unit.  The convention (docs/guide/conventions.md): an argument is
#: named for what it is (``range``, ``elevation``, ``step``), its unit stands in brackets
#: in its docstring and a Quantity in any unit of the kind is accepted at the door.
UNIT_ENDING = re.compile(
    r"_(deg|rad|arcsec|s|ms|min|h|days?|km|m|mm|cm|nm|um|au|hpa|pa|k|kg|kg_m3|m2|m3|sr|hz|"
    r"deg_s|rad_s|km_s|m_s|mag|bytes)$"
)
#: Arguments whose ending is not a unit, or whose unit cannot be a Quantity: the reason.
UNIT_ENDING_ALLOWED: dict[tuple[str, str], str] = {
    ("sbrdf_xr.brdf.microfacet.distribution_ggx", "cos2_h"): "h is the half vector, not hours",
    ("sbrdf_xr.brdf.microfacet.distribution_ggx", "sin2_h"): "h is the half vector, not hours",
    ("sbrdf_xr.materials.construction.paper_delta_theta_grid", "dt_min"): "the smallest step",
    ("sbrdf_xr.materials.goniometer.paper_scheme", "dt_min"): "the smallest step, not minutes",
    ("sbrdf_xr.invert._spin.fit.period_grid", "p_min"): "the shortest period, not minutes",
    ("sbrdf_xr.engine.plan.Estimate", "output_bytes"): "a count of bytes, a plain integer",
    ("sbrdf_xr.engine.plan.Estimate", "block_bytes"): "a count of bytes, a plain integer",
    ("sbrdf_xr.engine.scene.Scene", "block_bytes"): "a count of bytes, a plain integer",
    ("sbrdf_xr.materials.models.render", "max_bytes"): "a count of bytes, a plain integer",
}


def unit_endings() -> set[tuple[str, str]]:
    """(callable, argument) for every public argument whose name ends in a unit."""
    out = set()
    for name, obj in public_callables().items():
        try:
            sig = inspect.signature(obj)
        except (TypeError, ValueError):
            continue
        out |= {(name, arg) for arg in sig.parameters if UNIT_ENDING.search(arg)}
    return out


def test_the_unit_ending_rule_sees_units_and_spares_words():
    assert all(UNIT_ENDING.search(a) for a in ("range_km", "step_s", "rate_deg_s", "size_bytes"))
    assert not any(UNIT_ENDING.search(a) for a in ("range", "phase_angle", "n_axes", "is_sim"))


def test_no_public_argument_name_ends_in_a_unit():
    found = unit_endings()
    listed = set(UNIT_ENDING_ALLOWED)
    new = sorted(found - listed)
    assert not new, (
        "arguments named with a unit (name them bare, give the unit in brackets in the "
        f"docstring and take a Quantity; see docs/guide/conventions.md): {new}"
    )
    stale = sorted(listed - found)
    assert not stale, f"allowed unit endings that no longer exist: {stale}"
