"""The package's geometry: the angle convention of paper 000 and the attitudes it is applied in.

One convention for every layer, pure vectorised numpy (each function broadcasts over the
leading axes of arrays whose last axis holds a vector's three components):

``angles``
    The facet angles of paper 000 §3.1, Fig. 4 (``theta_i``, ``delta_theta``, ``phi``;
    DESIGN.md "Angle convention"), their normal-incidence and grazing limits, the
    conventional angles, phase angle, half vector and observation plane.
``anisotropy``
    Its extension to anisotropic materials: facet tangents and the azimuth ``psi`` of
    the illumination plane from the tangent.
``rotations``
    Attitudes as unit quaternions: validation, rotation matrices, sweeps and the body
    frame.

Every name of the three modules is importable from here.
"""

from ..errors import renamed_attributes
from . import angles, anisotropy, rotations
from .angles import (
    FacetAngles,
    facet_angles,
    facet_vectors,
    from_conventional,
    half_vector,
    normal_incidence_tolerance,
    normalize,
    observation_plane,
    phase_angle,
    to_conventional,
)
from .anisotropy import (
    DEFAULT_TANGENT_DIRECTION,
    PSI_PERIOD,
    TANGENT_TOLERANCE,
    illumination_azimuth,
    project_tangents,
    psi_average,
    psi_weights,
)
from .rotations import (
    QUATERNION_NORM_TOL,
    axis_rotation,
    check_quaternions,
    compose_quaternions,
    euler_attitudes,
    rotation_matrices,
    rotation_sweep,
    to_body_frame,
    uniform_attitudes,
)

__all__ = [
    "DEFAULT_TANGENT_DIRECTION",
    "PSI_PERIOD",
    "QUATERNION_NORM_TOL",
    "TANGENT_TOLERANCE",
    "FacetAngles",
    "angles",
    "anisotropy",
    "axis_rotation",
    "check_quaternions",
    "compose_quaternions",
    "euler_attitudes",
    "facet_angles",
    "facet_vectors",
    "from_conventional",
    "half_vector",
    "illumination_azimuth",
    "normal_incidence_tolerance",
    "normalize",
    "observation_plane",
    "phase_angle",
    "project_tangents",
    "psi_average",
    "psi_weights",
    "rotation_matrices",
    "rotation_sweep",
    "rotations",
    "to_body_frame",
    "to_conventional",
    "uniform_attitudes",
]

#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(__name__, globals(), {"compose": "compose_quaternions"})
