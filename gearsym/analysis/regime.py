"""Naming the motion at a parameter point from its Lyapunov spectrum and the spectrum's errors.

For a periodically forced system (the gear models) the n exponents are those of
the stroboscopic map, so

=================  ==================================================
periodic           every exponent below zero (a period-k orbit)
quasi-periodic     the largest is zero, the rest below
chaotic            exactly one above zero
hyperchaotic       two or more above zero (the paper's kS = 0.1 case)
=================  ==================================================

An autonomous system (Lorenz) always has a zero exponent along the flow; it is
left out first (``equilibrium`` when there is none: every exponent negative).

"Zero" is decided with the measurement's own uncertainty: an exponent counts
as zero when |lambda| <= max(3 stderr, 5 / measured time). The second term is
the finite-time bias of a zero exponent, which decays only like 1/T (a bounded
tangent vector stretch over time T).

Two verdicts are not regimes of an attractor:

* ``diverged``: the run grew without bound (:mod:`gearsym.analysis.divergence`); decided first, and then
  no regime is given.
* ``undetermined``: the largest exponent lies in the zero band, so the exponents cannot tell a torus
  (lambda_1 = 0) from a weakly stable orbit not reached yet (or a weakly unstable one), and the Poincare
  points do not show a torus either: they still converge or spread (a transient), or scatter too much to say
  (:mod:`gearsym.analysis.settling`). With the points stationary (their distance at a return changes by less
  than 10 % over the run, at its fitted rate plus two standard errors) the verdict is ``quasi-periodic`` (a
  torus, or a point on a bifurcation, at the run's resolution); with the points repeating to rounding it is
  ``periodic``. :func:`periods_to_decide` says how many measured periods would decide: with the points
  converging at a rate r (which estimates lambda_1: the slowest decay), T' = 10 / |r|, after which the
  transient has decayed by exp(-10) and the band's 5/T is |r|/2; otherwise the band's 3 stderr shrinks like
  1/sqrt(T) and its 5/T like 1/T, so T' = max(T (6 stderr / |lambda_1|)^2, 10 / |lambda_1|) leaves lambda_1
  twice the band from zero. Autonomous systems keep the rule of the exponents alone (their stroboscopic
  points sample a flow, not a map).
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .settling import SETTLED_STATE, Settling

REGIMES = ("periodic", "quasi-periodic", "chaotic", "hyperchaotic")
EQUILIBRIUM = "equilibrium"  # autonomous systems only
UNDETERMINED = "undetermined"  # the exponents cannot decide, and the Poincare points show a transient
DIVERGED = "diverged"  # unbounded growth: no regime
#: every verdict a run can get
VERDICTS = (*REGIMES, EQUILIBRIUM, UNDETERMINED, DIVERGED)

#: an exponent within this many standard errors of zero counts as zero
ZERO_SIGMAS = 3.0
#: ... or within this many units of 1/(measured time): a zero exponent's finite-time bias
ZERO_BIAS = 5.0


def zero_band(stderr: Sequence[float], measured_time) -> np.ndarray:
    """Half-width of the band around zero, per exponent (NaN errors: the bias term alone)."""
    err = np.asarray(stderr, dtype=float)
    return np.fmax(ZERO_SIGMAS * err, ZERO_BIAS / np.asarray(measured_time, dtype=float))


def classify_regime(exponents: Sequence[float], stderr: Sequence[float], measured_time: float,
                    autonomous: bool = False, settling: Settling | None = None) -> str:
    """The regime name for one spectrum; ``measured_time`` is the time the exponents were averaged over.
    ``settling``: what the Poincare points did (a forced system's), which decides where the exponents
    cannot (``quasi-periodic``, ``undetermined`` or ``periodic``, see the module's docstring)."""
    return _settled(_classify(exponents, stderr, measured_time, autonomous), settling, autonomous)


def _settled(regime: str, settling: Settling | None, autonomous: bool) -> str:
    """The exponents' ``regime`` with what the Poincare points say where the exponents cannot decide."""
    if regime != "quasi-periodic" or settling is None or autonomous:
        return regime
    if settling.state == SETTLED_STATE:
        return "periodic"
    return regime if settling.decides else UNDETERMINED


def _classify(exponents: Sequence[float], stderr: Sequence[float], measured_time: float, autonomous: bool) -> str:
    lam = np.asarray(exponents, dtype=float)
    band = zero_band(stderr, measured_time)
    if lam.shape != band.shape or lam.ndim != 1 or lam.size == 0:
        raise ValueError(f"need one standard error per exponent, got {lam.shape} and {band.shape}")
    if not (np.isfinite(lam).all() and measured_time > 0):
        raise ValueError("exponents must be finite and the measured time positive")
    if autonomous:
        flow = flow_exponent(lam, band)
        if flow is None:
            return EQUILIBRIUM if (lam < 0).all() else _by_signs(lam, band)
        lam, band = np.delete(lam, flow), np.delete(band, flow)
    return _by_signs(lam, band)


def classify_regimes(exponents: np.ndarray, stderr: np.ndarray, measured_time: np.ndarray,
                     autonomous: bool = False, settlings: Sequence[Settling | None] | None = None) -> list[str]:
    """:func:`classify_regime` of many spectra at once (rows of ``exponents``/``stderr``, one measured time
    each, and a settling each or None): a sweep's batch of points in a few array operations."""
    lam = np.asarray(exponents, dtype=float)
    settlings = settlings if settlings is not None else [None] * len(lam)
    if autonomous or lam.size == 0:  # (the flow exponent is left out point by point)
        return [classify_regime(*row, autonomous) for row in zip(lam, stderr, measured_time)]
    band = zero_band(stderr, np.asarray(measured_time, dtype=float)[:, None])
    if not (np.isfinite(lam).all() and np.all(measured_time > 0)):
        raise ValueError("exponents must be finite and the measured time positive")
    return [_settled(r, s, autonomous) for r, s in zip(_by_signs(lam, band), settlings)]


#: a run that would need more than this many times its measured periods to decide: none said
FARTHEST = 1000


def periods_to_decide(exponent: float, stderr: float, measured_time: float, period: float,
                      rate: float | None = None) -> int | None:
    """Measured periods after which the run would decide (see the module's docstring): with the Poincare points
    converging at ``rate`` (< 0), 2 ZERO_BIAS / |rate| (the transient has decayed by exp(-10), and the zero
    band's 1/T part is half the rate); otherwise those after which ``exponent`` would lie twice the zero band
    from zero, its error falling like 1/sqrt(T). None if that is more than FARTHEST times this run."""
    if rate is not None and np.isfinite(rate) and rate < 0:
        needed = 2 * ZERO_BIAS / abs(rate)
    else:
        size = abs(float(exponent))
        if not size > 0 or not np.isfinite(size):
            return None
        err = float(stderr) if np.isfinite(stderr) else 0.0
        needed = max(measured_time * (2 * ZERO_SIGMAS * err / size) ** 2, 2 * ZERO_BIAS / size)
    return int(np.ceil(needed / period)) if needed <= FARTHEST * measured_time else None


def flow_exponent(exponents: Sequence[float], band: Sequence[float]) -> int | None:
    """An autonomous system's exponent along the flow (0-based): the one nearest zero, if it is zero."""
    lam, band = np.asarray(exponents, dtype=float), np.asarray(band, dtype=float)
    flow = int(np.argmin(np.abs(lam) / band))
    return flow if abs(lam[flow]) <= band[flow] else None


#: what each regime says about the exponents, for a forced system
MEANING = {
    "periodic": "every exponent below zero: a periodic orbit",
    "quasi-periodic": "the largest exponent zero within its error, the rest below: a torus, or a bifurcation point",
    "chaotic": "exactly one exponent above zero",
    "hyperchaotic": "two or more exponents above zero",
    EQUILIBRIUM: "every exponent below zero, none along a flow: the motion comes to rest at a fixed point",
    UNDETERMINED: "the largest exponent cannot be told from zero in this run, and the Poincare points do not show "
                  "a torus: a transient, or too few periods to say",
    DIVERGED: "the motion grew without bound: no attractor, no regime",
}


def describe_regime(regime: str, exponents: Sequence[float], stderr: Sequence[float], measured_time: float,
                    autonomous: bool = False, settling: Settling | None = None) -> str:
    """The regime and what it means, in one line ('zero' is the band of :func:`zero_band`); ``settling``: what
    the Poincare points did, where they decided."""
    meaning = MEANING.get(regime, regime)
    if settling is not None and regime in ("periodic", "quasi-periodic"):  # the exponents could not decide
        return (f"{regime}: the largest exponent cannot be told from zero in this run, but {settling.describe()}: "
                + ("a periodic orbit, reached" if regime == "periodic" else "a torus (or a point on a bifurcation)"))
    flow = flow_exponent(exponents, zero_band(stderr, measured_time)) if autonomous else None
    if flow is None:
        return f"{regime}: {meaning}"
    return (f"{regime}: lambda_{flow + 1} is the exponent along the flow (zero for every motion of an autonomous "
            f"system that does not come to rest) and is left out; of the others, {meaning}")


def _by_signs(lam: np.ndarray, band: np.ndarray):
    """The regime of a spectrum (1-D), or of each row (2-D), from how many exponents lie above the band."""
    positive = np.sum(lam > band, axis=-1)
    zero = np.any(np.abs(lam) <= band, axis=-1)
    names = np.where(positive >= 2, "hyperchaotic", np.where(
        positive == 1, "chaotic", np.where(zero, "quasi-periodic", "periodic")))
    return names.tolist()
