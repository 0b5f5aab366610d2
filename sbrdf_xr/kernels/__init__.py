"""The compiled and numpy kernels: the arithmetic every layer above runs on.

Nothing here knows about xarray, files or scenes; every function takes and returns
plain arrays.

Modules
-------
``lut``
    Table look-up, smoothing splines and quadrature behind :mod:`sbrdf_xr.materials`
    (paper 000 §3.2-3.3).
``angles``
    The angle convention of paper 000 Fig. 4 in compiled code, one place for every
    kernel: the facet frame, its angles (one pair, or a chunk of geometries x terms
    vectorised) and the tangent's azimuth ``psi``.
``lookup``
    The look-up and the accumulation the compiled kernels share: cells, weights, the
    out-of-range policy, the lit-and-visible areas and the row sums.
``packing``
    What the compiled kernels take, as typed bundles: the tables
    (:class:`PackedTables`, :class:`TableGrids`), the terms (:class:`Facets`) and the
    options (:class:`KernelOptions`).
``reference``
    The numpy reference kernel of the spacecraft sum of paper 000 §3.4 (Eqs. 3-4).
``sums``
    The fused numba kernel of the same sum, and the dispatch between the two.
``anisotropic``
    The facet sums of anisotropic tables (a ``psi`` axis), on the same angles, look-up
    and accumulation.
``polygon``, ``shadow``, ``pair_table``, ``shadow_pairs`` and ``coverage``
    Plane-polygon clipping and the exact shadow kernels of :mod:`sbrdf_xr.body.visibility`:
    candidate occluders by a grid per direction, or from a table of the pairs that can
    shadow each other, built once per body; the area of a facet its shadows cover.
"""

from ..errors import ValidationError, renamed_attributes
from . import (
    angles,
    anisotropic,
    coverage,
    lookup,
    lut,
    packing,
    pair_table,
    polygon,
    reference,
    shadow,
    shadow_pairs,
    sums,
)
from .angles import (
    atan2_pos,
    chunk_angles,
    facet_frame,
    forward_direction,
    frame_angles,
    in_plane,
    observer_components,
    tangent_azimuth,
)
from .anisotropic import (
    AnisotropicTable,
    anisotropic_reflected,
    anisotropic_sums,
    pack_anisotropic,
    plan_step,
)
from .lut import (
    LOOKUP_METHODS,
    axis_weights,
    hemispherical_reflectance_kernel,
    lookup_kernel,
    lookup_matrix,
    normal_incidence_weight,
    smoothing_spline_matrix,
    table_edges,
    table_normal_blend,
)
from .packing import (
    MAX_BUCKETS,
    Facets,
    KernelOptions,
    PackedTables,
    TableGrids,
    bucket_map,
    pack_tables,
    typed_values,
)
from .polygon import (
    BUDGET,
    MAXM,
    MAXV,
    bounds,
    clip,
    hull,
    signed_area,
    union_area,
    union_area_slabs,
)
from .reference import MaterialSums, material_sums
from .sums import METHOD_CODES, BoundSums, FusedSums, fused_sums, normal_rows

__all__ = [
    "BUDGET",
    "LOOKUP_METHODS",
    "MAXM",
    "MAXV",
    "MAX_BUCKETS",
    "METHOD_CODES",
    "AnisotropicTable",
    "BoundSums",
    "Facets",
    "FusedSums",
    "KernelOptions",
    "MaterialSums",
    "PackedTables",
    "TableGrids",
    "ValidationError",
    "angles",
    "anisotropic",
    "anisotropic_reflected",
    "anisotropic_sums",
    "atan2_pos",
    "axis_weights",
    "bounds",
    "bucket_map",
    "chunk_angles",
    "clip",
    "coverage",
    "facet_frame",
    "forward_direction",
    "frame_angles",
    "fused_sums",
    "hemispherical_reflectance_kernel",
    "hull",
    "in_plane",
    "lookup",
    "lookup_kernel",
    "lookup_matrix",
    "lut",
    "material_sums",
    "normal_incidence_weight",
    "normal_rows",
    "observer_components",
    "pack_anisotropic",
    "pack_tables",
    "packing",
    "pair_table",
    "plan_step",
    "polygon",
    "reference",
    "shadow",
    "shadow_pairs",
    "signed_area",
    "smoothing_spline_matrix",
    "sums",
    "table_edges",
    "table_normal_blend",
    "tangent_azimuth",
    "typed_values",
    "union_area",
    "union_area_slabs",
]

#: Old names, served one release with a :class:`~sbrdf_xr.errors.RenamedWarning`.
__getattr__ = renamed_attributes(__name__, globals(), {"reflected": "anisotropic_reflected"})
