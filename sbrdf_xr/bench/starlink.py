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
  BRDF).

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


def predict_starlink(table: Any = None, **scene_options: Any) -> xr.Dataset:
    """Predicted and observed AB magnitudes at every row of ``table`` (module docstring).

    Parameters
    ----------
    table : TrackingTable, optional
        With the column ``ab_magnitude``; default :func:`pomenis_table`.
    **scene_options
        ``shadowing``, ``earthshine``, ``materials`` of :func:`starlink_scene`.

    Returns
    -------
    xarray.Dataset
        Over ``time``: ``magnitude_observed``, ``magnitude_model`` (sunlight and, if on,
        earthshine), ``magnitude_sunlight``, ``magnitude_sphere``, ``signal_chassis`` and
        ``signal_array`` [m2 sr-1], with the coordinates ``phase_angle``, ``elevation``,
        ``site_sun_elevation``, ``range``, ``sunlit_fraction``.  Magnitudes are AB in
        Bessell V (``band`` attribute), before any zero point.

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
    total = sun + cube["signal_earthshine"] if "signal_earthshine" in cube else sun
    geo = ("phase_angle", "elevation", "site_sun_elevation", "range", "sunlit_fraction")
    coords = {k: cube[k] for k in geo}
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
        "magnitude_sunlight": "predicted AB magnitude: sunlight only",
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
        sphere_area_albedo_m2=SPHERE_AREA_ALBEDO,
        source=table.source,
    )
    return out
