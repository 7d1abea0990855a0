"""Paper Figs. 4–5 (Naidu & Margot 2015; script study04): sections of 1991 VH at low elongation.

a/b = 1.01 (starts θ̇_p/n = 1.08 1.15 1.28 1.55 1.57 1.68 1.78) and a/b = 1.06 (1.13 1.63
1.70 1.78), all with θ_p = 0. At such low elongation (ω0 = 0.17 and 0.41) the resonances are
narrow and mostly separated by invariant curves: regular motion dominates, with thin chaotic
layers near the separatrices.

Coordinates: apsidal, the paper's (θ̇ from the osculating line of apsides, spin rate − ϖ̇;
docs/physics.md §6.7), so the starts are the paper's. In inertial coordinates the same
numbers start ϖ̇(0) ≈ 0.016 n lower and three a/b = 1.01 starts change class (1.15, 1.28,
1.57); --coordinates inertial shows them.

Prints: the classification of every start.
"""

from _common import parse, save
from _sections import arrays_for, numbers_for, section_panel

CASES = {1.01: [1.08, 1.15, 1.28, 1.55, 1.57, 1.68, 1.78], 1.06: [1.13, 1.63, 1.70, 1.78]}


def main():
    args, started = parse(__doc__.splitlines()[0], lambda p: p.add_argument(
        "--coordinates", choices=("apsidal", "inertial"), default="apsidal",
        help="section coordinates (default apsidal, the paper's)"))
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso

    orbits = 150 if args.quick else 1500
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6))
    numbers, arrays = {}, {}
    for ax, (q, starts) in zip(axes, CASES.items()):
        system = tso.catalog.system("1991 VH", elongation=q)
        result, cls = section_panel(ax, system, starts, orbits,
                                    what=rf"$\omega_0$ = {system.omega0:.3f}",
                                    coordinates=args.coordinates)
        numbers.update(numbers_for(f"a/b={q}", starts, cls))
        arrays.update(arrays_for(f"ab{q}", result))
    save(args, "study04_sections_low_elongation", fig, arrays,
         {"orbits": orbits, "rtol": 1e-12, "cases": {str(k): v for k, v in CASES.items()},
          "coordinates": args.coordinates},
         numbers, started)


if __name__ == "__main__":
    main()
