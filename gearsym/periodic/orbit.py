"""One periodic orbit at one parameter point: found by Newton from a state, a sweep's end or a simulation."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..checks import json_safe
from ..codegen import CompiledModel, engine_verb
from ..errors import GearsymError
from ..options import Integration
from .moduli import log_moduli
from .floquet import contact_regime, mesh_watches, multipliers, stable
from .shooting import Evaluation, NotConverged, OrbitMap, Shooting, newton

#: strobe points of the transient tried as Newton's start, the last first (a start on a chaotic
#: attractor may need another one)
STARTS_TRIED = 8


@dataclass(frozen=True)
class PeriodicOrbit:
    """A periodic orbit of ``period_multiple`` forcing periods and what its monodromy matrix says.

    ``state``: the state at the Poincare section (time t0 = 0 mod the forcing period); ``multipliers``: the
    Floquet multipliers, largest modulus first; ``amplitude``: (max - min)/2 of each observed state over the
    orbit's RK4 steps (as ``gearsym sweep`` reports it); ``contact``: each mesh's contact regime
    (:mod:`gearsym.periodic.floquet`); ``residual``: Newton's last residual relative to the state;
    ``trajectory``: every RK4 step over the orbit, (n, steps + 1), when asked for.
    """

    model: str
    parameters: dict[str, float]
    state_names: tuple[str, ...]
    state: np.ndarray
    period_multiple: int
    forcing_period: float
    multipliers: np.ndarray
    residual: float
    iterations: int
    amplitude: dict[str, float]
    extremes: dict[str, tuple[float, float]]
    contact: dict[str, str]
    segments: int = 1
    steps_per_period: int = 0
    locate_crossings: bool = True
    trajectory: np.ndarray | None = None
    #: log|mu_i| from the segments' maps (:mod:`.moduli`: what the monodromy matrix rounds away), largest first,
    #: and whether each was resolved (one that was not is at most that: a bound)
    log_moduli: np.ndarray | None = None
    resolved: np.ndarray | None = None

    @property
    def stable(self) -> bool:
        return stable(self.multipliers)

    @property
    def period(self) -> float:
        """The orbit's period in the model's time."""
        return self.period_multiple * self.forcing_period

    @property
    def exponents(self) -> np.ndarray:
        """ln|mu| / period: the orbit's Lyapunov exponents, largest first (what a long run converges to)."""
        return np.log(np.abs(self.multipliers)) / self.period

    def as_dict(self) -> dict:
        return json_safe({
            "model": self.model, "parameters": self.parameters,
            "state": dict(zip(self.state_names, self.state)),
            "period_multiple": self.period_multiple, "period": self.period,
            "multipliers": [{"re": float(m.real), "im": float(m.imag), "abs": float(abs(m))}
                            for m in self.multipliers],
            "stable": self.stable, "exponents": self.exponents, "residual": self.residual,
            "log_moduli": self.log_moduli, "moduli_resolved": self.resolved,
            "iterations": self.iterations, "amplitude": self.amplitude,
            "extremes": {k: {"min": lo, "max": hi} for k, (lo, hi) in self.extremes.items()},
            "contact": self.contact, "segments": self.segments, "steps_per_period": self.steps_per_period,
            "locate_crossings": self.locate_crossings,
        })


def describe_evaluation(problem: OrbitMap, ev: Evaluation, watches=None) -> dict:
    """Amplitudes, extremes and contact regimes of the orbit an evaluation holds."""
    model = problem.model
    watches = mesh_watches(model) if watches is None else watches
    amplitude = {name: float((hi - lo) / 2) for name, lo, hi in zip(model.observed, ev.low, ev.high)}
    extremes = {name: (float(lo), float(hi)) for name, lo, hi in zip(model.observed, ev.low, ev.high)}
    contact = {}
    for w in watches:
        lo, hi, eta = w.extremes(ev.low, ev.high, model.parameter_names, ev.inputs.p)
        contact[w.name] = contact_regime(lo, hi, eta)
    return {"amplitude": amplitude, "extremes": extremes, "contact": contact}


def orbit_from(problem: OrbitMap, ev: Evaluation, iterations: int, trajectory: bool = False) -> PeriodicOrbit:
    model, shooting = problem.model, problem.shooting
    states = None
    if trajectory:
        _, states = model.trajectory(ev.z[0], shooting.period_multiple, ev.inputs)
    return PeriodicOrbit(
        model=model.name, parameters=dict(zip(model.parameter_names, map(float, ev.inputs.p))),
        state_names=model.state_names, state=ev.z[0].copy(), period_multiple=shooting.period_multiple,
        forcing_period=ev.inputs.period, multipliers=multipliers(ev.monodromy), residual=ev.error(),
        iterations=iterations, **describe_evaluation(problem, ev), segments=shooting.segments,
        steps_per_period=model.steps_per_period, locate_crossings=model.options.locate_crossings,
        trajectory=states, **dict(zip(("log_moduli", "resolved"), log_moduli(ev.blocks))))


def starting_states(model: CompiledModel, y0, options: Integration, period_multiple: int,
                    inputs) -> list[np.ndarray]:
    """Where Newton may start: ``y0`` itself if given, else the states at the section after each of the
    last periods of a transient of ``options.periods`` forcing periods from the model's initial state."""
    if y0 is not None:
        return [model.initial_state(y0)]
    strobe, _, _ = model.orbit_run(None, options.periods, inputs)
    last = strobe.shape[1] - 1
    return [strobe[:, k] for k in range(last, max(-1, last - STARTS_TRIED * period_multiple), -period_multiple)]


def find_orbit(problem: OrbitMap, starts: list[np.ndarray], value: float | None = None) -> tuple[Evaluation, int]:
    """Newton from each start in turn until one converges."""
    last_error = None
    for y in starts:
        try:
            return newton(problem, problem.spread(y, value), value)
        except NotConverged as exc:
            last_error = exc
    where = ", ".join(f"{k}={v:g}" for k, v in zip(problem.model.parameter_names, problem.inputs(value).p))
    raise GearsymError(f"{problem.model.name}: {last_error} from {len(starts)} start(s) at {where}. The motion "
                       "there may not be periodic with this period: give a start near the orbit (y0, --y0), "
                       "another period multiple, or more transient periods")


@engine_verb
def periodic_orbit(model: CompiledModel, *, y0=None, period_multiple: int = 1, segments: int | None = None,
                   options: Integration | None = None, trajectory: bool = False, **values: float) -> PeriodicOrbit:
    """The periodic orbit of ``period_multiple`` periods near ``y0`` (a state at the section
    t = 0 mod the period), by Newton on P^n(y) - y = 0 with the exact monodromy matrix, in ``segments``
    shooting segments per period (default one per forcing period: 1, or for a model with shaft-order terms,
    whose period is a gear's revolution, one per mesh period). Without ``y0`` Newton starts where
    ``options.periods`` periods of simulation from the model's initial state end (the transient).
    ``trajectory``: keep every RK4 step.
    """
    options = model.run_options(options)
    segments = model.cycles if segments is None else segments
    problem = OrbitMap(model, Shooting(period_multiple, segments), values=values)
    if y0 is not None:
        y0 = model.initial_state(y0)
    ev, iterations = find_orbit(problem, starting_states(model, y0, options, period_multiple, problem.inputs(None)))
    return orbit_from(problem, ev, iterations, trajectory)


def sweep_start(sweep, model: CompiledModel, parameter: str, value: float, values=None) -> np.ndarray:
    """The final state of the point of a brute-force sweep (:func:`gearsym.read_sweep`) nearest to
    ``parameter`` = ``value`` (the up run's where there are two): a start on the attractor the sweep
    reached there. The sweep must be of the same model, at the same values of the other parameters (the
    model's, with ``values`` overriding)."""
    if sweep.model != model.name:
        raise GearsymError(f"the sweep {sweep.path} is of the model {sweep.model}, not {model.name}")
    if parameter not in sweep.columns:
        raise GearsymError(f"the sweep {sweep.path} does not vary {parameter}: it has {', '.join(sweep.columns)}")
    recorded = sweep.record.get("parameters", {})
    here = dict(zip(model.parameter_names, model.parameter_vector(values)))
    swept = {a.name for a in sweep.axes}
    differ = [f"{k}={recorded[k]:g} there, {here[k]:g} here" for k in here
              if k not in swept and k in recorded and not np.isclose(recorded[k], here[k], rtol=1e-12, atol=0)]
    if differ:
        raise GearsymError(f"the sweep {sweep.path} was run at other parameter values ({'; '.join(differ)}): give "
                           "the same --set values, or no --sweep")
    columns = [f"final_{s}" for s in model.state_names]
    missing = [c for c in columns if c not in sweep.columns]
    if missing or not len(sweep):
        raise GearsymError(f"the sweep {sweep.path} has no final states ({', '.join(missing) or 'no rows'})")
    rows = np.nonzero(sweep["direction"] == "up")[0] if np.any(sweep["direction"] == "up") else np.arange(len(sweep))
    row = rows[np.argmin(np.abs(sweep[parameter][rows] - value))]
    return np.array([float(sweep[c][row]) for c in columns])
