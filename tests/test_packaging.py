"""Install layout and runtime set-up: kernels/ ships as ti_spinorbit.kernels in a normal
(wheel) install as well as the editable one the tests run from; init is idempotent."""

import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

import ti_spinorbit as tso

# the slow part of the suite: deselect with -m "not slow" (README, its first lines)
pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[1]


def test_wheel_contains_kernels_as_subpackage_and_catalogue(tmp_path):
    # build isolation fetches a current setuptools (CI reaches the package registry)
    p = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w",
                        str(tmp_path), str(ROOT)], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    wheel, = tmp_path.glob("ti_spinorbit-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    for f in ("ti_spinorbit/kernels/advance.py", "ti_spinorbit/kernels/mutual_gravity.py",
              "ti_spinorbit/data/systems.json", "ti_spinorbit/cli/__init__.py",
              "ti_spinorbit/cli/section.py", "ti_spinorbit/cli/options.py"):
        assert f in names
    assert not any(n.startswith("kernels/") for n in names)   # no top-level "kernels" package
    entry = [n for n in names if n.endswith("entry_points.txt")]
    assert entry and "ti-spinorbit = ti_spinorbit.cli:main" in zipfile.ZipFile(wheel).read(entry[0]).decode()


def test_editable_install_maps_kernels_directory():
    import ti_spinorbit.kernels as k
    # from this checkout the subpackage is the top-level kernels/ folder itself
    assert Path(k.__file__).resolve().parent == (ROOT / "kernels").resolve()


def test_init_is_idempotent_and_arch_env_override():
    assert tso.init() == tso.init() == tso.runtime.current_arch()
    code = ("import os, ti_spinorbit as t; os.environ['TI_SPINORBIT_ARCH']='cpu'; "
            "import taichi as ti; print(t.runtime.current_arch()); print(t.init())")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                         env=dict(os.environ, TI_SPINORBIT_ARCH="cpu"))
    lines = [x for x in out.stdout.strip().splitlines() if not x.startswith("[Taichi]")]
    assert lines == ["None", "cpu"]                 # nothing initialised at import time


def test_source_checkout_finds_its_own_kernels_without_an_editable_install(tmp_path):
    # After a plain `pip install .`, `python -m pytest` in a checkout imports the checkout's
    # ti_spinorbit/ (the current directory comes first on sys.path), which has no kernels/
    # subfolder: the package must find the checkout's top-level kernels/ itself, not fail
    # (or, under an editable install, silently use another tree's).
    import shutil
    for d in ("ti_spinorbit", "kernels"):
        shutil.copytree(ROOT / d, tmp_path / d, ignore=shutil.ignore_patterns("__pycache__"))
    code = "import ti_spinorbit.kernels.tableau as k; print(k.__file__)"
    p = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                       text=True, timeout=120, env=dict(os.environ, PYTHONPATH=""))
    assert p.returncode == 0, p.stderr
    assert Path(p.stdout.strip().splitlines()[-1]).resolve() == (tmp_path / "kernels" / "tableau.py").resolve()
