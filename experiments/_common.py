"""Shared plumbing for the experiment scripts: arguments, output folder, saving.

The study scripts keep their file names study01 … study15 (stable names for the CLI's
``figures --only``, the saved files and the gallery's images) but are NAMED BY WHAT THEY
REPRODUCE of Naidu & Margot 2015: :data:`PAPER` maps each to the paper's figure or section;
its docstring's first line starts with that label, :func:`save` prints it, stores it in the
metadata and puts it in the figure's title (experiments/README.md has the table).

Every study script calls :func:`parse` (``--quick`` for CI, ``--out`` folder, ``--arch``),
computes, then :func:`save` writes ``<out>/<name>.npz`` (arrays + JSON parameters via
ti_spinorbit.output.io conventions) and ``<out>/<name>.png``, and prints the numbers it stands for.
"""

import argparse
import datetime
import os
import time


#: The paper's figure or (for results given in its text) section that each study reproduces.
PAPER = {
    "study01": "Fig. 1",          # energy exchange, energy-test system
    "study02": "Fig. 3",          # relaxed libration vs mass ratio
    "study03": "Fig. 2",          # angle diagram
    "study04": "Figs. 4–5",       # 1991 VH sections at a/b = 1.01 and 1.06
    "study05": "Fig. 6",          # ΔE/E0 contours and the overlap line
    "study06": "Figs. 7–9",       # sections of 1991 VH, 2003 YT1, 2004 DC
    "study07": "§6",              # overlap thresholds (text)
    "study08": "Fig. 10",         # relaxed libration vs elongation
    "study09": "Fig. 11",         # spin rate vs time
    "study10": "§8.1",            # tidal and YORP energy budgets (text)
    "study11": "§7",              # robustness to the secondary's c (text)
    "study12": "§7.1–7.3",        # 2:1 capture, 2003 YT1 libration, no 2004 DC island (text)
    "study13": "§3",              # energy and angular-momentum drift per year (text)
    "study14": "§8",              # does chaos delay synchronisation? tides in the equations
    "study15": "§2",              # beyond the paper: its order-4 model against order and shape
    "study16": "§8",              # beyond the paper: Earth flybys of 1991 VH (its non-synchronous secondary)
}


def paper_label(name):
    """"Fig. 3", "§6", ... for a study name such as ``study02_libration_mass_ratio``; None for
    scripts that are not studies of the paper."""
    return PAPER.get(name[:7])


def parse(description, extra=None):
    """Standard arguments; ``extra(parser)`` may add more. Returns (args, started_at)."""
    p = argparse.ArgumentParser(description=description)
    p.add_argument("--quick", action="store_true", help="small, fast run (CI)")
    p.add_argument("--out", default="out", help="output folder (default: out/)")
    p.add_argument("--arch", default=None, help="Taichi arch: cpu (default), cuda, ...")
    if extra is not None:
        extra(p)
    args = p.parse_args()
    os.makedirs(args.out, exist_ok=True)
    import ti_spinorbit as tso

    tso.init(arch=args.arch)
    return args, time.perf_counter()


def save(args, name, fig, arrays, parameters, numbers, started):
    """Write <out>/<name>.png and .npz (arrays + metadata JSON); print the key numbers."""
    import matplotlib.pyplot as plt

    import ti_spinorbit as tso
    from ti_spinorbit.output.io import write_archive
    from ti_spinorbit.output.plotting import raw_markup

    png = os.path.join(args.out, f"{name}.png")
    npz = os.path.join(args.out, f"{name}.npz")
    paper = paper_label(name)
    if paper is not None:
        texts = [fig._suptitle.get_text() if fig._suptitle is not None else ""]
        texts += [ax.get_title() for ax in fig.axes]
        if not any(paper in t for t in texts):       # name the figure by the paper's number
            old = texts[0]
            fig.suptitle(f"Naidu & Margot 2015, {paper}" + (f": {old}" if old else ""),
                         fontsize=10)
    raw = raw_markup(fig)        # labels use mathtext: θ_p as $\theta_p$, never "_" or "^"
    fig.tight_layout()
    fig.savefig(png, dpi=150, bbox_inches="tight")   # legends outside the axes stay in
    plt.close(fig)
    meta = {"study": name, "package_version": tso.__version__, "quick": bool(args.quick),
            "arch": tso.runtime.current_arch(),
            "created_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(),
            "paper": paper, "seconds": time.perf_counter() - started, "parameters": parameters,
            "numbers": numbers}
    write_archive(npz, arrays, meta)
    what = f"Naidu & Margot 2015 {paper}: " if paper else ""
    print(f"[{name}] {what}" + ", ".join(f"{k} = {_fmt(v)}" for k, v in numbers.items()))
    print(f"[{name}] wrote {png} and {npz} in {meta['seconds']:.1f} s")
    if raw:                      # after the files: the numbers are never lost to a label
        raise ValueError(f"{name}: figure texts with raw '_' or '^' outside mathtext: {raw[:5]}")
    return png, npz


def _fmt(v):
    if isinstance(v, float):
        return f"{v:.6g}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_fmt(x) for x in v) + "]"
    return str(v)
