"""The package's version, in a module of its own so that every module can import it at its
top (``ti_spinorbit.__version__`` re-exports it; pyproject.toml holds the same number)."""

__version__ = "0.1.0"
