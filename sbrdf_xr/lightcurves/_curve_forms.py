"""The shapes measured light curves come in: column names, wide tables, times, fluxes.

:func:`resolve_roles` finds the columns by the names observers give them
(:data:`ROLES`); :func:`wide_columns` finds the per-band columns of a wide table
(``V, V_err, R, R_err``; ``mag_V, e_mag_V``; ``flux_V, flux_V_err``);
:func:`utc_times` reads ISO 8601 strings, astropy ``Time`` columns, Julian and modified
Julian dates in a stated time scale; :func:`flux_magnitudes` turns flux densities into
AB magnitudes.  Used by :func:`sbrdf_xr.lightcurves.read_light_curve`.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

import numpy as np

from ..errors import LightCurveError

#: Column role -> the names it goes by (compared without regard to case).
ROLES: dict[str, tuple[str, ...]] = {
    "time": (
        "time",
        "utc",
        "time_utc",
        "date_obs",
        "date-obs",
        "dateobs",
        "datetime",
        "obs_time",
    ),
    "rotation_angle": ("rotation_angle",),
    "band": ("band", "filter", "filt", "passband", "bandpass", "filter_name"),
    "magnitude": ("magnitude", "mag"),
    "uncertainty": (
        "uncertainty",
        "mag_err",
        "magerr",
        "mag_error",
        "e_mag",
        "err",
        "error",
        "sigma",
        "mag_unc",
        "sigma_mag",
        "magnitude_error",
        "magnitude_uncertainty",
    ),
    "flux": ("flux", "flux_density"),
    "flux_uncertainty": ("flux_err", "flux_error", "e_flux", "flux_unc", "flux_uncertainty"),
    "system": ("system", "mag_system", "magnitude_system", "photometric_system"),
    "range_km": ("range_km",),
    "range": ("range",),
    "phase_angle": ("phase_angle",),
    "airmass": ("airmass", "air_mass"),
}

#: Time scales a Julian date or a zone-less ISO time may be stated in (astropy names).
TIME_SCALES = ("utc", "tai", "tt", "tdb", "tcg", "tcb")

_JD = re.compile(r"^(m?jd)(?:[_-]?(obs))?(?:[_-](utc|tai|tt|tdb|tcg|tcb))?$", re.IGNORECASE)
_HELIO = re.compile(r"^(?:h|b)jd", re.IGNORECASE)
_TZ = re.compile(r"(Z|[+-]\d\d:?\d\d)$", re.IGNORECASE)
_E = r"(?:err|error|unc|uncertainty|sigma)"
#: (kind, pattern) tried in order on the columns of a wide table; ``b`` is the band.
_WIDE = (
    ("flux_err", re.compile(rf"^flux[_-](?P<b>.+?)[_-]{_E}$|^(?P<c>.+?)[_-]flux[_-]{_E}$")),
    ("flux_err", re.compile(rf"^(?:e|{_E})[_-]flux[_-](?P<b>.+)$|^flux[_-]{_E}[_-](?P<c>.+)$")),
    ("flux", re.compile(r"^flux[_-](?P<b>.+)$|^(?P<c>.+?)[_-]flux$")),
    ("mag_err", re.compile(rf"^(?:mag[_-])?(?P<b>.+?)[_-]?(?:mag)?[_-]?{_E}$")),
    ("mag_err", re.compile(rf"^(?:e|{_E})[_-](?:mag[_-])?(?P<b>.+)$")),
    ("mag", re.compile(r"^mag[_-](?P<b>.+)$|^(?P<c>.+?)[_-]?mag$")),
)


def resolve_roles(columns: list[str], where: str) -> dict[str, str]:
    """Role -> column, from the names of :data:`ROLES` and Julian-date columns.

    Julian dates go by ``jd``/``mjd`` (``_obs``, then a scale: ``mjd_tai``) and are
    reported as the roles ``jd``/``mjd``; heliocentric and barycentric dates are refused.

    Examples
    --------
    >>> resolve_roles(["MJD", "Filter", "mag", "mag_err"], "t.csv")
    {'mjd': 'MJD', 'band': 'Filter', 'magnitude': 'mag', 'uncertainty': 'mag_err'}
    """
    found: dict[str, str] = {}
    for col in columns:
        key = col.strip().lower()
        for role, names in ROLES.items():
            if key in names:
                if role in found:
                    raise LightCurveError(
                        f"{where}: columns {found[role]!r} and {col!r} both hold the {role}; "
                        "keep one"
                    )
                found[role] = col
        m = _JD.match(col.strip())
        if m:
            role = m.group(1).lower()
            if role in found:
                raise LightCurveError(
                    f"{where}: columns {found[role]!r} and {col!r} both hold a {role.upper()}"
                )
            found[role] = col
        elif _HELIO.match(col.strip()):
            raise LightCurveError(
                f"{where}: column {col!r} holds heliocentric or barycentric dates: times at "
                "the Sun or the barycentre, not at the observer of a spacecraft; give UTC "
                "times (time, jd_utc or mjd_utc)"
            )
    return found


def jd_scale(column: str) -> str | None:
    """The time scale a Julian-date column's name states (``mjd_tai`` -> ``tai``), if any.

    Examples
    --------
    >>> jd_scale("MJD_TAI"), jd_scale("jd"), jd_scale("mjd_obs_utc")
    ('tai', None, 'utc')
    """
    m = _JD.match(column.strip())
    return m.group(3).lower() if m and m.group(3) else None


def wide_columns(
    columns: list[str], is_band: Callable[[str], bool], where: str
) -> tuple[list[tuple[str, str, str, str]], list[str]]:
    """The band columns of a wide table: ``(band as written, value, uncertainty, kind)``.

    ``kind`` is ``"mag"`` or ``"flux"``.  A bare column counts as a band when
    ``is_band`` says so or when an uncertainty column names it (``Clear``, ``Clear_err``:
    the caller then refuses the unknown filter by name); every band's value column needs
    its uncertainty column and the other way round.  Returns the bands and the columns
    left unused.

    Examples
    --------
    >>> bands, unused = wide_columns(["V", "V_err", "e_R", "R", "seeing"], lambda b: b in "VR",
    ...                              "t.csv")
    >>> bands, unused
    ([('V', 'V', 'V_err', 'mag'), ('R', 'R', 'e_R', 'mag')], ['seeing'])
    """
    parsed: dict[tuple[str, str], str] = {}
    bare: dict[str, str] = {}
    for col in columns:
        name = col.strip()
        for kind, pat in _WIDE:
            m = pat.match(name)
            if m:
                gd = m.groupdict()
                b = gd.get("b") or gd.get("c") or ""
                if kind.endswith("_err") or is_band(b):
                    parsed.setdefault((b, kind), col)
                    break
        else:
            if is_band(name):
                parsed.setdefault((name, "mag"), col)
            else:
                bare[name] = col
    bands: list[tuple[str, str, str, str]] = []
    used: set[str] = set()
    keys = [k for k in parsed if not k[1].endswith("_err")]
    keys += [(b, k.removesuffix("_err")) for b, k in parsed if k.endswith("_err")]
    for b, base in dict.fromkeys(keys):
        value = parsed.get((b, base)) or (bare.get(b) if base == "mag" else None)
        err = parsed.get((b, base + "_err"))
        if err is None:
            raise LightCurveError(
                f"{where}: column {value!r} ({base} in band {b!r}) has no uncertainty column; "
                f"name it {b + '_err'!r} (or e_{b}, {b}_unc, sigma_{b})"
            )
        if value is None:
            if is_band(b):
                raise LightCurveError(
                    f"{where}: column {err!r} is an uncertainty in band {b!r}, but no column "
                    f"holds the {base} itself (name it {b!r})"
                )
            continue  # an uncertainty of something else (seeing_err): not photometry
        used.update((value, err))
        bands.append((b, value, err, base))
    return bands, [c for c in columns if c not in used]


def utc_times(
    raw: Any, role: str, column: str, unit: Any, scale: str | None, row_name: Callable[[int], str]
) -> tuple[np.ndarray, str]:
    """UTC datetime64[ns] of a time column, and how it was read.

    ``role`` is ``time`` (ISO 8601 strings, with a zone or in ``scale``; or already
    UTC ISO strings of an astropy ``Time`` column, ``unit == "utc"``), ``jd`` or ``mjd``
    (numbers in ``scale``, converted by astropy).

    Examples
    --------
    >>> t, how = utc_times(["60386.0", "60386.5"], "mjd", "mjd", None, "tai", str)
    >>> t.astype("datetime64[s]").tolist()[0], how
    (datetime.datetime(2024, 3, 16, 23, 59, 23), 'MJD (column mjd) in TAI, converted to UTC')
    """
    import pandas as pd
    from astropy.time import Time

    text = pd.Series(raw).astype(str).str.strip()
    if role in ("jd", "mjd"):
        values = pd.to_numeric(text, errors="coerce").to_numpy(dtype=np.float64)
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise LightCurveError(
                f"{row_name(int(bad[0]))}, column {column!r}: {text.iloc[bad[0]]!r} is not a "
                f"{role.upper()}"
            )
        if scale is None:
            raise LightCurveError(
                f"column {column!r} holds {'modified ' if role == 'mjd' else ''}Julian dates "
                "but no time scale is stated (UTC? TAI? TT?): name the column "
                f"{role}_utc, pass time_scale='utc', or state it in the table metadata "
                "(time_scale or TIMESYS)"
            )
        t = Time(values, format=role, scale=scale).utc
        how = f"{role.upper()} (column {column}) in {scale.upper()}, converted to UTC"
        return np.asarray(t.datetime64, dtype="datetime64[ns]"), how
    if unit == "utc":
        return pd.to_datetime(text, format="ISO8601").to_numpy("datetime64[ns]"), (
            f"astropy Time column {column!r}, converted to UTC"
        )
    tt = pd.to_datetime(text, utc=True, errors="coerce", format="ISO8601")
    nat = np.flatnonzero(tt.isna().to_numpy())
    if nat.size:
        raise LightCurveError(
            f"{row_name(int(nat[0]))}, column {column!r}: value {text.iloc[nat[0]]!r} is "
            "neither a number of seconds nor an ISO 8601 time"
        )
    naive = np.array([not _TZ.search(v) for v in text])
    if naive.any() and scale is None:
        k = int(np.flatnonzero(naive)[0])
        raise LightCurveError(
            f"{row_name(k)}, column {column!r}: {text.iloc[k]!r} has no time zone and "
            "cannot be read as UTC; write it as ISO 8601 with 'Z' or an offset "
            "(2024-01-01T00:00:00Z), or pass time_scale='utc' (table metadata time_scale: utc)"
        )
    out = tt.dt.tz_convert("UTC").dt.tz_localize(None).to_numpy(dtype="datetime64[ns]")
    how = f"ISO 8601 times (column {column})"
    if naive.any() and scale != "utc":
        conv = Time(out[naive].astype("datetime64[ns]"), scale=scale).utc
        out[naive] = np.asarray(conv.datetime64, dtype="datetime64[ns]")
        how += f"; those without a zone in {str(scale).upper()}, converted to UTC"
    return out, how


def flux_magnitudes(
    flux: np.ndarray, sigma: np.ndarray, unit: Any, pivot_nm: np.ndarray, what: str
) -> tuple[np.ndarray, np.ndarray, str]:
    """AB magnitudes and their uncertainties from flux densities with a unit.

    ``m = -2.5 log10(f_nu / 3631 Jy)`` (Oke & Gunn 1983) and ``sigma_m = 2.5 / ln 10
    sigma_f / f`` (first order); a flux per unit wavelength becomes ``f_nu = f_lambda
    lambda_p^2 / c`` at the band's pivot wavelength ``lambda_p`` (exact for band-averaged
    flux densities, Tokunaga & Vacca 2005, PASP 117, 421).

    Examples
    --------
    >>> import astropy.units as u
    >>> m, s, how = flux_magnitudes(np.array([3631.0]), np.array([36.31]), u.Jy,
    ...                             np.array([550.0]), "flux")
    >>> m.round(6).tolist(), s.round(6).tolist()
    ([0.0], [0.010857])
    """
    import astropy.units as u

    if unit is None:
        raise LightCurveError(
            f"{what}: fluxes without a unit cannot be magnitudes; give the column a unit "
            "(ECSV, FITS, VOTable: e.g. mJy or erg s-1 cm-2 Hz-1) or the table metadata "
            "flux_unit, or give magnitudes"
        )
    unit = u.Unit(unit)
    bad = np.flatnonzero(~(flux > 0))
    if bad.size:
        raise LightCurveError(
            f"{what}: flux {flux[bad[0]]:g} {unit} at observation {int(bad[0])} is not > 0, "
            "so it has no magnitude; drop the row or give magnitudes"
        )
    equiv = u.spectral_density(np.asarray(pivot_nm) * u.nm)
    try:
        jy = (flux * unit).to_value(u.Jy, equivalencies=equiv)
        sjy = (sigma * unit).to_value(u.Jy, equivalencies=equiv)
    except u.UnitConversionError:
        raise LightCurveError(
            f"{what}: unit {unit} is not a flux density (per frequency or per wavelength)"
        ) from None
    m = -2.5 * np.log10(jy / 3631.0)
    s = 2.5 / np.log(10.0) * np.abs(sjy) / jy
    return m, s, f"flux densities in {unit} as AB magnitudes, -2.5 log10(f_nu / 3631 Jy)"
