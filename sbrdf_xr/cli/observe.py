"""``sbrdf-xr observe``: a real pass from the command line, no scene file to write.

Elements (a TLE or OMM file, or a catalog orbit), a site (a catalog observatory or
latitude, longitude and height), a UTC window and step, an attitude law with its
parameters, a spacecraft and its materials, and bands: the observation cube is
simulated, written by :func:`sbrdf_xr.store.write` and drawn with ``--plot``::

    sbrdf-xr observe --elements canx1-example --site mont-megantic \\
        --start 2024-03-17T01:20:00 --duration 300 --step 1 \\
        --attitude spin --spin-axis 0.3,0.4,0.866 --period 90 -o pass.nc --plot pass.png

Instead of elements and a window, ``--tracking FILE`` takes an observer's tracking table
(:mod:`sbrdf_xr.observing.tracking_io`: a CSV of ``time``, ``elevation``, ``azimuth`` and
``range`` or ``height`` at ``--site``, or with ``--tracking-format pomenis`` the
Pomenis Starlink table at its own site); ``--elements`` also takes a CCSDS OEM file and
``--series`` a CCSDS AEM.

The attitude laws are those of :mod:`sbrdf_xr.observing.attitude`: ``inertial``
(``--quaternion``), ``nadir`` (``--yaw``, ``--nadir-axis``, ``--velocity-axis``),
``sun-pointing`` (``--sun-axis``, ``--secondary-axis``, ``--secondary-target``),
``spin`` (``--spin-axis``, ``--period`` or ``--rate``, ``--phase``, ``--initial``),
``tumble`` (``--omega``, ``--inertia`` or ``--density`` of the mesh, ``--initial``) and
``series`` (``--series FILE``: quaternions over time).
"""

from __future__ import annotations

import argparse
import contextlib
import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from ..errors import AttitudeError, SbrdfError, ValidationError
from . import _observe_options as options

__all__ = [
    "add_observe_parser",
    "attitude_of",
    "cmd_observe",
    "observation_of",
]

LAW_NAMES = ("inertial", "nadir", "sun-pointing", "spin", "tumble", "series")
#: The fastest spin ``--period`` / ``--rate`` give [degree s-1]: 100 turns a second.
MAX_SPIN_RATE_DEG_S = 36000.0
#: The longest ``--duration`` [s]: about 32 years, beyond any use of one element set.
MAX_DURATION_S = 1e9


def _axis(text: str) -> Any:
    """``"+z"`` or ``"0.3,0.4,0.866"`` (comma- or space-separated components)."""
    parts = text.replace(",", " ").split()
    if len(parts) == 3:
        try:
            return [float(p) for p in parts]
        except ValueError:
            pass
    return text


def add_observe_parser(sub: Any, mesh_options: Any) -> argparse.ArgumentParser:
    """Add the ``observe`` sub-command to the sub-parsers ``sub``.

    Examples
    --------
    >>> from sbrdf_xr.cli.parser import build_parser
    >>> args = build_parser().parse_args(
    ...     ["observe", "--elements", "canx1-example", "--site", "haleakala",
    ...      "--start", "2024-03-17T06:14:00", "--duration", "600", "-o", "pass.nc"])
    >>> args.command, args.attitude, args.step, args.bands
    ('observe', 'nadir', 1.0, ['V', 'R', 'I'])
    """
    po = sub.add_parser(
        "observe",
        help="simulate a real pass: elements, a site, a UTC window, an attitude law",
        description="Simulate a real pass - elements (a TLE or OMM file, or a catalog orbit), "
        "a site, a UTC window and step, an attitude law - and write its cube (and, with "
        "--plot, its light curve); no scene file.",
    )
    options.orbit_and_site(po)
    options.utc_window(po)
    options.attitude_law(po, LAW_NAMES)
    options.spacecraft_and_output(po, mesh_options)
    po.set_defaults(func=cmd_observe)
    return po


@contextlib.contextmanager
def _flags(names: str) -> Iterator[None]:
    """An error of the law built from the options ``names`` says which they are."""
    try:
        yield
    except SbrdfError as exc:
        raise AttitudeError(f"{names}: {exc}") from None


def _quaternion(text: str, what: str) -> list[float]:
    parts = text.replace(",", " ").split()
    try:
        q = [float(p) for p in parts]
    except ValueError:
        q = []
    if len(q) != 4:
        raise AttitudeError(f"{what}: got {text!r}; expected a quaternion x,y,z,w")
    return q


def attitude_of(args: argparse.Namespace, spacecraft: Any = None) -> Any:
    """The attitude law of the ``observe`` options.

    Examples
    --------
    >>> from sbrdf_xr.cli.parser import build_parser
    >>> base = ["observe", "--elements", "canx1-example", "--site", "haleakala",
    ...         "--start", "2024-03-17T06:14:00", "--duration", "60", "-o", "p.nc"]
    >>> args = build_parser().parse_args([*base, "--attitude", "spin", "--period", "90",
    ...                                   "--spin-axis", "0,0,1", "--initial", "nadir"])
    >>> law = attitude_of(args)
    >>> type(law).__name__, law.rate, type(law.initial).__name__
    ('Spin', 4.0, 'Nadir')
    >>> attitude_of(build_parser().parse_args([*base, "--attitude", "spin"]))
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.AttitudeError: --attitude spin: give --period S or --rate DEG_S
    """
    from .. import observing as law

    kind = args.attitude
    if kind == "inertial":
        if args.quaternion is None:
            raise AttitudeError("--attitude inertial: give --quaternion X Y Z W")
        return law.Inertial(tuple(args.quaternion))
    if kind == "nadir":
        with _flags("--yaw, --nadir-axis, --velocity-axis"):
            return law.Nadir(args.yaw, _axis(args.nadir_axis), _axis(args.velocity_axis))
    if kind == "sun-pointing":
        target = args.secondary_target
        with _flags("--sun-axis, --secondary-axis, --secondary-target"):
            return law.SunPointing(
                _axis(args.sun_axis),
                _axis(args.secondary_axis),
                target
                if target in ("orbit_normal", "nadir", "velocity", "north")
                else _axis(target),
            )
    if kind == "series":
        if not args.series:
            raise AttitudeError("--attitude series: give --series FILE (.csv or .nc)")
        kind_of = "aem" if Path(args.series).suffix.lower() == ".aem" else "quaternion_series"
        return law.law_from_dict({"law": kind_of, "path": args.series})
    initial: Any = (0.0, 0.0, 0.0, 1.0)
    if args.initial:
        if kind == "spin" and args.initial in ("nadir", "sun-pointing"):
            initial = law.Nadir() if args.initial == "nadir" else law.SunPointing()
        else:
            initial = _quaternion(args.initial, "--initial")
    if kind == "spin":
        if (args.period is None) == (args.rate is None):
            raise AttitudeError("--attitude spin: give --period S or --rate DEG_S")
        if args.period is not None and not (math.isfinite(args.period) and args.period > 0):
            raise AttitudeError(f"--period: got {args.period}; allowed a finite period > 0 s")
        rate = args.rate if args.rate is not None else 360.0 / args.period
        given = f"--rate {args.rate}" if args.rate is not None else f"--period {args.period}"
        if not (math.isfinite(rate) and 0 < abs(rate) <= MAX_SPIN_RATE_DEG_S):
            raise AttitudeError(
                f"{given}: a spin rate of {rate:g} degree s-1; allowed a finite rate with "
                f"0 < |rate| <= {MAX_SPIN_RATE_DEG_S:g} degree s-1 (a period of at least "
                f"{360.0 / MAX_SPIN_RATE_DEG_S:g} s)"
            )
        with _flags("--spin-axis, --phase, --initial, --epoch"):
            return law.Spin(_axis(args.spin_axis), rate, args.phase, initial, args.epoch)
    if args.omega is None:
        raise AttitudeError("--attitude tumble: give --omega WX WY WZ [degree s-1]")
    if (args.inertia is None) == (args.density is None):
        raise AttitudeError("--attitude tumble: give --inertia IXX IYY IZZ or --density KG_M3")
    with _flags("--omega, --inertia, --density, --initial, --epoch"):
        if args.inertia is not None:
            return law.Tumble(tuple(args.inertia), tuple(args.omega), initial, args.epoch)
        return law.Tumble.from_spacecraft(
            spacecraft, args.density, tuple(args.omega), initial, args.epoch
        )


def _site_of(args: argparse.Namespace) -> Any:
    """The site of ``--site`` or ``--lat``/``--lon``/``--height``."""
    from ..observing.observe import Site

    latlon = [args.lat is not None, args.lon is not None]
    if args.site is not None and any(latlon):
        raise ValidationError("give --site NAME or --lat/--lon/--height, not both")
    if args.site is not None:
        return Site.from_catalog(args.site)
    elif all(latlon):
        try:
            return Site(args.lat, args.lon, args.height, name=f"{args.lat:g}, {args.lon:g}")
        except SbrdfError as exc:
            raise ValidationError(
                f"--lat {args.lat:g} --lon {args.lon:g} --height {args.height:g}: {exc}"
            ) from None
    else:
        raise ValidationError("give --site NAME (a catalog observatory) or both --lat and --lon")


def _tracking_observation(args: argparse.Namespace, spacecraft: Any) -> Any:
    """The observation of ``--tracking``: the table's times, orbit and (pomenis) site."""
    from ..observing.tracking_io import tracking_from_dict

    given = [f for f in ("elements", "start", "stop", "duration") if getattr(args, f)]
    if given:
        raise ValidationError(
            f"--tracking gives the orbit and the times; remove --{', --'.join(given)}"
        )
    spec: dict[str, Any] = {"path": args.tracking, "format": args.tracking_format}
    site = None
    if args.tracking_format == "csv":
        site = _site_of(args)
        spec["time_zone"] = "UTC" if args.utc else None
    elif args.site is not None or args.lat is not None:
        raise ValidationError("--tracking-format pomenis has its own site; remove the site")
    table = tracking_from_dict(spec, site)
    return table.observation(
        attitude_of(args, spacecraft),
        min_elevation=args.min_elevation,
        earth=args.earth,
        name=args.name or f"{table.name} from {table.site.name}",
    )


def observation_of(args: argparse.Namespace, spacecraft: Any = None) -> Any:
    """The :class:`~sbrdf_xr.observing.observation.Observation` of the ``observe`` options.

    Examples
    --------
    >>> from sbrdf_xr.cli.parser import build_parser
    >>> args = build_parser().parse_args(
    ...     ["observe", "--elements", "canx1-example", "--lat", "20.7", "--lon", "-156.26",
    ...      "--height", "3050", "--start", "2024-03-17T06:14:00", "--duration", "60",
    ...      "--step", "30", "-o", "p.nc"])
    >>> obs = observation_of(args)
    >>> obs.times.size, obs.site.height, type(obs.attitude).__name__
    (3, 3050.0, 'Nadir')
    """
    import numpy as np

    from ..observing.observe import Observation, Orbit, times
    from ..observing.oem_reader import is_oem_file, read_oem
    from ..observing.timescales import to_datetime64

    if args.tracking:
        return _tracking_observation(args, spacecraft)
    if not args.elements or not args.start:
        raise ValidationError("give --elements and --start (or a --tracking table)")
    spec = args.elements
    orbit: Any
    if Path(spec).is_file() and is_oem_file(spec):
        if args.satellite:
            raise ValidationError("--satellite picks from an element file, not from an OEM")
        orbit = read_oem(spec)
    elif Path(spec).is_file():
        orbit = Orbit.from_file(spec, args.satellite)
    else:
        if args.satellite:
            raise ValidationError("--satellite picks from an element file; --elements is a name")
        if not spec.strip():
            raise ValidationError(
                f"--elements: got {spec!r}; give a TLE or OMM file or a catalog orbit "
                "('sbrdf-xr catalog list --kind orbit')"
            )
        try:
            orbit = Orbit.from_catalog(spec)
        except SbrdfError as exc:
            raise ValidationError(f"--elements {spec}: {exc}") from None
    site = _site_of(args)
    if (args.stop is None) == (args.duration is None):
        raise ValidationError("give --stop UTC or --duration S (the end of the window)")
    start = to_datetime64(args.start, "--start")
    if args.duration is not None:
        if not (math.isfinite(args.duration) and 0 < args.duration <= MAX_DURATION_S):
            raise ValidationError(
                f"--duration: got {args.duration:g} s; allowed a finite duration > 0 and at "
                f"most {MAX_DURATION_S:g} s ({MAX_DURATION_S / 86400 / 365.25:.3g} years)"
            )
        stop = start + np.timedelta64(round(args.duration * 1e9), "ns")
    else:
        stop = to_datetime64(args.stop, "--stop")
    window = float((stop - start) / np.timedelta64(1, "ns")) * 1e-9
    if not (math.isfinite(args.step) and args.step > 0):
        raise ValidationError(f"--step: got {args.step:g} s; allowed a finite step > 0 s")
    if window > 0 and args.step > window:
        raise ValidationError(
            f"--step: got {args.step:g} s, longer than the {window:g} s window; allowed a "
            "step > 0 and at most the window (or give --duration / --stop a longer window)"
        )
    return Observation(
        orbit,
        site,
        times(start, stop, args.step),
        attitude_of(args, spacecraft),
        min_elevation=args.min_elevation,
        name=args.name or f"{orbit.name} from {site.name}",
        earth=args.earth,
    )


def cmd_observe(args: argparse.Namespace) -> int:
    """``sbrdf-xr observe``: simulate a pass and write its cube (and figure); returns 0.

    Examples
    --------
    A site where the object is below the horizon for the whole window is refused, with
    the time it next rises:

    >>> from sbrdf_xr.cli import main
    >>> main(["observe", "--elements", "canx1-example", "--site", "haleakala",
    ...       "--start", "2024-03-17T01:20:00", "--duration", "300", "-o", "p.nc",
    ...       "--plan"])  # doctest: +SKIP
    sbrdf-xr: error: ... below 0 deg elevation at every time ...; it next rises above 0 deg
    at 2024-03-17T06:13:16 UTC ...
    2
    """
    from ..engine import Scene
    from ..engine.run import simulate
    from ..store import formats
    from .commands import _save_figure, _with_body, spacecraft_of

    if not args.plan:  # every output is refused (a special file, ...) before the pass runs
        fmt = formats.check(args.output, "cube", overwrite=args.overwrite)
        if args.plot:
            formats.check(args.plot, "figure", overwrite=args.overwrite)
    body = spacecraft_of(args)
    obs = observation_of(args, body)
    bands = () if [b.lower() for b in args.bands] == ["none"] else tuple(args.bands)
    outputs = ("spacecraft_sbrdf", "signal", "brdf", "area") + (("band_signal",) if bands else ())
    scene = Scene(
        body,
        observation=obs,
        outputs=outputs,
        bands=bands,
        name=obs.name,
        description=f"sbrdf-xr observe: {obs!r}",
    )
    if args.material:  # the tables of --material for the body already loaded
        keep = {"spacecraft": None, "mesh_material": None, "material_map": None}
        scene = _with_body(scene, argparse.Namespace(**{**vars(args), **keep, "length_unit": None}))
    plan = scene.plan()
    if args.plan or not args.quiet:  # --quiet: the result lines only
        print(plan)
    if args.plan:
        return 0
    path = fmt.writer(
        simulate(plan), Path(args.output), overwrite=args.overwrite, progress=not args.quiet
    )
    print(f"wrote {path}")
    if args.plot:
        _save_figure(
            path, args.plot, overwrite=args.overwrite, bands=tuple(bands) or ("V", "R", "I")
        )
    return 0
