"""The catalogue reproduces Table 1 of Naidu & Margot 2015 (docs/physics.md §7) through the paper's
secondary prescription, and refuses bad requests with the allowed values."""

import math

import numpy as np
import pytest

import ti_spinorbit as tso
from ti_spinorbit.system import catalog

TABLE = {  # name: (R_p, rho_p, c, ab, a/b, rho_s, a, e) from docs/physics.md §7
    "1991 VH": (600, 1581, 190, 57600, 1.50, 2618, 3300, 0.05),
    "2003 YT1": (550, 2712, 88, 11025, 1.30, 3248, 3930, 0.18),
    "2004 DC": (180, 1461, 26, 900, 1.30, 2000, 750, 0.30),
    "Didymos": (400, 1955, 65, 5625, 1.30, 2252, 1180, 0.04),
    "2000 DP107": (400, 1791, 100, 22500, 1.30, 2122, 2692, 0.03),
    "2002 CE26": (1750, 966, 100, 22500, 1.30, 1454, 4870, 0.025),
    "2001 SN263": (1300, 996, 190, 52900, 1.30, 2320, 3800, 0.016),
    "1994 CC": (310, 2076, 48, 3249, 1.30, 8870, 1730, 0.002),
    "1999 KW4": (659, 1970, 190, 51076, 1.30, 3321, 2548, 0.0004),
    "1996 FG3": (850, 1300, 200, 60025, 1.30, 1592, 2535, 0.07),
}


def test_every_table_row_is_catalogued():
    assert set(TABLE) | {"test", "Didymos (radar shape)"} == set(catalog.names())


@pytest.mark.parametrize("name", sorted(TABLE))
def test_system_follows_the_table_and_prescription(name):
    Rp, rho_p, c, ab, q, rho_s, a, e = TABLE[name]
    s = catalog.system(name)
    assert s.primary.mass == pytest.approx(rho_p * 4 / 3 * math.pi * Rp**3, rel=1e-14)
    assert s.secondary.mass == pytest.approx(rho_s * 4 / 3 * math.pi * ab * c, rel=1e-14)
    a_s, b_s, c_s = s.secondary.semi_axes
    assert (a_s * b_s, a_s / b_s, c_s) == (pytest.approx(ab), pytest.approx(q), c)
    assert (s.a, s.e) == (a, e)
    assert s.omega0 == pytest.approx(math.sqrt(3 * (q * q - 1) / (q * q + 1)), rel=1e-13)
    # mean motion from Kepler's third law with the total mass
    assert s.mean_motion == pytest.approx(math.sqrt(tso.G * (s.primary.mass + s.secondary.mass) / a**3))


def test_mass_is_fixed_by_ab_and_c_whatever_the_elongation():
    m = {q: catalog.system("1991 VH", elongation=q).secondary.mass for q in (1.01, 1.06, 1.5)}
    assert m[1.01] == m[1.06] == m[1.5]
    assert catalog.system("1991 VH", secondary_density=2 * 2618).mass_ratio == pytest.approx(
        catalog.system("1991 VH").mass_ratio / 2)


def test_energy_test_case():
    s = catalog.system("test")
    assert s.primary.semi_axes == (600.0, 500.0, 400.0)
    assert s.secondary.semi_axes == (252.0, 229.0, 190.0)
    assert s.primary_spin_period == pytest.approx(2.775 * 3600)
    assert catalog.secondary_spin_period("test") == pytest.approx(32.59 * 3600)
    with pytest.raises(ValueError, match="only eccentricity"):
        catalog.system("test", elongation=1.2)


def test_names_are_forgiving_but_unknown_ones_list_the_catalogue():
    assert catalog.system("1991vh").name == catalog.system("1991_VH").name == "1991 VH"
    assert catalog.system("didymos_radar_shape").name == catalog.system(
        "Didymos-Radar-Shape").name == "Didymos (radar shape)"
    with pytest.raises(ValueError, match="known systems: test, 1991 VH"):
        catalog.system("Ida")


def test_elongation_beyond_b_equals_c_is_refused_with_the_limit():
    # 2004 DC: ab = 900, c = 26 -> b = c at a/b = 900/26² = 1.331
    with pytest.raises(ValueError, match="largest allowed is 1.331"):
        catalog.system("2004 DC", elongation=1.5)


def test_paper_section_starts_and_heliocentric_orbits():
    assert catalog.section_starts("1991 VH") == [0.43, 0.83, 1.63, 2.31, 2.53]
    assert catalog.heliocentric_orbit("2004 DC").e == pytest.approx(0.397)
    # ecliptic elements; the Sun's direction only where the binary's pole is published
    didymos = catalog.heliocentric_orbit("Didymos")
    assert (didymos.a_au, didymos.inclination_deg, didymos.pole) == (1.644, 3.41, (310.0, -84.0))
    assert didymos.oriented and not catalog.heliocentric_orbit("1991 VH").oriented
    assert catalog.system("Didymos").heliocentric_orbit == didymos
    assert catalog.heliocentric_orbit("2002 CE26") is None
    assert np.all(np.diff(catalog.section_starts("Didymos")) > 0)
