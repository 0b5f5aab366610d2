"""Every numerical knob of a simulation, and the presets, in one table.

A *knob* is an approximation with a price: interpolation order, precision,
wavelength sampling, band pre-integration, shadowing method and density, table
resolution, tabulated versus analytic material evaluation.  Each is declared once
here (name, allowed values, default, what it trades) and read by
:class:`~sbrdf_xr.engine.Scene` (its fields), :mod:`sbrdf_xr.engine.plan` (which resolves
them), :mod:`sbrdf_xr.body.visibility`, :mod:`sbrdf_xr.bench` and the command line.

The presets ``fast``, ``balanced`` and ``reference`` are chosen from the
accuracy/cost table of ``sbrdf-xr bench`` (README): against ``reference``, linear
look-up costs about a third of the time for glint errors of tens of mmag (median
below 1 mmag); float32 adds about 0.001 mmag; the paper's nearest look-up saves
little more time for about five times the error of linear, so no preset uses it.
Shadowing is area-exact (polygon clipping) in every preset: on the package's non-convex
bodies no sampled density up to 32 reaches 1% worst error, and on meshes below about
5e4 facets exact clipping costs less than 4 x 4 samples per facet; sampling
(``shadow_method="sampled"``) pays off only on larger meshes.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from ..errors import SceneError

__all__ = ["KNOBS", "PRESETS", "Knob", "apply_preset", "check_knob", "knob_table"]


@dataclass(frozen=True)
class Knob:
    """One numerical knob.

    Attributes
    ----------
    name : str
        The Scene field that holds it.
    default : object
        Its value when not set.
    allowed : tuple or None
        The allowed values, or None for a value checked by ``check``.
    check : callable or None
        ``check(value)`` returns an error text, or None when the value is fine.
    trades : str
        What the knob trades, for people (``sbrdf-xr bench`` measures it).

    Examples
    --------
    >>> from sbrdf_xr.engine.knobs import KNOBS
    >>> k = KNOBS["method"]
    >>> k.default, k.allowed
    ('linear', ('nearest', 'linear', 'cubic'))
    >>> KNOBS["shadow_density"].check(0)  # a knob checked by a function
    'expected an integer from 1 to 64'
    """

    name: str
    default: Any
    allowed: tuple[Any, ...] | None
    check: Callable[[Any], str | None] | None
    trades: str


def _positive_int(limit: int) -> Callable[[Any], str | None]:
    def check(v: Any) -> str | None:
        if isinstance(v, bool) or not isinstance(v, int) or not 1 <= v <= limit:
            return f"expected an integer from 1 to {limit}"
        return None

    return check


def _optional_positive_int(limit: int) -> Callable[[Any], str | None]:
    inner = _positive_int(limit)
    return lambda v: None if v is None else inner(v)


def _optional_step(v: Any) -> str | None:
    if v is None:
        return None
    if isinstance(v, bool) or not isinstance(v, int | float) or not 0 < float(v) <= 45:
        return "expected None (the table's own nodes) or a step in (0, 45] degree"
    return None


#: The knob table (one entry a knob).
KNOBS: dict[str, Knob] = {
    k.name: k
    for k in (
        Knob(
            "method",
            "linear",
            ("nearest", "linear", "cubic"),
            None,
            "look-up interpolation order: "
            "nearest (the paper's) < linear < cubic in accuracy and cost",
        ),
        Knob(
            "dtype",
            "float64",
            ("float32", "float64"),
            None,
            "precision of the spectra (geometry is always float64)",
        ),
        Knob(
            "wavelength_stride",
            1,
            None,
            _positive_int(1000),
            "use every n-th wavelength of the materials' common grid",
        ),
        Knob(
            "band_integration",
            "auto",
            ("auto", "spectral"),
            None,
            "auto: band-only scenes pre-integrate the tables over the bands (exact for nearest "
            "and linear); spectral: integrate the spectral signal instead",
        ),
        Knob(
            "shadow_method",
            "exact",
            ("exact", "sampled"),
            None,
            "facets hiding each other from the Sun and the observer: exact polygon clipping, "
            "or sub-facet ray sampling",
        ),
        Knob(
            "shadow_density",
            4,
            None,
            _positive_int(64),
            "shadow_method sampled: samples per facet side (density**2 per facet)",
        ),
        Knob(
            "table_theta_step",
            None,
            None,
            _optional_step,
            "resample the tables' theta_i axis to this step [degree] (None: as given)",
        ),
        Knob(
            "evaluation",
            "table",
            ("table", "analytic"),
            None,
            "table: look-up tables; analytic: each material's generating BRDF model "
            "(no table error, much slower)",
        ),
        Knob(
            "tilt_nodes",
            5,
            None,
            _positive_int(32),
            "surface imperfections: Gauss-Hermite nodes per tangent axis of the normal-tilt "
            "distribution (tilt_nodes**2 copies of every term)",
        ),
        Knob(
            "kernel",
            "fused",
            ("fused", "numpy"),
            None,
            "fused: the compiled one-pass kernel; numpy: the reference implementation (same sums)",
        ),
        Knob(
            "chunk",
            None,
            None,
            _optional_positive_int(10**9),
            "geometries per block (None: from the memory budget)",
        ),
        Knob(
            "block_bytes",
            32 * 2**20,
            None,
            _positive_int(2**34),
            "memory budget of one block's outputs [byte], sets the default chunk",
        ),
    )
}

#: Presets: knob values chosen from the accuracy/cost table (see the module docstring).
PRESETS: dict[str, dict[str, Any]] = {
    "fast": {"method": "linear", "dtype": "float32", "shadow_method": "exact"},
    "balanced": {"method": "linear", "dtype": "float64", "shadow_method": "exact"},
    "reference": {"method": "cubic", "dtype": "float64", "shadow_method": "exact"},
}


def check_knob(name: str, value: Any) -> Any:
    """Validate one knob value.

    Raises
    ------
    SceneError
        Unknown knob, or a value outside what it allows.

    Examples
    --------
    >>> from sbrdf_xr.engine.knobs import check_knob
    >>> check_knob("dtype", "float32")
    'float32'
    >>> check_knob("dtype", "float16")
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.SceneError: dtype: got 'float16'; allowed: float32, float64
    """
    try:
        knob = KNOBS[name]
    except KeyError:
        raise SceneError(f"unknown knob {name!r}; knobs: {', '.join(KNOBS)}") from None
    if knob.allowed is not None and value not in knob.allowed:
        raise SceneError(f"{name}: got {value!r}; allowed: {', '.join(map(str, knob.allowed))}")
    if knob.check is not None:
        why = knob.check(value)
        if why:
            raise SceneError(f"{name}: got {value!r}; {why}")
    return value


def apply_preset(preset: str, changes: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The knob values of ``preset``, updated with ``changes``.

    Raises
    ------
    SceneError
        Unknown preset.

    Examples
    --------
    >>> from sbrdf_xr.engine.knobs import apply_preset
    >>> apply_preset("fast", {"method": "cubic"})
    {'method': 'cubic', 'dtype': 'float32', 'shadow_method': 'exact'}
    """
    if preset not in PRESETS:
        raise SceneError(f"preset: unknown {preset!r}; allowed: {', '.join(PRESETS)}")
    return {**PRESETS[preset], **(changes or {})}


def knob_table() -> str:
    """The knobs and presets as a text table (``sbrdf-xr knobs``).

    Examples
    --------
    >>> from sbrdf_xr.engine.knobs import knob_table
    >>> print(knob_table())  # doctest: +ELLIPSIS
    knob               default     fast / balanced / reference   trades
    method             linear      linear / linear / cubic       look-up interpolation order: ...
    dtype              float64     float32 / float64 / float64   precision of the spectra ...
    ...
    """
    w = max(len(k) for k in KNOBS)
    lines = [f"{'knob':<{w}}  {'default':<10}  {' / '.join(PRESETS):<28}  trades"]
    for k in KNOBS.values():
        pre = " / ".join(str(PRESETS[p].get(k.name, "-")) for p in PRESETS)
        lines.append(f"{k.name:<{w}}  {k.default!s:<10}  {pre:<28}  {k.trades}")
    return "\n".join(lines)
