"""The sub-commands of ``sbrdf-xr`` that analyse a cube or measured data: ``photometry``
(band magnitudes and colours) and ``invert`` (material areas, spin state).  Each
``cmd_*`` takes the parsed arguments and returns the exit status.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from ..errors import SbrdfError, ValidationError
from ..store import derived, formats
from .commands import spacecraft_of
from .output import open_dataset

__all__ = ["cmd_invert", "cmd_photometry"]

#: The shortest wavelength a measured spectrum of ``invert unmix`` may hold [nm] (a
#: spectrum in micrometres or metres lies wholly below it).
MIN_WAVELENGTH_NM = 50.0
#: The shortest candidate period of ``invert spin --periods`` [s].
MIN_PERIOD_S = 1e-3


def _cube_range_km(cube) -> float | None:
    """The observer range a cube records [km] (attribute or scalar variable), if any."""
    for name in ("range_km", "observer_range_km"):
        if name in cube.attrs:
            return float(cube.attrs[name])
        if name in cube.variables and cube[name].ndim == 0:
            return float(cube[name].values)
    return None


def _parse_extinction(items: list[str] | None) -> dict[str, float] | None:
    if not items:
        return None
    out: dict[str, float] = {}
    for item in items:
        band, sep, k = item.partition("=")
        try:
            if not sep or not band:
                raise ValueError
            out[band.strip()] = float(k)
        except ValueError:
            raise SbrdfError(
                f"--extinction: {item!r} is not BAND=K (give e.g. --extinction V=0.2 R=0.1)"
            ) from None
    return out


def _parse_colours(text: str | None) -> list[tuple[str, str]] | None:
    if not text:
        return None
    pairs = []
    for item in text.split(","):
        a, sep, b = item.strip().partition("-")
        if not sep or not a or not b:
            raise SbrdfError(
                f"--colours: {item.strip()!r} is not a band pair like V-R (give e.g. V-R,R-I)"
            )
        pairs.append((a, b))
    return pairs


#: The options of ``photometry`` by the parameter that a message of
#: :func:`~sbrdf_xr.photometry.photometry` starts with.
_PHOTOMETRY_FLAGS = {
    "band": "--bands",
    "bands": "--bands",
    "pairs": "--colours",
    "extinction": "--extinction",
    "sun_distance": "--sun-distance-au",
    "range": "--range-km",
    "system": "--system",
    "extrapolate": "--extrapolate",
}


def _flag_of(message: str) -> str:
    """``"--flag: "`` for a message that starts with a parameter of an option, else ``""``."""
    head = message.split(":", 1)[0].split()[0] if message.strip() else ""
    flag = _PHOTOMETRY_FLAGS.get(head)
    return f"{flag}: " if flag and flag not in message else ""


def cmd_photometry(args: argparse.Namespace) -> int:
    """``sbrdf-xr photometry CUBE``: the band magnitudes (and colour indices) of a cube at
    the observer range of ``--range-km`` or the one the cube records, their table printed
    and written to the files of ``--output`` (netCDF) and ``--csv``; returns 0.

    Examples
    --------
    A unit box of albedo 0.5 facing the Sun and the observer sends ``0.5 / pi m2 sr-1``;
    at 1000 km its magnitudes are the Sun's plus ``30 - 2.5 log10(0.5 / pi) = 31.995``, and
    a grey body has the Sun's colours:

    >>> import contextlib
    >>> import io
    >>> import tempfile
    >>> from pathlib import Path
    >>> import numpy as np
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft, simulate, write
    >>> from sbrdf_xr.cli import cmd_photometry
    >>> from sbrdf_xr.cli.parser import build_parser
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, np.arange(400.0, 1001.0, 20.0), material="grey")
    >>> x = [[1.0, 0.0, 0.0]]
    >>> scene = Scene(box, {"grey": grey}, to_sun=x, to_observer=x, kernel="numpy")
    >>> out = io.StringIO()
    >>> with tempfile.TemporaryDirectory() as tmp, contextlib.redirect_stdout(out):
    ...     cube = write(simulate(scene), Path(tmp) / "cube.nc")
    ...     argv = ["photometry", str(cube), "--bands", "V", "R", "--range-km", "1000", "-q"]
    ...     status = cmd_photometry(build_parser().parse_args(argv))
    >>> status
    0
    >>> print(*out.getvalue().splitlines()[1:], sep="\\n")
    band     filter            m_sun      min   median      max
    V        bessell-V       -26.768    5.227    5.227    5.227
    R        bessell-R       -26.963    5.033    5.033    5.033
    colour V-R        median 0.194 mag
    """
    import numpy as np
    from tqdm.dask import TqdmCallback

    from .. import photometry as phot

    outputs = [(args.output, None), (args.csv, "photometry-csv")]
    if args.csv is not None:  # a CSV file under the suffix of another format is refused
        suffix = Path(args.csv).suffix.lower()
        owners = [f.label for f in formats.FORMATS.values() if suffix in f.suffixes]
        if suffix and suffix != ".csv" and owners:
            raise ValidationError(
                f"--csv {args.csv}: writes CSV, not {suffix} (the suffix of "
                f"{' or '.join(dict.fromkeys(owners))}); give a .csv name, or -o for netCDF"
            )
    for (out, name), flag in zip(outputs, ("-o", "--csv"), strict=True):
        if out is not None and not str(out).strip():
            raise ValidationError(f"{flag}: got {out!r}; give a file name for the output")
        if out is not None:  # refused before anything is computed
            formats.check(out, "photometry", overwrite=args.overwrite, name=name)
    with open_dataset(args.cube) as probe:
        # a signal its writer left out (computed from signal_material on read) counts
        left_out = "signal" in derived.recorded(probe) and "wavelength" in probe.dims
        if not left_out and not any(
            v in probe and "wavelength" in probe[v].dims for v in ("signal", "spacecraft_sbrdf")
        ):
            raise ValidationError(
                f"{args.cube}: not a spectral simulation cube of 'sbrdf-xr simulate' "
                "(it needs 'signal' or 'spacecraft_sbrdf' over wavelength)"
            )
    colours = _parse_colours(args.colours)
    extinction = _parse_extinction(args.extinction)
    with derived.open_cube(args.cube) as cube:  # lazily, its derived variables put back
        range_km = args.range_km
        if range_km is None and "range" not in cube.variables:
            range_km = _cube_range_km(cube)
            if range_km is None:
                raise SbrdfError(
                    f"{args.cube} records no observer range; give it with --range-km KM "
                    "(e.g. --range-km 36000 for a geostationary object)"
                )
        if extinction is not None and "airmass" not in cube.variables:
            raise SbrdfError(
                f"--extinction: {args.cube} records no airmass (only the cube of an "
                "observation does)"
            )
        try:
            lazy = phot.photometry(
                cube,
                args.bands,
                range_km,
                pairs=colours,
                system=args.system,
                sun_distance=args.sun_distance_au,
                extinction=extinction,
                weighting=args.weighting,
                quadrature=args.quadrature,
                extrapolate=args.extrapolate,
                solar=args.solar,
            )
        except SbrdfError as exc:  # the option named, with the function's own message
            raise ValidationError(f"{_flag_of(str(exc))}{exc}") from None
        with TqdmCallback(desc="photometry", disable=args.quiet):
            ds = lazy.compute()
    print(
        f"photometry of {args.cube}: range {ds.attrs['range_source']}, Sun distance "
        f"{ds.attrs['sun_distance_source']}, {ds.attrs['magnitude_system']} "
        f"magnitudes, {args.weighting} weighting, solar spectrum {args.solar}"
    )
    for k in ("range_override", "sun_distance_override", "extinction_coefficients"):
        if k in ds.attrs:
            print(f"{k.replace('_', ' ')}: {ds.attrs[k]}")
    print(f"{'band':<8} {'filter':<14} {'m_sun':>8} {'min':>8} {'median':>8} {'max':>8}")
    for b in ds.band.values:
        m = np.asarray(ds.magnitude.sel(band=b).values).ravel()
        fin = m[np.isfinite(m)]
        stats = (
            f"{fin.min():8.3f} {np.median(fin):8.3f} {fin.max():8.3f}"
            if fin.size
            else f"{'inf':>8} {'inf':>8} {'inf':>8}"
        )
        print(
            f"{b!s:<8} {ds.filter.sel(band=b).item()!s:<14} "
            f"{float(ds.sun_magnitude.sel(band=b)):8.3f} {stats}"
        )
    if "colour_index" in ds:
        for c in ds.colour.values:
            v = np.asarray(ds.colour_index.sel(colour=c).values).ravel()
            v = v[np.isfinite(v)]
            med = f"{np.median(v):.3f}" if v.size else "nan"
            print(f"colour {c!s:<10} median {med} mag")
    for out, name in outputs:
        if out is not None:
            formats.format_for(out, "photometry", name).writer(ds, out, overwrite=args.overwrite)
            print(f"wrote {out}")
    return 0


def _isel(terms, items: list[str] | None, cube: str):
    """``terms`` at the ``--isel DIM=INDEX`` selections, each checked against the cube."""
    from ..errors import InversionError

    samples = [d for d in terms.dims if d not in ("material", "wavelength", "band")]
    for item in items or []:
        dim, sep, idx = item.partition("=")
        dim = dim.strip()
        if not sep or not dim:
            raise InversionError(f"--isel {item!r}: expected DIM=INDEX (e.g. --isel geometry=0)")
        if dim not in samples:
            raise InversionError(
                f"--isel {item!r}: {cube} has no sample dimension {dim!r}; allowed: "
                f"{', '.join(f'{d} (0..{terms.sizes[d] - 1})' for d in samples) or 'none'}"
            )
        try:
            i = int(idx)
        except ValueError:
            raise InversionError(
                f"--isel {item!r}: the index {idx!r} is not an integer (0..{terms.sizes[dim] - 1})"
            ) from None
        n = terms.sizes[dim]
        if not -n <= i < n:
            raise InversionError(
                f"--isel {item!r}: index {i} is out of range; {dim} of {cube} has {n} entries "
                f"(0..{n - 1})"
            )
        terms = terms.isel({dim: i})
        samples.remove(dim)
    return terms


def _unmix(args: argparse.Namespace):
    from .. import invert
    from ..errors import InversionError
    from ..lightcurves import read_light_curve

    if args.range_km is not None and not (math.isfinite(args.range_km) and args.range_km > 0):
        raise InversionError(  # refused for a spectrum too, which does not use it
            f"--range-km: must be finite and > 0 km, got {args.range_km:g} (the observer range)"
        )
    with open_dataset(args.cube) as cube:
        terms = cube.load()["signal_material"] if "signal_material" in cube else None
    if terms is None:
        raise InversionError(
            f"{args.cube}: no signal_material; simulate with the per_material output"
        )
    terms = _isel(terms, args.isel, args.cube)
    if invert.measured_kind(args.measured) == "spectrum":
        y, sigma = invert.read_spectrum(args.measured)
        lo, hi = float(y.wavelength.min()), float(y.wavelength.max())
        if hi < MIN_WAVELENGTH_NM:
            raise InversionError(
                f"{args.measured}: wavelengths {lo:g}..{hi:g}; expected nm (values below "
                f"{MIN_WAVELENGTH_NM:g} look like micrometres or metres: give the wavelength "
                "column in nm)"
            )
    else:
        lc = read_light_curve(args.measured)
        if args.range_km is None:
            raise InversionError("--range-km: needed to turn measured magnitudes into signal")
        y, sigma = invert.magnitudes_to_signal(lc, args.range_km)
        terms = invert.band_terms(terms, [str(b) for b in y.band.values])
    if args.total_area and args.spacecraft is None:
        raise InversionError("--total-area: needs --spacecraft (the areas to add up)")
    areas = None if args.spacecraft is None else invert.material_areas(spacecraft_of(args))
    try:
        ds = invert.unmix(
            y,
            terms,
            sigma,
            areas=areas,
            total_area=True if args.total_area else None,
            select=None if args.select == "none" else args.select,
            criterion=args.criterion,
        )
    except SbrdfError as exc:  # the files named, with the fit's own message
        text = str(exc)
        if str(args.measured) not in text:
            text = f"{args.measured} against {args.cube}: {text}"
        raise InversionError(text) from None
    print(
        f"unmix {args.measured}: chi2 {float(ds.chi2):.4g} for "
        f"{int(ds.degrees_of_freedom)} degrees of freedom, "
        f"reduced {float(ds.reduced_chi_square):.4g} ({ds.attrs['fit_quality']}); "
        f"{args.criterion} selection: {ds.attrs['selected_materials']}"
    )
    for m in ds.material.values:
        kept = "" if bool(ds.selected.sel(material=m)) else "  (left out)"
        area = (
            f", area {float(ds.area.sel(material=m)):.4g} m2 "
            f"({float(ds.area_fraction.sel(material=m)):.3f} of the total)"
            if "area" in ds
            else ""
        )
        print(
            f"  {m!s:<24} scale {float(ds.scale.sel(material=m)):.4f} "
            f"+- {float(ds.scale_uncertainty.sel(material=m)):.4f}{area}{kept}"
        )
    print(f"  selection: {ds.attrs['selection_note']}")
    print(f"  degenerate: {ds.attrs['degenerate']}")
    return ds


def _periods(args: argparse.Namespace, lc) -> Any:
    """The candidate periods of ``--periods MIN MAX N``, after the size of the search is
    checked (so that a huge N is refused before anything is allocated)."""
    import numpy as np

    from .. import invert
    from ..errors import InversionError

    lo, hi, n = args.periods
    if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo <= hi):
        raise InversionError(
            f"--periods {lo:g} {hi:g} {n:g}: MIN and MAX must be finite with 0 < MIN <= MAX [s]"
        )
    if lo < MIN_PERIOD_S:
        raise InversionError(
            f"--periods {lo:g} {hi:g} {n:g}: MIN must be at least {MIN_PERIOD_S:g} s "
            "(a thousand turns a second)"
        )
    if not (np.isfinite(n) and n >= 1 and float(n) == int(n)):
        raise InversionError(f"--periods {lo:g} {hi:g} {n:g}: N must be an integer >= 1")
    d = invert.light_curve_fluxes(lc)
    times = np.unique(d["time"])
    invert.check_search_size(
        max(1, args.n_axes),
        int(n),
        max(1, args.n_phases),
        times.size,
        len(d["labels"]),
        d["flux"].size,
        size_limit=args.size_limit,
    )
    return np.linspace(lo, hi, int(n))


def _spin(args: argparse.Namespace):
    from .. import invert
    from ..engine import resolve_scene
    from ..errors import InversionError
    from ..lightcurves import read_light_curve

    given = [
        name
        for name, v in (("--cube", args.cube), ("--scene", args.scene), ("--to-sun", args.to_sun))
        if v is not None
    ]
    if len(given) != 1 or (args.to_sun is None) != (args.to_observer is None):
        raise InversionError(
            "invert spin: give the geometry once: --cube CUBE.nc (a cube over time), --scene "
            "NAME|SCENE.toml (a scene with an observation), or --to-sun X Y Z with "
            f"--to-observer X Y Z; got {', '.join(given) or 'none'}"
        )
    scene = geometry = None
    if args.scene is not None:
        scene = resolve_scene(args.scene)
        if scene.observation is None:
            raise InversionError(f"--scene {args.scene}: the scene has no observation")
        geometry = scene.observation
    elif args.cube is not None:
        with open_dataset(args.cube) as cube:
            geometry = cube.load()
    if scene is not None and args.spacecraft is None:
        sc = scene.spacecraft
    else:
        sc = spacecraft_of(
            argparse.Namespace(**{**vars(args), "spacecraft": args.spacecraft or "canx1"})
        )
    lc = read_light_curve(args.measured)
    ds = invert.fit_spin(
        lc,
        sc,
        geometry,
        to_sun=args.to_sun,
        to_observer=args.to_observer,
        periods=_periods(args, lc),
        axis_body=args.axis_body,
        n_axes=args.n_axes,
        n_phases=args.n_phases,
        offset=args.offset,
        method=args.method,
        size_limit=args.size_limit,
    )
    print(
        f"spin fit of {args.measured}: {ds.attrs['n_candidates']} candidates by "
        f"{ds.attrs['search_method']} in {ds.attrs['search_seconds']:.1f} s "
        f"({ds.attrs['search_check']}); chi2 {float(ds.chi2):.4g}, reduced "
        f"{float(ds.reduced_chi_square):.4g} ({ds.attrs['fit_quality']}); epoch {ds.attrs['epoch']}"
    )
    for k in ("axis_longitude", "axis_latitude", "period", "phase"):
        print(
            f"  {k:<15} {float(ds[k]):10.4f} +- {float(ds[k + '_uncertainty']):.4f} "
            f"{ds[k].attrs['units']}"
        )
    for sname in ds.solution.values:
        print(
            f"  alternative {sname!s:<14} chi2 gap {float(ds.chi2_gap.sel(solution=sname)):10.2f}"
        )
    return ds


def cmd_invert(args: argparse.Namespace) -> int:
    """``sbrdf-xr invert unmix MEASURED --cube CUBE`` (the material areas of a measured
    spectrum or band magnitudes, :func:`sbrdf_xr.invert.unmix`) or ``sbrdf-xr invert spin
    CURVE`` (spin axis, period and phase of a light curve, :func:`sbrdf_xr.invert.fit_spin`,
    with the geometry of ``--cube``, ``--scene`` or ``--to-sun``/``--to-observer``):
    the fit printed and written to the file of ``--output``; returns 0.

    Examples
    --------
    A measured spectrum twice the simulated signal of a unit box (with 1 % noise) unmixes
    to twice its area of the material, ``+- 0.01 / (0.5 / pi) / sqrt(3)`` for three
    wavelengths:

    >>> import contextlib
    >>> import io
    >>> import tempfile
    >>> from pathlib import Path
    >>> import trimesh
    >>> from sbrdf_xr import Scene, load_spacecraft, simulate, write
    >>> from sbrdf_xr.cli import cmd_invert
    >>> from sbrdf_xr.cli.parser import build_parser
    >>> from sbrdf_xr.errors import InversionError
    >>> from sbrdf_xr.materials.schema import lambertian
    >>> box = load_spacecraft(trimesh.creation.box(), material="grey")
    >>> grey = lambertian(0.5, [500.0, 600.0, 700.0], material="grey")
    >>> x = [[1.0, 0.0, 0.0]]
    >>> scene = Scene(box, {"grey": grey}, to_sun=x, to_observer=x,
    ...               outputs=("signal", "per_material"), kernel="numpy")
    >>> rows = "wavelength,signal,uncertainty\\n" + "".join(
    ...     f"{wl},{s},0.01\\n" for wl, s in ((500, 0.3283), (600, 0.3083), (700, 0.3183)))
    >>> out = io.StringIO()
    >>> with tempfile.TemporaryDirectory() as tmp, contextlib.redirect_stdout(out):
    ...     cube = write(simulate(scene), Path(tmp) / "cube.nc")
    ...     _ = (Path(tmp) / "spectrum.csv").write_text(rows)
    ...     argv = ["invert", "unmix", str(Path(tmp) / "spectrum.csv"), "--cube", str(cube),
    ...             "--isel", "geometry=0", "--select", "none"]
    ...     status = cmd_invert(build_parser().parse_args(argv))
    ...     try:
    ...         cmd_invert(build_parser().parse_args(argv[:-3] + ["geometry=3"]))
    ...     except InversionError as exc:
    ...         error = str(exc).replace(tmp, "TMP")
    >>> status
    0
    >>> print(*out.getvalue().splitlines()[1:], sep="\\n")
      grey                     scale 2.0000 +- 0.0363
      selection: the subset of lowest BIC (grey)
      degenerate: none
    >>> print(error)
    --isel 'geometry=3': index 3 is out of range; geometry of TMP/cube.nc has 1 entries (0..0)
    """
    if args.output:  # refused before anything is computed
        formats.check(args.output, "inversion", overwrite=args.overwrite)
    ds = _unmix(args) if args.invert_command == "unmix" else _spin(args)
    if args.output:
        formats.write(ds, args.output, kind="inversion", overwrite=args.overwrite)
        print(f"wrote {args.output}")
    return 0
