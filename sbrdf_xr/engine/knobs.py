"""Every numerical knob of a simulation, and the presets, in one table.

A *knob* is an approximation with a price: interpolation order, precision,
wavelength sampling, band pre-integration, shadowing method and density, table
resolution, tabulated versus analytic material evaluation.  Each is declared once here
(:class:`Knob`: name, default, type, allowed values or range, what it trades) and read
everywhere else: :class:`~sbrdf_xr.engine.Scene` takes its fields' defaults from here and
checks every value with :func:`check_knob`, the scene files take their TOML types and the
reference of their keys (:mod:`sbrdf_xr.engine.schema`) from here, and so do
:mod:`sbrdf_xr.engine.plan` (which resolves them), :mod:`sbrdf_xr.bench` and the command
line's ``--set`` help.

The presets ``fast``, ``balanced`` and ``reference`` are chosen from the
accuracy/cost table of ``sbrdf-xr bench`` (user guide, accuracy and cost): against
``reference``, linear
look-up costs about a third of the time for glint errors of tens of mmag (median
below 1 mmag); float32 adds about 0.001 mmag; the paper's nearest look-up saves
little more time for about five times the error of linear, so no preset uses it.
Shadowing is area-exact (polygon clipping) in every preset: on the package's non-convex
bodies no sampled density up to 32 reaches 1% worst error, and on meshes below about
5e4 facets exact clipping costs less than 4 x 4 samples per facet; sampling
(``shadow_method="sampled"``) pays off only on larger meshes.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ..errors import SceneError
from ..units import to_unit

__all__ = ["KNOBS", "PRESETS", "Knob", "apply_preset", "check_knob", "knob_table"]


@dataclass(frozen=True)
class Knob:
    """One numerical knob: the one declaration of its default, type, domain and meaning.

    :class:`~sbrdf_xr.engine.Scene` takes its field's default from here and checks every
    value with :meth:`check`; the scene files take its TOML type (:attr:`toml`); the
    command line and the scene-file reference (:mod:`sbrdf_xr.engine.schema`) its
    :meth:`domain` and :attr:`trades`.

    Attributes
    ----------
    name : str
        The Scene field (and scene-file key) that holds it.
    default : object
        Its value when not set.
    kind : type
        ``str``, ``int`` or ``float`` (a float knob takes integers too).
    trades : str
        What the knob trades, for people (``sbrdf-xr bench`` measures it).
    allowed : tuple or None
        The allowed values, or None for a number in ``[low, high]``.
    low, high : float or None
        Bounds of a number, inclusive (``low`` excluded with ``low_open``).
    none : str or None
        What None means, when None is allowed.
    unit : str
        Unit of a number (``"degree"``, ``"byte"``): an astropy Quantity given for the
        knob is converted to it (:meth:`convert`).

    Examples
    --------
    >>> from sbrdf_xr.engine.knobs import KNOBS
    >>> k = KNOBS["method"]
    >>> k.default, k.allowed, k.toml
    ('linear', ('nearest', 'linear', 'cubic'), (<class 'str'>,))
    >>> KNOBS["shadow_density"].check(0)  # a number checked against its range
    'expected an integer from 1 to 64'
    >>> KNOBS["table_theta_step"].domain()
    "none (the table's own nodes) or a number in (0, 45] degree"
    """

    name: str
    default: Any
    kind: type
    trades: str
    allowed: tuple[Any, ...] | None = None
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    none: str | None = None
    unit: str = ""

    @property
    def toml(self) -> tuple[type, ...]:
        """The TOML types a scene file may give it in."""
        return (int, float) if self.kind is float else (self.kind,)

    def _range(self) -> str:
        unit = f" {self.unit}" if self.unit else ""
        low, high = _number(self.low), _number(self.high)
        if self.kind is int:
            return f"an integer from {low} to {high}{unit}"
        return f"a number in {'(' if self.low_open else '['}{low}, {high}]{unit}"

    def domain(self) -> str:
        """Its allowed values, in words."""
        what = ", ".join(map(str, self.allowed)) if self.allowed is not None else self._range()
        return what if self.none is None else f"none ({self.none}) or {what}"

    def convert(self, value: Any) -> Any:
        """``value`` in :attr:`unit`: a Quantity converted (an integral value of an integer
        knob made an int), anything else unchanged.

        Raises
        ------
        UnitError
            For a Quantity of another kind, naming the knob.
        """
        if not self.unit:
            return value
        out = to_unit(value, self.unit, self.name)
        if self.kind is int and isinstance(out, float) and out.is_integer():
            return int(out)
        return out

    def check(self, value: Any) -> str | None:
        """An error text for ``value``, or None when the value is allowed."""
        if value is None and self.none is not None:
            return None
        if self.allowed is not None:
            if value in self.allowed:
                return None
            return f"allowed: {', '.join(map(str, self.allowed))}"
        number = not isinstance(value, bool) and isinstance(
            value, int if self.kind is int else int | float
        )
        low, high = self.low if self.low is not None else -float("inf"), self.high
        if number and (value > low if self.low_open else value >= low):
            if high is None or value <= high:
                return None
        nothing = f"None ({self.none}) or " if self.none is not None else ""
        return f"expected {nothing}{self._range()}"


def _number(x: float | None) -> str:
    if x is None:
        return "-"
    return str(int(x)) if float(x).is_integer() else f"{x:g}"


#: The knob table (one entry a knob).
KNOBS: dict[str, Knob] = {
    k.name: k
    for k in (
        Knob(
            "method",
            "linear",
            str,
            "look-up interpolation order: "
            "nearest (the paper's) < linear < cubic in accuracy and cost",
            allowed=("nearest", "linear", "cubic"),
        ),
        Knob(
            "dtype",
            "float64",
            str,
            "precision of the spectra (geometry is always float64)",
            allowed=("float32", "float64"),
        ),
        Knob(
            "wavelength_stride",
            1,
            int,
            "use every n-th wavelength of the materials' common grid",
            low=1,
            high=1000,
        ),
        Knob(
            "band_integration",
            "auto",
            str,
            "auto: band-only scenes pre-integrate the tables over the bands (exact for nearest "
            "and linear); spectral: integrate the spectral signal instead",
            allowed=("auto", "spectral"),
        ),
        Knob(
            "shadow_method",
            "exact",
            str,
            "facets hiding each other from the Sun and the observer: exact polygon clipping, "
            "or sub-facet ray sampling",
            allowed=("exact", "sampled"),
        ),
        Knob(
            "shadow_density",
            4,
            int,
            "shadow_method sampled: samples per facet side (density**2 per facet)",
            low=1,
            high=64,
        ),
        Knob(
            "table_theta_step",
            None,
            float,
            "resample the tables' theta_i axis to this step [degree] (None: as given)",
            low=0,
            high=45,
            low_open=True,
            none="the table's own nodes",
            unit="degree",
        ),
        Knob(
            "evaluation",
            "table",
            str,
            "table: look-up tables; analytic: each material's generating BRDF model "
            "(no table error, much slower)",
            allowed=("table", "analytic"),
        ),
        Knob(
            "tilt_nodes",
            5,
            int,
            "surface imperfections: Gauss-Hermite nodes per tangent axis of the normal-tilt "
            "distribution (tilt_nodes**2 copies of every term)",
            low=1,
            high=32,
        ),
        Knob(
            "kernel",
            "fused",
            str,
            "fused: the compiled one-pass kernel; numpy: the reference implementation (same sums)",
            allowed=("fused", "numpy"),
        ),
        Knob(
            "earth_model",
            "finite",
            str,
            "finite: a Lambertian Earth at its true size cut by each facet's horizon (a "
            "quadrature per geometry); point: a distant source at the Earth's centre",
            allowed=("finite", "point"),
        ),
        Knob(
            "conductance",
            "none",
            str,
            "conductance model of temperature='equilibrium': none: each facet an insulated "
            "panel radiating from its front; two_sided: a thin plate radiating from both faces; "
            "isothermal: all facets of a material at one temperature",
            allowed=("none", "two_sided", "isothermal"),
        ),
        Knob(
            "chunk",
            None,
            int,
            "geometries per block (None: from the memory budget)",
            low=1,
            high=10**9,
            none="from block_bytes",
        ),
        # 8 MiB: the writers hold one more block than they have threads; 32 MiB blocks
        # held 0.1 GB of a 1e6-attitude CanX-1 write's 0.39 GB of private memory on 2 cores
        Knob(
            "block_bytes",
            8 * 2**20,
            int,
            "memory budget of one block's outputs [byte], sets the default chunk",
            low=1,
            high=2**34,
            unit="byte",
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
    """Validate one knob value; returns it in the knob's unit (a Quantity converted,
    :meth:`Knob.convert`).

    Raises
    ------
    SceneError
        Unknown knob, or a value outside what it allows.
    UnitError
        A Quantity of another kind than the knob's unit.

    Examples
    --------
    >>> from sbrdf_xr.engine.knobs import check_knob
    >>> check_knob("dtype", "float32")
    'float32'
    >>> import astropy.units as u
    >>> check_knob("table_theta_step", 0.05 * u.rad)  # a Quantity: in the knob's unit
    2.8647889756541165
    >>> check_knob("dtype", "float16")
    Traceback (most recent call last):
    ...
    sbrdf_xr.errors.SceneError: dtype: got 'float16'; allowed: float32, float64
    """
    try:
        knob = KNOBS[name]
    except KeyError:
        raise SceneError(f"unknown knob {name!r}; knobs: {', '.join(KNOBS)}") from None
    value = knob.convert(value)
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
