"""Orbits at one parameter point: stroboscopic (Poincare) samples, amplitudes, phase trajectories."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..codegen import compiled_and_values
from ..checks import whole_number


@dataclass(frozen=True)
class Orbit:
    """``strobe``: the state at t0 + k*period (the Poincare section t mod period = t0), k after the transient."""

    model: str
    state_names: tuple[str, ...]
    strobe: np.ndarray  # (n, periods)
    amplitude: dict[str, float]
    final_state: dict[str, float]
    period: float


@dataclass(frozen=True)
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


def poincare_samples(model, *, periods: int = 200, discard: int = 100, y0=None, t0: float = 0.0,
                     steps_per_period: int = 200, backend: str = "auto", **settings) -> Orbit:
    """Stroboscopic samples after ``discard`` transient periods (no tangent vectors: cheaper)."""
    periods, discard = whole_number(periods, "periods", 1), whole_number(discard, "discard")
    compiled, values = compiled_and_values(model, settings, steps_per_period=steps_per_period, backend=backend)
    inputs = compiled.prepare(compiled.parameter_vector(values), t0=t0)
    strobe, low, high = compiled.orbit_run(y0, discard + periods, inputs)
    return Orbit(compiled.name, compiled.state_names, strobe[:, discard:],
                 amplitudes(compiled.observed, low[:, discard:], high[:, discard:]),
                 dict(zip(compiled.state_names, map(float, strobe[:, -1]))), inputs.period)


def phase_trajectory(model, *, periods: int = 20, discard: int = 100, y0=None, steps_per_period: int = 200,
                     backend: str = "auto", **settings) -> Trajectory:
    """The trajectory over ``periods`` periods after ``discard`` transient ones, at every step."""
    periods, discard = whole_number(periods, "periods"), whole_number(discard, "discard")
    compiled, values = compiled_and_values(model, settings, steps_per_period=steps_per_period, backend=backend)
    inputs = compiled.prepare(compiled.parameter_vector(values))
    start = compiled.initial_state(y0)
    if discard:
        strobe, _, _ = compiled.orbit_run(start, discard, inputs)
        start = strobe[:, -1]
    time, states = compiled.trajectory(start, periods, inputs)
    time = time + discard * inputs.period
    return Trajectory(compiled.name, compiled.state_names, time, states, states[:, ::compiled.steps_per_period])
