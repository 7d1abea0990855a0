"""``import ti_spinorbit`` is quiet and cheap: it prints nothing (no "[Taichi] version" banner)
and imports neither Taichi nor the kernels until the first computation. The kernels package's
pure-Python data modules are the exception: the Butcher tableaux and the controller
(``kernels/tableau.py``, ``kernels/controller.py``, no Taichi) are the one registry of methods
the host reads its method names from.

Each check runs in a fresh interpreter (``sys.executable``, this environment passed through so
PYTHONPATH keeps working): the test session itself has long since imported Taichi. The
variables that silence Taichi (or ask for its messages) are removed from that environment, so
what the package does is what is checked.

Taichi's own messages are hidden everywhere, library and command (ti_spinorbit/runtime.py):
the banner at ``import taichi``, the "Starting on arch" line of ``ti.init`` and the "Graphical
python shell detected" info line of a Jupyter-like process. ``TI_SPINORBIT_VERBOSE=1`` shows
them, which is also the proof that these checks can fail."""

import os
import subprocess
import sys

import pytest

#: The kernels package's modules that hold data only (no Taichi), which the host imports.
PURE = ("ti_spinorbit.kernels", "ti_spinorbit.kernels.tableau", "ti_spinorbit.kernels.controller")
#: Print the Taichi and kernel modules loaded (one line, a Python list).
LOADED = ("import sys; print(sorted(m for m in sys.modules if m.split('.')[0] == 'taichi' "
          f"or m.startswith('ti_spinorbit.kernels') and m not in {PURE!r}))")


#: Environment variables that decide what Taichi prints (the user's, or the package's opt-in).
TAICHI_CONSOLE_ENV = ("ENABLE_TAICHI_HEADER_PRINT", "TI_LOG_LEVEL", "TI_SPINORBIT_VERBOSE")
#: A tiny computation: Taichi imported, initialised, kernels compiled (or loaded) and run.
COMPUTE = ("import ti_spinorbit as tso; s = tso.catalog.system('1991 VH'); "
           "r = tso.surface_of_section(s, 0.0, [0.83], orbits=1); "
           "assert r.count[0] >= 1")
#: What Jupyter, IDLE and other graphical shells do: their own sys.stdout (Taichi's test for
#: "a graphical shell" is ``sys.stdout is not sys.__stdout__``, made at its import).
WRAPPED_STDOUT = ("import io, sys; sys.stdout = io.TextIOWrapper(sys.__stdout__.buffer, "
                  "write_through=True); ")


def run_python(code, **env_vars):
    env = {k: v for k, v in os.environ.items() if k not in TAICHI_CONSOLE_ENV}
    env.update(env_vars)
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


def test_the_first_computation_brings_taichi_in_silently():
    """The other side of the lazy import (so the checks above can fail): initialising the
    runtime imports Taichi, and Taichi prints nothing, neither its banner nor its start line."""
    done = run_python(f"import ti_spinorbit as tso; tso.init(); {LOADED}")
    assert done.returncode == 0, done.stderr
    assert "'taichi'" in done.stdout
    assert "[Taichi]" not in done.stdout + done.stderr
    assert done.stdout.count("\n") == 1 and done.stderr == ""     # the module list only


@pytest.mark.parametrize("shell", ["terminal", "graphical"])
def test_a_computation_prints_nothing(shell):
    """A computation (import, init, compile or load, run) writes nothing: no banner, no
    "Starting on arch", and in a Jupyter-like process (its own sys.stdout) no
    "[shell.py:_shell_pop_print@23] Graphical python shell detected" log line."""
    done = run_python((WRAPPED_STDOUT if shell == "graphical" else "") + COMPUTE)
    assert done.returncode == 0, done.stderr
    assert (done.stdout, done.stderr) == ("", "")


def test_verbose_shows_what_taichi_prints():
    """TI_SPINORBIT_VERBOSE=1 is the opt-in: banner, start line and the graphical-shell line
    (the same process as above, so that test would see them if they were not hidden)."""
    done = run_python(WRAPPED_STDOUT + COMPUTE, TI_SPINORBIT_VERBOSE="1")
    assert done.returncode == 0, done.stderr
    out = done.stdout + done.stderr
    assert "[Taichi] version" in out and "[Taichi] Starting on arch=" in out
    assert "Graphical python shell detected" in out


def test_init_verbose_and_the_users_own_settings_win():
    """init(verbose=True) shows the start line (and the banner: Taichi is not imported yet);
    a user's ENABLE_TAICHI_HEADER_PRINT=1 shows the banner only; the package's variables do
    not leak into the environment of child processes once Taichi is in."""
    done = run_python("import ti_spinorbit as tso; tso.init(verbose=True)")
    assert done.returncode == 0, done.stderr
    assert "[Taichi] version" in done.stdout and "[Taichi] Starting on arch=" in done.stdout
    done = run_python("import ti_spinorbit as tso; tso.init()", ENABLE_TAICHI_HEADER_PRINT="1")
    assert done.returncode == 0, done.stderr
    assert "[Taichi] version" in done.stdout and "Starting on arch" not in done.stdout
    done = run_python("import os, ti_spinorbit as tso; tso.init(); "
                      "print([k for k in os.environ if k in ('ENABLE_TAICHI_HEADER_PRINT', "
                      "'TI_LOG_LEVEL')])")
    assert done.returncode == 0, done.stderr
    assert done.stdout == "[]\n"


@pytest.mark.parametrize("verbose", [False, True])
def test_a_notebook_shows_no_taichi_lines(tmp_path, monkeypatch, verbose):
    """In a real Jupyter kernel (headless, nbclient) a computation's cell shows only what it
    prints: no banner, start line or "[shell.py:_shell_pop_print@23] Graphical python shell
    detected" line; with TI_SPINORBIT_VERBOSE=1 Taichi's lines show (so the check can fail)."""
    import json

    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    pytest.importorskip("ipykernel")
    spec = tmp_path / "jupyter" / "kernels" / "ti-spinorbit-quiet"
    spec.mkdir(parents=True)
    (spec / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "ti_spinorbit quiet test", "language": "python"}))
    monkeypatch.setenv("JUPYTER_PATH", str(tmp_path / "jupyter"))
    for name in TAICHI_CONSOLE_ENV:
        monkeypatch.delenv(name, raising=False)
    if verbose:
        monkeypatch.setenv("TI_SPINORBIT_VERBOSE", "1")
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell(COMPUTE.replace("; ", "\n") + "\nprint('ran')")]
    nbclient.NotebookClient(nb, kernel_name="ti-spinorbit-quiet", timeout=300,
                            resources={"metadata": {"path": str(tmp_path)}}).execute()
    shown = "".join(o.get("text", "") for o in nb.cells[0].outputs)
    if verbose:
        # (the graphical-shell line is Taichi's C++ log on the kernel's stderr: whether the
        # notebook shows it depends on ipykernel's capture of that file descriptor, so it is
        # checked by test_verbose_shows_what_taichi_prints instead)
        assert "[Taichi] version" in shown and "[Taichi] Starting on arch=" in shown, shown
    else:
        assert shown == "ran\n", shown
