"""The package version, dimension names, units and the attribute table of every variable
the package emits.

Names are defined here once and imported everywhere else; attributes of output
variables come from :data:`ATTRS` so that every array that leaves the package
carries CF-style ``units`` and ``long_name``.
"""

from __future__ import annotations

from typing import Any

#: The package version (read by hatch; re-exported as ``sbrdf_xr.__version__``).
__version__ = "0.1.0"

# --- dimensions -----------------------------------------------------------
THETA_I = "theta_i"
DELTA_THETA = "delta_theta"
PHI = "phi"
#: Azimuth of the illumination plane from a facet tangent (anisotropic materials).
PSI = "psi"
WAVELENGTH = "wavelength"
ATTITUDE = "attitude"
PHASE_ANGLE = "phase_angle"
BAND = "band"
SAMPLE = "sample"
FACET = "facet"
MATERIAL = "material"
GEOMETRY = "geometry"
VECTOR = "xyz"

#: Dimensions of a material sBRDF look-up table, in order.
LUT_DIMS: tuple[str, str, str, str] = (THETA_I, DELTA_THETA, PHI, WAVELENGTH)
#: Angular dimensions of a look-up table, in order.
ANGLE_DIMS: tuple[str, str, str] = (THETA_I, DELTA_THETA, PHI)
#: Dimensions of an anisotropic material table, in order (``psi`` before the spectrum,
#: so that every ``psi`` slice is an isotropic table).
ANISO_LUT_DIMS: tuple[str, str, str, str, str] = (THETA_I, DELTA_THETA, PHI, PSI, WAVELENGTH)

#: Name of the DataArray holding a material's sBRDF.
SBRDF = "sbrdf"
#: Name of the measured spectra in a measurement set (not ``sbrdf``: ``ds.sbrdf`` is the
#: Dataset accessor).
MEASURED = "measured_sbrdf"

# --- units (UDUNITS strings) ---------------------------------------------
DEGREE = "degree"
NM = "nm"
PER_SR = "sr-1"

#: Attribute table: variable or coordinate name -> CF attributes.
ATTRS: dict[str, dict[str, str]] = {
    THETA_I: {"units": DEGREE, "long_name": "illumination polar angle from the facet normal"},
    DELTA_THETA: {
        "units": DEGREE,
        "long_name": "difference-in-polar angle from the specular direction (signed)",
    },
    PHI: {
        "units": DEGREE,
        "long_name": "angle of the reflection direction from the illumination plane",
    },
    PSI: {"units": DEGREE, "long_name": "azimuth of the illumination plane from the facet tangent"},
    WAVELENGTH: {
        "units": NM,
        "long_name": "vacuum wavelength",
        "standard_name": "radiation_wavelength",
    },
    SBRDF: {
        "units": PER_SR,
        "long_name": "spectral bidirectional reflectance distribution function",
    },
    MEASURED: {
        "units": PER_SR,
        "long_name": "measured spectral bidirectional reflectance distribution function",
    },
    "theta_r": {"units": DEGREE, "long_name": "reflection polar angle from the facet normal"},
    "phi_i": {"units": DEGREE, "long_name": "illumination azimuth angle"},
    "phi_r": {"units": DEGREE, "long_name": "reflection azimuth angle"},
    PHASE_ANGLE: {"units": DEGREE, "long_name": "angle between the Sun and observer directions"},
    "reference": {
        "units": "1",
        "long_name": "reference point where the reflectance is indistinguishable from noise (zero)",
    },
    "reflectance": {
        "units": "1",
        "long_name": "directional-hemispherical reflectance",
    },
    # --- spacecraft facets and visibility (issue 4) ---
    FACET: {"units": "1", "long_name": "facet index"},
    VECTOR: {"units": "1", "long_name": "Cartesian component in the spacecraft body frame"},
    "normal": {"units": "1", "long_name": "outward unit normal of the facet in the body frame"},
    "area": {"units": "m2", "long_name": "facet area"},
    "centroid": {"units": "m", "long_name": "facet centroid in the body frame"},
    MATERIAL: {"units": "1", "long_name": "material name"},
    "term": {"units": "1", "long_name": "index of a group of facets sharing normal and material"},
    "n_facets": {"units": "1", "long_name": "number of facets merged into the term"},
    "tangent": {
        "units": "1",
        "long_name": (
            "unit facet tangent in the body frame (anisotropic materials' alpha_x direction)"
        ),
    },
    "facet_term": {"units": "1", "long_name": "term that each facet is merged into"},
    "lit_fraction": {
        "units": "1",
        "long_name": "fraction of the facet area from which the Sun is seen (not self-shadowed)",
    },
    "visible_fraction": {
        "units": "1",
        "long_name": "fraction of the facet area seen by the observer (not self-occluded)",
    },
    "lit_visible_fraction": {
        "units": "1",
        "long_name": "fraction of the facet area both lit by the Sun and seen by the observer",
    },
    "to_sun": {"units": "1", "long_name": "unit vector toward the Sun in the body frame"},
    "to_observer": {"units": "1", "long_name": "unit vector toward the observer in the body frame"},
    # --- photometry (issue 6) ---
    BAND: {"units": "1", "long_name": "photometric filter band"},
    "filter": {"units": "1", "long_name": "filter curve (speclite name, or user:<label>)"},
    "filter_source": {"units": "1", "long_name": "file and reference of the filter curve"},
    "filter_response": {"units": "1", "long_name": "filter response"},
    "solar_irradiance": {
        "units": "W m-2 nm-1",
        "long_name": "extraterrestrial solar spectral irradiance at 1 AU",
    },
    "band_weight": {
        "units": "1",
        "long_name": (
            "band-integration weight "
            "(solar spectrum x filter x spectral weighting x quadrature weight)"
        ),
    },
    "band_signal": {
        "units": "m2 sr-1",
        "long_name": "solar-weighted band mean of the radiometric signal",
    },
    # Magnitudes are dimensionless (UDUNITS has no "mag"): units "1", the system in the
    # attribute magnitude_system.
    "sun_magnitude": {"units": "1", "long_name": "apparent magnitude of the Sun at 1 AU"},
    "magnitude": {"units": "1", "long_name": "apparent magnitude of the reflected sunlight"},
    "magnitude_uncertainty": {"units": "1", "long_name": "1-sigma magnitude uncertainty"},
    "colour": {"units": "1", "long_name": "colour index (band pair)"},
    "colour_index": {"units": "1", "long_name": "colour index, difference of two band magnitudes"},
    "vega_flux": {"units": "W m-2 nm-1", "long_name": "spectral flux density of alpha Lyr (Vega)"},
    "airmass": {"units": "1", "long_name": "relative optical air mass"},
    "elevation": {
        "units": DEGREE,
        "long_name": "apparent elevation of the object above the horizon",
    },
    "transmission": {"units": "1", "long_name": "atmospheric transmission"},
    "extinction_coefficient": {
        "units": "1",
        "long_name": "atmospheric extinction coefficient (magnitudes per unit air mass)",
    },
    "range": {"units": "km", "long_name": "observer-object range"},
    "time": {"long_name": "time (UTC)", "standard_name": "time"},
    "srgb": {
        "units": "1",
        "long_name": "sRGB swatch of the reflected sunlight (display-normalised)",
    },
    "obs": {"units": "1", "long_name": "observation index"},
    "rotation_angle": {"units": DEGREE, "long_name": "body rotation angle"},
    # --- observations (sbrdf_xr.observing.observation) ---
    "to_earth": {
        "units": "1",
        "long_name": "unit vector toward the Earth's centre in the body frame",
    },
    "azimuth": {
        "units": "degree",
        "long_name": "azimuth of the spacecraft from north through east",
    },
    "solar_elongation": {
        "units": "degree",
        "long_name": "angle between the Sun and the spacecraft seen by the observer",
    },
    "sun_distance": {"units": "au", "long_name": "distance from the spacecraft to the Sun"},
    "sunlit_fraction": {
        "units": "1",
        "long_name": "fraction of the solar disc seen from the spacecraft not hidden by the Earth",
    },
    "earth_distance": {
        "units": "km",
        "long_name": "distance from the spacecraft to the Earth's centre",
    },
    "earth_phase_angle": {
        "units": "degree",
        "long_name": "Sun-Earth-spacecraft angle seen from the Earth's centre",
    },
    "site_sun_elevation": {
        "units": "degree",
        "long_name": "elevation of the Sun above the observer's horizon",
    },
    # --- simulation cubes ---
    ATTITUDE: {"units": "1", "long_name": "attitude index"},
    "attitude_angle": {"units": DEGREE, "long_name": "rotation angle of the attitude sweep"},
    "quaternion": {
        "units": "1",
        "long_name": "attitude quaternion, body to reference frame, scalar last (x, y, z, w)",
    },
    "component": {"units": "1", "long_name": "quaternion component (scalar last)"},
    GEOMETRY: {"units": "1", "long_name": "geometry index"},
    "time_since_first": {"units": "s", "long_name": "time since the first observation"},
}


def attrs(name: str, **extra: Any) -> dict[str, Any]:
    """Return a copy of the CF attributes of ``name``, updated with ``extra``.

    Parameters
    ----------
    name : str
        A key of :data:`ATTRS`.
    **extra
        Additional attributes that override or extend the table entry.

    Returns
    -------
    dict
        The attribute dictionary.
    """
    out = dict(ATTRS[name])
    out.update(extra)
    return out


#: Meanings of a boolean variable's two values, by variable name (CF flag_meanings).
FLAG_MEANINGS: dict[str, str] = {"reference": "measured_point reference_point"}


def cf_finish(ds: Any, *, history: str | None = None) -> Any:
    """A copy of ``ds`` with the CF/ACDD basics a file needs, before it is written.

    * global ``Conventions`` (CF-1.10), ``title`` (derived from the content when
      missing), ``source`` (the package and version when missing), ``history`` (one
      line appended: UTC time, package version, ``history`` or "written");
    * attribute names with characters other than letters, digits and ``_`` (e.g. a
      hyphen from a material name) rewritten with ``_`` (CF 2.3);
    * boolean variables get ``flag_values = [0, 1]`` and ``flag_meanings`` (CF 3.5);
    * a variable ``X`` with a standard uncertainty ``u_X`` (or ``uncertainty`` for
      ``magnitude``) names it in ``ancillary_variables`` (CF 3.4).
    """
    import re
    from datetime import UTC, datetime

    import numpy as np

    out = ds.copy()
    bad = re.compile(r"[^A-Za-z0-9_]")

    def clean(a: dict[str, Any]) -> dict[str, Any]:
        return {(bad.sub("_", k) if not k.startswith("_") else k): v for k, v in a.items()}

    out.attrs = clean(dict(out.attrs))
    for name in list(out.variables):
        var = out[name]
        var.attrs = clean(dict(var.attrs))
        if var.dtype == bool:
            var.attrs.setdefault("flag_values", np.array([0, 1], dtype=np.int8))
            var.attrs.setdefault("flag_meanings", FLAG_MEANINGS.get(str(name), "false true"))
        partner = (
            f"u_{name}"
            if f"u_{name}" in out.variables
            else (
                "uncertainty"
                if str(name) in ("magnitude", "measured_magnitude")
                and "uncertainty" in out.variables
                else None
            )
        )
        if partner is not None:
            have = str(var.attrs.get("ancillary_variables", "")).split()
            if partner not in have:
                var.attrs["ancillary_variables"] = " ".join([*have, partner])
    a = out.attrs
    a["Conventions"] = "CF-1.10"
    if not a.get("title"):
        who = a.get("material") or a.get("scene") or a.get("model") or ""
        kind = (
            "sBRDF table"
            if SBRDF in out
            else "sBRDF measurement set"
            if MEASURED in out
            else f"{a['model']} model parameters"
            if "model" in a
            else "sbrdf_xr dataset"
        )
        a["title"] = f"{kind} of {who}" if who else kind
    a.setdefault("source", f"sbrdf_xr {__version__}")
    stamp = datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
    line = f"{stamp} sbrdf_xr {__version__}: {history or 'written'}"
    a["history"] = f"{a['history']}\n{line}" if a.get("history") else line
    return out


# --- names of models and events shared by layers ----------------------------
#: Relative air-mass models (pvlib ``get_relative_airmass``): name -> description.
AIRMASS_MODELS: dict[str, str] = {
    "simple": "secant of the zenith angle (plane-parallel atmosphere)",
    "kasten1966": "Kasten 1966, CRREL Technical Report 136",
    "youngirvine1967": "Young & Irvine 1967, AJ 72, 945",
    "kastenyoung1989": "Kasten & Young 1989, Appl. Opt. 28, 4735 (default)",
    "gueymard1993": "Gueymard 1993, Sol. Energy 51, 121",
    "young1994": "Young 1994, Appl. Opt. 33, 1108",
    "pickering2002": "Pickering 2002, DIO 12, 3",
    "gueymard2003": "Gueymard 2003, Sol. Energy 74, 355",
}
#: Names of the Earth-shadow events of an observation, in the order of an eclipse.
SHADOW_EVENTS = ("penumbra_entry", "umbra_entry", "umbra_exit", "penumbra_exit")
