"""Exceptions and warnings raised by sbrdf_xr.

A small hierarchy: :class:`SbrdfError` is the base of everything the package
raises on purpose; :class:`ValidationError` (also a :class:`ValueError`) is raised
for bad input, with a message that names the field, what was received and what
is allowed.  Warnings derive from :class:`SbrdfWarning` so users can filter them.
"""

from __future__ import annotations

__all__ = [
    "AttitudeError",
    "CatalogError",
    "EpochGapWarning",
    "InversionError",
    "MeshError",
    "MeshRepairWarning",
    "NonPhysicalWarning",
    "NotObservableError",
    "ObservationError",
    "SbrdfError",
    "SbrdfWarning",
    "SceneError",
    "ValidationError",
]


class SbrdfError(Exception):
    """Base class of every exception raised on purpose by sbrdf_xr."""


class ValidationError(SbrdfError, ValueError):
    """Input that does not satisfy the documented schema or domain."""


class CatalogError(SbrdfError, LookupError):
    """A catalog entry that does not exist or cannot be loaded."""


class MeshError(ValidationError):
    """A spacecraft mesh that cannot be used as given."""


class SceneError(ValidationError):
    """A scene definition that cannot be compiled into a plan."""


class ObservationError(ValidationError):
    """An orbit (TLE/OMM), site, time axis or observation definition that cannot be used."""


class NotObservableError(ObservationError):
    """An observation whose object is below the horizon, or in shadow, at every time."""


class AttitudeError(ValidationError):
    """An unknown attitude law or bad law parameters."""


class InversionError(ValidationError):
    """Measured data, uncertainties or a model library that an inversion cannot use."""


class SbrdfWarning(UserWarning):
    """Base class of the warnings issued by sbrdf_xr."""


class NonPhysicalWarning(SbrdfWarning):
    """A quantity that violates a physical bound (for example reflectance > 1)."""


class MeshRepairWarning(SbrdfWarning):
    """A spacecraft mesh was repaired as documented in :mod:`sbrdf_xr.body.spacecraft`."""


class EpochGapWarning(SbrdfWarning):
    """Observation times far from the epoch of the orbital elements (SGP4 accuracy degrades)."""
