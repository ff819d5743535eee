"""Floquet multipliers far below the largest, from the shooting segments' maps (issue 38): the monodromy matrix of
a long period keeps its eigenvalues only down to its rounding."""
from __future__ import annotations

import numpy as np
import pytest

from gearsym.periodic.moduli import log_moduli


def test_the_moduli_of_a_product_of_segment_maps_are_exact_far_below_its_rounding():
    rng = np.random.default_rng(3)
    P = rng.normal(size=(4, 4)) + 3 * np.eye(4)
    rotation = np.array([[np.cos(0.7), -np.sin(0.7)], [np.sin(0.7), np.cos(0.7)]])
    D = np.zeros((4, 4))
    D[:2, :2] = 0.95 * rotation  # a complex pair of modulus 0.95 a segment
    D[2, 2], D[3, 3] = 1e-3, 1e-20  # a fast decay, and one a segment shrinks below its rounding
    blocks = [P @ D @ np.linalg.inv(P)] * 50
    exact = 50 * np.log([0.95, 0.95, 1e-3])
    assert np.max(np.abs(np.linalg.eigvals(np.linalg.multi_dot(blocks)))[2:]) > 1e-30  # eig of the product: noise
    logs, resolved = log_moduli(blocks)
    np.testing.assert_allclose(logs[:3], exact, rtol=1e-6)  # e^-345: the monodromy matrix would say 1e-17
    assert list(resolved) == [True, True, True, False]
    assert logs[3] > 50 * np.log(1e-20)  # lost: what is measured bounds it from above, never a value
