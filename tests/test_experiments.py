"""Every study script's --quick mode runs (CI), writes its figure and its data with
parameters, and prints the numbers it stands for; every study is named by the paper figure or
section it reproduces (experiments/_common.py ``PAPER``), and together they cover all 11 of
the paper's figures."""

import glob
import json
import os
import re
import subprocess
import sys

import numpy as np
import pytest

# the slow part of the suite: deselect with -m "not slow" (README, its first lines)
pytestmark = pytest.mark.slow

EXPERIMENTS = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "experiments")
STUDIES = sorted(os.path.basename(p)[:-3] for p in glob.glob(os.path.join(EXPERIMENTS, "study[0-9][0-9]_*.py")))
# every other experiment script too, except private helpers and the benchmark (timed, not tested)
OTHERS = sorted(os.path.basename(p)[:-3] for p in glob.glob(os.path.join(EXPERIMENTS, "[a-z]*.py"))
                if not os.path.basename(p).startswith(("study", "bench")))


sys.path.insert(0, EXPERIMENTS)
from _common import PAPER, paper_label  # noqa: E402  (the experiments folder is not a package)

sys.path.remove(EXPERIMENTS)


def test_every_study_is_named_by_the_paper():
    # file names: a running number, no gaps (``ti-spinorbit figures --only N`` uses it)
    assert [s[:7] for s in STUDIES] == [f"study{k:02d}" for k in range(1, len(STUDIES) + 1)]
    assert sorted(PAPER) == [s[:7] for s in STUDIES]
    figures = set()
    for study in STUDIES:
        label = paper_label(study)
        assert re.fullmatch(r"Figs?\. \d+(–\d+)?|§\d+(\.\d+)?(–\d+(\.\d+)?)?", label), label
        first = open(os.path.join(EXPERIMENTS, f"{study}.py"), encoding="utf-8").readline()
        assert first.startswith(f'"""Paper {label} (Naidu & Margot 2015'), (study, first)
        assert study[:7] in first                    # and it says which script it is
        m = re.fullmatch(r"Figs?\. (\d+)(?:–(\d+))?", label)
        if m:
            figures.update(range(int(m[1]), int(m[2] or m[1]) + 1))
    assert figures == set(range(1, 12))              # all 11 of the paper's figures
    assert paper_label("chaos_maps") is None


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
    if study in STUDIES:                             # printed and stored under the paper's name
        assert f"[{study}] Naidu & Margot 2015 {paper_label(study)}: " in p.stdout
        assert meta["paper"] == paper_label(study)
