"""colour-science spectra in and out, and the band integrals against colour-science's own.

The band signal ``S_band = int E T lambda S dl / int E T lambda dl`` (photon counting) of
the package's exact quadrature (``quadrature="linear"``: the product of the linear
interpolants of S, the Sun E and the filter T, integrated exactly at their native nodes) is
recomputed with colour-science's integration (``colour.sd_to_XYZ(..., method="Integration",
k=1)``: ``k sum S E cmf dl`` on a uniform grid, each input interpolated linearly onto it),
with ``T lambda`` as the "colour-matching function".
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from sbrdf_xr import photometry as P

with np.printoptions():  # colour-science switches numpy to legacy printing on import
    import colour

BANDS = ["V", "R", "I", "sdss2010-r"]
#: colour-science reports each alignment of an input to the integration grid (asked for here)
#: and the rounding of a grid step to fit the band's bounds.
pytestmark = pytest.mark.filterwarnings("ignore::colour.utilities.ColourRuntimeWarning")


def _spectrum(wl):
    """A smooth, structured spectrum: a slope, a dip at 700 nm and a 37 nm ripple."""
    return (
        (1 + 4e-4 * (wl - 550))
        * (1 - 0.3 * np.exp(-(((wl - 700) / 40) ** 2)))
        * (1 + 0.2 * np.sin(wl / 37.0))
    )


@pytest.fixture(scope="module")
def cube():
    wl = np.arange(400.0, 1101.0, 5.0)
    return xr.Dataset(
        {"signal": (("geometry", "wavelength"), _spectrum(wl)[None], {"units": "m2 sr-1"})},
        coords={"wavelength": ("wavelength", wl, {"units": "nm"})},
    )


def _linear(values, wl, name=""):
    return colour.SpectralDistribution(
        values, wl, name=name, interpolator=colour.LinearInterpolator
    )


def _colour_band_signal(cube, band, step):
    """S_band by colour-science's integration on a uniform grid of ``step`` nm."""
    sun = P.solar_spectrum()  # native ASTM G173 nodes
    f = P.filters([band])
    tw, tr = f.wavelength.values, f.values[0]
    nz = np.flatnonzero(tr > 0)
    shape = colour.SpectralShape(tw[max(nz[0] - 1, 0)], tw[min(nz[-1] + 1, tw.size - 1)], step)
    grid = shape.wavelengths
    weight = np.interp(grid, tw, tr) * grid  # photon counting: T lambda
    cmfs = colour.MultiSpectralDistributions(
        np.stack([weight] * 3, 1), grid, labels=["x", "y", "z"],
        interpolator=colour.LinearInterpolator,
    )  # fmt: skip
    ill = _linear(sun.values, sun.wavelength.values, "ASTM G173")
    wl = cube.wavelength.values
    s = _linear(cube.signal.values[0], wl, "S")
    one = _linear(np.ones_like(wl), wl, "1")
    kw = {"cmfs": cmfs, "illuminant": ill, "k": 1, "method": "Integration", "shape": shape}
    return colour.sd_to_XYZ(s, **kw)[0] / colour.sd_to_XYZ(one, **kw)[0]


@pytest.mark.parametrize("band", BANDS)
def test_band_integrals_agree_with_colour_science(cube, band):
    """colour-science's sum converges on the package's exact quadrature.

    Its uniform sum of a function that vanishes at both ends is the trapezoid rule, whose
    error is O(step**2): measured 1.2e-5 relative at 1 nm and 3e-6 at 0.5 nm, so about
    2e-7 at 0.125 nm; the tolerance (2e-6 relative, 0.002 mmag) leaves a factor 10, and
    the error must shrink at least threefold from 0.5 to 0.125 nm (ideally 16x).
    """
    exact = float(P.band_signal(cube, [band], quadrature="linear").values[0, 0])
    coarse = _colour_band_signal(cube, band, 0.5)
    fine = _colour_band_signal(cube, band, 0.125)
    assert abs(exact / fine - 1) < 2e-6
    assert abs(exact / fine - 1) * 3 < abs(exact / coarse - 1)


@pytest.mark.parametrize("band", BANDS)
def test_the_default_trapezoid_is_within_a_millimagnitude(cube, band):
    """The default quadrature takes S at its 5 nm nodes with the Sun's hat averages: for
    this spectrum 0.07-0.32 mmag from the exact integral (measured), held to 1 mmag."""
    trapezoid = float(P.band_signal(cube, [band]).values[0, 0])
    fine = _colour_band_signal(cube, band, 0.125)
    assert abs(2.5 * np.log10(trapezoid / fine)) < 1e-3


def test_filters_as_spectral_distributions(cube):
    own = {b: P.filters([b]) for b in ("V", "R")}  # each on its own native nodes
    sds = [_linear(own[b].values[0], own[b].wavelength.values, f"my-{b}") for b in ("V", "R")]
    f = P.filters(["V", "R"])  # both on the union of their nodes
    msds = colour.MultiSpectralDistributions(
        f.values.T, f.wavelength.values, labels=["my-V", "my-R"]
    )
    named = P.band_signal(cube, ["V", "R"]).values
    for given in (sds, msds, {"my-V": sds[0], "my-R": sds[1]}, [("my-V", sds[0]), "R"]):
        got = P.band_signal(cube, given)
        np.testing.assert_allclose(got.values, named, rtol=1e-13)
    assert P.band_signal(cube, sds).band.values.tolist() == ["my-V", "my-R"]
    assert P.filters(msds).filter.values.tolist() == ["user:my-V", "user:my-R"]


def test_a_solar_spectrum_as_a_spectral_distribution(cube):
    sun = P.solar_spectrum()
    sd = _linear(sun.values, sun.wavelength.values, "my-sun")
    np.testing.assert_allclose(
        P.magnitudes(cube, ["V", "I"], 1000.0, solar=sd).values,
        P.magnitudes(cube, ["V", "I"], 1000.0).values,
        rtol=1e-13,
    )
    key = P.solar_name(sd)
    assert key.startswith("user:my-sun:") and key in P.SOLAR_SPECTRA
    phot = P.photometry(cube, ["V", "R"], 1000.0, solar=sd)  # by object, then by its name
    again = P.photometry(cube, ["V", "R"], 1000.0, solar=key)
    np.testing.assert_array_equal(phot.magnitude.values, again.magnitude.values)
    assert P.band_weights(["V"], cube.wavelength.values, solar=sd).attrs["solar_spectrum"] == key
    half = _linear(sun.values / 2, sun.wavelength.values, "half-sun")
    dim = P.sun_magnitudes(["V"], solar=half).values - P.sun_magnitudes(["V"]).values
    np.testing.assert_allclose(dim, 2.5 * np.log10(2.0), rtol=1e-12)  # half the light


def test_solar_spectra_that_are_refused():
    sun = P.solar_spectrum([500.0, 600.0])
    with pytest.raises(ValueError, match="W m-2 nm-1"):
        P.solar_name(sun.assign_attrs(units="erg s-1 cm-2 A-1"))
    with pytest.raises(ValueError, match="non-negative"):
        P.solar_name(sun * -1)
    with pytest.raises(ValueError, match="SpectralDistribution"):
        P.solar_name(3.0)
    with pytest.raises(ValueError, match="unknown 'sunn'"):
        P.solar_name("sunn")


def test_spectra_as_spectral_distributions(cube):
    s = _linear(cube.signal.values[0], cube.wavelength.values, "S")
    np.testing.assert_array_equal(P.srgb(s).values, P.srgb(cube).isel(geometry=0).values)
    banded = P.pre_integrate(s, ["V"])
    np.testing.assert_allclose(banded.values, P.band_signal(cube, ["V"]).values[0], rtol=1e-13)
    # band signals and magnitudes take the SpectralDistribution as they take the cube
    np.testing.assert_allclose(
        P.band_signal(s, ["V", "R"]).values, P.band_signal(cube, ["V", "R"]).values[0], rtol=1e-13
    )
    np.testing.assert_allclose(
        P.magnitudes(s, ["V", "R"], range=1e3).values,
        P.magnitudes(cube, ["V", "R"], range=1e3).values[0],
        rtol=1e-13,
    )


def test_cubes_export_and_come_back(cube):
    two = xr.concat([cube, cube * 2], "attitude").assign_coords(attitude=[0, 5])
    msds = two.sbrdf.to_colour()
    assert isinstance(msds, colour.MultiSpectralDistributions)
    assert msds.labels == ["attitude=0, geometry=0", "attitude=5, geometry=0"]
    back = P.from_colour(msds, dim="spectrum")
    np.testing.assert_array_equal(back.values[1], two.signal.values[1, 0])
    np.testing.assert_array_equal(back.wavelength.values, cube.wavelength.values)
    sd = P.to_colour(cube.signal.isel(geometry=0))
    assert isinstance(sd, colour.SpectralDistribution) and sd.name == "signal"
    np.testing.assert_array_equal(P.from_colour(sd).values, cube.signal.values[0])
    with pytest.raises(ValueError, match="over 'wavelength'"):
        P.to_colour(cube.signal.isel(wavelength=0))
