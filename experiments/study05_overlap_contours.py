"""Paper Fig. 6 (Naidu & Margot 2015; script study05): chaotic-layer width ΔE/E0 over (a/b, e), overlap line.

Decoupled theory (Wisdom, Peale & Mignard 1984): the synchronous separatrix is surrounded by a
chaotic layer of half-width ΔE/E0 ≈ (14π e/ω0³) exp(−π/(2ω0)), E0 = n²ω0²C/4, with
ω0² = 3(a² − b²)/(a² + b²) for an ellipsoid; and the 1:1 and 3:2 resonances overlap (large-scale
chaos) once ω0 > ω0^RO = 1/(2 + √(14e)). Pure analytic, no integration. The asynchronous
systems of Table 1 sit far beyond the overlap line; the 1991 VH variants a/b = 1.01 and 1.06 of
the paper's Figs. 4–5 bracket it.

Prints: the overlap elongation at e = 0.05, 0.18, 0.30 (decoupled, and with the coupled
ω0,eff of the system with that e), and ΔE/E0 at each marked system.
"""

import numpy as np

from _common import parse, save

ASYNCHRONOUS = ("1991 VH", "2003 YT1", "2004 DC")
#: 1991 VH elongations of the paper's Figs. 4–5 (low and moderate elongation).
VH_VARIANTS = (1.01, 1.06)
#: ΔE/E0 contour levels (log-spaced, one per decade).
LEVELS = 10.0 ** np.arange(-8, 2)


def main():
    args, started = parse(__doc__.splitlines()[0])
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    import ti_spinorbit as tso
    from ti_spinorbit.model import analytic

    n_q, n_e = (201, 161) if args.quick else (801, 641)
    # (a) the paper's linear a/b axis; (b) a/b − 1 on a log axis, where the layer's
    # exp(−π/(2ω0)) dependence and the overlap line (a/b ≈ 1.02-1.09) live
    grids = {"linear": np.linspace(1.0, 2.0, n_q)[1:],     # a/b = 1 is a sphere: ω0 = 0
             "log": 1.0 + np.geomspace(1e-3, 1.0, n_q)}
    e = np.linspace(0.0, 0.4, n_e)
    e_line = np.linspace(0.0, 0.4, 401)
    q_line = analytic.overlap_elongation(e_line)
    widths = {}

    fig, axes = plt.subplots(1, 2, figsize=(13, 5.2))
    for ax, (kind, elongation) in zip(axes, grids.items()):
        Q, Egrid = np.meshgrid(elongation, e)
        width = widths[kind] = analytic.chaotic_layer_half_width(analytic.omega0(Q), Egrid)
        x = Q if kind == "linear" else Q - 1.0
        shown = np.clip(width, LEVELS[0] / 10, None)    # log norm: keep e = 0 (ΔE = 0) finite
        filled = ax.contourf(x, Egrid, shown, levels=LEVELS, norm=LogNorm(), cmap="viridis",
                             extend="both")
        lines = ax.contour(x, Egrid, width, levels=LEVELS, colors="w", linewidths=0.6)
        ax.clabel(lines, fmt=lambda v: f"{v:.0e}", fontsize=7,
                  manual=_label_positions(x, Egrid, width, kind))
        ax.plot(q_line if kind == "linear" else q_line - 1.0, e_line, "r", lw=2,
                label=r"1:1 / 3:2 overlap, $\omega_0 = \omega_0^{RO}(e)$")
        ax.set_ylim(0.0, 0.4)
        ax.set_ylabel("mutual-orbit eccentricity e")
    fig.colorbar(filled, ax=axes[1], label=r"$\Delta E / E_0$ (14π form)")  # same levels in both
    axes[0].set_xlim(1.0, 2.0)
    axes[0].set_xlabel("elongation a/b")
    axes[0].annotate("overlap: right of the red line", (1.1, 0.37), color="r", fontsize=8)
    axes[1].set_xscale("log")
    axes[1].set_xlim(1e-3, 1.0)
    ticks = np.array([1.001, 1.002, 1.005, 1.01, 1.02, 1.05, 1.1, 1.2, 1.5, 2.0])
    axes[1].set_xticks(ticks - 1.0, [f"{t:g}" for t in ticks])
    axes[1].minorticks_off()
    axes[1].set_xlabel("elongation a/b (log scale in a/b − 1)")
    axes[0].set_title(r"Chaotic-layer half-width $\Delta E/E_0 = (14\pi e/\omega_0^3)\,"
                      r"e^{-\pi/2\omega_0}$ and resonance overlap", fontsize=9)
    axes[1].set_title("the same, near a/b = 1", fontsize=9)

    numbers = {}
    marks = {}
    for k, name in enumerate(ASYNCHRONOUS):
        s = tso.catalog.system(name)
        q = tso.catalog.entry(name)["elongation"]
        dE = analytic.chaotic_layer_half_width(s.omega0, s.e)
        marks[name] = (q, s.e, dE)
        for ax, shift in zip(axes, (0.0, 1.0)):
            ax.plot(q - shift, s.e, marker="*", ms=14, color=f"C{k + 1}", mec="k", ls="none",
                    label=f"{name} (a/b = {q}, e = {s.e})")
        numbers[f"dE/E0 {name}"] = dE
    vh = tso.catalog.system("1991 VH")
    for q in VH_VARIANTS:
        dE = analytic.chaotic_layer_half_width(analytic.omega0(q), vh.e)
        marks[f"1991 VH a/b={q}"] = (q, vh.e, dE)
        for ax, shift in zip(axes, (0.0, 1.0)):
            ax.plot(q - shift, vh.e, marker="o", ms=7, mfc="none", mec="C1", mew=1.5, ls="none",
                    label="1991 VH a/b = 1.01, 1.06 (Figs. 4–5)" if q == VH_VARIANTS[0] else None)
        numbers[f"dE/E0 1991 VH a/b={q}"] = dE

    for e_i, name in zip((0.05, 0.18, 0.30), ASYNCHRONOUS):
        s = tso.catalog.system(name)
        fraction = s.primary.mass / s.total_mass
        numbers[f"omega0_RO(e={e_i})"] = analytic.omega0_overlap(e_i)
        numbers[f"overlap a/b(e={e_i})"] = analytic.overlap_elongation(e_i)
        numbers[f"overlap a/b(e={e_i}) coupled, {name} m1/M={fraction:.4f}"] = \
            analytic.overlap_elongation(e_i, primary_mass_fraction=fraction)

    axes[0].legend(fontsize=7, loc="upper right", framealpha=0.9)
    save(args, "study05_overlap_contours", fig,
         {"elongation": grids["linear"], "e": e, "dE_over_E0": widths["linear"],
          "elongation_log": grids["log"], "dE_over_E0_log": widths["log"], "overlap_e": e_line,
          "overlap_elongation": q_line,
          "marked_systems": np.array(list(marks)),
          "marked_values": np.array(list(marks.values()))},
         {"levels": LEVELS, "grid_points_a/b_e": [n_q, n_e], "coefficient": "14 pi"}, numbers, started)


def _label_positions(x, e, width, kind):
    """Where to put the contour labels: ΔE ∝ e crowds every level into e → 0, so label them
    along a row e ≈ 0.3 (log panel) or, on the linear panel, only the levels that cross the
    column a/b = 1.6 above e = 0.005."""
    positions = []
    if kind == "log":
        row = np.argmin(np.abs(e[:, 0] - 0.3))
        for level in LEVELS:
            above = np.flatnonzero(width[row] >= level)
            if len(above) and above[0] > 0:
                positions.append((x[row, above[0]], e[row, 0]))
    else:
        col = np.argmin(np.abs(x[0] - 1.6))
        for level in LEVELS:
            above = np.flatnonzero(width[:, col] >= level)
            if len(above) and e[above[0], col] > 0.005:
                positions.append((x[0, col], e[above[0], col]))
    return positions


if __name__ == "__main__":
    main()
