"""sRGB swatches of the reflected sunlight (colour-science colorimetry)."""

from __future__ import annotations

from importlib.metadata import version as _pkg_version

import numpy as np
import xarray as xr

from .._names import WAVELENGTH, attrs
from .colour_science import as_spectrum
from .magnitude import _signal_of
from .spectra import _choose, solar_spectrum

_CMFS = "CIE 1931 2 Degree Standard Observer"


# ------------------------------------------------------------------- colour


def _interp_matrix(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """(n_dst, n_src) matrix of linear interpolation with constant extrapolation."""
    p = np.zeros((dst.size, src.size))
    if src.size == 1:
        p[:, 0] = 1.0
        return p
    d = np.clip(dst, src[0], src[-1])
    j = np.clip(np.searchsorted(src, d, side="right") - 1, 0, src.size - 2)
    f = (d - src[j]) / (src[j + 1] - src[j])
    rows = np.arange(dst.size)
    p[rows, j] = 1.0 - f
    p[rows, j + 1] += f
    return p


def srgb(
    source: xr.Dataset | xr.DataArray,
    *,
    variable: str = "signal",
    white: str = "sun",
    normalise: str = "each",
) -> xr.DataArray:
    """sRGB swatches of the reflected sunlight (signal x solar spectrum).

    The spectrum ``S(lambda)`` is resampled linearly to 360-830 nm in 5 nm steps (held
    constant past its ends), taken as the reflectance factor of an object lit by the
    ASTM G173-03 Sun, and converted to CIE XYZ with the CIE 1931 2-degree observer by
    colour-science (``colour.msds_to_XYZ``, the vectorised ``sd_to_XYZ``, method
    ``Integration``): ``XYZ = k int S E_sun cmf dlambda``, ``k`` such that ``S = 1``
    gives ``Y = 100``.  Then ``colour.XYZ_to_sRGB``:

    * ``white="sun"`` (default): chromatic adaptation (CAT02) from the Sun's white
      point to D65, as an eye adapted to sunlight sees it - a spectrally flat
      reflector is neutral grey;
    * ``white="D65"``: no adaptation - the colour of the reflected light itself on a
      D65 display (the Sun appears slightly warm).

    Parameters
    ----------
    source : xarray.Dataset, DataArray or colour-science spectrum
        A cube (its ``variable``), spectra over ``wavelength``, or a colour-science
        ``SpectralDistribution`` / ``MultiSpectralDistributions``.
    variable : str
        Cube variable.
    white : {"sun", "D65"}
    normalise : {"each", "global"}
        ``each``: every swatch scaled so its largest linear channel is 1 (hue and
        saturation only); ``global``: one factor for all, the largest channel of the
        set is 1 (relative brightness kept).  Negative (out-of-gamut) linear values
        are clipped to 0 before the sRGB transfer function.  Black for zero spectra.

    Returns
    -------
    xarray.DataArray
        ``srgb`` [1] over the spectra's other dims plus ``rgb`` (R, G, B), encoded
        with the sRGB transfer function, in [0, 1].  Computed eagerly (loads the data).

    Examples
    --------
    >>> import xarray as xr
    >>> wl = np.arange(300.0, 1101.0, 10.0)
    >>> grey = np.full((2, wl.size), 0.1)  # 0.1 m2 sr-1 at every wavelength, two geometries
    >>> cube = xr.Dataset({"signal": (("geometry", "wavelength"), grey, {"units": "m2 sr-1"})},
    ...                   coords={"wavelength": ("wavelength", wl, {"units": "nm"})})
    >>> rgb = srgb(cube)
    >>> rgb.dims, np.round(rgb.isel(geometry=0).values, 3)  # a grey body under the Sun: white
    (('geometry', 'rgb'), array([1., 1., 1.]))
    """
    with np.printoptions():  # colour-science switches numpy to legacy printing on import
        import colour

    _choose(white, {"sun": "", "D65": ""}, "white")
    _choose(normalise, {"each": "", "global": ""}, "normalise")
    s = _signal_of(as_spectrum(source), variable)
    other = [d for d in s.dims if d != WAVELENGTH]
    s = s.transpose(*other, WAVELENGTH)
    wl = np.asarray(s[WAVELENGTH].values, dtype=np.float64)
    grid = np.arange(360.0, 831.0, 5.0)
    shape = colour.SpectralShape(360, 830, 5)
    vals = np.asarray(s.values, dtype=np.float64) @ _interp_matrix(wl, grid).T
    sun = solar_spectrum(grid, method="average").values
    cmfs = colour.MSDS_CMFS[_CMFS].copy().align(shape)  # 1931 CMFs at their 5 nm nodes (no warning)
    ill = colour.SpectralDistribution(sun, grid, name="ASTM G173-03 AM0")
    xyz = (
        colour.msds_to_XYZ(vals, cmfs=cmfs, illuminant=ill, method="Integration", shape=shape)
        / 100.0
    )
    d65 = colour.CCS_ILLUMINANTS[_CMFS]["D65"]
    if white == "sun":
        xyz_w = (
            colour.msds_to_XYZ(
                np.ones((1, grid.size)),
                cmfs=cmfs,
                illuminant=ill,
                method="Integration",
                shape=shape,
            )[0]
            / 100.0
        )
        rgb = colour.XYZ_to_sRGB(
            xyz,
            illuminant=colour.XYZ_to_xy(xyz_w),
            chromatic_adaptation_transform="CAT02",
            apply_cctf_encoding=False,
        )
    else:
        rgb = colour.XYZ_to_sRGB(
            xyz, illuminant=d65, chromatic_adaptation_transform=None, apply_cctf_encoding=False
        )
    rgb = np.clip(np.asarray(rgb, dtype=np.float64), 0.0, None)
    if normalise == "each":
        scale = rgb.max(axis=-1, keepdims=True)
    else:
        scale = np.full((*rgb.shape[:-1], 1), rgb.max() if rgb.size else 0.0)
    rgb = np.divide(rgb, scale, out=np.zeros_like(rgb), where=scale > 0)
    enc = np.asarray(
        colour.cctf_encoding(np.clip(rgb, 0.0, 1.0), function="sRGB"), dtype=np.float64
    )
    coords = {k: v for k, v in s.coords.items() if WAVELENGTH not in v.dims}
    coords["rgb"] = ("rgb", ["R", "G", "B"])
    return xr.DataArray(
        enc,
        dims=(*other, "rgb"),
        coords=coords,
        name="srgb",
        attrs=attrs(
            "srgb",
            white=white,
            normalise=normalise,
            colorimetry=f"{_CMFS}, CIE XYZ -> sRGB (IEC 61966-2-1) by colour-science "
            f"{_pkg_version('colour-science')}; illuminant: ASTM G173-03 AM0 Sun",
        ),
    )
