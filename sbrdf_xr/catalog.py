"""The catalogs that ship with sbrdf_xr: materials, measurement sets, paint parameters, spacecraft.

The catalog directory holds ``index.toml``, one ``[[entry]]`` table per item (its fields
are described in :mod:`sbrdf_xr._catalog_index`).

In a source checkout the directory is the top-level ``catalogs/``; an installed
package carries a copy at ``sbrdf_xr/catalogs`` (see ``pyproject.toml``).

The catalog sits above the domain modules: it imports them and maps every kind to
the function that builds its object from an entry (:data:`LOADERS`); none of them
imports it (they read an entry's file given the entry, from
:mod:`sbrdf_xr._catalog_index`).

User catalogs (directories named by ``SBRDF_XR_CATALOG_PATH``, see
:mod:`sbrdf_xr._catalog_index`) add entries; :func:`load_spacecraft_spec` and
:func:`load_material_spec` also accept a file where a name is expected (a mesh file, a
material table or model netCDF file).
"""

from __future__ import annotations

import contextlib
import functools
import os
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import AbstractContextManager
from pathlib import Path
from typing import Any

import numpy as np
import trimesh
import xarray as xr
from numpy.typing import DTypeLike

from ._catalog_index import (
    CATALOG_PATH_ENV,
    ENTRY_KINDS,
    CatalogEntry,
    catalog_dir,
    data_path,
    entries,
    entry,
    names,
    user_catalog_dirs,
)
from ._names import SBRDF, WAVELENGTH
from .body import spacecraft
from .errors import (
    CatalogError,
    ValidationError,
    did_you_mean,
    input_file,
    reading,
    renamed_attributes,
)
from .materials import models
from .materials import tables as material
from .materials.cache import cache_file, cached_table
from .materials.readers import read_measurements
from .materials.schema import SOURCES
from .materials.shipped import read_reflectance
from .observing import observe

__all__ = [
    "CATALOG_PATH_ENV",
    "ENTRY_KINDS",
    "LOADERS",
    "MATERIAL_SUFFIXES",
    "MESH_SUFFIXES",
    "SOURCES",
    "TABLE_DTYPES",
    "CatalogEntry",
    "catalog_dir",
    "data_path",
    "entries",
    "entry",
    "is_file_spec",
    "load",
    "load_material_spec",
    "load_materials",
    "load_spacecraft_spec",
    "material_tables",
    "names",
    "showing_progress",
    "table_cache_files",
    "to_build",
    "user_catalog_dirs",
]


#: The value types a material can be loaded in (:func:`load`'s ``dtype``).
TABLE_DTYPES: tuple[str, ...] = ("float32", "float64")


def _table_dtype(dtype: DTypeLike | None) -> str | None:
    """``dtype`` checked against :data:`TABLE_DTYPES`, by name (None stays None)."""
    if dtype is None:
        return None
    try:
        name = np.dtype(dtype).name
    except TypeError:
        name = repr(dtype)
    if name not in TABLE_DTYPES:
        raise CatalogError(
            f"dtype: got {dtype!r}; a material table loads as one of {', '.join(TABLE_DTYPES)}"
        )
    return name


def _load_material(e: CatalogEntry, dtype: str | None = None) -> xr.DataArray:
    """A table file, or (``build_from`` set) a table built from a measurement entry;
    its values in ``dtype`` (None: as stored)."""
    source = e.extra.get("build_from")
    if source is None:
        da = material.open_material(e.file, check_energy=False)  # checked when built
        return da if dtype is None else da.astype(dtype, copy=False)
    options = tuple(sorted(e.extra.get("build", {}).items()))
    # a new DataArray (its own attrs) over the one built table, whose values are read-only:
    # every load in a process shares them (a copy each would double the resident tables);
    # ``.copy()`` gives a writable table
    # built tables are float64: asking for it is asking for the one cached table
    da = _built_material(e.name, source, options, None if dtype == "float64" else dtype)
    da = da.copy(deep=False)
    return da if dtype is None or da.dtype == np.dtype(dtype) else da.astype(dtype)


@functools.lru_cache(maxsize=16)
def _built_material(
    name: str,
    measurements: str,
    options: tuple[tuple[str, Any], ...],
    dtype: str | None = None,
) -> xr.DataArray:
    """A table built from a measurement entry, through the disk cache
    (:mod:`sbrdf_xr.materials.cache`),
    its values in ``dtype`` (None: as built, float64).

    A table in another dtype is cast from the file's values, not from the float64 table
    cached here, so a process that asks only for float32 holds no float64 copy.
    """
    kw = dict(options)
    bar: list[Any] = []  # the progress bar of a build, if there is one

    def build() -> xr.DataArray:
        opts = dict(kw)
        meas = load(measurements)
        if "fit" in opts:  # a model entry that fills the unmeasurable range
            fit = entry(opts["fit"]).file
            opts["model"] = load(opts.pop("fit"))
            # its reflectance at the table's rows, shipped beside it while current
            ti = np.asarray(opts.get("theta_i", np.arange(0.0, 91.0)), dtype=np.float64)
            wl = np.asarray(meas[WAVELENGTH].values, dtype=np.float64)
            opts["model_reflectance"] = read_reflectance(fit, ti, wl)
        bar.append(_progress_bar(name))

        def report(fraction: float, step: str) -> None:
            bar[0].n = round(90.0 * fraction, 1)
            bar[0].set_postfix_str(step, refresh=False)
            bar[0].refresh()

        return material.build_lut(meas, material=name, progress=report, **opts)

    def write(da: xr.DataArray, path: Any) -> None:
        if bar:
            bar[0].set_postfix_str("writing the cache")
        material.to_netcdf(da, path, overwrite=True, complevel=0)  # fast to write and read

    def read(path: Any) -> xr.DataArray:
        da = material.open_material(path, check_energy=False)  # checked when built
        for k in _FILE_ATTRS:  # what writing a file adds, not what the build made
            da.attrs.pop(k, None)
        return da

    try:
        inputs = _table_inputs(measurements, kw)
        # memory-mapped from a values file beside the cache file: one copy for every process
        da = cached_table(name, inputs, repr(options), build, write, read, dtype or "float64")
    finally:
        if bar:
            bar[0].n = 100.0 if bar[0].n >= 90.0 else bar[0].n
            bar[0].set_postfix_str("done" if bar[0].n >= 100.0 else "failed")
            bar[0].close()
    _LOADED.add(name)
    if dtype is not None and da.dtype != np.dtype(dtype):
        da = da.astype(dtype)
    base: Any = da.values  # read-only through and through (also the array it views), so that
    while isinstance(base, np.ndarray):  # its fingerprint can be computed once and kept
        base.flags.writeable = False
        base = base.base
    return da


#: Attributes the netCDF writer adds to a file (CF/ACDD basics) that a built table lacks.
_FILE_ATTRS = ("title", "history")

#: Built tables this process has loaded (and will not build again).
_LOADED: set[str] = set()
#: The tables a batch load (:func:`material_tables`) will build, in order: for the labels
#: of their progress bars ("building table tjpv-cell (1 of 3)").
_BATCH: list[str] = []
#: Whether builds show their progress bars (:func:`showing_progress`).
_SHOW_PROGRESS = [True]


@contextlib.contextmanager
def showing_progress(show: bool) -> Iterator[None]:
    """Show (or, ``show=False``, hide) the progress bars of table builds while the block runs.

    The command line hides them with ``--quiet``.

    Examples
    --------
    >>> with showing_progress(False):
    ...     _SHOW_PROGRESS[0]
    False
    >>> _SHOW_PROGRESS[0]
    True
    """
    before = _SHOW_PROGRESS[0]
    _SHOW_PROGRESS[0] = bool(show)
    try:
        yield
    finally:
        _SHOW_PROGRESS[0] = before


def _table_inputs(measurements: str, kw: Mapping[str, Any]) -> list[Path]:
    """The files a built table depends on: its measurement set and its fit's model."""
    return [entry(measurements).file] + ([entry(kw["fit"]).file] if "fit" in kw else [])


def _progress_bar(name: str) -> Any:
    """A progress bar of the build of table ``name`` (tqdm.auto: a widget in Jupyter),
    labelled with its place in the batch being built."""
    from tqdm.auto import tqdm

    label = f"building table {name}"
    if name in _BATCH:
        label += f" ({_BATCH.index(name) + 1} of {len(_BATCH)})"
    return tqdm(
        total=100.0,
        desc=label,
        bar_format="{desc}: {percentage:3.0f}%|{bar}| {elapsed}<{remaining}{postfix}",
        leave=True,
        disable=not _SHOW_PROGRESS[0],
    )


def to_build(wanted: Iterable[str]) -> list[str]:
    """The built tables among catalog entries ``names`` that loading them would build.

    A material with ``build_from`` in its entry is built from its measurements on its
    first load and then read from the table cache (:mod:`sbrdf_xr.materials.cache`); these are
    the ones neither in the cache nor loaded in this process (with the cache switched off,
    every one not loaded yet).

    Parameters
    ----------
    wanted : iterable of str
        Catalog names (other kinds and unknown names are skipped).

    Returns
    -------
    list of str
        In the order given, without repeats.

    Examples
    --------
    >>> to_build(["lambertian-grey-50", "canx1", "no-such-entry"])  # nothing to build
    []
    """
    out = []
    known = names()
    for name in dict.fromkeys(wanted):
        if name not in known or name in _LOADED:
            continue
        e = entry(name)
        if e.kind != "material" or e.extra.get("build_from") is None:
            continue
        path = _cache_path(e)
        if path is None or not path.is_file():
            out.append(name)
    return out


def _cache_path(e: CatalogEntry) -> Path | None:
    """The table-cache file of built material entry ``e`` (None: the cache is off), keyed
    as :func:`_built_material` keys it."""
    kw = dict(e.extra.get("build", {}))
    options = tuple(sorted(kw.items()))
    return cache_file(e.name, _table_inputs(e.extra["build_from"], kw), repr(options))


def table_cache_files() -> list[Path]:
    """The table-cache files this installation loads its built materials from.

    Every ``material`` entry with ``build_from`` (shipped, and of the user catalogs of
    ``SBRDF_XR_CATALOG_PATH``) is built on its first load and kept in the table cache
    (:mod:`sbrdf_xr.materials.cache`) under a key of its files, its options and the
    code that builds it: these are the files of those keys, whether built yet or not.
    The other entries of the cache are stale for this installation
    (:func:`sbrdf_xr.materials.cache.prune`); an entry whose files cannot be read is
    left out.

    Returns
    -------
    list of pathlib.Path
        Empty when the cache is switched off.

    Examples
    --------
    >>> files = table_cache_files()
    >>> any(f.name.startswith("tjpv-cell-") for f in files), files[0].suffix
    (True, '.nc')
    """
    out = []
    for e in entries("material"):
        if e.extra.get("build_from") is None:
            continue
        try:
            path = _cache_path(e)
        except (OSError, CatalogError):  # its measurements or fit missing: never loads
            continue
        if path is not None:
            out.append(path)
    return out


def load_materials(
    wanted: Iterable[str],
    dtype: DTypeLike | None = None,
    while_building: Callable[[str, bool], AbstractContextManager[object]] | None = None,
) -> dict[str, Any]:
    """Load several material entries, the tables to build labelled as one batch.

    Every table that has to be built shows a progress bar "building table NAME (k of
    n)" (:func:`to_build`); loading from the cache shows nothing.  While tables build,
    the context ``while_building(dtype, progress)`` is held: the engine compiles its
    kernel for them in a second process meanwhile
    (:func:`sbrdf_xr.kernels.warm.compiling_ahead`), so that the first simulation finds
    it in numba's cache; the call returns when both are done.

    Parameters
    ----------
    wanted : iterable of str
        Names of ``material`` entries.
    dtype : {None, "float32", "float64"}, optional
        As :func:`load`.
    while_building : callable, optional
        Called with the tables' dtype name and whether progress bars show, when a table
        is to be built; returns a context manager held while they build.

    Returns
    -------
    dict of str to xarray.DataArray

    Examples
    --------
    >>> tables = load_materials(["lambertian-grey-50"], dtype="float32")
    >>> {k: v.dtype.name for k, v in tables.items()}
    {'lambertian-grey-50': 'float32'}
    """
    wanted = list(dict.fromkeys(wanted))
    building = to_build(wanted)
    meanwhile: AbstractContextManager[object] = contextlib.nullcontext()
    if building and while_building is not None:
        meanwhile = while_building(_table_dtype(dtype) or "float64", _SHOW_PROGRESS[0])
    with meanwhile, _batch(building):
        return {name: load(name, dtype=dtype) for name in wanted}


@contextlib.contextmanager
def _batch(names: list[str]) -> Iterator[None]:
    """Label the builds of ``names`` as one batch while the block runs."""
    _BATCH[:] = names
    try:
        yield
    finally:
        _BATCH.clear()


def _load_paint_parameters(e: CatalogEntry) -> xr.Dataset:
    with xr.open_dataset(e.file, engine="netcdf4") as ds:
        return ds.load()


#: Loader per kind: takes the entry, returns the loaded object.
LOADERS: dict[str, Callable[[CatalogEntry], Any]] = {
    "material": _load_material,
    "measurements": lambda e: read_measurements(e.file, **e.extra.get("read", {})),
    "model": lambda e: models.open_model(e.file),
    "paint_parameters": _load_paint_parameters,
    "spacecraft": spacecraft.load_catalog_entry,
    "orbit": observe.load_orbit_entry,
    "site": observe.load_site_entry,
}
assert set(LOADERS) == set(ENTRY_KINDS)


def load(name: str, dtype: DTypeLike | None = None) -> Any:
    """Load a catalog entry by name.

    Parameters
    ----------
    name : str
        Entry name (see :func:`names` or ``sbrdf-xr catalog list``).
    dtype : {None, "float32", "float64"}, optional
        For a ``material`` only: its values in this dtype.  ``float32`` holds half the
        memory of the stored float64 table (a scene in float32 loads its tables so, and
        its plan then reads them without a copy); None keeps the stored dtype.

    Returns
    -------
    object
        A material ``DataArray`` for ``material``; a measurement ``Dataset`` for
        ``measurements``; a parameter ``Dataset`` for ``model`` (see
        :mod:`sbrdf_xr.materials.models`) and ``paint_parameters``; a
        :class:`~sbrdf_xr.body.spacecraft.Spacecraft` for ``spacecraft``; an
        :class:`~sbrdf_xr.observing.observe.Orbit` for ``orbit``; a
        :class:`~sbrdf_xr.observing.observe.Site`
        for ``site``.  A material built from measurements on load shares its values
        with every other load of it in the process: they are read-only (``.copy()``
        gives a writable table); its attributes are each load's own.

    Examples
    --------
    A shipped table: an ideal Lambertian grey of albedo 0.5, ``f_r = 0.5 / pi``:

    >>> from sbrdf_xr import catalog
    >>> grey = catalog.load("lambertian-grey-50")
    >>> grey.dims
    ('theta_i', 'delta_theta', 'phi', 'wavelength')
    >>> grey.attrs["source"], round(float(grey.max()), 6), round(float(grey.min()), 6)
    ('synthetic', 0.159155, 0.159155)

    A spacecraft and an observing site:

    >>> catalog.load("canx1")  # doctest: +ELLIPSIS
    <Spacecraft 'canx1': 684 facets, materials ['aluminium-6061-t6', 'tjpv-cell', ...] m>
    >>> catalog.load("mont-megantic").latitude
    45.4555

    The grey table in float32, as a scene with ``dtype="float32"`` loads it:

    >>> catalog.load("lambertian-grey-50", dtype="float32").dtype
    dtype('float32')
    >>> catalog.load("canx1", dtype="float32")
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.CatalogError: dtype: 'canx1' is a spacecraft entry; only a material ...
    """
    e = entry(name)
    dt = _table_dtype(dtype)
    if dt is not None:
        if e.kind != "material":
            raise CatalogError(
                f"dtype: {name!r} is a {e.kind} entry; only a material loads in a chosen dtype"
            )
        return _load_material(e, dt)
    try:
        loader = LOADERS[e.kind]
    except KeyError:  # pragma: no cover - every kind has a loader (asserted above)
        raise CatalogError(f"no loader for catalog kind {e.kind!r}") from None
    return loader(e)


# --------------------------------------------------------------------------- names or files

#: Suffixes of a material file: a material table or a model, in netCDF.
MATERIAL_SUFFIXES: tuple[str, ...] = (".nc", ".nc4", ".netcdf")

#: Suffixes of a mesh file: the mesh formats :mod:`trimesh` reads here.
MESH_SUFFIXES: tuple[str, ...] = tuple(
    sorted(
        "." + f
        for f in trimesh.available_formats()
        if f.isalnum() and f not in ("zip", "bz2", "xyz")  # archives, point clouds
    )
)


def is_file_spec(spec: str | os.PathLike[str]) -> bool:
    """Whether ``spec`` names a file rather than a catalog entry.

    A path object always names a file; a string names a catalog entry if there is one
    of that name, and otherwise a file if it holds a path separator or ends in a
    suffix (``.stl``, ``.nc``, ...).  Catalog names have neither.

    Parameters
    ----------
    spec : str or os.PathLike
        A catalog name or a file path.

    Returns
    -------
    bool

    Examples
    --------
    >>> is_file_spec("lambertian-grey-50"), is_file_spec("box.stl"), is_file_spec("meshes/box")
    (False, True, True)
    """
    if not isinstance(spec, str):
        return True
    if spec in names():
        return False
    return "/" in spec or os.sep in spec or Path(spec).suffix != ""


def _entry_of(name: str, kinds: tuple[str, ...], what: str) -> CatalogEntry:
    """The entry ``name``; if there is none, a :class:`CatalogError` that suggests only the
    close names of ``kinds`` (a misspelt material is not offered a site)."""
    if name not in names():
        known = [n for kind in kinds for n in names(kind)]
        label = f"catalog {' and '.join(k if k == 'spacecraft' else k + 's' for k in kinds)}"
        raise CatalogError(
            f"{what}: no catalog entry named {name!r}; {did_you_mean(name, known, label)}"
        )
    return entry(name)


def _file_of(
    spec: str | os.PathLike[str],
    base_dir: str | os.PathLike[str] | None,
    what: str,
    suffixes: tuple[str, ...],
) -> Path:
    """The file a spec names (relative to ``base_dir``), with a known suffix, existing."""
    path = Path(spec).expanduser()
    if not path.is_absolute() and base_dir is not None:
        path = Path(base_dir) / path
    suffix = path.suffix.lower()
    if suffix not in suffixes:
        raise ValidationError(
            f"{what}: {os.fspath(spec)!r} is neither a catalog name nor a file with a known "
            f"suffix (got {suffix or 'no suffix'!r}); allowed suffixes: {', '.join(suffixes)}"
        )
    return input_file(spec, what, CatalogError, base_dir=base_dir)


def load_spacecraft_spec(
    spec: str | os.PathLike[str],
    *,
    base_dir: str | os.PathLike[str] | None = None,
    material: str | None = None,
    material_map: Mapping[Any, str] | str | os.PathLike[str] | None = None,
    **options: Any,
) -> Any:
    """A spacecraft from a catalog name or a mesh file.

    Parameters
    ----------
    spec : str or os.PathLike
        A ``spacecraft`` catalog entry (shipped or user) or a mesh file (a suffix of
        :data:`MESH_SUFFIXES`); see :func:`is_file_spec`.
    base_dir : str or os.PathLike, optional
        Directory that relative file paths (the mesh, a material map file) are taken from.
    material, material_map
        For a mesh file, exactly one: the one material of every facet, or the facet label
        -> material map (a mapping, or a TOML map file,
        :func:`sbrdf_xr.body.spacecraft.read_material_map`).
    **options
        For a mesh file: ``length_unit``, ``face_property``, ``repair``, ``name``, ``file_type``
        of :func:`sbrdf_xr.body.spacecraft.load_spacecraft`.

    Returns
    -------
    Spacecraft

    Raises
    ------
    CatalogError
        For an unknown name or a file that does not exist.
    ValidationError
        For a catalog entry that is not a spacecraft, an unknown suffix, a mesh file without
        ``material`` or ``material_map``, options given with a catalog name.

    Examples
    --------
    >>> import tempfile, trimesh
    >>> path = Path(tempfile.mkdtemp()) / "box.stl"
    >>> _ = trimesh.creation.box(extents=(1.0, 1.0, 1.0)).export(path)
    >>> sc = load_spacecraft_spec(path, material="lambertian-grey-50")
    >>> sc.name, sc.n_facets, sc.materials
    ('box', 12, ['lambertian-grey-50'])
    """
    if not is_file_spec(spec):
        name = str(spec)
        if material is not None or material_map is not None or options:
            given = [k for k, v in (("material", material), ("material_map", material_map)) if v]
            raise ValidationError(
                f"spacecraft: {name!r} is a catalog entry; the mesh options "
                f"{given + sorted(options)} apply to a mesh file only"
            )
        e = _entry_of(name, ("spacecraft",), "spacecraft")
        if e.kind != "spacecraft":
            raise ValidationError(
                f"spacecraft: catalog entry {name!r} is a {e.kind} entry, not a spacecraft"
            )
        return load(name)
    path = _file_of(spec, base_dir, "spacecraft", MESH_SUFFIXES)
    if (material is None) == (material_map is None):
        raise ValidationError(
            f"spacecraft: the mesh file {path} needs exactly one of material (the material of "
            "every facet) and material_map (facet colour or label -> material)"
        )
    if isinstance(material_map, str | os.PathLike):
        material_map = _file_of(material_map, base_dir, "material_map", (".toml",))
    return spacecraft.load_spacecraft(path, material_map=material_map, material=material, **options)


def load_material_spec(
    spec: str | os.PathLike[str], *, base_dir: str | os.PathLike[str] | None = None
) -> xr.DataArray | xr.Dataset:
    """A material table or a BRDF model from a catalog name or a netCDF file.

    Parameters
    ----------
    spec : str or os.PathLike
        A ``material`` or ``model`` catalog entry (shipped or user), or a netCDF file
        (a suffix of :data:`MATERIAL_SUFFIXES`) holding a material table (written by
        :func:`sbrdf_xr.materials.files.to_netcdf`) or a model (written by
        :func:`sbrdf_xr.materials.models.to_netcdf`).
    base_dir : str or os.PathLike, optional
        Directory that a relative file path is taken from.

    Returns
    -------
    xarray.DataArray or xarray.Dataset
        The table (a DataArray), or the model parameters (a Dataset).

    Raises
    ------
    CatalogError
        For an unknown name or a file that does not exist.
    ValidationError
        For an entry of another kind, an unknown suffix, or a file that is neither.

    Examples
    --------
    >>> import tempfile
    >>> from sbrdf_xr.materials import files as material_io, schema as material_schema
    >>> path = Path(tempfile.mkdtemp()) / "grey.nc"
    >>> table = material_schema.lambertian(0.3, wavelength=[500.0, 600.0], material="grey")
    >>> _ = material_io.to_netcdf(table, path)
    >>> da = load_material_spec(path)
    >>> da.attrs["material"], da.sizes["wavelength"]
    ('grey', 2)
    """
    if not is_file_spec(spec):
        e = _entry_of(str(spec), ("material", "model"), "material")
        if e.kind not in ("material", "model"):
            raise ValidationError(
                f"material: catalog entry {e.name!r} is a {e.kind} entry, not a material "
                "table or model"
            )
        return load(e.name)
    path = _file_of(spec, base_dir, "material", MATERIAL_SUFFIXES)
    with reading(path, "material", "netCDF"), xr.open_dataset(path, engine="netcdf4") as ds:
        is_table, is_model = SBRDF in ds.data_vars, "model" in ds.attrs
    if is_table:
        return material.open_material(path)
    if is_model:
        return models.open_model(path)
    raise ValidationError(
        f"material: {path} is neither a material table (an 'sbrdf' variable, written by "
        "sbrdf_xr.materials.files.to_netcdf) nor a BRDF model (a 'model' attribute, written by "
        "sbrdf_xr.materials.models.to_netcdf)"
    )


def material_tables(
    specs: Mapping[str, str | os.PathLike[str]],
    base_dir: str | os.PathLike[str] | None = None,
    where: Mapping[str, str] | None = None,
) -> tuple[dict[str, xr.DataArray], dict[str, xr.Dataset]]:
    """Material tables, and BRDF models, from catalog names or netCDF files.

    Parameters
    ----------
    specs : mapping of str to str or Path
        Material name (as the spacecraft labels its facets) -> a ``material`` or ``model``
        catalog entry or a netCDF file of a table or a model
        (:func:`sbrdf_xr.catalog.load_material_spec`).
    base_dir : str or Path, optional
        Directory that relative file paths are taken from.
    where : mapping of str to str, optional
        Where each material was named (``"[spacecraft] material_map"``, ``"--material"``),
        for the error messages; default ``"[materials]"``.

    Returns
    -------
    tables : dict of str to DataArray
        A table for every material; a model is rendered by :func:`sbrdf_xr.materials.models.render`
        on its default grid.
    models : dict of str to Dataset
        The models given (for ``evaluation = "analytic"``, which evaluates them exactly).

    Raises
    ------
    ValidationError
        Naming the material, for an entry of another kind, a file with an unknown
        suffix, or a file that is neither a table nor a model.
    CatalogError
        For an unknown name or a file that does not exist.

    Examples
    --------
    >>> import tempfile
    >>> from sbrdf_xr.materials import files as material_io, schema as material_schema
    >>> folder = Path(tempfile.mkdtemp())
    >>> table = material_schema.lambertian(0.3, wavelength=[500.0, 600.0], material="grey")
    >>> _ = material_io.to_netcdf(table, folder / "grey.nc")
    >>> tables, models = material_tables({"paint": "grey.nc"}, base_dir=folder)
    >>> sorted(tables), tables["paint"].attrs["material"], models
    (['paint'], 'grey', {})
    """
    tables: dict[str, xr.DataArray] = {}
    given: dict[str, xr.Dataset] = {}
    building = to_build(s for s in specs.values() if isinstance(s, str) and not is_file_spec(s))
    with _batch(building):
        for mat, spec in specs.items():
            try:
                obj = load_material_spec(spec, base_dir=base_dir)
                if isinstance(obj, xr.Dataset):
                    given[mat] = obj
                    obj = models.render(obj, progress=_SHOW_PROGRESS[0])
            except CatalogError as exc:
                raise CatalogError(
                    f"{(where or {}).get(mat, '[materials]')} {mat!r}: {exc}"
                ) from None
            except ValidationError as exc:
                raise ValidationError(
                    f"{(where or {}).get(mat, '[materials]')} {mat!r}: {exc}"
                ) from None
            tables[mat] = obj
    return tables, given


#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(__name__, globals(), {"KINDS": "ENTRY_KINDS"})
