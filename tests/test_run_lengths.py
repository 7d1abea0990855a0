"""The shared loop of the length-convergence checks (ti_spinorbit.engine.convergence.run_lengths):
stages in order with their share of the progress, stopped when settled."""

import pytest

from ti_spinorbit.engine.convergence import run_lengths


def test_every_length_runs_in_order_with_its_share_of_the_progress():
    seen, reports = [], []

    def stage(k, length, share):
        share(0.0)
        share(0.5)
        share(1.0)
        seen.append((k, length))
        return length * 10

    ladder = run_lengths([1, 2, 5], stage, reports.append)
    assert seen == [(0, 1.0), (1, 2.0), (2, 5.0)]
    assert ladder.outcomes == [10.0, 20.0, 50.0] and not ladder.settled
    assert ladder.lengths == [1.0, 2.0, 5.0] and ladder.done == pytest.approx(1.0)
    # shares proportional to the lengths: 1/8, 2/8, 5/8 of the work
    assert reports == pytest.approx([0.0, 1 / 16, 1 / 8, 1 / 8, 1 / 4, 3 / 8, 3 / 8,
                                     3 / 8 + 5 / 16, 1.0])


def test_settled_stops_the_ladder_and_reports_the_end():
    reports = []
    outcomes = iter([3, 1, 1, 1])
    ladder = run_lengths([1, 2, 4, 8], lambda k, L, share: next(outcomes), reports.append,
                         settled=lambda a, b: a == b)
    assert ladder.settled and ladder.lengths == [1.0, 2.0, 4.0] and ladder.outcomes == [3, 1, 1]
    assert reports[-1] == 1.0
    assert ladder.done == pytest.approx(7 / 15)


def test_work_after_the_ladder_keeps_its_share():
    reports = []
    ladder = run_lengths([1, 1], lambda k, L, share: share(1.0) or k, reports.append,
                         settled=lambda a, b: True, extra_work=2.0)
    assert ladder.settled and reports == pytest.approx([0.25, 0.5])   # no 1.0 yet
    assert ladder.done == pytest.approx(0.5)
