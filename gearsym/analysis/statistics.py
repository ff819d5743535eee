"""Standard errors of time averages of correlated samples (batch means)."""
from __future__ import annotations

import numpy as np


def batch_means_stderr(samples: np.ndarray, batches: int = 10, axis: int = -1) -> np.ndarray:
    """Standard error of the mean of ``samples`` along ``axis`` (time; default: each row of rows x time).

    Consecutive per-period stretches are correlated, so the naive sigma/sqrt(M)
    is too small; the means of ``batches`` contiguous batches are nearly
    independent, and their spread gives an honest error (batches differ in size
    by at most one sample, so every sample counts). NaN with fewer than two samples.
    """
    samples = np.atleast_2d(samples)
    m = samples.shape[axis]
    b = min(batches, m)
    if b < 2:
        return np.full(np.delete(samples.shape, axis), np.nan)
    sizes = np.full(b, m // b)
    sizes[: m % b] += 1  # as numpy.array_split: the first batches one longer
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    shape = [1] * samples.ndim
    shape[axis] = b
    means = np.add.reduceat(samples, starts, axis=axis) / sizes.reshape(shape)
    # batches last and contiguous: the spread is summed in the same order whatever the layout of samples
    return np.ascontiguousarray(np.moveaxis(means, axis, -1)).std(axis=-1, ddof=1) / np.sqrt(b)
