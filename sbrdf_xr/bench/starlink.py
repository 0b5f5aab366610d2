"""Real Starlink magnitudes: the built-in Starlink v1.5-class body at 1,173 Pomenis observations.

The observations (``catalogs/observe/pomenis-starlink-v1.5``, MIT licence; Fankhauser,
Askari & Tyson 2023, arXiv:2305.11123) give per row the UTC time, the height, the altitude
and azimuth of a Starlink v1.5 satellite seen from Mount Lemmon, and its AB magnitude.
:func:`starlink_scene` simulates at every row, with the package's own parts:

* geometry: :func:`~sbrdf_xr.observing.tracking_io.read_pomenis` (the site at 32.4434 N,
  110.7881 W and 2789 m, the range from the height above the WGS84 ellipsoid), the Sun
  from skyfield's DE421;
* body: :func:`~sbrdf_xr.body.starlink.starlink_v15`, the chassis (3.64 m2) on the
  geodetic nadir and the 22.68 m2 array turning about the vertical toward the Sun
  (:class:`~sbrdf_xr.body.parts.SunTracking`); attitude
  :class:`~sbrdf_xr.observing.attitude.YawSteering` (``-z`` on the geodetic nadir, ``+y``
  toward the Sun: the frame of the paper, and one that needs no velocity, which a single
  row of a table cannot give), so the array's normal is horizontal toward the Sun's
  azimuth as the paper's data description says; the array is one-sided (its back is not
  in the description);
* materials: the tables the catalog builds from the two laboratory in-plane scans at 532 nm
  (``starlink-v1.5-chassis``, ``starlink-v1.5-solar-array``);
* effects: sunlight scaled by the Earth's shadow (WGS84, finite Sun), exact self-shadowing
  and self-occlusion between chassis and array, and earthshine from a Lambertian Earth of
  Bond albedo 0.3 of finite size (the package's ``earthshine`` effect with its default
  ``earth_model="finite"``: each facet's irradiance integrated over the sunlit Earth its
  horizon sees, the BRDF taken at the direction of the Earth's centre; no measured Earth
  BRDF);
* the atmosphere at the Earth's limb (``predict_starlink(atmosphere=True)``, the
  default): near the edge of the Earth's shadow the satellite's sunlight has crossed
  the atmosphere low over the limb; :func:`limb_sunlight` gives its refraction and
  extinction (:mod:`sbrdf_xr.photometry.limb`: US Standard Atmosphere 1976, Rayleigh
  and ozone in V, averaged over the Sun's disc), which replaces the solid Earth's
  sunlit fraction.  On these rows the ray's lowest point is 0.1-553 km up; at the 74
  below 40 km the sunlight is dimmed by 0.1 to 3.8 mag.  Nothing in it is fitted to the
  magnitudes.

Band: the scans are at 532 nm and the surfaces are taken as grey, so the tables are
continued as constants (``band_extrapolate="constant"``) and the magnitudes are AB in the
Bessell V band: for a grey body the band signal is the 532 nm signal, and the choice of
band only moves every magnitude by the same amount (the Sun's V magnitude against its
flux density at 532 nm, which the paper's code, lumos-sat, converts with), which the one
free zero point of :func:`~sbrdf_xr.lightcurves.agreement.compare_magnitudes` absorbs.

:func:`predict_starlink` returns, per row, the observed magnitude, the model's (sunlight
plus earthshine), its sunlight-only part, and the diffuse-sphere control (a Lambert sphere
of albedo-area product 0.65 m2, the paper's fit; Russell 1916's phase function), with the
geometry (phase angle, elevation, the Sun's elevation at the site, range).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from ..engine.scene import Scene
from ..errors import ValidationError

__all__ = [
    "POMENIS_DATA",
    "SPHERE_AREA_ALBEDO",
    "STARLINK_TABLES",
    "limb_sunlight",
    "pomenis_table",
    "predict_starlink",
    "starlink_scene",
]

#: The Pomenis table inside the package's catalogs.
POMENIS_DATA = "observe/pomenis-starlink-v1.5/pomenis_observations.csv"
#: Body material -> catalog table built from the laboratory scan.
STARLINK_TABLES = {
    "starlink-chassis": "starlink-v1.5-chassis",
    "starlink-solar-array": "starlink-v1.5-solar-array",
}
#: Albedo-area product of the diffuse-sphere control [m2] (the paper's fit, 0.649 m2).
SPHERE_AREA_ALBEDO = 0.65

_BAND = "V"


def pomenis_table(
    path: str | Path | None = None, *, on_bad: str = "raise", rows: slice | None = None
) -> Any:
    """The Pomenis observations as a :class:`~sbrdf_xr.observing.tracking.TrackingTable`.

    Parameters
    ----------
    path : str or Path, optional
        A Pomenis CSV; default the shipped table (:data:`POMENIS_DATA`).
    on_bad : {"raise", "drop"}
        A bad row raises naming its line, or is left out, counted and listed.
    rows : slice, optional
        Keep these rows (in time order) only.

    Examples
    --------
    >>> table = pomenis_table()
    >>> table.times.size, table.dropped, table.site.height
    (1173, (), 2789.0)
    >>> pomenis_table(rows=slice(0, 3)).rows.tolist()  # the file's lines, in time order
    [20, 19, 25]
    """
    from ..catalog import data_path
    from ..observing.tracking import TrackingTable
    from ..observing.tracking_io import read_pomenis

    table = read_pomenis(data_path(POMENIS_DATA) if path is None else path, on_bad=on_bad)
    if rows is None:
        return table
    return TrackingTable(
        table.site,
        table.times[rows],
        elevation=table.elevation[rows],
        azimuth=table.azimuth[rows],
        height=table.height[rows],
        rows=table.rows[rows],
        columns={k: np.asarray(v)[rows] for k, v in table.columns.items()},
        dropped=table.dropped,
        name=table.name,
        source=table.source,
    )


def starlink_scene(
    table: Any = None,
    *,
    shadowing: bool = True,
    earthshine: bool = True,
    materials: dict[str, Any] | None = None,
) -> Scene:
    """The scene of the module docstring at every row of ``table``.

    Parameters
    ----------
    table : TrackingTable, optional
        Default :func:`pomenis_table`.
    shadowing, earthshine : bool
        Include self-shadowing and earthshine.
    materials : mapping, optional
        Tables for ``starlink-chassis`` and ``starlink-solar-array``; default the
        catalog's (:data:`STARLINK_TABLES`).

    Examples
    --------
    >>> plan = starlink_scene(pomenis_table(rows=slice(0, 3))).plan()
    >>> plan.effects
    ('sunlight', 'shadowing', 'eclipse', 'earthshine')
    >>> print(dict(plan.steps)["parts"])  # doctest: +ELLIPSIS
    solar-array (2 facets): sun-tracking about [0.0, 0.0, 1.0] ...
    """
    from ..body.starlink import starlink_v15
    from ..catalog import load
    from ..observing.attitude import YawSteering

    table = pomenis_table() if table is None else table
    if materials is None:
        materials = {k: load(v) for k, v in STARLINK_TABLES.items()}
    missing = sorted(set(STARLINK_TABLES) - set(materials))
    if missing:
        raise ValidationError(
            f"starlink_scene: no table for {missing}; give {sorted(STARLINK_TABLES)}"
        )
    effects = ("sunlight",) + (("shadowing",) if shadowing else ())
    effects += ("earthshine",) if earthshine else ()
    obs = table.observation(YawSteering(nadir_axis="-z", sun_axis="+y", vertical="geodetic"))
    return Scene(
        starlink_v15(back=False),
        dict(materials),
        observation=obs,
        outputs=("signal", "per_material"),
        effects=effects,
        band_extrapolate="constant",
        name="starlink-v1.5-pomenis",
        description="Starlink v1.5-class body (laboratory-scan tables) at the Pomenis rows",
    )


def _mags(signal: xr.DataArray) -> xr.DataArray:
    from ..photometry import magnitudes

    return magnitudes(signal, _BAND, system="AB", extrapolate="constant")


def limb_sunlight(table: Any = None) -> xr.Dataset:
    """The sunlight that reaches the satellite of every row through the Earth's limb.

    The satellite's position (the table's, rotated to the ITRS by skyfield) and the
    Sun's (DE421) give the straight ray toward the Sun
    (:func:`~sbrdf_xr.photometry.limb.limb_ray`); its refraction and extinction by the
    atmosphere, averaged over the Sun's disc, give the factor on the sunlight
    (:func:`~sbrdf_xr.photometry.limb.limb_transmission` in V: 550 nm, ozone 0.03).

    Parameters
    ----------
    table : TrackingTable, optional
        Default :func:`pomenis_table`.

    Returns
    -------
    xarray.Dataset
        Over ``time``: ``tangent_height`` and ``limb_distance`` [km], ``limb_transmission``
        [1].

    Examples
    --------
    Of the first rows, the first passes 352 km above the Earth, the 29th grazes it at 22 km
    and keeps 31 % of the sunlight (the mean Sun distance of the rows sets the disc):

    >>> limb = limb_sunlight(pomenis_table(rows=slice(0, 29, 28)))
    >>> limb.tangent_height.values.round(1), limb.limb_transmission.values.round(3)
    (array([352.1,  22.2]), array([1.   , 0.313]))
    """
    from skyfield.framelib import itrs

    from ..observing.timescales import skyfield_data, skyfield_time
    from ..photometry.limb import limb_ray, limb_transmission

    table = pomenis_table() if table is None else table
    _, eph = skyfield_data()
    t = skyfield_time(np.asarray(table.times))
    rot = itrs.rotation_at(t)
    sun = np.einsum(
        "ijn,jn->ni", rot, np.reshape((eph["sun"] - eph["earth"]).at(t).position.km, (3, -1))
    )
    sat = np.einsum("ijn,nj->ni", rot, table.positions())
    height, distance = limb_ray(sat, sun - sat)
    # the Sun's angular radius at the rows' mean distance (+-1.7 % over the year)
    radius = np.degrees(np.arcsin(695700.0 / np.mean(np.linalg.norm(sun - sat, axis=1))))
    trans = limb_transmission(height, distance, wavelength=550.0, sun_radius=radius)
    return xr.Dataset(
        {
            "tangent_height": (
                "time",
                height,
                {
                    "units": "km",
                    "long_name": "least height above WGS84 of the straight ray to the Sun",
                },
            ),
            "limb_distance": (
                "time",
                distance,
                {
                    "units": "km",
                    "long_name": "distance from the ray's lowest point to the satellite",
                },
            ),
            "limb_transmission": (
                "time",
                trans,
                {
                    "units": "1",
                    "long_name": "sunlight through the Earth's limb (refraction, Rayleigh, ozone), "
                    "per unit sunlight",
                },
            ),
        },
        coords={"time": np.asarray(table.times)},
    )


def predict_starlink(
    table: Any = None, *, atmosphere: bool = True, **scene_options: Any
) -> xr.Dataset:
    """Predicted and observed AB magnitudes at every row of ``table`` (module docstring).

    Parameters
    ----------
    table : TrackingTable, optional
        With the column ``ab_magnitude``; default :func:`pomenis_table`.
    atmosphere : bool
        Dim the sunlight by the Earth's limb (:func:`limb_sunlight`), in place of the
        solid Earth's sunlit fraction of the Sun's disc.
    **scene_options
        ``shadowing``, ``earthshine``, ``materials`` of :func:`starlink_scene`.

    Returns
    -------
    xarray.Dataset
        Over ``time``: ``magnitude_observed``, ``magnitude_model`` (sunlight through the
        limb if ``atmosphere``, and, if on, earthshine), ``magnitude_sunlight`` (the
        sunlight part), ``magnitude_sphere``, ``signal_chassis`` and ``signal_array``
        [m2 sr-1] (sunlight in the solid Earth's shadow), with the coordinates
        ``phase_angle``, ``elevation``, ``site_sun_elevation``, ``range``,
        ``sunlit_fraction`` and, if ``atmosphere``, ``tangent_height`` and
        ``limb_transmission``.  Magnitudes are AB in Bessell V (``band`` attribute),
        before any zero point.

    Examples
    --------
    >>> out = predict_starlink(pomenis_table(rows=slice(0, 3)))
    >>> out.magnitude_observed.values.round(2).tolist()
    [7.83, 4.86, 7.07]
    >>> bool(np.isfinite(out.magnitude_model).all()), out.attrs["band"][:14]
    (True, 'AB, Bessell V;')
    """
    from ..engine.run import simulate

    table = pomenis_table() if table is None else table
    if "ab_magnitude" not in table.columns:
        raise ValidationError(
            f"predict_starlink: the table has no column 'ab_magnitude' (it has "
            f"{sorted(table.columns)}); read it with read_pomenis or keep=('ab_magnitude',)"
        )
    scene = starlink_scene(table, **scene_options)
    cube = simulate(scene).compute()
    sun = cube["signal"]
    geo = ("phase_angle", "elevation", "site_sun_elevation", "range", "sunlit_fraction")
    coords = {k: cube[k] for k in geo}
    if atmosphere:
        limb = limb_sunlight(table)
        # the limb's factor holds the solid Earth's cut of the disc: the sunlit fraction
        # the eclipse effect applied is taken out (no row is in the umbra, where it is 0)
        frac = np.asarray(cube["sunlit_fraction"].values)
        factor = np.divide(
            limb.limb_transmission.values, frac, out=np.zeros_like(frac), where=frac > 0
        )
        sun = sun * xr.DataArray(factor, dims="time")
        for k in ("tangent_height", "limb_transmission"):
            coords[k] = xr.DataArray(limb[k].values, dims="time", attrs=limb[k].attrs)
    total = sun + cube["signal_earthshine"] if "signal_earthshine" in cube else sun
    alpha = np.asarray(cube["phase_angle"].values)
    from ..photometry import lambert_sphere_phase

    sphere = sun.copy(
        data=(SPHERE_AREA_ALBEDO / np.pi * lambert_sphere_phase(alpha))[:, None]
        * np.clip(cube["sunlit_fraction"].values, 0.0, 1.0)[:, None]
    )
    per = cube["signal_material"].isel(wavelength=0, drop=True)
    out = xr.Dataset(
        {
            "magnitude_observed": (
                "time",
                np.asarray(table.columns["ab_magnitude"], dtype=np.float64),
                {"units": "1", "long_name": "observed AB magnitude (Pomenis)"},
            ),
            "magnitude_model": _mags(total).isel(band=0, drop=True),
            "magnitude_sunlight": _mags(sun).isel(band=0, drop=True),
            "magnitude_sphere": _mags(sphere).isel(band=0, drop=True),
            "signal_chassis": per.sel(material="starlink-chassis", drop=True),
            "signal_array": per.sel(material="starlink-solar-array", drop=True),
        },
        coords=coords,
    )
    long = {
        "magnitude_model": "predicted AB magnitude: sunlight and earthshine",
        "magnitude_sunlight": "predicted AB magnitude: sunlight only"
        + (" (through the limb)" if atmosphere else ""),
        "magnitude_sphere": "AB magnitude of the diffuse (Lambert) sphere control",
        "signal_chassis": "radiometric signal of the chassis, sunlight",
        "signal_array": "radiometric signal of the solar array, sunlight",
    }
    for k, text in long.items():
        out[k].attrs.update(long_name=text, units="1" if k.startswith("mag") else "m2 sr-1")
    out.attrs.update(
        band=f"AB, Bessell {_BAND}; grey tables from the 532 nm scans",
        effects=", ".join(scene.plan().effects),
        earthshine="Lambertian Earth, Bond albedo 0.3, finite disc (earth_model finite)",
        attitude="YawSteering: -z on the geodetic nadir, +y toward the Sun; array sun-tracking",
        atmosphere=(
            "sunlight through the Earth's limb: refraction, Rayleigh and ozone (V, US "
            "Standard Atmosphere 1976), over the Sun's disc"
            if atmosphere
            else "none: the solid Earth's shadow"
        ),
        sphere_area_albedo_m2=SPHERE_AREA_ALBEDO,
        source=table.source,
    )
    return out
