"""Taichi kernels of ti_spinorbit (installed as ``ti_spinorbit.kernels``).

Importing these modules defines Taichi functions and kernels but does not initialise Taichi;
``ti_spinorbit.runtime.ensure_init`` must run before the first launch. Each module's
docstring says what it holds; the layouts they share with the host are in
``ti_spinorbit.layout``.
"""
