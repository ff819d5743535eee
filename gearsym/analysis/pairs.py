"""Pairs of Lyapunov exponents that belong to one rotating 2-D subspace (a complex pair of Floquet multipliers).

Near a periodic orbit whose monodromy matrix has a complex pair mu, conj(mu), the tangent vectors of that pair
turn in a plane: Gram-Schmidt never separates them, and each column's stretch in a period depends on where in
the turn it sits. Both true exponents are log|mu|/T, but the QR estimates split into two values whose
difference decays only like 1/(measured time), oscillating as the plane turns: spur_pair's -1903.8 /s (each)
came out as -1897.1 and -1910.5, with a batch-means error of 0.74 /s that does not see this bias at all.

What does not oscillate is the pair's sum: the two stretches of a period add up to the stretch of the plane's
area, which is the same every period on a periodic orbit. So a pair is recognised from the per-period
stretches of two neighbouring exponents (in descending order):

* they trade stretch: the variance of their per-period sum is at most ``TRADE`` of that of their difference
  (each oscillates, the sum stays steady: a correlation of -0.6 or lower), and
* Gram-Schmidt has not told them apart: the running mean of their difference returns to zero (or below)
  somewhere in the last half of the measured periods. Distinct real exponents separate within a few periods
  and stay apart; a complex pair's running split oscillates about zero, shrinking like 1/K.

A pair found is reported as what it is, two equal real parts: both exponents become the pair's mean, with a
standard error that covers the finite-time bias of that mean (the largest distance of its running value from
the final one over the last half of the measured periods) as well as its batch-means error.
"""
from __future__ import annotations

import numpy as np

from .statistics import batch_means_stderr

#: the per-period sum of a pair varies at most this fraction of its difference's variance
TRADE = 0.25
#: fewer measured periods than this: no pair is looked for (the running split needs turns to show)
MIN_PERIODS = 20


def rotating_pairs(measured: np.ndarray) -> list[tuple[int, int]]:
    """The neighbouring columns (i, i + 1) of ``measured`` (measured periods x n: each period's log stretch
    per unit time, columns in descending order of their means) that form a rotating pair."""
    m, n = measured.shape
    if m < MIN_PERIODS or not np.all(np.isfinite(measured)):
        return []
    running = np.cumsum(measured, axis=0) / np.arange(1, m + 1)[:, None]
    late = slice(m // 2, m)
    pairs, i = [], 0
    while i < n - 1:
        a, b = measured[:, i], measured[:, i + 1]
        spread = np.var(a - b)
        if spread > 0 and np.var(a + b) <= TRADE * spread and np.min(running[late, i] - running[late, i + 1]) <= 0:
            pairs.append((i, i + 1))
            i += 2
        else:
            i += 1
    return pairs


def finite_time_bias(measured: np.ndarray) -> np.ndarray:
    """How far the running mean of each column of ``measured`` (periods x k) still moves over the last half of
    the periods: max over K in [M/2, M] of |mean of the first K - mean of all M| (a bias ~ c(K)/K, c bounded,
    is at least about |c(M)|/M there)."""
    m = measured.shape[0]
    running = np.cumsum(measured, axis=0) / np.arange(1, m + 1)[:, None]
    return np.max(np.abs(running[m // 2:] - running[-1]), axis=0)


def merge_pairs(measured: np.ndarray, exponents: np.ndarray, stderr: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, list[tuple[int, int]]]:
    """``exponents`` and ``stderr`` (n, descending; ``measured`` in the same column order) with every rotating
    pair replaced by its common real part and that mean's error (batch means and finite-time bias together),
    and the pairs (0-based)."""
    pairs = rotating_pairs(measured)
    if not pairs:
        return exponents, stderr, pairs
    exponents, stderr = exponents.copy(), stderr.copy()
    for i, j in pairs:
        mean = (measured[:, i] + measured[:, j]) / 2
        error = np.hypot(batch_means_stderr(mean)[0], finite_time_bias(mean[:, None])[0])
        exponents[[i, j]] = mean.mean()
        stderr[[i, j]] = error
    return exponents, stderr, pairs
