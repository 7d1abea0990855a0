"""Figures in a notebook executed headless, as JupyterHub, a remote kernel, nbconvert or CI
run one: no display, no MPLBACKEND, so the kernel starts with Matplotlib's inline backend.
Every cell that draws (three results' ``.plot()`` and then the user's own
``plt.plot([0, 1])``) must show exactly one image: a library that switched the backend
(``matplotlib.use``) would leave the later cells, the user's own figure among them, blank.

The kernel is this interpreter (a kernel spec written for the test, so a ``python3`` spec
pointing elsewhere cannot stand in for it); the runs are tiny (two members, a few orbits).
About 15 s on 2 cores, most of it the kernel importing Taichi and loading its kernels."""

import json
import sys

import pytest

import ti_spinorbit as tso

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")
pytest.importorskip("ipykernel")

KERNEL = "ti-spinorbit-test-python"

SETUP = """\
import sys
import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import ti_spinorbit as tso
vh = tso.catalog.system("1991 VH")
print(sys.executable)
print(tso.__file__)
print(matplotlib.get_backend())"""

#: The cells that draw, each as a user writes it; each must show one image.
DRAWING = {
    "section": 'tso.surface_of_section(vh, 0.0, [0.83, 1.63], orbits=3, rtol=1e-9).plot()',
    "time series": ('ts = tso.time_series(vh, 0.0, [0.83, 1.63], orbits=2, samples_per_orbit=8,\n'
                    '                     rtol=1e-9)\n'
                    'ts.plot()'),
    "chaos map": ('cmap = tso.chaos_map(vh, [30.0, 120.0], [0.8, 1.6], orbits=3)\n'
                  'cmap.plot()\n'
                  'plt.show()'),
    "the user's own figure": 'plt.plot([0, 1])\nplt.show()',
}


def _kernel_spec(folder):
    """A kernel spec running this interpreter's ipykernel, under ``folder/kernels``."""
    spec = folder / "kernels" / KERNEL
    spec.mkdir(parents=True)
    (spec / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "ti_spinorbit test", "language": "python"}))


def _images(cell):
    return [o for o in cell.outputs
            if o.get("output_type") in ("display_data", "execute_result")
            and "image/png" in o.get("data", {})]


def test_every_plot_cell_of_a_headless_notebook_shows_one_image(tmp_path, monkeypatch):
    _kernel_spec(tmp_path / "jupyter")
    monkeypatch.setenv("JUPYTER_PATH", str(tmp_path / "jupyter"))
    for name in ("MPLBACKEND", "DISPLAY", "WAYLAND_DISPLAY"):   # headless, as Jupyter starts
        monkeypatch.delenv(name, raising=False)
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell(SETUP)] + \
        [nbformat.v4.new_code_cell(source) for source in DRAWING.values()]
    client = nbclient.NotebookClient(nb, kernel_name=KERNEL, timeout=300,
                                     resources={"metadata": {"path": str(tmp_path)}})
    client.execute()

    printed = "".join(o.get("text", "") for o in nb.cells[0].outputs
                      if o.get("output_type") == "stream" and o.get("name") == "stdout")
    executable, package, backend = printed.split("\n")[:3]
    assert executable == sys.executable                         # the kernel is this venv's
    assert package == tso.__file__                               # and runs this checkout
    assert "inline" in backend, backend                          # what Jupyter gives a kernel
    assert not _images(nb.cells[0])
    counts = {name: len(_images(cell)) for name, cell in zip(DRAWING, nb.cells[1:])}
    assert counts == {name: 1 for name in DRAWING}
