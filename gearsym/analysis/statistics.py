"""Standard errors of time averages of correlated samples (batch means)."""
from __future__ import annotations

import numpy as np


def batch_means_stderr(samples: np.ndarray, batches: int = 10) -> np.ndarray:
    """Standard error of the mean of each row of ``samples`` (rows x time).

    Consecutive per-period stretches are correlated, so the naive sigma/sqrt(M)
    is too small; the means of ``batches`` contiguous batches are nearly
    independent, and their spread gives an honest error. NaN with fewer than
    two batches' worth of samples.
    """
    samples = np.atleast_2d(samples)
    m = samples.shape[1]
    b = min(batches, m)
    if b < 2:
        return np.full(samples.shape[0], np.nan)
    size = m // b
    means = samples[:, : b * size].reshape(samples.shape[0], b, size).mean(axis=2)
    return means.std(axis=1, ddof=1) / np.sqrt(b)
