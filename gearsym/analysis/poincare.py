"""Orbits at one parameter point: stroboscopic (Poincare) samples, amplitudes, phase trajectories."""
from __future__ import annotations


import numpy as np

from ..records import record_class
from ..codegen import CompiledModel, engine_verb
from ..options import Integration


@record_class
class Orbit:
    """``strobe``: the state at t0 + k*period (the Poincare section t mod period = t0), k after the transient."""

    model: str
    state_names: tuple[str, ...]
    strobe: np.ndarray  # (n, periods)
    amplitude: dict[str, float]
    final_state: dict[str, float]
    period: float


@record_class
class Trajectory:
    """Every RK4 step: for phase portraits (x against v) with the Poincare points overlaid."""

    model: str
    state_names: tuple[str, ...]
    time: np.ndarray
    states: np.ndarray  # (n, steps)
    strobe: np.ndarray  # (n, periods + 1): every steps_per_period-th column of states

    def __getitem__(self, name: str) -> np.ndarray:
        return self.states[self.state_names.index(name)]


def amplitudes(names, low: np.ndarray, high: np.ndarray) -> dict[str, float]:
    """A = (max - min)/2 of each observed state, from per-period minima and maxima (observed x periods)."""
    return {n: float((h - lo) / 2) for n, lo, h in zip(names, low.min(axis=1), high.max(axis=1))}


@engine_verb
def poincare_samples(model: CompiledModel, *, options: Integration | None = None, y0=None, t0: float = 0.0,
                     **values: float) -> Orbit:
    """Stroboscopic samples of the ``periods - discard`` periods after the transient (no tangent
    vectors: cheaper than a spectrum). ``t0``: the phase of the section, t mod period = t0."""
    options = model.run_options(options)
    inputs = model.prepare(model.parameter_vector(values), t0=t0)
    strobe, low, high = model.orbit_run(y0, options.periods, inputs)
    d = options.discard
    return Orbit(model.name, model.state_names, strobe[:, d:], amplitudes(model.observed, low[:, d:], high[:, d:]),
                 dict(zip(model.state_names, map(float, strobe[:, -1]))), inputs.period)


@engine_verb
def phase_trajectory(model: CompiledModel, *, options: Integration | None = None, y0=None,
                     **values: float) -> Trajectory:
    """The trajectory at every RK4 step over the ``periods - discard`` periods after the transient."""
    options = model.run_options(options)
    inputs = model.prepare(model.parameter_vector(values))
    start = model.initial_state(y0)
    if options.discard:
        strobe, _, _ = model.orbit_run(start, options.discard, inputs)
        start = strobe[:, -1]
    time, states = model.trajectory(start, options.measured, inputs)
    time = time + options.discard * inputs.period
    return Trajectory(model.name, model.state_names, time, states, states[:, ::model.steps_per_period])
