"""``continue_orbits``: every branch of periodic orbits over a parameter range, and its bifurcations."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..checks import json_safe, whole_number
from ..codegen import CompiledModel, engine_verb
from ..errors import GearsymError, UnknownParameterError
from ..options import Execution, Integration
from .continuation import Solution, Steps, Traced, Tracer
from .floquet import contact_regime, mesh_watches, PERIOD_DOUBLING
from .orbit import find_orbit, starting_states
from .shooting import OrbitMap, Shooting

#: branches of period 2n, 4n, ... started at period doublings, at most
MAX_BRANCHES = 16


@dataclass(frozen=True)
class Bifurcation:
    """A located bifurcation: its ``kind`` (fold, period doubling, Neimark-Sacker, grazing), where, and the
    multipliers there; ``detail`` says which surface a grazing touches."""

    kind: str
    value: float
    branch: int
    period_multiple: int
    multipliers: np.ndarray
    state: np.ndarray
    detail: str = ""
    switched_to: int | None = None  # the period-2n branch born (or ending) here

    def as_dict(self, parameter: str, state_names) -> dict:
        return json_safe({"type": self.kind, parameter: self.value, "branch": self.branch,
                          "period_multiple": self.period_multiple,
                          "multipliers": [{"re": float(m.real), "im": float(m.imag), "abs": float(abs(m))}
                                          for m in self.multipliers],
                          "detail": self.detail, "state": dict(zip(state_names, self.state)),
                          "switched_to": self.switched_to})


@dataclass(frozen=True)
class Branch:
    """One branch of periodic orbits, its points in the order of the continuation."""

    index: int
    period_multiple: int
    values: np.ndarray  # (k,) the parameter
    states: np.ndarray  # (k, n) at the section
    multipliers: np.ndarray  # (k, n) complex, largest modulus first
    low: np.ndarray  # (k, observed)
    high: np.ndarray
    residual: np.ndarray  # (k,)
    contact: np.ndarray  # (k, meshes) str
    end: str
    parent: int | None = None
    events: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))  # indices of located points

    def __len__(self) -> int:
        return len(self.values)

    @property
    def stable(self) -> np.ndarray:
        return np.max(np.abs(self.multipliers), axis=1) < 1.0

    @property
    def amplitude(self) -> np.ndarray:
        """(k, observed): (max - min)/2 over each orbit."""
        return (self.high - self.low) / 2


@dataclass(frozen=True)
class Continuation:
    """Branches of periodic orbits of ``model`` over ``parameter`` from ``start`` to ``stop``."""

    model: str
    model_hash: str
    parameter: str
    start: float
    stop: float
    parameters: dict[str, float]  # every other parameter's value
    state_names: tuple[str, ...]
    observed: tuple[str, ...]
    meshes: tuple[str, ...]
    forcing_period: float
    branches: tuple[Branch, ...]
    bifurcations: tuple[Bifurcation, ...]
    settings: dict
    units: dict[str, str] = field(default_factory=dict)  # column -> unit, for a continuation in physical units

    def of_kind(self, kind: str) -> list[Bifurcation]:
        return [b for b in self.bifurcations if b.kind == kind]

    def rows(self) -> list[dict]:
        """One row per branch point: what ``gearsym orbits --out`` writes."""
        rows = []
        for br in self.branches:
            moduli = np.abs(br.multipliers)
            amplitude, stable = br.amplitude, br.stable  # (made once a branch, not once a row)
            located = set(br.events.tolist())
            for i in range(len(br)):
                row = {"branch": br.index, "period_multiple": br.period_multiple, self.parameter: br.values[i]}
                row.update({f"A_{c}": amplitude[i, j] for j, c in enumerate(self.observed)})
                row.update({f"mu_abs_{j + 1}": moduli[i, j] for j in range(moduli.shape[1])})
                row["stable"] = bool(stable[i])
                row.update({f"contact_{m}": br.contact[i, j] for j, m in enumerate(self.meshes)})
                row.update({f"min_{c}": br.low[i, j] for j, c in enumerate(self.observed)})
                row.update({f"max_{c}": br.high[i, j] for j, c in enumerate(self.observed)})
                row.update({f"state_{s}": br.states[i, j] for j, s in enumerate(self.state_names)})
                row["residual"] = br.residual[i]
                row["bifurcation"] = next((b.kind for b in self.bifurcations if b.branch == br.index
                                           and i in located and b.value == br.values[i]), "")
                rows.append(row)
        return rows

    def as_dict(self) -> dict:
        return json_safe({
            "model": self.model, "model_hash": self.model_hash, "parameter": self.parameter,
            "start": self.start, "stop": self.stop, "parameters": self.parameters, "settings": self.settings,
            "branches": [{"index": b.index, "period_multiple": b.period_multiple, "parent": b.parent,
                          "points": len(b), "end": b.end, "from": float(b.values[0]), "to": float(b.values[-1])}
                         for b in self.branches],
            "bifurcations": [b.as_dict(self.parameter, self.state_names) for b in self.bifurcations],
        })


@engine_verb
def continue_orbits(model: CompiledModel, parameter: str, start: float, stop: float, *, y0=None,
                    period_multiple: int = 1, segments: int | None = None, options: Integration | None = None,
                    step: float | None = None, max_step: float | None = None, max_points: int = 2000,
                    switch_depth: int = 1, execution: Execution | None = None, **values: float) -> Continuation:
    """Periodic orbits of ``period_multiple`` forcing periods from ``parameter`` = ``start`` to ``stop``, by
    pseudo-arclength continuation through folds, with their Floquet multipliers, stability, contact
    regimes and the bifurcations between them located (folds, period doublings, Neimark-Sacker, grazings).

    The first orbit is found by Newton at ``start`` from ``y0`` (a state at the section), or from where
    ``options.periods`` periods of simulation end. At each period doubling a branch of twice the period is
    followed too, down to ``switch_depth`` doublings (0: none). ``step``, ``max_step``: in the norm of
    :mod:`gearsym.periodic.continuation` (default: 1/50 of the range, and the smaller of half the range and
    ``MAX_STEP_OF_SIZE`` times 1 + the root-mean-square state of the orbit a step starts from).
    ``execution``: its ``progress`` says each branch's points as they come (a line every few seconds).
    """
    options = model.run_options(options)
    segments = model.cycles if segments is None else segments  # (one per mesh period of a revolution)
    if parameter not in model.parameter_names:
        raise UnknownParameterError(parameter, model.parameter_names, model.name)
    start, stop = float(start), float(stop)
    if not (np.isfinite(start) and np.isfinite(stop)) or start == stop:
        raise GearsymError(f"the continuation needs two different finite values of {parameter}, got {start} and {stop}")
    switch_depth = whole_number(switch_depth, "switch_depth")
    values = {**values, parameter: start}
    problem = OrbitMap(model, Shooting(period_multiple, segments), parameter, values)
    if y0 is not None:
        y0 = model.initial_state(y0)
    steps = Steps(step=step, max_step=max_step, max_points=whole_number(max_points, "max_points", 2))
    watches = mesh_watches(model)
    started: list[Traced] = []
    ev, _ = find_orbit(problem, starting_states(model, y0, options, period_multiple, problem.inputs(start)), start)
    say = execution.say if execution is not None and execution.verbose else None
    tracer = Tracer(problem, start, stop, steps, watches, started, say)
    settings = {"integration": options.describe(), "steps_per_period": model.steps_per_period,
                "locate_crossings": model.options.locate_crossings, "period_multiple": period_multiple,
                "segments": segments, "transient_periods": None if y0 is not None else options.periods,
                "switch_depth": switch_depth, "steps": vars(tracer.steps)}
    try:
        traced = [tracer.trace(tracer.first(ev.z, start))]
        _switch_branches(model, parameter, traced, start, stop, steps, watches, switch_depth, started, say)
    except KeyboardInterrupt as exc:
        if not started:
            raise
        started[-1].end = "interrupted"
        partial = _continuation(model, problem, parameter, start, stop, started, watches,
                                {**settings, "interrupted": True})
        raise ContinuationInterrupted(partial) from exc
    return _continuation(model, problem, parameter, start, stop, traced, watches, settings)


class ContinuationInterrupted(KeyboardInterrupt):
    """Ctrl-C during a continuation: ``result`` holds the branches as far as they were traced."""

    def __init__(self, result: Continuation):
        self.result = result
        points = sum(len(b) for b in result.branches)
        super().__init__(f"interrupted: kept {len(result.branches)} branch(es), {points} points")


def _continuation(model, problem, parameter, start, stop, traced, watches, settings) -> Continuation:
    branches, bifurcations = _results(model, traced, watches, parameter)
    fixed = dict(zip(model.parameter_names, map(float, problem.p)))
    fixed.pop(parameter)
    return Continuation(
        model=model.name, model_hash=model.hash, parameter=parameter, start=start, stop=stop, parameters=fixed,
        state_names=model.state_names, observed=model.observed, meshes=tuple(w.name for w in watches),
        forcing_period=problem.inputs(start).period, branches=branches, bifurcations=bifurcations,
        settings=settings)


def _switch_branches(model, parameter: str, traced: list[Traced], start, stop, steps, watches, depth: int,
                     started: list, say=None) -> None:
    """Branch switching at every period doubling (breadth first, ``depth`` doublings deep): a period-2n
    branch that rejoins its parent at another period doubling takes that one off the list."""
    queue = [(0, s) for s in traced[0].solutions if s.event and s.event[0] == PERIOD_DOUBLING] if depth else []
    done: set[int] = set()
    while queue and len(traced) < MAX_BRANCHES:
        parent, pd = queue.pop(0)
        if id(pd) in done:
            continue
        done.add(id(pd))
        child = _doubled_branch(model, parameter, traced[parent], pd, start, stop, steps, watches, started, say)
        if child is None:
            continue
        child.parent = parent
        pd.switched_to = len(traced)
        traced.append(child)
        if child.rejoined is not None:  # the other end of the bubble: not to be started again
            doublings = [s for s in traced[parent].solutions if s.event and s.event[0] == PERIOD_DOUBLING
                         and s is not pd]
            if doublings:
                other = min(doublings, key=lambda s: abs(s.value - child.rejoined))
                other.switched_to = pd.switched_to
                done.add(id(other))
        generations = 1
        p = parent
        while traced[p].parent is not None:
            generations, p = generations + 1, traced[p].parent
        if generations < depth:
            queue += [(len(traced) - 1, s) for s in child.solutions if s.event and s.event[0] == PERIOD_DOUBLING]


def _doubled_branch(model, parameter: str, parent: Traced, pd: Solution, start, stop, steps, watches,
                    started: list, say=None) -> Traced | None:
    """The period-2n branch born at the period doubling ``pd``: its start is ``pd``'s orbit taken twice
    plus a step along the eigenvector of the multiplier nearest -1, carried around the doubled orbit."""
    base = pd.ev.z
    shooting = Shooting(parent.period_multiple * 2, len(base) // parent.period_multiple)
    problem = OrbitMap(model, shooting, parameter, dict(zip(model.parameter_names, pd.ev.inputs.p)))
    tracer = Tracer(problem, start, stop, steps, watches, started, say)
    mu, vectors = np.linalg.eig(pd.ev.monodromy)
    k = int(np.argmin(np.abs(mu + 1)))
    direction = np.real(vectors[:, k])
    # LAPACK's eigenvector has either sign (the BLAS kernel decides): the branch would start on either half of the
    # pitchfork, the same orbits shifted by n periods but other points. Its largest component is made positive.
    direction = direction * np.sign(direction[np.argmax(np.abs(direction) >= np.max(np.abs(direction)) * (1 - 1e-9))])
    doubled = np.vstack([base, base])
    carried = np.empty_like(doubled)
    carried[0] = direction
    for j in range(1, len(doubled)):
        carried[j] = pd.ev.blocks[(j - 1) % len(base)] @ carried[j - 1]
    tangent = np.append(carried.reshape(-1), 0.0)
    tangent /= tracer.norm(tangent)
    u0 = np.append(doubled.reshape(-1), pd.value)
    ds = tracer.steps.step / 4
    for _ in range(6):  # a step too small falls back on the period-n orbit
        first = tracer.corrected(u0 + ds * tangent, tangent)
        if first is not None:
            split = np.max(np.abs(tracer.halves(first)))
            if split > 1e-6 * (1 + np.max(np.abs(first.ev.z))):
                first = tracer.analysed(first, tangent)
                return tracer.trace(first, ds=ds, doubled=True)
        ds *= 2
    return None


def _results(model: CompiledModel, traced: list[Traced], watches, parameter: str):
    names = model.parameter_names
    branches, bifurcations = [], []
    for index, t in enumerate(traced):
        sols = t.solutions
        contact = np.array([[contact_regime(*w.extremes(s.ev.low, s.ev.high, names, s.ev.inputs.p))
                             for w in watches] for s in sols], dtype=object).reshape(len(sols), len(watches))
        events = [i for i, s in enumerate(sols) if s.event]
        branches.append(Branch(
            index=index, period_multiple=t.period_multiple, values=np.array([s.value for s in sols]),
            states=np.array([s.ev.z[0] for s in sols]), multipliers=np.array([s.mu for s in sols]),
            low=np.array([s.ev.low for s in sols]), high=np.array([s.ev.high for s in sols]),
            residual=np.array([s.ev.error() for s in sols]), contact=contact, end=t.end, parent=t.parent,
            events=np.array(events, dtype=int)))
        for i in events:
            s = sols[i]
            bifurcations.append(Bifurcation(s.event[0], s.value, index, t.period_multiple, s.mu, s.ev.z[0].copy(),
                                            s.event[1], s.switched_to))
    return tuple(branches), tuple(bifurcations)
