"""The BRDF model interface: declared parameters, the :class:`Model` object, the registry.

A model is one :class:`Model`: its name, its pure-numpy ``brdf`` function, its
parameters (each a :class:`Parameter` with UDUNITS units, a long_name and a domain),
whether it is anisotropic, its citation and, optionally, its directional-hemispherical
reflectance.  Validation, the evaluation from paper-000 angles and the rendering on
angle grids are written once here and in :mod:`sbrdf_xr.brdf._common`, for every
model.  Models are registered in a :class:`ModelRegistry` (case-insensitive names in
the manner of colour-science's ``CanonicalMapping`` and ``validate_method``).
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import ValidationError
from ..units import to_unit
from ._common import (
    _angles_to_vectors,
    _band_param,
    _check_angles,
    _check_names,
    _check_wavelength,
    tangent_from_azimuth,
)

__all__ = ["Model", "ModelRegistry", "Parameter"]

#: Keywords of the interface that no parameter may take as its name.
RESERVED_NAMES = frozenset(
    {"wavelength", "material", "provenance", "model", "layers", "psi", "tangent", "horizon"}
)
_NAME = re.compile(r"[a-z][a-z0-9_]*\Z")
#: Nodes are evaluated at least this far inside the lit and visible hemisphere [degree]
#: by ``horizon="limit"`` rendering (:meth:`Model.render_grid`).
HORIZON_MARGIN_DEG = 1e-6
#: With ``horizon="limit"`` a ``theta_i = 90`` row is evaluated this far from grazing
#: incidence [degree]: the specular peak of a microfacet model diverges as both
#: directions graze, and a table node carries a value for the whole cell around it.
GRAZING_MARGIN_DEG = 0.5
#: The ways :meth:`Model.render_grid` treats nodes that are not lit and visible.
HORIZONS = ("zero", "limit")


@dataclass(frozen=True)
class Parameter:
    """One declared model parameter: its name, metadata and domain.

    Every parameter is a scalar or an array aligned with ``wavelength`` and is
    broadcast to ``(n_wl,)`` float64 by :meth:`validate`.

    Parameters
    ----------
    name : str
        Keyword of the model's functions and name of the variable in a model material.
    units : str
        UDUNITS units (``"1"`` for dimensionless).
    long_name : str
        CF long_name.
    lower, upper : float, optional
        Bounds of the domain (``None``: unbounded).
    lower_open : bool, default False
        ``lower`` itself is excluded.
    spectral : bool, default True
        A spectrum by nature (``False``: usually one value, per band allowed).

    Examples
    --------
    >>> p = Parameter("rho", "1", "albedo", lower=0.0, upper=1.0)
    >>> p.domain
    '0.0 <= rho <= 1.0'
    >>> p.validate([0.2, 0.4], 2).tolist()
    [0.2, 0.4]
    >>> p.attrs
    {'units': '1', 'long_name': 'albedo'}
    """

    name: str
    units: str
    long_name: str
    lower: float | None = None
    upper: float | None = None
    lower_open: bool = False
    spectral: bool = True

    @property
    def attrs(self) -> dict[str, str]:
        """CF attributes ``{"units", "long_name"}`` of the parameter's variable."""
        return {"units": self.units, "long_name": self.long_name}

    @property
    def domain(self) -> str:
        """The allowed domain as text, e.g. ``"0 < n"``."""
        lo = "" if self.lower is None else f"{self.lower} {'<' if self.lower_open else '<='} "
        hi = "" if self.upper is None else f" <= {self.upper}"
        return f"{lo}{self.name}{hi}" if (lo or hi) else f"{self.name} finite"

    def validate(self, value: ArrayLike, n_wl: int) -> NDArray[np.float64]:
        """``value`` checked against the domain and broadcast to ``(n_wl,)`` float64.

        Raises
        ------
        ValidationError
            Not real numbers, a shape other than scalar or ``(n_wl,)``, NaN, or a
            value outside the domain (the message gives the values and the domain).
        """
        return _band_param(
            self.name,
            value,
            n_wl,
            lower=self.lower,
            upper=self.upper,
            lower_open=self.lower_open,
            unit=self.units,
        )


def _check_declaration(model: Model) -> None:
    """Every declaration complete: the errors a model meets when it is declared."""
    what = f"model {model.name!r}"
    if not isinstance(model.name, str) or not _NAME.match(model.name):
        raise ValidationError(
            f"model name: got {model.name!r}; expected lower-case letters, digits and '_', "
            "starting with a letter"
        )
    if not callable(model.brdf):
        raise ValidationError(f"{what}: brdf must be a function, got {type(model.brdf).__name__}")
    refl = model.reflectance
    if refl is not None and not callable(refl):
        raise ValidationError(f"{what}: reflectance must be a function or None")
    for key, what_it_is in (("citation", "paper and equations"), ("long_name", "one line")):
        v = getattr(model, key)
        if not isinstance(v, str) or not v.strip():
            raise ValidationError(f"{what}: declare its {key} ({what_it_is}), got {v!r}")
    if not model.parameters:
        raise ValidationError(f"{what}: declares no parameters")
    seen: set[str] = set()
    for p in (*model.parameters, *model.stack):
        if not isinstance(p, Parameter):
            raise ValidationError(
                f"{what}: parameter {p!r} is a {type(p).__name__}, not a Parameter; every "
                "parameter declares its units, long_name and domain"
            )
        for key in ("units", "long_name"):
            v = getattr(p, key)
            if not isinstance(v, str) or not v.strip():
                raise ValidationError(
                    f"{what}: parameter {p.name!r} declares no {key} (got {v!r}); every "
                    "parameter needs UDUNITS units and a long_name"
                )
        if not isinstance(p.name, str) or not p.name.isidentifier() or p.name in RESERVED_NAMES:
            raise ValidationError(
                f"{what}: parameter name {p.name!r} is not an identifier or is reserved "
                f"({sorted(RESERVED_NAMES)})"
            )
        if p.name in seen:
            raise ValidationError(f"{what}: parameter {p.name!r} is declared twice")
        seen.add(p.name)
        if p.lower is not None and p.upper is not None and not p.lower <= p.upper:
            raise ValidationError(f"{what}: parameter {p.name!r} has an empty domain")


@dataclass(frozen=True)
class Model:
    """An analytic spectral BRDF model: its function, declared parameters and citation.

    Parameters
    ----------
    name : str
        Registry name (lower case, ``[a-z][a-z0-9_]*``).
    long_name : str
        One line saying what the model is.
    brdf : callable
        ``brdf(normal, to_sun, to_observer, wavelength, **params) -> (..., n_wl)``
        [sr-1], pure vectorised numpy, zero where unlit or unseen; anisotropic models
        also take ``tangent`` (``(..., 3)``, the direction of their first roughness).
    parameters : tuple of Parameter
        The model's parameters, in the order of the model material's variables.
    citation : str
        The paper (and equations) the model implements.
    reflectance : callable, optional
        ``reflectance(theta_i, wavelength, **params) -> (..., n_wl)``: the
        directional-hemispherical reflectance [1], in closed form or by quadrature.
    anisotropic : bool, default False
        Needs the facet tangent (``psi``): tables of it have a ``psi`` axis.
    stack : tuple of Parameter, default ()
        Declarations of a thin-film stack's variables (``layer_n``, ``layer_k``,
        ``layer_thickness``) if ``brdf`` takes ``layers``.
    constraint : callable, optional
        ``constraint(checked) -> None``, a joint condition on the validated parameters
        (raises :class:`~sbrdf_xr.errors.ValidationError`).
    reciprocal : bool, default False
        The model claims Helmholtz reciprocity, ``f(s, o) = f(o, s)``, over its whole
        domain (grazing and forward-scatter geometries included); the suite checks
        every model that claims it.

    Raises
    ------
    ValidationError
        A declaration is incomplete: a parameter without units or long_name, not a
        :class:`Parameter`, a reserved or repeated name, no citation.

    Examples
    --------
    >>> import numpy as np
    >>> from sbrdf_xr.brdf import get_model
    >>> m = get_model("Lambert")
    >>> m.name, m.param_names, m.anisotropic
    ('lambert', ('rho',), False)
    >>> m.parameter("rho").attrs
    {'units': '1', 'long_name': 'Lambertian albedo'}
    >>> round(float(m.brdf_angles(30.0, 0.0, 0.0, [550.0], rho=0.5)[0] * np.pi), 6)
    0.5
    """

    name: str
    long_name: str
    brdf: Callable[..., np.ndarray]
    parameters: tuple[Parameter, ...]
    citation: str
    reflectance: Callable[..., np.ndarray] | None = None
    anisotropic: bool = False
    stack: tuple[Parameter, ...] = ()
    constraint: Callable[[dict[str, NDArray[np.float64]]], None] | None = field(
        default=None, repr=False
    )
    reciprocal: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "parameters", tuple(self.parameters))
        object.__setattr__(self, "stack", tuple(self.stack))
        _check_declaration(self)

    @property
    def param_names(self) -> tuple[str, ...]:
        """Names of the parameters, in declaration order."""
        return tuple(p.name for p in self.parameters)

    @property
    def thin_film(self) -> bool:
        """Whether ``brdf`` takes a thin-film stack (``layers``)."""
        return bool(self.stack)

    def parameter(self, name: str) -> Parameter:
        """The declaration of parameter (or stack variable) ``name``.

        Raises
        ------
        ValidationError
            ``name`` is not declared; the message lists the declared names.
        """
        for p in (*self.parameters, *self.stack):
            if p.name == name:
                return p
        declared = [p.name for p in (*self.parameters, *self.stack)]
        raise ValidationError(f"model {self.name!r}: got parameter {name!r}; declared: {declared}")

    def check_params(self, wavelength: ArrayLike, **params: Any) -> dict[str, NDArray[np.float64]]:
        """Validate the parameters and broadcast them to the wavelength grid.

        Parameters
        ----------
        wavelength : array_like, shape (n_wl,)
            Vacuum wavelength [nm].
        **params
            Exactly the declared parameters, each a scalar or an array of shape ``(n_wl,)``.

        Returns
        -------
        dict
            The parameters as float64 arrays of shape ``(n_wl,)``, in declaration order.

        Raises
        ------
        ValidationError
            Missing or unexpected names, a shape not matching ``wavelength``, NaN, or a
            value outside a declared domain or the model's joint constraint.
        """
        wl = _check_wavelength(wavelength)
        _check_names(params, self.param_names, self.name)
        out = {p.name: p.validate(params[p.name], wl.size) for p in self.parameters}
        if self.constraint is not None:
            self.constraint(out)
        return out

    def brdf_angles(
        self,
        theta_i: ArrayLike,
        delta_theta: ArrayLike,
        phi: ArrayLike,
        wavelength: ArrayLike,
        *,
        psi: ArrayLike | None = None,
        **kwargs: Any,
    ) -> np.ndarray:
        """The BRDF from paper-000 angles [degree] (and ``psi``, anisotropic models).

        :attr:`brdf` evaluated on the facet-frame vectors of
        :func:`sbrdf_xr.geometry.facet_vectors`; with ``psi`` the tangent of
        :func:`sbrdf_xr.brdf.anisotropic.tangent_from_azimuth` goes in as ``tangent``.

        Parameters
        ----------
        theta_i, delta_theta, phi : array_like
            Paper-000 Fig. 4 angles [degree], broadcast together.
        wavelength : array_like, shape (n_wl,)
            Vacuum wavelength [nm].
        psi : array_like, optional
            Azimuth of the illumination plane from the facet tangent [degree]:
            required by anisotropic models, refused by isotropic ones.
        **kwargs
            The parameters and any option of :attr:`brdf`.

        Returns
        -------
        ndarray, shape broadcast(...) + (n_wl,)
            BRDF [sr-1].

        Examples
        --------
        >>> import numpy as np
        >>> from sbrdf_xr.brdf import get_model
        >>> f = get_model("lambert").brdf_angles([0.0, 95.0], 0.0, 0.0, [550.0], rho=np.pi / 10)
        >>> np.round(f, 6).tolist()
        [[0.1], [0.0]]
        """
        self._check_psi(psi)
        n, s, o = _angles_to_vectors(theta_i, delta_theta, phi)
        if psi is None:
            return self.brdf(n, s, o, wavelength, **kwargs)
        t = tangent_from_azimuth(_check_angles(("psi", psi))[0])
        n, s, o, t = np.broadcast_arrays(n, s, o, t)
        return self.brdf(n, s, o, wavelength, tangent=t, **kwargs)

    def render_grid(
        self,
        theta_i: ArrayLike,
        delta_theta: ArrayLike,
        phi: ArrayLike,
        wavelength: ArrayLike,
        *,
        psi: ArrayLike | None = None,
        horizon: str = "zero",
        **kwargs: Any,
    ) -> np.ndarray:
        """:meth:`brdf_angles` on the outer product of 1-D grids [degree].

        With ``horizon="limit"`` a node whose geometry is not lit and visible
        (``theta_i`` = 90 deg, the observer at or below the horizon: ``|theta_i +
        delta_theta| >= 90`` or ``phi >= 90``) carries the model's limit from inside
        the hemisphere: it is evaluated at the nearest lit and visible geometry,
        :data:`HORIZON_MARGIN_DEG` inside the horizon and :data:`GRAZING_MARGIN_DEG`
        from grazing incidence.  Interpolating between such a node and a visible one
        then never blends in a zero that the physics does not have (a Lambertian
        surface renders to ``rho / pi`` at every node).  ``"zero"`` evaluates every
        node as it is.

        Parameters
        ----------
        theta_i, delta_theta, phi : array_like, 1-D
            Grids of the paper-000 angles [degree].
        wavelength : array_like, shape (n_wl,)
            Vacuum wavelength [nm].
        psi : array_like, 1-D, optional
            A grid of tangent azimuths [degree] (anisotropic models): adds an axis
            before ``wavelength``.
        **kwargs
            As :meth:`brdf_angles`.
        horizon : {"zero", "limit"}, default "zero"
            Treatment of the nodes that are not lit and visible.

        Returns
        -------
        ndarray, shape (n_ti, n_dt, n_phi[, n_psi], n_wl)
            BRDF [sr-1].

        Examples
        --------
        >>> import numpy as np
        >>> from sbrdf_xr.brdf import get_model
        >>> m = get_model("lambert")
        >>> g = m.render_grid([30.0], [0.0, 70.0], [0.0, 45.0], [550.0], rho=0.5)
        >>> g.shape, np.round(g.ravel() * np.pi, 6).tolist()  # theta_r = 100 deg: unseen
        ((1, 2, 2, 1), [0.5, 0.5, 0.0, 0.0])
        >>> g = m.render_grid([30.0], [0.0, 70.0], [0.0, 45.0], [550.0], horizon="limit", rho=0.5)
        >>> np.round(g.ravel() * np.pi, 6).tolist()
        [0.5, 0.5, 0.5, 0.5]
        """
        if horizon not in HORIZONS:
            raise ValidationError(f"horizon: got {horizon!r}; allowed: {list(HORIZONS)}")
        named = {"theta_i": theta_i, "delta_theta": delta_theta, "phi": phi}
        if psi is not None:
            named["psi"] = psi
        grids = []
        for name, a in named.items():
            arr = np.asarray(to_unit(a, "deg", name))
            if arr.ndim != 1:
                raise ValidationError(
                    f"{name}: expected a 1-D grid [degree], got shape {arr.shape}"
                )
            grids.append(arr.astype(np.float64) if horizon == "limit" else arr)
        mesh = np.meshgrid(*grids, indexing="ij")
        t, d, p = mesh[:3]
        if horizon == "limit":
            m = HORIZON_MARGIN_DEG
            t_c = np.minimum(t, 90.0 - GRAZING_MARGIN_DEG)
            r_c = np.clip(t + d, -(90.0 - m), 90.0 - m)
            t, d, p = t_c, r_c - t_c, np.minimum(p, 90.0 - m)
        ps = mesh[3] if psi is not None else None
        return self.brdf_angles(t, d, p, wavelength, psi=ps, **kwargs)

    def directional_hemispherical_reflectance(
        self, theta_i: ArrayLike, wavelength: ArrayLike, **kwargs: Any
    ) -> NDArray[np.float64]:
        """The model's directional-hemispherical reflectance [1] (:attr:`reflectance`).

        Raises
        ------
        ValidationError
            The model declares no reflectance function.
        """
        if self.reflectance is None:
            raise ValidationError(
                f"model {self.name!r} declares no directional-hemispherical reflectance"
            )
        return self.reflectance(theta_i, wavelength, **kwargs)

    def _check_psi(self, psi: ArrayLike | None) -> None:
        if self.anisotropic and psi is None:
            raise ValidationError(
                f"model {self.name!r} is anisotropic: give psi, the azimuth of the "
                "illumination plane from the facet tangent [degree]"
            )
        if not self.anisotropic and psi is not None:
            raise ValidationError(f"model {self.name!r} is isotropic: it takes no psi")


def _canonical(name: str) -> str:
    """Lower case without ``-``, ``_`` and spaces (colour-science's canonical keys)."""
    return re.sub(r"[-_ ]", "", name.lower())


class ModelRegistry(Mapping[str, Model]):
    """Models by name; look-ups are case-insensitive and ignore ``-``, ``_`` and spaces.

    Examples
    --------
    >>> from sbrdf_xr.brdf import BRDF_MODELS
    >>> BRDF_MODELS["Robertson-Sandford"].name
    'robertson_sandford'
    >>> "MICROFACET" in BRDF_MODELS
    True
    >>> sorted(BRDF_MODELS.view(anisotropic=True))
    ['anisotropic_microfacet']
    """

    def __init__(self, where: Callable[[Model], bool] | None = None, base: Any = None) -> None:
        self._models: dict[str, Model] = {} if base is None else base._models
        self._where = where

    def _visible(self) -> dict[str, Model]:
        if self._where is None:
            return self._models
        return {k: m for k, m in self._models.items() if self._where(m)}

    def __getitem__(self, name: str) -> Model:
        return self._visible()[self.validate(name)]

    def __iter__(self) -> Iterator[str]:
        return iter(self._visible())

    def __len__(self) -> int:
        return len(self._visible())

    def __contains__(self, name: object) -> bool:
        if not isinstance(name, str):
            return False
        key = _canonical(name)
        return any(_canonical(k) == key for k in self._visible())

    def __repr__(self) -> str:
        return f"ModelRegistry({sorted(self)})"

    def get(self, name: str, default: Any = None) -> Any:
        """The model matching ``name``, or ``default``."""
        return self[name] if name in self else default

    def validate(self, name: object) -> str:
        """The registered name matching ``name`` (colour-science's ``validate_method``).

        Raises
        ------
        ValidationError
            ``name`` matches no registered model; the message lists the valid names.
        """
        visible = self._visible()
        if isinstance(name, str):
            key = _canonical(name)
            for k in visible:
                if _canonical(k) == key:
                    return k
        raise ValidationError(
            f"model: got {name!r}; valid model names are {sorted(visible)} (case-insensitive)"
        )

    def view(self, *, anisotropic: bool) -> ModelRegistry:
        """A live, read-only view of the isotropic or the anisotropic models."""
        return ModelRegistry(lambda m: m.anisotropic == anisotropic, base=self)

    def register(self, model: Model, *, replace: bool = False) -> Model:
        """Add ``model`` under ``model.name``.

        Raises
        ------
        ValidationError
            Not a :class:`Model` (or its declaration is incomplete), or a model of
            that (canonical) name is registered and ``replace`` is false.
        """
        if self._where is not None:
            raise ValidationError("register models in the registry itself, not in a view")
        if not isinstance(model, Model):
            raise ValidationError(
                f"register: expected a sbrdf_xr.brdf.Model, got {type(model).__name__}"
            )
        _check_declaration(model)
        clash = [k for k in self._models if _canonical(k) == _canonical(model.name)]
        if clash and not replace:
            raise ValidationError(
                f"register: a model named {clash[0]!r} is registered; pass replace=True"
            )
        for k in clash:
            del self._models[k]
        self._models[model.name] = model
        return model

    def unregister(self, name: str) -> Model:
        """Remove and return the model registered under ``name``."""
        if self._where is not None:
            raise ValidationError("unregister models in the registry itself, not in a view")
        return self._models.pop(self.validate(name))
