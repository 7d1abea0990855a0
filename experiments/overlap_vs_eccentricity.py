"""Resonance-overlap threshold vs eccentricity (the numerical counterpart of the
Chirikov estimate ω0^RO = 1/(2 + sqrt(14 e)) for the 1:1 and 3:2 resonances).

1991 VH with its eccentricity replaced by each value of a grid; at each e the elongation a/b
is scanned in steps of 0.01 (ti_spinorbit.studies.overlap) with MEGNO evidence for every connecting
trajectory. Higher e widens the 3:2 island (half-width ω0 sqrt(7e/2)), so overlap sets in at
smaller elongation.

Prints: numerical and analytic first-overlap a/b for each e, and the connecting orbits' ⟨Y⟩.
"""

import numpy as np

from _common import parse, save


def main():
    args, started = parse(__doc__.splitlines()[0])
    import matplotlib.pyplot as plt

    from ti_spinorbit.model import analytic
    from ti_spinorbit.studies.overlap import overlap_vs_eccentricity

    if args.quick:
        ecc, elong, kw = [0.05, 0.3], [1.01, 1.03, 1.06], dict(orbits=120, centre_starts=24,
                                                              separatrix_starts=12)
    else:
        ecc, elong, kw = [0.01, 0.05, 0.1, 0.2, 0.3], np.round(np.arange(1.01, 1.105, 0.01), 10), \
            dict(orbits=400)
    e, first, analytic_ab, scans = overlap_vs_eccentricity("1991 VH", ecc, elongations=elong, **kw)
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    fine = np.linspace(0.002, max(ecc) * 1.05, 200)
    ax.plot(fine, analytic.overlap_elongation(fine), "k--", label=r"analytic $\omega_0^{RO}(e)$")
    ax.plot(e, first, "o", color="tab:red", label="numerical (first overlapping a/b)")
    for s in scans:                       # every decision, faint: separate (green), overlap (blue)
        ax.scatter(np.full(len(s.elongations), s.eccentricity), s.elongations, s=8,
                   c=["tab:blue" if o else "tab:green" for o in s.overlaps], alpha=0.4)
    ax.set_xlabel("eccentricity e")
    ax.set_ylabel("elongation a/b")
    ax.set_title("1991 VH: 1:1 / 3:2 overlap threshold vs e", fontsize=9)
    ax.legend(fontsize=8)
    numbers = {}
    for s, f, a in zip(scans, first, analytic_ab):
        megno = [d.connecting_megno for d in s.decisions if d.overlap]
        numbers[f"e={s.eccentricity:g}"] = (f"numerical {f:.2f}, analytic {a:.4f}, connecting <Y> "
                                            f"min {min(megno):.1f}" if megno else
                                            f"no overlap up to {max(s.elongations):.2f}, analytic {a:.4f}")
    save(args, "overlap_vs_eccentricity", fig,
         {"eccentricity": e, "numerical_first_overlap": first, "analytic_elongation": analytic_ab,
          "elongations": np.asarray(elong)}, {"system": "1991 VH", **kw, "elongations": elong},
         numbers, started)


if __name__ == "__main__":
    main()
