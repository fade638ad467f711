"""Counters of predicate calls and undecided filter stages: one layout and one
vocabulary for both pipelines (``stats["counts"]``).

``counts`` is an int64 array indexed by the constants below.  The first six
are the predicates of paper 1's Table 1: calls, calls the stage-1 filter left
undecided, and calls stage 2 left undecided (decided by stage 3, exact
arithmetic); the stages are numbered as in lfqt.predicates.planar.
"Incircle" is the in-sphere test in 3D.  Incremental insertion adds paper
2's conflicting cells, skipped duplicates and cycles per phase.
"""
import numpy as np
from numba import njit

from .planar import incircle_staged, orient2d_staged

ORIENT, ORIENT_S1, ORIENT_S2, INCIRCLE, INCIRCLE_S1, INCIRCLE_S2 = range(6)
CONFLICTS, DUPLICATES, LOCATE_CYCLES, CAVITY_CYCLES = range(6, 10)
N_PREDICATE = 6   # the merge's counters
N_INSERT = 10     # incremental insertion's
NAMES = ("orientation_tests", "orientation_stage1_undecided", "orientation_stage2_undecided",
         "incircle_tests", "incircle_stage1_undecided", "incircle_stage2_undecided",
         "conflicts", "duplicates", "locate_cycles", "cavity_cycles")
PER_POINT = ("orientation_tests", "incircle_tests", "conflicts")


def new_counters(size=N_PREDICATE):
    return np.zeros(size, dtype=np.int64)


def as_dict(counts):
    """{name: int} of a counts array (its first len(counts) names)."""
    return dict(zip(NAMES, map(int, counts)))


def per_point(counts, points):
    """The per-point rates of paper 2 (tests and conflicts over ``points``)."""
    return {k: counts[k] / max(points, 1) for k in PER_POINT if k in counts}


@njit(cache=True, inline="always")
def tally(counts, first, stage):
    """Count one call of the predicate whose counters start at ``first``
    (ORIENT or INCIRCLE), decided by ``stage`` (1, 2 or 3)."""
    counts[first] += 1
    counts[first + 1] += stage > 1
    counts[first + 2] += stage > 2


@njit(cache=True, inline="always")
def tally_undecided(counts, first, stage):
    """The stage counts of ``tally`` alone, for a caller that counts its
    calls itself: nothing for a call stage 1 decided, on a branch, so that
    the common case does not touch ``counts``."""
    if stage > 1:
        counts[first + 1] += 1
        if stage > 2:
            counts[first + 2] += 1


@njit(cache=True, inline="always")
def orient2d(ax, ay, bx, by, cx, cy, bound, counts):
    """orient2d_staged, counted in ``counts``."""
    det, stage = orient2d_staged(ax, ay, bx, by, cx, cy, bound)
    tally(counts, ORIENT, stage)
    return det


@njit(cache=True, inline="always")
def incircle(ax, ay, bx, by, cx, cy, dx, dy, bound, counts):
    """incircle_staged, counted in ``counts``."""
    det, stage = incircle_staged(ax, ay, bx, by, cx, cy, dx, dy, bound)
    tally(counts, INCIRCLE, stage)
    return det
