"""Attitude from data: a quaternion time series, read from arrays, CSV or netCDF, slerped.

:class:`QuaternionSeries` interpolates user samples (body -> inertial, scalar-last) by
spherical linear interpolation (:class:`scipy.spatial.transform.Slerp`) and refuses
times outside them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation, Slerp

from ..errors import AttitudeError, check_declared_size
from ..geometry import check_quaternions
from .attitude import AttitudeLaw
from .frames import NS_PER_S, Context, check_epoch, seconds_since

__all__ = ["QuaternionSeries"]


@dataclass(frozen=True)
class QuaternionSeries(AttitudeLaw):
    """A user attitude time series, interpolated by slerp (:class:`scipy.spatial.transform.Slerp`).

    Parameters
    ----------
    times : array_like
        Strictly increasing sample times: ``datetime64`` (UTC) or seconds from ``epoch``.
    samples : array_like, shape (n, 4)
        Unit quaternions, scalar-last, body -> inertial.
    epoch : datetime64 or str, optional
        Time origin of float sample times (default: the start of the observation).

    Requests outside the sampled interval raise :class:`AttitudeError`.

    Examples
    --------
    >>> series = QuaternionSeries([0.0, 10.0], [[0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 0.0]])
    >>> np.round(series.quaternions([5.0]), 6)  # halfway: 90 degree about z
    array([[0.      , 0.      , 0.707107, 0.707107]])
    >>> series.quaternions([11.0])
    Traceback (most recent call last):
        ...
    sbrdf_xr.errors.AttitudeError: quaternion_series: requested times span [11, 11] s, outside ...
    """

    law_name: ClassVar[str] = "quaternion_series"
    law_parameters: ClassVar[tuple[str, ...]] = (
        "path",
        "time_column",
        "columns",
        "variable",
        "epoch",
    )

    times: Any
    samples: Any = None
    epoch: Any = None
    _secs: np.ndarray = field(init=False, repr=False, compare=False)
    _slerp: Slerp = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        t = np.atleast_1d(np.asarray(self.times))
        q = check_quaternions(self.samples) if self.samples is not None else None
        if q is None or q.ndim != 2 or q.shape[0] != t.shape[0] or t.ndim != 1 or t.size < 2:
            raise AttitudeError(
                f"quaternion_series: need >= 2 times and as many quaternions (n, 4); got times "
                f"{t.shape} and quaternions {None if q is None else q.shape}"
            )
        epoch = check_epoch(self.epoch)
        if np.issubdtype(t.dtype, np.datetime64):
            t = t.astype("datetime64[ns]")
            epoch = t[0] if epoch is None else epoch
            secs = (t - epoch).astype(np.int64) / NS_PER_S
        else:
            secs = t.astype(np.float64)
        if not np.all(np.diff(secs) > 0):
            raise AttitudeError("quaternion_series: times must be strictly increasing")
        object.__setattr__(self, "epoch", epoch)
        object.__setattr__(self, "_secs", secs)
        object.__setattr__(self, "_slerp", Slerp(secs, Rotation.from_quat(q)))

    @classmethod
    def from_table(cls, params: dict[str, Any]) -> QuaternionSeries:
        """The series of a TOML table: ``path`` (``.csv``, read by :meth:`from_csv` with
        ``time_column``, ``columns`` and ``epoch``, or netCDF, read by :meth:`from_netcdf`
        with ``variable``).

        Examples
        --------
        >>> QuaternionSeries.from_table({"time_column": "t"})
        Traceback (most recent call last):
            ...
        sbrdf_xr.errors.AttitudeError: attitude law 'quaternion_series': needs a path (.csv or .nc)
        """
        if "path" not in params:
            raise AttitudeError("attitude law 'quaternion_series': needs a path (.csv or .nc)")
        path = Path(params["path"])
        if path.suffix.lower() == ".csv":
            kw: dict[str, Any] = {k: params[k] for k in ("time_column", "epoch") if k in params}
            if "columns" in params:
                kw["columns"] = tuple(params["columns"])
            return cls.from_csv(path, **kw)
        return cls.from_netcdf(
            path, **({"variable": params["variable"]} if "variable" in params else {})
        )

    @classmethod
    def from_csv(
        cls,
        path: str | Path,
        time_column: str = "time",
        columns: Sequence[str] = ("qx", "qy", "qz", "qw"),
        epoch: Any = None,
    ) -> QuaternionSeries:
        """Read a CSV: a time column (ISO 8601 UTC, or seconds), scalar-last quaternion columns.

        Examples
        --------
        >>> import tempfile
        >>> from pathlib import Path
        >>> path = Path(tempfile.mkdtemp()) / "att.csv"
        >>> rows = ["time,qx,qy,qz,qw", "2024-03-17T01:20:00Z,0,0,0,1",
        ...         "2024-03-17T01:20:10Z,0,0,1,0"]
        >>> _ = path.write_text("\\n".join(rows))
        >>> series = QuaternionSeries.from_csv(path)
        >>> series.epoch
        np.datetime64('2024-03-17T01:20:00.000000000')
        >>> np.round(series.quaternions([5.0]), 6)
        array([[0.      , 0.      , 0.707107, 0.707107]])
        """
        import pandas as pd

        try:
            df = pd.read_csv(path)
        except (OSError, ValueError) as exc:
            raise AttitudeError(f"quaternion_series: cannot read {path}: {exc}") from None
        missing = [c for c in (time_column, *columns) if c not in df.columns]
        if missing:
            raise AttitudeError(
                f"quaternion_series: {path} lacks the columns {missing} (its header has "
                f"{len(df.columns)} columns; expected {[time_column, *columns]})"
            )
        tcol = df[time_column]
        if pd.api.types.is_numeric_dtype(tcol):
            t = tcol.to_numpy(np.float64)
        else:
            t = pd.to_datetime(tcol, utc=True).dt.tz_localize(None).to_numpy("datetime64[ns]")
        return cls(t, df[list(columns)].to_numpy(np.float64), epoch)

    @classmethod
    def from_netcdf(cls, path: str | Path, variable: str = "quaternion") -> QuaternionSeries:
        """Read ``variable(time, component)`` (components x, y, z, w) from a netCDF file.

        The ``quaternion`` of :meth:`sbrdf_xr.observing.observe.Observation.geometry` reads back.

        Examples
        --------
        >>> import tempfile
        >>> import xarray as xr
        >>> from pathlib import Path
        >>> path = Path(tempfile.mkdtemp()) / "att.nc"
        >>> q = xr.DataArray([[0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 0.0]],
        ...                  dims=("time", "component"),
        ...                  coords={"time": [0.0, 10.0], "component": ["x", "y", "z", "w"]})
        >>> q.to_dataset(name="quaternion").to_netcdf(path)
        >>> np.round(QuaternionSeries.from_netcdf(path).quaternions([5.0]), 6)
        array([[0.      , 0.      , 0.707107, 0.707107]])
        """
        import xarray as xr

        check_declared_size(Path(path), "quaternion_series", error=AttitudeError)
        try:
            with xr.open_dataset(path) as ds:
                da = ds[variable].load()
        except (OSError, KeyError, ValueError) as exc:
            raise AttitudeError(
                f"quaternion_series: cannot read {variable!r} from {path}: {exc}"
            ) from None
        if "component" in da.dims:
            da = da.transpose(..., "component").sel(component=["x", "y", "z", "w"])
        return cls(da[da.dims[0]].values, da.values)

    def quaternions(self, times: ArrayLike, context: Context | None = None) -> NDArray[np.float64]:
        t = seconds_since(times, self.epoch, context)
        lo, hi = self._secs[0], self._secs[-1]
        if t.min() < lo or t.max() > hi:
            raise AttitudeError(
                f"quaternion_series: requested times span [{t.min():.6g}, {t.max():.6g}] s, "
                "outside the "
                f"series [{lo:.6g}, {hi:.6g}] s from its epoch {self.epoch}"
            )
        return self._slerp(t).as_quat().reshape(-1, 4)
