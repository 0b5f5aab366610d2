"""Inputs of the bad-input tour: scene text, and files spoilt in the ways users spoil them.

Every factory writes into a directory it is given and returns the path; the tour's
cases then hand the path to the package.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
from bad_input_tour import SECRET

GREY = "lambertian-grey-50"
#: A valid scene, cheap to load (the grey table for every material of CanX-1).
BASE = {
    "name": "bad-input",
    "spacecraft": "canx1",
    "phase_angles": [10.0, 30.0],
    "outputs": ["spacecraft_sbrdf", "signal", "brdf", "area"],
    "chunk": 4,
    "attitude": {"kind": "sweep", "axis": [0, 0, 1], "start": 0, "stop": 20, "step": 5},
    "materials": {m: GREY for m in ("aluminium-6061-t6", "tjpv-cell", "white-paint-a276")},
}
#: A valid observation, cheap to compute (seven times over a minute of the shipped pass).
OBSERVATION = {
    "orbit": "canx1-example",
    "site": "mont-megantic",
    "start": "2024-03-17T01:22:00",
    "stop": "2024-03-17T01:23:00",
    "step_s": 10.0,
    "attitude": {"law": "nadir"},
}


def toml_value(v) -> str:
    """TOML text of a Python value (inline tables for dicts)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def toml_text(d: dict) -> str:
    plain = [f"{json.dumps(k)} = {toml_value(v)}" for k, v in d.items() if not isinstance(v, dict)]
    tables = [
        f"\n[{json.dumps(k)}]\n"
        + "\n".join(f"{json.dumps(a)} = {toml_value(b)}" for a, b in v.items())
        for k, v in d.items()
        if isinstance(v, dict)
    ]
    return "\n".join(plain) + "\n" + "\n".join(tables) + "\n"


def write_toml(path: Path, d: dict) -> Path:
    text = toml_text(d)
    try:
        path.write_text(text, encoding="utf-8")
    except UnicodeEncodeError:  # a lone surrogate: not writable as UTF-8, write its bytes
        path.write_bytes(text.encode("utf-8", "surrogatepass"))
    return path


def copy_of(d: dict) -> dict:
    return json.loads(json.dumps(d))


# ------------------------------------------------------------------ special files

SPECIAL = ("missing", "directory", "fifo", "dev-zero-link", "dangling-link", "empty", "secret")
#: What a message about each special file must say.
EXPECTED_SPECIAL = {
    "missing": "does not exist|no such file",
    "directory": "directory",
    "fifo": "FIFO|pipe",
    "dev-zero-link": "device",
    "dangling-link": "does not exist|dangling|broken",
    "empty": "empty",
}


def special_file(d: Path, kind: str, suffix: str) -> Path:
    """A path of ``kind`` (:data:`SPECIAL`) ending in ``suffix``."""
    p = d / f"{kind}{suffix}"
    if p.exists() or p.is_symlink():
        return p
    if kind == "directory":
        p.mkdir()
    elif kind == "fifo":
        os.mkfifo(p)
    elif kind == "dev-zero-link":
        p.symlink_to("/dev/zero")
    elif kind == "dangling-link":
        p.symlink_to(d / "nowhere" / "x")
    elif kind == "empty":
        p.write_bytes(b"")
    elif kind == "secret":
        p.write_text(f"{SECRET}\n{SECRET}\n", encoding="utf-8")
    return p


def spoil(data: bytes, how: str, at: float, junk: bytes) -> bytes:
    """``data`` truncated, flipped or spliced with ``junk`` at the fraction ``at``."""
    k = int(len(data) * at)
    if how == "truncate":
        return data[:k]
    if how == "flip":
        b = bytearray(data)
        for i in range(k, min(len(b), k + max(1, len(junk)))):
            b[i] ^= 0xFF
        return bytes(b)
    if how == "splice":
        return data[:k] + junk + data[k:]
    if how == "junk":
        return junk
    raise ValueError(how)


# ------------------------------------------------------------------ meshes

MESH_FORMATS = (".stl", ".obj", ".ply", ".off", ".glb")


def box_bytes(suffix: str) -> bytes:
    import trimesh

    return trimesh.creation.box(extents=(1.0, 1.0, 1.0)).export(file_type=suffix[1:]) or b""


def mesh_bytes(suffix: str) -> bytes:
    data = box_bytes(suffix)
    return data.encode() if isinstance(data, str) else data


#: Broken surfaces, as OBJ text: what each one is.
BROKEN_OBJ = {
    "fin": (  # three facets on one edge: non-manifold
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 0 -1 0\n"
        "f 1 2 3\nf 1 2 4\nf 1 2 5\nf 1 3 4\nf 2 3 4\n"
    ),
    "open-box": "\n".join(
        [f"v {x} {y} {z}" for x in (0, 1) for y in (0, 1) for z in (0, 1)]
        + ["f 1 3 4", "f 1 4 2", "f 5 6 8", "f 5 8 7", "f 1 2 6", "f 1 6 5", "f 3 7 8"]
    )
    + "\n",
    "nan-vertex": "v nan 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n",
    "huge": "v 0 0 0\nv 1e300 0 0\nv 0 1e300 0\nv 0 0 1e300\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    "tiny": "v 0 0 0\nv 1e-30 0 0\nv 0 1e-30 0\nv 0 0 1e-30\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    "flat": "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\nf 1 3 2\nf 2 3 4\n",
    "one-triangle": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "bad-index": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
    "no-faces": "v 0 0 0\nv 1 0 0\nv 0 1 0\n",
    "inside-out": "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 4 2\nf 1 3 4\nf 2 4 3\n",
    "duplicate-facets": (
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 2 3 4\n"
    ),
    "degenerate": (
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 2 0 0\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 1 2 5\n"
    ),
    "tetra": "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
}


# ------------------------------------------------------------------ material files


def material_dataset():
    """A small valid material table as a Dataset (what ``to_netcdf`` writes)."""
    from sbrdf_xr.materials.schema import new_material

    ti = np.array([0.0, 30.0, 60.0, 90.0])
    dt = np.array([-180.0, -90.0, 0.0, 90.0])
    ph = np.array([0.0, 45.0, 90.0])
    wl = np.array([450.0, 550.0, 650.0])
    v = np.full((4, 4, 3, 3), 0.3 / np.pi)
    return new_material(
        v, ti, dt, ph, wl, material="bad-input", source="synthetic", provenance="tour"
    ).to_dataset()


#: Spoilt material tables: how each is spoilt (a function of the Dataset), and whether
#: the package must refuse (True) or may accept it with a warning (False).
@np.errstate(all="ignore")
def spoilt_material(kind: str, scale: float):
    ds = material_dataset()
    sb = ds["sbrdf"]
    if kind == "scaled-values":
        ds["sbrdf"] = sb * scale
    elif kind == "int-values":
        ds["sbrdf"] = (sb * 1000).astype("int32")
    elif kind == "nan-values":
        ds["sbrdf"] = sb.where(sb.theta_i != 30.0)
    elif kind == "negative-values":
        ds["sbrdf"] = sb - 1.0
    elif kind in ("theta_i", "delta_theta", "phi", "wavelength"):
        c = ds[kind]
        ds = ds.assign_coords({kind: (kind, c.values * scale, dict(c.attrs))})
    elif kind == "wavelength-shift":
        c = ds["wavelength"]
        ds = ds.assign_coords(wavelength=("wavelength", c.values + scale, dict(c.attrs)))
    elif kind == "unsorted":
        ds = ds.isel(theta_i=[0, 2, 1, 3])
    elif kind == "wrong-units":
        ds["wavelength"].attrs["units"] = "um"
    elif kind == "no-units":
        ds["sbrdf"].attrs.pop("units", None)
    elif kind == "renamed-variable":
        ds = ds.rename(sbrdf="reflectance")
    elif kind == "renamed-dim":
        ds = ds.rename(phi="azimuth")
    elif kind == "extra-dim":
        ds["sbrdf"] = sb.expand_dims(extra=2)
    elif kind == "string-values":
        ds["sbrdf"] = sb.astype(str)
    elif kind == "bad-source":
        ds.attrs["source"] = "rumour"
        ds["sbrdf"].attrs["source"] = "rumour"
    elif kind == "string-coord":
        ds = ds.assign_coords(phi=("phi", ["a", "b", "c"], {"units": "degree"}))
    else:
        raise ValueError(kind)
    return ds


MATERIAL_SPOILS = (
    "scaled-values",
    "int-values",
    "nan-values",
    "negative-values",
    "theta_i",
    "delta_theta",
    "phi",
    "wavelength",
    "wavelength-shift",
    "unsorted",
    "wrong-units",
    "no-units",
    "renamed-variable",
    "renamed-dim",
    "extra-dim",
    "string-values",
    "bad-source",
    "string-coord",
)


def measurement_dataset():
    from sbrdf_xr.testing import make_measurements

    return make_measurements(n_wavelength=3, theta_i=(20.0, 50.0))


@np.errstate(all="ignore")
def spoilt_measurements(kind: str, scale: float):
    ds = measurement_dataset()
    m = ds["measured_sbrdf"]
    if kind == "scaled-values":
        ds["measured_sbrdf"] = m * scale
    elif kind == "int-values":
        ds["measured_sbrdf"] = (m * 1000).astype("int32")
    elif kind == "nan-values":
        v = m.values.copy()
        v.flat[0] = np.nan
        ds["measured_sbrdf"] = m.copy(data=v)
    elif kind == "negative-values":
        ds["measured_sbrdf"] = m - 10.0
    elif kind in ds.coords or kind in ds.data_vars:
        v = ds[kind]
        if np.issubdtype(v.dtype, np.number):
            ds[kind] = v * scale
    elif kind == "drop-variable":
        ds = ds.drop_vars("measured_sbrdf")
    elif kind == "no-units":
        ds["measured_sbrdf"].attrs.pop("units", None)
    else:
        raise ValueError(kind)
    return ds


MEASUREMENT_SPOILS = (
    "scaled-values",
    "int-values",
    "nan-values",
    "negative-values",
    "theta_i",
    "delta_theta",
    "phi",
    "wavelength",
    "drop-variable",
    "no-units",
)
