"""Physical constants and the paper's default dissipation parameters, shared by the energy
budgets (``analytic``) and the forces in the equations (``perturbations``), SI units. Kept
apart so that both can use them without importing each other."""

#: Nominal solar luminosity, W (IAU 2015 Resolution B3).
L_SUN = 3.828e26
#: Speed of light, m/s (exact, SI).
C_LIGHT = 299792458.0
#: Astronomical unit, m (IAU 2012 Resolution B2).
AU = 1.495978707e11
#: Heliocentric gravitational constant G M_⊙, m³ s⁻² (IAU 2015 nominal value).
GM_SUN = 1.3271244e20

#: Default tidal quality factor (Naidu & Margot 2015; docs/physics.md §9.4).
DEFAULT_Q = 100.0
#: Default YORP efficiency f_Y (Naidu & Margot 2015; docs/physics.md §9.4).
DEFAULT_F_YORP = 5e-4

#: Rubble-pile Love numbers k2(R) with R the body's radius in km.
K2_MODELS = {
    "goldreich-sari": lambda radius_km: 1e-5 * radius_km,         # Goldreich & Sari 2009
    "jacobson-scheeres": lambda radius_km: 2.5e-5 / radius_km,    # Jacobson & Scheeres 2011
}

#: Planets (and the Moon) a Flyby knows by name: GM in m³ s⁻² (IAU 2015 nominal Earth; the
#: JPL DE440 values for the others) and mean radius in km (IAU WG on Cartographic
#: Coordinates 2015).
PLANETS = {"Earth": (3.986004e14, 6371.0), "Venus": (3.248586e14, 6051.8),
           "Mars": (4.282837e13, 3389.5), "Moon": (4.902800e12, 1737.4)}
