"""Whether a run's Poincare points have settled: a torus, a periodic orbit reached, or a transient still going.

Where the largest exponent cannot be told from zero (see :mod:`gearsym.analysis.regime`) the exponents alone
cannot tell a torus (lambda_1 = 0 exactly) from a weakly stable orbit the run has not reached yet (lambda_1 < 0,
but closer to zero than the run can resolve). The stroboscopic (Poincare) points can: on a torus they fill
an invariant circle and do not move in or out, on the way to an orbit they spiral in.

The measure is the points' recurrence: the distance between the point of period k and that of period k + j,
for the lag j = 1 ... 16 at which the points return best over the measured periods (a period-j orbit returns
exactly; a torus has near returns), in coordinates scaled by the spread of the points. Its mean over each of
``CHUNKS`` consecutive chunks of the measured periods is fitted by exp(a + rate x time) (least squares on the
logarithm), and:

* ``settled``: the points repeat to rounding (the last chunk's mean at most ``SETTLED`` of their spread): a
  periodic orbit, reached;
* ``converging`` / ``spreading``: the rate is negative / positive, ``SIGNIFICANT`` times its standard error
  away from zero (the fit's residuals), and moves the distance by at least ``CHANGE`` over the measured time:
  the points still move in (a transient towards an orbit or a torus) or out; ``rate`` estimates the exponent
  that decides (one_stage-like gear trains with an undamped shaft: the rate agrees with lambda_1 = lambda_2 of a
  run ten times longer to 1 %);
* ``stationary``: the fit bounds the change: even at its rate plus two standard errors the distance would
  change by less than ``CHANGE`` over the measured time: the points stay on what they fill (a torus, at the
  run's resolution);
* ``irregular``: none of these: the chunks' distances scatter too much to bound a trend (a torus turning so
  slowly that a chunk sees only part of it, or a weakly chaotic cloud): the points do not decide either.
"""
from __future__ import annotations

import numpy as np

from ..records import record_class

#: lags (in forcing periods) compared, at most
MAX_LAG = 16
#: consecutive chunks of the measured periods whose mean recurrence distances are fitted
CHUNKS = 8
#: a rate this many of its standard errors away from zero ...
SIGNIFICANT = 4.0
#: ... that changes the recurrence distance by at least this factor (either way) over the measured time
CHANGE = 1.1
#: the last chunk's recurrence distance at most this (in units of the points' spread): the points repeat
SETTLED = 1e-7
#: fewer measured periods than this: nothing is said
MIN_PERIODS = 4 * CHUNKS

SETTLED_STATE, STATIONARY_STATE, CONVERGING, SPREADING, IRREGULAR = (
    "settled", "stationary", "converging", "spreading", "irregular")
#: the run is shorter than one period of the model's own fastest motion: its points cannot show anything
BRIEF = "brief"


@record_class
class Settling:
    """What the Poincare points did over the measured periods."""

    state: str  # settled, stationary, converging, spreading or irregular
    lag: int  # the lag (forcing periods) of the best return
    rate: float  # of the recurrence distance, per unit time (negative: converging)
    rate_stderr: float
    change: float  # the factor the fitted distance changed by over the measured periods

    @property
    def transient(self) -> bool:
        return self.state in (CONVERGING, SPREADING)

    @property
    def decides(self) -> bool:
        """The points say what the exponents could not: settled (periodic) or stationary (a torus)."""
        return self.state in (SETTLED_STATE, STATIONARY_STATE)

    def describe(self, time_unit: str = "unit time") -> str:
        if self.state == BRIEF:
            return (f"the measured periods last {self.change:.3g} of a period of the model's fastest own motion (its "
                    f"Jacobian's largest |eigenvalue| is {self.rate:.3g} per {time_unit}), too short for its Poincare "
                    "points to show an attractor (the forcing is too fast for the run, or the motion too slow)")
        if self.state == SETTLED_STATE:
            return f"the Poincare points repeat every {self.lag} period(s)"
        if self.state == STATIONARY_STATE:
            return (f"the Poincare points neither converge nor spread (their distance at a return changed less than "
                    f"{CHANGE:g}x over the measured periods)")
        if self.state == IRREGULAR:
            return ("the Poincare points' distance at a return scatters too much over the measured periods to say "
                    "whether they converge, spread or stay")
        how = "converge" if self.state == CONVERGING else "spread"
        return (f"the Poincare points still {how} (their distance at a return changed {self.change:.3g}x over the "
                f"measured periods, rate {self.rate:+.3g} +- {self.rate_stderr:.2g} per {time_unit}): a transient")


def brief_run(own_rate: float, measured_time: float) -> Settling | None:
    """A run whose ``measured_time`` is less than one period of the model's fastest own motion (``own_rate``, the
    largest |eigenvalue| of its Jacobian): a Settling that decides nothing (one_stage at omega = 1e308, whose
    forces underflow to zero in the tau-form: its points drift at a constant step, which looks stationary);
    None for a run long enough."""
    coverage = measured_time * own_rate / (2 * np.pi)
    return Settling(BRIEF, 0, float(own_rate), 0.0, float(coverage)) if not coverage >= 1 else None


def long_run_rate(measured_time: float) -> float:
    """An own rate from which a run of ``measured_time`` is not brief (:func:`brief_run`), a hair above the bound
    so that rounding cannot make one brief: where a search for the fastest own motion may stop."""
    return 2 * np.pi / measured_time * (1 + 1e-9) if measured_time > 0 else np.inf


def poincare_settling(strobe: np.ndarray, period: float) -> Settling | None:
    """The settling of the Poincare points ``strobe`` (measured periods x n) taken every ``period``; None with
    fewer than ``MIN_PERIODS`` points or non-finite ones."""
    points = np.asarray(strobe, dtype=float)
    m = points.shape[0]
    if m < MIN_PERIODS or not np.all(np.isfinite(points)):
        return None
    scale = np.maximum(points.std(axis=0), 1e-6 * (1.0 + np.abs(points).max(axis=0)))
    points = points / scale
    lags = range(1, min(MAX_LAG, m // (2 * CHUNKS)) + 1)
    steps = [np.sqrt(np.sum((points[lag:] - points[:-lag]) ** 2, axis=1)) for lag in lags]  # period k -> k + lag
    best = int(np.argmin([step.mean() for step in steps]))
    lag, step = best + 1, steps[best]
    chunks = np.array_split(np.arange(step.size), CHUNKS)
    means = np.array([step[c].mean() for c in chunks])
    if means[-1] <= SETTLED:
        return Settling(SETTLED_STATE, lag, 0.0, 0.0, 1.0)
    if np.any(means <= 0):  # (some chunk repeats exactly, a later one does not: moving away from rest)
        return Settling(SPREADING, lag, np.inf, 0.0, np.inf)
    t = np.array([c.mean() for c in chunks]) * period
    (rate, a), cov = np.polyfit(t, np.log(means), 1, cov=True)
    rate_stderr = float(np.sqrt(max(cov[0, 0], 0.0)))
    change = float(np.exp(abs(rate) * (t[-1] - t[0])))
    if abs(rate) > SIGNIFICANT * rate_stderr and change >= CHANGE:
        return Settling(CONVERGING if rate < 0 else SPREADING, lag, float(rate), rate_stderr, change)
    if np.exp((abs(rate) + 2 * rate_stderr) * (t[-1] - t[0])) < CHANGE:
        return Settling(STATIONARY_STATE, lag, float(rate), rate_stderr, change)
    return Settling(IRREGULAR, lag, float(rate), rate_stderr, change)
