"""The fastest linearised mode's rate from any Jacobian, and the step chosen over a sweep's points: the fastest
of them decides (:mod:`.step_choice`). From a compiled model's own Jacobian and period (:func:`chosen_by_compiled`)
the choice needs no SymPy: a sweep of a cached model chooses its step without loading the model."""
from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence

import numpy as np

from ..options import Integration
from .step_choice import chosen


def largest_rate(jacobian: Callable[[float, object], np.ndarray], system, cycle: float) -> float:
    """rho: the largest |eigenvalue| of ``jacobian(t, y)`` at eight times over the forcing period ``cycle``, at
    the system's initial state and at rest (zero state); a Jacobian not finite there is skipped."""
    rho = 0.0
    for y in (system.initial_vector, [0.0] * system.dimension):
        for k in range(8):
            J = np.asarray(jacobian(cycle * k / 8, y), dtype=float)
            if np.all(np.isfinite(J)):
                rho = max(rho, float(np.max(np.abs(np.linalg.eigvals(J)))))
    return rho


def fastest_of(options: Integration, rates: Sequence[float], system, cycle: float, points) -> Integration:
    """``options`` chosen (:func:`.step_choice.chosen`) for the largest of ``rates`` (the system's own, then each
    of ``points``'), the note naming the omega it was found at if not the model's; ``cycle``: the model's own
    forcing period."""
    own = system.parameters.get("omega")
    rho, omega = max(zip(rates, [own] + [values.get("omega", own) for values in points]), key=lambda r: r[0])
    # (a rate per unit time is per unit of tau: where omega differs from the model's, the note says at which, so
    # that its frequency is converted there)
    where = f" at omega={omega!r}" if omega is not None and omega != own else ""
    return chosen(options, rho, cycle, where)


def compiled_rate(compiled, values: Mapping[str, float] | None = None) -> tuple[float, float] | None:
    """The fastest rate (:func:`largest_rate`) and the forcing period at ``values``, from a compiled model's own
    Jacobian and period, or None where the period is not a positive number (the full system's error says why)."""
    p = compiled.parameter_vector(values)
    functions = compiled.native or compiled.functions  # (the library's own call where it has one: no CasADi loaded)
    period = float(np.asarray(functions["constants"](p)[1]).reshape(-1)[0])
    if not (math.isfinite(period) and period > 0):
        return None
    cycle = period / compiled.cycles
    return largest_rate(lambda t, y: compiled.jacobian(t, y, p), compiled.system, cycle), cycle


def chosen_by_compiled(options: Integration, compiled, points=()) -> Integration | None:
    """``options`` with the integrator and steps chosen at the model's values and at each of ``points`` (as
    :func:`~.fastest_mode.chosen_integration` chooses them), from a compiled model of the system
    (:func:`compiled_rate`), or None where a period is not a positive number."""
    if options.integrator != "auto":
        return options
    found = [compiled_rate(compiled)] + [compiled_rate(compiled, values) for values in points]
    if None in found:
        return None
    return fastest_of(options, [rate for rate, _ in found], compiled.system, found[0][1], points)
