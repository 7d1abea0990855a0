"""The README says how long things take (issue "a tool that fits a scientist's day"): its
first lines give the two set-up commands and the fast part of the suite with their times,
and every quick-start call that integrates a grid, a scan or a long run is announced by a
comment that says roughly how long it takes."""

import os
import re

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: A duration as the README writes it: "15 s", "a few seconds", "1.5 min", "10.5 minutes".
DURATION = re.compile(r"\d+(\.\d+)? ?(s|min|minutes)\b|seconds")
#: The calls that take more than a few seconds at the paper's sizes.
LONG = ("tso.chaos_map(", "tso.overlap_threshold(", "tso.surface_of_section(vh, theta_p=")


def readme():
    return open(os.path.join(ROOT, "README.md"), encoding="utf-8").read().splitlines()


def test_the_first_lines_give_the_set_up_commands_and_the_suite_times():
    head = readme()[:12]
    assert head[2].strip().startswith("pip install . && ti-spinorbit section")
    assert head[3].strip() == 'pip install -e ".[test]" && python -m pytest -q'
    text = " ".join(head)
    assert '-m "not slow"' in text
    assert len(DURATION.findall(text)) >= 2           # the whole suite and its fast part


def test_every_long_quick_start_call_says_how_long():
    lines = readme()
    start = lines.index("## Quick start (Python)")
    end = next(k for k in range(start + 1, len(lines)) if lines[k].startswith("## "))
    calls = [k for k in range(start, end) if any(c in lines[k] for c in LONG)]
    assert len(calls) >= 3
    for k in calls:
        comments = " ".join(line for line in lines[max(start, k - 4):k]
                            if line.lstrip().startswith("#"))
        assert DURATION.search(comments), f"README line {k + 1} does not say how long: {lines[k]}"
