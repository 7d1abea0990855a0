"""Figures in the conventions of Naidu & Margot 2015 (matplotlib, imported lazily).

Surface of section: θ_p (deg) in [0°, 180°) horizontally, θ̇_p/n vertically, one colour per
trajectory unless a classification gives the paper's colours (resonant red, chaotic blue,
quasi-periodic green)."""

from .classify import COLORS as CLASS_COLORS  # the paper's red / blue / green
from .coordinates import THETADOT_LABEL       # "θ̇_p/n (inertial)" or "(apsidal)"


def _pyplot():
    import matplotlib

    if matplotlib.get_backend().lower() not in ("agg", "pdf", "svg") and not _has_display():
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _has_display():
    import os

    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def plot_section(result, ax=None, colors=None, markersize=1.5, title=None, legend=True):
    """Scatter a SectionResult; ``colors`` is one colour per member (or a class name from
    CLASS_COLORS). Returns the matplotlib Axes."""
    plt = _pyplot()
    if ax is None:
        _, ax = plt.subplots(figsize=(6.4, 4.8), dpi=150)
    n = len(result.count)
    if colors is None:
        cmap = plt.get_cmap("viridis" if n > 10 else "tab10")
        colors = [cmap(k / max(n - 1, 1)) if n > 10 else cmap(k % 10) for k in range(n)]
    colors = [CLASS_COLORS.get(c, c) if isinstance(c, str) else c for c in colors]
    for k in range(n):
        c = result.count[k]
        label = f"θ̇p/n = {result.initial_thetadot_p[k]:.2f}" if n <= 12 else None
        if label and result.status_names[k] != "done":     # say which points to distrust
            label += f" ({result.status_names[k]})"
        ax.plot(result.theta_p[k, :c], result.thetadot_p[k, :c], ".", ms=markersize,
                color=colors[k], label=label)
    ax.set_xlim(0, 180)
    ax.set_xticks(range(0, 181, 30))
    ax.set_xlabel(r"$\theta_p$ (deg)")
    ax.set_ylabel(THETADOT_LABEL[getattr(result, "coordinates", "inertial")])
    if title is None:
        s = result.systems[0]
        axes = getattr(s.secondary, "semi_axes", None)
        shape = f", a/b = {axes[0] / axes[1]:.2f}" if axes else ""
        title = f"{s.name}{shape}, e = {s.e:.3g}, {result.orbits:g} orbits, rtol {result.rtol:.0e}"
    ax.set_title(title, fontsize=9)
    if legend and n <= 12:
        ax.legend(fontsize=6, markerscale=4, loc="best", framealpha=0.6)
    return ax


def save_figure(ax, path):
    """Write the figure of ``ax`` to ``path`` (PNG/PDF by extension) and close it."""
    plt = _pyplot()
    fig = ax.figure
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path
