"""What each jump of a continuation sweep is, from the branches of periodic orbits (:mod:`gearsym.periodic`).

A jump leaves the attractor the sweep was on. If that attractor is a stable periodic orbit on one of the
continued branches (its amplitude within ``MATCH`` of the branch's there), the branch's stable part is
followed in the run's direction to where it ends: a located fold (the orbit ceases to exist), period
doubling or Neimark-Sacker bifurcation (it loses stability), or a grazing (it touches a backlash surface
and its multipliers jump through the unit circle). If that end lies within a grid step of the jump, the
jump *is* that bifurcation; if the stable part runs on past the jump's arrival too, the jump is a steep
but smooth part of the branch (no bifurcation). A periodic attractor of another
period (up to ``CONTINUED_PERIOD``, read from the sweep's Poincare points) is continued itself from the
sweep's state across the jump, and its stable part's end found the same way. If the attractor is chaotic,
no continued orbit was left:
the jump is a crisis of the chaotic attractor, and the folds within a grid step (if any) are named; if it
is "quasi-periodic" (lambda_1 within its error of zero) next to a located bifurcation, the run sits on
that bifurcation, where a multiplier is on the unit circle and the run has not settled.
Nothing here is typed in: every sentence is made from the branches and the sweep.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..analysis.attractors import orbit_period
from ..codegen import CompiledModel
from ..codegen.build import compile_model
from ..errors import GearsymError
from ..periodic import FOLD, GRAZING, NEIMARK_SACKER, PERIOD_DOUBLING, Continuation, continue_orbits, periodic_orbit
from ..sweep import SweepResult
from ..loading import load
from .plan import JUMP_TOLERANCE, ORBITS, PAPER_JUMPS

#: relative amplitude difference within which a sweep's point lies on a branch (the sweeps use the paper's
#: plain RK4 and the branches the located steps: their amplitudes differ by ~1e-3)
MATCH = 0.01
#: a periodic attractor not on the period-1 and period-2 branches, of at most this period, is continued itself
CONTINUED_PERIOD = 4
CHAOTIC = ("chaotic", "hyperchaotic", "quasi-periodic")
FOLD_KIND, CRISIS, STEEP, LEFT, OTHER = FOLD, "crisis", "no bifurcation", "left a continuing orbit", "other orbit"
#: an end where the sweep's attractor is 'undetermined': said as such, not explained
UNDECIDED = "undetermined attractor"
MEANING = {FOLD: "it ceases to exist", PERIOD_DOUBLING: "it loses stability, a multiplier through -1",
           NEIMARK_SACKER: "it loses stability, a complex pair through |mu| = 1",
           GRAZING: "it touches a backlash surface and its multipliers jump through the unit circle"}


def explain_jumps(model: CompiledModel, result: Continuation, sweep: SweepResult, values: dict | None = None,
                  paper: bool = False) -> tuple[dict, list[Continuation]]:
    """Every hysteresis interval's two ends and every jump of the up run, classified; with ``paper``, the
    paper's jumps (Fig. 3a, D = 2) too, by the up run's jump nearest each (within the paper's tolerance).
    ``model`` (the orbits' scheme) and ``values`` are those of the continuation: a sweep's point is matched
    to a branch by the orbit Newton finds there from the branch. Returns the record and the branches of
    other periods continued across jumps (for the figure)."""
    step = float(np.min(np.diff(sweep.axes[0].values)))
    runs = {d: idx for d, _, idx in sweep.lines()}
    findings = sweep.findings()
    classify = _Classifier(model, result, sweep, values or {}, step)
    hysteresis = []
    for h in findings["hysteresis"]:
        hysteresis.append({"from": h["from"], "to": h["to"], "up": classify(runs.get("up"), h["to"], +1),
                           "down": classify(runs.get("down"), h["from"], -1)})
    up = [j for j in findings["jumps"] if j["direction"] == "up"]
    jumps = [{**j, **classify(runs["up"], j["from"], +1, j["to"])} for j in up]
    record = {"parameter": result.parameter, "step": step,
              # (not the number of points: it follows from the step control's decisions, which rounding changes)
              "branches": [{"period": b.period_multiple, "from": float(b.values.min()), "to": float(b.values.max())}
                           for b in result.branches],
              "bifurcations": [{"type": b.kind, "omega": b.value, "period": b.period_multiple, "detail": b.detail}
                               for b in result.bifurcations],
              "hysteresis": hysteresis, "jumps_up": jumps}
    if paper:
        record["paper_jumps"] = [_paper_jump(w, jumps) for w in PAPER_JUMPS]
    return record, classify.local


def _paper_jump(w: float, jumps: list[dict]) -> dict:
    near = [j for j in jumps if min(j["from"], j["to"]) - JUMP_TOLERANCE <= w <= max(j["from"], j["to"]) + JUMP_TOLERANCE]
    if not near:
        return {"omega": w, "kind": None, "text": f"no jump of the up run within ±{JUMP_TOLERANCE} of ω = {w}"}
    j = min(near, key=lambda j: abs((j["from"] + j["to"]) / 2 - w))
    return {"omega": w, "from": j["from"], "to": j["to"], "kind": j["kind"], "text": j["text"]}


@dataclass(frozen=True)
class _Leaving:
    """Where a run leaves its attractor: from ``at`` to ``arrival`` (``direction`` +1 up, -1 down), its
    amplitudes there, and the window (a grid step either side) a bifurcation must lie in to be the cause."""

    at: float
    arrival: float
    direction: int
    amplitude: float
    after: float
    window: tuple[float, float]


class _Classifier:
    """What a run does where it leaves its attractor (see the module docstring)."""

    def __init__(self, model, result: Continuation, sweep: SweepResult, values: dict, step: float):
        self.model, self.result, self.sweep, self.values, self.step = model, result, sweep, values, step
        self.coordinate = result.observed[0]
        self.local: list[Continuation] = []  # the orbits of other periods continued across a jump

    def __call__(self, idx, at: float, direction: int, arrival: float | None = None) -> dict:
        if idx is None:
            return {"kind": None, "text": "no such run"}
        omega = self.sweep[self.result.parameter][idx]
        i = int(np.argmin(np.abs(omega - at)))
        arrival = float(omega[min(i + 1, len(idx) - 1)]) if arrival is None else arrival
        leave = _Leaving(at, arrival, direction, float(self.sweep[f"A_{self.coordinate}"][idx][i]),
                         float(self.sweep[f"A_{self.coordinate}"][idx][int(np.argmin(np.abs(omega - arrival)))]),
                         (min(at, arrival) - self.step, max(at, arrival) + self.step))
        match = self.on_stable_branch(self.result, at, leave.amplitude)
        if match is not None:
            return self.from_branch(self.result, match, leave)
        regime = str(self.sweep["regime"][idx][i])
        period = self.period_of(str(self.sweep["direction"][idx[i]]), at) if regime == "periodic" else None
        if period and period <= CONTINUED_PERIOD:  # continue this orbit itself over the jump's window
            local = self.local_branch(idx[i], leave, period)
            if local is not None:
                return self.from_branch(local, (0, 0), leave)
        return self.not_on_a_branch(regime, leave.window, period)

    def from_branch(self, result: Continuation, match: tuple[int, int], leave: "_Leaving") -> dict:
        """The jump, from the stable segment ``match`` of ``result`` that the run was on."""
        b, k = match
        end, kind = _stable_end(result, b, k, leave.direction)
        period = f"the stable period-{result.branches[b].period_multiple} orbit"
        if leave.window[0] <= end <= leave.window[1]:
            return {"kind": kind, "at": end,
                    "text": f"a {kind} of {period} at ω = {end:.4f}: {MEANING.get(kind, 'the range ends there')}"}
        if (end - leave.arrival) * leave.direction > 0 and \
                self.on_stable_branch(result, leave.arrival, leave.after, b) is not None:
            return {"kind": STEEP, "at": None, "text": f"{STEEP}: {period} itself changes steeply there "
                                                         f"(A {leave.amplitude:.2f} → {leave.after:.2f}) and stays stable"}
        return {"kind": LEFT, "at": end, "text": f"the run left {period}, which stays stable to ω = {end:.4f} "
                                                 f"({kind} there): another attractor's basin took it"}

    def local_branch(self, row: int, leave: "_Leaving", period: int) -> Continuation | None:
        """The period-``period`` orbit the sweep was on at ``row``, continued from there across the window."""
        start = np.array([self.sweep[f"final_{s}"][row] for s in self.result.state_names])
        stop = leave.window[1] + self.step if leave.direction > 0 else leave.window[0] - self.step
        try:
            local = continue_orbits(self.model, self.result.parameter, leave.at, stop, y0=start, period_multiple=period,
                                    switch_depth=0, **self.values)
        except GearsymError:
            return None
        branch = local.branches[0]
        first = branch.amplitude[0, 0]
        if len(branch) < 2 or not _stable(branch, 0) or abs(first - leave.amplitude) > MATCH * abs(leave.amplitude):
            return None
        self.local.append(local)
        return local

    def period_of(self, direction: str, omega: float) -> int | None:
        """The period (in forcing periods) of the sweep's attractor at ``omega`` from its Poincare samples."""
        strobe = self.sweep.strobe
        if not strobe or self.result.parameter not in strobe:
            return None
        rows = (strobe["direction"] == direction) & np.isclose(strobe[self.result.parameter], omega)
        if rows.sum() < 2:
            return None
        points = np.array([strobe[s][rows] for s in self.result.state_names])
        return orbit_period([points], np.maximum(np.ptp(points, axis=1), 1e-12))

    def not_on_a_branch(self, regime: str, window, period: int | None = None) -> dict:
        inside = [b for b in self.result.bifurcations if window[0] <= b.value <= window[1] and b.kind != GRAZING]
        folds = [b.value for b in inside if b.kind == FOLD]
        near = (f"beside a periodic fold at ω = {', '.join(f'{f:.4f}' for f in folds)}" if folds else
                f"no periodic fold within {self.step:g} of it")
        if regime in ("quasi-periodic", "undetermined") and inside:  # lambda_1 ~ 0: on a bifurcation, not settled
            b = min(inside, key=lambda b: abs(b.value - (window[0] + window[1]) / 2))
            return {"kind": b.kind, "at": b.value,
                    "text": f"the run sits at a {b.kind} of the period-{b.period_multiple} orbit at ω = {b.value:.4f} "
                            f"(a multiplier on the unit circle: λ₁ ≈ 0, reported {regime}, not settled)"}
        if regime in CHAOTIC:
            return {"kind": CRISIS, "at": None, "text": f"a crisis of a {regime} attractor ({near})"}
        if regime == "undetermined":
            return {"kind": UNDECIDED, "at": None,
                    "text": f"an attractor whose regime the run cannot decide ({near}; more --periods would tell)"}
        which = f"a period-{period} orbit (from the sweep's Poincaré points)" if period else f"a {regime} attractor"
        return {"kind": OTHER, "at": None, "text": f"{which}, not on the continued period-1 and period-2 branches: "
                                                    f"its own end ({near})"}

    def on_stable_branch(self, result: Continuation, omega: float, amplitude: float, only: int | None = None):
        """(branch, k): the stable segment [k, k + 1] at ``omega`` where Newton, started from the branch, finds a
        stable orbit with the sweep's ``amplitude`` (within MATCH); the nearest such, or None."""
        best, found = np.inf, None
        for b, branch in enumerate(result.branches):
            if only is not None and b != only:
                continue
            for k in range(len(branch) - 1):
                lo, hi = sorted(branch.values[k:k + 2])
                if not (lo <= omega <= hi and hi > lo and _stable(branch, k)):
                    continue
                w = (omega - branch.values[k]) / (branch.values[k + 1] - branch.values[k])
                start = (1 - w) * branch.states[k] + w * branch.states[k + 1]
                try:
                    orbit = periodic_orbit(self.model, y0=start, period_multiple=branch.period_multiple,
                                           **{**self.values, result.parameter: omega})
                except GearsymError:
                    continue
                off = abs(orbit.amplitude[self.coordinate] - amplitude) / max(abs(amplitude), 1e-12)
                if orbit.stable and off <= MATCH and off < best:
                    best, found = off, (b, k)
        return found


def _stable(branch, k: int) -> bool:
    """The segment between points k and k + 1 is stable (the mean of its ends' largest |mu| below 1)."""
    largest = np.max(np.abs(branch.multipliers[k:k + 2]), axis=1)
    return bool(largest.mean() < 1.0)


def _stable_end(result: Continuation, b: int, k: int, direction: int) -> tuple[float, str]:
    """Where the stable segment [k, k + 1] of branch ``b`` ends, walking in ``direction`` of omega, and the
    located bifurcation there (the branch's end if it runs out of the range stable)."""
    branch = result.branches[b]
    step = 1 if (branch.values[k + 1] - branch.values[k]) * direction > 0 else -1
    j = k + 1 if step > 0 else k
    while 0 < j < len(branch) - 1 and _stable(branch, min(j, j + step)) and \
            (branch.values[j + step] - branch.values[j]) * direction > 0:
        j += step
    value = float(branch.values[j])
    kinds = [x.kind for x in result.bifurcations if x.branch == b and x.value == value]
    return value, (kinds[0] if kinds else "end of the range")


def jump_records(plan, sweeps: dict, orbits: dict) -> tuple[dict, dict]:
    """For each orbit job of ``plan``: its sweep's jumps and hysteresis explained by its branches (the paper's
    jumps where the sweep is Fig. 3's D = 2), and the orbits of other periods continued across them."""
    records, local = {}, {}
    for job in plan.orbits:
        sweep_job = plan.sweep(job.sweep)
        model = compile_model(load(sweep_job.model), ORBITS)
        record, local[job.sweep] = explain_jumps(model, orbits[job.sweep], sweeps[job.sweep], sweep_job.settings,
                                                 paper=job.sweep == PAPER_SWEEP)
        records[job.sweep] = {"model": sweep_job.model, **record}
    return records, local


#: the sweep whose up run the paper's jumps are about (Fig. 3a, curve '2')
PAPER_SWEEP = "fig3_D2"
