"""Taichi kernels of ti_spinorbit (installed as ``ti_spinorbit.kernels``).

Importing these modules defines Taichi functions and kernels but does not initialise Taichi;
``ti_spinorbit.runtime.ensure_init`` must run before the first launch.

* ``tableau``     Butcher tableaux (data) and controller constants
* ``mutual_gravity`` fourth-order mutual potential, force, torques
* ``eom``         equations of motion, member-parameter layout, diagnostics
* ``integrator``  generic embedded RK step, error norm, step-size controller
* ``advance``     the window kernel, pericentre events, dense sampling
"""
