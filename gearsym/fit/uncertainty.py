"""Uncertainties of a fit's estimates: Gauss-Newton standard errors with the start states profiled out, which
estimates the data cannot determine (not identifiable), and the strongly correlated pairs."""
from __future__ import annotations

import numpy as np

from .jacobian import Jacobian

#: a parameter whose direction has a singular value below this fraction of the largest (columns
#: normalised) cannot be told from the others by the data
NULL_SPACE = 1e-6
#: a parameter whose weight in the null space is within this of one half shares it with another: both are flagged,
#: not the one rounding happens to favour
TIE = 1e-6
#: correlations of estimates above this (in absolute value) are flagged
STRONG_CORRELATION = 0.95


def uncertainty(J: Jacobian, r: np.ndarray, sigma2: float, names: list[str], held: np.ndarray, prior=None):
    """Standard errors (None: not identifiable), identifiability, strong correlations and the covariance of the
    parameters and offsets ``names`` (those ``held`` at a bound left out), with the start states profiled out:
    the information matrix on them is the Schur complement U - sum_k W_k V_k^+ W_k^T. ``prior``: per name, the
    information a regularised fit's prior adds (w / sigma^2 for a ridge weight w): the posterior's."""
    free_names = [n for n, h in zip(names, held) if not h]
    p = len(free_names)
    if not J.finite or not np.isfinite(sigma2):  # a fit that went nowhere: nothing is determined
        return {n: None for n in names}, {n: False for n in names}, [], {}
    U, W, V, _, _ = J.normal(r)
    free = ~np.asarray(held, dtype=bool)
    U, W = U[np.ix_(free, free)], W[:, free, :]
    if prior is not None:
        U = U + np.diag(np.asarray(prior, dtype=float)[free])
    info = U - np.einsum("kpn,knm,kqm->pq", W, np.linalg.pinv(V), W)
    norms = np.sqrt(np.maximum(np.diag(U), 0.0))
    scale = np.where(norms > 0, norms, 1.0)
    eigenvalues, vectors = np.linalg.eigh(info / np.outer(scale, scale))
    top = max(float(eigenvalues.max(initial=0.0)), 1e-300)
    null = eigenvalues < NULL_SPACE**2 * top  # the column-normalised J's singular values below NULL_SPACE
    weight = (vectors[:, null] ** 2).sum(axis=1)
    bad = (norms <= 1e-300) | (weight > 0.5 - TIE)  # (two parameters exactly confounded: neither is determined)
    inverse = np.where(null, 0.0, 1 / np.where(null, 1.0, eigenvalues))
    cov = sigma2 * (vectors * inverse) @ vectors.T / np.outer(scale, scale)
    stderr = {n: None for n in names}
    identifiable = {n: False for n in names}
    for i, name in enumerate(free_names):
        identifiable[name] = not bool(bad[i])
        stderr[name] = float(np.sqrt(max(cov[i, i], 0.0))) if identifiable[name] else None
    covariance = {a: {b: float(cov[i, j]) for j, b in enumerate(free_names) if identifiable[b]}
                  for i, a in enumerate(free_names) if identifiable[a]}
    correlations = []
    for i in range(p):
        for j in range(i + 1, p):
            if bad[i] or bad[j] or cov[i, i] <= 0 or cov[j, j] <= 0:
                continue
            rho = cov[i, j] / np.sqrt(cov[i, i] * cov[j, j])
            if abs(rho) > STRONG_CORRELATION:
                correlations.append((free_names[i], free_names[j], float(rho)))
    return stderr, identifiable, correlations, covariance
