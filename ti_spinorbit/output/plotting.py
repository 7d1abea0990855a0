"""Figures in the conventions of Naidu & Margot 2015 (matplotlib, imported lazily).

Surface of section: θ_p (deg) in [0°, 180°) horizontally, θ̇_p/n vertically, one colour per
trajectory unless a classification gives the paper's colours (resonant red, chaotic blue,
quasi-periodic green).

How the figures are laid out, wherever they are shown or saved:

* The backend is the session's. Nothing here calls ``matplotlib.use``: in a notebook the
  figures are the inline ones, a headless script gets Matplotlib's own fallback (Agg), and
  only the command line picks a file backend for itself.
* A figure this module creates (no ``ax=`` given) uses Matplotlib's constrained layout
  (``layout="constrained"``), which makes room for legends outside the axes, colourbars and
  titles, so a plain ``fig.savefig(path)`` keeps every legend and no panel overlaps another.
  With your own ``ax``, create its figure with ``layout="constrained"`` as well (or ask for a
  legend inside the axes, ``legend_loc="inside"``, where a function offers it).
* Legend texts and legend titles are ``LEGEND_FONTSIZE`` (8 pt), titles ``TITLE_FONTSIZE``
  (9 pt); a title longer than its axes is broken after a comma.
"""

import os
import re

import numpy as np

from ..model import analytic
from ..studies.classify import COLORS as CLASS_COLORS  # the paper's red / blue / green
from ..model.coordinates import THETADOT_LABEL       # "θ̇_p/n (inertial)" or "(apsidal)"
from ..display import elongation, span
from ..files import atomic_write
from ..engine import results as _results

# matplotlib is imported inside the functions that draw (pyplot through _pyplot), so that
# importing the package, or this module, does not load it.

#: Font size (pt) of legend texts and legend titles.
LEGEND_FONTSIZE = 8
#: Font size (pt) of axes titles (the run's identity, broken into lines to fit the axes).
TITLE_FONTSIZE = 9
#: Where ``legend_loc`` may put a legend: right of the axes, below them (under the x label),
#: or inside them (Matplotlib's ``loc="best"``).
LEGEND_PLACES = ("right", "below", "inside")

#: MEGNO colour scale of maps: 2 (regular) to 8 and beyond (chaotic; the colourbar says ≥ 8).
MEGNO_COLOR_RANGE = (0.0, 8.0)


def _pyplot():
    """matplotlib.pyplot with the backend the session chose: a library never switches it
    (in a notebook that would turn the inline figures off for the whole kernel); the
    command line picks a file backend for itself (``cli.common.choose_backend``)."""
    import matplotlib.pyplot as plt      # matplotlib: when a figure is drawn

    return plt


#: Members up to which a section gets a legend (one entry per start); beyond it a colourbar of
#: the start θ̇_p(0)/n.
MAX_LEGEND = 10
#: Label of the start's spin rate (mathtext).
START_LABEL = r"$\dot\theta_p(0)/n$"
#: Label of MEGNO (mathtext).
MEGNO_LABEL = r"MEGNO $\langle Y\rangle$"
#: Colour order of the classes in legends and the classification map.
CLASS_ORDER = ("resonant", "quasi-periodic", "chaotic", "undetermined")


def _class_color(name):
    return CLASS_COLORS.get(name, "0.6")         # undetermined: grey


def run_title(systems, orbits=None, rtol=None, what=None):
    """A figure title with the run's identity: system, a/b, e, orbits, rtol, e.g.
    "1991 VH, a/b = 1.41, e = 0.05, 300 orbits, rtol 1e-12" (ranges for several systems),
    then ": what" when given."""
    unique = list({id(s): s for s in (systems or ())}.values())
    parts = []
    if len(unique) == 1:
        s = unique[0]
        parts += [str(s.name), f"a/b = {elongation(s.secondary):.3g}", f"e = {s.e:.3g}"]
    elif unique:
        names = sorted({str(s.name) for s in unique})
        parts += [", ".join(names[:2]) + (" …" if len(names) > 2 else ""),
                  f"a/b = {span([elongation(s.secondary) for s in unique])}",
                  f"e = {span([s.e for s in unique])}"]
    if orbits is not None:
        parts.append(f"{orbits:g} orbits")
    if rtol is not None and rtol == rtol:      # NaN: not known (old files)
        parts.append(f"rtol {rtol:.0e}")
    title = ", ".join(parts)
    return f"{title}: {what}" if what else title


def _figure(nrows=1, ncols=1, size=(6.4, 4.8), **kwargs):
    """A new figure with its Axes, in constrained layout (room for legends outside the axes,
    colourbars and titles: a plain ``savefig`` clips nothing)."""
    return _pyplot().subplots(nrows, ncols, figsize=size, dpi=150, layout="constrained",
                              **kwargs)


def _axes(ax, size=(6.4, 4.8)):
    if ax is None:
        _, ax = _figure(size=size)
    return ax


def _text_width_points(text, fontsize):
    """Width (pt) of ``text`` at ``fontsize`` as Matplotlib draws it (mathtext included),
    measured with the Agg renderer whatever the session's backend."""
    from matplotlib.backends.backend_agg import RendererAgg
    from matplotlib.font_manager import FontProperties
    from matplotlib.text import Text

    _, ismath = Text(text=text)._preprocess_math(text)
    width, _, _ = RendererAgg(1, 1, 72).get_text_width_height_descent(
        text, FontProperties(size=fontsize), ismath=ismath)
    return width


def _title(ax, title, fontsize=TITLE_FONTSIZE):
    """Set ``title`` on ``ax``, broken after a comma or colon (never inside mathtext) into
    lines no wider than the axes as first placed, so that a long run title is never cut at
    the figure's edge (layout engines give a title no room sideways)."""
    if not title:
        return
    fig = ax.figure
    width = fig.get_figwidth() * 72.0 * ax.get_position().width
    pieces, piece = [], ""
    for part in re.split(r"(?<=[,:]) ", title):
        piece = f"{piece} {part}" if piece else part
        if piece.count("$") % 2 == 0:            # not inside $...$
            pieces.append(piece)
            piece = ""
    if piece:
        pieces.append(piece)
    lines, line = [], ""
    for part in pieces:
        longer = f"{line} {part}" if line else part
        if line and _text_width_points(longer, fontsize) > width:
            lines.append(line)
            line = part
        else:
            line = longer
    lines.append(line)
    ax.set_title("\n".join(lines), fontsize=fontsize)


def _below_offset_points():
    """Points from the bottom of an axes to below its x tick labels and x label, from the
    rcParams (mathtext labels are a little taller than plain text: 1.5 line heights)."""
    from matplotlib import rcParams
    from matplotlib.font_manager import FontProperties

    def points(size):
        return FontProperties(size=size).get_size_in_points()

    ticks = (max(rcParams["xtick.major.size"], 0.0) + rcParams["xtick.major.pad"]
             + 1.3 * points(rcParams["xtick.labelsize"]))
    label = rcParams["axes.labelpad"] + 1.5 * points(rcParams["axes.labelsize"])
    return ticks + label + 2.0


def _legend_outside(ax, where="right", **kwargs):
    """A legend of ``ax`` placed by ``where``: "right" (outside, top-aligned with the axes),
    "below" (outside, under the x label, centred) or "inside" (``loc="best"``). Texts and the
    title at ``LEGEND_FONTSIZE``. Outside legends never cover the data; in a figure with
    constrained layout (the package's own) the layout makes room for them."""
    if where not in LEGEND_PLACES:
        raise ValueError(f"legend_loc must be 'right', 'below' or 'inside' (got {where!r})")
    if where == "right":
        place = dict(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    elif where == "below":
        from matplotlib.transforms import ScaledTranslation

        down = ScaledTranslation(0.0, -_below_offset_points() / 72.0, ax.figure.dpi_scale_trans)
        place = dict(loc="upper center", bbox_to_anchor=(0.5, 0.0), borderaxespad=0.0,
                     bbox_transform=ax.transAxes + down, ncol=kwargs.pop("ncol", 4))
    else:
        place = dict(loc="best")
    options = {"fontsize": LEGEND_FONTSIZE, "title_fontsize": LEGEND_FONTSIZE,
               "framealpha": 0.8, **kwargs}
    return ax.legend(**place, **options)


def class_legend(ax, classes, where="right", **kwargs):
    """A legend of the classes present (the paper's colours), titled "class", at ``where``:
    "right" of the axes, "below" them (under the x label) or "inside" them."""
    from matplotlib.lines import Line2D      # matplotlib: when a figure is drawn

    present = [c for c in CLASS_ORDER if c in set(map(str, classes))]
    handles = [Line2D([], [], ls="", marker="o", ms=4, color=_class_color(c), label=c)
               for c in present]
    return _legend_outside(ax, where, handles=handles, title="class", **kwargs)


def plot_section(result, ax=None, colors=None, markersize=1.5, title=None, legend=True,
                 classes=None, colorbar=True, legend_loc="right"):
    """Scatter a SectionResult: θ_p (deg, 0-180) horizontally against θ̇_p/n (units of the
    mean motion, in the result's coordinates) vertically, one dot per pericentre passage.
    Colours: ``classes`` (one class name per member, e.g.
    ``classify_section(result).classification``) in the paper's colours with a legend of the
    classes; else ``colors`` (one per member, colours or class names); else one per member
    with a legend for up to ``MAX_LEGEND`` members (labelled by the start θ̇_p(0)/n, and the
    status where it is not "done") and, above that, a colourbar of the start θ̇_p(0)/n.
    ``legend_loc`` puts the legend "right" of the axes (default), "below" them or "inside";
    without ``ax`` the figure is 6.4 × 4.8 in, 150 dpi, in constrained layout, so an outside
    legend is kept by a plain ``savefig``. The title is the run
    (:func:`run_title`; ``title=""`` for none). Returns the Axes."""
    plt = _pyplot()
    ax = _axes(ax)
    n = len(result.count)
    start = np.asarray(result.initial_thetadot_p, dtype=np.float64)
    by_start = None
    if classes is not None:
        classes = [str(c) for c in np.asarray(classes).ravel()]
        colors = [_class_color(c) for c in classes]
    elif colors is not None and all(isinstance(c, str) and c in CLASS_ORDER for c in colors):
        classes = list(colors)
        colors = [_class_color(c) for c in classes]
    elif colors is None and n > MAX_LEGEND:
        from matplotlib.colors import Normalize      # matplotlib: when a figure is drawn

        lo, hi = float(np.nanmin(start)), float(np.nanmax(start))
        by_start = plt.cm.ScalarMappable(Normalize(lo, hi if hi > lo else lo + 1e-9),
                                         plt.get_cmap("viridis"))
        colors = [by_start.to_rgba(w) for w in start]
    elif colors is None:
        cmap = plt.get_cmap("tab10")
        colors = [cmap(k % 10) for k in range(n)]
    per_member = classes is None and by_start is None and n <= MAX_LEGEND
    names = result.status_names
    for k in range(n):
        c = result.count[k]
        label = None
        if per_member:
            label = rf"{START_LABEL} = {start[k]:.2f}"
            if names[k] != "done":          # say which points to distrust
                label += f" ({names[k]})"
        ax.plot(result.theta_p[k, :c], result.thetadot_p[k, :c], ".", ms=markersize,
                color=colors[k], label=label, rasterized=n > 50)
    ax.set_xlim(0, 180)
    ax.set_xticks(range(0, 181, 30))
    ax.set_xlabel(r"$\theta_p$ (deg)")
    ax.set_ylabel(THETADOT_LABEL[getattr(result, "coordinates", "inertial")])
    if title is None:
        title = run_title(result.systems, result.orbits, result.rtol)
    _title(ax, title)
    if by_start is not None and colorbar:
        ax.figure.colorbar(by_start, ax=ax, pad=0.01).set_label(START_LABEL)
    elif legend and classes is not None:
        class_legend(ax, classes, legend_loc)
    elif legend and per_member:
        _legend_outside(ax, legend_loc, markerscale=4)
    return ax


def _edges(centres, low=None, high=None):
    """Cell edges for pcolormesh from cell centres (midpoints; outer cells mirrored)."""
    c = np.asarray(centres, dtype=np.float64)
    if c.size == 1:
        half = 0.5 if low is None else 0.5 * (high - low)
        return np.array([c[0] - half, c[0] + half])
    mid = 0.5 * (c[1:] + c[:-1])
    return np.concatenate([[2 * c[0] - mid[0]], mid, [2 * c[-1] - mid[-1]]])


#: Colour range (deg, log scale) of chaos maps of the largest pole tilt.
TILT_COLOR_RANGE = (1e-3, 90.0)


def plot_chaos_map(cmap, ax=None, quantity="megno", overlay=False, overlay_members=64,
                   colorbar=True, title=None):
    """pcolormesh of a ChaosMap: MEGNO (colours 0-8, ``extend="max"``: the top colour is
    ⟨Y⟩ ≥ 8), the Lyapunov exponent (``quantity="lyapunov"``, 1/orbit) or the classes
    (``"classification"``, with a legend of the classes) or the largest pole tilt
    (``"max_tilt"``, deg, log colours over ``TILT_COLOR_RANGE``) over θ_p (x, deg) and θ̇_p/n
    (y).
    ``overlay=True`` adds the section points of up to ``overlay_members`` evenly spaced members
    as small black dots. The class legend sits right of the axes; without ``ax`` the figure
    is 6.4 × 4.8 in in constrained layout (colourbar and legend inside the saved image). The
    title is the run with its chaotic fraction. Returns the Axes."""
    from matplotlib.colors import ListedColormap      # matplotlib: when a figure is drawn

    ax = _axes(ax)
    x, y = _edges(cmap.theta_p, 0.0, 180.0), _edges(cmap.thetadot_p)
    extend = "neither"
    if quantity == "megno":
        z = np.clip(cmap.megno, *MEGNO_COLOR_RANGE)
        kw, label = dict(cmap="magma", vmin=MEGNO_COLOR_RANGE[0], vmax=MEGNO_COLOR_RANGE[1]), MEGNO_LABEL
        extend = "max"
    elif quantity == "lyapunov":
        z, kw, label = cmap.lyapunov, dict(cmap="magma", vmin=0.0), r"$\lambda$ (1/orbit)"
    elif quantity == "max_tilt":
        from matplotlib.colors import LogNorm      # matplotlib: when a figure is drawn

        if getattr(cmap, "max_tilt", None) is None:
            raise ValueError("quantity='max_tilt' needs a map that recorded the tilt")
        # log scale: a regular member stays near its start tilt, an unstable one tumbles
        z = np.clip(cmap.max_tilt, TILT_COLOR_RANGE[0], TILT_COLOR_RANGE[1])
        kw = dict(cmap="viridis", norm=LogNorm(*TILT_COLOR_RANGE))
        label = "largest tilt of the pole (deg)"
    elif quantity == "classification":
        z = np.vectorize(lambda c: CLASS_ORDER.index(c) if c in CLASS_ORDER else 3)(
            cmap.classification).astype(float)
        kw = dict(cmap=ListedColormap([_class_color(k) for k in CLASS_ORDER]), vmin=-0.5,
                  vmax=3.5)
        label = "class"
    else:
        raise ValueError(f"quantity must be 'megno', 'lyapunov', 'classification' or "
                         f"'max_tilt' (got {quantity!r})")
    mesh = ax.pcolormesh(x, y, np.asarray(z).T, shading="flat", **kw)
    if colorbar and quantity == "classification":
        class_legend(ax, np.asarray(cmap.classification).ravel())
    elif colorbar:
        cb = ax.figure.colorbar(mesh, ax=ax, pad=0.01, extend=extend)
        cb.set_label(label)
        if quantity == "megno":
            ticks = list(range(0, int(MEGNO_COLOR_RANGE[1]) + 1, 2))
            cb.set_ticks(ticks)
            cb.set_ticklabels([str(t) for t in ticks[:-1]] + [rf"$\geq${ticks[-1]}"])
    if overlay and cmap.section is not None:
        sec = cmap.section
        pick = np.unique(np.linspace(0, len(sec.count) - 1,
                                     min(overlay_members, len(sec.count))).astype(int))
        ax.plot(sec.theta_p[pick].ravel(), sec.thetadot_p[pick].ravel(), ".", ms=0.6,
                color="k", alpha=0.6, rasterized=True)
    ax.set_xlim(0, 180)
    ax.set_ylim(y[0], y[-1])
    ax.set_xticks(range(0, 181, 30))
    ax.set_xlabel(r"$\theta_p$ (deg)")
    ax.set_ylabel(THETADOT_LABEL[cmap.coordinates])
    if title is None:
        systems = cmap.section.systems if cmap.section is not None else ()
        what = f"chaotic fraction {cmap.chaotic_fraction:.2f}"
        if cmap.n_inaccurate:
            what += (f" ({cmap.n_inaccurate} inaccurate members "
                     f"{'included' if cmap.include_inaccurate else 'excluded'})")
        title = run_title(systems, cmap.orbits, cmap.rtol, what)
    _title(ax, title)
    return ax


def plot_parameter_map(pmap, ax=None, contours=(1e-3, 1e-2, 0.1, 1.0), colorbar=True,
                       title=None):
    """pcolormesh of a ParameterMap's chaotic fraction over (e, a/b), with the analytic
    overlap line a/b(ω0^RO(e)) and contours of the chaotic-layer half-width ΔE/E0(ω0(a/b), e)
    (14π form as quoted), with the line's legend inside the axes (lower right). Without
    ``ax`` the figure is 6.4 × 4.8 in in constrained layout. Returns the Axes."""
    ax = _axes(ax)
    x = np.clip(_edges(pmap.eccentricities), 0.0, 0.999)  # physical ranges only
    y = np.maximum(_edges(pmap.elongations), 1.0)
    mesh = ax.pcolormesh(x, y, pmap.chaotic_fraction, shading="flat", cmap="viridis",
                         vmin=0.0, vmax=1.0)
    if colorbar:
        ax.figure.colorbar(mesh, ax=ax, pad=0.01).set_label("chaotic fraction")
    e_fine = np.linspace(max(x[0], 0.0), min(x[-1], 0.99), 200)
    ax.plot(e_fine, analytic.overlap_elongation(e_fine), "w--", lw=1.5,
            label=r"$\omega_0 = \omega_0^{RO}(e)$")
    q_fine = np.linspace(max(y[0], 1.001), y[-1], 200)  # ω0(1) = 0: no layer
    ee, qq = np.meshgrid(e_fine, q_fine)
    with np.errstate(all="ignore"):
        width = analytic.chaotic_layer_half_width(analytic.omega0(qq), np.maximum(ee, 1e-12))
    if contours:
        cs = ax.contour(ee, qq, width, levels=sorted(contours), colors="w", linewidths=0.7,
                        alpha=0.8)
        ax.clabel(cs, fmt=lambda v: rf"$\Delta E/E_0$={v:g}", fontsize=6)
    ax.set_xlim(x[0], x[-1])
    ax.set_ylim(y[0], y[-1])
    ax.set_xlabel(r"$e$")
    ax.set_ylabel(r"$a/b$")
    ax.legend(fontsize=LEGEND_FONTSIZE, loc="lower right", framealpha=0.5)
    if title is None:
        what = f"chaotic fraction of {pmap.megno.shape[-1]} starts"
        if pmap.n_inaccurate:
            what += (f" ({pmap.n_inaccurate} inaccurate starts "
                     f"{'included' if pmap.include_inaccurate else 'excluded'})")
        title = (f"{pmap.name}, a/b = {span(pmap.elongations)}, e = {span(pmap.eccentricities)}, "
                 f"{pmap.orbits:g} orbits, rtol {pmap.rtol:.0e}: {what}")
    _title(ax, title)
    return ax


def overlap_megno(scan):
    """Largest finite ⟨Y⟩ among each elongation's trajectories in the run its decision comes
    from (``OverlapDecision.max_megno``; for files written before it was kept, from the
    first run's sections), NaN where unknown: no indicators, or nothing saved."""
    out = np.full(len(scan.elongations), np.nan)
    for k, d in enumerate(scan.decisions):
        if d.max_megno is not None:
            out[k] = d.max_megno
        elif scan.sections is not None and scan.sections.megno is not None:
            sec, block = scan.section_block(k)
            megno = np.asarray(sec.megno[block], dtype=np.float64)
            if np.isfinite(megno).any():
                out[k] = np.nanmax(megno)
    return out


def plot_overlap(scan, ax=None, title=None):
    """Decision per elongation (overlap blue, separate green) with the numerical and the
    analytic thresholds, and on a second axis the largest MEGNO ⟨Y⟩ of each elongation's
    trajectories (chaos shows there before a trajectory connects the islands; the twin axes
    is ``ax.megno_axes``). One legend for both axes, inside (centre left). Without ``ax`` the
    figure is 6.4 × 3.6 in in constrained layout. Returns the Axes of the decisions."""
    ax = _axes(ax, (6.4, 3.6))
    ax.scatter(scan.elongations, scan.overlaps.astype(int),
               c=["tab:blue" if o else "tab:green" for o in scan.overlaps], s=25, zorder=3)
    ax.axvline(scan.elongation_ro, color="k", ls="--", lw=0.8,
               label=r"analytic $\omega_0 = \omega_0^{RO}$")
    if scan.first_overlap is not None:
        ax.axvline(scan.first_overlap, color="tab:red", lw=1.0, label="numerical")
    ax.set_yticks([0, 1], ["separate", "overlap"])
    ax.set_ylim(-0.3, 1.3)
    ax.set_xlabel(r"$a/b$")
    megno = overlap_megno(scan)
    handles, labels = ax.get_legend_handles_labels()
    if np.isfinite(megno).any():
        twin = ax.twinx()
        line, = twin.plot(scan.elongations, megno, "o-", color="tab:purple", ms=3, lw=0.8,
                          label=r"largest $\langle Y\rangle$")
        twin.axhline(4.0, color="tab:purple", lw=0.5, ls=":")
        twin.set_ylabel(MEGNO_LABEL, color="tab:purple")
        twin.set_ylim(bottom=0.0)
        handles.append(line)
        labels.append(line.get_label())
        ax.megno_axes = twin           # for callers (and tests) that want the ⟨Y⟩ axis
    ax.legend(handles, labels, fontsize=LEGEND_FONTSIZE, loc="center left")
    if title is None:
        verdict = "" if scan.lengths is None else \
            (f", converged at {scan.converged_orbits:g} orbits" if scan.converged
             else f", not converged by {scan.max_orbits:g} orbits (upper bound)")
        sec = scan.sections
        rtol = scan.rtol if scan.rtol == scan.rtol else getattr(sec, "rtol", None)
        title = (f"{scan.name}, a/b = {scan.elongations[0]:.3g}–{scan.elongations[-1]:.3g}, "
                 f"e = {scan.eccentricity:.3g}, {scan.orbits:g} orbits"
                 + (f", rtol {rtol:.0e}" if rtol is not None else "")
                 + f": 1:1 / 3:2 overlap{verdict}")
    _title(ax, title)
    return ax


def plot_time_series(ts, ax=None, quantity="thetadot", members=None, title=None):
    """One line per member against time (orbital periods of the first system): the spin rate
    θ̇/n (``quantity="thetadot"``), α (``"alpha"``, deg), θ (``"theta"``, deg) or r
    (``"r"``, units of a); time in orbital periods of each member's system. Members labelled
    by their start θ̇_p(0)/n (legend right of the axes, up to ``MAX_LEGEND``; a colourbar of
    the start beyond). Without ``ax`` the figure is 7 × 3.6 in, 150 dpi, in constrained
    layout, so a plain ``savefig`` keeps the legend; with your own ``ax``, give its figure
    ``layout="constrained"`` too. Returns the Axes."""
    labels = {"thetadot": r"$\dot\theta/n$" + f" ({ts.coordinates})", "alpha": r"$\alpha$ (deg)",
              "theta": r"$\theta$ (deg)", "r": r"$r/a$"}
    if quantity not in labels:
        raise ValueError(f"quantity must be one of {', '.join(labels)} (got {quantity!r})")
    plt = _pyplot()
    ax = _axes(ax, (7.0, 3.6))
    idx = range(len(ts.status)) if members is None else np.atleast_1d(members)
    idx = list(idx)
    start = ts.initial_thetadot_p
    mappable = None
    if len(idx) > MAX_LEGEND and start is not None:
        from matplotlib.colors import Normalize      # matplotlib: when a figure is drawn

        lo, hi = float(np.nanmin(start)), float(np.nanmax(start))
        mappable = plt.cm.ScalarMappable(Normalize(lo, hi if hi > lo else lo + 1e-9),
                                         plt.get_cmap("viridis"))
    for j, k in enumerate(idx):
        ok = np.isfinite(ts.t[k])
        period = ts.systems[k].orbital_period
        y = getattr(ts, quantity)[k, ok]
        if quantity == "r":
            y = y / ts.systems[k].a
        label = None if start is None or mappable is not None else \
            rf"{START_LABEL} = {start[k]:.3g}"
        color = mappable.to_rgba(start[k]) if mappable is not None else f"C{j % 10}"
        ax.plot(ts.t[k, ok] / period, y, lw=0.7, color=color, label=label)
    ax.set_xlabel("time (orbital periods)")
    ax.set_ylabel(labels[quantity])
    if mappable is not None:
        ax.figure.colorbar(mappable, ax=ax, pad=0.01).set_label(START_LABEL)
    elif start is not None:
        _legend_outside(ax)
    if title is None:
        title = run_title(ts.systems, ts.orbits, ts.rtol)
    _title(ax, title)
    return ax


def plot_conservation(ts, member=0, title=None):
    """Two panels for one member of a TimeSeriesResult: relative drift of the total energy
    and angular momentum, and the energy exchanged between orbit and spins, against time
    (:meth:`~ti_spinorbit.studies.section.TimeSeriesResult.conservation`), time in initial
    orbital periods; legends inside each panel. A new 7 × 6.5 in figure in constrained
    layout. Returns the top Axes."""
    numbers, (t, de, dl, parts) = ts.conservation(member)
    t_orbits = t / ts.systems[member].orbital_period
    fig, (top, bottom) = _figure(2, 1, size=(7, 6.5), sharex=True)
    top.plot(t_orbits, de, "k", lw=0.8, label=r"energy $\Delta E/|E_0|$")
    top.plot(t_orbits, dl, "C3", lw=0.8, label=r"angular momentum $|\Delta \mathbf{L}|/|L_0|$")
    top.set_ylabel("relative drift")
    top.legend(fontsize=LEGEND_FONTSIZE)
    if title is None:
        title = run_title([ts.systems[member]], ts.orbits, ts.rtol, "conservation")
    _title(top, title)
    for name, v in parts.items():
        bottom.plot(t_orbits, v, lw=0.8, label=f"{name}" + (" spin" if name != "orbit" else ""))
    bottom.set_ylabel(r"energy exchange $\Delta E_i/|E_0|$")
    bottom.set_xlabel("time (initial orbital periods)")
    bottom.legend(fontsize=LEGEND_FONTSIZE)
    return top


def plot_libration_search(result, axes=None):
    """Two panels of the centre search of a RelaxedLibration: every launch's section extent
    against the start θ̇_p(0)/n (the V whose tip is the centre), and the last window around
    the centre (start minus the centre, units of n); the left legend inside its panel. Without
    ``axes`` (two Axes) a new 9.6 × 4.2 in figure in constrained layout. Returns the left
    Axes."""
    if axes is None:
        _, axes = _figure(1, 2, size=(9.6, 4.2))
    left, right = axes
    for k, (x, extent) in enumerate(zip(result.candidates, result.extents)):
        style = dict(marker="o", ms=3, lw=0.8) if k == 0 else dict(marker=".", ms=2, lw=0.6)
        left.plot(x, extent, label="coarse" if k == 0 else ("zooms" if k == 1 else None),
                  **style)
    left.axvline(result.centre_thetadot_p, color="k", lw=0.6, ls="--", label="centre")
    left.set_xlabel(START_LABEL + f" ({result.coordinates})")
    left.set_ylabel(r"section extent max $|\theta_p|$ (deg)")
    left.legend(fontsize=LEGEND_FONTSIZE)
    x, extent = result.candidates[-1], result.extents[-1]
    right.plot(x - result.centre_thetadot_p, extent, ".-", ms=3, lw=0.6)
    right.axvline(0.0, color="k", lw=0.6, ls="--")
    right.set_xlabel(START_LABEL + r" $-$ centre")
    right.set_ylabel("extent (deg)")
    right.set_title(f"last window ({len(result.candidates) - 1} zooms)", fontsize=8)
    if any(np.isfinite(e).any() for e in result.extents):
        left.set_ylim(bottom=0)
    return left


def plot_libration(result, ax=None, title=None, search=None, legend_loc="below"):
    """α(t) (deg) of the trajectory at the island centre against time (orbital periods), with
    its amplitude max |α| (dashed) and the decoupled forced amplitude |ψ_A| as a band (ψ_A
    with ω0, and with ω0,eff dotted). The legend goes below the axes (``legend_loc``: or
    "right", "inside"), in two columns, so that it never reaches a neighbouring panel.
    Without ``ax`` (or with ``search=True``) the figure also gets the search's two panels
    (:func:`plot_libration_search`): a new 14.4 × 4.6 in figure (6.4 × 4.6 in alone) in
    constrained layout. The trajectory is the stored ``result.series`` (computed again for
    files written without it). Returns the Axes of α(t)."""
    search = ax is None if search is None else search
    if ax is None:
        fig, axes = _figure(1, 3 if search else 1, size=(14.4 if search else 6.4, 4.6),
                            squeeze=False)
        ax = axes[0, 0]
        if search:
            plot_libration_search(result, axes[0, 1:])
    ts = result.series if result.series is not None else result.trajectory()
    ok = np.isfinite(ts.t[0])
    t = ts.t[0, ok] / ts.systems[0].orbital_period
    alpha = np.unwrap(ts.alpha[0, ok], period=180.0)
    psi = abs(result.psi_A)
    if np.isfinite(psi):
        ax.axhspan(-psi, psi, color="tab:orange", alpha=0.2, lw=0,
                   label=rf"$|\psi_A|$ = {psi:.3g}° (decoupled)")
    if np.isfinite(result.psi_A_effective):
        for sign in (-1, 1):
            ax.axhline(sign * abs(result.psi_A_effective), color="tab:orange", lw=0.7, ls=":",
                       label=r"$|\psi_A|$ with $\omega_{0,\mathrm{eff}}$" if sign > 0 else None)
    ax.plot(t, alpha, "k", lw=0.7, label=r"$\alpha(t)$")
    for sign in (-1, 1):
        ax.axhline(sign * result.amplitude, color="tab:blue", lw=0.9, ls="--",
                   label=rf"amplitude max $|\alpha|$ = {result.amplitude:.3g}°" if sign > 0 else None)
    ax.set_xlabel("time (orbital periods)")
    ax.set_ylabel(r"$\alpha$ (deg)")
    _legend_outside(ax, legend_loc, **({"ncol": 2} if legend_loc == "below" else {}))
    if title is None:
        system = [result.system] if result.system is not None else ()
        title = run_title(system, result.orbits, result.rtol,
                          rf"centre {START_LABEL} = {result.centre_thetadot_p:.6g}"
                          + ("" if result.converged else " (NOT converged)"))
    _title(ax, title)
    return ax


def figure_texts(fig):
    """Every non-empty text of a figure (titles, axis and colourbar labels, legend entries,
    annotations, tick labels)."""
    from matplotlib.text import Text      # matplotlib: when a figure is drawn

    return [t.get_text() for t in fig.findobj(Text) if t.get_text()]


def raw_markup(fig):
    """The figure's texts that show a raw ``_`` or ``^`` outside mathtext (``$...$``): labels
    must say θ_p as ``$\\theta_p$``, never the characters."""
    return [t for t in figure_texts(fig) if re.search(r"[_^]", re.sub(r"\$[^$]*\$", "", t))]


def save_figure(ax, path):
    """Write the figure of ``ax`` to ``path`` (PNG, PDF or SVG by extension; PNG without
    one) and close it. A figure with a layout engine (the package's own: constrained layout)
    is saved as it is laid out, at its size; one without (an Axes of yours) is tightened
    first and cropped to its contents, so an outside legend stays. The write is atomic (:func:`ti_spinorbit.files.atomic_write`): the
    image goes to a temporary file in the same folder, fsync-ed, then replaces ``path``, so a
    failed or killed write never leaves a partial figure and never harms an existing one."""
    plt = _pyplot()
    fig = ax.figure
    try:
        laid_out = fig.get_layout_engine() is not None
        if not laid_out:
            fig.tight_layout()
        fmt = os.path.splitext(os.fspath(path))[1][1:].lower() or "png"
        with atomic_write(path) as fh:       # a file object: the format is given by name
            fig.savefig(fh, format=fmt, **({} if laid_out else {"bbox_inches": "tight"}))
    finally:
        plt.close(fig)
    return path


# Every result's plot() draws through this table (results.FIGURES), so the studies that
# define the results never import this module.
_results.FIGURES.update({
    ("section", "plot"): plot_section,
    ("time_series", "plot"): plot_time_series,
    ("time_series", "conservation"): plot_conservation,
    ("chaos_map", "plot"): plot_chaos_map,
    ("parameter_map", "plot"): plot_parameter_map,
    ("overlap_scan", "plot"): plot_overlap,
    ("relaxed_libration", "plot"): plot_libration,
})
