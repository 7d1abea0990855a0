"""What comes out: saved archives (``io``), xarray export and figures (``plotting``). The top
of the library: it may import every other layer, and nothing imports it but the package's
front (``ti_spinorbit/__init__.py``) and the command line.
"""
