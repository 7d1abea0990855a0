"""``import ti_spinorbit`` is quiet and cheap: it prints nothing (no "[Taichi] version" banner)
and imports neither Taichi nor the kernels until the first computation. The kernels package's
pure-Python data modules are the exception: the Butcher tableaux and the controller
(``kernels/tableau.py``, ``kernels/controller.py``, no Taichi) are the one registry of methods
the host reads its method names from.

Each check runs in a fresh interpreter (``sys.executable``, this environment passed through so
PYTHONPATH keeps working): the test session itself has long since imported Taichi. The
variable that silences Taichi's banner is removed, so the banner would show if Taichi were
imported."""

import os
import subprocess
import sys

import pytest

#: The kernels package's modules that hold data only (no Taichi), which the host imports.
PURE = ("ti_spinorbit.kernels", "ti_spinorbit.kernels.tableau", "ti_spinorbit.kernels.controller")
#: Print the Taichi and kernel modules loaded (one line, a Python list).
LOADED = ("import sys; print(sorted(m for m in sys.modules if m.split('.')[0] == 'taichi' "
          f"or m.startswith('ti_spinorbit.kernels') and m not in {PURE!r}))")


def run_python(code):
    env = dict(os.environ)
    env.pop("ENABLE_TAICHI_HEADER_PRINT", None)
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, timeout=300)


def test_import_prints_nothing():
    done = run_python("import ti_spinorbit")
    assert done.returncode == 0, done.stderr
    assert (done.stdout, done.stderr) == ("", "")


@pytest.mark.parametrize("code", [
    "import ti_spinorbit",
    "import ti_spinorbit as tso; from ti_spinorbit import cli; from ti_spinorbit.output import io, "
    "plotting; from ti_spinorbit.studies import classify; from ti_spinorbit.model import analytic",
    # describing a system and printing it is not a computation either
    "import ti_spinorbit as tso; s = tso.catalog.system('1991 VH'); repr(s); s._repr_html_(); "
    "s.omega0, s.orbital_period",
])
def test_no_taichi_until_the_first_computation(code):
    done = run_python(f"{code}; {LOADED}")
    assert done.returncode == 0, done.stderr
    assert done.stdout == "[]\n", done.stdout
    assert "[Taichi]" not in done.stderr


def test_the_first_computation_brings_taichi_in():
    """The other side of the lazy import (so the checks above can fail): initialising the
    runtime imports Taichi, banner and all."""
    done = run_python(f"import ti_spinorbit as tso; tso.init(); {LOADED}")
    assert done.returncode == 0, done.stderr
    assert "'taichi'" in done.stdout
    assert "[Taichi] version" in done.stdout + done.stderr
