"""MERL isotropic ``.binary`` BRDF files (Matusik et al., ACM TOG 22, 759, 2003).

The format, as the database's reader ``BRDFRead.cpp`` defines it: three ``int32``
dimensions ``(90, 90, 180)`` (``theta_half``, ``theta_diff``, ``phi_diff``), then
``3 * 90 * 90 * 180`` ``float64`` values, the red, green and blue channels one after
the other, each in C order over the three dimensions and scaled by ``1/1500``,
``1.15/1500`` and ``1.66/1500`` to sr-1.  The half-angle/difference parametrisation
(Rusinkiewicz 1998): ``theta_half`` bin ``i`` covers ``(i/90)**2 * 90`` to
``((i+1)/90)**2 * 90`` degree (dense near the mirror direction), ``theta_diff`` and
``phi_diff`` are 1-degree bins over ``[0, 90)`` and ``[0, 180)`` (``phi_diff`` and
``phi_diff + 180`` are the same by reciprocity).  Negative values mark cells that
were not measured.

:func:`read_merl` samples the file, interpolated linearly between bin centres (in the
bins' index coordinates), on a goniometer scheme of paper-000 rows (every incidence
angle's ``(delta_theta, phi)`` grid) and returns a measurement set whose three
``wavelength`` values are the colour channels at nominal wavelengths
(:data:`CHANNEL_WAVELENGTHS`, attribute ``channels``): they are RGB camera channels,
not spectral samples, and the set says so.  :func:`write_merl` writes a file from any
BRDF (a model, for tests and for renderers).
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from scipy.interpolate import RegularGridInterpolator

from ..errors import NonPhysicalWarning, ValidationError
from ..units import to_unit
from .readers import Reader, measurement_set, register_reader

__all__ = [
    "CHANNEL_WAVELENGTHS",
    "MERL_DIMS",
    "MERL_SCALES",
    "half_diff",
    "read_merl",
    "write_merl",
]

#: The dimensions of a MERL file: theta_half, theta_diff, phi_diff bins.
MERL_DIMS = (90, 90, 180)
#: The scale of the red, green and blue channels to sr-1 (BRDFRead.cpp).
MERL_SCALES = (1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0)
#: Nominal wavelengths [nm] standing for the blue, green and red channels (increasing).
CHANNEL_WAVELENGTHS = (465.0, 550.0, 630.0)


def half_diff(
    to_source: np.ndarray, to_observer: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Half-angle/difference angles of direction pairs (Rusinkiewicz 1998), isotropic.

    Parameters
    ----------
    to_source, to_observer : ndarray, shape (..., 3)
        Unit vectors in the surface frame (normal +z) [1].

    Returns
    -------
    theta_half, theta_diff, phi_diff : ndarray
        [degree]; ``phi_diff`` in ``[0, 180)`` (reciprocity).

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.materials.merl import half_diff
    >>> s = np.array([np.sin(0.5), 0.0, np.cos(0.5)])
    >>> [round(float(x), 9) for x in half_diff(s, s * [-1, -1, 1])]
    [0.0, 28.647889757, 0.0]
    """
    h = to_source + to_observer
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    th = np.arctan2(np.hypot(h[..., 0], h[..., 1]), h[..., 2])
    ph = np.arctan2(h[..., 1], h[..., 0])
    c, s = np.cos(-ph), np.sin(-ph)  # the source turned so that h is in the xz-plane ...
    x = c * to_source[..., 0] - s * to_source[..., 1]
    y = s * to_source[..., 0] + c * to_source[..., 1]
    z = to_source[..., 2]
    ct, st = np.cos(-th), np.sin(-th)  # ... and h onto +z
    dx, dz = ct * x + st * z, -st * x + ct * z
    td = np.arctan2(np.hypot(dx, y), dz)
    pd = np.mod(np.arctan2(y, dx), np.pi)
    return np.degrees(th), np.degrees(td), np.degrees(pd)


def _directions(th: np.ndarray, td: np.ndarray, pd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Source and observer unit vectors of half-angle/difference angles [degree] (phi_half 0)."""
    th, td, pd = (np.radians(a) for a in (th, td, pd))
    d = np.stack([np.sin(td) * np.cos(pd), np.sin(td) * np.sin(pd), np.cos(td)], -1)
    ct, st = np.cos(th), np.sin(th)  # turn the half vector from +z to theta_half
    s = np.stack([ct * d[..., 0] + st * d[..., 2], d[..., 1], -st * d[..., 0] + ct * d[..., 2]], -1)
    h = np.stack([st, np.zeros_like(st), ct], -1)
    o = 2.0 * np.sum(s * h, -1, keepdims=True) * h - s
    return s, o


def _centres() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The bins' centre angles [degree] in index coordinates ``i + 0.5``."""
    i = np.arange(MERL_DIMS[0]) + 0.5
    return (i / 90.0) ** 2 * 90.0, np.arange(MERL_DIMS[1]) + 0.5, np.arange(MERL_DIMS[2]) + 0.5


def write_merl(
    path: str | os.PathLike[str],
    brdf: Callable[[np.ndarray, np.ndarray], np.ndarray],
) -> Path:
    """Write a MERL ``.binary`` file of a BRDF given as a function of directions.

    Parameters
    ----------
    path : str or path-like
        The file to write.
    brdf : callable
        ``brdf(to_source, to_observer) -> (n, 3)`` values [sr-1] of the red, green and
        blue channels for unit vectors ``(n, 3)`` in the surface frame (normal +z).
        Cells with either direction below the horizon are written as -1 (unmeasured).

    Returns
    -------
    pathlib.Path

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> from sbrdf_xr.materials.merl import write_merl
    >>> p = write_merl(pathlib.Path(tempfile.mkdtemp()) / "grey.binary",
    ...                lambda s, o: np.full((len(s), 3), 0.1))
    >>> p.stat().st_size == 12 + 3 * 90 * 90 * 180 * 8
    True
    """
    g = np.meshgrid(*_centres(), indexing="ij")
    s, o = _directions(*(a.ravel() for a in g))
    values = np.full((s.shape[0], 3), -1.0)
    ok = (s[:, 2] > 0) & (o[:, 2] > 0)
    values[ok] = np.asarray(brdf(s[ok], o[ok]), dtype=np.float64).reshape(-1, 3)
    scaled = np.where(values >= 0, values / np.asarray(MERL_SCALES), -1.0)
    path = Path(path)
    with open(path, "wb") as f:
        f.write(np.asarray(MERL_DIMS, dtype="<i4").tobytes())
        f.write(np.ascontiguousarray(scaled.T, dtype="<f8").tobytes())
    return path


def _load(path: Path) -> np.ndarray:
    """The three channels [sr-1], shape (3, 90, 90, 180), NaN where unmeasured."""
    raw = path.read_bytes()
    if len(raw) < 12:
        raise ValidationError(
            f"MERL: {path.name} has {len(raw)} bytes, fewer than its 12-byte header"
        )
    dims = tuple(int(x) for x in np.frombuffer(raw[:12], dtype="<i4"))
    if dims != MERL_DIMS:
        raise ValidationError(
            f"MERL: {path.name} declares dimensions {dims}; allowed: {MERL_DIMS} (isotropic "
            "MERL files)"
        )
    want = 12 + 3 * int(np.prod(MERL_DIMS)) * 8
    if len(raw) != want:
        raise ValidationError(
            f"MERL: {path.name} has {len(raw)} bytes; a {MERL_DIMS} file has {want} "
            f"({'truncated' if len(raw) < want else 'trailing bytes'})"
        )
    data = np.frombuffer(raw[12:], dtype="<f8").reshape(3, *MERL_DIMS)
    out = data * np.asarray(MERL_SCALES)[:, None, None, None]
    return np.where(data >= 0, out, np.nan)


def read_merl(
    path: str | os.PathLike[str],
    *,
    theta_i: Sequence[float] = (5.0, 20.0, 35.0, 50.0, 65.0, 80.0),
    step: float = 2.0,
    material: str | None = None,
    provenance: str = "",
    **_: Any,
) -> Any:
    """A MERL file sampled on paper-000 rows: a three-channel measurement set.

    Parameters
    ----------
    path : str or path-like
        The ``.binary`` file.
    theta_i : sequence of float
        Incidence angles of the virtual scan [degree], in ``[0, 90)``.
    step : float, default 2
        Step of ``delta_theta`` and ``phi`` [degree]; the observer above the horizon.
    material, provenance : str, optional
        Attributes; default the file's stem and its path.

    Returns
    -------
    xarray.Dataset
        Wavelengths :data:`CHANNEL_WAVELENGTHS` standing for blue, green, red
        (attribute ``channels``).

    Raises
    ------
    ValidationError
        A file of the wrong size or dimensions (truncated or not MERL).

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> from sbrdf_xr.materials.merl import read_merl, write_merl
    >>> p = write_merl(pathlib.Path(tempfile.mkdtemp()) / "grey.binary",
    ...                lambda s, o: np.tile([0.3, 0.2, 0.1], (len(s), 1)))
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:  # a cell MERL leaves unmeasured
    ...     warnings.simplefilter("always")
    ...     ds = read_merl(p, theta_i=(30.0,), step=10.0)
    >>> [str(w.message)[:44] for w in caught]
    ['MERL: 1 of 153 sampled geometries of grey.bi']
    >>> ds.attrs["channels"], np.round(ds.measured_sbrdf.values[0], 12).tolist()
    ('blue, green, red (MERL RGB colour channels at nominal wavelengths)', [0.1, 0.2, 0.3])
    """
    path = Path(path)
    step = to_unit(step, "deg", "step")
    data = _load(path)
    pad = np.concatenate([data[..., -1:], data, data[..., :1]], axis=-1)  # phi_d periodic
    idx = (np.arange(90) + 0.5, np.arange(90) + 0.5, np.arange(-0.5, 180.6, 1.0))
    tis, dts, phs = [], [], []
    for t in np.asarray(to_unit(theta_i, "deg", "theta_i"), dtype=np.float64):
        d, p = np.meshgrid(
            np.arange(-90.0 - t + step, 90.0 - t - step / 2, step), np.arange(0.0, 90.0, step)
        )
        up = np.cos(np.radians(p)) * np.cos(np.radians(t + d)) > 1e-6
        tis.append(np.full(up.sum(), t))
        dts.append(d[up])
        phs.append(p[up])
    ti, dt, ph = (np.concatenate(a) for a in (tis, dts, phs))
    tr, pr = np.radians(ti + dt), np.radians(ph)
    s = np.stack([-np.sin(np.radians(ti)), 0 * ti, np.cos(np.radians(ti))], -1)
    o = np.stack([np.cos(pr) * np.sin(tr), np.sin(pr), np.cos(pr) * np.cos(tr)], -1)
    th, td, pd = half_diff(s, o)
    q = np.stack([np.clip(np.sqrt(th / 90.0) * 90.0, 0.5, 89.5), np.clip(td, 0.5, 89.5), pd], -1)
    rgb = np.stack(
        [
            RegularGridInterpolator(idx, pad[c], bounds_error=False, fill_value=None)(q)
            for c in range(3)
        ],
        -1,
    )
    bad = ~np.all(np.isfinite(rgb), axis=1)
    if bad.any():
        warnings.warn(
            f"MERL: {int(bad.sum())} of {bad.size} sampled geometries of {path.name} fall on "
            "unmeasured cells and are left out",
            NonPhysicalWarning,
            stacklevel=2,
        )
    keep = ~bad
    ds = measurement_set(
        ti[keep], dt[keep], ph[keep], np.asarray(CHANNEL_WAVELENGTHS), rgb[keep][:, ::-1],
        material=material or path.stem,
        provenance=provenance or f"{path.name} (MERL isotropic .binary, RGB), sampled by "
        f"sbrdf_xr.materials.read_measurements on paper-000 rows every {step:g} deg",
    )  # fmt: skip
    ds.attrs["channels"] = "blue, green, red (MERL RGB colour channels at nominal wavelengths)"
    ds.attrs["n_dropped_unmeasured"] = int(bad.sum())
    return ds


register_reader(Reader("merl", (".binary",), read_merl, "MERL isotropic .binary (RGB)"))
