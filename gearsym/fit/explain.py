"""The data loop: fit, find what the residual says the model lacks, add it, report before and after.

1. Split every record by time: the first part trains, the last ``held_out``
   (whole forcing periods) is held out.
2. Fit the named parameters to the training windows (multiple shooting,
   :mod:`.shooting`); the held-out error is the one-period-ahead prediction error
   (:mod:`.prediction`).
3. Forward selection over the effect library (:mod:`.effects`): each candidate
   not yet in the model is added and refitted (its own parameters with the
   named ones); the one that lowers the *held-out* error most is kept if it
   lowers it by at least ``min_gain`` (a fraction). Repeat while one does.
   In-sample fit never decides: a term that only fits noise does not predict.
4. Whether anything is left: the held-out residual of the final model should
   be measurement noise, uncorrelated from one sample to the next. Its lag-1
   autocorrelation above ``max_correlation`` means a smooth, systematic error
   is left, which no candidate explained: ``unexplained``.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..data.measurements import Measurements
from ..errors import GearsymError
from ..options import Integration
from ..system import FirstOrderSystem
from .effects import EFFECTS, Effect, augment, effect
from .prediction import Prediction, predict_ahead
from .shooting import Fit, Segment, fit_windows

MIN_GAIN = 0.2
MAX_CORRELATION = 0.5
MAX_EFFECTS = 2


@dataclass(frozen=True)
class Candidate:
    """One model tried: its effects, fit and held-out prediction."""

    effects: tuple[str, ...]
    fit: Fit
    prediction: Prediction

    @property
    def error(self) -> float:
        return self.prediction.error


@dataclass(frozen=True)
class Explanation:
    base: Candidate
    final: Candidate
    tried: list[Candidate]  # every candidate evaluated, in order
    unexplained: bool
    correlation: float  # lag-1 autocorrelation of the final held-out residual
    fitted: tuple[str, ...]
    held_out: float
    info: dict = field(default_factory=dict)

    @property
    def effects(self) -> list[str]:
        return list(self.final.effects)

    def as_dict(self) -> dict:
        def fit_dict(c: Candidate) -> dict:
            return {"effects": list(c.effects), "held_out_error": c.error, "estimates": c.fit.estimates,
                    "stderr": c.fit.stderr, "training_sigma": c.fit.sigma, "converged": c.fit.success}
        return {
            "effects": self.effects,
            "unexplained": self.unexplained,
            "error_before": self.base.error,
            "error_after": self.final.error,
            "parameters": self.final.fit.estimates,
            "stderr": self.final.fit.stderr,
            "parameters_before": self.base.fit.estimates,
            "residual_correlation": self.correlation,
            "fitted": list(self.fitted),
            "held_out_fraction": self.held_out,
            "candidates": [fit_dict(c) for c in self.tried],
        }


def segments_of(system: FirstOrderSystem, measurements: Measurements) -> tuple[list[Segment], list[tuple]]:
    """Every whole-period window as a Segment with the record's full parameter values for ``system``."""
    segments, keys = [], []
    for r in measurements:
        values = {**system.parameters, **measurements.parameters(r)}
        for w in r.windows():
            segments.append(Segment(w.tau, w.observed, values, f"{r.label} period {w.index}"))
            keys.append(((str(r.source), r.record), w.index))  # (which record, which period)
    return segments, keys


def explain(system: FirstOrderSystem, measurements: Measurements, fit: Sequence[str], *,
            candidates: Sequence[str | Effect] | None = None, held_out: float = 0.25,
            min_gain: float = MIN_GAIN, max_effects: int = MAX_EFFECTS,
            max_correlation: float = MAX_CORRELATION, progress=None,
            options: Integration = Integration()) -> Explanation:
    """Fit ``fit`` on ``measurements``, then add effects from ``candidates`` (default: the whole library)
    while they lower the held-out error; see the module docstring."""
    if not fit:
        raise GearsymError("name the parameters to fit, e.g. --fit zeta,B1")
    _check_one_value_each(measurements, fit)
    library = {e.name: e for e in map(effect, candidates if candidates is not None else list(EFFECTS))}
    train, test = measurements.split(held_out)
    say = progress or (lambda message: None)

    def evaluate(effects: tuple[str, ...], guess: dict) -> Candidate:
        model = augment(system, [library[e] for e in effects])
        names = list(fit) + [p for e in effects for p in library[e].fitted]
        seg_train, _ = segments_of(model, train)
        seg_test, keys = segments_of(model, test)
        result = fit_windows(model, seg_train, names, guess=guess, options=options)
        prediction = predict_ahead(model, seg_test, keys, result.estimates, options=options)
        say(f"{'+'.join(effects) or 'the model as declared'}: held-out error {prediction.error:.4g}")
        return Candidate(effects, result, prediction)

    base = evaluate((), {})
    tried, current = [base], base
    while len(current.effects) < max_effects:
        round_ = [evaluate(current.effects + (c.name,), dict(current.fit.estimates))
                  for c in library.values() if c.name not in current.effects]
        tried.extend(round_)
        if not round_:
            break
        best = min(round_, key=lambda c: c.error)
        if best.error > (1 - min_gain) * current.error:
            break
        current = best
    correlation = _lag1(current.prediction)
    return Explanation(base, current, tried, bool(correlation > max_correlation), correlation, tuple(fit), held_out)


def _check_one_value_each(measurements: Measurements, fit: Sequence[str]) -> None:
    """A fit estimates one value of each parameter for all records: refuse one the records set differently."""
    for name in fit:
        values = {r.conditions[name] for r in measurements if name in r.conditions}
        if len(values) > 1:
            shown = ", ".join(f"{v:g}" for v in sorted(values))
            raise GearsymError(f"cannot fit {name}: the records set it to different values ({shown}) and a fit "
                               f"estimates one value for all; leave it out of --fit, or explain one record (or "
                               f"records of one {name}) at a time")


def _lag1(prediction: Prediction) -> float:
    """Lag-1 autocorrelation of the held-out residual, within each predicted period (averaged over coordinates)."""
    values = []
    for k, r in prediction.residual.items():
        r = r - r.mean()
        pieces = np.array_split(r, prediction.pairs)
        num = sum(float(p[1:] @ p[:-1]) for p in pieces)
        den = sum(float(p @ p) for p in pieces)
        values.append(num / den if den > 0 else 0.0)
    return float(np.mean(values))
