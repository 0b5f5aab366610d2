"""The package version (read by hatch; re-exported as ``sbrdf_xr.__version__``)."""

__version__ = "0.1.0"
