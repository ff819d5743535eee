"""Period-1 orbits of many parameter points at once: Newton on P(y) - y = 0, every point's shot in the lanes.

Each iteration runs one period of every point still unconverged (state and tangent map: the monodromy matrix
at the current guess, exact) and takes the Newton step (M - I) d = -(P(y) - y) point by point. A point whose
Newton does not converge from its start (the static state, or a neighbour's orbit) within
:data:`MAX_ITERATIONS` is reported as not found: never guessed.
"""
from __future__ import annotations

import numpy as np

from .monodromies import MonodromyRunner

#: Newton stops when every residual component is below this times (1 + the largest |state|): the shooting's
MAX_ITERATIONS = 30
TOLERANCE = 1e-10


def periodic_orbits(runner: MonodromyRunner, p: np.ndarray, starts: np.ndarray,
                    progress=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(orbit state at the section, monodromy matrix there, converged) per row of ``p`` from ``starts``."""
    count, n = starts.shape
    z = np.array(starts, dtype=float)
    M = np.full((count, n, n), np.nan)
    converged = np.zeros(count, dtype=bool)
    active = np.nonzero(np.isfinite(z).all(axis=1))[0]
    for _ in range(MAX_ITERATIONS):
        if not len(active):
            break
        y1, Ma = runner.run(p[active], z[active])
        residual = y1 - z[active]
        error = np.max(np.abs(residual), axis=1) / (1.0 + np.max(np.abs(z[active]), axis=1))
        ok = np.isfinite(error) & np.isfinite(Ma).all(axis=(1, 2))
        done = ok & (error <= TOLERANCE)
        M[active[done]] = Ma[done]
        converged[active[done]] = True
        going = ok & ~done
        rows = active[going]
        if len(rows):
            A = Ma[going] - np.eye(n)
            try:
                step = np.linalg.solve(A, -residual[going][..., None])[..., 0]
            except np.linalg.LinAlgError:  # (a multiplier at +1: a fold; least squares, row by row)
                step = np.array([np.linalg.lstsq(a, -r, rcond=None)[0] for a, r in zip(A, residual[going])])
            z[rows] += step
        active = rows[np.isfinite(z[rows]).all(axis=1)] if len(rows) else rows
        if progress:
            progress(int(converged.sum()), count)
    z[~converged] = np.nan
    return z, M, converged
