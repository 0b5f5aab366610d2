"""Materials: spectral BRDF look-up tables and the models and measurements they come from.

A material is a labelled :class:`xarray.DataArray` over ``(theta_i, delta_theta, phi,
wavelength)`` (paper 000 §3.1) or a model parameter set (paper 001 §4).

Angles are in degree, wavelengths (and layer thicknesses) in nm.  Every such argument
of the functions of this package also takes an astropy Quantity, converted first (a
wavelength also from a frequency or wavenumber); one of another kind raises
:class:`~sbrdf_xr.errors.UnitError` naming the argument (:func:`sbrdf_xr.units.to_unit`).

Modules
-------
``schema``
    The table and measurement-set schema (:func:`new_material`, :func:`validate_material`).
``construction`` and ``build``
    The table construction from sparse measurements of paper 000 §3.2 (:func:`build_lut`).
``tables``
    Look-up (:func:`lookup`), anisotropic tables and the material front end.
``energy``
    The directional-hemispherical reflectance of a table.
``cache``
    The disk cache of tables built on load from their measurements, keyed by their inputs
    and the sources of the code that builds them.
``mapped``
    The cached tables memory-mapped from values files beside them: one copy in memory
    for every process and Dask worker, handed to workers as handles.
``files``
    Lossless, atomic netCDF files of tables and measurement sets.
``model_schema`` and ``models``
    Analytic materials as labelled parameter sets: evaluate, render to a table, measure.
``optical``
    Real materials from measured optical constants (refractiveindex.info): bare metals,
    Kapton MLI, optical solar reflectors, a covered GaAs cell (:func:`optical_material`).
``goniometer``
    A virtual goniospectrometer sampling any material with the scheme of paper 000.
``readers``, ``merl`` and ``rgl``
    Measurement files as laboratories deliver them (:func:`read_measurements`): long
    tables, in-plane scans, MERL ``.binary``, RGL ``.bsdf`` spectral tensor files.
``coverage`` and ``selfcheck``
    Angles grouped with a tolerance, scan layouts and model fills; every build checked
    against its own samples.
"""

from ..errors import NonPhysicalWarning, ValidationError
from . import (
    build,
    cache,
    construction,
    coverage,
    energy,
    files,
    goniometer,
    mapped,
    merl,
    model_schema,
    models,
    optical,
    readers,
    rgl,
    schema,
    selfcheck,
    tables,
)
from .build import BELOW_NOISE, EXTRAPOLATIONS, RENORMALISE, build_lut
from .construction import paper_delta_theta_grid, paper_phi_grid
from .energy import ENERGY_TOL, hemispherical_reflectance
from .files import open_material, open_measurements, write_netcdf_atomic
from .goniometer import PAPER_THETA_I, paper_scheme, scheme_extents
from .model_schema import ModelParameters, model_material, model_parameters, open_model
from .models import (
    fit_robertson_sandford,
    render,
    render_anisotropic,
    render_values,
    spectra,
    spectrum_function,
)
from .optical import OPTICAL_MATERIALS, optical_material
from .readers import READERS, Reader, read_measurements, register_reader
from .schema import (
    DUPLICATES,
    SOURCES,
    average_duplicates,
    check_coord,
    constant_material,
    lambertian,
    new_material,
    reference_mask,
    validate_material,
    validate_measurements,
)
from .tables import (
    LOOKUP_METHODS,
    build_lut_anisotropic,
    lookup,
    lookup_anisotropic,
    sample_rotation,
)

__all__ = [
    "BELOW_NOISE",
    "DUPLICATES",
    "ENERGY_TOL",
    "EXTRAPOLATIONS",
    "LOOKUP_METHODS",
    "OPTICAL_MATERIALS",
    "PAPER_THETA_I",
    "READERS",
    "RENORMALISE",
    "SOURCES",
    "ModelParameters",
    "NonPhysicalWarning",
    "Reader",
    "ValidationError",
    "average_duplicates",
    "build",
    "build_lut",
    "build_lut_anisotropic",
    "cache",
    "check_coord",
    "constant_material",
    "construction",
    "coverage",
    "energy",
    "files",
    "fit_robertson_sandford",
    "goniometer",
    "hemispherical_reflectance",
    "lambertian",
    "lookup",
    "lookup_anisotropic",
    "mapped",
    "merl",
    "model_material",
    "model_parameters",
    "model_schema",
    "models",
    "new_material",
    "open_material",
    "open_measurements",
    "open_model",
    "optical",
    "optical_material",
    "paper_delta_theta_grid",
    "paper_phi_grid",
    "paper_scheme",
    "read_measurements",
    "readers",
    "reference_mask",
    "register_reader",
    "render",
    "render_anisotropic",
    "render_values",
    "rgl",
    "sample_rotation",
    "schema",
    "scheme_extents",
    "selfcheck",
    "spectra",
    "spectrum_function",
    "tables",
    "validate_material",
    "validate_measurements",
    "write_netcdf_atomic",
]
