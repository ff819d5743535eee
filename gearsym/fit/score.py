"""The score test's pieces at a fit: the residual and the exact sensitivity columns of parameters added at 0, with
what the fit already moves projected out (how much a candidate effect would remove, to first order)."""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from ..options import Integration
from ..system import FirstOrderSystem
from .problem import Problem
from .result import Fit
from .segment import Segment


def score_columns(system: FirstOrderSystem, segments: Sequence[Segment], fit: Fit, extra: Sequence[str],
                  bias: Sequence[str], options: Integration) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The score test's pieces at ``fit`` with the parameters ``extra`` added at 0: the scaled residual (data -
    model) and the exact sensitivity columns of ``extra``, both with what the fit already moves (its parameters,
    start states and offsets) projected out; and the columns before the projection."""
    fitted = list(fit.estimates)
    problem = Problem(system, segments, fitted + list(extra), list(bias), 2 * np.pi, options)
    theta = np.array([fit.estimates[p] for p in fitted] + [0.0] * len(extra))
    u = np.concatenate([theta, [fit.bias[c] for c in problem.bias], fit.starts.reshape(-1, order="F")])
    r, J = problem(u)
    m = len(fitted)
    columns = J.P[:, m:m + len(extra)]
    nuisance = replace(J, P=np.delete(J.P, np.s_[m:m + len(extra)], axis=1))
    both = nuisance.project_out(np.hstack([-r[:, None], columns]))
    return both[:, 0], both[:, 1:], columns
