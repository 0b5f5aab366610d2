"""The spacecraft body: its mesh, facets, materials on the facets, and what it hides.

Modules
-------
``spacecraft``
    :class:`Spacecraft`: a triangulated surface in metres whose every facet carries a
    material name (:func:`load_spacecraft`, :func:`canx1`).
``meshes`` and ``repair``
    Reading meshes in five formats with length units and material maps; checks and repairs.
``facets``
    Facet tables: one row per facet, or facets merged by (normal, material).
``imperfections``
    Surface imperfections of CAD facets, a distribution of normal tilts (paper 000 §5).
``visibility``
    Self-shadowing and self-occlusion: exact polygon clipping, or sampled rays, beside
    the mesh access both methods read.
``occluders``
    What the exact method finds once per body: coplanar facets merged into convex
    occluders, and the pairs of facets that can shadow each other.
``rays``
    The sampled method's tools: sampling densities, point sets on facets, ray engines.
``picture``
    A 3-D picture of a spacecraft, each facet coloured by its material.
``sides``
    The sides light can reach: every facet's front, and a back where one is given.
``parts`` and ``posed``
    Articulated parts (a hinge and a pointing law), and shadowing on the posed body.
``geo_comsat``
    A built-in GEO communications satellite-like body: gold MLI bus, OSR radiators, two
    sun-tracking cell arrays.
``starlink``
    A built-in Starlink v1.5-class body: a nadir chassis and a sun-tracking array.
"""

from ..errors import MeshError, MeshRepairWarning, renamed_attributes
from . import (
    facets,
    geo_comsat,
    imperfections,
    meshes,
    occluders,
    parts,
    picture,
    posed,
    rays,
    repair,
    sides,
    spacecraft,
    starlink,
    visibility,
)
from .facets import NORMAL_TOLERANCE, check_facet_material, facet_table, merge_facets
from .geo_comsat import GEO_COMSAT_MATERIALS
from .imperfections import tilt_quadrature, tilted_normals
from .meshes import (
    LENGTH_UNITS,
    TANGENT_ATTRIBUTE,
    Color,
    face_tangents,
    label_faces,
    length_factor,
    normalise_map,
    read_material_map,
    read_mesh,
)
from .parts import (
    ARTICULATION_LAWS,
    PART_KEYS,
    AngleSeries,
    Fixed,
    Part,
    SunTracking,
    check_parts,
    hinge_rotation,
    part_from_spec,
    tracking_angle,
)
from .picture import plot_facets
from .posed import posed_fraction
from .rays import (
    DENSITY_PRESETS,
    ENGINES,
    MAX_RAYS_PER_CALL,
    OFFSET_FACTOR,
    SEED,
    available_engines,
    check_density,
    engine_name,
    intersector,
    sample_triangle,
    sample_uv,
    samples_per_facet,
    to_triangle,
)
from .repair import MERGE_DISTANCE, ZERO_AREA_FACTOR, clean_mesh
from .sides import Sides, build_sides, closed_facets, posed_vertices
from .spacecraft import CANX1_MATERIALS, Spacecraft, canx1, load_spacecraft
from .starlink import STARLINK_AREAS, STARLINK_MATERIALS, starlink_v15
from .visibility import (
    METHODS,
    PLANE_TOLERANCE,
    escape_masks,
    facet_visibility,
    is_convex,
    lit_fraction,
    lit_visible_fraction,
    mesh_of,
    supporting,
    visible_fraction,
)

__all__ = [
    "ARTICULATION_LAWS",
    "CANX1_MATERIALS",
    "DENSITY_PRESETS",
    "ENGINES",
    "GEO_COMSAT_MATERIALS",
    "LENGTH_UNITS",
    "MAX_RAYS_PER_CALL",
    "MERGE_DISTANCE",
    "METHODS",
    "NORMAL_TOLERANCE",
    "OFFSET_FACTOR",
    "PART_KEYS",
    "PLANE_TOLERANCE",
    "SEED",
    "STARLINK_AREAS",
    "STARLINK_MATERIALS",
    "TANGENT_ATTRIBUTE",
    "ZERO_AREA_FACTOR",
    "AngleSeries",
    "Color",
    "Fixed",
    "MeshError",
    "MeshRepairWarning",
    "Part",
    "Sides",
    "Spacecraft",
    "SunTracking",
    "available_engines",
    "build_sides",
    "canx1",
    "check_density",
    "check_facet_material",
    "check_parts",
    "clean_mesh",
    "closed_facets",
    "engine_name",
    "escape_masks",
    "face_tangents",
    "facet_table",
    "facet_visibility",
    "facets",
    "geo_comsat",
    "hinge_rotation",
    "imperfections",
    "intersector",
    "is_convex",
    "label_faces",
    "length_factor",
    "lit_fraction",
    "lit_visible_fraction",
    "load_spacecraft",
    "merge_facets",
    "mesh_of",
    "meshes",
    "normalise_map",
    "occluders",
    "part_from_spec",
    "parts",
    "picture",
    "plot_facets",
    "posed",
    "posed_fraction",
    "posed_vertices",
    "rays",
    "read_material_map",
    "read_mesh",
    "repair",
    "sample_triangle",
    "sample_uv",
    "samples_per_facet",
    "sides",
    "spacecraft",
    "starlink",
    "starlink_v15",
    "supporting",
    "tilt_quadrature",
    "tilted_normals",
    "to_triangle",
    "tracking_angle",
    "visibility",
    "visible_fraction",
]

#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(__name__, globals(), {"LAWS": "ARTICULATION_LAWS"})
