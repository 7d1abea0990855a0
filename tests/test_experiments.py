"""Every study script's --quick mode runs (CI), writes its figure and its data with
parameters, and prints the numbers it stands for."""

import glob
import json
import os
import subprocess
import sys

import numpy as np
import pytest

EXPERIMENTS = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "experiments")
STUDIES = sorted(os.path.basename(p)[:-3] for p in glob.glob(os.path.join(EXPERIMENTS, "study[0-9][0-9]_*.py")))
# every other experiment script too, except private helpers and the benchmark (timed, not tested)
OTHERS = sorted(os.path.basename(p)[:-3] for p in glob.glob(os.path.join(EXPERIMENTS, "[a-z]*.py"))
                if not os.path.basename(p).startswith(("study", "bench")))


def test_all_ten_studies_are_there():
    assert [s[:7] for s in STUDIES] == [f"study{k:02d}" for k in range(1, 11)]


@pytest.mark.parametrize("study", STUDIES + OTHERS)
def test_quick_mode(study, tmp_path):
    p = subprocess.run([sys.executable, f"{study}.py", "--quick", "--out", str(tmp_path)],
                       cwd=EXPERIMENTS, capture_output=True, text=True, timeout=900,
                       env=dict(os.environ, MPLBACKEND="Agg"))
    assert p.returncode == 0, p.stderr[-3000:]
    png = tmp_path / f"{study}.png"
    assert png.read_bytes()[:4] == b"\x89PNG" and png.stat().st_size > 5000
    with np.load(tmp_path / f"{study}.npz") as d:
        meta = json.loads(str(d["metadata"]))
    assert meta["quick"] is True and meta["numbers"]
    assert f"[{study}]" in p.stdout
