"""The joint fit of :func:`sbrdf_xr.invert.fit_observation`: model, starts, refinement,
result, twins, studies."""
