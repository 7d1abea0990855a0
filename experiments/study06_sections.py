"""Paper Figs. 7–9 (Naidu & Margot 2015; script study06): sections of the asynchronous systems.

1991 VH a/b = 1.5 (θ̇_p/n = 0.43 0.83 1.63 2.31 2.53), 2003 YT1 a/b = 1.3 (0.75 1.29 2.85 3.15
3.5 3.69) and 2004 DC a/b = 1.3 (1.39 4.29 4.49 5.39), θ_p = 0. With ω0 near or above the
overlap value the 1:1 and 3:2 resonances have merged into a large chaotic sea; the
synchronous island survives, shifted vertically by relaxed-mode libration.

Coordinates: apsidal, the paper's (θ̇ from the osculating line of apsides, spin rate − ϖ̇;
docs/physics.md §6.7), so the starts are the paper's.

Prints: the classification of every start.
"""

from _common import parse, save
from _sections import arrays_for, numbers_for, section_panel

SYSTEMS = ("1991 VH", "2003 YT1", "2004 DC")


def main():
    args, started = parse(__doc__.splitlines()[0])
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso

    orbits = 150 if args.quick else 1500
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    numbers, arrays = {}, {}
    for ax, name in zip(axes, SYSTEMS):
        system = tso.catalog.system(name)
        starts = tso.catalog.section_starts(name)
        result, cls = section_panel(ax, system, starts, orbits,
                                    what=rf"$\omega_0$ = {system.omega0:.3f}")
        numbers.update(numbers_for(name, starts, cls))
        arrays.update(arrays_for(name.replace(" ", ""), result))
    save(args, "study06_sections", fig, arrays, {"orbits": orbits, "rtol": 1e-12,
                                                 "systems": list(SYSTEMS),
                                                 "coordinates": "apsidal"}, numbers, started)


if __name__ == "__main__":
    main()
