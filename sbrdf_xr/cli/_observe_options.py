"""The options of ``sbrdf-xr observe``, by group (used by
:func:`sbrdf_xr.cli.observe.add_observe_parser`)."""

from __future__ import annotations

import argparse
from typing import Any


def orbit_and_site(po: argparse.ArgumentParser) -> None:
    """The elements or tracking table, the site and the Earth."""
    g = po.add_argument_group("orbit and site")
    g.add_argument(
        "--elements",
        metavar="FILE|NAME",
        help="a TLE file (2- or 3-line sets), an OMM file (.json, .xml, .csv), a CCSDS "
        "OEM file (states) or a catalog orbit ('sbrdf-xr catalog list --kind orbit')",
    )
    g.add_argument(
        "--tracking",
        metavar="FILE",
        help="instead of --elements and the window: an observer's tracking table (CSV: "
        "columns time, elevation, azimuth [degree] and range or height [km]; "
        "--tracking-format pomenis: the Pomenis Starlink table at its own site)",
    )
    g.add_argument(
        "--tracking-format",
        choices=("csv", "pomenis"),
        default="csv",
        help="the tracking table's layout (default csv)",
    )
    g.add_argument("--utc", action="store_true", help="tracking csv: zoneless times are UTC")
    g.add_argument(
        "--satellite",
        metavar="NAME|NUMBER",
        help="which satellite of an element file holding several",
    )
    g.add_argument(
        "--site", metavar="NAME", help="a catalog observatory ('sbrdf-xr catalog list --kind site')"
    )
    g.add_argument("--lat", type=float, metavar="DEG", help="geodetic latitude [degree]")
    g.add_argument("--lon", type=float, metavar="DEG", help="east longitude [degree]")
    g.add_argument(
        "--height",
        type=float,
        default=0.0,
        metavar="M",
        help="height above the WGS84 ellipsoid [m] (default 0)",
    )
    g.add_argument(
        "--min-elevation",
        type=float,
        default=0.0,
        metavar="DEG",
        help="elevation below which the object counts as not observable",
    )
    g.add_argument(
        "--earth",
        choices=("wgs84", "sphere"),
        default="wgs84",
        help="the Earth that casts the shadow (default wgs84)",
    )


def utc_window(po: argparse.ArgumentParser) -> None:
    """The UTC window and its step [s]."""
    w = po.add_argument_group("UTC window")
    w.add_argument("--start", metavar="UTC", help="first time, ISO 8601 UTC (not with --tracking)")
    w.add_argument("--stop", metavar="UTC", help="last time (or --duration)")
    w.add_argument("--duration", type=float, metavar="S", help="length of the window [s]")
    w.add_argument("--step", type=float, default=1.0, metavar="S", help="time step [s]")


def attitude_law(po: argparse.ArgumentParser, law_names: tuple[str, ...]) -> None:
    """The attitude law and its parameters."""
    a = po.add_argument_group("attitude law")
    a.add_argument(
        "--attitude",
        choices=law_names,
        default="nadir",
        help="the law of sbrdf_xr.observing.attitude (default nadir)",
    )
    a.add_argument(
        "--quaternion",
        type=float,
        nargs=4,
        metavar=("X", "Y", "Z", "W"),
        help="inertial: body-to-GCRS quaternion, scalar last",
    )
    a.add_argument("--yaw", type=float, default=0.0, metavar="DEG", help="nadir: yaw [degree]")
    a.add_argument(
        "--nadir-axis",
        default="+z",
        metavar="AXIS",
        help="nadir: body axis on the geocentre (+z, or x,y,z; a negative one as --nadir-axis=-z)",
    )
    a.add_argument(
        "--velocity-axis", default="+x", metavar="AXIS", help="nadir: body axis along track"
    )
    a.add_argument(
        "--sun-axis", default="+z", metavar="AXIS", help="sun-pointing: body axis on the Sun"
    )
    a.add_argument(
        "--secondary-axis",
        default="+x",
        metavar="AXIS",
        help="sun-pointing: body axis turned to the secondary target",
    )
    a.add_argument(
        "--secondary-target",
        default="orbit_normal",
        metavar="orbit_normal|nadir|velocity|north",
        help="sun-pointing: the secondary target",
    )
    a.add_argument("--spin-axis", default="+z", metavar="AXIS", help="spin: body axis")
    a.add_argument("--period", type=float, metavar="S", help="spin: rotation period [s]")
    a.add_argument("--rate", type=float, metavar="DEG_S", help="spin: rate [degree s-1]")
    a.add_argument(
        "--phase", type=float, default=0.0, metavar="DEG", help="spin: angle at the epoch [degree]"
    )
    a.add_argument(
        "--initial",
        metavar="LAW|X,Y,Z,W",
        help="spin, tumble: the attitude at angle 0: a quaternion, or (spin) "
        "'nadir' or 'sun-pointing' to spin about a pointing law",
    )
    a.add_argument("--epoch", metavar="UTC", help="spin, tumble: time of --phase / --initial")
    a.add_argument(
        "--omega",
        type=float,
        nargs=3,
        metavar=("WX", "WY", "WZ"),
        help="tumble: initial body rates [degree s-1]",
    )
    a.add_argument(
        "--inertia",
        type=float,
        nargs=3,
        metavar=("IXX", "IYY", "IZZ"),
        help="tumble: principal moments [kg m2] (or --density)",
    )
    a.add_argument(
        "--density",
        type=float,
        metavar="KG_M3",
        help="tumble: inertia of the mesh filled at this uniform density",
    )
    a.add_argument(
        "--series", metavar="FILE", help="series: quaternions over time (.csv, .nc, CCSDS .aem)"
    )


def spacecraft_and_output(po: argparse.ArgumentParser, mesh_options: Any) -> None:
    """The spacecraft, its materials, the bands and the output files."""
    s = po.add_argument_group("spacecraft and output")
    s.add_argument(
        "--spacecraft",
        default="canx1",
        metavar="NAME|MESH",
        help="a catalog spacecraft (default canx1) or a mesh file",
    )
    mesh_options(s)
    s.add_argument(
        "--material",
        action="append",
        metavar="MATERIAL=NAME|FILE.nc",
        help="the table of a material: a catalog name or a netCDF file (repeatable)",
    )
    s.add_argument(
        "--bands",
        nargs="+",
        default=["V", "R", "I"],
        help="bands of the band signal (default V R I); 'none' for spectra only",
    )
    s.add_argument("--name", help="name of the observation (default: satellite at site)")
    s.add_argument("-o", "--output", required=True, help="cube file to write (.nc or .zarr)")
    s.add_argument("--plot", metavar="FIG.png", help="also write the light-curve figure")
    s.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    s.add_argument("--plan", action="store_true", help="print the plan and stop")
    s.add_argument(
        "-q", "--quiet", action="store_true", help="no plan (unless --plan) and no progress bar"
    )
