"""A coordinate's position and rate at a window's start from its measured acceleration (or rate) alone: the window's
Fourier series integrated in time."""
from __future__ import annotations

import numpy as np
import sympy as sp

from .segment import Segment


def from_rate(seg: Segment, name: str, period: float):
    """(x - mean, v, amplitude of x) at the window's first sample from its x_ddot (or x_dot) channel, if it has one
    that is a multiple of the derivative alone; None otherwise."""
    for suffix, order in (("_ddot", 2), ("_dot", 1)):
        placeholder = sp.Symbol(name + suffix, real=True)
        channel = next((c for c in seg.observed if seg.channel(c).free_symbols == {placeholder}
                        and sp.diff(seg.channel(c), placeholder, 2) == 0), None)
        if channel is None:
            continue
        scale = float(sp.diff(seg.channel(channel), placeholder))
        rate = seg.observed[channel] / scale
        t = seg.tau - seg.tau[0]
        w = 2 * np.pi / period
        n = np.arange(1, max(1, min(8, len(t) // 2 - 1)) + 1)
        A = np.hstack([np.ones((t.size, 1)), np.cos(np.outer(t, n * w)), np.sin(np.outer(t, n * w))])
        coef = np.linalg.lstsq(A, rate, rcond=None)[0]
        a, b = coef[1:n.size + 1], coef[n.size + 1:]
        nw = n * w
        if order == 2:  # x'' = sum a cos + b sin: v = sum (a sin - b cos)/nw, x = -sum (a cos + b sin)/nw^2
            return float(-np.sum(a / nw**2)), float(-np.sum(b / nw)), float(np.sum(np.hypot(a, b) / nw**2))
        return float(-np.sum(b / nw)), float(rate[0]), float(np.sum(np.hypot(a, b) / nw))
    return None
