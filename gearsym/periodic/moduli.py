"""The moduli of an orbit's Floquet multipliers from its shooting segments' maps, where the monodromy matrix cannot
hold them.

The monodromy matrix of a long period is a product of segment maps M_K ... M_1, and as one matrix it keeps its
eigenvalues only down to the rounding of its largest: the two-stage gearbox's period of 61 mesh periods has
multipliers down to e^-2200, and eig of the product gives 1e-17 for all but the first pair. The product's QR in
product form (the periodic QR iteration: Q_k R_k = M_k Q_(k-1), around the period, several times) keeps each
direction's stretch per segment apart, so log|mu_i| is the sum over the segments of log|R_k[i, i]| once the
directions have converged (a complex pair: the sum of its two, each the pair's mean). A direction that one segment
shrinks e^30 times more than the first is lost in that segment's rounding: its modulus is then only bounded (at
most what was measured), and said so.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

#: rounds of the periodic QR iteration (the directions converge like the ratios of neighbouring multipliers, which
#: for a damped train over a long period are tiny: one round settles them; three check it)
ROUNDS = 3
#: a direction shrunk below this fraction of the first by one segment is lost in that segment's rounding
LOST = 1e-13


def log_moduli(blocks: Sequence[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """(log|mu_i| largest first, and whether each is resolved) of the product of ``blocks`` (M_1 first)."""
    n = blocks[0].shape[0]
    Q = np.eye(n)
    rounds = []
    for _ in range(ROUNDS):
        logs, lost = np.zeros(n), np.zeros(n, dtype=bool)
        for M in blocks:
            Q, R = np.linalg.qr(M @ Q)
            d = np.abs(np.diag(R))
            lost |= d < LOST * max(d.max(), 1e-300)
            logs += np.log(np.maximum(d, 1e-300))
        rounds.append(logs)
    logs, before = rounds[-1].copy(), rounds[-2]
    for i in range(n - 1):  # a rotating pair: its two directions trade stretch from round to round, their sum
        # does not; each is the pair's mean
        trade = abs(logs[i] - before[i]) + abs(logs[i + 1] - before[i + 1])
        kept = abs(logs[i] + logs[i + 1] - before[i] - before[i + 1])
        if not lost[i] and not lost[i + 1] and trade > 1e-9 * max(1.0, abs(logs[i])) and kept < 1e-3 * trade:
            logs[i] = logs[i + 1] = (logs[i] + logs[i + 1]) / 2
    order = np.argsort(-logs, kind="stable")
    return logs[order], ~lost[order]
