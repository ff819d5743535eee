"""Standard errors of time averages of correlated samples (batch means)."""
from __future__ import annotations

import numpy as np


def batch_means_stderr(samples: np.ndarray, batches: int = 10) -> np.ndarray:
    """Standard error of the mean of each row of ``samples`` (rows x time).

    Consecutive per-period stretches are correlated, so the naive sigma/sqrt(M)
    is too small; the means of ``batches`` contiguous batches are nearly
    independent, and their spread gives an honest error (batches differ in size
    by at most one sample, so every sample counts). NaN with fewer than two samples.
    """
    samples = np.atleast_2d(samples)
    m = samples.shape[1]
    b = min(batches, m)
    if b < 2:
        return np.full(samples.shape[0], np.nan)
    sizes = np.full(b, m // b)
    sizes[: m % b] += 1  # as numpy.array_split: the first batches one longer
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    means = np.add.reduceat(samples, starts, axis=1) / sizes
    return means.std(axis=1, ddof=1) / np.sqrt(b)
