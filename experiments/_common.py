"""Shared plumbing for the experiment scripts: arguments, output folder, saving.

Every study script calls :func:`parse` (``--quick`` for CI, ``--out`` folder, ``--arch``),
computes, then :func:`save` writes ``<out>/<name>.npz`` (arrays + JSON parameters via
ti_spinorbit.io conventions) and ``<out>/<name>.png``, and prints the numbers it stands for.
"""

import argparse
import datetime
import os
import time



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
    from ti_spinorbit.io import write_archive

    png = os.path.join(args.out, f"{name}.png")
    npz = os.path.join(args.out, f"{name}.npz")
    fig.tight_layout()
    fig.savefig(png, dpi=150)
    plt.close(fig)
    meta = {"study": name, "package_version": tso.__version__, "quick": bool(args.quick),
            "arch": tso.runtime.current_arch(),
            "created_utc": datetime.datetime.now(datetime.timezone.utc).isoformat(),
            "seconds": time.perf_counter() - started, "parameters": parameters,
            "numbers": numbers}
    write_archive(npz, arrays, meta)
    print(f"[{name}] " + ", ".join(f"{k} = {_fmt(v)}" for k, v in numbers.items()))
    print(f"[{name}] wrote {png} and {npz} in {meta['seconds']:.1f} s")
    return png, npz


def _fmt(v):
    if isinstance(v, float):
        return f"{v:.6g}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_fmt(x) for x in v) + "]"
    return str(v)
