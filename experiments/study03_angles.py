"""Paper Fig. 2 (Naidu & Margot 2015; script study03): the angle notation, drawn schematically.

f: true anomaly (primary-to-secondary direction measured from the line of apsides);
θ: the secondary's long axis measured from the line of apsides; α: the long axis measured
from the line of centres. ti_spinorbit uses α = θ − f, so that at pericentre (f = 0) α equals
the section angle θ_p; Naidu & Margot's angle diagram (docs/physics.md §6.2) writes
θ + α = f, the same angle with the opposite sign.
Amplitudes (max |α|) do not depend on the sign.
"""

import numpy as np

from _common import parse, save


def main():
    args, started = parse(__doc__.splitlines()[0])
    import matplotlib.pyplot as plt
    from matplotlib.patches import Arc, Circle, Ellipse

    f, theta = np.radians(50.0), np.radians(80.0)
    r = 3.0
    sx, sy = r * np.cos(f), r * np.sin(f)
    fig, ax = plt.subplots(figsize=(6, 5))
    ax.add_patch(Circle((0, 0), 0.6, color="0.6"))
    ax.add_patch(Ellipse((sx, sy), 0.9, 0.55, angle=np.degrees(theta), color="0.35"))
    ax.plot([-0.5, 4.2], [0, 0], "k--", lw=0.8)
    ax.annotate("line of apsides (to pericentre)", (3.0, -0.25), fontsize=8)
    ax.plot([0, sx * 1.35], [0, sy * 1.35], "k-", lw=0.8)
    ax.annotate("line of centres", (sx * 1.05 + 0.1, sy * 1.3), fontsize=8)
    L = 1.1
    ax.plot([sx, sx + L * np.cos(theta)], [sy, sy + L * np.sin(theta)], "r-", lw=1.5)
    ax.plot([sx, sx + 1.4], [sy, sy], "k:", lw=0.8)
    ax.annotate("long axis", (sx + L * np.cos(theta) - 0.2, sy + L * np.sin(theta) + 0.1),
                color="r", fontsize=8)
    ax.add_patch(Arc((0, 0), 1.8, 1.8, theta1=0, theta2=np.degrees(f)))
    ax.annotate("f", (0.95 * np.cos(f / 2) + 0.05, 0.95 * np.sin(f / 2)), fontsize=11)
    ax.add_patch(Arc((sx, sy), 1.2, 1.2, theta1=0, theta2=np.degrees(theta), color="b"))
    ax.annotate(r"$\theta$", (sx + 0.65 * np.cos(theta / 2), sy + 0.65 * np.sin(theta / 2)),
                color="b", fontsize=11)
    ax.add_patch(Arc((sx, sy), 2.0, 2.0, theta1=np.degrees(f), theta2=np.degrees(theta), color="g"))
    mid = (f + theta) / 2
    ax.annotate(r"$\alpha$", (sx + 1.05 * np.cos(mid), sy + 1.05 * np.sin(mid)), color="g", fontsize=11)
    ax.set_aspect("equal")
    ax.set_xlim(-1, 4.8)
    ax.set_ylim(-1, 4.2)
    ax.axis("off")
    ax.set_title("Angles: true anomaly f, long-axis angle θ, libration angle α (schematic)", fontsize=9)
    save(args, "study03_angles", fig, {"f_deg": np.degrees(f), "theta_deg": np.degrees(theta)},
         {"schematic": True}, {"alpha_deg": float(np.degrees(theta - f))}, started)


if __name__ == "__main__":
    main()
