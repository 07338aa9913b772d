"""The package version: one home, read by ``ddwmmr.__version__``, the records the tools
write (:func:`ddwmmr.outputs.package_version`) and the build (pyproject.toml)."""

__version__ = "0.1.0"
