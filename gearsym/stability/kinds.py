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
    if M.shape[-1] == 2:
        return _pairs(M)
    mu = np.linalg.eigvals(M)
    order = np.lexsort((-mu.imag, -np.abs(mu)), axis=-1)
    return np.take_along_axis(mu, order, axis=-1)


def _pairs(M: np.ndarray) -> np.ndarray:
    """The two multipliers of 2 x 2 matrices in closed form, already in order (numpy's eigvals and a sort cost
    microseconds a matrix, a chart has 10^5): a real pair as half +- root (the larger modulus first, the other as
    det / it: no cancellation), a complex pair as half +- i root (positive imaginary part first)."""
    a, b, c, d = M[:, 0, 0], M[:, 0, 1], M[:, 1, 0], M[:, 1, 1]
    half = a + d
    half *= 0.5
    det = a * d
    det -= b * c
    disc = half * half
    disc -= det
    real = disc >= 0
    root = np.abs(disc, out=disc)
    np.sqrt(root, out=root)
    big = np.copysign(root, half)
    big += half
    other = np.divide(det, big, out=np.zeros_like(big), where=big != 0)  # (big = 0: both are 0)
    mu = np.empty((len(M), 2), dtype=complex)
    mu.real[:, 0] = np.where(real, big, half)
    mu.real[:, 1] = np.where(real, other, half)
    mu.imag[:, 0] = np.where(real, 0.0, root)
    mu.imag[:, 1] = -mu.imag[:, 0]
    return mu


#: a point's kind by its code (:func:`classify`): stable, the three kinds of instability
_KIND_OF_CODE = np.array([None, FOLD, PERIOD_DOUBLING, NEIMARK_SACKER], dtype=object)


def classify(mu: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(largest modulus, unstable, kind) per point of ``mu`` (points x n, largest first; NaN rows: no result);
    the kind is None where the point is stable."""
    if not mu.shape[1]:
        return np.zeros(len(mu)), np.zeros(len(mu), dtype=bool), np.full(len(mu), None, dtype=object)
    first = mu[:, 0]
    largest = np.abs(first)
    unstable = largest > 1.0 + MARGIN
    real = np.abs(first.imag) <= REAL * largest
    code = np.where(real, np.where(first.real > 0, 1, 2), 3) * unstable
    return largest, unstable, _KIND_OF_CODE[code]
