"""Integrate at increasing lengths until the answer stops changing.

Every number of the package that depends on integration length is reported with its
evidence: the same computation at several lengths (docs/design.md, "Converged, or it says
so"). Four entry points do this, each with its own decision:

* :func:`~ti_spinorbit.studies.chaosmap.chaos_map` and :func:`~ti_spinorbit.studies.chaosmap.parameter_map`:
  the chaotic fraction at fixed lengths (orbits/4, orbits/2, orbits), every length run;
* :func:`~ti_spinorbit.studies.overlap.overlap_threshold`: the overlap decisions at orbits,
  2·orbits, 4·orbits, ... until two lengths agree;
* :func:`~ti_spinorbit.studies.libration.relaxed_libration`: the island centre and amplitude at
  doubled lengths until two agree.

:func:`run_lengths` is the loop they share: one stage per length, in order, each given its
share of the progress (its length over the total planned work), stopped early when
``settled(previous, current)`` says so. The stages themselves (what is integrated, what is
kept) belong to the entry points.
"""

from dataclasses import dataclass
from typing import Any, Callable, List, Optional, Sequence

from . import progress as _progress


@dataclass
class Ladder:
    """The outcome of :func:`run_lengths`: the lengths run (orbits, in order), each stage's
    outcome, whether ``settled`` stopped the ladder, and the progress fraction reached (the
    start of any work the caller does after it)."""

    lengths: List[float]
    outcomes: List[Any]
    settled: bool
    done: float


def run_lengths(lengths: Sequence[float], stage: Callable[[int, float, Callable], Any],
                report, settled: Optional[Callable[[Any, Any], bool]] = None,
                extra_work: float = 0.0) -> Ladder:
    """Run ``stage(k, length, progress)`` for each length in ``lengths`` in order.

    ``progress`` is the stage's share of ``report`` (:func:`ti_spinorbit.engine.progress.stage`):
    work is counted in orbits, the planned lengths plus ``extra_work`` (a check the caller
    runs after the ladder). After every stage but the first, ``settled(previous, current)``
    (the two last outcomes) may stop the ladder; ``report(1.0)`` then says the work is done
    unless ``extra_work`` is still to come."""
    lengths = [float(x) for x in lengths]
    work = sum(lengths) + float(extra_work)
    outcomes, done = [], 0.0
    for k, length in enumerate(lengths):
        outcomes.append(stage(k, length, _progress.stage(report, done / work, length / work)))
        done += length
        if settled is not None and k > 0 and settled(outcomes[-2], outcomes[-1]):
            if not extra_work:
                report(1.0)
            return Ladder(lengths[:k + 1], outcomes, True, done / work)
    return Ladder(lengths, outcomes, False, done / work)
