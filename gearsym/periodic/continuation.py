"""Branches of periodic orbits by pseudo-arclength continuation in one parameter, with their bifurcations.

The unknowns are u = (z, lambda): the shooting states and the parameter. From a solution u_a with unit
tangent t_a the predictor is u_a + ds t_a, and Newton corrects it on the hyperplane <t_a, u - u_pred> = 0
(Keller's pseudo-arclength), which crosses a fold like any other point. The inner product weighs the
states by 1/(their count), so that a step ds is about the root-mean-square change of a state plus the
change of the parameter. The new tangent solves [J  F_lambda; t_a^T] t = [0; 1].

Step control: a correction that fails (or needs many iterations, or turns the tangent by more than
``MAX_TURN``) is retried with half the step; an easy one lets the step grow by ``GROW`` up to ``max_step``;
the parameter moves at most ``max_parameter_step`` per step, so that a flat branch is still drawn with
enough points. The branch ends where it leaves [start, stop] (with a last point exactly on the bound),
after ``max_points`` points, or where no step gives a corrected point.

Non-smooth spots: at a grazing of the true flow the map stays continuous, but its derivative changes like a
square root, and a third crossing within one RK4 step is integrated to first order (see the engine's
located steps): Newton may fail to converge on such a spot at any step. Where the step falls below
``HOP_BELOW`` of the range, the tracer hops over it (a step of the size tried before, accepted with a larger
turn) and lists the hop in ``non_smooth``; a multiplier may change fast across it.

Bifurcations: the test functions of :mod:`.floquet` are evaluated at every point; where one changes sign
between two points, the zero is located by the Illinois variant of regula falsi on the arclength from the
first point (each trial a corrected point) and inserted into the branch. At a period doubling the branch
of period 2n is started (branch switching): the orbit doubled, plus a step along the eigenvector of the
multiplier -1 carried around the doubled orbit (the tangent of the pitchfork of P^2n); it is followed
until it leaves the range or rejoins the period-n branch at another period doubling (its two halves'
difference changes sign there), where it stops rather than trace itself again shifted by n periods.

A fold is a turning point of the parameter along the branch, and it is counted only if the branch turns back by
at least ``FOLD_WIDTH`` of the range: a pair of folds closer than that in the parameter (a wiggle), or a fold
that close to a branch's end, is dropped. Near a pitchfork's vertical tip the fold test is a small number whose
sign rounding decides; the count of folds must not be (the tip where a period-2n branch rejoins its parent is
never a fold: the branch turns there onto its own other half).
"""
from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from ..errors import GearsymError
from .floquet import (FOLD, GRAZING, NEIMARK_SACKER, PERIOD_DOUBLING, grazing_tests, multipliers,
                      neimark_sacker_test, period_doubling_test, torus_pair)
from .shooting import TOLERANCE, Evaluation, OrbitMap, _try_evaluate

#: the test of a period-2n branch coming back to its period-n parent (not a bifurcation of its own)
REJOIN = "rejoin"

#: the largest angle (radians, in the weighted norm) between consecutive tangents
MAX_TURN = 0.3
#: a step is taken only where Newton contracts from the predictor at once (its second correction at most this
#: fraction of its first: Deuflhard's a-priori test) and moves the point at most MAX_CORRECTION of the step: else
#: the predictor lay outside Newton's region of quadratic convergence, and where two parts of a branch come close
#: (the two sides of a resonance, a fold) the corrector converged onto the other part (measured: one_stage with
#: k = 1 + 0.2 cos(tau) from omega = 0.1 jumped back past its start, contraction 0.6-1.4, where smooth steps
#: contract by 0.03 or less); the step is halved instead
MAX_CONTRACTION, MAX_CORRECTION = 0.25, 0.5
#: without a ``max_step`` of the caller's, a step is at most this fraction of 1 + the root-mean-square state of
#: the orbit it starts from (and half the range): the steps move mostly the states, and steps of a few per cent
#: of the orbit's size crossed from one side of a narrow resonance loop to the other unnoticed (the same model:
#: steps of 0.3 did, 0.2 = 0.02 (1 + 9.7) did not)
MAX_STEP_OF_SIZE = 0.02
#: step growth after an easy correction (at most this many iterations), and shrinkage after a hard one
GROW, EASY, HARD = 1.5, 3, 5
#: Newton iterations of a corrector before the step is halved
MAX_CORRECTIONS = 8
#: seconds between two lines of a continuation's progress
PROGRESS_SECONDS = 2.0
#: regula falsi iterations to locate a test function's zero, and when it is located: the bracket below this
#: fraction of the step, or the test function below this fraction of its change over the step
MAX_LOCATE, LOCATED = 30, 1e-10
#: where the step falls below this fraction of the range, the tracer hops over the spot: a step of
#: these multiples of the last one tried, accepted with a turn of up to HOP_TURN
HOP_BELOW, HOPS, HOP_TURN = 1e-5, (0.25, 1.0, 2.0), 1.2
#: the fold test (the unit tangent's parameter component) below this at both ends of a step is rounding on a
#: vertical branch, not a fold: a linear regime's period doubling (a backlash model without impacts, its
#: stiffness varying) has a whole line of period-2 orbits at one parameter value (measured: 1e-12 on one)
FOLD_NOISE = 1e-8
#: folds that turn the branch back by less than this fraction of the range are not counted: next to a period
#: doubling's pitchfork, whose tip is vertical, the branch wiggles by 1e-7 to 1e-6 of the range (measured on
#: one_stage_resonant over omega 0.1..2: 2e-7 to 1.8e-6 in omega), and whether the tangent's parameter component
#: changes sign there depends on the last digits of the Jacobian (a fold counted on one CPU and not on another);
#: the narrowest real hysteresis seen is 1.4e-5 of the range (two folds 2.6e-5 apart in omega)
FOLD_WIDTH = 4e-6


@dataclass(frozen=True)
class Steps:
    """Step control of a continuation over [start, stop] (every length in the weighted norm, see the module
    docstring); None takes a fraction of the range."""

    step: float | None = None
    max_step: float | None = None
    max_parameter_step: float | None = None
    max_points: int = 2000

    def resolved(self, span: float) -> "Steps":
        span = abs(span)
        return Steps(self.step or span / 50, self.max_step or span / 2, self.max_parameter_step or span / 40,
                     self.max_points)


@dataclass
class Solution:
    """One corrected point of a branch, with what the analysis reads at it."""

    ev: Evaluation
    iterations: int
    tangent: np.ndarray | None = None
    mu: np.ndarray | None = None
    tests: dict = field(default_factory=dict)
    contraction: float = 0.0  # the corrector's second Newton step over its first (0: one step or none)
    event: tuple[str, str] | None = None  # (kind, detail) where a bifurcation was located here
    switched_to: int | None = None  # the index of the branch of twice the period started here
    curvature: np.ndarray | None = None  # d tangent / ds, from the step that reached this point

    @cached_property
    def u(self) -> np.ndarray:
        """The point as the tracer's vector: the segments' states, then the parameter (made once: a step, its
        events and their location read it many times; nobody writes into it)."""
        return np.append(self.ev.z.reshape(-1), self.ev.value)

    @property
    def value(self) -> float:
        return float(self.ev.value)


@dataclass
class Traced:
    """A branch as the tracer leaves it: its points in order and why it ended."""

    solutions: list
    end: str
    period_multiple: int
    parent: int | None = None
    rejoined: float | None = None  # where a period-2n branch came back to its parent
    non_smooth: list = field(default_factory=list)  # (from, to) of the parameter where the tracer hopped


class Tracer:
    """Follows branches of one shooting problem over [lo, hi] of its parameter."""

    def __init__(self, problem: OrbitMap, start: float, stop: float, steps: Steps, watches=(), started=None,
                 say: Callable[[str], None] | None = None):
        self.problem, self.steps = problem, steps.resolved(stop - start)
        self.start, self.say = start, say  # say: a line of progress every PROGRESS_SECONDS (None: silent)
        self.said = time.monotonic()  # (the first line after PROGRESS_SECONDS of work: a short run says none)
        self.sized = steps.max_step is None  # the largest step follows the orbits' size
        self.started = started if started is not None else []  # every branch traced, finished or not, in order
        self.lo, self.hi, self.direction = min(start, stop), max(start, stop), (1.0 if stop >= start else -1.0)
        self.watches = watches
        K, n = problem.shooting.count, problem.n
        self.weights = np.append(np.full(K * n, 1.0 / (K * n)), 1.0)
        self.reference: np.ndarray | None = None  # a doubled orbit's halves' difference at the last point

    def halves(self, s: "Solution") -> np.ndarray:
        """The state after n of the 2n periods minus the state at the start (zero on the period-n branch)."""
        z = s.ev.z
        return z[len(z) // 2] - z[0]

    def largest_step(self, s: "Solution") -> float:
        """The largest step from ``s`` (see ``MAX_STEP_OF_SIZE``)."""
        if not self.sized:
            return self.steps.max_step
        return min(self.steps.max_step, MAX_STEP_OF_SIZE * (1 + float(np.sqrt(np.mean(np.square(s.ev.z))))))

    # ------------------------------------------------------------------ basic operations
    def norm(self, v: np.ndarray) -> float:
        return float(np.sqrt(np.dot(self.weights * v, v)))

    @staticmethod
    def bordered(ev: Evaluation, last_row: np.ndarray) -> np.ndarray:
        """The shooting Jacobian with the derivative by the parameter as its last column and ``last_row`` below
        (the corrector's and the tangent's matrix), filled in place."""
        size = len(last_row)
        A = np.empty((size, size))
        A[:-1, :-1] = ev.jacobian()
        A[:-1, -1] = ev.d_parameter.reshape(-1)
        A[-1] = last_row
        return A

    def split(self, u: np.ndarray) -> tuple[np.ndarray, float]:
        return u[:-1].reshape(self.problem.shooting.count, self.problem.n), float(u[-1])

    def corrected(self, u_pred: np.ndarray, normal: np.ndarray, target: float | None = None,
                  start: np.ndarray | None = None) -> Solution | None:
        """Newton from ``u_pred`` (or ``start``) on the hyperplane <normal, u - u_pred> = 0 (weighted), or on
        lambda = target; None if it does not converge in ``MAX_CORRECTIONS`` iterations or leaves the range far behind. Every
        iteration differentiates by the parameter afresh: along a resonance the column changes so fast
        that a chord on it (the start's column kept) needs twice the iterations, measured."""
        a = self.weights * normal if target is None else np.eye(len(u_pred))[-1]
        b = float(np.dot(a, u_pred)) if target is None else target
        u = (u_pred if start is None else start).copy()
        if target is not None:
            u[-1] = target
        margin = 0.5 * (self.hi - self.lo)
        sizes = []  # of the Newton steps, in the weighted norm
        for iteration in range(MAX_CORRECTIONS + 1):
            z, value = self.split(u)
            if not self.lo - margin <= value <= self.hi + margin:
                return None
            ev = _try_evaluate(self.problem, z, value, d_parameter=True)
            if ev is None:
                return None
            if ev.error() <= TOLERANCE:
                return Solution(ev, iteration, contraction=sizes[1] / sizes[0] if len(sizes) > 1 and sizes[0] else 0.0)
            A = self.bordered(ev, a)
            try:
                du = np.linalg.solve(A, -np.append(ev.residual, np.dot(a, u) - b))
            except np.linalg.LinAlgError:
                return None
            if not np.all(np.isfinite(du)):
                return None
            sizes.append(self.norm(du))
            u = u + du
        return None

    def tangent(self, s: Solution, previous: np.ndarray) -> np.ndarray:
        """The unit tangent at ``s``, oriented along ``previous``."""
        ev = s.ev
        A = self.bordered(ev, self.weights * previous)
        rhs = np.zeros(len(previous))
        rhs[-1] = 1.0
        try:
            t = np.linalg.solve(A, rhs)
        except np.linalg.LinAlgError:
            t = np.linalg.lstsq(A, rhs, rcond=None)[0]
        return t / self.norm(t)

    def analysed(self, s: Solution, previous: np.ndarray) -> Solution:
        """``s`` with its tangent, multipliers and test functions."""
        s.tangent = self.tangent(s, previous)
        s.mu = multipliers(s.ev.monodromy)
        tests = {FOLD: float(s.tangent[-1]), PERIOD_DOUBLING: period_doubling_test(s.ev.monodromy),
                 NEIMARK_SACKER: neimark_sacker_test(s.mu)}
        names, p = self.problem.model.parameter_names, s.ev.inputs.p
        for w in self.watches:
            for key, value in grazing_tests(w, s.ev.low, s.ev.high, names, p).items():
                tests[(GRAZING, key)] = value
        if self.reference is not None:
            tests[REJOIN] = float(np.dot(self.halves(s), self.reference))
        s.tests = tests
        return s

    # ------------------------------------------------------------------ a branch
    def first(self, z: np.ndarray, value: float) -> Solution:
        """The corrected start at ``value`` (its tangent pointing towards the stop value)."""
        s = self.corrected(np.append(z.reshape(-1), value), np.zeros(len(self.weights)), target=value)
        if s is None:
            raise GearsymError(f"{self.problem.model.name}: Newton did not converge to the periodic orbit at "
                               f"{self.problem.parameter}={value:g} from the given start")
        toward = np.zeros(len(self.weights))
        toward[-1] = self.direction
        return self.analysed(s, toward)

    def trace(self, start: Solution, *, ds: float | None = None, doubled: bool = False) -> Traced:
        """Points from ``start`` along its tangent until the branch leaves the range, runs out of points or
        of step, or (``doubled``: a period-2n branch) comes back to the period-n branch; its folds narrower than
        ``FOLD_WIDTH`` dropped."""
        traced = self.follow(start, ds=ds, doubled=doubled)
        for s in wiggles(traced.solutions, FOLD_WIDTH * (self.hi - self.lo)):
            s.event = None
        return traced

    def follow(self, start: Solution, *, ds: float | None, doubled: bool) -> Traced:
        steps = self.steps
        ds = ds or steps.step
        traced = Traced([start], f"{steps.max_points} points reached before the end of the range (give more: "
                                 f"max_points=, --max-points on the command line)",
                        self.problem.shooting.period_multiple)
        self.started.append(traced)  # its points so far are kept if the run is interrupted
        a = start
        self.reference = self.halves(start) if doubled else None
        if doubled:
            self.analysed(start, start.tangent)
        while len(traced.solutions) < steps.max_points:
            b, ds = self.advance(a, ds, traced)
            if b is None:
                traced.end = (f"no corrected point beyond {self.problem.parameter}={a.value:.6g}, with any step: the "
                              "branch could not be followed further")
                break
            outside = not self.lo <= b.value <= self.hi
            if outside:
                bound = self.hi if b.value > self.hi else self.lo
                b = self.corrected(a.u + ds * a.tangent, a.tangent, target=bound)
                if b is None:
                    traced.end = f"could not end the branch on {self.problem.parameter}={bound:g}"
                    break
                b = self.analysed(b, a.tangent)
            located = self.events(a, b)
            rejoin = self.rejoin(located, b) if doubled else None
            if rejoin is not None:
                # the pitchfork's tip: the fold test vanishes there too, as the branch turns onto its other half.
                # A sign change of it in this step is that tip (a fold besides would make two: no sign change)
                traced.solutions += [e for e in located if e is not rejoin and e.event[0] != FOLD]
                traced.solutions.append(rejoin)
                traced.end = (f"rejoined the period-{self.problem.shooting.period_multiple // 2} branch at "
                              f"{self.problem.parameter}={rejoin.value:.6g}")
                traced.rejoined = rejoin.value
                break
            traced.solutions += located + [b]
            if outside:
                traced.end = f"reached {self.problem.parameter}={b.value:g}"
                break
            a = b
            self.report(traced, b)
            if doubled:
                self.reference = self.halves(b)
            ds = min(ds * GROW, self.largest_step(b)) if b.iterations <= EASY else ds / 2 if b.iterations >= HARD \
                else ds
        return traced

    def report(self, traced: Traced, b: Solution) -> None:
        """A line of progress, at most every ``PROGRESS_SECONDS``: the branch, its points, where it is in the range
        (as a share of it from the start: the parameter's own unit is the caller's)."""
        now = time.monotonic()
        if self.say is None or now - self.said < PROGRESS_SECONDS:
            return
        self.said = now
        share = (b.value - self.start) / (self.hi - self.lo) * self.direction
        self.say(f"orbits: period-{self.problem.shooting.period_multiple} branch: {len(traced.solutions)} points "
                 f"(at most {self.steps.max_points}), {share:.0%} of the range from its start")

    def rejoin(self, located: list, b: Solution) -> Solution | None:
        """Where a period-2n branch comes back to the period-n branch in this step: the located zero of its
        halves' difference, or ``b`` if that difference vanished there (a step that landed on the parent)."""
        back = next((e for e in located if e.event[0] == REJOIN), None)
        if back is None and np.max(np.abs(self.halves(b))) <= 1e-7 * (1 + np.max(np.abs(b.ev.z))):
            back = b
        if back is not None:
            back.event = None
        return back

    def step(self, a: Solution, ds: float, max_turn: float = MAX_TURN) -> Solution | None:
        """The corrected point ``ds`` along the tangent at ``a``, if the tangent turns by less than ``max_turn``."""
        bent = None if a.curvature is None else a.u + ds * a.tangent + ds * ds / 2 * a.curvature
        predicted = a.u + ds * a.tangent
        b = self.corrected(predicted, a.tangent, start=bent)
        if b is None:
            return None
        if max_turn <= MAX_TURN and (b.contraction > MAX_CONTRACTION
                                     or self.norm(b.u - predicted) > MAX_CORRECTION * ds):
            return None  # (a hop over a non-smooth spot, with its larger turn, is not held to this)
        b = self.analysed(b, a.tangent)
        cos = np.dot(self.weights * a.tangent, b.tangent)
        if np.arccos(np.clip(cos, -1, 1)) > max_turn:
            return None
        b.curvature = (b.tangent - a.tangent) / ds  # the predictor's second-order term at the next step
        return b

    def advance(self, a: Solution, ds: float, traced: Traced) -> tuple[Solution | None, float]:
        """The next point from ``a``: the step halved until the corrector converges with little turn; below
        ``HOP_BELOW`` of the range, a hop over the spot (the steps' map jumps there, see ``non_smooth``)."""
        steps, tried = self.steps, ds
        ds = min(ds, self.largest_step(a), steps.max_parameter_step / max(abs(a.tangent[-1]), 1e-300))
        if a.curvature is not None:  # a step the last curvature would turn by most of MAX_TURN is not tried
            ds = min(ds, 0.7 * MAX_TURN / max(self.norm(a.curvature), 1e-300))
        while ds >= HOP_BELOW * (self.hi - self.lo):
            b = self.step(a, ds)
            if b is not None:
                return b, ds
            ds /= 2
        for factor in HOPS:
            b = self.step(a, factor * min(tried, self.largest_step(a)), max_turn=HOP_TURN)
            if b is not None:
                traced.non_smooth.append((a.value, b.value))
                return b, min(tried, self.largest_step(a))
        return None, ds

    # ------------------------------------------------------------------ bifurcations
    def events(self, a: Solution, b: Solution) -> list[Solution]:
        """Every test function's zero between ``a`` and ``b``, located and in order of arclength."""
        found = []
        span = float(np.dot(self.weights * a.tangent, b.u - a.u))
        for key, fa in a.tests.items():
            fb = b.tests[key]
            if not (np.sign(fa) != np.sign(fb) and fa != 0):
                continue
            if key == FOLD and max(abs(fa), abs(fb)) < FOLD_NOISE:
                continue
            s, at, note = self.locate(a, b, key, span)
            kind = key[0] if isinstance(key, tuple) else key
            detail = "; ".join(x for x in (key[1] if isinstance(key, tuple) else "", note) if x)
            if kind == NEIMARK_SACKER and not torus_pair(at.mu):
                continue  # a neutral saddle: two real multipliers with product 1, no bifurcation
            at.event = (kind, detail)
            found.append((s, at))
        return [at for _, at in sorted(found, key=lambda x: x[0])]

    @staticmethod
    def between(lo: tuple, hi: tuple, s: float) -> np.ndarray:
        """Newton's start at arclength ``s`` inside a bracket: the line through its two corrected ends (closer
        to the branch than the tangent from the first point once the bracket is small)."""
        w = (s - lo[0]) / (hi[0] - lo[0])
        return (1 - w) * lo[1].u + w * hi[1].u

    def locate(self, a: Solution, b: Solution, key, span: float) -> tuple[float, Solution, str]:
        """The zero of test ``key`` on the arclength from ``a`` towards ``b`` (Illinois regula falsi), as a
        corrected point, and a note when the corrector failed inside (a non-smooth spot) before the bracket
        closed: then the nearer of the last bracket's ends stands for the zero."""
        fa, fb = a.tests[key], b.tests[key]
        lo, hi = (0.0, a), (span, b)
        side = 0
        for _ in range(MAX_LOCATE):
            s = (lo[0] * fb - hi[0] * fa) / (fb - fa) if fb != fa else (lo[0] + hi[0]) / 2
            if not lo[0] < s < hi[0]:
                s = (lo[0] + hi[0]) / 2
            trial = self.corrected(a.u + s * a.tangent, a.tangent, start=self.between(lo, hi, s))
            if trial is None:
                s = (lo[0] + hi[0]) / 2
                trial = self.corrected(a.u + s * a.tangent, a.tangent, start=self.between(lo, hi, s))
            if trial is None:
                end = lo if abs(fa) <= abs(fb) else hi
                return end[0], replace(end[1], event=None, switched_to=None), (
                    f"not located closer than {self.problem.parameter} in [{lo[1].value:.6g}, {hi[1].value:.6g}]: "
                    "the steps' map is not smooth there")
            trial = self.analysed(trial, a.tangent)
            f = trial.tests[key]
            if f == 0 or hi[0] - lo[0] <= LOCATED * abs(span):
                return s, trial, ""
            if np.sign(f) == np.sign(fa):
                lo, fa = (s, trial), f
                fb = fb / 2 if side == -1 else fb
                side = -1
            else:
                hi, fb = (s, trial), f
                fa = fa / 2 if side == 1 else fa
                side = 1
            if abs(f) <= LOCATED * abs(a.tests[key] - b.tests[key]):
                return s, trial, ""
        return s, trial, ""


def wiggles(solutions: list, width: float) -> list:
    """The located folds of a branch (``solutions`` in order) that turn it back by less than ``width`` in the
    parameter: the branch's turning points are simplified by persistence, the closest pair of neighbours in
    the parameter first (two folds, or a fold and the branch's end next to it, which then stands for it),
    until every pair is ``width`` or more apart."""
    folds = [s for s in solutions if s.event and s.event[0] == FOLD]
    if not folds:
        return []
    turns = [solutions[0], *folds, solutions[-1]]
    dropped = []
    while len(turns) > 2:
        gap, i = min((abs(turns[i + 1].value - turns[i].value), i) for i in range(len(turns) - 1))
        if gap >= width:
            break
        if i == 0:
            gone = [turns[1]]
        elif i + 1 == len(turns) - 1:
            gone = [turns[i]]
        else:
            gone = [turns[i], turns[i + 1]]
        dropped += gone
        turns = [t for t in turns if not any(t is g for g in gone)]
    return dropped
