"""Filter names as observers write them, mapped to the package's bands.

Observers label their photometry ``V``, ``Johnson V``, ``Bessell-V``, ``Rc``, ``Cousins
I``, ``r'``, ``sdss_g`` ...; :func:`band_label` maps each spelling to the band the
simulation uses: the aliases of :data:`~sbrdf_xr.photometry.bands.BAND_ALIASES`
(``U B V R I``: the Bessell 1990 curves, which realise Johnson UBV and Cousins RI;
``u g r i z``: SDSS 2010) or a speclite filter name.

Two mappings are refused on purpose, with the reason: Johnson's own R and I (their
passbands differ from the Cousins R and I of the Bessell curves by colour terms of a
tenth of a magnitude), and a bare ``v`` or ``b`` (Stromgren or Johnson?).  A
``band_map`` states what such a name means.  The primed u'g'r'i'z' of the USNO standard
system (Smith et al. 2002, AJ 123, 2121) are taken as the SDSS 2010 curves: the two
differ by a few hundredths of a magnitude, which a per-band zero point absorbs.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence

from ..errors import LightCurveError
from ..photometry import BAND_ALIASES, speclite_names

__all__ = ["band_label", "known_bands_text"]

_SYSTEMS_UBVRI = r"(?:johnson[-_ ]?cousins|bessell|cousins|johnson|landolt|jc|kron[-_ ]?cousins)"
_SYSTEMS_UGRIZ = r"(?:sdss|sloan|usno)"
_SEP = r"[-_ .:/]*"

#: Johnson's R and I are not Cousins' (Bessell 1990, PASP 102, 1181, section 3).
_JOHNSON_RI = re.compile(rf"^johnson{_SEP}([RI])$|^([RI]){_SEP}j$", re.IGNORECASE)
_UBVRI = re.compile(rf"^(?:{_SYSTEMS_UBVRI}{_SEP})?([UBVRI])(?:{_SEP}(?:c|j))?$", re.IGNORECASE)
_UGRIZ = re.compile(rf"^(?:{_SYSTEMS_UGRIZ}{_SEP})?([ugriz])('|prime)?$", re.IGNORECASE)


def known_bands_text() -> str:
    """The bands :func:`band_label` knows, in words, for messages.

    Examples
    --------
    >>> known_bands_text()[:49]
    'U B V R I (Bessell 1990: Johnson UBV, Cousins RI;'
    """
    return (
        "U B V R I (Bessell 1990: Johnson UBV, Cousins RI; also written 'Johnson V', "
        "'Bessell-V', 'Cousins R', 'Rc', 'I_C'), u g r i z (SDSS 2010; also r', 'sdss-r', "
        "'sloan_g'), or a speclite filter name (sbrdf_xr.photometry.speclite_names(), "
        "e.g. 'decam2014-r')"
    )


def band_label(
    name: str,
    *,
    band_map: Mapping[str, str] | None = None,
    bands: Sequence[str] | None = None,
) -> str:
    """The package's band for a filter name as an observer writes it.

    Parameters
    ----------
    name : str
        The filter name (``"V"``, ``"Johnson V"``, ``"Bessell-V"``, ``"Rc"``, ``"r'"``,
        ``"SDSS g"``, ``"bessell-I"``, ``"decam2014-r"``, ...).
    band_map : mapping, optional
        Names of your own -> band (tried first, exactly): ``{"Clear": "V"}``.
    bands : sequence of str, optional
        Labels accepted as they are (user bandpasses of the simulation).

    Returns
    -------
    str
        An alias of :data:`~sbrdf_xr.photometry.bands.BAND_ALIASES` (``"V"``, ``"r"``)
        or a speclite filter name.

    Raises
    ------
    LightCurveError
        For an unknown name, Johnson R or I, or an ambiguous bare ``v``/``b``; the
        message lists the known bands (:func:`known_bands_text`).

    Examples
    --------
    >>> [band_label(n) for n in ("V", "Johnson V", "Bessell-V", "Cousins R", "Rc", "I_C")]
    ['V', 'V', 'V', 'R', 'R', 'I']
    >>> [band_label(n) for n in ("r'", "sdss-g", "SDSS i'", "z", "bessell-B", "decam2014-r")]
    ['r', 'g', 'i', 'z', 'B', 'decam2014-r']
    >>> band_label("Clear", band_map={"Clear": "V"})
    'V'
    >>> band_label("Johnson R")
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.LightCurveError: filter 'Johnson R': Johnson's own R differs from the ...
    >>> band_label("H-alpha")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.LightCurveError: filter 'H-alpha': not a band the package knows; known: ...
    """
    raw = str(name)
    text = raw.strip().replace("\u2019", "'").replace("\u2032", "'").strip('"')
    if band_map and raw in band_map:
        return band_label(band_map[raw], bands=bands)
    if bands is not None and text in bands:
        return text
    if text in BAND_ALIASES:
        return text
    names = speclite_names()
    lower = {n.lower(): n for n in names}
    if text.lower() in lower:
        found = lower[text.lower()]
        back = {v: k for k, v in BAND_ALIASES.items()}
        return back.get(found, found)
    if _JOHNSON_RI.match(text):
        raise LightCurveError(
            f"filter {raw!r}: Johnson's own {text.strip()[-1].upper()} differs from the "
            "Cousins R and I of the package's Bessell curves by colour terms of about 0.1 mag "
            "(Bessell 1990, PASP 102, 1181); if your filter is Cousins, say so "
            f"(band_map={{{raw!r}: 'R'}} or 'I'), else give its bandpass"
        )
    if text in ("v", "b"):
        raise LightCurveError(
            f"filter {raw!r}: ambiguous (Johnson {text.upper()} or Stromgren {text}?); write "
            f"{text.upper()!r} for Johnson/Bessell, or map it with band_map={{{raw!r}: ...}}"
        )
    m = _UBVRI.match(text)
    if m and (text[0].isupper() or len(text) > 1):
        return m.group(1).upper()
    m = _UGRIZ.match(text)
    if m and (text[0].islower() or len(text) > 1):
        return m.group(1).lower()
    raise LightCurveError(
        f"filter {raw!r}: not a band the package knows; known: {known_bands_text()}"
        + (f"; or one of {sorted(bands)}" if bands else "")
        + f"; map your own names with band_map={{{raw!r}: 'V'}}"
    )
