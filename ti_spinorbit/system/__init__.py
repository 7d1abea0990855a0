"""What is simulated: rigid bodies (mass and inertia integrals), a binary system (two bodies,
their mutual orbit, spins, heliocentric orbit), initial states, and the catalogue of real
systems. Pure NumPy; imports only the package's base modules (``layout``, ``_validate``,
``display``, ``constants``).
"""
