"""The rule that calls a run diverged (gearsym/analysis/divergence.py), against the rule as its docstring states
it, written again here, on records built to sit on each side of each of its thresholds: growing in every
quarter or not, by 1.25 times or not, past 100 times the run's scale or not, past a million times it or not,
non-finite, a transient that grows before the measured periods, an exponent below zero or not.

Records are what a run gives the rule: each period's strobe and each observed coordinate's extremes.
"""
from __future__ import annotations

import numpy as np
import pytest

from gearsym.analysis.divergence import (BOUND, DRIFT, GROWING, GROWTH, NON_FINITE, PAST_BOUND, find_divergence,
                                         within_bound)

STATES = OBSERVED = ("x", "v")


def records(size_x, size_v=None):
    """Records whose coordinates reach ``size_x`` (and ``size_v``) each period, symmetric about 0."""
    sx = np.asarray(size_x, dtype=float)
    sv = np.ones_like(sx) if size_v is None else np.asarray(size_v, dtype=float)
    size = np.stack([sx, sv], axis=1)
    strobe = size * 0.5
    return strobe, -size, size


def verdict(size_x, size_v=None, *, discard=0, contracting=False):
    strobe, low, high = records(size_x, size_v)
    return find_divergence(strobe, low, high, STATES, OBSERVED, discard, contracting)


def reference(size: np.ndarray, discard: int, contracting: bool):
    """The docstring's rule for one coordinate (the other stays at 1): (reason, period) or None. The run's scale
    is max(1, the largest |value| over the first period)."""
    scale = max(1.0, float(size[0]))
    if not np.isfinite(size).all():
        k = int(np.argmin(np.isfinite(size)))
        past = np.flatnonzero(size[:k] > BOUND * scale)
        return (PAST_BOUND, int(past[0]) + 1) if past.size else (NON_FINITE, k + 1)
    past = np.flatnonzero(size > BOUND * scale)
    if past.size:
        return PAST_BOUND, int(past[0]) + 1
    measured = size[discard:]
    if contracting or measured.size < 4:
        return None
    q = [part.max() for part in np.array_split(measured, 4)]
    if all(b > a for a, b in zip(q, q[1:])) and q[-1] >= GROWTH * q[0] and q[-1] >= DRIFT * scale:
        return GROWING, len(size)
    return None


def test_a_coordinate_that_grows_in_every_quarter_past_100_scales_has_diverged():
    size = np.linspace(2.0, 400.0, 40)  # (a stiffness that holds nothing: the drift of k = 0)
    d = verdict(size)
    assert (d.reason, d.coordinate, d.period, d.periods) == (GROWING, "x", 40, 40)
    assert d.start == 2.0 and d.reached == 400.0 and d.bound == DRIFT * 2.0
    assert verdict(size, contracting=True) is None  # an exponent below zero brings it back: a transient


@pytest.mark.parametrize("quarters, diverged", [
    ((10, 300, 200, 250), False),  # falls in the third quarter: a beat, not a divergence
    ((10, 300, 350, 340), False),  # falls in the last
    ((300, 200, 250, 350), False),  # falls in the second
    ((100, 110, 120, 124), False),  # rises every quarter, but by less than 1.25 times
    ((20, 40, 60, 99), False),  # rises 5 times, but stays below 100 times the scale (1)
    ((20, 40, 60, 101), True),
    ((100, 110, 120, 126), True),
])
def test_growth_must_rise_in_every_quarter_by_a_quarter_and_past_100_scales(quarters, diverged):
    """Each quarter of 10 periods reaches its value once (the others below it), the first period at 1."""
    size = np.concatenate([np.r_[1.0, np.full(8, 0.5), q] if i == 0 else np.r_[np.full(9, 0.5), q]
                           for i, q in enumerate(quarters)])
    d = verdict(size)
    assert (d is not None and d.reason == GROWING) == diverged, d
    assert (reference(size, 0, False) is not None) == diverged


def test_the_scale_is_the_runs_first_period_so_a_large_start_needs_a_larger_growth():
    """Started at 5 the scale is 5: rising to 400 is not 100 scales, and 3e6 is not a million scales."""
    size = np.r_[5.0, np.linspace(5.0, 400.0, 39)]
    assert verdict(size) is None
    assert verdict(np.r_[1.0, size[1:]]).reason == GROWING
    big = np.r_[5.0, np.full(20, 3e6)]
    assert verdict(big, contracting=True) is None
    d = verdict(np.r_[5.0, np.full(5, 3e6), 6e6, np.full(5, 2e6)], contracting=True)
    assert (d.reason, d.period, d.bound, d.reached) == (PAST_BOUND, 7, BOUND * 5.0, 6e6)


def test_the_transient_is_not_measured_for_growth():
    """Discarded periods that rise do not make a settled motion diverged; the same rise measured does."""
    size = np.r_[1.0, np.linspace(2.0, 300.0, 19), np.full(20, 300.0) - np.arange(20) * 0.1]
    assert verdict(size, discard=20) is None
    rising = np.r_[1.0, np.full(19, 2.0), np.linspace(2.0, 300.0, 20)]
    assert verdict(rising, discard=20).reason == GROWING


def test_a_record_that_becomes_non_finite_says_when_and_whether_it_passed_the_bound_first():
    d = verdict(np.r_[1.0, 10.0, 100.0, np.inf, np.nan])
    assert (d.reason, d.period, d.overflow, d.reached) == (NON_FINITE, 4, 4, 100.0)
    d = verdict(np.r_[1.0, 10.0, 2e6, 5e7, np.inf], contracting=True)
    assert (d.reason, d.period, d.overflow, d.reached) == (PAST_BOUND, 3, 5, 5e7)
    d = verdict(np.ones(6), np.r_[1.0, 1.0, np.nan, 1.0, 1.0, 1.0])  # v's record, not x's
    assert (d.reason, d.coordinate, d.period) == (NON_FINITE, "v", 3)


def test_the_rule_is_the_docstrings_on_many_records():
    """Random records near the thresholds: growths of 1.1 to 1.4 times, ends of 50 to 200 scales, dips, starts
    of 0.5 to 5, a transient, overflows; every verdict (reason and period) is the rule's."""
    rng = np.random.default_rng(37)
    seen = set()
    for _ in range(400):
        periods = int(rng.integers(8, 60))
        discard = int(rng.integers(0, periods // 2))
        start = float(rng.choice([0.5, 1.0, 2.0, 5.0]))
        end = start * float(rng.choice([0.5, 50, 90, 110, 200, 2e5, 3e6]))
        size = np.geomspace(max(start, 1e-3), max(end, 1e-3), periods) * rng.uniform(0.8, 1.0, periods)
        size[0] = start
        if rng.random() < 0.3:  # a dip somewhere
            k = int(rng.integers(1, periods))
            size[k:] *= rng.uniform(0.3, 0.9)
        if rng.random() < 0.1:
            size[int(rng.integers(1, periods)):] = np.inf
        contracting = bool(rng.random() < 0.2)
        d = verdict(size, discard=discard, contracting=contracting)
        expected = reference(size, discard, contracting)
        assert (None if d is None else (d.reason, d.period)) == expected, (size.tolist(), discard, contracting)
        seen.add(None if expected is None else expected[0])
    assert seen == {None, GROWING, PAST_BOUND, NON_FINITE}


def test_a_continuation_goes_on_only_from_a_state_within_the_bound():
    start = np.array([3.0, -1.0])
    assert within_bound(np.array([2.9e6, 5.0]), start, STATES)
    assert not within_bound(np.array([3.1e6, 5.0]), start, STATES)  # a million times |start| = 3
    assert not within_bound(np.array([1.0, np.nan]), start, STATES)
    assert within_bound(np.array([3.1e6, 5.0]), start, STATES, counted=lambda names: [])  # (a free disk's twist)
