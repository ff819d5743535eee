"""The package version (one place: the package, the command line, sweep records and shipped models read it)."""
__version__ = "0.1.0"
