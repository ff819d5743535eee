"""The result of a multiple-shooting fit: :class:`Fit`."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..system import FirstOrderSystem


@dataclass(frozen=True)
class Fit:
    """The estimates, their standard errors, and what each window looks like under them.

    ``stderr[p]`` is None where ``p`` is not identifiable (``identifiable[p]`` False) or held at a bound
    (``at_bound[p]``: the bound and why it is there). ``correlations``: pairs of estimates correlated
    beyond :data:`STRONG_CORRELATION`. ``bias``: the fitted offset of each biased channel.
    """

    system: FirstOrderSystem
    estimates: dict[str, float]
    stderr: dict[str, float | None]
    starts: np.ndarray  # (n, windows): the fitted start state of each window
    predicted: list[dict[str, np.ndarray]]  # per window: the fitted channels at the samples (bias included)
    residuals: list[dict[str, np.ndarray]]  # per window: measured - fitted, unscaled
    sigma: float  # RMS of the scaled residuals
    success: bool
    iterations: int
    info: dict = field(default_factory=dict)
    states: list[np.ndarray] = field(default_factory=list)  # per window: (n, S) the fitted states
    bias: dict[str, float] = field(default_factory=dict)
    bias_stderr: dict[str, float | None] = field(default_factory=dict)
    identifiable: dict[str, bool] = field(default_factory=dict)
    at_bound: dict[str, tuple[float, str]] = field(default_factory=dict)
    correlations: list[tuple[str, str, float]] = field(default_factory=list)
    covariance: dict[str, dict[str, float]] = field(default_factory=dict)  # of the identifiable estimates

