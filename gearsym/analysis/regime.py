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
tangent vector stretch over time T). So a point on a bifurcation, where lambda_1
passes through zero, is reported quasi-periodic: the spectrum cannot tell the two apart.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

REGIMES = ("periodic", "quasi-periodic", "chaotic", "hyperchaotic")
EQUILIBRIUM = "equilibrium"  # autonomous systems only

#: an exponent within this many standard errors of zero counts as zero
ZERO_SIGMAS = 3.0
#: ... or within this many units of 1/(measured time): a zero exponent's finite-time bias
ZERO_BIAS = 5.0


def zero_band(stderr: Sequence[float], measured_time) -> np.ndarray:
    """Half-width of the band around zero, per exponent (NaN errors: the bias term alone)."""
    err = np.asarray(stderr, dtype=float)
    return np.fmax(ZERO_SIGMAS * err, ZERO_BIAS / np.asarray(measured_time, dtype=float))


def classify_regime(exponents: Sequence[float], stderr: Sequence[float], measured_time: float,
                    autonomous: bool = False) -> str:
    """The regime name for one spectrum; ``measured_time`` is the time the exponents were averaged over."""
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
                     autonomous: bool = False) -> list[str]:
    """:func:`classify_regime` of many spectra at once (rows of ``exponents``/``stderr``, one measured time
    each): a sweep's batch of points in a few array operations."""
    lam = np.asarray(exponents, dtype=float)
    if autonomous or lam.size == 0:  # (the flow exponent is left out point by point)
        return [classify_regime(*row, autonomous) for row in zip(lam, stderr, measured_time)]
    band = zero_band(stderr, np.asarray(measured_time, dtype=float)[:, None])
    if not (np.isfinite(lam).all() and np.all(measured_time > 0)):
        raise ValueError("exponents must be finite and the measured time positive")
    return _by_signs(lam, band)


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
}


def describe_regime(regime: str, exponents: Sequence[float], stderr: Sequence[float], measured_time: float,
                    autonomous: bool = False) -> str:
    """The regime and what it means, in one line ('zero' is the band of :func:`zero_band`)."""
    meaning = MEANING.get(regime, regime)
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
