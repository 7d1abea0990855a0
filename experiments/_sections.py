"""Shared code of the section studies (4 and 6): run, classify, draw panels in the paper's
convention (resonant red, chaotic blue, quasi-periodic green)."""

import numpy as np


def section_panel(ax, system, starts, orbits, rtol=1e-12, what=None, coordinates="apsidal"):
    """Integrate the starts (θ_p = 0), classify, draw (the classes in the paper's colours,
    with a legend of the classes below the panel; the title names system, a/b, e, orbits,
    rtol, then ``what``); returns (result, classification). ``coordinates`` defaults to the
    paper's apsidal ones (docs/physics.md §6.7): the starts θ̇_p/n are the paper's numbers."""
    import ti_spinorbit as tso
    from ti_spinorbit.studies.classify import classify_section
    from ti_spinorbit.output.plotting import run_title

    result = tso.surface_of_section(system, 0.0, np.array(starts, dtype=float), orbits=orbits,
                                    rtol=rtol, coordinates=coordinates)
    cls = classify_section(result)
    result.plot(ax=ax, classes=cls.classification, markersize=1.0, legend_loc="below",
                title=run_title([system], orbits, rtol, what))       # grey: undetermined
    for k, w in enumerate(starts):   # label each trace by its start, at its first point
        ax.annotate(f"{w}", (result.theta_p[k, 0] + 2, result.thetadot_p[k, 0]), fontsize=6)
    return result, cls


def numbers_for(prefix, starts, cls):
    """One printed entry per start: its label (and resonance for resonant orbits)."""
    out = {}
    for k, w in enumerate(starts):
        label = cls.classification[k]
        if label == "resonant" and np.isfinite(cls.resonance_p[k]):
            label += f" p={cls.resonance_p[k]:g}"
        out[f"{prefix} {w}"] = label
    return out


def arrays_for(prefix, result):
    return {f"{prefix}_theta_p": result.theta_p, f"{prefix}_thetadot_p": result.thetadot_p,
            f"{prefix}_starts": result.initial_thetadot_p, f"{prefix}_count": result.count}
