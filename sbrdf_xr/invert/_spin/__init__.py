"""The spin fit of :func:`sbrdf_xr.invert.fit_spin`: data, search, refinement, symmetry,
result, benchmark."""
