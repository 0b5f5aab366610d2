"""RGL ``.bsdf`` spectral BRDF files (Dupuy & Jakob, ACM TOG 37(6), 274, 2018).

The EPFL RGL material database stores each material in Mitsuba's *tensor file*
format: the 12 bytes ``b"tensor_file\\0"``, a version ``(1, 0)`` (two ``uint8``), a
``uint32`` field count, then per field a ``uint16`` name length and the name, a
``uint16`` rank, a ``uint8`` type code (:data:`TENSOR_DTYPES`), a ``uint64`` byte
offset of the data and a ``uint64`` size per dimension, all little-endian; each
field's data, C order, at its offset.

A material file has the fields ``theta_i`` and ``phi_i`` (incidence nodes [rad]),
``wavelengths`` [nm], ``ndf`` (the microfacet distribution over ``(phi_m, theta_m)``
in the unit coordinates ``u = sqrt(2 theta / pi)``, ``v = (phi + pi) / 2 pi``),
``sigma`` (its projected area over the incidence direction), ``vndf`` and
``luminance`` (warps of the unit square per incidence node), ``spectra`` (the
reflectance sampled on the square the ``vndf`` warps, per incidence node and
wavelength), ``description`` and ``jacobian``.  The value at a pair of directions is
(Dupuy & Jakob 2018 §5, as the reference code ``powitacq`` and Mitsuba 3's
``measured`` plugin evaluate it)::

    f_r cos(theta_o) = spectra(vndf^-1(u_m)) * ndf(u_m) / (4 sigma(u_i))

with ``u_m`` the half vector's unit coordinates (azimuth relative to the incidence
azimuth for isotropic files), ``vndf^-1`` the inverse of the Marginal2D warp (a
piecewise-bilinear density on the square, its rows sampled by their marginal and its
columns by their conditional CDF, both interpolated linearly between incidence nodes)
and ``ndf``, ``sigma``, ``spectra`` interpolated bilinearly (the last factor only where
``jacobian`` is set).  :func:`read_rgl` samples the file on paper-000 rows, as
:func:`~sbrdf_xr.materials.merl.read_merl` does for MERL files; :func:`write_rgl`
writes a file from any BRDF (for tests and for renderers).
"""

from __future__ import annotations

import itertools
import os
import struct
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import MAX_FILE_BYTES, ValidationError
from ..units import to_unit
from .readers import Reader, measurement_set, register_reader

__all__ = [
    "RGL_FIELDS",
    "TENSOR_DTYPES",
    "TENSOR_MAGIC",
    "read_rgl",
    "read_tensor_file",
    "write_rgl",
    "write_tensor_file",
]

#: The first 12 bytes of a tensor file.
TENSOR_MAGIC = b"tensor_file\x00"
#: The type codes of a tensor file (1 to 11) and their numpy types (little-endian).
TENSOR_DTYPES = {
    1: "u1", 2: "i1", 3: "<u2", 4: "<i2", 5: "<u4", 6: "<i4",
    7: "<u8", 8: "<i8", 9: "<f2", 10: "<f4", 11: "<f8",
}  # fmt: skip
#: The fields a material file has, and their rank.
RGL_FIELDS = {
    "theta_i": 1, "phi_i": 1, "wavelengths": 1, "ndf": 2, "sigma": 2, "vndf": 4,
    "luminance": 4, "spectra": 5, "description": 1, "jacobian": 1,
}  # fmt: skip
_CODES = {np.dtype(v).str: k for k, v in TENSOR_DTYPES.items()}


def read_tensor_file(path: str | os.PathLike[str]) -> dict[str, np.ndarray]:
    """The fields of a tensor file (Mitsuba's format, as the module describes it).

    Parameters
    ----------
    path : str or path-like
        The file.

    Returns
    -------
    dict of str to ndarray
        Every field, in file order.

    Raises
    ------
    ValidationError
        Too small, wrong magic bytes, another version, an unknown type code, or a
        field reaching past the end of the file (truncated).

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> from sbrdf_xr.materials.rgl import read_tensor_file, write_tensor_file
    >>> p = write_tensor_file(pathlib.Path(tempfile.mkdtemp()) / "t.bsdf",
    ...                       {"x": np.arange(3, dtype=np.float32)})
    >>> read_tensor_file(p)["x"].tolist()
    [0.0, 1.0, 2.0]
    """
    path = Path(path)
    if path.stat().st_size > MAX_FILE_BYTES:
        raise ValidationError(
            f"RGL: {path.name} has {path.stat().st_size} bytes; allowed: at most "
            f"{MAX_FILE_BYTES} (sbrdf_xr.errors.MAX_FILE_BYTES)"
        )
    raw = path.read_bytes()
    if len(raw) < 18:
        raise ValidationError(
            f"RGL: {path.name} has {len(raw)} bytes, fewer than a tensor file's 18-byte header"
        )
    if raw[:12] != TENSOR_MAGIC:
        raise ValidationError(
            f"RGL: {path.name} starts with {raw[:12]!r}; allowed: {TENSOR_MAGIC!r} (a tensor file)"
        )
    if tuple(raw[12:14]) != (1, 0):
        raise ValidationError(
            f"RGL: {path.name} is tensor-file version {raw[12]}.{raw[13]}; allowed: 1.0"
        )
    (n_fields,) = struct.unpack_from("<I", raw, 14)
    pos, out = 18, {}
    try:
        for _ in range(n_fields):
            (n,) = struct.unpack_from("<H", raw, pos)
            name = raw[pos + 2 : pos + 2 + n].decode("utf-8")
            ndim, code, offset = struct.unpack_from("<HBQ", raw, pos + 2 + n)
            shape = struct.unpack_from(f"<{ndim}Q", raw, pos + 13 + n)
            pos += 13 + n + 8 * ndim
            if code not in TENSOR_DTYPES:
                raise ValidationError(
                    f"RGL: field {name!r} of {path.name} has type code {code}; allowed: 1 to 11"
                )
            dtype = np.dtype(TENSOR_DTYPES[code])
            end = offset + dtype.itemsize * int(np.prod(shape, dtype=np.int64))
            if end > len(raw):
                raise ValidationError(
                    f"RGL: field {name!r} of {path.name} ends at byte {end}, past the file's "
                    f"{len(raw)} bytes (truncated)"
                )
            out[name] = np.frombuffer(raw, dtype, int(np.prod(shape)), offset).reshape(shape)
    except struct.error:
        raise ValidationError(
            f"RGL: the header of {path.name} ({len(raw)} bytes) ends inside the description of "
            f"field {len(out) + 1} of {n_fields} (truncated)"
        ) from None
    return out


def write_tensor_file(path: str | os.PathLike[str], fields: dict[str, np.ndarray]) -> Path:
    """Write arrays as a tensor file (data aligned on 8 bytes, as Mitsuba writes them).

    Parameters
    ----------
    path : str or path-like
        The file to write.
    fields : dict of str to ndarray
        Arrays of the types of :data:`TENSOR_DTYPES`.

    Returns
    -------
    pathlib.Path

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> from sbrdf_xr.materials.rgl import write_tensor_file
    >>> p = write_tensor_file(pathlib.Path(tempfile.mkdtemp()) / "t.bsdf",
    ...                       {"x": np.zeros(2, np.uint8)})
    >>> p.read_bytes()[:18]
    b'tensor_file\\x00\\x01\\x00\\x01\\x00\\x00\\x00'
    """
    arrays = {
        k: np.ascontiguousarray(v, dtype=np.dtype(v.dtype).newbyteorder("<"))
        for k, v in fields.items()
    }
    header = sum(2 + len(k.encode()) + 2 + 1 + 8 + 8 * a.ndim for k, a in arrays.items()) + 18
    blobs, offset, parts = [], header, [TENSOR_MAGIC, bytes([1, 0]), struct.pack("<I", len(arrays))]
    for name, a in arrays.items():
        offset += -offset % 8
        code = _CODES.get(a.dtype.str)
        if code is None:
            raise ValidationError(f"fields: {name!r} has dtype {a.dtype}; allowed: {TENSOR_DTYPES}")
        key = name.encode()
        parts.append(
            struct.pack(f"<H{len(key)}sHBQ{a.ndim}Q", len(key), key, a.ndim, code, offset, *a.shape)
        )
        blobs.append((offset, a.tobytes()))
        offset += a.nbytes
    data = bytearray(b"".join(parts).ljust(header, b"\0"))
    for at, blob in blobs:
        data.extend(b"\0" * (at - len(data)))
        data.extend(blob)
    path = Path(path)
    path.write_bytes(bytes(data))
    return path


class _Warp:
    """Mitsuba's ``Marginal2D`` (Dupuy & Jakob 2018 §5) over the unit square, numpy-vectorised.

    ``data`` has shape ``(*param_sizes, ny, nx)``; ``params`` the node values of each
    leading axis.  With ``cdf`` the density is normalised per slice and its CDFs built
    (for :meth:`invert` and :meth:`sample`), else :meth:`eval` interpolates the values.
    """

    def __init__(self, data: np.ndarray, params: Sequence[np.ndarray], cdf: bool):
        self.ny, self.nx = data.shape[-2:]
        self.params = [np.asarray(p, dtype=np.float64) for p in params]
        sizes = data.shape[:-2]
        self.strides = [
            int(np.prod(sizes[d + 1 :])) if sizes[d] > 1 else 0 for d in range(len(sizes))
        ]
        d = data.reshape(-1, self.ny, self.nx).astype(np.float64)
        if cdf:
            cond = np.zeros_like(d)
            cond[:, :, 1:] = np.cumsum(0.5 * (d[:, :, :-1] + d[:, :, 1:]), axis=2)
            marg = np.zeros(d.shape[:2])
            marg[:, 1:] = np.cumsum(0.5 * (cond[:, :-1, -1] + cond[:, 1:, -1]), axis=1)
            norm = 1.0 / marg[:, -1:]
            self.cond = (cond * norm[:, :, None]).reshape(len(d), -1)
            self.marg = marg * norm
            d = d * norm[:, :, None]
        self.data = d.reshape(len(d), -1)

    def _corners(self, param: Sequence[np.ndarray]) -> list[tuple[np.ndarray, np.ndarray]]:
        """(slice index, weight) of the 2**D corners about each query's parameters."""
        if not self.params:
            return [(np.zeros(1, dtype=np.int64), np.ones(1))]
        idx, w1 = [], []
        for nodes, p in zip(self.params, param, strict=True):
            if nodes.size == 1:
                idx.append(np.zeros(p.shape, dtype=np.int64))
                w1.append(np.zeros(p.shape))
                continue
            i = np.clip(np.searchsorted(nodes, p, side="right") - 1, 0, nodes.size - 2)
            idx.append(i)
            w1.append(np.clip((p - nodes[i]) / (nodes[i + 1] - nodes[i]), 0.0, 1.0))
        base = sum((s * i for s, i in zip(self.strides, idx, strict=True)), np.zeros_like(idx[0]))
        out = []
        for corner in itertools.product((0, 1), repeat=len(idx)):
            w = np.ones_like(w1[0])
            for c, wd in zip(corner, w1, strict=True):
                w = w * (wd if c else 1.0 - wd)
            out.append((base + sum(c * s for c, s in zip(corner, self.strides, strict=True)), w))
        return out

    @staticmethod
    def _look(arr: np.ndarray, corners: list, index: np.ndarray) -> np.ndarray:
        return sum(w * arr[s, index] for s, w in corners)

    def _cell(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s = u * [self.nx - 1, self.ny - 1]
        pos = np.minimum(s.astype(np.int64), [self.nx - 2, self.ny - 2])
        return pos, s - pos, pos[:, 0] + pos[:, 1] * self.nx

    def eval(self, u: np.ndarray, param: Sequence[np.ndarray]) -> np.ndarray:
        """The bilinear interpolant of the values at points ``u`` (n, 2) of the square."""
        c = self._corners(param)
        _, w, k = self._cell(u)
        x, y, n = w[:, 0], w[:, 1], self.nx
        v0 = (1 - x) * self._look(self.data, c, k) + x * self._look(self.data, c, k + 1)
        v1 = (1 - x) * self._look(self.data, c, k + n) + x * self._look(self.data, c, k + n + 1)
        return (1 - y) * v0 + y * v1

    def invert(self, u: np.ndarray, param: Sequence[np.ndarray]) -> np.ndarray:
        """The sample ``(n, 2)`` of the square that the warp maps to ``u``."""
        c, n = self._corners(param), self.nx
        pos, s, k = self._cell(u)
        v00, v10 = self._look(self.data, c, k), self._look(self.data, c, k + 1)
        v01, v11 = self._look(self.data, c, k + n), self._look(self.data, c, k + n + 1)
        x, y = s[:, 0], s[:, 1]
        c0, c1 = (1 - y) * v00 + y * v01, (1 - y) * v10 + y * v11
        x = x * (c0 + 0.5 * x * (c1 - c0))
        x = x + (1 - y) * self._look(self.cond, c, k) + y * self._look(self.cond, c, k + n)
        row = pos[:, 1] * n
        r0, r1 = self._look(self.cond, c, row + n - 1), self._look(self.cond, c, row + 2 * n - 1)
        x = x / ((1 - y) * r0 + y * r1)
        y = y * (r0 + 0.5 * y * (r1 - r0))
        marg = sum(w * self.marg[sl, pos[:, 1]] for sl, w in c)
        return np.stack([x, y + marg], -1)

    def sample(self, u: np.ndarray, slice_: int) -> np.ndarray:
        """The point ``(n, 2)`` of the square the warp maps the samples ``u`` to (at a node)."""
        u = np.clip(u, 1.0 - 0.999999940395355225, 0.999999940395355225)
        marg, cond, d, n = self.marg[slice_], self.cond[slice_], self.data[slice_], self.nx
        row = np.clip(np.searchsorted(marg, u[:, 1], side="left") - 1, 0, self.ny - 2)
        y = u[:, 1] - marg[row]
        r0, r1 = cond[row * n + n - 1], cond[row * n + 2 * n - 1]
        y = _solve_linear_density(r0, r1, y)
        x = u[:, 0] * ((1 - y) * r0 + y * r1)
        rows = (1 - y)[:, None] * cond.reshape(self.ny, n)[row] + y[:, None] * cond.reshape(
            self.ny, n
        )[row + 1]
        col = np.clip(np.sum(rows < x[:, None], axis=1) - 1, 0, n - 2)
        x = x - rows[np.arange(len(col)), col]
        k = row * n + col
        c0, c1 = (1 - y) * d[k] + y * d[k + n], (1 - y) * d[k + 1] + y * d[k + n + 1]
        x = _solve_linear_density(c0, c1, x)
        return np.stack([(col + x) / (n - 1), (row + y) / (self.ny - 1)], -1)


def _solve_linear_density(a: np.ndarray, b: np.ndarray, m: np.ndarray) -> np.ndarray:
    """``t`` in [0, 1] with ``a t + (b - a) t**2 / 2 = m`` (the CDF of a linear density)."""
    const = np.abs(a - b) < 1e-4 * (a + b)
    with np.errstate(invalid="ignore", divide="ignore"):
        t = (a - np.sqrt(np.maximum(a * a - 2.0 * m * (a - b), 0.0))) / (a - b)
    return np.where(const, 2.0 * m / np.where(a + b > 0, a + b, 1.0), t)


def _u_theta(theta: np.ndarray) -> np.ndarray:
    return np.sqrt(np.clip(theta, 0.0, None) * (2.0 / np.pi))


def _u_phi(phi: np.ndarray) -> np.ndarray:
    u = (phi + np.pi) / (2.0 * np.pi)
    return u - np.floor(u)


def _spherical(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Zenith (stable near the pole, as Mitsuba's ``elevation``) and azimuth [rad]."""
    theta = 2.0 * np.arcsin(np.clip(0.5 * np.linalg.norm(v - [0.0, 0.0, 1.0], axis=-1), 0, 1))
    return theta, np.arctan2(v[..., 1], v[..., 0])


def _checked(fields: dict[str, np.ndarray], name: str) -> dict[str, np.ndarray]:
    """The material fields, their presence, ranks and shapes checked (as ``powitacq`` does)."""
    missing = [k for k in RGL_FIELDS if k not in fields]
    if missing:
        raise ValidationError(
            f"RGL: {name} lacks the fields {missing}; an RGL material file has "
            f"{list(RGL_FIELDS)} (an RGB file of the database is not supported)"
        )
    for k, rank in RGL_FIELDS.items():
        if fields[k].ndim != rank:
            raise ValidationError(
                f"RGL: field {k!r} of {name} has rank {fields[k].ndim}; allowed: {rank}"
            )
    n = (fields["phi_i"].size, fields["theta_i"].size)
    want = {
        "vndf": n, "luminance": n, "spectra": (*n, fields["wavelengths"].size),
    }  # fmt: skip
    for k, lead in want.items():
        if (
            fields[k].shape[: len(lead)] != lead
            or fields[k].shape[-2:] != fields["spectra"].shape[-2:]
        ):
            raise ValidationError(
                f"RGL: field {k!r} of {name} has shape {fields[k].shape}; allowed: {lead} "
                f"followed by the spectra's square {fields['spectra'].shape[-2:]}"
            )
    return fields


class _RGLBRDF:
    """The BRDF of an RGL file's fields, evaluated as ``powitacq`` / Mitsuba do."""

    def __init__(self, f: dict[str, np.ndarray]):
        self.theta, self.phi = f["theta_i"].astype(float), f["phi_i"].astype(float)
        self.wavelengths = f["wavelengths"].astype(float)
        self.jacobian = bool(f["jacobian"][0])
        self.ndf = _Warp(f["ndf"], [], cdf=False)
        self.sigma = _Warp(f["sigma"], [], cdf=False)
        self.vndf = _Warp(f["vndf"], [self.phi, self.theta], cdf=True)
        self.spectra = _Warp(f["spectra"], [self.phi, self.theta, self.wavelengths], cdf=False)

    def factor(self, wi: np.ndarray, wo: np.ndarray) -> tuple[np.ndarray, ...]:
        """The half vector's unit coordinates, the incidence angles and ndf / (4 sigma)."""
        m = wi + wo
        m = m / np.linalg.norm(m, axis=-1, keepdims=True)
        ti, pi = _spherical(wi)
        tm, pm = _spherical(m)
        u_m = np.stack([_u_theta(tm), _u_phi(pm - pi)], -1)
        u_i = np.stack([_u_theta(ti), _u_phi(pi)], -1)
        scale = self.ndf.eval(u_m, []) / (4.0 * self.sigma.eval(u_i, []))
        return u_m, ti, pi, scale

    def __call__(self, wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
        """``f_r`` [sr-1], shape (n, wavelengths), for unit vectors (n, 3), normal +z."""
        u_m, ti, pi, scale = self.factor(wi, wo)
        sample = self.vndf.invert(u_m, [pi, ti])
        out = np.stack(
            [self.spectra.eval(sample, [pi, ti, np.full_like(ti, w)]) for w in self.wavelengths], -1
        )
        if self.jacobian:
            out = out * scale[:, None]
        return out / np.clip(wo[:, 2], 1e-12, None)[:, None]


def read_rgl(
    path: str | os.PathLike[str],
    *,
    theta_i: Sequence[float] = (5.0, 20.0, 35.0, 50.0, 65.0, 80.0),
    step: float = 2.0,
    max_zenith: float = 80.0,
    material: str | None = None,
    provenance: str = "",
    **_: Any,
) -> Any:
    """An RGL ``.bsdf`` file sampled on paper-000 rows: a spectral measurement set.

    The file's BRDF is evaluated as the module describes (the Marginal2D warp inverted
    at each geometry's half vector) at every ``(theta_i, delta_theta, phi)`` node of
    rows like :func:`~sbrdf_xr.materials.merl.read_merl`'s, at the file's wavelengths,
    up to an observer zenith ``max_zenith``: the file stores ``f_r cos(theta_o)``, which
    vanishes at the horizon, so that ``f_r`` there is its interpolation error divided by
    a vanishing cosine.  Isotropic files only (at most two ``phi_i`` nodes, as
    ``powitacq`` tells them): the package's tables are isotropic.

    Parameters
    ----------
    path : str or path-like
        The ``.bsdf`` file.
    theta_i : sequence of float
        Incidence angles of the virtual scan [degree], in ``[0, 90)``.
    step : float, default 2
        Step of ``delta_theta`` and ``phi`` [degree].
    max_zenith : float, default 80
        The largest observer zenith sampled [degree], in ``(0, 90)``.
    material, provenance : str, optional
        Attributes; default the file's ``description`` (or stem) and its path.

    Returns
    -------
    xarray.Dataset

    Raises
    ------
    ValidationError
        A file that is not a tensor file, of another version, truncated, without the
        fields of an RGL material (:data:`RGL_FIELDS`) in their shapes, or anisotropic.

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> from sbrdf_xr.materials.rgl import read_rgl, write_rgl
    >>> p = write_rgl(pathlib.Path(tempfile.mkdtemp()) / "grey.bsdf",
    ...               lambda s, o: np.full((len(s), 2), 0.1), wavelengths=(450.0, 650.0))
    >>> ds = read_rgl(p, theta_i=(30.0,), step=10.0)
    >>> err = np.abs(ds.measured_sbrdf.values / 0.1 - 1)  # the format's interpolation
    >>> ds.wavelength.values.tolist(), bool(np.median(err) < 0.002), bool(err.max() < 0.04)
    ([450.0, 650.0], True, True)
    """
    path = Path(path)
    step = to_unit(step, "deg", "step")
    top = to_unit(max_zenith, "deg", "max_zenith")
    if not 0.0 < top < 90.0:
        raise ValidationError(f"max_zenith: got {top!r} degree; allowed: in (0, 90)")
    fields = _checked(read_tensor_file(path), path.name)
    if fields["phi_i"].size > 2:
        raise ValidationError(
            f"RGL: {path.name} is anisotropic ({fields['phi_i'].size} phi_i nodes); allowed: "
            "isotropic files (at most 2 phi_i nodes), the package's tables being isotropic"
        )
    brdf = _RGLBRDF(fields)
    tis, dts, phs = [], [], []
    for t in np.asarray(to_unit(theta_i, "deg", "theta_i"), dtype=np.float64):
        d, p = np.meshgrid(
            np.arange(-90.0 - t + step, 90.0 - t - step / 2, step), np.arange(0.0, 90.0, step)
        )
        up = np.cos(np.radians(p)) * np.cos(np.radians(t + d)) >= np.cos(np.radians(top)) - 1e-9
        tis.append(np.full(up.sum(), t))
        dts.append(d[up])
        phs.append(p[up])
    ti, dt, ph = (np.concatenate(a) for a in (tis, dts, phs))
    tr, pr = np.radians(ti + dt), np.radians(ph)
    s = np.stack([-np.sin(np.radians(ti)), 0 * ti, np.cos(np.radians(ti))], -1)
    o = np.stack([np.cos(pr) * np.sin(tr), np.sin(pr), np.cos(pr) * np.cos(tr)], -1)
    text = bytes(fields["description"]).decode("utf-8", "replace").strip("\0 ")
    ds = measurement_set(
        ti, dt, ph, brdf.wavelengths, np.maximum(brdf(s, o), 0.0),
        material=material or text or path.stem,
        provenance=provenance or f"{path.name} (RGL .bsdf tensor file, Dupuy & Jakob 2018), "
        "evaluated by sbrdf_xr.materials.read_measurements on paper-000 rows every "
        f"{step:g} deg up to an observer zenith of {top:g} deg",
    )  # fmt: skip
    ds.attrs["rgl_description"] = text
    return ds


def _unit_grid(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit coordinates ``(u, v)`` of an ``n x n`` grid and its directions (rows v, columns u)."""
    u, v = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    t, p = u**2 * (np.pi / 2), (2 * v - 1) * np.pi
    return u, v, np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)


def write_rgl(
    path: str | os.PathLike[str],
    brdf: Callable[[np.ndarray, np.ndarray], np.ndarray],
    *,
    wavelengths: Sequence[float],
    theta_i: Sequence[float] = tuple(range(0, 90, 5)),
    resolution: int = 32,
    ndf_resolution: int = 64,
    description: str = "written by sbrdf_xr.materials.rgl.write_rgl",
) -> Path:
    """Write an isotropic RGL ``.bsdf`` file of a BRDF given as a function of directions.

    The NDF is taken from the BRDF's retro-reflection (``D(m) ~ f(m, m) cos**2 theta_m``,
    exact in shape for a microfacet lobe, Dupuy & Jakob 2018 §4), its projected area by
    quadrature, the VNDF warp from both per incidence node, and ``spectra`` is
    ``f_r cos(theta_o) 4 sigma / D`` at the points the warp maps the
    ``resolution x resolution`` grid of the square to, so that the file reproduces the
    BRDF at those points and interpolates between them.

    Parameters
    ----------
    path : str or path-like
        The file to write.
    brdf : callable
        ``brdf(to_source, to_observer) -> (n, len(wavelengths))`` values [sr-1] for unit
        vectors ``(n, 3)`` in the surface frame (normal +z).
    wavelengths : sequence of float
        [nm].
    theta_i : sequence of float, default 0, 5, ..., 85
        Incidence nodes [degree], increasing, in ``[0, 90)``.
    resolution, ndf_resolution : int, default 32 and 64
        Side of the sampled square and of the NDF grid.
    description : str
        The file's ``description`` field.

    Returns
    -------
    pathlib.Path

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> from sbrdf_xr.materials.rgl import read_tensor_file, write_rgl
    >>> p = write_rgl(pathlib.Path(tempfile.mkdtemp()) / "grey.bsdf",
    ...               lambda s, o: np.full((len(s), 1), 0.1), wavelengths=(550.0,))
    >>> read_tensor_file(p)["spectra"].shape
    (1, 18, 1, 32, 32)
    """
    wl = np.asarray(to_unit(wavelengths, "nm", "wavelengths", spectral=True), float).ravel()
    nodes = np.radians(np.asarray(to_unit(theta_i, "deg", "theta_i"), float).ravel())
    if np.any(np.diff(nodes) <= 0) or nodes[0] < 0 or nodes[-1] >= np.pi / 2:
        raise ValidationError(
            f"theta_i: got {np.degrees(nodes).round(6).tolist()} degree; allowed: increasing, "
            "in [0, 90)"
        )
    u, _, m = _unit_grid(ndf_resolution)
    retro = np.asarray(brdf(m.reshape(-1, 3), m.reshape(-1, 3)), float).reshape(*u.shape, -1)
    ndf = np.nanmean(retro, -1) * m[..., 2] ** 2
    ndf = np.maximum(ndf, 1e-6 * ndf.max() + 1e-30)
    weight = np.sin(u**2 * np.pi / 2) * u  # solid angle per unit (u, v) cell, up to a constant
    ti = (np.linspace(0, 1, ndf_resolution) ** 2) * (np.pi / 2)  # isotropic: one row, tiled
    wi_row = np.stack([np.sin(ti), 0 * ti, np.cos(ti)], -1)
    proj = np.clip(wi_row @ m.reshape(-1, 3).T, 0.0, None)
    sigma = np.tile(proj @ (ndf * weight).ravel() * (2 * np.pi**2) / ndf.size, (u.shape[0], 1))
    ndf_w, sigma_w = _Warp(ndf, [], cdf=False), _Warp(sigma, [], cdf=False)
    vndf = np.empty((1, nodes.size, resolution, resolution))
    spectra = np.empty((1, nodes.size, wl.size, resolution, resolution))
    ur, vr, mr = _unit_grid(resolution)
    square = np.stack([ur.ravel(), vr.ravel()], -1)
    for j, t in enumerate(nodes):
        wi = np.array([np.sin(t), 0.0, np.cos(t)])
        d = ndf_w.eval(np.stack([ur.ravel(), vr.ravel()], -1), []).reshape(ur.shape)
        vndf[0, j] = d * np.clip(mr @ wi, 0, None) * np.sin(ur**2 * np.pi / 2) * ur
        at = _Warp(vndf[0, j], [], cdf=True).sample(square, 0)
        tm, pm = at[:, 0] ** 2 * (np.pi / 2), (2 * at[:, 1] - 1) * np.pi
        mm = np.stack([np.sin(tm) * np.cos(pm), np.sin(tm) * np.sin(pm), np.cos(tm)], -1)
        wo = 2 * (mm @ wi)[:, None] * mm - wi
        wis = np.broadcast_to(wi, wo.shape)
        f = np.zeros((len(wo), wl.size))
        up = wo[:, 2] > 0
        f[up] = np.asarray(brdf(wis[up], wo[up]), float).reshape(-1, wl.size) * wo[up, 2:3]
        ui_j = np.array([[_u_theta(t), 0.5]])
        f *= (4 * sigma_w.eval(ui_j, []) / ndf_w.eval(at, []))[:, None]
        spectra[0, j] = f.T.reshape(wl.size, resolution, resolution)
    fields = {
        "description": np.frombuffer(description.encode(), np.uint8),
        "jacobian": np.array([1], np.uint8),
        "theta_i": nodes.astype(np.float32),
        "phi_i": np.zeros(1, np.float32),
        "wavelengths": wl.astype(np.float32),
        "ndf": ndf.astype(np.float32),
        "sigma": sigma.astype(np.float32),
        "vndf": vndf.astype(np.float32),
        "luminance": np.maximum(spectra.mean(2), 0.0).astype(np.float32),
        "spectra": spectra.astype(np.float32),
    }
    return write_tensor_file(path, fields)


register_reader(Reader("rgl", (".bsdf",), read_rgl, "RGL .bsdf spectral tensor files"))
