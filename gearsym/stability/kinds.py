"""What the multipliers of a point say: stable or not, and how stability is lost.

A point is unstable when a Floquet multiplier lies outside the unit circle by more than :data:`MARGIN` (an
undamped system's multipliers sit on the circle where it is stable; RK4 puts them a little inside, and rounding
must not make a neutral point unstable). Where it is unstable, the multiplier of largest modulus says the kind
of instability, by how it left the circle:

* ``fold``: a real multiplier through +1; on the boundary a solution of the forcing's period (T) exists: for
  Mathieu's equation the tongues of even order, at mesh frequency omega = 2 omega_n / r with r even;
* ``period doubling``: a real multiplier through -1; a solution of period 2T on the boundary: the principal
  parametric resonance omega = 2 omega_n and the tongues of odd order r;
* ``Neimark-Sacker``: a complex pair through the circle, the combination resonances
  omega = (omega_i + omega_j) / r of a system with several modes.
"""
from __future__ import annotations

import numpy as np

FOLD, PERIOD_DOUBLING, NEIMARK_SACKER = "fold", "period doubling", "Neimark-Sacker"
KINDS = (FOLD, PERIOD_DOUBLING, NEIMARK_SACKER)
#: what a point is marked when it has no multipliers (no static state or no periodic orbit found there)
NO_STATIC_STATE, NO_ORBIT = "no static state", "orbit not found"
#: unstable where the largest multiplier's modulus exceeds 1 by more than this
MARGIN = 1e-9
#: a multiplier is real when its imaginary part is below this times its modulus
REAL = 1e-7


def multipliers(M: np.ndarray) -> np.ndarray:
    """The multipliers of each matrix of ``M`` (points x n x n), largest modulus first (points x n)."""
    if M.shape[-1] == 2:  # (closed form: numpy's eigvals costs microseconds a matrix, a chart has 10^5)
        half = (M[:, 0, 0] + M[:, 1, 1]) / 2
        det = M[:, 0, 0] * M[:, 1, 1] - M[:, 0, 1] * M[:, 1, 0]
        disc = half * half - det
        real = disc >= 0
        root = np.sqrt(np.abs(disc))
        big = np.where(real, half + np.where(half >= 0, 1.0, -1.0) * root, half) + 1j * np.where(real, 0.0, root)
        with np.errstate(invalid="ignore", divide="ignore"):  # (no cancellation: the other real one is det / big)
            other = np.where(big.real != 0, det / np.where(big.real != 0, big.real, 1.0), half - root)
        mu = np.column_stack([big, np.where(real, other + 0j, np.conj(big))])
    else:
        mu = np.linalg.eigvals(M)
    order = np.lexsort((-mu.imag, -np.abs(mu)), axis=-1)
    return np.take_along_axis(mu, order, axis=-1)


def classify(mu: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(largest modulus, unstable, kind) per point of ``mu`` (points x n, largest first; NaN rows: no result);
    the kind is None where the point is stable."""
    largest = np.abs(mu[:, 0]) if mu.shape[1] else np.zeros(len(mu))
    unstable = largest > 1.0 + MARGIN
    first = mu[:, 0] if mu.shape[1] else np.zeros(len(mu), dtype=complex)
    real = np.abs(first.imag) <= REAL * np.abs(first)
    kind = np.full(len(mu), None, dtype=object)
    kind[unstable & real & (first.real > 0)] = FOLD
    kind[unstable & real & (first.real < 0)] = PERIOD_DOUBLING
    kind[unstable & ~real] = NEIMARK_SACKER
    return largest, unstable, kind
