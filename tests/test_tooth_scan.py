"""Which tooth (gearsym/fit/tooth_scan.py): a tooth counted from tau = 0 as each record counts it, for records that
start at any fraction of a mesh period (0.5 and beyond included) and meshes of order other than 1; and the windows
in which a tooth's pair is in mesh, against a brute-force scan of the mesh phase.

Teeth are counted from tau = 0: tooth n is in single contact in mesh period n (phase in [n - 1, n) mesh periods,
the mesh phase being order * tau / 2 pi), its pair in mesh over the contact ratio's 1.6 mesh periods centred on
n - 1/2, and the scan computes a tooth's column on a window within half a mesh period of that.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from gearsym.fit.tooth_scan import CONTACT, MARGIN, _meets, from_record_start


def counted_from(start: float, teeth: int, order: float) -> list[int]:
    """The teeth (counted from tau = 0) in the order a record starting at ``start`` (tau) meets them: first the
    one in single contact in the mesh period it starts in."""
    period_index = math.floor(order * start / (2 * math.pi) + 1e-9)
    return [(period_index + j) % teeth + 1 for j in range(teeth)]


@pytest.mark.parametrize("order", [1.0, 0.5, 2.5])
@pytest.mark.parametrize("fraction", [0.0, 0.3, 0.5, 0.75, 0.999])
def test_a_record_counts_teeth_from_the_one_in_mesh_where_it_starts(order, fraction):
    teeth = 13
    for whole in (0, 1, 7, 12, 13, 30):
        start = 2 * math.pi * (whole + fraction) / order  # (in tau: the mesh phase is order tau)
        seen = counted_from(start, teeth, order)
        for n in range(1, teeth + 1):
            assert from_record_start(n, teeth, start, order) == seen.index(n) + 1, (whole, fraction, n)


def test_a_record_from_tau_zero_counts_as_tau_does():
    assert [from_record_start(n, 9, 0.0) for n in range(1, 10)] == list(range(1, 10))
    # half a mesh period in, still the first mesh period: nothing moves; a whole one in, every tooth moves back one
    assert from_record_start(4, 9, math.pi) == 4 and from_record_start(4, 9, 2 * math.pi) == 3
    assert from_record_start(1, 9, 2 * math.pi) == 9


def in_mesh(t0: float, t1: float, tooth: int, teeth: int, period: float) -> bool:
    """Brute force: whether the mesh phase passes, in [t0, t1], within MARGIN mesh periods of the pair's path of
    contact (CONTACT mesh periods centred on tooth - 1/2, every revolution)."""
    phase = np.linspace(t0, t1, 4001) / period  # in mesh periods
    offset = (phase - (tooth - 0.5)) % teeth
    distance = np.minimum(offset, teeth - offset)
    return bool((distance <= CONTACT / 2 + MARGIN + 1e-9).any())


@pytest.mark.parametrize("order", [1.0, 2.5])
def test_a_tooths_windows_are_those_where_its_pair_is_in_mesh(order):
    teeth, period = 9, 2 * math.pi / order
    rng = np.random.default_rng(37)
    agree = {True: 0, False: 0}
    for _ in range(300):
        t0 = rng.uniform(0, 3 * teeth * period)
        t1 = t0 + rng.uniform(0.05, 2.5) * period
        tooth = int(rng.integers(1, teeth + 1))
        expected = in_mesh(t0, t1, tooth, teeth, period)
        assert _meets(t0, t1, tooth, teeth, period) == expected, (t0 / period, t1 / period, tooth)
        agree[expected] += 1
    assert min(agree.values()) > 50  # (both answers were asked for often)
