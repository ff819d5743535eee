"""Gauss–Legendre quadrature on any interval, vectorised over many intervals at once.

The energy integrals of a tooth are smooth along each piece of its profile (the fillet, the involute), so
Gauss–Legendre converges exponentially in the number of nodes; nodes and weights come from numpy
(``numpy.polynomial.legendre.leggauss``) and are mapped to each interval here.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np


@lru_cache(maxsize=64)
def _unit_rule(points: int) -> tuple[np.ndarray, np.ndarray]:
    nodes, weights = np.polynomial.legendre.leggauss(points)
    nodes.setflags(write=False)
    weights.setflags(write=False)
    return nodes, weights


def gauss_legendre(lower, upper, points: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of the ``points``-point rule on each interval [lower, upper].

    ``lower`` and ``upper`` broadcast to a shape S; the result has shape S + (points,), so that
    ``(f(nodes) * weights).sum(-1)`` is the integral over each interval (negative where upper < lower).
    """
    nodes, weights = _unit_rule(int(points))
    lower = np.asarray(lower, dtype=float)[..., None]
    upper = np.asarray(upper, dtype=float)[..., None]
    half = 0.5 * (upper - lower)
    return lower + half * (nodes + 1.0), half * weights
