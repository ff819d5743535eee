"""Runs that diverge: unbounded growth is a verdict of its own, not a regime of a bounded motion.

A run whose state overflows, or grows far beyond any size the model can give a vibration, has no attractor
to name: its Lyapunov exponents measure how fast it runs away (one_stage at k_a = 5 had lambda_1 = +0.47,
"chaotic"; with k = 0 a drift of 26 length units per period had lambda_1 = 0, "quasi-periodic"). The rule,
applied to every run (the discarded periods included) before any regime:

* **non-finite**: the state (or an extreme of a coordinate within a period) became inf or NaN;
* **past the bound**: a coordinate passed ``BOUND`` times the run's own scale, max(1, the largest |value|
  of the observed coordinates over the first period): for a gear model 1 is the length unit (the static
  deflection), so the bound is a million static deflections (or backlashes: the scale of the start);
* **growing without bound**: over the measured periods the largest |value| of a coordinate in each quarter
  rises from quarter to quarter, ends at least ``GROWTH`` times where it was in the first quarter and at
  least ``DRIFT`` times the scale, and nothing contracts it back: the largest exponent is not below zero
  (with every exponent below zero the motion contracts onto an attractor, and growth is a transient).

For a drivetrain, only its meshes' coordinates count (a shaft of zero stiffness lets its disk turn away
freely: the paper's kS = 0, where the twist x2 drifts while the gears vibrate); for a plain ODE, every
observed coordinate. A diverged run is reported as such: the period it was seen in, how far the coordinate
grew, and, from the couplings' stiffness expressions, where a stiffness goes negative (:func:`stiffness_notes`).
"""
from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np

from ..records import record_class
from ..errors import GearsymError

#: a coordinate past this many times the run's scale has diverged
BOUND = 1e6
#: growing without bound: the last quarter's largest |value| at least this many times the first quarter's ...
GROWTH = 1.25
#: ... and at least this many times the run's scale
DRIFT = 100.0

NON_FINITE, PAST_BOUND, GROWING = "non-finite", "past the bound", "growing without bound"


@record_class
class Divergence:
    """How a run diverged (see the module's rule)."""

    reason: str  # NON_FINITE, PAST_BOUND or GROWING
    period: int  # the forcing period of the run (1-based, discarded ones included) where it was seen
    periods: int  # of the run
    coordinate: str
    start: float  # the largest |coordinate| over the first period
    reached: float  # the largest finite |coordinate| the run reached
    bound: float  # the bound it passed (PAST_BOUND), or the scale times DRIFT (GROWING)
    overflow: int | None = None  # the period the state became non-finite in, if it did

    def describe(self, period: float, time_name: str = "t") -> str:
        """'|x| grew from 21.4 past 2.14e+07 (a million times its start) in period 8 of 400 (t = 50.27), and
        became non-finite in period 240' (one phrase)."""
        def when(k: int) -> str:
            return f"period {k} of {self.periods} ({time_name} = {k * period:.6g})"

        grew = f"|{self.coordinate}| grew from {self.start:.3g}"
        overflow = f", and the state became non-finite in period {self.overflow}" if self.overflow else ""
        if self.reason == NON_FINITE:
            return f"{grew} to {self.reached:.3g} and became non-finite in {when(self.period)}"
        if self.reason == PAST_BOUND:
            return (f"{grew} past {self.bound:.3g} ({BOUND:.0e} times the larger of 1 and its start) in "
                    f"{when(self.period)}, to {self.reached:.3g}{overflow}")
        return (f"{grew} to {self.reached:.3g} by {when(self.period)}, rising in every quarter of the measured "
                "periods with no exponent below zero to bring it back")

    def as_dict(self) -> dict:
        return {"reason": self.reason, "period": self.period, "periods": self.periods, "coordinate": self.coordinate,
                "start": self.start, "reached": self.reached, "bound": self.bound, "overflow": self.overflow}


def find_divergence(strobe: np.ndarray, low: np.ndarray, high: np.ndarray, states: Sequence[str],
                    observed: Sequence[str], discard: int, contracting: bool,
                    counted: Callable[[Sequence[str]], Sequence[str]] = lambda names: names) -> Divergence | None:
    """The divergence of one run, or None: ``strobe`` (periods x states), ``low``/``high`` (periods x
    observed: each period's extremes), ``discard`` transient periods, ``contracting``: the largest exponent is
    below zero. ``counted(names)`` keeps the coordinates that count (a drivetrain's meshes)."""
    periods = strobe.shape[0]
    size = np.maximum(np.abs(low), np.abs(high))  # (periods, observed)
    finite = np.isfinite(strobe).all(axis=1) & np.isfinite(size).all(axis=1)
    first = size[0] if finite[0] else np.zeros(size.shape[1])
    scale = max(1.0, float(np.max(first, initial=0.0)))

    def reached(j: int) -> float:
        ok = size[:, j][np.isfinite(size[:, j])]
        return float(ok.max()) if ok.size else float("nan")

    past = size > BOUND * scale
    if not finite.all():
        k = int(np.argmin(finite))
        before = past[:k].any(axis=0)
        if before.any():  # it passed the bound first: that is when it diverged
            j = int(np.argmin(np.where(before, np.argmax(past[:k], axis=0), periods)))
            return Divergence(PAST_BOUND, int(np.argmax(past[:k, j])) + 1, periods, observed[j], float(first[j]),
                              reached(j), BOUND * scale, overflow=k + 1)
        j = next((j for j in range(size.shape[1]) if not np.isfinite(size[k, j])), 0)
        return Divergence(NON_FINITE, k + 1, periods, observed[j], float(first[j]), reached(j), BOUND * scale,
                          overflow=k + 1)
    growing = _growing(size[discard:], scale) if not contracting else np.zeros(size.shape[1], dtype=bool)
    flagged = [observed[j] for j in range(size.shape[1]) if past[:, j].any() or growing[j]]
    if not flagged:
        return None
    kept = set(counted(flagged))
    for j, name in enumerate(observed):
        if name not in kept:
            continue
        if past[:, j].any():
            return Divergence(PAST_BOUND, int(np.argmax(past[:, j])) + 1, periods, name, float(first[j]), reached(j),
                              BOUND * scale)
        if growing[j]:
            return Divergence(GROWING, periods, periods, name, float(first[j]), reached(j), DRIFT * scale)
    return None


#: RK4 is stable for h |lambda| below about this (on the negative real axis: 2.785; 2.83 on the imaginary)
RK4_LIMIT = 2.78


def own_rate(model, y: np.ndarray, p: np.ndarray, period: float, samples: int = 16,
             enough: float = np.inf) -> float:
    """The largest |eigenvalue| of the Jacobian at the state ``y`` over one forcing period: the rate of the model's
    fastest own motion there (inf where the Jacobian is not finite: a parameter value overflows the equations).
    ``enough``: a caller that asks only whether the rate reaches it gets the first sample's rate that does (the
    other eigenvalue problems, most of a cached spectrum's own time after its run, are not solved)."""
    largest = 0.0
    for t in np.linspace(0.0, period, samples, endpoint=False):
        J = np.asarray(model.jacobian(t, y, p), dtype=float)
        if not np.all(np.isfinite(J)):
            return np.inf
        largest = max(largest, float(np.max(np.abs(np.linalg.eigvals(J)))))
        if largest >= enough:
            break
    return largest


def step_ratio(model, p: np.ndarray, y: np.ndarray, period: float, samples: int = 16) -> float:
    """h times the largest |eigenvalue| of the Jacobian at the state ``y`` over one forcing period (h = the
    period over the model's steps): above RK4_LIMIT the integrator itself blows up, whatever the motion does
    (one_stage at omega = 1e-8: 3e6)."""
    return period / model.steps_per_period * own_rate(model, y, p, period, samples)


def run_failure(model, p: np.ndarray, period: float, start: np.ndarray, strobe: np.ndarray,
                log_stretch: np.ndarray, divergence: Divergence | None) -> GearsymError | None:
    """The error of a run that failed rather than diverged, or None: its tangent vectors became non-finite while
    its state did not, or its state overflowed or left the bound with a step too large for RK4 at ``start`` (the
    state it began from; ``strobe``, ``log_stretch``: periods x n). To be raised by the caller."""
    state_finite = bool(np.isfinite(strobe).all())
    if state_finite and not np.isfinite(log_stretch).all():
        return _failed(model, p, strobe, log_stretch, "the tangent vectors did, not the state: the step is too "
                       "large for the linearised flow; give more --steps-per-period")
    if divergence is None or divergence.reason == GROWING:
        return None
    ratio = step_ratio(model, p, start, period)
    if not ratio > RK4_LIMIT:
        return None
    why = (f"h times the largest eigenvalue of the Jacobian is {ratio:.3g} at the start, and RK4 is stable only below "
           f"{RK4_LIMIT:g}: the integrator blew up, not (necessarily) the motion; give more --steps-per-period")
    if not np.isfinite(ratio):
        why = ("the equations are not finite at the start with these values: a value overflows the engine's "
               "doubles (a forcing frequency near 0 divides by omega squared); give values nearer the model's own")
    if not state_finite:
        return _failed(model, p, strobe, log_stretch, why)
    values = ", ".join(f"{n}={v:g}" for n, v in zip(model.parameter_names, p))
    return GearsymError(f"{model.name}: the solution grew past {divergence.bound:.3g} in period {divergence.period} "
                        f"({values}): {why}")


def _failed(model, p: np.ndarray, strobe: np.ndarray, log_stretch: np.ndarray, why: str) -> GearsymError:
    """The engine's own error of a non-finite run (its period and the values), with ``why``."""
    try:
        model.check_finite(p, strobe.T, log_stretch.T)
    except GearsymError as exc:
        return GearsymError(f"{exc} ({why})")
    return GearsymError(f"{model.name}: the run failed ({why})")


def within_bound(state: np.ndarray, start: np.ndarray, names: Sequence[str],
                 counted: Callable[[Sequence[str]], Sequence[str]] = lambda names: names) -> bool:
    """``state`` (a run's last, its entries named ``names``) is finite and no coordinate that ``counted`` keeps
    is beyond BOUND times the larger of 1 and |``start``| (the run's first): a continuation may go on from it
    (a free disk's twist may be anywhere)."""
    if not np.all(np.isfinite(state)):
        return False
    bound = BOUND * max(1.0, float(np.max(np.abs(start))))
    beyond = [n for n, v in zip(names, state) if abs(v) > bound]
    return not beyond or not counted(beyond)


def counted_coordinates(model, names: Sequence[str]) -> list[str]:
    """Of the coordinates ``names`` that grew, those whose growth is a divergence: a drivetrain's meshes (a
    shaft's twist may grow freely: a disk on a shaft of zero stiffness), every one of a plain ODE. (Asked only
    when a coordinate grew: a cached model's couplings load the model.)"""
    couplings = getattr(model.system, "couplings", ())
    if not couplings:
        return list(names)
    meshes = {c.coordinate for c in couplings if c.kind == "mesh"}
    return [n for n in names if n in meshes]


def _growing(size: np.ndarray, scale: float) -> np.ndarray:
    """Per coordinate (columns of ``size``: each measured period's largest |value|): rising in every quarter."""
    if size.shape[0] < 4:
        return np.zeros(size.shape[1], dtype=bool)
    quarters = np.array([q.max(axis=0) for q in np.array_split(size, 4)])  # (4, observed)
    rising = np.all(np.diff(quarters, axis=0) > 0, axis=0)
    return rising & (quarters[-1] >= GROWTH * quarters[0]) & (quarters[-1] >= DRIFT * scale)


# ------------------------------------------------------------------------------------------ what explains it
#: samples of the stiffness over one period, before its minimum is refined
SAMPLES = 2048


def stiffness_notes(system, values: Mapping[str, float], defaults: Mapping[str, float] | None = None) -> list[str]:
    """Where the stiffness of a coupling of ``system`` (a reduced drivetrain's FirstOrderSystem) is zero or
    negative over a period at the parameter ``values``, and which value of a parameter of it makes it so
    (found between ``defaults``' value, 0 or 1, where it is positive, and the run's): one phrase each."""
    import sympy as sp  # (only on the way to an error: a run that diverged)

    notes = []
    time = system.time
    period = float(sp.sympify(system.period, strict=True).subs({sp.Symbol(k, real=True): v for k, v in values.items()}))
    for c in getattr(system, "couplings", ()):
        expr = sp.sympify(c.stiffness, strict=True)
        names = sorted(s.name for s in expr.free_symbols if s != time and s.name in values)
        if {s for s in expr.free_symbols if s != time and s.name not in values}:
            continue
        symbols = [time, *(sp.Symbol(n, real=True) for n in names)]
        expr = expr.subs({s: sp.Symbol(s.name, real=True) for s in expr.free_symbols})
        f = sp.lambdify(symbols, expr, "numpy")
        taus = np.linspace(0.0, period, SAMPLES, endpoint=False)

        def lowest(**given: float) -> tuple[float, float]:
            at = {**{n: values[n] for n in names}, **given}
            k = np.broadcast_to(np.asarray(f(taus, *(at[n] for n in names)), dtype=float), taus.shape)
            i = int(np.argmin(k))
            return float(k[i]), float(taus[i])

        k_min, tau_min = lowest()
        if not np.isfinite(k_min) or k_min > 0:
            continue
        what = f"{c.kind} '{c.name}'"
        if time not in expr.free_symbols:
            given = f"{k_min:g}" if not names else \
                f"{sp.sstr(expr)} = {k_min:g} at {', '.join(f'{n}={values[n]:g}' for n in names)}"
            notes.append(f"the stiffness of {what} is {given}: "
                         + ("zero, nothing holds the deflection" if k_min == 0 else "negative, it pushes the deflection "
                            "on instead of back"))
            continue
        note = (f"k({time.name}) of {what} goes down to {k_min:.4g} (at {time.name} = {tau_min:.3g} in each period): "
                + ("zero stiffness, nothing holds the mesh there" if k_min == 0 else "a negative stiffness pushes "
                   "the teeth apart instead of back"))
        for name in names:
            threshold = _threshold(lambda v: lowest(**{name: v})[0], values[name],
                                   [x for x in ((defaults or {}).get(name), 0.0, 1.0) if x is not None])
            if threshold is not None:
                side = ">" if threshold < values[name] else "<"
                note += f"; it goes below 0 for {name} {side} {threshold:.6g} (here {name} = {values[name]:g})"
        notes.append(note)
    return notes


def _threshold(lowest: Callable[[float], float], value: float, candidates: list[float]) -> float | None:
    """Where ``lowest`` (the stiffness's minimum over a period as a function of one parameter) crosses zero
    between the first candidate where it is positive and ``value``, where it is not: bisection."""
    for start in candidates:
        if start != value and lowest(start) > 0:
            a, b = start, value
            for _ in range(80):
                mid = (a + b) / 2
                if lowest(mid) > 0:
                    a = mid
                else:
                    b = mid
            return (a + b) / 2
    return None
