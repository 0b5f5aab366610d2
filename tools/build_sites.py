"""Write the surveillance and survey observatories of ``catalogs/observe/sites.toml``.

Run ``python tools/build_sites.py`` to (re)write the block of MPC sites at the end of
``catalogs/observe/sites.toml`` and the matching ``[[entry]]`` tables of
``catalogs/index.toml`` (between their ``# MPC sites`` markers).

Each site is the Minor Planet Center's List of Observatory Codes entry (code, east
longitude [degree], parallax constants ``rho cos phi'`` and ``rho sin phi'`` in Earth
equatorial radii; https://minorplanetcenter.net/iau/lists/ObsCodes.html), converted to
WGS84 geodetic latitude and height with astropy's ``EarthLocation.from_geocentric``
taking the equatorial radius as 6378.137 km.  Constants given to 5 decimals fix the
position to about +-32 m (6 decimals: +-3 m), so the heights are good to tens of metres
(a few millidegrees of elevation for a LEO pass at its lowest).
"""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SITES = ROOT / "sbrdf_xr" / "catalogs" / "observe" / "sites.toml"
if not SITES.exists():  # a source checkout keeps the catalogs at the top
    SITES = ROOT / "catalogs" / "observe" / "sites.toml"
INDEX = SITES.parent.parent / "index.toml"

#: Equatorial radius the parallax constants are scaled by [km] (WGS84).
EQUATORIAL_RADIUS_KM = 6378.137

#: key -> (MPC code, longitude [degree east], rho cos phi', rho sin phi', MPC name, what it is)
MPC_SITES: dict[str, tuple[str, float, float, float, str, str]] = {
    "haleakala-amos": (
        "608",
        203.7420,
        0.93623,
        +0.35156,
        "Haleakala-AMOS",
        "Air Force Maui Optical and Supercomputing site (AMOS), Haleakala, Maui: space "
        "surveillance telescopes of the Maui Space Surveillance Complex",
    ),
    "haleakala-geodss": (
        "566",
        203.7424,
        0.93623,
        +0.35156,
        "Haleakala-NEAT/GEODSS",
        "GEODSS station of Maui (Ground-based Electro-Optical Deep Space Surveillance), Haleakala",
    ),
    "pan-starrs": (
        "F51",
        203.74409,
        0.936241,
        +0.351543,
        "Pan-STARRS 1, Haleakala",
        "Pan-STARRS 1 survey telescope, Haleakala, Maui",
    ),
    "socorro-ets": (
        "704",
        253.34093,
        0.831869,
        +0.553542,
        "Lincoln Laboratory ETS, New Mexico",
        "MIT Lincoln Laboratory Experimental Test Site near Socorro, New Mexico (LINEAR), "
        "beside the Socorro GEODSS station",
    ),
    "atom-site-sst": (
        "G45",
        253.63564,
        0.832748,
        +0.552480,
        "Space Surveillance Telescope, Atom Site",
        "DARPA Space Surveillance Telescope at the Atom Site, White Sands Missile Range, "
        "New Mexico (2011-2017)",
    ),
    "zimmerwald": (
        "026",
        7.46511,
        0.684884,
        +0.726402,
        "Berne-Zimmerwald",
        "Zimmerwald Observatory of the University of Bern (ZIMLAT, space debris and "
        "satellite laser ranging), Switzerland",
    ),
    "tenerife-ogs": (
        "J04",
        343.48817,
        0.881463,
        +0.471461,
        "ESA Optical Ground Station, Tenerife",
        "ESA Optical Ground Station (1 m, space debris surveys), Teide Observatory, Tenerife",
    ),
    "teide": (
        "954",
        343.4906,
        0.88148,
        +0.47142,
        "Teide Observatory",
        "Teide Observatory (IAC), Izana, Tenerife",
    ),
    "siding-spring": (
        "413",
        149.06608,
        0.855595,
        -0.516262,
        "Siding Spring Observatory",
        "Siding Spring Observatory, New South Wales",
    ),
    "siding-spring-survey": (
        "E12",
        149.0642,
        0.85563,
        -0.51621,
        "Siding Spring Survey",
        "Siding Spring Survey telescope (Catalina Sky Survey), New South Wales",
    ),
    "cerro-pachon": (
        "I11",
        289.26345,
        0.865020,
        -0.500901,
        "Gemini South Observatory, Cerro Pachon",
        "Cerro Pachon, Chile (Gemini South; the Rubin Observatory's mountain)",
    ),
    "cerro-tololo": (
        "807",
        289.1941,
        0.86560,
        -0.49980,
        "Cerro Tololo Observatory, La Serena",
        "Cerro Tololo Inter-American Observatory, Chile",
    ),
    "la-silla": (
        "809",
        289.26626,
        0.873440,
        -0.486052,
        "European Southern Observatory, La Silla",
        "ESO La Silla Observatory, Chile",
    ),
    "paranal": (
        "309",
        289.59569,
        0.909943,
        -0.414336,
        "Cerro Paranal",
        "ESO Paranal Observatory, Chile",
    ),
    "las-campanas": (
        "304",
        289.2980,
        0.87559,
        -0.48217,
        "Las Campanas Observatory",
        "Las Campanas Observatory, Chile",
    ),
    "mount-lemmon": (
        "G96",
        249.21128,
        0.845111,
        +0.533614,
        "Mt. Lemmon Survey",
        "Mount Lemmon Survey telescope (Catalina Sky Survey), Arizona",
    ),
    "catalina": (
        "703",
        249.26736,
        0.845315,
        +0.533213,
        "Catalina Sky Survey",
        "Catalina Sky Survey telescope, Mount Bigelow, Arizona",
    ),
    "palomar": (
        "675",
        243.13746,
        0.836357,
        +0.546831,
        "Palomar Mountain",
        "Palomar Observatory, California (ZTF)",
    ),
    "mauna-kea": (
        "568",
        204.5278,
        0.94171,
        +0.33725,
        "Mauna Kea",
        "Maunakea Observatories, Hawaii",
    ),
}

MARK = "# MPC sites: written by python tools/build_sites.py (do not edit by hand below)"


def geodetic(lon_deg: float, rho_cos: float, rho_sin: float) -> tuple[float, float, float]:
    """WGS84 geodetic latitude, east longitude in [-180, 180) [degree] and height [m]."""
    import astropy.units as u
    import numpy as np
    from astropy.coordinates import EarthLocation

    lon = np.radians(lon_deg)
    x, z = rho_cos * EQUATORIAL_RADIUS_KM, rho_sin * EQUATORIAL_RADIUS_KM
    loc = EarthLocation.from_geocentric(x * np.cos(lon), x * np.sin(lon), z, unit=u.km)
    g = loc.to_geodetic("WGS84")
    return float(g.lat.deg), (lon_deg + 180.0) % 360.0 - 180.0, float(g.height.to_value(u.m))


def _digits(x: float) -> int:
    text = f"{abs(x):.6f}".rstrip("0")
    return len(text.split(".")[1])


def main() -> None:
    site_lines = [MARK, ""]
    index_lines = [MARK, ""]
    for key, (code, lon, rc, rs, mpc_name, what) in MPC_SITES.items():
        lat, lon_e, h = geodetic(lon, rc, rs)
        tol = 32 if min(_digits(rc), _digits(rs)) <= 5 else 3
        coords = f"{abs(lat):.5f} {'N' if lat >= 0 else 'S'}, {abs(lon_e):.5f} "
        coords += f"{'E' if lon_e >= 0 else 'W'}, {h:.0f} m"
        source = (
            f"Minor Planet Center, List of Observatory Codes: {code} {mpc_name!r}, longitude "
            f"{lon} E, rho cos phi' {rc}, rho sin phi' {rs:+}; converted to WGS84 geodetic "
            f"coordinates (a = {EQUATORIAL_RADIUS_KM} km, astropy EarthLocation), about "
            f"+-{tol} m from the rounding of the constants"
        )
        site_lines += [
            f"[{key}]",
            f"latitude_deg = {lat:.5f}",
            f"longitude_deg = {lon_e:.5f}",
            f"height_m = {h:.0f}.0",
            f'mpc = ["{code}", {lon}, {rc}, {rs}]',
            f'source = "{source}"',
            "",
        ]
        index_lines += [
            "[[entry]]",
            f'name = "{key}"',
            'kind = "site"',
            'path = "observe/sites.toml"',
            'source = "measured"',
            f'description = "{what}: {coords} (MPC {code})."',
            f'provenance = "{source}."',
            "",
        ]
    for path, lines in ((SITES, site_lines), (INDEX, index_lines)):
        text = path.read_text(encoding="utf-8")
        head = text.split(MARK)[0].rstrip("\n")
        path.write_text(head + "\n\n" + "\n".join(lines).rstrip("\n") + "\n", encoding="utf-8")
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
